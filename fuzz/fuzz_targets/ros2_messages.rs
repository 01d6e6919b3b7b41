//! ROS 2 CDR messages (rosbag2 and foxglove_bridge): every type eotn reads decoded from the same
//! bytes, images on to a frame; and the Foxglove protobuf images.
#![no_main]

use eotn::formats::{CameraIntrinsics, ImageMessage, MessageKind, joint_positions, ros2};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for kind in [
        MessageKind::RosImage,
        MessageKind::RosCompressedImage,
        MessageKind::FoxgloveRawImage,
        MessageKind::FoxgloveCompressedImage,
    ] {
        if let Ok(m) = ImageMessage::decode(kind, data) {
            let _ = m.into_frame();
        }
    }
    let _ = CameraIntrinsics::decode(MessageKind::RosCameraInfo, data);
    let _ = CameraIntrinsics::decode(MessageKind::FoxgloveCameraCalibration, data);
    let _ = joint_positions(data);
    if let Ok(tf) = ros2::decode::<ros2::TfMessage>(data) {
        let mut tree = eotn::formats::tf::TfTree::default();
        tree.add(&tf);
        for t in &tf.transforms {
            let _ = tree.camera_pose(&t.child_frame_id.0);
        }
    }
});
