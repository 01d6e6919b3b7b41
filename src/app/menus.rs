//! The menu bar: File, Classification, View, Stream, Camera, Overhead, Windows, Help. Menus rather than buttons
//! leave the screen to the images; every item sends a [`Command`] or toggles a window.

use std::path::PathBuf;

use egui::Ui;

use super::file_dialog::FileAction;
use crate::blobs::Connectivity;
use crate::lut::{ColourClass, Sensitivity};
use crate::workspace::{
    Command, Overlays, ParamsCommand, PlaybackCommand, SPEEDS, TableCommand, ViewCommand, ViewKind,
    Window, Workspace, ZOOM_PRESETS, ZOOM_RANGE,
};

/// What the menus ask of the app besides commands.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct MenuOutput {
    /// Quit was chosen.
    pub quit: bool,
    /// Help ▸ About was chosen.
    pub about: bool,
}

/// Path typed into File ▸ Open path, and the file dialog a menu asked for.
#[derive(Debug, Default)]
pub struct MenuInput {
    /// The "Open path" window is shown.
    pub open: bool,
    /// The "Open path" window opens a label set over the frames (`Command::OpenLabels`)
    /// instead of a stream, frames or a table.
    pub open_labels: bool,
    /// The text of the path field.
    pub path: String,
    /// A file dialog to open (what for, and the file name to suggest for a save).
    pub dialog: Option<(FileAction, Option<String>)>,
}

/// The "Open path" window: a text field, because native dialogs are not always available.
pub fn open_path_window(ctx: &egui::Context, input: &mut MenuInput, commands: &mut Vec<Command>) {
    if !input.open {
        return;
    }
    let mut open = true;
    let mut done = false;
    let (title, hint) = if input.open_labels {
        (
            "Open labels path",
            "/path/to/labels-yolo, labels-voc or coco.json (over the open frames)",
        )
    } else {
        (
            "Open path",
            "/path/to/stream.mcap, table.lut, params.json, places.json or frames",
        )
    };
    egui::Window::new(title)
        .open(&mut open)
        .collapsible(false)
        .default_pos([300.0, 120.0])
        .show(ctx, |ui| {
            let label = ui.label("path");
            let edit = ui
                .add(
                    egui::TextEdit::singleline(&mut input.path)
                        .hint_text(hint)
                        .desired_width(420.0),
                )
                .labelled_by(label.id);
            edit.request_focus();
            let enter = ui.input(|i| i.key_pressed(egui::Key::Enter));
            if (ui.button("Open").clicked() || enter) && !input.path.trim().is_empty() {
                let path = PathBuf::from(input.path.trim());
                commands.push(if input.open_labels {
                    Command::OpenLabels(path)
                } else {
                    Command::Open(vec![path])
                });
                done = true;
            }
        });
    input.open = open && !done;
}

/// The menu bar.
pub fn menu_bar_ui(
    ui: &mut Ui,
    state: &Workspace,
    input: &mut MenuInput,
    commands: &mut Vec<Command>,
) -> MenuOutput {
    let mut out = MenuOutput::default();
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            file_menu_ui(ui, state, input, commands, &mut out)
        });
        ui.menu_button("Classification", |ui| {
            classification_menu_ui(ui, state, input, commands)
        });
        ui.menu_button("View", |ui| view_menu_ui(ui, state, commands));
        ui.menu_button("Stream", |ui| stream_menu_ui(ui, state, commands));
        ui.menu_button("Camera", |ui| {
            super::camera_menu::camera_menu_ui(ui, state, commands);
        });
        ui.menu_button("Overhead", |ui| {
            super::overhead_menu::overhead_menu_ui(ui, state, commands);
        });
        ui.menu_button("Windows", |ui| windows_menu_ui(ui, state, commands));
        ui.menu_button("Help", |ui| {
            if ui.button("About eotn").clicked() {
                out.about = true;
                ui.close();
            }
        });
    });
    out
}

fn file_menu_ui(
    ui: &mut Ui,
    state: &Workspace,
    input: &mut MenuInput,
    commands: &mut Vec<Command>,
    out: &mut MenuOutput,
) {
    if ui.button("Open stream or frames…").clicked() {
        input.dialog = Some((FileAction::Open, None));
        ui.close();
    }
    if ui.button("Open table…").clicked() {
        input.dialog = Some((FileAction::OpenTable, None));
        ui.close();
    }
    if ui
        .button("Open path…")
        .on_hover_text("type a path: a stream, frames, a folder of frames or a table")
        .clicked()
    {
        input.open = true;
        input.open_labels = false;
        ui.close();
    }
    labels_items_ui(ui, state, input);
    ui.menu_button("New table", |ui| {
        for bits in [6u8, 7, 8] {
            if ui
                .button(format!("{bits} bits ({}³ cells)", 1 << bits))
                .clicked()
            {
                commands.push(TableCommand::NewTable(bits).into());
                ui.close();
            }
        }
    });
    ui.separator();
    if ui
        .add_enabled(
            state.table_path().is_some(),
            egui::Button::new("Save table").shortcut_text("Ctrl+S"),
        )
        .clicked()
    {
        commands.push(TableCommand::SaveTable.into());
        ui.close();
    }
    if ui.button("Save table as…").clicked() {
        input.dialog = Some((FileAction::SaveTableAs, Some("table.lut".to_owned())));
        ui.close();
    }
    ui.separator();
    params_menu_items_ui(ui, state, input, commands);
    ui.separator();
    let has_frame = state.frame().is_some();
    if ui
        .add_enabled(has_frame, egui::Button::new("Export view as PNG…"))
        .clicked()
    {
        input.dialog = Some((FileAction::ExportView, Some(default_export_name(state))));
        ui.close();
    }
    if ui
        .add_enabled(
            has_frame,
            egui::Button::new(format!("Export view as {}", default_export_name(state))),
        )
        .on_hover_text("into the current folder, no dialog")
        .clicked()
    {
        commands.push(ViewCommand::ExportView(PathBuf::from(default_export_name(state))).into());
        ui.close();
    }
    ui.separator();
    ui.menu_button("Recent files", |ui| {
        if state.settings.recent.is_empty() {
            ui.weak("none yet");
        }
        for p in &state.settings.recent {
            if ui.button(p.display().to_string()).clicked() {
                commands.push(Command::Open(vec![p.clone()]));
                ui.close();
            }
        }
    });
    ui.separator();
    if ui
        .add(egui::Button::new("Quit").shortcut_text("Ctrl+Q"))
        .clicked()
    {
        out.quit = true;
        ui.close();
    }
}

/// File ▸ Open labels: a label set over the open frames (a YOLO or Pascal VOC folder from the
/// folder dialog, a COCO JSON file from the file dialog, or any of them as a typed path).
fn labels_items_ui(ui: &mut Ui, state: &Workspace, input: &mut MenuInput) {
    let frames = state.source().is_some();
    let why = "open the frames first, then their labels";
    ui.menu_button("Open labels", |ui| {
        if ui
            .add_enabled(frames, egui::Button::new("Labels folder (YOLO, VOC)…"))
            .on_disabled_hover_text(why)
            .clicked()
        {
            input.dialog = Some((FileAction::OpenLabelsFolder, None));
            ui.close();
        }
        if ui
            .add_enabled(frames, egui::Button::new("Labels file (COCO JSON)…"))
            .on_disabled_hover_text(why)
            .clicked()
        {
            input.dialog = Some((FileAction::OpenLabelsFile, None));
            ui.close();
        }
        if ui
            .add_enabled(frames, egui::Button::new("Labels path…"))
            .on_hover_text("type the path of a label set")
            .on_disabled_hover_text(why)
            .clicked()
        {
            input.open = true;
            input.open_labels = true;
            ui.close();
        }
    });
}

/// File ▸ Open parameters…, the stream's set, the defaults, Save parameters as….
fn params_menu_items_ui(
    ui: &mut Ui,
    state: &Workspace,
    input: &mut MenuInput,
    commands: &mut Vec<Command>,
) {
    if ui
        .button("Open parameters…")
        .on_hover_text("recognition parameters (params/spl2009.json: the 2009 SPL field)")
        .clicked()
    {
        input.dialog = Some((FileAction::OpenParams, None));
        ui.close();
    }
    if let Some(o) = &state.params_slot().offer {
        let label = format!("Use the stream's parameters ({})", o.name);
        let hover = o.path.as_ref().map_or_else(
            || format!("params/{}.json was not found near the stream", o.name),
            |p| p.display().to_string(),
        );
        if ui
            .add_enabled(o.path.is_some(), egui::Button::new(label))
            .on_hover_text(hover)
            .on_disabled_hover_text(format!(
                "params/{}.json was not found near the stream: Open parameters…",
                o.name
            ))
            .clicked()
        {
            commands.push(ParamsCommand::UseOfferedParams.into());
            ui.close();
        }
    }
    if ui
        .add_enabled(
            state.params_slot().path.is_some() || state.params_modified(),
            egui::Button::new("Default parameters"),
        )
        .clicked()
    {
        commands.push(ParamsCommand::DefaultParams.into());
        ui.close();
    }
    if ui.button("Save parameters as…").clicked() {
        input.dialog = Some((FileAction::SaveParams, Some("params.json".to_owned())));
        ui.close();
    }
}

/// `eotn-view-FRAME-VIEW.png`.
#[must_use]
pub fn default_export_name(state: &Workspace) -> String {
    format!(
        "eotn-view-{:05}-{}.png",
        state.index(),
        state.settings.main_view.name().to_ascii_lowercase()
    )
}

fn classification_menu_ui(
    ui: &mut Ui,
    state: &Workspace,
    input: &mut MenuInput,
    commands: &mut Vec<Command>,
) {
    class_menus_ui(ui, state, commands);
    ui.separator();
    table_edit_items_ui(ui, state, commands);
    ui.separator();
    places_items_ui(ui, state, input, commands);
}

/// The Class and Sensitivity submenus.
fn class_menus_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    ui.menu_button(format!("Class: {}", state.settings.class.name()), |ui| {
        for class in ColourClass::ALL {
            if ui
                .selectable_label(state.settings.class == class, class.name())
                .clicked()
            {
                commands.push(TableCommand::SetClass(class).into());
                ui.close();
            }
        }
    });
    ui.menu_button("Sensitivity", |ui| {
        for n in [0u8, 1, 2, 3, 4, 6, 8] {
            if ui
                .selectable_label(
                    state.settings.sensitivity == Sensitivity::uniform(n),
                    format!("± {n} cells"),
                )
                .clicked()
            {
                commands.push(TableCommand::SetSensitivity(Sensitivity::uniform(n)).into());
                ui.close();
            }
        }
    });
}

/// Undo, Redo, Commit selection, Try selection on whole stream.
fn table_edit_items_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let h = state.history();
    if ui
        .add_enabled(
            h.undo_len() > 0,
            egui::Button::new("Undo").shortcut_text("Ctrl+Z"),
        )
        .clicked()
    {
        commands.push(TableCommand::Undo.into());
        ui.close();
    }
    if ui
        .add_enabled(
            h.redo_len() > 0,
            egui::Button::new("Redo").shortcut_text("Ctrl+Y"),
        )
        .clicked()
    {
        commands.push(TableCommand::Redo.into());
        ui.close();
    }
    if ui
        .add_enabled(
            state.selection().is_some(),
            egui::Button::new("Commit selection"),
        )
        .clicked()
    {
        commands.push(TableCommand::Commit.into());
        ui.close();
    }
    if ui
        .add_enabled(
            state.selection().is_some() && state.source().is_some_and(|s| s.len() > 1),
            egui::Button::new("Try selection on whole stream"),
        )
        .clicked()
    {
        commands.push(TableCommand::TryEditOnStream.into());
        ui.close();
    }
}

/// Open and Close places, Rebuild table from journal.
fn places_items_ui(
    ui: &mut Ui,
    state: &Workspace,
    input: &mut MenuInput,
    commands: &mut Vec<Command>,
) {
    if ui
        .button("Open places…")
        .on_hover_text(
            "a places file from `eotn patterns learn`: pink markers are identified as its places",
        )
        .clicked()
    {
        input.dialog = Some((FileAction::OpenPlaces, None));
        ui.close();
    }
    let places = state.places_path().map_or_else(
        || "Close places".to_owned(),
        |p| format!("Close places {}", crate::frame::display_name(p)),
    );
    if ui
        .add_enabled(state.places_path().is_some(), egui::Button::new(places))
        .clicked()
    {
        commands.push(Command::ClosePlaces);
        ui.close();
    }
    ui.separator();
    if ui
        .add_enabled(
            state.table_path().is_some(),
            egui::Button::new("Rebuild table from journal"),
        )
        .on_hover_text("replay TABLE.journal.jsonl onto the table it started from")
        .clicked()
    {
        commands.push(TableCommand::RebuildFromJournal.into());
        ui.close();
    }
}

fn view_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    ui.menu_button("Enlarged view", |ui| {
        for kind in ViewKind::ALL {
            if ui
                .selectable_label(state.settings.main_view == kind, kind.name())
                .clicked()
            {
                commands.push(ViewCommand::SetMainView(kind).into());
                ui.close();
            }
        }
    });
    stays_open_on_clicks("Zoom", ui, |ui| {
        if ui.button("Fit (double-click)").clicked() {
            commands.push(ViewCommand::ResetView.into());
            ui.close();
        }
        for z in ZOOM_PRESETS {
            if ui.button(format!("{:.0}%", z * 100.0)).clicked() {
                commands.push(ViewCommand::SetZoom(Some(z)).into());
                ui.close();
            }
        }
        ui.separator();
        zoom_value_ui(ui, state, commands);
    });
    stays_open_on_clicks("Blob boxes", ui, |ui| blob_filter_ui(ui, state, commands));
    stays_open_on_clicks("Overlays", ui, |ui| overlays_menu_ui(ui, state, commands));
    let mut inspector = state.window_open(Window::Inspector);
    if ui.checkbox(&mut inspector, "Object inspector").changed() {
        commands.push(Command::ShowWindow(Window::Inspector, inspector));
    }
    let mut timings = state.settings.show_timings;
    if ui.checkbox(&mut timings, "Frame-time readout").changed() {
        commands.push(ViewCommand::ShowTimings(timings).into());
    }
    ui.separator();
    let c = state.settings.connectivity;
    for (conn, name) in [
        (Connectivity::Eight, "8-connected blobs"),
        (Connectivity::Four, "4-connected blobs"),
    ] {
        if ui.selectable_label(c == conn, name).clicked() {
            commands.push(ViewCommand::SetConnectivity(conn).into());
        }
    }
}

/// A submenu that a click inside leaves open (egui's menus close on any click inside), for
/// one holding value fields, sliders or switches: clicking a field to type into it, or the
/// opacity slider's track, must not close the menu, and several overlays can be switched in
/// one go. Its buttons close it themselves (`ui.close()`); a click outside or Escape closes it.
fn stays_open_on_clicks(title: &str, ui: &mut Ui, contents: impl FnOnce(&mut Ui)) {
    use egui::containers::menu::{MenuConfig, SubMenuButton};
    SubMenuButton::new(title)
        .config(MenuConfig::new().close_behavior(egui::PopupCloseBehavior::CloseOnClickOutside))
        .ui(ui, contents);
}

/// A typed zoom value in percent (Enter or leaving the field applies it).
pub fn zoom_value_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let mut percent = state.settings.transform.zoom.map_or(100.0, |z| z * 100.0);
    let before = percent;
    ui.horizontal(|ui| {
        let l = ui.label("Zoom");
        let r = ui
            .add(
                egui::DragValue::new(&mut percent)
                    .range(ZOOM_RANGE.0 * 100.0..=ZOOM_RANGE.1 * 100.0)
                    .suffix(" %")
                    .max_decimals(1),
            )
            .labelled_by(l.id)
            .on_hover_text("type a zoom in percent");
        if r.changed() && (percent - before).abs() > f32::EPSILON {
            commands.push(ViewCommand::SetZoom(Some(percent / 100.0)).into());
        }
    });
}

/// View ▸ Blob boxes: the smallest blob drawn and the classes drawn.
fn blob_filter_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let mut min = state.settings.min_blob_pixels;
    let mut hidden = state.settings.hidden_blob_classes.clone();
    let mut changed = false;
    ui.horizontal(|ui| {
        let l = ui.label("Smallest blob");
        changed |= ui
            .add(
                egui::DragValue::new(&mut min)
                    .range(1..=100_000)
                    .suffix(" px"),
            )
            .labelled_by(l.id)
            .changed();
    });
    ui.separator();
    for class in ColourClass::ALL.into_iter().skip(1) {
        let mut shown = !hidden.contains(&class);
        if ui
            .checkbox(&mut shown, format!("{} blobs", class.name()))
            .changed()
        {
            changed = true;
            if shown {
                hidden.retain(|c| *c != class);
            } else {
                hidden.push(class);
            }
        }
    }
    if changed {
        commands.push(
            ViewCommand::SetBlobFilter {
                min_pixels: min,
                hidden,
            }
            .into(),
        );
    }
}

/// View ▸ Overlays: every switch, the pipeline's first, then recognition's.
fn overlays_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let mut o: Overlays = state.settings.overlays;
    let before = o;
    ui.checkbox(&mut o.classified, "Classified over colour");
    ui.add(egui::Slider::new(&mut o.opacity, 0.0..=1.0).text("opacity"));
    ui.checkbox(&mut o.blob_boxes, "Blob boxes");
    ui.checkbox(&mut o.labels, "Blob labels");
    ui.checkbox(&mut o.preview, "Selection preview");
    ui.separator();
    ui.weak("Recognition");
    ui.checkbox(&mut o.candidates, "Candidate boxes");
    ui.checkbox(&mut o.circles, "Circle fits");
    ui.checkbox(&mut o.scan_areas, "Scan areas");
    ui.checkbox(&mut o.scan_points, "Scan points");
    ui.checkbox(&mut o.posts, "Goal posts");
    ui.checkbox(&mut o.gaps, "Gaps");
    ui.checkbox(&mut o.horizon, "Horizon");
    ui.checkbox(&mut o.patterns, "Coloured patterns (pink markers)");
    ui.checkbox(&mut o.object_labels, "Object labels (distance, bearing)");
    ui.horizontal(|ui| {
        for (name, on) in [("All recognition", true), ("None", false)] {
            if ui.button(name).clicked() {
                o.set_recognition(on);
            }
        }
    });
    if o != before {
        commands.push(ViewCommand::SetOverlays(o).into());
    }
}

fn stream_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let open = state.source().is_some();
    for (label, cmd, key) in [
        (
            "Previous frame",
            Command::Playback(PlaybackCommand::Step(-1)),
            "Left",
        ),
        (
            "Next frame",
            Command::Playback(PlaybackCommand::Step(1)),
            "Right",
        ),
        (
            "Back 10 frames",
            Command::Playback(PlaybackCommand::Step(-10)),
            "PgUp",
        ),
        (
            "Forward 10 frames",
            Command::Playback(PlaybackCommand::Step(10)),
            "PgDn",
        ),
        (
            "First frame",
            Command::Playback(PlaybackCommand::Seek(0)),
            "Home",
        ),
        (
            "Last frame",
            Command::Playback(PlaybackCommand::Seek(usize::MAX)),
            "End",
        ),
    ] {
        if ui
            .add_enabled(open, egui::Button::new(label).shortcut_text(key))
            .clicked()
        {
            commands.push(cmd);
        }
    }
    let play = if state.playing() { "Pause" } else { "Play" };
    if ui
        .add_enabled(open, egui::Button::new(play).shortcut_text("Space"))
        .clicked()
    {
        commands.push(PlaybackCommand::SetPlaying(!state.playing()).into());
        ui.close();
    }
    cameras_menu_ui(ui, state, commands);
    ui.menu_button("Speed", |ui| {
        for s in SPEEDS {
            let name = speed_name(s);
            if ui
                .selectable_label((state.settings.speed - s).abs() < 1e-6, name)
                .clicked()
            {
                commands.push(PlaybackCommand::SetSpeed(s).into());
                ui.close();
            }
        }
    });
}

/// The camera picker: every camera (image topic) of the open recording or shown robot, the
/// shown one ticked; picking one shows it at the same time with its own table
/// (`Command::OpenCamera`).
fn cameras_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let (cameras, shown) = state.cameras();
    let of = if state.shown_robot().is_some() {
        "Camera of the robot"
    } else {
        "Camera of the recording"
    };
    ui.add_enabled_ui(cameras.len() > 1, |ui| {
        ui.menu_button(of, |ui| {
            for camera in &cameras {
                if ui
                    .selectable_label(shown.as_ref() == Some(camera), camera.topic())
                    .clicked()
                {
                    commands.push(Command::OpenCamera(Some(camera.clone())));
                    ui.close();
                }
            }
        });
        // Every camera at once, stepped together by time, each with its own table.
        let mut together = !state.camera_panes().is_empty();
        if ui.checkbox(&mut together, "Cameras side by side").clicked() {
            let shown = if together { cameras } else { Vec::new() };
            commands.push(Command::ShowSideBySide(shown));
            ui.close();
        }
    });
}

/// "1×", "0.5×", or "every frame" for 0.
#[must_use]
pub fn speed_name(s: f32) -> String {
    if s <= 0.0 {
        "every frame".to_owned()
    } else {
        format!("{s}×")
    }
}

fn windows_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    for w in Window::ALL {
        let mut open = state.window_open(w);
        if ui.checkbox(&mut open, w.name()).changed() {
            commands.push(Command::ShowWindow(w, open));
        }
    }
}
