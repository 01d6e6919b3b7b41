//! A camera's intrinsics from where teams keep them: a ROS `camera_info` YAML file, or the
//! camera-info messages of a recording (`sensor_msgs/msg/CameraInfo`,
//! `foxglove.CameraCalibration`) — `eotn overhead calibrate --intrinsics` and the app's
//! Calibration window both read through [`load_intrinsics`].

use std::path::Path;

use crate::formats::{CameraInfoMessage, MessageKind};
use crate::overhead::intrinsics::Intrinsics;

/// Reads intrinsics from `path`: a recording (an MCAP file, a rosbag2 folder or storage file)
/// gives the first camera-info message of `camera`'s topic (`TOPIC/camera_info`, or beside
/// `NS/image_raw` `NS/camera_info`) or, without a camera or such a topic, of the only camera-info
/// channel; any other path is a `camera_info` YAML file.
///
/// # Errors
/// A message, naming the file: no camera-info channel, several and no camera to choose by, a
/// message that does not decode, or intrinsics eotn cannot use (as for a YAML file).
pub fn load_intrinsics(path: &Path, camera: Option<&str>) -> Result<Intrinsics, String> {
    if !super::is_recording(path) {
        return Intrinsics::load(path).map_err(|e| e.to_string());
    }
    let name = path.display();
    let mut reader = super::StreamReader::open(path).map_err(|e| e.to_string())?;
    let infos: Vec<(u16, String, MessageKind)> = reader
        .channels()
        .iter()
        .filter_map(|c| {
            let schema = c.schema.as_ref()?;
            let kind = MessageKind::of(&schema.name, &c.message_encoding)?;
            matches!(
                kind,
                MessageKind::RosCameraInfo | MessageKind::FoxgloveCameraCalibration
            )
            .then(|| (c.id, c.topic.clone(), kind))
        })
        .collect();
    let chosen = match (camera, infos.as_slice()) {
        (_, []) => return Err(format!("{name}: no camera-info channel in the recording")),
        (None, [one]) => one.clone(),
        (Some(topic), _) => infos
            .iter()
            .find(|(_, t, _)| is_camera_info_of(t, topic))
            .cloned()
            .ok_or_else(|| format!("{name}: no camera info beside camera {topic}"))?,
        (None, _) => {
            let topics: Vec<&str> = infos.iter().map(|(_, t, _)| t.as_str()).collect();
            return Err(format!(
                "{name}: several camera-info channels ({}); name the camera",
                topics.join(", ")
            ));
        }
    };
    let (id, topic, kind) = chosen;
    let mut first: Option<Result<CameraInfoMessage, String>> = None;
    reader
        .for_each_message(|m| {
            if m.channel == id && first.is_none() {
                first = Some(CameraInfoMessage::decode(kind, m.data).map_err(|e| e.to_string()));
            }
        })
        .map_err(|e| e.to_string())?;
    let message = first
        .ok_or_else(|| format!("{name}: {topic} holds no message"))?
        .map_err(|e| format!("{name}: {topic}: {e}"))?;
    let mut intrinsics =
        Intrinsics::from_message(&message).map_err(|e| format!("{name}: {topic}: {e}"))?;
    if intrinsics.camera_name.is_empty() {
        intrinsics.camera_name = format!("{name} {topic}");
    }
    Ok(intrinsics)
}

/// Whether `info_topic` is the camera info of the image topic `camera`: `camera/camera_info`,
/// or `NS/camera_info` beside `NS/image_raw` (or any `NS/IMAGE`).
fn is_camera_info_of(info_topic: &str, camera: &str) -> bool {
    let Some(ns) = info_topic.strip_suffix("/camera_info") else {
        return false;
    };
    ns == camera
        || camera
            .rsplit_once('/')
            .is_some_and(|(parent, _)| parent == ns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_camera_info_topic_goes_with_its_image_topic() {
        assert!(is_camera_info_of("/camera/top/camera_info", "/camera/top"));
        assert!(is_camera_info_of(
            "/camera/top/camera_info",
            "/camera/top/image_raw"
        ));
        assert!(!is_camera_info_of(
            "/camera/bottom/camera_info",
            "/camera/top/image_raw"
        ));
        assert!(!is_camera_info_of("/camera/top/info", "/camera/top"));
    }
}
