//! [`LiveRecorder`]: every message of a live robot into an MCAP stream, bit-exact, in arrival
//! order, through the project's [`StreamWriter`].
//!
//! Chunks hold one frame each (its image and the JSON that follows it) and are closed when the
//! next image arrives, or [`LiveRecorder::tick`] finds the robot quiet, so a recording cut off by
//! a crash or `kill -9` is readable as `OUT.partial` up to its last frame or so.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::RobotUrl;
use super::protocol::AdvertisedChannel;
use crate::streams::{
    Compression, RawChannelSpec, StreamError, StreamInfo, StreamWriter, WriterOptions,
};

/// A chunk with messages in it is closed after this long without a new image.
const QUIET_CLOSE: Duration = Duration::from_millis(200);

/// An open recording of one robot.
#[derive(Debug)]
pub struct LiveRecorder {
    path: PathBuf,
    writer: StreamWriter,
    /// The writer's view of each channel, by (channel id, topic): ids change on reconnection.
    specs: HashMap<(u32, String), RawChannelSpec>,
    messages: u64,
    unflushed: bool,
    last_write: Instant,
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
            specs: HashMap::new(),
            messages: 0,
            unflushed: false,
            last_write: Instant::now(),
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

    /// Appends one message exactly as it arrived.
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn message(
        &mut self,
        channel: &AdvertisedChannel,
        log_time_ns: u64,
        payload: &[u8],
    ) -> Result<(), StreamError> {
        let key = (channel.id, channel.topic.clone());
        let spec = self.specs.entry(key).or_insert_with(|| RawChannelSpec {
            topic: channel.topic.clone(),
            message_encoding: channel.encoding.clone(),
            schema_name: channel.schema_name.clone(),
            schema_encoding: channel.schema_encoding.clone(),
            schema: channel.schema.clone(),
        });
        self.writer.write_raw(spec, log_time_ns, payload)?;
        self.messages += 1;
        self.unflushed = true;
        self.last_write = Instant::now();
        Ok(())
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

/// A recording's file name (without `.mcap`) from a robot's server name: letters, digits, `-`,
/// `_`, `.` kept, the rest `_`; the address when nothing is left.
#[must_use]
pub fn file_stem(name: &str, url: &RobotUrl) -> String {
    let stem: String = name
        .chars()
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
