//! Reading the files a user names: only regular files, and only up to the size the expected
//! content can have, so that `/dev/zero`, a FIFO or a wrong multi-gigabyte file is refused with
//! one line before anything is read (a FIFO is refused before it is even opened: opening one
//! waits for a writer), instead of reading until memory runs out or waiting for ever.
//!
//! [`unknown_keys`] finds the keys of a JSON file that its type does not have, for loaders that
//! refuse them (hand-written files: a typo must not be silently ignored) or warn about them
//! (files another version of eotn may have written).

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

use serde_json::Value;

/// Largest side file (JSON parameters, sensors, labels, places, CSV, an edit journal) read,
/// bytes: far beyond any real one.
pub const MAX_SIDE_FILE_BYTES: u64 = 256 << 20;

/// Largest small hand-written or app-written JSON file (field descriptions, calibration points,
/// calibrations, settings, bookmarks) read, bytes: a real one is a few KiB.
pub const MAX_SMALL_FILE_BYTES: u64 = 4 << 20;

/// Opens `path` for reading when it is a regular file, with its length: looked at before it is
/// opened (a FIFO would block the open, a device is not a file) and again after (the path may
/// have changed in between). The file becomes an input of the running command's guard
/// ([`crate::atomic_file::guard_read`]), so no output of the command replaces it.
///
/// # Errors
/// The OS error, or `InvalidInput` saying that the path is not a regular file, so it cannot be
/// `what`.
pub fn open_regular(path: &Path, what: &str) -> io::Result<(File, u64)> {
    let not_a_file = || {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("not a regular file, so it cannot be {what}"),
        )
    };
    if !std::fs::metadata(path)?.is_file() {
        return Err(not_a_file());
    }
    let file = File::open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(not_a_file());
    }
    // Whatever the command, a file it reads is one its outputs must not replace.
    crate::atomic_file::guard_read(&meta, path);
    Ok((file, meta.len()))
}

/// Reads the whole of `path`, which must be a regular file of at most `max_bytes` bytes.
///
/// # Errors
/// The OS error, or `InvalidInput` saying that the path is not a regular file or is larger than
/// `max_bytes` (stated in the message, as the limit of `what`, e.g. "a lookup table").
pub fn read_bounded(path: &Path, max_bytes: u64, what: &str) -> io::Result<Vec<u8>> {
    let (file, len) = open_regular(path, what)?;
    if len > max_bytes {
        return Err(too_large(len, max_bytes, what));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
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

/// The keys of `given` (a JSON file as read) that `known` (the same file's type serialised back
/// with every field) does not have, as paths (`landmarks[3].heigth_cm`, `overlays.opacty`),
/// searched through objects and, element by element, arrays.
#[must_use]
pub fn unknown_keys(given: &Value, known: &Value) -> Vec<String> {
    let mut out = Vec::new();
    collect_unknown(given, known, "", &mut out);
    out
}

fn collect_unknown(given: &Value, known: &Value, prefix: &str, out: &mut Vec<String>) {
    match (given, known) {
        (Value::Object(g), Value::Object(k)) => {
            for (key, value) in g {
                let path = if prefix.is_empty() {
                    key.clone()
                } else {
                    format!("{prefix}.{key}")
                };
                match k.get(key) {
                    Some(kv) => collect_unknown(value, kv, &path, out),
                    None => out.push(path),
                }
            }
        }
        (Value::Array(g), Value::Array(k)) => {
            for (i, (gv, kv)) in g.iter().zip(k).enumerate() {
                collect_unknown(gv, kv, &format!("{prefix}[{i}]"), out);
            }
        }
        _ => {}
    }
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

/// Makes a FIFO at `path` for a test; `false` (a visible skip, a failure under `CI=true`) when
/// `mkfifo` cannot.
#[cfg(all(test, unix))]
pub(crate) fn make_fifo(path: &Path) -> bool {
    let made = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        crate::test_skip::skipped(
            "mkfifo failed: the FIFO case is not tested",
            "install coreutils' mkfifo, on a file system that allows FIFOs",
        );
    }
    made
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

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_waiting_for_a_writer() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo");
        if !make_fifo(&fifo) {
            return;
        }
        // Opening it would wait for ever: the test would hang, not fail.
        let err = read_bounded(&fifo, 1 << 20, "a calibration").unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
    }

    #[test]
    fn unknown_keys_are_found_with_their_paths() {
        let known = serde_json::json!({"name": "", "landmarks": [{"height_cm": 0}], "o": {"a": 1}});
        let given = serde_json::json!({
            "name": "x", "nmae": "y", "landmarks": [{"heigth_cm": 3}], "o": {"a": 2, "b": 3}
        });
        let mut found = unknown_keys(&given, &known);
        found.sort();
        assert_eq!(found, ["landmarks[0].heigth_cm", "nmae", "o.b"]);
        assert!(unknown_keys(&known, &known).is_empty());
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
