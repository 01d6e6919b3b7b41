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
//! ([`Severity::Doubt`]: the command line writes such a calibration only with `--accept`);
//! points outside the field description (wrong units?) are noted ([`Severity::Note`]).

use std::collections::HashSet;

use super::calibration::Calibration;
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
        "point {name:?} at ({x:.0}, {y:.0}) cm lies outside the field description (other units?)"
    )]
    OutsideField {
        /// The point's name.
        name: String,
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
            | Self::CameraBelowField { .. } => Severity::Refuse,
            Self::MedianResidual { .. }
            | Self::LargeResidual { .. }
            | Self::Focal { .. }
            | Self::PrincipalPoint { .. }
            | Self::Distortion { .. }
            | Self::Height { .. } => Severity::Doubt,
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
/// or outside the image refuse; points outside the field description are notes (returned).
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

/// Clicked points beyond the field description's landmarks and lines (with a margin of a
/// fifth of its size and half a metre): notes.
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
    let margin = [0, 1].map(|k| 0.2 * (hi[k] - lo[k]) + 50.0);
    points
        .points
        .iter()
        .filter(|p| {
            let f = p.field_cm;
            (0..2).any(|k| f[k] < lo[k] - margin[k] || f[k] > hi[k] + margin[k])
        })
        .map(|p| Finding::OutsideField {
            name: p.name.clone(),
            x: p.field_cm[0],
            y: p.field_cm[1],
        })
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
        let notes = check_points(&mm, &field).expect("notes only");
        assert!(!notes.is_empty());
        assert!(
            notes.iter().all(|n| n.severity() == Severity::Note),
            "{notes:?}"
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
        let r = review(&cal(&[0.5, f64::NAN, 0.5]));
        assert!(
            matches!(r.refusal(), Some(Finding::NotSeen { .. })),
            "{r:?}"
        );
    }
}
