//! rUNSWift 2005 (AIBO ERS-7) `.cal` tables — the original EOTN's own era and league.
//!
//! 128³ bytes, one per cell of 7 bits per channel. The loader indexes `[y/2][u/2][v/2]`, but the
//! AIBO's image bands come as Y, Cr, Cb, and the real table says so: in
//! `runswift2005-nnmc.cal` the ball-orange cells sit at a high *middle* axis (centroid 182) and a
//! low minor axis (80), beacon blue the other way round (122, 168), field green low on both
//! (104, 98). Orange is low Cb / high Cr, so the middle axis is Cr (our V) and the minor axis Cb
//! (our U): the grid is read as `[y][v][u]`.
//!
//! Values and their mapping (`MAPPING`): robot grey becomes black (the dark parts of the ERS-7);
//! beacon green (unused in 2005) becomes green; 127 is "none". Bit `0x10` marks a "maybe" cell of
//! the class in the low bits; it maps to that class's own mapping (the team's classifier treated
//! "maybe" as a weaker vote for the same colour, and our basic classes have no weaker form).
//! The real file holds no maybe cells.

use super::{Channel, Converted, SourceFormat, SourceGrid, TableError, build, lookup};
use crate::lut::ColourClass;

/// rUNSWift's "no colour" value.
pub const NONE: u8 = 127;

/// The "maybe" bit.
pub const MAYBE: u8 = 0x10;

/// rUNSWift value → name → our class.
pub const MAPPING: &[(u8, &str, ColourClass)] = &[
    (0, "ball orange", ColourClass::Orange),
    (1, "beacon blue", ColourClass::SkyBlue),
    (2, "beacon green", ColourClass::Green),
    (3, "beacon yellow", ColourClass::Yellow),
    (4, "beacon pink", ColourClass::Pink),
    (5, "robot blue", ColourClass::DarkBlue),
    (6, "robot red", ColourClass::Red),
    (7, "field green", ColourClass::Green),
    (8, "robot grey", ColourClass::Black),
    (9, "white", ColourClass::White),
    (10, "black", ColourClass::Black),
    (NONE, "none", ColourClass::Unclassified),
];

/// The name and class of a rUNSWift value, "maybe" cells included.
#[must_use]
pub fn class_of(value: u8) -> Option<(String, ColourClass)> {
    if value == NONE {
        return lookup(MAPPING, value);
    }
    if value & MAYBE != 0 {
        return lookup(MAPPING, value & !MAYBE)
            .map(|(name, class)| (format!("maybe {name}"), class));
    }
    lookup(MAPPING, value)
}

/// Converts the bytes of a `.cal` file.
///
/// # Errors
/// [`TableError::WrongLength`] when the size is not 128³ bytes.
pub fn convert(bytes: &[u8]) -> Result<Converted, TableError> {
    if bytes.len() != 1 << 21 {
        return Err(TableError::WrongLength {
            len: bytes.len(),
            table: "rUNSWift .cal",
            expected: "2,097,152 (128³)",
        });
    }
    let grid = SourceGrid {
        bits: [7, 7, 7],
        axes: [Channel::Y, Channel::V, Channel::U],
        cells: bytes.to_vec(),
    };
    build(SourceFormat::RunswiftCal, &grid, &class_of)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    #[test]
    fn axes_are_y_v_u_and_maybe_keeps_the_class() {
        let mut bytes = vec![NONE; 1 << 21];
        // Y 100, "u" (file middle axis) 200, "v" (file minor) 60 → our V 200, U 60.
        bytes[(50 << 14) | (100 << 7) | 30] = 0;
        bytes[(50 << 14) | (100 << 7) | 31] = MAYBE | 6;
        let c = convert(&bytes).unwrap();
        assert_eq!(c.table.bits(), 7);
        assert_eq!(
            c.table.class_of(Yuv::new(100, 60, 200)),
            ColourClass::Orange
        );
        assert_eq!(c.table.class_of(Yuv::new(100, 62, 200)), ColourClass::Red);
        assert_eq!(
            c.table.class_of(Yuv::new(100, 200, 60)),
            ColourClass::Unclassified
        );
        assert!(c.source_classes.iter().any(|s| s.name == "maybe robot red"));
        assert!(c.notes.is_empty(), "{:?}", c.notes);
        let e = convert(&[0; 10]).unwrap_err();
        assert!(matches!(e, TableError::WrongLength { len: 10, .. }), "{e}");
        assert!(e.to_string().contains("2,097,152"), "{e}");
    }
}
