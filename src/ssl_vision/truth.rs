//! SSL-Vision detection frames as the picture of the field at a given time: each camera's frames
//! indexed by capture time ([`FrameIndex`]), the frame of each camera nearest a time within half
//! a frame period, merged over the cameras (a robot seen by two cameras once, the more confident
//! reading; the most confident ball), and that picture as the truth `eotn eval` scores an
//! overhead stream against ([`overhead_truth`]).

use std::collections::BTreeMap;

use super::{CameraFrame, SslBall, SslRobot};
use crate::geometry::{ImagePoint, MarkerIdentity, MarkerTeam, OverheadCamera};
use crate::model::scene::Team;
use crate::model::truth::{OverheadMarkerTruth, OverheadObject, OverheadRobot, OverheadTruth};
use crate::overhead::OverheadDetections;
use crate::overhead::recognise::{OverheadBall, OverheadRobot as DetectedRobot};

/// Every camera's detection frames, each camera's in capture-time order.
#[derive(Debug, Clone, Default)]
pub struct FrameIndex {
    cameras: BTreeMap<u32, Vec<(u64, CameraFrame)>>,
    /// Frames left out: their capture time is not a usable number.
    pub untimed: usize,
}

impl FrameIndex {
    /// Indexes frames (any order).
    #[must_use]
    pub fn new(frames: impl IntoIterator<Item = CameraFrame>) -> Self {
        let mut index = Self::default();
        for f in frames {
            index.push(f);
        }
        for list in index.cameras.values_mut() {
            list.sort_by_key(|(t, _)| *t);
        }
        index
    }

    /// Adds a frame at the end of its camera's list (live frames arrive in time order; a frame
    /// out of order is put in its place).
    pub fn push(&mut self, frame: CameraFrame) {
        let Some(t) = frame.t_capture_ns() else {
            self.untimed += 1;
            return;
        };
        let list = self.cameras.entry(frame.camera_id).or_default();
        let at = list.partition_point(|(u, _)| *u <= t);
        list.insert(at, (t, frame));
    }

    /// Frames indexed, all cameras.
    #[must_use]
    pub fn len(&self) -> usize {
        self.cameras.values().map(Vec::len).sum()
    }

    /// True when no frame is indexed.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cameras' ids, ascending.
    pub fn camera_ids(&self) -> impl Iterator<Item = u32> + '_ {
        self.cameras.keys().copied()
    }

    /// The first and last capture time over all cameras, nanoseconds.
    #[must_use]
    pub fn span_ns(&self) -> Option<(u64, u64)> {
        let first = self
            .cameras
            .values()
            .filter_map(|l| l.first())
            .map(|f| f.0)
            .min()?;
        let last = self
            .cameras
            .values()
            .filter_map(|l| l.last())
            .map(|f| f.0)
            .max()?;
        Some((first, last))
    }

    /// All frames' capture times, every camera, ascending (the steps of a log shown alone).
    #[must_use]
    pub fn times_ns(&self) -> Vec<u64> {
        let mut t: Vec<u64> = self.cameras.values().flatten().map(|f| f.0).collect();
        t.sort_unstable();
        t.dedup();
        t
    }

    /// Each camera's frame nearest `t_ns` within half of `period_ns`, by camera id.
    #[must_use]
    pub fn near(&self, t_ns: u64, period_ns: u64) -> Vec<&CameraFrame> {
        self.cameras
            .values()
            .filter_map(|list| {
                let times: Vec<u64> = list.iter().map(|f| f.0).collect();
                crate::overhead::merge::frame_near(&times, t_ns, period_ns)
                    .and_then(|i| list.get(i))
                    .map(|f| &f.1)
            })
            .collect()
    }

    /// One camera's capture times, ascending (the reference camera's are a log's field frames).
    #[must_use]
    pub fn times_of(&self, camera_id: u32) -> Vec<u64> {
        self.cameras
            .get(&camera_id)
            .map(|l| l.iter().map(|f| f.0).collect())
            .unwrap_or_default()
    }

    /// Each camera's latest frame, by camera id.
    #[must_use]
    pub fn latest(&self) -> Vec<&CameraFrame> {
        self.cameras
            .values()
            .filter_map(|l| l.last().map(|f| &f.1))
            .collect()
    }

    /// Keeps each camera's last `n` frames (a live feed's memory).
    pub fn keep_last(&mut self, n: usize) {
        for list in self.cameras.values_mut() {
            let extra = list.len().saturating_sub(n);
            list.drain(..extra);
        }
    }
}

/// The field picture of several cameras' frames of one instant: the most confident ball, and
/// each robot (team and id) once, its most confident reading. Robots without an id are kept
/// (they cannot be merged).
#[must_use]
pub fn merged(frames: &[&CameraFrame]) -> (Option<SslBall>, Vec<SslRobot>) {
    let ball = frames
        .iter()
        .flat_map(|f| &f.balls)
        .max_by(|a, b| a.confidence.total_cmp(&b.confidence))
        .copied();
    let mut by_key: BTreeMap<(u8, u32), SslRobot> = BTreeMap::new();
    let mut unnamed = Vec::new();
    for r in frames.iter().flat_map(|f| &f.robots) {
        let Some(id) = r.robot_id else {
            unnamed.push(*r);
            continue;
        };
        let key = (u8::from(r.team == MarkerTeam::Yellow), id);
        let better = by_key.get(&key).is_none_or(|o| r.confidence > o.confidence);
        if better {
            by_key.insert(key, *r);
        }
    }
    let mut robots: Vec<SslRobot> = by_key.into_values().collect();
    robots.extend(unnamed);
    (ball, robots)
}

/// Several cameras' detection frames of one instant as one overhead picture in eotn's own
/// detections (what `eotn wmd` compares world models with when its overhead source is
/// SSL-Vision): [`merged`] over the cameras, each robot with an id of 0–15 and a heading as the
/// marker of its team colour (blue → blue, yellow → yellow) and that identity, at its field and
/// image position (the identity dots all at the centre: the packet has none), the ball's image
/// radius 0 (the packet has no size). Returns the detections and the robots left out (no id,
/// an id beyond eotn's sixteen markers, or no heading).
#[must_use]
pub fn detections(frames: &[&CameraFrame]) -> (OverheadDetections, usize) {
    let (ball, robots) = merged(frames);
    let mut left_out = 0;
    let robots = robots
        .iter()
        .filter_map(|r| {
            let Some((identity, heading_rad)) = as_marker(r) else {
                left_out += 1;
                return None;
            };
            let image = ImagePoint::new(r.image_px[0], r.image_px[1]);
            Some(DetectedRobot {
                team: r.team,
                identity,
                field_cm: r.field_cm,
                heading_rad,
                image,
                dots: [image; 4],
                confidence: r.confidence,
            })
        })
        .collect();
    let ball = ball.map(|b| OverheadBall {
        field_cm: b.field_cm,
        image: ImagePoint::new(b.image_px[0], b.image_px[1]),
        radius_px: 0.0,
        confidence: b.confidence,
    });
    let d = OverheadDetections {
        ball,
        robots,
        rejected: Vec::new(),
    };
    (d, left_out)
}

/// A robot as eotn's marker of its identity and its heading, radians; `None` without an id,
/// with an id beyond eotn's sixteen markers, or without a heading.
fn as_marker(r: &SslRobot) -> Option<(MarkerIdentity, f64)> {
    let identity = r
        .robot_id
        .and_then(|id| u8::try_from(id).ok())
        .and_then(MarkerIdentity::new)?;
    Some((identity, r.heading_rad?))
}

/// The truth of one instant from SSL detection frames, as `eotn eval` scores an overhead
/// frame against it: every robot with an id of 0–15 and a heading wears a fully visible marker
/// of its team (`plate_height_cm` high), the ball is visible enough to be found. `camera` is
/// the calibration the stream is read through (the truth needs one; evaluation does not use
/// it). Returns the truth and the robots left out (no id, an id beyond eotn's markers, or no
/// heading).
#[must_use]
pub fn overhead_truth(
    frames: &[&CameraFrame],
    camera: OverheadCamera,
    plate_height_cm: f64,
    time_s: f64,
) -> (OverheadTruth, usize) {
    let (ball, robots) = merged(frames);
    let mut left_out = 0;
    let robots = robots
        .iter()
        .filter_map(|r| {
            let Some((identity, heading_rad)) = as_marker(r) else {
                left_out += 1;
                return None;
            };
            Some(OverheadRobot {
                id: u32::from(identity.value()),
                // The uniform is not in the packet; evaluation reads the marker.
                team: match r.team {
                    MarkerTeam::Blue => Team::Blue,
                    MarkerTeam::Yellow => Team::Red,
                },
                field_cm: r.field_cm,
                heading_rad,
                image: None,
                visible_pixels: usize::MAX,
                marker: Some(OverheadMarkerTruth {
                    team: r.team,
                    identity,
                    plate_height_cm,
                    image: None,
                    visible_fraction: 1.0,
                }),
            })
        })
        .collect();
    let truth = OverheadTruth {
        time_s,
        camera,
        ball: ball.map(|b| OverheadObject {
            field_cm: b.field_cm,
            image: None,
            // Seen by ssl-vision: eligible whatever the evaluation's pixel threshold.
            visible_pixels: usize::MAX,
        }),
        robots,
    };
    (truth, left_out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(camera_id: u32, t_s: f64, robots: Vec<SslRobot>) -> CameraFrame {
        CameraFrame {
            camera_id,
            frame_number: 0,
            t_capture_s: t_s,
            t_sent_s: t_s,
            balls: Vec::new(),
            robots,
            dropped: 0,
        }
    }

    fn robot(id: Option<u32>, x: f64, confidence: f64) -> SslRobot {
        SslRobot {
            team: MarkerTeam::Blue,
            robot_id: id,
            field_cm: [x, 0.0],
            heading_rad: Some(0.1),
            image_px: [0.0, 0.0],
            confidence,
        }
    }

    #[test]
    fn frames_pair_within_half_a_period_and_merge_over_cameras() {
        let index = FrameIndex::new([
            frame(0, 1.000, vec![robot(Some(2), 10.0, 0.5)]),
            frame(0, 1.020, vec![robot(Some(2), 11.0, 0.5)]),
            frame(
                1,
                1.004,
                vec![robot(Some(2), 12.0, 0.9), robot(Some(40), 0.0, 1.0)],
            ),
        ]);
        assert_eq!(index.len(), 3);
        let near = index.near(1_003_000_000, 20_000_000);
        assert_eq!(near.len(), 2);
        let (_, robots) = merged(&near);
        assert_eq!(robots.len(), 2);
        assert_eq!(robots[0].field_cm[0], 12.0, "the more confident reading");
        // Beyond half a period of every frame: nothing.
        assert!(index.near(1_060_000_000, 20_000_000).is_empty());
        let (truth, left_out) =
            overhead_truth(&near, OverheadCamera::above_field_2005(), 22.5, 1.0);
        assert_eq!(
            (truth.robots.len(), left_out),
            (1, 1),
            "id 40 has no marker"
        );
        assert!(truth.robots[0].marker.is_some_and(|m| m.fully_visible()));
        let (d, left_out) = detections(&near);
        assert_eq!(left_out, 1, "id 40 has no marker");
        assert_eq!(d.robots.len(), 1);
        assert_eq!(
            (d.robots[0].identity.value(), d.robots[0].field_cm),
            (2, [12.0, 0.0])
        );
        assert_eq!(d.robots[0].team, MarkerTeam::Blue);
        assert!(d.ball.is_none());
        assert_eq!(index.times_of(0), [1_000_000_000, 1_020_000_000]);
        assert!(index.times_of(7).is_empty());
    }
}
