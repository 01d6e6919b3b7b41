//! "What is still unclassified?": the coverage hints — the colours of the stream (or a range of
//! it) that the table leaves unclassified, most pixels first, as a list and as numbered marks
//! on the U–V plane. Clicking a hint selects its cells (the image previews its pixels; Commit
//! classifies them) and shows its Y layer in the U–V plane.

use egui::{Color32, Painter, Rect, Stroke, Ui, pos2, vec2};

use crate::frame::yuv_to_rgb;
use crate::lut::Region;
use crate::workspace::{Command, HintsCommand, ViewCommand, Workspace};

/// The range, the scan's progress and the hints.
pub fn coverage_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let Some(src) = state.source() else {
        ui.label("Open a stream or frames first.");
        return;
    };
    let last_frame = src.len().saturating_sub(1);
    let id = egui::Id::unique("coverage_range");
    let mut range: [usize; 2] = ui.data(|d| d.get_temp(id)).unwrap_or([0, last_frame]);
    ui.horizontal(|ui| {
        ui.label("frames");
        ui.add(egui::DragValue::new(&mut range[0]).range(0..=last_frame))
            .on_hover_text("first frame counted");
        ui.label("to");
        ui.add(egui::DragValue::new(&mut range[1]).range(0..=last_frame))
            .on_hover_text("last frame counted");
        if ui
            .button("Find unclassified")
            .on_hover_text("count the colours the table leaves unclassified")
            .clicked()
        {
            commands.push(
                HintsCommand::FindUnclassified {
                    first: range[0].min(range[1]),
                    last: range[0].max(range[1]),
                }
                .into(),
            );
        }
    });
    ui.data_mut(|d| d.insert_temp(id, range));
    let Some(scan) = state.coverage() else {
        ui.weak("Not counted yet.");
        return;
    };
    let frames = scan.end - scan.first;
    if !scan.done() {
        ui.add(
            egui::ProgressBar::new(scan.counted() as f32 / frames.max(1) as f32)
                .text(format!("{} / {frames} frames", scan.counted())),
        );
    }
    let share = 100.0 * scan.unclassified_pixels() as f64 / scan.pixels.max(1) as f64;
    ui.label(format!(
        "frames {}–{}: {} of {} pixels unclassified ({share:.1}%){}",
        scan.first,
        scan.end.saturating_sub(1),
        scan.unclassified_pixels(),
        scan.pixels,
        if scan.errors > 0 {
            format!("; {} frames unreadable", scan.errors)
        } else {
            String::new()
        }
    ));
    hints_list_ui(ui, state, commands);
}

fn hints_list_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let Some(scan) = state.coverage() else {
        return;
    };
    let selected: Option<&[usize]> = match state.selection().map(|s| &s.region) {
        Some(Region::Cells { indices }) => Some(indices),
        _ => None,
    };
    egui::Grid::new("coverage_hints")
        .striped(true)
        .show(ui, |ui| {
            ui.strong("#");
            ui.strong("colour");
            ui.strong("pixels");
            ui.strong("cells");
            ui.end_row();
            for (i, h) in scan.hints().iter().enumerate() {
                let is_selected = selected == Some(h.cells.as_slice());
                let label = format!("hint {}", i + 1);
                if ui
                    .selectable_label(is_selected, &label)
                    .on_hover_text(
                        "select these cells: the image shows their pixels; Commit classifies them",
                    )
                    .clicked()
                {
                    commands.push(HintsCommand::SelectCells(h.cells.clone()).into());
                    commands.push(ViewCommand::SetUvPlaneY(h.mean.y).into());
                }
                ui.horizontal(|ui| {
                    super::classify_panel::swatch(ui, yuv_to_rgb(h.mean));
                    ui.monospace(format!("{:>3} {:>3} {:>3}", h.mean.y, h.mean.u, h.mean.v));
                });
                ui.label(format!("{}", h.pixels));
                ui.label(format!("{}", h.cells.len()));
                ui.end_row();
            }
        });
    if scan.hints().is_empty() && scan.done() {
        ui.label("Every colour of these frames is classified.");
    }
}

/// Numbered marks of the hints on the U–V plane (`rect`, `n` cells a side, U down, V across):
/// filled on the Y layer shown, hollow on others.
pub fn uv_plane_marks(painter: &Painter, rect: Rect, state: &Workspace) {
    let Some(scan) = state.coverage() else {
        return;
    };
    let lut = state.lut();
    let (n, shift) = (lut.side() as f32, lut.shift());
    let cell = rect.width() / n;
    let layer = state.settings.uv_plane_y >> shift;
    for (i, h) in scan.hints().iter().enumerate() {
        let at = rect.min
            + vec2(
                (f32::from(h.mean.v >> shift) + 0.5) * cell,
                (f32::from(h.mean.u >> shift) + 0.5) * cell,
            );
        let on_layer = h.mean.y >> shift == layer;
        // White on a black ring: visible over every class colour and the dark empty cells.
        let colour = Color32::WHITE;
        painter.circle_stroke(at, 6.0, Stroke::new(3.0, Color32::BLACK));
        if on_layer {
            painter.circle_filled(at, 5.0, colour);
        } else {
            painter.circle_stroke(at, 5.0, Stroke::new(1.5, colour));
        }
        painter.text(
            pos2(at.x + 6.0, at.y - 6.0),
            egui::Align2::LEFT_BOTTOM,
            format!("{}", i + 1),
            egui::FontId::monospace(10.0),
            colour,
        );
    }
}
