//! Tests of the calibration solver, its file and its checks.

use super::solver::with_positive_focal;
use super::*;
use crate::overhead::points::CalibrationPoint;
use crate::sim::SimRng;

fn clicked(camera: &OverheadCamera, field: &FieldDescription, noise_px: f64) -> PointsFile {
    let mut rng = SimRng::derived(5, 9);
    let mut file = PointsFile::new(camera.width_px, camera.height_px);
    for l in &field.landmarks {
        let p = Point::new(l.field_cm[0], l.field_cm[1], l.height_cm);
        if let Some(q) = camera.image_from_field(&p)
            && q.x_px > 0.0
            && q.y_px > 0.0
            && q.x_px < 640.0
            && q.y_px < 480.0
        {
            file.points.push(CalibrationPoint {
                name: l.name.clone(),
                field_cm: l.field_cm,
                height_cm: l.height_cm,
                image_px: [
                    q.x_px + noise_px * rng.normal(),
                    q.y_px + noise_px * rng.normal(),
                ],
            });
        }
    }
    file
}

#[test]
fn a_negative_focal_length_is_the_camera_turned_half_round() {
    let mut flipped = OverheadCamera::above_field_2005();
    flipped.focal_px = -flipped.focal_px;
    let fixed = with_positive_focal(flipped);
    assert!(fixed.focal_px > 0.0);
    for p in [
        Point::new(0.0, 0.0, 0.0),
        Point::new(120.0, -80.0, 0.0),
        Point::new(-200.0, 90.0, 22.5),
    ] {
        let a = flipped.image_from_field(&p).expect("in front");
        let b = fixed.image_from_field(&p).expect("in front");
        assert!(a.distance_to(&b) < 1e-6, "{a:?} {b:?}");
    }
}

#[test]
fn exact_clicks_give_back_the_camera() {
    let truth =
        crate::sim::Scenario::new(crate::sim::ScenarioKind::OverheadGame, 3).overhead_camera();
    let field = FieldDescription::four_legged_2005();
    let points = clicked(&truth, &field, 0.0);
    assert!(points.points.len() >= 20, "{}", points.points.len());
    let cal = calibrate(&points, &field, None, &CalibrationParams::default()).expect("fits");
    assert!(cal.median_point_error_px() < 0.05, "{cal:?}");
    for (x, y) in [(0.0, 0.0), (250.0, 170.0), (-200.0, 100.0)] {
        let p = Point::new(x, y, 22.5);
        let a = truth.image_from_field(&p).expect("seen");
        let b = cal.camera.image_from_field(&p).expect("seen");
        assert!(a.distance_to(&b) < 0.1, "({x}, {y}): {a:?} vs {b:?}");
    }
}

#[test]
fn a_turned_camera_is_found_without_a_turn_guess() {
    let mut truth = OverheadCamera::above_field_2005();
    truth.pose.yaw_rad += 2.0;
    let field = FieldDescription::four_legged_2005();
    let points = clicked(&truth, &field, 0.3);
    let cal = calibrate(&points, &field, None, &CalibrationParams::default()).expect("fits");
    assert!(cal.median_point_error_px() < 0.6, "{cal:?}");
}

#[test]
fn too_few_or_collinear_points_are_refused() {
    let field = FieldDescription::four_legged_2005();
    let camera = OverheadCamera::above_field_2005();
    let mut points = clicked(&camera, &field, 0.0);
    points.points.truncate(5);
    assert!(matches!(
        calibrate(&points, &field, None, &CalibrationParams::default()),
        Err(CalibrationError::Refused(Finding::TooFewPoints {
            count: 5
        }))
    ));
    // Eight landmarks along the centre line, clicked where a camera would see them: the
    // solver would fit them to 0.000 px with the camera's turn about that line free.
    let mut line = PointsFile::new(640, 480);
    for k in 0..8 {
        let y = -150.0 + 40.0 * f64::from(k);
        let q = camera
            .image_from_field(&Point::new(0.0, y, 0.0))
            .expect("seen");
        line.points.push(CalibrationPoint {
            name: format!("p{k}"),
            field_cm: [0.0, y],
            height_cm: 0.0,
            image_px: [q.x_px, q.y_px],
        });
    }
    let err = calibrate(&line, &field, None, &CalibrationParams::default()).expect_err("collinear");
    assert!(
        matches!(err, CalibrationError::Refused(Finding::Collinear { .. })),
        "{err:?}"
    );
    assert!(err.to_string().contains("lie on one line"), "{err}");
}

#[test]
fn a_well_spread_fit_is_determined_and_points_on_one_spot_are_not() {
    let field = FieldDescription::four_legged_2005();
    let camera = OverheadCamera::above_field_2005();
    let points = clicked(&camera, &field, 0.3);
    let targets: Vec<Target> = points
        .points
        .iter()
        .map(|p| Target {
            field: Point::new(p.field_cm[0], p.field_cm[1], p.height_cm),
            image: p.image(),
        })
        .collect();
    let prior = Priors {
        height_cm: 350.0,
        height_sd_cm: 50.0,
        centre: camera.centre,
        centre_sd_px: 32.0,
        distortion_sd: 0.3,
    };
    let good = conditioning(camera, &targets, &[], prior, Free::All);
    assert!(good > 1e3 * MIN_CONDITIONING, "{good:e}");
    // Every point on one spot: the turn and the focal length are free.
    let spot: Vec<Target> = targets
        .iter()
        .map(|_| Target {
            field: targets[0].field,
            image: targets[0].image,
        })
        .collect();
    let bad = conditioning(camera, &spot, &[], prior, Free::All);
    eprintln!("conditioning: spread {good:e}, one spot {bad:e}");
    assert!(bad < MIN_CONDITIONING, "{bad:e}");
}

#[test]
fn a_saved_calibration_loads_back_and_other_json_is_refused() {
    let field = FieldDescription::four_legged_2005();
    let camera = OverheadCamera::above_field_2005();
    let cal = calibrate(
        &clicked(&camera, &field, 0.0),
        &field,
        None,
        &CalibrationParams::default(),
    )
    .expect("fits");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("cal.json");
    cal.save(&path).expect("saves");
    let back = Calibration::load(&path).expect("loads");
    // Every field, bit for bit (serde_json's `float_roundtrip`).
    assert_eq!(back, cal);
    std::fs::write(&path, r#"{"format": "something else"}"#).expect("write");
    let err = Calibration::load(&path).expect_err("not ours");
    assert!(err.to_string().contains("cal.json"), "{err}");
}

#[test]
fn a_calibration_with_nan_is_never_written_and_unknown_keys_are_refused() {
    let field = FieldDescription::four_legged_2005();
    let camera = OverheadCamera::above_field_2005();
    let mut cal = calibrate(
        &clicked(&camera, &field, 0.0),
        &field,
        None,
        &CalibrationParams::default(),
    )
    .expect("fits");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("cal.json");
    cal.save(&path).expect("saves");
    let good = std::fs::read(&path).expect("read");
    // A point the camera does not see has no error: NaN.
    cal.points[1].error_px = f64::NAN;
    let err = cal.save(&path).expect_err("NaN");
    assert!(err.to_string().contains("not a number"), "{err}");
    assert_eq!(
        std::fs::read(&path).expect("read"),
        good,
        "the old file stays"
    );
    // A hand edit with a typo is refused, naming the key.
    let mut v: serde_json::Value = serde_json::from_slice(&good).expect("json");
    v["camera"]["focal"] = serde_json::json!(500.0);
    let err = Calibration::from_json(&v.to_string()).expect_err("a typo");
    assert!(err.contains("'camera.focal'"), "{err}");
    let mut v: serde_json::Value = serde_json::from_slice(&good).expect("json");
    v["points"][0]["eror_px"] = serde_json::json!(0.5);
    let err = Calibration::from_json(&v.to_string()).expect_err("a typo");
    assert!(err.contains("'points[0].eror_px'"), "{err}");
}
