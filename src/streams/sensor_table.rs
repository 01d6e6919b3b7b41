//! Tables of sensor readings to import with frames: CSV or JSON.
//!
//! **CSV**: a header row of [`SensorReadings`] field names (any subset, any order), plus the
//! optional columns `frame` (the 0-based frame index the row belongs to) and `time_s` (capture
//! time in seconds). An empty cell is a reading the source did not provide.
//!
//! **JSON**: an array of objects with the same keys; `null` or a missing key is a missing reading.
//!
//! Without a `frame` column, row *i* belongs to frame *i*. Frames without a row get no readings.
//! Unknown columns are an error (a typo would otherwise silently lose a sensor); non-finite
//! values (`nan`, `inf`) are read as missing, with a warning.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::sensors::SensorReadings;

/// One row of a sensor table.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SensorRow {
    /// The frame index the row belongs to, when the table says.
    pub frame: Option<usize>,
    /// Capture time, seconds, when the table says.
    pub time_s: Option<f64>,
    /// The readings.
    pub readings: SensorReadings,
}

/// A loaded sensor table with its rows and the warnings loading produced.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SensorTable {
    rows: Vec<SensorRow>,
    by_frame: HashMap<usize, usize>,
    warnings: Vec<String>,
}

/// Why a sensor table could not be read; names the file and, where it can, the line.
#[derive(Debug, thiserror::Error)]
pub enum SensorTableError {
    /// Reading the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The contents are no sensor table.
    #[error("{path}: {problem}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        #[source]
        problem: SensorTableProblem,
    },
}

/// Where in a table a row is: a CSV line (from 1, the header being line 1) or a JSON element
/// (from 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowPlace {
    /// A CSV line.
    Line(usize),
    /// A JSON array element.
    Element(usize),
}

impl std::fmt::Display for RowPlace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Line(n) => write!(f, "line {n}"),
            Self::Element(i) => write!(f, "element {i}"),
        }
    }
}

/// What is wrong with a sensor table's contents.
#[derive(Debug, thiserror::Error)]
pub enum SensorTableProblem {
    /// The CSV header row cannot be read.
    #[error("cannot read the header row: {0}")]
    Header(#[source] csv::Error),
    /// A CSV column that is no reading.
    #[error("unknown column '{name}' (known: {})", known_list())]
    UnknownColumn {
        /// The column's name.
        name: String,
    },
    /// A CSV line that cannot be read.
    #[error("line {line}: {source}")]
    Record {
        /// Line number.
        line: usize,
        /// What the CSV reader said.
        source: csv::Error,
    },
    /// A CSV cell that is not a number.
    #[error("line {line}, column {column}: '{cell}' is not a number")]
    NotANumber {
        /// Line number.
        line: usize,
        /// The column's name.
        column: String,
        /// The cell's text.
        cell: String,
    },
    /// Not JSON.
    #[error("not valid JSON: {0}")]
    Json(#[source] serde_json::Error),
    /// JSON that is not an array.
    #[error("expected a JSON array of objects, one per frame")]
    NotAnArray,
    /// An array element that is not an object.
    #[error("element {element} is not an object")]
    NotAnObject {
        /// Element index.
        element: usize,
    },
    /// A JSON key that is no reading.
    #[error("element {element}: unknown key '{name}' (known: {})", known_list())]
    UnknownKey {
        /// Element index.
        element: usize,
        /// The key.
        name: String,
    },
    /// A JSON value that is neither a number nor null.
    #[error("element {element}, key {name}: {value} is not a number or null")]
    NotANumberOrNull {
        /// Element index.
        element: usize,
        /// The key.
        name: String,
        /// The value, as JSON.
        value: serde_json::Value,
    },
    /// A `frame` that is no frame index.
    #[error("{at}: frame {value} is not a frame index")]
    BadFrame {
        /// The row.
        at: RowPlace,
        /// The value given.
        value: f64,
    },
    /// Readings that do not fit the schema.
    #[error("{at}: {source}")]
    Readings {
        /// The row.
        at: RowPlace,
        /// What the schema said.
        source: serde_json::Error,
    },
    /// Two rows for one frame.
    #[error("{at}: frame {frame} has more than one row")]
    FrameTwice {
        /// The second row.
        at: RowPlace,
        /// Frame index.
        frame: usize,
    },
}

fn known_column(name: &str) -> bool {
    name == "frame"
        || name == "time_s"
        || SensorReadings::default()
            .fields()
            .iter()
            .any(|f| f.name == name)
}

fn known_list() -> String {
    let mut names: Vec<&str> = vec!["frame", "time_s"];
    names.extend(SensorReadings::default().fields().iter().map(|f| f.name));
    names.join(", ")
}

impl SensorTable {
    /// Loads a table: `.json` files as JSON, anything else as CSV.
    ///
    /// # Errors
    /// [`SensorTableError`] naming the file: unreadable, unknown column, a cell that is not a
    /// number, a repeated frame.
    pub fn load(path: &Path) -> Result<Self, SensorTableError> {
        let text = crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SIDE_FILE_BYTES,
            "a sensor table",
        )
        .map_err(|source| SensorTableError::Io {
            path: path.to_owned(),
            source,
        })?;
        let is_json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        let table = if is_json {
            Self::parse_json(&text)
        } else {
            Self::parse_csv(&text)
        };
        table.map_err(|problem| SensorTableError::Invalid {
            path: path.to_owned(),
            problem,
        })
    }

    /// Parses CSV text (see the module docs).
    ///
    /// # Errors
    /// [`SensorTableProblem`] with the line number.
    pub fn parse_csv(text: &str) -> Result<Self, SensorTableProblem> {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .flexible(false)
            .from_reader(text.as_bytes());
        let headers: Vec<String> = reader
            .headers()
            .map_err(SensorTableProblem::Header)?
            .iter()
            .map(str::to_owned)
            .collect();
        if let Some(bad) = headers.iter().find(|h| !known_column(h)) {
            return Err(SensorTableProblem::UnknownColumn { name: bad.clone() });
        }
        let mut table = Self::default();
        for (i, record) in reader.records().enumerate() {
            let line = i + 2;
            let record = record.map_err(|source| SensorTableProblem::Record { line, source })?;
            let mut cells = Vec::new();
            for (name, cell) in headers.iter().zip(record.iter()) {
                if cell.is_empty() {
                    continue;
                }
                let v: f64 = cell.parse().map_err(|_| SensorTableProblem::NotANumber {
                    line,
                    column: name.clone(),
                    cell: cell.to_owned(),
                })?;
                cells.push((name.as_str(), v));
            }
            table.push_row(RowPlace::Line(line), cells)?;
        }
        Ok(table)
    }

    /// Parses JSON text: an array of objects (see the module docs).
    ///
    /// # Errors
    /// [`SensorTableProblem`] with the element number.
    pub fn parse_json(text: &str) -> Result<Self, SensorTableProblem> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(SensorTableProblem::Json)?;
        let rows = value.as_array().ok_or(SensorTableProblem::NotAnArray)?;
        let mut table = Self::default();
        for (i, row) in rows.iter().enumerate() {
            let obj = row
                .as_object()
                .ok_or(SensorTableProblem::NotAnObject { element: i })?;
            let mut cells = Vec::new();
            for (name, v) in obj {
                if !known_column(name) {
                    return Err(SensorTableProblem::UnknownKey {
                        element: i,
                        name: name.clone(),
                    });
                }
                match v {
                    serde_json::Value::Null => {}
                    serde_json::Value::Number(n) => {
                        cells.push((name.as_str(), n.as_f64().unwrap_or(f64::NAN)));
                    }
                    other => {
                        return Err(SensorTableProblem::NotANumberOrNull {
                            element: i,
                            name: name.clone(),
                            value: other.clone(),
                        });
                    }
                }
            }
            table.push_row(RowPlace::Element(i), cells)?;
        }
        Ok(table)
    }

    fn push_row(
        &mut self,
        at: RowPlace,
        cells: Vec<(&str, f64)>,
    ) -> Result<(), SensorTableProblem> {
        let mut row = SensorRow::default();
        let mut map = serde_json::Map::new();
        for (name, v) in cells {
            if !v.is_finite() {
                self.warnings
                    .push(format!("{at}, {name}: {v} is not finite; read as missing"));
                continue;
            }
            match name {
                "frame" => {
                    if v < 0.0 || v.fract() != 0.0 || v > 1e15 {
                        return Err(SensorTableProblem::BadFrame { at, value: v });
                    }
                    #[expect(
                        clippy::cast_possible_truncation,
                        clippy::cast_sign_loss,
                        reason = "checked: a non-negative whole number below 1e15"
                    )]
                    let f = v as usize;
                    row.frame = Some(f);
                }
                "time_s" => row.time_s = Some(v),
                _ => {
                    map.insert(name.to_owned(), serde_json::Value::from(v));
                }
            }
        }
        row.readings = serde_json::from_value(serde_json::Value::Object(map))
            .map_err(|source| SensorTableProblem::Readings { at, source })?;
        if let Some(f) = row.frame
            && self.by_frame.insert(f, self.rows.len()).is_some()
        {
            return Err(SensorTableProblem::FrameTwice { at, frame: f });
        }
        self.rows.push(row);
        Ok(())
    }

    /// The rows in file order.
    #[must_use]
    pub fn rows(&self) -> &[SensorRow] {
        &self.rows
    }

    /// Non-finite values that were read as missing.
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// True when rows say which frame they belong to (a `frame` column or key).
    #[must_use]
    pub fn has_frame_numbers(&self) -> bool {
        !self.by_frame.is_empty()
    }

    /// The row for frame `index`: by the `frame` column when the table has one, else row
    /// `index`.
    #[must_use]
    pub fn for_frame(&self, index: usize) -> Option<&SensorRow> {
        if self.has_frame_numbers() {
            self.by_frame.get(&index).and_then(|&i| self.rows.get(i))
        } else {
            self.rows.get(index)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_with_frame_column_and_gaps() {
        let t = SensorTable::parse_csv(
            "frame,time_s,head_pan_rad,ir_far_cm\n0,0.0,0.1,55\n2,0.08,,60\n3,0.12,nan,61\n",
        )
        .unwrap();
        assert_eq!(t.rows().len(), 3);
        assert_eq!(t.for_frame(0).unwrap().readings.head_pan_rad, Some(0.1));
        assert!(t.for_frame(1).is_none());
        let r2 = t.for_frame(2).unwrap();
        assert_eq!(r2.readings.head_pan_rad, None);
        assert_eq!(r2.readings.ir_far_cm, Some(60.0));
        assert_eq!(r2.time_s, Some(0.08));
        assert_eq!(t.for_frame(3).unwrap().readings.head_pan_rad, None);
        assert_eq!(t.warnings().len(), 1, "{:?}", t.warnings());
    }

    #[test]
    fn csv_rows_in_order_without_frame_column() {
        let t = SensorTable::parse_csv("head_tilt_rad\n-0.2\n-0.3\n").unwrap();
        assert_eq!(t.for_frame(1).unwrap().readings.head_tilt_rad, Some(-0.3));
        assert!(t.for_frame(2).is_none());
    }

    #[test]
    fn csv_errors_name_the_problem() {
        let e = SensorTable::parse_csv("head_pan,ir_far_cm\n1,2\n").unwrap_err();
        assert!(
            matches!(&e, SensorTableProblem::UnknownColumn { name } if name == "head_pan"),
            "{e}"
        );
        assert!(e.to_string().contains("unknown column 'head_pan'"), "{e}");
        let e = SensorTable::parse_csv("head_pan_rad\nabc\n").unwrap_err();
        assert!(
            matches!(&e, SensorTableProblem::NotANumber { line: 2, cell, .. } if cell == "abc"),
            "{e}"
        );
        assert!(e.to_string().contains("line 2"), "{e}");
        let e = SensorTable::parse_csv("frame,head_pan_rad\n1,0\n1,0\n").unwrap_err();
        assert!(
            matches!(
                e,
                SensorTableProblem::FrameTwice {
                    at: RowPlace::Line(3),
                    frame: 1
                }
            ),
            "{e}"
        );
        assert!(
            e.to_string()
                .contains("line 3: frame 1 has more than one row"),
            "{e}"
        );
        assert!(matches!(
            SensorTable::parse_csv("frame\n-1\n"),
            Err(SensorTableProblem::BadFrame {
                at: RowPlace::Line(2),
                ..
            })
        ));
    }

    #[test]
    fn json_array_of_objects() {
        let t = SensorTable::parse_json(
            r#"[{"head_pan_rad": 0.5, "battery_percent": null}, {"frame": 1, "pan_pwm": -0.2}]"#,
        )
        .unwrap();
        assert_eq!(t.for_frame(1).unwrap().readings.pan_pwm, Some(-0.2));
        assert!(t.for_frame(0).is_none(), "frame numbers given: by number");
        assert!(matches!(
            SensorTable::parse_json(r#"{"a": 1}"#),
            Err(SensorTableProblem::NotAnArray)
        ));
        assert!(matches!(
            SensorTable::parse_json(r#"[{"typo": 1}]"#),
            Err(SensorTableProblem::UnknownKey { element: 0, .. })
        ));
        let e = SensorTable::parse_json(r#"[{}, {"ir_far_cm": "far"}]"#).unwrap_err();
        assert!(
            matches!(e, SensorTableProblem::NotANumberOrNull { element: 1, .. }),
            "{e}"
        );
        assert!(
            e.to_string().contains(r#"element 1, key ir_far_cm: "far""#),
            "{e}"
        );
    }
}
