//! `eotn eval` on overhead streams: the overhead recogniser against the truth (ball and robot
//! position errors, identity and heading accuracy) and each robot's world model against the
//! overhead truth and the overhead detections.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use super::inputs::load_lut_arg;
use super::overhead::{load_field, params_for};
use crate::eval::overhead::{
    OverheadEvalParams, OverheadEvalReport, evaluate_overhead_frame, evaluate_world_model,
};
use crate::eval::{Percentiles, percentile_text};
use crate::model::truth::GroundTruth;
use crate::overhead::OverheadPipeline;
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
    json: bool,
) -> anyhow::Result<()> {
    let lut = load_lut_arg(lut)?;
    let field = load_field(field)?;
    let cal = calibration
        .map(super::overhead::load_usable_calibration)
        .transpose()?;
    let mut sizes = super::overhead::SizeCheck::default();
    let ep = OverheadEvalParams::default();
    let (mut frames, mut models, mut skipped) = (Vec::new(), Vec::new(), Vec::<String>::new());
    let mut global = 0usize;
    for path in streams {
        let mut reader = StreamReader::open_camera(path, camera)?;
        let name = crate::frame::display_name(path);
        let mut pipeline: Option<OverheadPipeline> = None;
        let bar = super::inputs::progress(reader.len(), "eval overhead");
        for i in 0..reader.len() {
            bar.inc(1);
            let record = match reader.read(i) {
                Ok(r) => r,
                Err(e) => {
                    skipped.push(format!("{name}#{i}: {e}"));
                    continue;
                }
            };
            let truth = match record
                .ground_truth
                .map(serde_json::from_value::<GroundTruth>)
            {
                Some(Ok(GroundTruth::Overhead(t))) => t,
                Some(Ok(GroundTruth::Robot(_))) => {
                    skipped.push(format!("{name}#{i}: robot-camera frame"));
                    continue;
                }
                Some(Err(e)) => {
                    skipped.push(format!("{name}#{i}: ground truth unreadable: {e}"));
                    continue;
                }
                None => {
                    skipped.push(format!("{name}#{i}: no ground truth"));
                    continue;
                }
            };
            if let Some(c) = &cal {
                let (w, h) = (record.frame.width(), record.frame.height());
                sizes.check(&c.camera, &format!("{name}#{i}"), w, h)?;
            }
            let p = pipeline.get_or_insert_with(|| {
                let camera = cal.as_ref().map_or(truth.camera, |c| c.camera);
                OverheadPipeline::new(lut.clone(), camera, params_for(&field))
            });
            let detections = p.process(&record.frame).clone();
            frames.push(evaluate_overhead_frame(global, &detections, &truth, &ep));
            for (topic, value) in &record.extra {
                if !crate::model::world_model::is_world_model_topic(topic) {
                    continue;
                }
                match crate::model::world_model::from_value(value) {
                    Ok(m) => models.extend(evaluate_world_model(&m, &truth, Some(&detections))),
                    Err(e) => skipped.push(format!("{name}#{i} {topic}: {e}")),
                }
            }
            global += 1;
        }
        bar.finish_and_clear();
    }
    if frames.is_empty() {
        bail!("no frame with overhead ground truth in the given streams");
    }
    let report = OverheadEvalReport::from_frames(&frames, &models);
    let calibration_name = calibration.map_or_else(
        || "the streams' true cameras (no --calibration)".to_owned(),
        |p| p.display().to_string(),
    );
    if json {
        let out = serde_json::json!({
            "overhead": report,
            "calibration": calibration_name,
            "skipped": skipped,
        });
        println!("{}", serde_json::to_string(&out).context("report")?);
    } else {
        print_report(&report, &calibration_name, &skipped);
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

/// The overhead report as text (`calibration`: what the frames were read through).
pub(super) fn print_report(r: &OverheadEvalReport, calibration: &str, skipped: &[String]) {
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
