//! Tekkotsu / CMVision threshold maps (`.tm`) with their colour file (`.col`), AIBO ERS-7.
//!
//! A `.tm` is an ASCII header `TMAP\nYUV'8\n16 64 64\n` (magic, colour space, cells per axis Y,
//! U, V) and then one byte per cell, Y major; the bytes index the `.col` file, whose lines read
//! `index (r g b) "name" merge density`. The axis order `[y][u][v]` was marked unverified; the
//! real `tekkotsu-7general.tm` confirms it: orange cells lie at low U / high V (centroid 55,
//! 206), yellow at the lowest U (36, 167), blue at high U / low V (204, 112), pink at high V
//! (124, 216), green low on both (69, 63). Read the other way, orange would be blue.
//!
//! Classes map by *name* (`class_for_name`): "unclassified" → 0, "unsaturated" (Tekkotsu's
//! bright, washed-out class: lines, walls, the robots' white) → white, "blue" → sky blue (the
//! AIBO league's goals and beacons), and any of our own names ("dark blue", "yellow-orange"…)
//! as themselves. A name with no counterpart is left unclassified, with a note.
//!
//! Output: 6 bits per channel for the usual 16×64×64 map, each Y slab repeated 4 times (exact).

use std::path::{Path, PathBuf};

use thiserror::Error;

use super::{Channel, Converted, SourceFormat, SourceGrid, TableError, build};
use crate::lut::ColourClass;

/// What is wrong with a `.col` file.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ColError {
    /// One line is malformed.
    #[error("line {line}: {problem}: '{text}'")]
    Line {
        /// Line number, from 1.
        line: usize,
        /// What is wrong with it.
        problem: ColLineProblem,
        /// The line, trimmed.
        text: String,
    },
    /// No line names a colour.
    #[error("no colours in the .col file")]
    NoColours,
}

/// What is wrong with one line of a `.col` file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum ColLineProblem {
    /// The line does not start with a number 0..=255.
    #[error("no colour index (0..=255) first")]
    NoIndex,
    /// The line has no name in double quotes.
    #[error("no quoted colour name")]
    NoName,
    /// An earlier line has the same index.
    #[error("index given twice")]
    RepeatedIndex,
}

/// What is wrong with a `.tm` threshold map.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ThresholdMapError {
    /// Fewer than three header lines in the first 256 bytes.
    #[error("no complete three-line header (TMAP, colour space, sizes)")]
    NoHeader,
    /// The first line is not `TMAP`.
    #[error("header starts '{first}', not TMAP")]
    NotTmap {
        /// The first line.
        first: String,
    },
    /// The colour space is not YUV.
    #[error("colour space '{space}' is not YUV")]
    NotYuv {
        /// The second line.
        space: String,
    },
    /// The sizes line is not three numbers.
    #[error("sizes line '{line}' is not three numbers")]
    BadSizes {
        /// The third line.
        line: String,
    },
    /// An axis size that is no power of two in 2..=256.
    #[error("axis size {size} is not a power of two from 2 to 256")]
    BadAxisSize {
        /// Cells along the axis.
        size: u32,
    },
    /// Fewer cells after the header than the sizes need.
    #[error(
        "{len} bytes of cells after the header; {}×{}×{} needs {need}",
        1u32 << .bits[0], 1u32 << .bits[1], 1u32 << .bits[2]
    )]
    ShortCells {
        /// Bytes after the header.
        len: usize,
        /// Bits per axis (Y, U, V).
        bits: [u8; 3],
        /// Cells the sizes need.
        need: usize,
    },
}

/// One line of a `.col` file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColEntry {
    /// The value in the `.tm` cells.
    pub index: u8,
    /// The quoted name.
    pub name: String,
    /// Our class for that name, if there is one.
    pub class: Option<ColourClass>,
}

/// Our class for a Tekkotsu colour name (see the module docs).
#[must_use]
pub fn class_for_name(name: &str) -> Option<ColourClass> {
    let lower = name.trim().to_ascii_lowercase();
    match lower.as_str() {
        "unclassified" | "none" | "background" | "clear" => {
            return Some(ColourClass::Unclassified);
        }
        "unsaturated" => return Some(ColourClass::White),
        _ => {}
    }
    if let Some(c) = ColourClass::parse(&lower) {
        return Some(c);
    }
    let has = |k: &str| lower.contains(k);
    Some(if has("orange") {
        ColourClass::Orange
    } else if has("pink") {
        ColourClass::Pink
    } else if has("yellow") {
        ColourClass::Yellow
    } else if has("green") {
        ColourClass::Green
    } else if has("blue") || has("cyan") {
        ColourClass::SkyBlue
    } else if has("white") {
        ColourClass::White
    } else if has("red") {
        ColourClass::Red
    } else if has("black") || has("grey") || has("gray") {
        ColourClass::Black
    } else {
        return None;
    })
}

/// Parses a `.col` file.
///
/// # Errors
/// [`ColError`] naming the line that has no index or no quoted name, or repeats an index.
pub fn parse_col(text: &str) -> Result<Vec<ColEntry>, ColError> {
    let mut out: Vec<ColEntry> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |problem| ColError::Line {
            line: n + 1,
            problem,
            text: line.to_owned(),
        };
        let index: u8 = line
            .split_whitespace()
            .next()
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| bad(ColLineProblem::NoIndex))?;
        let mut quoted = line.split('"');
        let name = match (quoted.next(), quoted.next()) {
            (Some(_), Some(name)) if line.matches('"').count() >= 2 => name.to_owned(),
            _ => return Err(bad(ColLineProblem::NoName)),
        };
        if out.iter().any(|e| e.index == index) {
            return Err(bad(ColLineProblem::RepeatedIndex));
        }
        out.push(ColEntry {
            index,
            class: class_for_name(&name),
            name,
        });
    }
    if out.is_empty() {
        return Err(ColError::NoColours);
    }
    Ok(out)
}

/// The `.col` file for a `.tm`: the same stem with `.col`, else the only `.col` in its folder.
#[must_use]
pub fn find_col(tm: &Path) -> Option<PathBuf> {
    let same = tm.with_extension("col");
    if same.is_file() {
        return Some(same);
    }
    let dir = tm
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut cols = std::fs::read_dir(dir).ok()?.filter_map(|e| {
        let p = e.ok()?.path();
        p.extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("col"))
            .then_some(p)
    });
    let first = cols.next()?;
    cols.next().is_none().then_some(first)
}

/// Parses the `.tm` header; returns cells per axis (Y, U, V) as bits and the data offset.
fn parse_header(bytes: &[u8]) -> Result<([u8; 3], usize), ThresholdMapError> {
    let mut lines = Vec::new();
    let mut start = 0;
    for (i, &b) in bytes.iter().enumerate().take(256) {
        if b == b'\n' {
            lines.push(String::from_utf8_lossy(&bytes[start..i]).trim().to_owned());
            start = i + 1;
            if lines.len() == 3 {
                break;
            }
        }
    }
    if lines.len() < 3 {
        return Err(ThresholdMapError::NoHeader);
    }
    if lines[0] != "TMAP" {
        return Err(ThresholdMapError::NotTmap {
            first: lines[0].clone(),
        });
    }
    if !lines[1].starts_with("YUV") {
        return Err(ThresholdMapError::NotYuv {
            space: lines[1].clone(),
        });
    }
    let bad_sizes = || ThresholdMapError::BadSizes {
        line: lines[2].clone(),
    };
    let sizes: Vec<u32> = lines[2]
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| bad_sizes())?;
    let [y, u, v] = sizes[..] else {
        return Err(bad_sizes());
    };
    let bits = |size: u32| {
        (size.is_power_of_two() && (2..=256).contains(&size))
            .then(|| u8::try_from(size.trailing_zeros()).unwrap_or(8))
            .ok_or(ThresholdMapError::BadAxisSize { size })
    };
    Ok(([bits(y)?, bits(u)?, bits(v)?], start))
}

/// Converts a `.tm` file's bytes with the classes of its `.col` file.
///
/// # Errors
/// [`TableError::Threshold`] for a bad header or too few cells.
pub fn convert(bytes: &[u8], col: &[ColEntry]) -> Result<Converted, TableError> {
    let (bits, offset) = parse_header(bytes)?;
    let need = 1usize << bits.iter().map(|&b| u32::from(b)).sum::<u32>();
    let data = &bytes[offset..];
    if data.len() < need {
        return Err(ThresholdMapError::ShortCells {
            len: data.len(),
            bits,
            need,
        }
        .into());
    }
    let grid = SourceGrid {
        bits,
        axes: [Channel::Y, Channel::U, Channel::V],
        cells: data[..need].to_vec(),
    };
    let map = |v: u8| {
        col.iter().find(|e| e.index == v).map(|e| match e.class {
            Some(c) => (e.name.clone(), c),
            None => (
                format!("{} (no eotn class)", e.name),
                ColourClass::Unclassified,
            ),
        })
    };
    let mut converted = build(SourceFormat::TekkotsuTm, &grid, &map)?;
    for e in col.iter().filter(|e| e.class.is_none()) {
        converted.notes.push(format!(
            "colour {} \"{}\" has no eotn class; its cells are left unclassified",
            e.index, e.name
        ));
    }
    if data.len() > need {
        converted.notes.push(format!(
            "{} bytes after the cells ignored",
            data.len() - need
        ));
    }
    Ok(converted)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    const COL: &str = "0 (128 128 128) \"unclassified\" 8 1.00\n\
                       1 (167 152 116) \"unsaturated\" 8 0.75\n\
                       4 (235 127 52) \"orange\" 8 0.75\n\
                       7 (1 2 3) \"mauve\" 8 0.75\n";

    fn tm(cells: &[u8]) -> Vec<u8> {
        let mut v = b"TMAP\nYUV'8\n16 64 64\n".to_vec();
        v.extend_from_slice(cells);
        v
    }

    #[test]
    fn header_col_and_axes() {
        let col = parse_col(COL).unwrap();
        assert_eq!(col.len(), 4);
        assert_eq!(col[1].class, Some(ColourClass::White));
        assert_eq!(col[3].class, None);
        let mut cells = vec![0u8; 1 << 16];
        cells[(8 << 12) | (14 << 6) | 51] = 4;
        cells[(8 << 12) | (14 << 6) | 52] = 7;
        let c = convert(&tm(&cells), &col).unwrap();
        assert_eq!(c.table.bits(), 6);
        assert_eq!(
            c.table.class_of(Yuv::new(140, 57, 205)),
            ColourClass::Orange
        );
        assert_eq!(
            c.table.class_of(Yuv::new(140, 205, 57)),
            ColourClass::Unclassified
        );
        assert_eq!(c.table.class_counts()[1], 4);
        assert!(c.notes.iter().any(|n| n.contains("mauve")), "{:?}", c.notes);
    }

    #[test]
    fn bad_inputs_say_what_is_wrong() {
        let col = parse_col(COL).unwrap();
        let threshold = |bytes: &[u8]| match convert(bytes, &col) {
            Err(TableError::Threshold(e)) => e,
            other => panic!("expected a threshold-map error, got {other:?}"),
        };
        let short = threshold(b"TMAP\nYUV'8\n16 64 64\n\0\0");
        assert!(matches!(
            short,
            ThresholdMapError::ShortCells {
                len: 2,
                need: 65536,
                ..
            }
        ));
        assert!(
            short.to_string().contains("16×64×64 needs 65536"),
            "{short}"
        );
        let not_tmap = threshold(b"TMAX\nYUV'8\n16 64 64\n");
        assert!(not_tmap.to_string().contains("TMAP"), "{not_tmap}");
        assert_eq!(
            threshold(b"TMAP\nYUV'8\n16 60 64\n"),
            ThresholdMapError::BadAxisSize { size: 60 }
        );
        assert_eq!(threshold(b"TMAP\nYUV"), ThresholdMapError::NoHeader);
        assert_eq!(
            threshold(b"TMAP\nRGB\n16 64 64\n"),
            ThresholdMapError::NotYuv {
                space: "RGB".into()
            }
        );
        let no_index = parse_col("x (1 2 3) \"a\"").unwrap_err();
        assert!(matches!(
            no_index,
            ColError::Line {
                line: 1,
                problem: ColLineProblem::NoIndex,
                ..
            }
        ));
        assert!(no_index.to_string().contains("line 1"), "{no_index}");
        let unquoted = parse_col("1 (1 2 3) a").unwrap_err();
        assert!(unquoted.to_string().contains("quoted"), "{unquoted}");
        assert!(matches!(
            parse_col("1 \"a\"\n1 \"b\"").unwrap_err(),
            ColError::Line {
                line: 2,
                problem: ColLineProblem::RepeatedIndex,
                ..
            }
        ));
        assert_eq!(parse_col("# nothing\n"), Err(ColError::NoColours));
    }
}
