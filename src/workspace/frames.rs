//! The frame side of the workspace: opening sources, showing a frame (the pipeline on it), and
//! the background scans of the whole recording.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context as _;

use super::source::Source;
use super::timings::StepTiming;
use super::{SCAN_BUDGET, SensorSeries, Workspace};
use crate::camera::{CameraFiles, CameraId};
use crate::sources::SourceFrame;

/// The files given to Open, by kind. Tables, parameters and places open after the source: each
/// camera kind has its own table (a table given beside an overhead stream belongs in the
/// overhead slot, whatever the order), and what is opened is remembered for the camera shown.
struct OpenPaths {
    streams: Vec<PathBuf>,
    frames: Vec<PathBuf>,
    tables: Vec<PathBuf>,
    /// Recognition parameters or places files (told by content when opened).
    jsons: Vec<PathBuf>,
    /// SSL-Vision sources: a league log file or a `udp://` multicast group.
    ssl: Vec<PathBuf>,
    /// Session files (`SESSION.json`): several overhead cameras of one field.
    sessions: Vec<PathBuf>,
}

impl OpenPaths {
    fn sort(paths: Vec<PathBuf>) -> Self {
        let mut sorted = Self {
            streams: Vec::new(),
            frames: Vec::new(),
            tables: Vec::new(),
            jsons: Vec::new(),
            ssl: Vec::new(),
            sessions: Vec::new(),
        };
        for p in paths {
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase())
                .unwrap_or_default();
            let kind = if is_ssl_source(&p, &ext) {
                &mut sorted.ssl
            } else if crate::streams::is_recording(&p) {
                &mut sorted.streams
            } else if ext == "json" && super::overhead::field_cameras::is_session_file(&p) {
                &mut sorted.sessions
            } else if ext == "json" {
                &mut sorted.jsons
            } else if crate::sources::is_frame_file(&p) || p.is_dir() {
                &mut sorted.frames
            } else {
                &mut sorted.tables
            };
            kind.push(p);
        }
        sorted
    }
}

impl Workspace {
    /// Opens each file by its kind; each opens or fails on its own (a bad table does not stop
    /// the stream beside it). Every failure is a warning naming its file; the error returned
    /// lists them all.
    pub(super) fn open(&mut self, paths: Vec<PathBuf>) -> anyhow::Result<()> {
        anyhow::ensure!(!paths.is_empty(), "nothing to open");
        let OpenPaths {
            mut streams,
            mut frames,
            mut tables,
            jsons,
            ssl,
            sessions,
        } = OpenPaths::sort(paths);
        let mut shown_camera = None;
        let mut offer = None;
        let mut failures = Vec::new();
        for p in ssl {
            if let Err(e) = self.open_ssl(&p) {
                failures.push(format!("{e:#}"));
            }
        }
        // A session shows its cameras instead of streams or frames given beside it.
        if let Some(s) = sessions.last() {
            for skipped in sessions.iter().rev().skip(1).chain(&streams).chain(&frames) {
                failures.push(format!(
                    "{}: not opened (one source at a time; session {} is shown)",
                    skipped.display(),
                    s.display()
                ));
            }
            streams.clear();
            frames.clear();
            if let Err(e) = self.open_session(s) {
                failures.push(format!("{e:#}"));
            }
        }
        // One source is shown: the last stream given, else the frames as one sequence.
        if let Some(s) = streams.pop() {
            for skipped in &streams {
                failures.push(format!(
                    "{}: not opened (one stream at a time; {} is shown)",
                    skipped.display(),
                    s.display()
                ));
            }
            match self.open_recording(&s, &mut tables) {
                Ok(camera) => {
                    offer = Some(s);
                    shown_camera = camera;
                    if self.source_is_recorded_session() {
                        self.request_wmd_layout();
                    }
                }
                Err(e) => failures.push(format!("{e:#}")),
            }
        } else if !frames.is_empty() {
            let opened = crate::sources::expand_frame_paths(&frames)
                .and_then(|files| Source::files(files).map_err(Into::into))
                .and_then(|source| self.set_source(source));
            match opened {
                Ok(()) => {
                    for f in &frames {
                        self.remember_recent(f);
                    }
                }
                Err(e) => failures.push(format!("{e:#}")),
            }
        }
        let opened_source = offer.is_some() || !frames.is_empty();
        let source_status = self.status.clone();
        for t in tables {
            if let Err(e) = self.open_table(&t) {
                failures.push(format!("{e:#}"));
            }
        }
        self.open_given_files(jsons, shown_camera, &mut failures);
        if opened_source {
            // What was opened is said by the source's line (frames, calibration in use).
            self.status = source_status;
        }
        // Last, so the status line ends with the stream's parameter set on offer.
        if let Some(s) = offer {
            self.offer_param_set(&s);
        }
        match failures.len() {
            0 => Ok(()),
            1 => Err(anyhow::anyhow!(failures.remove(0))),
            _ => {
                let last = failures.pop().unwrap_or_default();
                for f in failures {
                    self.warn(f);
                }
                Err(anyhow::anyhow!(last))
            }
        }
    }

    /// Shows the recording `s` on its camera; the camera's own table goes into `tables` unless
    /// one is given. Returns the camera shown and its own files, applied once the files given
    /// are open ([`Workspace::open_given_files`]).
    fn open_recording(
        &mut self,
        s: &Path,
        tables: &mut Vec<PathBuf>,
    ) -> anyhow::Result<Option<(CameraId, CameraFiles)>> {
        let source = Source::stream_camera(s, self.camera_for(s).as_deref())?;
        self.remember_recent(s);
        // The camera's own files: remembered for this recording's camera, else those it names.
        let camera = source.camera_id().map(|id| {
            let files = self.camera_files(&id);
            (id, files)
        });
        if tables.is_empty()
            && let Some(t) = camera.as_ref().and_then(|(_, f)| f.lut.clone())
        {
            tables.push(t);
        }
        self.set_source(source)?;
        Ok(camera)
    }

    /// After the source and its tables: the parameter and places files given, then the shown
    /// camera's own parameters (unless parameters were given) and calibration.
    fn open_given_files(
        &mut self,
        jsons: Vec<PathBuf>,
        shown_camera: Option<(CameraId, CameraFiles)>,
        failures: &mut Vec<String>,
    ) {
        let params_given = jsons.iter().any(|j| {
            matches!(
                super::params::json_kind(j),
                Ok(super::params::JsonKind::Params)
            )
        });
        for j in jsons {
            if let Err(e) = self.open_json(&j) {
                failures.push(format!("{e:#}"));
            }
        }
        if let Some((id, mut files)) = shown_camera {
            if params_given {
                // The parameters given win over the camera's own.
                files.params = None;
            }
            if let Err(e) = self.open_camera_files(&id, &files) {
                failures.push(format!("{e:#}"));
            }
        }
    }

    /// A `.json` given to Open: recognition parameters or a places file, told by content.
    fn open_json(&mut self, path: &std::path::Path) -> anyhow::Result<()> {
        match super::params::json_kind(path)? {
            super::params::JsonKind::Params => self.open_params(path),
            super::params::JsonKind::Places => self.open_places(path),
        }
    }

    pub(super) fn set_source(&mut self, source: Source) -> anyhow::Result<()> {
        // Cameras shown side by side belong to the source replaced (refused when one of their
        // tables has unsaved edits).
        self.close_side_by_side()?;
        let kind = source.info().camera;
        let old_kind = self.table_kind;
        let old = self.source.replace(source);
        self.use_table_of(kind);
        self.player.stop();
        self.try_edit = None;
        self.current = None;
        self.reset_overhead_for_source();
        if let Err(e) = self.seek(0) {
            self.source = old;
            self.use_table_of(old_kind);
            return Err(e);
        }
        self.live = None;
        self.robots.unshow();
        self.load_bookmarks();
        self.labels = None;
        if let Some(src) = &self.source {
            self.settings.last_source = src
                .paths()
                .into_iter()
                .map(|p| std::fs::canonicalize(&p).unwrap_or(p))
                .collect();
            let n = src.len();
            let label = src.label();
            let warnings = src.warnings();
            self.sensor_series = SensorSeries {
                points: Vec::new(),
                channels: std::collections::BTreeMap::new(),
                total: if src.is_stream() { n } else { 0 },
            };
            for w in warnings {
                self.warn(format!("{label}: {w}"));
            }
            self.status = format!("opened {label}: {n} frames");
            if self.overhead.active() {
                self.status = format!("{}; {}", self.status, self.overhead.calibration_status());
            }
        }
        Ok(())
    }

    /// Re-runs the pipeline on the shown frame (after a table or parameter change).
    pub(super) fn reprocess(&mut self) {
        if let Some(c) = self.current.take() {
            let t = self.run_pipeline(&c);
            self.current = Some(c);
            self.timings.last_step = StepTiming {
                classify: t.classify,
                blobs: t.blobs,
                recognition: t.recognition,
                ..StepTiming::default()
            };
            self.frame_generation += 1;
        }
        self.refresh_preview();
    }

    /// Runs every stage on `loaded` with its sensor readings (recognition needs the camera
    /// pose for heights and the horizon) and refreshes what is derived from the results.
    pub(super) fn run_pipeline(&mut self, loaded: &SourceFrame) -> crate::pipeline::StageTimings {
        if self.camera_kind() == crate::sources::CameraKind::Overhead {
            return self.run_overhead(loaded);
        }
        self.overhead_inactive();
        let r = self
            .pipeline
            .process(&loaded.frame, loaded.sensors.as_ref());
        let timings = r.timings;
        let (w, h) = (loaded.frame.width(), loaded.frame.height());
        let recognition = r.recognition;
        self.primitives = recognition.primitives(w, h);
        self.accepted_owners = recognition.accepted_owners();
        self.frame_counts = self.pipeline.result().classified.histogram();
        if self
            .selected_object
            .is_some_and(|o| !self.primitives.iter().any(|p| p.owner() == o))
        {
            self.selected_object = None;
        }
        timings
    }

    pub(super) fn refresh_preview(&mut self) {
        self.preview_mask = match (&self.selection, self.frame()) {
            (Some(s), Some(f)) => s
                .region
                .select(self.pipeline.lut())
                .preview_mask(self.pipeline.lut(), f),
            _ => Vec::new(),
        };
        self.preview_generation += 1;
    }

    pub(super) fn step(&mut self, delta: i64) -> anyhow::Result<()> {
        let len = self
            .source
            .as_ref()
            .context("no stream or frames open")?
            .len();
        let target = i64::try_from(self.index)
            .unwrap_or(i64::MAX)
            .saturating_add(delta)
            .clamp(0, i64::try_from(len).unwrap_or(i64::MAX) - 1);
        self.seek(usize::try_from(target).unwrap_or(0))
    }

    pub(super) fn seek(&mut self, index: usize) -> anyhow::Result<()> {
        let src = self.source.as_mut().context("no stream or frames open")?;
        let index = index
            .min(src.len().saturating_sub(1))
            .max(src.first_index());
        let t0 = Instant::now();
        let loaded = src.read(index)?;
        let resized = self.current.as_ref().and_then(|old| {
            let topic = src.camera().unwrap_or_else(|| "the source".to_owned());
            super::side_by_side::size_change(&topic, &old.frame, &loaded.frame, index)
        });
        let t1 = Instant::now();
        let t = self.run_pipeline(&loaded);
        let t2 = Instant::now();
        self.rgb.reset();
        for w in resized.iter().chain(&loaded.warnings) {
            if !self.warnings.contains(w) {
                self.warn(w.clone());
            }
        }
        self.record_shown(&loaded);
        self.current = Some(loaded);
        self.index = index;
        self.settings.last_index = index;
        self.refresh_preview();
        self.timings.last_step = StepTiming {
            read: t1 - t0,
            classify: t.classify,
            blobs: t.blobs,
            recognition: t.recognition,
            prepare: t2.elapsed(),
            upload: Duration::ZERO,
        };
        self.frame_generation += 1;
        self.sync_beside();
        self.sync_ssl();
        Ok(())
    }

    pub(super) fn scan_sensor_series(&mut self) {
        let Some(src) = self.source.as_mut() else {
            return;
        };
        if !self.settings.show_sensors
            || self.sensor_series.points.len() >= self.sensor_series.total
        {
            return;
        }
        let start = Instant::now();
        while self.sensor_series.points.len() < self.sensor_series.total
            && start.elapsed() < SCAN_BUDGET
        {
            let i = self.sensor_series.points.len();
            let t = src.time_ns(i) as f64 / 1e9;
            let frame = src.read_uncached(i).ok();
            for (topic, value) in frame.iter().flat_map(|f| &f.extra) {
                for (name, v) in crate::sensors::channel_readings(value) {
                    self.sensor_series
                        .channels
                        .entry(format!("{topic} {name}"))
                        .or_default()
                        .push([t, v]);
                }
            }
            let r = frame.and_then(|f| f.sensors);
            self.sensor_series.points.push((t, r));
        }
    }
}

/// An SSL-Vision source given to Open: `udp://…`, or a `.log` (`.log.gz`) file (a B-Human log
/// of the same name is told apart when read, and pointed to its importer).
fn is_ssl_source(p: &std::path::Path, ext: &str) -> bool {
    let text = p.to_string_lossy();
    crate::ssl_vision::listener::is_udp_url(&text)
        || ext == "log"
        || (ext == "gz" && text.to_ascii_lowercase().ends_with(".log.gz"))
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::super::{Command, Workspace};
    use crate::sources::CameraKind;

    fn repo(relative: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(relative)
    }

    #[test]
    fn a_table_given_before_an_overhead_stream_goes_into_the_overhead_slot() {
        let mut w = Workspace::default();
        let table = repo("lookup_tables/sim.lut");
        w.apply(Command::Open(vec![
            table.clone(),
            repo("streams/sim-overhead-game.mcap"),
        ]))
        .unwrap();
        assert_eq!(w.camera_kind(), CameraKind::Overhead);
        assert_eq!(w.table_path(), Some(table.as_path()));
        let counts = w.lut().class_counts();
        assert!(
            counts[1..].iter().sum::<usize>() > 0,
            "the overhead view classifies with the table given"
        );
    }
}
