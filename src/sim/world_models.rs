//! The robots' world models in the overhead game, as docs/formats.md fixes the message: each
//! robot named by the marker it wears (team blue/yellow, identity 0–15), its own estimate of
//! itself and of the ball, and `seen`: what its vision measured, made here from the truth with
//! noise (the game renders no robot camera): the ball and the two goals' mouth centres when in
//! front of it (bearing within ±90°), and the field's landmarks (given by name: the field file's
//! ground landmarks, [`Simulator::with_world_model_landmarks`](super::Simulator)) where its
//! camera would see them: within its field of view (±28.45°, the ERS-7's) and 1 to 6 m away.
//! Each message carries `time_ns`, the frame's time (the robot's clock is the simulator's).
//!
//! Without known errors a robot's estimate is the truth plus a slowly drifting bias (up to
//! 15 cm, 0.1 rad; ball 20 cm) and per-frame noise (σ 8 cm, 0.05 rad; ball σ 12 cm; distances
//! σ 3 %, bearings σ 0.03 rad). A robot given a [`KnownError`] has that error instead of the
//! bias, so tests can check the debugger finds it; `noise` scales every noise and bias (0: the
//! truth plus the known errors, exactly).

use serde_json::Value;

use super::SimRng;
use crate::model::Scene;
use crate::model::world_model::{RobotKey, Seen, SeenObject, SelfEstimate, WorldModelMessage};

/// An error a simulated robot's world model is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnownError {
    /// The scene's robot number (the overhead truth's `id`).
    pub robot: u32,
    /// Added to its own x and y, centimetres.
    pub offset_cm: [f64; 2],
    /// Added to its own heading, radians.
    pub heading_rad: f64,
    /// Its measured distances are the true ones times this.
    pub distance_scale: f64,
}

/// How the simulator's world models err.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldModelErrors {
    /// Robots given known errors.
    pub known: Vec<KnownError>,
    /// Scale of the noise and drifting bias (1: as described above; 0: none).
    pub noise: f64,
}

impl Default for WorldModelErrors {
    fn default() -> Self {
        Self {
            known: Vec::new(),
            noise: 1.0,
        }
    }
}

/// Half the horizontal field of view in which a robot sees a landmark, radians (the ERS-7's
/// 56.9°).
const LANDMARK_HALF_VIEW_RAD: f64 = 0.4965;
/// Nearest and farthest a landmark is seen, centimetres (nearer ones are under the camera's
/// view; farther ones too small to measure).
const LANDMARK_RANGE_CM: (f64, f64) = (100.0, 600.0);

/// Which frame a world model is for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldModelAt {
    /// Its time, seconds since the scenario start.
    pub t_s: f64,
    /// Its time as the stream gives it (the message's `time_ns`), nanoseconds.
    pub time_ns: u64,
    /// Its number.
    pub frame: u64,
}

/// Each marked robot's world model at frame `at`, keyed by its topic `/world_model/robotN` (N the
/// scene's robot number); `landmarks` the named ground places it may measure (field cm).
#[must_use]
pub fn world_models(
    scene: &Scene,
    at: WorldModelAt,
    seed: u64,
    errors: &WorldModelErrors,
    landmarks: &[(String, [f64; 2])],
) -> Vec<(String, Value)> {
    let (t_s, frame) = (at.t_s, at.frame);
    let mut rng = SimRng::derived(seed ^ 0x3D_0D31, frame);
    let s = errors.noise;
    let half = scene.field.length_cm / 2.0;
    let goals = [
        (SeenObject::YellowGoal, [half, 0.0]),
        (SeenObject::BlueGoal, [-half, 0.0]),
    ];
    scene
        .robots
        .iter()
        .filter_map(|r| {
            let marker = r.marker?;
            let id = f64::from(r.id);
            let known = errors.known.iter().find(|k| k.robot == r.id);
            let bias = |k: f64, amp: f64| match known {
                Some(_) => 0.0,
                None => s * amp * (0.3 * t_s + id * 1.7 + k).sin(),
            };
            let (offset, turn, scale) = known.map_or(([0.0; 2], 0.0, 1.0), |k| {
                (k.offset_cm, k.heading_rad, k.distance_scale)
            });
            let pose = r.pose;
            let own = SelfEstimate {
                x_cm: pose.x_cm + offset[0] + bias(0.0, 15.0) + s * 8.0 * rng.normal(),
                y_cm: pose.y_cm + offset[1] + bias(1.0, 15.0) + s * 8.0 * rng.normal(),
                heading_rad: pose.heading_rad + turn + bias(2.0, 0.1) + s * 0.05 * rng.normal(),
                sd_cm: Some(17.0),
                sd_heading_rad: Some(0.11),
            };
            let ball = scene.ball.map(|b| {
                [
                    b.x_cm + bias(3.0, 20.0) + s * 12.0 * rng.normal(),
                    b.y_cm + bias(4.0, 20.0) + s * 12.0 * rng.normal(),
                ]
            });
            let objects = scene
                .ball
                .map(|b| (SeenObject::Ball, [b.x_cm, b.y_cm], None))
                .into_iter()
                .chain(goals.iter().map(|(o, p)| (o.clone(), *p, None)))
                .chain(landmarks.iter().map(|(name, p)| {
                    let object = SeenObject::from_name(name);
                    (object, *p, Some(LANDMARK_RANGE_CM))
                }));
            let seen = objects
                .filter_map(|(object, p, range)| {
                    let (dx, dy) = (p[0] - pose.x_cm, p[1] - pose.y_cm);
                    let bearing = angle_diff(dy.atan2(dx), pose.heading_rad);
                    let half_view = match range {
                        Some(_) => LANDMARK_HALF_VIEW_RAD,
                        None => std::f64::consts::FRAC_PI_2,
                    };
                    let near = range.is_none_or(|(near, far)| (near..=far).contains(&dx.hypot(dy)));
                    (bearing.abs() <= half_view && near).then(|| {
                        let d = dx.hypot(dy);
                        Seen {
                            object,
                            distance_cm: d * scale * (1.0 + s * 0.03 * rng.normal()),
                            bearing_rad: bearing + s * 0.03 * rng.normal(),
                        }
                    })
                })
                .collect();
            let message = WorldModelMessage {
                robot: RobotKey {
                    team: marker.team,
                    identity: marker.identity,
                },
                own,
                ball,
                time_ns: Some(at.time_ns),
                seen,
            };
            Some((format!("/world_model/robot{}", r.id), message.to_json()))
        })
        .collect()
}

/// `a − b`, radians in (−π, π].
fn angle_diff(a: f64, b: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let d = (a - b).rem_euclid(TAU);
    if d > PI { d - TAU } else { d }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::world_model::from_value;
    use crate::sim::{Scenario, ScenarioKind};

    #[test]
    fn each_marked_robot_sends_its_marker_and_known_errors_come_out_exactly() {
        let s = Scenario::new(ScenarioKind::OverheadGame, 1);
        let scene = s.scene_at(0.5);
        let errors = WorldModelErrors {
            known: vec![KnownError {
                robot: 1,
                offset_cm: [30.0, -40.0],
                heading_rad: 0.2,
                distance_scale: 1.1,
            }],
            noise: 0.0,
        };
        let at = WorldModelAt {
            t_s: 0.5,
            time_ns: 500_000_000,
            frame: 15,
        };
        let models = world_models(&scene, at, 1, &errors, &[]);
        assert_eq!(models.len(), scene.robots.len());
        assert_eq!(models[0].0, "/world_model/robot1");
        let m = from_value(&models[0].1).expect("a valid message");
        let r = &scene.robots[0];
        let marker = r.marker.expect("marked");
        assert_eq!(
            (m.robot.team, m.robot.identity),
            (marker.team, marker.identity)
        );
        assert!((m.own.x_cm - r.pose.x_cm - 30.0).abs() < 1e-9);
        assert!((m.own.y_cm - r.pose.y_cm + 40.0).abs() < 1e-9);
        assert!((m.own.heading_rad - r.pose.heading_rad - 0.2).abs() < 1e-9);
        for seen in &m.seen {
            assert!(seen.bearing_rad.abs() <= std::f64::consts::FRAC_PI_2);
        }
        // Noise 1: the other robots err, but not wildly.
        assert_eq!(m.time_ns, Some(500_000_000));
        let noisy = world_models(&scene, at, 1, &WorldModelErrors::default(), &[]);
        let m = from_value(&noisy[1].1).expect("a valid message");
        let r = &scene.robots[1];
        assert!((m.own.x_cm - r.pose.x_cm).abs() < 80.0);
    }

    #[test]
    fn a_landmark_is_seen_in_the_cameras_view_between_one_and_six_metres() {
        let s = Scenario::new(ScenarioKind::OverheadGame, 1);
        let scene = s.scene_at(0.5);
        let r = &scene.robots[0];
        let (x, y, h) = (r.pose.x_cm, r.pose.y_cm, r.pose.heading_rad);
        let at = |d: f64, turn: f64| [x + d * (h + turn).cos(), y + d * (h + turn).sin()];
        let landmarks = vec![
            ("ahead".to_owned(), at(300.0, 0.1)),
            ("behind".to_owned(), at(300.0, 3.0)),
            ("aside".to_owned(), at(300.0, 0.8)),
            ("underfoot".to_owned(), at(50.0, 0.0)),
            ("far".to_owned(), at(900.0, 0.0)),
        ];
        let exact = WorldModelErrors {
            known: Vec::new(),
            noise: 0.0,
        };
        let at0 = WorldModelAt {
            t_s: 0.5,
            time_ns: 500_000_000,
            frame: 15,
        };
        let models = world_models(&scene, at0, 1, &exact, &landmarks);
        let m = from_value(&models[0].1).expect("a valid message");
        let named: Vec<&Seen> = m
            .seen
            .iter()
            .filter(|s| matches!(s.object, SeenObject::Landmark(_)))
            .collect();
        assert_eq!(named.len(), 1, "{:?}", m.seen);
        assert_eq!(named[0].object.name(), "ahead");
        assert!((named[0].distance_cm - 300.0).abs() < 1e-6);
        assert!((named[0].bearing_rad - 0.1).abs() < 1e-9);
    }
}
