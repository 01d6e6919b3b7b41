//! Reading the files a user names: only regular files, and only up to the size the expected
//! content can have, so that `/dev/zero`, a FIFO or a wrong multi-gigabyte file is refused with
//! one line before anything is read, instead of reading until memory runs out.

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// Largest side file (JSON parameters, sensors, labels, places, calibration, points, CSV) read,
/// bytes: far beyond any real one.
pub const MAX_SIDE_FILE_BYTES: u64 = 256 << 20;

/// Reads the whole of `path`, which must be a regular file of at most `max_bytes` bytes.
///
/// # Errors
/// The OS error, or `InvalidInput` saying that the path is not a regular file or is larger than
/// `max_bytes` (stated in the message, as the limit of `what`, e.g. "a lookup table").
pub fn read_bounded(path: &Path, max_bytes: u64, what: &str) -> io::Result<Vec<u8>> {
    let file = File::open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("not a regular file, so it cannot be {what}"),
        ));
    }
    if meta.len() > max_bytes {
        return Err(too_large(meta.len(), max_bytes, what));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    // A file that grows while it is read still stops at the limit.
    file.take(max_bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64, max_bytes, what));
    }
    Ok(bytes)
}

/// Like [`read_bounded`], as UTF-8 text.
///
/// # Errors
/// As [`read_bounded`], and `InvalidData` for text that is not UTF-8.
pub fn read_text_bounded(path: &Path, max_bytes: u64, what: &str) -> io::Result<String> {
    let bytes = read_bounded(path, max_bytes, what)?;
    String::from_utf8(bytes)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "not UTF-8 text"))
}

fn too_large(len: u64, max: u64, what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{} is more than {what} can be ({})",
            human_bytes(len),
            human_bytes(max)
        ),
    )
}

/// A byte count for people: `812 bytes`, `3.1 MiB`, `2.0 GiB`.
#[must_use]
pub fn human_bytes(n: u64) -> String {
    #[expect(clippy::cast_precision_loss, reason = "one decimal is shown")]
    let f = n as f64;
    if n < 1 << 10 {
        format!("{n} bytes")
    } else if n < 1 << 20 {
        format!("{:.1} KiB", f / 1024.0)
    } else if n < 1 << 30 {
        format!("{:.1} MiB", f / f64::from(1u32 << 20))
    } else {
        format!("{:.1} GiB", f / f64::from(1u32 << 30))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_is_refused_before_it_is_read() {
        let err = read_bounded(Path::new("/dev/zero"), 1 << 20, "a lookup table").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(err.to_string().contains("not a regular file"), "{err}");
    }

    #[test]
    fn a_file_over_the_limit_is_refused_with_both_sizes() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x");
        std::fs::write(&p, vec![0u8; 3000]).unwrap();
        let err = read_bounded(&p, 2048, "a frame").unwrap_err();
        assert!(
            err.to_string()
                .contains("2.9 KiB is more than a frame can be (2.0 KiB)"),
            "{err}"
        );
        assert_eq!(read_bounded(&p, 3000, "a frame").unwrap().len(), 3000);
    }
}
