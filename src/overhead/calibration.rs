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
//!
//! With a checkerboard's intrinsics ([`super::intrinsics`]: focal lengths, principal point and
//! a plumb_bob, rational_polynomial or equidistant lens) only the six pose parameters are
//! solved, from the pose of the homography between the field plane and the undistorted clicks
//! (`start`). Either way the fit's covariance at the solution gives each parameter's standard
//! deviation ([`Uncertainty`]), which [`super::review`] holds against its limits.

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::field::FieldDescription;
use super::intrinsics::{Intrinsics, IntrinsicsError};
use super::lines::{LineObservation, find_line_observations};
use super::points::PointsFile;
use super::review::{Finding, check_points, review};
use crate::atomic_file::write_atomic;
use crate::frame::Frame;
use crate::geometry::{Field, ImagePoint, OverheadCamera, Point};
use crate::stats::median;

mod solver;
mod start;
mod uncertainty;

use solver::{Free, MIN_CONDITIONING, conditioning, covariance, solve};
use start::{camera_from_homography, starting_camera};
pub use uncertainty::{CLICK_SD_FLOOR_PX, Uncertainty};

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
    /// The intrinsics are for another frame size.
    #[error(transparent)]
    Intrinsics(#[from] IntrinsicsError),
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
    /// Each fitted parameter's standard deviation (absent in calibrations written before it
    /// was computed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<Uncertainty>,
    /// The intrinsics the lens came from (their `camera_name` or file), when only the pose was
    /// fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intrinsics: Option<String>,
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
        .chain(c.focal_y_px)
        .chain(c.lens.iter().flat_map(|l| l.coefficients()))
        .chain(self.uncertainty.iter().flat_map(Uncertainty::values))
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
                "unknown key '{key}' (an overhead calibration has format, camera, field, points, line_samples, line_rms_px, uncertainty, intrinsics)"
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
/// one is given: pose, focal length, principal point and k1/k2 ([`calibrate_with`] without
/// intrinsics).
///
/// # Errors
/// [`CalibrationError`] when there are too few or degenerate points or the solver fails.
pub fn calibrate(
    points: &PointsFile,
    field: &FieldDescription,
    image: Option<&Frame>,
    params: &CalibrationParams,
) -> Result<Calibration, CalibrationError> {
    calibrate_with(points, field, image, params, None)
}

/// Calibrates an overhead camera; with a checkerboard's `intrinsics` (scaled to the points'
/// frame size when it is a whole factor of theirs) only the pose is fitted. The result carries
/// each fitted parameter's standard deviation ([`Uncertainty`]).
///
/// # Errors
/// [`CalibrationError`] when there are too few points for the parameters, degenerate points,
/// intrinsics for another frame size, or the solver fails.
pub fn calibrate_with(
    points: &PointsFile,
    field: &FieldDescription,
    image: Option<&Frame>,
    params: &CalibrationParams,
    intrinsics: Option<&Intrinsics>,
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
    let free = if intrinsics.is_some() {
        Free::Pose
    } else {
        Free::All
    };
    let needed = min_points_for(free);
    if points.points.len() < needed {
        return Err(Finding::TooFewForParameters {
            count: points.points.len(),
            needed,
            parameters: free.indices().len(),
        }
        .into());
    }
    let intrinsics = intrinsics
        .map(|i| i.for_frame(points.width, points.height))
        .transpose()?;
    let (mut camera, prior) = match &intrinsics {
        None => first_fit(points, &targets, field, params)?,
        Some(i) => {
            let start = match camera_from_homography(i, &targets) {
                Some(c) => c,
                None => i.applied_to(starting_camera(
                    points.width,
                    points.height,
                    &targets,
                    field,
                )?),
            };
            let prior = Priors::none();
            (solve(start, &targets, &[], prior, free)?, prior)
        }
    };
    let mut lines: Vec<LineObservation> = Vec::new();
    if let (Some(frame), true) = (image, params.refine_lines) {
        (camera, lines) = refine_along_lines(frame, field, params, camera, &targets, prior, free)?;
    }
    let residuals = point_residuals(points, &targets, &camera);
    let line_rms_px = (!lines.is_empty()).then(|| {
        let s: f64 = lines.iter().map(|l| l.distance_px(&camera).powi(2)).sum();
        (s / lines.len() as f64).sqrt()
    });
    let conditioning = conditioning(camera, &targets, &lines, prior, free);
    if conditioning.is_nan() || conditioning < MIN_CONDITIONING {
        return Err(Finding::NotDetermined { conditioning }.into());
    }
    let uncertainty = covariance(camera, &targets, &lines, prior, free, CLICK_SD_FLOOR_PX)
        .map(|(cov, sigma)| Uncertainty::from_covariance(&cov, sigma, free))
        .ok_or(Finding::NotDetermined { conditioning: 0.0 })?;
    let cal = Calibration {
        camera,
        field: field.name.clone(),
        points: residuals,
        line_samples: lines.len(),
        line_rms_px,
        uncertainty: Some(uncertainty),
        intrinsics: intrinsics.map(|i| i.camera_name.clone()),
    };
    if let Some(refusal) = review(&cal).refusal() {
        return Err(refusal.clone().into());
    }
    Ok(cal)
}

/// Fewest points for a fit of these parameters: two residuals each, at least five more
/// residuals than parameters (so that the residuals say how well the parameters fit), and at
/// least [`super::review::MIN_POINTS`].
#[must_use]
fn min_points_for(free: Free) -> usize {
    (free.indices().len() + 5)
        .div_ceil(2)
        .max(super::review::MIN_POINTS)
}

/// Fewest points a calibration without intrinsics needs (pose, focal length, principal point,
/// k1, k2), and with them (the pose).
#[must_use]
pub fn min_points(with_intrinsics: bool) -> usize {
    min_points_for(if with_intrinsics {
        Free::Pose
    } else {
        Free::All
    })
}

/// The fit without intrinsics: a straight-down start, a pinhole with its principal point at
/// the image centre (pose and focal length only), then everything from there — eleven free
/// parameters from a straight-down start can run off to a folded lens on clicks over half a
/// field.
fn first_fit(
    points: &PointsFile,
    targets: &[Target],
    field: &FieldDescription,
    params: &CalibrationParams,
) -> Result<(OverheadCamera, Priors), CalibrationError> {
    let start = starting_camera(points.width, points.height, targets, field)?;
    let prior = Priors {
        height_cm: field.camera_height_guess_cm,
        height_sd_cm: params.height_prior_fraction * field.camera_height_guess_cm,
        centre: start.centre,
        centre_sd_px: params.principal_point_prior_fraction * points.width as f64,
        distortion_sd: params.distortion_prior_sd,
    };
    let pinhole = Priors {
        centre_sd_px: 1e-3,
        distortion_sd: 1e-6,
        ..prior
    };
    let camera = solve(start, targets, &[], pinhole, Free::All)?;
    Ok((solve(camera, targets, &[], prior, Free::All)?, prior))
}

/// Rounds of "find the lines near where the camera puts them, solve again"; the line samples
/// of the last solve (none when too few were found to refine).
fn refine_along_lines(
    frame: &Frame,
    field: &FieldDescription,
    params: &CalibrationParams,
    mut camera: OverheadCamera,
    targets: &[Target],
    prior: Priors,
    free: Free,
) -> Result<(OverheadCamera, Vec<LineObservation>), CalibrationError> {
    let samples = field.line_samples(params.line_step_cm);
    let margin = (5.0 * field.line_width_cm).max(10.0);
    let samples = super::lines::away_from_crossings(field, &samples, margin);
    let mut refined = false;
    let mut lines = Vec::new();
    for _ in 0..params.line_rounds {
        let found = find_line_observations(frame, &camera, &samples, params.line_search_px);
        lines = reject_outliers(&camera, found);
        if lines.len() < MIN_LINE_SAMPLES {
            break;
        }
        camera = solve(camera, targets, &lines, prior, free)?;
        refined = true;
    }
    // Samples that never took part in a solve say nothing about the fit: without a
    // refinement there are none ([`Calibration::line_samples`] 0 says it was skipped).
    let lines = if refined {
        reject_outliers(&camera, lines)
    } else {
        Vec::new()
    };
    Ok((camera, lines))
}

/// Each clicked point's reprojection through `camera`.
fn point_residuals(
    points: &PointsFile,
    targets: &[Target],
    camera: &OverheadCamera,
) -> Vec<PointResidual> {
    points
        .points
        .iter()
        .zip(targets)
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
        .collect()
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

impl Priors {
    /// No priors (every residual 0): the pose fit with known intrinsics.
    const fn none() -> Self {
        Self {
            height_cm: 0.0,
            height_sd_cm: f64::INFINITY,
            centre: ImagePoint::new(0.0, 0.0),
            centre_sd_px: f64::INFINITY,
            distortion_sd: f64::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests;
