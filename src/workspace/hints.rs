//! The workspace side of the hand-classifier's three daily questions: what is still
//! unclassified ([`CoverageScan`]), why a pixel has its class ([`cell_origin`]), where something
//! happened ([`EventScan`], user bookmarks). State lives in [`Hints`], one field of the
//! workspace; the commands are applied here.

use std::path::PathBuf;

use anyhow::Context as _;

use super::bookmarks::{self, Event, EventKind, EventScan, UserBookmark};
use super::cell_origin::{CellOrigin, cell_origin};
use super::coverage::CoverageScan;
use super::{HintsCommand, PendingSelection, SCAN_BUDGET, SelectionClass, Workspace};
use crate::lut::Region;

/// Coverage, events and bookmarks of the open source.
#[derive(Debug, Default)]
pub struct Hints {
    coverage: Option<CoverageScan>,
    /// The table generation the coverage ranking was made for.
    ranked_generation: u64,
    events: Option<EventScan>,
    /// The bookmarks file of the open source, if it has a file.
    bookmarks_file: Option<PathBuf>,
    user: Vec<UserBookmark>,
    /// The shown frame's pixels per table cell and the frame generation they were counted at
    /// (each hint's pixels in the shown frame are summed from them).
    shown: Option<(u64, std::collections::HashMap<usize, u64>)>,
}

impl Workspace {
    /// Applies the coverage, bookmark and event commands.
    pub(super) fn apply_hints(&mut self, command: HintsCommand) -> anyhow::Result<()> {
        match command {
            HintsCommand::FindUnclassified { first, last } => {
                let total = self.source.as_ref().context("no stream open")?.len();
                let bits = self.pipeline.lut().bits();
                self.hints.coverage = Some(CoverageScan::new(first, last, total, bits));
                self.settings.show_coverage = true;
            }
            HintsCommand::SelectCells(indices) => {
                anyhow::ensure!(!indices.is_empty(), "no cells to select");
                let len = self.pipeline.lut().cells().len();
                anyhow::ensure!(
                    indices.iter().all(|&i| i < len),
                    "a cell lies outside the {}-bit table",
                    self.pipeline.lut().bits()
                );
                // A hint's colours are nobody's class yet: the class is chosen for them.
                self.selection = Some(PendingSelection {
                    region: Region::Cells { indices },
                    pixel: None,
                    class: SelectionClass::Unchosen,
                });
                self.refresh_preview();
            }
            HintsCommand::RankHints => {
                let c = self
                    .hints
                    .coverage
                    .as_mut()
                    .context("no coverage count yet")?;
                c.rank(self.pipeline.lut());
            }
            HintsCommand::FindEvents => {
                let total = self.source.as_ref().context("no stream open")?.len();
                let params = *self.pipeline.params();
                self.hints.events = Some(EventScan::new(self.pipeline.lut(), params, total));
                self.settings.show_bookmarks = true;
            }
            HintsCommand::AddBookmark(note) => {
                anyhow::ensure!(self.source.is_some(), "no stream open");
                let frame = self.index;
                self.hints.user.retain(|b| b.frame != frame);
                self.hints.user.push(UserBookmark { frame, note });
                self.hints.user.sort_by_key(|b| b.frame);
                self.save_bookmarks()?;
                self.status = format!("bookmark at frame {frame}");
            }
            HintsCommand::RemoveBookmark(frame) => {
                let before = self.hints.user.len();
                self.hints.user.retain(|b| b.frame != frame);
                anyhow::ensure!(
                    self.hints.user.len() < before,
                    "no bookmark at frame {frame}"
                );
                self.save_bookmarks()?;
            }
            HintsCommand::JumpToMark { forward } => {
                let frames = self.mark_frames();
                let target =
                    bookmarks::neighbour(frames, self.index, forward).with_context(|| {
                        format!(
                            "no mark {} frame {}",
                            if forward { "after" } else { "before" },
                            self.index
                        )
                    })?;
                self.seek(target)?;
            }
        }
        Ok(())
    }

    fn save_bookmarks(&mut self) -> anyhow::Result<()> {
        let path = self
            .hints
            .bookmarks_file
            .clone()
            .context("this source has no file to keep bookmarks beside")?;
        bookmarks::save(&path, &self.hints.user)
    }

    /// Loads the bookmarks kept beside the newly opened source (a bad file is a warning).
    pub(super) fn load_bookmarks(&mut self) {
        self.hints.coverage = None;
        self.hints.shown = None;
        self.hints.events = None;
        self.hints.user.clear();
        self.hints.bookmarks_file = self
            .source
            .as_ref()
            .and_then(|s| s.paths().into_iter().next())
            .map(|p| bookmarks::bookmarks_path(&p));
        if let Some(path) = self.hints.bookmarks_file.clone() {
            match bookmarks::load(&path) {
                Ok(marks) => self.hints.user = marks,
                Err(e) => self.warn(format!("{e:#}")),
            }
        }
    }

    /// Advances the coverage and event scans (called from [`Workspace::tick`]).
    pub(super) fn tick_hints(&mut self) {
        let Some(src) = self.source.as_mut() else {
            return;
        };
        if let Some(c) = self.hints.coverage.as_mut() {
            let counted = c.scan(src, self.pipeline.lut(), SCAN_BUDGET);
            if counted {
                c.rank(self.pipeline.lut());
                self.hints.ranked_generation = self.table_generation;
            } else if self.hints.ranked_generation != self.table_generation {
                // A commit or an undo: each row keeps its place (Re-rank orders afresh).
                c.refresh(self.pipeline.lut());
                self.hints.ranked_generation = self.table_generation;
            }
        }
        if let Some(e) = self.hints.events.as_mut() {
            e.scan(src, SCAN_BUDGET);
        }
        let stale = self
            .hints
            .shown
            .as_ref()
            .is_none_or(|(g, _)| *g != self.frame_generation);
        // One pass over the frame (a hash per pixel): not while playing, nor with the
        // Coverage window closed.
        if self.hints.coverage.is_some()
            && stale
            && self.settings.show_coverage
            && !self.player.playing()
        {
            self.hints.shown = self.frame().map(|f| {
                (
                    self.frame_generation,
                    super::coverage::cell_counts(f, self.pipeline.lut()),
                )
            });
        }
    }

    /// Pixels of the shown frame in any of `cells` (a coverage hint's): 0 before the first
    /// count of the shown frame.
    #[must_use]
    pub fn pixels_here(&self, cells: &[usize]) -> u64 {
        self.hints.shown.as_ref().map_or(0, |(_, counts)| {
            cells.iter().filter_map(|c| counts.get(c)).sum()
        })
    }

    /// The unclassified-colours count, if one was started.
    #[must_use]
    pub const fn coverage(&self) -> Option<&CoverageScan> {
        self.hints.coverage.as_ref()
    }

    /// The event scan, if one was started.
    #[must_use]
    pub const fn event_scan(&self) -> Option<&EventScan> {
        self.hints.events.as_ref()
    }

    /// The user's bookmarks of the open source, by frame.
    #[must_use]
    pub fn bookmarks(&self) -> &[UserBookmark] {
        &self.hints.user
    }

    /// Every event mark: the event scan's and the pending try-edit's frames whose blobs change.
    #[must_use]
    pub fn events(&self) -> Vec<Event> {
        let mut out: Vec<Event> = self
            .hints
            .events
            .as_ref()
            .map(|e| e.events.clone())
            .unwrap_or_default();
        if let Some(t) = &self.try_edit {
            out.extend(
                t.stream
                    .rows
                    .iter()
                    .filter(|r| r.blobs_before != r.blobs_after)
                    .map(|r| Event {
                        frame: r.index,
                        kind: EventKind::TryEditChange,
                        detail: format!("blobs {} -> {}", r.blobs_before, r.blobs_after),
                    }),
            );
        }
        if let Some(labels) = self.labels() {
            out.extend(labels.events());
        }
        out.sort_by_key(|e| e.frame);
        out
    }

    /// Frames of every mark, events and bookmarks.
    fn mark_frames(&self) -> Vec<usize> {
        let mut frames: Vec<usize> = self.events().iter().map(|e| e.frame).collect();
        frames.extend(self.hints.user.iter().map(|b| b.frame));
        frames
    }

    /// Who set the table cell of the shown frame's pixel (x, y); `None` outside the frame.
    #[must_use]
    pub fn pixel_origin(&self, x: usize, y: usize) -> Option<CellOrigin> {
        let p = self.frame()?.pixel(x, y)?;
        let lut = self.pipeline.lut();
        Some(cell_origin(&self.history, lut, lut.index(p)))
    }

    /// True while a coverage or event scan is running (the UI keeps redrawing).
    #[must_use]
    pub fn hints_busy(&self) -> bool {
        self.hints.coverage.as_ref().is_some_and(|c| !c.done())
            || self.hints.events.as_ref().is_some_and(|e| !e.done())
            || self.labels().is_some_and(|l| !l.done())
    }
}
