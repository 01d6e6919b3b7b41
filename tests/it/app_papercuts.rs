//! The last papercuts of issue 15 that were done but untested, each driven through the real
//! window under egui_kittest: object labels kept inside the view, the journal warning naming
//! the menu's command as the menu does, the class list's column headers, a typed zoom (and the
//! View submenus staying open while values change), the U–V plane's axis ticks, double-click
//! to fit without sampling a selection, and the Robots window fitting its dock tab.

use std::path::PathBuf;
use std::time::Duration;

use egui::{Event, Modifiers, PointerButton, Pos2, Rect, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use eotn::app::EotnApp;
use eotn::lut::ColourClass;
use eotn::workspace::{Command, RobotsCommand, TableCommand, ViewCommand, Window, Workspace};

use crate::common::repo_file;
use crate::harness::{click_label, fixture, harness_sized, run_steps_until, workspace};

/// The papercut tests' window: the size the user saw.
const SCREEN: Vec2 = Vec2::new(1280.0, 800.0);

fn harness(paths: Vec<PathBuf>) -> Harness<'static, EotnApp> {
    harness_sized(paths, SCREEN)
}

/// The app on the first frame of the harness's [`fixture`] and its table.
fn first_frame_harness(dir: &std::path::Path) -> Harness<'static, EotnApp> {
    let (frames, table) = fixture(dir);
    harness(vec![frames[0].clone(), table])
}

fn painted_texts(h: &Harness<'_, EotnApp>) -> Vec<(String, Rect)> {
    fn collect(shape: &egui::Shape, out: &mut Vec<(String, Rect)>) {
        match shape {
            egui::Shape::Text(t) => out.push((
                t.galley.text().to_owned(),
                Rect::from_min_size(t.pos, t.galley.size()),
            )),
            egui::Shape::Vec(shapes) => {
                for s in shapes {
                    collect(s, out);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    for c in &h.output().shapes {
        collect(&c.shape, &mut out);
    }
    out
}

/// What a node says: a label's text is its accessible value, a widget's its label.
fn node_text(n: &egui_kittest::Node<'_>) -> String {
    let a = n.accesskit_node();
    let text = if a.role() == egui::accesskit::Role::Label {
        a.value()
    } else {
        a.label()
    };
    text.expect("a node with text")
}

/// The screen rectangle of the node labelled exactly `label`.
fn node_rect(h: &Harness<'_, EotnApp>, label: &str) -> Rect {
    let r = h
        .get_by_label(label)
        .accesskit_node()
        .bounding_box()
        .expect("a laid-out node");
    Rect::from_min_max(
        Pos2::new(r.x0 as f32, r.y0 as f32),
        Pos2::new(r.x1 as f32, r.y1 as f32),
    )
}

/// The ball's label ("ball 123 cm +4°") painted in the enlarged view.
fn ball_label(h: &Harness<'_, EotnApp>, view: Rect) -> Option<Rect> {
    painted_texts(h)
        .into_iter()
        .filter(|(t, r)| t.starts_with("ball ") && t.contains(" cm") && r.intersects(view))
        .map(|(_, r)| r)
        .next()
        .or_else(|| {
            // Drawn outside the view altogether (the feature missing): still found, so the
            // assertion below names where it went.
            painted_texts(h)
                .into_iter()
                .filter(|(t, _)| t.starts_with("ball ") && t.contains(" cm"))
                .map(|(_, r)| r)
                .find(|r| r.width() > 0.0)
        })
}

#[test]
fn object_labels_stay_inside_the_view_when_the_object_is_beyond_an_edge() {
    let mut h = harness(vec![
        repo_file("streams/bhuman2009.mcap"),
        repo_file("lookup_tables/bhuman2009.lut"),
        repo_file("params/spl2009.json"),
    ]);
    h.run_steps(4);
    // Frame 0: the ball at (172, 149), radius 11 px, in the middle of the image.
    let ball = workspace(&h)
        .recognition()
        .ball
        .ball
        .clone()
        .expect("a ball");
    let (bx, by, r) = (
        ball.observed_center.x_px,
        ball.observed_center.y_px,
        ball.radius_px,
    );
    let fitted = h.state().last_view.expect("the image is drawn");
    let label = ball_label(&h, fitted.view).expect("the ball's label is drawn");
    assert!(fitted.view.contains_rect(label));
    // Zoomed to 400 % with the ball 40 image pixels above the view's top edge, then below its
    // bottom edge: its label stays in the view, at the edge nearest to the ball.
    let zoom = 4.0_f32;
    let half_height = fitted.view.height() / zoom / 2.0;
    for (above, centre_y) in [
        (true, by as f32 + r as f32 + 40.0 + half_height),
        (false, by as f32 - r as f32 - 40.0 - half_height),
    ] {
        h.state_mut()
            .state
            .run(ViewCommand::SetZoom(Some(zoom)).into());
        let size = workspace(&h).image_size();
        let c = workspace(&h)
            .settings
            .transform
            .effective_centre([size.0 as f32, size.1 as f32]);
        h.state_mut()
            .state
            .run(ViewCommand::Pan([c[0] - bx as f32, c[1] - centre_y]).into());
        h.run_steps(3);
        let xf = h.state().last_view.unwrap();
        let ball_on_screen = xf.to_screen(Pos2::new(bx as f32, by as f32));
        assert!(
            !xf.view.contains(ball_on_screen),
            "the ball is beyond the edge: {ball_on_screen:?} {:?}",
            xf.view
        );
        let label = ball_label(&h, xf.view).expect("the ball's label is still drawn");
        assert!(
            xf.view.contains_rect(label) && xf.image_rect().contains_rect(label),
            "label {label:?} inside the view {:?} and on the image {:?}",
            xf.view,
            xf.image_rect()
        );
        let edge_gap = if above {
            label.min.y - xf.view.min.y
        } else {
            xf.view.max.y - label.max.y
        };
        assert!(
            edge_gap < 6.0,
            "pinned to the nearest edge: {label:?} {:?}",
            xf.view
        );
    }
}

#[test]
fn the_journal_warning_names_the_menu_command_as_the_menu_shows_it() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, table) = fixture(dir.path());
    // An unsaved commit before a "crash": the table on disk lags its journal.
    let mut s = Workspace::default();
    s.apply(Command::Open(vec![table.clone(), frames[0].clone()]))
        .unwrap();
    s.apply(TableCommand::SetClass(ColourClass::Orange).into())
        .unwrap();
    s.apply(TableCommand::Sample { x: 65, y: 45 }.into())
        .unwrap();
    s.apply(TableCommand::Commit.into()).unwrap();
    let unsaved = s.lut().clone();
    drop(s);
    let mut h = harness(vec![frames[0].clone(), table]);
    h.run();
    // The warning as the user reads it in the warnings window.
    click_label(&mut h, "1 warning");
    let warning = node_text(&h.get_by_label_contains("differs from its journal"));
    let command = warning
        .split(": ")
        .last()
        .and_then(|t| t.strip_suffix(" recovers them"))
        .unwrap_or_else(|| panic!("the warning names a command: {warning}"));
    let (menu, item) = command
        .split_once(" > ")
        .unwrap_or_else(|| panic!("MENU > ITEM: {command}"));
    // That menu, and in it that item, exactly as the warning spells them.
    click_label(&mut h, menu);
    click_label(&mut h, item);
    assert_eq!(
        workspace(&h).lut(),
        &unsaved,
        "the command the warning names recovers the edit"
    );
}

#[test]
fn the_class_list_count_columns_have_headers_above_them() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = first_frame_harness(dir.path());
    h.run();
    let green = usize::from(ColourClass::Green.code());
    let cells = workspace(&h).table_counts()[green];
    let pixels = workspace(&h).frame_counts()[green];
    assert_ne!(
        cells, pixels,
        "the two columns are told apart by their values"
    );
    for (header, value) in [("table cells", cells), ("frame pixels", pixels)] {
        let head = node_rect(&h, header);
        let below: Vec<Rect> = h
            .query_all_by_label(&value.to_string())
            .filter_map(|n| n.accesskit_node().bounding_box())
            .map(|r| {
                Rect::from_min_max(
                    Pos2::new(r.x0 as f32, r.y0 as f32),
                    Pos2::new(r.x1 as f32, r.y1 as f32),
                )
            })
            .collect();
        assert!(
            below
                .iter()
                .any(|r| r.min.y >= head.max.y && r.min.x < head.max.x && r.max.x > head.min.x),
            "{header:?} {head:?} heads the column holding green's {value}: {below:?}"
        );
    }
}

#[test]
fn a_typed_zoom_value_sets_the_zoom() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = first_frame_harness(dir.path());
    h.run();
    assert_eq!(
        workspace(&h).settings.transform.zoom,
        None,
        "fitted at first"
    );
    click_label(&mut h, "View");
    click_label(&mut h, "Zoom");
    // The value field beside the presets: the "Zoom" that is a spin button, not the submenu.
    let field = h
        .query_all_by_label("Zoom")
        .find(|n| n.accesskit_node().role() == egui::accesskit::Role::SpinButton)
        .expect("a zoom value field");
    field.click();
    h.run();
    h.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
    h.run();
    // In edit mode the field is a focused text input.
    let field = h
        .query_all(egui_kittest::kittest::By::new().predicate(|n| n.is_focused()))
        .next()
        .expect("the field in edit mode");
    field.type_text("250");
    h.run();
    h.key_press(egui::Key::Enter);
    h.run();
    let zoom = workspace(&h)
        .settings
        .transform
        .zoom
        .expect("a zoom was set");
    assert!((zoom - 2.5).abs() < 1e-4, "{zoom}");
    let xf = h.state().last_view.unwrap();
    assert!(
        (xf.zoom - 2.5).abs() < 1e-4,
        "the view is drawn at 250 %: {}",
        xf.zoom
    );
    assert!(
        painted_texts(&h).iter().any(|(t, _)| t == "250%"),
        "the view's corner says so"
    );
}

#[test]
fn settings_submenus_stay_open_while_switches_change_and_escape_closes_them() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = first_frame_harness(dir.path());
    h.run();
    click_label(&mut h, "View");
    click_label(&mut h, "Overlays");
    let before = workspace(&h).settings.overlays;
    click_label(&mut h, "Circle fits");
    click_label(&mut h, "Horizon");
    let after = workspace(&h).settings.overlays;
    assert_ne!(after.circles, before.circles);
    assert_ne!(
        after.horizon, before.horizon,
        "a second switch in the same visit"
    );
    h.key_press(egui::Key::Escape);
    h.run();
    h.run();
    assert!(
        h.query_by_label("Circle fits").is_none(),
        "Escape closed it"
    );
}

#[test]
fn the_uv_plane_has_ticks_and_values_on_both_axes() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = first_frame_harness(dir.path());
    h.run();
    h.state_mut()
        .state
        .run(Command::ShowWindow(Window::UvPlane, true));
    h.run();
    // The plane's image (the dock tab is named after it too).
    let plane = h
        .query_all_by_label("U–V plane")
        .find(|n| n.accesskit_node().role() == egui::accesskit::Role::Image)
        .and_then(|n| n.accesskit_node().bounding_box())
        .map(|r| {
            Rect::from_min_max(
                Pos2::new(r.x0 as f32, r.y0 as f32),
                Pos2::new(r.x1 as f32, r.y1 as f32),
            )
        })
        .expect("the U–V plane is drawn");
    let values = ["0", "64", "128", "192", "255"];
    let texts: Vec<(String, Rect)> = painted_texts(&h)
        .into_iter()
        .filter(|(t, r)| values.contains(&t.as_str()) && plane.expand(12.0).contains_rect(*r))
        .collect();
    // V across, above the plane: one value each, left to right, on one row, evenly spaced.
    let left_edge = texts.iter().map(|(_, r)| r.min.x).fold(f32::MAX, f32::min);
    let top_edge = texts.iter().map(|(_, r)| r.min.y).fold(f32::MAX, f32::min);
    let across: Vec<Pos2> = values
        .iter()
        .map(|v| {
            texts
                .iter()
                .filter(|(t, r)| t == v && (r.min.y - top_edge).abs() < 1.0)
                .map(|(_, r)| r.center())
                .next()
                .unwrap_or_else(|| panic!("V value {v} above the plane: {texts:?}"))
        })
        .collect();
    let down: Vec<Pos2> = values
        .iter()
        .map(|v| {
            texts
                .iter()
                .filter(|(t, r)| t == v && r.min.x - left_edge < 20.0 && r.min.y > top_edge + 5.0)
                .map(|(_, r)| r.center())
                .next()
                .unwrap_or_else(|| panic!("U value {v} left of the plane: {texts:?}"))
        })
        .collect();
    let spacing = |p: &[Pos2], along: fn(&Pos2) -> f32| -> Vec<f32> {
        p.windows(2).map(|w| along(&w[1]) - along(&w[0])).collect()
    };
    for (axis, gaps) in [
        ("V", spacing(&across, |p| p.x)),
        ("U", spacing(&down, |p| p.y)),
    ] {
        assert!(gaps.iter().all(|g| *g > 10.0), "{axis}: {gaps:?}");
        // 0, 64, 128, 192 are 64 apart and 255 is 63 further: even to a point.
        assert!(
            (gaps[0] - gaps[1]).abs() < 1.0 && (gaps[1] - gaps[2]).abs() < 1.0,
            "{axis}: {gaps:?}"
        );
    }
    assert!(
        painted_texts(&h)
            .iter()
            .any(|(t, r)| t == "U / V" && plane.contains_rect(*r))
    );
}

/// A press and release of the primary button at `pos`, one UI frame each.
fn click_events(h: &Harness<'_, EotnApp>, pos: Pos2) {
    for pressed in [true, false] {
        h.event(Event::PointerButton {
            pos,
            button: PointerButton::Primary,
            pressed,
            modifiers: Modifiers::NONE,
        });
    }
}

#[test]
fn double_click_fits_the_view_and_keeps_the_selection() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, table) = fixture(dir.path());
    let paths = vec![frames[0].clone(), table];
    // A UI frame every 1/60 s: two clicks four frames apart come within egui's double-click
    // interval (0.3 s). The default step (0.25 s) would make them two single clicks.
    let mut h = Harness::builder()
        .with_size(Vec2::new(1280.0, 800.0))
        .with_step_dt(1.0 / 60.0)
        .build_eframe(move |cc| EotnApp::new(cc, paths.clone(), None));
    h.run();
    // A selection made earlier (a field pixel), then zoomed in.
    h.state_mut()
        .state
        .run(TableCommand::Sample { x: 150, y: 120 }.into());
    h.state_mut()
        .state
        .run(ViewCommand::SetZoom(Some(2.5)).into());
    h.run();
    let before = workspace(&h).selection().cloned();
    assert_eq!(before.as_ref().and_then(|s| s.pixel), Some((150, 120)));
    // Double-click on the orange square: the view fits, the selection is the one from before.
    let ball = h.state().last_view.unwrap().pixel_centre(65, 45);
    h.event(Event::PointerMoved(ball));
    click_events(&h, ball);
    click_events(&h, ball);
    h.run();
    assert_eq!(workspace(&h).settings.transform.zoom, None, "fitted");
    assert_eq!(
        workspace(&h).selection().cloned(),
        before,
        "the selection is kept"
    );
    // With no selection before, none after (half a second later: not a third click).
    h.state_mut().state.run(TableCommand::ClearSelection.into());
    h.state_mut()
        .state
        .run(ViewCommand::SetZoom(Some(2.5)).into());
    h.run_steps(30);
    let ball = h.state().last_view.unwrap().pixel_centre(65, 45);
    h.event(Event::PointerMoved(ball));
    click_events(&h, ball);
    click_events(&h, ball);
    h.run();
    assert_eq!(workspace(&h).settings.transform.zoom, None);
    assert!(
        workspace(&h).selection().is_none(),
        "{:?}",
        workspace(&h).selection()
    );
    // A single click still samples at once (and the zoom stays).
    h.state_mut()
        .state
        .run(ViewCommand::SetZoom(Some(2.5)).into());
    h.run_steps(30);
    let ball = h.state().last_view.unwrap().pixel_centre(65, 45);
    h.event(Event::PointerMoved(ball));
    click_events(&h, ball);
    h.run();
    assert_eq!(
        workspace(&h).selection().and_then(|s| s.pixel),
        Some((65, 45))
    );
    assert_eq!(workspace(&h).settings.transform.zoom, Some(2.5));
}

#[test]
fn the_robots_window_fits_its_dock_tab_with_two_robots() {
    use crate::common::sim_stream;
    use crate::live::serve;
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 10, None);
    let alpha = serve(&stream, "127.0.0.1:0", &["--loop", "--name", "alpha"]);
    let bravo = serve(&stream, "127.0.0.1:0", &["--loop", "--name", "bravo"]);
    let mut h = harness(Vec::new());
    h.run_steps(4);
    h.state_mut()
        .state
        .run(Command::ShowWindow(Window::Robots, true));
    for port in [alpha.port, bravo.port] {
        h.state_mut()
            .state
            .run(RobotsCommand::ConnectRobot(format!("127.0.0.1:{port}")).into());
    }
    run_steps_until(&mut h, Duration::from_secs(30), |a| {
        let rows = a.state.robots();
        rows.len() == 2 && rows.iter().all(|r| r.stats.frames >= 3)
    });
    h.run_steps(4);
    // The dock column is right of the image; every robot's name, figures and buttons lie
    // between the image and the window's right edge: nothing needs a sideways scroll.
    let column_left = h.state().last_view.expect("the image is drawn").view.max.x;
    let screen_right = 1280.0;
    let mut checked = 0;
    for label in ["alpha", "bravo", "Record", "Disconnect"] {
        let nodes: Vec<Rect> = h
            .query_all_by_label(label)
            .filter_map(|n| n.accesskit_node().bounding_box())
            .map(|r| {
                Rect::from_min_max(
                    Pos2::new(r.x0 as f32, r.y0 as f32),
                    Pos2::new(r.x1 as f32, r.y1 as f32),
                )
            })
            .collect();
        let expected = if label.starts_with(char::is_uppercase) {
            2
        } else {
            1
        };
        assert_eq!(nodes.len(), expected, "{label}: {nodes:?}");
        for r in nodes {
            assert!(
                r.min.x >= column_left - 1.0 && r.max.x <= screen_right,
                "{label} at {r:?}, the column is {column_left}..{screen_right}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 6);
    assert!(h.query_all_by_label_contains(" fps").count() >= 2);
}

#[test]
fn the_docked_inspector_shows_the_whole_confidence_breakdown_at_1280_by_800() {
    let mut s = Workspace::default();
    s.apply(Command::Open(vec![
        repo_file("streams/sample.mcap"),
        repo_file("lookup_tables/sample.lut"),
    ]))
    .unwrap();
    let ball = s
        .recognition()
        .ball
        .ball
        .clone()
        .expect("a ball in frame 0");
    s.apply(Command::ShowWindow(Window::Inspector, true))
        .unwrap();
    s.apply(Command::SelectObject(Some(
        eotn::recognition::ObjectId::Ball(ball.candidate),
    )))
    .unwrap();
    let mut h = Harness::builder()
        .with_size(SCREEN)
        .build_eframe(move |_| EotnApp::with_state(s));
    h.run();
    // Every column of the breakdown lies on the screen: side by side with the list in the
    // docked column, the last columns were cut off at its right edge.
    for label in ["test", "value", "range", "effect", "result"] {
        let r = node_rect(&h, label);
        assert!(
            r.max.x <= SCREEN.x && r.min.x >= 0.0,
            "{label} at x {}–{}",
            r.min.x,
            r.max.x
        );
    }
    let test_name = node_rect(&h, "unclassified_around");
    assert!(test_name.max.x <= SCREEN.x, "{test_name:?}");
}
