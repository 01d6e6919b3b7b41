//! Which camera: a recording's image topic, a live robot's image channel, or an overhead source
//! ([`CameraId`]), and the files each camera is recognised with ([`CameraFiles`]: its table,
//! recognition parameters and, for an overhead camera, calibration).
//!
//! One mechanism ties a recording's cameras to their files (docs/formats.md, "Several
//! cameras"): the stream's metadata names each camera's defaults (`eotn.camera` records, read by
//! the stream reader), and a sidecar file beside the recording, `REC.cameras.json`
//! ([`sidecar_path`]), overrides them key by key ([`files_for`]). The app remembers what the user
//! chose per camera in its settings, keyed by [`CameraId`].
//!
//! A stream's channels are laid out per camera: the camera `/camera/image` (or its compressed
//! twin) owns the channels streams have always had (`/sensors`, `/ground_truth`,
//! `/recognition`, `/camera/annotations`); any other camera `TOPIC` owns `TOPIC/sensors`,
//! `TOPIC/ground_truth`, `TOPIC/recognition`, `TOPIC/annotations` and `TOPIC/camera_info`
//! ([`CameraChannel`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// Topic of the camera image channel of eotn's streams (`foxglove.RawImage`, protobuf): the
/// first camera's.
pub const IMAGE_TOPIC: &str = "/camera/image";
/// Topic of the first camera's images stored compressed, as they came
/// (`foxglove.CompressedImage`, JPEG or PNG, written by `eotn import` from recordings that hold
/// them).
pub const COMPRESSED_IMAGE_TOPIC: &str = "/camera/image/compressed";

/// The start of a robot camera's image topic in a World Model Debugger session recording
/// (`eotn wmd -o`): `/robot/TEAM-ID` (a session's robot, by its marker) or `/robot/N` (the N-th
/// `--robot`). Such a camera of an overhead recording is a robot's camera, not the overhead one.
pub const SESSION_ROBOT_TOPIC_PREFIX: &str = "/robot/";

/// The MCAP metadata record naming one camera's default files (keys `topic`, `lut`, `params`,
/// `calibration`; one record per camera).
pub const CAMERA_METADATA_NAME: &str = "eotn.camera";
/// Appended to a recording's path to name its sidecar (`game.mcap` → `game.mcap.cameras.json`).
pub const SIDECAR_SUFFIX: &str = ".cameras.json";

/// True for the topics of a stream's first camera, which owns the unprefixed channels.
#[must_use]
pub fn is_default_camera(topic: &str) -> bool {
    topic == IMAGE_TOPIC || topic == COMPRESSED_IMAGE_TOPIC
}

/// A channel that belongs to one camera of a stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraChannel {
    /// Sensor readings (JSON `eotn.SensorReadings`).
    Sensors,
    /// Ground truth (JSON).
    GroundTruth,
    /// Recognition results (JSON).
    Recognition,
    /// `foxglove.ImageAnnotations`.
    Annotations,
    /// Camera intrinsics (`CameraInfo`, `CameraCalibration`, or their JSON).
    CameraInfo,
}

impl CameraChannel {
    /// Every per-camera channel.
    pub const ALL: [Self; 5] = [
        Self::Sensors,
        Self::GroundTruth,
        Self::Recognition,
        Self::Annotations,
        Self::CameraInfo,
    ];

    /// The last part of the topic under a camera's name (`sensors` of `/camera/top/sensors`).
    #[must_use]
    pub const fn suffix(self) -> &'static str {
        match self {
            Self::Sensors => "sensors",
            Self::GroundTruth => "ground_truth",
            Self::Recognition => "recognition",
            Self::Annotations => "annotations",
            Self::CameraInfo => "camera_info",
        }
    }

    /// The camera and channel a topic names when it is `CAMERA/SUFFIX` (whether `CAMERA` is an
    /// image topic of the stream is for the caller to check).
    #[must_use]
    pub fn of(topic: &str) -> Option<(&str, Self)> {
        let (camera, last) = topic.rsplit_once('/')?;
        if camera.is_empty() {
            return None;
        }
        Self::ALL
            .into_iter()
            .find(|c| c.suffix() == last)
            .map(|c| (camera, c))
    }

    /// This channel's topic for the camera `camera`: the stream's fixed topics for the first
    /// camera (`/sensors`, `/ground_truth`, `/recognition`, `/camera/annotations`,
    /// `/camera/camera_info`), `CAMERA/SUFFIX` for any other.
    #[must_use]
    pub fn topic(self, camera: &str) -> String {
        if is_default_camera(camera) {
            match self {
                Self::Sensors => "/sensors".to_owned(),
                Self::GroundTruth => "/ground_truth".to_owned(),
                Self::Recognition => "/recognition".to_owned(),
                Self::Annotations => "/camera/annotations".to_owned(),
                Self::CameraInfo => "/camera/camera_info".to_owned(),
            }
        } else {
            format!("{camera}/{}", self.suffix())
        }
    }
}

/// Which camera, as a type: what settings remember each camera's files under, and what the app's
/// commands name a camera by (never a bare string).
///
/// A camera is its source and its image topic together: every one-camera stream eotn writes has
/// the topic `/camera/image`, so a topic alone names no camera (two unrelated recordings, a robot's
/// and an overhead one, would share one table).
///
/// Written as text (settings keys, messages): `recording:PATH TOPIC`, `live:URL TOPIC`,
/// `overhead:SOURCE TOPIC` (topics start with `/` and hold no space, so the last space splits).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CameraId {
    /// A robot camera of one recording: the recording (its canonical path) and its image topic
    /// (`/camera/top`, `/camera/bottom/image_raw`).
    Recording {
        /// The recording's file or bag folder, canonical.
        recording: PathBuf,
        /// The image topic.
        topic: String,
    },
    /// A live robot's image channel.
    Live {
        /// The robot's server, `ws://HOST:PORT`.
        robot: String,
        /// The image channel's topic.
        topic: String,
    },
    /// An overhead camera: its source (a recording's canonical path, a camera device, a
    /// scenario) and image topic.
    Overhead {
        /// The source.
        source: String,
        /// The image topic (`/camera/image` for a source with one camera).
        topic: String,
    },
}

impl CameraId {
    /// The robot camera `topic` of the recording `recording` (canonical, or as given).
    #[must_use]
    pub fn recording(recording: &Path, topic: &str) -> Self {
        Self::Recording {
            recording: recording.to_owned(),
            topic: topic.to_owned(),
        }
    }

    /// The image channel `topic` of the live robot at `robot` (`ws://HOST:PORT`).
    #[must_use]
    pub fn live(robot: &str, topic: &str) -> Self {
        Self::Live {
            robot: robot.to_owned(),
            topic: topic.to_owned(),
        }
    }

    /// The overhead camera `topic` of `source`.
    #[must_use]
    pub fn overhead(source: &str, topic: &str) -> Self {
        Self::Overhead {
            source: source.to_owned(),
            topic: topic.to_owned(),
        }
    }

    /// Its image topic.
    #[must_use]
    pub fn topic(&self) -> &str {
        match self {
            Self::Recording { topic, .. }
            | Self::Live { topic, .. }
            | Self::Overhead { topic, .. } => topic,
        }
    }

    /// Its source as text: the recording's path, the robot's address, the overhead source.
    #[must_use]
    pub fn source(&self) -> String {
        match self {
            Self::Recording { recording, .. } => recording.to_string_lossy().into_owned(),
            Self::Live { robot, .. } => robot.clone(),
            Self::Overhead { source, .. } => source.clone(),
        }
    }

    /// True when both are cameras of the same source (two topics of one recording or robot).
    #[must_use]
    pub fn same_source(&self, other: &Self) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
            && self.source() == other.source()
    }

    /// The camera `topic` of the same source.
    #[must_use]
    pub fn with_topic(&self, topic: &str) -> Self {
        let mut id = self.clone();
        match &mut id {
            Self::Recording { topic: t, .. }
            | Self::Live { topic: t, .. }
            | Self::Overhead { topic: t, .. } => topic.clone_into(t),
        }
        id
    }
}

impl std::fmt::Display for CameraId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self {
            Self::Recording { .. } => "recording",
            Self::Live { .. } => "live",
            Self::Overhead { .. } => "overhead",
        };
        write!(f, "{kind}:{} {}", self.source(), self.topic())
    }
}

/// Why a camera's written name could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "'{0}' names no camera (recording:PATH TOPIC, live:ws://HOST:PORT TOPIC or overhead:SOURCE TOPIC)"
)]
pub struct BadCameraId(String);

impl std::str::FromStr for CameraId {
    type Err = BadCameraId;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let bad = || BadCameraId(text.to_owned());
        let (kind, rest) = text.split_once(':').ok_or_else(bad)?;
        let (source, topic) = rest.rsplit_once(' ').ok_or_else(bad)?;
        if source.is_empty() || !topic.starts_with('/') {
            return Err(bad());
        }
        match kind {
            "recording" => Ok(Self::recording(Path::new(source), topic)),
            "live" => Ok(Self::live(source, topic)),
            "overhead" => Ok(Self::overhead(source, topic)),
            _ => Err(bad()),
        }
    }
}

impl Serialize for CameraId {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for CameraId {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// Each camera's files by camera, read leniently: an entry whose key names no camera (written by
/// an older eotn, which keyed cameras by topic alone) is left out, so the rest of the settings
/// still load.
///
/// # Errors
/// The value is not a map of camera files.
pub fn deserialize_camera_map<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<BTreeMap<CameraId, CameraFiles>, D::Error> {
    let raw = BTreeMap::<String, serde_json::Value>::deserialize(d)?;
    Ok(raw
        .into_iter()
        .filter_map(|(k, v)| {
            let id = k.parse().ok()?;
            let files = serde_json::from_value(v).ok()?;
            Some((id, files))
        })
        .collect())
}

/// The files one camera is recognised with; each may be unset (the command line's, the app's
/// or the built-in defaults then apply).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraFiles {
    /// Its lookup table (`.lut`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lut: Option<PathBuf>,
    /// Its recognition parameters: a file, or a shipped set's name (`spl2009`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub params: Option<String>,
    /// An overhead camera's calibration file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibration: Option<PathBuf>,
}

impl CameraFiles {
    /// True when no file is named.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.lut.is_none() && self.params.is_none() && self.calibration.is_none()
    }

    /// These files with each one `over` names put in their place.
    #[must_use]
    pub fn overridden_by(self, over: &Self) -> Self {
        Self {
            lut: over.lut.clone().or(self.lut),
            params: over.params.clone().or(self.params),
            calibration: over.calibration.clone().or(self.calibration),
        }
    }

    /// Relative paths made relative to `folder` (a params value that names a shipped set —
    /// no `/` and no `.json` — is kept as it is).
    #[must_use]
    pub fn relative_to(mut self, folder: &Path) -> Self {
        let join = |p: PathBuf| if p.is_relative() { folder.join(p) } else { p };
        self.lut = self.lut.map(join);
        self.calibration = self.calibration.map(join);
        self.params = self.params.map(|p| {
            if p.contains('/') || p.ends_with(".json") {
                join(PathBuf::from(p)).to_string_lossy().into_owned()
            } else {
                p
            }
        });
        self
    }

    /// The files as an `eotn.camera` metadata record's keys (with `topic`).
    #[must_use]
    pub fn to_metadata(&self, topic: &str) -> BTreeMap<String, String> {
        let mut m = BTreeMap::from([("topic".to_owned(), topic.to_owned())]);
        if let Some(p) = &self.lut {
            m.insert("lut".to_owned(), p.to_string_lossy().into_owned());
        }
        if let Some(p) = &self.params {
            m.insert("params".to_owned(), p.clone());
        }
        if let Some(p) = &self.calibration {
            m.insert("calibration".to_owned(), p.to_string_lossy().into_owned());
        }
        m
    }

    /// An `eotn.camera` metadata record read back: its topic and files; `Err` names a key it
    /// does not have or one it should not.
    ///
    /// # Errors
    /// No `topic`, or a key other than `topic`, `lut`, `params`, `calibration`.
    pub fn from_metadata(m: &BTreeMap<String, String>) -> Result<(String, Self), String> {
        let topic = m
            .get("topic")
            .filter(|t| t.starts_with('/'))
            .ok_or_else(|| format!("{CAMERA_METADATA_NAME} metadata without a topic"))?;
        if let Some(k) = m
            .keys()
            .find(|k| !["topic", "lut", "params", "calibration"].contains(&k.as_str()))
        {
            return Err(format!(
                "{CAMERA_METADATA_NAME} metadata of {topic}: unknown key '{k}'"
            ));
        }
        Ok((
            topic.clone(),
            Self {
                lut: m.get("lut").map(PathBuf::from),
                params: m.get("params").cloned(),
                calibration: m.get("calibration").map(PathBuf::from),
            },
        ))
    }
}

/// The sidecar file of a recording: `REC.cameras.json` beside it (a bag folder's beside the
/// folder, `bag.cameras.json`).
#[must_use]
pub fn sidecar_path(recording: &Path) -> PathBuf {
    let trimmed = recording.to_string_lossy().trim_end_matches('/').to_owned();
    PathBuf::from(trimmed + SIDECAR_SUFFIX)
}

/// The sidecar's content: each camera's files by image topic (paths relative to the
/// sidecar's folder).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sidecar {
    /// Files per image topic.
    pub cameras: BTreeMap<String, CameraFiles>,
}

/// Why a sidecar could not be used; the message names the file.
#[derive(Debug, thiserror::Error)]
pub enum SidecarError {
    /// It could not be read (not a regular file, too large, I/O).
    #[error("{path}: {source}")]
    Io {
        /// The sidecar.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// It is not the sidecar's JSON (bad JSON, an unknown key, a topic not starting with `/`).
    #[error("{path}: {detail}")]
    Invalid {
        /// The sidecar.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
}

impl Sidecar {
    /// Reads the sidecar of `recording`; `None` when there is none. Relative paths are made
    /// relative to the sidecar's folder.
    ///
    /// # Errors
    /// [`SidecarError`] naming the file: unreadable, not JSON, unknown keys, bad topics.
    pub fn load(recording: &Path) -> Result<Option<Self>, SidecarError> {
        let path = sidecar_path(recording);
        let text = match crate::input_file::read_text_bounded(
            &path,
            crate::input_file::MAX_SMALL_FILE_BYTES,
            "a cameras sidecar",
        ) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(source) => return Err(SidecarError::Io { path, source }),
        };
        let invalid = |detail: String| SidecarError::Invalid {
            path: path.clone(),
            detail,
        };
        let sidecar: Self = serde_json::from_str(&text).map_err(|e| invalid(e.to_string()))?;
        if let Some(t) = sidecar.cameras.keys().find(|t| !t.starts_with('/')) {
            return Err(invalid(format!(
                "camera '{t}' is no topic (topics start with '/')"
            )));
        }
        let folder = path.parent().unwrap_or(Path::new("")).to_owned();
        Ok(Some(Self {
            cameras: sidecar
                .cameras
                .into_iter()
                .map(|(t, f)| (t, f.relative_to(&folder)))
                .collect(),
        }))
    }

    /// Writes the sidecar of `recording` (pretty JSON, through [`crate::atomic_file`]).
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn save(&self, recording: &Path) -> std::io::Result<()> {
        let mut text = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        text.push('\n');
        crate::atomic_file::write_atomic(&sidecar_path(recording), text.as_bytes())
    }
}

/// The files of the camera `topic` of `recording`: the stream's defaults (`metadata`, from its
/// `eotn.camera` records, paths relative to the recording's folder) with the sidecar's entries in
/// their place.
///
/// # Errors
/// A sidecar that is there but cannot be used.
pub fn files_for(
    recording: &Path,
    metadata: &[(String, CameraFiles)],
    topic: &str,
) -> Result<CameraFiles, SidecarError> {
    let folder = recording.parent().unwrap_or(Path::new("")).to_owned();
    // The first camera is one camera whether its frames are raw or compressed.
    let same = |t: &str| t == topic || (is_default_camera(t) && is_default_camera(topic));
    let defaults = metadata
        .iter()
        .find(|(t, _)| same(t))
        .map(|(_, f)| f.clone().relative_to(&folder))
        .unwrap_or_default();
    let sidecar = Sidecar::load(recording)?;
    let over = sidecar
        .as_ref()
        .and_then(|s| s.cameras.iter().find(|(t, _)| same(t)).map(|(_, f)| f));
    Ok(match over {
        Some(over) => defaults.overridden_by(over),
        None => defaults,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_ids_read_back_what_they_write() {
        let ids = [
            CameraId::recording(Path::new("/data/game one.mcap"), "/camera/top"),
            CameraId::live("ws://10.0.0.5:8765", "/camera/bottom/image_raw"),
            CameraId::overhead("/dev/video0", "/camera/image"),
        ];
        for id in ids {
            let text = id.to_string();
            assert_eq!(text.parse::<CameraId>(), Ok(id.clone()), "{text}");
            let json = serde_json::to_string(&id).unwrap();
            assert_eq!(serde_json::from_str::<CameraId>(&json).unwrap(), id);
        }
        for bad in [
            "",
            "/camera/top",
            "recording:/camera/top",
            "recording:a.mcap top",
            "live:/camera",
            "weird:x /camera",
        ] {
            assert!(bad.parse::<CameraId>().is_err(), "{bad}");
        }
        let a = CameraId::recording(Path::new("/a.mcap"), "/camera/image");
        assert!(a.same_source(&a.with_topic("/camera/bottom")));
        assert!(!a.same_source(&CameraId::recording(Path::new("/b.mcap"), "/camera/image")));
        assert!(!a.same_source(&CameraId::overhead("/a.mcap", "/camera/image")));
    }

    #[test]
    fn settings_written_by_an_older_eotn_drop_only_their_topic_keyed_cameras() {
        #[derive(Deserialize)]
        struct Holder {
            #[serde(deserialize_with = "deserialize_camera_map")]
            cameras: BTreeMap<CameraId, CameraFiles>,
        }
        let text = r#"{"cameras": {
            "recording:/camera/image": {"lut": "old.lut"},
            "recording:/data/a.mcap /camera/image": {"lut": "a.lut"}
        }}"#;
        let h: Holder = serde_json::from_str(text).unwrap();
        assert_eq!(h.cameras.len(), 1);
        let a = CameraId::recording(Path::new("/data/a.mcap"), "/camera/image");
        assert_eq!(h.cameras[&a].lut.as_deref(), Some(Path::new("a.lut")));
    }

    #[test]
    fn channels_are_named_under_their_camera() {
        assert_eq!(CameraChannel::Sensors.topic(IMAGE_TOPIC), "/sensors");
        assert_eq!(
            CameraChannel::Annotations.topic(COMPRESSED_IMAGE_TOPIC),
            "/camera/annotations"
        );
        let top = CameraChannel::Recognition.topic("/camera/top");
        assert_eq!(top, "/camera/top/recognition");
        assert_eq!(
            CameraChannel::of(&top),
            Some(("/camera/top", CameraChannel::Recognition))
        );
        assert_eq!(CameraChannel::of("/sensors"), None);
        assert_eq!(CameraChannel::of("/robot/pose"), None);
    }

    #[test]
    fn the_sidecar_overrides_the_stream_s_defaults_key_by_key() {
        let dir = tempfile::tempdir().unwrap();
        let rec = dir.path().join("game.mcap");
        let metadata = vec![
            (
                "/camera/top".to_owned(),
                CameraFiles {
                    lut: Some("tables/top.lut".into()),
                    params: Some("spl2009".into()),
                    calibration: None,
                },
            ),
            (
                "/camera/bottom".to_owned(),
                CameraFiles {
                    lut: Some("/abs/bottom.lut".into()),
                    ..CameraFiles::default()
                },
            ),
        ];
        let top = files_for(&rec, &metadata, "/camera/top").unwrap();
        assert_eq!(top.lut, Some(dir.path().join("tables/top.lut")));
        assert_eq!(top.params.as_deref(), Some("spl2009"));
        std::fs::write(
            sidecar_path(&rec),
            r#"{"cameras": {"/camera/top": {"lut": "mine.lut"}}}"#,
        )
        .unwrap();
        let top = files_for(&rec, &metadata, "/camera/top").unwrap();
        assert_eq!(top.lut, Some(dir.path().join("mine.lut")), "the sidecar's");
        assert_eq!(top.params.as_deref(), Some("spl2009"), "the stream's kept");
        let bottom = files_for(&rec, &metadata, "/camera/bottom").unwrap();
        assert_eq!(bottom.lut, Some(PathBuf::from("/abs/bottom.lut")));
        assert!(
            files_for(&rec, &metadata, "/camera/side")
                .unwrap()
                .is_empty()
        );
        std::fs::write(
            sidecar_path(&rec),
            r#"{"cameras": {"/top": {"table": "x"}}}"#,
        )
        .unwrap();
        let e = files_for(&rec, &metadata, "/top").unwrap_err().to_string();
        assert!(
            e.contains("game.mcap.cameras.json") && e.contains("table"),
            "{e}"
        );
    }

    #[test]
    fn metadata_records_round_trip_and_refuse_unknown_keys() {
        let f = CameraFiles {
            lut: Some("top.lut".into()),
            params: None,
            calibration: Some("cal.json".into()),
        };
        let m = f.to_metadata("/camera/top");
        assert_eq!(
            CameraFiles::from_metadata(&m),
            Ok(("/camera/top".to_owned(), f))
        );
        let mut bad = m.clone();
        bad.insert("colour".into(), "x".into());
        assert!(
            CameraFiles::from_metadata(&bad)
                .unwrap_err()
                .contains("colour")
        );
        bad.clear();
        assert!(CameraFiles::from_metadata(&bad).is_err());
    }

    #[test]
    fn a_bag_folder_s_sidecar_is_beside_it() {
        assert_eq!(
            sidecar_path(Path::new("/data/bag/")),
            PathBuf::from("/data/bag.cameras.json")
        );
    }
}
