//! Atomic file writes: a crash, a full disk or a failed write never leaves a half-written file.
//!
//! A hand-made lookup table is hours of work, so every save goes to a temporary file in the same
//! folder (same file system, so the rename is atomic), is flushed to disk with `fsync`, and only
//! then replaces the target by `rename`. On any error the temporary file is removed and the old
//! file is untouched.

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A temporary path beside `path`, unique within this process.
fn temp_path_for(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

/// Writes `bytes` to `path` atomically (see the module docs).
///
/// # Errors
/// Any I/O error; `path` then still holds its old contents (or still does not exist).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// Like [`write_atomic`], with the contents produced by `write` into the temporary file.
///
/// # Errors
/// Any I/O error from `write` or the file system; the target is then untouched.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut io::BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    clean_stale_temporaries(path);
    let tmp = temp_path_for(path);
    let result = (|| {
        let mut out = io::BufWriter::new(File::create(&tmp)?);
        write(&mut out)?;
        let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        fs::rename(&tmp, path)?;
        sync_parent(path);
        Ok(())
    })();
    if result.is_err() {
        // Best effort: the temporary file is ours and useless now.
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Removes temporaries of `path` left by writers of ours that were killed (`kill -9`, a power
/// cut): `.NAME.tmp-PID-N` files whose process no longer runs. Only our own naming is touched,
/// and only where the system says which processes run (`/proc`).
fn clean_stale_temporaries(path: &Path) {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return;
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !Path::new("/proc/self").exists() {
        return;
    }
    let prefix = format!(".{name}.tmp-");
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(rest) = file.to_str().and_then(|f| f.strip_prefix(&prefix)) else {
            continue;
        };
        let Some(pid) = rest.split('-').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = fs::remove_file(entry.path());
        }
    }
}

/// Flushes the folder entry of a renamed file, so the rename itself survives a power cut.
/// Not every platform can open a folder for syncing; failures are ignored there.
fn sync_parent(path: &Path) {
    #[cfg(unix)]
    if let Some(parent) = path.parent() {
        let parent = if parent.as_os_str().is_empty() {
            Path::new(".")
        } else {
            parent
        };
        if let Ok(dir) = File::open(parent) {
            let _ = dir.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = path;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporaries_of_dead_writers_are_cleaned_on_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.lut");
        // PID 999999999 is beyond any pid_max, so dead; a live one (ours) must be kept.
        let dead = dir.path().join(".t.lut.tmp-999999999-3");
        let live = dir
            .path()
            .join(format!(".t.lut.tmp-{}-77", std::process::id()));
        let other = dir.path().join(".u.lut.tmp-999999999-3");
        for f in [&dead, &live, &other] {
            fs::write(f, b"x").unwrap();
        }
        write_atomic(&p, b"new").unwrap();
        assert!(!dead.exists(), "a dead writer's temporary stays");
        assert!(live.exists() && other.exists());
        assert_eq!(fs::read(&p).unwrap(), b"new");
    }

    #[test]
    fn replaces_contents() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.lut");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"second");
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary files left"
        );
    }

    #[test]
    fn failed_write_keeps_old_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.lut");
        write_atomic(&p, b"precious work").unwrap();
        let err = write_atomic_with(&p, |f| {
            f.write_all(b"half of the new ")?;
            Err(io::Error::new(io::ErrorKind::StorageFull, "disk full"))
        })
        .unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::StorageFull);
        assert_eq!(fs::read(&p).unwrap(), b"precious work");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn missing_folder_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("no/such/folder/t.lut");
        assert!(write_atomic(&p, b"x").is_err());
    }
}
