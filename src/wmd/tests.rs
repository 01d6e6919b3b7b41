use super::*;
use crate::geometry::{MarkerIdentity, MarkerTeam};
use crate::model::world_model::{Seen, SelfEstimate};

fn key(team: MarkerTeam, id: u8) -> RobotKey {
    RobotKey {
        team,
        identity: MarkerIdentity::new(id).expect("id"),
    }
}

fn model(k: RobotKey, x: f64, y: f64, heading: f64) -> WorldModelMessage {
    WorldModelMessage {
        robot: k,
        own: SelfEstimate {
            x_cm: x,
            y_cm: y,
            heading_rad: heading,
            sd_cm: None,
            sd_heading_rad: None,
        },
        ball: Some([100.0, 30.0]),
        time_ns: None,
        seen: vec![
            Seen {
                object: SeenObject::YellowGoal,
                distance_cm: 280.0,
                bearing_rad: 0.1,
            },
            Seen {
                object: SeenObject::Ball,
                distance_cm: 100.0,
                bearing_rad: 0.0,
            },
            Seen {
                object: SeenObject::Landmark("nowhere".into()),
                distance_cm: 5.0,
                bearing_rad: 0.0,
            },
        ],
    }
}

fn view() -> OverheadView {
    OverheadView {
        ball: Some([100.0, 0.0]),
        robots: vec![
            OverheadRobotPose {
                key: key(MarkerTeam::Blue, 3),
                field_cm: [0.0, 0.0],
                heading_rad: 0.0,
            },
            OverheadRobotPose {
                key: key(MarkerTeam::Yellow, 9),
                field_cm: [-100.0, 50.0],
                heading_rad: 3.0,
            },
        ],
    }
}

#[test]
fn a_world_model_is_matched_by_its_marker_and_measured() {
    let targets = Targets::from_field(&FieldDescription::four_legged_2005());
    let m = model(key(MarkerTeam::Blue, 3), 30.0, 40.0, 0.2);
    let c = &compare(&view(), &[&m], &targets)[0];
    assert_eq!(c.matched, Matched::Marker);
    assert_eq!(c.overhead_robot, Some(key(MarkerTeam::Blue, 3)));
    assert!((c.position_error_cm.unwrap() - 50.0).abs() < 1e-9);
    assert!((c.heading_error_deg.unwrap() - 0.2_f64.to_degrees()).abs() < 1e-9);
    assert!((c.ball_error_cm.unwrap() - 30.0).abs() < 1e-9);
    // The yellow goal's mouth is at (270, 0): 270 cm straight ahead.
    let goal = &c.measurements[0];
    assert_eq!(goal.object, "yellow_goal");
    assert!((goal.true_cm.unwrap() - 270.0).abs() < 1e-9);
    assert!((goal.error_cm.unwrap() - 10.0).abs() < 1e-9);
    assert!((goal.bearing_error_deg.unwrap() - 0.1_f64.to_degrees()).abs() < 1e-9);
    assert!((c.measurements[1].error_cm.unwrap()).abs() < 1e-9);
    assert_eq!(
        c.measurements[2].true_cm, None,
        "not a landmark of the field"
    );
}

#[test]
fn without_its_marker_a_world_model_takes_the_nearest_unclaimed_robot() {
    let targets = Targets::default();
    // Blue 5's marker is not read; yellow 9 is claimed by its own world model; blue 3 is free.
    let lost = model(key(MarkerTeam::Blue, 5), 20.0, 0.0, 0.0);
    let nine = model(key(MarkerTeam::Yellow, 9), -100.0, 50.0, 3.0);
    let out = compare(&view(), &[&lost, &nine], &targets);
    assert_eq!(out[0].matched, Matched::Position);
    assert_eq!(out[0].overhead_robot, Some(key(MarkerTeam::Blue, 3)));
    assert_eq!(out[1].matched, Matched::Marker);
    // Too far from any free robot: unmatched, no errors but the ball's.
    let far = model(key(MarkerTeam::Blue, 5), 250.0, 0.0, 0.0);
    let three = model(key(MarkerTeam::Blue, 3), 0.0, 0.0, 0.0);
    let out = compare(&view(), &[&far, &three], &targets);
    assert_eq!(out[0].matched, Matched::Unmatched);
    assert_eq!(out[0].position_error_cm, None);
    assert!(out[0].ball_error_cm.is_some());
    assert_eq!(out[0].measurements[0].true_cm, None);
}

#[test]
fn angles_differ_the_short_way_round() {
    assert!((angle_diff(3.1, -3.1) - (6.2 - std::f64::consts::TAU)).abs() < 1e-12);
    assert!((angle_diff(-3.1, 3.1) - (std::f64::consts::TAU - 6.2)).abs() < 1e-12);
    assert!((angle_diff(0.5, 0.2) - 0.3).abs() < 1e-12);
}
