//! Every message of a stream in file order, whatever its channel: for tools that read channels
//! other than the frames (and for checking the reader against other MCAP implementations).

use mcap::records::{MessageHeader, Record, op};

use super::super::StreamError;
use super::chunk::for_each_chunk_message;
use super::mcap_file::{MAX_CHUNK_BYTES, McapFile};
use super::recovery::WalkEnd;

/// One message as stored: its channel, sequence number, times and undecoded data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamMessage<'a> {
    /// Id of its channel ([`super::ChannelSummary::id`]).
    pub channel: u16,
    /// The writer's sequence number.
    pub sequence: u32,
    /// When it was recorded, nanoseconds.
    pub log_time_ns: u64,
    /// When it was published, nanoseconds.
    pub publish_time_ns: u64,
    /// Its data, in the channel's message encoding.
    pub data: &'a [u8],
}

impl<'a> StreamMessage<'a> {
    fn new(header: &MessageHeader, data: &'a [u8]) -> Self {
        Self {
            channel: header.channel_id,
            sequence: header.sequence,
            log_time_ns: header.log_time,
            publish_time_ns: header.publish_time,
            data,
        }
    }
}

impl McapFile {
    /// Calls `each` with every message of the file in the order it is stored, inside chunks
    /// and outside them. Memory is one chunk at a time.
    ///
    /// # Errors
    /// I/O errors, and [`StreamError::Corrupt`] at the first damaged or cut-off record (the
    /// messages before it have been given to `each`).
    pub fn for_each_message(
        &mut self,
        mut each: impl FnMut(&StreamMessage<'_>),
    ) -> Result<(), StreamError> {
        let mut damage: Option<String> = None;
        let end = self.walk(|r, opcode, offset, len| {
            if opcode != op::MESSAGE && opcode != op::CHUNK {
                return Ok(true);
            }
            if len > MAX_CHUNK_BYTES {
                damage = Some(format!(
                    "record at offset {offset} is implausibly large ({len} bytes)"
                ));
                return Ok(false);
            }
            let body = r.read_exact_at(offset + 9, len)?;
            let read = if opcode == op::CHUNK {
                for_each_chunk_message(&body, |h, data| each(&StreamMessage::new(h, data)))
            } else {
                mcap::parse_record(opcode, &body).map(|record| {
                    if let Record::Message { header, data } = record {
                        each(&StreamMessage::new(&header, &data));
                    }
                })
            };
            match read {
                Ok(()) => Ok(true),
                Err(e) => {
                    damage = Some(format!("record at offset {offset} is damaged ({e})"));
                    Ok(false)
                }
            }
        })?;
        match (end, damage) {
            (WalkEnd::Complete, _) => Ok(()),
            (_, Some(detail)) | (WalkEnd::CutOff(detail), None) => Err(self.corrupt(detail)),
            (WalkEnd::FileEnds | WalkEnd::Stopped, None) => {
                Err(self.corrupt("the file ends without its Data End record".to_owned()))
            }
        }
    }
}
