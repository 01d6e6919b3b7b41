//! `eotn eval` on overhead streams: the overhead recogniser against the truth (ball and robot
//! position errors, identity and heading accuracy) and each robot's world model against the
//! overhead truth and the overhead detections. The truth is the stream's own (a simulated
//! stream's `/ground_truth`), or ssl-vision's detections of the same field (`--truth-ssl`: a
//! league log or a live address), paired with the stream's frames by capture time.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};

use super::inputs::load_lut_arg;
use super::overhead::{load_field, params_for};
use crate::eval::overhead::{
    OverheadEvalParams, OverheadEvalReport, evaluate_overhead_frame, evaluate_world_model,
};
use crate::eval::{Percentiles, percentile_text};
use crate::model::truth::{GroundTruth, OverheadTruth};
use crate::overhead::OverheadPipeline;
use crate::ssl_vision::truth::{FrameIndex, overhead_truth};
use crate::streams::StreamReader;

/// Whether the first frame of a stream carries overhead ground truth.
#[must_use]
pub fn is_overhead_stream(path: &Path) -> bool {
    StreamReader::open(path)
        .ok()
        .filter(|r| !r.is_empty())
        .and_then(|mut r| r.read(0).ok())
        .and_then(|rec| rec.ground_truth)
        .and_then(|t| serde_json::from_value::<GroundTruth>(t).ok())
        .is_some_and(|t| matches!(t, GroundTruth::Overhead(_)))
}

/// Where each frame's truth comes from.
pub enum TruthSource {
    /// The stream's own `/ground_truth` (a simulated stream).
    Stream,
    /// SSL-Vision detection frames (`--truth-ssl`: a league log or a live address), paired with
    /// the stream's frames by nearest capture time within half a frame period.
    Ssl {
        /// Every camera's frames by capture time.
        index: FrameIndex,
        /// Where they came from, for the report.
        name: String,
    },
}

/// Runs the overhead evaluation of `eotn eval`. Without a calibration each stream is read
/// through its own true camera (a perfect calibration), which the output says.
///
/// # Errors
/// Unreadable inputs, naming the file; no overhead frame at all.
pub fn run(
    streams: &[PathBuf],
    camera: Option<&str>,
    lut: &Path,
    calibration: Option<&Path>,
    field: Option<&Path>,
    truth: &TruthSource,
    json: bool,
) -> anyhow::Result<()> {
    let lut = load_lut_arg(lut)?;
    let field = load_field(field)?;
    let cal = calibration
        .map(super::overhead::load_usable_calibration)
        .transpose()?;
    let mut c = Collected::default();
    for path in streams {
        let mut reader = StreamReader::open_camera(path, camera)?;
        let name = crate::frame::display_name(path);
        let times: Vec<u64> = (0..reader.len())
            .filter_map(|i| reader.time_ns(i))
            .collect();
        let period_ns = crate::wmd::clock::frame_period_ns(&times);
        let mut pipeline: Option<OverheadPipeline> = None;
        let bar = super::inputs::progress(reader.len(), "eval overhead");
        for i in 0..reader.len() {
            bar.inc(1);
            let record = match reader.read(i) {
                Ok(r) => r,
                Err(e) => {
                    c.skipped.push(format!("{name}#{i}: {e}"));
                    continue;
                }
            };
            let own = stream_truth(&record);
            let Some(camera) = cal.as_ref().map(|c| c.camera).or_else(|| {
                pipeline
                    .as_ref()
                    .map(|p| *p.camera())
                    .or_else(|| own.as_ref().ok().map(|t| t.camera))
            }) else {
                bail!("{name}: no --calibration and no overhead truth to take the camera from");
            };
            let truth = match truth {
                TruthSource::Stream => own,
                TruthSource::Ssl { index, .. } => {
                    ssl_truth(index, record.time_ns, period_ns, camera, &field, &mut c)
                }
            };
            let truth = match truth {
                Ok(t) => t,
                Err(why) => {
                    c.skipped.push(format!("{name}#{i}: {why}"));
                    continue;
                }
            };
            if let Some(cal) = &cal {
                let (w, h) = (record.frame.width(), record.frame.height());
                c.sizes.check(&cal.camera, &format!("{name}#{i}"), w, h)?;
            }
            let p = pipeline.get_or_insert_with(|| {
                OverheadPipeline::new(lut.clone(), camera, params_for(&field))
            });
            let detections = p.process(&record.frame).clone();
            c.add_frame(&name, i, &record, &detections, &truth);
        }
        bar.finish_and_clear();
    }
    report(&c, calibration, truth, json)
}

/// Frames' comparisons and what was skipped, over every stream.
#[derive(Default)]
struct Collected {
    frames: Vec<crate::eval::overhead::OverheadFrameEval>,
    models: Vec<crate::eval::overhead::WorldModelFrameEval>,
    skipped: Vec<String>,
    sizes: super::overhead::SizeCheck,
    /// SSL robots left out of the truth (no id 0–15 or no heading).
    ssl_robots_left_out: usize,
}

impl Collected {
    fn add_frame(
        &mut self,
        name: &str,
        i: usize,
        record: &crate::streams::FrameRecord,
        detections: &crate::overhead::OverheadDetections,
        truth: &OverheadTruth,
    ) {
        let ep = OverheadEvalParams::default();
        self.frames.push(evaluate_overhead_frame(
            self.frames.len(),
            detections,
            truth,
            &ep,
        ));
        for (topic, value) in &record.extra {
            if !crate::model::world_model::is_world_model_topic(topic) {
                continue;
            }
            match crate::model::world_model::from_value(value) {
                Ok(m) => self
                    .models
                    .extend(evaluate_world_model(&m, truth, Some(detections))),
                Err(e) => self.skipped.push(format!("{name}#{i} {topic}: {e}")),
            }
        }
    }
}

/// A record's own overhead truth, or why it has none.
fn stream_truth(record: &crate::streams::FrameRecord) -> Result<OverheadTruth, String> {
    match record
        .ground_truth
        .clone()
        .map(serde_json::from_value::<GroundTruth>)
    {
        Some(Ok(GroundTruth::Overhead(t))) => Ok(*t),
        Some(Ok(GroundTruth::Robot(_))) => Err("robot-camera frame".to_owned()),
        Some(Err(e)) => Err(format!("ground truth unreadable: {e}")),
        None => Err("no ground truth".to_owned()),
    }
}

/// The SSL truth at `time_ns`: each camera's frame within half of `period_ns`, merged.
fn ssl_truth(
    index: &FrameIndex,
    time_ns: u64,
    period_ns: u64,
    camera: crate::geometry::OverheadCamera,
    field: &crate::overhead::FieldDescription,
    c: &mut Collected,
) -> Result<OverheadTruth, String> {
    let near = index.near(time_ns, period_ns);
    if near.is_empty() {
        return Err(format!(
            "no SSL-Vision frame within half a frame period ({:.1} ms) of {:.3} s",
            period_ns as f64 / 2e6,
            time_ns as f64 * 1e-9
        ));
    }
    let (truth, left_out) =
        overhead_truth(&near, camera, field.plate_height_cm, time_ns as f64 * 1e-9);
    c.ssl_robots_left_out += left_out;
    Ok(truth)
}

/// The SSL-Vision frames of `--truth-ssl`: a league log file, or `udp://GROUP:PORT` listened to
/// until the packets stop (see [`listen_for_truth`]).
///
/// # Errors
/// A file that is not a league log (a B-Human log is named as one), a log without detection
/// frames, an address that cannot be listened on, no packet in time.
pub fn load_ssl_truth(source: &Path) -> anyhow::Result<TruthSource> {
    let text = source.to_string_lossy().into_owned();
    let frames = if crate::ssl_vision::listener::is_udp_url(&text) {
        listen_for_truth(&text)?
    } else {
        let log = crate::ssl_vision::log::read_log_file(source)
            .with_context(|| source.display().to_string())?;
        eprintln!("{}: {}", source.display(), log.summary());
        log.frames.into_iter().map(|f| f.frame).collect()
    };
    let index = FrameIndex::new(frames);
    if index.is_empty() {
        bail!("{text}: no SSL-Vision detection frame with a capture time");
    }
    Ok(TruthSource::Ssl { index, name: text })
}

/// How long `--truth-ssl udp://…` waits for the first packet.
const FIRST_PACKET_WAIT: Duration = Duration::from_secs(30);
/// How long without a packet ends the listening.
const QUIET_END: Duration = Duration::from_secs(2);

/// Detection frames received on `url` until [`QUIET_END`] passes without one (after the first,
/// which may take up to [`FIRST_PACKET_WAIT`]); packets that do not decode are counted and
/// said once.
fn listen_for_truth(url: &str) -> anyhow::Result<Vec<crate::ssl_vision::CameraFrame>> {
    use crate::ssl_vision::listener::{Listener, Received};
    let listener = Listener::start(url)?;
    eprintln!("{url}: listening for SSL-Vision packets");
    let (mut frames, mut bad) = (Vec::new(), 0usize);
    let started = Instant::now();
    let mut last = None::<Instant>;
    loop {
        let quiet = last.map_or(started.elapsed() >= FIRST_PACKET_WAIT, |t| {
            t.elapsed() >= QUIET_END
        });
        if quiet {
            break;
        }
        match listener.next_timeout(Duration::from_millis(100)) {
            Some(Received::Packet { packet, .. }) => {
                last = Some(Instant::now());
                if let Some(d) = &packet.detection {
                    frames.push(crate::ssl_vision::CameraFrame::from_message(d));
                }
            }
            Some(Received::Bad { from, why }) => {
                if bad == 0 {
                    log::warn!(
                        "{url}: a packet from {from} is not SSL-Vision: {why} (skipped; said once)"
                    );
                }
                bad += 1;
            }
            None => {}
        }
    }
    if frames.is_empty() {
        bail!(
            "{url}: no SSL-Vision detection frame arrived within {} s",
            FIRST_PACKET_WAIT.as_secs()
        );
    }
    eprintln!(
        "{url}: {} detection frames received{}{}",
        frames.len(),
        if bad > 0 {
            format!(", {bad} packets not SSL-Vision")
        } else {
            String::new()
        },
        match listener.dropped() {
            0 => String::new(),
            n => format!(", {n} dropped (eotn fell behind)"),
        }
    );
    Ok(frames)
}

fn report(
    c: &Collected,
    calibration: Option<&Path>,
    truth: &TruthSource,
    json: bool,
) -> anyhow::Result<()> {
    if c.frames.is_empty() {
        match truth {
            TruthSource::Stream => {
                bail!("no frame with overhead ground truth in the given streams")
            }
            TruthSource::Ssl { name, .. } => bail!(
                "no frame of the streams has an SSL-Vision frame of {name} within half a frame period (first skipped: {})",
                c.skipped.first().map_or("none", String::as_str)
            ),
        }
    }
    let report = OverheadEvalReport::from_frames(&c.frames, &c.models);
    let calibration_name = calibration.map_or_else(
        || "the streams' true cameras (no --calibration)".to_owned(),
        |p| p.display().to_string(),
    );
    let truth_name = match truth {
        TruthSource::Stream => "the streams' ground truth".to_owned(),
        TruthSource::Ssl { name, .. } => format!("SSL-Vision {name}"),
    };
    if json {
        let out = serde_json::json!({
            "overhead": report,
            "calibration": calibration_name,
            "truth": truth_name,
            "ssl_robots_left_out": c.ssl_robots_left_out,
            "skipped": c.skipped,
        });
        println!("{}", serde_json::to_string(&out).context("report")?);
    } else {
        println!("truth                  {truth_name}");
        if c.ssl_robots_left_out > 0 {
            println!(
                "                       {} SSL robots left out (no id 0-15 or no orientation)",
                c.ssl_robots_left_out
            );
        }
        print_report(&report, &calibration_name, &c.skipped);
    }
    Ok(())
}

/// Median, p90 and p95 of a summary with its unit and sample size, or "—" without a sample.
fn three(p: Option<&Percentiles>, unit: &str) -> String {
    p.map_or_else(
        || "— (n=0)".to_owned(),
        |p| {
            format!(
                "median {:.2}{unit} p90 {:.2}{unit} p95 {:.2}{unit} (n={})",
                p.p50, p.p90, p.p95, p.n
            )
        },
    )
}

fn print_report(r: &OverheadEvalReport, calibration: &str, skipped: &[String]) {
    let pct = |n: usize, d: usize| {
        if d == 0 {
            "—".to_owned()
        } else {
            format!("{:.1}%", 100.0 * n as f64 / d as f64)
        }
    };
    println!(
        "overhead frames        {} (calibration: {calibration})",
        r.frames
    );
    println!(
        "ball found             {}/{} = {}   false {}",
        r.ball_found,
        r.ball_eligible,
        pct(r.ball_found, r.ball_eligible),
        r.ball_false
    );
    println!(
        "ball position error    {}",
        three(r.ball_error_cm.as_ref(), " cm")
    );
    println!(
        "robots found           {}/{} fully visible markers = {}   false {}",
        r.robots_found,
        r.robots_eligible,
        pct(r.robots_found, r.robots_eligible),
        r.robots_false
    );
    println!(
        "identity right         {}/{} = {}",
        r.identity_right,
        r.robots_eligible,
        pct(r.identity_right, r.robots_eligible)
    );
    println!(
        "robot position error   {}",
        three(r.robot_error_cm.as_ref(), " cm")
    );
    println!(
        "heading error          {}",
        three(r.heading_error_deg.as_ref(), "°")
    );
    for (t, read) in &r.wrong_identities {
        println!("  wrong identity: {t} read as {read}");
    }
    for m in &r.world_models {
        let q = |p: &Option<Percentiles>, pick: fn(&Percentiles) -> f64, unit: &str| {
            percentile_text(p.as_ref(), pick, 1.0, 1, unit)
        };
        println!(
            "world model robot{:<2}   vs truth: self median {} p95 {}, heading {}, ball {}",
            m.robot_id,
            q(&m.self_error_cm, |p| p.p50, " cm"),
            q(&m.self_error_cm, |p| p.p95, " cm"),
            q(&m.heading_error_deg, |p| p.p50, "°"),
            q(&m.ball_error_cm, |p| p.p50, " cm"),
        );
        if let Some(vs) = &m.self_error_vs_overhead_cm {
            println!(
                "                       vs overhead: self median {:.1} cm p95 {:.1} (n={}), \
                 heading {}, ball {}",
                vs.p50,
                vs.p95,
                vs.n,
                q(&m.heading_error_vs_overhead_deg, |p| p.p50, "°"),
                m.ball_error_vs_overhead_cm
                    .map_or_else(|| "not seen".to_owned(), |b| format!("{:.1} cm", b.p50))
            );
        } else {
            println!("                       vs overhead: not seen overhead");
        }
    }
    if !skipped.is_empty() {
        println!(
            "skipped                {} (first: {})",
            skipped.len(),
            skipped[0]
        );
    }
}

/// `eotn eval OVERHEAD… --truth-ssl LOG|udp://…`: the overhead streams against ssl-vision's
/// detections.
fn run_truth_ssl(args: &super::eval::Args, source: &Path, lut_path: &Path) -> anyhow::Result<()> {
    super::overhead::refuse_robot_streams(&robot_camera_streams(args)?)
        .context("--truth-ssl is the truth of overhead streams")?;
    let truth = load_ssl_truth(source)?;
    run(
        &args.streams,
        args.camera.get(),
        lut_path,
        args.calibration.as_deref(),
        args.field.as_deref(),
        &truth,
        args.json,
    )
}

/// The streams among `args.streams` whose source kind is not an overhead camera's.
fn robot_camera_streams(args: &super::eval::Args) -> anyhow::Result<Vec<PathBuf>> {
    let inputs =
        super::inputs::FrameInputs::open_camera(&args.streams, Some(0..1), args.camera.get())?;
    Ok(inputs.robot_streams().to_vec())
}

/// Overhead streams, against their own truth or ssl-vision's (`--truth-ssl`), are evaluated by
/// `eval_overhead`: `Ok(true)` when they were, `Ok(false)` when the streams are robot cameras'.
pub(super) fn run_from_eval(args: &super::eval::Args, lut_path: &Path) -> anyhow::Result<bool> {
    if let Some(source) = &args.truth_ssl {
        run_truth_ssl(args, source, lut_path)?;
        return Ok(true);
    }
    let overhead = args
        .streams
        .iter()
        .filter(|p| is_overhead_stream(p))
        .count();
    if overhead == args.streams.len() {
        run(
            &args.streams,
            args.camera.get(),
            lut_path,
            args.calibration.as_deref(),
            args.field.as_deref(),
            &TruthSource::Stream,
            args.json,
        )?;
        return Ok(true);
    } else if overhead > 0 {
        bail!("give overhead streams and robot-camera streams to separate `eotn eval` runs");
    }
    Ok(false)
}
