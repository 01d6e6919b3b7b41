//! Sending the app's overhead detections as SSL-Vision packets (`eotn open --ssl-vision
//! HOST:PORT`, or Overhead ▸ Send SSL-Vision): every overhead frame the workspace processes —
//! played, stepped, live — goes out as a detection frame of camera 0 with its capture time on
//! the source's clock, and the geometry (the field in use, the camera's calibration in use in
//! ssl-vision's model) first, every few seconds, and again when the calibration or field
//! changes. A frame without a calibration in use has no field positions, so nothing is sent for
//! it. The UI only shows [`SslOutStatus`]; `OverheadCommand::SendSslVision` starts and stops it.

use crate::geometry::OverheadCamera;
use crate::overhead::FieldDescription;
use crate::ssl_vision::CameraEntry;
use crate::ssl_vision::out::SslOut;

use super::Workspace;

/// The `camera_id` the app's overhead camera sends as.
pub const APP_CAMERA_ID: u32 = 0;

/// A running output and what its geometry was made from.
#[derive(Debug)]
pub struct SslOutState {
    out: SslOut,
    address: String,
    camera: Option<OverheadCamera>,
    field: FieldDescription,
}

/// What the UI shows of the output.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SslOutStatus {
    /// Where the packets go (`HOST:PORT` as given).
    pub address: String,
    /// Detection packets sent.
    pub detection_packets: u64,
    /// Geometry packets sent.
    pub geometry_packets: u64,
    /// Sends that failed.
    pub failures: u64,
    /// The last send's error, while sends fail.
    pub last_error: Option<String>,
    /// The camera's distortion fit, as the CLI says it (none before a calibration is in use).
    pub fits: Vec<String>,
}

fn entries(camera: Option<OverheadCamera>) -> Vec<CameraEntry> {
    camera
        .map(|camera| CameraEntry {
            camera_id: APP_CAMERA_ID,
            camera,
        })
        .into_iter()
        .collect()
}

impl Workspace {
    /// Starts sending to `address` (`HOST:PORT`; another output is replaced), or stops.
    ///
    /// # Errors
    /// An address that does not parse or resolve, or no socket (the old output is kept).
    pub(super) fn set_ssl_out(&mut self, address: Option<String>) -> anyhow::Result<()> {
        let Some(address) = address else {
            if let Some(s) = self.overhead.ssl_out.take() {
                self.status = format!("stopped sending: {}", s.out.summary());
            }
            return Ok(());
        };
        let camera = self.overhead.camera().map(|(c, _)| *c);
        let field = self.overhead.field().clone();
        let out = SslOut::open(&address, &field, &entries(camera))?;
        for line in out.fit_lines() {
            log::info!("{line}");
        }
        self.status = format!(
            "sending SSL-Vision packets to {} (camera {APP_CAMERA_ID})",
            out.sender().target()
        );
        self.overhead.ssl_out = Some(SslOutState {
            out,
            address,
            camera,
            field,
        });
        // The shown frame goes out at once.
        self.reprocess();
        Ok(())
    }

    /// Sends the shown overhead frame's detections (captured at `time_ns`), after new geometry
    /// when the calibration or field in use changed.
    pub(super) fn send_ssl_out(&mut self, time_ns: u64) {
        let camera = self.overhead.camera().map(|(c, _)| *c);
        let Some(mut state) = self.overhead.ssl_out.take() else {
            return;
        };
        if state.camera != camera || state.field != *self.overhead.field() {
            state.camera = camera;
            state.field = self.overhead.field().clone();
            state.out.set_geometry(&state.field, &entries(camera));
        }
        if let Some(d) = self.overhead.detections() {
            state.out.send(APP_CAMERA_ID, time_ns, d);
        }
        self.overhead.ssl_out = Some(state);
    }

    /// The SSL-Vision output's state, while sending.
    #[must_use]
    pub fn ssl_out_status(&self) -> Option<SslOutStatus> {
        let s = self.overhead.ssl_out.as_ref()?;
        let sender = s.out.sender();
        Some(SslOutStatus {
            address: s.address.clone(),
            detection_packets: sender.frames_sent,
            geometry_packets: sender.geometry_sent,
            failures: sender.failures,
            last_error: sender.last_error.clone(),
            fits: s.out.fit_lines(),
        })
    }
}
