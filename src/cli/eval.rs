//! `eotn eval`: recognition against the ground truth of synthetic streams — detection and false
//! identification rates, distance, bearing, post and gap errors, the frames that missed — and
//! two tables or parameter sets side by side; `--calibrate-goals` fits the goal-distance
//! relation to the truth and writes it as recognition parameters. `--labels` scores a real
//! stream against hand labels instead (`eval_labels.rs`).

use std::path::PathBuf;

use anyhow::{Context, bail};
use serde::Serialize;

use super::detect::{load_params, params_or_camera_s};
use super::inputs::load_lut_arg;
use super::pct;
use crate::eval::skew::{self, SkewReport};
use crate::eval::{
    EvalParams, EvalReport, FrameEval, Percentiles, evaluate_frame, fit_inverse_size,
    fit_inverse_size_multiplier, percentile_text, sample_size,
};
use crate::model::truth::{GroundTruth, RobotViewTruth};
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::patterns::PatternMemory;
use crate::recognition::{Recognition, RecognitionParams};
use crate::streams::StreamReader;

/// Arguments of `eotn eval`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Streams with a `/ground_truth` channel (from `eotn sim`).
    #[arg(required = true)]
    pub streams: Vec<PathBuf>,
    /// Lookup table; default: the table the first recording names for the camera read (its
    /// `REC.cameras.json` sidecar, else its metadata).
    #[arg(long)]
    pub lut: Option<PathBuf>,
    /// Recognition parameters JSON (default: the set the first recording names for the camera read, else the defaults).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// A second table to compare on the same frames.
    #[arg(long)]
    pub compare_lut: Option<PathBuf>,
    /// A second parameter set to compare on the same frames.
    #[arg(long)]
    pub compare_params: Option<PathBuf>,
    /// Frames whose pan speed is at least this (rad/s) also run without skew correction, to
    /// measure what the correction gains.
    #[arg(long, default_value_t = 1.5, value_parser = super::values::number_in(0.0, 100.0))]
    pub fast_pan_rad_per_s: f64,
    /// Fit distance = multiplier / height + offset for goals to the truth and write the result as
    /// a recognition-parameter JSON file.
    #[arg(long, value_name = super::paths::OUT)]
    pub calibrate_goals: Option<PathBuf>,
    /// Multiplier and offset are both fitted only when the tallest goal is at least this many
    /// times the shortest (else the multiplier alone).
    #[arg(long, default_value_t = 1.3, value_parser = super::values::number_in(1.0, 100.0))]
    pub calibration_min_spread: f64,
    /// Draw the evaluation as PNG charts into this folder (measured against true distance,
    /// error histograms, found rates per distance band, post errors).
    #[arg(long, value_name = super::paths::OUT_DIR)]
    pub plots: Option<PathBuf>,
    /// Score real frames against hand labels instead of ground truth: eotn's labels JSON (see
    /// the README's "Hand labels"; one stream: ball found/missed/false, centre and radius
    /// errors, goals, goal distances), or boxes as teams keep them — a YOLO folder, a COCO
    /// JSON file or a Pascal VOC folder, told apart by content — scored on the ball (frame
    /// recall, precision, centre error, by ball size; docs/recognition.md).
    #[arg(long)]
    pub labels: Option<PathBuf>,
    /// YOLO labels without `classes.txt`: the class names in order of their numbers
    /// (`robot,ball,goal`).
    #[arg(long, value_name = "NAMES")]
    pub class_names: Option<String>,
    /// Box labels: which eotn object each class name is, `name=object,…` (objects `ball`,
    /// `robot`, `goal`, `other`; `ball`, `robot` and `goal` are themselves by default).
    #[arg(long, value_name = "MAP")]
    pub classes: Option<String>,
    /// Labels: score every frame, the tuning frames, or the held-out frames (those whose
    /// number ends in 7, 8 or 9: a file's number, or a stream frame's index).
    #[arg(long, value_enum, default_value_t = crate::eval::label_sets::Split::All)]
    pub split: crate::eval::label_sets::Split,
    /// A places file (`eotn patterns learn`): also score the pink markers' identification
    /// against the truth's markers (correct, wrong, missed; distance errors).
    #[arg(long)]
    pub patterns: Option<PathBuf>,
    /// Overhead streams: the calibration to read them through (`eotn overhead calibrate`);
    /// without it each stream's true camera is used.
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    /// Overhead streams: the field description (ball radius, plate height).
    #[arg(long)]
    pub field: Option<PathBuf>,
    /// Overhead streams: take ssl-vision's detections of the same field as the truth, from a
    /// league log file (`SSL_LOG_FILE`, plain or `.gz`) or live from `udp://GROUP:PORT`
    /// (listened to until the packets stop): each stream frame is paired with every camera's
    /// frame of nearest capture time within half a frame period, and scored as against the
    /// simulator's truth (ball and robot position and heading errors, identities, misses,
    /// false robots).
    #[arg(long, value_name = "LOG_OR_UDP")]
    pub truth_ssl: Option<PathBuf>,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Which camera of the recordings.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
}

/// A frame whose results differ between the two configurations.
#[derive(Debug, Clone, Serialize)]
pub struct Difference {
    /// Stream file name.
    pub stream: String,
    /// Frame index.
    pub frame: usize,
    /// What differs.
    pub what: String,
}

/// Everything `eotn eval` reports.
#[derive(Debug, Clone, Serialize)]
pub struct EvalOutput {
    /// Against the truth, first configuration.
    pub report: EvalReport,
    /// Skew correction on versus off on fast pans.
    pub skew: Option<SkewReport>,
    /// Against the truth, second configuration.
    pub compare: Option<EvalReport>,
    /// Frames where the two configurations disagree.
    pub differences: Vec<Difference>,
    /// Fitted goal distance relation (multiplier cm·px, offset cm), if asked for.
    pub goal_calibration: Option<(f64, f64)>,
    /// Charts written by `--plots` (and the calibration plot is beside the calibration file).
    pub plots: Vec<PathBuf>,
    /// Frames skipped, with the reason.
    pub skipped: Vec<String>,
    /// Coloured patterns against the truth's markers, with `--patterns`.
    pub patterns: Option<crate::eval::patterns::PatternEvalReport>,
}

fn differ(a: &Recognition, b: &Recognition) -> Option<String> {
    let mut what = Vec::new();
    match (&a.ball.ball, &b.ball.ball) {
        (Some(x), Some(y)) if (x.center_x - y.center_x).hypot(x.center_y - y.center_y) > 1.0 => {
            what.push("ball moved".to_owned());
        }
        (Some(_), None) => what.push("ball lost".to_owned()),
        (None, Some(_)) => what.push("ball gained".to_owned()),
        _ => {}
    }
    let goals = |r: &Recognition| r.goals.goals().map(|g| g.colour.code()).collect::<Vec<_>>();
    if goals(a) != goals(b) {
        what.push(format!("goals {:?} → {:?}", goals(a), goals(b)));
    }
    (!what.is_empty()).then(|| what.join(", "))
}

/// The pipelines one run compares: the given configuration, the same without skew correction
/// (run on fast pans only), and the `--compare-*` one.
struct Pipelines {
    main: Pipeline,
    no_skew: Pipeline,
    other: Option<Pipeline>,
}

impl Pipelines {
    fn new(
        args: &Args,
        lut: crate::lut::LookupTable,
        rp: RecognitionParams,
        places: Option<&PatternMemory>,
    ) -> anyhow::Result<Self> {
        let params = PipelineParams {
            recognition: rp,
            ..PipelineParams::default()
        };
        let mut main = Pipeline::new(lut.clone(), params);
        main.set_pattern_memory(places.cloned());
        let no_skew = Pipeline::new(
            lut.clone(),
            PipelineParams {
                recognition: RecognitionParams {
                    ball: crate::recognition::BallParams {
                        skew_correction: false,
                        ..rp.ball
                    },
                    ..rp
                },
                ..params
            },
        );
        let other = if args.compare_lut.is_some() || args.compare_params.is_some() {
            let l = match &args.compare_lut {
                Some(p) => load_lut_arg(p)?,
                None => lut,
            };
            let p = match &args.compare_params {
                Some(p) => load_params(Some(p))?,
                None => rp,
            };
            Some(Pipeline::new(
                l,
                PipelineParams {
                    recognition: p,
                    ..params
                },
            ))
        } else {
            None
        };
        Ok(Self {
            main,
            no_skew,
            other,
        })
    }
}

/// What the frames of every stream add up to.
#[derive(Default)]
struct Collected {
    frames_a: Vec<FrameEval>,
    frames_b: Vec<FrameEval>,
    skew_frames: usize,
    skew_samples: Vec<skew::SkewSample>,
    differences: Vec<Difference>,
    skipped: Vec<String>,
    /// `(height px, true distance cm)` of uncut goals, for `--calibrate-goals`.
    goal_samples: Vec<(f64, f64)>,
    pattern_frames: Vec<crate::eval::patterns::PatternFrameEval>,
    place_markers: Vec<(usize, Option<usize>)>,
}

/// Frame `i` of `reader` with its robot-camera truth, or `None` with the reason in `skipped`.
fn frame_with_truth(
    reader: &mut StreamReader,
    name: &str,
    i: usize,
    skipped: &mut Vec<String>,
) -> Option<(crate::streams::FrameRecord, Box<RobotViewTruth>)> {
    let record = match reader.read(i) {
        Ok(r) => r,
        Err(e) => {
            skipped.push(format!("{name}#{i}: {e}"));
            return None;
        }
    };
    let Some(truth) = record.ground_truth.clone() else {
        skipped.push(format!("{name}#{i}: no ground truth"));
        return None;
    };
    match serde_json::from_value::<GroundTruth>(truth) {
        Ok(GroundTruth::Robot(t)) => Some((record, t)),
        Ok(GroundTruth::Overhead(_)) => {
            skipped.push(format!("{name}#{i}: overhead frame"));
            None
        }
        Err(e) => {
            skipped.push(format!("{name}#{i}: ground truth unreadable: {e}"));
            None
        }
    }
}

impl Collected {
    /// Evaluates one frame with every pipeline (`global`: its index over all streams).
    #[expect(
        clippy::too_many_arguments,
        reason = "one frame's context, passed once per frame"
    )]
    fn add_frame(
        &mut self,
        pipelines: &mut Pipelines,
        places: Option<&PatternMemory>,
        args: &Args,
        rp: &RecognitionParams,
        (name, i, global): (&str, usize, usize),
        record: &crate::streams::FrameRecord,
        truth: &RobotViewTruth,
    ) {
        let ep = EvalParams::default();
        let (w, h) = (record.frame.width() as f64, record.frame.height() as f64);
        let sensors = record.sensors.as_ref();
        let ra = pipelines
            .main
            .process(&record.frame, sensors)
            .recognition
            .clone();
        if let Some(m) = places {
            let pattern_params = crate::eval::patterns::PatternEvalParams::default();
            // Learnt places are matched to the markers of the first frame that lists any.
            if !truth.markers.is_empty() && self.place_markers.iter().all(|(_, k)| k.is_none()) {
                self.place_markers =
                    crate::eval::patterns::place_markers(m, &truth.markers, &pattern_params);
            }
            self.pattern_frames
                .push(crate::eval::patterns::evaluate_patterns(
                    global,
                    &ra,
                    truth,
                    &self.place_markers,
                    &pattern_params,
                ));
        }
        for g in ra.goals.goals() {
            if let Some(tg) = truth
                .goals
                .iter()
                .find(|t| crate::eval::goal_class(t.colour) == g.colour)
                && !g.cut_off.top
                && !g.cut_off.bottom
                && !g.distance_from_ir
            {
                self.goal_samples
                    .push((g.height_px, tg.relative.camera_distance_cm));
            }
        }
        let fast = sensors
            .and_then(crate::sensors::SensorReadings::pan_velocity_rad_per_s)
            .is_some_and(|v| v.abs() >= args.fast_pan_rad_per_s);
        if fast {
            self.skew_frames += 1;
            let rn = &pipelines
                .no_skew
                .process(&record.frame, sensors)
                .recognition;
            let camera = rp.camera_for(record.frame.width(), record.frame.height());
            self.skew_samples
                .extend(skew::compare_ball(&ra, rn, truth, &camera, 2.0));
        }
        if let Some(o) = pipelines.other.as_mut() {
            let rb = o.process(&record.frame, sensors).recognition.clone();
            self.frames_b
                .push(evaluate_frame(global, &rb, truth, w, h, &ep));
            if let Some(what) = differ(&ra, &rb) {
                self.differences.push(Difference {
                    stream: name.to_owned(),
                    frame: i,
                    what,
                });
            }
        }
        self.frames_a
            .push(evaluate_frame(global, &ra, truth, w, h, &ep));
    }
}

/// Fits goal distance = multiplier / height + offset to `samples` (`(height px, distance cm)`),
/// writes it over `rp` as a parameter file at `out` and draws the fit beside it.
fn calibrate_goals(
    out: &std::path::Path,
    samples: &[(f64, f64)],
    rp: &RecognitionParams,
    min_spread: f64,
) -> anyhow::Result<(f64, f64)> {
    let (lo_h, hi_h) = samples.iter().fold((f64::INFINITY, 0.0_f64), |(a, b), s| {
        (a.min(s.0), b.max(s.0))
    });
    // Heights within a narrow band (one distance) cannot separate multiplier and offset:
    // then only the multiplier is fitted and the offset kept.
    let (m, o) = if hi_h >= min_spread * lo_h {
        let Some((m, o)) = fit_inverse_size(samples) else {
            bail!("too few uncut goals ({}) to calibrate", samples.len());
        };
        (m, o)
    } else {
        let o = rp.goals.distance_offset_cm;
        let Some(m) = fit_inverse_size_multiplier(samples, o) else {
            bail!("no uncut goal to calibrate from");
        };
        eprintln!(
            "goal heights span only {lo_h:.1}–{hi_h:.1} px: fitting the multiplier only, \
             offset kept at {o:.1} cm"
        );
        (m, o)
    };
    if !(m > 0.0 && m.is_finite() && o.is_finite()) {
        let (lo, hi) = samples.iter().fold((f64::INFINITY, 0.0_f64), |(a, b), s| {
            (a.min(s.1), b.max(s.1))
        });
        bail!(
            "goal calibration gives distance = {m:.1} / height + {o:.1} cm from {} goals \
             {lo:.0}–{hi:.0} cm away: not a size → distance relation; give streams with \
             goals over a wider range of distances",
            samples.len()
        );
    }
    let mut p = *rp;
    p.goals.distance_multiplier = m;
    p.goals.distance_offset_cm = o;
    let json = serde_json::to_vec_pretty(&p)?;
    // The plot goes beside the calibration (not beside a device or FIFO).
    let plot = crate::atomic_file::beside_output(out, "png");
    crate::atomic_file::write_atomic(out, &json)
        .with_context(|| format!("{}: cannot write", out.display()))?;
    if let Some(plot) = plot {
        crate::eval::plots::write_calibration_plot(
            &plot,
            samples,
            (m, o),
            (rp.goals.distance_multiplier, rp.goals.distance_offset_cm),
        )
        .context("calibration plot")?;
    }
    Ok((m, o))
}

/// Runs `eotn eval`.
///
/// # Errors
/// Unreadable inputs or streams without ground truth, naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let lut_path =
        super::inputs::table_or_camera_s(args.lut.as_deref(), &args.streams, args.camera.get())?;
    if super::eval_overhead::run_from_eval(args, &lut_path)? {
        return Ok(());
    }
    if args.calibration.is_some() || args.field.is_some() {
        super::overhead::refuse_robot_streams(&args.streams)
            .context("--calibration and --field are for overhead streams")?;
    }
    let lut = load_lut_arg(&lut_path)?;
    let rp = params_or_camera_s(args.params.as_deref(), &args.streams, args.camera.get())?;
    if let Some(labels) = &args.labels {
        return run_labels(args, labels, lut, rp);
    }
    let places = args
        .patterns
        .as_deref()
        .map(PatternMemory::load)
        .transpose()?;
    let mut pipelines = Pipelines::new(args, lut, rp, places.as_ref())?;
    let mut c = Collected::default();
    let mut global = 0usize;
    for path in &args.streams {
        let mut reader = StreamReader::open_camera(path, args.camera.get())?;
        let name = crate::frame::display_name(path);
        let bar = super::inputs::progress(reader.len(), "eval");
        for i in 0..reader.len() {
            bar.inc(1);
            let Some((record, truth)) = frame_with_truth(&mut reader, &name, i, &mut c.skipped)
            else {
                continue;
            };
            let at = (name.as_str(), i, global);
            c.add_frame(
                &mut pipelines,
                places.as_ref(),
                args,
                &rp,
                at,
                &record,
                &truth,
            );
            global += 1;
        }
        bar.finish_and_clear();
    }
    if c.frames_a.is_empty() {
        bail!("no frame with robot-camera ground truth in the given streams");
    }
    let goal_calibration = args
        .calibrate_goals
        .as_deref()
        .map(|out| calibrate_goals(out, &c.goal_samples, &rp, args.calibration_min_spread))
        .transpose()?;
    let plots = match &args.plots {
        Some(dir) => crate::eval::plots::write_eval_plots(dir, &c.frames_a).context("plots")?,
        None => Vec::new(),
    };
    let output = EvalOutput {
        report: EvalReport::from_frames(&c.frames_a),
        skew: (c.skew_frames > 0).then(|| SkewReport::from_samples(c.skew_frames, &c.skew_samples)),
        compare: pipelines
            .other
            .is_some()
            .then(|| EvalReport::from_frames(&c.frames_b)),
        differences: c.differences,
        goal_calibration,
        plots,
        skipped: c.skipped,
        patterns: places.is_some().then(|| {
            crate::eval::patterns::PatternEvalReport::from_frames(
                &c.pattern_frames,
                c.place_markers,
            )
        }),
    };
    if args.json {
        println!("{}", serde_json::to_string(&output)?);
    } else {
        print_summary(&output);
    }
    Ok(())
}

/// `eotn eval --labels`: boxed labels as teams keep them (YOLO, COCO, VOC), or eotn's own
/// labels JSON of one stream.
fn run_labels(
    args: &Args,
    labels: &std::path::Path,
    lut: crate::lut::LookupTable,
    rp: RecognitionParams,
) -> anyhow::Result<()> {
    if !is_eotn_labels(labels) {
        let boxes = super::eval_boxes::BoxEvalArgs {
            images: &args.streams,
            labels,
            class_names: args.class_names.as_deref(),
            classes: args.classes.as_deref(),
            split: args.split,
            plots: args.plots.as_deref(),
            json: args.json,
        };
        return super::eval_boxes::run(&boxes, lut, rp);
    }
    let [stream] = args.streams.as_slice() else {
        bail!("--labels scores one stream, {} given", args.streams.len());
    };
    super::eval_labels::run(
        stream,
        args.camera.get(),
        labels,
        lut,
        rp,
        args.split,
        args.json,
    )
}

/// Whether `path` is eotn's own labels JSON (`"format": "eotn.labels"`), told by content; any
/// other file or folder is a YOLO, COCO or VOC set.
fn is_eotn_labels(path: &std::path::Path) -> bool {
    path.is_file()
        && crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SIDE_FILE_BYTES,
            "a labels file",
        )
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|v| {
            v.get("format").and_then(|f| f.as_str()) == Some(crate::eval::labels::LABELS_FORMAT)
        })
}

/// The human-readable summary: the ball, the skew study, goals, the frames that went wrong,
/// the comparison, what was written, the pink markers.
fn print_summary(o: &EvalOutput) {
    let r = &o.report;
    println!("frames                 {}", r.frames);
    print_ball_summary(r);
    if let Some(s) = &o.skew {
        print_skew_summary(s);
    }
    print_goal_summary(r);
    print_beacon_summary(r);
    print_frame_lists(r);
    if let Some(c) = &o.compare {
        println!(
            "compared: ball {}/{}, false {}, goals {}/{}; {} frame(s) differ",
            c.ball_found,
            c.ball_eligible,
            c.ball_false,
            c.goals_found,
            c.goals_eligible,
            o.differences.len()
        );
        for d in o.differences.iter().take(50) {
            println!("  {}#{}: {}", d.stream, d.frame, d.what);
        }
    }
    if let Some((m, off)) = o.goal_calibration {
        println!("goal distance          = {m:.1} / height_px + {off:.1} cm (written)");
    }
    if !o.plots.is_empty() {
        println!("plots                  {} written", o.plots.len());
    }
    if let Some(p) = &o.patterns {
        print_pattern_summary(p);
    }
    if !o.skipped.is_empty() {
        println!(
            "skipped {} frame(s), first: {}",
            o.skipped.len(),
            o.skipped[0]
        );
    }
}

/// The ball's lines of the summary.
fn print_ball_summary(r: &EvalReport) {
    println!(
        "ball found             {}/{} = {}   false {} = {} of frames",
        r.ball_found,
        r.ball_eligible,
        pct(r.ball_found_rate),
        r.ball_false,
        pct(r.ball_false_rate)
    );
    let share = |p: &Option<Percentiles>, pick: fn(&Percentiles) -> f64| {
        percentile_text(p.as_ref(), pick, 100.0, 1, "%")
    };
    println!(
        "ball distance error    median {} p90 {} (n={}); cut off: median {} (n={})",
        share(&r.ball_distance_error, |p| p.p50),
        share(&r.ball_distance_error, |p| p.p90),
        sample_size(r.ball_distance_error.as_ref()),
        share(&r.ball_distance_error_cut, |p| p.p50),
        sample_size(r.ball_distance_error_cut.as_ref())
    );
    let signed =
        |b: Option<f64>| b.map_or_else(|| "-".to_owned(), |v| format!("{:+.1}%", v * 100.0));
    println!(
        "ball distance bias     median signed {} (measured − true); cut off: {}",
        signed(r.ball_distance_bias),
        signed(r.ball_distance_bias_cut)
    );
    println!(
        "ball bearing error     median {} p90 {}; radius error median {}",
        percentile_text(r.ball_bearing_error_deg.as_ref(), |p| p.p50, 1.0, 2, "°"),
        percentile_text(r.ball_bearing_error_deg.as_ref(), |p| p.p90, 1.0, 2, "°"),
        percentile_text(r.ball_radius_error_px.as_ref(), |p| p.p50, 1.0, 2, " px")
    );
}

/// The skew study's lines of the summary.
fn print_skew_summary(s: &SkewReport) {
    println!(
        "skew correction        {} fast-panning frames, {} with a ball on the true one in both runs",
        s.frames, s.compared
    );
    for (name, e) in [
        ("all balls", &s.all),
        ("seen from one side", &s.one_sided),
        ("whole outline", &s.whole),
    ] {
        let Some(n) = e.radius_with_px.map(|p| p.n) else {
            continue;
        };
        let px = |p: &Option<Percentiles>| percentile_text(p.as_ref(), |p| p.p50, 1.0, 2, " px");
        println!(
            "  {name:<20} radius error median {} with, {} without; centre {} with, {} \
             without (n={n})",
            px(&e.radius_with_px),
            px(&e.radius_without_px),
            px(&e.centre_with_px),
            px(&e.centre_without_px),
        );
    }
}

/// The goals', posts' and gaps' lines of the summary.
fn print_goal_summary(r: &EvalReport) {
    println!(
        "goals found            {}/{} = {}   false {}; distance error median {} (n={})",
        r.goals_found,
        r.goals_eligible,
        pct(r.goal_found_rate),
        r.goals_false,
        percentile_text(r.goal_distance_error.as_ref(), |p| p.p50, 100.0, 1, "%"),
        sample_size(r.goal_distance_error.as_ref())
    );
    println!(
        "posts                  median {}, within 2 px {} (n={})",
        percentile_text(r.post_error_px.as_ref(), |p| p.p50, 1.0, 2, " px"),
        pct(r.posts_within_2px),
        sample_size(r.post_error_px.as_ref())
    );
    println!(
        "gaps                   median {}, within 3 px {} (n={})",
        percentile_text(r.gap_error_px.as_ref(), |p| p.p50, 1.0, 2, " px"),
        pct(r.gaps_within_3px),
        sample_size(r.gap_error_px.as_ref())
    );
}

/// The beacons' lines of the summary.
fn print_beacon_summary(r: &EvalReport) {
    println!(
        "beacons found          {}/{} = {}, colours right {}   false {}",
        r.beacons_found,
        r.beacons_eligible,
        pct(r.beacon_found_rate),
        r.beacons_colours_right,
        r.beacons_false
    );
    let signed =
        |b: Option<f64>| b.map_or_else(|| "—".to_owned(), |v| format!("{:+.1}%", v * 100.0));
    println!(
        "beacon distance error  median {} p90 {} (n={}); signed median {}",
        percentile_text(r.beacon_distance_error.as_ref(), |p| p.p50, 100.0, 1, "%"),
        percentile_text(r.beacon_distance_error.as_ref(), |p| p.p90, 100.0, 1, "%"),
        sample_size(r.beacon_distance_error.as_ref()),
        signed(r.beacon_distance_bias)
    );
}

/// The frames where the ball or a goal was missed or false.
fn print_frame_lists(r: &EvalReport) {
    if !r.ball_misses.is_empty() {
        println!("ball missed in frames  {:?}", r.ball_misses);
    }
    if !r.ball_false_frames.is_empty() {
        println!("false ball in frames   {:?}", r.ball_false_frames);
    }
    if !r.goal_misses.is_empty() {
        println!("goal missed in frames  {:?}", r.goal_misses);
    }
    if !r.goal_false_frames.is_empty() {
        println!("false goal in frames   {:?}", r.goal_false_frames);
    }
    if !r.beacon_misses.is_empty() {
        println!("beacon missed, frames  {:?}", r.beacon_misses);
    }
    if !r.beacon_false_frames.is_empty() {
        println!("false beacon in frames {:?}", r.beacon_false_frames);
    }
}

/// The pink markers' lines of the summary.
fn print_pattern_summary(p: &crate::eval::patterns::PatternEvalReport) {
    println!(
        "pink markers           {}/{} identified correctly = {}, wrongly {}, not at all {}; \
         false identifications {}",
        p.correct,
        p.eligible,
        pct(p.correct_rate),
        p.wrong,
        p.missed,
        p.false_identifications
    );
    let share = |pick: fn(&Percentiles) -> f64| {
        percentile_text(p.distance_error.as_ref(), pick, 100.0, 1, "%")
    };
    println!(
        "marker distance error  median {} p90 {} p95 {} (n={}); signed median {}",
        share(|p| p.p50),
        share(|p| p.p90),
        share(|p| p.p95),
        sample_size(p.distance_error.as_ref()),
        p.distance_bias_cm
            .map_or_else(|| "-".to_owned(), |b| format!("{b:+.1} cm"))
    );
    let lost: Vec<usize> = p
        .places
        .iter()
        .filter(|(_, m)| m.is_none())
        .map(|(id, _)| *id)
        .collect();
    if !lost.is_empty() {
        println!("places near no marker  {lost:?}");
    }
    if !p.wrong_frames.is_empty() {
        println!("wrong place in frames  {:?}", p.wrong_frames);
    }
}
