//! The camera's pose over the ground from ROS's transform tree (`/tf`, `/tf_static`,
//! `tf2_msgs/msg/TFMessage`): the image's frame followed up its parents to the ground, as the
//! camera-pose readings of [`SensorReadings`] (which recognition uses instead of a body model).
//!
//! The ground is `base_footprint` when the chain passes through it (the point on the ground
//! below the robot, ROS's REP 120), else the chain's root (`odom`, `map`, …). A frame whose name
//! ends in `optical_frame` looks along +z with x right and y down (REP 103's optical frame);
//! any other camera frame looks along +x with y left and z up. Transforms are the latest given
//! for each child (no interpolation in time).

use std::collections::HashMap;

use super::ros2::{TfMessage, Transform};
use crate::sensors::SensorReadings;

/// The name of the frame on the ground below a ROS robot.
const GROUND_FRAME: &str = "base_footprint";
/// Longest parent chain followed (a loop in a damaged tree ends here).
const MAX_DEPTH: usize = 64;

/// A rigid transform: rotation (unit quaternion w, x, y, z) then translation, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pose {
    q: [f64; 4],
    t: [f64; 3],
}

impl Pose {
    const IDENTITY: Self = Self {
        q: [1.0, 0.0, 0.0, 0.0],
        t: [0.0; 3],
    };

    fn from_msg(tf: &Transform) -> Option<Self> {
        let r = tf.rotation;
        let n = (r.w * r.w + r.x * r.x + r.y * r.y + r.z * r.z).sqrt();
        let t = tf.translation;
        let finite = [r.w, r.x, r.y, r.z, t.x, t.y, t.z]
            .iter()
            .all(|v| v.is_finite());
        (finite && n > 1e-9).then(|| Self {
            q: [r.w / n, r.x / n, r.y / n, r.z / n],
            t: [t.x, t.y, t.z],
        })
    }

    fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        let [w, x, y, z] = self.q;
        // v + 2w(u×v) + 2u×(u×v), u = (x, y, z).
        let u = [x, y, z];
        let c1 = cross(u, v);
        let c2 = cross(u, c1);
        [
            v[0] + 2.0 * (w * c1[0] + c2[0]),
            v[1] + 2.0 * (w * c1[1] + c2[1]),
            v[2] + 2.0 * (w * c1[2] + c2[2]),
        ]
    }

    /// `self ∘ child`: the child's pose in this pose's parent.
    fn then(&self, child: &Self) -> Self {
        let [aw, ax, ay, az] = self.q;
        let [bw, bx, by, bz] = child.q;
        let q = [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ];
        let r = self.rotate(child.t);
        Self {
            q,
            t: [r[0] + self.t[0], r[1] + self.t[1], r[2] + self.t[2]],
        }
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The transform tree: each child frame's latest pose in its parent.
#[derive(Debug, Clone, Default)]
pub struct TfTree {
    parents: HashMap<String, (String, Pose)>,
}

impl TfTree {
    /// Adds (or replaces) the transforms of one message; transforms that are not finite or
    /// have no rotation are skipped.
    pub fn add(&mut self, msg: &TfMessage) {
        for t in &msg.transforms {
            let (child, parent) = (
                t.child_frame_id.0.trim_start_matches('/'),
                t.header.frame_id.0.trim_start_matches('/'),
            );
            if child.is_empty() || child == parent {
                continue;
            }
            if let Some(pose) = Pose::from_msg(&t.transform) {
                self.parents
                    .insert(child.to_owned(), (parent.to_owned(), pose));
            }
        }
    }

    /// True when no transform is known.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.parents.is_empty()
    }

    /// The camera of image frame `frame_id` over the ground, as camera-pose readings (every
    /// other reading empty); `None` when the frame is not in the tree.
    #[must_use]
    pub fn camera_pose(&self, frame_id: &str) -> Option<SensorReadings> {
        let mut frame = frame_id.trim_start_matches('/');
        self.parents.get(frame)?;
        let mut pose = Pose::IDENTITY;
        for _ in 0..MAX_DEPTH {
            if frame == GROUND_FRAME {
                break;
            }
            let Some((parent, step)) = self.parents.get(frame) else {
                break;
            };
            pose = step.then(&pose);
            frame = parent;
        }
        let optical = frame_id.ends_with("optical_frame") || frame_id.ends_with("optical");
        let (forward, left, up) = if optical {
            ([0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0])
        } else {
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
        };
        let (f, l, u) = (pose.rotate(forward), pose.rotate(left), pose.rotate(up));
        let yaw = f[1].atan2(f[0]);
        let pitch = (-f[2]).atan2(f[0].hypot(f[1]));
        let roll = l[2].atan2(u[2]);
        Some(SensorReadings {
            camera_x_cm: Some(pose.t[0] * 100.0),
            camera_y_cm: Some(pose.t[1] * 100.0),
            camera_height_cm: Some(pose.t[2] * 100.0),
            camera_roll_rad: Some(roll),
            camera_pitch_rad: Some(pitch),
            camera_yaw_rad: Some(yaw),
            ..SensorReadings::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::ros2::{CdrString, Header, Quaternion, TransformStamped, Vector3};

    fn tf(parent: &str, child: &str, t: [f64; 3], q: [f64; 4]) -> TransformStamped {
        TransformStamped {
            header: Header {
                frame_id: CdrString(parent.into()),
                ..Header::default()
            },
            child_frame_id: CdrString(child.into()),
            transform: Transform {
                translation: Vector3 {
                    x: t[0],
                    y: t[1],
                    z: t[2],
                },
                rotation: Quaternion {
                    w: q[0],
                    x: q[1],
                    y: q[2],
                    z: q[3],
                },
            },
        }
    }

    /// Rotation by `angle` about a unit axis, as (w, x, y, z).
    fn about(axis: [f64; 3], angle: f64) -> [f64; 4] {
        let s = (angle / 2.0).sin();
        [(angle / 2.0).cos(), axis[0] * s, axis[1] * s, axis[2] * s]
    }

    #[test]
    fn a_head_pitched_down_gives_height_and_pitch() {
        let mut tree = TfTree::default();
        tree.add(&TfMessage {
            transforms: vec![
                tf(
                    "odom",
                    "base_footprint",
                    [3.0, 1.0, 0.0],
                    about([0.0, 0.0, 1.0], 1.0),
                ),
                tf(
                    "base_footprint",
                    "base_link",
                    [0.0, 0.0, 0.3],
                    [1.0, 0.0, 0.0, 0.0],
                ),
                tf(
                    "base_link",
                    "head",
                    [0.05, 0.0, 0.2],
                    about([0.0, 1.0, 0.0], 0.3),
                ),
                // Optical frame: z forward, x right, y down (a fixed rotation of the head's axes).
                tf(
                    "head",
                    "camera_optical_frame",
                    [0.0; 3],
                    [0.5, -0.5, 0.5, -0.5],
                ),
            ],
        });
        let p = tree.camera_pose("camera_optical_frame").unwrap();
        let near = |a: Option<f64>, b: f64| (a.unwrap() - b).abs() < 1e-9;
        assert!(near(p.camera_height_cm, 50.0), "{p:?}");
        assert!(near(p.camera_x_cm, 5.0), "{p:?}");
        assert!(near(p.camera_pitch_rad, 0.3), "{p:?}");
        assert!(
            near(p.camera_yaw_rad, 0.0) && near(p.camera_roll_rad, 0.0),
            "{p:?}"
        );
        assert_eq!(tree.camera_pose("elsewhere"), None);
    }

    #[test]
    fn yaw_and_roll_of_a_link_frame() {
        let mut tree = TfTree::default();
        let q = Pose {
            q: about([0.0, 0.0, 1.0], 0.4),
            t: [0.0; 3],
        }
        .then(&Pose {
            q: about([1.0, 0.0, 0.0], 0.2),
            t: [0.0; 3],
        })
        .q;
        tree.add(&TfMessage {
            transforms: vec![tf("base_footprint", "camera", [0.0, 0.0, 0.4], q)],
        });
        let p = tree.camera_pose("camera").unwrap();
        assert!((p.camera_yaw_rad.unwrap() - 0.4).abs() < 1e-9, "{p:?}");
        assert!((p.camera_roll_rad.unwrap() - 0.2).abs() < 1e-9, "{p:?}");
    }

    #[test]
    fn loops_and_nonsense_do_not_hang_or_panic() {
        let mut tree = TfTree::default();
        tree.add(&TfMessage {
            transforms: vec![
                tf("a", "b", [0.0; 3], [1.0, 0.0, 0.0, 0.0]),
                tf("b", "a", [0.0; 3], [1.0, 0.0, 0.0, 0.0]),
                tf("a", "c", [f64::NAN; 3], [1.0, 0.0, 0.0, 0.0]),
                tf("a", "d", [0.0; 3], [0.0; 4]),
            ],
        });
        assert!(tree.camera_pose("b").is_some());
        assert_eq!(tree.camera_pose("c"), None);
        assert_eq!(tree.camera_pose("d"), None);
    }
}
