//! The session file (`SESSION.json`, docs/formats.md): one field watched by several overhead
//! cameras, each with its own table and calibration, and any number of robots sending their
//! world models.
//!
//! Plain data in and out: [`Session::load`] reads the file, resolves every path against the
//! session file's folder, and checks what can be checked without opening anything heavy —
//! unknown keys, ids in range and unique, the files named exist and are files. Each error names
//! the entry (`overhead[2] (id 5)`) and the key. The calibration's `intrinsics` is a path that
//! is carried, not read (the lens models are the calibration's business).

#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use serde::Deserialize;
use serde_json::Value;
use thiserror::Error;

use crate::geometry::{MarkerIdentity, MarkerTeam};
use crate::input_file::{MAX_SMALL_FILE_BYTES, read_text_bounded};
use crate::overhead::FieldDescription;
use crate::overhead::field::{SHIPPED_FIELDS, shipped_field_names};

pub use crate::overhead::merge::SslCameraId;

/// Where a camera's or robot's frames come from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SessionSource {
    /// A recording eotn reads (MCAP stream, frame file, folder), resolved against the session
    /// file's folder.
    Recording(PathBuf),
    /// A `ws://` or `wss://` robot or overhead server.
    Live(String),
    /// A camera device as `eotn sources` names it (`/dev/videoN`).
    Device(PathBuf),
    /// SSL-Vision's detection frames in place of an eotn overhead camera (no table or
    /// calibration: ssl-vision has found the ball and robots already).
    Ssl(SslSource),
}

/// Where SSL-Vision detection frames come from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SslSource {
    /// Packets received live on `udp://GROUP:PORT` (a multicast group or a unicast address).
    Udp(String),
    /// A league log file (`SSL_LOG_FILE`, plain or gzip), resolved against the session file's
    /// folder.
    Log(PathBuf),
}

/// The source as the user wrote it, with what it is: "recording streams/x.mcap", "SSL-Vision
/// udp://224.5.23.2:10006" — for messages that refuse a kind of source.
impl std::fmt::Display for SessionSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Recording(p) => write!(f, "recording {}", p.display()),
            Self::Live(url) => write!(f, "live server {url}"),
            Self::Device(p) => write!(f, "camera device {}", p.display()),
            Self::Ssl(s) => write!(f, "SSL-Vision {s}"),
        }
    }
}

impl std::fmt::Display for SslSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Udp(url) => f.write_str(url),
            Self::Log(p) => write!(f, "{}", p.display()),
        }
    }
}

/// Whether a path names a league log by its extension (`.log`, `.log.gz`): it is read as one,
/// and a B-Human log so named gets the line pointing to `eotn import --bhuman`.
fn is_log_name(p: &Path) -> bool {
    let name = p.to_string_lossy().to_ascii_lowercase();
    name.ends_with(".log") || name.ends_with(".log.gz")
}

impl SessionSource {
    /// What a command-line SOURCE names: a `ws://`/`wss://` server, a `/dev/…` device, a
    /// `udp://` SSL-Vision address or a league log (`.log`, `.log.gz`), else a recording.
    #[must_use]
    pub fn parse_arg(arg: &Path) -> Self {
        let s = arg.to_string_lossy();
        if s.starts_with("ws://") || s.starts_with("wss://") {
            Self::Live(s.into_owned())
        } else if crate::ssl_vision::listener::is_udp_url(&s) {
            Self::Ssl(SslSource::Udp(s.into_owned()))
        } else if is_log_name(arg) {
            Self::Ssl(SslSource::Log(arg.to_owned()))
        } else if s.starts_with("/dev/") {
            Self::Device(arg.to_owned())
        } else {
            Self::Recording(arg.to_owned())
        }
    }
}

/// The field of a session.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldRef {
    /// A field description file, resolved against the session file's folder.
    File(PathBuf),
    /// A field description shipped with eotn, by name (the names `--field` takes:
    /// [`crate::overhead::field::SHIPPED_FIELDS`]).
    Shipped(String),
}

impl FieldRef {
    /// The field description.
    ///
    /// # Errors
    /// The field file's loader error, naming it.
    pub fn load(&self) -> anyhow::Result<FieldDescription> {
        match self {
            Self::File(p) => Ok(FieldDescription::load(p)?),
            Self::Shipped(name) => Ok(FieldDescription::resolve(name)?),
        }
    }
}

/// One overhead camera of the session.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OverheadEntry {
    /// Its SSL camera id.
    pub id: SslCameraId,
    /// Its frames.
    pub source: SessionSource,
    /// The topic of its frames when the source has several.
    pub camera: Option<String>,
    /// Its lookup table (required, except for an SSL-Vision source, which has none).
    pub lut: Option<PathBuf>,
    /// Its calibration (`eotn overhead calibrate`; required, except for an SSL-Vision source).
    pub calibration: Option<PathBuf>,
    /// Its lens intrinsics (ROS `camera_info` YAML), carried for the calibration.
    pub intrinsics: Option<PathBuf>,
    /// Its overhead recogniser parameters.
    pub params: Option<PathBuf>,
}

impl OverheadEntry {
    /// Which camera this is, as the app and the settings name it: the overhead camera of its
    /// source (a recording's canonical path, a server, a device) and topic (`/camera/image`
    /// when it names none).
    #[must_use]
    pub fn camera_id(&self) -> crate::camera::CameraId {
        let source = match &self.source {
            SessionSource::Recording(p) => std::fs::canonicalize(p)
                .unwrap_or_else(|_| p.clone())
                .to_string_lossy()
                .into_owned(),
            SessionSource::Live(url) => url.clone(),
            SessionSource::Device(p) => p.to_string_lossy().into_owned(),
            SessionSource::Ssl(s) => s.to_string(),
        };
        let topic = self.camera.as_deref().unwrap_or(crate::camera::IMAGE_TOPIC);
        crate::camera::CameraId::overhead(&source, topic)
    }
}

/// One robot of the session, named by the marker it wears.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RobotEntry {
    /// The marker's team.
    pub team: MarkerTeam,
    /// The marker's identity.
    pub robot_id: MarkerIdentity,
    /// Its world models (and camera frames).
    pub source: SessionSource,
    /// The topic of its camera frames when the source has several.
    pub camera: Option<String>,
    /// Its camera's table, when its frames are to be recognised.
    pub lut: Option<PathBuf>,
    /// Its recognition parameters.
    pub params: Option<PathBuf>,
}

/// A session file, read and checked, its paths resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Session {
    /// The file it was read from.
    pub path: PathBuf,
    /// The field.
    pub field: FieldRef,
    /// The overhead cameras, in file order; the first is the reference camera.
    pub overhead: Vec<OverheadEntry>,
    /// The robots, in file order.
    pub robots: Vec<RobotEntry>,
}

/// Why a session file cannot be used.
#[derive(Debug, Error)]
pub enum SessionError {
    /// The file cannot be read.
    #[error("{path}: cannot read the session file: {source}")]
    Read {
        /// The session file.
        path: PathBuf,
        /// The reason.
        source: std::io::Error,
    },
    /// The file or one entry is not what the format says.
    #[error("{path}: {entry}: {message}")]
    Entry {
        /// The session file.
        path: PathBuf,
        /// Which entry (`overhead[1] (id 3)`, `field`, the top level).
        entry: String,
        /// What is wrong.
        message: String,
    },
}

/// The file's top level, its entries left as JSON so each is read (and named) on its own.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSession {
    field: String,
    #[serde(default)]
    overhead: Vec<Value>,
    #[serde(default)]
    robots: Vec<Value>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOverhead {
    id: u8,
    source: String,
    camera: Option<String>,
    lut: Option<PathBuf>,
    calibration: Option<PathBuf>,
    intrinsics: Option<PathBuf>,
    params: Option<PathBuf>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRobot {
    team: String,
    robot_id: u8,
    source: String,
    camera: Option<String>,
    lut: Option<PathBuf>,
    params: Option<PathBuf>,
}

impl Session {
    /// Reads and checks a session file.
    ///
    /// # Errors
    /// [`SessionError`], naming the file and the entry.
    pub fn load(path: &Path) -> Result<Self, SessionError> {
        let text =
            read_text_bounded(path, MAX_SMALL_FILE_BYTES, "a session file").map_err(|source| {
                SessionError::Read {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        let base = path.parent().unwrap_or_else(|| Path::new("")).to_path_buf();
        Self::from_json(&text, path, &base)
    }

    /// Reads a session from JSON text; `path` names it in errors, `base` is the folder its
    /// relative paths start from.
    ///
    /// # Errors
    /// [`SessionError::Entry`], naming the entry.
    pub fn from_json(text: &str, path: &Path, base: &Path) -> Result<Self, SessionError> {
        let err = |entry: String, message: String| SessionError::Entry {
            path: path.to_path_buf(),
            entry,
            message,
        };
        let raw: RawSession =
            serde_json::from_str(text).map_err(|e| err("the session".into(), format!("{e}")))?;
        let ctx = Resolver { base };
        let field = ctx.field(&raw.field).map_err(|m| err("field".into(), m))?;
        if raw.overhead.is_empty() {
            return Err(err(
                "overhead".into(),
                "no overhead camera: a session needs at least one".into(),
            ));
        }
        let mut overhead: Vec<OverheadEntry> = Vec::new();
        for (i, value) in raw.overhead.iter().enumerate() {
            let name = entry_name("overhead", i, value, "id");
            let e = ctx.overhead(value).map_err(|m| err(name.clone(), m))?;
            if let Some(j) = overhead.iter().position(|o| o.id == e.id) {
                return Err(err(
                    name,
                    format!(
                        "camera id {} is also overhead[{j}]'s: each camera needs its own id",
                        e.id
                    ),
                ));
            }
            overhead.push(e);
        }
        if overhead.len() > 1
            && let Some(i) = overhead
                .iter()
                .position(|o| matches!(o.source, SessionSource::Ssl(_)))
        {
            return Err(err(
                entry_name("overhead", i, &raw.overhead[i], "id"),
                "an SSL-Vision source brings its own cameras (merged by capture time): it is the \
                 session's only overhead entry"
                    .into(),
            ));
        }
        let mut robots: Vec<RobotEntry> = Vec::new();
        for (i, value) in raw.robots.iter().enumerate() {
            let name = entry_name("robots", i, value, "robot_id");
            let r = ctx.robot(value).map_err(|m| err(name.clone(), m))?;
            if let Some(j) = robots
                .iter()
                .position(|o| (o.team, o.robot_id) == (r.team, r.robot_id))
            {
                return Err(err(
                    name,
                    format!(
                        "robot {} {} is also robots[{j}]: each robot wears its own marker",
                        r.team.name(),
                        r.robot_id
                    ),
                ));
            }
            robots.push(r);
        }
        Ok(Self {
            path: path.to_path_buf(),
            field,
            overhead,
            robots,
        })
    }

    /// The camera with `id`.
    #[must_use]
    pub fn camera(&self, id: SslCameraId) -> Option<&OverheadEntry> {
        self.overhead.iter().find(|o| o.id == id)
    }
}

/// `overhead[2] (id 5)`: an entry named by its place and, when it has one, its id.
fn entry_name(list: &str, i: usize, value: &Value, id_key: &str) -> String {
    match value.get(id_key).and_then(Value::as_u64) {
        Some(id) => format!("{list}[{i}] ({id_key} {id})"),
        None => format!("{list}[{i}]"),
    }
}

/// Resolves an entry's paths against the session file's folder and checks them.
struct Resolver<'a> {
    base: &'a Path,
}

impl Resolver<'_> {
    fn field(&self, name: &str) -> Result<FieldRef, String> {
        if let Some((n, _)) = SHIPPED_FIELDS.iter().find(|(n, _)| *n == name) {
            return Ok(FieldRef::Shipped((*n).to_owned()));
        }
        let p = self.base.join(name);
        if p.is_file() {
            return Ok(FieldRef::File(p));
        }
        Err(format!(
            "{}: no such field file, and {name:?} is not a shipped field ({})",
            p.display(),
            shipped_field_names()
        ))
    }

    fn overhead(&self, value: &Value) -> Result<OverheadEntry, String> {
        let raw: RawOverhead = serde_json::from_value(value.clone()).map_err(|e| e.to_string())?;
        let source = self.source(&raw.source)?;
        let ssl = matches!(source, SessionSource::Ssl(_));
        for (key, given) in [("lut", &raw.lut), ("calibration", &raw.calibration)] {
            if given.is_none() && !ssl {
                return Err(format!(
                    "missing field `{key}`: an eotn camera needs its table and calibration (only \
                     an SSL-Vision source, udp:// or a league .log, goes without)"
                ));
            }
        }
        Ok(OverheadEntry {
            id: SslCameraId(raw.id),
            source,
            camera: raw.camera,
            lut: raw
                .lut
                .map(|p| self.file("lut", "lookup table", &p))
                .transpose()?,
            calibration: raw
                .calibration
                .map(|p| self.file("calibration", "calibration", &p))
                .transpose()?,
            intrinsics: raw
                .intrinsics
                .map(|p| self.file("intrinsics", "intrinsics file", &p))
                .transpose()?,
            params: raw
                .params
                .map(|p| self.file("params", "parameter file", &p))
                .transpose()?,
        })
    }

    fn robot(&self, value: &Value) -> Result<RobotEntry, String> {
        let raw: RawRobot = serde_json::from_value(value.clone()).map_err(|e| e.to_string())?;
        let team = MarkerTeam::from_name(&raw.team)
            .ok_or_else(|| format!("team {:?}: must be blue or yellow", raw.team))?;
        let robot_id = MarkerIdentity::new(raw.robot_id).ok_or_else(|| {
            format!(
                "robot_id {}: must be 0-15 (the marker's identity)",
                raw.robot_id
            )
        })?;
        Ok(RobotEntry {
            team,
            robot_id,
            source: self.source(&raw.source)?,
            camera: raw.camera,
            lut: raw
                .lut
                .map(|p| self.file("lut", "lookup table", &p))
                .transpose()?,
            params: raw
                .params
                .map(|p| self.file("params", "parameter file", &p))
                .transpose()?,
        })
    }

    fn source(&self, s: &str) -> Result<SessionSource, String> {
        if s.starts_with("ws://") || s.starts_with("wss://") {
            return Ok(SessionSource::Live(s.to_owned()));
        }
        if s.starts_with("/dev/") {
            return Ok(SessionSource::Device(PathBuf::from(s)));
        }
        if crate::ssl_vision::listener::is_udp_url(s) {
            return Ok(SessionSource::Ssl(SslSource::Udp(s.to_owned())));
        }
        let p = self.base.join(s);
        if p.is_file() && is_log_name(&p) {
            return Ok(SessionSource::Ssl(SslSource::Log(p)));
        }
        if p.exists() {
            Ok(SessionSource::Recording(p))
        } else {
            Err(format!(
                "source {}: no such recording (a source is a recording, a ws:// server, a /dev/video device, udp://GROUP:PORT or an SSL-Vision .log)",
                p.display()
            ))
        }
    }

    /// `key`'s file, which must exist and be a regular file.
    fn file(&self, key: &str, what: &str, p: &Path) -> Result<PathBuf, String> {
        let full = self.base.join(p);
        match std::fs::metadata(&full) {
            Ok(m) if m.is_file() => Ok(full),
            Ok(_) => Err(format!(
                "{key} {}: not a file, so not a {what}",
                full.display()
            )),
            Err(e) => Err(format!("{key} {}: no {what} there ({e})", full.display())),
        }
    }
}

/// A session camera's overhead recogniser settings (its `params` file); unknown keys refused.
///
/// # Errors
/// An unreadable or oversized file, not JSON, not these settings, or an unknown key: each
/// naming the file.
pub fn load_camera_params(path: &Path) -> anyhow::Result<crate::overhead::OverheadParams> {
    use anyhow::Context as _;
    let text = read_text_bounded(path, MAX_SMALL_FILE_BYTES, "overhead parameters")
        .with_context(|| format!("{}", path.display()))?;
    let given: Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let params: crate::overhead::OverheadParams = serde_json::from_value(given.clone())
        .with_context(|| format!("{}: not overhead parameters", path.display()))?;
    let known = serde_json::to_value(params)?;
    if let Some(key) = crate::input_file::unknown_keys(&given, &known).first() {
        anyhow::bail!("{}: unknown key '{key}'", path.display());
    }
    Ok(params)
}
