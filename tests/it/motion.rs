//! Motion in the rolling shutter, measured on the renderer: the camera's skew correction on
//! close balls during fast pans (`close-pans`), and the moving-circle (constrained ellipse) fit
//! of a ball rolling across a still camera (`rolling-ball`): its image and ground velocity, and
//! whether it places the ball better than the plain circle.

use eotn::eval::{EvalParams, EvalReport, Percentiles, evaluate_frame};
use eotn::geometry::{Camera, Ers7Dimensions, Field, PinholeCamera, Point, Transform};
use eotn::lut::LookupTable;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::recognition::ball::is_ball_colour;
use eotn::recognition::fit::{fit_circle, fit_circle_trimmed};
use eotn::recognition::scan::{EdgeScanPattern, edge_points};
use eotn::sim::truth::{BallTruth, GroundTruth, RobotViewTruth};
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

/// The circle a perfect outline of the ball fits at mid-readout, scanned the way the detector
/// scanned it: the sphere's silhouette (the tangent circle of the viewing cone) projected with
/// the mid-readout camera pose, crossed with every pixel row (or column) inside the image, and
/// only the crossings the edge-scan `pattern` takes (e.g. the leftmost per row for a ball cut at
/// the right). Off the optical axis a sphere projects as an ellipse stretched away from the
/// image centre (over 10% at the image side for a close ball), so which part of it is scanned
/// changes the fitted radius; `image_radius_px` (the on-axis size, what distance needs) does
/// not include that. Returns (centre, radius), pixels.
fn outline_truth(
    truth: &RobotViewTruth,
    ball: &BallTruth,
    pattern: EdgeScanPattern,
) -> Option<((f64, f64), f64)> {
    let camera = PinholeCamera::ers7();
    let field_from_camera: Transform<Field, Camera> = truth.body.field_from_body(&truth.robot_pose)
        * Ers7Dimensions::ERS7.body_from_camera(&truth.joints);
    let [x, y] = ball.relative.field_cm;
    let c = (field_from_camera.inverse() * Point::<Field>::new(x, y, 4.25)).coords;
    let (r, d) = (4.25, c.coords.norm());
    if d <= r {
        return None;
    }
    let axis = c.coords / d;
    let centre = c.coords * (1.0 - r * r / (d * d));
    let radius = r * (1.0 - r * r / (d * d)).sqrt();
    let u = axis.cross(&nalgebra::Vector3::z()).normalize();
    let v = axis.cross(&u);
    let outline: Vec<(f64, f64)> = (0..720)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 720.0;
            let p = centre + radius * (a.cos() * u + a.sin() * v);
            camera
                .project(&Point::<Camera>::new(p.x, p.y, p.z))
                .map(|q| (q.x_px, q.y_px))
        })
        .collect::<Option<Vec<_>>>()?;
    let (w, h) = (camera.width_px as f64, camera.height_px as f64);
    // Crossings of the closed outline with the line coordinate `at` along axis 1 (rows) or 0.
    let crossings = |at: f64, rows: bool| -> Option<(f64, f64)> {
        let mut xs = Vec::new();
        for (i, a) in outline.iter().enumerate() {
            let b = outline[(i + 1) % outline.len()];
            let (a0, a1, b0, b1) = if rows {
                (a.1, a.0, b.1, b.0)
            } else {
                (a.0, a.1, b.0, b.1)
            };
            if (a0 - at) * (b0 - at) <= 0.0 && (a0 - b0).abs() > 1e-12 {
                xs.push(a1 + (b1 - a1) * (at - a0) / (b0 - a0));
            }
        }
        let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
    };
    use EdgeScanPattern as P;
    let rows = matches!(pattern, P::LeftToRight | P::RightToLeft | P::SidesToCentre);
    let mut pts = Vec::new();
    let lines = if rows { h } else { w };
    for j in 0..lines as usize {
        let at = j as f64 + 0.5;
        let Some((lo, hi)) = crossings(at, rows) else {
            continue;
        };
        let (take_lo, take_hi) = match pattern {
            P::LeftToRight | P::TopToBottom => (true, false),
            P::RightToLeft | P::BottomToTop => (false, true),
            P::SidesToCentre | P::TopBottomToCentre => (true, true),
        };
        for (take, t) in [(take_lo, lo), (take_hi, hi)] {
            let p = if rows { (t, at) } else { (at, t) };
            if take && p.0 > 0.0 && p.0 < w && p.1 > 0.0 && p.1 < h {
                pts.push(p);
            }
        }
    }
    if pts.len() < 10 {
        return None;
    }
    let f = fit_circle(&pts)?;
    Some(((f.center_x, f.center_y), f.radius))
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
        eprintln!(
            "{label}: n = {}; radius error vs outline truth median {:.3} px unskewed, {:.3} px as \
             read (p90 {:.2} vs {:.2}); vs on-axis radius {:.3} vs {:.3}; centre error {:.2} vs \
             {:.2} px",
            self.raw_r.len(),
            p(&self.fixed_r).p50,
            p(&self.raw_r).p50,
            p(&self.fixed_r).p90,
            p(&self.raw_r).p90,
            p(&self.fixed_r_axis).p50,
            p(&self.raw_r_axis).p50,
            p(&self.fixed_c).p50,
            p(&self.raw_c).p50,
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
        let Some((tc, tr)) = outline_truth(truth, tb, cand.pattern) else {
            continue;
        };
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
        let fit = |pts: &[(f64, f64)]| {
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
                    tc.0,
                    tc.1,
                    ctx.skew_x_per_line
                );
            }
            let e = if side_cut { &mut cut } else { &mut uncut };
            e.raw_r.push((a.radius - tr).abs());
            e.fixed_r.push((c.radius - tr).abs());
            e.raw_r_axis.push((a.radius - axis_r).abs());
            e.fixed_r_axis.push((c.radius - axis_r).abs());
            e.raw_c.push((a.center_x - tc.0).hypot(a.center_y - tc.1));
            e.fixed_c.push((c.center_x - tc.0).hypot(c.center_y - tc.1));
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
    let med = |v: &[f64]| Percentiles::of(v).p50;
    let p90 = |v: &[f64]| Percentiles::of(v).p90;
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
    for (name, p) in [("on", params), ("off", off)] {
        let r = eval_report(ScenarioKind::ClosePans, 150, &lut, p);
        eprintln!(
            "close-pans, skew correction {name}: found {}/{}, distance error median {:.4} (cut \
             {:.4}), radius error median {:.3} px",
            r.ball_found,
            r.ball_eligible,
            r.ball_distance_error.p50,
            r.ball_distance_error_cut.p50,
            r.ball_radius_error_px.p50
        );
    }
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
        let p = Percentiles::of;
        format!(
            "found {}; n = {}, centre error median {:.2} px (p90 {:.2}), radius error median \
             {:.3} px, distance error median {:.2}% (p90 {:.2}%); velocity from {} balls: x \
             error median {:.0} px/s (p90 {:.0}, relative {:.1}%), vector error {:.0} px/s; \
             ground: across the view {:.0} cm/s (p90 {:.0}), vector {:.0} cm/s (p90 {:.0})",
            self.found,
            self.centre.len(),
            p(&self.centre).p50,
            p(&self.centre).p90,
            p(&self.radius).p50,
            100.0 * p(&self.distance).p50,
            100.0 * p(&self.distance).p90,
            self.vx.len(),
            p(&self.vx).p50,
            p(&self.vx).p90,
            100.0 * p(&self.vx_rel).p50,
            p(&self.v).p50,
            p(&self.g_across).p50,
            p(&self.g_across).p90,
            p(&self.g).p50,
            p(&self.g).p90,
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
    let med = |v: &[f64]| Percentiles::of(v).p50;
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
}
