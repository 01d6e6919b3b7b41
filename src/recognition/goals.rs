//! Goals: blobs of a goal colour (yellow or sky blue) joined with the soft colours that may be
//! that colour, merged into candidates (near each other, lined up, or split by a goalkeeper),
//! checked for sides cut off by the image edge, given a distance from their height, tested, and
//! then searched for posts (line fits along uncut sides) and the largest open gap.
//!
//! "Parallel to the horizon" is done by rotating image points about the image centre by the
//! horizon's angle (the *level* frame), working there, and rotating results back.

use serde::{Deserialize, Serialize};

use super::confidence::{Confidence, TestWeight};
use super::context::{Relative, ViewContext};
use super::draw::{LineRole, Primitive};
use super::fit::{LineFit, Point, fit_line, rotate_about};
use super::scan::{CutOff, scan_rotated_rect};
use crate::blobs::{Blob, BlobSet};
use crate::classify::ClassifiedImage;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;

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
    pub top: Point,
    /// Bottom end of the fitted line, image pixels.
    pub bottom: Point,
    /// The fit (in image coordinates).
    pub fit: LineFit,
    /// Top end moved to the reference row's read-out time (rolling shutter), pixels: where the
    /// post is in the instant the camera pose describes. Equals `top` without skew correction.
    #[serde(default)]
    pub reference_top: Point,
    /// Bottom end moved to the reference row's read-out time, pixels.
    #[serde(default)]
    pub reference_bottom: Point,
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
    pub left: Point,
    /// Right end, image pixels (as scanned).
    pub right: Point,
    /// Length, pixels.
    pub width_px: f64,
    /// Camera-relative direction of the gap's centre (what a kick should aim at).
    pub camera: Relative,
    /// Bearing of the left end, radians.
    pub left_bearing_rad: f64,
    /// Bearing of the right end, radians.
    pub right_bearing_rad: f64,
}

/// A recognised goal, or a rejected candidate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoalCandidate {
    /// Yellow or sky blue.
    pub colour: ColourClass,
    /// `[minx, miny, maxx, maxy]`, inclusive pixels.
    pub bounds: [u32; 4],
    /// Pixels of goal colours.
    pub pixels: u32,
    /// Bounds of the basic goal-colour part.
    pub basic_bounds: [u32; 4],
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
    /// Posts whose fit was rejected, and why.
    pub rejected_posts: Vec<String>,
    /// Points scanned for posts, pixels.
    pub post_points: Vec<Point>,
    /// The largest open gap.
    pub gap: Option<Gap>,
    /// The gap scan line, pixels.
    pub gap_scan: Option<(Point, Point)>,
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

fn near(a: &Blob, b: &Blob, gap: u32) -> bool {
    a.minx <= b.maxx + gap + 1
        && b.minx <= a.maxx + gap + 1
        && a.miny <= b.maxy + gap + 1
        && b.miny <= a.maxy + gap + 1
}

/// A candidate while it is being built: the joined blob and its basic-colour part.
#[derive(Debug, Clone)]
struct Group {
    all: Blob,
    basic: Blob,
    members: Vec<u32>,
}

fn level_extent(b: &Blob, centre: Point, angle: f64) -> [f64; 4] {
    let corners = [
        (f64::from(b.minx), f64::from(b.miny)),
        (f64::from(b.maxx + 1), f64::from(b.miny)),
        (f64::from(b.maxx + 1), f64::from(b.maxy + 1)),
        (f64::from(b.minx), f64::from(b.maxy + 1)),
    ];
    let mut e = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for c in corners {
        let p = rotate_about(c, centre, angle);
        e[0] = e[0].min(p.0);
        e[1] = e[1].min(p.1);
        e[2] = e[2].max(p.0);
        e[3] = e[3].max(p.1);
    }
    e
}

/// Level-frame extent of the pixels of some blobs (their runs' ends, rotated), tighter than
/// the rotated box when the horizon is tilted: a tilted box's corners add w·sin θ to its height.
fn pixel_level_extent(
    blobs: &BlobSet,
    members: impl Iterator<Item = u32>,
    centre: Point,
    angle: f64,
) -> Option<[f64; 4]> {
    let mut e = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for m in members {
        for r in blobs.runs_of(m) {
            let (x0, x1, y) = (f64::from(r.x0), f64::from(r.x1), f64::from(r.y));
            for c in [(x0, y), (x1, y), (x0, y + 1.0), (x1, y + 1.0)] {
                let q = rotate_about(c, centre, angle);
                e[0] = e[0].min(q.0);
                e[1] = e[1].min(q.1);
                e[2] = e[2].max(q.0);
                e[3] = e[3].max(q.1);
            }
        }
    }
    (e[0] < e[2] && e[1] < e[3]).then_some(e)
}

fn build_groups(
    blobs: &BlobSet,
    colour: ColourClass,
    ctx: &ViewContext,
    p: &GoalParams,
) -> Vec<Group> {
    let soft: Vec<&Blob> = blobs
        .active()
        .filter(|b| {
            ColourClass::from_code(b.colour).is_some_and(|c| c != colour && c.may_be_class(colour))
        })
        .collect();
    let mut used = vec![false; soft.len()];
    let mut groups: Vec<Group> = Vec::new();
    for b in blobs
        .of_class(colour)
        .filter(|b| b.pixels >= p.min_blob_pixels)
    {
        let mut g = Group {
            all: *b,
            basic: *b,
            members: vec![b.number],
        };
        for (i, s) in soft.iter().enumerate() {
            if !used[i] && near(&g.all, s, p.join_px) {
                g.all = g.all.merged_with(s);
                g.members.push(s.number);
                used[i] = true;
            }
        }
        groups.push(g);
    }
    // Merge until stable: near, lined up, or split by a goalkeeper (level tops/bottoms equal).
    let centre = (ctx.camera.centre.x_px, ctx.camera.centre.y_px);
    let angle = ctx.horizon_angle();
    loop {
        let mut merged = false;
        'outer: for i in 0..groups.len() {
            for j in i + 1..groups.len() {
                let (a, b) = (&groups[i].all, &groups[j].all);
                let (ha, hb) = (
                    f64::from(a.maxy - a.miny + 1),
                    f64::from(b.maxy - b.miny + 1),
                );
                let overlap =
                    (f64::from(a.maxy.min(b.maxy)) - f64::from(a.miny.max(b.miny)) + 1.0).max(0.0);
                let lined_up = overlap >= p.line_up_overlap * ha.min(hb);
                let (ea, eb) = (
                    level_extent(a, centre, angle),
                    level_extent(b, centre, angle),
                );
                let tol = p.split_tolerance * (ea[3] - ea[1]).max(eb[3] - eb[1]);
                let split = (ea[1] - eb[1]).abs() <= tol && (ea[3] - eb[3]).abs() <= tol;
                if near(a, b, p.join_px) || lined_up && split {
                    let other = groups.swap_remove(j);
                    let g = &mut groups[i];
                    g.all = g.all.merged_with(&other.all);
                    g.basic = g.basic.merged_with(&other.basic);
                    g.members.extend(other.members);
                    merged = true;
                    break 'outer;
                }
            }
        }
        if !merged {
            break;
        }
    }
    groups.retain(|g| g.all.pixels >= p.min_candidate_pixels);
    groups.sort_by_key(|g| std::cmp::Reverse(g.all.pixels));
    groups
}

/// Share of box `a` covered by box `b` (inclusive pixel boxes).
fn overlap_fraction(a: [u32; 4], b: [u32; 4]) -> f64 {
    let w = (a[2].min(b[2]) + 1).saturating_sub(a[0].max(b[0]));
    let h = (a[3].min(b[3]) + 1).saturating_sub(a[1].max(b[1]));
    let area = f64::from(a[2] - a[0] + 1) * f64::from(a[3] - a[1] + 1);
    f64::from(w) * f64::from(h) / area
}

/// Cut-off detection: the level box's 8 points (corners and side midpoints), rotated back into
/// the image; a side is cut off when two or more of its three points are near or outside the edge.
fn detect_cut_off(e: [f64; 4], centre: Point, angle: f64, w: f64, h: f64, margin: f64) -> CutOff {
    let un = |x: f64, y: f64| rotate_about((x, y), centre, -angle);
    let (mx, my) = ((e[0] + e[2]) / 2.0, (e[1] + e[3]) / 2.0);
    let at_edge =
        |p: Point| p.0 <= margin || p.1 <= margin || p.0 >= w - margin || p.1 >= h - margin;
    let count = |pts: [Point; 3]| pts.iter().filter(|p| at_edge(**p)).count() >= 2;
    CutOff {
        left: count([un(e[0], e[1]), un(e[0], my), un(e[0], e[3])]),
        right: count([un(e[2], e[1]), un(e[2], my), un(e[2], e[3])]),
        top: count([un(e[0], e[1]), un(mx, e[1]), un(e[2], e[1])]),
        bottom: count([un(e[0], e[3]), un(mx, e[3]), un(e[2], e[3])]),
    }
}

fn is_goal_colour(colour: ColourClass) -> impl Fn(u8) -> bool {
    move |code| ColourClass::from_code(code).is_some_and(|c| c == colour || c.may_be_class(colour))
}

/// Recognises yellow and sky-blue goals.
#[must_use]
pub fn recognise_goals(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    ctx: &ViewContext,
    p: &GoalParams,
    beacons: &[[u32; 4]],
) -> GoalResult {
    let mut result = GoalResult::default();
    for colour in [ColourClass::Yellow, ColourClass::SkyBlue] {
        let mut accepted_one = false;
        for g in build_groups(blobs, colour, ctx, p) {
            let mut cand = examine(img, blobs, &g, colour, ctx, p);
            // A beacon's yellow or sky-blue band is not a goal.
            let overlap = beacons
                .iter()
                .map(|b| overlap_fraction(cand.bounds, *b))
                .fold(0.0, f64::max);
            if overlap > 0.0 {
                cand.confidence.range_test(
                    "beacon_overlap",
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
                cand.rejected_posts.push(format!(
                    "not searched: confidence {:.2} cannot turn positive",
                    cand.confidence.total
                ));
            } else {
                find_posts(img, &mut cand, colour, ctx, p);
            }
            let e = cand.level_extent;
            let area = f64::from(cand.bounds[2] - cand.bounds[0] + 1)
                * f64::from(cand.bounds[3] - cand.bounds[1] + 1);
            let fills = area >= p.fills_image_fraction * img.width() as f64 * img.height() as f64;
            let sides_in_view = !(cand.cut_off.left && cand.cut_off.right);
            if hopeless || fills || !sides_in_view || e[3] - e[1] < p.post_test_min_height_px {
                cand.confidence.skipped("upright_posts", [1.0, 2.0]);
            } else {
                // A goal shows an upright post on a side in view; a band of goal colour along
                // the edge of a line or a shadow does not.
                cand.confidence.range_test(
                    "upright_posts",
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

fn examine(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    g: &Group,
    colour: ColourClass,
    ctx: &ViewContext,
    p: &GoalParams,
) -> GoalCandidate {
    let (w, h) = (img.width() as f64, img.height() as f64);
    let centre = (ctx.camera.centre.x_px, ctx.camera.centre.y_px);
    let angle = ctx.horizon_angle();
    // Cut-off from the rotated box (its corners reach the edge when the goal does); sizes and
    // positions from the pixels themselves.
    let cut = detect_cut_off(
        level_extent(&g.all, centre, angle),
        centre,
        angle,
        w,
        h,
        p.edge_margin_px,
    );
    let e_all = pixel_level_extent(blobs, g.members.iter().copied(), centre, angle)
        .unwrap_or_else(|| level_extent(&g.all, centre, angle));
    let basic_members = g
        .members
        .iter()
        .copied()
        .filter(|m| blobs.get(*m).is_some_and(|b| b.colour == colour.code()));
    let e_basic = pixel_level_extent(blobs, basic_members, centre, angle)
        .unwrap_or_else(|| level_extent(&g.basic, centre, angle));
    let h_all = e_all[3] - e_all[1];
    let h_basic = e_basic[3] - e_basic[1];
    let use_basic = (h_all - h_basic) <= p.soft_side_tolerance * h_all;
    let e_h = if use_basic { e_basic } else { e_all };
    let level_height = e_h[3] - e_h[1];
    let upright = |x: f64, top: f64, bottom: f64| {
        let (a, b) = (
            rotate_about((x, top), centre, -angle),
            rotate_about((x, bottom), centre, -angle),
        );
        if p.off_axis_correction {
            equivalent_height(ctx, a, b).unwrap_or(bottom - top)
        } else {
            bottom - top
        }
    };
    let mut height_px = upright((e_h[0] + e_h[2]) / 2.0, e_h[1], e_h[3]);
    // Whole goal in view: the distance is that of the mouth's centre, between the two posts'
    // distances (the tallest level column near each side; the box's height is the nearer
    // post's). The equivalent height is their harmonic mean.
    if !cut.any() {
        let basic = |c: u8| c == colour.code();
        let any = is_goal_colour(colour);
        let pred: &dyn Fn(u8) -> bool = if use_basic { &basic } else { &any };
        let band = ((e_h[2] - e_h[0]) * p.post_height_band).max(3.0);
        if let (Some(l), Some(r)) = (
            side_height(img, pred, e_h, true, band, centre, angle),
            side_height(img, pred, e_h, false, band, centre, angle),
        ) && (l.2 - l.1).min(r.2 - r.1) >= p.post_height_agreement * level_height
        {
            let (hl, hr) = (upright(l.0, l.1, l.2), upright(r.0, r.1, r.2));
            height_px = 2.0 / (1.0 / hl + 1.0 / hr);
        }
    }
    let mut distance = p.distance_multiplier / height_px.max(1.0) + p.distance_offset_cm;
    // Top cut off, bottom in view: the foot on the ground (through the camera pose) gives the
    // distance; the height would only give a maximum.
    let bottom_mid = rotate_about(((e_all[0] + e_all[2]) / 2.0, e_all[3]), centre, -angle);
    let mut from_ground = false;
    if cut.top
        && !cut.bottom
        && let Some(f) = ctx
            .distance_to_plane(bottom_mid, 0.0)
            .filter(|f| f.is_finite() && *f > 0.0)
    {
        distance = f;
        from_ground = true;
    }
    let mut from_ir = false;
    if let Some(ir) = ctx
        .ir_distance_cm
        .filter(|d| d.is_finite() && *d > 0.0 && *d < p.ir_max_cm)
        && distance < p.ir_max_cm * 1.5
    {
        distance = ir;
        from_ir = true;
    }
    let mut mid = rotate_about(
        ((e_all[0] + e_all[2]) / 2.0, (e_all[1] + e_all[3]) / 2.0),
        centre,
        -angle,
    );
    if p.skew_correction {
        mid = unskew(ctx, p, mid, distance);
    }
    let camera = ctx.camera_relative(mid, distance);
    let body = ctx.body_relative(mid, distance);
    let mut confidence = Confidence::default();
    confidence.range_test(
        "pixels",
        f64::from(g.all.pixels),
        [f64::from(p.min_candidate_pixels), f64::INFINITY],
        TestWeight::new(p.size_bonus, 1.0),
    );
    let area = f64::from(g.all.maxx - g.all.minx + 1) * f64::from(g.all.maxy - g.all.miny + 1);
    let fills = area >= p.fills_image_fraction * w * h;
    confidence.range_test(
        "pixel_ratio",
        f64::from(g.all.pixels) / area,
        p.pixel_ratio,
        p.pixel_ratio_weight,
    );
    if fills {
        confidence.skipped("cut_sides", [0.0, p.max_cut_sides]);
        confidence.skipped("green_below", p.green_below);
        confidence.skipped("bottom_height_cm", p.bottom_height_cm);
        confidence.skipped("elevation_rad", p.elevation_rad);
    } else {
        // A sliver cut off on three or four sides that does not fill the image shows too
        // little of itself to be identified.
        let cut_sides = [cut.left, cut.right, cut.top, cut.bottom]
            .iter()
            .filter(|c| **c)
            .count();
        confidence.range_test(
            "cut_sides",
            cut_sides as f64,
            [0.0, p.max_cut_sides],
            TestWeight::new(0.0, p.cut_sides_penalty),
        );
        let half_w = (e_all[2] - e_all[0]) / 2.0;
        let band = (height_px * 0.3).max(2.0);
        let below = scan_rotated_rect(
            img,
            bottom_mid,
            [-half_w, half_w, 1.0, 1.0 + band],
            -angle,
            (band / 4.0).max(1.0),
        );
        match below.ratio(|c| c == ColourClass::Green.code() || c == ColourClass::White.code()) {
            Some(r) => confidence.range_test(
                "green_below",
                r,
                p.green_below,
                TestWeight::new(p.green_below_bonus, p.green_below_penalty),
            ),
            None => confidence.skipped("green_below", p.green_below),
        }
        let foot_band = (height_px * p.ground_at_foot_band).max(2.0);
        let at_foot = scan_rotated_rect(
            img,
            bottom_mid,
            [-half_w, half_w, 1.0, 1.0 + foot_band],
            -angle,
            1.0,
        );
        match at_foot.ratio(|c| c == ColourClass::Green.code() || c == ColourClass::White.code()) {
            Some(r) if !cut.bottom => confidence.range_test(
                "ground_at_foot",
                r,
                p.ground_at_foot,
                p.ground_at_foot_weight,
            ),
            _ => confidence.skipped("ground_at_foot", p.ground_at_foot),
        }
        if cut.bottom {
            confidence.skipped("bottom_height_cm", p.bottom_height_cm);
        } else {
            match ctx.height_above_ground(bottom_mid, distance) {
                Some(z) => confidence.range_test(
                    "bottom_height_cm",
                    z,
                    p.bottom_height_cm,
                    p.bottom_height_weight,
                ),
                None => confidence.skipped("bottom_height_cm", p.bottom_height_cm),
            }
        }
        if cut.left || cut.right {
            confidence.skipped("apparent_width_cm", p.apparent_width_cm);
        } else {
            confidence.range_test(
                "apparent_width_cm",
                (e_all[2] - e_all[0]) * distance / ctx.camera.focal_px,
                p.apparent_width_cm,
                p.apparent_width_weight,
            );
        }
        let foot = ctx.distance_to_plane(bottom_mid, 0.0);
        match foot {
            Some(f) if !cut.bottom && !cut.top && f > 0.0 => confidence.range_test(
                "distance_agreement",
                distance / f,
                p.distance_agreement,
                p.distance_agreement_weight,
            ),
            _ => confidence.skipped("distance_agreement", p.distance_agreement),
        }
        match &body {
            Some(b) => confidence.range_test(
                "elevation_rad",
                b.elevation_rad,
                p.elevation_rad,
                p.elevation_weight,
            ),
            None => confidence.skipped("elevation_rad", p.elevation_rad),
        }
    }
    GoalCandidate {
        colour,
        bounds: [g.all.minx, g.all.miny, g.all.maxx, g.all.maxy],
        pixels: g.all.pixels,
        basic_bounds: [g.basic.minx, g.basic.miny, g.basic.maxx, g.basic.maxy],
        blobs: g.members.clone(),
        cut_off: cut,
        height_px,
        camera,
        body,
        distance_is_max: !from_ir && !from_ground && (cut.top || cut.bottom),
        distance_from_ir: from_ir,
        distance_from_ground: from_ground && !from_ir,
        level_extent: e_all,
        confidence,
        posts: Vec::new(),
        rejected_posts: Vec::new(),
        post_points: Vec::new(),
        gap: None,
        gap_scan: None,
        accepted: false,
    }
}

/// The tallest run of goal colour along level columns within `band` pixels inside one side of
/// the level extent `e`: the post on that side as (level x, top y, bottom y), pixels.
fn side_height(
    img: &ClassifiedImage,
    is_goal: &dyn Fn(u8) -> bool,
    e: [f64; 4],
    left: bool,
    band: f64,
    centre: Point,
    angle: f64,
) -> Option<(f64, f64, f64)> {
    let columns = band.ceil() as usize;
    let rows = (e[3] - e[1]).ceil() as usize + 2;
    let mut best: Option<(f64, f64, f64)> = None;
    for k in 0..columns {
        let x = if left {
            e[0] + 0.5 + k as f64
        } else {
            e[2] - 0.5 - k as f64
        };
        let (mut top, mut bottom) = (None, None);
        for i in 0..rows {
            let y = e[1] - 1.0 + i as f64;
            let q = rotate_about((x, y + 0.5), centre, -angle);
            if img.get_at(q.0, q.1).is_some_and(is_goal) {
                top.get_or_insert(y);
                bottom = Some(y + 1.0);
            }
        }
        if let (Some(t), Some(b)) = (top, bottom)
            && best.is_none_or(|(_, bt, bb)| b - t > bb - bt)
        {
            best = Some((x, t, b));
        }
    }
    best
}

/// The height in pixels that an upright segment from image point `top` to `bottom` would have
/// seen face-on at the image centre: focal length × the angle it subtends ÷ the cosine of its
/// elevation above the ground (the camera's own elevation without a pose). A pixel height
/// alone shrinks off the optical axis and when looking up or down at a goal, so
/// multiplier / height would not be a distance everywhere in the image.
fn equivalent_height(ctx: &ViewContext, top: Point, bottom: Point) -> Option<f64> {
    let ray = |p: Point| ctx.camera.unit_ray(ImagePoint::new(p.0, p.1)).coords;
    let (a, b) = (ray(top), ray(bottom));
    let phi = a.dot(&b).clamp(-1.0, 1.0).acos();
    let mid = ((top.0 + bottom.0) / 2.0, (top.1 + bottom.1) / 2.0);
    let elevation = match (
        ctx.height_above_ground(mid, 100.0),
        ctx.height_above_ground(mid, 0.0),
    ) {
        (Some(far), Some(near)) => ((far - near) / 100.0).clamp(-1.0, 1.0).asin(),
        _ => ctx.camera_angles(mid).1,
    };
    let h = ctx.camera.focal_px * phi / elevation.cos();
    (h.is_finite() && h > 0.0).then_some(h)
}

/// Scans from outside a level x position inward along a level row until a goal-coloured pixel;
/// returns the level x where the scan line enters that pixel, pixels. Steps of one pixel find
/// the pixel; bisection between the last sample outside and the first inside then finds the
/// crossing of its border to 1/64 pixel. (Returning a whole step's sample instead puts the edge
/// up to a pixel inward when the horizon is tilted, where samples fall anywhere in a pixel.)
fn scan_level_row(
    img: &ClassifiedImage,
    is_goal: &impl Fn(u8) -> bool,
    y: f64,
    from: f64,
    to: f64,
    centre: Point,
    angle: f64,
) -> Option<f64> {
    let dir = if to >= from { 1.0 } else { -1.0 };
    let steps = (to - from).abs().ceil() as usize;
    let goal_at = |x: f64| {
        let q = rotate_about((x, y), centre, -angle);
        img.get_at(q.0, q.1).is_some_and(is_goal)
    };
    for k in 0..=steps {
        let x = from + dir * k as f64;
        if goal_at(x) {
            if k == 0 {
                return Some(x);
            }
            let (mut outside, mut inside) = (x - dir, x);
            for _ in 0..6 {
                let m = (outside + inside) / 2.0;
                if goal_at(m) {
                    inside = m;
                } else {
                    outside = m;
                }
            }
            return Some((outside + inside) / 2.0);
        }
    }
    None
}

/// An image point of a goal `distance_cm` away moved to the reference row's read-out time.
fn unskew(ctx: &ViewContext, p: &GoalParams, q: Point, distance_cm: f64) -> Point {
    if p.pose_skew_model {
        ctx.unskew_at(q, distance_cm, true)
    } else {
        ctx.unskew(q, false)
    }
}

/// Posts: level scans inward along each uncut side, a line fit through their edges, accepted
/// when straight and upright.
fn find_posts(
    img: &ClassifiedImage,
    cand: &mut GoalCandidate,
    colour: ColourClass,
    ctx: &ViewContext,
    p: &GoalParams,
) {
    let centre = (ctx.camera.centre.x_px, ctx.camera.centre.y_px);
    let angle = ctx.horizon_angle();
    let e = cand.level_extent;
    let is_goal = is_goal_colour(colour);
    let distance = cand.camera.distance_cm;
    let height = e[3] - e[1];
    let n = p.post_scans.max(3);
    let inset_px = if distance > 0.0 {
        (p.post_inset_cm * ctx.camera.focal_px / distance).clamp(0.0, (e[2] - e[0]) / 4.0)
    } else {
        0.0
    };
    for (side, cut, from, to) in [
        (
            PostSide::Left,
            cand.cut_off.left,
            e[0] - 3.0,
            (e[0] + e[2]) / 2.0,
        ),
        (
            PostSide::Right,
            cand.cut_off.right,
            e[2] + 3.0,
            (e[0] + e[2]) / 2.0,
        ),
    ] {
        if cut {
            continue;
        }
        let mut level_pts = Vec::new();
        for k in 0..n {
            // Inner 80% of the height: the ends are rounded by blur and shading.
            let y = e[1] + height * (0.1 + 0.8 * (k as f64 + 0.5) / n as f64);
            if let Some(x) = scan_level_row(img, &is_goal, y, from, to, centre, angle) {
                level_pts.push((x, y));
            }
        }
        cand.post_points
            .extend(level_pts.iter().map(|q| rotate_about(*q, centre, -angle)));
        let dir = match side {
            PostSide::Left => 1.0,
            PostSide::Right => -1.0,
        };
        let far_side_cut = match side {
            PostSide::Left => cand.cut_off.right,
            PostSide::Right => cand.cut_off.left,
        };
        let side_wall = if p.post_front_corner {
            front_corner(
                img,
                &is_goal,
                &level_pts,
                e,
                dir,
                far_side_cut,
                (centre, angle),
            )
        } else {
            None
        };
        if let Some(w) = side_wall {
            for c in std::iter::once(w.foot).chain(w.top) {
                cand.post_points.push(rotate_about(c.at, centre, -angle));
            }
        }
        // The scans find the outline's outer edge; the post's centre is half a wall inside it,
        // or half a wall outside the front corner of a side wall seen from outside.
        let image_pts: Vec<Point> = level_pts
            .iter()
            .map(|q| {
                let shift = side_wall.map_or(inset_px, |w| w.offset_at(q.1) - inset_px);
                rotate_about((q.0 + dir * shift, q.1), centre, -angle)
            })
            .collect();
        let good = |f: &LineFit| {
            f.residual_variance <= p.post_max_residual_variance
                && (f.r_squared >= p.post_min_r_squared || f.steep)
        };
        // A stray point (a robot's leg or a shadow on one scan row) is dropped, farthest from
        // the line first, while the fit fails and enough points remain.
        let mut pts = image_pts;
        let mut fit = fit_line(&pts);
        let mut dropped = 0;
        while let Some(f) = fit
            && !good(&f)
            && dropped < p.post_max_outliers
            && pts.len() > 5
        {
            let off = |q: &Point| {
                if f.steep {
                    (q.0 - f.at(q.1).0).abs()
                } else {
                    (q.1 - f.at(q.0).1).abs()
                }
            };
            let Some(worst) = (0..pts.len()).max_by(|a, b| off(&pts[*a]).total_cmp(&off(&pts[*b])))
            else {
                break;
            };
            pts.remove(worst);
            dropped += 1;
            fit = fit_line(&pts);
        }
        let Some(fit) = fit else {
            cand.rejected_posts
                .push(format!("{side:?}: {} points, no line", pts.len()));
            continue;
        };
        if !good(&fit) || pts.len() < 3 {
            cand.rejected_posts.push(format!(
                "{side:?}: r² {:.2}, s² {:.2} px² from {} points",
                fit.r_squared,
                fit.residual_variance,
                pts.len()
            ));
            continue;
        }
        let top_level = rotate_about(pts[0], centre, angle);
        let top = if fit.steep {
            fit.at(rotate_about((top_level.0, e[1]), centre, -angle).1)
        } else {
            pts[0]
        };
        let bottom = if fit.steep {
            fit.at(rotate_about((top_level.0, e[3]), centre, -angle).1)
        } else {
            pts[pts.len() - 1]
        };
        let (lt, lb) = (
            rotate_about(top, centre, angle),
            rotate_about(bottom, centre, angle),
        );
        let lean = (lb.0 - lt.0).abs().atan2((lb.1 - lt.1).abs());
        if lean.is_nan() || lean > p.post_max_lean_rad {
            cand.rejected_posts.push(format!(
                "{side:?}: leans {:.0}° from upright",
                lean.to_degrees()
            ));
            continue;
        }
        let (reference_top, reference_bottom) = if p.skew_correction {
            (
                unskew(ctx, p, top, distance),
                unskew(ctx, p, bottom, distance),
            )
        } else {
            (top, bottom)
        };
        let mid = (
            (reference_top.0 + reference_bottom.0) / 2.0,
            (reference_top.1 + reference_bottom.1) / 2.0,
        );
        cand.posts.push(Post {
            side,
            top,
            bottom,
            fit,
            reference_top,
            reference_bottom,
            camera: ctx.camera_relative(mid, distance),
            body: ctx.body_relative(mid, distance),
            side_wall_px: side_wall.map(|w| w.foot.offset),
        });
    }
}

/// How much higher (sample rows) the foot of a side wall seen from outside must be at the
/// outline, and just beyond the wall's front corner, than at the corner. One row is the
/// classification's own noise along a goal's bottom: a partly covered row of pixels shows in
/// some columns only.
const FOOT_STEP_ROWS: usize = 2;

/// The lowest foot of a side wall seen from outside lies at least this many columns (pixels)
/// inside the outline. Two are seen on goals from in front: a partly covered bottom row can put
/// a chroma pair of goal colour below the rest next to the post. A narrower wall moves the
/// post by only about two pixels.
const MIN_WALL_COLUMNS: usize = 3;

/// A corner of a side wall seen from outside: where the wall ends towards the mouth on one
/// level row.
#[derive(Debug, Clone, Copy, PartialEq)]
struct WallCorner {
    /// The corner, level frame, pixels.
    at: Point,
    /// Its distance inside the outline along the row, pixels.
    offset: f64,
}

/// The front corner of a side wall seen from outside, found by [`front_corner`]: at its foot
/// and, when the top shows it too, at its top.
#[derive(Debug, Clone, Copy, PartialEq)]
struct SideWall {
    /// The corner on the lowest foot row.
    foot: WallCorner,
    /// The corner on the highest top row, when it is clear and its offset differs from the
    /// foot's by at most [`SideWall::MAX_LEAN`] of the rows between them.
    top: Option<WallCorner>,
}

impl SideWall {
    /// Largest accepted difference between the top's and the foot's offsets, as a fraction of
    /// the rows between them. Both corners lie on one upright edge, which leans (rolling
    /// shutter, perspective) as the back corner does, but the outline's fit through a few
    /// scans of that far edge can lean a pixel or two differently; a larger difference is
    /// noise at the top.
    const MAX_LEAN: f64 = 0.2;

    /// The offset inside the outline at level row `y`, pixels: between the foot's and the
    /// top's, linearly (the foot's alone when the top gave none).
    fn offset_at(&self, y: f64) -> f64 {
        let f = self.foot;
        match self.top {
            Some(t) if (f.at.1 - t.at.1).abs() > f64::EPSILON => {
                f.offset + (t.offset - f.offset) * (f.at.1 - y) / (f.at.1 - t.at.1)
            }
            _ => f.offset,
        }
    }
}

/// A box goal's side wall seen from outside (the camera beyond the wall's outer face, beside
/// the goal). The outline's outer edge on that side is then the wall's back corner, and the
/// post, the wall's front end, lies inside the goal-coloured region. Being nearer, the post is
/// the side's tallest stretch: the wall's foot descends from the back corner to it, and just
/// beyond it the carpet inside the mouth shows under the back wall, which is farther away and
/// so ends higher (and its top lower). Seen from in front, the outline's edge is the post
/// itself and the foot is lowest right there, so none of this applies.
///
/// `outline`: the side's scan points in the level frame; `dir`: +1 for the left side (inward
/// is +x), −1 for the right; `far_side_cut`: the other side is cut off by the image edge;
/// `level`: the image centre and horizon angle of the level frame. Columns run parallel to the
/// outline one pixel apart; in each, the lowest and the highest goal sample within half the
/// height of the extent's bottom and top. The front corner is accepted when every sign is
/// there: the lowest foot at least [`MIN_WALL_COLUMNS`] inside the outline (in the near half
/// of the goal, or across it when the other side is cut off) and [`FOOT_STEP_ROWS`] lower than
/// at it, carpet (green or a white line) under the slanting foot in at least half of those
/// columns (not a robot in front of the post), the foot higher again in the next two columns
/// beyond the corner, by [`FOOT_STEP_ROWS`] in one of them, with carpet there, and the top at
/// the corner at most a row lower than at the outline. Each corner is placed to 1/64 px by
/// bisection along its row.
fn front_corner(
    img: &ClassifiedImage,
    is_goal: &impl Fn(u8) -> bool,
    outline: &[Point],
    e: [f64; 4],
    dir: f64,
    far_side_cut: bool,
    (centre, angle): (Point, f64),
) -> Option<SideWall> {
    let line = fit_line(outline).filter(|f| f.steep)?;
    let edge_x = |y: f64| line.at(y).0;
    // Level frame → image: `rotate_about` by −angle with its sine and cosine taken once.
    let (sin, cos) = (-angle).sin_cos();
    let code_at = |x: f64, y: f64| {
        let (dx, dy) = (x - centre.0, y - centre.1);
        let q = (
            centre.0 + cos * dx - sin * dy,
            centre.1 + sin * dx + cos * dy,
        );
        img.get_at(q.0, q.1)
    };
    let goal_at = |x: f64, y: f64| code_at(x, y).is_some_and(is_goal);
    let ground = |c: Option<u8>| {
        c.is_some_and(|c| c == ColourClass::Green.code() || c == ColourClass::White.code())
    };
    let height = e[3] - e[1];
    if !(height.is_finite() && height > 0.0 && e[2] > e[0]) {
        return None;
    }
    let rows = (height / 2.0).ceil() as usize;
    let columns = (e[2] - e[0]).floor() as usize;
    // The corner lies in the near half of the goal (anywhere across it when the other side is
    // cut off) and no farther inside than the goal is tall: a side wall shows at most its
    // depth, and the 2005 goals' walls are as deep as they are tall (30 cm).
    let search = if far_side_cut { columns } else { columns / 2 }.min(height.ceil() as usize);
    // Sample row i counted from below the extent's bottom (feet) and from above its top (tops).
    let foot_y = |i: usize| e[3] + 0.5 - i as f64;
    let top_y = |i: usize| e[1] - 0.5 + i as f64;
    let column_x = |k: usize, y: f64| edge_x(y) + dir * (k as f64 + 0.5);
    let foot_of = |k: usize| (0..rows).find(|&i| goal_at(column_x(k, foot_y(i)), foot_y(i)));
    // Seen from in front, the outline's foot is the lowest already (most goals): done.
    if (0..2).filter_map(foot_of).max()? < FOOT_STEP_ROWS {
        return None;
    }
    // Per column: the sample row of its lowest goal sample (smaller = farther out); the tops
    // are looked at only once the feet show a corner.
    let feet: Vec<Option<usize>> = (0..columns.min(search + 4)).map(foot_of).collect();
    let foot = |k: usize| feet.get(k).copied().flatten();
    // The lowest foot: its first column from the outline and the end of its plateau.
    let (k0, lowest) = (0..search)
        .filter_map(|k| foot(k).map(|f| (k, f)))
        .min_by_key(|&(k, f)| (f, k))?;
    let foot_at_edge = (0..2).filter_map(foot).max()?;
    if k0 < MIN_WALL_COLUMNS
        || (0..k0).any(|k| foot(k).is_none())
        || foot_at_edge < lowest + FOOT_STEP_ROWS
    {
        return None;
    }
    let k1 = plateau_end(&foot, k0, lowest);
    // Beyond the corner the foot jumps up (after at most one column between) and stays up: the
    // back wall's bottom. On a goal seen from in front the feet go on down towards a nearer
    // post instead. Outside the image nothing is known.
    let yf = foot_y(lowest);
    let up = |k: usize, step: usize| {
        k < feet.len()
            && code_at(column_x(k, yf), yf).is_some()
            && foot(k).is_none_or(|f| f >= lowest + step)
    };
    let jumps = up(k1 + 1, 1)
        && up(k1 + 2, 1)
        && (up(k1 + 1, FOOT_STEP_ROWS) || up(k1 + 2, FOOT_STEP_ROWS));
    if !jumps || !(1..=3).any(|d| ground(code_at(column_x(k1 + d, yf), yf))) {
        return None;
    }
    // Carpet under the slanting foot, in at least half of those columns (the first row under
    // it is often a mixed pixel): not a robot standing in front of the post.
    let carpet_under = (0..k0)
        .filter(|&k| {
            foot(k).is_some_and(|f| {
                (1..=2).any(|d| {
                    let y = foot_y(f) + d as f64;
                    ground(code_at(column_x(k, y), y))
                })
            })
        })
        .count();
    if carpet_under * 2 < k0 {
        return None;
    }
    // The corner is nearer, so its top is no lower than the outline's; it rises less than the
    // foot descends when the camera is below the goal's top, and a row of it is noise.
    let tops: Vec<Option<usize>> = (0..feet.len())
        .map(|k| (0..rows).find(|&i| goal_at(column_x(k, top_y(i)), top_y(i))))
        .collect();
    let top = |k: usize| tops.get(k).copied().flatten();
    let top_at_edge = (0..2).filter_map(top).min()?;
    let highest = (0..=k1).filter_map(top).min()?;
    if (k0..=k1).filter_map(top).min()? > top_at_edge + 1 {
        return None;
    }
    let crossing = |k: usize, y: f64| {
        let (mut inside, mut outside) = (column_x(k, y), column_x(k + 1, y));
        for _ in 0..6 {
            let m = (inside + outside) / 2.0;
            if goal_at(m, y) {
                inside = m;
            } else {
                outside = m;
            }
        }
        let x = (inside + outside) / 2.0;
        WallCorner {
            at: (x, y),
            offset: dir * (x - edge_x(y)),
        }
    };
    let foot_corner = crossing(k1, yf);
    // The top's corner: the end of the highest top's plateau, the top lower in the next two
    // columns (the back wall's, farther away).
    let top_corner = (0..=k1).find(|&k| top(k) == Some(highest)).and_then(|k| {
        let end = plateau_end(&top, k, highest);
        let lower = |k: usize| k < tops.len() && top(k).is_none_or(|t| t > highest);
        let yt = top_y(highest);
        let corner = crossing(end, yt);
        (lower(end + 1)
            && lower(end + 2)
            && code_at(column_x(end + 1, yt), yt).is_some()
            && (corner.offset - foot_corner.offset).abs() <= SideWall::MAX_LEAN * (yf - yt))
            .then_some(corner)
    });
    Some(SideWall {
        foot: foot_corner,
        top: top_corner,
    })
}

/// The last column of a plateau of `value` starting at column `from` in a profile: a single
/// column one row off inside it is noise.
fn plateau_end(profile: &impl Fn(usize) -> Option<usize>, from: usize, value: usize) -> usize {
    let mut end = from;
    let mut k = from + 1;
    while let Some(v) = profile(k) {
        if v == value {
            end = k;
        } else if !(v == value + 1 && profile(k + 1) == Some(value)) {
            break;
        }
        k += 1;
    }
    end
}

/// The gap: the longest goal-coloured run on a level row at shoulder height.
fn find_gap(
    img: &ClassifiedImage,
    cand: &mut GoalCandidate,
    colour: ColourClass,
    ctx: &ViewContext,
    p: &GoalParams,
) {
    let centre = (ctx.camera.centre.x_px, ctx.camera.centre.y_px);
    let angle = ctx.horizon_angle();
    let e = cand.level_extent;
    let is_goal = is_goal_colour(colour);
    let distance = cand.camera.distance_cm;
    let height = e[3] - e[1];
    // Gap scan: a level row at the shoulder height above the goal's bottom (from the foot's
    // distance when the top is cut off, since then the visible height is not the goal's).
    let y = if cand.distance_from_ground && distance > 0.0 {
        (e[3] - p.gap_scan_height_cm * ctx.camera.focal_px / distance).max(e[1] + 0.5)
    } else {
        e[3] - height * (p.gap_scan_height_cm / p.height_cm).clamp(0.0, 1.0)
    };
    let (x0, x1) = (e[0].floor(), e[2].ceil());
    // Runs as (start, its row, end, its row), level frame: an end whose sample was moved into
    // the image is reported where it was seen.
    let mut best: Option<(f64, f64, f64, f64)> = None;
    let mut run_start: Option<(f64, f64)> = None;
    let mut last_goal = (f64::NEG_INFINITY, y);
    let mut x = x0;
    let (w, h) = (img.width() as f64, img.height() as f64);
    while x <= x1 {
        // Where the scan row leaves the image (a goal at the top edge under a tilted horizon),
        // look down the level column to the first row inside it, above the goal's bottom.
        let mut yy = y;
        let mut q = rotate_about((x + 0.5, yy), centre, -angle);
        while (q.0 < 0.0 || q.1 < 0.0 || q.0 >= w || q.1 >= h) && yy + 1.0 < e[3] {
            yy += 1.0;
            q = rotate_about((x + 0.5, yy), centre, -angle);
        }
        let goal_at = |q: Point| img.get_at(q.0, q.1).is_some_and(&is_goal);
        // A sample moved into the image lies on its outermost rows, which vignetting and the
        // shared chroma of a cut-off pixel pair leave unclassified now and then: the next row
        // in counts too.
        let seen_at = if goal_at(q) {
            Some(yy)
        } else {
            let below = yy + 1.0;
            (yy > y && below < e[3] && goal_at(rotate_about((x + 0.5, below), centre, -angle)))
                .then_some(below)
        };
        if let Some(row) = seen_at {
            if run_start.is_none() || x - last_goal.0 > f64::from(p.gap_hole_px) + 1.0 {
                run_start = Some((x, row));
            }
            last_goal = (x, row);
            if let Some((s, s_row)) = run_start
                && best.is_none_or(|(a, _, b, _)| last_goal.0 + 1.0 - s > b - a)
            {
                best = Some((s, s_row, last_goal.0 + 1.0, row));
            }
        }
        x += 1.0;
    }
    cand.gap_scan = Some((
        rotate_about((e[0], y), centre, -angle),
        rotate_about((e[2], y), centre, -angle),
    ));
    if let Some((a, a_row, b, b_row)) = best {
        let left = rotate_about((a, a_row), centre, -angle);
        let right = rotate_about((b, b_row), centre, -angle);
        let (ref_left, ref_right) = if p.skew_correction {
            (
                unskew(ctx, p, left, distance),
                unskew(ctx, p, right, distance),
            )
        } else {
            (left, right)
        };
        let mid = (
            (ref_left.0 + ref_right.0) / 2.0,
            (ref_left.1 + ref_right.1) / 2.0,
        );
        cand.gap = Some(Gap {
            left,
            right,
            width_px: b - a,
            camera: ctx.camera_relative(mid, distance),
            left_bearing_rad: ctx.camera_angles(ref_left).0,
            right_bearing_rad: ctx.camera_angles(ref_right).0,
        });
    }
}

impl GoalResult {
    /// Drawing primitives: candidate boxes, post points and lines, the gap and its scan, labels.
    #[must_use]
    pub fn primitives(&self) -> Vec<Primitive> {
        let mut out = Vec::new();
        for (i, c) in self.candidates.iter().enumerate() {
            let owner = super::draw::owner::goal(c.colour, i);
            out.push(Primitive::Box {
                owner: owner.clone(),
                colour: c.colour.code(),
                bounds: c.bounds,
            });
            if !c.post_points.is_empty() {
                out.push(Primitive::ScanPoints {
                    owner: owner.clone(),
                    points: c.post_points.clone(),
                });
            }
            for post in &c.posts {
                out.push(Primitive::Line {
                    owner: owner.clone(),
                    role: LineRole::Post,
                    from: post.top,
                    to: post.bottom,
                });
            }
            if let Some((a, b)) = c.gap_scan {
                out.push(Primitive::Line {
                    owner: owner.clone(),
                    role: LineRole::Scan,
                    from: a,
                    to: b,
                });
            }
            if let Some(gap) = &c.gap {
                out.push(Primitive::Line {
                    owner: owner.clone(),
                    role: LineRole::Gap,
                    from: gap.left,
                    to: gap.right,
                });
            }
            if c.accepted {
                out.push(Primitive::Label {
                    owner,
                    at: (f64::from(c.bounds[0]), f64::from(c.bounds[1]) - 2.0),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blobs::Connectivity;
    use crate::geometry::{Ers7Dimensions, PinholeCamera};
    use crate::sensors::SensorReadings;

    fn ctx() -> ViewContext {
        let readings = SensorReadings {
            head_pan_rad: Some(0.0),
            head_tilt_rad: Some(-0.1),
            neck_tilt_rad: Some(0.0),
            ..SensorReadings::default()
        };
        ViewContext::from_sensors(PinholeCamera::ers7(), &readings, &Ers7Dimensions::ERS7)
    }

    /// Green below row `bottom`, white above; a goal box of `colour` from x0..x1 and y0..bottom;
    /// a red goalkeeper box covering `keeper` columns from y `keeper_top` to the bottom.
    fn scene(
        x0: usize,
        x1: usize,
        y0: usize,
        bottom: usize,
        keeper: Option<(usize, usize, usize)>,
    ) -> ClassifiedImage {
        let (w, h) = (208, 160);
        let mut codes = vec![ColourClass::White.code(); w * h];
        for y in 0..h {
            for x in 0..w {
                let c = &mut codes[y * w + x];
                if y >= bottom {
                    *c = ColourClass::Green.code();
                } else if (x0..x1).contains(&x) && y >= y0 {
                    *c = ColourClass::Yellow.code();
                }
                if let Some((k0, k1, top)) = keeper
                    && (k0..k1).contains(&x)
                    && y >= top
                    && y < bottom + 4
                {
                    *c = ColourClass::Red.code();
                }
            }
        }
        ClassifiedImage::from_codes(w, h, codes).expect("size")
    }

    #[test]
    fn a_goal_split_by_a_keeper_is_one_goal_with_posts_and_the_larger_gap() {
        let ctx = ctx();
        // Put the goal's bottom where the ground 230 cm ahead appears, its top 25 px higher.
        let pose = ctx.pose.expect("pose");
        let foot = pose
            .image_from_field(&crate::geometry::Point::new(191.9 * 30.0 / 25.0, 0.0, 0.0))
            .expect("in view");
        let bottom = foot.y_px.round() as usize;
        let mut img = scene(40, 150, bottom - 25, bottom, Some((70, 90, bottom - 35)));
        // A noisy UYVY pixel pair on the gap scan's row (12.5 px above the bottom) leaves two
        // pixels unclassified: the gap goes on across them.
        for x in [120, 121] {
            img.codes_mut()[(bottom - 13) * 208 + x] = ColourClass::Unclassified.code();
        }
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_goals(&img, &blobs, &ctx, &GoalParams::default(), &[]);
        let goals: Vec<_> = res.goals().collect();
        assert_eq!(goals.len(), 1, "{:#?}", res.candidates);
        let g = goals[0];
        assert_eq!(g.colour, ColourClass::Yellow);
        assert_eq!(g.blobs.len(), 2, "keeper split merged");
        assert!(!g.cut_off.any() && !g.distance_is_max);
        // Distance from height: 25 px → 191.9·30/25 ≈ 230 cm at the image centre; these posts
        // stand 55–64 px off the axis, where 25 px subtend about 5% less (a real goal there
        // would look taller), so the drawn rectangle reads a little farther.
        let d = g.camera.distance_cm;
        assert!(d > 230.0 && d < 250.0, "{d}");
        assert_eq!(g.posts.len(), 2, "{:?}", g.rejected_posts);
        let left = g
            .posts
            .iter()
            .find(|p| p.side == PostSide::Left)
            .expect("left");
        assert!((left.top.0 - 40.0).abs() < 1.0 && (left.bottom.0 - 40.0).abs() < 1.0);
        let right = g
            .posts
            .iter()
            .find(|p| p.side == PostSide::Right)
            .expect("right");
        assert!((right.top.0 - 150.0).abs() < 1.0);
        // Seen from in front: no side wall's outer face.
        assert!(g.posts.iter().all(|p| p.side_wall_px.is_none()));
        let gap = g.gap.as_ref().expect("gap");
        assert!(
            (gap.left.0 - 90.0).abs() < 1.5 && (gap.right.0 - 150.0).abs() < 1.5,
            "{gap:?}"
        );
        assert!(gap.left_bearing_rad > gap.right_bearing_rad);
        assert!(!res.primitives().is_empty());
    }

    #[test]
    fn a_side_wall_seen_from_outside_puts_the_post_on_its_front_corner() {
        // Standing beside a box goal: the left side wall's outer face shows from its back corner
        // (x = 40, the outline) to its front corner (x = 48). The front is nearer, so the wall's
        // foot descends towards it and its top rises; beyond it the back wall, farther away,
        // ends two rows higher, with the carpet inside the mouth below it.
        let ctx = ctx();
        let pose = ctx.pose.expect("pose");
        let foot = pose
            .image_from_field(&crate::geometry::Point::new(191.9 * 30.0 / 25.0, 0.0, 0.0))
            .expect("in view");
        let bottom = foot.y_px.round() as usize;
        let top = bottom - 25;
        let (w, h) = (208, 160);
        let extent = |x: usize| match x {
            40..=41 => Some((top + 1, bottom - 2)),
            42..=44 => Some((top + 1, bottom - 1)),
            45..=47 => Some((top, bottom)),
            48..=150 => Some((top + 2, bottom - 2)),
            _ => None,
        };
        let codes = (0..w * h)
            .map(|k| {
                let (x, y) = (k % w, k / w);
                match extent(x) {
                    Some((t, b)) if (t..b).contains(&y) => ColourClass::Yellow.code(),
                    Some((_, b)) if y >= b => ColourClass::Green.code(),
                    None if y >= bottom - 2 => ColourClass::Green.code(),
                    _ => ColourClass::White.code(),
                }
            })
            .collect();
        let img = ClassifiedImage::from_codes(w, h, codes).expect("size");
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let p = GoalParams::default();
        let res = recognise_goals(&img, &blobs, &ctx, &p, &[]);
        let g = res.goals().next().expect("goal");
        let left = g
            .posts
            .iter()
            .find(|q| q.side == PostSide::Left)
            .expect("left post");
        // The post's centre is half a wall outside the corner.
        let inset = p.post_inset_cm * ctx.camera.focal_px / g.camera.distance_cm;
        let wall = left.side_wall_px.expect("side wall seen");
        assert!((wall - 8.0).abs() < 0.5, "{wall}");
        for x in [left.top.0, left.bottom.0] {
            assert!((x - (48.0 - inset)).abs() < 0.5, "{left:?}");
        }
        // The right side is seen from in front: its post stays on the outline.
        let right = g
            .posts
            .iter()
            .find(|q| q.side == PostSide::Right)
            .expect("right post");
        assert!(right.side_wall_px.is_none() && (right.top.0 - 151.0).abs() < 1.5);
        // Without the front-corner search the left post is the back corner's.
        let off = GoalParams {
            post_front_corner: false,
            ..p
        };
        let res = recognise_goals(&img, &blobs, &ctx, &off, &[]);
        let g = res.goals().next().expect("goal");
        let left = g
            .posts
            .iter()
            .find(|q| q.side == PostSide::Left)
            .expect("left");
        assert!(left.side_wall_px.is_none() && (left.top.0 - (40.0 + inset)).abs() < 0.5);
    }

    #[test]
    fn a_goal_cut_at_the_top_is_measured_at_its_foot() {
        let ctx = ctx();
        let img = scene(0, 60, 0, 90, None);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_goals(&img, &blobs, &ctx, &GoalParams::default(), &[]);
        let g = res.goals().next().expect("goal");
        assert!(g.cut_off.left && g.cut_off.top && !g.cut_off.right && !g.cut_off.bottom);
        // The top is cut but the foot is in view: the distance is the foot's on the ground.
        assert!(g.distance_from_ground && !g.distance_is_max);
        let foot = ctx.distance_to_plane((30.0, 90.0), 0.0).expect("foot");
        assert!((g.camera.distance_cm - foot).abs() < 5.0, "{foot}");
        assert_eq!(g.posts.len(), 1);
        assert_eq!(g.posts[0].side, PostSide::Right);
    }

    #[test]
    fn a_goal_cut_at_the_bottom_has_a_maximum_distance() {
        let img = scene(50, 150, 130, 160, None);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_goals(&img, &blobs, &ctx(), &GoalParams::default(), &[]);
        let g = &res.candidates[0];
        assert!(g.cut_off.bottom && !g.cut_off.top);
        assert!(g.distance_is_max && !g.distance_from_ground);
    }

    #[test]
    fn level_scans_find_the_edge_to_a_fraction_of_a_pixel_under_a_tilted_horizon() {
        // Yellow columns 40..60; level rows at 0.1 rad cross the edges between pixel samples.
        let (w, h) = (208, 160);
        let codes = (0..w * h)
            .map(|k| {
                if (40..60).contains(&(k % w)) {
                    ColourClass::Yellow.code()
                } else {
                    ColourClass::Green.code()
                }
            })
            .collect();
        let img = ClassifiedImage::from_codes(w, h, codes).expect("size");
        let is_goal = is_goal_colour(ColourClass::Yellow);
        let (centre, angle) = ((104.0, 80.0), 0.1);
        for k in 0..20 {
            let y = 60.0 + 1.37 * f64::from(k);
            // The edges' level x at this row (the level frame turns image columns into slants).
            let level = |x: f64| rotate_about((x, 70.0), centre, angle);
            let (l0, r0) = (level(30.0).0 - 10.0, level(70.0).0 + 10.0);
            for (from, to, edge) in [(l0, 110.0, 40.0), (r0, 20.0, 60.0)] {
                let x = scan_level_row(&img, &is_goal, y, from, to, centre, angle).expect("edge");
                let q = rotate_about((x, y), centre, -angle);
                assert!((q.0 - edge).abs() < 0.05, "row {y}: {q:?} vs x = {edge}");
            }
        }
    }

    #[test]
    fn cut_off_uses_two_of_three_points_per_side() {
        let c = detect_cut_off(
            [10.0, 10.0, 50.0, 50.0],
            (104.0, 80.0),
            0.0,
            208.0,
            160.0,
            1.5,
        );
        assert!(!c.any());
        let c = detect_cut_off(
            [-5.0, 10.0, 50.0, 159.5],
            (104.0, 80.0),
            0.0,
            208.0,
            160.0,
            1.5,
        );
        assert!(c.left && c.bottom && !c.top && !c.right);
    }

    #[test]
    fn a_small_tile_of_goal_colour_in_the_sky_is_not_searched_for_posts() {
        // A 9 × 9-pixel yellow tile high above the horizon (a coloured-pattern marker's): its
        // other tests already rule it out, so the post search is not run, and says so.
        let mut img = scene(0, 0, 0, 90, None);
        for y in 2..11 {
            for x in 150..159 {
                img.codes_mut()[y * 208 + x] = ColourClass::Yellow.code();
            }
        }
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let p = GoalParams::default();
        let res = recognise_goals(&img, &blobs, &ctx(), &p, &[]);
        assert_eq!(res.candidates.len(), 1);
        let c = &res.candidates[0];
        assert!(!c.accepted);
        assert!(c.confidence.total + p.post_weight.reward <= 0.0);
        assert!(c.posts.is_empty() && c.post_points.is_empty());
        assert!(
            c.rejected_posts
                .iter()
                .any(|r| r.starts_with("not searched")),
            "{:?}",
            c.rejected_posts
        );
        let posts = c.confidence.test("upright_posts").expect("posts test");
        assert_eq!(
            posts.outcome,
            crate::recognition::confidence::TestOutcome::Skipped
        );
    }

    #[test]
    fn no_goal_colour_no_candidates() {
        let img = scene(0, 0, 0, 90, None);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let res = recognise_goals(&img, &blobs, &ctx(), &GoalParams::default(), &[]);
        assert!(res.candidates.is_empty());
    }
}
