//! The overhead pipeline: classification and blobs as for the robot camera, then the overhead
//! recogniser through a calibration, with per-stage timings. The app and `eotn overhead detect`
//! both run this for frames whose source is an overhead camera.

use std::time::{Duration, Instant};

use crate::blobs::{BlobSet, Connectivity};
use crate::classify::{ClassifiedImage, classify_into};
use crate::frame::Frame;
use crate::geometry::OverheadCamera;
use crate::lut::LookupTable;

use super::recognise::{
    OverheadDetections, OverheadParams, RecognitionParts, recognise_overhead_timed,
};

/// How long each stage took on the last frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OverheadTimings {
    /// Table lookup of every pixel.
    pub classify: Duration,
    /// Run-length encoding and union-find.
    pub blobs: Duration,
    /// Ball and markers.
    pub recognition: Duration,
    /// Of recognition: the ball, the markers, and the points carried through the lens.
    pub parts: RecognitionParts,
}

impl OverheadTimings {
    /// Every stage.
    #[must_use]
    pub fn total(&self) -> Duration {
        self.classify + self.blobs + self.recognition
    }
}

/// The overhead pipeline's table, camera and buffers.
#[derive(Debug, Clone)]
pub struct OverheadPipeline {
    lut: LookupTable,
    camera: OverheadCamera,
    params: OverheadParams,
    classified: ClassifiedImage,
    blobs: BlobSet,
    detections: OverheadDetections,
    timings: OverheadTimings,
}

/// How a calibration made for one image size fits a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameFit {
    /// The size it was made for.
    Same,
    /// Another size of the same shape (within 1 %): the camera is scaled to it.
    Scaled {
        /// The calibration's size, pixels.
        from: (usize, usize),
        /// The frame's size, pixels.
        to: (usize, usize),
    },
    /// Another shape: not this camera's view.
    Mismatch {
        /// The calibration's size, pixels.
        calibrated: (usize, usize),
        /// The frame's size, pixels.
        frame: (usize, usize),
    },
}

impl std::fmt::Display for FrameFit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Same => write!(f, "the calibration's own frame size"),
            Self::Scaled { from, to } => write!(
                f,
                "the calibration is for {}x{} frames, these are {}x{} (the same shape): the camera is scaled to them",
                from.0, from.1, to.0, to.1
            ),
            Self::Mismatch { calibrated, frame } => write!(
                f,
                "the calibration is for {}x{} frames, this one is {}x{}: another shape, so another camera or view; calibrate for it",
                calibrated.0, calibrated.1, frame.0, frame.1
            ),
        }
    }
}

/// How `camera` (a calibration) fits a frame of `width`×`height` pixels.
#[must_use]
pub fn frame_fit(camera: &OverheadCamera, width: usize, height: usize) -> FrameFit {
    let calibrated = (camera.width_px, camera.height_px);
    if calibrated == (width, height) {
        return FrameFit::Same;
    }
    let sx = width as f64 / camera.width_px.max(1) as f64;
    let sy = height as f64 / camera.height_px.max(1) as f64;
    if (sx / sy - 1.0).abs() <= 0.01 {
        FrameFit::Scaled {
            from: calibrated,
            to: (width, height),
        }
    } else {
        FrameFit::Mismatch {
            calibrated,
            frame: (width, height),
        }
    }
}

impl OverheadPipeline {
    /// A pipeline classifying with `lut` and placing objects through `camera`.
    #[must_use]
    pub fn new(lut: LookupTable, camera: OverheadCamera, params: OverheadParams) -> Self {
        Self {
            lut,
            camera,
            params,
            classified: ClassifiedImage::default(),
            blobs: BlobSet::default(),
            detections: OverheadDetections::default(),
            timings: OverheadTimings::default(),
        }
    }

    /// Runs every stage on a frame; the results stay until the next one.
    pub fn process(&mut self, frame: &Frame) -> &OverheadDetections {
        let t0 = Instant::now();
        classify_into(frame, &self.lut, &mut self.classified);
        let t1 = Instant::now();
        self.blobs.find(&self.classified, Connectivity::Eight);
        let t2 = Instant::now();
        let parts;
        (self.detections, parts) = match self.camera_for(frame) {
            Some(camera) => {
                recognise_overhead_timed(&self.classified, &self.blobs, &camera, &self.params)
            }
            None => Default::default(),
        };
        self.timings = OverheadTimings {
            classify: t1 - t0,
            blobs: t2 - t1,
            recognition: t2.elapsed(),
            parts,
        };
        &self.detections
    }

    /// The camera for a frame: the calibration's, scaled to a frame of another size with the
    /// same shape; `None` for a frame of another shape (nothing is placed then: the calibration
    /// was made for another camera or view).
    fn camera_for(&self, frame: &Frame) -> Option<OverheadCamera> {
        let (w, h) = (frame.width(), frame.height());
        match frame_fit(&self.camera, w, h) {
            FrameFit::Same => Some(self.camera),
            FrameFit::Mismatch { .. } => None,
            FrameFit::Scaled { .. } => Some(self.camera.scaled_to(w, h)),
        }
    }

    /// The last frame's classified image.
    #[must_use]
    pub fn classified(&self) -> &ClassifiedImage {
        &self.classified
    }

    /// The last frame's blobs.
    #[must_use]
    pub fn blobs(&self) -> &BlobSet {
        &self.blobs
    }

    /// The last frame's detections.
    #[must_use]
    pub fn detections(&self) -> &OverheadDetections {
        &self.detections
    }

    /// The last frame's stage timings.
    #[must_use]
    pub fn timings(&self) -> OverheadTimings {
        self.timings
    }

    /// The camera in use.
    #[must_use]
    pub fn camera(&self) -> &OverheadCamera {
        &self.camera
    }

    /// Replaces the camera (a new calibration).
    pub fn set_camera(&mut self, camera: OverheadCamera) {
        self.camera = camera;
    }

    /// The recogniser's settings in use.
    #[must_use]
    pub const fn params(&self) -> &OverheadParams {
        &self.params
    }

    /// Replaces the recogniser's settings (the parameters were tuned or another field chosen).
    pub fn set_params(&mut self, params: OverheadParams) {
        self.params = params;
    }

    /// The table in use.
    #[must_use]
    pub fn lut(&self) -> &LookupTable {
        &self.lut
    }

    /// Replaces the table.
    pub fn set_lut(&mut self, lut: LookupTable) {
        self.lut = lut;
    }
}
