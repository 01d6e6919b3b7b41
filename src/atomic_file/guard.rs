//! The guard that keeps a command from replacing what it reads: files are compared by identity
//! (device and inode), so another spelling of the path, a symbolic link, a hard link or a bind
//! mount of an input is caught alike.
//!
//! The command line runs one command per process: [`guard_command`] declares the files it reads
//! (every path its arguments name as inputs, folders expanded), and from then until the returned
//! [`CommandGuard`] is dropped every [`super::OutputTarget::open`] refuses an output that is one
//! of them, and an output this command has already written (two inputs of the same name would
//! otherwise overwrite each other's result). The inputs a command finds on its own are guarded
//! the same way, whichever command reads them: every file read through
//! [`crate::input_file::open_regular`] (a rosbag2 folder's `metadata.yaml` and `.mcap` files,
//! the table, parameters and `REC.cameras.json` a recording names, the files a session names)
//! and every SQLite storage file is declared to the guard ([`guard_read`]) when it is opened,
//! and an output is checked again just before it is renamed into place. Files the command line
//! names as replaced on purpose ([`guard_updated`]: `patterns learn --update`) are read without
//! becoming inputs. The app does not guard: saving a table over the table it opened is what
//! Save does.

use std::fs::{self, Metadata};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// A file's identity: the device it is on and its inode there.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FileId {
    device: u64,
    inode: u64,
}

impl FileId {
    /// The identity of the file `meta` describes (`None` where the platform has no inodes).
    #[must_use]
    pub fn of(meta: &Metadata) -> Option<Self> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt as _;
            Some(Self {
                device: meta.dev(),
                inode: meta.ino(),
            })
        }
        #[cfg(not(unix))]
        {
            let _ = meta;
            None
        }
    }

    /// The identity of the file at `path` (after links), if it exists.
    #[must_use]
    pub fn of_path(path: &Path) -> Option<Self> {
        fs::metadata(path).ok().as_ref().and_then(Self::of)
    }
}

/// The files of the running command.
#[derive(Debug, Default)]
struct Guarded {
    /// Whether a command is guarded now.
    active: bool,
    /// What it reads.
    inputs: Vec<(FileId, PathBuf)>,
    /// What it has written so far.
    written: Vec<(FileId, PathBuf)>,
    /// What it reads and then replaces on purpose (never an input).
    updated: Vec<FileId>,
}

static GUARDED: Mutex<Guarded> = Mutex::new(Guarded {
    active: false,
    inputs: Vec::new(),
    written: Vec::new(),
    updated: Vec::new(),
});

fn guarded() -> MutexGuard<'static, Guarded> {
    GUARDED.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Guards the outputs of the command about to run against `inputs` (see the module docs);
/// paths that do not exist are skipped. The guard ends when the returned value is dropped.
#[must_use = "the guard ends when this is dropped"]
pub fn guard_command<P: AsRef<Path>>(inputs: impl IntoIterator<Item = P>) -> CommandGuard {
    {
        let mut g = guarded();
        *g = Guarded {
            active: true,
            ..Guarded::default()
        };
    }
    guard_inputs(inputs);
    CommandGuard { _private: () }
}

/// Adds inputs found while the command runs (the frames of a folder, a label mask beside a
/// frame, a bag's storage file) to the guard; nothing happens when no command is guarded.
pub fn guard_inputs<P: AsRef<Path>>(inputs: impl IntoIterator<Item = P>) {
    let mut g = guarded();
    for p in inputs {
        let p = p.as_ref();
        if let Some(id) = FileId::of_path(p) {
            g.add_input(id, p);
        }
    }
}

/// Declares a file the running command has just opened for reading, by the metadata of the
/// open file (so the file read is the one guarded, whatever happens to its path later); nothing
/// happens when no command is guarded. [`crate::input_file::open_regular`] calls it for every
/// file it opens.
pub fn guard_read(meta: &Metadata, path: &Path) {
    if let Some(id) = FileId::of(meta) {
        guarded().add_input(id, path);
    }
}

/// Declares the files the guarded command reads and then replaces on purpose (`--update`):
/// reading them does not make them inputs.
pub fn guard_updated<P: AsRef<Path>>(paths: impl IntoIterator<Item = P>) {
    let mut g = guarded();
    if !g.active {
        return;
    }
    for p in paths {
        if let Some(id) = FileId::of_path(p.as_ref()) {
            g.inputs.retain(|(i, _)| *i != id);
            g.updated.push(id);
        }
    }
}

/// Ends the guard of [`guard_command`] when dropped.
#[derive(Debug)]
pub struct CommandGuard {
    _private: (),
}

impl Drop for CommandGuard {
    fn drop(&mut self) {
        *guarded() = Guarded::default();
    }
}

impl Guarded {
    /// Adds the input `id` (at `path`) while a command is guarded, unless it is known already or
    /// replaced on purpose.
    fn add_input(&mut self, id: FileId, path: &Path) {
        if self.active && !self.updated.contains(&id) && !self.inputs.iter().any(|(i, _)| *i == id)
        {
            self.inputs.push((id, path.to_owned()));
        }
    }

    /// Why the existing file `id` must not be replaced by an output, if it must not.
    fn refusal(&self, id: FileId) -> Option<io::Error> {
        if !self.active {
            return None;
        }
        if let Some((_, input)) = self.inputs.iter().find(|(i, _)| *i == id) {
            return Some(replaces_input(input));
        }
        self.written.iter().find(|(i, _)| *i == id).map(|(_, before)| {
            io::Error::new(
                io::ErrorKind::AlreadyExists,
                format!(
                    "{} was written already by this command: two inputs give outputs of the same name (rename one, or write them into separate folders)",
                    before.display()
                ),
            )
        })
    }
}

/// Refuses to replace the existing file `meta` describes when the guarded command reads it or
/// has written it already.
pub(super) fn check_output(meta: &Metadata) -> io::Result<()> {
    match FileId::of(meta).and_then(|id| guarded().refusal(id)) {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Refuses, just before an output is renamed onto `path`, a file there that the guarded command
/// has read meanwhile (an input found while it ran, after the output was opened).
pub(super) fn check_before_rename(path: &Path) -> io::Result<()> {
    match fs::metadata(path) {
        Ok(meta) if meta.is_file() => check_output(&meta),
        _ => Ok(()),
    }
}

/// Remembers an output the guarded command has finished writing.
pub(super) fn note_written(path: &Path) {
    let mut g = guarded();
    if g.active
        && let Some(id) = FileId::of_path(path)
    {
        g.written.push((id, path.to_owned()));
    }
}

/// Refuses, before any work, an output of the guarded command that is one of its inputs (the
/// output itself, or the `.partial` file a stream output is written through). Outputs are
/// checked again when written; this makes a command fail before its work rather than after.
///
/// # Errors
/// `InvalidInput` naming the input.
pub fn refuse_inputs(output: &Path) -> io::Result<()> {
    if let Some(input) = is_input(output) {
        return Err(replaces_input(&input));
    }
    match is_input(&super::partial_path(output)) {
        Some(input) => Err(goes_through_input(output, &input)),
        None => Ok(()),
    }
}

/// The error for a stream output whose `.partial` file is an input.
pub(super) fn goes_through_input(output: &Path, input: &Path) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "writing {} goes through {}, which this command reads; give the output another name",
            output.display(),
            input.display()
        ),
    )
}

/// True when the existing file at `path` is an input of the guarded command.
pub(super) fn is_input(path: &Path) -> Option<PathBuf> {
    let id = FileId::of_path(path)?;
    let g = guarded();
    g.inputs
        .iter()
        .find(|(i, _)| *i == id)
        .map(|(_, p)| p.clone())
}

fn replaces_input(input: &Path) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "the output would replace the input {}; name another file",
            input.display()
        ),
    )
}

/// Refuses an `output` that is one of `inputs` by identity (also through a link or another
/// spelling of the path): the check [`super::OutputTarget::open`] makes against a guarded
/// command's inputs, for callers that hold their own list.
///
/// # Errors
/// `InvalidInput` naming the input the output would replace.
pub fn refuse_overwriting(output: &Path, inputs: &[PathBuf]) -> io::Result<()> {
    // An output that does not exist yet cannot be an input.
    let Some(out) = FileId::of_path(output) else {
        return Ok(());
    };
    match inputs.iter().find(|p| FileId::of_path(p) == Some(out)) {
        Some(p) => Err(replaces_input(p)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The process-wide guard is not switched on here: other tests write files in parallel.
    #[test]
    fn inputs_and_outputs_written_before_are_refused_by_identity() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (input, written, other) = (
            dir.path().join("in.json"),
            dir.path().join("a.png"),
            dir.path().join("b.png"),
        );
        for p in [&input, &written, &other] {
            fs::write(p, b"x").expect("write");
        }
        let id = |p: &Path| FileId::of_path(p).expect("exists");
        let mut g = Guarded {
            active: true,
            inputs: vec![(id(&input), input.clone())],
            written: vec![(id(&written), written.clone())],
            updated: Vec::new(),
        };
        let e = g.refusal(id(&input)).expect("an input");
        assert!(e.to_string().contains("would replace the input"), "{e}");
        let e = g.refusal(id(&written)).expect("written before");
        assert!(e.to_string().contains("written already"), "{e}");
        assert!(g.refusal(id(&other)).is_none());
        // A file read and replaced on purpose is never an input.
        let updated = dir.path().join("places.json");
        fs::write(&updated, b"x").expect("write");
        g.updated.push(id(&updated));
        g.add_input(id(&updated), &updated);
        g.add_input(id(&other), &other);
        assert!(g.refusal(id(&updated)).is_none(), "updated on purpose");
        assert!(g.refusal(id(&other)).is_some(), "read while running");
        g.active = false;
        assert!(g.refusal(id(&input)).is_none(), "no command guarded");
    }
}
