//! "Try edit on the stream": the frames a pending edit would change, scanned a few frames per UI
//! frame so the window stays responsive.

use std::time::{Duration, Instant};

use super::source::Source;
use crate::blobs::{BlobSet, Connectivity};
use crate::classify::ClassifiedImage;
use crate::lut::{ColourClass, LookupTable, Region};

/// One frame that a tried edit would change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TryEditRow {
    /// Frame index.
    pub index: usize,
    /// Pixels whose class would change.
    pub changed_pixels: usize,
    /// Blobs (at least the minimum size) before the edit.
    pub blobs_before: usize,
    /// Blobs (at least the minimum size) after the edit.
    pub blobs_after: usize,
}

/// The whole-stream check of a pending edit, run a few frames per UI frame.
#[derive(Debug, Clone)]
pub struct TryEdit {
    /// The class the edit writes.
    pub class: ColourClass,
    /// The cells.
    pub region: Region,
    edited: LookupTable,
    /// Next frame to scan.
    pub next: usize,
    /// Frames in the source.
    pub total: usize,
    /// Frames that would change, in order.
    pub rows: Vec<TryEditRow>,
    /// Frames that could not be read.
    pub errors: usize,
}

impl TryEdit {
    /// True when every frame was scanned.
    #[must_use]
    pub fn done(&self) -> bool {
        self.next >= self.total
    }

    /// A check of writing `region` as `class` into `lut`, over the `total` frames of a source.
    #[must_use]
    pub fn new(class: ColourClass, region: Region, lut: &LookupTable, total: usize) -> Self {
        let mut edited = lut.clone();
        edited.apply(crate::lut::EditRecord::now(class, region.clone()));
        Self {
            class,
            region,
            edited,
            next: 0,
            total,
            rows: Vec::new(),
            errors: 0,
        }
    }

    /// Scans frames of `src` against `lut` (the table without the edit) for up to `budget`;
    /// blobs smaller than `min_pixels` are not counted.
    pub fn scan(
        &mut self,
        src: &mut Source,
        lut: &LookupTable,
        connectivity: Connectivity,
        min_pixels: u32,
        budget: Duration,
    ) {
        let start = Instant::now();
        while !self.done() && start.elapsed() < budget {
            let i = self.next;
            self.next += 1;
            let Ok(f) = src.read_uncached(i) else {
                self.errors += 1;
                continue;
            };
            let before = ClassifiedImage::from_frame(&f.frame, lut);
            let after = ClassifiedImage::from_frame(&f.frame, &self.edited);
            let changed = before
                .codes()
                .iter()
                .zip(after.codes())
                .filter(|(a, b)| a != b)
                .count();
            if changed == 0 {
                continue;
            }
            let count = |img: &ClassifiedImage| {
                BlobSet::from_image(img, connectivity)
                    .active()
                    .filter(|b| b.pixels >= min_pixels)
                    .count()
            };
            self.rows.push(TryEditRow {
                index: i,
                changed_pixels: changed,
                blobs_before: count(&before),
                blobs_after: count(&after),
            });
        }
    }
}
