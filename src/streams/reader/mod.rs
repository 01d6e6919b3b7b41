//! [`StreamReader`]: random access to the frames of a recording, by index and by time: an MCAP
//! file (eotn's streams and any other writer's), a rosbag2 bag (folder, `metadata.yaml`, or one
//! storage file, SQLite or MCAP, split or zstd-compressed), read as one sequence of frames.
//!
//! Each storage gives a frame's raw messages ([`RawFrame`]: `mcap_file`, `rosbag2::db3`);
//! `assemble` decodes them the same way for all (`crate::formats`). An MCAP file is read as the
//! specification says (`summary`, `recovery`: the summary when it describes the whole file, else
//! one walk of the data section, messages outside chunks included); `catalog` counts its records
//! and channels, `messages` gives every message in file order.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::rosbag2::db3::Db3File;
use super::rosbag2::{Layout, StorageKind, StoragePart, layout_of};
use super::{FrameRecord, StreamError, StreamInfo, param_set_of_source};
use crate::formats::tf::TfTree;
use crate::formats::{ImageMessage, MessageKind, ros2};
pub use catalog::{ChannelSummary, RecordCounts, SchemaSummary};
use channels::Role;
pub use channels::{CAMERA_CHOICE_NOTE, ImageTopic};
use mcap_file::McapFile;
pub use messages::StreamMessage;

mod assemble;
#[cfg(test)]
mod cameras_tests;
mod catalog;
pub(crate) mod channels;
mod chunk;
mod mcap_file;
mod messages;
mod recovery;
mod summary;

/// Warnings kept; later ones are only counted, so memory stays bounded on a bad file.
const MAX_WARNINGS: usize = 100;
/// Largest storage file decompressed from `.zstd`, bytes.
const MAX_DECOMPRESSED_FILE: u64 = 64 << 30;

/// One frame's messages as stored: the image's bytes and, of the other channels read, those
/// that go with it (borrowed from a cached chunk, or owned).
pub(crate) struct RawFrame<'a> {
    /// The frame's time (its image's log time), nanoseconds.
    pub(crate) time_ns: u64,
    /// The image's message type.
    pub(crate) kind: MessageKind,
    /// The image message's bytes.
    pub(crate) image: Cow<'a, [u8]>,
    /// The other messages.
    pub(crate) others: Vec<RawMsg<'a>>,
}

/// One message that goes with a frame.
pub(crate) struct RawMsg<'a> {
    /// What it is.
    pub(crate) role: Role,
    /// Its bytes.
    pub(crate) data: Cow<'a, [u8]>,
}

/// One storage file of a recording.
enum Part {
    Mcap(Box<McapFile>),
    Db3(Box<Db3File>),
}

impl Part {
    fn len(&self) -> usize {
        match self {
            Self::Mcap(m) => m.frames.len(),
            Self::Db3(d) => d.len(),
        }
    }

    fn time_ns(&self, i: usize) -> Option<u64> {
        match self {
            Self::Mcap(m) => m.frames.get(i).map(|f| f.time_ns),
            Self::Db3(d) => d.time_ns(i),
        }
    }

    fn read_raw(&mut self, i: usize) -> Result<RawFrame<'_>, StreamError> {
        match self {
            Self::Mcap(m) => m.read_raw(i),
            Self::Db3(d) => d.read_raw(i),
        }
    }

    fn take_warnings(&mut self) -> Vec<String> {
        match self {
            Self::Mcap(m) => std::mem::take(&mut m.warnings),
            Self::Db3(d) => std::mem::take(&mut d.warnings),
        }
    }

    fn image_topics(&self) -> &[ImageTopic] {
        match self {
            Self::Mcap(m) => &m.image_topics,
            Self::Db3(d) => &d.image_topics,
        }
    }

    fn channels(&self) -> &[ChannelSummary] {
        match self {
            Self::Mcap(m) => &m.channels,
            Self::Db3(d) => &d.channels,
        }
    }

    fn static_transforms(&mut self) -> Vec<Vec<u8>> {
        match self {
            Self::Mcap(m) => m.static_transforms(),
            Self::Db3(d) => d.static_transforms(),
        }
    }
}

/// Reads a recording: an MCAP stream written by [`super::StreamWriter`] or another tool, or a
/// rosbag2 bag.
///
/// Opening reads the indexes only; [`StreamReader::read`] reads one frame (for MCAP, the one
/// chunk it is in, which stays cached). Memory is the index (about 24 bytes a frame) plus one
/// chunk, whatever the recording's length.
pub struct StreamReader {
    path: PathBuf,
    parts: Vec<Part>,
    /// The first frame of each part.
    starts: Vec<usize>,
    times: Vec<u64>,
    times_sorted: bool,
    info: StreamInfo,
    param_set: Option<String>,
    /// Each camera's default files (`eotn.camera` metadata of the first MCAP file).
    camera_files: Vec<(String, crate::camera::CameraFiles)>,
    /// The image topic frames are read from (`None` when there is none).
    camera: Option<String>,
    chunk_count: usize,
    /// Every channel of the storage files: the first file's by id, then those of later files
    /// (a split bag) that it does not have.
    channels: Vec<ChannelSummary>,
    /// For each part, its channel ids → those of `channels`.
    channel_ids: Vec<HashMap<u16, u16>>,
    /// The records of the MCAP storage files, summed.
    counts: RecordCounts,
    zstd_messages: bool,
    image_topics: Vec<ImageTopic>,
    tf_static: TfTree,
    warnings: Vec<String>,
    warnings_dropped: usize,
    notes: Vec<String>,
    grey_noted: bool,
    /// Decompressed copies of `.zstd` storage files, removed when the reader is dropped.
    _decompressed: Vec<tempfile::TempPath>,
}

impl std::fmt::Debug for StreamReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamReader")
            .field("path", &self.path)
            .field("frames", &self.times.len())
            .field("parts", &self.parts.len())
            .finish_non_exhaustive()
    }
}

impl StreamReader {
    /// Opens a recording: an MCAP file, a rosbag2 folder (or its `metadata.yaml`), or one storage
    /// file (`.mcap`, `.db3`, with or without `metadata.yaml` beside it). MCAP files without a
    /// summary (a recording cut off by a crash) are recovered by scanning their complete chunks;
    /// recordings without frames open with zero frames. Both say so in
    /// [`StreamReader::warnings`].
    ///
    /// # Errors
    /// [`StreamError`] naming the file when it cannot be read, is not MCAP or SQLite, or is a
    /// folder that is not a bag.
    pub fn open(path: &Path) -> Result<Self, StreamError> {
        Self::open_camera(path, None)
    }

    /// Opens a recording reading the frames of the camera `camera` (an image topic; `None`: the
    /// first camera, as [`StreamReader::open`]). A stream's channels that belong to another
    /// camera (docs/formats.md, "Several cameras") are not read.
    ///
    /// # Errors
    /// As [`StreamReader::open`]; [`StreamError::NoSuchCamera`] listing the cameras there are
    /// when `camera` is not one of them.
    pub fn open_camera(path: &Path, camera: Option<&str>) -> Result<Self, StreamError> {
        let mut layout = layout_of(path)?;
        if let Some(c) = camera {
            layout.image_topic = Some(c.to_owned());
        }
        let mut reader = Self {
            path: path.to_owned(),
            parts: Vec::new(),
            starts: Vec::new(),
            times: Vec::new(),
            times_sorted: true,
            info: StreamInfo::default(),
            param_set: None,
            camera_files: Vec::new(),
            camera: None,
            chunk_count: 0,
            channels: Vec::new(),
            channel_ids: Vec::new(),
            counts: RecordCounts::default(),
            zstd_messages: layout.zstd_messages,
            image_topics: Vec::new(),
            tf_static: TfTree::default(),
            warnings: Vec::new(),
            warnings_dropped: 0,
            notes: Vec::new(),
            grey_noted: false,
            _decompressed: Vec::new(),
        };
        reader.open_parts(&layout)?;
        if let Some(c) = camera
            && !reader.image_topics.iter().any(|t| t.topic == c)
        {
            return Err(StreamError::NoSuchCamera {
                path: path.to_owned(),
                topic: c.to_owned(),
                cameras: reader
                    .image_topics
                    .iter()
                    .map(|t| t.topic.clone())
                    .collect(),
            });
        }
        reader.camera = camera
            .map(str::to_owned)
            .or_else(|| layout.image_topic.clone())
            .or_else(|| reader.image_topics.first().map(|t| t.topic.clone()));
        Ok(reader)
    }

    fn open_parts(&mut self, layout: &Layout) -> Result<(), StreamError> {
        if let Some(meta) = &layout.metadata {
            for w in &meta.warnings {
                self.warn(format!("metadata.yaml: {w}"));
            }
        }
        let several = layout.parts.len() > 1;
        let mut wanted = layout.image_topic.clone();
        for (i, part) in layout.parts.iter().enumerate() {
            let opened = self.open_part(part, wanted.clone());
            let mut part_reader = match opened {
                Ok(p) => p,
                // One damaged file of a split bag costs its frames, not the bag.
                Err(e) if several && i > 0 => {
                    self.warn(format!("{e}; its frames are not read"));
                    continue;
                }
                Err(e) => return Err(e),
            };
            let name = crate::frame::display_name(&part.path);
            for w in part_reader.take_warnings() {
                if several {
                    self.warn(format!("{name}: {w}"));
                } else {
                    self.warn(w);
                }
            }
            if wanted.is_none() {
                wanted = part_reader.image_topics().first().map(|t| t.topic.clone());
            }
            for t in part_reader.image_topics() {
                if !self.image_topics.iter().any(|k| k.topic == t.topic) {
                    self.image_topics.push(t.clone());
                }
            }
            for bytes in part_reader.static_transforms() {
                let bytes = if self.zstd_messages {
                    match assemble_unzstd(&bytes) {
                        Ok(b) => b,
                        Err(_) => continue,
                    }
                } else {
                    bytes
                };
                if let Ok(msg) = ros2::decode::<ros2::TfMessage>(&bytes) {
                    self.tf_static.add(&msg);
                }
            }
            self.channel_ids.push(catalog::merge_channels(
                &mut self.channels,
                part_reader.channels(),
            ));
            if let Part::Mcap(m) = &mut part_reader {
                if i == 0 {
                    self.info = m.info.clone();
                    self.param_set = m.param_set.clone();
                    self.camera_files = m.camera_files.clone();
                }
                self.chunk_count += m.chunk_count();
                self.counts.add(m.counts);
                for note in std::mem::take(&mut m.notes) {
                    let note = if several {
                        format!("{name}: {note}")
                    } else {
                        note
                    };
                    if !self.notes.contains(&note) {
                        self.notes.push(note);
                    }
                }
            }
            self.starts.push(self.times.len());
            for f in 0..part_reader.len() {
                self.times.push(part_reader.time_ns(f).unwrap_or(0));
            }
            self.parts.push(part_reader);
        }
        if self.info == StreamInfo::default() {
            self.info.source = "unknown".to_owned();
        }
        self.times_sorted = self.times.windows(2).all(|w| w[0] <= w[1]);
        Ok(())
    }

    fn open_part(
        &mut self,
        part: &StoragePart,
        wanted: Option<String>,
    ) -> Result<Part, StreamError> {
        let path = if part.zstd_file {
            let temp = decompress_to_temp(&part.path)?;
            let p = temp.to_path_buf();
            self._decompressed.push(temp);
            p
        } else {
            part.path.clone()
        };
        Ok(match part.kind {
            StorageKind::Mcap => Part::Mcap(Box::new(McapFile::open(&path, wanted)?)),
            StorageKind::Sqlite => Part::Db3(Box::new(Db3File::open(&path, wanted)?)),
        })
    }

    /// What the stream is (from its `eotn.stream` metadata; source `"unknown"` without it).
    #[must_use]
    pub fn info(&self) -> &StreamInfo {
        &self.info
    }

    /// The recognition parameter set the stream is meant for (`"spl2009"`): its
    /// [`super::PARAMS_METADATA_NAME`] metadata record, else the set known for its source kind
    /// ([`param_set_of_source`]: B-Human streams imported before the record existed); `None`
    /// for the built-in defaults.
    #[must_use]
    pub fn param_set(&self) -> Option<&str> {
        self.param_set
            .as_deref()
            .or_else(|| param_set_of_source(&self.info.source))
    }

    /// The file or folder this reader reads.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of frames.
    #[must_use]
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// True when the stream holds no frames.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Number of MCAP chunks holding frames (or, after a recovery scan, the complete chunks
    /// found); 0 for SQLite storage.
    #[must_use]
    pub fn chunk_count(&self) -> usize {
        self.chunk_count
    }

    /// Every channel of the recording — topic, encodings, schema, message count — whatever it
    /// carries, frames or not. A split bag's files are summed: a channel of a later file with the
    /// topic, encoding and schema of one listed adds its messages to it, any other is listed
    /// after the first file's (renumbered if its id is taken). SQLite storage lists its topics
    /// (id: the place in the `topics` table; schema: the type's name, without an encoding).
    #[must_use]
    pub fn channels(&self) -> &[ChannelSummary] {
        &self.channels
    }

    /// How many messages, schemas, channels, chunks, attachments and metadata records the MCAP
    /// storage files hold (summed over a split bag's files; zero for SQLite storage).
    #[must_use]
    pub fn counts(&self) -> RecordCounts {
        self.counts
    }

    /// Facts about a valid recording worth a line: channels it does not read, frames on another
    /// topic, no camera frames at all, not written by eotn.
    #[must_use]
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// Calls `each` with every message of the recording in the order it is stored (of each
    /// storage file in turn): MCAP inside chunks and outside them, SQLite by row. Channel ids are
    /// those of [`StreamReader::channels`]. Memory is one chunk (one SQLite row) at a time.
    ///
    /// # Errors
    /// I/O errors, [`StreamError::Corrupt`] at the first damaged or cut-off record (the messages
    /// before it have been given to `each`).
    pub fn for_each_message(
        &mut self,
        mut each: impl FnMut(&StreamMessage<'_>),
    ) -> Result<(), StreamError> {
        for (part, ids) in self.parts.iter_mut().zip(&self.channel_ids) {
            let mut renumbered = |m: &StreamMessage<'_>| {
                let channel = ids.get(&m.channel).copied().unwrap_or(m.channel);
                each(&StreamMessage { channel, ..*m });
            };
            match part {
                Part::Mcap(m) => m.for_each_message(&mut renumbered)?,
                Part::Db3(d) => d.for_each_message(&mut renumbered)?,
            }
        }
        Ok(())
    }

    /// Every camera image topic of the recording with its message type, the one read first.
    #[must_use]
    pub fn image_topics(&self) -> &[ImageTopic] {
        &self.image_topics
    }

    /// The image topic frames are read from; `None` when the recording has no camera.
    #[must_use]
    pub fn camera(&self) -> Option<&str> {
        self.camera.as_deref()
    }

    /// Each camera's default files as the stream's `eotn.camera` metadata names them, by image
    /// topic (paths as written; [`crate::camera::files_for`] resolves them and applies the
    /// sidecar).
    #[must_use]
    pub fn camera_metadata(&self) -> &[(String, crate::camera::CameraFiles)] {
        &self.camera_files
    }

    /// The files of the camera read: the stream's defaults with the sidecar's in their place,
    /// the stream's parameter set ([`StreamReader::param_set`]) when neither names one.
    ///
    /// # Errors
    /// A sidecar that is there but cannot be used.
    pub fn camera_files(&self) -> Result<crate::camera::CameraFiles, crate::camera::SidecarError> {
        let topic = self.camera.as_deref().unwrap_or_default();
        let mut files = crate::camera::files_for(&self.path, &self.camera_files, topic)?;
        if files.params.is_none() {
            files.params = self.param_set().map(str::to_owned);
        }
        Ok(files)
    }

    /// Capture time of frame `index`, nanoseconds, or `None` past the end.
    #[must_use]
    pub fn time_ns(&self, index: usize) -> Option<u64> {
        self.times.get(index).copied()
    }

    /// The frame at or before `time_ns` (the latest such; the first frame when all are later,
    /// and 0 for an empty stream).
    #[must_use]
    pub fn index_at_time(&self, time_ns: u64) -> usize {
        if self.times_sorted {
            return self
                .times
                .partition_point(|&t| t <= time_ns)
                .saturating_sub(1);
        }
        let mut best: Option<(u64, usize)> = None;
        for (i, &t) in self.times.iter().enumerate() {
            if t <= time_ns && best.is_none_or(|(b, _)| t >= b) {
                best = Some((t, i));
            }
        }
        best.map_or_else(
            || {
                self.times
                    .iter()
                    .enumerate()
                    .min_by_key(|(_, t)| **t)
                    .map_or(0, |(i, _)| i)
            },
            |(_, i)| i,
        )
    }

    /// Things the reader skipped or repaired: truncation, unknown channels, bad JSON, NaN
    /// sensor values. Bounded: after 100 only a count is kept.
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Reads frame `index` with all its data.
    ///
    /// # Errors
    /// [`StreamError::NoSuchFrame`] past the end; I/O or corruption errors naming the file; an
    /// image that does not decode (that frame only).
    pub fn read(&mut self, index: usize) -> Result<FrameRecord, StreamError> {
        Ok(self.read_frame(index, false)?.0)
    }

    /// Reads frame `index` and its image message as it was stored (for `eotn import`, which
    /// keeps it unchanged).
    ///
    /// # Errors
    /// As [`StreamReader::read`].
    pub fn read_with_image(
        &mut self,
        index: usize,
    ) -> Result<(FrameRecord, ImageMessage), StreamError> {
        let (record, image) = self.read_frame(index, true)?;
        let image = image.ok_or_else(|| StreamError::Corrupt {
            path: self.path.clone(),
            detail: format!("frame {index}: its image message was not kept"),
        })?;
        Ok((record, image))
    }

    fn read_frame(
        &mut self,
        index: usize,
        keep_image: bool,
    ) -> Result<(FrameRecord, Option<ImageMessage>), StreamError> {
        let len = self.times.len();
        let no_such = |path: &Path| StreamError::NoSuchFrame {
            path: path.to_owned(),
            index,
            len,
        };
        if index >= len {
            return Err(no_such(&self.path));
        }
        let p = self
            .starts
            .partition_point(|&s| s <= index)
            .saturating_sub(1);
        let local = index - self.starts.get(p).copied().unwrap_or(0);
        let Self {
            parts,
            tf_static,
            zstd_messages,
            path,
            ..
        } = self;
        let Some(part) = parts.get_mut(p) else {
            return Err(no_such(path));
        };
        let raw = part.read_raw(local)?;
        let assembled = assemble::assemble(index, raw, tf_static, *zstd_messages, keep_image)
            .map_err(|detail| StreamError::Corrupt {
                path: path.clone(),
                detail: format!("frame {index}: {detail}"),
            });
        let part_warnings = part.take_warnings();
        for w in part_warnings {
            self.warn(w);
        }
        let assembled = assembled?;
        for w in assembled.warnings {
            self.warn(w);
        }
        if assembled.grey && !self.grey_noted {
            self.grey_noted = true;
            self.warn(
                "the frames are mono8 (grey): they show and step, but a colour table cannot classify them"
                    .to_owned(),
            );
        }
        Ok((assembled.record, assembled.image))
    }

    fn warn(&mut self, text: String) {
        if self.warnings.len() < MAX_WARNINGS {
            self.warnings.push(text);
            return;
        }
        self.warnings_dropped += 1;
        let note = format!("… and {} more warnings", self.warnings_dropped);
        if self.warnings_dropped == 1 {
            self.warnings.push(note);
        } else if let Some(last) = self.warnings.last_mut() {
            *last = note;
        }
    }
}

fn assemble_unzstd(data: &[u8]) -> Result<Vec<u8>, String> {
    use std::io::Read as _;
    let mut out = Vec::new();
    zstd::stream::read::Decoder::new(data)
        .map_err(|e| e.to_string())?
        .take(64 << 20)
        .read_to_end(&mut out)
        .map_err(|e| e.to_string())?;
    Ok(out)
}

/// A `.zstd` storage file decompressed into a temporary file (removed when dropped).
fn decompress_to_temp(path: &Path) -> Result<tempfile::TempPath, StreamError> {
    use std::io::{Read as _, Write as _};
    let io = |source| StreamError::Io {
        path: path.to_owned(),
        source,
    };
    let (input, _) = crate::input_file::open_regular(path, "a stream").map_err(io)?;
    let mut out = tempfile::NamedTempFile::new().map_err(io)?;
    let decoder = zstd::stream::read::Decoder::new(input).map_err(io)?;
    let copied = std::io::copy(
        &mut decoder.take(MAX_DECOMPRESSED_FILE + 1),
        out.as_file_mut(),
    )
    .map_err(|e| StreamError::Corrupt {
        path: path.to_owned(),
        detail: format!("zstd: {e}"),
    })?;
    if copied > MAX_DECOMPRESSED_FILE {
        return Err(StreamError::Corrupt {
            path: path.to_owned(),
            detail: "decompresses to more than 64 GiB".to_owned(),
        });
    }
    out.flush().map_err(io)?;
    Ok(out.into_temp_path())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Frame, Yuv};
    use crate::streams::schema::{ImageEncoding, encode_image, raw_image_schema};

    /// A file from another writer: frames on another topic, times out of order, default
    /// chunking, no eotn metadata.
    fn foreign_file(path: &Path, times: &[u64]) {
        let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
        let mut w = mcap::Writer::new(file).unwrap();
        let s = raw_image_schema().unwrap();
        let sid = w.add_schema(&s.name, &s.encoding, &s.data).unwrap();
        let ch = w
            .add_channel(sid, "/cam/front", "protobuf", &Default::default())
            .unwrap();
        let tf = w
            .add_channel(0, "/tf", "ros1msg", &Default::default())
            .unwrap();
        let mut buf = Vec::new();
        for (i, &t) in times.iter().enumerate() {
            let f = Frame::filled_uyvy(4, 2, Yuv::new(u8::try_from(i).unwrap(), 128, 128)).unwrap();
            encode_image(t, &f, ImageEncoding::Uyvy, &mut buf).unwrap();
            let header = |channel_id| mcap::records::MessageHeader {
                channel_id,
                sequence: 0,
                log_time: t,
                publish_time: t,
            };
            w.write_to_known_channel(&header(ch), &buf).unwrap();
            w.write_to_known_channel(&header(tf), b"\x01\x02").unwrap();
        }
        w.finish().unwrap();
    }

    #[test]
    fn frames_of_another_writer_and_unsorted_times() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.mcap");
        foreign_file(&p, &[100, 300, 200, 400]);
        let mut r = StreamReader::open(&p).unwrap();
        assert_eq!(r.len(), 4);
        assert_eq!(r.info().source, "unknown");
        assert!(r.warnings().is_empty(), "{:?}", r.warnings());
        let joined = r.notes().join("\n");
        assert!(
            joined.contains("/cam/front") && joined.contains("/tf"),
            "{joined}"
        );
        assert_eq!(r.index_at_time(250), 2, "latest frame at or before 250 ns");
        assert_eq!(r.index_at_time(350), 1);
        assert_eq!(r.index_at_time(50), 0);
        for i in 0..4 {
            let rec = r.read(i).unwrap();
            assert_eq!(rec.frame.pixel(0, 0).unwrap().y, u8::try_from(i).unwrap());
            assert!(rec.sensors.is_none() && rec.extra.is_empty());
        }
    }

    #[test]
    fn warnings_are_bounded() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.mcap");
        foreign_file(&p, &[1]);
        let mut r = StreamReader::open(&p).unwrap();
        for i in 0..1000 {
            r.warn(format!("w{i}"));
        }
        assert_eq!(r.warnings().len(), MAX_WARNINGS + 1);
        assert!(r.warnings().last().unwrap().contains("more warnings"));
    }
}
