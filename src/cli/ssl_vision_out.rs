//! `--ssl-vision HOST:PORT`: a command's overhead detections sent as SSL-Vision packets while it
//! runs (`eotn overhead detect`, one camera or a session's; `eotn wmd`), through
//! [`crate::ssl_vision::out::SslOut`], which the app uses too.
//!
//! Opening says on stderr, per camera, the one distortion coefficient fitted to its lens and
//! how far that model is from eotn's; the end says how many packets went out.

use crate::overhead::FieldDescription;
use crate::ssl_vision::CameraEntry;
pub use crate::ssl_vision::out::{SslOut, session_camera_id};

/// Opens the output to `address` for `field` and `cameras`, saying each camera's κ fit.
///
/// # Errors
/// An address that does not parse or resolve, or no socket.
pub fn open(
    address: &str,
    field: &FieldDescription,
    cameras: &[CameraEntry],
) -> anyhow::Result<SslOut> {
    let out = SslOut::open(address, field, cameras)?;
    for line in out.fit_lines() {
        eprintln!("{line}");
    }
    Ok(out)
}

/// Says on stderr what was sent.
pub fn finish(out: &SslOut) {
    eprintln!("{}", out.summary());
}
