//! Painted field lines in an overhead image: where the calibration expects them, where the
//! image shows them, and the lines drawn over the image.
//!
//! Refinement looks across each projected line (along its image normal) for the brightest
//! stretch of luma, a white line on the carpet, and takes the centroid of its upper half as the
//! line's centre to a fraction of a pixel. Samples near a crossing of two lines are left out:
//! there the brightest stretch may belong to the other line.

use serde::{Deserialize, Serialize};

use super::field::{FieldDescription, LineSample};
use crate::frame::Frame;
use crate::geometry::{Camera, Field, ImagePoint, OverheadCamera, Point, Transform};

/// A line sample and where the image shows the line's centre across it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineObservation {
    /// The sample's field position `[x, y]` on the ground, centimetres.
    pub field_cm: [f64; 2],
    /// The line's unit direction there, field `[x, y]`.
    pub direction: [f64; 2],
    /// The line centre found in the image, pixels.
    pub found: ImagePoint,
}

impl LineObservation {
    /// Signed distance (pixels) of the found centre from the line as `camera` projects it,
    /// measured across the projected line; NaN where the camera does not see the sample.
    #[must_use]
    pub fn distance_px(&self, camera: &OverheadCamera) -> f64 {
        self.distance_px_with(camera, &camera.field_from_camera().inverse())
    }

    /// The same with the camera's `camera_from_field` given (the solver builds it directly).
    #[must_use]
    pub fn distance_px_with(
        &self,
        camera: &OverheadCamera,
        camera_from_field: &Transform<Camera, Field>,
    ) -> f64 {
        let [x, y] = self.field_cm;
        let [dx, dy] = self.direction;
        let project = |p: Point<Field>| camera.image_from_camera(&(*camera_from_field * p));
        let (Some(a), Some(b)) = (
            project(Point::new(x, y, 0.0)),
            project(Point::new(x + dx, y + dy, 0.0)),
        ) else {
            return f64::NAN;
        };
        let (tx, ty) = (b.x_px - a.x_px, b.y_px - a.y_px);
        let len = tx.hypot(ty);
        if len < 1e-9 {
            return f64::NAN;
        }
        ((self.found.x_px - a.x_px) * -ty + (self.found.y_px - a.y_px) * tx) / len
    }
}

/// Keeps the samples farther than `margin_cm` from every other line and arc of the field.
#[must_use]
pub fn away_from_crossings(
    field: &FieldDescription,
    samples: &[LineSample],
    margin_cm: f64,
) -> Vec<LineSample> {
    samples
        .iter()
        .filter(|s| {
            let [x, y] = s.field_cm;
            let near_segments = field
                .lines
                .iter()
                .filter(|l| segment_distance(x, y, l.from_cm, l.to_cm) < margin_cm)
                .count();
            let near_arcs = field
                .arcs
                .iter()
                .filter(|a| {
                    let r = (x - a.centre_cm[0]).hypot(y - a.centre_cm[1]);
                    let angle = (y - a.centre_cm[1]).atan2(x - a.centre_cm[0]);
                    let within = [
                        angle,
                        angle + std::f64::consts::TAU,
                        angle - std::f64::consts::TAU,
                    ]
                    .iter()
                    .any(|t| (a.from_rad - 0.05..=a.to_rad + 0.05).contains(t));
                    within && (r - a.radius_cm).abs() < margin_cm
                })
                .count();
            near_segments + near_arcs <= 1
        })
        .copied()
        .collect()
}

fn segment_distance(x: f64, y: f64, a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((x - a[0]) * dx + (y - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (x - a[0] - t * dx).hypot(y - a[1] - t * dy)
}

/// Luma at a sub-pixel position (bilinear between pixel centres), or `None` outside.
fn luma_at(frame: &Frame, x: f64, y: f64) -> Option<f64> {
    let (fx, fy) = (x - 0.5, y - 0.5);
    if !(fx >= 0.0 && fy >= 0.0) {
        return None;
    }
    let (i, j) = (fx.floor() as usize, fy.floor() as usize);
    let (ax, ay) = (fx - i as f64, fy - j as f64);
    let p = |i, j| frame.pixel(i, j).map(|p| f64::from(p.y));
    let (a, b, c, d) = (p(i, j)?, p(i + 1, j)?, p(i, j + 1)?, p(i + 1, j + 1)?);
    Some((a * (1.0 - ax) + b * ax) * (1.0 - ay) + (c * (1.0 - ax) + d * ax) * ay)
}

/// Smallest luma rise of a line over the carpet beside it, code values.
const MIN_CONTRAST: f64 = 18.0;

/// The centre of a bright line across `p` along the unit `normal`, within `search_px`, or
/// `None` when no bright stretch stands out there.
#[must_use]
pub fn line_centre_across(
    frame: &Frame,
    p: ImagePoint,
    normal: (f64, f64),
    search_px: f64,
) -> Option<ImagePoint> {
    const STEP: f64 = 0.5;
    let n = (search_px / STEP).ceil() as i64;
    let mut profile = Vec::with_capacity(2 * n as usize + 1);
    for k in -n..=n {
        let t = k as f64 * STEP;
        profile.push((
            t,
            luma_at(frame, p.x_px + t * normal.0, p.y_px + t * normal.1)?,
        ));
    }
    let (peak_at, peak) = profile
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.1.total_cmp(&b.1.1))
        .map(|(i, s)| (i, s.1))?;
    let ends = 3.min(profile.len() / 4).max(1);
    let left = profile[..ends].iter().map(|s| s.1).sum::<f64>() / ends as f64;
    let right = profile[profile.len() - ends..]
        .iter()
        .map(|s| s.1)
        .sum::<f64>()
        / ends as f64;
    let base = left.max(right);
    if peak - base < MIN_CONTRAST || peak_at < ends || peak_at >= profile.len() - ends {
        return None;
    }
    // Centroid of the contiguous stretch above half height around the peak.
    let half = base + (peak - base) / 2.0;
    let (mut lo, mut hi) = (peak_at, peak_at);
    while lo > 0 && profile[lo - 1].1 > half {
        lo -= 1;
    }
    while hi + 1 < profile.len() && profile[hi + 1].1 > half {
        hi += 1;
    }
    if lo == 0 || hi + 1 == profile.len() {
        return None;
    }
    let (mut sw, mut st) = (0.0, 0.0);
    for s in &profile[lo..=hi] {
        let w = s.1 - half;
        sw += w;
        st += w * s.0;
    }
    let t = st / sw;
    t.is_finite()
        .then(|| ImagePoint::new(p.x_px + t * normal.0, p.y_px + t * normal.1))
}

/// Looks for every sample's line in `frame` where `camera` projects it.
#[must_use]
pub fn find_line_observations(
    frame: &Frame,
    camera: &OverheadCamera,
    samples: &[LineSample],
    search_px: f64,
) -> Vec<LineObservation> {
    let (w, h) = (frame.width() as f64, frame.height() as f64);
    let margin = search_px + 2.0;
    samples
        .iter()
        .filter_map(|s| {
            let [x, y] = s.field_cm;
            let [dx, dy] = s.direction;
            let a = camera.image_from_field(&Point::new(x, y, 0.0))?;
            let b = camera.image_from_field(&Point::new(x + dx, y + dy, 0.0))?;
            if a.x_px < margin || a.y_px < margin || a.x_px > w - margin || a.y_px > h - margin {
                return None;
            }
            let (tx, ty) = (b.x_px - a.x_px, b.y_px - a.y_px);
            let len = tx.hypot(ty);
            if len < 1e-9 {
                return None;
            }
            let found = line_centre_across(frame, a, (-ty / len, tx / len), search_px)?;
            Some(LineObservation {
                field_cm: s.field_cm,
                direction: s.direction,
                found,
            })
        })
        .collect()
}

/// Most points a projected line or arc is drawn with.
const MAX_CURVE_POINTS: f64 = 4096.0;

/// Every painted line and arc as image polylines through `camera` (about 2 cm steps), split
/// where the camera does not see them or they leave the image by more than a margin: what the
/// app and `eotn overhead calibrate --image` draw to judge a calibration.
#[must_use]
pub fn projected_field_lines(
    field: &FieldDescription,
    camera: &OverheadCamera,
) -> Vec<Vec<ImagePoint>> {
    let (w, h) = (camera.width_px as f64, camera.height_px as f64);
    let inside =
        |p: &ImagePoint| p.x_px > -20.0 && p.y_px > -20.0 && p.x_px < w + 20.0 && p.y_px < h + 20.0;
    let mut curves: Vec<Vec<[f64; 2]>> = Vec::new();
    for l in &field.lines {
        let len = (l.to_cm[0] - l.from_cm[0]).hypot(l.to_cm[1] - l.from_cm[1]);
        // A point every 2 cm, at most MAX_CURVE_POINTS a line (the image is never finer).
        let n = (len / 2.0).ceil().clamp(1.0, MAX_CURVE_POINTS) as usize;
        curves.push(
            (0..=n)
                .map(|k| {
                    let t = k as f64 / n as f64;
                    [
                        l.from_cm[0] + t * (l.to_cm[0] - l.from_cm[0]),
                        l.from_cm[1] + t * (l.to_cm[1] - l.from_cm[1]),
                    ]
                })
                .collect(),
        );
    }
    for a in &field.arcs {
        let sweep = a.to_rad - a.from_rad;
        let n = (sweep.abs() * a.radius_cm / 2.0)
            .ceil()
            .clamp(8.0, MAX_CURVE_POINTS) as usize;
        curves.push(
            (0..=n)
                .map(|k| {
                    let angle = a.from_rad + sweep * k as f64 / n as f64;
                    [
                        a.centre_cm[0] + a.radius_cm * angle.cos(),
                        a.centre_cm[1] + a.radius_cm * angle.sin(),
                    ]
                })
                .collect(),
        );
    }
    let mut out = Vec::new();
    for curve in curves {
        let mut run = Vec::new();
        for [x, y] in curve {
            match camera.image_from_field(&Point::new(x, y, 0.0)) {
                Some(p) if inside(&p) => run.push(p),
                _ => {
                    if run.len() > 1 {
                        out.push(std::mem::take(&mut run));
                    }
                    run.clear();
                }
            }
        }
        if run.len() > 1 {
            out.push(run);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Frame, Yuv};

    #[test]
    fn a_bright_stripe_is_found_to_a_fraction_of_a_pixel() {
        // A vertical stripe 3 px wide centred at x = 20.25 (bright 200 on 80), drawn with
        // partial pixels at its edges.
        let frame = Frame::yuv444_from_fn(40, 20, |x, _| {
            let (a, b) = (x as f64, x as f64 + 1.0);
            let cover = (b.min(21.75) - a.max(18.75)).clamp(0.0, 1.0);
            Yuv {
                y: (80.0 + 120.0 * cover).round() as u8,
                u: 128,
                v: 128,
            }
        })
        .expect("frame");
        let found = line_centre_across(&frame, ImagePoint::new(17.0, 10.0), (1.0, 0.0), 7.0)
            .expect("stripe found");
        assert!((found.x_px - 20.25).abs() < 0.15, "{found:?}");
        assert!(line_centre_across(&frame, ImagePoint::new(5.0, 10.0), (1.0, 0.0), 3.0).is_none());
    }

    #[test]
    fn samples_near_crossings_are_left_out() {
        let field = FieldDescription::four_legged_2005();
        let all = field.line_samples(5.0);
        let kept = away_from_crossings(&field, &all, 12.0);
        assert!(kept.len() < all.len() && kept.len() > all.len() / 2);
        // Nothing kept on the centre line near the centre circle, which crosses it.
        assert!(
            !kept
                .iter()
                .any(|s| s.field_cm[0].abs() < 1e-9 && (s.field_cm[1].abs() - 18.0).abs() < 10.0)
        );
    }

    #[test]
    fn projected_lines_stay_near_the_image() {
        let field = FieldDescription::four_legged_2005();
        let camera = OverheadCamera::above_field_2005();
        let curves = projected_field_lines(&field, &camera);
        assert!(curves.len() >= field.lines.len());
        for p in curves.iter().flatten() {
            assert!(p.x_px > -21.0 && p.x_px < 661.0 && p.y_px > -21.0 && p.y_px < 501.0);
        }
    }
}
