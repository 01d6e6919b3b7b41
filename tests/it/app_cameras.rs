//! The app's camera picker (issue 28): a recording with two cameras lists both under Stream ▸
//! Camera of the recording; picking one shows it at the same time with the table its recording
//! names for it, and a table opened then is remembered for that camera only.

use eotn::camera::{CameraFiles, CameraId};
use eotn::frame::{Frame, Yuv};
use eotn::lut::{ColourClass, LookupTable};
use eotn::streams::{FrameRecord, StreamInfo, StreamWriter};

use egui_kittest::kittest::Queryable as _;

use crate::harness::{click_label, harness, workspace};

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
    assert_eq!(workspace(&h).cameras().1, Some("/camera/image"));
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
    assert_eq!(workspace(&h).cameras().1, Some("/camera/bottom"));
    assert_eq!(name(&h), "bottom.lut", "the bottom camera's own table");
    let top = CameraId::recording("/camera/image");
    let bottom = CameraId::recording("/camera/bottom");
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
    let (_, xf) = panes
        .iter()
        .find(|(t, _)| t == topic)
        .unwrap_or_else(|| panic!("no pane of {topic}: {panes:?}"));
    xf.pixel_centre(x, y)
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
    let shown = panes(&h);
    assert_eq!(shown.len(), 2);
    assert_eq!((shown[0].0.as_str(), shown[0].1), ("/camera/image", true));
    assert_eq!((shown[1].0.as_str(), shown[1].1), ("/camera/bottom", false));
    assert_eq!(shown[0].2, ColourClass::Orange.code(), "top by top.lut");
    assert_eq!(
        shown[1].2,
        ColourClass::Green.code(),
        "bottom by bottom.lut"
    );
    assert_eq!(h.state().last_panes.len(), 2, "both drawn");
    assert!(h.query_by_label("camera /camera/bottom").is_some());
    let bottom_table = shown[1].3.clone();
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
    assert_eq!(workspace(&h).cameras().1, Some("/camera/bottom"));
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
    assert_eq!(after[0].3, shown[0].3, "top's table unchanged");
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
    h.state_mut()
        .state
        .run(Command::FocusCamera("/camera/image".into()));
    h.state_mut()
        .state
        .run(eotn::workspace::PlaybackCommand::Seek(5).into());
    h.run();
    assert!(
        h.query_by_label_contains("ended 0.12 s before the cursor")
            .is_some()
    );
}
