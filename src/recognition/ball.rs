//! The ball: orange blobs (joined with touching soft colours that may be orange) become
//! candidates, largest first; each is scored by the confidence tests; the first with a positive
//! total is the ball. Its outline is scanned in one of six patterns chosen by which sides are cut
//! off or hidden, the rolling shutter's shear removed, and a circle fitted; distance, bearing and
//! elevation come from the circle through the camera model.

use serde::{Deserialize, Serialize};

use super::confidence::{Confidence, TestWeight};
use super::context::{Relative, ViewContext};
use super::draw::{CircleRole, Primitive};
use super::fit::{CircleFit, Point, ShearedCircleFit, fit_circle_trimmed, fit_sheared_circle};
use super::scan::{
    CutOff, EdgeScanPattern, MixedEdge, ScanArea, edge_points_with_mixed, scan_rotated_rect,
};
use crate::blobs::{Blob, BlobSet};
use crate::classify::ClassifiedImage;
use crate::lut::ColourClass;

/// Settings of ball recognition. Amounts are confidence points; the defaults follow the
/// original's rules and were checked on the renderer's scenarios.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BallParams {
    /// Ball diameter, centimetres (2005 Four-Legged League: 8.5).
    pub diameter_cm: f64,
    /// Candidates with fewer pixels are ignored.
    pub min_pixels: u32,
    /// At most this many candidates are scored per frame.
    pub max_candidates: usize,
    /// Soft-colour blobs join an orange blob when their boxes come this close, pixels.
    pub soft_join_px: u32,
    /// Accepted pixels / box area (a full disc fills π/4 ≈ 0.785 of its box).
    pub pixel_ratio: [f64; 2],
    /// Weight of the pixel-ratio test.
    pub pixel_ratio_weight: TestWeight,
    /// Accepted height of the ball's centre above the ground, centimetres (true: 4.25).
    pub height_cm: [f64; 2],
    /// Weight of the height test.
    pub height_weight: TestWeight,
    /// The height range widens by distance × tan(this) on both sides, radians: the camera
    /// pose's angular error turns into a height error growing with distance. 0 by default: the
    /// simulator's pose is exact, and there 2° of slack lets the orange clutter hovering just
    /// above the carpet pass as balls (23 of 90 frames). A real robot's own estimate is off by
    /// about a degree — the B-Human log's camera matrices against the hand-labelled balls
    /// beyond 1 m: median 0.8°, p90 3.2° (after a kick and while the robot is lifted) — so
    /// `params/spl2009.json` sets 2°.
    pub height_pose_slack_rad: f64,
    /// Green fraction below the ball that earns the colour-below bonus.
    pub green_below: [f64; 2],
    /// Bonus for green below (never a penalty: a ball on a line or against a robot is still a ball).
    pub green_below_bonus: f64,
    /// Accepted box width / height for an uncut candidate.
    pub aspect: [f64; 2],
    /// Weight of the roundness test.
    pub aspect_weight: TestWeight,
    /// Share of a candidate's pixels that must be basic orange (soft-only blobs are doubtful).
    pub orange_fraction: [f64; 2],
    /// Weight of the orange-fraction test.
    pub orange_fraction_weight: TestWeight,
    /// Accepted share of unclassified pixels on the ring just outside the candidate's box: a
    /// ball lies against field, lines, robots or goals, all classified; orange specks inside an
    /// unclassified region (a robot's shaded red shoulder on the B-Human recording) are not balls.
    pub unclassified_around: [f64; 2],
    /// Weight of the unclassified-surroundings test.
    pub unclassified_around_weight: TestWeight,
    /// Accepted share of ball colours among the image pixels inside the circle (where the image
    /// shows it): a ball fills its outline, even with a side hidden (an eligible ball is at
    /// least 60% in view) or holes in its classification; a thin orange arc — the red rim of the
    /// robot's own toe on the B-Human recording — or a speck given a large circle does not.
    pub circle_fill: [f64; 2],
    /// Weight of the circle-fill test.
    pub circle_fill_weight: TestWeight,
    /// Edge scans start this many pixels outside the box.
    pub edge_margin_px: u32,
    /// An edge scan stops at the first run of this many ball-coloured pixels, so single noisy
    /// pixels outside the ball are not taken for its outline.
    pub edge_run_px: u32,
    /// Where an unclassified pixel right outside the ball's run counts as the ball's rim (see
    /// [`MixedEdge`]): UYVY pixel pairs share their chroma, so a rim pixel paired with a carpet
    /// pixel is classified as neither; without this the outline of a far ball is half a pixel
    /// small and its distance 10–20% long.
    pub mixed_edge: MixedEdge,
    /// A side touching the image border counts as cut off only when at least this share of the
    /// box's pixels along that side are ball-coloured (a cut ball has a long chord on the
    /// border; a stray pixel reaching it does not make the ball cut).
    pub border_cut_min_share: f64,
    /// A side bordered by robot colours counts as hidden only when at least this share of the
    /// box's pixels along that side are ball-coloured: an occluder cuts a ball along a long
    /// chord, while a round side lying against a white line or stand (the B-Human recording's
    /// close balls) touches its box over about 2√r pixels only, a share of about 1/√r. 0 takes
    /// every bordered side as hidden (as before 2026-12).
    pub hidden_min_chord_share: f64,
    /// ... for balls whose box is at least twice this across that side, pixels. Below it a round
    /// side's share (1/√r ≥ 0.29) cannot be told from a slightly hidden one's, and holes in a
    /// small ball's classified rim shorten the chord, so every bordered side counts as hidden.
    pub hidden_chord_min_radius_px: f64,
    /// Outline points farther than this many residual SDs from the first circle are dropped
    /// and the circle refitted (see [`super::fit::fit_circle_trimmed`]).
    pub fit_trim_sd: f64,
    /// ... but never closer than this, pixels.
    pub fit_trim_min_px: f64,
    /// ... and only when at most this share of the points would go.
    pub fit_trim_max_share: f64,
    /// A fitted circle is rejected when its diameter is below this fraction of the blob's
    /// uncut extent.
    pub min_fit_diameter_ratio: f64,
    /// A fitted circle is rejected when its residual spread exceeds this fraction of its radius
    /// plus 0.75 px.
    pub max_fit_residual_ratio: f64,
    /// Largest visible extent along a cut-off axis relative to the uncut extent (a ball cut at
    /// the top cannot be taller than wide).
    pub max_cut_extent_ratio: f64,
    /// Weight of the cut-extent test.
    pub cut_extent_weight: TestWeight,
    /// Pixels added to the uncut extent in the cut-extent ratio: both extents of a small ball
    /// are whole pixels and either may be one too many.
    pub extent_slack_px: f64,
    /// Bonus when the outline fits a circle with at least [`Self::circle_fit_min_points`]
    /// points (a well-fitted outline says "round" better than the fill of the box, which holes
    /// in a real ball's classification lower).
    pub circle_fit_bonus: f64,
    /// Outline points needed for the circle-fit bonus.
    pub circle_fit_min_points: usize,
    /// Smallest fitted radius that earns the circle-fit bonus, pixels (a circle through the
    /// outline of a speck proves little).
    pub circle_fit_min_radius_px: f64,
    /// A fitted circle is rejected when its diameter exceeds this multiple of the blob's
    /// uncut extent (an uncut ball's circle is as wide as its blob).
    pub max_fit_diameter_ratio: f64,
    /// Penalty when the outline was scanned but does not fit a circle (residuals too large, or
    /// the points lie on a line: a straight edge is not a ball's).
    pub bad_circle_penalty: f64,
    /// Combine the size-based distance with where the ray through the centre meets the plane of
    /// ball centres (through the camera pose), weighting each by its expected error. Beyond the
    /// original: far balls are a few pixels wide, and half a pixel of radius is 10% of distance.
    pub ground_plane_fusion: bool,
    /// Added to every measured radius, pixels: the classified outline of a real ball is a little
    /// larger than its geometric disc (edge pixels mixing ball and carpet classify as ball);
    /// `eotn eval` measures it.
    pub radius_bias_px: f64,
    /// Expected error of the fitted radius, pixels.
    pub radius_sigma_px: f64,
    /// Expected error of the radius of a ball cut off by the image edge or hidden on a side, or
    /// measured from its box (no circle fit), pixels: a partial outline, often in the darkened
    /// image corners where classification loses rim pixels. The fusion then leans on the
    /// ground plane.
    pub radius_sigma_cut_px: f64,
    /// Expected error of the camera's pitch from the joints and body model, radians.
    pub pose_sigma_rad: f64,
    /// Remove the horizontal rolling-shutter shear (pan velocity) before fitting.
    pub skew_correction: bool,
    /// Remove the skew through the body model (the camera pose at each row's read-out time,
    /// [`ViewContext::unskew_at`]) when the pose and the head's motion are known; otherwise, or
    /// when false, the linear shear Δx = d·tan θ − d·tan θ_prev per frame.
    pub pose_skew_model: bool,
    /// Remove the vertical counterpart (tilt velocity) too. On by default: on the walk-and-pan
    /// scenario (the head tilts while tracking) it lowers the median distance error from 5.5%
    /// to 4.8% and changes nothing where the tilt is still.
    pub vertical_skew_correction: bool,
    /// Fit the outline as a circle that moved while its rows were read out (a constrained
    /// ellipse: circle plus one shear per axis, [`super::fit::fit_sheared_circle`]) after the
    /// camera's skew is removed, giving the ball's own image velocity. Beyond the original (its
    /// "future work"); off by default (see README for the measured effect).
    pub ellipse_fit: bool,
    /// Let the ellipse fit find a vertical shear too. Off by default: on the rolling-ball
    /// scenario the vertical stretch it must measure (tenths of a pixel) is swamped by the
    /// classified outline's unevenness, and its errors turn into large ground-velocity errors;
    /// with it off the vertical image velocity is reported as 0.
    pub ellipse_vertical_shear: bool,
    /// Outline points the ellipse fit needs.
    pub ellipse_min_points: usize,
    /// The ellipse fit is used only when both shears' standard errors are below this, pixels
    /// per line (a short arc of a cut ball leaves the shear undetermined).
    pub ellipse_max_shear_sd: f64,
}

impl Default for BallParams {
    fn default() -> Self {
        Self {
            diameter_cm: 8.5,
            min_pixels: 5,
            max_candidates: 6,
            soft_join_px: 2,
            pixel_ratio: [0.4, 1.0],
            pixel_ratio_weight: TestWeight::new(1.0, 2.0),
            height_cm: [-6.0, 16.0],
            height_weight: TestWeight::new(1.0, 4.0),
            height_pose_slack_rad: 0.0,
            green_below: [0.25, 1.0],
            green_below_bonus: 1.0,
            aspect: [0.6, 1.67],
            aspect_weight: TestWeight::new(0.5, 1.5),
            orange_fraction: [0.3, 1.0],
            orange_fraction_weight: TestWeight::new(0.5, 2.0),
            unclassified_around: [0.0, 0.6],
            unclassified_around_weight: TestWeight::new(0.0, 2.0),
            circle_fill: [0.2, 1.0],
            circle_fill_weight: TestWeight::new(0.0, 3.0),
            edge_margin_px: 3,
            edge_run_px: 2,
            mixed_edge: MixedEdge::ChromaPairs,
            border_cut_min_share: 0.25,
            hidden_min_chord_share: 0.35,
            hidden_chord_min_radius_px: 20.0,
            fit_trim_sd: 2.5,
            fit_trim_min_px: 1.0,
            fit_trim_max_share: 0.2,
            min_fit_diameter_ratio: 0.75,
            max_fit_residual_ratio: 0.15,
            max_cut_extent_ratio: 1.25,
            cut_extent_weight: TestWeight::new(0.0, 3.0),
            extent_slack_px: 1.0,
            bad_circle_penalty: 1.5,
            circle_fit_bonus: 1.0,
            circle_fit_min_points: 12,
            circle_fit_min_radius_px: 8.0,
            max_fit_diameter_ratio: 1.5,
            ground_plane_fusion: true,
            radius_bias_px: 0.0,
            radius_sigma_px: 0.5,
            radius_sigma_cut_px: 1.0,
            pose_sigma_rad: 0.01,
            skew_correction: true,
            pose_skew_model: true,
            vertical_skew_correction: true,
            ellipse_fit: false,
            ellipse_vertical_shear: false,
            ellipse_min_points: 12,
            ellipse_max_shear_sd: 0.03,
        }
    }
}

/// Inverse-variance combination of the size-based distance with the ground-plane one. The
/// plane distance D = h / sin φ (h: camera height above ball centres, φ: depression of the ray)
/// has an error of about D² / h · σ_φ; the size distance one of D · σ_r / r. When the two
/// disagree by more than a factor of two (a ball in the air or held), the size distance stands.
fn fuse_with_ground_plane(
    ctx: &ViewContext,
    center: Point,
    radius: f64,
    radius_sigma_px: f64,
    size_distance: f64,
    params: &BallParams,
) -> f64 {
    let Some(pose) = ctx.pose else {
        return size_distance;
    };
    let ip = crate::geometry::ImagePoint::new(center.0, center.1);
    let Some(hit) = pose.point_on_plane(ip, params.diameter_cm / 2.0) else {
        return size_distance;
    };
    let plane = hit.distance_to(&pose.position());
    if !(plane.is_finite() && plane > 0.5 * size_distance && plane < 2.0 * size_distance) {
        return size_distance;
    }
    let h = (pose.position().z() - params.diameter_cm / 2.0)
        .abs()
        .max(1.0);
    let sigma_phi = params.pose_sigma_rad + params.radius_sigma_px / ctx.camera.focal_px;
    let var_plane = (plane * plane / h * sigma_phi).powi(2);
    let var_size = (size_distance * radius_sigma_px / radius.max(0.5)).powi(2);
    (plane / var_plane + size_distance / var_size) / (1.0 / var_plane + 1.0 / var_size)
}

/// Distance (cm) to the centre of a ball of `diameter_cm` whose outline in the image is the
/// circle (`center`, `radius` px), from the angle the ball subtends. A sphere off the optical
/// axis projects to an ellipse stretched away from the axis (by 1/cos θ across and 1/cos² θ
/// along the radial direction, θ the angle off the axis): at the side of the ERS-7's image a
/// ball looks 15–25% wider than at the centre, and the original's d × 8.5 / diameter reads
/// that much too close. The half-angle between the rays through opposite ends of a diameter is
/// the ball's angular radius α for the ellipse's axes; the mean over the radial and the
/// tangential diameter of the fitted circle undoes the stretch, and distance = R / sin α.
/// Falls back to d × diameter / (2 × radius) when the rays are degenerate.
#[must_use]
pub fn distance_from_circle(
    camera: &crate::geometry::PinholeCamera,
    center: Point,
    radius: f64,
    diameter_cm: f64,
) -> f64 {
    use crate::geometry::ImagePoint;
    let radius = radius.max(0.25);
    let fallback = camera.focal_px * diameter_cm / (2.0 * radius);
    let (dx, dy) = (center.0 - camera.centre.x_px, center.1 - camera.centre.y_px);
    let off = dx.hypot(dy);
    let u = if off > 1e-6 {
        (dx / off, dy / off)
    } else {
        (1.0, 0.0)
    };
    let half_angle = |dir: (f64, f64)| {
        let a = camera.unit_ray(ImagePoint::new(
            center.0 + radius * dir.0,
            center.1 + radius * dir.1,
        ));
        let b = camera.unit_ray(ImagePoint::new(
            center.0 - radius * dir.0,
            center.1 - radius * dir.1,
        ));
        a.coords.dot(&b.coords).clamp(-1.0, 1.0).acos() / 2.0
    };
    let alpha = (half_angle(u) + half_angle((-u.1, u.0))) / 2.0;
    let d = diameter_cm / 2.0 / alpha.sin();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        fallback
    }
}

/// The ball's angular radius (radians) from its outline points: the points are turned into
/// the view of a camera looking straight at `center` (gnomonic coordinates about the ray
/// through it, scaled by d so that they stay in pixels), where a sphere's outline is an exact
/// circle wherever it is in the image, and a circle is fitted there. Unlike
/// [`distance_from_circle`] this also holds for a short arc (a ball cut by the image edge sees
/// only the side facing the image centre, whose curvature is not the fitted circle's mean).
/// `None` when the points do not fit a circle.
fn angular_radius(
    camera: &crate::geometry::PinholeCamera,
    points: &[Point],
    center: Point,
    params: &BallParams,
) -> Option<f64> {
    use crate::geometry::ImagePoint;
    let ray = |p: Point| camera.unit_ray(ImagePoint::new(p.0, p.1)).coords;
    let e1 = ray(center);
    let side = ray((center.0 + 1.0, center.1));
    let e2 = (side - e1 * side.dot(&e1)).try_normalize(1e-12)?;
    let e3 = e1.cross(&e2);
    let f = camera.focal_px;
    let turned: Vec<Point> = points
        .iter()
        .filter_map(|&p| {
            let r = ray(p);
            let along = r.dot(&e1);
            (along > 1e-6).then(|| (f * r.dot(&e2) / along, f * r.dot(&e3) / along))
        })
        .collect();
    if turned.len() < 5 {
        return None;
    }
    let fit = fit_circle_trimmed(
        &turned,
        params.fit_trim_sd,
        params.fit_trim_min_px,
        params.fit_trim_max_share,
    )?;
    let alpha = (fit.radius / f).atan();
    (alpha.is_finite() && alpha > 0.0).then_some(alpha)
}

/// The recognised ball.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ball {
    /// Index of the accepted candidate in [`BallResult::candidates`].
    pub candidate: usize,
    /// Centre x, image pixels, at the reference row's read-out time (skew removed): where the
    /// sensor readings place the ball.
    pub center_x: f64,
    /// Centre y, image pixels, at the reference read-out time.
    pub center_y: f64,
    /// Centre where the ball appears in the image (each row at its own read-out time), pixels:
    /// equal to the centre without skew; several pixels away on a fast pan.
    #[serde(default)]
    pub observed_center: Point,
    /// Radius, pixels.
    pub radius_px: f64,
    /// Camera-relative distance, bearing, elevation.
    pub camera: Relative,
    /// Body-relative distance, bearing, elevation (when the joints were known).
    pub body: Option<Relative>,
    /// Total confidence.
    pub confidence: f64,
    /// Sides cut off by the image edge or hidden.
    pub cut_off: CutOff,
    /// True when centre and radius come from the circle fit, false when from the blob box.
    pub from_circle_fit: bool,
    /// The ball's own image velocity from the ellipse fit (camera skew removed), pixels per
    /// second (x right, y down); `None` unless [`BallParams::ellipse_fit`] is on and the fit
    /// was determined.
    #[serde(default)]
    pub image_velocity_px_s: Option<[f64; 2]>,
    /// That velocity on the ground (plane of ball centres) in the robot's frame (x ahead, y
    /// left), centimetres per second, through the camera pose; `None` without the pose.
    #[serde(default)]
    pub ground_velocity_cm_s: Option<[f64; 2]>,
}

/// One scored candidate, accepted or not, with everything that decided it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BallCandidate {
    /// `[minx, miny, maxx, maxy]`, inclusive pixels (joined blobs).
    pub bounds: [u32; 4],
    /// Pixels of ball colours in the joined blobs.
    pub pixels: u32,
    /// Pixels of basic orange.
    pub orange_pixels: u32,
    /// The confidence breakdown.
    pub confidence: Confidence,
    /// Sides cut off or hidden.
    pub cut_off: CutOff,
    /// The edge-scan pattern used.
    pub pattern: EdgeScanPattern,
    /// Outline points after skew removal, pixels.
    pub edge_points: Vec<Point>,
    /// The outline points where the scans found them in the image (before skew removal),
    /// pixels: what the overlay draws.
    #[serde(default)]
    pub scanned_points: Vec<Point>,
    /// The circle fit, if one was found.
    pub fit: Option<CircleFit>,
    /// The moving-circle (constrained ellipse) fit, when [`BallParams::ellipse_fit`] is on and
    /// it was tried.
    #[serde(default)]
    pub ellipse: Option<ShearedCircleFit>,
    /// Why the circle fit was not used, if it was not.
    pub fit_rejected: Option<String>,
    /// The colour-below scan area.
    pub below: Option<ScanArea>,
    /// Estimated centre, pixels, at the reference read-out time (skew removed).
    pub center: Point,
    /// The centre where the ball appears in the image, pixels (see [`Ball::observed_center`]).
    #[serde(default)]
    pub observed_center: Point,
    /// Estimated radius, pixels.
    pub radius_px: f64,
    /// Camera-relative estimate.
    pub camera: Relative,
    /// Whether this candidate became the ball.
    pub accepted: bool,
}

/// Ball recognition's output for one frame.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct BallResult {
    /// The ball, if a candidate was accepted.
    pub ball: Option<Ball>,
    /// Every candidate scored, in the order tried.
    pub candidates: Vec<BallCandidate>,
}

/// Whether a class code is a ball colour: orange or a soft colour that may be orange.
#[must_use]
pub fn is_ball_colour(code: u8) -> bool {
    ColourClass::from_code(code)
        .is_some_and(|c| c == ColourClass::Orange || c.may_be_class(ColourClass::Orange))
}

fn is_robot_colour(code: u8) -> bool {
    matches!(
        ColourClass::from_code(code),
        Some(ColourClass::White | ColourClass::Red | ColourClass::DarkBlue | ColourClass::Black)
    )
}

fn near(a: &Blob, b: &Blob, gap: u32) -> bool {
    a.minx <= b.maxx + gap + 1
        && b.minx <= a.maxx + gap + 1
        && a.miny <= b.maxy + gap + 1
        && b.miny <= a.maxy + gap + 1
}

/// Candidate groups: each orange blob joined with the soft-orange blobs near it, then soft blobs
/// left over on their own; largest first.
fn candidate_groups(blobs: &BlobSet, params: &BallParams) -> Vec<(Blob, u32)> {
    let soft: Vec<&Blob> = blobs
        .active()
        .filter(|b| b.colour != ColourClass::Orange.code() && is_ball_colour(b.colour))
        .collect();
    let mut used = vec![false; soft.len()];
    let mut groups: Vec<(Blob, u32)> = Vec::new();
    for orange in blobs.of_class(ColourClass::Orange) {
        let mut joined = *orange;
        for (i, s) in soft.iter().enumerate() {
            if !used[i] && near(&joined, s, params.soft_join_px) {
                joined = joined.merged_with(s);
                used[i] = true;
            }
        }
        groups.push((joined, orange.pixels));
    }
    for (i, s) in soft.iter().enumerate() {
        if !used[i] {
            groups.push((**s, 0));
        }
    }
    groups.retain(|(b, _)| b.pixels >= params.min_pixels);
    groups.sort_by_key(|g| std::cmp::Reverse(g.0.pixels));
    groups.truncate(params.max_candidates);
    groups
}

/// Which sides of `b` are cut by the image border or hidden: cut when at least `border_share` of
/// the box's own line along the border is ball-coloured; hidden when a robot's white, red, dark
/// blue or black borders most of that side *and* at least `hidden_share` of the box's line
/// there is ball-coloured (for a box at least `2 × hidden_min_radius_px` long there; shorter
/// sides need one ball pixel). A ball cut by an edge or an occluder meets it along a long straight chord; a round side
/// only touches its box over a few pixels, whatever it lies against (a ball on a white line or
/// its white stand on the B-Human recording is round there, not hidden).
fn cut_off(
    img: &ClassifiedImage,
    b: &Blob,
    border_share: f64,
    hidden_share: f64,
    hidden_min_radius_px: f64,
) -> CutOff {
    let (w, h) = (img.width() as u32, img.height() as u32);
    let chord = |samples: &[(i64, i64)], chord_share: f64| {
        let (mut n, mut ball) = (0u32, 0u32);
        for &(x, y) in samples {
            if let Some(c) = img.get_signed(x, y) {
                n += 1;
                ball += u32::from(is_ball_colour(c));
            }
        }
        ball >= 1 && f64::from(ball) >= chord_share * f64::from(n)
    };
    let bordered = |samples: &[(i64, i64)]| {
        let (mut n, mut robot) = (0u32, 0u32);
        for &(x, y) in samples {
            if let Some(c) = img.get_signed(x, y) {
                n += 1;
                robot += u32::from(is_robot_colour(c));
            }
        }
        n >= 3 && robot * 2 > n
    };
    let (minx, miny, maxx, maxy) = (
        i64::from(b.minx),
        i64::from(b.miny),
        i64::from(b.maxx),
        i64::from(b.maxy),
    );
    let rows = |x: i64| (miny..=maxy).map(|y| (x, y)).collect::<Vec<_>>();
    let columns = |y: i64| (minx..=maxx).map(|x| (x, y)).collect::<Vec<_>>();
    // `own`: the box's own first or last line; `outside`: the line just beyond it (none at the
    // image border).
    let side = |at_border: bool, own: Vec<(i64, i64)>, outside: Vec<(i64, i64)>| {
        if at_border {
            chord(&own, border_share)
        } else {
            let small = (own.len() as f64) < 2.0 * hidden_min_radius_px;
            bordered(&outside) && chord(&own, if small { 0.0 } else { hidden_share })
        }
    };
    CutOff {
        left: side(b.minx == 0, rows(minx), rows(minx - 1)),
        right: side(b.maxx + 1 >= w, rows(maxx), rows(maxx + 1)),
        top: side(b.miny == 0, columns(miny), columns(miny - 1)),
        bottom: side(b.maxy + 1 >= h, columns(maxy), columns(maxy + 1)),
    }
}

/// Centre and radius from the box alone: the uncut extent is the diameter; a cut side puts the
/// centre a radius from the visible opposite side.
fn box_estimate(b: &Blob, cut: CutOff) -> (Point, f64) {
    let w = f64::from(b.maxx - b.minx + 1);
    let h = f64::from(b.maxy - b.miny + 1);
    let horizontal_cut = cut.left || cut.right;
    let vertical_cut = cut.top || cut.bottom;
    let r = match (horizontal_cut, vertical_cut) {
        (false, false) => (w + h) / 4.0,
        (true, false) => h / 2.0,
        (false, true) => w / 2.0,
        (true, true) => w.max(h) / 2.0,
    };
    let cx = match (cut.left, cut.right) {
        (true, false) => f64::from(b.maxx + 1) - r,
        (false, true) => f64::from(b.minx) + r,
        _ => f64::from(b.minx) + w / 2.0,
    };
    let cy = match (cut.top, cut.bottom) {
        (true, false) => f64::from(b.maxy + 1) - r,
        (false, true) => f64::from(b.miny) + r,
        _ => f64::from(b.miny) + h / 2.0,
    };
    ((cx, cy), r)
}

/// Whether a fitted circle can be the blob's ball: the box's centre lies inside it, and it
/// reaches every side the blob is cut at (a short arc of a few outline points can bend the fit
/// the wrong way, putting the circle beside the blob). `shift` moves the box as the skew removal
/// moved its centre (the circle is fitted to unskewed points).
fn circle_holds_blob(f: &CircleFit, b: &Blob, cut: CutOff, shift: Point) -> bool {
    let (minx, miny) = (f64::from(b.minx) + shift.0, f64::from(b.miny) + shift.1);
    let (maxx, maxy) = (
        f64::from(b.maxx + 1) + shift.0,
        f64::from(b.maxy + 1) + shift.1,
    );
    let (bx, by) = ((minx + maxx) / 2.0, (miny + maxy) / 2.0);
    let inside = (bx - f.center_x).hypot(by - f.center_y) <= f.radius;
    let reach = 1.0;
    inside
        && (!cut.left || f.center_x - f.radius <= minx + reach)
        && (!cut.right || f.center_x + f.radius >= maxx - reach)
        && (!cut.top || f.center_y - f.radius <= miny + reach)
        && (!cut.bottom || f.center_y + f.radius >= maxy - reach)
}

/// Share of unclassified pixels on the ring one pixel outside the box (pixels inside the image
/// only); `None` when the ring lies wholly outside.
fn unclassified_around(img: &ClassifiedImage, b: &Blob) -> Option<f64> {
    let (minx, miny) = (i64::from(b.minx) - 1, i64::from(b.miny) - 1);
    let (maxx, maxy) = (i64::from(b.maxx) + 1, i64::from(b.maxy) + 1);
    let ring = (minx..=maxx)
        .flat_map(|x| [(x, miny), (x, maxy)])
        .chain((miny + 1..maxy).flat_map(|y| [(minx, y), (maxx, y)]));
    let (mut n, mut none) = (0u32, 0u32);
    for (x, y) in ring {
        if let Some(c) = img.get_signed(x, y) {
            n += 1;
            none += u32::from(c == ColourClass::Unclassified.code());
        }
    }
    (n > 0).then(|| f64::from(none) / f64::from(n))
}

/// Share of ball colours among the image pixels whose centres lie inside the circle (`center`,
/// `radius` px), sampled every pixel up to a 24-pixel diameter and on a 24 × 24 grid over
/// larger circles (a close ball or a robot's arm fills tens of thousands of pixels; the share
/// needs a few hundred); `None` when no sample of the image lies inside.
fn circle_fill(img: &ClassifiedImage, center: Point, radius: f64) -> Option<f64> {
    if !(center.0.is_finite() && center.1.is_finite() && radius.is_finite() && radius > 0.0) {
        return None;
    }
    let step = (2.0 * radius / 24.0).max(1.0);
    let (w, h) = (img.width() as f64, img.height() as f64);
    let (mut n, mut ball) = (0u32, 0u32);
    let mut y = (center.1 - radius).floor() + 0.5;
    while y <= center.1 + radius {
        let mut x = (center.0 - radius).floor() + 0.5;
        while x <= center.0 + radius {
            if x >= 0.0
                && y >= 0.0
                && x < w
                && y < h
                && (x - center.0).powi(2) + (y - center.1).powi(2) <= radius * radius
                && let Some(c) = img.get_at(x, y)
            {
                n += 1;
                ball += u32::from(is_ball_colour(c));
            }
            x += step;
        }
        y += step;
    }
    (n > 0).then(|| f64::from(ball) / f64::from(n))
}

/// One outline point moved to the reference row's read-out time: through the body model when
/// asked and possible, else by the linear shear; `depth_cm` is the point's distance estimate.
fn unskew_point(ctx: &ViewContext, params: &BallParams, p: Point, depth_cm: f64) -> Point {
    if params.pose_skew_model && ctx.motion.is_some() && ctx.pose.is_some() {
        ctx.unskew_at(p, depth_cm, params.vertical_skew_correction)
    } else {
        ctx.unskew(p, params.vertical_skew_correction)
    }
}

/// Whether a moving-circle fit may replace the plain circle: both shears determined, and a
/// radius within a quarter of the plain fit's (a wild fit on noisy points is not a ball).
fn ellipse_usable(e: &ShearedCircleFit, plain: Option<&CircleFit>, params: &BallParams) -> bool {
    e.shear_x_sd <= params.ellipse_max_shear_sd
        && e.shear_y_sd <= params.ellipse_max_shear_sd
        && plain.is_some_and(|f| (e.circle.radius - f.radius).abs() <= 0.25 * f.radius)
}

/// The ground velocity (robot frame, cm/s) of a ball at image point `center` moving at
/// `v_px_s` pixels per second: where the ray through the centre meets the plane of ball
/// centres now and 10 ms later.
fn ground_velocity(
    ctx: &ViewContext,
    center: Point,
    v_px_s: (f64, f64),
    params: &BallParams,
) -> Option<[f64; 2]> {
    let pose = ctx.pose?;
    let dt = 0.01;
    let z = params.diameter_cm / 2.0;
    let a = pose.point_on_plane(crate::geometry::ImagePoint::new(center.0, center.1), z)?;
    let b = pose.point_on_plane(
        crate::geometry::ImagePoint::new(center.0 + v_px_s.0 * dt, center.1 + v_px_s.1 * dt),
        z,
    )?;
    let v = [(b.x() - a.x()) / dt, (b.y() - a.y()) / dt];
    v.iter().all(|c| c.is_finite()).then_some(v)
}

/// Recognises the ball in a classified frame.
#[must_use]
pub fn recognise_ball(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    ctx: &ViewContext,
    params: &BallParams,
) -> BallResult {
    let mut result = BallResult::default();
    let d = ctx.camera.focal_px;
    for (group, orange_pixels) in candidate_groups(blobs, params) {
        let cut = cut_off(
            img,
            &group,
            params.border_cut_min_share,
            params.hidden_min_chord_share,
            params.hidden_chord_min_radius_px,
        );
        let bounds = [group.minx, group.miny, group.maxx, group.maxy];
        let pattern = EdgeScanPattern::for_cut_off(cut);
        let mut points = edge_points_with_mixed(
            img,
            bounds,
            pattern,
            params.edge_margin_px,
            params.edge_run_px,
            is_ball_colour,
            |c| c == ColourClass::Unclassified.code(),
            params.mixed_edge,
        );
        let (box_centre, box_radius) = box_estimate(&group, cut);
        // Move every outline point to the read-out time of the reference row, the instant the
        // sensor readings describe: this removes the shear and puts the ball where the camera
        // pose says it is. The body model needs a depth: the distance the box's size implies.
        let depth = d * params.diameter_cm / (2.0 * box_radius.max(0.5));
        let unskew = |p: Point| unskew_point(ctx, params, p, depth);
        let scanned_points = points.clone();
        let rows: Vec<f64> = points.iter().map(|p| p.1).collect();
        let mut box_shift = (0.0, 0.0);
        if params.skew_correction {
            for p in &mut points {
                *p = unskew(*p);
            }
            let c = unskew(box_centre);
            box_shift = (c.0 - box_centre.0, c.1 - box_centre.1);
        }
        let w = f64::from(group.maxx - group.minx + 1);
        let h = f64::from(group.maxy - group.miny + 1);
        let uncut_extent = match (cut.left || cut.right, cut.top || cut.bottom) {
            (false, false) => w.max(h),
            (true, false) => h,
            (false, true) => w,
            (true, true) => 0.0,
        };
        let fit = (points.len() >= 5)
            .then(|| {
                fit_circle_trimmed(
                    &points,
                    params.fit_trim_sd,
                    params.fit_trim_min_px,
                    params.fit_trim_max_share,
                )
            })
            .flatten();
        let fit_rejected = match &fit {
            None if points.len() < 5 => Some(format!("only {} edge points", points.len())),
            None => Some("edge points do not fit a circle".to_owned()),
            Some(f) if 2.0 * f.radius < params.min_fit_diameter_ratio * uncut_extent => {
                Some(format!(
                    "diameter {:.1} px much smaller than blob extent {uncut_extent:.0} px",
                    2.0 * f.radius
                ))
            }
            Some(f) if f.residual_sd > params.max_fit_residual_ratio * f.radius + 0.75 => {
                Some(format!(
                    "residual spread {:.2} px too large for radius {:.1} px",
                    f.residual_sd, f.radius
                ))
            }
            Some(f) if f.radius > 4.0 * d => Some("radius beyond any ball".to_owned()),
            Some(f)
                if uncut_extent > 0.0
                    && 2.0 * f.radius > params.max_fit_diameter_ratio * uncut_extent =>
            {
                Some(format!(
                    "diameter {:.1} px much larger than blob extent {uncut_extent:.0} px",
                    2.0 * f.radius
                ))
            }
            Some(f) if !circle_holds_blob(f, &group, cut, box_shift) => {
                Some("circle does not hold the blob".to_owned())
            }
            Some(_) => None,
        };
        let use_fit = fit.is_some() && fit_rejected.is_none();
        let ellipse = (params.ellipse_fit && use_fit && points.len() >= params.ellipse_min_points)
            .then(|| {
                fit_sheared_circle(
                    &points,
                    &rows,
                    ctx.reference_row(),
                    params.ellipse_vertical_shear,
                )
            })
            .flatten();
        let moving = ellipse.filter(|e| ellipse_usable(e, fit.as_ref(), params));
        let (center, radius) = match (&fit, use_fit) {
            (Some(_), true) if moving.is_some() => moving.map_or(((0.0, 0.0), 0.0), |e| {
                ((e.circle.center_x, e.circle.center_y), e.circle.radius)
            }),
            (Some(f), true) => ((f.center_x, f.center_y), f.radius),
            _ if params.skew_correction => (unskew(box_centre), box_radius),
            _ => (box_centre, box_radius),
        };
        let radius = (radius + params.radius_bias_px).max(0.5);
        // With the fit's own points, the angle the ball subtends; else from the circle.
        let alpha = use_fit
            .then(|| angular_radius(&ctx.camera, &points, center, params))
            .flatten();
        let size_distance = match alpha {
            Some(a) => params.diameter_cm / 2.0 / a.sin(),
            None => distance_from_circle(&ctx.camera, center, radius, params.diameter_cm),
        };
        let distance = if params.ground_plane_fusion {
            let sigma = if use_fit && !cut.any() {
                params.radius_sigma_px
            } else {
                params.radius_sigma_cut_px
            };
            fuse_with_ground_plane(ctx, center, radius, sigma, size_distance, params)
        } else {
            size_distance
        };
        let camera = ctx.camera_relative(center, distance);
        // Back to where the ball is in the image: the point the skew removal moves onto the
        // centre (a fixed-point iteration; the removal is nearly a shift over a ball's size).
        let observed_center = if params.skew_correction {
            let mut p = (center.0 - box_shift.0, center.1 - box_shift.1);
            for _ in 0..3 {
                let q = unskew(p);
                p = (center.0 - (q.0 - p.0), center.1 - (q.1 - p.1));
            }
            if p.0.is_finite() && p.1.is_finite() {
                p
            } else {
                center
            }
        } else {
            center
        };
        // A ball that moved on its own while read out sits where it was when its centre row was
        // read.
        let observed_center = match &moving {
            Some(e) => {
                let lines = observed_center.1 - ctx.reference_row();
                (
                    observed_center.0 + e.shear_x * lines,
                    observed_center.1 + e.shear_y * lines,
                )
            }
            None => observed_center,
        };

        let mut confidence = Confidence::default();
        let area = w * h;
        confidence.range_test(
            "orange_fraction",
            f64::from(orange_pixels) / f64::from(group.pixels.max(1)),
            params.orange_fraction,
            params.orange_fraction_weight,
        );
        match circle_fill(img, observed_center, radius) {
            Some(fill) => confidence.range_test(
                "circle_fill",
                fill,
                params.circle_fill,
                params.circle_fill_weight,
            ),
            None => confidence.skipped("circle_fill", params.circle_fill),
        }
        if let Some(share) = unclassified_around(img, &group) {
            confidence.range_test(
                "unclassified_around",
                share,
                params.unclassified_around,
                params.unclassified_around_weight,
            );
        }
        let horizontal_cut = cut.left || cut.right;
        let vertical_cut = cut.top || cut.bottom;
        if horizontal_cut != vertical_cut {
            let slack = params.extent_slack_px;
            let ratio = if horizontal_cut {
                w / (h + slack)
            } else {
                h / (w + slack)
            };
            confidence.range_test(
                "cut_extent",
                ratio,
                [0.0, params.max_cut_extent_ratio],
                params.cut_extent_weight,
            );
        }
        if let (Some(f), Some(why)) = (&fit, &fit_rejected)
            && why.starts_with("residual")
        {
            confidence.range_test(
                "circle_residual_px",
                f.residual_sd,
                [0.0, params.max_fit_residual_ratio * f.radius + 0.75],
                TestWeight::new(0.0, params.bad_circle_penalty),
            );
        }
        if let (Some(f), true) = (&fit, use_fit)
            && f.radius >= params.circle_fit_min_radius_px
        {
            confidence.bonus_test(
                "circle_fit_points",
                f.points as f64,
                [params.circle_fit_min_points as f64, f64::INFINITY],
                params.circle_fit_bonus,
            );
        }
        if fit.is_none() && points.len() >= 5 {
            // Enough outline points, but on a line: a straight edge.
            confidence.range_test(
                "circle_fit",
                0.0,
                [1.0, 1.0],
                TestWeight::new(0.0, params.bad_circle_penalty),
            );
        }
        if cut.any() {
            confidence.skipped("pixel_ratio", params.pixel_ratio);
            confidence.skipped("roundness", params.aspect);
        } else {
            confidence.range_test(
                "pixel_ratio",
                f64::from(group.pixels) / area,
                params.pixel_ratio,
                params.pixel_ratio_weight,
            );
            confidence.range_test("roundness", w / h, params.aspect, params.aspect_weight);
        }
        // The pose's angular error turns into a height error that grows with distance.
        let slack = distance * params.height_pose_slack_rad.tan();
        let height_range = if slack.is_finite() && slack > 0.0 {
            [params.height_cm[0] - slack, params.height_cm[1] + slack]
        } else {
            params.height_cm
        };
        match ctx.height_above_ground(center, distance) {
            Some(z) => confidence.range_test("height_cm", z, height_range, params.height_weight),
            None => confidence.skipped("height_cm", height_range),
        }
        // Colour below: an area under the ball, parallel to the horizon, where the ball is in
        // the image (the centre before skew removal).
        let below_scan = scan_rotated_rect(
            img,
            (center.0 - box_shift.0, center.1 - box_shift.1),
            [
                -radius,
                radius,
                radius + 1.0,
                radius + 1.0 + (radius * 0.8).max(2.0),
            ],
            -ctx.horizon_angle(),
            (radius / 6.0).max(1.0),
        );
        match below_scan.ratio(|c| c == ColourClass::Green.code()) {
            Some(green) => confidence.bonus_test(
                "green_below",
                green,
                params.green_below,
                params.green_below_bonus,
            ),
            None => confidence.skipped("green_below", params.green_below),
        }
        let accepted = result.ball.is_none() && confidence.accepted();
        let index = result.candidates.len();
        // Rows are read out over the camera's read-out time, not the (logged) frame interval.
        let line_s = ctx.readout_s / ctx.camera.height_px.max(1) as f64;
        let image_velocity = moving.map(|e| e.velocity_px_s(line_s));
        if accepted {
            result.ball = Some(Ball {
                candidate: index,
                center_x: center.0,
                center_y: center.1,
                observed_center,
                radius_px: radius,
                camera,
                body: ctx.body_relative(center, distance),
                confidence: confidence.total,
                cut_off: cut,
                from_circle_fit: use_fit,
                image_velocity_px_s: image_velocity.map(|v| [v.0, v.1]),
                ground_velocity_cm_s: image_velocity
                    .and_then(|v| ground_velocity(ctx, center, v, params)),
            });
        }
        result.candidates.push(BallCandidate {
            bounds,
            pixels: group.pixels,
            orange_pixels,
            confidence,
            cut_off: cut,
            pattern,
            edge_points: points,
            scanned_points,
            fit,
            ellipse,
            fit_rejected,
            below: Some(below_scan.area),
            center,
            observed_center,
            radius_px: radius,
            camera,
            accepted,
        });
        if accepted {
            break;
        }
    }
    result
}

impl BallResult {
    /// Drawing primitives: every candidate's box, scan area and edge points; circles and a
    /// label for the accepted ball.
    #[must_use]
    pub fn primitives(&self) -> Vec<Primitive> {
        let mut out = Vec::new();
        for (i, c) in self.candidates.iter().enumerate() {
            let owner = super::draw::owner::ball(i);
            out.push(Primitive::Box {
                owner: owner.clone(),
                colour: ColourClass::Orange.code(),
                bounds: c.bounds,
            });
            if let Some(area) = c.below {
                out.push(Primitive::ScanArea {
                    owner: owner.clone(),
                    corners: area.corners,
                });
            }
            if !c.scanned_points.is_empty() {
                out.push(Primitive::ScanPoints {
                    owner: owner.clone(),
                    points: c.scanned_points.clone(),
                });
            }
            if c.accepted {
                // On the ball as the image shows it; where the skew correction puts it as a
                // second, dashed circle when that is visibly elsewhere.
                let seen = c.observed_center;
                out.push(Primitive::Circle {
                    owner: owner.clone(),
                    center: seen,
                    radius: c.radius_px,
                    role: CircleRole::Observed,
                });
                if (c.center.0 - seen.0).hypot(c.center.1 - seen.1) > 0.5 {
                    out.push(Primitive::Circle {
                        owner: owner.clone(),
                        center: c.center,
                        radius: c.radius_px,
                        role: CircleRole::SkewCorrected,
                    });
                }
                out.push(Primitive::Label {
                    owner,
                    at: (seen.0, seen.1 - c.radius_px - 2.0),
                    text: format!(
                        "ball {:.0} cm {:+.0}°",
                        c.camera.distance_cm,
                        c.camera.bearing_rad.to_degrees()
                    ),
                });
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blobs::Connectivity;
    use crate::geometry::{Ers7Dimensions, PinholeCamera, Point as GeoPoint};
    use crate::sensors::SensorReadings;

    fn level_context() -> ViewContext {
        let readings = SensorReadings {
            head_pan_rad: Some(0.0),
            head_tilt_rad: Some(-0.2),
            neck_tilt_rad: Some(0.0),
            ..SensorReadings::default()
        };
        ViewContext::from_sensors(PinholeCamera::ers7(), &readings, &Ers7Dimensions::ERS7)
    }

    /// Green field with an orange disc; `shear` shifts row y by shear·(y − cy) pixels.
    fn scene(cx: f64, cy: f64, r: f64, shear: f64) -> ClassifiedImage {
        let (w, h) = (208usize, 160usize);
        let mut codes = vec![ColourClass::Green.code(); w * h];
        for y in 0..h {
            for x in 0..w {
                let yc = y as f64 + 0.5;
                let dx = x as f64 + 0.5 - cx - shear * (yc - cy);
                let dy = yc - cy;
                if dx * dx + dy * dy <= r * r {
                    codes[y * w + x] = ColourClass::Orange.code();
                }
            }
        }
        ClassifiedImage::from_codes(w, h, codes).expect("size")
    }

    fn true_ball(ctx: &ViewContext, x: f64, y: f64) -> (Point, f64, f64) {
        let pose = ctx.pose.expect("pose");
        let centre = GeoPoint::new(x, y, 4.25);
        let p = pose.image_from_field(&centre).expect("in front");
        let cam = pose.position();
        let dist = cam.distance_to(&centre);
        ((p.x_px, p.y_px), ctx.camera.focal_px * 4.25 / dist, dist)
    }

    #[test]
    fn finds_a_ball_on_the_field_with_distance_from_the_circle() {
        let ctx = level_context();
        let (c, r, dist) = true_ball(&ctx, 90.0, 10.0);
        let img = scene(c.0, c.1, r, 0.0);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        let ball = res.ball.clone().expect("ball");
        assert!(ball.from_circle_fit);
        assert!((ball.center_x - c.0).abs() < 0.6 && (ball.center_y - c.1).abs() < 0.6);
        let err = (ball.camera.distance_cm - dist).abs() / dist;
        assert!(err < 0.05, "distance {} vs {dist}", ball.camera.distance_cm);
        assert!(ball.body.is_some());
        let cand = &res.candidates[ball.candidate];
        assert!(
            cand.confidence
                .test("height_cm")
                .is_some_and(|t| t.effect > 0.0)
        );
        assert!(
            cand.confidence
                .test("green_below")
                .is_some_and(|t| t.effect > 0.0)
        );
        assert!(!res.primitives().is_empty());
    }

    #[test]
    fn an_orange_thing_far_above_the_ground_is_not_a_ball() {
        let ctx = level_context();
        let img = scene(60.0, 12.0, 6.0, 0.0);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        assert!(res.ball.is_none(), "{:?}", res.candidates[0].confidence);
        let height = res.candidates[0]
            .confidence
            .test("height_cm")
            .expect("height test");
        assert!(height.value > 20.0 && height.effect < 0.0);
    }

    #[test]
    fn a_ball_cut_by_the_image_edge_keeps_its_distance() {
        let ctx = level_context();
        let pose = ctx.pose.expect("pose");
        // A ball on the field placed so that about a third of it is outside the left edge.
        let (_, r0, _) = true_ball(&ctx, 45.0, 0.0);
        let y = (0..400)
            .map(|i| f64::from(i) * 0.1)
            .min_by(|a, b| {
                let off = |y: f64| (true_ball(&ctx, 45.0, y).0.0 - 0.4 * r0).abs();
                off(*a).total_cmp(&off(*b))
            })
            .expect("positions");
        let (c, _, dist) = true_ball(&ctx, 45.0, y);
        // Rendered as a sphere, not a circle: a pixel shows the ball when its ray is within the
        // ball's angular radius of the centre's direction (off the optical axis the outline is
        // an ellipse, wider than a circle of the on-axis radius).
        let towards = ctx
            .camera
            .unit_ray(
                pose.image_from_field(&GeoPoint::new(45.0, y, 4.25))
                    .expect("in front"),
            )
            .coords;
        let cos_alpha = (4.25 / dist).asin().cos();
        let (w, h) = (208usize, 160usize);
        let codes = (0..w * h)
            .map(|i| {
                let ray = ctx
                    .camera
                    .unit_ray(crate::geometry::ImagePoint::pixel_centre(i % w, i / w));
                if ray.coords.dot(&towards) >= cos_alpha {
                    ColourClass::Orange.code()
                } else {
                    ColourClass::Green.code()
                }
            })
            .collect();
        let img = ClassifiedImage::from_codes(w, h, codes).expect("size");
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        let ball = res.ball.expect("ball");
        assert!(ball.cut_off.left && !ball.cut_off.right);
        assert!(ball.from_circle_fit);
        // The visible arc is the flatter inner side of the ellipse: the circle through it sits
        // a little inwards.
        assert!(
            (ball.center_x - c.0).abs() < 3.0,
            "{} vs {}",
            ball.center_x,
            c.0
        );
        let err = (ball.camera.distance_cm - dist) / dist;
        assert!(
            err.abs() < 0.04,
            "distance {} vs {dist}",
            ball.camera.distance_cm
        );
        // The original's d × 8.5 / diameter reads the stretched outline much too close.
        let naive = ctx.camera.focal_px * 8.5 / (2.0 * ball.radius_px);
        assert!(naive < 0.95 * dist, "naive {naive} vs {dist}");
    }

    #[test]
    fn distance_from_the_subtended_angle_holds_across_the_image() {
        let camera = PinholeCamera::ers7();
        // A sphere 100 cm away at the centre and 25° off the axis: its outline's mean
        // semi-axis (see `distance_from_circle`) gives the distance back within 0.5%.
        for theta_deg in [0.0_f64, 15.0, 25.0] {
            let (t, alpha) = (theta_deg.to_radians(), (4.25_f64 / 100.0).asin());
            let f = camera.focal_px;
            let a = f / 2.0 * ((t + alpha).tan() - (t - alpha).tan());
            let b = f * alpha.sin() / (t.cos().powi(2) - alpha.sin().powi(2)).sqrt();
            let centre_x = camera.centre.x_px + f / 2.0 * ((t + alpha).tan() + (t - alpha).tan());
            let d =
                distance_from_circle(&camera, (centre_x, camera.centre.y_px), (a + b) / 2.0, 8.5);
            assert!((d - 100.0).abs() < 0.5, "{theta_deg}°: {d}");
        }
    }

    #[test]
    fn skew_correction_restores_the_radius_of_a_sheared_ball() {
        let mut ctx = level_context();
        let (c, r, _) = true_ball(&ctx, 70.0, 0.0);
        let shear = 0.6;
        let img = scene(c.0, c.1, r, shear);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let plain = recognise_ball(
            &img,
            &blobs,
            &ctx,
            &BallParams {
                skew_correction: false,
                ..BallParams::default()
            },
        );
        // The pan during one read-out that shifts rows near the image centre by `shear` px each.
        ctx.pan_per_readout_rad = shear * ctx.camera.height_px as f64 / ctx.camera.focal_px;
        let fixed = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        let e_plain = (plain.ball.expect("plain").radius_px - r).abs();
        let e_fixed = (fixed.ball.expect("fixed").radius_px - r).abs();
        assert!(e_fixed * 2.0 < e_plain, "fixed {e_fixed} plain {e_plain}");
    }

    #[test]
    fn ellipse_fit_gives_the_image_velocity_of_a_moving_ball() {
        let ctx = level_context();
        let (c, r, _) = true_ball(&ctx, 45.0, 0.0);
        // Moving right 0.25 px per line (1200 px/s at 160 lines in 1/30 s), centred on the
        // reference row.
        let img = scene(c.0, 80.0, r, 0.25);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let plain = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        let plain = plain.ball.expect("plain");
        assert!(plain.image_velocity_px_s.is_none() && plain.ground_velocity_cm_s.is_none());
        let params = BallParams {
            ellipse_fit: true,
            ..BallParams::default()
        };
        let res = recognise_ball(&img, &blobs, &ctx, &params);
        let ball = res.ball.clone().expect("ball");
        let v = ball.image_velocity_px_s.expect("velocity");
        assert!((v[0] - 1200.0).abs() < 120.0 && v[1] == 0.0, "{v:?}");
        assert!(res.candidates[ball.candidate].ellipse.is_some());
        // Moving right in the image, straight ahead: to the robot's right on the ground.
        let g = ball.ground_velocity_cm_s.expect("ground velocity");
        assert!(g[1] < 0.0 && g[1].abs() > 3.0 * g[0].abs(), "{g:?}");
        assert!((ball.radius_px - r).abs() <= (plain.radius_px - r).abs() + 0.2);
    }

    #[test]
    fn soft_orange_joins_and_a_frame_without_orange_has_no_candidates() {
        let ctx = level_context();
        let (c, r, _) = true_ball(&ctx, 80.0, 0.0);
        let mut img = scene(c.0, c.1, r, 0.0);
        // Paint the lower half of the ball red-orange (shadow).
        let w = img.width();
        let codes = img.codes_mut();
        for (i, code) in codes.iter_mut().enumerate() {
            if *code == ColourClass::Orange.code() && (i / w) as f64 > c.1 {
                *code = ColourClass::RedOrange.code();
            }
        }
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        let ball = res.ball.expect("ball");
        assert!((ball.radius_px - r).abs() < 1.0);
        let green = scene(0.0, 0.0, 0.0, 0.0);
        let none = recognise_ball(
            &green,
            &BlobSet::from_image(&green, Connectivity::Eight),
            &ctx,
            &BallParams::default(),
        );
        assert!(none.ball.is_none() && none.candidates.is_empty());
    }

    /// A 320×240 green frame (no pose) with an orange disc, white wherever `white(x, y)`.
    fn big_scene(cx: f64, cy: f64, r: f64, white: impl Fn(f64, f64) -> bool) -> ClassifiedImage {
        let (w, h) = (320usize, 240usize);
        let codes = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                if (x - cx).hypot(y - cy) <= r {
                    ColourClass::Orange.code()
                } else if white(x, y) {
                    ColourClass::White.code()
                } else {
                    ColourClass::Green.code()
                }
            })
            .collect();
        ClassifiedImage::from_codes(w, h, codes).expect("size")
    }

    #[test]
    fn a_large_ball_on_a_white_line_is_round_not_hidden() {
        let ctx = ViewContext::without_pose(PinholeCamera::from_horizontal_fov(
            320,
            240,
            45.0_f64.to_radians(),
        ));
        // A 40-px ball lying on a thick white line that runs behind it, with its white stand
        // below: white borders most of its left, right and bottom sides, but it is round there.
        let img = big_scene(160.0, 120.0, 40.0, |x, y| {
            (95.0..150.0).contains(&y) || ((110.0..210.0).contains(&x) && y > 150.0)
        });
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        let ball = res.ball.expect("ball");
        assert!(!ball.cut_off.any(), "{:?}", ball.cut_off);
        assert!(ball.from_circle_fit);
        assert!((ball.radius_px - 40.0).abs() < 1.0, "{}", ball.radius_px);
        // The same ball behind a white robot leg whose straight edge cuts off its right third:
        // a long chord, hidden.
        let img = big_scene(160.0, 120.0, 40.0, |x, _| x > 187.0);
        let mut codes = img.codes().to_vec();
        for (i, c) in codes.iter_mut().enumerate() {
            if (i % 320) as f64 + 0.5 > 187.0 {
                *c = ColourClass::White.code();
            }
        }
        let img = ClassifiedImage::from_codes(320, 240, codes).expect("size");
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        let ball = res.ball.expect("ball");
        assert!(
            ball.cut_off.right && !ball.cut_off.left,
            "{:?}",
            ball.cut_off
        );
        assert!((ball.radius_px - 40.0).abs() < 1.5, "{}", ball.radius_px);
        // Taking every bordered side as hidden (the old rule) cuts the ball on the line too.
        let old = BallParams {
            hidden_min_chord_share: 0.0,
            ..BallParams::default()
        };
        let img = big_scene(160.0, 120.0, 40.0, |x, y| {
            (95.0..150.0).contains(&y) || ((110.0..210.0).contains(&x) && y > 150.0)
        });
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_ball(&img, &blobs, &ctx, &old);
        assert!(res.ball.expect("ball").cut_off.any());
    }

    #[test]
    fn a_thin_orange_arc_does_not_fill_its_circle() {
        let ctx = level_context();
        // The red-orange rim of a white toe: a 2-px arc of a 20-px circle, white inside.
        let (w, h) = (208usize, 160usize);
        let (cx, cy, r) = (104.0, 110.0, 20.0);
        let codes = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                let d = (x - cx).hypot(y - cy);
                if y < cy && (r - 2.0..=r).contains(&d) {
                    ColourClass::Orange.code()
                } else if d < r || y >= cy {
                    ColourClass::White.code()
                } else {
                    ColourClass::Green.code()
                }
            })
            .collect();
        let img = ClassifiedImage::from_codes(w, h, codes).expect("size");
        assert!(circle_fill(&img, (cx, cy), r).is_some_and(|f| f < 0.2));
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
        assert!(res.ball.is_none(), "{:?}", res.candidates[0].confidence);
        let fill = res.candidates[0]
            .confidence
            .test("circle_fill")
            .expect("circle fill test");
        assert!(fill.effect < 0.0, "{fill:?}");
        // A whole disc fills its circle; one outside the image has no fill.
        let disc = scene(60.0, 60.0, 8.0, 0.0);
        assert!(circle_fill(&disc, (60.0, 60.0), 8.0).is_some_and(|f| f > 0.95));
        assert_eq!(circle_fill(&disc, (-50.0, 60.0), 8.0), None);
        assert_eq!(circle_fill(&disc, (60.0, 60.0), f64::NAN), None);
    }
}
