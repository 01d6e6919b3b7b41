//! The horizon line in the image: where the ground plane would meet the sky at infinite distance.
//!
//! Recognition uses it to ignore what lies above it (nothing on the field is much above the
//! horizon for a robot-height camera: goals and beacons reach a few degrees over it) and to scan
//! below it. It is the image of every horizontal direction: image points whose ray is
//! perpendicular to the world's up vector. It depends only on the camera's orientation, not its
//! position or heading.
//!
//! Representation: the angle of the line in the image and its offset from the optical centre.
//! `angle_rad` is 0 for a level camera and positive when the line rises to the right as seen on
//! screen (counter-clockwise); `offset_px` is how far the line lies *above* the optical centre,
//! along the line's normal (positive when the camera looks down, so the horizon moves up).

use serde::{Deserialize, Serialize};

use super::{Camera, Field, Transform};
use crate::geometry::camera::{ImagePoint, PinholeCamera};

/// A horizon line in image coordinates (pixels, `FORMATS.md` convention).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Horizon {
    /// Angle of the line on screen, radians, counter-clockwise (rising to the right) positive.
    pub angle_rad: f64,
    /// Distance of the line above the optical centre along its normal, pixels (negative: below).
    pub offset_px: f64,
    /// The optical centre the offset is measured from, pixels.
    pub centre: ImagePoint,
}

impl Horizon {
    /// The horizon of a camera with the given orientation in the field (only the rotation of
    /// `field_from_camera` matters). `None` when the camera looks within 10⁻⁹ rad of straight up
    /// or down, where no horizon line exists in the image plane.
    #[must_use]
    pub fn from_pose(
        camera: &PinholeCamera,
        field_from_camera: &Transform<Field, Camera>,
    ) -> Option<Self> {
        // World up in camera axes. A ray (d, cx − x, cy − y) is horizontal when its dot product
        // with `up` is zero: d·ux + (cx − x)·uy + (cy − y)·uz = 0, a line in (x, y).
        let up = field_from_camera.rotation().inverse() * nalgebra::Vector3::z();
        let norm = up.y.hypot(up.z);
        if norm < 1e-9 || !norm.is_finite() {
            return None;
        }
        // Unit normal pointing to the sky side, image axes: (−uy, −uz) / norm. With
        // n = (−sin α, −cos α) this gives α.
        let (nx, ny) = (-up.y / norm, -up.z / norm);
        let angle_rad = (-nx).atan2(-ny);
        // Signed distance of the centre above the line is d·ux / norm; the line lies that far
        // below the centre, so the offset is its negative.
        let offset_px = -camera.focal_px * up.x / norm;
        Some(Self {
            angle_rad,
            offset_px,
            centre: camera.centre,
        })
    }

    /// The unit normal pointing to the sky side, image axes (x right, y down).
    #[must_use]
    pub fn normal(&self) -> (f64, f64) {
        (-self.angle_rad.sin(), -self.angle_rad.cos())
    }

    /// Signed distance of an image point above the horizon, pixels: positive on the sky side.
    #[must_use]
    pub fn above_px(&self, p: ImagePoint) -> f64 {
        let (nx, ny) = self.normal();
        (p.x_px - self.centre.x_px) * nx + (p.y_px - self.centre.y_px) * ny - self.offset_px
    }

    /// Whether an image point lies strictly above the horizon.
    #[must_use]
    pub fn is_above(&self, p: ImagePoint) -> bool {
        self.above_px(p) > 0.0
    }

    /// The row at which the horizon crosses column `x_px`, or `None` for a (near) vertical line.
    #[must_use]
    pub fn y_at(&self, x_px: f64) -> Option<f64> {
        let (s, c) = self.angle_rad.sin_cos();
        (c.abs() > 1e-9)
            .then(|| self.centre.y_px - (self.offset_px + (x_px - self.centre.x_px) * s) / c)
    }

    /// The horizon's foot point: the point of the line nearest the optical centre, pixels.
    #[must_use]
    pub fn foot(&self) -> ImagePoint {
        let (nx, ny) = self.normal();
        ImagePoint::new(
            self.centre.x_px + self.offset_px * nx,
            self.centre.y_px + self.offset_px * ny,
        )
    }

    /// The part of the line inside the rectangle [0, width] × [0, height] (pixels), for
    /// drawing; `None` when the horizon misses the image.
    #[must_use]
    pub fn clip_to_image(&self, width_px: f64, height_px: f64) -> Option<(ImagePoint, ImagePoint)> {
        let p = self.foot();
        let (dx, dy) = (self.angle_rad.cos(), -self.angle_rad.sin());
        // Liang–Barsky on the infinite line p + t·(dx, dy).
        let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
        for (d, lo, hi, v) in [(dx, 0.0, width_px, p.x_px), (dy, 0.0, height_px, p.y_px)] {
            if d.abs() < 1e-12 {
                if v < lo || v > hi {
                    return None;
                }
            } else {
                let (a, b) = ((lo - v) / d, (hi - v) / d);
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
        }
        (t0 <= t1).then(|| {
            (
                ImagePoint::new(p.x_px + t0 * dx, p.y_px + t0 * dy),
                ImagePoint::new(p.x_px + t1 * dx, p.y_px + t1 * dy),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::camera::CameraPose;
    use crate::geometry::{Point, rotation_x, rotation_y, rotation_z};
    use approx::assert_relative_eq;
    use nalgebra::Vector3;

    fn pose(pitch: f64, roll: f64) -> CameraPose {
        CameraPose {
            camera: PinholeCamera::ers7(),
            field_from_camera: Transform::new(
                Vector3::new(0.0, 0.0, 20.0),
                rotation_z(0.7) * rotation_y(pitch) * rotation_x(roll),
            ),
        }
    }

    #[test]
    fn level_camera_has_horizon_through_the_centre() {
        let h = pose(0.0, 0.0).horizon().expect("horizon");
        assert_relative_eq!(h.angle_rad, 0.0, epsilon = 1e-12);
        assert_relative_eq!(h.offset_px, 0.0, epsilon = 1e-9);
        assert_relative_eq!(h.y_at(0.0).expect("row"), 80.0, epsilon = 1e-9);
        assert!(h.is_above(ImagePoint::new(50.0, 10.0)));
        assert!(!h.is_above(ImagePoint::new(50.0, 150.0)));
    }

    #[test]
    fn looking_down_moves_the_horizon_up_by_d_tan_pitch() {
        let h = pose(0.2, 0.0).horizon().expect("horizon");
        assert_relative_eq!(h.offset_px, 191.9 * 0.2_f64.tan(), epsilon = 0.1);
        assert_relative_eq!(
            h.y_at(104.0).expect("row"),
            80.0 - h.offset_px,
            epsilon = 1e-9
        );
    }

    #[test]
    fn rolled_camera_tilts_the_horizon() {
        // Camera rolled right side down (clockwise seen from behind): the scene turns
        // counter-clockwise in the image, so the horizon rises to the right by the roll angle.
        let h = pose(0.0, 0.25).horizon().expect("horizon");
        assert_relative_eq!(h.angle_rad, 0.25, epsilon = 1e-9);
        let left = h.y_at(0.0).expect("row");
        let right = h.y_at(208.0).expect("row");
        assert!(right < left);
    }

    #[test]
    fn far_ground_points_approach_the_horizon_from_below() {
        for &(pitch, roll) in &[(0.3, 0.0), (0.1, 0.2), (-0.2, -0.3)] {
            let pose = pose(pitch, roll);
            let h = pose.horizon().expect("horizon");
            let c = pose.position();
            // A ground point 100 m away along the camera's heading direction.
            let axis = pose.field_from_camera
                * crate::geometry::Vector::<crate::geometry::Camera>::new(1.0, 0.0, 0.0);
            let dir = Vector3::new(axis.coords.x, axis.coords.y, 0.0).normalize();
            let far = Point::<Field>::from(nalgebra::Point3::new(
                c.x() + dir.x * 10_000.0,
                c.y() + dir.y * 10_000.0,
                0.0,
            ));
            let img = pose.image_from_field(&far).expect("in front");
            let above = h.above_px(img);
            assert!(above < 0.0 && above > -1.0, "{above} for {pitch} {roll}");
        }
    }

    #[test]
    fn clipping_spans_the_image_for_a_level_horizon() {
        let h = pose(0.1, 0.0).horizon().expect("horizon");
        let (a, b) = h.clip_to_image(208.0, 160.0).expect("visible");
        assert_relative_eq!(a.x_px.min(b.x_px), 0.0, epsilon = 1e-9);
        assert_relative_eq!(a.x_px.max(b.x_px), 208.0, epsilon = 1e-9);
        // Looking steeply down pushes the horizon out of the top.
        let h = pose(0.9, 0.0).horizon().expect("horizon");
        assert!(h.clip_to_image(208.0, 160.0).is_none());
    }

    #[test]
    fn straight_down_has_no_horizon() {
        assert!(pose(std::f64::consts::FRAC_PI_2, 0.0).horizon().is_none());
    }
}
