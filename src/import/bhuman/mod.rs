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
        problem: String,
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
            problem: format!(
                "no decodable camera image in the log ({})",
                log.warnings.join("; ")
            ),
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
fn messages<'a>(bytes: &'a [u8], warnings: &mut Vec<String>) -> Result<Vec<Message<'a>>, String> {
    let header = bytes
        .get(..8)
        .ok_or_else(|| format!("{} bytes is too short for a log header", bytes.len()))?;
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
        return Err("no complete message after the header".into());
    }
    if out.len() != count {
        warnings.push(format!(
            "header says {count} messages, {} were read",
            out.len()
        ));
    }
    Ok(out)
}

fn le_u32(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4)
        .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

fn parse_joints(p: &[u8]) -> Option<JointRecord> {
    if p.len() != 22 * 8 + 4 {
        return None;
    }
    let mut angles = [0.0; 22];
    for (i, a) in angles.iter_mut().enumerate() {
        let s = p.get(i * 8..i * 8 + 8)?;
        *a = f64::from_le_bytes(s.try_into().ok()?);
    }
    Some(JointRecord {
        angles,
        time_ms: le_u32(p, 176)?,
    })
}

fn parse_sensors(p: &[u8]) -> Option<SensorRecord> {
    if p.len() != 18 * 4 + 22 * 2 + 22 + 4 + 4 {
        return None;
    }
    let mut data = [0.0f32; 18];
    for (i, d) in data.iter_mut().enumerate() {
        *d = f32::from_bits(le_u32(p, i * 4)?);
    }
    let mut currents = [0i16; 22];
    for (i, c) in currents.iter_mut().enumerate() {
        let s = p.get(72 + i * 2..74 + i * 2)?;
        *c = i16::from_le_bytes([s[0], s[1]]);
    }
    let mut temperatures = [0u8; 22];
    temperatures.copy_from_slice(p.get(116..138)?);
    Some(SensorRecord {
        data,
        currents,
        temperatures,
        us_mode: i32::from_le_bytes(p.get(138..142)?.try_into().ok()?),
        time_ms: le_u32(p, 142)?,
    })
}

fn le_f64(b: &[u8], at: usize) -> Option<f64> {
    Some(f64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// A CameraMatrix payload: 12 `f64` (rotation column by column, translation in mm) and
/// `isValid` (the first byte after them; B-Human writes it as 4 bytes).
#[must_use]
pub fn parse_camera_matrix(p: &[u8]) -> Option<CameraMatrixRecord> {
    if p.len() != 97 && p.len() != 100 {
        return None;
    }
    let v = |i: usize| le_f64(p, i * 8);
    let column = |c: usize| Some([v(3 * c)?, v(3 * c + 1)?, v(3 * c + 2)?]);
    Some(CameraMatrixRecord {
        rotation_columns: [column(0)?, column(1)?, column(2)?],
        translation_mm: [v(9)?, v(10)?, v(11)?],
        is_valid: *p.get(96)? != 0,
    })
}

/// An ImageCoordinateSystem payload (160 bytes) as JSON: the offset to the previous image
/// (rad, about z and y), the read-out factors a and b, and the camera info.
fn image_coordinate_system_json(p: &[u8]) -> Option<serde_json::Value> {
    if p.len() != 160 {
        return None;
    }
    let f = |at: usize| le_f64(p, at);
    let i = |at: usize| Some(i32::from_le_bytes(p.get(at..at + 4)?.try_into().ok()?));
    Some(serde_json::json!({
        "horizon_origin_px": [f(64)?, f(72)?],
        "horizon_direction": [f(0)?, f(8)?],
        "offset_rad": [f(80)?, f(88)?],
        "a": f(96)?,
        "b": f(104)?,
        "resolution": [i(112)?, i(116)?],
        "opening_angle_width_rad": f(120)?,
        "opening_angle_height_rad": f(128)?,
        "focal_length_px": f(136)?,
        "optical_center_px": [f(144)?, f(152)?],
    }))
}

fn camera_matrix_json(m: &CameraMatrixRecord) -> serde_json::Value {
    serde_json::json!({
        "rotation_columns": m.rotation_columns,
        "translation_mm": m.translation_mm,
        "is_valid": m.is_valid,
    })
}

/// Decodes a JPEGImage payload's JPEG to B-Human's macropixels: `width × height` entries of
/// `[Y0, Cb, Y1, Cr]` (zune-jpeg's CMYK output as it comes; see the module docs).
///
/// # Errors
/// A message when the JPEG does not decode or is not 4-component at the given size.
pub fn decode_macropixels(
    jpeg: &[u8],
    width: usize,
    height: usize,
) -> Result<Vec<[u8; 4]>, String> {
    use zune_core::colorspace::ColorSpace;
    use zune_core::options::DecoderOptions;
    let options = DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::CMYK);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(std::io::Cursor::new(jpeg), options);
    decoder
        .decode_headers()
        .map_err(|e| format!("JPEG header: {e:?}"))?;
    let info = decoder.info().ok_or("JPEG header gave no image size")?;
    if (usize::from(info.width), usize::from(info.height)) != (width, height) {
        return Err(format!(
            "JPEG is {}×{}, the message says {width}×{height}",
            info.width, info.height
        ));
    }
    if decoder.input_colorspace() != Some(ColorSpace::CMYK) {
        return Err(format!(
            "JPEG colour space {:?}, expected 4 untransformed components",
            decoder.input_colorspace()
        ));
    }
    let mut out = vec![0u8; width * height * 4];
    decoder
        .decode_into(&mut out)
        .map_err(|e| format!("JPEG data: {e:?}"))?;
    Ok(out
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect())
}

/// Macropixels (`[Y0, Cb, Y1, Cr]`, `width` per row) → a UYVY frame of the same width: pixel
/// *x* takes the mean luma of macropixel *x*; each pair shares the mean chroma of its two.
///
/// # Errors
/// A message when the width is odd or the count does not match.
pub fn macropixels_to_uyvy(mp: &[[u8; 4]], width: usize, height: usize) -> Result<Frame, String> {
    if !width.is_multiple_of(2) || mp.len() != width * height {
        return Err(format!(
            "{} macropixels for {width}×{height} (the width must be even)",
            mp.len()
        ));
    }
    let mean =
        |a: u8, b: u8| u8::try_from((u16::from(a) + u16::from(b)).div_ceil(2)).unwrap_or(u8::MAX);
    let mut data = Vec::with_capacity(width * height * 2);
    for pair in mp.chunks_exact(2) {
        let (a, b) = (pair[0], pair[1]);
        data.extend_from_slice(&[
            mean(a[1], b[1]),
            mean(a[0], a[2]),
            mean(a[3], b[3]),
            mean(b[0], b[2]),
        ]);
    }
    Frame::from_uyvy(width, height, data).map_err(|e| e.to_string())
}

/// A reading B-Human marks as missing (1000 off, 2000 ignore) or non-finite → `None`.
fn reading(v: f64) -> Option<f64> {
    (v.is_finite() && v != 1000.0 && v != 2000.0).then_some(v)
}

/// Our sensor schema from B-Human's records (see the module docs for each mapping).
#[must_use]
pub fn map_sensors(joints: Option<&JointRecord>, sensors: Option<&SensorRecord>) -> SensorReadings {
    let mut r = SensorReadings::default();
    if let Some(j) = joints {
        r.head_pan_rad = reading(j.angles[0]);
        r.head_tilt_rad = reading(j.angles[1]);
    }
    if let Some(s) = sensors {
        let d = |i: usize| reading(f64::from(s.data[i]));
        r.accel_x_mps2 = d(3).map(|a| -a * G_MPS2);
        r.accel_y_mps2 = d(4).map(|a| -a * G_MPS2);
        r.accel_z_mps2 = d(5).map(|a| -a * G_MPS2);
        r.battery_percent = d(6).filter(|b| (0.0..=1.0).contains(b)).map(|b| b * 100.0);
        r.body_roll_rad = d(16);
        r.body_pitch_rad = d(17);
    }
    r
}

fn raw_json(joints: Option<&JointRecord>, sensors: Option<&SensorRecord>) -> serde_json::Value {
    let mut v = serde_json::Map::new();
    if let Some(j) = joints {
        let angles: serde_json::Map<String, serde_json::Value> = JOINT_NAMES
            .iter()
            .zip(j.angles)
            .map(|(n, a)| ((*n).to_owned(), a.into()))
            .collect();
        v.insert("joint_time_ms".into(), j.time_ms.into());
        v.insert("joint_angles_rad".into(), angles.into());
    }
    if let Some(s) = sensors {
        let data: serde_json::Map<String, serde_json::Value> = SENSOR_NAMES
            .iter()
            .zip(s.data)
            .map(|(n, d)| ((*n).to_owned(), f64::from(d).into()))
            .collect();
        v.insert("sensor_time_ms".into(), s.time_ms.into());
        v.insert("sensors".into(), data.into());
        v.insert("motor_currents".into(), s.currents.to_vec().into());
        v.insert(
            "motor_temperatures_c".into(),
            s.temperatures.to_vec().into(),
        );
        v.insert("us_mode".into(), s.us_mode.into());
    }
    v.into()
}

/// Parses a whole log held in memory.
///
/// # Errors
/// A message when the header is missing or no message is complete; lesser damage (a cut-off
/// tail, a bad image, a malformed record) becomes a warning and the rest is kept.
pub fn parse_log(bytes: &[u8]) -> Result<BhumanLog, String> {
    let mut log = BhumanLog::default();
    let msgs = messages(bytes, &mut log.warnings)?;
    let mut joints: Option<JointRecord> = None;
    let mut all_joints: Vec<JointRecord> = Vec::new();
    let mut sensors: Option<SensorRecord> = None;
    // The frame whose image was logged in the current process cycle (since the last
    // ProcessBegin): the cycle's camera matrix and coordinate system belong to it.
    let mut cycle_frame: Option<usize> = None;
    for (index, m) in msgs.iter().enumerate() {
        *log.message_counts.entry(m.id).or_default() += 1;
        match m.id {
            ids::PROCESS_BEGIN => cycle_frame = None,
            ids::CAMERA_MATRIX => {
                let frame = cycle_frame.and_then(|i| log.frames.get_mut(i));
                match (parse_camera_matrix(m.payload), frame) {
                    (Some(matrix), Some(frame)) if frame.camera_matrix.is_none() => {
                        let pose = matrix.field_from_camera();
                        if pose.is_none() {
                            log.warnings.push(format!(
                                "message {index}: CameraMatrix is not a rotation and a \
                                 translation; kept raw only"
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
                    (None, _) => log.warnings.push(format!(
                        "message {index}: CameraMatrix of {} bytes, expected 100; skipped",
                        m.payload.len()
                    )),
                    (Some(_), _) => log.warnings.push(format!(
                        "message {index}: CameraMatrix without an image of its own in its \
                         cycle; skipped"
                    )),
                }
            }
            ids::IMAGE_COORDINATE_SYSTEM => {
                let json = image_coordinate_system_json(m.payload);
                let frame = cycle_frame.and_then(|i| log.frames.get_mut(i));
                match (json, frame) {
                    (Some(v), Some(frame)) => {
                        if let Some(obj) = frame.raw.as_object_mut() {
                            obj.insert("image_coordinate_system".into(), v);
                        }
                    }
                    (None, _) => log.warnings.push(format!(
                        "message {index}: ImageCoordinateSystem of {} bytes, expected 160; \
                         skipped",
                        m.payload.len()
                    )),
                    (Some(_), None) => log.warnings.push(format!(
                        "message {index}: ImageCoordinateSystem without an image in its cycle; \
                         skipped"
                    )),
                }
            }
            ids::JOINT_DATA => match parse_joints(m.payload) {
                Some(j) => {
                    all_joints.push(j.clone());
                    joints = Some(j);
                }
                None => log.warnings.push(format!(
                    "message {index}: JointData of {} bytes, expected 180; skipped",
                    m.payload.len()
                )),
            },
            ids::SENSOR_DATA => match parse_sensors(m.payload) {
                Some(s) => sensors = Some(s),
                None => log.warnings.push(format!(
                    "message {index}: SensorData of {} bytes, expected 146; skipped",
                    m.payload.len()
                )),
            },
            ids::JPEG_IMAGE => match image(m.payload) {
                Ok((time_ms, frame)) => {
                    let s = map_sensors(joints.as_ref(), sensors.as_ref());
                    let mut raw = raw_json(joints.as_ref(), sensors.as_ref());
                    if let Some(obj) = raw.as_object_mut() {
                        obj.insert("image_time_ms".into(), time_ms.into());
                    }
                    cycle_frame = Some(log.frames.len());
                    log.frames.push(BhumanFrame {
                        time_ms,
                        frame,
                        sensors: s,
                        camera_matrix: None,
                        raw,
                    });
                }
                Err(problem) => log
                    .warnings
                    .push(format!("message {index}: JPEGImage skipped: {problem}")),
            },
            _ => {}
        }
    }
    head_at_image_times(&mut log.frames, &mut all_joints);
    Ok(log)
}

/// Head pan and tilt (B-Human's `headPan`, `headTilt`) at time `t_ms`, interpolated between the
/// joint records around it (`joints` sorted by time), and the two records' times; the nearest
/// record's angles outside their span. `None` without a usable record.
fn head_at(joints: &[JointRecord], t_ms: u32) -> Option<((f64, f64), [u32; 2])> {
    let usable: Vec<&JointRecord> = joints
        .iter()
        .filter(|j| reading(j.angles[0]).is_some() && reading(j.angles[1]).is_some())
        .collect();
    let after = usable.partition_point(|j| j.time_ms <= t_ms);
    let (a, b) = match (
        after.checked_sub(1).and_then(|i| usable.get(i)),
        usable.get(after),
    ) {
        (Some(a), Some(b)) => (*a, *b),
        (Some(a), None) => (*a, *a),
        (None, Some(b)) => (*b, *b),
        (None, None) => return None,
    };
    let span = f64::from(b.time_ms.saturating_sub(a.time_ms));
    let f = if span > 0.0 {
        (f64::from(t_ms.saturating_sub(a.time_ms)) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let lerp = |i: usize| a.angles[i] + f * (b.angles[i] - a.angles[i]);
    Some(((lerp(0), lerp(1)), [a.time_ms, b.time_ms]))
}

/// Sets each frame's head pan and tilt to their values at its image's time, interpolated
/// between the joint records logged around it (the log keeps about 8 of them per second, taken
/// up to ±180 ms from its images, so the last one before an image may be far from it, or even
/// the same record as the previous image's), and the previous frame's as the previous values,
/// with the time between the images as the interval.
fn head_at_image_times(frames: &mut [BhumanFrame], joints: &mut [JointRecord]) {
    joints.sort_by_key(|j| j.time_ms);
    let mut previous: Option<(u32, SensorReadings)> = None;
    for f in frames.iter_mut() {
        if let Some(((pan, tilt), [ta, tb])) = head_at(joints, f.time_ms) {
            f.sensors.head_pan_rad = Some(pan);
            f.sensors.head_tilt_rad = Some(tilt);
            if let Some(obj) = f.raw.as_object_mut() {
                obj.insert("head_interpolated_between_ms".into(), vec![ta, tb].into());
            }
        }
        if let Some((t0, prev)) = &previous {
            f.sensors.previous_head_pan_rad = prev.head_pan_rad;
            f.sensors.previous_head_tilt_rad = prev.head_tilt_rad;
            f.sensors.frame_interval_s =
                (f.time_ms > *t0).then(|| f64::from(f.time_ms - t0) / 1000.0);
        }
        previous = Some((f.time_ms, f.sensors));
    }
}

/// Decodes a JPEGImage payload to its time and frame.
fn image(p: &[u8]) -> Result<(u32, Frame), String> {
    let field = |at: usize| le_u32(p, at).ok_or("payload shorter than its 16-byte header");
    let (w, h, time_ms, len) = (field(0)?, field(4)?, field(8)?, field(12)? as usize);
    let (w, h) = (w as usize, h as usize);
    if !(2..=4096).contains(&w) || !(1..=4096).contains(&h) {
        return Err(format!("image size {w}×{h} is not plausible"));
    }
    let jpeg = p
        .get(16..16 + len)
        .ok_or_else(|| format!("JPEG of {len} bytes, the payload has {}", p.len() - 16))?;
    let mp = decode_macropixels(jpeg, w, h)?;
    Ok((time_ms, macropixels_to_uyvy(&mp, w, h)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn macropixels_become_uyvy_with_mean_luma_and_shared_chroma() {
        let mp = [[10, 100, 20, 200], [30, 110, 41, 210]];
        let f = macropixels_to_uyvy(&mp, 2, 1).unwrap();
        assert_eq!(f.data(), &[105, 15, 205, 36]);
        assert!(macropixels_to_uyvy(&mp, 3, 1).is_err());
    }

    #[test]
    fn sensors_map_with_signs_units_and_missing_values() {
        let mut angles = [0.0; 22];
        angles[0] = 0.3;
        angles[1] = 0.4;
        let j = JointRecord { angles, time_ms: 5 };
        let mut data = [0.0f32; 18];
        data[5] = -1.0;
        data[6] = 0.5;
        data[16] = 1000.0;
        data[17] = 0.1;
        let s = SensorRecord {
            data,
            currents: [0; 22],
            temperatures: [0; 22],
            us_mode: 0,
            time_ms: 5,
        };
        let r = map_sensors(Some(&j), Some(&s));
        assert_eq!(r.head_pan_rad, Some(0.3));
        assert_eq!(r.head_tilt_rad, Some(0.4));
        assert!((r.accel_z_mps2.unwrap() - G_MPS2).abs() < 1e-9);
        assert_eq!(r.battery_percent, Some(50.0));
        assert_eq!(r.body_roll_rad, None);
        assert!((r.body_pitch_rad.unwrap() - 0.1).abs() < 1e-6);
        assert_eq!(r.neck_tilt_rad, None);
        assert_eq!(map_sensors(None, None), SensorReadings::default());
    }

    #[test]
    fn damaged_logs_are_errors_or_warnings() {
        assert!(parse_log(&[1, 2, 3]).unwrap_err().contains("too short"));
        // Header + one complete JointData + a cut-off message.
        let mut b = Vec::new();
        b.extend_from_slice(&0u32.to_le_bytes());
        b.extend_from_slice(&2u32.to_le_bytes());
        b.extend_from_slice(&[ids::JOINT_DATA, 180, 0, 0]);
        b.extend_from_slice(&[0u8; 180]);
        b.extend_from_slice(&[ids::JPEG_IMAGE, 100, 0, 0, 1, 2]);
        let log = parse_log(&b).unwrap();
        assert!(log.frames.is_empty());
        assert_eq!(log.message_counts.get(&ids::JOINT_DATA), Some(&1));
        assert!(
            log.warnings.iter().any(|w| w.contains("cut off")),
            "{:?}",
            log.warnings
        );
        // A JPEGImage whose JPEG is garbage is skipped with a warning.
        let mut b = Vec::new();
        b.extend_from_slice(&0u32.to_le_bytes());
        b.extend_from_slice(&1u32.to_le_bytes());
        let mut p = Vec::new();
        for v in [320u32, 240, 7, 4] {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p.extend_from_slice(&[0xff, 0xd8, 0, 0]);
        b.extend_from_slice(&[ids::JPEG_IMAGE, p.len() as u8, 0, 0]);
        b.extend_from_slice(&p);
        let log = parse_log(&b).unwrap();
        assert!(log.frames.is_empty());
        assert!(
            log.warnings.iter().any(|w| w.contains("JPEGImage skipped")),
            "{:?}",
            log.warnings
        );
    }

    fn camera_matrix_payload(columns: [[f64; 3]; 3], t: [f64; 3], valid: bool) -> Vec<u8> {
        let mut p = Vec::new();
        for v in columns.iter().flatten().chain(t.iter()) {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p.extend_from_slice(&u32::from(valid).to_le_bytes());
        p
    }

    #[test]
    fn camera_matrix_parses_column_by_column_into_a_pose_in_centimetres() {
        // Looking 13° down, 48.5 cm up, 5.6 cm ahead of the feet (frame 0 of the log).
        let (s, c) = 13.0_f64.to_radians().sin_cos();
        let columns = [[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]];
        let p = camera_matrix_payload(columns, [56.0, 4.0, 485.0], true);
        assert_eq!(p.len(), 100);
        let m = parse_camera_matrix(&p).expect("parses");
        assert!(m.is_valid);
        assert_eq!(m.rotation_columns, columns);
        let pose = m.field_from_camera().expect("a rotation");
        let o = pose.origin();
        assert!((o.z() - 48.5).abs() < 1e-9 && (o.x() - 5.6).abs() < 1e-9);
        let axis = pose * crate::geometry::Vector::<crate::geometry::Camera>::new(1.0, 0.0, 0.0);
        assert!((axis.coords.z + s).abs() < 1e-9, "{axis:?}");
        let mut r = SensorReadings::default();
        crate::geometry::write_camera_pose(&pose, &mut r);
        assert!((r.camera_pitch_rad.expect("pitch") - 13.0_f64.to_radians()).abs() < 1e-9);
        assert!(r.camera_yaw_rad.expect("yaw").abs() < 1e-9);
        assert!(
            !parse_camera_matrix(&camera_matrix_payload(columns, [0.0; 3], false))
                .expect("parses")
                .is_valid
        );
        // Wrong sizes and non-rotations are refused.
        assert!(parse_camera_matrix(&p[..96]).is_none());
        let skewed = [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let bad = parse_camera_matrix(&camera_matrix_payload(skewed, [0.0; 3], true));
        assert!(bad.expect("parses").field_from_camera().is_none());
        let nan = [[f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let bad = parse_camera_matrix(&camera_matrix_payload(nan, [0.0; 3], true));
        assert!(bad.expect("parses").field_from_camera().is_none());
    }

    #[test]
    fn a_camera_matrix_outside_an_image_cycle_is_a_warning() {
        let columns = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let p = camera_matrix_payload(columns, [0.0, 0.0, 480.0], true);
        let mut b = Vec::new();
        b.extend_from_slice(&0u32.to_le_bytes());
        b.extend_from_slice(&3u32.to_le_bytes());
        b.extend_from_slice(&[ids::PROCESS_BEGIN, 1, 0, 0, 0]);
        b.extend_from_slice(&[ids::CAMERA_MATRIX, p.len() as u8, 0, 0]);
        b.extend_from_slice(&p);
        b.extend_from_slice(&[ids::CAMERA_MATRIX, 3, 0, 0, 1, 2, 3]);
        let log = parse_log(&b).expect("parses");
        assert!(
            log.warnings
                .iter()
                .any(|w| w.contains("without an image of its own")),
            "{:?}",
            log.warnings
        );
        assert!(
            log.warnings.iter().any(|w| w.contains("expected 100")),
            "{:?}",
            log.warnings
        );
    }

    #[test]
    fn head_angles_are_interpolated_at_the_image_time() {
        let record = |time_ms: u32, pan: f64, tilt: f64| {
            let mut angles = [0.0; 22];
            angles[0] = pan;
            angles[1] = tilt;
            JointRecord { angles, time_ms }
        };
        let mut joints = vec![
            record(300, 0.4, -0.2),
            record(100, 0.0, 0.0),
            record(200, 1000.0, 1000.0),
        ];
        joints.sort_by_key(|j| j.time_ms);
        // The record marked "off" (1000) is passed over: 250 ms lies three quarters of the way
        // from 100 to 300 ms.
        let ((pan, tilt), span) = head_at(&joints, 250).expect("records");
        assert_eq!(span, [100, 300]);
        assert!(
            (pan - 0.3).abs() < 1e-12 && (tilt + 0.15).abs() < 1e-12,
            "{pan} {tilt}"
        );
        // Outside the records' span: the nearest one.
        assert_eq!(head_at(&joints, 50).map(|h| h.0), Some((0.0, 0.0)));
        assert_eq!(head_at(&joints, 900).map(|h| h.0), Some((0.4, -0.2)));
        assert_eq!(head_at(&[], 100), None);
        // Frames get those values, the previous frame's as previous, the image interval.
        let frame = |time_ms: u32| BhumanFrame {
            time_ms,
            frame: Frame::from_uyvy(2, 1, vec![128, 16, 128, 16]).expect("frame"),
            sensors: SensorReadings::default(),
            camera_matrix: None,
            raw: serde_json::json!({}),
        };
        let mut frames = vec![frame(150), frame(250)];
        head_at_image_times(&mut frames, &mut joints);
        let s = frames[1].sensors;
        assert_eq!(s.previous_head_pan_rad, frames[0].sensors.head_pan_rad);
        assert!((s.frame_interval_s.expect("interval") - 0.1).abs() < 1e-12);
        assert!((s.head_pan_rad.expect("pan") - 0.3).abs() < 1e-12);
        assert!((frames[0].sensors.head_pan_rad.expect("pan") - 0.1).abs() < 1e-12);
        assert_eq!(frames[0].sensors.frame_interval_s, None);
        assert_eq!(
            frames[1].raw["head_interpolated_between_ms"],
            serde_json::json!([100, 300])
        );
    }
}
