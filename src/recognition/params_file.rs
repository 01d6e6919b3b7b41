//! Recognition parameter files (`--params P.json`, `params/spl2009.json`): any subset of
//! [`RecognitionParams`]' fields over the defaults, checked so that a typo or a nonsense value is
//! an error naming the field instead of a silent no-op.
//!
//! Checked: every key exists (a misspelt `"bal"` would otherwise change nothing), every number
//! is finite, every `[low, high]` range is ordered, sizes are positive, the field of view lies
//! strictly between 0° and 180°, the shutter's read-out time between 0 and 1 s, the overhead
//! recogniser's fills and layout agreement (shares) above 0 and at most 1, its area ratios
//! positive.

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::RecognitionParams;

/// Why a parameters file was refused; names the file and the field.
#[derive(Debug, thiserror::Error)]
pub enum ParamsError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// Not JSON, or a value of the wrong type.
    #[error("{path}: not valid recognition parameters ({detail})")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        detail: String,
    },
    /// A key that no parameter has.
    #[error("{path}: unknown parameter '{key}'{hint}")]
    UnknownKey {
        /// The file.
        path: PathBuf,
        /// The key's path, e.g. `ball.diamter_cm`.
        key: String,
        /// ` (did you mean 'ball'?)` or the known keys.
        hint: String,
    },
    /// A value outside what the parameter can mean.
    #[error("{path}: {key} = {value}: {why}")]
    OutOfRange {
        /// The file.
        path: PathBuf,
        /// The key's path.
        key: String,
        /// The value as written.
        value: String,
        /// What it must be.
        why: &'static str,
    },
}

/// Reads and checks a parameters file.
///
/// # Errors
/// [`ParamsError`] naming the file and, for a bad key or value, the field.
pub fn load(path: &Path) -> Result<RecognitionParams, ParamsError> {
    let text = crate::input_file::read_text_bounded(
        path,
        crate::input_file::MAX_SIDE_FILE_BYTES,
        "a parameters file",
    )
    .map_err(|source| ParamsError::Io {
        path: path.to_owned(),
        source,
    })?;
    from_json(&text).map_err(|e| e.at(path))
}

/// Parses and checks parameters from JSON text (errors carry an empty path until
/// [`ParamsError::at`] names the file).
///
/// # Errors
/// [`ParamsError`] for bad JSON, unknown keys or values out of range.
pub fn from_json(text: &str) -> Result<RecognitionParams, ParamsError> {
    let parse = |e: serde_json::Error| ParamsError::Parse {
        path: PathBuf::new(),
        detail: e.to_string(),
    };
    let given: Value = serde_json::from_str(text).map_err(parse)?;
    let params: RecognitionParams = serde_json::from_value(given.clone()).map_err(parse)?;
    let full = serde_json::to_value(params).map_err(parse)?;
    check_keys(&given, &full, "")?;
    check_values(&full, "")?;
    Ok(params)
}

impl ParamsError {
    /// The same error naming `path`.
    #[must_use]
    pub fn at(self, path: &Path) -> Self {
        let p = path.to_owned();
        match self {
            Self::Io { source, .. } => Self::Io { path: p, source },
            Self::Parse { detail, .. } => Self::Parse { path: p, detail },
            Self::UnknownKey { key, hint, .. } => Self::UnknownKey { path: p, key, hint },
            Self::OutOfRange {
                key, value, why, ..
            } => Self::OutOfRange {
                path: p,
                key,
                value,
                why,
            },
        }
    }
}

/// Every key of `given` must be a key of `full` (the parameters with every field), recursively.
fn check_keys(given: &Value, full: &Value, prefix: &str) -> Result<(), ParamsError> {
    let (Value::Object(g), Value::Object(f)) = (given, full) else {
        return Ok(());
    };
    for (k, v) in g {
        let key = join(prefix, k);
        match f.get(k) {
            Some(fv) => check_keys(v, fv, &key)?,
            None => {
                let known: Vec<&str> = f.keys().map(String::as_str).collect();
                return Err(ParamsError::UnknownKey {
                    path: PathBuf::new(),
                    hint: hint(k, &known),
                    key,
                });
            }
        }
    }
    Ok(())
}

/// ` (did you mean 'x'?)` for a close known key, else the list of known keys.
fn hint(key: &str, known: &[&str]) -> String {
    let best = known
        .iter()
        .map(|k| (edit_distance(key, k), *k))
        .min_by_key(|(d, _)| *d);
    match best {
        Some((d, k)) if d <= 2.max(key.len() / 3) => format!(" (did you mean '{k}'?)"),
        _ => format!(" (known here: {})", known.join(", ")),
    }
}

/// Levenshtein distance, for the "did you mean" hint.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_owned()
    } else {
        format!("{prefix}.{key}")
    }
}

/// Range checks over the complete parameters (defaults included, so a check that fires names
/// a value the file set).
fn check_values(v: &Value, key: &str) -> Result<(), ParamsError> {
    let bad = |why: &'static str| ParamsError::OutOfRange {
        path: PathBuf::new(),
        key: key.to_owned(),
        value: v.to_string(),
        why,
    };
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                check_values(x, &join(key, k))?;
            }
        }
        Value::Array(items) => {
            if let [Value::Number(a), Value::Number(b)] = items.as_slice()
                && let (Some(a), Some(b)) = (a.as_f64(), b.as_f64())
                && a > b
            {
                return Err(bad("a range must be [low, high], low ≤ high"));
            }
            if key.ends_with("area_ratio")
                && let Some(Value::Number(a)) = items.first()
                && a.as_f64().is_none_or(|a| a <= 0.0)
            {
                return Err(bad("an area ratio must be positive"));
            }
        }
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(f64::NAN);
            let name = key.rsplit('.').next().unwrap_or(key);
            if !x.is_finite() {
                return Err(bad("must be a finite number"));
            }
            let size = name.ends_with("diameter_cm")
                || name.ends_with("radius_cm")
                || name == "height_cm"
                || name == "width_cm"
                || name == "min_height_cm";
            if size && x <= 0.0 {
                return Err(bad("a size must be positive"));
            }
            if name.ends_with("fov_deg") && !(x > 0.0 && x < 180.0) {
                return Err(bad(
                    "a field of view lies strictly between 0 and 180 degrees",
                ));
            }
            if name.ends_with("readout_s") && !(0.0..1.0).contains(&x) {
                return Err(bad("a read-out time lies between 0 and 1 second"));
            }
            if key.starts_with("overhead.")
                && (name.ends_with("_fill") || name.ends_with("_agreement"))
                && !(x > 0.0 && x <= 1.0)
            {
                return Err(bad("a share lies between 0 (excluded) and 1"));
            }
        }
        _ => {}
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        from_json(text)
            .unwrap_err()
            .at(Path::new("p.json"))
            .to_string()
    }

    #[test]
    fn a_subset_over_the_defaults_is_taken() {
        let p = from_json(r#"{"ball": {"diameter_cm": 8.6}, "other_camera_fov_deg": 45}"#).unwrap();
        assert_eq!(p.ball.diameter_cm, 8.6);
        assert_eq!(p.other_camera_fov_deg, 45.0);
        assert_eq!(p.goals, RecognitionParams::default().goals);
    }

    #[test]
    fn an_unknown_key_is_named_with_the_closest_known_one() {
        let e = err(r#"{"bal": {"diameter_cm": 8.6}}"#);
        assert_eq!(e, "p.json: unknown parameter 'bal' (did you mean 'ball'?)");
        let e = err(r#"{"ball": {"diamter_cm": 8.6}}"#);
        assert!(
            e.contains("'ball.diamter_cm'") && e.contains("'diameter_cm'"),
            "{e}"
        );
    }

    #[test]
    fn nonsense_values_name_their_field() {
        let e = err(r#"{"ball": {"diameter_cm": -8}}"#);
        assert!(
            e.contains("ball.diameter_cm = -8.0") && e.contains("positive"),
            "{e}"
        );
        let e = err(r#"{"ball": {"height_cm": [20, 5]}}"#);
        assert!(
            e.contains("ball.height_cm") && e.contains("low ≤ high"),
            "{e}"
        );
        for fov in ["0", "180", "-3"] {
            let e = err(&format!(r#"{{"other_camera_fov_deg": {fov}}}"#));
            assert!(e.contains("other_camera_fov_deg"), "{e}");
        }
    }

    #[test]
    fn the_overhead_section_is_read_and_checked() {
        let p = from_json(
            r#"{"overhead": {"team_dot_diameter_cm": 5.0, "id_dot_ring_radius_cm": 6.5}}"#,
        )
        .unwrap();
        assert_eq!(p.overhead.team_dot_diameter_cm, 5.0);
        assert_eq!(p.overhead.id_dot_ring_radius_cm, 6.5);
        assert_eq!(
            p.overhead.min_layout_agreement,
            RecognitionParams::default().overhead.min_layout_agreement
        );
        let e = err(r#"{"overhead": {"team_dot_diamter_cm": 5.0}}"#);
        assert!(e.contains("'overhead.team_dot_diamter_cm'"), "{e}");
        let e = err(r#"{"overhead": {"ball_min_fill": 1.5}}"#);
        assert!(
            e.contains("overhead.ball_min_fill") && e.contains("share"),
            "{e}"
        );
        let e = err(r#"{"overhead": {"team_dot_diameter_cm": 0}}"#);
        assert!(e.contains("positive"), "{e}");
        let e = err(r#"{"overhead": {"area_ratio": [0, 2]}}"#);
        assert!(e.contains("area ratio"), "{e}");
    }

    #[test]
    fn the_shipped_parameter_set_passes() {
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("params/spl2009.json"),
        )
        .unwrap();
        assert!(from_json(&text).is_ok());
    }
}
