//! Everything the UI can ask of the workspace, and the windows it can open.

use std::path::PathBuf;

use crate::sources::{SourceSettings, SourceSpec};

use super::overhead::RobotKey;
use super::robots::RobotId;
use super::settings::{OverheadView, Overlays, ViewKind};
use crate::blobs::Connectivity;
use crate::camera::CameraId;
use crate::lut::{ColourClass, Sensitivity};
use crate::recognition::ObjectId;

/// Everything the UI can ask for: a few commands that cross areas (open files, windows, the
/// selected object), the rest by area, each applied by its area's `apply_…`, which matches its
/// own enum exhaustively (a command no handler takes does not compile).
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Open files by kind: `.mcap` streams, frame files (as one sequence), `.json` recognition
    /// parameters or places (told by content), SSL-Vision sources (a league log `.log` or
    /// `.log.gz`, or `udp://GROUP:PORT`; shown in the field view), anything else as a table.
    /// Each file opens or fails on its own.
    Open(Vec<PathBuf>),
    /// Show another camera of the open recording or shown robot (one of
    /// [`crate::workspace::Workspace::cameras`]; `None`: the first): it is shown at the frame
    /// nearest the time shown, with that camera's table, parameters and calibration
    /// (remembered for it, else those the recording names). Reopening the recording opens on it.
    OpenCamera(Option<CameraId>),
    /// Show these cameras of the open recording or shown robot side by side, stepped together
    /// by time: each shows its frame nearest the shared cursor (the focused camera's frame
    /// time), classified with its own table, its own recognition drawn. The camera shown so
    /// far stays focused when listed. Fewer than two: one camera again (refused while a camera
    /// leaving the view has unsaved table edits). `workspace/side_by_side.rs`.
    ShowSideBySide(Vec<CameraId>),
    /// Make this camera (shown side by side) the focused one: hand classification, commit,
    /// undo, save, playback and the sensors window act on it and its own table.
    FocusCamera(CameraId),
    /// Open a lookup table.
    OpenTable(PathBuf),
    /// Open a places file (`eotn patterns learn`): pink markers are identified as its places.
    OpenPlaces(PathBuf),
    /// Forget the places file: pink markers keep their signatures, unidentified.
    ClosePlaces,
    /// Open a label set (a YOLO or Pascal VOC folder, a COCO JSON file) over the open frames:
    /// its boxes drawn by class, recognition scored against them, the missed and false frames
    /// as events (`workspace/labels.rs`).
    OpenLabels(PathBuf),
    /// Score the opened labels on these frames only: all, the tuning frames (numbers ending in
    /// 0–6) or the held-out ones (7–9), from the first frame again.
    SetLabelsSplit(crate::eval::label_sets::Split),
    /// Open or close a window.
    ShowWindow(Window, bool),
    /// Select a recognition candidate (the object its primitives belong to) to highlight its
    /// overlays; `None` shows all alike. Refused for an object not in the shown frame.
    SelectObject(Option<ObjectId>),
    /// The recognition parameters (`workspace/params.rs`): open, use the stream's set, tune, reset,
    /// save, try on the stream.
    Params(ParamsCommand),
    /// The lookup table (`workspace/table.rs`): new, save, the journal, the class and sensitivity,
    /// the pending selection, commit, undo and redo, the whole-stream try.
    Table(TableCommand),
    /// Moving through the source's frames (`workspace/playback.rs`).
    Playback(PlaybackCommand),
    /// How the frame is shown (`workspace/view.rs`): the enlarged view, overlays, blobs, zoom and
    /// pan, export.
    View(ViewCommand),
    /// The Camera menu's source (`workspace/live.rs`): connect, settings, grab, stream, record.
    Source(SourceCommand),
    /// Several live robots at once (`workspace/robots.rs`): connect, show, follow, record.
    Robots(RobotsCommand),
    /// What the table leaves unclassified, the pipeline's events and the user's bookmarks
    /// (`workspace/hints.rs`).
    Hints(HintsCommand),
    /// The overhead camera: calibration, picked points, robot selection, view options.
    Overhead(OverheadCommand),
    /// Show this step (capture time) of an SSL-Vision log opened without a stream
    /// (`workspace/ssl_feed.rs`).
    ShowSslStep(usize),
}

/// The recognition parameters (`workspace/params.rs`): open, use the stream's set, tune, reset,
/// save, try on the stream.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamsCommand {
    /// Open a recognition parameters file (`params/spl2009.json`): the frame is re-run with it.
    OpenParams(PathBuf),
    /// Use the parameter set the open stream names (the file found for it).
    UseOfferedParams,
    /// Back to the built-in default parameters.
    DefaultParams,
    /// Set one recognition parameter: `pointer` is a JSON pointer into the parameters
    /// (`/ball/diameter_cm`, `/ball/height_cm/0`), checked as a parameters file is.
    SetParamValue {
        /// Where the value is.
        pointer: String,
        /// The new value.
        value: serde_json::Value,
    },
    /// Reset one parameter (JSON pointer) to its value in the file opened or saved last.
    ResetParamValue(String),
    /// Reset every parameter to the file opened or saved last.
    ResetParams,
    /// Save the parameters (what differs from the defaults) as a parameters file.
    SaveParams(PathBuf),
    /// Start the whole-stream check of the tuned parameters against the opened ones.
    TryParamsOnStream,
}

impl From<ParamsCommand> for Command {
    fn from(c: ParamsCommand) -> Self {
        Self::Params(c)
    }
}

/// The lookup table (`workspace/table.rs`): new, save, the journal, the class and sensitivity, the
/// pending selection, commit, undo and redo, the whole-stream try.
#[derive(Debug, Clone, PartialEq)]
pub enum TableCommand {
    /// A new empty table with the given bits per channel.
    NewTable(u8),
    /// Save the table where it came from.
    SaveTable,
    /// Save the table under a new name (it becomes the table's path).
    SaveTableAs(PathBuf),
    /// Drop the table's unsaved edits (Quit without saving): they are undone, and the undoing
    /// journalled, so the journal replays to the saved table and the next start keeps the undo
    /// history (the dropped edits can be redone) instead of warning of a crash.
    DiscardUnsaved,
    /// Replace the table by replaying its journal.
    RebuildFromJournal,
    /// The class being defined.
    SetClass(ColourClass),
    /// Selection reach.
    SetSensitivity(Sensitivity),
    /// Change one channel's reach (0 = Y, 1 = U, 2 = V) by ± cells.
    AdjustSensitivity {
        /// 0 = Y, 1 = U, 2 = V.
        channel: usize,
        /// Cells to add (negative shrinks).
        delta: i32,
    },
    /// Select around the pixel at (x, y), image pixels: the preview, nothing written.
    Sample {
        /// Column, pixels.
        x: usize,
        /// Row, pixels.
        y: usize,
    },
    /// Select around a table cell (Y, U, V cell coordinates), as clicking the U–V plane.
    SampleCell([usize; 3]),
    /// Drop the pending selection.
    ClearSelection,
    /// Put back a pending selection as it was (the first click of a double-click sampled).
    RestoreSelection(Option<super::PendingSelection>),
    /// Write the pending selection into the table with the current class.
    Commit,
    /// Undo the latest edit.
    Undo,
    /// Redo the latest undone edit.
    Redo,
    /// Start the whole-stream check of the pending selection.
    TryEditOnStream,
}

impl From<TableCommand> for Command {
    fn from(c: TableCommand) -> Self {
        Self::Table(c)
    }
}

/// Moving through the source's frames (`workspace/playback.rs`).
#[derive(Debug, Clone, PartialEq)]
pub enum PlaybackCommand {
    /// Move by this many frames.
    Step(i64),
    /// Go to a frame.
    Seek(usize),
    /// Start or stop playback.
    SetPlaying(bool),
    /// Playback speed, × recorded rate (0 = every frame).
    SetSpeed(f32),
}

impl From<PlaybackCommand> for Command {
    fn from(c: PlaybackCommand) -> Self {
        Self::Playback(c)
    }
}

/// How the frame is shown (`workspace/view.rs`): the enlarged view, overlays, blobs, zoom and pan,
/// export.
#[derive(Debug, Clone, PartialEq)]
pub enum ViewCommand {
    /// Enlarge another view.
    SetMainView(ViewKind),
    /// Overlay switches.
    SetOverlays(Overlays),
    /// Blob connectivity.
    SetConnectivity(Connectivity),
    /// Which blobs get boxes and labels: at least `min_pixels` pixels, not of a `hidden` class.
    SetBlobFilter {
        /// Smallest blob drawn, pixels.
        min_pixels: u32,
        /// Classes whose blobs are not drawn.
        hidden: Vec<ColourClass>,
    },
    /// Zoom to a value (screen points per pixel), keeping the centre; `None` fits.
    SetZoom(Option<f32>),
    /// Zoom by `factor` keeping the image point `about` (pixels) where it is on screen.
    ZoomAbout {
        /// Multiplier of the current zoom.
        factor: f32,
        /// Image point that stays put, pixels.
        about: [f32; 2],
        /// The fitted zoom of the view, for when no zoom was set yet.
        fit: f32,
    },
    /// Move the view by image pixels (positive moves the image right/down).
    Pan([f32; 2]),
    /// Fit and centre.
    ResetView,
    /// Write the enlarged view with its overlays as a PNG.
    ExportView(PathBuf),
    /// The Y of the U–V plane.
    SetUvPlaneY(u8),
    /// Show or hide the frame-time readout.
    ShowTimings(bool),
}

impl From<ViewCommand> for Command {
    fn from(c: ViewCommand) -> Self {
        Self::View(c)
    }
}

/// The Camera menu's source (`workspace/live.rs`): connect, settings, grab, stream, record.
#[derive(Debug, Clone, PartialEq)]
pub enum SourceCommand {
    /// Connect a source (Camera ▸ Connect…): a recorded one opens for stepping, a live one
    /// streams on its own thread; what was connected before is disconnected.
    Connect(SourceSpec),
    /// Disconnect the live source or close the recorded one.
    Disconnect,
    /// Ask the live source for other settings (resolution, frame rate, exposure, gain).
    SetSourceSettings(SourceSettings),
    /// One new image: a live source stops streaming and grabs one; a recorded one steps on.
    GrabImage,
    /// Stream the live source at its rate again (true) or hold it (false).
    SetStreaming(bool),
    /// Record what the connected source delivers into this MCAP stream.
    StartRecording(PathBuf),
    /// Finish the recording.
    StopRecording,
}

impl From<SourceCommand> for Command {
    fn from(c: SourceCommand) -> Self {
        Self::Source(c)
    }
}

/// Several live robots at once (`workspace/robots.rs`): connect, show, follow, record.
#[derive(Debug, Clone, PartialEq)]
pub enum RobotsCommand {
    /// Connect a robot at `HOST:PORT` (or `ws://HOST:PORT`) beside those connected already
    /// (Camera ▸ Connect to robot…); shown when no robot is.
    ConnectRobot(String),
    /// Show this robot in the views, following its newest frame; the others keep receiving.
    ShowRobot(RobotId),
    /// Disconnect this robot, finishing its recording.
    DisconnectRobot(RobotId),
    /// Record this robot, bit-exact, into this MCAP stream.
    RecordRobot(RobotId, PathBuf),
    /// Record every robot not recording yet into this folder, one file per robot.
    RecordAllRobots(PathBuf),
    /// Finish this robot's recording.
    StopRecordingRobot(RobotId),
    /// Follow the shown robot's newest frame (true) or hold the view where it is (false);
    /// reception and recording go on either way.
    SetFollowLive(bool),
}

impl From<RobotsCommand> for Command {
    fn from(c: RobotsCommand) -> Self {
        Self::Robots(c)
    }
}

/// What the table leaves unclassified, the pipeline's events and the user's bookmarks
/// (`workspace/hints.rs`).
#[derive(Debug, Clone, PartialEq)]
pub enum HintsCommand {
    /// Count the colours the table leaves unclassified over frames `first..=last` (clamped to
    /// the source), a few frames per UI frame: the coverage hints.
    FindUnclassified {
        /// First frame.
        first: usize,
        /// Last frame (inclusive).
        last: usize,
    },
    /// Select these table cells (by index), as clicking a coverage hint: the preview, nothing
    /// written until a Commit.
    SelectCells(Vec<usize>),
    /// Order the coverage hints afresh by their unclassified pixels (after commits a hint
    /// keeps its row until this).
    RankHints,
    /// Run the pipeline over the whole source for its events (ball found or lost, goal
    /// appears, warnings), a few frames per UI frame.
    FindEvents,
    /// Bookmark the shown frame with a note (replacing one there), saved beside the stream.
    AddBookmark(String),
    /// Remove the bookmark at this frame.
    RemoveBookmark(usize),
    /// Go to the next (or previous) mark: an event or a bookmark.
    JumpToMark {
        /// Next when true, previous when false.
        forward: bool,
    },
}

impl From<HintsCommand> for Command {
    fn from(c: HintsCommand) -> Self {
        Self::Hints(c)
    }
}

impl From<OverheadCommand> for Command {
    fn from(c: OverheadCommand) -> Self {
        Self::Overhead(c)
    }
}

/// What the UI can ask of the overhead camera's side (`workspace/overhead.rs`).
#[derive(Debug, Clone, PartialEq)]
pub enum OverheadCommand {
    /// Use this calibration file (`eotn overhead calibrate` writes them).
    OpenCalibration(PathBuf),
    /// Save the calibration in use (opened or solved here) as this file.
    SaveCalibration(PathBuf),
    /// Forget the opened or solved calibration: the stream's own camera, if any, is used.
    CloseCalibration,
    /// Use this field description: a file (`params/fields/`) or a shipped field's name
    /// (`spl-2020`, …).
    OpenField(PathBuf),
    /// Use the lens's checkerboard intrinsics (a ROS `camera_info` YAML file): Calibrate then
    /// fits only the camera's pose.
    OpenIntrinsics(PathBuf),
    /// Forget the intrinsics: Calibrate fits the lens too.
    CloseIntrinsics,
    /// Open a points file (`*.points.json`) to go on picking or to calibrate from.
    OpenPoints(PathBuf),
    /// Save the picked points as a points file.
    SavePoints(PathBuf),
    /// The landmark (by its name in the field description) the next image click picks.
    ChooseLandmark(Option<String>),
    /// Pick the chosen landmark at this point of the camera's image (pixels, not undistorted).
    PickPoint {
        /// Column, pixels (pixel centres at +0.5).
        x_px: f64,
        /// Row, pixels.
        y_px: f64,
    },
    /// Leave the chosen landmark unpicked (not in view) and choose the next one not picked.
    SkipLandmark,
    /// Undo the latest pick.
    UndoPick,
    /// Solve the camera from the picked points, refined along the frame's field lines.
    Calibrate,
    /// Frame files (JPEG, PNG, …) come from an overhead camera (`true`) or a robot's: the
    /// overhead recogniser and the overhead table are used for them. Streams say it themselves.
    SetOverheadCamera(bool),
    /// Select a robot in every view (`None` clears); its camera, when the session has it, is
    /// shown beside the overhead camera (`workspace/wmd.rs`).
    SelectRobot(Option<RobotKey>),
    /// Arrange the World Model Debugger layout: the overhead view, the field view and the
    /// robots list (applied by itself when a session file or a recorded session opens).
    WmdLayout,
    /// Overhead view options.
    SetView(OverheadView),
    /// Send each processed overhead frame's detections as SSL-Vision packets to `HOST:PORT`
    /// (and the geometry every few seconds), or stop (`None`): `workspace/ssl_out.rs`.
    SendSslVision(Option<String>),
}

/// The app's extra windows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Window {
    /// Sensor readings and plots.
    Sensors,
    /// The U–V plane of the table.
    UvPlane,
    /// The whole-stream check of a pending edit.
    TryEdit,
    /// Every recognition candidate with its confidence breakdown.
    Inspector,
    /// Camera ▸ Connect…: pick a source.
    Connect,
    /// Camera ▸ Settings…: the live source's settings.
    SourceSettings,
    /// Camera ▸ Start recording…: name the stream.
    Record,
    /// The overhead camera's field view: ball, robots, world models.
    FieldView,
    /// Overhead calibration: pick landmarks, solve, reprojection errors.
    Calibration,
    /// Camera ▸ Connect to robot…: the robots list.
    Robots,
    /// The colours the table leaves unclassified (coverage hints).
    Coverage,
    /// Events and bookmarks on the timeline.
    Bookmarks,
    /// The recognition parameters: tune, reset, save.
    Parameters,
}

impl Window {
    /// Every window, for the Windows menu.
    pub const ALL: [Self; 10] = [
        Self::Sensors,
        Self::UvPlane,
        Self::TryEdit,
        Self::Inspector,
        Self::FieldView,
        Self::Calibration,
        Self::Robots,
        Self::Coverage,
        Self::Bookmarks,
        Self::Parameters,
    ];

    /// Its title.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Sensors => "Sensors",
            Self::UvPlane => "U–V plane",
            Self::TryEdit => "Try edit on stream",
            Self::Inspector => "Object inspector",
            Self::Connect => "Connect a source",
            Self::SourceSettings => "Source settings",
            Self::Record => "Record into a stream",
            Self::FieldView => "Field view",
            Self::Calibration => "Overhead calibration",
            Self::Robots => "Robots",
            Self::Coverage => "Unclassified colours",
            Self::Bookmarks => "Events and bookmarks",
            Self::Parameters => "Parameters",
        }
    }
}
