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

use super::{Channel, Converted, SourceFormat, SourceGrid, build};
use crate::lut::ColourClass;

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
/// A message naming the line that has no index or no quoted name, or repeats an index.
pub fn parse_col(text: &str) -> Result<Vec<ColEntry>, String> {
    let mut out: Vec<ColEntry> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |what: &str| format!("line {}: {what}: '{line}'", n + 1);
        let index: u8 = line
            .split_whitespace()
            .next()
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| bad("no colour index (0..=255) first"))?;
        let mut quoted = line.split('"');
        let name = match (quoted.next(), quoted.next()) {
            (Some(_), Some(name)) if line.matches('"').count() >= 2 => name.to_owned(),
            _ => return Err(bad("no quoted colour name")),
        };
        if out.iter().any(|e| e.index == index) {
            return Err(bad("index given twice"));
        }
        out.push(ColEntry {
            index,
            class: class_for_name(&name),
            name,
        });
    }
    if out.is_empty() {
        return Err("no colours in the .col file".into());
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
fn parse_header(bytes: &[u8]) -> Result<([u8; 3], usize), String> {
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
        return Err("no complete three-line header (TMAP, colour space, sizes)".into());
    }
    if lines[0] != "TMAP" {
        return Err(format!("header starts '{}', not TMAP", lines[0]));
    }
    if !lines[1].starts_with("YUV") {
        return Err(format!("colour space '{}' is not YUV", lines[1]));
    }
    let sizes: Vec<u32> = lines[2]
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| format!("sizes line '{}' is not three numbers", lines[2]))?;
    let [y, u, v] = sizes[..] else {
        return Err(format!("sizes line '{}' is not three numbers", lines[2]));
    };
    let bits = |s: u32| {
        (s.is_power_of_two() && (2..=256).contains(&s))
            .then(|| u8::try_from(s.trailing_zeros()).unwrap_or(8))
            .ok_or_else(|| format!("axis size {s} is not a power of two from 2 to 256"))
    };
    Ok(([bits(y)?, bits(u)?, bits(v)?], start))
}

/// Converts a `.tm` file's bytes with the classes of its `.col` file.
///
/// # Errors
/// A message for a bad header or too few cells.
pub fn convert(bytes: &[u8], col: &[ColEntry]) -> Result<Converted, String> {
    let (bits, offset) = parse_header(bytes)?;
    let need = 1usize << bits.iter().map(|&b| u32::from(b)).sum::<u32>();
    let data = &bytes[offset..];
    if data.len() < need {
        return Err(format!(
            "{} bytes of cells after the header; {}×{}×{} needs {need}",
            data.len(),
            1u32 << bits[0],
            1u32 << bits[1],
            1u32 << bits[2]
        ));
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
        assert!(
            convert(b"TMAP\nYUV'8\n16 64 64\n\0\0", &col)
                .unwrap_err()
                .contains("needs 65536")
        );
        assert!(
            convert(b"TMAX\nYUV'8\n16 64 64\n", &col)
                .unwrap_err()
                .contains("TMAP")
        );
        assert!(
            convert(b"TMAP\nYUV'8\n16 60 64\n", &col)
                .unwrap_err()
                .contains("power of two")
        );
        assert!(convert(b"TMAP\nYUV", &col).unwrap_err().contains("header"));
        assert!(parse_col("x (1 2 3) \"a\"").unwrap_err().contains("line 1"));
        assert!(parse_col("1 (1 2 3) a").unwrap_err().contains("quoted"));
        assert!(parse_col("# nothing\n").is_err());
    }
}
