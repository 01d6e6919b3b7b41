//! Skips in the library's own tests, said aloud as the integration tests say them
//! (`tests/it/common.rs`): a part of a test that cannot run here (a CPU without the instructions,
//! a machine that refuses `mknod` or `mkfifo`) prints a "SKIPPED" line and appends one line to
//! the file `EOTN_SKIP_LOG` names, so `scripts/test.sh` lists it in its summary with why and how
//! to get what it needs. Built for tests only.

use std::io::Write as _;

/// True when running in CI (`CI=true`), where a missing tool or instruction set is a failure.
pub(crate) fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

/// Says the running test skipped a check (`reason`) and how to run it (`remedy`); fails the test
/// under `CI=true`, where nothing may skip.
#[track_caller]
pub(crate) fn skipped(reason: &str, remedy: &str) {
    let test = test_name();
    assert!(
        !in_ci(),
        "{test}: {reason}, and CI=true allows no skip ({remedy})"
    );
    skip_noted(reason, remedy);
}

/// [`skipped`] without the failure under CI: for what a CI machine may lack by design (an
/// instruction set its CPU does not have), still listed in the summary.
pub(crate) fn skip_noted(reason: &str, remedy: &str) {
    let test = test_name();
    eprintln!("SKIPPED: {test}: {reason} ({remedy})");
    if let Some(log) = std::env::var_os("EOTN_SKIP_LOG") {
        let line = format!("{test}\t{reason}\t{remedy}\n").replace('\r', " ");
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

/// The test's name as the harness gives it (the thread's name), e.g. `blobs::tests::…`.
fn test_name() -> String {
    std::thread::current()
        .name()
        .unwrap_or("(unnamed test)")
        .to_owned()
}
