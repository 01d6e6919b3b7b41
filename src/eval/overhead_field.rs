//! A whole overhead field against the truth: the merged picture of several cameras
//! ([`FieldPicture`]) scored as one frame — the ball, every robot once, its identity and
//! heading — with what merging adds: robots seen by several cameras, a robot reported twice,
//! and why a ball that shows was missed.
//!
//! The cameras are not synchronised (each frame up to half a frame period from the reference
//! camera's), and merging does not move detections to one instant. So each detection is scored
//! against the truth at the times of the frames it came from: the ball against the truth of
//! the camera whose ball it is, a robot against the mean of its true poses in the frames of the
//! cameras that saw it. The truth names every robot in every camera's frame; which ones a
//! camera shows whole is its own.

use serde::{Deserialize, Serialize};

use super::overhead::{
    OverheadEvalParams, OverheadEvalReport, OverheadFrameEval, angle_diff, dist, label,
    nearest_unused,
};
use crate::model::truth::{OverheadRobot as TruthRobot, OverheadTruth};
use crate::overhead::merge::{FieldPicture, FieldRobot, SslCameraId};

/// One field frame's comparison.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FieldFrameEval {
    /// The merged picture scored as one frame: a robot is eligible when some camera shows its
    /// marker whole, the ball when some camera shows enough of it.
    pub merged: OverheadFrameEval,
    /// Matched robots that more than one camera saw.
    pub robots_seen_by_several: usize,
    /// Detections beside the matched one near a true robot: one robot reported twice.
    pub duplicates: usize,
    /// The ball showed enough to be found and the merged picture has none near it.
    pub ball_miss: Option<BallMiss>,
    /// Each camera that missed a ball showing enough in its own frame (before merging): the
    /// share of the ball's whole image disc that showed there.
    pub camera_ball_misses: Vec<f64>,
}

/// A ball that showed and was missed: how much of it each camera showed, and whether a
/// camera's own detections had it (then merging lost it).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct BallMiss {
    /// Field frame index.
    pub frame: usize,
    /// Per camera that showed any of it: `(camera, pixels showing it, share of its whole image
    /// disc)`.
    pub shown: Vec<(SslCameraId, usize, f64)>,
    /// Some camera's own detections had a ball within the match distance.
    pub found_by_a_camera: bool,
}

/// One camera's part of a field frame, for scoring.
#[derive(Debug, Clone, Copy)]
pub struct CameraTruth<'a> {
    /// The camera.
    pub camera: SslCameraId,
    /// Its frame's truth.
    pub truth: &'a OverheadTruth,
    /// Whether its own detections had a ball near the true one.
    pub found_ball: bool,
}

/// Share of the ball's whole image disc that showed in `truth`'s frame (its true camera gives
/// the disc: the ball's radius carried to the image at its place); `None` without a ball or
/// where it does not project.
#[must_use]
pub fn ball_shown_fraction(truth: &OverheadTruth, ball_radius_cm: f64) -> Option<f64> {
    use crate::geometry::Point;
    let b = truth.ball.as_ref()?;
    let cam = &truth.camera;
    let at = |dx: f64, dy: f64| {
        cam.image_from_field(&Point::new(
            b.field_cm[0] + dx,
            b.field_cm[1] + dy,
            ball_radius_cm,
        ))
    };
    let c = at(0.0, 0.0)?;
    let mut r = 0.0;
    for (dx, dy) in [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)] {
        r += at(dx * ball_radius_cm, dy * ball_radius_cm)?.distance_to(&c) / 4.0;
    }
    let disc = std::f64::consts::PI * r * r;
    (disc > 0.0).then(|| b.visible_pixels as f64 / disc)
}

/// Compares one field frame's merged picture with the truth of each camera's frame in it
/// (`cameras`: the reference camera first). `ball_radius_cm` sizes the ball's image disc for
/// [`BallMiss`].
#[must_use]
pub fn evaluate_field_frame(
    frame: usize,
    picture: &FieldPicture,
    cameras: &[CameraTruth<'_>],
    params: &OverheadEvalParams,
    ball_radius_cm: f64,
) -> FieldFrameEval {
    let mut e = FieldFrameEval {
        merged: OverheadFrameEval {
            frame,
            ..OverheadFrameEval::default()
        },
        ..FieldFrameEval::default()
    };
    let Some(reference) = cameras.first() else {
        return e;
    };
    score_ball(&mut e, picture, cameras, params, ball_radius_cm);
    let m = &mut e.merged;
    let mut used = vec![false; picture.robots.len()];
    for t in &reference.truth.robots {
        let Some(marker) = t.marker else { continue };
        let eligible = cameras.iter().any(|c| {
            robot_in(c.truth, t.id)
                .and_then(|r| r.marker)
                .is_some_and(|m| m.fully_visible())
        });
        m.robots_eligible += usize::from(eligible);
        let positions = picture.robots.iter().map(|d| d.field_cm);
        let Some((k, _)) = nearest_unused(positions, &used, t.field_cm, params.match_cm) else {
            continue;
        };
        used[k] = true;
        let d = &picture.robots[k];
        let (true_cm, true_heading) = true_pose_seen_by(d, t, cameras);
        m.robot_errors_cm.push(dist(d.field_cm, true_cm));
        e.robots_seen_by_several += usize::from(d.camera_ids.len() >= 2);
        if eligible {
            m.robots_found += 1;
            m.heading_errors_deg
                .push(angle_diff(d.heading_rad, true_heading).abs().to_degrees());
            if d.team == marker.team && d.identity == marker.identity {
                m.identity_right += 1;
            } else {
                m.wrong_identities.push((
                    label(marker.team, marker.identity),
                    label(d.team, d.identity),
                ));
            }
        }
    }
    for (d, _) in picture.robots.iter().zip(&used).filter(|(_, u)| !**u) {
        m.robots_false += 1;
        let near_a_robot = reference
            .truth
            .robots
            .iter()
            .any(|t| dist(d.field_cm, t.field_cm) <= params.match_cm);
        e.duplicates += usize::from(near_a_robot);
    }
    e
}

fn robot_in(truth: &OverheadTruth, id: u32) -> Option<&TruthRobot> {
    truth.robots.iter().find(|r| r.id == id)
}

/// The true pose of robot `t` at the frames of the cameras that saw detection `d`: the mean
/// position and circular mean heading over those frames (the reference frame's when none of
/// them has it).
fn true_pose_seen_by(
    d: &FieldRobot,
    t: &TruthRobot,
    cameras: &[CameraTruth<'_>],
) -> ([f64; 2], f64) {
    let poses: Vec<&TruthRobot> = cameras
        .iter()
        .filter(|c| d.camera_ids.contains(&c.camera))
        .filter_map(|c| robot_in(c.truth, t.id))
        .collect();
    if poses.is_empty() {
        return (t.field_cm, t.heading_rad);
    }
    let n = poses.len() as f64;
    let mean = |f: &dyn Fn(&TruthRobot) -> f64| poses.iter().map(|r| f(r)).sum::<f64>() / n;
    (
        [mean(&|r| r.field_cm[0]), mean(&|r| r.field_cm[1])],
        mean(&|r| r.heading_rad.sin()).atan2(mean(&|r| r.heading_rad.cos())),
    )
}

/// The merged ball against the truth of the camera whose ball it is (the reference camera's
/// truth without a ball); eligible when some camera shows at least `ball_min_pixels` of it.
fn score_ball(
    e: &mut FieldFrameEval,
    picture: &FieldPicture,
    cameras: &[CameraTruth<'_>],
    params: &OverheadEvalParams,
    ball_radius_cm: f64,
) {
    let m = &mut e.merged;
    m.ball_eligible = cameras.iter().any(|c| {
        c.truth
            .ball
            .as_ref()
            .is_some_and(|b| b.visible_pixels >= params.ball_min_pixels)
    });
    let source = picture
        .ball
        .as_ref()
        .and_then(|b| cameras.iter().find(|c| c.camera == b.camera))
        .or(cameras.first());
    let true_ball = source.and_then(|c| c.truth.ball.as_ref());
    match (true_ball, &picture.ball) {
        (Some(t), Some(d)) => {
            let err = dist(t.field_cm, d.ball.field_cm);
            if err <= params.match_cm {
                m.ball_error_cm = Some(err);
            } else {
                m.ball_false = true;
            }
        }
        (None, Some(_)) => m.ball_false = true,
        _ => {}
    }
    e.camera_ball_misses = cameras
        .iter()
        .filter(|c| !c.found_ball)
        .filter(|c| {
            c.truth
                .ball
                .as_ref()
                .is_some_and(|b| b.visible_pixels >= params.ball_min_pixels)
        })
        .map(|c| ball_shown_fraction(c.truth, ball_radius_cm).unwrap_or(f64::NAN))
        .collect();
    let m = &mut e.merged;
    if m.ball_eligible && m.ball_error_cm.is_none() {
        e.ball_miss = Some(BallMiss {
            frame: m.frame,
            shown: cameras
                .iter()
                .filter_map(|c| {
                    let b = c.truth.ball.as_ref().filter(|b| b.visible_pixels > 0)?;
                    let share = ball_shown_fraction(c.truth, ball_radius_cm).unwrap_or(f64::NAN);
                    Some((c.camera, b.visible_pixels, share))
                })
                .collect(),
            found_by_a_camera: cameras.iter().any(|c| c.found_ball),
        });
    }
}

/// A whole field's evaluation.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FieldEvalReport {
    /// Cameras in the session.
    pub cameras: usize,
    /// The merged pictures against the truth, one per field frame.
    pub merged: OverheadEvalReport,
    /// Each camera's own detections against its frame's truth, every camera's frames together
    /// (before merging).
    pub per_camera: OverheadEvalReport,
    /// Matched robots that more than one camera saw (robot-frames).
    pub robots_seen_by_several: usize,
    /// Robots reported twice (robot-frames): must be 0.
    pub duplicates: usize,
    /// Field frames whose ball showed and was missed, first few.
    pub ball_misses: Vec<BallMiss>,
    /// Of all such misses, how many a camera's own detections had (merging lost them).
    pub ball_misses_found_by_a_camera: usize,
    /// Of all such misses, how many no camera showed at least half of.
    pub ball_misses_never_half_shown: usize,
    /// Camera frames (before merging) whose ball showed at least `ball_min_pixels` and was
    /// missed by that camera.
    pub camera_ball_misses: usize,
    /// Of those, how many showed less than half the ball (cut by the image border or hidden by
    /// a robot): too little for the recogniser, whose ball must fill 35 % of its disc.
    pub camera_ball_misses_under_half_shown: usize,
}

impl FieldEvalReport {
    /// Sums the field frames and the cameras' own frames.
    #[must_use]
    pub fn from_frames(
        cameras: usize,
        field: &[FieldFrameEval],
        per_camera: &[OverheadFrameEval],
    ) -> Self {
        let merged: Vec<OverheadFrameEval> = field.iter().map(|f| f.merged.clone()).collect();
        let misses: Vec<&BallMiss> = field.iter().filter_map(|f| f.ball_miss.as_ref()).collect();
        Self {
            cameras,
            merged: OverheadEvalReport::from_frames(&merged, &[]),
            per_camera: OverheadEvalReport::from_frames(per_camera, &[]),
            robots_seen_by_several: field.iter().map(|f| f.robots_seen_by_several).sum(),
            duplicates: field.iter().map(|f| f.duplicates).sum(),
            ball_misses_found_by_a_camera: misses.iter().filter(|m| m.found_by_a_camera).count(),
            ball_misses_never_half_shown: misses
                .iter()
                .filter(|m| m.shown.iter().all(|s| s.2.is_nan() || s.2 < 0.5))
                .count(),
            ball_misses: misses.into_iter().take(20).cloned().collect(),
            camera_ball_misses: field.iter().map(|f| f.camera_ball_misses.len()).sum(),
            camera_ball_misses_under_half_shown: field
                .iter()
                .flat_map(|f| &f.camera_ball_misses)
                .filter(|&&share| share < 0.5)
                .count(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{ImagePoint, MarkerIdentity, MarkerTeam, OverheadCamera};
    use crate::model::scene::Team;
    use crate::model::truth::{OverheadMarkerTruth, OverheadObject};
    use crate::overhead::merge::FieldBall;
    use crate::overhead::recognise::OverheadBall;

    /// Robot 1 (blue 1) at `x1`, robot 2 (blue 2) at 100 cm; marker shown share `shown`.
    fn truth(x1: f64, shown: [f64; 2], ball_pixels: usize) -> OverheadTruth {
        let robot = |id: u32, x: f64, visible_fraction: f64| TruthRobot {
            id,
            team: Team::Blue,
            field_cm: [x, 0.0],
            heading_rad: 0.5,
            image: None,
            visible_pixels: 500,
            marker: Some(OverheadMarkerTruth {
                team: MarkerTeam::Blue,
                identity: MarkerIdentity::new(id as u8).expect("in range"),
                plate_height_cm: 22.5,
                image: None,
                visible_fraction,
            }),
        };
        OverheadTruth {
            time_s: 0.0,
            camera: OverheadCamera::above_field_2005(),
            ball: Some(OverheadObject {
                field_cm: [10.0, 10.0],
                image: None,
                visible_pixels: ball_pixels,
            }),
            robots: vec![robot(1, x1, shown[0]), robot(2, 100.0, shown[1])],
        }
    }

    fn merged(id: u8, x: f64, cameras: &[u8]) -> FieldRobot {
        FieldRobot {
            team: MarkerTeam::Blue,
            identity: MarkerIdentity::new(id).expect("in range"),
            field_cm: [x, 0.0],
            heading_rad: 0.5,
            confidence: 0.9,
            camera_ids: cameras.iter().map(|&c| SslCameraId(c)).collect(),
        }
    }

    #[test]
    fn each_robot_is_scored_at_the_frames_that_saw_it_and_a_second_report_is_a_duplicate() {
        // Camera 0 shows robot 2 whole and robot 1 cut; camera 1 (its frame a little later,
        // robot 1 moved 2 cm) shows robot 1 whole.
        let (t0, t1) = (truth(-100.0, [0.5, 1.0], 0), truth(-98.0, [1.0, 0.0], 0));
        let cams = [
            CameraTruth {
                camera: SslCameraId(0),
                truth: &t0,
                found_ball: false,
            },
            CameraTruth {
                camera: SslCameraId(1),
                truth: &t1,
                found_ball: false,
            },
        ];
        let picture = FieldPicture {
            ball: None,
            robots: vec![
                merged(1, -98.0, &[1]),
                merged(2, 101.0, &[0, 1]),
                merged(7, 103.0, &[1]),
            ],
        };
        let p = OverheadEvalParams::default();
        let e = evaluate_field_frame(4, &picture, &cams, &p, 4.25);
        let m = &e.merged;
        assert_eq!(
            (m.robots_eligible, m.robots_found, m.identity_right),
            (2, 2, 2)
        );
        // Robot 1 against camera 1's truth (where it was when camera 1 saw it): no error.
        assert!(m.robot_errors_cm[0].abs() < 1e-9, "{:?}", m.robot_errors_cm);
        assert!((m.robot_errors_cm[1] - 1.0).abs() < 1e-9);
        assert_eq!(
            (e.robots_seen_by_several, e.duplicates, m.robots_false),
            (1, 1, 1)
        );
        assert!(e.ball_miss.is_none(), "no ball showed");
        let r = FieldEvalReport::from_frames(2, &[e], &[]);
        assert_eq!((r.merged.robots_found, r.duplicates), (2, 1));
    }

    #[test]
    fn the_ball_is_scored_against_its_own_camera_and_a_miss_says_what_showed() {
        let (t0, mut t1) = (truth(-100.0, [1.0, 1.0], 12), truth(-100.0, [1.0, 1.0], 80));
        if let Some(b) = t1.ball.as_mut() {
            b.field_cm = [14.0, 10.0];
        }
        let cams = |found: bool| {
            [
                CameraTruth {
                    camera: SslCameraId(0),
                    truth: &t0,
                    found_ball: false,
                },
                CameraTruth {
                    camera: SslCameraId(1),
                    truth: &t1,
                    found_ball: found,
                },
            ]
        };
        let ball = FieldBall {
            ball: OverheadBall {
                field_cm: [14.5, 10.0],
                image: ImagePoint::default(),
                radius_px: 4.0,
                confidence: 0.8,
            },
            camera: SslCameraId(1),
            camera_ids: vec![SslCameraId(1)],
        };
        let p = OverheadEvalParams::default();
        let seen = FieldPicture {
            ball: Some(ball),
            robots: Vec::new(),
        };
        let e = evaluate_field_frame(0, &seen, &cams(true), &p, 4.25);
        assert!(e.merged.ball_eligible);
        assert!((e.merged.ball_error_cm.expect("matched") - 0.5).abs() < 1e-9);
        let e = evaluate_field_frame(0, &FieldPicture::default(), &cams(true), &p, 4.25);
        let miss = e.ball_miss.clone().expect("a miss");
        assert!(miss.found_by_a_camera);
        assert_eq!(miss.shown.len(), 2);
        assert_eq!((miss.shown[1].0, miss.shown[1].1), (SslCameraId(1), 80));
        // The 2005 camera shows a 4.25 cm ball near the centre as a disc of about 5 px radius
        // (80 px): 80 px is nearly all of it, 12 px under a sixth.
        assert!(miss.shown[1].2 > 0.8 && miss.shown[0].2 < 0.17, "{miss:?}");
        // Camera 1 found it, camera 0 (12 px: short of the 30 needed) was not asked to.
        assert!(e.camera_ball_misses.is_empty(), "{e:?}");
        let r = FieldEvalReport::from_frames(2, &[e], &[]);
        assert_eq!(
            (
                r.ball_misses_found_by_a_camera,
                r.ball_misses_never_half_shown
            ),
            (1, 0)
        );
        // Camera 1 missing the whole ball it showed is a camera miss of a ball shown whole.
        let e = evaluate_field_frame(0, &FieldPicture::default(), &cams(false), &p, 4.25);
        assert_eq!(e.camera_ball_misses.len(), 1);
        let r = FieldEvalReport::from_frames(2, &[e], &[]);
        assert_eq!(
            (r.camera_ball_misses, r.camera_ball_misses_under_half_shown),
            (1, 0)
        );
    }
}
