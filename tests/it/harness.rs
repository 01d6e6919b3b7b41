//! Helpers shared by the app tests (egui_kittest drives the real app through the same
//! `Workspace`/`Command` path as the window): one way to build the harness, read its workspace,
//! find and click a pixel of the enlarged view, close the window, run frames until something
//! holds; the small synthetic field the table tests classify, and streams written from records.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use egui::{Event, Modifiers, PointerButton, Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use eotn::app::EotnApp;
use eotn::frame::{Frame, Yuv};
use eotn::lut::{ColourClass, EditRecord, LookupTable, Region, Sensitivity};
use eotn::workspace::{Command, Window, Workspace};

/// The field's green.
pub const GREEN: Yuv = Yuv::new(100, 110, 100);
/// The ball's orange.
pub const ORANGE: Yuv = Yuv::new(120, 80, 190);
/// The goal's yellow.
pub const YELLOW: Yuv = Yuv::new(190, 40, 150);

/// The window size most app tests use, points.
pub const WINDOW: Vec2 = Vec2::new(1200.0, 800.0);

/// A 208×160 field: green everywhere, an orange 20×20 ball whose place depends on `n`, a
/// yellow goal bar on the left.
pub fn scene(n: usize) -> Frame {
    Frame::uyvy_from_fn(208, 160, |x, y| {
        let bx = 60 + 10 * n;
        if (bx..bx + 20).contains(&x) && (40..60).contains(&y) {
            ORANGE
        } else if x < 12 && (20..100).contains(&y) {
            YELLOW
        } else {
            GREEN
        }
    })
    .unwrap()
}

/// Three frame files of [`scene`] and a 7-bit table with green and yellow classified, orange
/// not.
pub fn fixture(dir: &Path) -> (Vec<PathBuf>, PathBuf) {
    let mut frames = Vec::new();
    for n in 0..3 {
        let p = dir.join(format!("f{n}.uyvy"));
        std::fs::write(&p, scene(n).data()).unwrap();
        frames.push(p);
    }
    let mut lut = LookupTable::new(7).unwrap();
    for (class, sample) in [(ColourClass::Green, GREEN), (ColourClass::Yellow, YELLOW)] {
        lut.apply(EditRecord::now(
            class,
            Region::AroundSample {
                sample,
                sensitivity: Sensitivity::uniform(2),
            },
        ));
    }
    let table = dir.join("field.lut");
    lut.save(&table).unwrap();
    (frames, table)
}

/// The files of [`fixture`] as the command line gives them: the frames, then the table.
pub fn fixture_files(dir: &Path) -> Vec<PathBuf> {
    let (mut paths, table) = fixture(dir);
    paths.push(table);
    paths
}

/// A workspace (no window) with the files of [`fixture`] open.
pub fn opened_fixture(dir: &Path) -> Workspace {
    let mut w = Workspace::default();
    w.apply(Command::Open(fixture_files(dir))).unwrap();
    w
}

/// The app in a [`WINDOW`]-sized window, opening `paths` as the command line would.
pub fn harness(paths: Vec<PathBuf>) -> Harness<'static, EotnApp> {
    harness_sized(paths, WINDOW)
}

/// The app in a window of `size` points, opening `paths` as the command line would.
pub fn harness_sized(paths: Vec<PathBuf>, size: Vec2) -> Harness<'static, EotnApp> {
    Harness::builder()
        .with_size(size)
        .build_eframe(move |cc| EotnApp::new(cc, paths.clone(), None))
}

/// The app in a [`WINDOW`]-sized window around a workspace made beforehand.
pub fn harness_with(w: Workspace) -> Harness<'static, EotnApp> {
    Harness::builder()
        .with_size(WINDOW)
        .build_eframe(move |_| EotnApp::with_state(w))
}

/// The app around a workspace made beforehand, in a window of `size` points drawn by wgpu: for
/// snapshots.
pub fn snapshot_harness(w: Workspace, size: Vec2) -> Harness<'static, EotnApp> {
    Harness::builder()
        .with_size(size)
        .wgpu()
        .build_eframe(move |_| EotnApp::with_state(w))
}

/// The app's workspace.
pub fn workspace<'h>(h: &'h Harness<'_, EotnApp>) -> &'h Workspace {
    &h.state().state
}

/// Where pixel (x, y) of the enlarged view is on screen.
pub fn pixel_pos(h: &Harness<'_, EotnApp>, x: usize, y: usize) -> Pos2 {
    h.state()
        .last_view
        .expect("the view was drawn")
        .pixel_centre(x, y)
}

/// Moves the pointer to `pos` and presses and releases `button` there.
pub fn click_at(h: &Harness<'_, EotnApp>, pos: Pos2, button: PointerButton) {
    h.event(Event::PointerMoved(pos));
    for pressed in [true, false] {
        h.event(Event::PointerButton {
            pos,
            button,
            pressed,
            modifiers: Modifiers::NONE,
        });
    }
}

/// Clicks the widget labelled `label` (which must be there, once) and runs the UI until it
/// settles.
pub fn click_label(h: &mut Harness<'_, EotnApp>, label: &str) {
    h.get_by_label(label).click();
    h.run();
}

/// Opens `window` through the command the Windows menu sends, and runs the UI until it settles.
pub fn show_window(h: &mut Harness<'_, EotnApp>, window: Window) {
    h.state_mut().state.run(Command::ShowWindow(window, true));
    h.run();
}

/// Asks the window to close, as its close button does (the app may ask first).
pub fn close_window(h: &mut Harness<'_, EotnApp>) {
    h.input_mut()
        .viewports
        .entry(egui::ViewportId::ROOT)
        .or_default()
        .events
        .push(egui::ViewportEvent::Close);
}

/// Runs UI frames (each until the UI settles) until `done` holds, failing after `within` of wall
/// time with the workspace's warnings; work arriving from other threads (a source's frames, a
/// scan) gets 10 ms between frames.
pub fn run_until(h: &mut Harness<'_, EotnApp>, within: Duration, done: impl Fn(&EotnApp) -> bool) {
    wait_until(h, within, done, |h| {
        h.run();
    });
}

/// [`run_until`] for a UI that keeps repainting while frames arrive (a live robot): four steps
/// a time instead of waiting for it to settle.
pub fn run_steps_until(
    h: &mut Harness<'_, EotnApp>,
    within: Duration,
    done: impl Fn(&EotnApp) -> bool,
) {
    wait_until(h, within, done, |h| h.run_steps(4));
}

fn wait_until(
    h: &mut Harness<'_, EotnApp>,
    within: Duration,
    done: impl Fn(&EotnApp) -> bool,
    mut step: impl FnMut(&mut Harness<'_, EotnApp>),
) {
    let start = Instant::now();
    while !done(h.state()) {
        assert!(
            start.elapsed() < within,
            "not done within {within:?}; warnings: {:?}",
            h.state().state.warnings()
        );
        step(h);
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Writes `records` into a new stream at `path` recorded from `source` (`"robot"`,
/// `"sim:pattern-tour"`, …, which tells the camera kind); returns the path.
pub fn write_stream(
    path: &Path,
    source: &str,
    records: impl IntoIterator<Item = eotn::streams::FrameRecord>,
) -> PathBuf {
    let info = eotn::streams::StreamInfo {
        source: source.to_owned(),
        description: "test stream".to_owned(),
    };
    let mut w = eotn::streams::StreamWriter::create(path, &info).unwrap();
    for r in records {
        w.write(&r).unwrap();
    }
    w.finish().unwrap();
    path.to_owned()
}
