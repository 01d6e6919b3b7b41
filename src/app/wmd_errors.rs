//! The field view's world-model errors (issue 30): each world model of the shown frame with its
//! errors; below the plots, each robot's median and 95th percentile of its position, heading, ball and
//! tape-measure errors over the frames seen so far, with the frames where its error jumped (the
//! rule `eotn wmd` marks jumps by, `crate::wmd::summary`); and three plots over time — position
//! and ball error, heading error, the tape measure (each `seen` distance minus the true one) —
//! with the jumps marked. The plots neither zoom nor pan under the wheel or a drag (the window
//! scrolls), and their legends are rows above them, not drawn over the curves. It draws the
//! workspace's field model only.

use egui::{Color32, RichText, Sense, Ui, vec2};
use egui_plot::{Line, MarkerShape, Plot, Points, VLine};

use crate::wmd::summary::Spread;
use crate::workspace::{RobotKey, Workspace};

/// Colour of the jump marks.
const JUMP_COLOUR: Color32 = Color32::from_rgb(255, 40, 40);
/// Height of each plot, points.
const PLOT_HEIGHT: f32 = 120.0;

/// One curve or set of points of a plot.
struct Series {
    name: String,
    colour: Color32,
    points: Vec<[f64; 2]>,
    /// Drawn as points (measurements) rather than a line.
    scattered: bool,
}

/// The error table, the robots' spreads and the plots.
pub fn errors_ui(ui: &mut Ui, state: &Workspace) {
    frame_table_ui(ui, state);
    let model = &state.overhead().field_model;
    let now_s = state.current().map_or(0.0, |c| c.time_ns as f64 / 1e9);
    let robots: Vec<RobotKey> = model.summaries().iter().map(|s| s.robot).collect();
    let colour = |r: &RobotKey, k: usize| {
        let i = robots.iter().position(|x| x == r).unwrap_or(0);
        series_colour(2 * i + k)
    };
    let samples: Vec<&crate::workspace::field_model::ErrorSample> = model.error_samples().collect();
    // Jumps: where each robot's position or heading error jumped (`wmd::summary`'s rule).
    let jump_at = |robot: RobotKey, t_ns: u64| {
        samples
            .iter()
            .find(|s| s.time_ns == t_ns)
            .and_then(|s| s.comparisons.iter().find(|c| c.robot == robot))
    };
    let mut position = Vec::new();
    let mut heading = Vec::new();
    let mut tape = Vec::new();
    for r in &robots {
        let per = |f: &dyn Fn(&crate::wmd::Comparison) -> Option<f64>| -> Vec<[f64; 2]> {
            samples
                .iter()
                .filter_map(|s| {
                    let c = s.comparisons.iter().find(|c| c.robot == *r)?;
                    f(c).map(|e| [s.time_s, e])
                })
                .collect()
        };
        position.push(line(
            format!("{r} self"),
            colour(r, 0),
            per(&|c| c.position_error_cm),
        ));
        position.push(line(
            format!("{r} ball"),
            colour(r, 1),
            per(&|c| c.ball_error_cm),
        ));
        heading.push(line(
            format!("{r} heading"),
            colour(r, 0),
            per(&|c| c.heading_error_deg.map(f64::abs)),
        ));
        let measured: Vec<[f64; 2]> = samples
            .iter()
            .flat_map(|s| {
                s.comparisons
                    .iter()
                    .filter(|c| c.robot == *r)
                    .flat_map(|c| c.measurements.iter().filter_map(|m| m.error_cm))
                    .map(|e| [s.time_s, e])
            })
            .collect();
        tape.push(Series {
            name: format!("{r} seen"),
            colour: colour(r, 0),
            points: measured,
            scattered: true,
        });
    }
    let mut jumps_position = Vec::new();
    let mut jumps_heading = Vec::new();
    for s in model.summaries() {
        for &t in &s.jumps_ns {
            if let Some(c) = jump_at(s.robot, t) {
                let t_s = t as f64 / 1e9;
                jumps_position.extend(c.position_error_cm.map(|e| [t_s, e]));
                jumps_heading.extend(c.heading_error_deg.map(|e| [t_s, e.abs()]));
            }
        }
    }
    let jumps = |points: Vec<[f64; 2]>| Series {
        name: "jump".to_owned(),
        colour: JUMP_COLOUR,
        points,
        scattered: true,
    };
    position.push(jumps(jumps_position));
    heading.push(jumps(jumps_heading));
    let plots = [
        (errors_plot_id(), "position and ball error (cm)", position),
        (heading_plot_id(), "heading error (°)", heading),
        (tape_plot_id(), "tape measure: seen − true (cm)", tape),
    ];
    for (id, title, series) in plots {
        ui.label(RichText::new(title).strong());
        plot_ui(ui, id, &series, now_s);
    }
    ui.add_space(4.0);
    spreads_ui(ui, state);
}

fn line(name: String, colour: Color32, points: Vec<[f64; 2]>) -> Series {
    Series {
        name,
        colour,
        points,
        scattered: false,
    }
}

/// A plot with its legend as a row above it. The wheel scrolls the window, not the plot
/// (zooming under the wheel trapped the scroll); the legend is not drawn over the curves
/// (egui_plot's legend hid a third of them).
fn plot_ui(ui: &mut Ui, id: egui::Id, series: &[Series], now_s: f64) {
    ui.horizontal_wrapped(|ui| {
        for s in series.iter().filter(|s| !s.points.is_empty()) {
            let (r, _) = ui.allocate_exact_size(vec2(14.0, 3.0), Sense::hover());
            ui.painter().rect_filled(r, 0.0, s.colour);
            ui.label(RichText::new(&s.name).small());
        }
    });
    Plot::new(id)
        .id(id)
        .height(PLOT_HEIGHT)
        .allow_zoom(false)
        .allow_scroll(false)
        .allow_drag(false)
        .allow_boxed_zoom(false)
        .show(ui, |p| {
            for s in series {
                if s.scattered {
                    let (shape, radius) = if s.colour == JUMP_COLOUR {
                        (MarkerShape::Diamond, 6.0)
                    } else {
                        (MarkerShape::Circle, 2.0)
                    };
                    p.points(
                        Points::new(s.name.clone(), s.points.clone())
                            .color(s.colour)
                            .shape(shape)
                            .radius(radius)
                            .filled(true),
                    );
                } else {
                    p.line(Line::new(s.name.clone(), s.points.clone()).color(s.colour));
                }
            }
            p.vline(VLine::new("current frame", now_s).color(Color32::WHITE));
        });
}

/// Each world model on this frame: how it was matched and its errors.
fn frame_table_ui(ui: &mut Ui, state: &Workspace) {
    let model = &state.overhead().field_model;
    let cm = |e: Option<f64>| e.map_or_else(|| "—".to_owned(), |e| format!("{e:.1}"));
    egui::Grid::new("world-model-errors")
        .striped(true)
        .show(ui, |ui| {
            for h in [
                "world model",
                "robot",
                "self (cm)",
                "heading (°)",
                "ball (cm)",
            ] {
                ui.strong(h);
            }
            ui.end_row();
            for m in model.world_models() {
                ui.label(format!("from {}", m.robot));
                ui.label(match (m.matched, m.key) {
                    (crate::wmd::Matched::Marker, Some(k)) => format!("marker {k}"),
                    (crate::wmd::Matched::Position, Some(k)) => format!("by position: {k}"),
                    _ => "not seen".to_owned(),
                });
                ui.monospace(cm(m.self_error_cm));
                ui.monospace(cm(m.heading_error_deg));
                ui.monospace(cm(m.ball_error_cm));
                ui.end_row();
            }
        });
}

/// A spread as a cell: "median / p95 (n)", or "— (0)" without data (a percentile of nothing is
/// no figure).
#[must_use]
pub fn spread_text(s: Option<Spread>) -> String {
    s.map_or_else(
        || "— (0)".to_owned(),
        |s| format!("{:.1} / {:.1} ({})", s.median, s.p95, s.n),
    )
}

/// Each robot's medians and 95th percentiles over the frames seen, and its jumps.
fn spreads_ui(ui: &mut Ui, state: &Workspace) {
    let summaries = state.overhead().field_model.summaries();
    if summaries.is_empty() {
        return;
    }
    ui.label(RichText::new("over the frames seen: median / p95 (samples)").weak());
    egui::Grid::new("world-model-spreads")
        .striped(true)
        .show(ui, |ui| {
            for h in [
                "robot",
                "self (cm)",
                "heading (°)",
                "ball (cm)",
                "tape (cm)",
                "jumps",
            ] {
                ui.strong(h);
            }
            ui.end_row();
            for s in summaries {
                ui.label(format!("{} (all frames)", s.robot));
                for spread in [s.position_cm, s.heading_deg, s.ball_cm, s.distance_cm] {
                    ui.monospace(spread_text(spread));
                }
                if s.jumps_ns.is_empty() {
                    ui.label("none");
                } else {
                    let at: Vec<String> = s
                        .jumps_ns
                        .iter()
                        .map(|t| format!("{:.2} s", *t as f64 / 1e9))
                        .collect();
                    ui.colored_label(JUMP_COLOUR, format!("jump at {}", at.join(", ")));
                }
                ui.end_row();
            }
        });
}

/// The position and ball error plot's id (tests read its memory: the wheel leaves its bounds
/// alone).
#[must_use]
pub fn errors_plot_id() -> egui::Id {
    egui::Id::unique("eotn-world-model-error-plot")
}

/// The heading error plot's id.
#[must_use]
pub fn heading_plot_id() -> egui::Id {
    egui::Id::unique("eotn-world-model-heading-plot")
}

/// The tape-measure plot's id.
#[must_use]
pub fn tape_plot_id() -> egui::Id {
    egui::Id::unique("eotn-world-model-tape-plot")
}

/// The `k`th plotted series' colour: distinct hues round the wheel.
fn series_colour(k: usize) -> Color32 {
    const PALETTE: [Color32; 8] = [
        Color32::from_rgb(255, 99, 71),
        Color32::from_rgb(60, 170, 255),
        Color32::from_rgb(250, 220, 40),
        Color32::from_rgb(120, 220, 120),
        Color32::from_rgb(230, 120, 230),
        Color32::from_rgb(255, 160, 60),
        Color32::from_rgb(80, 220, 220),
        Color32::from_rgb(200, 200, 200),
    ];
    PALETTE[k % PALETTE.len()]
}
