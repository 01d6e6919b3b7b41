//! The fixed-layout records of a log (JointData, SensorData, CameraMatrix,
//! ImageCoordinateSystem), their raw JSON, our sensor schema from them, and the head angles
//! interpolated at each image's time.

use super::{
    BhumanFrame, CameraMatrixRecord, G_MPS2, JOINT_NAMES, JointRecord, SENSOR_NAMES, SensorRecord,
};
use crate::sensors::SensorReadings;

pub(super) fn le_u32(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4)
        .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

pub(super) fn parse_joints(p: &[u8]) -> Option<JointRecord> {
    if p.len() != 22 * 8 + 4 {
        return None;
    }
    let mut angles = [0.0; 22];
    for (i, a) in angles.iter_mut().enumerate() {
        let s = p.get(i * 8..i * 8 + 8)?;
        *a = f64::from_le_bytes(s.try_into().ok()?);
    }
    Some(JointRecord {
        angles,
        time_ms: le_u32(p, 176)?,
    })
}

pub(super) fn parse_sensors(p: &[u8]) -> Option<SensorRecord> {
    if p.len() != 18 * 4 + 22 * 2 + 22 + 4 + 4 {
        return None;
    }
    let mut data = [0.0f32; 18];
    for (i, d) in data.iter_mut().enumerate() {
        *d = f32::from_bits(le_u32(p, i * 4)?);
    }
    let mut currents = [0i16; 22];
    for (i, c) in currents.iter_mut().enumerate() {
        let s = p.get(72 + i * 2..74 + i * 2)?;
        *c = i16::from_le_bytes([s[0], s[1]]);
    }
    let mut temperatures = [0u8; 22];
    temperatures.copy_from_slice(p.get(116..138)?);
    Some(SensorRecord {
        data,
        currents,
        temperatures,
        us_mode: i32::from_le_bytes(p.get(138..142)?.try_into().ok()?),
        time_ms: le_u32(p, 142)?,
    })
}

pub(super) fn le_f64(b: &[u8], at: usize) -> Option<f64> {
    Some(f64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// A CameraMatrix payload: 12 `f64` (rotation column by column, translation in mm) and
/// `isValid` (the first byte after them; B-Human writes it as 4 bytes).
#[must_use]
pub fn parse_camera_matrix(p: &[u8]) -> Option<CameraMatrixRecord> {
    if p.len() != 97 && p.len() != 100 {
        return None;
    }
    let v = |i: usize| le_f64(p, i * 8);
    let column = |c: usize| Some([v(3 * c)?, v(3 * c + 1)?, v(3 * c + 2)?]);
    Some(CameraMatrixRecord {
        rotation_columns: [column(0)?, column(1)?, column(2)?],
        translation_mm: [v(9)?, v(10)?, v(11)?],
        is_valid: *p.get(96)? != 0,
    })
}

/// An ImageCoordinateSystem payload (160 bytes) as JSON: the offset to the previous image
/// (rad, about z and y), the read-out factors a and b, and the camera info.
pub(super) fn image_coordinate_system_json(p: &[u8]) -> Option<serde_json::Value> {
    if p.len() != 160 {
        return None;
    }
    let f = |at: usize| le_f64(p, at);
    let i = |at: usize| Some(i32::from_le_bytes(p.get(at..at + 4)?.try_into().ok()?));
    Some(serde_json::json!({
        "horizon_origin_px": [f(64)?, f(72)?],
        "horizon_direction": [f(0)?, f(8)?],
        "offset_rad": [f(80)?, f(88)?],
        "a": f(96)?,
        "b": f(104)?,
        "resolution": [i(112)?, i(116)?],
        "opening_angle_width_rad": f(120)?,
        "opening_angle_height_rad": f(128)?,
        "focal_length_px": f(136)?,
        "optical_center_px": [f(144)?, f(152)?],
    }))
}

pub(super) fn camera_matrix_json(m: &CameraMatrixRecord) -> serde_json::Value {
    serde_json::json!({
        "rotation_columns": m.rotation_columns,
        "translation_mm": m.translation_mm,
        "is_valid": m.is_valid,
    })
}

/// A reading B-Human marks as missing (1000 off, 2000 ignore) or non-finite → `None`.
pub(super) fn reading(v: f64) -> Option<f64> {
    (v.is_finite() && v != 1000.0 && v != 2000.0).then_some(v)
}

/// Our sensor schema from B-Human's records (see the module docs for each mapping).
#[must_use]
pub fn map_sensors(joints: Option<&JointRecord>, sensors: Option<&SensorRecord>) -> SensorReadings {
    let mut r = SensorReadings::default();
    if let Some(j) = joints {
        r.head_pan_rad = reading(j.angles[0]);
        r.head_tilt_rad = reading(j.angles[1]);
    }
    if let Some(s) = sensors {
        let d = |i: usize| reading(f64::from(s.data[i]));
        r.accel_x_mps2 = d(3).map(|a| -a * G_MPS2);
        r.accel_y_mps2 = d(4).map(|a| -a * G_MPS2);
        r.accel_z_mps2 = d(5).map(|a| -a * G_MPS2);
        r.battery_percent = d(6).filter(|b| (0.0..=1.0).contains(b)).map(|b| b * 100.0);
        r.body_roll_rad = d(16);
        r.body_pitch_rad = d(17);
    }
    r
}

pub(super) fn raw_json(
    joints: Option<&JointRecord>,
    sensors: Option<&SensorRecord>,
) -> serde_json::Value {
    let mut v = serde_json::Map::new();
    if let Some(j) = joints {
        let angles: serde_json::Map<String, serde_json::Value> = JOINT_NAMES
            .iter()
            .zip(j.angles)
            .map(|(n, a)| ((*n).to_owned(), a.into()))
            .collect();
        v.insert("joint_time_ms".into(), j.time_ms.into());
        v.insert("joint_angles_rad".into(), angles.into());
    }
    if let Some(s) = sensors {
        let data: serde_json::Map<String, serde_json::Value> = SENSOR_NAMES
            .iter()
            .zip(s.data)
            .map(|(n, d)| ((*n).to_owned(), f64::from(d).into()))
            .collect();
        v.insert("sensor_time_ms".into(), s.time_ms.into());
        v.insert("sensors".into(), data.into());
        v.insert("motor_currents".into(), s.currents.to_vec().into());
        v.insert(
            "motor_temperatures_c".into(),
            s.temperatures.to_vec().into(),
        );
        v.insert("us_mode".into(), s.us_mode.into());
    }
    v.into()
}

/// Head pan and tilt (B-Human's `headPan`, `headTilt`) at time `t_ms`, interpolated between the
/// joint records around it (`joints` sorted by time), and the two records' times; the nearest
/// record's angles outside their span. `None` without a usable record.
pub(super) fn head_at(joints: &[JointRecord], t_ms: u32) -> Option<((f64, f64), [u32; 2])> {
    let usable: Vec<&JointRecord> = joints
        .iter()
        .filter(|j| reading(j.angles[0]).is_some() && reading(j.angles[1]).is_some())
        .collect();
    let after = usable.partition_point(|j| j.time_ms <= t_ms);
    let (a, b) = match (
        after.checked_sub(1).and_then(|i| usable.get(i)),
        usable.get(after),
    ) {
        (Some(a), Some(b)) => (*a, *b),
        (Some(a), None) => (*a, *a),
        (None, Some(b)) => (*b, *b),
        (None, None) => return None,
    };
    let span = f64::from(b.time_ms.saturating_sub(a.time_ms));
    let f = if span > 0.0 {
        (f64::from(t_ms.saturating_sub(a.time_ms)) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let lerp = |i: usize| a.angles[i] + f * (b.angles[i] - a.angles[i]);
    Some(((lerp(0), lerp(1)), [a.time_ms, b.time_ms]))
}

/// Sets each frame's head pan and tilt to their values at its image's time, interpolated
/// between the joint records logged around it (the log keeps about 8 of them per second, taken
/// up to ±180 ms from its images, so the last one before an image may be far from it, or even
/// the same record as the previous image's), and the previous frame's as the previous values,
/// with the time between the images as the interval.
pub(super) fn head_at_image_times(frames: &mut [BhumanFrame], joints: &mut [JointRecord]) {
    joints.sort_by_key(|j| j.time_ms);
    let mut previous: Option<(u32, SensorReadings)> = None;
    for f in frames.iter_mut() {
        if let Some(((pan, tilt), [ta, tb])) = head_at(joints, f.time_ms) {
            f.sensors.head_pan_rad = Some(pan);
            f.sensors.head_tilt_rad = Some(tilt);
            if let Some(obj) = f.raw.as_object_mut() {
                obj.insert("head_interpolated_between_ms".into(), vec![ta, tb].into());
            }
        }
        if let Some((t0, prev)) = &previous {
            f.sensors.previous_head_pan_rad = prev.head_pan_rad;
            f.sensors.previous_head_tilt_rad = prev.head_tilt_rad;
            f.sensors.frame_interval_s =
                (f.time_ms > *t0).then(|| f64::from(f.time_ms - t0) / 1000.0);
        }
        previous = Some((f.time_ms, f.sensors));
    }
}
