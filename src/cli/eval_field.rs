//! `eotn eval --session SESSION.json`: a whole overhead field against the truth of its
//! simulated recordings. Every camera runs over its recording through its own table and
//! calibration (the cameras of a field frame in parallel, as `overhead detect --session` runs
//! them); each field frame's merged picture is scored as one frame (ball, every robot once,
//! identity, heading), and each camera's own detections before merging beside it.

use std::path::Path;

use anyhow::{Context, bail};

use super::field::{camera_views, frame_times, open_cameras};
use super::overhead::{SizeCheck, params_for};
use crate::eval::overhead::{OverheadEvalParams, evaluate_overhead_frame};
use crate::eval::overhead_field::{
    CameraTruth, FieldEvalReport, FieldFrameEval, evaluate_field_frame,
};
use crate::overhead::merge::{SslCameraId, merge_detections};
use crate::overhead::recognise::OverheadDetections;
use crate::session::Session;

/// Runs `eotn eval --session`.
///
/// # Errors
/// An unusable session (named entry), a camera's frame of another shape than its calibration,
/// no field frame with truth.
pub fn run(path: &Path, json: bool) -> anyhow::Result<()> {
    let session = Session::load(path)?;
    let (field, mut cameras) = open_cameras(&session)?;
    let ball_radius_cm = params_for(&field).ball_radius_cm;
    let times = frame_times(&cameras);
    let reference = times.first().cloned().unwrap_or_default();
    let period_ns = crate::wmd::clock::frame_period_ns(&reference);
    let mut sizes: Vec<SizeCheck> = cameras.iter().map(|_| SizeCheck::default()).collect();
    let params = OverheadEvalParams::default();
    let (mut field_frames, mut own, mut skipped) = (Vec::new(), Vec::new(), Vec::<String>::new());
    let bar = super::inputs::progress(reference.len(), "eval field");
    for i in 0..reference.len() {
        bar.inc(1);
        let views = camera_views(&mut cameras, &times, i, period_ns, &mut sizes)?;
        let mut truths = Vec::new();
        for v in &views {
            let Some(t) = &v.truth else {
                skipped.push(format!(
                    "camera {} frame {}: no overhead truth",
                    v.id, v.index
                ));
                continue;
            };
            let e = evaluate_overhead_frame(own.len(), &v.detections, t, &params);
            truths.push(CameraTruth {
                camera: v.id,
                truth: t,
                found_ball: e.ball_error_cm.is_some(),
            });
            own.push(e);
        }
        if truths.is_empty() {
            continue;
        }
        let refs: Vec<(SslCameraId, &OverheadDetections)> =
            views.iter().map(|v| (v.id, &v.detections)).collect();
        let picture = merge_detections(&refs);
        field_frames.push(evaluate_field_frame(
            i,
            &picture,
            &truths,
            &params,
            ball_radius_cm,
        ));
    }
    bar.finish_and_clear();
    if field_frames.is_empty() {
        bail!(
            "{}: no field frame with overhead truth (eval --session scores simulated fields: `eotn overhead sim-field`)",
            path.display()
        );
    }
    let report = FieldEvalReport::from_frames(cameras.len(), &field_frames, &own);
    if json {
        let out = serde_json::json!({
            "field": report,
            "field_frames": field_frames.len(),
            "skipped": skipped,
        });
        println!("{}", serde_json::to_string(&out).context("report")?);
    } else {
        print_field(&report, &field_frames, &skipped);
    }
    Ok(())
}

fn print_field(r: &FieldEvalReport, frames: &[FieldFrameEval], skipped: &[String]) {
    println!(
        "{} cameras, {} field frames: the merged picture of each, every detection against the truth at its frames' times",
        r.cameras,
        frames.len()
    );
    super::eval_overhead::print_report(&r.merged, "each camera's own, from the session", skipped);
    println!(
        "robots seen by several {} (robot-frames)   reported twice {}",
        r.robots_seen_by_several, r.duplicates
    );
    let misses = r.merged.ball_eligible.saturating_sub(r.merged.ball_found);
    if misses > 0 {
        println!(
            "ball misses            {misses}: {} found by a camera and lost in merging, {} never shown half whole by any camera",
            r.ball_misses_found_by_a_camera, r.ball_misses_never_half_shown
        );
    }
    let p50 = |p: Option<&crate::eval::Percentiles>| p.map_or(f64::NAN, |p| p.p50);
    let c = &r.per_camera;
    println!(
        "each camera alone      ball {}/{} found, median {:.2} cm; robots {}/{} found, {}/{} identified, heading median {:.2}°; {} false",
        c.ball_found,
        c.ball_eligible,
        p50(c.ball_error_cm.as_ref()),
        c.robots_found,
        c.robots_eligible,
        c.identity_right,
        c.robots_eligible,
        p50(c.heading_error_deg.as_ref()),
        c.robots_false
    );
    if r.camera_ball_misses > 0 {
        println!(
            "                       its ball misses {}: {} of them showed less than half the ball (cut by the image border or hidden)",
            r.camera_ball_misses, r.camera_ball_misses_under_half_shown
        );
    }
}
