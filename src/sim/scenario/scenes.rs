//! What each robot-camera scenario's world does over time: one function per scenario, filling
//! the 2005 field with the ball, the observing robot (its pose, body and head) and the others;
//! and the pieces they share (robots, the trot, the rolling ball's passes, the pattern markers,
//! the orange clutter).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::{OBSERVER_ID, look_at};
use crate::geometry::{BodyPose, HeadJoints, Point, RobotPose};
use crate::model::scene::{Ball, Clutter, Marker, Material, Robot, Scene, Shape, Team};

/// A robot walks towards the ball, scanning with its head, then tracks the ball.
pub(super) fn walk_and_pan(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    let ball = Ball::at(80.0 + 30.0 * j[0], 50.0 + 30.0 * j[1]);
    scene.ball = Some(ball);
    let start = (-180.0, -90.0);
    let (dx, dy) = (ball.x_cm - start.0, ball.y_cm - start.1);
    let total = dx.hypot(dy);
    let walked = (20.0 * t_s).min(total - 35.0).max(0.0);
    let heading = dy.atan2(dx);
    let pose = RobotPose::new(
        start.0 + heading.cos() * walked,
        start.1 + heading.sin() * walked,
        heading,
    );
    let body = walking_body(t_s, walked < total - 35.0);
    let scan = HeadJoints {
        tilt1_rad: -0.3,
        pan_rad: 0.9 * (TAU * t_s / 2.0).sin(),
        tilt2_rad: 0.0,
    };
    let track = look_at(&pose, &body, &Point::new(ball.x_cm, ball.y_cm, 4.25));
    let wgt = (t_s - 1.5).clamp(0.0, 1.0);
    let joints = blend(&scan, &track, wgt);
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
    scene.robots.push(standing(5, Team::Blue, 150.0, -60.0, PI));
}

/// A standing robot watches the ball roll across its view, out of the image edges and
/// behind two robots.
pub(super) fn ball_edge(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    // Triangle wave: the ball rolls from y = +110 to −110 and back every 12 s.
    let phase = (t_s / 12.0 + 0.1 * j[0]).rem_euclid(1.0);
    let y = 110.0 - 440.0 * if phase < 0.5 { phase } else { 1.0 - phase };
    scene.ball = Some(Ball::at(110.0, y));
    let pose = RobotPose::new(-40.0, 5.0 * j[1], 0.0);
    let body = BodyPose::ERS7_STANCE;
    let joints = HeadJoints {
        tilt1_rad: -0.28,
        pan_rad: 0.05 * j[2],
        tilt2_rad: 0.0,
    };
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
    scene.robots.push(standing(2, Team::Blue, 70.0, 18.0, PI));
    scene
        .robots
        .push(standing(3, Team::Blue, 75.0, -32.0, PI - 0.4));
}

/// A robot looks at the yellow goal while a goalkeeper moves across it.
pub(super) fn goalkeeper(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    scene.ball = Some(Ball::at(190.0 + 10.0 * j[0], -45.0));
    let pose = RobotPose::new(100.0, 30.0 + 10.0 * j[1], 0.0);
    let body = BodyPose::ERS7_STANCE;
    let pose = RobotPose {
        heading_rad: (0.0 - pose.y_cm).atan2(270.0 - pose.x_cm),
        ..pose
    };
    let joints = look_at(&pose, &body, &Point::new(270.0, 0.0, 12.0));
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
    let keeper_y = 28.0 * (TAU * t_s / 4.0 + j[2]).sin();
    scene
        .robots
        .push(standing(2, Team::Blue, 245.0, keeper_y, PI));
    scene
        .robots
        .push(standing(3, Team::Blue, 200.0, 70.0, PI + 0.5));
}

/// Fast sinusoidal head pans past the ball.
pub(super) fn fast_pans(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    scene.ball = Some(Ball::at(70.0 + 15.0 * j[0], -10.0 + 15.0 * j[1]));
    let pose = RobotPose::new(-60.0, 20.0, 0.0);
    let body = BodyPose::ERS7_STANCE;
    let joints = HeadJoints {
        tilt1_rad: -0.32,
        pan_rad: 1.1 * (TAU * t_s / 1.2).sin(),
        tilt2_rad: 0.0,
    };
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
}

/// A robot at the side line looks off the field at orange and yellow clutter.
pub(super) fn orange_clutter_scene(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    scene.ball = Some(Ball::at(115.0 + 10.0 * j[0], 150.0));
    let pose = RobotPose::new(130.0, 120.0, FRAC_PI_2 + 0.2 * j[1]);
    let body = BodyPose::ERS7_STANCE;
    let joints = HeadJoints {
        tilt1_rad: -0.12,
        pan_rad: 1.0 * (TAU * t_s / 4.0).sin(),
        tilt2_rad: 0.05,
    };
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
    scene.clutter.extend(orange_clutter());
}

/// A robot circles the centre with its head panning.
pub(super) fn beacon_tour(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    let angle = TAU * t_s / 16.0 + j[0];
    let pose = RobotPose::new(90.0 * angle.cos(), 90.0 * angle.sin(), angle);
    let body = walking_body(t_s, true);
    let joints = HeadJoints {
        tilt1_rad: -0.05,
        pan_rad: 1.2 * (TAU * t_s / 3.0).sin(),
        tilt2_rad: 0.1,
    };
    scene.ball = Some(Ball::at(-30.0 + 20.0 * j[1], 40.0));
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
    scene
        .robots
        .push(standing(4, Team::Blue, 160.0, -100.0, 2.5));
}

/// A robot close to each beacon in turn (6 s each), on the field side of it and facing it, 55
/// to 145 cm from its axis; its head circles the beacon twice a beacon — pan ±0.45 rad and tilt
/// ±0.4 rad about looking at the bands' boundary, about half the image's field of view — so the
/// beacon leaves the image at the left, top, right and bottom in turn, whole in between.
pub(super) fn beacon_edges(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    const EACH_S: f64 = 6.0;
    // The switch to the next beacon falls between two frames' read-outs (each spans a frame
    // interval about its time), so no frame shows two poses torn apart by the rolling shutter.
    let k = ((t_s + crate::sim::FRAME_INTERVAL_S / 2.0) / EACH_S)
        .floor()
        .rem_euclid(4.0) as usize;
    let Some(beacon) = scene.beacons.get(k).cloned() else {
        return;
    };
    let phase = TAU * t_s / (EACH_S / 2.0) + PI * j[0];
    let distance = 100.0 + 45.0 * (TAU * t_s / EACH_S + j[1]).sin();
    // From the beacon towards the field's long axis (the beacons stand beyond the side lines),
    // a little to one side by the seed.
    let away = if beacon.y_cm > 0.0 {
        -FRAC_PI_2
    } else {
        FRAC_PI_2
    } + 0.3 * j[2];
    let pose = RobotPose::new(
        beacon.x_cm + (beacon.radius_cm + distance) * away.cos(),
        beacon.y_cm + (beacon.radius_cm + distance) * away.sin(),
        away + PI,
    );
    let body = BodyPose::ERS7_STANCE;
    let boundary = beacon.base_height_cm + beacon.band_height_cm;
    let mut joints = look_at(
        &pose,
        &body,
        &Point::new(beacon.x_cm, beacon.y_cm, boundary),
    );
    joints.pan_rad += 0.45 * phase.cos();
    // Up and down with the lower tilt (whose motion the readings carry, so the rolling
    // shutter's skew can be removed), the nod holding the head up at the bands.
    joints.tilt2_rad = 0.45;
    joints.tilt1_rad = (-0.35 + 0.4 * phase.sin()).min(0.0);
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
    scene.ball = Some(Ball::at(
        pose.x_cm + 40.0 * away.cos(),
        pose.y_cm + 40.0 * away.sin(),
    ));
}

/// Fast head pans past a close ball.
pub(super) fn close_pans(scene: &mut Scene, t_s: f64, j: [f64; 4], seed: u64) {
    // A new ball spot each pan cycle, switched while the head looks away (pan
    // phase −90°): 36–66 cm ahead of the body centre, a little to the left. The
    // period is not a whole number of frames, so the ball is caught at many phases.
    const SPOTS_CM: [f64; 7] = [40.0, 50.0, 60.0, 36.0, 45.0, 66.0, 55.0];
    let period = 1.27;
    let cycle = ((t_s - 0.9) / period).floor();
    #[expect(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "small, clamped to ≥ 0"
    )]
    let k = (cycle + 1.0).max(0.0) as usize + usize::try_from(seed % 7).unwrap_or(0);
    let d = SPOTS_CM[k % SPOTS_CM.len()] + 2.0 * j[0];
    let bearing = 0.25 + 0.05 * j[1];
    let pose = RobotPose::new(-60.0, 20.0, 0.0);
    let ball = Ball::at(pose.x_cm + d * bearing.cos(), pose.y_cm + d * bearing.sin());
    scene.ball = Some(ball);
    let body = BodyPose::ERS7_STANCE;
    let track = look_at(&pose, &body, &Point::new(ball.x_cm, ball.y_cm, 4.25));
    let joints = HeadJoints {
        pan_rad: track.pan_rad + 0.9 * (TAU * t_s / period).sin(),
        ..track
    };
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
}

/// A standing robot with a still head watches the ball roll across its view.
pub(super) fn rolling_ball(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    let pose = RobotPose::new(-100.0, 0.0, 0.0);
    let (x, y) = rolling_pass(t_s + 0.2 * j[0]);
    scene.ball = Some(Ball::at(pose.x_cm + x, pose.y_cm + y));
    let body = BodyPose::ERS7_STANCE;
    let joints = look_at(&pose, &body, &Point::new(pose.x_cm + 65.0, 0.0, 4.25));
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
}

/// A robot walks round the centre panning past the six pattern markers.
pub(super) fn pattern_tour(scene: &mut Scene, t_s: f64, j: [f64; 4]) {
    scene.markers = pattern_markers();
    // An ellipse round the centre, facing outwards, one lap in 16 s; the seed moves
    // the start, the size of the ellipse and the pan's phase.
    let angle = TAU * t_s / 16.0 + PI * j[0];
    let (rx, ry) = (110.0 + 15.0 * j[1], 70.0 + 10.0 * j[2]);
    let (x, y) = (rx * angle.cos(), ry * angle.sin());
    let pose = RobotPose::new(x, y, y.atan2(x));
    let body = walking_body(t_s, true);
    let joints = HeadJoints {
        tilt1_rad: -0.05,
        pan_rad: 1.3 * (TAU * t_s / 3.0 + j[3]).sin(),
        tilt2_rad: 0.1,
    };
    scene.ball = Some(Ball::at(-30.0 + 20.0 * j[1], 40.0));
    scene
        .robots
        .push(robot(OBSERVER_ID, Team::Red, pose, body, joints));
    scene
        .robots
        .push(standing(4, Team::Blue, 160.0, -100.0, 2.5));
}

/// The rolling ball's position relative to the observer (cm, x ahead, y left) at `t_s`: a
/// cycle of five passes, each a straight roll of 140 cm across the view at its own speed
/// (1–3 m/s), distance ahead and direction, alternating left-to-right and right-to-left. The
/// ball jumps between passes while outside the image.
fn rolling_pass(t_s: f64) -> (f64, f64) {
    const SPEED_CM_S: [f64; 5] = [100.0, 200.0, 300.0, 150.0, 250.0];
    const AHEAD_CM: [f64; 5] = [55.0, 70.0, 50.0, 85.0, 60.0];
    const ANGLE_RAD: [f64; 5] = [0.0, 0.4, -0.3, 0.2, -0.5];
    const LENGTH_CM: f64 = 140.0;
    let cycle: f64 = SPEED_CM_S.iter().map(|v| LENGTH_CM / v).sum();
    let mut t = t_s.rem_euclid(cycle);
    for (k, v) in SPEED_CM_S.iter().enumerate() {
        let duration = LENGTH_CM / v;
        if t < duration || k + 1 == SPEED_CM_S.len() {
            // Travelled along the path, centred on the pass's mid-point.
            let along = v * t.min(duration) - LENGTH_CM / 2.0;
            let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
            let (s, c) = ANGLE_RAD[k].sin_cos();
            // Direction: across the view (±y), turned by the pass's angle.
            let (dx, dy) = (sign * s, sign * c);
            return (AHEAD_CM[k] + along * dx, along * dy);
        }
        t -= duration;
    }
    (AHEAD_CM[0], 0.0)
}

pub(super) fn robot(
    id: u32,
    team: Team,
    pose: RobotPose,
    body: BodyPose,
    joints: HeadJoints,
) -> Robot {
    Robot {
        id,
        team,
        pose,
        body,
        joints,
        marker: None,
    }
}

fn standing(id: u32, team: Team, x_cm: f64, y_cm: f64, heading_rad: f64) -> Robot {
    robot(
        id,
        team,
        RobotPose::new(x_cm, y_cm, heading_rad),
        BodyPose::ERS7_STANCE,
        HeadJoints {
            tilt1_rad: -0.3,
            ..HeadJoints::default()
        },
    )
}

/// The body bobbing with a 2 Hz trot while walking, still otherwise.
pub(super) fn walking_body(t_s: f64, walking: bool) -> BodyPose {
    let s = if walking { 1.0 } else { 0.0 };
    let step = TAU * 2.0 * t_s;
    BodyPose {
        height_cm: 12.0 + s * 0.4 * step.sin(),
        pitch_rad: 0.10 + s * 0.02 * (step + 0.5).sin(),
        roll_rad: s * 0.025 * (step / 2.0).sin(),
    }
}

fn blend(a: &HeadJoints, b: &HeadJoints, w: f64) -> HeadJoints {
    HeadJoints {
        tilt1_rad: a.tilt1_rad + (b.tilt1_rad - a.tilt1_rad) * w,
        pan_rad: a.pan_rad + (b.pan_rad - a.pan_rad) * w,
        tilt2_rad: a.tilt2_rad + (b.tilt2_rad - a.tilt2_rad) * w,
    }
}

/// The pattern tour's six markers beside the field, each facing into it: two on each side line
/// and one beside each goal. North-west and north-east differ only in their top-left and
/// bottom-right tiles, south-west and south-east only in the middle row's outer tiles (swapped),
/// so those pairs agree on seven of nine regions: one short of a match. Yellow and sky blue only
/// ever sit left or right of the pink tile: above, below or at a corner the beacon recogniser
/// takes the pair for a beacon. No two neighbouring tiles share a colour, and there is no green
/// (the tables were never shown carpet on an upright face) and no orange (the ball).
#[must_use]
pub fn pattern_markers() -> Vec<Marker> {
    use crate::model::scene::Material::{
        Pink as P, RobotBlack as K, SkyBlue as B, UniformDarkBlue as D,
    };
    use crate::model::scene::Material::{UniformRed as R, White as W, Yellow as Y};
    let marker = |name: &str, x_cm: f64, y_cm: f64, facing_rad: f64, tiles| Marker {
        name: name.to_owned(),
        x_cm,
        y_cm,
        centre_height_cm: 25.0,
        facing_rad,
        tile_cm: 8.0,
        tiles,
    };
    vec![
        marker(
            "north_west",
            -90.0,
            225.0,
            -FRAC_PI_2,
            [W, K, R, Y, P, B, D, R, W],
        ),
        marker(
            "north_east",
            90.0,
            225.0,
            -FRAC_PI_2,
            [D, K, R, Y, P, B, D, R, K],
        ),
        marker(
            "south_west",
            -90.0,
            -225.0,
            FRAC_PI_2,
            [R, W, K, B, P, Y, K, D, R],
        ),
        marker(
            "south_east",
            90.0,
            -225.0,
            FRAC_PI_2,
            [R, W, K, Y, P, B, K, D, R],
        ),
        marker("blue_goal", -330.0, 90.0, 0.0, [K, R, D, W, P, Y, R, W, D]),
        marker("yellow_goal", 330.0, -90.0, PI, [D, W, R, K, P, W, W, K, D]),
    ]
}

/// Off-field things in ball and goal colours: an orange chair, an orange ball-sized sphere on
/// the table, a yellow box, an orange bag.
fn orange_clutter() -> Vec<Clutter> {
    vec![
        Clutter {
            name: "orange chair".to_owned(),
            shape: Shape::Box {
                length_cm: 45.0,
                width_cm: 45.0,
                height_cm: 45.0,
            },
            position_cm: [150.0, 265.0, 0.0],
            yaw_rad: 0.3,
            material: Material::ClutterOrange,
        },
        Clutter {
            name: "orange toy ball".to_owned(),
            shape: Shape::Sphere { radius_cm: 6.0 },
            position_cm: [80.0, 320.0, 75.0],
            yaw_rad: 0.0,
            material: Material::ClutterOrange,
        },
        Clutter {
            name: "yellow box".to_owned(),
            shape: Shape::Box {
                length_cm: 40.0,
                width_cm: 30.0,
                height_cm: 30.0,
            },
            position_cm: [40.0, 250.0, 0.0],
            yaw_rad: -0.2,
            material: Material::ClutterYellow,
        },
        Clutter {
            name: "orange bag".to_owned(),
            shape: Shape::Cylinder {
                radius_cm: 12.0,
                height_cm: 25.0,
            },
            position_cm: [230.0, 240.0, 0.0],
            yaw_rad: 0.0,
            material: Material::ClutterOrange,
        },
    ]
}
