//! [`Channels`]: the channels one connection to a robot has seen advertised and the
//! subscriptions made to them, within the client's [`Limits`] (pure: messages in, what to
//! subscribe and what to say out; no I/O).
//!
//! A robot may advertise anything: a channel past [`Limits::max_channels`], with a name longer
//! than [`Limits::max_name_bytes`] or a schema larger than [`Limits::max_schema_bytes`] is not
//! subscribed, with one warning per kind and connection, and the rest go on. A channel advertised
//! again under its id with another encoding or schema replaces the old one: its messages from
//! then on carry the new description (a recording writes them as a new channel).

use std::collections::HashMap;
use std::sync::Arc;

use super::client::Limits;
use super::protocol::AdvertisedChannel;

/// What one `advertise` message asks of the client.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct AdvertiseOutcome {
    /// Subscriptions to request: (subscription id, channel id).
    pub subscribe: Vec<(u32, u32)>,
    /// Channels new or changed, as messages on them will name them.
    pub channels: Vec<Arc<AdvertisedChannel>>,
    /// One line per limit first hit on this connection, and per channel re-advertised.
    pub warnings: Vec<String>,
}

/// Channels not subscribed on this connection, by why (each kind warned about once).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Refused {
    /// Past [`Limits::max_channels`].
    pub too_many: usize,
    /// A topic, encoding or schema name longer than [`Limits::max_name_bytes`].
    pub long_names: usize,
    /// A schema larger than [`Limits::max_schema_bytes`].
    pub big_schemas: usize,
}

/// The channels of one connection (a reconnection starts afresh: ids are the server's).
#[derive(Debug)]
pub struct Channels {
    limits: Limits,
    channels: HashMap<u32, Arc<AdvertisedChannel>>,
    /// Subscription id → channel, and channel id → subscription id.
    subscriptions: HashMap<u32, Arc<AdvertisedChannel>>,
    subscription_of: HashMap<u32, u32>,
    next_subscription: u32,
    refused: Refused,
}

/// `text` cut to at most `max` bytes (on a character boundary), with `…` when cut.
#[must_use]
pub fn cut(text: &str, max: usize) -> String {
    if text.len() <= max {
        return text.to_owned();
    }
    let mut end = max;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}…", &text[..end])
}

impl Channels {
    /// No channels yet.
    #[must_use]
    pub fn new(limits: Limits) -> Self {
        Self {
            limits,
            channels: HashMap::new(),
            subscriptions: HashMap::new(),
            subscription_of: HashMap::new(),
            next_subscription: 1,
            refused: Refused::default(),
        }
    }

    /// Channels known (subscribed) now.
    #[must_use]
    pub fn len(&self) -> usize {
        self.channels.len()
    }

    /// True before any channel.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.channels.is_empty()
    }

    /// Channels refused on this connection so far.
    #[must_use]
    pub const fn refused(&self) -> Refused {
        self.refused
    }

    /// The channel a message on `subscription` belongs to.
    #[must_use]
    pub fn subscription(&self, subscription: u32) -> Option<&Arc<AdvertisedChannel>> {
        self.subscriptions.get(&subscription)
    }

    /// Takes in one `advertise` message: `list` as parsed, `beyond` channels the parser only
    /// counted (past the cap it was given).
    pub fn advertise(&mut self, list: Vec<AdvertisedChannel>, beyond: usize) -> AdvertiseOutcome {
        let mut out = AdvertiseOutcome::default();
        for c in list {
            if let Some(why) = self.refusal(&c) {
                out.warnings.extend(why);
                continue;
            }
            let c = Arc::new(c);
            match self.channels.get(&c.id) {
                Some(old) if **old == *c => {}
                Some(old) => {
                    out.warnings.push(format!(
                        "channel {} advertised again as {} {} (was {} {}): recorded as a new channel",
                        cut(&c.topic, 80),
                        c.encoding,
                        c.schema_name,
                        old.encoding,
                        old.schema_name
                    ));
                    if let Some(sub) = self.subscription_of.get(&c.id) {
                        self.subscriptions.insert(*sub, Arc::clone(&c));
                    }
                    self.channels.insert(c.id, Arc::clone(&c));
                    out.channels.push(c);
                }
                None if self.channels.len() >= self.limits.max_channels => {
                    out.warnings.extend(self.too_many(1));
                }
                None => {
                    let sub = self.next_subscription;
                    self.next_subscription = self.next_subscription.wrapping_add(1);
                    out.subscribe.push((sub, c.id));
                    self.subscriptions.insert(sub, Arc::clone(&c));
                    self.subscription_of.insert(c.id, sub);
                    self.channels.insert(c.id, Arc::clone(&c));
                    out.channels.push(c);
                }
            }
        }
        if beyond > 0 {
            out.warnings.extend(self.too_many(beyond));
        }
        out
    }

    /// Forgets withdrawn channels and their subscriptions.
    pub fn unadvertise(&mut self, ids: &[u32]) {
        for id in ids {
            self.channels.remove(id);
            if let Some(sub) = self.subscription_of.remove(id) {
                self.subscriptions.remove(&sub);
            }
        }
    }

    /// Counts `n` channels past the limit; a warning the first time.
    fn too_many(&mut self, n: usize) -> Option<String> {
        let first = self.refused.too_many == 0;
        self.refused.too_many += n;
        first.then(|| {
            format!(
                "more than {} channels advertised: later channels are not subscribed",
                self.limits.max_channels
            )
        })
    }

    /// Why `c` is refused (a warning the first time for its kind), or `None` when it is fine.
    fn refusal(&mut self, c: &AdvertisedChannel) -> Option<Option<String>> {
        let max = self.limits.max_name_bytes;
        let longest = [&c.topic, &c.encoding, &c.schema_name, &c.schema_encoding]
            .into_iter()
            .map(String::len)
            .max()
            .unwrap_or(0);
        if longest > max {
            let first = self.refused.long_names == 0;
            self.refused.long_names += 1;
            return Some(first.then(|| {
                format!(
                    "channel {} dropped: a name of {longest} bytes (at most {max}); others like it are dropped too",
                    cut(&c.topic, 60)
                )
            }));
        }
        let max = self.limits.max_schema_bytes;
        if c.schema.len() > max {
            let first = self.refused.big_schemas == 0;
            self.refused.big_schemas += 1;
            return Some(first.then(|| {
                format!(
                    "channel {} dropped: its schema is {} bytes (at most {max}); others like it are dropped too",
                    cut(&c.topic, 60),
                    c.schema.len()
                )
            }));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(id: u32, topic: &str, encoding: &str) -> AdvertisedChannel {
        AdvertisedChannel {
            id,
            topic: topic.to_owned(),
            encoding: encoding.to_owned(),
            schema_name: "s".to_owned(),
            schema_encoding: "jsonschema".to_owned(),
            schema: b"{}".to_vec(),
        }
    }

    fn limits() -> Limits {
        Limits {
            max_channels: 3,
            max_name_bytes: 20,
            max_schema_bytes: 100,
            ..Limits::default()
        }
    }

    #[test]
    fn channels_past_the_limit_are_counted_and_warned_about_once() {
        let mut ch = Channels::new(limits());
        let first = ch.advertise((0..5).map(|i| channel(i, "/t", "json")).collect(), 10);
        assert_eq!(first.subscribe, vec![(1, 0), (2, 1), (3, 2)]);
        assert_eq!(first.warnings.len(), 1, "{:?}", first.warnings);
        assert!(first.warnings[0].contains("more than 3 channels"));
        let again = ch.advertise(vec![channel(9, "/t", "json")], 0);
        assert!(again.subscribe.is_empty() && again.warnings.is_empty());
        assert_eq!(ch.refused().too_many, 2 + 10 + 1);
        // A withdrawn channel makes room for another.
        ch.unadvertise(&[0]);
        let room = ch.advertise(vec![channel(9, "/t", "json")], 0);
        assert_eq!(room.subscribe, vec![(4, 9)]);
        assert_eq!(ch.len(), 3);
        assert!(ch.subscription(1).is_none());
        assert_eq!(ch.subscription(4).map(|c| c.id), Some(9));
    }

    #[test]
    fn long_names_and_big_schemas_drop_only_their_channel() {
        let mut ch = Channels::new(limits());
        let mut big = channel(2, "/big", "json");
        big.schema = vec![b' '; 101];
        let out = ch.advertise(
            vec![
                channel(0, &"x".repeat(300), "json"),
                channel(1, "/ok", "json"),
                big,
                channel(3, "/y", &"e".repeat(21)),
            ],
            0,
        );
        assert_eq!(out.subscribe, vec![(1, 1)]);
        assert_eq!(out.warnings.len(), 2, "{:?}", out.warnings);
        assert!(out.warnings[0].contains("300 bytes") && out.warnings[0].len() < 200);
        assert!(out.warnings[1].contains("101 bytes"));
        assert_eq!(
            ch.refused(),
            Refused {
                too_many: 0,
                long_names: 2,
                big_schemas: 1
            }
        );
    }

    #[test]
    fn a_channel_advertised_again_with_another_encoding_replaces_the_old_under_its_subscription() {
        let mut ch = Channels::new(limits());
        ch.advertise(vec![channel(7, "/odometry", "json")], 0);
        let same = ch.advertise(vec![channel(7, "/odometry", "json")], 0);
        assert_eq!(same, AdvertiseOutcome::default());
        let changed = ch.advertise(vec![channel(7, "/odometry", "cdr")], 0);
        assert!(changed.subscribe.is_empty(), "the subscription stands");
        assert_eq!(changed.channels.len(), 1);
        assert!(changed.warnings[0].contains("advertised again as cdr"));
        assert_eq!(ch.subscription(1).map(|c| c.encoding.as_str()), Some("cdr"));
    }

    #[test]
    fn cut_keeps_whole_characters() {
        assert_eq!(cut("abc", 5), "abc");
        assert_eq!(cut("ééé", 3), "é…");
        assert_eq!(cut("abcdef", 3), "abc…");
    }
}
