//! `eotn bench`: how fast classification and blob formation run on given frames.
//!
//! Each frame is processed `--warmup` times untimed, then `--reps` times through the same
//! [`Pipeline`] the app uses, with every stage timed separately. Reported figures are medians
//! over all timed repetitions of all frames, in ns per pixel and ms per frame.

use std::time::Duration;

use serde::Serialize;

use super::inputs::{InputArgs, parse_connectivity, progress};
use crate::blobs::Connectivity;
use crate::pipeline::{Pipeline, PipelineParams};

/// Arguments of `eotn bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Frames, table and raw frame size.
    #[command(flatten)]
    pub input: InputArgs,
    /// 8: diagonal neighbours join a blob; 4: they do not.
    #[arg(long, default_value = "8", value_parser = parse_connectivity)]
    pub connectivity: Connectivity,
    /// Timed repetitions per frame.
    #[arg(long, default_value_t = 200, value_parser = super::values::whole_in::<usize>(1, 100_000))]
    pub reps: usize,
    /// Untimed repetitions per frame first (caches, branch predictors).
    #[arg(long, default_value_t = 10, value_parser = super::values::whole_in::<usize>(0, 100_000))]
    pub warmup: usize,
    /// End with one JSON line of the medians.
    #[arg(long)]
    pub json: bool,
}

/// The final `--json` line.
#[derive(Debug, Serialize)]
pub struct BenchJson {
    /// Frames timed.
    pub frames: usize,
    /// Pixels per frame (of the last frame when sizes differ).
    pub pixels_per_frame: usize,
    /// Table bits per channel.
    pub lut_bits: u8,
    /// 4 or 8.
    pub connectivity: u8,
    /// Timed repetitions per frame.
    pub reps: usize,
    /// The kernels used on this CPU: `avx2` or `portable`.
    pub kernels: &'static str,
    /// Median classification time per pixel, ns.
    pub classify_ns_per_px: f64,
    /// Median blob-formation time per pixel, ns.
    pub blobs_ns_per_px: f64,
    /// Median of classify + blobs per pixel, ns.
    pub total_ns_per_px: f64,
    /// Median classify + blobs per frame, ms.
    pub total_ms_per_frame: f64,
}

fn median(v: &[f64]) -> f64 {
    crate::stats::median(v).unwrap_or(f64::NAN)
}

fn ns_per_px(d: Duration, pixels: usize) -> f64 {
    d.as_nanos() as f64 / pixels as f64
}

/// Runs `eotn bench`.
///
/// # Errors
/// Unreadable inputs, naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let (lut, mut inputs) = args.input.open()?;
    let bits = lut.bits();

    let connectivity = args.connectivity;
    let mut pipeline = Pipeline::new(
        lut,
        PipelineParams {
            connectivity,
            ..PipelineParams::default()
        },
    );
    let (mut classify, mut blobs, mut total) = (Vec::new(), Vec::new(), Vec::new());
    let mut total_ms = Vec::new();
    let mut pixels = 0;
    let bar = progress(inputs.len(), "bench");
    for i in 0..inputs.len() {
        let frame = inputs.load(i, args.input.size)?;
        pixels = frame.pixel_count();
        for _ in 0..args.warmup {
            pipeline.process_frame(&frame);
        }
        for _ in 0..args.reps.max(1) {
            let t = pipeline.process_frame(&frame).timings;
            classify.push(ns_per_px(t.classify, pixels));
            blobs.push(ns_per_px(t.blobs, pixels));
            total.push(ns_per_px(t.total(), pixels));
            total_ms.push(t.total().as_secs_f64() * 1e3);
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let result = BenchJson {
        frames: inputs.len(),
        pixels_per_frame: pixels,
        lut_bits: bits,
        connectivity: connectivity.neighbours(),
        reps: args.reps.max(1),
        kernels: crate::classify::active_kernels(),
        classify_ns_per_px: median(&classify),
        blobs_ns_per_px: median(&blobs),
        total_ns_per_px: median(&total),
        total_ms_per_frame: median(&total_ms),
    };
    outln!(
        "# eotn bench: {} frame(s), {} px/frame, lut b={}, conn={}, reps={}/frame, {} kernels",
        result.frames,
        result.pixels_per_frame,
        result.lut_bits,
        result.connectivity,
        result.reps,
        result.kernels
    );
    outln!(
        "classify  median {:7.3} ns/pixel",
        result.classify_ns_per_px
    );
    outln!("blobs     median {:7.3} ns/pixel", result.blobs_ns_per_px);
    outln!(
        "total     median {:7.3} ns/pixel  {:8.4} ms/frame",
        result.total_ns_per_px,
        result.total_ms_per_frame
    );
    if args.json {
        outln!("{}", serde_json::to_string(&result)?);
    }
    Ok(())
}
