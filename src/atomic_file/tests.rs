use std::fs;
use std::io::{self, Read as _, Seek as _, SeekFrom, Write as _};
use std::path::{Path, PathBuf};

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

#[test]
fn a_folder_is_a_clear_error_and_stays() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("sub");
    fs::create_dir(&sub).unwrap();
    fs::write(sub.join("inside"), b"kept").unwrap();
    let err = write_atomic(&sub, b"x").unwrap_err();
    assert_eq!(err.kind(), io::ErrorKind::IsADirectory);
    assert!(err.to_string().contains("is a folder"), "{err}");
    assert_eq!(fs::read(sub.join("inside")).unwrap(), b"kept");
}

#[cfg(unix)]
fn mode(p: &Path) -> u32 {
    use std::os::unix::fs::PermissionsExt as _;
    fs::metadata(p).unwrap().permissions().mode() & 0o7777
}

#[cfg(unix)]
#[test]
fn a_replaced_file_keeps_its_permission_bits() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = tempfile::tempdir().unwrap();
    for bits in [0o600, 0o640, 0o444] {
        let p = dir.path().join(format!("f{bits:o}"));
        fs::write(&p, b"old").unwrap();
        fs::set_permissions(&p, fs::Permissions::from_mode(bits)).unwrap();
        write_atomic(&p, b"new").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new");
        assert_eq!(mode(&p), bits, "mode {bits:o} changed");
    }
}

#[cfg(unix)]
#[test]
fn a_symlink_stays_and_its_target_is_replaced() {
    use std::os::unix::fs::{PermissionsExt as _, symlink};
    let dir = tempfile::tempdir().unwrap();
    let real_dir = dir.path().join("real");
    fs::create_dir(&real_dir).unwrap();
    let target = real_dir.join("t.json");
    fs::write(&target, b"old").unwrap();
    fs::set_permissions(&target, fs::Permissions::from_mode(0o600)).unwrap();
    // A relative link through a second link.
    let first = dir.path().join("first");
    let link = dir.path().join("link");
    symlink("real/t.json", &first).unwrap();
    symlink("first", &link).unwrap();
    write_atomic(&link, b"new").unwrap();
    assert!(
        fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert!(
        fs::symlink_metadata(&first)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(fs::read(&target).unwrap(), b"new");
    assert_eq!(mode(&target), 0o600);
    assert_eq!(
        fs::read_dir(&real_dir).unwrap().count(),
        1,
        "no temporary left"
    );
    // A link to nothing yet makes its target, as a shell's `>` does.
    let dangling = dir.path().join("dangling");
    symlink("real/made.json", &dangling).unwrap();
    write_atomic(&dangling, b"made").unwrap();
    assert!(
        fs::symlink_metadata(&dangling)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(fs::read(real_dir.join("made.json")).unwrap(), b"made");
    // A loop is an error, not a hang.
    symlink("loop-b", dir.path().join("loop-a")).unwrap();
    symlink("loop-a", dir.path().join("loop-b")).unwrap();
    assert!(write_atomic(&dir.path().join("loop-a"), b"x").is_err());
}

/// A private device node like `/dev/null` (character device 1, 3) in `dir`, or `None` (with a
/// note) where `mknod` is refused: not root, or a container without the capability. Under
/// `CI=true` a refusal fails the test.
#[cfg(unix)]
pub(crate) fn private_null(dir: &Path) -> Option<PathBuf> {
    let p = dir.join("null");
    let ok = std::process::Command::new("mknod")
        .args(["-m", "666"])
        .arg(&p)
        .args(["c", "1", "3"])
        .status()
        .is_ok_and(|s| s.success());
    if ok {
        return Some(p);
    }
    crate::test_skip::skipped(
        "mknod is refused here (not root?): the device-node case is not tested",
        "run the tests as root, or in a container that allows mknod",
    );
    None
}

#[cfg(unix)]
fn is_null_device(p: &Path) -> bool {
    use std::os::unix::fs::{FileTypeExt as _, MetadataExt as _};
    let m = fs::symlink_metadata(p).unwrap();
    m.file_type().is_char_device() && m.rdev() == fs::metadata("/dev/null").unwrap().rdev()
}

#[cfg(unix)]
#[test]
fn a_device_is_written_in_place_and_never_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let Some(null) = private_null(dir.path()) else {
        return;
    };
    let target = OutputTarget::open(&null).unwrap();
    assert!(target.is_direct());
    write_atomic(&null, b"discarded").unwrap();
    assert!(is_null_device(&null), "the device node was replaced");
    assert_eq!(mode(&null), 0o666, "the device node was chmod-ed");
    // A stream into it: front to back, no partial file.
    let mut out = target.create_partial().unwrap();
    assert!(!out.seekable() && out.partial().is_none());
    out.write_all(b"0123").unwrap();
    assert_eq!(out.stream_position().unwrap(), 4);
    assert!(out.seek(SeekFrom::Start(0)).is_err(), "seeking back");
    out.finish().unwrap();
    assert!(is_null_device(&null));
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1, "{dir:?}");
}

/// A FIFO in `dir` whose contents a thread collects; `None` (with a note) without `mkfifo`.
#[cfg(unix)]
pub(crate) fn fifo_with_reader(dir: &Path) -> Option<(PathBuf, std::thread::JoinHandle<Vec<u8>>)> {
    let p = dir.join("fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&p)
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        crate::test_skip::skipped(
            "mkfifo failed: the FIFO case is not tested",
            "install coreutils' mkfifo, on a file system that allows FIFOs",
        );
        return None;
    }
    let reader = p.clone();
    let handle = std::thread::spawn(move || {
        let mut bytes = Vec::new();
        fs::File::open(reader)
            .and_then(|mut f| f.read_to_end(&mut bytes))
            .unwrap();
        bytes
    });
    Some((p, handle))
}

#[cfg(unix)]
#[test]
fn a_fifo_is_written_in_place() {
    use std::os::unix::fs::FileTypeExt as _;
    let dir = tempfile::tempdir().unwrap();
    let Some((fifo, reader)) = fifo_with_reader(dir.path()) else {
        return;
    };
    write_atomic(&fifo, b"through the pipe").unwrap();
    assert_eq!(reader.join().unwrap(), b"through the pipe");
    assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
}

#[test]
fn an_earlier_partial_is_moved_aside_never_truncated() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rec.mcap");
    let crashed = partial_path(&out);
    fs::write(&crashed, b"twenty seconds of a crashed recording").unwrap();
    fs::write(dir.path().join("rec.mcap.partial.1"), b"an older one").unwrap();
    let mut file = OutputTarget::open(&out).unwrap().create_partial().unwrap();
    let aside = dir.path().join("rec.mcap.partial.2");
    assert_eq!(file.moved_aside(), Some(aside.as_path()));
    assert_eq!(
        fs::read(&aside).unwrap(),
        b"twenty seconds of a crashed recording"
    );
    assert_eq!(
        fs::read(dir.path().join("rec.mcap.partial.1")).unwrap(),
        b"an older one"
    );
    file.write_all(b"new").unwrap();
    file.finish().unwrap();
    assert_eq!(fs::read(&out).unwrap(), b"new");
    assert!(!crashed.exists());
    assert!(is_partial_name("rec.mcap.partial.2") && is_partial_name("rec.mcap.partial"));
    assert!(!is_partial_name("rec.mcap.partial.x") && !is_partial_name("rec.mcap"));
}

#[test]
fn a_second_writer_of_the_same_output_is_refused_while_the_first_writes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rec.mcap");
    let mut first = OutputTarget::open(&out).unwrap().create_partial().unwrap();
    first.write_all(b"the first recording").unwrap();
    let err = OutputTarget::open(&out)
        .unwrap()
        .create_partial()
        .expect_err("a second writer");
    assert_eq!(err.kind(), io::ErrorKind::ResourceBusy);
    assert!(err.to_string().contains("another eotn is writing"), "{err}");
    first.sync().unwrap();
    assert_eq!(
        fs::read(partial_path(&out)).unwrap(),
        b"the first recording",
        "the second writer touched the first's file"
    );
    first.finish().unwrap();
    // Once the first has finished, the output is free again.
    let second = OutputTarget::open(&out).unwrap().create_partial().unwrap();
    assert!(second.moved_aside().is_none());
}

#[cfg(unix)]
#[test]
fn a_finished_stream_keeps_the_replaced_file_s_mode() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rec.mcap");
    fs::write(&out, b"old").unwrap();
    fs::set_permissions(&out, fs::Permissions::from_mode(0o600)).unwrap();
    let mut file = OutputTarget::open(&out).unwrap().create_partial().unwrap();
    file.write_all(b"new").unwrap();
    file.finish().unwrap();
    assert_eq!(fs::read(&out).unwrap(), b"new");
    assert_eq!(mode(&out), 0o600);
}

#[test]
fn hard_links_and_other_spellings_of_an_input_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.lut");
    fs::write(&input, b"x").unwrap();
    let hard = dir.path().join("alias.lut");
    fs::hard_link(&input, &hard).unwrap();
    let inputs = [input.clone()];
    let err = refuse_overwriting(&hard, &inputs).unwrap_err();
    assert!(err.to_string().contains("in.lut"), "{err}");
    let dotted = dir.path().join(".").join("in.lut");
    assert!(refuse_overwriting(&dotted, &inputs).is_err());
    assert!(refuse_overwriting(&dir.path().join("new.lut"), &inputs).is_ok());
    fs::write(dir.path().join("other.lut"), b"y").unwrap();
    assert!(refuse_overwriting(&dir.path().join("other.lut"), &inputs).is_ok());
}
