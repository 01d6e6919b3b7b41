//! Motion in the rolling shutter, measured on the renderer: the camera's skew correction on
//! close balls during fast pans (`close-pans`), and the moving-circle (constrained ellipse) fit
//! of a ball rolling across a still camera (`rolling-ball`): its image and ground velocity, and
//! whether it places the ball better than the plain circle.

use eotn::eval::skew::{SkewReport, compare_ball, outline_circle};
use eotn::eval::{EvalParams, EvalReport, Percentiles, evaluate_frame};

use crate::common::{figure, percentiles, sampled};
use eotn::geometry::PinholeCamera;
use eotn::lut::LookupTable;
use eotn::model::truth::GroundTruth;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::recognition::ball::is_ball_colour;
use eotn::recognition::fit::{fit_circle, fit_circle_trimmed};
use eotn::recognition::scan::{EdgeScanPattern, edge_points};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

/// A table learnt from every 10th frame of a few robot scenarios with seed 100 (the test
/// frames use seed 7).
fn learnt_table() -> LookupTable {
    crate::recognition::table_learnt_from(&[
        ScenarioKind::WalkAndPan,
        ScenarioKind::FastPans,
        ScenarioKind::BallEdge,
        ScenarioKind::ClosePans,
        ScenarioKind::RollingBall,
    ])
}

/// Radius and centre errors of the same balls fitted as read ("raw") and with the camera's skew
/// removed ("fixed"), against the outline truth and against the on-axis radius.
#[derive(Default)]
struct SkewErrors {
    raw_r: Vec<f64>,
    fixed_r: Vec<f64>,
    raw_c: Vec<f64>,
    fixed_c: Vec<f64>,
    raw_r_axis: Vec<f64>,
    fixed_r_axis: Vec<f64>,
}

impl SkewErrors {
    fn print(&self, label: &str) {
        let p = Percentiles::of;
        let (p50, p90) = (|v| figure(p(v), |p| p.p50), |v| figure(p(v), |p| p.p90));
        eprintln!(
            "{label}: n = {}; radius error vs outline truth median {:.3} px unskewed, {:.3} px as \
             read (p90 {:.2} vs {:.2}); vs on-axis radius {:.3} vs {:.3}; centre error {:.2} vs \
             {:.2} px",
            self.raw_r.len(),
            p50(&self.fixed_r),
            p50(&self.raw_r),
            p90(&self.fixed_r),
            p90(&self.raw_r),
            p50(&self.fixed_r_axis),
            p50(&self.raw_r_axis),
            p50(&self.fixed_c),
            p50(&self.raw_c),
        );
    }
}

/// Every accepted ball of the first `frames` frames of `kind` (seed 7) whose truth has ≥ 30%
/// of the disc visible: its outline scanned again and fitted once as read and once moved to the
/// reference read-out time. Split into (uncut, cut by the image side).
fn skew_comparison(
    kind: ScenarioKind,
    frames: u64,
    lut: &LookupTable,
    params: PipelineParams,
) -> (SkewErrors, SkewErrors) {
    let b = params.recognition.ball;
    let sim = Simulator::new(Scenario::new(kind, 7));
    let mut pipeline = Pipeline::new(lut.clone(), params);
    let (mut uncut, mut cut) = (SkewErrors::default(), SkewErrors::default());
    for i in 0..frames {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
        };
        let Some(tb) = truth.ball.as_ref().filter(|t| t.visible_fraction >= 0.3) else {
            continue;
        };
        let Some(axis_r) = tb.image_radius_px else {
            continue;
        };
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        let Some(ball) = &r.recognition.ball.ball else {
            continue;
        };
        let cand = &r.recognition.ball.candidates[ball.candidate];
        let Some(outline) = outline_circle(truth, &PinholeCamera::ers7(), cand.pattern) else {
            continue;
        };
        let (tc, tr) = (outline.center, outline.radius_px);
        let ctx = params.recognition.context_for(208, 160, f.sensors.as_ref());
        let points = edge_points(
            r.classified,
            cand.bounds,
            cand.pattern,
            b.edge_margin_px,
            b.edge_run_px,
            is_ball_colour,
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
            let side_cut = tb.cut_off.left || tb.cut_off.right;
            if std::env::var_os("EOTN_MOTION_DEBUG").is_some() {
                eprintln!(
                    "{} #{i}: cut {:?} pattern {:?} n {} r raw {:.2} fixed {:.2} outline {:.2} \
                     axis {:.2}; centre raw ({:.1},{:.1}) fixed ({:.1},{:.1}) truth ({:.1},{:.1}); \
                     skew/line {:.3}",
                    kind.name(),
                    tb.cut_off,
                    cand.pattern,
                    points.len(),
                    a.radius,
                    c.radius,
                    tr,
                    axis_r,
                    a.center_x,
                    a.center_y,
                    c.center_x,
                    c.center_y,
                    tc.x_px,
                    tc.y_px,
                    ctx.skew_x_per_line
                );
            }
            let e = if side_cut { &mut cut } else { &mut uncut };
            e.raw_r.push((a.radius - tr).abs());
            e.fixed_r.push((c.radius - tr).abs());
            e.raw_r_axis.push((a.radius - axis_r).abs());
            e.fixed_r_axis.push((c.radius - axis_r).abs());
            e.raw_c.push(a.center().distance_to(&tc));
            e.fixed_c.push(c.center().distance_to(&tc));
        }
    }
    (uncut, cut)
}

#[test]
fn skew_correction_on_close_balls_during_fast_pans() {
    let lut = learnt_table();
    let params = PipelineParams::default();
    let (uncut, cut) = skew_comparison(ScenarioKind::ClosePans, 150, &lut, params);
    uncut.print("close-pans, uncut balls");
    cut.print("close-pans, balls cut by the image side");
    let (fp_uncut, fp_cut) = skew_comparison(ScenarioKind::FastPans, 90, &lut, params);
    fp_uncut.print("fast-pans, uncut balls");
    fp_cut.print("fast-pans, balls cut by the image side");
    let med = |v: &[f64]| figure(Percentiles::of(v), |p| p.p50);
    let p90 = |v: &[f64]| figure(Percentiles::of(v), |p| p.p90);
    let all = |f: fn(&SkewErrors) -> &Vec<f64>| {
        let mut v = f(&uncut).clone();
        v.extend(f(&cut));
        v
    };
    let (raw, fixed) = (all(|e| &e.raw_r), all(|e| &e.fixed_r));
    eprintln!(
        "close-pans, all balls: radius error median {:.3} px unskewed vs {:.3} px as read, p90 \
         {:.2} vs {:.2} (n = {})",
        med(&fixed),
        med(&raw),
        p90(&fixed),
        p90(&raw),
        raw.len()
    );
    // The whole pipeline with the correction on and off (eval's figures: radius against the
    // on-axis size, which a close ball at the image side exceeds by up to 10% through
    // perspective).
    let mut off = params;
    off.recognition.ball.skew_correction = false;
    let [on_report, off_report] = [("on", params), ("off", off)].map(|(name, p)| {
        let r = eval_report(ScenarioKind::ClosePans, 150, &lut, p);
        eprintln!(
            "close-pans, skew correction {name}: found {}/{}, distance error median {:.4} (cut \
             {:.4}), radius error median {:.3} px",
            r.ball_found,
            r.ball_eligible,
            figure(r.ball_distance_error, |p| p.p50),
            figure(r.ball_distance_error_cut, |p| p.p50),
            figure(r.ball_radius_error_px, |p| p.p50)
        );
        r
    });
    // What the correction is for, through the whole pipeline: at least as many close balls
    // found, and their distances (from the unskewed outline) at least as good as without it.
    assert!(
        on_report.ball_eligible >= 30 && on_report.ball_found >= off_report.ball_found,
        "found {} with the correction, {} without (of {})",
        on_report.ball_found,
        off_report.ball_found,
        on_report.ball_eligible
    );
    let on_d = sampled(on_report.ball_distance_error_cut, 10, "close-pans cut, on");
    let off_d = sampled(
        off_report.ball_distance_error_cut,
        10,
        "close-pans cut, off",
    );
    assert!(
        on_d.p50 <= off_d.p50,
        "cut balls' distance error {on_d:?} on vs {off_d:?} off"
    );
    // The same comparison as `eotn eval` makes it: the whole pipeline run with and without the
    // correction on the fast-panning frames (≥ 1.5 rad/s), each run's own outline pattern.
    let mut reports = Vec::new();
    for (kind, frames) in [(ScenarioKind::ClosePans, 150), (ScenarioKind::FastPans, 90)] {
        let r = skew_report(kind, frames, &lut, params);
        for (name, e) in [
            ("all", &r.all),
            ("one side", &r.one_sided),
            ("whole", &r.whole),
        ] {
            eprintln!(
                "{} eval skew report ({} fast-panning frames), {name}: n = {}, radius error median {:.3} px with, {:.3} \
                 without (p90 {:.2} vs {:.2}); centre {:.2} vs {:.2} px",
                kind.name(),
                r.frames,
                e.radius_with_px.map_or(0, |p| p.n),
                figure(e.radius_with_px, |p| p.p50),
                figure(e.radius_without_px, |p| p.p50),
                figure(e.radius_with_px, |p| p.p90),
                figure(e.radius_without_px, |p| p.p90),
                figure(e.centre_with_px, |p| p.p50),
                figure(e.centre_without_px, |p| p.p50)
            );
        }
        reports.push(r);
    }
    // Achieved levels (see README). On the fast pans (small balls anywhere in the image) the
    // correction cuts the median radius error by more than 2 and the centre error by more
    // than 10; on the close pans (a tracked ball, large and central) it does so where one side
    // of the outline is seen, while whole outlines there are within 0.1 px either way.
    let (close, fast) = (&reports[0], &reports[1]);
    assert!(close.compared >= 30 && fast.compared >= 20);
    let n = |e: Option<Percentiles>, min: usize, what: &str| sampled(e, min, what);
    assert!(
        n(fast.all.radius_with_px, 20, "fast, with").p50 * 2.0
            <= n(fast.all.radius_without_px, 20, "fast, without").p50
    );
    assert!(
        n(fast.all.centre_with_px, 20, "fast, with").p50 * 10.0
            <= n(fast.all.centre_without_px, 20, "fast, without").p50
    );
    let one = |e: Option<Percentiles>| n(e, 10, "close, one side");
    assert!(
        one(close.one_sided.radius_with_px).p50 * 2.0 <= one(close.one_sided.radius_without_px).p50
    );
    assert!(
        one(close.one_sided.centre_with_px).p50 * 2.0 <= one(close.one_sided.centre_without_px).p50
    );
    let whole = |e: Option<Percentiles>| n(e, 20, "close, whole");
    assert!(
        whole(close.whole.radius_with_px).p50 <= whole(close.whole.radius_without_px).p50 + 0.05
    );

    assert!(uncut.raw_r.len() >= 20 && cut.raw_r.len() >= 10);
    // Achieved levels (see README). Where the skew matters to the radius — close balls cut by
    // the image side, only one side's outline seen — the correction cuts the radius error by
    // more than 4 (median) and 2 (p90), and the centre error by more than 5.
    assert!(med(&cut.fixed_r) * 4.0 <= med(&cut.raw_r));
    assert!(p90(&cut.fixed_r) * 2.0 <= p90(&cut.raw_r));
    assert!(med(&cut.fixed_c) * 5.0 <= med(&cut.raw_c));
    // On whole outlines a shear changes the fitted radius only at second order (≈ k²/8 · r,
    // 0.1–0.2 px here): less than the classified outline's own bias, so no halving there; the
    // correction must not cost more than that.
    assert!(med(&uncut.fixed_r) <= med(&uncut.raw_r) + 0.15);
    assert!(med(&fp_uncut.fixed_c) * 10.0 <= med(&fp_uncut.raw_c));
}

/// The ball's exact outline as a rolling shutter records it: for each image row, where that
/// row's ray (cast with the camera pose of the row's own read-out time, as the renderer does)
/// first and last touches the sphere, found to 1/1000 px by bisection. Only rows whose both
/// crossings are inside the image. No classification: this isolates the camera model.
fn rolling_shutter_outline(
    scenario: &Scenario,
    t_s: f64,
    ball_cm: [f64; 2],
    camera: &PinholeCamera,
) -> Vec<eotn::geometry::ImagePoint> {
    use eotn::geometry::{Camera, Ers7Dimensions, Field, ImagePoint, Transform};
    let centre = nalgebra::Vector3::new(ball_cm[0], ball_cm[1], 4.25);
    let (w, h) = (camera.width_px as f64, camera.height_px as f64);
    let mut out = Vec::new();
    for row in 0..camera.height_px {
        let y = row as f64 + 0.5;
        let readout = t_s + (y / h - 0.5) * eotn::sim::FRAME_INTERVAL_S;
        let Some((robot, body, joints)) = scenario.observer_at(readout) else {
            continue;
        };
        let pose: Transform<Field, Camera> =
            body.field_from_body(&robot) * Ers7Dimensions::ERS7.body_from_camera(&joints);
        let hits = |x: f64| {
            let ray = camera.unit_ray(ImagePoint::new(x, y)).coords;
            let dir = pose.isometry.rotation * ray;
            let oc = pose.isometry.translation.vector - centre;
            let b = oc.dot(&dir);
            b < 0.0 && b * b - (oc.dot(&oc) - 4.25 * 4.25) >= 0.0
        };
        let Some(inside) = (0..(2.0 * w) as usize)
            .map(|k| k as f64 / 2.0)
            .find(|&x| hits(x))
        else {
            continue;
        };
        // Bisect each end between a point on the ball and one off it.
        let edge = |mut on: f64, mut off: f64| {
            for _ in 0..40 {
                let mid = (on + off) / 2.0;
                if hits(mid) { on = mid } else { off = mid }
            }
            on
        };
        let (lo, hi) = (edge(inside, -1.0), edge(inside, w + 1.0));
        if lo > 0.0 && hi < w {
            out.push(ImagePoint::new(lo, y));
            out.push(ImagePoint::new(hi, y));
        }
    }
    out
}

/// The camera model on its own: exact rolling-shutter outlines of the ball on every
/// fast-panning frame of `fast-pans` and `close-pans` (whole balls inside the image), fitted as
/// recorded and after [`ViewContext::unskew_at`], against the circle of the true outline at the
/// reference read-out time. A pan is not a pure shear: the tangent's growth towards the image
/// sides makes the shift vary along a row, which scales an off-centre ball horizontally at first
/// order (by about 2·(x − cx)/d times the pan since the reference row).
#[test]
fn skew_removal_restores_exact_outlines_during_fast_pans() {
    let camera = PinholeCamera::ers7();
    let params = eotn::recognition::RecognitionParams::default();
    for (kind, frames) in [(ScenarioKind::FastPans, 90), (ScenarioKind::ClosePans, 150)] {
        let scenario = Scenario::new(kind, 7);
        let sim = Simulator::new(scenario);
        let (mut raw_r, mut fixed_r, mut raw_c, mut fixed_c) = (vec![], vec![], vec![], vec![]);
        for i in 0..frames {
            let f = sim.frame(i).expect("frame");
            let GroundTruth::Robot(truth) = &f.ground_truth else {
                continue;
            };
            let fast = f.sensors.as_ref().and_then(|s| s.pan_velocity_rad_per_s());
            let (Some(tb), true) = (truth.ball.as_ref(), fast.is_some_and(|v| v.abs() >= 1.5))
            else {
                continue;
            };
            let Some(outline) = outline_circle(truth, &camera, EdgeScanPattern::SidesToCentre)
            else {
                continue;
            };
            let recorded =
                rolling_shutter_outline(&scenario, truth.time_s, tb.relative.field_cm, &camera);
            // Whole balls only: every row of the true disc recorded with both ends inside.
            if (recorded.len() as f64) < 2.0 * (2.0 * outline.radius_px - 2.0) {
                continue;
            }
            let ctx = params.context_for(208, 160, f.sensors.as_ref());
            let depth = tb.relative.camera_distance_cm;
            let moved: Vec<_> = recorded
                .iter()
                .map(|p| ctx.unskew_at(*p, depth, true))
                .collect();
            let (Some(a), Some(b)) = (fit_circle(&recorded), fit_circle(&moved)) else {
                continue;
            };
            raw_r.push((a.radius - outline.radius_px).abs());
            fixed_r.push((b.radius - outline.radius_px).abs());
            raw_c.push(a.center().distance_to(&outline.center));
            fixed_c.push(b.center().distance_to(&outline.center));
        }
        assert!(raw_r.len() >= 15, "{}: {} balls", kind.name(), raw_r.len());
        let p = |v: &[f64]| percentiles(v, 15, kind.name());
        eprintln!(
            "{}: exact outlines of {} whole balls on fast-panning frames: radius error median \
             {:.3} px unskewed vs {:.3} px as recorded (p90 {:.3} vs {:.3}); centre {:.3} vs {:.2} px",
            kind.name(),
            raw_r.len(),
            p(&fixed_r).p50,
            p(&raw_r).p50,
            p(&fixed_r).p90,
            p(&raw_r).p90,
            p(&fixed_c).p50,
            p(&raw_c).p50,
        );
        // Achieved: the removal leaves a few hundredths of a pixel (the pan speed is taken from
        // the previous frame's readings), at least 4× less than the recorded outline's error.
        assert!(p(&fixed_r).p50 * 4.0 <= p(&raw_r).p50, "{}", kind.name());
        assert!(p(&fixed_r).p90 * 2.0 <= p(&raw_r).p90, "{}", kind.name());
        assert!(p(&fixed_c).p50 * 10.0 <= p(&raw_c).p50, "{}", kind.name());
    }
}

/// The skew report of `eotn eval` on the first `frames` frames of `kind` (seed 7): frames panning
/// at ≥ 1.5 rad/s (eval's default) recognised with `params` and again without the correction.
fn skew_report(
    kind: ScenarioKind,
    frames: u64,
    lut: &LookupTable,
    params: PipelineParams,
) -> SkewReport {
    let sim = Simulator::new(Scenario::new(kind, 7));
    let mut off = params;
    off.recognition.ball.skew_correction = false;
    let (mut with, mut without) = (
        Pipeline::new(lut.clone(), params),
        Pipeline::new(lut.clone(), off),
    );
    let camera = PinholeCamera::ers7();
    let (mut fast, mut samples) = (0, Vec::new());
    for i in 0..frames {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
        };
        let speed = f.sensors.as_ref().and_then(|s| s.pan_velocity_rad_per_s());
        if !speed.is_some_and(|v| v.abs() >= 1.5) {
            continue;
        }
        fast += 1;
        let a = with
            .process(&f.frame, f.sensors.as_ref())
            .recognition
            .clone();
        let b = &without.process(&f.frame, f.sensors.as_ref()).recognition;
        let sample = compare_ball(&a, b, truth, &camera, 2.0);
        if std::env::var_os("EOTN_MOTION_DEBUG").is_some()
            && let (Some(s), Some(x), Some(y)) = (sample, &a.ball.ball, &b.ball.ball)
        {
            let (cx, cy) = (
                &a.ball.candidates[x.candidate],
                &b.ball.candidates[y.candidate],
            );
            eprintln!(
                "{} #{i} eval: one side {} r with {:.2} ({:?}, fit {}, {}) without {:.2} ({:?}, \
                 fit {}, {}); errors {:.2} / {:.2}",
                kind.name(),
                s.one_sided,
                x.radius_px,
                cx.pattern,
                x.from_circle_fit,
                cx.fit_rejected
                    .map_or_else(|| "-".to_owned(), |r| r.to_string()),
                y.radius_px,
                cy.pattern,
                y.from_circle_fit,
                cy.fit_rejected
                    .map_or_else(|| "-".to_owned(), |r| r.to_string()),
                s.radius_error_with_px,
                s.radius_error_without_px,
            );
        }
        samples.extend(sample);
    }
    SkewReport::from_samples(fast, &samples)
}

/// The evaluation report of `frames` frames of `kind` (seed 7), as `eotn eval` gives it.
fn eval_report(
    kind: ScenarioKind,
    frames: u64,
    lut: &LookupTable,
    params: PipelineParams,
) -> EvalReport {
    let sim = Simulator::new(Scenario::new(kind, 7));
    let mut pipeline = Pipeline::new(lut.clone(), params);
    let mut evals = Vec::new();
    for i in 0..frames {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
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
    EvalReport::from_frames(&evals)
}

/// Per-ball errors on the rolling ball, for one parameter set.
#[derive(Default, Debug)]
struct MovingErrors {
    found: usize,
    centre: Vec<f64>,
    radius: Vec<f64>,
    distance: Vec<f64>,
    /// Image velocity: error of the x component, of the whole vector, relative x error.
    vx: Vec<f64>,
    v: Vec<f64>,
    vx_rel: Vec<f64>,
    /// Ground velocity: error of the component across the line of sight, of the whole vector.
    g_across: Vec<f64>,
    g: Vec<f64>,
}

impl MovingErrors {
    fn line(&self) -> String {
        let p = |v: &[f64]| Percentiles::of(v);
        let (p50, p90) = (|v| figure(p(v), |p| p.p50), |v| figure(p(v), |p| p.p90));
        format!(
            "found {}; n = {}, centre error median {:.2} px (p90 {:.2}), radius error median \
             {:.3} px, distance error median {:.2}% (p90 {:.2}%); velocity from {} balls: x \
             error median {:.0} px/s (p90 {:.0}, relative {:.1}%), vector error {:.0} px/s; \
             ground: across the view {:.0} cm/s (p90 {:.0}), vector {:.0} cm/s (p90 {:.0})",
            self.found,
            self.centre.len(),
            p50(&self.centre),
            p90(&self.centre),
            p50(&self.radius),
            100.0 * p50(&self.distance),
            100.0 * p90(&self.distance),
            self.vx.len(),
            p50(&self.vx),
            p90(&self.vx),
            100.0 * p50(&self.vx_rel),
            p50(&self.v),
            p50(&self.g_across),
            p90(&self.g_across),
            p50(&self.g),
            p90(&self.g),
        )
    }
}

/// Runs `frames` frames of `kind` (seed 7) through each parameter set and collects the errors
/// of the balls every set found (eligible: ≥ 60% visible, ≥ 6 px across, velocity truth known).
fn moving_errors(
    kind: ScenarioKind,
    frames: u64,
    lut: &LookupTable,
    sets: &[PipelineParams],
) -> (usize, Vec<MovingErrors>) {
    let sim = Simulator::new(Scenario::new(kind, 7));
    let mut pipelines: Vec<Pipeline> = sets
        .iter()
        .map(|p| Pipeline::new(lut.clone(), *p))
        .collect();
    let mut out: Vec<MovingErrors> = sets.iter().map(|_| MovingErrors::default()).collect();
    let mut eligible = 0;
    for i in 0..frames {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
        };
        let Some(tb) = truth.ball.as_ref().filter(|t| t.visible_fraction >= 0.6) else {
            continue;
        };
        let (Some(tc), Some(tr), Some(tv), Some(tg)) = (
            tb.relative.image,
            tb.image_radius_px,
            tb.image_velocity_px_s,
            tb.ground_velocity_cm_s,
        ) else {
            continue;
        };
        if 2.0 * tr < 6.0 {
            continue;
        }
        eligible += 1;
        let balls: Vec<_> = pipelines
            .iter_mut()
            .map(|p| {
                p.process(&f.frame, f.sensors.as_ref())
                    .recognition
                    .ball
                    .ball
                    .clone()
            })
            .collect();
        if balls.iter().any(Option::is_none) {
            for (e, b) in out.iter_mut().zip(&balls) {
                e.found += usize::from(b.is_some());
            }
            continue;
        }
        // Across the line of sight on the ground: perpendicular to the ball's body bearing.
        let (s, c) = tb.relative.body_bearing_rad.sin_cos();
        let across = |v: [f64; 2]| -s * v[0] + c * v[1];
        let dist = tb.relative.camera_distance_cm;
        for (e, ball) in out.iter_mut().zip(balls.iter().flatten()) {
            e.found += 1;
            e.centre
                .push((ball.center_x - tc.x_px).hypot(ball.center_y - tc.y_px));
            e.radius.push((ball.radius_px - tr).abs());
            e.distance
                .push((ball.camera.distance_cm - dist).abs() / dist);
            if let Some(v) = ball.image_velocity_px_s {
                e.vx.push((v[0] - tv[0]).abs());
                e.vx_rel.push((v[0] - tv[0]).abs() / tv[0].abs().max(1.0));
                e.v.push((v[0] - tv[0]).hypot(v[1] - tv[1]));
                let g = ball
                    .ground_velocity_cm_s
                    .expect("pose known: ground velocity");
                e.g_across.push((across(g) - across(tg)).abs());
                e.g.push((g[0] - tg[0]).hypot(g[1] - tg[1]));
                if std::env::var_os("EOTN_MOTION_DEBUG").is_some() {
                    eprintln!(
                        "{} #{i}: image velocity ({:.0}, {:.0}) px/s, truth ({:.0}, {:.0}); \
                         ground ({:.0}, {:.0}) cm/s, truth ({:.0}, {:.0}); r {tr:.1} px",
                        kind.name(),
                        v[0],
                        v[1],
                        tv[0],
                        tv[1],
                        g[0],
                        g[1],
                        tg[0],
                        tg[1]
                    );
                }
            }
        }
    }
    (eligible, out)
}

#[test]
fn ellipse_fit_measures_a_rolling_ball() {
    let lut = learnt_table();
    let plain = PipelineParams::default();
    assert!(!plain.recognition.ball.ellipse_fit, "off by default");
    let mut across = plain;
    across.recognition.ball.ellipse_fit = true;
    let mut both = across;
    both.recognition.ball.ellipse_vertical_shear = true;
    let (eligible, e) = moving_errors(ScenarioKind::RollingBall, 150, &lut, &[plain, across, both]);
    eprintln!("rolling-ball: {eligible} eligible balls");
    for (name, e) in [
        "plain circle",
        "ellipse fit",
        "ellipse fit + vertical shear",
    ]
    .iter()
    .zip(&e)
    {
        eprintln!("rolling-ball, {name}: {}", e.line());
    }
    let med = |v: &[f64]| percentiles(v, 30, "rolling-ball").p50;
    let (plain_e, fit_e) = (&e[0], &e[1]);
    assert!(eligible >= 30 && fit_e.found >= plain_e.found);
    assert!(plain_e.vx.is_empty(), "no velocity without the ellipse fit");
    assert!(
        fit_e.vx.len() * 4 >= fit_e.centre.len() * 3,
        "velocity for most balls"
    );
    // Achieved levels (see README). Counting the rim pixels that UYVY chroma pairs leave
    // unclassified back into the outline (`mixed_edge`) gives velocities for more balls (59 vs
    // 56) and a better centre, at 15.0% rather than 14.2% median relative error.
    assert!(med(&fit_e.vx_rel) <= 0.16, "{}", fit_e.line());
    assert!(
        med(&fit_e.centre) < med(&plain_e.centre),
        "{}",
        fit_e.line()
    );

    // On the camera's own motion (no ball motion) the ellipse fit should find no velocity.
    let (_, still) = moving_errors(ScenarioKind::ClosePans, 150, &lut, &[plain, across]);
    eprintln!("close-pans (still ball), plain circle: {}", still[0].line());
    eprintln!("close-pans (still ball), ellipse fit: {}", still[1].line());
    // The ball stands still there: whatever velocity the fit reports is the error, and it must
    // stay far below the rolling ball's (1–3 m/s, hundreds of px/s); the fit must not cost the
    // still balls' centres more than a fraction of a pixel.
    let v = percentiles(&still[1].v, 10, "close-pans, ellipse-fit velocities");
    let rolling = percentiles(&fit_e.vx, 30, "rolling-ball velocities x");
    assert!(v.p50 <= 60.0, "still ball's velocity median {v:?}");
    let centre = |e: &MovingErrors| percentiles(&e.centre, 30, "close-pans centres").p50;
    assert!(
        centre(&still[1]) <= centre(&still[0]) + 0.5,
        "{} / {}",
        still[1].line(),
        still[0].line()
    );
    eprintln!("rolling-ball velocity x error for scale: {rolling:?}");
}
