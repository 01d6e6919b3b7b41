//! The window's furniture after a new user's round (issue 33), with egui_kittest on the real
//! app: the timeline's marks lie along the slider's track (not its label); a dock group split
//! by a dropped tab keeps every window's tab, title and close button; every character the app
//! and its file dialog show is in the fonts (no empty boxes).

use egui::{FontFamily, FontId};
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use egui_tiles::{Container, Tile};
use eotn::app::dock::Pane;
use eotn::workspace::{Command, HintsCommand, PlaybackCommand, Window, Workspace};

use crate::common::repo_file;
use crate::harness::{fixture_files, harness_with, show_window};

#[test]
fn the_timeline_marks_lie_along_the_slider_track() {
    let dir = tempfile::tempdir().unwrap();
    let mut w = Workspace::default();
    w.apply(Command::Open(fixture_files(dir.path()))).unwrap();
    for frame in [0, 2] {
        w.apply(PlaybackCommand::Seek(frame).into()).unwrap();
        w.apply(HintsCommand::AddBookmark(format!("mark {frame}")).into())
            .unwrap();
    }
    let mut h = harness_with(w);
    h.run();
    let track = h
        .state()
        .last_timeline_track
        .expect("the timeline was drawn");
    // The slider's own rectangle (its accessible node) is the track: the text after it is not.
    let slider = h
        .get_all_by_role(egui::accesskit::Role::Slider)
        .find(|n| n.accesskit_node().label().as_deref() == Some("timeline"))
        .expect("the timeline slider")
        .rect();
    assert!(
        (track.left() - slider.left()).abs() < 1.0 && (track.right() - slider.right()).abs() < 1.0,
        "marks over {track:?}, slider at {slider:?}"
    );
}

/// The tiles holding a window pane, with the kind of each one's parent.
fn parents(
    h: &egui_kittest::Harness<'_, eotn::app::EotnApp>,
) -> Vec<(Window, Option<egui_tiles::ContainerKind>)> {
    h.state().dock.window_parents()
}

#[test]
fn a_dock_group_split_by_a_dropped_tab_keeps_every_windows_tab() {
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![repo_file("streams/sample.mcap")]))
        .unwrap();
    let mut h = harness_with(w);
    show_window(&mut h, Window::Sensors);
    show_window(&mut h, Window::Inspector);
    // What a tab dropped on the side of another group makes: a row of the two bare windows
    // inside one tab group (egui_tiles titles it "Horizontal"; its windows have no tab bar).
    {
        let tree = h.state_mut().dock.tree_mut();
        let sensors = tree
            .tiles
            .find_pane(&Pane::Window(Window::Sensors))
            .unwrap();
        let inspector = tree
            .tiles
            .find_pane(&Pane::Window(Window::Inspector))
            .unwrap();
        for pane in [sensors, inspector] {
            let parent = tree.tiles.parent_of(pane).unwrap();
            if let Some(Tile::Container(c)) = tree.tiles.get_mut(parent) {
                c.remove_child(pane);
            }
        }
        let row = tree.tiles.insert_horizontal_tile(vec![sensors, inspector]);
        let group = tree
            .tiles
            .tile_ids()
            .find(|id| matches!(tree.tiles.get(*id), Some(Tile::Container(Container::Tabs(t))) if t.children.is_empty()))
            .unwrap();
        if let Some(Tile::Container(Container::Tabs(t))) = tree.tiles.get_mut(group) {
            t.add_child(row);
            t.set_active(row);
        }
    }
    h.run();
    for (w, kind) in parents(&h) {
        assert_eq!(
            kind,
            Some(egui_tiles::ContainerKind::Tabs),
            "{w:?} has no tab"
        );
    }
    assert!(
        h.query_by_label("Horizontal").is_none(),
        "a tab titled Horizontal"
    );
    // Each window's tab: its title, and a close button that closes it.
    for name in [Window::Sensors.name(), Window::Inspector.name()] {
        assert!(
            h.query_all_by_label(name).count() >= 1,
            "{name}'s tab title"
        );
    }
    let titles: Vec<String> = h
        .query_all_by_label_contains(" + ")
        .filter_map(|n| n.accesskit_node().label())
        .collect();
    assert!(
        titles.iter().any(|t| t == "Sensors + Object inspector"),
        "the group's tab is named by its windows: {titles:?}; all: {:?}",
        h.root()
            .children_recursive()
            .filter_map(|n| n.accesskit_node().label())
            .collect::<Vec<_>>()
    );
}

#[test]
fn every_character_the_app_and_its_file_dialog_show_is_in_the_fonts() {
    let mut text = String::new();
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(repo_file("src/app"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in files {
        let source = std::fs::read_to_string(&f).unwrap();
        // String literals only (comments may say anything).
        for (k, piece) in source.split('"').enumerate() {
            if k % 2 == 1 {
                text.push_str(piece);
            }
        }
    }
    // egui_file 0.29's icons (folder, file, parent, refresh, save).
    text.push_str("🗀🗋⬆⟲📁📂💾");
    let wanted: std::collections::BTreeSet<char> = text
        .chars()
        .filter(|c| !c.is_ascii() && !c.is_control())
        .collect();
    assert!(wanted.contains(&'✔') && wanted.contains(&'🗀'));
    let h = harness_with(Workspace::default());
    let missing: Vec<(char, &str)> = h.ctx.fonts_mut(|f| {
        let mut out = Vec::new();
        for family in [FontFamily::Proportional, FontFamily::Monospace] {
            let name = if family == FontFamily::Proportional {
                "proportional"
            } else {
                "monospace"
            };
            for &c in &wanted {
                if !f.has_glyph(&FontId::new(14.0, family.clone()), c) {
                    out.push((c, name));
                }
            }
        }
        out
    });
    assert!(missing.is_empty(), "no glyph for {missing:?}");
}
