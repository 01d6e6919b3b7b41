//! `eotn overhead sim-field`: N overhead cameras over one simulated field (the overhead game),
//! written as one recording per camera with truth, each camera's own table and calibration, and
//! the `SESSION.json` that names them — a whole field to detect, merge and benchmark with.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};

use super::inputs::parse_size;
use super::overhead::{load_field, simulated_clicks};
use crate::lut::learn::{LearnParams, TableBuilder};
use crate::overhead::calibration::{CalibrationParams, calibrate_with};
use crate::overhead::intrinsics::Intrinsics;
use crate::overhead::review::{Severity, review};
use crate::sim::field_rig::{FieldRig, MAX_RIG_CAMERAS, MAX_RIG_SIZE, RIG_FPS};
use crate::streams::{FrameRecord, StreamInfo, StreamWriter};

/// Arguments of `eotn overhead sim-field`.
#[derive(Debug, clap::Args)]
pub struct SimFieldArgs {
    /// Number of overhead cameras, each over its own tile of the field with overlapping edges.
    #[arg(long, default_value_t = 4, value_parser = super::values::whole_in::<usize>(1, MAX_RIG_CAMERAS as u64))]
    pub cameras: usize,
    /// Frame size of every camera, WxH, at most 1920x1200.
    #[arg(long, default_value = "1920x1200", value_parser = parse_size)]
    pub size: (usize, usize),
    /// Frames per camera (75 a second).
    #[arg(long, default_value_t = 75, value_parser = super::values::whole_in::<u64>(1, 100_000))]
    pub frames: u64,
    /// Seed: poses, lenses, clocks and the game. Seeds 41 and 53 are held out (never used to
    /// tune anything).
    #[arg(long, default_value_t = 1, value_parser = super::values::seed())]
    pub seed: u64,
    /// Ideal frames: no noise or vignetting.
    #[arg(long)]
    pub ideal: bool,
    /// Click noise of each camera's simulated calibration points, pixels.
    #[arg(long, default_value_t = 0.5, value_parser = super::values::number_in(0.0, 20.0))]
    pub noise_px: f64,
    /// Output folder: `camN.mcap`, `camN.lut`, `camN.cal.json` per camera and `SESSION.json`.
    #[arg(short, long, value_name = super::paths::OUT_DIR)]
    pub output: PathBuf,
}

/// Frames of each camera whose true labels teach its table.
const TABLE_FRAMES: u64 = 8;

/// Runs `eotn overhead sim-field`.
///
/// # Errors
/// A size beyond 1920x1200, a camera whose simulated calibration fails, or a file that cannot
/// be written (named).
pub fn run(a: &SimFieldArgs) -> anyhow::Result<()> {
    let (w, h) = a.size;
    if w > MAX_RIG_SIZE.0 || h > MAX_RIG_SIZE.1 || w < 64 || h < 48 {
        bail!(
            "--size {w}x{h}: a rig camera is 64x48 to {}x{}",
            MAX_RIG_SIZE.0,
            MAX_RIG_SIZE.1
        );
    }
    crate::atomic_file::output_folder(&a.output)
        .with_context(|| format!("{}", a.output.display()))?;
    let mut rig = FieldRig::new(a.seed, a.cameras, w, h);
    if a.ideal {
        rig = rig.with_effects(crate::sim::CameraEffects::NONE);
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let start = Instant::now();
    let results: Vec<anyhow::Result<()>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads.min(a.cameras))
            .map(|t| {
                let rig = &rig;
                s.spawn(move || -> anyhow::Result<()> {
                    for k in (t..a.cameras).step_by(threads) {
                        write_camera(rig, k, a)?;
                    }
                    Ok(())
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(anyhow::anyhow!("a camera's thread failed")))
            })
            .collect()
    });
    for r in results {
        r?;
    }
    let session = session_json(a.cameras);
    let path = a.output.join("SESSION.json");
    let mut text = serde_json::to_string_pretty(&session)?;
    text.push('\n');
    crate::atomic_file::write_atomic(&path, text.as_bytes())
        .with_context(|| format!("{}: cannot write", path.display()))?;
    eprintln!(
        "{}: {} cameras of {w}x{h}, {} frames each at {RIG_FPS} fps, in {:.1} s",
        path.display(),
        a.cameras,
        a.frames,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The name of camera `k`'s files.
#[must_use]
pub fn camera_stem(k: usize) -> String {
    format!("cam{k}")
}

/// The session of `n` cameras named as [`write_camera`] writes them (ids 0..n).
fn session_json(n: usize) -> serde_json::Value {
    let overhead: Vec<serde_json::Value> = (0..n)
        .map(|k| {
            let stem = camera_stem(k);
            serde_json::json!({
                "id": k,
                "source": format!("{stem}.mcap"),
                "lut": format!("{stem}.lut"),
                "calibration": format!("{stem}.cal.json"),
            })
        })
        .collect();
    serde_json::json!({
        "field": "four-legged-2005",
        "overhead": overhead,
        "robots": [],
    })
}

/// Renders camera `k`'s frames into its recording, learns its table from the true labels of
/// [`TABLE_FRAMES`] of them, and calibrates it from simulated clicks refined along the lines of
/// its first frame.
fn write_camera(rig: &FieldRig, k: usize, a: &SimFieldArgs) -> anyhow::Result<()> {
    let stem = camera_stem(k);
    let dir = &a.output;
    let renderer = rig.renderer(k).context("camera index")?;
    let cam = rig.cameras()[k];
    let info = StreamInfo {
        source: format!("sim:overhead-game camera {k}"),
        description: format!(
            "eotn overhead sim-field --cameras {} --size {}x{} --frames {} --seed {}{}: camera {k} of the field",
            a.cameras,
            a.size.0,
            a.size.1,
            a.frames,
            a.seed,
            if a.ideal { " --ideal" } else { "" }
        ),
    };
    let mcap = dir.join(format!("{stem}.mcap"));
    let mut writer = StreamWriter::create(&mcap, &info)?;
    // The recording names its own table and calibration (beside it), so the app and every
    // command open the camera with them.
    let files = crate::camera::CameraFiles {
        lut: Some(format!("{stem}.lut").into()),
        calibration: Some(format!("{stem}.cal.json").into()),
        params: None,
    };
    writer.name_camera_files(crate::streams::IMAGE_TOPIC, &files)?;
    let mut builder = TableBuilder::new(7)?;
    let every = (a.frames / TABLE_FRAMES).max(1);
    let mut first = None;
    for index in 0..a.frames {
        let f = rig.frame(&renderer, k, index)?;
        if index % every == 0 {
            builder
                .add_frame(&f.frame, &f.labels)
                .with_context(|| format!("{stem}: labels"))?;
        }
        if first.is_none() {
            first = Some(f.frame.clone());
        }
        let mut record = FrameRecord::new(f.time_ns, f.frame);
        record.ground_truth = Some(serde_json::to_value(&f.ground_truth)?);
        writer.write(&record)?;
    }
    writer.finish()?;
    drop(renderer);
    let lut = dir.join(format!("{stem}.lut"));
    builder
        .build(&LearnParams::default())
        .save(&lut)
        .with_context(|| format!("{}: cannot write", lut.display()))?;
    let cal_path = dir.join(format!("{stem}.cal.json"));
    write_calibration(&cal_path, &cam.camera, first.as_ref(), a, k)
}

fn write_calibration(
    path: &Path,
    camera: &crate::geometry::OverheadCamera,
    frame: Option<&crate::frame::Frame>,
    a: &SimFieldArgs,
    k: usize,
) -> anyhow::Result<()> {
    let field = load_field(None)?;
    let points = simulated_clicks(camera, &field, a.noise_px, a.seed ^ (k as u64 + 1));
    // As a team would: the lens known from a checkerboard, only the pose fitted from clicks (a
    // camera seeing few landmarks cannot determine its lens from them).
    let intrinsics = true_intrinsics(camera, k);
    let cal = calibrate_with(
        &points,
        &field,
        frame,
        &CalibrationParams::default(),
        Some(&intrinsics),
    )
    .with_context(|| format!("camera {k}: its simulated calibration failed"))?;
    let r = review(&cal);
    if let Some(refusal) = r.refusal() {
        bail!("camera {k}: its simulated calibration is refused: {refusal}");
    }
    if r.doubtful() {
        log::warn!(
            "camera {k}: its simulated calibration is doubtful ({} warnings), kept",
            r.of(Severity::Doubt).count()
        );
    }
    cal.save(path)?;
    Ok(())
}

/// The simulated camera's own intrinsics (its lens; a k1/k2 lens as `plumb_bob`, the same
/// normalised-coordinate polynomial).
fn true_intrinsics(camera: &crate::geometry::OverheadCamera, k: usize) -> Intrinsics {
    Intrinsics {
        camera_name: format!("simulated camera {k}"),
        width_px: camera.width_px,
        height_px: camera.height_px,
        fx: camera.focal_px,
        fy: camera.focal_y(),
        centre: camera.centre,
        lens: camera.lens.unwrap_or(crate::geometry::LensModel::PlumbBob {
            k1: camera.k1,
            k2: camera.k2,
            p1: 0.0,
            p2: 0.0,
            k3: 0.0,
        }),
    }
}
