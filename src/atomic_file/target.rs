//! [`OutputTarget`]: what an output path names, decided once from the file system;
//! [`OutputFile`]: the writer it gives, committed by [`OutputFile::commit`].

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use super::{clean_stale_temporaries, guard, parent_or_dot, sync_parent, temp_path_for};

/// Most symbolic links followed from an output path to its file (Linux's own limit).
const MAX_LINKS: usize = 40;

/// How an output is written, decided by [`OutputTarget::open`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetKind {
    /// Nothing is there yet: a temporary file is renamed onto the name.
    New,
    /// A regular file: replaced by a renamed temporary that keeps its permission bits (and its
    /// owner where the process may set it).
    Replace,
    /// A device, a FIFO, or a file reached through `/proc` (`/dev/stdout`): written in place,
    /// never replaced. `seekable` is false for devices and FIFOs (streams are then written
    /// front to back).
    Direct {
        /// Whether the target can seek (a regular file behind `/dev/stdout`).
        seekable: bool,
    },
}

/// An output path, looked at: where the bytes go and how (see the module docs of
/// [`crate::atomic_file`]).
#[derive(Debug, Clone)]
pub struct OutputTarget {
    /// The path as given.
    given: PathBuf,
    /// The file written: `given`, or the end of its chain of symbolic links.
    path: PathBuf,
    kind: TargetKind,
}

impl OutputTarget {
    /// Looks at `path`: a new file, a file to replace, a device or FIFO to write into.
    ///
    /// # Errors
    /// `IsADirectory` for a folder, `InvalidInput` for a file the running command reads (see
    /// [`super::guard_command`]) or a loop of links, and what the OS says about the path.
    pub fn open(path: &Path) -> io::Result<Self> {
        let target = |kind, resolved: PathBuf| Self {
            given: path.to_owned(),
            path: resolved,
            kind,
        };
        match fs::metadata(path) {
            Ok(meta) if meta.is_dir() => Err(io::Error::new(
                io::ErrorKind::IsADirectory,
                "is a folder; name a file (an output file is written, not a folder)",
            )),
            Ok(meta) if meta.is_file() => match resolve_links(path)? {
                Some(resolved) => {
                    guard::check_output(&meta)?;
                    Ok(target(TargetKind::Replace, resolved))
                }
                None => Ok(target(
                    TargetKind::Direct { seekable: true },
                    path.to_owned(),
                )),
            },
            // A character or block device, a FIFO, a socket: written in place, as Unix tools do.
            Ok(_) => Ok(target(
                TargetKind::Direct { seekable: false },
                path.to_owned(),
            )),
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                // Nothing there, or a link to nothing yet: the file at the end of the chain is
                // made (as a shell's `>` makes it).
                let resolved = resolve_links(path)?.unwrap_or_else(|| path.to_owned());
                Ok(target(TargetKind::New, resolved))
            }
            Err(e) => Err(e),
        }
    }

    /// The path as the user gave it.
    #[must_use]
    pub fn given(&self) -> &Path {
        &self.given
    }

    /// The file that is written: the given path, or the end of its chain of links.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// How it is written.
    #[must_use]
    pub const fn kind(&self) -> TargetKind {
        self.kind
    }

    /// True when the output is written in place (a device, a FIFO): nothing is renamed.
    #[must_use]
    pub const fn is_direct(&self) -> bool {
        matches!(self.kind, TargetKind::Direct { .. })
    }

    /// Starts writing: a temporary file beside the target, or the device itself.
    ///
    /// # Errors
    /// The temporary cannot be made (a missing or read-only folder), or the device cannot be
    /// opened.
    pub fn create(&self) -> io::Result<OutputFile> {
        let (file, temp) = match self.kind {
            TargetKind::Direct { seekable } => (open_direct(&self.path, seekable)?, None),
            TargetKind::New | TargetKind::Replace => {
                clean_stale_temporaries(&self.path);
                let tmp = temp_path_for(&self.path);
                let file = OpenOptions::new().write(true).create_new(true).open(&tmp)?;
                let temp = Temporary(Some(tmp));
                if self.kind == TargetKind::Replace {
                    keep_mode_and_owner(&file, &self.path)?;
                }
                (file, Some(temp))
            }
        };
        Ok(OutputFile {
            out: BufWriter::with_capacity(1 << 16, file),
            temp,
            path: self.path.clone(),
        })
    }
}

/// Opens a device, FIFO or `/proc`-reached file for writing in place (a FIFO waits for its
/// reader, as any writer does). A regular file reached that way is truncated first, as a
/// shell's `>` does.
pub(super) fn open_direct(path: &Path, truncate: bool) -> io::Result<File> {
    OpenOptions::new().write(true).truncate(truncate).open(path)
}

/// A temporary file, removed when dropped unless taken (renamed into place).
#[derive(Debug)]
struct Temporary(Option<PathBuf>);

impl Drop for Temporary {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            // Best effort: the temporary file is ours and useless now.
            let _ = fs::remove_file(p);
        }
    }
}

/// An output being written ([`OutputTarget::create`]): nothing reaches the named file until
/// [`OutputFile::commit`]; dropped without it, the temporary is removed.
#[derive(Debug)]
pub struct OutputFile {
    out: BufWriter<File>,
    temp: Option<Temporary>,
    path: PathBuf,
}

impl OutputFile {
    /// The file that is written (after links).
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and renames the temporary onto the target (a device is only flushed).
    ///
    /// # Errors
    /// A write, sync or rename error; the target then still holds its old contents.
    pub fn commit(self) -> io::Result<()> {
        let Self {
            out,
            mut temp,
            path,
        } = self;
        let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
        let Some(tmp) = temp.as_mut().and_then(|t| t.0.take()) else {
            // In place: a regular file behind `/dev/stdout` is synced; a device or FIFO may
            // not sync at all (EINVAL), which is not an error of the output.
            if file.metadata().is_ok_and(|m| m.is_file()) {
                file.sync_all()?;
            }
            return Ok(());
        };
        let result = file.sync_all().and_then(|()| {
            drop(file);
            guard::check_before_rename(&path)?;
            fs::rename(&tmp, &path)
        });
        if let Err(e) = result {
            let _ = fs::remove_file(&tmp);
            return Err(e);
        }
        sync_parent(&path);
        guard::note_written(&path);
        Ok(())
    }
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.out.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.out.write_all(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

/// Follows the symbolic links of `path` to the file they end at (which may not exist yet).
/// `None` when the chain passes through `/proc` (`/dev/stdout` → `/proc/self/fd/1`), whose
/// links name open files rather than paths: such a target is written in place.
///
/// # Errors
/// A loop (more than 40 links), or what the OS says.
pub(super) fn resolve_links(path: &Path) -> io::Result<Option<PathBuf>> {
    let mut p = path.to_owned();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                if through_proc(&p) {
                    return Ok(None);
                }
                let link = fs::read_link(&p)?;
                p = if link.is_absolute() {
                    link
                } else {
                    parent_or_dot(&p).join(link)
                };
            }
            Ok(_) => return Ok(Some(p)),
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Some(p)),
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("more than {MAX_LINKS} symbolic links (a loop?)"),
    ))
}

/// True when the link `p` lives in `/proc` (after its folder's own links: `/dev/fd` is
/// `/proc/self/fd`).
fn through_proc(p: &Path) -> bool {
    fs::canonicalize(parent_or_dot(p)).is_ok_and(|d| d.starts_with("/proc"))
}

/// Gives the new file `file` the permission bits of the file at `old` (and its owner and group
/// where the process may: as root; elsewhere a failed `chown` leaves ours, as `cp` does).
#[cfg(unix)]
pub(super) fn keep_mode_and_owner(file: &File, old: &Path) -> io::Result<()> {
    use std::os::unix::fs::{MetadataExt as _, PermissionsExt as _};
    let Ok(meta) = fs::metadata(old) else {
        return Ok(());
    };
    let ours = file.metadata()?;
    if (ours.uid(), ours.gid()) != (meta.uid(), meta.gid()) {
        // Before the mode: a change of owner clears set-user-id bits.
        let _ = std::os::unix::fs::fchown(file, Some(meta.uid()), Some(meta.gid()));
    }
    file.set_permissions(fs::Permissions::from_mode(meta.mode() & 0o7777))
}

/// Gives the new file the old one's read-only flag (the only permission other systems keep).
#[cfg(not(unix))]
pub(super) fn keep_mode_and_owner(file: &File, old: &Path) -> io::Result<()> {
    match fs::metadata(old) {
        Ok(meta) => file.set_permissions(meta.permissions()),
        Err(_) => Ok(()),
    }
}
