//! What each channel (MCAP) or topic (rosbag2 SQLite) of a recording is to a frame: told once
//! from its topic, schema and encoding through [`MessageKind::of`], the same for every storage.

use std::collections::HashMap;

use super::super::{
    ANNOTATIONS_TOPIC, GROUND_TRUTH_TOPIC, IMAGE_TOPIC, RECOGNITION_TOPIC, SENSORS_TOPIC,
};
use crate::camera::{CameraChannel, is_default_camera};
use crate::formats::MessageKind;

/// Name of the schema of image overlays (`eotn detect --annotate`, or other tools').
const ANNOTATIONS_SCHEMA: &str = "foxglove.ImageAnnotations";

/// What a channel's messages are to a frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Role {
    /// The camera images read as frames.
    Image(MessageKind),
    /// eotn's JSON sensor readings.
    Sensors,
    /// eotn's JSON ground truth.
    GroundTruth,
    /// eotn's JSON recognition results.
    Recognition,
    /// `foxglove.ImageAnnotations`.
    Annotations,
    /// Camera intrinsics (`CameraInfo`, `CameraCalibration`) on this topic.
    CameraInfo(MessageKind, String),
    /// `sensor_msgs/msg/JointState` on this topic.
    Joints(String),
    /// `tf2_msgs/msg/TFMessage`; `true` for `/tf_static`.
    Tf(bool),
    /// Any other JSON channel.
    Extra(String),
    /// Not read (another camera, an unknown type).
    Ignored,
}

impl Role {
    /// The topic as warnings name it.
    pub(crate) fn topic(&self) -> &str {
        match self {
            Self::Image(_) => IMAGE_TOPIC,
            Self::Sensors => SENSORS_TOPIC,
            Self::GroundTruth => GROUND_TRUTH_TOPIC,
            Self::Recognition => RECOGNITION_TOPIC,
            Self::Annotations => ANNOTATIONS_TOPIC,
            Self::CameraInfo(_, t) | Self::Joints(t) | Self::Extra(t) => t,
            Self::Tf(true) => "/tf_static",
            Self::Tf(false) => "/tf",
            Self::Ignored => "an ignored channel",
        }
    }
}

/// An image topic of a recording: what the next issue's camera choice lists.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImageTopic {
    /// The topic.
    pub topic: String,
    /// Its message type.
    pub kind: MessageKind,
}

/// Schemas and channels seen so far, to give each channel its [`Role`].
#[derive(Debug, Default)]
pub(crate) struct ChannelTable {
    /// The channel read as frames.
    pub(crate) image: Option<u16>,
    /// Its topic.
    pub(crate) image_topic: Option<String>,
    /// Channels known to hold no messages (never chosen as the camera).
    pub(crate) empty: std::collections::HashSet<u16>,
    /// The topic frames must come from (split bags: every file reads the same camera).
    pub(crate) wanted_image_topic: Option<String>,
    pub(crate) roles: HashMap<u16, Role>,
    /// Every image channel, in the order met.
    pub(crate) image_topics: Vec<ImageTopic>,
    pub(crate) notes: Vec<String>,
    /// Channels of types eotn does not read, named once in the notes.
    unread: Vec<String>,
    /// The topic of every channel given a role other than an image, to tell which camera it
    /// belongs to once every image topic is known.
    topics: HashMap<u16, String>,
}

impl ChannelTable {
    /// A table that reads frames only from `topic` when given.
    pub(crate) fn wanting(topic: Option<String>) -> Self {
        Self {
            wanted_image_topic: topic,
            ..Self::default()
        }
    }

    /// Gives channel `id` its role (once; later calls for the same id are ignored). Channels
    /// should come canonical topic first, then in id order: the first image channel is read.
    pub(crate) fn add(&mut self, id: u16, topic: &str, encoding: &str, schema_name: Option<&str>) {
        if self.roles.contains_key(&id) {
            return;
        }
        let kind = MessageKind::of(schema_name.unwrap_or(""), encoding);
        let role = match kind {
            Some(k) if k.is_image() => self.image_role(id, topic, k),
            Some(k @ (MessageKind::RosCameraInfo | MessageKind::FoxgloveCameraCalibration)) => {
                Role::CameraInfo(k, topic.to_owned())
            }
            Some(MessageKind::RosJointState) => Role::Joints(topic.to_owned()),
            Some(MessageKind::RosTf) => Role::Tf(topic == "/tf_static"),
            _ if topic == IMAGE_TOPIC => {
                self.notes.push(format!(
                    "channel {topic} is no image eotn reads (schema {}, encoding {encoding}; eotn reads {})",
                    schema_name.unwrap_or("none"),
                    MessageKind::NAMES
                ));
                Role::Ignored
            }
            _ if (topic == ANNOTATIONS_TOPIC
                || CameraChannel::of(topic)
                    .is_some_and(|(_, c)| c == CameraChannel::Annotations))
                && schema_name == Some(ANNOTATIONS_SCHEMA)
                && encoding == "protobuf" =>
            {
                Role::Annotations
            }
            _ if encoding == "json" => match topic {
                SENSORS_TOPIC => Role::Sensors,
                GROUND_TRUTH_TOPIC => Role::GroundTruth,
                RECOGNITION_TOPIC => Role::Recognition,
                _ => Role::Extra(topic.to_owned()),
            },
            _ => {
                self.unread.push(format!(
                    "{topic} ({}, {encoding})",
                    schema_name.filter(|s| !s.is_empty()).unwrap_or("no schema")
                ));
                Role::Ignored
            }
        };
        if !matches!(role, Role::Image(_) | Role::Ignored) {
            self.topics.insert(id, topic.to_owned());
        }
        self.roles.insert(id, role);
    }

    fn image_role(&mut self, id: u16, topic: &str, kind: MessageKind) -> Role {
        if self.empty.contains(&id) {
            return Role::Ignored;
        }
        if !self.image_topics.iter().any(|t| t.topic == topic) {
            self.image_topics.push(ImageTopic {
                topic: topic.to_owned(),
                kind,
            });
        }
        let wanted = self
            .wanted_image_topic
            .as_deref()
            .is_none_or(|w| w == topic);
        if self.image.is_none() && wanted {
            self.image = Some(id);
            self.image_topic = Some(topic.to_owned());
            Role::Image(kind)
        } else {
            Role::Ignored
        }
    }

    /// Gives each camera its own channels once every image topic is known (the layout of
    /// docs/formats.md, "Several cameras"): `CAMERA/sensors`, `CAMERA/ground_truth`,
    /// `CAMERA/recognition`, `CAMERA/annotations` and `CAMERA/camera_info` belong to the image
    /// topic `CAMERA`; the unprefixed `/sensors`, `/ground_truth`, `/recognition` and
    /// `/camera/annotations` to the stream's first camera (`/camera/image` or
    /// `/camera/image/compressed` when there, else the first image topic); a ROS `camera_info`
    /// beside an image topic (`NS/camera_info` for `NS/image_raw`) to that camera. Another
    /// camera's channels are not read; every other channel goes with whichever camera is read.
    fn assign_camera_channels(&mut self) {
        let Some(chosen) = self.image_topic.clone() else {
            return;
        };
        let cameras: Vec<String> = self.image_topics.iter().map(|t| t.topic.clone()).collect();
        let first = cameras
            .iter()
            .find(|t| is_default_camera(t))
            .or(cameras.first())
            .cloned();
        let reads_first = first.as_deref() == Some(chosen.as_str());
        for (id, topic) in &self.topics {
            let Some(role) = self.roles.get_mut(id) else {
                continue;
            };
            let owned =
                CameraChannel::of(topic).filter(|(camera, _)| cameras.iter().any(|c| c == camera));
            let keep = if let Some((camera, channel)) = owned {
                let mine = camera == chosen;
                if mine {
                    *role = match (channel, &*role) {
                        (CameraChannel::Sensors, Role::Extra(_)) => Role::Sensors,
                        (CameraChannel::GroundTruth, Role::Extra(_)) => Role::GroundTruth,
                        (CameraChannel::Recognition, Role::Extra(_)) => Role::Recognition,
                        _ => role.clone(),
                    };
                }
                mine
            } else {
                match role {
                    Role::Sensors | Role::GroundTruth | Role::Recognition | Role::Annotations => {
                        reads_first && !(*topic != ANNOTATIONS_TOPIC && *role == Role::Annotations)
                    }
                    Role::CameraInfo(..) => {
                        let ns = namespace(topic);
                        let beside: Vec<&String> =
                            cameras.iter().filter(|c| namespace(c) == ns).collect();
                        beside.is_empty() || beside.iter().any(|c| **c == chosen)
                    }
                    _ => true,
                }
            };
            if !keep {
                *role = Role::Ignored;
            }
        }
    }

    /// The notes of a finished table: the channels not read and the other cameras, by name.
    /// Also gives each camera its own channels (`assign_camera_channels`).
    pub(crate) fn note_other_cameras(&mut self) {
        self.assign_camera_channels();
        if !self.unread.is_empty() {
            self.notes.push(format!(
                "{} channels are not read: {} (eotn reads {})",
                self.unread.len(),
                self.unread.join(", "),
                MessageKind::NAMES
            ));
            self.unread.clear();
        }
        let Some(chosen) = self.image_topic.clone() else {
            return;
        };
        let others: Vec<&str> = self
            .image_topics
            .iter()
            .map(|t| t.topic.as_str())
            .filter(|t| *t != chosen)
            .collect();
        if !others.is_empty() {
            self.notes.push(format!(
                "{} image topics: {CAMERA_CHOICE_NOTE} {chosen}; not read: {}",
                others.len() + 1,
                others.join(", ")
            ));
        } else if chosen != IMAGE_TOPIC {
            self.notes.push(format!("{CAMERA_CHOICE_NOTE} {chosen}"));
        }
    }
}

/// The words of the note that says which camera a reader reads: a command that reads every
/// camera (`eotn import` of several) leaves that note out.
pub const CAMERA_CHOICE_NOTE: &str = "frames are read from";

/// A topic's folder: `/camera/top` of `/camera/top/camera_info`.
fn namespace(topic: &str) -> &str {
    topic.rsplit_once('/').map_or("", |(ns, _)| ns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_camera_is_read_and_the_others_named() {
        let mut t = ChannelTable::default();
        t.add(1, "/cam/left", "cdr", Some("sensor_msgs/msg/Image"));
        t.add(
            2,
            "/cam/right",
            "cdr",
            Some("sensor_msgs/msg/CompressedImage"),
        );
        t.add(
            3,
            "/joint_states",
            "cdr",
            Some("sensor_msgs/msg/JointState"),
        );
        t.add(4, "/tf_static", "cdr", Some("tf2_msgs/msg/TFMessage"));
        t.add(5, "/odd", "cdr", Some("nav_msgs/msg/Odometry"));
        t.note_other_cameras();
        assert_eq!(t.image, Some(1));
        assert_eq!(t.roles[&2], Role::Ignored);
        assert_eq!(t.roles[&3], Role::Joints("/joint_states".into()));
        assert_eq!(t.roles[&4], Role::Tf(true));
        assert_eq!(t.image_topics.len(), 2);
        let notes = t.notes.join("\n");
        assert!(
            notes.contains("nav_msgs/msg/Odometry") && notes.contains("sensor_msgs/msg/Image"),
            "{notes}"
        );
        assert!(notes.contains("not read: /cam/right"), "{notes}");
    }

    #[test]
    fn a_wanted_topic_is_read_whatever_comes_first() {
        let mut t = ChannelTable::wanting(Some("/cam/right".into()));
        t.add(1, "/cam/left", "cdr", Some("sensor_msgs/msg/Image"));
        t.add(2, "/cam/right", "cdr", Some("sensor_msgs/msg/Image"));
        assert_eq!(t.image, Some(2));
    }

    #[test]
    fn each_camera_reads_its_own_channels() {
        let json = |t: &mut ChannelTable, id, topic| t.add(id, topic, "json", Some("eotn.Json"));
        for (wanted, sensors, recognition) in [
            (None, 3, 5),
            (Some("/camera/image"), 3, 5),
            (Some("/camera/bottom"), 4, 6),
        ] {
            let mut t = ChannelTable::wanting(wanted.map(str::to_owned));
            t.add(1, IMAGE_TOPIC, "protobuf", Some("foxglove.RawImage"));
            t.add(2, "/camera/bottom", "protobuf", Some("foxglove.RawImage"));
            json(&mut t, 3, SENSORS_TOPIC);
            json(&mut t, 4, "/camera/bottom/sensors");
            json(&mut t, 5, RECOGNITION_TOPIC);
            json(&mut t, 6, "/camera/bottom/recognition");
            json(&mut t, 7, "/world_model/robot3");
            t.add(
                8,
                "/camera/bottom/annotations",
                "protobuf",
                Some(ANNOTATIONS_SCHEMA),
            );
            t.note_other_cameras();
            let of = |role: &Role| -> Vec<u16> {
                let mut ids: Vec<u16> = t
                    .roles
                    .iter()
                    .filter(|(_, r)| *r == role)
                    .map(|(id, _)| *id)
                    .collect();
                ids.sort_unstable();
                ids
            };
            assert_eq!(of(&Role::Sensors), [sensors], "{wanted:?}");
            assert_eq!(of(&Role::Recognition), [recognition], "{wanted:?}");
            assert_eq!(
                t.roles[&7],
                Role::Extra("/world_model/robot3".into()),
                "shared"
            );
            let bottom = wanted == Some("/camera/bottom");
            assert_eq!(t.roles[&8] == Role::Annotations, bottom, "{wanted:?}");
        }
    }

    #[test]
    fn a_ros_camera_info_goes_with_the_image_beside_it() {
        for (wanted, top_info, bottom_info) in [
            ("/camera/top/image_raw", true, false),
            ("/camera/bottom/image_raw", false, true),
        ] {
            let mut t = ChannelTable::wanting(Some(wanted.into()));
            t.add(
                1,
                "/camera/top/image_raw",
                "cdr",
                Some("sensor_msgs/msg/Image"),
            );
            t.add(
                2,
                "/camera/bottom/image_raw",
                "cdr",
                Some("sensor_msgs/msg/Image"),
            );
            t.add(
                3,
                "/camera/top/camera_info",
                "cdr",
                Some("sensor_msgs/msg/CameraInfo"),
            );
            t.add(
                4,
                "/camera/bottom/camera_info",
                "cdr",
                Some("sensor_msgs/msg/CameraInfo"),
            );
            t.add(5, "/calibration", "cdr", Some("sensor_msgs/msg/CameraInfo"));
            t.note_other_cameras();
            assert_eq!(t.roles[&3] != Role::Ignored, top_info);
            assert_eq!(t.roles[&4] != Role::Ignored, bottom_info);
            assert_ne!(t.roles[&5], Role::Ignored, "beside no camera: shared");
        }
    }
}
