//! [`LiveRecorder`]: every message of a live robot into an MCAP stream, bit-exact, in arrival
//! order, through the project's [`StreamWriter`].
//!
//! Chunks hold one frame each (its image and the JSON that follows it) and are closed when the
//! next image arrives, or [`LiveRecorder::tick`] finds the robot quiet, so a recording cut off by
//! a crash or `kill -9` is readable as `OUT.partial` up to its last frame or so.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::RobotUrl;
use super::protocol::AdvertisedChannel;
use crate::streams::{
    Compression, RawChannelSpec, StreamError, StreamInfo, StreamWriter, WriterOptions,
};

/// A chunk with messages in it is closed after this long without a new image.
const QUIET_CLOSE: Duration = Duration::from_millis(200);

/// Distinct channels one recording holds (a channel advertised again with another encoding or
/// schema counts as another). Messages on channels past it are not written: a robot that
/// advertises new channels without end (withdrawing each before the next) cannot grow the
/// recorder's memory or the file's summary without bound.
pub const MAX_CHANNELS: usize = 256;

/// Longest file-name stem [`file_stem`] makes from a robot's name, bytes (file systems allow
/// 255, and `-N.mcap.partial` follows it).
pub const MAX_STEM_BYTES: usize = 100;

/// What became of one message given to [`LiveRecorder::message`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Recorded {
    /// Written.
    Written,
    /// Not written: its channel would be one more than [`MAX_CHANNELS`].
    OverChannelLimit,
    /// Not written: the image channel of a camera not chosen (`eotn record --camera`), or one
    /// of that camera's own channels (`TOPIC/…`, a ROS `NS/camera_info` beside `NS/image_raw`).
    OtherCamera,
}

/// An open recording of one robot.
#[derive(Debug)]
pub struct LiveRecorder {
    path: PathBuf,
    writer: StreamWriter,
    /// The channels written so far, as the writer knows them (topic, encodings, schema): a
    /// channel advertised again differently is written as a new channel. At most
    /// [`MAX_CHANNELS`].
    written: HashSet<Arc<RawChannelSpec>>,
    /// Each advertised channel (ids change on reconnection) → its entry of `written`; a cache of
    /// at most [`MAX_CHANNELS`] entries, emptied when full.
    specs: HashMap<Arc<AdvertisedChannel>, Arc<RawChannelSpec>>,
    /// Messages not written because of [`MAX_CHANNELS`].
    over_limit: u64,
    messages: u64,
    unflushed: bool,
    last_write: Instant,
    /// The cameras (image topics) kept; empty: every camera.
    cameras: Vec<String>,
    /// Image topics seen that are not kept: their own channels are not written either.
    dropped_cameras: HashSet<String>,
}

impl LiveRecorder {
    /// Starts recording into `path` (written as `path.partial` until [`LiveRecorder::finish`]).
    ///
    /// # Errors
    /// [`StreamError`] naming the file when it cannot be created.
    pub fn create(path: &Path, info: &StreamInfo) -> Result<Self, StreamError> {
        let options = WriterOptions {
            // LZ4: a live recording must keep up with several robots on one core.
            compression: Compression::Lz4,
            frames_per_chunk: Some(1),
            ..WriterOptions::default()
        };
        Ok(Self {
            path: path.to_owned(),
            writer: StreamWriter::create_with(path, info, options)?,
            written: HashSet::new(),
            specs: HashMap::new(),
            over_limit: 0,
            messages: 0,
            unflushed: false,
            last_write: Instant::now(),
            cameras: Vec::new(),
            dropped_cameras: HashSet::new(),
        })
    }

    /// Keeps only these cameras (image topics; empty: every camera, as recorded by default).
    #[must_use]
    pub fn only_cameras(mut self, topics: Vec<String>) -> Self {
        self.cameras = topics;
        self
    }

    /// Whether a message on `channel` belongs to a camera not kept.
    fn other_camera(&mut self, channel: &AdvertisedChannel) -> bool {
        if self.cameras.is_empty() {
            return false;
        }
        let topic = channel.topic.as_str();
        let image = crate::formats::MessageKind::of(&channel.schema_name, &channel.encoding)
            .is_some_and(crate::formats::MessageKind::is_image);
        if image {
            let kept = self.cameras.iter().any(|c| c == topic);
            if !kept && self.dropped_cameras.len() < MAX_CHANNELS {
                self.dropped_cameras.insert(topic.to_owned());
            }
            return !kept;
        }
        self.dropped_cameras.iter().any(|camera| {
            let namespace = camera
                .strip_suffix("/image_raw")
                .or_else(|| camera.strip_suffix("/image"));
            topic
                .strip_prefix(camera.as_str())
                .is_some_and(|rest| rest.starts_with('/'))
                || namespace.is_some_and(|ns| topic == format!("{ns}/camera_info"))
        })
    }

    /// Where the finished recording goes.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Frames (image messages) written so far.
    #[must_use]
    pub fn frames(&self) -> usize {
        self.writer.frames()
    }

    /// Messages of all channels written so far.
    #[must_use]
    pub fn messages(&self) -> u64 {
        self.messages
    }

    /// Messages not written so far because the recording had [`MAX_CHANNELS`] channels.
    #[must_use]
    pub fn over_limit(&self) -> u64 {
        self.over_limit
    }

    /// Appends one message exactly as it arrived (unless its channel would be one too many).
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn message(
        &mut self,
        channel: &Arc<AdvertisedChannel>,
        log_time_ns: u64,
        payload: &[u8],
    ) -> Result<Recorded, StreamError> {
        if self.other_camera(channel) {
            return Ok(Recorded::OtherCamera);
        }
        let spec = match self.specs.get(channel) {
            Some(spec) => Arc::clone(spec),
            None => {
                let spec = raw_spec(channel);
                let spec = match self.written.get(&spec) {
                    Some(known) => Arc::clone(known),
                    None if self.written.len() >= MAX_CHANNELS => {
                        self.over_limit += 1;
                        return Ok(Recorded::OverChannelLimit);
                    }
                    None => {
                        let spec = Arc::new(spec);
                        self.written.insert(Arc::clone(&spec));
                        spec
                    }
                };
                if self.specs.len() >= MAX_CHANNELS {
                    self.specs.clear();
                }
                self.specs.insert(Arc::clone(channel), Arc::clone(&spec));
                spec
            }
        };
        self.writer.write_raw(&spec, log_time_ns, payload)?;
        self.messages += 1;
        self.unflushed = true;
        self.last_write = Instant::now();
        Ok(Recorded::Written)
    }

    /// Closes the open chunk when nothing has arrived for a while (call it now and then).
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn tick(&mut self) -> Result<(), StreamError> {
        if self.unflushed && self.last_write.elapsed() >= QUIET_CLOSE {
            self.unflushed = false;
            self.writer.close_chunk()?;
        }
        Ok(())
    }

    /// Writes the indexes and renames the file into place; returns its path.
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn finish(self) -> Result<PathBuf, StreamError> {
        self.writer.finish()?;
        Ok(self.path)
    }
}

/// How the writer records a channel: as it was advertised.
fn raw_spec(channel: &AdvertisedChannel) -> RawChannelSpec {
    RawChannelSpec {
        topic: channel.topic.clone(),
        message_encoding: channel.encoding.clone(),
        schema_name: channel.schema_name.clone(),
        schema_encoding: channel.schema_encoding.clone(),
        schema: channel.schema.clone(),
    }
}

/// A recording's file name (without `.mcap`) from a robot's server name: letters, digits, `-`,
/// `_`, `.` kept, the rest `_`, at most [`MAX_STEM_BYTES`]; the address when nothing is left.
#[must_use]
pub fn file_stem(name: &str, url: &RobotUrl) -> String {
    let stem: String = name
        .chars()
        .take(MAX_STEM_BYTES)
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stem = stem.trim_matches('.');
    if stem.is_empty() {
        format!("{}_{}", url.host, url.port)
    } else {
        stem.to_owned()
    }
}
