//! Overhead camera calibration: camera pose, focal length, principal point and two radial
//! distortion terms from clicked landmarks, refined along the painted lines.
//!
//! The model is [`OverheadCamera`]'s (pinhole plus `1 + k1·r² + k2·r⁴`). Its eleven parameters
//! (position 3, rotation 3 as a small rotation vector on the starting rotation, focal 1,
//! principal point 2, k1, k2) are solved by Levenberg–Marquardt (the `levenberg-marquardt`
//! crate) on pixel residuals: each clicked point's projection minus its click, and, when the
//! image is given, each line sample's distance across its projected line from the line centre
//! found in the image's luma ([`super::lines`]). A camera looking almost straight down at a flat
//! field cannot tell its height from its focal length by ground points alone (both scale the
//! image alike), so goal-post tops above the ground pin it when clicked, and a weak prior on
//! the field description's height guess keeps the problem well posed when they are not.
//!
//! The start comes from a closed-form 2-D similarity between the ground points and the image
//! (scale, turn and mirror of a camera looking straight down), so no guess of the camera's
//! turn is needed. A pinhole (principal point at the image centre, no distortion) is fitted
//! first, then all eleven parameters, with weak priors holding the principal point near the
//! image centre and k1, k2 near 0 where the clicks alone cannot place them (a half field seen
//! by a wide lens: the real SSL 2008 frame ran off to a folded lens without them).

use std::path::Path;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::field::FieldDescription;
use super::lines::{LineObservation, find_line_observations};
use super::points::PointsFile;
use super::review::{Finding, check_points, review};
use crate::atomic_file::write_atomic;
use crate::frame::Frame;
use crate::geometry::{Camera, Field, ImagePoint, OverheadCamera, Point, PoseRecord, Transform};
use crate::stats::median;

/// Settings of the calibration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CalibrationParams {
    /// Refine along the painted lines when an image is given.
    pub refine_lines: bool,
    /// How far across a projected line to look for its centre, pixels.
    pub line_search_px: f64,
    /// Rounds of "find the lines, solve again".
    pub line_rounds: usize,
    /// Standard deviation of the prior on the camera's height, as a fraction of the field
    /// description's guess (0.15: ±52 cm for a 350 cm guess).
    pub height_prior_fraction: f64,
    /// Line samples about this far apart along the lines, centimetres.
    pub line_step_cm: f64,
    /// Standard deviation of the weak prior pulling the principal point towards the image
    /// centre, as a fraction of the image width (0.05: ±32 px at 640). Clicks on half a field
    /// leave it loosely determined; the lines, when found, outweigh it.
    pub principal_point_prior_fraction: f64,
    /// Standard deviation of the weak prior pulling k1 and k2 towards 0.
    pub distortion_prior_sd: f64,
}

impl Default for CalibrationParams {
    fn default() -> Self {
        Self {
            refine_lines: true,
            line_search_px: 7.0,
            line_rounds: 3,
            height_prior_fraction: 0.15,
            line_step_cm: 6.0,
            principal_point_prior_fraction: 0.05,
            distortion_prior_sd: 0.3,
        }
    }
}

/// Why a calibration failed.
#[derive(Debug, Error)]
pub enum CalibrationError {
    /// The points, or the camera solved from them, are refused by the checks of
    /// [`super::review`] (too few, on one line, clicked twice, outside the image; a camera below
    /// the field or one the points do not determine).
    #[error(transparent)]
    Refused(#[from] Finding),
    /// The ground points all lie on one line (or on one spot): no start can be made.
    #[error("the ground points lie on a line: click landmarks spread over the field")]
    Degenerate,
    /// The solver ended without a usable camera.
    #[error("the solver found no camera that fits ({reason})")]
    NoFit {
        /// Why.
        reason: String,
    },
    /// Reading or writing a calibration file.
    #[error("{path}: {what}")]
    File {
        /// The file.
        path: String,
        /// What went wrong.
        what: String,
    },
}

/// One clicked point's fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointResidual {
    /// Landmark name.
    pub name: String,
    /// Where it was clicked, pixels.
    pub image_px: [f64; 2],
    /// Where the fitted camera puts it, pixels.
    pub projected_px: [f64; 2],
    /// Distance between the two, pixels.
    pub error_px: f64,
}

/// A solved calibration: the camera and how well it fits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// The fitted camera.
    pub camera: OverheadCamera,
    /// Name of the field description it was fitted against.
    pub field: String,
    /// Each clicked point's reprojection error.
    pub points: Vec<PointResidual>,
    /// Line samples used in the last round of line refinement (0: no refinement: no image, or
    /// fewer than [`MIN_LINE_SAMPLES`] found along the lines).
    pub line_samples: usize,
    /// Root-mean-square distance of those samples from their projected lines, pixels.
    pub line_rms_px: Option<f64>,
}

/// The file format's tag, so that other JSON is refused clearly.
const FORMAT: &str = "eotn-overhead-calibration-1";

#[derive(Serialize, Deserialize)]
struct CalibrationFile {
    format: String,
    #[serde(flatten)]
    calibration: Calibration,
}

impl Calibration {
    /// Median of the clicked points' reprojection errors, pixels.
    #[must_use]
    pub fn median_point_error_px(&self) -> f64 {
        let e: Vec<f64> = self.points.iter().map(|p| p.error_px).collect();
        median(&e).unwrap_or(f64::NAN)
    }

    /// Every number of the calibration, for the check that none is NaN or infinite.
    fn values(&self) -> impl Iterator<Item = f64> + '_ {
        let c = &self.camera;
        [
            c.focal_px,
            c.centre.x_px,
            c.centre.y_px,
            c.k1,
            c.k2,
            c.pose.yaw_rad,
            c.pose.pitch_rad,
            c.pose.roll_rad,
        ]
        .into_iter()
        .chain(c.pose.position_cm)
        .chain(self.line_rms_px)
        .chain(self.points.iter().flat_map(|p| {
            p.image_px
                .into_iter()
                .chain(p.projected_px)
                .chain([p.error_px])
        }))
    }

    /// Writes the calibration atomically as JSON; one with a value that is not a number is
    /// never written (it could not be read back).
    ///
    /// # Errors
    /// [`CalibrationError::File`] when it has a non-finite value or cannot be written.
    pub fn save(&self, path: &Path) -> Result<(), CalibrationError> {
        let err = |what: String| CalibrationError::File {
            path: path.display().to_string(),
            what,
        };
        if !self.values().all(f64::is_finite) {
            return Err(err(
                "the calibration has a value that is not a number; not written".into(),
            ));
        }
        let file = CalibrationFile {
            format: FORMAT.into(),
            calibration: self.clone(),
        };
        let mut text = serde_json::to_string_pretty(&file).map_err(|e| err(e.to_string()))?;
        text.push('\n');
        write_atomic(path, text.as_bytes()).map_err(|e| err(e.to_string()))
    }

    /// Reads a calibration file.
    ///
    /// # Errors
    /// [`CalibrationError::File`] for a missing, oversized or non-regular file, other JSON, a key
    /// the format does not have (named), or a camera with non-finite or non-positive values.
    pub fn load(path: &Path) -> Result<Self, CalibrationError> {
        let err = |what: String| CalibrationError::File {
            path: path.display().to_string(),
            what,
        };
        let text = crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SMALL_FILE_BYTES,
            "an overhead calibration",
        )
        .map_err(|e| err(e.to_string()))?;
        Self::from_json(&text).map_err(err)
    }

    /// Parses and checks a calibration file's text.
    ///
    /// # Errors
    /// What is wrong, as a message: not JSON of this format, an unknown key (hand edits must not
    /// be silently ignored), a value that is not usable.
    pub fn from_json(text: &str) -> Result<Self, String> {
        let given: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format!("not an overhead calibration: {e}"))?;
        let file: CalibrationFile = serde_json::from_value(given.clone())
            .map_err(|e| format!("not an overhead calibration: {e}"))?;
        if file.format != FORMAT {
            return Err(format!("format {:?}, expected {FORMAT:?}", file.format));
        }
        let known = serde_json::to_value(&file).map_err(|e| e.to_string())?;
        if let Some(key) = crate::input_file::unknown_keys(&given, &known).first() {
            return Err(format!(
                "unknown key '{key}' (an overhead calibration has format, camera, field, points, line_samples, line_rms_px)"
            ));
        }
        let cal = file.calibration;
        let c = &cal.camera;
        if !cal.values().all(f64::is_finite)
            || c.focal_px <= 0.0
            || c.width_px == 0
            || c.height_px == 0
        {
            return Err("the camera has a value that is not usable".into());
        }
        Ok(cal)
    }
}

/// Calibrates an overhead camera from a points file, refined along the lines of `image` when
/// one is given.
///
/// # Errors
/// [`CalibrationError`] when there are too few or degenerate points or the solver fails.
pub fn calibrate(
    points: &PointsFile,
    field: &FieldDescription,
    image: Option<&Frame>,
    params: &CalibrationParams,
) -> Result<Calibration, CalibrationError> {
    let targets: Vec<Target> = points
        .points
        .iter()
        .map(|p| Target {
            field: Point::new(p.field_cm[0], p.field_cm[1], p.height_cm),
            image: p.image(),
        })
        .collect();
    check_points(points, field)?;
    let start = starting_camera(points.width, points.height, &targets, field)?;
    let prior = Priors {
        height_cm: field.camera_height_guess_cm,
        height_sd_cm: params.height_prior_fraction * field.camera_height_guess_cm,
        centre: start.centre,
        centre_sd_px: params.principal_point_prior_fraction * points.width as f64,
        distortion_sd: params.distortion_prior_sd,
    };
    // First a pinhole with its principal point at the image centre (pose and focal length
    // only), then everything from there: eleven free parameters from a straight-down start can
    // run off to a folded lens on clicks over half a field.
    let pinhole = Priors {
        centre_sd_px: 1e-3,
        distortion_sd: 1e-6,
        ..prior
    };
    let camera = solve(start, &targets, &[], pinhole)?;
    let mut camera = solve(camera, &targets, &[], prior)?;
    let mut lines: Vec<LineObservation> = Vec::new();
    if let (Some(frame), true) = (image, params.refine_lines) {
        let samples = field.line_samples(params.line_step_cm);
        let margin = (5.0 * field.line_width_cm).max(10.0);
        let samples = super::lines::away_from_crossings(field, &samples, margin);
        let mut refined = false;
        for _ in 0..params.line_rounds {
            let found = find_line_observations(frame, &camera, &samples, params.line_search_px);
            lines = reject_outliers(&camera, found);
            if lines.len() < MIN_LINE_SAMPLES {
                break;
            }
            camera = solve(camera, &targets, &lines, prior)?;
            refined = true;
        }
        // Samples that never took part in a solve say nothing about the fit: without a
        // refinement there are none ([`Calibration::line_samples`] 0 says it was skipped).
        lines = if refined {
            reject_outliers(&camera, lines)
        } else {
            Vec::new()
        };
    }
    let residuals = points
        .points
        .iter()
        .zip(&targets)
        .map(|(p, t)| {
            let projected = camera
                .image_from_field(&t.field)
                .unwrap_or(ImagePoint::new(f64::NAN, f64::NAN));
            PointResidual {
                name: p.name.clone(),
                image_px: p.image_px,
                projected_px: [projected.x_px, projected.y_px],
                error_px: projected.distance_to(&t.image),
            }
        })
        .collect();
    let line_rms_px = (!lines.is_empty()).then(|| {
        let s: f64 = lines.iter().map(|l| l.distance_px(&camera).powi(2)).sum();
        (s / lines.len() as f64).sqrt()
    });
    let conditioning = conditioning(camera, &targets, &lines, prior);
    if conditioning.is_nan() || conditioning < MIN_CONDITIONING {
        return Err(Finding::NotDetermined { conditioning }.into());
    }
    let cal = Calibration {
        camera,
        field: field.name.clone(),
        points: residuals,
        line_samples: lines.len(),
        line_rms_px,
    };
    if let Some(refusal) = review(&cal).refusal() {
        return Err(refusal.clone().into());
    }
    Ok(cal)
}

/// Below this, [`conditioning`] says the fit leaves some parameter free.
const MIN_CONDITIONING: f64 = 1e-9;

/// How well the residuals pin every parameter down at `camera`: the smallest over the largest
/// singular value of the Jacobian with each parameter's column scaled to unit length (0 when a
/// parameter, or a combination of them, changes nothing).
fn conditioning(
    camera: OverheadCamera,
    targets: &[Target],
    lines: &[LineObservation],
    prior: Priors,
) -> f64 {
    let problem = Problem {
        base: camera,
        base_rotation: camera.field_from_camera().rotation(),
        targets,
        lines,
        prior,
        params: params_of(&camera),
    };
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

/// Fewest line samples found along the projected lines for the lines to refine the fit.
pub const MIN_LINE_SAMPLES: usize = 10;

/// Keeps the line observations within three times the median distance (at least 1 px).
fn reject_outliers(camera: &OverheadCamera, found: Vec<LineObservation>) -> Vec<LineObservation> {
    let d: Vec<f64> = found.iter().map(|l| l.distance_px(camera).abs()).collect();
    let limit = (3.0 * median(&d).unwrap_or(0.0)).max(1.0);
    found
        .into_iter()
        .filter(|l| l.distance_px(camera).abs() <= limit)
        .collect()
}

#[derive(Debug, Clone, Copy)]
struct Target {
    field: Point<Field>,
    image: ImagePoint,
}

/// Weak priors that keep the problem well posed (each a residual of one "pixel" per standard
/// deviation).
#[derive(Debug, Clone, Copy)]
struct Priors {
    /// The field description's guess of the camera height, centimetres.
    height_cm: f64,
    /// Its standard deviation, centimetres.
    height_sd_cm: f64,
    /// Where the principal point is expected (the image centre), pixels.
    centre: ImagePoint,
    /// Its standard deviation, pixels.
    centre_sd_px: f64,
    /// Standard deviation of k1 and k2 about 0.
    distortion_sd: f64,
}

/// A camera looking straight down from the similarity that best maps the ground points to the
/// image: `w = a·z + b` in complex numbers, field `z = x + iy`, image `w = u − iv` (image y
/// points down, so the image is the field seen in a mirror).
fn starting_camera(
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
    })
}

/// Number of camera parameters.
const PARAMS: usize = 11;

/// The least-squares problem: parameters `[x, y, z, ωx, ωy, ωz, f, cx, cy, k1, k2]` with the
/// rotation `exp(ω)·R0`.
struct Problem<'a> {
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

impl Problem<'_> {
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
        for (p, v) in self.params.iter_mut().zip(x.iter()) {
            *p = *v;
        }
    }

    fn params(&self) -> DVector<f64> {
        DVector::from_column_slice(&self.params)
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self.residuals_at(&self.params);
        r.iter()
            .all(|v| v.is_finite())
            .then(|| DVector::from_vec(r))
    }

    /// Central differences: the projection through the lens has no tidy closed-form
    /// derivative, and eleven parameters make this cheap.
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let rows = self.residuals_at(&self.params).len();
        let mut j = DMatrix::zeros(rows, PARAMS);
        for k in 0..PARAMS {
            let (mut hi, mut lo) = (self.params, self.params);
            hi[k] += STEPS[k];
            lo[k] -= STEPS[k];
            let (a, b) = (self.residuals_at(&hi), self.residuals_at(&lo));
            for (row, (x, y)) in a.iter().zip(&b).enumerate() {
                j[(row, k)] = (x - y) / (2.0 * STEPS[k]);
            }
        }
        j.iter().all(|v| v.is_finite()).then_some(j)
    }
}

/// The same camera with a positive focal length: a negative one (which the solver can step
/// into, as it did on the real SSL 2008 frame) turns the image half round about the principal
/// point, which is the camera turned half round about its optical axis. The radial lens
/// model is the same either way, so every projection is unchanged.
fn with_positive_focal(camera: OverheadCamera) -> OverheadCamera {
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

fn solve(
    start: OverheadCamera,
    targets: &[Target],
    lines: &[LineObservation],
    prior: Priors,
) -> Result<OverheadCamera, CalibrationError> {
    let problem = Problem {
        base: start,
        base_rotation: start.field_from_camera().rotation(),
        targets,
        lines,
        prior,
        params: params_of(&start),
    };
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

#[cfg(test)]
mod tests;
