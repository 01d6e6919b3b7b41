//! One frame's messages into a [`FrameRecord`]: the image through its decoder, JSON channels,
//! annotations, camera info and joint states as the frame's channels, `/tf` into the camera's
//! pose. The same for every storage.

use std::borrow::Cow;
use std::io::Read as _;

use foxglove::Decode as _;

use super::channels::Role;
use super::{RawFrame, RawMsg};
use crate::formats::tf::TfTree;
use crate::formats::{CameraIntrinsics, ImageMessage, joint_positions, ros2};
use crate::sensors::SensorReadings;
use crate::streams::FrameRecord;
use crate::streams::schema::parse_json_lenient;

/// Largest message after zstd decompression, bytes.
const MAX_DECOMPRESSED_BYTES: u64 = 256 << 20;

/// A frame's messages decoded: the record, the image message as it came, and what was skipped.
pub(super) struct Assembled {
    pub(super) record: FrameRecord,
    /// The image message as it came, when asked for.
    pub(super) image: Option<ImageMessage>,
    /// The frame is grey (`mono8`).
    pub(super) grey: bool,
    pub(super) warnings: Vec<String>,
}

/// Decompresses one zstd-compressed message, bounded.
fn unzstd(data: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let decoder = zstd::stream::read::Decoder::new(data).map_err(|e| e.to_string())?;
    decoder
        .take(MAX_DECOMPRESSED_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("zstd: {e}"))?;
    if out.len() as u64 > MAX_DECOMPRESSED_BYTES {
        return Err("decompresses to more than 256 MiB".to_owned());
    }
    Ok(out)
}

fn bytes<'a>(data: &'a Cow<'a, [u8]>, zstd: bool) -> Result<Cow<'a, [u8]>, String> {
    if zstd {
        unzstd(data).map(Cow::Owned)
    } else {
        Ok(Cow::Borrowed(&data[..]))
    }
}

/// Assembles frame `index` from its raw messages. `keep_image` keeps a copy of the image message
/// (for `eotn import`); without it the message's pixel buffer becomes the frame's.
///
/// # Errors
/// Why the image did not decode: the frame is lost, the caller names it.
pub(super) fn assemble(
    index: usize,
    raw: RawFrame<'_>,
    tf_static: &TfTree,
    zstd_messages: bool,
    keep_image: bool,
) -> Result<Assembled, String> {
    let image_bytes = bytes(&raw.image, zstd_messages)?;
    let image = ImageMessage::decode(raw.kind, &image_bytes).map_err(|e| e.to_string())?;
    let frame_id = image.frame_id.clone();
    let grey = image.is_grey();
    let (frame, image) = if keep_image {
        (image.to_frame(), Some(image))
    } else {
        (image.into_frame(), None)
    };
    let frame = frame.map_err(|e| e.to_string())?;
    let mut record = FrameRecord::new(raw.time_ns, frame);
    let mut warnings = Vec::new();
    let mut tree: Option<TfTree> = None;
    let mut calibration: Option<CameraIntrinsics> = None;
    for m in &raw.others {
        let data = match bytes(&m.data, zstd_messages) {
            Ok(d) => d,
            Err(e) => {
                warnings.push(format!("frame {index}: {} skipped: {e}", m.role.topic()));
                continue;
            }
        };
        if let Err(e) = take(
            &mut record,
            m,
            &data,
            tf_static,
            &mut tree,
            &mut calibration,
        ) {
            warnings.push(format!("frame {index}: {e}"));
        }
    }
    let tree = tree.as_ref().unwrap_or(tf_static);
    if !tree.is_empty()
        && let Some(pose) = tree.camera_pose(&frame_id)
    {
        let mut s = record.sensors.unwrap_or_default();
        fill_camera_pose(&mut s, &pose);
        record.sensors = Some(s);
    }
    if let Some(k) = calibration {
        let mut s = record.sensors.unwrap_or_default();
        if k.fill_readings(record.frame.width(), record.frame.height(), &mut s) {
            record.sensors = Some(s);
        }
    }
    Ok(Assembled {
        record,
        image,
        grey,
        warnings,
    })
}

/// The camera pose from the transform tree where the readings have none of their own.
fn fill_camera_pose(s: &mut SensorReadings, pose: &SensorReadings) {
    if s.camera_height_cm.is_some() || s.camera_pitch_rad.is_some() {
        return;
    }
    s.camera_x_cm = pose.camera_x_cm;
    s.camera_y_cm = pose.camera_y_cm;
    s.camera_height_cm = pose.camera_height_cm;
    s.camera_roll_rad = pose.camera_roll_rad;
    s.camera_pitch_rad = pose.camera_pitch_rad;
    s.camera_yaw_rad = pose.camera_yaw_rad;
}

/// One message into the record (a camera calibration also into `calibration`, for the
/// readings); `Err` names what was skipped and why.
fn take(
    record: &mut FrameRecord,
    m: &RawMsg<'_>,
    data: &[u8],
    tf_static: &TfTree,
    tree: &mut Option<TfTree>,
    calibration: &mut Option<CameraIntrinsics>,
) -> Result<(), String> {
    let topic = m.role.topic();
    match &m.role {
        Role::Annotations => {
            let a = foxglove::messages::ImageAnnotations::decode(data).map_err(|e| {
                format!("{topic} is not a foxglove.ImageAnnotations ({e}); skipped")
            })?;
            record.annotations = Some(a);
        }
        Role::CameraInfo(kind, topic) => {
            if let Some(k) = CameraIntrinsics::decode(*kind, data)
                .map_err(|e| format!("{topic}: {e}; skipped"))?
            {
                record.extra.push((topic.clone(), k.to_json()));
                *calibration = Some(k);
            }
        }
        Role::Joints(topic) => {
            let v = joint_positions(data).map_err(|e| format!("{topic}: {e}; skipped"))?;
            record.extra.push((topic.clone(), v));
        }
        Role::Tf(_) => {
            let msg: ros2::TfMessage = ros2::decode(data)
                .map_err(|e| format!("{topic}: not a TFMessage ({e}); skipped"))?;
            tree.get_or_insert_with(|| tf_static.clone()).add(&msg);
        }
        Role::Sensors | Role::GroundTruth | Role::Recognition | Role::Extra(_) => {
            take_json(record, &m.role, data)?;
        }
        Role::Image(_) | Role::Ignored => {}
    }
    Ok(())
}

fn take_json(record: &mut FrameRecord, role: &Role, data: &[u8]) -> Result<(), String> {
    let topic = role.topic();
    let (value, replaced) = parse_json_lenient(data)
        .map_err(|e| format!("{topic} is not valid JSON ({e}); skipped"))?;
    match role {
        Role::Sensors => {
            let s = serde_json::from_value::<SensorReadings>(value)
                .map_err(|e| format!("{topic} does not match the sensor schema ({e}); skipped"))?;
            let (clean, dropped) = s.sanitised();
            record.sensors = Some(clean);
            if !dropped.is_empty() {
                return Err(format!(
                    "non-finite or impossible sensor values dropped: {}",
                    dropped.join(", ")
                ));
            }
        }
        Role::GroundTruth => record.ground_truth = Some(value),
        Role::Recognition => record.recognition = Some(value),
        Role::Extra(t) => record.extra.push((t.clone(), value)),
        _ => {}
    }
    if replaced {
        return Err(format!("{topic} has NaN/Infinity values; read as missing"));
    }
    Ok(())
}
