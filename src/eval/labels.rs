//! Hand labels for real streams, and recognition scored against them.
//!
//! Real recordings have no renderer's ground truth; someone looks at each frame and writes down
//! where the ball is. A labels file (JSON, `format` `"eotn.labels"`, `version` 1) lists frames
//! of one stream by index; a listed frame is labelled, an unlisted one is not scored:
//!
//! ```json
//! {"format": "eotn.labels", "version": 1, "stream": "bhuman2009.mcap",
//!  "width": 320, "height": 240, "description": "who labelled what, how",
//!  "frames": [
//!    {"frame": 0, "ball": {"center": [171.8, 149.2], "radius_px": 10.8, "cut": []},
//!     "goals": ["sky_blue"]},
//!    {"frame": 13, "ball": {"center": [73.3, 234.5], "radius_px": 11.3, "cut": ["bottom"]}},
//!    {"frame": 27, "ball": null, "goals": [], "note": "the robot's own red arm"}]}
//! ```
//!
//! `ball` is the ball's outline as the image shows it (each row at its own read-out time, blur
//! included): centre and radius in image pixels (`FORMATS.md`: pixel centres at +0.5), `cut`
//! the image edges that cut it off (`left`, `right`, `top`, `bottom`); `null` or missing: no
//! ball to be seen. `goals` (optional; missing = goals not labelled in that frame) lists the
//! goal colours of which at least one post is in view (`sky_blue`, `yellow`). `note` is free
//! text. Recognition is then scored as on synthetic streams ([`super::EvalParams`]): a ball is
//! found when the recognised ball's observed centre lies within half the labelled radius of the
//! labelled centre (the whole radius when cut, at least 4 px), near (neither found nor false)
//! within two radii, and false anywhere else or in a frame without a ball.

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::{EvalParams, Percentiles, rate};
use crate::lut::ColourClass;
use crate::recognition::Recognition;

/// The `format` value of a labels file.
pub const LABELS_FORMAT: &str = "eotn.labels";
/// The labels format version this reader understands.
pub const LABELS_VERSION: u32 = 1;

/// An image edge that cuts a labelled ball off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Edge {
    /// x = 0.
    Left,
    /// x = width.
    Right,
    /// y = 0.
    Top,
    /// y = height.
    Bottom,
}

/// A goal colour in a labels file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GoalColourLabel {
    /// The sky-blue goal.
    SkyBlue,
    /// The yellow goal.
    Yellow,
}

impl GoalColourLabel {
    /// The class code recognition reports this goal with.
    #[must_use]
    pub fn class(self) -> ColourClass {
        match self {
            Self::SkyBlue => ColourClass::SkyBlue,
            Self::Yellow => ColourClass::Yellow,
        }
    }
}

/// The ball as a person saw it in one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BallLabel {
    /// Centre of the outline, image pixels `[x, y]` (may lie outside the image when cut).
    pub center: [f64; 2],
    /// Radius of the outline, pixels.
    pub radius_px: f64,
    /// Image edges that cut the ball off.
    #[serde(default)]
    pub cut: Vec<Edge>,
}

/// One labelled frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameLabel {
    /// Frame index in the stream.
    pub frame: usize,
    /// The ball, or `None` when none is to be seen.
    #[serde(default)]
    pub ball: Option<BallLabel>,
    /// Goal colours in view; `None`: goals not labelled in this frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goals: Option<Vec<GoalColourLabel>>,
    /// Free text (blur, what the orange thing is, …).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A whole labels file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Labels {
    /// Always [`LABELS_FORMAT`].
    pub format: String,
    /// [`LABELS_VERSION`].
    pub version: u32,
    /// File name of the stream the labels are for (informative).
    #[serde(default)]
    pub stream: Option<String>,
    /// Frame width the labels were made on, pixels (checked against the stream when given).
    #[serde(default)]
    pub width: Option<usize>,
    /// Frame height, pixels.
    #[serde(default)]
    pub height: Option<usize>,
    /// Who labelled, when, how.
    #[serde(default)]
    pub description: Option<String>,
    /// The labelled frames.
    pub frames: Vec<FrameLabel>,
}

/// Why a labels file cannot be used.
#[derive(Debug, Error)]
pub enum LabelsError {
    /// Reading the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The file is not a valid labels file.
    #[error("{path}: {problem}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        #[source]
        problem: LabelsProblem,
    },
}

/// What is wrong with the contents of a labels file.
#[derive(Debug, Error)]
pub enum LabelsProblem {
    /// Not JSON of the labels shape.
    #[error("{0}")]
    Json(#[from] serde_json::Error),
    /// Another `format`.
    #[error("format is {found:?}, expected {LABELS_FORMAT:?}")]
    Format {
        /// The file's `format`.
        found: String,
    },
    /// Another `version`.
    #[error("version {found} (this eotn reads version {LABELS_VERSION})")]
    Version {
        /// The file's `version`.
        found: u32,
    },
    /// A frame with two entries.
    #[error("frame {frame} is labelled twice")]
    FrameTwice {
        /// Frame index.
        frame: usize,
    },
    /// A ball label with a non-finite centre or a radius that is not positive.
    #[error("frame {frame}: ball centre {center:?} radius {radius_px} is not a circle")]
    NotACircle {
        /// Frame index.
        frame: usize,
        /// The labelled centre, pixels.
        center: [f64; 2],
        /// The labelled radius, pixels.
        radius_px: f64,
    },
}

impl Labels {
    /// Reads and checks a labels file.
    ///
    /// # Errors
    /// [`LabelsError`] naming the file: unreadable, not JSON of this format, another version,
    /// a frame listed twice, a non-finite or non-positive value.
    pub fn load(path: &Path) -> Result<Self, LabelsError> {
        let name = path.display().to_string();
        let text = crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SIDE_FILE_BYTES,
            "a labels file",
        )
        .map_err(|source| LabelsError::Io {
            path: name.clone(),
            source,
        })?;
        Self::parse(&text).map_err(|problem| LabelsError::Invalid {
            path: name,
            problem,
        })
    }

    /// Parses and checks labels from JSON text.
    ///
    /// # Errors
    /// [`LabelsProblem`]: what is wrong (see [`Self::load`]).
    pub fn parse(text: &str) -> Result<Self, LabelsProblem> {
        let labels: Self = serde_json::from_str(text)?;
        if labels.format != LABELS_FORMAT {
            return Err(LabelsProblem::Format {
                found: labels.format,
            });
        }
        if labels.version != LABELS_VERSION {
            return Err(LabelsProblem::Version {
                found: labels.version,
            });
        }
        let mut seen = std::collections::BTreeSet::new();
        for f in &labels.frames {
            if !seen.insert(f.frame) {
                return Err(LabelsProblem::FrameTwice { frame: f.frame });
            }
            if let Some(b) = &f.ball
                && !(b.center.iter().all(|v| v.is_finite())
                    && b.radius_px.is_finite()
                    && b.radius_px > 0.0)
            {
                return Err(LabelsProblem::NotACircle {
                    frame: f.frame,
                    center: b.center,
                    radius_px: b.radius_px,
                });
            }
        }
        Ok(labels)
    }

    /// The label of a frame, if it was labelled.
    #[must_use]
    pub fn frame(&self, index: usize) -> Option<&FrameLabel> {
        self.frames.iter().find(|f| f.frame == index)
    }
}

/// Share of a circle's area inside the image [0, width) × [0, height) (sampled on a 41 × 41
/// grid over its box).
#[must_use]
pub fn visible_fraction(center: [f64; 2], radius: f64, width: f64, height: f64) -> f64 {
    let n = 40;
    let (mut inside, mut total) = (0usize, 0usize);
    for i in 0..=n {
        for j in 0..=n {
            let x = center[0] - radius + 2.0 * radius * f64::from(i) / f64::from(n);
            let y = center[1] - radius + 2.0 * radius * f64::from(j) / f64::from(n);
            if (x - center[0]).hypot(y - center[1]) <= radius {
                total += 1;
                inside += usize::from(x >= 0.0 && y >= 0.0 && x < width && y < height);
            }
        }
    }
    if total == 0 {
        0.0
    } else {
        inside as f64 / total as f64
    }
}

/// How one labelled frame went.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LabelledFrameEval {
    /// Frame index.
    pub frame: usize,
    /// A ball is labelled.
    pub ball_visible: bool,
    /// ... and at least [`EvalParams::ball_min_visible_fraction`] of it is in the image and it
    /// is at least [`EvalParams::ball_min_diameter_px`] across (the synthetic streams' rule).
    pub ball_eligible: bool,
    /// The labelled ball is cut by the image edge.
    pub ball_cut: bool,
    /// Share of the labelled ball inside the image.
    pub ball_visible_fraction: Option<f64>,
    /// A ball was reported.
    pub ball_reported: bool,
    /// The reported ball matches the label.
    pub ball_found: bool,
    /// The reported ball is within two radii of the labelled one (not false, perhaps badly
    /// placed).
    pub ball_near: bool,
    /// A ball was reported where there is none (or far from it).
    pub ball_false: bool,
    /// Distance from the labelled centre to the reported ball's observed centre, pixels.
    pub ball_center_error_px: Option<f64>,
    /// Reported minus labelled radius, pixels.
    pub ball_radius_error_px: Option<f64>,
    /// Goals were labelled in this frame.
    pub goals_labelled: bool,
    /// Labelled goal colours.
    pub goals_visible: usize,
    /// Of those, reported.
    pub goals_found: usize,
    /// Goals reported in a colour not labelled.
    pub goals_false: usize,
}

/// Compares one frame's recognition with its label.
#[must_use]
pub fn evaluate_labelled_frame(
    r: &Recognition,
    label: &FrameLabel,
    width: f64,
    height: f64,
    p: &EvalParams,
) -> LabelledFrameEval {
    let mut e = LabelledFrameEval {
        frame: label.frame,
        ..LabelledFrameEval::default()
    };
    let reported = r.ball.ball.as_ref();
    e.ball_reported = reported.is_some();
    if let Some(b) = &label.ball {
        let fraction = visible_fraction(b.center, b.radius_px, width, height);
        e.ball_visible = true;
        e.ball_cut = !b.cut.is_empty();
        e.ball_visible_fraction = Some(fraction);
        e.ball_eligible =
            fraction >= p.ball_min_visible_fraction && 2.0 * b.radius_px >= p.ball_min_diameter_px;
        if let Some(found) = reported {
            let seen = found.observed_center;
            let off = (seen.x_px - b.center[0]).hypot(seen.y_px - b.center[1]);
            let share = if e.ball_cut {
                1.0
            } else {
                p.ball_match_radius_fraction
            };
            e.ball_found = off <= (share * b.radius_px).max(p.ball_match_min_px);
            e.ball_near = off <= 2.0 * b.radius_px + p.ball_match_min_px;
            if e.ball_near {
                e.ball_center_error_px = Some(off);
                e.ball_radius_error_px = Some(found.radius_px - b.radius_px);
            }
        }
    }
    e.ball_false = e.ball_reported && !e.ball_near;
    if let Some(goals) = &label.goals {
        e.goals_labelled = true;
        let reported: Vec<ColourClass> = r.goals.goals().map(|g| g.colour).collect();
        e.goals_visible = goals.len();
        e.goals_found = goals
            .iter()
            .filter(|g| reported.contains(&g.class()))
            .count();
        let labelled: Vec<ColourClass> = goals.iter().map(|g| g.class()).collect();
        e.goals_false = reported.iter().filter(|c| !labelled.contains(c)).count();
    }
    e
}

/// Recognition against hand labels, summed over a stream.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LabelsReport {
    /// Labelled frames compared.
    pub frames: usize,
    /// Frames with a labelled ball.
    pub ball_visible: usize,
    /// Of those, found.
    pub ball_found: usize,
    /// Found / visible.
    pub ball_found_rate: Option<f64>,
    /// Frames whose ball is eligible by the synthetic rule (≥ 60% in view, ≥ 6 px across).
    pub ball_eligible: usize,
    /// Of those, found.
    pub ball_eligible_found: usize,
    /// Frames whose labelled ball is cut by the image edge.
    pub ball_cut: usize,
    /// Of those, found.
    pub ball_cut_found: usize,
    /// Frames with a false ball (reported where no ball is, or far from it).
    pub ball_false: usize,
    /// False balls / labelled frames.
    pub ball_false_rate: Option<f64>,
    /// Frames without a labelled ball.
    pub ball_absent: usize,
    /// Centre error of found balls not cut off, pixels.
    pub ball_center_error_px: Option<Percentiles>,
    /// Centre error of found balls cut off by the image edge, pixels.
    pub ball_center_error_cut_px: Option<Percentiles>,
    /// |radius error| of found balls not cut off, pixels.
    pub ball_radius_error_px: Option<Percentiles>,
    /// |radius error| of found cut balls, pixels.
    pub ball_radius_error_cut_px: Option<Percentiles>,
    /// Median signed radius error (reported − labelled) of found uncut balls, pixels.
    pub ball_radius_bias_px: Option<f64>,
    /// Frames whose labelled ball was not found (near misses included).
    pub ball_missed_frames: Vec<usize>,
    /// Frames with a false ball.
    pub ball_false_frames: Vec<usize>,
    /// Frames whose ball was reported near but not within the match tolerance.
    pub ball_near_frames: Vec<usize>,
    /// Frames with goals labelled.
    pub goal_frames: usize,
    /// Labelled goals (colour per frame).
    pub goals_visible: usize,
    /// Of those, reported.
    pub goals_found: usize,
    /// Found / visible.
    pub goal_found_rate: Option<f64>,
    /// Goals reported in a colour not labelled in their frame.
    pub goals_false: usize,
    /// Frames where a labelled goal was not reported.
    pub goal_missed_frames: Vec<usize>,
    /// Frames with a false goal.
    pub goal_false_frames: Vec<usize>,
}

impl LabelsReport {
    /// Sums frame evaluations.
    #[must_use]
    pub fn from_frames(frames: &[LabelledFrameEval]) -> Self {
        let mut r = Self {
            frames: frames.len(),
            ..Self::default()
        };
        let (mut centre, mut centre_cut, mut radius, mut radius_cut, mut signed) =
            (vec![], vec![], vec![], vec![], vec![]);
        for f in frames {
            if f.ball_visible {
                r.ball_visible += 1;
                r.ball_found += usize::from(f.ball_found);
                r.ball_eligible += usize::from(f.ball_eligible);
                r.ball_eligible_found += usize::from(f.ball_eligible && f.ball_found);
                r.ball_cut += usize::from(f.ball_cut);
                r.ball_cut_found += usize::from(f.ball_cut && f.ball_found);
                if !f.ball_found {
                    r.ball_missed_frames.push(f.frame);
                    if f.ball_near {
                        r.ball_near_frames.push(f.frame);
                    }
                }
            } else {
                r.ball_absent += 1;
            }
            if f.ball_false {
                r.ball_false += 1;
                r.ball_false_frames.push(f.frame);
            }
            if f.ball_found
                && let (Some(c), Some(e)) = (f.ball_center_error_px, f.ball_radius_error_px)
            {
                if f.ball_cut {
                    centre_cut.push(c);
                    radius_cut.push(e.abs());
                } else {
                    centre.push(c);
                    radius.push(e.abs());
                    signed.push(e);
                }
            }
            if f.goals_labelled {
                r.goal_frames += 1;
                r.goals_visible += f.goals_visible;
                r.goals_found += f.goals_found;
                r.goals_false += f.goals_false;
                if f.goals_found < f.goals_visible {
                    r.goal_missed_frames.push(f.frame);
                }
                if f.goals_false > 0 {
                    r.goal_false_frames.push(f.frame);
                }
            }
        }
        r.ball_found_rate = rate(r.ball_found, r.ball_visible);
        r.ball_false_rate = rate(r.ball_false, r.frames);
        r.ball_center_error_px = Percentiles::of(&centre);
        r.ball_center_error_cut_px = Percentiles::of(&centre_cut);
        r.ball_radius_error_px = Percentiles::of(&radius);
        r.ball_radius_error_cut_px = Percentiles::of(&radius_cut);
        r.ball_radius_bias_px = Percentiles::median_of(&signed);
        r.goal_found_rate = rate(r.goals_found, r.goals_visible);
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognition::Relative;
    use crate::recognition::ball::{Ball, BallResult};
    use crate::recognition::scan::CutOff;

    fn recognised(center: (f64, f64), radius: f64) -> Recognition {
        let camera = Relative {
            distance_cm: 100.0,
            bearing_rad: 0.0,
            elevation_rad: 0.0,
        };
        Recognition {
            ball: BallResult {
                ball: Some(Ball {
                    candidate: 0,
                    center_x: center.0 + 30.0,
                    center_y: center.1,
                    observed_center: crate::geometry::ImagePoint::new(center.0, center.1),
                    radius_px: radius,
                    camera,
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

    const FILE: &str = r#"{"format": "eotn.labels", "version": 1, "width": 320, "height": 240,
        "frames": [
          {"frame": 0, "ball": {"center": [100.0, 100.0], "radius_px": 10.0}, "goals": ["sky_blue"]},
          {"frame": 1, "ball": {"center": [100.0, 236.0], "radius_px": 12.0, "cut": ["bottom"]}},
          {"frame": 2, "ball": null, "goals": [], "note": "a red robot arm"},
          {"frame": 3}]}"#;

    #[test]
    fn labels_parse_and_bad_files_say_why() {
        let labels = Labels::parse(FILE).expect("valid");
        assert_eq!(labels.frames.len(), 4);
        assert_eq!(
            labels
                .frame(1)
                .and_then(|f| f.ball.as_ref())
                .map(|b| b.cut.clone()),
            Some(vec![Edge::Bottom])
        );
        assert!(
            labels
                .frame(3)
                .is_some_and(|f| f.ball.is_none() && f.goals.is_none())
        );
        assert!(labels.frame(9).is_none());
        let twice = FILE.replace(r#"{"frame": 3}"#, r#"{"frame": 2}"#);
        let message = |text: &str| Labels::parse(text).unwrap_err().to_string();
        assert!(matches!(
            Labels::parse(&twice),
            Err(LabelsProblem::FrameTwice { frame: 2 })
        ));
        assert!(message(&twice).contains("twice"));
        let v2 = FILE.replace(r#""version": 1"#, r#""version": 2"#);
        assert!(matches!(
            Labels::parse(&v2),
            Err(LabelsProblem::Version { found: 2 })
        ));
        assert!(message(&v2).contains("version 2"));
        let other = FILE.replace("eotn.labels", "something");
        assert!(matches!(
            Labels::parse(&other),
            Err(LabelsProblem::Format { .. })
        ));
        assert!(message(&other).contains("format"));
        let zero = FILE.replace(r#""radius_px": 10.0"#, r#""radius_px": 0"#);
        assert!(matches!(
            Labels::parse(&zero),
            Err(LabelsProblem::NotACircle { frame: 0, .. })
        ));
        assert!(message(&zero).contains("not a circle"));
        assert!(matches!(
            Labels::parse("[1, 2]"),
            Err(LabelsProblem::Json(_))
        ));
    }

    #[test]
    fn visible_fraction_of_a_cut_circle() {
        assert!((visible_fraction([50.0, 50.0], 10.0, 320.0, 240.0) - 1.0).abs() < 1e-9);
        let half = visible_fraction([50.0, 240.0], 10.0, 320.0, 240.0);
        assert!((half - 0.5).abs() < 0.05, "{half}");
        assert_eq!(visible_fraction([-50.0, 50.0], 10.0, 320.0, 240.0), 0.0);
    }

    #[test]
    fn found_near_false_and_goals_are_counted() {
        let labels = Labels::parse(FILE).expect("valid");
        let p = EvalParams::default();
        let at = |i: usize, r: &Recognition| {
            evaluate_labelled_frame(r, labels.frame(i).expect("labelled"), 320.0, 240.0, &p)
        };
        // Found: 3 px off a 10 px ball (within half its radius); the skew-corrected centre
        // (30 px away) is not what counts.
        let f0 = at(0, &recognised((103.0, 100.0), 11.0));
        assert!(f0.ball_found && !f0.ball_false && f0.ball_eligible);
        assert_eq!(f0.ball_radius_error_px, Some(1.0));
        assert_eq!((f0.goals_visible, f0.goals_found), (1, 0));
        // Near: 15 px off, within two radii: neither found nor false.
        let f0b = at(0, &recognised((115.0, 100.0), 10.0));
        assert!(!f0b.ball_found && f0b.ball_near && !f0b.ball_false);
        // A cut ball matches within its whole radius.
        let f1 = at(1, &recognised((100.0, 226.0), 12.0));
        assert!(f1.ball_found && f1.ball_cut);
        // A ball where none is labelled is false; no ball where none is, is fine.
        let f2 = at(2, &recognised((50.0, 50.0), 8.0));
        assert!(f2.ball_false && !f2.ball_visible);
        let f3 = at(3, &Recognition::default());
        assert!(!f3.ball_false && !f3.goals_labelled);
        let report = LabelsReport::from_frames(&[f0, f0b, f1, f2, f3]);
        assert_eq!((report.ball_visible, report.ball_found), (3, 2));
        assert_eq!((report.ball_false, report.ball_absent), (1, 2));
        assert_eq!(report.ball_missed_frames, vec![0]);
        assert_eq!(report.ball_near_frames, vec![0]);
        assert_eq!(report.ball_false_frames, vec![2]);
        assert_eq!((report.ball_cut, report.ball_cut_found), (1, 1));
        assert_eq!(report.ball_center_error_px.map(|p| p.n), Some(1));
        assert_eq!(report.ball_center_error_cut_px.map(|p| p.n), Some(1));
        assert_eq!(report.ball_radius_bias_px, Some(1.0));
        // Frame 0 twice (two recognitions), and frame 2 with no goal.
        assert_eq!(
            (report.goal_frames, report.goals_visible, report.goals_found),
            (3, 2, 0)
        );
        assert_eq!(report.goal_missed_frames, vec![0, 0]);
    }
}
