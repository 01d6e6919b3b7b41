//! How well the clicks determine each fitted parameter: standard deviations from the fit's
//! covariance at the solution ([`super::solver::covariance`]), in the units a user reads.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::solver::Free;

/// The least pixel error the standard deviations assume, pixels: a click is no better than
/// half a pixel however well a few points happen to fit (exact synthetic clicks would
/// otherwise claim a camera known to the micrometre).
pub const CLICK_SD_FLOOR_PX: f64 = 0.5;

/// Standard deviations of a calibration's fitted parameters (one standard deviation; `None`
/// for a parameter the intrinsics fix).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Uncertainty {
    /// The pixel error the figures assume: the fit's residuals' own spread
    /// (`√(Σr² / (residuals − parameters))`), at least [`CLICK_SD_FLOOR_PX`], pixels.
    pub residual_sd_px: f64,
    /// The camera's position along field x, y and z, centimetres.
    pub position_cm: [f64; 3],
    /// The camera's rotation about the field's x, y and z axes, degrees.
    pub rotation_deg: [f64; 3],
    /// Focal length, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focal_px: Option<f64>,
    /// Principal point x and y, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_px: Option<[f64; 2]>,
    /// k1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k1: Option<f64>,
    /// k2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k2: Option<f64>,
}

impl Uncertainty {
    /// The standard deviations of a covariance in [`Free::indices`] order.
    pub(super) fn from_covariance(cov: &DMatrix<f64>, residual_sd_px: f64, free: Free) -> Self {
        let sd = |k: usize| cov.get((k, k)).map_or(f64::NAN, |v| v.max(0.0).sqrt());
        let lens = free == Free::All;
        Self {
            residual_sd_px,
            position_cm: [sd(0), sd(1), sd(2)],
            rotation_deg: [sd(3), sd(4), sd(5)].map(f64::to_degrees),
            focal_px: lens.then(|| sd(6)),
            centre_px: lens.then(|| [sd(7), sd(8)]),
            k1: lens.then(|| sd(9)),
            k2: lens.then(|| sd(10)),
        }
    }

    /// The largest of the position's three standard deviations, centimetres (NaN when one
    /// is).
    #[must_use]
    pub fn position_sd_cm(&self) -> f64 {
        if self.position_cm.iter().any(|v| v.is_nan()) {
            return f64::NAN;
        }
        self.position_cm.into_iter().fold(0.0, f64::max)
    }

    /// Every number, for the check that none is NaN or infinite.
    pub(super) fn values(&self) -> Vec<f64> {
        let mut v = vec![self.residual_sd_px];
        v.extend(self.position_cm);
        v.extend(self.rotation_deg);
        v.extend(self.focal_px);
        v.extend(self.centre_px.into_iter().flatten());
        v.extend(self.k1);
        v.extend(self.k2);
        v
    }
}
