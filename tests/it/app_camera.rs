//! The Camera menu and its dialogs driven headlessly with egui_kittest: connect a synthetic
//! scenario through the Connect dialog, see its frames arrive, open Settings, record into a typed
//! path, stop, and read the recording back; disconnect.

use std::time::Duration;

use egui_kittest::kittest::Queryable as _;
use eotn::app::EotnApp;
use eotn::sources::{CameraKind, FrameSource as _, RecordedSource as _, StreamSource};
use eotn::workspace::Window;

use crate::harness::{click_label, harness, run_until};

/// How long a connected source may take to deliver what a step waits for.
const WITHIN: Duration = Duration::from_secs(60);

#[test]
fn camera_menu_connects_a_scenario_records_it_and_disconnects() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Vec::new());
    h.run();
    click_label(&mut h, "Camera");
    assert!(h.query_by_label("nothing connected").is_some());
    click_label(&mut h, "Connect…");
    assert!(h.state().state.window_open(Window::Connect));
    click_label(&mut h, "synthetic");
    click_label(&mut h, "Connect");
    assert!(
        !h.state().state.window_open(Window::Connect),
        "connecting closes the dialog"
    );
    let live = |a: &EotnApp| a.state.live().map_or(0, |l| l.frames());
    run_until(&mut h, WITHIN, |a| live(a) >= 1);
    assert_eq!(h.state().state.camera_kind(), CameraKind::Robot);
    assert!(h.state().state.frame().is_some());

    // Settings… shows what the source delivers.
    click_label(&mut h, "Camera");
    click_label(&mut h, "Settings…");
    assert!(h.state().state.window_open(Window::SourceSettings));
    assert!(h.query_by_label("208×160").is_some(), "{:#?}", h.root());

    // Start recording… asks for the file; a typed path works (no file dialog needed).
    let out = dir.path().join("camera.mcap");
    click_label(&mut h, "Camera");
    click_label(&mut h, "Start recording…");
    h.state_mut().camera.record_path.clear();
    h.run();
    let field = h.get_by_label("file");
    field.focus();
    field.type_text(&out.display().to_string());
    h.run();
    click_label(&mut h, "Start recording");
    assert_eq!(h.state().state.recording(), Some(out.clone()));
    let at = live(h.state());
    run_until(&mut h, WITHIN, |a| live(a) >= at + 3);
    click_label(&mut h, "Camera");
    h.get_by_label("Stop recording").click();
    run_until(&mut h, WITHIN, |_| out.exists());
    let back = StreamSource::open(&out).unwrap();
    assert!(back.len() >= 2, "{} frames recorded", back.len());
    assert_eq!(back.info().stream_source, "sim:walk-and-pan");

    click_label(&mut h, "Camera");
    click_label(&mut h, "Disconnect");
    assert!(h.state().state.live().is_none());
}

#[test]
fn camera_connect_dialog_lists_no_camera_in_one_line_and_opens_a_typed_stream() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("s.mcap");
    let ok = std::process::Command::new(env!("CARGO_BIN_EXE_eotn"))
        .args(["sim", "--scenario", "overhead-game", "--frames", "2", "-o"])
        .arg(&stream)
        .status()
        .unwrap();
    assert!(ok.success());
    let mut h = harness(Vec::new());
    h.state_mut()
        .state
        .run(eotn::workspace::Command::ShowWindow(Window::Connect, true));
    h.run();
    click_label(&mut h, "camera");
    if eotn::sources::available().cameras.is_empty() {
        assert!(h.query_by_label_contains("no camera found").is_some());
    }
    click_label(&mut h, "stream");
    let field = h.get_by_label("stream file");
    field.focus();
    field.type_text(&stream.display().to_string());
    h.run();
    click_label(&mut h, "Connect");
    let s = &h.state().state;
    assert_eq!(s.source().map(|s| s.len()), Some(2), "{:?}", s.warnings());
    assert_eq!(s.camera_kind(), CameraKind::Overhead);
    assert_eq!(s.table_kind(), CameraKind::Overhead);
}
