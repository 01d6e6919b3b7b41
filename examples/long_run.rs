//! A long stream stepped end to end through the app's state (the headless [`Workspace`] the
//! window draws, with the same commands), resident memory sampled as it goes: nothing may grow
//! beyond the frame cache's bound. `scripts/long-run.sh` makes a 20-minute stream and runs this.
//!
//!   cargo run --release --no-default-features --example long_run -- STREAM TABLE [MAX_GROWTH_MIB]
//!
//! Prints one line per sample (frame, resident MiB) and a summary; exits 1 when the resident
//! memory after the first tenth of the stream grows by more than MAX_GROWTH_MIB (default 16).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use eotn::workspace::{Command, PlaybackCommand, Workspace};

/// Samples taken over the stream.
const SAMPLES: usize = 40;

/// This process's resident memory, MiB (Linux `/proc/self/status`).
fn resident_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(stream), Some(table)) = (args.first(), args.get(1)) else {
        eprintln!("usage: long_run STREAM TABLE [MAX_GROWTH_MIB]");
        return ExitCode::from(2);
    };
    let max_growth: f64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(16.0);
    let mut state = Workspace::default();
    if let Err(e) = state.apply(Command::Open(vec![
        PathBuf::from(table),
        PathBuf::from(stream),
    ])) {
        eprintln!("long_run: {e:#}");
        return ExitCode::from(2);
    }
    let frames = state.source().map_or(0, eotn::workspace::Source::len);
    let every = (frames / SAMPLES).max(1);
    let start = Instant::now();
    let mut after_warm_up = None;
    let mut peak: f64 = 0.0;
    println!("frame resident_mib");
    for index in 0..frames {
        if index > 0 {
            state.run(PlaybackCommand::Step(1).into());
        }
        if index % every == 0 || index + 1 == frames {
            let rss = resident_mib().unwrap_or(f64::NAN);
            println!("{index} {rss:.1}");
            if index >= frames / 10 {
                after_warm_up.get_or_insert(rss);
                peak = peak.max(rss);
            }
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let base = after_warm_up.unwrap_or(f64::NAN);
    let growth = peak - base;
    println!(
        "long_run: {frames} frames in {seconds:.0} s ({:.2} ms a frame), shown frame {}; resident {base:.1} MiB after the first tenth, peak {peak:.1} MiB (growth {growth:.1} MiB, allowed {max_growth})",
        1e3 * seconds / frames.max(1) as f64,
        state.index()
    );
    if state.index() + 1 != frames {
        eprintln!("long_run: stopped at frame {} of {frames}", state.index());
        return ExitCode::FAILURE;
    }
    if growth.is_nan() || growth > max_growth {
        eprintln!("long_run: memory grew by {growth:.1} MiB");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
