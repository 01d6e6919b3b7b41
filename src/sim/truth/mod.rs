//! Per-frame ground truth computed from a rendered frame: what a perfect recognition would
//! report. The truth's types (its JSON) are [`crate::model::truth`]'s; this module fills them in
//! from the scene, the camera pose at mid-readout and the rendered object buffer, which counts
//! each object's visible pixels (occlusion, the image border and the rolling shutter's skew
//! included).
//!
//! | file | role |
//! |---|---|
//! | `mod.rs` | the pixel coverage of an object, the ball's velocity truth |
//! | `robot_view.rs` | [`robot_view_truth`]: ball, goals and their gaps, beacons, robots, markers |
//! | `overhead.rs` | [`overhead_truth`]: ball, robots and their marker plates from above |

mod overhead;
mod robot_view;

pub use overhead::overhead_truth;
pub use robot_view::{GAP_SCAN_HEIGHT_CM, robot_view_truth};

use crate::frame::PixelBox;
use crate::geometry::{CameraPose, Field, Point, RobotPose};
use crate::model::truth::BallTruth;

/// Fills in a ball's velocity truth from its field velocity `v_cm_s` (cm/s): turned into the
/// observer's frame, and as the image motion of its centre through the mid-readout `pose`
/// (a finite difference over ±1 ms).
pub fn add_ball_velocity(
    ball: &mut BallTruth,
    v_cm_s: [f64; 2],
    robot: &RobotPose,
    pose: &CameraPose,
) {
    let (s, c) = robot.heading_rad.sin_cos();
    ball.ground_velocity_cm_s = Some([
        c * v_cm_s[0] + s * v_cm_s[1],
        -s * v_cm_s[0] + c * v_cm_s[1],
    ]);
    let centre = ball.relative.field_cm;
    let h = 1e-3;
    let at = |k: f64| {
        pose.image_from_field(&Point::<Field>::new(
            centre[0] + k * h * v_cm_s[0],
            centre[1] + k * h * v_cm_s[1],
            4.25,
        ))
    };
    ball.image_velocity_px_s = match (at(-1.0), at(1.0)) {
        (Some(a), Some(b)) => Some([(b.x_px - a.x_px) / (2.0 * h), (b.y_px - a.y_px) / (2.0 * h)]),
        _ => None,
    };
}

/// Pixel statistics of one object in an object buffer.
#[derive(Debug, Clone, Copy, Default)]
struct Coverage {
    pixels: usize,
    bbox: Option<PixelBox>,
}

fn coverage(objects: &[u16], width: usize, id: u16) -> Coverage {
    coverage_where(objects, width, |k| objects[k] == id)
}

/// The pixels (by index into the row-major buffer of `width` columns) for which `counts` holds.
fn coverage_where(objects: &[u16], width: usize, counts: impl Fn(usize) -> bool) -> Coverage {
    let mut c = Coverage::default();
    for k in (0..objects.len()).filter(|k| counts(*k)) {
        let (x, y) = (k % width, k / width);
        let (x, y) = (
            u32::try_from(x).unwrap_or(u32::MAX),
            u32::try_from(y).unwrap_or(u32::MAX),
        );
        c.pixels += 1;
        c.bbox = Some(match c.bbox {
            None => PixelBox::new(x, y, x, y),
            Some(b) => PixelBox::new(
                b.min_x.min(x),
                b.min_y.min(y),
                b.max_x.max(x),
                b.max_y.max(y),
            ),
        });
    }
    c
}

/// The share of an object's full image area (pixels²) that its visible pixels cover, 0 to 1
/// (0 when the area is empty).
fn covered_fraction(pixels: usize, area: f64) -> f64 {
    if area > 0.0 {
        (pixels as f64 / area).min(1.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_counts_pixels_and_boxes() {
        let mut objects = vec![0_u16; 10 * 4];
        objects[12] = 1;
        objects[27] = 1;
        let c = coverage(&objects, 10, 1);
        assert_eq!(c.pixels, 2);
        assert_eq!(c.bbox, Some(PixelBox::new(2, 1, 7, 2)));
    }
}
