//! The desktop app driven headlessly with egui_kittest: the real `EotnApp` and `Workspace`, real
//! clicks and keys, assertions on state, on the saved table's bytes and on the journal.

use std::path::{Path, PathBuf};

use egui::{Event, Key, Modifiers, PointerButton, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use eotn::app::EotnApp;
use eotn::lut::{ColourClass, Sensitivity};
use eotn::recognition::ObjectId;
use eotn::workspace::journal;
use eotn::workspace::{
    Command, PlaybackCommand, TableCommand, ViewCommand, ViewKind, Window, Workspace,
};

use crate::common::repo_file;
use crate::harness::{
    ORANGE, click_at, click_label, close_window, fixture, fixture_files, harness, opened_fixture,
    pixel_pos, scene, show_window, snapshot_harness, workspace, write_stream,
};

#[test]
fn step_switch_views_zoom_pan_classify_undo_save() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, table) = fixture(dir.path());
    let mut paths = frames;
    paths.push(table.clone());
    let mut h = harness(paths);
    h.run();
    assert!(
        workspace(&h).warnings().is_empty(),
        "{:?}",
        workspace(&h).warnings()
    );
    assert_eq!(workspace(&h).source().unwrap().len(), 3);
    assert_eq!(workspace(&h).table_path(), Some(table.as_path()));

    // Step with the arrow keys and the timeline button.
    h.key_press(Key::ArrowRight);
    h.run();
    assert_eq!(workspace(&h).index(), 1);
    click_label(&mut h, "Next");
    assert_eq!(workspace(&h).index(), 2);
    h.key_press(Key::ArrowRight);
    h.run();
    assert_eq!(workspace(&h).index(), 2, "stepping stops at the last frame");
    h.key_press(Key::Home);
    h.run();
    assert_eq!(workspace(&h).index(), 0);

    // Thumbnails swap with the enlarged view.
    click_label(&mut h, "Classified");
    assert_eq!(workspace(&h).settings.main_view, ViewKind::Classified);
    click_label(&mut h, "Raw");
    assert_eq!(workspace(&h).settings.main_view, ViewKind::Raw);

    // Overlays switch.
    let mut o = workspace(&h).settings.overlays;
    o.classified = true;
    o.opacity = 0.7;
    h.state_mut().state.run(ViewCommand::SetOverlays(o).into());
    h.run();
    assert!(workspace(&h).settings.overlays.classified);

    // Hover readout.
    let ball = pixel_pos(&h, 65, 45);
    h.event(Event::PointerMoved(ball));
    h.run();
    let info = h.state().hovered().copied().expect("hovering a pixel");
    assert_eq!((info.x, info.y, info.yuv), (65, 45, ORANGE));
    assert_eq!(info.class, ColourClass::Unclassified);

    // Zoom about the cursor: the pixel under it stays under it.
    h.event(Event::Zoom(2.0));
    h.run();
    let z = workspace(&h).settings.transform.zoom.expect("zoom set");
    let xf = h.state().last_view.unwrap();
    assert!((xf.zoom - z).abs() < 1e-4);
    assert_eq!(xf.pixel_at(ball), Some((65, 45)));
    // Middle-drag pans by screen points / zoom.
    let before = xf.centre;
    h.event(Event::PointerButton {
        pos: ball,
        button: PointerButton::Middle,
        pressed: true,
        modifiers: Modifiers::NONE,
    });
    h.run();
    for k in 1..=4 {
        h.event(Event::PointerMoved(ball + Vec2::new(10.0 * k as f32, 0.0)));
        h.run();
    }
    h.event(Event::PointerButton {
        pos: ball + Vec2::new(40.0, 0.0),
        button: PointerButton::Middle,
        pressed: false,
        modifiers: Modifiers::NONE,
    });
    h.run();
    let after = h.state().last_view.unwrap().centre;
    assert!(
        after.x < before.x,
        "panning right moves the centre left: {before:?} → {after:?}"
    );
    assert!((after.y - before.y).abs() < 1e-3);
    h.state_mut().state.run(ViewCommand::ResetView.into());
    h.run();
    assert_eq!(workspace(&h).settings.transform.zoom, None);

    // Left-click samples with a sensitivity: the preview marks the ball, nothing is written.
    h.state_mut()
        .state
        .run(TableCommand::SetClass(ColourClass::Orange).into());
    h.state_mut()
        .state
        .run(TableCommand::SetSensitivity(Sensitivity::uniform(1)).into());
    let original = std::fs::read(&table).unwrap();
    click_at(&h, pixel_pos(&h, 65, 45), PointerButton::Primary);
    h.run();
    let s = workspace(&h);
    assert_eq!(s.selection().and_then(|s| s.pixel), Some((65, 45)));
    assert_eq!(s.preview_mask().iter().filter(|&&m| m).count(), 400);
    assert_eq!(s.lut().cells(), &original[..], "preview writes nothing");
    // Keys widen the sensitivity.
    h.key_press(Key::Y);
    h.run();
    assert_eq!(workspace(&h).settings.sensitivity.y, 2);
    h.key_press_modifiers(Modifiers::SHIFT, Key::Y);
    h.run();
    assert_eq!(workspace(&h).settings.sensitivity.y, 1);

    // Right-click commits; the pipeline re-runs at once.
    click_at(&h, pixel_pos(&h, 65, 45), PointerButton::Secondary);
    h.run();
    let s = workspace(&h);
    assert!(s.dirty());
    assert!(s.title().contains('*'), "{}", s.title());
    assert_eq!(s.lut().class_counts()[1], 27);
    let balls: Vec<_> = s.blobs().of_class(ColourClass::Orange).collect();
    assert_eq!(balls.len(), 1);
    assert_eq!(
        (balls[0].minx, balls[0].miny, balls[0].pixels),
        (60, 40, 400)
    );
    let committed = s.lut().clone();

    // Undo and redo with the keys.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(workspace(&h).lut().cells(), &original[..]);
    assert_eq!(
        workspace(&h).blobs().of_class(ColourClass::Orange).count(),
        0
    );
    h.key_press_modifiers(Modifiers::COMMAND, Key::Y);
    h.run();
    assert_eq!(workspace(&h).lut(), &committed);

    // Save: the file holds exactly the table, atomically replaced; the journal replays to it.
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    assert!(!workspace(&h).dirty(), "{}", workspace(&h).status);
    assert_eq!(std::fs::read(&table).unwrap(), committed.cells());
    let r = journal::replay(&table).unwrap();
    assert_eq!(r.table, committed);
    assert_eq!(r.commits, 1);
    assert!(r.warnings.is_empty());
    let lines = std::fs::read_to_string(journal::journal_path(&table)).unwrap();
    assert_eq!(
        lines.lines().count(),
        4,
        "start, commit, undo, redo:\n{lines}"
    );
    assert!(lines.contains(r#""event":"commit""#) && lines.contains(r#""class":"Orange""#));

    // Export the view with overlays.
    let png = dir.path().join("view.png");
    h.state_mut()
        .state
        .run(ViewCommand::ExportView(png.clone()).into());
    let img = image::open(&png).unwrap().into_rgb8();
    assert_eq!(img.dimensions(), (208, 160));
}

#[test]
fn reopening_a_table_restores_undo_from_the_journal() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, table) = fixture(dir.path());
    let mut s = Workspace::default();
    s.apply(Command::Open(vec![table.clone(), frames[0].clone()]))
        .unwrap();
    let original = s.lut().clone();
    s.apply(TableCommand::SetClass(ColourClass::Orange).into())
        .unwrap();
    s.apply(TableCommand::Sample { x: 65, y: 45 }.into())
        .unwrap();
    s.apply(TableCommand::Commit.into()).unwrap();
    s.apply(TableCommand::SetClass(ColourClass::White).into())
        .unwrap();
    s.apply(TableCommand::Sample { x: 100, y: 100 }.into())
        .unwrap();
    s.apply(TableCommand::Commit.into()).unwrap();
    s.apply(TableCommand::SaveTable.into()).unwrap();
    let saved = s.lut().clone();

    // A new session: the journal gives back both undo steps.
    let mut s2 = Workspace::default();
    s2.apply(Command::OpenTable(table.clone())).unwrap();
    assert_eq!(s2.lut(), &saved);
    assert_eq!(s2.history().undo_len(), 2);
    s2.apply(TableCommand::Undo.into()).unwrap();
    s2.apply(TableCommand::Undo.into()).unwrap();
    assert_eq!(s2.lut(), &original);
    assert!(s2.dirty());

    // A crash before saving: the table on disk lags the journal, which recovers it.
    s2.apply(TableCommand::Redo.into()).unwrap();
    let unsaved = s2.lut().clone();
    let mut s3 = Workspace::default();
    s3.apply(Command::OpenTable(table.clone())).unwrap();
    assert_eq!(s3.warnings().len(), 1, "{:?}", s3.warnings());
    s3.apply(TableCommand::RebuildFromJournal.into()).unwrap();
    assert_eq!(s3.lut(), &unsaved);

    // A torn last line is skipped with a warning, not an error.
    let jp = journal::journal_path(&table);
    let mut text = std::fs::read_to_string(&jp).unwrap();
    text.push_str("{\"event\":\"commit\",\"rec");
    std::fs::write(&jp, text).unwrap();
    let r = journal::replay(&table).unwrap();
    assert_eq!(r.warnings.len(), 1);
    assert_eq!(r.table, unsaved);
}

#[test]
fn bad_files_are_reported_not_fatal() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("short.lut");
    std::fs::write(&bad, [0u8; 1000]).unwrap();
    let mut s = Workspace::default();
    let err = s.apply(Command::Open(vec![bad.clone()])).unwrap_err();
    assert!(format!("{err:#}").contains("short.lut"), "{err:#}");
    let frame = dir.path().join("odd.uyvy");
    std::fs::write(&frame, [0u8; 333]).unwrap();
    s.run(Command::Open(vec![frame]));
    assert_eq!(s.warnings().len(), 1);
    assert!(s.warnings()[0].contains("odd.uyvy"), "{:?}", s.warnings());
    assert!(s.source().is_none());
}

#[test]
fn try_edit_lists_the_frames_that_would_change() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = opened_fixture(dir.path());
    // Selecting green as white would change every frame's field.
    s.apply(TableCommand::SetClass(ColourClass::White).into())
        .unwrap();
    s.apply(TableCommand::Sample { x: 150, y: 120 }.into())
        .unwrap();
    s.apply(TableCommand::TryEditOnStream.into()).unwrap();
    while !s.try_edit().unwrap().done() {
        s.tick(std::time::Duration::from_millis(16));
    }
    let t = &s.try_edit().unwrap().stream;
    assert_eq!(t.rows.len(), 3);
    let field = 208 * 160 - 400 - 12 * 80;
    assert!(
        t.rows.iter().all(|r| r.changed_pixels == field),
        "{:?}",
        t.rows
    );
    // Nothing was written.
    assert_eq!(s.lut().class_counts()[6], 0);
}

#[test]
fn every_window_and_menu_opens() {
    let dir = tempfile::tempdir().unwrap();
    let paths = fixture_files(dir.path());
    let mut h = harness(paths);
    h.run();
    for w in Window::ALL {
        h.state_mut().state.run(Command::ShowWindow(w, true));
    }
    h.state_mut()
        .state
        .run(TableCommand::Sample { x: 65, y: 45 }.into());
    h.state_mut()
        .state
        .run(TableCommand::TryEditOnStream.into());
    h.run();
    assert!(
        h.query_all_by_label_contains("plane").count() >= 1,
        "{:#?}",
        h.root()
    );
    for menu in ["File", "Classification", "View", "Stream", "Windows"] {
        click_label(&mut h, menu);
    }
    // Clicking the U–V plane selects around a cell and previews matching pixels.
    h.state_mut().state.run(TableCommand::ClearSelection.into());
    h.state_mut()
        .state
        .run(ViewCommand::SetUvPlaneY(100).into());
    h.run();
    let s = workspace(&h);
    assert!(s.selection().is_none());
    h.state_mut()
        .state
        .run(TableCommand::SampleCell([50, 55, 50]).into());
    assert_eq!(
        workspace(&h).preview_mask().iter().filter(|&&m| m).count(),
        208 * 160 - 400 - 12 * 80,
        "the green cell marks the field"
    );
}

#[test]
fn closing_with_unsaved_changes_asks_first() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, table) = fixture(dir.path());
    let mut h = harness(vec![frames[0].clone(), table]);
    h.run();
    h.state_mut()
        .state
        .run(TableCommand::Sample { x: 65, y: 45 }.into());
    h.state_mut().state.run(TableCommand::Commit.into());
    h.run();
    assert!(workspace(&h).dirty());
    close_window(&mut h);
    h.run();
    assert!(h.state().confirming_close());
    assert!(h.query_by_label("Quit without saving").is_some());
    click_label(&mut h, "Cancel");
    assert!(!h.state().confirming_close());
}

#[test]
fn snapshot_with_overlays() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = opened_fixture(dir.path());
    let mut o = s.settings.overlays;
    o.classified = true;
    o.opacity = 0.6;
    s.apply(ViewCommand::SetOverlays(o).into()).unwrap();
    s.apply(TableCommand::SetClass(ColourClass::Orange).into())
        .unwrap();
    s.apply(TableCommand::Sample { x: 65, y: 45 }.into())
        .unwrap();
    // Timings differ from run to run; everything else on screen is deterministic.
    s.apply(ViewCommand::ShowTimings(false).into()).unwrap();
    let mut h = snapshot_harness(s, Vec2::new(1000.0, 700.0));
    h.run();
    h.snapshot("app_overlays");
}

/// A short recorded stream: the scenes above at 25 fps with head-pan readings.
fn stream_fixture(dir: &Path, frames: usize) -> PathBuf {
    use eotn::sensors::SensorReadings;
    use eotn::streams::FrameRecord;
    let records = (0..frames).map(|i| {
        let mut r = FrameRecord::new(i as u64 * 40_000_000, scene(i % 3));
        r.sensors = Some(SensorReadings {
            head_pan_rad: Some(0.1 * i as f64),
            previous_head_pan_rad: Some(0.1 * i.saturating_sub(1) as f64),
            frame_interval_s: Some(0.04),
            pan_pwm: if i == 2 { Some(f64::NAN) } else { Some(0.5) },
            ..SensorReadings::default()
        });
        r
    });
    write_stream(&dir.join("s.mcap"), "robot", records)
}

#[test]
fn stream_steps_plays_and_plots_sensors() {
    let dir = tempfile::tempdir().unwrap();
    let (_, table) = fixture(dir.path());
    let stream = stream_fixture(dir.path(), 20);
    let mut h = harness(vec![stream, table]);
    h.run();
    let s = workspace(&h);
    assert_eq!(s.source().unwrap().len(), 20);
    assert!(s.source().unwrap().is_stream());
    h.key_press(Key::ArrowRight);
    h.key_press(Key::ArrowRight);
    h.run();
    let s = workspace(&h);
    assert_eq!(s.index(), 2);
    let c = s.current().unwrap();
    assert_eq!(c.time_ns, 80_000_000);
    let sensors = c.sensors.unwrap();
    assert!((sensors.head_pan_rad.unwrap() - 0.2).abs() < 1e-9);
    // NaN cannot be stored in JSON: it arrives as a missing reading, never as a number.
    assert_eq!(sensors.pan_pwm, None);
    // Jump, and the cache stays small.
    h.state_mut().state.run(PlaybackCommand::Seek(15).into());
    for i in 0..15 {
        h.state_mut().state.run(PlaybackCommand::Seek(i).into());
    }
    assert!(workspace(&h).source().unwrap().cached() <= eotn::workspace::source::CACHE_FRAMES);
    // The sensor dialog reads the whole series in the background.
    show_window(&mut h, Window::Sensors);
    let st = &mut h.state_mut().state;
    for _ in 0..100 {
        st.tick(std::time::Duration::from_millis(16));
    }
    assert_eq!(st.sensor_series.points.len(), 20);
    // Play at the recorded rate: 0.2 s of wall time moves 5 frames.
    st.run(PlaybackCommand::Seek(0).into());
    st.run(PlaybackCommand::SetSpeed(1.0).into());
    st.run(PlaybackCommand::SetPlaying(true).into());
    // The window sleeps until the next frame is due (40 ms at 25 fps) instead of spinning.
    let due = st.next_frame_due().expect("playing");
    assert!((due.as_secs_f64() - 0.04).abs() < 1e-6, "{due:?}");
    st.tick(std::time::Duration::from_millis(200));
    assert_eq!(st.index(), 5);
    st.run(PlaybackCommand::SetSpeed(4.0).into());
    st.tick(std::time::Duration::from_millis(200));
    assert_eq!(st.index(), 19);
    assert!(!st.playing(), "stops at the end");
    h.run();
}

/// Circles drawn in the last frame with their stroke widths and alphas.
fn drawn_circles(h: &Harness<'_, EotnApp>) -> Vec<(f32, u8)> {
    h.output()
        .shapes
        .iter()
        .filter_map(|c| match &c.shape {
            egui::Shape::Circle(s) if s.fill == egui::Color32::TRANSPARENT => {
                Some((s.stroke.width, s.stroke.color.a()))
            }
            _ => None,
        })
        .collect()
}

#[test]
fn recognition_overlays_and_inspector_on_a_sim_stream() {
    let stream = repo_file("streams/sim-walk-and-pan.mcap");
    let table = repo_file("lookup_tables/sim.lut");
    let mut h = harness(vec![stream, table]);
    h.run();
    let s = workspace(&h);
    assert_eq!(s.index(), 0);
    assert!(
        s.current().unwrap().sensors.is_some(),
        "the stream carries joints"
    );
    let ball = s
        .recognition()
        .ball
        .ball
        .clone()
        .expect("frame 0 shows the ball");
    let ball_owner = ObjectId::Ball(ball.candidate);
    assert!(s.accepted_owners().contains(&ball_owner));
    let prims = s.primitives();
    assert!(
        prims
            .iter()
            .any(|p| matches!(p, eotn::recognition::Primitive::Circle { .. })),
        "a circle fit"
    );
    assert!(
        prims.iter().any(
            |p| matches!(p, eotn::recognition::Primitive::Label { text, .. } if text.contains("cm"))
        ),
        "a label with the distance"
    );
    // The ball's circle is on screen, in every view that shows recognition (main + objects
    // thumbnail).
    assert!(!drawn_circles(&h).is_empty());

    // View > Overlays > Circle fits switches the circles off everywhere but the objects view.
    click_label(&mut h, "View");
    click_label(&mut h, "Overlays");
    click_label(&mut h, "Circle fits");
    assert!(!workspace(&h).settings.overlays.circles);
    h.key_press(Key::Escape);
    h.state_mut()
        .state
        .run(ViewCommand::SetMainView(ViewKind::Raw).into());
    h.run();
    let with_objects_thumb = drawn_circles(&h).len();
    let mut o = workspace(&h).settings.overlays;
    o.set_recognition(false);
    h.state_mut().state.run(ViewCommand::SetOverlays(o).into());
    h.run();
    assert_eq!(
        drawn_circles(&h).len(),
        with_objects_thumb,
        "only the objects thumbnail still draws the ball's circle"
    );
    o.set_recognition(true);
    h.state_mut().state.run(ViewCommand::SetOverlays(o).into());
    h.run();
    let all_circles = drawn_circles(&h);
    assert!(all_circles.len() > with_objects_thumb);
    assert!(all_circles.iter().all(|&(w, a)| w == 1.5 && a == 255));

    // The inspector lists every candidate; selecting the ball shows its breakdown and
    // highlights its overlays.
    show_window(&mut h, Window::Inspector);
    let n = eotn::app::inspector::candidates(
        workspace(&h).recognition(),
        workspace(&h).places(),
        workspace(&h).image_size(),
    )
    .len();
    assert!(n >= 2, "ball and goal candidates, got {n}");
    assert_eq!(
        h.query_all_by_label_contains("accepted ").count()
            + h.query_all_by_label_contains("rejected ").count(),
        n,
        "one row per candidate"
    );
    h.get_by_label_contains(&format!("accepted {ball_owner}"))
        .click();
    h.run();
    assert_eq!(workspace(&h).selected_object(), Some(ball_owner));
    assert!(
        h.query_all_by_label("pixel_ratio").count() == 1,
        "{:#?}",
        h.root()
    );
    assert!(h.query_all_by_label("pass").count() >= 1);
    assert!(h.query_all_by_label_contains("bearing").count() >= 1);
    let circles = drawn_circles(&h);
    assert!(
        circles.iter().any(|&(w, _)| w == 3.0),
        "selected: thicker {circles:?}"
    );
    // Selecting another candidate dims the ball.
    let goal = eotn::app::inspector::candidates(
        workspace(&h).recognition(),
        workspace(&h).places(),
        workspace(&h).image_size(),
    )
    .into_iter()
    .map(|c| c.owner)
    .find(|o| *o != ball_owner)
    .expect("another candidate in frame 0");
    h.state_mut().state.run(Command::SelectObject(Some(goal)));
    h.run();
    let circles = drawn_circles(&h);
    assert!(
        circles.iter().all(|&(w, a)| w == 1.5 && a < 255),
        "{circles:?}"
    );
    // An unknown owner is refused; stepping to a frame without it clears the selection.
    let mut st = Workspace::default();
    assert!(
        st.apply(Command::SelectObject(Some(ObjectId::Ball(9))))
            .is_err()
    );
    h.state_mut().state.run(PlaybackCommand::Seek(14).into());
    let s = workspace(&h);
    if !s.primitives().iter().any(|p| p.owner() == goal) {
        assert_eq!(s.selected_object(), None);
    }
    // Export draws the same primitives.
    let (w, hgt, rgb) = workspace(&h).compose_view_rgb(ViewKind::Objects).unwrap();
    assert_eq!(rgb.len(), w * hgt * 3);
}

#[test]
fn nan_sensor_readings_of_a_side_file_show_as_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, table) = fixture(dir.path());
    std::fs::write(
        dir.path().join("f1.sensors.json"),
        r#"{"head_pan_rad": NaN, "head_tilt_rad": -0.3, "neck_tilt_rad": 0.0, "ir_far_cm": Infinity}"#,
    )
    .unwrap();
    let mut paths = frames;
    paths.push(table);
    let mut h = harness(paths);
    h.run();
    assert!(workspace(&h).warnings().is_empty());
    assert!(h.query_by_label_contains("this frame:").is_none());
    h.key_press(Key::ArrowRight);
    h.run();
    let s = workspace(&h);
    assert_eq!(s.index(), 1);
    let c = s.current().unwrap();
    let r = c.sensors.unwrap();
    assert_eq!((r.head_pan_rad, r.head_tilt_rad), (None, Some(-0.3)));
    assert_eq!(r.ir_far_cm, None);
    let w = s.warnings().last().expect("a warning").clone();
    assert!(
        w.contains("f1.sensors.json") && w.contains("head_pan_rad") && w.contains("ir_far_cm"),
        "{w}"
    );
    assert!(h.query_by_label_contains("this frame:").is_some());
    assert!(h.query_by_label("1 warning").is_some());
    // The next frame has no problems: the frame line goes, the list keeps the warning.
    h.key_press(Key::ArrowRight);
    h.run();
    assert!(h.query_by_label_contains("this frame:").is_none());
    assert_eq!(workspace(&h).warnings().len(), 1);
}

#[test]
fn snapshot_with_recognition_and_inspector() {
    let mut s = Workspace::default();
    s.apply(Command::Open(vec![
        repo_file("streams/sim-walk-and-pan.mcap"),
        repo_file("lookup_tables/sim.lut"),
    ]))
    .unwrap();
    s.apply(ViewCommand::ShowTimings(false).into()).unwrap();
    s.apply(Command::ShowWindow(Window::Inspector, true))
        .unwrap();
    let ball = s
        .recognition()
        .ball
        .ball
        .clone()
        .expect("a ball in frame 0");
    s.apply(Command::SelectObject(Some(ObjectId::Ball(ball.candidate))))
        .unwrap();
    let mut h = snapshot_harness(s, Vec2::new(1280.0, 800.0));
    h.run();
    h.snapshot("app_recognition");
}

#[test]
fn nan_in_a_recorded_stream_shows_as_a_warning_of_its_frame() {
    use eotn::sensors::SensorReadings;
    use eotn::streams::{Compression, FrameRecord, StreamInfo, StreamWriter, WriterOptions};
    let dir = tempfile::tempdir().unwrap();
    let (_, table) = fixture(dir.path());
    let path = dir.path().join("nan.mcap");
    let options = WriterOptions {
        compression: Compression::None,
        frames_per_chunk: Some(1),
        ..WriterOptions::default()
    };
    let mut w = StreamWriter::create_with(&path, &StreamInfo::default(), options).unwrap();
    for i in 0..3 {
        let mut r = FrameRecord::new(i as u64 * 40_000_000, scene(i));
        r.sensors = Some(SensorReadings {
            head_pan_rad: if i == 1 { None } else { Some(0.1) },
            ..SensorReadings::default()
        });
        w.write(&r).unwrap();
    }
    w.finish().unwrap();
    // What Python's json.dumps writes for a NaN reading, in frame 1's message (same length, so
    // the uncompressed chunk stays well-formed).
    let mut bytes = std::fs::read(&path).unwrap();
    let from = br#""head_pan_rad":null"#;
    let at = bytes
        .windows(from.len())
        .position(|w| w == from)
        .expect("frame 1 has no head pan");
    bytes[at..at + from.len()].copy_from_slice(br#""head_pan_rad":NaN "#);
    // The chunk's CRC no longer matches: 0 means "not computed" in MCAP. Walk the records
    // (magic, then opcode u8 + length u64 + body) to the chunk holding the edit.
    let mut pos = 8;
    loop {
        let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().unwrap()) as usize;
        let body = pos + 9;
        if (body..body + len).contains(&at) {
            assert_eq!(bytes[pos], 0x06, "a chunk record");
            // start time u64, end time u64, uncompressed size u64, then the CRC u32.
            bytes[body + 24..body + 28].fill(0);
            break;
        }
        pos = body + len;
    }
    std::fs::write(&path, &bytes).unwrap();

    let mut h = harness(vec![path, table]);
    h.run();
    assert!(h.query_by_label_contains("this frame:").is_none());
    h.key_press(Key::ArrowRight);
    h.run();
    let s = workspace(&h);
    let c = s.current().unwrap();
    assert_eq!(s.index(), 1, "{:?}", s.warnings());
    assert_eq!(c.sensors.unwrap().head_pan_rad, None, "{:?}", s.warnings());
    assert!(
        c.warnings
            .iter()
            .any(|w| w.contains("frame 1") && w.contains("NaN")),
        "{:?}",
        c.warnings
    );
    assert!(s.warnings().iter().any(|w| w.contains("NaN")));
    assert!(h.query_by_label_contains("this frame:").is_some());
}

/// Frames 8..32 of the pattern tour (seed 1), where a marker passes through the view, as a
/// stream with the robot's readings.
fn pattern_stream(dir: &Path) -> PathBuf {
    use eotn::sim::{Scenario, ScenarioKind, Simulator};
    use eotn::streams::FrameRecord;
    let sim = Simulator::new(Scenario::new(ScenarioKind::PatternTour, 1));
    let records = (8..32).map(|i| {
        let f = sim.frame(i).unwrap();
        let mut r = FrameRecord::new(f.time_ns, f.frame);
        r.sensors = f.sensors;
        r
    });
    write_stream(&dir.join("tour.mcap"), "sim:pattern-tour", records)
}

#[test]
fn inspector_shows_a_pattern_match_from_a_places_file() {
    use eotn::recognition::patterns::{PatternMemory, PatternObject, Placement, SizeRelation};
    let dir = tempfile::tempdir().unwrap();
    let stream = pattern_stream(dir.path());
    let table = repo_file("lookup_tables/sim.lut");
    // Find a frame with a pink marker seen whole, and make a places file that knows it (as
    // `eotn patterns learn` would; learning itself is tested in tests/it/patterns.rs).
    let mut s = Workspace::default();
    s.apply(Command::Open(vec![stream.clone(), table.clone()]))
        .unwrap();
    let mut frame = None;
    for i in 0..s.source().unwrap().len() {
        s.apply(PlaybackCommand::Seek(i).into()).unwrap();
        if let Some(c) = s.recognition().patterns.iter().find(|c| {
            c.observation.regions_in_image == 9 && c.observation.signature.coloured_regions() == 9
        }) {
            frame = Some((i, c.observation.signature));
            break;
        }
    }
    let (index, signature) = frame.expect("a whole marker in one of the frames");
    let places = dir.path().join("places.json");
    PatternMemory {
        objects: vec![PatternObject {
            id: 7,
            field_cm: [90.0, 225.0],
            height_cm: Some(25.0),
            patterns: vec![signature],
            views: 12,
            placed_by: Placement::Triangulation,
            residual_cm: 1.0,
        }],
        relation: Some(SizeRelation {
            multiplier_cm_px: 1535.0,
            offset_cm: 0.0,
            residual_cm: 5.0,
            samples: 12,
        }),
        ..PatternMemory::default()
    }
    .save(&places)
    .unwrap();

    // The places file opens like any file (by its extension), and the marker is identified.
    let mut h = harness(vec![stream, table, places.clone()]);
    h.run();
    assert_eq!(workspace(&h).places_path(), Some(places.as_path()));
    h.state_mut().state.run(PlaybackCommand::Seek(index).into());
    show_window(&mut h, Window::Inspector);
    let s = workspace(&h);
    let (k, c) = s
        .recognition()
        .patterns
        .iter()
        .enumerate()
        .find(|(_, c)| c.accepted)
        .expect("identified");
    assert_eq!(c.identification.map(|m| (m.id, m.agreement)), Some((7, 9)));
    let owner = ObjectId::Pattern(k);
    assert!(
        s.accepted_owners().contains(&owner),
        "the objects view shows it"
    );
    assert!(
        s.primitives()
            .iter()
            .filter(|p| matches!(p, eotn::recognition::Primitive::PatternRegion { owner: o, .. } if *o == owner))
            .count()
            == 9
    );
    // Its row in the inspector; selecting it shows the nine regions and the match.
    h.get_by_label_contains(&format!("accepted {owner}"))
        .click();
    h.run();
    assert_eq!(workspace(&h).selected_object(), Some(owner));
    assert!(
        h.query_by_label_contains("pink marker: place 7").is_some(),
        "{:#?}",
        h.root()
    );
    assert_eq!(h.query_all_by_label("agrees").count(), 9);
    assert!(
        h.query_by_label_contains("against place 7: 9/9 agree")
            .is_some()
    );
    assert!(
        h.query_all_by_label_contains("pink").count() >= 2,
        "the middle region is pink"
    );
    assert!(
        h.query_all_by_label("agreement").count() == 1,
        "the breakdown's test row"
    );
    // Closing the places file leaves the marker unidentified; a garbled one is a warning.
    h.state_mut().state.run(Command::ClosePlaces);
    h.run();
    assert!(
        workspace(&h)
            .recognition()
            .patterns
            .iter()
            .all(|c| !c.accepted)
    );
    assert_eq!(workspace(&h).settings.last_places, None);
    let garbled = dir.path().join("garbled.json");
    std::fs::write(&garbled, "{\"format\": \"eotn.places\", \"objects\": 3}").unwrap();
    h.state_mut().state.run(Command::OpenPlaces(garbled));
    h.run();
    let w = workspace(&h).warnings().last().cloned().unwrap_or_default();
    assert!(
        w.contains("garbled.json") && w.contains("not a places file"),
        "{w}"
    );
    assert_eq!(workspace(&h).places_path(), None);
    // The menu offers it; the recent files list has it.
    assert!(
        workspace(&h)
            .settings
            .recent
            .iter()
            .any(|p| p.ends_with("places.json"))
    );
    click_label(&mut h, "Classification");
    assert!(h.query_by_label("Open places…").is_some());
}

/// A ROS 2 bag written by `rosbags` with `sensor_msgs/JointState` beside its images: the Sensors
/// window shows the joints of the shown frame with their positions, and the series it plots
/// holds every frame's joint positions.
#[test]
fn joint_states_are_shown_and_plotted_in_the_sensors_window() {
    let Some(bag) = crate::recordings::joint_state_bag() else {
        return;
    };
    let mut h = harness(vec![bag]);
    // The window reads the series a few frames per UI frame, repainting until it has them all.
    h.state_mut()
        .state
        .run(Command::ShowWindow(Window::Sensors, true));
    let frames = workspace(&h).source().unwrap().len();
    assert_eq!(frames, 24);
    crate::harness::run_steps_until(&mut h, std::time::Duration::from_secs(120), |app| {
        app.state.sensor_series.points.len() == frames
    });
    h.run();
    h.get_by_label("/joint_states");
    h.get_by_label("HeadYaw");
    h.get_by_label("HeadPitch");
    for value in ["0.1000", "0.2000"] {
        assert!(
            h.query_by_label_contains(value).is_some(),
            "the joint position {value} is shown"
        );
    }
    let series = &workspace(&h).sensor_series.channels;
    for (joint, position) in [("HeadYaw", 0.1), ("HeadPitch", 0.2)] {
        let points = &series[&format!("/joint_states {joint}")];
        assert_eq!(points.len(), frames, "{joint}: a point per frame");
        assert!(
            points.iter().all(|p| (p[1] - position).abs() < 1e-12),
            "{joint}"
        );
        assert!(
            points.windows(2).all(|w| w[0][0] < w[1][0]),
            "{joint}: in time order"
        );
    }
}
