//! The ball: orange blobs (joined with touching soft colours that may be orange) become
//! candidates, largest first; each is scored by the confidence tests; the first with a positive
//! total is the ball. Its outline is scanned in one of six patterns chosen by which sides are cut
//! off or hidden, the rolling shutter's shear removed, and a circle fitted; distance, bearing and
//! elevation come from the circle through the camera model.
//!
//! The stages, one file each: `outline` (candidate groups, cut-off, edge scans and the shear's
//! removal), `circle` (the circle fit, accepted or refused with a [`FitRejection`], and the
//! moving-circle fit), `distance` (from the angle the outline subtends, fused with the ground
//! plane; where the ball shows in the image) and `checks` (the confidence tests).

mod checks;
mod circle;
mod distance;
mod outline;
#[cfg(test)]
mod tests;

use serde::{Deserialize, Serialize};

use super::confidence::{Confidence, TestWeight};
use super::context::{Relative, ViewContext};
use super::draw::{CircleRole, Primitive};
use super::fit::{CircleFit, ShearedCircleFit};
use super::scan::{CutOff, EdgeScanPattern, MixedEdge, ScanArea};
use crate::blobs::BlobSet;
use crate::classify::ClassifiedImage;
use crate::frame::PixelBox;
use crate::frame::xy_array;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;

pub use circle::FitRejection;
pub use distance::distance_from_circle;

/// Settings of ball recognition. Amounts are confidence points; the defaults follow the
/// original's rules and were checked on the renderer's scenarios.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BallParams {
    /// Ball diameter, centimetres (2005 Four-Legged League: 8.5).
    pub diameter_cm: f64,
    /// Candidates whose orange core (the basic-orange blob, before soft colours join it) has
    /// fewer pixels are ignored; a group of soft colours alone needs this many of its own.
    pub min_pixels: u32,
    /// At most this many candidates are scored per frame.
    pub max_candidates: usize,
    /// Soft-colour blobs join an orange blob when their boxes come this close, pixels.
    pub soft_join_px: u32,
    /// Soft-colour blobs that join no orange blob are candidates of their own (scored with the
    /// orange-fraction test). Off for a camera whose dim ball colours are soft classes shared
    /// with skin, wood and lights (`params/ssl-onboard.json`): there a soft colour only widens an
    /// orange core to the ball's rim and shadow side, and is never a ball by itself.
    pub soft_candidates: bool,
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
    /// Without a camera pose (frames without sensor readings: no height test), the share of
    /// field colours (green or white) that a ball needs right at its foot (a band just below
    /// its box): a ball lies on the field, while an orange thing off the field — in the
    /// audience, on a table, a chair on the floor — has furniture or floor at its foot. With a
    /// pose the height test rejects such things and this test is not applied.
    pub field_below_without_pose: [f64; 2],
    /// Weight of the field-below test (applied only without a pose).
    pub field_below_without_pose_weight: TestWeight,
    /// How far below its foot the field-below test may look, in the candidate's radii (half its
    /// box's larger side): the band is also taken one, two, … pixels lower down to this reach,
    /// and the best share counts. The carpet right under a lit ball is its own shadow (dark
    /// enough to classify as black or not at all), while the foot of a light on a robot is the
    /// robot's body all the way down. 0 (the default) reads the band at the foot only.
    pub field_below_reach_radii: f64,
    /// Without a camera pose, the share of field colours (green or white) a ball needs in the
    /// strip beneath it: as wide as its box, from two pixels below it down
    /// [`Self::field_beneath_radii`] radii (inside the image). A ball on the field has field
    /// down to the image's bottom but for robots and lines; an orange light or shirt in the
    /// audience has people, banners and the field's border beneath it, even where a speck of
    /// carpet-like grey passes `field_below` at its foot. Off unless its weight has a penalty
    /// (`params/ssl-onboard.json` turns it on), so nothing else changes.
    pub field_beneath_without_pose: [f64; 2],
    /// Weight of the field-beneath test (applied only without a pose, and only with a penalty).
    pub field_beneath_without_pose_weight: TestWeight,
    /// Length of the field-beneath strip, in the candidate's radii (half its box's larger side).
    pub field_beneath_radii: f64,
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
    /// The unclassified-surroundings ring lies this many pixels further out than right beside
    /// the box: past a blurred ball's rim, whose pixels mix the ball's colour with the carpet's
    /// and classify as neither (the SSL on-board frames' small balls, `params/ssl-onboard.json`).
    /// 0 (the default) reads the ring right beside the box.
    pub unclassified_ring_gap_px: u32,
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
    /// A hidden side stays hidden after the circle fit only when the circle reaches more than
    /// this beyond the blob there, pixels (else the ball is whole on that side: it lies against
    /// a white line or a robot without being covered).
    pub hidden_min_overhang_px: f64,
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
            soft_candidates: true,
            pixel_ratio: [0.4, 1.0],
            pixel_ratio_weight: TestWeight::new(1.0, 2.0),
            height_cm: [-6.0, 16.0],
            height_weight: TestWeight::new(1.0, 4.0),
            height_pose_slack_rad: 0.0,
            green_below: [0.25, 1.0],
            green_below_bonus: 1.0,
            field_below_without_pose: [0.5, 1.0],
            field_below_without_pose_weight: TestWeight::new(0.0, 2.5),
            field_below_reach_radii: 0.0,
            field_beneath_without_pose: [0.5, 1.0],
            field_beneath_without_pose_weight: TestWeight::new(0.0, 0.0),
            field_beneath_radii: 12.0,
            aspect: [0.6, 1.67],
            aspect_weight: TestWeight::new(0.5, 1.5),
            orange_fraction: [0.3, 1.0],
            orange_fraction_weight: TestWeight::new(0.5, 2.0),
            unclassified_around: [0.0, 0.6],
            unclassified_around_weight: TestWeight::new(0.0, 2.0),
            unclassified_ring_gap_px: 0,
            circle_fill: [0.2, 1.0],
            circle_fill_weight: TestWeight::new(0.0, 3.0),
            edge_margin_px: 3,
            edge_run_px: 2,
            mixed_edge: MixedEdge::ChromaPairs,
            border_cut_min_share: 0.25,
            hidden_min_chord_share: 0.35,
            hidden_chord_min_radius_px: 20.0,
            hidden_min_overhang_px: 1.5,
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
    #[serde(default, with = "xy_array")]
    pub observed_center: ImagePoint,
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
    /// The joined blobs' box, inclusive pixels.
    pub bounds: PixelBox,
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
    #[serde(with = "xy_array")]
    pub edge_points: Vec<ImagePoint>,
    /// The outline points where the scans found them in the image (before skew removal),
    /// pixels: what the overlay draws.
    #[serde(default, with = "xy_array")]
    pub scanned_points: Vec<ImagePoint>,
    /// The circle fit, if one was found.
    pub fit: Option<CircleFit>,
    /// The moving-circle (constrained ellipse) fit, when [`BallParams::ellipse_fit`] is on and
    /// it was tried.
    #[serde(default)]
    pub ellipse: Option<ShearedCircleFit>,
    /// Why the circle fit was not used, if it was not.
    pub fit_rejected: Option<FitRejection>,
    /// The colour-below scan area.
    pub below: Option<ScanArea>,
    /// Estimated centre, pixels, at the reference read-out time (skew removed).
    #[serde(with = "xy_array")]
    pub center: ImagePoint,
    /// The centre where the ball appears in the image, pixels (see [`Ball::observed_center`]).
    #[serde(default, with = "xy_array")]
    pub observed_center: ImagePoint,
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

/// Recognises the ball in a classified frame: each candidate group, largest first, is
/// outlined, fitted, placed and tested; the first with a positive total is the ball.
#[must_use]
pub fn recognise_ball(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    ctx: &ViewContext,
    params: &BallParams,
) -> BallResult {
    let mut result = BallResult::default();
    for (group, orange_pixels) in outline::candidate_groups(blobs, params) {
        let mut outline = outline::Outline::scan(img, &group, ctx, params);
        let circle = circle::CircleStage::fit(&outline, ctx, params);
        if let Some(fit) = circle.fit.as_ref().filter(|_| circle.used()) {
            outline.cut = circle::confirmed_cut(
                fit,
                outline.bounds,
                outline.cut,
                outline.box_shift,
                (img.width() as u32, img.height() as u32),
                params.hidden_min_overhang_px,
            );
        }
        let (center, radius) = circle.center_and_radius(&outline, ctx, params);
        let distance = distance::ball_distance(ctx, &outline, &circle, center, radius, params);
        let camera = ctx.camera_relative(center, distance);
        let observed_center =
            distance::observed_center(ctx, &outline, circle.moving.as_ref(), center, params);
        let measured = checks::Measured {
            group: &group,
            orange_pixels,
            outline: &outline,
            circle: &circle,
            center,
            observed_center,
            radius,
            distance,
        };
        let (confidence, below_scan) = checks::score(img, ctx, &measured, params);
        let accepted = result.ball.is_none() && confidence.accepted();
        let index = result.candidates.len();
        if accepted {
            // Rows are read out over the camera's read-out time, not the (logged) frame interval.
            let line_s = ctx.readout_s / ctx.camera.height_px.max(1) as f64;
            let image_velocity = circle.moving.map(|e| e.velocity_px_s(line_s));
            result.ball = Some(Ball {
                candidate: index,
                center_x: center.x_px,
                center_y: center.y_px,
                observed_center,
                radius_px: radius,
                camera,
                body: ctx.body_relative(center, distance),
                confidence: confidence.total,
                cut_off: outline.cut,
                from_circle_fit: circle.used(),
                image_velocity_px_s: image_velocity.map(|v| [v.0, v.1]),
                ground_velocity_cm_s: image_velocity
                    .and_then(|v| distance::ground_velocity(ctx, center, v, params)),
            });
        }
        result.candidates.push(BallCandidate {
            bounds: outline.bounds,
            pixels: group.pixels,
            orange_pixels,
            confidence,
            cut_off: outline.cut,
            pattern: outline.pattern,
            edge_points: outline.points,
            scanned_points: outline.scanned_points,
            fit: circle.fit,
            ellipse: circle.ellipse,
            fit_rejected: circle.rejection,
            below: Some(below_scan),
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
            let owner = super::draw::ObjectId::Ball(i);
            out.push(Primitive::Box {
                owner,
                colour: ColourClass::Orange.code(),
                bounds: c.bounds,
            });
            if let Some(area) = c.below {
                out.push(Primitive::ScanArea {
                    owner,
                    corners: area.corners,
                });
            }
            if !c.scanned_points.is_empty() {
                out.push(Primitive::ScanPoints {
                    owner,
                    points: c.scanned_points.clone(),
                });
            }
            if c.accepted {
                // On the ball as the image shows it; where the skew correction puts it as a
                // second, dashed circle when that is visibly elsewhere.
                let seen = c.observed_center;
                out.push(Primitive::Circle {
                    owner,
                    center: seen,
                    radius: c.radius_px,
                    role: CircleRole::Observed,
                });
                if c.center.distance_to(&seen) > 0.5 {
                    out.push(Primitive::Circle {
                        owner,
                        center: c.center,
                        radius: c.radius_px,
                        role: CircleRole::SkewCorrected,
                    });
                }
                out.push(Primitive::Label {
                    owner,
                    at: ImagePoint::new(seen.x_px, seen.y_px - c.radius_px - 2.0),
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
