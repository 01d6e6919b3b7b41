//! `eotn eval IMAGES --labels YOLO_FOLDER|COCO.json|VOC_FOLDER`: recognition on labelled frames
//! (a folder of images, or a stream) scored against boxes as teams keep them
//! (`crate::eval::label_sets`, `crate::eval::ball_boxes`): frame recall, precision, centre
//! error, recall by ball size, the missed and false frames by name; `--split` scores the tuning
//! or the held-out frames alone.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use serde::Serialize;

use super::inputs::{FrameInput, FrameInputs};
use super::pct;
use crate::eval::ball_boxes::{BoxFrameEval, BoxReport, BoxScoring, evaluate_box_frame};
use crate::eval::label_sets::{ClassMap, LabelFormat, LabelSet, ReadOptions, Split, file_stem};
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::RecognitionParams;

/// What `eotn eval` needs to score boxed labels.
pub struct BoxEvalArgs<'a> {
    /// Frames: image files, folders, streams.
    pub images: &'a [PathBuf],
    /// The label set.
    pub labels: &'a Path,
    /// `--class-names`: YOLO class names by number.
    pub class_names: Option<&'a str>,
    /// `--classes`: class name → object.
    pub classes: Option<&'a str>,
    /// Which frames to score.
    pub split: Split,
    /// `--plots`: the charts' folder.
    pub plots: Option<&'a Path>,
    /// One JSON object instead of text.
    pub json: bool,
}

/// Everything the box evaluation reports.
#[derive(Debug, Clone, Serialize)]
pub struct BoxEvalOutput {
    /// The label set's format.
    pub format: LabelFormat,
    /// The frames scored.
    pub split: Split,
    /// The scoring rule.
    pub scoring: BoxScoring,
    /// The sums.
    pub report: BoxReport,
    /// Every scored frame.
    pub frames: Vec<BoxFrameEval>,
    /// Frames of the split without labels (not scored), by name.
    pub unlabelled_frames: Vec<String>,
    /// Labelled frames of the split that no image matched.
    pub labels_without_frame: Vec<String>,
    /// Charts written by `--plots`.
    pub plots: Vec<PathBuf>,
    /// Decoding and recognising the scored frames, seconds (wall clock, this run).
    pub seconds: f64,
}

/// The name a frame is known by in a label set: a file's stem, or a stream frame's index.
pub(super) fn label_name(input: &FrameInput) -> String {
    match input {
        FrameInput::File(p) => file_stem(p),
        FrameInput::Stream { index, .. } => index.to_string(),
    }
}

/// The labels of a stream frame: its index may be written with leading zeros (`00042`).
pub(super) fn stream_key(set: &LabelSet, name: &str) -> Option<String> {
    if set.frames.contains_key(name) {
        return Some(name.to_owned());
    }
    let index: usize = name.parse().ok()?;
    set.frames
        .keys()
        .find(|k| k.parse::<usize>().ok() == Some(index))
        .cloned()
}

/// How the set is read: `--classes` and `--class-names`.
fn read_options(args: &BoxEvalArgs<'_>) -> anyhow::Result<ReadOptions> {
    Ok(ReadOptions {
        classes: args
            .classes
            .map(ClassMap::parse)
            .transpose()
            .context("--classes")?
            .unwrap_or_default(),
        class_names: args
            .class_names
            .map(|t| t.split(',').map(|n| n.trim().to_owned()).collect()),
    })
}

/// Reads the set, runs the pipeline over the split's frames and reports.
///
/// # Errors
/// Unreadable labels or frames, labels made on another frame size, no labelled frame in the
/// split, unwritable charts.
pub fn run(
    args: &BoxEvalArgs<'_>,
    lut: crate::lut::LookupTable,
    params: RecognitionParams,
) -> anyhow::Result<()> {
    let set = LabelSet::load(args.labels, &read_options(args)?)?;
    for w in &set.warnings {
        log::warn!("{w}");
    }
    let mut inputs = FrameInputs::open(args.images, None)?;
    let mut pipeline = Pipeline::new(
        lut,
        PipelineParams {
            recognition: params,
            ..PipelineParams::default()
        },
    );
    let scoring = BoxScoring::default();
    let (mut frames, mut unlabelled, mut matched) = (Vec::new(), Vec::new(), Vec::new());
    let started = Instant::now();
    let bar = super::inputs::progress(inputs.len(), "eval");
    for i in 0..inputs.len() {
        bar.inc(1);
        let name = label_name(&inputs.items()[i]);
        if !args.split.takes(&name) {
            continue;
        }
        let Some(key) = stream_key(&set, &name) else {
            unlabelled.push(name);
            continue;
        };
        let (frame, sensors) = inputs.load_with_sensors(i, None)?;
        let (w, h) = (frame.width(), frame.height());
        let Some(labels) = set.frame_in_pixels(&key, w, h) else {
            continue;
        };
        if let Some((lw, lh)) = labels.size
            && (lw, lh) != (w, h)
        {
            bail!(
                "{}: frame {key:?} is labelled as {lw}×{lh}, but {} is {w}×{h}",
                args.labels.display(),
                inputs.name(i)
            );
        }
        let result = pipeline.process(&frame, sensors.as_ref());
        frames.push(evaluate_box_frame(
            &name,
            result.recognition,
            &labels,
            &scoring,
        ));
        matched.push(key);
    }
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    if frames.is_empty() {
        bail!(
            "{}: no frame of the {} split is labelled",
            args.labels.display(),
            split_name(args.split)
        );
    }
    let labels_without_frame: Vec<String> = set
        .frames
        .keys()
        .filter(|k| args.split.takes(k) && !matched.contains(k))
        .cloned()
        .collect();
    let plots = match args.plots {
        Some(dir) => crate::eval::plots::write_box_plots(dir, &frames).context("plots")?,
        None => Vec::new(),
    };
    let output = BoxEvalOutput {
        format: set.format,
        split: args.split,
        scoring,
        report: BoxReport::from_frames(&frames),
        frames,
        unlabelled_frames: unlabelled,
        labels_without_frame,
        plots,
        seconds,
    };
    if args.json {
        outln!("{}", serde_json::to_string(&output)?);
    } else {
        print_summary(&output);
    }
    Ok(())
}

pub(crate) fn split_name(s: Split) -> &'static str {
    match s {
        Split::All => "whole",
        Split::Tuning => "tuning",
        Split::HeldOut => "held-out",
    }
}

fn print_summary(o: &BoxEvalOutput) {
    let r = &o.report;
    outln!(
        "labelled frames        {} ({} split, {:?} labels; {} with a ball, {} ball boxes)",
        r.frames,
        split_name(o.split),
        o.format,
        r.frames_with_ball,
        r.balls_labelled
    );
    outln!(
        "frame recall           {}/{} eligible frames = {} (a ball box ≥ {} px; centre in a ball box grown {} px)",
        r.found,
        r.eligible,
        pct(r.recall),
        o.scoring.min_side_px,
        o.scoring.grow_px
    );
    outln!(
        "precision              {}/{} reported balls = {}; false: {} in robots, {} in goals, {} in other boxes, {} elsewhere",
        r.correct,
        r.reported,
        pct(r.precision),
        r.false_in_robot,
        r.false_in_goal,
        r.false_in_other,
        r.false_elsewhere
    );
    if let Some(p) = &r.centre_error {
        outln!(
            "centre error           median {:.3} p90 {:.3} of the box's larger side (n={})",
            p.p50,
            p.p90,
            p.n
        );
    }
    for b in &r.by_size {
        let band = b.to_px.map_or_else(
            || format!("≥ {} px", b.from_px),
            |t| format!("{}–{} px", b.from_px, t),
        );
        outln!(
            "  ball {band:<12}    {}/{} = {}",
            b.found,
            b.eligible,
            pct(b.recall)
        );
    }
    if !r.missed_frames.is_empty() {
        outln!("missed frames          {}", r.missed_frames.join(" "));
    }
    if !r.false_frames.is_empty() {
        outln!("false-ball frames      {}", r.false_frames.join(" "));
    }
    if !o.unlabelled_frames.is_empty() {
        outln!("unlabelled frames      {}", o.unlabelled_frames.len());
    }
    if !o.labels_without_frame.is_empty() {
        outln!(
            "labels without frame   {}",
            o.labels_without_frame.join(" ")
        );
    }
    if !o.plots.is_empty() {
        outln!("plots                  {} written", o.plots.len());
    }
    outln!(
        "time                   {:.2} s for {} frames ({:.2} ms a frame: decode, classify, recognise)",
        o.seconds,
        r.frames,
        1000.0 * o.seconds / r.frames as f64
    );
}
