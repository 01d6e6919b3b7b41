//! The JPEGImage message: B-Human's four-component JPEG of macropixels, decoded to a UYVY frame.

use thiserror::Error;

use super::records::le_u32;
use crate::frame::Frame;

/// Why one JPEGImage message could not become a frame (the log goes on without it).
#[derive(Debug, Error)]
pub enum JpegImageError {
    /// The payload ends inside its 16-byte header.
    #[error("payload shorter than its 16-byte header")]
    ShortHeader,
    /// The header's size is outside 2..=4096 × 1..=4096.
    #[error("image size {width}×{height} is not plausible")]
    ImplausibleSize {
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
    },
    /// The payload holds less JPEG than its header says.
    #[error("JPEG of {len} bytes, the payload has {available}")]
    ShortJpeg {
        /// JPEG bytes the header announces.
        len: usize,
        /// Bytes after the header.
        available: usize,
    },
    /// The JPEG header does not decode.
    #[error("JPEG header: {0:?}")]
    Header(zune_jpeg::errors::DecodeErrors),
    /// The JPEG header has no size.
    #[error("JPEG header gave no image size")]
    NoSize,
    /// The JPEG's size is not the message's.
    #[error("JPEG is {jpeg_width}×{jpeg_height}, the message says {width}×{height}")]
    SizeMismatch {
        /// The JPEG's width, pixels.
        jpeg_width: u16,
        /// The JPEG's height, pixels.
        jpeg_height: u16,
        /// The message's width, pixels.
        width: usize,
        /// The message's height, pixels.
        height: usize,
    },
    /// The JPEG is not B-Human's four untransformed components.
    #[error("JPEG colour space {space:?}, expected 4 untransformed components")]
    NotFourComponents {
        /// The colour space the JPEG declares.
        space: Option<zune_core::colorspace::ColorSpace>,
    },
    /// The JPEG data does not decode.
    #[error("JPEG data: {0:?}")]
    Data(zune_jpeg::errors::DecodeErrors),
    /// The macropixels do not fill the size, or the width is odd.
    #[error("{count} macropixels for {width}×{height} (the width must be even)")]
    MacropixelCount {
        /// Macropixels given.
        count: usize,
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
    },
    /// The frame could not be made.
    #[error(transparent)]
    Frame(#[from] crate::frame::FrameError),
}

/// Decodes a JPEGImage payload's JPEG to B-Human's macropixels: `width × height` entries of
/// `[Y0, Cb, Y1, Cr]` (zune-jpeg's CMYK output as it comes; see the module docs).
///
/// # Errors
/// [`JpegImageError`] when the JPEG does not decode or is not 4-component at the given size.
pub fn decode_macropixels(
    jpeg: &[u8],
    width: usize,
    height: usize,
) -> Result<Vec<[u8; 4]>, JpegImageError> {
    use zune_core::colorspace::ColorSpace;
    use zune_core::options::DecoderOptions;
    let options = DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::CMYK);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(std::io::Cursor::new(jpeg), options);
    decoder.decode_headers().map_err(JpegImageError::Header)?;
    let info = decoder.info().ok_or(JpegImageError::NoSize)?;
    if (usize::from(info.width), usize::from(info.height)) != (width, height) {
        return Err(JpegImageError::SizeMismatch {
            jpeg_width: info.width,
            jpeg_height: info.height,
            width,
            height,
        });
    }
    if decoder.input_colorspace() != Some(ColorSpace::CMYK) {
        return Err(JpegImageError::NotFourComponents {
            space: decoder.input_colorspace(),
        });
    }
    let mut out = vec![0u8; width * height * 4];
    decoder
        .decode_into(&mut out)
        .map_err(JpegImageError::Data)?;
    Ok(out
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect())
}

/// Macropixels (`[Y0, Cb, Y1, Cr]`, `width` per row) → a UYVY frame of the same width: pixel
/// *x* takes the mean luma of macropixel *x*; each pair shares the mean chroma of its two.
///
/// # Errors
/// [`JpegImageError::MacropixelCount`] when the width is odd or the count does not match.
pub fn macropixels_to_uyvy(
    mp: &[[u8; 4]],
    width: usize,
    height: usize,
) -> Result<Frame, JpegImageError> {
    if !width.is_multiple_of(2) || mp.len() != width * height {
        return Err(JpegImageError::MacropixelCount {
            count: mp.len(),
            width,
            height,
        });
    }
    let mean =
        |a: u8, b: u8| u8::try_from((u16::from(a) + u16::from(b)).div_ceil(2)).unwrap_or(u8::MAX);
    let mut data = Vec::with_capacity(width * height * 2);
    for pair in mp.chunks_exact(2) {
        let (a, b) = (pair[0], pair[1]);
        data.extend_from_slice(&[
            mean(a[1], b[1]),
            mean(a[0], a[2]),
            mean(a[3], b[3]),
            mean(b[0], b[2]),
        ]);
    }
    Ok(Frame::from_uyvy(width, height, data)?)
}

/// Decodes a JPEGImage payload to its time and frame.
pub(super) fn image(p: &[u8]) -> Result<(u32, Frame), JpegImageError> {
    let field = |at: usize| le_u32(p, at).ok_or(JpegImageError::ShortHeader);
    let (w, h, time_ms, len) = (field(0)?, field(4)?, field(8)?, field(12)? as usize);
    let (w, h) = (w as usize, h as usize);
    if !(2..=4096).contains(&w) || !(1..=4096).contains(&h) {
        return Err(JpegImageError::ImplausibleSize {
            width: w,
            height: h,
        });
    }
    let jpeg = p.get(16..16 + len).ok_or(JpegImageError::ShortJpeg {
        len,
        available: p.len() - 16,
    })?;
    let mp = decode_macropixels(jpeg, w, h)?;
    Ok((time_ms, macropixels_to_uyvy(&mp, w, h)?))
}
