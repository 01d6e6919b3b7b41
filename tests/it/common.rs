//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use eotn::eval::Percentiles;

/// The `../shared/` folder beside the project (overridable with `EOTN_SHARED`).
pub fn shared_dir() -> PathBuf {
    std::env::var_os("EOTN_SHARED").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared"),
        PathBuf::from,
    )
}

/// True when running in CI (`CI=true`), where missing tools or data are failures.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

/// Says a test is skipped: a "SKIPPED" line on stderr (which the harness shows only for failing
/// tests, unless `--nocapture`), and one line appended to the file `EOTN_SKIP_LOG` names —
/// `scripts/test.sh` sets it and ends with a summary of every skip: the test, why, and how to
/// get what it needs. Fails the test under `CI=true`, where nothing may skip.
#[track_caller]
pub fn skipped(reason: &str, remedy: &str) {
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("(unnamed test)");
    assert!(
        !in_ci(),
        "{test}: {reason}, and CI=true allows no skip ({remedy})"
    );
    skip_noted(reason, remedy);
}

/// [`skipped`] without the failure under CI: for what a CI container cannot have (a kernel
/// module for a virtual camera), still listed in the summary.
pub fn skip_noted(reason: &str, remedy: &str) {
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("(unnamed test)");
    eprintln!("SKIPPED: {test}: {reason} ({remedy})");
    if let Some(log) = std::env::var_os("EOTN_SKIP_LOG") {
        use std::io::Write as _;
        let line = format!("{test}\t{reason}\t{remedy}\n").replace(['\r'], " ");
        if let Ok(mut f) = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&log)
        {
            // One short write of one line: appends from parallel tests do not interleave.
            let _ = f.write_all(line.as_bytes());
        }
    }
}

/// What `make` builds once for every test of a file (recordings written by Python tools), or
/// `None` when it cannot be made. `make` says its own skip to the first test that asks; every
/// later test that finds it missing says one too, naming `what`, so none passes unlisted.
pub fn made_once<T: Sync>(
    cell: &'static std::sync::OnceLock<Option<T>>,
    what: &str,
    make: impl FnOnce() -> Option<T>,
) -> Option<&'static T> {
    let mut made_here = false;
    let made = cell
        .get_or_init(|| {
            made_here = true;
            make()
        })
        .as_ref();
    if made.is_none() && !made_here {
        skipped(
            &format!("{what} could not be made (see that file's first skip)"),
            "install what that skip names",
        );
    }
    made
}

/// A file under `../shared/`, or `None` with a clear "skipped" line when it is absent outside CI.
/// Under `CI=true` a missing file fails the test.
pub fn shared_file(relative: &str) -> Option<PathBuf> {
    let p = shared_dir().join(relative);
    if p.exists() {
        return Some(p);
    }
    skipped(
        &format!("{} is not here", p.display()),
        "put the shared data folder beside the project as ../shared, or set EOTN_SHARED \
         (../shared/data/README.md)",
    );
    None
}

/// Runs the `eotn` binary built for these tests.
pub fn eotn(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eotn"))
        .args(args)
        .output()
        .expect("the eotn binary runs")
}

/// Runs the `eotn` binary and fails the test, showing its stderr, unless it succeeds.
pub fn eotn_ok(args: &[&std::ffi::OsStr]) -> Output {
    let out = eotn(args);
    assert!(
        out.status.success(),
        "eotn {:?}: {}",
        args,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A python3 that has numpy and OpenCV, or `None` (with a "skipped" line) outside CI.
/// Under `CI=true` their absence fails the test: the cross-check must never skip silently there.
pub fn python_with_opencv() -> Option<PathBuf> {
    python_with(
        "import numpy, cv2",
        "numpy and opencv-python-headless",
        "the peer cross-check",
    )
}

/// A python3 with the `mcap` and `mcap_protobuf` readers (an independent MCAP implementation),
/// or `None` (with a "skipped" line) outside CI. Under `CI=true` their absence fails the test.
pub fn python_with_mcap() -> Option<PathBuf> {
    python_with(
        "import mcap, mcap_protobuf",
        "mcap and mcap-protobuf-support",
        "the independent-reader cross-check",
    )
}

/// A python3 with the official Foxglove SDK (`foxglove-sdk`: a WebSocket server that is not ours),
/// or `None` (with a "skipped" line) outside CI. Under `CI=true` its absence fails the test.
pub fn python_with_foxglove() -> Option<PathBuf> {
    python_with(
        "import foxglove",
        "foxglove-sdk",
        "the Foxglove SDK server test",
    )
}

/// The tests' Python: `$PYTHON` if set, else the project's `.venv/` that `scripts/deps.sh --test`
/// makes from the system interpreter (with the pinned packages of `scripts/requirements-test.txt`),
/// else `python3` from the PATH.
pub fn test_python() -> PathBuf {
    if let Some(p) = std::env::var_os("PYTHON") {
        return PathBuf::from(p);
    }
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    if venv.exists() {
        return venv;
    }
    PathBuf::from("python3")
}

/// [`test_python`] when `import_line` runs in it; else fails under CI and skips with a line saying
/// which `check` did not run.
pub fn python_with(import_line: &str, packages: &str, check: &str) -> Option<PathBuf> {
    let python = test_python();
    let ok = Command::new(&python)
        .args(["-c", import_line])
        .output()
        .is_ok_and(|o| o.status.success());
    if ok {
        return Some(python);
    }
    skipped(
        &format!("python3 with {packages} not found; {check} did not run"),
        "scripts/deps.sh --test installs them into .venv/",
    );
    None
}

/// A file of the repository (sample streams, tables, parameters).
pub fn repo_file(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// A stream of `frames` frames of `scenario` made by `eotn sim` in `dir` (with `--seed` when
/// given): `SCENARIO.mcap`, or `SCENARIO-SEED.mcap` with a seed.
pub fn sim_stream(dir: &Path, scenario: &str, frames: usize, seed: Option<u64>) -> PathBuf {
    let out = dir.join(match seed {
        Some(seed) => format!("{scenario}-{seed}.mcap"),
        None => format!("{scenario}.mcap"),
    });
    let frames = frames.to_string();
    let seed = seed.map(|s| s.to_string());
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "sim".as_ref(),
        "--scenario".as_ref(),
        scenario.as_ref(),
        "--frames".as_ref(),
        frames.as_ref(),
    ];
    if let Some(seed) = &seed {
        args.extend([std::ffi::OsStr::new("--seed"), std::ffi::OsStr::new(seed)]);
    }
    args.extend(["-o".as_ref(), out.as_os_str()]);
    eotn_ok(&args);
    out
}

/// The robot-camera scenarios shipped as `streams/sim-NAME.mcap` (`sim-overhead-game.mcap` is
/// shipped too, but is an overhead camera's).
pub const SHIPPED_ROBOT_SCENARIOS: [&str; 6] = [
    "walk-and-pan",
    "ball-edge",
    "goalkeeper",
    "fast-pans",
    "orange-clutter",
    "beacon-tour",
];

/// The first frame of each shipped sim stream (`eotn sim --seed 1 --first N`): where in its
/// scenario the stream shows what it is named for (README, "Sample streams").
pub fn shipped_first_frame(scenario: &str) -> u64 {
    match scenario {
        "walk-and-pan" => 75,
        "ball-edge" => 210,
        "fast-pans" => 90,
        "orange-clutter" => 45,
        "beacon-tour" => 15,
        _ => 0,
    }
}

/// A percentile summary taken over at least `min_n` values, for a test to assert on: fails the
/// test (naming `what`) when the sample is smaller or empty, so that no percentile assertion
/// passes on too little data (an empty sample has no percentiles at all).
#[track_caller]
pub fn sampled(p: Option<Percentiles>, min_n: usize, what: &str) -> Percentiles {
    let n = p.map_or(0, |p| p.n);
    assert!(
        n >= min_n,
        "{what}: {n} values, the assertion needs at least {min_n}"
    );
    p.expect("a sample of at least one value")
}

/// The percentiles of `values` over at least `min_n` of them ([`sampled`]).
#[track_caller]
pub fn percentiles(values: &[f64], min_n: usize, what: &str) -> Percentiles {
    sampled(Percentiles::of(values), min_n, what)
}

/// A summary's figure for printing: `pick` of it, or NaN without a sample.
pub fn figure(p: Option<Percentiles>, pick: fn(&Percentiles) -> f64) -> f64 {
    p.as_ref().map_or(f64::NAN, pick)
}
