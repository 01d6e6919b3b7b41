//! The data section read record by record: for a file whose summary does not describe it
//! (none written, no statistics, channels repeated without their schemas, messages outside
//! chunks), and as the recovery of a file cut off or never finished — up to its first record
//! that is cut off or damaged. Each chunk is decompressed once; messages outside chunks are
//! read in place.

use mcap::records::{Record, op};

use super::super::{StreamError, StreamInfo};
use super::catalog::Catalog;
use super::channels::{ChannelTable, Role};
use super::chunk::{ChunkItem, decode_chunk};
use super::mcap_file::{
    BlockKind, BlockLoc, FrameLoc, MAGIC, MAX_CHUNK_BYTES, MAX_INDEX_BYTES, McapFile,
};

/// Largest run of records outside chunks kept as one frame's block, bytes: a frame's image
/// and the messages after it that belong to it.
const MAX_LOOSE_BLOCK_BYTES: u64 = 64 << 20;
/// Bytes of a message record's body before its data: channel, sequence, log and publish time.
const MESSAGE_HEADER_BYTES: u64 = 2 + 4 + 8 + 8;

/// How a walk of the data section ended.
#[derive(Debug, PartialEq, Eq)]
pub(super) enum WalkEnd {
    /// At the Data End record (or the footer): the data section is whole.
    Complete,
    /// The visitor stopped it at damage it has reported.
    Stopped,
    /// The file ends at a record boundary, before any Data End record.
    FileEnds,
    /// The file ends inside a record: what is cut off.
    CutOff(String),
}

impl McapFile {
    /// Walks the data section's records from the header on, calling `each` with the opcode,
    /// offset and body length of every record that lies whole in the file, until the Data End
    /// record, the end of the file, a record cut off, or `each` returns `false`.
    pub(super) fn walk(
        &mut self,
        mut each: impl FnMut(&mut Self, u8, u64, u64) -> Result<bool, StreamError>,
    ) -> Result<WalkEnd, StreamError> {
        let mut offset = MAGIC.len() as u64;
        loop {
            let remaining = self.file_len.saturating_sub(offset);
            if remaining == 0 {
                return Ok(WalkEnd::FileEnds);
            }
            if remaining < 9 {
                return Ok(WalkEnd::CutOff(format!(
                    "the file ends inside a record header at offset {offset}"
                )));
            }
            let head = self.read_exact_at(offset, 9)?;
            let opcode = head[0];
            let len = u64::from_le_bytes(head[1..9].try_into().unwrap_or([0xff; 8]));
            if opcode == op::DATA_END || opcode == op::FOOTER {
                return Ok(WalkEnd::Complete);
            }
            if len > remaining - 9 {
                return Ok(WalkEnd::CutOff(format!(
                    "record at offset {offset} (opcode {opcode:#04x}) needs {len} bytes but the file ends after {}: it was cut off; frames up to the last complete chunk are kept",
                    remaining - 9
                )));
            }
            if !each(self, opcode, offset, len)? {
                return Ok(WalkEnd::Stopped);
            }
            offset += 9 + len;
        }
    }

    /// Reads the data section into `table`, `catalog` and the frame index, and says what was
    /// wrong with it, if anything: a file whose data section is whole reads without warnings.
    pub(super) fn scan(
        &mut self,
        table: &mut ChannelTable,
        catalog: &mut Catalog,
    ) -> Result<(), StreamError> {
        // The block of the last frame found outside chunks, while the records after it may
        // still belong to that frame.
        let mut loose: Option<u32> = None;
        let end = self.walk(|r, opcode, offset, len| match opcode {
            op::CHUNK => {
                loose = None;
                r.scan_chunk(offset, len, table, catalog)
            }
            op::MESSAGE => r.scan_message(offset, len, table, catalog, &mut loose),
            _ => {
                r.extend_loose(&mut loose, offset, len);
                match opcode {
                    op::SCHEMA | op::CHANNEL | op::METADATA => {
                        r.scan_index_record(offset, opcode, len, table, catalog)
                    }
                    op::ATTACHMENT => {
                        catalog.counts.attachments += 1;
                        Ok(true)
                    }
                    // The header, message indexes, and records this reader does not know.
                    _ => Ok(true),
                }
            }
        })?;
        self.finish_scan(end, catalog);
        Ok(())
    }

    /// The chunk record at `offset` (body `len` bytes): its schemas and channels, its message
    /// counts, its images as frames. `false` when it is damaged and the scan stops.
    fn scan_chunk(
        &mut self,
        offset: u64,
        len: u64,
        table: &mut ChannelTable,
        catalog: &mut Catalog,
    ) -> Result<bool, StreamError> {
        if len > MAX_CHUNK_BYTES {
            self.warn(format!(
                "chunk at offset {offset} is implausibly large ({len} bytes); stopping"
            ));
            return Ok(false);
        }
        let body = self.read_exact_at(offset + 9, len)?;
        let mut records = Vec::new();
        if let Err(e) = decode_chunk(&body, |r| records.push(r)) {
            self.warn(format!(
                "chunk at offset {offset} is damaged ({e}); frames up to the previous chunk are kept"
            ));
            return Ok(false);
        }
        catalog.counts.chunks += 1;
        let block = u32::try_from(self.blocks.len())
            .map_err(|_| self.corrupt("more than 2³² chunks".to_owned()))?;
        let mut nth = 0u32;
        let mut has_static = false;
        for r in records {
            match r {
                ChunkItem::Schema { id, name, encoding } => {
                    catalog.add_schema(id, &name, &encoding)
                }
                ChunkItem::Channel(c) => add_channel(table, catalog, &c),
                ChunkItem::Message(channel, log_time) => {
                    catalog.count_message(channel);
                    has_static |= table.roles.get(&channel) == Some(&Role::Tf(true));
                    if Some(channel) == table.image {
                        self.frames.push(FrameLoc {
                            time_ns: log_time,
                            block,
                            nth,
                        });
                        nth = nth.saturating_add(1);
                    }
                }
            }
        }
        let loc = BlockLoc {
            offset,
            length: len + 9,
            kind: BlockKind::Chunk,
        };
        if has_static {
            self.note_static_block(loc);
        }
        if nth > 0 {
            self.blocks.push(loc);
        }
        Ok(true)
    }

    /// A message record outside chunks: counted; an image starts a new frame's block, any
    /// other message joins the block of the frame before it. `false` when it is malformed.
    fn scan_message(
        &mut self,
        offset: u64,
        len: u64,
        table: &ChannelTable,
        catalog: &mut Catalog,
        loose: &mut Option<u32>,
    ) -> Result<bool, StreamError> {
        if len < MESSAGE_HEADER_BYTES {
            self.warn(format!(
                "message record at offset {offset} is too short for its header; stopping"
            ));
            return Ok(false);
        }
        let head = self.read_exact_at(offset + 9, MESSAGE_HEADER_BYTES)?;
        let channel = u16::from_le_bytes([head[0], head[1]]);
        let log_time = u64::from_le_bytes(head[6..14].try_into().unwrap_or([0; 8]));
        catalog.count_message(channel);
        if table.roles.get(&channel) == Some(&Role::Tf(true)) {
            self.note_static_block(BlockLoc {
                offset,
                length: len + 9,
                kind: BlockKind::Loose,
            });
        }
        if Some(channel) != table.image {
            self.extend_loose(loose, offset, len);
            return Ok(true);
        }
        let block = self.push_block(BlockLoc {
            offset,
            length: len + 9,
            kind: BlockKind::Loose,
        })?;
        self.frames.push(FrameLoc {
            time_ns: log_time,
            block,
            nth: 0,
        });
        *loose = Some(block);
        Ok(true)
    }

    /// Adds the record at `offset` to the open block of records outside chunks when it
    /// follows that block directly and the block stays small; else closes the block.
    fn extend_loose(&mut self, loose: &mut Option<u32>, offset: u64, len: u64) {
        let Some(b) = loose.and_then(|b| self.blocks.get_mut(b as usize)) else {
            return;
        };
        let grown = b.length + 9 + len;
        if b.offset + b.length == offset && grown <= MAX_LOOSE_BLOCK_BYTES {
            b.length = grown;
        } else {
            *loose = None;
        }
    }

    /// A schema, channel or metadata record outside chunks. `false` when it is implausibly
    /// large or malformed and the scan stops.
    fn scan_index_record(
        &mut self,
        offset: u64,
        opcode: u8,
        len: u64,
        table: &mut ChannelTable,
        catalog: &mut Catalog,
    ) -> Result<bool, StreamError> {
        if len > MAX_INDEX_BYTES {
            self.warn(format!(
                "record at offset {offset} is implausibly large; stopping"
            ));
            return Ok(false);
        }
        let body = self.read_exact_at(offset + 9, len)?;
        match mcap::parse_record(opcode, &body) {
            Ok(Record::Schema { header, .. }) => {
                catalog.add_schema(header.id, &header.name, &header.encoding);
            }
            Ok(Record::Channel(c)) => add_channel(table, catalog, &c),
            Ok(Record::Metadata(_)) => {
                catalog.counts.metadata += 1;
                self.take_metadata(opcode, &body);
            }
            _ => {
                self.warn(format!("record at offset {offset} is malformed; stopping"));
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// What a finished scan says: a note when the stream is not eotn's, warnings for messages
    /// on undefined channels and for a data section that did not end whole.
    fn finish_scan(&mut self, end: WalkEnd, catalog: &Catalog) {
        if self.info == StreamInfo::default() {
            self.no_metadata();
        }
        if catalog.orphan_messages > 0 {
            self.warn(format!(
                "{} messages on channels the file never defines were skipped",
                catalog.orphan_messages
            ));
        }
        match end {
            WalkEnd::Complete => return,
            WalkEnd::CutOff(what) => self.warn(what),
            WalkEnd::FileEnds => {
                self.warn("the file ends without its Data End record".to_owned());
            }
            WalkEnd::Stopped => {}
        }
        self.warn(format!(
            "recovered {} frames from {} complete chunks",
            self.frames.len(),
            catalog.counts.chunks
        ));
    }
}

/// A channel from the data section: into the catalog and, when new, given its role.
fn add_channel(table: &mut ChannelTable, catalog: &mut Catalog, c: &mcap::records::Channel) {
    if catalog.add_channel(c) {
        table.add(
            c.id,
            &c.topic,
            &c.message_encoding,
            catalog.schema_name(c.schema_id),
        );
    }
}
