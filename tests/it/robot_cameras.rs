//! A live robot's two cameras (issue 28), sent by the official Foxglove SDK
//! (`foxglove_sender.py --bottom`: 64×48 frames on `/camera/image`, 32×24 on `/camera/bottom`,
//! each camera's readings on its own channel), through the same `Command`s the app sends: the
//! camera picker lists both, each camera opens with the table remembered for it
//! (`CameraId::Live`), and side by side each pane shows its own camera's frame nearest the
//! focused one's, classified with its own table.

use std::path::{Path, PathBuf};
use std::process::{Child, Command as Process, Stdio};

use eotn::camera::{CameraFiles, CameraId};
use eotn::live::RobotUrl;
use eotn::lut::{ColourClass, LookupTable};
use eotn::workspace::{Command, PlaybackCommand, RobotsCommand, Settings, Workspace};

use crate::robots::tick_until;

/// The SDK sender with a second camera, `frames` frames of each at 30 fps once a viewer
/// subscribes; `None` (skipped, said) without the Python packages. Kill it when done.
pub fn two_camera_sender(frames: usize) -> Option<(Child, String)> {
    let python = crate::common::python_with_foxglove()?;
    let port = crate::live::free_port();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/it/foxglove_sender.py");
    let child = Process::new(python)
        .arg(script)
        .args(["--port", &port.to_string(), "--frames", &frames.to_string()])
        .arg("--bottom")
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    Some((child, format!("ws://127.0.0.1:{port}")))
}

/// A table that classifies every colour as `class`, saved at `dir/name`.
pub fn whole_table(dir: &Path, name: &str, class: ColourClass) -> PathBuf {
    let mut t = LookupTable::new(6).unwrap();
    for i in 0..t.cells().len() {
        t.set(i, class);
    }
    let p = dir.join(name);
    t.save(&p).unwrap();
    p
}

/// Settings remembering `top` for the robot's `/camera/image` and `bottom` for its
/// `/camera/bottom`, as the app remembers a live robot's cameras' tables.
pub fn live_camera_settings(address: &str, top: &Path, bottom: &Path) -> Settings {
    let robot = address.parse::<RobotUrl>().unwrap().to_string();
    let mut settings = Settings::default();
    for (topic, lut) in [("/camera/image", top), ("/camera/bottom", bottom)] {
        let files = CameraFiles {
            lut: Some(lut.to_owned()),
            ..CameraFiles::default()
        };
        settings
            .cameras
            .insert(CameraId::live(&robot, topic), files);
    }
    settings
}

/// The sender's frame number of a frame: byte 0 is 3 i (top) or 5 i (bottom) mod 256.
fn sent_number(w: usize, data: &[u8]) -> usize {
    let step = if w == 64 { 3 } else { 5 };
    (0..256)
        .find(|i| (i * step) % 256 == usize::from(data[0]))
        .unwrap_or(usize::MAX)
}

#[test]
fn a_robot_s_two_cameras_are_picked_and_shown_side_by_side_each_with_its_own_table() {
    // 120 frames: four seconds of frames to look at while they arrive.
    let Some((mut sender, address)) = two_camera_sender(120) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let top = whole_table(dir.path(), "top.lut", ColourClass::Orange);
    let bottom = whole_table(dir.path(), "bottom.lut", ColourClass::Green);
    let mut w = Workspace::new(live_camera_settings(&address, &top, &bottom));
    w.apply(RobotsCommand::ConnectRobot(address).into())
        .unwrap();
    let both = tick_until(&mut w, 30.0, |w| {
        w.cameras().0.len() == 2 && w.frame().is_some()
    });
    assert!(both, "cameras {:?}", w.cameras().0);
    let (cameras, shown) = w.cameras();
    let topics: Vec<&str> = cameras.iter().map(CameraId::topic).collect();
    assert_eq!(topics, ["/camera/image", "/camera/bottom"]);
    assert!(
        matches!(&cameras[1], CameraId::Live { .. }),
        "{}",
        cameras[1]
    );
    assert_eq!(shown.as_ref(), Some(&cameras[0]));
    let table = |w: &Workspace| w.table_path().map(eotn::frame::display_name);
    assert_eq!(table(&w).as_deref(), Some("top.lut"), "remembered for it");
    // The picker: the bottom camera's own frames, readings and table.
    w.apply(Command::OpenCamera(Some(cameras[1].clone())))
        .unwrap();
    let small = tick_until(&mut w, 10.0, |w| w.frame().is_some_and(|f| f.width() == 32));
    assert!(small, "{:?}", w.frame().map(|f| (f.width(), f.height())));
    assert_eq!(table(&w).as_deref(), Some("bottom.lut"));
    let pan = w
        .current()
        .and_then(|c| c.sensors)
        .and_then(|s| s.head_pan_rad);
    assert!(
        pan.is_some_and(|p| p <= 0.0),
        "the bottom camera's readings: {pan:?}"
    );
    // Side by side: each pane its own camera, frame and table.
    w.apply(Command::ShowSideBySide(cameras.clone())).unwrap();
    let paired = tick_until(&mut w, 10.0, |w| {
        w.camera_panes().iter().all(|p| p.frame.is_some())
    });
    assert!(paired, "{:?}", w.warnings());
    let panes = w.camera_panes();
    let summary: Vec<(&str, usize, u8)> = panes
        .iter()
        .map(|p| (p.topic, p.frame.map_or(0, |f| f.width()), p.codes[0]))
        .collect();
    assert_eq!(
        summary,
        [
            ("/camera/image", 64, ColourClass::Orange.code()),
            ("/camera/bottom", 32, ColourClass::Green.code()),
        ]
    );
    assert!(panes[1].focused, "the camera shown stays focused");
    drop(panes);
    // Held, stepping the focused camera: the other shows the frame sent with it (nearest by
    // arrival), within one frame.
    tick_until(&mut w, 10.0, |w| w.source().is_some_and(|s| s.len() >= 20));
    w.apply(RobotsCommand::SetFollowLive(false).into()).unwrap();
    let first = w.source().map_or(0, eotn::workspace::Source::first_index);
    for index in [first + 3, first + 8, first + 13] {
        w.apply(PlaybackCommand::Seek(index).into()).unwrap();
        let panes = w.camera_panes();
        let numbers: Vec<usize> = panes
            .iter()
            .filter_map(|p| p.frame.map(|f| sent_number(f.width(), f.data())))
            .collect();
        assert_eq!(numbers.len(), 2);
        assert!(
            numbers[0].abs_diff(numbers[1]) <= 1,
            "frame {index}: {numbers:?}"
        );
    }
    let _ = sender.kill();
    let _ = sender.wait();
}
