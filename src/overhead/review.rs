//! Whether an overhead calibration can be trusted: the one place its checks live, used by
//! `eotn overhead calibrate`, by `overhead detect` and `eval` on the calibration they are given,
//! and by the app. A solver always ends somewhere; these checks say when where it ended is not
//! a camera over this field.
//!
//! Before solving ([`check_points`]): fewer than [`MIN_POINTS`] points, points on one line, the
//! same landmark clicked twice, or a click outside the image refuse. After solving ([`review`],
//! which takes the solved calibration): a clicked point the camera cannot see, or a camera
//! below the field, refuse ([`Severity::Refuse`]); a median residual over 2 px or any over 8 px,
//! a focal length outside 0.3–3 image widths, a principal point outside the middle half of the
//! image, |k1| over 1, or a camera not 0.5–15 m above the field are doubts
//! ([`Severity::Doubt`]: the command line writes such a calibration only with `--accept`), and
//! so are the points not determining the camera: without intrinsics, clicks spanning less than
//! half the image's width or height ([`MIN_COVERAGE`]); any fit whose camera position has a
//! standard deviation over 25 cm, focal length over 6 %, or principal point over 3 % of the
//! image width (from the fit's covariance, [`Uncertainty`]); and points whose coordinates are
//! not those of the field description's landmark of that name (points for another field).
//! Fewer points than the fitted parameters need (five residuals to spare) refuse. Points more
//! than half a metre outside the field description (another field, wrong units?) are noted
//! ([`Severity::Note`]).

use std::collections::HashSet;

use super::calibration::{Calibration, Uncertainty};
use super::field::FieldDescription;
use super::points::PointsFile;
use crate::geometry::OverheadCamera;

/// Fewest clicked points a calibration is solved from (11 parameters: 12 residuals at least).
pub const MIN_POINTS: usize = 6;
/// A median reprojection error above this is doubtful, pixels.
pub const MAX_MEDIAN_RESIDUAL_PX: f64 = 2.0;
/// Any one reprojection error above this is doubtful, pixels.
pub const MAX_RESIDUAL_PX: f64 = 8.0;
/// Focal lengths outside this range of image widths are doubtful.
pub const FOCAL_WIDTHS: (f64, f64) = (0.3, 3.0);
/// |k1| above this is doubtful (a lens folded over itself, clicks swapped).
pub const MAX_K1: f64 = 1.0;
/// Camera heights outside this range are doubtful, centimetres (0.5–15 m).
pub const HEIGHT_RANGE_CM: (f64, f64) = (50.0, 1500.0);
/// Without intrinsics, the clicks must span at least this fraction of the image's width and of
/// its height (their bounding box): the lens (focal length, principal point, distortion) is
/// seen only where points are.
pub const MIN_COVERAGE: f64 = 0.5;
/// A camera position whose standard deviation (the largest of x, y, z) exceeds this is not
/// determined by the clicks, centimetres. About twice what every landmark of the 2005 field
/// clicked with 1 px of noise gives the simulator's camera looking straight down (13 cm, its
/// height, which ground points cannot tell from the focal length): the two click sets
/// gave cameras 42 cm apart.
pub const MAX_POSITION_SD_CM: f64 = 25.0;
/// A focal length whose standard deviation exceeds this fraction of it is not determined
/// (the same clicks: 3.6 %; the two fits: 492 and 408 px).
pub const MAX_FOCAL_SD_FRACTION: f64 = 0.06;
/// A principal point whose standard deviation (x or y) exceeds this fraction of the image
/// width is not determined (the weak prior alone holds it: 5 % of the width).
pub const MAX_CENTRE_SD_FRACTION: f64 = 0.03;
/// A clicked point's field coordinates this far from the field description's landmark of the
/// same name mean the points were made for another field, centimetres.
pub const LANDMARK_MISMATCH_CM: f64 = 5.0;
/// Clicked points farther than this beyond the field description's landmarks and lines are
/// outside the field, centimetres.
pub const OUTSIDE_FIELD_MARGIN_CM: f64 = 50.0;
/// Ground points spread across their line by less than this fraction of their spread along it
/// are on one line.
const COLLINEAR_FRACTION: f64 = 0.02;

/// How bad a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// Said, nothing more.
    Note,
    /// Doubtful: written only when the user accepts it.
    Doubt,
    /// Not a camera over this field: never used or written.
    Refuse,
}

/// Something wrong with clicked points or a solved calibration.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Finding {
    /// Too few points to solve the camera.
    #[error(
        "{count} calibration points, at least {MIN_POINTS} are needed (3 of them on the ground)"
    )]
    TooFewPoints {
        /// Points given.
        count: usize,
    },
    /// The clicked landmarks lie on one line (or one spot): the camera's turn about that line
    /// is not determined.
    #[error(
        "the clicked landmarks lie on one line (spread {across_cm:.1} cm across it, {along_cm:.1} cm along): click landmarks spread over the field"
    )]
    Collinear {
        /// Spread across the best line, centimetres (standard deviation).
        across_cm: f64,
        /// Spread along it, centimetres.
        along_cm: f64,
    },
    /// Fewer points than the fitted parameters need.
    #[error(
        "{count} calibration points, {needed} are needed to fit {parameters} parameters (two residuals per point, five to spare){hint}",
        hint = if *parameters > 6 { "; with the lens's intrinsics (--intrinsics) only the pose is fitted, from fewer points" } else { "" }
    )]
    TooFewForParameters {
        /// Points given.
        count: usize,
        /// Points needed.
        needed: usize,
        /// Parameters fitted.
        parameters: usize,
    },
    /// Without intrinsics, clicks in one part of the image only.
    #[error(
        "the clicks cover {x_pct:.0}% of the image width and {y_pct:.0}% of its height (x {x0:.0}–{x1:.0}, y {y0:.0}–{y1:.0} px): fitting the lens needs clicks spread over at least {need:.0}% of each; click landmarks across the whole image, or give the lens's intrinsics (--intrinsics) so that only the pose is fitted",
        need = MIN_COVERAGE * 100.0
    )]
    Clustered {
        /// Width covered, percent.
        x_pct: f64,
        /// Height covered, percent.
        y_pct: f64,
        /// Leftmost click, pixels.
        x0: f64,
        /// Rightmost click, pixels.
        x1: f64,
        /// Topmost click, pixels.
        y0: f64,
        /// Bottommost click, pixels.
        y1: f64,
    },
    /// A fitted parameter the clicks leave uncertain.
    #[error(
        "the clicks do not determine the {what}: standard deviation {sd:.2} {unit} (limit {limit:.2} {unit}); click more landmarks spread over the image{hint}",
        hint = if *with_intrinsics { "" } else { ", or give the lens's intrinsics (--intrinsics)" }
    )]
    Uncertain {
        /// Which parameter.
        what: &'static str,
        /// Its standard deviation.
        sd: f64,
        /// The limit.
        limit: f64,
        /// The unit of both.
        unit: &'static str,
        /// Whether the lens was given (then only the pose was fitted).
        with_intrinsics: bool,
    },
    /// A clicked point at other coordinates than the field's landmark of the same name.
    #[error(
        "point {name:?} is at ({x:.0}, {y:.0}) cm in the points file, the field description {field:?} has it at ({fx:.0}, {fy:.0}) cm: points made for another field? (--field names the field)"
    )]
    LandmarkMismatch {
        /// The point's name.
        name: String,
        /// The field description's name.
        field: String,
        /// Points file x, centimetres.
        x: f64,
        /// Points file y, centimetres.
        y: f64,
        /// The field's x, centimetres.
        fx: f64,
        /// The field's y, centimetres.
        fy: f64,
    },
    /// The same landmark clicked twice.
    #[error("landmark {name:?} is clicked twice")]
    DuplicateName {
        /// Its name.
        name: String,
    },
    /// A click outside the image the points are for.
    #[error(
        "point {name:?} is clicked at ({x:.1}, {y:.1}), outside the {width}x{height} image (points for another image size?)"
    )]
    OutsideImage {
        /// The point's name.
        name: String,
        /// Where it was clicked, pixels.
        x: f64,
        /// Where it was clicked, pixels.
        y: f64,
        /// Image width, pixels.
        width: usize,
        /// Image height, pixels.
        height: usize,
    },
    /// The solver's parameters are not pinned down by the points (a degenerate layout).
    #[error(
        "the fit does not determine the camera (conditioning {conditioning:.1e}): click landmarks spread over the field, some off the ground"
    )]
    NotDetermined {
        /// Smallest over largest singular value of the scaled Jacobian.
        conditioning: f64,
    },
    /// A clicked point the solved camera cannot see.
    #[error("the solved camera does not see point {name:?}")]
    NotSeen {
        /// The point's name.
        name: String,
    },
    /// The solved camera is at or below the carpet.
    #[error(
        "the solved camera is {height_cm:.1} cm above the field, that is below it: the clicks do not match the landmarks"
    )]
    CameraBelowField {
        /// Its height, centimetres.
        height_cm: f64,
    },
    /// The median reprojection error is large.
    #[error("median reprojection error {px:.2} px (over {MAX_MEDIAN_RESIDUAL_PX} px)")]
    MedianResidual {
        /// The median, pixels.
        px: f64,
    },
    /// One point's reprojection error is large.
    #[error(
        "point {name:?} is {px:.2} px from where the camera puts it (over {MAX_RESIDUAL_PX} px: a wrong click or landmark?)"
    )]
    LargeResidual {
        /// The point's name.
        name: String,
        /// Its error, pixels.
        px: f64,
    },
    /// A focal length unlike any lens.
    #[error("focal length {focal_px:.1} px is {widths:.2} image widths (expected {lo}–{hi})", lo = FOCAL_WIDTHS.0, hi = FOCAL_WIDTHS.1)]
    Focal {
        /// The focal length, pixels.
        focal_px: f64,
        /// In image widths.
        widths: f64,
    },
    /// A principal point far from the image centre.
    #[error(
        "principal point ({x:.1}, {y:.1}) px is outside the middle half of the {width}x{height} image"
    )]
    PrincipalPoint {
        /// Its x, pixels.
        x: f64,
        /// Its y, pixels.
        y: f64,
        /// Image width, pixels.
        width: usize,
        /// Image height, pixels.
        height: usize,
    },
    /// Radial distortion beyond a real lens.
    #[error("radial distortion k1 = {k1:.3} (|k1| over {MAX_K1}: swapped clicks?)")]
    Distortion {
        /// The coefficient.
        k1: f64,
    },
    /// A camera height unlike an overhead camera's.
    #[error("the camera is {height_m:.2} m above the field (expected {lo}–{hi} m: a field in other units?)", lo = HEIGHT_RANGE_CM.0 / 100.0, hi = HEIGHT_RANGE_CM.1 / 100.0)]
    Height {
        /// Its height, metres.
        height_m: f64,
    },
    /// A clicked point outside the field description.
    #[error(
        "point {name:?} at ({x:.0}, {y:.0}) cm lies outside the field description {field:?} (another field, or other units? --field names the field)"
    )]
    OutsideField {
        /// The point's name.
        name: String,
        /// The field description's name.
        field: String,
        /// Field x, centimetres.
        x: f64,
        /// Field y, centimetres.
        y: f64,
    },
}

impl Finding {
    /// How bad it is.
    #[must_use]
    pub const fn severity(&self) -> Severity {
        match self {
            Self::TooFewPoints { .. }
            | Self::Collinear { .. }
            | Self::DuplicateName { .. }
            | Self::OutsideImage { .. }
            | Self::NotDetermined { .. }
            | Self::NotSeen { .. }
            | Self::CameraBelowField { .. }
            | Self::TooFewForParameters { .. } => Severity::Refuse,
            Self::MedianResidual { .. }
            | Self::LargeResidual { .. }
            | Self::Focal { .. }
            | Self::PrincipalPoint { .. }
            | Self::Distortion { .. }
            | Self::Height { .. }
            | Self::Clustered { .. }
            | Self::Uncertain { .. }
            | Self::LandmarkMismatch { .. } => Severity::Doubt,
            Self::OutsideField { .. } => Severity::Note,
        }
    }
}

/// The findings on a calibration, worst first.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Review {
    /// Everything found.
    pub findings: Vec<Finding>,
}

impl Review {
    /// The findings of one severity.
    pub fn of(&self, severity: Severity) -> impl Iterator<Item = &Finding> {
        self.findings
            .iter()
            .filter(move |f| f.severity() == severity)
    }

    /// The first refusal, if any.
    #[must_use]
    pub fn refusal(&self) -> Option<&Finding> {
        self.of(Severity::Refuse).next()
    }

    /// True when something is doubtful (and nothing refused).
    #[must_use]
    pub fn doubtful(&self) -> bool {
        self.of(Severity::Doubt).next().is_some()
    }
}

/// The checks of clicked points before anything is solved: too few, on one line, clicked twice
/// or outside the image refuse; points outside the field description (notes) or at other
/// coordinates than its landmark of the same name (doubts) are returned.
///
/// # Errors
/// The first refusal.
pub fn check_points(
    points: &PointsFile,
    field: &FieldDescription,
) -> Result<Vec<Finding>, Finding> {
    let ground = points.points.iter().filter(|p| p.height_cm == 0.0).count();
    if points.points.len() < MIN_POINTS || ground < 3 {
        return Err(Finding::TooFewPoints {
            count: points.points.len(),
        });
    }
    let mut names = HashSet::new();
    for p in &points.points {
        if !names.insert(p.name.as_str()) {
            return Err(Finding::DuplicateName {
                name: p.name.clone(),
            });
        }
        let [x, y] = p.image_px;
        let inside =
            (0.0..=points.width as f64).contains(&x) && (0.0..=points.height as f64).contains(&y);
        if !inside {
            return Err(Finding::OutsideImage {
                name: p.name.clone(),
                x,
                y,
                width: points.width,
                height: points.height,
            });
        }
    }
    let (along, across) = spread(points.points.iter().map(|p| p.field_cm));
    if across < COLLINEAR_FRACTION * along || across < 1.0 {
        return Err(Finding::Collinear {
            across_cm: across,
            along_cm: along,
        });
    }
    Ok(outside_field(points, field))
}

/// Standard deviations of points along and across their best line (the principal axes).
fn spread(points: impl Iterator<Item = [f64; 2]>) -> (f64, f64) {
    let p: Vec<[f64; 2]> = points.collect();
    let n = p.len().max(1) as f64;
    let (mx, my) = p
        .iter()
        .fold((0.0, 0.0), |(a, b), q| (a + q[0] / n, b + q[1] / n));
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for q in &p {
        let (dx, dy) = (q[0] - mx, q[1] - my);
        sxx += dx * dx / n;
        syy += dy * dy / n;
        sxy += dx * dy / n;
    }
    // Eigenvalues of the 2×2 covariance.
    let mean = (sxx + syy) / 2.0;
    let d = ((sxx - syy) / 2.0).hypot(sxy);
    ((mean + d).max(0.0).sqrt(), (mean - d).max(0.0).sqrt())
}

/// The findings on a solved calibration (see the module docs).
#[must_use]
pub fn review(cal: &Calibration) -> Review {
    let mut findings = review_camera(&cal.camera);
    for p in &cal.points {
        if !p.error_px.is_finite() {
            findings.push(Finding::NotSeen {
                name: p.name.clone(),
            });
        }
    }
    if cal.intrinsics.is_none() {
        findings.extend(coverage(cal));
    }
    if let Some(u) = &cal.uncertainty {
        findings.extend(uncertain(u, &cal.camera, cal.intrinsics.is_some()));
    }
    let median = cal.median_point_error_px();
    if median > MAX_MEDIAN_RESIDUAL_PX {
        findings.push(Finding::MedianResidual { px: median });
    }
    if let Some(worst) = cal
        .points
        .iter()
        .filter(|p| p.error_px.is_finite())
        .max_by(|a, b| a.error_px.total_cmp(&b.error_px))
        .filter(|p| p.error_px > MAX_RESIDUAL_PX)
    {
        findings.push(Finding::LargeResidual {
            name: worst.name.clone(),
            px: worst.error_px,
        });
    }
    findings.sort_by_key(|f| std::cmp::Reverse(f.severity()));
    Review { findings }
}

/// The clicks' bounding box against [`MIN_COVERAGE`] of the image.
fn coverage(cal: &Calibration) -> Option<Finding> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &cal.points {
        for k in 0..2 {
            lo[k] = lo[k].min(p.image_px[k]);
            hi[k] = hi[k].max(p.image_px[k]);
        }
    }
    let (w, h) = (cal.camera.width_px as f64, cal.camera.height_px as f64);
    let (fx, fy) = ((hi[0] - lo[0]) / w.max(1.0), (hi[1] - lo[1]) / h.max(1.0));
    let covered = fx >= MIN_COVERAGE && fy >= MIN_COVERAGE;
    (!covered && !cal.points.is_empty()).then_some(Finding::Clustered {
        x_pct: 100.0 * fx,
        y_pct: 100.0 * fy,
        x0: lo[0],
        x1: hi[0],
        y0: lo[1],
        y1: hi[1],
    })
}

/// The fitted parameters whose standard deviations exceed their limits.
fn uncertain(u: &Uncertainty, camera: &OverheadCamera, with_intrinsics: bool) -> Vec<Finding> {
    let finding = |what, sd: f64, limit, unit| {
        (sd.is_nan() || sd > limit).then_some(Finding::Uncertain {
            what,
            sd,
            limit,
            unit,
            with_intrinsics,
        })
    };
    let centre_sd = u.centre_px.map_or(0.0, |[x, y]| x.max(y));
    [
        finding(
            "camera position",
            u.position_sd_cm(),
            MAX_POSITION_SD_CM,
            "cm",
        ),
        finding(
            "focal length",
            u.focal_px.unwrap_or(0.0),
            MAX_FOCAL_SD_FRACTION * camera.focal_px,
            "px",
        ),
        finding(
            "principal point",
            centre_sd,
            MAX_CENTRE_SD_FRACTION * camera.width_px as f64,
            "px",
        ),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// The checks of the camera alone: where it is and what its lens is like.
#[must_use]
pub fn review_camera(c: &OverheadCamera) -> Vec<Finding> {
    let mut findings = Vec::new();
    let height_cm = c.pose.position_cm[2];
    if height_cm.is_nan() || height_cm <= 0.0 {
        findings.push(Finding::CameraBelowField { height_cm });
    } else if !(HEIGHT_RANGE_CM.0..=HEIGHT_RANGE_CM.1).contains(&height_cm) {
        findings.push(Finding::Height {
            height_m: height_cm / 100.0,
        });
    }
    let (w, h) = (c.width_px as f64, c.height_px as f64);
    let widths = c.focal_px / w.max(1.0);
    if !(FOCAL_WIDTHS.0..=FOCAL_WIDTHS.1).contains(&widths) {
        findings.push(Finding::Focal {
            focal_px: c.focal_px,
            widths,
        });
    }
    let (x, y) = (c.centre.x_px, c.centre.y_px);
    if (x - w / 2.0).abs() > w / 4.0 || (y - h / 2.0).abs() > h / 4.0 {
        findings.push(Finding::PrincipalPoint {
            x,
            y,
            width: c.width_px,
            height: c.height_px,
        });
    }
    if c.k1.is_nan() || c.k1.abs() > MAX_K1 {
        findings.push(Finding::Distortion { k1: c.k1 });
    }
    findings
}

/// Clicked points beyond the field description's landmarks and lines by more than
/// [`OUTSIDE_FIELD_MARGIN_CM`] (notes), and points whose coordinates differ from the field's
/// landmark of the same name (doubts).
fn outside_field(points: &PointsFile, field: &FieldDescription) -> Vec<Finding> {
    let corners = field
        .landmarks
        .iter()
        .map(|l| l.field_cm)
        .chain(field.lines.iter().flat_map(|l| [l.from_cm, l.to_cm]));
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for c in corners {
        for k in 0..2 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
        return Vec::new();
    }
    let margin = OUTSIDE_FIELD_MARGIN_CM;
    let mismatched = points.points.iter().filter_map(|p| {
        let l = field.landmark(&p.name)?;
        let d = (l.field_cm[0] - p.field_cm[0]).hypot(l.field_cm[1] - p.field_cm[1]);
        (d > LANDMARK_MISMATCH_CM).then(|| Finding::LandmarkMismatch {
            name: p.name.clone(),
            field: field.name.clone(),
            x: p.field_cm[0],
            y: p.field_cm[1],
            fx: l.field_cm[0],
            fy: l.field_cm[1],
        })
    });
    let mismatched: Vec<Finding> = mismatched.collect();
    points
        .points
        .iter()
        .filter(|p| {
            let f = p.field_cm;
            (0..2).any(|k| f[k] < lo[k] - margin || f[k] > hi[k] + margin)
        })
        .map(|p| Finding::OutsideField {
            name: p.name.clone(),
            field: field.name.clone(),
            x: p.field_cm[0],
            y: p.field_cm[1],
        })
        .chain(mismatched)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Point;
    use crate::overhead::calibration::PointResidual;
    use crate::overhead::points::CalibrationPoint;

    /// Every landmark of the 2005 field that `camera` sees, clicked exactly.
    fn clicks(camera: &OverheadCamera, field: &FieldDescription) -> PointsFile {
        let mut file = PointsFile::new(camera.width_px, camera.height_px);
        for l in &field.landmarks {
            if let Some(q) =
                camera.image_from_field(&Point::new(l.field_cm[0], l.field_cm[1], l.height_cm))
                && (0.0..640.0).contains(&q.x_px)
                && (0.0..480.0).contains(&q.y_px)
            {
                file.points.push(CalibrationPoint {
                    name: l.name.clone(),
                    field_cm: l.field_cm,
                    height_cm: l.height_cm,
                    image_px: [q.x_px, q.y_px],
                });
            }
        }
        file
    }

    fn kinds(findings: &[Finding]) -> Vec<String> {
        findings
            .iter()
            .map(|f| {
                format!("{f:?}")
                    .split([' ', '{'])
                    .next()
                    .unwrap_or("")
                    .to_owned()
            })
            .collect()
    }

    #[test]
    fn clicks_twice_outside_the_image_or_in_other_units_are_caught_before_solving() {
        let field = FieldDescription::four_legged_2005();
        let camera = OverheadCamera::above_field_2005();
        let good = clicks(&camera, &field);
        assert_eq!(check_points(&good, &field), Ok(Vec::new()));
        let mut twice = good.clone();
        twice.points.push(twice.points[2].clone());
        assert!(matches!(
            check_points(&twice, &field),
            Err(Finding::DuplicateName { .. })
        ));
        // Clicks in a full-size frame saved as a half-size view's points.
        let mut half = good.clone();
        (half.width, half.height) = (320, 240);
        let err = check_points(&half, &field).expect_err("outside");
        assert!(matches!(err, Finding::OutsideImage { .. }), "{err:?}");
        assert!(
            err.to_string().contains("outside the 320x240 image"),
            "{err}"
        );
        // The field's coordinates in millimetres: every point far outside it.
        let mut mm = good.clone();
        for p in &mut mm.points {
            p.field_cm = p.field_cm.map(|v| v * 10.0);
        }
        let found = check_points(&mm, &field).expect("notes and doubts only");
        assert!(!found.is_empty());
        // Beyond the field: notes; a landmark at ten times its place: a doubt naming it.
        assert!(found.iter().all(|n| match n {
            Finding::OutsideField { .. } => n.severity() == Severity::Note,
            Finding::LandmarkMismatch { .. } => n.severity() == Severity::Doubt,
            _ => false,
        }));
        assert!(
            found
                .iter()
                .any(|f| f.to_string().contains("\"yellow left corner\"")
                    && f.to_string().contains("another field")),
            "{found:?}"
        );
    }

    #[test]
    fn the_camera_checks_catch_each_bad_value() {
        let good = OverheadCamera::above_field_2005();
        assert!(
            review_camera(&good).is_empty(),
            "{:?}",
            review_camera(&good)
        );
        let with = |f: fn(&mut OverheadCamera)| {
            let mut c = good;
            f(&mut c);
            kinds(&review_camera(&c))
        };
        assert_eq!(
            with(|c| c.pose.position_cm[2] = -120.0),
            ["CameraBelowField"]
        );
        assert_eq!(with(|c| c.pose.position_cm[2] = 4000.0), ["Height"]);
        assert_eq!(with(|c| c.pose.position_cm[2] = 30.0), ["Height"]);
        assert_eq!(with(|c| c.k1 = -3.2), ["Distortion"]);
        assert_eq!(with(|c| c.k1 = f64::NAN), ["Distortion"]);
        assert_eq!(with(|c| c.focal_px = 100.0), ["Focal"]);
        assert_eq!(with(|c| c.focal_px = 2500.0), ["Focal"]);
        assert_eq!(with(|c| c.centre.x_px = 500.0), ["PrincipalPoint"]);
        assert_eq!(with(|c| c.centre.y_px = 50.0), ["PrincipalPoint"]);
    }

    #[test]
    fn parameters_the_clicks_leave_uncertain_are_doubted_each_by_name() {
        let camera = OverheadCamera::above_field_2005();
        let sure = Uncertainty {
            residual_sd_px: 0.8,
            position_cm: [2.0, 3.0, 13.0],
            rotation_deg: [0.2, 0.2, 0.1],
            focal_px: Some(0.035 * camera.focal_px),
            centre_px: Some([10.0, 12.0]),
            k1: Some(0.01),
            k2: Some(0.01),
        };
        assert!(uncertain(&sure, &camera, false).is_empty());
        // The fits: cameras 42 cm apart, focal 492 vs 408 px, principal points 100 px.
        let unsure = Uncertainty {
            position_cm: [30.0, 12.0, 20.0],
            focal_px: Some(45.0),
            centre_px: Some([60.0, 20.0]),
            ..sure
        };
        let found = uncertain(&unsure, &camera, false);
        assert_eq!(kinds(&found), ["Uncertain", "Uncertain", "Uncertain"]);
        let text: Vec<String> = found.iter().map(ToString::to_string).collect();
        assert!(
            text[0].contains("camera position: standard deviation 30.00 cm (limit 25.00 cm)"),
            "{text:?}"
        );
        assert!(
            text[1].contains("focal length") && text[2].contains("principal point"),
            "{text:?}"
        );
        assert!(text.iter().all(|t| t.contains("--intrinsics")), "{text:?}");
        assert!(found.iter().all(|f| f.severity() == Severity::Doubt));
        // With intrinsics there is only the pose; the hint is not repeated.
        let pose_only = Uncertainty {
            focal_px: None,
            centre_px: None,
            k1: None,
            k2: None,
            ..unsure
        };
        let found = uncertain(&pose_only, &camera, true);
        assert_eq!(kinds(&found), ["Uncertain"]);
        assert!(!found[0].to_string().contains("--intrinsics"), "{found:?}");
        // A standard deviation that is not a number is not a determined parameter.
        let nan = Uncertainty {
            position_cm: [f64::NAN, 1.0, 1.0],
            ..sure
        };
        assert_eq!(kinds(&uncertain(&nan, &camera, false)), ["Uncertain"]);
    }

    #[test]
    fn residuals_too_large_or_unseen_points_are_found() {
        let cal = |errors: &[f64]| Calibration {
            camera: OverheadCamera::above_field_2005(),
            field: String::new(),
            points: errors
                .iter()
                .enumerate()
                .map(|(i, &e)| PointResidual {
                    name: format!("p{i}"),
                    image_px: [0.0; 2],
                    projected_px: [0.0; 2],
                    error_px: e,
                })
                .collect(),
            line_samples: 0,
            line_rms_px: None,
            uncertainty: None,
            // With intrinsics: the clicks' coverage is not asked for (tested below).
            intrinsics: Some("a checkerboard".into()),
        };
        assert!(review(&cal(&[0.5, 1.0, 1.5, 7.9])).findings.is_empty());
        let r = review(&cal(&[2.5, 2.6, 2.7]));
        assert_eq!(kinds(&r.findings), ["MedianResidual"]);
        assert!(r.doubtful() && r.refusal().is_none());
        let r = review(&cal(&[0.5, 0.5, 9.0]));
        assert_eq!(kinds(&r.findings), ["LargeResidual"]);
        assert!(
            r.findings[0].to_string().contains("\"p2\""),
            "{}",
            r.findings[0]
        );
        // Without intrinsics, clicks on one spot of the image are doubtful, the coverage named.
        let mut clustered = cal(&[0.5, 0.5, 0.5]);
        clustered.intrinsics = None;
        clustered.points[1].image_px = [100.0, 90.0];
        let r = review(&clustered);
        assert_eq!(kinds(&r.findings), ["Clustered"]);
        assert!(r.findings[0].to_string().contains("at least 50%"), "{r:?}");
        let r = review(&cal(&[0.5, f64::NAN, 0.5]));
        assert!(
            matches!(r.refusal(), Some(Finding::NotSeen { .. })),
            "{r:?}"
        );
    }
}
