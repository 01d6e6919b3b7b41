//! [`McapFile`]: one MCAP file's frames, by index — through the summary and the image channel's
//! message indexes when the summary describes the whole file, else through one walk of the data
//! section (chunked or not, cut off or whole) — each frame's image with the messages that go
//! with it.

use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use mcap::records::op;

use super::super::{IMAGE_TOPIC, StreamError, StreamInfo};
use super::catalog::{Catalog, ChannelSummary, RecordCounts};
use super::channels::{ChannelTable, ImageTopic, Role};
use super::chunk::{Block, Msg, decode_chunk_block, decode_loose_block};
use super::summary::SummaryProblem;
use super::{RawFrame, RawMsg};
use crate::formats::MessageKind;

/// The MCAP magic bytes at both ends of a file.
pub(super) const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";
/// Largest chunk record read into memory, bytes (compressed or not); larger ones are corrupt.
pub(super) const MAX_CHUNK_BYTES: u64 = 1 << 30;
/// The file's read buffer, bytes: small records read one after another come from it; reads
/// at least this long bypass it. Each jump elsewhere (a message index, a frame's chunk) refills
/// it, so it is kept small.
const READ_BUFFER_BYTES: usize = 16 << 10;
/// Largest summary-side record (message index, metadata) read, bytes.
pub(super) const MAX_INDEX_BYTES: u64 = 64 << 20;
/// Most blocks read at opening for `/tf_static` (it is written once, at the start).
const MAX_STATIC_BLOCKS: usize = 64;
/// Warnings kept by one file before the reader takes them; the reader bounds them again.
const MAX_FILE_WARNINGS: usize = 1000;

/// What a block of the file is: one chunk record, or a run of records outside chunks (a frame's
/// image message and the messages after it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum BlockKind {
    Chunk,
    Loose,
}

/// Where a block of records holding frames lies in the file (opcodes and length prefixes
/// included), bytes.
#[derive(Debug, Clone, Copy)]
pub(super) struct BlockLoc {
    pub(super) offset: u64,
    pub(super) length: u64,
    pub(super) kind: BlockKind,
}

/// Where a frame is: its time, its block, and which image message of that block it is.
#[derive(Debug, Clone, Copy)]
pub(super) struct FrameLoc {
    pub(super) time_ns: u64,
    pub(super) block: u32,
    pub(super) nth: u32,
}

/// One MCAP file of a recording (an eotn stream, another writer's MCAP, or one storage file of
/// a rosbag2 bag).
///
/// Opening reads the summary and the image channel's message indexes (a few bytes per chunk)
/// when the summary describes the whole file (statistics matching its channels, schemas and
/// indexes, as eotn and most writers write); any other valid MCAP file — unchunked, without a
/// summary or statistics, channels repeated without their schemas — is read through its data
/// section once. [`McapFile::read_raw`] then reads and decompresses only the block holding the
/// frame and keeps that one block cached. Memory is this index (16 bytes a frame) plus one
/// chunk, whatever the file's length.
pub(super) struct McapFile {
    path: PathBuf,
    file: BufReader<File>,
    /// Where `file` is, bytes; `None` after an I/O error (the next read seeks from the start).
    pos: Option<u64>,
    pub(super) file_len: u64,
    pub(super) info: StreamInfo,
    /// The recognition parameter set the stream names (`eotn.recognition` metadata).
    pub(super) param_set: Option<String>,
    /// Each camera's default files (`eotn.camera` metadata), by image topic.
    pub(super) camera_files: Vec<(String, crate::camera::CameraFiles)>,
    /// Written by eotn (its `eotn.stream` metadata): a frame's messages follow its image.
    pub(super) written_by_eotn: bool,
    roles: HashMap<u16, Role>,
    image_channel: Option<u16>,
    image_kind: Option<MessageKind>,
    pub(super) image_topics: Vec<ImageTopic>,
    /// Every channel of the file, by id.
    pub(super) channels: Vec<ChannelSummary>,
    pub(super) counts: RecordCounts,
    /// Blocks holding frames, in file order.
    pub(super) blocks: Vec<BlockLoc>,
    pub(super) frames: Vec<FrameLoc>,
    /// Blocks that hold `/tf_static` messages.
    static_blocks: Vec<BlockLoc>,
    /// True when the index came from the summary alone (the data section was not read).
    pub(super) from_summary: bool,
    /// The block last read, by number: its records and where its messages lie in them.
    cache: Option<(u32, Block)>,
    /// Warnings not yet taken by the reader.
    pub(super) warnings: Vec<String>,
    /// Facts about the file worth a line (not problems with it).
    pub(super) notes: Vec<String>,
}

impl std::fmt::Debug for McapFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapFile")
            .field("path", &self.path)
            .field("frames", &self.frames.len())
            .field("chunks", &self.counts.chunks)
            .finish_non_exhaustive()
    }
}

impl McapFile {
    /// Opens one MCAP file, reading frames from `wanted_topic` when given (else the canonical
    /// image topic, else the first image channel with messages). Files cut off before their
    /// footer are recovered by scanning their complete chunks, and say so in the warnings;
    /// files without frames open with zero frames and say so in the notes.
    ///
    /// # Errors
    /// [`StreamError`] naming the file when it cannot be read or is not MCAP at all.
    pub(super) fn open(path: &Path, wanted_topic: Option<String>) -> Result<Self, StreamError> {
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
            camera_files: Vec::new(),
            written_by_eotn: false,
            roles: HashMap::new(),
            image_channel: None,
            image_kind: None,
            image_topics: Vec::new(),
            channels: Vec::new(),
            counts: RecordCounts::default(),
            blocks: Vec::new(),
            frames: Vec::new(),
            static_blocks: Vec::new(),
            from_summary: false,
            cache: None,
            warnings: Vec::new(),
            notes: Vec::new(),
        };
        reader.check_magic()?;
        let mut table = ChannelTable::wanting(wanted_topic.clone());
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
            table = ChannelTable::wanting(wanted_topic);
            catalog = Catalog::default();
            reader.info = StreamInfo::default();
            reader.param_set = None;
            reader.camera_files.clear();
            reader.written_by_eotn = false;
            reader.notes.clear();
            reader.blocks.clear();
            reader.frames.clear();
            reader.static_blocks.clear();
            reader.scan(&mut table, &mut catalog)?;
        }
        table.note_other_cameras();
        reader.notes.append(&mut table.notes);
        if table.image.is_none() {
            reader.notes.push(format!(
                "no camera frames: no camera image channel ({IMAGE_TOPIC} or any other image topic) among its {} channels",
                catalog.counts.channels
            ));
        }
        (reader.channels, reader.counts) = catalog.into_channels();
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

    /// Number of chunk records in the file (after a recovery scan, the complete chunks found).
    pub(super) fn chunk_count(&self) -> usize {
        usize::try_from(self.counts.chunks).unwrap_or(usize::MAX)
    }

    /// Frame `index`'s image and the messages that go with it, borrowed from the cached block.
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
        if self.cache.as_ref().is_none_or(|(c, _)| *c != loc.block) {
            self.cache = None;
            let messages = self.load_block(loc.block)?;
            self.cache = Some((loc.block, messages));
        }
        let (Some((_, block)), Some(image), Some(kind)) =
            (self.cache.as_ref(), self.image_channel, self.image_kind)
        else {
            return Err(self.corrupt(format!("frame {index}: its chunk could not be loaded")));
        };
        let messages = &block.messages;
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
        let others = if self.written_by_eotn {
            messages[at + 1..end]
                .iter()
                .filter_map(|m| self.raw_msg(block, m))
                .collect()
        } else {
            let t = messages[at].log_time;
            let mut nearest: HashMap<u16, usize> = HashMap::new();
            for (i, m) in messages.iter().enumerate().take(end).skip(start) {
                if i == at || self.raw_msg(block, m).is_none() {
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
            picked
                .into_iter()
                .filter_map(|i| self.raw_msg(block, &messages[i]))
                .collect()
        };
        Ok(RawFrame {
            time_ns: loc.time_ns,
            kind,
            image: Cow::Borrowed(block.data(&messages[at])),
            others,
        })
    }

    /// A message that goes with a frame, when its channel is read and is not the camera.
    fn raw_msg<'a>(&self, block: &'a Block, m: &Msg) -> Option<RawMsg<'a>> {
        match self.roles.get(&m.channel) {
            None | Some(Role::Ignored | Role::Image(_)) => None,
            Some(role) => Some(RawMsg {
                role: role.clone(),
                data: Cow::Borrowed(block.data(m)),
            }),
        }
    }

    /// The `/tf_static` channels.
    pub(super) fn static_channels(roles: &HashMap<u16, Role>) -> HashSet<u16> {
        roles
            .iter()
            .filter(|(_, r)| **r == Role::Tf(true))
            .map(|(id, _)| *id)
            .collect()
    }

    /// Every `/tf_static` message of the file (it is written once, near the start), bytes in
    /// file order.
    pub(super) fn static_transforms(&mut self) -> Vec<Vec<u8>> {
        let statics = Self::static_channels(&self.roles);
        let mut out = Vec::new();
        for loc in std::mem::take(&mut self.static_blocks) {
            if let Ok(block) = self.load_loc(loc) {
                out.extend(
                    block
                        .messages
                        .iter()
                        .filter(|m| statics.contains(&m.channel))
                        .map(|m| block.data(m).to_vec()),
                );
            }
        }
        out
    }

    /// Remembers a block that holds `/tf_static` messages (the first few only).
    pub(super) fn note_static_block(&mut self, loc: BlockLoc) {
        if self.static_blocks.len() < MAX_STATIC_BLOCKS {
            self.static_blocks.push(loc);
        }
    }

    pub(super) fn warn(&mut self, text: String) {
        // Bounded: the reader keeps only the first hundred anyway.
        if self.warnings.len() < MAX_FILE_WARNINGS {
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
        move |cause| StreamError::Mcap {
            path,
            context,
            cause,
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
    pub(super) fn read_record_at(
        &mut self,
        offset: u64,
        limit: u64,
    ) -> Result<(u8, Vec<u8>), StreamError> {
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
    pub(super) fn push_block(&mut self, loc: BlockLoc) -> Result<u32, StreamError> {
        let block = u32::try_from(self.blocks.len())
            .map_err(|_| self.corrupt("more than 2³² chunks".to_owned()))?;
        self.blocks.push(loc);
        Ok(block)
    }

    /// Reads block `block` into its messages: a chunk decompressed, or records outside chunks.
    fn load_block(&mut self, block: u32) -> Result<Block, StreamError> {
        let loc = *self
            .blocks
            .get(block as usize)
            .ok_or_else(|| self.corrupt(format!("no chunk {block}")))?;
        self.load_loc(loc)
    }

    /// Reads the block at `loc`: its records as read (decompressed when compressed), and where
    /// its messages lie in them.
    fn load_loc(&mut self, loc: BlockLoc) -> Result<Block, StreamError> {
        if loc.kind == BlockKind::Loose {
            let bytes = self.read_exact_at(loc.offset, loc.length)?;
            return decode_loose_block(bytes)
                .map_err(self.mcap_err(format!("reading the messages at offset {}", loc.offset)));
        }
        let (opcode, body) = self.read_record_at(loc.offset, loc.length.saturating_sub(9))?;
        if opcode != op::CHUNK {
            return Err(self.corrupt(format!(
                "the chunk index points at offset {} which holds no chunk",
                loc.offset
            )));
        }
        decode_chunk_block(body)
            .map_err(self.mcap_err(format!("reading the chunk at offset {}", loc.offset)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Frame, Yuv};
    use crate::streams::schema::{ImageEncoding, encode_image, raw_image_schema};

    /// Another writer's file of `n` 4×2 frames on `/cam`, one uncompressed chunk each (with
    /// its CRC), and a complete summary: statistics, chunk and message indexes.
    fn chunked_file(path: &Path, n: u8) {
        let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
        let mut w = mcap::WriteOptions::new()
            .compression(None)
            .create(file)
            .unwrap();
        let s = raw_image_schema().unwrap();
        let sid = w.add_schema(&s.name, &s.encoding, &s.data).unwrap();
        let ch = w
            .add_channel(sid, "/cam", "protobuf", &Default::default())
            .unwrap();
        let mut buf = Vec::new();
        for i in 0..n {
            let t = 100 * u64::from(i) + 100;
            let f = Frame::filled_uyvy(4, 2, Yuv::new(i, 128, 128)).unwrap();
            encode_image(t, &f, ImageEncoding::Uyvy, &mut buf).unwrap();
            let header = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: 0,
                log_time: t,
                publish_time: t,
            };
            w.write_to_known_channel(&header, &buf).unwrap();
            // Ends the chunk: one chunk a frame.
            w.flush().unwrap();
        }
        w.finish().unwrap();
    }

    /// A file whose summary is complete opens from the summary alone: the chunk of frame 1 is
    /// damaged (a byte of its records flipped, so its CRC fails), and opening neither sees nor
    /// warns about it — a walk of the data section would (`from_summary` is what decides) —,
    /// while reading that frame finds the damage and the other frames read.
    #[test]
    fn a_complete_summary_is_enough() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.mcap");
        chunked_file(&p, 3);
        let mut bytes = std::fs::read(&p).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        assert_eq!(summary.chunk_indexes.len(), 3, "one chunk a frame");
        let second = &summary.chunk_indexes[1];
        let last_record_byte = second.chunk_start_offset + second.chunk_length - 1;
        bytes[usize::try_from(last_record_byte).unwrap()] ^= 0xff;
        std::fs::write(&p, &bytes).unwrap();

        let mut f = McapFile::open(&p, None).unwrap();
        assert!(
            f.from_summary,
            "a complete summary: the data section is not read"
        );
        assert!(f.warnings.is_empty(), "{:?}", f.warnings);
        assert_eq!(f.frames.len(), 3);
        assert_eq!(f.chunk_count(), 3);
        let e = f.read_raw(1).err().unwrap().to_string();
        assert!(e.contains("CRC"), "{e}");
        for i in [0, 2] {
            let raw = f.read_raw(i).unwrap();
            assert_eq!(raw.time_ns, 100 * i as u64 + 100);
        }

        // Without its statistics the summary does not say it describes the whole file: the data
        // section is walked, and the damaged chunk is found at opening.
        let mut bare = mcap::WriteOptions::new()
            .compression(None)
            .emit_statistics(false)
            .create(std::io::BufWriter::new(
                std::fs::File::create(dir.path().join("g.mcap")).unwrap(),
            ))
            .unwrap();
        let s = raw_image_schema().unwrap();
        let sid = bare.add_schema(&s.name, &s.encoding, &s.data).unwrap();
        let ch = bare
            .add_channel(sid, "/cam", "protobuf", &Default::default())
            .unwrap();
        let mut buf = Vec::new();
        let f0 = Frame::filled_uyvy(4, 2, Yuv::new(9, 128, 128)).unwrap();
        encode_image(5, &f0, ImageEncoding::Uyvy, &mut buf).unwrap();
        let header = mcap::records::MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: 5,
            publish_time: 5,
        };
        bare.write_to_known_channel(&header, &buf).unwrap();
        bare.finish().unwrap();
        drop(bare);
        let g = McapFile::open(&dir.path().join("g.mcap"), None).unwrap();
        assert!(!g.from_summary, "no statistics: the data section is walked");
        assert_eq!(g.frames.len(), 1);
    }
}
