//! B-Human colour tables (`.c64`), as shipped with their 2009 code release.
//!
//! Run-length encoded: repeated (`i32` run length, little-endian; `u8` class), ended by a run
//! length of 0; the runs fill 64³ = 262,144 cells indexed `[y>>2][cb>>2][cr>>2]` (our layout at
//! 6 bits). Checked on `coltable.c64`: orange cells at low Cb / high Cr (centroid 99, 162), blue
//! at high Cb / low Cr (153, 112), and frame 80 of the log recorded with it classifies as the
//! team said (field green, the ball one orange blob; see `tests/it/real_data.rs`).
//!
//! Mapping (`MAPPING`): B-Human's blue is the goal (sky blue), robot blue the uniform (dark
//! blue). A value with bit `0x80` set is a set of classes, bit *i* of the low seven meaning
//! B-Human class *i* + 1 (orange … red): a pair with a soft class becomes it (orange+yellow →
//! yellow-orange, orange+red → red-orange, yellow+green → shadow yellow), anything else the
//! first class of the set in B-Human's order (orange first: the ball matters most). Neither real
//! table uses such cells.

use thiserror::Error;

use super::{Channel, Converted, SourceFormat, SourceGrid, TableError, build, lookup};
use crate::lut::ColourClass;

/// Cells in a B-Human table (64³).
pub const CELLS: usize = 1 << 18;

/// B-Human class → name → our class.
pub const MAPPING: &[(u8, &str, ColourClass)] = &[
    (0, "none", ColourClass::Unclassified),
    (1, "orange", ColourClass::Orange),
    (2, "yellow", ColourClass::Yellow),
    (3, "blue", ColourClass::SkyBlue),
    (4, "white", ColourClass::White),
    (5, "green", ColourClass::Green),
    (6, "black", ColourClass::Black),
    (7, "red", ColourClass::Red),
    (8, "robot blue", ColourClass::DarkBlue),
];

/// The bit marking a multi-class cell.
pub const MULTI: u8 = 0x80;

/// The name and class of a B-Human value, multi-class cells included.
#[must_use]
pub fn class_of(value: u8) -> Option<(String, ColourClass)> {
    if value & MULTI == 0 {
        return lookup(MAPPING, value);
    }
    let members: Vec<u8> = (0..7)
        .filter(|i| value & (1 << i) != 0)
        .map(|i| i + 1)
        .collect();
    let names: Vec<String> = members
        .iter()
        .filter_map(|&m| lookup(MAPPING, m).map(|(n, _)| n))
        .collect();
    let class = match members.as_slice() {
        [] => return None,
        [1, 2] => ColourClass::YellowOrange,
        [1, 7] => ColourClass::RedOrange,
        [2, 5] => ColourClass::ShadowYellow,
        [first, ..] => lookup(MAPPING, *first)?.1,
    };
    Some((names.join("+"), class))
}

/// What is wrong with a `.c64` run-length stream; byte offsets count from the file's start.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum RleError {
    /// The stream ends where a run length should be.
    #[error("truncated at byte {at}: no run length (the stream ends with a run length of 0)")]
    NoRunLength {
        /// Where the run length should start.
        at: usize,
    },
    /// A run length below zero.
    #[error("negative run length {run} at byte {at}")]
    NegativeRun {
        /// The run length read.
        run: i32,
        /// Where it starts.
        at: usize,
    },
    /// A run length with no class byte after it.
    #[error("truncated at byte {at}: a run has no class byte")]
    NoClassByte {
        /// Where the class byte should be.
        at: usize,
    },
    /// The runs overflow the table.
    #[error("runs fill more than 64³ = {CELLS} cells (at byte {at})")]
    TooManyCells {
        /// Where the overflowing run starts.
        at: usize,
    },
    /// The runs end before the table is full.
    #[error("runs fill {cells} cells; a B-Human table has 64³ = {CELLS}")]
    TooFewCells {
        /// Cells filled.
        cells: usize,
    },
    /// Bytes follow the end marker.
    #[error("{extra} bytes after the end marker at byte {at}")]
    TrailingBytes {
        /// Bytes after the marker.
        extra: usize,
        /// Where the marker starts.
        at: usize,
    },
}

/// Expands the run-length stream to its 262,144 cells.
///
/// # Errors
/// [`RleError`]: a truncated stream, a negative run, runs past 64³ cells, or too few cells.
pub fn decode_rle(bytes: &[u8]) -> Result<Vec<u8>, RleError> {
    let mut cells = Vec::with_capacity(CELLS);
    let mut pos = 0usize;
    loop {
        let Some(len_bytes) = bytes.get(pos..pos + 4) else {
            return Err(RleError::NoRunLength { at: pos });
        };
        let run = i32::from_le_bytes([len_bytes[0], len_bytes[1], len_bytes[2], len_bytes[3]]);
        pos += 4;
        if run == 0 {
            break;
        }
        let run = usize::try_from(run).map_err(|_| RleError::NegativeRun { run, at: pos - 4 })?;
        let Some(&class) = bytes.get(pos) else {
            return Err(RleError::NoClassByte { at: pos });
        };
        pos += 1;
        if cells.len() + run > CELLS {
            return Err(RleError::TooManyCells { at: pos - 5 });
        }
        cells.resize(cells.len() + run, class);
    }
    if cells.len() != CELLS {
        return Err(RleError::TooFewCells { cells: cells.len() });
    }
    if pos != bytes.len() {
        return Err(RleError::TrailingBytes {
            extra: bytes.len() - pos,
            at: pos - 4,
        });
    }
    Ok(cells)
}

/// Converts the bytes of a `.c64` file.
///
/// # Errors
/// [`TableError::Rle`] when the run-length stream is malformed ([`decode_rle`]).
pub fn convert(bytes: &[u8]) -> Result<Converted, TableError> {
    let grid = SourceGrid {
        bits: [6, 6, 6],
        axes: [Channel::Y, Channel::U, Channel::V],
        cells: decode_rle(bytes)?,
    };
    build(SourceFormat::BhumanC64, &grid, &class_of)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    fn rle(runs: &[(i32, u8)]) -> Vec<u8> {
        let mut out = Vec::new();
        for &(n, c) in runs {
            out.extend_from_slice(&n.to_le_bytes());
            out.push(c);
        }
        out.extend_from_slice(&0i32.to_le_bytes());
        out
    }

    #[test]
    fn runs_expand_and_map() {
        let i = (30 << 12) | (10 << 6) | 50;
        let bytes = rle(&[(i, 0), (1, 1), (1, MULTI | 0b11), (CELLS as i32 - i - 2, 5)]);
        let c = convert(&bytes).unwrap();
        assert_eq!(c.table.bits(), 6);
        assert_eq!(
            c.table.class_of(Yuv::new(120, 40, 200)),
            ColourClass::Orange
        );
        assert_eq!(
            c.table.class_of(Yuv::new(120, 40, 204)),
            ColourClass::YellowOrange
        );
        assert_eq!(c.table.class_counts()[5], CELLS - i as usize - 2);
        assert!(c.source_classes.iter().any(|s| s.name == "orange+yellow"));
    }

    #[test]
    fn malformed_streams_say_what_is_wrong() {
        let short = decode_rle(&rle(&[(10, 1)])).unwrap_err();
        assert_eq!(short, RleError::TooFewCells { cells: 10 });
        assert!(short.to_string().contains("fill 10 cells"), "{short}");
        assert_eq!(
            decode_rle(&rle(&[(CELLS as i32 + 1, 1)])).unwrap_err(),
            RleError::TooManyCells { at: 0 }
        );
        let negative = decode_rle(&rle(&[(-3, 1)])).unwrap_err();
        assert_eq!(negative, RleError::NegativeRun { run: -3, at: 0 });
        assert!(negative.to_string().contains("negative"), "{negative}");
        let full = rle(&[(CELLS as i32, 1)]);
        assert_eq!(
            decode_rle(&full[..7]).unwrap_err(),
            RleError::NoRunLength { at: 5 }
        );
        assert_eq!(
            decode_rle(&full[..4]).unwrap_err(),
            RleError::NoClassByte { at: 4 }
        );
        let mut extra = full.clone();
        extra.push(9);
        let trailing = decode_rle(&extra).unwrap_err();
        assert_eq!(trailing, RleError::TrailingBytes { extra: 1, at: 5 });
        assert!(trailing.to_string().contains("after the end"), "{trailing}");
        assert_eq!(decode_rle(&full).unwrap().len(), CELLS);
    }

    #[test]
    fn multi_class_cells_prefer_soft_pairs() {
        assert_eq!(
            class_of(MULTI | 0b100_0001).unwrap().1,
            ColourClass::RedOrange
        );
        assert_eq!(
            class_of(MULTI | 0b1_0010).unwrap().1,
            ColourClass::ShadowYellow
        );
        assert_eq!(class_of(MULTI | 0b1_1000).unwrap().1, ColourClass::White);
        assert_eq!(class_of(MULTI), None);
        assert_eq!(class_of(9), None);
    }
}
