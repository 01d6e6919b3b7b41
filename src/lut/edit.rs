//! Editing a lookup table as data: select cells, preview, commit, undo, redo.
//!
//! The original tool's workflow: click a sample pixel, widen the selection per channel with a
//! *sensitivity* (0 = only the sample's own cell, 1 = ±1 cell, … in the table's resolution), see
//! which pixels it would classify, then write it. Here every change is an [`EditRecord`] (class,
//! region, time): records can be saved in a journal, replayed to rebuild a table, and tested.
//! Applying a record yields an [`AppliedEdit`] holding exactly the cells it changed and their old
//! codes, which is what undo needs. [`EditHistory`] keeps an undo stack bounded by the memory it holds, and a redo stack.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use super::{ColourClass, LookupTable};
use crate::frame::{Frame, Yuv};

/// How far a selection reaches from the sample's cell, per channel, in table cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub struct Sensitivity {
    /// ± cells along Y.
    pub y: u8,
    /// ± cells along U.
    pub u: u8,
    /// ± cells along V.
    pub v: u8,
}

impl Sensitivity {
    /// The same reach on all three channels.
    #[must_use]
    pub const fn uniform(cells: u8) -> Self {
        Self {
            y: cells,
            u: cells,
            v: cells,
        }
    }
}

/// An inclusive box of table cells: `min[c]..=max[c]` for channels Y, U, V.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct CellBox {
    /// Lowest cell per channel (Y, U, V).
    pub min: [usize; 3],
    /// Highest cell per channel (Y, U, V), inclusive.
    pub max: [usize; 3],
}

impl CellBox {
    /// Number of cells in the box.
    #[must_use]
    pub fn len(&self) -> usize {
        (0..3).map(|c| self.max[c] + 1 - self.min[c]).product()
    }

    /// Never true: a box holds at least its sample's cell.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// True when the cell coordinates lie in the box.
    #[must_use]
    pub fn contains(&self, cell: [usize; 3]) -> bool {
        (0..3).all(|c| (self.min[c]..=self.max[c]).contains(&cell[c]))
    }
}

/// Which cells an edit touches.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Region {
    /// The box of cells around a sample pixel's cell, as the original's sensitivity control.
    AroundSample {
        /// The clicked pixel.
        sample: Yuv,
        /// The reach per channel.
        sensitivity: Sensitivity,
    },
    /// Cells picked one by one (for instance in the U–V plane view), by index.
    Cells {
        /// Cell indices into the table the edit was made for.
        indices: Vec<usize>,
    },
}

/// A region resolved against one table, ready to test pixels quickly.
#[derive(Debug, Clone)]
pub enum Selection {
    /// A box of cells.
    Box(CellBox),
    /// An explicit set, one flag per table cell.
    Set(Vec<bool>),
}

impl Region {
    /// True when the region holds the cell at `index` of `lut` (without resolving a whole
    /// selection: cheap enough to ask per hovered pixel).
    #[must_use]
    pub fn contains_index(&self, lut: &LookupTable, index: usize) -> bool {
        match self {
            Self::AroundSample { .. } => self.select(lut).contains_index(lut, index),
            Self::Cells { indices } => indices.contains(&index),
        }
    }

    /// The box of cells an `AroundSample` region covers in `lut`; `None` for picked cells.
    fn select_cells(&self, lut: &LookupTable) -> Option<CellBox> {
        match self {
            // Not through `select`: for picked cells it makes a flag per table cell.
            Self::Cells { .. } => None,
            Self::AroundSample { .. } => match self.select(lut) {
                Selection::Box(b) => Some(b),
                Selection::Set(_) => None,
            },
        }
    }

    /// Resolves the region for a table of this resolution.
    #[must_use]
    pub fn select(&self, lut: &LookupTable) -> Selection {
        match self {
            Self::AroundSample {
                sample,
                sensitivity,
            } => {
                let centre = lut.cell_of(*sample);
                let reach = [sensitivity.y, sensitivity.u, sensitivity.v].map(usize::from);
                let top = lut.side() - 1;
                Selection::Box(CellBox {
                    min: [0, 1, 2].map(|c| centre[c].saturating_sub(reach[c])),
                    max: [0, 1, 2].map(|c| (centre[c] + reach[c]).min(top)),
                })
            }
            Self::Cells { indices } => {
                let mut set = vec![false; lut.cells().len()];
                for &i in indices {
                    if let Some(flag) = set.get_mut(i) {
                        *flag = true;
                    }
                }
                Selection::Set(set)
            }
        }
    }
}

impl Selection {
    /// True when the cell at `index` of `lut` is selected.
    #[must_use]
    pub fn contains_index(&self, lut: &LookupTable, index: usize) -> bool {
        match self {
            Self::Box(b) => b.contains(lut.cell_of_index(index)),
            Self::Set(s) => s.get(index).copied().unwrap_or(false),
        }
    }

    /// True when the pixel's cell is selected.
    #[must_use]
    pub fn contains_pixel(&self, lut: &LookupTable, p: Yuv) -> bool {
        match self {
            Self::Box(b) => b.contains(lut.cell_of(p)),
            Self::Set(s) => s.get(lut.index(p)).copied().unwrap_or(false),
        }
    }

    /// Every selected cell index, ascending.
    pub fn indices<'a>(&'a self, lut: &'a LookupTable) -> Box<dyn Iterator<Item = usize> + 'a> {
        match self {
            Self::Box(b) => Box::new((b.min[0]..=b.max[0]).flat_map(move |y| {
                (b.min[1]..=b.max[1]).flat_map(move |u| {
                    (b.min[2]..=b.max[2]).map(move |v| lut.index_of_cell([y, u, v]))
                })
            })),
            Self::Set(s) => Box::new(s.iter().enumerate().filter(|(_, f)| **f).map(|(i, _)| i)),
        }
    }

    /// The preview: one flag per frame pixel (raster order), true where the pixel's cell is
    /// selected. Nothing is written to the table.
    #[must_use]
    pub fn preview_mask(&self, lut: &LookupTable, frame: &Frame) -> Vec<bool> {
        let mut mask = vec![false; frame.pixel_count()];
        let w = frame.width();
        frame.for_each_pixel(|x, y, p| mask[y * w + x] = self.contains_pixel(lut, p));
        mask
    }
}

/// One change to a table, as data.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct EditRecord {
    /// The class written into the region (unclassified erases).
    pub class: ColourClass,
    /// The cells written.
    pub region: Region,
    /// When the edit was made, milliseconds since the Unix epoch (0 when unknown).
    #[serde(default)]
    pub time_unix_ms: u64,
    /// The frame and pixel the sample was taken from, when the edit came from one (absent in
    /// journals written before 2026-12-03 and for cells picked in the U–V plane).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampled_at: Option<SampleAt>,
}

/// Where an edit's sample pixel was: which frame of the open source, which pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SampleAt {
    /// Frame index in the source.
    pub frame: usize,
    /// Column, pixels.
    pub x: usize,
    /// Row, pixels.
    pub y: usize,
}

impl EditRecord {
    /// A record stamped with the current time.
    #[must_use]
    pub fn now(class: ColourClass, region: Region) -> Self {
        Self {
            class,
            region,
            time_unix_ms: now_unix_ms(),
            sampled_at: None,
        }
    }
}

/// Milliseconds since the Unix epoch, 0 if the clock is before it: the time stamp of edits and
/// journal entries.
#[must_use]
pub fn now_unix_ms() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_millis()).unwrap_or(u64::MAX))
}

/// An edit that was applied: the record and the old codes it overwrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AppliedEdit {
    /// What was done.
    pub record: EditRecord,
    /// The old codes, for undo.
    pub previous: PreviousCodes,
    /// Number of cells whose class changed.
    changed: usize,
}

/// The codes an edit overwrote, kept compactly: a whole 8-bit table's box is 16 MiB (one byte a
/// cell), not a list of 16 million (index, code) pairs, so the undo history holds 16 such edits
/// and a journal of whole-table edits replays at memory speed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PreviousCodes {
    /// Picked cells: the index and old code of each cell that changed, in index order.
    Cells {
        /// Cell indices (a table has at most 2^24 cells).
        indices: Vec<u32>,
        /// Their old codes, one per index.
        codes: Vec<u8>,
    },
    /// A box: the old code of every cell in it, row by row (V fastest, then U, then Y).
    Box {
        /// The cells covered.
        cells: CellBox,
        /// One old code per cell of the box.
        codes: Vec<u8>,
    },
}

impl PreviousCodes {
    /// Bytes the codes hold.
    fn held_bytes(&self) -> usize {
        match self {
            Self::Cells { indices, codes } => indices.len() * size_of::<u32>() + codes.len(),
            Self::Box { codes, .. } => codes.len(),
        }
    }
}

impl AppliedEdit {
    /// Number of cells whose class changed.
    #[must_use]
    pub const fn changed_cells(&self) -> usize {
        self.changed
    }
}

impl LookupTable {
    /// Writes an edit into the table and returns what it changed (for undo).
    pub fn apply(&mut self, record: EditRecord) -> AppliedEdit {
        let code = record.class.code();
        let (previous, changed) = match record.region.select_cells(self) {
            // Picked cells directly (sorted, once each, inside the table): resolving them to a
            // flag per cell would cost the whole table for every small edit (20,000 such edits
            // took 30 s to replay on a 7-bit table).
            None => self.apply_to_cells(&record.region, code),
            // A box, row by row (a row of V is contiguous), without listing its cells.
            Some(b) => self.apply_to_box(b, code),
        };
        AppliedEdit {
            record,
            previous,
            changed,
        }
    }

    /// The rows of V of a box: (first index, length) of each.
    fn box_rows(&self, b: CellBox) -> impl Iterator<Item = (usize, usize)> + use<> {
        let side = self.side();
        let row_len = b.max[2] + 1 - b.min[2];
        (b.min[0]..=b.max[0]).flat_map(move |y| {
            (b.min[1]..=b.max[1]).map(move |u| ((y * side + u) * side + b.min[2], row_len))
        })
    }

    fn apply_to_box(&mut self, b: CellBox, code: u8) -> (PreviousCodes, usize) {
        let mut codes = Vec::with_capacity(b.len());
        let mut changed = 0;
        for (start, len) in self.box_rows(b) {
            if let Some(row) = self.cells.get_mut(start..start + len) {
                codes.extend_from_slice(row);
                changed += row.iter().filter(|&&c| c != code).count();
                row.fill(code);
            }
        }
        (PreviousCodes::Box { cells: b, codes }, changed)
    }

    fn apply_to_cells(&mut self, region: &Region, code: u8) -> (PreviousCodes, usize) {
        let len = self.cells.len();
        let mut picked: Vec<usize> = match region {
            Region::Cells { indices } => indices.iter().copied().filter(|&i| i < len).collect(),
            Region::AroundSample { .. } => Vec::new(),
        };
        picked.sort_unstable();
        picked.dedup();
        let (mut indices, mut codes) = (Vec::new(), Vec::new());
        for i in picked {
            let (Some(cell), Ok(index)) = (self.cells.get_mut(i), u32::try_from(i)) else {
                continue;
            };
            if *cell != code {
                indices.push(index);
                codes.push(std::mem::replace(cell, code));
            }
        }
        let changed = indices.len();
        (PreviousCodes::Cells { indices, codes }, changed)
    }

    /// Puts back the cells an applied edit changed.
    pub fn revert(&mut self, edit: &AppliedEdit) {
        match &edit.previous {
            PreviousCodes::Cells { indices, codes } => {
                for (&i, &old) in indices.iter().zip(codes) {
                    if let Some(cell) = self.cells.get_mut(i as usize) {
                        *cell = old;
                    }
                }
            }
            PreviousCodes::Box { cells, codes } => {
                let mut rest = codes.as_slice();
                for (start, len) in self.box_rows(*cells) {
                    let (Some(row), Some((old, tail))) = (
                        self.cells.get_mut(start..start + len),
                        rest.split_at_checked(len),
                    ) else {
                        return;
                    };
                    row.copy_from_slice(old);
                    rest = tail;
                }
            }
        }
    }
}

/// Most memory the undo and redo steps of an [`EditHistory`] hold together, bytes (256 MiB):
/// about 16 million changed cells, one whole-table edit of an 8-bit table. Beyond it the oldest
/// undo steps are dropped (the journal keeps them).
pub const MAX_HISTORY_BYTES: usize = 256 << 20;

impl AppliedEdit {
    /// Memory the edit holds, bytes: its changed cells' old codes and its region's cell list.
    #[must_use]
    pub fn held_bytes(&self) -> usize {
        let cells = match &self.record.region {
            Region::Cells { indices } => indices.len() * size_of::<usize>(),
            Region::AroundSample { .. } => 0,
        };
        size_of::<Self>() + self.previous.held_bytes() + cells
    }
}

/// Undo and redo over applied edits, bounded by the memory they hold: the oldest undo steps
/// are dropped when the steps together hold more than the limit (the newest is always kept).
#[derive(Debug, Clone)]
pub struct EditHistory {
    undo: VecDeque<AppliedEdit>,
    redo: Vec<AppliedEdit>,
    /// Most bytes held ([`AppliedEdit::held_bytes`] over both stacks).
    max_bytes: usize,
    /// Bytes held now.
    bytes: usize,
    /// Undo steps dropped so far to stay within `max_bytes`.
    dropped: usize,
}

impl Default for EditHistory {
    fn default() -> Self {
        Self::new(MAX_HISTORY_BYTES)
    }
}

impl EditHistory {
    /// A history holding at most `max_bytes` bytes of steps (the newest step is kept whatever
    /// its size).
    #[must_use]
    pub fn new(max_bytes: usize) -> Self {
        Self {
            undo: VecDeque::new(),
            redo: Vec::new(),
            max_bytes,
            bytes: 0,
            dropped: 0,
        }
    }

    /// Applies `record` to `lut` and remembers it; clears the redo stack. Returns the number
    /// of cells that changed.
    pub fn commit(&mut self, lut: &mut LookupTable, record: EditRecord) -> usize {
        let applied = lut.apply(record);
        let changed = applied.changed_cells();
        for e in self.redo.drain(..) {
            self.bytes -= e.held_bytes();
        }
        self.push_undo(applied);
        changed
    }

    /// Puts an applied edit on the undo stack, dropping the oldest steps beyond the limit.
    fn push_undo(&mut self, applied: AppliedEdit) {
        self.bytes += applied.held_bytes();
        self.undo.push_back(applied);
        while self.bytes > self.max_bytes && self.undo.len() > 1 {
            if let Some(old) = self.undo.pop_front() {
                self.bytes -= old.held_bytes();
                self.dropped += 1;
            }
        }
    }

    /// Undo steps dropped so far because the history held too much (a caller compares it
    /// before and after a commit to say so).
    #[must_use]
    pub const fn dropped(&self) -> usize {
        self.dropped
    }

    /// Bytes the steps hold now.
    #[must_use]
    pub const fn held_bytes(&self) -> usize {
        self.bytes
    }

    /// Undoes the latest edit; returns its record, or `None` when there is nothing to undo.
    pub fn undo(&mut self, lut: &mut LookupTable) -> Option<&EditRecord> {
        let edit = self.undo.pop_back()?;
        lut.revert(&edit);
        self.redo.push(edit);
        self.redo.last().map(|e| &e.record)
    }

    /// Redoes the latest undone edit; returns its record, or `None` when there is none.
    pub fn redo(&mut self, lut: &mut LookupTable) -> Option<&EditRecord> {
        let edit = self.redo.pop()?;
        self.bytes -= edit.held_bytes();
        let applied = lut.apply(edit.record);
        self.push_undo(applied);
        self.undo.back().map(|e| &e.record)
    }

    /// Edits that can be undone, oldest first.
    pub fn undo_stack(&self) -> impl Iterator<Item = &AppliedEdit> {
        self.undo.iter()
    }

    /// Number of edits that can be undone.
    #[must_use]
    pub fn undo_len(&self) -> usize {
        self.undo.len()
    }

    /// Number of edits that can be redone.
    #[must_use]
    pub fn redo_len(&self) -> usize {
        self.redo.len()
    }

    /// Forgets everything (after loading another table).
    pub fn clear(&mut self) {
        self.undo.clear();
        self.redo.clear();
        self.bytes = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn around(y: u8, u: u8, v: u8, s: u8) -> Region {
        Region::AroundSample {
            sample: Yuv::new(y, u, v),
            sensitivity: Sensitivity::uniform(s),
        }
    }

    #[test]
    fn sensitivity_zero_selects_one_cell_and_one_widens_by_one() {
        let lut = LookupTable::new(7).unwrap();
        let Selection::Box(b) = around(100, 100, 100, 0).select(&lut) else {
            panic!("box expected")
        };
        assert_eq!(b.len(), 1);
        assert_eq!(b.min, [50, 50, 50]);
        let Selection::Box(b) = around(100, 100, 100, 1).select(&lut) else {
            panic!("box expected")
        };
        assert_eq!((b.min, b.max, b.len()), ([49; 3], [51; 3], 27));
    }

    #[test]
    fn selection_is_clamped_at_the_table_edges() {
        let lut = LookupTable::new(6).unwrap();
        let Selection::Box(b) = around(0, 255, 3, 2).select(&lut) else {
            panic!("box expected")
        };
        assert_eq!(b.min, [0, 61, 0]);
        assert_eq!(b.max, [2, 63, 2]);
        assert_eq!(b.len(), 3 * 3 * 3);
    }

    #[test]
    fn preview_marks_matching_pixels_without_writing() {
        let lut = LookupTable::new(7).unwrap();
        let frame = Frame::uyvy_from_fn(4, 2, |x, _| {
            if x < 2 {
                Yuv::new(120, 80, 190)
            } else {
                Yuv::new(60, 128, 128)
            }
        })
        .unwrap();
        let sel = around(121, 81, 191, 0).select(&lut);
        let mask = sel.preview_mask(&lut, &frame);
        assert_eq!(mask, [true, true, false, false, true, true, false, false]);
        assert_eq!(
            lut.class_counts()[0],
            lut.cells().len(),
            "preview writes nothing"
        );
    }

    #[test]
    fn commit_undo_redo_restore_exact_tables() {
        let mut lut = LookupTable::new(6).unwrap();
        let mut history = EditHistory::default();
        let empty = lut.clone();
        let changed = history.commit(
            &mut lut,
            EditRecord::now(ColourClass::Orange, around(120, 80, 190, 1)),
        );
        assert_eq!(changed, 27);
        let after_first = lut.clone();
        // An overlapping edit changes only the cells that differ.
        let changed = history.commit(
            &mut lut,
            EditRecord::now(ColourClass::Green, around(124, 80, 190, 1)),
        );
        assert_eq!(changed, 27);
        // Y cells 29..=31 then 30..=32: two of the three orange layers were overwritten.
        assert_eq!(lut.class_counts()[1], 9);
        assert_eq!(lut.class_counts()[5], 27);
        let after_second = lut.clone();

        assert_eq!(
            history.undo(&mut lut).map(|r| r.class),
            Some(ColourClass::Green)
        );
        assert_eq!(lut, after_first);
        assert_eq!(
            history.undo(&mut lut).map(|r| r.class),
            Some(ColourClass::Orange)
        );
        assert_eq!(lut, empty);
        assert!(history.undo(&mut lut).is_none());
        history.redo(&mut lut);
        history.redo(&mut lut);
        assert_eq!(lut, after_second);
        assert!(history.redo(&mut lut).is_none());
    }

    #[test]
    fn new_commit_clears_redo_and_history_is_bounded_by_bytes() {
        let mut lut = LookupTable::new(6).unwrap();
        let one = |i: u8| EditRecord::now(ColourClass::Pink, around(i * 40, 10, 10, 0));
        // Room for three one-cell steps.
        let step = lut.clone().apply(one(0)).held_bytes();
        let mut history = EditHistory::new(3 * step);
        for i in 0..5u8 {
            history.commit(&mut lut, one(i));
        }
        assert_eq!((history.undo_len(), history.dropped()), (3, 2));
        assert!(history.held_bytes() <= 3 * step);
        history.undo(&mut lut);
        assert_eq!(history.redo_len(), 1);
        history.commit(
            &mut lut,
            EditRecord::now(ColourClass::White, around(250, 128, 128, 0)),
        );
        assert_eq!(history.redo_len(), 0);
        assert_eq!(
            history.held_bytes(),
            3 * step,
            "the redo step's bytes are freed"
        );
        // A step larger than the whole limit is still kept, alone: it can be undone.
        let whole = EditRecord::now(ColourClass::Green, around(128, 128, 128, 63));
        history.commit(&mut lut, whole);
        assert_eq!((history.undo_len(), history.dropped()), (1, 5));
        history.undo(&mut lut);
        assert_eq!(lut.class_counts()[5], 0);
    }

    #[test]
    fn picked_cells_apply_like_their_selection() {
        let indices = vec![900, 5, 9, 5, 1 << 30];
        let region = Region::Cells {
            indices: indices.clone(),
        };
        let mut direct = LookupTable::new(6).unwrap();
        let applied = direct.apply(EditRecord::now(ColourClass::Yellow, region.clone()));
        let expected: Vec<usize> = region.select(&direct).indices(&direct).collect();
        assert_eq!(expected, [5, 9, 900]);
        let PreviousCodes::Cells { indices, .. } = &applied.previous else {
            panic!("picked cells keep a list");
        };
        let changed: Vec<usize> = indices.iter().map(|&i| i as usize).collect();
        assert_eq!(changed, expected, "sorted, once each, inside the table");
    }

    #[test]
    fn explicit_cells_region_and_records_serialise() {
        let mut lut = LookupTable::new(6).unwrap();
        let record = EditRecord {
            class: ColourClass::Yellow,
            region: Region::Cells {
                indices: vec![5, 9, usize::MAX],
            },
            time_unix_ms: 42,
            sampled_at: Some(SampleAt {
                frame: 3,
                x: 10,
                y: 20,
            }),
        };
        let json = serde_json::to_string(&record).unwrap();
        let back: EditRecord = serde_json::from_str(&json).unwrap();
        assert_eq!(back, record);
        let applied = lut.apply(back);
        assert_eq!(applied.changed_cells(), 2, "out-of-range index ignored");
        assert_eq!(lut.get(9), Some(3));
    }
}
