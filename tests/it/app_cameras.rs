//! The app's camera picker (issue 28): a recording with two cameras lists both under Stream ▸
//! Camera of the recording; picking one shows it at the same time with the table its recording
//! names for it, and a table opened then is remembered for that camera only.

use eotn::camera::{CameraFiles, CameraId};
use eotn::frame::{Frame, Yuv};
use eotn::lut::{ColourClass, LookupTable};
use eotn::streams::{FrameRecord, StreamInfo, StreamWriter};

use egui_kittest::kittest::Queryable as _;

use crate::harness::{click_label, harness, workspace};

/// The image topic of the camera shown.
fn shown(h: &egui_kittest::Harness<'_, eotn::app::EotnApp>) -> Option<String> {
    workspace(h).cameras().1.map(|c| c.topic().to_owned())
}

/// The camera `topic` of the source shown.
fn camera(h: &egui_kittest::Harness<'_, eotn::app::EotnApp>, topic: &str) -> CameraId {
    let all = workspace(h).cameras().0;
    all.into_iter()
        .find(|c| c.topic() == topic)
        .unwrap_or_else(|| panic!("no camera {topic}"))
}

/// `two.mcap`: `/camera/image` (16×8) and `/camera/bottom` (8×4), four frames each, the bottom
/// camera naming `bottom.lut`; `top.lut` (the frames orange) and `bottom.lut` (green) beside it.
fn recording(dir: &std::path::Path) -> std::path::PathBuf {
    let p = dir.join("two.mcap");
    let mut w = StreamWriter::create(&p, &StreamInfo::default()).unwrap();
    let files = CameraFiles {
        lut: Some("bottom.lut".into()),
        ..CameraFiles::default()
    };
    w.name_camera_files("/camera/bottom", &files).unwrap();
    let grey = Yuv::new(90, 128, 128);
    for i in 0..4u64 {
        let top = FrameRecord::new(i * 40, Frame::filled_uyvy(16, 8, grey).unwrap());
        w.write_camera("/camera/image", &top, None).unwrap();
        let bottom = FrameRecord::new(i * 40 + 3, Frame::filled_uyvy(8, 4, grey).unwrap());
        w.write_camera("/camera/bottom", &bottom, None).unwrap();
    }
    w.finish().unwrap();
    for (name, class) in [
        ("top.lut", ColourClass::Orange),
        ("bottom.lut", ColourClass::Green),
    ] {
        let mut t = LookupTable::new(6).unwrap();
        let i = t.index(grey);
        t.set(i, class);
        t.save(&dir.join(name)).unwrap();
    }
    p
}

#[test]
fn the_camera_picker_shows_the_other_camera_with_its_own_table() {
    let dir = tempfile::tempdir().unwrap();
    let rec = recording(dir.path());
    let mut h = harness(vec![rec, dir.path().join("top.lut")]);
    h.run();
    assert_eq!(shown(&h).as_deref(), Some("/camera/image"));
    let name = |h: &egui_kittest::Harness<'_, eotn::app::EotnApp>| {
        workspace(h)
            .table_path()
            .map(eotn::frame::display_name)
            .unwrap_or_default()
    };
    assert_eq!(name(&h), "top.lut");
    click_label(&mut h, "Stream");
    click_label(&mut h, "Camera of the recording");
    click_label(&mut h, "/camera/bottom");
    assert_eq!(shown(&h).as_deref(), Some("/camera/bottom"));
    assert_eq!(name(&h), "bottom.lut", "the bottom camera's own table");
    let (top, bottom) = (camera(&h, "/camera/image"), camera(&h, "/camera/bottom"));
    let remembered = |h: &egui_kittest::Harness<'_, eotn::app::EotnApp>, id: &CameraId| {
        workspace(h)
            .settings
            .cameras
            .get(id)
            .and_then(|f| f.lut.clone())
    };
    assert!(
        remembered(&h, &top).is_some_and(|p| p.ends_with("top.lut")),
        "the top camera keeps its table"
    );
    assert!(remembered(&h, &bottom).is_some_and(|p| p.ends_with("bottom.lut")));
    // Back to the top camera: its own table again, the bottom one's untouched.
    click_label(&mut h, "Stream");
    click_label(&mut h, "Camera of the recording");
    click_label(&mut h, "/camera/image");
    assert_eq!(name(&h), "top.lut");
    assert!(remembered(&h, &bottom).is_some_and(|p| p.ends_with("bottom.lut")));
}

/// `pair.mcap`: `/camera/image` (16×8, 25 fps, six frames) and `/camera/bottom` (8×4, 12.5 fps,
/// two frames: it ends early), each frame carrying its camera's far IR reading (11 cm top, 22 cm
/// bottom); `top.lut` (grey → orange) and `bottom.lut` (grey → green), the bottom camera naming
/// its own.
fn pair(dir: &std::path::Path) -> std::path::PathBuf {
    let p = dir.join("pair.mcap");
    let mut w = StreamWriter::create(&p, &StreamInfo::default()).unwrap();
    let files = CameraFiles {
        lut: Some("bottom.lut".into()),
        ..CameraFiles::default()
    };
    w.name_camera_files("/camera/bottom", &files).unwrap();
    let grey = Yuv::new(90, 128, 128);
    let ms = 1_000_000;
    let record = |t: u64, w: usize, h: usize, ir: f64| {
        let mut r = FrameRecord::new(t, Frame::filled_uyvy(w, h, grey).unwrap());
        r.sensors = Some(eotn::sensors::SensorReadings {
            ir_far_cm: Some(ir),
            ..Default::default()
        });
        r
    };
    for i in 0..6u64 {
        w.write_camera("/camera/image", &record(i * 40 * ms, 16, 8, 11.0), None)
            .unwrap();
        if i < 2 {
            let bottom = record(i * 80 * ms + 3 * ms, 8, 4, 22.0);
            w.write_camera("/camera/bottom", &bottom, None).unwrap();
        }
    }
    w.finish().unwrap();
    for (name, class) in [
        ("top.lut", ColourClass::Orange),
        ("bottom.lut", ColourClass::Green),
    ] {
        let mut t = LookupTable::new(6).unwrap();
        let i = t.index(grey);
        t.set(i, class);
        t.save(&dir.join(name)).unwrap();
    }
    p
}

/// Where pixel (x, y) of camera `topic`'s pane is on screen.
fn pane_pixel(
    h: &egui_kittest::Harness<'_, eotn::app::EotnApp>,
    topic: &str,
    x: usize,
    y: usize,
) -> egui::Pos2 {
    let panes = &h.state().last_panes;
    let pane = panes
        .iter()
        .find(|p| p.topic == topic)
        .unwrap_or_else(|| panic!("no pane of {topic}: {panes:?}"));
    pane.transform.pixel_centre(x, y)
}

#[test]
fn cameras_side_by_side_each_classify_with_their_own_table_and_an_edit_stays_in_one() {
    use crate::harness::click_at;
    use eotn::workspace::{Command, TableCommand, Window};
    let dir = tempfile::tempdir().unwrap();
    let rec = pair(dir.path());
    let top_file = dir.path().join("top.lut");
    let top_bytes = std::fs::read(&top_file).unwrap();
    let mut h = harness(vec![rec, top_file.clone()]);
    h.run();
    click_label(&mut h, "Stream");
    click_label(&mut h, "Cameras side by side");
    let panes = |h: &egui_kittest::Harness<'_, eotn::app::EotnApp>| {
        workspace(h)
            .camera_panes()
            .iter()
            .map(|p| (p.topic.to_owned(), p.focused, p.codes[0], p.lut.clone()))
            .collect::<Vec<_>>()
    };
    let first = panes(&h);
    assert_eq!(first.len(), 2);
    assert_eq!((first[0].0.as_str(), first[0].1), ("/camera/image", true));
    assert_eq!((first[1].0.as_str(), first[1].1), ("/camera/bottom", false));
    assert_eq!(first[0].2, ColourClass::Orange.code(), "top by top.lut");
    assert_eq!(
        first[1].2,
        ColourClass::Green.code(),
        "bottom by bottom.lut"
    );
    assert_eq!(h.state().last_panes.len(), 2, "both drawn");
    assert!(h.query_by_label("camera /camera/bottom").is_some());
    let bottom_table = first[1].3.clone();
    // The sensors window shows the focused camera's readings: the top's 11 cm.
    h.state_mut()
        .state
        .run(Command::ShowWindow(Window::Sensors, true));
    h.run();
    assert!(
        h.query_by_label_contains("camera /camera/image, frame 0")
            .is_some()
    );
    assert!(h.query_by_label_contains("11.0000").is_some());
    // A click on the bottom camera's pane focuses it and samples there; the commit goes to
    // its table only.
    h.state_mut()
        .state
        .run(TableCommand::SetClass(ColourClass::White).into());
    click_at(
        &h,
        pane_pixel(&h, "/camera/bottom", 2, 1),
        egui::PointerButton::Primary,
    );
    h.run();
    assert_eq!(shown(&h).as_deref(), Some("/camera/bottom"));
    assert_eq!(
        workspace(&h).selection().and_then(|s| s.pixel),
        Some((2, 1))
    );
    assert!(
        h.query_by_label_contains("camera /camera/bottom, frame 0")
            .is_some()
    );
    assert!(h.query_by_label_contains("22.0000").is_some());
    click_at(
        &h,
        pane_pixel(&h, "/camera/bottom", 2, 1),
        egui::PointerButton::Secondary,
    );
    h.run();
    let after = panes(&h);
    assert_eq!(
        (after[0].0.as_str(), after[1].0.as_str()),
        ("/camera/image", "/camera/bottom"),
        "the panes keep their places"
    );
    assert!(after[1].1, "bottom focused");
    assert_eq!(after[1].2, ColourClass::White.code(), "the edit in bottom");
    assert_ne!(after[1].3, bottom_table);
    assert_eq!(after[0].2, ColourClass::Orange.code(), "top unchanged");
    assert_eq!(after[0].3, first[0].3, "top's table unchanged");
    // Saved: bottom.lut has the edit, top.lut is byte-identical.
    h.state_mut().state.run(TableCommand::SaveTable.into());
    h.run();
    assert!(
        workspace(&h).warnings().is_empty(),
        "{:?}",
        workspace(&h).warnings()
    );
    assert_eq!(std::fs::read(&top_file).unwrap(), top_bytes);
    let bottom = LookupTable::load(&dir.path().join("bottom.lut")).unwrap();
    assert_eq!(bottom.class_of(Yuv::new(90, 128, 128)), ColourClass::White);
    // The bottom camera ends at 83 ms: stepping the top camera on, it shows its last frame,
    // marked as ended.
    let top = camera(&h, "/camera/image");
    h.state_mut().state.run(Command::FocusCamera(top));
    h.state_mut()
        .state
        .run(eotn::workspace::PlaybackCommand::Seek(5).into());
    h.run();
    assert!(
        h.query_by_label_contains("ended 0.12 s before the cursor")
            .is_some()
    );
}

/// `goal.mcap`: the first four frames of the shipped goalkeeper stream (a yellow goal) as two
/// cameras, `/camera/image` naming the shipped simulation table and `/camera/bottom` naming
/// none, so it starts with an empty table of its own.
fn goal_pair(dir: &std::path::Path) -> std::path::PathBuf {
    let mut source =
        eotn::streams::StreamReader::open(&crate::common::repo_file("streams/sim-goalkeeper.mcap"))
            .unwrap();
    let p = dir.join("goal.mcap");
    let mut w = StreamWriter::create(&p, &StreamInfo::default()).unwrap();
    let files = CameraFiles {
        lut: Some(crate::common::repo_file("lookup_tables/sim.lut")),
        ..CameraFiles::default()
    };
    w.name_camera_files("/camera/image", &files).unwrap();
    let ms = 1_000_000;
    for i in 0..4u64 {
        let read = source.read(usize::try_from(i).unwrap()).unwrap();
        for (topic, t) in [
            ("/camera/image", i * 40 * ms),
            ("/camera/bottom", i * 40 * ms + ms),
        ] {
            let mut r = FrameRecord::new(t, read.frame.clone());
            r.sensors = read.sensors;
            w.write_camera(topic, &r, None).unwrap();
        }
    }
    w.finish().unwrap();
    p
}

#[test]
fn each_pane_side_by_side_draws_its_own_camera_s_recognition() {
    use eotn::recognition::ObjectId;
    use eotn::workspace::Command;
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(vec![goal_pair(dir.path())]);
    h.run();
    click_label(&mut h, "Stream");
    click_label(&mut h, "Cameras side by side");
    let drawn = |h: &egui_kittest::Harness<'_, eotn::app::EotnApp>| {
        let panes = &h.state().last_panes;
        panes
            .iter()
            .map(|p| (p.topic.clone(), p.primitives))
            .collect::<Vec<_>>()
    };
    // The same frames: the top camera's table finds the goal, the bottom camera's empty table
    // nothing, and each pane draws its own camera's recognition.
    let goals = |h: &egui_kittest::Harness<'_, eotn::app::EotnApp>| {
        workspace(h)
            .camera_panes()
            .iter()
            .map(|p| {
                p.primitives
                    .iter()
                    .any(|q| matches!(q.owner(), ObjectId::Goal(..)))
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(goals(&h), [true, false]);
    let before = drawn(&h);
    assert_eq!(before.len(), 2);
    assert_eq!(
        (before[0].0.as_str(), before[1].0.as_str()),
        ("/camera/image", "/camera/bottom")
    );
    assert!(before[0].1 > before[1].1, "{before:?}");
    // Focused, the bottom camera is drawn by the enlarged view, the top beside it: each pane
    // still draws its own camera's primitives.
    let bottom = camera(&h, "/camera/bottom");
    h.state_mut().state.run(Command::FocusCamera(bottom));
    h.run();
    assert_eq!(goals(&h), [true, false]);
    assert_eq!(drawn(&h), before);
}

#[test]
fn a_live_robot_s_two_cameras_are_picked_and_shown_side_by_side_each_with_its_own_table() {
    use crate::harness::{click_at, harness_with, run_steps_until};
    use crate::robot_cameras::{live_camera_settings, two_camera_sender, whole_table};
    use eotn::workspace::{RobotsCommand, TableCommand, Workspace};
    const WITHIN: std::time::Duration = std::time::Duration::from_secs(30);
    // Five seconds of frames from the Foxglove SDK sender: /camera/image 64×48 and
    // /camera/bottom 32×24, each camera's table remembered for it.
    let Some((mut sender, address)) = two_camera_sender(150) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let top = whole_table(dir.path(), "top.lut", ColourClass::Orange);
    let bottom = whole_table(dir.path(), "bottom.lut", ColourClass::Green);
    let mut state = Workspace::new(live_camera_settings(&address, &top, &bottom));
    state
        .apply(RobotsCommand::ConnectRobot(address).into())
        .unwrap();
    let mut h = harness_with(state);
    run_steps_until(&mut h, WITHIN, |a| {
        a.state.cameras().0.len() == 2 && a.state.frame().is_some()
    });
    // Frames keep arriving, so the UI never settles: step, do not `run`.
    let click = |h: &mut egui_kittest::Harness<'_, eotn::app::EotnApp>, label: &str| {
        h.get_by_label(label).click();
        h.run_steps(4);
    };
    click(&mut h, "Stream");
    click(&mut h, "Camera of the robot");
    click(&mut h, "/camera/bottom");
    run_steps_until(&mut h, WITHIN, |a| {
        a.state.frame().is_some_and(|f| f.width() == 32)
    });
    assert_eq!(shown(&h).as_deref(), Some("/camera/bottom"));
    let table = workspace(&h).table_path().map(eotn::frame::display_name);
    assert_eq!(table.as_deref(), Some("bottom.lut"), "its own table");
    click(&mut h, "Stream");
    click(&mut h, "Cameras side by side");
    run_steps_until(&mut h, WITHIN, |a| {
        a.last_panes.len() == 2 && a.state.camera_panes().iter().all(|p| p.frame.is_some())
    });
    let panes = |h: &egui_kittest::Harness<'_, eotn::app::EotnApp>| {
        workspace(h)
            .camera_panes()
            .iter()
            .map(|p| (p.topic.to_owned(), p.codes[0], p.lut.clone()))
            .collect::<Vec<_>>()
    };
    let before = panes(&h);
    assert_eq!(
        (before[0].0.as_str(), before[0].1),
        ("/camera/image", ColourClass::Orange.code())
    );
    assert_eq!(
        (before[1].0.as_str(), before[1].1),
        ("/camera/bottom", ColourClass::Green.code())
    );
    // A click on the top camera's pane focuses it and samples there; the commit goes to its
    // table only.
    h.state_mut()
        .state
        .run(TableCommand::SetClass(ColourClass::White).into());
    click_at(
        &h,
        pane_pixel(&h, "/camera/image", 2, 1),
        egui::PointerButton::Primary,
    );
    h.run_steps(4);
    assert_eq!(shown(&h).as_deref(), Some("/camera/image"));
    click_at(
        &h,
        pane_pixel(&h, "/camera/image", 2, 1),
        egui::PointerButton::Secondary,
    );
    h.run_steps(4);
    let after = panes(&h);
    assert_ne!(
        after[0].2, before[0].2,
        "the edit in the top camera's table"
    );
    assert_eq!(
        after[1].2, before[1].2,
        "the bottom camera's table unchanged"
    );
    assert_eq!(
        after[1].2,
        LookupTable::load(&bottom).unwrap(),
        "still bottom.lut"
    );
    let _ = sender.kill();
    let _ = sender.wait();
}
