//! A rosbag2 folder's `metadata.yaml`, versions 4 to 9, read defensively: every field optional,
//! unknown fields ignored, `offered_qos_profiles` (a string up to version 8, a list in 9) not
//! looked at, file names kept inside the bag's folder. Parsed by `serde-saphyr` (pure Rust, with
//! budgets against alias bombs and deep nesting), from at most 16 MiB.

use std::path::{Component, Path, PathBuf};

use serde::Deserialize;

/// Largest `metadata.yaml` read, bytes (a real one is a few kilobytes).
const MAX_METADATA_BYTES: u64 = 16 << 20;
/// Metadata versions this reader was written for; others are read with a warning.
pub const KNOWN_VERSIONS: std::ops::RangeInclusive<u32> = 1..=9;

/// Why a `metadata.yaml` could not be used.
#[derive(Debug, thiserror::Error)]
pub enum MetadataError {
    /// It could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// It is not the YAML of a rosbag2 bag.
    #[error("{path}: not a rosbag2 metadata.yaml: {detail}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// What the parser said.
        detail: String,
    },
}

#[derive(Debug, Deserialize)]
struct Document {
    rosbag2_bagfile_information: Info,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
struct Info {
    version: Option<u32>,
    storage_identifier: Option<String>,
    relative_file_paths: Vec<String>,
    files: Vec<FileEntry>,
    topics_with_message_count: Vec<TopicEntry>,
    compression_format: Option<String>,
    compression_mode: Option<String>,
    message_count: Option<u64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
struct FileEntry {
    path: Option<String>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
struct TopicEntry {
    topic_metadata: TopicMetadata,
    message_count: Option<u64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
struct TopicMetadata {
    name: String,
    #[serde(rename = "type")]
    type_name: String,
    serialization_format: String,
}

/// How a bag's data is compressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BagCompression {
    /// Not compressed.
    #[default]
    None,
    /// Each storage file compressed whole with zstd (`NAME.db3.zstd`, `NAME.mcap.zstd`).
    ZstdFiles,
    /// Each message's bytes compressed with zstd.
    ZstdMessages,
}

/// One topic the metadata lists.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagTopic {
    /// Topic name.
    pub name: String,
    /// ROS type (`sensor_msgs/msg/Image`).
    pub type_name: String,
    /// Serialisation (`cdr`).
    pub serialization_format: String,
    /// Messages, as the metadata counts them.
    pub message_count: u64,
}

/// What eotn needs from a `metadata.yaml`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagMetadata {
    /// The metadata version (4 to 9 from the ROS 2 releases of 2021–2026).
    pub version: u32,
    /// `sqlite3` or `mcap` (or empty when not said).
    pub storage_identifier: String,
    /// The storage files, in order, inside the bag's folder.
    pub files: Vec<PathBuf>,
    /// The topics.
    pub topics: Vec<BagTopic>,
    /// The compression.
    pub compression: BagCompression,
    /// Messages in the bag, as counted.
    pub message_count: u64,
    /// Things that were odd but did not stop the reading.
    pub warnings: Vec<String>,
}

impl BagMetadata {
    /// Reads `metadata.yaml` of the bag folder `dir`.
    ///
    /// # Errors
    /// [`MetadataError`] when it cannot be read or is not rosbag2 metadata.
    pub fn load(dir: &Path) -> Result<Self, MetadataError> {
        let path = dir.join("metadata.yaml");
        let bytes = crate::input_file::read_bounded(&path, MAX_METADATA_BYTES, "a metadata.yaml")
            .map_err(|source| MetadataError::Io {
            path: path.clone(),
            source,
        })?;
        Self::parse(&bytes).map_err(|detail| MetadataError::Malformed { path, detail })
    }

    /// Parses the text of a `metadata.yaml`.
    ///
    /// # Errors
    /// What is wrong with it.
    pub fn parse(bytes: &[u8]) -> Result<Self, String> {
        let text = std::str::from_utf8(bytes).map_err(|e| format!("not UTF-8 text ({e})"))?;
        let doc: Document = serde_saphyr::from_str(text).map_err(|e| {
            let e = e.to_string();
            e.lines().next().unwrap_or("malformed YAML").to_owned()
        })?;
        let info = doc.rosbag2_bagfile_information;
        let mut warnings = Vec::new();
        let version = info.version.unwrap_or(0);
        if !KNOWN_VERSIONS.contains(&version) {
            warnings.push(format!(
                "metadata version {version} is not one of 1–9; read as far as it is understood"
            ));
        }
        let names: Vec<String> = if info.relative_file_paths.is_empty() {
            info.files.into_iter().filter_map(|f| f.path).collect()
        } else {
            info.relative_file_paths
        };
        let mut files = Vec::new();
        for name in names {
            match inside_folder(&name) {
                Some(p) => files.push(p),
                None => warnings.push(format!(
                    "storage file '{name}' is not inside the bag's folder; skipped"
                )),
            }
        }
        let format = info.compression_format.unwrap_or_default();
        let mode = info
            .compression_mode
            .unwrap_or_default()
            .to_ascii_uppercase();
        let compression = match (format.as_str(), mode.as_str()) {
            ("", _) | (_, "" | "NONE") => BagCompression::None,
            ("zstd", "FILE") => BagCompression::ZstdFiles,
            ("zstd", "MESSAGE") => BagCompression::ZstdMessages,
            (f, m) => {
                return Err(format!(
                    "compression '{f}' of mode '{m}' is not read (zstd of files or messages is)"
                ));
            }
        };
        let topics = info
            .topics_with_message_count
            .into_iter()
            .map(|t| BagTopic {
                name: t.topic_metadata.name,
                type_name: t.topic_metadata.type_name,
                serialization_format: t.topic_metadata.serialization_format,
                message_count: t.message_count.unwrap_or(0),
            })
            .collect();
        Ok(Self {
            version,
            storage_identifier: info.storage_identifier.unwrap_or_default(),
            files,
            topics,
            compression,
            message_count: info.message_count.unwrap_or(0),
            warnings,
        })
    }
}

/// A relative path that stays inside the bag's folder (no `..`, no root), or `None`.
fn inside_folder(name: &str) -> Option<PathBuf> {
    let p = Path::new(name);
    let ok = !name.is_empty() && p.components().all(|c| matches!(c, Component::Normal(_)));
    ok.then(|| p.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Version 4 (Foxy/Galactic): no `files`, qos as a string.
    const V4: &str = "rosbag2_bagfile_information:
  version: 4
  storage_identifier: sqlite3
  relative_file_paths:
    - test_bag_0.db3
  duration:
    nanoseconds: 2
  starting_time:
    nanoseconds_since_epoch: 1
  message_count: 3
  topics_with_message_count:
    - topic_metadata:
        name: /camera
        type: sensor_msgs/msg/Image
        serialization_format: cdr
        offered_qos_profiles: \"- history: 3\\n  depth: 0\\n\"
      message_count: 3
  compression_format: \"\"
  compression_mode: \"\"
";

    /// Version 9 (Jazzy and later): qos as a list, type hashes, custom data.
    const V9: &str = "rosbag2_bagfile_information:
  version: 9
  storage_identifier: mcap
  duration: {nanoseconds: 5}
  starting_time: {nanoseconds_since_epoch: 10}
  message_count: 2
  topics_with_message_count:
    - topic_metadata:
        name: /image
        type: sensor_msgs/msg/CompressedImage
        serialization_format: cdr
        offered_qos_profiles:
          - history: keep_last
            depth: 10
        type_description_hash: RIHS01_abc
      message_count: 2
  compression_format: zstd
  compression_mode: MESSAGE
  relative_file_paths: [a_0.mcap, a_1.mcap]
  files:
    - path: a_0.mcap
      starting_time: {nanoseconds_since_epoch: 10}
      duration: {nanoseconds: 1}
      message_count: 1
  custom_data: {who: me}
  ros_distro: jazzy
";

    /// Version 7 (Iron): `files`, `custom_data` and type hashes, qos as a string, no
    /// `ros_distro` (rosbag2's `yaml.hpp` reads that from version 8 on).
    const V7: &str = "rosbag2_bagfile_information:
  version: 7
  storage_identifier: mcap
  duration:
    nanoseconds: 800000000
  starting_time:
    nanoseconds_since_epoch: 1700000000000000000
  message_count: 48
  topics_with_message_count:
    - topic_metadata:
        name: /camera/image_raw
        type: sensor_msgs/msg/Image
        serialization_format: cdr
        offered_qos_profiles: \"- history: 3\\n  depth: 0\\n  reliability: 1\\n\"
        type_description_hash: RIHS01_d31d9d8d0e1ea53a
      message_count: 24
    - topic_metadata:
        name: /joint_states
        type: sensor_msgs/msg/JointState
        serialization_format: cdr
        offered_qos_profiles: \"\"
        type_description_hash: RIHS01_a5a5
      message_count: 24
  compression_format: \"\"
  compression_mode: \"\"
  relative_file_paths:
    - iron_0.mcap
  files:
    - path: iron_0.mcap
      starting_time:
        nanoseconds_since_epoch: 1700000000000000000
      duration:
        nanoseconds: 800000000
      message_count: 48
  custom_data: ~
";

    #[test]
    fn version_seven_parses_with_its_type_hashes_and_without_a_distro() {
        let m = BagMetadata::parse(V7.as_bytes()).unwrap();
        assert_eq!(m.version, 7);
        assert!(m.warnings.is_empty(), "{:?}", m.warnings);
        assert_eq!(m.storage_identifier, "mcap");
        assert_eq!(m.files, [PathBuf::from("iron_0.mcap")]);
        assert_eq!(m.compression, BagCompression::None);
        let names: Vec<&str> = m.topics.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["/camera/image_raw", "/joint_states"]);
        assert_eq!(m.topics[0].type_name, "sensor_msgs/msg/Image");
        assert_eq!(m.topics[0].message_count, 24);
    }

    #[test]
    fn versions_four_and_nine_parse() {
        let m = BagMetadata::parse(V4.as_bytes()).unwrap();
        assert_eq!(m.version, 4);
        assert_eq!(m.files, [PathBuf::from("test_bag_0.db3")]);
        assert_eq!(m.topics[0].type_name, "sensor_msgs/msg/Image");
        assert_eq!(m.compression, BagCompression::None);
        assert!(m.warnings.is_empty());
        let m = BagMetadata::parse(V9.as_bytes()).unwrap();
        assert_eq!(m.version, 9);
        assert_eq!(m.storage_identifier, "mcap");
        assert_eq!(m.files.len(), 2);
        assert_eq!(m.compression, BagCompression::ZstdMessages);
        assert_eq!(m.topics[0].message_count, 2);
    }

    #[test]
    fn hostile_or_odd_metadata_is_refused_or_contained() {
        let escaping = V4.replace("test_bag_0.db3", "../../etc/passwd");
        let m = BagMetadata::parse(escaping.as_bytes()).unwrap();
        assert!(
            m.files.is_empty() && m.warnings[0].contains("not inside"),
            "{m:?}"
        );
        assert!(BagMetadata::parse(b"just: a map").is_err());
        assert!(BagMetadata::parse(b"\xff\xfe").is_err());
        let lz4 = V4
            .replace("compression_format: \"\"", "compression_format: lz4")
            .replace("compression_mode: \"\"", "compression_mode: FILE");
        let e = BagMetadata::parse(lz4.as_bytes()).unwrap_err();
        assert!(e.contains("lz4"), "{e}");
        // A billion laughs: the parser's budget stops it.
        let mut bomb = String::from("a: &a [x, x, x, x, x, x, x, x, x, x]\n");
        for i in 1..12 {
            bomb.push_str(&format!(
                "b{i}: &b{i} [{0}, {0}, {0}, {0}, {0}, {0}, {0}, {0}, {0}, {0}]\n",
                if i == 1 {
                    "*a".to_owned()
                } else {
                    format!("*b{}", i - 1)
                }
            ));
        }
        let doc = format!(
            "rosbag2_bagfile_information:\n  version: 5\n  custom_data:\n    {}",
            bomb.replace('\n', "\n    ")
        );
        let _ = BagMetadata::parse(doc.as_bytes());
    }
}
