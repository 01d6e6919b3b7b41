//! The lookup table side of the workspace: opening, saving, the edit history and its journal,
//! the pending selection and its commit, the places file.

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use super::journal::{self, JournalEntry, now_unix_ms};
use super::{PendingSelection, SelectionClass, TableCommand, TryEdit, Workspace};
use crate::frame::Yuv;
use crate::lut::{ColourClass, EditRecord, LookupTable, Region, Sensitivity};
use crate::sources::CameraKind;

/// Why a commit or try of a coverage hint's colours is refused before a class is chosen.
const UNCHOSEN_CLASS: &str = "choose the class of these colours first: Commit as… in the Coverage window, or a class in the Classify panel";

impl Workspace {
    /// Applies the table's commands: new, save, the journal, the class and sensitivity, the
    /// pending selection, commit, undo and redo, the whole-stream try (the rest of
    /// [`Workspace::apply`]).
    pub(super) fn apply_table_edit(&mut self, command: TableCommand) -> anyhow::Result<()> {
        match command {
            TableCommand::NewTable(bits) => self.new_table(bits)?,
            TableCommand::SaveTable => {
                let path = self
                    .table_path
                    .clone()
                    .context("the table has no file yet: use Save table as…")?;
                self.save_table(&path)?;
            }
            TableCommand::SaveTableAs(p) => self.save_table(&p)?,
            TableCommand::RebuildFromJournal => self.rebuild_from_journal()?,
            TableCommand::DiscardUnsaved => self.discard_unsaved()?,
            TableCommand::SetClass(c) => {
                self.settings.class = c;
                // A class picked while a coverage hint's colours are pending is their class.
                if let Some(sel) = self.selection.as_mut()
                    && sel.class != SelectionClass::Current
                {
                    sel.class = SelectionClass::Chosen(c);
                }
                // A class chosen means classifying: a left click samples again.
                self.disarm_landmark_picking();
                // The preview tells pixels already of the class from those a commit changes.
                self.preview_generation += 1;
            }
            TableCommand::SetSensitivity(s) => self.set_sensitivity(s),
            TableCommand::AdjustSensitivity { channel, delta } => {
                self.adjust_sensitivity(channel, delta)?;
            }
            TableCommand::Sample { x, y } => self.sample(x, y)?,
            TableCommand::SampleCell(cell) => self.sample_cell(cell)?,
            TableCommand::ClearSelection => {
                self.selection = None;
                self.refresh_preview();
            }
            TableCommand::RestoreSelection(s) => {
                self.selection = s;
                self.refresh_preview();
            }
            TableCommand::Commit => self.commit()?,
            TableCommand::Undo => self.undo()?,
            TableCommand::Redo => self.redo()?,
            TableCommand::TryEditOnStream => self.try_edit_on_stream()?,
        }
        Ok(())
    }

    fn try_edit_on_stream(&mut self) -> anyhow::Result<()> {
        let sel = self
            .selection
            .clone()
            .context("no pending selection to try")?;
        let total = self.source.as_ref().context("no stream open")?.len();
        let class = self.selection_class().context(UNCHOSEN_CLASS)?;
        self.try_edit = Some(TryEdit::new(class, sel.region, self.pipeline.lut(), total));
        self.settings.show_try_edit = true;
        Ok(())
    }

    pub(super) fn open_table(&mut self, path: &Path) -> anyhow::Result<()> {
        let lut = LookupTable::load(path)?;
        self.set_table(lut, Some(path.to_owned()));
        self.remember_recent(path);
        self.remember_table(path);
        self.status = format!("opened table {}", path.display());
        if journal::journal_path(path).exists() {
            match journal::replay(path) {
                Ok(r) if &r.table == self.pipeline.lut() => {
                    for w in r.warnings {
                        self.warn(w);
                    }
                    let n = r.history.undo_len();
                    self.history = r.history;
                    self.saved_undo_len = Some(n);
                    self.status = format!("opened table {}; journal: {n} edits can be undone", path.display());
                }
                Ok(r) => self.warn(format!(
                    "{}: the table differs from its journal's replay ({} edits; unsaved edits before a crash?): Classification > Rebuild table from journal recovers them",
                    path.display(),
                    r.commits
                )),
                Err(e) => self.warn(format!("{e:#}")),
            }
        }
        Ok(())
    }

    pub(super) fn open_places(&mut self, path: &Path) -> anyhow::Result<()> {
        let memory = crate::recognition::patterns::PatternMemory::load(path)?;
        let (objects, relation) = (memory.objects.len(), memory.relation);
        self.pipeline.set_pattern_memory(Some(memory));
        self.places_path = Some(path.to_owned());
        self.remember_recent(path);
        self.settings.last_places =
            Some(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned()));
        self.reprocess();
        self.status = format!(
            "opened places {}: {objects} objects{}",
            path.display(),
            relation.map_or_else(
                || ", no size relation (no distances)".to_owned(),
                |r| format!(
                    ", distance = {:.0} / size + {:.1} cm",
                    r.multiplier_cm_px, r.offset_cm
                )
            )
        );
        Ok(())
    }

    fn set_table(&mut self, lut: LookupTable, path: Option<PathBuf>) {
        self.unsaved_journal = path.is_none().then(|| (lut.clone(), Vec::new()));
        self.pipeline.set_lut(lut);
        self.table_path = path;
        self.history.clear();
        self.dirty = false;
        self.saved_undo_len = Some(0);
        self.table_changed();
    }

    pub(super) fn save_table(&mut self, path: &Path) -> anyhow::Result<()> {
        let moved = self.table_path.as_deref() != Some(path);
        self.pipeline.lut().save(path)?;
        if moved && !journal::journal_path(path).exists() {
            // The journal follows the table. A table saved for the first time writes the edits
            // made since it was new (the journal then replays from its first commit); a table
            // saved under another name takes its journal along.
            let written = match self.unsaved_journal.take() {
                Some((start, entries)) => journal::append(path, &start, &entries),
                None => self.carry_journal(path),
            };
            if let Err(e) = written {
                self.warn(format!("{e:#}"));
            }
        }
        self.unsaved_journal = None;
        self.table_path = Some(path.to_owned());
        self.remember_table(path);
        self.remember_recent(path);
        self.dirty = false;
        self.saved_undo_len = Some(self.history.undo_len());
        self.status = format!("saved {}", path.display());
        Ok(())
    }

    /// The journal of a table saved under another name (`to`): the journal it had (with the
    /// base copy it starts from) when that replays to the table, so the new file still replays
    /// from its first edit (a seeded table opened, clicked on, then saved as the final name);
    /// otherwise a journal starting from the table as saved.
    fn carry_journal(&self, to: &Path) -> anyhow::Result<()> {
        if let Some(from) = self.table_path.as_deref()
            && journal::journal_path(from).exists()
            && journal::replay(from).is_ok_and(|r| &r.table == self.pipeline.lut())
        {
            return journal::copy(from, to);
        }
        journal::append(to, self.pipeline.lut(), &[])
    }

    fn journal(&mut self, entry: &JournalEntry) {
        let Some(path) = self.table_path.clone() else {
            if let Some((_, entries)) = self.unsaved_journal.as_mut() {
                entries.push(entry.clone());
            }
            return;
        };
        if let Err(e) = journal::append(&path, self.pipeline.lut(), std::slice::from_ref(entry)) {
            self.warn(format!("{e:#}"));
        }
    }

    pub(super) fn commit(&mut self) -> anyhow::Result<()> {
        let sel = self
            .selection
            .clone()
            .context("nothing selected: left-click a pixel first")?;
        let class = self.selection_class().context(UNCHOSEN_CLASS)?;
        let mut record = EditRecord::now(class, sel.region);
        record.sampled_at = sel.pixel.map(|(x, y)| crate::lut::SampleAt {
            frame: self.index,
            x,
            y,
        });
        // The journal must start from the table before its first edit.
        if let Some(path) = self.table_path.clone()
            && !journal::journal_path(&path).exists()
            && let Err(e) = journal::append(&path, self.pipeline.lut(), &[])
        {
            self.warn(format!("{e:#}"));
        }
        if self
            .saved_undo_len
            .is_some_and(|saved| self.history.undo_len() < saved)
        {
            // The saved state was undone and is now replaced: no undo leads back to it.
            self.saved_undo_len = None;
        }
        let dropped_before = self.history.dropped();
        let changed = self.history.commit(self.pipeline.lut_mut(), record.clone());
        self.note_dropped_steps(self.history.dropped() - dropped_before);
        self.journal(&JournalEntry::Commit { record });
        self.dirty = true;
        self.selection = None;
        self.table_changed();
        self.status = format!("{changed} cells set to {}", class.name());
        Ok(())
    }

    /// True when the whole-stream try shown is not for the pending selection (another
    /// region, sensitivity or class, or nothing pending): its rows are an earlier edit's.
    #[must_use]
    pub fn try_edit_stale(&self) -> bool {
        let Some(t) = &self.try_edit else {
            return false;
        };
        match &self.selection {
            Some(sel) => sel.region != t.region || self.selection_class() != Some(t.class),
            None => true,
        }
    }

    /// The class a commit of the pending selection writes: the selection's own (a coverage
    /// hint's, once chosen) or the Classify panel's; `None` with nothing pending or while a
    /// hint's class is not chosen.
    #[must_use]
    pub fn selection_class(&self) -> Option<ColourClass> {
        match self.selection.as_ref()?.class {
            SelectionClass::Current => Some(self.settings.class),
            SelectionClass::Chosen(c) => Some(c),
            SelectionClass::Unchosen => None,
        }
    }

    /// After `n` old undo steps were dropped to keep the history within its memory bound: the
    /// saved state is that many steps nearer (or out of reach), and the user is told once.
    fn note_dropped_steps(&mut self, n: usize) {
        if n == 0 {
            return;
        }
        self.saved_undo_len = self.saved_undo_len.and_then(|s| s.checked_sub(n));
        self.warn(format!(
            "the oldest {n} edit(s) can no longer be undone: the undo history keeps at most {} MiB (the journal keeps every edit)",
            crate::lut::edit::MAX_HISTORY_BYTES >> 20
        ));
    }

    pub(super) fn set_sensitivity(&mut self, s: Sensitivity) {
        let max = self.max_sensitivity();
        let s = Sensitivity {
            y: s.y.min(max),
            u: s.u.min(max),
            v: s.v.min(max),
        };
        self.settings.sensitivity = s;
        if let Some(PendingSelection {
            region: Region::AroundSample { sensitivity, .. },
            ..
        }) = &mut self.selection
        {
            *sensitivity = s;
            self.refresh_preview();
        }
    }

    pub(super) fn table_changed(&mut self) {
        self.table_generation += 1;
        self.table_counts = self.pipeline.lut().class_counts();
        self.try_edit = None;
        self.params.try_run = None;
        self.reprocess();
    }

    pub(super) fn close_places(&mut self) {
        self.pipeline.set_pattern_memory(None);
        self.places_path = None;
        self.settings.last_places = None;
        self.reprocess();
        self.status = "places file closed: pink markers are not identified".to_owned();
    }

    pub(super) fn new_table(&mut self, bits: u8) -> anyhow::Result<()> {
        let lut = LookupTable::new(bits).map_err(|e| anyhow::anyhow!("new table: {e}"))?;
        self.set_table(lut, None);
        self.settings.new_table_bits = bits;
        self.status = format!("new empty {bits}-bit table");
        Ok(())
    }

    pub(super) fn rebuild_from_journal(&mut self) -> anyhow::Result<()> {
        let path = self.table_path.clone().context("the table has no file")?;
        let r = journal::replay(&path)?;
        for w in r.warnings {
            self.warn(w);
        }
        self.pipeline.set_lut(r.table);
        self.history = r.history;
        self.saved_undo_len = None;
        self.dirty = true;
        self.table_changed();
        self.status = format!("rebuilt from the journal: {} edits replayed", r.commits);
        Ok(())
    }

    /// See [`super::TableCommand::DiscardUnsaved`]. Where undoing cannot reach the saved table (it
    /// was undone and then replaced by new edits) the journal is left as it is.
    pub(super) fn discard_unsaved(&mut self) -> anyhow::Result<()> {
        if !self.dirty {
            return Ok(());
        }
        let saved = self
            .saved_undo_len
            .context("the saved table cannot be reached by undoing: the journal keeps the edits")?;
        while self.history.undo_len() > saved {
            self.undo()?;
        }
        while self.history.undo_len() < saved && self.history.redo_len() > 0 {
            self.redo()?;
        }
        self.dirty = false;
        self.status = "unsaved edits dropped (they can be redone)".to_owned();
        Ok(())
    }

    pub(super) fn undo(&mut self) -> anyhow::Result<()> {
        let record = self
            .history
            .undo(self.pipeline.lut_mut())
            .cloned()
            .context("nothing to undo")?;
        self.journal(&JournalEntry::Undo {
            time_unix_ms: now_unix_ms(),
        });
        self.dirty = true;
        self.table_changed();
        self.status = format!("undid {} edit", record.class.name());
        Ok(())
    }

    pub(super) fn redo(&mut self) -> anyhow::Result<()> {
        let record = self
            .history
            .redo(self.pipeline.lut_mut())
            .cloned()
            .context("nothing to redo")?;
        self.journal(&JournalEntry::Redo {
            time_unix_ms: now_unix_ms(),
        });
        self.dirty = true;
        self.table_changed();
        self.status = format!("redid {} edit", record.class.name());
        Ok(())
    }

    pub(super) fn adjust_sensitivity(&mut self, channel: usize, delta: i32) -> anyhow::Result<()> {
        let mut s = self.settings.sensitivity;
        let slot = match channel {
            0 => &mut s.y,
            1 => &mut s.u,
            2 => &mut s.v,
            _ => anyhow::bail!("channel {channel} is not 0 (Y), 1 (U) or 2 (V)"),
        };
        let max = i32::from(self.max_sensitivity());
        *slot = u8::try_from((i32::from(*slot) + delta).clamp(0, max)).unwrap_or(0);
        self.set_sensitivity(s);
        Ok(())
    }

    pub(super) fn sample(&mut self, x: usize, y: usize) -> anyhow::Result<()> {
        let frame = self.frame().context("no frame to sample")?;
        let sample = frame
            .pixel(x, y)
            .with_context(|| format!("({x}, {y}) is outside the frame"))?;
        self.selection = Some(PendingSelection {
            region: Region::AroundSample {
                sample,
                sensitivity: self.settings.sensitivity,
            },
            pixel: Some((x, y)),
            class: SelectionClass::Current,
        });
        self.refresh_preview();
        Ok(())
    }

    /// Pixels of the shown frame the pending selection selects, and of those the ones whose
    /// class a commit would change (the others already have the class): the second is what
    /// Try edit counts for this frame. The classification compared is the shown frame's, from
    /// whichever pipeline ran (an overhead frame's is not the robot pipeline's).
    #[must_use]
    pub fn selection_pixel_counts(&self) -> (usize, usize) {
        self.preview_pixels().fold((0, 0), |(sel, chg), p| match p {
            super::compose::PreviewPixel::Outside => (sel, chg),
            super::compose::PreviewPixel::Unchanged => (sel + 1, chg),
            super::compose::PreviewPixel::Changes => (sel + 1, chg + 1),
        })
    }

    pub(super) fn sample_cell(&mut self, cell: [usize; 3]) -> anyhow::Result<()> {
        let lut = self.pipeline.lut();
        anyhow::ensure!(
            cell.iter().all(|&c| c < lut.side()),
            "cell {cell:?} is outside the {}-bit table",
            lut.bits()
        );
        let shift = lut.shift();
        let half = (1usize << shift) / 2;
        let v = cell.map(|c| u8::try_from((c << shift) + half).unwrap_or(255));
        self.selection = Some(PendingSelection {
            region: Region::AroundSample {
                sample: Yuv::new(v[0], v[1], v[2]),
                sensitivity: self.settings.sensitivity,
            },
            pixel: None,
            class: SelectionClass::Current,
        });
        self.refresh_preview();
        Ok(())
    }
}

/// The lookup table not in use: the robot camera's while an overhead source is shown, and the
/// other way round. Both cameras see colours differently, so each keeps its own table, file,
/// undo history and unsaved mark.
#[derive(Debug)]
pub struct TableSlot {
    pub(super) lut: LookupTable,
    pub(super) path: Option<PathBuf>,
    pub(super) history: crate::lut::EditHistory,
    pub(super) dirty: bool,
    pub(super) saved_undo_len: Option<usize>,
    /// The journal of a table without a file (see `Workspace::unsaved_journal`).
    pub(super) unsaved_journal: Option<(LookupTable, Vec<JournalEntry>)>,
}

impl TableSlot {
    /// An empty table of `bits` per channel, without a file.
    pub(super) fn empty(bits: u8) -> Self {
        let lut = LookupTable::new(bits).unwrap_or_else(|_| super::seven_bit_table());
        Self {
            unsaved_journal: Some((lut.clone(), Vec::new())),
            lut,
            path: None,
            history: crate::lut::EditHistory::default(),
            dirty: false,
            saved_undo_len: Some(0),
        }
    }

    /// Its file, if it has one.
    #[must_use]
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// True when it has edits not yet saved.
    #[must_use]
    pub const fn dirty(&self) -> bool {
        self.dirty
    }
}

impl Workspace {
    /// Makes the table of camera `kind` the one in use (the other is kept as it is).
    pub(super) fn use_table_of(&mut self, kind: CameraKind) {
        if kind == self.table_kind {
            return;
        }
        let o = &mut self.other_table;
        std::mem::swap(self.pipeline.lut_mut(), &mut o.lut);
        std::mem::swap(&mut self.table_path, &mut o.path);
        std::mem::swap(&mut self.history, &mut o.history);
        std::mem::swap(&mut self.dirty, &mut o.dirty);
        std::mem::swap(&mut self.saved_undo_len, &mut o.saved_undo_len);
        std::mem::swap(&mut self.unsaved_journal, &mut o.unsaved_journal);
        self.table_kind = kind;
        self.selection = None;
        self.table_changed();
    }

    /// Which camera's table is in use.
    #[must_use]
    pub const fn table_kind(&self) -> CameraKind {
        self.table_kind
    }

    /// The other camera's table.
    #[must_use]
    pub const fn other_table(&self) -> &TableSlot {
        &self.other_table
    }

    /// Remembers `path` as the table of the camera in use, to reopen at start.
    pub(super) fn remember_table(&mut self, path: &Path) {
        let p = Some(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned()));
        self.remember_for_camera(|f| f.lut.clone_from(&p));
        match self.table_kind {
            CameraKind::Robot => self.settings.last_table = p,
            CameraKind::Overhead => self.settings.last_overhead_table = p,
        }
    }
}
