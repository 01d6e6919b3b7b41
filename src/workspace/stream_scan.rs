//! The one loop of the whole-stream checks (try a table edit, try tuned parameters): every frame
//! of the open source read in order, a few per UI frame so the window stays responsive, each
//! frame that changes listed as a row.

use std::time::{Duration, Instant};

use super::source::Source;
use crate::sources::SourceFrame;

/// A whole-stream check under way: how far it got, the frames that change, the frames that could
/// not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StreamScan<Row> {
    /// Next frame to read.
    pub next: usize,
    /// Frames in the source.
    pub total: usize,
    /// The frames that change, in order.
    pub rows: Vec<Row>,
    /// Frames that could not be read.
    pub errors: usize,
}

impl<Row> StreamScan<Row> {
    /// A check of the `total` frames of a source, none read yet.
    #[must_use]
    pub const fn new(total: usize) -> Self {
        Self {
            next: 0,
            total,
            rows: Vec::new(),
            errors: 0,
        }
    }

    /// True when every frame was read.
    #[must_use]
    pub const fn done(&self) -> bool {
        self.next >= self.total
    }

    /// Reads frames of `src` in order (uncached: a scan must not push the shown frames out of
    /// the cache) until all are read or `budget` of wall time is spent. `row_of` gets each
    /// readable frame with its index and gives its row when the frame changes; a frame that
    /// cannot be read counts in [`Self::errors`].
    pub fn scan(
        &mut self,
        src: &mut Source,
        budget: Duration,
        mut row_of: impl FnMut(usize, &SourceFrame) -> Option<Row>,
    ) {
        let start = Instant::now();
        while !self.done() && start.elapsed() < budget {
            let index = self.next;
            self.next += 1;
            let Ok(frame) = src.read_uncached(index) else {
                self.errors += 1;
                continue;
            };
            if let Some(row) = row_of(index, &frame) {
                self.rows.push(row);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use super::*;

    /// `n` grey 208×160 frame files; those in `broken` are cut short, so they cannot be read.
    fn frames(dir: &Path, n: usize, broken: &[usize]) -> Vec<PathBuf> {
        (0..n)
            .map(|i| {
                let p = dir.join(format!("{i:02}.uyvy"));
                let len = if broken.contains(&i) {
                    100
                } else {
                    208 * 160 * 2
                };
                std::fs::write(&p, vec![128u8; len]).expect("write");
                p
            })
            .collect()
    }

    #[test]
    fn a_scan_reads_every_frame_in_order_lists_the_rows_and_counts_unreadable_frames() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut src = Source::files(frames(dir.path(), 5, &[3])).expect("source");
        let mut scan = StreamScan::new(src.len());
        let mut seen = Vec::new();
        scan.scan(&mut src, Duration::from_secs(60), |index, _| {
            seen.push(index);
            (index % 2 == 0).then_some(index * 10)
        });
        assert!(scan.done());
        assert_eq!(seen, [0, 1, 2, 4], "every readable frame, in order");
        assert_eq!(scan.rows, [0, 20, 40]);
        assert_eq!(scan.errors, 1);
        assert_eq!(src.cached(), 0, "the scan leaves the cache alone");
    }

    #[test]
    fn a_scan_with_no_time_left_reads_nothing_and_goes_on_where_it_stopped() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut src = Source::files(frames(dir.path(), 3, &[])).expect("source");
        let mut scan = StreamScan::new(src.len());
        scan.scan(&mut src, Duration::ZERO, |i, _| Some(i));
        assert_eq!((scan.next, scan.rows.len()), (0, 0));
        scan.scan(&mut src, Duration::from_secs(60), |i, _| Some(i));
        assert_eq!(scan.rows, [0, 1, 2]);
        assert!(scan.done());
    }
}
