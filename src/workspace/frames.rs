//! The frame side of the workspace: opening sources, showing a frame (the pipeline on it), and
//! the background scans of the whole recording.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context as _;

use super::source::Source;
use super::timings::StepTiming;
use super::{SCAN_BUDGET, SensorSeries, Workspace};
use crate::sources::SourceFrame;

impl Workspace {
    pub(super) fn open(&mut self, paths: Vec<PathBuf>) -> anyhow::Result<()> {
        anyhow::ensure!(!paths.is_empty(), "nothing to open");
        let mut frames = Vec::new();
        let mut stream = None;
        let mut tables = Vec::new();
        for p in paths {
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase())
                .unwrap_or_default();
            if ext == "mcap" {
                stream = Some(p);
            } else if ext == "json" {
                self.open_places(&p)?;
            } else if crate::sources::is_frame_file(&p) || p.is_dir() {
                frames.push(p);
            } else {
                tables.push(p);
            }
        }
        // Tables after the source: a table named with an overhead stream is the overhead
        // camera's, which is only in use once that stream is open.
        let opens_source = stream.is_some() || !frames.is_empty();
        self.open_source_of(stream, frames)?;
        let source_status = self.status.clone();
        for t in tables {
            self.open_table(&t)?;
        }
        if opens_source {
            // What was opened is said by the source's line (frames, calibration in use).
            self.status = source_status;
        }
        Ok(())
    }

    fn open_source_of(
        &mut self,
        stream: Option<PathBuf>,
        frames: Vec<PathBuf>,
    ) -> anyhow::Result<()> {
        if let Some(s) = stream {
            let source = Source::stream(&s)?;
            self.remember_recent(&s);
            self.set_source(source)?;
        } else if !frames.is_empty() {
            let files = crate::sources::expand_frame_paths(&frames)?;
            for f in &frames {
                self.remember_recent(f);
            }
            self.set_source(Source::files(files)?)?;
        }
        Ok(())
    }

    pub(super) fn set_source(&mut self, source: Source) -> anyhow::Result<()> {
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
            .as_ref()
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
        let index = index.min(src.len().saturating_sub(1));
        let t0 = Instant::now();
        let loaded = src.read(index)?;
        let t1 = Instant::now();
        let t = self.run_pipeline(&loaded);
        let t2 = Instant::now();
        loaded.frame.to_rgb_into(&mut self.rgb);
        for w in &loaded.warnings {
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
            let r = src.read_uncached(i).ok().and_then(|f| f.sensors);
            self.sensor_series.points.push((t, r));
        }
    }
}
