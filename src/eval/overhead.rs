//! Overhead evaluation: the overhead recogniser against the truth of synthetic overhead frames
//! (ball and robot position errors, identity and heading accuracy), and each robot's own world
//! model (docs/formats.md, "World models") against the overhead truth and against what the overhead
//! camera found.
//!
//! A robot counts for identity when its marker is fully visible (`OverheadMarkerTruth::
//! fully_visible`); a detection matches the nearest true robot within
//! [`OverheadEvalParams::match_cm`].

use serde::{Deserialize, Serialize};

use super::Percentiles;
use crate::geometry::{MarkerIdentity, MarkerTeam};
use crate::model::truth::OverheadTruth;
use crate::model::world_model::WorldModelMessage;
use crate::overhead::OverheadDetections;

/// Matching rules.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OverheadEvalParams {
    /// A detection within this of a true robot or ball matches it, centimetres.
    pub match_cm: f64,
    /// The ball must be found when at least this many of its pixels show.
    pub ball_min_pixels: usize,
}

impl Default for OverheadEvalParams {
    fn default() -> Self {
        Self {
            match_cm: 15.0,
            ball_min_pixels: 30,
        }
    }
}

/// One frame's comparison.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct OverheadFrameEval {
    /// Frame index (over all streams).
    pub frame: usize,
    /// The ball showed enough to be found.
    pub ball_eligible: bool,
    /// Position error of a matched ball, centimetres.
    pub ball_error_cm: Option<f64>,
    /// A ball was reported far from the true one (or with none there).
    pub ball_false: bool,
    /// Robots whose marker is fully visible.
    pub robots_eligible: usize,
    /// Of those, matched by a detection.
    pub robots_found: usize,
    /// Of those, with team and identity right.
    pub identity_right: usize,
    /// Position errors of matched robots (any visibility), centimetres.
    pub robot_errors_cm: Vec<f64>,
    /// Heading errors of matched fully visible robots, degrees (absolute).
    pub heading_errors_deg: Vec<f64>,
    /// Detections matching no true robot.
    pub robots_false: usize,
    /// Fully visible robots read with the wrong team or identity: `(true, read)`.
    pub wrong_identities: Vec<(String, String)>,
}

/// `a − b` wrapped into [−π, π), radians.
pub(super) fn angle_diff(a: f64, b: f64) -> f64 {
    (a - b + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// A marker as `eval` names it (`blue 3`).
pub(super) fn label(team: MarkerTeam, id: MarkerIdentity) -> String {
    format!("{} {id}", team.name())
}

/// Compares one frame's detections with its truth.
#[must_use]
pub fn evaluate_overhead_frame(
    frame: usize,
    detections: &OverheadDetections,
    truth: &OverheadTruth,
    params: &OverheadEvalParams,
) -> OverheadFrameEval {
    let mut e = OverheadFrameEval {
        frame,
        ..OverheadFrameEval::default()
    };
    match (&truth.ball, &detections.ball) {
        (Some(t), Some(d)) => {
            e.ball_eligible = t.visible_pixels >= params.ball_min_pixels;
            let err = dist(t.field_cm, d.field_cm);
            if err <= params.match_cm {
                e.ball_error_cm = Some(err);
            } else {
                e.ball_false = true;
            }
        }
        (Some(t), None) => e.ball_eligible = t.visible_pixels >= params.ball_min_pixels,
        (None, Some(_)) => e.ball_false = true,
        (None, None) => {}
    }
    let mut used = vec![false; detections.robots.len()];
    for t in &truth.robots {
        let Some(marker) = t.marker else { continue };
        let eligible = marker.fully_visible();
        e.robots_eligible += usize::from(eligible);
        let positions = detections.robots.iter().map(|d| d.field_cm);
        let Some((k, err)) = nearest_unused(positions, &used, t.field_cm, params.match_cm) else {
            continue;
        };
        used[k] = true;
        let d = &detections.robots[k];
        e.robot_errors_cm.push(err);
        if eligible {
            e.robots_found += 1;
            e.heading_errors_deg
                .push(angle_diff(d.heading_rad, t.heading_rad).abs().to_degrees());
            if d.team == marker.team && d.identity == marker.identity {
                e.identity_right += 1;
            } else {
                e.wrong_identities.push((
                    label(marker.team, marker.identity),
                    label(d.team, d.identity),
                ));
            }
        }
    }
    e.robots_false = used.iter().filter(|u| !**u).count();
    e
}

/// A robot's world-model estimate compared with the truth and with the overhead detection of
/// the same robot.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct WorldModelFrameEval {
    /// Robot id.
    pub robot_id: u32,
    /// Its own position estimate's error against the truth, centimetres.
    pub self_error_cm: Option<f64>,
    /// Its own heading estimate's error against the truth, degrees (absolute).
    pub heading_error_deg: Option<f64>,
    /// Its ball estimate's error against the true ball, centimetres.
    pub ball_error_cm: Option<f64>,
    /// Its own position estimate's error against the overhead detection of its marker,
    /// centimetres (what the debugger shows when there is no truth).
    pub self_error_vs_overhead_cm: Option<f64>,
    /// Its own heading estimate's error against the overhead detection of its marker,
    /// degrees (absolute).
    pub heading_error_vs_overhead_deg: Option<f64>,
    /// Its ball estimate's error against the ball the overhead camera found, centimetres.
    pub ball_error_vs_overhead_cm: Option<f64>,
}

/// Compares one world-model message with the frame's truth and detections; `None` when no
/// robot of the truth wears the marker it names. Its `robot_id` in the result is the truth's
/// robot number.
#[must_use]
pub fn evaluate_world_model(
    model: &WorldModelMessage,
    truth: &OverheadTruth,
    detections: Option<&OverheadDetections>,
) -> Option<WorldModelFrameEval> {
    let t = truth.robots.iter().find(|r| {
        r.marker
            .is_some_and(|m| m.team == model.robot.team && m.identity == model.robot.identity)
    })?;
    let own = [model.own.x_cm, model.own.y_cm];
    let overhead = t.marker.and_then(|m| {
        detections?
            .robots
            .iter()
            .find(|d| d.team == m.team && d.identity == m.identity)
    });
    Some(WorldModelFrameEval {
        robot_id: t.id,
        self_error_cm: Some(dist(own, t.field_cm)),
        heading_error_deg: Some(
            angle_diff(model.own.heading_rad, t.heading_rad)
                .abs()
                .to_degrees(),
        ),
        ball_error_cm: match (&model.ball, &truth.ball) {
            (Some(b), Some(tb)) => Some(dist(*b, tb.field_cm)),
            _ => None,
        },
        self_error_vs_overhead_cm: overhead.map(|d| dist(own, d.field_cm)),
        heading_error_vs_overhead_deg: overhead.map(|d| {
            angle_diff(model.own.heading_rad, d.heading_rad)
                .abs()
                .to_degrees()
        }),
        ball_error_vs_overhead_cm: match (&model.ball, detections.and_then(|d| d.ball.as_ref())) {
            (Some(b), Some(seen)) => Some(dist(*b, seen.field_cm)),
            _ => None,
        },
    })
}

/// World-model errors of one robot over a stream.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct WorldModelReport {
    /// Robot id.
    pub robot_id: u32,
    /// Self position error against the truth, centimetres.
    pub self_error_cm: Option<Percentiles>,
    /// Heading error, degrees.
    pub heading_error_deg: Option<Percentiles>,
    /// Ball error, centimetres.
    pub ball_error_cm: Option<Percentiles>,
    /// Self position error against the overhead detection, centimetres.
    pub self_error_vs_overhead_cm: Option<Percentiles>,
    /// Heading error against the overhead detection, degrees.
    pub heading_error_vs_overhead_deg: Option<Percentiles>,
    /// Ball error against the ball the overhead camera found, centimetres.
    pub ball_error_vs_overhead_cm: Option<Percentiles>,
}

/// The whole overhead evaluation.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct OverheadEvalReport {
    /// Frames compared.
    pub frames: usize,
    /// Frames whose ball had to be found.
    pub ball_eligible: usize,
    /// Of those, found (matched).
    pub ball_found: usize,
    /// Frames with a false ball.
    pub ball_false: usize,
    /// Ball position error, centimetres.
    pub ball_error_cm: Option<Percentiles>,
    /// Robot markers fully visible (robot-frames).
    pub robots_eligible: usize,
    /// Of those, found.
    pub robots_found: usize,
    /// Of those, read with the right team and identity.
    pub identity_right: usize,
    /// `identity_right / robots_eligible`.
    pub identity_rate: Option<f64>,
    /// Robot position error, centimetres.
    pub robot_error_cm: Option<Percentiles>,
    /// Heading error, degrees.
    pub heading_error_deg: Option<Percentiles>,
    /// Detections matching no robot.
    pub robots_false: usize,
    /// The first few wrong identities: `(true, read)`.
    pub wrong_identities: Vec<(String, String)>,
    /// Per robot: its world model against the truth.
    pub world_models: Vec<WorldModelReport>,
}

impl OverheadEvalReport {
    /// Sums frames and world-model comparisons.
    #[must_use]
    pub fn from_frames(frames: &[OverheadFrameEval], models: &[WorldModelFrameEval]) -> Self {
        let ball: Vec<f64> = frames.iter().filter_map(|f| f.ball_error_cm).collect();
        let robots: Vec<f64> = frames
            .iter()
            .flat_map(|f| f.robot_errors_cm.clone())
            .collect();
        let headings: Vec<f64> = frames
            .iter()
            .flat_map(|f| f.heading_errors_deg.clone())
            .collect();
        let sum = |g: fn(&OverheadFrameEval) -> usize| frames.iter().map(g).sum::<usize>();
        let eligible = sum(|f| f.robots_eligible);
        let right = sum(|f| f.identity_right);
        let mut ids: Vec<u32> = models.iter().map(|m| m.robot_id).collect();
        ids.sort_unstable();
        ids.dedup();
        let world_models = ids
            .into_iter()
            .map(|id| {
                let of = |g: fn(&WorldModelFrameEval) -> Option<f64>| {
                    let v: Vec<f64> = models
                        .iter()
                        .filter(|m| m.robot_id == id)
                        .filter_map(g)
                        .collect();
                    Percentiles::of(&v)
                };
                WorldModelReport {
                    robot_id: id,
                    self_error_cm: of(|m| m.self_error_cm),
                    heading_error_deg: of(|m| m.heading_error_deg),
                    ball_error_cm: of(|m| m.ball_error_cm),
                    self_error_vs_overhead_cm: of(|m| m.self_error_vs_overhead_cm),
                    heading_error_vs_overhead_deg: of(|m| m.heading_error_vs_overhead_deg),
                    ball_error_vs_overhead_cm: of(|m| m.ball_error_vs_overhead_cm),
                }
            })
            .collect();
        Self {
            frames: frames.len(),
            ball_eligible: frames.iter().filter(|f| f.ball_eligible).count(),
            ball_found: frames
                .iter()
                .filter(|f| f.ball_eligible && f.ball_error_cm.is_some())
                .count(),
            ball_false: frames.iter().filter(|f| f.ball_false).count(),
            ball_error_cm: Percentiles::of(&ball),
            robots_eligible: eligible,
            robots_found: sum(|f| f.robots_found),
            identity_right: right,
            identity_rate: (eligible > 0).then(|| right as f64 / eligible as f64),
            robot_error_cm: Percentiles::of(&robots),
            heading_error_deg: Percentiles::of(&headings),
            robots_false: sum(|f| f.robots_false),
            wrong_identities: frames
                .iter()
                .flat_map(|f| f.wrong_identities.clone())
                .take(20)
                .collect(),
            world_models,
        }
    }
}

/// Distance between two field positions (centimetres).
pub(super) fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The detection nearest `target` among `positions` not yet `used`, if within `max_cm`: its
/// index and distance (centimetres). Truth and detections are paired one to one this way.
pub(super) fn nearest_unused(
    positions: impl Iterator<Item = [f64; 2]>,
    used: &[bool],
    target: [f64; 2],
    max_cm: f64,
) -> Option<(usize, f64)> {
    positions
        .enumerate()
        .filter(|(k, _)| !used.get(*k).copied().unwrap_or(true))
        .map(|(k, p)| (k, dist(p, target)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .filter(|(_, err)| *err <= max_cm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{ImagePoint, OverheadCamera};
    use crate::model::scene::Team;
    use crate::model::truth::{OverheadMarkerTruth, OverheadObject, OverheadRobot as TruthRobot};
    use crate::overhead::recognise::{OverheadBall, OverheadRobot};

    fn truth() -> OverheadTruth {
        let marker = |id| OverheadMarkerTruth {
            team: MarkerTeam::Blue,
            identity: MarkerIdentity::new(id).expect("in range"),
            plate_height_cm: 22.5,
            image: None,
            visible_fraction: 1.0,
        };
        let robot = |id, x| TruthRobot {
            id,
            team: Team::Blue,
            field_cm: [x, 0.0],
            heading_rad: 0.5,
            image: None,
            visible_pixels: 500,
            marker: Some(marker(id as u8)),
        };
        OverheadTruth {
            time_s: 0.0,
            camera: OverheadCamera::above_field_2005(),
            ball: Some(OverheadObject {
                field_cm: [10.0, 10.0],
                image: None,
                visible_pixels: 80,
            }),
            robots: vec![robot(1, -100.0), robot(2, 100.0)],
        }
    }

    fn detected(id: u8, x: f64, heading: f64) -> OverheadRobot {
        OverheadRobot {
            team: MarkerTeam::Blue,
            identity: MarkerIdentity::new(id).expect("in range"),
            field_cm: [x, 0.0],
            heading_rad: heading,
            image: ImagePoint::default(),
            dots: [ImagePoint::default(); 4],
            confidence: 1.0,
        }
    }

    #[test]
    fn matched_robots_score_position_heading_and_identity() {
        let d = OverheadDetections {
            ball: Some(OverheadBall {
                field_cm: [13.0, 14.0],
                image: ImagePoint::default(),
                radius_px: 5.0,
                confidence: 1.0,
            }),
            robots: vec![
                detected(1, -98.0, 0.5 + 0.1),
                detected(7, 101.0, 0.5),
                detected(3, 0.0, 0.0),
            ],
            rejected: Vec::new(),
        };
        let e = evaluate_overhead_frame(0, &d, &truth(), &OverheadEvalParams::default());
        assert_eq!(e.ball_error_cm, Some(5.0));
        assert_eq!(
            (e.robots_eligible, e.robots_found, e.identity_right),
            (2, 2, 1)
        );
        assert_eq!(e.robots_false, 1);
        assert_eq!(e.wrong_identities, vec![("blue 2".into(), "blue 7".into())]);
        assert!((e.heading_errors_deg[0] - 0.1f64.to_degrees()).abs() < 1e-9);
        let report = OverheadEvalReport::from_frames(&[e], &[]);
        assert_eq!(report.identity_rate, Some(0.5));
        assert_eq!(report.ball_found, 1);
    }

    #[test]
    fn a_world_model_is_scored_against_truth_and_overhead() {
        let model = crate::model::world_model::from_value(&serde_json::json!({
            "robot_id": 2, "team": "blue",
            "self": {"x_cm": 103.0, "y_cm": 4.0, "heading_rad": 0.4, "sd_cm": 17.0},
            "ball": {"x_cm": 10.0, "y_cm": 0.0, "sd_cm": 25.0}
        }))
        .expect("a world model");
        let mut d = OverheadDetections {
            robots: vec![detected(2, 100.0, 0.5)],
            ..OverheadDetections::default()
        };
        let e = evaluate_world_model(&model, &truth(), Some(&d)).expect("robot 2 is there");
        assert!((e.self_error_cm.expect("error") - 5.0).abs() < 1e-9);
        assert!((e.ball_error_cm.expect("error") - 10.0).abs() < 1e-9);
        assert!((e.self_error_vs_overhead_cm.expect("error") - 5.0).abs() < 1e-9);
        let heading = e.heading_error_vs_overhead_deg.expect("seen overhead");
        assert!((heading - 0.1f64.to_degrees()).abs() < 1e-9, "{heading}");
        // No ball overhead: nothing to compare; a ball 6-8-10 away from the model's.
        assert_eq!(e.ball_error_vs_overhead_cm, None);
        d.ball = Some(OverheadBall {
            field_cm: [16.0, 8.0],
            image: ImagePoint::default(),
            radius_px: 5.0,
            confidence: 1.0,
        });
        let e = evaluate_world_model(&model, &truth(), Some(&d)).expect("robot 2 is there");
        assert!((e.ball_error_vs_overhead_cm.expect("error") - 10.0).abs() < 1e-9);
        assert!(
            evaluate_world_model(
                &WorldModelMessage {
                    robot: crate::model::world_model::RobotKey {
                        team: MarkerTeam::Blue,
                        identity: MarkerIdentity::new(9).expect("in range"),
                    },
                    ..model
                },
                &truth(),
                None
            )
            .is_none()
        );
    }
}
