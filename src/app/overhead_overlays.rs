//! The overhead camera's overlays on the image views, through the view's one
//! [`ImageTransform`]: the field lines projected through the calibration in use (to judge it at
//! a glance), the ball (circle and field position), each robot (marker outline, heading arrow,
//! team colour, identity; the selected one thicker, the rest dimmed), and the picked
//! calibration points with each one's reprojection error drawn as a line to where the
//! calibration puts it; each robot's world model (`wmd_overlay.rs`). In the undistorted view every point goes through the lens model first.

use egui::{Color32, FontId, Painter, Pos2, Rect, Stroke, pos2, vec2};

use super::overlays::ImageTransform;
use crate::geometry::{ImagePoint, MarkerTeam};
use crate::workspace::{RobotKey, ViewKind, Workspace};

/// Colour of the projected field lines.
const FIELD_LINE_COLOUR: Color32 = Color32::from_rgb(255, 40, 200);
/// Colour of the ball's circle and label.
const BALL_COLOUR: Color32 = Color32::from_rgb(255, 150, 30);
/// Alpha of robots other than the selected one.
const DIMMED_ALPHA: f32 = 0.35;

/// The display colour of a team's dot.
#[must_use]
pub fn team_colour(team: MarkerTeam) -> Color32 {
    match team {
        MarkerTeam::Blue => Color32::from_rgb(60, 170, 255),
        MarkerTeam::Yellow => Color32::from_rgb(250, 220, 40),
    }
}

/// Paints the overhead overlays of view `kind` (nothing for a robot-camera frame).
pub fn paint_overhead(
    painter: &Painter,
    xf: &ImageTransform,
    kind: ViewKind,
    state: &Workspace,
    with_overlays: bool,
) {
    let overhead = state.overhead();
    if !overhead.active() {
        return;
    }
    let to_screen = |p: ImagePoint| -> Option<Pos2> {
        let v = state.overhead_view_point(p)?;
        Some(xf.to_screen(pos2(v.x_px as f32, v.y_px as f32)))
    };
    let view = state.settings.overhead;
    if with_overlays
        && view.field_lines
        && kind != ViewKind::Blobs
        && let Some((camera, _)) = overhead.camera()
    {
        let stroke = Stroke::new(1.0, FIELD_LINE_COLOUR.gamma_multiply(0.8));
        // Projected lines run a little past the frame (points up to 20 px outside are kept so
        // that lines reach its edges): clipped to the image, not drawn over the background.
        let painter = painter.with_clip_rect(painter.clip_rect().intersect(xf.image_rect()));
        // The lines are computed for the calibration's size; scaled to the frame's.
        let (w, h) = state.image_size();
        let s = [
            w as f64 / camera.width_px.max(1) as f64,
            h as f64 / camera.height_px.max(1) as f64,
        ];
        for curve in overhead.projected_field_lines() {
            let pts: Vec<Pos2> = curve
                .iter()
                .filter_map(|p| to_screen(ImagePoint::new(p.x_px * s[0], p.y_px * s[1])))
                .collect();
            painter.add(egui::Shape::line(pts, stroke));
        }
    }
    if kind == ViewKind::Objects || with_overlays {
        paint_detections(painter, xf, state, with_overlays, &to_screen);
        super::wmd_overlay::paint_world_models(painter, state, &to_screen);
    }
    if with_overlays && view.points {
        paint_points(painter, state, &to_screen);
    }
}

fn paint_detections(
    painter: &Painter,
    xf: &ImageTransform,
    state: &Workspace,
    labels: bool,
    to_screen: &dyn Fn(ImagePoint) -> Option<Pos2>,
) {
    let Some(d) = state.overhead_detections() else {
        return;
    };
    if let Some(b) = &d.ball
        && let Some(c) = to_screen(b.image)
    {
        let r = (b.radius_px as f32 * xf.zoom).max(3.0);
        painter.circle_stroke(c, r, Stroke::new(2.0, BALL_COLOUR));
        if labels {
            label(
                painter,
                c + vec2(r + 3.0, -r),
                format!("ball ({:.0}, {:.0}) cm", b.field_cm[0], b.field_cm[1]),
                BALL_COLOUR,
            );
        }
    }
    let selected = state.overhead().selected();
    for r in &d.robots {
        let key = RobotKey {
            team: r.team,
            identity: r.identity,
        };
        let mine = selected == Some(key);
        let mut colour = team_colour(r.team);
        if selected.is_some() && !mine {
            colour = colour.gamma_multiply(DIMMED_ALPHA);
        }
        let Some(c) = to_screen(r.image) else {
            continue;
        };
        let dots: Vec<Pos2> = r.dots.iter().filter_map(|&p| to_screen(p)).collect();
        // The plate is 30 cm across; the dots' centres are 10 cm from its centre.
        let spread = dots.iter().map(|p| p.distance(c)).sum::<f32>() / dots.len().max(1) as f32;
        let plate = (spread * 1.5).max(4.0);
        let width = if mine { 3.0 } else { 1.5 };
        painter.circle_stroke(c, plate, Stroke::new(width + 1.0, Color32::BLACK));
        painter.circle_stroke(c, plate, Stroke::new(width, colour));
        for p in &dots {
            painter.circle_stroke(*p, (spread * 0.3).max(1.5), Stroke::new(1.0, colour));
        }
        // Heading: from the centre through the middle of the front dots (bits 0 and 1).
        if let (Some(a), Some(b)) = (dots.first(), dots.get(1)) {
            let front = pos2((a.x + b.x) / 2.0, (a.y + b.y) / 2.0);
            let dir = (front - c).normalized();
            if dir.is_finite() {
                painter.arrow(c, dir * plate * 1.6, Stroke::new(width, colour));
            }
        }
        if labels {
            label(
                painter,
                c + vec2(plate + 3.0, -plate),
                format!(
                    "{} {} ({:.0}, {:.0}) cm {:.0}°",
                    r.team.name(),
                    r.identity.value(),
                    r.field_cm[0],
                    r.field_cm[1],
                    r.heading_rad.to_degrees()
                ),
                colour,
            );
        }
    }
}

/// Each picked point as a cross with its name; with a calibration solved from them, a line to
/// where the calibration reprojects it (its error, pixels).
fn paint_points(
    painter: &Painter,
    state: &Workspace,
    to_screen: &dyn Fn(ImagePoint) -> Option<Pos2>,
) {
    let overhead = state.overhead();
    let residuals = overhead
        .calibration()
        .map(|c| c.points.as_slice())
        .unwrap_or(&[]);
    for p in &overhead.points().points {
        let Some(c) = to_screen(p.image()) else {
            continue;
        };
        for stroke in [
            Stroke::new(3.0, Color32::BLACK),
            Stroke::new(1.0, Color32::WHITE),
        ] {
            painter.line_segment([c - vec2(5.0, 0.0), c + vec2(5.0, 0.0)], stroke);
            painter.line_segment([c - vec2(0.0, 5.0), c + vec2(0.0, 5.0)], stroke);
        }
        let mut text = p.name.clone();
        if let Some(r) = residuals.iter().find(|r| r.name == p.name) {
            let projected = ImagePoint::new(r.projected_px[0], r.projected_px[1]);
            if let Some(q) = to_screen(projected) {
                painter.line_segment([c, q], Stroke::new(2.0, Color32::RED));
                painter.circle_filled(q, 2.5, Color32::RED);
            }
            text = format!("{text} {:.2} px", r.error_px);
        }
        label(painter, c + vec2(6.0, 14.0), text, Color32::WHITE);
    }
}

fn label(painter: &Painter, at: Pos2, text: String, colour: Color32) {
    let galley = painter.layout_no_wrap(text, FontId::proportional(11.0), colour);
    let bg = Rect::from_min_size(at - vec2(0.0, galley.size().y), galley.size()).expand(2.0);
    painter.rect_filled(bg, 3.0, Color32::from_black_alpha(170));
    painter.galley(bg.min + vec2(2.0, 2.0), galley, colour);
}
