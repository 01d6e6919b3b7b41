//! The app watching a robot: Camera ▸ Connect… ▸ network to an `eotn serve` stand-in robot,
//! driven headlessly with egui_kittest; its frames arrive in the app state with their sensors.
//! Camera ▸ Connect to robot…: two robots at once in the robots window, clicking one shows it,
//! the Live switch holds the view while frames keep arriving, Record all writes one file each
//! and moves no button (Stop where Record was), Disconnect asks for a second click.
//! A robot that sends garbage gets one orange line in the robots window.

use std::time::Duration;

use egui::Vec2;
use egui_kittest::kittest::Queryable as _;
use eotn::app::EotnApp;
use eotn::sources::{CameraKind, SourceKind};
use eotn::workspace::Window;

use crate::common::sim_stream;
use crate::harness::{click_label, harness, harness_sized, run_steps_until, run_until};
use crate::live::serve;
use crate::live_peers::{Peer, garbage};

/// How long a robot may take to deliver what a step waits for.
const WITHIN: Duration = Duration::from_secs(30);

#[test]
fn camera_connect_to_a_robot_served_by_eotn_serve_shows_its_frames() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 10, None);
    let served = serve(&stream, "127.0.0.1:0", &["--loop"]);
    let mut h = harness(Vec::new());
    h.run();
    click_label(&mut h, "Camera");
    click_label(&mut h, "Connect…");
    assert!(h.state().state.window_open(Window::Connect));
    click_label(&mut h, "network");
    h.state_mut().camera.address.clear();
    h.run();
    let field = h.get_by_label("address");
    field.focus();
    field.type_text(&format!("ws://127.0.0.1:{}", served.port));
    h.run();
    // Frames keep arriving once connected, so the UI never settles: step, do not `run`.
    h.get_by_label("Connect").click();
    h.run_steps(4);
    // Connect… ▸ network puts the robot into the robots list, shown at once.
    let frames = |a: &EotnApp| a.state.robots().first().map_or(0, |r| r.stats.frames);
    run_until(&mut h, WITHIN, |a| {
        frames(a) >= 5 && a.state.frame().is_some()
    });
    let info = h.state().state.connected_info().unwrap();
    assert_eq!(info.kind, SourceKind::Network);
    assert!(info.label.starts_with("robot "), "{}", info.label);
    assert_eq!(h.state().state.camera_kind(), CameraKind::Robot);
    assert!(h.state().state.shown_robot().is_some());
    h.get_by_label("Camera").click();
    h.run_steps(4);
    click_label(&mut h, "Disconnect");
    assert!(h.state().state.robots().is_empty());
    assert!(h.state().state.connected_info().is_none());
}

fn robot_frames(a: &EotnApp, name: &str) -> usize {
    a.state
        .robots()
        .iter()
        .find(|r| r.name == name)
        .map_or(0, |r| r.stats.frames)
}

#[test]
fn two_robots_connected_from_the_robots_window_are_listed_and_clicking_one_shows_it() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 10, None);
    let alpha = serve(&stream, "127.0.0.1:0", &["--loop", "--name", "alpha"]);
    let bravo = serve(&stream, "127.0.0.1:0", &["--loop", "--name", "bravo"]);
    let mut h = harness_sized(Vec::new(), Vec2::new(1280.0, 800.0));
    h.run_steps(4);
    h.get_by_label("Camera").click();
    h.run_steps(4);
    h.get_by_label("Connect to robot…").click();
    h.run_steps(4);
    assert!(h.state().state.window_open(Window::Robots));
    for port in [alpha.port, bravo.port] {
        h.state_mut().robots.address.clear();
        h.run_steps(4);
        let field = h.get_by_label("address");
        field.focus();
        field.type_text(&format!("127.0.0.1:{port}"));
        h.run_steps(4);
        h.get_by_label("Connect robot").click();
        h.run_steps(4);
    }
    run_steps_until(&mut h, WITHIN, |a| {
        robot_frames(a, "alpha") >= 3 && robot_frames(a, "bravo") >= 3
    });
    let rows = h.state().state.robots();
    assert_eq!(rows.len(), 2);
    assert!(rows[0].shown && !rows[1].shown, "the first robot is shown");
    assert!(h.state().state.frame().is_some());
    // The list shows each robot's state and figures.
    assert!(h.query_all_by_label("connected").count() >= 2);

    h.get_by_label("bravo").click();
    h.run_steps(4);
    assert_eq!(h.state().state.shown_robot(), Some(rows[1].id));
    assert!(
        h.state().state.title().contains("robot bravo"),
        "{}",
        h.state().state.title()
    );
    // Alpha, not shown, keeps receiving.
    let before = robot_frames(h.state(), "alpha");
    run_steps_until(&mut h, WITHIN, |a| robot_frames(a, "alpha") > before + 2);

    // The Live switch holds the view; frames keep arriving; Live again shows the newest.
    run_steps_until(&mut h, WITHIN, |a| a.state.frame().is_some());
    // (The switch is in the timeline and in the robots window.)
    h.get_all_by_label("Live").next().unwrap().click();
    h.run_steps(4);
    assert!(!h.state().state.following_live());
    let held = h.state().state.index();
    let received = robot_frames(h.state(), "bravo");
    run_steps_until(&mut h, WITHIN, |a| robot_frames(a, "bravo") > received + 2);
    assert_eq!(h.state().state.index(), held, "the view is held");
    h.get_all_by_label("Live").next().unwrap().click();
    h.run_steps(4);
    assert!(h.state().state.following_live());
    assert!(h.state().state.index() > held);

    // Record all: one file per robot, named after it.
    let folder = dir.path().join("rec");
    h.state_mut().robots.folder = folder.display().to_string();
    h.run_steps(4);
    let rect_of = |h: &egui_kittest::Harness<'_, EotnApp>, label: &str| {
        h.get_all_by_label(label).next().unwrap().rect()
    };
    let (record, disconnect) = (rect_of(&h, "Record"), rect_of(&h, "Disconnect"));
    h.get_by_label("Record all").click();
    h.run_steps(4);
    run_steps_until(&mut h, WITHIN, |a| {
        a.state
            .robots()
            .iter()
            .all(|r| r.stats.recorded.is_some_and(|n| n >= 2))
    });
    // Nothing moved under the cursor: Stop is where Record was, Disconnect where it was.
    assert_eq!(rect_of(&h, "Stop recording"), record);
    assert_eq!(rect_of(&h, "Disconnect"), disconnect);
    // One click on Disconnect only asks; Cancel keeps the robot.
    h.get_all_by_label("Disconnect").next().unwrap().click();
    h.run_steps(4);
    assert_eq!(h.state().state.robots().len(), 2);
    h.get_by_label("Cancel").click();
    h.run_steps(4);
    assert!(h.query_by_label("Confirm disconnect").is_none());
    for _ in 0..2 {
        // The list may be taller than its dock tab: bring the button into view, as a user scrolls.
        h.get_all_by_label("Disconnect")
            .next()
            .unwrap()
            .scroll_to_me();
        h.run_steps(4);
        h.get_all_by_label("Disconnect").next().unwrap().click();
        h.run_steps(4);
        h.get_by_label("Confirm disconnect").click();
        h.run_steps(4);
    }
    assert!(h.state().state.robots().is_empty());
    for name in ["alpha", "bravo"] {
        let r = eotn::streams::StreamReader::open(&folder.join(format!("{name}.mcap"))).unwrap();
        assert!(r.len() >= 2, "{name}: {} frames", r.len());
    }
}

#[test]
fn a_robot_that_sends_garbage_gets_one_line_in_the_robots_window_and_disconnects_at_once() {
    let peer = Peer::start(garbage);
    let mut h = harness_sized(Vec::new(), Vec2::new(1280.0, 800.0));
    h.run_steps(4);
    h.get_by_label("Camera").click();
    h.run_steps(4);
    h.get_by_label("Connect to robot…").click();
    h.run_steps(4);
    h.state_mut().robots.address.clear();
    h.run_steps(4);
    let field = h.get_by_label("address");
    field.focus();
    field.type_text(&peer.address());
    h.run_steps(4);
    h.get_by_label("Connect robot").click();
    h.run_steps(4);
    run_steps_until(&mut h, WITHIN, |a| {
        a.state
            .robots()
            .first()
            .is_some_and(|r| r.stats.problem.is_some())
    });
    // The robot gone, its line stays (and stops counting).
    drop(peer);
    std::thread::sleep(Duration::from_millis(300));
    h.run_steps(4);
    // One line, under the robot (its state line may say the same while it reconnects).
    let problem = h.state().state.robots()[0].stats.problem.clone().unwrap();
    assert!(!problem.contains('\n'), "{problem}");
    assert_eq!(h.query_all_by_label(&problem).count(), 1, "{problem}");
    h.get_by_label("Disconnect").click();
    h.run_steps(2);
    h.get_by_label("Confirm disconnect").click();
    h.run_steps(2);
    assert!(h.state().state.robots().is_empty());
}
