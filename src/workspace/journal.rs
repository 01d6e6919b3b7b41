//! The edit journal kept beside a lookup table: every committed edit, undo and redo, one JSON
//! object a line in `TABLE.journal.jsonl` (e.g. `ball.lut.journal.jsonl`).
//!
//! It survives restarts and crashes: replaying it onto the table it started from (an empty
//! table, or the copy saved as `TABLE.journal-base` when the journal began on a non-empty
//! table) rebuilds the table and its undo history. Lines are appended and synced one at a time,
//! so a crash loses at most the line being written; a torn last line is skipped with a warning.
//! No egui here: the journal is plain data so tests can replay it.

use std::io::Write as _;
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
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("{}: cannot open the edit journal", path.display()))?;
    file.write_all(lines.as_bytes())
        .and_then(|()| file.sync_data())
        .with_context(|| format!("{}: cannot write the edit journal", path.display()))
}

/// What replaying a journal gives.
#[derive(Debug)]
pub struct Replay {
    /// The rebuilt table.
    pub table: LookupTable,
    /// Its undo/redo history, as if the edits had been made in this session.
    pub history: EditHistory,
    /// Commits replayed.
    pub commits: usize,
    /// Lines skipped (torn or unknown), with the reason.
    pub warnings: Vec<String>,
}

/// Reads the journal of `table` and replays it onto its starting table.
///
/// # Errors
/// The journal cannot be read, has no start line, or its base copy is missing or not a table.
pub fn replay(table: &Path) -> anyhow::Result<Replay> {
    let path = journal_path(table);
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("{}: cannot read the edit journal", path.display()))?;
    let mut warnings = Vec::new();
    let mut entries = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<JournalEntry>(line) {
            Ok(e) => entries.push(e),
            Err(e) => warnings.push(format!("{} line {}: skipped ({e})", path.display(), n + 1)),
        }
    }
    let Some(JournalEntry::Start { bits, base, .. }) = entries.first().cloned() else {
        anyhow::bail!("{}: the journal has no start line", path.display());
    };
    let mut lut = if base {
        LookupTable::load(&base_path(table))?
    } else {
        LookupTable::new(bits).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?
    };
    anyhow::ensure!(
        lut.bits() == bits,
        "{}: the base table has {} bits, the journal says {bits}",
        path.display(),
        lut.bits()
    );
    let mut history = EditHistory::default();
    let mut commits = 0;
    for e in entries.into_iter().skip(1) {
        match e {
            JournalEntry::Commit { record } => {
                history.commit(&mut lut, record);
                commits += 1;
            }
            JournalEntry::Undo { .. } => {
                history.undo(&mut lut);
            }
            JournalEntry::Redo { .. } => {
                history.redo(&mut lut);
            }
            JournalEntry::Start { .. } => {
                warnings.push(format!("{}: a second start line, ignored", path.display()));
            }
        }
    }
    Ok(Replay {
        table: lut,
        history,
        commits,
        warnings,
    })
}
