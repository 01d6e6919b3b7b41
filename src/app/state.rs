//! Everything the app knows that is not a widget: the open table and frames, the pipeline's
//! results, the pending selection, playback, zoom and pan, settings. The UI reads it and sends
//! [`Command`]s; [`AppState::apply`] is the one place they change anything, so the kittest tests
//! and the real window go through the same path. No egui here.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context as _;
use serde::{Deserialize, Serialize};

use super::journal::{self, JournalEntry, now_unix_ms};
use super::source::{LoadedFrame, Source};
use crate::blobs::{Blob, BlobSet, Connectivity};
use crate::classify::ClassifiedImage;
use crate::frame::{Frame, Yuv, save_rgb_png, yuv_to_rgb};
use crate::lut::edit::Selection;
use crate::lut::{ColourClass, EditHistory, EditRecord, LookupTable, Region, Sensitivity};
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::draw::owner;
use crate::recognition::{LineRole, Primitive, Recognition};
use crate::sensors::SensorReadings;

/// How many warnings the status area keeps (oldest dropped first).
pub const MAX_WARNINGS: usize = 200;
/// How many recent files the File menu lists.
pub const MAX_RECENT: usize = 10;
/// Zoom limits, screen points per image pixel.
pub const ZOOM_RANGE: (f32, f32) = (0.1, 64.0);
/// Zoom presets of the View menu, screen points per image pixel.
pub const ZOOM_PRESETS: [f32; 6] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0];
/// Playback speeds offered, × recorded rate; 0 plays every frame as fast as the machine can.
pub const SPEEDS: [f32; 7] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 0.0];
/// Time per UI frame a whole-stream scan may take, so the window stays responsive.
const SCAN_BUDGET: Duration = Duration::from_millis(12);
/// How many step and frame times are kept for the medians.
const TIMING_SAMPLES: usize = 600;

/// The four image views; one is enlarged, the others are thumbnails.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum ViewKind {
    /// The camera image in colour.
    #[default]
    Raw,
    /// Every pixel in its class's display colour.
    Classified,
    /// The classified image dimmed, with each blob's box.
    Blobs,
    /// The colour image with the recognised objects: ball, goals with posts and gap, beacons,
    /// labelled with distance and bearing.
    Objects,
}

impl ViewKind {
    /// All views in thumbnail order.
    pub const ALL: [Self; 4] = [Self::Raw, Self::Classified, Self::Blobs, Self::Objects];

    /// The name shown under a thumbnail and in menus.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Raw => "Raw",
            Self::Classified => "Classified",
            Self::Blobs => "Blobs",
            Self::Objects => "Objects",
        }
    }
}

/// Which overlays are drawn on the enlarged view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Overlays {
    /// Classified colours over the colour image (raw and objects views).
    pub classified: bool,
    /// Opacity of the classified overlay, 0..=1.
    pub opacity: f32,
    /// Blob boxes on every view.
    pub blob_boxes: bool,
    /// Class names beside the boxes.
    pub labels: bool,
    /// The pending selection's preview highlight.
    pub preview: bool,
    /// Recognition: the horizon (needs the camera pose from sensor readings).
    pub horizon: bool,
    /// Recognition: every candidate's box, accepted or rejected.
    pub candidates: bool,
    /// Recognition: the scanned areas (green below a ball).
    pub scan_areas: bool,
    /// Recognition: edge points found by the ball's and the posts' scans.
    pub scan_points: bool,
    /// Recognition: the ball's fitted circle.
    pub circles: bool,
    /// Recognition: fitted goal posts.
    pub posts: bool,
    /// Recognition: a goal's largest gap and its scan line.
    pub gaps: bool,
    /// Recognition: labels of accepted objects with distance (cm) and bearing (degrees).
    pub object_labels: bool,
    /// Recognition: the nine regions around each pink marker and its place.
    pub patterns: bool,
}

impl Overlays {
    /// Every overlay on, the classified colours at half opacity: the heaviest view.
    #[must_use]
    pub fn all_on() -> Self {
        Self {
            classified: true,
            ..Self::default()
        }
    }

    /// Switches every recognition overlay on or off.
    pub fn set_recognition(&mut self, on: bool) {
        self.horizon = on;
        self.candidates = on;
        self.scan_areas = on;
        self.scan_points = on;
        self.circles = on;
        self.posts = on;
        self.gaps = on;
        self.object_labels = on;
        self.patterns = on;
    }
}

impl Default for Overlays {
    fn default() -> Self {
        Self {
            classified: false,
            opacity: 0.5,
            blob_boxes: true,
            labels: true,
            preview: true,
            horizon: true,
            candidates: true,
            scan_areas: true,
            scan_points: true,
            circles: true,
            posts: true,
            gaps: true,
            object_labels: true,
            patterns: true,
        }
    }
}

/// Zoom and pan of the enlarged view, in image pixels so they survive a window resize.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewTransform {
    /// Screen points per image pixel; `None` fits the image to the view.
    pub zoom: Option<f32>,
    /// The image point (pixels) shown at the centre of the view; `None` is the image centre.
    pub centre: Option<[f32; 2]>,
}

impl ViewTransform {
    /// The zoom in effect when the fitted zoom is `fit`.
    #[must_use]
    pub fn effective_zoom(&self, fit: f32) -> f32 {
        self.zoom.unwrap_or(fit)
    }

    /// The centre in effect for an image of `size` (width, height) pixels.
    #[must_use]
    pub fn effective_centre(&self, size: [f32; 2]) -> [f32; 2] {
        self.centre.unwrap_or([size[0] / 2.0, size[1] / 2.0])
    }
}

/// Settings that persist between runs (eframe storage).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    /// Recently opened files, newest first.
    pub recent: Vec<PathBuf>,
    /// The table to reopen at start.
    pub last_table: Option<PathBuf>,
    /// The places file (learnt coloured patterns) to reopen at start.
    pub last_places: Option<PathBuf>,
    /// The stream or frame files to reopen at start.
    pub last_source: Vec<PathBuf>,
    /// The frame that was shown.
    pub last_index: usize,
    /// The class being defined.
    pub class: ColourClass,
    /// Selection reach per channel, table cells.
    pub sensitivity: Sensitivity,
    /// Overlay switches.
    pub overlays: Overlays,
    /// The enlarged view.
    pub main_view: ViewKind,
    /// Zoom and pan of the enlarged view.
    pub transform: ViewTransform,
    /// Playback speed, × recorded rate (0 = every frame, as fast as possible).
    pub speed: f32,
    /// Blob connectivity.
    pub connectivity: Connectivity,
    /// Blobs smaller than this many pixels get no box or label.
    pub min_blob_pixels: u32,
    /// Bits of a new table.
    pub new_table_bits: u8,
    /// Sensor dialog open.
    pub show_sensors: bool,
    /// U–V plane window open.
    pub show_uv_plane: bool,
    /// The Y value whose layer the U–V plane shows, 0..=255.
    pub uv_plane_y: u8,
    /// "Try edit on the stream" window open.
    pub show_try_edit: bool,
    /// The step and frame-time readout in the status bar.
    pub show_timings: bool,
    /// The object inspector window open.
    pub show_inspector: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            recent: Vec::new(),
            last_table: None,
            last_places: None,
            last_source: Vec::new(),
            last_index: 0,
            class: ColourClass::Orange,
            sensitivity: Sensitivity::uniform(1),
            overlays: Overlays::default(),
            main_view: ViewKind::Raw,
            transform: ViewTransform::default(),
            speed: 1.0,
            connectivity: Connectivity::default(),
            min_blob_pixels: 10,
            new_table_bits: 7,
            show_sensors: false,
            show_uv_plane: false,
            uv_plane_y: 128,
            show_try_edit: false,
            show_timings: true,
            show_inspector: false,
        }
    }
}

/// Everything the UI can ask for.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Open files by kind: `.mcap` streams, frame files (as one sequence), anything else as a table.
    Open(Vec<PathBuf>),
    /// Open a lookup table.
    OpenTable(PathBuf),
    /// Open a places file (`eotn patterns learn`): pink markers are identified as its places.
    OpenPlaces(PathBuf),
    /// Forget the places file: pink markers keep their signatures, unidentified.
    ClosePlaces,
    /// A new empty table with the given bits per channel.
    NewTable(u8),
    /// Save the table where it came from.
    SaveTable,
    /// Save the table under a new name (it becomes the table's path).
    SaveTableAs(PathBuf),
    /// Replace the table by replaying its journal.
    RebuildFromJournal,
    /// Move by this many frames.
    Step(i64),
    /// Go to a frame.
    Seek(usize),
    /// Start or stop playback.
    SetPlaying(bool),
    /// Playback speed, × recorded rate (0 = every frame).
    SetSpeed(f32),
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
    /// Write the pending selection into the table with the current class.
    Commit,
    /// Undo the latest edit.
    Undo,
    /// Redo the latest undone edit.
    Redo,
    /// Enlarge another view.
    SetMainView(ViewKind),
    /// Overlay switches.
    SetOverlays(Overlays),
    /// Blob connectivity.
    SetConnectivity(Connectivity),
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
    /// Start the whole-stream check of the pending selection.
    TryEditOnStream,
    /// The Y of the U–V plane.
    SetUvPlaneY(u8),
    /// Open or close a window.
    ShowWindow(Window, bool),
    /// Show or hide the frame-time readout.
    ShowTimings(bool),
    /// Select a recognition candidate by its owner name (`"ball#0"`, `"goal:yellow#1"`,
    /// `"beacon#0"`) to highlight its overlays; `None` shows all alike.
    SelectObject(Option<String>),
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
}

impl Window {
    /// Every window, for the Windows menu.
    pub const ALL: [Self; 4] = [Self::Sensors, Self::UvPlane, Self::TryEdit, Self::Inspector];

    /// Its title.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Sensors => "Sensors",
            Self::UvPlane => "U–V plane",
            Self::TryEdit => "Try edit on stream",
            Self::Inspector => "Object inspector",
        }
    }
}

/// How long the parts of the last step took.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepTiming {
    /// Reading (and decoding) the frame, or the cache hit.
    pub read: Duration,
    /// Ball, goals, beacons.
    pub recognition: Duration,
    /// Classification.
    pub classify: Duration,
    /// Blob formation.
    pub blobs: Duration,
    /// RGB conversion and preview mask.
    pub prepare: Duration,
    /// Building and uploading textures (filled in by the UI).
    pub upload: Duration,
}

impl StepTiming {
    /// Everything.
    #[must_use]
    pub fn total(&self) -> Duration {
        self.read + self.classify + self.blobs + self.recognition + self.prepare + self.upload
    }
}

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
}

/// A pending (previewed, unwritten) selection.
#[derive(Debug, Clone, PartialEq)]
pub struct PendingSelection {
    /// The cells.
    pub region: Region,
    /// The pixel it was made from, if any.
    pub pixel: Option<(usize, usize)>,
}

/// One frame that a tried edit would change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TryEditRow {
    /// Frame index.
    pub index: usize,
    /// Pixels whose class would change.
    pub changed_pixels: usize,
    /// Blobs (at least the minimum size) before the edit.
    pub blobs_before: usize,
    /// Blobs (at least the minimum size) after the edit.
    pub blobs_after: usize,
}

/// The whole-stream check of a pending edit, run a few frames per UI frame.
#[derive(Debug, Clone)]
pub struct TryEdit {
    /// The class the edit writes.
    pub class: ColourClass,
    /// The cells.
    pub region: Region,
    edited: LookupTable,
    /// Next frame to scan.
    pub next: usize,
    /// Frames in the source.
    pub total: usize,
    /// Frames that would change, in order.
    pub rows: Vec<TryEditRow>,
    /// Frames that could not be read.
    pub errors: usize,
}

impl TryEdit {
    /// True when every frame was scanned.
    #[must_use]
    pub fn done(&self) -> bool {
        self.next >= self.total
    }
}

/// Sensor readings of every frame of the stream, filled a few frames per UI frame.
#[derive(Debug, Clone, Default)]
pub struct SensorSeries {
    /// (time in seconds, readings) per frame read so far, in frame order.
    pub points: Vec<(f64, Option<SensorReadings>)>,
    /// Frames in the source.
    pub total: usize,
}

/// Runtime measurements for the status readout and the exit report.
#[derive(Debug, Clone, Default)]
pub struct Timings {
    /// The last step.
    pub last_step: StepTiming,
    /// Recent step totals, milliseconds.
    pub steps_ms: Vec<f64>,
    /// Recent UI frame intervals, milliseconds.
    pub frames_ms: Vec<f64>,
    /// Recent UI frame intervals while playing, milliseconds.
    pub playing_frames_ms: Vec<f64>,
    /// While playing: time our own UI code took per frame (layout and painting commands, not
    /// tessellation or rasterisation), milliseconds.
    pub playing_ui_ms: Vec<f64>,
    /// While playing: eframe's CPU time per frame (our UI, tessellation, the renderer's
    /// submission; not the wait for the display), milliseconds.
    pub playing_cpu_ms: Vec<f64>,
    /// Frames shown by playback since the app started.
    pub played_frames: u64,
    /// Frames playback skipped because the next one was already due (not ready in time).
    pub dropped_frames: u64,
}

fn push_capped(v: &mut Vec<f64>, x: f64) {
    if v.len() >= TIMING_SAMPLES {
        v.remove(0);
    }
    v.push(x);
}

/// Median of a list of samples (0 for none).
#[must_use]
pub fn median(samples: &[f64]) -> f64 {
    if samples.is_empty() {
        return 0.0;
    }
    let mut s = samples.to_vec();
    s.sort_by(f64::total_cmp);
    s[s.len() / 2]
}

/// The app's state; see the module documentation.
#[derive(Debug)]
pub struct AppState {
    /// Persisted settings.
    pub settings: Settings,
    pipeline: Pipeline,
    table_path: Option<PathBuf>,
    history: EditHistory,
    dirty: bool,
    source: Option<Source>,
    index: usize,
    current: Option<LoadedFrame>,
    rgb: Vec<u8>,
    selection: Option<PendingSelection>,
    preview_mask: Vec<bool>,
    warnings: Vec<String>,
    /// The last message for the status line (what the last command did).
    pub status: String,
    frame_generation: u64,
    preview_generation: u64,
    table_generation: u64,
    playing: bool,
    play_clock_ns: f64,
    /// Measurements.
    pub timings: Timings,
    /// The sensor series of the open stream.
    pub sensor_series: SensorSeries,
    try_edit: Option<TryEdit>,
    places_path: Option<PathBuf>,
    table_counts: crate::lut::ClassCounts,
    frame_counts: [usize; 256],
    primitives: Vec<Primitive>,
    accepted_owners: Vec<String>,
    selected_object: Option<String>,
}

impl Default for AppState {
    fn default() -> Self {
        Self::new(Settings::default())
    }
}

impl AppState {
    /// A state with these settings, an empty table of their bits and nothing open.
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
        Self {
            settings,
            pipeline: Pipeline::new(lut, params),
            table_path: None,
            history: EditHistory::default(),
            dirty: false,
            source: None,
            index: 0,
            current: None,
            rgb: Vec::new(),
            selection: None,
            preview_mask: Vec::new(),
            warnings: Vec::new(),
            status: String::new(),
            frame_generation: 0,
            preview_generation: 0,
            table_generation: 0,
            playing: false,
            play_clock_ns: 0.0,
            timings: Timings::default(),
            sensor_series: SensorSeries::default(),
            try_edit: None,
            places_path: None,
            table_counts,
            frame_counts: [0; 256],
            primitives: Vec::new(),
            accepted_owners: Vec::new(),
            selected_object: None,
        }
    }

    /// Reopens what the settings name (last table, last stream or frames), reporting failures
    /// as warnings: a moved file must not stop the app from starting.
    pub fn reopen_last(&mut self) {
        if let Some(t) = self.settings.last_table.clone() {
            self.run(Command::OpenTable(t));
        }
        if let Some(p) = self.settings.last_places.clone() {
            self.run(Command::OpenPlaces(p));
        }
        let src = self.settings.last_source.clone();
        let index = self.settings.last_index;
        if !src.is_empty() {
            self.run(Command::Open(src));
            if self.source.is_some() && index > 0 {
                self.run(Command::Seek(index));
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
        match command {
            Command::Open(paths) => self.open(paths)?,
            Command::OpenTable(p) => self.open_table(&p)?,
            Command::OpenPlaces(p) => self.open_places(&p)?,
            Command::ClosePlaces => {
                self.pipeline.set_pattern_memory(None);
                self.places_path = None;
                self.settings.last_places = None;
                self.reprocess();
                self.status = "places file closed: pink markers are not identified".to_owned();
            }
            Command::NewTable(bits) => {
                let lut = LookupTable::new(bits).map_err(|e| anyhow::anyhow!("new table: {e}"))?;
                self.set_table(lut, None);
                self.settings.new_table_bits = bits;
                self.status = format!("new empty {bits}-bit table");
            }
            Command::SaveTable => {
                let path = self
                    .table_path
                    .clone()
                    .context("the table has no file yet: use Save table as…")?;
                self.save_table(&path)?;
            }
            Command::SaveTableAs(p) => self.save_table(&p)?,
            Command::RebuildFromJournal => {
                let path = self.table_path.clone().context("the table has no file")?;
                let r = journal::replay(&path)?;
                for w in r.warnings {
                    self.warn(w);
                }
                self.pipeline.set_lut(r.table);
                self.history = r.history;
                self.dirty = true;
                self.table_changed();
                self.status = format!("rebuilt from the journal: {} edits replayed", r.commits);
            }
            Command::Step(delta) => {
                let len = self
                    .source
                    .as_ref()
                    .context("no stream or frames open")?
                    .len();
                let target = i64::try_from(self.index)
                    .unwrap_or(i64::MAX)
                    .saturating_add(delta)
                    .clamp(0, i64::try_from(len).unwrap_or(i64::MAX) - 1);
                self.seek(usize::try_from(target).unwrap_or(0))?;
            }
            Command::Seek(i) => self.seek(i)?,
            Command::SetPlaying(p) => {
                if p {
                    let src = self.source.as_ref().context("no stream or frames open")?;
                    if self.index + 1 >= src.len() {
                        // Playing from the end starts again.
                        self.seek(0)?;
                    }
                    let t = self.source.as_ref().map_or(0, |s| s.time_ns(self.index));
                    self.play_clock_ns = t as f64;
                }
                self.playing = p;
            }
            Command::SetSpeed(s) => {
                self.settings.speed = if s.is_finite() { s.max(0.0) } else { 1.0 }
            }
            Command::SetClass(c) => self.settings.class = c,
            Command::SetSensitivity(s) => self.set_sensitivity(s),
            Command::AdjustSensitivity { channel, delta } => {
                let mut s = self.settings.sensitivity;
                let slot = match channel {
                    0 => &mut s.y,
                    1 => &mut s.u,
                    2 => &mut s.v,
                    _ => anyhow::bail!("channel {channel} is not 0 (Y), 1 (U) or 2 (V)"),
                };
                let max = i32::from(self.max_sensitivity());
                *slot = u8::try_from((i32::from(*slot) + delta).clamp(0, max)).unwrap_or(0);
                self.set_sensitivity(s);
            }
            Command::Sample { x, y } => {
                let frame = self.frame().context("no frame to sample")?;
                let sample = frame
                    .pixel(x, y)
                    .with_context(|| format!("({x}, {y}) is outside the frame"))?;
                self.selection = Some(PendingSelection {
                    region: Region::AroundSample {
                        sample,
                        sensitivity: self.settings.sensitivity,
                    },
                    pixel: Some((x, y)),
                });
                self.refresh_preview();
            }
            Command::SampleCell(cell) => {
                let lut = self.pipeline.lut();
                anyhow::ensure!(
                    cell.iter().all(|&c| c < lut.side()),
                    "cell {cell:?} is outside the {}-bit table",
                    lut.bits()
                );
                let shift = lut.shift();
                let half = (1usize << shift) / 2;
                let v = cell.map(|c| u8::try_from((c << shift) + half).unwrap_or(255));
                self.selection = Some(PendingSelection {
                    region: Region::AroundSample {
                        sample: Yuv::new(v[0], v[1], v[2]),
                        sensitivity: self.settings.sensitivity,
                    },
                    pixel: None,
                });
                self.refresh_preview();
            }
            Command::ClearSelection => {
                self.selection = None;
                self.refresh_preview();
            }
            Command::Commit => self.commit()?,
            Command::Undo => {
                let record = self
                    .history
                    .undo(self.pipeline.lut_mut())
                    .cloned()
                    .context("nothing to undo")?;
                self.journal(&JournalEntry::Undo {
                    time_unix_ms: now_unix_ms(),
                });
                self.dirty = true;
                self.table_changed();
                self.status = format!("undid {} edit", record.class.name());
            }
            Command::Redo => {
                let record = self
                    .history
                    .redo(self.pipeline.lut_mut())
                    .cloned()
                    .context("nothing to redo")?;
                self.journal(&JournalEntry::Redo {
                    time_unix_ms: now_unix_ms(),
                });
                self.dirty = true;
                self.table_changed();
                self.status = format!("redid {} edit", record.class.name());
            }
            Command::SetMainView(v) => self.settings.main_view = v,
            Command::SetOverlays(o) => {
                let mut o = o;
                o.opacity = if o.opacity.is_finite() {
                    o.opacity.clamp(0.0, 1.0)
                } else {
                    0.5
                };
                self.settings.overlays = o;
            }
            Command::SetConnectivity(c) => {
                self.settings.connectivity = c;
                let mut params = *self.pipeline.params();
                params.connectivity = c;
                self.pipeline.set_params(params);
                self.reprocess();
            }
            Command::SetZoom(z) => {
                self.settings.transform.zoom = z.filter(|z| z.is_finite()).map(clamp_zoom);
            }
            Command::ZoomAbout { factor, about, fit } => {
                anyhow::ensure!(
                    factor.is_finite() && factor > 0.0 && fit.is_finite() && fit > 0.0,
                    "bad zoom factor"
                );
                let size = self.image_size_f32();
                let t = &mut self.settings.transform;
                let old = t.effective_zoom(fit);
                let new = clamp_zoom(old * factor);
                let c = t.effective_centre(size);
                // Keep `about` at the same screen offset from the view centre.
                let k = old / new;
                t.centre = Some([
                    about[0] - (about[0] - c[0]) * k,
                    about[1] - (about[1] - c[1]) * k,
                ]);
                t.zoom = Some(new);
            }
            Command::Pan(d) => {
                let size = self.image_size_f32();
                let t = &mut self.settings.transform;
                let c = t.effective_centre(size);
                t.centre = Some([c[0] - d[0], c[1] - d[1]]);
            }
            Command::ResetView => self.settings.transform = ViewTransform::default(),
            Command::ExportView(p) => {
                let (w, h, rgb) = self.compose_view_rgb(self.settings.main_view)?;
                save_rgb_png(&p, w, h, &rgb)?;
                self.status = format!("view saved as {}", p.display());
            }
            Command::TryEditOnStream => {
                let sel = self
                    .selection
                    .clone()
                    .context("no pending selection to try")?;
                let total = self.source.as_ref().context("no stream open")?.len();
                let mut edited = self.pipeline.lut().clone();
                edited.apply(EditRecord::now(self.settings.class, sel.region.clone()));
                self.try_edit = Some(TryEdit {
                    class: self.settings.class,
                    region: sel.region,
                    edited,
                    next: 0,
                    total,
                    rows: Vec::new(),
                    errors: 0,
                });
                self.settings.show_try_edit = true;
            }
            Command::SetUvPlaneY(y) => self.settings.uv_plane_y = y,
            Command::ShowWindow(w, open) => *self.window_flag(w) = open,
            Command::ShowTimings(on) => self.settings.show_timings = on,
            Command::SelectObject(owner) => {
                if let Some(o) = &owner {
                    anyhow::ensure!(
                        self.primitives.iter().any(|p| p.owner() == o),
                        "no object {o} in this frame"
                    );
                }
                self.selected_object = owner;
            }
        }
        Ok(())
    }

    /// Advances playback and background scans by `dt` of wall time; returns true when the shown
    /// frame changed. Called once per UI frame.
    pub fn tick(&mut self, dt: Duration) {
        self.scan_sensor_series();
        self.scan_try_edit();
        if !self.playing {
            return;
        }
        let Some(len) = self.source.as_ref().map(Source::len) else {
            self.playing = false;
            return;
        };
        let target = if self.settings.speed <= 0.0 {
            self.index + 1
        } else {
            self.play_clock_ns += dt.as_secs_f64() * 1e9 * f64::from(self.settings.speed);
            let clock = self.play_clock_ns as u64;
            let at = self.source.as_ref().map_or(0, |s| s.index_at_time(clock));
            at.max(self.index)
        };
        let target = target.min(len.saturating_sub(1));
        if target == self.index && target + 1 >= len {
            self.playing = false;
            return;
        }
        if target != self.index {
            self.timings.played_frames += 1;
            self.timings.dropped_frames += (target - self.index - 1) as u64;
            self.run(Command::Seek(target));
            if target + 1 >= len {
                self.playing = false;
            }
        }
    }

    /// While playing, the wall time until the next frame is due (zero when playing every frame
    /// or already late); `None` when not playing. The UI sleeps until then instead of redrawing
    /// an unchanged frame.
    #[must_use]
    pub fn next_frame_due(&self) -> Option<Duration> {
        if !self.playing {
            return None;
        }
        let speed = f64::from(self.settings.speed);
        let src = self.source.as_ref()?;
        if speed <= 0.0 || self.index + 1 >= src.len() {
            return Some(Duration::ZERO);
        }
        let next = src.time_ns(self.index + 1) as f64;
        let wait_s = ((next - self.play_clock_ns) / speed / 1e9).max(0.0);
        Some(Duration::from_secs_f64(wait_s.min(1.0)))
    }

    /// Records one UI frame interval for the frame-time readout.
    pub fn record_frame_time(&mut self, dt: Duration) {
        let ms = dt.as_secs_f64() * 1e3;
        push_capped(&mut self.timings.frames_ms, ms);
        if self.playing {
            push_capped(&mut self.timings.playing_frames_ms, ms);
        }
    }

    /// Records, while playing, how long our UI code and eframe's whole frame took (CPU time).
    pub fn record_ui_time(&mut self, ui: Duration, cpu_s: Option<f32>) {
        if self.playing {
            push_capped(&mut self.timings.playing_ui_ms, ui.as_secs_f64() * 1e3);
            if let Some(c) = cpu_s.filter(|c| c.is_finite()) {
                push_capped(&mut self.timings.playing_cpu_ms, f64::from(c) * 1e3);
            }
        }
    }

    /// Records the texture-upload part of the last step (measured by the UI).
    pub fn record_upload(&mut self, d: Duration) {
        self.timings.last_step.upload = d;
        let total = self.timings.last_step.total().as_secs_f64() * 1e3;
        push_capped(&mut self.timings.steps_ms, total);
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
    pub const fn current(&self) -> Option<&LoadedFrame> {
        self.current.as_ref()
    }

    /// The shown frame's image.
    #[must_use]
    pub fn frame(&self) -> Option<&Frame> {
        self.current.as_ref().map(|c| c.frame.as_ref())
    }

    /// The shown frame as packed RGB.
    #[must_use]
    pub fn rgb(&self) -> &[u8] {
        &self.rgb
    }

    /// The classified shown frame.
    #[must_use]
    pub fn classified(&self) -> &ClassifiedImage {
        self.pipeline.result().classified
    }

    /// The shown frame's blobs.
    #[must_use]
    pub fn blobs(&self) -> &BlobSet {
        self.pipeline.result().blobs
    }

    /// What recognition made of the shown frame: every candidate with its evidence.
    #[must_use]
    pub fn recognition(&self) -> &Recognition {
        self.pipeline.result().recognition
    }

    /// The shown frame's drawing primitives (image pixels), computed once per frame.
    #[must_use]
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }

    /// Owners (`"ball#0"`, `"goal:yellow#1"`, `"beacon#0"`) of the accepted objects: what the
    /// objects view shows.
    #[must_use]
    pub fn accepted_owners(&self) -> &[String] {
        &self.accepted_owners
    }

    /// The candidate selected in the inspector, whose overlays are highlighted.
    #[must_use]
    pub fn selected_object(&self) -> Option<&str> {
        self.selected_object.as_deref()
    }

    /// Blobs large enough to draw, largest first within each class.
    #[must_use]
    pub fn drawn_blobs(&self) -> Vec<Blob> {
        let min = self.settings.min_blob_pixels;
        self.blobs()
            .active()
            .filter(|b| b.pixels >= min)
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
        self.playing
    }

    /// The whole-stream check of the pending edit.
    #[must_use]
    pub const fn try_edit(&self) -> Option<&TryEdit> {
        self.try_edit.as_ref()
    }

    /// Whether a window is open.
    #[must_use]
    pub const fn window_open(&self, w: Window) -> bool {
        match w {
            Window::Sensors => self.settings.show_sensors,
            Window::UvPlane => self.settings.show_uv_plane,
            Window::TryEdit => self.settings.show_try_edit,
            Window::Inspector => self.settings.show_inspector,
        }
    }

    fn window_flag(&mut self, w: Window) -> &mut bool {
        match w {
            Window::Sensors => &mut self.settings.show_sensors,
            Window::UvPlane => &mut self.settings.show_uv_plane,
            Window::TryEdit => &mut self.settings.show_try_edit,
            Window::Inspector => &mut self.settings.show_inspector,
        }
    }

    /// The largest useful sensitivity for the table: half its side.
    #[must_use]
    pub fn max_sensitivity(&self) -> u8 {
        u8::try_from(self.pipeline.lut().side() / 2).unwrap_or(u8::MAX)
    }

    /// The window title: table (with `*` when unsaved) and source.
    #[must_use]
    pub fn title(&self) -> String {
        let table = self
            .table_path
            .as_deref()
            .map_or_else(|| "untitled table".to_owned(), crate::frame::display_name);
        let mark = if self.dirty { " *" } else { "" };
        let source = self
            .source
            .as_ref()
            .map(|s| format!(" — {}", s.label()))
            .unwrap_or_default();
        format!("eotn — {table}{mark}{source}")
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
        })
    }

    /// Frame size in pixels, (0, 0) when nothing is open.
    #[must_use]
    pub fn image_size(&self) -> (usize, usize) {
        self.frame().map_or((0, 0), |f| (f.width(), f.height()))
    }

    fn image_size_f32(&self) -> [f32; 2] {
        let (w, h) = self.image_size();
        [w as f32, h as f32]
    }

    /// The view `kind` with the current overlays as packed RGB (what Export view writes):
    /// (width, height, pixels).
    ///
    /// # Errors
    /// No frame open.
    pub fn compose_view_rgb(&self, kind: ViewKind) -> anyhow::Result<(usize, usize, Vec<u8>)> {
        let (w, h) = self.image_size();
        anyhow::ensure!(w > 0, "no frame to export");
        let codes = self.classified().codes();
        let o = self.settings.overlays;
        let mut out = match kind {
            ViewKind::Raw | ViewKind::Objects => {
                let mut rgb = self.rgb.clone();
                if o.classified {
                    let a = o.opacity;
                    for (px, &c) in rgb.chunks_exact_mut(3).zip(codes) {
                        if c != 0 {
                            let k = crate::lut::code_display_rgb(c);
                            for i in 0..3 {
                                px[i] = mix(px[i], k[i], a);
                            }
                        }
                    }
                }
                rgb
            }
            ViewKind::Classified => self.classified().to_rgb(),
            ViewKind::Blobs => {
                let mut rgb = self.classified().to_rgb();
                rgb.iter_mut().for_each(|v| *v /= 2);
                rgb
            }
        };
        if o.preview
            && let Some(k) = self.preview_colour()
        {
            for (px, &m) in out.chunks_exact_mut(3).zip(&self.preview_mask) {
                if m {
                    px.copy_from_slice(&k);
                } else {
                    // As on screen: the rest is dimmed so the highlight always shows.
                    px.iter_mut().for_each(|v| *v = mix(*v, 0, 110.0 / 255.0));
                }
            }
        }
        let boxes = match kind {
            ViewKind::Objects => Vec::new(),
            ViewKind::Blobs => self.drawn_blobs(),
            _ if o.blob_boxes => self.drawn_blobs(),
            _ => Vec::new(),
        };
        for b in boxes {
            crate::overlay::outline_box(
                &mut out,
                w,
                h,
                [b.minx, b.miny, b.maxx, b.maxy],
                box_colour(b.colour),
            );
        }
        let filter = match kind {
            ViewKind::Objects => Some(PrimitiveFilter::objects(o, &self.accepted_owners)),
            ViewKind::Raw | ViewKind::Classified => Some(PrimitiveFilter::all(o)),
            ViewKind::Blobs => None,
        };
        if let Some(f) = filter {
            let shown: Vec<Primitive> = self
                .primitives
                .iter()
                .filter(|p| f.shows(p))
                .cloned()
                .collect();
            if let Some(mut canvas) = crate::overlay::Canvas::from_rgb(w, h, &out, 1) {
                canvas.draw(&shown);
                out = canvas.rgb;
            }
        }
        Ok((w, h, out))
    }

    /// The colour of the preview highlight: the class being defined (magenta for
    /// unclassified, which erases).
    #[must_use]
    pub fn preview_colour(&self) -> Option<[u8; 3]> {
        self.selection.as_ref()?;
        Some(match self.settings.class {
            ColourClass::Unclassified => [255, 0, 255],
            c => c.display_rgb(),
        })
    }

    // ---- changing ----

    fn warn(&mut self, w: String) {
        log::warn!("{w}");
        if self.warnings.len() >= MAX_WARNINGS {
            self.warnings.remove(0);
        }
        self.warnings.push(w);
    }

    fn remember_recent(&mut self, path: &Path) {
        let p = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned());
        self.settings.recent.retain(|r| r != &p);
        self.settings.recent.insert(0, p);
        self.settings.recent.truncate(MAX_RECENT);
    }

    fn open(&mut self, paths: Vec<PathBuf>) -> anyhow::Result<()> {
        anyhow::ensure!(!paths.is_empty(), "nothing to open");
        let mut frames = Vec::new();
        let mut stream = None;
        for p in paths {
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase())
                .unwrap_or_default();
            if ext == "mcap" {
                stream = Some(p);
            } else if ext == "json" {
                self.open_places(&p)?;
            } else if crate::cli::inputs::is_frame_file(&p) || p.is_dir() {
                frames.push(p);
            } else {
                self.open_table(&p)?;
            }
        }
        if let Some(s) = stream {
            let source = Source::stream(&s)?;
            self.remember_recent(&s);
            self.set_source(source)?;
        } else if !frames.is_empty() {
            let files = crate::cli::inputs::expand_frame_paths(&frames)?;
            for f in &frames {
                self.remember_recent(f);
            }
            self.set_source(Source::files(files)?)?;
        }
        Ok(())
    }

    fn set_source(&mut self, source: Source) -> anyhow::Result<()> {
        let old = self.source.replace(source);
        self.playing = false;
        self.try_edit = None;
        self.current = None;
        if let Err(e) = self.seek(0) {
            self.source = old;
            return Err(e);
        }
        if let Some(src) = &self.source {
            self.settings.last_source = src
                .paths()
                .into_iter()
                .map(|p| std::fs::canonicalize(&p).unwrap_or(p))
                .collect();
            let n = src.len();
            let label = src.label();
            let warnings = src.warnings();
            self.sensor_series = SensorSeries {
                points: Vec::new(),
                total: if src.is_stream() { n } else { 0 },
            };
            for w in warnings {
                self.warn(format!("{label}: {w}"));
            }
            self.status = format!("opened {label}: {n} frames");
        }
        Ok(())
    }

    fn open_table(&mut self, path: &Path) -> anyhow::Result<()> {
        let lut = LookupTable::load(path)?;
        self.set_table(lut, Some(path.to_owned()));
        self.remember_recent(path);
        self.settings.last_table =
            Some(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned()));
        self.status = format!("opened table {}", path.display());
        if journal::journal_path(path).exists() {
            match journal::replay(path) {
                Ok(r) if &r.table == self.pipeline.lut() => {
                    let n = r.history.undo_len();
                    self.history = r.history;
                    self.status = format!("opened table {}; journal: {n} edits can be undone", path.display());
                }
                Ok(r) => self.warn(format!(
                    "{}: the table differs from its journal's replay ({} edits; unsaved edits before a crash?): Classification > Rebuild from journal recovers them",
                    path.display(),
                    r.commits
                )),
                Err(e) => self.warn(format!("{e:#}")),
            }
        }
        Ok(())
    }

    fn open_places(&mut self, path: &Path) -> anyhow::Result<()> {
        let memory = crate::recognition::patterns::PatternMemory::load(path)?;
        let (objects, relation) = (memory.objects.len(), memory.relation);
        self.pipeline.set_pattern_memory(Some(memory));
        self.places_path = Some(path.to_owned());
        self.remember_recent(path);
        self.settings.last_places =
            Some(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned()));
        self.reprocess();
        self.status = format!(
            "opened places {}: {objects} objects{}",
            path.display(),
            relation.map_or_else(
                || ", no size relation (no distances)".to_owned(),
                |r| format!(
                    ", distance = {:.0} / size + {:.1} cm",
                    r.multiplier_cm_px, r.offset_cm
                )
            )
        );
        Ok(())
    }

    fn set_table(&mut self, lut: LookupTable, path: Option<PathBuf>) {
        self.pipeline.set_lut(lut);
        self.table_path = path;
        self.history.clear();
        self.dirty = false;
        self.table_changed();
    }

    fn save_table(&mut self, path: &Path) -> anyhow::Result<()> {
        let moved = self.table_path.as_deref() != Some(path);
        self.pipeline.lut().save(path)?;
        if moved && !journal::journal_path(path).exists() {
            // The journal follows the table: a new file starts one from the table as saved.
            if let Err(e) = journal::append(path, self.pipeline.lut(), &[]) {
                self.warn(format!("{e:#}"));
            }
        }
        self.table_path = Some(path.to_owned());
        self.settings.last_table =
            Some(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned()));
        self.remember_recent(path);
        self.dirty = false;
        self.status = format!("saved {}", path.display());
        Ok(())
    }

    fn journal(&mut self, entry: &JournalEntry) {
        let Some(path) = self.table_path.clone() else {
            return;
        };
        if let Err(e) = journal::append(&path, self.pipeline.lut(), std::slice::from_ref(entry)) {
            self.warn(format!("{e:#}"));
        }
    }

    fn commit(&mut self) -> anyhow::Result<()> {
        let sel = self
            .selection
            .clone()
            .context("nothing selected: left-click a pixel first")?;
        let record = EditRecord::now(self.settings.class, sel.region);
        // The journal must start from the table before its first edit.
        if let Some(path) = self.table_path.clone()
            && !journal::journal_path(&path).exists()
            && let Err(e) = journal::append(&path, self.pipeline.lut(), &[])
        {
            self.warn(format!("{e:#}"));
        }
        let changed = self.history.commit(self.pipeline.lut_mut(), record.clone());
        self.journal(&JournalEntry::Commit { record });
        self.dirty = true;
        self.selection = None;
        self.table_changed();
        self.status = format!("{changed} cells set to {}", self.settings.class.name());
        Ok(())
    }

    fn set_sensitivity(&mut self, s: Sensitivity) {
        let max = self.max_sensitivity();
        let s = Sensitivity {
            y: s.y.min(max),
            u: s.u.min(max),
            v: s.v.min(max),
        };
        self.settings.sensitivity = s;
        if let Some(PendingSelection {
            region: Region::AroundSample { sensitivity, .. },
            ..
        }) = &mut self.selection
        {
            *sensitivity = s;
            self.refresh_preview();
        }
    }

    fn table_changed(&mut self) {
        self.table_generation += 1;
        self.table_counts = self.pipeline.lut().class_counts();
        self.try_edit = None;
        self.reprocess();
    }

    /// Re-runs the pipeline on the shown frame (after a table or parameter change).
    fn reprocess(&mut self) {
        if let Some(c) = self.current.take() {
            let t = self.run_pipeline(&c);
            self.current = Some(c);
            self.timings.last_step = StepTiming {
                classify: t.classify,
                blobs: t.blobs,
                recognition: t.recognition,
                ..StepTiming::default()
            };
            self.frame_generation += 1;
        }
        self.refresh_preview();
    }

    /// Runs every stage on `loaded` with its sensor readings (recognition needs the camera
    /// pose for heights and the horizon) and refreshes what is derived from the results.
    fn run_pipeline(&mut self, loaded: &LoadedFrame) -> crate::pipeline::StageTimings {
        let r = self
            .pipeline
            .process(&loaded.frame, loaded.sensors.as_ref());
        let timings = r.timings;
        let (w, h) = (loaded.frame.width(), loaded.frame.height());
        let recognition = r.recognition;
        self.primitives = recognition.primitives(w, h);
        self.accepted_owners = accepted_owners(recognition);
        self.frame_counts = self.pipeline.result().classified.histogram();
        if self
            .selected_object
            .as_ref()
            .is_some_and(|o| !self.primitives.iter().any(|p| p.owner() == o))
        {
            self.selected_object = None;
        }
        timings
    }

    fn refresh_preview(&mut self) {
        self.preview_mask = match (&self.selection, self.frame()) {
            (Some(s), Some(f)) => s
                .region
                .select(self.pipeline.lut())
                .preview_mask(self.pipeline.lut(), f),
            _ => Vec::new(),
        };
        self.preview_generation += 1;
    }

    fn seek(&mut self, index: usize) -> anyhow::Result<()> {
        let src = self.source.as_mut().context("no stream or frames open")?;
        let index = index.min(src.len().saturating_sub(1));
        let t0 = Instant::now();
        let loaded = src.read(index)?;
        let t1 = Instant::now();
        let t = self.run_pipeline(&loaded);
        let t2 = Instant::now();
        loaded.frame.to_rgb_into(&mut self.rgb);
        for w in &loaded.warnings {
            if !self.warnings.contains(w) {
                self.warn(w.clone());
            }
        }
        self.current = Some(loaded);
        self.index = index;
        self.settings.last_index = index;
        self.refresh_preview();
        self.timings.last_step = StepTiming {
            read: t1 - t0,
            classify: t.classify,
            blobs: t.blobs,
            recognition: t.recognition,
            prepare: t2.elapsed(),
            upload: Duration::ZERO,
        };
        self.frame_generation += 1;
        Ok(())
    }

    fn scan_sensor_series(&mut self) {
        let Some(src) = self.source.as_mut() else {
            return;
        };
        if !self.settings.show_sensors
            || self.sensor_series.points.len() >= self.sensor_series.total
        {
            return;
        }
        let start = Instant::now();
        while self.sensor_series.points.len() < self.sensor_series.total
            && start.elapsed() < SCAN_BUDGET
        {
            let i = self.sensor_series.points.len();
            let t = src.time_ns(i) as f64 / 1e9;
            let r = src.read_uncached(i).ok().and_then(|f| f.sensors);
            self.sensor_series.points.push((t, r));
        }
    }

    fn scan_try_edit(&mut self) {
        let (Some(t), Some(src)) = (self.try_edit.as_mut(), self.source.as_mut()) else {
            return;
        };
        let start = Instant::now();
        let min = self.settings.min_blob_pixels;
        let conn = self.settings.connectivity;
        let lut = self.pipeline.lut();
        while !t.done() && start.elapsed() < SCAN_BUDGET {
            let i = t.next;
            t.next += 1;
            let Ok(f) = src.read_uncached(i) else {
                t.errors += 1;
                continue;
            };
            let before = ClassifiedImage::from_frame(&f.frame, lut);
            let after = ClassifiedImage::from_frame(&f.frame, &t.edited);
            let changed = before
                .codes()
                .iter()
                .zip(after.codes())
                .filter(|(a, b)| a != b)
                .count();
            if changed == 0 {
                continue;
            }
            let count = |img: &ClassifiedImage| {
                BlobSet::from_image(img, conn)
                    .active()
                    .filter(|b| b.pixels >= min)
                    .count()
            };
            t.rows.push(TryEditRow {
                index: i,
                changed_pixels: changed,
                blobs_before: count(&before),
                blobs_after: count(&after),
            });
        }
    }
}

/// Which recognition primitives a view draws.
#[derive(Debug, Clone, Copy)]
pub struct PrimitiveFilter<'a> {
    /// The overlay switches.
    pub overlays: Overlays,
    /// Only these owners (the objects view: accepted objects); `None` draws every candidate.
    pub owners: Option<&'a [String]>,
}

impl<'a> PrimitiveFilter<'a> {
    /// Every candidate, as the switches say.
    #[must_use]
    pub const fn all(overlays: Overlays) -> Self {
        Self {
            overlays,
            owners: None,
        }
    }

    /// Accepted objects only, always with their boxes and labels (the objects view).
    #[must_use]
    pub const fn objects(overlays: Overlays, accepted: &'a [String]) -> Self {
        let mut o = overlays;
        o.candidates = true;
        o.object_labels = true;
        Self {
            overlays: o,
            owners: Some(accepted),
        }
    }

    /// Whether `p` is drawn.
    #[must_use]
    pub fn shows(&self, p: &Primitive) -> bool {
        let o = &self.overlays;
        let on = match p {
            Primitive::Box { .. } => o.candidates,
            Primitive::ScanArea { .. } => o.scan_areas,
            Primitive::ScanPoints { .. } => o.scan_points,
            Primitive::Circle { .. } => o.circles,
            Primitive::Line { role, .. } => match role {
                LineRole::Horizon => o.horizon,
                LineRole::Post => o.posts,
                LineRole::Gap | LineRole::Scan => o.gaps,
            },
            Primitive::PatternRegion { .. } => o.patterns,
            Primitive::Label { owner, .. } => {
                o.object_labels && (o.patterns || !owner::is_pattern(owner))
            }
        };
        let horizon = matches!(
            p,
            Primitive::Line {
                role: LineRole::Horizon,
                ..
            }
        );
        on && (horizon || self.owners.is_none_or(|w| w.iter().any(|x| x == p.owner())))
    }
}

/// Owners of the accepted objects, named as their primitives name them.
fn accepted_owners(r: &Recognition) -> Vec<String> {
    let balls = r.ball.candidates.iter().enumerate();
    let balls = balls
        .filter(|(_, c)| c.accepted)
        .map(|(i, _)| owner::ball(i));
    let goals = r
        .goals
        .candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| c.accepted);
    let goals = goals.map(|(i, c)| owner::goal(c.colour, i));
    let beacons = r.beacons.iter().enumerate().filter(|(_, b)| b.accepted);
    let patterns = r.patterns.iter().enumerate().filter(|(_, p)| p.accepted);
    balls
        .chain(goals)
        .chain(beacons.map(|(i, _)| owner::beacon(i)))
        .chain(patterns.map(|(i, _)| owner::pattern(i)))
        .collect()
}

fn seven_bit_table() -> LookupTable {
    // Bits are checked to be 6..=8 before this is needed, so it never runs in practice.
    LookupTable::new(7).expect("7 bits per channel is a supported table size")
}

fn clamp_zoom(z: f32) -> f32 {
    z.clamp(ZOOM_RANGE.0, ZOOM_RANGE.1)
}

fn mix(a: u8, b: u8, t: f32) -> u8 {
    (f32::from(a) * (1.0 - t) + f32::from(b) * t).round() as u8
}

/// The colour blob boxes of class `code` are drawn in: the class colour, white for black blobs
/// would vanish otherwise.
#[must_use]
pub fn box_colour(code: u8) -> [u8; 3] {
    match code {
        9 => [255, 255, 255],
        c => crate::lut::code_display_rgb(c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoom_about_keeps_the_point_under_the_cursor() {
        let mut s = AppState::default();
        // No frame: image size 0; centre defaults to (0, 0).
        s.apply(Command::ZoomAbout {
            factor: 2.0,
            about: [10.0, 20.0],
            fit: 1.0,
        })
        .unwrap();
        let t = s.settings.transform;
        assert_eq!(t.zoom, Some(2.0));
        // Screen offset of `about` from the centre: before (10 - 0) * 1, after (10 - c) * 2.
        let c = t.centre.unwrap();
        assert!(((10.0 - c[0]) * 2.0 - 10.0).abs() < 1e-4);
        assert!(((20.0 - c[1]) * 2.0 - 20.0).abs() < 1e-4);
        s.apply(Command::SetZoom(Some(1000.0))).unwrap();
        assert_eq!(s.settings.transform.zoom, Some(ZOOM_RANGE.1));
        s.apply(Command::ResetView).unwrap();
        assert_eq!(s.settings.transform, ViewTransform::default());
    }

    #[test]
    fn commands_without_data_fail_cleanly() {
        let mut s = AppState::default();
        assert!(s.apply(Command::Commit).is_err());
        assert!(s.apply(Command::Undo).is_err());
        assert!(s.apply(Command::Step(1)).is_err());
        assert!(s.apply(Command::SaveTable).is_err());
        assert!(s.apply(Command::Sample { x: 0, y: 0 }).is_err());
        s.run(Command::Undo);
        assert_eq!(s.warnings().len(), 1);
    }

    #[test]
    fn sensitivity_keys_clamp() {
        let mut s = AppState::default();
        s.apply(Command::AdjustSensitivity {
            channel: 1,
            delta: -5,
        })
        .unwrap();
        assert_eq!(s.settings.sensitivity.u, 0);
        s.apply(Command::AdjustSensitivity {
            channel: 2,
            delta: 500,
        })
        .unwrap();
        assert_eq!(s.settings.sensitivity.v, 64);
        assert!(
            s.apply(Command::AdjustSensitivity {
                channel: 3,
                delta: 1
            })
            .is_err()
        );
    }
}
