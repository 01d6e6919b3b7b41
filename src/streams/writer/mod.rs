//! [`StreamWriter`]: frames and their data into a chunked, indexed MCAP file.

use std::collections::{BTreeMap, HashMap};
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use foxglove::Encode as _;
use mcap::records::MessageHeader;

use crate::atomic_file::{OutputTarget, PartialFile};

mod cameras;
use crate::formats::{ImageMessage, MessageKind};

use super::schema::{
    EXTRA_SCHEMA_NAME, GROUND_TRUTH_SCHEMA_NAME, ImageEncoding, RECOGNITION_SCHEMA_NAME,
    SENSORS_SCHEMA_NAME, any_json_schema, encode_image, object_json_schema, raw_image_schema,
    sensors_json_schema,
};
use super::{
    ANNOTATIONS_TOPIC, COMPRESSED_IMAGE_TOPIC, FORMAT_VERSION, FrameRecord, GROUND_TRUTH_TOPIC,
    IMAGE_TOPIC, METADATA_NAME, PARAMS_METADATA_NAME, RECOGNITION_TOPIC, SENSORS_TOPIC,
    StreamError, StreamInfo,
};

/// How chunks are compressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Compression {
    /// Zstandard: smaller files (the default).
    #[default]
    Zstd,
    /// LZ4: faster to write and read, larger.
    Lz4,
    /// No compression.
    None,
}

/// Tuning of a [`StreamWriter`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WriterOptions {
    /// Chunk compression.
    pub compression: Compression,
    /// Frames per chunk; `None` chooses about 1 MiB of image data per chunk (16 robot-camera
    /// frames, 1 overhead frame). Fewer frames per chunk: faster random access, larger files,
    /// less lost in a crash.
    pub frames_per_chunk: Option<usize>,
    /// Byte order of the frames in the stream (`yuyv` unless asked: Rerun reads only that one).
    pub image_encoding: ImageEncoding,
}

/// Uncompressed image bytes aimed at per chunk when [`WriterOptions::frames_per_chunk`] is `None`.
const TARGET_CHUNK_BYTES: usize = 1 << 20;
/// Most frames in one chunk when the writer chooses.
const MAX_FRAMES_PER_CHUNK: usize = 16;

/// Writes a stream: one [`FrameRecord`] at a time, each frame's messages in one chunk.
///
/// The file is written through [`crate::atomic_file`]'s [`PartialFile`]: as `PATH.partial`,
/// locked against a second writer, renamed to `PATH` by [`StreamWriter::finish`], so an existing
/// stream is never replaced by a half-written one and an earlier crashed `PATH.partial` is moved
/// aside rather than truncated; a device or FIFO is written front to back in place. Each finished
/// chunk is flushed to the `.partial` file: after a crash it is readable (by
/// [`super::StreamReader`]) up to its last complete chunk.
pub struct StreamWriter {
    path: PathBuf,
    /// The file written until [`StreamWriter::finish`] (the device itself when written in place).
    partial: PathBuf,
    /// Where an earlier unfinished `PATH.partial` was moved.
    moved_aside: Option<PathBuf>,
    mcap: mcap::Writer<BufWriter<PartialFile>>,
    /// `/camera/image` and `/sensors`, added with the first message of either (`/sensors` with
    /// the image, as one-camera streams always had it): a stream whose cameras all have topics of
    /// their own has no empty first-camera channels.
    image_channel: Option<u16>,
    sensors_channel: Option<u16>,
    lazy_channels: HashMap<String, u16>,
    annotations_channel: Option<u16>,
    compressed_channel: Option<u16>,
    /// Image channels of cameras other than the first, by topic and compressed or not.
    camera_images: HashMap<(String, bool), u16>,
    frames_per_chunk: Option<usize>,
    image_encoding: ImageEncoding,
    frames_in_chunk: usize,
    frames: u32,
    buf: Vec<u8>,
    /// Channels of [`StreamWriter::write_raw`] (other than the fixed two) by their whole
    /// description: a topic advertised again with another encoding or schema is a new channel.
    raw_channels: HashMap<RawChannelSpec, u16>,
}

/// A channel whose messages are recorded as they arrive ([`StreamWriter::write_raw`]): a live
/// robot's channel as its server advertised it.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct RawChannelSpec {
    /// Topic, e.g. `/camera/image`.
    pub topic: String,
    /// Message encoding (`protobuf`, `json`, …).
    pub message_encoding: String,
    /// Schema name, e.g. `foxglove.RawImage`; empty for none.
    pub schema_name: String,
    /// Schema encoding (`protobuf`, `jsonschema`, …).
    pub schema_encoding: String,
    /// Schema bytes.
    pub schema: Vec<u8>,
}

impl RawChannelSpec {
    /// True for the stream's image channel: `/camera/image` as protobuf `foxglove.RawImage`.
    #[must_use]
    pub fn is_image(&self) -> bool {
        self.topic == IMAGE_TOPIC
            && self.message_encoding == "protobuf"
            && self.schema_name == "foxglove.RawImage"
    }

    /// True for any camera image channel eotn reads (`foxglove.RawImage`, `CompressedImage`,
    /// `sensor_msgs/msg/Image`, …, see [`MessageKind`]): its messages are frames.
    #[must_use]
    pub fn is_frame(&self) -> bool {
        MessageKind::of(&self.schema_name, &self.message_encoding)
            .is_some_and(MessageKind::is_image)
    }
}

impl std::fmt::Debug for StreamWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamWriter")
            .field("path", &self.path)
            .field("frames", &self.frames)
            .finish_non_exhaustive()
    }
}

impl StreamWriter {
    /// Starts a stream at `path` with the default options (zstd, about 1 MiB per chunk).
    ///
    /// # Errors
    /// [`StreamError`] naming the file when it cannot be created.
    pub fn create(path: &Path, info: &StreamInfo) -> Result<Self, StreamError> {
        Self::create_with(path, info, WriterOptions::default())
    }

    /// Starts a stream at `path` with the given options.
    ///
    /// # Errors
    /// [`StreamError`] naming the file when it cannot be created.
    pub fn create_with(
        path: &Path,
        info: &StreamInfo,
        options: WriterOptions,
    ) -> Result<Self, StreamError> {
        let io = |source| StreamError::Io {
            path: path.to_owned(),
            source,
        };
        let file = OutputTarget::open(path)
            .and_then(|t| t.create_partial())
            .map_err(io)?;
        let partial = file.partial().unwrap_or(file.path()).to_owned();
        let moved_aside = file.moved_aside().map(Path::to_owned);
        let seekable = file.seekable();
        let mcap_err = |context: &str| {
            let path = partial.clone();
            let context = context.to_owned();
            move |cause| StreamError::Mcap {
                path,
                context,
                cause,
            }
        };
        let compression = match options.compression {
            Compression::Zstd => Some(mcap::Compression::Zstd),
            Compression::Lz4 => Some(mcap::Compression::Lz4),
            Compression::None => None,
        };
        let mut mcap = mcap::WriteOptions::new()
            .compression(compression)
            .chunk_size(None)
            .compression_threads(1)
            .profile("")
            .library(concat!("eotn ", env!("CARGO_PKG_VERSION")))
            // A device or FIFO is written front to back: chunks are assembled in memory.
            .disable_seeking(!seekable)
            .create(BufWriter::with_capacity(1 << 20, file))
            .map_err(mcap_err("cannot start the MCAP file"))?;
        let metadata = mcap::records::Metadata {
            name: METADATA_NAME.to_owned(),
            metadata: BTreeMap::from([
                ("source".to_owned(), info.source.clone()),
                ("description".to_owned(), info.description.clone()),
                ("format_version".to_owned(), FORMAT_VERSION.to_owned()),
                (
                    "writer".to_owned(),
                    concat!("eotn ", env!("CARGO_PKG_VERSION")).to_owned(),
                ),
            ]),
        };
        mcap.write_metadata(&metadata)
            .map_err(mcap_err("cannot write the stream metadata"))?;
        Ok(Self {
            path: path.to_owned(),
            partial,
            moved_aside,
            mcap,
            image_channel: None,
            sensors_channel: None,
            lazy_channels: HashMap::new(),
            annotations_channel: None,
            compressed_channel: None,
            camera_images: HashMap::new(),
            frames_per_chunk: options.frames_per_chunk.map(|n| n.max(1)),
            image_encoding: options.image_encoding,
            frames_in_chunk: 0,
            frames: 0,
            buf: Vec::new(),
            raw_channels: HashMap::new(),
        })
    }

    /// Where an earlier unfinished `PATH.partial` (a crashed recording) was moved when this
    /// writer started (a warning said so too).
    #[must_use]
    pub fn moved_aside(&self) -> Option<&Path> {
        self.moved_aside.as_deref()
    }

    /// Number of frames written so far.
    #[must_use]
    pub fn frames(&self) -> usize {
        self.frames as usize
    }

    fn mcap_err(&self, context: &str) -> impl FnOnce(mcap::McapError) -> StreamError {
        let path = self.partial.clone();
        let context = context.to_owned();
        move |cause| StreamError::Mcap {
            path,
            context,
            cause,
        }
    }

    /// The `foxglove.CompressedImage` channel, added with the first compressed frame.
    fn compressed_channel(&mut self) -> Result<u16, StreamError> {
        if let Some(id) = self.compressed_channel {
            return Ok(id);
        }
        let schema = foxglove::messages::CompressedImage::get_schema().ok_or_else(|| {
            StreamError::Corrupt {
                path: self.partial.clone(),
                detail: "the foxglove.CompressedImage schema is not available".to_owned(),
            }
        })?;
        let schema_id = self
            .mcap
            .add_schema(&schema.name, &schema.encoding, &schema.data)
            .map_err(self.mcap_err("cannot add the compressed image schema"))?;
        let id = self
            .mcap
            .add_channel(
                schema_id,
                COMPRESSED_IMAGE_TOPIC,
                "protobuf",
                &BTreeMap::new(),
            )
            .map_err(self.mcap_err("cannot add the compressed image channel"))?;
        self.compressed_channel = Some(id);
        Ok(id)
    }

    /// The `foxglove.ImageAnnotations` channel, added with the first annotated frame.
    fn annotations_channel(&mut self) -> Result<u16, StreamError> {
        if let Some(id) = self.annotations_channel {
            return Ok(id);
        }
        let id = self.add_annotations_channel(ANNOTATIONS_TOPIC)?;
        self.annotations_channel = Some(id);
        Ok(id)
    }

    /// Adds a `foxglove.ImageAnnotations` channel on `topic` (with its schema).
    pub(super) fn add_annotations_channel(&mut self, topic: &str) -> Result<u16, StreamError> {
        let schema = foxglove::messages::ImageAnnotations::get_schema().ok_or_else(|| {
            StreamError::Corrupt {
                path: self.partial.clone(),
                detail: "the foxglove.ImageAnnotations schema is not available".to_owned(),
            }
        })?;
        let schema_id = self
            .mcap
            .add_schema(&schema.name, &schema.encoding, &schema.data)
            .map_err(self.mcap_err("cannot add the annotations schema"))?;
        self.mcap
            .add_channel(schema_id, topic, "protobuf", &BTreeMap::new())
            .map_err(self.mcap_err("cannot add an annotations channel"))
    }

    fn json_channel(&mut self, topic: &str) -> Result<u16, StreamError> {
        if let Some(&id) = self.lazy_channels.get(topic) {
            return Ok(id);
        }
        let (name, schema) = match topic {
            GROUND_TRUTH_TOPIC => (
                GROUND_TRUTH_SCHEMA_NAME,
                object_json_schema(
                    GROUND_TRUTH_SCHEMA_NAME,
                    "What was really in the frame (from a renderer or simulator).",
                ),
            ),
            RECOGNITION_TOPIC => (
                RECOGNITION_SCHEMA_NAME,
                object_json_schema(
                    RECOGNITION_SCHEMA_NAME,
                    "What the vision pipeline recognised in the frame.",
                ),
            ),
            _ => (EXTRA_SCHEMA_NAME, any_json_schema()),
        };
        let schema_id = self
            .mcap
            .add_schema(name, "jsonschema", schema.to_string().as_bytes())
            .map_err(self.mcap_err("cannot add a schema"))?;
        let id = self
            .mcap
            .add_channel(schema_id, topic, "json", &BTreeMap::new())
            .map_err(self.mcap_err("cannot add a channel"))?;
        self.lazy_channels.insert(topic.to_owned(), id);
        Ok(id)
    }

    fn put(&mut self, channel_id: u16, time_ns: u64, data: &[u8]) -> Result<(), StreamError> {
        let header = MessageHeader {
            channel_id,
            sequence: self.frames,
            log_time: time_ns,
            publish_time: time_ns,
        };
        self.mcap
            .write_to_known_channel(&header, data)
            .map_err(self.mcap_err("cannot write a message"))
    }

    /// Names the recognition parameter set the stream is meant for (`"spl2009"` reads
    /// `params/spl2009.json`): a [`PARAMS_METADATA_NAME`] metadata record the app offers.
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn name_param_set(&mut self, name: &str) -> Result<(), StreamError> {
        let metadata = mcap::records::Metadata {
            name: PARAMS_METADATA_NAME.to_owned(),
            metadata: BTreeMap::from([("params".to_owned(), name.to_owned())]),
        };
        let path = self.partial.clone();
        self.mcap
            .write_metadata(&metadata)
            .map_err(|cause| StreamError::Mcap {
                path,
                context: "cannot write the parameter set's metadata".to_owned(),
                cause,
            })
    }

    /// Names the default files of the camera `topic` (its table, parameters, calibration): an
    /// `eotn.camera` metadata record, which a sidecar beside the stream overrides
    /// ([`crate::camera::files_for`]).
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn name_camera_files(
        &mut self,
        topic: &str,
        files: &crate::camera::CameraFiles,
    ) -> Result<(), StreamError> {
        let metadata = mcap::records::Metadata {
            name: crate::camera::CAMERA_METADATA_NAME.to_owned(),
            metadata: files.to_metadata(topic),
        };
        self.mcap
            .write_metadata(&metadata)
            .map_err(self.mcap_err("cannot write a camera's metadata"))
    }

    /// Appends one frame with its data. Non-finite sensor values are written as `null`.
    ///
    /// # Errors
    /// [`StreamError::BadRecord`] for an image that cannot be UYVY (odd width) or a reserved
    /// extra topic; I/O errors naming the file.
    pub fn write(&mut self, record: &FrameRecord) -> Result<(), StreamError> {
        self.write_with_image(record, None)
    }

    /// Appends one frame with its data, its image stored as the message it came in when `image`
    /// is given: raw pixels as a `foxglove.RawImage` on [`IMAGE_TOPIC`] in their own encoding,
    /// step and bytes; compressed ones as a `foxglove.CompressedImage` on
    /// [`COMPRESSED_IMAGE_TOPIC`], bytes unchanged. Readers convert them when they read.
    ///
    /// # Errors
    /// As [`StreamWriter::write`].
    pub fn write_with_image(
        &mut self,
        record: &FrameRecord,
        image: Option<&ImageMessage>,
    ) -> Result<(), StreamError> {
        let path = self.path.clone();
        let bad = |detail: String| StreamError::BadRecord {
            path: path.clone(),
            time_ns: record.time_ns,
            detail,
        };
        for (topic, _) in &record.extra {
            if [
                IMAGE_TOPIC,
                COMPRESSED_IMAGE_TOPIC,
                SENSORS_TOPIC,
                GROUND_TRUTH_TOPIC,
                RECOGNITION_TOPIC,
                ANNOTATIONS_TOPIC,
            ]
            .contains(&topic.as_str())
                || !topic.starts_with('/')
            {
                return Err(bad(format!(
                    "extra channel '{topic}' must start with '/' and not be a fixed channel"
                )));
            }
        }
        let mut bytes = std::mem::take(&mut self.buf);
        let channel = match image {
            Some(message) => {
                bytes.clear();
                match message.encode_foxglove(&mut bytes).map_err(&bad)? {
                    MessageKind::FoxgloveCompressedImage => self.compressed_channel()?,
                    _ => self.image_channel()?,
                }
            }
            None => {
                encode_image(
                    record.time_ns,
                    &record.frame,
                    self.image_encoding,
                    &mut bytes,
                )
                .map_err(|e| bad(e.to_string()))?;
                self.image_channel()?
            }
        };
        let written = self.put(channel, record.time_ns, &bytes);
        self.buf = bytes;
        written?;
        if let Some(s) = &record.sensors {
            let (clean, _) = s.sanitised();
            let json = serde_json::to_vec(&clean).map_err(|e| bad(e.to_string()))?;
            let id = self.sensors_channel()?;
            self.put(id, record.time_ns, &json)?;
        }
        let fixed = [
            (GROUND_TRUTH_TOPIC, record.ground_truth.as_ref()),
            (RECOGNITION_TOPIC, record.recognition.as_ref()),
        ];
        let extra = record.extra.iter().map(|(t, v)| (t.as_str(), Some(v)));
        for (topic, value) in fixed.into_iter().chain(extra) {
            if let Some(v) = value {
                let id = self.json_channel(topic)?;
                let json = serde_json::to_vec(v).map_err(|e| bad(e.to_string()))?;
                self.put(id, record.time_ns, &json)?;
            }
        }
        if let Some(a) = &record.annotations {
            let id = self.annotations_channel()?;
            let mut bytes = Vec::with_capacity(a.encoded_len().unwrap_or(0));
            a.encode(&mut bytes).map_err(|e| bad(e.to_string()))?;
            self.put(id, record.time_ns, &bytes)?;
        }
        self.frame_written()
    }

    /// The first camera's `foxglove.RawImage` channel, `/camera/image`, added when first used.
    fn image_channel(&mut self) -> Result<u16, StreamError> {
        if let Some(id) = self.image_channel {
            return Ok(id);
        }
        let schema = raw_image_schema().ok_or_else(|| StreamError::Corrupt {
            path: self.partial.clone(),
            detail: "the foxglove.RawImage schema is not available".to_owned(),
        })?;
        let schema_id = self
            .mcap
            .add_schema(&schema.name, &schema.encoding, &schema.data)
            .map_err(self.mcap_err("cannot add the image schema"))?;
        let id = self
            .mcap
            .add_channel(schema_id, IMAGE_TOPIC, "protobuf", &BTreeMap::new())
            .map_err(self.mcap_err("cannot add the image channel"))?;
        self.image_channel = Some(id);
        // A one-camera stream keeps its layout: `/sensors` beside the image, even when empty.
        self.sensors_channel()?;
        Ok(id)
    }

    /// The first camera's sensor readings channel, `/sensors`, added when first used.
    fn sensors_channel(&mut self) -> Result<u16, StreamError> {
        if let Some(id) = self.sensors_channel {
            return Ok(id);
        }
        let schema_id = self
            .mcap
            .add_schema(
                SENSORS_SCHEMA_NAME,
                "jsonschema",
                sensors_json_schema().to_string().as_bytes(),
            )
            .map_err(self.mcap_err("cannot add the sensors schema"))?;
        let id = self
            .mcap
            .add_channel(schema_id, SENSORS_TOPIC, "json", &BTreeMap::new())
            .map_err(self.mcap_err("cannot add the sensors channel"))?;
        self.sensors_channel = Some(id);
        Ok(id)
    }

    /// Counts a frame written and ends its chunk when the chunk is full.
    fn frame_written(&mut self) -> Result<(), StreamError> {
        self.frames = self.frames.saturating_add(1);
        self.frames_in_chunk += 1;
        let per_chunk = self.frames_per_chunk.unwrap_or_else(|| {
            (TARGET_CHUNK_BYTES / self.buf.len().max(1)).clamp(1, MAX_FRAMES_PER_CHUNK)
        });
        if self.frames_in_chunk >= per_chunk {
            self.frames_in_chunk = 0;
            // Ends the chunk and flushes it to the file: it survives a crash from here on.
            self.mcap
                .flush()
                .map_err(self.mcap_err("cannot finish a chunk"))?;
        }
        Ok(())
    }

    /// Appends one message exactly as it arrived (a live robot's), on the channel `spec`
    /// describes: `/camera/image` as `foxglove.RawImage` goes to the image channel and counts as
    /// a frame, `/sensors` as JSON to the sensors channel, any other topic to a channel of its own
    /// made on first use. The bytes are stored unchanged. A frame's chunk is closed when the next
    /// frame's image arrives (so a frame's later messages stay with it), or by
    /// [`StreamWriter::close_chunk`].
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn write_raw(
        &mut self,
        spec: &RawChannelSpec,
        log_time_ns: u64,
        data: &[u8],
    ) -> Result<(), StreamError> {
        let is_frame = spec.is_frame();
        if is_frame && !spec.is_image() {
            // Another writer's camera (ROS `cdr`, a compressed image): its own channel, but its
            // messages make frames and chunks as ours do.
            self.close_chunk_if_full(data.len())?;
        }
        let channel = if spec.is_image() {
            self.close_chunk_if_full(data.len())?;
            self.image_channel()?
        } else if spec.topic == SENSORS_TOPIC && spec.message_encoding == "json" {
            self.sensors_channel()?
        } else if let Some(&id) = self.raw_channels.get(spec) {
            id
        } else {
            let schema = if spec.schema_name.is_empty() {
                0
            } else {
                self.mcap
                    .add_schema(&spec.schema_name, &spec.schema_encoding, &spec.schema)
                    .map_err(self.mcap_err("cannot add a schema"))?
            };
            let id = self
                .mcap
                .add_channel(
                    schema,
                    &spec.topic,
                    &spec.message_encoding,
                    &BTreeMap::new(),
                )
                .map_err(self.mcap_err("cannot add a channel"))?;
            self.raw_channels.insert(spec.clone(), id);
            id
        };
        self.put(channel, log_time_ns, data)?;
        if is_frame {
            self.frames = self.frames.saturating_add(1);
            self.frames_in_chunk += 1;
        }
        Ok(())
    }

    fn close_chunk_if_full(&mut self, image_bytes: usize) -> Result<(), StreamError> {
        let per_chunk = self.frames_per_chunk.unwrap_or_else(|| {
            (TARGET_CHUNK_BYTES / image_bytes.max(1)).clamp(1, MAX_FRAMES_PER_CHUNK)
        });
        if self.frames_in_chunk >= per_chunk {
            self.close_chunk()?;
        }
        Ok(())
    }

    /// Ends the current chunk and flushes it to the file: what was written survives a crash.
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn close_chunk(&mut self) -> Result<(), StreamError> {
        self.frames_in_chunk = 0;
        self.mcap
            .flush()
            .map_err(self.mcap_err("cannot finish a chunk"))
    }

    /// Stops without a stream: the `.partial` file is removed and the output left as it was
    /// (for a command that found nothing to write).
    ///
    /// # Errors
    /// The partial file cannot be removed.
    pub fn discard(self) -> Result<(), StreamError> {
        let partial = self.partial.clone();
        let file = self
            .mcap
            .into_inner()
            .into_inner()
            .map_err(|e| StreamError::Io {
                path: partial.clone(),
                source: e.into_error(),
            })?;
        file.discard().map_err(|source| StreamError::Io {
            path: partial,
            source,
        })
    }

    /// Writes the summary (indexes, statistics), syncs the file and renames it into place.
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn finish(mut self) -> Result<(), StreamError> {
        self.mcap
            .finish()
            .map_err(self.mcap_err("cannot write the summary"))?;
        let io = |path: &Path| {
            let path = path.to_owned();
            move |source| StreamError::Io { path, source }
        };
        let file = self
            .mcap
            .into_inner()
            .into_inner()
            .map_err(|e| StreamError::Io {
                path: self.partial.clone(),
                source: e.into_error(),
            })?;
        file.finish().map_err(io(&self.path))?;
        Ok(())
    }
}
