//! Field descriptions for overhead calibration: the landmarks a user clicks (by name), the
//! painted lines the calibration is refined along, and the heights overhead recognition needs.
//!
//! A description is a small JSON file (`params/fields/*.json`): one for our 2005 Four-Legged
//! League field (the simulator's, [`FieldDescription::four_legged_2005`]) and one for the Small
//! Size League field of 2008 (the real overhead frame of `../shared/data/ssl2008/`). Field
//! coordinates follow `FORMATS.md`: centimetres, origin at the centre spot, x towards the yellow
//! goal, y left. Lines are given along their painted centres.

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::geometry::marker::DEFAULT_PLATE_HEIGHT_CM;
use crate::model::scene::FieldSpec;

/// A named point of the field that a user can click.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Landmark {
    /// Its name, as offered in the app and written into points files.
    pub name: String,
    /// Field position `[x, y]`, centimetres.
    pub field_cm: [f64; 2],
    /// Height above the ground, centimetres (0 for points on the carpet; goal tops are higher).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub height_cm: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// A straight painted line between two field points (its centre line), centimetres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineSegment {
    /// One end `[x, y]`, centimetres.
    pub from_cm: [f64; 2],
    /// The other end `[x, y]`, centimetres.
    pub to_cm: [f64; 2],
}

/// A painted circular arc (its centre line), counter-clockwise from `from_rad` to `to_rad`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Arc {
    /// Centre `[x, y]`, centimetres.
    pub centre_cm: [f64; 2],
    /// Radius, centimetres.
    pub radius_cm: f64,
    /// Start angle, radians counter-clockwise from +x.
    pub from_rad: f64,
    /// End angle, radians (greater than `from_rad`).
    pub to_rad: f64,
}

/// What overhead calibration and recognition need to know about a field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FieldDescription {
    /// A human name, e.g. "RoboCup 2005 Four-Legged League".
    pub name: String,
    /// Clickable landmarks.
    pub landmarks: Vec<Landmark>,
    /// Straight painted lines.
    pub lines: Vec<LineSegment>,
    /// Painted arcs and circles.
    #[serde(default)]
    pub arcs: Vec<Arc>,
    /// Width of the painted lines, centimetres.
    pub line_width_cm: f64,
    /// Ball radius, centimetres (the ball's centre is this high).
    pub ball_radius_cm: f64,
    /// Height of the robots' marker plates, centimetres.
    #[serde(default = "default_plate_height")]
    pub plate_height_cm: f64,
    /// A rough camera height above the carpet, centimetres: the calibration's starting point
    /// and a weak prior (a camera looking straight down at a flat field cannot tell its height
    /// from its focal length by ground points alone).
    pub camera_height_guess_cm: f64,
}

fn default_plate_height() -> f64 {
    DEFAULT_PLATE_HEIGHT_CM
}

/// Why a field description could not be read.
#[derive(Debug, Error)]
pub enum FieldError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The error.
        source: std::io::Error,
    },
    /// The file is not a field description.
    #[error("{path}: not a field description: {source}")]
    Parse {
        /// The file.
        path: String,
        /// The error.
        source: serde_json::Error,
    },
    /// JSON of the right shape with a value out of range.
    #[error("{path}: {problem}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        #[source]
        problem: FieldProblem,
    },
}

/// What makes a field description of the right shape unusable.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FieldProblem {
    /// A landmark, line or arc coordinate that is NaN or infinite.
    #[error("a coordinate is not a finite number")]
    NotFinite,
    /// A size that must be positive is not (`line_width_cm`, `ball_radius_cm`, …).
    #[error("{key} must be positive, is {value}")]
    NotPositive {
        /// The key in the file.
        key: &'static str,
        /// Its value.
        value: f64,
    },
}

impl FieldDescription {
    /// Reads a description file.
    ///
    /// # Errors
    /// [`FieldError`] when the file is missing, not JSON of this shape, or has non-finite or
    /// non-positive sizes.
    pub fn load(path: &Path) -> Result<Self, FieldError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| FieldError::Io {
            path: name.clone(),
            source,
        })?;
        let field: Self = serde_json::from_str(&text).map_err(|source| FieldError::Parse {
            path: name.clone(),
            source,
        })?;
        field.check().map_err(|problem| FieldError::Invalid {
            path: name,
            problem,
        })?;
        Ok(field)
    }

    fn check(&self) -> Result<(), FieldProblem> {
        let finite = self
            .landmarks
            .iter()
            .flat_map(|l| [l.field_cm[0], l.field_cm[1], l.height_cm])
            .chain(
                self.lines
                    .iter()
                    .flat_map(|l| [l.from_cm[0], l.from_cm[1], l.to_cm[0], l.to_cm[1]]),
            )
            .chain(self.arcs.iter().flat_map(|a| {
                [
                    a.centre_cm[0],
                    a.centre_cm[1],
                    a.radius_cm,
                    a.from_rad,
                    a.to_rad,
                ]
            }))
            .all(f64::is_finite);
        if !finite {
            return Err(FieldProblem::NotFinite);
        }
        for (key, value) in [
            ("line_width_cm", self.line_width_cm),
            ("ball_radius_cm", self.ball_radius_cm),
            ("plate_height_cm", self.plate_height_cm),
            ("camera_height_guess_cm", self.camera_height_guess_cm),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(FieldProblem::NotPositive { key, value });
            }
        }
        Ok(())
    }

    /// The landmark with this name.
    #[must_use]
    pub fn landmark(&self, name: &str) -> Option<&Landmark> {
        self.landmarks.iter().find(|l| l.name == name)
    }

    /// Points along every painted line and arc, about `step_cm` apart, with the unit direction
    /// of the line there (field `[x, y]`, centimetres): where the calibration looks for lines.
    #[must_use]
    pub fn line_samples(&self, step_cm: f64) -> Vec<LineSample> {
        let step = step_cm.max(0.5);
        let mut out = Vec::new();
        for l in &self.lines {
            let (dx, dy) = (l.to_cm[0] - l.from_cm[0], l.to_cm[1] - l.from_cm[1]);
            let len = dx.hypot(dy);
            if len < 1e-9 {
                continue;
            }
            let n = (len / step).ceil().max(1.0);
            // Stop short of the ends: corners are where two lines meet and confuse the search.
            for k in 1..n as usize {
                let t = k as f64 / n;
                out.push(LineSample {
                    field_cm: [l.from_cm[0] + t * dx, l.from_cm[1] + t * dy],
                    direction: [dx / len, dy / len],
                });
            }
        }
        for a in &self.arcs {
            let sweep = a.to_rad - a.from_rad;
            let n = (sweep.abs() * a.radius_cm / step).ceil().max(1.0);
            for k in 1..n as usize {
                let angle = a.from_rad + sweep * k as f64 / n;
                let (s, c) = angle.sin_cos();
                out.push(LineSample {
                    field_cm: [
                        a.centre_cm[0] + a.radius_cm * c,
                        a.centre_cm[1] + a.radius_cm * s,
                    ],
                    direction: [-s, c],
                });
            }
        }
        out
    }

    /// The description of a simulator field ([`FieldSpec`]): its corners, centre, centre-line
    /// ends, centre-circle crossings, goal-post feet and tops, penalty-area corners; every line.
    #[must_use]
    pub fn from_field_spec(name: &str, f: &FieldSpec) -> Self {
        let half_lw = f.line_width_cm / 2.0;
        let (gx, sy) = (f.length_cm / 2.0 - half_lw, f.width_cm / 2.0 - half_lw);
        let (hl, r) = (f.length_cm / 2.0, f.centre_circle_radius_cm);
        let (px, pw) = (hl - f.penalty_area_depth_cm, f.penalty_area_width_cm / 2.0);
        let post = f.goal_width_cm / 2.0;
        let mut landmarks = vec![
            landmark("centre", 0.0, 0.0, 0.0),
            landmark("centre line left end", 0.0, sy, 0.0),
            landmark("centre line right end", 0.0, -sy, 0.0),
            landmark("centre circle left", 0.0, r, 0.0),
            landmark("centre circle right", 0.0, -r, 0.0),
            landmark("centre circle yellow side", r, 0.0, 0.0),
            landmark("centre circle blue side", -r, 0.0, 0.0),
        ];
        for (goal, s) in [("yellow", 1.0), ("blue", -1.0)] {
            // "left" and "right" as seen from the centre spot facing that goal.
            for (side, t) in [("left", s), ("right", -s)] {
                landmarks.push(landmark(
                    &format!("{goal} {side} corner"),
                    s * gx,
                    t * sy,
                    0.0,
                ));
                landmarks.push(landmark(
                    &format!("{goal} goal {side} post foot"),
                    s * hl,
                    t * post,
                    0.0,
                ));
                landmarks.push(landmark(
                    &format!("{goal} goal {side} post top"),
                    s * hl,
                    t * post,
                    f.goal_height_cm,
                ));
                landmarks.push(landmark(
                    &format!("{goal} penalty area {side} front corner"),
                    s * px,
                    t * pw,
                    0.0,
                ));
                landmarks.push(landmark(
                    &format!("{goal} penalty area {side} goal-line corner"),
                    s * gx,
                    t * pw,
                    0.0,
                ));
            }
        }
        let mut lines = vec![
            segment([-gx, sy], [gx, sy]),
            segment([-gx, -sy], [gx, -sy]),
            segment([gx, -sy], [gx, sy]),
            segment([-gx, -sy], [-gx, sy]),
            segment([0.0, -sy], [0.0, sy]),
        ];
        for s in [1.0, -1.0] {
            lines.push(segment([s * px, -pw], [s * px, pw]));
            lines.push(segment([s * px, pw], [s * gx, pw]));
            lines.push(segment([s * px, -pw], [s * gx, -pw]));
        }
        Self {
            name: name.into(),
            landmarks,
            lines,
            arcs: vec![Arc {
                centre_cm: [0.0, 0.0],
                radius_cm: r,
                from_rad: 0.0,
                to_rad: std::f64::consts::TAU,
            }],
            line_width_cm: f.line_width_cm,
            ball_radius_cm: 4.25,
            plate_height_cm: DEFAULT_PLATE_HEIGHT_CM,
            camera_height_guess_cm: 350.0,
        }
    }

    /// Our field: the 2005 Four-Legged League field the simulator renders.
    #[must_use]
    pub fn four_legged_2005() -> Self {
        Self::from_field_spec("RoboCup 2005 Four-Legged League", &FieldSpec::default())
    }
}

/// A point on a painted line and the line's direction there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineSample {
    /// Field position `[x, y]` on the ground, centimetres.
    pub field_cm: [f64; 2],
    /// Unit direction of the line, field `[x, y]`.
    pub direction: [f64; 2],
}

fn landmark(name: &str, x: f64, y: f64, height_cm: f64) -> Landmark {
    Landmark {
        name: name.into(),
        field_cm: [x, y],
        height_cm,
    }
}

fn segment(from_cm: [f64; 2], to_cm: [f64; 2]) -> LineSegment {
    LineSegment { from_cm, to_cm }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_four_legged_description_matches_the_simulator_field() {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("params/fields/four-legged-2005.json");
        let shipped = FieldDescription::load(&path).expect("shipped description loads");
        assert_eq!(shipped, FieldDescription::four_legged_2005());
    }

    #[test]
    fn shipped_ssl_description_loads_with_its_landmarks() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/fields/ssl-2008.json");
        let ssl = FieldDescription::load(&path).expect("shipped description loads");
        assert!(ssl.landmarks.len() >= 6);
        assert!(ssl.landmark("centre").is_some());
        assert!(!ssl.line_samples(10.0).is_empty());
    }

    #[test]
    fn line_samples_lie_on_the_lines_away_from_the_ends() {
        let f = FieldDescription::four_legged_2005();
        let samples = f.line_samples(10.0);
        assert!(samples.len() > 150, "{}", samples.len());
        for s in &samples {
            let d = s.direction[0].hypot(s.direction[1]);
            assert!((d - 1.0).abs() < 1e-9);
        }
        let circle: Vec<_> = samples
            .iter()
            .filter(|s| (s.field_cm[0].hypot(s.field_cm[1]) - 18.0).abs() < 1e-9)
            .collect();
        assert!(circle.len() >= 10);
    }

    #[test]
    fn bad_files_give_clear_errors() {
        let dir = tempfile::tempdir().expect("tempdir");
        let p = dir.path().join("f.json");
        std::fs::write(&p, "{").expect("write");
        assert!(matches!(
            FieldDescription::load(&p),
            Err(FieldError::Parse { .. })
        ));
        let mut f = FieldDescription::four_legged_2005();
        f.camera_height_guess_cm = -3.0;
        std::fs::write(&p, serde_json::to_string(&f).expect("json")).expect("write");
        let err = FieldDescription::load(&p).expect_err("negative height");
        assert!(err.to_string().contains("camera_height_guess_cm"), "{err}");
        assert!(
            matches!(
                &err,
                FieldError::Invalid {
                    problem: FieldProblem::NotPositive {
                        key: "camera_height_guess_cm",
                        ..
                    },
                    ..
                }
            ),
            "{err:?}"
        );
    }
}
