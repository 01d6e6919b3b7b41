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
#[error("{path}: {detail}")]
pub struct SensorTableError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub detail: String,
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
        let err = |detail: String| SensorTableError {
            path: path.to_owned(),
            detail,
        };
        let text = crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SIDE_FILE_BYTES,
            "a sensor table",
        )
        .map_err(|e| err(e.to_string()))?;
        let is_json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        let table = if is_json {
            Self::parse_json(&text)
        } else {
            Self::parse_csv(&text)
        };
        table.map_err(err)
    }

    /// Parses CSV text (see the module docs).
    ///
    /// # Errors
    /// A message with the line number.
    pub fn parse_csv(text: &str) -> Result<Self, String> {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .flexible(false)
            .from_reader(text.as_bytes());
        let headers: Vec<String> = reader
            .headers()
            .map_err(|e| format!("cannot read the header row: {e}"))?
            .iter()
            .map(str::to_owned)
            .collect();
        if let Some(bad) = headers.iter().find(|h| !known_column(h)) {
            return Err(format!("unknown column '{bad}' (known: {})", known_list()));
        }
        let mut table = Self::default();
        for (i, record) in reader.records().enumerate() {
            let line = i + 2;
            let record = record.map_err(|e| format!("line {line}: {e}"))?;
            let mut cells = Vec::new();
            for (name, cell) in headers.iter().zip(record.iter()) {
                if cell.is_empty() {
                    continue;
                }
                let v: f64 = cell
                    .parse()
                    .map_err(|_| format!("line {line}, column {name}: '{cell}' is not a number"))?;
                cells.push((name.as_str(), v));
            }
            table.push_row(&format!("line {line}"), cells)?;
        }
        Ok(table)
    }

    /// Parses JSON text: an array of objects (see the module docs).
    ///
    /// # Errors
    /// A message with the element number.
    pub fn parse_json(text: &str) -> Result<Self, String> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format!("not valid JSON: {e}"))?;
        let rows = value
            .as_array()
            .ok_or("expected a JSON array of objects, one per frame")?;
        let mut table = Self::default();
        for (i, row) in rows.iter().enumerate() {
            let obj = row
                .as_object()
                .ok_or_else(|| format!("element {i} is not an object"))?;
            let mut cells = Vec::new();
            for (name, v) in obj {
                if !known_column(name) {
                    return Err(format!(
                        "element {i}: unknown key '{name}' (known: {})",
                        known_list()
                    ));
                }
                match v {
                    serde_json::Value::Null => {}
                    serde_json::Value::Number(n) => {
                        cells.push((name.as_str(), n.as_f64().unwrap_or(f64::NAN)));
                    }
                    other => {
                        return Err(format!(
                            "element {i}, key {name}: {other} is not a number or null"
                        ));
                    }
                }
            }
            table.push_row(&format!("element {i}"), cells)?;
        }
        Ok(table)
    }

    fn push_row(&mut self, at: &str, cells: Vec<(&str, f64)>) -> Result<(), String> {
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
                        return Err(format!("{at}: frame {v} is not a frame index"));
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
            .map_err(|e| format!("{at}: {e}"))?;
        if let Some(f) = row.frame
            && self.by_frame.insert(f, self.rows.len()).is_some()
        {
            return Err(format!("{at}: frame {f} has more than one row"));
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
        assert!(e.contains("unknown column 'head_pan'"), "{e}");
        let e = SensorTable::parse_csv("head_pan_rad\nabc\n").unwrap_err();
        assert!(e.contains("line 2") && e.contains("abc"), "{e}");
        let e = SensorTable::parse_csv("frame,head_pan_rad\n1,0\n1,0\n").unwrap_err();
        assert!(e.contains("more than one row"), "{e}");
        assert!(SensorTable::parse_csv("frame\n-1\n").is_err());
    }

    #[test]
    fn json_array_of_objects() {
        let t = SensorTable::parse_json(
            r#"[{"head_pan_rad": 0.5, "battery_percent": null}, {"frame": 1, "pan_pwm": -0.2}]"#,
        )
        .unwrap();
        assert_eq!(t.for_frame(1).unwrap().readings.pan_pwm, Some(-0.2));
        assert!(t.for_frame(0).is_none(), "frame numbers given: by number");
        assert!(SensorTable::parse_json(r#"{"a": 1}"#).is_err());
        assert!(SensorTable::parse_json(r#"[{"typo": 1}]"#).is_err());
        assert!(SensorTable::parse_json(r#"[{"ir_far_cm": "far"}]"#).is_err());
    }
}
