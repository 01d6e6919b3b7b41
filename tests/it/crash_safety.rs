//! Crash safety by test: eotn killed with SIGKILL at moments spread over the whole run while it
//! writes a lookup table, exports frames and records a stream. An output is the old file or the
//! new one, never a mix; every PNG left is whole; a stream is readable to its last complete
//! chunk; the temporaries a killed run leaves are gone after the next run.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::eotn_ok;

/// Kills per test, at 0, 1/N, 2/N … of the time a whole run takes.
const KILLS: u32 = 12;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs eotn to its end and returns how long that took.
fn time_to_finish(args: &[&OsStr]) -> Duration {
    let start = Instant::now();
    eotn_ok(args);
    start.elapsed()
}

/// Starts eotn, kills it with SIGKILL after `after`; true when it had finished by then (exited
/// by itself, successfully).
fn run_and_kill(args: &[&OsStr], after: Duration) -> bool {
    let mut child = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let _ = child.kill();
    // Finished when it exited by itself (a run can end between a check and the kill).
    child.wait().unwrap().success()
}

/// The moments to kill at: spread evenly over a whole run.
fn kill_times(whole: Duration) -> impl Iterator<Item = Duration> {
    (0..KILLS).map(move |i| whole.mul_f64(f64::from(i) / f64::from(KILLS)))
}

/// Our temporaries (`.NAME.tmp-PID-N`) in `dir`.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .and_then(OsStr::to_str)
                .is_some_and(|n| n.starts_with('.') && n.contains(".tmp-"))
        })
        .collect()
}

#[test]
fn a_table_written_while_killed_is_the_old_table_or_the_new_one() {
    let dir = tempfile::tempdir().unwrap();
    // A foreign 128³ table: our own sample read as an rUNSWift calibration.
    let foreign = dir.path().join("robot.cal");
    std::fs::copy(root().join("lookup_tables/sample.lut"), &foreign).unwrap();
    let old = std::fs::read(root().join("lookup_tables/bhuman2009.lut")).unwrap();
    let out = dir.path().join("robot.lut");
    let args = |out: &Path| {
        [
            "lut",
            "convert",
            foreign.to_str().unwrap(),
            "--format",
            "runswift-cal",
            "-o",
            out.to_str().unwrap(),
        ]
        .map(|a| OsStr::new(a).to_owned())
    };
    let expected_path = dir.path().join("expected.lut");
    let expected_args = args(&expected_path);
    let whole = time_to_finish(&expected_args.each_ref().map(|a| a.as_os_str()));
    let new = std::fs::read(&expected_path).unwrap();
    assert_ne!(new, old);
    let run_args = args(&out);
    let run_args = run_args.each_ref().map(|a| a.as_os_str());
    for after in kill_times(whole) {
        std::fs::write(&out, &old).unwrap();
        run_and_kill(&run_args, after);
        let now = std::fs::read(&out).unwrap();
        assert!(
            now == old || now == new,
            "killed after {after:?}: robot.lut is neither the old table nor the new one ({} bytes)",
            now.len()
        );
    }
    // One kill that lands mid-write for certain: as soon as the temporary appears (the spread
    // kills above may all land before or after the write).
    std::fs::write(&out, &old).unwrap();
    let before = temporaries(dir.path());
    let fresh = || {
        temporaries(dir.path())
            .into_iter()
            .any(|t| !before.contains(&t))
    };
    let mut child = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .args(run_args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    let landed = loop {
        if fresh() {
            let _ = child.kill();
            break true;
        }
        if child.try_wait().unwrap().is_some() || t0.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            break false;
        }
        std::thread::sleep(Duration::from_micros(100));
    };
    let _ = child.wait();
    assert!(landed, "the run ended before its temporary was seen");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        old,
        "killed mid-write: robot.lut is still the old table"
    );
    assert!(fresh(), "the killed write left its temporary");
    // The next whole run writes the table and clears what the killed ones left.
    eotn_ok(&run_args);
    assert_eq!(std::fs::read(&out).unwrap(), new);
    assert_eq!(temporaries(dir.path()), Vec::<PathBuf>::new());
}

#[test]
fn frames_exported_while_killed_are_whole_pictures() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("walk.mcap");
    eotn_ok(&[
        "sim".as_ref(),
        "--scenario".as_ref(),
        "walk-and-pan".as_ref(),
        "--frames".as_ref(),
        "60".as_ref(),
        "-o".as_ref(),
        stream.as_os_str(),
    ]);
    let out = dir.path().join("png");
    let lut = root().join("lookup_tables/sim.lut");
    let args: [&OsStr; 8] = [
        "export".as_ref(),
        stream.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "--view".as_ref(),
        "blobs".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ];
    let whole = time_to_finish(&args);
    std::fs::remove_dir_all(&out).unwrap();
    let mut pictures_seen = 0;
    for after in kill_times(whole) {
        run_and_kill(&args, after);
        let Ok(entries) = std::fs::read_dir(&out) else {
            continue; // killed before it made the folder
        };
        for entry in entries {
            let path = entry.unwrap().path();
            if path.extension() == Some(OsStr::new("png")) {
                let picture = image::open(&path);
                assert!(
                    picture.is_ok(),
                    "killed after {after:?}: {} is not a whole PNG: {:?}",
                    path.display(),
                    picture.err()
                );
                pictures_seen += 1;
            }
        }
    }
    assert!(
        pictures_seen > 0,
        "no kill came late enough to leave a picture"
    );
    eotn_ok(&args);
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 60);
    assert_eq!(temporaries(&out), Vec::<PathBuf>::new());
}

#[test]
fn a_stream_recorded_while_killed_reads_to_its_last_complete_chunk() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rec.mcap");
    let partial = dir.path().join("rec.mcap.partial");
    let sim = |seed: &str, out: &Path| {
        [
            "sim",
            "--scenario",
            "walk-and-pan",
            "--frames",
            "150",
            "--seed",
            seed,
            "-o",
            out.to_str().unwrap(),
        ]
        .map(|a| OsStr::new(a).to_owned())
    };
    // An older recording under the same name, which a killed run must leave whole.
    let old_args = sim("7", &out);
    let whole = time_to_finish(&old_args.each_ref().map(|a| a.as_os_str()));
    let old = std::fs::read(&out).unwrap();
    let run_args = sim("1", &out);
    let run_args = run_args.each_ref().map(|a| a.as_os_str());
    let mut partial_frames = Vec::new();
    for after in kill_times(whole) {
        let _ = std::fs::remove_file(&partial);
        std::fs::write(&out, &old).unwrap();
        let finished = run_and_kill(&run_args, after);
        let now = eotn::streams::StreamReader::open(&out).unwrap();
        // A run killed between renaming its whole stream into place and exiting has not
        // "finished" by its exit status, yet rec.mcap is already the complete new recording:
        // the old one or the whole new one, never anything between.
        let unchanged = std::fs::read(&out).unwrap() == old;
        if finished || !unchanged {
            assert_eq!(
                now.len(),
                150,
                "killed after {after:?}: rec.mcap changed before the new one was complete"
            );
        }
        // Killed between creating the file and its first write: nothing to read, nothing torn.
        let written = std::fs::metadata(&partial).map_or(0, |m| m.len());
        if written > 0 {
            let mut r = eotn::streams::StreamReader::open(&partial).unwrap();
            for index in 0..r.len() {
                assert!(
                    r.read(index).is_ok(),
                    "killed after {after:?}: frame {index} of {} does not read",
                    r.len()
                );
            }
            partial_frames.push(r.len());
        }
    }
    assert!(
        partial_frames.iter().any(|&n| n > 0),
        "no kill left a partial stream with frames: {partial_frames:?}"
    );
}
