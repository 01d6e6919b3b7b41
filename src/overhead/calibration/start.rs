//! Where the solver starts: a camera looking straight down from a 2-D similarity of the
//! clicks (no lens known), or, with a checkerboard's intrinsics, the pose of the homography
//! between the field plane and the undistorted clicks (a camera at any tilt).

use nalgebra::{DMatrix, Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::{CalibrationError, Target};
use crate::geometry::{Camera, Field, ImagePoint, OverheadCamera, PoseRecord, Transform};
use crate::overhead::field::FieldDescription;
use crate::overhead::intrinsics::Intrinsics;

/// A camera looking straight down from the similarity that best maps the ground points to the
/// image: `w = a·z + b` in complex numbers, field `z = x + iy`, image `w = u − iv` (image y
/// points down, so the image is the field seen in a mirror).
pub(super) fn starting_camera(
    width: usize,
    height: usize,
    targets: &[Target],
    field: &FieldDescription,
) -> Result<OverheadCamera, CalibrationError> {
    let ground: Vec<&Target> = targets.iter().filter(|t| t.field.z() == 0.0).collect();
    let n = ground.len() as f64;
    let (zx, zy) = ground.iter().fold((0.0, 0.0), |(a, b), t| {
        (a + t.field.x() / n, b + t.field.y() / n)
    });
    let (wx, wy) = ground.iter().fold((0.0, 0.0), |(a, b), t| {
        (a + t.image.x_px / n, b - t.image.y_px / n)
    });
    // a = Σ conj(z − z̄)(w − w̄) / Σ |z − z̄|².
    let (mut re, mut im, mut norm) = (0.0, 0.0, 0.0);
    for t in &ground {
        let (dx, dy) = (t.field.x() - zx, t.field.y() - zy);
        let (du, dv) = (t.image.x_px - wx, -t.image.y_px - wy);
        re += dx * du + dy * dv;
        im += dx * dv - dy * du;
        norm += dx * dx + dy * dy;
    }
    let scale = re.hypot(im) / norm.max(f64::MIN_POSITIVE);
    if norm < 1.0 || !scale.is_finite() || scale <= 0.0 {
        return Err(CalibrationError::Degenerate);
    }
    let theta = im.atan2(re);
    let (ar, ai) = (scale * theta.cos(), scale * theta.sin());
    // The field point under the image centre: z0 = (w_c − b)/a with b = w̄ − a·z̄.
    let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
    let (br, bi) = (wx - (ar * zx - ai * zy), wy - (ar * zy + ai * zx));
    let (nr, ni) = (cx - br, -cy - bi);
    let d = ar * ar + ai * ai;
    let (x0, y0) = ((nr * ar + ni * ai) / d, (ni * ar - nr * ai) / d);
    let h = field.camera_height_guess_cm;
    // Camera axes in the field: optical axis down; image right is e^{−iθ}, image up i·e^{−iθ}.
    let (s, c) = theta.sin_cos();
    let m = Matrix3::from_columns(&[
        Vector3::new(0.0, 0.0, -1.0),
        Vector3::new(-c, s, 0.0),
        Vector3::new(s, c, 0.0),
    ]);
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
    let t: Transform<Field, Camera> = Transform::new(Vector3::new(x0, y0, h), rotation);
    Ok(OverheadCamera {
        width_px: width,
        height_px: height,
        focal_px: scale * h,
        centre: ImagePoint::new(cx, cy),
        k1: 0.0,
        k2: 0.0,
        pose: PoseRecord::from_transform(&t),
        focal_y_px: None,
        lens: None,
    })
}

/// The camera of `intrinsics` at the pose of the homography from the field plane to the
/// undistorted ground clicks (direct linear transform: the null vector of `AᵀA` by a symmetric
/// eigen decomposition, field coordinates centred and scaled first), its rotation made
/// orthonormal by an SVD. `None` with fewer than four ground clicks the lens can undistort,
/// or a degenerate layout.
pub(super) fn camera_from_homography(
    intrinsics: &Intrinsics,
    targets: &[Target],
) -> Option<OverheadCamera> {
    let template = intrinsics.applied_to(OverheadCamera::above_field_2005());
    // Ground clicks as (field x, y) ↔ undistorted normalised (right, down) coordinates.
    let pairs: Vec<([f64; 2], [f64; 2])> = targets
        .iter()
        .filter(|t| t.field.z() == 0.0)
        .filter_map(|t| {
            let ud = (t.image.x_px - template.centre.x_px) / template.focal_px;
            let vd = (t.image.y_px - template.centre.y_px) / template.focal_y();
            let (u, v) = intrinsics.lens.undistort(ud, vd).ok()?;
            Some(([t.field.x(), t.field.y()], [u, v]))
        })
        .collect();
    if pairs.len() < 4 {
        return None;
    }
    let n = pairs.len() as f64;
    let (mx, my) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), (f, _)| (a + f[0] / n, b + f[1] / n));
    let spread = (pairs
        .iter()
        .map(|(f, _)| (f[0] - mx).powi(2) + (f[1] - my).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    if spread.is_nan() || spread <= 1e-6 {
        return None;
    }
    let mut a = DMatrix::<f64>::zeros(2 * pairs.len(), 9);
    for (row, (f, [u, v])) in pairs.iter().enumerate() {
        let (x, y) = ((f[0] - mx) / spread, (f[1] - my) / spread);
        let r = 2 * row;
        for (c, value) in [x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, -u]
            .into_iter()
            .enumerate()
        {
            a[(r, c)] = value;
        }
        for (c, value) in [0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y, -v]
            .into_iter()
            .enumerate()
        {
            a[(r + 1, c)] = value;
        }
    }
    let eigen = (a.transpose() * &a).symmetric_eigen();
    let smallest = eigen.eigenvalues.imin();
    let h = eigen.eigenvectors.column(smallest);
    let normalised = Matrix3::from_row_slice(h.as_slice());
    // Undo the centring and scaling: H·T with T the field → normalised-field map.
    let t = Matrix3::new(
        1.0 / spread,
        0.0,
        -mx / spread,
        0.0,
        1.0 / spread,
        -my / spread,
        0.0,
        0.0,
        1.0,
    );
    let h = normalised * t;
    pose_from_plane_homography(&h, &pairs, template)
}

/// Splits `H = λ·[r1 r2 t]` (field plane → normalised camera coordinates, OpenCV axes: x
/// right, y down, z forward) into the camera's pose and returns `template` there.
fn pose_from_plane_homography(
    h: &Matrix3<f64>,
    pairs: &[([f64; 2], [f64; 2])],
    template: OverheadCamera,
) -> Option<OverheadCamera> {
    let (h1, h2, h3) = (h.column(0), h.column(1), h.column(2));
    let mut lambda = 2.0 / (h1.norm() + h2.norm());
    // The sign that puts the clicked points in front of the camera.
    let depth: f64 = pairs
        .iter()
        .map(|(f, _)| h[(2, 0)] * f[0] + h[(2, 1)] * f[1] + h[(2, 2)])
        .sum();
    if depth < 0.0 {
        lambda = -lambda;
    }
    let (r1, r2) = (h1 * lambda, h2 * lambda);
    let r3 = r1.cross(&r2);
    let approx = Matrix3::from_columns(&[r1, r2, r3]);
    let svd = approx.svd(true, true);
    let mut rotation = svd.u? * svd.v_t?;
    if rotation.determinant() < 0.0 {
        return None;
    }
    if !rotation.iter().all(|v| v.is_finite()) {
        return None;
    }
    let translation = h3 * lambda;
    // Camera position in the field: −Rᵀ·t.
    let position = -(rotation.transpose() * translation);
    // eotn's camera axes (x forward, y left, z up) in OpenCV's: x_cv = −y, y_cv = −z, z_cv = x.
    let cv_from_eotn = Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0);
    rotation = rotation.transpose() * cv_from_eotn;
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(rotation));
    let t: Transform<Field, Camera> = Transform::new(position, q);
    Some(OverheadCamera {
        pose: PoseRecord::from_transform(&t),
        ..template
    })
}
