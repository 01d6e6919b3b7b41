//! The menu bar: File, Classification, View, Stream, Camera, Overhead, Windows, Help. Menus rather than buttons
//! leave the screen to the images; every item sends a [`Command`] or toggles a window.

use std::path::PathBuf;

use egui::Ui;

use crate::blobs::Connectivity;
use crate::lut::{ColourClass, Sensitivity};
use crate::workspace::{Command, Overlays, SPEEDS, ViewKind, Window, Workspace, ZOOM_PRESETS};

/// What the menus ask of the app besides commands.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct MenuOutput {
    /// Quit was chosen.
    pub quit: bool,
    /// Help ▸ About was chosen.
    pub about: bool,
}

/// Path typed into File ▸ Open path (dialogs are not always available, e.g. under Xvfb).
#[derive(Debug, Default)]
pub struct MenuInput {
    /// The "Open path" window is shown.
    pub open: bool,
    /// The text of the path field.
    pub path: String,
}

/// The "Open path" window: a text field, because native dialogs are not always available.
pub fn open_path_window(ctx: &egui::Context, input: &mut MenuInput, commands: &mut Vec<Command>) {
    if !input.open {
        return;
    }
    let mut open = true;
    let mut done = false;
    egui::Window::new("Open path")
        .open(&mut open)
        .collapsible(false)
        .default_pos([300.0, 120.0])
        .show(ctx, |ui| {
            let edit = ui.add(
                egui::TextEdit::singleline(&mut input.path)
                    .hint_text("/path/to/stream.mcap, table.lut, places.json or frames")
                    .desired_width(420.0),
            );
            edit.request_focus();
            let enter = ui.input(|i| i.key_pressed(egui::Key::Enter));
            if (ui.button("Open").clicked() || enter) && !input.path.trim().is_empty() {
                commands.push(Command::Open(vec![PathBuf::from(input.path.trim())]));
                done = true;
            }
        });
    input.open = open && !done;
}

fn pick_open(title: &str, filters: &[(&str, &[&str])]) -> Option<Vec<PathBuf>> {
    let mut d = rfd::FileDialog::new().set_title(title);
    for (name, ext) in filters {
        d = d.add_filter(*name, ext);
    }
    d.pick_files()
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
            classification_menu_ui(ui, state, commands)
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
        if let Some(p) = pick_open(
            "Open a stream or frames",
            &[(
                "Streams and frames",
                &["mcap", "uyvy", "yuv", "raw", "png", "jpg", "jpeg"],
            )],
        ) {
            commands.push(Command::Open(p));
        }
        ui.close();
    }
    if ui.button("Open table…").clicked() {
        if let Some(p) = pick_open(
            "Open a lookup table",
            &[("Lookup tables", &["lut", "cal", "raw"])],
        ) {
            commands.extend(p.into_iter().map(Command::OpenTable));
        }
        ui.close();
    }
    if ui
        .button("Open path…")
        .on_hover_text("type a path: a stream, frames, a folder of frames or a table")
        .clicked()
    {
        input.open = true;
        ui.close();
    }
    ui.menu_button("New table", |ui| {
        for bits in [6u8, 7, 8] {
            if ui
                .button(format!("{bits} bits ({}³ cells)", 1 << bits))
                .clicked()
            {
                commands.push(Command::NewTable(bits));
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
        commands.push(Command::SaveTable);
        ui.close();
    }
    if ui.button("Save table as…").clicked() {
        if let Some(p) = rfd::FileDialog::new()
            .set_title("Save the lookup table")
            .add_filter("Lookup tables", &["lut"])
            .save_file()
        {
            commands.push(Command::SaveTableAs(p));
        }
        ui.close();
    }
    ui.separator();
    let has_frame = state.frame().is_some();
    if ui
        .add_enabled(has_frame, egui::Button::new("Export view as PNG…"))
        .clicked()
    {
        if let Some(p) = rfd::FileDialog::new()
            .set_title("Export the view")
            .add_filter("PNG", &["png"])
            .set_file_name(default_export_name(state))
            .save_file()
        {
            commands.push(Command::ExportView(p));
        }
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
        commands.push(Command::ExportView(PathBuf::from(default_export_name(
            state,
        ))));
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

/// `eotn-view-FRAME-VIEW.png`.
#[must_use]
pub fn default_export_name(state: &Workspace) -> String {
    format!(
        "eotn-view-{:05}-{}.png",
        state.index(),
        state.settings.main_view.name().to_ascii_lowercase()
    )
}

fn classification_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    ui.menu_button(format!("Class: {}", state.settings.class.name()), |ui| {
        for class in ColourClass::ALL {
            if ui
                .selectable_label(state.settings.class == class, class.name())
                .clicked()
            {
                commands.push(Command::SetClass(class));
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
                commands.push(Command::SetSensitivity(Sensitivity::uniform(n)));
                ui.close();
            }
        }
    });
    ui.separator();
    let h = state.history();
    if ui
        .add_enabled(
            h.undo_len() > 0,
            egui::Button::new("Undo").shortcut_text("Ctrl+Z"),
        )
        .clicked()
    {
        commands.push(Command::Undo);
        ui.close();
    }
    if ui
        .add_enabled(
            h.redo_len() > 0,
            egui::Button::new("Redo").shortcut_text("Ctrl+Y"),
        )
        .clicked()
    {
        commands.push(Command::Redo);
        ui.close();
    }
    if ui
        .add_enabled(
            state.selection().is_some(),
            egui::Button::new("Commit selection"),
        )
        .clicked()
    {
        commands.push(Command::Commit);
        ui.close();
    }
    if ui
        .add_enabled(
            state.selection().is_some() && state.source().is_some_and(|s| s.len() > 1),
            egui::Button::new("Try selection on whole stream"),
        )
        .clicked()
    {
        commands.push(Command::TryEditOnStream);
        ui.close();
    }
    ui.separator();
    if ui
        .button("Open places…")
        .on_hover_text(
            "a places file from `eotn patterns learn`: pink markers are identified as its places",
        )
        .clicked()
    {
        if let Some(p) = pick_open("Open a places file", &[("Places", &["json"])]) {
            commands.extend(p.into_iter().map(Command::OpenPlaces));
        }
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
        commands.push(Command::RebuildFromJournal);
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
                commands.push(Command::SetMainView(kind));
                ui.close();
            }
        }
    });
    ui.menu_button("Zoom", |ui| {
        if ui.button("Fit (double-click)").clicked() {
            commands.push(Command::ResetView);
            ui.close();
        }
        for z in ZOOM_PRESETS {
            if ui.button(format!("{:.0}%", z * 100.0)).clicked() {
                commands.push(Command::SetZoom(Some(z)));
                ui.close();
            }
        }
    });
    ui.menu_button("Overlays", |ui| overlays_menu_ui(ui, state, commands));
    let mut inspector = state.window_open(Window::Inspector);
    if ui.checkbox(&mut inspector, "Object inspector").changed() {
        commands.push(Command::ShowWindow(Window::Inspector, inspector));
    }
    let mut timings = state.settings.show_timings;
    if ui.checkbox(&mut timings, "Frame-time readout").changed() {
        commands.push(Command::ShowTimings(timings));
    }
    ui.separator();
    let c = state.settings.connectivity;
    for (conn, name) in [
        (Connectivity::Eight, "8-connected blobs"),
        (Connectivity::Four, "4-connected blobs"),
    ] {
        if ui.selectable_label(c == conn, name).clicked() {
            commands.push(Command::SetConnectivity(conn));
        }
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
        commands.push(Command::SetOverlays(o));
    }
}

fn stream_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let open = state.source().is_some();
    for (label, cmd, key) in [
        ("Previous frame", Command::Step(-1), "Left"),
        ("Next frame", Command::Step(1), "Right"),
        ("Back 10 frames", Command::Step(-10), "PgUp"),
        ("Forward 10 frames", Command::Step(10), "PgDn"),
        ("First frame", Command::Seek(0), "Home"),
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
        commands.push(Command::SetPlaying(!state.playing()));
        ui.close();
    }
    ui.menu_button("Speed", |ui| {
        for s in SPEEDS {
            let name = speed_name(s);
            if ui
                .selectable_label((state.settings.speed - s).abs() < 1e-6, name)
                .clicked()
            {
                commands.push(Command::SetSpeed(s));
                ui.close();
            }
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
