//! A chunk record's body, read without copying: its schemas, channels and messages; and a run
//! of message records outside chunks.

use mcap::records::{Record, op};

use super::mcap_file::{MAX_CHUNK_BYTES, Msg};

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

/// Parses a run of whole records from the data section (outside chunks) into its messages;
/// other records in the run are skipped.
pub(super) fn decode_loose_messages(
    mut bytes: &[u8],
    out: &mut Vec<Msg>,
) -> Result<(), mcap::McapError> {
    while !bytes.is_empty() {
        let (opcode, len) = match bytes.get(..9) {
            Some(h) => (
                h[0],
                u64::from_le_bytes(h[1..9].try_into().unwrap_or([0xff; 8])),
            ),
            None => return Err(mcap::McapError::UnexpectedEof),
        };
        let body = usize::try_from(len)
            .ok()
            .and_then(|n| bytes.get(9..9usize.checked_add(n)?))
            .ok_or(mcap::McapError::UnexpectedEof)?;
        if opcode == op::MESSAGE
            && let Record::Message { header, data } = mcap::parse_record(opcode, body)?
        {
            out.push(Msg {
                channel: header.channel_id,
                log_time: header.log_time,
                data: data.into_owned(),
            });
        }
        bytes = &bytes[9 + body.len()..];
    }
    Ok(())
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
        let mut out = Vec::new();
        decode_chunk_messages(&chunk_body(&records), &mut out).unwrap();
        assert_eq!(out.len(), 1);
        assert_eq!((out[0].channel, out[0].data.as_slice()), (7, &[42u8][..]));
    }
}
