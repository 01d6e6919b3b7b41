//! The B-Human 2009 message log: 160 camera images of a real Nao on the 2009 SPL field, with
//! joint and sensor records, recorded by B-Human's own software (`logfile.log` of their code
//! release; format in `../shared/data/bhuman2009/README.md`).
//!
//! **Log.** `u32 usedSize`, `u32 numberOfMessages`, then messages of `u8 id`, `u24 size`
//! (little-endian) and the payload. Read here: 4 JPEGImage, 5 JointData (22 `f64` angles in
//! radians, `u32` time), 6 SensorData (18 `f32` readings, 22 `i16` currents, 22 `u8`
//! temperatures, `i32` ultrasound mode, `u32` time), 17 CameraMatrix and 18
//! ImageCoordinateSystem (below), and 1 ProcessBegin, which opens each process's cycle. Others
//! (process end, key states, odometry) are counted and skipped. A truncated log keeps every
//! complete message before the cut, with a warning.
//!
//! **Camera pose.** B-Human's `CameraMatrix` is a `Pose3D` from the robot's ground frame (origin
//! on the ground between the feet, x forward, y left, z up — our robot frame) to the camera (x
//! along the optical axis, y left, z up — our camera frame): 9 `f64` of the rotation matrix
//! column by column (the camera's x, y, z axes in ground coordinates), 3 `f64` of the
//! translation in millimetres, and `isValid` (4 bytes, 0 or 1). The layout was checked against
//! the data: the first column is the optical axis and points 13° down in frame 0, the camera
//! stands 48.5 cm high (42–49 cm over the log: standing, walking, crouching to kick), and the
//! horizon it implies runs where B-Human's own ImageCoordinateSystem record of the same cycle
//! puts it (y = 29.7 at the centre column of frame 0); read row by row instead, the optical
//! axis would point up. The cognition process logs JPEGImage, CameraMatrix and
//! ImageCoordinateSystem in that order within one cycle, so the matrix belongs to the image
//! logged before it since the last ProcessBegin. A valid matrix becomes the frame's
//! `camera_*` readings (position in cm, yaw · pitch · roll); B-Human marks it invalid while the
//! motion is unstable, the robot has fallen or is penalised (frames 138–159 of the log), and
//! their perception then ignores it, so an invalid matrix stays in the raw record only.
//! ImageCoordinateSystem (rotation to the horizon, origin, the offset to the previous image,
//! the read-out scale factors a and b, and the camera info — 320×240, focal length 385.54 px,
//! optical centre (160, 120)) is kept raw.
//!
//! **Images.** The JPEGImage payload is `i32 width` (320), `i32 height` (240), `u32 timeStamp`
//! (ms), `u32 length` and a JPEG with 4 components (Adobe APP14, no colour transform). Each
//! decoded "pixel" is one YUYV macropixel of the camera — Y0, Cb, Y1, Cr. The `image` crate
//! converts 4-component JPEGs to RGB and cannot hand back the four raw channels, so this uses
//! `zune-jpeg` (the decoder `image` itself uses) with CMYK output. Decoders in libjpeg's style
//! return Adobe CMYK channels inverted (255 − v); zune-jpeg's CMYK output is already the values
//! B-Human wrote, checked against their table: as decoded, frame 80 classifies (with one luma
//! per macropixel, as B-Human did) into 49,623 green, 12,339 white and 3,880 orange pixels — their
//! published ~49,600 / 12,300 / 3,900 — while the inverted values give 5,769 green and no orange.
//!
//! **Frames: 320×240 UYVY.** B-Human's camera gave 640×480 YUV 4:2:2; their software kept every
//! second row and treated each macropixel (two camera pixels side by side) as one pixel of a
//! 320×240 image — the image their colour table, camera matrix and the published pixel counts
//! refer to, with square pixels. We keep that grid: output pixel *x* of a row is macropixel *x*,
//! its luma the mean of the macropixel's two lumas, and each UYVY pair's shared chroma the mean
//! of its two macropixels' chroma. That is a plain 2× horizontal downsample of the 640×240
//! 4:2:2 data (luma and chroma halved alike). The alternative, 640×240 with both lumas, keeps
//! every sample but has pixels twice as tall as wide, so every view and the camera model would
//! need an aspect correction, and the stream would be twice as large; the luma detail it keeps
//! is half a macropixel, below what the table's 4-level cells resolve.
//!
//! **Sensors.** Each frame takes the last JointData and SensorData logged before it, except head
//! pan and tilt: those are interpolated at the image's time between the JointData records
//! logged around it. The log keeps about 8 joint records per second, taken up to ±180 ms from
//! its images (the last one before an image is sometimes the previous image's too), so the
//! head's velocity between two images comes out wrong by up to 5× from the last records (frame
//! 63: 10 rad/s of pan instead of 2). Mapped to
//! [`SensorReadings`]: head pan = B-Human's `headPan` (the Nao's HeadYaw, positive left, as
//! ours); head tilt = `headTilt` (B-Human's joint is already positive *up*, the negated
//! HeadPitch of the Nao, as ours: their `CameraMatrixProvider` turns the camera by −`headTilt`
//! and then 40° down, and over this log the camera matrices' pitch is 0.685 − 0.97 · `headTilt`
//! rad, r = −0.98; an earlier version negated it; the Nao has no second tilt joint, so neck
//! tilt stays `None`); previous pan/tilt and the frame
//! interval from the previous image; accelerations = −`acc` × 9.80665 (B-Human logs the gravity
//! direction in g, −1 on z when upright; we store what an accelerometer measures, +9.8 m/s² up
//! when still); body roll = `angleX` and pitch = `angleY` (the Nao's inertial angles: roll
//! positive right side down, pitch positive nose down, as ours); battery = `batteryLevel` ×
//! 100 %. Values of 1000 or 2000 (B-Human's "off"/"ignore") become `None`. Everything else
//! (all 22 joints, gyros, foot pressure, ultrasound, motor temperatures) is kept raw in
//! [`BhumanFrame::raw`].

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::frame::Frame;
use crate::sensors::SensorReadings;

mod jpeg;
mod records;
#[cfg(test)]
mod tests;

pub use jpeg::{JpegImageError, decode_macropixels, macropixels_to_uyvy};
use records::{
    camera_matrix_json, head_at_image_times, image_coordinate_system_json, parse_joints,
    parse_sensors, raw_json,
};
pub use records::{map_sensors, parse_camera_matrix};

/// Message ids of B-Human 2009 (`MessageIDs.h`) that this reader uses.
pub mod ids {
    /// A compressed camera image.
    pub const JPEG_IMAGE: u8 = 4;
    /// Measured joint angles.
    pub const JOINT_DATA: u8 = 5;
    /// Inertial, foot, battery and ultrasound readings.
    pub const SENSOR_DATA: u8 = 6;
    /// The start of a process's cycle (motion or cognition).
    pub const PROCESS_BEGIN: u8 = 1;
    /// The camera's pose over the ground (`Pose3D` + `isValid`).
    pub const CAMERA_MATRIX: u8 = 17;
    /// Horizon-aligned image coordinates, rolling-shutter factors and camera info.
    pub const IMAGE_COORDINATE_SYSTEM: u8 = 18;
}

/// Standard gravity, m/s² (B-Human logs accelerations in g).
pub const G_MPS2: f64 = 9.806_65;

/// B-Human's joint names, in the order of their `JointData::Joint`.
pub const JOINT_NAMES: [&str; 22] = [
    "headPan",
    "headTilt",
    "armLeft0",
    "armLeft1",
    "armLeft2",
    "armLeft3",
    "armRight0",
    "armRight1",
    "armRight2",
    "armRight3",
    "legLeft0",
    "legLeft1",
    "legLeft2",
    "legLeft3",
    "legLeft4",
    "legLeft5",
    "legRight0",
    "legRight1",
    "legRight2",
    "legRight3",
    "legRight4",
    "legRight5",
];

/// B-Human's sensor names, in the order of their `SensorData::Sensor`.
pub const SENSOR_NAMES: [&str; 18] = [
    "gyroX",
    "gyroY",
    "gyroZ",
    "accX",
    "accY",
    "accZ",
    "batteryLevel",
    "fsrLFL",
    "fsrLFR",
    "fsrLBL",
    "fsrLBR",
    "fsrRFL",
    "fsrRFR",
    "fsrRBL",
    "fsrRBR",
    "us",
    "angleX",
    "angleY",
];

/// Why a log could not be read at all (damage after the header only warns).
#[derive(Debug, Error)]
pub enum BhumanError {
    /// Reading the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The file is no B-Human log, or holds no usable image.
    #[error("{path}: {problem}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        #[source]
        problem: LogError,
    },
}

/// Why a log's contents are unusable as a whole.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum LogError {
    /// Fewer bytes than the 8-byte header.
    #[error("{len} bytes is too short for a log header")]
    TooShort {
        /// The log's length, bytes.
        len: usize,
    },
    /// The header is followed by no complete message.
    #[error("no complete message after the header")]
    NoMessage,
    /// No image in the log could be decoded.
    #[error("no decodable camera image in the log ({})", .warnings.join("; "))]
    NoImage {
        /// What was skipped, and why.
        warnings: Vec<String>,
    },
}

/// B-Human's measured joint angles at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct JointRecord {
    /// Angles in radians, [`JOINT_NAMES`] order (1000 = off, 2000 = ignore, as logged).
    pub angles: [f64; 22],
    /// B-Human time, milliseconds since the robot's software started.
    pub time_ms: u32,
}

/// B-Human's sensor readings at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorRecord {
    /// Readings in [`SENSOR_NAMES`] order, B-Human's units (g, rad, fraction, mm; 1000 = off).
    pub data: [f32; 18],
    /// Motor currents, B-Human's raw units, [`JOINT_NAMES`] order.
    pub currents: [i16; 22],
    /// Motor temperatures, °C, [`JOINT_NAMES`] order.
    pub temperatures: [u8; 22],
    /// Ultrasound measuring mode (0 left, 1 left→right, 2 right→left, 3 right).
    pub us_mode: i32,
    /// B-Human time, milliseconds.
    pub time_ms: u32,
}

/// B-Human's camera matrix of one image: the camera's pose in the robot's ground frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraMatrixRecord {
    /// Rotation matrix, column by column: the camera's x (optical axis), y (left) and z (up)
    /// axes in ground coordinates.
    pub rotation_columns: [[f64; 3]; 3],
    /// Camera position in the ground frame, millimetres.
    pub translation_mm: [f64; 3],
    /// B-Human's `isValid`: the motion was stable, the robot upright and not penalised.
    pub is_valid: bool,
}

impl CameraMatrixRecord {
    /// The pose as a transform (centimetres), or `None` when the rotation is not a rotation
    /// (columns not orthonormal within 10⁻³) or a value is not finite.
    #[must_use]
    pub fn field_from_camera(
        &self,
    ) -> Option<crate::geometry::Transform<crate::geometry::Field, crate::geometry::Camera>> {
        use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
        let [x, y, z] = self.rotation_columns;
        let m = Matrix3::from_columns(&[Vector3::from(x), Vector3::from(y), Vector3::from(z)]);
        let t = Vector3::from(self.translation_mm) / 10.0;
        let orthonormal = (m.transpose() * m - Matrix3::identity()).abs().max() < 1e-3
            && (m.determinant() - 1.0).abs() < 1e-3;
        if !(m.iter().all(|v| v.is_finite()) && t.iter().all(|v| v.is_finite()) && orthonormal) {
            return None;
        }
        let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&m));
        Some(crate::geometry::Transform::new(t, rotation))
    }
}

/// One camera frame of the log with the readings that go with it.
#[derive(Debug, Clone)]
pub struct BhumanFrame {
    /// Image time, B-Human milliseconds (since the robot's software started).
    pub time_ms: u32,
    /// The image as 320×240 UYVY (see the module docs).
    pub frame: Frame,
    /// Readings mapped to our schema (with the camera pose when the cycle's camera matrix was
    /// valid).
    pub sensors: SensorReadings,
    /// The camera matrix logged with this image, valid or not.
    pub camera_matrix: Option<CameraMatrixRecord>,
    /// The raw joint and sensor records this frame took its readings from, as JSON.
    pub raw: serde_json::Value,
}

/// Everything read from a log.
#[derive(Debug, Clone, Default)]
pub struct BhumanLog {
    /// The frames in log order.
    pub frames: Vec<BhumanFrame>,
    /// Messages per id, all of them (read or skipped).
    pub message_counts: BTreeMap<u8, usize>,
    /// Problems met and skipped: truncation, undecodable images, odd sizes.
    pub warnings: Vec<String>,
}

/// Reads a B-Human 2009 log file.
///
/// # Errors
/// [`BhumanError`] naming the file when it cannot be read, has no valid header, or holds no
/// decodable image; lesser damage becomes [`BhumanLog::warnings`].
pub fn read_log(path: &Path) -> Result<BhumanLog, BhumanError> {
    let bytes =
        crate::input_file::read_bounded(path, 4 << 30, "a B-Human log").map_err(|source| {
            BhumanError::Io {
                path: path.to_owned(),
                source,
            }
        })?;
    let log = parse_log(&bytes).map_err(|problem| BhumanError::Invalid {
        path: path.to_owned(),
        problem,
    })?;
    if log.frames.is_empty() {
        return Err(BhumanError::Invalid {
            path: path.to_owned(),
            problem: LogError::NoImage {
                warnings: log.warnings,
            },
        });
    }
    Ok(log)
}

/// One message: id and payload.
struct Message<'a> {
    id: u8,
    payload: &'a [u8],
}

/// Splits the log into messages; a cut-off tail becomes a warning.
fn messages<'a>(bytes: &'a [u8], warnings: &mut Vec<String>) -> Result<Vec<Message<'a>>, LogError> {
    let header = bytes
        .get(..8)
        .ok_or(LogError::TooShort { len: bytes.len() })?;
    let used = u32::from_le_bytes([header[0], header[1], header[2], header[3]]) as usize;
    let count = u32::from_le_bytes([header[4], header[5], header[6], header[7]]) as usize;
    if used + 8 != bytes.len() {
        warnings.push(format!(
            "header says {used} bytes of messages, the file has {}",
            bytes.len().saturating_sub(8)
        ));
    }
    let mut out = Vec::with_capacity(count.min(1 << 20));
    let mut pos = 8;
    while pos < bytes.len() {
        let Some(h) = bytes.get(pos..pos + 4) else {
            warnings.push(format!("log cut off inside a message header at byte {pos}"));
            break;
        };
        let size = usize::from(h[1]) | usize::from(h[2]) << 8 | usize::from(h[3]) << 16;
        let Some(payload) = bytes.get(pos + 4..pos + 4 + size) else {
            warnings.push(format!(
                "log cut off at byte {}: message {} (id {}) needs {size} bytes, {} are left",
                bytes.len(),
                out.len(),
                h[0],
                bytes.len() - pos - 4
            ));
            break;
        };
        out.push(Message { id: h[0], payload });
        pos += 4 + size;
    }
    if out.is_empty() {
        return Err(LogError::NoMessage);
    }
    if out.len() != count {
        warnings.push(format!(
            "header says {count} messages, {} were read",
            out.len()
        ));
    }
    Ok(out)
}

/// Parses a whole log held in memory.
///
/// # Errors
/// [`LogError`] when the header is missing or no message is complete; lesser damage (a cut-off
/// tail, a bad image, a malformed record) becomes a warning and the rest is kept.
pub fn parse_log(bytes: &[u8]) -> Result<BhumanLog, LogError> {
    let mut reader = LogReader::default();
    for (index, m) in messages(bytes, &mut reader.log.warnings)?
        .iter()
        .enumerate()
    {
        reader.message(index, m);
    }
    let LogReader {
        mut log,
        mut all_joints,
        ..
    } = reader;
    head_at_image_times(&mut log.frames, &mut all_joints);
    Ok(log)
}

/// The log read so far and the latest records, as the messages are read in order.
#[derive(Default)]
struct LogReader {
    log: BhumanLog,
    /// The latest JointData.
    joints: Option<JointRecord>,
    /// Every JointData, for the head angles at the image times.
    all_joints: Vec<JointRecord>,
    /// The latest SensorData.
    sensors: Option<SensorRecord>,
    /// The frame whose image was logged in the current process cycle (since the last
    /// ProcessBegin): the cycle's camera matrix and coordinate system belong to it.
    cycle_frame: Option<usize>,
}

impl LogReader {
    /// Takes one message (number `index`) into the log.
    fn message(&mut self, index: usize, m: &Message<'_>) {
        *self.log.message_counts.entry(m.id).or_default() += 1;
        match m.id {
            ids::PROCESS_BEGIN => self.cycle_frame = None,
            ids::CAMERA_MATRIX => self.camera_matrix(index, m.payload),
            ids::IMAGE_COORDINATE_SYSTEM => self.image_coordinate_system(index, m.payload),
            ids::JOINT_DATA => match parse_joints(m.payload) {
                Some(j) => {
                    self.all_joints.push(j.clone());
                    self.joints = Some(j);
                }
                None => self.log.warnings.push(format!(
                    "message {index}: JointData of {} bytes, expected 180; skipped",
                    m.payload.len()
                )),
            },
            ids::SENSOR_DATA => match parse_sensors(m.payload) {
                Some(s) => self.sensors = Some(s),
                None => self.log.warnings.push(format!(
                    "message {index}: SensorData of {} bytes, expected 146; skipped",
                    m.payload.len()
                )),
            },
            ids::JPEG_IMAGE => self.jpeg_image(index, m.payload),
            _ => {}
        }
    }

    /// A CameraMatrix: the pose of the cycle's image (its camera pose when valid).
    fn camera_matrix(&mut self, index: usize, payload: &[u8]) {
        let frame = self.cycle_frame.and_then(|i| self.log.frames.get_mut(i));
        match (parse_camera_matrix(payload), frame) {
            (Some(matrix), Some(frame)) if frame.camera_matrix.is_none() => {
                let pose = matrix.field_from_camera();
                if pose.is_none() {
                    self.log.warnings.push(format!(
                        "message {index}: CameraMatrix is not a rotation and a translation; \
                         kept raw only"
                    ));
                }
                if let Some(pose) = pose.filter(|_| matrix.is_valid) {
                    crate::geometry::write_camera_pose(&pose, &mut frame.sensors);
                }
                if let Some(obj) = frame.raw.as_object_mut() {
                    obj.insert("camera_matrix".into(), camera_matrix_json(&matrix));
                }
                frame.camera_matrix = Some(matrix);
            }
            (None, _) => self.log.warnings.push(format!(
                "message {index}: CameraMatrix of {} bytes, expected 100; skipped",
                payload.len()
            )),
            (Some(_), _) => self.log.warnings.push(format!(
                "message {index}: CameraMatrix without an image of its own in its cycle; skipped"
            )),
        }
    }

    /// An ImageCoordinateSystem: kept raw with the cycle's image.
    fn image_coordinate_system(&mut self, index: usize, payload: &[u8]) {
        let json = image_coordinate_system_json(payload);
        let frame = self.cycle_frame.and_then(|i| self.log.frames.get_mut(i));
        match (json, frame) {
            (Some(v), Some(frame)) => {
                if let Some(obj) = frame.raw.as_object_mut() {
                    obj.insert("image_coordinate_system".into(), v);
                }
            }
            (None, _) => self.log.warnings.push(format!(
                "message {index}: ImageCoordinateSystem of {} bytes, expected 160; skipped",
                payload.len()
            )),
            (Some(_), None) => self.log.warnings.push(format!(
                "message {index}: ImageCoordinateSystem without an image in its cycle; skipped"
            )),
        }
    }

    /// A JPEGImage: a new frame with the latest joint and sensor readings.
    fn jpeg_image(&mut self, index: usize, payload: &[u8]) {
        match jpeg::image(payload) {
            Ok((time_ms, frame)) => {
                let sensors = map_sensors(self.joints.as_ref(), self.sensors.as_ref());
                let mut raw = raw_json(self.joints.as_ref(), self.sensors.as_ref());
                if let Some(obj) = raw.as_object_mut() {
                    obj.insert("image_time_ms".into(), time_ms.into());
                }
                self.cycle_frame = Some(self.log.frames.len());
                self.log.frames.push(BhumanFrame {
                    time_ms,
                    frame,
                    sensors,
                    camera_matrix: None,
                    raw,
                });
            }
            Err(problem) => self
                .log
                .warnings
                .push(format!("message {index}: JPEGImage skipped: {problem}")),
        }
    }
}
