use crate::camera::CameraFiles;
use crate::frame::{Frame, Yuv};
use crate::lut::{ColourClass, LookupTable};
use crate::streams::{FrameRecord, StreamInfo, StreamWriter};
use crate::workspace::cameras::tests::{cam, cams, shown};
use crate::workspace::{Command, PlaybackCommand, Settings, TableCommand, Workspace};

const MS: u64 = 1_000_000;
const GREY: Yuv = Yuv::new(90, 128, 128);

/// `two.mcap`: `/camera/image` 8×4 at 25 fps (frames 0..10, every 40 ms) and `/camera/bottom`
/// 4×2 at 12.5 fps starting 5 ms later and ending early (frames 0..3, every 80 ms); the bottom
/// camera names `bottom.lut`. Tables `top.lut` (grey → orange) and `bottom.lut` (grey → green).
fn recording(dir: &std::path::Path) -> std::path::PathBuf {
    let p = dir.join("two.mcap");
    let mut w = StreamWriter::create(&p, &StreamInfo::default()).unwrap();
    let files = CameraFiles {
        lut: Some("bottom.lut".into()),
        params: Some("bottom.json".into()),
        ..CameraFiles::default()
    };
    w.name_camera_files("/camera/bottom", &files).unwrap();
    for i in 0..10u64 {
        let top = FrameRecord::new(i * 40 * MS, Frame::filled_uyvy(8, 4, GREY).unwrap());
        w.write_camera("/camera/image", &top, None).unwrap();
        if i < 3 {
            let bottom = FrameRecord::new(
                i * 80 * MS + 5 * MS,
                Frame::filled_uyvy(4, 2, GREY).unwrap(),
            );
            w.write_camera("/camera/bottom", &bottom, None).unwrap();
        }
    }
    w.finish().unwrap();
    for (name, class) in [
        ("top.lut", ColourClass::Orange),
        ("bottom.lut", ColourClass::Green),
    ] {
        let mut t = LookupTable::new(6).unwrap();
        let i = t.index(GREY);
        t.set(i, class);
        t.save(&dir.join(name)).unwrap();
    }
    std::fs::write(dir.join("bottom.json"), r#"{"ball": {"min_pixels": 77}}"#).unwrap();
    p
}

fn side_by_side(dir: &std::path::Path) -> Workspace {
    let rec = recording(dir);
    let mut ws = Workspace::new(Settings::default());
    ws.apply(Command::Open(vec![rec, dir.join("top.lut")]))
        .unwrap();
    ws.apply(Command::ShowSideBySide(cams(
        &ws,
        &["/camera/image", "/camera/bottom"],
    )))
    .unwrap();
    ws
}

/// (topic, frame index, class of the first pixel, note) of every pane.
fn panes(ws: &Workspace) -> Vec<(String, usize, u8, Option<String>)> {
    ws.camera_panes()
        .iter()
        .map(|p| {
            (
                p.topic.to_owned(),
                p.index,
                p.codes.first().copied().unwrap_or(0),
                p.note.map(str::to_owned),
            )
        })
        .collect()
}

#[test]
fn cameras_step_together_by_time_each_with_its_own_table() {
    let dir = tempfile::tempdir().unwrap();
    let mut ws = side_by_side(dir.path());
    let (orange, green) = (ColourClass::Orange.code(), ColourClass::Green.code());
    assert_eq!(
        panes(&ws),
        [
            ("/camera/image".into(), 0, orange, None),
            ("/camera/bottom".into(), 0, green, None),
        ]
    );
    assert!(ws.camera_panes()[0].focused && !ws.camera_panes()[1].focused);
    // Top frame 3 is at 120 ms: the bottom frames are at 5, 85, 165 ms; 85 is nearest.
    ws.apply(PlaybackCommand::Seek(3).into()).unwrap();
    assert_eq!(panes(&ws)[1].1, 1);
    // 160 ms: bottom frame 2 (165 ms), not the one before it.
    ws.apply(PlaybackCommand::Step(1).into()).unwrap();
    assert_eq!(panes(&ws)[1].1, 2);
    assert_eq!(panes(&ws)[1].3, None);
    // 360 ms: the bottom camera ended at 165 ms; its last frame is shown, said to have ended.
    ws.apply(PlaybackCommand::Seek(9).into()).unwrap();
    let bottom = &panes(&ws)[1];
    assert_eq!(bottom.1, 2);
    let note = bottom.3.clone().unwrap_or_default();
    assert!(note.starts_with("ended 0.20 s before the cursor"), "{note}");
}

#[test]
fn an_edit_goes_to_the_focused_camera_s_table_only() {
    let dir = tempfile::tempdir().unwrap();
    let mut ws = side_by_side(dir.path());
    let top_before = ws.camera_panes()[0].lut.clone();
    // A click on the bottom camera's pane focuses it, then samples there.
    ws.apply(Command::FocusCamera(cam(&ws, "/camera/bottom")))
        .unwrap();
    assert_eq!(shown(&ws), Some("/camera/bottom".to_owned()));
    assert_eq!(
        ws.table_path().map(crate::frame::display_name).as_deref(),
        Some("bottom.lut")
    );
    let order: Vec<_> = ws.camera_panes().iter().map(|p| p.topic).collect();
    assert_eq!(
        order,
        ["/camera/image", "/camera/bottom"],
        "panes keep their place"
    );
    ws.apply(TableCommand::SetClass(ColourClass::White).into())
        .unwrap();
    ws.apply(TableCommand::Sample { x: 1, y: 1 }.into())
        .unwrap();
    ws.apply(TableCommand::Commit.into()).unwrap();
    let panes = ws.camera_panes();
    assert_eq!(panes[1].codes[0], ColourClass::White.code());
    assert_eq!(panes[0].codes[0], ColourClass::Orange.code());
    assert_eq!(
        panes[0].lut, &top_before,
        "the top camera's table is unchanged"
    );
    assert!(panes[1].dirty && !panes[0].dirty);
    // Focus moves back: the top camera's own table, the bottom's edit kept beside it.
    ws.apply(Command::FocusCamera(cam(&ws, "/camera/image")))
        .unwrap();
    assert_eq!(ws.lut(), &top_before);
    assert_eq!(ws.unsaved_beside(), ["/camera/bottom"]);
    let e = ws.apply(Command::ShowSideBySide(Vec::new())).unwrap_err();
    assert!(format!("{e}").contains("unsaved edits"), "{e}");
    let e = ws.apply(Command::Open(vec![dir.path().join("two.mcap")]));
    assert!(
        e.is_err(),
        "another source would drop the unsaved bottom table"
    );
    assert_eq!(ws.camera_panes().len(), 2, "still side by side");
    // Saved through its own focus, the bottom table's file has the edit, top.lut not.
    ws.apply(Command::OpenCamera(Some(cam(&ws, "/camera/bottom"))))
        .unwrap();
    ws.apply(TableCommand::SaveTable.into()).unwrap();
    let saved = LookupTable::load(&dir.path().join("bottom.lut")).unwrap();
    assert_eq!(saved.class_of(GREY), ColourClass::White);
    let top = LookupTable::load(&dir.path().join("top.lut")).unwrap();
    assert_eq!(top, top_before);
    ws.apply(Command::ShowSideBySide(Vec::new())).unwrap();
    assert!(ws.camera_panes().is_empty());
}

#[test]
fn each_camera_side_by_side_recognises_with_its_own_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let mut ws = side_by_side(dir.path());
    let default_min = ws.recognition_params().ball.min_pixels;
    assert_ne!(default_min, 77);
    let named = |ws: &Workspace| -> Vec<Option<String>> {
        ws.camera_panes()
            .iter()
            .map(|p| p.params_path.map(crate::frame::display_name))
            .collect()
    };
    assert_eq!(named(&ws), [None, Some("bottom.json".to_owned())]);
    ws.apply(Command::FocusCamera(cam(&ws, "/camera/bottom")))
        .unwrap();
    assert_eq!(ws.recognition_params().ball.min_pixels, 77, "its own set");
    assert_eq!(named(&ws), [None, Some("bottom.json".to_owned())]);
    ws.apply(Command::FocusCamera(cam(&ws, "/camera/image")))
        .unwrap();
    assert_eq!(ws.recognition_params().ball.min_pixels, default_min);
}

#[test]
fn a_camera_without_a_table_of_its_own_gets_an_empty_one_not_another_s() {
    let dir = tempfile::tempdir().unwrap();
    let rec = recording(dir.path());
    std::fs::remove_file(dir.path().join("bottom.lut")).unwrap();
    let mut ws = Workspace::new(Settings::default());
    ws.apply(Command::Open(vec![rec, dir.path().join("top.lut")]))
        .unwrap();
    ws.run(Command::ShowSideBySide(cams(
        &ws,
        &["/camera/image", "/camera/bottom"],
    )));
    let panes = ws.camera_panes();
    assert_eq!(panes.len(), 2, "{:?}", ws.warnings());
    assert_eq!(panes[1].codes[0], 0, "unclassified by an empty table");
    assert!(panes[1].table_path.is_none());
    assert!(
        ws.warnings()
            .iter()
            .any(|w| w.contains("camera /camera/bottom has no table of its own")),
        "{:?}",
        ws.warnings()
    );
}

#[test]
fn unknown_cameras_and_sources_without_cameras_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut ws = side_by_side(dir.path());
    let e = ws
        .apply(Command::ShowSideBySide(cams(
            &ws,
            &["/camera/image", "/camera/side"],
        )))
        .unwrap_err();
    let text = format!("{e:#}");
    assert!(text.contains("/camera/image, /camera/bottom"), "{text}");
    assert_eq!(ws.camera_panes().len(), 2, "unchanged");
    let e = ws.apply(Command::FocusCamera(cam(&ws, "/camera/side")));
    assert!(e.is_err());
    let mut empty = Workspace::new(Settings::default());
    assert!(
        empty
            .apply(Command::ShowSideBySide(cams(&empty, &["/a", "/b"])))
            .is_err()
    );
}

#[test]
fn a_frame_size_change_is_a_warning_line_and_each_frame_is_shown_as_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("resized.mcap");
    let mut w = StreamWriter::create(&p, &StreamInfo::default()).unwrap();
    for i in 0..4u64 {
        let (fw, fh) = if i < 2 { (8, 4) } else { (16, 8) };
        let top = FrameRecord::new(i * 40 * MS, Frame::filled_uyvy(fw, fh, GREY).unwrap());
        w.write_camera("/camera/image", &top, None).unwrap();
        let bottom = FrameRecord::new(i * 40 * MS, Frame::filled_uyvy(fw, fh, GREY).unwrap());
        w.write_camera("/camera/bottom", &bottom, None).unwrap();
    }
    w.finish().unwrap();
    let mut ws = Workspace::new(Settings::default());
    ws.apply(Command::Open(vec![p])).unwrap();
    ws.run(Command::ShowSideBySide(cams(
        &ws,
        &["/camera/image", "/camera/bottom"],
    )));
    ws.apply(PlaybackCommand::Seek(3).into()).unwrap();
    for pane in ws.camera_panes() {
        let f = pane.frame.unwrap();
        assert_eq!((f.width(), f.height()), (16, 8), "{}", pane.topic);
        assert_eq!(pane.rgb.len(), 16 * 8 * 3);
    }
    for topic in ["/camera/image", "/camera/bottom"] {
        let line = format!("camera {topic}: the frame size changes from 8×4 to 16×8 at frame 3");
        assert!(
            ws.warnings().iter().any(|w| w.starts_with(&line)),
            "{line}: {:?}",
            ws.warnings()
        );
    }
}
