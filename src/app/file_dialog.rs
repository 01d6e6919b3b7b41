//! File dialogs drawn by the app itself (`egui_file`), so File ▸ Open… and Save as… work
//! everywhere: native dialogs need a desktop portal that bare X servers, Xvfb and many tiling
//! desktops lack (they returned nothing, silently). File ▸ Open path… stays for typing a path.

use std::path::{Path, PathBuf};

use egui_file::{FileDialog, State};

use crate::workspace::{
    Command, OverheadCommand, ParamsCommand, SourceCommand, TableCommand, ViewCommand,
};

/// What a dialog is for; it decides the title, the filter and the command sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileAction {
    /// A stream, frames or anything Open takes.
    Open,
    /// A lookup table.
    OpenTable,
    /// Recognition parameters.
    OpenParams,
    /// A places file.
    OpenPlaces,
    /// A label set kept as a folder (YOLO, Pascal VOC) over the open frames.
    OpenLabelsFolder,
    /// A label set kept as one file (COCO JSON) over the open frames.
    OpenLabelsFile,
    /// Save the table under a new name.
    SaveTableAs,
    /// Save the recognition parameters.
    SaveParams,
    /// Export the enlarged view as PNG.
    ExportView,
    /// Record the connected source into a new stream.
    Record,
    /// An overhead calibration (`*.json`).
    OpenCalibration,
    /// Save the overhead calibration.
    SaveCalibration,
    /// Picked calibration points (`*.points.json`).
    OpenPoints,
    /// Save the picked calibration points.
    SavePoints,
}

impl FileAction {
    /// The dialog's title.
    #[must_use]
    pub const fn title(self) -> &'static str {
        match self {
            Self::Open => "Open a stream, frames, a table or parameters",
            Self::OpenTable => "Open a lookup table",
            Self::OpenParams => "Open recognition parameters",
            Self::OpenPlaces => "Open a places file",
            Self::OpenLabelsFolder => "Open labels: a YOLO or Pascal VOC folder",
            Self::OpenLabelsFile => "Open labels: a COCO JSON file",
            Self::SaveTableAs => "Save the lookup table as",
            Self::SaveParams => "Save the recognition parameters as",
            Self::ExportView => "Export the view as PNG",
            Self::Record => "Record into",
            Self::OpenCalibration => "Open an overhead calibration",
            Self::SaveCalibration => "Save the overhead calibration as",
            Self::OpenPoints => "Open picked calibration points",
            Self::SavePoints => "Save the picked calibration points as",
        }
    }

    /// File name endings shown (folders always are); empty shows every file.
    #[must_use]
    pub const fn extensions(self) -> &'static [&'static str] {
        match self {
            Self::Open | Self::OpenLabelsFolder => &[],
            Self::OpenTable | Self::SaveTableAs => &["lut", "cal", "raw", "tm", "col"],
            Self::OpenParams
            | Self::OpenPlaces
            | Self::SaveParams
            | Self::OpenLabelsFile
            | Self::OpenCalibration
            | Self::SaveCalibration
            | Self::OpenPoints
            | Self::SavePoints => &["json"],
            Self::ExportView => &["png"],
            Self::Record => &["mcap"],
        }
    }

    const fn saves(self) -> bool {
        matches!(
            self,
            Self::SaveTableAs
                | Self::SaveParams
                | Self::ExportView
                | Self::Record
                | Self::SaveCalibration
                | Self::SavePoints
        )
    }

    /// The command for the chosen path.
    #[must_use]
    pub fn command(self, path: PathBuf) -> Command {
        match self {
            Self::Open => Command::Open(vec![path]),
            Self::OpenTable => Command::OpenTable(path),
            Self::OpenParams => Command::Params(ParamsCommand::OpenParams(path)),
            Self::OpenPlaces => Command::OpenPlaces(path),
            Self::OpenLabelsFolder | Self::OpenLabelsFile => Command::OpenLabels(path),
            Self::SaveTableAs => Command::Table(TableCommand::SaveTableAs(path)),
            Self::SaveParams => Command::Params(ParamsCommand::SaveParams(path)),
            Self::ExportView => Command::View(ViewCommand::ExportView(path)),
            Self::Record => Command::Source(SourceCommand::StartRecording(path)),
            Self::OpenCalibration => Command::Overhead(OverheadCommand::OpenCalibration(path)),
            Self::SaveCalibration => Command::Overhead(OverheadCommand::SaveCalibration(path)),
            Self::OpenPoints => Command::Overhead(OverheadCommand::OpenPoints(path)),
            Self::SavePoints => Command::Overhead(OverheadCommand::SavePoints(path)),
        }
    }
}

/// The dialog shown, if any.
#[derive(Default)]
pub struct FileDialogs {
    shown: Option<(FileAction, FileDialog)>,
}

impl std::fmt::Debug for FileDialogs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FileDialogs")
            .field("shown", &self.shown.as_ref().map(|(a, _)| *a))
            .finish()
    }
}

impl FileDialogs {
    /// Which dialog is shown.
    #[must_use]
    pub fn shown(&self) -> Option<FileAction> {
        self.shown.as_ref().map(|(a, _)| *a)
    }

    /// Opens the dialog for `action` in `folder` (the current folder when `None`), with
    /// `file_name` filled in for a save.
    pub fn open(&mut self, action: FileAction, folder: Option<&Path>, file_name: Option<String>) {
        let mut d = if action.saves() {
            FileDialog::save_file()
        } else if action == FileAction::OpenLabelsFolder {
            FileDialog::select_folder()
        } else {
            FileDialog::open_file()
        };
        d = d
            .title(action.title())
            .show_rename(false)
            .show_new_folder(action.saves());
        if let Some(f) = folder.filter(|f| f.is_dir()) {
            d = d.initial_path(f);
        }
        if let Some(name) = file_name {
            d = d.default_filename(name);
        }
        let exts = action.extensions();
        if !exts.is_empty() {
            d = d.show_files_filter(Box::new(move |p: &Path| {
                p.extension()
                    .and_then(|e| e.to_str())
                    .is_some_and(|e| exts.iter().any(|x| x.eq_ignore_ascii_case(e)))
            }));
        }
        d.open();
        self.shown = Some((action, d));
    }

    /// Draws the shown dialog; a chosen file becomes its command.
    pub fn show(&mut self, ctx: &egui::Context, commands: &mut Vec<Command>) {
        let Some((action, dialog)) = self.shown.as_mut() else {
            return;
        };
        match dialog.show(ctx).state() {
            State::Open => {}
            State::Selected => {
                if let Some(p) = dialog.path() {
                    commands.push(action.command(p.to_owned()));
                }
                self.shown = None;
            }
            State::Closed | State::Cancelled => self.shown = None,
        }
    }
}
