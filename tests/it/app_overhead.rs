//! The overhead camera in the app, through the same `Workspace`/`Command` path the window uses
//! and with egui_kittest on the real `EotnApp`: an overhead stream runs the overhead
//! recogniser (a robot stream does not), the calibration in use (the stream's own camera, an
//! opened or solved one, none), picking points by landmark name with undo, Calibrate with the
//! reprojection error per point, saving points and calibration, the undistorted view, the
//! field view with the world models, and one robot selection.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use egui::{PointerButton, Pos2};
use egui_kittest::kittest::Queryable as _;
use eotn::app::field_view::FieldTransform;
use eotn::geometry::{ImagePoint, Point};
use eotn::model::truth::{GroundTruth, OverheadTruth};
use eotn::overhead::calibration::Calibration;
use eotn::overhead::{FieldDescription, PointsFile};
use eotn::sources::CameraKind;
use eotn::streams::{FrameRecord, StreamReader};
use eotn::workspace::{
    CalibrationSource, Command, OverheadCommand, PlaybackCommand, RobotKey, ViewCommand, ViewKind,
    Window, Workspace,
};

use crate::common::{repo_file, sim_stream};
use crate::harness::{click_at, click_label, harness_with, show_window, write_stream};

/// An overhead-game stream of 4 frames rendered once for every test (markers, truth, world
/// models), and a table learnt from its own labels.
fn fixture() -> (&'static PathBuf, &'static PathBuf) {
    static FIXTURE: OnceLock<(tempfile::TempDir, PathBuf, PathBuf)> = OnceLock::new();
    let (_, stream, table) = FIXTURE.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let stream = sim_stream(dir.path(), "overhead-game", 4, Some(3));
        let table = dir.path().join("overhead.lut");
        let sim = eotn::sim::Simulator::new(eotn::sim::Scenario::new(
            eotn::sim::ScenarioKind::OverheadGame,
            99,
        ));
        let mut builder = eotn::lut::learn::TableBuilder::new(7).unwrap();
        for index in (0..300).step_by(30) {
            let f = sim.frame(index).unwrap();
            builder.add_frame(&f.frame, &f.labels).unwrap();
        }
        builder
            .build(&eotn::lut::learn::LearnParams::default())
            .save(&table)
            .unwrap();
        (dir, stream, table)
    });
    (stream, table)
}

fn truth(stream: &Path, index: usize) -> OverheadTruth {
    let record = StreamReader::open(stream).unwrap().read(index).unwrap();
    match serde_json::from_value(record.ground_truth.unwrap()).unwrap() {
        GroundTruth::Overhead(t) => *t,
        GroundTruth::Robot(_) => panic!("an overhead stream"),
    }
}

/// A workspace with the overhead table and stream open.
fn opened() -> Workspace {
    let (stream, table) = fixture();
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![stream.clone()])).unwrap();
    w.apply(Command::OpenTable(table.clone())).unwrap();
    w
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[test]
fn an_overhead_stream_runs_the_overhead_recogniser_with_the_streams_own_camera() {
    let (stream, _) = fixture();
    let w = opened();
    assert_eq!(w.camera_kind(), CameraKind::Overhead);
    assert_eq!(
        w.overhead().camera().map(|(_, s)| s),
        Some(CalibrationSource::Stream)
    );
    let t = truth(stream, 0);
    let d = w.overhead_detections().expect("overhead detections");
    let ball = d.ball.expect("the ball is found");
    let true_ball = t.ball.unwrap().field_cm;
    assert!(
        dist(ball.field_cm, true_ball) < 5.0,
        "{ball:?} vs {true_ball:?}"
    );
    let mut matched = 0;
    for r in &t.robots {
        let m = r.marker.unwrap();
        if !m.fully_visible() {
            continue;
        }
        let found = d
            .robots
            .iter()
            .find(|x| x.team == m.team && x.identity == m.identity)
            .unwrap_or_else(|| panic!("robot {} ({m:?}) not found in {:?}", r.id, d.robots));
        assert!(dist(found.field_cm, r.field_cm) < 5.0);
        matched += 1;
    }
    assert!(matched >= 4, "{matched} fully visible robots");
    // The robot recogniser did not run: no robot-camera ball at some distance ahead.
    assert!(w.recognition().ball.candidates.is_empty());
    assert!(w.primitives().is_empty());
    // Classification and blobs come from the overhead pipeline and show in the views.
    assert!(w.blobs().active().count() > 10);
    assert!(w.frame_counts()[0] < w.image_size().0 * w.image_size().1);
}

#[test]
fn a_table_opened_with_an_overhead_stream_is_the_overhead_cameras() {
    let (stream, table) = fixture();
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![table.clone(), stream.clone()]))
        .unwrap();
    assert_eq!(w.table_kind(), CameraKind::Overhead);
    assert_eq!(w.table_path(), Some(table.as_path()));
    assert!(
        w.other_table().path().is_none(),
        "the robot table is untouched"
    );
    assert!(
        w.overhead_detections()
            .is_some_and(|d| !d.robots.is_empty())
    );
}

#[test]
fn a_robot_stream_keeps_the_robot_recogniser() {
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![repo_file(
        "streams/sim-walk-and-pan.mcap",
    )]))
    .unwrap();
    w.apply(Command::OpenTable(repo_file("lookup_tables/sim.lut")))
        .unwrap();
    assert_eq!(w.camera_kind(), CameraKind::Robot);
    assert!(!w.overhead().active());
    assert!(w.overhead_detections().is_none());
}

/// An overhead stream with no truth (as a real overhead camera records it): `n` frames.
fn stream_without_truth(dir: &Path) -> PathBuf {
    let (stream, _) = fixture();
    let mut reader = StreamReader::open(stream).unwrap();
    let records = (0..2).map(|i| {
        let r = reader.read(i).unwrap();
        FrameRecord::new(r.time_ns, r.frame)
    });
    write_stream(&dir.join("real.mcap"), "overhead camera", records)
}

#[test]
fn each_overhead_recording_reopens_with_its_own_calibration() {
    // Two overhead recordings, both one-camera streams on /camera/image: each is a camera of
    // its own, and each reopens with the calibration last used with it.
    let dir = tempfile::tempdir().unwrap();
    let (a_dir, b_dir) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir(&a_dir).unwrap();
    std::fs::create_dir(&b_dir).unwrap();
    let (a, b) = (stream_without_truth(&a_dir), stream_without_truth(&b_dir));
    let (stream, table) = fixture();
    let mut cal = Calibration {
        camera: truth(stream, 0).camera,
        field: "four-legged-2005".into(),
        points: Vec::new(),
        line_samples: 0,
        line_rms_px: None,
        uncertainty: None,
        intrinsics: None,
    };
    let (cal_a, cal_b) = (dir.path().join("a.cal.json"), dir.path().join("b.cal.json"));
    cal.save(&cal_a).unwrap();
    cal.camera.focal_px *= 1.01;
    cal.save(&cal_b).unwrap();
    let in_use = |w: &Workspace| {
        w.overhead()
            .calibration_path()
            .map(eotn::frame::display_name)
    };
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![a.clone(), table.clone()]))
        .unwrap();
    w.apply(OverheadCommand::OpenCalibration(cal_a).into())
        .unwrap();
    w.apply(Command::Open(vec![b.clone()])).unwrap();
    // The second camera has none of its own: the first's stays, and that is said.
    assert_eq!(in_use(&w).as_deref(), Some("a.cal.json"));
    assert!(
        w.warnings()
            .iter()
            .any(|l| l.contains("has no calibration of its own") && l.contains("a.cal.json")),
        "{:?}",
        w.warnings()
    );
    w.apply(OverheadCommand::OpenCalibration(cal_b).into())
        .unwrap();
    w.apply(Command::Open(vec![a])).unwrap();
    assert_eq!(in_use(&w).as_deref(), Some("a.cal.json"), "its own again");
    assert_eq!(
        w.overhead().camera().map(|(_, s)| s),
        Some(CalibrationSource::User)
    );
    w.apply(Command::Open(vec![b])).unwrap();
    assert_eq!(in_use(&w).as_deref(), Some("b.cal.json"));
}

#[test]
fn without_a_calibration_nothing_is_placed_and_the_status_says_so_until_one_is_opened() {
    let dir = tempfile::tempdir().unwrap();
    let (stream, table) = fixture();
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![stream_without_truth(dir.path())]))
        .unwrap();
    w.apply(Command::OpenTable(table.clone())).unwrap();
    assert!(w.overhead().active());
    assert!(w.overhead().camera().is_none());
    assert!(w.overhead_detections().is_none());
    assert!(w.blobs().active().count() > 10, "still classified");
    assert!(
        w.overhead().calibration_status().contains("no calibration"),
        "{}",
        w.overhead().calibration_status()
    );
    // A calibration file of the true camera places them.
    let cal = Calibration {
        camera: truth(stream, 0).camera,
        field: "four-legged-2005".into(),
        points: Vec::new(),
        line_samples: 0,
        line_rms_px: None,
        uncertainty: None,
        intrinsics: None,
    };
    let path = dir.path().join("true.calibration.json");
    cal.save(&path).unwrap();
    w.apply(OverheadCommand::OpenCalibration(path).into())
        .unwrap();
    assert_eq!(
        w.overhead().camera().map(|(_, s)| s),
        Some(CalibrationSource::User)
    );
    assert!(w.overhead_detections().is_some_and(|d| d.ball.is_some()));
    assert!(
        w.apply(OverheadCommand::OpenCalibration(dir.path().join("missing.json")).into())
            .is_err()
    );
    assert!(
        w.overhead_detections().is_some(),
        "a failed open changes nothing"
    );
    // The same camera calibrated on frames of twice the size (the same shape): scaled to these
    // frames, with one warning, and it places the ball where the true camera does.
    let ball = w
        .overhead_detections()
        .and_then(|d| d.ball)
        .map(|b| b.field_cm);
    let open_as = |w: &mut Workspace, name: &str, f: &dyn Fn(&mut Calibration)| {
        let mut c = cal.clone();
        f(&mut c);
        let p = dir.path().join(name);
        c.save(&p).unwrap();
        w.apply(Command::Overhead(OverheadCommand::OpenCalibration(p)))
            .unwrap();
    };
    open_as(&mut w, "double.json", &|c| {
        (c.camera.width_px, c.camera.height_px) = (1280, 960);
        c.camera.focal_px *= 2.0;
        c.camera.centre.x_px *= 2.0;
        c.camera.centre.y_px *= 2.0;
    });
    let scaled = w
        .overhead_detections()
        .and_then(|d| d.ball)
        .map(|b| b.field_cm);
    let (a, b) = (
        ball.expect("ball"),
        scaled.expect("ball through the scaled camera"),
    );
    assert!(dist(a, b) < 1.0, "{a:?} {b:?}");
    let said = w.warnings().join("\n");
    assert!(
        said.contains("is for 1280x960 frames, these are 640x480"),
        "{said}"
    );
    // Made for another shape: nothing placed, and said.
    open_as(&mut w, "wide.json", &|c| c.camera.height_px = 360);
    assert!(w.overhead_detections().is_none());
    let said = w.warnings().join("\n");
    assert!(
        said.contains("another shape") && said.contains("nothing is placed"),
        "{said}"
    );
}

/// Where the true camera puts each of the field's landmarks that it sees (pixel centres).
fn true_clicks(stream: &Path) -> Vec<(String, ImagePoint)> {
    let camera = truth(stream, 0).camera;
    FieldDescription::four_legged_2005()
        .landmarks
        .iter()
        .filter_map(|l| {
            let p =
                camera.image_from_field(&Point::new(l.field_cm[0], l.field_cm[1], l.height_cm))?;
            (p.x_px > 3.0 && p.y_px > 3.0 && p.x_px < 637.0 && p.y_px < 477.0)
                .then(|| (l.name.clone(), p))
        })
        .collect()
}

fn pick(w: &mut Workspace, name: &str, p: ImagePoint) {
    w.apply(OverheadCommand::ChooseLandmark(Some(name.to_owned())).into())
        .unwrap();
    w.apply(
        OverheadCommand::PickPoint {
            x_px: p.x_px,
            y_px: p.y_px,
        }
        .into(),
    )
    .unwrap();
}

#[test]
fn picked_points_calibrate_with_an_error_per_point_undo_and_files() {
    let dir = tempfile::tempdir().unwrap();
    let (stream, _) = fixture();
    let mut w = opened();
    let clicks = true_clicks(stream);
    assert!(clicks.len() >= 8, "{} landmarks in view", clicks.len());
    for (name, p) in clicks.iter().take(5) {
        pick(&mut w, name, *p);
    }
    let err = w.apply(OverheadCommand::Calibrate.into()).unwrap_err();
    assert!(format!("{err}").contains("at least 6"), "{err}");
    // A wrong click, then undone: the point goes and its landmark is chosen again.
    let (name5, p5) = &clicks[5];
    pick(&mut w, name5, ImagePoint::new(10.0, 10.0));
    assert_eq!(w.overhead().points().points.len(), 6);
    w.apply(OverheadCommand::UndoPick.into()).unwrap();
    assert_eq!(w.overhead().points().points.len(), 5);
    assert_eq!(w.overhead().landmark(), Some(name5.as_str()));
    for (name, p) in &clicks[5..] {
        pick(&mut w, name, *p);
    }
    assert!(
        w.apply(
            OverheadCommand::PickPoint {
                x_px: -4.0,
                y_px: 3.0
            }
            .into()
        )
        .is_err()
            || w.overhead().landmark().is_none()
    );
    w.apply(OverheadCommand::Calibrate.into()).unwrap();
    let cal = w.overhead().calibration().expect("solved").clone();
    assert_eq!(cal.points.len(), clicks.len());
    assert!(cal.median_point_error_px() < 0.5, "{cal:?}");
    assert_eq!(
        w.overhead().camera().map(|(_, s)| s),
        Some(CalibrationSource::User)
    );
    let _ = p5;
    // The solved camera places the ball as the true one does.
    let t = truth(stream, 0);
    let ball = w.overhead_detections().and_then(|d| d.ball).unwrap();
    assert!(dist(ball.field_cm, t.ball.unwrap().field_cm) < 5.0);

    let points = dir.path().join("clicked.points.json");
    w.apply(OverheadCommand::SavePoints(points.clone()).into())
        .unwrap();
    let back = PointsFile::load(&points).unwrap();
    assert_eq!(back.points.len(), w.overhead().points().points.len());
    for (a, b) in back.points.iter().zip(&w.overhead().points().points) {
        assert_eq!((&a.name, a.field_cm), (&b.name, b.field_cm));
        assert!(a.image().distance_to(&b.image()) < 1e-9);
    }
    let saved = dir.path().join("clicked.calibration.json");
    w.apply(OverheadCommand::SaveCalibration(saved.clone()).into())
        .unwrap();
    let back = Calibration::load(&saved).unwrap();
    assert_eq!(back.points.len(), cal.points.len());
    assert!((back.camera.focal_px - cal.camera.focal_px).abs() < 1e-9);
    w.apply(OverheadCommand::CloseCalibration.into()).unwrap();
    assert_eq!(
        w.overhead().camera().map(|(_, s)| s),
        Some(CalibrationSource::Stream)
    );
    assert!(
        w.apply(OverheadCommand::ChooseLandmark(Some("no such landmark".into())).into())
            .is_err()
    );
}

#[test]
fn the_undistorted_view_remaps_the_image_and_clicks_go_back_to_camera_pixels() {
    let mut w = opened();
    let before = w.view_rgb().into_owned();
    assert_eq!(before, w.rgb());
    let mut v = w.settings.overhead;
    v.undistorted = true;
    w.apply(OverheadCommand::SetView(v).into()).unwrap();
    assert!(w.undistorted_view());
    assert_ne!(w.view_rgb().as_ref(), w.rgb());
    assert_eq!(w.view_codes().len(), w.rgb().len() / 3);
    let p = ImagePoint::new(100.0, 90.0);
    let shown = w.overhead_view_point(p).unwrap();
    let back = w.camera_point_of_view(shown);
    assert!(back.distance_to(&p) < 1e-3);
    // Corners bend outwards under the lens: they move in the undistorted view.
    assert!(shown.distance_to(&p) > 1.0);
}

#[test]
fn world_models_are_compared_with_the_overhead_robots() {
    let (stream, _) = fixture();
    let mut w = opened();
    w.apply(PlaybackCommand::Step(1).into()).unwrap();
    w.apply(PlaybackCommand::Step(1).into()).unwrap();
    let model = &w.overhead().field_model;
    let models = model.world_models();
    assert!(models.len() >= 4, "{models:?}");
    let t = truth(stream, 2);
    for m in models {
        // The world model names the marker its robot wears.
        let r = t
            .robots
            .iter()
            .find(|r| {
                r.marker.is_some_and(|k| {
                    RobotKey {
                        team: k.team,
                        identity: k.identity,
                    } == m.robot
                })
            })
            .unwrap();
        let marker = r.marker.unwrap();
        if marker.fully_visible() {
            assert_eq!(m.key, Some(m.robot));
            assert_eq!(m.matched, eotn::wmd::Matched::Marker);
            // The simulator's world models are the truth plus at most about 15 cm of bias and
            // 8 cm noise per axis.
            let e = m.self_error_cm.expect("the robot is seen");
            assert!(e < 80.0, "{} {e} cm", m.robot);
        }
    }
    assert_eq!(model.error_samples().count(), 3);
    assert!(model.trails().values().any(|t| t.len() == 3));
}

#[test]
fn the_app_picks_points_by_clicking_and_calibrates_from_the_window() {
    let (stream, _) = fixture();
    let w = opened();
    let clicks = true_clicks(stream);
    let mut h = harness_with(w);
    h.run();
    let first = clicks[0].0.clone();
    h.state_mut()
        .state
        .run(OverheadCommand::ChooseLandmark(Some(first)).into());
    h.run();
    let mut advanced = 0;
    for (k, (name, p)) in clicks.iter().enumerate() {
        // After each click the next landmark of the field not yet picked is chosen; landmarks
        // outside this camera's image (goal-post tops) are chosen by name instead.
        if h.state().state.overhead().landmark() == Some(name.as_str()) {
            advanced += 1;
        } else {
            h.state_mut()
                .state
                .run(OverheadCommand::ChooseLandmark(Some(name.clone())).into());
            h.run();
        }
        let xf = h.state().last_view.expect("the view was drawn");
        click_at(
            &h,
            xf.to_screen(Pos2::new(p.x_px as f32, p.y_px as f32)),
            PointerButton::Primary,
        );
        h.run();
        assert_eq!(h.state().state.overhead().points().points.len(), k + 1);
        assert!(
            h.state().state.selection().is_none(),
            "a pick is not a classification sample"
        );
    }
    assert!(
        advanced > clicks.len() / 4,
        "{advanced} of {}",
        clicks.len()
    );
    // Clicks land within a screen point of the true pixel.
    for (name, p) in &clicks {
        let got = h
            .state()
            .state
            .overhead()
            .points()
            .points
            .iter()
            .find(|q| &q.name == name)
            .unwrap()
            .image();
        assert!(got.distance_to(p) < 1.5, "{name}: {got:?} vs {p:?}");
    }
    // The window docks beside the image; its buttons fit the column (no sideways scrolling).
    show_window(&mut h, Window::Calibration);
    click_label(&mut h, "Undo pick");
    assert_eq!(
        h.state().state.overhead().points().points.len(),
        clicks.len() - 1
    );
    let calibrate = h.get_by_label("Calibrate");
    assert!(
        calibrate.rect().max.x <= 1200.0,
        "Calibrate is on screen: {:?}",
        calibrate.rect()
    );
    calibrate.click();
    h.run();
    h.run();
    let cal = h
        .state()
        .state
        .overhead()
        .calibration()
        .cloned()
        .expect("solved");
    assert!(cal.median_point_error_px() < 1.5, "{cal:?}");
    assert!(h.query_by_label("error (px)").is_some());
    assert!(h.query_all_by_label_contains(" px over ").count() == 1);
}

#[test]
fn clicking_a_robot_in_the_field_view_selects_it_everywhere() {
    let mut w = opened();
    w.apply(Command::ShowWindow(Window::FieldView, true))
        .unwrap();
    w.apply(Command::ShowWindow(Window::Inspector, true))
        .unwrap();
    w.apply(ViewCommand::SetMainView(ViewKind::Objects).into())
        .unwrap();
    let robot = w.overhead_detections().unwrap().robots[0];
    let key = RobotKey {
        team: robot.team,
        identity: robot.identity,
    };
    let mut h = harness_with(w);
    h.run();
    h.run();
    let rect = h.get_by_label("field drawing").rect();
    let xf = FieldTransform::fit(rect, h.state().state.overhead().field());
    click_at(&h, xf.to_screen(robot.field_cm), PointerButton::Primary);
    h.run();
    assert_eq!(h.state().state.overhead().selected(), Some(key));
    // The inspector lists it selected; clicking it there clears the selection.
    h.get_by_label(&key.to_string()).click();
    h.run();
    assert_eq!(h.state().state.overhead().selected(), None);
    assert!(h.query_by_label_contains("world model").is_some());
}
