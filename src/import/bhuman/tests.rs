use super::records::{head_at, head_at_image_times};
use super::*;

#[test]
fn macropixels_become_uyvy_with_mean_luma_and_shared_chroma() {
    let mp = [[10, 100, 20, 200], [30, 110, 41, 210]];
    let f = macropixels_to_uyvy(&mp, 2, 1).unwrap();
    assert_eq!(f.data(), &[105, 15, 205, 36]);
    assert!(macropixels_to_uyvy(&mp, 3, 1).is_err());
}

#[test]
fn sensors_map_with_signs_units_and_missing_values() {
    let mut angles = [0.0; 22];
    angles[0] = 0.3;
    angles[1] = 0.4;
    let j = JointRecord { angles, time_ms: 5 };
    let mut data = [0.0f32; 18];
    data[5] = -1.0;
    data[6] = 0.5;
    data[16] = 1000.0;
    data[17] = 0.1;
    let s = SensorRecord {
        data,
        currents: [0; 22],
        temperatures: [0; 22],
        us_mode: 0,
        time_ms: 5,
    };
    let r = map_sensors(Some(&j), Some(&s));
    assert_eq!(r.head_pan_rad, Some(0.3));
    assert_eq!(r.head_tilt_rad, Some(0.4));
    assert!((r.accel_z_mps2.unwrap() - G_MPS2).abs() < 1e-9);
    assert_eq!(r.battery_percent, Some(50.0));
    assert_eq!(r.body_roll_rad, None);
    assert!((r.body_pitch_rad.unwrap() - 0.1).abs() < 1e-6);
    assert_eq!(r.neck_tilt_rad, None);
    assert_eq!(map_sensors(None, None), SensorReadings::default());
}

#[test]
fn damaged_logs_are_errors_or_warnings() {
    let short = parse_log(&[1, 2, 3]).unwrap_err();
    assert_eq!(short, LogError::TooShort { len: 3 });
    assert!(short.to_string().contains("too short"), "{short}");
    // Header + one complete JointData + a cut-off message.
    let mut b = Vec::new();
    b.extend_from_slice(&0u32.to_le_bytes());
    b.extend_from_slice(&2u32.to_le_bytes());
    b.extend_from_slice(&[ids::JOINT_DATA, 180, 0, 0]);
    b.extend_from_slice(&[0u8; 180]);
    b.extend_from_slice(&[ids::JPEG_IMAGE, 100, 0, 0, 1, 2]);
    let log = parse_log(&b).unwrap();
    assert!(log.frames.is_empty());
    assert_eq!(log.message_counts.get(&ids::JOINT_DATA), Some(&1));
    assert!(
        log.warnings.iter().any(|w| w.contains("cut off")),
        "{:?}",
        log.warnings
    );
    // A JPEGImage whose JPEG is garbage is skipped with a warning.
    let mut b = Vec::new();
    b.extend_from_slice(&0u32.to_le_bytes());
    b.extend_from_slice(&1u32.to_le_bytes());
    let mut p = Vec::new();
    for v in [320u32, 240, 7, 4] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    p.extend_from_slice(&[0xff, 0xd8, 0, 0]);
    b.extend_from_slice(&[ids::JPEG_IMAGE, p.len() as u8, 0, 0]);
    b.extend_from_slice(&p);
    let log = parse_log(&b).unwrap();
    assert!(log.frames.is_empty());
    assert!(
        log.warnings.iter().any(|w| w.contains("JPEGImage skipped")),
        "{:?}",
        log.warnings
    );
}

fn camera_matrix_payload(columns: [[f64; 3]; 3], t: [f64; 3], valid: bool) -> Vec<u8> {
    let mut p = Vec::new();
    for v in columns.iter().flatten().chain(t.iter()) {
        p.extend_from_slice(&v.to_le_bytes());
    }
    p.extend_from_slice(&u32::from(valid).to_le_bytes());
    p
}

#[test]
fn camera_matrix_parses_column_by_column_into_a_pose_in_centimetres() {
    // Looking 13° down, 48.5 cm up, 5.6 cm ahead of the feet (frame 0 of the log).
    let (s, c) = 13.0_f64.to_radians().sin_cos();
    let columns = [[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]];
    let p = camera_matrix_payload(columns, [56.0, 4.0, 485.0], true);
    assert_eq!(p.len(), 100);
    let m = parse_camera_matrix(&p).expect("parses");
    assert!(m.is_valid);
    assert_eq!(m.rotation_columns, columns);
    let pose = m.field_from_camera().expect("a rotation");
    let o = pose.origin();
    assert!((o.z() - 48.5).abs() < 1e-9 && (o.x() - 5.6).abs() < 1e-9);
    let axis = pose * crate::geometry::Vector::<crate::geometry::Camera>::new(1.0, 0.0, 0.0);
    assert!((axis.coords.z + s).abs() < 1e-9, "{axis:?}");
    let mut r = SensorReadings::default();
    crate::geometry::write_camera_pose(&pose, &mut r);
    assert!((r.camera_pitch_rad.expect("pitch") - 13.0_f64.to_radians()).abs() < 1e-9);
    assert!(r.camera_yaw_rad.expect("yaw").abs() < 1e-9);
    assert!(
        !parse_camera_matrix(&camera_matrix_payload(columns, [0.0; 3], false))
            .expect("parses")
            .is_valid
    );
    // Wrong sizes and non-rotations are refused.
    assert!(parse_camera_matrix(&p[..96]).is_none());
    let skewed = [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let bad = parse_camera_matrix(&camera_matrix_payload(skewed, [0.0; 3], true));
    assert!(bad.expect("parses").field_from_camera().is_none());
    let nan = [[f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let bad = parse_camera_matrix(&camera_matrix_payload(nan, [0.0; 3], true));
    assert!(bad.expect("parses").field_from_camera().is_none());
}

#[test]
fn a_camera_matrix_outside_an_image_cycle_is_a_warning() {
    let columns = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let p = camera_matrix_payload(columns, [0.0, 0.0, 480.0], true);
    let mut b = Vec::new();
    b.extend_from_slice(&0u32.to_le_bytes());
    b.extend_from_slice(&3u32.to_le_bytes());
    b.extend_from_slice(&[ids::PROCESS_BEGIN, 1, 0, 0, 0]);
    b.extend_from_slice(&[ids::CAMERA_MATRIX, p.len() as u8, 0, 0]);
    b.extend_from_slice(&p);
    b.extend_from_slice(&[ids::CAMERA_MATRIX, 3, 0, 0, 1, 2, 3]);
    let log = parse_log(&b).expect("parses");
    assert!(
        log.warnings
            .iter()
            .any(|w| w.contains("without an image of its own")),
        "{:?}",
        log.warnings
    );
    assert!(
        log.warnings.iter().any(|w| w.contains("expected 100")),
        "{:?}",
        log.warnings
    );
}

#[test]
fn head_angles_are_interpolated_at_the_image_time() {
    let record = |time_ms: u32, pan: f64, tilt: f64| {
        let mut angles = [0.0; 22];
        angles[0] = pan;
        angles[1] = tilt;
        JointRecord { angles, time_ms }
    };
    let mut joints = vec![
        record(300, 0.4, -0.2),
        record(100, 0.0, 0.0),
        record(200, 1000.0, 1000.0),
    ];
    joints.sort_by_key(|j| j.time_ms);
    // The record marked "off" (1000) is passed over: 250 ms lies three quarters of the way
    // from 100 to 300 ms.
    let ((pan, tilt), span) = head_at(&joints, 250).expect("records");
    assert_eq!(span, [100, 300]);
    assert!(
        (pan - 0.3).abs() < 1e-12 && (tilt + 0.15).abs() < 1e-12,
        "{pan} {tilt}"
    );
    // Outside the records' span: the nearest one.
    assert_eq!(head_at(&joints, 50).map(|h| h.0), Some((0.0, 0.0)));
    assert_eq!(head_at(&joints, 900).map(|h| h.0), Some((0.4, -0.2)));
    assert_eq!(head_at(&[], 100), None);
    // Frames get those values, the previous frame's as previous, the image interval.
    let frame = |time_ms: u32| BhumanFrame {
        time_ms,
        frame: Frame::from_uyvy(2, 1, vec![128, 16, 128, 16]).expect("frame"),
        sensors: SensorReadings::default(),
        camera_matrix: None,
        raw: serde_json::json!({}),
    };
    let mut frames = vec![frame(150), frame(250)];
    head_at_image_times(&mut frames, &mut joints);
    let s = frames[1].sensors;
    assert_eq!(s.previous_head_pan_rad, frames[0].sensors.head_pan_rad);
    assert!((s.frame_interval_s.expect("interval") - 0.1).abs() < 1e-12);
    assert!((s.head_pan_rad.expect("pan") - 0.3).abs() < 1e-12);
    assert!((frames[0].sensors.head_pan_rad.expect("pan") - 0.1).abs() < 1e-12);
    assert_eq!(frames[0].sensors.frame_interval_s, None);
    assert_eq!(
        frames[1].raw["head_interpolated_between_ms"],
        serde_json::json!([100, 300])
    );
}
