//! Recognition on the renderer's scenarios, measured against their ground truth with the same
//! evaluation `eotn eval` prints. The table is learnt from labelled frames of other seeds (as
//! `eotn lut-from-labels` does), so the test frames are held back.

use eotn::eval::{EvalParams, EvalReport, FrameEval, evaluate_frame};
use eotn::lut::LookupTable;
use eotn::lut::learn::{LearnParams, TableBuilder};
use eotn::model::truth::GroundTruth;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

use crate::common::{figure, sampled};

pub(crate) const ROBOT_SCENARIOS: [ScenarioKind; 6] = [
    ScenarioKind::WalkAndPan,
    ScenarioKind::BallEdge,
    ScenarioKind::Goalkeeper,
    ScenarioKind::FastPans,
    ScenarioKind::OrangeClutter,
    ScenarioKind::BeaconTour,
];

/// A table learnt from every 10th frame of each robot scenario with seed 100.
pub(crate) fn learnt_table() -> LookupTable {
    table_learnt_from(&ROBOT_SCENARIOS)
}

/// A table learnt from every 10th frame of `kinds` with seed 100 (test frames use seed 7).
pub(crate) fn table_learnt_from(kinds: &[ScenarioKind]) -> LookupTable {
    table_learnt_every(kinds, 10)
}

/// A table learnt from every `step`-th of the first 90 frames of `kinds` with seed 100.
pub(crate) fn table_learnt_every(kinds: &[ScenarioKind], step: usize) -> LookupTable {
    let mut builder = TableBuilder::new(7).expect("7 bits");
    for &kind in kinds {
        let sim = Simulator::new(Scenario::new(kind, 100));
        for i in (0..90).step_by(step) {
            let f = sim.frame(i).expect("frame");
            builder.add_frame(&f.frame, &f.labels).expect("labels fit");
        }
    }
    builder.build(&LearnParams::default())
}

fn evaluate(
    kind: ScenarioKind,
    seed: u64,
    frames: u64,
    lut: &LookupTable,
    params: PipelineParams,
) -> EvalReport {
    let sim = Simulator::new(Scenario::new(kind, seed));
    let mut pipeline = Pipeline::new(lut.clone(), params);
    let mut evals: Vec<FrameEval> = Vec::new();
    for i in 0..frames {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            panic!("robot scenario gave an overhead frame");
        };
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        let (w, h) = (f.frame.width() as f64, f.frame.height() as f64);
        evals.push(evaluate_frame(
            i as usize,
            r.recognition,
            truth,
            w,
            h,
            &EvalParams::default(),
        ));
    }
    let report = EvalReport::from_frames(&evals);
    eprintln!(
        "{}: {}",
        kind.name(),
        serde_json::to_string(&report).expect("json")
    );
    report
}

#[test]
fn recognition_on_synthetic_scenarios() {
    // The targets are: ball found in ≥ 98% of eligible frames, ≤ 0.5% false balls with
    // off-field clutter, median distance error ≤ 4% (≤ 8% cut off), skew correction halving the
    // radius error on fast pans, goals found in ≥ 97%, posts within 2 px, gaps within 3 px.
    // The assertions hold what this code achieves today (see the README's recognition figures)
    // so that a regression fails; where a figure is below its target the README says so.
    let lut = learnt_table();
    let params = PipelineParams::default();
    let mut all = Vec::new();
    for kind in ROBOT_SCENARIOS {
        all.push((kind, evaluate(kind, 7, 90, &lut, params)));
    }
    let sum = |f: &dyn Fn(&EvalReport) -> usize| all.iter().map(|(_, r)| f(r)).sum::<usize>();
    let report = |k: ScenarioKind| &all.iter().find(|(kind, _)| *kind == k).expect("scenario").1;
    let eligible = sum(&|r| r.ball_eligible);
    let found = sum(&|r| r.ball_found);
    eprintln!("ball found {found}/{eligible}");
    assert!(eligible > 100, "scenarios must show the ball");
    assert!(
        found as f64 >= 0.98 * eligible as f64,
        "ball found {found}/{eligible}"
    );
    let clutter = report(ScenarioKind::OrangeClutter);
    assert!(
        clutter.ball_false as f64 <= 0.005 * clutter.frames as f64,
        "false balls in clutter frames {:?}",
        clutter.ball_false_frames
    );
    let false_balls = sum(&|r| r.ball_false);
    assert_eq!(false_balls, 0, "false balls in any scenario");
    // Distances come from the angle the ball subtends (its outline off the optical axis is a
    // stretched ellipse) with the rim pixels that UYVY chroma pairs leave unclassified counted
    // back: the median error is under 3% and the signed median (the bias) within ±3% on each.
    for k in [
        ScenarioKind::BallEdge,
        ScenarioKind::FastPans,
        ScenarioKind::WalkAndPan,
    ] {
        let r = report(k);
        eprintln!(
            "{}: ball distance error median {:.1}% (n = {}), signed median {:+.1}%; cut off \
             {:.1}% (n = {}), signed {:+.1}%",
            k.name(),
            100.0 * figure(r.ball_distance_error, |p| p.p50),
            r.ball_distance_error.map_or(0, |p| p.n),
            100.0 * r.ball_distance_bias.unwrap_or(f64::NAN),
            100.0 * figure(r.ball_distance_error_cut, |p| p.p50),
            r.ball_distance_error_cut.map_or(0, |p| p.n),
            100.0 * r.ball_distance_bias_cut.unwrap_or(f64::NAN),
        );
        let d = sampled(r.ball_distance_error, 10, k.name());
        assert!(d.p50 <= 0.03, "{}: {d:?}", k.name());
        assert!(
            r.ball_distance_bias.is_some_and(|b| b.abs() <= 0.03),
            "{}: bias {:?}",
            k.name(),
            r.ball_distance_bias
        );
    }
    // Few balls are cut by the image edge on seed 7 (4 on ball-edge, 6 on walk-and-pan): the
    // medians of so few say little, but none may be missing.
    for k in [ScenarioKind::BallEdge, ScenarioKind::WalkAndPan] {
        let cut = sampled(report(k).ball_distance_error_cut, 4, k.name());
        assert!(cut.p50 <= 0.04, "{}: cut balls {cut:?}", k.name());
    }
    let goals_eligible = sum(&|r| r.goals_eligible);
    let goals_found = sum(&|r| r.goals_found);
    eprintln!("goals found {goals_found}/{goals_eligible}");
    assert!(goals_eligible > 200, "scenarios must show goals");
    assert!(goals_found as f64 >= 0.97 * goals_eligible as f64);
    // The yellow box among the off-field clutter is not a goal (width and ground-at-foot tests),
    // nor is anything else in any scenario.
    assert_eq!(
        sum(&|r| r.goals_false),
        0,
        "false goals in clutter frames {:?}",
        clutter.goal_false_frames
    );
    // Beacons: every one whose bands the frame shows whole found with its colours, none false,
    // the distance from the bands' edges (the targets: median ≤ 3%, p90 ≤ 8%).
    let (eligible, found) = (sum(&|r| r.beacons_eligible), sum(&|r| r.beacons_found));
    eprintln!(
        "beacons found {found}/{eligible}, colours right {}, false {}",
        sum(&|r| r.beacons_colours_right),
        sum(&|r| r.beacons_false)
    );
    // With this table (54 frames of seed 100) the far beacon of orange-clutter in the image's
    // shaded corner (frames 28, 29, 34, 35, 2.6 m) has no sky-blue pixels to find: the
    // classification, not the recogniser, misses it (a table learnt from every third frame
    // classifies it, and `beacons.rs` finds every whole beacon with that one).
    assert!(
        eligible >= 100 && found * 100 >= eligible * 97,
        "beacons {found}/{eligible}"
    );
    assert_eq!(sum(&|r| r.beacons_colours_right), found);
    assert_eq!(sum(&|r| r.beacons_false), 0);
    // The targets (median ≤ 3%, p90 ≤ 8%) on every scenario where this coarse table
    // classifies the beacons' bands, or 2–3× what seed 7 gives where that is tighter. Seed 7
    // gave (2026-12-07, median/p90): walk-and-pan 2.9%/5.0%, fast-pans 1.4%/4.0%, beacon-tour
    // 0.6%/1.6%, orange-clutter 4.1%/11.0%. Orange-clutter's far beacon in the shaded corner
    // (2.6 m) keeps few classified pixels with this table (54 frames of seed 100), so its band
    // edges fall where the classification ends, not at the paint: its limits are 2.5× what is
    // achieved, and the targets are asserted on it, with a table that classifies it, in
    // `beacons.rs` (held-out seeds 41 and 53).
    const TARGET: [f64; 2] = [0.03, 0.08];
    for (k, [p50, p90]) in [
        (ScenarioKind::WalkAndPan, TARGET),
        (ScenarioKind::FastPans, TARGET),
        (ScenarioKind::BeaconTour, [0.015, 0.04]),
        (ScenarioKind::OrangeClutter, [0.10, 0.25]),
    ] {
        let d = sampled(report(k).beacon_distance_error, 20, k.name());
        eprintln!(
            "{}: beacon distance error median {:.1}% p90 {:.1}% (n = {})",
            k.name(),
            100.0 * d.p50,
            100.0 * d.p90,
            d.n
        );
        assert!(d.p50 <= p50 && d.p90 <= p90, "{}: {d:?}", k.name());
    }
    let keeper = report(ScenarioKind::Goalkeeper);
    let walk = report(ScenarioKind::WalkAndPan);
    let tour = report(ScenarioKind::BeaconTour);
    let keeper_posts = sampled(keeper.post_error_px, 100, "goalkeeper posts");
    assert!(
        keeper.posts_within_2px == Some(1.0) && keeper_posts.p50 <= 0.6,
        "{keeper_posts:?}"
    );
    let walk_posts = sampled(walk.post_error_px, 30, "walk-and-pan posts");
    assert!(
        walk.posts_within_2px == Some(1.0) && walk_posts.p50 <= 1.1,
        "{walk_posts:?}"
    );
    // Beside the goal (beacon tour) the outline's edge is a side wall's back corner; the posts
    // are found on the front corners (`front_corner`) but for one whose front corner is at the
    // image edge: 7 of 8.
    let tour_posts = sampled(tour.post_error_px, 8, "beacon-tour posts");
    assert!(
        tour.posts_within_2px.is_some_and(|f| f >= 0.87) && tour_posts.p50 <= 1.0,
        "{tour_posts:?}"
    );
    // Every gap's ends within 3 px of the true largest gap (or of a second one as wide within
    // 3 px), in every scenario that shows gaps.
    for k in [
        ScenarioKind::Goalkeeper,
        ScenarioKind::WalkAndPan,
        ScenarioKind::FastPans,
        ScenarioKind::BallEdge,
        ScenarioKind::BeaconTour,
    ] {
        let r = report(k);
        let gaps = sampled(r.gap_error_px, 10, k.name());
        assert!(
            r.gaps_within_3px == Some(1.0) && gaps.p50 <= 1.0,
            "{}: {gaps:?}",
            k.name()
        );
    }
    for r in [keeper, walk] {
        let d = sampled(r.goal_distance_error, 30, "goal distances");
        assert!(d.p50 <= 0.05, "{d:?}");
    }

    // Skew correction on the fast pans: the radius error with it against without it.
    let mut off = params;
    off.recognition.ball.skew_correction = false;
    let without = evaluate(ScenarioKind::FastPans, 7, 90, &lut, off);
    let with = report(ScenarioKind::FastPans);
    eprintln!(
        "fast pans: radius error median {:.3} px with skew correction, {:.3} px without; found {} vs {}",
        figure(with.ball_radius_error_px, |p| p.p50),
        figure(without.ball_radius_error_px, |p| p.p50),
        with.ball_found,
        without.ball_found
    );
    assert!(
        with.ball_found > without.ball_found,
        "correction must find more balls on fast pans"
    );
    let (raw, fixed) = skew_radius_comparison(&lut, params);
    let [raw_r, raw_c, fixed_r, fixed_c] =
        [raw.0, raw.1, fixed.0, fixed.1].map(|p| sampled(p, 20, "fast pans, same balls refitted"));
    eprintln!(
        "fast pans, same balls refitted: radius error median {:.3} px with the outline unskewed, \
         {:.3} px without (n = {}); centre error {:.2} px vs {:.2} px",
        fixed_r.p50, raw_r.p50, fixed_r.n, fixed_c.p50, raw_c.p50
    );
    assert!(fixed_c.p50 * 2.0 < raw_c.p50);

    // The vertical (tilt) part of the skew, on and off, where the head tilts while moving.
    let mut vertical = params;
    vertical.recognition.ball.vertical_skew_correction = false;
    for k in [ScenarioKind::WalkAndPan, ScenarioKind::FastPans] {
        let v = evaluate(k, 7, 90, &lut, vertical);
        let r = report(k);
        eprintln!(
            "{}: vertical skew correction off: found {}/{}, distance error median {:.4}, radius \
             error median {:.3} px; on: {}/{}, {:.4}, {:.3} px",
            k.name(),
            v.ball_found,
            v.ball_eligible,
            figure(v.ball_distance_error, |p| p.p50),
            figure(v.ball_radius_error_px, |p| p.p50),
            r.ball_found,
            r.ball_eligible,
            figure(r.ball_distance_error, |p| p.p50),
            figure(r.ball_radius_error_px, |p| p.p50)
        );
        // What the tilt's correction is for: no ball lost to it, and the balls' distances and
        // radii no worse than without it (a little slack for the pixel noise of a refit).
        assert!(r.ball_found >= v.ball_found, "{}: found", k.name());
        let (on_d, off_d) = (
            sampled(r.ball_distance_error, 10, k.name()),
            sampled(v.ball_distance_error, 10, k.name()),
        );
        assert!(
            on_d.p50 <= off_d.p50 + 0.002,
            "{}: {on_d:?} vs {off_d:?}",
            k.name()
        );
        let (on_r, off_r) = (
            sampled(r.ball_radius_error_px, 10, k.name()),
            sampled(v.ball_radius_error_px, 10, k.name()),
        );
        assert!(
            on_r.p50 <= off_r.p50 + 0.02,
            "{}: {on_r:?} vs {off_r:?}",
            k.name()
        );
    }
}

/// Radius and centre error percentiles, pixels (`None`: no ball measured).
type RadiusCentre = (
    Option<eotn::eval::Percentiles>,
    Option<eotn::eval::Percentiles>,
);

/// The skew correction on the fast pans measured on the same balls: every accepted ball's
/// outline is scanned again and fitted once as read and once moved to the reference read-out
/// time. Returns (radius error, centre error) percentiles in pixels, without and with.
fn skew_radius_comparison(
    lut: &LookupTable,
    params: PipelineParams,
) -> (RadiusCentre, RadiusCentre) {
    use eotn::recognition::fit::fit_circle_trimmed;
    use eotn::recognition::scan::edge_points;
    let b = params.recognition.ball;
    let sim = Simulator::new(Scenario::new(ScenarioKind::FastPans, 7));
    let mut pipeline = Pipeline::new(lut.clone(), params);
    let (mut raw_r, mut raw_c, mut fixed_r, mut fixed_c) = (vec![], vec![], vec![], vec![]);
    for i in 0..90 {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
        };
        let Some((tb, (tr, tc))) = truth
            .ball
            .as_ref()
            .and_then(|tb| Some((tb, (tb.image_radius_px?, tb.relative.image?))))
        else {
            continue;
        };
        if tb.visible_fraction < 0.6 {
            continue;
        }
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        let Some(ball) = &r.recognition.ball.ball else {
            continue;
        };
        let cand = &r.recognition.ball.candidates[ball.candidate];
        let ctx = params.recognition.context_for(208, 160, f.sensors.as_ref());
        let points = edge_points(
            r.classified,
            cand.bounds,
            cand.pattern,
            b.edge_margin_px,
            b.edge_run_px,
            eotn::recognition::ball::is_ball_colour,
        );
        let depth = ball.camera.distance_cm;
        let moved: Vec<_> = points
            .iter()
            .map(|p| ctx.unskew_at(*p, depth, b.vertical_skew_correction))
            .collect();
        let fit = |pts: &[eotn::geometry::ImagePoint]| {
            fit_circle_trimmed(pts, b.fit_trim_sd, b.fit_trim_min_px, b.fit_trim_max_share)
        };
        if let (Some(a), Some(c)) = (fit(&points), fit(&moved)) {
            raw_r.push((a.radius - tr).abs());
            raw_c.push((a.center_x - tc.x_px).hypot(a.center_y - tc.y_px));
            fixed_r.push((c.radius - tr).abs());
            fixed_c.push((c.center_x - tc.x_px).hypot(c.center_y - tc.y_px));
        }
    }
    let p = eotn::eval::Percentiles::of;
    ((p(&raw_r), p(&raw_c)), (p(&fixed_r), p(&fixed_c)))
}

/// The overlay draws the ball where the image shows it: on the fast pans the skew correction
/// moves the centre several pixels (to the reference read-out time), but the solid circle must
/// stay on the ball's pixels (the truth box of the pixels that show the ball), with the
/// corrected circle as a second, dashed one.
#[test]
fn drawn_ball_circle_sits_on_the_observed_ball() {
    use eotn::recognition::{CircleRole, Primitive};
    let lut = learnt_table();
    let sim = Simulator::new(Scenario::new(ScenarioKind::FastPans, 7));
    let mut pipeline = Pipeline::new(lut, PipelineParams::default());
    let (mut checked, mut apart, mut offsets) = (0, 0, Vec::new());
    for i in 0..90 {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
        };
        let Some((tb, bx)) = truth
            .ball
            .as_ref()
            .filter(|b| b.visible_fraction >= 0.95 && b.in_image_fraction >= 0.999)
            .and_then(|b| Some((b, b.image_box?)))
        else {
            continue;
        };
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        if r.recognition.ball.ball.is_none() {
            continue;
        }
        let seen = eotn::geometry::ImagePoint::new(
            (bx.min_x + bx.max_x + 1) as f64 / 2.0,
            (bx.min_y + bx.max_y + 1) as f64 / 2.0,
        );
        let circles: Vec<_> = r
            .recognition
            .ball
            .primitives()
            .into_iter()
            .filter_map(|p| match p {
                Primitive::Circle {
                    center,
                    radius,
                    role,
                    ..
                } => Some((center, radius, role)),
                _ => None,
            })
            .collect();
        let off = |c: eotn::geometry::ImagePoint| c.distance_to(&seen);
        let solid: Vec<_> = circles
            .iter()
            .filter(|c| c.2 == CircleRole::Observed)
            .collect();
        assert_eq!(solid.len(), 1, "frame {i}: one solid circle");
        // The circle fitted to the outline points as scanned, before any skew removal.
        let ball = r.recognition.ball.ball.as_ref().expect("ball");
        let cand = &r.recognition.ball.candidates[ball.candidate];
        let raw = eotn::recognition::fit::fit_circle(&cand.scanned_points).expect("raw fit");
        let c = solid[0].0;
        assert!(
            c.distance_to(&raw.center()) <= 1.0,
            "frame {i}: solid circle at {c:?}, outline as scanned fits ({:.1}, {:.1})",
            raw.center_x,
            raw.center_y
        );
        offsets.push(off(c));
        eprintln!(
            "frame {i}: solid circle {:.2} px from the ball's pixels (radius {:.1} px)",
            off(c),
            tb.image_radius_px.unwrap_or(0.0)
        );
        if let Some(dashed) = circles.iter().find(|c| c.2 == CircleRole::SkewCorrected) {
            apart += usize::from(off(dashed.0) > 3.0);
        }
        checked += 1;
    }
    eprintln!(
        "drawn circle on the ball in {checked} frames; corrected circle > 3 px away in {apart}"
    );
    assert!(checked >= 15, "{checked} frames checked");
    // Classification moves a ball's outline by a pixel or two now and then (its bright top in
    // the darkened image corners): within 1.5 px in nine frames of ten.
    let within = offsets.iter().filter(|o| **o <= 1.5).count();
    assert!(
        within * 10 >= offsets.len() * 9,
        "solid circle within 1.5 px of the ball's pixels in {within} of {} frames",
        offsets.len()
    );
    assert!(
        apart >= 5,
        "the fast pans must move the corrected centre off the ball ({apart} frames)"
    );
}

/// Writes `frames` frames of a scenario to a stream with sensors and ground truth, as `eotn sim`
/// does, and the learnt table beside it.
fn write_scenario(
    dir: &std::path::Path,
    kind: ScenarioKind,
    frames: u64,
) -> (std::path::PathBuf, std::path::PathBuf) {
    use eotn::streams::{FrameRecord, StreamInfo, StreamWriter};
    let stream = dir.join(format!("{}.mcap", kind.name()));
    let info = StreamInfo {
        source: format!("sim:{}", kind.name()),
        description: "test".into(),
    };
    let mut w = StreamWriter::create(&stream, &info).unwrap();
    let sim = Simulator::new(Scenario::new(kind, 7));
    for i in 0..frames {
        let f = sim.frame(i).unwrap();
        let mut rec = FrameRecord::new(f.time_ns, f.frame);
        rec.sensors = f.sensors;
        rec.ground_truth = Some(serde_json::to_value(&f.ground_truth).unwrap());
        w.write(&rec).unwrap();
    }
    w.finish().unwrap();
    let lut = dir.join("learnt.lut");
    learnt_table().save(&lut).unwrap();
    (stream, lut)
}

#[test]
fn detect_render_and_eval_commands_on_a_rendered_stream() {
    let dir = tempfile::tempdir().unwrap();
    let (stream, lut) = write_scenario(dir.path(), ScenarioKind::Goalkeeper, 12);
    let out = super::common::eotn(&[
        "detect".as_ref(),
        stream.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "--json".as_ref(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 12);
    let goals = lines[0]["goals"].as_array().unwrap();
    assert_eq!(goals.len(), 1, "{}", lines[0]);
    assert_eq!(goals[0]["colour"], "yellow");
    assert!(goals[0]["posts"].as_array().is_some_and(|p| !p.is_empty()));
    assert!(goals[0]["gap"].is_object());
    assert!(
        goals[0]["body_distance_cm"].is_number(),
        "streams carry joint readings"
    );
    assert!(lines[0]["ball"].is_null());

    let render_dir = dir.path().join("render");
    let out = super::common::eotn(&[
        "render".as_ref(),
        stream.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "-o".as_ref(),
        render_dir.as_os_str(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = image::open(render_dir.join("goalkeeper_000000.png")).unwrap();
    assert_eq!((png.width(), png.height()), (208 * 3, 160 * 3));

    // Evaluation and calibration on a robot walking towards the goal (about 4 m away) and the
    // goalkeeper frames (1.6 m): a size → distance fit needs a spread of distances.
    let (walk, _) = write_scenario(dir.path(), ScenarioKind::WalkAndPan, 60);
    let calibrated = dir.path().join("calibrated.json");
    let plots = dir.path().join("plots");
    let out = super::common::eotn(&[
        "eval".as_ref(),
        walk.as_os_str(),
        stream.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "--json".as_ref(),
        "--calibrate-goals".as_ref(),
        calibrated.as_os_str(),
        "--plots".as_ref(),
        plots.as_os_str(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["report"]["frames"], 72);
    assert!(
        report["report"]["ball_found"]
            .as_u64()
            .is_some_and(|n| n >= 5),
        "{report}"
    );
    // Beacons against the truth (walk-and-pan shows them; seed 7's 60 frames: every whole one
    // found, none false), within the targets: median ≤ 3%, p90 ≤ 8%.
    let r = &report["report"];
    let (eligible, found) = (
        r["beacons_eligible"].as_u64().unwrap(),
        r["beacons_found"].as_u64().unwrap(),
    );
    assert!(eligible >= 20 && found == eligible, "{r}");
    assert_eq!(r["beacons_colours_right"], found, "{r}");
    assert_eq!(r["beacons_false"], 0, "{r}");
    let beacon_median = r["beacon_distance_error"]["p50"].as_f64().unwrap();
    let beacon_p90 = r["beacon_distance_error"]["p90"].as_f64().unwrap();
    eprintln!(
        "eval on walk-and-pan: beacon distance error median {:.1}% p90 {:.1}%",
        100.0 * beacon_median,
        100.0 * beacon_p90
    );
    assert!(beacon_median <= 0.03 && beacon_p90 <= 0.08, "{r}");
    assert!(
        r["beacon_distance_error"]["n"].as_u64().unwrap() >= 20,
        "{r}"
    );
    // The text shows the same; a stream without beacons has no percentiles ("—"), not 0%.
    let text = |streams: &[&std::path::Path]| {
        let mut args: Vec<&std::ffi::OsStr> = vec!["eval".as_ref()];
        args.extend(streams.iter().map(|s| s.as_os_str()));
        args.extend(["--lut".as_ref(), lut.as_os_str()]);
        let out = super::common::eotn(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let both = text(&[&walk, &stream]);
    assert!(
        both.contains(&format!(
            "beacons found          {found}/{eligible} = 100.0%"
        )) && both.contains(&format!(
            "beacon distance error  median {:.1}%",
            100.0 * beacon_median
        )),
        "{both}"
    );
    let keeper = text(&[&stream]);
    assert!(
        keeper.contains("beacons found          0/0 = —")
            && keeper.contains("beacon distance error  median — p90 — (n=0)"),
        "{keeper}"
    );
    let fitted = report["goal_calibration"].as_array().unwrap();
    assert!(
        fitted
            .iter()
            .all(|v| v.as_f64().is_some_and(f64::is_finite))
    );
    let params: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&calibrated).unwrap()).unwrap();
    assert_eq!(
        params["goals"]["distance_multiplier"], fitted[0],
        "the written parameters hold the fit"
    );

    // The charts: every one a 720×480 PNG; the distance charts show their data points in the
    // series colours, the calibration plot its samples and the fitted curve.
    let count = |img: &image::RgbImage, c: [u8; 3]| img.pixels().filter(|p| p.0 == c).count();
    for name in [
        "ball_distance.png",
        "goal_distance.png",
        "ball_distance_error.png",
        "goal_distance_error.png",
        "ball_detection.png",
        "goal_detection.png",
        "post_error.png",
    ] {
        let img = image::open(plots.join(name)).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (720, 480), "{name}");
        let dark = img.pixels().filter(|p| p.0.iter().all(|v| *v < 60)).count();
        assert!(
            dark > 500,
            "{name}: axes and text drawn ({dark} dark pixels)"
        );
    }
    let ball = image::open(plots.join("ball_distance.png"))
        .unwrap()
        .to_rgb8();
    assert!(
        count(&ball, [235, 120, 20]) >= 25 * 5,
        "ball points and legend"
    );
    let goal = image::open(plots.join("goal_distance.png"))
        .unwrap()
        .to_rgb8();
    assert!(count(&goal, [210, 170, 0]) >= 25 * 3, "yellow goal points");
    let calibration = image::open(calibrated.with_extension("png"))
        .unwrap()
        .to_rgb8();
    assert!(count(&calibration, [30, 140, 220]) >= 25 * 3, "samples");
    assert!(count(&calibration, [200, 30, 30]) >= 100, "fitted curve");
    assert_eq!(
        report["plots"].as_array().map(Vec::len),
        Some(7),
        "{report}"
    );

    // A frame without truth is refused clearly, not a panic.
    let bad = dir.path().join("garbage.mcap");
    std::fs::write(&bad, b"not an mcap file").unwrap();
    let out = super::common::eotn(&[
        "eval".as_ref(),
        bad.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("garbage.mcap"));
}
