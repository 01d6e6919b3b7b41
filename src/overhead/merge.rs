//! Several overhead cameras' detections of one instant merged into one field picture: robots
//! by identity (a robot seen by two cameras is one robot at one position), the ball by
//! confidence; and which camera frames form one field frame.
//!
//! Plain data in and out: each camera's [`OverheadDetections`] (already in field coordinates
//! through its own calibration) → [`FieldPicture`].

use crate::geometry::{MarkerIdentity, MarkerTeam};

use super::recognise::{OverheadBall, OverheadDetections};

/// The SSL `camera_id` of an overhead camera, 0–255: its number within a session (SSL-Vision's
/// `camera_id`), how merged detections name the cameras that saw them. Which camera it is —
/// its source and image topic, what its table and calibration are remembered under — is a
/// [`crate::camera::CameraId`] (`OverheadEntry::camera_id` of a session).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(transparent)]
pub struct SslCameraId(pub u8);

impl std::fmt::Display for SslCameraId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// Two detections of one identity farther apart than this (cm) are not one robot: the less
/// confident is dropped as a misreading.
pub const SAME_ROBOT_CM: f64 = 30.0;

/// Two balls closer than this (cm) are one ball seen twice.
pub const SAME_BALL_CM: f64 = 15.0;

/// The merged ball.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldBall {
    /// The most confident camera's ball.
    pub ball: OverheadBall,
    /// The camera it came from.
    pub camera: SslCameraId,
    /// Every camera whose ball agrees with it, ascending.
    pub camera_ids: Vec<SslCameraId>,
}

/// A merged robot.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldRobot {
    /// Team dot colour.
    pub team: MarkerTeam,
    /// Identity.
    pub identity: MarkerIdentity,
    /// Position, centimetres `[x, y]`: the confidence-weighted mean of the cameras' readings.
    pub field_cm: [f64; 2],
    /// Heading, radians in (−π, π]: the confidence-weighted circular mean.
    pub heading_rad: f64,
    /// The highest confidence of the readings.
    pub confidence: f64,
    /// The cameras that saw it, ascending.
    pub camera_ids: Vec<SslCameraId>,
}

/// One field frame's merged detections.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FieldPicture {
    /// The ball, if a camera saw it.
    pub ball: Option<FieldBall>,
    /// The robots, one per identity, by team then identity.
    pub robots: Vec<FieldRobot>,
}

/// Merges the detections of several cameras taken at (nearly) one instant.
#[must_use]
pub fn merge_detections(views: &[(SslCameraId, &OverheadDetections)]) -> FieldPicture {
    FieldPicture {
        ball: merge_ball(views),
        robots: merge_robots(views),
    }
}

/// One camera's detections as a field picture, unmerged: every robot it found (a misread
/// identity found twice stays twice, as the camera saw it) and its ball, each seen by `camera`
/// alone. What the field view draws for a single overhead camera.
#[must_use]
pub fn one_camera(camera: SslCameraId, d: &OverheadDetections) -> FieldPicture {
    FieldPicture {
        ball: d.ball.map(|ball| FieldBall {
            ball,
            camera,
            camera_ids: vec![camera],
        }),
        robots: d
            .robots
            .iter()
            .map(|r| FieldRobot {
                team: r.team,
                identity: r.identity,
                field_cm: r.field_cm,
                heading_rad: r.heading_rad,
                confidence: r.confidence,
                camera_ids: vec![camera],
            })
            .collect(),
    }
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn merge_ball(views: &[(SslCameraId, &OverheadDetections)]) -> Option<FieldBall> {
    let balls: Vec<(SslCameraId, OverheadBall)> = views
        .iter()
        .filter_map(|(id, d)| d.ball.map(|b| (*id, b)))
        .collect();
    let (camera, best) = *balls
        .iter()
        .max_by(|a, b| a.1.confidence.total_cmp(&b.1.confidence))?;
    let mut camera_ids: Vec<SslCameraId> = balls
        .iter()
        .filter(|(_, b)| dist(b.field_cm, best.field_cm) <= SAME_BALL_CM)
        .map(|(id, _)| *id)
        .collect();
    camera_ids.sort_unstable();
    camera_ids.dedup();
    Some(FieldBall {
        ball: best,
        camera,
        camera_ids,
    })
}

fn merge_robots(views: &[(SslCameraId, &OverheadDetections)]) -> Vec<FieldRobot> {
    let mut readings: Vec<(SslCameraId, &super::recognise::OverheadRobot)> = views
        .iter()
        .flat_map(|(id, d)| d.robots.iter().map(move |r| (*id, r)))
        .collect();
    readings.sort_by(|a, b| {
        (a.1.team.name(), a.1.identity.value())
            .cmp(&(b.1.team.name(), b.1.identity.value()))
            .then(b.1.confidence.total_cmp(&a.1.confidence))
    });
    let mut out: Vec<FieldRobot> = Vec::new();
    for group in readings.chunk_by(|a, b| a.1.team == b.1.team && a.1.identity == b.1.identity) {
        // The most confident reading first; the others join it when they agree.
        let anchor = group[0].1;
        let agree: Vec<_> = group
            .iter()
            .filter(|(_, r)| dist(r.field_cm, anchor.field_cm) <= SAME_ROBOT_CM)
            .collect();
        let total: f64 = agree.iter().map(|(_, r)| r.confidence.max(1e-6)).sum();
        let mean = |f: &dyn Fn(&super::recognise::OverheadRobot) -> f64| {
            agree
                .iter()
                .map(|(_, r)| r.confidence.max(1e-6) * f(r))
                .sum::<f64>()
                / total
        };
        let (s, c) = (
            mean(&|r| r.heading_rad.sin()),
            mean(&|r| r.heading_rad.cos()),
        );
        let mut camera_ids: Vec<SslCameraId> = agree.iter().map(|(id, _)| *id).collect();
        camera_ids.sort_unstable();
        camera_ids.dedup();
        out.push(FieldRobot {
            team: anchor.team,
            identity: anchor.identity,
            field_cm: [mean(&|r| r.field_cm[0]), mean(&|r| r.field_cm[1])],
            heading_rad: s.atan2(c),
            confidence: anchor.confidence,
            camera_ids,
        });
    }
    drop_misreadings(out)
}

/// Two robots closer than this (cm) are one robot read as two identities: marker plates are
/// 30 cm across, so two real robots are never this close.
pub const ONE_PLACE_CM: f64 = 20.0;

/// Of robots at one place with different identities (a camera misread the dots), keeps the
/// reading more cameras agree on, then the more confident; the result is by team, identity.
fn drop_misreadings(mut robots: Vec<FieldRobot>) -> Vec<FieldRobot> {
    robots.sort_by(|a, b| {
        b.camera_ids
            .len()
            .cmp(&a.camera_ids.len())
            .then(b.confidence.total_cmp(&a.confidence))
    });
    let mut kept: Vec<FieldRobot> = Vec::new();
    for r in robots {
        if kept
            .iter()
            .all(|k| dist(k.field_cm, r.field_cm) > ONE_PLACE_CM)
        {
            kept.push(r);
        }
    }
    kept.sort_by_key(|r| (r.team.name(), r.identity.value()));
    kept
}

/// The frame of a camera (times `times_ns`, ascending) that belongs to the field frame at
/// `reference_ns`: the nearest within half a frame period (`period_ns`), if any.
#[must_use]
pub fn frame_near(times_ns: &[u64], reference_ns: u64, period_ns: u64) -> Option<usize> {
    let i = times_ns.partition_point(|&t| t < reference_ns);
    let gap = |k: usize| times_ns[k].abs_diff(reference_ns);
    let best = [i.checked_sub(1), (i < times_ns.len()).then_some(i)]
        .into_iter()
        .flatten()
        .min_by_key(|&k| gap(k))?;
    (2 * gap(best) <= period_ns).then_some(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::ImagePoint;
    use crate::overhead::recognise::OverheadRobot;

    fn robot(team: MarkerTeam, id: u8, x: f64, y: f64, heading: f64, conf: f64) -> OverheadRobot {
        OverheadRobot {
            team,
            identity: MarkerIdentity::new(id).expect("id"),
            field_cm: [x, y],
            heading_rad: heading,
            image: ImagePoint::new(0.0, 0.0),
            dots: [ImagePoint::new(0.0, 0.0); 4],
            confidence: conf,
        }
    }

    fn ball(x: f64, conf: f64) -> OverheadBall {
        OverheadBall {
            field_cm: [x, 0.0],
            image: ImagePoint::new(0.0, 0.0),
            radius_px: 5.0,
            confidence: conf,
        }
    }

    #[test]
    fn a_robot_seen_by_two_cameras_is_one_robot_at_one_position() {
        let a = OverheadDetections {
            robots: vec![robot(MarkerTeam::Blue, 3, 100.0, 10.0, 3.1, 0.9)],
            ..OverheadDetections::default()
        };
        let b = OverheadDetections {
            robots: vec![
                robot(MarkerTeam::Blue, 3, 101.0, 10.0, -3.1, 0.9),
                robot(MarkerTeam::Yellow, 3, -50.0, 0.0, 0.0, 0.8),
            ],
            ..OverheadDetections::default()
        };
        let p = merge_detections(&[(SslCameraId(0), &a), (SslCameraId(4), &b)]);
        assert_eq!(p.robots.len(), 2);
        let blue = &p.robots[0];
        assert_eq!((blue.team, blue.identity.value()), (MarkerTeam::Blue, 3));
        assert!((blue.field_cm[0] - 100.5).abs() < 1e-9);
        // Headings either side of ±π average to π, not 0.
        assert!(blue.heading_rad.abs() > 3.1, "{}", blue.heading_rad);
        assert_eq!(blue.camera_ids, vec![SslCameraId(0), SslCameraId(4)]);
        assert_eq!(p.robots[1].camera_ids, vec![SslCameraId(4)]);
    }

    #[test]
    fn a_misread_identity_far_away_does_not_move_the_robot() {
        let a = OverheadDetections {
            robots: vec![robot(MarkerTeam::Blue, 3, 100.0, 10.0, 0.0, 0.95)],
            ..OverheadDetections::default()
        };
        let b = OverheadDetections {
            robots: vec![robot(MarkerTeam::Blue, 3, -200.0, 10.0, 0.0, 0.5)],
            ..OverheadDetections::default()
        };
        let p = merge_detections(&[(SslCameraId(0), &a), (SslCameraId(1), &b)]);
        assert_eq!(p.robots.len(), 1);
        assert_eq!(p.robots[0].field_cm, [100.0, 10.0]);
        assert_eq!(p.robots[0].camera_ids, vec![SslCameraId(0)]);
    }

    #[test]
    fn a_robot_read_as_two_identities_is_kept_as_the_one_more_cameras_read() {
        let a = OverheadDetections {
            robots: vec![robot(MarkerTeam::Yellow, 9, -9.7, -29.6, 2.3, 0.9)],
            ..OverheadDetections::default()
        };
        let b = OverheadDetections {
            robots: vec![robot(MarkerTeam::Yellow, 1, -10.8, -28.9, 2.3, 0.95)],
            ..OverheadDetections::default()
        };
        let views = [
            (SslCameraId(0), &a),
            (SslCameraId(1), &a),
            (SslCameraId(2), &b),
        ];
        let p = merge_detections(&views);
        assert_eq!(p.robots.len(), 1);
        assert_eq!(p.robots[0].identity.value(), 9);
        assert_eq!(p.robots[0].camera_ids, vec![SslCameraId(0), SslCameraId(1)]);
    }

    #[test]
    fn the_ball_is_the_most_confident_and_names_every_camera_that_agrees() {
        let a = OverheadDetections {
            ball: Some(ball(10.0, 0.6)),
            ..OverheadDetections::default()
        };
        let b = OverheadDetections {
            ball: Some(ball(12.0, 0.9)),
            ..OverheadDetections::default()
        };
        let c = OverheadDetections {
            ball: Some(ball(200.0, 0.3)),
            ..OverheadDetections::default()
        };
        let p = merge_detections(&[
            (SslCameraId(2), &a),
            (SslCameraId(1), &b),
            (SslCameraId(3), &c),
        ]);
        let f = p.ball.expect("ball");
        assert_eq!(f.camera, SslCameraId(1));
        assert_eq!(f.ball.field_cm[0], 12.0);
        assert_eq!(f.camera_ids, vec![SslCameraId(1), SslCameraId(2)]);
        assert!(merge_detections(&[]).ball.is_none());
    }

    #[test]
    fn frames_within_half_a_period_of_the_reference_belong_to_its_field_frame() {
        let times = [0, 13_000_000, 26_700_000, 40_000_000];
        assert_eq!(frame_near(&times, 13_300_000, 13_333_333), Some(1));
        assert_eq!(frame_near(&times, 20_100_000, 13_333_333), Some(2));
        assert_eq!(frame_near(&times, 60_000_000, 13_333_333), None);
        assert_eq!(frame_near(&[], 0, 13_333_333), None);
    }
}
