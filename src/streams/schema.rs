//! Schemas and encodings of the stream's channels: the camera image as `foxglove.RawImage`
//! (protobuf) and JSON channels described by `jsonschema` documents.

use foxglove::{Decode, Encode};

use crate::frame::{Frame, FrameError, PixelLayout};
use crate::sensors::SensorReadings;

/// Why a frame could not become a `foxglove.RawImage`, or a message a frame.
#[derive(Debug, thiserror::Error)]
pub enum ImageMessageError {
    /// The frame cannot be made 4:2:2, or the decoded data is no frame.
    #[error(transparent)]
    Frame(#[from] FrameError),
    /// The frame is too large for the message's 32-bit fields.
    #[error("{width}×{height} is too large")]
    TooLarge {
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
    },
    /// Protobuf encoding failed.
    #[error("{0}")]
    Encode(#[source] <foxglove::messages::RawImage as Encode>::Error),
    /// The bytes are no `foxglove.RawImage`.
    #[error("image message is not a foxglove.RawImage: {0}")]
    NotRawImage(#[source] <foxglove::messages::RawImage as Decode>::Error),
    /// An encoding other than the 4:2:2 orders.
    #[error(
        "image encoding '{encoding}' is not supported ({})",
        ImageEncoding::NAMES
    )]
    Encoding {
        /// The message's `encoding`.
        encoding: String,
    },
    /// A size whose row or data length overflows.
    #[error("image size {width}×{height} is not usable")]
    Unusable {
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
    },
    /// A row step shorter than a row.
    #[error("image step {step} is shorter than a {width}-pixel UYVY row ({row} bytes)")]
    ShortStep {
        /// The message's `step`, bytes.
        step: usize,
        /// Width, pixels.
        width: usize,
        /// A row's bytes.
        row: usize,
    },
    /// Less data than the size and step need (or no rows).
    #[error("image data has {len} bytes, a {width}×{height} frame with step {step} needs {needed}")]
    ShortData {
        /// Bytes of data.
        len: usize,
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
        /// Row step, bytes.
        step: usize,
        /// Bytes needed.
        needed: usize,
    },
}

/// Name of the sensor readings' JSON schema.
pub const SENSORS_SCHEMA_NAME: &str = "eotn.SensorReadings";
/// Name of the ground-truth JSON schema (a free-form object).
pub const GROUND_TRUTH_SCHEMA_NAME: &str = "eotn.GroundTruth";
/// Name of the recognition JSON schema (a free-form object).
pub const RECOGNITION_SCHEMA_NAME: &str = "eotn.Recognition";
/// Name of the schema of extra JSON channels (any JSON value).
pub const EXTRA_SCHEMA_NAME: &str = "eotn.Json";
/// Foxglove frame id written into every image (the camera's optical frame).
pub const CAMERA_FRAME_ID: &str = "camera";

/// The `jsonschema` document of [`SensorReadings`]: every field a number (or null when the source
/// did not provide it), with its unit in the description.
#[must_use]
pub fn sensors_json_schema() -> serde_json::Value {
    let mut props = serde_json::Map::new();
    for f in SensorReadings::default().fields() {
        props.insert(
            f.name.to_owned(),
            serde_json::json!({ "type": ["number", "null"], "description": format!("unit: {}", f.unit) }),
        );
    }
    serde_json::json!({
        "title": SENSORS_SCHEMA_NAME,
        "description": "The robot's sensor readings for one frame. Angles in radians (pan positive \
                        to the left, tilt positive up), lengths in centimetres, accelerations in \
                        m/s². A missing or null field was not provided by the source. \
                        camera_x_cm, camera_y_cm, camera_height_cm, camera_roll_rad, \
                        camera_pitch_rad, camera_yaw_rad: the robot's own estimate of its \
                        camera's pose over the ground (position in its ground frame, x ahead, y \
                        left; rotation yaw, then pitch positive looking down, then roll positive \
                        right side down); recognition uses it, when height and pitch are given, \
                        instead of a body model.",
        "type": "object",
        "properties": props,
    })
}

/// The `jsonschema` document of a free-form JSON object channel.
#[must_use]
pub fn object_json_schema(title: &str, description: &str) -> serde_json::Value {
    serde_json::json!({ "title": title, "description": description, "type": "object" })
}

/// The `jsonschema` document of extra channels: any JSON value.
#[must_use]
pub fn any_json_schema() -> serde_json::Value {
    serde_json::json!({ "title": EXTRA_SCHEMA_NAME, "description": "Any JSON value." })
}

/// The protobuf schema (a serialised `FileDescriptorSet`) of `foxglove.RawImage`, and its name.
#[must_use]
pub fn raw_image_schema() -> Option<foxglove::Schema> {
    foxglove::messages::RawImage::get_schema()
}

/// The byte order of 4:2:2 frames in a stream's `foxglove.RawImage` messages.
///
/// Both hold the same samples (a byte permutation of each pixel pair, no loss). Streams eotn
/// writes use [`ImageEncoding::Yuyv`] by default because Rerun's MCAP importer reads `yuyv` but not
/// `uyvy` (Foxglove reads both); `uyvy` keeps the cameras' own order for whoever wants it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ImageEncoding {
    /// `yuyv` (Y0 U Y1 V), also named `yuv422_yuy2`.
    #[default]
    Yuyv,
    /// `uyvy` (U Y0 V Y1), also named `yuv422`: the AIBO's and most cameras' order.
    Uyvy,
}

impl ImageEncoding {
    /// The encodings a reader accepts, by the names `foxglove.RawImage` uses.
    pub const NAMES: &'static str = "yuyv, yuv422_yuy2, uyvy, yuv422";

    /// The `encoding` field written for this order.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Yuyv => "yuyv",
            Self::Uyvy => "uyvy",
        }
    }

    /// The order a `foxglove.RawImage` `encoding` field names, if it is a 4:2:2 one we read.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "yuyv" | "yuv422_yuy2" => Some(Self::Yuyv),
            "uyvy" | "yuv422" => Some(Self::Uyvy),
            _ => None,
        }
    }
}

impl std::str::FromStr for ImageEncoding {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s).ok_or_else(|| {
            format!(
                "image encoding '{s}' is not one of {} (the 4:2:2 orders)",
                Self::NAMES
            )
        })
    }
}

/// Swaps each pixel pair between UYVY (U Y0 V Y1) and YUYV (Y0 U Y1 V): its own inverse.
fn swap_pairs(data: &mut [u8]) {
    for q in data.chunks_exact_mut(4) {
        q.swap(0, 1);
        q.swap(2, 3);
    }
}

/// Encodes a frame as a `foxglove.RawImage` in `encoding` with `step` = 2 × width bytes; 4:4:4
/// frames are converted to 4:2:2 first.
///
/// # Errors
/// [`ImageMessageError`] when the frame cannot become UYVY (odd width) or is too large for the
/// message's 32-bit fields.
pub fn encode_image(
    time_ns: u64,
    frame: &Frame,
    encoding: ImageEncoding,
    out: &mut Vec<u8>,
) -> Result<(), ImageMessageError> {
    let converted;
    let uyvy = if frame.layout() == PixelLayout::Uyvy {
        frame
    } else {
        converted = frame.to_uyvy()?;
        &converted
    };
    let too_big = ImageMessageError::TooLarge {
        width: uyvy.width(),
        height: uyvy.height(),
    };
    let (Ok(width), Ok(height)) = (u32::try_from(uyvy.width()), u32::try_from(uyvy.height()))
    else {
        return Err(too_big);
    };
    let step = width.checked_mul(2).ok_or(too_big)?;
    let sec = u32::try_from(time_ns / 1_000_000_000).unwrap_or(u32::MAX);
    let nsec = u32::try_from(time_ns % 1_000_000_000).unwrap_or(0);
    let mut data = uyvy.data().to_vec();
    if encoding == ImageEncoding::Yuyv {
        swap_pairs(&mut data);
    }
    let msg = foxglove::messages::RawImage {
        timestamp: Some(foxglove::messages::Timestamp::new(sec, nsec)),
        frame_id: CAMERA_FRAME_ID.to_owned(),
        width,
        height,
        encoding: encoding.name().to_owned(),
        step,
        data: data.into(),
    };
    out.clear();
    out.reserve(msg.encoded_len().unwrap_or(0));
    msg.encode(out).map_err(ImageMessageError::Encode)
}

/// Decodes a `foxglove.RawImage` into a UYVY frame (the pipeline's order). Encodings
/// `uyvy`/`yuv422` are taken as they are, `yuyv`/`yuv422_yuy2` are reordered; row padding (`step` > 2 × width) is dropped.
///
/// # Errors
/// [`ImageMessageError`] for undecodable protobuf, other encodings, or sizes that do not match
/// the data.
pub fn decode_image(bytes: &[u8]) -> Result<Frame, ImageMessageError> {
    decode_image_with_time(bytes).map(|(frame, _)| frame)
}

/// [`decode_image`], also giving the image's own `timestamp` (the capture time), nanoseconds
/// since the Unix epoch or the stream's start, when it has one.
///
/// # Errors
/// As [`decode_image`].
pub fn decode_image_with_time(bytes: &[u8]) -> Result<(Frame, Option<u64>), ImageMessageError> {
    let msg =
        foxglove::messages::RawImage::decode(bytes).map_err(ImageMessageError::NotRawImage)?;
    let time_ns = msg
        .timestamp
        .map(|t| u64::from(t.sec()) * 1_000_000_000 + u64::from(t.nsec()));
    let (w, h) = (msg.width as usize, msg.height as usize);
    let Some(encoding) = ImageEncoding::from_name(&msg.encoding) else {
        return Err(ImageMessageError::Encoding {
            encoding: msg.encoding,
        });
    };
    let unusable = ImageMessageError::Unusable {
        width: w,
        height: h,
    };
    let row = w.checked_mul(2).ok_or(unusable)?;
    let step = msg.step as usize;
    if step < row {
        return Err(ImageMessageError::ShortStep {
            step,
            width: w,
            row,
        });
    }
    let needed = step
        .checked_mul(h.saturating_sub(1))
        .and_then(|n| n.checked_add(row))
        .ok_or(ImageMessageError::Unusable {
            width: w,
            height: h,
        })?;
    if h == 0 || msg.data.len() < needed {
        return Err(ImageMessageError::ShortData {
            len: msg.data.len(),
            width: w,
            height: h,
            step,
            needed,
        });
    }
    let mut data = Vec::with_capacity(row * h);
    for r in msg.data.chunks(step).take(h) {
        data.extend_from_slice(r.get(..row).unwrap_or(r));
    }
    if encoding == ImageEncoding::Yuyv {
        swap_pairs(&mut data);
    }
    let frame = Frame::from_uyvy(w, h, data)?;
    Ok((frame, time_ns))
}

/// Parses a JSON message leniently: Python's `NaN`, `Infinity` and `-Infinity` (not JSON, but
/// what `json.dumps` writes) become `null`. Returns the value and whether any were replaced.
///
/// # Errors
/// The JSON parser's error on the bytes as they are.
pub fn parse_json_lenient(bytes: &[u8]) -> Result<(serde_json::Value, bool), serde_json::Error> {
    match serde_json::from_slice(bytes) {
        Ok(v) => Ok((v, false)),
        Err(first) => {
            let Ok(text) = std::str::from_utf8(bytes) else {
                return Err(first);
            };
            let (fixed, replaced) = replace_non_finite_tokens(text);
            if !replaced {
                return Err(first);
            }
            serde_json::from_str(&fixed)
                .map(|v| (v, true))
                .map_err(|_| first)
        }
    }
}

/// Replaces `NaN`, `Infinity`, `-Infinity` outside strings with `null`.
fn replace_non_finite_tokens(text: &str) -> (String, bool) {
    let mut out = String::with_capacity(text.len());
    let mut replaced = false;
    let mut in_string = false;
    let mut escaped = false;
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        if in_string {
            out.push(c);
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
            rest = &rest[c.len_utf8()..];
            continue;
        }
        let token = ["-Infinity", "Infinity", "NaN"]
            .into_iter()
            .find(|t| rest.starts_with(t));
        if let Some(t) = token {
            out.push_str("null");
            replaced = true;
            rest = &rest[t.len()..];
            continue;
        }
        if c == '"' {
            in_string = true;
        }
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    (out, replaced)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    #[test]
    fn image_round_trip_keeps_bytes_and_times_in_both_orders() {
        let f = Frame::uyvy_from_fn(6, 4, |x, y| Yuv::new((x * 10 + y) as u8, 90, 200)).unwrap();
        for encoding in [ImageEncoding::Yuyv, ImageEncoding::Uyvy] {
            let mut buf = Vec::new();
            encode_image(3_000_000_123, &f, encoding, &mut buf).unwrap();
            let msg = foxglove::messages::RawImage::decode(buf.as_slice()).unwrap();
            assert_eq!((msg.width, msg.height, msg.step), (6, 4, 12));
            assert_eq!(msg.encoding, encoding.name());
            let ts = msg.timestamp.unwrap();
            assert_eq!((ts.sec(), ts.nsec()), (3, 123));
            assert_eq!(decode_image(&buf).unwrap(), f);
        }
    }

    #[test]
    fn yuyv_messages_hold_luma_first() {
        // One pixel pair: U=1 Y0=2 V=3 Y1=4 in the frame, Y0 U Y1 V in a yuyv message.
        let f = Frame::from_uyvy(2, 1, vec![1, 2, 3, 4]).unwrap();
        let mut buf = Vec::new();
        encode_image(0, &f, ImageEncoding::Yuyv, &mut buf).unwrap();
        let msg = foxglove::messages::RawImage::decode(buf.as_slice()).unwrap();
        assert_eq!(&msg.data[..], &[2, 1, 4, 3]);
    }

    #[test]
    fn encoding_names_parse_with_their_aliases() {
        assert_eq!("yuv422_yuy2".parse(), Ok(ImageEncoding::Yuyv));
        assert_eq!("yuv422".parse(), Ok(ImageEncoding::Uyvy));
        let err = "rgb8".parse::<ImageEncoding>().unwrap_err();
        assert!(err.contains("rgb8") && err.contains("uyvy"), "{err}");
    }

    #[test]
    fn padded_rows_and_yuyv_are_understood() {
        let msg = foxglove::messages::RawImage {
            width: 2,
            height: 2,
            step: 6,
            encoding: "yuyv".into(),
            data: vec![10, 20, 30, 40, 0, 0, 11, 21, 31, 41, 0, 0].into(),
            ..Default::default()
        };
        let mut buf = Vec::new();
        msg.encode(&mut buf).unwrap();
        let f = decode_image(&buf).unwrap();
        assert_eq!(f.data(), &[20, 10, 40, 30, 21, 11, 41, 31]);
    }

    #[test]
    fn bad_images_are_errors_not_panics() {
        assert!(decode_image(b"\xff\xff\xff garbage").is_err());
        for (enc, w, h, step, len) in [
            ("rgb8", 2, 2, 6, 12),
            ("uyvy", 4, 2, 4, 16),
            ("uyvy", 4, 2, 8, 15),
            ("uyvy", u32::MAX, u32::MAX, u32::MAX, 4),
            ("uyvy", 3, 1, 6, 6),
        ] {
            let msg = foxglove::messages::RawImage {
                width: w,
                height: h,
                step,
                encoding: enc.into(),
                data: vec![0; len].into(),
                ..Default::default()
            };
            let mut buf = Vec::new();
            msg.encode(&mut buf).unwrap();
            assert!(decode_image(&buf).is_err(), "{enc} {w}x{h}");
        }
    }

    #[test]
    fn lenient_json_turns_python_nan_into_null() {
        let (v, replaced) =
            parse_json_lenient(br#"{"a": NaN, "b": -Infinity, "s": "NaN in text", "c": 1}"#)
                .unwrap();
        assert!(replaced);
        assert!(v["a"].is_null() && v["b"].is_null());
        assert_eq!(v["s"], "NaN in text");
        assert_eq!(v["c"], 1);
        assert!(parse_json_lenient(b"{not json").is_err());
        assert_eq!(
            parse_json_lenient(b"[1]").unwrap(),
            (serde_json::json!([1]), false)
        );
    }

    #[test]
    fn sensor_schema_lists_every_field() {
        let s = sensors_json_schema();
        let props = s["properties"].as_object().unwrap();
        assert_eq!(props.len(), SensorReadings::default().fields().len());
        assert_eq!(props["ir_far_cm"]["description"], "unit: cm");
    }
}
