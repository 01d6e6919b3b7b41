//! `eotn overhead bench`: the overhead pipeline's throughput on frames held in memory — one
//! camera's frames, or a whole field's (`--session`: each camera its own frames, table and
//! calibration, checked against the truth in the same run) — on N threads, with one thread's
//! figure beside it.

use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use serde::Serialize;

use super::field::open_cameras;
use super::inputs::{FrameInputs, load_lut_arg, parse_size};
use super::overhead::{load_field, load_usable_calibration, params_for, refuse_robot_streams};
use crate::eval::overhead::{OverheadEvalParams, OverheadEvalReport, evaluate_overhead_frame};
use crate::frame::Frame;
use crate::model::truth::OverheadTruth;
use crate::overhead::OverheadPipeline;
use crate::session::Session;

/// Arguments of `eotn overhead bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Frames (`.uyvy`, `.png`, `.jpg`), folders of them, or MCAP streams of one camera.
    #[arg(required_unless_present = "session", conflicts_with = "session")]
    pub frames: Vec<PathBuf>,
    /// Which camera of the recordings (with FRAME…).
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
    /// Lookup table of the camera (with FRAME…).
    #[arg(long, required_unless_present = "session", conflicts_with = "session")]
    pub lut: Option<PathBuf>,
    /// Calibration of the camera (with FRAME…).
    #[arg(long, required_unless_present = "session", conflicts_with = "session")]
    pub calibration: Option<PathBuf>,
    /// A session file: every overhead camera's recorded frames with its own table and
    /// calibration, checked against the recordings' truth when they have it.
    #[arg(long)]
    pub session: Option<PathBuf>,
    /// Worker threads; every core by default.
    #[arg(long, value_parser = super::values::whole_in::<usize>(1, 256))]
    pub threads: Option<usize>,
    /// Seconds each timed run lasts (one thread, then N threads).
    #[arg(long, default_value_t = 3.0, value_parser = super::values::number_in(0.05, 3600.0))]
    pub seconds: f64,
    /// Most frames held per camera.
    #[arg(long, default_value_t = 150, value_parser = super::values::whole_in::<usize>(1, 100_000))]
    pub max_frames: usize,
    /// Frame size of raw files, WxH.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// One JSON object.
    #[arg(long)]
    pub json: bool,
}

/// One camera's frames in memory with its pipeline.
struct BenchCamera {
    pipeline: OverheadPipeline,
    frames: Vec<Frame>,
    truths: Vec<Option<OverheadTruth>>,
}

/// One timed run's figures.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RunFigures {
    /// Frames processed per second of wall time, all threads together.
    pub frames_per_s: f64,
    /// Median time of one frame on one thread, milliseconds.
    pub median_frame_ms: f64,
    /// 99th percentile of it, milliseconds.
    pub p99_frame_ms: f64,
    /// Threads.
    pub threads: usize,
    /// Frames processed.
    pub frames: usize,
}

/// `eotn overhead bench --json` (the first six keys are fixed by issue 31).
#[derive(Debug, Serialize)]
struct BenchJson {
    frames_per_s: f64,
    median_frame_ms: f64,
    p99_frame_ms: f64,
    threads: usize,
    width: usize,
    height: usize,
    /// The same on one thread, measured in the same run.
    one_thread: RunFigures,
    /// Cameras benchmarked.
    cameras: usize,
    /// Distinct frames held (all cameras).
    distinct_frames: usize,
    /// Kernel set in use.
    kernels: String,
    /// Where one frame's time goes: each stage's median over the accuracy pass.
    stages: StageFigures,
    /// Detections against the truth (when the frames have it), every held frame once.
    accuracy: Option<OverheadEvalReport>,
}

/// Median time of each pipeline stage over every held frame once, on one thread, milliseconds.
#[derive(Debug, Clone, Copy, Default, Serialize)]
struct StageFigures {
    classify_ms: f64,
    blobs_ms: f64,
    recognition_ms: f64,
}

/// Runs `eotn overhead bench`.
///
/// # Errors
/// Unreadable inputs (named), no frames, frames of another shape than their calibration.
pub fn run(a: &BenchArgs) -> anyhow::Result<()> {
    let mut cameras = match &a.session {
        Some(path) => session_cameras(&Session::load(path)?, a.max_frames)?,
        None => vec![frames_camera(a)?],
    };
    let distinct: usize = cameras.iter().map(|c| c.frames.len()).sum();
    if distinct == 0 {
        bail!("no frames to benchmark");
    }
    let (width, height) = cameras
        .iter()
        .flat_map(|c| c.frames.first())
        .map(|f| (f.width(), f.height()))
        .next()
        .unwrap_or_default();
    let (accuracy, stages) = check_accuracy(&mut cameras);
    let threads = a
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let seconds = Duration::from_secs_f64(a.seconds);
    let one = timed_run(&cameras, 1, seconds);
    let many = timed_run(&cameras, threads, seconds);
    let out = BenchJson {
        frames_per_s: many.frames_per_s,
        median_frame_ms: many.median_frame_ms,
        p99_frame_ms: many.p99_frame_ms,
        threads,
        width,
        height,
        one_thread: one,
        cameras: cameras.len(),
        distinct_frames: distinct,
        kernels: crate::kernels::active().name().to_owned(),
        stages,
        accuracy,
    };
    print_bench(&out, a.json)
}

fn print_bench(out: &BenchJson, json: bool) -> anyhow::Result<()> {
    let mut stdout = std::io::stdout().lock();
    if json {
        serde_json::to_writer(&mut stdout, out)?;
        writeln!(stdout)?;
        return Ok(());
    }
    writeln!(
        stdout,
        "{} cameras, {} distinct {}x{} frames, kernels {}",
        out.cameras, out.distinct_frames, out.width, out.height, out.kernels
    )?;
    let r = &out.one_thread;
    writeln!(
        stdout,
        "1 thread:   {:8.1} frames/s, median {:.3} ms, p99 {:.3} ms",
        r.frames_per_s, r.median_frame_ms, r.p99_frame_ms
    )?;
    let st = &out.stages;
    writeln!(
        stdout,
        "stages (median ms, one pass, one thread): classify {:.3}, blobs {:.3}, recognition {:.3}",
        st.classify_ms, st.blobs_ms, st.recognition_ms
    )?;
    writeln!(
        stdout,
        "{} threads: {:8.1} frames/s, median {:.3} ms, p99 {:.3} ms ({:.2}x one thread)",
        out.threads,
        out.frames_per_s,
        out.median_frame_ms,
        out.p99_frame_ms,
        out.frames_per_s / out.one_thread.frames_per_s.max(f64::MIN_POSITIVE)
    )?;
    if let Some(r) = &out.accuracy {
        let p50 = |p: &Option<crate::eval::Percentiles>| p.map_or(f64::NAN, |p| p.p50);
        writeln!(
            stdout,
            "against the truth: ball {}/{} found, median {:.2} cm; robots {}/{} found, {}/{} identified, heading median {:.2}°; {} false robots",
            r.ball_found,
            r.ball_eligible,
            p50(&r.ball_error_cm),
            r.robots_found,
            r.robots_eligible,
            r.identity_right,
            r.robots_eligible,
            p50(&r.heading_error_deg),
            r.robots_false
        )?;
    }
    Ok(())
}

/// The frames of FRAME… with `--lut` and `--calibration`.
fn frames_camera(a: &BenchArgs) -> anyhow::Result<BenchCamera> {
    let (Some(lut), Some(cal)) = (&a.lut, &a.calibration) else {
        bail!("--lut and --calibration are needed with frames (or give --session)");
    };
    let lut = load_lut_arg(lut)?;
    let cal = load_usable_calibration(cal)?;
    let field = load_field(None)?;
    let mut inputs = FrameInputs::open_camera(&a.frames, None, a.camera.get())?;
    refuse_robot_streams(inputs.robot_streams())?;
    let mut sizes = super::overhead::SizeCheck::default();
    let mut frames = Vec::new();
    for i in 0..inputs.len().min(a.max_frames) {
        let f = inputs.load(i, a.size)?;
        sizes.check(&cal.camera, &inputs.name(i), f.width(), f.height())?;
        frames.push(f);
    }
    Ok(BenchCamera {
        pipeline: OverheadPipeline::new(lut, cal.camera, params_for(&field)),
        truths: vec![None; frames.len()],
        frames,
    })
}

/// Every camera of a session with up to `max_frames` of its frames.
fn session_cameras(session: &Session, max_frames: usize) -> anyhow::Result<Vec<BenchCamera>> {
    let (_, cameras) = open_cameras(session)?;
    let mut out = Vec::new();
    for mut cam in cameras {
        let mut sizes = super::overhead::SizeCheck::default();
        let (mut frames, mut truths) = (Vec::new(), Vec::new());
        for i in 0..cam.len().min(max_frames) {
            let f = cam.read(i)?;
            let camera = *cam.pipeline.camera();
            sizes
                .check(
                    &camera,
                    &format!("{} frame {i}", cam.name),
                    f.frame.width(),
                    f.frame.height(),
                )
                .with_context(|| format!("camera {}", cam.id))?;
            frames.push(f.frame);
            truths.push(f.truth);
        }
        out.push(BenchCamera {
            pipeline: cam.pipeline,
            frames,
            truths,
        });
    }
    Ok(out)
}

/// Every held frame once through its camera's pipeline, against its truth (`None` when no
/// frame has one). Also warms the caches before the timed runs.
fn check_accuracy(cameras: &mut [BenchCamera]) -> (Option<OverheadEvalReport>, StageFigures) {
    let params = OverheadEvalParams::default();
    let mut evals = Vec::new();
    let mut stages: [Vec<f64>; 3] = Default::default();
    for cam in cameras.iter_mut() {
        for (i, (frame, truth)) in cam.frames.iter().zip(&cam.truths).enumerate() {
            let d = cam.pipeline.process(frame);
            if let Some(t) = truth {
                evals.push(evaluate_overhead_frame(i, d, t, &params));
            }
            let t = cam.pipeline.timings();
            for (v, d) in stages.iter_mut().zip([t.classify, t.blobs, t.recognition]) {
                v.push(d.as_secs_f64() * 1e3);
            }
        }
    }
    let median = |v: &[f64]| crate::stats::median(v).unwrap_or(f64::NAN);
    let stages = StageFigures {
        classify_ms: median(&stages[0]),
        blobs_ms: median(&stages[1]),
        recognition_ms: median(&stages[2]),
    };
    let report = (!evals.is_empty()).then(|| OverheadEvalReport::from_frames(&evals, &[]));
    (report, stages)
}

/// `threads` threads taking frames in turn (camera by camera, frame by frame) for `seconds`,
/// each with its own copy of every camera's pipeline.
fn timed_run(cameras: &[BenchCamera], threads: usize, seconds: Duration) -> RunFigures {
    let order: Vec<(usize, usize)> = {
        let longest = cameras.iter().map(|c| c.frames.len()).max().unwrap_or(0);
        (0..longest)
            .flat_map(|i| {
                cameras
                    .iter()
                    .enumerate()
                    .filter(move |(_, c)| i < c.frames.len())
                    .map(move |(k, _)| (k, i))
            })
            .collect()
    };
    let next = AtomicUsize::new(0);
    let start = Instant::now();
    let per_thread: Vec<(Vec<f64>, Instant)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                let (order, next) = (&order, &next);
                s.spawn(move || {
                    let mut pipelines: Vec<OverheadPipeline> =
                        cameras.iter().map(|c| c.pipeline.clone()).collect();
                    let mut ms = Vec::new();
                    while start.elapsed() < seconds {
                        let n = next.fetch_add(1, Ordering::Relaxed);
                        let (k, i) = order[n % order.len()];
                        let t = Instant::now();
                        pipelines[k].process(&cameras[k].frames[i]);
                        ms.push(t.elapsed().as_secs_f64() * 1e3);
                    }
                    (ms, Instant::now())
                })
            })
            .collect();
        handles.into_iter().filter_map(|h| h.join().ok()).collect()
    });
    let end = per_thread.iter().map(|(_, e)| *e).max().unwrap_or(start);
    let mut all: Vec<f64> = per_thread.into_iter().flat_map(|(ms, _)| ms).collect();
    all.sort_by(f64::total_cmp);
    let at = |q: f64| {
        all.get(((all.len() as f64 - 1.0) * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    let wall = (end - start).as_secs_f64().max(1e-9);
    RunFigures {
        frames_per_s: all.len() as f64 / wall,
        median_frame_ms: at(0.5),
        p99_frame_ms: at(0.99),
        threads,
        frames: all.len(),
    }
}
