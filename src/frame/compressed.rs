//! Compressed images (JPEG, PNG) into frames, from bytes: files and `CompressedImage` messages
//! alike.
//!
//! JPEG is decoded by `zune-jpeg` straight to its own YCbCr (full range, JFIF) and mapped to the
//! tables' studio range ([`super::colour`]): no round trip through RGB, whose clamp to 0..255
//! would move saturated colours. Grey JPEGs become grey frames; CMYK ones go through RGB. PNG
//! (any bit depth, grey or colour, with or without alpha) is decoded by `image` to 8-bit RGB and
//! converted with the one RGB → YUV conversion.

use thiserror::Error;
use zune_core::colorspace::ColorSpace;
use zune_core::options::DecoderOptions;

use super::colour::{RgbToYuv, full_to_studio_in_place};
use super::{Frame, FrameError, MAX_FRAME_PIXELS, MAX_FRAME_SIDE, PixelLayout};

/// A compressed image format eotn reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CompressedFormat {
    /// JPEG (JFIF or Exif).
    Jpeg,
    /// PNG.
    Png,
}

impl CompressedFormat {
    /// The formats read, as messages name them.
    pub const NAMES: &'static str = "jpeg, png";

    /// The format a `format` field names: `jpeg`/`jpg`/`png`, any case, and image_transport's
    /// `"bgr8; jpeg compressed bgr8"` (the format is the word before `compressed`).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        let lower = name.trim().to_ascii_lowercase();
        let word = match lower.split_once(';') {
            Some((_, rest)) => rest.split_whitespace().next().unwrap_or(""),
            None => lower.as_str(),
        };
        match word {
            "jpeg" | "jpg" => Some(Self::Jpeg),
            "png" => Some(Self::Png),
            _ => None,
        }
    }

    /// The format the bytes start with, if any (for a `format` field that says nothing).
    #[must_use]
    pub fn sniff(data: &[u8]) -> Option<Self> {
        if data.starts_with(&[0xFF, 0xD8, 0xFF]) {
            Some(Self::Jpeg)
        } else if data.starts_with(b"\x89PNG\r\n\x1a\n") {
            Some(Self::Png)
        } else {
            None
        }
    }

    /// The canonical name (`jpeg`, `png`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Jpeg => "jpeg",
            Self::Png => "png",
        }
    }
}

/// Why compressed bytes could not become a frame.
#[derive(Debug, Error)]
pub enum CompressedImageError {
    /// A format eotn does not read.
    #[error("image format '{0}' is not read (eotn reads {names})", names = CompressedFormat::NAMES)]
    UnknownFormat(String),
    /// The JPEG does not decode.
    #[error("JPEG: {0}")]
    Jpeg(String),
    /// The PNG does not decode.
    #[error("PNG: {0}")]
    Png(#[source] image::ImageError),
    /// Larger than any frame eotn takes.
    #[error("{width}×{height} is larger than the frames eotn takes (at most 4096×4096 pixels)")]
    TooLarge {
        /// Width, pixels.
        width: u64,
        /// Height, pixels.
        height: u64,
    },
    /// The frame could not be made.
    #[error(transparent)]
    Frame(#[from] FrameError),
}

/// Decodes compressed bytes in `format` (sniffed from the bytes when the name says nothing).
///
/// # Errors
/// [`CompressedImageError`] for an unknown format or bytes that do not decode.
pub fn decode_compressed(format: &str, data: &[u8]) -> Result<Frame, CompressedImageError> {
    let kind = CompressedFormat::from_name(format)
        .or_else(|| CompressedFormat::sniff(data))
        .ok_or_else(|| CompressedImageError::UnknownFormat(format.to_owned()))?;
    match kind {
        CompressedFormat::Jpeg => decode_jpeg(data),
        CompressedFormat::Png => decode_png(data),
    }
}

fn too_large(w: u64, h: u64) -> bool {
    w == 0
        || h == 0
        || w > u64::from(MAX_FRAME_SIDE)
        || h > u64::from(MAX_FRAME_SIDE)
        || w * h > MAX_FRAME_PIXELS
}

/// Decodes a JPEG to its YCbCr and maps it to studio range: a 4:4:4 frame.
///
/// # Errors
/// [`CompressedImageError`] when it does not decode or is too large.
pub fn decode_jpeg(data: &[u8]) -> Result<Frame, CompressedImageError> {
    let jpeg_err =
        |e: zune_jpeg::errors::DecodeErrors| CompressedImageError::Jpeg(format!("{e:?}"));
    let options = DecoderOptions::default()
        .set_max_width(MAX_FRAME_SIDE as usize)
        .set_max_height(MAX_FRAME_SIDE as usize)
        .jpeg_set_out_colorspace(ColorSpace::YCbCr);
    // One decoder: the headers first (size and components), then the pixels.
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(std::io::Cursor::new(data), options);
    decoder.decode_headers().map_err(jpeg_err)?;
    let info = decoder
        .info()
        .ok_or_else(|| CompressedImageError::Jpeg("no image size in the header".to_owned()))?;
    let (w, h) = (usize::from(info.width), usize::from(info.height));
    if too_large(w as u64, h as u64) {
        return Err(CompressedImageError::TooLarge {
            width: w as u64,
            height: h as u64,
        });
    }
    let out_space = match decoder.input_colorspace() {
        Some(ColorSpace::Luma) => ColorSpace::Luma,
        Some(ColorSpace::YCbCr) => ColorSpace::YCbCr,
        _ => ColorSpace::RGB,
    };
    if out_space != ColorSpace::YCbCr {
        decoder.set_options(options.jpeg_set_out_colorspace(out_space));
    }
    let len = w * h * out_space.num_components();
    if decoder.output_buffer_size() != Some(len) {
        return Err(CompressedImageError::Jpeg(format!(
            "the decoder would give {:?} bytes for {w}×{h} {out_space:?}",
            decoder.output_buffer_size()
        )));
    }
    let mut pixels = vec![0u8; len];
    decoder.decode_into(&mut pixels).map_err(jpeg_err)?;
    let yuv = match out_space {
        ColorSpace::YCbCr => {
            full_to_studio_in_place(&mut pixels);
            pixels
        }
        ColorSpace::Luma => {
            let luma = super::colour::studio_maps().0;
            pixels
                .iter()
                .flat_map(|&g| [luma[usize::from(g)], 128, 128])
                .collect()
        }
        _ => rgb_to_yuv_bytes(&pixels),
    };
    Ok(Frame::new(w, h, PixelLayout::Yuv444Packed, yuv)?)
}

/// Decodes a PNG (header checked against the size limits first) to RGB, then to YUV.
///
/// # Errors
/// [`CompressedImageError`] when it does not decode or is too large.
pub fn decode_png(data: &[u8]) -> Result<Frame, CompressedImageError> {
    let rgb = decode_rgb(data, image::ImageFormat::Png)?;
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    Ok(Frame::new(
        w,
        h,
        PixelLayout::Yuv444Packed,
        rgb_to_yuv_bytes(rgb.as_raw()),
    )?)
}

/// Decodes image bytes of `format` to 8-bit RGB through `image`, refusing sizes beyond a frame's
/// before decoding.
///
/// # Errors
/// [`CompressedImageError`] when it does not decode or is too large.
pub fn decode_rgb(
    data: &[u8],
    format: image::ImageFormat,
) -> Result<image::RgbImage, CompressedImageError> {
    let reader = || {
        let mut r = image::ImageReader::with_format(std::io::Cursor::new(data), format);
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_FRAME_SIDE);
        limits.max_image_height = Some(MAX_FRAME_SIDE);
        limits.max_alloc = Some(MAX_FRAME_PIXELS * 8);
        r.limits(limits);
        r
    };
    let (w, h) = reader()
        .into_dimensions()
        .map_err(CompressedImageError::Png)?;
    if too_large(u64::from(w), u64::from(h)) {
        return Err(CompressedImageError::TooLarge {
            width: u64::from(w),
            height: u64::from(h),
        });
    }
    Ok(reader()
        .decode()
        .map_err(CompressedImageError::Png)?
        .into_rgb8())
}

/// Packed RGB → packed studio-range YUV through the one conversion.
fn rgb_to_yuv_bytes(rgb: &[u8]) -> Vec<u8> {
    let t = RgbToYuv::get();
    let mut out = Vec::with_capacity(rgb.len());
    for p in rgb.chunks_exact(3) {
        let yuv = t.convert(p[0], p[1], p[2]);
        out.extend_from_slice(&[yuv.y, yuv.u, yuv.v]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::rgb_to_yuv;

    fn encoded(format: image::ImageFormat, rgb: &image::RgbImage) -> Vec<u8> {
        let mut out = Vec::new();
        rgb.write_to(&mut std::io::Cursor::new(&mut out), format)
            .unwrap();
        out
    }

    #[test]
    fn formats_are_named_in_ros_and_foxglove_spellings() {
        assert_eq!(
            CompressedFormat::from_name("jpeg"),
            Some(CompressedFormat::Jpeg)
        );
        assert_eq!(
            CompressedFormat::from_name("JPG"),
            Some(CompressedFormat::Jpeg)
        );
        assert_eq!(
            CompressedFormat::from_name("bgr8; jpeg compressed bgr8"),
            Some(CompressedFormat::Jpeg)
        );
        assert_eq!(
            CompressedFormat::from_name("rgb8; png compressed rgb8"),
            Some(CompressedFormat::Png)
        );
        assert_eq!(CompressedFormat::from_name("webp"), None);
        let e = decode_compressed("webp", b"RIFF....")
            .unwrap_err()
            .to_string();
        assert!(e.contains("webp") && e.contains("jpeg, png"), "{e}");
    }

    #[test]
    fn png_is_exact_and_jpeg_is_close() {
        let img = image::RgbImage::from_fn(32, 16, |x, _| {
            if x < 16 {
                image::Rgb([250, 110, 20])
            } else {
                image::Rgb([45, 140, 60])
            }
        });
        let png = decode_compressed("png", &encoded(image::ImageFormat::Png, &img)).unwrap();
        assert_eq!(png.pixel(3, 3), Some(rgb_to_yuv([250, 110, 20])));
        let jpeg = encoded(image::ImageFormat::Jpeg, &img);
        let f = decode_compressed("", &jpeg).unwrap();
        assert_eq!((f.width(), f.height()), (32, 16));
        let (got, want) = (f.pixel(4, 8).unwrap(), rgb_to_yuv([250, 110, 20]));
        assert!(
            got.y.abs_diff(want.y) <= 4 && got.v.abs_diff(want.v) <= 6,
            "{got:?} {want:?}"
        );
    }

    #[test]
    fn grey_jpeg_is_a_grey_frame() {
        let img = image::GrayImage::from_pixel(16, 8, image::Luma([255]));
        let mut out = Vec::new();
        img.write_to(
            &mut std::io::Cursor::new(&mut out),
            image::ImageFormat::Jpeg,
        )
        .unwrap();
        let f = decode_jpeg(&out).unwrap();
        let p = f.pixel(5, 5).unwrap();
        assert_eq!((p.u, p.v), (128, 128));
        assert!(p.y >= 233, "{p:?}");
    }

    #[test]
    fn damaged_bytes_are_errors_not_panics() {
        let img = image::RgbImage::from_pixel(16, 16, image::Rgb([9, 9, 9]));
        for format in [image::ImageFormat::Jpeg, image::ImageFormat::Png] {
            let bytes = encoded(format, &img);
            for cut in [0, 2, 10, bytes.len() / 2] {
                let name = if format == image::ImageFormat::Png {
                    "png"
                } else {
                    "jpeg"
                };
                // A cut JPEG may still decode (zune fills the rest); it must not panic.
                let _ = decode_compressed(name, &bytes[..cut]);
            }
        }
        assert!(decode_compressed("jpeg", b"\xff\xd8\xff garbage").is_err());
    }
}
