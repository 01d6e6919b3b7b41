//! The headless command line: the same pipeline as the app, for scripts, CI and benchmarks.
//!
//! One file per subcommand, each with its clap `Args` and a `run` function. Errors carry
//! `anyhow` context naming the file; `main` prints them as one line and exits non-zero.

/// `println!` for command output: a closed pipe (`eotn detect … | head`) ends the process
/// quietly with success, as Unix tools end, instead of panicking.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

mod bench;
mod bench_floor;
mod bench_live;
mod blobs;
mod bounds;
mod classify;
pub mod detect;
mod detect_field;
mod eval;
mod eval_boxes;
mod eval_field;
mod eval_labels;
mod eval_overhead;
mod export;
mod field;
mod import;
mod import_bhuman;
mod info;
pub mod inputs;
mod interrupt;
mod lut;
mod lut_from_labels;
pub mod open;
pub mod overhead;
mod overhead_bench;
pub mod overhead_calibrate;
pub mod paths;
pub mod patterns;
mod record;
mod render;
mod serve;
mod sim;
mod sim_field;
mod sources;
pub mod ssl_vision_out;
pub mod values;
mod wmd;
mod wmd_feeds;
mod wmd_inputs;
mod wmd_live;
pub mod wmd_record;
mod wmd_ssl;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use clap::{Parser, Subcommand};

pub use paths::{Parsed, parse};

/// A rate as a percentage with one decimal, or a dash when there was nothing to rate.
pub(crate) fn pct(r: Option<f64>) -> String {
    r.map_or_else(|| "—".to_owned(), |v| format!("{:.1}%", v * 100.0))
}

/// eotn — Eye Of The NUbot: see what your robots see.
///
/// With no command, opens the desktop app (when built with the `gui` feature).
#[derive(Debug, Parser)]
#[command(name = "eotn", version, about, long_about = None)]
pub struct Cli {
    /// What to do; none opens the app.
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Describe frames, lookup tables and streams: sizes, layouts, class counts.
    Info(info::Args),
    /// Classify frames with a lookup table and write the classified images as PNG.
    Classify(classify::Args),
    /// Find the blobs of classified frames; `--json` prints the peer-compatible JSON Lines.
    Blobs(blobs::Args),
    /// Time classification and blob formation; `--json` ends with the medians in ns/pixel.
    Bench(bench::Args),
    /// Recognise ball, goals (posts, gap) and beacons; `--json` prints one line per frame.
    Detect(detect::Args),
    /// Draw frames with recognition overlays (circles, posts, gaps, horizon, scans) as PNG.
    Render(render::Args),
    /// Coloured patterns: learn places from pink markers and robot poses (`learn`), print a
    /// places file (`show`).
    Patterns(patterns::Args),
    /// Compare recognition with the ground truth of synthetic streams (or a real stream's hand
    /// labels, `--labels`): rates, errors, misses; two tables or parameter sets side by side;
    /// goal-distance calibration.
    Eval(eval::Args),
    /// Build an MCAP stream from frame files and a CSV/JSON table of sensor readings.
    Import(import::Args),
    /// Write frames of streams or frame files as PNG: raw, classified, or with blob boxes.
    Export(export::Args),
    /// Build a first lookup table from labelled frames and score it on held-back frames.
    LutFromLabels(lut_from_labels::Args),
    /// Render a synthetic scenario into a stream with sensor readings and ground truth.
    Sim(sim::Args),
    /// Lookup-table tools: `eotn lut convert` reads other teams' tables.
    Lut(lut::Args),
    /// List the frame sources that can be connected: cameras found, synthetic scenarios.
    Sources(sources::Args),
    /// The overhead camera: printable robot markers (`marker`), calibration from clicked points
    /// (`calibrate`), ball and robots in field coordinates (`detect`), points from a synthetic
    /// stream's truth (`sim-points`).
    Overhead(overhead::Args),
    /// The World Model Debugger headless: the robots' recorded world models against an
    /// overhead camera (or a session's): matched by marker, errors and the tape measure per
    /// frame (`--json`) or per robot.
    Wmd(wmd::Args),
    /// Latency and CPU of live robots on loopback: sender's write to the frame in the app state.
    BenchLive(bench_live::Args),
    /// A stand-in robot: play a stream at its recorded rate as a Foxglove WebSocket server.
    Serve(serve::Args),
    /// Record live robots (Foxglove WebSocket servers) into MCAP streams, bit-exact.
    Record(record::Args),
    /// Open the desktop app on streams (.mcap), lookup tables (.lut) and frames (.uyvy, .png).
    Open(open::Args),
}

/// Runs a headless subcommand; no output it writes may replace one of `inputs` (the files its
/// arguments name, [`paths::Parsed::inputs`]), a file it reads while it runs, or an output it
/// wrote before; `updated` ([`paths::Parsed::updated`]) are read and replaced on purpose. The
/// `outputs` its arguments name are checked before it starts.
///
/// # Errors
/// An output that is an input; whatever the subcommand reports, with context naming the file.
pub fn run(
    command: Command,
    inputs: &[PathBuf],
    outputs: &[PathBuf],
    updated: &[PathBuf],
) -> anyhow::Result<()> {
    let _guard = crate::atomic_file::guard_command(inputs);
    crate::atomic_file::guard_updated(updated);
    for out in outputs {
        crate::atomic_file::refuse_inputs(out).with_context(|| format!("{}", out.display()))?;
    }
    match command {
        Command::Info(a) => info::run(&a),
        Command::Classify(a) => classify::run(&a),
        Command::Blobs(a) => blobs::run(&a),
        Command::Bench(a) => bench::run(&a),
        Command::Import(a) => import::run(&a),
        Command::Export(a) => export::run(&a),
        Command::LutFromLabels(a) => lut_from_labels::run(&a),
        Command::Sim(a) => sim::run(&a),
        Command::Lut(a) => lut::run(&a),
        Command::Detect(a) => detect::run(&a),
        Command::Render(a) => render::run(&a),
        Command::Patterns(a) => patterns::run(&a),
        Command::Eval(a) => eval::run(&a),
        Command::Sources(a) => sources::run(&a),
        Command::Overhead(a) => overhead::run(&a),
        Command::Open(a) => open::run(&a),
        Command::BenchLive(a) => bench_live::run(&a),
        Command::Serve(a) => serve::run(&a),
        Command::Record(a) => record::run(&a),
        Command::Wmd(a) => wmd::run(&a),
    }
}

/// Writes command output to stdout; when stdout is a closed pipe, ends the process with
/// success at once (the reader has what it wanted), and on any other write error with failure.
pub fn write_stdout(args: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("eotn: cannot write the output: {e}");
        std::process::exit(1);
    }
}

/// Whether an error is stdout closed by its reader (`| head`): not a failure.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    let pipe = Some(std::io::ErrorKind::BrokenPipe);
    err.chain().any(|c| {
        c.downcast_ref::<std::io::Error>().map(std::io::Error::kind) == pipe
            || c.downcast_ref::<serde_json::Error>()
                .and_then(serde_json::Error::io_error_kind)
                == pipe
    })
}

/// One line for an error: its messages from the outside in, each said once. Layers that repeat
/// their cause's text in their own (`X: msg: msg`) are shortened to the first saying.
#[must_use]
pub fn error_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        let text = text.trim();
        if text.is_empty() || line.contains(text) {
            continue;
        }
        // A layer whose message ends with what was already said adds only its own prefix.
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(text);
    }
    // Causes printed on their own lines by some decoders become one line.
    line.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Prints an error as one line, `eotn: …`, and gives the failure exit code; a closed output
/// pipe ends quietly with success.
#[must_use]
pub fn report(err: &anyhow::Error) -> ExitCode {
    if is_broken_pipe(err) {
        return ExitCode::SUCCESS;
    }
    // The library says a raw frame's size must be given; on the command line that is `--size`.
    let unknown_size = err.chain().any(|e| {
        matches!(
            e.downcast_ref::<crate::frame::FrameFileError>(),
            Some(crate::frame::FrameFileError::UnknownSize { .. })
        )
    });
    let hint = if unknown_size { " (--size WxH)" } else { "" };
    eprintln!("eotn: {}{hint}", error_line(err));
    ExitCode::FAILURE
}
