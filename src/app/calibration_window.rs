//! The overhead calibration window: the field description, the calibration file (open, save,
//! close), picking points — choose a landmark by name, click it in the image (the next one not
//! yet picked is chosen after each click), undo —, Calibrate, and the reprojection error of
//! each point in a table. File names are typed (native dialogs are not always available).

use std::path::PathBuf;

use egui::Ui;

use super::file_dialog::FileAction;
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
    /// Where SSL-Vision packets go (`HOST:PORT`; empty: the league's group).
    pub ssl_vision: String,
}

/// A file dialog a window asks for: what for, and the file name a save suggests.
pub type DialogRequest = Option<(FileAction, Option<String>)>;

/// The window's contents.
pub fn calibration_ui(
    ui: &mut Ui,
    state: &Workspace,
    paths: &mut OverheadPaths,
    commands: &mut Vec<Command>,
    dialog: &mut DialogRequest,
) {
    let overhead = state.overhead();
    ui.label(overhead.calibration_status());
    files_ui(ui, state, paths, commands, dialog);
    ui.separator();
    view_options_ui(ui, state, commands);
    ui.separator();
    picking_ui(ui, state, commands);
    ui.separator();
    points_table_ui(ui, state);
    ui.separator();
    ssl_vision_ui(ui, state, &mut paths.ssl_vision, commands);
}

/// Sending the detections as SSL-Vision packets: the address, the switch, what was sent and
/// the last error (the workspace sends: `workspace/ssl_out.rs`).
fn ssl_vision_ui(
    ui: &mut Ui,
    state: &Workspace,
    address: &mut String,
    commands: &mut Vec<Command>,
) {
    let status = state.ssl_out_status();
    ui.horizontal_wrapped(|ui| {
        let mut sending = status.is_some();
        let name = ui.label("SSL-Vision to");
        ui.add_enabled(
            !sending,
            egui::TextEdit::singleline(address)
                .hint_text(crate::ssl_vision::LEAGUE_ADDRESS)
                .desired_width(160.0),
        )
        .labelled_by(name.id);
        let toggle = ui.checkbox(&mut sending, "Send SSL-Vision").on_hover_text(
            "send each overhead frame's ball and robots as SSL-Vision packets over UDP \
                 (camera 0), and the field and calibration every few seconds, for any Small \
                 Size League team's software",
        );
        if toggle.changed() {
            let typed = address.trim();
            let target = if typed.is_empty() {
                crate::ssl_vision::LEAGUE_ADDRESS
            } else {
                typed
            };
            commands
                .push(OverheadCommand::SendSslVision(sending.then(|| target.to_owned())).into());
        }
    });
    if let Some(s) = status {
        ui.label(format!(
            "sending to {}: {} detection and {} geometry packets",
            s.address, s.detection_packets, s.geometry_packets
        ));
        if let Some(e) = &s.last_error {
            ui.colored_label(
                ui.visuals().warn_fg_color,
                format!("{} sends failed; the last: {e}", s.failures),
            );
        }
    }
}

/// One button of a [`path_row`]: its text, whether it can be used, and the file dialog it
/// opens when no path is typed (`None`: it needs a typed path).
type PathButton<'a> = (&'a str, bool, Option<FileAction>);

/// A typed path and its buttons; returns the button clicked. A button with a dialog stays
/// usable with no path typed (the dialog asks for one); one without says what it needs.
fn path_row(
    ui: &mut Ui,
    label: &str,
    hint: &str,
    text: &mut String,
    buttons: &[PathButton<'_>],
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
        let empty = text.trim().is_empty();
        for (k, (name, enabled, dialog)) in buttons.iter().enumerate() {
            let usable = *enabled && (!empty || dialog.is_some());
            let button = ui.add_enabled(usable, egui::Button::new(*name));
            let button = if empty && dialog.is_some() {
                button.on_hover_text("no file typed: choose one in a dialog")
            } else {
                button.on_disabled_hover_text(if empty {
                    format!("type the {label} first")
                } else {
                    "nothing to save yet".to_owned()
                })
            };
            if button.clicked() {
                clicked = Some(k);
            }
        }
    });
    clicked
}

/// What a [`path_row`] button does: its command with the typed path, or with none typed the
/// dialog that asks for one.
fn path_action(
    text: &str,
    dialog_action: FileAction,
    suggested: &str,
    command: impl FnOnce(PathBuf) -> Command,
    commands: &mut Vec<Command>,
    dialog: &mut DialogRequest,
) {
    let typed = text.trim();
    if typed.is_empty() {
        let name = dialog_action_saves(dialog_action).then(|| suggested.to_owned());
        *dialog = Some((dialog_action, name));
    } else {
        commands.push(command(PathBuf::from(typed)));
    }
}

const fn dialog_action_saves(a: FileAction) -> bool {
    matches!(a, FileAction::SaveCalibration | FileAction::SavePoints)
}

fn files_ui(
    ui: &mut Ui,
    state: &Workspace,
    paths: &mut OverheadPaths,
    commands: &mut Vec<Command>,
    dialog: &mut DialogRequest,
) {
    let overhead = state.overhead();
    let path = |s: &str| PathBuf::from(s.trim());
    ui.label(format!("Field: {}", overhead.field().name));
    if path_row(
        ui,
        "field file or name",
        "spl-2020",
        &mut paths.field,
        &[("Open field", true, None)],
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
        &[("Open intrinsics", true, None)],
    ) == Some(0)
    {
        commands.push(OverheadCommand::OpenIntrinsics(path(&paths.intrinsics)).into());
    }
    if has_intrinsics && ui.button("Close intrinsics").clicked() {
        commands.push(OverheadCommand::CloseIntrinsics.into());
    }
    saved_files_ui(ui, state, paths, commands, dialog);
}

/// The calibration and the points files: open, save (a dialog when no name is typed), close.
fn saved_files_ui(
    ui: &mut Ui,
    state: &Workspace,
    paths: &mut OverheadPaths,
    commands: &mut Vec<Command>,
    dialog: &mut DialogRequest,
) {
    let overhead = state.overhead();
    let has_cal = overhead.calibration().is_some();
    let clicked = path_row(
        ui,
        "calibration",
        "camera.calibration.json",
        &mut paths.calibration,
        &[
            ("Open calibration", true, Some(FileAction::OpenCalibration)),
            (
                "Save calibration",
                has_cal,
                Some(FileAction::SaveCalibration),
            ),
        ],
    );
    match clicked {
        Some(0) => path_action(
            &paths.calibration,
            FileAction::OpenCalibration,
            "",
            |p| OverheadCommand::OpenCalibration(p).into(),
            commands,
            dialog,
        ),
        Some(_) => path_action(
            &paths.calibration,
            FileAction::SaveCalibration,
            "camera.calibration.json",
            |p| OverheadCommand::SaveCalibration(p).into(),
            commands,
            dialog,
        ),
        None => {}
    }
    if has_cal && ui.button("Close calibration").clicked() {
        commands.push(OverheadCommand::CloseCalibration.into());
    }
    let has_points = !overhead.points().points.is_empty();
    let clicked = path_row(
        ui,
        "points",
        "camera.points.json",
        &mut paths.points,
        &[
            ("Open points", true, Some(FileAction::OpenPoints)),
            ("Save points", has_points, Some(FileAction::SavePoints)),
        ],
    );
    match clicked {
        Some(0) => path_action(
            &paths.points,
            FileAction::OpenPoints,
            "",
            |p| OverheadCommand::OpenPoints(p).into(),
            commands,
            dialog,
        ),
        Some(_) => path_action(
            &paths.points,
            FileAction::SavePoints,
            "camera.points.json",
            |p| OverheadCommand::SavePoints(p).into(),
            commands,
            dialog,
        ),
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
            .add_enabled(chosen.is_some(), egui::Button::new("Skip"))
            .on_hover_text("not visible in this frame: go on to the next landmark not picked")
            .clicked()
        {
            commands.push(OverheadCommand::SkipLandmark.into());
        }
        if ui
            .add_enabled(chosen.is_some(), egui::Button::new("Stop picking"))
            .on_hover_text("a left click in the image samples colours again")
            .clicked()
        {
            commands.push(OverheadCommand::ChooseLandmark(None).into());
        }
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
    match &chosen {
        Some(l) => ui.label(format!(
            "Picking: a left click in the image places {l}; the next landmark not picked follows \
             (Skip one that is not in view). Calibrate, Stop picking or choosing a class ends it."
        )),
        None => ui.weak("Not picking: a left click in the image samples colours."),
    };
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
