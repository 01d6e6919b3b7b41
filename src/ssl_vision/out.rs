//! Sending a command's or the app's overhead detections as SSL-Vision packets while it runs
//! (`eotn overhead detect --ssl-vision`, `eotn wmd --ssl-vision`, `eotn open --ssl-vision` and
//! the app's overhead menu): [`SslOut`] numbers each camera's frames, stamps `t_sent`, and keeps
//! the geometry (the field and each camera's calibration in ssl-vision's model) to send first
//! and every few seconds. What is sent is in docs/formats.md, "SSL-Vision packets".

use std::collections::BTreeMap;

use super::geometry::{CameraCalibration, geometry_data};
use super::sender::{SendError, SslSender};
use super::{CameraEntry, detection_frame};
use crate::overhead::merge::SslCameraId;
use crate::overhead::{FieldDescription, OverheadDetections};

/// A running output; see the module documentation.
#[derive(Debug)]
pub struct SslOut {
    sender: SslSender,
    /// Each camera's next frame number.
    numbers: BTreeMap<u32, u32>,
    plate_height_cm: f64,
    /// Each camera's calibration as sent, with the fit of its distortion coefficient.
    calibrations: Vec<CameraCalibration>,
}

impl SslOut {
    /// Opens the socket to `address` (`HOST:PORT`) and prepares the geometry of `field` and
    /// `cameras` (sent first and every few seconds).
    ///
    /// # Errors
    /// [`SendError`]: an address that does not parse or resolve, or no socket.
    pub fn open(
        address: &str,
        field: &FieldDescription,
        cameras: &[CameraEntry],
    ) -> Result<Self, SendError> {
        let mut out = Self {
            sender: SslSender::new(address)?,
            numbers: BTreeMap::new(),
            plate_height_cm: field.plate_height_cm,
            calibrations: Vec::new(),
        };
        out.set_geometry(field, cameras);
        Ok(out)
    }

    /// Sends this field and these cameras as the geometry from now on (a calibration or field
    /// changed), at once with the next frame.
    pub fn set_geometry(&mut self, field: &FieldDescription, cameras: &[CameraEntry]) {
        let (geometry, calibrations) = geometry_data(field, cameras);
        self.sender.set_geometry(geometry);
        self.plate_height_cm = field.plate_height_cm;
        self.calibrations = calibrations;
    }

    /// One line per camera on the distortion coefficient κ fitted to its lens and how far that
    /// model is from eotn's (RMS and largest residual over the image, pixels).
    #[must_use]
    pub fn fit_lines(&self) -> Vec<String> {
        self.calibrations
            .iter()
            .map(|c| {
                format!(
                    "ssl-vision: camera {}: distortion κ = {:.5} fitted to eotn's lens over {} pixels (every {} px): residual RMS {:.2} px, largest {:.2} px{}",
                    c.message.camera_id,
                    c.fit.kappa,
                    c.fit.samples,
                    super::geometry::GRID_STEP_PX,
                    c.fit.rms_px,
                    c.fit.max_px,
                    if c.fit.skipped > 0 {
                        format!(
                            " ({} grid pixels where the lens folds over left out)",
                            c.fit.skipped
                        )
                    } else {
                        String::new()
                    }
                )
            })
            .collect()
    }

    /// Sends one camera's detections of a frame captured at `time_ns` (the recording's clock).
    pub fn send(&mut self, camera_id: u32, time_ns: u64, detections: &OverheadDetections) {
        let number = self.numbers.entry(camera_id).or_insert(0);
        let t_sent = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0.0, |d| d.as_secs_f64());
        let frame = detection_frame(
            camera_id,
            *number,
            (time_ns as f64 * 1e-9, t_sent),
            detections,
            self.plate_height_cm,
        );
        *number = number.wrapping_add(1);
        self.sender.send_frame(frame);
    }

    /// The sender: where packets go, how many went, the last error.
    #[must_use]
    pub const fn sender(&self) -> &SslSender {
        &self.sender
    }

    /// One line on what was sent.
    #[must_use]
    pub fn summary(&self) -> String {
        self.sender.summary()
    }
}

/// The `camera_id` of a session camera.
#[must_use]
pub fn session_camera_id(id: SslCameraId) -> u32 {
    u32::from(id.0)
}
