//! The Parameters window: every recognition parameter (each test's accepted range and weight,
//! sizes, scan settings) as an editor; a change re-runs the shown frame at once, so the image and
//! the inspector follow. Per value a Reset back to the file's value; Save as writes a parameters
//! file; Try on stream lists the frames whose recognition the change alters.
//!
//! The editors are built from the parameters' JSON form, so a parameter added to
//! `RecognitionParams` appears here without UI code.

use egui::{RichText, Ui};
use serde_json::Value;

use super::file_dialog::FileAction;
use crate::workspace::{Command, ParamsCommand, PlaybackCommand, TryParams, Workspace};

/// The Parameters window's contents. `dialog` receives a file dialog request (Open…, Save as…).
pub fn params_panel_ui(
    ui: &mut Ui,
    state: &Workspace,
    commands: &mut Vec<Command>,
    dialog: &mut Option<(FileAction, Option<String>)>,
) {
    let slot = state.params_slot();
    let origin = slot.path.as_deref().map_or_else(
        || "built-in defaults (2005 field)".to_owned(),
        crate::frame::display_name,
    );
    let modified = state.params_modified();
    ui.label(format!(
        "Parameters: {origin}{}",
        if modified { " (tuned, not saved)" } else { "" }
    ));
    if let Some(o) = &slot.offer {
        ui.horizontal_wrapped(|ui| {
            ui.colored_label(
                ui.visuals().warn_fg_color,
                format!("This stream is meant for the parameter set {}.", o.name),
            );
            if o.path.is_some() {
                if ui.button(format!("Use {}", o.name)).clicked() {
                    commands.push(ParamsCommand::UseOfferedParams.into());
                }
            } else {
                ui.weak(format!("params/{}.json not found: Open…", o.name));
            }
        });
    }
    ui.horizontal_wrapped(|ui| {
        if ui.button("Open…").clicked() {
            *dialog = Some((FileAction::OpenParams, None));
        }
        if ui.button("Save as…").clicked() {
            let name = slot
                .path
                .as_deref()
                .map_or_else(|| "params.json".to_owned(), crate::frame::display_name);
            *dialog = Some((FileAction::SaveParams, Some(name)));
        }
        if ui
            .add_enabled(modified, egui::Button::new("Reset all"))
            .on_hover_text("every value back to the file's")
            .clicked()
        {
            commands.push(ParamsCommand::ResetParams.into());
        }
        if ui.button("Defaults").clicked() {
            commands.push(ParamsCommand::DefaultParams.into());
        }
        if ui
            .add_enabled(
                modified && state.source().is_some_and(|s| s.len() > 1),
                egui::Button::new("Try on stream"),
            )
            .on_hover_text("list the frames whose recognition the tuned values change")
            .clicked()
        {
            commands.push(ParamsCommand::TryParamsOnStream.into());
        }
    });
    let filter_id = egui::Id::unique("eotn-params-filter");
    let mut filter: String = ui.data(|d| d.get_temp(filter_id)).unwrap_or_default();
    ui.horizontal(|ui| {
        let l = ui.label("Find");
        ui.add(egui::TextEdit::singleline(&mut filter).hint_text("e.g. height or weight"))
            .labelled_by(l.id);
    });
    ui.data_mut(|d| d.insert_temp(filter_id, filter.clone()));
    ui.separator();
    let current = serde_json::to_value(state.recognition_params()).unwrap_or(Value::Null);
    let loaded = serde_json::to_value(slot.loaded).unwrap_or(Value::Null);
    let mut rows = Rows {
        loaded: &loaded,
        filter: filter.trim().to_ascii_lowercase(),
        commands,
    };
    rows.object_ui(ui, "", &current);
}

/// Draws editors, sending a command per change.
struct Rows<'a> {
    loaded: &'a Value,
    filter: String,
    commands: &'a mut Vec<Command>,
}

impl Rows<'_> {
    /// The members of an object: values first, then nested groups as collapsible sections.
    fn object_ui(&mut self, ui: &mut Ui, pointer: &str, v: &Value) {
        let Value::Object(members) = v else {
            return;
        };
        for (key, value) in members {
            if value.is_object() {
                continue;
            }
            let p = format!("{pointer}/{key}");
            if self.matches(&p) {
                self.leaf_ui(ui, &p, key, value);
            }
        }
        for (key, value) in members {
            if !value.is_object() {
                continue;
            }
            let p = format!("{pointer}/{key}");
            if !self.filter.is_empty() && !contains_match(value, &p, &self.filter) {
                continue;
            }
            let changed = self.loaded.pointer(&p) != Some(value);
            let title = if changed {
                RichText::new(format!("{key} *")).strong()
            } else {
                RichText::new(key)
            };
            egui::CollapsingHeader::new(title)
                .id_salt(&p)
                .open((!self.filter.is_empty()).then_some(true))
                .show(ui, |ui| self.object_ui(ui, &p, value));
        }
    }

    fn matches(&self, pointer: &str) -> bool {
        self.filter.is_empty() || pointer.to_ascii_lowercase().contains(&self.filter)
    }

    /// One value: its editor, and Reset when it differs from the file's.
    fn leaf_ui(&mut self, ui: &mut Ui, pointer: &str, key: &str, value: &Value) {
        let loaded = self.loaded.pointer(pointer);
        let changed = loaded != Some(value);
        ui.horizontal(|ui| {
            let name = if changed {
                RichText::new(key).strong()
            } else {
                RichText::new(key)
            };
            let label = ui.label(name);
            let label_id = label.id;
            if let Some(new) = value_editor_ui(ui, label_id, value) {
                self.commands.push(
                    ParamsCommand::SetParamValue {
                        pointer: pointer.to_owned(),
                        value: new,
                    }
                    .into(),
                );
            }
            let reset = ui
                .add_enabled(changed, egui::Button::new("Reset").small())
                .on_hover_text(format!(
                    "back to {}",
                    loaded.map_or_else(|| "the file's".to_owned(), Value::to_string)
                ));
            if reset.clicked() {
                self.commands
                    .push(ParamsCommand::ResetParamValue(pointer.to_owned()).into());
            }
        });
    }
}

/// True when a member of `v` (an object) has a pointer containing `filter`.
fn contains_match(v: &Value, pointer: &str, filter: &str) -> bool {
    match v {
        Value::Object(m) => m
            .iter()
            .any(|(k, x)| contains_match(x, &format!("{pointer}/{k}"), filter)),
        _ => pointer.to_ascii_lowercase().contains(filter),
    }
}

/// An editor for a number, a flag, a `[low, high]` range or a list; the new value when changed.
fn value_editor_ui(ui: &mut Ui, label: egui::Id, value: &Value) -> Option<Value> {
    match value {
        Value::Number(_) => number_ui(ui, label, value),
        Value::Bool(b) => {
            let mut on = *b;
            ui.checkbox(&mut on, "")
                .labelled_by(label)
                .changed()
                .then_some(Value::Bool(on))
        }
        Value::Array(items) => {
            let mut out = None;
            for (i, item) in items.iter().enumerate() {
                if items.len() == 2 && item.is_number() {
                    ui.weak(if i == 0 { "low" } else { "high" });
                }
                if let Some(new) = value_editor_ui(ui, label, item) {
                    let mut all = items.clone();
                    all[i] = new;
                    out = Some(Value::Array(all));
                }
            }
            out
        }
        Value::String(s) => {
            ui.monospace(s);
            None
        }
        Value::Null => {
            ui.weak("none");
            None
        }
        Value::Object(_) => None,
    }
}

fn number_ui(ui: &mut Ui, label: egui::Id, value: &Value) -> Option<Value> {
    if let Some(n) = value.as_u64() {
        let mut x = n;
        let r = ui.add(egui::DragValue::new(&mut x).speed(0.2));
        return r.labelled_by(label).changed().then(|| Value::from(x));
    }
    if let Some(n) = value.as_i64() {
        let mut x = n;
        let r = ui.add(egui::DragValue::new(&mut x).speed(0.2));
        return r.labelled_by(label).changed().then(|| Value::from(x));
    }
    let mut x = value.as_f64()?;
    let speed = (x.abs() * 0.005).max(0.001);
    let r = ui.add(egui::DragValue::new(&mut x).speed(speed).max_decimals(5));
    let changed = r.labelled_by(label).changed() && x.is_finite();
    changed.then(|| serde_json::Number::from_f64(x).map(Value::Number))?
}

/// The results of a parameter try: the changed values, then the frames whose recognition
/// changes; clicking a row shows that frame.
pub fn try_params_ui(ui: &mut Ui, t: &TryParams, current: usize, commands: &mut Vec<Command>) {
    for c in &t.changes {
        ui.monospace(c);
    }
    if !t.done() {
        ui.add(
            egui::ProgressBar::new(t.stream.next as f32 / t.stream.total.max(1) as f32)
                .text(format!("{} / {}", t.stream.next, t.stream.total)),
        );
    }
    ui.label(format!(
        "{} of {} frames recognise differently{}",
        t.stream.rows.len(),
        t.stream.next,
        if t.stream.errors > 0 {
            format!("; {} frames unreadable", t.stream.errors)
        } else {
            String::new()
        }
    ));
    egui::ScrollArea::vertical()
        .id_salt("try_params_rows")
        .max_height(300.0)
        .show(ui, |ui| {
            for r in &t.stream.rows {
                let text = format!("frame {:>5}   {}  ->  {}", r.index, r.before, r.after);
                let row =
                    egui::Button::selectable(r.index == current, RichText::new(text).monospace())
                        .min_size(egui::vec2(ui.available_width(), 0.0));
                if ui.add(row).clicked() {
                    commands.push(PlaybackCommand::Seek(r.index).into());
                }
            }
        });
}
