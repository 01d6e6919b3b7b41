//! The lens models teams calibrate with a checkerboard (OpenCV, ROS `camera_calibration`), as
//! plain types: [`LensModel::PlumbBob`] (k1, k2, p1, p2, k3), [`LensModel::RationalPolynomial`]
//! (k1–k6, p1, p2) and [`LensModel::Equidistant`] (the OpenCV fisheye model, k1–k4).
//!
//! Each maps undistorted normalised image coordinates `(x, y)` — a camera-frame point's
//! right/forward and down/forward, the pinhole's image before focal length and principal point
//! — to distorted ones, with OpenCV's formulas (`calib3d`'s "Detailed description" and
//! `cv::fisheye`):
//!
//! - plumb_bob and rational_polynomial, with `r² = x² + y²`:
//!   `x' = x·(1 + k1·r² + k2·r⁴ + k3·r⁶)/(1 + k4·r² + k5·r⁴ + k6·r⁶) + 2·p1·x·y + p2·(r² + 2x²)`,
//!   `y' = y·(…)/(…) + p1·(r² + 2y²) + 2·p2·x·y` (plumb_bob: k4 = k5 = k6 = 0);
//! - equidistant, with `r = √(x² + y²)`, `θ = atan r`:
//!   `θd = θ·(1 + k1·θ² + k2·θ⁴ + k3·θ⁶ + k4·θ⁸)` and `(x', y') = (θd / r)·(x, y)`.
//!
//! Going back has no closed form: [`LensModel::undistort`] solves it by Newton's method (in two
//! dimensions for the polynomial models, on the angle for equidistant) and says so with a
//! [`LensError`] when it does not converge, or where the lens folds over (its mapping stops
//! being one-to-one), rather than returning a point that does not map back.

use serde::{Deserialize, Serialize};

/// A checkerboard-calibrated lens, by the names ROS's `distortion_model` gives it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum LensModel {
    /// OpenCV's default (Brown–Conrady): three radial and two tangential terms.
    PlumbBob {
        /// Radial r² coefficient.
        k1: f64,
        /// Radial r⁴ coefficient.
        k2: f64,
        /// Tangential coefficient (decentring).
        p1: f64,
        /// Tangential coefficient (decentring).
        p2: f64,
        /// Radial r⁶ coefficient.
        k3: f64,
    },
    /// OpenCV's `CALIB_RATIONAL_MODEL`: a ratio of radial polynomials, two tangential terms.
    RationalPolynomial {
        /// Numerator r² coefficient.
        k1: f64,
        /// Numerator r⁴ coefficient.
        k2: f64,
        /// Tangential coefficient.
        p1: f64,
        /// Tangential coefficient.
        p2: f64,
        /// Numerator r⁶ coefficient.
        k3: f64,
        /// Denominator r² coefficient.
        k4: f64,
        /// Denominator r⁴ coefficient.
        k5: f64,
        /// Denominator r⁶ coefficient.
        k6: f64,
    },
    /// The OpenCV fisheye model: the image radius follows the angle from the optical axis.
    Equidistant {
        /// θ³ coefficient.
        k1: f64,
        /// θ⁵ coefficient.
        k2: f64,
        /// θ⁷ coefficient.
        k3: f64,
        /// θ⁹ coefficient.
        k4: f64,
    },
}

/// Why a distorted point has no undistorted one.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum LensError {
    /// A coordinate is NaN or infinite.
    #[error("the image point is not a finite number")]
    NotFinite,
    /// Newton's method ended without a point that maps back (the lens folds over there, or
    /// the point lies beyond what the coefficients describe).
    #[error(
        "undistortion did not converge: the best point maps {residual:.2e} (normalised units) from the given one; the lens model folds over there or does not reach it"
    )]
    NotConverged {
        /// How far the last iterate maps from the distorted point, normalised units.
        residual: f64,
    },
    /// The fisheye angle reached 90° or more: the point is not in front of a pinhole.
    #[error("the point lies {angle_deg:.1}° from the optical axis: not in front of the camera")]
    BeyondNinetyDegrees {
        /// Its angle from the optical axis, degrees.
        angle_deg: f64,
    },
}

/// Newton iterations before [`LensError::NotConverged`].
const MAX_ITERATIONS: usize = 100;
/// An undistorted point is accepted when it maps back within this, normalised units (about
/// 10⁻⁷ px at any focal length a camera has).
const TOLERANCE: f64 = 1e-10;

impl LensModel {
    /// The name ROS's `distortion_model` gives it.
    #[must_use]
    pub const fn ros_name(&self) -> &'static str {
        match self {
            Self::PlumbBob { .. } => "plumb_bob",
            Self::RationalPolynomial { .. } => "rational_polynomial",
            Self::Equidistant { .. } => "equidistant",
        }
    }

    /// The coefficients in ROS's `distortion_coefficients` order (plumb_bob `k1 k2 p1 p2 k3`,
    /// rational_polynomial `k1 k2 p1 p2 k3 k4 k5 k6`, equidistant `k1 k2 k3 k4`).
    #[must_use]
    pub fn coefficients(&self) -> Vec<f64> {
        match *self {
            Self::PlumbBob { k1, k2, p1, p2, k3 } => vec![k1, k2, p1, p2, k3],
            Self::RationalPolynomial {
                k1,
                k2,
                p1,
                p2,
                k3,
                k4,
                k5,
                k6,
            } => vec![k1, k2, p1, p2, k3, k4, k5, k6],
            Self::Equidistant { k1, k2, k3, k4 } => vec![k1, k2, k3, k4],
        }
    }

    /// The model ROS names `name` with its `distortion_coefficients`. plumb_bob takes 4 or 5
    /// (k3 = 0 when 4, as OpenCV does), rational_polynomial 8, equidistant 4.
    ///
    /// # Errors
    /// An unknown model (the known ones listed) or the wrong number of coefficients, as a
    /// message.
    pub fn from_ros(name: &str, d: &[f64]) -> Result<Self, String> {
        let count = |want: &str| {
            format!(
                "distortion_model {name} takes {want} distortion_coefficients, the file has {}",
                d.len()
            )
        };
        let model = match (name, d) {
            ("plumb_bob", &[k1, k2, p1, p2]) => Self::PlumbBob {
                k1,
                k2,
                p1,
                p2,
                k3: 0.0,
            },
            ("plumb_bob", &[k1, k2, p1, p2, k3]) => Self::PlumbBob { k1, k2, p1, p2, k3 },
            ("plumb_bob", _) => return Err(count("4 or 5")),
            ("rational_polynomial", &[k1, k2, p1, p2, k3, k4, k5, k6]) => {
                Self::RationalPolynomial {
                    k1,
                    k2,
                    p1,
                    p2,
                    k3,
                    k4,
                    k5,
                    k6,
                }
            }
            ("rational_polynomial", _) => return Err(count("8")),
            ("equidistant", &[k1, k2, k3, k4]) => Self::Equidistant { k1, k2, k3, k4 },
            ("equidistant", _) => return Err(count("4")),
            _ => {
                return Err(format!(
                    "distortion_model {name:?} is not one eotn knows (plumb_bob, rational_polynomial, equidistant)"
                ));
            }
        };
        if !model.coefficients().iter().all(|v| v.is_finite()) {
            return Err("a distortion coefficient is not a finite number".into());
        }
        Ok(model)
    }

    /// Applies the lens: undistorted normalised coordinates → distorted ones.
    #[must_use]
    pub fn distort(&self, x: f64, y: f64) -> (f64, f64) {
        match *self {
            Self::PlumbBob { k1, k2, p1, p2, k3 } => {
                polynomial(x, y, [k1, k2, k3], [0.0; 3], p1, p2)
            }
            Self::RationalPolynomial {
                k1,
                k2,
                p1,
                p2,
                k3,
                k4,
                k5,
                k6,
            } => polynomial(x, y, [k1, k2, k3], [k4, k5, k6], p1, p2),
            Self::Equidistant { k1, k2, k3, k4 } => {
                let r = x.hypot(y);
                if r < 1e-15 {
                    return (x, y);
                }
                let scale = equidistant_theta_d(r.atan(), [k1, k2, k3, k4]) / r;
                (x * scale, y * scale)
            }
        }
    }

    /// Removes the lens: distorted normalised coordinates → undistorted ones.
    ///
    /// # Errors
    /// [`LensError`] for a non-finite point, one beyond 90° (equidistant), or where Newton's
    /// method does not reach a point that maps back within 10⁻¹⁰.
    pub fn undistort(&self, xd: f64, yd: f64) -> Result<(f64, f64), LensError> {
        if !(xd.is_finite() && yd.is_finite()) {
            return Err(LensError::NotFinite);
        }
        match *self {
            Self::Equidistant { k1, k2, k3, k4 } => undistort_equidistant(xd, yd, [k1, k2, k3, k4]),
            _ => self.undistort_newton(xd, yd),
        }
    }

    /// Two-dimensional Newton on `distort(x, y) = (xd, yd)` from `(xd, yd)`, with the
    /// Jacobian by central differences and the step halved while it does not bring the point
    /// closer.
    fn undistort_newton(&self, xd: f64, yd: f64) -> Result<(f64, f64), LensError> {
        let miss = |x: f64, y: f64| {
            let (a, b) = self.distort(x, y);
            (a - xd, b - yd)
        };
        let (mut x, mut y) = (xd, yd);
        let (mut fx, mut fy) = miss(x, y);
        for _ in 0..MAX_ITERATIONS {
            let norm = fx.hypot(fy);
            if norm < TOLERANCE {
                return Ok((x, y));
            }
            let h = 1e-7 * (1.0 + x.hypot(y));
            let (ax, ay) = self.distort(x + h, y);
            let (bx, by) = self.distort(x - h, y);
            let (cx, cy) = self.distort(x, y + h);
            let (dx, dy) = self.distort(x, y - h);
            let (j11, j21) = ((ax - bx) / (2.0 * h), (ay - by) / (2.0 * h));
            let (j12, j22) = ((cx - dx) / (2.0 * h), (cy - dy) / (2.0 * h));
            let det = j11 * j22 - j12 * j21;
            // A Jacobian that is singular or turns the image over: the lens folds here.
            if !(det.is_finite() && det > 1e-12) {
                return Err(LensError::NotConverged { residual: norm });
            }
            let sx = (j22 * fx - j12 * fy) / det;
            let sy = (j11 * fy - j21 * fx) / det;
            let mut t = 1.0;
            loop {
                let (nx, ny) = (x - t * sx, y - t * sy);
                let (gx, gy) = miss(nx, ny);
                if gx.hypot(gy) < norm || t < 1e-6 {
                    (x, y, fx, fy) = (nx, ny, gx, gy);
                    break;
                }
                t /= 2.0;
            }
        }
        if fx.hypot(fy) < TOLERANCE {
            Ok((x, y))
        } else {
            Err(LensError::NotConverged {
                residual: fx.hypot(fy),
            })
        }
    }
}

/// OpenCV's rational/plumb_bob distortion of one normalised point.
fn polynomial(x: f64, y: f64, num: [f64; 3], den: [f64; 3], p1: f64, p2: f64) -> (f64, f64) {
    let r2 = x * x + y * y;
    let (r4, r6) = (r2 * r2, r2 * r2 * r2);
    let radial = (1.0 + num[0] * r2 + num[1] * r4 + num[2] * r6)
        / (1.0 + den[0] * r2 + den[1] * r4 + den[2] * r6);
    (
        x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
        y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
    )
}

/// `θd = θ·(1 + k1·θ² + k2·θ⁴ + k3·θ⁶ + k4·θ⁸)`.
fn equidistant_theta_d(theta: f64, k: [f64; 4]) -> f64 {
    let t2 = theta * theta;
    theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))))
}

/// The fisheye inverse: θ from θd by Newton's method, then `r = tan θ`.
fn undistort_equidistant(xd: f64, yd: f64, k: [f64; 4]) -> Result<(f64, f64), LensError> {
    let rd = xd.hypot(yd);
    if rd < 1e-15 {
        return Ok((xd, yd));
    }
    let mut theta = rd.min(1.5);
    let mut miss = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        miss = equidistant_theta_d(theta, k) - rd;
        if miss.abs() < TOLERANCE {
            break;
        }
        let t2 = theta * theta;
        let slope =
            1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
        if !(slope.is_finite() && slope > 1e-9) {
            return Err(LensError::NotConverged {
                residual: miss.abs(),
            });
        }
        theta -= miss / slope;
        if !theta.is_finite() {
            break;
        }
    }
    if !(miss.abs() < TOLERANCE && theta.is_finite() && theta >= 0.0) {
        return Err(LensError::NotConverged {
            residual: miss.abs(),
        });
    }
    if theta >= std::f64::consts::FRAC_PI_2 {
        return Err(LensError::BeyondNinetyDegrees {
            angle_deg: theta.to_degrees(),
        });
    }
    let scale = theta.tan() / rd;
    Ok((xd * scale, yd * scale))
}

#[cfg(test)]
mod tests;
