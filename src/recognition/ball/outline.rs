//! The outline stage: candidate groups (orange blobs joined with touching soft colours), which
//! sides are cut off or hidden, the edge scans chosen by them, and the rolling shutter's shear
//! removed from every outline point.

use super::{BallParams, is_ball_colour};
use crate::blobs::{Blob, BlobSet};
use crate::classify::ClassifiedImage;
use crate::frame::PixelBox;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;
use crate::recognition::context::ViewContext;
use crate::recognition::scan::{CutOff, EdgeScanPattern, edge_points_with_mixed};

/// One candidate's outline: where the scans found it and where it is at the reference row's
/// read-out time, with the box's own estimate beside it.
#[derive(Debug, Clone)]
pub(super) struct Outline {
    /// The group's box, inclusive pixels.
    pub bounds: PixelBox,
    /// Sides cut off by the image edge or hidden.
    pub cut: CutOff,
    /// The edge-scan pattern the cut sides chose.
    pub pattern: EdgeScanPattern,
    /// Outline points after skew removal (when on), pixels.
    pub points: Vec<ImagePoint>,
    /// Outline points where the scans found them, pixels.
    pub scanned_points: Vec<ImagePoint>,
    /// Each scanned point's image row (its read-out time).
    pub rows: Vec<f64>,
    /// Centre from the box alone, pixels.
    pub box_centre: ImagePoint,
    /// Radius from the box alone, pixels.
    pub box_radius: f64,
    /// How far the skew removal moved the box's centre, pixels.
    pub box_shift: ImagePoint,
    /// Box width and height, pixels.
    pub width: f64,
    /// Box height, pixels.
    pub height: f64,
    /// Distance the box's size implies, centimetres: the depth the skew removal assumes.
    pub depth_cm: f64,
}

impl Outline {
    /// Scans `group`'s outline and removes the shear.
    pub fn scan(
        img: &ClassifiedImage,
        group: &Blob,
        ctx: &ViewContext,
        params: &BallParams,
    ) -> Self {
        let bounds = group.bounds();
        let cut = cut_off(
            img,
            bounds,
            params.border_cut_min_share,
            params.hidden_min_chord_share,
            params.hidden_chord_min_radius_px,
        );
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
        let (box_centre, box_radius) = box_estimate(bounds, cut);
        // Move every outline point to the read-out time of the reference row, the instant the
        // sensor readings describe: this removes the shear and puts the ball where the camera
        // pose says it is. The body model needs a depth: the distance the box's size implies.
        let depth_cm = ctx.camera.focal_px * params.diameter_cm / (2.0 * box_radius.max(0.5));
        let scanned_points = points.clone();
        let rows: Vec<f64> = points.iter().map(|p| p.y_px).collect();
        let mut box_shift = ImagePoint::default();
        if params.skew_correction {
            for p in &mut points {
                *p = unskew_point(ctx, params, *p, depth_cm);
            }
            let c = unskew_point(ctx, params, box_centre, depth_cm);
            box_shift = c - box_centre;
        }
        Self {
            bounds,
            cut,
            pattern,
            points,
            scanned_points,
            rows,
            box_centre,
            box_radius,
            box_shift,
            width: f64::from(bounds.width_px()),
            height: f64::from(bounds.height_px()),
            depth_cm,
        }
    }

    /// The box's extent along the sides not cut off, pixels: the diameter a fit must match (0
    /// when both directions are cut).
    pub fn uncut_extent(&self) -> f64 {
        let cut = self.cut;
        match (cut.left || cut.right, cut.top || cut.bottom) {
            (false, false) => self.width.max(self.height),
            (true, false) => self.height,
            (false, true) => self.width,
            (true, true) => 0.0,
        }
    }

    /// `p` moved to the reference row's read-out time at this outline's depth.
    pub fn unskew(&self, ctx: &ViewContext, params: &BallParams, p: ImagePoint) -> ImagePoint {
        unskew_point(ctx, params, p, self.depth_cm)
    }
}

fn is_robot_colour(code: u8) -> bool {
    matches!(
        ColourClass::from_code(code),
        Some(ColourClass::White | ColourClass::Red | ColourClass::DarkBlue | ColourClass::Black)
    )
}

/// Candidate groups: each orange blob of at least `min_pixels` joined with the soft-orange blobs
/// near it, then (when [`BallParams::soft_candidates`]) soft blobs left over on their own;
/// largest first. The orange core alone must reach `min_pixels`: a speck of orange on a red
/// shirt is not made a candidate by the shirt's soft colours joining it.
pub(super) fn candidate_groups(blobs: &BlobSet, params: &BallParams) -> Vec<(Blob, u32)> {
    let soft: Vec<&Blob> = blobs
        .active()
        .filter(|b| b.colour != ColourClass::Orange.code() && is_ball_colour(b.colour))
        .collect();
    let mut used = vec![false; soft.len()];
    let mut groups: Vec<(Blob, u32)> = Vec::new();
    let cores = blobs
        .of_class(ColourClass::Orange)
        .filter(|o| o.pixels >= params.min_pixels);
    for orange in cores {
        let mut joined = *orange;
        for (i, s) in soft.iter().enumerate() {
            if !used[i] && joined.bounds().is_near(&s.bounds(), params.soft_join_px) {
                joined = joined.merged_with(s);
                used[i] = true;
            }
        }
        groups.push((joined, orange.pixels));
    }
    if params.soft_candidates {
        for (i, s) in soft.iter().enumerate() {
            if !used[i] {
                groups.push((**s, 0));
            }
        }
    }
    groups.retain(|(b, _)| b.pixels >= params.min_pixels);
    groups.sort_by_key(|g| std::cmp::Reverse(g.0.pixels));
    groups.truncate(params.max_candidates);
    groups
}

/// Which sides of the box `b` are cut by the image border or hidden: cut when at least `border_share` of
/// the box's own line along the border is ball-coloured; hidden when a robot's white, red, dark
/// blue or black borders most of that side *and* at least `hidden_share` of the box's line
/// there is ball-coloured (for a box at least `2 × hidden_min_radius_px` long there; shorter
/// sides need one ball pixel). A ball cut by an edge or an occluder meets it along a long straight chord; a round side
/// only touches its box over a few pixels, whatever it lies against (a ball on a white line or
/// its white stand on the B-Human recording is round there, not hidden).
fn cut_off(
    img: &ClassifiedImage,
    b: PixelBox,
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
        i64::from(b.min_x),
        i64::from(b.min_y),
        i64::from(b.max_x),
        i64::from(b.max_y),
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
        left: side(b.min_x == 0, rows(minx), rows(minx - 1)),
        right: side(b.max_x + 1 >= w, rows(maxx), rows(maxx + 1)),
        top: side(b.min_y == 0, columns(miny), columns(miny - 1)),
        bottom: side(b.max_y + 1 >= h, columns(maxy), columns(maxy + 1)),
    }
}

/// Centre and radius from the box alone: the uncut extent is the diameter; a cut side puts the
/// centre a radius from the visible opposite side.
fn box_estimate(b: PixelBox, cut: CutOff) -> (ImagePoint, f64) {
    let w = f64::from(b.width_px());
    let h = f64::from(b.height_px());
    let horizontal_cut = cut.left || cut.right;
    let vertical_cut = cut.top || cut.bottom;
    let r = match (horizontal_cut, vertical_cut) {
        (false, false) => (w + h) / 4.0,
        (true, false) => h / 2.0,
        (false, true) => w / 2.0,
        (true, true) => w.max(h) / 2.0,
    };
    let cx = match (cut.left, cut.right) {
        (true, false) => f64::from(b.max_x + 1) - r,
        (false, true) => f64::from(b.min_x) + r,
        _ => f64::from(b.min_x) + w / 2.0,
    };
    let cy = match (cut.top, cut.bottom) {
        (true, false) => f64::from(b.max_y + 1) - r,
        (false, true) => f64::from(b.min_y) + r,
        _ => f64::from(b.min_y) + h / 2.0,
    };
    (ImagePoint::new(cx, cy), r)
}

/// One outline point moved to the reference row's read-out time: through the body model when
/// asked and possible, else by the linear shear; `depth_cm` is the point's distance estimate.
fn unskew_point(
    ctx: &ViewContext,
    params: &BallParams,
    p: ImagePoint,
    depth_cm: f64,
) -> ImagePoint {
    if params.pose_skew_model && ctx.motion.is_some() && ctx.pose.is_some() {
        ctx.unskew_at(p, depth_cm, params.vertical_skew_correction)
    } else {
        ctx.unskew(p, params.vertical_skew_correction)
    }
}
