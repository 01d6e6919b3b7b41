//! The recovery scan of a stream without a usable summary (cut off, or never finished): the
//! data section walked record by record, each chunk decompressed once, up to the first record
//! that is cut off or damaged.

use mcap::records::{Record, op};

use super::super::{StreamError, StreamInfo};
use super::channels::{ChannelTable, Role};
use super::chunk::{ChunkItem, decode_chunk};
use super::mcap_file::{ChunkLoc, FrameLoc, MAX_CHUNK_BYTES, MAX_INDEX_BYTES, McapFile};

impl McapFile {
    /// Recovery: walks the data section record by record, decompressing each chunk once, and
    /// stops at the first record that is cut off or damaged.
    pub(super) fn scan(&mut self, table: &mut ChannelTable) -> Result<(), StreamError> {
        let mut offset = 8u64;
        let mut loose_messages = 0u64;
        let mut complete = false;
        loop {
            let remaining = self.file_len.saturating_sub(offset);
            if remaining == 0 {
                break;
            }
            if remaining < 9 {
                self.warn(format!(
                    "the file ends inside a record header at offset {offset}"
                ));
                break;
            }
            let head = self.read_exact_at(offset, 9)?;
            let opcode = head[0];
            let len = u64::from_le_bytes(head[1..9].try_into().unwrap_or([0xff; 8]));
            if opcode == op::DATA_END || opcode == op::FOOTER {
                complete = true;
                break;
            }
            if len > remaining - 9 {
                self.warn(format!(
                    "record at offset {offset} (opcode {opcode:#04x}) needs {len} bytes but the file ends after {}: it was cut off; frames up to the last complete chunk are kept",
                    remaining - 9
                ));
                break;
            }
            let go_on = match opcode {
                op::CHUNK => self.scan_chunk(offset, len, table)?,
                op::SCHEMA | op::CHANNEL | op::METADATA => {
                    self.scan_index_record(offset, opcode, len, table)?
                }
                op::MESSAGE => {
                    loose_messages += 1;
                    true
                }
                _ => true,
            };
            if !go_on {
                break;
            }
            offset += 9 + len;
        }
        self.finish_scan(loose_messages, complete);
        Ok(())
    }

    /// The chunk record at `offset` (body `len` bytes): its schemas and channels into `table`,
    /// its images as frames. `false` when it is damaged and the scan stops.
    fn scan_chunk(
        &mut self,
        offset: u64,
        len: u64,
        table: &mut ChannelTable,
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
        let chunk = u32::try_from(self.chunks.len())
            .map_err(|_| self.corrupt("more than 2³² chunks".to_owned()))?;
        let mut nth = 0u32;
        let mut has_static = false;
        for r in records {
            match r {
                ChunkItem::Schema(id, name) => {
                    table.schema_names.insert(id, name);
                }
                ChunkItem::Channel(c) => add_channel(table, &c),
                ChunkItem::Message(channel, log_time) => {
                    has_static |= table.roles.get(&channel) == Some(&Role::Tf(true));
                    if Some(channel) == table.image {
                        self.frames.push(FrameLoc {
                            time_ns: log_time,
                            chunk,
                            nth,
                        });
                        nth = nth.saturating_add(1);
                    }
                }
            }
        }
        let loc = ChunkLoc {
            offset,
            length: len + 9,
        };
        if has_static {
            self.note_static_chunk(loc);
        }
        self.chunks.push(loc);
        Ok(true)
    }

    /// A schema, channel or metadata record outside chunks. `false` when it is implausibly
    /// large or malformed and the scan stops.
    fn scan_index_record(
        &mut self,
        offset: u64,
        opcode: u8,
        len: u64,
        table: &mut ChannelTable,
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
                table.schema_names.insert(header.id, header.name);
            }
            Ok(Record::Channel(c)) => add_channel(table, &c),
            Ok(Record::Metadata(_)) => self.take_metadata(opcode, &body),
            _ => {
                self.warn(format!("record at offset {offset} is malformed; stopping"));
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// The warnings of a finished scan: no metadata, skipped loose messages, a recovered
    /// (incomplete) file.
    fn finish_scan(&mut self, loose_messages: u64, complete: bool) {
        if self.info == StreamInfo::default() {
            self.no_metadata();
        }
        if loose_messages > 0 {
            self.warn(format!(
                "{loose_messages} messages outside chunks were skipped (only chunked streams are read)"
            ));
        }
        if !complete {
            self.warn(format!(
                "recovered {} frames from {} complete chunks",
                self.frames.len(),
                self.chunks.len()
            ));
        }
    }
}

fn add_channel(table: &mut ChannelTable, c: &mcap::records::Channel) {
    let schema = table.schema_names.get(&c.schema_id).cloned();
    table.add(c.id, &c.topic, &c.message_encoding, schema.as_deref());
}
