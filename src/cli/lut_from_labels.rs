//! `eotn lut-from-labels`: a first lookup table from labelled frames, scored on held-back ones.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::inputs::{FrameInput, FrameInputs, parse_size, progress};
use crate::frame::Frame;
use crate::lut::ColourClass;
use crate::lut::learn::{Accuracy, LearnParams, TableBuilder};
use crate::sim::{Scenario, ScenarioKind, Simulator};

/// Arguments of `eotn lut-from-labels`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Labelled frames: each `NAME.uyvy`/`.png` needs a mask `NAME.cls` beside it (one class
    /// code per pixel, row-major, as `eotn classify --raw` writes), or `--boxes`. Folders are
    /// searched. Recordings too (MCAP streams, ROS 2 bags; the camera `--camera` names): frame
    /// N of `REC` is labelled by its index in `--boxes`, or by the mask `STEM_NNNNNN.cls`
    /// beside the recording (as `eotn classify --raw REC` names it).
    pub frames: Vec<PathBuf>,
    /// Which camera of the recordings.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
    /// Instead of masks: boxed labels (a YOLO folder, COCO JSON or Pascal VOC folder, as
    /// `eotn eval --labels`). The pixels within the ellipse inscribed in each ball box, shrunk
    /// to `--ball-core` of its size, vote orange; every other pixel votes "no colour", so a cell
    /// becomes orange only where ball pixels outnumber the rest (`--min-purity`).
    #[arg(long, value_name = "LABELS")]
    pub boxes: Option<PathBuf>,
    /// With `--boxes`: the share of a ball box's width and height whose inscribed ellipse votes
    /// orange (the rim mixes ball and background).
    #[arg(long, default_value_t = 0.7, value_parser = super::values::number_in(0.05, 1.0))]
    pub ball_core: f64,
    /// With `--boxes`: YOLO class names in order of their numbers.
    #[arg(long, value_name = "NAMES")]
    pub class_names: Option<String>,
    /// With `--boxes`: which frames to learn from (`tuning`: frames whose number ends in 0–6;
    /// the held-out ones, 7–9, are never looked at).
    #[arg(long, value_enum, default_value_t = crate::eval::label_sets::Split::Tuning)]
    pub split: crate::eval::label_sets::Split,
    /// Also (or instead) render labelled frames of these scenarios (repeatable).
    #[arg(long = "sim")]
    pub scenarios: Vec<String>,
    /// Frames rendered per scenario.
    #[arg(long, default_value_t = 60, value_parser = super::values::whole_in::<u64>(1, 100_000))]
    pub frames_per_scenario: u64,
    /// Seed for rendered frames.
    #[arg(long, default_value_t = 1, value_parser = super::values::seed())]
    pub seed: u64,
    /// Hold back every Kth frame (from building) to score the table on.
    #[arg(long, default_value_t = 4, value_parser = super::values::whole_in::<u64>(2, 1_000_000))]
    pub holdout_every: u64,
    /// Table resolution, bits per channel (6, 7 or 8).
    #[arg(long, default_value_t = 7, value_parser = super::values::whole_in::<u8>(6, 8))]
    pub bits: u8,
    /// Cells each class grows into unseen neighbouring colours.
    #[arg(long, default_value_t = 2, value_parser = super::values::whole_in::<usize>(0, 64))]
    pub margin: usize,
    /// Fewest labelled pixels of the winning class for a cell to take it.
    #[arg(long, default_value_t = 2, value_parser = super::values::whole_in::<u32>(1, super::values::MAX_PIXELS))]
    pub min_pixels: u32,
    /// Smallest share of a cell's pixels the winning class needs (0..1).
    #[arg(long, default_value_t = 0.6, value_parser = super::values::number_in(0.0, 1.0))]
    pub min_purity: f64,
    /// Frame size of raw files, WxH; 208x160 and 640x480 are inferred.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// Where to write the table (`.lut`).
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: PathBuf,
    /// Print the accuracy as one JSON line.
    #[arg(long)]
    pub json: bool,
}

/// The label mask of a frame: `NAME.cls` beside `NAME.uyvy`, or `NAME.uyvy.cls` as
/// `eotn classify --raw` writes it.
fn load_mask(frame_path: &Path, frame: &Frame) -> anyhow::Result<Vec<u8>> {
    let mut beside = frame_path.as_os_str().to_owned();
    beside.push(".cls");
    let beside = std::path::PathBuf::from(beside);
    let mask = if beside.exists() {
        beside
    } else {
        frame_path.with_extension("cls")
    };
    let max = crate::frame::MAX_FRAME_PIXELS;
    let bytes = crate::input_file::read_bounded(&mask, max, "a label mask")
        .with_context(|| format!("{}: cannot read label mask", mask.display()))?;
    let pixels = frame.width() * frame.height();
    anyhow::ensure!(
        bytes.len() == pixels,
        "{}: {} bytes, but {} has {pixels} pixels",
        mask.display(),
        bytes.len(),
        frame_path.display()
    );
    Ok(bytes)
}

/// Runs `eotn lut-from-labels`.
///
/// # Errors
/// Unreadable frames or masks, unknown scenarios, an unwritable table, or no labelled frames.
pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.min_purity.is_finite() && (0.0..=1.0).contains(&args.min_purity),
        "--min-purity must be between 0 and 1"
    );
    let params = LearnParams {
        bits: args.bits,
        margin_cells: args.margin,
        min_pixels: args.min_pixels,
        min_purity: args.min_purity,
    };
    let mut training = Training {
        builder: TableBuilder::new(args.bits)?,
        held_back: Vec::new(),
        taken: 0,
        holdout_every: args.holdout_every,
    };
    gather_labelled_frames(args, &mut training)?;
    let Training {
        builder, held_back, ..
    } = training;
    anyhow::ensure!(
        builder.pixel_count() > 0,
        "no labelled frames to build from (give frames with .cls masks, or --sim SCENARIO)"
    );
    let table = builder.build(&params);
    table
        .save(&args.output)
        .with_context(|| format!("{}: cannot save the table", args.output.display()))?;
    let mut accuracy = Accuracy::default();
    for (name, frame, labels) in &held_back {
        accuracy
            .add_frame(frame, labels, &table)
            .with_context(|| format!("{name}: labels"))?;
    }
    print_report(args, &builder, held_back.len(), &accuracy);
    Ok(())
}

/// Labelled frames as they come: every `holdout_every`-th is held back to score the table, the
/// others go into it.
struct Training {
    builder: TableBuilder,
    held_back: Vec<(String, Frame, Vec<u8>)>,
    /// Frames taken so far.
    taken: u64,
    holdout_every: u64,
}

impl Training {
    fn take(&mut self, name: String, frame: Frame, labels: Vec<u8>) -> anyhow::Result<()> {
        self.taken += 1;
        if self.taken.is_multiple_of(self.holdout_every) {
            self.held_back.push((name, frame, labels));
        } else {
            self.builder
                .add_frame(&frame, &labels)
                .with_context(|| format!("{name}: labels"))?;
        }
        Ok(())
    }
}

/// The frames with their `.cls` masks (or `--boxes`), then `--frames-per-scenario` frames of
/// each scenario with the simulator's labels.
fn gather_labelled_frames(args: &Args, training: &mut Training) -> anyhow::Result<()> {
    let mut inputs = if args.frames.is_empty() {
        None
    } else {
        Some(FrameInputs::open_camera(
            &args.frames,
            None,
            args.camera.get(),
        )?)
    };
    let boxes = match &args.boxes {
        Some(p) => Some(crate::eval::label_sets::LabelSet::load(
            p,
            &crate::eval::label_sets::ReadOptions {
                class_names: args
                    .class_names
                    .as_ref()
                    .map(|t| t.split(',').map(|n| n.trim().to_owned()).collect()),
                ..Default::default()
            },
        )?),
        None => None,
    };
    for i in 0..inputs.as_ref().map_or(0, FrameInputs::len) {
        let Some(inputs) = inputs.as_mut() else {
            break;
        };
        let input = inputs.items()[i].clone();
        let name = match &input {
            FrameInput::File(p) => p.display().to_string(),
            FrameInput::Stream { path, index } => format!("{} frame {index}", path.display()),
        };
        let (frame, mask) = match &boxes {
            Some(set) => {
                let stem = super::eval_boxes::label_name(&input);
                let key = match &input {
                    FrameInput::File(_) => {
                        Some(stem.clone()).filter(|k| set.frames.contains_key(k))
                    }
                    FrameInput::Stream { .. } => super::eval_boxes::stream_key(set, &stem),
                };
                let Some(key) = key.filter(|_| args.split.takes(&stem)) else {
                    continue;
                };
                let frame = inputs.load(i, args.size)?;
                let mask = box_mask(set, &key, &frame, args.ball_core);
                (frame, mask)
            }
            None => {
                let frame = inputs.load(i, args.size)?;
                let mask = load_mask(&mask_path(&input), &frame)?;
                (frame, mask)
            }
        };
        training.take(name, frame, mask)?;
    }
    for name in &args.scenarios {
        let kind =
            ScenarioKind::from_name(name).with_context(|| format!("unknown scenario {name:?}"))?;
        let sim = Simulator::new(Scenario::new(kind, args.seed));
        let bar = progress(
            usize::try_from(args.frames_per_scenario).unwrap_or(usize::MAX),
            name,
        );
        for k in 0..args.frames_per_scenario {
            let f = sim.frame(k)?;
            training.take(format!("{name}#{k}"), f.frame, f.labels)?;
            bar.inc(1);
        }
        bar.finish_and_clear();
    }
    Ok(())
}

/// Where a frame's label mask is looked for: beside a frame file (see [`load_mask`]); for frame
/// N of a recording, `STEM_NNNNNN.cls` beside the recording ([`FrameInput::name`]).
fn mask_path(input: &FrameInput) -> PathBuf {
    match input {
        FrameInput::File(p) => p.clone(),
        FrameInput::Stream { path, .. } => {
            let folder = path.parent().unwrap_or(Path::new(""));
            folder.join(input.name())
        }
    }
}

/// A label mask from boxes: orange within the ellipse inscribed in each ball box shrunk to
/// `core` of its size (pixel centres at +0.5), no colour (code 0) everywhere else.
fn box_mask(
    set: &crate::eval::label_sets::LabelSet,
    stem: &str,
    frame: &Frame,
    core: f64,
) -> Vec<u8> {
    let (w, h) = (frame.width(), frame.height());
    let mut mask = vec![0u8; w * h];
    let Some(labels) = set.frame_in_pixels(stem, w, h) else {
        return mask;
    };
    for b in labels.balls() {
        let [cx, cy] = b.centre();
        let (rx, ry) = (core * b.width() / 2.0, core * b.height() / 2.0);
        let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n);
        for y in clamp(cy - ry, h)..clamp(cy + ry + 1.0, h) {
            for x in clamp(cx - rx, w)..clamp(cx + rx + 1.0, w) {
                let (dx, dy) = ((x as f64 + 0.5 - cx) / rx, (y as f64 + 0.5 - cy) / ry);
                if dx * dx + dy * dy <= 1.0 {
                    mask[y * w + x] = ColourClass::Orange.code();
                }
            }
        }
    }
    mask
}

/// The table written and its scores on the held-back frames, as text or `--json`.
fn print_report(args: &Args, builder: &TableBuilder, held_back: usize, accuracy: &Accuracy) {
    let recalls: Vec<(String, f64)> = ColourClass::ALL
        .iter()
        .filter_map(|&c| {
            (c != ColourClass::Unclassified)
                .then(|| accuracy.recall(c).map(|r| (c.name().to_owned(), r)))
                .flatten()
        })
        .collect();
    if args.json {
        let per_class: serde_json::Map<String, serde_json::Value> = recalls
            .iter()
            .map(|(n, r)| (n.clone(), serde_json::json!(r)))
            .collect();
        outln!(
            "{}",
            serde_json::json!({
                "table": args.output.display().to_string(),
                "bits": args.bits,
                "training_pixels": builder.pixel_count(),
                "cells_seen": builder.cells_seen(),
                "held_back_frames": held_back,
                "colour_accuracy": accuracy.colour_accuracy(),
                "false_colour_rate": accuracy.false_colour_rate(),
                "recall": per_class,
            })
        );
    } else {
        outln!(
            "{}: {}-bit table from {} labelled pixels ({} cells seen)",
            args.output.display(),
            args.bits,
            builder.pixel_count(),
            builder.cells_seen()
        );
        outln!(
            "held back {held_back} frames: colour accuracy {:.2}%, false colour on unlabelled pixels {:.2}%",
            100.0 * accuracy.colour_accuracy(),
            100.0 * accuracy.false_colour_rate()
        );
        for (name, r) in &recalls {
            outln!("  {name:<12} {:.2}%", 100.0 * r);
        }
    }
}
