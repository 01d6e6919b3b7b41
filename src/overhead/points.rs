//! Calibration points files (`*.points.json`, `FORMATS.md`): image points of named field
//! landmarks, as a user clicks them in the app or a tool writes them.
//!
//! `{"width": 640, "height": 480, "points": [{"name": "centre", "field_cm": [0, 0],
//! "image_px": [321.4, 238.0]}, …]}`. `field_cm` lie on the ground; `image_px` are in the
//! distorted image as the camera delivers it (pixel centres at +0.5). The project adds one
//! optional key per point, `height_cm`, for landmarks above the ground (goal-post tops): other
//! readers ignore it, and without it the point is on the ground as the format says.
//!
//! The format is an interchange format, so keys it does not have (another tool's) are not an
//! error: each is named in a warning and the rest is read.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::atomic_file::write_atomic;
use crate::geometry::ImagePoint;

/// One clicked landmark.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibrationPoint {
    /// The landmark's name.
    pub name: String,
    /// Field position `[x, y]`, centimetres.
    pub field_cm: [f64; 2],
    /// Height above the ground, centimetres (an extension of the format; 0 when absent).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub height_cm: f64,
    /// Where it is in the distorted image `[x, y]`, pixels.
    pub image_px: [f64; 2],
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl CalibrationPoint {
    /// The image position.
    #[must_use]
    pub fn image(&self) -> ImagePoint {
        ImagePoint::new(self.image_px[0], self.image_px[1])
    }
}

/// A points file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointsFile {
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// The clicked landmarks.
    pub points: Vec<CalibrationPoint>,
}

/// A points file as read: the format's keys and whatever else it holds.
#[derive(Deserialize)]
struct PointsRead {
    width: usize,
    height: usize,
    points: Vec<PointRead>,
    #[serde(flatten)]
    other: BTreeMap<String, serde_json::Value>,
}

/// A point as read.
#[derive(Deserialize)]
struct PointRead {
    name: String,
    field_cm: [f64; 2],
    #[serde(default)]
    height_cm: f64,
    image_px: [f64; 2],
    #[serde(flatten)]
    other: BTreeMap<String, serde_json::Value>,
}

/// Why a points file could not be read or written.
#[derive(Debug, Error)]
pub enum PointsError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The error.
        source: std::io::Error,
    },
    /// Not a points file.
    #[error("{path}: not a calibration points file: {source}")]
    Parse {
        /// The file.
        path: String,
        /// The error.
        source: serde_json::Error,
    },
    /// JSON of the right shape with a value that is unusable.
    #[error("{path}: {problem}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        #[source]
        problem: PointsProblem,
    },
}

impl PointsError {
    /// The same error naming the file `path`.
    #[must_use]
    pub fn at(self, path: &str) -> Self {
        let path = path.to_owned();
        match self {
            Self::Io { source, .. } => Self::Io { path, source },
            Self::Parse { source, .. } => Self::Parse { path, source },
            Self::Invalid { problem, .. } => Self::Invalid { path, problem },
        }
    }
}

/// What makes a points file of the right shape unusable.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PointsProblem {
    /// A zero width or height.
    #[error("image size {width}x{height} is empty")]
    EmptyImage {
        /// The file's width, pixels.
        width: usize,
        /// The file's height, pixels.
        height: usize,
    },
    /// A coordinate or height that is NaN or infinite.
    #[error("point {name:?} has a value that is not a number")]
    NotANumber {
        /// The point's name.
        name: String,
    },
}

impl PointsFile {
    /// An empty file for an image size.
    #[must_use]
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            points: Vec::new(),
        }
    }

    /// Reads and checks a points file; keys the format does not have are named in warnings
    /// (logged) and ignored.
    ///
    /// # Errors
    /// [`PointsError`] for a missing, oversized or non-regular file, bad JSON, a zero image size
    /// or a non-finite value.
    pub fn load(path: &Path) -> Result<Self, PointsError> {
        let (file, warnings) = Self::load_with_warnings(path)?;
        for w in warnings {
            log::warn!("{w}");
        }
        Ok(file)
    }

    /// Like [`PointsFile::load`], with the warnings (unknown keys, naming the file) returned.
    ///
    /// # Errors
    /// As [`PointsFile::load`].
    pub fn load_with_warnings(path: &Path) -> Result<(Self, Vec<String>), PointsError> {
        let name = path.display().to_string();
        let text = crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SMALL_FILE_BYTES,
            "a calibration points file",
        )
        .map_err(|source| PointsError::Io {
            path: name.clone(),
            source,
        })?;
        let (file, unknown) = Self::from_json(&text).map_err(|e| e.at(&name))?;
        let warnings = unknown
            .into_iter()
            .map(|key| {
                format!("{name}: unknown key '{key}' ignored (not part of the points format)")
            })
            .collect();
        Ok((file, warnings))
    }

    /// Parses and checks a points file's text; also gives the keys the format does not have
    /// (errors name no file until [`PointsError::at`]).
    ///
    /// # Errors
    /// [`PointsError::Parse`] or [`PointsError::Invalid`].
    pub fn from_json(text: &str) -> Result<(Self, Vec<String>), PointsError> {
        let read: PointsRead = serde_json::from_str(text).map_err(|source| PointsError::Parse {
            path: String::new(),
            source,
        })?;
        let mut unknown: Vec<String> = read.other.into_keys().collect();
        let mut points = Vec::with_capacity(read.points.len());
        for (i, p) in read.points.into_iter().enumerate() {
            unknown.extend(p.other.into_keys().map(|k| format!("points[{i}].{k}")));
            points.push(CalibrationPoint {
                name: p.name,
                field_cm: p.field_cm,
                height_cm: p.height_cm,
                image_px: p.image_px,
            });
        }
        let file = Self {
            width: read.width,
            height: read.height,
            points,
        };
        file.check().map_err(|problem| PointsError::Invalid {
            path: String::new(),
            problem,
        })?;
        Ok((file, unknown))
    }

    fn check(&self) -> Result<(), PointsProblem> {
        if self.width == 0 || self.height == 0 {
            return Err(PointsProblem::EmptyImage {
                width: self.width,
                height: self.height,
            });
        }
        for p in &self.points {
            let values = [
                p.field_cm[0],
                p.field_cm[1],
                p.height_cm,
                p.image_px[0],
                p.image_px[1],
            ];
            if !values.iter().all(|v| v.is_finite()) {
                return Err(PointsProblem::NotANumber {
                    name: p.name.clone(),
                });
            }
        }
        Ok(())
    }

    /// Writes the file atomically (pretty JSON).
    ///
    /// # Errors
    /// [`PointsError::Io`] when it cannot be written.
    pub fn save(&self, path: &Path) -> Result<(), PointsError> {
        let mut text = serde_json::to_string_pretty(self).map_err(|source| PointsError::Parse {
            path: path.display().to_string(),
            source,
        })?;
        text.push('\n');
        write_atomic(path, text.as_bytes()).map_err(|source| PointsError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Adds a point, replacing an earlier one of the same name (a re-click).
    pub fn set(&mut self, point: CalibrationPoint) {
        match self.points.iter_mut().find(|p| p.name == point.name) {
            Some(old) => *old = point,
            None => self.points.push(point),
        }
    }

    /// Removes the point of this name; whether there was one.
    pub fn remove(&mut self, name: &str) -> bool {
        let before = self.points.len();
        self.points.retain(|p| p.name != name);
        self.points.len() != before
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_formats_example_parses_and_round_trips() {
        let text = r#"{"width": 640, "height": 480, "points": [{"name": "centre",
            "field_cm": [0, 0], "image_px": [321.4, 238.0]}]}"#;
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("a.points.json");
        std::fs::write(&path, text).expect("write");
        let file = PointsFile::load(&path).expect("loads");
        assert_eq!(file.points[0].image_px, [321.4, 238.0]);
        assert_eq!(file.points[0].height_cm, 0.0);
        let out = dir.path().join("b.points.json");
        file.save(&out).expect("saves");
        let written = std::fs::read_to_string(&out).expect("read");
        assert!(
            !written.contains("height_cm"),
            "ground points stay in the fixed format"
        );
        assert_eq!(PointsFile::load(&out).expect("loads"), file);
    }

    #[test]
    fn unknown_keys_are_named_in_warnings_and_the_rest_is_read() {
        let text = r#"{"width": 640, "height": 480, "camera": "ssl-1", "points": [{"name": "goal top",
            "field_cm": [0, 0], "heigth_cm": 22.5, "image_px": [321.4, 238.0]}]}"#;
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("typo.points.json");
        std::fs::write(&path, text).expect("write");
        let (file, warnings) = PointsFile::load_with_warnings(&path).expect("loads");
        assert_eq!(file.points.len(), 1);
        assert_eq!(file.points[0].image_px, [321.4, 238.0]);
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(
            warnings[0].contains("typo.points.json") && warnings[0].contains("'camera'"),
            "{warnings:?}"
        );
        assert!(
            warnings[1].contains("'points[0].heigth_cm'"),
            "{warnings:?}"
        );
    }

    #[test]
    fn a_re_click_replaces_the_point_of_that_name() {
        let mut file = PointsFile::new(640, 480);
        let p = |x| CalibrationPoint {
            name: "centre".into(),
            field_cm: [0.0, 0.0],
            height_cm: 0.0,
            image_px: [x, 10.0],
        };
        file.set(p(1.0));
        file.set(p(2.0));
        assert_eq!(file.points.len(), 1);
        assert_eq!(file.points[0].image_px[0], 2.0);
        assert!(file.remove("centre") && !file.remove("centre"));
    }

    #[test]
    fn nan_and_empty_sizes_are_refused_with_the_file_name() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("bad.points.json");
        std::fs::write(&path, r#"{"width": 0, "height": 480, "points": []}"#).expect("write");
        let err = PointsFile::load(&path).expect_err("empty size");
        assert!(err.to_string().contains("bad.points.json"), "{err}");
        assert!(
            matches!(
                &err,
                PointsError::Invalid {
                    problem: PointsProblem::EmptyImage {
                        width: 0,
                        height: 480
                    },
                    ..
                }
            ),
            "{err:?}"
        );
        assert!(
            err.to_string().contains("image size 0x480 is empty"),
            "{err}"
        );
        std::fs::write(&path, "{\"width\": 640").expect("write");
        assert!(matches!(
            PointsFile::load(&path),
            Err(PointsError::Parse { .. })
        ));
    }

    #[test]
    fn a_points_file_of_the_wrong_shape_names_what_is_wrong() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("shape.points.json");
        // One image coordinate instead of two.
        std::fs::write(
            &path,
            r#"{"width": 640, "height": 480, "points": [{"name": "centre",
                "field_cm": [0, 0], "image_px": [321.4]}]}"#,
        )
        .expect("write");
        let err = PointsFile::load(&path).expect_err("short image_px");
        assert!(matches!(err, PointsError::Parse { .. }), "{err:?}");
        let text = err.to_string();
        assert!(
            text.contains("shape.points.json")
                && text.contains("not a calibration points file")
                && text.contains("expected an array of length 2"),
            "{text}"
        );
        // No list of points at all.
        std::fs::write(&path, r#"{"width": 640, "height": 480}"#).expect("write");
        let text = PointsFile::load(&path).expect_err("no points").to_string();
        assert!(text.contains("missing field `points`"), "{text}");
    }
}
