//! `--ssl-vision HOST:PORT`: a command's overhead detections sent as SSL-Vision packets while it
//! runs (`eotn overhead detect`, one camera or a session's; `eotn wmd` calls the same
//! [`SslOut`]). What is sent is in docs/formats.md, "SSL-Vision packets".
//!
//! Opening says on stderr, per camera, the one distortion coefficient fitted to its lens and
//! how far that model is from eotn's (RMS and largest residual over the image, pixels); the
//! end says how many packets went out.

use std::collections::BTreeMap;

use crate::overhead::{FieldDescription, OverheadDetections};
use crate::ssl_vision::geometry::geometry_data;
use crate::ssl_vision::sender::SslSender;
use crate::ssl_vision::{CameraEntry, detection_frame};

/// A running `--ssl-vision` output; see the module documentation.
#[derive(Debug)]
pub struct SslOut {
    sender: SslSender,
    /// Each camera's next frame number.
    numbers: BTreeMap<u32, u32>,
    plate_height_cm: f64,
}

impl SslOut {
    /// Opens the socket to `address` (`HOST:PORT`) and prepares the geometry of `field` and
    /// `cameras` (sent first and every few seconds); says each camera's κ fit on stderr.
    ///
    /// # Errors
    /// An address that does not parse or resolve, or no socket.
    pub fn open(
        address: &str,
        field: &FieldDescription,
        cameras: &[CameraEntry],
    ) -> anyhow::Result<Self> {
        let mut sender = SslSender::new(address)?;
        let (geometry, calibrations) = geometry_data(field, cameras);
        for c in &calibrations {
            eprintln!(
                "ssl-vision: camera {}: distortion κ = {:.5} fitted to eotn's lens over {} pixels (every {} px): residual RMS {:.2} px, largest {:.2} px{}",
                c.message.camera_id,
                c.fit.kappa,
                c.fit.samples,
                crate::ssl_vision::geometry::GRID_STEP_PX,
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
            );
        }
        sender.set_geometry(geometry);
        Ok(Self {
            sender,
            numbers: BTreeMap::new(),
            plate_height_cm: field.plate_height_cm,
        })
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

    /// Says on stderr what was sent.
    pub fn finish(&self) {
        eprintln!("{}", self.sender.summary());
    }
}

/// The `camera_id` of a session camera.
#[must_use]
pub fn session_camera_id(id: crate::session::SslCameraId) -> u32 {
    u32::from(id.0)
}
