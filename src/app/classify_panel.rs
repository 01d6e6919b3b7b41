//! Hand classification: the class picker, the sensitivity sliders, the pending selection with
//! commit, undo and redo, and the whole-stream check of a pending edit.

use egui::{Color32, RichText, Sense, Ui, vec2};

use crate::lut::{ColourClass, Sensitivity};
use crate::workspace::{Command, ParamsCommand, PlaybackCommand, TableCommand, TryEdit, Workspace};

/// A colour swatch the size of a line of text.
pub fn swatch(ui: &mut Ui, rgb: [u8; 3]) {
    let (rect, _) = ui.allocate_exact_size(vec2(12.0, 12.0), Sense::hover());
    ui.painter()
        .rect_filled(rect, 2.0, Color32::from_rgb(rgb[0], rgb[1], rgb[2]));
}

/// The side panel's contents: the pending selection (Commit, Clear, Try) and Undo/Redo at its
/// foot, always in view; the classes and sensitivity above them, scrolling when the window is
/// short (at 800 px the buttons had fallen below the fold, and the scroll jumped back up
/// whenever a selection changed the content's height).
pub fn classify_panel_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    egui::Panel::bottom("classify-actions")
        .resizable(false)
        .show(ui, |ui| {
            ui.add_space(4.0);
            pending_selection_ui(ui, state, commands);
            ui.separator();
            undo_redo_ui(ui, state, commands);
        });
    egui::ScrollArea::vertical()
        .id_salt("classify-scroll")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            ui.heading("Classify");
            ui.label(
                RichText::new("left-click: sample · right-click: commit")
                    .small()
                    .weak(),
            );
            ui.separator();
            classes_ui(ui, state, commands);
            ui.separator();
            sensitivity_ui(ui, state, commands);
        });
}

/// Each class with its table cells and frame pixels; clicking one picks it.
fn classes_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let counts = state.table_counts();
    let frame_counts = state.frame_counts();
    egui::Grid::new("classes").num_columns(3).show(ui, |ui| {
        ui.label(RichText::new("class").small().weak());
        ui.label(RichText::new("table cells").small().weak())
            .on_hover_text("cells of the lookup table set to the class");
        ui.label(RichText::new("frame pixels").small().weak())
            .on_hover_text("pixels of the shown frame of the class");
        ui.end_row();
        for class in ColourClass::ALL {
            ui.horizontal(|ui| {
                swatch(ui, class.display_rgb());
                if ui
                    .selectable_label(state.settings.class == class, class.name())
                    .clicked()
                {
                    commands.push(TableCommand::SetClass(class).into());
                }
            });
            let code = usize::from(class.code());
            ui.label(RichText::new(format!("{}", counts[code])).small())
                .on_hover_text("table cells of this class");
            ui.label(RichText::new(format!("{}", frame_counts[code])).small())
                .on_hover_text("pixels of this class in the frame");
            ui.end_row();
        }
    });
}

/// The Y, U and V reach of a selection, with presets.
fn sensitivity_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    ui.label("Sensitivity (± cells)");
    let max = state.max_sensitivity();
    let mut s = state.settings.sensitivity;
    let before = s;
    for (name, value, keys) in [
        ("Y", &mut s.y, "Y / Shift+Y"),
        ("U", &mut s.u, "U / Shift+U"),
        ("V", &mut s.v, "V / Shift+V"),
    ] {
        ui.add(egui::Slider::new(value, 0..=max).text(name))
            .on_hover_text(format!("keys {keys}; + and - change all three"));
    }
    if s != before {
        commands.push(TableCommand::SetSensitivity(s).into());
    }
    ui.horizontal(|ui| {
        for n in [0u8, 1, 2, 4] {
            if ui.small_button(format!("{n}")).clicked() {
                commands.push(TableCommand::SetSensitivity(Sensitivity::uniform(n)).into());
            }
        }
    });
}

/// The pending selection: where it came from, what it changes, Commit, Clear, Try.
fn pending_selection_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    match (state.selection(), state.resolved_selection()) {
        (Some(sel), Some(resolved)) => {
            let cells = resolved.indices(state.lut()).count();
            let (selected, changing) = state.selection_pixel_counts();
            if let Some((x, y)) = sel.pixel {
                ui.label(format!("sample ({x}, {y})"));
            } else {
                ui.label("sample from the U–V plane");
            }
            match state.selection_class().map(ColourClass::name) {
                Some(class) => ui
                    .label(format!(
                        "{cells} cells; {changing} pixels of this frame change to {class} ({} already {class})",
                        selected - changing,
                    ))
                    .on_hover_text(format!(
                        "{selected} pixels selected; the {changing} a commit changes are hatched, \
                         those already {class} are left as they are (Try edit counts the {changing})"
                    )),
                None => ui.label(format!(
                    "{cells} cells; {selected} pixels of this frame, no class chosen yet: pick the \
                     class these colours are (Commit as… in the Coverage window, or a class above)"
                )),
            };
            ui.horizontal(|ui| {
                if ui
                    .button("Commit")
                    .on_hover_text("right-click in the image")
                    .clicked()
                {
                    commands.push(TableCommand::Commit.into());
                }
                if ui.button("Clear").on_hover_text("Esc").clicked() {
                    commands.push(TableCommand::ClearSelection.into());
                }
            });
            if state.source().is_some_and(|s| s.len() > 1)
                && ui
                    .button("Try on whole stream")
                    .on_hover_text("list the frames this edit would change")
                    .clicked()
            {
                commands.push(TableCommand::TryEditOnStream.into());
            }
        }
        _ => {
            ui.weak("no pending selection");
        }
    }
}

/// Undo and Redo with the history's lengths.
fn undo_redo_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let h = state.history();
    ui.horizontal(|ui| {
        if ui
            .add_enabled(h.undo_len() > 0, egui::Button::new("Undo"))
            .on_hover_text("Ctrl+Z")
            .clicked()
        {
            commands.push(TableCommand::Undo.into());
        }
        if ui
            .add_enabled(h.redo_len() > 0, egui::Button::new("Redo"))
            .on_hover_text("Ctrl+Y")
            .clicked()
        {
            commands.push(TableCommand::Redo.into());
        }
        ui.label(format!("{} / {}", h.undo_len(), h.redo_len()));
    });
}

/// The Try edit window's contents: the frames the pending table edit would change and the
/// frames whose recognition a parameter change alters; before any run, what to do to start one.
/// Clicking a row shows that frame.
pub fn try_edit_panel_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let has_stream = state.source().is_some_and(|s| s.len() > 1);
    ui.strong("Table edit");
    match state.try_edit() {
        Some(t) => {
            let stale = state.try_edit_stale();
            if stale {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    "This result is for an earlier selection (the selection, its sensitivity \
                     or the class changed since).",
                );
            }
            let again = if stale {
                "Try the current selection"
            } else {
                "Try again"
            };
            if ui
                .add_enabled(
                    state.selection().is_some() && has_stream,
                    egui::Button::new(again),
                )
                .on_disabled_hover_text("left-click a pixel to select its colours first")
                .clicked()
            {
                commands.push(TableCommand::TryEditOnStream.into());
            }
            try_edit_ui(ui, t, state.index(), commands);
        }
        None => {
            ui.weak(try_edit_hint(state, has_stream));
            if ui
                .add_enabled(
                    state.selection().is_some() && has_stream,
                    egui::Button::new("Try the selection on the whole stream"),
                )
                .clicked()
            {
                commands.push(TableCommand::TryEditOnStream.into());
            }
        }
    }
    ui.separator();
    ui.strong("Parameter change");
    match &state.params_slot().try_run {
        Some(t) => super::params_panel::try_params_ui(ui, t, state.index(), commands),
        None => {
            ui.weak(if state.params_modified() {
                "Parameters tuned: try them to list the frames whose recognition changes."
            } else {
                "No parameter tuned: change one in the Parameters window, then try it here."
            });
            if ui
                .add_enabled(
                    state.params_modified() && has_stream,
                    egui::Button::new("Try the tuned parameters on the whole stream"),
                )
                .clicked()
            {
                commands.push(ParamsCommand::TryParamsOnStream.into());
            }
        }
    }
}

/// What to do before a table edit can be tried.
fn try_edit_hint(state: &Workspace, has_stream: bool) -> &'static str {
    if !has_stream {
        "No check yet: open a stream of more than one frame."
    } else if state.selection().is_none() {
        "No check yet: left-click a pixel to select its colours, then try the selection."
    } else {
        "No check yet: the pending selection can be tried."
    }
}

fn try_edit_ui(ui: &mut Ui, t: &TryEdit, current: usize, commands: &mut Vec<Command>) {
    ui.horizontal(|ui| {
        super::classify_panel::swatch(ui, t.class.display_rgb());
        ui.label(format!("{} over {} frames", t.class.name(), t.stream.total));
    });
    if !t.done() {
        ui.add(
            egui::ProgressBar::new(t.stream.next as f32 / t.stream.total.max(1) as f32)
                .text(format!("{} / {}", t.stream.next, t.stream.total)),
        );
    }
    let changed: usize = t.stream.rows.iter().map(|r| r.changed_pixels).sum();
    ui.label(format!(
        "{} frames change, {changed} pixels in all{}",
        t.stream.rows.len(),
        if t.stream.errors > 0 {
            format!("; {} frames unreadable", t.stream.errors)
        } else {
            String::new()
        }
    ));
    // Most changed first by default: "where" is the question after "how much".
    let by_frame_id = egui::Id::unique("eotn-try-rows-by-frame");
    let mut by_frame: bool = ui.data(|d| d.get_temp(by_frame_id)).unwrap_or(false);
    ui.horizontal(|ui| {
        ui.label(RichText::new("order:").small().weak());
        ui.selectable_value(&mut by_frame, false, "most changed first");
        ui.selectable_value(&mut by_frame, true, "by frame");
    });
    ui.data_mut(|d| d.insert_temp(by_frame_id, by_frame));
    if let Some(most) = t.stream.rows.iter().max_by_key(|r| r.changed_pixels)
        && ui
            .button(format!(
                "Go to frame {} ({} px change)",
                most.index, most.changed_pixels
            ))
            .clicked()
    {
        commands.push(PlaybackCommand::Seek(most.index).into());
    }
    ui.label(
        RichText::new("frame · pixels changed · blobs before -> after")
            .small()
            .weak(),
    );
    let mut rows: Vec<&crate::workspace::TryEditRow> = t.stream.rows.iter().collect();
    if !by_frame {
        rows.sort_by(|a, b| {
            b.changed_pixels
                .cmp(&a.changed_pixels)
                .then(a.index.cmp(&b.index))
        });
    }
    egui::ScrollArea::vertical()
        .id_salt("try_rows")
        .max_height(300.0)
        .show(ui, |ui| {
            for r in rows {
                let delta = r.blobs_after as i64 - r.blobs_before as i64;
                let text = format!(
                    "frame {:>5}   {:>6} px   blobs {} -> {} ({delta:+})",
                    r.index, r.changed_pixels, r.blobs_before, r.blobs_after
                );
                // The whole row is one button: anywhere on it shows the frame.
                let row =
                    egui::Button::selectable(r.index == current, RichText::new(text).monospace())
                        .min_size(vec2(ui.available_width(), 0.0));
                if ui.add(row).clicked() {
                    commands.push(PlaybackCommand::Seek(r.index).into());
                }
            }
        });
}
