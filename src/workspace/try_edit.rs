//! "Try edit on the stream": the frames a pending edit would change, scanned a few frames per UI
//! frame so the window stays responsive.

use std::time::Duration;

use super::source::Source;
use super::stream_scan::StreamScan;
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
    /// The frames read so far and those that would change.
    pub stream: StreamScan<TryEditRow>,
}

impl TryEdit {
    /// True when every frame was scanned.
    #[must_use]
    pub const fn done(&self) -> bool {
        self.stream.done()
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
            stream: StreamScan::new(total),
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
        let edited = &self.edited;
        self.stream.scan(src, budget, |index, f| {
            let before = ClassifiedImage::from_frame(&f.frame, lut);
            let after = ClassifiedImage::from_frame(&f.frame, edited);
            let changed = before
                .codes()
                .iter()
                .zip(after.codes())
                .filter(|(a, b)| a != b)
                .count();
            if changed == 0 {
                return None;
            }
            let count = |img: &ClassifiedImage| {
                BlobSet::from_image(img, connectivity)
                    .active()
                    .filter(|b| b.pixels >= min_pixels)
                    .count()
            };
            Some(TryEditRow {
                index,
                changed_pixels: changed,
                blobs_before: count(&before),
                blobs_after: count(&after),
            })
        });
    }
}
