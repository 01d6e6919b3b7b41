//! "Why is this pixel that class?": which edit of the history (the journal, replayed when the
//! table was opened) last wrote the pixel's table cell, or that the cell is as the table was
//! loaded.
//!
//! An edit writes its class into every cell of its region, so the newest edit whose region holds
//! the cell decided its code; undone edits are not in the undo stack and do not count.

use crate::frame::Yuv;
use crate::lut::{ColourClass, EditHistory, LookupTable, Region, SampleAt, Sensitivity};

/// Who set a table cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellOrigin {
    /// No remembered edit touched it: its code is the table's as loaded (or from an edit older
    /// than the history keeps).
    AsLoaded,
    /// An edit of the history.
    Edit(EditOrigin),
}

/// The edit that last wrote a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EditOrigin {
    /// Its place in the history, 1 = the oldest edit that can be undone.
    pub number: usize,
    /// The class it wrote.
    pub class: ColourClass,
    /// When it was made, milliseconds since the Unix epoch (0 when unknown).
    pub time_unix_ms: u64,
    /// The sample colour and reach, for an edit around a sample pixel.
    pub sample: Option<(Yuv, Sensitivity)>,
    /// The frame and pixel sampled, when recorded.
    pub sampled_at: Option<SampleAt>,
    /// Cells picked one by one, for an edit of explicit cells (U–V plane, coverage hints).
    pub picked_cells: Option<usize>,
}

/// The origin of the cell at `index` of `lut` given its edit history.
#[must_use]
pub fn cell_origin(history: &EditHistory, lut: &LookupTable, index: usize) -> CellOrigin {
    let edits: Vec<_> = history.undo_stack().collect();
    for (i, e) in edits.iter().enumerate().rev() {
        let r = &e.record;
        if !r.region.contains_index(lut, index) {
            continue;
        }
        let (sample, picked_cells) = match &r.region {
            Region::AroundSample {
                sample,
                sensitivity,
            } => (Some((*sample, *sensitivity)), None),
            Region::Cells { indices } => (None, Some(indices.len())),
        };
        return CellOrigin::Edit(EditOrigin {
            number: i + 1,
            class: r.class,
            time_unix_ms: r.time_unix_ms,
            sample,
            sampled_at: r.sampled_at,
            picked_cells,
        });
    }
    CellOrigin::AsLoaded
}

impl std::fmt::Display for CellOrigin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Self::Edit(e) = self else {
            return f.write_str("cell as the table was loaded");
        };
        write!(f, "edit {}: {}", e.number, e.class.name())?;
        if let Some(at) = e.sampled_at {
            write!(f, " from frame {} pixel ({}, {})", at.frame, at.x, at.y)?;
        }
        if let Some((yuv, s)) = e.sample {
            write!(
                f,
                " sample YUV {} {} {} ± {}/{}/{}",
                yuv.y, yuv.u, yuv.v, s.y, s.u, s.v
            )?;
        }
        if let Some(n) = e.picked_cells {
            write!(f, " ({n} cells picked)")?;
        }
        if e.time_unix_ms > 0 {
            write!(f, " at {}", utc_time(e.time_unix_ms))?;
        }
        Ok(())
    }
}

/// `YYYY-MM-DD hh:mm:ss UTC` from milliseconds since the Unix epoch (civil-from-days, Howard
/// Hinnant's algorithm), so the readout needs no time-zone crate.
#[must_use]
pub fn utc_time(unix_ms: u64) -> String {
    let secs = unix_ms / 1000;
    let (days, rem) = (secs / 86_400, secs % 86_400);
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02} {:02}:{:02}:{:02} UTC",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lut::EditRecord;

    #[test]
    fn the_newest_edit_holding_the_cell_wins_and_undo_forgets_it() {
        let mut lut = LookupTable::new(7).expect("table");
        let mut history = EditHistory::default();
        let p = Yuv::new(120, 60, 200);
        let index = lut.index(p);
        assert_eq!(cell_origin(&history, &lut, index), CellOrigin::AsLoaded);
        let mut first = EditRecord::now(
            ColourClass::Orange,
            Region::AroundSample {
                sample: p,
                sensitivity: Sensitivity::uniform(1),
            },
        );
        first.sampled_at = Some(SampleAt {
            frame: 7,
            x: 30,
            y: 40,
        });
        history.commit(&mut lut, first);
        // A second edit elsewhere does not touch the cell.
        history.commit(
            &mut lut,
            EditRecord::now(
                ColourClass::Green,
                Region::Cells {
                    indices: vec![index + 1000],
                },
            ),
        );
        let CellOrigin::Edit(e) = cell_origin(&history, &lut, index) else {
            panic!("the orange edit set the cell");
        };
        assert_eq!((e.number, e.class), (1, ColourClass::Orange));
        assert_eq!(e.sampled_at.map(|s| s.frame), Some(7));
        let text = cell_origin(&history, &lut, index).to_string();
        assert!(
            text.contains("orange from frame 7 pixel (30, 40)"),
            "{text}"
        );
        // A third edit over it wins; undoing it gives the first back.
        history.commit(
            &mut lut,
            EditRecord::now(
                ColourClass::Yellow,
                Region::Cells {
                    indices: vec![index],
                },
            ),
        );
        assert!(matches!(
            cell_origin(&history, &lut, index),
            CellOrigin::Edit(EditOrigin {
                number: 3,
                class: ColourClass::Yellow,
                ..
            })
        ));
        history.undo(&mut lut);
        assert!(matches!(
            cell_origin(&history, &lut, index),
            CellOrigin::Edit(EditOrigin { number: 1, .. })
        ));
    }

    #[test]
    fn utc_time_of_known_instants() {
        assert_eq!(utc_time(0), "1970-01-01 00:00:00 UTC");
        // 2026-12-03 08:00:00 UTC.
        assert_eq!(utc_time(1_796_284_800_000), "2026-12-03 08:00:00 UTC");
        assert_eq!(utc_time(951_782_400_000), "2000-02-29 00:00:00 UTC");
    }
}
