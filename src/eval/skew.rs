//! What the rolling-shutter skew correction gains: the same frames recognised with and without
//! it, each ball's fitted circle compared with the circle its true outline would fit.
//!
//! A fast pan shifts every row by the pan made since the reference row was read. Were the
//! shift the same along a row (a pure shear), a whole outline's fitted radius would change only
//! at second order (about k²/8 · r for k pixels per row). But the shift grows towards the image
//! sides (the tangent: d · tan θ), so an off-centre ball is also stretched or squeezed sideways
//! at first order, by about 2 · (x − cx) / d times the pan since the reference row: on the fast
//! pans, 0.3 px (p90 0.8 px) on a 7–8 px ball. And on an outline seen from one side only (a ball
//! cut by the image's left or right edge) the shear tilts the arc, which the circle fit reads as
//! a wrong radius. The report keeps one-sided outlines apart from whole ones.
//!
//! The true circle is the one a perfect outline fits *scanned the way the detector scanned it*
//! (`outline_circle`): off the optical axis a sphere projects as an ellipse stretched away from
//! the image centre (over 10% at the image side for a close ball), so which part of it the
//! scans see changes the fitted radius.

use serde::{Deserialize, Serialize};

use super::Percentiles;
use crate::geometry::{Camera, Field, ImagePoint, PinholeCamera, Point, Transform};
use crate::model::truth::RobotViewTruth;
use crate::recognition::Recognition;
use crate::recognition::fit::fit_circle;
use crate::recognition::scan::EdgeScanPattern;

/// Radius of the simulated ball, centimetres (the 8.5 cm ball of the scene).
const BALL_RADIUS_CM: f64 = 4.25;

/// A circle in image pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OutlineCircle {
    /// Centre, pixels.
    #[serde(with = "crate::frame::xy_array")]
    pub center: ImagePoint,
    /// Radius, pixels.
    pub radius_px: f64,
}

/// The circle that the true ball's outline fits, scanned with `pattern`: the sphere's
/// silhouette (the tangent circle of its viewing cone) projected with the truth's mid-readout
/// camera pose, crossed with every pixel row (or column) inside the image, keeping only the
/// crossings the pattern takes (the leftmost per row for a ball cut at the right, …).
/// `None` without a ball, when the camera is inside it, when part of the silhouette is behind
/// the camera, or when fewer than 10 crossings fall inside the image.
#[must_use]
pub fn outline_circle(
    truth: &RobotViewTruth,
    camera: &PinholeCamera,
    pattern: EdgeScanPattern,
) -> Option<OutlineCircle> {
    let ball = truth.ball.as_ref()?;
    let field_from_camera: Transform<Field, Camera> = truth.camera_pose.to_transform();
    let [x, y] = ball.relative.field_cm;
    let c = (field_from_camera.inverse() * Point::<Field>::new(x, y, BALL_RADIUS_CM)).coords;
    let (r, d) = (BALL_RADIUS_CM, c.coords.norm());
    if d.is_nan() || d <= r {
        return None;
    }
    // The silhouette: the circle where the viewing cone touches the sphere.
    let axis = c.coords / d;
    let centre = c.coords * (1.0 - r * r / (d * d));
    let radius = r * (1.0 - r * r / (d * d)).sqrt();
    let u = axis.cross(&nalgebra::Vector3::z());
    let u = if u.norm() > 1e-9 {
        u.normalize()
    } else {
        axis.cross(&nalgebra::Vector3::x()).normalize()
    };
    let v = axis.cross(&u);
    let outline: Vec<ImagePoint> = (0..720)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 720.0;
            let p = centre + radius * (a.cos() * u + a.sin() * v);
            camera.project(&Point::<Camera>::new(p.x, p.y, p.z))
        })
        .collect::<Option<Vec<_>>>()?;
    let (w, h) = (camera.width_px as f64, camera.height_px as f64);
    use EdgeScanPattern as P;
    let rows = matches!(pattern, P::LeftToRight | P::RightToLeft | P::SidesToCentre);
    let (take_lo, take_hi) = match pattern {
        P::LeftToRight | P::TopToBottom => (true, false),
        P::RightToLeft | P::BottomToTop => (false, true),
        P::SidesToCentre | P::TopBottomToCentre => (true, true),
    };
    let mut points = Vec::new();
    let lines = if rows {
        camera.height_px
    } else {
        camera.width_px
    };
    for j in 0..lines {
        let at = j as f64 + 0.5;
        let Some((lo, hi)) = crossings(&outline, at, rows) else {
            continue;
        };
        for (take, t) in [(take_lo, lo), (take_hi, hi)] {
            let p = if rows {
                ImagePoint::new(t, at)
            } else {
                ImagePoint::new(at, t)
            };
            if take && p.x_px > 0.0 && p.x_px < w && p.y_px > 0.0 && p.y_px < h {
                points.push(p);
            }
        }
    }
    if points.len() < 10 {
        return None;
    }
    let f = fit_circle(&points)?;
    Some(OutlineCircle {
        center: f.center(),
        radius_px: f.radius,
    })
}

/// The first and last crossing of the closed polygon `outline` with the row `y = at` (`rows`)
/// or the column `x = at`, as the coordinate along that line.
fn crossings(outline: &[ImagePoint], at: f64, rows: bool) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, a) in outline.iter().enumerate() {
        let b = outline[(i + 1) % outline.len()];
        let (a0, a1, b0, b1) = if rows {
            (a.y_px, a.x_px, b.y_px, b.x_px)
        } else {
            (a.x_px, a.y_px, b.x_px, b.y_px)
        };
        if (a0 - at) * (b0 - at) <= 0.0 && (a0 - b0).abs() > 1e-12 {
            let t = a1 + (b1 - a1) * (at - a0) / (b0 - a0);
            lo = lo.min(t);
            hi = hi.max(t);
        }
    }
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}

/// One ball recognised with and without skew correction on the same frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SkewSample {
    /// The ball was seen from one side only (cut by the image's left or right edge, so its
    /// outline was scanned from the other side).
    pub one_sided: bool,
    /// Radius error with the correction, against the outline circle of the pattern used,
    /// pixels.
    pub radius_error_with_px: f64,
    /// The same without the correction, pixels.
    pub radius_error_without_px: f64,
    /// Distance of the reported centre from the true centre at the reference read-out time,
    /// with the correction, pixels.
    pub centre_error_with_px: f64,
    /// The same without the correction, pixels.
    pub centre_error_without_px: f64,
}

/// Compares the balls of two recognitions of one frame — `with` the skew correction and
/// `without` it — with the truth. `None` unless both reported a ball whose scanned outline lies
/// on the true ball (the reported centre as the image shows it within the true ball's visible
/// box, widened by `tolerance_px`) and both outline circles are known.
#[must_use]
pub fn compare_ball(
    with: &Recognition,
    without: &Recognition,
    truth: &RobotViewTruth,
    camera: &PinholeCamera,
    tolerance_px: f64,
) -> Option<SkewSample> {
    let tb = truth.ball.as_ref()?;
    let tbox = tb.image_box?;
    let true_centre = tb.relative.image?;
    let on_ball = |p: ImagePoint| {
        p.x_px >= tbox.min_x as f64 - tolerance_px
            && p.x_px <= tbox.max_x as f64 + 1.0 + tolerance_px
            && p.y_px >= tbox.min_y as f64 - tolerance_px
            && p.y_px <= tbox.max_y as f64 + 1.0 + tolerance_px
    };
    let errors = |r: &Recognition| {
        let ball = r.ball.ball.as_ref()?;
        let cand = r.ball.candidates.get(ball.candidate)?;
        if !on_ball(ball.observed_center) {
            return None;
        }
        let outline = outline_circle(truth, camera, cand.pattern)?;
        let centre = (ball.center_x - true_centre.x_px).hypot(ball.center_y - true_centre.y_px);
        Some((
            (ball.radius_px - outline.radius_px).abs(),
            centre,
            cand.pattern,
        ))
    };
    let (rw, cw, pattern) = errors(with)?;
    let (rn, cn, _) = errors(without)?;
    Some(SkewSample {
        one_sided: matches!(
            pattern,
            EdgeScanPattern::LeftToRight | EdgeScanPattern::RightToLeft
        ),
        radius_error_with_px: rw,
        radius_error_without_px: rn,
        centre_error_with_px: cw,
        centre_error_without_px: cn,
    })
}

/// Errors with and without the correction over a group of balls.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SkewErrors {
    /// Radius error with the correction, pixels.
    pub radius_with_px: Option<Percentiles>,
    /// Radius error without it, pixels.
    pub radius_without_px: Option<Percentiles>,
    /// Centre error with the correction, pixels.
    pub centre_with_px: Option<Percentiles>,
    /// Centre error without it, pixels.
    pub centre_without_px: Option<Percentiles>,
}

impl SkewErrors {
    fn of<'a>(samples: impl Iterator<Item = &'a SkewSample> + Clone) -> Self {
        let pick = |f: fn(&SkewSample) -> f64| {
            Percentiles::of(&samples.clone().map(f).collect::<Vec<_>>())
        };
        Self {
            radius_with_px: pick(|s| s.radius_error_with_px),
            radius_without_px: pick(|s| s.radius_error_without_px),
            centre_with_px: pick(|s| s.centre_error_with_px),
            centre_without_px: pick(|s| s.centre_error_without_px),
        }
    }
}

/// The skew correction's gain over fast-panning frames.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SkewReport {
    /// Fast-panning frames looked at.
    pub frames: usize,
    /// Of those, frames where both runs put a ball on the true one.
    pub compared: usize,
    /// Every compared ball.
    pub all: SkewErrors,
    /// Balls seen from one side only (cut by the image's left or right edge).
    pub one_sided: SkewErrors,
    /// Balls whose outline was seen on both sides (or from above and below).
    pub whole: SkewErrors,
}

impl SkewReport {
    /// The report of `samples` taken on `frames` fast-panning frames.
    #[must_use]
    pub fn from_samples(frames: usize, samples: &[SkewSample]) -> Self {
        Self {
            frames,
            compared: samples.len(),
            all: SkewErrors::of(samples.iter()),
            one_sided: SkewErrors::of(samples.iter().filter(|s| s.one_sided)),
            whole: SkewErrors::of(samples.iter().filter(|s| !s.one_sided)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{BodyPose, HeadJoints, PoseRecord, RobotPose};
    use crate::model::truth::{BallTruth, CutOff, Relative};
    use crate::sensors::SensorReadings;

    /// Truth for a ball `ahead_cm` in front of a level camera at the ball centres' height,
    /// `left_cm` to its left.
    fn truth(ahead_cm: f64, left_cm: f64) -> RobotViewTruth {
        let relative = Relative {
            field_cm: [ahead_cm, left_cm],
            camera_distance_cm: ahead_cm.hypot(left_cm),
            body_distance_cm: ahead_cm.hypot(left_cm),
            body_bearing_rad: left_cm.atan2(ahead_cm),
            camera_bearing_rad: left_cm.atan2(ahead_cm),
            camera_elevation_rad: 0.0,
            image: None,
        };
        RobotViewTruth {
            time_s: 0.0,
            observer_id: 0,
            robot_pose: RobotPose::default(),
            body: BodyPose::ERS7_STANCE,
            joints: HeadJoints::default(),
            camera_pose: PoseRecord {
                position_cm: [0.0, 0.0, BALL_RADIUS_CM],
                yaw_rad: 0.0,
                pitch_rad: 0.0,
                roll_rad: 0.0,
            },
            sensors: SensorReadings::default(),
            horizon: None,
            ball: Some(BallTruth {
                relative,
                image_radius_px: None,
                visible_pixels: 1,
                visible_fraction: 1.0,
                in_image_fraction: 1.0,
                cut_off: CutOff::default(),
                image_box: None,
                ground_velocity_cm_s: None,
                image_velocity_px_s: None,
            }),
            goals: Vec::new(),
            beacons: Vec::new(),
            robots: Vec::new(),
            markers: Vec::new(),
        }
    }

    #[test]
    fn an_on_axis_ball_fits_its_pinhole_radius_with_every_pattern() {
        let camera = PinholeCamera::ers7();
        let t = truth(60.0, 0.0);
        let expected = camera
            .sphere_radius_px(BALL_RADIUS_CM, 60.0)
            .expect("in front");
        for p in [
            EdgeScanPattern::SidesToCentre,
            EdgeScanPattern::LeftToRight,
            EdgeScanPattern::TopBottomToCentre,
        ] {
            let c = outline_circle(&t, &camera, p).expect("outline");
            assert!(
                (c.radius_px - expected).abs() < 0.05,
                "{p:?}: {c:?} vs {expected}"
            );
            assert!((c.center.x_px - camera.centre.x_px).abs() < 0.05);
            assert!((c.center.y_px - camera.centre.y_px).abs() < 0.05);
        }
    }

    #[test]
    fn an_off_axis_ball_is_larger_on_its_outer_side() {
        let camera = PinholeCamera::ers7();
        // 25 cm to the left at 50 cm ahead: the ball sits near the image's left side.
        let t = truth(50.0, 25.0);
        let inner = outline_circle(&t, &camera, EdgeScanPattern::RightToLeft).expect("inner");
        let whole = outline_circle(&t, &camera, EdgeScanPattern::SidesToCentre).expect("whole");
        let on_axis = camera
            .sphere_radius_px(BALL_RADIUS_CM, 50.0_f64.hypot(25.0))
            .expect("in front");
        assert!(whole.radius_px > on_axis * 1.02, "{whole:?} vs {on_axis}");
        assert!(whole.center.x_px < camera.centre.x_px - 50.0);
        assert!((inner.radius_px - whole.radius_px).abs() > 0.05);
    }

    #[test]
    fn no_outline_without_a_ball_or_behind_the_camera() {
        let camera = PinholeCamera::ers7();
        let mut t = truth(60.0, 0.0);
        let behind = truth(-60.0, 0.0);
        assert!(outline_circle(&behind, &camera, EdgeScanPattern::SidesToCentre).is_none());
        t.ball = None;
        assert!(outline_circle(&t, &camera, EdgeScanPattern::SidesToCentre).is_none());
    }

    #[test]
    fn report_splits_one_sided_and_whole_balls() {
        let s = |one_sided, rw, rn| SkewSample {
            one_sided,
            radius_error_with_px: rw,
            radius_error_without_px: rn,
            centre_error_with_px: 0.5,
            centre_error_without_px: 10.0,
        };
        let r = SkewReport::from_samples(
            5,
            &[s(true, 0.2, 1.0), s(false, 0.3, 0.3), s(true, 0.1, 0.8)],
        );
        assert_eq!((r.frames, r.compared), (5, 3));
        assert_eq!(r.one_sided.radius_with_px.map(|p| p.n), Some(2));
        assert_eq!(r.whole.radius_without_px.map(|p| p.p50), Some(0.3));
        assert_eq!(r.one_sided.radius_without_px.map(|p| p.p50), Some(0.8));
        assert_eq!(r.all.centre_without_px.map(|p| p.p50), Some(10.0));
    }
}
