//! `eotn detect`: runs the whole pipeline, recognition included, and prints what was found per
//! frame — one JSON line per frame with `--json` (documented in the README), else a short table.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;
use serde::Serialize;

use super::inputs::{InputArgs, parse_connectivity, progress};
use crate::blobs::Connectivity;
use crate::frame::PixelBox;
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::patterns::PatternMemory;
use crate::recognition::{GoalCandidate, Recognition, Relative};
use crate::sensors::SensorReadings;

/// Arguments of `eotn detect`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Frames, table and raw frame size.
    #[command(flatten)]
    pub input: InputArgs,
    /// Sensor readings for raw frames: a JSON file holding one object with the fields of the
    /// sensor schema (applies to every frame) or an array of such objects in frame order.
    #[arg(long)]
    pub sensors: Option<PathBuf>,
    /// 8: diagonal neighbours join a blob; 4: they do not.
    #[arg(long, default_value = "8", value_parser = parse_connectivity)]
    pub connectivity: Connectivity,
    /// Recognition parameters as JSON (any subset of the fields; the rest keep their defaults) (default: the set the first recording names for the camera read, else the defaults).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// One JSON object per frame per line.
    #[arg(long)]
    pub json: bool,
    /// With `--json`: add every candidate with its confidence breakdown.
    #[arg(long)]
    pub evidence: bool,
    /// Also write the frames with their recognition to this MCAP stream: each frame with the
    /// channels it came with, `/recognition` (the JSON line) and `/camera/annotations`
    /// (`foxglove.ImageAnnotations`), so Foxglove and Rerun draw what eotn found.
    #[arg(long, value_name = super::paths::OUT)]
    pub annotate: Option<PathBuf>,
    /// A places file (`eotn patterns learn`): identify the pink markers' coloured patterns;
    /// `--json` then lists them as `patterns`.
    #[arg(long)]
    pub patterns: Option<PathBuf>,
}

/// Camera- and body-relative position of an object, flattened for JSON.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct PlacementJson {
    /// Camera-relative distance, centimetres.
    pub distance_cm: f64,
    /// Camera-relative bearing, radians, positive left.
    pub bearing_rad: f64,
    /// Camera-relative elevation, radians, positive up.
    pub elevation_rad: f64,
    /// Body-relative distance, centimetres (null without joint readings).
    pub body_distance_cm: Option<f64>,
    /// Body-relative bearing, radians.
    pub body_bearing_rad: Option<f64>,
    /// Body-relative elevation, radians.
    pub body_elevation_rad: Option<f64>,
}

impl PlacementJson {
    fn new(camera: &Relative, body: Option<&Relative>) -> Self {
        Self {
            distance_cm: camera.distance_cm,
            bearing_rad: camera.bearing_rad,
            elevation_rad: camera.elevation_rad,
            body_distance_cm: body.map(|b| b.distance_cm),
            body_bearing_rad: body.map(|b| b.bearing_rad),
            body_elevation_rad: body.map(|b| b.elevation_rad),
        }
    }
}

/// The ball in `--json` output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BallJson {
    /// Centre x, image pixels.
    pub center_x: f64,
    /// Centre y, image pixels.
    pub center_y: f64,
    /// Radius, pixels.
    pub radius_px: f64,
    /// Where it is.
    #[serde(flatten)]
    pub placement: PlacementJson,
    /// Total confidence.
    pub confidence: f64,
    /// Sides cut off: any of `left`, `right`, `top`, `bottom`.
    pub cut_off: Vec<&'static str>,
    /// Whether a circle fit gave centre and radius.
    pub from_circle_fit: bool,
    /// The ball's own image velocity `[x, y]`, pixels per second, from the ellipse fit (null
    /// unless `ball.ellipse_fit` is on and the fit was determined).
    pub image_velocity_px_s: Option<[f64; 2]>,
    /// That velocity on the ground in the robot's frame `[ahead, left]`, cm/s (null without it
    /// or without the camera pose).
    pub ground_velocity_cm_s: Option<[f64; 2]>,
}

/// A goal post in `--json` output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct PostJson {
    /// `left` or `right` in the image.
    pub side: &'static str,
    /// Top end, image pixels `[x, y]`.
    pub top: [f64; 2],
    /// Bottom end, image pixels.
    pub bottom: [f64; 2],
    /// Camera-relative bearing of the post's centre, radians.
    pub bearing_rad: f64,
}

/// The gap in `--json` output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct GapJson {
    /// Left end, image pixels.
    pub left: [f64; 2],
    /// Right end, image pixels.
    pub right: [f64; 2],
    /// Length, pixels.
    pub width_px: f64,
    /// Camera-relative bearing of its centre, radians.
    pub bearing_rad: f64,
}

/// A goal in `--json` output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct GoalJson {
    /// `yellow` or `sky blue`.
    pub colour: &'static str,
    /// Box, inclusive pixels.
    pub minx: u32,
    /// Box top row.
    pub miny: u32,
    /// Box right column.
    pub maxx: u32,
    /// Box bottom row.
    pub maxy: u32,
    /// Where it is.
    #[serde(flatten)]
    pub placement: PlacementJson,
    /// True when top or bottom is cut off: the distance is an upper bound.
    pub distance_is_max: bool,
    /// Sides cut off.
    pub cut_off: Vec<&'static str>,
    /// Fitted posts.
    pub posts: Vec<PostJson>,
    /// Largest open gap.
    pub gap: Option<GapJson>,
    /// Total confidence.
    pub confidence: f64,
}

/// A beacon in `--json` output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BeaconJson {
    /// E.g. `pink over yellow`.
    pub kind: String,
    /// Box, inclusive pixels (`[minx, miny, maxx, maxy]` in JSON).
    pub bounds: PixelBox,
    /// Where it is.
    #[serde(flatten)]
    pub placement: PlacementJson,
    /// Total confidence.
    pub confidence: f64,
}

/// The place a pink marker was identified as, in `--json` output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct PlaceJson {
    /// The place's id in the places file.
    pub id: usize,
    /// Regions agreeing on the most common colour, of nine.
    pub agreement: usize,
    /// Camera distance from the learnt size relation, centimetres (null without one).
    pub distance_cm: Option<f64>,
}

/// A pink marker's coloured pattern in `--json` output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct PatternJson {
    /// The pink blob's box, inclusive pixels (`[minx, miny, maxx, maxy]` in JSON).
    pub bounds: PixelBox,
    /// The two most common class codes of each of the nine regions, row by row (0: nothing).
    pub signature: [[u8; 2]; 9],
    /// The pink blob's size (mean column height), pixels.
    pub size_px: f64,
    /// Camera bearing of its centre, radians, positive left.
    pub bearing_rad: f64,
    /// Camera elevation of its centre, radians, positive up.
    pub elevation_rad: f64,
    /// The identified place, or null.
    #[serde(rename = "match")]
    pub matched: Option<PlaceJson>,
    /// Body-relative distance (cm), bearing and elevation (rad) of an identified marker with a
    /// distance, when the joints were known.
    pub body_distance_cm: Option<f64>,
    /// Body-relative bearing, radians.
    pub body_bearing_rad: Option<f64>,
    /// Body-relative elevation, radians.
    pub body_elevation_rad: Option<f64>,
    /// The best-agreeing place and its agreement even when it did not match: `[id, regions]`.
    pub closest: Option<[usize; 2]>,
    /// Two places agree equally well.
    pub ambiguous: bool,
    /// Some regions reach outside the image.
    pub cut_off: bool,
    /// Total confidence.
    pub confidence: f64,
}

fn pattern_json(c: &crate::recognition::patterns::PatternCandidate) -> PatternJson {
    let o = &c.observation;
    PatternJson {
        bounds: o.bounds,
        signature: o.signature.0,
        size_px: o.size_px,
        bearing_rad: o.bearing_rad,
        elevation_rad: o.elevation_rad,
        matched: c.identification.map(|m| PlaceJson {
            id: m.id,
            agreement: m.agreement,
            distance_cm: m.distance_cm,
        }),
        body_distance_cm: c.body.map(|b| b.distance_cm),
        body_bearing_rad: c.body.map(|b| b.bearing_rad),
        body_elevation_rad: c.body.map(|b| b.elevation_rad),
        closest: c.closest.map(|b| [b.id, b.agreement]),
        ambiguous: c.ambiguous,
        cut_off: c.cut_off,
        confidence: c.confidence.total,
    }
}

/// One frame's line of `eotn detect --json`.
#[derive(Debug, Clone, Serialize)]
pub struct DetectJson {
    /// Frame name (file name, or `stream#index`).
    pub frame: String,
    /// The ball, or null.
    pub ball: Option<BallJson>,
    /// Accepted goals.
    pub goals: Vec<GoalJson>,
    /// Accepted beacons.
    pub beacons: Vec<BeaconJson>,
    /// With `--patterns`: every pink marker, identified or not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub patterns: Option<Vec<PatternJson>>,
    /// Recognition time, microseconds.
    pub recognition_us: f64,
    /// With `--evidence`: every candidate and its confidence breakdown.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub evidence: Option<Recognition>,
}

fn sides(cut: crate::recognition::scan::CutOff) -> Vec<&'static str> {
    let mut v = Vec::new();
    for (on, name) in [
        (cut.left, "left"),
        (cut.right, "right"),
        (cut.top, "top"),
        (cut.bottom, "bottom"),
    ] {
        if on {
            v.push(name);
        }
    }
    v
}

fn goal_json(g: &GoalCandidate) -> GoalJson {
    GoalJson {
        colour: g.colour.name(),
        minx: g.bounds.min_x,
        miny: g.bounds.min_y,
        maxx: g.bounds.max_x,
        maxy: g.bounds.max_y,
        placement: PlacementJson::new(&g.camera, g.body.as_ref()),
        distance_is_max: g.distance_is_max,
        cut_off: sides(g.cut_off),
        posts: g
            .posts
            .iter()
            .map(|p| PostJson {
                side: match p.side {
                    crate::recognition::goals::PostSide::Left => "left",
                    crate::recognition::goals::PostSide::Right => "right",
                },
                top: [p.top.x_px, p.top.y_px],
                bottom: [p.bottom.x_px, p.bottom.y_px],
                bearing_rad: p.camera.bearing_rad,
            })
            .collect(),
        gap: g.gap.as_ref().map(|gap| GapJson {
            left: [gap.left.x_px, gap.left.y_px],
            right: [gap.right.x_px, gap.right.y_px],
            width_px: gap.width_px,
            bearing_rad: gap.camera.bearing_rad,
        }),
        confidence: g.confidence.total,
    }
}

/// The JSON line for one frame's recognition.
#[must_use]
pub fn detect_json(
    frame: String,
    r: &Recognition,
    recognition_us: f64,
    evidence: bool,
) -> DetectJson {
    DetectJson {
        frame,
        ball: r.ball.ball.as_ref().map(|b| BallJson {
            center_x: b.center_x,
            center_y: b.center_y,
            radius_px: b.radius_px,
            placement: PlacementJson::new(&b.camera, b.body.as_ref()),
            confidence: b.confidence,
            cut_off: sides(b.cut_off),
            from_circle_fit: b.from_circle_fit,
            image_velocity_px_s: b.image_velocity_px_s,
            ground_velocity_cm_s: b.ground_velocity_cm_s,
        }),
        goals: r.goals.goals().map(goal_json).collect(),
        beacons: r
            .beacons
            .iter()
            .filter(|b| b.accepted)
            .map(|b| BeaconJson {
                kind: b.kind.name(),
                bounds: b.bounds,
                placement: PlacementJson::new(&b.camera, b.body.as_ref()),
                confidence: b.confidence.total,
            })
            .collect(),
        patterns: None,
        recognition_us,
        evidence: evidence.then(|| r.clone()),
    }
}

/// Sensor readings from `--sensors`: one object for every frame, or one per frame. Python's
/// `NaN` reads as missing (as in side files); an unknown field or an impossible value is an
/// error naming the entry and the field.
///
/// # Errors
/// An unreadable file, JSON that is neither shape, an unknown field or an impossible value,
/// naming the file.
pub fn load_sensor_file(path: &std::path::Path) -> anyhow::Result<Vec<SensorReadings>> {
    let bytes = crate::input_file::read_bounded(
        path,
        crate::input_file::MAX_SIDE_FILE_BYTES,
        "a sensor file",
    )
    .with_context(|| format!("{}: cannot read", path.display()))?;
    let (value, _) = crate::streams::schema::parse_json_lenient(&bytes)
        .map_err(|e| anyhow::anyhow!("{}: not JSON ({e})", path.display()))?;
    let list = match value {
        serde_json::Value::Array(items) => items,
        other => vec![other],
    };
    let known: Vec<&str> = SensorReadings::default()
        .fields()
        .iter()
        .map(|f| f.name)
        .collect();
    list.into_iter()
        .enumerate()
        .map(|(i, v)| {
            if let Some(unknown) = v
                .as_object()
                .and_then(|o| o.keys().find(|k| !known.contains(&k.as_str())))
            {
                anyhow::bail!(
                    "{}: entry {i}: '{unknown}' is not a sensor field (fields: {})",
                    path.display(),
                    known.join(", ")
                );
            }
            let r: SensorReadings = serde_json::from_value(v).map_err(|e| {
                anyhow::anyhow!(
                    "{}: entry {i} is not a sensor reading ({e})",
                    path.display()
                )
            })?;
            if let Some(f) = r.fields().into_iter().find(|f| {
                f.value
                    .is_some_and(|x| x.is_finite() && !crate::sensors::plausible(f.name, f.unit, x))
            }) {
                anyhow::bail!(
                    "{}: entry {i}: {} = {} {} is not a possible reading",
                    path.display(),
                    f.name,
                    f.value.unwrap_or_default(),
                    f.unit
                );
            }
            Ok(r.sanitised().0)
        })
        .collect()
}

/// What the first recording among `paths` names for the camera read (`camera`; `None`: its
/// first) — its sidecar's entry, else its `eotn.camera` metadata —, with that recording's path;
/// `None` when no recording is among them.
///
/// # Errors
/// An unreadable recording or sidecar, or a camera the recording does not have.
pub fn named_camera_files(
    paths: &[PathBuf],
    camera: Option<&str>,
) -> anyhow::Result<Option<(PathBuf, crate::camera::CameraFiles)>> {
    let Some(rec) = paths.iter().find(|p| crate::streams::is_recording(p)) else {
        return Ok(None);
    };
    let reader = crate::streams::StreamReader::open_camera(rec, camera)?;
    Ok(Some((rec.clone(), reader.camera_files()?)))
}

/// The recognition parameters of a command: `--params` when given, else those the first
/// recording among `paths` names for the camera read (a file, or a set's name found as the app
/// finds it: `params/NAME.json` beside the recording or up to three folders above, or in the
/// current folder), else the defaults.
///
/// # Errors
/// As [`load_params`]; a named set found nowhere.
pub fn params_or_camera_s(
    explicit: Option<&std::path::Path>,
    paths: &[PathBuf],
    camera: Option<&str>,
) -> anyhow::Result<crate::recognition::RecognitionParams> {
    if explicit.is_some() {
        return load_params(explicit);
    }
    let Some((rec, files)) = named_camera_files(paths, camera)? else {
        return load_params(None);
    };
    let Some(name) = files.params else {
        return load_params(None);
    };
    let path = crate::workspace::params::named_param_file(&name, &rec).with_context(|| {
        format!(
            "{}: its camera's parameter set {name} is nowhere (params/{name}.json beside the recording or above it, or here): give --params",
            rec.display()
        )
    })?;
    load_params(Some(&path)).with_context(|| {
        format!(
            "{}: the recognition parameters named for its camera",
            rec.display()
        )
    })
}

/// Loads `--params`: recognition parameters as JSON over the defaults, every key and range
/// checked ([`crate::recognition::params_file`]).
///
/// # Errors
/// An unreadable file, an unknown key or a value out of range, naming the file and the field.
pub fn load_params(
    path: Option<&std::path::Path>,
) -> anyhow::Result<crate::recognition::RecognitionParams> {
    let Some(path) = path else {
        return Ok(crate::recognition::RecognitionParams::default());
    };
    Ok(crate::recognition::params_file::load(path)?)
}

/// The sensor readings for frame `i`: the stream's own when it has them, else the `--sensors`
/// file's (one entry for every frame, or one per frame in order).
#[must_use]
pub fn readings_for<'a>(
    recorded: Option<&'a SensorReadings>,
    file: Option<&'a [SensorReadings]>,
    i: usize,
) -> Option<&'a SensorReadings> {
    recorded.or_else(|| file.and_then(|s| if s.len() == 1 { s.first() } else { s.get(i) }))
}

/// Runs `eotn detect`.
///
/// # Errors
/// Unreadable or malformed inputs, naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let (lut, mut inputs) = args.input.open()?;
    if let Some(p) = inputs.overhead_streams().first() {
        anyhow::bail!(
            "{}: an overhead camera's stream (it looks down at the field); `eotn detect` runs the \
             robot camera's recogniser: use `eotn overhead detect {} --lut TABLE --calibration \
             CAL.json`",
            p.display(),
            p.display()
        );
    }

    let sensors = args.sensors.as_deref().map(load_sensor_file).transpose()?;
    let params = PipelineParams {
        connectivity: args.connectivity,
        recognise: true,
        recognition: params_or_camera_s(
            args.params.as_deref(),
            &args.input.frames,
            args.input.camera.get(),
        )?,
    };
    let mut pipeline = Pipeline::new(lut, params);
    if let Some(p) = &args.patterns {
        pipeline.set_pattern_memory(Some(PatternMemory::load(p)?));
    }
    let mut annotated = args
        .annotate
        .as_deref()
        .map(|p| annotated_writer(p, &args.input.frames))
        .transpose()?;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let bar = progress(inputs.len(), "detect");
    let mut last_size = None;
    for i in 0..inputs.len() {
        let Some(mut record) = inputs.load_record_or_skip(i, args.input.size)? else {
            bar.inc(1);
            continue;
        };
        let size = (record.frame.width(), record.frame.height());
        if let Some((w, h)) = last_size.replace(size)
            && (w, h) != size
        {
            // Each frame is detected at its own size; the change is said where it happens.
            log::warn!(
                "{}: the frame size changes from {w}x{h} to {}x{}",
                inputs.name(i),
                size.0,
                size.1
            );
        }
        let readings = readings_for(record.sensors.as_ref(), sensors.as_deref(), i);
        let result = pipeline.process(&record.frame, readings);
        let us = result.timings.recognition.as_secs_f64() * 1e6;
        let mut line = detect_json(inputs.name(i), result.recognition, us, args.evidence);
        if args.patterns.is_some() {
            line.patterns = Some(
                result
                    .recognition
                    .patterns
                    .iter()
                    .map(pattern_json)
                    .collect(),
            );
        }
        if let Some(w) = annotated.as_mut() {
            let (width, height) = (record.frame.width(), record.frame.height());
            record.annotations = Some(crate::annotate::image_annotations(
                result.recognition,
                width,
                height,
                record.time_ns,
            ));
            record.recognition = Some(serde_json::to_value(&line)?);
            w.write(&record)?;
        }
        if args.json {
            serde_json::to_writer(&mut out, &line)?;
            writeln!(out)?;
        } else {
            write_summary(&mut out, &line)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    out.flush().context("writing output")?;
    if let Some(w) = annotated {
        w.finish()?;
    }
    Ok(())
}

/// The writer of `--annotate OUT` (which never replaces an input: see [`super::paths`]).
fn annotated_writer(
    path: &std::path::Path,
    inputs: &[PathBuf],
) -> anyhow::Result<crate::streams::StreamWriter> {
    // A stream's own source kind is kept (it says which camera the frames came from).
    let source = inputs
        .iter()
        .find(|p| crate::streams::is_recording(p))
        .and_then(|p| crate::streams::StreamReader::open(p).ok())
        .map_or_else(|| "import".to_owned(), |r| r.info().source.clone());
    let info = crate::streams::StreamInfo {
        source,
        description: format!(
            "frames of {} with eotn's recognition as /recognition and /camera/annotations",
            inputs
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    Ok(crate::streams::StreamWriter::create(path, &info)?)
}

/// The human-readable line for a frame.
fn write_summary(out: &mut impl Write, d: &DetectJson) -> std::io::Result<()> {
    write!(out, "{}:", d.frame)?;
    match &d.ball {
        Some(b) => write!(
            out,
            " ball at ({:.1}, {:.1}) r {:.1} px, {:.0} cm, {:+.1}°",
            b.center_x,
            b.center_y,
            b.radius_px,
            b.placement.distance_cm,
            b.placement.bearing_rad.to_degrees()
        )?,
        None => write!(out, " no ball")?,
    }
    for g in &d.goals {
        write!(
            out,
            "; {} goal {}{:.0} cm {:+.1}°, {} post(s){}",
            g.colour,
            if g.distance_is_max { "≤" } else { "" },
            g.placement.distance_cm,
            g.placement.bearing_rad.to_degrees(),
            g.posts.len(),
            if g.gap.is_some() { ", gap" } else { "" }
        )?;
    }
    for b in &d.beacons {
        write!(out, "; beacon {} {:.0} cm", b.kind, b.placement.distance_cm)?;
    }
    for p in d.patterns.iter().flatten() {
        match &p.matched {
            Some(m) => write!(
                out,
                "; place {} ({}/9){}",
                m.id,
                m.agreement,
                m.distance_cm
                    .map(|d| format!(" {d:.0} cm"))
                    .unwrap_or_default()
            )?,
            None => write!(out, "; pink marker, no place")?,
        }
    }
    writeln!(out)
}
