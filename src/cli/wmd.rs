//! `eotn wmd`: the World Model Debugger headless. An overhead camera (or a session's cameras)
//! and the robots' recorded world models: each world model is paired with the overhead frame
//! nearest in time after its robot's clock offset (`crate::wmd::clock`), matched with its
//! robot by marker (else by position), and its errors measured; `--json` prints one line per
//! overhead frame, else a table per robot.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, bail};
use serde_json::{Value, json};

use super::field::{FieldCamera, open_cameras};
use super::overhead::{load_field, load_usable_calibration, overhead_json, params_for};
use super::wmd_inputs::{FieldFrame, RobotModels, field_frames, read_world_models, recorded};
use crate::model::world_model::RobotKey;
use crate::overhead::OverheadPipeline;
use crate::overhead::merge::{SslCameraId, frame_near};
use crate::session::{Session, SessionSource};
use crate::wmd::clock::{ClockOffset, estimate_offset, frame_period_ns, shifted};
use crate::wmd::summary::{RobotSummary, Spread, Summaries};
use crate::wmd::{Comparison, Targets, WorldModelMessage, compare};

/// Arguments of `eotn wmd`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The overhead camera's recording.
    #[arg(long, required_unless_present = "session", conflicts_with = "session")]
    pub overhead: Option<PathBuf>,
    /// A robot's recording with its world models (`/world_model`, `/world_model/<name>`;
    /// docs/formats.md); repeatable; one recording may hold several robots'.
    #[arg(long, required_unless_present = "session", conflicts_with = "session")]
    pub robot: Vec<PathBuf>,
    /// The overhead camera's lookup table.
    #[arg(long, required_unless_present = "session", conflicts_with = "session")]
    pub lut: Option<PathBuf>,
    /// The overhead camera's calibration (`eotn overhead calibrate`).
    #[arg(long, required_unless_present = "session", conflicts_with = "session")]
    pub calibration: Option<PathBuf>,
    /// Field description (a file or a shipped field's name): ball radius, plate height, and
    /// where the goals and landmarks a robot measures stand; four-legged-2005 by default.
    #[arg(long, value_name = "FIELD", conflicts_with = "session")]
    pub field: Option<PathBuf>,
    /// A session file (docs/formats.md): its overhead cameras merged, its robots' sources.
    #[arg(long)]
    pub session: Option<PathBuf>,
    /// One JSON object per overhead frame per line: `time_ns`, `ball`, `robots` (as
    /// `eotn overhead detect --json` prints them), `world_models`.
    #[arg(long)]
    pub json: bool,
    /// How far to search for each robot's clock offset, seconds (0: the start only).
    #[arg(long, default_value_t = 2.0, value_parser = super::values::number_in(0.0, 3600.0))]
    pub max_clock_offset: f64,
    /// Which camera of the overhead recording.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
}

/// Runs `eotn wmd`.
///
/// # Errors
/// An unreadable input (named), a live or device source, no world models at all.
pub fn run(a: &Args) -> anyhow::Result<()> {
    let (field, mut cameras, robots, single) = open(a)?;
    let mut models = RobotModels::new();
    for (path, only) in &robots {
        read_world_models(path, *only, &mut models)?;
    }
    if models.is_empty() {
        bail!("no world model in the robots' recordings");
    }
    let frames = field_frames(&mut cameras, single)?;
    if frames.is_empty() {
        bail!("the overhead recording has no frames");
    }
    let times: Vec<u64> = frames.iter().map(|f| f.time_ns).collect();
    let period = frame_period_ns(&times);
    #[expect(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "0..=3600 s"
    )]
    let max_offset = (a.max_clock_offset * 1e9) as u64;
    let views: Vec<crate::wmd::OverheadView> = frames.iter().map(FieldFrame::view).collect();
    let (offsets, paired) = pair(&models, &times, &views, period, max_offset);
    for (key, o) in &offsets {
        log::info!(
            "{key}: clock offset {:+.3} s ({:?}, {} pairs)",
            o.offset_ns as f64 * 1e-9,
            o.start,
            o.pairs
        );
    }
    let targets = Targets::from_field(&field);
    let mut summaries = Summaries::default();
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for (i, frame) in frames.iter().enumerate() {
        let results = compare(&views[i], &paired[i], &targets);
        let jumps: Vec<bool> = results
            .iter()
            .map(|c| summaries.add(frame.time_ns, c))
            .collect();
        if a.json {
            let line = line_json(frame, &results, &jumps)?;
            serde_json::to_writer(&mut out, &line)?;
            writeln!(out)?;
        }
    }
    let summaries = summaries.finish();
    let last_ns = times.last().copied().unwrap_or(0);
    for s in &summaries {
        if last_ns.saturating_sub(s.last_ns) > 10 * period {
            log::warn!(
                "{}: no world model after {:.3} s (the overhead frames run to {:.3} s)",
                s.robot,
                s.last_ns as f64 * 1e-9,
                last_ns as f64 * 1e-9
            );
        }
    }
    if a.json {
        for (key, o) in &offsets {
            eprintln!("{key}: clock offset {}", offset_text(o));
        }
    } else {
        write_table(&mut out, &summaries, &offsets)?;
    }
    out.flush().context("writing output")?;
    Ok(())
}

/// Each robot's clock offset, and the world models paired with each frame (of each robot the
/// one nearest the frame's time, within half a frame period).
fn pair<'a>(
    models: &'a RobotModels,
    times: &[u64],
    views: &[crate::wmd::OverheadView],
    period: u64,
    max_offset: u64,
) -> (
    Vec<(RobotKey, ClockOffset)>,
    Vec<Vec<&'a WorldModelMessage>>,
) {
    let mut offsets = Vec::new();
    let mut paired: Vec<Vec<&WorldModelMessage>> = vec![Vec::new(); times.len()];
    for (key, list) in models {
        let own: Vec<(u64, [f64; 2])> = list
            .iter()
            .map(|(t, m)| (*t, [m.own.x_cm, m.own.y_cm]))
            .collect();
        let robot_at = |i: usize| {
            views[i]
                .robots
                .iter()
                .find(|r| r.key == *key)
                .map(|r| r.field_cm)
        };
        let offset = estimate_offset(times, period, robot_at, &own, max_offset);
        // The message nearest in time to each frame.
        let mut nearest: Vec<Option<(u64, &WorldModelMessage)>> = vec![None; times.len()];
        for (t, m) in list {
            let Some(t) = shifted(*t, offset.offset_ns) else {
                continue;
            };
            let Some(i) = frame_near(times, t, period) else {
                continue;
            };
            let gap = t.abs_diff(times[i]);
            if nearest[i].is_none_or(|(g, _)| gap < g) {
                nearest[i] = Some((gap, m));
            }
        }
        for (i, n) in nearest.into_iter().enumerate() {
            paired[i].extend(n.map(|n| n.1));
        }
        offsets.push((*key, offset));
    }
    (offsets, paired)
}

/// The inputs: field, overhead cameras, robot recordings (each with the robot it is for, in a
/// session), whether there is one camera from the command line.
type Opened = (
    crate::overhead::FieldDescription,
    Vec<FieldCamera>,
    Vec<(PathBuf, Option<RobotKey>)>,
    bool,
);

fn open(a: &Args) -> anyhow::Result<Opened> {
    if let Some(path) = &a.session {
        let session = Session::load(path)?;
        if session.robots.is_empty() {
            bail!("{}: no robots to debug", path.display());
        }
        for e in &session.overhead {
            recorded(&e.source, &format!("overhead camera {}", e.id))?;
        }
        let robots = session
            .robots
            .iter()
            .map(|r| {
                let key = RobotKey {
                    team: r.team,
                    identity: r.robot_id,
                };
                Ok((recorded(&r.source, &format!("robot {key}"))?, Some(key)))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let (field, cameras) = open_cameras(&session)?;
        return Ok((field, cameras, robots, false));
    }
    let (Some(overhead), Some(lut), Some(cal)) = (&a.overhead, &a.lut, &a.calibration) else {
        bail!("--overhead, --lut and --calibration name the overhead camera (or give --session)");
    };
    let source = |p: &PathBuf, what: &str| recorded(&SessionSource::parse_arg(p), what);
    let overhead = source(overhead, "overhead")?;
    let robots = a
        .robot
        .iter()
        .map(|p| Ok((source(p, "robot")?, None)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let field = load_field(a.field.as_deref())?;
    let cal = load_usable_calibration(cal)?;
    let lut = super::inputs::load_lut_arg(lut)?;
    let reader = crate::streams::StreamReader::open_camera(&overhead, a.camera.get())?;
    let camera = FieldCamera {
        id: SslCameraId(0),
        pipeline: OverheadPipeline::new(lut, cal.camera, params_for(&field)),
        reader,
        name: crate::frame::display_name(&overhead),
    };
    Ok((field, vec![camera], robots, true))
}

fn line_json(frame: &FieldFrame, results: &[Comparison], jumps: &[bool]) -> anyhow::Result<Value> {
    let mut line = match &frame.single {
        Some(d) => {
            let mut v = serde_json::to_value(overhead_json(String::new(), d, 0.0))?;
            if let Some(o) = v.as_object_mut() {
                o.remove("frame");
                o.remove("overhead_us");
            }
            v
        }
        None => {
            super::detect_field::field_line_value(frame.time_ns, &frame.picture, &frame.cameras)?
        }
    };
    line["time_ns"] = json!(frame.time_ns);
    line["world_models"] = results
        .iter()
        .zip(jumps)
        .map(|(c, jump)| {
            json!({
                "team": c.robot.team.name(),
                "id": c.robot.identity.value(),
                "matched": c.matched,
                "overhead_robot": c.overhead_robot.map(|k| json!({"team": k.team.name(), "id": k.identity.value()})),
                "position_error_cm": c.position_error_cm,
                "heading_error_deg": c.heading_error_deg,
                "ball_error_cm": c.ball_error_cm,
                "measurements": c.measurements,
                "jump": jump,
            })
        })
        .collect();
    Ok(line)
}

fn offset_text(o: &ClockOffset) -> String {
    let start = match o.start {
        crate::wmd::clock::OffsetStart::SameClock => "searched from 0",
        crate::wmd::clock::OffsetStart::FirstMessages => "searched from the first messages",
    };
    let err = o
        .median_error_cm
        .map_or_else(|| "–".to_owned(), |e| format!("{e:.1} cm"));
    format!(
        "{:+.3} s ({start}; {} pairs, median position error {err})",
        o.offset_ns as f64 * 1e-9,
        o.pairs
    )
}

fn write_table(
    out: &mut impl Write,
    summaries: &[RobotSummary],
    offsets: &[(RobotKey, ClockOffset)],
) -> anyhow::Result<()> {
    let spread = |s: &Option<Spread>| {
        s.map_or_else(
            || "–".to_owned(),
            |s| format!("{:.1}/{:.1}", s.median, s.p95),
        )
    };
    writeln!(
        out,
        "{:<10} {:>6} {:>6} {:>8} {:>9} {:>13} {:>13} {:>13} {:>13} {:>13} {:>6} {:>9}  clock offset",
        "robot",
        "models",
        "marker",
        "position",
        "unmatched",
        "position cm",
        "heading °",
        "ball cm",
        "distance cm",
        "bearing °",
        "jumps",
        "until s"
    )?;
    for s in summaries {
        let offset = offsets
            .iter()
            .find(|o| o.0 == s.robot)
            .map(|o| offset_text(&o.1))
            .unwrap_or_default();
        writeln!(
            out,
            "{:<10} {:>6} {:>6} {:>8} {:>9} {:>13} {:>13} {:>13} {:>13} {:>13} {:>6} {:>9.3}  {offset}",
            s.robot.to_string(),
            s.world_models,
            s.by_marker,
            s.by_position,
            s.unmatched,
            spread(&s.position_cm),
            spread(&s.heading_deg),
            spread(&s.ball_cm),
            spread(&s.distance_cm),
            spread(&s.bearing_deg),
            s.jumps_ns.len(),
            s.last_ns as f64 * 1e-9,
        )?;
    }
    writeln!(
        out,
        "(median/p95 of the absolute errors; jumps: frames whose error jumped)"
    )?;
    Ok(())
}
