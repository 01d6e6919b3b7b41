//! Every output option the command line defines, run against what Unix tools must respect: a
//! regular file (kept mode), a symbolic link (kept, its target replaced), a device node (written
//! in place, never replaced), a FIFO (written in place), a folder (a clear error), and a hard
//! link of each of the command's own inputs (refused, the input untouched). The options are
//! found by walking `eotn`'s clap definition (`eotn::cli::paths`), so an output added later
//! without a recipe here fails the test instead of being missed.
//!
//! Device nodes are private ones made with `mknod` in a temporary folder (the test skips that
//! case visibly where `mknod` is refused, and fails under `CI=true`); `/dev/null` is never used.

use std::ffi::{OsStr, OsString};
use std::fs;
use std::os::unix::fs::{FileTypeExt as _, MetadataExt as _, PermissionsExt as _, symlink};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use clap::CommandFactory as _;
use eotn::cli::paths::{PathRole, path_role};

use crate::common::{eotn, eotn_ok, repo_file, sim_stream};

/// The user and group id given to an output file before it is replaced (no such user needed).
const OTHER_ID: u32 = 4242;

/// Inputs every recipe may use, made once in a temporary folder.
struct Fixture {
    dir: tempfile::TempDir,
    lut: PathBuf,
    ball_edge: PathBuf,
    walk: PathBuf,
    goalkeeper: PathBuf,
    overhead: PathBuf,
    overhead_frame: PathBuf,
    points: PathBuf,
    field: PathBuf,
    pattern_tour: PathBuf,
    foreign_table: PathBuf,
    served: crate::live::Served,
}

impl Fixture {
    fn new() -> Self {
        let dir = tempfile::tempdir().unwrap();
        let copy = |name: &str, from: &str| {
            let p = dir.path().join(name);
            fs::copy(repo_file(from), &p).unwrap();
            p
        };
        let lut = copy("sim.lut", "lookup_tables/sim.lut");
        let ball_edge = copy("ball-edge.mcap", "streams/sim-ball-edge.mcap");
        let walk = copy("walk.mcap", "streams/sim-walk-and-pan.mcap");
        let goalkeeper = copy("goalkeeper.mcap", "streams/sim-goalkeeper.mcap");
        let overhead = copy("overhead.mcap", "streams/sim-overhead-game.mcap");
        let field = copy("field.json", "params/fields/four-legged-2005.json");
        // rUNSWift's calibration format is a bare 128³ table: our own sample read as one.
        let foreign_table = copy("robot.cal", "lookup_tables/sample.lut");
        let frames = dir.path().join("frames");
        eotn_ok(&[
            "export".as_ref(),
            overhead.as_os_str(),
            "--frames".as_ref(),
            "0".as_ref(),
            "-o".as_ref(),
            frames.as_os_str(),
        ]);
        let overhead_frame = dir.path().join("overhead.png");
        fs::rename(frames.join("overhead_000000.raw.png"), &overhead_frame).unwrap();
        let points = dir.path().join("points.json");
        eotn_ok(&[
            "overhead".as_ref(),
            "sim-points".as_ref(),
            "--stream".as_ref(),
            overhead.as_os_str(),
            "-o".as_ref(),
            points.as_os_str(),
        ]);
        let pattern_tour = sim_stream(dir.path(), "pattern-tour", 30, None);
        let served = crate::live::serve(&ball_edge, "127.0.0.1:0", &["--loop"]);
        Self {
            dir,
            lut,
            ball_edge,
            walk,
            goalkeeper,
            overhead,
            overhead_frame,
            points,
            field,
            pattern_tour,
            foreign_table,
            served,
        }
    }
}

/// The arguments of one command writing its output to `out`.
type Recipe = fn(&Fixture, &Path) -> Vec<OsString>;

fn args(parts: &[&OsStr]) -> Vec<OsString> {
    parts.iter().map(|p| (*p).to_owned()).collect()
}

/// A way to run every output option: `SUBCOMMAND… --LONG`.
fn recipes() -> Vec<(&'static str, Recipe)> {
    vec![
        ("classify --output", |f, out| {
            args(&[
                "classify".as_ref(),
                f.ball_edge.as_os_str(),
                "--lut".as_ref(),
                f.lut.as_os_str(),
                "--raw".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("export --output", |f, out| {
            args(&[
                "export".as_ref(),
                f.ball_edge.as_os_str(),
                "--frames".as_ref(),
                "0..2".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("render --output", |f, out| {
            args(&[
                "render".as_ref(),
                f.ball_edge.as_os_str(),
                "--lut".as_ref(),
                f.lut.as_os_str(),
                "--scale".as_ref(),
                "1".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("detect --annotate", |f, out| {
            args(&[
                "detect".as_ref(),
                f.ball_edge.as_os_str(),
                "--lut".as_ref(),
                f.lut.as_os_str(),
                "--annotate".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("eval --calibrate-goals", |f, out| {
            args(&[
                "eval".as_ref(),
                f.walk.as_os_str(),
                f.goalkeeper.as_os_str(),
                "--lut".as_ref(),
                f.lut.as_os_str(),
                "--calibrate-goals".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("eval --plots", |f, out| {
            args(&[
                "eval".as_ref(),
                f.ball_edge.as_os_str(),
                "--lut".as_ref(),
                f.lut.as_os_str(),
                "--plots".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("import --output", |f, out| {
            args(&[
                "import".as_ref(),
                f.ball_edge.as_os_str(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("lut-from-labels --output", |_, out| {
            args(&[
                "lut-from-labels".as_ref(),
                "--sim".as_ref(),
                "ball-edge".as_ref(),
                "--frames-per-scenario".as_ref(),
                "4".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("sim --output", |_, out| {
            args(&[
                "sim".as_ref(),
                "--scenario".as_ref(),
                "ball-edge".as_ref(),
                "--frames".as_ref(),
                "2".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("lut convert --output", |f, out| {
            args(&[
                "lut".as_ref(),
                "convert".as_ref(),
                f.foreign_table.as_os_str(),
                "--format".as_ref(),
                "runswift-cal".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("overhead marker --output", |_, out| {
            args(&[
                "overhead".as_ref(),
                "marker".as_ref(),
                "--team".as_ref(),
                "blue".as_ref(),
                "--id".as_ref(),
                "3".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("overhead calibrate --output", |f, out| {
            args(&[
                "overhead".as_ref(),
                "calibrate".as_ref(),
                "--points".as_ref(),
                f.points.as_os_str(),
                "--image".as_ref(),
                f.overhead_frame.as_os_str(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("overhead sim-field --output", |_, out| {
            args(&[
                "overhead".as_ref(),
                "sim-field".as_ref(),
                "--cameras".as_ref(),
                "1".as_ref(),
                "--size".as_ref(),
                "320x200".as_ref(),
                "--frames".as_ref(),
                "2".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("overhead sim-points --output", |f, out| {
            args(&[
                "overhead".as_ref(),
                "sim-points".as_ref(),
                "--stream".as_ref(),
                f.overhead.as_os_str(),
                "--field".as_ref(),
                f.field.as_os_str(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("patterns learn --output", |f, out| {
            args(&[
                "patterns".as_ref(),
                "learn".as_ref(),
                f.pattern_tour.as_os_str(),
                "--lut".as_ref(),
                f.lut.as_os_str(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
        ("record --output", |f, out| {
            let url = format!("ws://127.0.0.1:{}", f.served.port);
            args(&[
                "record".as_ref(),
                url.as_ref(),
                "--frames".as_ref(),
                "2".as_ref(),
                "-o".as_ref(),
                out.as_os_str(),
            ])
        }),
    ]
}

/// Every output option of the command line: (`SUBCOMMAND… --LONG`, a folder of outputs?).
fn defined_outputs() -> Vec<(String, bool)> {
    fn walk(cmd: &clap::Command, path: &mut Vec<String>, out: &mut Vec<(String, bool)>) {
        for arg in cmd.get_arguments() {
            let role = path_role(arg);
            let key = format!(
                "{} --{}",
                path.join(" "),
                arg.get_long().unwrap_or(arg.get_id().as_str())
            );
            // A file-writing option not marked as an output would escape the guard and this
            // test: its name gives it away.
            let long = arg.get_long().unwrap_or_default();
            let looks_like_output = arg.get_short() == Some('o')
                || [
                    "output",
                    "annotate",
                    "plots",
                    "calibrate-goals",
                    "save",
                    "write",
                ]
                .iter()
                .any(|w| long.contains(w));
            assert!(
                !looks_like_output
                    || matches!(role, Some(PathRole::Output | PathRole::OutputFolder)),
                "{key} looks like an output but its value name is not OUT or OUT_DIR"
            );
            match role {
                Some(PathRole::Output) => out.push((key, false)),
                Some(PathRole::OutputFolder) => out.push((key, true)),
                _ => {}
            }
        }
        for sub in cmd.get_subcommands() {
            path.push(sub.get_name().to_owned());
            walk(sub, path, out);
            path.pop();
        }
    }
    let mut out = Vec::new();
    walk(&eotn::cli::Cli::command(), &mut Vec::new(), &mut out);
    out
}

fn run(f: &Fixture, recipe: Recipe, out: &Path) -> Output {
    let a = recipe(f, out);
    let refs: Vec<&OsStr> = a.iter().map(OsString::as_os_str).collect();
    eotn(&refs)
}

fn ok(key: &str, case: &str, o: &Output) {
    assert!(
        o.status.success(),
        "{key} onto {case}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The one `eotn:` line of a failure.
fn failure(key: &str, case: &str, o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success(), "{key} onto {case} should fail");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("eotn:")).collect();
    assert_eq!(lines.len(), 1, "{key} onto {case}: one error line: {err}");
    lines[0].to_owned()
}

/// A private `/dev/null` (character device 1, 3), or `None` with a visible skip.
fn private_null(dir: &Path) -> Option<PathBuf> {
    private_device(dir, "null", 3)
}

/// A private copy of the memory device `1, minor` (3 `/dev/null`, 7 `/dev/full`) named `name`
/// in `dir`, mode 0666, or `None` with a visible skip where `mknod` is refused.
fn private_device(dir: &Path, name: &str, minor: u32) -> Option<PathBuf> {
    let p = dir.join(name);
    let made = Command::new("mknod")
        .args(["-m", "666"])
        .arg(&p)
        .args(["c", "1", &minor.to_string()])
        .status()
        .is_ok_and(|s| s.success());
    if made {
        return Some(p);
    }
    crate::common::skipped(
        "mknod is refused here (not root?): outputs onto a device are not tested",
        "run the tests as root, or in a container that allows mknod",
    );
    None
}

/// True while `p` is still the private device `1, minor` made by [`private_device`].
fn is_private_device(p: &Path, minor: u64) -> bool {
    let m = fs::symlink_metadata(p).unwrap();
    m.file_type().is_char_device()
        && m.rdev() == libc_makedev(1, minor)
        && m.mode() & 0o777 == 0o666
}

/// `makedev(major, minor)` as Linux encodes small numbers (the `rdev` of a memory device).
const fn libc_makedev(major: u64, minor: u64) -> u64 {
    ((major & 0xfff) << 8) | (minor & 0xff)
}

fn is_private_null(p: &Path) -> bool {
    let m = fs::symlink_metadata(p).unwrap();
    m.file_type().is_char_device()
        && m.rdev() == fs::metadata("/dev/null").unwrap().rdev()
        && m.mode() & 0o777 == 0o666
}

/// A FIFO with `cat` reading it into a file: (FIFO, reader, the file it fills).
fn fifo_with_reader(dir: &Path) -> (PathBuf, Child, PathBuf) {
    let fifo = dir.join("fifo");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let got = dir.join("from-fifo");
    let reader = Command::new("cat")
        .arg(&fifo)
        .stdout(fs::File::create(&got).unwrap())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    (fifo, reader, got)
}

/// Waits up to 10 s for the FIFO's reader to see the end; false if the writer never opened it.
fn reader_finished(reader: &mut Child) -> bool {
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(10) {
        if reader.try_wait().unwrap().is_some() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = reader.kill();
    let _ = reader.wait();
    false
}

/// An output file onto a regular file, a symlink, a device, a FIFO and a folder.
fn file_output_cases(f: &Fixture, key: &str, recipe: Recipe) {
    let case = tempfile::tempdir_in(f.dir.path()).unwrap();
    let dir = case.path();
    // A regular file keeps its mode.
    let plain = dir.join("plain.out");
    fs::write(&plain, b"old").unwrap();
    fs::set_permissions(&plain, fs::Permissions::from_mode(0o600)).unwrap();
    ok(key, "a 0600 file", &run(f, recipe, &plain));
    assert_ne!(fs::read(&plain).unwrap(), b"old", "{key}: not written");
    assert_eq!(fs::metadata(&plain).unwrap().mode() & 0o777, 0o600, "{key}");
    // A file of another owner keeps its owner and group (root can give them back; a user
    // cannot make such a file, which is a visible skip).
    let owned = dir.join("owned.out");
    fs::write(&owned, b"old").unwrap();
    if std::os::unix::fs::chown(&owned, Some(OTHER_ID), Some(OTHER_ID)).is_ok() {
        ok(key, "a file of another owner", &run(f, recipe, &owned));
        let m = fs::metadata(&owned).unwrap();
        assert_ne!(fs::read(&owned).unwrap(), b"old", "{key}: not written");
        assert_eq!((m.uid(), m.gid()), (OTHER_ID, OTHER_ID), "{key}: owner");
    } else {
        crate::common::skipped(
            "chown is refused (not root): the kept owner of an output is not tested",
            "run the tests as root",
        );
    }
    // A symlink stays; its target is replaced and keeps its mode.
    fs::create_dir(dir.join("real")).unwrap();
    let target = dir.join("real/target.out");
    fs::write(&target, b"old").unwrap();
    fs::set_permissions(&target, fs::Permissions::from_mode(0o640)).unwrap();
    let link = dir.join("link.out");
    symlink("real/target.out", &link).unwrap();
    ok(key, "a symlink", &run(f, recipe, &link));
    assert_eq!(
        fs::read_link(&link).unwrap(),
        Path::new("real/target.out"),
        "{key}"
    );
    assert_ne!(
        fs::read(&target).unwrap(),
        b"old",
        "{key}: target not written"
    );
    assert_eq!(
        fs::metadata(&target).unwrap().mode() & 0o777,
        0o640,
        "{key}"
    );
    // A device is written in place and stays the device.
    let devices = dir.join("dev");
    fs::create_dir(&devices).unwrap();
    if let Some(null) = private_null(&devices) {
        ok(key, "a device", &run(f, recipe, &null));
        assert!(
            is_private_null(&null),
            "{key}: the device node was replaced"
        );
        let left: Vec<_> = fs::read_dir(&devices).unwrap().flatten().collect();
        assert_eq!(left.len(), 1, "{key}: files beside the device: {left:?}");
    }
    // A full device (`/dev/full`'s numbers): a clear error, the device kept, nothing beside it.
    let full_dir = dir.join("full");
    fs::create_dir(&full_dir).unwrap();
    if let Some(full) = private_device(&full_dir, "full", 7) {
        let err = failure(key, "a full device", &run(f, recipe, &full));
        assert!(
            err.contains("full") && err.contains("No space left on device"),
            "{key}: {err}"
        );
        assert!(
            is_private_device(&full, 7),
            "{key}: the device was replaced"
        );
        let left: Vec<_> = fs::read_dir(&full_dir).unwrap().flatten().collect();
        assert_eq!(left.len(), 1, "{key}: files beside the device: {left:?}");
    }
    // `/dev/stdout` prints: the child's standard output (a pipe here) gets the bytes the
    // regular file got, and nothing is made beside the command.
    let o = run(f, recipe, Path::new("/dev/stdout"));
    ok(key, "/dev/stdout", &o);
    let written = fs::read(&plain).unwrap();
    assert!(
        !o.stdout.is_empty() && o.stdout.len() >= written.len() / 2,
        "{key}: /dev/stdout got {} bytes, the file {}",
        o.stdout.len(),
        written.len()
    );
    let head = &written[..written.len().min(8)];
    assert!(
        o.stdout.windows(head.len()).any(|w| w == head),
        "{key}: the output's first bytes are not on standard output"
    );
    // A FIFO is written in place.
    let (fifo, mut reader, got) = fifo_with_reader(dir);
    let o = run(f, recipe, &fifo);
    assert!(
        reader_finished(&mut reader),
        "{key}: the FIFO was never opened"
    );
    ok(key, "a FIFO", &o);
    assert!(fs::metadata(&got).unwrap().len() > 0, "{key}: nothing read");
    assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    // A folder is a clear error.
    let folder = dir.join("folder");
    fs::create_dir(&folder).unwrap();
    fs::write(folder.join("kept"), b"x").unwrap();
    let err = failure(key, "a folder", &run(f, recipe, &folder));
    assert!(err.contains("folder"), "{key}: {err}");
    assert_eq!(fs::read(folder.join("kept")).unwrap(), b"x");
    assert_eq!(fs::read_dir(&folder).unwrap().count(), 1, "{key}");
}

/// An output file onto a hard link of each of the command's inputs: refused, input untouched.
fn replaces_no_input(f: &Fixture, key: &str, recipe: Recipe) {
    let probe = f.dir.path().join("probe.out");
    let a = recipe(f, &probe);
    let parsed = eotn::cli::paths::parse_from(std::iter::once(OsString::from("eotn")).chain(a));
    let inputs: Vec<&PathBuf> = parsed.inputs.iter().filter(|p| p.is_file()).collect();
    for input in inputs {
        let case = tempfile::tempdir_in(f.dir.path()).unwrap();
        let alias = case.path().join("alias");
        fs::hard_link(input, &alias).unwrap();
        let before = fs::read(input).unwrap();
        let err = failure(key, "a hard link of an input", &run(f, recipe, &alias));
        assert!(
            err.contains("would replace the input") || err.contains("goes through"),
            "{key} over {}: {err}",
            input.display()
        );
        assert_eq!(fs::read(input).unwrap(), before, "{key}: {input:?} changed");
    }
}

/// A folder of outputs onto a file, a device, a FIFO (errors, all kept) and a link to a folder.
fn folder_output_cases(f: &Fixture, key: &str, recipe: Recipe) {
    let case = tempfile::tempdir_in(f.dir.path()).unwrap();
    let dir = case.path();
    let file = dir.join("a-file");
    fs::write(&file, b"kept").unwrap();
    let err = failure(key, "a file", &run(f, recipe, &file));
    assert!(err.contains("not a folder"), "{key}: {err}");
    assert_eq!(fs::read(&file).unwrap(), b"kept");
    if let Some(null) = private_null(dir) {
        let err = failure(key, "a device", &run(f, recipe, &null));
        assert!(err.contains("not a folder"), "{key}: {err}");
        assert!(
            is_private_null(&null),
            "{key}: the device node was replaced"
        );
    }
    let (fifo, mut reader, _) = fifo_with_reader(dir);
    let err = failure(key, "a FIFO", &run(f, recipe, &fifo));
    assert!(err.contains("not a folder"), "{key}: {err}");
    assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    // Nothing opened the FIFO: end its reader.
    let _ = reader.kill();
    let _ = reader.wait();
    fs::create_dir(dir.join("real")).unwrap();
    let link = dir.join("link");
    symlink("real", &link).unwrap();
    ok(key, "a link to a folder", &run(f, recipe, &link));
    assert!(
        fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert!(
        fs::read_dir(dir.join("real")).unwrap().count() > 0,
        "{key}: nothing written into the linked folder"
    );
}

#[test]
fn every_output_option_respects_devices_fifos_links_folders_and_inputs() {
    let recipes = recipes();
    let defined = defined_outputs();
    for (key, _) in &defined {
        assert!(
            recipes.iter().any(|(k, _)| k == key),
            "the output option `eotn {key}` has no recipe in tests/it/outputs.rs: add one so \
             that it is run onto a device, a FIFO, a link, a folder and its own inputs"
        );
    }
    for (key, _) in &recipes {
        assert!(
            defined.iter().any(|(k, _)| k == key),
            "`eotn {key}` is no longer an output option; remove its recipe"
        );
    }
    let f = Fixture::new();
    for (key, folder) in defined {
        let recipe = recipes.iter().find(|(k, _)| *k == key).unwrap().1;
        if folder {
            folder_output_cases(&f, &key, recipe);
        } else {
            file_output_cases(&f, &key, recipe);
            replaces_no_input(&f, &key, recipe);
        }
    }
}
