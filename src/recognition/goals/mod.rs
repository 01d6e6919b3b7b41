//! Goals: blobs of a goal colour (yellow or sky blue) joined with the soft colours that may be
//! that colour, merged into candidates (near each other, lined up, or split by a goalkeeper),
//! checked for sides cut off by the image edge, given a distance from their height, tested, and
//! then searched for posts (line fits along uncut sides) and the largest open gap.
//!
//! "Parallel to the horizon" is done by rotating image points about the image centre by the
//! horizon's angle (the *level* frame), working there, and rotating results back.
//!
//! Stages, one file each: `candidates` (blobs joined and merged, the level extent, cut-off),
//! `examine` (distance and the confidence tests), `posts` (line fits along uncut sides),
//! `side_wall` (a side wall seen from outside moves a post to its front corner) and `gap`.

mod candidates;
mod examine;
mod gap;
mod posts;
mod side_wall;
#[cfg(test)]
mod tests;

use serde::{Deserialize, Serialize};

use super::confidence::{Confidence, TestName, TestWeight};
use super::context::{Relative, ViewContext};
use super::draw::{LineRole, ObjectId, Primitive};
use super::fit::LineFit;
use super::scan::CutOff;
use crate::blobs::BlobSet;
use crate::classify::ClassifiedImage;
use crate::frame::PixelBox;
use crate::frame::xy_array;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;

// The stages' items, for each other (each stage file reads them through `use super::*`).
use candidates::*;
use examine::*;
use gap::*;
use posts::*;
use side_wall::*;

/// Settings of goal recognition.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GoalParams {
    /// Goal height, centimetres (2005 rules: 30).
    pub height_cm: f64,
    /// Goal width, centimetres (2005 rules: 80).
    pub width_cm: f64,
    /// Blobs of the basic goal colour with fewer pixels are ignored.
    pub min_blob_pixels: u32,
    /// Candidates with fewer pixels in all are ignored.
    pub min_candidate_pixels: u32,
    /// Soft blobs join, and candidates merge, when their boxes come this close, pixels.
    pub join_px: u32,
    /// Candidates line up horizontally when their vertical overlap is at least this fraction of
    /// the shorter one's height.
    pub line_up_overlap: f64,
    /// In the level frame, tops and bottoms within this fraction of the height are "about equal"
    /// (a goal split by a goalkeeper).
    pub split_tolerance: f64,
    /// A rotated box point within this many pixels of the image edge counts as at the edge.
    pub edge_margin_px: f64,
    /// Distance = multiplier / height(px) + offset: multiplier, cm·px (pinhole: d × 30 cm =
    /// 5757). The default is the calibrated one: `eotn eval --calibrate-goals` on 720 rendered
    /// frames (walk-and-pan, beacon-tour, goalkeeper; seed 11; goals 160–410 cm away).
    pub distance_multiplier: f64,
    /// Distance offset, centimetres (calibrated with the multiplier).
    pub distance_offset_cm: f64,
    /// The goal-colour part's height is used when the soft sides add less than this fraction.
    pub soft_side_tolerance: f64,
    /// Each post's height is the tallest level column within this fraction of the goal's
    /// width from its side (at least 3 pixels).
    pub post_height_band: f64,
    /// The two posts' heights are used only when the shorter is at least this fraction of the
    /// goal's height (a robot in front of a post shortens it).
    pub post_height_agreement: f64,
    /// Measure heights as the angle they subtend, corrected for the elevation (see
    /// `equivalent_height`), instead of plain pixels.
    pub off_axis_correction: bool,
    /// Below this distance (cm) the infra-red reading replaces the size-based distance.
    pub ir_max_cm: f64,
    /// Goals covering more than this fraction of the image skip the identification tests.
    pub fills_image_fraction: f64,
    /// Candidates cut off on more sides than this (and not filling the image) are penalised.
    pub max_cut_sides: f64,
    /// Penalty for too many cut sides.
    pub cut_sides_penalty: f64,
    /// Accepted pixels / box area.
    pub pixel_ratio: [f64; 2],
    /// Weight of the pixel-ratio test.
    pub pixel_ratio_weight: TestWeight,
    /// Green fraction below the goal that earns a bonus.
    pub green_below: [f64; 2],
    /// Bonus for green (or white lines) below.
    pub green_below_bonus: f64,
    /// Penalty when there is too little green below (a yellow thing off the field).
    pub green_below_penalty: f64,
    /// Green or white fraction in a thin band right under the bottom edge (the carpet or the
    /// goal line a goal stands on; a yellow thing off the field stands on the floor).
    pub ground_at_foot: [f64; 2],
    /// Height of that band as a fraction of the goal's height (at least 2 pixels).
    pub ground_at_foot_band: f64,
    /// Weight of the ground-at-foot test.
    pub ground_at_foot_weight: TestWeight,
    /// Accepted ratio of the size-based distance to the distance of the bottom's foot on the
    /// ground (through the camera pose); a thing of another height than a goal fails.
    pub distance_agreement: [f64; 2],
    /// Weight of the distance-agreement test.
    pub distance_agreement_weight: TestWeight,
    /// Accepted height of the goal's bottom above the ground, centimetres.
    pub bottom_height_cm: [f64; 2],
    /// Weight of the bottom-height test.
    pub bottom_height_weight: TestWeight,
    /// Accepted body-relative elevation of the goal's centre, radians.
    pub elevation_rad: [f64; 2],
    /// Weight of the elevation test.
    pub elevation_weight: TestWeight,
    /// Accepted real width of a candidate, centimetres: its level width in pixels times the
    /// size-based distance over the focal length. A goal shows its 84-cm front (less when seen
    /// from the side, but its 30-cm-deep side wall then shows too); a yellow box or jacket of
    /// a goal's height is narrower. Skipped when the left or right side is cut off.
    pub apparent_width_cm: [f64; 2],
    /// Weight of the width test.
    pub apparent_width_weight: TestWeight,
    /// Base confidence of a candidate with enough pixels.
    pub size_bonus: f64,
    /// Number of scan lines per post.
    pub post_scans: usize,
    /// How far the post's centre lies inside the goal's outer edge, centimetres: half the
    /// side wall's thickness (2 cm walls in the simulator's 2005 field). The scans find the
    /// outline; the post line is moved inward by this at the goal's distance (≈ 1.2 px at
    /// 1.6 m). Where the camera sees a side wall's outer face (standing beside the goal) the
    /// outline is the wall's back corner, farther out; `post_front_corner` finds the post
    /// there.
    pub post_inset_cm: f64,
    /// Look for a side wall seen from outside on each side (the camera beyond the wall's outer
    /// face, beside a box goal): the outline's outer edge is then the wall's back corner, and
    /// the post is moved to the wall's front corner, where its foot is lowest and the carpet
    /// inside the mouth shows beyond it (see `front_corner`).
    pub post_front_corner: bool,
    /// A post is accepted when r² is at least this, or the points hardly vary across the line.
    pub post_min_r_squared: f64,
    /// ... and the residual variance s² is at most this, pixels².
    pub post_max_residual_variance: f64,
    /// ... and the line leans at most this far from the horizon's perpendicular, radians: a
    /// post stands upright (the rolling shutter leans it by about 6° on the fastest simulated
    /// pans); a flat line along a candidate's side is an edge of something else.
    pub post_max_lean_rad: f64,
    /// Up to this many scan points farthest from the line are dropped (one at a time,
    /// refitting) while the fit fails and more than five points remain.
    pub post_max_outliers: usize,
    /// Candidates at least this tall (level frame, pixels), with a left or right side in the
    /// image and not filling it, must show an upright post there.
    pub post_test_min_height_px: f64,
    /// Weight of that test.
    pub post_weight: TestWeight,
    /// Height of the gap scan above the ground, centimetres (about a robot's shoulder).
    pub gap_scan_height_cm: f64,
    /// Holes up to this many pixels inside a goal-coloured run do not end it: two are one UYVY
    /// pixel pair, whose shared chroma noise can leave both unclassified.
    pub gap_hole_px: u32,
    /// Move posts, gap and centre to the reference row's read-out time (rolling shutter).
    pub skew_correction: bool,
    /// Do that through the body model (the camera pose at each row's read-out time, pan and
    /// tilt, [`ViewContext::unskew_at`]) when the head's motion is known; when false, or
    /// without the motion, the linear shear from the pan alone. On walk-and-pan the linear
    /// shear is up to 4 px wrong at a post near the image top with the head tilted while
    /// tracking; the body model is within 0.5 px of the renderer's rolling shutter.
    pub pose_skew_model: bool,
    /// Penalty for a candidate overlapping an accepted beacon (its yellow or sky-blue band).
    pub beacon_overlap_penalty: f64,
    /// Accepted share of green (not white) below a candidate whose top is cut off and whose
    /// foot is in view: a beacon's band over its white base has none.
    pub green_below_cut: [f64; 2],
    /// Penalty when that share is below the range.
    pub green_below_cut_penalty: f64,
}

impl Default for GoalParams {
    fn default() -> Self {
        Self {
            height_cm: 30.0,
            width_cm: 80.0,
            min_blob_pixels: 12,
            min_candidate_pixels: 30,
            join_px: 3,
            line_up_overlap: 0.5,
            split_tolerance: 0.2,
            edge_margin_px: 1.5,
            distance_multiplier: 5762.0,
            distance_offset_cm: -5.0,
            soft_side_tolerance: 0.15,
            post_height_band: 0.15,
            post_height_agreement: 0.75,
            off_axis_correction: true,
            ir_max_cm: 60.0,
            fills_image_fraction: 0.6,
            max_cut_sides: 2.0,
            cut_sides_penalty: 3.0,
            pixel_ratio: [0.3, 1.0],
            pixel_ratio_weight: TestWeight::new(0.5, 1.5),
            green_below: [0.2, 1.0],
            green_below_bonus: 1.0,
            green_below_penalty: 1.5,
            ground_at_foot: [0.5, 1.0],
            ground_at_foot_band: 0.1,
            ground_at_foot_weight: TestWeight::new(0.5, 6.0),
            distance_agreement: [0.6, 1.6],
            distance_agreement_weight: TestWeight::new(1.0, 3.0),
            bottom_height_cm: [-20.0, 20.0],
            bottom_height_weight: TestWeight::new(1.0, 3.0),
            elevation_rad: [-0.8, 0.5],
            elevation_weight: TestWeight::new(0.5, 2.0),
            apparent_width_cm: [55.0, 160.0],
            apparent_width_weight: TestWeight::new(0.5, 6.0),
            size_bonus: 0.5,
            post_scans: 8,
            post_inset_cm: 1.0,
            post_front_corner: true,
            post_min_r_squared: 0.5,
            post_max_residual_variance: 2.0,
            post_max_outliers: 2,
            post_max_lean_rad: 0.35,
            post_test_min_height_px: 5.0,
            post_weight: TestWeight::new(0.0, 2.0),
            gap_scan_height_cm: 15.0,
            gap_hole_px: 2,
            skew_correction: true,
            pose_skew_model: true,
            beacon_overlap_penalty: 10.0,
            green_below_cut: [0.1, 1.0],
            green_below_cut_penalty: 3.0,
        }
    }
}

/// Which side of a goal a post is on, as seen in the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PostSide {
    /// The post on the image's left.
    Left,
    /// The post on the image's right.
    Right,
}

/// A goal post found by a line fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Post {
    /// Left or right in the image.
    pub side: PostSide,
    /// Top end of the fitted line, image pixels.
    #[serde(with = "xy_array")]
    pub top: ImagePoint,
    /// Bottom end of the fitted line, image pixels.
    #[serde(with = "xy_array")]
    pub bottom: ImagePoint,
    /// The fit (in image coordinates).
    pub fit: LineFit,
    /// Top end moved to the reference row's read-out time (rolling shutter), pixels: where the
    /// post is in the instant the camera pose describes. Equals `top` without skew correction.
    #[serde(default, with = "xy_array")]
    pub reference_top: ImagePoint,
    /// Bottom end moved to the reference row's read-out time, pixels.
    #[serde(default, with = "xy_array")]
    pub reference_bottom: ImagePoint,
    /// Camera-relative direction of the post's centre (distance: the goal's).
    pub camera: Relative,
    /// Body-relative direction of the post's centre.
    pub body: Option<Relative>,
    /// When the goal's side wall was seen from outside: how far inside the outline's outer
    /// edge (the wall's back corner) its front corner was found at its foot, pixels; the post
    /// is half a wall outside that corner.
    #[serde(default)]
    pub side_wall_px: Option<f64>,
}

/// The largest open stretch of goal between obstacles, along the gap scan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Gap {
    /// Left end, image pixels (as scanned; the bearings below are skew-corrected).
    #[serde(with = "xy_array")]
    pub left: ImagePoint,
    /// Right end, image pixels (as scanned).
    #[serde(with = "xy_array")]
    pub right: ImagePoint,
    /// Length, pixels.
    pub width_px: f64,
    /// Camera-relative direction of the gap's centre (what a kick should aim at).
    pub camera: Relative,
    /// Bearing of the left end, radians.
    pub left_bearing_rad: f64,
    /// Bearing of the right end, radians.
    pub right_bearing_rad: f64,
}

/// Why a goal candidate has no post on a side (the JSON names the reason in `reason`, with its
/// measured values beside it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum PostRejection {
    /// The candidate cannot reach a positive confidence even with the posts' reward, so no
    /// post was searched for.
    NotSearched {
        /// Its confidence before the post test.
        confidence: f64,
    },
    /// Too few scan points for a line.
    NoLine {
        /// Which side.
        side: PostSide,
        /// Points left.
        points: usize,
    },
    /// The line fits the points too poorly.
    PoorFit {
        /// Which side.
        side: PostSide,
        /// Coefficient of determination of the line fit.
        r_squared: f64,
        /// Residual variance, pixels².
        residual_variance_px2: f64,
        /// Points used.
        points: usize,
    },
    /// The line leans too far from upright.
    Leans {
        /// Which side.
        side: PostSide,
        /// Lean from upright in the level frame, degrees.
        lean_deg: f64,
    },
}

impl std::fmt::Display for PostRejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::NotSearched { confidence } => write!(
                f,
                "not searched: confidence {confidence:.2} cannot turn positive"
            ),
            Self::NoLine { side, points } => write!(f, "{side:?}: {points} points, no line"),
            Self::PoorFit {
                side,
                r_squared,
                residual_variance_px2,
                points,
            } => write!(
                f,
                "{side:?}: r² {r_squared:.2}, s² {residual_variance_px2:.2} px² from {points} points"
            ),
            Self::Leans { side, lean_deg } => {
                write!(f, "{side:?}: leans {lean_deg:.0}° from upright")
            }
        }
    }
}

/// A recognised goal, or a rejected candidate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoalCandidate {
    /// Yellow or sky blue.
    pub colour: ColourClass,
    /// Bounds, inclusive pixels.
    pub bounds: PixelBox,
    /// Pixels of goal colours.
    pub pixels: u32,
    /// Bounds of the basic goal-colour part.
    pub basic_bounds: PixelBox,
    /// Numbers of the blobs that make it up.
    pub blobs: Vec<u32>,
    /// Sides cut off by the image edge.
    pub cut_off: CutOff,
    /// Height used for the distance, pixels (level frame).
    pub height_px: f64,
    /// Camera-relative distance, bearing, elevation of the centre.
    pub camera: Relative,
    /// Body-relative, when the joints are known.
    pub body: Option<Relative>,
    /// True when top or bottom is cut off: the real goal is at most this far.
    pub distance_is_max: bool,
    /// True when the infra-red reading gave the distance.
    pub distance_from_ir: bool,
    /// True when the distance is that of the goal's foot on the ground (through the camera
    /// pose), used when the top is cut off.
    #[serde(default)]
    pub distance_from_ground: bool,
    /// Extent of the candidate's pixels in the level frame (rotated about the image centre by
    /// the horizon angle): `[min x, min y, max x, max y]`, pixels.
    #[serde(default)]
    pub level_extent: [f64; 4],
    /// Confidence breakdown.
    pub confidence: Confidence,
    /// Fitted posts.
    pub posts: Vec<Post>,
    /// Posts whose fit was rejected (or not searched for), and why.
    pub rejected_posts: Vec<PostRejection>,
    /// Points scanned for posts, pixels.
    #[serde(with = "xy_array")]
    pub post_points: Vec<ImagePoint>,
    /// The largest open gap.
    pub gap: Option<Gap>,
    /// The gap scan line, pixels.
    #[serde(with = "xy_array")]
    pub gap_scan: Option<(ImagePoint, ImagePoint)>,
    /// Accepted as a goal.
    pub accepted: bool,
}

/// Goal recognition's output: every candidate of both colours; accepted ones are goals.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GoalResult {
    /// All candidates, accepted first within each colour.
    pub candidates: Vec<GoalCandidate>,
}

impl GoalResult {
    /// The accepted goals.
    pub fn goals(&self) -> impl Iterator<Item = &GoalCandidate> {
        self.candidates.iter().filter(|c| c.accepted)
    }
}

/// Recognises yellow and sky-blue goals.
#[must_use]
pub fn recognise_goals(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    ctx: &ViewContext,
    p: &GoalParams,
    beacons: &[PixelBox],
) -> GoalResult {
    let mut result = GoalResult::default();
    for colour in [ColourClass::Yellow, ColourClass::SkyBlue] {
        let mut accepted_one = false;
        for g in build_groups(blobs, colour, ctx, p) {
            let mut cand = examine(img, blobs, &g, colour, ctx, p);
            // A beacon's yellow or sky-blue band is not a goal.
            let overlap = beacons
                .iter()
                .map(|b| cand.bounds.overlap_fraction(b))
                .fold(0.0, f64::max);
            if overlap > 0.0 {
                cand.confidence.range_test(
                    TestName::BeaconOverlap,
                    overlap,
                    [0.0, 0.2],
                    TestWeight::new(0.0, p.beacon_overlap_penalty),
                );
            }
            // The post search is most of a candidate's cost. One that cannot reach a positive
            // total even with the posts' reward (a tile of goal colour far too small or too
            // high for a goal) is not searched: its breakdown says why it failed already.
            let hopeless = cand.confidence.total + p.post_weight.reward <= 0.0;
            if hopeless {
                cand.rejected_posts.push(PostRejection::NotSearched {
                    confidence: cand.confidence.total,
                });
            } else {
                find_posts(img, &mut cand, colour, ctx, p);
            }
            let e = cand.level_extent;
            let area = cand.bounds.area_px();
            let fills = area >= p.fills_image_fraction * img.width() as f64 * img.height() as f64;
            let sides_in_view = !(cand.cut_off.left && cand.cut_off.right);
            if hopeless || fills || !sides_in_view || e[3] - e[1] < p.post_test_min_height_px {
                cand.confidence.skipped(TestName::UprightPosts, [1.0, 2.0]);
            } else {
                // A goal shows an upright post on a side in view; a band of goal colour along
                // the edge of a line or a shadow does not.
                cand.confidence.range_test(
                    TestName::UprightPosts,
                    cand.posts.len() as f64,
                    [1.0, 2.0],
                    p.post_weight,
                );
            }
            if !accepted_one && cand.confidence.accepted() {
                cand.accepted = true;
                accepted_one = true;
                find_gap(img, &mut cand, colour, ctx, p);
            }
            result.candidates.push(cand);
        }
    }
    result
}

impl GoalResult {
    /// Drawing primitives: candidate boxes, post points and lines, the gap and its scan, labels.
    #[must_use]
    pub fn primitives(&self) -> Vec<Primitive> {
        let mut out = Vec::new();
        for (i, c) in self.candidates.iter().enumerate() {
            let owner = ObjectId::Goal(c.colour, i);
            out.push(Primitive::Box {
                owner,
                colour: c.colour.code(),
                bounds: c.bounds,
            });
            if !c.post_points.is_empty() {
                out.push(Primitive::ScanPoints {
                    owner,
                    points: c.post_points.clone(),
                });
            }
            for post in &c.posts {
                out.push(Primitive::Line {
                    owner,
                    role: LineRole::Post,
                    from: post.top,
                    to: post.bottom,
                });
            }
            if let Some((a, b)) = c.gap_scan {
                out.push(Primitive::Line {
                    owner,
                    role: LineRole::Scan,
                    from: a,
                    to: b,
                });
            }
            if let Some(gap) = &c.gap {
                out.push(Primitive::Line {
                    owner,
                    role: LineRole::Gap,
                    from: gap.left,
                    to: gap.right,
                });
            }
            if c.accepted {
                out.push(Primitive::Label {
                    owner,
                    at: ImagePoint::new(f64::from(c.bounds.min_x), f64::from(c.bounds.min_y) - 2.0),
                    text: format!(
                        "{} goal {}{:.0} cm {:+.0}°",
                        c.colour.name(),
                        if c.distance_is_max { "≤" } else { "" },
                        c.camera.distance_cm,
                        c.camera.bearing_rad.to_degrees()
                    ),
                });
            }
        }
        out
    }
}
