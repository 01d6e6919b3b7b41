//! The overhead calibration window: the field description, the calibration file (open, save,
//! close), picking points — choose a landmark by name, click it in the image (the next one not
//! yet picked is chosen after each click), undo —, Calibrate, and the reprojection error of
//! each point in a table. File names are typed (native dialogs are not always available).

use std::path::PathBuf;

use egui::Ui;

use crate::workspace::{
    Command, OverheadCommand, OverheadView, Workspace, overhead::MIN_CALIBRATION_POINTS,
};

/// The file names typed in the window.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct OverheadPaths {
    /// Calibration file (`*.json`).
    pub calibration: String,
    /// Points file (`*.points.json`).
    pub points: String,
    /// Field description (`params/fields/*.json`, or a shipped field's name).
    pub field: String,
    /// The lens's intrinsics (a ROS `camera_info` YAML file).
    pub intrinsics: String,
}

/// The window's contents.
pub fn calibration_ui(
    ui: &mut Ui,
    state: &Workspace,
    paths: &mut OverheadPaths,
    commands: &mut Vec<Command>,
) {
    let overhead = state.overhead();
    ui.label(overhead.calibration_status());
    files_ui(ui, state, paths, commands);
    ui.separator();
    view_options_ui(ui, state, commands);
    ui.separator();
    picking_ui(ui, state, commands);
    ui.separator();
    points_table_ui(ui, state);
}

fn path_row(
    ui: &mut Ui,
    label: &str,
    hint: &str,
    text: &mut String,
    buttons: &[(&str, bool)],
) -> Option<usize> {
    let mut clicked = None;
    // Wrapped: the docked window may be narrower than a row.
    ui.horizontal_wrapped(|ui| {
        let name = ui.label(label);
        ui.add(
            egui::TextEdit::singleline(text)
                .hint_text(hint)
                .desired_width(220.0),
        )
        .labelled_by(name.id);
        for (k, (name, enabled)) in buttons.iter().enumerate() {
            if ui
                .add_enabled(
                    *enabled && !text.trim().is_empty(),
                    egui::Button::new(*name),
                )
                .clicked()
            {
                clicked = Some(k);
            }
        }
    });
    clicked
}

fn files_ui(
    ui: &mut Ui,
    state: &Workspace,
    paths: &mut OverheadPaths,
    commands: &mut Vec<Command>,
) {
    let overhead = state.overhead();
    let path = |s: &str| PathBuf::from(s.trim());
    ui.label(format!("Field: {}", overhead.field().name));
    if path_row(
        ui,
        "field file or name",
        "spl-2020",
        &mut paths.field,
        &[("Open field", true)],
    ) == Some(0)
    {
        commands.push(OverheadCommand::OpenField(path(&paths.field)).into());
    }
    ui.label(match overhead.intrinsics() {
        Some((i, p)) => format!(
            "Intrinsics: {} ({}x{}, {}): Calibrate fits only the pose",
            p.display(),
            i.width_px,
            i.height_px,
            i.lens.ros_name()
        ),
        None => "Intrinsics: none (Calibrate fits the lens too)".to_owned(),
    });
    let has_intrinsics = overhead.intrinsics().is_some();
    if path_row(
        ui,
        "intrinsics",
        "camera_info.yaml or a recording",
        &mut paths.intrinsics,
        &[("Open intrinsics", true)],
    ) == Some(0)
    {
        commands.push(OverheadCommand::OpenIntrinsics(path(&paths.intrinsics)).into());
    }
    if has_intrinsics && ui.button("Close intrinsics").clicked() {
        commands.push(OverheadCommand::CloseIntrinsics.into());
    }
    let has_cal = overhead.calibration().is_some();
    match path_row(
        ui,
        "calibration",
        "camera.calibration.json",
        &mut paths.calibration,
        &[("Open calibration", true), ("Save calibration", has_cal)],
    ) {
        Some(0) => commands.push(OverheadCommand::OpenCalibration(path(&paths.calibration)).into()),
        Some(_) => commands.push(OverheadCommand::SaveCalibration(path(&paths.calibration)).into()),
        None => {}
    }
    if has_cal && ui.button("Close calibration").clicked() {
        commands.push(OverheadCommand::CloseCalibration.into());
    }
    let has_points = !overhead.points().points.is_empty();
    match path_row(
        ui,
        "points",
        "camera.points.json",
        &mut paths.points,
        &[("Open points", true), ("Save points", has_points)],
    ) {
        Some(0) => {
            commands.push(OverheadCommand::OpenPoints(path(&paths.points)).into());
        }
        Some(_) => {
            commands.push(OverheadCommand::SavePoints(path(&paths.points)).into());
        }
        None => {}
    }
}

/// The overhead view switches (also in the Overhead menu).
pub fn view_options_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let mut v: OverheadView = state.settings.overhead;
    let before = v;
    ui.horizontal(|ui| {
        ui.checkbox(&mut v.field_lines, "Field lines");
        ui.checkbox(&mut v.undistorted, "Undistorted");
        ui.checkbox(&mut v.points, "Picked points");
    });
    if v != before {
        commands.push(OverheadCommand::SetView(v).into());
    }
}

fn picking_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let overhead = state.overhead();
    let picked = |n: &str| overhead.points().points.iter().any(|p| p.name == n);
    let chosen = overhead.landmark().map(str::to_owned);
    // Wrapped: in the narrow dock column Undo pick and Calibrate go below the landmark.
    ui.horizontal_wrapped(|ui| {
        egui::ComboBox::from_label("pick landmark")
            .selected_text(chosen.clone().unwrap_or_else(|| "(not picking)".to_owned()))
            .width(200.0)
            .show_ui(ui, |ui| {
                if ui
                    .selectable_label(chosen.is_none(), "(not picking)")
                    .clicked()
                {
                    commands.push(OverheadCommand::ChooseLandmark(None).into());
                }
                for l in &overhead.field().landmarks {
                    let mark = if picked(&l.name) { " ✔" } else { "" };
                    let text = format!("{}{mark}", l.name);
                    if ui
                        .selectable_label(chosen.as_deref() == Some(l.name.as_str()), text)
                        .clicked()
                    {
                        commands.push(OverheadCommand::ChooseLandmark(Some(l.name.clone())).into());
                    }
                }
            });
        if ui
            .add_enabled(overhead.picks_to_undo() > 0, egui::Button::new("Undo pick"))
            .clicked()
        {
            commands.push(OverheadCommand::UndoPick.into());
        }
        let n = overhead.points().points.len();
        if ui
            .add_enabled(n >= MIN_CALIBRATION_POINTS, egui::Button::new("Calibrate"))
            .on_hover_text(format!(
                "at least {MIN_CALIBRATION_POINTS} points; refined along the frame's field lines"
            ))
            .clicked()
        {
            commands.push(OverheadCommand::Calibrate.into());
        }
    });
    if chosen.is_some() {
        ui.weak("Click the landmark in the image (left button); the next one is chosen after.");
    }
}

fn points_table_ui(ui: &mut Ui, state: &Workspace) {
    let overhead = state.overhead();
    let points = &overhead.points().points;
    if points.is_empty() {
        ui.weak("No points picked.");
        return;
    }
    let residuals = overhead
        .calibration()
        .map(|c| c.points.as_slice())
        .unwrap_or(&[]);
    egui::ScrollArea::vertical()
        .max_height(260.0)
        .show(ui, |ui| {
            egui::Grid::new("calibration-points")
                .striped(true)
                .num_columns(4)
                .show(ui, |ui| {
                    for h in ["landmark", "field (cm)", "image (px)", "error (px)"] {
                        ui.strong(h);
                    }
                    ui.end_row();
                    for p in points {
                        ui.label(&p.name);
                        ui.monospace(format!("{:7.1} {:7.1}", p.field_cm[0], p.field_cm[1]));
                        ui.monospace(format!("{:6.1} {:6.1}", p.image_px[0], p.image_px[1]));
                        match residuals.iter().find(|r| r.name == p.name) {
                            Some(r) => ui.monospace(format!("{:.2}", r.error_px)),
                            None => ui.weak("–"),
                        };
                        ui.end_row();
                    }
                });
        });
    if let Some(c) = overhead.calibration() {
        ui.label(format!(
            "median {:.2} px over {} points{}",
            c.median_point_error_px(),
            c.points.len(),
            c.line_rms_px
                .map(|r| format!("; lines {r:.2} px rms ({} samples)", c.line_samples))
                .unwrap_or_default()
        ));
    }
}
