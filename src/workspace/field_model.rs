//! The field view's model, headless: where the overhead camera puts the ball and each robot
//! (with short trails), each robot's own world-model estimate of itself and of the ball beside
//! that overhead truth, the error of each, and the errors over the frames seen so far (for the
//! plot: position, heading, ball and tape-measure errors), each robot's medians, 95th percentiles
//! and error jumps over them (`crate::wmd::summary`, the rule `eotn wmd` marks jumps by). The
//! app's field view (`app/field_view.rs`, `app/wmd_errors.rs`) only draws this. The tape
//! measure finds goals and landmarks in the field description in use ([`FieldModel::set_field`]).
//!
//! A world model (`/world_model`, `/world_model/<anything>`; docs/formats.md) names its robot by
//! the marker it wears; it is compared with the overhead robot reading that marker, else by
//! position (`crate::wmd::compare`). Messages that are not world models are warned about once
//! and skipped.

use std::collections::{BTreeMap, VecDeque};

use super::overhead::RobotKey;
use crate::model::world_model::{self, is_world_model_topic};
use crate::overhead::merge::FieldPicture;
use crate::wmd::summary::{RobotSummary, Summaries};
use crate::wmd::{Comparison, Matched, OverheadRobotPose, OverheadView, Targets};

/// Positions a trail keeps (frames).
pub const TRAIL_FRAMES: usize = 30;

/// Farthest a world model's self estimate may be from a detected robot to be matched with it
/// by position, centimetres.
pub const MATCH_RADIUS_CM: f64 = crate::wmd::MATCH_RADIUS_CM;

/// One robot's world model on the shown frame, beside the overhead truth.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldModelView {
    /// The robot, by the marker the message names.
    pub robot: RobotKey,
    /// How it was matched with an overhead robot.
    pub matched: Matched,
    /// The overhead robot it is compared with, if found.
    pub key: Option<RobotKey>,
    /// Its own estimate of itself: field x, y (cm) and heading (rad).
    pub own: [f64; 3],
    /// Its estimate of the ball, field x, y (cm).
    pub ball: Option<[f64; 2]>,
    /// Distance of its self estimate from the overhead robot, cm.
    pub self_error_cm: Option<f64>,
    /// Its heading error against the overhead robot's, degrees (absolute).
    pub heading_error_deg: Option<f64>,
    /// Distance of its ball estimate from the overhead ball, cm.
    pub ball_error_cm: Option<f64>,
}

/// Errors of every world model at one frame, for the plot.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorSample {
    /// Frame time, seconds since the first frame.
    pub time_s: f64,
    /// Frame time, nanoseconds since the first frame (the summaries' jumps are at these).
    pub time_ns: u64,
    /// Per robot: self error and ball error, cm.
    pub errors: Vec<(RobotKey, Option<f64>, Option<f64>)>,
    /// Every world model of the frame compared: heading errors (signed, degrees) and the tape
    /// measure of each `seen` measurement among them.
    pub comparisons: Vec<Comparison>,
}

/// See the module documentation.
#[derive(Debug, Clone, Default)]
pub struct FieldModel {
    trails: BTreeMap<RobotKey, VecDeque<(usize, [f64; 2])>>,
    ball_trail: VecDeque<(usize, [f64; 2])>,
    last_index: Option<usize>,
    world_models: Vec<WorldModelView>,
    errors: BTreeMap<usize, ErrorSample>,
    warned: bool,
    /// SSL-Vision's detections shown beside eotn's: each camera's frame (`workspace/ssl_feed.rs`).
    ssl: Vec<crate::ssl_vision::CameraFrame>,
    /// Where the goals and landmarks a robot measures stand (the field in use).
    targets: Targets,
    /// The summaries gathered over the frames in `errors` up to `gathered_to` (frame index),
    /// in order: playback adds each new frame; a frame out of order gathers them again.
    gathered: Summaries,
    gathered_to: Option<usize>,
    /// Each robot's summary over the frames seen so far.
    summaries: Vec<RobotSummary>,
}

impl FieldModel {
    /// Takes in the shown frame: `index` in the source, its time, what the overhead cameras
    /// found (one camera's detections, or several cameras' merged) and its extra channels (the
    /// world models).
    pub fn observe(
        &mut self,
        index: usize,
        time_ns: u64,
        detections: Option<&FieldPicture>,
        extra: &[(String, serde_json::Value)],
    ) {
        // Trails follow playback: a jump (seek, step back) starts them again; the same frame
        // processed again (a new table or calibration) replaces its own points.
        let again = self.last_index == Some(index);
        if !again && self.last_index.is_none_or(|i| index != i + 1) {
            self.trails.clear();
            self.ball_trail.clear();
        }
        self.last_index = Some(index);
        if let Some(d) = detections {
            for r in &d.robots {
                let key = RobotKey {
                    team: r.team,
                    identity: r.identity,
                };
                push_trail(self.trails.entry(key).or_default(), index, r.field_cm);
            }
            if let Some(b) = &d.ball {
                push_trail(&mut self.ball_trail, index, b.ball.field_cm);
            }
        }
        let models: Vec<world_model::WorldModelMessage> = extra
            .iter()
            .filter(|(topic, _)| is_world_model_topic(topic))
            .filter_map(|(topic, v)| match world_model::from_value(v) {
                Ok(m) => Some(m),
                Err(e) => {
                    if !std::mem::replace(&mut self.warned, true) {
                        log::warn!("{topic}: not a world model ({e}); skipped");
                    }
                    None
                }
            })
            .collect();
        let refs: Vec<&world_model::WorldModelMessage> = models.iter().collect();
        let view = overhead_view(detections);
        let comparisons = crate::wmd::compare(&view, &refs, &self.targets);
        self.world_models = comparisons
            .iter()
            .zip(&models)
            .map(|(c, m)| WorldModelView {
                robot: m.robot,
                matched: c.matched,
                key: c.overhead_robot,
                own: [m.own.x_cm, m.own.y_cm, m.own.heading_rad],
                ball: m.ball,
                self_error_cm: c.position_error_cm,
                heading_error_deg: c.heading_error_deg.map(f64::abs),
                ball_error_cm: c.ball_error_cm,
            })
            .collect();
        self.world_models.sort_by_key(|m| m.robot);
        if !self.world_models.is_empty() {
            self.errors.insert(
                index,
                ErrorSample {
                    time_s: time_ns as f64 / 1e9,
                    time_ns,
                    errors: self
                        .world_models
                        .iter()
                        .map(|m| (m.robot, m.self_error_cm, m.ball_error_cm))
                        .collect(),
                    comparisons,
                },
            );
            self.gather(index);
        }
    }

    /// Brings the summaries up to frame `index` (just inserted): added on when it follows the
    /// frames gathered, else all gathered again in frame order.
    fn gather(&mut self, index: usize) {
        if self.gathered_to.is_some_and(|g| index <= g) {
            self.gathered = Summaries::default();
            self.gathered_to = None;
        }
        let from = self.gathered_to.map_or(0, |g| g + 1);
        for (i, s) in self.errors.range(from..) {
            for c in &s.comparisons {
                self.gathered.add(s.time_ns, c);
            }
            self.gathered_to = Some(*i);
        }
        self.summaries = self.gathered.clone().finish();
    }

    /// Each robot's medians, 95th percentiles and error jumps over the frames seen so far,
    /// blue team first, then by identity.
    #[must_use]
    pub fn summaries(&self) -> &[RobotSummary] {
        &self.summaries
    }

    /// Uses `field`'s goals and landmarks for the tape measure (frames already seen keep theirs).
    pub fn set_field(&mut self, field: &crate::overhead::FieldDescription) {
        self.targets = Targets::from_field(field);
    }

    /// Each robot's trail, oldest first: (frame index, field position in cm).
    #[must_use]
    pub const fn trails(&self) -> &BTreeMap<RobotKey, VecDeque<(usize, [f64; 2])>> {
        &self.trails
    }

    /// The ball's trail, oldest first: (frame index, field position in cm).
    #[must_use]
    pub const fn ball_trail(&self) -> &VecDeque<(usize, [f64; 2])> {
        &self.ball_trail
    }

    /// The shown frame's world models, blue team first, then by identity.
    #[must_use]
    pub fn world_models(&self) -> &[WorldModelView] {
        &self.world_models
    }

    /// The world-model errors of every frame seen so far, in frame order.
    pub fn error_samples(&self) -> impl Iterator<Item = &ErrorSample> {
        self.errors.values()
    }

    /// Takes the SSL-Vision frames to show (one per camera, by camera id).
    pub fn set_ssl(&mut self, frames: &[crate::ssl_vision::CameraFrame]) {
        self.ssl = frames.to_vec();
    }

    /// The SSL-Vision frames shown beside eotn's detections, one per camera, by camera id:
    /// each camera's balls and robots (field centimetres), for the field view to mark by camera.
    #[must_use]
    pub fn ssl(&self) -> &[crate::ssl_vision::CameraFrame] {
        &self.ssl
    }
}

fn push_trail(trail: &mut VecDeque<(usize, [f64; 2])>, index: usize, p: [f64; 2]) {
    if trail.back().is_some_and(|(i, _)| *i == index) {
        trail.pop_back();
    }
    trail.push_back((index, p));
    while trail.len() > TRAIL_FRAMES {
        trail.pop_front();
    }
}

/// What the overhead cameras saw, as the comparison takes it.
fn overhead_view(detections: Option<&FieldPicture>) -> OverheadView {
    detections.map_or_else(OverheadView::default, |d| OverheadView {
        ball: d.ball.as_ref().map(|b| b.ball.field_cm),
        robots: d
            .robots
            .iter()
            .map(|r| OverheadRobotPose {
                key: RobotKey {
                    team: r.team,
                    identity: r.identity,
                },
                field_cm: r.field_cm,
                heading_rad: r.heading_rad,
            })
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{ImagePoint, MarkerIdentity, MarkerTeam};
    use crate::overhead::merge::{SslCameraId, one_camera};
    use crate::overhead::recognise::{OverheadBall, OverheadDetections, OverheadRobot};

    fn detections(robot_at: [f64; 2], ball_at: [f64; 2]) -> FieldPicture {
        let p = ImagePoint::new(0.0, 0.0);
        let d = OverheadDetections {
            ball: Some(OverheadBall {
                field_cm: ball_at,
                image: p,
                radius_px: 4.0,
                confidence: 1.0,
            }),
            robots: vec![OverheadRobot {
                team: MarkerTeam::Blue,
                identity: MarkerIdentity::new(5).expect("identity"),
                field_cm: robot_at,
                heading_rad: 0.0,
                image: p,
                dots: [p; 4],
                confidence: 1.0,
            }],
            rejected: Vec::new(),
        };
        one_camera(SslCameraId(0), &d)
    }

    fn world_model(id: u32, x: f64, heading: f64, ball_x: f64) -> (String, serde_json::Value) {
        (
            "/world_model".to_owned(),
            serde_json::json!({"team": "blue", "robot_id": id, "self": {"x_cm": x, "y_cm": 0.0,
                "heading_rad": heading}, "ball": {"x_cm": ball_x, "y_cm": 0.0}}),
        )
    }

    #[test]
    fn a_world_model_is_compared_with_its_marker_else_the_nearest_robot() {
        let mut m = FieldModel::default();
        let d = detections([100.0, 0.0], [0.0, 0.0]);
        m.observe(0, 0, Some(&d), &[world_model(5, 130.0, 0.5, 40.0)]);
        let w = &m.world_models()[0];
        assert_eq!(w.matched, Matched::Marker);
        assert_eq!(w.key.map(|k| k.identity.value()), Some(5));
        assert!((w.self_error_cm.expect("matched") - 30.0).abs() < 1e-9);
        // Blue 3's marker is not read: the nearest robot, said as such.
        m.observe(0, 0, Some(&d), &[world_model(3, 130.0, 0.5, 40.0)]);
        let w = &m.world_models()[0];
        assert_eq!(w.matched, Matched::Position);
        assert_eq!(w.key.map(|k| k.identity.value()), Some(5));
        assert!((w.self_error_cm.expect("matched") - 30.0).abs() < 1e-9);
        assert!((w.heading_error_deg.expect("matched") - 0.5f64.to_degrees()).abs() < 1e-9);
        assert!((w.ball_error_cm.expect("ball") - 40.0).abs() < 1e-9);
        // Too far from every robot: no match, no self error; the ball error stays.
        m.observe(1, 40_000_000, Some(&d), &[world_model(3, 400.0, 0.0, 10.0)]);
        let w = &m.world_models()[0];
        assert_eq!((w.key, w.self_error_cm), (None, None));
        assert_eq!(m.error_samples().count(), 2);
    }

    #[test]
    fn the_tape_measure_uses_the_fields_goals_and_a_jump_is_marked_once() {
        let field = crate::overhead::FieldDescription::four_legged_2005();
        let goal = crate::wmd::Targets::from_field(&field)
            .place(
                &crate::wmd::SeenObject::YellowGoal,
                &OverheadView::default(),
            )
            .expect("the 2005 field has a yellow goal");
        let mut m = FieldModel::default();
        m.set_field(&field);
        let d = detections([100.0, 0.0], [0.0, 0.0]);
        let true_cm = (goal[0] - 100.0).hypot(goal[1]);
        for i in 0..12 {
            let x = if i == 8 { 400.0 } else { 110.0 };
            let (topic, mut v) = world_model(5, x, 0.0, 0.0);
            v["seen"] = serde_json::json!([{"object": "yellow_goal",
                "distance_cm": true_cm + 20.0, "bearing_rad": 0.0}]);
            m.observe(i, i as u64 * 1_000_000, Some(&d), &[(topic, v)]);
        }
        let s = &m.summaries()[0];
        let tape = s.distance_cm.expect("measured against the field's goal");
        assert!((tape.median - 20.0).abs() < 1e-6, "{tape:?}");
        assert_eq!(s.jumps_ns, [8_000_000]);
        assert_eq!(s.ball_cm.map(|b| b.n), Some(12));
        // A frame seen again (a new table): gathered again, the same summary.
        let before = m.summaries().to_vec();
        m.observe(3, 3_000_000, Some(&d), &[world_model(5, 110.0, 0.0, 0.0)]);
        assert_eq!(m.summaries()[0].jumps_ns, before[0].jumps_ns);
        assert_eq!(m.summaries()[0].world_models, 12);
    }

    #[test]
    fn trails_grow_with_playback_stay_short_and_restart_on_a_jump() {
        let mut m = FieldModel::default();
        for i in 0..TRAIL_FRAMES + 5 {
            let d = detections([i as f64, 0.0], [0.0, i as f64]);
            m.observe(i, 0, Some(&d), &[]);
        }
        let trail = m.trails().values().next().expect("one robot");
        assert_eq!(trail.len(), TRAIL_FRAMES);
        assert_eq!(
            trail.back(),
            Some(&(TRAIL_FRAMES + 4, [(TRAIL_FRAMES + 4) as f64, 0.0]))
        );
        // The same frame again replaces its point.
        m.observe(
            TRAIL_FRAMES + 4,
            0,
            Some(&detections([-1.0, 0.0], [0.0, 0.0])),
            &[],
        );
        let trail = m.trails().values().next().expect("one robot");
        assert_eq!(trail.len(), TRAIL_FRAMES);
        assert_eq!(trail.back(), Some(&(TRAIL_FRAMES + 4, [-1.0, 0.0])));
        assert_eq!(m.ball_trail().len(), TRAIL_FRAMES);
        m.observe(3, 0, Some(&detections([0.0, 0.0], [0.0, 0.0])), &[]);
        assert_eq!(m.trails().values().next().map(VecDeque::len), Some(1));
    }
}
