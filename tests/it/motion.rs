//! Motion in the rolling shutter, measured on the renderer: the camera's skew correction on
//! close balls during fast pans (`close-pans`), and the moving-circle (constrained ellipse) fit
//! of a ball rolling across a still camera (`rolling-ball`): its image and ground velocity, and
//! whether it places the ball better than the plain circle.

use eotn::eval::Percentiles;
use eotn::geometry::{Camera, Ers7Dimensions, Field, PinholeCamera, Point, Transform};
use eotn::lut::LookupTable;
use eotn::lut::learn::{LearnParams, TableBuilder};
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::recognition::ball::is_ball_colour;
use eotn::recognition::fit::{fit_circle, fit_circle_trimmed};
use eotn::recognition::scan::edge_points;
use eotn::sim::truth::{BallTruth, GroundTruth, RobotViewTruth};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

/// A table learnt from every 10th frame of a few robot scenarios with seed 100 (the test
/// frames use seed 7).
fn learnt_table() -> LookupTable {
    let mut builder = TableBuilder::new(7).expect("7 bits");
    for kind in [
        ScenarioKind::WalkAndPan,
        ScenarioKind::FastPans,
        ScenarioKind::BallEdge,
        ScenarioKind::ClosePans,
        ScenarioKind::RollingBall,
    ] {
        let sim = Simulator::new(Scenario::new(kind, 100));
        for i in (0..90).step_by(10) {
            let f = sim.frame(i).expect("frame");
            builder.add_frame(&f.frame, &f.labels).expect("labels fit");
        }
    }
    builder.build(&LearnParams::default())
}

/// The circle a perfect outline of the ball's visible part fits at mid-readout: the sphere's
/// silhouette (the tangent circle of the viewing cone) projected with the mid-readout camera
/// pose, keeping the points inside the image. Off the optical axis a sphere projects as an
/// ellipse stretched away from the centre (13% at the image side for a close ball), which
/// `image_radius_px` (the on-axis size) does not include. Returns (centre, radius), pixels.
fn outline_truth(truth: &RobotViewTruth, ball: &BallTruth) -> Option<((f64, f64), f64)> {
    let camera = PinholeCamera::ers7();
    let field_from_camera: Transform<Field, Camera> = truth
        .body
        .field_from_body(&truth.robot_pose)
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
    let (w, h) = (camera.width_px as f64, camera.height_px as f64);
    let pts: Vec<(f64, f64)> = (0..180)
        .filter_map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 180.0;
            let p = centre + radius * (a.cos() * u + a.sin() * v);
            camera.project(&Point::<Camera>::new(p.x, p.y, p.z))
        })
        .map(|p| (p.x_px, p.y_px))
        .filter(|p| p.0 > 0.0 && p.0 < w && p.1 > 0.0 && p.1 < h)
        .collect();
    if pts.len() < 20 {
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
        let (Some(axis_r), Some((tc, tr))) = (tb.image_radius_px, outline_truth(truth, tb))
        else {
            continue;
        };
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
    let all = |f: fn(&SkewErrors) -> &Vec<f64>| {
        let mut v = f(&uncut).clone();
        v.extend(f(&cut));
        v
    };
    let (raw, fixed) = (all(|e| &e.raw_r), all(|e| &e.fixed_r));
    eprintln!(
        "close-pans, all balls: radius error median {:.3} px unskewed vs {:.3} px as read (n = {})",
        med(&fixed),
        med(&raw),
        raw.len()
    );
    assert!(uncut.raw_r.len() >= 10 && cut.raw_r.len() >= 5);
    // Achieved levels (see README): the correction at least halves the radius error of close
    // balls cut by the image side, and of all close balls together.
    assert!(med(&cut.fixed_r) * 2.0 <= med(&cut.raw_r));
    assert!(med(&fixed) * 2.0 <= med(&raw));
    assert!(med(&uncut.fixed_c) * 2.0 <= med(&uncut.raw_c));
}

/// Per-ball errors on the rolling ball, for one parameter set.
#[derive(Default, Debug)]
struct MovingErrors {
    centre: Vec<f64>,
    radius: Vec<f64>,
    distance: Vec<f64>,
}

impl MovingErrors {
    fn line(&self) -> String {
        let p = Percentiles::of;
        format!(
            "n = {}, centre error median {:.2} px (p90 {:.2}), radius error median {:.3} px, \
             distance error median {:.2}% (p90 {:.2}%)",
            self.centre.len(),
            p(&self.centre).p50,
            p(&self.centre).p90,
            p(&self.radius).p50,
            100.0 * p(&self.distance).p50,
            100.0 * p(&self.distance).p90,
        )
    }
}

#[test]
fn ellipse_fit_measures_a_rolling_ball() {
    let lut = learnt_table();
    let plain = PipelineParams::default();
    assert!(!plain.recognition.ball.ellipse_fit, "off by default");
    let mut with = plain;
    with.recognition.ball.ellipse_fit = true;
    let sim = Simulator::new(Scenario::new(ScenarioKind::RollingBall, 7));
    let mut p_plain = Pipeline::new(lut.clone(), plain);
    let mut p_with = Pipeline::new(lut.clone(), with);
    let (mut e_plain, mut e_with) = (MovingErrors::default(), MovingErrors::default());
    let (mut v_err, mut v_rel, mut g_err, mut g_rel) = (vec![], vec![], vec![], vec![]);
    let (mut found_plain, mut found_with, mut eligible, mut velocities) = (0, 0, 0, 0);
    for i in 0..150 {
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
        let a = p_plain
            .process(&f.frame, f.sensors.as_ref())
            .recognition
            .ball
            .ball
            .clone();
        let b = p_with
            .process(&f.frame, f.sensors.as_ref())
            .recognition
            .ball
            .ball
            .clone();
        found_plain += usize::from(a.is_some());
        found_with += usize::from(b.is_some());
        let (Some(a), Some(b)) = (a, b) else {
            continue;
        };
        let dist = tb.relative.camera_distance_cm;
        for (ball, e) in [(&a, &mut e_plain), (&b, &mut e_with)] {
            e.centre
                .push((ball.center_x - tc.x_px).hypot(ball.center_y - tc.y_px));
            e.radius.push((ball.radius_px - tr).abs());
            e.distance
                .push((ball.camera.distance_cm - dist).abs() / dist);
        }
        assert!(a.image_velocity_px_s.is_none());
        if let Some(v) = b.image_velocity_px_s {
            velocities += 1;
            let err = (v[0] - tv[0]).hypot(v[1] - tv[1]);
            v_err.push(err);
            v_rel.push(err / tv[0].hypot(tv[1]).max(1.0));
            let g = b.ground_velocity_cm_s.expect("pose known: ground velocity");
            let gerr = (g[0] - tg[0]).hypot(g[1] - tg[1]);
            g_err.push(gerr);
            g_rel.push(gerr / tg[0].hypot(tg[1]).max(1.0));
            eprintln!(
                "frame {i}: image velocity ({:.0}, {:.0}) px/s, truth ({:.0}, {:.0}); ground \
                 ({:.0}, {:.0}) cm/s, truth ({:.0}, {:.0}); r {:.1} px",
                v[0], v[1], tv[0], tv[1], g[0], g[1], tg[0], tg[1], tr
            );
        }
    }
    let p = Percentiles::of;
    eprintln!(
        "rolling-ball: eligible {eligible}, found plain {found_plain}, with ellipse fit \
         {found_with}, velocity from {velocities}"
    );
    eprintln!(
        "rolling-ball image velocity error: median {:.0} px/s (p90 {:.0}), relative median \
         {:.1}% (p90 {:.1}%)",
        p(&v_err).p50,
        p(&v_err).p90,
        100.0 * p(&v_rel).p50,
        100.0 * p(&v_rel).p90
    );
    eprintln!(
        "rolling-ball ground velocity error: median {:.0} cm/s (p90 {:.0}), relative median \
         {:.1}% (p90 {:.1}%)",
        p(&g_err).p50,
        p(&g_err).p90,
        100.0 * p(&g_rel).p50,
        100.0 * p(&g_rel).p90
    );
    eprintln!("rolling-ball, plain circle: {}", e_plain.line());
    eprintln!("rolling-ball, ellipse fit:  {}", e_with.line());
    assert!(eligible >= 30 && found_with >= found_plain);
}
