//! The workspace: everything the app, the CLI and the tests share that is not a widget — the open
//! table with its edit history and journal, the open frame source and its cache, the pipeline's
//! results on the shown frame, the pending selection and its whole-stream try, playback, zoom and
//! pan, settings. The UI reads it and sends [`Command`]s; [`Workspace::apply`] is the one place
//! they change anything, so the kittest tests and the real window go through the same path. It
//! builds without the `gui` feature.
//!
//! | file | role |
//! |---|---|
//! | `mod.rs` | [`Workspace`]: its fields, [`Workspace::apply`] (it hands each area's enum to that area's `apply_…`, which matches it exhaustively), what the UI reads |
//! | `command.rs` | [`Command`]: everything the UI can ask for, nested by area ([`TableCommand`], [`PlaybackCommand`], [`ViewCommand`], [`SourceCommand`], [`RobotsCommand`], [`ParamsCommand`], [`HintsCommand`], [`OverheadCommand`]; `From` each into `Command`); [`Window`] |
//! | `settings.rs` | [`Settings`] that persist; [`ViewKind`], [`Overlays`], [`ViewTransform`] |
//! | `source.rs` | [`Source`]: the open recorded source with a cache of decoded frames |
//! | `frames.rs` | opening sources, showing a frame, the sensor-series scan |
//! | `player.rs` | [`Player`]: playback clock, `tick`, `next_frame_due` |
//! | `playback.rs` | the Step/Seek/Play/Speed commands, [`Workspace::tick`] (playback and background scans), [`Workspace::next_frame_due`], frame-time records |
//! | `view.rs` | view options (enlarged view, overlays, blob filter, zoom, pan, Export view) and which windows are open |
//! | `live.rs` | [`Live`]: a connected live source streaming on its thread; recording; the Camera menu's commands |
//! | `robots.rs` | robots over the network, several at once: the list, the shown one, following live, recording each |
//! | `table.rs` | the table: its commands (open, save, class, sensitivity, selection, commit, undo/redo, journal, try on the stream), places file; one table per camera kind |
//! | `journal.rs` | the edit journal beside a table: append, replay |
//! | `try_edit.rs`, `stream_scan.rs` | [`TryEdit`]: the frames a pending edit would change; [`StreamScan`]: the whole-stream checks' one loop, a few frames per UI frame |
//! | `coverage.rs`, `cell_origin.rs`, `bookmarks.rs`, `hints.rs` | what is unclassified, who set a cell, events and bookmarks |
//! | `labels.rs` | [`OpenLabels`]: a boxed label set over the open frames, scored; its missed and false frames as events |
//! | `params.rs` | recognition parameters: open, tune, reset, save, the set a stream names, [`params::TryParams`] |
//! | `compose.rs`, `timings.rs` | the enlarged view as RGB (Export view), [`PrimitiveFilter`]; step and frame-time measurements |
//! | `overhead.rs` | [`Overhead`]: an overhead source's frames through the overhead pipeline, calibration, picked points, robot selection |
//! | `cameras.rs` | the camera shown of a recording with several (`Command::OpenCamera`) and each camera's own table |
//! | `side_by_side.rs` | several cameras side by side, stepped together by time, each with its own table, pipeline and results; the focused one gets the clicks |
//! | `field_model.rs`, `wmd.rs` | the field view's model: trails, world models beside the overhead truth, errors over time and their spreads and jumps, SSL-Vision's detections by camera; the World Model Debugger's robot cameras shown beside the overhead camera, world models on the overhead image, the WMD layout |
//! | `ssl_feed.rs`, `ssl_out.rs` | [`SslFeed`]: SSL-Vision's detections opened beside the frames (a league log, paired by capture time, or a live address); sending the processed overhead frames' detections as SSL-Vision packets (`OverheadCommand::SendSslVision`, [`ssl_out::SslOutStatus`] for the UI) |

pub mod bookmarks;
mod cameras;
pub mod cell_origin;
mod command;
mod compose;
pub mod coverage;
pub mod field_model;
mod frames;
mod hints;
pub mod journal;
mod labels;
mod live;
pub mod overhead;
pub mod params;
mod playback;
pub mod player;
mod robots;
mod settings;
mod shown_rgb;
mod side_by_side;
pub mod source;
mod ssl_feed;
pub mod ssl_out;
mod stream_scan;
mod table;
mod timings;
mod try_edit;
mod view;
pub mod wmd;

use std::path::{Path, PathBuf};
use std::time::Duration;

pub use command::{
    Command, HintsCommand, OverheadCommand, ParamsCommand, PlaybackCommand, RobotsCommand,
    SourceCommand, TableCommand, ViewCommand, Window,
};
pub use compose::{PreviewPixel, PrimitiveFilter, box_colour, hatch_rgb, visible_preview_rgb};
pub use labels::OpenLabels;
pub use live::Live;
pub use overhead::{CalibrationSource, Overhead, RobotKey};
pub use params::{ParamsOffer, ParamsSlot, TryParams, TryParamsRow};
pub use player::Player;
pub use robots::{RobotId, RobotRow, Wake};
pub use settings::{
    MAX_RECENT, MAX_WARNINGS, OverheadView, Overlays, SETTINGS_FILE_NAME, SPEEDS, Settings,
    ViewKind, ViewTransform, ZOOM_PRESETS, ZOOM_RANGE,
};
pub use side_by_side::CameraPane;
pub use source::Source;
pub use ssl_feed::SslFeed;
pub use stream_scan::StreamScan;
pub use table::TableSlot;
pub use timings::{StepTiming, Timings, median};
pub use try_edit::{TryEdit, TryEditRow};

use crate::blobs::{Blob, BlobSet};
use crate::camera::CameraId;
use crate::classify::ClassifiedImage;
use crate::frame::{Frame, Yuv, yuv_to_rgb};
use crate::lut::edit::Selection;
use crate::lut::{ColourClass, EditHistory, LookupTable, Region};
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::{Primitive, Recognition};
use crate::sensors::SensorReadings;
use crate::sources::{CameraKind, Recorder, SourceFrame};

/// Time per UI frame a whole-stream scan may take, so the window stays responsive.
const SCAN_BUDGET: Duration = Duration::from_millis(12);

/// What hovering a pixel shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelInfo {
    /// Column, pixels.
    pub x: usize,
    /// Row, pixels.
    pub y: usize,
    /// The camera's value.
    pub yuv: Yuv,
    /// Its display colour.
    pub rgb: [u8; 3],
    /// The table's class.
    pub class: ColourClass,
    /// The blob it belongs to.
    pub blob: Option<Blob>,
    /// Where the pixel's centre lies on the field (on the ground), centimetres `[x, y]`:
    /// for an overhead frame with a calibration in use.
    pub field_cm: Option<[f64; 2]>,
}

/// A pending (previewed, unwritten) selection.
#[derive(Debug, Clone, PartialEq)]
pub struct PendingSelection {
    /// The cells.
    pub region: Region,
    /// The pixel it was made from, if any.
    pub pixel: Option<(usize, usize)>,
    /// Which class a commit writes.
    pub class: SelectionClass,
}

/// Which class a pending selection commits as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SelectionClass {
    /// The class chosen in the Classify panel (a sampled pixel, a U–V plane cell).
    Current,
    /// A class chosen for this selection (a coverage hint's colours, after Commit as…).
    Chosen(ColourClass),
    /// None yet: a coverage hint's colours are nobody's class until one is chosen for them
    /// (committing them in whatever class happened to be selected turned a wall orange), so
    /// a commit is refused and the preview is neutral.
    Unchosen,
}

/// Sensor readings of every frame of the stream, filled a few frames per UI frame.
#[derive(Debug, Clone, Default)]
pub struct SensorSeries {
    /// (time in seconds, readings) per frame read so far, in frame order.
    pub points: Vec<(f64, Option<SensorReadings>)>,
    /// The numeric readings of other channels ([`crate::sensors::channel_readings`]: joint
    /// positions of a ROS `JointState`, …), keyed `"topic name"` (`"/joint_states HeadYaw"`):
    /// (time in seconds, value) of the frames read so far that carry it.
    pub channels: std::collections::BTreeMap<String, Vec<[f64; 2]>>,
    /// Frames in the source.
    pub total: usize,
}

/// The workspace; see the module documentation.
#[derive(Debug)]
pub struct Workspace {
    /// Persisted settings.
    pub settings: Settings,
    pipeline: Pipeline,
    table_path: Option<PathBuf>,
    history: EditHistory,
    dirty: bool,
    source: Option<Source>,
    /// The camera last picked (the camera picker, a pane focused): its recording reopens on it.
    camera: Option<CameraId>,
    /// The camera (image topic) other recordings open on (`eotn open --camera`); `None`: each
    /// recording's first.
    open_topic: Option<String>,
    index: usize,
    current: Option<SourceFrame>,
    rgb: shown_rgb::ShownRgb,
    selection: Option<PendingSelection>,
    preview_mask: Vec<bool>,
    warnings: Vec<String>,
    /// The last message for the status line (what the last command did).
    pub status: String,
    frame_generation: u64,
    preview_generation: u64,
    table_generation: u64,
    player: Player,
    /// Measurements.
    pub timings: Timings,
    /// The sensor series of the open stream.
    pub sensor_series: SensorSeries,
    try_edit: Option<TryEdit>,
    places_path: Option<PathBuf>,
    table_counts: crate::lut::ClassCounts,
    frame_counts: [usize; 256],
    primitives: Vec<Primitive>,
    accepted_owners: Vec<crate::recognition::ObjectId>,
    selected_object: Option<crate::recognition::ObjectId>,
    live: Option<Live>,
    /// Robots over the network, one of them perhaps shown.
    robots: robots::Robots,
    /// Recording a recorded source's shown frames (a live source records on its thread).
    recorder: Option<Recorder>,
    /// Which camera's table the pipeline holds.
    table_kind: CameraKind,
    /// The other camera's table.
    other_table: TableSlot,
    /// The overhead camera's pipeline, calibration, picked points and selection.
    overhead: overhead::Overhead,
    /// Coverage hints, events and bookmarks.
    hints: hints::Hints,
    /// A label set opened over the source (`eotn open FOLDER --labels LABELS`), its scoring.
    labels: Option<labels::OpenLabels>,
    /// The recognition parameters' file, the loaded values, the stream's offer.
    params: ParamsSlot,
    /// The other cameras shown side by side with the focused one (empty: one camera shown).
    beside: side_by_side::SideBySide,
    /// Edits in the undo history when the table was last opened or saved (`None` when that
    /// state can no longer be reached by undoing).
    saved_undo_len: Option<usize>,
    /// A table without a file yet (new, or made in this session): the table it started from and
    /// the journal entries since, written as its journal when it is first saved, so the journal
    /// records from the table's first commit (`None` once the table has a file).
    unsaved_journal: Option<(LookupTable, Vec<journal::JournalEntry>)>,
    /// SSL-Vision's detections opened beside the frames (a league log or a live address).
    ssl_vision: Option<ssl_feed::SslFeed>,
}

impl Default for Workspace {
    fn default() -> Self {
        Self::new(Settings::default())
    }
}

impl Workspace {
    /// A workspace with these settings, an empty table of their bits and nothing open.
    #[must_use]
    pub fn new(settings: Settings) -> Self {
        let bits = if (6..=8).contains(&settings.new_table_bits) {
            settings.new_table_bits
        } else {
            7
        };
        let lut = LookupTable::new(bits).unwrap_or_else(|_| seven_bit_table());
        let params = PipelineParams {
            connectivity: settings.connectivity,
            ..PipelineParams::default()
        };
        let table_counts = lut.class_counts();
        let unsaved_journal = Some((lut.clone(), Vec::new()));
        Self {
            settings,
            pipeline: Pipeline::new(lut, params),
            table_path: None,
            history: EditHistory::default(),
            dirty: false,
            source: None,
            camera: None,
            open_topic: None,
            index: 0,
            current: None,
            rgb: shown_rgb::ShownRgb::default(),
            selection: None,
            preview_mask: Vec::new(),
            warnings: Vec::new(),
            status: String::new(),
            frame_generation: 0,
            preview_generation: 0,
            table_generation: 0,
            player: Player::default(),
            timings: Timings::default(),
            sensor_series: SensorSeries::default(),
            try_edit: None,
            places_path: None,
            table_counts,
            frame_counts: [0; 256],
            primitives: Vec::new(),
            accepted_owners: Vec::new(),
            selected_object: None,
            live: None,
            robots: robots::Robots::default(),
            recorder: None,
            table_kind: CameraKind::Robot,
            other_table: TableSlot::empty(bits),
            overhead: overhead::Overhead::default(),
            hints: hints::Hints::default(),
            labels: None,
            params: ParamsSlot::default(),
            beside: side_by_side::SideBySide::default(),
            saved_undo_len: Some(0),
            unsaved_journal,
            ssl_vision: None,
        }
    }

    /// A workspace with the settings of the settings file at `path` (see [`Settings::load`]):
    /// what it cannot read is in [`Workspace::warnings`].
    #[must_use]
    pub fn with_settings_file(path: &Path) -> Self {
        let (settings, warnings) = Settings::load(path);
        let mut w = Self::new(settings);
        for warning in warnings {
            w.warn(warning);
        }
        w
    }

    /// Reopens what the settings name (last table, last stream or frames), reporting failures
    /// as warnings: a moved file must not stop the app from starting.
    pub fn reopen_last(&mut self) {
        if let Some(t) = self.settings.last_overhead_table.clone() {
            self.use_table_of(CameraKind::Overhead);
            self.run(Command::OpenTable(t));
            self.use_table_of(CameraKind::Robot);
        }
        if let Some(t) = self.settings.last_table.clone() {
            self.run(Command::OpenTable(t));
        }
        if let Some(p) = self.settings.last_places.clone() {
            self.run(Command::OpenPlaces(p));
        }
        if let Some(p) = self.settings.last_params.clone() {
            self.run(ParamsCommand::OpenParams(p).into());
        }
        let src = self.settings.last_source.clone();
        let index = self.settings.last_index;
        if !src.is_empty() {
            self.run(Command::Open(src));
            if self.source.is_some() && index > 0 {
                self.run(PlaybackCommand::Seek(index).into());
            }
        }
    }

    /// Applies a command and reports a failure in the status area instead of returning it.
    pub fn run(&mut self, command: Command) {
        if let Err(e) = self.apply(command) {
            let msg = format!("{e:#}");
            self.status.clone_from(&msg);
            self.warn(msg);
        }
    }

    /// Applies a command: the one place state changes.
    ///
    /// # Errors
    /// File problems (naming the file), nothing to commit or save, and the like; the state is
    /// unchanged by a failed command.
    pub fn apply(&mut self, command: Command) -> anyhow::Result<()> {
        if matches!(
            command,
            Command::Playback(
                PlaybackCommand::Step(_)
                    | PlaybackCommand::Seek(_)
                    | PlaybackCommand::SetPlaying(_)
            )
        ) {
            // Moving through a shown robot's frames holds the view (reception goes on).
            self.leave_live();
        }
        match command {
            Command::Open(paths) => self.open(paths)?,
            Command::OpenCamera(camera) => self.open_camera(camera)?,
            Command::ShowSideBySide(cameras) => self.show_side_by_side(&cameras)?,
            Command::FocusCamera(camera) => self.focus_camera(&camera)?,
            Command::OpenTable(p) => self.open_table(&p)?,
            Command::OpenPlaces(p) => self.open_places(&p)?,
            Command::ClosePlaces => self.close_places(),
            Command::OpenLabels(p) => self.open_labels(&p)?,
            Command::SetLabelsSplit(split) => self.set_labels_split(split)?,
            Command::ShowWindow(w, open) => {
                *self.window_flag(w) = open;
                if w == Window::Inspector && !open {
                    // Its highlight belongs to it: closed, every object is drawn alike again.
                    self.selected_object = None;
                }
                if w == Window::Calibration && !open {
                    // Picking belongs to the calibration window: closed, a click samples.
                    self.disarm_landmark_picking();
                }
            }
            Command::SelectObject(owner) => {
                if let Some(o) = owner {
                    anyhow::ensure!(
                        self.primitives.iter().any(|p| p.owner() == o),
                        "no object {o} in this frame"
                    );
                }
                self.selected_object = owner;
            }
            Command::Params(c) => self.apply_params(c)?,
            Command::Table(c) => self.apply_table_edit(c)?,
            Command::Playback(c) => self.apply_playback(c)?,
            Command::View(c) => self.apply_view(c)?,
            Command::Source(c) => self.apply_source(c)?,
            Command::Robots(c) => self.apply_robot_command(c)?,
            Command::Hints(c) => self.apply_hints(c)?,
            Command::Overhead(c) => self.apply_overhead(c)?,
            Command::ShowSslStep(step) => self.show_ssl_step(step)?,
        }
        Ok(())
    }

    /// Which camera the shown frames come from (robot when nothing is open): it chooses the
    /// recogniser and the lookup table.
    #[must_use]
    pub fn camera_kind(&self) -> CameraKind {
        self.connected_info()
            .map_or(CameraKind::Robot, |s| s.camera)
    }

    // ---- reading ----

    /// The table in use.
    #[must_use]
    pub fn lut(&self) -> &LookupTable {
        self.pipeline.lut()
    }

    /// The table's file, if it has one.
    #[must_use]
    pub fn table_path(&self) -> Option<&Path> {
        self.table_path.as_deref()
    }

    /// The open places file, if any.
    #[must_use]
    pub fn places_path(&self) -> Option<&Path> {
        self.places_path.as_deref()
    }

    /// The learnt places pink markers are identified against, if a places file is open.
    #[must_use]
    pub fn places(&self) -> Option<&crate::recognition::patterns::PatternMemory> {
        self.pipeline.pattern_memory()
    }

    /// True when the table has edits not yet saved.
    #[must_use]
    pub const fn dirty(&self) -> bool {
        self.dirty
    }

    /// The undo/redo history.
    #[must_use]
    pub const fn history(&self) -> &EditHistory {
        &self.history
    }

    /// The open stream or frames.
    #[must_use]
    pub const fn source(&self) -> Option<&Source> {
        self.source.as_ref()
    }

    /// Index of the shown frame.
    #[must_use]
    pub const fn index(&self) -> usize {
        self.index
    }

    /// The shown frame with its time and sensors.
    #[must_use]
    pub const fn current(&self) -> Option<&SourceFrame> {
        self.current.as_ref()
    }

    /// The shown frame's image.
    #[must_use]
    pub fn frame(&self) -> Option<&Frame> {
        self.current.as_ref().map(|c| c.frame.as_ref())
    }

    /// The classified shown frame.
    #[must_use]
    pub fn classified(&self) -> &ClassifiedImage {
        self.shown_classified()
    }

    /// The shown frame's blobs.
    #[must_use]
    pub fn blobs(&self) -> &BlobSet {
        self.shown_blobs()
    }

    /// What recognition made of the shown frame: every candidate with its evidence.
    #[must_use]
    pub fn recognition(&self) -> &Recognition {
        self.shown_recognition()
    }

    /// The shown frame's drawing primitives (image pixels), computed once per frame.
    #[must_use]
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }

    /// The accepted objects: what the objects view shows.
    #[must_use]
    pub fn accepted_owners(&self) -> &[crate::recognition::ObjectId] {
        &self.accepted_owners
    }

    /// The candidate selected in the inspector, whose overlays are highlighted.
    #[must_use]
    pub const fn selected_object(&self) -> Option<crate::recognition::ObjectId> {
        self.selected_object
    }

    /// Blobs large enough to draw, largest first within each class.
    #[must_use]
    pub fn drawn_blobs(&self) -> Vec<Blob> {
        let min = self.settings.min_blob_pixels;
        let hidden = &self.settings.hidden_blob_classes;
        self.blobs()
            .active()
            .filter(|b| b.pixels >= min && !hidden.iter().any(|c| c.code() == b.colour))
            .copied()
            .collect()
    }

    /// Table cells per class code, kept up to date on every table change (counting 2M cells
    /// every UI frame would cost milliseconds).
    #[must_use]
    pub const fn table_counts(&self) -> &crate::lut::ClassCounts {
        &self.table_counts
    }

    /// Pixels of the shown frame per class code.
    #[must_use]
    pub const fn frame_counts(&self) -> &[usize; 256] {
        &self.frame_counts
    }

    /// The pending selection.
    #[must_use]
    pub const fn selection(&self) -> Option<&PendingSelection> {
        self.selection.as_ref()
    }

    /// One flag per pixel: would the pending selection select it (empty when none)?
    #[must_use]
    pub fn preview_mask(&self) -> &[bool] {
        &self.preview_mask
    }

    /// The pending selection resolved against the table.
    #[must_use]
    pub fn resolved_selection(&self) -> Option<Selection> {
        self.selection
            .as_ref()
            .map(|s| s.region.select(self.pipeline.lut()))
    }

    /// Warnings collected so far, oldest first.
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Forgets the collected warnings.
    pub fn clear_warnings(&mut self) {
        self.warnings.clear();
    }

    /// Changes when the shown frame or its results change (textures compare it).
    #[must_use]
    pub const fn frame_generation(&self) -> u64 {
        self.frame_generation
    }

    /// Changes when the preview mask changes.
    #[must_use]
    pub const fn preview_generation(&self) -> u64 {
        self.preview_generation
    }

    /// Changes when the table changes (the U–V plane compares it).
    #[must_use]
    pub const fn table_generation(&self) -> u64 {
        self.table_generation
    }

    /// True while playing.
    #[must_use]
    pub const fn playing(&self) -> bool {
        self.player.playing()
    }

    /// The whole-stream check of the pending edit.
    #[must_use]
    pub const fn try_edit(&self) -> Option<&TryEdit> {
        self.try_edit.as_ref()
    }

    /// The largest useful sensitivity for the table: half its side.
    #[must_use]
    pub fn max_sensitivity(&self) -> u8 {
        u8::try_from(self.pipeline.lut().side() / 2).unwrap_or(u8::MAX)
    }

    /// The window title: table (with `*` when unsaved; the other camera's too when it has
    /// unsaved edits) and source.
    #[must_use]
    pub fn title(&self) -> String {
        let table = self
            .table_path
            .as_deref()
            .map_or_else(|| "untitled table".to_owned(), crate::frame::display_name);
        let mark = if self.dirty { " *" } else { "" };
        let other = if self.other_table.dirty() {
            let name = self
                .other_table
                .path()
                .map_or_else(|| "untitled table".to_owned(), crate::frame::display_name);
            format!(" (+ {name} *)")
        } else {
            String::new()
        };
        let source = self
            .connected_info()
            .map(|s| format!(" — {}", s.label))
            .unwrap_or_default();
        format!("eotn — {table}{mark}{other}{source}")
    }

    /// What hovering (x, y) shows, or `None` outside the frame.
    #[must_use]
    pub fn pixel_info(&self, x: usize, y: usize) -> Option<PixelInfo> {
        let yuv = self.frame()?.pixel(x, y)?;
        Some(PixelInfo {
            x,
            y,
            yuv,
            rgb: yuv_to_rgb(yuv),
            class: self.pipeline.lut().class_of(yuv),
            blob: self.blobs().blob_at(x, y).copied(),
            field_cm: self.field_point_of_pixel(x, y),
        })
    }

    /// Frame size in pixels, (0, 0) when nothing is open.
    #[must_use]
    pub fn image_size(&self) -> (usize, usize) {
        self.frame().map_or((0, 0), |f| (f.width(), f.height()))
    }

    // ---- changing ----

    pub(super) fn warn(&mut self, w: String) {
        log::warn!("{w}");
        if self.warnings.len() >= MAX_WARNINGS {
            self.warnings.remove(0);
        }
        self.warnings.push(w);
    }

    pub(super) fn remember_recent(&mut self, path: &Path) {
        let p = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned());
        self.settings.recent.retain(|r| r != &p);
        self.settings.recent.insert(0, p);
        self.settings.recent.truncate(MAX_RECENT);
    }
}

fn seven_bit_table() -> LookupTable {
    // Bits are checked to be 6..=8 before this is needed, so it never runs in practice.
    LookupTable::new(7).expect("7 bits per channel is a supported table size")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_without_data_fail_cleanly() {
        let mut s = Workspace::default();
        assert!(s.apply(TableCommand::Commit.into()).is_err());
        assert!(s.apply(TableCommand::Undo.into()).is_err());
        assert!(s.apply(PlaybackCommand::Step(1).into()).is_err());
        assert!(s.apply(TableCommand::SaveTable.into()).is_err());
        assert!(s.apply(TableCommand::Sample { x: 0, y: 0 }.into()).is_err());
        s.run(TableCommand::Undo.into());
        assert_eq!(s.warnings().len(), 1);
    }

    #[test]
    fn sensitivity_keys_clamp() {
        let mut s = Workspace::default();
        s.apply(
            TableCommand::AdjustSensitivity {
                channel: 1,
                delta: -5,
            }
            .into(),
        )
        .unwrap();
        assert_eq!(s.settings.sensitivity.u, 0);
        s.apply(
            TableCommand::AdjustSensitivity {
                channel: 2,
                delta: 500,
            }
            .into(),
        )
        .unwrap();
        assert_eq!(s.settings.sensitivity.v, 64);
        assert!(
            s.apply(
                TableCommand::AdjustSensitivity {
                    channel: 3,
                    delta: 1
                }
                .into()
            )
            .is_err()
        );
    }

    #[test]
    fn a_new_table_journals_from_its_first_commit() {
        let dir = tempfile::tempdir().expect("temp");
        let path = dir.path().join("new.lut");
        let mut s = Workspace::default();
        s.apply(TableCommand::NewTable(6).into()).unwrap();
        for (class, cell) in [
            (ColourClass::Orange, [30, 20, 50]),
            (ColourClass::Green, [20, 12, 12]),
            (ColourClass::White, [60, 32, 32]),
        ] {
            s.apply(TableCommand::SetClass(class).into()).unwrap();
            s.apply(TableCommand::SampleCell(cell).into()).unwrap();
            s.apply(TableCommand::Commit.into()).unwrap();
        }
        s.apply(TableCommand::Undo.into()).unwrap();
        s.apply(TableCommand::SaveTableAs(path.clone()).into())
            .unwrap();
        // Before the fix the journal began at the save, with the edits folded into a base copy.
        assert!(!journal::base_path(&path).exists());
        let replay = journal::replay(&path).unwrap();
        assert_eq!(replay.commits, 3);
        assert_eq!(&replay.table, s.pipeline.lut());
        assert_eq!(replay.table, LookupTable::load(&path).unwrap());
        // Edits after the save are appended as before.
        s.apply(TableCommand::Redo.into()).unwrap();
        s.apply(TableCommand::SaveTable.into()).unwrap();
        assert_eq!(
            journal::replay(&path).unwrap().table,
            LookupTable::load(&path).unwrap()
        );
    }

    /// A table opened from a file (a seeded one, no journal yet), clicked on, then saved under
    /// another name keeps every click in the new name's journal, which starts from the seed
    /// (before, Save As folded the clicks into a new base copy).
    #[test]
    fn save_as_of_an_opened_table_keeps_its_journal_from_the_seed() {
        let dir = tempfile::tempdir().expect("temp");
        let seed = dir.path().join("seed.lut");
        let mut lut = LookupTable::new(6).unwrap();
        lut.apply(crate::lut::EditRecord::now(
            ColourClass::Orange,
            crate::lut::Region::Cells { indices: vec![5] },
        ));
        lut.save(&seed).unwrap();
        let mut s = Workspace::default();
        s.apply(Command::OpenTable(seed.clone())).unwrap();
        for (class, cell) in [
            (ColourClass::Green, [20, 12, 12]),
            (ColourClass::White, [60, 32, 32]),
        ] {
            s.apply(TableCommand::SetClass(class).into()).unwrap();
            s.apply(TableCommand::SampleCell(cell).into()).unwrap();
            s.apply(TableCommand::Commit.into()).unwrap();
        }
        let path = dir.path().join("final.lut");
        s.apply(TableCommand::SaveTableAs(path.clone()).into())
            .unwrap();
        let replay = journal::replay(&path).unwrap();
        assert_eq!(replay.commits, 2);
        assert_eq!(replay.table, LookupTable::load(&path).unwrap());
        assert_eq!(
            LookupTable::load(&journal::base_path(&path)).unwrap(),
            LookupTable::load(&seed).unwrap()
        );
        // Later edits go to the new name's journal only.
        s.apply(TableCommand::Undo.into()).unwrap();
        s.apply(TableCommand::SaveTable.into()).unwrap();
        assert_eq!(
            journal::replay(&path).unwrap().table,
            LookupTable::load(&path).unwrap()
        );
        assert_eq!(journal::replay(&seed).unwrap().commits, 2);
    }
}
