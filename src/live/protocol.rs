//! The Foxglove WebSocket protocol, client side: one server message in, a typed message or a
//! typed error out (pure functions, no I/O), and the client's `subscribe` request.
//!
//! Text messages are JSON objects with an `op` field; binary messages start with an opcode byte.
//! Only what a viewer needs is typed (`serverInfo`, `status`, `advertise`, `unadvertise`, message
//! data, time); other operations are [`ServerMessage::Other`] and ignored by the client.

use std::fmt;

use base64::Engine as _;
use serde::Deserialize;
use serde::de::{DeserializeSeed, IgnoredAny, MapAccess, SeqAccess, Visitor};

/// Binary opcode of a message-data frame: subscription id (u32 LE), log time (u64 LE, ns), payload.
pub const OP_MESSAGE_DATA: u8 = 0x01;
/// Binary opcode of a server time frame: timestamp (u64 LE, ns).
pub const OP_TIME: u8 = 0x02;
/// Bytes before the payload of a message-data frame.
const MESSAGE_DATA_HEADER: usize = 1 + 4 + 8;

/// A channel the server advertised.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AdvertisedChannel {
    /// Server-chosen channel id.
    pub id: u32,
    /// Topic, e.g. `/camera/image`.
    pub topic: String,
    /// Message encoding: `protobuf`, `json`, …
    pub encoding: String,
    /// Schema name, e.g. `foxglove.RawImage`.
    pub schema_name: String,
    /// Schema encoding (`protobuf`, `jsonschema`, …); empty when the server gave none.
    pub schema_encoding: String,
    /// Schema bytes: decoded from base64 for binary schema encodings (protobuf), the text as it
    /// came otherwise.
    pub schema: Vec<u8>,
}

/// One message from the server.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ServerMessage<'a> {
    /// The first message: the server's name and capabilities.
    ServerInfo {
        /// The server's name (robots name themselves here).
        name: String,
    },
    /// A status message for people (level 0 info, 1 warning, 2 error).
    Status {
        /// Severity: 0 info, 1 warning, 2 error.
        level: u8,
        /// The text.
        message: String,
    },
    /// New channels: at most the cap [`parse_text`] was given, the rest only counted (an
    /// endless list costs no memory).
    Advertise {
        /// The channels kept, in the order they came.
        channels: Vec<AdvertisedChannel>,
        /// Channels in the message beyond the cap, not parsed into memory.
        beyond: usize,
    },
    /// Channels that are gone.
    Unadvertise(Vec<u32>),
    /// One message on a subscription.
    MessageData {
        /// The client's subscription id.
        subscription_id: u32,
        /// The message's log time, nanoseconds (the sender's clock).
        log_time_ns: u64,
        /// The message bytes, exactly as sent.
        payload: &'a [u8],
    },
    /// The server's clock, nanoseconds.
    Time(u64),
    /// An operation a viewer does not need (parameters, services, assets, …).
    Other(String),
}

/// Why one server message was not understood.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ProtocolError {
    /// A text message that is not JSON or not an object with a string `op`.
    #[error("text message is not a protocol message: {0}")]
    BadJson(String),
    /// A known text operation with missing or mistyped fields.
    #[error("'{op}' message is malformed: {detail}")]
    BadFields {
        /// The operation.
        op: String,
        /// What serde said.
        detail: String,
    },
    /// A binary message shorter than its opcode's header.
    #[error("binary message with opcode {opcode:#04x} is {len} bytes, shorter than its header")]
    Truncated {
        /// The opcode.
        opcode: u8,
        /// Bytes received.
        len: usize,
    },
    /// An empty binary message.
    #[error("empty binary message")]
    Empty,
    /// A schema that should be base64 and is not.
    #[error("channel {channel} ({topic}): schema is not valid base64")]
    BadSchema {
        /// The channel id.
        channel: u32,
        /// The topic.
        topic: String,
    },
}

#[derive(Deserialize)]
struct Op {
    op: String,
}

#[derive(Deserialize)]
struct ServerInfoJson {
    #[serde(default)]
    name: String,
}

#[derive(Deserialize)]
struct StatusJson {
    level: u8,
    message: String,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct ChannelJson {
    id: u32,
    topic: String,
    encoding: String,
    schema_name: String,
    #[serde(default)]
    schema: String,
    #[serde(default)]
    schema_encoding: Option<String>,
}

/// An `advertise` message's channels, at most `cap` of them parsed; the rest are skipped over
/// (counted in `beyond`), so a message listing a million channels allocates only `cap`.
#[derive(Default)]
struct CappedChannels {
    kept: Vec<ChannelJson>,
    beyond: usize,
}

/// Reads an `advertise` object (the `channels` field through [`ChannelsSeed`]; others skipped).
struct AdvertiseSeed(usize);

/// Reads a list of channels, keeping the first `.0`.
struct ChannelsSeed(usize);

impl<'de> DeserializeSeed<'de> for AdvertiseSeed {
    type Value = CappedChannels;

    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for AdvertiseSeed {
    type Value = CappedChannels;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("an advertise object")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut channels = None;
        while let Some(key) = map.next_key::<std::borrow::Cow<'de, str>>()? {
            if key == "channels" {
                channels = Some(map.next_value_seed(ChannelsSeed(self.0))?);
            } else {
                map.next_value::<IgnoredAny>()?;
            }
        }
        channels.ok_or_else(|| serde::de::Error::missing_field("channels"))
    }
}

impl<'de> DeserializeSeed<'de> for ChannelsSeed {
    type Value = CappedChannels;

    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for ChannelsSeed {
    type Value = CappedChannels;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a list of channels")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = CappedChannels::default();
        while out.kept.len() < self.0 {
            match seq.next_element::<ChannelJson>()? {
                Some(c) => out.kept.push(c),
                None => return Ok(out),
            }
        }
        while seq.next_element::<IgnoredAny>()?.is_some() {
            out.beyond += 1;
        }
        Ok(out)
    }
}

/// Parses an `advertise` message's channels, at most `cap`.
fn advertise_fields(text: &str, cap: usize) -> Result<CappedChannels, ProtocolError> {
    let bad = |e: serde_json::Error| ProtocolError::BadFields {
        op: "advertise".to_owned(),
        detail: e.to_string(),
    };
    let mut de = serde_json::Deserializer::from_str(text);
    let channels = AdvertiseSeed(cap).deserialize(&mut de).map_err(bad)?;
    de.end().map_err(bad)?;
    Ok(channels)
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct UnadvertiseJson {
    channel_ids: Vec<u32>,
}

fn fields<'de, T: Deserialize<'de>>(op: &str, text: &'de str) -> Result<T, ProtocolError> {
    serde_json::from_str(text).map_err(|e| ProtocolError::BadFields {
        op: op.to_owned(),
        detail: e.to_string(),
    })
}

/// Schema encodings whose schema travels as base64 in `advertise`.
fn is_binary_schema(schema_encoding: &str) -> bool {
    matches!(schema_encoding, "protobuf" | "flatbuffer")
}

/// Parses one text (JSON) message from the server; of an `advertise` message at most
/// `max_channels` channels are parsed (the rest are counted in its `beyond`).
///
/// # Errors
/// [`ProtocolError`] saying what is wrong with it.
pub fn parse_text(
    text: &str,
    max_channels: usize,
) -> Result<ServerMessage<'static>, ProtocolError> {
    let op: Op = serde_json::from_str(text).map_err(|e| ProtocolError::BadJson(e.to_string()))?;
    Ok(match op.op.as_str() {
        "serverInfo" => ServerMessage::ServerInfo {
            name: fields::<ServerInfoJson>(&op.op, text)?.name,
        },
        "status" => {
            let s: StatusJson = fields(&op.op, text)?;
            ServerMessage::Status {
                level: s.level,
                message: s.message,
            }
        }
        "advertise" => {
            let a = advertise_fields(text, max_channels)?;
            let mut channels = Vec::with_capacity(a.kept.len());
            for c in a.kept {
                let schema_encoding = c.schema_encoding.unwrap_or_default();
                let schema = if is_binary_schema(&schema_encoding) {
                    base64::engine::general_purpose::STANDARD
                        .decode(c.schema.as_bytes())
                        .map_err(|_| ProtocolError::BadSchema {
                            channel: c.id,
                            topic: c.topic.clone(),
                        })?
                } else {
                    c.schema.into_bytes()
                };
                channels.push(AdvertisedChannel {
                    id: c.id,
                    topic: c.topic,
                    encoding: c.encoding,
                    schema_name: c.schema_name,
                    schema_encoding,
                    schema,
                });
            }
            ServerMessage::Advertise {
                channels,
                beyond: a.beyond,
            }
        }
        "unadvertise" => {
            ServerMessage::Unadvertise(fields::<UnadvertiseJson>(&op.op, text)?.channel_ids)
        }
        _ => ServerMessage::Other(op.op),
    })
}

fn u32_le(bytes: &[u8], at: usize) -> Option<u32> {
    let b: [u8; 4] = bytes.get(at..at + 4)?.try_into().ok()?;
    Some(u32::from_le_bytes(b))
}

fn u64_le(bytes: &[u8], at: usize) -> Option<u64> {
    let b: [u8; 8] = bytes.get(at..at + 8)?.try_into().ok()?;
    Some(u64::from_le_bytes(b))
}

/// Parses one binary message from the server; the payload borrows from `bytes`.
///
/// # Errors
/// [`ProtocolError::Empty`] or [`ProtocolError::Truncated`] for messages shorter than their header.
pub fn parse_binary(bytes: &[u8]) -> Result<ServerMessage<'_>, ProtocolError> {
    let &opcode = bytes.first().ok_or(ProtocolError::Empty)?;
    let truncated = ProtocolError::Truncated {
        opcode,
        len: bytes.len(),
    };
    match opcode {
        OP_MESSAGE_DATA => {
            let (Some(subscription_id), Some(log_time_ns), Some(payload)) = (
                u32_le(bytes, 1),
                u64_le(bytes, 5),
                bytes.get(MESSAGE_DATA_HEADER..),
            ) else {
                return Err(truncated);
            };
            Ok(ServerMessage::MessageData {
                subscription_id,
                log_time_ns,
                payload,
            })
        }
        OP_TIME => u64_le(bytes, 1).map(ServerMessage::Time).ok_or(truncated),
        other => Ok(ServerMessage::Other(format!("binary opcode {other:#04x}"))),
    }
}

/// The client's `subscribe` request: one subscription per (subscription id, channel id).
#[must_use]
pub fn subscribe_request(subscriptions: &[(u32, u32)]) -> String {
    let subs: Vec<serde_json::Value> = subscriptions
        .iter()
        .map(|&(id, channel)| serde_json::json!({ "id": id, "channelId": channel }))
        .collect();
    serde_json::json!({ "op": "subscribe", "subscriptions": subs }).to_string()
}

/// Encodes a message-data frame as a server sends it (for tests and fuzzing seeds).
#[must_use]
pub fn encode_message_data(subscription_id: u32, log_time_ns: u64, payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(MESSAGE_DATA_HEADER + payload.len());
    out.push(OP_MESSAGE_DATA);
    out.extend_from_slice(&subscription_id.to_le_bytes());
    out.extend_from_slice(&log_time_ns.to_le_bytes());
    out.extend_from_slice(payload);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_data_round_trips_with_the_payload_untouched() {
        let bytes = encode_message_data(7, 1_234_567_890_123, b"\x00\xffpayload");
        assert_eq!(
            parse_binary(&bytes),
            Ok(ServerMessage::MessageData {
                subscription_id: 7,
                log_time_ns: 1_234_567_890_123,
                payload: b"\x00\xffpayload",
            })
        );
    }

    #[test]
    fn a_message_data_frame_cut_inside_its_header_is_truncated() {
        let bytes = encode_message_data(1, 2, b"");
        for len in 1..bytes.len() {
            assert_eq!(
                parse_binary(&bytes[..len]),
                Err(ProtocolError::Truncated {
                    opcode: OP_MESSAGE_DATA,
                    len
                })
            );
        }
        assert_eq!(parse_binary(&[]), Err(ProtocolError::Empty));
    }

    #[test]
    fn advertise_decodes_protobuf_schemas_from_base64_and_keeps_json_schemas_as_text() {
        let text = r#"{"op":"advertise","channels":[
            {"id":1,"topic":"/camera/image","encoding":"protobuf","schemaName":"foxglove.RawImage","schema":"AAEC","schemaEncoding":"protobuf"},
            {"id":2,"topic":"/sensors","encoding":"json","schemaName":"eotn.SensorReadings","schema":"{\"type\":\"object\"}","schemaEncoding":"jsonschema"}]}"#;
        let Ok(ServerMessage::Advertise {
            channels,
            beyond: 0,
        }) = parse_text(text, 8)
        else {
            panic!("not parsed as advertise: {:?}", parse_text(text, 8));
        };
        assert_eq!(channels[0].schema, vec![0, 1, 2]);
        assert_eq!(channels[1].schema, br#"{"type":"object"}"#.to_vec());
        assert_eq!(channels[1].topic, "/sensors");
    }

    #[test]
    fn an_advertise_past_the_cap_keeps_the_first_channels_and_counts_the_rest() {
        let channels: Vec<String> = (0..10)
            .map(|i| {
                format!(
                    r#"{{"id":{i},"topic":"/t{i}","encoding":"json","schemaName":"s","schema":"{{}}"}}"#
                )
            })
            .collect();
        let text = format!(
            r#"{{"op":"advertise","extra":[1,2],"channels":[{}]}}"#,
            channels.join(",")
        );
        let Ok(ServerMessage::Advertise { channels, beyond }) = parse_text(&text, 3) else {
            panic!("{:?}", parse_text(&text, 3));
        };
        assert_eq!(channels.len(), 3);
        assert_eq!(channels[2].topic, "/t2");
        assert_eq!(beyond, 7);
        // A malformed channel within the cap makes the message malformed; past it, only its
        // JSON syntax is read.
        let bad = text.replace(r#""id":1,"#, r#""id":"one","#);
        assert!(parse_text(&bad, 3).is_err());
        let past = text.replace(r#""id":9,"#, r#""id":"nine","#);
        assert!(parse_text(&past, 3).is_ok());
        assert!(matches!(
            parse_text(r#"{"op":"advertise"}"#, 3),
            Err(ProtocolError::BadFields { .. })
        ));
    }

    #[test]
    fn garbage_text_and_mistyped_fields_are_errors_and_unknown_ops_are_other() {
        assert!(matches!(
            parse_text("not json", 8),
            Err(ProtocolError::BadJson(_))
        ));
        assert!(matches!(
            parse_text(r#"{"op":"advertise","channels":5}"#, 8),
            Err(ProtocolError::BadFields { .. })
        ));
        assert_eq!(
            parse_text(r#"{"op":"parameterValues","parameters":[]}"#, 8),
            Ok(ServerMessage::Other("parameterValues".to_owned()))
        );
        assert_eq!(
            parse_text(
                r#"{"op":"serverInfo","name":"robot3","capabilities":[]}"#,
                8
            ),
            Ok(ServerMessage::ServerInfo {
                name: "robot3".to_owned()
            })
        );
    }

    #[test]
    fn subscribe_names_each_channel_once() {
        let v: serde_json::Value =
            serde_json::from_str(&subscribe_request(&[(1, 10), (2, 11)])).unwrap_or_default();
        assert_eq!(v["op"], "subscribe");
        assert_eq!(v["subscriptions"][1]["channelId"], 11);
    }
}
