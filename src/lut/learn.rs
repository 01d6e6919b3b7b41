//! A first lookup table from labelled frames, and how well a table classifies labelled frames.
//!
//! Hand-classifying a table from nothing takes hours; starting from a table built out of
//! labelled pixels takes minutes. Labels come from the renderer's ground truth
//! ([`crate::sim::Rendered::labels`]) or from a user's masks (one class code per pixel, the
//! `.cls` format of `eotn classify --raw`). [`TableBuilder`] counts, per table cell, how many
//! labelled pixels of each class fall into it; [`TableBuilder::build`] gives each cell its
//! majority class when the vote is clear, then grows every class by a margin of cells into the
//! unseen colour space around it, so that colours a little darker or brighter than the samples
//! still classify. Cells where unlabelled pixels (code 0: walls, floor, people) win stay
//! unclassified, which keeps off-field colours out.

use std::collections::HashMap;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::{CLASS_COUNT, ColourClass, LookupTable, LutError};
use crate::frame::Frame;

/// How a table is made from the counts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LearnParams {
    /// Table resolution, bits per channel (6, 7 or 8).
    pub bits: u8,
    /// Cells each class grows into unseen neighbouring cells (6-neighbourhood steps).
    pub margin_cells: usize,
    /// Fewest labelled pixels of the winning class for a cell to take it.
    pub min_pixels: u32,
    /// Smallest share of the cell's pixels the winning class must have (0..1).
    pub min_purity: f64,
}

impl Default for LearnParams {
    fn default() -> Self {
        Self {
            bits: 7,
            margin_cells: 2,
            min_pixels: 2,
            min_purity: 0.6,
        }
    }
}

/// Labels that do not fit their frame.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum LabelError {
    /// The mask has a different number of pixels than the frame.
    #[error("label mask has {labels} entries but the frame has {pixels} pixels")]
    WrongLength {
        /// Entries in the mask.
        labels: usize,
        /// Pixels in the frame.
        pixels: usize,
    },
    /// A mask entry is not a class code of `FORMATS.md`.
    #[error("label mask entry {index} is {code}, not a class code (0..=14)")]
    UnknownCode {
        /// Position in the mask.
        index: usize,
        /// The byte.
        code: u8,
    },
}

fn check(frame: &Frame, labels: &[u8]) -> Result<(), LabelError> {
    let pixels = frame.width() * frame.height();
    if labels.len() != pixels {
        return Err(LabelError::WrongLength {
            labels: labels.len(),
            pixels,
        });
    }
    if let Some(index) = labels.iter().position(|&c| usize::from(c) >= CLASS_COUNT) {
        return Err(LabelError::UnknownCode {
            index,
            code: labels[index],
        });
    }
    Ok(())
}

/// Counts labelled pixels per table cell and class.
#[derive(Debug, Clone)]
pub struct TableBuilder {
    table: LookupTable,
    counts: HashMap<u32, [u32; CLASS_COUNT]>,
    pixels: u64,
}

impl TableBuilder {
    /// An empty builder for a table of `bits` bits per channel.
    ///
    /// # Errors
    /// [`LutError::BadBits`] for bits other than 6, 7, 8.
    pub fn new(bits: u8) -> Result<Self, LutError> {
        Ok(Self {
            table: LookupTable::new(bits)?,
            counts: HashMap::new(),
            pixels: 0,
        })
    }

    /// Adds one frame's pixels with their labels (row-major class codes).
    ///
    /// # Errors
    /// [`LabelError`] when the mask does not fit the frame.
    pub fn add_frame(&mut self, frame: &Frame, labels: &[u8]) -> Result<(), LabelError> {
        check(frame, labels)?;
        let w = frame.width();
        for (k, &label) in labels.iter().enumerate() {
            if let Some(p) = frame.pixel(k % w, k / w) {
                let cell = u32::try_from(self.table.index(p)).unwrap_or(u32::MAX);
                self.counts.entry(cell).or_insert([0; CLASS_COUNT])[usize::from(label)] += 1;
                self.pixels += 1;
            }
        }
        Ok(())
    }

    /// Labelled pixels seen so far.
    #[must_use]
    pub fn pixel_count(&self) -> u64 {
        self.pixels
    }

    /// Cells that received at least one pixel.
    #[must_use]
    pub fn cells_seen(&self) -> usize {
        self.counts.len()
    }

    /// The table: majority class per seen cell (when clear), then `margin_cells` of growth.
    /// `params.bits` is ignored (the builder's resolution is used).
    #[must_use]
    pub fn build(&self, params: &LearnParams) -> LookupTable {
        let mut table = self.table.clone();
        let n = table.side();
        let mut seen = vec![false; n * n * n];
        for (&cell, votes) in &self.counts {
            let cell = cell as usize;
            let Some(flag) = seen.get_mut(cell) else {
                continue;
            };
            *flag = true;
            let total: u32 = votes.iter().sum();
            let (best, &count) = votes
                .iter()
                .enumerate()
                .max_by_key(|&(code, &c)| (c, std::cmp::Reverse(code)))
                .unwrap_or((0, &0));
            #[expect(clippy::cast_possible_truncation, reason = "codes are below 15")]
            let class = ColourClass::from_code(best as u8).unwrap_or(ColourClass::Unclassified);
            if best != 0
                && count >= params.min_pixels
                && f64::from(count) >= params.min_purity * f64::from(total)
            {
                table.set(cell, class);
            }
        }
        // Grow into unseen cells, one 6-neighbourhood step at a time; the first class to reach
        // a cell keeps it (ties go to the lower index order, deterministic).
        for _ in 0..params.margin_cells {
            let before = table.cells().to_vec();
            let mut grown = Vec::new();
            for (cell, &code) in before.iter().enumerate() {
                if code != 0 || seen[cell] {
                    continue;
                }
                let [y, u, v] = table.cell_of_index(cell);
                let neighbours = [
                    (y.wrapping_sub(1), u, v),
                    (y + 1, u, v),
                    (y, u.wrapping_sub(1), v),
                    (y, u + 1, v),
                    (y, u, v.wrapping_sub(1)),
                    (y, u, v + 1),
                ];
                let found = neighbours.iter().find_map(|&(a, b, c)| {
                    (a < n && b < n && c < n)
                        .then(|| before[table.index_of_cell([a, b, c])])
                        .filter(|&code| code != 0)
                });
                if let Some(code) = found.and_then(ColourClass::from_code) {
                    grown.push((cell, code));
                }
            }
            if grown.is_empty() {
                break;
            }
            for (cell, class) in grown {
                table.set(cell, class);
            }
        }
        table
    }
}

/// How one class fared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ClassScore {
    /// Pixels labelled with this class.
    pub labelled: u64,
    /// Of those, how many the table gave this class.
    pub correct: u64,
    /// Of those, how many the table left unclassified.
    pub unclassified: u64,
}

/// Classification accuracy of a table on labelled frames.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Accuracy {
    /// Per class code (index = code; 0 counts pixels labelled unclassified).
    pub per_class: Vec<ClassScore>,
    /// Pixels labelled unclassified that the table gave a colour (false colour).
    pub false_colour: u64,
}

impl Default for Accuracy {
    fn default() -> Self {
        Self {
            per_class: vec![ClassScore::default(); CLASS_COUNT],
            false_colour: 0,
        }
    }
}

impl Accuracy {
    /// Adds one labelled frame classified by `table`.
    ///
    /// # Errors
    /// [`LabelError`] when the mask does not fit the frame.
    pub fn add_frame(
        &mut self,
        frame: &Frame,
        labels: &[u8],
        table: &LookupTable,
    ) -> Result<(), LabelError> {
        check(frame, labels)?;
        let w = frame.width();
        for (k, &label) in labels.iter().enumerate() {
            let Some(p) = frame.pixel(k % w, k / w) else {
                continue;
            };
            let got = table.classify(p);
            let Some(score) = self.per_class.get_mut(usize::from(label)) else {
                continue;
            };
            score.labelled += 1;
            if got == label {
                score.correct += 1;
            }
            if got == 0 {
                score.unclassified += 1;
            }
            if label == 0 && got != 0 {
                self.false_colour += 1;
            }
        }
        Ok(())
    }

    /// Pixels labelled with a colour (code ≠ 0).
    #[must_use]
    pub fn colour_pixels(&self) -> u64 {
        self.per_class.iter().skip(1).map(|s| s.labelled).sum()
    }

    /// Share of colour-labelled pixels given their own class (0..1).
    #[must_use]
    pub fn colour_accuracy(&self) -> f64 {
        let correct: u64 = self.per_class.iter().skip(1).map(|s| s.correct).sum();
        ratio(correct, self.colour_pixels())
    }

    /// Share of unlabelled pixels (code 0) that the table gave a colour (0..1).
    #[must_use]
    pub fn false_colour_rate(&self) -> f64 {
        ratio(
            self.false_colour,
            self.per_class.first().map_or(0, |s| s.labelled),
        )
    }

    /// Share of a class's pixels given that class (0..1), `None` if it never occurs.
    #[must_use]
    pub fn recall(&self, class: ColourClass) -> Option<f64> {
        let s = self.per_class.get(usize::from(class.code()))?;
        (s.labelled > 0).then(|| ratio(s.correct, s.labelled))
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 { 0.0 } else { a as f64 / b as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    fn two_colour_frame() -> (Frame, Vec<u8>) {
        // Left half orange-ish, right half green-ish, with a little variation.
        let frame = Frame::uyvy_from_fn(16, 4, |x, y| {
            let d = u8::try_from((x + y) % 3).unwrap_or(0);
            if x < 8 {
                Yuv::new(140 + d, 60, 200)
            } else {
                Yuv::new(100 + d, 110, 100)
            }
        })
        .expect("frame");
        let labels = (0..64)
            .map(|k| {
                if k % 16 < 8 {
                    ColourClass::Orange.code()
                } else {
                    ColourClass::Green.code()
                }
            })
            .collect();
        (frame, labels)
    }

    #[test]
    fn built_table_classifies_its_training_frame() {
        let (frame, labels) = two_colour_frame();
        let mut b = TableBuilder::new(7).expect("bits");
        b.add_frame(&frame, &labels).expect("fits");
        let table = b.build(&LearnParams {
            min_pixels: 1,
            ..LearnParams::default()
        });
        let mut acc = Accuracy::default();
        acc.add_frame(&frame, &labels, &table).expect("fits");
        assert!((acc.colour_accuracy() - 1.0).abs() < 1e-12);
        assert_eq!(acc.recall(ColourClass::Orange), Some(1.0));
        // The margin reaches a slightly brighter orange that was never seen.
        assert_eq!(
            table.classify(Yuv::new(145, 60, 200)),
            ColourClass::Orange.code()
        );
        // Far away stays unclassified.
        assert_eq!(table.classify(Yuv::new(250, 250, 10)), 0);
    }

    #[test]
    fn unlabelled_majority_keeps_a_cell_empty() {
        let frame = Frame::filled_uyvy(4, 2, Yuv::new(120, 70, 190)).expect("frame");
        let mut labels = vec![0_u8; 8];
        labels[0] = ColourClass::Orange.code();
        let mut b = TableBuilder::new(6).expect("bits");
        b.add_frame(&frame, &labels).expect("fits");
        let table = b.build(&LearnParams::default());
        assert_eq!(table.classify(Yuv::new(120, 70, 190)), 0);
        let mut acc = Accuracy::default();
        acc.add_frame(&frame, &labels, &table).expect("fits");
        assert_eq!(acc.false_colour, 0);
        assert_eq!(acc.recall(ColourClass::Orange), Some(0.0));
    }

    #[test]
    fn masks_that_do_not_fit_are_errors() {
        let (frame, _) = two_colour_frame();
        let mut b = TableBuilder::new(7).expect("bits");
        assert_eq!(
            b.add_frame(&frame, &[1, 2, 3]),
            Err(LabelError::WrongLength {
                labels: 3,
                pixels: 64
            })
        );
        let mut bad = vec![0_u8; 64];
        bad[5] = 99;
        assert_eq!(
            b.add_frame(&frame, &bad),
            Err(LabelError::UnknownCode { index: 5, code: 99 })
        );
    }
}
