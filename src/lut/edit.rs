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

    /// True when the edit writes every cell of `lut` (a box over the whole table): the table
    /// after it is the same whatever it was before.
    #[must_use]
    pub fn covers_table(&self, lut: &LookupTable) -> bool {
        self.region
            .select_cells(lut)
            .is_some_and(|b| b.len() == lut.cells().len())
    }

    /// The fewest bytes the undo step of this edit on `lut` holds ([`AppliedEdit::held_bytes`]),
    /// known before it is applied: exact for a box (one old code a cell), without the old codes
    /// of picked cells (those that change, which only applying tells).
    #[must_use]
    pub fn least_held_bytes(&self, lut: &LookupTable) -> usize {
        size_of::<AppliedEdit>()
            + match &self.region {
                Region::Cells { indices } => indices.len() * size_of::<usize>(),
                Region::AroundSample { .. } => self.region.select_cells(lut).map_or(0, |b| b.len()),
            }
    }
}

/// Number of `cells` whose code is not `code`. Counted in byte-wide lanes, 255 cells at a
/// time (a byte counter cannot overflow), which the compiler turns into wide vector compares.
fn count_other_codes(cells: &[u8], code: u8) -> usize {
    cells
        .chunks(255)
        .map(|chunk| {
            let same = chunk
                .iter()
                .fold(0u8, |n, &c| n.wrapping_add(u8::from(c == code)));
            chunk.len() - usize::from(same)
        })
        .sum()
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
        self.apply_reusing(record, Vec::new())
    }

    /// [`LookupTable::apply`], keeping a box's old codes in `spare` (cleared first): the undo
    /// history hands back the buffer of a step it dropped, so a journal of whole-table edits
    /// does not fault in 16 MiB of fresh memory per edit.
    pub fn apply_reusing(&mut self, record: EditRecord, spare: Vec<u8>) -> AppliedEdit {
        let code = record.class.code();
        let (previous, changed) = match record.region.select_cells(self) {
            // Picked cells directly (sorted, once each, inside the table): resolving them to a
            // flag per cell would cost the whole table for every small edit (20,000 such edits
            // took 30 s to replay on a 7-bit table).
            None => self.apply_to_cells(&record.region, code),
            // A box, row by row (a row of V is contiguous), without listing its cells.
            Some(b) => self.apply_to_box(b, code, spare),
        };
        AppliedEdit {
            record,
            previous,
            changed,
        }
    }

    /// The runs of contiguous cells of a box, in index order: (first index, length) of each.
    /// A row of V is contiguous; rows spanning every V run on into the next U, and planes
    /// spanning every U and V into the next Y, so a whole table is one run.
    fn box_rows(&self, b: CellBox) -> impl Iterator<Item = (usize, usize)> + use<> {
        let side = self.side();
        let full_v = b.min[2] == 0 && b.max[2] + 1 == side;
        let full_uv = full_v && b.min[1] == 0 && b.max[1] + 1 == side;
        let row_len = b.max[2] + 1 - b.min[2];
        // Per Y plane: one run when the plane's rows join up, else one run per U row.
        let (u_runs, run_len) = if full_v {
            (b.min[1]..=b.min[1], row_len * (b.max[1] + 1 - b.min[1]))
        } else {
            (b.min[1]..=b.max[1], row_len)
        };
        let (y_runs, run_len) = if full_uv {
            (b.min[0]..=b.min[0], run_len * (b.max[0] + 1 - b.min[0]))
        } else {
            (b.min[0]..=b.max[0], run_len)
        };
        y_runs.flat_map(move |y| {
            u_runs
                .clone()
                .map(move |u| ((y * side + u) * side + b.min[2], run_len))
        })
    }

    fn apply_to_box(&mut self, b: CellBox, code: u8, spare: Vec<u8>) -> (PreviousCodes, usize) {
        let mut codes = spare;
        codes.clear();
        codes.reserve(b.len());
        let mut changed = 0;
        for (start, len) in self.box_rows(b) {
            if let Some(run) = self.cells.get_mut(start..start + len) {
                // In pieces that stay in the first-level cache: kept, counted and overwritten
                // in one pass over memory rather than three.
                for piece in run.chunks_mut(4096) {
                    codes.extend_from_slice(piece);
                    changed += count_other_codes(piece, code);
                    piece.fill(code);
                }
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
    /// The old-codes buffer of the latest box step dropped, handed to the next edit (not
    /// counted in `bytes`: at most one buffer, emptied).
    spare: Vec<u8>,
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
            spare: Vec::new(),
        }
    }

    /// Applies `record` to `lut` and remembers it; clears the redo stack. Returns the number
    /// of cells that changed.
    pub fn commit(&mut self, lut: &mut LookupTable, record: EditRecord) -> usize {
        let applied = lut.apply_reusing(record, std::mem::take(&mut self.spare));
        let changed = applied.changed_cells();
        for e in std::mem::take(&mut self.redo) {
            self.bytes -= e.held_bytes();
            self.keep_spare(e);
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
                self.keep_spare(old);
            }
        }
    }

    /// Keeps a forgotten step's box buffer for the next edit when it is the largest seen.
    fn keep_spare(&mut self, old: AppliedEdit) {
        if let PreviousCodes::Box { codes, .. } = old.previous
            && codes.capacity() > self.spare.capacity()
        {
            self.spare = codes;
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

    /// Most bytes the steps may hold ([`MAX_HISTORY_BYTES`] by default).
    #[must_use]
    pub const fn max_bytes(&self) -> usize {
        self.max_bytes
    }

    /// Counts `steps` more as dropped: steps a replay knew would be dropped and never kept
    /// (`workspace::journal`'s replay from the last whole-table edit the bound drops).
    pub const fn note_dropped(&mut self, steps: usize) {
        self.dropped += steps;
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
        let spare = match edit.previous {
            PreviousCodes::Box { codes, .. } => codes,
            PreviousCodes::Cells { .. } => std::mem::take(&mut self.spare),
        };
        let applied = lut.apply_reusing(edit.record, spare);
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
        self.spare = Vec::new();
        self.bytes = 0;
    }
}

#[cfg(test)]
#[path = "edit_tests.rs"]
mod tests;
