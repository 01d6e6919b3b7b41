//! The robot's sensor readings that travel with each camera frame.
//!
//! One schema for every source (recorded streams, the renderer's ground truth, imported logs, a
//! live robot) so that recognition and the app never care where a frame came from. Angles are in
//! radians with the signs of `FORMATS.md` (pan positive to the left, tilt positive up); lengths in
//! centimetres; accelerations in m/s². A reading the source did not provide is `None`, never a
//! made-up zero. NaN or infinite values are turned into `None` by [`SensorReadings::sanitised`],
//! which says which fields it dropped so the caller can warn.

use serde::{Deserialize, Serialize};

/// Everything the robot reported for one frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct SensorReadings {
    /// Head pan (yaw) in radians, positive to the left.
    pub head_pan_rad: Option<f64>,
    /// Head tilt in radians, positive up (the ERS-7's lower head tilt joint, "tilt1").
    pub head_tilt_rad: Option<f64>,
    /// Neck tilt in radians, positive up (the ERS-7's upper tilt joint, "tilt2"/nod).
    pub neck_tilt_rad: Option<f64>,
    /// Head pan at the previous frame, radians: with [`Self::frame_interval_s`] it gives the pan
    /// velocity used for rolling-shutter skew correction.
    pub previous_head_pan_rad: Option<f64>,
    /// Head tilt at the previous frame, radians (vertical skew correction).
    pub previous_head_tilt_rad: Option<f64>,
    /// Time between this frame and the previous one, seconds.
    pub frame_interval_s: Option<f64>,
    /// Duty cycle of the pan motor's PWM, −1..1 (sign = direction of the applied torque).
    pub pan_pwm: Option<f64>,
    /// Head infra-red distance sensor, near range, centimetres.
    pub ir_near_cm: Option<f64>,
    /// Head infra-red distance sensor, far range, centimetres.
    pub ir_far_cm: Option<f64>,
    /// Chest infra-red distance sensor, centimetres.
    pub ir_chest_cm: Option<f64>,
    /// Body acceleration along the robot's x axis (forward), m/s².
    pub accel_x_mps2: Option<f64>,
    /// Body acceleration along the robot's y axis (left), m/s².
    pub accel_y_mps2: Option<f64>,
    /// Body acceleration along the robot's z axis (up), m/s².
    pub accel_z_mps2: Option<f64>,
    /// Body pitch in radians, positive nose down, when the source knows it (else estimate it from
    /// the accelerations).
    pub body_pitch_rad: Option<f64>,
    /// Body roll in radians, positive right side down.
    pub body_roll_rad: Option<f64>,
    /// Height of the body centre above the ground, centimetres.
    pub body_height_cm: Option<f64>,
    /// Battery charge, percent (0–100).
    pub battery_percent: Option<f64>,
    /// Body temperature, degrees Celsius.
    pub temperature_c: Option<f64>,
    /// The robot's own estimate of its camera's pose over the ground (B-Human's `CameraMatrix`):
    /// camera position ahead of the robot's ground origin (the point on the ground between its
    /// feet, or below its body centre), centimetres. With [`Self::camera_height_cm`] and
    /// [`Self::camera_pitch_rad`] present recognition uses this pose instead of a body model
    /// (`geometry::camera_pose_from_readings`).
    pub camera_x_cm: Option<f64>,
    /// Camera position to the left of the robot's ground origin, centimetres.
    pub camera_y_cm: Option<f64>,
    /// Camera height above the ground, centimetres.
    pub camera_height_cm: Option<f64>,
    /// Camera roll about its optical axis, radians, positive right side down.
    pub camera_roll_rad: Option<f64>,
    /// Camera pitch, radians, positive looking down.
    pub camera_pitch_rad: Option<f64>,
    /// Camera yaw relative to the robot's forward direction, radians, positive left; the
    /// rotation is yaw · pitch · roll (about z, then the turned y, then the optical axis).
    pub camera_yaw_rad: Option<f64>,
    /// The camera's calibrated focal length, pixels of this frame (ROS `CameraInfo`'s `fx`,
    /// scaled to the frame's width): with it recognition uses this camera instead of the
    /// parameters' field of view. Absent from the JSON when unknown.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_focal_px: Option<f64>,
    /// Where the optical axis meets the image, pixels from the left edge (`CameraInfo`'s `cx`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_centre_x_px: Option<f64>,
    /// Where the optical axis meets the image, pixels from the top edge (`CameraInfo`'s `cy`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_centre_y_px: Option<f64>,
}

/// One field of [`SensorReadings`]: its name, unit and value, for tables and plots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorField {
    /// Field name as in the JSON schema.
    pub name: &'static str,
    /// Unit shown to the user.
    pub unit: &'static str,
    /// The reading, if the source gave one.
    pub value: Option<f64>,
}

/// Whether `v` can be a reading of the field `name` in `unit`: finite, and within what any
/// robot can report (angles within ±8π rad, lengths within ±1 km and heights and ranges not
/// below the ground, durations from 0 to an hour, duty cycles within ±1, accelerations within
/// ±1000 m/s², the battery within 0–100 %, temperatures within −100 to 200 °C, pixel positions
/// within ±100,000 and focal lengths positive).
#[must_use]
pub fn plausible(name: &str, unit: &str, v: f64) -> bool {
    if !v.is_finite() {
        return false;
    }
    let not_below_ground = name.ends_with("height_cm") || name.starts_with("ir_");
    match unit {
        "rad" => v.abs() <= 8.0 * std::f64::consts::PI,
        "cm" if not_below_ground => (0.0..=1e5).contains(&v),
        "cm" => v.abs() <= 1e5,
        "s" => (0.0..=3600.0).contains(&v),
        "duty" => v.abs() <= 1.0,
        "m/s²" => v.abs() <= 1000.0,
        "%" => (0.0..=100.0).contains(&v),
        "°C" => (-100.0..=200.0).contains(&v),
        "px" if name.contains("focal") => v > 0.0 && v <= 1e5,
        "px" => v.abs() <= 1e5,
        _ => true,
    }
}

macro_rules! sensor_fields {
    ($($field:ident : $unit:literal),* $(,)?) => {
        impl SensorReadings {
            /// Every field with its name and unit, in schema order.
            #[must_use]
            pub fn fields(&self) -> Vec<SensorField> {
                vec![$(SensorField { name: stringify!($field), unit: $unit, value: self.$field }),*]
            }

            /// The readings with every non-finite or impossible value removed (see
            /// [`plausible`]), and the names of the fields that were removed, so the caller can
            /// warn instead of computing with NaN or a 1e300-radian pan.
            #[must_use]
            pub fn sanitised(mut self) -> (Self, Vec<&'static str>) {
                let mut dropped = Vec::new();
                $(
                    if self.$field.is_some_and(|v| !plausible(stringify!($field), $unit, v)) {
                        self.$field = None;
                        dropped.push(stringify!($field));
                    }
                )*
                (self, dropped)
            }
        }
    };
}

sensor_fields! {
    head_pan_rad: "rad",
    head_tilt_rad: "rad",
    neck_tilt_rad: "rad",
    previous_head_pan_rad: "rad",
    previous_head_tilt_rad: "rad",
    frame_interval_s: "s",
    pan_pwm: "duty",
    ir_near_cm: "cm",
    ir_far_cm: "cm",
    ir_chest_cm: "cm",
    accel_x_mps2: "m/s²",
    accel_y_mps2: "m/s²",
    accel_z_mps2: "m/s²",
    body_pitch_rad: "rad",
    body_roll_rad: "rad",
    body_height_cm: "cm",
    battery_percent: "%",
    temperature_c: "°C",
    camera_x_cm: "cm",
    camera_y_cm: "cm",
    camera_height_cm: "cm",
    camera_roll_rad: "rad",
    camera_pitch_rad: "rad",
    camera_yaw_rad: "rad",
    camera_focal_px: "px",
    camera_centre_x_px: "px",
    camera_centre_y_px: "px",
}

impl SensorReadings {
    /// Pan velocity in rad/s from the current and previous pan, if all three values are known
    /// and the interval is positive.
    #[must_use]
    pub fn pan_velocity_rad_per_s(&self) -> Option<f64> {
        let (now, before, dt) = (
            self.head_pan_rad?,
            self.previous_head_pan_rad?,
            self.frame_interval_s?,
        );
        (dt > 0.0).then(|| (now - before) / dt)
    }
}

/// The numeric readings another channel carries with a frame: its per-frame JSON when that is a
/// flat object of numbers (nulls left out) — as a ROS `sensor_msgs/msg/JointState` is read,
/// joint name → position (rad) —, by name; empty for anything else.
#[must_use]
pub fn channel_readings(value: &serde_json::Value) -> Vec<(&str, f64)> {
    let Some(object) = value.as_object() else {
        return Vec::new();
    };
    if !object.values().all(|v| v.is_number() || v.is_null()) {
        return Vec::new();
    }
    object
        .iter()
        .filter_map(|(name, v)| v.as_f64().map(|x| (name.as_str(), x)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sanitised_drops_non_finite_values_and_names_them() {
        let readings = SensorReadings {
            head_pan_rad: Some(f64::NAN),
            head_tilt_rad: Some(0.1),
            ir_far_cm: Some(f64::INFINITY),
            ..SensorReadings::default()
        };
        let (clean, dropped) = readings.sanitised();
        assert_eq!(clean.head_pan_rad, None);
        assert_eq!(clean.head_tilt_rad, Some(0.1));
        assert_eq!(clean.ir_far_cm, None);
        assert_eq!(dropped, vec!["head_pan_rad", "ir_far_cm"]);
    }

    #[test]
    fn sanitised_drops_impossible_values_too() {
        let readings = SensorReadings {
            head_pan_rad: Some(1e300),
            camera_height_cm: Some(-20.0),
            camera_x_cm: Some(-20.0),
            battery_percent: Some(101.0),
            ..SensorReadings::default()
        };
        let (clean, dropped) = readings.sanitised();
        assert_eq!(
            dropped,
            vec!["head_pan_rad", "battery_percent", "camera_height_cm"]
        );
        assert_eq!(clean.camera_x_cm, Some(-20.0));
    }

    #[test]
    fn json_round_trip_keeps_missing_fields_missing() {
        let readings = SensorReadings {
            head_pan_rad: Some(0.5),
            battery_percent: Some(80.0),
            ..SensorReadings::default()
        };
        let json = serde_json::to_string(&readings).expect("serialise");
        let back: SensorReadings = serde_json::from_str(&json).expect("parse");
        assert_eq!(back, readings);
        let partial: SensorReadings =
            serde_json::from_str(r#"{"head_tilt_rad": -0.2}"#).expect("parse partial");
        assert_eq!(partial.head_tilt_rad, Some(-0.2));
        assert_eq!(partial.head_pan_rad, None);
    }

    #[test]
    fn pan_velocity_needs_all_three_readings() {
        let mut r = SensorReadings {
            head_pan_rad: Some(0.3),
            previous_head_pan_rad: Some(0.1),
            frame_interval_s: Some(0.04),
            ..SensorReadings::default()
        };
        let v = r.pan_velocity_rad_per_s().expect("velocity");
        assert!((v - 5.0).abs() < 1e-9);
        r.frame_interval_s = Some(0.0);
        assert_eq!(r.pan_velocity_rad_per_s(), None);
        r.frame_interval_s = None;
        assert_eq!(r.pan_velocity_rad_per_s(), None);
    }

    #[test]
    fn fields_lists_every_reading_with_units() {
        let fields = SensorReadings::default().fields();
        assert_eq!(fields.len(), 27);
        assert!(
            fields
                .iter()
                .any(|f| f.name == "pan_pwm" && f.unit == "duty")
        );
        assert!(fields.iter().all(|f| f.value.is_none()));
    }

    #[test]
    fn a_calibration_is_written_only_when_known_and_must_be_possible() {
        let json = serde_json::to_string(&SensorReadings::default()).expect("serialise");
        assert!(!json.contains("camera_focal_px"), "{json}");
        let r = SensorReadings {
            camera_focal_px: Some(-3.0),
            camera_centre_x_px: Some(-20.0),
            ..SensorReadings::default()
        };
        let (clean, dropped) = r.sanitised();
        assert_eq!(dropped, vec!["camera_focal_px"]);
        assert_eq!(clean.camera_centre_x_px, Some(-20.0));
    }

    #[test]
    fn flat_objects_of_numbers_are_readings_and_nothing_else() {
        let joints = serde_json::json!({"HeadYaw": 0.1, "HeadPitch": -0.2, "LHand": null});
        assert_eq!(
            channel_readings(&joints),
            vec![("HeadPitch", -0.2), ("HeadYaw", 0.1)]
        );
        for other in [
            serde_json::json!({"ball": {"x": 1.0}}),
            serde_json::json!({"name": "x", "v": 1.0}),
            serde_json::json!([1.0, 2.0]),
            serde_json::json!(3.0),
        ] {
            assert!(channel_readings(&other).is_empty(), "{other}");
        }
    }
}
