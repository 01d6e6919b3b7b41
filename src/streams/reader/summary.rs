//! The summary section: the footer, then the summary's schemas, channels, statistics and
//! indexes read record by record; and the frame index built from them when they describe the
//! whole file.
//!
//! Not read through mcap's `SummaryReader`: it rejects a summary that repeats channels without
//! their schemas, which the specification allows (the schemas are in the data section).

use mcap::records::{Channel, ChunkIndex, MetadataIndex, Record, Statistics, op};

use super::super::{
    CAMERA_METADATA_NAME, IMAGE_TOPIC, METADATA_NAME, PARAMS_METADATA_NAME, StreamError, StreamInfo,
};
use super::catalog::Catalog;
use super::channels::ChannelTable;
use super::mcap_file::{
    BlockKind, BlockLoc, FrameLoc, MAGIC, MAX_CHUNK_BYTES, MAX_INDEX_BYTES, McapFile,
};

/// The footer record (opcode, length, 20-byte body) and the closing magic, bytes.
const FOOTER_AND_MAGIC: u64 = 1 + 8 + 20 + 8;
/// Largest summary section read, bytes: a chunk index is about 100 bytes, so this is millions
/// of chunks; a larger claim is damage.
const MAX_SUMMARY_BYTES: u64 = 256 << 20;

/// What the summary section holds (empty when the footer says there is none).
#[derive(Debug, Default)]
pub(super) struct Summary {
    /// Schemas: id, name, encoding.
    schemas: Vec<(u16, String, String)>,
    channels: Vec<Channel>,
    stats: Option<Statistics>,
    chunk_indexes: Vec<ChunkIndex>,
    metadata_indexes: Vec<MetadataIndex>,
}

/// Why the summary cannot be used; the data section is read instead.
#[derive(Debug)]
pub(super) enum SummaryProblem {
    /// No footer at the end: the file was cut off, or its writer never finished it.
    NoFooter(String),
    /// A footer, but the summary it points at is damaged.
    Damaged(String),
}

impl McapFile {
    /// Reads the footer and the summary section it points at.
    ///
    /// # Errors
    /// I/O errors; what is wrong with the footer or summary is the inner [`SummaryProblem`].
    pub(super) fn read_summary(&mut self) -> Result<Result<Summary, SummaryProblem>, StreamError> {
        use SummaryProblem::{Damaged, NoFooter};
        let file_len = self.file_len;
        if file_len < MAGIC.len() as u64 + FOOTER_AND_MAGIC {
            return Ok(Err(NoFooter(
                "the file is too short to hold a footer".into(),
            )));
        }
        let footer_start = file_len - FOOTER_AND_MAGIC;
        let tail = self.read_exact_at(footer_start, FOOTER_AND_MAGIC)?;
        let u64_at = |b: &[u8], at: usize| {
            b.get(at..at + 8)
                .and_then(|s| s.try_into().ok())
                .map_or(u64::MAX, u64::from_le_bytes)
        };
        if &tail[29..] != MAGIC {
            return Ok(Err(NoFooter(
                "the file does not end with the MCAP magic bytes".into(),
            )));
        }
        if tail[0] != op::FOOTER || u64_at(&tail, 1) != 20 {
            return Ok(Err(NoFooter(
                "no footer record before the closing magic bytes".into(),
            )));
        }
        let summary_start = u64_at(&tail, 9);
        let offsets_start = u64_at(&tail, 17);
        let crc = u32::from_le_bytes([tail[25], tail[26], tail[27], tail[28]]);
        if summary_start == 0 {
            return Ok(Ok(Summary::default()));
        }
        let end = if offsets_start == 0 {
            footer_start
        } else {
            offsets_start
        };
        if summary_start < MAGIC.len() as u64 || summary_start > end || end > footer_start {
            return Ok(Err(Damaged(format!(
                "the footer points outside the file (summary at {summary_start}, offsets at {offsets_start})"
            ))));
        }
        // The CRC covers the summary, the summary offsets and the footer up to its CRC field.
        let crc_len = footer_start + 1 + 8 + 16 - summary_start;
        if crc_len > MAX_SUMMARY_BYTES {
            return Ok(Err(Damaged(format!("the summary claims {crc_len} bytes"))));
        }
        let bytes = self.read_exact_at(summary_start, crc_len)?;
        if crc != 0 && crc32fast::hash(&bytes) != crc {
            return Ok(Err(Damaged("its CRC does not match".into())));
        }
        let records = &bytes[..usize::try_from(end - summary_start).unwrap_or(0)];
        Ok(parse_summary(records, summary_start).map_err(Damaged))
    }

    /// Builds the catalog and the frame index from the summary alone. `false` when the summary
    /// does not describe the whole file — no statistics, channels or schemas left out, messages
    /// outside indexed chunks, chunks without message indexes — so the caller reads the data
    /// section instead; everything set here is then reset.
    pub(super) fn index_from_summary(
        &mut self,
        summary: &Summary,
        table: &mut ChannelTable,
        catalog: &mut Catalog,
    ) -> Result<bool, StreamError> {
        let Some(stats) = &summary.stats else {
            return Ok(false);
        };
        for (id, name, encoding) in &summary.schemas {
            catalog.add_schema(*id, name, encoding);
        }
        for c in &summary.channels {
            catalog.add_channel(c);
        }
        if !describes_whole_file(summary, stats, catalog) {
            return Ok(false);
        }
        catalog.set_message_counts(&stats.channel_message_counts);
        catalog.counts.chunks = stats.chunk_count.into();
        catalog.counts.attachments = stats.attachment_count.into();
        catalog.counts.metadata = stats.metadata_count.into();
        self.metadata_from_indexes(&summary.metadata_indexes);
        if self.info == StreamInfo::default() {
            self.no_metadata();
        }
        // A channel without messages is never chosen as the camera.
        table.empty = summary
            .channels
            .iter()
            .map(|c| c.id)
            .filter(|id| stats.channel_message_counts.get(id).is_none_or(|n| *n == 0))
            .collect();
        let mut channels: Vec<&Channel> = summary.channels.iter().collect();
        // Prefer the canonical image topic over any other RawImage channel.
        channels.sort_by_key(|c| (c.topic != IMAGE_TOPIC, c.id));
        for c in channels {
            table.add(
                c.id,
                &c.topic,
                &c.message_encoding,
                catalog.schema_name(c.schema_id),
            );
        }
        self.static_blocks_from_indexes(&summary.chunk_indexes, table);
        let Some(image) = table.image else {
            return Ok(true);
        };
        let frames = stats.channel_message_counts.get(&image).copied();
        if frames.unwrap_or(0) == 0 {
            return Ok(true);
        }
        if !self.frames_from_message_indexes(&summary.chunk_indexes, image)? {
            return Ok(false);
        }
        // Fewer indexed frames than the statistics count: some are outside chunks.
        Ok(Some(self.frames.len() as u64) == frames)
    }

    /// The chunks holding `/tf_static` messages, through the chunk indexes.
    fn static_blocks_from_indexes(&mut self, chunk_indexes: &[ChunkIndex], table: &ChannelTable) {
        let statics = McapFile::static_channels(&table.roles);
        if statics.is_empty() {
            return;
        }
        let mut sorted: Vec<&ChunkIndex> = chunk_indexes.iter().collect();
        sorted.sort_by_key(|c| c.chunk_start_offset);
        for ci in sorted {
            let inside = ci.chunk_length <= MAX_CHUNK_BYTES
                && ci.chunk_start_offset.saturating_add(ci.chunk_length) <= self.file_len;
            if inside
                && ci
                    .message_index_offsets
                    .keys()
                    .any(|id| statics.contains(id))
            {
                self.note_static_block(BlockLoc {
                    offset: ci.chunk_start_offset,
                    length: ci.chunk_length,
                    kind: BlockKind::Chunk,
                });
            }
        }
    }

    /// The image channel's frames through each chunk's message index. `false` when a chunk has
    /// no message indexes or they are unreadable (the caller reads the data section).
    fn frames_from_message_indexes(
        &mut self,
        chunk_indexes: &[ChunkIndex],
        image: u16,
    ) -> Result<bool, StreamError> {
        let mut sorted: Vec<&ChunkIndex> = chunk_indexes.iter().collect();
        sorted.sort_by_key(|c| c.chunk_start_offset);
        for ci in sorted {
            if ci.chunk_length > MAX_CHUNK_BYTES
                || ci.chunk_start_offset.saturating_add(ci.chunk_length) > self.file_len
            {
                self.warn(format!(
                    "chunk index points outside the file (offset {}, {} bytes); the summary is not trusted",
                    ci.chunk_start_offset, ci.chunk_length
                ));
                return Ok(false);
            }
            // An empty map means the chunk has no message indexes: only reading it tells.
            if ci.message_index_offsets.is_empty() {
                return Ok(false);
            }
            let Some(&at) = ci.message_index_offsets.get(&image) else {
                continue;
            };
            let Some(mut entries) = self.message_index(at, image) else {
                return Ok(false);
            };
            let block = self.push_block(BlockLoc {
                offset: ci.chunk_start_offset,
                length: ci.chunk_length,
                kind: BlockKind::Chunk,
            })?;
            entries.sort_by_key(|e| e.offset);
            for (nth, e) in entries.iter().enumerate() {
                self.frames.push(FrameLoc {
                    time_ns: e.log_time,
                    block,
                    nth: u32::try_from(nth).unwrap_or(u32::MAX),
                });
            }
        }
        Ok(true)
    }

    /// The entries of the message index record of `channel` at `at`; `None` (with a warning)
    /// when it is unreadable or malformed.
    fn message_index(
        &mut self,
        at: u64,
        channel: u16,
    ) -> Option<Vec<mcap::records::MessageIndexEntry>> {
        match self.read_record_at(at, MAX_INDEX_BYTES) {
            Ok((op::MESSAGE_INDEX, body)) => match mcap::parse_record(op::MESSAGE_INDEX, &body) {
                Ok(Record::MessageIndex(mi)) if mi.channel_id == channel => Some(mi.records),
                _ => {
                    self.warn(format!(
                        "message index at offset {at} is malformed; scanning instead"
                    ));
                    None
                }
            },
            Ok(_) | Err(_) => {
                self.warn(format!(
                    "message index at offset {at} is unreadable; scanning instead"
                ));
                None
            }
        }
    }

    /// The stream's own metadata records (`eotn.stream`, `eotn.recognition`, `eotn.camera`),
    /// found through
    /// the summary's metadata indexes.
    fn metadata_from_indexes(&mut self, indexes: &[MetadataIndex]) {
        for index in indexes {
            if ![METADATA_NAME, PARAMS_METADATA_NAME, CAMERA_METADATA_NAME]
                .contains(&index.name.as_str())
            {
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
    }

    /// Without `eotn.stream` metadata the stream is another writer's: source `unknown` (a fact
    /// about the file, not a problem with it).
    pub(super) fn no_metadata(&mut self) {
        self.info = StreamInfo {
            source: "unknown".to_owned(),
            description: String::new(),
        };
        self.notes.push(format!(
            "no {METADATA_NAME} metadata: not written by eotn, source unknown"
        ));
    }

    /// A metadata record: the stream's info or parameter set when it is one of eotn's.
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
            Ok(Record::Metadata(m)) if m.name == CAMERA_METADATA_NAME => {
                match crate::camera::CameraFiles::from_metadata(&m.metadata) {
                    Ok(camera) => self.camera_files.push(camera),
                    Err(e) => self.warn(format!("{e}; ignored")),
                }
            }
            Ok(Record::Metadata(_)) => {}
            _ => self.warn("a metadata record is malformed; ignored".to_owned()),
        }
    }
}

/// True when the summary alone gives the file's true counts: statistics whose counts its
/// schemas, channels, chunk and metadata indexes match, with per-channel message counts.
fn describes_whole_file(summary: &Summary, stats: &Statistics, catalog: &Catalog) -> bool {
    let per_channel = stats
        .channel_message_counts
        .values()
        .fold(0u64, |a, &n| a.saturating_add(n));
    catalog.counts.schemas == u64::from(stats.schema_count)
        && catalog.counts.channels == u64::from(stats.channel_count)
        && summary
            .channels
            .iter()
            .all(|c| catalog.has_schema(c.schema_id))
        && summary.chunk_indexes.len() as u64 == u64::from(stats.chunk_count)
        && summary.metadata_indexes.len() as u64 == u64::from(stats.metadata_count)
        && per_channel == stats.message_count
        && stats
            .channel_message_counts
            .keys()
            .all(|id| summary.channels.iter().any(|c| c.id == *id))
}

/// Parses the summary section's records (`start`: its offset in the file, for messages).
/// Attachment indexes, summary offsets and unknown records are skipped.
fn parse_summary(bytes: &[u8], start: u64) -> Result<Summary, String> {
    let mut summary = Summary::default();
    let mut at = 0usize;
    while at < bytes.len() {
        let offset = start + at as u64;
        let Some(head) = bytes.get(at..at + 9) else {
            return Err(format!("a record header at offset {offset} is cut off"));
        };
        let len = head[1..9].try_into().map_or(u64::MAX, u64::from_le_bytes);
        let body_start = at + 9;
        let Some(body) = usize::try_from(len)
            .ok()
            .and_then(|n| bytes.get(body_start..body_start.checked_add(n)?))
        else {
            return Err(format!(
                "the record at offset {offset} runs past the summary"
            ));
        };
        let opcode = head[0];
        if matches!(
            opcode,
            op::SCHEMA | op::CHANNEL | op::STATISTICS | op::CHUNK_INDEX | op::METADATA_INDEX
        ) {
            let record = mcap::parse_record(opcode, body)
                .map_err(|e| format!("the record at offset {offset} is malformed ({e})"))?;
            summary.take(record);
        }
        at = body_start + body.len();
    }
    Ok(summary)
}

impl Summary {
    fn take(&mut self, record: Record<'_>) {
        match record {
            Record::Schema { header, .. } => {
                self.schemas.push((header.id, header.name, header.encoding));
            }
            Record::Channel(c) => self.channels.push(c),
            Record::Statistics(s) => {
                // At most one is allowed; the first is kept.
                self.stats.get_or_insert(s);
            }
            Record::ChunkIndex(c) => self.chunk_indexes.push(c),
            Record::MetadataIndex(m) => self.metadata_indexes.push(m),
            _ => {}
        }
    }
}
