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
#[must_use]
pub fn replay_onto(
    lut: &mut LookupTable,
    entries: impl IntoIterator<Item = JournalEntry>,
    name: &str,
) -> Replayed {
    let mut history = EditHistory::default();
    let (mut commits, mut warnings) = (0, Vec::new());
    for e in entries {
        match e {
            JournalEntry::Commit { record } => {
                history.commit(lut, record);
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

    #[test]
    fn torn_lines_are_skipped_with_their_line_number() {
        let text = "{\"event\":\"start\",\"bits\":6,\"base\":false,\"time_unix_ms\":0}\n\n{\"event\":\"undo\",\"ti";
        let (entries, warnings) = parse(text, "j");
        assert_eq!(entries.len(), 1);
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].starts_with("j line 3: skipped"), "{warnings:?}");
    }
}
