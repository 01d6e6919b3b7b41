//! Raw image encodings of `sensor_msgs/msg/Image` and `foxglove.RawImage` into frames.
//!
//! The 4:2:2 orders stay 4:2:2 (UYVY, the pipeline's own layout: YUYV is reordered, nothing is
//! lost). Everything else becomes a 4:4:4 frame: RGB and BGR (with or without alpha) through the
//! one RGB → YUV conversion ([`super::colour::RgbToYuv`]), `nv12` with its chroma up-sampled
//! bilinearly, 8-bit Bayer demosaiced linearly (bilinear with Malvar–He–Cutler's gradient
//! correction), `mono8` as grey (U = V = 128: it shows and
//! steps, but a colour table cannot classify it). `step` (bytes a row, padding included) is
//! honoured for every encoding.

use thiserror::Error;

use super::colour::RgbToYuv;
use super::{Frame, FrameError, MAX_FRAME_PIXELS, PixelLayout};

/// The colour order of an 8-bit Bayer mosaic: the colours of its top-left 2×2 cell, row by row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BayerOrder {
    /// R G / G B.
    Rggb,
    /// B G / G R.
    Bggr,
    /// G B / R G.
    Gbrg,
    /// G R / B G.
    Grbg,
}

impl BayerOrder {
    /// The colour (0 red, 1 green, 2 blue) of the photosite at (x, y).
    const fn colour_at(self, x: usize, y: usize) -> usize {
        let cell = match self {
            Self::Rggb => [[0, 1], [1, 2]],
            Self::Bggr => [[2, 1], [1, 0]],
            Self::Gbrg => [[1, 2], [0, 1]],
            Self::Grbg => [[1, 0], [2, 1]],
        };
        cell[y & 1][x & 1]
    }
}

/// A raw image encoding eotn reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PixelEncoding {
    /// `uyvy` / `yuv422`: U Y0 V Y1 (ROS's `yuv422` is this order).
    Uyvy,
    /// `yuyv` / `yuv422_yuy2`: Y0 U Y1 V.
    Yuyv,
    /// `rgb8`: R G B.
    Rgb8,
    /// `rgba8`: R G B A.
    Rgba8,
    /// `bgr8`: B G R (OpenCV's order).
    Bgr8,
    /// `bgra8`: B G R A.
    Bgra8,
    /// `mono8`: one grey byte a pixel.
    Mono8,
    /// `nv12`: a Y plane, then a half-size plane of interleaved U V.
    Nv12,
    /// 8-bit Bayer mosaic (`bayer_rggb8`, …).
    Bayer(BayerOrder),
}

impl PixelEncoding {
    /// The names read, with their aliases, for messages that list them.
    pub const NAMES: &'static str = "uyvy (yuv422), yuyv (yuv422_yuy2), rgb8, rgba8, bgr8, bgra8, \
                                     mono8, nv12, bayer_rggb8, bayer_bggr8, bayer_gbrg8, \
                                     bayer_grbg8";

    /// The encoding an `encoding` field names (ROS and Foxglove spellings), if eotn reads it.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        let name = name.trim().to_ascii_lowercase();
        Some(match name.as_str() {
            "uyvy" | "yuv422" | "uyvy422" => Self::Uyvy,
            "yuyv" | "yuv422_yuy2" | "yuy2" | "yuyv422" => Self::Yuyv,
            "rgb8" => Self::Rgb8,
            "rgba8" => Self::Rgba8,
            "bgr8" => Self::Bgr8,
            "bgra8" => Self::Bgra8,
            "mono8" | "8uc1" => Self::Mono8,
            "nv12" => Self::Nv12,
            "bayer_rggb8" | "rggb8" => Self::Bayer(BayerOrder::Rggb),
            "bayer_bggr8" | "bggr8" => Self::Bayer(BayerOrder::Bggr),
            "bayer_gbrg8" | "gbrg8" => Self::Bayer(BayerOrder::Gbrg),
            "bayer_grbg8" | "grbg8" => Self::Bayer(BayerOrder::Grbg),
            _ => return None,
        })
    }

    /// The name Foxglove and ROS both read for it.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Uyvy => "uyvy",
            Self::Yuyv => "yuyv",
            Self::Rgb8 => "rgb8",
            Self::Rgba8 => "rgba8",
            Self::Bgr8 => "bgr8",
            Self::Bgra8 => "bgra8",
            Self::Mono8 => "mono8",
            Self::Nv12 => "nv12",
            Self::Bayer(BayerOrder::Rggb) => "bayer_rggb8",
            Self::Bayer(BayerOrder::Bggr) => "bayer_bggr8",
            Self::Bayer(BayerOrder::Gbrg) => "bayer_gbrg8",
            Self::Bayer(BayerOrder::Grbg) => "bayer_grbg8",
        }
    }

    /// True when the frame has no colour (a colour table cannot classify it).
    #[must_use]
    pub const fn is_grey(self) -> bool {
        matches!(self, Self::Mono8)
    }

    /// Bytes of one row's pixels, without padding (the Y plane's for `nv12`).
    const fn row_bytes(self, width: usize) -> usize {
        match self {
            Self::Uyvy | Self::Yuyv => width * 2,
            Self::Rgb8 | Self::Bgr8 => width * 3,
            Self::Rgba8 | Self::Bgra8 => width * 4,
            Self::Mono8 | Self::Nv12 | Self::Bayer(_) => width,
        }
    }
}

/// Why a raw image could not become a frame.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum RawImageError {
    /// An encoding eotn does not read.
    #[error("image encoding '{0}' is not read (eotn reads {names})", names = PixelEncoding::NAMES)]
    UnknownEncoding(String),
    /// Zero, or more pixels than a frame may have.
    #[error("image size {width}×{height} is not usable (at most 4096×4096 pixels)")]
    BadSize {
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
    },
    /// A width (or for `nv12` a height) that the encoding cannot have.
    #[error("{encoding} needs an even width and height, not {width}×{height}")]
    Odd {
        /// The encoding's name.
        encoding: &'static str,
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
    },
    /// A row step shorter than a row.
    #[error("image step {step} is shorter than a {width}-pixel {encoding} row ({row} bytes)")]
    ShortStep {
        /// The encoding's name.
        encoding: &'static str,
        /// The message's `step`, bytes.
        step: usize,
        /// Width, pixels.
        width: usize,
        /// A row's bytes.
        row: usize,
    },
    /// Less data than the size and step need.
    #[error(
        "image data has {len} bytes; {width}×{height} {encoding} with step {step} needs {needed}"
    )]
    ShortData {
        /// The encoding's name.
        encoding: &'static str,
        /// Bytes of data.
        len: usize,
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
        /// Row step, bytes.
        step: usize,
        /// Bytes needed.
        needed: usize,
    },
    /// The frame could not be made.
    #[error(transparent)]
    Frame(#[from] FrameError),
}

/// A raw image as a message holds it: size, encoding name, row step and the pixel bytes.
#[derive(Debug, Clone, Copy)]
pub struct RawImage<'a> {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// The `encoding` field.
    pub encoding: &'a str,
    /// Bytes from one row's start to the next's (`0` is taken as unpadded).
    pub step: usize,
    /// The pixel bytes.
    pub data: &'a [u8],
}

/// Decodes a raw image into a frame: 4:2:2 orders into UYVY, the rest into 4:4:4.
///
/// # Errors
/// [`RawImageError`] for an unknown encoding, a size or step that does not fit the data.
pub fn decode_raw(image: &RawImage<'_>) -> Result<Frame, RawImageError> {
    let Some(encoding) = PixelEncoding::from_name(image.encoding) else {
        return Err(RawImageError::UnknownEncoding(image.encoding.to_owned()));
    };
    decode_raw_as(encoding, image)
}

/// [`decode_raw`] with the encoding already known.
///
/// # Errors
/// As [`decode_raw`].
pub fn decode_raw_as(
    encoding: PixelEncoding,
    image: &RawImage<'_>,
) -> Result<Frame, RawImageError> {
    let (w, h) = (image.width, image.height);
    let bad_size = RawImageError::BadSize {
        width: w,
        height: h,
    };
    if w == 0 || h == 0 || w > 65_535 || h > 65_535 || (w as u64) * (h as u64) > MAX_FRAME_PIXELS {
        return Err(bad_size);
    }
    let needs_even_width = matches!(encoding, PixelEncoding::Uyvy | PixelEncoding::Yuyv);
    let needs_even = matches!(encoding, PixelEncoding::Nv12);
    if (needs_even_width && w % 2 != 0) || (needs_even && (w % 2 != 0 || h % 2 != 0)) {
        return Err(RawImageError::Odd {
            encoding: encoding.name(),
            width: w,
            height: h,
        });
    }
    let row = encoding.row_bytes(w);
    let step = if image.step == 0 { row } else { image.step };
    if step < row {
        return Err(RawImageError::ShortStep {
            encoding: encoding.name(),
            step,
            width: w,
            row,
        });
    }
    // Rows of the data: `h` (plus `h / 2` chroma rows for nv12), the last without its padding.
    let rows = if encoding == PixelEncoding::Nv12 {
        h + h / 2
    } else {
        h
    };
    let needed = step
        .checked_mul(rows - 1)
        .and_then(|n| n.checked_add(row))
        .ok_or(bad_size)?;
    if image.data.len() < needed {
        return Err(RawImageError::ShortData {
            encoding: encoding.name(),
            len: image.data.len(),
            width: w,
            height: h,
            step,
            needed,
        });
    }
    let rows = Rows {
        data: image.data,
        step,
        row,
    };
    let frame = match encoding {
        PixelEncoding::Uyvy => Frame::from_uyvy(w, h, rows.packed(h))?,
        PixelEncoding::Yuyv => {
            let mut data = rows.packed(h);
            for q in data.chunks_exact_mut(4) {
                q.swap(0, 1);
                q.swap(2, 3);
            }
            Frame::from_uyvy(w, h, data)?
        }
        PixelEncoding::Rgb8 => from_rgb(w, h, &rows, 3, [0, 1, 2])?,
        PixelEncoding::Rgba8 => from_rgb(w, h, &rows, 4, [0, 1, 2])?,
        PixelEncoding::Bgr8 => from_rgb(w, h, &rows, 3, [2, 1, 0])?,
        PixelEncoding::Bgra8 => from_rgb(w, h, &rows, 4, [2, 1, 0])?,
        PixelEncoding::Mono8 => {
            let mut data = Vec::with_capacity(w * h * 3);
            for y in 0..h {
                for &g in rows.get(y) {
                    data.extend_from_slice(&[grey_luma(g), 128, 128]);
                }
            }
            Frame::new(w, h, PixelLayout::Yuv444Packed, data)?
        }
        PixelEncoding::Nv12 => from_nv12(w, h, &rows)?,
        PixelEncoding::Bayer(order) => from_bayer(w, h, &rows, order)?,
    };
    Ok(frame)
}

/// [`decode_raw_as`] taking the message's pixel buffer: unpadded 4:2:2 data becomes the frame
/// without another copy (YUYV reordered in place); everything else is converted from it.
///
/// # Errors
/// As [`decode_raw`].
pub fn decode_raw_owned(
    encoding: PixelEncoding,
    width: usize,
    height: usize,
    step: usize,
    mut data: Vec<u8>,
) -> Result<Frame, RawImageError> {
    let row = encoding.row_bytes(width);
    let is_422 = matches!(encoding, PixelEncoding::Uyvy | PixelEncoding::Yuyv);
    let fits = width.is_multiple_of(2)
        && (step == row || step == 0)
        && row.checked_mul(height).is_some_and(|n| n <= data.len());
    if !is_422 || !fits || width == 0 || height == 0 {
        let image = RawImage {
            width,
            height,
            encoding: encoding.name(),
            step,
            data: &data,
        };
        return decode_raw_as(encoding, &image);
    }
    data.truncate(row * height);
    if encoding == PixelEncoding::Yuyv {
        for q in data.chunks_exact_mut(4) {
            q.swap(0, 1);
            q.swap(2, 3);
        }
    }
    if (width as u64) * (height as u64) > MAX_FRAME_PIXELS {
        return Err(RawImageError::BadSize { width, height });
    }
    Ok(Frame::from_uyvy(width, height, data)?)
}

/// A grey level (0 black .. 255 white) as studio-range luma, as [`super::rgb_to_yuv`] gives it
/// for R = G = B.
fn grey_luma(g: u8) -> u8 {
    RgbToYuv::get().convert(g, g, g).y
}

/// The rows of an image's data, each `row` bytes at multiples of `step`.
struct Rows<'a> {
    data: &'a [u8],
    step: usize,
    row: usize,
}

impl Rows<'_> {
    /// Row `y` (checked against the data's length by the caller; empty beyond it).
    fn get(&self, y: usize) -> &[u8] {
        let start = y * self.step;
        self.data.get(start..start + self.row).unwrap_or(&[])
    }

    /// The first `h` rows without their padding, in one buffer (one copy of the pixels).
    fn packed(&self, h: usize) -> Vec<u8> {
        if self.step == self.row {
            return self.data.get(..self.row * h).unwrap_or(&[]).to_vec();
        }
        let mut out = Vec::with_capacity(self.row * h);
        for y in 0..h {
            out.extend_from_slice(self.get(y));
        }
        out
    }
}

/// RGB-family rows (`bytes` a pixel, red/green/blue at `order`) into a 4:4:4 frame.
fn from_rgb(
    w: usize,
    h: usize,
    rows: &Rows<'_>,
    bytes: usize,
    order: [usize; 3],
) -> Result<Frame, FrameError> {
    let t = RgbToYuv::get();
    let mut data = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for p in rows.get(y).chunks_exact(bytes) {
            let yuv = t.convert(p[order[0]], p[order[1]], p[order[2]]);
            data.extend_from_slice(&[yuv.y, yuv.u, yuv.v]);
        }
    }
    Frame::new(w, h, PixelLayout::Yuv444Packed, data)
}

/// `nv12` into a 4:4:4 frame. Chroma samples sit beside the even columns (co-sited) and
/// between each pair of rows (MPEG-2's siting): up-sampled bilinearly, edges repeated.
fn from_nv12(w: usize, h: usize, rows: &Rows<'_>) -> Result<Frame, FrameError> {
    let (cw, ch) = (w / 2, h / 2);
    // Chroma at column x of chroma row j (x in luma columns): co-sited on even columns, the
    // mean of its neighbours on odd ones. Values ×2 to keep the half.
    let chroma_row = |j: usize, out: &mut Vec<[u16; 2]>| {
        out.clear();
        let r = rows.get(h + j.min(ch - 1));
        for x in 0..w {
            let i = x / 2;
            let at = |i: usize| {
                let i = i.min(cw - 1);
                [
                    u16::from(r.get(2 * i).copied().unwrap_or(128)),
                    u16::from(r.get(2 * i + 1).copied().unwrap_or(128)),
                ]
            };
            let a = at(i);
            let b = if x % 2 == 0 { a } else { at(i + 1) };
            out.push([a[0] + b[0], a[1] + b[1]]);
        }
    };
    let mut above = Vec::with_capacity(w);
    let mut below = Vec::with_capacity(w);
    let mut data = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        // Row y lies a quarter of a chroma row from its nearer chroma row.
        let j = y / 2;
        let (near, far) = if y % 2 == 0 {
            (j, j.saturating_sub(1))
        } else {
            (j, (j + 1).min(ch - 1))
        };
        chroma_row(near, &mut above);
        chroma_row(far, &mut below);
        for (x, &luma) in rows.get(y).iter().enumerate() {
            let (n, f) = (above[x], below[x]);
            // (3·near + far) / 4 of values held ×2: divide by 8, rounded.
            let mix = |a: u16, b: u16| u8::try_from((3 * a + b + 4) / 8).unwrap_or(u8::MAX);
            data.extend_from_slice(&[luma, mix(n[0], f[0]), mix(n[1], f[1])]);
        }
    }
    Frame::new(w, h, PixelLayout::Yuv444Packed, data)
}

/// Malvar–He–Cutler kernels (×16, 5×5, row-major) for one missing colour: bilinear
/// interpolation corrected by the photosite's own Laplacian, which keeps edges from growing
/// colour fringes. Green at a red or blue photosite:
const MHC_GREEN: [i32; 25] = [
    0, 0, -2, 0, 0, 0, 0, 4, 0, 0, -2, 4, 8, 4, -2, 0, 0, 4, 0, 0, 0, 0, -2, 0, 0,
];
/// At a green photosite, the colour whose neighbours lie left and right.
const MHC_ROW: [i32; 25] = [
    0, 0, 1, 0, 0, 0, -2, 0, -2, 0, -2, 8, 10, 8, -2, 0, -2, 0, -2, 0, 0, 0, 1, 0, 0,
];
/// At a green photosite, the colour whose neighbours lie above and below.
const MHC_COLUMN: [i32; 25] = [
    0, 0, -2, 0, 0, 0, -2, 8, -2, 0, 1, 0, 10, 0, 1, 0, -2, 8, -2, 0, 0, 0, -2, 0, 0,
];
/// Red at a blue photosite, or blue at a red one.
const MHC_DIAGONAL: [i32; 25] = [
    0, 0, -3, 0, 0, 0, 4, 0, 4, 0, -3, 0, 12, 0, -3, 0, 4, 0, 4, 0, 0, 0, -3, 0, 0,
];

/// An 8-bit Bayer mosaic demosaiced linearly into a 4:4:4 frame: each missing colour from the
/// nearest photosites of that colour (bilinear), corrected by the local gradient
/// (Malvar, He and Cutler 2004: "High-quality linear interpolation for demosaicing of
/// Bayer-patterned color images"); edges mirrored.
fn from_bayer(w: usize, h: usize, rows: &Rows<'_>, order: BayerOrder) -> Result<Frame, FrameError> {
    let t = RgbToYuv::get();
    let mut data = Vec::with_capacity(w * h * 3);
    if w == 0 || h == 0 {
        return Frame::new(w, h, PixelLayout::Yuv444Packed, data);
    }
    // The mosaic with a mirrored border of 2 photosites (-1 → 1, n → n - 2: keeps each
    // photosite's colour), so the 5×5 kernels index it directly.
    let mirror = |i: isize, n: usize| -> usize {
        let n = n as isize;
        let m = if i < 0 {
            -i
        } else if i >= n {
            2 * (n - 1) - i
        } else {
            i
        };
        usize::try_from(m.clamp(0, n - 1)).unwrap_or(0)
    };
    let pw = w + 4;
    let mut padded = Vec::with_capacity(pw * (h + 4));
    for py in 0..h + 4 {
        let row = rows.get(mirror(py as isize - 2, h));
        for px in 0..pw {
            padded.push(i32::from(
                row.get(mirror(px as isize - 2, w)).copied().unwrap_or(0),
            ));
        }
    }
    // Each kernel as (offset into `padded`, weight) of its non-zero taps.
    let taps = |kernel: &[i32; 25]| -> Vec<(usize, i32)> {
        kernel
            .iter()
            .enumerate()
            .filter(|(_, c)| **c != 0)
            .map(|(k, &c)| ((k / 5) * pw + k % 5, c))
            .collect()
    };
    let [green, along_row, along_column, diagonal] =
        [&MHC_GREEN, &MHC_ROW, &MHC_COLUMN, &MHC_DIAGONAL].map(taps);
    // `corner`: index of the 5×5 window's top-left photosite.
    let apply = |taps: &[(usize, i32)], corner: usize| -> i32 {
        let sum: i32 = taps.iter().map(|&(o, c)| c * padded[corner + o]).sum();
        (sum + 8) >> 4
    };
    for y in 0..h {
        for x in 0..w {
            let corner = y * pw + x;
            let here = order.colour_at(x, y);
            let mut rgb = [0i32; 3];
            rgb[here] = padded[corner + 2 * pw + 2];
            if here == 1 {
                // Green: one colour lies left and right on this row, the other above and below.
                let row_colour = order.colour_at(x + 1, y);
                rgb[row_colour] = apply(&along_row, corner);
                rgb[2 - row_colour] = apply(&along_column, corner);
            } else {
                rgb[1] = apply(&green, corner);
                rgb[2 - here] = apply(&diagonal, corner);
            }
            let c = |v: i32| u8::try_from(v.clamp(0, 255)).unwrap_or(u8::MAX);
            let yuv = t.convert(c(rgb[0]), c(rgb[1]), c(rgb[2]));
            data.extend_from_slice(&[yuv.y, yuv.u, yuv.v]);
        }
    }
    Frame::new(w, h, PixelLayout::Yuv444Packed, data)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Yuv, rgb_to_yuv};

    fn raw<'a>(w: usize, h: usize, encoding: &'a str, step: usize, data: &'a [u8]) -> RawImage<'a> {
        RawImage {
            width: w,
            height: h,
            encoding,
            step,
            data,
        }
    }

    #[test]
    fn every_name_and_alias_parses_and_names_round_trip() {
        for name in PixelEncoding::NAMES
            .split([',', ' ', '(', ')'])
            .filter(|s| !s.is_empty())
        {
            let e = PixelEncoding::from_name(name).unwrap_or_else(|| panic!("{name}"));
            assert_eq!(PixelEncoding::from_name(e.name()), Some(e));
        }
        assert_eq!(
            PixelEncoding::from_name("yuv422"),
            Some(PixelEncoding::Uyvy)
        );
        assert_eq!(
            PixelEncoding::from_name("yuv422_yuy2"),
            Some(PixelEncoding::Yuyv)
        );
        let e = decode_raw(&raw(2, 1, "rgb16", 0, &[0; 12]))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("rgb16") && e.contains("bayer_grbg8") && e.contains("nv12"),
            "{e}"
        );
    }

    #[test]
    fn rgb_and_bgr_orders_with_and_without_alpha_give_the_same_frame() {
        let colours = [[250u8, 110, 20], [45, 140, 60], [40, 110, 200]];
        let (w, h) = (3, 1);
        let mut rgb = Vec::new();
        let mut bgra = Vec::new();
        for c in colours {
            rgb.extend_from_slice(&c);
            bgra.extend_from_slice(&[c[2], c[1], c[0], 255]);
        }
        let a = decode_raw(&raw(w, h, "rgb8", 9, &rgb)).unwrap();
        let b = decode_raw(&raw(w, h, "bgra8", 12, &bgra)).unwrap();
        assert_eq!(a, b);
        for (x, c) in colours.iter().enumerate() {
            assert_eq!(a.pixel(x, 0), Some(rgb_to_yuv(*c)));
        }
    }

    #[test]
    fn padded_rows_are_skipped_for_every_encoding() {
        // 2×2 of each encoding with 3 padding bytes a row: the padding (0xEE) must not show.
        for (name, row) in [
            ("uyvy", 4),
            ("yuyv", 4),
            ("rgb8", 6),
            ("rgba8", 8),
            ("bgr8", 6),
            ("bgra8", 8),
            ("mono8", 2),
            ("bayer_rggb8", 2),
        ] {
            let step = row + 3;
            let mut data = vec![0xEE; step * 2];
            for y in 0..2 {
                data[y * step..y * step + row].fill(100);
            }
            let f = decode_raw(&raw(2, 2, name, step, &data)).unwrap();
            let flat = decode_raw(&raw(2, 2, name, row, &vec![100; row * 2])).unwrap();
            assert_eq!(f, flat, "{name}");
        }
    }

    #[test]
    fn owned_buffers_give_the_same_frames() {
        let data: Vec<u8> = (0..24).collect();
        for (enc, step) in [("uyvy", 8), ("yuyv", 8), ("yuyv", 12), ("rgb8", 12)] {
            let e = PixelEncoding::from_name(enc).unwrap();
            let h = 24 / step;
            let borrowed = decode_raw(&raw(4, h, enc, step, &data)).unwrap();
            let owned = decode_raw_owned(e, 4, h, step, data.clone()).unwrap();
            assert_eq!(borrowed, owned, "{enc} {step}");
        }
    }

    #[test]
    fn yuyv_becomes_uyvy_and_mono_is_grey() {
        let f = decode_raw(&raw(2, 1, "yuv422_yuy2", 0, &[10, 20, 30, 40])).unwrap();
        assert_eq!(f.data(), &[20, 10, 40, 30]);
        let g = decode_raw(&raw(2, 1, "mono8", 2, &[0, 255])).unwrap();
        assert_eq!(g.pixel(0, 0), Some(Yuv::new(16, 128, 128)));
        assert_eq!(g.pixel(1, 0), Some(Yuv::new(235, 128, 128)));
    }

    #[test]
    fn nv12_flat_chroma_stays_and_luma_is_kept() {
        let (w, h) = (4, 4);
        let mut data: Vec<u8> = (0..16).map(|i| 50 + i).collect();
        data.extend_from_slice(&[90, 200, 90, 200, 90, 200, 90, 200]);
        let f = decode_raw(&raw(w, h, "nv12", 0, &data)).unwrap();
        for y in 0..h {
            for x in 0..w {
                assert_eq!(
                    f.pixel(x, y),
                    Some(Yuv::new(50 + (y * w + x) as u8, 90, 200))
                );
            }
        }
        // A chroma step from the left half to the right half is interpolated on column 1.
        let mut data = vec![100; 16];
        data.extend_from_slice(&[60, 60, 160, 160, 60, 60, 160, 160]);
        let f = decode_raw(&raw(w, h, "nv12", 0, &data)).unwrap();
        assert_eq!(f.pixel(0, 0).map(|p| p.u), Some(60));
        assert_eq!(f.pixel(1, 0).map(|p| p.u), Some(110));
        assert_eq!(f.pixel(2, 0).map(|p| p.u), Some(160));
        assert!(decode_raw(&raw(3, 4, "nv12", 0, &[0; 18])).is_err());
    }

    #[test]
    fn a_flat_colour_survives_every_bayer_order() {
        let c = [200u8, 120, 40];
        for (name, order) in [
            ("bayer_rggb8", BayerOrder::Rggb),
            ("bayer_bggr8", BayerOrder::Bggr),
            ("gbrg8", BayerOrder::Gbrg),
            ("grbg8", BayerOrder::Grbg),
        ] {
            let (w, h) = (6, 4);
            let mosaic: Vec<u8> = (0..h)
                .flat_map(|y| (0..w).map(move |x| c[order.colour_at(x, y)]))
                .collect();
            let f = decode_raw(&raw(w, h, name, 0, &mosaic)).unwrap();
            f.for_each_pixel(|x, y, p| assert_eq!(p, rgb_to_yuv(c), "{name} at {x},{y}"));
        }
    }

    /// Malvar–He–Cutler written out per photosite, edges mirrored: what the padded, tap-list
    /// form must equal on a mosaic with edges and noise, for every order, odd sizes and 1×1.
    #[test]
    fn bayer_equals_the_kernels_applied_photosite_by_photosite() {
        let mirror = |i: isize, n: usize| {
            let n = n as isize;
            let m = if i < 0 {
                -i
            } else if i >= n {
                2 * (n - 1) - i
            } else {
                i
            };
            m.clamp(0, n - 1) as usize
        };
        for (w, h) in [(7, 5), (1, 1), (2, 3)] {
            let mosaic: Vec<u8> = (0..w * h)
                .map(|i| ((i * 97 + i / w * 31) % 256) as u8)
                .collect();
            for order in [
                BayerOrder::Rggb,
                BayerOrder::Bggr,
                BayerOrder::Gbrg,
                BayerOrder::Grbg,
            ] {
                let at = |x: isize, y: isize| i32::from(mosaic[mirror(y, h) * w + mirror(x, w)]);
                let apply = |k: &[i32; 25], x: usize, y: usize| {
                    let sum: i32 = (0..25)
                        .map(|i| {
                            k[i] * at(
                                x as isize + i as isize % 5 - 2,
                                y as isize + i as isize / 5 - 2,
                            )
                        })
                        .sum();
                    (sum + 8) >> 4
                };
                let f =
                    decode_raw(&raw(w, h, PixelEncoding::Bayer(order).name(), 0, &mosaic)).unwrap();
                f.for_each_pixel(|x, y, p| {
                    let here = order.colour_at(x, y);
                    let mut rgb = [0i32; 3];
                    rgb[here] = at(x as isize, y as isize);
                    if here == 1 {
                        let row = order.colour_at(x + 1, y);
                        rgb[row] = apply(&MHC_ROW, x, y);
                        rgb[2 - row] = apply(&MHC_COLUMN, x, y);
                    } else {
                        rgb[1] = apply(&MHC_GREEN, x, y);
                        rgb[2 - here] = apply(&MHC_DIAGONAL, x, y);
                    }
                    let c = rgb.map(|v| v.clamp(0, 255) as u8);
                    assert_eq!(p, rgb_to_yuv(c), "{order:?} {w}x{h} at {x},{y}");
                });
            }
        }
    }

    #[test]
    fn bad_sizes_are_errors_not_panics() {
        for (enc, w, h, step, len) in [
            ("uyvy", 3, 1, 6, 6),
            ("uyvy", 4, 2, 4, 16),
            ("rgb8", 4, 2, 12, 23),
            ("nv12", 4, 2, 4, 11),
            ("mono8", 0, 2, 0, 4),
            ("mono8", 5000, 5000, 5000, 10),
            ("mono8", usize::MAX, 2, usize::MAX, 10),
            ("bgra8", 2, usize::MAX, 8, 10),
        ] {
            let data = vec![0; len];
            assert!(
                decode_raw(&raw(w, h, enc, step, &data)).is_err(),
                "{enc} {w}x{h}"
            );
        }
    }
}
