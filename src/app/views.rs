//! The image views: one enlarged view with zoom, pan, hover readout and the clicks of hand
//! classification, and a row of thumbnails that swap with it. Pixels stay square and sharp
//! (nearest filtering, one zoom for both axes).

use egui::{Align2, Color32, PointerButton, Sense, Ui, vec2};

use super::overlays::{FrameTextures, ImageTransform, corner_text, paint_view};
use crate::geometry::ImagePoint;
use crate::workspace::{
    Command, OverheadCommand, PendingSelection, PixelInfo, TableCommand, ViewCommand, ViewKind,
    Workspace,
};

/// Screen points the mouse wheel must move for the zoom to double.
const WHEEL_POINTS_PER_DOUBLING: f32 = 240.0;

/// What the enlarged view reports besides commands.
#[derive(Debug, Default, Clone, Copy)]
pub struct MainViewOutput {
    /// The pixel under the pointer.
    pub hovered: Option<PixelInfo>,
    /// Where the view was drawn and how (tests click pixels through it).
    pub transform: Option<ImageTransform>,
    /// How many of recognition's primitives it drew.
    pub primitives_drawn: usize,
}

/// The enlarged view, filling `ui`; pushes what the user did as commands.
pub fn main_view_ui(
    ui: &mut Ui,
    state: &Workspace,
    tex: Option<&FrameTextures>,
    commands: &mut Vec<Command>,
) -> MainViewOutput {
    let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
    let kind = state.settings.main_view;
    response.widget_info(|| {
        egui::WidgetInfo::labeled(egui::Role::Image, true, format!("{} view", kind.name()))
    });
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, Color32::from_gray(24));
    let (Some(tex), true) = (tex, state.frame().is_some()) else {
        corner_text(
            &painter,
            rect,
            Align2::CENTER_CENTER,
            "File > Open… a stream (.mcap), frames (.uyvy, .png) or a table (.lut)".to_owned(),
        );
        return MainViewOutput::default();
    };
    let xf = ImageTransform::for_state(rect, state);
    let primitives_drawn = paint_view(&painter, &xf, kind, state, tex, true);

    let mut out = MainViewOutput {
        hovered: None,
        transform: Some(xf),
        primitives_drawn,
    };
    if let Some(pos) = response.hover_pos() {
        out.hovered = xf
            .pixel_at(pos)
            .and_then(|_| camera_pixel(state, xf.to_image(pos)))
            .and_then(|(x, y)| state.pixel_info(x, y));
        let (scroll, zoom_delta) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        let factor = if (zoom_delta - 1.0).abs() > f32::EPSILON {
            zoom_delta
        } else {
            (scroll / WHEEL_POINTS_PER_DOUBLING).exp2()
        };
        if (factor - 1.0).abs() > 1e-4 {
            let about = xf.to_image(pos);
            commands.push(
                ViewCommand::ZoomAbout {
                    factor,
                    about: [about.x, about.y],
                    fit: ImageTransform::fit_zoom(rect, xf.size),
                }
                .into(),
            );
        }
    }
    if response.dragged_by(PointerButton::Middle) {
        let d = response.drag_delta() / xf.zoom;
        if d != egui::Vec2::ZERO {
            commands.push(ViewCommand::Pan([d.x, d.y]).into());
        }
    }
    // A click samples at once; when it turns out to be the first of a double-click (fit), the
    // selection from before it is put back, so fitting never changes the selection.
    if response.clicked_by(PointerButton::Primary)
        || response.clicked_by(PointerButton::Secondary)
        || response.drag_started()
    {
        take_keyboard_focus(ui);
    }
    let before_click = egui::Id::unique("eotn-selection-before-click");
    if response.double_clicked_by(PointerButton::Primary) {
        commands.push(ViewCommand::ResetView.into());
        if let Some(before) =
            ui.data_mut(|d| d.remove_temp::<Option<PendingSelection>>(before_click))
        {
            commands.push(TableCommand::RestoreSelection(before).into());
        }
    } else if response.clicked_by(PointerButton::Primary)
        && let Some(pos) = response.interact_pointer_pos()
        && xf.pixel_at(pos).is_some()
    {
        let before = state.selection().cloned();
        ui.data_mut(|d| d.insert_temp(before_click, before));
        commands.push(click_command(state, xf.to_image(pos)));
    }
    if response.clicked_by(PointerButton::Secondary) && state.selection().is_some() {
        commands.push(TableCommand::Commit.into());
    }
    let zoom_text = match state.settings.transform.zoom {
        None => format!("fit {:.0}%", xf.zoom * 100.0),
        Some(z) => format!("{:.0}%", z * 100.0),
    };
    corner_text(&painter, rect, Align2::RIGHT_TOP, zoom_text);
    // What a left click does now: picking a calibration landmark or sampling a colour.
    corner_text(&painter, rect, Align2::LEFT_TOP, state.left_click_mode());
    out
}

/// A click in the image takes the keyboard: a text field loses its focus (so Y/U/V and the
/// arrows reach the shortcuts instead of the field), and the window asks the window manager
/// for focus (under some window managers keys went nowhere until the title bar was clicked).
fn take_keyboard_focus(ui: &Ui) {
    ui.ctx().memory_mut(egui::Memory::stop_text_input);
    if !ui.ctx().input(|i| i.focused) {
        ui.ctx().send_viewport_cmd(egui::ViewportCommand::Focus);
    }
}

/// The camera's pixel a view point (image pixels of the view) shows: the same, or through the
/// lens model in the undistorted view.
fn camera_pixel(state: &Workspace, p: egui::Pos2) -> Option<(usize, usize)> {
    let q = state.camera_point_of_view(ImagePoint::new(f64::from(p.x), f64::from(p.y)));
    let (w, h) = state.image_size();
    (q.x_px >= 0.0 && q.y_px >= 0.0 && q.x_px < w as f64 && q.y_px < h as f64)
        .then_some((q.x_px as usize, q.y_px as usize))
}

/// What a left click at view point `p` does: picks the chosen landmark there while picking
/// calibration points (sub-pixel, in the camera's image), else samples the pixel for hand
/// classification.
fn click_command(state: &Workspace, p: egui::Pos2) -> Command {
    if state.overhead().active() && state.overhead().landmark().is_some() {
        let q = state.camera_point_of_view(ImagePoint::new(f64::from(p.x), f64::from(p.y)));
        return Command::Overhead(OverheadCommand::PickPoint {
            x_px: q.x_px,
            y_px: q.y_px,
        });
    }
    let (x, y) = camera_pixel(state, p).unwrap_or((p.x as usize, p.y as usize));
    Command::Table(TableCommand::Sample { x, y })
}

/// The thumbnails of the other views in a row; clicking one enlarges it.
pub fn thumbnails_ui(
    ui: &mut Ui,
    state: &Workspace,
    tex: Option<&FrameTextures>,
    commands: &mut Vec<Command>,
) {
    let (w, h) = state.image_size();
    let aspect = if w > 0 { h as f32 / w as f32 } else { 0.75 };
    let height = ui.available_height().max(40.0);
    let width = ((height - 16.0) / aspect).max(40.0);
    ui.horizontal(|ui| {
        for kind in ViewKind::ALL {
            {
                let (block, response) = ui.allocate_exact_size(vec2(width, height), Sense::click());
                let rect = egui::Rect::from_min_size(block.min, vec2(width, height - 16.0));
                let selected = kind == state.settings.main_view;
                response.widget_info(|| {
                    egui::WidgetInfo::selected(egui::Role::Button, true, selected, kind.name())
                });
                let painter = ui.painter_at(rect);
                painter.rect_filled(rect, 2.0, Color32::from_gray(24));
                if let (Some(tex), true) = (tex, w > 0) {
                    let xf = ImageTransform::fitted(rect, [w as f32, h as f32]);
                    paint_view(&painter, &xf, kind, state, tex, false);
                }
                let stroke = if selected {
                    egui::Stroke::new(2.0, ui.visuals().selection.stroke.color)
                } else if response.hovered() {
                    egui::Stroke::new(1.0, Color32::GRAY)
                } else {
                    egui::Stroke::new(1.0, Color32::from_gray(60))
                };
                painter.rect_stroke(rect, 2.0, stroke, egui::StrokeKind::Inside);
                // Painted, not a label widget: the thumbnail itself carries the accessible name.
                painter.text(
                    rect.left_bottom() + vec2(0.0, 2.0),
                    Align2::LEFT_TOP,
                    kind.name(),
                    egui::FontId::proportional(11.0),
                    ui.visuals().text_color(),
                );
                if response.clicked() {
                    commands.push(ViewCommand::SetMainView(kind).into());
                }
                response.on_hover_text(format!("Enlarge the {} view", kind.name()));
            }
        }
    });
}

/// The hover readout: coordinates, Y/U/V, R/G/B, class, blob.
pub fn pixel_readout_ui(ui: &mut Ui, info: Option<&PixelInfo>) {
    let Some(p) = info else {
        ui.weak("hover a pixel");
        return;
    };
    let [r, g, b] = p.rgb;
    let (sw, _) = ui.allocate_exact_size(vec2(10.0, 10.0), Sense::hover());
    ui.painter()
        .rect_filled(sw, 1.0, Color32::from_rgb(r, g, b));
    let blob = p.blob.map_or_else(
        || "no blob".to_owned(),
        |bl| {
            format!(
                "blob #{} {}×{} {} px",
                bl.number,
                bl.width(),
                bl.height(),
                bl.pixels
            )
        },
    );
    let field = p
        .field_cm
        .map(|[x, y]| format!("  field ({x:.1}, {y:.1}) cm"))
        .unwrap_or_default();
    ui.monospace(format!(
        "({:>3},{:>3})  YUV {:>3} {:>3} {:>3}  RGB {:>3} {:>3} {:>3}  {}  {}{field}",
        p.x,
        p.y,
        p.yuv.y,
        p.yuv.u,
        p.yuv.v,
        r,
        g,
        b,
        p.class.name(),
        blob
    ));
}
