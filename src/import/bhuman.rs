//! The B-Human 2009 message log: 160 camera images of a real Nao on the 2009 SPL field, with
//! joint and sensor records, recorded by B-Human's own software (`logfile.log` of their code
//! release; format in `../shared/data/bhuman2009/README.md`).
//!
//! **Log.** `u32 usedSize`, `u32 numberOfMessages`, then messages of `u8 id`, `u24 size`
//! (little-endian) and the payload. Read here: 4 JPEGImage, 5 JointData (22 `f64` angles in
//! radians, `u32` time), 6 SensorData (18 `f32` readings, 22 `i16` currents, 22 `u8`
//! temperatures, `i32` ultrasound mode, `u32` time). Others (process markers, key states,
//! odometry, camera matrix, image coordinate system) are counted and skipped. A truncated log
//! keeps every complete message before the cut, with a warning.
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
//! **Sensors.** Each frame takes the last JointData and SensorData logged before it (the motion
//! process logs them just before the cognition process logs its image). Mapped to
//! [`SensorReadings`]: head pan = B-Human's `headPan` (the Nao's HeadYaw, positive left, as
//! ours); head tilt = −`headTilt` (the Nao's HeadPitch is positive *down*; ours is positive up;
//! the Nao has no second tilt joint, so neck tilt stays `None`); previous pan/tilt and the frame
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

/// One camera frame of the log with the readings that go with it.
#[derive(Debug, Clone)]
pub struct BhumanFrame {
    /// Image time, B-Human milliseconds (since the robot's software started).
    pub time_ms: u32,
    /// The image as 320×240 UYVY (see the module docs).
    pub frame: Frame,
    /// Readings mapped to our schema.
    pub sensors: SensorReadings,
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
    let bytes = std::fs::read(path).map_err(|source| BhumanError::Io {
        path: path.to_owned(),
        source,
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
        r.head_tilt_rad = reading(j.angles[1]).map(|t| -t);
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
    let mut sensors: Option<SensorRecord> = None;
    let mut previous: Option<(u32, SensorReadings)> = None;
    for (index, m) in msgs.iter().enumerate() {
        *log.message_counts.entry(m.id).or_default() += 1;
        match m.id {
            ids::JOINT_DATA => match parse_joints(m.payload) {
                Some(j) => joints = Some(j),
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
                    let mut s = map_sensors(joints.as_ref(), sensors.as_ref());
                    if let Some((t0, prev)) = &previous {
                        s.previous_head_pan_rad = prev.head_pan_rad;
                        s.previous_head_tilt_rad = prev.head_tilt_rad;
                        s.frame_interval_s =
                            (time_ms > *t0).then(|| f64::from(time_ms - t0) / 1000.0);
                    }
                    previous = Some((time_ms, s));
                    let mut raw = raw_json(joints.as_ref(), sensors.as_ref());
                    if let Some(obj) = raw.as_object_mut() {
                        obj.insert("image_time_ms".into(), time_ms.into());
                    }
                    log.frames.push(BhumanFrame {
                        time_ms,
                        frame,
                        sensors: s,
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
    Ok(log)
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
        assert_eq!(r.head_tilt_rad, Some(-0.4));
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
}
