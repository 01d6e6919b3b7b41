//! `eotn overhead`: the overhead camera's tools — the printable marker, calibration from a
//! points file, detection of ball and robots in field coordinates, and clicked points made from
//! a synthetic stream's truth.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Serialize;

use super::inputs::{FrameInputs, load_lut_arg, parse_size, progress};
use crate::geometry::{MarkerIdentity, MarkerTeam, OverheadCamera, Point};
use crate::model::GroundTruth;
use crate::overhead::OverheadPipeline;
use crate::overhead::calibration::Calibration;
use crate::overhead::drawing::marker_svg;
use crate::overhead::field::FieldDescription;
use crate::overhead::pipeline::{FrameFit, frame_fit};
use crate::overhead::points::{CalibrationPoint, PointsFile};
use crate::overhead::recognise::{OverheadDetections, OverheadParams};
use crate::overhead::review::review;
use crate::sim::SimRng;
use crate::streams::StreamReader;

/// Arguments of `eotn overhead`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// What to do.
    #[command(subcommand)]
    pub command: OverheadCommand,
}

/// The `eotn overhead` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum OverheadCommand {
    /// Write the printable robot marker of a team and identity as SVG at real size.
    Marker(MarkerArgs),
    /// Fit the camera (pose, focal, principal point, k1, k2; only the pose with --intrinsics)
    /// to a points file; print the parameters with their standard deviations and each point's
    /// reprojection error.
    Calibrate(CalibrateArgs),
    /// Find ball and robots in overhead frames: one JSON line per frame with `--json`.
    Detect(DetectArgs),
    /// Write a points file from a synthetic overhead stream's true camera: every visible
    /// landmark "clicked" with Gaussian noise (for tests and figures).
    SimPoints(SimPointsArgs),
    /// Render N overhead cameras over one field (overlapping views, each its own pose, lens and
    /// clock; up to 1920x1200): one recording with truth, table and calibration per camera, and
    /// the `SESSION.json` naming them.
    SimField(super::sim_field::SimFieldArgs),
    /// Throughput of the overhead pipeline on frames held in memory, on N threads beside one:
    /// one camera's frames, or a whole field's (`--session`), checked against the truth.
    Bench(super::overhead_bench::BenchArgs),
}

/// Arguments of `eotn overhead marker`.
#[derive(Debug, clap::Args)]
pub struct MarkerArgs {
    /// Team dot colour: `blue` or `yellow`.
    #[arg(long, required_unless_present = "all", conflicts_with = "all")]
    pub team: Option<String>,
    /// Identity, 0–15.
    #[arg(long, required_unless_present = "all", conflicts_with = "all")]
    pub id: Option<u8>,
    /// Write every marker (both teams, identities 0–15) into the folder `-o` names, as
    /// `TEAM-NN.svg` (the set shipped in `assets/markers/`).
    #[arg(long)]
    pub all: bool,
    /// Output SVG (with `--all`, the folder).
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: PathBuf,
}

/// Arguments of `eotn overhead calibrate`.
#[derive(Debug, clap::Args)]
pub struct CalibrateArgs {
    /// The clicked landmarks (`*.points.json`).
    #[arg(long)]
    pub points: PathBuf,
    /// Where to write the calibration (JSON).
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: PathBuf,
    /// A frame of the camera: refine along its field lines and write the lines projected over
    /// it as `CAL.lines.png` beside the calibration.
    #[arg(long)]
    pub image: Option<PathBuf>,
    /// Field description (landmarks, lines, heights): a file, or a shipped field's name
    /// (four-legged-2005, ssl-2008, spl-2020, ssl-div-a, ssl-div-b); four-legged-2005 by
    /// default.
    #[arg(long, value_name = "FIELD")]
    pub field: Option<PathBuf>,
    /// Frame size of a raw `--image`, WxH.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// The lens's intrinsics from a checkerboard calibration: a ROS `camera_info` YAML file as
    /// `camera_calibration` writes it (plumb_bob, rational_polynomial or equidistant), or a
    /// recording holding a `sensor_msgs/CameraInfo` or `foxglove.CameraCalibration` channel
    /// (its first message); then only the camera's pose is fitted. Intrinsics made at a whole
    /// multiple or fraction of the points' frame size are scaled.
    #[arg(long)]
    pub intrinsics: Option<PathBuf>,
    /// With a recording as `--intrinsics` holding several cameras: the image topic whose camera
    /// info to take.
    #[arg(
        long = "intrinsics-camera",
        value_name = "TOPIC",
        requires = "intrinsics"
    )]
    pub intrinsics_camera: Option<String>,
    /// Do not refine along the lines even with `--image`.
    #[arg(long)]
    pub no_lines: bool,
    /// Print the result as one JSON object (the calibration, each parameter's standard
    /// deviation, the findings) instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write the calibration even when it is doubtful (a large residual; a focal length,
    /// principal point, distortion or height unlike a real overhead camera; clicks in one part
    /// of the image or parameters they leave uncertain; points made for another field): without
    /// it such a calibration is reported and not written, and the command fails.
    #[arg(long)]
    pub accept: bool,
}

/// Arguments of `eotn overhead detect`.
#[derive(Debug, clap::Args)]
pub struct DetectArgs {
    /// Frames (`.uyvy`, `.png`, `.jpg`), folders of them, or MCAP streams.
    #[arg(required_unless_present = "session", conflicts_with = "session")]
    pub frames: Vec<PathBuf>,
    /// Lookup table of the overhead camera (default: the one the recording names for the
    /// camera read, docs/formats.md 'Several cameras').
    #[arg(long, conflicts_with = "session")]
    pub lut: Option<PathBuf>,
    /// Calibration (`eotn overhead calibrate`; default: the one the recording names for the
    /// camera read).
    #[arg(long, conflicts_with = "session")]
    pub calibration: Option<PathBuf>,
    /// A session file (docs/formats.md): every overhead camera through its own table and
    /// calibration, merged into one field picture per frame of the first (reference) camera;
    /// with `--json` one line per field frame with `time_ns`, `ball`, `robots` (each with
    /// `camera_ids`) and `cameras` (each merged frame's `id` and `time_ns`).
    #[arg(long)]
    pub session: Option<PathBuf>,
    /// Field description for the ball radius and plate height: a file or a shipped field's
    /// name (as `overhead calibrate --field`); four-legged-2005 by default.
    #[arg(long, value_name = "FIELD")]
    pub field: Option<PathBuf>,
    /// Frame size of raw files, WxH.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// One JSON object per frame per line.
    #[arg(long)]
    pub json: bool,
    /// Also send the detections as SSL-Vision packets over UDP to HOST:PORT (a unicast address,
    /// or the league's multicast group 224.5.23.2:10006): an `SSL_WrapperPacket` per camera
    /// frame (millimetres in the field frame) and the field and each camera's calibration every
    /// few seconds (docs/formats.md, "SSL-Vision packets").
    #[arg(long, value_name = "HOST:PORT")]
    pub ssl_vision: Option<String>,
    /// The `camera_id` of a single camera's packets (a session's cameras send their session
    /// ids).
    #[arg(
        long,
        value_name = "ID",
        default_value_t = 0,
        requires = "ssl_vision",
        conflicts_with = "session"
    )]
    pub ssl_camera_id: u8,
    /// Which camera of the recordings.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
}

/// Arguments of `eotn overhead sim-points`.
#[derive(Debug, clap::Args)]
pub struct SimPointsArgs {
    /// A synthetic overhead stream (`eotn sim --scenario overhead-game`).
    #[arg(long)]
    pub stream: PathBuf,
    /// Click noise, pixels (standard deviation per axis).
    #[arg(long, default_value_t = 1.0, value_parser = super::values::number_in(0.0, 100.0))]
    pub noise_px: f64,
    /// Seed of the noise.
    #[arg(long, default_value_t = 1, value_parser = super::values::seed())]
    pub seed: u64,
    /// Which camera of the recordings.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
    /// Field description: a file or a shipped field's name (as `overhead calibrate --field`);
    /// four-legged-2005 by default.
    #[arg(long, value_name = "FIELD")]
    pub field: Option<PathBuf>,
    /// Output points file.
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: PathBuf,
}

/// Runs `eotn overhead`.
///
/// # Errors
/// Whatever the subcommand reports, naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    match &args.command {
        OverheadCommand::Marker(a) => run_marker(a),
        OverheadCommand::Calibrate(a) => super::overhead_calibrate::run(a),
        OverheadCommand::Detect(a) => run_detect(a),
        OverheadCommand::SimPoints(a) => run_sim_points(a),
        OverheadCommand::SimField(a) => super::sim_field::run(a),
        OverheadCommand::Bench(a) => super::overhead_bench::run(a),
    }
}

/// The field description `--field` names (a file or a shipped field's name), or the 2005
/// field.
///
/// # Errors
/// The loader's error naming the file, or an unknown name with the shipped names listed.
pub fn load_field(path: Option<&Path>) -> anyhow::Result<FieldDescription> {
    Ok(match path {
        Some(p) => FieldDescription::resolve(&p.to_string_lossy())?,
        None => FieldDescription::four_legged_2005(),
    })
}

fn run_marker(a: &MarkerArgs) -> anyhow::Result<()> {
    if a.all {
        return write_all_markers(&a.output);
    }
    let (Some(name), Some(value)) = (a.team.as_deref(), a.id) else {
        bail!("--team and --id name the marker (or --all writes every one)");
    };
    let team = MarkerTeam::from_name(name)
        .with_context(|| format!("team {name:?}: must be blue or yellow"))?;
    let id = MarkerIdentity::new(value).with_context(|| format!("id {value}: must be 0-15"))?;
    crate::atomic_file::write_atomic(&a.output, marker_svg(team, id).as_bytes())
        .with_context(|| format!("{}: cannot write", a.output.display()))?;
    eprintln!(
        "{}: marker team {} id {id}",
        a.output.display(),
        team.name()
    );
    Ok(())
}

/// The file name of a marker in a `--all` folder: `blue-05.svg`.
#[must_use]
pub fn marker_file_name(team: MarkerTeam, id: MarkerIdentity) -> String {
    format!("{}-{:02}.svg", team.name(), id.value())
}

/// Writes all 32 markers into `dir` (made if missing).
fn write_all_markers(dir: &Path) -> anyhow::Result<()> {
    crate::atomic_file::output_folder(dir).with_context(|| format!("{}", dir.display()))?;
    for team in [MarkerTeam::Blue, MarkerTeam::Yellow] {
        for value in 0..16 {
            let id = MarkerIdentity::new(value).context("identity in 0..16")?;
            let path = dir.join(marker_file_name(team, id));
            crate::atomic_file::write_atomic(&path, marker_svg(team, id).as_bytes())
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
    }
    eprintln!("{}: 32 markers (blue and yellow, 0-15)", dir.display());
    Ok(())
}

/// The ball in `eotn overhead detect --json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BallJson {
    /// Field x, centimetres.
    pub x_cm: f64,
    /// Field y, centimetres.
    pub y_cm: f64,
    /// Image centre `[x, y]`, pixels.
    pub image_px: [f64; 2],
    /// Image radius, pixels.
    pub radius_px: f64,
    /// Confidence, 0–1.
    pub confidence: f64,
}

/// A robot in `eotn overhead detect --json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct RobotJson {
    /// `blue` or `yellow`.
    pub team: &'static str,
    /// Identity 0–15.
    pub id: u8,
    /// Field x, centimetres.
    pub x_cm: f64,
    /// Field y, centimetres.
    pub y_cm: f64,
    /// Heading, radians counter-clockwise from +x.
    pub heading_rad: f64,
    /// Confidence, 0–1.
    pub confidence: f64,
}

/// One line of `eotn overhead detect --json` (the interface is fixed: other tools read it).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct OverheadJson {
    /// Frame name (file name, or `STEM_NNNNNN` for a stream frame).
    pub frame: String,
    /// The ball, or null.
    pub ball: Option<BallJson>,
    /// The robots.
    pub robots: Vec<RobotJson>,
    /// Time of the whole overhead processing (classification, blobs, recognition), µs.
    pub overhead_us: f64,
}

/// The JSON line of one frame's detections.
#[must_use]
pub fn overhead_json(frame: String, d: &OverheadDetections, overhead_us: f64) -> OverheadJson {
    OverheadJson {
        frame,
        ball: d.ball.map(|b| BallJson {
            x_cm: b.field_cm[0],
            y_cm: b.field_cm[1],
            image_px: [b.image.x_px, b.image.y_px],
            radius_px: b.radius_px,
            confidence: b.confidence,
        }),
        robots: d
            .robots
            .iter()
            .map(|r| RobotJson {
                team: r.team.name(),
                id: r.identity.value(),
                x_cm: r.field_cm[0],
                y_cm: r.field_cm[1],
                heading_rad: r.heading_rad,
                confidence: r.confidence,
            })
            .collect(),
        overhead_us,
    }
}

/// The recogniser's settings for a field.
#[must_use]
pub fn params_for(field: &FieldDescription) -> OverheadParams {
    OverheadParams {
        ball_radius_cm: field.ball_radius_cm,
        plate_height_cm: field.plate_height_cm,
        ..OverheadParams::default()
    }
}

/// The calibration of `--calibration`: refused when [`review`] refuses it, its doubts warned
/// about.
///
/// # Errors
/// The loader's error, or the refusal, naming the file.
pub fn load_usable_calibration(path: &Path) -> anyhow::Result<Calibration> {
    let cal = Calibration::load(path)?;
    let review = review(&cal);
    if let Some(refusal) = review.refusal() {
        bail!("{}: not a usable calibration: {refusal}", path.display());
    }
    for f in &review.findings {
        log::warn!("{}: {f}", path.display());
    }
    Ok(cal)
}

/// Frame sizes against the calibration's: another shape stops the command, another size of
/// the same shape is warned about once.
#[derive(Debug, Default)]
pub struct SizeCheck {
    warned: Vec<(usize, usize)>,
}

impl SizeCheck {
    /// Checks a frame of `name`.
    ///
    /// # Errors
    /// A frame of another shape than the calibration's.
    pub fn check(
        &mut self,
        camera: &OverheadCamera,
        name: &str,
        w: usize,
        h: usize,
    ) -> anyhow::Result<()> {
        match frame_fit(camera, w, h) {
            FrameFit::Same => Ok(()),
            fit @ FrameFit::Mismatch { .. } => bail!("{name}: {fit}"),
            fit @ FrameFit::Scaled { .. } => {
                if !self.warned.contains(&(w, h)) {
                    self.warned.push((w, h));
                    log::warn!("{name}: {fit}");
                }
                Ok(())
            }
        }
    }
}

/// Refuses robot-camera streams given to an overhead command.
///
/// # Errors
/// The first such stream, named.
pub fn refuse_robot_streams(streams: &[PathBuf]) -> anyhow::Result<()> {
    if let Some(p) = streams.first() {
        bail!(
            "{}: a robot camera's stream (its source kind does not say overhead); overhead commands read overhead cameras' streams (`eotn import --source overhead` marks imported ones)",
            p.display()
        );
    }
    Ok(())
}

fn run_detect(a: &DetectArgs) -> anyhow::Result<()> {
    if let Some(session) = &a.session {
        return super::detect_field::run(session, a.json, a.ssl_vision.as_deref());
    }
    // Not given: the table and calibration the recording names for the camera read.
    let named = super::detect::named_camera_files(&a.frames, a.camera.get())?
        .map(|(_, files)| files)
        .unwrap_or_default();
    let (Some(lut), Some(cal)) = (
        a.lut.as_ref().or(named.lut.as_ref()),
        a.calibration.as_ref().or(named.calibration.as_ref()),
    ) else {
        bail!(
            "--lut and --calibration are needed with frames whose recording names none for the camera (or give --session)"
        );
    };
    let lut = load_lut_arg(lut)?;
    let cal = load_usable_calibration(cal)?;
    let field = load_field(a.field.as_deref())?;
    let mut pipeline = OverheadPipeline::new(lut, cal.camera, params_for(&field));
    let mut inputs = FrameInputs::open_camera(&a.frames, None, a.camera.get())?;
    refuse_robot_streams(inputs.robot_streams())?;
    let camera_id = u32::from(a.ssl_camera_id);
    let mut ssl = a
        .ssl_vision
        .as_deref()
        .map(|addr| {
            let entry = crate::ssl_vision::CameraEntry {
                camera_id,
                camera: cal.camera,
            };
            super::ssl_vision_out::open(addr, &field, &[entry])
        })
        .transpose()?;
    let mut sizes = SizeCheck::default();
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let bar = progress(inputs.len(), "overhead detect");
    for i in 0..inputs.len() {
        let loaded = inputs.load_source_frame(i, a.size)?;
        let frame = &loaded.frame;
        sizes.check(&cal.camera, &inputs.name(i), frame.width(), frame.height())?;
        pipeline.process(frame);
        if let Some(out) = ssl.as_mut() {
            out.send(camera_id, loaded.time_ns, pipeline.detections());
        }
        let us = pipeline.timings().total().as_secs_f64() * 1e6;
        let line = overhead_json(inputs.name(i), pipeline.detections(), us);
        if a.json {
            serde_json::to_writer(&mut out, &line)?;
            writeln!(out)?;
        } else {
            write!(out, "{}:", line.frame)?;
            match &line.ball {
                Some(b) => write!(out, " ball ({:.1}, {:.1}) cm", b.x_cm, b.y_cm)?,
                None => write!(out, " no ball")?,
            }
            for r in &line.robots {
                write!(
                    out,
                    "; {} {} ({:.1}, {:.1}) cm {:.0}°",
                    r.team,
                    r.id,
                    r.x_cm,
                    r.y_cm,
                    r.heading_rad.to_degrees()
                )?;
            }
            writeln!(out)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    out.flush().context("writing output")?;
    if let Some(ssl) = &ssl {
        super::ssl_vision_out::finish(ssl);
    }
    Ok(())
}

/// Every landmark of `field` that `camera` sees inside the image, "clicked" with Gaussian
/// noise of `noise_px` per axis.
#[must_use]
pub fn simulated_clicks(
    camera: &OverheadCamera,
    field: &FieldDescription,
    noise_px: f64,
    seed: u64,
) -> PointsFile {
    let mut rng = SimRng::derived(seed, 0xC11C);
    let mut file = PointsFile::new(camera.width_px, camera.height_px);
    let (w, h) = (camera.width_px as f64, camera.height_px as f64);
    for l in &field.landmarks {
        let p = Point::new(l.field_cm[0], l.field_cm[1], l.height_cm);
        let Some(q) = camera.image_from_field(&p) else {
            continue;
        };
        if q.x_px < 2.0 || q.y_px < 2.0 || q.x_px > w - 2.0 || q.y_px > h - 2.0 {
            continue;
        }
        file.points.push(CalibrationPoint {
            name: l.name.clone(),
            field_cm: l.field_cm,
            height_cm: l.height_cm,
            image_px: [
                q.x_px + noise_px * rng.normal(),
                q.y_px + noise_px * rng.normal(),
            ],
        });
    }
    file
}

/// The true overhead camera of a synthetic stream (from its first frame's truth).
///
/// # Errors
/// A stream without overhead truth.
pub fn stream_truth_camera(path: &Path, camera: Option<&str>) -> anyhow::Result<OverheadCamera> {
    let mut reader = StreamReader::open_camera(path, camera)?;
    let record = reader.read(0)?;
    let truth = record
        .ground_truth
        .with_context(|| format!("{}: frame 0 has no ground truth", path.display()))?;
    match serde_json::from_value::<GroundTruth>(truth) {
        Ok(GroundTruth::Overhead(t)) => Ok(t.camera),
        Ok(GroundTruth::Robot(_)) => {
            bail!("{}: a robot-camera stream, not overhead", path.display())
        }
        Err(e) => bail!("{}: unreadable ground truth: {e}", path.display()),
    }
}

fn run_sim_points(a: &SimPointsArgs) -> anyhow::Result<()> {
    if !(a.noise_px.is_finite() && a.noise_px >= 0.0) {
        bail!("--noise-px must be a non-negative number");
    }
    let field = load_field(a.field.as_deref())?;
    let camera = stream_truth_camera(&a.stream, a.camera.get())?;
    let file = simulated_clicks(&camera, &field, a.noise_px, a.seed);
    file.save(&a.output)?;
    eprintln!(
        "{}: {} landmarks with {} px noise",
        a.output.display(),
        file.points.len(),
        a.noise_px
    );
    Ok(())
}
