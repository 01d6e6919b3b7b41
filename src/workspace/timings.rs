//! Runtime measurements of the workspace's steps and the UI's frames, for the status readout and
//! the exit report.

use std::time::Duration;

/// How many step and frame times are kept for the medians.
const TIMING_SAMPLES: usize = 600;

/// How long the parts of the last step took.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepTiming {
    /// Reading (and decoding) the frame, or the cache hit.
    pub read: Duration,
    /// Ball, goals, beacons.
    pub recognition: Duration,
    /// Classification.
    pub classify: Duration,
    /// Blob formation.
    pub blobs: Duration,
    /// RGB conversion and preview mask.
    pub prepare: Duration,
    /// Building and uploading textures (filled in by the UI).
    pub upload: Duration,
}

impl StepTiming {
    /// Everything.
    #[must_use]
    pub fn total(&self) -> Duration {
        self.read + self.classify + self.blobs + self.recognition + self.prepare + self.upload
    }
}

/// Runtime measurements for the status readout and the exit report.
#[derive(Debug, Clone, Default)]
pub struct Timings {
    /// The last step.
    pub last_step: StepTiming,
    /// Recent step totals, milliseconds.
    pub steps_ms: Vec<f64>,
    /// The parts of the recent steps (as many as `steps_ms`), for where a step's time goes.
    pub step_parts: Vec<StepTiming>,
    /// Recent UI frame intervals, milliseconds.
    pub frames_ms: Vec<f64>,
    /// Recent UI frame intervals while playing, milliseconds.
    pub playing_frames_ms: Vec<f64>,
    /// While playing: time our own UI code took per frame (layout and painting commands, not
    /// tessellation or rasterisation), milliseconds.
    pub playing_ui_ms: Vec<f64>,
    /// While playing: eframe's CPU time per frame (our UI, tessellation, the renderer's
    /// submission; not the wait for the display), milliseconds.
    pub playing_cpu_ms: Vec<f64>,
    /// UI frame intervals that followed a frame with input (pointer, wheel, keys): how long
    /// the window took to answer the user while zooming, panning or typing, milliseconds.
    pub input_frames_ms: Vec<f64>,
    /// From the app's start to its first frame on screen, milliseconds (`None` before).
    pub first_frame_ms: Option<f64>,
    /// Frames shown by playback since the app started.
    pub played_frames: u64,
    /// Frames playback skipped because the next one was already due (not ready in time).
    pub dropped_frames: u64,
    /// Frames playback showed late instead of skipping them (a later frame was already due,
    /// but the player was less than [`super::player::MAX_LAG`] behind).
    pub late_frames: u64,
}

impl Timings {
    /// The median of each part of the recent steps, milliseconds, named as the exit report
    /// names them: read, classify, blobs, recognition, prepare, upload.
    #[must_use]
    pub fn step_part_medians(&self) -> [(&'static str, f64); 6] {
        let ms = |f: fn(&StepTiming) -> Duration| {
            let v: Vec<f64> = self
                .step_parts
                .iter()
                .map(|s| f(s).as_secs_f64() * 1e3)
                .collect();
            median(&v)
        };
        [
            ("read", ms(|s| s.read)),
            ("classify", ms(|s| s.classify)),
            ("blobs", ms(|s| s.blobs)),
            ("recognition", ms(|s| s.recognition)),
            ("prepare", ms(|s| s.prepare)),
            ("upload", ms(|s| s.upload)),
        ]
    }
}

pub(crate) fn push_capped(v: &mut Vec<f64>, x: f64) {
    if v.len() >= TIMING_SAMPLES {
        v.remove(0);
    }
    v.push(x);
}

/// Median of a list of samples (0 for none).
#[must_use]
pub fn median(samples: &[f64]) -> f64 {
    crate::stats::median(samples).unwrap_or(0.0)
}
