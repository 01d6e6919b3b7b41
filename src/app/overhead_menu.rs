//! The Overhead menu: whether open frame files are an overhead camera's, the calibration
//! window and the field view, the overhead view options (field lines, undistorted, picked
//! points), closing the calibration.

use egui::Ui;

use crate::workspace::{Command, OverheadCommand, Window, Workspace};

/// The menu's items.
pub fn overhead_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let overhead = state.overhead();
    // Frame files do not say which camera made them: the user does.
    let files = state
        .source()
        .is_some_and(|s| s.info().kind == crate::sources::SourceKind::Files)
        && state.live().is_none();
    let mut is_overhead = state.camera_kind() == crate::sources::CameraKind::Overhead;
    if ui
        .add_enabled(
            files,
            egui::Checkbox::new(&mut is_overhead, "This is an overhead camera"),
        )
        .on_hover_text("the open JPEG or PNG frames are an overhead camera's: find robot markers and the ball on the field")
        .on_disabled_hover_text("for frame files (JPEG, PNG); a stream says which camera made it")
        .changed()
    {
        commands.push(OverheadCommand::SetOverheadCamera(is_overhead).into());
    }
    if !overhead.active() {
        ui.weak("The shown frame is not from an overhead camera.");
    }
    for w in [Window::Calibration, Window::FieldView] {
        let mut open = state.window_open(w);
        if ui.checkbox(&mut open, w.name()).changed() {
            commands.push(Command::ShowWindow(w, open));
        }
    }
    if ui
        .button("World Model Debugger layout")
        .on_hover_text("the overhead view, the field view and the robots list side by side")
        .clicked()
    {
        commands.push(OverheadCommand::WmdLayout.into());
        ui.close();
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
