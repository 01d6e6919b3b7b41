//! `eotn overhead detect --session SESSION.json`: every overhead camera of a session through
//! its own table and calibration, merged into one field picture per field frame (robots by
//! identity, the ball by confidence). The reference camera (the session's first) sets the field
//! frames: another camera's frame within half of its frame period joins it.

use std::io::Write;
use std::path::Path;

use anyhow::Context;
use serde::Serialize;

use super::field::{field_views, frame_times, open_cameras};
use super::overhead::{BallJson, RobotJson, SizeCheck};
use crate::overhead::merge::{FieldPicture, SslCameraId, merge_detections};
use crate::overhead::recognise::OverheadDetections;
use crate::session::Session;

/// The merged ball in a field line: as `eotn overhead detect --json` prints it, from the most
/// confident camera, with every camera that saw it.
#[derive(Debug, Serialize)]
struct FieldBallJson {
    #[serde(flatten)]
    ball: BallJson,
    /// The camera whose ball it is (its `image_px`, `radius_px`).
    camera_id: SslCameraId,
    camera_ids: Vec<SslCameraId>,
}

/// A merged robot in a field line.
#[derive(Debug, Serialize)]
struct FieldRobotJson {
    #[serde(flatten)]
    robot: RobotJson,
    camera_ids: Vec<SslCameraId>,
}

/// A camera frame merged into a field frame.
#[derive(Debug, Serialize)]
struct CameraFrameJson {
    id: SslCameraId,
    time_ns: u64,
}

/// One line of `eotn overhead detect --session --json`.
#[derive(Debug, Serialize)]
struct FieldLineJson {
    /// The reference camera's frame time, nanoseconds.
    time_ns: u64,
    ball: Option<FieldBallJson>,
    robots: Vec<FieldRobotJson>,
    cameras: Vec<CameraFrameJson>,
}

/// Runs `eotn overhead detect --session`; with `ssl_vision` (`HOST:PORT`) each camera's frames
/// are also sent as SSL-Vision packets, `camera_id` its session id.
///
/// # Errors
/// An unusable session (named entry), a camera's frame of another shape than its calibration.
/// A camera whose frame cannot be read is warned about and left out of that field frame.
pub fn run(path: &Path, json: bool, ssl_vision: Option<&str>) -> anyhow::Result<()> {
    let session = Session::load(path)?;
    let (field, mut cameras) = open_cameras(&session)?;
    let mut ssl = ssl_vision
        .map(|addr| super::ssl_vision_out::open(addr, &field, &ssl_cameras(&cameras)))
        .transpose()?;
    let times = frame_times(&cameras);
    let reference = times.first().cloned().unwrap_or_default();
    let period_ns = frame_period_ns(&reference);
    let mut sizes: Vec<SizeCheck> = cameras.iter().map(|_| SizeCheck::default()).collect();
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for (i, &t_ref) in reference.iter().enumerate() {
        let (views, frames) =
            field_views(cameras.as_mut_slice(), &times, i, period_ns, &mut sizes)?;
        if let Some(out) = ssl.as_mut() {
            for ((id, d), (_, time_ns)) in views.iter().zip(&frames) {
                out.send(super::ssl_vision_out::session_camera_id(*id), *time_ns, d);
            }
        }
        let frames = frames
            .into_iter()
            .map(|(id, time_ns)| CameraFrameJson { id, time_ns })
            .collect();
        let refs: Vec<(SslCameraId, &OverheadDetections)> =
            views.iter().map(|(id, d)| (*id, d)).collect();
        let line = field_line(t_ref, &merge_detections(&refs), frames);
        if json {
            serde_json::to_writer(&mut out, &line)?;
            writeln!(out)?;
        } else {
            write_text(&mut out, &line)?;
        }
    }
    out.flush().context("writing output")?;
    if let Some(ssl) = &ssl {
        super::ssl_vision_out::finish(ssl);
    }
    Ok(())
}

/// Each camera's id and calibration, for the SSL-Vision geometry.
pub(super) fn ssl_cameras(
    cameras: &[super::field::FieldCamera],
) -> Vec<crate::ssl_vision::CameraEntry> {
    cameras
        .iter()
        .map(|c| crate::ssl_vision::CameraEntry {
            camera_id: super::ssl_vision_out::session_camera_id(c.id),
            camera: *c.pipeline.camera(),
        })
        .collect()
}

/// One field frame as a line of `overhead detect --session --json` (`time_ns`, `ball`,
/// `robots`, `cameras`), for `eotn wmd` to add its world models to.
pub(super) fn field_line_value(
    time_ns: u64,
    p: &FieldPicture,
    cameras: &[(SslCameraId, u64)],
) -> serde_json::Result<serde_json::Value> {
    let frames = cameras
        .iter()
        .map(|&(id, time_ns)| CameraFrameJson { id, time_ns })
        .collect();
    serde_json::to_value(field_line(time_ns, p, frames))
}

/// The reference camera's frame period: the median gap between its frames (1/75 s for one
/// frame, the SSL cameras' rate).
fn frame_period_ns(times: &[u64]) -> u64 {
    let mut gaps: Vec<u64> = times
        .windows(2)
        .map(|w| w[1].saturating_sub(w[0]))
        .collect();
    gaps.sort_unstable();
    gaps.get(gaps.len() / 2)
        .copied()
        .filter(|&g| g > 0)
        .unwrap_or(13_333_333)
}

fn field_line(time_ns: u64, p: &FieldPicture, cameras: Vec<CameraFrameJson>) -> FieldLineJson {
    FieldLineJson {
        time_ns,
        ball: p.ball.as_ref().map(|b| FieldBallJson {
            ball: BallJson {
                x_cm: b.ball.field_cm[0],
                y_cm: b.ball.field_cm[1],
                image_px: [b.ball.image.x_px, b.ball.image.y_px],
                radius_px: b.ball.radius_px,
                confidence: b.ball.confidence,
            },
            camera_id: b.camera,
            camera_ids: b.camera_ids.clone(),
        }),
        robots: p
            .robots
            .iter()
            .map(|r| FieldRobotJson {
                robot: RobotJson {
                    team: r.team.name(),
                    id: r.identity.value(),
                    x_cm: r.field_cm[0],
                    y_cm: r.field_cm[1],
                    heading_rad: r.heading_rad,
                    confidence: r.confidence,
                },
                camera_ids: r.camera_ids.clone(),
            })
            .collect(),
        cameras,
    }
}

fn write_text(out: &mut impl Write, line: &FieldLineJson) -> anyhow::Result<()> {
    write!(
        out,
        "{:.3} s ({} cameras):",
        line.time_ns as f64 * 1e-9,
        line.cameras.len()
    )?;
    match &line.ball {
        Some(b) => write!(out, " ball ({:.1}, {:.1}) cm", b.ball.x_cm, b.ball.y_cm)?,
        None => write!(out, " no ball")?,
    }
    for r in &line.robots {
        let ids: Vec<String> = r.camera_ids.iter().map(ToString::to_string).collect();
        write!(
            out,
            "; {} {} ({:.1}, {:.1}) cm {:.0}° [cameras {}]",
            r.robot.team,
            r.robot.id,
            r.robot.x_cm,
            r.robot.y_cm,
            r.robot.heading_rad.to_degrees(),
            ids.join(",")
        )?;
    }
    writeln!(out)?;
    Ok(())
}
