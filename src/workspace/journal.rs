//! The edit journal kept beside a lookup table: every committed edit, undo and redo, one JSON
//! object a line in `TABLE.journal.jsonl` (e.g. `ball.lut.journal.jsonl`).
//!
//! It survives restarts and crashes: replaying it onto the table it started from (an empty
//! table, or the copy saved as `TABLE.journal-base` when the journal began on a non-empty
//! table) rebuilds the table and its undo history. Lines are appended and synced one at a time,
//! so a crash loses at most the line being written; a torn last line is skipped with a warning.
//! No egui here: the journal is plain data so tests can replay it.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use serde::{Deserialize, Serialize};

use crate::lut::{EditHistory, EditRecord, LookupTable};

/// One line of the journal.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum JournalEntry {
    /// The journal began; `base` says whether a base copy of the table was saved beside it.
    Start {
        /// Bits per channel of the table.
        bits: u8,
        /// True when the journal began on a non-empty table, saved as the base file.
        base: bool,
        /// Milliseconds since the Unix epoch.
        time_unix_ms: u64,
    },
    /// An edit was committed (class, region with sample and sensitivity, time).
    Commit {
        /// The edit.
        record: EditRecord,
    },
    /// The latest edit was undone.
    Undo {
        /// Milliseconds since the Unix epoch.
        time_unix_ms: u64,
    },
    /// The latest undone edit was redone.
    Redo {
        /// Milliseconds since the Unix epoch.
        time_unix_ms: u64,
    },
}

pub use crate::lut::edit::now_unix_ms;

/// The journal file of a table: the table's file name with `.journal.jsonl` appended.
#[must_use]
pub fn journal_path(table: &Path) -> PathBuf {
    let mut name = table.as_os_str().to_owned();
    name.push(".journal.jsonl");
    PathBuf::from(name)
}

/// The base copy of a table whose journal began when it was not empty.
#[must_use]
pub fn base_path(table: &Path) -> PathBuf {
    let mut name = table.as_os_str().to_owned();
    name.push(".journal-base");
    PathBuf::from(name)
}

/// Appends entries to the journal of `table`, starting it (and saving the base copy of
/// `start_table` when that is not empty) if it does not exist yet.
///
/// # Errors
/// Writing fails; the message names the file.
pub fn append(
    table: &Path,
    start_table: &LookupTable,
    entries: &[JournalEntry],
) -> anyhow::Result<()> {
    let path = journal_path(table);
    let mut lines = String::new();
    if !path.exists() {
        let empty = start_table.cells().iter().all(|&c| c == 0);
        if !empty {
            start_table.save(&base_path(table))?;
        }
        let start = JournalEntry::Start {
            bits: start_table.bits(),
            base: !empty,
            time_unix_ms: now_unix_ms(),
        };
        lines.push_str(&serde_json::to_string(&start)?);
        lines.push('\n');
    }
    for e in entries {
        lines.push_str(&serde_json::to_string(e)?);
        lines.push('\n');
    }
    crate::atomic_file::append_synced(&path, lines.as_bytes())
        .with_context(|| format!("{}: cannot write the edit journal", path.display()))
}

/// Makes the journal of `from` (with its base copy, when it has one) the journal of `to`, so
/// a table saved under another name keeps its whole record.
///
/// # Errors
/// Reading the journal or its base, or writing the copies; the messages name the files.
pub fn copy(from: &Path, to: &Path) -> anyhow::Result<()> {
    let source = journal_path(from);
    let text = crate::input_file::read_text_bounded(
        &source,
        crate::input_file::MAX_SIDE_FILE_BYTES,
        "an edit journal",
    )
    .with_context(|| format!("{}: cannot read the edit journal", source.display()))?;
    let base = base_path(from);
    if base.exists() {
        LookupTable::load(&base)?.save(&base_path(to))?;
    }
    let target = journal_path(to);
    crate::atomic_file::write_atomic(&target, text.as_bytes())
        .with_context(|| format!("{}: cannot write the edit journal", target.display()))
}

/// What replaying a journal gives.
#[derive(Debug)]
pub struct Replay {
    /// The rebuilt table.
    pub table: LookupTable,
    /// Its undo/redo history, as if the edits had been made in this session (bounded by
    /// [`crate::lut::edit::MAX_HISTORY_BYTES`]: the oldest steps of a long journal are not
    /// kept, see [`EditHistory::dropped`]).
    pub history: EditHistory,
    /// Commits replayed.
    pub commits: usize,
    /// Lines skipped (torn or unknown), with the reason; a note when old undo steps were
    /// dropped.
    pub warnings: Vec<String>,
}

/// Parses a journal's text into entries; lines that are not entries are skipped, each with a
/// warning naming `name` and the line number.
#[must_use]
pub fn parse(text: &str, name: &str) -> (Vec<JournalEntry>, Vec<String>) {
    let mut warnings = Vec::new();
    let mut entries = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<JournalEntry>(line) {
            Ok(e) => entries.push(e),
            Err(e) => warnings.push(format!("{name} line {}: skipped ({e})", n + 1)),
        }
    }
    (entries, warnings)
}

/// What [`replay_onto`] gives: the history, commits replayed and warnings.
#[derive(Debug)]
pub struct Replayed {
    /// The undo/redo history rebuilt.
    pub history: EditHistory,
    /// Commits replayed.
    pub commits: usize,
    /// A second start line, old undo steps dropped: each said once, naming `name`.
    pub warnings: Vec<String>,
}

/// Replays journal entries (after the start line) onto `lut`, rebuilding the undo history.
///
/// A journal whose oldest edits the history's bound drops is replayed from its last whole-table
/// edit that the bound surely drops (`settled_start`): the table after that edit is the same
/// whatever came before it, and nothing before it can be undone, so the edits before it are
/// counted as dropped without being applied (40 whole-table edits of an 8-bit table: 17 passes
/// over the table instead of 40).
#[must_use]
pub fn replay_onto(
    lut: &mut LookupTable,
    entries: impl IntoIterator<Item = JournalEntry>,
    name: &str,
) -> Replayed {
    replay_bounded(
        lut,
        entries.into_iter().collect(),
        name,
        EditHistory::default(),
    )
}

/// [`replay_onto`] into `history` (empty, with its bound).
fn replay_bounded(
    lut: &mut LookupTable,
    entries: Vec<JournalEntry>,
    name: &str,
    history: EditHistory,
) -> Replayed {
    let start = settled_start(lut, &entries, history.max_bytes()).unwrap_or(0);
    if start == 0 {
        return replay_from(lut, &entries, 0, name, history);
    }
    let before = lut.clone();
    let fresh = EditHistory::new(history.max_bytes());
    let replayed = replay_from(lut, &entries, start, name, history);
    // The edit replay began with was dropped, so nothing applied before it mattered. Were it
    // kept (the bound's arithmetic and `settled_start` disagreeing), replay it all.
    if replayed.history.dropped() > start {
        return replayed;
    }
    *lut = before;
    replay_from(lut, &entries, 0, name, fresh)
}

/// Replays `entries[start..]` into `history`; the `start` entries before, all commits, are
/// counted as commits and as dropped steps.
fn replay_from(
    lut: &mut LookupTable,
    entries: &[JournalEntry],
    start: usize,
    name: &str,
    mut history: EditHistory,
) -> Replayed {
    history.note_dropped(start);
    let (mut commits, mut warnings) = (start, Vec::new());
    for e in entries.iter().skip(start) {
        match e {
            JournalEntry::Commit { record } => {
                history.commit(lut, record.clone());
                commits += 1;
            }
            JournalEntry::Undo { .. } => {
                history.undo(lut);
            }
            JournalEntry::Redo { .. } => {
                history.redo(lut);
            }
            JournalEntry::Start { .. } => {
                warnings.push(format!("{name}: a second start line, ignored"));
            }
        }
    }
    if history.dropped() > 0 {
        warnings.push(format!(
            "{name}: the oldest {} edits cannot be undone (the undo history keeps at most {} MiB); the journal keeps them",
            history.dropped(),
            crate::lut::edit::MAX_HISTORY_BYTES >> 20
        ));
    }
    Replayed {
        history,
        commits,
        warnings,
    }
}

/// Where a replay may begin: the last commit that writes the whole table, when every entry
/// before it is a commit (so all of them are dropped before it, none undone) and the undo
/// history bounded by `max_bytes` surely drops it. `None` when there is none.
fn settled_start(lut: &LookupTable, entries: &[JournalEntry], max_bytes: usize) -> Option<usize> {
    let commits_first = entries
        .iter()
        .position(|e| !matches!(e, JournalEntry::Commit { .. }))
        .unwrap_or(entries.len());
    (1..commits_first).rev().find(|&j| {
        matches!(&entries[j], JournalEntry::Commit { record } if record.covers_table(lut))
            && surely_dropped(lut, entries, j, max_bytes)
    })
}

/// Whether the step of the commit `entries[j]` is dropped by a history bounded by `max_bytes`
/// before anything undoes it, whatever the steps before it held: the steps after it are
/// followed with the fewest bytes each can hold ([`EditRecord::least_held_bytes`]); a history
/// drops its oldest steps first, so once the steps from `j` on hold more than the bound with
/// one above `j`'s, everything before it and then `j`'s step go. An undo that would reach
/// `j`'s step first gives `false`.
fn surely_dropped(lut: &LookupTable, entries: &[JournalEntry], j: usize, max_bytes: usize) -> bool {
    let Some(JournalEntry::Commit { record }) = entries.get(j) else {
        return false;
    };
    let mut bytes = record.least_held_bytes(lut);
    // The fewest bytes of each undo step above `j`'s, and of each redo step.
    let (mut above, mut redo) = (Vec::new(), Vec::<usize>::new());
    for e in &entries[j + 1..] {
        match e {
            JournalEntry::Commit { record } => {
                bytes -= redo.drain(..).sum::<usize>();
                let b = record.least_held_bytes(lut);
                above.push(b);
                bytes += b;
            }
            JournalEntry::Undo { .. } => match above.pop() {
                Some(b) => redo.push(b),
                None => return false,
            },
            JournalEntry::Redo { .. } => {
                if let Some(b) = redo.pop() {
                    above.push(b);
                }
            }
            JournalEntry::Start { .. } => {}
        }
        if bytes > max_bytes && !above.is_empty() {
            return true;
        }
    }
    false
}

/// Reads the journal of `table` and replays it onto its starting table.
///
/// # Errors
/// The journal cannot be read (also: not a regular file, over
/// [`crate::input_file::MAX_SIDE_FILE_BYTES`]), has no start line, or its base copy is missing
/// or not a table.
pub fn replay(table: &Path) -> anyhow::Result<Replay> {
    let path = journal_path(table);
    let text = crate::input_file::read_text_bounded(
        &path,
        crate::input_file::MAX_SIDE_FILE_BYTES,
        "an edit journal",
    )
    .with_context(|| format!("{}: cannot read the edit journal", path.display()))?;
    let name = path.display().to_string();
    let (entries, mut warnings) = parse(&text, &name);
    let Some(JournalEntry::Start { bits, base, .. }) = entries.first().cloned() else {
        anyhow::bail!("{name}: the journal has no start line");
    };
    let mut lut = if base {
        LookupTable::load(&base_path(table))?
    } else {
        LookupTable::new(bits).map_err(|e| anyhow::anyhow!("{name}: {e}"))?
    };
    anyhow::ensure!(
        lut.bits() == bits,
        "{name}: the base table has {} bits, the journal says {bits}",
        lut.bits()
    );
    let replayed = replay_onto(&mut lut, entries.into_iter().skip(1), &name);
    warnings.extend(replayed.warnings);
    Ok(Replay {
        table: lut,
        history: replayed.history,
        commits: replayed.commits,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;
    use crate::lut::edit::MAX_HISTORY_BYTES;
    use crate::lut::{ColourClass, Region, Sensitivity};

    fn whole_table(class: ColourClass) -> JournalEntry {
        JournalEntry::Commit {
            record: EditRecord {
                class,
                region: Region::AroundSample {
                    sample: Yuv::new(128, 128, 128),
                    sensitivity: Sensitivity::uniform(255),
                },
                time_unix_ms: 0,
                sampled_at: None,
            },
        }
    }

    #[test]
    fn a_journal_of_whole_table_edits_keeps_the_undo_history_within_its_bound() {
        // 40 whole-table edits of an 8-bit table: 16 MiB of old codes each, 640 MiB unbounded
        // (and 5.5 GB when each changed cell was an (index, code) pair).
        let dir = tempfile::tempdir().expect("tempdir");
        let table = dir.path().join("t.lut");
        let mut text = serde_json::to_string(&JournalEntry::Start {
            bits: 8,
            base: false,
            time_unix_ms: 0,
        })
        .expect("json");
        let classes = [ColourClass::Orange, ColourClass::Green];
        for i in 0..40 {
            text.push('\n');
            text.push_str(&serde_json::to_string(&whole_table(classes[i % 2])).expect("json"));
        }
        std::fs::write(journal_path(&table), text).expect("write");
        let r = replay(&table).expect("replays");
        assert_eq!(r.commits, 40);
        assert!(
            r.history.held_bytes() <= MAX_HISTORY_BYTES,
            "{}",
            r.history.held_bytes()
        );
        assert!(r.history.undo_len() >= 2, "{}", r.history.undo_len());
        assert_eq!(r.history.undo_len() + r.history.dropped(), 40);
        let note = r.warnings.join("\n");
        assert!(note.contains("edits cannot be undone"), "{note}");
        // The table is the last edit's, whatever was dropped.
        assert_eq!(
            r.table.class_counts()[ColourClass::Green.code() as usize],
            r.table.cells().len()
        );
    }

    fn small_edit(class: ColourClass, i: u8) -> JournalEntry {
        JournalEntry::Commit {
            record: EditRecord {
                class,
                region: Region::AroundSample {
                    sample: Yuv::new(i.wrapping_mul(37), i.wrapping_mul(11), 200),
                    sensitivity: Sensitivity::uniform(2),
                },
                time_unix_ms: 0,
                sampled_at: None,
            },
        }
    }

    fn picked(class: ColourClass, first: usize) -> JournalEntry {
        JournalEntry::Commit {
            record: EditRecord {
                class,
                region: Region::Cells {
                    indices: vec![first, first + 1, first + 4096],
                },
                time_unix_ms: 0,
                sampled_at: None,
            },
        }
    }

    /// Replays `entries` onto a fresh 6-bit table both ways (from the start, and from where
    /// `settled_start` says) with a history of `max_bytes`, and holds the two to the same
    /// table, steps, bytes and drops, and the same tables after every undo and redo that
    /// follows. Returns where the fast replay began.
    fn assert_replays_alike(entries: &[JournalEntry], max_bytes: usize) -> usize {
        let base = LookupTable::new(6).expect("6 bits");
        let (mut full_lut, mut fast_lut) = (base.clone(), base.clone());
        let full = replay_from(&mut full_lut, entries, 0, "j", EditHistory::new(max_bytes));
        let fast = replay_bounded(
            &mut fast_lut,
            entries.to_vec(),
            "j",
            EditHistory::new(max_bytes),
        );
        let start = settled_start(&base, entries, max_bytes).unwrap_or(0);
        let (mut a, mut b) = (full.history, fast.history);
        assert!(full_lut == fast_lut, "tables differ (start {start})");
        assert_eq!(
            (
                a.undo_len(),
                a.redo_len(),
                a.dropped(),
                a.held_bytes(),
                full.commits
            ),
            (
                b.undo_len(),
                b.redo_len(),
                b.dropped(),
                b.held_bytes(),
                fast.commits
            ),
            "start {start}"
        );
        assert_eq!(full.warnings, fast.warnings);
        while a.undo(&mut full_lut).is_some() {
            assert!(b.undo(&mut fast_lut).is_some());
            assert!(full_lut == fast_lut, "after an undo (start {start})");
        }
        assert!(b.undo(&mut fast_lut).is_none());
        while a.redo(&mut full_lut).is_some() {
            assert!(b.redo(&mut fast_lut).is_some());
            assert!(full_lut == fast_lut, "after a redo (start {start})");
        }
        start
    }

    #[test]
    fn replaying_from_the_last_dropped_whole_table_edit_gives_what_replaying_all_gives() {
        use ColourClass::{Green, Orange, White, Yellow};
        // A 6-bit table's whole-table step holds 256 KiB: a 1 MiB history keeps three of them.
        let bound = 1 << 20;
        let wholes = |n: usize| -> Vec<JournalEntry> {
            (0..n)
                .map(|i| whole_table([Orange, Green, Yellow][i % 3]))
                .collect()
        };
        // Only whole-table edits: begun at the eighth of twelve, the rest counted as dropped.
        let start = assert_replays_alike(&wholes(12), bound);
        assert!(start >= 7, "{start}");
        // Small edits, picked cells, undos and redos after them, and more whole-table edits.
        let mut mixed = wholes(8);
        mixed.extend([small_edit(White, 1), picked(Yellow, 77)]);
        mixed.extend([
            JournalEntry::Undo { time_unix_ms: 0 },
            small_edit(Orange, 2),
        ]);
        mixed.extend(wholes(2));
        mixed.extend([
            JournalEntry::Undo { time_unix_ms: 0 },
            JournalEntry::Undo { time_unix_ms: 0 },
            JournalEntry::Redo { time_unix_ms: 0 },
            picked(Green, 9000),
        ]);
        assert!(assert_replays_alike(&mixed, bound) > 0);
        // Undone far enough to reach every whole-table edit the bound keeps: the replay
        // begins earlier (or at the start) and still gives the same.
        let mut undone = wholes(9);
        undone.extend((0..7).map(|_| JournalEntry::Undo { time_unix_ms: 0 }));
        assert_replays_alike(&undone, bound);
        // An undo line before the whole-table edits: replayed from the start.
        let mut early_undo = vec![small_edit(White, 3), JournalEntry::Undo { time_unix_ms: 0 }];
        early_undo.extend(wholes(10));
        assert_eq!(assert_replays_alike(&early_undo, bound), 0);
        // Nothing dropped: from the start.
        assert_eq!(assert_replays_alike(&wholes(3), bound), 0);
    }

    #[test]
    fn torn_lines_are_skipped_with_their_line_number() {
        let text = "{\"event\":\"start\",\"bits\":6,\"base\":false,\"time_unix_ms\":0}\n\n{\"event\":\"undo\",\"ti";
        let (entries, warnings) = parse(text, "j");
        assert_eq!(entries.len(), 1);
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].starts_with("j line 3: skipped"), "{warnings:?}");
    }
}
