//! The field view: a top-down drawing of the field description's lines with the ball and each
//! robot where the overhead camera puts them (position, heading, team colour, identity) and
//! short trails; each robot's own world-model estimate of itself and of the ball drawn beside
//! that overhead truth with the error of each, and the errors over the frames seen
//! (`wmd_errors.rs`).
//! Clicking a robot selects it in every view. SSL-Vision's detections (a league log or a live
//! address opened beside, or alone) are drawn over it, each camera's in its own colour. It draws
//! the workspace's field model only. Each overhead camera's coverage, the camera legend and which
//! cameras saw each robot and the ball (a session's merged picture) are drawn by
//! `field_cameras.rs`.

use egui::{Color32, FontId, Pos2, Rect, Sense, Stroke, Ui, vec2};

use super::overhead_overlays::team_colour;
pub use super::wmd_errors::errors_plot_id;
use crate::overhead::FieldDescription;
use crate::workspace::{Command, OverheadCommand, RobotKey, Workspace};

/// Margin round the field's lines, centimetres.
const MARGIN_CM: f32 = 30.0;
/// A robot's drawn radius, centimetres (the marker plate's).
const ROBOT_RADIUS_CM: f32 = 15.0;
/// Screen distance within which a click selects a robot, points.
const CLICK_RADIUS_PT: f32 = 14.0;
/// Colour of a robot's own world-model estimates.
const WORLD_MODEL_COLOUR: Color32 = Color32::from_rgb(230, 230, 230);
/// Colour of the ball.
const BALL_COLOUR: Color32 = Color32::from_rgb(255, 150, 30);

/// Field cm ↔ screen points for the drawing: x right, y up.
#[derive(Debug, Clone, Copy)]
pub struct FieldTransform {
    rect: Rect,
    centre_cm: [f32; 2],
    scale: f32,
}

impl FieldTransform {
    /// Fits the field's lines and landmarks (with a margin) into `rect`.
    #[must_use]
    pub fn fit(rect: Rect, field: &FieldDescription) -> Self {
        let mut lo = [f32::MAX; 2];
        let mut hi = [f32::MIN; 2];
        let points = field
            .lines
            .iter()
            .flat_map(|l| [l.from_cm, l.to_cm])
            .chain(field.landmarks.iter().map(|l| l.field_cm));
        for p in points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k] as f32);
                hi[k] = hi[k].max(p[k] as f32);
            }
        }
        if lo[0] > hi[0] {
            lo = [-300.0, -200.0];
            hi = [300.0, 200.0];
        }
        let (w, h) = (
            hi[0] - lo[0] + 2.0 * MARGIN_CM,
            hi[1] - lo[1] + 2.0 * MARGIN_CM,
        );
        Self {
            rect,
            centre_cm: [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0],
            scale: (rect.width() / w).min(rect.height() / h).max(1e-3),
        }
    }

    /// A field point (cm) on screen.
    #[must_use]
    pub fn to_screen(&self, p: [f64; 2]) -> Pos2 {
        self.rect.center()
            + vec2(
                (p[0] as f32 - self.centre_cm[0]) * self.scale,
                -(p[1] as f32 - self.centre_cm[1]) * self.scale,
            )
    }

    /// Screen points per centimetre.
    #[must_use]
    pub const fn scale(&self) -> f32 {
        self.scale
    }
}

/// The window's contents: the drawing, then the table and the plot of world-model errors.
pub fn field_view_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let overhead = state.overhead();
    let ssl = state.ssl_vision();
    if !overhead.active() && ssl.is_none() {
        ui.label(
            "Not an overhead frame: open an overhead stream (e.g. streams/sim-overhead-game.mcap) or SSL-Vision packets (a league log, udp://224.5.23.2:10006).",
        );
        return;
    }
    if overhead.active() && overhead.detections().is_none() {
        ui.label(overhead.calibration_status());
    }
    if let Some(feed) = ssl {
        ssl_feed_ui(ui, state, feed, commands);
    }
    super::field_cameras::legend_ui(ui, state, commands);
    let field = match ssl.and_then(crate::workspace::SslFeed::field) {
        Some(f) if !overhead.active() => f,
        _ => overhead.field(),
    };
    let models = overhead.field_model.world_models();
    let plot_height = if models.is_empty() { 0.0 } else { 200.0 };
    let size = vec2(
        ui.available_width(),
        (ui.available_height() - plot_height).clamp(220.0, 360.0),
    );
    let (rect, response) = ui.allocate_exact_size(size, Sense::click());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "field drawing"));
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_rgb(20, 90, 40));
    let xf = FieldTransform::fit(rect, field);
    if overhead.active() && state.settings.overhead.coverage {
        super::field_cameras::paint_coverage(&painter, &xf, &overhead.field_cameras().cameras());
    }
    paint_field(&painter, &xf, field, overhead.landmark());
    let show_truth_id = egui::Id::unique("eotn-field-view-truth");
    let mut show_truth: bool = ui.data(|d| d.get_temp(show_truth_id)).unwrap_or(true);
    if show_truth && let Some(t) = overhead.truth() {
        paint_truth(&painter, &xf, t);
    }
    let robots = paint_objects(&painter, &xf, state);
    super::field_cameras::paint_seen_by(&painter, &xf, overhead.field_cameras(), ROBOT_RADIUS_CM);
    paint_ssl(&painter, &xf, overhead.field_model.ssl());
    let hover_radius = CLICK_RADIUS_PT.max(ROBOT_RADIUS_CM * xf.scale());
    super::field_cameras::seen_by_tooltip(&response, state, &xf, hover_radius);
    if response.clicked()
        && let Some(pos) = response.interact_pointer_pos()
    {
        let hit = robots
            .iter()
            .map(|(k, p)| (p.distance(pos), *k))
            .filter(|(d, _)| *d <= CLICK_RADIUS_PT.max(ROBOT_RADIUS_CM * xf.scale()))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, k)| k);
        commands.push(OverheadCommand::SelectRobot(hit).into());
    }
    if overhead.truth().is_some() {
        ui.horizontal_wrapped(|ui| {
            ui.checkbox(&mut show_truth, "Ground truth").on_hover_text(
                "the stream's own truth: dashed white rings and a ring for the ball",
            );
            ui.weak("filled: what the camera found; dashed: where they really are");
        });
        ui.data_mut(|d| d.insert_temp(show_truth_id, show_truth));
    }
    if !models.is_empty() {
        super::wmd_errors::errors_ui(ui, state);
    }
}

/// Colour of the ground truth's marks.
const TRUTH_COLOUR: Color32 = Color32::from_rgb(255, 255, 255);

/// The stream's ground truth: each robot as a dashed ring with its heading, the ball as a
/// ring, so that what the camera found (filled) is seen against where things are.
fn paint_truth(
    painter: &egui::Painter,
    xf: &FieldTransform,
    truth: &crate::model::truth::OverheadTruth,
) {
    let stroke = Stroke::new(1.2, TRUTH_COLOUR);
    let radius = (ROBOT_RADIUS_CM * xf.scale()).max(4.0) + 2.0;
    for r in &truth.robots {
        let c = xf.to_screen(r.field_cm);
        let n = 24;
        let ring: Vec<Pos2> = (0..=n)
            .map(|k| {
                let t = k as f32 / n as f32 * std::f32::consts::TAU;
                c + vec2(radius * t.cos(), radius * t.sin())
            })
            .collect();
        painter.extend(egui::Shape::dashed_line(&ring, stroke, 3.0, 3.0));
        let dir = vec2(r.heading_rad.cos() as f32, -(r.heading_rad.sin() as f32));
        painter.line_segment([c + dir * radius, c + dir * radius * 1.6], stroke);
    }
    if let Some(b) = &truth.ball {
        painter.circle_stroke(
            xf.to_screen(b.field_cm),
            (4.25 * xf.scale()).max(3.0) + 3.0,
            stroke,
        );
    }
}

/// The field's lines and landmarks; each landmark's name where it does not cover another's,
/// and the one being picked (`picking`) always, highlighted: where to click for it.
fn paint_field(
    painter: &egui::Painter,
    xf: &FieldTransform,
    field: &FieldDescription,
    picking: Option<&str>,
) {
    let stroke = Stroke::new(1.5, Color32::from_gray(235));
    for l in &field.lines {
        painter.line_segment([xf.to_screen(l.from_cm), xf.to_screen(l.to_cm)], stroke);
    }
    let name_colour = Color32::from_rgb(255, 230, 120);
    let chosen_colour = Color32::from_rgb(255, 80, 220);
    let mut placed: Vec<Rect> = Vec::new();
    // The landmark being picked first, so its name is never the one left out.
    let mut order: Vec<&crate::overhead::field::Landmark> = field.landmarks.iter().collect();
    order.sort_by_key(|l| Some(l.name.as_str()) != picking);
    for l in order {
        let at = xf.to_screen(l.field_cm);
        let chosen = Some(l.name.as_str()) == picking;
        let colour = if chosen { chosen_colour } else { name_colour };
        painter.circle_filled(at, if chosen { 4.5 } else { 2.5 }, colour);
        let galley = painter.layout_no_wrap(l.name.clone(), FontId::proportional(9.0), colour);
        let text_rect = Rect::from_min_size(at + vec2(3.0, -3.0 - galley.size().y), galley.size());
        if chosen || !placed.iter().any(|p| p.intersects(text_rect)) {
            placed.push(text_rect);
            painter.galley(text_rect.min, galley, colour);
        }
    }
    for a in &field.arcs {
        let n = 48;
        let pts: Vec<Pos2> = (0..=n)
            .map(|k| {
                let t = a.from_rad + (a.to_rad - a.from_rad) * f64::from(k) / f64::from(n);
                xf.to_screen([
                    a.centre_cm[0] + a.radius_cm * t.cos(),
                    a.centre_cm[1] + a.radius_cm * t.sin(),
                ])
            })
            .collect();
        painter.add(egui::Shape::line(pts, stroke));
    }
}

/// Draws trails, ball, robots and world models; returns each robot's screen position (for
/// clicks).
fn paint_objects(
    painter: &egui::Painter,
    xf: &FieldTransform,
    state: &Workspace,
) -> Vec<(RobotKey, Pos2)> {
    let overhead = state.overhead();
    let model = &overhead.field_model;
    let selected = overhead.selected();
    let trail = |pts: Vec<Pos2>, colour: Color32| {
        painter.add(egui::Shape::line(
            pts,
            Stroke::new(1.0, colour.gamma_multiply(0.6)),
        ));
    };
    trail(
        model
            .ball_trail()
            .iter()
            .map(|(_, p)| xf.to_screen(*p))
            .collect(),
        BALL_COLOUR,
    );
    for (k, t) in model.trails() {
        trail(
            t.iter().map(|(_, p)| xf.to_screen(*p)).collect(),
            team_colour(k.team),
        );
    }
    let mut out = Vec::new();
    let radius = (ROBOT_RADIUS_CM * xf.scale()).max(4.0);
    if let Some(d) = overhead.field_cameras().picture() {
        for r in &d.robots {
            let key = RobotKey {
                team: r.team,
                identity: r.identity,
            };
            let c = xf.to_screen(r.field_cm);
            let colour = team_colour(r.team);
            let width = if selected == Some(key) { 3.0 } else { 1.0 };
            painter.circle_filled(c, radius, colour.gamma_multiply(0.8));
            painter.circle_stroke(c, radius, Stroke::new(width, Color32::WHITE));
            let dir = vec2(r.heading_rad.cos() as f32, -(r.heading_rad.sin() as f32));
            painter.line_segment(
                [c, c + dir * radius * 1.8],
                Stroke::new(2.0, Color32::BLACK),
            );
            painter.text(
                c,
                egui::Align2::CENTER_CENTER,
                r.identity.value().to_string(),
                FontId::proportional(11.0),
                Color32::BLACK,
            );
            out.push((key, c));
        }
        if let Some(b) = &d.ball {
            painter.circle_filled(
                xf.to_screen(b.ball.field_cm),
                (4.25 * xf.scale()).max(3.0),
                BALL_COLOUR,
            );
        }
    }
    for m in model.world_models() {
        let own = xf.to_screen([m.own[0], m.own[1]]);
        let stroke = Stroke::new(1.0, WORLD_MODEL_COLOUR);
        painter.circle_stroke(own, radius * 0.7, stroke);
        let dir = vec2(m.own[2].cos() as f32, -(m.own[2].sin() as f32));
        painter.line_segment([own, own + dir * radius * 1.4], stroke);
        if let Some(k) = m.key
            && let Some((_, c)) = out.iter().find(|(key, _)| *key == k)
        {
            painter.extend(egui::Shape::dashed_line(&[own, *c], stroke, 4.0, 3.0));
        }
        let text = format!(
            "{}{}",
            m.robot,
            m.self_error_cm
                .map(|e| format!(" {e:.0} cm"))
                .unwrap_or_default()
        );
        painter.text(
            own + vec2(radius, radius),
            egui::Align2::LEFT_TOP,
            text,
            FontId::proportional(10.0),
            WORLD_MODEL_COLOUR,
        );
        if let Some(b) = m.ball {
            painter.circle_stroke(
                xf.to_screen(b),
                (4.25 * xf.scale()).max(3.0),
                Stroke::new(1.0, BALL_COLOUR),
            );
        }
    }
    out
}

/// The colour of SSL-Vision camera `id`'s marks.
#[must_use]
pub fn ssl_camera_colour(id: u32) -> Color32 {
    const PALETTE: [Color32; 8] = [
        Color32::from_rgb(255, 80, 200),
        Color32::from_rgb(80, 230, 255),
        Color32::from_rgb(180, 255, 80),
        Color32::from_rgb(255, 190, 60),
        Color32::from_rgb(170, 120, 255),
        Color32::from_rgb(255, 255, 255),
        Color32::from_rgb(255, 110, 90),
        Color32::from_rgb(90, 255, 170),
    ];
    PALETTE[id as usize % PALETTE.len()]
}

/// What the SSL-Vision source is and shows; a log opened alone gets its own slider.
fn ssl_feed_ui(
    ui: &mut Ui,
    state: &Workspace,
    feed: &crate::workspace::SslFeed,
    commands: &mut Vec<Command>,
) {
    let shown = state.overhead().field_model.ssl();
    let mut line = format!("ssl-vision {}: {} frames", feed.name(), feed.frames());
    if feed.bad_packets() > 0 {
        line.push_str(&format!(", {} packets not SSL-Vision", feed.bad_packets()));
    }
    ui.horizontal_wrapped(|ui| {
        ui.label(line);
        for f in shown {
            ui.colored_label(
                ssl_camera_colour(f.camera_id),
                format!("camera {}", f.camera_id),
            );
        }
        if shown.is_empty() {
            let span = feed.span_ns().map_or_else(String::new, |(a, b)| {
                format!(
                    " (its frames span {:.3}–{:.3} s)",
                    a as f64 * 1e-9,
                    b as f64 * 1e-9
                )
            });
            ui.label(format!(
                "no ssl-vision frame within half a frame period of this time{span}"
            ));
        }
    });
    let (steps, step) = feed.steps();
    if state.source().is_none() && !feed.is_live() && steps > 1 {
        let mut chosen = step;
        let t = shown.first().map_or(0.0, |f| f.t_capture_s);
        let slider = egui::Slider::new(&mut chosen, 0..=steps - 1)
            .text(format!("ssl-vision step ({t:.3} s)"));
        if ui.add(slider).changed() {
            commands.push(Command::ShowSslStep(chosen));
        }
    }
}

/// SSL-Vision's detections, each camera's in its own colour: robots as squares filled with
/// their team's colour, with a heading tick and the id; balls as diamonds.
fn paint_ssl(
    painter: &egui::Painter,
    xf: &FieldTransform,
    frames: &[crate::ssl_vision::CameraFrame],
) {
    let half = (ROBOT_RADIUS_CM * xf.scale()).max(4.0) * 0.8;
    for f in frames {
        let colour = ssl_camera_colour(f.camera_id);
        let stroke = Stroke::new(1.5, colour);
        for r in &f.robots {
            let c = xf.to_screen(r.field_cm);
            let rect = Rect::from_center_size(c, vec2(2.0 * half, 2.0 * half));
            painter.rect_filled(rect, 0.0, team_colour(r.team).gamma_multiply(0.35));
            painter.rect_stroke(rect, 0.0, stroke, egui::StrokeKind::Middle);
            if let Some(h) = r.heading_rad {
                let dir = vec2(h.cos() as f32, -(h.sin() as f32));
                painter.line_segment([c, c + dir * half * 1.8], stroke);
            }
            if let Some(id) = r.robot_id {
                painter.text(
                    c + vec2(half, -half),
                    egui::Align2::LEFT_BOTTOM,
                    id.to_string(),
                    FontId::proportional(10.0),
                    colour,
                );
            }
        }
        for b in &f.balls {
            let c = xf.to_screen(b.field_cm);
            let d = (4.25 * xf.scale()).max(3.0) * 1.6;
            let diamond = vec![
                c + vec2(0.0, -d),
                c + vec2(d, 0.0),
                c + vec2(0.0, d),
                c + vec2(-d, 0.0),
            ];
            painter.add(egui::Shape::closed_line(diamond, stroke));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::pos2;

    #[test]
    fn the_field_fits_its_rectangle_with_x_right_and_y_up() {
        let rect = Rect::from_min_size(pos2(0.0, 0.0), vec2(600.0, 400.0));
        let xf = FieldTransform::fit(rect, &FieldDescription::four_legged_2005());
        let c = xf.to_screen([0.0, 0.0]);
        assert!((c - rect.center()).length() < 1.0);
        assert!(xf.to_screen([100.0, 0.0]).x > c.x);
        assert!(xf.to_screen([0.0, 100.0]).y < c.y);
    }
}
