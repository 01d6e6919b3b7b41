//! The shown frame as packed RGB, made only when something asks for it.

use std::sync::OnceLock;

use crate::frame::Frame;

/// The shown frame's RGB (3 bytes a pixel, row-major), converted the first time something asks
/// for it after the frame changed. While a stream plays, the views build their textures straight
/// from the YUV frame and nothing needs the whole frame in RGB: converting every shown
/// 1920×1200 frame cost 9 ms of each step (docs/speed.md). Export, the undistorted view, cameras
/// side by side and full-resolution textures ask for it.
#[derive(Debug, Default)]
pub(super) struct ShownRgb(OnceLock<Vec<u8>>);

impl ShownRgb {
    /// Forgets the previous frame's RGB: call whenever another frame is shown.
    pub(super) fn reset(&mut self) {
        self.0 = OnceLock::new();
    }

    /// The RGB of `frame`, the frame shown since the last [`ShownRgb::reset`]; empty without one.
    pub(super) fn get(&self, frame: Option<&Frame>) -> &[u8] {
        match frame {
            Some(f) => self.0.get_or_init(|| f.to_rgb()),
            None => &[],
        }
    }
}

impl super::Workspace {
    /// The shown frame as packed RGB (converted on the first call after the frame changed).
    #[must_use]
    pub fn rgb(&self) -> &[u8] {
        self.rgb.get(self.frame())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;

    #[test]
    fn converts_once_per_frame_and_again_after_a_reset() {
        let grey = Frame::filled_uyvy(4, 2, Yuv::new(126, 128, 128)).expect("frame");
        let white = Frame::filled_uyvy(4, 2, Yuv::new(235, 128, 128)).expect("frame");
        let mut rgb = ShownRgb::default();
        assert!(rgb.get(None).is_empty());
        assert_eq!(rgb.get(Some(&grey)), grey.to_rgb().as_slice());
        // Asked again for the same frame, the kept conversion is handed out.
        assert_eq!(rgb.get(Some(&grey)).as_ptr(), rgb.get(Some(&grey)).as_ptr());
        rgb.reset();
        assert_eq!(rgb.get(Some(&white)), vec![255; 4 * 2 * 3].as_slice());
    }
}
