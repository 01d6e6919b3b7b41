//! The app watching a robot: Camera ▸ Connect… ▸ network to an `eotn serve` stand-in robot,
//! driven headlessly with egui_kittest; its frames arrive in the app state with their sensors.

use std::time::{Duration, Instant};

use egui::Vec2;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use eotn::app::EotnApp;
use eotn::sources::{CameraKind, SourceKind};
use eotn::workspace::Window;

use crate::live::{serve, sim_stream};

#[test]
fn camera_connect_to_a_robot_served_by_eotn_serve_shows_its_frames() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), 10);
    let served = serve(&stream, "127.0.0.1:0", &["--loop"]);
    let mut h: Harness<'static, EotnApp> = Harness::builder()
        .with_size(Vec2::new(1200.0, 800.0))
        .build_eframe(|cc| EotnApp::new(cc, Vec::new()));
    h.run();
    h.get_by_label("Camera").click();
    h.run();
    h.get_by_label("Connect…").click();
    h.run();
    assert!(h.state().state.window_open(Window::Connect));
    h.get_by_label("network").click();
    h.run();
    h.state_mut().camera.address.clear();
    h.run();
    let field = h.get_by_label("address");
    field.focus();
    field.type_text(&format!("ws://127.0.0.1:{}", served.port));
    h.run();
    h.get_by_label("Connect").click();
    h.run();
    let frames = |a: &EotnApp| a.state.live().map_or(0, |l| l.frames());
    let start = Instant::now();
    while frames(h.state()) < 5 {
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "{:?}",
            h.state().state.warnings()
        );
        h.run();
        std::thread::sleep(Duration::from_millis(10));
    }
    let info = h.state().state.connected_info().unwrap();
    assert_eq!(info.kind, SourceKind::Network);
    assert!(info.label.starts_with("robot "), "{}", info.label);
    assert_eq!(h.state().state.camera_kind(), CameraKind::Robot);
    assert!(h.state().state.frame().is_some());
    h.get_by_label("Camera").click();
    h.run();
    h.get_by_label("Disconnect").click();
    h.run();
    assert!(h.state().state.live().is_none());
}
