//! The gap: the longest goal-coloured run on a horizon-parallel scan at robot shoulder height.

use super::*;
use crate::classify::ClassifiedImage;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;
use crate::recognition::context::ViewContext;

/// The gap: the longest goal-coloured run on a level row at shoulder height.
pub(super) fn find_gap(
    img: &ClassifiedImage,
    cand: &mut GoalCandidate,
    colour: ColourClass,
    ctx: &ViewContext,
    p: &GoalParams,
) {
    let centre = ctx.camera.centre;
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
    // A level-frame point in the image.
    let image_at = |x: f64, y: f64| ImagePoint::new(x, y).rotated_about(centre, -angle);
    while x <= x1 {
        // Where the scan row leaves the image (a goal at the top edge under a tilted horizon),
        // look down the level column to the first row inside it, above the goal's bottom.
        let mut yy = y;
        let mut q = image_at(x + 0.5, yy);
        while (q.x_px < 0.0 || q.y_px < 0.0 || q.x_px >= w || q.y_px >= h) && yy + 1.0 < e[3] {
            yy += 1.0;
            q = image_at(x + 0.5, yy);
        }
        let goal_at = |q: ImagePoint| img.get_at(q.x_px, q.y_px).is_some_and(&is_goal);
        // A sample moved into the image lies on its outermost rows, which vignetting and the
        // shared chroma of a cut-off pixel pair leave unclassified now and then: the next row
        // in counts too.
        let seen_at = if goal_at(q) {
            Some(yy)
        } else {
            let below = yy + 1.0;
            (yy > y && below < e[3] && goal_at(image_at(x + 0.5, below))).then_some(below)
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
    cand.gap_scan = Some((image_at(e[0], y), image_at(e[2], y)));
    if let Some((a, a_row, b, b_row)) = best {
        let (left, right) = (image_at(a, a_row), image_at(b, b_row));
        let (ref_left, ref_right) = if p.skew_correction {
            (
                unskew(ctx, p, left, distance),
                unskew(ctx, p, right, distance),
            )
        } else {
            (left, right)
        };
        let mid = ref_left.midpoint(ref_right);
        cand.gap = Some(Gap {
            left,
            right,
            width_px: b - a,
            camera: ctx.camera_relative(mid, distance),
            left_bearing_rad: ctx.camera.bearing_rad(ref_left),
            right_bearing_rad: ctx.camera.bearing_rad(ref_right),
        });
    }
}
