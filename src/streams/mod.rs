//! Recorded streams: camera frames with the robot's sensor readings, ground truth and recognition
//! results, in one MCAP file that Foxglove and other MCAP tools open.
//!
//! One frame is one message on [`IMAGE_TOPIC`] (`foxglove.RawImage`, protobuf; frames eotn makes
//! are `yuyv` or `uyvy` with `step` = 2 × width bytes; images imported from other recordings keep
//! their own encoding and step) or, for images that came compressed, on
//! [`COMPRESSED_IMAGE_TOPIC`] (`foxglove.CompressedImage`, JPEG or PNG, unchanged). The frame's other data are JSON messages with the image's log time,
//! written right after it in the same chunk: [`SENSORS_TOPIC`] (a [`SensorReadings`]),
//! [`GROUND_TRUTH_TOPIC`], [`RECOGNITION_TOPIC`] and any extra JSON channels (for example
//! `/world_model/robot3`). Every JSON channel has a `jsonschema` schema. The stream's
//! [`StreamInfo`] is an MCAP metadata record named [`METADATA_NAME`].
//!
//! [`StreamWriter`] writes chunks of a few frames (zstd by default) with message and chunk
//! indexes; each finished chunk is flushed to the file, so a recording cut off by a crash stays
//! readable up to its last complete chunk. [`StreamReader`] finds frames through the summary's
//! chunk indexes and the image channel's message indexes, and reads only the one chunk a frame is
//! in (the last chunk stays cached), so memory stays flat however long the file is; when the
//! summary is missing it recovers by scanning the complete chunks, and says so in
//! [`StreamReader::warnings`]. Any valid MCAP file opens (the MCAP conformance suite is a test):
//! one whose summary does not describe it whole is read through its data section, messages
//! outside chunks included; [`StreamReader::channels`] lists every channel with its message
//! count, whatever it carries.
//!
//! [`StreamReader`] reads other recordings too: MCAP files of other writers and ROS 2 bags
//! ([`rosbag2`]: folders with `metadata.yaml`, SQLite or MCAP storage), their images in any
//! encoding through [`crate::formats`].

pub mod camera_info;
mod reader;
pub mod rosbag2;
pub mod schema;
pub mod sensor_table;
pub mod world_models;
mod writer;

use std::path::PathBuf;

pub use reader::{
    CAMERA_CHOICE_NOTE, ChannelSummary, ImageTopic, RecordCounts, SchemaSummary, StreamMessage,
    StreamReader,
};
pub use rosbag2::{is_bag_folder, is_recording};
pub use writer::{Compression, RawChannelSpec, StreamWriter, WriterOptions};

use crate::frame::Frame;
use crate::sensors::SensorReadings;

pub use crate::camera::{CAMERA_METADATA_NAME, COMPRESSED_IMAGE_TOPIC, IMAGE_TOPIC};
/// Topic of the sensor readings channel (JSON, schema `eotn.SensorReadings`).
pub const SENSORS_TOPIC: &str = "/sensors";
/// Topic of the ground-truth channel (JSON object, free form; written by renderers/simulators).
pub const GROUND_TRUTH_TOPIC: &str = "/ground_truth";
/// Topic of the recognition-results channel (JSON object, free form; written by the pipeline).
pub const RECOGNITION_TOPIC: &str = "/recognition";
/// Topic of the recognition results drawn as `foxglove.ImageAnnotations` (protobuf) over the
/// camera image, so Foxglove and Rerun show eotn's overlays (`eotn detect --annotate`).
pub const ANNOTATIONS_TOPIC: &str = "/camera/annotations";
/// Name of the MCAP metadata record that holds the [`StreamInfo`].
pub const METADATA_NAME: &str = "eotn.stream";
/// Name of the MCAP metadata record naming the recognition parameter set a stream is meant for
/// (key `params`, e.g. `spl2009` for `params/spl2009.json`).
pub const PARAMS_METADATA_NAME: &str = "eotn.recognition";

/// The parameter set streams of this source kind need when they do not name one: B-Human 2009
/// streams (the SPL field through a Nao camera) need `spl2009`; every other kind runs on the
/// defaults.
#[must_use]
pub fn param_set_of_source(source: &str) -> Option<&'static str> {
    (source == "bhuman2009").then_some("spl2009")
}

/// Version of the stream layout written by this crate (metadata key `format_version`).
pub const FORMAT_VERSION: &str = "1";
/// The stream source (`StreamInfo::source`) of a World Model Debugger session recording
/// (`eotn wmd -o`). It names "overhead": the stream is the overhead camera's; its robot cameras
/// (`/robot/…`) are robots' ([`crate::camera::SESSION_ROBOT_TOPIC_PREFIX`]).
pub const WMD_SESSION_SOURCE: &str = "overhead:wmd-session";

/// What a stream is: where its frames came from and a free description.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct StreamInfo {
    /// Kind of source: `"robot"`, `"overhead"`, `"sim:SCENARIO"`, `"bhuman2009"`, `"import"`, …
    pub source: String,
    /// Free text for people (what was recorded, where, when).
    pub description: String,
}

/// One frame of a stream with everything recorded for it.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameRecord {
    /// Capture time, nanoseconds since the stream's start (or since the Unix epoch).
    pub time_ns: u64,
    /// The camera image (stored as UYVY; 4:4:4 frames are converted when written).
    pub frame: Frame,
    /// The robot's sensor readings, channel [`SENSORS_TOPIC`].
    pub sensors: Option<SensorReadings>,
    /// Ground truth, channel [`GROUND_TRUTH_TOPIC`].
    pub ground_truth: Option<serde_json::Value>,
    /// Recognition results, channel [`RECOGNITION_TOPIC`].
    pub recognition: Option<serde_json::Value>,
    /// Other JSON channels as (topic, value), e.g. `("/world_model/robot3", …)`.
    pub extra: Vec<(String, serde_json::Value)>,
    /// Overlays for other viewers, channel [`ANNOTATIONS_TOPIC`].
    pub annotations: Option<foxglove::messages::ImageAnnotations>,
}

impl FrameRecord {
    /// A record with only the image.
    #[must_use]
    pub fn new(time_ns: u64, frame: Frame) -> Self {
        Self {
            time_ns,
            frame,
            sensors: None,
            ground_truth: None,
            recognition: None,
            extra: Vec::new(),
            annotations: None,
        }
    }
}

/// Why a stream could not be written or read; the message always names the file.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// The operating system refused to open, read, write or rename the file.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The file does not start with the MCAP magic bytes.
    #[error("{path}: not an MCAP stream ({detail})")]
    NotMcap {
        /// The file.
        path: PathBuf,
        /// What was found instead.
        detail: String,
    },
    /// The MCAP library reported a malformed record, bad CRC, failed decompression, or the
    /// file could not be written (a full disk, a full device).
    #[error("{path}: {context}: {}", mcap_error_text(cause))]
    Mcap {
        /// The file.
        path: PathBuf,
        /// What we were doing.
        context: String,
        /// The MCAP library's error; its text, with its cause, is part of this error's, so
        /// every caller shows "No space left on device" however it prints the error.
        cause: mcap::McapError,
    },
    /// The file is MCAP but its contents do not make sense (bad index, broken message).
    #[error("{path}: {detail}")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
    /// A frame index past the end of the stream.
    #[error("{path}: no frame {index} (the stream has {len} frames)")]
    NoSuchFrame {
        /// The file.
        path: PathBuf,
        /// Index asked for.
        index: usize,
        /// Number of frames.
        len: usize,
    },
    /// The camera asked for (`--camera TOPIC`) is not among the recording's image topics.
    #[error("{path}: no camera {topic}; its cameras: {}", if cameras.is_empty() { "none".to_owned() } else { cameras.join(", ") })]
    NoSuchCamera {
        /// The recording.
        path: PathBuf,
        /// The topic asked for.
        topic: String,
        /// The image topics there are.
        cameras: Vec<String>,
    },
    /// A record the writer cannot store (odd width, unserialisable JSON, bad topic).
    #[error("{path}: cannot write frame at {time_ns} ns: {detail}")]
    BadRecord {
        /// The file.
        path: PathBuf,
        /// The record's time, nanoseconds.
        time_ns: u64,
        /// What is wrong.
        detail: String,
    },
}

/// The MCAP library's error said with its cause: its I/O errors by the system's own words (its
/// own text, "I/O error from writing, or reading a compression stream", hides them).
fn mcap_error_text(e: &mcap::McapError) -> String {
    if let mcap::McapError::Io(io) = e {
        return io.to_string();
    }
    let mut text = e.to_string();
    let mut cause = std::error::Error::source(e);
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

/// True when the path looks like an MCAP stream (`.mcap`, or `.mcap.partial` as a killed writer
/// leaves it, or `.mcap.partial.N` as the next writer moved it aside; any case): what eotn
/// writes. Inputs are told by [`is_recording`], which also takes
/// rosbag2 bags.
#[must_use]
pub fn is_stream_file(path: &std::path::Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    // `NAME.mcap.partial` is a stream whose writer was killed: readable to its last chunk.
    name.ends_with(".mcap")
        || name.rsplit_once(".mcap.partial").is_some_and(|(_, rest)| {
            crate::atomic_file::is_partial_name(&format!(".partial{rest}"))
        })
}
