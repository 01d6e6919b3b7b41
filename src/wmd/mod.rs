//! The world-model debugger's comparison, plain data in and out: what the overhead camera saw at
//! one instant ([`OverheadView`]) beside the world models the robots sent for that instant
//! ([`WorldModelMessage`]) → for each world model, which overhead robot it is ([`Matched`]: by
//! the marker it names, by position only when that marker is not read this frame, or none) and
//! its errors: position, heading, ball, and for each `seen` measurement the true distance and
//! bearing from the overhead positions (the tape measure). [`clock`] pairs world models with
//! overhead frames in time and estimates each robot's clock offset; [`summary`] gathers each
//! robot's medians, 95th percentiles and error jumps.

pub mod clock;
pub mod scene;
pub mod summary;

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;

pub use crate::model::world_model::{RobotKey, SeenObject, WorldModelMessage};
use crate::overhead::FieldDescription;

/// Farthest a world model's own estimate may be from an overhead robot to be matched with it by
/// position, centimetres.
pub const MATCH_RADIUS_CM: f64 = 100.0;

/// One robot as the overhead camera placed it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverheadRobotPose {
    /// Its marker, as read.
    pub key: RobotKey,
    /// Field position of its marker's centre, `[x, y]` centimetres.
    pub field_cm: [f64; 2],
    /// Heading, radians counter-clockwise from +x.
    pub heading_rad: f64,
}

/// What the overhead camera saw at one instant.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OverheadView {
    /// The ball, field `[x, y]` centimetres.
    pub ball: Option<[f64; 2]>,
    /// The robots whose markers it read.
    pub robots: Vec<OverheadRobotPose>,
}

/// Where the objects a robot may measure stand, field `[x, y]` centimetres: the goals' mouth
/// centres and the field file's landmarks (their feet).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Targets {
    places: BTreeMap<String, [f64; 2]>,
}

impl Targets {
    /// The targets of a field description: `yellow_goal` and `blue_goal` are the midpoints of
    /// its `yellow goal left post foot` / `… right post foot` landmarks (and the blue ones), when
    /// it has them; every landmark on the ground (height 0) by its name.
    #[must_use]
    pub fn from_field(field: &FieldDescription) -> Self {
        let mut places = BTreeMap::new();
        for l in field.landmarks.iter().filter(|l| l.height_cm == 0.0) {
            places.insert(l.name.clone(), l.field_cm);
        }
        for colour in ["yellow", "blue"] {
            let foot = |side: &str| {
                field
                    .landmark(&format!("{colour} goal {side} post foot"))
                    .map(|l| l.field_cm)
            };
            if let (Some(a), Some(b)) = (foot("left"), foot("right")) {
                let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
                places.insert(format!("{colour}_goal"), mid);
            }
        }
        Self { places }
    }

    /// Where `object` stands; the ball is where the overhead camera saw it.
    #[must_use]
    pub fn place(&self, object: &SeenObject, view: &OverheadView) -> Option<[f64; 2]> {
        match object {
            SeenObject::Ball => view.ball,
            other => self.places.get(other.name()).copied(),
        }
    }
}

/// How a world model was paired with an overhead robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Matched {
    /// The overhead camera read the marker the world model names.
    Marker,
    /// Its marker was not read this frame: the nearest overhead robot no world model claims,
    /// within [`MATCH_RADIUS_CM`] of its own estimate.
    Position,
    /// No overhead robot for it.
    Unmatched,
}

/// One `seen` measurement against the overhead camera (the tape measure).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measurement {
    /// What was measured (`ball`, `yellow_goal`, `blue_goal`, a landmark's name).
    pub object: String,
    /// The robot's distance, centimetres.
    pub measured_cm: f64,
    /// The distance from the overhead robot to the object, centimetres; `None` when either is
    /// unknown (an unmatched robot, no ball seen from above, a name the field file lacks).
    pub true_cm: Option<f64>,
    /// `measured_cm − true_cm`, centimetres.
    pub error_cm: Option<f64>,
    /// The measured bearing minus the true one, degrees in (−180, 180].
    pub bearing_error_deg: Option<f64>,
}

/// One world model compared with the overhead camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// The robot the message names.
    pub robot: RobotKey,
    /// How it was matched.
    pub matched: Matched,
    /// The overhead robot it was compared with (by position: a different marker).
    pub overhead_robot: Option<RobotKey>,
    /// Distance from its own estimate to the overhead robot, centimetres.
    pub position_error_cm: Option<f64>,
    /// Its heading minus the overhead robot's, degrees in (−180, 180].
    pub heading_error_deg: Option<f64>,
    /// Distance from its ball estimate to the overhead ball, centimetres.
    pub ball_error_cm: Option<f64>,
    /// Its `seen` measurements against the overhead positions.
    pub measurements: Vec<Measurement>,
}

/// The signed difference `a − b` of two angles, radians in (−π, π].
#[must_use]
pub fn angle_diff(a: f64, b: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let d = (a - b).rem_euclid(TAU);
    if d > PI { d - TAU } else { d }
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Compares the world models of one instant (at most one per robot) with what the overhead
/// camera saw then. The result is in the order of `models`.
#[must_use]
pub fn compare(
    view: &OverheadView,
    models: &[&WorldModelMessage],
    targets: &Targets,
) -> Vec<Comparison> {
    let claimed: BTreeSet<RobotKey> = models.iter().map(|m| m.robot).collect();
    let mut taken: BTreeSet<RobotKey> = BTreeSet::new();
    let mut chosen: Vec<(Matched, Option<&OverheadRobotPose>)> = models
        .iter()
        .map(|m| {
            let r = view.robots.iter().find(|r| r.key == m.robot);
            if let Some(r) = r {
                taken.insert(r.key);
                (Matched::Marker, Some(r))
            } else {
                (Matched::Unmatched, None)
            }
        })
        .collect();
    for (m, choice) in models.iter().zip(&mut chosen) {
        if choice.0 == Matched::Marker {
            continue;
        }
        let own = [m.own.x_cm, m.own.y_cm];
        let nearest = view
            .robots
            .iter()
            .filter(|r| !claimed.contains(&r.key) && !taken.contains(&r.key))
            .map(|r| (distance(own, r.field_cm), r))
            .filter(|(d, _)| *d <= MATCH_RADIUS_CM)
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, r)) = nearest {
            taken.insert(r.key);
            *choice = (Matched::Position, Some(r));
        }
    }
    models
        .iter()
        .zip(chosen)
        .map(|(m, (matched, r))| compare_one(m, matched, r, view, targets))
        .collect()
}

fn compare_one(
    m: &WorldModelMessage,
    matched: Matched,
    r: Option<&OverheadRobotPose>,
    view: &OverheadView,
    targets: &Targets,
) -> Comparison {
    let own = [m.own.x_cm, m.own.y_cm];
    let measurements = m
        .seen
        .iter()
        .map(|s| {
            let truth = r.zip(targets.place(&s.object, view)).map(|(r, p)| {
                let (dx, dy) = (p[0] - r.field_cm[0], p[1] - r.field_cm[1]);
                (dx.hypot(dy), angle_diff(dy.atan2(dx), r.heading_rad))
            });
            Measurement {
                object: s.object.name().to_owned(),
                measured_cm: s.distance_cm,
                true_cm: truth.map(|t| t.0),
                error_cm: truth.map(|t| s.distance_cm - t.0),
                bearing_error_deg: truth.map(|t| angle_diff(s.bearing_rad, t.1).to_degrees()),
            }
        })
        .collect();
    Comparison {
        robot: m.robot,
        matched,
        overhead_robot: r.map(|r| r.key),
        position_error_cm: r.map(|r| distance(own, r.field_cm)),
        heading_error_deg: r.map(|r| angle_diff(m.own.heading_rad, r.heading_rad).to_degrees()),
        ball_error_cm: m.ball.zip(view.ball).map(|(a, b)| distance(a, b)),
        measurements,
    }
}

#[cfg(test)]
mod tests;
