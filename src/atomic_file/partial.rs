//! [`PartialFile`]: a long output (a recorded or rendered stream) written as `NAME.partial`
//! beside its name, readable up to its last flushed part after a crash, and renamed onto the
//! name when finished.
//!
//! Rules, so that nothing recorded is lost to the next writer:
//! - an existing `NAME.partial` (a crashed recording) is never truncated: it is moved aside to
//!   `NAME.partial.1` (the first free number), with a warning naming where;
//! - the partial file is locked (`flock`) while written: a second writer of the same output gets
//!   an error saying another eotn is writing it;
//! - a device or FIFO is written in place (no partial, nothing renamed), front to back.

use std::fs::{self, File, OpenOptions, TryLockError};
use std::io::{self, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::target::{keep_mode_and_owner, open_direct};
use super::{FileId, OutputTarget, TargetKind, guard, sync_parent};

/// Most earlier partial files kept beside one output (`NAME.partial.1` … `.999`).
const MAX_MOVED_ASIDE: u32 = 999;

/// The partial file of an output: `NAME.partial` beside it.
#[must_use]
pub fn partial_path(path: &Path) -> PathBuf {
    let mut p = path.as_os_str().to_owned();
    p.push(".partial");
    PathBuf::from(p)
}

/// True for a file name written by [`PartialFile`]: `NAME.partial`, or one moved aside,
/// `NAME.partial.N`.
#[must_use]
pub fn is_partial_name(name: &str) -> bool {
    name.ends_with(".partial")
        || name.rsplit_once(".partial.").is_some_and(|(_, n)| {
            !n.is_empty() && n.len() <= 3 && n.bytes().all(|b| b.is_ascii_digit())
        })
}

/// A stream output being written (see the module docs): [`Write`] and [`Seek`] (for a device
/// or FIFO, seeking reports the position only, as `mcap`'s `NoSeek` expects).
#[derive(Debug)]
pub struct PartialFile {
    file: File,
    /// The file written until [`PartialFile::finish`]; `None` when written in place.
    partial: Option<PathBuf>,
    /// The file replaced at the end (after links).
    path: PathBuf,
    /// Whether `file` seeks.
    seekable: bool,
    /// Bytes written, for the position of a file that does not seek.
    position: u64,
    /// Where an earlier partial file was moved.
    moved_aside: Option<PathBuf>,
}

impl OutputTarget {
    /// Starts a stream output: `NAME.partial`, locked, after moving an earlier one aside; or the
    /// device itself.
    ///
    /// # Errors
    /// Another writer holds the partial file; the partial name is taken by something that is
    /// not a file, or is an input of the running command; what the OS says.
    pub fn create_partial(&self) -> io::Result<PartialFile> {
        if let TargetKind::Direct { seekable } = self.kind() {
            return Ok(PartialFile {
                file: open_direct(self.path(), seekable)?,
                partial: None,
                path: self.path().to_owned(),
                seekable,
                position: 0,
                moved_aside: None,
            });
        }
        let partial = partial_path(self.path());
        let moved_aside = move_aside(&partial, self.path())?;
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&partial)
            .map_err(|e| {
                if e.kind() == io::ErrorKind::AlreadyExists {
                    another_writer(self.path())
                } else {
                    e
                }
            })?;
        lock(&file, self.path())?;
        // Another writer could have moved our fresh file aside between its creation and the
        // lock: the name must still be ours.
        if FileId::of(&file.metadata()?) != FileId::of_path(&partial) {
            return Err(another_writer(self.path()));
        }
        if self.kind() == TargetKind::Replace {
            keep_mode_and_owner(&file, self.path())?;
        }
        Ok(PartialFile {
            file,
            partial: Some(partial),
            path: self.path().to_owned(),
            seekable: true,
            position: 0,
            moved_aside,
        })
    }
}

/// Moves an earlier `partial` of `output` aside to `partial.N`, unless a writer holds it.
fn move_aside(partial: &Path, output: &Path) -> io::Result<Option<PathBuf>> {
    let meta = match fs::symlink_metadata(partial) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e),
    };
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::AlreadyExists,
            format!(
                "{} is in the way and is not a file eotn wrote; move it away",
                partial.display()
            ),
        ));
    }
    if let Some(input) = guard::is_input(partial) {
        return Err(guard::goes_through_input(output, &input));
    }
    let old = File::open(partial)?;
    lock(&old, output)?;
    let Some(aside) = (1..=MAX_MOVED_ASIDE)
        .map(|n| {
            let mut p = partial.as_os_str().to_owned();
            p.push(format!(".{n}"));
            PathBuf::from(p)
        })
        .find(|p| fs::symlink_metadata(p).is_err())
    else {
        return Err(io::Error::new(
            io::ErrorKind::AlreadyExists,
            format!(
                "{} and {MAX_MOVED_ASIDE} earlier partial files are in the way; clear them",
                partial.display()
            ),
        ));
    };
    fs::rename(partial, &aside)?;
    sync_parent(partial);
    log::warn!(
        "{}: an unfinished earlier recording (its writer stopped) was kept as {}",
        partial.display(),
        aside.display()
    );
    Ok(Some(aside))
}

/// Takes the advisory lock of a partial file without waiting.
fn lock(file: &File, output: &Path) -> io::Result<()> {
    match file.try_lock() {
        Ok(()) => Ok(()),
        Err(TryLockError::WouldBlock) => Err(another_writer(output)),
        Err(TryLockError::Error(e)) if e.kind() == io::ErrorKind::Unsupported => Ok(()),
        Err(TryLockError::Error(e)) => Err(e),
    }
}

fn another_writer(output: &Path) -> io::Error {
    io::Error::new(
        io::ErrorKind::ResourceBusy,
        format!(
            "another eotn is writing {} (its .partial file is locked); choose another output or wait for it to finish",
            output.display()
        ),
    )
}

impl PartialFile {
    /// False for a device or FIFO: the writer must not seek back.
    #[must_use]
    pub const fn seekable(&self) -> bool {
        self.seekable
    }

    /// The file written until [`PartialFile::finish`] (`None`: written in place).
    #[must_use]
    pub fn partial(&self) -> Option<&Path> {
        self.partial.as_deref()
    }

    /// The file the output ends as (after links).
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Where an earlier unfinished partial file of this output was moved, if there was one.
    #[must_use]
    pub fn moved_aside(&self) -> Option<&Path> {
        self.moved_aside.as_deref()
    }

    /// Writes what is buffered to the disk (`fsync`; a device or FIFO is only flushed).
    ///
    /// # Errors
    /// The sync fails.
    pub fn sync(&mut self) -> io::Result<()> {
        self.file.flush()?;
        if self.partial.is_some() {
            self.file.sync_data()?;
        }
        Ok(())
    }

    /// Syncs the partial file and renames it onto the output (keeping the replaced file's
    /// permission bits); a device or FIFO is only flushed.
    ///
    /// # Errors
    /// The sync or the rename fails; the partial file then stays.
    pub fn finish(self) -> io::Result<()> {
        let Some(partial) = self.partial else {
            return (&self.file).flush();
        };
        self.file.sync_all()?;
        keep_mode_and_owner(&self.file, &self.path)?;
        guard::check_before_rename(&self.path)?;
        fs::rename(&partial, &self.path)?;
        sync_parent(&self.path);
        guard::note_written(&self.path);
        // The lock goes with the file, after the rename.
        drop(self.file);
        Ok(())
    }
}

impl PartialFile {
    /// Stops writing and removes the partial file: nothing reaches the output (written in
    /// place, what was written stays written).
    ///
    /// # Errors
    /// The partial file cannot be removed.
    pub fn discard(self) -> io::Result<()> {
        match self.partial {
            Some(p) => fs::remove_file(p),
            None => Ok(()),
        }
    }
}

impl Write for PartialFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.file.write(buf)?;
        self.position += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

impl Seek for PartialFile {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        if self.seekable {
            let at = self.file.seek(pos)?;
            self.position = at;
            return Ok(at);
        }
        // Front to back only: asking where we are is answered, moving is not.
        match pos {
            SeekFrom::Current(0) | SeekFrom::End(0) => Ok(self.position),
            SeekFrom::Start(p) if p == self.position => Ok(p),
            _ => Err(io::Error::new(
                io::ErrorKind::Unsupported,
                "the output is a device or FIFO: it cannot seek",
            )),
        }
    }
}
