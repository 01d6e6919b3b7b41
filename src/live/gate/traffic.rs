//! [`Traffic`]: what `eotn serve`'s gate reads of the messages it relays between a viewer and the
//! `foxglove` server, to tell a frame's image from other message data when a slow viewer's
//! [`super::outbox::Outbox`] drops some (pure: message text in, nothing out but its [`Kind`]).
//!
//! It follows the server's `advertise`/`unadvertise` (channel id → image channel or not) and
//! the viewer's `subscribe`/`unsubscribe` (subscription id → channel id), each map at most
//! [`MAX_TRACKED`] entries. Anything it does not understand is still relayed, untouched (the
//! server answers it); it only counts as data that is not an image. From the subscriptions it
//! follows it writes the requests that pause a viewer that does not read, and resume it.

use std::collections::{HashMap, HashSet};

use serde::Deserialize;

use super::outbox::Kind;
use crate::live::protocol::{OP_MESSAGE_DATA, subscribe_request};
use crate::streams::IMAGE_TOPIC;

/// Channels and subscriptions followed, each at most (more are relayed, not followed).
pub const MAX_TRACKED: usize = 4096;

/// What a viewer's text message was, as far as its subscriptions go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewerOp {
    /// `subscribe`.
    Subscribe,
    /// `unsubscribe`.
    Unsubscribe,
    /// Anything else (or nothing understood).
    Other,
}

/// The channels and subscriptions of one viewer's connection.
#[derive(Debug, Default)]
pub struct Traffic {
    image_channels: HashSet<u32>,
    /// Subscription id → channel id.
    subscriptions: HashMap<u32, u32>,
}

#[derive(Deserialize)]
struct Op<'a> {
    #[serde(borrow)]
    op: std::borrow::Cow<'a, str>,
}

#[derive(Deserialize)]
struct Subscribe {
    #[serde(default)]
    subscriptions: Vec<SubscriptionJson>,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct SubscriptionJson {
    id: u32,
    channel_id: u32,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Unsubscribe {
    #[serde(default)]
    subscription_ids: Vec<u32>,
}

#[derive(Deserialize)]
struct Advertise {
    #[serde(default)]
    channels: Vec<ChannelJson>,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct ChannelJson {
    id: u32,
    #[serde(default)]
    topic: String,
    #[serde(default)]
    schema_name: String,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Unadvertise {
    #[serde(default)]
    channel_ids: Vec<u32>,
}

impl Traffic {
    /// Nothing followed yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Subscriptions followed now.
    #[must_use]
    pub fn subscriptions(&self) -> usize {
        self.subscriptions.len()
    }

    /// Takes note of a viewer's text message (`subscribe`, `unsubscribe`; others ignored).
    pub fn from_viewer(&mut self, text: &str) -> ViewerOp {
        let Ok(op) = serde_json::from_str::<Op<'_>>(text) else {
            return ViewerOp::Other;
        };
        match op.op.as_ref() {
            "subscribe" => {
                if let Ok(s) = serde_json::from_str::<Subscribe>(text) {
                    for sub in s.subscriptions {
                        if self.subscriptions.len() < MAX_TRACKED
                            || self.subscriptions.contains_key(&sub.id)
                        {
                            self.subscriptions.insert(sub.id, sub.channel_id);
                        }
                    }
                }
                ViewerOp::Subscribe
            }
            "unsubscribe" => {
                if let Ok(u) = serde_json::from_str::<Unsubscribe>(text) {
                    for id in u.subscription_ids {
                        self.subscriptions.remove(&id);
                    }
                }
                ViewerOp::Unsubscribe
            }
            _ => ViewerOp::Other,
        }
    }

    /// True when the viewer is subscribed to a camera image channel.
    #[must_use]
    pub fn has_image_subscription(&self) -> bool {
        self.subscriptions
            .values()
            .any(|c| self.image_channels.contains(c))
    }

    /// The server message that ends every subscription followed (to pause a viewer that does
    /// not read); `None` when there is none.
    #[must_use]
    pub fn pause_request(&self) -> Option<String> {
        let mut ids: Vec<u32> = self.subscriptions.keys().copied().collect();
        ids.sort_unstable();
        (!ids.is_empty())
            .then(|| serde_json::json!({"op": "unsubscribe", "subscriptionIds": ids}).to_string())
    }

    /// The server message that makes every subscription followed again (to resume it).
    #[must_use]
    pub fn resume_request(&self) -> Option<String> {
        let mut subs: Vec<(u32, u32)> = self.subscriptions.iter().map(|(&s, &c)| (s, c)).collect();
        subs.sort_unstable();
        (!subs.is_empty()).then(|| subscribe_request(&subs))
    }

    /// Takes note of the server's text message (`advertise`, `unadvertise`; others ignored).
    pub fn from_server(&mut self, text: &str) {
        let Ok(op) = serde_json::from_str::<Op<'_>>(text) else {
            return;
        };
        match op.op.as_ref() {
            "advertise" => {
                if let Ok(a) = serde_json::from_str::<Advertise>(text) {
                    for c in a.channels {
                        let image = c.topic == IMAGE_TOPIC || c.schema_name == "foxglove.RawImage";
                        if !image {
                            self.image_channels.remove(&c.id);
                        } else if self.image_channels.len() < MAX_TRACKED {
                            self.image_channels.insert(c.id);
                        }
                    }
                }
            }
            "unadvertise" => {
                if let Ok(u) = serde_json::from_str::<Unadvertise>(text) {
                    for id in u.channel_ids {
                        self.image_channels.remove(&id);
                    }
                }
            }
            _ => {}
        }
    }

    /// What a binary message from the server is: message data (an image or not, by its
    /// subscription) or control.
    #[must_use]
    pub fn kind_of_binary(&self, bytes: &[u8]) -> Kind {
        let (Some(&OP_MESSAGE_DATA), Some(sub)) = (bytes.first(), bytes.get(1..5)) else {
            return Kind::Control;
        };
        let sub = u32::from_le_bytes([sub[0], sub[1], sub[2], sub[3]]);
        let image = self
            .subscriptions
            .get(&sub)
            .is_some_and(|channel| self.image_channels.contains(channel));
        Kind::Data { image }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::live::protocol::encode_message_data;

    #[test]
    fn message_data_on_a_subscription_to_the_image_channel_is_a_frame() {
        let mut t = Traffic::new();
        t.from_server(
            r#"{"op":"advertise","channels":[{"id":1,"topic":"/camera/image","encoding":"protobuf","schemaName":"foxglove.RawImage"},{"id":2,"topic":"/sensors","encoding":"json","schemaName":"s"}]}"#,
        );
        t.from_viewer(
            r#"{"op":"subscribe","subscriptions":[{"id":7,"channelId":1},{"id":8,"channelId":2}]}"#,
        );
        assert_eq!(
            t.kind_of_binary(&encode_message_data(7, 0, b"x")),
            Kind::Data { image: true }
        );
        assert_eq!(
            t.kind_of_binary(&encode_message_data(8, 0, b"x")),
            Kind::Data { image: false }
        );
        assert_eq!(t.kind_of_binary(&[0x02, 0, 0]), Kind::Control);
        assert_eq!(t.kind_of_binary(&[0x01, 7]), Kind::Control);
        t.from_viewer(r#"{"op":"unsubscribe","subscriptionIds":[7]}"#);
        assert!(!t.has_image_subscription());
        assert_eq!(
            t.kind_of_binary(&encode_message_data(7, 0, b"x")),
            Kind::Data { image: false }
        );
        t.from_server(r#"{"op":"unadvertise","channelIds":[1]}"#);
        assert_eq!(t.subscriptions(), 1);
    }

    #[test]
    fn garbage_and_endless_subscriptions_are_ignored_or_capped() {
        let mut t = Traffic::new();
        for text in [
            "",
            "{",
            "[]",
            r#"{"op":5}"#,
            r#"{"op":"subscribe","subscriptions":7}"#,
        ] {
            t.from_viewer(text);
            t.from_server(text);
        }
        let subs: Vec<String> = (0..MAX_TRACKED as u32 + 100)
            .map(|i| format!(r#"{{"id":{i},"channelId":1}}"#))
            .collect();
        t.from_viewer(&format!(
            r#"{{"op":"subscribe","subscriptions":[{}]}}"#,
            subs.join(",")
        ));
        assert_eq!(t.subscriptions(), MAX_TRACKED);
    }
}
