//! Camera and body geometry shared by the renderer and recognition: where a pixel looks, where
//! a field point appears, where the horizon lies.
//!
//! Points and transforms carry the coordinate frame they live in as a type parameter, so a body
//! point cannot be fed where a field point is expected: [`Point<Field>`], [`Point<Body>`],
//! [`Point<Camera>`], and [`Transform<To, From>`] (read right to left: `body_from_camera` maps
//! camera coordinates to body coordinates, `field_from_body * body_from_camera` is
//! `field_from_camera`). Every frame is right-handed with lengths in centimetres:
//!
//! | frame | origin | axes |
//! |---|---|---|
//! | [`Field`] | centre of the field, on the carpet | x towards the yellow goal, y left, z up (`FORMATS.md`) |
//! | [`Body`] | the body centre | x forward, y left, z up (`FORMATS.md`) |
//! | [`Head`] | the head's upper tilt joint | x forward along the snout, y left, z up, all joints at zero |
//! | [`Camera`] | the camera's centre of projection | x along the optical axis, y left, z up in the image |
//!
//! The camera frame keeps the robot's axis convention (x forward) rather than the computer-vision
//! one (z forward), so a camera at rest with zero joints has the same axes as the body; image x
//! grows with −y and image y with −z.
//!
//! Modules: [`camera`] (the ERS-7 pinhole head camera), [`kinematics`] (joint readings → camera
//! pose), [`horizon`] (the horizon line in the image), [`overhead`] (a fish-eye overhead camera),
//! [`marker`] (the overhead robot marker).

pub mod camera;
pub mod horizon;
pub mod kinematics;
pub mod lens;
pub mod marker;
pub mod overhead;

use std::marker::PhantomData;
use std::ops::Mul;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

pub use camera::{CameraPose, ImagePoint, PinholeCamera};
pub use horizon::Horizon;
pub use kinematics::{
    BodyPose, Ers7Dimensions, HeadJoints, RobotPose, camera_pose_from_readings, write_camera_pose,
};
pub use lens::{LensError, LensModel};
pub use marker::{MarkerIdentity, MarkerTeam, RobotMarker};
pub use overhead::{OverheadCamera, OverheadProjector};

/// The field frame: origin at the centre spot, x towards the yellow goal, y left, z up (cm).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {}
/// The robot body frame: origin at the body centre, x forward, y left, z up (cm).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Body {}
/// The head frame: origin at the upper tilt joint, x forward along the snout, y left, z up (cm).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Head {}
/// A camera frame: origin at the centre of projection, x along the optical axis, y left, z up (cm).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Camera {}

/// A point in coordinate frame `F`, centimetres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point<F> {
    /// The coordinates, centimetres.
    pub coords: Point3<f64>,
    frame: PhantomData<F>,
}

impl<F> Point<F> {
    /// A point from its three coordinates, centimetres.
    #[must_use]
    pub fn new(x: f64, y: f64, z: f64) -> Self {
        Self::from(Point3::new(x, y, z))
    }

    /// x coordinate, centimetres.
    #[must_use]
    pub fn x(&self) -> f64 {
        self.coords.x
    }

    /// y coordinate, centimetres.
    #[must_use]
    pub fn y(&self) -> f64 {
        self.coords.y
    }

    /// z coordinate, centimetres.
    #[must_use]
    pub fn z(&self) -> f64 {
        self.coords.z
    }

    /// The vector from the frame's origin to the point, centimetres.
    #[must_use]
    pub fn to_vector(&self) -> Vector<F> {
        Vector::from(self.coords.coords)
    }

    /// Distance to another point of the same frame, centimetres.
    #[must_use]
    pub fn distance_to(&self, other: &Self) -> f64 {
        (self.coords - other.coords).norm()
    }

    /// The coordinates as an array `[x, y, z]`, centimetres (for serialised ground truth).
    #[must_use]
    pub fn to_array(&self) -> [f64; 3] {
        [self.coords.x, self.coords.y, self.coords.z]
    }
}

impl<F> From<Point3<f64>> for Point<F> {
    fn from(coords: Point3<f64>) -> Self {
        Self {
            coords,
            frame: PhantomData,
        }
    }
}

/// A direction or displacement in coordinate frame `F`, centimetres (unit length where a method
/// says so).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vector<F> {
    /// The components, centimetres.
    pub coords: Vector3<f64>,
    frame: PhantomData<F>,
}

impl<F> Vector<F> {
    /// A vector from its three components, centimetres.
    #[must_use]
    pub fn new(x: f64, y: f64, z: f64) -> Self {
        Self::from(Vector3::new(x, y, z))
    }

    /// The same direction with length 1, or `None` for a zero or non-finite vector.
    #[must_use]
    pub fn normalized(&self) -> Option<Self> {
        let n = self.coords.norm();
        (n > 0.0 && n.is_finite()).then(|| Self::from(self.coords / n))
    }
}

impl<F> From<Vector3<f64>> for Vector<F> {
    fn from(coords: Vector3<f64>) -> Self {
        Self {
            coords,
            frame: PhantomData,
        }
    }
}

/// A rigid transform taking coordinates in frame `From` to frame `To` (rotation, then
/// translation). Name values `to_from_from`: `field_from_body`, `body_from_camera`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform<To, From> {
    /// The rigid motion; translations in centimetres.
    pub isometry: Isometry3<f64>,
    frames: PhantomData<(To, From)>,
}

impl<To, From> Transform<To, From> {
    /// A transform from a rigid motion (translation in centimetres).
    #[must_use]
    pub fn from_isometry(isometry: Isometry3<f64>) -> Self {
        Self {
            isometry,
            frames: PhantomData,
        }
    }

    /// The transform that maps `From` coordinates to `To` coordinates by rotating by `rotation`
    /// and then moving by `translation_cm`.
    #[must_use]
    pub fn new(translation_cm: Vector3<f64>, rotation: UnitQuaternion<f64>) -> Self {
        Self::from_isometry(Isometry3::from_parts(
            Translation3::from(translation_cm),
            rotation,
        ))
    }

    /// The identity between two frames that coincide.
    #[must_use]
    pub fn identity() -> Self {
        Self::from_isometry(Isometry3::identity())
    }

    /// The inverse transform, `From` ← `To` becomes `To` → `From`.
    #[must_use]
    pub fn inverse(&self) -> Transform<From, To> {
        Transform::from_isometry(self.isometry.inverse())
    }

    /// Where the origin of `From` lies in `To`, centimetres.
    #[must_use]
    pub fn origin(&self) -> Point<To> {
        Point::from(Point3::from(self.isometry.translation.vector))
    }

    /// The rotation part.
    #[must_use]
    pub fn rotation(&self) -> UnitQuaternion<f64> {
        self.isometry.rotation
    }
}

impl<A, B, C> Mul<Transform<B, C>> for Transform<A, B> {
    type Output = Transform<A, C>;
    fn mul(self, rhs: Transform<B, C>) -> Transform<A, C> {
        Transform::from_isometry(self.isometry * rhs.isometry)
    }
}

impl<A, B> Mul<Point<B>> for Transform<A, B> {
    type Output = Point<A>;
    fn mul(self, rhs: Point<B>) -> Point<A> {
        Point::from(self.isometry * rhs.coords)
    }
}

impl<A, B> Mul<Vector<B>> for Transform<A, B> {
    type Output = Vector<A>;
    fn mul(self, rhs: Vector<B>) -> Vector<A> {
        Vector::from(self.isometry.rotation * rhs.coords)
    }
}

/// A pose serialised for ground truth and streams: position in centimetres and the rotation as
/// yaw (about z), pitch (about y, positive nose *down*, as the body pitch of
/// [`crate::sensors::SensorReadings`]) and roll (about x, positive right side down), radians,
/// applied in the order yaw · pitch · roll.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseRecord {
    /// Position of the frame's origin, centimetres `[x, y, z]`.
    pub position_cm: [f64; 3],
    /// Rotation about z, radians, counter-clockwise seen from above.
    pub yaw_rad: f64,
    /// Rotation about y, radians; positive turns +x downwards.
    pub pitch_rad: f64,
    /// Rotation about x, radians; positive turns +y upwards (right side down).
    pub roll_rad: f64,
}

impl PoseRecord {
    /// The record of a transform.
    #[must_use]
    pub fn from_transform<A, B>(t: &Transform<A, B>) -> Self {
        let (roll, pitch, yaw) = t.isometry.rotation.euler_angles();
        Self {
            position_cm: t.origin().to_array(),
            yaw_rad: yaw,
            pitch_rad: pitch,
            roll_rad: roll,
        }
    }

    /// The transform this record describes.
    #[must_use]
    pub fn to_transform<A, B>(&self) -> Transform<A, B> {
        let [x, y, z] = self.position_cm;
        Transform::new(
            Vector3::new(x, y, z),
            UnitQuaternion::from_euler_angles(self.roll_rad, self.pitch_rad, self.yaw_rad),
        )
    }
}

/// Rotation about the z axis by `angle_rad` (counter-clockwise seen from above: +x turns to +y).
#[must_use]
pub fn rotation_z(angle_rad: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle_rad)
}

/// Rotation about the y axis by `angle_rad` (right-handed: positive turns +x towards −z, i.e.
/// nose down).
#[must_use]
pub fn rotation_y(angle_rad: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::y_axis(), angle_rad)
}

/// Rotation about the x axis by `angle_rad` (right-handed: positive turns +y towards +z, i.e.
/// right side down).
#[must_use]
pub fn rotation_x(angle_rad: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), angle_rad)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn transforms_compose_right_to_left_and_invert() {
        let field_from_body: Transform<Field, Body> =
            Transform::new(Vector3::new(100.0, 50.0, 12.0), rotation_z(0.5));
        let body_from_camera: Transform<Body, Camera> =
            Transform::new(Vector3::new(10.0, 0.0, 8.0), rotation_y(0.3));
        let field_from_camera = field_from_body * body_from_camera;
        let p = Point::<Camera>::new(30.0, -4.0, 2.0);
        let direct = field_from_camera * p;
        let stepwise = field_from_body * (body_from_camera * p);
        assert_relative_eq!(direct.coords, stepwise.coords, epsilon = 1e-9);
        let back = field_from_camera.inverse() * direct;
        assert_relative_eq!(back.coords, p.coords, epsilon = 1e-9);
    }

    #[test]
    fn rotation_signs_match_formats_md() {
        let x = Vector3::x();
        // Pitch positive nose down.
        assert!((rotation_y(0.2) * x).z < 0.0);
        // Yaw positive to the left.
        assert!((rotation_z(0.2) * x).y > 0.0);
        // Roll positive right side down: the left (+y) side goes up.
        assert!((rotation_x(0.2) * Vector3::y()).z > 0.0);
    }

    #[test]
    fn pose_record_round_trips() {
        let t: Transform<Field, Camera> = Transform::new(
            Vector3::new(1.0, 2.0, 3.0),
            rotation_z(0.4) * rotation_y(0.3) * rotation_x(-0.1),
        );
        let r = PoseRecord::from_transform(&t);
        assert_relative_eq!(r.yaw_rad, 0.4, epsilon = 1e-9);
        assert_relative_eq!(r.pitch_rad, 0.3, epsilon = 1e-9);
        assert_relative_eq!(r.roll_rad, -0.1, epsilon = 1e-9);
        let back: Transform<Field, Camera> = r.to_transform();
        assert_relative_eq!(back.isometry, t.isometry, epsilon = 1e-9);
    }
}
