//! Writing the files a user names: the one way every output of eotn is written (the command
//! line's `-o`, `--annotate`, `--plots`, …, the app's saves, recorded streams), so that every
//! command, including those added later, follows the same rules. [`OutputTarget::open`] looks
//! at the path once and decides:
//!
//! | the path is | what happens |
//! |---|---|
//! | nothing yet | a temporary file beside it, `fsync`, `rename` onto the name |
//! | a regular file | the same; the new file keeps the old one's permission bits (and its owner and group where the process may set them: as root) |
//! | a symbolic link | the file at the end of the chain is replaced as above; the link stays |
//! | a character or block device, a FIFO | written in place, never replaced, renamed or `chmod`-ed: `-o /dev/null` discards, `-o /dev/stdout` prints |
//! | a folder | an error saying so |
//! | a file the running command reads (`guard`) | an error naming the input, compared by device and inode, so a hard link or a bind mount is caught |
//!
//! A hand-made lookup table is hours of work: a crash, a full disk or a failed write never
//! leaves a half-written file. On any error the temporary file is removed and the old file is
//! untouched. Streams are written as `NAME.partial` beside the name instead, readable after a
//! crash, locked while written, and never truncated by the next writer ([`PartialFile`]).

mod guard;
mod partial;
mod target;

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

pub use guard::{
    CommandGuard, FileId, guard_command, guard_inputs, guard_read, guard_updated, refuse_inputs,
    refuse_overwriting,
};
pub use partial::{PartialFile, is_partial_name, partial_path};
pub use target::{OutputFile, OutputTarget, TargetKind};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A temporary path beside `path`, unique within this process.
fn temp_path_for(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

/// Writes `bytes` to `path` through [`OutputTarget`] (see the module docs).
///
/// # Errors
/// Any I/O error, a folder, or an input of the running command; `path` then still holds its old
/// contents (or still does not exist).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// Like [`write_atomic`], with the contents produced by `write`.
///
/// # Errors
/// Any I/O error from `write` or the file system; the target is then untouched.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut OutputFile) -> io::Result<()>,
) -> io::Result<()> {
    let mut out = OutputTarget::open(path)?.create()?;
    write(&mut out)?;
    out.commit()
}

/// Appends `bytes` to the file at `path` (made when missing) and syncs them to the disk: the
/// edit journal's one line at a time. Links are followed as any append follows them; a device
/// or FIFO is written to as it is (nothing is renamed anyway); a folder is an error.
///
/// # Errors
/// A folder, or what the OS says.
pub fn append_synced(path: &Path, bytes: &[u8]) -> io::Result<()> {
    if fs::metadata(path).is_ok_and(|m| m.is_dir()) {
        return Err(io::Error::new(
            io::ErrorKind::IsADirectory,
            "is a folder; name a file",
        ));
    }
    let mut file = fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)?;
    file.write_all(bytes)?;
    if file.metadata()?.is_file() {
        file.sync_data()?;
    }
    Ok(())
}

/// Makes `path` a folder that outputs can be written into: made with its parents when missing,
/// a link to a folder followed.
///
/// # Errors
/// `NotADirectory` when something else is there (a file, a device, a FIFO), or what the OS
/// says.
pub fn output_folder(path: &Path) -> io::Result<()> {
    match fs::metadata(path) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => Err(io::Error::new(
            io::ErrorKind::NotADirectory,
            "is not a folder: name a folder for the files (it is made if missing)",
        )),
        Err(e) if e.kind() == io::ErrorKind::NotFound => fs::create_dir_all(path),
        Err(e) => Err(e),
    }
}

/// A file written beside an output and named after it (`CAL.lines.png` beside `CAL.json`:
/// `extension` replaces the output's), or `None` when the output is written in place (a device
/// or FIFO, or `/dev/stdout`, has no folder of its own for it).
#[must_use]
pub fn beside_output(output: &Path, extension: &str) -> Option<PathBuf> {
    let in_place = match fs::metadata(output) {
        Ok(m) if m.is_file() => target::resolve_links(output).ok().flatten().is_none(),
        Ok(m) => !m.is_dir(),
        Err(_) => false,
    };
    (!in_place).then(|| output.with_extension(extension))
}

/// Removes temporaries of `path` left by writers of ours that were killed (`kill -9`, a power
/// cut): `.NAME.tmp-PID-N` files whose process no longer runs. Only our own naming is touched,
/// and only where the system says which processes run (`/proc`).
fn clean_stale_temporaries(path: &Path) {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return;
    };
    let dir = parent_or_dot(path);
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

/// The folder of `path`, `.` for a bare file name.
fn parent_or_dot(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Flushes the folder entry of a renamed file, so the rename itself survives a power cut.
/// Not every platform can open a folder for syncing; failures are ignored there.
fn sync_parent(path: &Path) {
    #[cfg(unix)]
    if let Ok(dir) = File::open(parent_or_dot(path)) {
        let _ = dir.sync_all();
    }
    #[cfg(not(unix))]
    let _ = path;
}

#[cfg(test)]
mod tests;
