//! One message that is not a camera image, attached to its frame: eotn's JSON channels, ROS
//! joint states and camera intrinsics as the frame's channels, transforms into the robot's tree;
//! and which advertised channels are camera images.

use super::protocol::AdvertisedChannel;
use crate::formats::tf::TfTree;
use crate::formats::{CameraIntrinsics, MessageKind, joint_positions, ros2};
use crate::sensors::SensorReadings;
use crate::streams::schema::parse_json_lenient;
use crate::streams::{
    FrameRecord, GROUND_TRUTH_TOPIC, IMAGE_TOPIC, RECOGNITION_TOPIC, SENSORS_TOPIC,
};

/// Attaches one JSON or CDR message to its frame as the channel `as_topic` (a camera's
/// `CAMERA/sensors` is its frames' `/sensors`; transforms go into the robot's tree); a note when
/// it had to be skipped.
pub(super) fn attach(
    record: &mut FrameRecord,
    channel: &AdvertisedChannel,
    as_topic: &str,
    bytes: &[u8],
    tf: &mut TfTree,
) -> Option<String> {
    let topic = channel.topic.as_str();
    match MessageKind::of(&channel.schema_name, &channel.encoding) {
        Some(MessageKind::RosJointState) => {
            return match joint_positions(bytes) {
                Ok(v) => {
                    record.extra.push((topic.to_owned(), v));
                    None
                }
                Err(e) => Some(format!("{topic}: {e}; skipped")),
            };
        }
        Some(kind @ (MessageKind::RosCameraInfo | MessageKind::FoxgloveCameraCalibration)) => {
            return match CameraIntrinsics::decode(kind, bytes) {
                Ok(k) => {
                    if let Some(k) = k {
                        record.extra.push((topic.to_owned(), k.to_json()));
                        let mut s = record.sensors.unwrap_or_default();
                        if k.fill_readings(record.frame.width(), record.frame.height(), &mut s) {
                            record.sensors = Some(s);
                        }
                    }
                    None
                }
                Err(e) => Some(format!("{topic}: {e}; skipped")),
            };
        }
        Some(MessageKind::RosTf) => {
            return match ros2::decode::<ros2::TfMessage>(bytes) {
                Ok(m) => {
                    tf.add(&m);
                    None
                }
                Err(e) => Some(format!("{topic}: not a TFMessage ({e}); skipped")),
            };
        }
        _ if channel.encoding != "json" => return None,
        _ => {}
    }
    let value = match parse_json_lenient(bytes) {
        Ok((v, _)) => v,
        Err(e) => return Some(format!("{topic}: not JSON ({e}); skipped")),
    };
    match as_topic {
        SENSORS_TOPIC => match serde_json::from_value::<SensorReadings>(value) {
            Ok(s) => record.sensors = Some(s.sanitised().0),
            Err(e) => return Some(format!("{topic}: not sensor readings ({e}); skipped")),
        },
        GROUND_TRUTH_TOPIC => record.ground_truth = Some(value),
        RECOGNITION_TOPIC => record.recognition = Some(value),
        _ => record.extra.push((topic.to_owned(), value)),
    }
    None
}

/// The image kind of a camera channel: any image schema eotn reads (`foxglove.RawImage`,
/// `CompressedImage`, ROS `sensor_msgs/msg/Image` in `cdr`, …), and a protobuf `/camera/image`
/// whatever its schema name says.
pub(super) fn image_kind(c: &AdvertisedChannel) -> Option<MessageKind> {
    match MessageKind::of(&c.schema_name, &c.encoding) {
        Some(k) if k.is_image() => Some(k),
        _ if c.encoding == "protobuf" && c.topic == IMAGE_TOPIC => {
            Some(MessageKind::FoxgloveRawImage)
        }
        _ => None,
    }
}
