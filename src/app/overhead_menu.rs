//! The Overhead menu: the calibration window and the field view, the overhead view options
//! (field lines, undistorted, picked points), closing the calibration.

use egui::Ui;

use crate::workspace::{Command, OverheadCommand, Window, Workspace};

/// The menu's items.
pub fn overhead_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let overhead = state.overhead();
    if !overhead.active() {
        ui.weak("The shown frame is not from an overhead camera.");
    }
    for w in [Window::Calibration, Window::FieldView] {
        let mut open = state.window_open(w);
        if ui.checkbox(&mut open, w.name()).changed() {
            commands.push(Command::ShowWindow(w, open));
        }
    }
    ui.separator();
    let mut v = state.settings.overhead;
    let before = v;
    ui.checkbox(&mut v.field_lines, "Field lines through the calibration");
    ui.checkbox(&mut v.undistorted, "Undistorted image");
    ui.checkbox(&mut v.points, "Picked points and their errors");
    if v != before {
        commands.push(OverheadCommand::SetView(v).into());
    }
    ui.separator();
    if ui
        .add_enabled(
            overhead.calibration().is_some(),
            egui::Button::new("Close calibration"),
        )
        .clicked()
    {
        commands.push(OverheadCommand::CloseCalibration.into());
        ui.close();
    }
    if overhead.selected().is_some() && ui.button("Clear robot selection").clicked() {
        commands.push(OverheadCommand::SelectRobot(None).into());
        ui.close();
    }
}
