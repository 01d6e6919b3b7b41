//! A chunk record's body, read without copying: its schemas, channels and messages; and a run
//! of message records outside chunks.

use std::io::Read;
use std::ops::Range;

use mcap::records::{Record, op};

use super::mcap_file::MAX_CHUNK_BYTES;

/// What the recovery scan needs from a chunk's records.
pub(super) enum ChunkItem {
    Schema {
        id: u16,
        name: String,
        encoding: String,
    },
    Channel(mcap::records::Channel),
    Message(u16, u64),
}

/// Parses a chunk record's body and calls `each` for its schemas, channels and messages.
pub(super) fn decode_chunk(
    body: &[u8],
    mut each: impl FnMut(ChunkItem),
) -> Result<(), mcap::McapError> {
    for_each_chunk_record(body, |r| match r {
        Record::Schema { header, .. } => each(ChunkItem::Schema {
            id: header.id,
            name: header.name,
            encoding: header.encoding,
        }),
        Record::Channel(c) => each(ChunkItem::Channel(c)),
        Record::Message { header, .. } => {
            each(ChunkItem::Message(header.channel_id, header.log_time));
        }
        _ => {}
    })
}

/// A block of records in memory — a chunk's records (the chunk record's body as read when it is
/// not compressed, else its records decompressed), or a run of records outside chunks as read —
/// and where each message's data lies in it. Messages are not copied out: a frame's decoder
/// reads its pixels from here, the one copy they get on their way into the frame.
#[derive(Debug, Default)]
pub(super) struct Block {
    bytes: Vec<u8>,
    /// The block's messages, in file order.
    pub(super) messages: Vec<Msg>,
}

/// One message of a [`Block`]: its channel, log time and where its data lies in the block.
#[derive(Debug, Clone)]
pub(super) struct Msg {
    pub(super) channel: u16,
    pub(super) log_time: u64,
    data: Range<usize>,
}

impl Block {
    /// Message `m`'s data (borrowed from the block).
    pub(super) fn data(&self, m: &Msg) -> &[u8] {
        self.bytes.get(m.data.clone()).unwrap_or(&[])
    }
}

/// The fixed part of a message record's body before its data: channel id (2 bytes), sequence
/// (4), log time (8), publish time (8).
const MESSAGE_HEADER_BYTES: usize = 22;

/// A chunk record's body into its block: decompressed (zstd, lz4) or, uncompressed, kept as it
/// is; its CRC checked when it has one; its messages located.
pub(super) fn decode_chunk_block(body: Vec<u8>) -> Result<Block, mcap::McapError> {
    let Record::Chunk { header, data } = mcap::parse_record(op::CHUNK, &body)? else {
        return Err(mcap::McapError::BadIndex);
    };
    if header.uncompressed_size > MAX_CHUNK_BYTES {
        return Err(mcap::McapError::ChunkTooLarge(header.uncompressed_size));
    }
    let size = usize::try_from(header.uncompressed_size)
        .map_err(|_| mcap::McapError::ChunkTooLarge(header.uncompressed_size))?;
    // The records are the chunk's last field: start and end time, uncompressed size and CRC
    // (28 bytes), the compression string (4 + its length), the records' length (8).
    let start = 40 + header.compression.len();
    let records = start..start + data.len();
    let decompressed = match header.compression.as_str() {
        "" => None,
        "zstd" => {
            let decoder = zstd::stream::read::Decoder::new(&data[..])?;
            Some(read_bounded(decoder, size)?)
        }
        "lz4" => Some(read_bounded(lz4::Decoder::new(&data[..])?, size)?),
        other => return Err(mcap::McapError::UnsupportedCompression(other.to_owned())),
    };
    drop(data);
    let (bytes, records) = match decompressed {
        Some(d) => {
            let n = d.len();
            (d, 0..n)
        }
        None if body.get(records.clone()).is_some() => (body, records),
        None => return Err(mcap::McapError::UnexpectedEoc),
    };
    if records.len() != size {
        return Err(mcap::McapError::DecompressionError(format!(
            "the chunk's records are {} bytes, its header says {size}",
            records.len()
        )));
    }
    let in_block = &bytes[records.clone()];
    if header.uncompressed_crc != 0 {
        let calculated = crc32fast::hash(in_block);
        if calculated != header.uncompressed_crc {
            return Err(mcap::McapError::BadChunkCrc {
                saved: header.uncompressed_crc,
                calculated,
            });
        }
    }
    let mut messages = Vec::new();
    locate_messages(&bytes, records, &mut messages)?;
    Ok(Block { bytes, messages })
}

/// Decompresses at most `size` bytes; a stream that gives more or fewer is refused by the
/// caller's length check (one byte more is read to tell).
fn read_bounded(decoder: impl Read, size: usize) -> Result<Vec<u8>, mcap::McapError> {
    let mut out = Vec::with_capacity(size.min(64 << 20));
    decoder.take(size as u64 + 1).read_to_end(&mut out)?;
    Ok(out)
}

/// Walks the whole records in `bytes[range]` and notes where each message's data lies; other
/// records are skipped.
fn locate_messages(
    bytes: &[u8],
    range: Range<usize>,
    out: &mut Vec<Msg>,
) -> Result<(), mcap::McapError> {
    let mut at = range.start;
    while at < range.end {
        let (opcode, len) = match bytes.get(at..at + 9) {
            Some(h) if at + 9 <= range.end => (
                h[0],
                u64::from_le_bytes(h[1..9].try_into().unwrap_or([0xff; 8])),
            ),
            _ => return Err(mcap::McapError::UnexpectedEoc),
        };
        let body_start = at + 9;
        let body_end = usize::try_from(len)
            .ok()
            .and_then(|n| body_start.checked_add(n))
            .filter(|&end| end <= range.end)
            .ok_or(mcap::McapError::UnexpectedEoc)?;
        if opcode == op::MESSAGE {
            let body = &bytes[body_start..body_end];
            if let Record::Message { header, .. } = mcap::parse_record(opcode, body)? {
                out.push(Msg {
                    channel: header.channel_id,
                    log_time: header.log_time,
                    data: (body_start + MESSAGE_HEADER_BYTES).min(body_end)..body_end,
                });
            }
        }
        at = body_end;
    }
    Ok(())
}

/// A run of whole records from the data section (outside chunks) into its block; other records
/// in the run are skipped.
pub(super) fn decode_loose_block(bytes: Vec<u8>) -> Result<Block, mcap::McapError> {
    let mut messages = Vec::new();
    locate_messages(&bytes, 0..bytes.len(), &mut messages)?;
    Ok(Block { bytes, messages })
}

/// Parses a chunk record's body and calls `each` with every message's header and data.
pub(super) fn for_each_chunk_message(
    body: &[u8],
    mut each: impl FnMut(&mcap::records::MessageHeader, &[u8]),
) -> Result<(), mcap::McapError> {
    for_each_chunk_record(body, |r| {
        if let Record::Message { header, data } = r {
            each(&header, &data);
        }
    })
}

fn for_each_chunk_record(
    body: &[u8],
    mut each: impl FnMut(Record<'_>),
) -> Result<(), mcap::McapError> {
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    let Record::Chunk { header, .. } = mcap::parse_record(op::CHUNK, body)? else {
        return Err(mcap::McapError::BadIndex);
    };
    if header.uncompressed_size > MAX_CHUNK_BYTES {
        return Err(mcap::McapError::ChunkTooLarge(header.uncompressed_size));
    }
    // The chunk is read as the one record of a file by the linear reader, whose record-length
    // limit then holds inside the chunk too: mcap 0.26's `ChunkReader` sets none, and a damaged
    // record length inside a chunk made it allocate exabytes (found by fuzz/mcap_stream). No
    // record in the chunk can be longer than the chunk.
    let limit = usize::try_from(header.uncompressed_size)
        .unwrap_or(usize::MAX)
        .max(body.len());
    // The record's opcode and length, then its body: fed as two pieces, so the chunk (read once
    // per frame on demand) is not copied.
    let mut opcode_len = [0u8; 9];
    opcode_len[0] = op::CHUNK;
    opcode_len[1..].copy_from_slice(&(body.len() as u64).to_le_bytes());
    let mut pieces = [&opcode_len[..], body];
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_validate_chunk_crcs(true)
            .with_record_length_limit(limit),
    );
    while let Some(event) = reader.next_event() {
        match event? {
            LinearReadEvent::ReadRequest(need) => {
                // The first piece with bytes left (none left: 0, which tells the reader EOF).
                let rest = pieces.iter_mut().find(|p| !p.is_empty());
                let n = rest.as_ref().map_or(0, |p| need.min(p.len()));
                if let Some(rest) = rest {
                    reader.insert(n).copy_from_slice(&rest[..n]);
                    *rest = &rest[n..];
                }
                reader.notify_read(n);
            }
            // Only the records the reader uses are parsed: mcap 0.26's parser panics on some
            // others when damaged (an attachment too short for its CRC), and they are skipped.
            LinearReadEvent::Record { data, opcode }
                if matches!(opcode, op::SCHEMA | op::CHANNEL | op::MESSAGE) =>
            {
                each(mcap::parse_record(opcode, data)?);
            }
            LinearReadEvent::Record { .. } => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An uncompressed chunk record's body holding `records`, without a CRC.
    fn chunk_body(records: &[u8]) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend(0u64.to_le_bytes()); // message start time
        b.extend(0u64.to_le_bytes()); // message end time
        b.extend((records.len() as u64).to_le_bytes()); // uncompressed size
        b.extend(0u32.to_le_bytes()); // uncompressed CRC: none
        b.extend(0u32.to_le_bytes()); // compression: "" (none)
        b.extend((records.len() as u64).to_le_bytes());
        b.extend(records);
        b
    }

    /// A record mcap's parser cannot take (an attachment too short for its CRC made it slice
    /// backwards and panic) inside a chunk is skipped: only schemas, channels and messages are
    /// parsed.
    #[test]
    fn records_the_reader_does_not_need_are_not_parsed() {
        let mut attachment = Vec::new();
        attachment.extend(1u64.to_le_bytes()); // log time
        attachment.extend(1u64.to_le_bytes()); // create time
        attachment.extend(0u32.to_le_bytes()); // name ""
        attachment.extend(0u32.to_le_bytes()); // media type ""
        attachment.extend(0u64.to_le_bytes()); // data length; no data, no CRC
        let mut records = vec![op::ATTACHMENT];
        records.extend((attachment.len() as u64).to_le_bytes());
        records.extend(&attachment);
        let mut message = vec![op::MESSAGE];
        message.extend(23u64.to_le_bytes());
        message.extend(7u16.to_le_bytes()); // channel
        message.extend(0u32.to_le_bytes()); // sequence
        message.extend(5u64.to_le_bytes()); // log time
        message.extend(5u64.to_le_bytes()); // publish time
        message.push(42); // data
        records.extend(&message);
        let block = decode_chunk_block(chunk_body(&records)).unwrap();
        assert_eq!(block.messages.len(), 1);
        let m = &block.messages[0];
        assert_eq!((m.channel, m.log_time, block.data(m)), (7, 5, &[42u8][..]));
    }
}
