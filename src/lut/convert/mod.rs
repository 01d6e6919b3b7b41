//! Other teams' colour tables, converted to ours (`FORMATS.md`).
//!
//! No tool in the field reads another team's table; this one does, so a team can start from a
//! table someone else made, compare tables, or classify a foreign log with the table recorded
//! beside it. One file per format, each with its class-mapping table documented in code:
//!
//! | format | file | source grid (bits Y/U/V, axis order) | output |
//! |---|---|---|---|
//! | [`SourceFormat::RunswiftCal`] | rUNSWift 2005 `.cal` | 7/7/7, `[y][v][u]` (AIBO band order; checked on data) | 7 bits, exact |
//! | [`SourceFormat::NubotsLut`] | NUbots 2013 `.lut` | 7/7/7, `[y][u][v]` | 7 bits, exact |
//! | [`SourceFormat::BhumanC64`] | B-Human `.c64` (run-length) | 6/6/6, `[y][u][v]` | 6 bits, exact |
//! | [`SourceFormat::UpennRaw`] | UPennalizers `.raw` (bitmasks) | 6/6/6, `[y][u][v]` | 6 bits, exact |
//! | [`SourceFormat::SslXml`] | ssl-vision XML (base64) | 4/6/6, `[y][v][u]` (checked on data) | 6 bits, exact |
//! | [`SourceFormat::TekkotsuTm`] | Tekkotsu `.tm` + `.col` | from its header, 4/6/6, `[y][u][v]` | 6 bits, exact |
//!
//! **Resolution.** The output has the smallest of 6, 7 or 8 bits per channel that holds the
//! source grid exactly: each output cell takes the source cell it lies in. For the 4/6/6 grids
//! (ssl-vision, Tekkotsu) that is 6 bits, each source Y slab repeated over 4 output Y cells —
//! nothing is interpolated and nothing is lost (converting back would give the source grid).
//!
//! **Classes.** Each format maps its own values to `FORMATS.md` codes; "maybe" and multi-class
//! (bitmask) cells become the soft class of the pair when one exists, else the most likely basic
//! class; the choices are in each module's `MAPPING` table and doc comment. A value a format
//! does not define is left unclassified with a note, never an error, so a table with a few
//! stray cells still converts.

pub mod bhuman;
pub mod nubots;
pub mod runswift;
pub mod ssl;
pub mod tekkotsu;
pub mod upenn;

use std::path::{Path, PathBuf};

use serde::Serialize;
use thiserror::Error;

use super::{ColourClass, LookupTable};

/// The foreign table formats `eotn lut convert` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum SourceFormat {
    /// rUNSWift 2005 (AIBO ERS-7) `.cal`: 128³ bytes.
    RunswiftCal,
    /// NUbots 2013 `.lut`: 128³ bytes.
    NubotsLut,
    /// B-Human `.c64`: run-length encoded 64³ table.
    BhumanC64,
    /// UPennalizers `.raw`: 64³ bytes of class bitmasks.
    UpennRaw,
    /// ssl-vision XML settings with a base64 `LUT Data` blob (4/6/6 bits).
    SslXml,
    /// Tekkotsu / CMVision `.tm` threshold map, with a `.col` file naming its classes.
    TekkotsuTm,
}

impl SourceFormat {
    /// Every format, in the order of the command-line option.
    pub const ALL: [Self; 6] = [
        Self::RunswiftCal,
        Self::NubotsLut,
        Self::BhumanC64,
        Self::UpennRaw,
        Self::SslXml,
        Self::TekkotsuTm,
    ];

    /// The name used on the command line (`--format runswift-cal`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::RunswiftCal => "runswift-cal",
            Self::NubotsLut => "nubots-lut",
            Self::BhumanC64 => "bhuman-c64",
            Self::UpennRaw => "upenn-raw",
            Self::SslXml => "ssl-xml",
            Self::TekkotsuTm => "tekkotsu-tm",
        }
    }

    /// The format of a command-line name.
    #[must_use]
    pub fn parse(text: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == text.trim())
    }

    /// Guesses the format from the file name and contents: `TMAP` header → Tekkotsu, XML →
    /// ssl-vision, `.c64` (or a well-formed run-length stream) → B-Human, then by extension and
    /// size (`.cal` / 128³ with rUNSWift's 127 "none" → rUNSWift, `.lut` / 128³ → NUbots,
    /// `.raw` / 64³ → UPennalizers).
    #[must_use]
    pub fn detect(path: &Path, bytes: &[u8]) -> Option<Self> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if bytes.starts_with(b"TMAP") {
            return Some(Self::TekkotsuTm);
        }
        let head = &bytes[..bytes.len().min(512)];
        let head = String::from_utf8_lossy(head);
        if head
            .trim_start_matches('\u{feff}')
            .trim_start()
            .starts_with('<')
        {
            return Some(Self::SslXml);
        }
        match (ext.as_str(), bytes.len()) {
            ("c64", _) => Some(Self::BhumanC64),
            ("cal", 2_097_152) => Some(Self::RunswiftCal),
            ("lut", 2_097_152) => Some(Self::NubotsLut),
            ("raw", 262_144) => Some(Self::UpennRaw),
            (_, 2_097_152) => Some(if bytes.contains(&runswift::NONE) {
                Self::RunswiftCal
            } else {
                Self::NubotsLut
            }),
            (_, 262_144) => Some(Self::UpennRaw),
            _ => bhuman::decode_rle(bytes).is_ok().then_some(Self::BhumanC64),
        }
    }
}

impl std::fmt::Display for SourceFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a foreign table could not be converted; always names the file.
#[derive(Debug, Error)]
pub enum ConvertError {
    /// Reading the table (or its `.col` file) failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The format could not be told from the name and contents.
    #[error("{path}: cannot tell which team's format this is ({len} bytes); give it with --format")]
    Unknown {
        /// The file.
        path: PathBuf,
        /// Its length, bytes.
        len: usize,
    },
    /// The contents do not follow the format.
    #[error("{path}: not a valid {format} table: {problem}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The format it was read as.
        format: SourceFormat,
        /// What is wrong.
        #[source]
        problem: TableError,
    },
}

/// What is wrong with a foreign table's contents (the file is named by [`ConvertError`]).
#[derive(Debug, Error)]
pub enum TableError {
    /// A fixed-size format of the wrong length.
    #[error("{len} bytes; a {table} is {expected}")]
    WrongLength {
        /// Bytes read.
        len: usize,
        /// The kind of file ("NUbots 2013 .lut").
        table: &'static str,
        /// Its length in words ("2,097,152 (128³)").
        expected: &'static str,
    },
    /// A grid whose cell count does not match its bits per axis.
    #[error(
        "{cells} cells where a {}×{}×{} grid needs {want}",
        1u32 << .bits[0], 1u32 << .bits[1], 1u32 << .bits[2]
    )]
    GridCells {
        /// Cells held.
        cells: usize,
        /// Bits per file axis.
        bits: [u8; 3],
        /// Cells the bits need.
        want: usize,
    },
    /// An axis with fewer than 1 or more than 8 bits.
    #[error("{bits:?} bits per axis; each must be 1..=8")]
    GridBits {
        /// Bits per file axis.
        bits: [u8; 3],
    },
    /// Our table could not be made from the converted cells.
    #[error(transparent)]
    Table(#[from] super::LutError),
    /// B-Human's run-length stream is malformed.
    #[error(transparent)]
    Rle(#[from] bhuman::RleError),
    /// The ssl-vision settings hold no usable `LUT Data`.
    #[error(transparent)]
    Ssl(#[from] ssl::SslError),
    /// The Tekkotsu `.tm` is malformed.
    #[error(transparent)]
    Threshold(#[from] tekkotsu::ThresholdMapError),
    /// The Tekkotsu `.col` file is malformed.
    #[error(transparent)]
    Colours(#[from] tekkotsu::ColError),
    /// A Tekkotsu `.tm` with no `.col` file to name its classes.
    #[error("no .col file names its classes: give one with --col FILE.col")]
    NoColFile,
    /// A Tekkotsu `.tm` given as bytes alone, without its `.col`.
    #[error("a Tekkotsu .tm needs its .col file (use convert_file or tekkotsu::convert)")]
    NeedsColFile,
}

/// One of the source's values, what it was called there, the class it became, and how many
/// source cells (at the source's own resolution) held it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SourceClass {
    /// The raw value in the source table.
    pub value: u8,
    /// The source's name for it ("ball orange", "orange+yellow", "unsaturated").
    pub name: String,
    /// The `FORMATS.md` class it maps to.
    pub class: ColourClass,
    /// Source cells holding it.
    pub cells: usize,
}

/// A converted table and what the conversion did.
#[derive(Debug, Clone)]
pub struct Converted {
    /// The format read.
    pub format: SourceFormat,
    /// The table in our format.
    pub table: LookupTable,
    /// Bits per channel of the source grid (Y, U, V).
    pub source_bits: [u8; 3],
    /// Every value present in the source, in value order, with its mapping and cell count.
    pub source_classes: Vec<SourceClass>,
    /// Things the user should know: undefined values, resampling.
    pub notes: Vec<String>,
}

/// Which of our channels a source axis holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Channel {
    /// Luma.
    Y,
    /// Cb.
    U,
    /// Cr.
    V,
}

/// A source table on a regular grid, before class mapping: `cells` in the file's order, axis 0
/// major; `bits[k]` and `axes[k]` give each file axis's resolution and channel.
#[derive(Debug, Clone)]
pub(crate) struct SourceGrid {
    pub(crate) bits: [u8; 3],
    pub(crate) axes: [Channel; 3],
    pub(crate) cells: Vec<u8>,
}

impl SourceGrid {
    /// Checks the cell count against the bits.
    fn check(&self) -> Result<(), TableError> {
        let want = 1usize << self.bits.iter().map(|&b| u32::from(b)).sum::<u32>();
        if self.cells.len() == want {
            Ok(())
        } else {
            Err(TableError::GridCells {
                cells: self.cells.len(),
                bits: self.bits,
                want,
            })
        }
    }

    /// Bits per channel in our order (Y, U, V).
    fn channel_bits(&self) -> [u8; 3] {
        let mut out = [0; 3];
        for (k, ch) in self.axes.iter().enumerate() {
            out[*ch as usize] = self.bits[k];
        }
        out
    }
}

/// Maps a source grid to our table (`map` names and maps each raw value, `None` for values the
/// format does not define) at the smallest of 6/7/8 bits that holds it exactly.
pub(crate) fn build(
    format: SourceFormat,
    grid: &SourceGrid,
    map: &dyn Fn(u8) -> Option<(String, ColourClass)>,
) -> Result<Converted, TableError> {
    if grid.bits.iter().any(|&b| !(1..=8).contains(&b)) {
        return Err(TableError::GridBits { bits: grid.bits });
    }
    grid.check()?;
    let source_bits = grid.channel_bits();
    let out_bits = source_bits.iter().copied().max().unwrap_or(6).max(6);
    let mut counts = [0usize; 256];
    for &c in &grid.cells {
        counts[usize::from(c)] += 1;
    }
    let mut code_of = [0u8; 256];
    let mut source_classes = Vec::new();
    let mut notes = Vec::new();
    for value in 0..=255u8 {
        let cells = counts[usize::from(value)];
        if cells == 0 {
            continue;
        }
        if let Some((name, class)) = map(value) {
            code_of[usize::from(value)] = class.code();
            source_classes.push(SourceClass {
                value,
                name,
                class,
                cells,
            });
        } else {
            notes.push(format!(
                "{cells} cells hold {value}, which {format} does not define; left unclassified"
            ));
            source_classes.push(SourceClass {
                value,
                name: "undefined".into(),
                class: ColourClass::Unclassified,
                cells,
            });
        }
    }
    if source_bits != [out_bits; 3] {
        notes.push(format!(
            "source grid is {}/{}/{} bits (Y/U/V); written at {out_bits} bits per channel, each \
             source cell repeated over the output cells it covers (exact, nothing interpolated)",
            source_bits[0], source_bits[1], source_bits[2]
        ));
    }
    let mut table = LookupTable::new(out_bits)?;
    let n = table.side();
    // For each file axis, which output coordinate feeds it and by how much it shifts.
    let shift = grid.bits.map(|b| out_bits - b);
    let mut cells = vec![0u8; n * n * n];
    for y in 0..n {
        for u in 0..n {
            for v in 0..n {
                let ours = [y, u, v];
                let a = |k: usize| ours[grid.axes[k] as usize] >> shift[k];
                let src = (((a(0) << grid.bits[1]) | a(1)) << grid.bits[2]) | a(2);
                cells[(y * n + u) * n + v] = code_of[usize::from(grid.cells[src])];
            }
        }
    }
    table = LookupTable::from_bytes(cells)?;
    Ok(Converted {
        format,
        table,
        source_bits,
        source_classes,
        notes,
    })
}

/// Reads and converts a foreign table file.
///
/// `format` `None` detects it ([`SourceFormat::detect`]). `col` is Tekkotsu's class file; when
/// absent, a `.col` beside the `.tm` with the same stem, or else the only `.col` in its folder,
/// is used.
///
/// # Errors
/// [`ConvertError`] naming the file: unreadable, unknown format, or malformed contents.
pub fn convert_file(
    path: &Path,
    format: Option<SourceFormat>,
    col: Option<&Path>,
) -> Result<Converted, ConvertError> {
    let bytes =
        crate::input_file::read_bounded(path, 256 << 20, "a colour table").map_err(|source| {
            ConvertError::Io {
                path: path.to_owned(),
                source,
            }
        })?;
    let format = match format {
        Some(f) => f,
        None => SourceFormat::detect(path, &bytes).ok_or(ConvertError::Unknown {
            path: path.to_owned(),
            len: bytes.len(),
        })?,
    };
    let invalid = |problem: TableError| ConvertError::Invalid {
        path: path.to_owned(),
        format,
        problem,
    };
    match format {
        SourceFormat::TekkotsuTm => {
            let col_path = match col {
                Some(c) => c.to_owned(),
                None => tekkotsu::find_col(path).ok_or_else(|| invalid(TableError::NoColFile))?,
            };
            let col_text = crate::input_file::read_text_bounded(
                &col_path,
                crate::input_file::MAX_SIDE_FILE_BYTES,
                "a colour file",
            )
            .map_err(|source| ConvertError::Io {
                path: col_path.clone(),
                source,
            })?;
            let classes =
                tekkotsu::parse_col(&col_text).map_err(|problem| ConvertError::Invalid {
                    path: col_path.clone(),
                    format,
                    problem: problem.into(),
                })?;
            tekkotsu::convert(&bytes, &classes).map_err(invalid)
        }
        _ => convert_bytes(format, &bytes).map_err(invalid),
    }
}

/// Converts the bytes of a table in any format but Tekkotsu's (which needs its `.col`; see
/// [`tekkotsu::convert`]).
///
/// # Errors
/// [`TableError`]: what is wrong with the contents.
pub fn convert_bytes(format: SourceFormat, bytes: &[u8]) -> Result<Converted, TableError> {
    match format {
        SourceFormat::RunswiftCal => runswift::convert(bytes),
        SourceFormat::NubotsLut => nubots::convert(bytes),
        SourceFormat::BhumanC64 => bhuman::convert(bytes),
        SourceFormat::UpennRaw => upenn::convert(bytes),
        SourceFormat::SslXml => ssl::convert(bytes),
        SourceFormat::TekkotsuTm => Err(TableError::NeedsColFile),
    }
}

/// Looks a value up in a fixed mapping table.
pub(crate) fn lookup(
    table: &[(u8, &'static str, ColourClass)],
    value: u8,
) -> Option<(String, ColourClass)> {
    table
        .iter()
        .find(|(v, _, _)| *v == value)
        .map(|(_, name, class)| ((*name).to_owned(), *class))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn build_repeats_coarse_axes_and_swaps_channels() {
        // A 2/1/1-bit grid stored [y][v][u]: 2 × 2 × 2... with Y 2 bits → 4×2×2 = 16 cells.
        let mut cells = vec![0u8; 16];
        // y slab 3, v half 1, u half 0 → index (3 << 2) | (1 << 1) | 0 = 14.
        cells[14] = 1;
        let grid = SourceGrid {
            bits: [2, 1, 1],
            axes: [Channel::Y, Channel::V, Channel::U],
            cells,
        };
        let c = build(SourceFormat::SslXml, &grid, &|v| {
            Some((v.to_string(), ColourClass::from_code(v)?))
        })
        .unwrap();
        assert_eq!(c.table.bits(), 6);
        assert_eq!(c.source_bits, [2, 1, 1]);
        let t = &c.table;
        // High Y, low U, high V is orange; low V is not; low Y is not.
        assert_eq!(t.classify(crate::frame::Yuv::new(255, 10, 200)), 1);
        assert_eq!(t.classify(crate::frame::Yuv::new(192, 127, 128)), 1);
        assert_eq!(t.classify(crate::frame::Yuv::new(255, 200, 10)), 0);
        assert_eq!(t.classify(crate::frame::Yuv::new(191, 10, 200)), 0);
        // One source cell of 16 → 1/16 of the output.
        assert_eq!(t.class_counts()[1], (1 << 18) / 16);
        assert_eq!(c.source_classes.len(), 2);
        assert!(c.notes.iter().any(|n| n.contains("2/1/1")), "{:?}", c.notes);
    }

    #[test]
    fn undefined_values_are_noted_not_fatal() {
        let grid = SourceGrid {
            bits: [6, 6, 6],
            axes: [Channel::Y, Channel::U, Channel::V],
            cells: {
                let mut c = vec![0u8; 1 << 18];
                c[5] = 200;
                c
            },
        };
        let c = build(SourceFormat::NubotsLut, &grid, &|v| {
            (v == 0).then(|| ("none".to_owned(), ColourClass::Unclassified))
        })
        .unwrap();
        assert_eq!(c.table.class_counts()[0], 1 << 18);
        assert!(c.notes[0].contains("200"), "{:?}", c.notes);
    }

    #[test]
    fn wrong_cell_count_is_an_error() {
        let grid = SourceGrid {
            bits: [6, 6, 6],
            axes: [Channel::Y, Channel::U, Channel::V],
            cells: vec![0; 1000],
        };
        let e = build(SourceFormat::UpennRaw, &grid, &|_| None).unwrap_err();
        assert!(
            matches!(
                e,
                TableError::GridCells {
                    cells: 1000,
                    want: 262_144,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("64×64×64"), "{e}");
    }

    #[test]
    fn detect_by_header_extension_and_size() {
        let p = |s: &str| PathBuf::from(s);
        assert_eq!(
            SourceFormat::detect(&p("x.tm"), b"TMAP\nYUV'8\n"),
            Some(SourceFormat::TekkotsuTm)
        );
        assert_eq!(
            SourceFormat::detect(&p("x"), "\u{feff}<?xml".as_bytes()),
            Some(SourceFormat::SslXml)
        );
        assert_eq!(
            SourceFormat::detect(&p("a.lut"), &vec![0; 2_097_152]),
            Some(SourceFormat::NubotsLut)
        );
        assert_eq!(
            SourceFormat::detect(&p("a.bin"), &{
                let mut v = vec![0; 2_097_152];
                v[9] = 127;
                v
            }),
            Some(SourceFormat::RunswiftCal)
        );
        assert_eq!(SourceFormat::detect(&p("a.bin"), &[1, 2, 3]), None);
        for f in SourceFormat::ALL {
            assert_eq!(SourceFormat::parse(f.name()), Some(f));
        }
    }
}
