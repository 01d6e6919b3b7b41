//! The field as Foxglove draws it: one `foxglove.SceneUpdate` per field frame, so a World
//! Model Debugger session recording (`eotn wmd -o`) shows the game in Foxglove's 3D panel
//! without eotn. Plain data in (the field description, what the overhead cameras saw, the world
//! models paired with the frame), the message out.
//!
//! Everything is in the frame [`SCENE_FRAME_ID`]: field coordinates in metres (Foxglove's
//! unit), origin at the centre spot, x towards the yellow goal, y left, z up. Entities:
//! `field` (the painted lines and arcs), `ball` (a sphere where the cameras saw it),
//! `robot/TEAM/ID` (each robot the cameras read: a cylinder in its team's colour and an arrow
//! along its heading, its marker as a label) and `world_model/TEAM/ID` (each robot's own
//! estimate: a grey arrow, a line to the overhead robot it was compared with, its ball as a
//! small grey sphere). Each entity lives for [`ENTITY_LIFETIME_NS`], so a robot that is no
//! longer seen disappears by itself.

use foxglove::messages::{
    ArrowPrimitive, Color, CylinderPrimitive, Duration, KeyValuePair, LinePrimitive, Point3, Pose,
    Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, TextPrimitive, Timestamp, Vector3,
    line_primitive,
};

use super::{Comparison, OverheadView, WorldModelMessage};
use crate::geometry::MarkerTeam;
use crate::overhead::FieldDescription;

/// The coordinate frame every entity is drawn in (field coordinates, metres).
pub const SCENE_FRAME_ID: &str = "field";

/// How long an entity stays without being sent again, nanoseconds (a third of a second: ten
/// frames at 30 fps).
pub const ENTITY_LIFETIME_NS: u64 = 333_333_333;

/// Height of a robot's cylinder, metres (about an ERS-7's or a small-size robot's).
const ROBOT_HEIGHT_M: f64 = 0.25;
/// Diameter of a robot's cylinder, metres (the marker plate's 30 cm).
const ROBOT_DIAMETER_M: f64 = 0.30;
/// Points per full circle of a painted arc.
const ARC_POINTS: f64 = 72.0;

fn cm(v: f64) -> f64 {
    v / 100.0
}

fn timestamp(time_ns: u64) -> Timestamp {
    let sec = u32::try_from(time_ns / 1_000_000_000).unwrap_or(u32::MAX);
    let nsec = (time_ns % 1_000_000_000) as u32;
    Timestamp::new(sec, nsec)
}

fn lifetime() -> Duration {
    #[expect(clippy::cast_possible_truncation, reason = "below 1e9")]
    Duration::new(0, ENTITY_LIFETIME_NS as u32)
}

const fn rgba(r: f64, g: f64, b: f64, a: f64) -> Color {
    Color { r, g, b, a }
}

fn team_colour(team: MarkerTeam) -> Color {
    match team {
        MarkerTeam::Blue => rgba(0.25, 0.6, 1.0, 1.0),
        MarkerTeam::Yellow => rgba(1.0, 0.85, 0.1, 1.0),
    }
}

/// A pose at field `[x, y]` centimetres, `z` metres, turned `heading_rad` about z.
fn pose(field_cm: [f64; 2], z_m: f64, heading_rad: f64) -> Pose {
    let half = heading_rad / 2.0;
    Pose {
        position: Some(Vector3 {
            x: cm(field_cm[0]),
            y: cm(field_cm[1]),
            z: z_m,
        }),
        orientation: Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: half.sin(),
            w: half.cos(),
        }),
    }
}

fn point(field_cm: [f64; 2], z_m: f64) -> Point3 {
    Point3 {
        x: cm(field_cm[0]),
        y: cm(field_cm[1]),
        z: z_m,
    }
}

fn entity(time_ns: u64, id: String) -> SceneEntity {
    SceneEntity {
        timestamp: Some(timestamp(time_ns)),
        frame_id: SCENE_FRAME_ID.to_owned(),
        id,
        lifetime: Some(lifetime()),
        ..SceneEntity::default()
    }
}

fn arrow(at: Pose, length_m: f64, colour: Color) -> ArrowPrimitive {
    ArrowPrimitive {
        pose: Some(at),
        shaft_length: length_m * 0.7,
        shaft_diameter: 0.04,
        head_length: length_m * 0.3,
        head_diameter: 0.1,
        color: Some(colour),
    }
}

/// The painted lines and arcs of `field`, as one line list.
fn field_entity(time_ns: u64, field: &FieldDescription) -> SceneEntity {
    let mut points = Vec::new();
    for l in &field.lines {
        points.push(point(l.from_cm, 0.0));
        points.push(point(l.to_cm, 0.0));
    }
    for a in &field.arcs {
        let span = a.to_rad - a.from_rad;
        #[expect(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            reason = "a span of at most one turn: at most 72 steps"
        )]
        let steps = ((span / std::f64::consts::TAU * ARC_POINTS).ceil() as usize).max(2);
        let at = |k: usize| {
            let t = a.from_rad + span * k as f64 / steps as f64;
            [
                a.centre_cm[0] + a.radius_cm * t.cos(),
                a.centre_cm[1] + a.radius_cm * t.sin(),
            ]
        };
        for k in 0..steps {
            points.push(point(at(k), 0.0));
            points.push(point(at(k + 1), 0.0));
        }
    }
    let mut e = entity(time_ns, "field".to_owned());
    e.lines.push(LinePrimitive {
        r#type: line_primitive::Type::LineList as i32,
        pose: Some(pose([0.0, 0.0], 0.0, 0.0)),
        thickness: cm(field.line_width_cm),
        scale_invariant: false,
        points,
        color: Some(rgba(1.0, 1.0, 1.0, 1.0)),
        ..LinePrimitive::default()
    });
    e
}

/// One field frame as a `foxglove.SceneUpdate` (see the module documentation): `view` what the
/// overhead cameras saw at `time_ns`, `models` the world models paired with it and
/// `comparisons` their comparison (in the same order, as [`super::compare`] gives them).
#[must_use]
pub fn scene_update(
    time_ns: u64,
    field: &FieldDescription,
    view: &OverheadView,
    models: &[&WorldModelMessage],
    comparisons: &[Comparison],
) -> SceneUpdate {
    let mut entities = vec![field_entity(time_ns, field)];
    if let Some(b) = view.ball {
        let d = 2.0 * cm(field.ball_radius_cm);
        let mut e = entity(time_ns, "ball".to_owned());
        e.spheres.push(SpherePrimitive {
            pose: Some(pose(b, d / 2.0, 0.0)),
            size: Some(Vector3 { x: d, y: d, z: d }),
            color: Some(rgba(1.0, 0.45, 0.0, 1.0)),
        });
        entities.push(e);
    }
    for r in &view.robots {
        let name = format!("{} {}", r.key.team.name(), r.key.identity.value());
        let mut e = entity(
            time_ns,
            format!("robot/{}/{}", r.key.team.name(), r.key.identity.value()),
        );
        let colour = team_colour(r.key.team);
        e.cylinders.push(CylinderPrimitive {
            pose: Some(pose(r.field_cm, ROBOT_HEIGHT_M / 2.0, r.heading_rad)),
            size: Some(Vector3 {
                x: ROBOT_DIAMETER_M,
                y: ROBOT_DIAMETER_M,
                z: ROBOT_HEIGHT_M,
            }),
            bottom_scale: 1.0,
            top_scale: 1.0,
            color: Some(colour),
        });
        e.arrows.push(arrow(
            pose(r.field_cm, ROBOT_HEIGHT_M + 0.02, r.heading_rad),
            0.4,
            colour,
        ));
        e.texts.push(TextPrimitive {
            pose: Some(pose(r.field_cm, ROBOT_HEIGHT_M + 0.2, 0.0)),
            billboard: true,
            font_size: 14.0,
            scale_invariant: true,
            color: Some(rgba(1.0, 1.0, 1.0, 1.0)),
            text: name,
        });
        entities.push(e);
    }
    for (m, c) in models.iter().zip(comparisons) {
        entities.push(world_model_entity(time_ns, m, c, view));
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// A world model's own estimate: a grey arrow, a red line to the overhead robot it was compared
/// with, its ball; its errors as the entity's metadata.
fn world_model_entity(
    time_ns: u64,
    m: &WorldModelMessage,
    c: &Comparison,
    view: &OverheadView,
) -> SceneEntity {
    let own = [m.own.x_cm, m.own.y_cm];
    let grey = rgba(0.75, 0.75, 0.75, 0.8);
    let mut e = entity(
        time_ns,
        format!(
            "world_model/{}/{}",
            m.robot.team.name(),
            m.robot.identity.value()
        ),
    );
    e.arrows
        .push(arrow(pose(own, 0.05, m.own.heading_rad), 0.4, grey));
    let overhead = c
        .overhead_robot
        .and_then(|k| view.robots.iter().find(|r| r.key == k));
    if let Some(r) = overhead {
        e.lines.push(LinePrimitive {
            r#type: line_primitive::Type::LineStrip as i32,
            pose: Some(pose([0.0, 0.0], 0.0, 0.0)),
            thickness: 0.02,
            scale_invariant: false,
            points: vec![point(own, 0.05), point(r.field_cm, 0.05)],
            color: Some(rgba(1.0, 0.2, 0.2, 0.9)),
            ..LinePrimitive::default()
        });
    }
    if let Some(b) = m.ball {
        e.spheres.push(SpherePrimitive {
            pose: Some(pose(b, 0.04, 0.0)),
            size: Some(Vector3 {
                x: 0.08,
                y: 0.08,
                z: 0.08,
            }),
            color: Some(grey),
        });
    }
    let value = |v: Option<f64>| v.map_or_else(|| "none".to_owned(), |v| format!("{v:.1}"));
    e.metadata = vec![
        KeyValuePair {
            key: "matched".to_owned(),
            value: format!("{:?}", c.matched).to_lowercase(),
        },
        KeyValuePair {
            key: "position_error_cm".to_owned(),
            value: value(c.position_error_cm),
        },
        KeyValuePair {
            key: "heading_error_deg".to_owned(),
            value: value(c.heading_error_deg),
        },
    ];
    e
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::MarkerIdentity;
    use crate::model::world_model::{RobotKey, SelfEstimate};
    use crate::wmd::{OverheadRobotPose, Targets, compare};

    #[test]
    fn a_frame_shows_the_field_ball_robots_and_world_models_in_metres() {
        let key = RobotKey {
            team: MarkerTeam::Blue,
            identity: MarkerIdentity::new(3).expect("0-15"),
        };
        let view = OverheadView {
            ball: Some([100.0, -50.0]),
            robots: vec![OverheadRobotPose {
                key,
                field_cm: [200.0, 40.0],
                heading_rad: std::f64::consts::FRAC_PI_2,
            }],
        };
        let model = WorldModelMessage {
            robot: key,
            own: SelfEstimate {
                x_cm: 230.0,
                y_cm: 0.0,
                heading_rad: 0.0,
                sd_cm: None,
                sd_heading_rad: None,
            },
            ball: None,
            time_ns: None,
            seen: Vec::new(),
        };
        let field = FieldDescription::four_legged_2005();
        let comparisons = compare(&view, &[&model], &Targets::from_field(&field));
        let s = scene_update(2_500_000_000, &field, &view, &[&model], &comparisons);
        let ids: Vec<&str> = s.entities.iter().map(|e| e.id.as_str()).collect();
        assert_eq!(ids, ["field", "ball", "robot/blue/3", "world_model/blue/3"]);
        assert!(s.entities.iter().all(|e| e.frame_id == SCENE_FRAME_ID));
        let stamp = s.entities[1].timestamp.expect("stamped");
        assert_eq!((stamp.sec(), stamp.nsec()), (2, 500_000_000));
        let field_points = &s.entities[0].lines[0].points;
        assert_eq!(field_points.len() % 2, 0);
        assert!(field_points.len() >= 2 * field.lines.len());
        let ball = s.entities[1].spheres[0].pose.and_then(|p| p.position);
        let ball = ball.expect("placed");
        assert!((ball.x - 1.0).abs() < 1e-12 && (ball.y + 0.5).abs() < 1e-12);
        let robot = &s.entities[2];
        let q = robot.arrows[0]
            .pose
            .and_then(|p| p.orientation)
            .expect("turned");
        // A quarter turn about z.
        assert!((q.z - q.w).abs() < 1e-12 && q.z > 0.0);
        assert_eq!(robot.texts[0].text, "blue 3");
        let wm = &s.entities[3];
        let line = &wm.lines[0].points;
        assert!((line[0].x - 2.3).abs() < 1e-12 && (line[1].y - 0.4).abs() < 1e-12);
        let matched = wm.metadata.iter().find(|kv| kv.key == "matched");
        assert_eq!(matched.map(|kv| kv.value.as_str()), Some("marker"));
        let error = wm.metadata.iter().find(|kv| kv.key == "position_error_cm");
        assert_eq!(error.map(|kv| kv.value.as_str()), Some("50.0"));
    }
}
