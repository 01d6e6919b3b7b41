//! Recognition scored against boxed labels (`super::label_sets`): only the ball is scored, and
//! every other box is "not a ball". The definitions (issue 29, written in the report too):
//!
//! - a frame is **eligible** when it holds a ball box of at least [`BoxScoring::min_side_px`]
//!   (6 px; the larger of width and height);
//! - **frame recall** = eligible frames whose reported ball centre lies in one of the frame's
//!   ball boxes grown by [`BoxScoring::grow_px`] (2 px) on every side, over eligible frames;
//! - **precision** = reported balls whose centre lies in a ball box (grown the same 2 px, so a
//!   ball that counts as found also counts as right), over reported balls, in every scored
//!   frame, eligible or not; a ball in a robot or goal box, or anywhere else, is false;
//! - **centre error** = distance from the matched box's centre to the reported centre over the
//!   box's larger side (0 at the centre, 0.5 at the edge of a square box's inscribed circle).
//!
//! The reported centre is the observed one (`Ball::observed_center`: where the image shows the
//! ball, before any rolling-shutter correction), as for the other hand labels.

use serde::{Deserialize, Serialize};

use super::label_sets::{FrameBoxes, LabelBox, LabelObject};
use super::{Percentiles, rate};
use crate::recognition::Recognition;

/// The scoring rule's two numbers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoxScoring {
    /// A frame is eligible with a ball box at least this large (larger side), pixels.
    pub min_side_px: f64,
    /// Ball boxes grow by this on every side when matching a reported centre, pixels.
    pub grow_px: f64,
}

impl Default for BoxScoring {
    fn default() -> Self {
        Self {
            min_side_px: 6.0,
            grow_px: 2.0,
        }
    }
}

/// Where a false ball lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FalseBallPlace {
    /// Inside a robot box.
    Robot,
    /// Inside a goal box.
    Goal,
    /// Inside a box of another class.
    Other,
    /// Outside every box.
    Nowhere,
}

/// How one labelled frame went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoxFrameEval {
    /// The frame's name (image stem, or a stream's frame number).
    pub name: String,
    /// Ball boxes labelled.
    pub balls_labelled: usize,
    /// The larger side of the frame's largest ball box, pixels.
    pub ball_size_px: Option<f64>,
    /// Holds a ball box of at least [`BoxScoring::min_side_px`].
    pub eligible: bool,
    /// The reported ball's observed centre, pixels `[x, y]`.
    pub reported: Option<[f64; 2]>,
    /// The reported centre lies in a (grown) ball box.
    pub correct: bool,
    /// Where a reported ball that is not correct lies.
    pub false_place: Option<FalseBallPlace>,
    /// Distance from the matched ball box's centre over its larger side.
    pub centre_error: Option<f64>,
    /// The matched box's larger side, pixels (the size band a found ball counts in).
    pub matched_size_px: Option<f64>,
}

impl BoxFrameEval {
    /// Eligible and found.
    #[must_use]
    pub fn found(&self) -> bool {
        self.eligible && self.correct
    }

    /// Eligible and not found.
    #[must_use]
    pub fn missed(&self) -> bool {
        self.eligible && !self.correct
    }
}

/// Scores one frame's recognition against its boxes (in pixels of that frame).
#[must_use]
pub fn evaluate_box_frame(
    name: &str,
    r: &Recognition,
    labels: &FrameBoxes,
    s: &BoxScoring,
) -> BoxFrameEval {
    let balls: Vec<&LabelBox> = labels.balls().collect();
    let ball_size_px = balls.iter().map(|b| b.larger_side()).reduce(f64::max);
    let reported = r
        .ball
        .ball
        .as_ref()
        .map(|b| [b.observed_center.x_px, b.observed_center.y_px]);
    let mut e = BoxFrameEval {
        name: name.to_owned(),
        balls_labelled: balls.len(),
        ball_size_px,
        eligible: ball_size_px.is_some_and(|side| side >= s.min_side_px),
        reported,
        correct: false,
        false_place: None,
        centre_error: None,
        matched_size_px: None,
    };
    let Some([x, y]) = reported else {
        return e;
    };
    let matched = balls
        .iter()
        .filter(|b| b.contains(x, y, s.grow_px))
        .map(|b| {
            let [cx, cy] = b.centre();
            ((x - cx).hypot(y - cy), b.larger_side())
        })
        .min_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((distance, side)) = matched {
        e.correct = true;
        e.centre_error = Some(distance / side);
        e.matched_size_px = Some(side);
    } else {
        let inside = |o: LabelObject| {
            labels
                .boxes
                .iter()
                .any(|b| b.object == o && b.contains(x, y, 0.0))
        };
        e.false_place = Some(if inside(LabelObject::Robot) {
            FalseBallPlace::Robot
        } else if inside(LabelObject::Goal) {
            FalseBallPlace::Goal
        } else if inside(LabelObject::Other) {
            FalseBallPlace::Other
        } else {
            FalseBallPlace::Nowhere
        });
    }
    e
}

/// Eligible and found frames of one ball-size band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SizeBand {
    /// Smallest larger side in the band, pixels (inclusive).
    pub from_px: f64,
    /// Largest, pixels (exclusive; `None`: no upper end).
    pub to_px: Option<f64>,
    /// Eligible frames whose largest ball box is in the band.
    pub eligible: usize,
    /// Of those, found.
    pub found: usize,
    /// Found / eligible.
    pub recall: Option<f64>,
}

/// The size bands of the report, pixels: 6–8, 8–10, 10–12, 12–16, 16–24, 24 and up.
pub const SIZE_BAND_EDGES_PX: [f64; 6] = [6.0, 8.0, 10.0, 12.0, 16.0, 24.0];

/// Recognition against boxed labels, summed over frames.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct BoxReport {
    /// Labelled frames scored.
    pub frames: usize,
    /// Frames with at least one ball box.
    pub frames_with_ball: usize,
    /// Ball boxes labelled.
    pub balls_labelled: usize,
    /// Eligible frames.
    pub eligible: usize,
    /// Eligible frames whose ball was found.
    pub found: usize,
    /// Frame recall: found / eligible.
    pub recall: Option<f64>,
    /// Balls reported (at most one a frame).
    pub reported: usize,
    /// Of those, in a ball box.
    pub correct: usize,
    /// Precision: correct / reported.
    pub precision: Option<f64>,
    /// False balls inside robot boxes.
    pub false_in_robot: usize,
    /// ... inside goal boxes.
    pub false_in_goal: usize,
    /// ... inside boxes of other classes.
    pub false_in_other: usize,
    /// ... outside every box.
    pub false_elsewhere: usize,
    /// Centre error of correct balls (over the box's larger side).
    pub centre_error: Option<Percentiles>,
    /// Recall by the size of the frame's largest ball box.
    pub by_size: Vec<SizeBand>,
    /// Eligible frames whose ball was not found, by name.
    pub missed_frames: Vec<String>,
    /// Frames with a false ball, by name.
    pub false_frames: Vec<String>,
}

impl BoxReport {
    /// Sums frame evaluations.
    #[must_use]
    pub fn from_frames(frames: &[BoxFrameEval]) -> Self {
        let mut r = Self {
            frames: frames.len(),
            ..Self::default()
        };
        let mut errors = Vec::new();
        for f in frames {
            r.frames_with_ball += usize::from(f.balls_labelled > 0);
            r.balls_labelled += f.balls_labelled;
            r.eligible += usize::from(f.eligible);
            r.found += usize::from(f.found());
            if f.missed() {
                r.missed_frames.push(f.name.clone());
            }
            if f.reported.is_some() {
                r.reported += 1;
                r.correct += usize::from(f.correct);
            }
            if let Some(e) = f.centre_error {
                errors.push(e);
            }
            if let Some(place) = f.false_place {
                r.false_frames.push(f.name.clone());
                match place {
                    FalseBallPlace::Robot => r.false_in_robot += 1,
                    FalseBallPlace::Goal => r.false_in_goal += 1,
                    FalseBallPlace::Other => r.false_in_other += 1,
                    FalseBallPlace::Nowhere => r.false_elsewhere += 1,
                }
            }
        }
        r.recall = rate(r.found, r.eligible);
        r.precision = rate(r.correct, r.reported);
        r.centre_error = Percentiles::of(&errors);
        r.by_size = size_bands(frames);
        r
    }

    /// False balls in all.
    #[must_use]
    pub fn false_balls(&self) -> usize {
        self.reported - self.correct
    }
}

fn size_bands(frames: &[BoxFrameEval]) -> Vec<SizeBand> {
    SIZE_BAND_EDGES_PX
        .iter()
        .enumerate()
        .map(|(i, &from)| {
            let to = SIZE_BAND_EDGES_PX.get(i + 1).copied();
            let within = |f: &&BoxFrameEval| {
                f.eligible
                    && f.ball_size_px
                        .is_some_and(|s| s >= from && to.is_none_or(|t| s < t))
            };
            let eligible = frames.iter().filter(within).count();
            let found = frames.iter().filter(within).filter(|f| f.correct).count();
            SizeBand {
                from_px: from,
                to_px: to,
                eligible,
                found,
                recall: rate(found, eligible),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::label_sets::checked_box;
    use crate::geometry::ImagePoint;
    use crate::recognition::Relative;
    use crate::recognition::ball::{Ball, BallResult};
    use crate::recognition::scan::CutOff;

    fn reported_at(x: f64, y: f64) -> Recognition {
        Recognition {
            ball: BallResult {
                ball: Some(Ball {
                    candidate: 0,
                    center_x: x,
                    center_y: y,
                    observed_center: ImagePoint::new(x, y),
                    radius_px: 4.0,
                    camera: Relative {
                        distance_cm: 100.0,
                        bearing_rad: 0.0,
                        elevation_rad: 0.0,
                    },
                    body: None,
                    confidence: 1.0,
                    cut_off: CutOff::default(),
                    from_circle_fit: true,
                    image_velocity_px_s: None,
                    ground_velocity_cm_s: None,
                }),
                candidates: Vec::new(),
            },
            ..Recognition::default()
        }
    }

    fn frame(boxes: &[(&str, LabelObject, [f64; 4])]) -> FrameBoxes {
        FrameBoxes {
            size: Some((224, 224)),
            boxes: boxes
                .iter()
                .map(|(c, o, v)| checked_box(c, *o, *v).expect("a box"))
                .collect(),
        }
    }

    #[test]
    fn found_false_and_where_false_balls_lie() {
        let s = BoxScoring::default();
        let labels = frame(&[
            ("ball", LabelObject::Ball, [100.0, 100.0, 110.0, 108.0]),
            ("ball", LabelObject::Ball, [10.0, 10.0, 14.0, 14.0]),
            ("robot", LabelObject::Robot, [150.0, 150.0, 200.0, 200.0]),
        ]);
        // Inside the 10 px ball: found, centre error 1 px / 10 px.
        let hit = evaluate_box_frame("00001", &reported_at(106.0, 104.0), &labels, &s);
        assert!(hit.eligible && hit.correct && hit.found());
        assert_eq!(hit.ball_size_px, Some(10.0));
        assert!((hit.centre_error.expect("matched") - 0.1).abs() < 1e-12);
        // 2 px outside the box still counts; 2.5 px does not.
        assert!(evaluate_box_frame("a", &reported_at(112.0, 104.0), &labels, &s).correct);
        let off = evaluate_box_frame("a", &reported_at(112.5, 104.0), &labels, &s);
        assert!(!off.correct && off.missed());
        assert_eq!(off.false_place, Some(FalseBallPlace::Nowhere));
        // A ball in the robot box is false, and said to be in the robot.
        let robot = evaluate_box_frame("a", &reported_at(170.0, 170.0), &labels, &s);
        assert_eq!(robot.false_place, Some(FalseBallPlace::Robot));
        // The 4 px ball alone does not make a frame eligible, but a ball found on it is right.
        let small = frame(&[("ball", LabelObject::Ball, [10.0, 10.0, 14.0, 14.0])]);
        let tiny = evaluate_box_frame("b", &reported_at(12.0, 12.0), &small, &s);
        assert!(!tiny.eligible && tiny.correct && tiny.false_place.is_none());
        // No ball reported: missed, nothing false.
        let none = evaluate_box_frame("c", &Recognition::default(), &labels, &s);
        assert!(none.missed() && none.reported.is_none() && none.false_place.is_none());
        let report = BoxReport::from_frames(&[hit, off, robot, tiny, none]);
        assert_eq!((report.frames, report.eligible, report.found), (5, 4, 1));
        assert_eq!((report.reported, report.correct), (4, 2));
        assert_eq!(report.recall, Some(0.25));
        assert_eq!(report.precision, Some(0.5));
        assert_eq!((report.false_in_robot, report.false_elsewhere), (1, 1));
        assert_eq!(report.false_balls(), 2);
        assert_eq!(report.missed_frames, vec!["a", "a", "c"]);
        assert_eq!(report.false_frames, vec!["a", "a"]);
        // The 10 px frames fall in the 10–12 band: 1 found of 4.
        let band = report
            .by_size
            .iter()
            .find(|b| b.from_px == 10.0)
            .expect("band");
        assert_eq!((band.eligible, band.found), (4, 1));
        assert_eq!(report.by_size.iter().map(|b| b.eligible).sum::<usize>(), 4);
    }
}
