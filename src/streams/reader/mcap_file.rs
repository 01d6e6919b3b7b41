//! [`McapFile`]: one MCAP file's frames, by index, through the chunk and message indexes (or a
//! recovery scan when the summary is missing), each frame's image with the messages that go
//! with it.

use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use mcap::records::{Record, op};
use mcap::sans_io::{SummaryReadEvent, SummaryReader, SummaryReaderOptions};

use super::super::{IMAGE_TOPIC, METADATA_NAME, PARAMS_METADATA_NAME, StreamError, StreamInfo};
use super::channels::{ChannelTable, ImageTopic, Role};
use super::chunk::decode_chunk_messages;
use super::{RawFrame, RawMsg};
use crate::formats::MessageKind;

/// The MCAP magic bytes at both ends of a file.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";
/// Largest chunk record read into memory, bytes (compressed or not); larger ones are corrupt.
pub(super) const MAX_CHUNK_BYTES: u64 = 1 << 30;
/// Largest summary-side record (message index, metadata) read, bytes.
pub(super) const MAX_INDEX_BYTES: u64 = 64 << 20;
/// Most chunks read at opening for `/tf_static` (it is written once, at the start).
const MAX_STATIC_CHUNKS: usize = 64;

/// Where a chunk record lies in the file (opcode and length prefix included), bytes.
#[derive(Debug, Clone, Copy)]
pub(super) struct ChunkLoc {
    pub(super) offset: u64,
    pub(super) length: u64,
}

/// Where a frame is: its time, its chunk, and which image message of that chunk it is.
#[derive(Debug, Clone, Copy)]
pub(super) struct FrameLoc {
    pub(super) time_ns: u64,
    pub(super) chunk: u32,
    pub(super) nth: u32,
}

/// One message of a decoded chunk.
#[derive(Debug)]
pub(super) struct Msg {
    pub(super) channel: u16,
    pub(super) log_time: u64,
    pub(super) data: Vec<u8>,
}

/// One MCAP file of a recording (an eotn stream, another writer's MCAP, or one storage file of
/// a rosbag2 bag).
///
/// Opening reads the summary and the image channel's message indexes (a few bytes per chunk);
/// [`McapFile::read_raw`] then reads and decompresses only the chunk holding the frame and keeps
/// that one chunk cached. Memory is this index (16 bytes a frame) plus one chunk, whatever the
/// file's length.
pub(super) struct McapFile {
    path: PathBuf,
    file: BufReader<File>,
    pub(super) file_len: u64,
    pub(super) info: StreamInfo,
    /// The recognition parameter set the stream names (`eotn.recognition` metadata).
    pub(super) param_set: Option<String>,
    /// Written by eotn (its `eotn.stream` metadata): a frame's messages follow its image.
    written_by_eotn: bool,
    roles: HashMap<u16, Role>,
    image_channel: Option<u16>,
    pub(super) image_kind: Option<MessageKind>,
    pub(super) image_topics: Vec<ImageTopic>,
    pub(super) chunks: Vec<ChunkLoc>,
    pub(super) frames: Vec<FrameLoc>,
    /// Chunks that hold `/tf_static` messages.
    static_chunks: Vec<ChunkLoc>,
    cache: Option<(u32, Vec<Msg>)>,
    /// Warnings not yet taken by the reader.
    pub(super) warnings: Vec<String>,
}

impl std::fmt::Debug for McapFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapFile")
            .field("path", &self.path)
            .field("frames", &self.frames.len())
            .field("chunks", &self.chunks.len())
            .finish_non_exhaustive()
    }
}

impl McapFile {
    /// Opens one MCAP file, reading frames from `wanted_topic` when given (else the canonical
    /// image topic, else the first image channel with messages). Files without a summary (a
    /// recording cut off by a crash) are recovered by scanning their complete chunks; files
    /// without frames open with zero frames. Both say so in the warnings.
    ///
    /// # Errors
    /// [`StreamError`] naming the file when it cannot be read or is not MCAP at all.
    pub(super) fn open(path: &Path, wanted_topic: Option<String>) -> Result<Self, StreamError> {
        let io = |source| StreamError::Io {
            path: path.to_owned(),
            source,
        };
        let file = File::open(path).map_err(io)?;
        let meta = file.metadata().map_err(io)?;
        if !meta.is_file() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file, so it cannot be a stream",
            )));
        }
        let file_len = meta.len();
        let mut reader = Self {
            path: path.to_owned(),
            file: BufReader::with_capacity(64 << 10, file),
            file_len,
            info: StreamInfo::default(),
            param_set: None,
            written_by_eotn: false,
            roles: HashMap::new(),
            image_channel: None,
            image_kind: None,
            image_topics: Vec::new(),
            chunks: Vec::new(),
            frames: Vec::new(),
            static_chunks: Vec::new(),
            cache: None,
            warnings: Vec::new(),
        };
        reader.check_magic()?;
        let mut table = ChannelTable::wanting(wanted_topic.clone());
        let indexed = match reader.read_summary() {
            Ok(Some(summary)) => reader.index_from_summary(&summary, &mut table)?,
            Ok(None) => {
                reader.warn("the file has no summary section; scanning its chunks".to_owned());
                false
            }
            Err(e) => {
                reader.warn(format!(
                    "no usable summary ({e}): the recording was probably cut off; scanning its complete chunks"
                ));
                false
            }
        };
        if !indexed {
            table = ChannelTable::wanting(wanted_topic);
            reader.chunks.clear();
            reader.frames.clear();
            reader.static_chunks.clear();
            reader.scan(&mut table)?;
        }
        table.note_other_cameras();
        for note in std::mem::take(&mut table.notes) {
            reader.warn(note);
        }
        if table.image.is_none() {
            reader.warn(format!(
                "no camera image channel ({IMAGE_TOPIC} or any other image topic): the file holds no frames"
            ));
        }
        reader.image_channel = table.image;
        reader.image_kind = table.image.and_then(|id| match table.roles.get(&id) {
            Some(Role::Image(k)) => Some(*k),
            _ => None,
        });
        reader.image_topics = std::mem::take(&mut table.image_topics);
        reader.roles = table.roles;
        Ok(reader)
    }

    fn check_magic(&mut self) -> Result<(), StreamError> {
        let mut magic = [0u8; 8];
        let got = self.read_up_to(0, &mut magic)?;
        if got == magic.len() && &magic == MAGIC {
            return Ok(());
        }
        let detail = if self.file_len == 0 {
            "the file is empty".to_owned()
        } else if got < magic.len() {
            format!("only {} bytes, no MCAP header", self.file_len)
        } else {
            "it does not start with the MCAP magic bytes".to_owned()
        };
        Err(StreamError::NotMcap {
            path: self.path.clone(),
            detail,
        })
    }

    /// Number of chunks holding frames (or, after a recovery scan, the complete chunks found).
    pub(super) fn chunk_count(&self) -> usize {
        self.chunks.len()
    }

    /// Frame `index`'s image and the messages that go with it, borrowed from the cached chunk.
    ///
    /// The messages of an eotn stream follow their image with its log time; another writer's
    /// messages are matched by time: of each channel, the message between the previous image
    /// and the next closest in time to this one (the later on a tie).
    ///
    /// # Errors
    /// I/O or corruption errors naming the file.
    pub(super) fn read_raw(&mut self, index: usize) -> Result<RawFrame<'_>, StreamError> {
        let Some(&loc) = self.frames.get(index) else {
            return Err(StreamError::NoSuchFrame {
                path: self.path.clone(),
                index,
                len: self.frames.len(),
            });
        };
        if self.cache.as_ref().is_none_or(|(c, _)| *c != loc.chunk) {
            self.cache = None;
            let messages = self.load_chunk(loc.chunk)?;
            self.cache = Some((loc.chunk, messages));
        }
        let (Some((_, messages)), Some(image), Some(kind)) =
            (self.cache.as_ref(), self.image_channel, self.image_kind)
        else {
            return Err(self.corrupt(format!("frame {index}: its chunk could not be loaded")));
        };
        let images: Vec<usize> = messages
            .iter()
            .enumerate()
            .filter(|(_, m)| m.channel == image)
            .map(|(i, _)| i)
            .collect();
        let nth = loc.nth as usize;
        let Some(&at) = images.get(nth) else {
            return Err(self.corrupt(format!(
                "frame {index}: its chunk does not hold the indexed image"
            )));
        };
        let end = images.get(nth + 1).copied().unwrap_or(messages.len());
        let start = if nth == 0 { 0 } else { images[nth - 1] + 1 };
        let mine = |m: &Msg| -> Option<Role> {
            match self.roles.get(&m.channel) {
                None | Some(Role::Ignored | Role::Image(_)) => None,
                Some(r) => Some(r.clone()),
            }
        };
        let mut others = Vec::new();
        if self.written_by_eotn {
            for m in &messages[at + 1..end] {
                if let Some(role) = mine(m) {
                    others.push(RawMsg {
                        role,
                        data: Cow::Borrowed(m.data.as_slice()),
                    });
                }
            }
        } else {
            let t = messages[at].log_time;
            let mut nearest: HashMap<u16, usize> = HashMap::new();
            for (i, m) in messages.iter().enumerate().take(end).skip(start) {
                if i == at || mine(m).is_none() {
                    continue;
                }
                let better = nearest
                    .get(&m.channel)
                    .is_none_or(|&j| m.log_time.abs_diff(t) <= messages[j].log_time.abs_diff(t));
                if better {
                    nearest.insert(m.channel, i);
                }
            }
            let mut picked: Vec<usize> = nearest.into_values().collect();
            picked.sort_unstable();
            for i in picked {
                let m = &messages[i];
                if let Some(role) = mine(m) {
                    others.push(RawMsg {
                        role,
                        data: Cow::Borrowed(m.data.as_slice()),
                    });
                }
            }
        }
        Ok(RawFrame {
            time_ns: loc.time_ns,
            kind,
            image: Cow::Borrowed(messages[at].data.as_slice()),
            others,
        })
    }

    /// Every `/tf_static` message of the file (it is written once, near the start), bytes in
    /// file order.
    pub(super) fn static_transforms(&mut self) -> Vec<Vec<u8>> {
        let statics: HashSet<u16> = self
            .roles
            .iter()
            .filter(|(_, r)| **r == Role::Tf(true))
            .map(|(id, _)| *id)
            .collect();
        let mut out = Vec::new();
        for loc in std::mem::take(&mut self.static_chunks) {
            let body = match self.read_record_at(loc.offset, loc.length.saturating_sub(9)) {
                Ok((op::CHUNK, body)) => body,
                _ => continue,
            };
            let mut messages = Vec::new();
            if decode_chunk_messages(&body, &mut messages).is_ok() {
                out.extend(
                    messages
                        .into_iter()
                        .filter(|m| statics.contains(&m.channel))
                        .map(|m| m.data),
                );
            }
        }
        out
    }

    /// Remembers a chunk that holds `/tf_static` messages (the first few only).
    pub(super) fn note_static_chunk(&mut self, loc: ChunkLoc) {
        if self.static_chunks.len() < MAX_STATIC_CHUNKS {
            self.static_chunks.push(loc);
        }
    }

    pub(super) fn warn(&mut self, text: String) {
        // Bounded: the reader keeps only the first hundred anyway.
        if self.warnings.len() < 1000 {
            self.warnings.push(text);
        }
    }

    pub(super) fn corrupt(&self, detail: String) -> StreamError {
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
        self.file.seek(SeekFrom::Start(offset)).map_err(io)?;
        let mut got = 0;
        while got < buf.len() {
            match self.file.read(&mut buf[got..]) {
                Ok(0) => break,
                Ok(n) => got += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io(e)),
            }
        }
        Ok(got)
    }

    /// Reads `len` bytes at `offset`, which the caller has checked lie inside the file.
    pub(super) fn read_exact_at(&mut self, offset: u64, len: u64) -> Result<Vec<u8>, StreamError> {
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

    fn read_summary(&mut self) -> Result<Option<mcap::Summary>, StreamError> {
        let path = self.path.clone();
        let io = |source| StreamError::Io {
            path: path.clone(),
            source,
        };
        let mut summary = SummaryReader::new_with_options(
            SummaryReaderOptions::default()
                .with_file_size(self.file_len)
                .with_record_length_limit(256 << 20),
        );
        let mut steps = 0u64;
        while let Some(event) = summary.next_event() {
            steps += 1;
            if steps > 100_000_000 {
                return Err(self.corrupt("the summary section never ends".to_owned()));
            }
            match event.map_err(self.mcap_err("reading the summary".to_owned()))? {
                SummaryReadEvent::ReadRequest(n) => {
                    let got = self.file.read(summary.insert(n)).map_err(io)?;
                    summary.notify_read(got);
                }
                SummaryReadEvent::SeekRequest(to) => {
                    let pos = self.file.seek(to).map_err(io)?;
                    summary.notify_seeked(pos);
                }
            }
        }
        Ok(summary.finish())
    }

    /// Builds the frame index from the summary; `false` when the summary cannot locate the
    /// frames (no chunk indexes), so the caller scans instead.
    fn index_from_summary(
        &mut self,
        summary: &mcap::Summary,
        table: &mut ChannelTable,
    ) -> Result<bool, StreamError> {
        for index in &summary.metadata_indexes {
            if index.name != METADATA_NAME && index.name != PARAMS_METADATA_NAME {
                continue;
            }
            if index.length > MAX_INDEX_BYTES
                || index.offset.saturating_add(index.length) > self.file_len
            {
                self.warn("the stream metadata index points outside the file".to_owned());
                continue;
            }
            match self.read_record_at(index.offset, MAX_INDEX_BYTES) {
                Ok((opcode, body)) => self.take_metadata(opcode, &body),
                Err(e) => self.warn(format!("stream metadata unreadable: {e}")),
            }
        }
        if self.info == StreamInfo::default() {
            self.no_metadata();
        }
        let statics = channels_from_summary(summary, table);
        let messages = summary.stats.as_ref().map_or(1, |s| s.message_count);
        if summary.chunk_indexes.is_empty() {
            return Ok(messages == 0);
        }
        let Some(image) = table.image else {
            return Ok(true);
        };
        let mut chunk_indexes: Vec<&mcap::records::ChunkIndex> =
            summary.chunk_indexes.iter().collect();
        chunk_indexes.sort_by_key(|c| c.chunk_start_offset);
        for ci in chunk_indexes {
            if ci.chunk_length > MAX_CHUNK_BYTES
                || ci.chunk_start_offset.saturating_add(ci.chunk_length) > self.file_len
            {
                self.warn(format!(
                    "chunk index points outside the file (offset {}, {} bytes); the summary is not trusted",
                    ci.chunk_start_offset, ci.chunk_length
                ));
                return Ok(false);
            }
            if self.static_chunks.len() < MAX_STATIC_CHUNKS
                && ci
                    .message_index_offsets
                    .keys()
                    .any(|id| statics.contains(id))
            {
                self.static_chunks.push(ChunkLoc {
                    offset: ci.chunk_start_offset,
                    length: ci.chunk_length,
                });
            }
            let Some(&at) = ci.message_index_offsets.get(&image) else {
                continue;
            };
            let entries = match self.read_record_at(at, MAX_INDEX_BYTES) {
                Ok((op::MESSAGE_INDEX, body)) => match mcap::parse_record(op::MESSAGE_INDEX, &body)
                {
                    Ok(Record::MessageIndex(mi)) if mi.channel_id == image => mi.records,
                    _ => {
                        self.warn(format!(
                            "message index at offset {at} is malformed; scanning instead"
                        ));
                        return Ok(false);
                    }
                },
                Ok(_) | Err(_) => {
                    self.warn(format!(
                        "message index at offset {at} is unreadable; scanning instead"
                    ));
                    return Ok(false);
                }
            };
            let chunk = u32::try_from(self.chunks.len())
                .map_err(|_| self.corrupt("more than 2³² chunks".to_owned()))?;
            self.chunks.push(ChunkLoc {
                offset: ci.chunk_start_offset,
                length: ci.chunk_length,
            });
            let mut entries = entries;
            entries.sort_by_key(|e| e.offset);
            for (nth, e) in entries.iter().enumerate() {
                self.frames.push(FrameLoc {
                    time_ns: e.log_time,
                    chunk,
                    nth: u32::try_from(nth).unwrap_or(u32::MAX),
                });
            }
        }
        Ok(true)
    }

    pub(super) fn no_metadata(&mut self) {
        self.info = StreamInfo {
            source: "unknown".to_owned(),
            description: String::new(),
        };
        self.warn(format!(
            "no {METADATA_NAME} metadata: not written by eotn, source unknown"
        ));
    }

    pub(super) fn take_metadata(&mut self, opcode: u8, body: &[u8]) {
        match mcap::parse_record(opcode, body) {
            Ok(Record::Metadata(m)) if m.name == METADATA_NAME => {
                self.written_by_eotn = true;
                let get = |k: &str| m.metadata.get(k).cloned().unwrap_or_default();
                self.info = StreamInfo {
                    source: get("source"),
                    description: get("description"),
                };
            }
            Ok(Record::Metadata(m)) if m.name == PARAMS_METADATA_NAME => {
                self.param_set = m.metadata.get("params").filter(|s| !s.is_empty()).cloned();
            }
            Ok(Record::Metadata(_)) => {}
            _ => self.warn("a metadata record is malformed; ignored".to_owned()),
        }
    }

    /// Reads and decompresses chunk `chunk` into its messages.
    pub(super) fn load_chunk(&mut self, chunk: u32) -> Result<Vec<Msg>, StreamError> {
        let loc = *self
            .chunks
            .get(chunk as usize)
            .ok_or_else(|| self.corrupt(format!("no chunk {chunk}")))?;
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

/// Gives every channel of the summary its role (the canonical image topic first, channels
/// without messages never the camera); returns the `/tf_static` channels.
fn channels_from_summary(summary: &mcap::Summary, table: &mut ChannelTable) -> HashSet<u16> {
    let mut ids: Vec<u16> = summary.channels.keys().copied().collect();
    ids.sort_unstable();
    // Prefer the canonical image topic over any other RawImage channel.
    ids.sort_by_key(|id| {
        summary
            .channels
            .get(id)
            .is_none_or(|c| c.topic != IMAGE_TOPIC)
    });
    // A channel no chunk holds messages of is never chosen as the camera.
    let with_messages: HashSet<u16> = if summary.chunk_indexes.is_empty() {
        summary.stats.as_ref().map_or_else(
            || ids.iter().copied().collect(),
            |s| {
                s.channel_message_counts
                    .iter()
                    .filter(|(_, n)| **n > 0)
                    .map(|(id, _)| *id)
                    .collect()
            },
        )
    } else {
        summary
            .chunk_indexes
            .iter()
            .flat_map(|c| c.message_index_offsets.keys().copied())
            .collect()
    };
    table.empty = ids
        .iter()
        .copied()
        .filter(|id| !with_messages.contains(id))
        .collect();
    for &id in &ids {
        if let Some(c) = summary.channels.get(&id) {
            let schema = c.schema.as_ref().map(|s| s.name.as_str());
            table.add(id, &c.topic, &c.message_encoding, schema);
        }
    }
    ids.iter()
        .copied()
        .filter(|id| table.roles.get(id) == Some(&Role::Tf(true)))
        .collect()
}
