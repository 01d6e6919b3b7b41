//! The robots window (Camera ▸ Connect to robot…): connect robots by address, several at once,
//! and a list of them — name, connection state (with why a connection closed), frame rate,
//! drops, latency, recording, the robot's latest misbehaviour — where clicking a robot shows it.
//! Every action is a [`Command`].
//! [`live_controls_ui`] is the timeline's Live switch while a robot is shown.

use std::path::PathBuf;

use egui::{RichText, Ui};

use crate::live::Connection;
use crate::workspace::{Command, RobotId, RobotRow, RobotsCommand, Workspace};

/// What the robots window is editing.
#[derive(Debug)]
pub struct RobotsPanel {
    /// The robot address typed (`HOST:PORT` or `ws://HOST:PORT`).
    pub address: String,
    /// The folder recordings go into, one file per robot named after it.
    pub folder: String,
    /// The robot whose Disconnect was clicked once: it asks for a second click.
    pub confirm_disconnect: Option<RobotId>,
}

impl Default for RobotsPanel {
    fn default() -> Self {
        Self {
            address: "127.0.0.1:8765".to_owned(),
            folder: "recordings".to_owned(),
            confirm_disconnect: None,
        }
    }
}

/// Widths of the robot rows' cells, points: fixed, so that no button moves when a figure, the
/// recording or the connection changes (after Record all, the next click hit Disconnect).
const FPS_WIDTH: f32 = 56.0;
const DROPS_WIDTH: f32 = 76.0;
const LATENCY_WIDTH: f32 = 120.0;
const RECORDED_WIDTH: f32 = 110.0;
const BUTTON_WIDTH: f32 = 120.0;

/// The window's contents: the address field, recording into a folder, the robots list. Every
/// line wraps, so in a narrow dock tab all buttons stay in view without scrolling sideways.
pub fn robots_ui(
    ui: &mut Ui,
    state: &Workspace,
    panel: &mut RobotsPanel,
    commands: &mut Vec<Command>,
) {
    super::wmd_robots::wmd_robots_ui(ui, state, commands);
    ui.horizontal_wrapped(|ui| {
        let label = ui.label("address");
        ui.add(
            egui::TextEdit::singleline(&mut panel.address)
                .hint_text("HOST:PORT")
                .desired_width(220.0),
        )
        .labelled_by(label.id);
        let address = panel.address.trim();
        if ui
            .add_enabled(!address.is_empty(), egui::Button::new("Connect robot"))
            .on_hover_text("connect beside the robots connected already")
            .clicked()
        {
            commands.push(RobotsCommand::ConnectRobot(address.to_owned()).into());
        }
    });
    ui.horizontal_wrapped(|ui| {
        let label = ui.label("record into folder");
        ui.add(egui::TextEdit::singleline(&mut panel.folder).desired_width(220.0))
            .labelled_by(label.id);
        let folder = panel.folder.trim();
        if ui
            .add_enabled(
                !folder.is_empty() && !state.robots().is_empty(),
                egui::Button::new("Record all"),
            )
            .on_hover_text("every robot not recording yet, one file each, bit-exact")
            .clicked()
        {
            commands.push(RobotsCommand::RecordAllRobots(PathBuf::from(folder)).into());
        }
    });
    ui.separator();
    let rows = state.robots();
    if rows.is_empty() {
        ui.weak("No robot connected. A team is four or five: connect each by its address.");
        return;
    }
    // One block per robot, its lines wrapping: the list fits its dock tab at any width (a
    // table of seven columns was wider than the tab at 1280×800, its buttons off to the right).
    for row in &rows {
        robot_row_ui(ui, state, panel, row, commands);
        ui.separator();
    }
    live_controls_ui(ui, state, commands);
}

/// One robot: its name (click to show it) and connection state; its figures in cells of fixed
/// width; Record/Stop as one button of constant width; Disconnect on its own line at the right,
/// asking for a second click.
fn robot_row_ui(
    ui: &mut Ui,
    state: &Workspace,
    panel: &mut RobotsPanel,
    row: &RobotRow,
    commands: &mut Vec<Command>,
) {
    let id = row.id;
    ui.horizontal_wrapped(|ui| {
        if ui
            .selectable_label(row.shown, RichText::new(&row.name).strong())
            .on_hover_text(format!("{}: click to show it", row.url))
            .clicked()
            && !row.shown
        {
            commands.push(RobotsCommand::ShowRobot(id).into());
        }
        let text = row.connection.to_string();
        let state_label = match &row.connection {
            Connection::Connected(_) => ui.label(text),
            Connection::Connecting => ui.weak(text),
            Connection::Disconnected { .. } => ui.colored_label(ui.visuals().warn_fg_color, text),
        };
        state_label.on_hover_text(state.robot_log(id).join("\n"));
    });
    ui.horizontal_wrapped(|ui| {
        let s = &row.stats;
        let cell = |ui: &mut Ui, width: f32, text: String| {
            ui.add_sized(
                [width, ui.spacing().interact_size.y],
                egui::Label::new(RichText::new(text).monospace()).truncate(),
            )
        };
        cell(ui, FPS_WIDTH, format!("{:.0} fps", s.fps));
        cell(ui, DROPS_WIDTH, format!("{} drops", s.drops));
        cell(
            ui,
            LATENCY_WIDTH,
            match (s.latency_median_ms, s.latency_p99_ms) {
                (Some(m), Some(p)) => format!("{m:.1} / {p:.1} ms"),
                _ => "- ms".to_owned(),
            },
        )
        .on_hover_text("latency, median / 99th percentile: the sender's write to the frame here");
        let recorded = match &row.recording {
            Some(_) => format!("rec {}", s.recorded.unwrap_or(0)),
            None => "not recording".to_owned(),
        };
        let r = cell(ui, RECORDED_WIDTH, recorded);
        if let Some(path) = &row.recording {
            r.on_hover_text(path.display().to_string());
        }
    });
    ui.horizontal(|ui| {
        let (text, hover) = match &row.recording {
            Some(_) => ("Stop recording", "close its recording"),
            None => ("Record", "into the folder above, named after the robot"),
        };
        if ui
            .add_sized([BUTTON_WIDTH, 0.0], egui::Button::new(text).small())
            .on_hover_text(hover)
            .clicked()
        {
            let command = match &row.recording {
                Some(_) => RobotsCommand::StopRecordingRobot(id),
                None => RobotsCommand::RecordRobot(
                    id,
                    state.robot_recording_path(id, &PathBuf::from(panel.folder.trim())),
                ),
            };
            commands.push(command.into());
        }
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
            disconnect_ui(ui, panel, id, &row.name, commands);
        });
    });
    if let Some(problem) = &row.stats.problem {
        // One line per misbehaviour (garbage, a message too large, a limit reached), kept
        // after the robot reconnects.
        ui.colored_label(ui.visuals().warn_fg_color, problem)
            .on_hover_text("what this robot last did wrong; hover its state for its log");
    }
}

/// Disconnect, then (in its place) "Confirm disconnect" and Cancel: a robot is never dropped
/// by one stray click.
fn disconnect_ui(
    ui: &mut Ui,
    panel: &mut RobotsPanel,
    id: RobotId,
    name: &str,
    commands: &mut Vec<Command>,
) {
    if panel.confirm_disconnect == Some(id) {
        if ui.small_button("Cancel").clicked() {
            panel.confirm_disconnect = None;
        }
        if ui
            .small_button("Confirm disconnect")
            .on_hover_text(format!("drop the connection to {name}"))
            .clicked()
        {
            panel.confirm_disconnect = None;
            commands.push(RobotsCommand::DisconnectRobot(id).into());
        }
    } else if ui
        .small_button("Disconnect")
        .on_hover_text("asks again before dropping the connection")
        .clicked()
    {
        panel.confirm_disconnect = Some(id);
    }
}

/// While a robot is shown: the Live switch (follow its newest frame, or hold the view to step
/// back through what has arrived) and where the view is.
pub fn live_controls_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    if state.shown_robot().is_none() {
        return;
    }
    let live = state.following_live();
    let button = egui::Button::new("Live").selected(live);
    let hover = if live {
        "showing each frame as it arrives: click to hold the view"
    } else {
        "back to the newest frame"
    };
    if ui.add(button).on_hover_text(hover).clicked() {
        commands.push(RobotsCommand::SetFollowLive(!live).into());
    }
    if !live {
        ui.weak("held")
            .on_hover_text("reception and recording go on; Live shows the newest frame");
    }
}
