//! Blob formation: connected regions of one colour class in a classified image.
//!
//! A blob is a maximal connected set of pixels of one class code other than 0 (`FORMATS.md`).
//! With [`Connectivity::Eight`] (the default, as the original EOTN and CMVision) diagonal
//! neighbours join; with [`Connectivity::Four`] only left/right/up/down neighbours do.
//!
//! The algorithm is CMVision's: run-length encode each row (runs are found a machine word at a
//! time: a run of one colour is skipped 8 bytes per step, or 32 with AVX2 and 64 with AVX-512
//! when the chosen [`KernelSet`] has them), join overlapping runs of equal colour
//! in adjacent rows with union-find (the root is always the run first in raster order), then one
//! pass over the runs accumulates each blob's box, pixel count and centroid sums. All buffers
//! live in a [`BlobSet`] that is reused frame after frame.
//!
//! The original tool marked blobs it had merged with `trueblob`/`ignore` flags; here
//! [`BlobSet::merge`] joins two blobs explicitly and [`BlobSet::active`] lists the survivors.

mod avx2;
mod avx512;

use serde::{Deserialize, Serialize};

use crate::classify::ClassifiedImage;
use crate::frame::{ImagePoint, PixelBox};
use crate::kernels::{self, KernelSet};
use crate::lut::ColourClass;

/// Which neighbours join a blob.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Connectivity {
    /// Left, right, up and down neighbours.
    #[serde(rename = "4")]
    Four,
    /// Also the four diagonal neighbours.
    #[default]
    #[serde(rename = "8")]
    Eight,
}

impl Connectivity {
    /// 4 or 8.
    #[must_use]
    pub const fn neighbours(self) -> u8 {
        match self {
            Self::Four => 4,
            Self::Eight => 8,
        }
    }

    /// From 4 or 8.
    #[must_use]
    pub const fn from_neighbours(n: u8) -> Option<Self> {
        match n {
            4 => Some(Self::Four),
            8 => Some(Self::Eight),
            _ => None,
        }
    }
}

/// A horizontal run of one colour: pixels `x0..x1` (end exclusive) of row `y`.
///
/// Sixteen-bit coordinates (frame sides are at most 65,535 pixels) keep a run in 8 bytes: the
/// run list of a frame is walked three times, so its size is most of the blob pass's memory
/// traffic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Run {
    /// First column.
    pub x0: u16,
    /// One past the last column.
    pub x1: u16,
    /// Row.
    pub y: u16,
    /// Class code.
    pub colour: u8,
}

/// A connected region of one class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Blob {
    /// Class code of its pixels.
    pub colour: u8,
    /// Its index in the [`BlobSet`] (raster order of its first pixel).
    pub number: u32,
    /// Leftmost column, inclusive.
    pub minx: u32,
    /// Top row, inclusive.
    pub miny: u32,
    /// Rightmost column, inclusive.
    pub maxx: u32,
    /// Bottom row, inclusive.
    pub maxy: u32,
    /// Number of its own pixels.
    pub pixels: u32,
    /// Sum of its pixels' column indices (for the centroid).
    pub sum_x: u64,
    /// Sum of its pixels' row indices (for the centroid).
    pub sum_y: u64,
}

impl Blob {
    /// Its bounding box, inclusive pixels.
    #[must_use]
    pub const fn bounds(&self) -> PixelBox {
        PixelBox::new(self.minx, self.miny, self.maxx, self.maxy)
    }

    /// Box width, pixels.
    #[must_use]
    pub const fn width(&self) -> u32 {
        self.maxx - self.minx + 1
    }

    /// Box height, pixels.
    #[must_use]
    pub const fn height(&self) -> u32 {
        self.maxy - self.miny + 1
    }

    /// Box area (width × height), pixels; compare with [`Blob::pixels`] for how full it is.
    #[must_use]
    pub const fn area(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }

    /// The class of its pixels.
    #[must_use]
    pub fn class(&self) -> ColourClass {
        ColourClass::from_code(self.colour).unwrap_or(ColourClass::Unclassified)
    }

    /// Mean pixel centre in image coordinates (pixel (i, j) has its centre at (i + 0.5, j + 0.5)).
    #[must_use]
    pub fn centroid(&self) -> (f64, f64) {
        let n = f64::from(self.pixels.max(1));
        (self.sum_x as f64 / n + 0.5, self.sum_y as f64 / n + 0.5)
    }

    /// Box centre in image coordinates, pixels.
    #[must_use]
    pub fn box_centre(&self) -> ImagePoint {
        ImagePoint::new(
            f64::from(self.minx + self.maxx + 1) / 2.0,
            f64::from(self.miny + self.maxy + 1) / 2.0,
        )
    }

    /// The blob both together make: the union of boxes, pixels and sums added; keeps this blob's
    /// colour and number.
    #[must_use]
    pub fn merged_with(&self, other: &Self) -> Self {
        Self {
            colour: self.colour,
            number: self.number,
            minx: self.minx.min(other.minx),
            miny: self.miny.min(other.miny),
            maxx: self.maxx.max(other.maxx),
            maxy: self.maxy.max(other.maxy),
            pixels: self.pixels + other.pixels,
            sum_x: self.sum_x + other.sum_x,
            sum_y: self.sum_y + other.sum_y,
        }
    }
}

/// The blobs of one classified image, with the runs they were built from, and reusable buffers.
#[derive(Debug, Clone, Default)]
pub struct BlobSet {
    width: usize,
    height: usize,
    connectivity: Connectivity,
    /// The run search's kernels; `None`: those chosen for this CPU ([`kernels::active`]).
    kernels: Option<KernelSet>,
    blobs: Vec<Blob>,
    /// For each blob: `None`, or the blob it was merged into.
    merged_into: Vec<Option<u32>>,
    runs: Vec<Run>,
    /// Union-find parent per run (scratch while finding).
    parent: Vec<u32>,
    /// The blob number of each run.
    run_blob: Vec<u32>,
    /// Index of each row's first run; one extra entry at the end.
    row_start: Vec<u32>,
}

impl BlobSet {
    /// Finds the blobs of `img` and returns them as a new set.
    #[must_use]
    pub fn from_image(img: &ClassifiedImage, connectivity: Connectivity) -> Self {
        let mut set = Self::default();
        set.find(img, connectivity);
        set
    }

    /// Finds the blobs of `img`, replacing what the set held (buffers are reused).
    pub fn find(&mut self, img: &ClassifiedImage, connectivity: Connectivity) {
        self.width = img.width();
        self.height = img.height();
        self.connectivity = connectivity;
        self.blobs.clear();
        self.merged_into.clear();
        self.runs.clear();
        self.parent.clear();
        self.run_blob.clear();
        self.row_start.clear();
        let reach = u32::from(connectivity == Connectivity::Eight);
        let set = self.kernels.unwrap_or_else(kernels::active);

        for y in 0..img.height() {
            let first = self.runs.len();
            self.row_start.push(u32_of(first));
            encode_row(img.row(y), u16_of(y), &mut self.runs, set);
            self.parent.extend(u32_of(first)..u32_of(self.runs.len()));
            if y > 0 {
                let prev = u32_index(self.row_start[y - 1])..first;
                self.join_rows(prev, first, reach);
            }
        }
        self.row_start.push(u32_of(self.runs.len()));
        self.collect_blobs();
    }

    /// Chooses the run search's kernels for later [`BlobSet::find`] calls (the default is the
    /// set chosen for this CPU); every set finds the same runs.
    pub fn set_kernels(&mut self, set: KernelSet) {
        self.kernels = Some(set);
    }

    /// Unites each run of the current row (from `current`) with the runs of the previous row
    /// (`prev`) it touches.
    fn join_rows(&mut self, prev: std::ops::Range<usize>, current: usize, reach: u32) {
        let (before, now) = self.runs.split_at(current);
        let above = before.get(prev.clone()).unwrap_or(&[]);
        let parent = &mut self.parent;
        let mut j = 0;
        for (offset, r) in now.iter().enumerate() {
            // Skip previous-row runs that end (plus reach) before this run starts.
            let (x0, x1) = (u32::from(r.x0), u32::from(r.x1));
            while above.get(j).is_some_and(|a| u32::from(a.x1) + reach <= x0) {
                j += 1;
            }
            for (k, a) in above.iter().enumerate().skip(j) {
                if u32::from(a.x0) >= x1 + reach {
                    break;
                }
                if a.colour == r.colour {
                    unite(parent, prev.start + k, current + offset);
                }
            }
        }
    }

    /// One pass in raster order: roots open blobs, members add to their root's blob.
    ///
    /// Every parent pointer points to a smaller run index (unions keep the smaller root, path
    /// halving only shortens), so when run `i` is reached its parent already knows its blob
    /// number — no root search is needed here.
    fn collect_blobs(&mut self) {
        self.run_blob.resize(self.runs.len(), 0);
        for i in 0..self.runs.len() {
            let r = self.runs[i];
            let (x0, x1, y) = (u32::from(r.x0), u32::from(r.x1), u32::from(r.y));
            let len = x1 - x0;
            let sum_x = (u64::from(x0) + u64::from(x1) - 1) * u64::from(len) / 2;
            let sum_y = u64::from(y) * u64::from(len);
            let parent = u32_index(self.parent[i]);
            if parent == i {
                let number = u32_of(self.blobs.len());
                self.blobs.push(Blob {
                    colour: r.colour,
                    number,
                    minx: x0,
                    miny: y,
                    maxx: x1 - 1,
                    maxy: y,
                    pixels: len,
                    sum_x,
                    sum_y,
                });
                self.run_blob[i] = number;
            } else {
                let number = self.run_blob[parent];
                self.run_blob[i] = number;
                let b = &mut self.blobs[u32_index(number)];
                b.minx = b.minx.min(x0);
                b.maxx = b.maxx.max(x1 - 1);
                b.maxy = y;
                b.pixels += len;
                b.sum_x += sum_x;
                b.sum_y += sum_y;
            }
        }
        self.merged_into.resize(self.blobs.len(), None);
    }

    /// Every blob found, merged or not, in raster order of their first pixel.
    #[must_use]
    pub fn all(&self) -> &[Blob] {
        &self.blobs
    }

    /// The blobs not merged into another, in raster order.
    pub fn active(&self) -> impl Iterator<Item = &Blob> {
        self.blobs
            .iter()
            .zip(&self.merged_into)
            .filter(|(_, m)| m.is_none())
            .map(|(b, _)| b)
    }

    /// Active blobs of one class.
    pub fn of_class(&self, class: ColourClass) -> impl Iterator<Item = &Blob> {
        self.active().filter(move |b| b.colour == class.code())
    }

    /// A blob by number.
    #[must_use]
    pub fn get(&self, number: u32) -> Option<&Blob> {
        self.blobs.get(u32_index(number))
    }

    /// Merges blob `absorb` into blob `keep` (the `trueblob`/`ignore` of the original): `keep`
    /// grows to cover both, `absorb` is no longer active. Returns false (and changes nothing)
    /// when either number is unknown, they are the same, or either was already merged away.
    pub fn merge(&mut self, keep: u32, absorb: u32) -> bool {
        let (k, a) = (u32_index(keep), u32_index(absorb));
        let ok = k != a
            && k < self.blobs.len()
            && a < self.blobs.len()
            && self.merged_into[k].is_none()
            && self.merged_into[a].is_none();
        if ok {
            self.blobs[k] = self.blobs[k].merged_with(&self.blobs[a]);
            self.merged_into[a] = Some(keep);
        }
        ok
    }

    /// The blob a merged blob ended up in (itself when never merged).
    #[must_use]
    pub fn survivor(&self, number: u32) -> u32 {
        let mut n = number;
        // Merges only point to active blobs at merge time, so chains are short and acyclic.
        for _ in 0..self.blobs.len() {
            match self.merged_into.get(u32_index(n)).copied().flatten() {
                Some(next) => n = next,
                None => break,
            }
        }
        n
    }

    /// The active blob holding pixel (x, y), or `None` for unclassified pixels and outside.
    #[must_use]
    pub fn blob_at(&self, x: usize, y: usize) -> Option<&Blob> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let (x, start, end) = (
            u32_of(x),
            u32_index(*self.row_start.get(y)?),
            u32_index(*self.row_start.get(y + 1)?),
        );
        let runs = self.runs.get(start..end)?;
        let i = runs.partition_point(|r| u32::from(r.x1) <= x);
        runs.get(i).filter(|r| u32::from(r.x0) <= x)?;
        let number = *self.run_blob.get(start + i)?;
        self.get(self.survivor(number))
    }

    /// All runs, row by row.
    #[must_use]
    pub fn runs(&self) -> &[Run] {
        &self.runs
    }

    /// The runs of one blob (as found, before any merge).
    pub fn runs_of(&self, number: u32) -> impl Iterator<Item = &Run> {
        self.runs
            .iter()
            .zip(&self.run_blob)
            .filter(move |(_, b)| **b == number)
            .map(|(r, _)| r)
    }

    /// The connectivity the set was found with.
    #[must_use]
    pub const fn connectivity(&self) -> Connectivity {
        self.connectivity
    }

    /// Size of the image the set was found in, pixels.
    #[must_use]
    pub const fn image_size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

/// Appends the runs of one row (unclassified pixels make no runs).
///
/// Run boundaries are found a machine word at a time (SWAR): each 8-byte word of the row is
/// compared with itself shifted by one byte (the byte before the word shifted in), and every
/// non-zero byte of the difference is a place where the colour changes. Inside a long run a word
/// costs one load, a shift and a compare.
fn encode_row(row: &[u8], y: u16, runs: &mut Vec<Run>, set: KernelSet) {
    let done = match set {
        KernelSet::Portable => false,
        KernelSet::Avx2 | KernelSet::Avx2Gather => avx2::encode_row(row, y, runs),
        KernelSet::Avx512 | KernelSet::Avx512Gather => avx512::encode_row(row, y, runs),
    };
    if !done {
        encode_row_words(row, y, runs);
    }
}

/// The runs of one row as its colour boundaries are found, shared by both run searches.
struct RowRuns<'a> {
    runs: &'a mut Vec<Run>,
    y: u16,
    /// First column of the run being built.
    start: usize,
    /// Its colour.
    colour: u8,
}

impl<'a> RowRuns<'a> {
    /// Starts row `y` whose first pixel has `first` colour.
    fn new(runs: &'a mut Vec<Run>, y: u16, first: u8) -> Self {
        Self {
            runs,
            y,
            start: 0,
            colour: first,
        }
    }

    /// The run being built ends before column `x`; a run of `colour` starts there.
    fn boundary(&mut self, x: usize, colour: u8) {
        self.close(x);
        self.start = x;
        self.colour = colour;
    }

    /// Boundaries found pixel by pixel, for the columns `from..` of `row` no word covered.
    fn scan_tail(&mut self, row: &[u8], from: usize) {
        for (x, &c) in row.iter().enumerate().skip(from) {
            if c != self.colour {
                self.boundary(x, c);
            }
        }
    }

    /// Ends the last run at the row's end (`width`).
    fn finish(mut self, width: usize) {
        self.close(width);
    }

    /// Appends the run being built, ending before `x` (unclassified pixels make no runs).
    fn close(&mut self, x: usize) {
        if self.colour != 0 {
            self.runs.push(Run {
                x0: u16_of(self.start),
                x1: u16_of(x),
                y: self.y,
                colour: self.colour,
            });
        }
    }
}

/// The portable run search: 8 pixels per step in a 64-bit word.
fn encode_row_words(row: &[u8], y: u16, runs: &mut Vec<Run>) {
    let Some(&first) = row.first() else { return };
    let mut out = RowRuns::new(runs, y, first);
    let (words, tail) = row.as_chunks::<8>();
    // The byte before the current word, in the low byte; the first pixel is its own predecessor.
    let mut before = u64::from(first);
    for (k, bytes) in words.iter().enumerate() {
        let word = u64::from_le_bytes(*bytes);
        let shifted = (word << 8) | before;
        before = word >> 56;
        let diff = word ^ shifted;
        if diff == 0 {
            continue;
        }
        let mut changed = nonzero_bytes(diff);
        while changed != 0 {
            let byte = (changed.trailing_zeros() / 8) as usize;
            changed &= changed - 1;
            out.boundary(k * 8 + byte, bytes[byte]);
        }
    }
    out.scan_tail(row, row.len() - tail.len());
    out.finish(row.len());
}

/// Bit 7 of every non-zero byte of `t`, all other bits clear.
const fn nonzero_bytes(t: u64) -> u64 {
    const LOW7: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    // (b & 0x7f) + 0x7f sets bit 7 for any non-zero low part without carrying into the next
    // byte; or-ing b itself catches 0x80.
    (((t & LOW7) + LOW7) | t) & !LOW7
}

/// The root of run `i`'s set, halving the path on the way (each run then points to its
/// grandparent).
fn root(parent: &mut [u32], mut i: usize) -> usize {
    while u32_index(parent[i]) != i {
        let grand = parent[u32_index(parent[i])];
        parent[i] = grand;
        i = u32_index(grand);
    }
    i
}

/// Joins the sets of run `above` (previous row) and run `below` (current row, `above < below`).
///
/// The smaller root index stays root, so every parent pointer points to a smaller index and a
/// root precedes its members in raster order. Current-row runs are never anyone's parent (they
/// only join earlier runs), so a current-row run that is still its own parent is a singleton and
/// simply takes the other root.
fn unite(parent: &mut [u32], above: usize, below: usize) {
    let ra = root(parent, above);
    if u32_index(parent[below]) == below {
        parent[below] = u32_of(ra);
        return;
    }
    let rb = root(parent, below);
    if ra < rb {
        parent[rb] = u32_of(ra);
    } else if rb < ra {
        parent[ra] = u32_of(rb);
    }
}

/// Coordinates and counts fit u32: frames are at most 65,535 pixels a side.
fn u32_of(v: usize) -> u32 {
    u32::try_from(v).unwrap_or(u32::MAX)
}

/// Run coordinates fit u16: frame sides are at most 65,535 pixels (`Frame` checks it; larger
/// classified images made by hand saturate rather than wrap).
fn u16_of(v: usize) -> u16 {
    u16::try_from(v).unwrap_or(u16::MAX)
}

fn u32_index(v: u32) -> usize {
    v as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image from rows of digits ('.' = 0).
    fn img(rows: &[&str]) -> ClassifiedImage {
        let w = rows[0].len();
        let codes = rows
            .iter()
            .flat_map(|r| r.bytes().map(|b| if b == b'.' { 0 } else { b - b'0' }))
            .collect();
        ClassifiedImage::from_codes(w, rows.len(), codes).unwrap()
    }

    fn boxes(set: &BlobSet) -> Vec<(u8, u32, u32, u32, u32, u32)> {
        set.active()
            .map(|b| (b.colour, b.minx, b.miny, b.maxx, b.maxy, b.pixels))
            .collect()
    }

    #[test]
    fn diagonal_neighbours_join_only_with_eight_connectivity() {
        let i = img(&["1.", ".1"]);
        assert_eq!(
            boxes(&BlobSet::from_image(&i, Connectivity::Eight)),
            [(1, 0, 0, 1, 1, 2)]
        );
        assert_eq!(
            boxes(&BlobSet::from_image(&i, Connectivity::Four)),
            [(1, 0, 0, 0, 0, 1), (1, 1, 1, 1, 1, 1)]
        );
    }

    #[test]
    fn colours_never_mix_and_unclassified_makes_no_blobs() {
        let i = img(&["1122..", "1122..", "......"]);
        let set = BlobSet::from_image(&i, Connectivity::Eight);
        assert_eq!(boxes(&set), [(1, 0, 0, 1, 1, 4), (2, 2, 0, 3, 1, 4)]);
    }

    #[test]
    fn u_shape_joins_late_through_union_find() {
        let i = img(&["1...1", "1...1", "11111"]);
        let set = BlobSet::from_image(&i, Connectivity::Four);
        assert_eq!(boxes(&set), [(1, 0, 0, 4, 2, 9)]);
        let b = set.all()[0];
        assert_eq!((b.width(), b.height(), b.area()), (5, 3, 15));
    }

    #[test]
    fn blob_numbers_never_mix_with_union_find_parents() {
        // Regression: the third run's root is not the run with its blob's number; an early
        // version stored blob numbers in the parent array and merged the 2s into the 1s.
        let set = BlobSet::from_image(&img(&["1.", "12", "22"]), Connectivity::Four);
        assert_eq!(boxes(&set), [(1, 0, 0, 0, 1, 2), (2, 0, 1, 1, 2, 3)]);
    }

    #[test]
    fn long_runs_cross_word_boundaries() {
        let row = format!("{}{}{}", "5".repeat(19), "1".repeat(9), "5".repeat(4));
        let i = img(&[&row, &row]);
        let set = BlobSet::from_image(&i, Connectivity::Eight);
        assert_eq!(
            boxes(&set),
            [
                (5, 0, 0, 18, 1, 38),
                (1, 19, 0, 27, 1, 18),
                (5, 28, 0, 31, 1, 8)
            ]
        );
        assert_eq!(set.runs().len(), 6);
    }

    #[test]
    fn word_at_a_time_runs_equal_a_plain_scan() {
        // Rows of every length up to 100 (AVX2 blocks of 32, AVX-512 of 64, and their tails) with runs of random lengths, including 0x80-valued and
        // adjacent equal-low-bit colours that naive zero-byte tricks get wrong.
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut rand = move |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        let palette = [0u8, 1, 2, 3, 0x80, 0x81, 0xff];
        let sets = crate::kernels::runnable_saying_the_rest("run search");
        for len in 1..150 {
            for _ in 0..50 {
                let mut row = Vec::new();
                while row.len() < len {
                    let c = palette[rand(palette.len() as u64) as usize];
                    for _ in 0..=rand(10) {
                        row.push(c);
                    }
                }
                row.truncate(len);
                let mut fast = Vec::new();
                encode_row_words(&row, 3, &mut fast);
                // Each set's own scan, so that none is the portable one under another name.
                for &set in &sets {
                    let mut other = Vec::new();
                    let ran = match set {
                        KernelSet::Portable => {
                            encode_row_words(&row, 3, &mut other);
                            true
                        }
                        KernelSet::Avx2 | KernelSet::Avx2Gather => {
                            avx2::encode_row(&row, 3, &mut other)
                        }
                        KernelSet::Avx512 | KernelSet::Avx512Gather => {
                            avx512::encode_row(&row, 3, &mut other)
                        }
                    };
                    assert!(ran, "{set} is runnable here, so its own scan ran");
                    assert_eq!(other, fast, "{set}, row {row:?}");
                }
                let mut plain = Vec::new();
                let mut x0 = 0;
                for x in 1..=row.len() {
                    if x == row.len() || row[x] != row[x0] {
                        if row[x0] != 0 {
                            plain.push(Run {
                                x0: x0 as u16,
                                x1: x as u16,
                                y: 3,
                                colour: row[x0],
                            });
                        }
                        x0 = x;
                    }
                }
                assert_eq!(fast, plain, "row {row:?}");
            }
        }
    }

    #[test]
    fn centroid_uses_pixel_centres() {
        let set = BlobSet::from_image(&img(&["11", "11"]), Connectivity::Eight);
        assert_eq!(set.all()[0].centroid(), (1.0, 1.0));
        assert_eq!(set.all()[0].box_centre(), ImagePoint::new(1.0, 1.0));
    }

    #[test]
    fn blob_at_finds_the_blob_under_a_pixel() {
        let set = BlobSet::from_image(&img(&["1.2", "1.2"]), Connectivity::Eight);
        assert_eq!(set.blob_at(0, 1).map(|b| b.colour), Some(1));
        assert_eq!(set.blob_at(1, 1), None);
        assert_eq!(set.blob_at(2, 0).map(|b| b.number), Some(1));
        assert_eq!(set.blob_at(9, 0), None);
    }

    #[test]
    fn merge_replaces_trueblob_and_ignore_flags() {
        let mut set = BlobSet::from_image(&img(&["3.3.1"]), Connectivity::Eight);
        assert_eq!(set.active().count(), 3);
        assert!(set.merge(0, 1));
        assert!(!set.merge(1, 2), "a merged-away blob cannot keep");
        assert!(!set.merge(0, 0));
        assert_eq!(boxes(&set), [(3, 0, 0, 2, 0, 2), (1, 4, 0, 4, 0, 1)]);
        assert_eq!(set.survivor(1), 0);
        assert_eq!(set.blob_at(2, 0).map(|b| b.number), Some(0));
        assert_eq!(set.runs_of(1).count(), 1);
    }

    #[test]
    fn reuse_clears_previous_results() {
        let mut set = BlobSet::from_image(&img(&["111", "111"]), Connectivity::Eight);
        set.find(&img(&["..", ".."]), Connectivity::Four);
        assert_eq!(set.all().len(), 0);
        assert_eq!(set.connectivity(), Connectivity::Four);
    }
}
