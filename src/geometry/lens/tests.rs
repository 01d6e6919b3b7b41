//! The lens models against OpenCV's own numbers, and undistortion against distortion.

use super::*;

/// Normalised points `(x/z, y/z)`: near the axis, far out, and beyond 45°.
const POINTS: [(f64, f64); 3] = [(0.3, -0.2), (-0.9, 0.6), (1.2, 0.4)];

const PLUMB_BOB: LensModel = LensModel::PlumbBob {
    k1: -0.28,
    k2: 0.07,
    p1: 0.001,
    p2: -0.0015,
    k3: -0.008,
};

const RATIONAL: LensModel = LensModel::RationalPolynomial {
    k1: 0.9,
    k2: -0.1,
    p1: 0.0012,
    p2: -0.0008,
    k3: 0.01,
    k4: 1.2,
    k5: 0.05,
    k6: 0.02,
};

const FISHEYE: LensModel = LensModel::Equidistant {
    k1: -0.02,
    k2: 0.004,
    k3: -0.003,
    k4: 0.0005,
};

/// OpenCV 5.0.0 (`opencv-python-headless` of scripts/requirements-test.txt) on `POINTS` with
/// an identity camera matrix, printed by:
///
/// ```text
/// pts = np.array([[[0.3,-0.2,1]],[[-0.9,0.6,1]],[[1.2,0.4,1]]], float); K = np.eye(3); z = np.zeros(3)
/// cv2.projectPoints(pts, z, z, K, [-0.28, 0.07, 0.001, -0.0015, -0.008])
/// cv2.projectPoints(pts, z, z, K, [0.9, -0.1, 0.0012, -0.0008, 0.01, 1.2, 0.05, 0.02])
/// cv2.fisheye.projectPoints(pts, z, z, K, [-0.02, 0.004, -0.003, 0.0005])
/// ```
const OPENCV: [(LensModel, [[f64; 2]; 3]); 3] = [
    (
        PLUMB_BOB,
        [
            [0.288_844_627_200_000_04, -0.192_563_084_800_000_03],
            [-0.685_134_086_4, 0.456_756_057_6],
            [0.832_358_399_999_999_9, 0.279_852_799_999_999_96],
        ],
    ),
    (
        RATIONAL,
        [
            [0.288_831_606_027_385_83, -0.192_467_737_351_590_56],
            [-0.697_849_942_855_252_7, 0.466_013_295_236_835_16],
            [0.850_609_611_287_189_5, 0.285_883_203_762_396_45],
        ],
    ),
    (
        FISHEYE,
        [
            [0.287_253_932_400_066_14, -0.191_502_621_600_044_1],
            [-0.677_480_288_462_390_5, 0.451_653_525_641_593_6],
            [0.842_706_786_814_813_8, 0.280_902_262_271_604_6],
        ],
    ),
];

#[test]
fn distortion_matches_opencv() {
    for (model, expected) in OPENCV {
        for (&(x, y), want) in POINTS.iter().zip(expected) {
            let (a, b) = model.distort(x, y);
            assert!(
                (a - want[0]).abs() < 1e-12 && (b - want[1]).abs() < 1e-12,
                "{}: ({x}, {y}) -> ({a}, {b}), OpenCV {want:?}",
                model.ros_name()
            );
        }
    }
}

#[test]
fn undistortion_inverts_distortion_where_the_lens_is_one_to_one() {
    for (model, expected) in OPENCV {
        for (&(x, y), d) in POINTS.iter().zip(expected) {
            let (u, v) = model.undistort(d[0], d[1]).expect("converges");
            assert!(
                (u - x).abs() < 1e-9 && (v - y).abs() < 1e-9,
                "{}: {d:?} -> ({u}, {v}), expected ({x}, {y})",
                model.ros_name()
            );
        }
        assert_eq!(model.undistort(0.0, 0.0), Ok((0.0, 0.0)));
        assert_eq!(model.undistort(f64::NAN, 0.1), Err(LensError::NotFinite));
    }
}

#[test]
fn beyond_the_fold_undistortion_fails_clearly() {
    // Barrel distortion strong enough that the radius turns back: r(1 − 0.5 r²) peaks at
    // r = 0.816, distorted radius 0.544; a point further out has no undistorted point.
    let folded = LensModel::PlumbBob {
        k1: -0.5,
        k2: 0.0,
        p1: 0.0,
        p2: 0.0,
        k3: 0.0,
    };
    let err = folded.undistort(0.6, 0.0).expect_err("beyond the fold");
    assert!(matches!(err, LensError::NotConverged { .. }), "{err:?}");
    assert!(err.to_string().contains("did not converge"), "{err}");
    assert!(folded.undistort(0.5, 0.0).is_ok());
    // A fisheye radius of 2 (θd ≈ 2 rad with these small k) lies beyond 90°.
    let err = FISHEYE.undistort(2.0, 0.0).expect_err("behind");
    assert!(
        matches!(err, LensError::BeyondNinetyDegrees { .. }),
        "{err:?}"
    );
}

#[test]
fn ros_names_and_coefficient_counts() {
    let pb = LensModel::from_ros("plumb_bob", &[-0.28, 0.07, 0.001, -0.0015, -0.008]);
    assert_eq!(pb, Ok(PLUMB_BOB));
    assert_eq!(
        PLUMB_BOB.coefficients(),
        [-0.28, 0.07, 0.001, -0.0015, -0.008]
    );
    let four = LensModel::from_ros("plumb_bob", &[0.1, 0.2, 0.3, 0.4]).expect("k3 = 0");
    assert_eq!(four.coefficients(), [0.1, 0.2, 0.3, 0.4, 0.0]);
    assert_eq!(
        LensModel::from_ros("rational_polynomial", &RATIONAL.coefficients()),
        Ok(RATIONAL)
    );
    assert_eq!(
        LensModel::from_ros("equidistant", &FISHEYE.coefficients()),
        Ok(FISHEYE)
    );
    let err = LensModel::from_ros("equidistant", &[0.1; 5]).expect_err("five");
    assert!(err.contains("takes 4"), "{err}");
    let err = LensModel::from_ros("kannala_brandt", &[0.1; 4]).expect_err("unknown");
    assert!(
        err.contains("plumb_bob, rational_polynomial, equidistant"),
        "{err}"
    );
    let err = LensModel::from_ros("plumb_bob", &[f64::NAN; 5]).expect_err("NaN");
    assert!(err.contains("finite"), "{err}");
    // The JSON form names the model as ROS does.
    let json = serde_json::to_value(FISHEYE).expect("json");
    assert_eq!(json["model"], "equidistant");
    assert_eq!(
        serde_json::from_value::<LensModel>(json).expect("back"),
        FISHEYE
    );
}
