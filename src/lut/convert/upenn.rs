//! UPennalizers (Nao) `.raw` colour tables: 64³ bytes of class bitmasks.
//!
//! Indexed `(y>>2)<<12 | (u>>2)<<6 | (v>>2)` (our layout at 6 bits). Each cell is a bitmask of
//! UPenn's colours (`Config_NaoV4_Vision.lua`): 1 ball, 2 yellow, 4 robot blue (cyan in older
//! configs), 8 field, 16 white, 32 robot pink.
//!
//! **Bit 1 is decided by the data.** It was orange while the ball was orange; in 2016 the SPL
//! ball became black and white, and in the real 2016 table (`upenn2016-Germany2016_10am_Top.raw`)
//! the bit-1 cells are dark and colourless (Y 36–148, Cb 112–152, Cr 96–140, centroid 81/132/122:
//! the chroma of the table's own white), not orange (orange has Cr far above 128). So bit 1 maps
//! to orange when its cells' mean Cr is above 150, else to black, and the conversion says which.
//! The axis order is confirmed by the same file: field cells have Cr below 128 (centroid Cb 139,
//! Cr 88; read the other way round the carpet would be magenta), and white, field and the bit-1
//! cells share one colour cast (Cr 10–40 below Cb).
//!
//! Cells with several bits: ball+yellow → yellow-orange (when the ball is orange), yellow+field →
//! shadow yellow, otherwise the lowest bit set (UPenn's own order, ball first).

use super::{Channel, Converted, SourceFormat, SourceGrid, TableError, build};
use crate::lut::ColourClass;

/// UPenn bit → name → our class (bit 1 is decided per table; see the module docs).
pub const MAPPING: &[(u8, &str, ColourClass)] = &[
    (1, "ball", ColourClass::Orange),
    (2, "yellow", ColourClass::Yellow),
    (4, "robot blue", ColourClass::DarkBlue),
    (8, "field", ColourClass::Green),
    (16, "white", ColourClass::White),
    (32, "robot pink", ColourClass::Pink),
];

/// The name and class of a UPenn bitmask, with the class bit 1 stands for in this table.
#[must_use]
pub fn class_of(value: u8, ball: ColourClass) -> Option<(String, ColourClass)> {
    if value == 0 {
        return Some(("none".into(), ColourClass::Unclassified));
    }
    let bits: Vec<(u8, &str, ColourClass)> = MAPPING
        .iter()
        .filter(|(bit, _, _)| value & bit != 0)
        .map(|&(bit, name, class)| (bit, name, if bit == 1 { ball } else { class }))
        .collect();
    let defined: u8 = MAPPING.iter().map(|(b, _, _)| b).sum();
    if value & !defined != 0 || bits.is_empty() {
        return None;
    }
    let name = bits
        .iter()
        .map(|(_, n, _)| *n)
        .collect::<Vec<_>>()
        .join("+");
    let class = match value {
        3 if ball == ColourClass::Orange => ColourClass::YellowOrange,
        10 => ColourClass::ShadowYellow,
        _ => bits[0].2,
    };
    Some((name, class))
}

/// What bit 1 means in these cells: orange when its cells' mean Cr is above 150, else black.
fn ball_class(cells: &[u8]) -> (ColourClass, Option<f64>) {
    let (mut sum, mut n) = (0u64, 0u64);
    for (i, &c) in cells.iter().enumerate() {
        if c & 1 != 0 {
            sum += ((i & 63) as u64) * 4 + 2;
            n += 1;
        }
    }
    if n == 0 {
        return (ColourClass::Orange, None);
    }
    let mean_cr = sum as f64 / n as f64;
    let class = if mean_cr > 150.0 {
        ColourClass::Orange
    } else {
        ColourClass::Black
    };
    (class, Some(mean_cr))
}

/// Converts the bytes of a `.raw` file.
///
/// # Errors
/// [`TableError::WrongLength`] when the size is not 64³ bytes.
pub fn convert(bytes: &[u8]) -> Result<Converted, TableError> {
    if bytes.len() != 1 << 18 {
        return Err(TableError::WrongLength {
            len: bytes.len(),
            table: "UPennalizers .raw",
            expected: "262,144 (64³)",
        });
    }
    let (ball, mean_cr) = ball_class(bytes);
    let grid = SourceGrid {
        bits: [6, 6, 6],
        axes: [Channel::Y, Channel::U, Channel::V],
        cells: bytes.to_vec(),
    };
    let mut converted = build(SourceFormat::UpennRaw, &grid, &|v| class_of(v, ball))?;
    if let Some(cr) = mean_cr {
        converted.notes.push(format!(
            "bit 1 (ball) cells have mean Cr {cr:.0}: read as {} ({})",
            ball.name(),
            if ball == ColourClass::Orange {
                "an orange ball"
            } else {
                "the black patches of the black-and-white ball used since 2016"
            }
        ));
    }
    Ok(converted)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    #[test]
    fn bit_one_follows_the_data_and_pairs_go_soft() {
        let at = |y: usize, u: usize, v: usize| (y << 12) | (u << 6) | v;
        let mut orange = vec![0u8; 1 << 18];
        orange[at(30, 10, 50)] = 1;
        orange[at(30, 10, 51)] = 3;
        orange[at(30, 10, 52)] = 10;
        let c = convert(&orange).unwrap();
        assert_eq!(
            c.table.class_of(Yuv::new(120, 40, 200)),
            ColourClass::Orange
        );
        assert_eq!(
            c.table.class_of(Yuv::new(120, 40, 204)),
            ColourClass::YellowOrange
        );
        assert_eq!(
            c.table.class_of(Yuv::new(120, 40, 208)),
            ColourClass::ShadowYellow
        );
        let mut black = vec![0u8; 1 << 18];
        black[at(20, 32, 32)] = 1;
        black[at(20, 32, 33)] = 64;
        let c = convert(&black).unwrap();
        assert_eq!(c.table.class_of(Yuv::new(80, 128, 128)), ColourClass::Black);
        assert!(
            c.notes
                .iter()
                .any(|n| n.contains("64") && n.contains("does not define"))
        );
        assert!(c.notes.iter().any(|n| n.contains("black")), "{:?}", c.notes);
    }
}
