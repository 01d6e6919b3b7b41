//! Scenarios: scenes that move over time, each exercising one part of the pipeline.
//!
//! A [`Scenario`] is a pure function of time (seconds) and its seed: [`Scenario::scene_at`]
//! gives the whole world at any instant, so the renderer can ask for the observing robot's pose
//! at each row's exposure time (rolling shutter) and frames can be made in any order. The seed
//! moves the ball and robots a little and sets the world-model noise, so different seeds give
//! different but equally valid streams. `scenes.rs` holds what each robot-camera scenario's
//! world does over time.

mod scenes;

pub use scenes::pattern_markers;

use std::f64::consts::TAU;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::rng::SimRng;
use crate::model::scene::{Ball, Scene, Team};
use nalgebra::UnitQuaternion;
use scenes::{robot, walking_body};

use crate::geometry::{
    BodyPose, Camera, Ers7Dimensions, Field, HeadJoints, MarkerIdentity, MarkerTeam,
    OverheadCamera, PinholeCamera, Point, RobotMarker, RobotPose, Transform,
};

/// Which camera a scenario films with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum View {
    /// The head camera of the robot with this id.
    Robot {
        /// The observing robot's id.
        observer_id: u32,
    },
    /// The overhead camera.
    Overhead,
}

/// The scenarios, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ScenarioKind {
    /// A robot walks towards the ball, scanning with its head, then tracks the ball.
    WalkAndPan,
    /// A standing robot watches the ball roll across its view, out of the image edges and
    /// behind two robots.
    BallEdge,
    /// A robot looks at the yellow goal while a goalkeeper moves across it, splitting the open
    /// goal into gaps.
    Goalkeeper,
    /// Fast sinusoidal head pans past the ball: the rolling shutter skews it.
    FastPans,
    /// A robot at the side line looks off the field at orange and yellow clutter.
    OrangeClutter,
    /// A robot circles the centre with its head panning: every beacon and goal in turn.
    BeaconTour,
    /// The overhead camera over a game of 4–8 robots and a moving ball, with each robot's noisy
    /// world-model estimate.
    OverheadGame,
    /// Fast head pans past a close ball (36–66 cm ahead, about 30–80 px across): the rolling
    /// shutter shears it a lot, and the pans cut it at the image sides.
    ClosePans,
    /// A standing robot with a still head watches the ball roll across its view at 1–3 m/s:
    /// the ball itself moves while the rows are read out.
    RollingBall,
    /// A robot walks round the centre with its head panning past six coloured-pattern markers
    /// beside the field (two pairs that differ in only two tiles): the "almost SLAM" places.
    PatternTour,
    /// A robot close to each beacon in turn, its head circling so that the beacon leaves the
    /// image at every edge: a beacon cut by the image border (a yellow band on its white base
    /// with the pink band above the image) is not a goal.
    BeaconEdges,
}

impl ScenarioKind {
    /// Every scenario in documentation order.
    pub const ALL: [Self; 11] = [
        Self::WalkAndPan,
        Self::BallEdge,
        Self::Goalkeeper,
        Self::FastPans,
        Self::OrangeClutter,
        Self::BeaconTour,
        Self::OverheadGame,
        Self::ClosePans,
        Self::RollingBall,
        Self::PatternTour,
        Self::BeaconEdges,
    ];

    /// The command-line name (`walk-and-pan`, …).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::WalkAndPan => "walk-and-pan",
            Self::BallEdge => "ball-edge",
            Self::Goalkeeper => "goalkeeper",
            Self::FastPans => "fast-pans",
            Self::OrangeClutter => "orange-clutter",
            Self::BeaconTour => "beacon-tour",
            Self::OverheadGame => "overhead-game",
            Self::ClosePans => "close-pans",
            Self::RollingBall => "rolling-ball",
            Self::PatternTour => "pattern-tour",
            Self::BeaconEdges => "beacon-edges",
        }
    }

    /// The scenario with this command-line name.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// One line on what it exercises.
    #[must_use]
    pub const fn description(self) -> &'static str {
        match self {
            Self::WalkAndPan => "a robot walks towards the ball, scanning, then tracks it",
            Self::BallEdge => "the ball rolls out of the image edges and behind two robots",
            Self::Goalkeeper => "a goalkeeper moves across the yellow goal, splitting it",
            Self::FastPans => "fast head pans past the ball: rolling-shutter skew",
            Self::OrangeClutter => "orange and yellow things off the field, and the real ball",
            Self::BeaconTour => "a robot circles the centre, panning past every beacon",
            Self::OverheadGame => "overhead view of 4-8 robots and the ball, with world models",
            Self::ClosePans => {
                "fast head pans past a close ball (30-80 px): strong skew, cut sides"
            }
            Self::RollingBall => "the ball rolls across a still camera at 1-3 m/s",
            Self::PatternTour => "a robot walks round the centre, panning past six pattern markers",
            Self::BeaconEdges => {
                "close to each beacon, the head circling it out of every image edge"
            }
        }
    }
}

/// A scenario with its seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scenario {
    /// Which one.
    pub kind: ScenarioKind,
    /// The seed.
    pub seed: u64,
    /// Seed-dependent offsets, −1..1.
    jitter: [f64; 4],
    /// Robots in the overhead game.
    robot_count: u32,
}

/// The observing robot's id in every robot-camera scenario.
pub const OBSERVER_ID: u32 = 1;

impl Scenario {
    /// A scenario for a seed.
    #[must_use]
    pub fn new(kind: ScenarioKind, seed: u64) -> Self {
        let mut rng = SimRng::derived(seed, 0x5CE7_A210);
        let jitter = [0; 4].map(|_| rng.range(-1.0, 1.0));
        let robot_count = 4 + u32::try_from(rng.below(5)).unwrap_or(0);
        Self {
            kind,
            seed,
            jitter,
            robot_count,
        }
    }

    /// Which camera films it.
    #[must_use]
    pub fn view(&self) -> View {
        match self.kind {
            ScenarioKind::OverheadGame => View::Overhead,
            _ => View::Robot {
                observer_id: OBSERVER_ID,
            },
        }
    }

    /// Whether the renderer moves the ball while the rows are read out (its position at each
    /// row's exposure time). Only the scenarios made for it: the older ones keep the ball still
    /// during a frame so that figures measured on them stay comparable.
    #[must_use]
    pub fn ball_moves_during_readout(&self) -> bool {
        matches!(self.kind, ScenarioKind::RollingBall)
    }

    /// The ball's field velocity at time `t_s`, centimetres per second (central difference over
    /// ±1 ms), when the scene has a ball.
    #[must_use]
    pub fn ball_velocity_cm_s(&self, t_s: f64) -> Option<[f64; 2]> {
        let h = 1e-3;
        let (a, b) = (self.scene_at(t_s - h).ball?, self.scene_at(t_s + h).ball?);
        Some([(b.x_cm - a.x_cm) / (2.0 * h), (b.y_cm - a.y_cm) / (2.0 * h)])
    }

    /// The world at time `t_s` (seconds from the start).
    #[must_use]
    pub fn scene_at(&self, t_s: f64) -> Scene {
        let mut scene = Scene::four_legged_2005();
        let j = self.jitter;
        let s = &mut scene;
        match self.kind {
            ScenarioKind::WalkAndPan => scenes::walk_and_pan(s, t_s, j),
            ScenarioKind::BallEdge => scenes::ball_edge(s, t_s, j),
            ScenarioKind::Goalkeeper => scenes::goalkeeper(s, t_s, j),
            ScenarioKind::FastPans => scenes::fast_pans(s, t_s, j),
            ScenarioKind::OrangeClutter => scenes::orange_clutter_scene(s, t_s, j),
            ScenarioKind::BeaconTour => scenes::beacon_tour(s, t_s, j),
            ScenarioKind::ClosePans => scenes::close_pans(s, t_s, j, self.seed),
            ScenarioKind::RollingBall => scenes::rolling_ball(s, t_s, j),
            ScenarioKind::PatternTour => scenes::pattern_tour(s, t_s, j),
            ScenarioKind::BeaconEdges => scenes::beacon_edges(s, t_s, j),
            ScenarioKind::OverheadGame => self.overhead_game(s, t_s),
        }
        scene
    }

    /// The overhead game: 4–8 robots on their paths, wearing markers, and a moving ball.
    fn overhead_game(&self, scene: &mut Scene, t_s: f64) {
        let j = self.jitter;
        for k in 0..self.robot_count {
            let team = if k % 2 == 0 { Team::Red } else { Team::Blue };
            let (x, y, heading) = self.game_path(k, t_s);
            let mut r = robot(
                k + 1,
                team,
                RobotPose::new(x, y, heading),
                walking_body(t_s + f64::from(k), true),
                HeadJoints {
                    tilt1_rad: -0.4,
                    pan_rad: 0.8 * (TAU * t_s / 2.5 + f64::from(k)).sin(),
                    tilt2_rad: 0.0,
                },
            );
            r.marker = Some(self.game_marker(k, team));
            scene.robots.push(r);
        }
        let w = 0.35;
        scene.ball = Some(Ball::at(
            200.0 * (w * t_s + j[0]).sin(),
            120.0 * (1.7 * w * t_s + j[1]).sin(),
        ));
    }

    /// Robot `k`'s overhead marker in the overhead game: red robots wear yellow team dots, blue
    /// ones sky blue; identities differ within a team and move round all 16 with the seed.
    fn game_marker(&self, k: u32, team: Team) -> RobotMarker {
        let marker_team = match team {
            Team::Red => MarkerTeam::Yellow,
            Team::Blue => MarkerTeam::Blue,
        };
        // 5 is prime to 16, so the four members of a team (k / 2 = 0..3) get distinct values.
        let value = (self.seed.wrapping_mul(7) + u64::from(k / 2) * 5 + u64::from(k % 2) * 3) % 16;
        let identity =
            MarkerIdentity::new(u8::try_from(value).unwrap_or(0)).unwrap_or(MarkerIdentity::MIN);
        RobotMarker::new(marker_team, identity)
    }

    /// The overhead camera of this scenario: the 2005 rig (350 cm above the centre spot, focal
    /// 420 px, k1 = −0.18, k2 = 0.03) moved, turned and refocused a little by the seed, so that
    /// calibration is measured on many cameras rather than tuned to one.
    #[must_use]
    pub fn overhead_camera(&self) -> OverheadCamera {
        let mut rng = SimRng::derived(self.seed, 0x0CA3_E7A5);
        let mut camera = OverheadCamera::looking_down(
            640,
            480,
            rng.range(335.0, 370.0),
            rng.range(400.0, 440.0),
            rng.range(-0.21, -0.15),
            rng.range(0.015, 0.04),
        );
        camera.centre.x_px += rng.range(-8.0, 8.0);
        camera.centre.y_px += rng.range(-6.0, 6.0);
        camera.pose.position_cm[0] += rng.range(-15.0, 15.0);
        camera.pose.position_cm[1] += rng.range(-10.0, 10.0);
        let tilt = UnitQuaternion::from_euler_angles(
            rng.range(-0.03, 0.03),
            rng.range(-0.03, 0.03),
            rng.range(-0.04, 0.04),
        );
        let t: Transform<Field, Camera> = camera.field_from_camera();
        let turned: Transform<Field, Camera> =
            Transform::new(t.origin().coords.coords, tilt * t.rotation());
        camera.pose = crate::geometry::PoseRecord::from_transform(&turned);
        camera
    }

    /// Robot `k`'s smooth path in the overhead game: position (cm) and heading along the
    /// direction of travel.
    fn game_path(&self, k: u32, t_s: f64) -> (f64, f64, f64) {
        let mut rng = SimRng::derived(self.seed, 100 + u64::from(k));
        let (cx, cy) = (rng.range(-150.0, 150.0), rng.range(-100.0, 100.0));
        let (ax, ay) = (rng.range(40.0, 90.0), rng.range(30.0, 70.0));
        let (wx, wy) = (rng.range(0.2, 0.5), rng.range(0.2, 0.5));
        let (px, py) = (rng.range(0.0, TAU), rng.range(0.0, TAU));
        let x = cx + ax * (wx * t_s + px).sin();
        let y = cy + ay * (wy * t_s + py).sin();
        let vx = ax * wx * (wx * t_s + px).cos();
        let vy = ay * wy * (wy * t_s + py).cos();
        (x, y, vy.atan2(vx))
    }

    /// What the observing robot does at time `t_s`: pose, body and head joints (`None` for the
    /// overhead view).
    #[must_use]
    pub fn observer_at(&self, t_s: f64) -> Option<(RobotPose, BodyPose, HeadJoints)> {
        match self.view() {
            View::Overhead => None,
            View::Robot { observer_id } => self
                .scene_at(t_s)
                .robot(observer_id)
                .map(|r| (r.pose, r.body, r.joints)),
        }
    }
}

/// Head joints (lower tilt and pan; upper tilt 0) that put `target` at the image centre, within
/// the ERS-7's joint ranges (tilt1 −75°..0°, pan ±91°).
#[must_use]
pub fn look_at(robot: &RobotPose, body: &BodyPose, target: &Point<Field>) -> HeadJoints {
    let camera = PinholeCamera::ers7();
    let field_from_body = body.field_from_body(robot);
    let mut joints = HeadJoints::default();
    for _ in 0..8 {
        let field_from_camera: Transform<Field, Camera> =
            field_from_body * Ers7Dimensions::ERS7.body_from_camera(&joints);
        let local = field_from_camera.inverse() * *target;
        let Some(p) = camera.project(&local) else {
            // Behind: turn towards it first.
            let b = field_from_body.inverse() * *target;
            joints.pan_rad = b.y().atan2(b.x());
            continue;
        };
        let err_pan = camera.bearing_rad(p);
        let err_tilt = camera.elevation_rad(p);
        joints.pan_rad = (joints.pan_rad + err_pan).clamp(-1.59, 1.59);
        joints.tilt1_rad = (joints.tilt1_rad + err_tilt).clamp(-1.31, 0.0);
        if err_pan.abs() + err_tilt.abs() < 1e-6 {
            break;
        }
    }
    joints
}

/// The vector from a robot's camera to a point, field axes (cm); handy in tests.
#[must_use]
pub fn camera_to(
    robot: &RobotPose,
    body: &BodyPose,
    joints: &HeadJoints,
    p: &Point<Field>,
) -> Vector3<f64> {
    let c = (body.field_from_body(robot) * Ers7Dimensions::ERS7.body_from_camera(joints)).origin();
    p.coords - c.coords
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::scene::Material;

    #[test]
    fn names_round_trip() {
        for k in ScenarioKind::ALL {
            assert_eq!(ScenarioKind::from_name(k.name()), Some(k));
        }
        assert_eq!(ScenarioKind::from_name("nope"), None);
    }

    #[test]
    fn look_at_centres_the_target() {
        let robot = RobotPose::new(10.0, -20.0, 0.4);
        let body = BodyPose::ERS7_STANCE;
        let target = Point::new(80.0, 30.0, 4.25);
        let joints = look_at(&robot, &body, &target);
        let t = body.field_from_body(&robot) * Ers7Dimensions::ERS7.body_from_camera(&joints);
        let p = PinholeCamera::ers7()
            .project(&(t.inverse() * target))
            .expect("in front");
        assert!(
            (p.x_px - 104.0).abs() < 0.01 && (p.y_px - 80.0).abs() < 0.01,
            "{p:?}"
        );
        assert!(camera_to(&robot, &body, &joints, &target).norm() > 50.0);
    }

    #[test]
    fn scenes_are_pure_functions_of_time_and_seed() {
        for k in ScenarioKind::ALL {
            let a = Scenario::new(k, 3);
            let b = Scenario::new(k, 3);
            assert_eq!(a.scene_at(1.25), b.scene_at(1.25), "{}", k.name());
            if let View::Robot { observer_id } = a.view() {
                assert!(a.scene_at(0.0).robot(observer_id).is_some());
            }
        }
        let game = Scenario::new(ScenarioKind::OverheadGame, 9).scene_at(2.0);
        assert!((4..=8).contains(&game.robots.len()));
    }

    #[test]
    fn the_rolling_ball_rolls_at_one_to_three_metres_a_second() {
        let s = Scenario::new(ScenarioKind::RollingBall, 7);
        assert!(s.ball_moves_during_readout());
        let mut speeds: Vec<f64> = (0..120)
            .filter_map(|k| s.ball_velocity_cm_s(f64::from(k) / 30.0 + 0.01))
            .map(|v| v[0].hypot(v[1]))
            .collect();
        speeds.sort_by(f64::total_cmp);
        assert!(
            speeds[5] >= 99.0 && speeds[speeds.len() - 5] <= 301.0,
            "{speeds:?}"
        );
        let still = Scenario::new(ScenarioKind::FastPans, 7);
        assert!(!still.ball_moves_during_readout());
        assert_eq!(still.ball_velocity_cm_s(1.0), Some([0.0, 0.0]));
    }

    #[test]
    fn pattern_markers_follow_their_design_rules() {
        let markers = pattern_markers();
        let classes: Vec<[u8; 9]> = markers
            .iter()
            .map(|m| m.tiles.map(|t| t.class().code()))
            .collect();
        let agree = |a: &[u8; 9], b: &[u8; 9]| a.iter().zip(b).filter(|(x, y)| x == y).count();
        let pink = Material::Pink.class().code();
        for (i, m) in markers.iter().enumerate() {
            assert_eq!(classes[i][4], pink, "{}: pink in the middle", m.name);
            assert_eq!(classes[i].iter().filter(|&&c| c == pink).count(), 1);
            for k in [0, 1, 2, 6, 7, 8] {
                assert!(
                    !matches!(m.tiles[k], Material::Yellow | Material::SkyBlue),
                    "{}: a goal colour above or below pink is a beacon",
                    m.name
                );
                assert!(!matches!(
                    m.tiles[k],
                    Material::Carpet | Material::BallOrange
                ));
            }
            for k in 0..9 {
                if k % 3 < 2 {
                    assert_ne!(m.tiles[k], m.tiles[k + 1], "{} tiles {k}", m.name);
                }
                if k < 6 {
                    assert_ne!(m.tiles[k], m.tiles[k + 3], "{} tiles {k}", m.name);
                }
            }
            for j in i + 1..markers.len() {
                let a = agree(&classes[i], &classes[j]);
                let twins = matches!((i, j), (0, 1) | (2, 3));
                if twins {
                    assert_eq!(a, 7, "{} / {}", m.name, markers[j].name);
                } else {
                    assert!(a <= 3, "{} / {}: {a}", m.name, markers[j].name);
                }
            }
        }
        let s = Scenario::new(ScenarioKind::PatternTour, 1).scene_at(2.0);
        assert_eq!(s.markers.len(), 6);
        assert!(Scene::four_legged_2005().markers.is_empty());
    }
}
