//! Which part of the field each overhead camera sees: its frame's border carried through its
//! calibration onto a horizontal plane, as a polygon in field centimetres — what the field view
//! draws per camera, and what says which cameras can see a field point.
//!
//! Plain data: a camera (its calibration, scaled to the frame size) in, a polygon out. Which
//! camera saw a merged detection is already in the [`FieldPicture`](super::merge::FieldPicture)
//! (`camera_ids`).

use serde::Serialize;

use super::merge::SslCameraId;
use super::pipeline::{FrameFit, frame_fit};
use crate::geometry::{ImagePoint, OverheadCamera};

/// Points taken along each side of the frame: enough for a barrel lens's bent border to be
/// followed within a few centimetres on a 1920-pixel side (the border is sampled every 1/16th).
pub const SAMPLES_PER_SIDE: usize = 16;

/// One camera's view of the field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CameraCoverage {
    /// The camera's session id.
    pub camera: SslCameraId,
    /// The frame border on the plane, centimetres `[x, y]`, in order around the border (image
    /// top-left, along the top, down the right side, back along the bottom and up the left).
    /// Border points whose ray misses the plane (a lens folding over, a camera tilted to the
    /// horizon) are left out.
    pub polygon_cm: Vec<[f64; 2]>,
}

impl CameraCoverage {
    /// Whether the camera sees field point `p` (centimetres) on its plane.
    #[must_use]
    pub fn contains(&self, p: [f64; 2]) -> bool {
        polygon_contains(&self.polygon_cm, p)
    }
}

/// The border of a `width`×`height` frame of `camera` on the plane `height_cm` above the carpet
/// (0: the carpet; the marker plates' height for robots). The calibration is scaled to a frame
/// of another size with its shape; `None` for a frame of another shape (the calibration is not
/// this camera's view) or when fewer than three border points reach the plane.
#[must_use]
pub fn coverage_polygon(
    camera: &OverheadCamera,
    width: usize,
    height: usize,
    height_cm: f64,
) -> Option<Vec<[f64; 2]>> {
    let camera = match frame_fit(camera, width, height) {
        FrameFit::Same => *camera,
        FrameFit::Scaled { .. } => camera.scaled_to(width, height),
        FrameFit::Mismatch { .. } => return None,
    };
    let (w, h) = (width as f64, height as f64);
    let n = SAMPLES_PER_SIDE;
    let along = |k: usize| k as f64 / n as f64;
    let border = (0..n)
        .map(|k| (along(k) * w, 0.0))
        .chain((0..n).map(|k| (w, along(k) * h)))
        .chain((0..n).map(|k| ((1.0 - along(k)) * w, h)))
        .chain((0..n).map(|k| (0.0, (1.0 - along(k)) * h)));
    let polygon: Vec<[f64; 2]> = border
        .filter_map(|(x, y)| camera.field_from_image(ImagePoint::new(x, y), height_cm))
        .map(|p| [p.x(), p.y()])
        .collect();
    (polygon.len() >= 3).then_some(polygon)
}

/// Every camera's coverage on the plane `height_cm` above the carpet, in the order given: each
/// `(id, calibrated camera, frame width, frame height)`. A camera whose coverage cannot be
/// drawn (see [`coverage_polygon`]) is left out.
#[must_use]
pub fn field_coverage(
    cameras: &[(SslCameraId, OverheadCamera, usize, usize)],
    height_cm: f64,
) -> Vec<CameraCoverage> {
    cameras
        .iter()
        .filter_map(|(id, camera, w, h)| {
            coverage_polygon(camera, *w, *h, height_cm).map(|polygon_cm| CameraCoverage {
                camera: *id,
                polygon_cm,
            })
        })
        .collect()
}

/// The cameras whose coverage holds field point `p` (centimetres), in the order given.
#[must_use]
pub fn cameras_seeing(coverage: &[CameraCoverage], p: [f64; 2]) -> Vec<SslCameraId> {
    coverage
        .iter()
        .filter(|c| c.contains(p))
        .map(|c| c.camera)
        .collect()
}

/// Whether `p` lies inside `polygon` (even–odd rule; a point on the border may go either way).
#[must_use]
pub fn polygon_contains(polygon: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = polygon.len();
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + n - 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 640×400 camera 300 cm up looking straight down, focal 400 px, no lens: it sees
    /// 300·320/400 = 240 cm either side in x and 150 cm in y on the carpet.
    fn pinhole() -> OverheadCamera {
        OverheadCamera::looking_down(640, 400, 300.0, 400.0, 0.0, 0.0)
    }

    #[test]
    fn a_straight_down_pinhole_covers_the_rectangle_under_it() {
        let poly = coverage_polygon(&pinhole(), 640, 400, 0.0).expect("a polygon");
        assert_eq!(poly.len(), 4 * SAMPLES_PER_SIDE);
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in &poly {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        for (got, want) in [
            (lo[0], -240.0),
            (hi[0], 240.0),
            (lo[1], -150.0),
            (hi[1], 150.0),
        ] {
            assert!((got - want).abs() < 1e-6, "{got} vs {want}");
        }
        // Plates 25 cm up are nearer the camera: a smaller patch.
        let plates = coverage_polygon(&pinhole(), 640, 400, 25.0).expect("a polygon");
        let reach = plates.iter().map(|p| p[0]).fold(f64::MIN, f64::max);
        assert!((reach - 240.0 * 275.0 / 300.0).abs() < 1e-6, "{reach}");
    }

    #[test]
    fn the_frame_size_scales_the_view_and_another_shape_has_none() {
        let full = coverage_polygon(&pinhole(), 640, 400, 0.0).expect("a polygon");
        let half = coverage_polygon(&pinhole(), 320, 200, 0.0).expect("the same shape");
        for (a, b) in full.iter().zip(&half) {
            assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
        }
        assert_eq!(coverage_polygon(&pinhole(), 640, 480, 0.0), None);
    }

    #[test]
    fn a_barrel_lens_sees_farther_and_points_say_which_cameras_see_them() {
        let mut left = pinhole();
        left.k1 = -0.15;
        let bent = coverage_polygon(&left, 640, 400, 0.0).expect("a polygon");
        let reach = bent.iter().map(|p| p[0]).fold(f64::MIN, f64::max);
        assert!(
            reach > 250.0,
            "a barrel lens reaches past the pinhole: {reach}"
        );
        // Two cameras side by side, 400 cm apart: only the middle is seen by both.
        let mut right = pinhole();
        right.pose.position_cm[0] += 400.0;
        let cams = [
            (SslCameraId(3), left, 640, 400),
            (SslCameraId(7), right, 640, 400),
            (SslCameraId(9), pinhole(), 640, 480),
        ];
        let coverage = field_coverage(&cams, 0.0);
        assert_eq!(coverage.len(), 2, "the mismatched frame size is left out");
        assert_eq!(cameras_seeing(&coverage, [0.0, 0.0]), vec![SslCameraId(3)]);
        assert_eq!(
            cameras_seeing(&coverage, [200.0, 100.0]),
            vec![SslCameraId(3), SslCameraId(7)]
        );
        assert_eq!(
            cameras_seeing(&coverage, [400.0, -140.0]),
            vec![SslCameraId(7)]
        );
        assert!(cameras_seeing(&coverage, [200.0, 200.0]).is_empty());
    }
}
