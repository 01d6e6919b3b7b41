//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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

/// A file under `../shared/`, or `None` with a clear "skipped" line when it is absent outside CI.
/// Under `CI=true` a missing file fails the test.
pub fn shared_file(relative: &str) -> Option<PathBuf> {
    let p = shared_dir().join(relative);
    if p.exists() {
        return Some(p);
    }
    assert!(
        !in_ci(),
        "{} is missing, and CI=true requires it",
        p.display()
    );
    eprintln!(
        "SKIPPED: {} is not here (the shared data folder is absent)",
        p.display()
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

/// A python3 that has numpy and OpenCV, or `None` (with a "skipped" line) outside CI.
/// Under `CI=true` their absence fails the test: the cross-check must never skip silently there.
pub fn python_with_opencv() -> Option<PathBuf> {
    let python = PathBuf::from(std::env::var_os("PYTHON").unwrap_or_else(|| "python3".into()));
    let ok = Command::new(&python)
        .args(["-c", "import numpy, cv2"])
        .output()
        .is_ok_and(|o| o.status.success());
    if ok {
        return Some(python);
    }
    assert!(
        !in_ci(),
        "python3 with numpy and opencv-python-headless is required under CI=true (pip install numpy opencv-python-headless)"
    );
    eprintln!("SKIPPED: python3 with numpy + OpenCV not found; the peer cross-check did not run");
    None
}

/// A python3 with the `mcap` and `mcap_protobuf` readers (an independent MCAP implementation),
/// or `None` (with a "skipped" line) outside CI. Under `CI=true` their absence fails the test.
pub fn python_with_mcap() -> Option<PathBuf> {
    let python = PathBuf::from(std::env::var_os("PYTHON").unwrap_or_else(|| "python3".into()));
    let ok = Command::new(&python)
        .args(["-c", "import mcap, mcap_protobuf"])
        .output()
        .is_ok_and(|o| o.status.success());
    if ok {
        return Some(python);
    }
    assert!(
        !in_ci(),
        "python3 with mcap and mcap-protobuf-support is required under CI=true (pip install mcap mcap-protobuf-support)"
    );
    eprintln!(
        "SKIPPED: python3 with the mcap + mcap_protobuf readers not found; the independent-reader cross-check did not run"
    );
    None
}
