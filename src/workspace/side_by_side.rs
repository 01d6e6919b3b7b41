//! Several cameras of one recording or live robot side by side (issue 28): the focused camera is the
//! workspace's own source, table and results, so hand classification, commit, undo, save,
//! playback and the sensors window act on it as on one camera; every other camera shown is a
//! [`BesideCamera`] with its own source, table (file, undo history, unsaved mark) and pipeline,
//! showing its frame nearest the shared cursor — the focused camera's frame time on the
//! recording's clock (a live robot's: the arrival clock of its frames). Focusing another camera ([`crate::workspace::Command::FocusCamera`], a
//! click on its pane) hands the workspace that camera's source and table and keeps the one
//! focused before as a beside camera: a table never moves from one camera to another.

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use super::journal::JournalEntry;
use super::params::ParamsSlot;
use super::source::Source;
use super::{SensorSeries, Workspace};
use crate::camera::CameraId;
use crate::frame::Frame;
use crate::lut::{EditHistory, LookupTable};
use crate::pipeline::Pipeline;
use crate::recognition::Primitive;
use crate::recognition::params_file;
use crate::sources::{SourceError, SourceFrame};

/// A table's state beside its cells: file, undo history, unsaved mark, the journal of a table
/// without a file — what moves with the table when the focus moves.
#[derive(Debug, Default)]
struct TableState {
    path: Option<PathBuf>,
    history: EditHistory,
    dirty: bool,
    saved_undo_len: Option<usize>,
    unsaved_journal: Option<(LookupTable, Vec<JournalEntry>)>,
}

/// A camera shown beside the focused one.
#[derive(Debug)]
pub(super) struct BesideCamera {
    camera: CameraId,
    source: Source,
    /// Classifies and recognises this camera's frames; holds its table and parameters.
    pipeline: Pipeline,
    /// Where its recognition parameters came from (moves with them when the focus moves).
    params: ParamsSlot,
    table: TableState,
    index: usize,
    current: Option<SourceFrame>,
    rgb: Vec<u8>,
    primitives: Vec<Primitive>,
    /// Said on its pane: the camera has ended (its last frame is shown) or not begun at the
    /// cursor.
    note: Option<String>,
    generation: u64,
}

/// The cameras shown side by side: their order on screen and those not focused.
#[derive(Debug, Default)]
pub(super) struct SideBySide {
    /// The cameras, left to right.
    order: Vec<CameraId>,
    cameras: Vec<BesideCamera>,
}

/// One camera's pane, as the app draws it.
#[derive(Debug, Clone, Copy)]
pub struct CameraPane<'a> {
    /// The camera.
    pub camera: &'a CameraId,
    /// The camera's image topic.
    pub topic: &'a str,
    /// True for the focused camera (the workspace's own frame, table and selection).
    pub focused: bool,
    /// The frame shown, if one could be read.
    pub frame: Option<&'a Frame>,
    /// The frame as packed RGB.
    pub rgb: &'a [u8],
    /// One class code per pixel, by this camera's table.
    pub codes: &'a [u8],
    /// This camera's recognition, image pixels.
    pub primitives: &'a [Primitive],
    /// This camera's table.
    pub lut: &'a LookupTable,
    /// Its file, if it has one.
    pub table_path: Option<&'a Path>,
    /// Unsaved edits in its table.
    pub dirty: bool,
    /// The file of its recognition parameters, if they came from one.
    pub params_path: Option<&'a Path>,
    /// Index of the frame shown in this camera's own frames.
    pub index: usize,
    /// The camera has ended or not begun at the cursor (its nearest frame is shown).
    pub note: Option<&'a str>,
    /// Changes when the pane's frame or results change (textures compare it).
    pub generation: u64,
}

impl Workspace {
    /// The panes of the cameras side by side, left to right; empty when one camera is shown.
    #[must_use]
    pub fn camera_panes(&self) -> Vec<CameraPane<'_>> {
        if self.beside.cameras.is_empty() {
            return Vec::new();
        }
        let shown = self.cameras().1;
        let mut panes = Vec::new();
        for camera in &self.beside.order {
            let topic = camera.topic();
            if shown.as_ref() == Some(camera) {
                panes.push(CameraPane {
                    camera,
                    topic,
                    focused: true,
                    frame: self.frame(),
                    rgb: self.rgb(),
                    codes: self.pipeline.result().classified.codes(),
                    primitives: &self.primitives,
                    lut: self.pipeline.lut(),
                    table_path: self.table_path.as_deref(),
                    dirty: self.dirty,
                    params_path: self.params.path.as_deref(),
                    index: self.index,
                    note: None,
                    generation: self.frame_generation,
                });
            } else if let Some(b) = self.beside.cameras.iter().find(|c| &c.camera == camera) {
                panes.push(CameraPane {
                    camera,
                    topic,
                    focused: false,
                    frame: b.current.as_ref().map(|c| c.frame.as_ref()),
                    rgb: &b.rgb,
                    codes: b.pipeline.result().classified.codes(),
                    primitives: &b.primitives,
                    lut: b.pipeline.lut(),
                    table_path: b.table.path.as_deref(),
                    dirty: b.table.dirty,
                    params_path: b.params.path.as_deref(),
                    index: b.index,
                    note: b.note.as_deref(),
                    generation: b.generation,
                });
            }
        }
        panes
    }

    /// The cameras not focused whose tables have unsaved edits (their image topics).
    #[must_use]
    pub fn unsaved_beside(&self) -> Vec<&str> {
        self.beside
            .cameras
            .iter()
            .filter(|c| c.table.dirty)
            .map(|c| c.camera.topic())
            .collect()
    }

    /// The shared cursor: the focused camera's frame time on the recording's clock, ns.
    fn cursor_ns(&self) -> Option<u64> {
        let src = self.source.as_ref()?;
        Some(src.start_ns().saturating_add(src.time_ns(self.index)))
    }

    /// Shows `cameras` side by side (fewer than two: one camera again).
    pub(super) fn show_side_by_side(&mut self, cameras: &[CameraId]) -> anyhow::Result<()> {
        let mut wanted: Vec<CameraId> = Vec::new();
        for c in cameras {
            if !wanted.contains(c) {
                wanted.push(c.clone());
            }
        }
        if wanted.len() < 2 {
            self.refuse_unsaved_beside(|_| true)?;
            self.beside = SideBySide::default();
            self.status = "one camera shown".to_owned();
            return Ok(());
        }
        let src = self
            .source
            .as_ref()
            .context("no recording or robot is shown")?;
        let all = src.camera_ids();
        anyhow::ensure!(
            !all.is_empty(),
            "the source is not a recording or robot: it has no cameras to show side by side"
        );
        // A session robot's camera may come from its own recording (`wmd.rs`).
        if let Some(c) = wanted
            .iter()
            .find(|c| !all.contains(c) && self.session_robot_files(c).is_none())
        {
            anyhow::bail!(
                "camera {} is not in {}: its cameras are {}",
                c.topic(),
                src.label(),
                src.cameras().join(", ")
            );
        }
        self.refuse_unsaved_beside(|c| !wanted.contains(&c.camera))?;
        let shown = src.camera_id();
        if shown.as_ref().is_none_or(|s| !wanted.contains(s)) {
            anyhow::ensure!(
                !self.dirty,
                "the table of camera {} has unsaved edits: save it before it leaves the view",
                shown.as_ref().map_or("?", CameraId::topic)
            );
            self.beside = SideBySide::default();
            self.open_camera(wanted.first().cloned())?;
        }
        let shown = self.cameras().1;
        let mut kept = std::mem::take(&mut self.beside.cameras);
        kept.retain(|c| wanted.contains(&c.camera));
        for camera in &wanted {
            if shown.as_ref() != Some(camera) && !kept.iter().any(|c| &c.camera == camera) {
                kept.push(self.open_beside(camera)?);
            }
        }
        let names: Vec<&str> = wanted.iter().map(CameraId::topic).collect();
        self.status = format!(
            "cameras side by side: {}; {} focused (clicks and edits go to its table)",
            names.join(", "),
            shown.as_ref().map_or("?", CameraId::topic)
        );
        self.beside = SideBySide {
            order: wanted,
            cameras: kept,
        };
        self.sync_beside();
        Ok(())
    }

    /// Camera `camera` of the source shown, opened beside the focused one with its own table
    /// (the one used with it before, else the one the recording names, else a new empty table
    /// — never the table of another camera).
    fn open_beside(&mut self, camera: &CameraId) -> anyhow::Result<BesideCamera> {
        let src = self
            .source
            .as_ref()
            .context("no recording or robot is shown")?;
        let topic = camera.topic();
        let own_recording = match camera {
            CameraId::Recording { recording, .. } if !src.camera_ids().contains(camera) => {
                Some(recording.clone())
            }
            _ => None,
        };
        let source = match (own_recording, src.robot_frames()) {
            (Some(path), _) => Source::stream_camera(&path, Some(topic))?,
            (None, Some(robot)) => Source::robot(robot.camera_view(topic)),
            (None, None) => {
                let path = src
                    .paths()
                    .into_iter()
                    .next()
                    .context("no recording is open")?;
                Source::stream_camera(&path, Some(topic))?
            }
        };
        let bits = self.pipeline.lut().bits();
        let mut files = self.camera_files(camera);
        if let Some(session) = self.session_robot_files(camera) {
            files = files.overridden_by(session);
        }
        let own = files
            .lut
            .clone()
            .map(|p| LookupTable::load(&p).map(|t| (t, p)));
        let (lut, path) = if let Some(Ok((t, p))) = own {
            (t, Some(p))
        } else {
            let why = match own {
                Some(Err(e)) => format!("its table cannot be read: {e}"),
                _ => "none used with it, none its recording names".to_owned(),
            };
            self.warn(format!(
                "camera {topic} has no table of its own ({why}): it starts with an empty {bits}-bit table"
            ));
            let lut = LookupTable::new(bits).map_err(|e| anyhow::anyhow!("new table: {e}"))?;
            (lut, None)
        };
        let table = TableState {
            unsaved_journal: path.is_none().then(|| (lut.clone(), Vec::new())),
            path,
            history: EditHistory::default(),
            dirty: false,
            saved_undo_len: Some(0),
        };
        // Its own parameters when it names them, else those in use (said on its pane).
        let mut params = *self.pipeline.params();
        let mut slot = ParamsSlot {
            path: self.params_slot().path.clone(),
            loaded: self.params_slot().loaded,
            ..ParamsSlot::default()
        };
        if let Some(p) = self.camera_params(camera, &files) {
            let own = params_file::load(&p)
                .with_context(|| format!("camera {topic}: its parameters {}", p.display()))?;
            params.recognition = own;
            slot.loaded = own;
            slot.path = Some(p);
        }
        Ok(BesideCamera {
            camera: camera.clone(),
            source,
            params: slot,
            pipeline: Pipeline::new(lut, params),
            table,
            index: 0,
            current: None,
            rgb: Vec::new(),
            primitives: Vec::new(),
            note: None,
            generation: 0,
        })
    }

    /// Refuses when a beside camera `leaving` selects has unsaved table edits.
    fn refuse_unsaved_beside(&self, leaving: impl Fn(&BesideCamera) -> bool) -> anyhow::Result<()> {
        if let Some(c) = self
            .beside
            .cameras
            .iter()
            .find(|c| c.table.dirty && leaving(c))
        {
            anyhow::bail!(
                "the table of camera {} has unsaved edits: focus it and save (or undo) before it leaves the view",
                c.camera.topic()
            );
        }
        Ok(())
    }

    /// Before another source replaces this one: no beside table with unsaved edits is dropped.
    pub(super) fn close_side_by_side(&mut self) -> anyhow::Result<()> {
        self.refuse_unsaved_beside(|_| true)?;
        self.beside = SideBySide::default();
        Ok(())
    }

    /// Makes camera `camera` (shown side by side) the focused one: the workspace takes its
    /// source and table, the camera focused so far keeps its own as a beside camera.
    pub(super) fn focus_camera(&mut self, camera: &CameraId) -> anyhow::Result<()> {
        if self.cameras().1.as_ref() == Some(camera) {
            return Ok(());
        }
        let topic = camera.topic();
        let Some(pos) = self.beside.cameras.iter().position(|c| &c.camera == camera) else {
            anyhow::bail!("camera {topic} is not shown side by side");
        };
        let cursor = self.cursor_ns().unwrap_or(0);
        let src = self.source.as_mut().context("no recording is open")?;
        let b = &mut self.beside.cameras[pos];
        std::mem::swap(src, &mut b.source);
        std::mem::swap(self.pipeline.lut_mut(), b.pipeline.lut_mut());
        let (mine, theirs) = (*self.pipeline.params(), *b.pipeline.params());
        self.pipeline.set_params(theirs);
        b.pipeline.set_params(mine);
        std::mem::swap(&mut self.params.path, &mut b.params.path);
        std::mem::swap(&mut self.params.loaded, &mut b.params.loaded);
        self.params.try_run = None;
        std::mem::swap(&mut self.table_path, &mut b.table.path);
        std::mem::swap(&mut self.history, &mut b.table.history);
        std::mem::swap(&mut self.dirty, &mut b.table.dirty);
        std::mem::swap(&mut self.saved_undo_len, &mut b.table.saved_undo_len);
        std::mem::swap(&mut self.unsaved_journal, &mut b.table.unsaved_journal);
        if let Some(id) = b.source.camera_id() {
            b.camera = id;
        }
        // Its results are of the other camera's frame: shown again at the next sync.
        b.current = None;
        let index = nearest_index(src, cursor);
        let total = src.len();
        self.camera = Some(camera.clone());
        self.current = None;
        self.selection = None;
        self.try_edit = None;
        self.player.stop();
        self.sensor_series = SensorSeries {
            total,
            ..SensorSeries::default()
        };
        self.table_changed();
        self.robot_camera_shown();
        self.seek(index)?;
        let table = self.table_path.as_deref().map_or_else(
            || "a table without a file".to_owned(),
            crate::frame::display_name,
        );
        self.status = format!("camera {topic} focused: clicks and edits go to its table, {table}");
        Ok(())
    }

    /// Shows each beside camera's frame nearest the cursor, classified with its own table.
    pub(super) fn sync_beside(&mut self) {
        if self.beside.cameras.is_empty() {
            return;
        }
        let Some(cursor) = self.cursor_ns() else {
            return;
        };
        let mut warnings = Vec::new();
        for b in &mut self.beside.cameras {
            if let Err(e) = b.show_at(cursor, &mut warnings) {
                warnings.push(format!("camera {}: {e}", b.camera.topic()));
            }
        }
        for w in warnings {
            if !self.warnings.contains(&w) {
                self.warn(w);
            }
        }
    }
}

impl BesideCamera {
    /// Shows the frame nearest `cursor` (ns on the recording's clock); what is worth a
    /// warning line (a changed frame size, the reader's problems) goes to `warnings`.
    fn show_at(&mut self, cursor: u64, warnings: &mut Vec<String>) -> Result<(), SourceError> {
        let index = nearest_index(&self.source, cursor);
        self.note = beyond_note(&self.source, cursor);
        if self.current.is_some() && index == self.index {
            return Ok(());
        }
        let loaded = self.source.read(index)?;
        if let Some(w) = self
            .current
            .as_ref()
            .and_then(|old| size_change(self.camera.topic(), &old.frame, &loaded.frame, index))
        {
            warnings.push(w);
        }
        warnings.extend(loaded.warnings.iter().cloned());
        let (w, h) = (loaded.frame.width(), loaded.frame.height());
        let r = self
            .pipeline
            .process(&loaded.frame, loaded.sensors.as_ref());
        self.primitives = r.recognition.primitives(w, h);
        loaded.frame.to_rgb_into(&mut self.rgb);
        self.current = Some(loaded);
        self.index = index;
        self.generation += 1;
        Ok(())
    }
}

/// The frame of `source` nearest `cursor` (ns on the recording's clock).
pub(super) fn nearest_index(source: &Source, cursor: u64) -> usize {
    let rel = cursor.saturating_sub(source.start_ns());
    let i = source.index_at_time(rel);
    let next = (i + 1).min(source.len().saturating_sub(1));
    if next != i && source.time_ns(next).abs_diff(rel) < source.time_ns(i).abs_diff(rel) {
        next
    } else {
        i
    }
}

/// What a pane says when the cursor is outside its camera's frames by more than one of its
/// frame intervals: ended (its last frame shown) or not begun (its first shown).
fn beyond_note(source: &Source, cursor: u64) -> Option<String> {
    let n = source.len();
    let start = source.start_ns();
    let span = source.time_ns(n.saturating_sub(1));
    let interval = span / u64::try_from(n.saturating_sub(1).max(1)).unwrap_or(1);
    let end = start.saturating_add(span);
    let s = |ns: u64| ns as f64 / 1e9;
    if cursor > end.saturating_add(interval) {
        Some(format!(
            "ended {:.2} s before the cursor: its last frame ({n}) shown",
            s(cursor - end)
        ))
    } else if cursor.saturating_add(interval) < start {
        Some(format!(
            "begins {:.2} s after the cursor: its first frame shown",
            s(start - cursor)
        ))
    } else {
        None
    }
}

/// The warning line when camera `topic`'s frame size changes from `old` to `new` (at frame
/// `index`); `None` when it does not.
pub(super) fn size_change(topic: &str, old: &Frame, new: &Frame, index: usize) -> Option<String> {
    let (a, b) = ((old.width(), old.height()), (new.width(), new.height()));
    (a != b).then(|| {
        format!(
            "camera {topic}: the frame size changes from {}×{} to {}×{} at frame {index}; each frame is shown as it is",
            a.0, a.1, b.0, b.1
        )
    })
}

#[cfg(test)]
#[path = "side_by_side_tests.rs"]
mod tests;
