//! ROS 2 messages in CDR (the `cdr` serialisation of rosbag2 and foxglove_bridge), decoded with
//! the `cdr` crate through serde: `sensor_msgs/msg/Image`, `CompressedImage`, `CameraInfo`,
//! `JointState` and `tf2_msgs/msg/TFMessage`.
//!
//! Two guards keep a damaged message from costing more than itself. The `cdr` crate allocates a
//! string's or byte array's claimed length before it reads it, so strings are read here as
//! sequences of bytes (serde caps what it reserves for those), and the one large byte array,
//! the image's `data`, has its length checked against the message before it is read.

use serde::de::{Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};

/// Why a CDR message did not decode.
#[derive(Debug, thiserror::Error)]
pub enum CdrError {
    /// Shorter than the 4-byte encapsulation header, or an unknown representation.
    #[error("not a CDR message (encapsulation header {0:02x?})")]
    Header(Vec<u8>),
    /// A byte array claims more bytes than the message has.
    #[error("'{field}' claims {claimed} bytes, the message has {available} after it")]
    Truncated {
        /// The field.
        field: &'static str,
        /// Bytes claimed.
        claimed: u64,
        /// Bytes left.
        available: u64,
    },
    /// The CDR crate's error (cut off, bad UTF-8, …).
    #[error("{0}")]
    Cdr(#[from] cdr::Error),
}

/// A CDR `string`: read as a byte sequence (so a damaged length cannot allocate gigabytes), its
/// terminating NUL dropped, invalid UTF-8 replaced.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CdrString(pub String);

impl<'de> Deserialize<'de> for CdrString {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Bytes;
        impl<'de> Visitor<'de> for Bytes {
            type Value = Vec<u8>;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a CDR string")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<u8>, A::Error> {
                // At most 4 KiB reserved whatever the length claims; the rest as it is read.
                let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(4096));
                while let Some(b) = seq.next_element::<u8>()? {
                    out.push(b);
                }
                Ok(out)
            }
        }
        let mut bytes = deserializer.deserialize_seq(Bytes)?;
        if bytes.last() == Some(&0) {
            bytes.pop();
        }
        Ok(Self(String::from_utf8_lossy(&bytes).into_owned()))
    }
}

impl Serialize for CdrString {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.0)
    }
}

/// `builtin_interfaces/Time`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, 0..1e9.
    pub nanosec: u32,
}

impl Time {
    /// Nanoseconds since the epoch (or the recording's start); `None` before it or for zero.
    #[must_use]
    pub fn as_ns(self) -> Option<u64> {
        let sec = u64::try_from(self.sec).ok()?;
        let ns = sec
            .checked_mul(1_000_000_000)?
            .checked_add(u64::from(self.nanosec))?;
        (ns > 0).then_some(ns)
    }
}

/// `std_msgs/Header`.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Header {
    /// Capture time.
    pub stamp: Time,
    /// The coordinate frame of the data (`camera_optical_frame`, …).
    pub frame_id: CdrString,
}

/// The fields of `sensor_msgs/msg/Image` up to its `data`'s claimed length, read by the same
/// deserialiser (so strings without their NUL or with invalid UTF-8 cannot shift it).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ImageHead {
    /// Header.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding (`rgb8`, `yuv422_yuy2`, …).
    pub encoding: CdrString,
    /// 1 when multi-byte samples are big-endian.
    pub is_bigendian: u8,
    /// Bytes a row, padding included.
    pub step: u32,
    /// How many pixel bytes the message claims to hold.
    pub data_len: u32,
}

/// `sensor_msgs/msg/Image` (CDR has no field names, so [`ImageHead`]'s fields are repeated here
/// rather than flattened: serde's `flatten` needs a self-describing format).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Image {
    /// Header.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding (`rgb8`, `yuv422_yuy2`, …).
    pub encoding: CdrString,
    /// 1 when multi-byte samples are big-endian.
    pub is_bigendian: u8,
    /// Bytes a row, padding included.
    pub step: u32,
    /// The pixels.
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
}

/// The fields of `sensor_msgs/msg/CompressedImage` up to its `data`'s claimed length.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CompressedImageHead {
    /// Header.
    pub header: Header,
    /// `jpeg`, `png`, or image_transport's `bgr8; jpeg compressed bgr8`.
    pub format: CdrString,
    /// How many compressed bytes the message claims to hold.
    pub data_len: u32,
}

/// `sensor_msgs/msg/CompressedImage`.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CompressedImage {
    /// Header.
    pub header: Header,
    /// `jpeg`, `png`, or image_transport's `bgr8; jpeg compressed bgr8`.
    pub format: CdrString,
    /// The compressed bytes.
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
}

/// `sensor_msgs/msg/RegionOfInterest`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RegionOfInterest {
    /// Left edge, pixels.
    pub x_offset: u32,
    /// Top edge, pixels.
    pub y_offset: u32,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Whether the region is rectified.
    pub do_rectify: bool,
}

/// `sensor_msgs/msg/CameraInfo`: the camera's intrinsics.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CameraInfo {
    /// Header.
    pub header: Header,
    /// Rows of the calibrated image.
    pub height: u32,
    /// Columns of the calibrated image.
    pub width: u32,
    /// `plumb_bob`, `rational_polynomial`, …
    pub distortion_model: CdrString,
    /// Distortion coefficients.
    pub d: Vec<f64>,
    /// Intrinsic matrix, row-major: fx 0 cx / 0 fy cy / 0 0 1 (pixels).
    pub k: [f64; 9],
    /// Rectification rotation, row-major.
    pub r: [f64; 9],
    /// Projection matrix, row-major 3×4.
    pub p: [f64; 12],
    /// Horizontal binning.
    pub binning_x: u32,
    /// Vertical binning.
    pub binning_y: u32,
    /// Region of interest.
    pub roi: RegionOfInterest,
}

/// `sensor_msgs/msg/JointState`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct JointState {
    /// Header.
    pub header: Header,
    /// Joint names.
    pub name: Vec<CdrString>,
    /// Positions, radians (or metres for prismatic joints).
    pub position: Vec<f64>,
    /// Velocities.
    pub velocity: Vec<f64>,
    /// Efforts.
    pub effort: Vec<f64>,
}

/// `geometry_msgs/Vector3`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x, metres.
    pub x: f64,
    /// y, metres.
    pub y: f64,
    /// z, metres.
    pub z: f64,
}

/// `geometry_msgs/Quaternion`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

/// `geometry_msgs/Transform`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Translation, metres.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/TransformStamped`: the pose of `child_frame_id` in `header.frame_id`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Header (the parent frame).
    pub header: Header,
    /// The child frame.
    pub child_frame_id: CdrString,
    /// The child's pose in the parent.
    pub transform: Transform,
}

/// `tf2_msgs/msg/TFMessage`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

/// Decodes a CDR message of type `T` (encapsulation header checked).
///
/// # Errors
/// [`CdrError`] when the bytes are not such a message.
pub fn decode<'de, T: Deserialize<'de>>(bytes: &[u8]) -> Result<T, CdrError> {
    check_header(bytes)?;
    Ok(cdr::deserialize::<T>(bytes)?)
}

fn check_header(bytes: &[u8]) -> Result<bool, CdrError> {
    match bytes.get(..4) {
        Some([0, 0 | 2, _, _]) => Ok(false),
        Some([0, 1 | 3, _, _]) => Ok(true),
        _ => Err(CdrError::Header(bytes.iter().take(4).copied().collect())),
    }
}

/// Checks a byte array's claimed length against the message's size before the array is read
/// (the `cdr` crate allocates a claimed length before reading it).
fn check_claimed_bytes(bytes: &[u8], claimed: u32, field: &'static str) -> Result<(), CdrError> {
    let available = bytes.len().saturating_sub(4) as u64;
    if u64::from(claimed) > available {
        return Err(CdrError::Truncated {
            field,
            claimed: u64::from(claimed),
            available,
        });
    }
    Ok(())
}

/// Decodes a `sensor_msgs/msg/Image`, its pixel bytes read once.
///
/// # Errors
/// [`CdrError`] when the bytes are not such a message.
pub fn decode_image(bytes: &[u8]) -> Result<Image, CdrError> {
    let head: ImageHead = decode(bytes)?;
    check_claimed_bytes(bytes, head.data_len, "data")?;
    decode(bytes)
}

/// Decodes a `sensor_msgs/msg/CompressedImage`.
///
/// # Errors
/// [`CdrError`] when the bytes are not such a message.
pub fn decode_compressed_image(bytes: &[u8]) -> Result<CompressedImage, CdrError> {
    let head: CompressedImageHead = decode(bytes)?;
    check_claimed_bytes(bytes, head.data_len, "data")?;
    decode(bytes)
}

/// Encodes a message as little-endian CDR (tests and tools; eotn stores messages as they came).
///
/// # Errors
/// [`CdrError`] from the serialiser.
pub fn encode<T: Serialize>(value: &T) -> Result<Vec<u8>, CdrError> {
    Ok(cdr::serialize::<_, _, cdr::CdrLe>(value, cdr::Infinite)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, encoding: &str, data: Vec<u8>) -> Image {
        Image {
            header: Header {
                stamp: Time { sec: 3, nanosec: 7 },
                frame_id: CdrString("cam_optical_frame".into()),
            },
            height: h,
            width: w,
            encoding: CdrString(encoding.into()),
            is_bigendian: 0,
            step: w * 2,
            data,
        }
    }

    #[test]
    fn the_documented_layout_decodes() {
        // A 2×1 yuv422 image written by hand (offsets aligned relative to byte 4).
        let mut b = vec![0, 1, 0, 0];
        b.extend_from_slice(&3i32.to_le_bytes());
        b.extend_from_slice(&7u32.to_le_bytes());
        b.extend_from_slice(&2u32.to_le_bytes());
        b.extend_from_slice(b"c\0\0\0");
        b.extend_from_slice(&1u32.to_le_bytes());
        b.extend_from_slice(&2u32.to_le_bytes());
        b.extend_from_slice(&7u32.to_le_bytes());
        // "yuv422" and its NUL end at byte 35; the u8 `is_bigendian` needs no padding.
        b.extend_from_slice(b"yuv422\0");
        b.push(0);
        b.extend_from_slice(&4u32.to_le_bytes());
        b.extend_from_slice(&4u32.to_le_bytes());
        b.extend_from_slice(&[1, 2, 3, 4]);
        let img = decode_image(&b).unwrap();
        assert_eq!(img, {
            let mut i = image(2, 1, "yuv422", vec![1, 2, 3, 4]);
            i.header.frame_id = CdrString("c".into());
            i
        });
        assert_eq!(img.header.stamp.as_ns(), Some(3_000_000_007));
        assert_eq!(encode(&img).unwrap(), b);
    }

    #[test]
    fn every_message_round_trips() {
        let ci = CameraInfo {
            width: 640,
            height: 480,
            distortion_model: CdrString("plumb_bob".into()),
            d: vec![0.1, -0.2, 0.0, 0.0, 0.0],
            k: [500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0],
            ..CameraInfo::default()
        };
        assert_eq!(decode::<CameraInfo>(&encode(&ci).unwrap()).unwrap(), ci);
        let js = JointState {
            name: vec![CdrString("HeadYaw".into()), CdrString("HeadPitch".into())],
            position: vec![0.25, -0.5],
            ..JointState::default()
        };
        assert_eq!(decode::<JointState>(&encode(&js).unwrap()).unwrap(), js);
        let tf = TfMessage {
            transforms: vec![TransformStamped {
                child_frame_id: CdrString("camera".into()),
                transform: Transform {
                    translation: Vector3 {
                        x: 0.1,
                        y: 0.0,
                        z: 0.5,
                    },
                    rotation: Quaternion {
                        w: 1.0,
                        ..Quaternion::default()
                    },
                },
                ..TransformStamped::default()
            }],
        };
        assert_eq!(decode::<TfMessage>(&encode(&tf).unwrap()).unwrap(), tf);
        let c = CompressedImage {
            format: CdrString("jpeg".into()),
            data: vec![0xff, 0xd8, 0xff],
            ..CompressedImage::default()
        };
        assert_eq!(decode_compressed_image(&encode(&c).unwrap()).unwrap(), c);
    }

    #[test]
    fn damaged_lengths_are_errors_without_huge_allocations() {
        let good = encode(&image(2, 1, "uyvy", vec![1, 2, 3, 4])).unwrap();
        // The data length (last field before the 4 pixel bytes) claims 4 GB.
        let mut huge = good.clone();
        let at = huge.len() - 8;
        huge[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(
            decode_image(&huge),
            Err(CdrError::Truncated { .. })
        ));
        // The frame_id length claims 4 GB: read byte by byte, it runs out of message.
        let mut name = good.clone();
        name[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode_image(&name).is_err());
        for cut in 0..good.len() {
            assert!(decode_image(&good[..cut]).is_err(), "cut at {cut}");
        }
        // A frame_id without its NUL: the data length is still the one the message claims
        // (the fuzzer's case: a re-serialised head put the length 4 bytes further on).
        let no_nul = CompressedImage {
            header: Header {
                stamp: Time { sec: 1, nanosec: 2 },
                frame_id: CdrString("cam".into()),
            },
            format: CdrString("\u{4}".into()),
            data: vec![7; 8],
        };
        let mut b = encode(&no_nul).unwrap();
        b[19] = 8; // "cam\0" → "cam\x08"
        let at = b.len() - 12;
        b[at..at + 4].copy_from_slice(&0xff00_0005_u32.to_le_bytes());
        assert!(matches!(
            decode_compressed_image(&b),
            Err(CdrError::Truncated { .. })
        ));
        assert!(matches!(
            decode_image(b"\x00\x07\x00\x00"),
            Err(CdrError::Header(_))
        ));
    }

    #[test]
    fn big_endian_messages_decode_too() {
        let img = image(2, 1, "uyvy", vec![9, 8, 7, 6]);
        let be = cdr::serialize::<_, _, cdr::CdrBe>(&img, cdr::Infinite).unwrap();
        assert_eq!(decode_image(&be).unwrap(), img);
    }
}
