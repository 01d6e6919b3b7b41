//! One decoder per message type, shared by the MCAP reader, the rosbag2 reader and the live
//! client: a channel is told by its schema name and message encoding ([`MessageKind::of`]), and
//! its messages decode the same wherever they came from.
//!
//! | schema (encoding) | what it gives |
//! |---|---|
//! | `foxglove.RawImage` (protobuf), `sensor_msgs/msg/Image` (cdr) | a frame ([`ImageMessage`]) |
//! | `foxglove.CompressedImage` (protobuf), `sensor_msgs/msg/CompressedImage` (cdr) | a frame (JPEG, PNG) |
//! | `sensor_msgs/msg/CameraInfo` (cdr), `foxglove.CameraCalibration` (protobuf) | the camera's intrinsics ([`CameraIntrinsics`]) |
//! | `sensor_msgs/msg/JointState` (cdr) | joint positions by name ([`joint_positions`]) |
//! | `tf2_msgs/msg/TFMessage` (cdr) on `/tf`, `/tf_static` | the camera's pose over the ground ([`tf`]) |
//!
//! An image message is kept as it came ([`ImageMessage`]: size, encoding, step and bytes, or the
//! compressed bytes and their format) and becomes a frame only when read
//! ([`ImageMessage::into_frame`]), so `eotn import` stores it unchanged.

pub mod ros2;
pub mod tf;

use foxglove::Decode as _;

use crate::frame::{
    CompressedImageError, Frame, PixelEncoding, RawImage, RawImageError, decode_compressed,
    decode_raw_owned,
};
use crate::sensors::SensorReadings;

/// What a channel carries, told by its schema name and message encoding.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MessageKind {
    /// `foxglove.RawImage`, protobuf.
    FoxgloveRawImage,
    /// `foxglove.CompressedImage`, protobuf.
    FoxgloveCompressedImage,
    /// `sensor_msgs/msg/Image`, CDR.
    RosImage,
    /// `sensor_msgs/msg/CompressedImage`, CDR.
    RosCompressedImage,
    /// `sensor_msgs/msg/CameraInfo`, CDR.
    RosCameraInfo,
    /// `foxglove.CameraCalibration`, protobuf.
    FoxgloveCameraCalibration,
    /// `sensor_msgs/msg/JointState`, CDR.
    RosJointState,
    /// `tf2_msgs/msg/TFMessage`, CDR.
    RosTf,
}

impl MessageKind {
    /// The message types eotn reads, for messages that list them.
    pub const NAMES: &'static str = "foxglove.RawImage, foxglove.CompressedImage, \
        foxglove.CameraCalibration (protobuf); sensor_msgs/msg/Image, \
        sensor_msgs/msg/CompressedImage, sensor_msgs/msg/CameraInfo, sensor_msgs/msg/JointState, \
        tf2_msgs/msg/TFMessage (cdr); JSON channels";

    /// The kind of a channel with this schema name (or ROS type) and message encoding, if eotn
    /// reads it. ROS 1 spellings (`sensor_msgs/Image`) are accepted for the type name.
    #[must_use]
    pub fn of(schema_name: &str, message_encoding: &str) -> Option<Self> {
        let ros = schema_name.replace("/msg/", "/");
        match (message_encoding, schema_name, ros.as_str()) {
            ("protobuf", "foxglove.RawImage", _) => Some(Self::FoxgloveRawImage),
            ("protobuf", "foxglove.CompressedImage", _) => Some(Self::FoxgloveCompressedImage),
            ("protobuf", "foxglove.CameraCalibration", _) => Some(Self::FoxgloveCameraCalibration),
            ("cdr", _, "sensor_msgs/Image") => Some(Self::RosImage),
            ("cdr", _, "sensor_msgs/CompressedImage") => Some(Self::RosCompressedImage),
            ("cdr", _, "sensor_msgs/CameraInfo") => Some(Self::RosCameraInfo),
            ("cdr", _, "sensor_msgs/JointState") => Some(Self::RosJointState),
            ("cdr", _, "tf2_msgs/TFMessage") => Some(Self::RosTf),
            _ => None,
        }
    }

    /// True for the camera image kinds.
    #[must_use]
    pub const fn is_image(self) -> bool {
        matches!(
            self,
            Self::FoxgloveRawImage
                | Self::FoxgloveCompressedImage
                | Self::RosImage
                | Self::RosCompressedImage
        )
    }

    /// The schema name as the message's world spells it.
    #[must_use]
    pub const fn schema_name(self) -> &'static str {
        match self {
            Self::FoxgloveRawImage => "foxglove.RawImage",
            Self::FoxgloveCompressedImage => "foxglove.CompressedImage",
            Self::FoxgloveCameraCalibration => "foxglove.CameraCalibration",
            Self::RosImage => "sensor_msgs/msg/Image",
            Self::RosCompressedImage => "sensor_msgs/msg/CompressedImage",
            Self::RosCameraInfo => "sensor_msgs/msg/CameraInfo",
            Self::RosJointState => "sensor_msgs/msg/JointState",
            Self::RosTf => "tf2_msgs/msg/TFMessage",
        }
    }
}

/// Why one message did not decode (it costs that message only).
#[derive(Debug, thiserror::Error)]
pub enum MessageError {
    /// Not a protobuf message of the schema.
    #[error("not a {schema}: {detail}")]
    Protobuf {
        /// The schema.
        schema: &'static str,
        /// The decoder's words.
        detail: String,
    },
    /// Not a CDR message of the type.
    #[error("not a {schema}: {source}")]
    Cdr {
        /// The type.
        schema: &'static str,
        /// The decoder's error.
        source: ros2::CdrError,
    },
    /// A kind that is not an image was asked for a frame.
    #[error("{0} is not an image")]
    NotAnImage(&'static str),
    /// The raw pixels do not make a frame.
    #[error(transparent)]
    Raw(#[from] RawImageError),
    /// The compressed bytes do not make a frame.
    #[error(transparent)]
    Compressed(#[from] CompressedImageError),
}

/// An image message's pixels as they came.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ImageBody {
    /// Raw pixels.
    Raw {
        /// Width, pixels.
        width: u32,
        /// Height, pixels.
        height: u32,
        /// The `encoding` field, as written.
        encoding: String,
        /// Bytes a row, padding included.
        step: u32,
        /// The pixels.
        data: Vec<u8>,
    },
    /// Compressed bytes.
    Compressed {
        /// The `format` field, as written.
        format: String,
        /// The bytes.
        data: Vec<u8>,
    },
}

/// One camera image message, decoded from its wire format but not yet into a frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImageMessage {
    /// The capture time it carries, nanoseconds (Unix epoch or the recording's start), if any.
    pub timestamp_ns: Option<u64>,
    /// Its coordinate frame (`camera_optical_frame`, …), empty when none.
    pub frame_id: String,
    /// The pixels.
    pub body: ImageBody,
}

impl ImageMessage {
    /// Decodes a message of an image `kind`.
    ///
    /// # Errors
    /// [`MessageError`] when the bytes are not such a message, or `kind` is no image.
    pub fn decode(kind: MessageKind, bytes: &[u8]) -> Result<Self, MessageError> {
        let protobuf = |detail: String| MessageError::Protobuf {
            schema: kind.schema_name(),
            detail,
        };
        let cdr = |source| MessageError::Cdr {
            schema: kind.schema_name(),
            source,
        };
        let foxglove_time = |t: Option<foxglove::messages::Timestamp>| {
            t.map(|t| t.total_nanos()).filter(|&t| t > 0)
        };
        Ok(match kind {
            MessageKind::FoxgloveRawImage => {
                let m = foxglove::messages::RawImage::decode(bytes)
                    .map_err(|e| protobuf(e.to_string()))?;
                Self {
                    timestamp_ns: foxglove_time(m.timestamp),
                    frame_id: m.frame_id,
                    body: ImageBody::Raw {
                        width: m.width,
                        height: m.height,
                        encoding: m.encoding,
                        step: m.step,
                        data: m.data.into(),
                    },
                }
            }
            MessageKind::FoxgloveCompressedImage => {
                let m = foxglove::messages::CompressedImage::decode(bytes)
                    .map_err(|e| protobuf(e.to_string()))?;
                Self {
                    timestamp_ns: foxglove_time(m.timestamp),
                    frame_id: m.frame_id,
                    body: ImageBody::Compressed {
                        format: m.format,
                        data: m.data.into(),
                    },
                }
            }
            MessageKind::RosImage => {
                let m = ros2::decode_image(bytes).map_err(cdr)?;
                Self {
                    timestamp_ns: m.header.stamp.as_ns(),
                    frame_id: m.header.frame_id.0,
                    body: ImageBody::Raw {
                        width: m.width,
                        height: m.height,
                        encoding: m.encoding.0,
                        step: m.step,
                        data: m.data,
                    },
                }
            }
            MessageKind::RosCompressedImage => {
                let m = ros2::decode_compressed_image(bytes).map_err(cdr)?;
                Self {
                    timestamp_ns: m.header.stamp.as_ns(),
                    frame_id: m.header.frame_id.0,
                    body: ImageBody::Compressed {
                        format: m.format.0,
                        data: m.data,
                    },
                }
            }
            other => return Err(MessageError::NotAnImage(other.schema_name())),
        })
    }

    /// The encoding (raw) or format (compressed), as written.
    #[must_use]
    pub fn encoding(&self) -> &str {
        match &self.body {
            ImageBody::Raw { encoding, .. } => encoding,
            ImageBody::Compressed { format, .. } => format,
        }
    }

    /// True when the frame will be grey (`mono8`): a colour table cannot classify it.
    #[must_use]
    pub fn is_grey(&self) -> bool {
        matches!(&self.body, ImageBody::Raw { encoding, .. }
            if PixelEncoding::from_name(encoding).is_some_and(PixelEncoding::is_grey))
    }

    /// The frame, converting the pixels into the tables' YUV; the buffer of unpadded 4:2:2
    /// pixels becomes the frame's without a copy.
    ///
    /// # Errors
    /// [`MessageError`] for an unknown encoding or format, or pixels that do not fit the size.
    pub fn into_frame(self) -> Result<Frame, MessageError> {
        match self.body {
            ImageBody::Raw {
                width,
                height,
                encoding,
                step,
                data,
            } => {
                let Some(known) = PixelEncoding::from_name(&encoding) else {
                    return Err(RawImageError::UnknownEncoding(encoding).into());
                };
                Ok(decode_raw_owned(
                    known,
                    width as usize,
                    height as usize,
                    step as usize,
                    data,
                )?)
            }
            ImageBody::Compressed { format, data } => Ok(decode_compressed(&format, &data)?),
        }
    }

    /// The frame, leaving the message as it is.
    ///
    /// # Errors
    /// As [`ImageMessage::into_frame`].
    pub fn to_frame(&self) -> Result<Frame, MessageError> {
        match &self.body {
            ImageBody::Raw {
                width,
                height,
                encoding,
                step,
                data,
            } => Ok(crate::frame::decode_raw(&RawImage {
                width: *width as usize,
                height: *height as usize,
                encoding,
                step: *step as usize,
                data,
            })?),
            ImageBody::Compressed { format, data } => Ok(decode_compressed(format, data)?),
        }
    }

    /// The message as a Foxglove message, unchanged in its pixels: `foxglove.RawImage` for raw
    /// pixels (same encoding, step and bytes), `foxglove.CompressedImage` for compressed ones.
    /// Returns the schema's kind and appends the protobuf bytes to `out`.
    ///
    /// # Errors
    /// The protobuf encoder's words.
    pub fn encode_foxglove(&self, out: &mut Vec<u8>) -> Result<MessageKind, String> {
        use foxglove::Encode as _;
        let timestamp = self.timestamp_ns.map(|ns| {
            foxglove::messages::Timestamp::new(
                u32::try_from(ns / 1_000_000_000).unwrap_or(u32::MAX),
                u32::try_from(ns % 1_000_000_000).unwrap_or(0),
            )
        });
        match &self.body {
            ImageBody::Raw {
                width,
                height,
                encoding,
                step,
                data,
            } => {
                let m = foxglove::messages::RawImage {
                    timestamp,
                    frame_id: self.frame_id.clone(),
                    width: *width,
                    height: *height,
                    encoding: encoding.clone(),
                    step: *step,
                    data: data.clone().into(),
                };
                m.encode(out).map_err(|e| e.to_string())?;
                Ok(MessageKind::FoxgloveRawImage)
            }
            ImageBody::Compressed { format, data } => {
                let m = foxglove::messages::CompressedImage {
                    timestamp,
                    frame_id: self.frame_id.clone(),
                    data: data.clone().into(),
                    format: format.clone(),
                };
                m.encode(out).map_err(|e| e.to_string())?;
                Ok(MessageKind::FoxgloveCompressedImage)
            }
        }
    }
}

/// A camera-info message as it came — `sensor_msgs/msg/CameraInfo` or
/// `foxglove.CameraCalibration` —, with its lens: what `eotn overhead calibrate --intrinsics`
/// takes from a recording (the frames' [`CameraIntrinsics`] keep only the pinhole part).
#[derive(Debug, Clone, PartialEq)]
pub struct CameraInfoMessage {
    /// The image size it was calibrated at, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Its frame id (the camera's name where nothing else names it).
    pub frame_id: String,
    /// `fx 0 cx / 0 fy cy / 0 0 1`, row-major, pixels (pixel centres at whole numbers).
    pub k: [f64; 9],
    /// `plumb_bob`, `rational_polynomial`, `equidistant`, …
    pub distortion_model: String,
    /// The distortion coefficients in the model's order.
    pub d: Vec<f64>,
}

impl CameraInfoMessage {
    /// Decodes a camera-info message of `kind`.
    ///
    /// # Errors
    /// [`MessageError`] when the bytes are not such a message, its matrix does not have 9
    /// values, or `kind` is no camera info.
    pub fn decode(kind: MessageKind, bytes: &[u8]) -> Result<Self, MessageError> {
        match kind {
            MessageKind::RosCameraInfo => {
                let m: ros2::CameraInfo =
                    ros2::decode(bytes).map_err(|source| MessageError::Cdr {
                        schema: kind.schema_name(),
                        source,
                    })?;
                Ok(Self {
                    width: m.width,
                    height: m.height,
                    frame_id: m.header.frame_id.0,
                    k: m.k,
                    distortion_model: m.distortion_model.0,
                    d: m.d,
                })
            }
            MessageKind::FoxgloveCameraCalibration => {
                let protobuf = |detail: String| MessageError::Protobuf {
                    schema: kind.schema_name(),
                    detail,
                };
                let m = foxglove::messages::CameraCalibration::decode(bytes)
                    .map_err(|e| protobuf(e.to_string()))?;
                let k: [f64; 9] = m
                    .k
                    .try_into()
                    .map_err(|k: Vec<f64>| protobuf(format!("K has {} values, not 9", k.len())))?;
                Ok(Self {
                    width: m.width,
                    height: m.height,
                    frame_id: m.frame_id,
                    k,
                    distortion_model: m.distortion_model,
                    d: m.d,
                })
            }
            other => Err(MessageError::NotAnImage(other.schema_name())),
        }
    }
}

/// A camera's intrinsics from `CameraInfo` / `CameraCalibration`, pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraIntrinsics {
    /// Image width the calibration is for, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
}

impl CameraIntrinsics {
    /// Decodes a camera-info message of `kind`; `None` inside when its matrix is all zeros (an
    /// uncalibrated camera).
    ///
    /// # Errors
    /// [`MessageError`] when the bytes are not such a message.
    pub fn decode(kind: MessageKind, bytes: &[u8]) -> Result<Option<Self>, MessageError> {
        let (width, height, k) = match kind {
            MessageKind::RosCameraInfo => {
                let m: ros2::CameraInfo =
                    ros2::decode(bytes).map_err(|source| MessageError::Cdr {
                        schema: kind.schema_name(),
                        source,
                    })?;
                (m.width, m.height, m.k.to_vec())
            }
            MessageKind::FoxgloveCameraCalibration => {
                let m = foxglove::messages::CameraCalibration::decode(bytes).map_err(|e| {
                    MessageError::Protobuf {
                        schema: kind.schema_name(),
                        detail: e.to_string(),
                    }
                })?;
                (m.width, m.height, m.k)
            }
            other => return Err(MessageError::NotAnImage(other.schema_name())),
        };
        let get = |i: usize| k.get(i).copied().unwrap_or(0.0);
        let (fx, fy, cx, cy) = (get(0), get(4), get(2), get(5));
        let usable = [fx, fy, cx, cy].iter().all(|v| v.is_finite()) && fx > 0.0 && fy > 0.0;
        Ok(usable.then_some(Self {
            width,
            height,
            fx,
            fy,
            cx,
            cy,
        }))
    }

    /// As JSON, for the frame's channels (`fx`, `fy`, `cx`, `cy` in pixels).
    #[must_use]
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "width": self.width, "height": self.height,
            "fx": self.fx, "fy": self.fy, "cx": self.cx, "cy": self.cy,
        })
    }

    /// Puts this calibration into the readings of a `width`×`height` frame (focal length and
    /// optical centre, scaled when the calibration was made at another size), where the readings
    /// have none of their own; recognition then uses this camera. False when the calibration
    /// gives no usable focal length.
    pub fn fill_readings(&self, width: usize, height: usize, s: &mut SensorReadings) -> bool {
        if s.camera_focal_px.is_some() {
            return false;
        }
        let scale = |frame: usize, calibrated: u32| {
            if calibrated == 0 {
                1.0
            } else {
                frame as f64 / f64::from(calibrated)
            }
        };
        let (sx, sy) = (scale(width, self.width), scale(height, self.height));
        let focal = self.fx * sx;
        if !(focal.is_finite() && focal > 0.0 && focal <= 1e5) {
            return false;
        }
        let centre = |c: f64, s: f64| Some(c * s).filter(|v| v.is_finite() && v.abs() <= 1e5);
        s.camera_focal_px = Some(focal);
        s.camera_centre_x_px = centre(self.cx, sx);
        s.camera_centre_y_px = centre(self.cy, sy);
        true
    }
}

/// A `sensor_msgs/msg/JointState` as JSON: `{"NAME": position, …}` (radians, or metres for
/// prismatic joints); non-finite positions become `null`.
///
/// # Errors
/// [`MessageError`] when the bytes are not such a message.
pub fn joint_positions(bytes: &[u8]) -> Result<serde_json::Value, MessageError> {
    let m: ros2::JointState = ros2::decode(bytes).map_err(|source| MessageError::Cdr {
        schema: MessageKind::RosJointState.schema_name(),
        source,
    })?;
    let mut out = serde_json::Map::new();
    for (name, p) in m.name.into_iter().zip(m.position) {
        let value = serde_json::Number::from_f64(p).map_or(serde_json::Value::Null, Into::into);
        out.insert(name.0, value);
    }
    Ok(serde_json::Value::Object(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use foxglove::Encode as _;

    #[test]
    fn kinds_are_told_by_schema_and_encoding() {
        assert_eq!(
            MessageKind::of("sensor_msgs/msg/Image", "cdr"),
            Some(MessageKind::RosImage)
        );
        assert_eq!(
            MessageKind::of("sensor_msgs/Image", "cdr"),
            Some(MessageKind::RosImage)
        );
        assert_eq!(
            MessageKind::of("foxglove.CompressedImage", "protobuf"),
            Some(MessageKind::FoxgloveCompressedImage)
        );
        assert_eq!(MessageKind::of("foxglove.RawImage", "json"), None);
        assert_eq!(MessageKind::of("sensor_msgs/msg/Image", "ros1"), None);
        assert!(MessageKind::RosCompressedImage.is_image());
        assert!(!MessageKind::RosTf.is_image());
    }

    #[test]
    fn ros_and_foxglove_images_give_the_same_frame_and_rewrap_unchanged() {
        let pixels: Vec<u8> = (0..24).collect();
        let ros = ros2::encode(&ros2::Image {
            header: ros2::Header {
                stamp: ros2::Time { sec: 1, nanosec: 5 },
                frame_id: ros2::CdrString("cam".into()),
            },
            height: 2,
            width: 4,
            encoding: ros2::CdrString("rgb8".into()),
            is_bigendian: 0,
            step: 12,
            data: pixels.clone(),
        })
        .unwrap();
        let from_ros = ImageMessage::decode(MessageKind::RosImage, &ros).unwrap();
        assert_eq!(from_ros.timestamp_ns, Some(1_000_000_005));
        let mut fox = Vec::new();
        assert_eq!(
            from_ros.encode_foxglove(&mut fox),
            Ok(MessageKind::FoxgloveRawImage)
        );
        let from_fox = ImageMessage::decode(MessageKind::FoxgloveRawImage, &fox).unwrap();
        assert_eq!(from_fox, from_ros);
        assert_eq!(from_fox.to_frame().unwrap(), from_ros.into_frame().unwrap());
    }

    #[test]
    fn unknown_encodings_are_named_with_the_known_ones() {
        let m = foxglove::messages::RawImage {
            width: 2,
            height: 2,
            step: 4,
            encoding: "16UC1".into(),
            data: vec![0; 8].into(),
            ..Default::default()
        };
        let mut b = Vec::new();
        m.encode(&mut b).unwrap();
        let e = ImageMessage::decode(MessageKind::FoxgloveRawImage, &b)
            .unwrap()
            .into_frame()
            .unwrap_err()
            .to_string();
        assert!(e.contains("16UC1") && e.contains("bayer_rggb8"), "{e}");
    }

    #[test]
    fn joint_states_and_camera_info_decode() {
        let js = ros2::encode(&ros2::JointState {
            name: vec![ros2::CdrString("HeadYaw".into())],
            position: vec![0.5],
            ..ros2::JointState::default()
        })
        .unwrap();
        assert_eq!(
            joint_positions(&js).unwrap(),
            serde_json::json!({"HeadYaw": 0.5})
        );
        let ci = ros2::encode(&ros2::CameraInfo {
            width: 640,
            height: 480,
            k: [500.0, 0.0, 320.0, 0.0, 501.0, 240.0, 0.0, 0.0, 1.0],
            ..ros2::CameraInfo::default()
        })
        .unwrap();
        let k = CameraIntrinsics::decode(MessageKind::RosCameraInfo, &ci)
            .unwrap()
            .unwrap();
        assert_eq!((k.fx, k.fy, k.cx, k.cy), (500.0, 501.0, 320.0, 240.0));
        let empty = ros2::encode(&ros2::CameraInfo::default()).unwrap();
        assert_eq!(
            CameraIntrinsics::decode(MessageKind::RosCameraInfo, &empty).unwrap(),
            None
        );
    }

    /// Found by the `ros2_messages` fuzz target (an out-of-memory abort): a message whose
    /// claimed sizes exceed its bytes is refused by every decoder without a large allocation.
    #[test]
    fn the_fuzzers_oversized_message_is_refused_cheaply() {
        let bytes = include_bytes!("../../fuzz/regressions/ros2_messages/oom-image-claims.cdr");
        for kind in [
            MessageKind::RosImage,
            MessageKind::RosCompressedImage,
            MessageKind::FoxgloveRawImage,
            MessageKind::FoxgloveCompressedImage,
        ] {
            if let Ok(m) = ImageMessage::decode(kind, bytes) {
                assert!(m.into_frame().is_err(), "{kind:?} made a frame of it");
            }
        }
        assert!(matches!(
            ros2::decode_compressed_image(bytes),
            Err(ros2::CdrError::Truncated { .. })
        ));
        let _ = CameraIntrinsics::decode(MessageKind::RosCameraInfo, bytes);
        let _ = CameraIntrinsics::decode(MessageKind::FoxgloveCameraCalibration, bytes);
        let _ = joint_positions(bytes);
        let _ = ros2::decode::<ros2::TfMessage>(bytes);
    }

    #[test]
    fn a_calibration_fills_the_readings_scaled_to_the_frame() {
        let k = CameraIntrinsics {
            width: 640,
            height: 480,
            fx: 500.0,
            fy: 501.0,
            cx: 330.0,
            cy: 250.0,
        };
        let mut s = SensorReadings::default();
        assert!(k.fill_readings(320, 240, &mut s));
        assert_eq!(s.camera_focal_px, Some(250.0));
        assert_eq!(
            (s.camera_centre_x_px, s.camera_centre_y_px),
            (Some(165.0), Some(125.0))
        );
        // Readings with a calibration of their own keep it.
        let mut own = SensorReadings {
            camera_focal_px: Some(100.0),
            ..SensorReadings::default()
        };
        assert!(!k.fill_readings(640, 480, &mut own));
        assert_eq!(own.camera_focal_px, Some(100.0));
        // A calibration without a usable focal length leaves the readings alone.
        let bad = CameraIntrinsics { fx: -1.0, ..k };
        let mut s = SensorReadings::default();
        assert!(!bad.fill_readings(640, 480, &mut s));
        assert_eq!(s, SensorReadings::default());
        let nan = CameraIntrinsics { fx: f64::NAN, ..k };
        assert!(!nan.fill_readings(640, 480, &mut s));
    }
}
