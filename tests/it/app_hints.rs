//! The hand-classifier's three questions in the app, driven with egui_kittest through the same
//! `Workspace`/`Command` path as the window: what is still unclassified (coverage hints), why a
//! pixel has its class (the edit that set its cell), where something happened (events and
//! bookmarks on the timeline).

use std::path::{Path, PathBuf};
use std::time::Duration;

use egui::{Event, Key, Modifiers};
use egui_kittest::kittest::Queryable as _;
use eotn::frame::{Frame, Yuv};
use eotn::lut::{ColourClass, EditRecord, LookupTable, Region, Sensitivity};
use eotn::workspace::bookmarks::{EventKind, bookmarks_path};
use eotn::workspace::cell_origin::CellOrigin;
use eotn::workspace::{Command, HintsCommand, PlaybackCommand, TableCommand, Window, Workspace};

use crate::harness::{
    GREEN, ORANGE, click_label, harness, pixel_pos, run_until, show_window, workspace,
};

/// How long a background scan may take.
const WITHIN: Duration = Duration::from_secs(60);

const PINK: Yuv = Yuv::new(170, 150, 200);

/// 208×160 green; an orange 20×20 ball on frames 1 and 2 (not 0); a pink 10×10 patch on all.
fn scene(n: usize) -> Frame {
    Frame::uyvy_from_fn(208, 160, |x, y| {
        let bx = 60 + 10 * n;
        if n > 0 && (bx..bx + 20).contains(&x) && (40..60).contains(&y) {
            ORANGE
        } else if (150..160).contains(&x) && (100..110).contains(&y) {
            PINK
        } else {
            GREEN
        }
    })
    .unwrap()
}

/// Three frame files and a 7-bit table with only green classified.
fn fixture(dir: &Path) -> Vec<PathBuf> {
    let mut paths = Vec::new();
    for n in 0..3 {
        let p = dir.join(format!("f{n}.uyvy"));
        std::fs::write(&p, scene(n).data()).unwrap();
        paths.push(p);
    }
    let mut lut = LookupTable::new(7).unwrap();
    lut.apply(EditRecord::now(
        ColourClass::Green,
        Region::AroundSample {
            sample: GREEN,
            sensitivity: Sensitivity::uniform(2),
        },
    ));
    let table = dir.join("field.lut");
    lut.save(&table).unwrap();
    paths.push(table);
    paths
}

#[test]
fn coverage_hints_rank_unclassified_colours_and_a_click_selects_them_for_commit() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(fixture(dir.path()));
    h.run();
    show_window(&mut h, Window::Coverage);
    click_label(&mut h, "Find unclassified");
    run_until(&mut h, WITHIN, |a| {
        a.state.coverage().is_some_and(|c| c.done())
    });
    h.run();
    let scan = workspace(&h).coverage().unwrap();
    // Orange: 2 frames × 400 pixels; pink: 3 × 100. Green is classified.
    let pixels: Vec<u64> = scan.hints().iter().map(|x| x.pixels).collect();
    assert_eq!(pixels, vec![800, 300], "{:?}", scan.hints());
    assert_eq!(scan.unclassified_pixels(), 1100);
    let orange_cells = scan.hints()[0].cells.clone();
    assert_eq!(orange_cells, vec![workspace(&h).lut().index(ORANGE)]);

    // Clicking the first hint selects its cells and previews its pixels in the image.
    h.state_mut().state.run(PlaybackCommand::Seek(1).into());
    h.run();
    click_label(&mut h, "hint 1");
    let previewed = workspace(&h).preview_mask().iter().filter(|&&m| m).count();
    assert_eq!(previewed, 400, "the ball's pixels are previewed");
    // The hint's class is chosen for it (issue 33: not whatever class was selected).
    h.state_mut()
        .state
        .run(TableCommand::SetClass(ColourClass::Orange).into());
    h.run();
    click_label(&mut h, "Commit as orange");
    assert_eq!(workspace(&h).lut().class_of(ORANGE), ColourClass::Orange);
    // Orange is classified now: its row stays where it was, marked; pink is left open.
    h.run();
    let hints = workspace(&h).coverage().unwrap().hints().to_vec();
    let pixels: Vec<u64> = hints.iter().map(|x| x.pixels).collect();
    assert_eq!(pixels, vec![0, 300]);
    assert_eq!(hints[0].done, Some(ColourClass::Orange));

    // Why is the ball orange? The hint's edit. Why is a pink pixel unclassified? As loaded.
    let origin = workspace(&h).pixel_origin(75, 45).unwrap();
    let CellOrigin::Edit(e) = origin else {
        panic!("the commit set the ball's cell: {origin:?}");
    };
    assert_eq!(
        (e.number, e.class, e.picked_cells),
        (1, ColourClass::Orange, Some(1))
    );
    assert_eq!(
        workspace(&h).pixel_origin(155, 105),
        Some(CellOrigin::AsLoaded)
    );
    // A sampled commit records its frame and pixel, shown when hovering.
    h.state_mut()
        .state
        .run(TableCommand::Sample { x: 155, y: 105 }.into());
    h.state_mut()
        .state
        .run(TableCommand::SetClass(ColourClass::Pink).into());
    h.state_mut().state.run(TableCommand::Commit.into());
    h.run();
    let pos = pixel_pos(&h, 155, 105);
    h.event(Event::PointerMoved(pos));
    h.run();
    h.get_by_label_contains("edit 2: pink from frame 1 pixel (155, 105)");
}

#[test]
fn events_and_bookmarks_mark_the_timeline_and_bookmarks_stay_beside_the_stream() {
    let dir = tempfile::tempdir().unwrap();
    let paths = fixture(dir.path());
    let mut lut = LookupTable::load(&paths[3]).unwrap();
    lut.apply(EditRecord::now(
        ColourClass::Orange,
        Region::AroundSample {
            sample: ORANGE,
            sensitivity: Sensitivity::uniform(1),
        },
    ));
    lut.save(&paths[3]).unwrap();
    let mut h = harness(paths.clone());
    h.run();
    show_window(&mut h, Window::Bookmarks);
    // A bookmark with a note on frame 2, saved beside the first frame file.
    h.state_mut().state.run(PlaybackCommand::Seek(2).into());
    h.run();
    let field = h.get_by_label("note");
    field.focus();
    field.type_text("ball near the line");
    h.run();
    click_label(&mut h, "Bookmark this frame");
    let file = bookmarks_path(&paths[0]);
    let text = std::fs::read_to_string(&file).expect("saved");
    assert!(
        text.contains("ball near the line") && text.contains("\"frame\": 2"),
        "{text}"
    );

    // Ctrl+→ from frame 0 jumps to the bookmark (a plain step would go to 1).
    h.state_mut().state.run(PlaybackCommand::Seek(0).into());
    h.run();
    h.key_press_modifiers(Modifiers::COMMAND, Key::ArrowRight);
    h.run();
    assert_eq!(workspace(&h).index(), 2);

    click_label(&mut h, "Find events");
    run_until(&mut h, WITHIN, |a| {
        a.state.event_scan().is_some_and(|e| e.done())
    });
    let kinds: Vec<(usize, EventKind)> = workspace(&h)
        .events()
        .iter()
        .map(|e| (e.frame, e.kind))
        .collect();
    assert_eq!(
        kinds,
        vec![(1, EventKind::BallFound)],
        "the ball appears at frame 1"
    );

    // Jumps: from 0 the next mark is the event at 1, then the bookmark at 2; and back.
    h.state_mut().state.run(PlaybackCommand::Seek(0).into());
    h.run();
    click_label(&mut h, "Next mark");
    assert_eq!(workspace(&h).index(), 1);
    click_label(&mut h, "Next mark");
    assert_eq!(workspace(&h).index(), 2);
    click_label(&mut h, "Previous mark");
    assert_eq!(workspace(&h).index(), 1);

    // Reopening finds the bookmark; removing it saves the file again.
    drop(h);
    let mut h = harness(paths);
    h.run();
    assert_eq!(workspace(&h).bookmarks().len(), 1);
    assert_eq!(workspace(&h).bookmarks()[0].note, "ball near the line");
    h.state_mut()
        .state
        .run(HintsCommand::RemoveBookmark(2).into());
    h.run();
    assert!(workspace(&h).bookmarks().is_empty());
    assert!(!std::fs::read_to_string(&file).unwrap().contains("line"));
    // A damaged bookmarks file is a warning, not a failure to open.
    std::fs::write(&file, "not json").unwrap();
    let mut s = Workspace::default();
    s.run(Command::Open(vec![file.with_file_name("f0.uyvy")]));
    assert!(s.source().is_some());
    assert!(
        s.warnings()
            .iter()
            .any(|w| w.contains("not a bookmarks file")),
        "{:?}",
        s.warnings()
    );
}

/// Boxed labels opened over the frames (`eotn open FOLDER --labels LABELS` sends the same
/// command): the Events and bookmarks window shows the report's figures, the missed and false
/// frames are marks to step between.
#[test]
fn labels_over_frames_show_the_report_and_step_between_missed_and_false_frames() {
    let dir = tempfile::tempdir().unwrap();
    let mut paths = fixture(dir.path());
    // The fixture's table knows green only: orange too, so the balls of frames 1 and 2 are seen.
    let table = paths.pop().unwrap();
    let mut lut = LookupTable::load(&table).unwrap();
    lut.apply(EditRecord::now(
        ColourClass::Orange,
        Region::AroundSample {
            sample: ORANGE,
            sensitivity: Sensitivity::uniform(2),
        },
    ));
    lut.save(&table).unwrap();
    paths.push(table);
    // YOLO: frame 0 labelled with a ball it does not show (missed), frame 1's ball labelled
    // (found), frame 2's ball not labelled (false).
    let labels = dir.path().join("labels");
    std::fs::create_dir_all(&labels).unwrap();
    std::fs::write(labels.join("classes.txt"), "robot\nball\ngoal\n").unwrap();
    let ball = |bx: f64| {
        format!(
            "1 {} {} {} {}\n",
            (bx + 10.0) / 208.0,
            50.0 / 160.0,
            20.0 / 208.0,
            20.0 / 160.0
        )
    };
    std::fs::write(labels.join("f0.txt"), ball(60.0)).unwrap();
    std::fs::write(labels.join("f1.txt"), ball(70.0)).unwrap();
    std::fs::write(labels.join("f2.txt"), "0 0.9 0.9 0.1 0.1\n").unwrap();
    let mut h = harness(paths);
    h.state_mut().state.run(Command::OpenLabels(labels));
    show_window(&mut h, Window::Bookmarks);
    run_until(&mut h, WITHIN, |a| {
        a.state
            .labels()
            .is_some_and(eotn::workspace::OpenLabels::done)
    });
    h.run();
    // Recall (1 of 2 eligible frames) and precision (1 of 2 reported balls).
    assert_eq!(h.query_all_by_label("1 / 2 = 50.0%").count(), 2);
    let kinds: Vec<(usize, EventKind)> = workspace(&h)
        .events()
        .iter()
        .filter(|e| matches!(e.kind, EventKind::LabelMissed | EventKind::LabelFalse))
        .map(|e| (e.frame, e.kind))
        .collect();
    assert_eq!(
        kinds,
        vec![(0, EventKind::LabelMissed), (2, EventKind::LabelFalse)]
    );
    assert_eq!(workspace(&h).index(), 0);
    assert_eq!(
        workspace(&h).shown_label_boxes().map(|b| b.boxes.len()),
        Some(1)
    );
    click_label(&mut h, "Next mark");
    assert_eq!(workspace(&h).index(), 2);
    click_label(&mut h, "Previous mark");
    assert_eq!(workspace(&h).index(), 0);
}

/// Label boxes painted over the image: dashed segments in the class's colour (ball orange) and
/// the class name above each box.
fn painted_label_boxes(h: &egui_kittest::Harness<'_, eotn::app::EotnApp>) -> (usize, usize) {
    fn walk(shape: &egui::Shape, out: &mut (usize, usize)) {
        match shape {
            egui::Shape::LineSegment { stroke, .. }
                if stroke.color == egui::Color32::from_rgb(255, 120, 0) =>
            {
                out.0 += 1;
            }
            egui::Shape::Text(t) if t.galley.text() == "ball" => out.1 += 1,
            egui::Shape::Vec(shapes) => shapes.iter().for_each(|s| walk(s, out)),
            _ => {}
        }
    }
    let mut out = (0, 0);
    for c in &h.output().shapes {
        walk(&c.shape, &mut out);
    }
    out
}

/// Labels opened from inside the app (File ▸ Open labels ▸ Labels path…): the shown frame's
/// ball box is painted, dashed and named; the scoring follows a table edit made afterwards.
#[test]
fn labels_opened_from_the_menu_are_painted_and_scored_with_the_table_in_use() {
    let dir = tempfile::tempdir().unwrap();
    let paths = fixture(dir.path());
    let labels = dir.path().join("labels");
    std::fs::create_dir_all(&labels).unwrap();
    std::fs::write(labels.join("classes.txt"), "robot\nball\ngoal\n").unwrap();
    // Frames 1 and 2 show a 20 × 20 ball at x = 70 and 80, y = 40: labelled there.
    for n in 1..3 {
        let x = (70.0 + 10.0 * (n - 1) as f64 + 10.0) / 208.0;
        std::fs::write(
            labels.join(format!("f{n}.txt")),
            format!("1 {x} {} {} {}\n", 50.0 / 160.0, 20.0 / 208.0, 20.0 / 160.0),
        )
        .unwrap();
    }
    let mut h = harness(paths);
    h.run();
    show_window(&mut h, Window::Bookmarks);
    h.state_mut().state.run(PlaybackCommand::Seek(1).into());
    h.run();
    assert_eq!(painted_label_boxes(&h), (0, 0));
    click_label(&mut h, "File");
    click_label(&mut h, "Open labels");
    click_label(&mut h, "Labels path…");
    let field = h.get_by_label("path");
    field.focus();
    field.type_text(&labels.display().to_string());
    h.run();
    click_label(&mut h, "Open");
    assert!(
        workspace(&h).labels().is_some(),
        "{:?}",
        workspace(&h).warnings()
    );
    run_until(&mut h, WITHIN, |a| {
        a.state
            .labels()
            .is_some_and(eotn::workspace::OpenLabels::done)
    });
    h.run();
    let (dashes, names) = painted_label_boxes(&h);
    assert!(dashes >= 8, "{dashes} dashes of the ball box");
    assert_eq!(names, 1);
    // The fixture's table has no orange: no ball is found.
    assert_eq!(workspace(&h).labels().unwrap().report().found, 0);
    assert_eq!(h.query_all_by_label("0 / 2 = 0.0%").count(), 1);
    // Orange clicked on the ball: scored again with the table in use, both balls are found.
    h.state_mut()
        .state
        .run(TableCommand::SetClass(ColourClass::Orange).into());
    h.state_mut()
        .state
        .run(TableCommand::SetSensitivity(Sensitivity::uniform(1)).into());
    h.state_mut()
        .state
        .run(TableCommand::Sample { x: 80, y: 50 }.into());
    h.state_mut().state.run(TableCommand::Commit.into());
    run_until(&mut h, WITHIN, |a| {
        a.state
            .labels()
            .is_some_and(|l| l.done() && l.report().found == 2)
    });
    h.run();
    // Recall and precision.
    assert_eq!(h.query_all_by_label("2 / 2 = 100.0%").count(), 2);
    // The split: held-out frames only (none here: f1, f2 end in 1 and 2).
    click_label(&mut h, "held out");
    run_until(&mut h, WITHIN, |a| {
        a.state
            .labels()
            .is_some_and(|l| l.split() == eotn::eval::label_sets::Split::HeldOut && l.done())
    });
    assert_eq!(workspace(&h).labels().unwrap().report().eligible, 0);
}
