//! Ball and goal detail per frame of a scenario, the ball-distance bias table and the rim study.

use eotn::eval::{EvalParams, evaluate_frame};
use eotn::model::truth::GroundTruth;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

use crate::{debug_setup, learnt_table};

/// Prints what happened per frame: `EOTN_DEBUG_SCENARIO=fast-pans
/// cargo run --example debug_recognition --no-default-features -- scenario`.
pub fn debug_scenario() {
    let name = std::env::var("EOTN_DEBUG_SCENARIO").unwrap_or_else(|_| "walk-and-pan".into());
    let kind = ScenarioKind::from_name(&name).expect("scenario name");
    // EOTN_DEBUG_LUT, EOTN_DEBUG_SEED and EOTN_DEBUG_NFRAMES pick another table, seed, count.
    let (lut, seed, count) = debug_setup();
    let sim = Simulator::new(Scenario::new(kind, seed));
    let mut pipeline = Pipeline::new(lut, PipelineParams::default());
    // EOTN_DEBUG_FRAMES=19,53 also prints those frames' ball candidates in full.
    let detail: Vec<u64> = std::env::var("EOTN_DEBUG_FRAMES")
        .unwrap_or_default()
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    for i in 0..count {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
        };
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        let tb = truth.ball.as_ref().filter(|b| b.visible_pixels > 0);
        let db = r.recognition.ball.ball.as_ref();
        eprintln!(
            "#{i} pan {:?} prev {:?} | truth ball {:?} | found {:?} | cands {:?}",
            f.sensors
                .and_then(|s| s.head_pan_rad)
                .map(|v| (v * 1000.0).round() / 1000.0),
            f.sensors
                .and_then(|s| s.previous_head_pan_rad)
                .map(|v| (v * 1000.0).round() / 1000.0),
            tb.map(|b| (
                b.relative.image.map(|p| (p.x_px.round(), p.y_px.round())),
                b.image_radius_px.map(|r| (r * 10.0).round() / 10.0),
                b.relative.camera_distance_cm.round(),
                b.visible_fraction
            )),
            db.map(|b| (
                (b.center_x.round(), b.center_y.round()),
                (b.radius_px * 10.0).round() / 10.0,
                b.camera.distance_cm.round()
            )),
            r.recognition
                .ball
                .candidates
                .iter()
                .map(|c| (
                    c.bounds,
                    c.pixels,
                    (c.confidence.total * 10.0).round() / 10.0,
                    c.fit_rejected
                ))
                .collect::<Vec<_>>(),
        );
        if detail.contains(&i) {
            print_ball_detail(&r);
        }
        let fe = evaluate_frame(
            i as usize,
            r.recognition,
            truth,
            208.0,
            160.0,
            &EvalParams::default(),
        );
        eprintln!(
            "    eval goals {}/{} false {} posts {:?} gaps {:?} dist {:?}",
            fe.goals_found,
            fe.goals_eligible,
            fe.goals_false,
            fe.post_errors_px
                .iter()
                .map(|e| (e * 10.0).round() / 10.0)
                .collect::<Vec<_>>(),
            fe.gap_errors_px
                .iter()
                .map(|e| (e * 10.0).round() / 10.0)
                .collect::<Vec<_>>(),
            fe.goal_distances_cm
                .iter()
                .map(|g| (g.true_cm.round(), g.measured_cm.round(), g.height_px))
                .collect::<Vec<_>>(),
        );
        for g in &r.recognition.goals.candidates {
            eprintln!(
                "    {} cut {:?} h {:.1} tests {:?}",
                if g.accepted { "ACCEPTED" } else { "rejected" },
                g.cut_off,
                g.height_px,
                g.confidence
                    .tests
                    .iter()
                    .map(|t| (t.test.as_str(), (t.value * 100.0).round() / 100.0, t.effect))
                    .collect::<Vec<_>>()
            );
            let t = truth
                .goals
                .iter()
                .find(|t| eotn::eval::goal_class(t.colour) == g.colour);
            eprintln!(
                "    goal {:?} {:?} gap {:?} d {:.0} (truth {:?}) posts {:?} truth posts {:?}",
                g.colour,
                g.bounds,
                g.gap
                    .as_ref()
                    .map(|g| (g.left.x_px.round(), g.right.x_px.round())),
                g.camera.distance_cm,
                t.map(|t| (t.relative.camera_distance_cm.round(), t.visible_pixels)),
                g.posts
                    .iter()
                    .map(|p| (p.side, p.reference_top, p.reference_bottom))
                    .collect::<Vec<_>>(),
                t.map(|t| (
                    t.largest_gap.map(|g| (g.from_x_px, g.to_x_px + 1)),
                    t.posts
                        .iter()
                        .map(|p| (p.image_top, p.image_base))
                        .collect::<Vec<_>>()
                ))
            );
        }
    }
}

/// Prints every ball candidate's tests, fit and the class codes around it (one character per
/// pixel: `O` orange, `o` soft orange, `g` green, `w` white, `r` red, `.` other).
fn print_ball_detail(r: &eotn::pipeline::FrameResult<'_>) {
    use eotn::lut::ColourClass;
    let img = r.classified;
    for c in &r.recognition.ball.candidates {
        eprintln!(
            "    cand {:?} px {} orange {} cut {:?} pattern {:?} centre ({:.1},{:.1}) r {:.2} fit {:?} rejected {:?}",
            c.bounds,
            c.pixels,
            c.orange_pixels,
            c.cut_off,
            c.pattern,
            c.center.x_px,
            c.center.y_px,
            c.radius_px,
            c.fit,
            c.fit_rejected
        );
        for t in &c.confidence.tests {
            eprintln!(
                "      {:<20} {:>8.3} in {:?} -> {:+.1}",
                t.test.as_str(),
                t.value,
                t.range,
                t.effect
            );
        }
        eprintln!(
            "      edge points {:?}",
            c.edge_points
                .iter()
                .map(|p| (
                    (p.x_px * 10.0).round() / 10.0,
                    (p.y_px * 10.0).round() / 10.0
                ))
                .collect::<Vec<_>>()
        );
        let [x0, y0, x1, y1] = c.bounds.to_array();
        for y in y0.saturating_sub(3)..=(y1 + 3).min(img.height() as u32 - 1) {
            let row: String = (x0.saturating_sub(4)..=(x1 + 4).min(img.width() as u32 - 1))
                .map(|x| {
                    let code = img.get(x as usize, y as usize).unwrap_or(0);
                    match ColourClass::from_code(code) {
                        Some(ColourClass::Orange) => 'O',
                        Some(ColourClass::Green) => 'g',
                        Some(ColourClass::White) => 'w',
                        Some(ColourClass::Red) => 'r',
                        Some(k) if k.may_be_class(ColourClass::Orange) => 'o',
                        _ => '.',
                    }
                })
                .collect();
            eprintln!("      {y:>3} {row}");
        }
    }
}

/// Prints one CSV line per correctly matched ball (prefix `BIAS,`) for studying the distance
/// error's sign: `EOTN_BIAS_FRAMES=180
/// cargo run --example debug_recognition --no-default-features -- bias`. Columns: scenario, seed, frame, true distance, true radius, true centre x/y,
/// cut, measured distance, radius, centre x/y, from circle fit, the original's d × 8.5 /
/// diameter, blob box width/height, truth box width/height, ground-plane distance.
pub fn ball_distance_bias() {
    let frames: u64 = std::env::var("EOTN_BIAS_FRAMES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(90);
    let seeds: Vec<u64> = std::env::var("EOTN_BIAS_SEEDS")
        .unwrap_or_else(|_| "7".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let lut = learnt_table();
    let params = PipelineParams::default();
    let b = params.recognition.ball;
    for kind in [
        ScenarioKind::WalkAndPan,
        ScenarioKind::BallEdge,
        ScenarioKind::FastPans,
        ScenarioKind::OrangeClutter,
    ] {
        for &seed in &seeds {
            let sim = Simulator::new(Scenario::new(kind, seed));
            let mut pipeline = Pipeline::new(lut.clone(), params);
            for i in 0..frames {
                let f = sim.frame(i).expect("frame");
                let GroundTruth::Robot(truth) = &f.ground_truth else {
                    continue;
                };
                let r = pipeline.process(&f.frame, f.sensors.as_ref());
                let fe = evaluate_frame(
                    i as usize,
                    r.recognition,
                    truth,
                    208.0,
                    160.0,
                    &EvalParams::default(),
                );
                let (Some(tb), Some(ball)) = (truth.ball.as_ref(), &r.recognition.ball.ball) else {
                    continue;
                };
                if !fe.ball_eligible || fe.ball_distance_error.is_none() {
                    continue;
                }
                let cand = &r.recognition.ball.candidates[ball.candidate];
                let img = tb.relative.image.expect("matched ball projects");
                let [x0, y0, x1, y1] = cand.bounds.to_array();
                let (tw, th) = tb.image_box.map_or((0, 0), |bx| {
                    (bx.max_x + 1 - bx.min_x, bx.max_y + 1 - bx.min_y)
                });
                let ctx = params.recognition.context_for(208, 160, f.sensors.as_ref());
                let plane = ctx
                    .pose
                    .and_then(|p| {
                        let ip = eotn::geometry::ImagePoint::new(ball.center_x, ball.center_y);
                        Some(p.point_on_plane(ip, 4.25)?.distance_to(&p.position()))
                    })
                    .unwrap_or(f64::NAN);
                eprintln!(
                    "BIAS,{},{seed},{i},{:.2},{:.3},{:.2},{:.2},{},{:.2},{:.3},{:.2},{:.2},{},{:.2},{},{},{tw},{th},{plane:.2}",
                    kind.name(),
                    tb.relative.camera_distance_cm,
                    tb.image_radius_px.unwrap_or(0.0),
                    img.x_px,
                    img.y_px,
                    u8::from(fe.ball_cut),
                    ball.camera.distance_cm,
                    ball.radius_px,
                    ball.center_x,
                    ball.center_y,
                    u8::from(ball.from_circle_fit),
                    191.9 * b.diameter_cm / (2.0 * ball.radius_px),
                    x1 + 1 - x0,
                    y1 + 1 - y0,
                );
            }
        }
    }
}

/// Which of the ball's true pixels classification loses, and to what, by where they are on the
/// ball (top/bottom rim, left/right rim with the UYVY chroma partner on or off the ball,
/// inside): how the half-pixel rim loss behind the long ball distances was found.
/// `cargo run --example debug_recognition --no-default-features -- rim`.
pub fn ball_rim_study() {
    use eotn::lut::ColourClass;
    let lut = learnt_table();
    let params = PipelineParams::default();
    let orange = ColourClass::Orange.code();
    let mut tally: std::collections::BTreeMap<String, [usize; 2]> = Default::default();
    for kind in [
        ScenarioKind::WalkAndPan,
        ScenarioKind::BallEdge,
        ScenarioKind::FastPans,
    ] {
        let sim = Simulator::new(Scenario::new(kind, 7));
        let mut pipeline = Pipeline::new(lut.clone(), params);
        for i in 0..90 {
            let f = sim.frame(i).expect("frame");
            let GroundTruth::Robot(truth) = &f.ground_truth else {
                continue;
            };
            let r = pipeline.process(&f.frame, f.sensors.as_ref());
            let Some(tb) = truth.ball.as_ref().filter(|b| b.visible_fraction > 0.9) else {
                continue;
            };
            let Some(bx) = tb.image_box else { continue };
            let img = r.classified;
            let w = 208usize;
            let lab = |x: i64, y: i64| -> bool {
                x >= 0
                    && y >= 0
                    && (x as usize) < w
                    && (y as usize) < 160
                    && f.labels[y as usize * w + x as usize] == orange
            };
            for y in bx.min_y..=bx.max_y {
                for x in bx.min_x..=bx.max_x {
                    let (xi, yi) = (x as i64, y as i64);
                    if !lab(xi, yi) {
                        continue;
                    }
                    let region = if !lab(xi, yi - 1) {
                        "top"
                    } else if !lab(xi, yi + 1) {
                        "bottom"
                    } else if !lab(xi - 1, yi) || !lab(xi + 1, yi) {
                        // Left/right rim: is the pair partner also ball?
                        let partner = xi ^ 1;
                        if lab(partner, yi) {
                            "side-pair-ball"
                        } else {
                            "side-pair-mixed"
                        }
                    } else {
                        "inside"
                    };
                    let c = img.get(x as usize, y as usize).unwrap_or(0);
                    let is_ball = eotn::recognition::ball::is_ball_colour(c);
                    let e = tally
                        .entry(format!("{} {region}", kind.name()))
                        .or_default();
                    e[usize::from(is_ball)] += 1;
                    if !is_ball {
                        *tally
                            .entry(format!("  lost as {:?}", ColourClass::from_code(c)))
                            .or_default()
                            .get_mut(0)
                            .expect("slot") += 1;
                    }
                }
            }
        }
    }
    for (k, [lost, kept]) in tally {
        eprintln!(
            "{k:40} lost {lost:5} kept {kept:5} ({:.0}% lost)",
            100.0 * lost as f64 / (lost + kept).max(1) as f64
        );
    }
}
