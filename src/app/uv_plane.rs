//! The table itself, not only its effect: the U–V plane of the table at one Y, each cell in its
//! class's colour, with the current frame's pixels of that Y drawn over it as a histogram.
//! The pending selection's cells are outlined; clicking a cell selects around it, which marks
//! the matching pixels in the image (selection works both ways).

use egui::{
    Color32, ColorImage, Rect, Sense, Stroke, StrokeKind, TextureHandle, TextureOptions, pos2, vec2,
};

use crate::lut::edit::Selection;
use crate::workspace::{Command, TableCommand, ViewCommand, Workspace};

/// The U–V plane texture, rebuilt when the table, frame or Y changes.
#[derive(Default)]
pub struct UvPlane {
    texture: Option<TextureHandle>,
    key: (u64, u64, u8),
}

impl UvPlane {
    /// The U–V plane's contents.
    pub fn ui(&mut self, ui: &mut egui::Ui, state: &Workspace, commands: &mut Vec<Command>) {
        let lut = state.lut();
        let n = lut.side();
        let shift = lut.shift();
        let mut y = state.settings.uv_plane_y;
        if ui
            .add(egui::Slider::new(&mut y, 0..=255).text("Y"))
            .on_hover_text("the luma of the layer shown")
            .changed()
        {
            commands.push(ViewCommand::SetUvPlaneY(y).into());
        }
        let layer = usize::from(y >> shift);
        let key = (
            state.table_generation(),
            state.frame_generation(),
            y >> shift,
        );
        if self.texture.is_none() || self.key != key {
            let image = self.build(state, layer);
            match &mut self.texture {
                Some(t) => t.set(image, TextureOptions::NEAREST),
                None => {
                    self.texture = Some(ui.ctx().load_texture(
                        "uv_plane",
                        image,
                        TextureOptions::NEAREST,
                    ));
                }
            }
            self.key = key;
        }
        let side = (ui.available_width() - AXIS_MARGIN).clamp(128.0, 512.0);
        let (outer, response) =
            ui.allocate_exact_size(vec2(side + AXIS_MARGIN, side + AXIS_MARGIN), Sense::click());
        let rect =
            Rect::from_min_size(outer.min + vec2(AXIS_MARGIN, AXIS_MARGIN), vec2(side, side));
        axis_ticks(ui, rect);
        response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "U–V plane"));
        if let Some(t) = &self.texture {
            ui.painter().image(
                t.id(),
                rect,
                Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0)),
                Color32::WHITE,
            );
        }
        super::coverage_panel::uv_plane_marks(ui.painter(), rect, state);
        let cell = side / n as f32;
        // Selected cells on this layer: outline their bounding box.
        if let Some(Selection::Box(b)) = state.resolved_selection()
            && (b.min[0]..=b.max[0]).contains(&layer)
        {
            let r = Rect::from_min_max(
                rect.min + vec2(b.min[2] as f32 * cell, b.min[1] as f32 * cell),
                rect.min + vec2((b.max[2] + 1) as f32 * cell, (b.max[1] + 1) as f32 * cell),
            );
            ui.painter().rect_stroke(
                r,
                0.0,
                Stroke::new(2.0, Color32::from_rgb(255, 0, 255)),
                StrokeKind::Outside,
            );
        }
        let to_cell = |p: egui::Pos2| {
            if !rect.contains(p) {
                return None;
            }
            let u = ((p.y - rect.min.y) / cell) as usize;
            let v = ((p.x - rect.min.x) / cell) as usize;
            (u < n && v < n).then_some((u, v))
        };
        if let Some((u, v)) = response.hover_pos().and_then(to_cell) {
            let code = lut.get(lut.index_of_cell([layer, u, v])).unwrap_or(0);
            let name = crate::lut::ColourClass::from_code(code).map_or("?", |c| c.name());
            ui.monospace(format!("U {} V {}: {name}", u << shift, v << shift));
        } else {
            ui.weak("U down, V across; bright dots: this frame's pixels");
        }
        if response.clicked()
            && let Some((u, v)) = response.interact_pointer_pos().and_then(to_cell)
        {
            commands.push(TableCommand::SampleCell([layer, u, v]).into());
        }
    }

    /// Cells in class colours (unclassified dark), brightened where the frame has pixels.
    fn build(&self, state: &Workspace, layer: usize) -> ColorImage {
        let lut = state.lut();
        let n = lut.side();
        let shift = lut.shift();
        let mut hist = vec![0u32; n * n];
        if let Some(f) = state.frame() {
            f.for_each_pixel(|_, _, p| {
                if usize::from(p.y >> shift) == layer {
                    hist[usize::from(p.u >> shift) * n + usize::from(p.v >> shift)] += 1;
                }
            });
        }
        let max = hist.iter().copied().max().unwrap_or(0).max(1) as f32;
        let mut pixels = Vec::with_capacity(n * n);
        for u in 0..n {
            for v in 0..n {
                let code = lut.get(lut.index_of_cell([layer, u, v])).unwrap_or(0);
                let [r, g, b] = if code == 0 {
                    [40, 40, 40]
                } else {
                    crate::lut::code_display_rgb(code)
                };
                let h = hist[u * n + v];
                let c = if h > 0 {
                    // Log scale so a few pixels still show next to thousands.
                    let t = 0.35 + 0.65 * ((h as f32).ln_1p() / max.ln_1p());
                    let m = |x: u8| (f32::from(x) * (1.0 - t) + 255.0 * t) as u8;
                    Color32::from_rgb(m(r), m(g), m(b))
                } else {
                    Color32::from_rgb(r, g, b)
                };
                pixels.push(c);
            }
        }
        ColorImage::new([n, n], pixels)
    }
}

/// Room left of and above the plane for its axes, screen points.
const AXIS_MARGIN: f32 = 26.0;

/// Ticks and values (0, 64, 128, 192, 255) along the V axis (across, above the plane) and the
/// U axis (down, left of it).
fn axis_ticks(ui: &egui::Ui, plane: Rect) {
    let painter = ui.painter();
    let colour = ui.visuals().weak_text_color();
    let font = egui::FontId::monospace(9.0);
    let stroke = Stroke::new(1.0, colour);
    for value in [0u16, 64, 128, 192, 255] {
        let t = (f32::from(value) + 0.5) / 256.0;
        let x = plane.min.x + t * plane.width();
        let y = plane.min.y + t * plane.height();
        painter.line_segment([pos2(x, plane.min.y - 4.0), pos2(x, plane.min.y)], stroke);
        painter.text(
            pos2(x, plane.min.y - 5.0),
            egui::Align2::CENTER_BOTTOM,
            value.to_string(),
            font.clone(),
            colour,
        );
        painter.line_segment([pos2(plane.min.x - 4.0, y), pos2(plane.min.x, y)], stroke);
        painter.text(
            pos2(plane.min.x - 5.0, y),
            egui::Align2::RIGHT_CENTER,
            value.to_string(),
            font.clone(),
            colour,
        );
    }
    let corner = plane.min - vec2(AXIS_MARGIN, AXIS_MARGIN);
    painter.text(
        corner,
        egui::Align2::LEFT_TOP,
        "U / V",
        egui::FontId::proportional(9.0),
        colour,
    );
}
