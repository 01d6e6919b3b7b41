//! What the camera adds to the ideal image the renderer computes: noise, vignetting with blue
//! corners, the rolling shutter's read-out time. A rendering detail, not part of the world
//! ([`crate::model::scene`]).

use serde::{Deserialize, Serialize};

/// What the camera adds to the ideal image.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CameraEffects {
    /// Standard deviation of the luma noise, code values.
    pub noise_y: f64,
    /// Standard deviation of the chroma noise, code values.
    pub noise_uv: f64,
    /// Brightness lost in the far corners, fraction (the ERS-7's is strong).
    pub vignetting: f64,
    /// Shift of U (towards blue) in the far corners, code values (the ERS-7's corners are blue).
    pub corner_blue_u: f64,
    /// Time to read all rows, seconds; 0 turns the rolling shutter off.
    pub readout_s: f64,
}

impl CameraEffects {
    /// The ERS-7 head camera: visible noise, strong vignetting with blue corners, rows read over
    /// one 1/30 s frame period.
    pub const ERS7: Self = Self {
        noise_y: 2.5,
        noise_uv: 2.0,
        vignetting: 0.35,
        corner_blue_u: 8.0,
        readout_s: 1.0 / 30.0,
    };

    /// An overhead video camera: some noise, mild vignetting, global shutter.
    pub const OVERHEAD: Self = Self {
        noise_y: 2.0,
        noise_uv: 1.5,
        vignetting: 0.15,
        corner_blue_u: 0.0,
        readout_s: 0.0,
    };

    /// No effects at all: the ideal image (tests).
    pub const NONE: Self = Self {
        noise_y: 0.0,
        noise_uv: 0.0,
        vignetting: 0.0,
        corner_blue_u: 0.0,
        readout_s: 0.0,
    };
}

impl Default for CameraEffects {
    fn default() -> Self {
        Self::ERS7
    }
}
