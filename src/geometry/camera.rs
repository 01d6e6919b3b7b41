//! The AIBO ERS-7 head camera as an ideal pinhole: pixel ↔ ray, bearing and elevation.
//!
//! The ERS-7 camera delivers 208×160 pixels over a 56.9° horizontal and 45.2° vertical field of
//! view (Sony's ERS-7 model information). The effective camera distance — the focal length in
//! pixels — is `d = (W/2) / tan(FOV/2) = 104 / tan(28.45°) = 191.9 px`. The vertical figure gives
//! `80 / tan(22.6°) = 192.2 px`, the same within the rounding of the published angles, so pixels
//! are taken as square and `d` is used for both axes. Lens distortion of the ERS-7 is small and is
//! not modelled (vignetting is, in the renderer).
//!
//! Image coordinates follow `FORMATS.md`: x right, y down, pixel (i, j) covers
//! [i, i+1) × [j, j+1), so the optical centre of a 208×160 image is (104, 80). Rays are in the
//! [`Camera`] frame (x along the optical axis, y left, z up), so a point left of the centre has a
//! positive bearing and a point above the centre a positive elevation.

use serde::{Deserialize, Serialize};

use super::horizon::Horizon;
use super::{Camera, Field, Point, Transform, Vector};
pub use crate::frame::ImagePoint;

/// Horizontal field of view of the ERS-7 head camera, degrees.
pub const ERS7_HORIZONTAL_FOV_DEG: f64 = 56.9;
/// Vertical field of view of the ERS-7 head camera, degrees.
pub const ERS7_VERTICAL_FOV_DEG: f64 = 45.2;

/// An undistorted pinhole camera with square pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PinholeCamera {
    /// Image width, pixels.
    pub width_px: usize,
    /// Image height, pixels.
    pub height_px: usize,
    /// Effective camera distance (focal length), pixels.
    pub focal_px: f64,
    /// Where the optical axis meets the image, pixels.
    pub centre: ImagePoint,
}

impl PinholeCamera {
    /// The ERS-7 head camera: 208×160, d = 104 / tan(56.9°/2) ≈ 191.9 px, centre (104, 80).
    #[must_use]
    pub fn ers7() -> Self {
        Self::from_horizontal_fov(208, 160, ERS7_HORIZONTAL_FOV_DEG.to_radians())
    }

    /// A camera whose horizontal field of view is `fov_rad`, optical axis at the image centre.
    #[must_use]
    pub fn from_horizontal_fov(width_px: usize, height_px: usize, fov_rad: f64) -> Self {
        let (w, h) = (width_px as f64, height_px as f64);
        Self {
            width_px,
            height_px,
            focal_px: (w / 2.0) / (fov_rad / 2.0).tan(),
            centre: ImagePoint::new(w / 2.0, h / 2.0),
        }
    }

    /// Horizontal field of view, radians.
    #[must_use]
    pub fn horizontal_fov_rad(&self) -> f64 {
        let w = self.width_px as f64;
        2.0 * (w / 2.0 / self.focal_px).atan()
    }

    /// Vertical field of view, radians.
    #[must_use]
    pub fn vertical_fov_rad(&self) -> f64 {
        let h = self.height_px as f64;
        2.0 * (h / 2.0 / self.focal_px).atan()
    }

    /// The direction (camera frame, not normalised: x component = focal length in pixels) in
    /// which an image point looks.
    #[must_use]
    pub fn ray(&self, p: ImagePoint) -> Vector<Camera> {
        Vector::new(
            self.focal_px,
            self.centre.x_px - p.x_px,
            self.centre.y_px - p.y_px,
        )
    }

    /// The unit direction in which an image point looks, camera frame.
    #[must_use]
    pub fn unit_ray(&self, p: ImagePoint) -> Vector<Camera> {
        let r = self.ray(p);
        Vector::from(r.coords / r.coords.norm())
    }

    /// Where a camera-frame direction or point appears in the image, or `None` if it lies at or
    /// behind the camera's plane (x ≤ 0). The result may lie outside the image.
    #[must_use]
    pub fn project_direction(&self, v: &Vector<Camera>) -> Option<ImagePoint> {
        let c = v.coords;
        (c.x > 1e-12 && c.iter().all(|a| a.is_finite())).then(|| {
            ImagePoint::new(
                self.centre.x_px - self.focal_px * c.y / c.x,
                self.centre.y_px - self.focal_px * c.z / c.x,
            )
        })
    }

    /// Where a camera-frame point appears in the image (see [`Self::project_direction`]).
    #[must_use]
    pub fn project(&self, p: &Point<Camera>) -> Option<ImagePoint> {
        self.project_direction(&p.to_vector())
    }

    /// Bearing of an image point relative to the optical axis, radians, positive left.
    #[must_use]
    pub fn bearing_rad(&self, p: ImagePoint) -> f64 {
        (self.centre.x_px - p.x_px).atan2(self.focal_px)
    }

    /// Elevation of an image point above the camera's x–y plane, radians, positive up (the angle
    /// of its ray above that plane, not the plain row angle).
    #[must_use]
    pub fn elevation_rad(&self, p: ImagePoint) -> f64 {
        let r = self.ray(p).coords;
        r.z.atan2(r.x.hypot(r.y))
    }

    /// Whether an image point lies inside the image rectangle [0, W) × [0, H).
    #[must_use]
    pub fn contains(&self, p: ImagePoint) -> bool {
        let (w, h) = (self.width_px as f64, self.height_px as f64);
        p.x_px >= 0.0 && p.y_px >= 0.0 && p.x_px < w && p.y_px < h
    }

    /// Image radius in pixels of a sphere of `radius_cm` whose centre is `distance_cm` from the
    /// camera (exact for a sphere on the optical axis; a good estimate near it). `None` when the
    /// camera is inside the sphere.
    #[must_use]
    pub fn sphere_radius_px(&self, radius_cm: f64, distance_cm: f64) -> Option<f64> {
        (distance_cm > radius_cm).then(|| {
            let half_angle = (radius_cm / distance_cm).asin();
            self.focal_px * half_angle.tan()
        })
    }
}

/// A pinhole camera placed in the field: what recognition and the renderer both need to go
/// between image points and field points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPose {
    /// The camera's intrinsics.
    pub camera: PinholeCamera,
    /// The camera's pose in the field (cm). For robot-relative work use a robot standing at the
    /// field origin facing +x ([`super::RobotPose::default`]): the field frame then is the
    /// robot's ground frame.
    pub field_from_camera: Transform<Field, Camera>,
}

impl CameraPose {
    /// Where a field point appears in the image, or `None` behind the camera.
    #[must_use]
    pub fn image_from_field(&self, p: &Point<Field>) -> Option<ImagePoint> {
        self.camera
            .project(&(self.field_from_camera.inverse() * *p))
    }

    /// The unit direction, in field axes, in which an image point looks.
    #[must_use]
    pub fn field_ray(&self, p: ImagePoint) -> Vector<Field> {
        self.field_from_camera * self.camera.unit_ray(p)
    }

    /// The camera's centre of projection in the field, centimetres.
    #[must_use]
    pub fn position(&self) -> Point<Field> {
        self.field_from_camera.origin()
    }

    /// Where an image point's ray meets the horizontal plane at height `z_cm` (0 = the carpet,
    /// 4.25 = ball centres), or `None` when the ray does not go down (or up) to it.
    #[must_use]
    pub fn point_on_plane(&self, p: ImagePoint, z_cm: f64) -> Option<Point<Field>> {
        let origin = self.position();
        let ray = self.field_ray(p).coords;
        if ray.z.abs() < 1e-12 {
            return None;
        }
        let t = (z_cm - origin.z()) / ray.z;
        (t > 0.0 && t.is_finite()).then(|| Point::from(origin.coords + ray * t))
    }

    /// The horizon line in the image, or `None` when the camera looks straight up or down.
    #[must_use]
    pub fn horizon(&self) -> Option<Horizon> {
        Horizon::from_pose(&self.camera, &self.field_from_camera)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn ers7_effective_distance_is_191_9_px() {
        let cam = PinholeCamera::ers7();
        assert!((cam.focal_px - 191.9).abs() < 0.05, "{}", cam.focal_px);
        assert_eq!(cam.centre, ImagePoint::new(104.0, 80.0));
        assert_relative_eq!(
            cam.horizontal_fov_rad().to_degrees(),
            ERS7_HORIZONTAL_FOV_DEG,
            epsilon = 1e-9
        );
        // The published vertical field of view agrees with square pixels to 0.1°.
        assert!((cam.vertical_fov_rad().to_degrees() - ERS7_VERTICAL_FOV_DEG).abs() < 0.1);
    }

    #[test]
    fn image_ray_image_round_trip() {
        let cam = PinholeCamera::ers7();
        for &(x, y) in &[(0.0, 0.0), (104.0, 80.0), (207.5, 159.5), (13.25, 150.0)] {
            let p = ImagePoint::new(x, y);
            let back = cam
                .project_direction(&cam.unit_ray(p))
                .expect("in front of the camera");
            assert_relative_eq!(back.x_px, x, epsilon = 1e-9);
            assert_relative_eq!(back.y_px, y, epsilon = 1e-9);
        }
    }

    #[test]
    fn angle_signs_follow_formats_md() {
        let cam = PinholeCamera::ers7();
        let left_top = ImagePoint::new(10.0, 10.0);
        assert!(cam.bearing_rad(left_top) > 0.0);
        assert!(cam.elevation_rad(left_top) > 0.0);
        let right_bottom = ImagePoint::new(200.0, 150.0);
        assert!(cam.bearing_rad(right_bottom) < 0.0);
        assert!(cam.elevation_rad(right_bottom) < 0.0);
        // The left edge is half the field of view to the left.
        assert_relative_eq!(
            cam.bearing_rad(ImagePoint::new(0.0, 80.0)),
            ERS7_HORIZONTAL_FOV_DEG.to_radians() / 2.0,
            epsilon = 1e-9
        );
    }

    #[test]
    fn points_behind_the_camera_do_not_project() {
        let cam = PinholeCamera::ers7();
        assert!(cam.project(&Point::new(-10.0, 0.0, 0.0)).is_none());
        assert!(cam.project(&Point::new(0.0, 5.0, 0.0)).is_none());
        assert!(cam.project(&Point::new(f64::NAN, 5.0, 0.0)).is_none());
        let p = cam.project(&Point::new(100.0, 0.0, 0.0)).expect("ahead");
        assert_eq!(p, cam.centre);
    }

    #[test]
    fn a_level_camera_sees_the_ground_below_the_centre() {
        use crate::geometry::rotation_y;
        use nalgebra::Vector3;
        // Camera 20 cm up looking 0.3 rad down: the centre pixel hits the carpet at
        // 20 / tan(0.3) cm ahead.
        let pose = CameraPose {
            camera: PinholeCamera::ers7(),
            field_from_camera: Transform::new(Vector3::new(0.0, 0.0, 20.0), rotation_y(0.3)),
        };
        let g = pose
            .point_on_plane(pose.camera.centre, 0.0)
            .expect("looks down");
        assert_relative_eq!(g.x(), 20.0 / 0.3_f64.tan(), epsilon = 1e-9);
        assert_relative_eq!(g.y(), 0.0, epsilon = 1e-9);
        let back = pose.image_from_field(&g).expect("in front");
        assert_relative_eq!(back.x_px, 104.0, epsilon = 1e-9);
        assert_relative_eq!(back.y_px, 80.0, epsilon = 1e-9);
        // The top row looks above the horizon: it never meets the carpet.
        assert!(
            pose.point_on_plane(ImagePoint::new(104.0, 0.0), 0.0)
                .is_none()
        );
    }

    #[test]
    fn ball_radius_matches_small_angle_estimate() {
        let cam = PinholeCamera::ers7();
        // An 8.5 cm ball 100 cm away: about d · 4.25 / 100 ≈ 8.16 px.
        let r = cam.sphere_radius_px(4.25, 100.0).expect("outside");
        assert!((r - 8.16).abs() < 0.02, "{r}");
        assert!(cam.sphere_radius_px(4.25, 3.0).is_none());
    }
}
