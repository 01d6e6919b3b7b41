//! "What is still unclassified?": the colours of the open stream (or a range of its frames) that
//! the table leaves unclassified, most pixels first. Frames are counted a few per UI frame (as
//! the try-edit scan does) so the window stays responsive; every pixel's table cell is counted,
//! whatever its class, so committing or undoing an edit re-ranks the hints at once without a
//! new scan.
//!
//! A hint is one bin of 8 × 8 × 8 YUV values (a few neighbouring table cells): the unclassified
//! cells of that bin that the frames show, with their pixel count. Selecting a hint selects
//! exactly those cells ([`crate::lut::Region::Cells`]), so a Commit classifies what was seen and
//! nothing more.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use super::source::Source;
use crate::frame::Yuv;
use crate::lut::{ColourClass, LookupTable};

/// Bits dropped from each 8-bit channel to form a hint's bin: bins of 8 values per channel.
pub const HINT_BIN_SHIFT: u8 = 3;

/// At most this many hints are listed.
pub const MAX_HINTS: usize = 24;

/// Per table cell, the frames with the most of its pixels that are remembered (and per hint
/// the frames listed): enough to go and look, small enough for every cell of a long stream.
pub const FRAMES_KEPT: usize = 8;

/// One colour the table leaves unclassified.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageHint {
    /// Pixels of the scanned frames whose cell is in this hint (and still unclassified).
    pub pixels: u64,
    /// The pixel-weighted mean colour of those pixels' cells (cell centres).
    pub mean: Yuv,
    /// The hint's unclassified table cells the frames show, by index, ascending; once every
    /// one is classified, the cells it had.
    pub cells: Vec<usize>,
    /// The frames with the most of its pixels, most first: (frame index, pixels), at most
    /// [`FRAMES_KEPT`].
    pub frames: Vec<(usize, u64)>,
    /// The class its cells were given, once every one of them is classified: the row stays
    /// where it was (a list that re-sorted after a commit put another hint under the cursor).
    pub done: Option<ColourClass>,
}

/// The whole-stream count of unclassified colours over a range of frames.
#[derive(Debug, Clone)]
pub struct CoverageScan {
    /// First frame of the range.
    pub first: usize,
    /// One past the last frame of the range.
    pub end: usize,
    /// Next frame to count.
    pub next: usize,
    /// Frames that could not be read.
    pub errors: usize,
    /// Pixels counted so far.
    pub pixels: u64,
    /// Bits per channel of the table the cells index.
    bits: u8,
    /// Pixels per table cell, over every class.
    per_cell: HashMap<usize, u64>,
    /// Per table cell, the frames with most of its pixels (frame, pixels), most first, at most
    /// [`FRAMES_KEPT`].
    cell_frames: HashMap<usize, Vec<(usize, u64)>>,
    /// The ranking, refreshed by [`CoverageScan::rank`].
    hints: Vec<CoverageHint>,
    /// Pixels of the counted frames the table leaves unclassified (as of the last ranking).
    unclassified_pixels: u64,
}

impl CoverageScan {
    /// A count over frames `first..=last` (clamped to the `total` frames of the source) for a
    /// table of `bits` bits per channel.
    #[must_use]
    pub fn new(first: usize, last: usize, total: usize, bits: u8) -> Self {
        let end = last.saturating_add(1).min(total);
        let first = first.min(end);
        Self {
            first,
            end,
            next: first,
            errors: 0,
            pixels: 0,
            bits,
            per_cell: HashMap::new(),
            cell_frames: HashMap::new(),
            hints: Vec::new(),
            unclassified_pixels: 0,
        }
    }

    /// True when every frame of the range was counted.
    #[must_use]
    pub fn done(&self) -> bool {
        self.next >= self.end
    }

    /// Frames counted so far.
    #[must_use]
    pub fn counted(&self) -> usize {
        self.next - self.first
    }

    /// Counts frames of `src` for up to `budget` of wall time (at least one frame per call).
    /// Returns true when it counted anything.
    pub fn scan(&mut self, src: &mut Source, lut: &LookupTable, budget: Duration) -> bool {
        let start = Instant::now();
        let mut any = false;
        while !self.done() && (!any || start.elapsed() < budget) {
            any = true;
            let i = self.next;
            self.next += 1;
            let Ok(f) = src.read_uncached(i) else {
                self.errors += 1;
                continue;
            };
            self.count_frame(i, &f.frame, lut);
        }
        any
    }

    /// Counts the pixels of frame `index` by table cell, and remembers it among the frames
    /// with most pixels of each of its cells.
    pub fn count_frame(&mut self, index: usize, frame: &crate::frame::Frame, lut: &LookupTable) {
        if lut.bits() != self.bits {
            return;
        }
        let here = cell_counts(frame, lut);
        for (&cell, &n) in &here {
            *self.per_cell.entry(cell).or_insert(0) += n;
            keep_top_frames(self.cell_frames.entry(cell).or_default(), (index, n));
        }
        self.pixels += frame.pixel_count() as u64;
    }

    /// Pixels of the counted frames in table cell `index`.
    #[must_use]
    pub fn cell_pixels(&self, index: usize) -> u64 {
        self.per_cell.get(&index).copied().unwrap_or(0)
    }

    /// The frames with most pixels of table cell `index`, most first: (frame, pixels).
    #[must_use]
    pub fn cell_frames(&self, index: usize) -> &[(usize, u64)] {
        self.cell_frames.get(&index).map_or(&[], Vec::as_slice)
    }

    /// The frames with most pixels of any of `cells`, most first: (frame, pixels), at most
    /// [`FRAMES_KEPT`] (from each cell's own best frames, so a frame's count is a lower
    /// bound when a cell did not keep it).
    #[must_use]
    pub fn frames_of(&self, cells: &[usize]) -> Vec<(usize, u64)> {
        let mut by_frame: HashMap<usize, u64> = HashMap::new();
        for c in cells {
            for &(f, n) in self.cell_frames(*c) {
                *by_frame.entry(f).or_insert(0) += n;
            }
        }
        let mut frames: Vec<(usize, u64)> = by_frame.into_iter().collect();
        frames.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        frames.truncate(FRAMES_KEPT);
        frames
    }

    /// Ranks the counted cells that `lut` leaves unclassified into hints, most pixels first. A
    /// table of other bits than the count's gives no hints.
    pub fn rank(&mut self, lut: &LookupTable) {
        self.hints.clear();
        self.unclassified_pixels = 0;
        if lut.bits() != self.bits {
            return;
        }
        // Table cell → bin: the cell's value bits above HINT_BIN_SHIFT.
        let drop = HINT_BIN_SHIFT.saturating_sub(lut.shift());
        let mut bins: HashMap<[usize; 3], (u64, [u64; 3], Vec<usize>)> = HashMap::new();
        let unclassified = ColourClass::Unclassified.code();
        for (&index, &n) in &self.per_cell {
            if lut.get(index) != Some(unclassified) {
                continue;
            }
            self.unclassified_pixels += n;
            let cell = lut.cell_of_index(index);
            let bin = cell.map(|c| c >> drop);
            let e = bins.entry(bin).or_insert((0, [0; 3], Vec::new()));
            e.0 += n;
            for (sum, c) in e.1.iter_mut().zip(cell) {
                *sum += n * cell_centre(c, lut.shift());
            }
            e.2.push(index);
        }
        let mut hints: Vec<CoverageHint> = bins
            .into_values()
            .map(|(pixels, sums, mut cells)| {
                cells.sort_unstable();
                let mean = sums.map(|s| u8::try_from(s / pixels.max(1)).unwrap_or(u8::MAX));
                CoverageHint {
                    pixels,
                    mean: Yuv::new(mean[0], mean[1], mean[2]),
                    cells,
                    frames: Vec::new(),
                    done: None,
                }
            })
            .collect();
        // Most pixels first; ties by the first cell, so the order never depends on hashing.
        hints.sort_by(|a, b| b.pixels.cmp(&a.pixels).then(a.cells.cmp(&b.cells)));
        hints.truncate(MAX_HINTS);
        for h in &mut hints {
            h.frames = self.frames_of(&h.cells);
        }
        self.hints = hints;
    }

    /// Follows table edits without re-ranking: each hint keeps its place in the list, losing
    /// the cells that are now classified (its pixels with them); a hint whose every cell is
    /// classified stays, marked with the class they got. [`Self::rank`] orders afresh.
    pub fn refresh(&mut self, lut: &LookupTable) {
        if lut.bits() != self.bits {
            self.hints.clear();
            return;
        }
        let unclassified = ColourClass::Unclassified.code();
        let per_cell = &self.per_cell;
        for h in &mut self.hints {
            let open: Vec<usize> = h
                .cells
                .iter()
                .copied()
                .filter(|&c| lut.get(c) == Some(unclassified))
                .collect();
            if open.is_empty() {
                h.done = h
                    .cells
                    .first()
                    .and_then(|&c| lut.get(c))
                    .and_then(ColourClass::from_code);
                h.pixels = 0;
            } else {
                h.done = None;
                h.pixels = open.iter().filter_map(|c| per_cell.get(c)).sum();
                h.cells = open;
            }
        }
        self.unclassified_pixels = self
            .per_cell
            .iter()
            .filter(|&(&c, _)| lut.get(c) == Some(unclassified))
            .map(|(_, n)| n)
            .sum();
    }

    /// The hints of the last ranking, most pixels first.
    #[must_use]
    pub fn hints(&self) -> &[CoverageHint] {
        &self.hints
    }

    /// Pixels of the counted frames that the table (as of the last ranking) leaves unclassified.
    #[must_use]
    pub const fn unclassified_pixels(&self) -> u64 {
        self.unclassified_pixels
    }
}

/// Pixels of `frame` per table cell of `lut`.
#[must_use]
pub fn cell_counts(frame: &crate::frame::Frame, lut: &LookupTable) -> HashMap<usize, u64> {
    let mut here: HashMap<usize, u64> = HashMap::new();
    frame.for_each_pixel(|_, _, p| *here.entry(lut.index(p)).or_insert(0) += 1);
    here
}

/// Adds `entry` (frame, pixels) to `frames`, keeping the [`FRAMES_KEPT`] with most pixels,
/// most first.
fn keep_top_frames(frames: &mut Vec<(usize, u64)>, entry: (usize, u64)) {
    let at = frames
        .iter()
        .position(|f| f.1 < entry.1)
        .unwrap_or(frames.len());
    if at < FRAMES_KEPT {
        frames.insert(at, entry);
        frames.truncate(FRAMES_KEPT);
    }
}

/// The 8-bit value at the centre of a cell along one channel.
fn cell_centre(cell: usize, shift: u8) -> u64 {
    ((cell as u64) << shift) + ((1u64 << shift) >> 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Frame;
    use crate::lut::{EditRecord, Region};

    /// A 16×4 frame: 40 pixels of `a`, 24 of `b`.
    fn frame(a: Yuv, b: Yuv) -> Frame {
        Frame::yuv444_from_fn(16, 4, |x, y| if y < 2 || x < 4 { a } else { b }).expect("frame")
    }

    #[test]
    fn ranks_unclassified_colours_by_pixels_and_follows_table_edits() {
        let (a, b) = (Yuv::new(100, 60, 200), Yuv::new(40, 140, 90));
        let mut lut = LookupTable::new(7).expect("table");
        let mut scan = CoverageScan::new(0, 0, 1, 7);
        scan.count_frame(0, &frame(a, b), &lut);
        scan.rank(&lut);
        let hints = scan.hints();
        assert_eq!(hints.len(), 2);
        assert_eq!((hints[0].pixels, hints[1].pixels), (40, 24));
        assert_eq!(hints[0].cells, vec![lut.index(a)]);
        // The mean is the cell's centre: within half a cell (1 value at 7 bits) of the pixel.
        assert!(hints[0].mean.u.abs_diff(a.u) <= 1 && hints[0].mean.v.abs_diff(a.v) <= 1);
        assert_eq!(scan.unclassified_pixels(), 64);
        // Classifying the first hint's cells removes it; the other stays.
        lut.apply(EditRecord::now(
            ColourClass::Green,
            Region::Cells {
                indices: hints[0].cells.clone(),
            },
        ));
        // Refreshed, the list keeps its order: the first hint stays, marked green.
        scan.refresh(&lut);
        assert_eq!(scan.hints().len(), 2);
        assert_eq!(scan.hints()[0].done, Some(ColourClass::Green));
        assert_eq!(scan.hints()[1].cells, vec![lut.index(b)]);
        assert_eq!(scan.unclassified_pixels(), 24);
        // Ranked afresh, only the open one is left.
        scan.rank(&lut);
        assert_eq!(scan.hints().len(), 1);
        assert_eq!(scan.hints()[0].cells, vec![lut.index(b)]);
        assert_eq!(scan.unclassified_pixels(), 24);
    }

    #[test]
    fn a_hint_names_the_frames_with_most_of_its_pixels() {
        let (a, b) = (Yuv::new(100, 60, 200), Yuv::new(40, 140, 90));
        let lut = LookupTable::new(7).expect("table");
        let mut scan = CoverageScan::new(0, 20, 21, 7);
        // Frame k shows k+1 pixels of `a` … (frames 0..=19), frame 20 none.
        for k in 0..20 {
            let f = Frame::yuv444_from_fn(8, 4, |x, y| if y * 8 + x <= k { a } else { b })
                .expect("frame");
            scan.count_frame(k, &f, &lut);
        }
        scan.rank(&lut);
        let hint_a = scan
            .hints()
            .iter()
            .find(|h| h.cells == vec![lut.index(a)])
            .expect("a's hint");
        assert_eq!(hint_a.frames.len(), FRAMES_KEPT);
        assert_eq!(hint_a.frames[0], (19, 20));
        assert!(hint_a.frames.windows(2).all(|w| w[0].1 >= w[1].1));
        assert_eq!(scan.cell_pixels(lut.index(a)), (1..=20).sum::<u64>());
    }

    #[test]
    fn neighbouring_cells_share_a_hint_and_a_range_is_clamped() {
        // 100 and 102 fall in different 7-bit cells but in one 8-value bin.
        let (a, b) = (Yuv::new(100, 60, 200), Yuv::new(102, 60, 200));
        let lut = LookupTable::new(7).expect("table");
        let mut scan = CoverageScan::new(3, 99, 10, 7);
        assert_eq!((scan.first, scan.end), (3, 10));
        scan.count_frame(0, &frame(a, b), &lut);
        scan.rank(&lut);
        assert_eq!(scan.hints().len(), 1);
        assert_eq!(scan.hints()[0].pixels, 64);
        assert_eq!(scan.hints()[0].cells.len(), 2);
        // A table of other bits gives no hints rather than wrong cells.
        let other = LookupTable::new(6).expect("table");
        scan.rank(&other);
        assert!(scan.hints().is_empty());
        let empty = CoverageScan::new(5, 2, 10, 7);
        assert!(empty.done());
    }
}
