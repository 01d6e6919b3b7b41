//! Reading frames from files (raw `.uyvy`, PNG, JPEG) and writing RGB views as PNG.

use std::path::{Path, PathBuf};

use thiserror::Error;

use super::compressed::{CompressedFormat, decode_compressed};
use super::{AIBO_SIZE, Frame, FrameError, OVERHEAD_SIZE, PixelLayout};

/// Most pixels a frame may have: 4096 × 4096 (16.8 Mpx; 50 MiB as 4:4:4), far beyond the
/// cameras' 208×160 to 1920×1080. Larger images are refused before they are decoded.
pub const MAX_FRAME_PIXELS: u64 = 4096 * 4096;
/// Largest side of a frame, pixels.
pub const MAX_FRAME_SIDE: u32 = 16384;
/// Largest PNG/JPEG file read, bytes.
const MAX_IMAGE_FILE_BYTES: u64 = 512 << 20;

/// Why a frame file could not be read or written; always names the file.
#[derive(Debug, Error)]
pub enum FrameFileError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// A raw file's length matches no known size and none was given.
    #[error(
        "{path}: {len} bytes is not a known UYVY frame size (208×160 or 640×480); its width and height must be given"
    )]
    UnknownSize {
        /// The file.
        path: PathBuf,
        /// Its length, bytes.
        len: usize,
    },
    /// The bytes do not make a frame of the given size.
    #[error("{path}: {source}")]
    Frame {
        /// The file.
        path: PathBuf,
        /// The frame error.
        source: FrameError,
    },
    /// The image does not decode, or is too large.
    #[error("{path}: {source}")]
    Compressed {
        /// The file.
        path: PathBuf,
        /// The decoder's error.
        source: super::compressed::CompressedImageError,
    },
    /// The image encoder failed.
    #[error("{path}: {source}")]
    Image {
        /// The file.
        path: PathBuf,
        /// The decoder's error.
        source: image::ImageError,
    },
    /// A JPEG that stops before its end (a cut-off copy or download): the decoder would fill
    /// the missing part with grey or with the first scans' blur and call it a whole frame.
    #[error("{path}: the JPEG is cut off (no end-of-image marker after its last scan)")]
    TruncatedJpeg {
        /// The file.
        path: PathBuf,
    },
}

/// True when JPEG `bytes` end their last scan with an end-of-image marker (`FF D9`). Inside a
/// scan's coded data a 0xFF byte is always followed by 0x00 or a restart marker, so the last
/// `FF DA` (start of scan) is the last scan header, and a whole file has `FF D9` after it; an
/// earlier `FF D9` (an embedded thumbnail's) does not count.
#[must_use]
pub fn jpeg_is_complete(bytes: &[u8]) -> bool {
    let marker = |m: u8| move |w: &[u8]| w == [0xFF, m];
    let Some(last_scan) = bytes.windows(2).rposition(marker(0xDA)) else {
        return false;
    };
    bytes[last_scan..].windows(2).any(marker(0xD9))
}

/// A file's name without its folders, for messages, labels and the JSON `frame` field; the whole
/// path when it has no file name (such as `..`).
#[must_use]
pub fn display_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// The frame size a raw UYVY file of `len` bytes has when none is given: 208×160 or 640×480.
#[must_use]
pub fn infer_uyvy_size(len: usize) -> Option<(usize, usize)> {
    [AIBO_SIZE, OVERHEAD_SIZE]
        .into_iter()
        .find(|&(w, h)| PixelLayout::Uyvy.frame_len(w, h) == len)
}

/// Reads a raw UYVY file; `size` (width, height) is inferred from the length when `None`.
///
/// # Errors
/// [`FrameFileError`] naming the file: unreadable, unknown size, or wrong length.
pub fn load_raw_uyvy(path: &Path, size: Option<(usize, usize)>) -> Result<Frame, FrameFileError> {
    let data = crate::input_file::read_bounded(path, MAX_FRAME_PIXELS * 2, "a UYVY frame")
        .map_err(|source| FrameFileError::Io {
            path: path.to_owned(),
            source,
        })?;
    let (width, height) = match size.or_else(|| infer_uyvy_size(data.len())) {
        Some(s) => s,
        None => {
            return Err(FrameFileError::UnknownSize {
                path: path.to_owned(),
                len: data.len(),
            });
        }
    };
    Frame::from_uyvy(width, height, data).map_err(|source| FrameFileError::Frame {
        path: path.to_owned(),
        source,
    })
}

/// True when the path names an image format the `image` crate reads for us (PNG, JPEG).
#[must_use]
pub fn is_image_file(path: &Path) -> bool {
    matches!(
        path.extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .as_deref(),
        Some("png" | "jpg" | "jpeg")
    )
}

/// Reads a frame: JPEG through its own YCbCr and PNG through RGB, both into the tables' YUV
/// ([`super::colour`]) as 4:4:4 frames; anything else as raw UYVY.
///
/// # Errors
/// [`FrameFileError`] naming the file.
pub fn load_frame(path: &Path, size: Option<(usize, usize)>) -> Result<Frame, FrameFileError> {
    if !is_image_file(path) {
        return load_raw_uyvy(path, size);
    }
    let bytes = crate::input_file::read_bounded(path, MAX_IMAGE_FILE_BYTES, "an image frame")
        .map_err(|source| FrameFileError::Io {
            path: path.to_owned(),
            source,
        })?;
    // The content decides (a `.jpg` that is a PNG opens too); the extension when it says nothing.
    let sniffed = CompressedFormat::sniff(&bytes);
    if sniffed == Some(CompressedFormat::Jpeg) && !jpeg_is_complete(&bytes) {
        return Err(FrameFileError::TruncatedJpeg {
            path: path.to_owned(),
        });
    }
    let format = sniffed.map_or_else(
        || {
            path.extension()
                .map(|e| e.to_string_lossy().into_owned())
                .unwrap_or_default()
        },
        |f| f.name().to_owned(),
    );
    decode_compressed(&format, &bytes).map_err(|source| FrameFileError::Compressed {
        path: path.to_owned(),
        source,
    })
}

/// Writes packed RGB (3 bytes a pixel) as a PNG, atomically.
///
/// # Errors
/// [`FrameFileError`] naming the file when the buffer is the wrong length or writing fails.
pub fn save_rgb_png(
    path: &Path,
    width: usize,
    height: usize,
    rgb: &[u8],
) -> Result<(), FrameFileError> {
    let bad = || FrameFileError::Frame {
        path: path.to_owned(),
        source: FrameError::WrongLength {
            len: rgb.len(),
            expected: width * height * 3,
            width,
            height,
            layout: PixelLayout::Yuv444Packed,
        },
    };
    let (w, h) = (
        u32::try_from(width).map_err(|_| bad())?,
        u32::try_from(height).map_err(|_| bad())?,
    );
    let img = image::RgbImage::from_raw(w, h, rgb.to_vec()).ok_or_else(bad)?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|source| FrameFileError::Image {
            path: path.to_owned(),
            source,
        })?;
    // Atomically: a killed export leaves the old file or the new one, never a truncated PNG.
    crate::atomic_file::write_atomic(path, &png).map_err(|source| FrameFileError::Io {
        path: path.to_owned(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Yuv, yuv_to_rgb};

    /// A progressive JPEG of 96×64 noise, ten scans (`convert -size 96x64 xc: +noise Random
    /// -interlace JPEG -quality 85`, ImageMagick).
    const PROGRESSIVE: &[u8] = include_bytes!("../../tests/data/progressive-96x64.jpg");

    #[test]
    fn a_cut_off_progressive_jpeg_is_refused_and_a_whole_one_loads() {
        let dir = tempfile::tempdir().unwrap();
        let whole = dir.path().join("whole.jpg");
        std::fs::write(&whole, PROGRESSIVE).unwrap();
        let f = load_frame(&whole, None).unwrap();
        assert_eq!((f.width(), f.height()), (96, 64));
        for cut in [PROGRESSIVE.len() * 6 / 10, PROGRESSIVE.len() - 2] {
            let p = dir.path().join(format!("cut{cut}.jpg"));
            std::fs::write(&p, &PROGRESSIVE[..cut]).unwrap();
            let err = load_frame(&p, None).expect_err("cut off");
            assert!(
                matches!(err, FrameFileError::TruncatedJpeg { .. }),
                "{cut}: {err}"
            );
            assert!(err.to_string().contains("cut off"), "{err}");
        }
    }

    #[test]
    fn raw_sizes_are_inferred_for_the_two_cameras() {
        assert_eq!(infer_uyvy_size(208 * 160 * 2), Some((208, 160)));
        assert_eq!(infer_uyvy_size(640 * 480 * 2), Some((640, 480)));
        assert_eq!(infer_uyvy_size(1000), None);
    }

    #[test]
    fn wrong_sized_raw_file_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("odd.uyvy");
        std::fs::write(&p, [0u8; 1000]).unwrap();
        let e = load_raw_uyvy(&p, None).unwrap_err().to_string();
        assert!(e.contains("odd.uyvy") && e.contains("1000 bytes"), "{e}");
        let e = load_raw_uyvy(&p, Some((20, 20))).unwrap_err().to_string();
        assert!(e.contains("odd.uyvy") && e.contains("800 bytes"), "{e}");
    }

    #[test]
    fn png_round_trip_keeps_colours() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.png");
        let f = Frame::uyvy_from_fn(8, 4, |x, _| {
            if x < 4 {
                Yuv::new(120, 80, 190)
            } else {
                Yuv::new(100, 100, 100)
            }
        })
        .unwrap();
        save_rgb_png(&p, 8, 4, &f.to_rgb()).unwrap();
        let back = load_frame(&p, None).unwrap();
        assert_eq!((back.width(), back.height()), (8, 4));
        let a = yuv_to_rgb(back.pixel(1, 1).unwrap());
        let b = yuv_to_rgb(f.pixel(1, 1).unwrap());
        for (x, y) in a.iter().zip(b) {
            assert!(x.abs_diff(y) <= 2);
        }
    }
}
