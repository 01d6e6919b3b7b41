//! `eotn patterns`: the coloured-pattern recogniser's learning phase and its places files.
//!
//! `eotn patterns learn` runs the pipeline over streams or frames, takes the robot's field pose
//! for each frame from (in this order) a `--poses` table, a typed `--pose`, the stream's
//! `/robot_pose` channel or the `/ground_truth` of a simulated stream, and learns the places
//! the pink markers show (`recognition::patterns`: bearing-only triangulation, then the
//! size → distance relation). The places file is written atomically. `eotn patterns show`
//! prints one.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::{Deserialize, Serialize};

use super::detect::{load_sensor_file, readings_for};
use super::inputs::{FrameInput, InputArgs, load_frame_arg, progress};
use crate::geometry::RobotPose;
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::patterns::{LearnParams, LearnReport, LearnView, PatternMemory, Placement};
use crate::streams::StreamReader;

/// Arguments of `eotn patterns`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// What to do.
    #[command(subcommand)]
    pub command: PatternsCommand,
}

/// The `eotn patterns` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum PatternsCommand {
    /// Learn places from the pink markers of streams or frames and the robot's poses; write a
    /// places file for `eotn detect --patterns`.
    Learn(Box<LearnArgs>),
    /// Print a places file: objects, patterns, the size → distance relation.
    Show(ShowArgs),
}

/// Arguments of `eotn patterns learn`.
#[derive(Debug, clap::Args)]
pub struct LearnArgs {
    /// Frames, table and raw frame size.
    #[command(flatten)]
    pub input: InputArgs,
    /// Robot poses per frame: CSV with the header `frame,x_cm,y_cm,heading_rad`, or JSON (an
    /// array of objects with those keys). `frame` counts every input frame in order from 0
    /// (for one stream: its frame index). Frames without a row are skipped.
    #[arg(long)]
    pub poses: Option<PathBuf>,
    /// A typed robot pose `X_CM,Y_CM,HEADING_RAD` for every frame of one input (repeat it once
    /// per input file or stream, in order; given once, it applies to all): a robot standing
    /// still at a known spot.
    #[arg(long, value_parser = parse_pose, allow_hyphen_values = true)]
    pub pose: Vec<RobotPose>,
    /// Sensor readings JSON for raw frames (as for `eotn detect`); streams carry their own.
    #[arg(long)]
    pub sensors: Option<PathBuf>,
    /// Recognition parameters JSON (the `patterns` part sets min_pixels, min_agreement, …) (default: the set the first recording names for the camera read, else the defaults).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Start from this places file and add to it (it may be the output).
    #[arg(long, value_name = super::paths::UPDATED)]
    pub update: Option<PathBuf>,
    /// A place placed within this distance of a known object adds its pattern to it, cm.
    #[arg(long, default_value_t = LearnParams::default().same_object_cm, value_parser = super::values::number_in(0.0, 10_000.0))]
    pub same_object_cm: f64,
    /// Views a marker needs to be learnt.
    #[arg(long, default_value_t = LearnParams::default().min_views, value_parser = super::values::whole_in::<usize>(1, 100_000))]
    pub min_views: usize,
    /// Smallest spread of bearings for triangulation, degrees.
    #[arg(long, default_value_t = LearnParams::default().min_spread_deg, value_parser = super::values::number_in(0.0, 180.0))]
    pub min_spread_deg: f64,
    /// Rays passing farther than this from a triangulated marker are outliers, cm.
    #[arg(long, default_value_t = LearnParams::default().outlier_cm, value_parser = super::values::number_in(0.0, 10_000.0))]
    pub outlier_cm: f64,
    /// The places file to write.
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: PathBuf,
    /// Print what was learnt as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `eotn patterns show`.
#[derive(Debug, clap::Args)]
pub struct ShowArgs {
    /// A places file.
    pub places: PathBuf,
    /// Print it as JSON (checked, normalised).
    #[arg(long)]
    pub json: bool,
}

/// Parses `X,Y,HEADING` (centimetres, centimetres, radians).
///
/// # Errors
/// A message for anything but three finite numbers.
pub fn parse_pose(text: &str) -> anyhow::Result<RobotPose> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("'{text}' is not X_CM,Y_CM,HEADING_RAD"))?;
    match v.as_slice() {
        [x, y, h] if v.iter().all(|a| a.is_finite()) => Ok(RobotPose::new(*x, *y, *h)),
        _ => bail!("'{text}' is not three numbers X_CM,Y_CM,HEADING_RAD"),
    }
}

/// One row of a pose table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseRow {
    /// Frame index across the inputs.
    pub frame: usize,
    /// Field x, centimetres.
    pub x_cm: f64,
    /// Field y, centimetres.
    pub y_cm: f64,
    /// Heading, radians counter-clockwise from field +x.
    pub heading_rad: f64,
}

/// Reads a pose table (`.json`: an array of rows; anything else: CSV with a header row).
///
/// # Errors
/// Unreadable file, a row that is not four numbers, an unknown column, a non-finite value or a
/// frame given twice, naming the file (and the line for CSV).
pub fn load_pose_table(path: &Path) -> anyhow::Result<HashMap<usize, RobotPose>> {
    let text = crate::input_file::read_text_bounded(
        path,
        crate::input_file::MAX_SIDE_FILE_BYTES,
        "a pose table",
    )
    .with_context(|| format!("{}: cannot read", path.display()))?;
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let rows: Vec<(usize, PoseRow)> = if is_json {
        let rows: Vec<PoseRow> = serde_json::from_str(&text).with_context(|| {
            format!(
                "{}: not a pose table (an array of {{frame, x_cm, y_cm, heading_rad}})",
                path.display()
            )
        })?;
        rows.into_iter().enumerate().collect()
    } else {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let headers = reader
            .headers()
            .with_context(|| format!("{}: no header row", path.display()))?
            .clone();
        for h in &headers {
            if !["frame", "x_cm", "y_cm", "heading_rad"].contains(&h) {
                bail!(
                    "{}: unknown column {h:?} (a pose table has frame, x_cm, y_cm, heading_rad)",
                    path.display()
                );
            }
        }
        let mut rows = Vec::new();
        for (i, r) in reader.deserialize::<PoseRow>().enumerate() {
            let row = r.with_context(|| format!("{}: line {}", path.display(), i + 2))?;
            rows.push((i + 2, row));
        }
        rows
    };
    let mut out = HashMap::new();
    for (line, r) in rows {
        if ![r.x_cm, r.y_cm, r.heading_rad]
            .iter()
            .all(|v| v.is_finite())
        {
            bail!("{}: row {line}: a pose is not a number", path.display());
        }
        if out
            .insert(r.frame, RobotPose::new(r.x_cm, r.y_cm, r.heading_rad))
            .is_some()
        {
            bail!("{}: frame {} has two poses", path.display(), r.frame);
        }
    }
    Ok(out)
}

/// Where the robot poses of a learning run came from, counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct PoseSources {
    /// From `--poses`.
    pub table: usize,
    /// From `--pose`.
    pub typed: usize,
    /// From the stream's `/robot_pose` channel.
    pub robot_pose_channel: usize,
    /// From the stream's `/ground_truth` (a simulator's truth).
    pub ground_truth: usize,
    /// Frames without a pose (skipped).
    pub none: usize,
}

/// What `eotn patterns learn --json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct LearnOutput {
    /// Frames read.
    pub frames: usize,
    /// Where their poses came from.
    pub poses: PoseSources,
    /// What learning did.
    pub report: LearnReport,
    /// The memory as written.
    pub places: PatternMemory,
    /// The file written.
    pub output: PathBuf,
}

/// A frame's robot pose from a stream record: the `/robot_pose` channel, else the ground
/// truth's `robot_pose`.
fn recorded_pose(
    (truth, extra): &RecordedChannels,
    sources: &mut PoseSources,
) -> Option<RobotPose> {
    if let Some(p) = extra
        .iter()
        .find(|(t, _)| t == "/robot_pose")
        .and_then(|(_, v)| serde_json::from_value::<RobotPose>(v.clone()).ok())
        .filter(|p| {
            [p.x_cm, p.y_cm, p.heading_rad]
                .iter()
                .all(|v| v.is_finite())
        })
    {
        sources.robot_pose_channel += 1;
        return Some(p);
    }
    let p = truth
        .as_ref()
        .and_then(|t| t.get("robot_pose"))
        .and_then(|v| serde_json::from_value::<RobotPose>(v.clone()).ok())?;
    sources.ground_truth += 1;
    Some(p)
}

/// Runs the learning phase.
///
/// # Errors
/// Unreadable inputs, pose tables or places files, an unwritable output.
pub fn learn(args: &LearnArgs) -> anyhow::Result<LearnOutput> {
    let (lut, inputs) = args.input.open()?;
    let table = args.poses.as_deref().map(load_pose_table).transpose()?;
    let sensors = args.sensors.as_deref().map(load_sensor_file).transpose()?;
    let recognition = super::detect::params_or_camera_s(
        args.params.as_deref(),
        &args.input.frames,
        args.input.camera.get(),
    )?;
    let mut memory = match &args.update {
        Some(p) if p.exists() || p != &args.output => PatternMemory::load(p)?,
        _ => PatternMemory::default(),
    };
    let learn_params = LearnParams {
        same_object_cm: args.same_object_cm,
        min_views: args.min_views,
        min_spread_deg: args.min_spread_deg,
        outlier_cm: args.outlier_cm,
    };
    // Typed poses belong to the input paths in order.
    let paths = super::inputs::expand_frame_paths(&args.input.frames)?;
    if args.pose.len() > 1 && args.pose.len() != paths.len() {
        bail!(
            "{} --pose values for {} inputs: give one per input, or one for all",
            args.pose.len(),
            paths.len()
        );
    }
    let mut pipeline = Pipeline::new(
        lut,
        PipelineParams {
            recognition,
            ..PipelineParams::default()
        },
    );
    let mut sources = PoseSources::default();
    let mut views = Vec::new();
    let mut reader: Option<StreamReader> = None;
    let bar = progress(inputs.len(), "learn");
    for (i, item) in inputs.items().iter().enumerate() {
        bar.inc(1);
        let (frame, recorded_sensors, recorded) =
            read_input(item, &mut reader, args.input.size, args.input.camera.get())?;
        let path = match item {
            FrameInput::File(p) | FrameInput::Stream { path: p, .. } => p,
        };
        let robot = if let Some(t) = &table {
            let p = t.get(&i).copied();
            if p.is_some() {
                sources.table += 1;
            }
            p
        } else if let Some(p) = typed_pose(&args.pose, &paths, path) {
            sources.typed += 1;
            Some(p)
        } else {
            recorded
                .as_ref()
                .and_then(|r| recorded_pose(r, &mut sources))
        };
        let Some(robot) = robot else {
            sources.none += 1;
            continue;
        };
        let readings = readings_for(recorded_sensors.as_ref(), sensors.as_deref(), i);
        let result = pipeline.process(&frame, readings);
        views.extend(result.recognition.patterns.iter().map(|c| LearnView {
            frame: i,
            robot,
            observation: c.observation,
        }));
    }
    bar.finish_and_clear();
    if sources.none == inputs.len() {
        bail!(
            "no frame has a robot pose: give --poses FILE or --pose X,Y,HEADING (or streams \
             with a /robot_pose or /ground_truth channel)"
        );
    }
    let report = memory.learn(&views, &recognition.patterns, &learn_params);
    memory.save(&args.output)?;
    Ok(LearnOutput {
        frames: inputs.len(),
        poses: sources,
        report,
        places: memory,
        output: args.output.clone(),
    })
}

/// What a stream recorded beside a frame: its ground truth and extra channels.
type RecordedChannels = (Option<serde_json::Value>, Vec<(String, serde_json::Value)>);

/// One input's frame, with the sensor readings and channels its stream recorded (none for a
/// frame file); `reader` keeps the last stream open.
fn read_input(
    item: &FrameInput,
    reader: &mut Option<StreamReader>,
    size: Option<(usize, usize)>,
    camera: Option<&str>,
) -> anyhow::Result<(
    crate::frame::Frame,
    Option<crate::sensors::SensorReadings>,
    Option<RecordedChannels>,
)> {
    Ok(match item {
        FrameInput::File(p) => (load_frame_arg(p, size)?, None, None),
        FrameInput::Stream { path, index } => {
            if reader.as_ref().is_none_or(|r| r.path() != path) {
                *reader = Some(StreamReader::open_camera(path, camera)?);
            }
            let Some(r) = reader.as_mut() else {
                bail!("{}: stream not open", path.display());
            };
            let record = r.read(*index)?;
            (
                record.frame,
                record.sensors,
                Some((record.ground_truth, record.extra)),
            )
        }
    })
}

/// The `--pose` typed for input `path`: the only one, or the one at its place among `paths`.
fn typed_pose(poses: &[RobotPose], paths: &[PathBuf], path: &Path) -> Option<RobotPose> {
    match poses {
        [] => None,
        [one] => Some(*one),
        many => paths
            .iter()
            .position(|q| q == path)
            .and_then(|i| many.get(i).copied()),
    }
}

/// Runs `eotn patterns`.
///
/// # Errors
/// Whatever the subcommand reports.
pub fn run(args: &Args) -> anyhow::Result<()> {
    match &args.command {
        PatternsCommand::Learn(a) => {
            let out = learn(a)?;
            if a.json {
                outln!("{}", serde_json::to_string(&out)?);
            } else {
                print_learnt(&out);
            }
            Ok(())
        }
        PatternsCommand::Show(a) => {
            let memory = PatternMemory::load(&a.places)?;
            if a.json {
                outln!("{}", serde_json::to_string(&memory)?);
            } else {
                print_places(&memory);
            }
            Ok(())
        }
    }
}

fn print_learnt(o: &LearnOutput) {
    let p = &o.poses;
    outln!(
        "frames                 {} (robot pose from: --poses {}, --pose {}, /robot_pose {}, \
         /ground_truth {}; none {})",
        o.frames,
        p.table,
        p.typed,
        p.robot_pose_channel,
        p.ground_truth,
        p.none
    );
    let r = &o.report;
    outln!(
        "pink markers seen      {} ({} without a camera pose, {} with too little colour \
         around)",
        r.views,
        r.views_without_ray,
        r.views_without_colour
    );
    outln!(
        "learnt                 {} new object(s) {:?}, {} pattern(s) added to known objects, \
         {} view(s) of known patterns",
        r.objects_created.len(),
        r.objects_created,
        r.patterns_added.len(),
        r.views_merged
    );
    if !r.patterns_refused.is_empty() {
        outln!(
            "  {} further pattern(s) refused (within one region of another place's): places {:?}",
            r.patterns_refused.len(),
            r.patterns_refused
        );
    }
    for g in &r.groups_dropped {
        outln!("  not learnt: {g}");
    }
    for (a, b) in &r.indistinct {
        outln!(
            "  warning: places {a} and {b} have matching patterns: identification cannot tell \
             them apart"
        );
    }
    print_places(&o.places);
    outln!("written                {}", o.output.display());
}

fn print_places(m: &PatternMemory) {
    outln!("objects                {}", m.objects.len());
    for o in &m.objects {
        let how = match o.placed_by {
            Placement::Triangulation => {
                format!("triangulated, rays within {:.1} cm", o.residual_cm)
            }
            Placement::SizeRelation => "placed by size".to_owned(),
        };
        outln!(
            "  place {:<3} at ({:7.1}, {:7.1}) cm{}, {} view(s), {} pattern(s), {how}",
            o.id,
            o.field_cm[0],
            o.field_cm[1],
            o.height_cm
                .map(|h| format!(", {h:.1} cm up"))
                .unwrap_or_default(),
            o.views,
            o.patterns.len()
        );
        for p in &o.patterns {
            outln!("      {}", p.short_text());
        }
    }
    match &m.relation {
        Some(r) => outln!(
            "size → distance        distance = {:.1} / size_px + {:.1} cm (rms residual {:.1} cm \
             over {} samples)",
            r.multiplier_cm_px,
            r.offset_cm,
            r.residual_cm,
            r.samples
        ),
        None => outln!("size → distance        not learnt (no triangulated place)"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poses_parse_from_text_and_tables() {
        assert_eq!(
            parse_pose("10, -20.5, 1.57").ok(),
            Some(RobotPose::new(10.0, -20.5, 1.57))
        );
        assert!(parse_pose("1,2").is_err());
        assert!(parse_pose("a,b,c").is_err());
        assert!(parse_pose("1,2,NaN").is_err());
        let dir = tempfile::tempdir().expect("tempdir");
        let csv = dir.path().join("poses.csv");
        std::fs::write(&csv, "frame,x_cm,y_cm,heading_rad\n0,1,2,0.5\n3,4,5,-0.5\n")
            .expect("write");
        let t = load_pose_table(&csv).expect("loads");
        assert_eq!(t.get(&3), Some(&RobotPose::new(4.0, 5.0, -0.5)));
        assert_eq!(t.len(), 2);
        std::fs::write(&csv, "frame,x,y\n0,1,2\n").expect("write");
        let e = load_pose_table(&csv).expect_err("bad column");
        assert!(e.to_string().contains("unknown column \"x\""), "{e}");
        std::fs::write(&csv, "frame,x_cm,y_cm,heading_rad\n0,1,2,zero\n").expect("write");
        let e = load_pose_table(&csv).expect_err("not a number");
        assert!(format!("{e:#}").contains("line 2"), "{e:#}");
        std::fs::write(&csv, "frame,x_cm,y_cm,heading_rad\n0,1,2,0\n0,1,2,0\n").expect("write");
        assert!(load_pose_table(&csv).is_err(), "a frame twice");
        let json = dir.path().join("poses.json");
        std::fs::write(
            &json,
            r#"[{"frame": 2, "x_cm": 1, "y_cm": 2, "heading_rad": 0}]"#,
        )
        .expect("write");
        assert_eq!(load_pose_table(&json).expect("json").len(), 1);
        std::fs::write(&json, r#"{"frame": 2}"#).expect("write");
        assert!(load_pose_table(&json).is_err());
    }
}
