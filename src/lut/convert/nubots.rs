//! NUbots 2013 (Nao, DARwIn-OP) `.lut` tables — our own lineage.
//!
//! 128³ bytes indexed `(y>>1)<<14 | (cb>>1)<<7 | (cr>>1)`: already `FORMATS.md`'s layout at 7
//! bits, so only the values change. Checked on `nubots2013-lab-NUbot2.lut`: orange cells at low
//! Cb / high Cr (centroid 25, 211), blue at high Cb / low Cr (186, 64), green low on both.
//!
//! Mapping (`MAPPING`): "shadow object" (dark, shadowed parts of objects) becomes black; NUbots'
//! single blue (goals before 2012, team markers after) becomes sky blue, and its shadow blue our
//! shadow blue (sky or dark blue); the soft oranges map one to one.

use super::{Channel, Converted, SourceFormat, SourceGrid, TableError, build, lookup};
use crate::lut::ColourClass;

/// NUbots value → name → our class.
pub const MAPPING: &[(u8, &str, ColourClass)] = &[
    (0, "unclassified", ColourClass::Unclassified),
    (1, "white", ColourClass::White),
    (2, "green", ColourClass::Green),
    (3, "shadow object", ColourClass::Black),
    (4, "pink", ColourClass::Pink),
    (5, "pink-orange", ColourClass::PinkOrange),
    (6, "orange", ColourClass::Orange),
    (7, "yellow-orange", ColourClass::YellowOrange),
    (8, "yellow", ColourClass::Yellow),
    (9, "blue", ColourClass::SkyBlue),
    (10, "shadow blue", ColourClass::ShadowBlue),
];

/// The name and class of a NUbots value.
#[must_use]
pub fn class_of(value: u8) -> Option<(String, ColourClass)> {
    lookup(MAPPING, value)
}

/// Converts the bytes of a NUbots `.lut`.
///
/// # Errors
/// [`TableError::WrongLength`] when the size is not 128³ bytes.
pub fn convert(bytes: &[u8]) -> Result<Converted, TableError> {
    if bytes.len() != 1 << 21 {
        return Err(TableError::WrongLength {
            len: bytes.len(),
            table: "NUbots 2013 .lut",
            expected: "2,097,152 (128³)",
        });
    }
    let grid = SourceGrid {
        bits: [7, 7, 7],
        axes: [Channel::Y, Channel::U, Channel::V],
        cells: bytes.to_vec(),
    };
    build(SourceFormat::NubotsLut, &grid, &class_of)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    #[test]
    fn layout_is_ours_and_values_map() {
        let mut bytes = vec![0u8; 1 << 21];
        bytes[(60 << 14) | (20 << 7) | 100] = 6;
        bytes[(60 << 14) | (20 << 7) | 101] = 10;
        let c = convert(&bytes).unwrap();
        assert_eq!(
            c.table.class_of(Yuv::new(120, 40, 200)),
            ColourClass::Orange
        );
        assert_eq!(
            c.table.class_of(Yuv::new(120, 40, 202)),
            ColourClass::ShadowBlue
        );
        assert_eq!(c.table.class_counts()[0], (1 << 21) - 2);
        assert!(convert(&[0; 3]).is_err());
    }
}
