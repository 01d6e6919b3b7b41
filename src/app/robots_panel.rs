//! The robots window (Camera ▸ Connect to robot…): connect robots by address, several at once,
//! and a list of them — name, connection state (with why a connection closed), frame rate,
//! drops, latency, recording, the robot's latest misbehaviour — where clicking a robot shows it.
//! Every action is a [`Command`].
//! [`live_controls_ui`] is the timeline's Live switch while a robot is shown.

use std::path::PathBuf;

use egui::{RichText, Ui};

use crate::live::Connection;
use crate::workspace::{Command, RobotRow, RobotsCommand, Workspace};

/// What the robots window is editing.
#[derive(Debug)]
pub struct RobotsPanel {
    /// The robot address typed (`HOST:PORT` or `ws://HOST:PORT`).
    pub address: String,
    /// The folder recordings go into, one file per robot named after it.
    pub folder: String,
}

impl Default for RobotsPanel {
    fn default() -> Self {
        Self {
            address: "127.0.0.1:8765".to_owned(),
            folder: "recordings".to_owned(),
        }
    }
}

/// The window's contents: the address field, recording into a folder, the robots list. Every
/// line wraps, so in a narrow dock tab all buttons stay in view without scrolling sideways.
pub fn robots_ui(
    ui: &mut Ui,
    state: &Workspace,
    panel: &mut RobotsPanel,
    commands: &mut Vec<Command>,
) {
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

/// One robot: its name (click to show it) and connection state, then its figures, recording
/// and buttons.
fn robot_row_ui(
    ui: &mut Ui,
    state: &Workspace,
    panel: &RobotsPanel,
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
        ui.monospace(format!("{:.0} fps", s.fps));
        ui.monospace(format!("{} drops", s.drops));
        ui.monospace(match (s.latency_median_ms, s.latency_p99_ms) {
            (Some(m), Some(p)) => format!("{m:.1} / {p:.1} ms"),
            _ => "- ms".to_owned(),
        })
        .on_hover_text("latency, median / 99th percentile: the sender's write to the frame here");
        match &row.recording {
            Some(path) => {
                ui.label(RichText::new(format!("rec {}", s.recorded.unwrap_or(0))).strong())
                    .on_hover_text(path.display().to_string());
                if ui.small_button("Stop").clicked() {
                    commands.push(RobotsCommand::StopRecordingRobot(id).into());
                }
            }
            None => {
                let folder = PathBuf::from(panel.folder.trim());
                if ui
                    .small_button("Record")
                    .on_hover_text("into the folder above, named after the robot")
                    .clicked()
                {
                    commands.push(
                        RobotsCommand::RecordRobot(id, state.robot_recording_path(id, &folder))
                            .into(),
                    );
                }
            }
        }
        if ui.small_button("Disconnect").clicked() {
            commands.push(RobotsCommand::DisconnectRobot(id).into());
        }
    });
    if let Some(problem) = &row.stats.problem {
        // One line per misbehaviour (garbage, a message too large, a limit reached), kept
        // after the robot reconnects.
        ui.colored_label(ui.visuals().warn_fg_color, problem)
            .on_hover_text("what this robot last did wrong; hover its state for its log");
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
