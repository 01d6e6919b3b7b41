//! Each robot's world model drawn over the overhead image (issue 30): where it believes it is (a
//! ring with a tick along the heading it believes) and where it believes the ball is (a ring),
//! carried from field centimetres into the image through the calibration in use
//! (`Workspace::world_model_marks`), each labelled with its robot; the selected robot's
//! thicker. The field view draws the same world models on the field.

use egui::{Color32, FontId, Painter, Pos2, Stroke, vec2};

use crate::geometry::ImagePoint;
use crate::workspace::Workspace;

/// Colour of the world models (as the field view draws them).
const WORLD_MODEL_COLOUR: Color32 = Color32::from_rgb(230, 230, 230);
/// Colour of a world model's ball.
const BALL_COLOUR: Color32 = Color32::from_rgb(255, 150, 30);
/// Radius of a world model's ring on screen, points.
const RING_PT: f32 = 9.0;

/// Paints the shown frame's world models; `to_screen` carries a camera pixel to the screen.
pub fn paint_world_models(
    painter: &Painter,
    state: &Workspace,
    to_screen: &dyn Fn(ImagePoint) -> Option<Pos2>,
) {
    let selected = state.overhead().selected();
    for m in state.world_model_marks() {
        let width = if selected == Some(m.robot) { 2.5 } else { 1.2 };
        let stroke = Stroke::new(width, WORLD_MODEL_COLOUR);
        if let Some(own) = m.own.and_then(to_screen) {
            painter.circle_stroke(own, RING_PT, stroke);
            if let Some(ahead) = m.heading.and_then(to_screen) {
                let dir = (ahead - own).normalized();
                painter.line_segment([own, own + dir * RING_PT * 1.8], stroke);
            }
            painter.text(
                own + vec2(RING_PT, RING_PT),
                egui::Align2::LEFT_TOP,
                format!("{} thinks", m.robot),
                FontId::proportional(10.0),
                WORLD_MODEL_COLOUR,
            );
        }
        if let Some(ball) = m.ball.and_then(to_screen) {
            painter.circle_stroke(ball, RING_PT * 0.6, Stroke::new(width, BALL_COLOUR));
        }
    }
}
