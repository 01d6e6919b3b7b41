//! `eotn eval STREAM --labels FILE`: recognition on a real stream scored against hand labels
//! (`crate::eval::labels`): ball found / missed / false counts and rates, centre and radius
//! error percentiles, the frames that missed or saw a false ball, goals found and false, and
//! each found goal's size-based distance beside the distance of its foot through the camera
//! pose (the two agree when the goal model fits the field).

use std::path::Path;

use anyhow::{Context, bail};
use serde::Serialize;

use super::pct;
use crate::eval::label_sets::Split;
use crate::eval::labels::{LabelledFrameEval, Labels, LabelsReport, evaluate_labelled_frame};
use crate::eval::{EvalParams, Percentiles, percentile_text, sample_size};
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::RecognitionParams;
use crate::streams::StreamReader;

/// A found goal's two distances: from its size and from its foot on the ground.
#[derive(Debug, Clone, Serialize)]
pub struct GoalDistances {
    /// Frame index.
    pub frame: usize,
    /// The distance recognition reports (size-based unless top or bottom is cut), cm.
    pub distance_cm: f64,
    /// The distance of the goal's foot (the middle of its bottom edge) on the ground through
    /// the camera pose, cm; `None` without a pose or with the bottom cut off.
    pub foot_distance_cm: Option<f64>,
    /// Whether the top or bottom is cut off (the reported distance is then a maximum or the
    /// foot's).
    pub cut_top_or_bottom: bool,
}

/// Everything `eotn eval --labels` reports.
#[derive(Debug, Clone, Serialize)]
pub struct LabelsOutput {
    /// Which frames were scored (`all`, `tuning`, `held-out`).
    pub split: Split,
    /// The sums.
    pub report: LabelsReport,
    /// Found goals with both ends in the image: size-based / foot distance, percentiles.
    pub goal_size_over_foot: Option<Percentiles>,
    /// Every found goal's distances.
    pub goal_distances: Vec<GoalDistances>,
    /// Every labelled frame.
    pub frames: Vec<LabelledFrameEval>,
    /// Stream frames without a label, and labels without a frame.
    pub unlabelled_frames: Vec<usize>,
    /// Labels of frames the stream does not have.
    pub labels_beyond_stream: Vec<usize>,
}

/// Runs the labels evaluation of one stream.
///
/// # Errors
/// Unreadable stream or labels, labels made on another frame size, or no labelled frame.
pub fn run(
    stream: &Path,
    camera: Option<&str>,
    labels_path: &Path,
    lut: crate::lut::LookupTable,
    params: RecognitionParams,
    split: Split,
    json: bool,
) -> anyhow::Result<()> {
    let labels = Labels::load(labels_path)?;
    let mut reader = StreamReader::open_camera(stream, camera)?;
    let mut pipeline = Pipeline::new(
        lut,
        PipelineParams {
            recognition: params,
            ..PipelineParams::default()
        },
    );
    let ep = EvalParams::default();
    let mut frames = Vec::new();
    let mut unlabelled = Vec::new();
    let mut goal_distances = Vec::new();
    let bar = super::inputs::progress(reader.len(), "eval");
    for i in 0..reader.len() {
        bar.inc(1);
        if !split.takes(&i.to_string()) {
            continue;
        }
        let Some(label) = labels.frame(i) else {
            unlabelled.push(i);
            continue;
        };
        let record = reader
            .read(i)
            .with_context(|| format!("{}: frame {i}", stream.display()))?;
        let (w, h) = (record.frame.width(), record.frame.height());
        if let (Some(lw), Some(lh)) = (labels.width, labels.height)
            && (lw, lh) != (w, h)
        {
            bail!(
                "{}: labels are for {lw}×{lh} frames, frame {i} of {} is {w}×{h}",
                labels_path.display(),
                stream.display()
            );
        }
        let sensors = record.sensors.as_ref();
        let ctx = params.context_for(w, h, sensors);
        let result = pipeline.process(&record.frame, sensors);
        let r = &result.recognition;
        goal_distances.extend(goal_distances_of(i, r, &ctx));
        frames.push(evaluate_labelled_frame(r, label, w as f64, h as f64, &ep));
    }
    bar.finish_and_clear();
    let labels_beyond_stream: Vec<usize> = labels
        .frames
        .iter()
        .map(|f| f.frame)
        .filter(|f| *f >= reader.len())
        .collect();
    if frames.is_empty() {
        bail!(
            "{}: no frame of {} in the {} split is labelled",
            labels_path.display(),
            stream.display(),
            super::eval_boxes::split_name(split)
        );
    }
    let ratios: Vec<f64> = goal_distances
        .iter()
        .filter(|g| !g.cut_top_or_bottom)
        .filter_map(|g| g.foot_distance_cm.map(|f| g.distance_cm / f))
        .collect();
    let output = LabelsOutput {
        split,
        report: LabelsReport::from_frames(&frames),
        goal_size_over_foot: Percentiles::of(&ratios),
        goal_distances,
        frames,
        unlabelled_frames: unlabelled,
        labels_beyond_stream,
    };
    if json {
        outln!("{}", serde_json::to_string(&output)?);
    } else {
        print_summary(&output);
    }
    Ok(())
}

/// Each goal of a frame's recognition with its size-based distance and its foot's.
fn goal_distances_of(
    frame: usize,
    r: &crate::recognition::Recognition,
    ctx: &crate::recognition::ViewContext,
) -> Vec<GoalDistances> {
    r.goals
        .goals()
        .map(|g| {
            let bottom = crate::geometry::ImagePoint::new(
                (g.level_extent[0] + g.level_extent[2]) / 2.0,
                g.level_extent[3],
            );
            let foot = bottom.rotated_about(ctx.camera.centre, -ctx.horizon_angle());
            GoalDistances {
                frame,
                distance_cm: g.camera.distance_cm,
                foot_distance_cm: (!g.cut_off.bottom)
                    .then(|| ctx.distance_to_plane(foot, 0.0))
                    .flatten(),
                cut_top_or_bottom: g.cut_off.top || g.cut_off.bottom,
            }
        })
        .collect()
}

fn print_summary(o: &LabelsOutput) {
    let r = &o.report;
    outln!(
        "labelled frames        {} ({} split)",
        r.frames,
        super::eval_boxes::split_name(o.split)
    );
    outln!(
        "ball found             {}/{} labelled visible = {}; cut by the image edge {}/{}; \
         ≥ 60% in view and ≥ 6 px {}/{}",
        r.ball_found,
        r.ball_visible,
        pct(r.ball_found_rate),
        r.ball_cut_found,
        r.ball_cut,
        r.ball_eligible_found,
        r.ball_eligible
    );
    outln!(
        "false ball             {} of {} frames = {} ({} frames without a ball)",
        r.ball_false,
        r.frames,
        pct(r.ball_false_rate),
        r.ball_absent
    );
    let q = |p: &Option<Percentiles>, pick: fn(&Percentiles) -> f64| {
        percentile_text(p.as_ref(), pick, 1.0, 2, " px")
    };
    outln!(
        "ball centre error      median {} p90 {} (n={}); cut: median {} (n={})",
        q(&r.ball_center_error_px, |p| p.p50),
        q(&r.ball_center_error_px, |p| p.p90),
        sample_size(r.ball_center_error_px.as_ref()),
        q(&r.ball_center_error_cut_px, |p| p.p50),
        sample_size(r.ball_center_error_cut_px.as_ref())
    );
    outln!(
        "ball radius error      median {} p90 {}, signed median {}; cut: median {}",
        q(&r.ball_radius_error_px, |p| p.p50),
        q(&r.ball_radius_error_px, |p| p.p90),
        r.ball_radius_bias_px
            .map_or_else(|| "—".to_owned(), |b| format!("{b:+.2} px")),
        q(&r.ball_radius_error_cut_px, |p| p.p50)
    );
    if !r.ball_missed_frames.is_empty() {
        outln!("ball missed in frames  {:?}", r.ball_missed_frames);
    }
    if !r.ball_near_frames.is_empty() {
        outln!("  of those, near       {:?}", r.ball_near_frames);
    }
    if !r.ball_false_frames.is_empty() {
        outln!("false ball in frames   {:?}", r.ball_false_frames);
    }
    if r.goal_frames > 0 {
        outln!(
            "goals found            {}/{} = {}, false {} (in {} frames with goals labelled)",
            r.goals_found,
            r.goals_visible,
            pct(r.goal_found_rate),
            r.goals_false,
            r.goal_frames
        );
        if !r.goal_missed_frames.is_empty() {
            outln!("goal missed in frames  {:?}", r.goal_missed_frames);
        }
        if !r.goal_false_frames.is_empty() {
            outln!("false goal in frames   {:?}", r.goal_false_frames);
        }
    }
    if let Some(g) = &o.goal_size_over_foot {
        outln!(
            "goal distance          size / foot on the ground: median {:.2}, p90 {:.2} (n={})",
            g.p50,
            g.p90,
            g.n
        );
    }
    if !o.unlabelled_frames.is_empty() {
        outln!("unlabelled frames      {}", o.unlabelled_frames.len());
    }
    if !o.labels_beyond_stream.is_empty() {
        outln!(
            "labels beyond the stream's {} frames: {:?}",
            r.frames + o.unlabelled_frames.len(),
            o.labels_beyond_stream
        );
    }
}
