//! A rosbag2 SQLite storage file (`.db3`): its `topics` table (id, name, type,
//! serialization_format, …) and `messages` table (id, topic_id, timestamp, data), read through
//! `rusqlite` with SQLite built in. Opened read-only and immutable (no journal or lock files are
//! made beside it); the tables are checked for the columns eotn reads, whatever else they have
//! (versions 1 to 9 add `offered_qos_profiles`, `type_description_hash`, `message_definitions`,
//! `metadata`, `schema`).

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use rusqlite::{Connection, OpenFlags, OptionalExtension as _};

use super::super::StreamError;
use super::super::reader::channels::{ChannelTable, ImageTopic, Role};
use super::super::reader::{ChannelSummary, RawFrame, RawMsg, SchemaSummary, StreamMessage};
use crate::formats::MessageKind;

/// Largest message read, bytes (a 4096×4096 RGBA frame is 64 MiB).
const MAX_MESSAGE_BYTES: i64 = 256 << 20;
/// Most topics a bag may have (channel ids are 16-bit).
const MAX_TOPICS: usize = 60_000;

/// One topic of the `topics` table.
#[derive(Debug, Clone)]
struct Topic {
    id: i64,
}

/// An open `.db3` file.
pub(crate) struct Db3File {
    path: PathBuf,
    conn: Connection,
    topics: Vec<Topic>,
    /// Every topic as a channel (id: its place in the `topics` table), with its message count.
    pub(crate) channels: Vec<ChannelSummary>,
    roles: HashMap<i64, Role>,
    image_topic: Option<i64>,
    pub(crate) image_kind: Option<MessageKind>,
    pub(crate) image_topics: Vec<ImageTopic>,
    /// The frames: message row id and timestamp (ns), in time order.
    frames: Vec<(i64, u64)>,
    pub(crate) warnings: Vec<String>,
}

impl std::fmt::Debug for Db3File {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Db3File")
            .field("path", &self.path)
            .field("frames", &self.frames.len())
            .finish_non_exhaustive()
    }
}

/// A path as an SQLite URI (`file:…?immutable=1`), every byte outside the unreserved set
/// percent-encoded.
fn immutable_uri(path: &Path) -> String {
    let mut uri = String::from("file:");
    for b in path.as_os_str().as_encoded_bytes() {
        if b.is_ascii_alphanumeric() || b"/-_.~".contains(b) {
            uri.push(char::from(*b));
        } else {
            uri.push_str(&format!("%{b:02X}"));
        }
    }
    uri.push_str("?immutable=1");
    uri
}

impl Db3File {
    /// Opens a `.db3`, reading frames from `wanted_topic` when given, else from its first image
    /// topic with messages.
    ///
    /// # Errors
    /// [`StreamError`] naming the file: not a regular file, not SQLite, not a rosbag2 database.
    pub(crate) fn open(path: &Path, wanted_topic: Option<String>) -> Result<Self, StreamError> {
        let meta = std::fs::metadata(path).map_err(|source| StreamError::Io {
            path: path.to_owned(),
            source,
        })?;
        if !meta.is_file() {
            return Err(StreamError::Io {
                path: path.to_owned(),
                source: std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "not a regular file, so it cannot be a rosbag2 database",
                ),
            });
        }
        let flags = OpenFlags::SQLITE_OPEN_READ_ONLY
            | OpenFlags::SQLITE_OPEN_URI
            | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        let sql = |e: rusqlite::Error| StreamError::Corrupt {
            path: path.to_owned(),
            detail: format!("not a rosbag2 SQLite database: {e}"),
        };
        let conn = Connection::open_with_flags(immutable_uri(path), flags).map_err(sql)?;
        // Read as every input is: no output of the running command may replace it.
        crate::atomic_file::guard_inputs([path]);
        let mut file = Self {
            path: path.to_owned(),
            conn,
            topics: Vec::new(),
            channels: Vec::new(),
            roles: HashMap::new(),
            image_topic: None,
            image_kind: None,
            image_topics: Vec::new(),
            frames: Vec::new(),
            warnings: Vec::new(),
        };
        file.read_topics(wanted_topic).map_err(sql)?;
        file.read_frames().map_err(sql)?;
        Ok(file)
    }

    fn read_topics(&mut self, wanted_topic: Option<String>) -> rusqlite::Result<()> {
        let mut stmt = self
            .conn
            .prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")?;
        let rows = stmt.query_map([], |r| {
            Ok((
                r.get::<_, i64>(0)?,
                r.get::<_, String>(1)?,
                r.get::<_, String>(2)?,
                r.get::<_, String>(3)?,
            ))
        })?;
        let mut listed = Vec::new();
        for row in rows {
            listed.push(row?);
            if listed.len() > MAX_TOPICS {
                break;
            }
        }
        drop(stmt);
        let mut counts = self
            .conn
            .prepare("SELECT EXISTS(SELECT 1 FROM messages WHERE topic_id = ?1)")?;
        let mut table = ChannelTable::wanting(wanted_topic);
        for (i, (id, name, type_name, format)) in listed.iter().enumerate() {
            let Ok(channel) = u16::try_from(i) else {
                break;
            };
            if !counts.query_row([id], |r| r.get::<_, bool>(0))? {
                table.empty.insert(channel);
            }
            table.add(channel, name, format, Some(type_name));
        }
        drop(counts);
        self.channels = self.channel_summaries(&listed)?;
        table.note_other_cameras();
        self.warnings.append(&mut table.notes);
        for (i, (id, ..)) in listed.into_iter().enumerate() {
            let Ok(channel) = u16::try_from(i) else {
                break;
            };
            if let Some(role) = table.roles.remove(&channel) {
                if let Role::Image(kind) = role {
                    self.image_kind = Some(kind);
                }
                if Some(channel) == table.image {
                    self.image_topic = Some(id);
                }
                self.roles.insert(id, role);
            }
            self.topics.push(Topic { id });
        }
        self.image_topics = table.image_topics;
        if self.image_topic.is_none() {
            self.warnings.push(
                "no camera image topic (sensor_msgs/msg/Image or CompressedImage): the bag holds no frames"
                    .to_owned(),
            );
        }
        Ok(())
    }

    fn read_frames(&mut self) -> rusqlite::Result<()> {
        let Some(topic) = self.image_topic else {
            return Ok(());
        };
        let mut stmt = self.conn.prepare(
            "SELECT id, timestamp FROM messages WHERE topic_id = ?1 ORDER BY timestamp, id",
        )?;
        let rows = stmt.query_map([topic], |r| Ok((r.get::<_, i64>(0)?, r.get::<_, i64>(1)?)))?;
        let mut negative = 0usize;
        for row in rows {
            let (id, t) = row?;
            negative += usize::from(t < 0);
            self.frames.push((id, u64::try_from(t).unwrap_or(0)));
        }
        if negative > 0 {
            self.warnings.push(format!(
                "{negative} images have negative timestamps; read as 0"
            ));
        }
        Ok(())
    }

    /// The topics as channels: id (the topic's place in the table, as the frames' channel
    /// table numbers them), name, serialization format, type (the schema's name; SQLite storage
    /// keeps no schema text, so its encoding is empty), and message count.
    fn channel_summaries(
        &self,
        listed: &[(i64, String, String, String)],
    ) -> rusqlite::Result<Vec<ChannelSummary>> {
        let mut stmt = self
            .conn
            .prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id")?;
        let counts: HashMap<i64, i64> = stmt
            .query_map([], |r| Ok((r.get::<_, i64>(0)?, r.get::<_, i64>(1)?)))?
            .collect::<rusqlite::Result<_>>()?;
        Ok(listed
            .iter()
            .zip(0..=u16::MAX)
            .map(|((id, name, type_name, format), channel)| ChannelSummary {
                id: channel,
                topic: name.clone(),
                message_encoding: format.clone(),
                schema: Some(SchemaSummary {
                    name: type_name.clone(),
                    encoding: String::new(),
                }),
                message_count: counts.get(id).map_or(0, |&n| u64::try_from(n).unwrap_or(0)),
            })
            .collect())
    }

    /// Calls `each` with every message of the file in the order it was stored (row id), its
    /// channel numbered as in [`Db3File::channels`]; sequence 0 and the timestamp as both times
    /// (the table keeps one).
    ///
    /// # Errors
    /// [`StreamError::Corrupt`] at the first row that cannot be read or is larger than any
    /// message eotn reads (the messages before it have been given to `each`).
    pub(crate) fn for_each_message(
        &self,
        mut each: impl FnMut(&StreamMessage<'_>),
    ) -> Result<(), StreamError> {
        let sql = |e: rusqlite::Error| self.corrupt(format!("reading the messages: {e}"));
        let channel_of: HashMap<i64, u16> =
            self.topics.iter().map(|t| t.id).zip(0..=u16::MAX).collect();
        // Oversized rows come back without their data, so they are refused, not loaded.
        let mut stmt = self
            .conn
            .prepare(
                "SELECT id, topic_id, timestamp, length(data), \
                 CASE WHEN length(data) <= ?1 THEN data END FROM messages ORDER BY id",
            )
            .map_err(sql)?;
        let mut rows = stmt.query([MAX_MESSAGE_BYTES]).map_err(sql)?;
        while let Some(row) = rows.next().map_err(sql)? {
            let id: i64 = row.get(0).map_err(sql)?;
            let topic: i64 = row.get(1).map_err(sql)?;
            let time = u64::try_from(row.get::<_, i64>(2).map_err(sql)?).unwrap_or(0);
            let Some(data) = row
                .get_ref(4)
                .map_err(sql)?
                .as_blob_or_null()
                .map_err(|e| self.corrupt(format!("message {id}: {e}")))?
            else {
                let len: Option<i64> = row.get(3).map_err(sql)?;
                return Err(self.corrupt(match len {
                    Some(n) => {
                        format!("message {id} holds {n} bytes, more than any message eotn reads")
                    }
                    None => format!("message {id} has no data"),
                }));
            };
            let Some(&channel) = channel_of.get(&topic) else {
                return Err(self.corrupt(format!(
                    "message {id} is on topic {topic}, which the topics table does not list"
                )));
            };
            each(&StreamMessage {
                channel,
                sequence: 0,
                log_time_ns: time,
                publish_time_ns: time,
                data,
            });
        }
        Ok(())
    }

    /// Number of frames.
    pub(crate) fn len(&self) -> usize {
        self.frames.len()
    }

    /// Frame `index`'s timestamp, nanoseconds.
    pub(crate) fn time_ns(&self, index: usize) -> Option<u64> {
        self.frames.get(index).map(|f| f.1)
    }

    fn corrupt(&self, detail: String) -> StreamError {
        StreamError::Corrupt {
            path: self.path.clone(),
            detail,
        }
    }

    /// The message bytes of row `id`, refusing ones larger than any frame.
    fn message(&self, id: i64) -> Result<Vec<u8>, StreamError> {
        let sql = |e: rusqlite::Error| self.corrupt(format!("message {id}: {e}"));
        let len: Option<i64> = self
            .conn
            .query_row(
                "SELECT length(data) FROM messages WHERE id = ?1",
                [id],
                |r| r.get(0),
            )
            .optional()
            .map_err(sql)?
            .flatten();
        match len {
            None => Err(self.corrupt(format!("message {id} has no data"))),
            Some(n) if n > MAX_MESSAGE_BYTES => {
                Err(self.corrupt(format!("message {id} holds {n} bytes, more than any frame")))
            }
            Some(_) => self
                .conn
                .query_row("SELECT data FROM messages WHERE id = ?1", [id], |r| {
                    r.get::<_, Vec<u8>>(0)
                })
                .map_err(sql),
        }
    }

    /// Frame `index`'s image and, of each other topic eotn reads, the message between the
    /// previous image and the next that is closest in time to it (the later on a tie).
    ///
    /// # Errors
    /// [`StreamError`] naming the file when the database cannot be read.
    pub(crate) fn read_raw(&mut self, index: usize) -> Result<RawFrame<'static>, StreamError> {
        let (Some(&(id, t)), Some(kind)) = (self.frames.get(index), self.image_kind) else {
            return Err(StreamError::NoSuchFrame {
                path: self.path.clone(),
                index,
                len: self.frames.len(),
            });
        };
        let image = self.message(id)?;
        let after = index
            .checked_sub(1)
            .and_then(|i| self.frames.get(i))
            .map_or(i64::MIN, |f| i64::try_from(f.1).unwrap_or(i64::MAX));
        let before = self
            .frames
            .get(index + 1)
            .map_or(i64::MAX, |f| i64::try_from(f.1).unwrap_or(i64::MAX));
        let t_i = i64::try_from(t).unwrap_or(i64::MAX);
        let mut others = Vec::new();
        let sql = |e: rusqlite::Error| self.corrupt(format!("frame {index}: {e}"));
        let mut stmt = self
            .conn
            .prepare(
                "SELECT id, timestamp FROM messages WHERE topic_id = ?1 AND timestamp > ?2 \
                 AND timestamp < ?3 ORDER BY abs(timestamp - ?4), timestamp DESC LIMIT 1",
            )
            .map_err(sql)?;
        let mut picked = Vec::new();
        for topic in &self.topics {
            let Some(role) = self.roles.get(&topic.id) else {
                continue;
            };
            if matches!(role, Role::Ignored | Role::Image(_)) {
                continue;
            }
            let near = stmt
                .query_row(rusqlite::params![topic.id, after, before, t_i], |r| {
                    Ok((r.get::<_, i64>(0)?, r.get::<_, i64>(1)?))
                })
                .optional()
                .map_err(sql)?;
            if let Some((msg, time)) = near {
                picked.push((role.clone(), msg, time));
            }
        }
        drop(stmt);
        for (role, msg, _time) in picked {
            others.push(RawMsg {
                role,
                data: Cow::Owned(self.message(msg)?),
            });
        }
        Ok(RawFrame {
            time_ns: t,
            kind,
            image: Cow::Owned(image),
            others,
        })
    }

    /// Every `/tf_static` message of the file (at most 1000), in time order.
    pub(crate) fn static_transforms(&mut self) -> Vec<Vec<u8>> {
        let statics: Vec<i64> = self
            .roles
            .iter()
            .filter(|(_, r)| **r == Role::Tf(true))
            .map(|(id, _)| *id)
            .collect();
        let mut out = Vec::new();
        for topic in statics {
            let ids: Vec<i64> = self
                .conn
                .prepare(
                    "SELECT id FROM messages WHERE topic_id = ?1 ORDER BY timestamp LIMIT 1000",
                )
                .and_then(|mut s| {
                    s.query_map([topic], |r| r.get::<_, i64>(0))?
                        .collect::<rusqlite::Result<Vec<i64>>>()
                })
                .unwrap_or_default();
            out.extend(ids.into_iter().filter_map(|id| self.message(id).ok()));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_escape_what_sqlite_would_read_as_syntax() {
        assert_eq!(
            immutable_uri(Path::new("/tmp/a b?#%/x.db3")),
            "file:/tmp/a%20b%3F%23%25/x.db3?immutable=1"
        );
    }

    #[test]
    fn files_that_are_not_bags_say_so() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.db3");
        std::fs::write(&p, b"this is not sqlite at all, not even close....").unwrap();
        let e = Db3File::open(&p, None).unwrap_err().to_string();
        assert!(e.contains("x.db3") && e.contains("not a rosbag2"), "{e}");
        let conn = Connection::open(dir.path().join("y.db3")).unwrap();
        conn.execute_batch("CREATE TABLE other(a INTEGER);")
            .unwrap();
        drop(conn);
        let e = Db3File::open(&dir.path().join("y.db3"), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("topics"), "{e}");
        assert!(Db3File::open(dir.path(), None).is_err());
    }

    #[test]
    fn a_minimal_bag_gives_its_frames_and_nearest_messages() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("b.db3");
        let conn = Connection::open(&p).unwrap();
        conn.execute_batch(
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
               serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
             CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,
               timestamp INTEGER NOT NULL, data BLOB NOT NULL);
             INSERT INTO topics VALUES (1, '/img', 'sensor_msgs/msg/CompressedImage', 'cdr', ''),
                                       (2, '/joint_states', 'sensor_msgs/msg/JointState', 'cdr', ''),
                                       (3, '/rosout', 'rcl_interfaces/msg/Log', 'cdr', '');
             INSERT INTO messages VALUES (1, 1, 100, x'01'), (2, 2, 90, x'02'), (3, 2, 104, x'03'),
                                         (4, 1, 200, x'04'), (5, 2, 170, x'05');",
        )
        .unwrap();
        drop(conn);
        let mut f = Db3File::open(&p, None).unwrap();
        assert_eq!(f.len(), 2);
        assert!(
            f.warnings.join(" ").contains("rcl_interfaces/msg/Log"),
            "{:?}",
            f.warnings
        );
        let r = f.read_raw(0).unwrap();
        assert_eq!((r.time_ns, &r.image[..]), (100, &[1u8][..]));
        assert_eq!(r.others.len(), 1);
        assert_eq!(&r.others[0].data[..], &[3]);
        let r = f.read_raw(1).unwrap();
        assert_eq!(&r.others[0].data[..], &[5]);
    }
}
