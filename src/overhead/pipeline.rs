//! The overhead pipeline: classification and blobs as for the robot camera, then the overhead
//! recogniser through a calibration, with per-stage timings. The app and `eotn overhead detect`
//! both run this for frames whose source is an overhead camera.

use std::time::{Duration, Instant};

use crate::blobs::{BlobSet, Connectivity};
use crate::classify::{ClassifiedImage, classify_into};
use crate::frame::Frame;
use crate::geometry::OverheadCamera;
use crate::lut::LookupTable;

use super::recognise::{OverheadDetections, OverheadParams, recognise_overhead};

/// How long each stage took on the last frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OverheadTimings {
    /// Table lookup of every pixel.
    pub classify: Duration,
    /// Run-length encoding and union-find.
    pub blobs: Duration,
    /// Ball and markers.
    pub recognition: Duration,
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
        let camera = self.camera_for(frame);
        self.detections = recognise_overhead(&self.classified, &self.blobs, &camera, &self.params);
        self.timings = OverheadTimings {
            classify: t1 - t0,
            blobs: t2 - t1,
            recognition: t2.elapsed(),
        };
        &self.detections
    }

    /// The camera, rescaled when a frame's size differs from the calibration's.
    fn camera_for(&self, frame: &Frame) -> OverheadCamera {
        let (w, h) = (frame.width(), frame.height());
        if (w, h) == (self.camera.width_px, self.camera.height_px) {
            return self.camera;
        }
        let s = w as f64 / self.camera.width_px.max(1) as f64;
        let mut c = self.camera;
        c.width_px = w;
        c.height_px = h;
        c.focal_px *= s;
        c.centre.x_px *= s;
        c.centre.y_px *= h as f64 / self.camera.height_px.max(1) as f64;
        c
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
