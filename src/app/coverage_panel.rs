//! "What is still unclassified?": the coverage hints — the colours of the stream (or a range of
//! it) that the table leaves unclassified, most pixels first, as a list and as numbered marks
//! on the U–V plane. Clicking a hint selects its cells (the image previews its pixels) and
//! shows its Y layer in the U–V plane; its class is chosen here before it is committed. Each
//! hint names the frames with most of its pixels (one click goes there with them previewed)
//! and splits into its cells; after a commit the rows keep their places.

use egui::{Color32, Painter, Rect, Stroke, Ui, pos2, vec2};

use crate::frame::yuv_to_rgb;
use crate::lut::{ColourClass, Region};
use crate::workspace::coverage::CoverageHint;
use crate::workspace::{
    Command, HintsCommand, PlaybackCommand, TableCommand, ViewCommand, Workspace,
};

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
    let split_id = egui::Id::unique("eotn-coverage-split");
    let mut split: Option<usize> = ui.data(|d| d.get_temp(split_id)).flatten();
    ui.horizontal_wrapped(|ui| {
        ui.weak("Rows keep their place after a commit;");
        if ui
            .small_button("Re-rank")
            .on_hover_text("order the hints afresh by their unclassified pixels")
            .clicked()
        {
            commands.push(HintsCommand::RankHints.into());
        }
    });
    egui::Grid::new("coverage_hints")
        .striped(true)
        .show(ui, |ui| {
            for h in ["#", "colour", "pixels", "here", "cells", "most in frame"] {
                ui.strong(h);
            }
            ui.end_row();
            for (i, h) in scan.hints().iter().enumerate() {
                hint_row_ui(ui, state, i, h, selected, &mut split, commands);
                ui.end_row();
            }
        });
    ui.data_mut(|d| d.insert_temp(split_id, split));
    if let Some(h) = split.and_then(|i| scan.hints().get(i).map(|h| (i, h))) {
        hint_cells_ui(ui, state, h.0, h.1, selected, commands);
    }
    if scan.hints().is_empty() && scan.done() {
        ui.label("Every colour of these frames is classified.");
    }
    if selected.is_some() && state.selection().is_some() {
        commit_as_ui(ui, state, commands);
    }
}

/// One hint's row: select it, its colour, pixels (all, shown frame), its cells (split into
/// rows), and the frame with most of its pixels (go there, its pixels previewed).
fn hint_row_ui(
    ui: &mut Ui,
    state: &Workspace,
    i: usize,
    h: &CoverageHint,
    selected: Option<&[usize]>,
    split: &mut Option<usize>,
    commands: &mut Vec<Command>,
) {
    let label = format!("hint {}", i + 1);
    if let Some(class) = h.done {
        ui.add_enabled(false, egui::Button::selectable(false, &label));
        ui.horizontal(|ui| {
            super::classify_panel::swatch(ui, class.display_rgb());
            ui.weak(format!("now {}", class.name()));
        });
        ui.weak("0");
        ui.weak("–");
        ui.weak(format!("{}", h.cells.len()));
        ui.weak("–");
        return;
    }
    let is_selected = selected == Some(h.cells.as_slice());
    if ui
        .selectable_label(is_selected, &label)
        .on_hover_text(
            "select these cells: the image previews their pixels; choose their class to commit",
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
    ui.label(format!("{}", state.pixels_here(&h.cells)))
        .on_hover_text("pixels of the shown frame in this hint's cells");
    let open = *split == Some(i);
    if ui
        .selectable_label(open, format!("{} cells", h.cells.len()))
        .on_hover_text("split the hint into its cells, each with its own frames")
        .clicked()
    {
        *split = if open { None } else { Some(i) };
    }
    frames_ui(
        ui,
        &h.frames,
        &h.cells,
        &format!("hint {}", i + 1),
        commands,
    );
}

/// The frame with most of `cells`' pixels as a button (go there and select them), the others
/// in its hover menu.
fn frames_ui(
    ui: &mut Ui,
    frames: &[(usize, u64)],
    cells: &[usize],
    what: &str,
    commands: &mut Vec<Command>,
) {
    let Some(&(best, n)) = frames.first() else {
        ui.weak("–");
        return;
    };
    let go = |commands: &mut Vec<Command>, frame: usize| {
        commands.push(PlaybackCommand::Seek(frame).into());
        commands.push(HintsCommand::SelectCells(cells.to_vec()).into());
    };
    ui.horizontal(|ui| {
        if ui
            .button(format!("frame {best}"))
            .on_hover_text(format!(
                "{n} px of {what} there: show that frame with them previewed"
            ))
            .clicked()
        {
            go(commands, best);
        }
        if frames.len() > 1 {
            ui.menu_button("more", |ui| {
                for &(f, n) in frames {
                    if ui.button(format!("frame {f}: {n} px")).clicked() {
                        go(commands, f);
                        ui.close();
                    }
                }
            });
        }
    });
}

/// The cells of hint `i`, one row each: its colour, pixels, frames; clicking one selects that
/// cell alone (a hint whose cells are wall in one camera and carpet in another is split here).
fn hint_cells_ui(
    ui: &mut Ui,
    state: &Workspace,
    i: usize,
    h: &CoverageHint,
    selected: Option<&[usize]>,
    commands: &mut Vec<Command>,
) {
    let Some(scan) = state.coverage() else {
        return;
    };
    let lut = state.lut();
    ui.separator();
    ui.strong(format!("Cells of hint {}", i + 1));
    egui::ScrollArea::vertical()
        .id_salt("coverage_cells")
        .max_height(240.0)
        .show(ui, |ui| {
            egui::Grid::new("coverage_cells_grid")
                .striped(true)
                .show(ui, |ui| {
                    for &cell in &h.cells {
                        let [y, u, v] = lut.cell_of_index(cell).map(|c| cell_value(c, lut.shift()));
                        let one = [cell];
                        let label = format!("cell {y} {u} {v}");
                        if ui
                            .selectable_label(selected == Some(&one[..]), &label)
                            .on_hover_text("select this cell alone")
                            .clicked()
                        {
                            commands.push(HintsCommand::SelectCells(one.to_vec()).into());
                            commands.push(ViewCommand::SetUvPlaneY(y).into());
                        }
                        super::classify_panel::swatch(
                            ui,
                            yuv_to_rgb(crate::frame::Yuv::new(y, u, v)),
                        );
                        ui.label(format!("{} px", scan.cell_pixels(cell)));
                        frames_ui(ui, scan.cell_frames(cell), &one, &label, commands);
                        ui.end_row();
                    }
                });
        });
}

/// The 8-bit value at the centre of table cell `c` along one channel.
fn cell_value(c: usize, shift: u8) -> u8 {
    u8::try_from((c << shift) + ((1usize << shift) >> 1)).unwrap_or(u8::MAX)
}

/// The selected hint's class, chosen here (never the Classify panel's class by accident),
/// and its commit.
fn commit_as_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let chosen = state.selection_class();
    ui.separator();
    ui.horizontal_wrapped(|ui| {
        let text = chosen.map_or("(choose a class)", ColourClass::name);
        egui::ComboBox::from_label("class of these colours")
            .selected_text(text)
            .show_ui(ui, |ui| {
                for class in ColourClass::ALL {
                    if ui
                        .selectable_label(chosen == Some(class), class.name())
                        .clicked()
                    {
                        commands.push(TableCommand::SetClass(class).into());
                    }
                }
            });
        let commit = match chosen {
            Some(c) => format!("Commit as {}", c.name()),
            None => "Commit".to_owned(),
        };
        if ui
            .add_enabled(chosen.is_some(), egui::Button::new(commit))
            .on_disabled_hover_text("choose the class these colours are first")
            .clicked()
        {
            commands.push(TableCommand::Commit.into());
        }
    });
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
