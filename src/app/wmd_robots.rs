//! The World Model Debugger's robots list, at the top of the robots window: each robot of the
//! session (its world models seen, or its camera in the session) with how its world models were
//! matched and whether its camera can be shown; clicking a robot selects it, which shows its
//! camera beside the overhead view ([`OverheadCommand::SelectRobot`]).

use egui::Ui;

use crate::workspace::{Command, OverheadCommand, Workspace};

/// The list; nothing when the session has no robots.
pub fn wmd_robots_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let rows = state.wmd_robots();
    if rows.is_empty() {
        return;
    }
    ui.strong("World models");
    let selected = state.overhead().selected();
    egui::Grid::new("wmd-robots").striped(true).show(ui, |ui| {
        for h in ["robot", "world models", "camera"] {
            ui.strong(h);
        }
        ui.end_row();
        for r in &rows {
            let mine = selected == Some(r.robot);
            if ui
                .selectable_label(mine, format!("robot {}", r.robot))
                .on_hover_text("select it in every view; its camera beside the overhead view")
                .clicked()
            {
                let key = (!mine).then_some(r.robot);
                commands.push(OverheadCommand::SelectRobot(key).into());
            }
            ui.label(r.summary.map_or_else(
                || "none seen yet".to_owned(),
                |s| {
                    format!(
                        "{} ({} by marker, {} by position, {} unmatched)",
                        s.world_models, s.by_marker, s.by_position, s.unmatched
                    )
                },
            ));
            ui.label(r.camera.as_ref().map_or("—", |c| c.topic()));
            ui.end_row();
        }
    });
    ui.separator();
}
