//! YUV camera frames: the pipeline's input.
//!
//! Robot cameras deliver UYVY 4:2:2 (the AIBO's 208×160, an overhead camera's 640×480, any even
//! width); some sources deliver YUV 4:4:4, packed or planar. [`Frame`] holds any of these and
//! answers [`Frame::pixel`] in one way, so later stages never care which layout came in. The hot
//! classification loop reads the raw bytes ([`Frame::data`]) directly.
//!
//! Display conversion to RGB uses the exact integer BT.601 formula of `FORMATS.md`
//! ([`yuv_to_rgb`]); everything else comes in through one conversion into the tables' studio-range
//! YUV ([`colour`]: [`rgb_to_yuv`] for RGB, JPEG's own YCbCr mapped without RGB), from image
//! files ([`load_frame`]), compressed images ([`compressed`]) and raw message encodings
//! ([`encodings`]: YUYV, RGB/BGR, mono, NV12, Bayer).
//!
//! Positions in a frame are [`ImagePoint`]s (pixels, sub-pixel) and [`PixelBox`]es (whole
//! pixels), shared by every later stage.

pub mod colour;
pub mod compressed;
pub mod encodings;
mod image_point;
mod io;
mod pixel_box;

pub use compressed::{CompressedFormat, CompressedImageError, decode_compressed, decode_jpeg};
pub use encodings::{PixelEncoding, RawImage, RawImageError, decode_raw, decode_raw_owned};
pub use image_point::{ImagePoint, xy_array};
pub use io::{
    FrameFileError, MAX_FRAME_PIXELS, MAX_FRAME_SIDE, display_name, infer_uyvy_size, is_image_file,
    load_frame, load_raw_uyvy, save_rgb_png,
};
pub use pixel_box::{CutOff, PixelBox};

use serde::{Deserialize, Serialize};
use std::ops::Range;
use thiserror::Error;

/// Width × height of the AIBO ERS-7 head camera, pixels.
pub const AIBO_SIZE: (usize, usize) = (208, 160);
/// Width × height of an overhead camera, pixels.
pub const OVERHEAD_SIZE: (usize, usize) = (640, 480);

/// One pixel's luma and chroma, each 0..=255.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub struct Yuv {
    /// Luma.
    pub y: u8,
    /// Blue-difference chroma (Cb).
    pub u: u8,
    /// Red-difference chroma (Cr).
    pub v: u8,
}

impl Yuv {
    /// A pixel from its three channels.
    #[must_use]
    pub const fn new(y: u8, u: u8, v: u8) -> Self {
        Self { y, u, v }
    }
}

/// How a frame's bytes are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum PixelLayout {
    /// 4:2:2 packed, 4 bytes `U Y0 V Y1` per pixel pair; row = 2 × width bytes.
    Uyvy,
    /// 4:4:4 packed, 3 bytes `Y U V` per pixel; row = 3 × width bytes.
    Yuv444Packed,
    /// 4:4:4 planar: a full Y plane, then U, then V; each width × height bytes.
    Yuv444Planar,
}

impl PixelLayout {
    /// Bytes a frame of this layout and size occupies.
    #[must_use]
    pub const fn frame_len(self, width: usize, height: usize) -> usize {
        match self {
            Self::Uyvy => width * height * 2,
            Self::Yuv444Packed | Self::Yuv444Planar => width * height * 3,
        }
    }
}

/// Why a frame could not be made from the given bytes.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum FrameError {
    /// Width or height is zero, or too large for the pipeline (65,535 pixels a side).
    #[error("frame size {width}×{height} is not usable (each side 1..=65535 pixels)")]
    BadSize {
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
    },
    /// UYVY shares chroma between two pixels, so the width must be even.
    #[error("UYVY width must be even, got {width}")]
    OddWidth {
        /// Width, pixels.
        width: usize,
    },
    /// The byte count does not match the size and layout.
    #[error("{len} bytes do not make a {width}×{height} {layout:?} frame ({expected} bytes)")]
    WrongLength {
        /// Bytes given.
        len: usize,
        /// Bytes needed.
        expected: usize,
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
        /// Layout asked for.
        layout: PixelLayout,
    },
}

/// A YUV image in one of the [`PixelLayout`]s.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Frame {
    width: usize,
    height: usize,
    layout: PixelLayout,
    data: Vec<u8>,
}

impl Frame {
    /// A frame from raw bytes, checked against size and layout.
    ///
    /// # Errors
    /// [`FrameError`] when the size is zero or huge, a UYVY width is odd, or the length is wrong.
    pub fn new(
        width: usize,
        height: usize,
        layout: PixelLayout,
        data: Vec<u8>,
    ) -> Result<Self, FrameError> {
        if width == 0 || height == 0 || width > 65_535 || height > 65_535 {
            return Err(FrameError::BadSize { width, height });
        }
        if layout == PixelLayout::Uyvy && !width.is_multiple_of(2) {
            return Err(FrameError::OddWidth { width });
        }
        let expected = layout.frame_len(width, height);
        if data.len() != expected {
            return Err(FrameError::WrongLength {
                len: data.len(),
                expected,
                width,
                height,
                layout,
            });
        }
        Ok(Self {
            width,
            height,
            layout,
            data,
        })
    }

    /// A UYVY frame from raw bytes.
    ///
    /// # Errors
    /// As [`Frame::new`].
    pub fn from_uyvy(width: usize, height: usize, data: Vec<u8>) -> Result<Self, FrameError> {
        Self::new(width, height, PixelLayout::Uyvy, data)
    }

    /// A UYVY frame of one colour everywhere; handy for tests and placeholders.
    ///
    /// # Errors
    /// As [`Frame::new`].
    pub fn filled_uyvy(width: usize, height: usize, colour: Yuv) -> Result<Self, FrameError> {
        let pair = [colour.u, colour.y, colour.v, colour.y];
        let data = pair
            .iter()
            .copied()
            .cycle()
            .take(PixelLayout::Uyvy.frame_len(width, height))
            .collect();
        Self::from_uyvy(width, height, data)
    }

    /// A UYVY frame built pixel by pixel from a function of (x, y); the two pixels of each pair
    /// share the rounded mean of their chroma, as a UYVY camera does.
    ///
    /// # Errors
    /// As [`Frame::new`].
    pub fn uyvy_from_fn(
        width: usize,
        height: usize,
        mut pixel: impl FnMut(usize, usize) -> Yuv,
    ) -> Result<Self, FrameError> {
        if !width.is_multiple_of(2) {
            return Err(FrameError::OddWidth { width });
        }
        let mut data = Vec::with_capacity(width * height * 2);
        for y in 0..height {
            for x in (0..width).step_by(2) {
                let a = pixel(x, y);
                let b = pixel(x + 1, y);
                data.push(mean_u8(a.u, b.u));
                data.push(a.y);
                data.push(mean_u8(a.v, b.v));
                data.push(b.y);
            }
        }
        Self::from_uyvy(width, height, data)
    }

    /// A 4:4:4 packed frame built pixel by pixel from a function of (x, y).
    ///
    /// # Errors
    /// As [`Frame::new`].
    pub fn yuv444_from_fn(
        width: usize,
        height: usize,
        mut pixel: impl FnMut(usize, usize) -> Yuv,
    ) -> Result<Self, FrameError> {
        let mut data = Vec::with_capacity(width * height * 3);
        for y in 0..height {
            for x in 0..width {
                let p = pixel(x, y);
                data.extend_from_slice(&[p.y, p.u, p.v]);
            }
        }
        Self::new(width, height, PixelLayout::Yuv444Packed, data)
    }

    /// Width, pixels.
    #[must_use]
    pub const fn width(&self) -> usize {
        self.width
    }

    /// Height, pixels.
    #[must_use]
    pub const fn height(&self) -> usize {
        self.height
    }

    /// Number of pixels.
    #[must_use]
    pub const fn pixel_count(&self) -> usize {
        self.width * self.height
    }

    /// Byte layout.
    #[must_use]
    pub const fn layout(&self) -> PixelLayout {
        self.layout
    }

    /// The raw bytes, laid out as [`Frame::layout`] says.
    #[must_use]
    pub fn data(&self) -> &[u8] {
        &self.data
    }

    /// Gives the bytes back (to reuse the allocation).
    #[must_use]
    pub fn into_data(self) -> Vec<u8> {
        self.data
    }

    /// The pixel at column `x`, row `y`, or `None` outside the frame.
    #[must_use]
    pub fn pixel(&self, x: usize, y: usize) -> Option<Yuv> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let w = self.width;
        let d = &self.data;
        Some(match self.layout {
            PixelLayout::Uyvy => {
                let pair = (y * w + (x & !1)) * 2;
                let luma = if x.is_multiple_of(2) {
                    pair + 1
                } else {
                    pair + 3
                };
                Yuv::new(d[luma], d[pair], d[pair + 2])
            }
            PixelLayout::Yuv444Packed => {
                let i = (y * w + x) * 3;
                Yuv::new(d[i], d[i + 1], d[i + 2])
            }
            PixelLayout::Yuv444Planar => {
                let i = y * w + x;
                let plane = w * self.height;
                Yuv::new(d[i], d[plane + i], d[2 * plane + i])
            }
        })
    }

    /// Calls `f(x, y, pixel)` for every pixel in raster order.
    pub fn for_each_pixel(&self, mut f: impl FnMut(usize, usize, Yuv)) {
        match self.layout {
            PixelLayout::Uyvy => {
                for (i, q) in self.data.chunks_exact(4).enumerate() {
                    let x = (i * 2) % self.width;
                    let y = (i * 2) / self.width;
                    f(x, y, Yuv::new(q[1], q[0], q[2]));
                    f(x + 1, y, Yuv::new(q[3], q[0], q[2]));
                }
            }
            PixelLayout::Yuv444Packed => {
                for (i, p) in self.data.chunks_exact(3).enumerate() {
                    f(i % self.width, i / self.width, Yuv::new(p[0], p[1], p[2]));
                }
            }
            PixelLayout::Yuv444Planar => {
                let n = self.pixel_count();
                let (ys, rest) = self.data.split_at(n);
                let (us, vs) = rest.split_at(n);
                for (i, ((&y, &u), &v)) in ys.iter().zip(us).zip(vs).enumerate() {
                    f(i % self.width, i / self.width, Yuv::new(y, u, v));
                }
            }
        }
    }

    /// This frame as UYVY (4:4:4 chroma averaged over each pixel pair); a copy even if it already
    /// is UYVY.
    ///
    /// # Errors
    /// [`FrameError::OddWidth`] when a 4:4:4 frame has an odd width.
    pub fn to_uyvy(&self) -> Result<Self, FrameError> {
        if self.layout == PixelLayout::Uyvy {
            return Ok(self.clone());
        }
        Self::uyvy_from_fn(self.width, self.height, |x, y| {
            self.pixel(x, y).unwrap_or_default()
        })
    }

    /// The frame as packed 8-bit RGB (3 bytes a pixel, row-major) through [`yuv_to_rgb`],
    /// written into `out` (resized), so a viewer can reuse one buffer.
    pub fn to_rgb_into(&self, out: &mut Vec<u8>) {
        out.clear();
        out.resize(self.pixel_count() * 3, 0);
        match self.layout {
            // A pixel pair at a time, written in place: the app converts every frame it shows
            // (2.3 million pixels at 1920×1200), and a call per pixel with its position worked
            // out by division, appending to the buffer, cost several times this.
            PixelLayout::Uyvy => {
                for (q, rgb) in self.data.chunks_exact(4).zip(out.chunks_exact_mut(6)) {
                    let (u, v) = (q[0], q[2]);
                    rgb[..3].copy_from_slice(&yuv_to_rgb(Yuv::new(q[1], u, v)));
                    rgb[3..].copy_from_slice(&yuv_to_rgb(Yuv::new(q[3], u, v)));
                }
            }
            PixelLayout::Yuv444Packed => {
                for (p, rgb) in self.data.chunks_exact(3).zip(out.chunks_exact_mut(3)) {
                    rgb.copy_from_slice(&yuv_to_rgb(Yuv::new(p[0], p[1], p[2])));
                }
            }
            PixelLayout::Yuv444Planar => {
                let w = self.width;
                self.for_each_pixel(|x, y, p| {
                    let i = (y * w + x) * 3;
                    out[i..i + 3].copy_from_slice(&yuv_to_rgb(p));
                });
            }
        }
    }

    /// The RGB ([`yuv_to_rgb`]) of the top-left pixel of each `step`×`step` block, with an
    /// opaque alpha (255), in raster order: (0, 0), (step, 0), …, then the row `step` down;
    /// `width.div_ceil(step)` × `height.div_ceil(step)` of them. What a view showing the frame
    /// smaller than 1:1 with nearest filtering shows of it, converted without the rest. A `step`
    /// of 0 counts as 1.
    ///
    /// Each row is converted by a loop over whole pixel pairs into a slice made beforehand (no
    /// per-pixel position, bounds or capacity checks), which the compiler vectorises: a
    /// 1920×1200 frame at a step of 2 took 5 ms as a call per pixel (docs/speed.md).
    #[must_use]
    pub fn rgba_every(&self, step: usize) -> Vec<[u8; 4]> {
        self.rgba_part(step, 0..self.width, 0..self.height)
    }

    /// The RGB ([`yuv_to_rgb`]) of the pixels in columns `cols` and rows `rows` (each clamped to
    /// the frame), with an opaque alpha, in raster order: what a view zoomed in past 1:1 shows
    /// of a large frame, converted without the rest. Give UYVY frames an even start and width
    /// (a pixel pair shares its chroma); an odd last column is left black.
    #[must_use]
    pub fn rgba_in(&self, cols: Range<usize>, rows: Range<usize>) -> Vec<[u8; 4]> {
        self.rgba_part(1, cols, rows)
    }

    /// The pixels of `cols` × `rows` (clamped to the frame) at `step` (0 counts as 1): what
    /// [`Frame::rgba_every`] and [`Frame::rgba_in`] hand out.
    fn rgba_part(&self, step: usize, cols: Range<usize>, rows: Range<usize>) -> Vec<[u8; 4]> {
        let (step, w, n) = (step.max(1), self.width, self.pixel_count());
        let (x0, x1) = (cols.start.min(w), cols.end.min(w));
        let (y0, y1) = (rows.start.min(self.height), rows.end.min(self.height));
        let tw = x1.saturating_sub(x0).div_ceil(step);
        let mut out = vec![[0, 0, 0, 255]; tw * y1.saturating_sub(y0).div_ceil(step)];
        if tw == 0 {
            return out;
        }
        let rgba = |p: Yuv| {
            let [r, g, b] = yuv_to_rgb(p);
            [r, g, b, 255]
        };
        for (o, y) in out.chunks_exact_mut(tw).zip((y0..y1).step_by(step)) {
            let (start, end) = (y * w + x0, y * w + x1);
            match self.layout {
                PixelLayout::Uyvy => uyvy_row_every(&self.data[start * 2..end * 2], step, o),
                PixelLayout::Yuv444Packed => {
                    let row = &self.data[start * 3..end * 3];
                    for (o, p) in o.iter_mut().zip(row.chunks_exact(3).step_by(step)) {
                        *o = rgba(Yuv::new(p[0], p[1], p[2]));
                    }
                }
                PixelLayout::Yuv444Planar => {
                    let at = |plane: usize| &self.data[plane * n + start..plane * n + end];
                    let (ys, us, vs) = (at(0), at(1), at(2));
                    for (o, i) in o.iter_mut().zip((0..end - start).step_by(step)) {
                        *o = rgba(Yuv::new(ys[i], us[i], vs[i]));
                    }
                }
            }
        }
        out
    }

    /// The frame as packed 8-bit RGB; see [`Frame::to_rgb_into`].
    #[must_use]
    pub fn to_rgb(&self) -> Vec<u8> {
        let mut out = Vec::new();
        self.to_rgb_into(&mut out);
        out
    }
}

fn mean_u8(a: u8, b: u8) -> u8 {
    // Rounded mean; the sum of two u8 fits u16, the result fits u8.
    u8::try_from((u16::from(a) + u16::from(b)).div_ceil(2)).unwrap_or(u8::MAX)
}

/// One UYVY row's pixels at `step` ([`Frame::rgba_every`]) into `out` (its texels, made
/// beforehand): whole pixel pairs at steps 1 and 2, the common cases, in loops the compiler
/// vectorises; other steps a pixel at a time.
fn uyvy_row_every(row: &[u8], step: usize, out: &mut [[u8; 4]]) {
    let rgba = |y: u8, u: u8, v: u8| {
        let [r, g, b] = yuv_to_rgb(Yuv::new(y, u, v));
        [r, g, b, 255]
    };
    match step {
        1 => {
            for (q, o) in row.chunks_exact(4).zip(out.chunks_exact_mut(2)) {
                o[0] = rgba(q[1], q[0], q[2]);
                o[1] = rgba(q[3], q[0], q[2]);
            }
        }
        2 => {
            for (q, o) in row.chunks_exact(4).zip(out.iter_mut()) {
                *o = rgba(q[1], q[0], q[2]);
            }
        }
        _ => {
            for (o, x) in out.iter_mut().zip((0..row.len() / 2).step_by(step)) {
                let pair = (x & !1) * 2;
                *o = rgba(row[pair + 1 + 2 * (x & 1)], row[pair], row[pair + 2]);
            }
        }
    }
}

/// Clamps to 0..=255. Written so the compiler emits conditional moves, not branches: the
/// display conversion runs on millions of pixels a frame, where `u8::try_from` kept a branch
/// per channel that mispredicted on real images.
#[inline]
fn clip(v: i32) -> u8 {
    // In range after the clamp: the cast cannot truncate.
    v.clamp(0, 255) as u8
}

/// YUV → RGB for display, the exact integer BT.601 studio-range formula of `FORMATS.md`.
///
/// ```
/// use eotn::frame::{yuv_to_rgb, Yuv};
/// assert_eq!(yuv_to_rgb(Yuv::new(16, 128, 128)), [0, 0, 0]);
/// assert_eq!(yuv_to_rgb(Yuv::new(235, 128, 128)), [255, 255, 255]);
/// ```
#[must_use]
#[inline]
pub fn yuv_to_rgb(p: Yuv) -> [u8; 3] {
    let c = 298 * (i32::from(p.y) - 16);
    let d = i32::from(p.u) - 128;
    let e = i32::from(p.v) - 128;
    [
        clip((c + 409 * e + 128) >> 8),
        clip((c - 100 * d - 208 * e + 128) >> 8),
        clip((c + 516 * d + 128) >> 8),
    ]
}

/// RGB → YUV, BT.601 studio range (Y 16..235, U and V 16..240): the inverse of
/// [`yuv_to_rgb`] up to rounding, used to bring PNG/JPEG images into the pipeline.
///
/// `Y = 16 + (65.481 R + 128.553 G + 24.966 B) / 255`,
/// `U = 128 + (−37.797 R − 74.203 G + 112 B) / 255`,
/// `V = 128 + (112 R − 93.786 G − 18.214 B) / 255`, rounded to nearest.
///
/// ```
/// use eotn::frame::{rgb_to_yuv, Yuv};
/// assert_eq!(rgb_to_yuv([255, 255, 255]), Yuv::new(235, 128, 128));
/// ```
#[must_use]
pub fn rgb_to_yuv(rgb: [u8; 3]) -> Yuv {
    let [r, g, b] = rgb.map(f64::from);
    let y = 16.0 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0;
    let u = 128.0 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0;
    let v = 128.0 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0;
    Yuv::new(round_u8(y), round_u8(u), round_u8(v))
}

/// Rounds and clamps a float to 0..=255 (NaN becomes 0).
#[must_use]
pub fn round_u8(v: f64) -> u8 {
    if v.is_nan() {
        return 0;
    }
    // After the clamp the value is exactly representable in u8.
    #[expect(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "clamped to 0..=255"
    )]
    let out = v.round().clamp(0.0, 255.0) as u8;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb_of_a_frame_is_each_pixels_rgb_in_every_layout() {
        let yuv = |x: usize, y: usize| {
            Yuv::new(
                u8::try_from(16 + (x * 13 + y * 7) % 220).unwrap_or(0),
                u8::try_from((x * 31 + y * 3) % 256).unwrap_or(0),
                u8::try_from((x * 5 + y * 29) % 256).unwrap_or(0),
            )
        };
        let frames = [
            Frame::uyvy_from_fn(10, 4, yuv).unwrap(),
            Frame::yuv444_from_fn(10, 4, yuv).unwrap(),
        ];
        for f in frames {
            let rgb = f.to_rgb();
            assert_eq!(rgb.len(), 10 * 4 * 3);
            for y in 0..4 {
                for x in 0..10 {
                    let i = (y * 10 + x) * 3;
                    assert_eq!(
                        rgb[i..i + 3],
                        yuv_to_rgb(f.pixel(x, y).unwrap()),
                        "{:?} ({x}, {y})",
                        f.layout()
                    );
                }
            }
        }
    }

    /// A `w`×`h` frame of a varied pattern in each of the three layouts.
    fn in_every_layout(w: usize, h: usize) -> [Frame; 3] {
        let yuv = |x: usize, y: usize| {
            Yuv::new(
                u8::try_from(16 + (x * 13 + y * 7) % 220).unwrap_or(0),
                u8::try_from((x * 31 + y * 3) % 256).unwrap_or(0),
                u8::try_from((x * 5 + y * 29) % 256).unwrap_or(0),
            )
        };
        let packed = Frame::yuv444_from_fn(w, h, yuv).unwrap();
        let mut planar = vec![0; w * h * 3];
        packed.for_each_pixel(|x, y, p| {
            let i = y * w + x;
            (planar[i], planar[w * h + i], planar[2 * w * h + i]) = (p.y, p.u, p.v);
        });
        [
            Frame::uyvy_from_fn(w, h, yuv).unwrap(),
            packed,
            Frame::new(w, h, PixelLayout::Yuv444Planar, planar).unwrap(),
        ]
    }

    /// The opaque RGB of pixel (x, y), one pixel at a time.
    fn rgba_at(f: &Frame, x: usize, y: usize) -> [u8; 4] {
        let [r, g, b] = yuv_to_rgb(f.pixel(x, y).unwrap());
        [r, g, b, 255]
    }

    #[test]
    fn rgba_every_step_is_the_top_left_pixel_of_each_block_in_every_layout() {
        let (w, h) = (10, 7);
        for f in in_every_layout(w, h) {
            for step in 0..=5 {
                let s = step.max(1);
                let want: Vec<[u8; 4]> = (0..h)
                    .step_by(s)
                    .flat_map(|y| (0..w).step_by(s).map(move |x| (x, y)))
                    .map(|(x, y)| rgba_at(&f, x, y))
                    .collect();
                assert_eq!(f.rgba_every(step), want, "{:?} step {step}", f.layout());
            }
        }
    }

    #[test]
    fn rgba_in_is_the_frames_part_in_every_layout() {
        let (w, h) = (12, 6);
        for f in in_every_layout(w, h) {
            for (cols, rows) in [(2..8, 1..4), (0..12, 0..6), (4..40, 5..9), (6..6, 0..6)] {
                let want: Vec<[u8; 4]> = (rows.start..rows.end.min(h))
                    .flat_map(|y| (cols.start..cols.end.min(w)).map(move |x| (x, y)))
                    .map(|(x, y)| rgba_at(&f, x, y))
                    .collect();
                let got = f.rgba_in(cols.clone(), rows.clone());
                assert_eq!(got, want, "{:?} {cols:?} {rows:?}", f.layout());
            }
        }
    }

    #[test]
    fn yuv_to_rgb_matches_hand_computed_values() {
        // Black and white points of studio range.
        assert_eq!(yuv_to_rgb(Yuv::new(16, 128, 128)), [0, 0, 0]);
        assert_eq!(yuv_to_rgb(Yuv::new(235, 128, 128)), [255, 255, 255]);
        // Y=81,U=90,V=240: c=298*65=19370, d=-38, e=112
        // R=(19370+45808+128)>>8=255 (65306>>8=255), G=(19370+3800-23296+128)>>8=0 (2>>8),
        // B=(19370-19608+128)>>8 = -110>>8 = -1 → 0
        assert_eq!(yuv_to_rgb(Yuv::new(81, 90, 240)), [255, 0, 0]);
        // Mid grey: Y=126 → c=32780 → (32780+128)>>8 = 128
        assert_eq!(yuv_to_rgb(Yuv::new(126, 128, 128)), [128, 128, 128]);
        // An orange: Y=120,U=80,V=190: c=30992,d=-48,e=62
        // R=(30992+25358+128)>>8=56478>>8=220; G=(30992+4800-12896+128)>>8=23024>>8=89;
        // B=(30992-24768+128)>>8=6352>>8=24
        assert_eq!(yuv_to_rgb(Yuv::new(120, 80, 190)), [220, 89, 24]);
    }

    #[test]
    fn yuv_to_rgb_clips_at_both_ends() {
        // Below black: Y=0 → negative, clipped to 0.
        assert_eq!(yuv_to_rgb(Yuv::new(0, 128, 128)), [0, 0, 0]);
        // Above white: Y=255 → (298*239+128)>>8 = 278 → 255.
        assert_eq!(yuv_to_rgb(Yuv::new(255, 128, 128)), [255, 255, 255]);
        // Extreme chroma both ways.
        // Y=128,U=255,V=0: c=33376,d=127,e=-128 → R=-18848>>8<0, G=47428>>8=185, B=99036>>8>255
        assert_eq!(yuv_to_rgb(Yuv::new(128, 255, 0)), [0, 185, 255]);
        // Y=128,U=0,V=255: c=33376,d=-128,e=127 → R=85447>>8>255, G=19888>>8=77, B<0
        assert_eq!(yuv_to_rgb(Yuv::new(128, 0, 255)), [255, 77, 0]);
    }

    #[test]
    fn rgb_to_yuv_round_trips_through_display_conversion() {
        for rgb in [
            [0, 0, 0],
            [255, 255, 255],
            [250, 110, 20],
            [45, 140, 60],
            [40, 110, 200],
        ] {
            let back = yuv_to_rgb(rgb_to_yuv(rgb));
            for (a, b) in rgb.iter().zip(back) {
                assert!(a.abs_diff(b) <= 2, "{rgb:?} → {back:?}");
            }
        }
    }

    #[test]
    fn uyvy_pixels_share_chroma_per_pair() {
        let f = Frame::from_uyvy(4, 1, vec![10, 20, 30, 40, 50, 60, 70, 80]).unwrap();
        assert_eq!(f.pixel(0, 0), Some(Yuv::new(20, 10, 30)));
        assert_eq!(f.pixel(1, 0), Some(Yuv::new(40, 10, 30)));
        assert_eq!(f.pixel(2, 0), Some(Yuv::new(60, 50, 70)));
        assert_eq!(f.pixel(3, 0), Some(Yuv::new(80, 50, 70)));
        assert_eq!(f.pixel(4, 0), None);
        assert_eq!(f.pixel(0, 1), None);
    }

    #[test]
    fn all_layouts_agree_on_pixels() {
        let pattern =
            |x: usize, y: usize| Yuv::new((x * 7 + y) as u8, (x * 3) as u8, (y * 5) as u8);
        let packed = Frame::yuv444_from_fn(6, 3, pattern).unwrap();
        let mut planar_data = vec![0; 6 * 3 * 3];
        packed.for_each_pixel(|x, y, p| {
            let i = y * 6 + x;
            planar_data[i] = p.y;
            planar_data[18 + i] = p.u;
            planar_data[36 + i] = p.v;
        });
        let planar = Frame::new(6, 3, PixelLayout::Yuv444Planar, planar_data).unwrap();
        for y in 0..3 {
            for x in 0..6 {
                assert_eq!(packed.pixel(x, y), Some(pattern(x, y)));
                assert_eq!(planar.pixel(x, y), Some(pattern(x, y)));
            }
        }
        let uyvy = packed.to_uyvy().unwrap();
        assert_eq!(uyvy.layout(), PixelLayout::Uyvy);
        assert_eq!(uyvy.pixel(3, 2).map(|p| p.y), Some(pattern(3, 2).y));
    }

    #[test]
    fn bad_sizes_are_errors_not_panics() {
        assert_eq!(
            Frame::from_uyvy(3, 2, vec![0; 12]),
            Err(FrameError::OddWidth { width: 3 })
        );
        assert!(matches!(
            Frame::from_uyvy(4, 2, vec![0; 15]),
            Err(FrameError::WrongLength {
                len: 15,
                expected: 16,
                ..
            })
        ));
        assert!(matches!(
            Frame::from_uyvy(0, 2, vec![]),
            Err(FrameError::BadSize { .. })
        ));
    }

    #[test]
    fn to_rgb_is_three_bytes_per_pixel() {
        let f = Frame::filled_uyvy(8, 2, Yuv::new(235, 128, 128)).unwrap();
        let rgb = f.to_rgb();
        assert_eq!(rgb.len(), 8 * 2 * 3);
        assert!(rgb.iter().all(|&c| c == 255));
    }
}
