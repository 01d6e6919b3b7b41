//! Frame sources: one abstraction for everything that delivers camera frames — a recorded
//! stream, frame files, the synthetic renderer playing a scenario live, a real camera (V4L2) and
//! a robot over the network — used by the app, the CLI and the tests alike.
//!
//! | file | source |
//! |---|---|
//! | `stream.rs` | [`StreamSource`]: a recorded MCAP stream, random access by index and time |
//! | `files.rs` | [`FileSource`]: frame files (`.uyvy`, PNG, JPEG) with their sensor side files |
//! | `synthetic.rs` | [`SyntheticSource`]: a scenario of [`crate::sim`] rendered live at its frame rate |
//! | `camera.rs` | `CameraSource`: a V4L2 camera (UVC webcams delivering YUYV or UYVY; Linux) |
//! | (network) | a robot over the network (Foxglove WebSocket) lives in `crate::live`, after this module in the data flow: it implements [`FrameSource`] (frames from its own socket thread; `connect` returns at once) and the workspace builds it for [`SourceSpec::Network`] |
//! | `recorder.rs` | [`Recorder`]: any source's frames into an MCAP stream the user names |
//! | `streamer.rs` | [`Streamer`]: any source grabbed at a fixed rate on its own thread |
//!
//! Every source implements [`FrameSource`] (connect, disconnect, settings, grab one image).
//! Recorded sources also implement [`RecordedSource`] (frames by index, times), which
//! [`FrameSource::recorded`] hands out. Streaming at a fixed rate and recording are not part of
//! any one source: [`Streamer`] runs any source on a thread (the UI only polls a channel, so a
//! slow camera never blocks it) and [`Recorder`] writes what any source delivered.
//!
//! Which camera a source films with, the robot's head camera or the overhead camera above the
//! field, is decided in one place: [`CameraKind::of_stream_source`].

#[cfg(target_os = "linux")]
mod camera;
mod files;
mod recorder;
mod stream;
mod streamer;
mod synthetic;

use std::path::PathBuf;
use std::sync::Arc;

#[cfg(target_os = "linux")]
pub use camera::CameraSource;
pub use files::{
    FileSource, RAW_EXTENSIONS, expand_frame_paths, is_frame_file, load_side_sensors,
    sensor_side_file,
};
pub use recorder::Recorder;
pub use stream::StreamSource;
pub use streamer::{Streamer, StreamerEvent};
pub use synthetic::SyntheticSource;

use crate::frame::Frame;
use crate::sensors::SensorReadings;

/// Nominal interval between frames that carry no time (frame files), nanoseconds: 25 fps.
pub const NOMINAL_FRAME_INTERVAL_NS: u64 = 40_000_000;

/// One frame as a source delivers it, with everything that travels with it.
#[derive(Debug, Clone)]
pub struct SourceFrame {
    /// The image.
    pub frame: Arc<Frame>,
    /// Capture time, nanoseconds since the source's first frame (frame files: index × 40 ms).
    pub time_ns: u64,
    /// The robot's sensor readings, when the source has them (NaN values already removed).
    pub sensors: Option<SensorReadings>,
    /// Other per-frame data as (channel, JSON): `/ground_truth`, `/recognition`,
    /// `/world_model/robotN`, …
    pub extra: Vec<(String, serde_json::Value)>,
    /// Problems found while reading this frame (NaN readings dropped, …).
    pub warnings: Vec<String>,
}

impl SourceFrame {
    /// A frame with only its image and time.
    #[must_use]
    pub fn new(time_ns: u64, frame: Frame) -> Self {
        Self {
            frame: Arc::new(frame),
            time_ns,
            sensors: None,
            extra: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// The frame as a stream record: `/ground_truth` and `/recognition` go to their own
    /// channels, the rest stay extra channels.
    #[must_use]
    pub fn into_record(self) -> crate::streams::FrameRecord {
        let mut record =
            crate::streams::FrameRecord::new(self.time_ns, Arc::unwrap_or_clone(self.frame));
        record.sensors = self.sensors;
        for (topic, value) in self.extra {
            match topic.as_str() {
                crate::streams::GROUND_TRUTH_TOPIC => record.ground_truth = Some(value),
                crate::streams::RECOGNITION_TOPIC => record.recognition = Some(value),
                _ => record.extra.push((topic, value)),
            }
        }
        record
    }

    /// The JSON of channel `topic`, if this frame carries it.
    #[must_use]
    pub fn channel(&self, topic: &str) -> Option<&serde_json::Value> {
        self.extra.iter().find(|(t, _)| t == topic).map(|(_, v)| v)
    }
}

/// What kind of thing a source is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceKind {
    /// A recorded MCAP stream.
    Stream,
    /// Frame files.
    Files,
    /// The synthetic renderer playing a scenario.
    Synthetic,
    /// A camera on this machine (V4L2).
    Camera,
    /// A robot or camera server over the network.
    Network,
}

impl SourceKind {
    /// The name used in listings and the Connect dialog.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Stream => "stream",
            Self::Files => "frame files",
            Self::Synthetic => "synthetic",
            Self::Camera => "camera",
            Self::Network => "network",
        }
    }
}

/// Which camera the frames come from: it chooses the recogniser and the lookup table (the robot
/// and the overhead camera see colours differently and keep separate tables).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum CameraKind {
    /// A robot's head camera (the default: every recorded robot stream, frame files).
    #[default]
    Robot,
    /// A camera above the field looking down (the World Model Debugger's camera).
    Overhead,
}

impl CameraKind {
    /// The camera kind of a stream whose [`crate::streams::StreamInfo::source`] is `source`
    /// (`"overhead"`, `"sim:overhead-game"`, `"robot"`, `"bhuman2009"`, …): the one place this
    /// is decided. Anything naming "overhead" is the overhead camera; the rest are robots.
    #[must_use]
    pub fn of_stream_source(source: &str) -> Self {
        if source.to_ascii_lowercase().contains("overhead") {
            Self::Overhead
        } else {
            Self::Robot
        }
    }

    /// The camera kind of image topic `topic` of a stream whose source is `source`: the
    /// stream's kind ([`Self::of_stream_source`]), except that a robot camera of a World Model
    /// Debugger session recording (an overhead stream, topics
    /// [`crate::camera::SESSION_ROBOT_TOPIC_PREFIX`]…) is a robot's.
    #[must_use]
    pub fn of_stream_camera(source: &str, topic: Option<&str>) -> Self {
        match Self::of_stream_source(source) {
            Self::Overhead
                if topic
                    .is_some_and(|t| t.starts_with(crate::camera::SESSION_ROBOT_TOPIC_PREFIX)) =>
            {
                Self::Robot
            }
            kind => kind,
        }
    }

    /// The stream source kind a recording of a live camera of this kind gets (`"robot camera"`,
    /// `"overhead camera"`), which [`Self::of_stream_source`] reads back as this kind.
    #[must_use]
    pub fn stream_source(self) -> String {
        format!("{} camera", self.name())
    }

    /// The name shown in the app and listings.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Robot => "robot",
            Self::Overhead => "overhead",
        }
    }
}

/// What a source is, for titles, listings and choosing the camera kind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceInfo {
    /// Its kind.
    pub kind: SourceKind,
    /// A short description for the title and status line (`"walk.mcap (sim:walk-and-pan)"`).
    pub label: String,
    /// Which camera the frames come from.
    pub camera: CameraKind,
    /// The files it reads (streams, frame files); empty for live sources.
    pub paths: Vec<PathBuf>,
    /// The value recorded as the stream's source kind when this source is recorded
    /// ([`crate::streams::StreamInfo::source`]), so a recording keeps its camera kind.
    pub stream_source: String,
}

/// A frame size, pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Resolution {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
}

impl std::fmt::Display for Resolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}×{}", self.width, self.height)
    }
}

/// A control a camera offers with its range (V4L2 `exposure_absolute`, `gain`, …).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ControlRange {
    /// Smallest value.
    pub min: i64,
    /// Largest value.
    pub max: i64,
    /// Step between values.
    pub step: i64,
}

/// A source's settings: what it delivers now, or what is asked of it. `None` where the source has
/// no such setting (a recorded stream has no exposure).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct SourceSettings {
    /// Frame size.
    pub resolution: Option<Resolution>,
    /// Frames per second.
    pub frame_rate: Option<f64>,
    /// Exposure, in the device's units (V4L2: 100 µs steps).
    pub exposure: Option<i64>,
    /// Gain, in the device's units.
    pub gain: Option<i64>,
}

/// What a source lets the user change, for the Settings dialog.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SourceControls {
    /// Frame sizes offered (empty: fixed).
    pub resolutions: Vec<Resolution>,
    /// Frame rates offered, frames per second (empty: fixed).
    pub frame_rates: Vec<f64>,
    /// The exposure control, where the camera offers one.
    pub exposure: Option<ControlRange>,
    /// The gain control, where the camera offers one.
    pub gain: Option<ControlRange>,
}

/// Why a source failed; every message says which source.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// Reading a recorded stream failed.
    #[error(transparent)]
    Stream(#[from] crate::streams::StreamError),
    /// A frame file could not be read.
    #[error(transparent)]
    FrameFile(#[from] crate::frame::FrameFileError),
    /// A frame could not be made (bad size, odd width).
    #[error("{source_label}: {error}")]
    Frame {
        /// The source.
        source_label: String,
        /// What went wrong.
        error: crate::frame::FrameError,
    },
    /// Asked for a frame while disconnected.
    #[error("{0}: not connected")]
    NotConnected(String),
    /// A frame index past the end.
    #[error("{label}: no frame {index} ({len} frames)")]
    NoSuchFrame {
        /// The source.
        label: String,
        /// Index asked for.
        index: usize,
        /// Frames in the source.
        len: usize,
    },
    /// The source has no such setting or does not take this value.
    #[error("{label}: {detail}")]
    Unsupported {
        /// The source.
        label: String,
        /// What was refused.
        detail: String,
    },
    /// The device or peer failed (a camera unplugged, a robot disconnecting mid-frame).
    #[error("{label}: {detail}")]
    Device {
        /// The source.
        label: String,
        /// What it said.
        detail: String,
    },
    /// Nothing to read: the list of files or the stream is empty (the message says which).
    #[error("{0}")]
    Empty(String),
}

/// Anything that delivers camera frames. Sources are `Send` so that a [`Streamer`] can run
/// them on its own thread.
pub trait FrameSource: Send {
    /// What it is (kind, label, camera kind).
    fn info(&self) -> SourceInfo;

    /// Opens the device, file or connection; a connected source is left as it is.
    ///
    /// # Errors
    /// The device or file cannot be opened.
    fn connect(&mut self) -> Result<(), SourceError>;

    /// Closes it; grabbing then fails with [`SourceError::NotConnected`] until connected again.
    fn disconnect(&mut self);

    /// True between a successful [`Self::connect`] and [`Self::disconnect`].
    fn is_connected(&self) -> bool;

    /// What it delivers now.
    fn settings(&self) -> SourceSettings;

    /// What may be changed, and to what.
    fn controls(&self) -> SourceControls {
        SourceControls::default()
    }

    /// Changes the settings given as `Some` and returns what the source now delivers (a camera
    /// may round a frame rate or exposure to what it can do).
    ///
    /// # Errors
    /// A setting the source does not have or a value it refuses, naming both.
    fn set_settings(&mut self, wanted: &SourceSettings) -> Result<SourceSettings, SourceError> {
        let now = self.settings();
        let refused = [
            (
                "resolution",
                wanted.resolution.is_some() && wanted.resolution != now.resolution,
            ),
            (
                "frame rate",
                wanted.frame_rate.is_some() && wanted.frame_rate != now.frame_rate,
            ),
            (
                "exposure",
                wanted.exposure.is_some() && wanted.exposure != now.exposure,
            ),
            ("gain", wanted.gain.is_some() && wanted.gain != now.gain),
        ];
        if let Some((name, _)) = refused.iter().find(|(_, r)| *r) {
            return Err(SourceError::Unsupported {
                label: self.info().label,
                detail: format!("its {name} cannot be changed"),
            });
        }
        Ok(now)
    }

    /// The next image: a live source waits for it (at most about one frame interval); a
    /// recorded source gives the frame after the last one grabbed, from the start again after
    /// the end.
    ///
    /// # Errors
    /// Not connected, or the device, file or peer failed.
    fn grab(&mut self) -> Result<SourceFrame, SourceError>;

    /// The frames by index, for sources that hold a recording (streams, frame files).
    fn recorded(&mut self) -> Option<&mut dyn RecordedSource> {
        None
    }
}

/// A source whose frames are all there already: read by index, stepped, sought by time.
pub trait RecordedSource: FrameSource {
    /// Number of frames (never 0: an empty recording is refused when opening).
    fn len(&self) -> usize;

    /// Never true; see [`Self::len`].
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The first frame that can be read: 0, except for a live robot whose oldest frames have
    /// left memory (frames `first_index()..len()` are readable).
    fn first_index(&self) -> usize {
        0
    }

    /// Time of frame `index`, nanoseconds since the first frame.
    fn time_ns(&self, index: usize) -> u64;

    /// The first frame's own time, nanoseconds on the source's clock (a recording's log
    /// time): the cameras of one recording share this clock, so cameras shown side by side
    /// are matched by it. 0 for sources without one.
    fn start_ns(&self) -> u64 {
        0
    }

    /// The last frame at or before `time_ns` (relative to the first frame).
    fn index_at_time(&self, time_ns: u64) -> usize;

    /// Frame `index`.
    ///
    /// # Errors
    /// Index out of range; the file's read error, naming it.
    fn read(&mut self, index: usize) -> Result<SourceFrame, SourceError>;

    /// Problems found while opening (skipped messages, truncation), for the status area.
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
}

/// How long one pass through a recording lasts when it is grabbed over and over, nanoseconds:
/// its span plus one mean frame interval, so the times of a live replay keep increasing.
fn lap_ns(r: &dyn RecordedSource) -> u64 {
    let n = r.len() as u64;
    let span = r.time_ns(r.len().saturating_sub(1));
    let interval = if n > 1 && span > 0 {
        span / (n - 1)
    } else {
        NOMINAL_FRAME_INTERVAL_NS
    };
    span + interval
}

/// The `next`-th grab of a recording played over and over: frame `next % len`, its time moved
/// on by one [`lap_ns`] per pass, so a live replay's times keep increasing.
fn grab_looping(r: &mut dyn RecordedSource, next: usize) -> Result<SourceFrame, SourceError> {
    let len = r.len().max(1);
    let (lap, index) = (next / len, next % len);
    let mut frame = r.read(index)?;
    frame.time_ns += lap as u64 * lap_ns(r);
    Ok(frame)
}

/// A source the user picked (Camera ▸ Connect…, the command line): turned into a connected
/// source by [`SourceSpec::open`], the one place each kind is built.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SourceSpec {
    /// A camera device (`/dev/video0`) and which camera it is: a robot's or one above the field
    /// (a USB camera can be either; the user says which).
    Camera {
        /// The device.
        device: PathBuf,
        /// Robot or overhead camera.
        kind: CameraKind,
    },
    /// A scenario of the synthetic renderer, played live.
    Synthetic {
        /// Which scenario.
        scenario: crate::sim::ScenarioKind,
        /// Its seed: the same seed plays the same frames.
        seed: u64,
    },
    /// A recorded MCAP stream.
    Stream(PathBuf),
    /// Frame files, in order.
    Files(Vec<PathBuf>),
    /// A robot or camera server over the network (Foxglove WebSocket, `ws://HOST:PORT`).
    Network(String),
}

impl SourceSpec {
    /// The source's kind.
    #[must_use]
    pub const fn kind(&self) -> SourceKind {
        match self {
            Self::Camera { .. } => SourceKind::Camera,
            Self::Synthetic { .. } => SourceKind::Synthetic,
            Self::Stream(_) => SourceKind::Stream,
            Self::Files(_) => SourceKind::Files,
            Self::Network(_) => SourceKind::Network,
        }
    }

    /// True for sources whose frames are all there already (streams, frame files): they are
    /// stepped and played; the others deliver frames live.
    #[must_use]
    pub const fn is_recorded(&self) -> bool {
        matches!(self, Self::Stream(_) | Self::Files(_))
    }

    /// Builds the source and connects it.
    ///
    /// # Errors
    /// The file, device or peer cannot be opened; a kind not built into this program.
    pub fn open(&self) -> Result<Box<dyn FrameSource>, SourceError> {
        let mut source: Box<dyn FrameSource> = match self {
            Self::Camera { device, kind } => open_camera(device, *kind)?,
            Self::Synthetic { scenario, seed } => Box::new(SyntheticSource::new(*scenario, *seed)),
            Self::Stream(path) => Box::new(StreamSource::open(path)?),
            Self::Files(paths) => Box::new(FileSource::new(paths.clone(), None)?),
            Self::Network(address) => {
                // Built by `crate::workspace` from `crate::live`, which comes after this module.
                return Err(SourceError::Unsupported {
                    label: address.clone(),
                    detail: "a network source is opened through the workspace".to_owned(),
                });
            }
        };
        source.connect()?;
        Ok(source)
    }

    /// Builds a recorded source (stream or frame files) for stepping and playback.
    ///
    /// # Errors
    /// As [`Self::open`]; a live source, which has no frames by index.
    pub fn open_recorded(&self) -> Result<Box<dyn RecordedSource>, SourceError> {
        match self {
            Self::Stream(path) => Ok(Box::new(StreamSource::open(path)?)),
            Self::Files(paths) => Ok(Box::new(FileSource::new(paths.clone(), None)?)),
            other => Err(SourceError::Unsupported {
                label: other.kind().name().to_owned(),
                detail: "a live source has no recorded frames to step through".to_owned(),
            }),
        }
    }
}

#[cfg(target_os = "linux")]
fn open_camera(
    path: &std::path::Path,
    kind: CameraKind,
) -> Result<Box<dyn FrameSource>, SourceError> {
    Ok(Box::new(CameraSource::new(path, kind)))
}

#[cfg(not(target_os = "linux"))]
fn open_camera(
    path: &std::path::Path,
    _kind: CameraKind,
) -> Result<Box<dyn FrameSource>, SourceError> {
    Err(SourceError::Unsupported {
        label: path.display().to_string(),
        detail: "cameras are read through V4L2, which only Linux has".to_owned(),
    })
}

/// The sources that can be connected on this machine, for `eotn sources` and the Connect
/// dialog: cameras found (with a one-line note when there are none) and the scenarios.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Available {
    /// Cameras found: (device path, name).
    pub cameras: Vec<(PathBuf, String)>,
    /// Why there are no cameras, in one line (`"no camera found (no /dev/video*)"`).
    pub camera_note: Option<String>,
    /// Scenarios the synthetic source plays.
    pub scenarios: Vec<crate::sim::ScenarioKind>,
}

/// Lists what can be connected now; never fails (a machine without cameras lists none).
#[must_use]
pub fn available() -> Available {
    let (cameras, camera_note) = list_cameras();
    Available {
        cameras,
        camera_note,
        scenarios: crate::sim::ScenarioKind::ALL.to_vec(),
    }
}

/// Camera devices (`/dev/video*`) with the names their drivers give, or a one-line note why there
/// are none.
#[cfg(target_os = "linux")]
fn list_cameras() -> (Vec<(PathBuf, String)>, Option<String>) {
    let mut cameras: Vec<(PathBuf, String)> = v4l::context::enum_devices()
        .into_iter()
        .map(|node| {
            let path = node.path().to_owned();
            let name = node
                .name()
                .unwrap_or_else(|| crate::frame::display_name(&path));
            (path, name)
        })
        .collect();
    cameras.sort();
    if cameras.is_empty() {
        return (
            Vec::new(),
            Some("no camera found (no /dev/video*)".to_owned()),
        );
    }
    (cameras, None)
}

/// Camera devices: none where there is no V4L2.
#[cfg(not(target_os = "linux"))]
fn list_cameras() -> (Vec<(PathBuf, String)>, Option<String>) {
    (
        Vec::new(),
        Some("no camera found (cameras need Linux's V4L2)".to_owned()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overhead_streams_are_overhead_cameras_and_the_rest_robots() {
        assert_eq!(
            CameraKind::of_stream_source("overhead"),
            CameraKind::Overhead
        );
        assert_eq!(
            CameraKind::of_stream_source("sim:overhead-game"),
            CameraKind::Overhead
        );
        assert_eq!(CameraKind::of_stream_source("robot"), CameraKind::Robot);
        // A session recording's robot cameras are robots'; its overhead camera is not.
        let session = crate::streams::WMD_SESSION_SOURCE;
        assert_eq!(
            CameraKind::of_stream_camera(session, Some("/robot/blue-3")),
            CameraKind::Robot
        );
        assert_eq!(
            CameraKind::of_stream_camera(session, Some("/camera/image")),
            CameraKind::Overhead
        );
        assert_eq!(
            CameraKind::of_stream_camera("robot", Some("/camera/image")),
            CameraKind::Robot
        );
        assert_eq!(
            CameraKind::of_stream_source("bhuman2009"),
            CameraKind::Robot
        );
        assert_eq!(CameraKind::of_stream_source(""), CameraKind::Robot);
        for k in [CameraKind::Robot, CameraKind::Overhead] {
            assert_eq!(CameraKind::of_stream_source(&k.stream_source()), k);
        }
    }

    #[test]
    fn listing_the_sources_never_fails_and_names_every_scenario() {
        let a = available();
        assert_eq!(a.scenarios.len(), crate::sim::ScenarioKind::ALL.len());
        assert_eq!(a.cameras.is_empty(), a.camera_note.is_some());
    }
}
