//! `eotn wmd`: the World Model Debugger headless. An overhead camera (or a session's cameras)
//! and the robots' world models: each world model is paired with the overhead frame nearest in
//! time, matched with its robot by marker (else by position), and its errors measured; `--json`
//! prints one line per overhead frame, else a table per robot; `-o` records the whole session.
//!
//! With recordings only, the session is read through as fast as it goes, each robot's clock
//! offset searched from the data (`crate::wmd::clock`). With a live source (a `ws://` server, a
//! camera device) it runs on this machine's clock until `--seconds`, Ctrl+C or SIGTERM
//! ([`super::wmd_live`]).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, bail};
use serde_json::{Value, json};

use super::field::{FieldCamera, open_cameras};
use super::overhead::{load_field, overhead_json};
use super::wmd_inputs::{FieldFrame, RobotModels, field_frames, read_world_models, recorded};
use super::wmd_record::{CameraFrame, SessionRecorder};
use crate::model::world_model::RobotKey;
use crate::overhead::merge::{SslCameraId, frame_near};
use crate::session::{Session, SessionSource, SslSource};
use crate::wmd::clock::{ClockOffset, estimate_offset, frame_period_ns, shifted};
use crate::wmd::summary::{RobotSummary, Spread, Summaries};
use crate::wmd::{Comparison, Targets, WorldModelMessage, compare};

/// Arguments of `eotn wmd`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The overhead camera: a recording, a `ws://HOST:PORT` server or a camera device
    /// (`/dev/videoN`, as `eotn sources` lists them); or SSL-Vision's detections in its place,
    /// live on `udp://GROUP:PORT` (the league's is udp://224.5.23.2:10006) or a league log
    /// (`.log`, `.log.gz`) read through, which need no --lut or --calibration.
    #[arg(
        long,
        value_name = "SOURCE",
        required_unless_present = "session",
        conflicts_with = "session"
    )]
    pub overhead: Option<PathBuf>,
    /// A robot's world models (`/world_model`, `/world_model/<name>`; docs/formats.md): a
    /// recording or a `ws://HOST:PORT` robot; repeatable; one source may carry several robots'.
    #[arg(
        long,
        value_name = "SOURCE",
        required_unless_present = "session",
        conflicts_with = "session"
    )]
    pub robot: Vec<PathBuf>,
    /// The overhead camera's lookup table (required, except for an SSL-Vision source).
    #[arg(long, conflicts_with = "session")]
    pub lut: Option<PathBuf>,
    /// The overhead camera's calibration (`eotn overhead calibrate`; required, except for an
    /// SSL-Vision source).
    #[arg(long, conflicts_with = "session")]
    pub calibration: Option<PathBuf>,
    /// Field description (a file or a shipped field's name): ball radius, plate height, and
    /// where the goals and landmarks a robot measures stand; four-legged-2005 by default.
    #[arg(long, value_name = "FIELD", conflicts_with = "session")]
    pub field: Option<PathBuf>,
    /// A session file (docs/formats.md): its overhead cameras merged, its robots' sources.
    #[arg(long)]
    pub session: Option<PathBuf>,
    /// One JSON object per overhead frame per line: `time_ns`, `ball`, `robots` (as
    /// `eotn overhead detect --json` prints them), `world_models`.
    #[arg(long)]
    pub json: bool,
    /// Record the whole session: overhead frames, detections (also as a `foxglove.SceneUpdate`),
    /// each robot's world models and camera frames, in one MCAP (docs/formats.md).
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: Option<PathBuf>,
    /// With a live source: stop after this many seconds (above 0, at most 604800). Without it a
    /// live session runs until Ctrl+C or SIGTERM.
    #[arg(long, value_parser = super::bounds::seconds, allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Recordings only: how far to search for each robot's clock offset, seconds (0: the start
    /// only).
    #[arg(long, default_value_t = 2.0, value_parser = super::values::number_in(0.0, 3600.0))]
    pub max_clock_offset: f64,
    /// Also send the overhead detections as SSL-Vision packets over UDP to HOST:PORT (a unicast
    /// address, or the league's group 224.5.23.2:10006): an `SSL_WrapperPacket` per camera frame,
    /// `camera_id` the session's id (0 with `--overhead`), and the geometry every few seconds, as
    /// `eotn overhead detect --ssl-vision` sends them.
    #[arg(long, value_name = "HOST:PORT")]
    pub ssl_vision: Option<String>,
    /// Which camera of the overhead recording.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
}

/// What a session came to, for the table and the closing warnings.
#[derive(Debug)]
pub struct Outcome {
    /// Each robot's summary.
    pub summaries: Vec<RobotSummary>,
    /// Each robot's clock offset.
    pub offsets: Vec<(RobotKey, ClockOffset)>,
    /// The last field frame's time, nanoseconds.
    pub last_ns: u64,
    /// The reference camera's frame period, nanoseconds.
    pub period_ns: u64,
    /// Field frames made.
    pub field_frames: usize,
}

/// Runs `eotn wmd`.
///
/// # Errors
/// An unreadable input (named), no world models at all (recordings), no overhead frame.
pub fn run(a: &Args) -> anyhow::Result<()> {
    if a.ssl_vision.is_some() && has_ssl_source(a)? {
        bail!(
            "--ssl-vision: the overhead source is SSL-Vision already; its packets go to its own \
             clients"
        );
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let outcome = if is_live(a)? {
        let (inputs, recorder) = super::wmd_inputs::open_live(a)?;
        let ssl = a
            .ssl_vision
            .as_deref()
            .map(|addr| {
                super::ssl_vision_out::open(addr, &inputs.field, &live_ssl_cameras(&inputs))
            })
            .transpose()?;
        super::wmd_live::run(inputs, a.json, a.seconds, (recorder, ssl), &mut out)?
    } else {
        if a.seconds.is_some() {
            log::warn!("--seconds: every source is a recording, read to its end");
        }
        recorded_session(a, &mut out)?
    };
    report(a.json, &outcome, &mut out)?;
    out.flush().context("writing output")?;
    if outcome.field_frames == 0 {
        bail!("no overhead frame arrived");
    }
    Ok(())
}

/// Each live overhead camera's id and calibration, for the SSL-Vision geometry.
fn live_ssl_cameras(inputs: &super::wmd_live::LiveInputs) -> Vec<crate::ssl_vision::CameraEntry> {
    inputs
        .cameras
        .iter()
        .filter_map(|c| {
            Some(crate::ssl_vision::CameraEntry {
                camera_id: super::ssl_vision_out::session_camera_id(c.id),
                camera: *c.pipeline.as_ref()?.camera(),
            })
        })
        .collect()
}

/// The overhead sources named (the session's or `--overhead`).
fn overhead_sources(a: &Args) -> anyhow::Result<Vec<SessionSource>> {
    Ok(match &a.session {
        Some(path) => Session::load(path)?
            .overhead
            .into_iter()
            .map(|e| e.source)
            .collect(),
        None => a
            .overhead
            .iter()
            .map(|p| SessionSource::parse_arg(p))
            .collect(),
    })
}

/// True when the overhead source is SSL-Vision.
fn has_ssl_source(a: &Args) -> anyhow::Result<bool> {
    Ok(overhead_sources(a)?
        .iter()
        .any(|s| matches!(s, SessionSource::Ssl(_))))
}

/// True when any source is live or a device.
fn is_live(a: &Args) -> anyhow::Result<bool> {
    if let Some(path) = &a.session {
        let session = Session::load(path)?;
        let sources = session.overhead.iter().map(|e| &e.source);
        let robots = session.robots.iter().map(|r| &r.source);
        return Ok(sources.chain(robots).any(is_live_source));
    }
    let args = a.overhead.iter().chain(&a.robot);
    Ok(args
        .map(|p| SessionSource::parse_arg(p))
        .any(|s| is_live_source(&s)))
}

/// Live: a server, a device, udp://; a recording and an SSL-Vision log are read through.
fn is_live_source(s: &SessionSource) -> bool {
    !matches!(
        s,
        SessionSource::Recording(_) | SessionSource::Ssl(SslSource::Log(_))
    )
}

/// The closing report: robots that stopped early warned about; the table (or, with `--json`,
/// each robot's clock offset on stderr).
fn report(json: bool, o: &Outcome, out: &mut impl Write) -> anyhow::Result<()> {
    for s in &o.summaries {
        if o.last_ns.saturating_sub(s.last_ns) > 10 * o.period_ns {
            log::warn!(
                "{}: no world model after {:.3} s (the overhead frames run to {:.3} s)",
                s.robot,
                s.last_ns as f64 * 1e-9,
                o.last_ns as f64 * 1e-9
            );
        }
    }
    if json {
        for (key, off) in &o.offsets {
            eprintln!("{key}: clock offset {}", offset_text(off));
        }
    } else {
        write_table(out, &o.summaries, &o.offsets)?;
    }
    Ok(())
}

/// A session of recordings, read through: world models first, then the field frames, each
/// robot's clock offset searched, every frame compared (and recorded with `-o`).
fn recorded_session(a: &Args, out: &mut impl Write) -> anyhow::Result<Outcome> {
    let (field, mut cameras, robots, single) = open(a)?;
    let ssl_log = ssl_log_source(a)?;
    let mut models = RobotModels::new();
    let mut paired_before = std::collections::BTreeSet::new();
    for (path, only) in &robots {
        let read = read_world_models(path, *only, &mut models)?;
        log::info!("{}: {} world models", path.display(), read.read);
        paired_before.extend(read.paired_when_recorded);
    }
    if models.is_empty() {
        bail!("no world model in the robots' recordings");
    }
    let mut recorder = a
        .output
        .as_deref()
        .map(|p| SessionRecorder::create(p, &recorded_cameras(a, &cameras)?))
        .transpose()?;
    let mut ssl = a
        .ssl_vision
        .as_deref()
        .map(|addr| {
            super::ssl_vision_out::open(addr, &field, &super::detect_field::ssl_cameras(&cameras))
        })
        .transpose()?;
    let frames = match &ssl_log {
        Some(log) => super::wmd_ssl::log_field_frames(log)?,
        None => field_frames(&mut cameras, single, ssl.as_mut())?,
    };
    if let Some(ssl) = &ssl {
        super::ssl_vision_out::finish(ssl);
    }
    if frames.is_empty() {
        bail!("the overhead recording has no frames");
    }
    let times: Vec<u64> = frames.iter().map(|f| f.time_ns).collect();
    let period = frame_period_ns(&times);
    #[expect(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "0..=3600 s"
    )]
    let max_offset = (a.max_clock_offset * 1e9) as u64;
    let views: Vec<crate::wmd::OverheadView> = frames.iter().map(FieldFrame::view).collect();
    let search = Search {
        period,
        max_offset,
        paired_before: &paired_before,
    };
    let (offsets, paired) = pair(&models, &times, &views, &search);
    let targets = Targets::from_field(&field);
    let mut summaries = Summaries::default();
    for (i, frame) in frames.iter().enumerate() {
        let results = compare(&views[i], &paired[i], &targets);
        let jumps: Vec<bool> = results
            .iter()
            .map(|c| summaries.add(frame.time_ns, c))
            .collect();
        let line = line_json(frame, &results, &jumps)?;
        if a.json {
            serde_json::to_writer(&mut *out, &line)?;
            writeln!(out)?;
        }
        if let Some(rec) = recorder.as_mut() {
            let scene = crate::wmd::scene::scene_update(
                frame.time_ns,
                &field,
                &views[i],
                &paired[i],
                &results,
            );
            let read = read_frames(&mut cameras, &frame.cameras)?;
            let cameras: Vec<CameraFrame<'_>> = read
                .iter()
                .map(|(id, time_ns, f)| CameraFrame {
                    id: *id,
                    time_ns: *time_ns,
                    frame: f,
                })
                .collect();
            rec.field_frame(frame.time_ns, &cameras, &paired[i], &line, &scene)?;
        }
    }
    if let Some(rec) = recorder {
        rec.finish()?;
    }
    Ok(Outcome {
        summaries: summaries.finish(),
        offsets,
        last_ns: times.last().copied().unwrap_or(0),
        period_ns: period,
        field_frames: frames.len(),
    })
}

/// The SSL-Vision log that is the overhead source, if one is (refused with `-o`: it holds no
/// frames to record).
fn ssl_log_source(a: &Args) -> anyhow::Result<Option<PathBuf>> {
    let ssl_log = overhead_sources(a)?.into_iter().find_map(|s| match s {
        SessionSource::Ssl(SslSource::Log(p)) => Some(p),
        _ => None,
    });
    if let (Some(log), Some(_)) = (&ssl_log, &a.output) {
        bail!(
            "-o: {} is SSL-Vision, which holds no frames to record; record without -o, or keep \
             the league's log",
            log.display()
        );
    }
    Ok(ssl_log)
}

/// The overhead cameras as the recording names them, with their files.
fn recorded_cameras(
    a: &Args,
    cameras: &[FieldCamera],
) -> anyhow::Result<Vec<super::wmd_record::RecordedCamera>> {
    let files: Vec<crate::camera::CameraFiles> = match &a.session {
        Some(path) => Session::load(path)?
            .overhead
            .iter()
            .map(|e| crate::camera::CameraFiles {
                lut: e.lut.clone(),
                params: None,
                calibration: e.calibration.clone(),
            })
            .collect(),
        None => vec![crate::camera::CameraFiles {
            lut: a.lut.clone(),
            params: None,
            calibration: a.calibration.clone(),
        }],
    };
    Ok(cameras
        .iter()
        .zip(files)
        .map(|(c, files)| super::wmd_record::RecordedCamera { id: c.id, files })
        .collect())
}

/// Each camera's frame of a field frame read again (for the recording), by its time.
fn read_frames(
    cameras: &mut [FieldCamera],
    wanted: &[(SslCameraId, u64)],
) -> anyhow::Result<Vec<(SslCameraId, u64, crate::frame::Frame)>> {
    let mut out = Vec::new();
    for &(id, time_ns) in wanted {
        let Some(cam) = cameras.iter_mut().find(|c| c.id == id) else {
            continue;
        };
        let index = (0..cam.len()).find(|&i| cam.reader.time_ns(i) == Some(time_ns));
        if let Some(i) = index {
            out.push((id, time_ns, cam.read(i)?.frame));
        }
    }
    Ok(out)
}

/// How each robot's clock offset is found: the frame period, how far to search, and the robots
/// whose world models were paired when their session was recorded (offset 0, not searched).
struct Search<'a> {
    period: u64,
    max_offset: u64,
    paired_before: &'a std::collections::BTreeSet<RobotKey>,
}

/// Each robot's clock offset, and the world models paired with each frame (of each robot the
/// one nearest the frame's time, within half a frame period).
fn pair<'a>(
    models: &'a RobotModels,
    times: &[u64],
    views: &[crate::wmd::OverheadView],
    search: &Search<'_>,
) -> (
    Vec<(RobotKey, ClockOffset)>,
    Vec<Vec<&'a WorldModelMessage>>,
) {
    let mut offsets = Vec::new();
    let mut paired: Vec<Vec<&WorldModelMessage>> = vec![Vec::new(); times.len()];
    for (key, list) in models {
        let own: Vec<(u64, [f64; 2])> = list
            .iter()
            .map(|(t, m)| (*t, [m.own.x_cm, m.own.y_cm]))
            .collect();
        let robot_at = |i: usize| {
            views[i]
                .robots
                .iter()
                .find(|r| r.key == *key)
                .map(|r| r.field_cm)
        };
        let period = search.period;
        let max_offset = if search.paired_before.contains(key) {
            0
        } else {
            search.max_offset
        };
        let offset = estimate_offset(times, period, robot_at, &own, max_offset);
        // The message nearest in time to each frame.
        let mut nearest: Vec<Option<(u64, &WorldModelMessage)>> = vec![None; times.len()];
        for (t, m) in list {
            let Some(t) = shifted(*t, offset.offset_ns) else {
                continue;
            };
            let Some(i) = frame_near(times, t, period) else {
                continue;
            };
            let gap = t.abs_diff(times[i]);
            if nearest[i].is_none_or(|(g, _)| gap < g) {
                nearest[i] = Some((gap, m));
            }
        }
        for (i, n) in nearest.into_iter().enumerate() {
            paired[i].extend(n.map(|n| n.1));
        }
        offsets.push((*key, offset));
    }
    (offsets, paired)
}

/// The inputs: field, overhead cameras, robot recordings (each with the robot it is for, in a
/// session), whether there is one camera from the command line.
type Opened = (
    crate::overhead::FieldDescription,
    Vec<FieldCamera>,
    Vec<(PathBuf, Option<RobotKey>)>,
    bool,
);

fn open(a: &Args) -> anyhow::Result<Opened> {
    if let Some(path) = &a.session {
        let session = Session::load(path)?;
        if session.robots.is_empty() {
            bail!("{}: no robots to debug", path.display());
        }
        let ssl = session
            .overhead
            .iter()
            .any(|e| matches!(e.source, SessionSource::Ssl(_)));
        for e in session.overhead.iter().filter(|_| !ssl) {
            recorded(&e.source, &format!("overhead camera {}", e.id))?;
        }
        super::wmd_inputs::say_unused_session_keys(&session, a.output.is_some(), false);
        let robots = session
            .robots
            .iter()
            .map(|r| {
                let key = RobotKey {
                    team: r.team,
                    identity: r.robot_id,
                };
                Ok((recorded(&r.source, &format!("robot {key}"))?, Some(key)))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        if ssl {
            let field = session.field.load()?;
            return Ok((field, Vec::new(), robots, false));
        }
        let (field, cameras) = open_cameras(&session)?;
        return Ok((field, cameras, robots, false));
    }
    let Some(overhead) = &a.overhead else {
        bail!("--overhead names the overhead camera (or give --session)");
    };
    let source = |p: &PathBuf, what: &str| recorded(&SessionSource::parse_arg(p), what);
    let robots = a
        .robot
        .iter()
        .map(|p| Ok((source(p, "robot")?, None)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let field = load_field(a.field.as_deref())?;
    let overhead_source = SessionSource::parse_arg(overhead);
    let Some(pipeline) = super::wmd_inputs::overhead_pipeline(a, &overhead_source, &field)? else {
        // SSL-Vision: its log's frames are read by the caller.
        return Ok((field, Vec::new(), robots, true));
    };
    let overhead = recorded(&overhead_source, "overhead")?;
    let reader = crate::streams::StreamReader::open_camera(&overhead, a.camera.get())?;
    let camera = FieldCamera {
        id: SslCameraId(0),
        pipeline,
        reader,
        name: crate::frame::display_name(&overhead),
    };
    Ok((field, vec![camera], robots, true))
}

/// One field frame's `--json` line.
pub(super) fn line_json(
    frame: &FieldFrame,
    results: &[Comparison],
    jumps: &[bool],
) -> anyhow::Result<Value> {
    let mut line = match &frame.single {
        Some(d) => {
            let mut v = serde_json::to_value(overhead_json(String::new(), d, 0.0))?;
            if let Some(o) = v.as_object_mut() {
                o.remove("frame");
                o.remove("overhead_us");
            }
            v
        }
        None => {
            super::detect_field::field_line_value(frame.time_ns, &frame.picture, &frame.cameras)?
        }
    };
    line["time_ns"] = json!(frame.time_ns);
    line["world_models"] = results
        .iter()
        .zip(jumps)
        .map(|(c, jump)| {
            json!({
                "team": c.robot.team.name(),
                "id": c.robot.identity.value(),
                "matched": c.matched,
                "overhead_robot": c.overhead_robot.map(|k| json!({"team": k.team.name(), "id": k.identity.value()})),
                "position_error_cm": c.position_error_cm,
                "heading_error_deg": c.heading_error_deg,
                "ball_error_cm": c.ball_error_cm,
                "measurements": c.measurements,
                "jump": jump,
            })
        })
        .collect();
    Ok(line)
}

fn offset_text(o: &ClockOffset) -> String {
    let start = match o.start {
        crate::wmd::clock::OffsetStart::SameClock => "searched from 0",
        crate::wmd::clock::OffsetStart::FirstMessages => "searched from the first messages",
        crate::wmd::clock::OffsetStart::Arrival => {
            "measured on arrival: this machine's clock − the robot's, latency included; live \
             world models are paired by arrival"
        }
    };
    let err = o
        .median_error_cm
        .map_or_else(|| "–".to_owned(), |e| format!("{e:.1} cm"));
    format!(
        "{:+.3} s ({start}; {} pairs, median position error {err})",
        o.offset_ns as f64 * 1e-9,
        o.pairs
    )
}

fn write_table(
    out: &mut impl Write,
    summaries: &[RobotSummary],
    offsets: &[(RobotKey, ClockOffset)],
) -> anyhow::Result<()> {
    let spread = |s: &Option<Spread>| {
        s.map_or_else(
            || "–".to_owned(),
            |s| format!("{:.1}/{:.1}", s.median, s.p95),
        )
    };
    writeln!(
        out,
        "{:<10} {:>6} {:>6} {:>8} {:>9} {:>13} {:>13} {:>13} {:>13} {:>13} {:>6} {:>9}  clock offset",
        "robot",
        "models",
        "marker",
        "position",
        "unmatched",
        "position cm",
        "heading °",
        "ball cm",
        "distance cm",
        "bearing °",
        "jumps",
        "until s"
    )?;
    for s in summaries {
        let offset = offsets
            .iter()
            .find(|o| o.0 == s.robot)
            .map(|o| offset_text(&o.1))
            .unwrap_or_default();
        writeln!(
            out,
            "{:<10} {:>6} {:>6} {:>8} {:>9} {:>13} {:>13} {:>13} {:>13} {:>13} {:>6} {:>9.3}  {offset}",
            s.robot.to_string(),
            s.world_models,
            s.by_marker,
            s.by_position,
            s.unmatched,
            spread(&s.position_cm),
            spread(&s.heading_deg),
            spread(&s.ball_cm),
            spread(&s.distance_cm),
            spread(&s.bearing_deg),
            s.jumps_ns.len(),
            s.last_ns as f64 * 1e-9,
        )?;
    }
    writeln!(
        out,
        "(median/p95 of the absolute errors; jumps: frames whose error jumped)"
    )?;
    Ok(())
}
