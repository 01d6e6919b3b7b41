//! Cameras side by side (`Command::ShowSideBySide`): the image area split into one column per
//! camera, each with a header (topic, its table, unsaved mark, focus) and its frame classified
//! with its own table, its recognition drawn. The focused camera's column is the full enlarged
//! view (zoom, pan, selection preview); a click on another camera's column focuses it and
//! samples the pixel clicked, so the edit goes to that camera's table.

use std::collections::HashMap;

use egui::{Align2, Color32, ColorImage, Sense, TextureHandle, TextureOptions, Ui, vec2};

use super::overlays::{FrameTextures, ImageTransform, corner_text, paint_primitives};
use super::views::{self, MainViewOutput};
use crate::workspace::{CameraPane, Command, PrimitiveFilter, TableCommand, Workspace};

/// Height of a column's header, points.
const HEADER: f32 = 18.0;

/// One beside camera's textures and the pane generation they were built from.
struct PaneTextures {
    raw: TextureHandle,
    classified: TextureHandle,
    generation: u64,
}

/// The textures of the cameras shown beside the focused one, by image topic.
#[derive(Default)]
pub struct BesideTextures {
    panes: HashMap<String, PaneTextures>,
}

impl BesideTextures {
    /// Uploads the panes whose frame or results changed; forgets cameras no longer shown.
    pub fn update(&mut self, ctx: &egui::Context, state: &Workspace, palette: &[Color32; 256]) {
        let panes = state.camera_panes();
        self.panes
            .retain(|topic, _| panes.iter().any(|p| !p.focused && p.topic == topic));
        let opts = TextureOptions::NEAREST;
        for p in panes.iter().filter(|p| !p.focused) {
            if self
                .panes
                .get(p.topic)
                .is_some_and(|t| t.generation == p.generation)
            {
                continue;
            }
            let Some((raw, classified)) = pane_images(p, palette) else {
                continue;
            };
            match self.panes.get_mut(p.topic) {
                Some(t) => {
                    t.raw.set(raw, opts);
                    t.classified.set(classified, opts);
                    t.generation = p.generation;
                }
                None => {
                    let name = |kind: &str| format!("{kind} {}", p.topic);
                    self.panes.insert(
                        p.topic.to_owned(),
                        PaneTextures {
                            raw: ctx.load_texture(name("raw"), raw, opts),
                            classified: ctx.load_texture(name("classified"), classified, opts),
                            generation: p.generation,
                        },
                    );
                }
            }
        }
    }
}

/// A pane's colour and class-colour images; `None` without a frame or with results of another
/// size (never drawn stretched).
fn pane_images(p: &CameraPane<'_>, palette: &[Color32; 256]) -> Option<(ColorImage, ColorImage)> {
    let f = p.frame?;
    let size = [f.width(), f.height()];
    let n = size[0] * size[1];
    if p.rgb.len() != n * 3 || p.codes.len() != n {
        return None;
    }
    let raw = ColorImage::from_rgb(size, p.rgb);
    let classified = ColorImage::new(
        size,
        p.codes.iter().map(|&c| palette[usize::from(c)]).collect(),
    );
    Some((raw, classified))
}

/// One camera's pane as it was drawn.
#[derive(Debug, Clone)]
pub struct DrawnPane {
    /// The camera's image topic.
    pub topic: String,
    /// Where its image was drawn (tests click pixels through it).
    pub transform: ImageTransform,
    /// How many of its recognition's primitives were drawn over it.
    pub primitives: usize,
}

/// What the side-by-side view reports: the focused view's output and each camera's pane as
/// drawn.
#[derive(Debug, Default, Clone)]
pub struct SideBySideOutput {
    /// The focused camera's enlarged view.
    pub focused: MainViewOutput,
    /// The panes, left to right.
    pub panes: Vec<DrawnPane>,
}

/// The cameras side by side, filling `ui`.
pub fn side_by_side_ui(
    ui: &mut Ui,
    state: &Workspace,
    tex: Option<&FrameTextures>,
    beside: &BesideTextures,
    commands: &mut Vec<Command>,
) -> SideBySideOutput {
    let panes = state.camera_panes();
    let area = ui.available_rect_before_wrap();
    let n = panes.len().max(1) as f32;
    let width = area.width() / n;
    let mut out = SideBySideOutput::default();
    for (i, pane) in panes.iter().enumerate() {
        let column = egui::Rect::from_min_size(
            area.min + vec2(width * i as f32, 0.0),
            vec2(width, area.height()),
        )
        .shrink2(vec2(1.0, 0.0));
        let (header, body) = column.split_top_bottom_at_y(column.top() + HEADER);
        header_ui(ui, header, pane);
        if pane.focused {
            let view = ui.scope_builder(egui::UiBuilder::new().max_rect(body), |ui| {
                views::main_view_ui(ui, state, tex, commands)
            });
            out.focused = view.inner;
            if let Some(xf) = out.focused.transform {
                out.panes.push(DrawnPane {
                    topic: pane.topic.to_owned(),
                    transform: xf,
                    primitives: out.focused.primitives_drawn,
                });
            }
        } else if let Some((xf, primitives)) =
            beside_pane_ui(ui, body, state, pane, beside, commands)
        {
            out.panes.push(DrawnPane {
                topic: pane.topic.to_owned(),
                transform: xf,
                primitives,
            });
        }
    }
    ui.advance_cursor_after_rect(area);
    out
}

/// A column's header: the camera, its table (`*` unsaved), its parameters when they came from
/// a file, and which one is focused.
fn header_ui(ui: &Ui, rect: egui::Rect, pane: &CameraPane<'_>) {
    let table = pane
        .table_path
        .map_or_else(|| "untitled table".to_owned(), crate::frame::display_name);
    let params = pane
        .params_path
        .map(|p| format!(" · {}", crate::frame::display_name(p)))
        .unwrap_or_default();
    let mark = if pane.dirty { " *" } else { "" };
    let focus = if pane.focused {
        " — focused"
    } else {
        " — click to focus"
    };
    let colour = if pane.focused {
        ui.visuals().strong_text_color()
    } else {
        ui.visuals().weak_text_color()
    };
    ui.painter().text(
        rect.left_center() + vec2(4.0, 0.0),
        Align2::LEFT_CENTER,
        format!("{} · {table}{mark}{params}{focus}", pane.topic),
        egui::FontId::proportional(12.0),
        colour,
    );
}

/// A camera not focused: its frame, its classes over it, its recognition, and what it says when
/// it has ended; a click focuses it and samples the pixel. Returns where its image was drawn
/// and how many of its primitives.
fn beside_pane_ui(
    ui: &mut Ui,
    rect: egui::Rect,
    state: &Workspace,
    pane: &CameraPane<'_>,
    beside: &BesideTextures,
    commands: &mut Vec<Command>,
) -> Option<(ImageTransform, usize)> {
    let response = ui.interact(
        rect,
        egui::Id::unique(("camera pane", pane.topic)),
        Sense::click(),
    );
    // What the pane says (ended, not begun) is part of its accessible name.
    let name = match pane.note {
        Some(note) => format!("camera {}: {note}", pane.topic),
        None => format!("camera {}", pane.topic),
    };
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, &name));
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, Color32::from_gray(24));
    let f = pane.frame?;
    let xf = ImageTransform::fitted(rect, [f.width() as f32, f.height() as f32]);
    let img = xf.image_rect();
    let uv = egui::Rect::from_min_max(egui::Pos2::ZERO, egui::pos2(1.0, 1.0));
    let o = state.settings.overlays;
    if let Some(t) = beside.panes.get(pane.topic) {
        // An ended camera's last frame is dimmed under its note.
        let tint = if pane.note.is_some() {
            Color32::from_gray(110)
        } else {
            Color32::WHITE
        };
        painter.image(t.raw.id(), img, uv, tint);
        if o.classified {
            let a = (o.opacity.clamp(0.0, 1.0) * 255.0) as u8;
            painter.image(t.classified.id(), img, uv, Color32::from_white_alpha(a));
        }
    }
    let drawn = paint_primitives(
        &painter,
        &xf,
        pane.primitives,
        &PrimitiveFilter::all(o),
        None,
    );
    if let Some(note) = pane.note {
        corner_text(&painter, rect, Align2::CENTER_CENTER, note.to_owned());
    }
    if response.clicked()
        && let Some(pos) = response.interact_pointer_pos()
        && let Some((x, y)) = xf.pixel_at(pos)
    {
        commands.push(Command::FocusCamera(pane.camera.clone()));
        commands.push(TableCommand::Sample { x, y }.into());
    }
    response.on_hover_text(format!(
        "camera {}: click to focus it and classify with its table",
        pane.topic
    ));
    Some((xf, drawn))
}
