//! The fit stage: a circle fitted to the outline, refused with a [`FitRejection`] when it
//! cannot be this blob's ball, and (when asked) the moving-circle fit of the ball's own motion.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::BallParams;
use super::outline::Outline;
use crate::frame::PixelBox;
use crate::geometry::ImagePoint;
use crate::recognition::context::ViewContext;
use crate::recognition::fit::{
    CircleFit, ShearedCircleFit, fit_circle_trimmed, fit_sheared_circle,
};
use crate::recognition::scan::CutOff;

/// Why a ball candidate's circle fit was not used (the JSON names the reason in `reason`, with
/// its measured values beside it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum FitRejection {
    /// Fewer than five outline points.
    TooFewPoints {
        /// Outline points found.
        points: usize,
    },
    /// Enough points, but they do not fit a circle (they lie on a line).
    NotACircle,
    /// The circle is much smaller than the blob.
    TooSmall {
        /// Fitted diameter, pixels.
        diameter_px: f64,
        /// The blob's uncut extent, pixels.
        extent_px: f64,
    },
    /// The points scatter too far about the circle for its radius.
    ResidualTooLarge {
        /// Standard deviation of the points' distances from the circle, pixels.
        residual_sd_px: f64,
        /// Fitted radius, pixels.
        radius_px: f64,
    },
    /// A radius over four focal lengths: no ball in front of the camera.
    BeyondAnyBall,
    /// The circle is much larger than the blob.
    TooLarge {
        /// Fitted diameter, pixels.
        diameter_px: f64,
        /// The blob's uncut extent, pixels.
        extent_px: f64,
    },
    /// The circle does not contain the box's centre or does not reach a cut side.
    MissesBlob,
}

impl fmt::Display for FitRejection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::TooFewPoints { points } => write!(f, "only {points} edge points"),
            Self::NotACircle => write!(f, "edge points do not fit a circle"),
            Self::TooSmall {
                diameter_px,
                extent_px,
            } => write!(
                f,
                "diameter {diameter_px:.1} px much smaller than blob extent {extent_px:.0} px"
            ),
            Self::ResidualTooLarge {
                residual_sd_px,
                radius_px,
            } => write!(
                f,
                "residual spread {residual_sd_px:.2} px too large for radius {radius_px:.1} px"
            ),
            Self::BeyondAnyBall => write!(f, "radius beyond any ball"),
            Self::TooLarge {
                diameter_px,
                extent_px,
            } => write!(
                f,
                "diameter {diameter_px:.1} px much larger than blob extent {extent_px:.0} px"
            ),
            Self::MissesBlob => write!(f, "circle does not hold the blob"),
        }
    }
}

/// The fit stage's outcome for one candidate.
#[derive(Debug, Clone)]
pub(super) struct CircleStage {
    /// The circle fit, if the points gave one.
    pub fit: Option<CircleFit>,
    /// Why that fit is not used, if it is not.
    pub rejection: Option<FitRejection>,
    /// The moving-circle fit, when tried.
    pub ellipse: Option<ShearedCircleFit>,
    /// That fit when it may replace the plain circle.
    pub moving: Option<ShearedCircleFit>,
}

impl CircleStage {
    /// Fits the outline's points and decides whether the fit can be the blob's ball.
    pub fn fit(outline: &Outline, ctx: &ViewContext, params: &BallParams) -> Self {
        let points = &outline.points;
        let fit = (points.len() >= 5)
            .then(|| {
                fit_circle_trimmed(
                    points,
                    params.fit_trim_sd,
                    params.fit_trim_min_px,
                    params.fit_trim_max_share,
                )
            })
            .flatten();
        let rejection = rejection(fit.as_ref(), outline, ctx, params);
        let used = fit.is_some() && rejection.is_none();
        let ellipse = (params.ellipse_fit && used && points.len() >= params.ellipse_min_points)
            .then(|| {
                fit_sheared_circle(
                    points,
                    &outline.rows,
                    ctx.reference_row(),
                    params.ellipse_vertical_shear,
                )
            })
            .flatten();
        let moving = ellipse.filter(|e| ellipse_usable(e, fit.as_ref(), params));
        Self {
            fit,
            rejection,
            ellipse,
            moving,
        }
    }

    /// Whether the circle fit gives centre and radius.
    pub fn used(&self) -> bool {
        self.fit.is_some() && self.rejection.is_none()
    }

    /// Centre (pixels, at the reference read-out time) and radius (pixels, with the radius
    /// bias): from the moving circle, the circle, or the box.
    pub fn center_and_radius(
        &self,
        outline: &Outline,
        ctx: &ViewContext,
        params: &BallParams,
    ) -> (ImagePoint, f64) {
        let (center, radius) = match (&self.fit, self.used()) {
            (Some(_), true) if self.moving.is_some() => {
                self.moving.map_or((ImagePoint::default(), 0.0), |e| {
                    (e.circle.center(), e.circle.radius)
                })
            }
            (Some(f), true) => (f.center(), f.radius),
            _ if params.skew_correction => (
                outline.unskew(ctx, params, outline.box_centre),
                outline.box_radius,
            ),
            _ => (outline.box_centre, outline.box_radius),
        };
        (center, (radius + params.radius_bias_px).max(0.5))
    }
}

/// Why `fit` cannot be the blob's ball, or `None` when it can.
fn rejection(
    fit: Option<&CircleFit>,
    outline: &Outline,
    ctx: &ViewContext,
    params: &BallParams,
) -> Option<FitRejection> {
    let points = outline.points.len();
    let extent = outline.uncut_extent();
    let Some(f) = fit else {
        return Some(if points < 5 {
            FitRejection::TooFewPoints { points }
        } else {
            FitRejection::NotACircle
        });
    };
    let diameter = 2.0 * f.radius;
    if diameter < params.min_fit_diameter_ratio * extent {
        Some(FitRejection::TooSmall {
            diameter_px: diameter,
            extent_px: extent,
        })
    } else if f.residual_sd > params.max_fit_residual_ratio * f.radius + 0.75 {
        Some(FitRejection::ResidualTooLarge {
            residual_sd_px: f.residual_sd,
            radius_px: f.radius,
        })
    } else if f.radius > 4.0 * ctx.camera.focal_px {
        Some(FitRejection::BeyondAnyBall)
    } else if extent > 0.0 && diameter > params.max_fit_diameter_ratio * extent {
        Some(FitRejection::TooLarge {
            diameter_px: diameter,
            extent_px: extent,
        })
    } else if !circle_holds_blob(f, outline.bounds, outline.cut, outline.box_shift) {
        Some(FitRejection::MissesBlob)
    } else {
        None
    }
}

/// The box's outer edges (left, top, right, bottom; pixels, a pixel's far edge for right and
/// bottom) moved by `shift`, as the skew removal moved the points the circle is fitted to.
fn shifted_edges(b: PixelBox, shift: ImagePoint) -> [f64; 4] {
    [
        f64::from(b.min_x) + shift.x_px,
        f64::from(b.min_y) + shift.y_px,
        f64::from(b.max_x + 1) + shift.x_px,
        f64::from(b.max_y + 1) + shift.y_px,
    ]
}

/// Whether a fitted circle can be the blob's ball: the box's centre lies inside it, and it
/// reaches every side the blob is cut at (a short arc of a few outline points can bend the fit
/// the wrong way, putting the circle beside the blob). `shift` moves the box as the skew removal
/// moved its centre (the circle is fitted to unskewed points).
fn circle_holds_blob(f: &CircleFit, b: PixelBox, cut: CutOff, shift: ImagePoint) -> bool {
    let [minx, miny, maxx, maxy] = shifted_edges(b, shift);
    let (bx, by) = ((minx + maxx) / 2.0, (miny + maxy) / 2.0);
    let inside = (bx - f.center_x).hypot(by - f.center_y) <= f.radius;
    let reach = 1.0;
    inside
        && (!cut.left || f.center_x - f.radius <= minx + reach)
        && (!cut.right || f.center_x + f.radius >= maxx - reach)
        && (!cut.top || f.center_y - f.radius <= miny + reach)
        && (!cut.bottom || f.center_y + f.radius >= maxy - reach)
}

/// The hidden sides the fitted circle confirms: a side bordered by robot colours (not the image
/// border) stays hidden only when the circle reaches more than `min_overhang_px` beyond the
/// blob's box there. A round side that merely lies against a white field line or a robot is
/// whole: the circle fitted to the other sides ends at the box (sample stream, frame 3: a ball
/// under a field line read "cut off: top" with the circle's top 0.4 px inside its box).
/// `shift` moves the box as the skew removal moved its centre.
#[must_use]
pub fn confirmed_cut(
    f: &CircleFit,
    b: PixelBox,
    cut: CutOff,
    shift: ImagePoint,
    image_size: (u32, u32),
    min_overhang_px: f64,
) -> CutOff {
    let [minx, miny, maxx, maxy] = shifted_edges(b, shift);
    let (w, h) = image_size;
    let keep = |hidden: bool, at_border: bool, overhang: f64| {
        hidden && (at_border || overhang > min_overhang_px)
    };
    CutOff {
        left: keep(cut.left, b.min_x == 0, minx - (f.center_x - f.radius)),
        right: keep(cut.right, b.max_x + 1 >= w, f.center_x + f.radius - maxx),
        top: keep(cut.top, b.min_y == 0, miny - (f.center_y - f.radius)),
        bottom: keep(cut.bottom, b.max_y + 1 >= h, f.center_y + f.radius - maxy),
    }
}

/// Whether a moving-circle fit may replace the plain circle: both shears determined, and a
/// radius within a quarter of the plain fit's (a wild fit on noisy points is not a ball).
fn ellipse_usable(e: &ShearedCircleFit, plain: Option<&CircleFit>, params: &BallParams) -> bool {
    e.shear_x_sd <= params.ellipse_max_shear_sd
        && e.shear_y_sd <= params.ellipse_max_shear_sd
        && plain.is_some_and(|f| (e.circle.radius - f.radius).abs() <= 0.25 * f.radius)
}
