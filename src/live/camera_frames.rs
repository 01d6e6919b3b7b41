//! One camera of a live robot (an image channel): its frames as they arrived, numbered from 0,
//! the newest kept in memory within its share of the robot's byte budget, and every frame's
//! arrival time on the robot's clock (from the robot's first frame of any camera), so a robot's
//! cameras can be shown side by side, each frame the one nearest the shared cursor.

use std::collections::VecDeque;
use std::sync::Arc;

use super::gaps::FrameGaps;
use super::robot::LiveFrame;

/// One camera's frames; see the module documentation.
#[derive(Debug, Default)]
pub(super) struct CameraFrames {
    /// The image channel's topic.
    pub(super) topic: String,
    /// The newest frames, oldest first.
    pub(super) frames: VecDeque<Arc<LiveFrame>>,
    kept_bytes: usize,
    /// Frames received so far (the next frame's index).
    pub(super) received: usize,
    /// Lost frames judged on this camera's capture times.
    pub(super) gaps: FrameGaps,
    /// Every frame's arrival, nanoseconds after the robot's first frame (of any camera), by
    /// index (8 bytes a frame, kept for frames no longer in memory too, so the timeline's times
    /// never change).
    arrival_offsets_ns: Vec<u64>,
}

impl CameraFrames {
    /// A camera with no frame yet.
    pub(super) fn new(topic: &str) -> Self {
        Self {
            topic: topic.to_owned(),
            ..Self::default()
        }
    }

    /// Adds a frame that arrived `offset_ns` after the robot's first frame; the oldest frames
    /// leave memory until this camera holds at most `keep_bytes` (always its newest frame).
    pub(super) fn push(&mut self, frame: LiveFrame, offset_ns: u64, keep_bytes: usize) {
        self.kept_bytes += frame.record.frame.data().len();
        self.frames.push_back(Arc::new(frame));
        self.received += 1;
        self.arrival_offsets_ns.push(offset_ns);
        while self.kept_bytes > keep_bytes && self.frames.len() > 1 {
            if let Some(old) = self.frames.pop_front() {
                self.kept_bytes -= old.record.frame.data().len();
            }
        }
    }

    /// Index of the oldest frame still in memory (`received` when none is).
    pub(super) fn first_kept(&self) -> usize {
        self.frames.front().map_or(self.received, |f| f.index)
    }

    /// Frame `index` if it is still in memory.
    pub(super) fn frame(&self, index: usize) -> Option<Arc<LiveFrame>> {
        let first = self.frames.front()?.index;
        self.frames.get(index.checked_sub(first)?).cloned()
    }

    /// When this camera's first frame arrived, nanoseconds after the robot's first frame.
    pub(super) fn start_ns(&self) -> u64 {
        self.arrival_offsets_ns.first().copied().unwrap_or(0)
    }

    /// When frame `index` arrived, nanoseconds after this camera's first frame (the last
    /// frame's time past the end; 0 before any frame).
    pub(super) fn arrival_ns(&self, index: usize) -> u64 {
        let times = &self.arrival_offsets_ns;
        times
            .get(index)
            .or_else(|| times.last())
            .map_or(0, |t| t - self.start_ns())
    }

    /// The last frame that arrived at or before `offset_ns` after this camera's first one (0
    /// when none).
    pub(super) fn index_at_arrival(&self, offset_ns: u64) -> usize {
        let at = self.start_ns().saturating_add(offset_ns);
        self.arrival_offsets_ns
            .partition_point(|&t| t <= at)
            .saturating_sub(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Frame, Yuv};
    use crate::streams::FrameRecord;

    fn frame(index: usize) -> LiveFrame {
        LiveFrame {
            index,
            record: FrameRecord::new(0, Frame::filled_uyvy(4, 2, Yuv::new(1, 2, 3)).unwrap()),
            received_ns: 0,
            latency_ns: 0,
        }
    }

    #[test]
    fn a_camera_keeps_its_newest_frames_and_times_from_its_own_first() {
        let mut c = CameraFrames::new("/camera/bottom");
        let bytes = 4 * 2 * 2;
        for i in 0..5 {
            c.push(frame(i), 1_000 + 10 * i as u64, 2 * bytes);
        }
        assert_eq!((c.received, c.first_kept()), (5, 3));
        assert!(c.frame(2).is_none() && c.frame(4).is_some());
        assert_eq!(c.start_ns(), 1_000, "on the robot's clock");
        assert_eq!(c.arrival_ns(0), 0);
        assert_eq!(c.arrival_ns(4), 40);
        assert_eq!(c.arrival_ns(9), 40, "the last frame's past the end");
        assert_eq!(c.index_at_arrival(25), 2);
        assert_eq!(c.index_at_arrival(0), 0);
    }
}
