//! The whole pipeline, one frame at a time: classification, blobs and recognition, with
//! per-stage timings.
//!
//! [`Pipeline`] owns the lookup table and every reusable buffer; the CLI, the benchmarks and the
//! app all call [`Pipeline::process_frame`], so what the app shows is exactly what the headless
//! tools compute.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::blobs::{BlobSet, Connectivity};
use crate::classify::{ClassifiedImage, classify_into_with};
use crate::frame::Frame;
use crate::kernels::{self, KernelSet};
use crate::lut::LookupTable;
use crate::recognition::patterns::PatternMemory;
use crate::recognition::{Recognition, RecognitionParams, recognise};
use crate::sensors::SensorReadings;

/// Settings of the pipeline's stages.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PipelineParams {
    /// Which neighbours join a blob.
    pub connectivity: Connectivity,
    /// Run object recognition after the blobs (off for pure classification benchmarks).
    pub recognise: bool,
    /// Settings of the recognisers.
    pub recognition: RecognitionParams,
}

impl Default for PipelineParams {
    fn default() -> Self {
        Self {
            connectivity: Connectivity::default(),
            recognise: true,
            recognition: RecognitionParams::default(),
        }
    }
}

/// How long each stage took on the last frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StageTimings {
    /// Table lookup of every pixel.
    pub classify: Duration,
    /// Run-length encoding and union-find.
    pub blobs: Duration,
    /// Ball, goals, beacons.
    pub recognition: Duration,
}

impl StageTimings {
    /// Classification and blobs: the per-pixel part, which the speed targets are about.
    #[must_use]
    pub fn total(&self) -> Duration {
        self.classify + self.blobs
    }

    /// Every stage, recognition included.
    #[must_use]
    pub fn all(&self) -> Duration {
        self.classify + self.blobs + self.recognition
    }
}

/// The pipeline: a table, parameters and the buffers of the last frame's results.
#[derive(Debug, Clone)]
pub struct Pipeline {
    lut: LookupTable,
    params: PipelineParams,
    classified: ClassifiedImage,
    blobs: BlobSet,
    recognition: Recognition,
    pattern_memory: Option<PatternMemory>,
    timings: StageTimings,
    /// Classification's and the run search's kernels; `None`: those chosen for this CPU.
    kernels: Option<KernelSet>,
}

impl Pipeline {
    /// A pipeline classifying with `lut`.
    #[must_use]
    pub fn new(lut: LookupTable, params: PipelineParams) -> Self {
        Self {
            lut,
            params,
            classified: ClassifiedImage::default(),
            blobs: BlobSet::default(),
            recognition: Recognition::default(),
            pattern_memory: None,
            timings: StageTimings::default(),
            kernels: None,
        }
    }

    /// Runs classification and blobs with the kernels of `set` from now on (benchmarks compare
    /// the sets; every set gives the same results). By default the set chosen for this CPU.
    pub fn set_kernels(&mut self, set: KernelSet) {
        self.kernels = Some(set);
        self.blobs.set_kernels(set);
    }

    /// Runs every stage on a frame without sensor readings (recognition then has no camera
    /// pose: no heights, no horizon); results stay in the pipeline until the next frame.
    pub fn process_frame(&mut self, frame: &Frame) -> FrameResult<'_> {
        self.process(frame, None)
    }

    /// Runs every stage on `frame` with the robot's readings for it.
    pub fn process(&mut self, frame: &Frame, sensors: Option<&SensorReadings>) -> FrameResult<'_> {
        let t0 = Instant::now();
        let set = self.kernels.unwrap_or_else(kernels::active);
        classify_into_with(set, frame, &self.lut, &mut self.classified);
        let t1 = Instant::now();
        self.blobs.find(&self.classified, self.params.connectivity);
        let t2 = Instant::now();
        if self.params.recognise {
            let p = &self.params.recognition;
            let ctx = p.context_for(frame.width(), frame.height(), sensors);
            self.recognition = recognise(
                &self.classified,
                &self.blobs,
                &ctx,
                p,
                self.pattern_memory.as_ref(),
            );
        } else {
            self.recognition = Recognition::default();
        }
        let t3 = Instant::now();
        self.timings = StageTimings {
            classify: t1 - t0,
            blobs: t2 - t1,
            recognition: t3 - t2,
        };
        self.result()
    }

    /// The results of the last processed frame.
    #[must_use]
    pub fn result(&self) -> FrameResult<'_> {
        FrameResult {
            classified: &self.classified,
            blobs: &self.blobs,
            recognition: &self.recognition,
            timings: self.timings,
        }
    }

    /// The table in use.
    #[must_use]
    pub fn lut(&self) -> &LookupTable {
        &self.lut
    }

    /// The table, for editing; re-run [`Pipeline::process_frame`] to see the effect.
    pub fn lut_mut(&mut self) -> &mut LookupTable {
        &mut self.lut
    }

    /// Replaces the table.
    pub fn set_lut(&mut self, lut: LookupTable) {
        self.lut = lut;
    }

    /// Learnt coloured patterns used to identify pink markers (none: signatures only).
    pub fn set_pattern_memory(&mut self, memory: Option<PatternMemory>) {
        self.pattern_memory = memory;
    }

    /// The learnt coloured patterns in use, if any.
    #[must_use]
    pub const fn pattern_memory(&self) -> Option<&PatternMemory> {
        self.pattern_memory.as_ref()
    }

    /// The stage settings.
    #[must_use]
    pub const fn params(&self) -> &PipelineParams {
        &self.params
    }

    /// Changes the stage settings.
    pub fn set_params(&mut self, params: PipelineParams) {
        self.params = params;
    }
}

/// What the pipeline made of one frame (borrowed from the pipeline's buffers).
#[derive(Debug, Clone, Copy)]
pub struct FrameResult<'a> {
    /// One class code per pixel.
    pub classified: &'a ClassifiedImage,
    /// Blobs of every class.
    pub blobs: &'a BlobSet,
    /// Ball, goals, beacons, horizon, with their evidence.
    pub recognition: &'a Recognition,
    /// How long each stage took.
    pub timings: StageTimings,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;
    use crate::lut::{ColourClass, EditRecord, Region, Sensitivity};

    #[test]
    fn process_frame_classifies_and_finds_blobs() {
        let orange = Yuv::new(120, 80, 190);
        let frame = Frame::uyvy_from_fn(32, 16, |x, y| {
            if (8..16).contains(&x) && (4..10).contains(&y) {
                orange
            } else {
                Yuv::new(60, 128, 128)
            }
        })
        .unwrap();
        let mut lut = LookupTable::new(7).unwrap();
        lut.apply(EditRecord::now(
            ColourClass::Orange,
            Region::AroundSample {
                sample: orange,
                sensitivity: Sensitivity::uniform(1),
            },
        ));
        let mut p = Pipeline::new(lut, PipelineParams::default());
        let r = p.process_frame(&frame);
        let balls: Vec<_> = r.blobs.of_class(ColourClass::Orange).collect();
        assert_eq!(balls.len(), 1);
        assert_eq!(
            (balls[0].minx, balls[0].miny, balls[0].maxx, balls[0].maxy),
            (8, 4, 15, 9)
        );
        assert_eq!(balls[0].pixels, 48);
    }
}
