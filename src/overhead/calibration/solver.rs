//! The calibration's least-squares problem for the `levenberg-marquardt` crate: the camera's
//! eleven parameters (or, with a checkerboard's intrinsics, only its pose), the residuals
//! (clicks, line samples, weak priors), their Jacobian by central differences, and what the
//! Jacobian says at the solution: how well it pins the parameters down ([`conditioning`]) and
//! their covariance ([`covariance`]).

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned, UnitQuaternion, Vector3};

use super::{CalibrationError, Priors, Target};
use crate::geometry::{Camera, Field, ImagePoint, OverheadCamera, PoseRecord, Transform};
use crate::overhead::lines::LineObservation;

/// Which parameters the solver moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Free {
    /// All eleven: pose, focal length, principal point, k1, k2.
    All,
    /// The pose (position and rotation) only: the intrinsics are known.
    Pose,
}

impl Free {
    /// The indices into the parameter vector that move.
    pub(super) const fn indices(self) -> &'static [usize] {
        match self {
            Self::All => &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10],
            Self::Pose => &[0, 1, 2, 3, 4, 5],
        }
    }
}

/// Below this, [`conditioning`] says the fit leaves some parameter free.
pub(super) const MIN_CONDITIONING: f64 = 1e-9;

/// How well the residuals pin every parameter down at `camera`: the smallest over the largest
/// singular value of the Jacobian with each parameter's column scaled to unit length (0 when a
/// parameter, or a combination of them, changes nothing).
pub(super) fn conditioning(
    camera: OverheadCamera,
    targets: &[Target],
    lines: &[LineObservation],
    prior: Priors,
    free: Free,
) -> f64 {
    let problem = Problem::new(camera, targets, lines, prior, free);
    let Some(mut j) = problem.jacobian() else {
        return 0.0;
    };
    for mut column in j.column_iter_mut() {
        let norm = column.norm();
        if norm > 0.0 {
            column /= norm;
        }
    }
    let s = j.singular_values();
    let (lo, hi) = (s.min(), s.max());
    if hi > 0.0 { lo / hi } else { 0.0 }
}

/// Number of camera parameters.
pub(super) const PARAMS: usize = 11;

/// The least-squares problem: parameters `[x, y, z, ωx, ωy, ωz, f, cx, cy, k1, k2]` with the
/// rotation `exp(ω)·R0`.
struct Problem<'a> {
    free: Free,
    base: OverheadCamera,
    base_rotation: UnitQuaternion<f64>,
    targets: &'a [Target],
    lines: &'a [LineObservation],
    prior: Priors,
    params: [f64; PARAMS],
}

/// Residual of a point the camera cannot see, pixels: large, so the solver moves away, but
/// finite, so it keeps going.
const UNSEEN_PX: f64 = 1000.0;

impl<'a> Problem<'a> {
    /// The problem of fitting `free` parameters from `base`, the other parameters held.
    fn new(
        base: OverheadCamera,
        targets: &'a [Target],
        lines: &'a [LineObservation],
        prior: Priors,
        free: Free,
    ) -> Self {
        Self {
            free,
            base,
            base_rotation: base.field_from_camera().rotation(),
            targets,
            lines,
            prior,
            params: params_of(&base),
        }
    }

    /// The camera of a parameter vector, and its `field_from_camera` built directly (the
    /// camera's pose record goes through Euler angles, which lose digits near straight down).
    fn model(&self, p: &[f64; PARAMS]) -> (OverheadCamera, Transform<Field, Camera>) {
        let rotation =
            UnitQuaternion::from_scaled_axis(Vector3::new(p[3], p[4], p[5])) * self.base_rotation;
        let t: Transform<Field, Camera> = Transform::new(Vector3::new(p[0], p[1], p[2]), rotation);
        let camera = OverheadCamera {
            focal_px: p[6],
            centre: ImagePoint::new(p[7], p[8]),
            k1: p[9],
            k2: p[10],
            pose: PoseRecord::from_transform(&t),
            ..self.base
        };
        (camera, t)
    }

    fn camera(&self, p: &[f64; PARAMS]) -> OverheadCamera {
        self.model(p).0
    }

    fn residuals_at(&self, p: &[f64; PARAMS]) -> Vec<f64> {
        let len = 2 * self.targets.len() + self.lines.len() + 5;
        let (camera, field_from_camera) = self.model(p);
        let camera_from_field = field_from_camera.inverse();
        let mut r = Vec::with_capacity(len);
        for t in self.targets {
            match camera.image_from_camera(&(camera_from_field * t.field)) {
                Some(q) => {
                    r.push(q.x_px - t.image.x_px);
                    r.push(q.y_px - t.image.y_px);
                }
                None => r.extend([UNSEEN_PX, UNSEEN_PX]),
            }
        }
        for l in self.lines {
            let d = l.distance_px_with(&camera, &camera_from_field);
            r.push(if d.is_finite() { d } else { UNSEEN_PX });
        }
        // The priors in pixel-like units: one "pixel" per standard deviation.
        let q = &self.prior;
        r.push((p[2] - q.height_cm) / q.height_sd_cm.max(1e-6));
        r.push((p[7] - q.centre.x_px) / q.centre_sd_px.max(1e-9));
        r.push((p[8] - q.centre.y_px) / q.centre_sd_px.max(1e-9));
        r.push(p[9] / q.distortion_sd.max(1e-12));
        r.push(p[10] / q.distortion_sd.max(1e-12));
        r
    }
}

fn params_of(camera: &OverheadCamera) -> [f64; PARAMS] {
    let o = camera.pose.position_cm;
    [
        o[0],
        o[1],
        o[2],
        0.0,
        0.0,
        0.0,
        camera.focal_px,
        camera.centre.x_px,
        camera.centre.y_px,
        camera.k1,
        camera.k2,
    ]
}

/// Finite-difference steps per parameter: small against each one's scale.
const STEPS: [f64; PARAMS] = [
    1e-3, 1e-3, 1e-3, 1e-6, 1e-6, 1e-6, 1e-3, 1e-3, 1e-3, 1e-6, 1e-6,
];

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        for (&k, v) in self.free.indices().iter().zip(x.iter()) {
            self.params[k] = *v;
        }
    }

    fn params(&self) -> DVector<f64> {
        DVector::from_iterator(
            self.free.indices().len(),
            self.free.indices().iter().map(|&k| self.params[k]),
        )
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self.residuals_at(&self.params);
        r.iter()
            .all(|v| v.is_finite())
            .then(|| DVector::from_vec(r))
    }

    /// Central differences: the projection through the lens has no tidy closed-form
    /// derivative, and eleven parameters make this cheap. One column per free parameter.
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let rows = self.residuals_at(&self.params).len();
        let free = self.free.indices();
        let mut j = DMatrix::zeros(rows, free.len());
        for (column, &k) in free.iter().enumerate() {
            let (mut hi, mut lo) = (self.params, self.params);
            hi[k] += STEPS[k];
            lo[k] -= STEPS[k];
            let (a, b) = (self.residuals_at(&hi), self.residuals_at(&lo));
            for (row, (x, y)) in a.iter().zip(&b).enumerate() {
                j[(row, column)] = (x - y) / (2.0 * STEPS[k]);
            }
        }
        j.iter().all(|v| v.is_finite()).then_some(j)
    }
}

/// The same camera with a positive focal length: a negative one (which the solver can step
/// into, as it did on the real SSL 2008 frame) turns the image half round about the principal
/// point, which is the camera turned half round about its optical axis. The radial lens
/// model is the same either way, so every projection is unchanged.
pub(super) fn with_positive_focal(camera: OverheadCamera) -> OverheadCamera {
    if camera.focal_px >= 0.0 {
        return camera;
    }
    let t = camera.field_from_camera();
    let half_turn = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
    let turned: Transform<Field, Camera> =
        Transform::new(t.origin().coords.coords, t.rotation() * half_turn);
    OverheadCamera {
        focal_px: -camera.focal_px,
        pose: PoseRecord::from_transform(&turned),
        ..camera
    }
}

pub(super) fn solve(
    start: OverheadCamera,
    targets: &[Target],
    lines: &[LineObservation],
    prior: Priors,
    free: Free,
) -> Result<OverheadCamera, CalibrationError> {
    let problem = Problem::new(start, targets, lines, prior, free);
    let (problem, report) = LevenbergMarquardt::new()
        .with_patience(200)
        .minimize(problem);
    let camera = with_positive_focal(problem.camera(&problem.params));
    let finite = problem.params.iter().all(|v| v.is_finite());
    if !finite || !report.objective_function.is_finite() || camera.focal_px <= 0.0 {
        return Err(CalibrationError::NoFit {
            reason: format!(
                "{:?}, focal {:.1} px, objective {:.3e}",
                report.termination, camera.focal_px, report.objective_function
            ),
        });
    }
    Ok(camera)
}

/// The fit's covariance at `camera`, in the order of [`Free::indices`], with the pixel
/// residuals' standard deviation it assumes: `(Jₚᵀ·Jₚ / σ² + J_qᵀ·J_q)⁻¹`, `Jₚ` the rows of the
/// clicks and line samples, `J_q` those of the priors (already one unit per standard
/// deviation), and `σ` the residuals' own spread (`√(Σr² / (rows − parameters))`), at least
/// `floor_px`. `None` when there are no more pixel residuals than parameters or the matrix is
/// singular (some parameter is not determined at all).
pub(super) fn covariance(
    camera: OverheadCamera,
    targets: &[Target],
    lines: &[LineObservation],
    prior: Priors,
    free: Free,
    floor_px: f64,
) -> Option<(DMatrix<f64>, f64)> {
    let problem = Problem::new(camera, targets, lines, prior, free);
    let j = problem.jacobian()?;
    let r = problem.residuals_at(&problem.params);
    let pixel_rows = 2 * targets.len() + lines.len();
    let n = free.indices().len();
    if pixel_rows <= n {
        return None;
    }
    let ssr: f64 = r[..pixel_rows].iter().map(|v| v * v).sum();
    let sigma = (ssr / (pixel_rows - n) as f64).sqrt().max(floor_px);
    let jp = j.rows(0, pixel_rows);
    let jq = j.rows(pixel_rows, j.nrows() - pixel_rows);
    let information = jp.transpose() * jp / (sigma * sigma) + jq.transpose() * jq;
    let cov = information.cholesky()?.inverse();
    cov.iter().all(|v| v.is_finite()).then_some((cov, sigma))
}
