//! The 3D YUV lookup table: the hand-made heart of colour classification.
//!
//! A table has N³ one-byte cells, N = 2^bits with 6, 7 or 8 bits per channel; a pixel's cell is
//! `((Y >> s) * N + (U >> s)) * N + (V >> s)` with `s = 8 − bits` (Y major, V minor), and the
//! cell holds a [`ColourClass`] code. The file format is the raw cells and nothing else
//! (`FORMATS.md`), so tables move freely between tools; loading infers `bits` from the size.
//!
//! Editing (selecting cells around a sample pixel, committing, undo/redo) is in [`edit`];
//! other teams' formats convert in [`convert`].

pub mod classes;
pub mod convert;
pub mod edit;
pub mod learn;

pub use classes::{CLASS_COUNT, ClassKind, ColourClass, code_display_rgb};
pub use edit::{AppliedEdit, CellBox, EditHistory, EditRecord, Region, SampleAt, Sensitivity};

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::frame::Yuv;

/// Why bytes are not a lookup table.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum LutError {
    /// The size is not 64³, 128³ or 256³ bytes.
    #[error(
        "{len} bytes is not a lookup-table size (262,144, 2,097,152 or 16,777,216 bytes for 6, 7 or 8 bits)"
    )]
    WrongSize {
        /// Bytes given.
        len: usize,
    },
    /// Bits per channel other than 6, 7 or 8.
    #[error("{bits} bits per channel is not supported (6, 7 or 8)")]
    BadBits {
        /// Bits asked for.
        bits: u8,
    },
    /// A cell holds a value that is no class of `FORMATS.md`.
    #[error(
        "cell {index} holds {code}, which is no colour class (0..=14); {count} cells in all hold undefined codes"
    )]
    UnknownCode {
        /// First offending cell.
        index: usize,
        /// Its value.
        code: u8,
        /// How many cells hold undefined codes.
        count: usize,
    },
}

/// A lookup-table file problem, naming the file.
#[derive(Debug, Error)]
pub enum LutFileError {
    /// Reading or writing failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The contents are not a table.
    #[error("{path}: {source}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: LutError,
    },
}

/// A 3D YUV → colour-class table.
#[derive(Clone, PartialEq, Eq)]
pub struct LookupTable {
    bits: u8,
    cells: Vec<u8>,
}

impl std::fmt::Debug for LookupTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LookupTable")
            .field("bits", &self.bits)
            .field("cells", &self.cells.len())
            .finish()
    }
}

/// Per-class cell counts, indexed by class code.
pub type ClassCounts = [usize; CLASS_COUNT];

impl LookupTable {
    /// An all-unclassified table with `bits` (6, 7 or 8) bits per channel.
    ///
    /// # Errors
    /// [`LutError::BadBits`] for other bit counts.
    pub fn new(bits: u8) -> Result<Self, LutError> {
        if !(6..=8).contains(&bits) {
            return Err(LutError::BadBits { bits });
        }
        Ok(Self {
            bits,
            cells: vec![0; 1 << (3 * u32::from(bits))],
        })
    }

    /// A table from raw cells, bits inferred from the length, every code checked.
    ///
    /// # Errors
    /// [`LutError::WrongSize`] or [`LutError::UnknownCode`].
    pub fn from_bytes(cells: Vec<u8>) -> Result<Self, LutError> {
        let bits = bits_for_len(cells.len()).ok_or(LutError::WrongSize { len: cells.len() })?;
        let bad = |&c: &u8| usize::from(c) >= CLASS_COUNT;
        if let Some(index) = cells.iter().position(bad) {
            return Err(LutError::UnknownCode {
                index,
                code: cells[index],
                count: cells.iter().filter(|c| bad(c)).count(),
            });
        }
        Ok(Self { bits, cells })
    }

    /// Reads a raw table file.
    ///
    /// # Errors
    /// [`LutFileError`] naming the file: unreadable, wrong size, or an unknown code.
    pub fn load(path: &Path) -> Result<Self, LutFileError> {
        // The largest table (8 bits per channel) is 16 MiB: anything larger is refused unread.
        let bytes =
            crate::input_file::read_bounded(path, 1 << 24, "a lookup table").map_err(|source| {
                LutFileError::Io {
                    path: path.to_owned(),
                    source,
                }
            })?;
        Self::from_bytes(bytes).map_err(|source| LutFileError::Invalid {
            path: path.to_owned(),
            source,
        })
    }

    /// Writes the raw table atomically (temporary file, fsync, rename): a crash or a full disk
    /// never leaves a half-written table.
    ///
    /// # Errors
    /// [`LutFileError::Io`] naming the file; the old file is then untouched.
    pub fn save(&self, path: &Path) -> Result<(), LutFileError> {
        crate::atomic_file::write_atomic(path, &self.cells).map_err(|source| LutFileError::Io {
            path: path.to_owned(),
            source,
        })
    }

    /// Bits per channel: 6, 7 or 8.
    #[must_use]
    pub const fn bits(&self) -> u8 {
        self.bits
    }

    /// Cells per channel, N = 2^bits.
    #[must_use]
    pub const fn side(&self) -> usize {
        1 << self.bits
    }

    /// How far an 8-bit channel value shifts right to give its cell coordinate: 8 − bits.
    #[must_use]
    pub const fn shift(&self) -> u8 {
        8 - self.bits
    }

    /// All N³ cells, Y major, V minor.
    #[must_use]
    pub fn cells(&self) -> &[u8] {
        &self.cells
    }

    /// The cell index of a pixel (`FORMATS.md`).
    ///
    /// ```
    /// use eotn::{frame::Yuv, lut::LookupTable};
    /// let t = LookupTable::new(7).unwrap();
    /// // ((200>>1)*128 + (10>>1))*128 + (255>>1)
    /// assert_eq!(t.index(Yuv::new(200, 10, 255)), (100 * 128 + 5) * 128 + 127);
    /// ```
    #[must_use]
    pub fn index(&self, p: Yuv) -> usize {
        let s = self.shift();
        self.index_of_cell([p.y >> s, p.u >> s, p.v >> s].map(usize::from))
    }

    /// The cell coordinates (Y, U, V), each 0..N, of a pixel.
    #[must_use]
    pub fn cell_of(&self, p: Yuv) -> [usize; 3] {
        let s = self.shift();
        [p.y >> s, p.u >> s, p.v >> s].map(usize::from)
    }

    /// The index of cell coordinates (each must be below N).
    #[must_use]
    pub fn index_of_cell(&self, [y, u, v]: [usize; 3]) -> usize {
        let n = self.side();
        (y * n + u) * n + v
    }

    /// The cell coordinates of an index.
    #[must_use]
    pub fn cell_of_index(&self, index: usize) -> [usize; 3] {
        let n = self.side();
        [index / (n * n), (index / n) % n, index % n]
    }

    /// The class code of a pixel.
    #[must_use]
    pub fn classify(&self, p: Yuv) -> u8 {
        self.cells[self.index(p)]
    }

    /// The class of a pixel.
    #[must_use]
    pub fn class_of(&self, p: Yuv) -> ColourClass {
        ColourClass::from_code(self.classify(p)).unwrap_or(ColourClass::Unclassified)
    }

    /// The code in a cell, or `None` past the end.
    #[must_use]
    pub fn get(&self, index: usize) -> Option<u8> {
        self.cells.get(index).copied()
    }

    /// Sets one cell; returns the previous code, or `None` (and changes nothing) past the end.
    pub fn set(&mut self, index: usize, class: ColourClass) -> Option<u8> {
        self.cells
            .get_mut(index)
            .map(|c| std::mem::replace(c, class.code()))
    }

    /// How many cells hold each class.
    #[must_use]
    pub fn class_counts(&self) -> ClassCounts {
        let mut raw = [0usize; 256];
        for &c in &self.cells {
            raw[usize::from(c)] += 1;
        }
        let mut counts = [0; CLASS_COUNT];
        counts.copy_from_slice(&raw[..CLASS_COUNT]);
        counts
    }

    /// This table at another resolution: each new cell takes the class at its centre in the old
    /// table (coarsening keeps the centre cell's class; refining copies).
    #[must_use]
    pub fn resampled(&self, bits: u8) -> Option<Self> {
        let mut out = Self::new(bits).ok()?;
        let n = out.side();
        let half = (1usize << (8 - bits)) / 2;
        for y in 0..n {
            for u in 0..n {
                for v in 0..n {
                    let centre =
                        |c: usize| u8::try_from((c << (8 - bits)) + half).unwrap_or(u8::MAX);
                    let code = self.classify(Yuv::new(centre(y), centre(u), centre(v)));
                    let i = out.index_of_cell([y, u, v]);
                    out.cells[i] = code;
                }
            }
        }
        Some(out)
    }
}

/// The bits per channel of a raw table of `len` bytes.
#[must_use]
pub fn bits_for_len(len: usize) -> Option<u8> {
    match len {
        262_144 => Some(6),
        2_097_152 => Some(7),
        16_777_216 => Some(8),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_follows_formats_md_for_every_bit_count() {
        for bits in [6u8, 7, 8] {
            let t = LookupTable::new(bits).unwrap();
            let n = 1usize << bits;
            let s = 8 - bits;
            let p = Yuv::new(201, 17, 254);
            let expect = ((usize::from(201u8 >> s) * n) + usize::from(17u8 >> s)) * n
                + usize::from(254u8 >> s);
            assert_eq!(t.index(p), expect);
            assert_eq!(t.cell_of_index(expect), t.cell_of(p));
            assert_eq!(t.cells().len(), n * n * n);
        }
    }

    #[test]
    fn wrong_size_and_unknown_codes_are_clear_errors() {
        assert_eq!(
            LookupTable::from_bytes(vec![0; 1000]),
            Err(LutError::WrongSize { len: 1000 })
        );
        let mut cells = vec![0u8; 1 << 18];
        cells[77] = 99;
        cells[78] = 15;
        assert_eq!(
            LookupTable::from_bytes(cells),
            Err(LutError::UnknownCode {
                index: 77,
                code: 99,
                count: 2
            })
        );
        assert_eq!(LookupTable::new(5), Err(LutError::BadBits { bits: 5 }));
    }

    #[test]
    fn load_errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("garbage.lut");
        std::fs::write(&p, [200u8; 1 << 18]).unwrap();
        let e = LookupTable::load(&p).unwrap_err().to_string();
        assert!(e.contains("garbage.lut") && e.contains("200"), "{e}");
        let e = LookupTable::load(&dir.path().join("missing.lut"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.lut"), "{e}");
    }

    #[test]
    fn save_and_load_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.lut");
        let mut t = LookupTable::new(6).unwrap();
        t.set(12_345, ColourClass::Orange);
        t.save(&p).unwrap();
        let back = LookupTable::load(&p).unwrap();
        assert_eq!(back, t);
        assert_eq!(back.class_counts()[1], 1);
        assert_eq!(back.class_counts()[0], (1 << 18) - 1);
    }

    #[test]
    fn resampling_keeps_classes() {
        let mut t = LookupTable::new(8).unwrap();
        // Mark a whole 4×4×4 block so the 6-bit cell centre lands in it.
        for y in 100..104 {
            for u in 40..44 {
                for v in 200..204 {
                    let i = t.index(Yuv::new(y, u, v));
                    t.set(i, ColourClass::Pink);
                }
            }
        }
        let small = t.resampled(6).unwrap();
        assert_eq!(small.class_of(Yuv::new(101, 41, 201)), ColourClass::Pink);
        assert_eq!(small.class_counts()[4], 1);
    }
}
