//! Goal posts against the renderer's geometry: where each detected post line lies relative to
//! the posts' corners as the rolling shutter imaged them (each row with its own camera pose)
//! and as the reference instant sees them.

use crate::debug_setup;
use eotn::geometry::{CameraPose, Ers7Dimensions, ImagePoint, Point};
use eotn::model::truth::GroundTruth;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::sim::{FRAME_INTERVAL_S, Scenario, ScenarioKind, Simulator};

/// Where a field point appears under the rolling shutter: the row whose own pose images the
/// point on itself (fixed-point iteration from the reference pose's row).
fn rolling_image(
    scenario: &Scenario,
    t: f64,
    p: &Point<eotn::geometry::Field>,
) -> Option<ImagePoint> {
    let dims = Ers7Dimensions::ERS7;
    let camera = eotn::geometry::PinholeCamera::ers7();
    let pose_at = |tr: f64| {
        let (r, b, j) = scenario.observer_at(tr)?;
        Some(CameraPose {
            camera,
            field_from_camera: b.field_from_body(&r) * dims.body_from_camera(&j),
        })
    };
    let mut y = 80.0;
    let mut x = 0.0;
    for _ in 0..6 {
        let tr = t + (y / 160.0 - 0.5) * FRAME_INTERVAL_S;
        let q = pose_at(tr)?.image_from_field(p)?;
        x = q.x_px;
        y = q.y_px;
    }
    Some(ImagePoint::new(x, y))
}

/// Per-post detail for one scenario: `EOTN_DEBUG_SCENARIO=walk-and-pan
/// cargo run --example debug_recognition --no-default-features -- posts`. For each detected post: signed error (detected − true,
/// pixels, at mid-height) of the raw line against the rolling-shutter image of the post's front
/// centre, front outer corner and back outer corner, and of the reference line against the
/// reference-instant projection of the front centre (what `eotn eval` scores).
pub fn debug_posts() {
    let name = std::env::var("EOTN_DEBUG_SCENARIO").unwrap_or_else(|_| "walk-and-pan".into());
    let kind = ScenarioKind::from_name(&name).expect("scenario name");
    let (lut, seed, frames) = debug_setup();
    let scenario = Scenario::new(kind, seed);
    let sim = Simulator::new(scenario);
    let field = scenario.scene_at(0.0).field;
    let mut pipeline = Pipeline::new(lut, PipelineParams::default());
    for i in 0..frames {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
        };
        let t = i as f64 * FRAME_INTERVAL_S;
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        let (robot, _, _) = scenario.observer_at(t).expect("observer");
        for g in r.recognition.goals.goals() {
            let s = if g.colour == eotn::lut::ColourClass::Yellow {
                1.0
            } else {
                -1.0
            };
            let tg = truth
                .goals
                .iter()
                .find(|t| eotn::eval::goal_class(t.colour) == g.colour)
                .expect("truth goal");
            for post in &g.posts {
                let line_x = |a: ImagePoint, b: ImagePoint, y: f64| {
                    if (b.y_px - a.y_px).abs() > 1e-9 {
                        a.x_px + (b.x_px - a.x_px) * (y - a.y_px) / (b.y_px - a.y_px)
                    } else {
                        a.x_px
                    }
                };
                // Which field post is it: the one whose reference projection is nearest.
                let mid_y = (post.top.y_px + post.bottom.y_px) / 2.0;
                let (k, tp) = tg
                    .posts
                    .iter()
                    .enumerate()
                    .filter_map(|(k, tp)| Some((k, tp.image_base?, tp.image_top?)))
                    .map(|(k, b, top)| {
                        let x = line_x(top, b, mid_y);
                        (k, (x - line_x(post.top, post.bottom, mid_y)).abs())
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(k, _)| (k, tg.posts[k]))
                    .expect("a truth post");
                let y_post = tp.field_cm[1];
                let outer = y_post.signum() * (field.goal_width_cm / 2.0 + field.goal_wall_cm);
                let x0 = s * field.length_cm / 2.0;
                let x1 = s * (field.length_cm / 2.0 + field.goal_depth_cm);
                let z = field.goal_height_cm / 2.0;
                let errs: Vec<Option<f64>> = [(x0, y_post), (x0, outer), (x1, outer)]
                    .iter()
                    .map(|(x, y)| {
                        let q = rolling_image(&scenario, t, &Point::new(*x, *y, z))?;
                        Some(line_x(post.top, post.bottom, q.y_px) - q.x_px)
                    })
                    .collect();
                // Raw (rolling-shutter) errors of the raw line at the foot and top of the front
                // centre and of the back outer corner.
                let raw_ends: Vec<Option<(f64, f64)>> = [(x0, y_post), (x1, outer)]
                    .iter()
                    .map(|(x, y)| {
                        let err = |z: f64| {
                            let q = rolling_image(&scenario, t, &Point::new(*x, *y, z))?;
                            Some(
                                ((line_x(post.top, post.bottom, q.y_px) - q.x_px) * 100.0).round()
                                    / 100.0,
                            )
                        };
                        Some((err(0.0)?, err(field.goal_height_cm)?))
                    })
                    .collect();
                eprintln!(
                    "    raw (foot, top) errors: front centre {:?}, back outer {:?}",
                    raw_ends[0], raw_ends[1]
                );
                let reference = {
                    let (b, top) = (tp.image_base.expect("b"), tp.image_top.expect("t"));
                    let y = (b.y_px + top.y_px) / 2.0;
                    let x = (b.x_px + top.x_px) / 2.0;
                    line_x(post.reference_top, post.reference_bottom, y) - x
                };
                // What `eotn eval` scores: the reference line against the true foot and top.
                let ends = {
                    let (b, top) = (tp.image_base.expect("b"), tp.image_top.expect("t"));
                    let at = |q: ImagePoint| {
                        ((line_x(post.reference_top, post.reference_bottom, q.y_px) - q.x_px)
                            * 100.0)
                            .round()
                            / 100.0
                    };
                    (at(b), at(top))
                };
                // The rolling shutter's true displacement of the front centre at mid-height
                // (reference projection − rolling image) against the models' displacement of
                // the raw point: linear shear and body model.
                let ctx =
                    PipelineParams::default()
                        .recognition
                        .context_for(208, 160, f.sensors.as_ref());
                let fc = Point::new(x0, y_post, z);
                let skew = rolling_image(&scenario, t, &fc).and_then(|q| {
                    let pose = CameraPose {
                        camera: eotn::geometry::PinholeCamera::ers7(),
                        field_from_camera: {
                            let (r, b, j) = scenario.observer_at(t)?;
                            b.field_from_body(&r) * Ers7Dimensions::ERS7.body_from_camera(&j)
                        },
                    };
                    let m = pose.image_from_field(&fc)?;
                    let lin = ctx.unskew(q, false);
                    let body = ctx.unskew_at(q, g.camera.distance_cm, true);
                    Some((
                        ((m.x_px - q.x_px) * 100.0).round() / 100.0,
                        ((lin.x_px - q.x_px) * 100.0).round() / 100.0,
                        ((body.x_px - q.x_px) * 100.0).round() / 100.0,
                        q.y_px.round(),
                    ))
                });
                eprintln!("    skew at post (true, linear, body model, row) {skew:?}");
                // Camera outside the wall's outer plane (seen from the side it faces)?
                let lateral =
                    robot.y_cm.abs() > outer.abs() && robot.y_cm.signum() == outer.signum();
                let r1 = |v: Option<f64>| v.map(|v| (v * 100.0).round() / 100.0);
                eprintln!(
                    "#{i:>2} {:?} post{k} {:?} pan {:+.3} dpan {:+.4} robot ({:.0},{:.0}) outer-face {} side wall {:?} | raw vs front-centre {:?} front-outer {:?} back-outer {:?} | ref err {:+.2} (foot, top) {:?} | top-bottom dx {:+.2}",
                    g.colour,
                    post.side,
                    f.sensors.and_then(|s| s.head_pan_rad).unwrap_or(f64::NAN),
                    f.sensors
                        .and_then(|s| Some(s.head_pan_rad? - s.previous_head_pan_rad?))
                        .unwrap_or(f64::NAN),
                    robot.x_cm,
                    robot.y_cm,
                    lateral,
                    r1(post.side_wall_px),
                    r1(errs[0]),
                    r1(errs[1]),
                    r1(errs[2]),
                    reference,
                    ends,
                    post.bottom.x_px - post.top.x_px,
                );
            }
        }
    }
}

/// Level-frame picture of each accepted goal's sides: `EOTN_DEBUG_SCENARIO=beacon-tour
/// cargo run --example debug_recognition --no-default-features -- post-profiles` (`EOTN_DEBUG_FRAMES=61,64`
/// picks frames). One character per level pixel (`Y` goal colour, `g` green, `w` white, `.`
/// other); below each picture the level x of the true front-post centre and back outer corner
/// (rolling-shutter image at the goal's mid-height) and of the detected post.
pub fn debug_post_profiles() {
    use eotn::lut::ColourClass;
    let name = std::env::var("EOTN_DEBUG_SCENARIO").unwrap_or_else(|_| "beacon-tour".into());
    let kind = ScenarioKind::from_name(&name).expect("scenario name");
    let frames: Vec<u64> = std::env::var("EOTN_DEBUG_FRAMES")
        .unwrap_or_default()
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let (lut, seed, count) = debug_setup();
    let scenario = Scenario::new(kind, seed);
    let sim = Simulator::new(scenario);
    let field = scenario.scene_at(0.0).field;
    let mut pipeline = Pipeline::new(lut, PipelineParams::default());
    for i in 0..count {
        if !frames.is_empty() && !frames.contains(&i) {
            continue;
        }
        let f = sim.frame(i).expect("frame");
        let t = i as f64 * FRAME_INTERVAL_S;
        let ctx = PipelineParams::default()
            .recognition
            .context_for(208, 160, f.sensors.as_ref());
        let centre = ctx.camera.centre;
        let angle = ctx.horizon_angle();
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        let img = r.classified;
        for g in r.recognition.goals.goals() {
            let s = if g.colour == ColourClass::Yellow {
                1.0
            } else {
                -1.0
            };
            let e = g.level_extent;
            eprintln!(
                "#{i} {:?} level extent {:.1?} cut {:?} d {:.0} angle {:.3}",
                g.colour, e, g.cut_off, g.camera.distance_cm, angle
            );
            let x0 = s * field.length_cm / 2.0;
            let x1 = s * (field.length_cm / 2.0 + field.goal_depth_cm);
            let z = field.goal_height_cm / 2.0;
            let level_of = |p: &Point<eotn::geometry::Field>| {
                rolling_image(&scenario, t, p).map(|q| q.rotated_about(centre, angle).x_px)
            };
            let mut marks = Vec::new();
            for side in [1.0, -1.0] {
                let y_post = side * (field.goal_width_cm / 2.0 + field.goal_wall_cm / 2.0);
                let outer = side * (field.goal_width_cm / 2.0 + field.goal_wall_cm);
                marks.push(("front-centre", level_of(&Point::new(x0, y_post, z))));
                marks.push(("back-outer", level_of(&Point::new(x1, outer, z))));
            }
            for post in &g.posts {
                let m = post.top.midpoint(post.bottom);
                marks.push(("detected", Some(m.rotated_about(centre, angle).x_px)));
            }
            for (label, x) in &marks {
                eprintln!("    {label} {x:.2?}");
            }
            let (xa, xb) = (
                e[0].floor() as i64 - 3,
                (e[0].floor() as i64 + 40).min(e[2].ceil() as i64 + 3),
            );
            let (xa2, xb2) = ((e[2].ceil() as i64 - 40).max(xa), e[2].ceil() as i64 + 3);
            for (a, b) in [(xa, xb), (xa2, xb2)] {
                eprintln!("    columns {a}..{b}");
                for y in (e[1].floor() as i64 - 2)..=(e[3].ceil() as i64 + 2) {
                    let row: String = (a..b)
                        .map(|x| {
                            let q = ImagePoint::new(x as f64 + 0.5, y as f64 + 0.5)
                                .rotated_about(centre, -angle);
                            match img
                                .get_signed(q.x_px.floor() as i64, q.y_px.floor() as i64)
                                .and_then(ColourClass::from_code)
                            {
                                Some(c) if c == g.colour => 'Y',
                                Some(c) if c.may_be_class(g.colour) => 'y',
                                Some(ColourClass::Green) => 'g',
                                Some(ColourClass::White) => 'w',
                                None => ' ',
                                Some(_) => '.',
                            }
                        })
                        .collect();
                    eprintln!("    {y:4} {row}");
                }
            }
        }
    }
}
