//! `eotn sim`: render a scenario into a stream, with sensor readings and ground truth.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;

use super::inputs::progress;
use crate::sim::{ScenarioKind, Simulator};
use crate::streams::schema::ImageEncoding;
use crate::streams::{FrameRecord, StreamInfo, StreamWriter, WriterOptions};

/// Arguments of `eotn sim`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario: walk-and-pan, ball-edge, goalkeeper, fast-pans, orange-clutter, beacon-tour,
    /// overhead-game, close-pans, rolling-ball, pattern-tour (`--list` describes them).
    #[arg(long, required_unless_present = "list")]
    pub scenario: Option<String>,
    /// Number of frames (30 a second).
    #[arg(long, default_value_t = 90, value_parser = super::values::whole_in::<u64>(1, super::values::MAX_FRAMES))]
    pub frames: u64,
    /// Seed: the same seed gives the same stream.
    #[arg(long, default_value_t = 1, value_parser = super::values::seed())]
    pub seed: u64,
    /// Index of the first frame: a short stream from the middle of a scenario, where it shows
    /// what it is named for (the stream's times still start at 0).
    #[arg(long, default_value_t = 0, value_parser = super::values::whole_in::<u64>(0, super::values::MAX_FRAMES))]
    pub first: u64,
    /// Output stream (`.mcap`).
    #[arg(short, long, required_unless_present = "list", value_name = super::paths::OUT)]
    pub output: Option<PathBuf>,
    /// Ideal frames: no noise, vignetting or rolling shutter.
    #[arg(long)]
    pub ideal: bool,
    /// Byte order of the stored frames: `yuyv` (read by Foxglove and Rerun) or `uyvy`.
    #[arg(long, default_value = "yuyv")]
    pub image_encoding: ImageEncoding,
    /// List the scenarios and exit.
    #[arg(long)]
    pub list: bool,
    /// overhead-game: give robot N's world model a known error, `N:DX_CM,DY_CM,DHEADING_DEG` or
    /// `N:DX_CM,DY_CM,DHEADING_DEG,DISTANCE_PERCENT` (its `seen` distances that much too long),
    /// N the truth's robot number; repeatable. The robots' `seen` measurements are made from
    /// the truth with noise (the game renders no robot camera).
    #[arg(long, value_name = "N:DX,DY,DHEADING[,PERCENT]", value_parser = known_error)]
    pub world_model_error: Vec<crate::sim::KnownError>,
    /// overhead-game: scale of the world models' noise and drifting bias (0: the truth plus the
    /// known errors exactly).
    #[arg(long, default_value_t = 1.0, value_parser = super::values::number_in(0.0, 10.0))]
    pub world_model_noise: f64,
}

/// `N:DX,DY,DHEADING[,PERCENT]` of `--world-model-error`.
fn known_error(text: &str) -> Result<crate::sim::KnownError, String> {
    let usage = || format!("'{text}' is not N:DX_CM,DY_CM,DHEADING_DEG[,DISTANCE_PERCENT]");
    let (robot, rest) = text.split_once(':').ok_or_else(usage)?;
    let robot: u32 = robot.trim().parse().map_err(|_| usage())?;
    let values: Vec<f64> = rest
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| usage())?;
    let ([dx, dy, dh] | [dx, dy, dh, _]) = values[..] else {
        return Err(usage());
    };
    let percent = values.get(3).copied().unwrap_or(0.0);
    let ok = |v: f64, lo: f64, hi: f64| v.is_finite() && (lo..=hi).contains(&v);
    if !(ok(dx, -1000.0, 1000.0) && ok(dy, -1000.0, 1000.0)) {
        return Err(format!("{text}: offsets must be from -1000 to 1000 cm"));
    }
    if !ok(dh, -180.0, 180.0) || !ok(percent, -90.0, 900.0) {
        return Err(format!(
            "{text}: the heading error must be from -180 to 180 degrees, the distance error from -90 to 900 %"
        ));
    }
    Ok(crate::sim::KnownError {
        robot,
        offset_cm: [dx, dy],
        heading_rad: dh.to_radians(),
        distance_scale: 1.0 + percent / 100.0,
    })
}

/// The world-model options as given, for the stream's description.
fn world_model_options(args: &Args) -> String {
    let mut out = String::new();
    for k in &args.world_model_error {
        out += &format!(
            " --world-model-error {}:{},{},{},{}",
            k.robot,
            k.offset_cm[0],
            k.offset_cm[1],
            k.heading_rad.to_degrees(),
            (k.distance_scale - 1.0) * 100.0
        );
    }
    if args.world_model_noise != 1.0 {
        out += &format!(" --world-model-noise {}", args.world_model_noise);
    }
    out
}

/// Runs `eotn sim`.
///
/// # Errors
/// Unknown scenario, or the stream cannot be written (naming the file).
pub fn run(args: &Args) -> anyhow::Result<()> {
    if args.list {
        for k in ScenarioKind::ALL {
            outln!("{:<15} {}", k.name(), k.description());
        }
        return Ok(());
    }
    let name = args.scenario.as_deref().unwrap_or_default();
    let kind = ScenarioKind::from_name(name).with_context(|| {
        let known: Vec<&str> = ScenarioKind::ALL.iter().map(|k| k.name()).collect();
        format!("unknown scenario {name:?}; known: {}", known.join(", "))
    })?;
    let Some(path) = &args.output else {
        anyhow::bail!("--output is required");
    };
    if args.frames == 0 {
        anyhow::bail!("--frames must be at least 1: a stream without frames shows nothing");
    }
    let scenario = crate::sim::Scenario::new(kind, args.seed);
    let mut sim = Simulator::new(scenario);
    if args.ideal {
        sim = sim.with_effects(crate::sim::CameraEffects::NONE);
    }
    sim = sim.with_world_model_errors(crate::sim::WorldModelErrors {
        known: args.world_model_error.clone(),
        noise: args.world_model_noise,
    });
    let field = crate::overhead::FieldDescription::four_legged_2005();
    sim = sim.with_world_model_landmarks(
        field
            .landmarks
            .iter()
            .filter(|l| l.height_cm == 0.0)
            .map(|l| (l.name.clone(), l.field_cm))
            .collect(),
    );
    let info = StreamInfo {
        source: format!("sim:{}", kind.name()),
        description: format!(
            "eotn sim --scenario {} --frames {} --seed {}{}{}{}: {}",
            kind.name(),
            args.frames,
            args.seed,
            if args.first > 0 {
                format!(" --first {}", args.first)
            } else {
                String::new()
            },
            if args.ideal { " --ideal" } else { "" },
            world_model_options(args),
            kind.description()
        ),
    };
    let options = WriterOptions {
        image_encoding: args.image_encoding,
        ..WriterOptions::default()
    };
    let mut writer = StreamWriter::create_with(path, &info, options)?;
    let bar = progress(usize::try_from(args.frames).unwrap_or(usize::MAX), "sim");
    let mut render_s = 0.0;
    let mut size = (0, 0);
    let last = args
        .first
        .checked_add(args.frames)
        .context("--first + --frames is beyond the last frame index")?;
    let mut first_ns = None;
    for index in args.first..last {
        let start = Instant::now();
        let f = sim.frame(index)?;
        render_s += start.elapsed().as_secs_f64();
        size = (f.frame.width(), f.frame.height());
        // The stream starts at 0 like any recording, whichever frame it starts at.
        let first_ns = *first_ns.get_or_insert(f.time_ns);
        let mut record = FrameRecord::new(f.time_ns.saturating_sub(first_ns), f.frame);
        record.sensors = f.sensors;
        record.ground_truth = Some(
            serde_json::to_value(&f.ground_truth).context("ground truth is not serialisable")?,
        );
        record.extra = f.extra;
        writer.write(&record)?;
        bar.inc(1);
    }
    writer.finish()?;
    bar.finish_and_clear();
    let ms = 1000.0 * render_s / args.frames.max(1) as f64;
    eprintln!(
        "{}: {} frames of {}x{} ({}), {ms:.1} ms/frame to render",
        path.display(),
        args.frames,
        size.0,
        size.1,
        kind.name()
    );
    Ok(())
}
