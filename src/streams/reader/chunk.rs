//! A chunk record's body, read without copying: its schemas, channels and messages.

use mcap::records::{Record, op};

use super::mcap_file::{MAX_CHUNK_BYTES, Msg};

/// What the recovery scan needs from a chunk's records.
pub(super) enum ChunkItem {
    Schema(u16, String),
    Channel(mcap::records::Channel),
    Message(u16, u64),
}

/// Parses a chunk record's body and calls `each` for its schemas, channels and messages.
pub(super) fn decode_chunk(
    body: &[u8],
    mut each: impl FnMut(ChunkItem),
) -> Result<(), mcap::McapError> {
    for_each_chunk_record(body, |r| match r {
        Record::Schema { header, .. } => each(ChunkItem::Schema(header.id, header.name)),
        Record::Channel(c) => each(ChunkItem::Channel(c)),
        Record::Message { header, .. } => {
            each(ChunkItem::Message(header.channel_id, header.log_time));
        }
        _ => {}
    })
}

/// Parses a chunk record's body into its messages.
pub(super) fn decode_chunk_messages(
    body: &[u8],
    out: &mut Vec<Msg>,
) -> Result<(), mcap::McapError> {
    for_each_chunk_record(body, |r| {
        if let Record::Message { header, data } = r {
            out.push(Msg {
                channel: header.channel_id,
                log_time: header.log_time,
                data: data.into_owned(),
            });
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
            LinearReadEvent::Record { data, opcode } => each(mcap::parse_record(opcode, data)?),
        }
    }
    Ok(())
}
