//! The field view's cameras: each overhead camera's view of the carpet (outlined and lightly
//! filled in the camera's colour, labelled with its session id), the legend (the Camera
//! coverage switch, each camera's colour and whether its frame is current or stale), which
//! cameras saw each robot and the ball (a dot per camera in its colour beside it), and the
//! tooltip over a robot or the ball listing those cameras with their frames' times. It draws
//! the workspace's [`crate::workspace::overhead::FieldCameras`] only.

use egui::{Color32, FontId, Pos2, Stroke, Ui, vec2};

use super::field_view::{FieldTransform, ssl_camera_colour};
use crate::overhead::merge::{FieldPicture, SslCameraId};
use crate::workspace::overhead::{CameraShown, FieldCameras, FrameState};
use crate::workspace::{Command, OverheadCommand, Workspace};

/// Opacity of a coverage's fill: light enough that the field lines, robots and other cameras'
/// coverage show through where views overlap.
const FILL_OPACITY: f32 = 0.12;
/// Radius of a "seen by" dot, points.
const DOT_RADIUS_PT: f32 = 2.6;

/// Camera `id`'s colour: SSL-Vision's camera of the same id has the same one.
#[must_use]
pub fn camera_colour(id: SslCameraId) -> Color32 {
    ssl_camera_colour(u32::from(id.0))
}

/// The fill of camera `id`'s coverage.
#[must_use]
pub fn coverage_fill(id: SslCameraId) -> Color32 {
    camera_colour(id).gamma_multiply(FILL_OPACITY)
}

/// The legend row above the drawing: the Camera coverage switch, then each camera in its
/// colour with its frame's state (hover for its recording and frame time).
pub fn legend_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let overhead = state.overhead();
    if !overhead.active() {
        return;
    }
    let cameras = overhead.field_cameras().cameras();
    let shown_ns = match cameras.first().map(|c| c.frame) {
        Some(FrameState::Current { time_ns, .. }) => Some(time_ns),
        _ => None,
    };
    ui.horizontal_wrapped(|ui| {
        let mut view = state.settings.overhead;
        if ui
            .checkbox(&mut view.coverage, "Camera coverage")
            .on_hover_text(
                "each camera's view of the carpet, outlined and lightly filled in its colour",
            )
            .changed()
        {
            commands.push(OverheadCommand::SetView(view).into());
        }
        for c in &cameras {
            camera_entry_ui(ui, c, shown_ns);
        }
    });
}

/// One camera's legend entry: a swatch, `camera N` in its colour, `current` or `stale`.
fn camera_entry_ui(ui: &mut Ui, c: &CameraShown<'_>, shown_ns: Option<u64>) {
    let colour = camera_colour(c.id);
    let (r, _) = ui.allocate_exact_size(vec2(12.0, 12.0), egui::Sense::hover());
    ui.painter().rect_filled(r, 2.0, colour);
    let name = format!("camera {}", c.id);
    let coverage = if c.coverage.is_some() {
        ""
    } else {
        "; no coverage drawn (no calibration, or its frames are not its calibration's shape)"
    };
    let (word, tip, word_colour) = match c.frame {
        FrameState::Current { index, time_ns } => (
            "current".to_owned(),
            format!(
                "{}: frame {index} at {:.3} s{coverage}",
                c.name,
                time_ns as f64 * 1e-9
            ),
            ui.visuals().weak_text_color(),
        ),
        FrameState::Stale { last_time_ns } => {
            let age = match (last_time_ns, shown_ns) {
                (Some(last), Some(now)) => format!(
                    "its last frame {:.2} s before this one",
                    now.saturating_sub(last) as f64 * 1e-9
                ),
                _ => "no frame of it yet".to_owned(),
            };
            (
                "stale".to_owned(),
                format!(
                    "{}: no frame within half a frame period of the shown one ({age}): it stopped delivering or has a gap{coverage}",
                    c.name
                ),
                ui.visuals().warn_fg_color,
            )
        }
    };
    ui.colored_label(colour, name).on_hover_text(&tip);
    ui.label(egui::RichText::new(word).small().color(word_colour))
        .on_hover_text(tip);
}

/// Each camera's coverage, outlined and lightly filled in its colour, labelled `camera N` at
/// its middle.
pub fn paint_coverage(painter: &egui::Painter, xf: &FieldTransform, cameras: &[CameraShown<'_>]) {
    for c in cameras {
        let Some(cov) = c.coverage else { continue };
        let points: Vec<Pos2> = cov.polygon_cm.iter().map(|p| xf.to_screen(*p)).collect();
        if points.len() < 3 {
            continue;
        }
        let colour = camera_colour(c.id);
        painter.add(egui::Shape::convex_polygon(
            points.clone(),
            coverage_fill(c.id),
            Stroke::NONE,
        ));
        painter.add(egui::Shape::closed_line(
            points.clone(),
            Stroke::new(1.5, colour),
        ));
        // The label near the middle of the view, nudged per camera so overlapping views'
        // labels do not cover each other.
        let n = points.len() as f32;
        let mid = points.iter().fold(Pos2::ZERO, |a, p| a + p.to_vec2() / n);
        painter.text(
            mid + vec2(0.0, 12.0 * f32::from(c.id.0 % 3) - 12.0),
            egui::Align2::CENTER_CENTER,
            format!("camera {}", c.id),
            FontId::proportional(11.0),
            colour,
        );
    }
}

/// A row of dots, one per camera in its colour, starting at `at` and going right: which
/// cameras saw the object there.
fn paint_dots(painter: &egui::Painter, at: Pos2, ids: &[SslCameraId]) {
    for (k, id) in ids.iter().enumerate() {
        let c = at + vec2(k as f32 * (2.0 * DOT_RADIUS_PT + 1.5), 0.0);
        painter.circle_filled(c, DOT_RADIUS_PT, camera_colour(*id));
        painter.circle_stroke(c, DOT_RADIUS_PT, Stroke::new(0.6, Color32::BLACK));
    }
}

/// Which cameras saw each robot (dots under its lower right) and the ball (dots beside it),
/// where there are several cameras (a session); `robot_radius_cm` as the robots are drawn.
pub fn paint_seen_by(
    painter: &egui::Painter,
    xf: &FieldTransform,
    cameras: &FieldCameras,
    robot_radius_cm: f32,
) {
    let (Some(picture), Some(_)) = (cameras.picture(), cameras.session()) else {
        return;
    };
    let robot_radius_pt = (robot_radius_cm * xf.scale()).max(4.0);
    for r in &picture.robots {
        let c = xf.to_screen(r.field_cm);
        paint_dots(
            painter,
            c + vec2(robot_radius_pt * 0.2, robot_radius_pt + DOT_RADIUS_PT + 1.0),
            &r.camera_ids,
        );
    }
    if let Some(b) = &picture.ball {
        let c = xf.to_screen(b.ball.field_cm);
        paint_dots(painter, c + vec2(7.0, 0.0), &b.camera_ids);
    }
}

/// What the pointer is over, for the tooltip: the nearest robot or ball within `radius_pt`,
/// as its name and the cameras that saw it.
fn hovered(
    picture: &FieldPicture,
    xf: &FieldTransform,
    pointer: Pos2,
    radius_pt: f32,
) -> Option<(String, Vec<SslCameraId>)> {
    let robots = picture.robots.iter().map(|r| {
        (
            xf.to_screen(r.field_cm),
            format!("{} {}", r.team.name(), r.identity.value()),
            r.camera_ids.clone(),
        )
    });
    let ball = picture.ball.iter().map(|b| {
        (
            xf.to_screen(b.ball.field_cm),
            "ball".to_owned(),
            b.camera_ids.clone(),
        )
    });
    robots
        .chain(ball)
        .map(|(p, name, ids)| (p.distance(pointer), name, ids))
        .filter(|(d, _, _)| *d <= radius_pt)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, name, ids)| (name, ids))
}

/// The tooltip over a robot or the ball: the cameras that saw it, each with its frame's time.
pub fn seen_by_tooltip(
    response: &egui::Response,
    state: &Workspace,
    xf: &FieldTransform,
    radius_pt: f32,
) {
    let cameras = state.overhead().field_cameras();
    let (Some(picture), Some(pointer)) = (cameras.picture(), response.hover_pos()) else {
        return;
    };
    let Some((name, ids)) = hovered(picture, xf, pointer, radius_pt) else {
        return;
    };
    let shown = cameras.cameras();
    response.clone().on_hover_ui_at_pointer(|ui| {
        ui.strong(format!("{name}: seen by"));
        for id in ids {
            let time = shown
                .iter()
                .find(|c| c.id == id)
                .and_then(|c| match c.frame {
                    FrameState::Current { index, time_ns } => {
                        Some(format!("frame {index} at {:.3} s", time_ns as f64 * 1e-9))
                    }
                    FrameState::Stale { .. } => None,
                });
            ui.colored_label(
                camera_colour(id),
                format!("camera {id}: {}", time.unwrap_or_else(|| "–".to_owned())),
            );
        }
    });
}
