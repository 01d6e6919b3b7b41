//! [`StreamReader`]: random access to the frames of an MCAP stream, by index and by time.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use foxglove::Decode as _;
use mcap::records::op;

use super::schema::{decode_image, parse_json_lenient};
use super::{
    ANNOTATIONS_TOPIC, FrameRecord, GROUND_TRUTH_TOPIC, IMAGE_TOPIC, METADATA_NAME,
    PARAMS_METADATA_NAME, RECOGNITION_TOPIC, SENSORS_TOPIC, StreamError, StreamInfo,
    param_set_of_source,
};
use crate::sensors::SensorReadings;
use catalog::Catalog;
use chunk::{decode_chunk_messages, decode_loose_messages};
use summary::SummaryProblem;

pub use catalog::{ChannelSummary, RecordCounts, SchemaSummary};
pub use messages::StreamMessage;

mod catalog;
mod chunk;
mod messages;
mod recovery;
mod summary;

/// The MCAP magic bytes at both ends of a file.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";
/// Largest chunk record read into memory, bytes (compressed or not); larger ones are corrupt.
const MAX_CHUNK_BYTES: u64 = 1 << 30;
/// The file's read buffer, bytes: small records read one after another come from it; reads
/// at least this long bypass it. Each jump elsewhere (a message index, a frame's chunk) refills
/// it, so it is kept small.
const READ_BUFFER_BYTES: usize = 16 << 10;
/// Largest summary-side record (message index, metadata) read, bytes.
const MAX_INDEX_BYTES: u64 = 64 << 20;
/// Warnings kept; later ones are only counted, so memory stays bounded on a bad file.
const MAX_WARNINGS: usize = 100;
/// Name of the schema of frame images from other writers.
const RAW_IMAGE_SCHEMA: &str = "foxglove.RawImage";
/// Name of the schema of image overlays (`eotn detect --annotate`, or other tools').
const ANNOTATIONS_SCHEMA: &str = "foxglove.ImageAnnotations";

/// What a channel's messages are to a frame.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Role {
    Image,
    Sensors,
    GroundTruth,
    Recognition,
    Annotations,
    Extra(String),
    Ignored,
}

/// What a block of the file is: one chunk record, or a run of records outside chunks (a frame's
/// image message and the messages after it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum BlockKind {
    Chunk,
    Loose,
}

/// Where a block of records holding frames lies in the file (opcodes and length prefixes
/// included), bytes.
#[derive(Debug, Clone, Copy)]
struct BlockLoc {
    offset: u64,
    length: u64,
    kind: BlockKind,
}

/// Where a frame is: its time, its block, and which image message of that block it is.
#[derive(Debug, Clone, Copy)]
struct FrameLoc {
    time_ns: u64,
    block: u32,
    nth: u32,
}

/// One message of a decoded chunk.
#[derive(Debug)]
struct Msg {
    channel: u16,
    data: Vec<u8>,
}

/// Reads a stream written by [`super::StreamWriter`] (or any MCAP file with `foxglove.RawImage`
/// frames on [`IMAGE_TOPIC`]).
///
/// Opening reads the summary and the image channel's message indexes (a few bytes per chunk)
/// when the summary describes the whole file (statistics matching its channels, schemas and
/// indexes, as eotn and most writers write); any other valid MCAP file — unchunked, without a
/// summary or statistics, channels repeated without their schemas — is read through its data
/// section once. [`StreamReader::read`] then reads and decompresses only the chunk holding the
/// frame and keeps that one chunk cached. Memory is this index (16 bytes a frame) plus one
/// chunk, whatever the file's length.
pub struct StreamReader {
    path: PathBuf,
    file: BufReader<File>,
    /// Where `file` is, bytes; `None` after an I/O error (the next read seeks from the start).
    pos: Option<u64>,
    file_len: u64,
    info: StreamInfo,
    /// The recognition parameter set the stream names (`eotn.recognition` metadata).
    param_set: Option<String>,
    roles: HashMap<u16, Role>,
    /// Every channel of the file, by id.
    channels: Vec<ChannelSummary>,
    counts: RecordCounts,
    /// Blocks holding frames, in file order.
    blocks: Vec<BlockLoc>,
    frames: Vec<FrameLoc>,
    times_sorted: bool,
    /// True when the index came from the summary alone (the data section was not read).
    from_summary: bool,
    cache: Option<(u32, Vec<Msg>)>,
    warnings: Vec<String>,
    warnings_dropped: usize,
    notes: Vec<String>,
}

impl std::fmt::Debug for StreamReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamReader")
            .field("path", &self.path)
            .field("frames", &self.frames.len())
            .field("chunks", &self.counts.chunks)
            .finish_non_exhaustive()
    }
}

/// Schemas and channels seen so far, to give each channel its [`Role`].
#[derive(Default)]
struct ChannelTable {
    image: Option<u16>,
    roles: HashMap<u16, Role>,
    notes: Vec<String>,
}

impl ChannelTable {
    fn add(&mut self, id: u16, topic: &str, encoding: &str, schema_name: Option<&str>) {
        if self.roles.contains_key(&id) {
            return;
        }
        let is_raw_image = schema_name == Some(RAW_IMAGE_SCHEMA) && encoding == "protobuf";
        let role = if (topic == IMAGE_TOPIC || is_raw_image) && self.image.is_none() {
            if !is_raw_image {
                self.notes.push(format!(
                    "channel {topic} is not a protobuf foxglove.RawImage (schema {}, encoding {encoding}); its frames will not decode",
                    schema_name.unwrap_or("none")
                ));
            } else if topic != IMAGE_TOPIC {
                self.notes.push(format!(
                    "no {IMAGE_TOPIC} channel yet; frames are read from {topic}"
                ));
            }
            self.image = Some(id);
            Role::Image
        } else if topic == ANNOTATIONS_TOPIC
            && schema_name == Some(ANNOTATIONS_SCHEMA)
            && encoding == "protobuf"
        {
            Role::Annotations
        } else if encoding != "json" {
            self.notes.push(format!(
                "channel {topic} ({encoding}) is not read: only {IMAGE_TOPIC} and JSON channels are"
            ));
            Role::Ignored
        } else {
            match topic {
                SENSORS_TOPIC => Role::Sensors,
                GROUND_TRUTH_TOPIC => Role::GroundTruth,
                RECOGNITION_TOPIC => Role::Recognition,
                _ => Role::Extra(topic.to_owned()),
            }
        };
        self.roles.insert(id, role);
    }
}

impl StreamReader {
    /// Opens a stream, or any valid MCAP file. Files cut off before their footer (a recording
    /// cut off by a crash) are recovered by scanning their complete chunks, and say so in
    /// [`StreamReader::warnings`]; files without frames open with zero frames and say so in
    /// [`StreamReader::notes`].
    ///
    /// # Errors
    /// [`StreamError`] naming the file when it cannot be read or is not MCAP at all.
    pub fn open(path: &Path) -> Result<Self, StreamError> {
        let io = |source| StreamError::Io {
            path: path.to_owned(),
            source,
        };
        // Looked at before it is opened: a FIFO would hang the open.
        let (file, file_len) = crate::input_file::open_regular(path, "a stream").map_err(io)?;
        let mut reader = Self {
            path: path.to_owned(),
            file: BufReader::with_capacity(READ_BUFFER_BYTES, file),
            pos: None,
            file_len,
            info: StreamInfo::default(),
            param_set: None,
            roles: HashMap::new(),
            channels: Vec::new(),
            counts: RecordCounts::default(),
            blocks: Vec::new(),
            frames: Vec::new(),
            times_sorted: true,
            from_summary: false,
            cache: None,
            warnings: Vec::new(),
            warnings_dropped: 0,
            notes: Vec::new(),
        };
        let mut magic = [0u8; 8];
        let got = reader.read_up_to(0, &mut magic)?;
        if got < magic.len() || &magic != MAGIC {
            let detail = if file_len == 0 {
                "the file is empty".to_owned()
            } else if got < magic.len() {
                format!("only {file_len} bytes, no MCAP header")
            } else {
                "it does not start with the MCAP magic bytes".to_owned()
            };
            return Err(StreamError::NotMcap {
                path: path.to_owned(),
                detail,
            });
        }
        let mut table = ChannelTable::default();
        let mut catalog = Catalog::default();
        reader.from_summary = match reader.read_summary()? {
            Ok(summary) => reader.index_from_summary(&summary, &mut table, &mut catalog)?,
            Err(SummaryProblem::NoFooter(why)) => {
                reader.warn(format!(
                    "no usable summary ({why}): the recording was probably cut off; scanning its complete chunks"
                ));
                false
            }
            Err(SummaryProblem::Damaged(why)) => {
                reader.warn(format!(
                    "the summary is damaged ({why}); reading the data section instead"
                ));
                false
            }
        };
        if !reader.from_summary {
            // Whatever a summary that does not describe the whole file gave is read again.
            table = ChannelTable::default();
            catalog = Catalog::default();
            reader.info = StreamInfo::default();
            reader.param_set = None;
            reader.notes.clear();
            reader.blocks.clear();
            reader.frames.clear();
            reader.scan(&mut table, &mut catalog)?;
        }
        reader.notes.append(&mut table.notes);
        if table.image.is_none() {
            reader.notes.push(format!(
                "no camera frames: no {IMAGE_TOPIC} channel and no foxglove.RawImage channel among its {} channels",
                catalog.counts.channels
            ));
        }
        (reader.channels, reader.counts) = catalog.into_channels();
        reader.roles = table.roles;
        reader.times_sorted = reader
            .frames
            .windows(2)
            .all(|w| w[0].time_ns <= w[1].time_ns);
        Ok(reader)
    }

    /// What the stream is (from its `eotn.stream` metadata; source `"unknown"` without it).
    #[must_use]
    pub fn info(&self) -> &StreamInfo {
        &self.info
    }

    /// The recognition parameter set the stream is meant for (`"spl2009"`): its
    /// [`PARAMS_METADATA_NAME`] metadata record, else the set known for its source kind
    /// ([`param_set_of_source`]: B-Human streams imported before the record existed); `None`
    /// for the built-in defaults.
    #[must_use]
    pub fn param_set(&self) -> Option<&str> {
        self.param_set
            .as_deref()
            .or_else(|| param_set_of_source(&self.info.source))
    }

    /// The file this reader reads.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of frames.
    #[must_use]
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// True when the stream holds no frames.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Number of chunk records in the file (after a recovery scan, the complete chunks found).
    #[must_use]
    pub fn chunk_count(&self) -> usize {
        usize::try_from(self.counts.chunks).unwrap_or(usize::MAX)
    }

    /// Every channel of the file by id — topic, encodings, schema, message count — whatever
    /// it carries, frames or not.
    #[must_use]
    pub fn channels(&self) -> &[ChannelSummary] {
        &self.channels
    }

    /// How many messages, schemas, channels, chunks, attachments and metadata records the file
    /// holds.
    #[must_use]
    pub fn counts(&self) -> RecordCounts {
        self.counts
    }

    /// Capture time of frame `index`, nanoseconds, or `None` past the end.
    #[must_use]
    pub fn time_ns(&self, index: usize) -> Option<u64> {
        self.frames.get(index).map(|f| f.time_ns)
    }

    /// The frame at or before `time_ns` (the latest such; the first frame when all are later,
    /// and 0 for an empty stream).
    #[must_use]
    pub fn index_at_time(&self, time_ns: u64) -> usize {
        if self.times_sorted {
            return self
                .frames
                .partition_point(|f| f.time_ns <= time_ns)
                .saturating_sub(1);
        }
        let mut best: Option<(u64, usize)> = None;
        for (i, f) in self.frames.iter().enumerate() {
            if f.time_ns <= time_ns && best.is_none_or(|(t, _)| f.time_ns >= t) {
                best = Some((f.time_ns, i));
            }
        }
        best.map_or_else(
            || {
                self.frames
                    .iter()
                    .enumerate()
                    .min_by_key(|(_, f)| f.time_ns)
                    .map_or(0, |(i, _)| i)
            },
            |(_, i)| i,
        )
    }

    /// Things wrong with the file that the reader skipped or repaired: truncation, damage, bad
    /// JSON, NaN sensor values. Bounded: after 100 only a count is kept.
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Facts about a valid file worth a line: channels it does not read, frames on another
    /// topic, no camera frames at all, not written by eotn.
    #[must_use]
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// Reads frame `index` with all its data.
    ///
    /// # Errors
    /// [`StreamError::NoSuchFrame`] past the end; I/O or corruption errors naming the file.
    pub fn read(&mut self, index: usize) -> Result<FrameRecord, StreamError> {
        let loc = *self
            .frames
            .get(index)
            .ok_or_else(|| StreamError::NoSuchFrame {
                path: self.path.clone(),
                index,
                len: self.frames.len(),
            })?;
        if self.cache.as_ref().is_none_or(|(c, _)| *c != loc.block) {
            self.cache = None;
            let messages = self.load_block(loc.block)?;
            self.cache = Some((loc.block, messages));
        }
        let Some((_, messages)) = self.cache.take() else {
            return Err(self.corrupt(format!("frame {index}: its chunk could not be loaded")));
        };
        let result = self.assemble(index, loc, &messages);
        self.cache = Some((loc.block, messages));
        result
    }

    fn assemble(
        &mut self,
        index: usize,
        loc: FrameLoc,
        messages: &[Msg],
    ) -> Result<FrameRecord, StreamError> {
        let mut images = messages
            .iter()
            .enumerate()
            .filter(|(_, m)| self.roles.get(&m.channel) == Some(&Role::Image));
        let Some((at, image)) = images.nth(loc.nth as usize) else {
            return Err(self.corrupt(format!(
                "frame {index}: its chunk does not hold the indexed image"
            )));
        };
        let frame = decode_image(&image.data)
            .map_err(|detail| self.corrupt(format!("frame {index}: {detail}")))?;
        let mut record = FrameRecord::new(loc.time_ns, frame);
        for m in messages.iter().skip(at + 1) {
            let role = self.roles.get(&m.channel).cloned().unwrap_or(Role::Ignored);
            if role == Role::Image {
                break;
            }
            if role == Role::Ignored {
                continue;
            }
            if role == Role::Annotations {
                match foxglove::messages::ImageAnnotations::decode(m.data.as_slice()) {
                    Ok(a) => record.annotations = Some(a),
                    Err(e) => self.warn(format!(
                        "frame {index}: {ANNOTATIONS_TOPIC} is not a foxglove.ImageAnnotations ({e}); skipped"
                    )),
                }
                continue;
            }
            let value = match parse_json_lenient(&m.data) {
                Ok((v, replaced)) => {
                    if replaced {
                        self.warn(format!(
                            "frame {index}: {} has NaN/Infinity values; read as missing",
                            topic_of(&role)
                        ));
                    }
                    v
                }
                Err(e) => {
                    self.warn(format!(
                        "frame {index}: {} is not valid JSON ({e}); skipped",
                        topic_of(&role)
                    ));
                    continue;
                }
            };
            match role {
                Role::Sensors => match serde_json::from_value::<SensorReadings>(value) {
                    Ok(s) => {
                        let (clean, dropped) = s.sanitised();
                        if !dropped.is_empty() {
                            self.warn(format!(
                                "frame {index}: non-finite or impossible sensor values dropped: {}",
                                dropped.join(", ")
                            ));
                        }
                        record.sensors = Some(clean);
                    }
                    Err(e) => self.warn(format!(
                        "frame {index}: {SENSORS_TOPIC} does not match the sensor schema ({e}); skipped"
                    )),
                },
                Role::GroundTruth => record.ground_truth = Some(value),
                Role::Recognition => record.recognition = Some(value),
                Role::Extra(topic) => record.extra.push((topic, value)),
                Role::Image | Role::Annotations | Role::Ignored => {}
            }
        }
        Ok(record)
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

    fn corrupt(&self, detail: String) -> StreamError {
        StreamError::Corrupt {
            path: self.path.clone(),
            detail,
        }
    }

    fn mcap_err(&self, context: String) -> impl FnOnce(mcap::McapError) -> StreamError {
        let path = self.path.clone();
        move |source| StreamError::Mcap {
            path,
            context,
            source,
        }
    }

    /// Reads as many bytes as the file has at `offset`, up to `buf.len()`.
    fn read_up_to(&mut self, offset: u64, buf: &mut [u8]) -> Result<usize, StreamError> {
        let io = |source| StreamError::Io {
            path: self.path.clone(),
            source,
        };
        // A relative seek keeps the buffer when `offset` lies in it, so records read one after
        // another (the data section walked, a record's body after its header) cost one read of
        // the file, not one each; an absolute seek always drops it.
        let delta = self
            .pos
            .take()
            .and_then(|p| i64::try_from(i128::from(offset) - i128::from(p)).ok());
        match delta {
            Some(d) => self.file.seek_relative(d),
            None => self.file.seek(SeekFrom::Start(offset)).map(drop),
        }
        .map_err(io)?;
        let mut got = 0;
        while got < buf.len() {
            match self.file.read(&mut buf[got..]) {
                Ok(0) => break,
                Ok(n) => got += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io(e)),
            }
        }
        self.pos = Some(offset + got as u64);
        Ok(got)
    }

    /// Reads `len` bytes at `offset`, which the caller has checked lie inside the file.
    fn read_exact_at(&mut self, offset: u64, len: u64) -> Result<Vec<u8>, StreamError> {
        let n = usize::try_from(len).map_err(|_| self.corrupt(format!("{len} bytes too large")))?;
        let mut buf = vec![0u8; n];
        let got = self.read_up_to(offset, &mut buf)?;
        if got < n {
            return Err(self.corrupt(format!(
                "the file ends {got} bytes into a {n}-byte record at offset {offset}"
            )));
        }
        Ok(buf)
    }

    /// Reads one record (opcode, length, body) at `offset` whose total length must not exceed
    /// `limit` bytes.
    fn read_record_at(&mut self, offset: u64, limit: u64) -> Result<(u8, Vec<u8>), StreamError> {
        let head = self.read_exact_at(offset, 9)?;
        let opcode = head[0];
        let len = u64::from_le_bytes(head[1..9].try_into().unwrap_or([0xff; 8]));
        let end = offset.saturating_add(9).saturating_add(len);
        if len > limit || end > self.file_len {
            return Err(self.corrupt(format!(
                "record at offset {offset} claims {len} bytes, beyond the file or any sane size"
            )));
        }
        Ok((opcode, self.read_exact_at(offset + 9, len)?))
    }

    /// Adds a block holding frames; its number.
    fn push_block(&mut self, loc: BlockLoc) -> Result<u32, StreamError> {
        let block = u32::try_from(self.blocks.len())
            .map_err(|_| self.corrupt("more than 2³² chunks".to_owned()))?;
        self.blocks.push(loc);
        Ok(block)
    }

    /// Reads block `block` into its messages: a chunk decompressed, or records outside chunks.
    fn load_block(&mut self, block: u32) -> Result<Vec<Msg>, StreamError> {
        let loc = *self
            .blocks
            .get(block as usize)
            .ok_or_else(|| self.corrupt(format!("no chunk {block}")))?;
        if loc.kind == BlockKind::Loose {
            let bytes = self.read_exact_at(loc.offset, loc.length)?;
            let mut messages = Vec::new();
            decode_loose_messages(&bytes, &mut messages)
                .map_err(self.mcap_err(format!("reading the messages at offset {}", loc.offset)))?;
            return Ok(messages);
        }
        let (opcode, body) = self.read_record_at(loc.offset, loc.length.saturating_sub(9))?;
        if opcode != op::CHUNK {
            return Err(self.corrupt(format!(
                "the chunk index points at offset {} which holds no chunk",
                loc.offset
            )));
        }
        let mut messages = Vec::new();
        decode_chunk_messages(&body, &mut messages)
            .map_err(self.mcap_err(format!("reading the chunk at offset {}", loc.offset)))?;
        Ok(messages)
    }
}

fn topic_of(role: &Role) -> &str {
    match role {
        Role::Image => IMAGE_TOPIC,
        Role::Sensors => SENSORS_TOPIC,
        Role::GroundTruth => GROUND_TRUTH_TOPIC,
        Role::Recognition => RECOGNITION_TOPIC,
        Role::Annotations => ANNOTATIONS_TOPIC,
        Role::Extra(t) => t,
        Role::Ignored => "an ignored channel",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Frame, Yuv};
    use crate::streams::schema::{ImageEncoding, encode_image, raw_image_schema};

    /// A file from another writer: frames on another topic, times out of order, default
    /// chunking, no eotn metadata.
    fn foreign_file(path: &Path, times: &[u64]) {
        let file = std::io::BufWriter::new(File::create(path).unwrap());
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

    /// A file whose summary describes it whole (eotn's own, the `mcap` crate's defaults) is
    /// indexed from its summary alone, without reading the data section.
    #[test]
    fn a_complete_summary_is_enough() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.mcap");
        foreign_file(&p, &[100, 300, 200, 400]);
        let r = StreamReader::open(&p).unwrap();
        assert!(r.from_summary);
        let c = r.counts();
        assert_eq!((c.messages, c.channels, c.schemas), (8, 2, 1));
        let tf = &r.channels()[1];
        assert_eq!((tf.topic.as_str(), tf.message_count), ("/tf", 4));
        assert_eq!(tf.schema, None);
        assert_eq!(
            r.channels()[0].schema.as_ref().map(|s| s.encoding.as_str()),
            Some("protobuf")
        );
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
