//! An overhead camera above the field: pinhole plus radial (barrel / fish-eye) distortion.
//!
//! Teams filmed games with a wide-angle camera hung over the field; its frames (UYVY 640×480)
//! give the true positions of ball and robots. The model is the usual radial one: a camera-frame
//! point (x forward along the optical axis, y left, z up) has normalised image coordinates
//! `u = −y/x` (right) and `v = −z/x` (down); with `r² = u² + v²` the lens moves it to
//! `(u, v)·(1 + k1·r² + k2·r⁴)`, and the pixel is `centre + focal·(u_d, v_d)`. Barrel
//! distortion has `k1 < 0`. Going back (image → ray) solves the radial polynomial by Newton's
//! method, which converges in a handful of steps wherever the mapping is monotonic.
//!
//! A camera whose intrinsics come from a checkerboard (ROS `camera_info`) carries its
//! [`LensModel`] instead of k1/k2 and may have a vertical focal length of its own (`fy`).

use nalgebra::{Matrix3, Point3, Rotation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::camera::ImagePoint;
use super::lens::LensModel;
use super::{Camera, Field, Point, PoseRecord, Transform, Vector};

/// A distorted overhead camera and its pose above the field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OverheadCamera {
    /// Image width, pixels.
    pub width_px: usize,
    /// Image height, pixels.
    pub height_px: usize,
    /// Focal length, pixels (square pixels).
    pub focal_px: f64,
    /// Where the optical axis meets the image, pixels.
    pub centre: ImagePoint,
    /// First radial distortion coefficient (negative: barrel).
    pub k1: f64,
    /// Second radial distortion coefficient.
    pub k2: f64,
    /// The camera's pose in the field (position in cm, yaw/pitch/roll in radians).
    pub pose: PoseRecord,
    /// The vertical focal length when it differs from `focal_px` (a checkerboard calibration's
    /// `fy`), pixels; `None`: square pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focal_y_px: Option<f64>,
    /// A checkerboard-calibrated lens (ROS's `distortion_model`) in place of `k1`/`k2` (which
    /// are then 0 and unused); `None`: the radial k1/k2 model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lens: Option<LensModel>,
}

impl OverheadCamera {
    /// A 640×480 camera 350 cm above the centre spot looking straight down, image x along field
    /// +x (towards the yellow goal) and image y along field −y, focal 420 px, k1 = −0.18,
    /// k2 = 0.03: it sees the whole 600×400 cm carpet with a moderate fish-eye bend.
    #[must_use]
    pub fn above_field_2005() -> Self {
        Self::looking_down(640, 480, 350.0, 420.0, -0.18, 0.03)
    }

    /// A camera `height_cm` above the centre spot looking straight down (image x along field
    /// +x, image y along field −y).
    #[must_use]
    pub fn looking_down(
        width_px: usize,
        height_px: usize,
        height_cm: f64,
        focal_px: f64,
        k1: f64,
        k2: f64,
    ) -> Self {
        // Camera axes in field axes: optical axis down, camera y (image left) = field −x,
        // camera z (image up) = field +y.
        let m = Matrix3::from_columns(&[
            Vector3::new(0.0, 0.0, -1.0),
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
        ]);
        let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
        let t: Transform<Field, Camera> =
            Transform::new(Vector3::new(0.0, 0.0, height_cm), rotation);
        let centre = ImagePoint::new(width_px as f64 / 2.0, height_px as f64 / 2.0);
        Self {
            width_px,
            height_px,
            focal_px,
            centre,
            k1,
            k2,
            pose: PoseRecord::from_transform(&t),
            focal_y_px: None,
            lens: None,
        }
    }

    /// The same camera for a frame of `width`×`height` pixels (the same view resampled): focal
    /// lengths and principal point scaled with the frame (pixel edges at whole numbers, so a
    /// pure scale; square pixels stay square), the lens unchanged (it works in normalised coordinates).
    #[must_use]
    pub fn scaled_to(&self, width: usize, height: usize) -> Self {
        let sx = width as f64 / self.width_px.max(1) as f64;
        let sy = height as f64 / self.height_px.max(1) as f64;
        Self {
            width_px: width,
            height_px: height,
            focal_px: self.focal_px * sx,
            focal_y_px: self.focal_y_px.map(|f| f * sy),
            centre: ImagePoint::new(self.centre.x_px * sx, self.centre.y_px * sy),
            ..*self
        }
    }

    /// The camera's pose in the field.
    #[must_use]
    pub fn field_from_camera(&self) -> Transform<Field, Camera> {
        self.pose.to_transform()
    }

    /// The vertical focal length, pixels (`focal_px` unless the intrinsics give another).
    #[must_use]
    pub fn focal_y(&self) -> f64 {
        self.focal_y_px.unwrap_or(self.focal_px)
    }

    /// Applies the lens: undistorted normalised coordinates → distorted ones.
    #[must_use]
    pub fn distort(&self, u: f64, v: f64) -> (f64, f64) {
        if let Some(lens) = &self.lens {
            return lens.distort(u, v);
        }
        let r2 = u * u + v * v;
        let f = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
        (u * f, v * f)
    }

    /// Removes the lens: distorted normalised coordinates → undistorted ones, by Newton's method
    /// on the radius. `None` where the lens mapping folds over (not monotonic) or does not
    /// converge.
    #[must_use]
    pub fn undistort(&self, ud: f64, vd: f64) -> Option<(f64, f64)> {
        if let Some(lens) = &self.lens {
            return lens.undistort(ud, vd).ok();
        }
        let rd = ud.hypot(vd);
        if !rd.is_finite() {
            return None;
        }
        if rd < 1e-15 {
            return Some((ud, vd));
        }
        let mut r = rd;
        for _ in 0..50 {
            let r2 = r * r;
            let f = r * (1.0 + self.k1 * r2 + self.k2 * r2 * r2) - rd;
            let df = 1.0 + 3.0 * self.k1 * r2 + 5.0 * self.k2 * r2 * r2;
            if df <= 1e-9 {
                return None;
            }
            let step = f / df;
            r -= step;
            if step.abs() < 1e-13 {
                return (r > 0.0).then(|| (ud * r / rd, vd * r / rd));
            }
        }
        None
    }

    /// Where a field point appears in the image, or `None` behind the camera. The result may lie
    /// outside the image. (Many points: [`OverheadProjector`], which builds the pose once.)
    #[must_use]
    pub fn image_from_field(&self, p: &Point<Field>) -> Option<ImagePoint> {
        let c = self.field_from_camera().inverse() * *p;
        self.image_from_camera(&c)
    }

    /// This camera ready to carry many points: its pose's transforms built once.
    #[must_use]
    pub fn projector(&self) -> OverheadProjector {
        let field_from_camera = self.field_from_camera();
        OverheadProjector {
            camera: *self,
            camera_from_field: field_from_camera.inverse(),
            field_from_camera,
        }
    }

    /// Where a camera-frame point appears in the image, or `None` behind the camera.
    #[must_use]
    pub fn image_from_camera(&self, c: &Point<Camera>) -> Option<ImagePoint> {
        if c.x() <= 1e-12 || !c.coords.iter().all(|a| a.is_finite()) {
            return None;
        }
        let (ud, vd) = self.distort(-c.y() / c.x(), -c.z() / c.x());
        Some(ImagePoint::new(
            self.centre.x_px + self.focal_px * ud,
            self.centre.y_px + self.focal_y() * vd,
        ))
    }

    /// The unit ray, camera frame, through an image point; `None` where undistortion fails.
    #[must_use]
    pub fn camera_ray(&self, p: ImagePoint) -> Option<Vector<Camera>> {
        let (u, v) = self.undistort(
            (p.x_px - self.centre.x_px) / self.focal_px,
            (p.y_px - self.centre.y_px) / self.focal_y(),
        )?;
        Vector::new(1.0, -u, -v).normalized()
    }

    /// Where an image point's ray meets the horizontal plane at height `z_cm` (0 = the carpet),
    /// or `None` when it does not.
    #[must_use]
    pub fn field_from_image(&self, p: ImagePoint, z_cm: f64) -> Option<Point<Field>> {
        self.field_from_image_through(&self.field_from_camera(), p, z_cm)
    }

    fn field_from_image_through(
        &self,
        field_from_camera: &Transform<Field, Camera>,
        p: ImagePoint,
        z_cm: f64,
    ) -> Option<Point<Field>> {
        let ray = (*field_from_camera * self.camera_ray(p)?).coords;
        let origin = field_from_camera.origin().coords;
        if ray.z.abs() < 1e-12 {
            return None;
        }
        let t = (z_cm - origin.z) / ray.z;
        (t > 0.0 && t.is_finite()).then(|| Point::from(Point3::from(origin.coords + ray * t)))
    }
}

/// An [`OverheadCamera`] with its pose's transforms built once ([`OverheadCamera::projector`]):
/// the same results bit for bit, without rebuilding the rotation from the pose's angles for
/// every point — the overhead recogniser carries thousands of points through the lens a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverheadProjector {
    camera: OverheadCamera,
    field_from_camera: Transform<Field, Camera>,
    camera_from_field: Transform<Camera, Field>,
}

impl OverheadProjector {
    /// The camera.
    #[must_use]
    pub fn camera(&self) -> &OverheadCamera {
        &self.camera
    }

    /// As [`OverheadCamera::image_from_field`].
    #[must_use]
    pub fn image_from_field(&self, p: &Point<Field>) -> Option<ImagePoint> {
        self.camera
            .image_from_camera(&(self.camera_from_field * *p))
    }

    /// As [`OverheadCamera::field_from_image`].
    #[must_use]
    pub fn field_from_image(&self, p: ImagePoint, z_cm: f64) -> Option<Point<Field>> {
        self.camera
            .field_from_image_through(&self.field_from_camera, p, z_cm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn the_centre_pixel_looks_straight_down() {
        let cam = OverheadCamera::above_field_2005();
        let g = cam.field_from_image(cam.centre, 0.0).expect("on carpet");
        assert_relative_eq!(g.x(), 0.0, epsilon = 1e-9);
        assert_relative_eq!(g.y(), 0.0, epsilon = 1e-9);
        // Image right is field +x, image down is field −y.
        let right = cam
            .field_from_image(ImagePoint::new(400.0, 240.0), 0.0)
            .expect("on carpet");
        assert!(right.x() > 10.0 && right.y().abs() < 1e-9);
        let down = cam
            .field_from_image(ImagePoint::new(320.0, 300.0), 0.0)
            .expect("on carpet");
        assert!(down.y() < -10.0 && down.x().abs() < 1e-9);
    }

    #[test]
    fn undistort_inverts_distort() {
        let cam = OverheadCamera::above_field_2005();
        for &(u, v) in &[(0.0, 0.0), (0.3, -0.2), (-0.9, 0.6), (1.1, 0.3)] {
            let (ud, vd) = cam.distort(u, v);
            let (u2, v2) = cam.undistort(ud, vd).expect("monotonic");
            assert_relative_eq!(u2, u, epsilon = 1e-10);
            assert_relative_eq!(v2, v, epsilon = 1e-10);
        }
        assert!(cam.undistort(f64::NAN, 0.0).is_none());
    }

    #[test]
    fn field_image_field_round_trip_over_the_carpet() {
        let cam = OverheadCamera::above_field_2005();
        for &(x, y) in &[(0.0, 0.0), (270.0, 180.0), (-300.0, -200.0), (120.0, -40.0)] {
            let p = Point::<Field>::new(x, y, 0.0);
            let img = cam.image_from_field(&p).expect("below camera");
            assert!(
                img.x_px >= 0.0 && img.x_px < 640.0 && img.y_px >= 0.0 && img.y_px < 480.0,
                "{img:?} for ({x}, {y})"
            );
            let back = cam.field_from_image(img, 0.0).expect("on carpet");
            assert_relative_eq!(back.x(), x, epsilon = 1e-6);
            assert_relative_eq!(back.y(), y, epsilon = 1e-6);
        }
    }

    #[test]
    fn barrel_distortion_bends_straight_lines_outwards() {
        // The side line y = 180 cm: its middle appears further from the image centre, relative
        // to the chord between its ends, than a pinhole would show (barrel bulges outwards).
        let cam = OverheadCamera::above_field_2005();
        let at = |x: f64| {
            cam.image_from_field(&Point::new(x, 180.0, 0.0))
                .expect("visible")
        };
        let (a, m, b) = (at(-270.0), at(0.0), at(270.0));
        let chord_y = (a.y_px + b.y_px) / 2.0;
        assert!(m.y_px < chord_y - 3.0, "middle {} chord {chord_y}", m.y_px);
        let pinhole = OverheadCamera {
            k1: 0.0,
            k2: 0.0,
            ..cam
        };
        let at = |x: f64| {
            pinhole
                .image_from_field(&Point::new(x, 180.0, 0.0))
                .expect("visible")
        };
        assert_relative_eq!(at(0.0).y_px, at(270.0).y_px, epsilon = 1e-9);
    }

    #[test]
    fn pose_record_keeps_the_straight_down_rotation() {
        let cam = OverheadCamera::above_field_2005();
        let axis = cam.field_from_camera() * Vector::<Camera>::new(1.0, 0.0, 0.0);
        assert_relative_eq!(axis.coords, Vector3::new(0.0, 0.0, -1.0), epsilon = 1e-9);
        let json = serde_json::to_string(&cam).expect("serialise");
        let back: OverheadCamera = serde_json::from_str(&json).expect("parse");
        assert_eq!(back, cam);
    }
}
