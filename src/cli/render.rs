//! `eotn render`: draws a frame (raw colour or classified) with chosen overlays to PNG, headless,
//! from the same drawing primitives the app uses.

use std::path::PathBuf;

use anyhow::Context;

use super::detect::{load_sensor_file, readings_for};
use super::inputs::InputArgs;
use crate::frame::save_rgb_png;
use crate::overlay::Canvas;
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::{LineRole, ObjectId, Primitive};

/// Which picture is drawn under the overlays.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum View {
    /// The camera image in colour.
    Raw,
    /// Each pixel in its class's display colour.
    Classified,
}

/// Overlays that can be switched on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Overlay {
    /// Every blob's box (blobs of at least `--min-blob-pixels`).
    Blobs,
    /// Candidate boxes of recognised objects.
    Candidates,
    /// Scan areas (colour below).
    Scans,
    /// Edge and post scan points.
    Points,
    /// Fitted circles.
    Circles,
    /// Goal posts.
    Posts,
    /// Gaps and gap scans.
    Gaps,
    /// The horizon.
    Horizon,
    /// The nine regions around each pink marker and its identification (with `--patterns`).
    Patterns,
    /// Everything above.
    All,
}

/// Most pixels a rendered picture may have (64 Mpx, 192 MiB of RGB): `--scale` beyond it is
/// refused before anything is drawn.
const MAX_PICTURE_PIXELS: u64 = 64_000_000;

/// Arguments of `eotn render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Frames, table and raw frame size.
    #[command(flatten)]
    pub input: InputArgs,
    /// Output folder; one PNG per frame, named after it.
    #[arg(short, long, value_name = super::paths::OUT_DIR)]
    pub output: PathBuf,
    /// Sensor readings JSON (as for `eotn detect`).
    #[arg(long)]
    pub sensors: Option<PathBuf>,
    /// Recognition parameters JSON (default: the set the first recording names for the camera read, else the defaults).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// The picture under the overlays.
    #[arg(long, value_enum, default_value = "raw")]
    pub view: View,
    /// Overlays to draw (comma-separated).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "all")]
    pub overlays: Vec<Overlay>,
    /// Enlargement factor (nearest neighbour), 1..=16.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(1..=16))]
    pub scale: u8,
    /// Smallest blob drawn by the `blobs` overlay, pixels.
    #[arg(long, default_value_t = 4, value_parser = super::values::whole_in::<u32>(0, super::values::MAX_PIXELS))]
    pub min_blob_pixels: u32,
    /// A places file (`eotn patterns learn`): pink markers are identified and labelled with
    /// their place and distance by the `patterns` overlay.
    #[arg(long)]
    pub patterns: Option<PathBuf>,
}

fn wanted(overlays: &[Overlay], p: &Primitive) -> bool {
    let on = |o: Overlay| overlays.contains(&o) || overlays.contains(&Overlay::All);
    match p {
        Primitive::Box { .. } => on(Overlay::Candidates),
        Primitive::ScanArea { .. } => on(Overlay::Scans),
        Primitive::ScanPoints { .. } => on(Overlay::Points),
        Primitive::Circle { .. } => on(Overlay::Circles),
        Primitive::Line { role, .. } => match role {
            LineRole::Horizon => on(Overlay::Horizon),
            LineRole::Post => on(Overlay::Posts),
            LineRole::Gap | LineRole::Scan => on(Overlay::Gaps),
        },
        Primitive::PatternRegion { .. } => on(Overlay::Patterns),
        Primitive::Label { owner, .. } => owner.is_pattern() && on(Overlay::Patterns),
    }
}

/// Runs `eotn render`.
///
/// # Errors
/// Unreadable inputs or an unwritable output, naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let (lut, mut inputs) = args.input.open()?;

    let sensors = args.sensors.as_deref().map(load_sensor_file).transpose()?;
    let params = PipelineParams {
        recognition: super::detect::params_or_camera_s(
            args.params.as_deref(),
            &args.input.frames,
            args.input.camera.get(),
        )?,
        ..PipelineParams::default()
    };
    crate::atomic_file::output_folder(&args.output)
        .with_context(|| format!("{}", args.output.display()))?;
    let mut pipeline = Pipeline::new(lut, params);
    if let Some(p) = &args.patterns {
        pipeline.set_pattern_memory(Some(crate::recognition::patterns::PatternMemory::load(p)?));
    }
    for i in 0..inputs.len() {
        let Some(record) = inputs.load_record_or_skip(i, args.input.size)? else {
            continue;
        };
        let (frame, recorded) = (record.frame, record.sensors);
        let readings = readings_for(recorded.as_ref(), sensors.as_deref(), i);
        let result = pipeline.process(&frame, readings);
        let (w, h) = (frame.width(), frame.height());
        let scaled = (w as u64 * u64::from(args.scale)) * (h as u64 * u64::from(args.scale));
        if scaled > MAX_PICTURE_PIXELS {
            anyhow::bail!(
                "{}: {w}×{h} at --scale {} makes a {}×{} picture, larger than the {} Mpx a render may be; use a smaller --scale",
                inputs.name(i),
                args.scale,
                w * usize::from(args.scale),
                h * usize::from(args.scale),
                MAX_PICTURE_PIXELS / 1_000_000
            );
        }
        let base = match args.view {
            View::Raw => frame.to_rgb(),
            View::Classified => result.classified.to_rgb(),
        };
        let mut canvas = Canvas::from_rgb(w, h, &base, usize::from(args.scale))
            .context("internal: picture size does not match the frame")?;
        let mut prims: Vec<Primitive> = Vec::new();
        if args.overlays.contains(&Overlay::Blobs) || args.overlays.contains(&Overlay::All) {
            prims.extend(
                result
                    .blobs
                    .active()
                    .filter(|b| b.pixels >= args.min_blob_pixels)
                    .map(|b| Primitive::Box {
                        owner: ObjectId::Blob(b.number),
                        colour: b.colour,
                        bounds: b.bounds(),
                    }),
            );
        }
        prims.extend(
            result
                .recognition
                .primitives(w, h)
                .into_iter()
                .filter(|p| wanted(&args.overlays, p)),
        );
        canvas.draw(&prims);
        let name = inputs.name(i);
        let stem = name.rsplit_once('.').map_or(name.as_str(), |(s, _)| s);
        let out = args.output.join(format!("{stem}.png"));
        save_rgb_png(&out, canvas.width, canvas.height, &canvas.rgb)?;
    }
    Ok(())
}
