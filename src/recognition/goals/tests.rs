//! Goal recognition on small synthetic scenes.

use super::*;
use crate::blobs::Connectivity;
use crate::geometry::{Ers7Dimensions, PinholeCamera};
use crate::recognition::confidence::TestName;
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
    // Posts, gap and scan points keep their `[x, y]` JSON form.
    let json = serde_json::to_value(g).expect("json");
    let top = &json["posts"][0]["top"];
    assert_eq!(top[0].as_f64(), Some(g.posts[0].top.x_px), "{top}");
    assert_eq!(top[1].as_f64(), Some(g.posts[0].top.y_px), "{top}");
    assert!(json["gap"]["left"].is_array() && json["post_points"][0].is_array());
    assert!(json["gap_scan"][1].is_array(), "{}", json["gap_scan"]);
    // (A whole candidate does not read back: an open test range is written as null.)
    let back: Post = serde_json::from_value(json["posts"][0].clone()).expect("read back");
    assert_eq!(back, g.posts[0]);
    let left = g
        .posts
        .iter()
        .find(|p| p.side == PostSide::Left)
        .expect("left");
    assert!((left.top.x_px - 40.0).abs() < 1.0 && (left.bottom.x_px - 40.0).abs() < 1.0);
    let right = g
        .posts
        .iter()
        .find(|p| p.side == PostSide::Right)
        .expect("right");
    assert!((right.top.x_px - 150.0).abs() < 1.0);
    // Seen from in front: no side wall's outer face.
    assert!(g.posts.iter().all(|p| p.side_wall_px.is_none()));
    let gap = g.gap.as_ref().expect("gap");
    assert!(
        (gap.left.x_px - 90.0).abs() < 1.5 && (gap.right.x_px - 150.0).abs() < 1.5,
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
    for x in [left.top.x_px, left.bottom.x_px] {
        assert!((x - (48.0 - inset)).abs() < 0.5, "{left:?}");
    }
    // The right side is seen from in front: its post stays on the outline.
    let right = g
        .posts
        .iter()
        .find(|q| q.side == PostSide::Right)
        .expect("right post");
    assert!(right.side_wall_px.is_none() && (right.top.x_px - 151.0).abs() < 1.5);
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
    assert!(left.side_wall_px.is_none() && (left.top.x_px - (40.0 + inset)).abs() < 0.5);
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
    let foot = ctx
        .distance_to_plane(ImagePoint::new(30.0, 90.0), 0.0)
        .expect("foot");
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
    let (centre, angle) = (ImagePoint::new(104.0, 80.0), 0.1);
    for k in 0..20 {
        let y = 60.0 + 1.37 * f64::from(k);
        // The edges' level x at this row (the level frame turns image columns into slants).
        let level = |x: f64| ImagePoint::new(x, 70.0).rotated_about(centre, angle);
        let (l0, r0) = (level(30.0).x_px - 10.0, level(70.0).x_px + 10.0);
        for (from, to, edge) in [(l0, 110.0, 40.0), (r0, 20.0, 60.0)] {
            let x = scan_level_row(&img, &is_goal, y, from, to, centre, angle).expect("edge");
            let q = ImagePoint::new(x, y).rotated_about(centre, -angle);
            assert!((q.x_px - edge).abs() < 0.05, "row {y}: {q:?} vs x = {edge}");
        }
    }
}

#[test]
fn cut_off_uses_two_of_three_points_per_side() {
    let c = detect_cut_off(
        [10.0, 10.0, 50.0, 50.0],
        ImagePoint::new(104.0, 80.0),
        0.0,
        208.0,
        160.0,
        1.5,
    );
    assert!(!c.any());
    let c = detect_cut_off(
        [-5.0, 10.0, 50.0, 159.5],
        ImagePoint::new(104.0, 80.0),
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
            .any(|r| matches!(r, PostRejection::NotSearched { .. })),
        "{:?}",
        c.rejected_posts
    );
    let posts = c
        .confidence
        .test(TestName::UprightPosts)
        .expect("posts test");
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
