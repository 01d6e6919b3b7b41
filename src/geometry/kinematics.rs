//! The ERS-7's body-to-camera chain, driven by joint readings: where the head camera is and where
//! it looks.
//!
//! The chain, from the body centre outwards (all joints at zero: head level, looking forward):
//!
//! 1. the lower tilt joint ("tilt1", [`SensorReadings::head_tilt_rad`]) sits
//!    [`Ers7Dimensions::neck_base_forward_cm`] ahead of and [`Ers7Dimensions::neck_base_up_cm`]
//!    above the body centre and tilts the whole neck;
//! 2. the pan joint sits [`Ers7Dimensions::neck_length_cm`] up the neck and turns the head;
//! 3. the upper tilt joint ("tilt2", nod, [`SensorReadings::neck_tilt_rad`]) is taken to coincide
//!    with the pan axis, as the ERS-7 model drawing shows within a few millimetres;
//! 4. the camera sits [`Ers7Dimensions::camera_forward_cm`] ahead of and
//!    [`Ers7Dimensions::camera_up_cm`] above (negative: below) the upper tilt joint, looking
//!    along the snout.
//!
//! Sources for the lengths: Sony's "ERS-7 Model Information" drawings (2004), as the GermanTeam
//! 2004/2005 code base (`RobotDimensionsERS7`) quotes them: neck base 67.5 mm ahead and 19.5 mm
//! above the body centre, neck 80 mm, camera 81.06 mm ahead and 14.6 mm below the head's tilt
//! axis. They are quoted from that secondary source, not re-measured; every one is a field of
//! [`Ers7Dimensions`] so a team can correct them. The body centre's height above the ground and
//! the body's pitch depend on the walk; [`BodyPose::ERS7_STANCE`] is a typical walking stance
//! (body centre 12 cm up, 0.10 rad nose down), our choice rather than a measured figure.
//!
//! Signs follow `FORMATS.md` and [`SensorReadings`]: pan positive left, tilts positive up, body
//! pitch positive nose down, roll positive right side down.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::{Body, Camera, Field, Head, Transform, rotation_x, rotation_y, rotation_z};
use crate::sensors::SensorReadings;

/// Standard gravity, m/s², for turning accelerations into tilts.
pub const GRAVITY_MPS2: f64 = 9.806_65;

/// Lengths of the ERS-7's head chain, centimetres (see the module documentation for sources).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Ers7Dimensions {
    /// How far the lower tilt joint lies ahead of the body centre, centimetres.
    pub neck_base_forward_cm: f64,
    /// How far the lower tilt joint lies above the body centre, centimetres.
    pub neck_base_up_cm: f64,
    /// From the lower tilt joint up the neck to the pan and upper tilt joints, centimetres.
    pub neck_length_cm: f64,
    /// From the upper tilt joint forward to the camera, centimetres.
    pub camera_forward_cm: f64,
    /// From the upper tilt joint up to the camera, centimetres (negative: below).
    pub camera_up_cm: f64,
}

impl Ers7Dimensions {
    /// The ERS-7 figures quoted in the module documentation.
    pub const ERS7: Self = Self {
        neck_base_forward_cm: 6.75,
        neck_base_up_cm: 1.95,
        neck_length_cm: 8.0,
        camera_forward_cm: 8.106,
        camera_up_cm: -1.46,
    };

    /// Head (upper tilt joint) pose in the body for the given joint angles.
    #[must_use]
    pub fn body_from_head(&self, joints: &HeadJoints) -> Transform<Body, Head> {
        // Tilt positive up is a negative rotation about +y (which turns the nose down).
        let neck_base = Transform::<Body, Head>::new(
            Vector3::new(self.neck_base_forward_cm, 0.0, self.neck_base_up_cm),
            rotation_y(-joints.tilt1_rad),
        );
        let neck_top = Transform::<Head, Head>::new(
            Vector3::new(0.0, 0.0, self.neck_length_cm),
            rotation_z(joints.pan_rad) * rotation_y(-joints.tilt2_rad),
        );
        neck_base * neck_top
    }

    /// The camera's fixed pose in the head frame.
    #[must_use]
    pub fn head_from_camera(&self) -> Transform<Head, Camera> {
        Transform::new(
            Vector3::new(self.camera_forward_cm, 0.0, self.camera_up_cm),
            UnitQuaternion::identity(),
        )
    }

    /// The camera pose in the body for the given joint angles.
    #[must_use]
    pub fn body_from_camera(&self, joints: &HeadJoints) -> Transform<Body, Camera> {
        self.body_from_head(joints) * self.head_from_camera()
    }
}

impl Default for Ers7Dimensions {
    fn default() -> Self {
        Self::ERS7
    }
}

/// The three head joints of the ERS-7, radians.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct HeadJoints {
    /// Lower tilt joint (tilt1, at the body), radians, positive up; [`SensorReadings::head_tilt_rad`].
    pub tilt1_rad: f64,
    /// Pan joint, radians, positive left; [`SensorReadings::head_pan_rad`].
    pub pan_rad: f64,
    /// Upper tilt joint (tilt2, nod, at the head), radians, positive up;
    /// [`SensorReadings::neck_tilt_rad`].
    pub tilt2_rad: f64,
}

impl HeadJoints {
    /// The joints from the sensor readings, or `None` when pan or the lower tilt is missing. A
    /// missing upper tilt is taken as 0 (sources with a single tilt joint, such as the Nao).
    #[must_use]
    pub fn from_sensors(readings: &SensorReadings) -> Option<Self> {
        let finite = |v: Option<f64>| v.filter(|a| a.is_finite());
        Some(Self {
            tilt1_rad: finite(readings.head_tilt_rad)?,
            pan_rad: finite(readings.head_pan_rad)?,
            tilt2_rad: finite(readings.neck_tilt_rad).unwrap_or(0.0),
        })
    }

    /// Writes these joints into sensor readings (the renderer's ground truth).
    pub fn write_to(&self, readings: &mut SensorReadings) {
        readings.head_tilt_rad = Some(self.tilt1_rad);
        readings.head_pan_rad = Some(self.pan_rad);
        readings.neck_tilt_rad = Some(self.tilt2_rad);
    }
}

/// Where the robot stands on the field: the ground point below its body centre and its heading.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RobotPose {
    /// Field x of the body centre, centimetres.
    pub x_cm: f64,
    /// Field y of the body centre, centimetres.
    pub y_cm: f64,
    /// Heading, radians, counter-clockwise from field +x.
    pub heading_rad: f64,
}

impl RobotPose {
    /// A pose from position (cm) and heading (rad).
    #[must_use]
    pub const fn new(x_cm: f64, y_cm: f64, heading_rad: f64) -> Self {
        Self {
            x_cm,
            y_cm,
            heading_rad,
        }
    }
}

/// The body's height and tilt, from the walk or the accelerometers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BodyPose {
    /// Height of the body centre above the ground, centimetres.
    pub height_cm: f64,
    /// Pitch, radians, positive nose down.
    pub pitch_rad: f64,
    /// Roll, radians, positive right side down.
    pub roll_rad: f64,
}

impl BodyPose {
    /// A typical ERS-7 walking stance: body centre 12 cm up, nose down 0.10 rad, no roll.
    pub const ERS7_STANCE: Self = Self {
        height_cm: 12.0,
        pitch_rad: 0.10,
        roll_rad: 0.0,
    };

    /// The body pose from sensor readings: height, pitch and roll where given, else pitch and
    /// roll from the accelerometers, else the `fallback`'s values.
    #[must_use]
    pub fn from_sensors(readings: &SensorReadings, fallback: &Self) -> Self {
        let finite = |v: Option<f64>| v.filter(|a| a.is_finite());
        let from_accel = match (
            finite(readings.accel_x_mps2),
            finite(readings.accel_y_mps2),
            finite(readings.accel_z_mps2),
        ) {
            (Some(x), Some(y), Some(z)) => pitch_roll_from_accelerometer(x, y, z),
            _ => None,
        };
        Self {
            height_cm: finite(readings.body_height_cm).unwrap_or(fallback.height_cm),
            pitch_rad: finite(readings.body_pitch_rad)
                .or(from_accel.map(|a| a.0))
                .unwrap_or(fallback.pitch_rad),
            roll_rad: finite(readings.body_roll_rad)
                .or(from_accel.map(|a| a.1))
                .unwrap_or(fallback.roll_rad),
        }
    }

    /// Writes height, pitch, roll and the resting accelerometer readings they imply.
    pub fn write_to(&self, readings: &mut SensorReadings) {
        readings.body_height_cm = Some(self.height_cm);
        readings.body_pitch_rad = Some(self.pitch_rad);
        readings.body_roll_rad = Some(self.roll_rad);
        let [x, y, z] = accelerometer_at_rest(self.pitch_rad, self.roll_rad);
        readings.accel_x_mps2 = Some(x);
        readings.accel_y_mps2 = Some(y);
        readings.accel_z_mps2 = Some(z);
    }

    /// The body pose in the field for a robot standing at `robot`.
    #[must_use]
    pub fn field_from_body(&self, robot: &RobotPose) -> Transform<Field, Body> {
        Transform::new(
            Vector3::new(robot.x_cm, robot.y_cm, self.height_cm),
            rotation_z(robot.heading_rad) * rotation_y(self.pitch_rad) * rotation_x(self.roll_rad),
        )
    }
}

impl Default for BodyPose {
    fn default() -> Self {
        Self::ERS7_STANCE
    }
}

/// The camera's pose over the ground as the robot itself estimated it, from the readings'
/// `camera_*` fields: position (cm) in the robot's ground frame and the rotation yaw · pitch ·
/// roll (pitch positive looking down, roll positive right side down, as [`super::PoseRecord`]).
/// `None` unless height and pitch are present and finite; a missing x, y, roll or yaw is taken
/// as 0 (a source that knows only how high its camera is and how far it looks down).
#[must_use]
pub fn camera_pose_from_readings(readings: &SensorReadings) -> Option<Transform<Field, Camera>> {
    let finite = |v: Option<f64>| v.filter(|a| a.is_finite());
    let height = finite(readings.camera_height_cm)?;
    let pitch = finite(readings.camera_pitch_rad)?;
    let or_zero = |v: Option<f64>| finite(v).unwrap_or(0.0);
    Some(Transform::new(
        Vector3::new(
            or_zero(readings.camera_x_cm),
            or_zero(readings.camera_y_cm),
            height,
        ),
        rotation_z(or_zero(readings.camera_yaw_rad))
            * rotation_y(pitch)
            * rotation_x(or_zero(readings.camera_roll_rad)),
    ))
}

/// Writes a camera pose into the readings' `camera_*` fields (the inverse of
/// [`camera_pose_from_readings`]).
pub fn write_camera_pose(
    field_from_camera: &Transform<Field, Camera>,
    readings: &mut SensorReadings,
) {
    let (roll, pitch, yaw) = field_from_camera.rotation().euler_angles();
    let o = field_from_camera.origin();
    readings.camera_x_cm = Some(o.x());
    readings.camera_y_cm = Some(o.y());
    readings.camera_height_cm = Some(o.z());
    readings.camera_roll_rad = Some(roll);
    readings.camera_pitch_rad = Some(pitch);
    readings.camera_yaw_rad = Some(yaw);
}

/// Body pitch (positive nose down) and roll (positive right side down), radians, from a resting
/// accelerometer reading (m/s², body axes). An accelerometer at rest measures the reaction to
/// gravity: +g along body +z when level, −g·sin(pitch) along +x when the nose is down, and
/// +g·cos(pitch)·sin(roll) along +y when the right side is down. `None` when the reading is not finite or too weak
/// (below 0.2 g) to give a direction.
#[must_use]
pub fn pitch_roll_from_accelerometer(x_mps2: f64, y_mps2: f64, z_mps2: f64) -> Option<(f64, f64)> {
    let norm = (x_mps2 * x_mps2 + y_mps2 * y_mps2 + z_mps2 * z_mps2).sqrt();
    if !norm.is_finite() || norm < 0.2 * GRAVITY_MPS2 {
        return None;
    }
    let pitch = (-x_mps2).atan2(y_mps2.hypot(z_mps2));
    let roll = y_mps2.atan2(z_mps2);
    Some((pitch, roll))
}

/// What a resting accelerometer reads (m/s², body x, y, z) for a body at this pitch and roll;
/// the inverse of [`pitch_roll_from_accelerometer`].
#[must_use]
pub fn accelerometer_at_rest(pitch_rad: f64, roll_rad: f64) -> [f64; 3] {
    // The up vector expressed in body axes, times g.
    let body_from_level = (rotation_y(pitch_rad) * rotation_x(roll_rad)).inverse();
    let up = body_from_level * Vector3::z();
    [
        up.x * GRAVITY_MPS2,
        up.y * GRAVITY_MPS2,
        up.z * GRAVITY_MPS2,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Point, Vector};
    use approx::assert_relative_eq;

    #[test]
    fn zero_joints_put_the_camera_ahead_and_above_the_body() {
        let dims = Ers7Dimensions::ERS7;
        let body_from_camera = dims.body_from_camera(&HeadJoints::default());
        let c = body_from_camera.origin();
        assert_relative_eq!(c.x(), 6.75 + 8.106, epsilon = 1e-9);
        assert_relative_eq!(c.y(), 0.0, epsilon = 1e-9);
        assert_relative_eq!(c.z(), 1.95 + 8.0 - 1.46, epsilon = 1e-9);
        // Looking forward.
        let axis = body_from_camera * Vector::<Camera>::new(1.0, 0.0, 0.0);
        assert_relative_eq!(axis.coords, Vector3::x(), epsilon = 1e-12);
    }

    #[test]
    fn pan_left_looks_left_and_tilt_up_looks_up() {
        let dims = Ers7Dimensions::ERS7;
        let pan = dims.body_from_camera(&HeadJoints {
            pan_rad: 0.5,
            ..HeadJoints::default()
        });
        let axis = pan * Vector::<Camera>::new(1.0, 0.0, 0.0);
        assert_relative_eq!(axis.coords.y.atan2(axis.coords.x), 0.5, epsilon = 1e-12);
        for tilt in [
            HeadJoints {
                tilt1_rad: 0.3,
                ..HeadJoints::default()
            },
            HeadJoints {
                tilt2_rad: 0.3,
                ..HeadJoints::default()
            },
        ] {
            let axis = dims.body_from_camera(&tilt) * Vector::<Camera>::new(1.0, 0.0, 0.0);
            assert_relative_eq!(axis.coords.z.asin(), 0.3, epsilon = 1e-12);
        }
    }

    #[test]
    fn lower_tilt_swings_the_neck_forward() {
        // Tilting the neck down by 90° lays it forward: the pan joint ends up 8 cm ahead of the
        // neck base, at its height.
        let dims = Ers7Dimensions::ERS7;
        let head = dims.body_from_head(&HeadJoints {
            tilt1_rad: -std::f64::consts::FRAC_PI_2,
            ..HeadJoints::default()
        });
        let o = head.origin();
        assert_relative_eq!(o.x(), 6.75 + 8.0, epsilon = 1e-9);
        assert_relative_eq!(o.z(), 1.95, epsilon = 1e-9);
    }

    #[test]
    fn camera_height_in_the_standard_stance() {
        let dims = Ers7Dimensions::ERS7;
        let body = BodyPose {
            pitch_rad: 0.0,
            ..BodyPose::ERS7_STANCE
        };
        let field_from_camera = body.field_from_body(&RobotPose::new(100.0, -50.0, 0.0))
            * dims.body_from_camera(&HeadJoints::default());
        let c = field_from_camera * Point::<Camera>::new(0.0, 0.0, 0.0);
        assert_relative_eq!(c.z(), 12.0 + 1.95 + 8.0 - 1.46, epsilon = 1e-9);
        assert_relative_eq!(c.x(), 100.0 + 6.75 + 8.106, epsilon = 1e-9);
        assert_relative_eq!(c.y(), -50.0, epsilon = 1e-9);
    }

    #[test]
    fn accelerometer_round_trip_and_signs() {
        for &(p, r) in &[(0.0, 0.0), (0.1, 0.0), (-0.2, 0.15), (0.4, -0.3)] {
            let [x, y, z] = accelerometer_at_rest(p, r);
            let (p2, r2) = pitch_roll_from_accelerometer(x, y, z).expect("strong enough");
            assert_relative_eq!(p2, p, epsilon = 1e-12);
            assert_relative_eq!(r2, r, epsilon = 1e-12);
        }
        // Level: +g on z.
        let [x, y, z] = accelerometer_at_rest(0.0, 0.0);
        assert_relative_eq!(z, GRAVITY_MPS2, epsilon = 1e-12);
        assert_relative_eq!(x.hypot(y), 0.0, epsilon = 1e-12);
        assert!(pitch_roll_from_accelerometer(0.0, 0.0, 0.1).is_none());
        assert!(pitch_roll_from_accelerometer(f64::NAN, 0.0, 9.8).is_none());
    }

    #[test]
    fn sensor_round_trip() {
        let joints = HeadJoints {
            tilt1_rad: -0.4,
            pan_rad: 0.7,
            tilt2_rad: 0.2,
        };
        let body = BodyPose {
            height_cm: 11.0,
            pitch_rad: 0.12,
            roll_rad: -0.03,
        };
        let mut readings = SensorReadings::default();
        joints.write_to(&mut readings);
        body.write_to(&mut readings);
        assert_eq!(HeadJoints::from_sensors(&readings), Some(joints));
        assert_eq!(
            BodyPose::from_sensors(&readings, &BodyPose::ERS7_STANCE),
            body
        );
        // Without explicit pitch and roll they come from the accelerometers.
        readings.body_pitch_rad = None;
        readings.body_roll_rad = None;
        let estimated = BodyPose::from_sensors(&readings, &BodyPose::ERS7_STANCE);
        assert_relative_eq!(estimated.pitch_rad, 0.12, epsilon = 1e-12);
        assert_relative_eq!(estimated.roll_rad, -0.03, epsilon = 1e-12);
        // Missing pan: no joints.
        readings.head_pan_rad = None;
        assert_eq!(HeadJoints::from_sensors(&readings), None);
    }

    #[test]
    fn camera_pose_readings_round_trip_and_need_height_and_pitch() {
        let pose: Transform<Field, Camera> = Transform::new(
            Vector3::new(5.6, 0.4, 48.5),
            rotation_z(0.3) * rotation_y(0.23) * rotation_x(-0.01),
        );
        let mut readings = SensorReadings::default();
        write_camera_pose(&pose, &mut readings);
        assert_relative_eq!(
            readings.camera_height_cm.expect("height"),
            48.5,
            epsilon = 1e-12
        );
        assert_relative_eq!(
            readings.camera_pitch_rad.expect("pitch"),
            0.23,
            epsilon = 1e-12
        );
        assert_relative_eq!(readings.camera_yaw_rad.expect("yaw"), 0.3, epsilon = 1e-12);
        let back = camera_pose_from_readings(&readings).expect("pose");
        assert_relative_eq!(back.isometry, pose.isometry, epsilon = 1e-12);
        // Looking down: the optical axis points below the horizontal.
        let axis = back * Vector::<Camera>::new(1.0, 0.0, 0.0);
        assert!(axis.coords.z < 0.0);
        // Height and pitch alone are enough; without either there is no pose.
        let minimal = SensorReadings {
            camera_height_cm: Some(50.0),
            camera_pitch_rad: Some(0.1),
            ..SensorReadings::default()
        };
        let p = camera_pose_from_readings(&minimal).expect("pose");
        assert_relative_eq!(p.origin().z(), 50.0, epsilon = 1e-12);
        assert!(
            camera_pose_from_readings(&SensorReadings {
                camera_pitch_rad: Some(f64::NAN),
                ..minimal
            })
            .is_none()
        );
        assert!(
            camera_pose_from_readings(&SensorReadings {
                camera_height_cm: None,
                ..minimal
            })
            .is_none()
        );
    }
}
