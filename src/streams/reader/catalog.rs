//! What an MCAP file holds, whatever it carries: its channels (topic, encodings, schema, message
//! count) and how many records of each kind — gathered from the summary when it is complete,
//! else from the data section.

use std::collections::{BTreeMap, HashMap};

/// The schema of a channel: its name (`foxglove.RawImage`, `sensor_msgs/msg/Image`) and the
/// encoding of the schema text (`protobuf`, `ros2msg`, `jsonschema`, …).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SchemaSummary {
    /// Schema name.
    pub name: String,
    /// Encoding of the schema data.
    pub encoding: String,
}

/// One channel of a stream: what its messages are and how many there are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelSummary {
    /// The channel's id in the file.
    pub id: u16,
    /// Topic, e.g. `/camera/image`.
    pub topic: String,
    /// Encoding of its messages (`protobuf`, `json`, `cdr`, `ros1`, …).
    pub message_encoding: String,
    /// Its schema; `None` for a channel without one (schema id 0).
    pub schema: Option<SchemaSummary>,
    /// Messages on the channel in the file.
    pub message_count: u64,
}

/// Adds a further storage file's channels to a split bag's list: a channel with the topic,
/// message encoding and schema of one listed adds its messages to it; any other is appended,
/// keeping its id unless the list has that id already (then it gets the next free one). Returns
/// the file's channel ids → the list's.
pub(super) fn merge_channels(
    into: &mut Vec<ChannelSummary>,
    more: &[ChannelSummary],
) -> HashMap<u16, u16> {
    let mut ids = HashMap::new();
    for c in more {
        let same = into.iter_mut().find(|k| {
            k.topic == c.topic && k.message_encoding == c.message_encoding && k.schema == c.schema
        });
        if let Some(k) = same {
            k.message_count = k.message_count.saturating_add(c.message_count);
            ids.insert(c.id, k.id);
            continue;
        }
        let taken = |id: u16| into.iter().any(|k| k.id == id);
        let id = if taken(c.id) {
            (0..=u16::MAX).find(|&id| !taken(id)).unwrap_or(c.id)
        } else {
            c.id
        };
        ids.insert(c.id, id);
        into.push(ChannelSummary { id, ..c.clone() });
    }
    ids
}

/// How many records of each kind the file holds (the MCAP statistics, checked or counted).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RecordCounts {
    /// Messages on all channels.
    pub messages: u64,
    /// Distinct schemas.
    pub schemas: u64,
    /// Distinct channels.
    pub channels: u64,
    /// Chunk records.
    pub chunks: u64,
    /// Attachment records.
    pub attachments: u64,
    /// Metadata records.
    pub metadata: u64,
}

impl RecordCounts {
    /// Adds another file's counts (the files of a split bag).
    pub(super) fn add(&mut self, other: Self) {
        self.messages += other.messages;
        self.schemas += other.schemas;
        self.channels += other.channels;
        self.chunks += other.chunks;
        self.attachments += other.attachments;
        self.metadata += other.metadata;
    }
}

/// The schemas and channels seen so far, with message counts: a summary's, or a data section's
/// as it is walked.
#[derive(Debug, Default)]
pub(super) struct Catalog {
    schemas: HashMap<u16, SchemaSummary>,
    channels: BTreeMap<u16, ChannelSummary>,
    /// Messages whose channel was never defined (invalid MCAP), counted apart.
    pub(super) orphan_messages: u64,
    pub(super) counts: RecordCounts,
}

impl Catalog {
    /// Adds a schema; the first definition of an id wins (repeats are the same record).
    /// Schema id 0 is invalid and ignored, as the specification says.
    pub(super) fn add_schema(&mut self, id: u16, name: &str, encoding: &str) {
        if id == 0 || self.schemas.contains_key(&id) {
            return;
        }
        self.schemas.insert(
            id,
            SchemaSummary {
                name: name.to_owned(),
                encoding: encoding.to_owned(),
            },
        );
        self.counts.schemas += 1;
    }

    /// True when the schema id is 0 (none) or its schema is known.
    pub(super) fn has_schema(&self, id: u16) -> bool {
        id == 0 || self.schemas.contains_key(&id)
    }

    /// The name of schema `id`, when known.
    pub(super) fn schema_name(&self, id: u16) -> Option<&str> {
        self.schemas.get(&id).map(|s| s.name.as_str())
    }

    /// Adds a channel; `true` when it is new (repeats of a channel are the same record).
    pub(super) fn add_channel(&mut self, c: &mcap::records::Channel) -> bool {
        if self.channels.contains_key(&c.id) {
            return false;
        }
        self.channels.insert(
            c.id,
            ChannelSummary {
                id: c.id,
                topic: c.topic.clone(),
                message_encoding: c.message_encoding.clone(),
                schema: self.schemas.get(&c.schema_id).cloned(),
                message_count: 0,
            },
        );
        self.counts.channels += 1;
        true
    }

    /// Counts one message on `channel`.
    pub(super) fn count_message(&mut self, channel: u16) {
        self.counts.messages += 1;
        match self.channels.get_mut(&channel) {
            Some(c) => c.message_count += 1,
            None => self.orphan_messages += 1,
        }
    }

    /// Sets the message count of every channel from the summary's statistics.
    pub(super) fn set_message_counts(&mut self, counts: &BTreeMap<u16, u64>) {
        for c in self.channels.values_mut() {
            c.message_count = counts.get(&c.id).copied().unwrap_or(0);
        }
        self.counts.messages = counts.values().fold(0u64, |a, &n| a.saturating_add(n));
    }

    /// The channels by id.
    pub(super) fn into_channels(self) -> (Vec<ChannelSummary>, RecordCounts) {
        (self.channels.into_values().collect(), self.counts)
    }
}
