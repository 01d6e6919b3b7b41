//! Posts: least-squares line fits on horizon-parallel scans along the uncut sides.

use super::*;
use crate::classify::ClassifiedImage;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;
use crate::recognition::context::ViewContext;
use crate::recognition::fit::{LineFit, fit_line};

/// Scans from outside a level x position inward along a level row until a goal-coloured pixel;
/// returns the level x where the scan line enters that pixel, pixels. Steps of one pixel find
/// the pixel; bisection between the last sample outside and the first inside then finds the
/// crossing of its border to 1/64 pixel. (Returning a whole step's sample instead puts the edge
/// up to a pixel inward when the horizon is tilted, where samples fall anywhere in a pixel.)
pub(super) fn scan_level_row(
    img: &ClassifiedImage,
    is_goal: &impl Fn(u8) -> bool,
    y: f64,
    from: f64,
    to: f64,
    centre: ImagePoint,
    angle: f64,
) -> Option<f64> {
    let dir = if to >= from { 1.0 } else { -1.0 };
    let steps = (to - from).abs().ceil() as usize;
    let back = (-angle).sin_cos();
    let goal_at = |x: f64| {
        let q = ImagePoint::new(x, y).rotated_by(centre, back);
        img.get_at(q.x_px, q.y_px).is_some_and(is_goal)
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
pub(super) fn unskew(
    ctx: &ViewContext,
    p: &GoalParams,
    q: ImagePoint,
    distance_cm: f64,
) -> ImagePoint {
    if p.pose_skew_model {
        ctx.unskew_at(q, distance_cm, true)
    } else {
        ctx.unskew(q, false)
    }
}

/// Posts: level scans inward along each uncut side, a line fit through their edges, accepted
/// when straight and upright.
pub(super) fn find_posts(
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
                level_pts.push(ImagePoint::new(x, y));
            }
        }
        cand.post_points
            .extend(level_pts.iter().map(|q| q.rotated_about(centre, -angle)));
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
                cand.post_points.push(c.at.rotated_about(centre, -angle));
            }
        }
        // The scans find the outline's outer edge; the post's centre is half a wall inside it,
        // or half a wall outside the front corner of a side wall seen from outside.
        let image_pts: Vec<ImagePoint> = level_pts
            .iter()
            .map(|q| {
                let shift = side_wall.map_or(inset_px, |w| w.offset_at(q.y_px) - inset_px);
                ImagePoint::new(q.x_px + dir * shift, q.y_px).rotated_about(centre, -angle)
            })
            .collect();
        let wall_px = side_wall.map(|w| w.foot.offset);
        match post_from_points(image_pts, side, wall_px, e, ctx, p, distance) {
            Ok(post) => cand.posts.push(post),
            Err(why) => cand.rejected_posts.push(why),
        }
    }
}

/// Whether a post's line fit is straight enough.
fn good_fit(f: &LineFit, p: &GoalParams) -> bool {
    f.residual_variance <= p.post_max_residual_variance
        && (f.r_squared >= p.post_min_r_squared || f.steep)
}

/// A line through `pts`; a stray point (a robot's leg or a shadow on one scan row) is dropped,
/// farthest from the line first, while the fit fails and enough points remain. Returns the
/// points kept and the fit.
fn fit_dropping_outliers(
    mut pts: Vec<ImagePoint>,
    p: &GoalParams,
) -> (Vec<ImagePoint>, Option<LineFit>) {
    let mut fit = fit_line(&pts);
    let mut dropped = 0;
    while let Some(f) = fit
        && !good_fit(&f, p)
        && dropped < p.post_max_outliers
        && pts.len() > 5
    {
        let off = |q: &ImagePoint| {
            if f.steep {
                (q.x_px - f.at(q.y_px).x_px).abs()
            } else {
                (q.y_px - f.at(q.x_px).y_px).abs()
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
    (pts, fit)
}

/// The post on `side` from its edge points (image pixels, already moved to the post's centre
/// line), or why there is none: no line, a poor fit, or a lean.
fn post_from_points(
    image_pts: Vec<ImagePoint>,
    side: PostSide,
    side_wall_px: Option<f64>,
    e: [f64; 4],
    ctx: &ViewContext,
    p: &GoalParams,
    distance: f64,
) -> Result<Post, PostRejection> {
    let centre = ctx.camera.centre;
    let angle = ctx.horizon_angle();
    let (pts, fit) = fit_dropping_outliers(image_pts, p);
    let Some(fit) = fit else {
        return Err(PostRejection::NoLine {
            side,
            points: pts.len(),
        });
    };
    if !good_fit(&fit, p) || pts.len() < 3 {
        return Err(PostRejection::PoorFit {
            side,
            r_squared: fit.r_squared,
            residual_variance_px2: fit.residual_variance,
            points: pts.len(),
        });
    }
    let top_level = pts[0].rotated_about(centre, angle);
    // The line's point at the image row of a level-frame point.
    let line_at = |level: ImagePoint| fit.at(level.rotated_about(centre, -angle).y_px);
    let top = if fit.steep {
        line_at(ImagePoint::new(top_level.x_px, e[1]))
    } else {
        pts[0]
    };
    let bottom = if fit.steep {
        line_at(ImagePoint::new(top_level.x_px, e[3]))
    } else {
        pts[pts.len() - 1]
    };
    let (lt, lb) = (
        top.rotated_about(centre, angle),
        bottom.rotated_about(centre, angle),
    );
    let lean = (lb.x_px - lt.x_px).abs().atan2((lb.y_px - lt.y_px).abs());
    if lean.is_nan() || lean > p.post_max_lean_rad {
        return Err(PostRejection::Leans {
            side,
            lean_deg: lean.to_degrees(),
        });
    }
    let (reference_top, reference_bottom) = if p.skew_correction {
        (
            unskew(ctx, p, top, distance),
            unskew(ctx, p, bottom, distance),
        )
    } else {
        (top, bottom)
    };
    let mid = reference_top.midpoint(reference_bottom);
    Ok(Post {
        side,
        top,
        bottom,
        fit,
        reference_top,
        reference_bottom,
        camera: ctx.camera_relative(mid, distance),
        body: ctx.body_relative(mid, distance),
        side_wall_px,
    })
}
