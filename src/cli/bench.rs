//! `eotn bench`: how fast classification and blob formation run on given frames, with every
//! kernel set this CPU can run, beside the hand-written C floor.
//!
//! Each round takes every frame through the same [`Pipeline`] the app uses once per kernel set
//! (`--warmup` untimed passes, then `--reps` timed ones, every stage timed separately;
//! recognition off, as in the floor) and runs
//! the C floor (`bench_floor.rs`) on it, so machine load hits all alike. Reported figures are
//! medians over all timed repetitions, in ns per pixel and ms per frame; the floor's is the
//! median of its per-round medians.

use std::path::PathBuf;
use std::time::Duration;

use serde::Serialize;

use super::bench_floor::{self, Floor};
use super::inputs::{InputArgs, parse_connectivity, progress};
use crate::blobs::Connectivity;
use crate::kernels::{self, KernelSet};
use crate::pipeline::{Pipeline, PipelineParams};

/// Arguments of `eotn bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Frames, table and raw frame size.
    #[command(flatten)]
    pub input: InputArgs,
    /// 8: diagonal neighbours join a blob; 4: they do not (the C floor is 8 only).
    #[arg(long, default_value = "8", value_parser = parse_connectivity)]
    pub connectivity: Connectivity,
    /// Timed repetitions per frame, kernel set and round.
    #[arg(long, default_value_t = 200, value_parser = super::values::whole_in::<usize>(1, 100_000))]
    pub reps: usize,
    /// Untimed repetitions per frame first (caches, branch predictors).
    #[arg(long, default_value_t = 10, value_parser = super::values::whole_in::<usize>(0, 100_000))]
    pub warmup: usize,
    /// Rounds; each runs every kernel set and the floor once per frame, interleaved.
    #[arg(long, default_value_t = 3, value_parser = super::values::whole_in::<usize>(1, 1000))]
    pub rounds: usize,
    /// The C floor: `floors.c` (compiled with `$CC` or `cc -O3 -march=native`) or the compiled
    /// program; by default `$EOTN_SHARED/bench/floors.c` or `../shared/bench/floors.c`. It runs
    /// on the first 8 frames of each round.
    #[arg(long, value_name = "FLOORS")]
    pub floor: Option<PathBuf>,
    /// Do not run the C floor.
    #[arg(long, conflicts_with = "floor")]
    pub no_floor: bool,
    /// Only the kernel set chosen for this CPU (or `EOTN_KERNELS`'s), not every runnable one.
    #[arg(long)]
    pub chosen_only: bool,
    /// End with one JSON line of the medians.
    #[arg(long)]
    pub json: bool,
}

/// Frames per round the floor runs on (the first ones): the floor times a dozen loops per frame,
/// about half a second, which on a long stream would dwarf the bench itself.
const FLOOR_FRAMES: usize = 8;

/// The figures of one kernel set.
#[derive(Debug, Serialize)]
pub struct SetFigures {
    /// The set's name (`EOTN_KERNELS`).
    pub kernels: &'static str,
    /// Median classification time per pixel, ns.
    pub classify_ns_per_px: f64,
    /// Median blob-formation time per pixel, ns.
    pub blobs_ns_per_px: f64,
    /// Median of classify + blobs per pixel, ns.
    pub total_ns_per_px: f64,
    /// Median classify + blobs per frame, ms.
    pub total_ms_per_frame: f64,
    /// `total_ns_per_px` over the floor's (below 1: faster than the floor).
    pub vs_floor: Option<f64>,
}

/// The final `--json` line. The top-level figures are the chosen set's.
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
    /// Timed repetitions per frame, set and round.
    pub reps: usize,
    /// Rounds.
    pub rounds: usize,
    /// The CPU as it names itself, with vendor, family and model.
    pub cpu: String,
    /// The kernel set chosen for this CPU (or forced by `EOTN_KERNELS`).
    pub kernels: &'static str,
    /// Median classification time per pixel with the chosen set, ns.
    pub classify_ns_per_px: f64,
    /// Median blob-formation time per pixel with the chosen set, ns.
    pub blobs_ns_per_px: f64,
    /// Median of classify + blobs per pixel with the chosen set, ns.
    pub total_ns_per_px: f64,
    /// Median classify + blobs per frame with the chosen set, ms.
    pub total_ms_per_frame: f64,
    /// The C floor's classify + 8-connected blobs, ns/pixel; `None` when not measured.
    pub floor_ns_per_px: Option<f64>,
    /// Every set measured, the chosen one among them.
    pub sets: Vec<SetFigures>,
}

/// Timed samples of one kernel set.
#[derive(Debug, Default)]
struct Samples {
    classify: Vec<f64>,
    blobs: Vec<f64>,
    total: Vec<f64>,
    total_ms: Vec<f64>,
}

fn median(v: &[f64]) -> f64 {
    crate::stats::median(v).unwrap_or(f64::NAN)
}

fn ns_per_px(d: Duration, pixels: usize) -> f64 {
    d.as_nanos() as f64 / pixels as f64
}

/// The CPU line of the report: brand string, vendor, family and model.
fn cpu_description() -> String {
    let cpu = kernels::cpu();
    format!(
        "{} ({:?} family {:#x} model {:#x})",
        cpu.model_name, cpu.vendor, cpu.family, cpu.model
    )
}

/// The floor to run: `--floor`, else the default `floors.c` when it exists (`None` with a note
/// on stderr when it does not, when `--no-floor` asked, or for 4-connectivity).
fn open_floor(args: &Args, lut: &crate::lut::LookupTable) -> anyhow::Result<Option<Floor>> {
    if args.no_floor {
        return Ok(None);
    }
    if args.connectivity != Connectivity::Eight {
        eprintln!("eotn bench: the C floor is measured for 8-connectivity only; not run");
        return Ok(None);
    }
    match (&args.floor, bench_floor::default_source()) {
        (Some(path), _) => Floor::prepare(path, lut).map(Some),
        (None, Some(path)) => Ok(Floor::prepare(&path, lut)
            .inspect_err(|e| eprintln!("eotn bench: C floor not measured: {e:#}"))
            .ok()),
        (None, None) => {
            eprintln!(
                "eotn bench: C floor not measured (no ../shared/bench/floors.c; pass --floor)"
            );
            Ok(None)
        }
    }
}

/// Runs `eotn bench`.
///
/// # Errors
/// Unreadable inputs, naming the file; a `--floor` that does not build or run.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let (lut, mut inputs) = args.input.open()?;
    let bits = lut.bits();
    let chosen = kernels::from_env()?;
    let sets: Vec<KernelSet> = if args.chosen_only {
        vec![chosen]
    } else {
        kernels::runnable(kernels::cpu())
    };
    let floor = open_floor(args, &lut)?;

    let connectivity = args.connectivity;
    let mut pipeline = Pipeline::new(
        lut,
        // Classification and blobs only, in a tight loop as the floor runs them.
        PipelineParams {
            connectivity,
            recognise: false,
            ..PipelineParams::default()
        },
    );
    let mut samples: Vec<Samples> = sets.iter().map(|_| Samples::default()).collect();
    let mut floor_figures = Vec::new();
    let mut pixels = 0;
    let (rounds, reps) = (args.rounds.max(1), args.reps.max(1));
    let bar = progress(inputs.len() * rounds, "bench");
    for _ in 0..rounds {
        for i in 0..inputs.len() {
            let frame = inputs.load(i, args.input.size)?;
            pixels = frame.pixel_count();
            for (&set, s) in sets.iter().zip(&mut samples) {
                pipeline.set_kernels(set);
                for _ in 0..args.warmup {
                    pipeline.process_frame(&frame);
                }
                for _ in 0..reps {
                    let t = pipeline.process_frame(&frame).timings;
                    s.classify.push(ns_per_px(t.classify, pixels));
                    s.blobs.push(ns_per_px(t.blobs, pixels));
                    s.total.push(ns_per_px(t.total(), pixels));
                    s.total_ms.push(t.total().as_secs_f64() * 1e3);
                }
            }
            if let Some(floor) = floor.as_ref().filter(|_| i < FLOOR_FRAMES) {
                floor_figures.push(floor.measure(&frame)?);
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let floor_ns = (!floor_figures.is_empty()).then(|| median(&floor_figures));
    let figures: Vec<SetFigures> = sets
        .iter()
        .zip(&samples)
        .map(|(set, s)| {
            let total = median(&s.total);
            SetFigures {
                kernels: set.name(),
                classify_ns_per_px: median(&s.classify),
                blobs_ns_per_px: median(&s.blobs),
                total_ns_per_px: total,
                total_ms_per_frame: median(&s.total_ms),
                vs_floor: floor_ns.map(|f| total / f),
            }
        })
        .collect();
    let main = figures
        .iter()
        .find(|f| f.kernels == chosen.name())
        .or(figures.first());
    let pick = |f: fn(&SetFigures) -> f64| main.map_or(f64::NAN, f);
    let result = BenchJson {
        frames: inputs.len(),
        pixels_per_frame: pixels,
        lut_bits: bits,
        connectivity: connectivity.neighbours(),
        reps,
        rounds,
        cpu: cpu_description(),
        kernels: chosen.name(),
        classify_ns_per_px: pick(|f| f.classify_ns_per_px),
        blobs_ns_per_px: pick(|f| f.blobs_ns_per_px),
        total_ns_per_px: pick(|f| f.total_ns_per_px),
        total_ms_per_frame: pick(|f| f.total_ms_per_frame),
        floor_ns_per_px: floor_ns,
        sets: figures,
    };
    print_report(&result, floor.as_ref().map(|f| f.source.clone()), args.json)
}

/// The table of figures (and the JSON line with `--json`).
fn print_report(r: &BenchJson, floor_source: Option<PathBuf>, json: bool) -> anyhow::Result<()> {
    outln!("# cpu: {}", r.cpu);
    outln!(
        "# eotn bench: {} frame(s), {} px/frame, lut b={}, conn={}, {} round(s) x {} reps/frame/set, kernels chosen: {}",
        r.frames,
        r.pixels_per_frame,
        r.lut_bits,
        r.connectivity,
        r.rounds,
        r.reps,
        r.kernels
    );
    outln!("kernels        classify    blobs    total ns/pixel   ms/frame   vs C floor");
    for f in &r.sets {
        let mark = if f.kernels == r.kernels { "*" } else { " " };
        let vs = f
            .vs_floor
            .map_or_else(|| "-".to_owned(), |v| format!("{v:.2}x"));
        outln!(
            "{mark}{:<13} {:8.3} {:8.3} {:8.3}       {:8.4}   {vs:>8}",
            f.kernels,
            f.classify_ns_per_px,
            f.blobs_ns_per_px,
            f.total_ns_per_px,
            f.total_ms_per_frame
        );
    }
    match (r.floor_ns_per_px, floor_source) {
        (Some(ns), Some(src)) => outln!(
            " C floor                         {ns:8.3}                   1.00x  ({}, classify+cc8 simd-rle)",
            src.display()
        ),
        _ => outln!(" C floor: not measured"),
    }
    if json {
        outln!("{}", serde_json::to_string(r)?);
    }
    Ok(())
}
