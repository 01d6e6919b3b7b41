//! Field descriptions for overhead calibration: the landmarks a user clicks (by name), the
//! painted lines the calibration is refined along, and the heights overhead recognition needs.
//!
//! A description is a small JSON file (`params/fields/*.json`): one for our 2005 Four-Legged
//! League field (the simulator's, [`FieldDescription::four_legged_2005`]), one for the Small
//! Size League field of 2008 (the real overhead frame of `../shared/data/ssl2008/`), and today's
//! fields: the Standard Platform League's of 2020 (`spl-2020`) and the Small Size League's
//! divisions A and B (`ssl-div-a`, `ssl-div-b`). These are built in ([`SHIPPED_FIELDS`]):
//! `--field` takes a shipped field's name or a file ([`FieldDescription::resolve`]). Field
//! coordinates follow `FORMATS.md`: centimetres, origin at the centre spot, x towards the yellow
//! goal, y left. Lines are given along their painted centres.
//!
//! Descriptions are written by hand: a key the format does not have is refused, naming it (a
//! typo `heigth_cm` would otherwise put a goal top on the ground). Every coordinate lies within
//! [`MAX_FIELD_CM`] of the centre (a field in millimetres or a line a kilometre long is refused,
//! not sampled into gigabytes), and the line samples drawn from it are bounded in number.

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::geometry::marker::DEFAULT_PLATE_HEIGHT_CM;
use crate::model::scene::FieldSpec;

/// Farthest any coordinate of a field description lies from the centre spot, centimetres (100 m:
/// every RoboCup field fits with room to spare).
pub const MAX_FIELD_CM: f64 = 10_000.0;
/// Most landmarks, and most lines and arcs together, a description may have.
pub const MAX_FIELD_ITEMS: usize = 1000;
/// Most line samples [`FieldDescription::line_samples`] gives (the step widens beyond it).
pub const MAX_LINE_SAMPLES: usize = 20_000;
/// Largest size (line width, ball radius) a description may give, centimetres.
const MAX_SIZE_CM: f64 = 100.0;

/// The field descriptions shipped with eotn (`params/fields/NAME.json`, built in), by the name
/// `--field` takes.
pub const SHIPPED_FIELDS: [(&str, &str); 5] = [
    (
        "four-legged-2005",
        include_str!("../../params/fields/four-legged-2005.json"),
    ),
    (
        "ssl-2008",
        include_str!("../../params/fields/ssl-2008.json"),
    ),
    (
        "spl-2020",
        include_str!("../../params/fields/spl-2020.json"),
    ),
    (
        "ssl-div-a",
        include_str!("../../params/fields/ssl-div-a.json"),
    ),
    (
        "ssl-div-b",
        include_str!("../../params/fields/ssl-div-b.json"),
    ),
];

/// The shipped fields' names, comma-separated (for messages and help).
#[must_use]
pub fn shipped_field_names() -> String {
    SHIPPED_FIELDS.map(|(name, _)| name).join(", ")
}

/// A named point of the field that a user can click.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
#[serde(deny_unknown_fields)]
pub struct LineSegment {
    /// One end `[x, y]`, centimetres.
    pub from_cm: [f64; 2],
    /// The other end `[x, y]`, centimetres.
    pub to_cm: [f64; 2],
}

/// A painted circular arc (its centre line), counter-clockwise from `from_rad` to `to_rad`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
#[serde(deny_unknown_fields)]
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

impl FieldError {
    /// The same error naming the file `path`.
    #[must_use]
    pub fn at(self, path: &str) -> Self {
        let path = path.to_owned();
        match self {
            Self::Io { source, .. } => Self::Io { path, source },
            Self::Parse { source, .. } => Self::Parse { path, source },
            Self::Invalid { problem, .. } => Self::Invalid { path, problem },
            unknown @ Self::Unknown { .. } => unknown,
        }
    }
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
    /// Neither a shipped field's name nor a file.
    #[error(
        "no field {name:?}: give a field description file or one of the shipped fields ({})",
        shipped_field_names()
    )]
    Unknown {
        /// What was given.
        name: String,
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
    /// A coordinate, radius or size beyond what a field can have (units? millimetres?).
    #[error("{what} is {value}, more than a field can have (at most {limit}; centimetres?)")]
    TooFar {
        /// Which value, e.g. `lines[3].to_cm`.
        what: String,
        /// Its value.
        value: f64,
        /// The largest allowed.
        limit: f64,
    },
    /// More landmarks, lines or arcs than a field has.
    #[error("{count} {what}, more than a field description may have ({MAX_FIELD_ITEMS})")]
    TooMany {
        /// Which list.
        what: &'static str,
        /// How many were given.
        count: usize,
    },
    /// An arc that does not run counter-clockwise by at most one full turn.
    #[error("arcs[{index}]: to_rad must lie above from_rad by at most one turn (2π)")]
    BadArc {
        /// The arc's place in the list.
        index: usize,
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
        let text = crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SMALL_FILE_BYTES,
            "a field description",
        )
        .map_err(|source| FieldError::Io {
            path: name.clone(),
            source,
        })?;
        Self::from_json(&text).map_err(|e| e.at(&name))
    }

    /// Parses and checks a description's text (errors name no file until [`FieldError::at`]).
    ///
    /// # Errors
    /// [`FieldError::Parse`] (an unknown key among them, named) or [`FieldError::Invalid`].
    pub fn from_json(text: &str) -> Result<Self, FieldError> {
        let field: Self = serde_json::from_str(text).map_err(|source| FieldError::Parse {
            path: String::new(),
            source,
        })?;
        field.check().map_err(|problem| FieldError::Invalid {
            path: String::new(),
            problem,
        })?;
        Ok(field)
    }

    fn check(&self) -> Result<(), FieldProblem> {
        if self.landmarks.len() > MAX_FIELD_ITEMS {
            return Err(FieldProblem::TooMany {
                what: "landmarks",
                count: self.landmarks.len(),
            });
        }
        if self.lines.len() + self.arcs.len() > MAX_FIELD_ITEMS {
            return Err(FieldProblem::TooMany {
                what: "lines and arcs",
                count: self.lines.len() + self.arcs.len(),
            });
        }
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
        self.check_extent()
    }

    /// Every coordinate within [`MAX_FIELD_CM`] of the centre, sizes within reason, arcs at
    /// most one turn.
    fn check_extent(&self) -> Result<(), FieldProblem> {
        let too_far = |what: String, value: f64, limit: f64| {
            (value.abs() > limit).then_some(FieldProblem::TooFar { what, value, limit })
        };
        let named = |list: &str, i: usize, key: &str| format!("{list}[{i}].{key}");
        let mut values: Vec<(String, f64, f64)> = Vec::new();
        for (i, l) in self.landmarks.iter().enumerate() {
            values.extend(
                l.field_cm
                    .map(|v| (named("landmarks", i, "field_cm"), v, MAX_FIELD_CM)),
            );
            values.push((
                named("landmarks", i, "height_cm"),
                l.height_cm,
                MAX_FIELD_CM,
            ));
        }
        for (i, l) in self.lines.iter().enumerate() {
            values.extend(
                l.from_cm
                    .map(|v| (named("lines", i, "from_cm"), v, MAX_FIELD_CM)),
            );
            values.extend(
                l.to_cm
                    .map(|v| (named("lines", i, "to_cm"), v, MAX_FIELD_CM)),
            );
        }
        for (i, a) in self.arcs.iter().enumerate() {
            values.extend(
                a.centre_cm
                    .map(|v| (named("arcs", i, "centre_cm"), v, MAX_FIELD_CM)),
            );
            values.push((named("arcs", i, "radius_cm"), a.radius_cm, MAX_FIELD_CM));
            let sweep = a.to_rad - a.from_rad;
            if !(sweep > 0.0 && sweep <= std::f64::consts::TAU + 1e-9) || a.from_rad.abs() > 100.0 {
                return Err(FieldProblem::BadArc { index: i });
            }
        }
        values.extend([
            ("line_width_cm".to_owned(), self.line_width_cm, MAX_SIZE_CM),
            (
                "ball_radius_cm".to_owned(),
                self.ball_radius_cm,
                MAX_SIZE_CM,
            ),
            (
                "plate_height_cm".to_owned(),
                self.plate_height_cm,
                MAX_FIELD_CM,
            ),
            (
                "camera_height_guess_cm".to_owned(),
                self.camera_height_guess_cm,
                MAX_FIELD_CM,
            ),
        ]);
        match values
            .into_iter()
            .find_map(|(what, value, limit)| too_far(what, value, limit))
        {
            Some(problem) => Err(problem),
            None => Ok(()),
        }
    }

    /// The landmark with this name.
    #[must_use]
    pub fn landmark(&self, name: &str) -> Option<&Landmark> {
        self.landmarks.iter().find(|l| l.name == name)
    }

    /// Points along every painted line and arc, about `step_cm` apart (farther when that would
    /// give more than [`MAX_LINE_SAMPLES`]), with the unit direction of the line there (field
    /// `[x, y]`, centimetres): where the calibration looks for lines.
    #[must_use]
    pub fn line_samples(&self, step_cm: f64) -> Vec<LineSample> {
        let total_cm: f64 = self
            .lines
            .iter()
            .map(|l| (l.to_cm[0] - l.from_cm[0]).hypot(l.to_cm[1] - l.from_cm[1]))
            .chain(
                self.arcs
                    .iter()
                    .map(|a| (a.to_rad - a.from_rad).abs() * a.radius_cm),
            )
            .filter(|v| v.is_finite())
            .sum();
        let step = step_cm
            .max(0.5)
            .max(total_cm / MAX_LINE_SAMPLES as f64)
            .max(f64::MIN_POSITIVE);
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

    /// The field a `--field` argument names: a shipped field by its name ([`SHIPPED_FIELDS`]),
    /// else a description file.
    ///
    /// # Errors
    /// [`FieldError::Unknown`] for a name that is neither shipped nor a file path (the shipped
    /// names listed), or the loader's error for a file.
    pub fn resolve(arg: &str) -> Result<Self, FieldError> {
        if let Some((_, text)) = SHIPPED_FIELDS.iter().find(|(name, _)| *name == arg) {
            return Self::from_json(text).map_err(|e| e.at(&format!("shipped field {arg}")));
        }
        let path = Path::new(arg);
        let looks_like_a_path = arg.contains(std::path::MAIN_SEPARATOR)
            || arg.contains('/')
            || path.extension().is_some();
        if !looks_like_a_path && !path.exists() {
            return Err(FieldError::Unknown {
                name: arg.to_owned(),
            });
        }
        Self::load(path)
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
    fn every_shipped_field_resolves_by_name_and_by_path_alike() {
        for (name, _) in SHIPPED_FIELDS {
            let by_name = FieldDescription::resolve(name).expect("shipped");
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("params/fields")
                .join(format!("{name}.json"));
            let by_path = FieldDescription::resolve(&path.display().to_string()).expect("the file");
            assert_eq!(by_name, by_path, "{name}");
            assert!(by_name.landmark("centre").is_some(), "{name}");
        }
        let err = FieldDescription::resolve("spl-2021").expect_err("unknown");
        let text = err.to_string();
        assert!(
            text.contains("\"spl-2021\"") && text.contains("spl-2020, ssl-div-a, ssl-div-b"),
            "{text}"
        );
        // A path that does not exist is the loader's error, naming the file.
        let err = FieldDescription::resolve("no/such/field.json").expect_err("missing");
        assert!(err.to_string().contains("no/such/field.json"), "{err}");
    }

    #[test]
    fn todays_fields_have_the_rule_books_dimensions() {
        let spl = FieldDescription::resolve("spl-2020").expect("shipped");
        let at = |f: &FieldDescription, n: &str| f.landmark(n).map(|l| l.field_cm);
        // SPL 2020: 9 × 6 m, centre circle 1.5 m across, penalty mark 1.3 m from the goal
        // line, penalty area 1.65 × 4 m, goal area 0.6 × 2.2 m, goal 1.5 m wide inside.
        assert_eq!(at(&spl, "+x left corner"), Some([450.0, 300.0]));
        assert_eq!(at(&spl, "centre circle left"), Some([0.0, 75.0]));
        assert_eq!(at(&spl, "+x penalty mark"), Some([320.0, 0.0]));
        assert_eq!(
            at(&spl, "-x penalty area left front corner"),
            Some([-285.0, -200.0])
        );
        assert_eq!(
            at(&spl, "+x goal area right front corner"),
            Some([390.0, -110.0])
        );
        let post = at(&spl, "+x goal left post foot").expect("post");
        // Post centres 5 cm (half a 10 cm post) outside the 1.5 m inner width.
        assert_eq!(post[1], 80.0);
        for (name, length, width, defense) in [
            ("ssl-div-a", 1200.0, 900.0, [480.0, 120.0]),
            ("ssl-div-b", 900.0, 600.0, [350.0, 100.0]),
        ] {
            let f = FieldDescription::resolve(name).expect("shipped");
            assert_eq!(
                at(&f, "+x left corner"),
                Some([length / 2.0, width / 2.0]),
                "{name}"
            );
            assert_eq!(at(&f, "+x defense area left front corner"), Some(defense));
            assert_eq!(at(&f, "centre circle left"), Some([0.0, 50.0]));
        }
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
    fn an_unknown_key_is_refused_naming_it() {
        let mut v = serde_json::to_value(FieldDescription::four_legged_2005()).expect("json");
        v["landmarks"][3]["heigth_cm"] = serde_json::json!(22.5);
        let err = FieldDescription::from_json(&v.to_string()).expect_err("a typo");
        assert!(
            err.to_string().contains("unknown field `heigth_cm`"),
            "{err}"
        );
        let mut v = serde_json::to_value(FieldDescription::four_legged_2005()).expect("json");
        v["ball_radius"] = serde_json::json!(4.0);
        let err = FieldDescription::from_json(&v.to_string()).expect_err("a typo");
        assert!(
            err.to_string().contains("unknown field `ball_radius`"),
            "{err}"
        );
    }

    #[test]
    fn a_line_a_kilometre_long_or_a_field_in_millimetres_is_refused() {
        let mut f = FieldDescription::four_legged_2005();
        f.lines[0].to_cm = [100_000.0, 0.0];
        let err = FieldDescription::from_json(&serde_json::to_string(&f).expect("json"))
            .expect_err("1 km");
        assert!(
            err.to_string().contains("lines[0].to_cm is 100000"),
            "{err}"
        );
        let mut f = FieldDescription::four_legged_2005();
        for l in &mut f.landmarks {
            l.field_cm = l.field_cm.map(|v| v * 10.0);
        }
        for l in &mut f.lines {
            l.from_cm = l.from_cm.map(|v| v * 10.0);
            l.to_cm = l.to_cm.map(|v| v * 10.0);
        }
        // The 2005 field in millimetres is 5.4 m wide: still within bounds (the calibration
        // warns of such points); ten times that is not a field.
        assert!(FieldDescription::from_json(&serde_json::to_string(&f).expect("json")).is_ok());
        let mut f = FieldDescription::four_legged_2005();
        f.arcs[0].to_rad = 1e9;
        let err = FieldDescription::from_json(&serde_json::to_string(&f).expect("json"))
            .expect_err("an arc of a billion radians");
        assert!(err.to_string().contains("arcs[0]"), "{err}");
    }

    #[test]
    fn line_samples_are_bounded_in_number() {
        // Built in code, not read: no bounds were checked.
        let mut f = FieldDescription::four_legged_2005();
        f.lines.push(LineSegment {
            from_cm: [0.0, 0.0],
            to_cm: [1e8, 0.0],
        });
        let n = f.line_samples(0.5).len();
        assert!(n <= MAX_LINE_SAMPLES, "{n}");
        let curves = crate::overhead::lines::projected_field_lines(
            &f,
            &crate::geometry::OverheadCamera::above_field_2005(),
        );
        let points: usize = curves.iter().map(Vec::len).sum();
        assert!(points < 100_000, "{points}");
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
