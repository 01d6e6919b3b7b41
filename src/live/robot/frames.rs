//! [`RobotFrames`]: a read-only handle on one camera of a robot, what a viewer steps through.

use std::sync::{Arc, Mutex};

use super::{CameraFrames, Connection, Inner, LiveFrame, RobotStats, lock};
use crate::live::RobotUrl;

/// A read-only handle on a robot's frames (cheap to clone): what a viewer steps through while
/// the robot's thread goes on adding frames. It reads the same state as its [`LiveRobot`](super::LiveRobot) and
/// stays readable (frozen) after the robot is dropped.
#[derive(Clone)]
pub struct RobotFrames {
    pub(super) url: RobotUrl,
    pub(super) shared: Arc<Mutex<Inner>>,
    /// The camera (image topic) whose frames these are; `None`: the robot's shown camera.
    pub(super) camera: Option<String>,
}

impl std::fmt::Debug for RobotFrames {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RobotFrames")
            .field("url", &self.url)
            .finish_non_exhaustive()
    }
}

impl RobotFrames {
    /// The robot's address.
    #[must_use]
    pub const fn url(&self) -> &RobotUrl {
        &self.url
    }

    /// The robot's server name once it said it, else its address.
    #[must_use]
    pub fn name(&self) -> String {
        lock(&self.shared)
            .name
            .clone()
            .unwrap_or_else(|| self.url.to_string())
    }

    /// The connection's state.
    #[must_use]
    pub fn connection(&self) -> Connection {
        lock(&self.shared)
            .connection
            .clone()
            .unwrap_or(Connection::Connecting)
    }

    /// The image topic of the camera these frames are of (`None` before the robot advertised
    /// an image channel).
    #[must_use]
    pub fn camera(&self) -> Option<String> {
        self.camera
            .clone()
            .or_else(|| lock(&self.shared).cameras.first().map(|c| c.topic.clone()))
    }

    /// Every camera (image topic) the robot advertised, the one shown first.
    #[must_use]
    pub fn cameras(&self) -> Vec<String> {
        lock(&self.shared)
            .cameras
            .iter()
            .map(|c| c.topic.clone())
            .collect()
    }

    /// The frames of the robot's camera `topic` (which it may advertise later).
    #[must_use]
    pub fn camera_view(&self, topic: &str) -> Self {
        Self {
            url: self.url.clone(),
            shared: Arc::clone(&self.shared),
            camera: Some(topic.to_owned()),
        }
    }

    /// Reads this camera's frames, if the robot has advertised it.
    fn with_camera<T>(&self, read: impl FnOnce(&CameraFrames) -> T) -> Option<T> {
        let inner = lock(&self.shared);
        let camera = match &self.camera {
            Some(t) => inner.cameras.iter().find(|c| &c.topic == t),
            None => inner.cameras.first(),
        };
        camera.map(read)
    }

    /// Frames received so far (the next frame's index).
    #[must_use]
    pub fn len(&self) -> usize {
        self.with_camera(|c| c.received).unwrap_or(0)
    }

    /// True before the first frame.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Index of the oldest frame still in memory (`len()` when none is).
    #[must_use]
    pub fn first_kept(&self) -> usize {
        self.with_camera(CameraFrames::first_kept).unwrap_or(0)
    }

    /// Frame `index` if it is still in memory.
    #[must_use]
    pub fn frame(&self, index: usize) -> Option<Arc<LiveFrame>> {
        self.with_camera(|c| c.frame(index)).flatten()
    }

    /// The newest frame.
    #[must_use]
    pub fn latest(&self) -> Option<Arc<LiveFrame>> {
        self.with_camera(|c| c.frames.back().cloned()).flatten()
    }

    /// The figures for the robot list.
    #[must_use]
    pub fn stats(&self) -> RobotStats {
        lock(&self.shared).stats()
    }

    /// When this camera's first frame arrived, nanoseconds after the robot's first frame (of
    /// any camera): the clock a robot's cameras are matched on side by side.
    #[must_use]
    pub fn start_ns(&self) -> u64 {
        self.with_camera(CameraFrames::start_ns).unwrap_or(0)
    }

    /// When frame `index` arrived, nanoseconds after this camera's first frame (the last
    /// frame's time past the end; 0 before any frame).
    #[must_use]
    pub fn arrival_ns(&self, index: usize) -> u64 {
        self.with_camera(|c| c.arrival_ns(index)).unwrap_or(0)
    }

    /// The last frame that arrived at or before `offset_ns` after the first one (0 when none).
    #[must_use]
    pub fn index_at_arrival(&self, offset_ns: u64) -> usize {
        self.with_camera(|c| c.index_at_arrival(offset_ns))
            .unwrap_or(0)
    }
}
