//! ssl-vision (Small Size League) colour tables: the XML settings file with a base64 blob.
//!
//! `<Var name="LUT Data" type="blob">` holds base64 whose first 65,536 bytes are a 4/6/6-bit
//! table (16 Y slabs × 64 × 64). The README (from the loader) reads the index as
//! `(y>>4)<<12 | (u>>2)<<6 | (v>>2)`, but the real 2024 table says the middle axis is Cr: its
//! orange cells sit at middle 220 / minor 100, yellow at 163 / 60, blue at 76 / 178 — read as
//! (Cb, Cr) that would make orange blue-violet and yellow cyan, read as (Cr, Cb) every class
//! lands where its colour is (orange low Cb high Cr, yellow lowest Cb, blue high Cb, field green
//! below 128 Cr). So the grid is read `[y][v][u]`; a whole-file test checks it.
//!
//! Output: 6 bits per channel, each Y slab repeated over 4 output Y cells (exact). Mapping
//! (`MAPPING`): the blue team marker is a uniform (dark blue), cyan the light blue (sky blue); the
//! field green and the green id-marker dots both become green, as ours has one green.

use base64::Engine;

use thiserror::Error;

use super::{Channel, Converted, SourceFormat, SourceGrid, TableError, build, lookup};
use crate::lut::ColourClass;

/// ssl-vision channel → name → our class.
pub const MAPPING: &[(u8, &str, ColourClass)] = &[
    (0, "clear", ColourClass::Unclassified),
    (1, "field green", ColourClass::Green),
    (2, "orange", ColourClass::Orange),
    (3, "yellow", ColourClass::Yellow),
    (4, "blue", ColourClass::DarkBlue),
    (5, "pink", ColourClass::Pink),
    (6, "cyan", ColourClass::SkyBlue),
    (7, "green", ColourClass::Green),
    (8, "white", ColourClass::White),
    (9, "black", ColourClass::Black),
];

/// Bytes of the table at the start of the blob (4 + 6 + 6 bits).
pub const TABLE_BYTES: usize = 1 << 16;

/// The name and class of an ssl-vision channel.
#[must_use]
pub fn class_of(value: u8) -> Option<(String, ColourClass)> {
    lookup(MAPPING, value)
}

/// What is wrong with an ssl-vision settings file as a table.
#[derive(Debug, Error)]
pub enum SslError {
    /// The file is not UTF-8.
    #[error("not UTF-8 text: {0}")]
    NotText(#[from] std::str::Utf8Error),
    /// No `LUT Data` variable.
    #[error("no <Var name=\"LUT Data\"> element")]
    NoLutData,
    /// The variable's opening tag does not end.
    #[error("the LUT Data element is not closed")]
    UnclosedElement,
    /// The variable does not end.
    #[error("no </Var> after the LUT Data")]
    NoEndTag,
    /// The blob is not base64.
    #[error("LUT Data is not base64: {0}")]
    NotBase64(#[from] base64::DecodeError),
    /// The blob is shorter than a table.
    #[error("LUT Data holds {len} bytes; a 4/6/6-bit table needs {TABLE_BYTES}")]
    ShortBlob {
        /// Bytes decoded.
        len: usize,
    },
}

/// The decoded `LUT Data` blob of an ssl-vision settings file.
///
/// # Errors
/// [`SslError`] when the variable is missing, unterminated or not base64.
pub fn lut_blob(text: &str) -> Result<Vec<u8>, SslError> {
    let start = text.find(r#"name="LUT Data""#).ok_or(SslError::NoLutData)?;
    let open = text[start..]
        .find('>')
        .map(|i| start + i + 1)
        .ok_or(SslError::UnclosedElement)?;
    let close = text[open..]
        .find("</Var>")
        .map(|i| open + i)
        .ok_or(SslError::NoEndTag)?;
    let b64: String = text[open..close]
        .chars()
        .filter(|c| !c.is_ascii_whitespace())
        .collect();
    Ok(base64::engine::general_purpose::STANDARD.decode(b64)?)
}

/// Converts the bytes of an ssl-vision XML settings file.
///
/// # Errors
/// [`TableError::Ssl`] when the file is not UTF-8, has no LUT blob, or the blob is too short.
pub fn convert(bytes: &[u8]) -> Result<Converted, TableError> {
    let text = std::str::from_utf8(bytes).map_err(SslError::from)?;
    let blob = lut_blob(text)?;
    if blob.len() < TABLE_BYTES {
        return Err(SslError::ShortBlob { len: blob.len() }.into());
    }
    let rest_used = blob[TABLE_BYTES..].iter().filter(|&&b| b != 0).count();
    let grid = SourceGrid {
        bits: [4, 6, 6],
        axes: [Channel::Y, Channel::V, Channel::U],
        cells: blob[..TABLE_BYTES].to_vec(),
    };
    let mut converted = build(SourceFormat::SslXml, &grid, &class_of)?;
    if blob.len() > TABLE_BYTES {
        converted.notes.push(format!(
            "LUT Data holds {} bytes; the first {TABLE_BYTES} are the table, the other {} \
             ({rest_used} non-zero) are ignored",
            blob.len(),
            blob.len() - TABLE_BYTES
        ));
    }
    Ok(converted)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    fn xml(table: &[u8]) -> Vec<u8> {
        let b64 = base64::engine::general_purpose::STANDARD.encode(table);
        format!(
            "\u{feff}<?xml version=\"1.0\"?>\n<VarXML>\n\t<Var name=\"LUT Data\" type=\"blob\">\n{b64}\n\t</Var>\n</VarXML>\n"
        )
        .into_bytes()
    }

    #[test]
    fn blob_decodes_and_axes_are_y_v_u() {
        let mut t = vec![0u8; TABLE_BYTES];
        // Y slab 8 (128..143), middle axis (V) 55 (220..223), minor (U) 25 (100..103): orange.
        t[(8 << 12) | (55 << 6) | 25] = 2;
        let c = convert(&xml(&t)).unwrap();
        assert_eq!(c.table.bits(), 6);
        for y in [128, 135, 143] {
            assert_eq!(c.table.class_of(Yuv::new(y, 101, 221)), ColourClass::Orange);
        }
        assert_eq!(
            c.table.class_of(Yuv::new(144, 101, 221)),
            ColourClass::Unclassified
        );
        assert_eq!(
            c.table.class_of(Yuv::new(130, 221, 101)),
            ColourClass::Unclassified
        );
        assert_eq!(c.table.class_counts()[1], 4);
    }

    #[test]
    fn missing_or_short_blobs_are_errors() {
        let none = convert(b"<VarXML></VarXML>").unwrap_err();
        assert!(
            matches!(none, TableError::Ssl(SslError::NoLutData)),
            "{none}"
        );
        assert!(none.to_string().contains("LUT Data"), "{none}");
        let short = convert(&xml(&[0; 100])).unwrap_err();
        assert!(
            matches!(short, TableError::Ssl(SslError::ShortBlob { len: 100 })),
            "{short}"
        );
        assert!(short.to_string().contains("100 bytes"), "{short}");
        let bad = b"<Var name=\"LUT Data\" type=\"blob\">@@@@</Var>";
        let bad = convert(bad).unwrap_err();
        assert!(
            matches!(bad, TableError::Ssl(SslError::NotBase64(_))),
            "{bad}"
        );
        assert!(bad.to_string().contains("base64"), "{bad}");
        let unclosed = convert(b"<Var name=\"LUT Data\"").unwrap_err();
        assert!(
            matches!(unclosed, TableError::Ssl(SslError::UnclosedElement)),
            "{unclosed}"
        );
    }
}
