//! The World Model Debugger in the app (issue 30): a recorded session (written by the recorder
//! `eotn wmd -o` uses, from the simulated game of `wmd.rs` whose robots carry known errors, with
//! robot 1's camera frames) reopens as a session — the overhead camera plus the robot's camera
//! as its own camera, the world models matched by marker, the WMD layout —; clicking a robot
//! on the field view shows its camera beside the overhead view with its own table, and its world
//! model is placed on the overhead image; the error plots show heading and tape-measure errors,
//! each robot's median and p95 (no figure without data), and a jump; a session file's robot
//! whose source is a recording of camera frames is shown the same way.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use egui::{PointerButton, Pos2};
use egui_kittest::kittest::Queryable as _;
use eotn::camera::{CameraFiles, CameraId};
use eotn::cli::wmd_record::{CameraFrame, RecordedCamera, SessionRecorder};
use eotn::formats::{ImageBody, ImageMessage};
use eotn::model::world_model::{self, RobotKey, WorldModelMessage};
use eotn::session::SslCameraId;
use eotn::sources::CameraKind;
use eotn::streams::StreamReader;
use eotn::workspace::{Command, OverheadCommand, Window, Workspace};
use serde_json::Value;

use crate::common::repo_file;
use crate::harness::{click_at, harness_with};
use crate::wmd::fixture;

/// The frame of robot 2's world models moved 3 m away (a jump).
const JUMP_FRAME: usize = 30;

struct Recorded {
    path: PathBuf,
    /// Robot 1 (50 cm, 10° off; its camera recorded) and robot 2 (20° turned, no `seen`).
    robots: [RobotKey; 2],
    /// Each frame's time, nanoseconds.
    times: Vec<u64>,
}

/// The robot camera's table (the bundled robot stream's).
fn robot_table() -> PathBuf {
    repo_file("lookup_tables/sim.lut")
}

/// The world model of simulated robot `n` among a frame's channels.
fn model_of(extra: &[(String, Value)], n: u32) -> WorldModelMessage {
    let topic = format!("/world_model/robot{n}");
    let (_, v) = extra.iter().find(|(t, _)| *t == topic).unwrap();
    world_model::from_value(v).unwrap()
}

/// The session recording: the game's overhead frames with robots 1 and 2's world models (robot
/// 2's moved 3 m at [`JUMP_FRAME`] and without its `seen`), robot 1's camera frames (the bundled
/// goalkeeper stream's) on its session topic, its table named.
fn recorded() -> &'static Recorded {
    static R: OnceLock<Recorded> = OnceLock::new();
    R.get_or_init(|| {
        let f = fixture();
        let path = f.dir.path().join("app-session.mcap");
        let mut game = StreamReader::open(&f.stream).unwrap();
        let mut robot_stream =
            StreamReader::open(&repo_file("streams/sim-goalkeeper.mcap")).unwrap();
        let first = game.read(0).unwrap();
        let robots = [1, 2].map(|n| model_of(&first.extra, n).robot);
        let mut rec = SessionRecorder::create(
            &path,
            &[RecordedCamera {
                id: SslCameraId(0),
                files: CameraFiles {
                    lut: Some(f.table.clone()),
                    params: None,
                    calibration: Some(f.cal.clone()),
                },
            }],
        )
        .unwrap();
        let topic = robots[0].camera_topic();
        rec.name_robot_camera(
            &topic,
            &CameraFiles {
                lut: Some(robot_table()),
                ..CameraFiles::default()
            },
        )
        .unwrap();
        let mut times = Vec::new();
        for i in 0..game.len() {
            let r = game.read(i).unwrap();
            let robot = robot_stream.read(i % robot_stream.len()).unwrap();
            let (w, h) = (robot.frame.width(), robot.frame.height());
            let image = ImageMessage {
                timestamp_ns: Some(r.time_ns),
                frame_id: String::new(),
                body: ImageBody::Raw {
                    width: u32::try_from(w).unwrap(),
                    height: u32::try_from(h).unwrap(),
                    encoding: "rgb8".to_owned(),
                    step: u32::try_from(3 * w).unwrap(),
                    data: robot.frame.to_rgb(),
                },
            };
            rec.robot_frame(&topic, r.time_ns, image).unwrap();
            let one = model_of(&r.extra, 1);
            let mut two = model_of(&r.extra, 2);
            two.seen.clear();
            if i == JUMP_FRAME {
                two.own.x_cm += 300.0;
            }
            let camera = CameraFrame {
                id: SslCameraId(0),
                time_ns: r.time_ns,
                frame: &r.frame,
            };
            rec.field_frame(
                r.time_ns,
                &[camera],
                &[&one, &two],
                &serde_json::json!({}),
                &foxglove::messages::SceneUpdate::default(),
            )
            .unwrap();
            times.push(r.time_ns);
        }
        rec.finish().unwrap();
        Recorded {
            path,
            robots,
            times,
        }
    })
}

/// The recorded session opened as the app opens it.
fn opened() -> Workspace {
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![recorded().path.clone()]))
        .unwrap();
    w
}

/// Every frame shown once, in order (the field model gathers the errors of the frames seen).
fn play_through(w: &mut Workspace) {
    for i in 0..recorded().times.len() {
        w.apply(Command::Playback(eotn::workspace::PlaybackCommand::Seek(i)))
            .unwrap();
    }
}

fn canonical(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap()
}

#[test]
fn a_recorded_session_reopens_with_the_robots_camera_as_its_own_and_the_wmd_layout() {
    let r = recorded();
    let mut w = opened();
    assert_eq!(w.camera_kind(), CameraKind::Overhead);
    let (cameras, shown) = w.cameras();
    let topics: Vec<&str> = cameras.iter().map(CameraId::topic).collect();
    let robot_topic = r.robots[0].camera_topic();
    assert_eq!(
        topics,
        ["/camera/image", robot_topic.as_str()],
        "{cameras:?}"
    );
    assert_eq!(shown.as_ref().map(CameraId::topic), Some("/camera/image"));
    // The WMD layout was asked for: the field view and the robots list are open.
    assert_eq!(w.wmd_layout_requests(), 1);
    assert!(w.window_open(Window::FieldView) && w.window_open(Window::Robots));
    // The world models, matched by marker.
    let models = w.overhead().field_model.world_models();
    assert_eq!(models.len(), 2, "{models:?}");
    assert!(
        models
            .iter()
            .all(|m| m.matched == eotn::wmd::Matched::Marker),
        "{models:?}"
    );
    let rows = w.wmd_robots();
    assert_eq!(rows.len(), 2);
    assert_eq!(
        rows.iter()
            .find(|row| row.robot == r.robots[0])
            .and_then(|row| row.camera.as_ref())
            .map(CameraId::topic),
        Some(robot_topic.as_str())
    );
    // The robot's camera is its own camera: a robot's, with the table the recording names.
    let robot_camera = cameras[1].clone();
    w.apply(Command::OpenCamera(Some(robot_camera))).unwrap();
    assert_eq!(w.camera_kind(), CameraKind::Robot);
    assert_eq!(w.table_path(), Some(robot_table().as_path()));
    assert!(w.frame().is_some());
    // And back: the overhead camera with its own table.
    w.apply(Command::OpenCamera(Some(cameras[0].clone())))
        .unwrap();
    assert_eq!(w.camera_kind(), CameraKind::Overhead);
    assert_eq!(w.table_path(), Some(fixture().table.as_path()));
}

#[test]
fn clicking_a_robot_on_the_field_shows_its_camera_beside_the_overhead_view() {
    let r = recorded();
    let w = opened();
    let mut h = harness_with(w);
    h.run();
    h.run();
    let state = &h.state().state;
    let d = state.overhead().field_cameras().picture().unwrap().clone();
    let one = d
        .robots
        .iter()
        .find(|x| x.team == r.robots[0].team && x.identity == r.robots[0].identity)
        .expect("robot 1 seen from above");
    let rect = h.get_by_label("field drawing").rect();
    let xf = eotn::app::field_view::FieldTransform::fit(rect, state.overhead().field());
    let at: Pos2 = xf.to_screen(one.field_cm);
    click_at(&h, at, PointerButton::Primary);
    h.run();
    h.run();
    let state = &h.state().state;
    assert_eq!(state.overhead().selected(), Some(r.robots[0]));
    let panes = state.camera_panes();
    assert_eq!(panes.len(), 2, "status: {}", state.status);
    assert!(panes[0].focused && panes[0].topic == "/camera/image");
    let beside = &panes[1];
    assert_eq!(beside.topic, r.robots[0].camera_topic());
    assert!(beside.frame.is_some());
    assert_eq!(beside.table_path, Some(robot_table().as_path()));
    assert_eq!(
        state.camera_kind(),
        CameraKind::Overhead,
        "the overhead camera stays focused"
    );
    // Its world model over the overhead image: robot 2 (no position error) where the camera
    // sees it, robot 1 (50 cm off) away from its marker.
    let marks = state.world_model_marks();
    let d = state.overhead_detections().unwrap();
    let off = |k: RobotKey| {
        let mark = marks.iter().find(|m| m.robot == k).unwrap().own.unwrap();
        let seen = d
            .robots
            .iter()
            .find(|x| x.team == k.team && x.identity == k.identity)
            .unwrap()
            .image;
        mark.distance_to(&seen)
    };
    let (near, far) = (off(r.robots[1]), off(r.robots[0]));
    assert!(near < 15.0 && far > near + 20.0, "{near} {far}");
    // Clicking the empty field: the overhead camera alone again.
    let corner = rect.left_top() + egui::vec2(3.0, 3.0);
    click_at(&h, corner, PointerButton::Primary);
    h.run();
    assert!(h.state().state.camera_panes().is_empty());
}

#[test]
fn the_errors_show_heading_tape_spreads_and_a_jump_and_the_wheel_scrolls_past_the_plots() {
    let r = recorded();
    let mut w = opened();
    play_through(&mut w);
    let s = w.overhead().field_model.summaries();
    let of = |k: RobotKey| s.iter().find(|x| x.robot == k).unwrap();
    let (one, two) = (of(r.robots[0]), of(r.robots[1]));
    // Known errors: robot 1 10° turned and its distances 10 % long; robot 2 20° turned.
    let heading = one.heading_deg.unwrap();
    assert!((heading.median - 10.0).abs() < 4.0, "{heading:?}");
    assert!((two.heading_deg.unwrap().median - 20.0).abs() < 4.0);
    let tape = one.distance_cm.expect("robot 1's distances measured");
    assert!(tape.median > 3.0 && tape.n > 40, "{tape:?}");
    assert_eq!(two.distance_cm, None, "robot 2 measured nothing");
    assert_eq!(two.jumps_ns, [r.times[JUMP_FRAME]]);
    assert!(one.jumps_ns.is_empty());
    let mut h = harness_with(w);
    h.run();
    h.run();
    let jump = format!("jump at {:.2} s", r.times[JUMP_FRAME] as f64 / 1e9);
    assert!(h.query_by_label(&jump).is_some(), "{jump}");
    assert!(
        h.query_by_label("— (0)").is_some(),
        "robot 2's tape: no figure"
    );
    let tape_cell = eotn::app::wmd_errors::spread_text(Some(tape));
    assert!(h.query_by_label(&tape_cell).is_some(), "{tape_cell}");
    // The heading and tape plots are drawn and do not zoom under the wheel.
    for id in [
        eotn::app::wmd_errors::heading_plot_id(),
        eotn::app::wmd_errors::tape_plot_id(),
    ] {
        let memory = egui_plot::PlotMemory::load(&h.ctx, id).expect("the plot was drawn");
        let frame = *memory.transform().frame();
        let bounds = *memory.bounds();
        h.hover_at(frame.center());
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, -40.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Unknown,
            modifiers: egui::Modifiers::NONE,
        });
        h.run();
        let after = egui_plot::PlotMemory::load(&h.ctx, id).unwrap();
        assert_eq!(*after.bounds(), bounds, "the plot did not zoom or move");
    }
}

#[test]
fn the_wmd_layout_puts_the_field_view_above_the_robots_list_beside_the_overhead_view() {
    let mut h = harness_with(opened());
    h.run();
    h.run();
    let groups = h.state().dock.column_groups();
    assert_eq!(groups.len(), 2, "{groups:?}");
    assert_eq!(groups[0], [Window::FieldView]);
    assert_eq!(groups[1].first(), Some(&Window::Robots));
    assert!(h.query_by_label("World models").is_some());
    // Rearranged by hand, then asked for again from the Overhead menu's command.
    h.state_mut()
        .state
        .run(Command::ShowWindow(Window::Inspector, true));
    h.run();
    h.state_mut().state.run(OverheadCommand::WmdLayout.into());
    h.run();
    let groups = h.state().dock.column_groups();
    assert_eq!(groups[0], [Window::FieldView]);
    assert_eq!(groups[1], [Window::Robots, Window::Inspector]);
}

#[test]
fn a_session_files_robot_recording_is_shown_beside_the_overhead_camera_with_its_own_table() {
    let f = fixture();
    let key = recorded().robots[0];
    let dir = tempfile::tempdir().unwrap();
    let session = dir.path().join("SESSION.json");
    let robot = repo_file("streams/sim-goalkeeper.mcap");
    std::fs::write(
        &session,
        serde_json::json!({
            "field": "four-legged-2005",
            "overhead": [{"id": 0, "source": f.stream, "lut": f.table, "calibration": f.cal}],
            "robots": [{"team": key.team.name(), "robot_id": key.identity.value(),
                "source": robot, "lut": robot_table()}],
        })
        .to_string(),
    )
    .unwrap();
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![session])).unwrap();
    assert_eq!(w.wmd_layout_requests(), 1);
    // Its recording holds camera frames but no world models: said, not refused.
    assert!(
        w.warnings()
            .iter()
            .any(|l| l.contains(&format!("robot {key}")) && l.contains("no world-model channel")),
        "{:?}",
        w.warnings()
    );
    let (camera, _) = w
        .robot_camera(key)
        .expect("the robot's recording has frames");
    assert_eq!(
        camera,
        CameraId::recording(&canonical(&robot), "/camera/image")
    );
    w.apply(OverheadCommand::SelectRobot(Some(key)).into())
        .unwrap();
    let panes = w.camera_panes();
    assert_eq!(panes.len(), 2, "{}", w.status);
    assert_eq!(*panes[1].camera, camera);
    assert_eq!(panes[1].table_path, Some(robot_table().as_path()));
    assert!(panes[1].frame.is_some());
    assert_eq!(w.camera_kind(), CameraKind::Overhead);
    // Another robot, without a camera: the overhead camera alone.
    let other = recorded().robots[1];
    w.apply(OverheadCommand::SelectRobot(Some(other)).into())
        .unwrap();
    assert!(w.camera_panes().is_empty());
}

/// Robot 1's own recording: its world models (the game's, moved 80 cm along x) on
/// `/world_model`, logged and stamped at the overhead frames' times (one clock).
fn own_recording(dir: &Path) -> PathBuf {
    let path = dir.join("robot1-own.mcap");
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let mut w = mcap::Writer::new(file).unwrap();
    let channel = w
        .add_channel(
            0,
            "/world_model",
            "json",
            &std::collections::BTreeMap::new(),
        )
        .unwrap();
    let mut game = StreamReader::open(&fixture().stream).unwrap();
    for i in 0..game.len() {
        let r = game.read(i).unwrap();
        let (_, v) = r
            .extra
            .iter()
            .find(|(t, _)| t == "/world_model/robot1")
            .unwrap();
        let mut v = v.clone();
        v["self"]["x_cm"] = (v["self"]["x_cm"].as_f64().unwrap() + 80.0).into();
        v["time_ns"] = r.time_ns.into();
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: u32::try_from(i).unwrap(),
            log_time: r.time_ns,
            publish_time: r.time_ns,
        };
        w.write_to_known_channel(&header, &serde_json::to_vec(&v).unwrap())
            .unwrap();
    }
    w.finish().unwrap();
    path
}

#[test]
fn a_session_files_robot_brings_its_own_world_models_in_place_of_the_streams() {
    let f = fixture();
    let key = recorded().robots[0];
    let dir = tempfile::tempdir().unwrap();
    let own = own_recording(dir.path());
    let session = dir.path().join("SESSION.json");
    std::fs::write(
        &session,
        serde_json::json!({
            "field": "four-legged-2005",
            "overhead": [{"id": 0, "source": f.stream, "lut": f.table, "calibration": f.cal}],
            "robots": [{"team": key.team.name(), "robot_id": key.identity.value(), "source": own}],
        })
        .to_string(),
    )
    .unwrap();
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![session])).unwrap();
    w.apply(Command::Playback(eotn::workspace::PlaybackCommand::Seek(
        10,
    )))
    .unwrap();
    let record = StreamReader::open(&f.stream).unwrap().read(10).unwrap();
    let streamed = model_of(&record.extra, 1);
    let models = w.overhead().field_model.world_models();
    let mine: Vec<_> = models.iter().filter(|m| m.robot == key).collect();
    assert_eq!(mine.len(), 1, "one world model of robot 1: {models:?}");
    assert!(
        (mine[0].own[0] - (streamed.own.x_cm + 80.0)).abs() < 1e-6,
        "its own recording's: {:?} vs {:?}",
        mine[0].own,
        streamed.own
    );
    assert_eq!(mine[0].matched, eotn::wmd::Matched::Marker);
    // The other robots' world models still come from the stream.
    assert!(models.len() > 1, "{models:?}");
    // A recording of world models only has no camera to show.
    assert!(
        w.robot_camera(key).is_none(),
        "no frames in a world-model recording"
    );
}
