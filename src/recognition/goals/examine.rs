//! One goal candidate examined: its distance from the height it subtends (or its foot on the
//! ground), and the confidence tests.

use super::*;
use crate::blobs::BlobSet;
use crate::classify::ClassifiedImage;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;
use crate::recognition::confidence::{Confidence, TestName, TestWeight};
use crate::recognition::context::{Relative, ViewContext};
use crate::recognition::scan::{CutOff, scan_rotated_rect};

/// What the level frame shows of one candidate.
struct LevelShape {
    /// Sides cut off.
    cut: CutOff,
    /// The pixels' extent in the level frame, pixels.
    e_all: [f64; 4],
    /// The height the distance comes from (off-axis corrected, both posts' for a whole goal),
    /// pixels.
    height_px: f64,
    /// The middle of the foot, image pixels.
    bottom_mid: ImagePoint,
    /// The middle of the top, image pixels.
    top_mid: ImagePoint,
}

pub(super) fn examine(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    g: &Group,
    colour: ColourClass,
    ctx: &ViewContext,
    p: &GoalParams,
) -> GoalCandidate {
    let shape = level_shape(img, blobs, g, colour, ctx, p);
    let (distance, from_ground, from_ir) = goal_distance(ctx, p, &shape);
    let (cut, e_all, height_px) = (shape.cut, shape.e_all, shape.height_px);
    let (centre, angle) = (ctx.camera.centre, ctx.horizon_angle());
    let mut mid = ImagePoint::new((e_all[0] + e_all[2]) / 2.0, (e_all[1] + e_all[3]) / 2.0)
        .rotated_about(centre, -angle);
    if p.skew_correction {
        mid = unskew(ctx, p, mid, distance);
    }
    let camera = ctx.camera_relative(mid, distance);
    let body = ctx.body_relative(mid, distance);
    let confidence = goal_tests(img, g, ctx, p, &shape, distance, body.as_ref());
    GoalCandidate {
        colour,
        bounds: g.all.bounds(),
        pixels: g.all.pixels,
        basic_bounds: g.basic.bounds(),
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

/// Cut-off from the rotated box (its corners reach the edge when the goal does); extent and
/// height from the pixels themselves.
fn level_shape(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    g: &Group,
    colour: ColourClass,
    ctx: &ViewContext,
    p: &GoalParams,
) -> LevelShape {
    let (w, h) = (img.width() as f64, img.height() as f64);
    let centre = ctx.camera.centre;
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
            ImagePoint::new(x, top).rotated_about(centre, -angle),
            ImagePoint::new(x, bottom).rotated_about(centre, -angle),
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
    let bottom_mid =
        ImagePoint::new((e_all[0] + e_all[2]) / 2.0, e_all[3]).rotated_about(centre, -angle);
    let top_mid =
        ImagePoint::new((e_all[0] + e_all[2]) / 2.0, e_all[1]).rotated_about(centre, -angle);
    LevelShape {
        cut,
        e_all,
        height_px,
        bottom_mid,
        top_mid,
    }
}

/// The camera distance (cm) from the height; from the foot on the ground when the top is cut;
/// from the infra-red when close. Also whether the ground or the infra-red gave it.
fn goal_distance(ctx: &ViewContext, p: &GoalParams, shape: &LevelShape) -> (f64, bool, bool) {
    let (cut, height_px, bottom_mid) = (shape.cut, shape.height_px, shape.bottom_mid);
    let mut distance = p.distance_multiplier / height_px.max(1.0) + p.distance_offset_cm;
    // Top cut off, bottom in view: the foot on the ground (through the camera pose) gives the
    // distance; the height would only give a maximum.
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
    (distance, from_ground, from_ir)
}

/// Every confidence test of one candidate.
fn goal_tests(
    img: &ClassifiedImage,
    g: &Group,
    ctx: &ViewContext,
    p: &GoalParams,
    shape: &LevelShape,
    distance: f64,
    body: Option<&Relative>,
) -> Confidence {
    let (w, h) = (img.width() as f64, img.height() as f64);
    let mut confidence = Confidence::default();
    confidence.range_test(
        TestName::Pixels,
        f64::from(g.all.pixels),
        [f64::from(p.min_candidate_pixels), f64::INFINITY],
        TestWeight::new(p.size_bonus, 1.0),
    );
    let area = f64::from(g.all.maxx - g.all.minx + 1) * f64::from(g.all.maxy - g.all.miny + 1);
    let fills = area >= p.fills_image_fraction * w * h;
    confidence.range_test(
        TestName::PixelRatio,
        f64::from(g.all.pixels) / area,
        p.pixel_ratio,
        p.pixel_ratio_weight,
    );
    if fills {
        confidence.skipped(TestName::CutSides, [0.0, p.max_cut_sides]);
        confidence.skipped(TestName::GreenBelow, p.green_below);
        confidence.skipped(TestName::BottomHeightCm, p.bottom_height_cm);
        confidence.skipped(TestName::ElevationRad, p.elevation_rad);
    } else {
        placement_tests(&mut confidence, img, ctx, p, shape, distance, body);
    }
    confidence
}

/// The tests of a candidate that does not fill the image: cut sides, green below and at the
/// foot, the foot's height, real width, the two distances' agreement and the elevation.
fn placement_tests(
    confidence: &mut Confidence,
    img: &ClassifiedImage,
    ctx: &ViewContext,
    p: &GoalParams,
    shape: &LevelShape,
    distance: f64,
    body: Option<&Relative>,
) {
    let cut = shape.cut;
    // A sliver cut off on three or four sides that does not fill the image shows too
    // little of itself to be identified.
    let cut_sides = [cut.left, cut.right, cut.top, cut.bottom]
        .iter()
        .filter(|c| **c)
        .count();
    confidence.range_test(
        TestName::CutSides,
        cut_sides as f64,
        [0.0, p.max_cut_sides],
        TestWeight::new(0.0, p.cut_sides_penalty),
    );
    ground_tests(confidence, img, ctx, p, shape);
    distance_tests(confidence, ctx, p, shape, distance, body);
}

/// Green (or a white line) in a band below the candidate, and in a thinner band at its foot.
fn ground_tests(
    confidence: &mut Confidence,
    img: &ClassifiedImage,
    ctx: &ViewContext,
    p: &GoalParams,
    shape: &LevelShape,
) {
    let (cut, e_all, height_px, bottom_mid) =
        (shape.cut, shape.e_all, shape.height_px, shape.bottom_mid);
    let angle = ctx.horizon_angle();
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
            TestName::GreenBelow,
            r,
            p.green_below,
            TestWeight::new(p.green_below_bonus, p.green_below_penalty),
        ),
        None => confidence.skipped(TestName::GreenBelow, p.green_below),
    }
    // With its top cut off, a yellow or sky-blue band standing on white is a beacon's lower band
    // on its white base (its pink band above the image), which white alone below would pass
    // as ground: a goal's foot has carpet below it beyond the goal line.
    match below.ratio(|c| c == ColourClass::Green.code()) {
        Some(r) if cut.top && !cut.bottom => confidence.range_test(
            TestName::GreenBelowCut,
            r,
            p.green_below_cut,
            TestWeight::new(0.0, p.green_below_cut_penalty),
        ),
        _ => confidence.skipped(TestName::GreenBelowCut, p.green_below_cut),
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
            TestName::GroundAtFoot,
            r,
            p.ground_at_foot,
            p.ground_at_foot_weight,
        ),
        _ => confidence.skipped(TestName::GroundAtFoot, p.ground_at_foot),
    }
}

/// The foot's height above the ground at `distance` (cm), the real width, the size distance
/// against the foot's ground distance, and the elevation.
fn distance_tests(
    confidence: &mut Confidence,
    ctx: &ViewContext,
    p: &GoalParams,
    shape: &LevelShape,
    distance: f64,
    body: Option<&Relative>,
) {
    let (cut, e_all, bottom_mid) = (shape.cut, shape.e_all, shape.bottom_mid);
    if cut.bottom {
        confidence.skipped(TestName::BottomHeightCm, p.bottom_height_cm);
    } else {
        match ctx.height_above_ground(bottom_mid, distance) {
            Some(z) => confidence.range_test(
                TestName::BottomHeightCm,
                z,
                p.bottom_height_cm,
                p.bottom_height_weight,
            ),
            None => confidence.skipped(TestName::BottomHeightCm, p.bottom_height_cm),
        }
    }
    // Bottom cut off, top in view: the height gives only a maximum distance, which would let
    // anything narrow pass as wide. The top, were it a goal's, lies on the plane of the goal's
    // height: that distance (through the camera pose) sizes it. A beacon's upper band with its
    // lower band below the image (its top 40 cm up, not 30) comes out a few centimetres wide.
    let width_distance = if cut.bottom && !cut.top {
        ctx.distance_to_plane(shape.top_mid, p.height_cm)
            .filter(|d| d.is_finite() && *d > 0.0)
            .map_or(distance, |d| d.min(distance))
    } else {
        distance
    };
    if cut.left || cut.right {
        confidence.skipped(TestName::ApparentWidthCm, p.apparent_width_cm);
    } else {
        confidence.range_test(
            TestName::ApparentWidthCm,
            (e_all[2] - e_all[0]) * width_distance / ctx.camera.focal_px,
            p.apparent_width_cm,
            p.apparent_width_weight,
        );
    }
    let foot = ctx.distance_to_plane(bottom_mid, 0.0);
    match foot {
        Some(f) if !cut.bottom && !cut.top && f > 0.0 => confidence.range_test(
            TestName::DistanceAgreement,
            distance / f,
            p.distance_agreement,
            p.distance_agreement_weight,
        ),
        _ => confidence.skipped(TestName::DistanceAgreement, p.distance_agreement),
    }
    match body {
        Some(b) => confidence.range_test(
            TestName::ElevationRad,
            b.elevation_rad,
            p.elevation_rad,
            p.elevation_weight,
        ),
        None => confidence.skipped(TestName::ElevationRad, p.elevation_rad),
    }
}

/// The tallest run of goal colour along level columns within `band` pixels inside one side of
/// the level extent `e`: the post on that side as (level x, top y, bottom y), pixels.
pub(super) fn side_height(
    img: &ClassifiedImage,
    is_goal: &dyn Fn(u8) -> bool,
    e: [f64; 4],
    left: bool,
    band: f64,
    centre: ImagePoint,
    angle: f64,
) -> Option<(f64, f64, f64)> {
    let columns = band.ceil() as usize;
    let rows = (e[3] - e[1]).ceil() as usize + 2;
    let mut best: Option<(f64, f64, f64)> = None;
    let back = (-angle).sin_cos();
    for k in 0..columns {
        let x = if left {
            e[0] + 0.5 + k as f64
        } else {
            e[2] - 0.5 - k as f64
        };
        let (mut top, mut bottom) = (None, None);
        for i in 0..rows {
            let y = e[1] - 1.0 + i as f64;
            let q = ImagePoint::new(x, y + 0.5).rotated_by(centre, back);
            if img.get_at(q.x_px, q.y_px).is_some_and(is_goal) {
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
pub(super) fn equivalent_height(
    ctx: &ViewContext,
    top: ImagePoint,
    bottom: ImagePoint,
) -> Option<f64> {
    let (a, b) = (
        ctx.camera.unit_ray(top).coords,
        ctx.camera.unit_ray(bottom).coords,
    );
    let phi = a.dot(&b).clamp(-1.0, 1.0).acos();
    let mid = top.midpoint(bottom);
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
