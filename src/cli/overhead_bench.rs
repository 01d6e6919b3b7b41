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

use super::bench_floor::{Floor, FloorStages};
use super::field::open_cameras;
use super::inputs::{FrameInputs, load_lut_arg, parse_size};
use super::overhead::{load_field, load_usable_calibration, params_for, refuse_robot_streams};
use crate::eval::overhead::{OverheadEvalParams, OverheadEvalReport, evaluate_overhead_frame};
use crate::eval::overhead_field::{CameraTruth, FieldEvalReport, evaluate_field_frame};
use crate::frame::Frame;
use crate::geometry::{ImagePoint, OverheadCamera};
use crate::model::truth::OverheadTruth;
use crate::overhead::merge::{SslCameraId, merge_detections};
use crate::overhead::{OverheadDetections, OverheadParams, OverheadPipeline};
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
    /// The hand-written C floor to hold the stages against (`floors.c`, compiled here, or the
    /// compiled program); default `../shared/bench/floors.c` when it exists.
    #[arg(long, value_name = "FLOORS")]
    pub floor: Option<PathBuf>,
    /// Do not run the C floor.
    #[arg(long, conflicts_with = "floor")]
    pub no_floor: bool,
    /// One JSON object.
    #[arg(long)]
    pub json: bool,
}

/// One camera's frames in memory with its pipeline.
struct BenchCamera {
    id: SslCameraId,
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
    /// The C floor's stages on the first held frame, measured in this run, and eotn's stage
    /// medians over them (`None`: no floor, or `--no-floor`).
    floor: Option<FloorComparison>,
    /// Each camera's detections against its frame's truth (when the frames have it), every
    /// held frame once.
    accuracy: Option<OverheadEvalReport>,
    /// `--session`: the merged field pictures against the truth (frame i of every camera as one
    /// field frame: the simulator's cameras deliver in step).
    field_accuracy: Option<FieldEvalReport>,
}

/// Median time of each pipeline stage over every held frame once, on one thread, milliseconds.
#[derive(Debug, Clone, Copy, Default, Serialize)]
struct StageFigures {
    /// Table lookup of every pixel.
    classify_ms: f64,
    /// Run-length encoding and union-find.
    blobs_ms: f64,
    /// Ball and markers together.
    recognition_ms: f64,
    /// Of recognition: finding the ball.
    ball_ms: f64,
    /// Of recognition: reading the robot markers.
    markers_ms: f64,
    /// Of ball and markers: carrying points through the lens and pose, estimated as the
    /// median count of points a frame times one point's measured cost each way.
    undistortion_ms: f64,
    /// Points a frame carried from the field into the image (median).
    points_to_image: f64,
    /// Image points a frame carried onto the field (median).
    points_to_field: f64,
    /// One point's cost each way, nanoseconds.
    projection: ProjectionCosts,
    /// `--session`: merging one field frame's cameras.
    merge_ms: Option<f64>,
}

/// One point's cost through a calibrated camera, nanoseconds: each way with the pose built
/// once (as recognition runs), and into the image with the pose rebuilt from its angles for
/// the point (as before the pose was built once a frame).
#[derive(Debug, Clone, Copy, Default, Serialize)]
struct ProjectionCosts {
    to_image_ns: f64,
    to_field_ns: f64,
    to_image_pose_per_point_ns: f64,
}

/// The C floor's stages and eotn's over them.
#[derive(Debug, Clone, Copy, Serialize)]
struct FloorComparison {
    /// The floor's figures.
    #[serde(flatten)]
    floor: FloorStages,
    /// eotn's classification median over the floor's.
    classify_ratio: f64,
    /// eotn's blobs median over the floor's.
    blobs_ratio: f64,
    /// eotn's classification + blobs over the floor's pipeline.
    pipeline_ratio: f64,
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
    let (accuracy, field_accuracy, stages) = check_accuracy(&mut cameras, a.session.is_some());
    let floor = compare_floor(a, &cameras, &stages);
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
        floor,
        accuracy,
        field_accuracy,
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
    write_stages(&mut stdout, &out.stages, out.floor.as_ref())?;
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
    if let Some(f) = &out.field_accuracy {
        let m = &f.merged;
        let p50 = |p: &Option<crate::eval::Percentiles>| p.map_or(f64::NAN, |p| p.p50);
        writeln!(
            stdout,
            "merged field pictures: ball {}/{} found, median {:.2} cm; robots {}/{} found, {}/{} identified, heading median {:.2}°; {} seen by several cameras, {} reported twice, {} false",
            m.ball_found,
            m.ball_eligible,
            p50(&m.ball_error_cm),
            m.robots_found,
            m.robots_eligible,
            m.identity_right,
            m.robots_eligible,
            p50(&m.heading_error_deg),
            f.robots_seen_by_several,
            f.duplicates,
            m.robots_false
        )?;
        writeln!(
            stdout,
            "cameras' own ball misses {}: {} of them showed less than half the ball",
            f.camera_ball_misses, f.camera_ball_misses_under_half_shown
        )?;
    }
    Ok(())
}

fn write_stages(
    out: &mut impl Write,
    st: &StageFigures,
    floor: Option<&FloorComparison>,
) -> anyhow::Result<()> {
    writeln!(
        out,
        "stages (median ms, one pass, one thread): classify {:.3}, blobs {:.3}, recognition {:.3} (ball {:.3}, markers {:.3}; of them lens and pose ≈ {:.3}: {:.0} points to the image at {:.1} ns, {:.0} to the field at {:.1} ns)",
        st.classify_ms,
        st.blobs_ms,
        st.recognition_ms,
        st.ball_ms,
        st.markers_ms,
        st.undistortion_ms,
        st.points_to_image,
        st.projection.to_image_ns,
        st.points_to_field,
        st.projection.to_field_ns
    )?;
    if let Some(m) = st.merge_ms {
        writeln!(out, "merging one field frame: {m:.4} ms")?;
    }
    if let Some(f) = floor {
        writeln!(
            out,
            "C floor (first frame): frame copy {:.3} ms, classify {:.3} ms ({:.2}x), blobs {:.3} ms ({:.2}x), both {:.3} ms ({:.2}x)",
            f.floor.frame_copy_ms,
            f.floor.classify_ms,
            f.classify_ratio,
            f.floor.blobs_ms,
            f.blobs_ratio,
            f.floor.pipeline_ms,
            f.pipeline_ratio
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
        id: SslCameraId(0),
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
            id: cam.id,
            pipeline: cam.pipeline,
            frames,
            truths,
        });
    }
    Ok(out)
}

/// Every held frame once through its camera's pipeline, against its truth (`None` when no
/// frame has one), each stage timed; with `field`, frame i of every camera merged into one field
/// picture, timed and held against the truth. Also warms the caches before the timed runs.
fn check_accuracy(
    cameras: &mut [BenchCamera],
    field: bool,
) -> (
    Option<OverheadEvalReport>,
    Option<FieldEvalReport>,
    StageFigures,
) {
    let params = OverheadEvalParams::default();
    let mut evals = Vec::new();
    let mut stages: [Vec<f64>; 7] = Default::default();
    let mut detections: Vec<Vec<OverheadDetections>> = Vec::new();
    for cam in cameras.iter_mut() {
        let mut mine = Vec::new();
        for (i, (frame, truth)) in cam.frames.iter().zip(&cam.truths).enumerate() {
            let d = cam.pipeline.process(frame);
            if let Some(t) = truth {
                evals.push(evaluate_overhead_frame(i, d, t, &params));
            }
            mine.push(d.clone());
            let t = cam.pipeline.timings();
            let ms = |d: Duration| d.as_secs_f64() * 1e3;
            let figures = [
                ms(t.classify),
                ms(t.blobs),
                ms(t.recognition),
                ms(t.parts.ball),
                ms(t.parts.markers),
                f64::from(t.parts.to_image),
                f64::from(t.parts.to_field),
            ];
            for (v, x) in stages.iter_mut().zip(figures) {
                v.push(x);
            }
        }
        detections.push(mine);
    }
    let (field_accuracy, merge_ms) = if field {
        merge_field_frames(cameras, &detections, &params)
    } else {
        (None, None)
    };
    let median = |v: &[f64]| crate::stats::median(v).unwrap_or(f64::NAN);
    let projection = cameras
        .first()
        .map(|c| projection_costs(c.pipeline.camera()))
        .unwrap_or_default();
    let (to_image, to_field) = (median(&stages[5]), median(&stages[6]));
    let stages = StageFigures {
        classify_ms: median(&stages[0]),
        blobs_ms: median(&stages[1]),
        recognition_ms: median(&stages[2]),
        ball_ms: median(&stages[3]),
        markers_ms: median(&stages[4]),
        undistortion_ms: (to_image * projection.to_image_ns + to_field * projection.to_field_ns)
            * 1e-6,
        points_to_image: to_image,
        points_to_field: to_field,
        projection,
        merge_ms,
    };
    let report = (!evals.is_empty()).then(|| OverheadEvalReport::from_frames(&evals, &[]));
    (report, field_accuracy, stages)
}

/// Frame i of every camera merged as one field frame: the merged pictures against the truth
/// (when every frame has one) and the median time of one merge, milliseconds.
fn merge_field_frames(
    cameras: &[BenchCamera],
    detections: &[Vec<OverheadDetections>],
    params: &OverheadEvalParams,
) -> (Option<FieldEvalReport>, Option<f64>) {
    let longest = detections.iter().map(Vec::len).max().unwrap_or(0);
    let (mut times, mut field, mut own) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..longest {
        let views: Vec<(SslCameraId, &OverheadDetections)> = cameras
            .iter()
            .zip(detections)
            .filter_map(|(c, d)| Some((c.id, d.get(i)?)))
            .collect();
        let t = Instant::now();
        let picture = merge_detections(&views);
        times.push(t.elapsed().as_secs_f64() * 1e3);
        let mut truths = Vec::new();
        for ((c, d), (id, _)) in cameras.iter().zip(detections).zip(&views) {
            let (Some(Some(truth)), Some(d)) = (c.truths.get(i), d.get(i)) else {
                continue;
            };
            let e = evaluate_overhead_frame(own.len(), d, truth, params);
            truths.push(CameraTruth {
                camera: *id,
                truth,
                found_ball: e.ball_error_cm.is_some(),
            });
            own.push(e);
        }
        if !truths.is_empty() {
            let radius = OverheadParams::default().ball_radius_cm;
            field.push(evaluate_field_frame(i, &picture, &truths, params, radius));
        }
    }
    let report =
        (!field.is_empty()).then(|| FieldEvalReport::from_frames(cameras.len(), &field, &own));
    (report, crate::stats::median(&times))
}

/// One point's cost through `camera` each way (median of 31 passes over a 24×16 grid of image
/// points at the marker plates' height), nanoseconds.
fn projection_costs(camera: &OverheadCamera) -> ProjectionCosts {
    use std::hint::black_box;
    let z = OverheadParams::default().plate_height_cm;
    let projector = camera.projector();
    let (w, h) = (camera.width_px as f64, camera.height_px as f64);
    let image: Vec<ImagePoint> = (0..16)
        .flat_map(|r| {
            (0..24).map(move |c| {
                ImagePoint::new(
                    (f64::from(c) + 0.5) * w / 24.0,
                    (f64::from(r) + 0.5) * h / 16.0,
                )
            })
        })
        .collect();
    let field: Vec<_> = image
        .iter()
        .filter_map(|&p| projector.field_from_image(p, z))
        .collect();
    let per_point = |n: usize, pass: &dyn Fn()| {
        let mut samples: Vec<f64> = (0..31)
            .map(|_| {
                let t = Instant::now();
                pass();
                t.elapsed().as_secs_f64() * 1e9 / n.max(1) as f64
            })
            .collect();
        samples.sort_by(f64::total_cmp);
        samples[samples.len() / 2]
    };
    ProjectionCosts {
        to_image_ns: per_point(field.len(), &|| {
            for p in &field {
                black_box(projector.image_from_field(black_box(p)));
            }
        }),
        to_field_ns: per_point(image.len(), &|| {
            for &p in &image {
                black_box(projector.field_from_image(black_box(p), z));
            }
        }),
        to_image_pose_per_point_ns: per_point(field.len(), &|| {
            for p in &field {
                black_box(camera.image_from_field(black_box(p)));
            }
        }),
    }
}

/// The C floor's stages on the first held frame against eotn's stage medians, both measured in
/// this run; `None` (said on stderr) without a floor.
fn compare_floor(
    a: &BenchArgs,
    cameras: &[BenchCamera],
    stages: &StageFigures,
) -> Option<FloorComparison> {
    if a.no_floor {
        return None;
    }
    let cam = cameras.iter().find(|c| !c.frames.is_empty())?;
    let Some(source) = a.floor.clone().or_else(super::bench_floor::default_source) else {
        eprintln!(
            "eotn overhead bench: C floor not measured (no ../shared/bench/floors.c; pass --floor)"
        );
        return None;
    };
    let measured =
        Floor::prepare(&source, cam.pipeline.lut()).and_then(|f| f.measure_stages(&cam.frames[0]));
    match measured {
        Ok(floor) => Some(FloorComparison {
            classify_ratio: stages.classify_ms / floor.classify_ms,
            blobs_ratio: stages.blobs_ms / floor.blobs_ms,
            pipeline_ratio: (stages.classify_ms + stages.blobs_ms) / floor.pipeline_ms,
            floor,
        }),
        Err(e) => {
            eprintln!("eotn overhead bench: C floor not measured: {e:#}");
            None
        }
    }
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
