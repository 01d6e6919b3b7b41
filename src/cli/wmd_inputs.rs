//! What `eotn wmd` reads: the overhead cameras' field frames (one camera from the command line,
//! or a session's cameras merged as `eotn overhead detect --session` merges them) and the
//! robots' world models from their recordings; for a live session ([`open_live`]) every source
//! opened as a feed ([`super::wmd_feeds`]).

use std::path::Path;

use anyhow::{Context, bail};

use super::field::FieldCamera;
use crate::model::world_model::{RobotKey, WorldModelMessage};
use crate::overhead::merge::{FieldPicture, SslCameraId, merge_detections};
use crate::overhead::recognise::OverheadDetections;
use crate::session::SessionSource;
use crate::wmd::{OverheadRobotPose, OverheadView};

/// One field frame: the reference camera's frame time and what the cameras saw then.
#[derive(Debug)]
pub struct FieldFrame {
    /// The reference camera's frame time, nanoseconds on its recording's clock.
    pub time_ns: u64,
    /// One camera's detections (a single overhead camera), as `overhead detect` prints them.
    pub single: Option<OverheadDetections>,
    /// The merged picture (a session), as `overhead detect --session` prints it.
    pub picture: FieldPicture,
    /// The merged cameras' frames: id and time.
    pub cameras: Vec<(SslCameraId, u64)>,
}

impl FieldFrame {
    /// What the comparison takes.
    #[must_use]
    pub fn view(&self) -> OverheadView {
        OverheadView {
            ball: self.picture.ball.as_ref().map(|b| b.ball.field_cm),
            robots: self
                .picture
                .robots
                .iter()
                .map(|r| OverheadRobotPose {
                    key: RobotKey {
                        team: r.team,
                        identity: r.identity,
                    },
                    field_cm: r.field_cm,
                    heading_rad: r.heading_rad,
                })
                .collect(),
        }
    }
}

/// Runs every camera over its recording: one field frame per frame of the first (reference)
/// camera; another camera's frame within half a frame period joins it. With `ssl`, each
/// camera's detections are also sent as SSL-Vision packets.
///
/// # Errors
/// A camera's frame of another shape than its calibration. An unreadable frame is warned about
/// and left out.
pub fn field_frames(
    cameras: &mut [FieldCamera],
    single: bool,
    mut ssl: Option<&mut super::ssl_vision_out::SslOut>,
) -> anyhow::Result<Vec<FieldFrame>> {
    let times = super::field::frame_times(cameras);
    let reference = times.first().cloned().unwrap_or_default();
    let period_ns = crate::wmd::clock::frame_period_ns(&reference);
    let mut sizes: Vec<super::overhead::SizeCheck> = cameras
        .iter()
        .map(|_| super::overhead::SizeCheck::default())
        .collect();
    let bar = super::inputs::progress(reference.len(), "overhead");
    let mut out = Vec::with_capacity(reference.len());
    for (i, &t_ref) in reference.iter().enumerate() {
        let (views, frames) = super::field::field_views(cameras, &times, i, period_ns, &mut sizes)?;
        if let Some(out) = ssl.as_deref_mut() {
            for ((id, d), (_, time_ns)) in views.iter().zip(&frames) {
                out.send(super::ssl_vision_out::session_camera_id(*id), *time_ns, d);
            }
        }
        let refs: Vec<(SslCameraId, &OverheadDetections)> =
            views.iter().map(|(id, d)| (*id, d)).collect();
        let picture = merge_detections(&refs);
        out.push(FieldFrame {
            time_ns: t_ref,
            single: if single {
                views.into_iter().next().map(|v| v.1)
            } else {
                None
            },
            picture,
            cameras: frames,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(out)
}

/// The recording a source names, for a session of recordings only (a live session reads every
/// kind: [`open_live`]).
///
/// # Errors
/// A live (`ws://`) or device source.
pub fn recorded(source: &SessionSource, what: &str) -> anyhow::Result<std::path::PathBuf> {
    match source {
        SessionSource::Recording(p) => Ok(p.clone()),
        SessionSource::Live(url) => bail!("{what} {url}: a live source in a recorded session"),
        SessionSource::Device(p) => {
            bail!(
                "{what} {}: a camera device in a recorded session",
                p.display()
            )
        }
        SessionSource::Ssl(s) => bail!(
            "{what} {s}: SSL-Vision's detections are an overhead source, not a recording of \
             world models"
        ),
    }
}

/// Says which keys of a session `eotn wmd` does not use, so none is ignored silently: a robot's
/// `camera`, `lut` and `params` when its camera frames are not recorded (no `-o`, or a recorded
/// robot: only a live robot's frames are recorded and, with a table, recognised). (An overhead
/// camera's `intrinsics`: [`super::field::say_unused_intrinsics`].)
pub fn say_unused_session_keys(session: &crate::session::Session, output: bool, live: bool) {
    for (i, r) in session.robots.iter().enumerate() {
        let keys: Vec<&str> = [
            r.camera.as_ref().map(|_| "camera"),
            r.lut.as_ref().map(|_| "lut"),
            r.params.as_ref().map(|_| "params"),
        ]
        .into_iter()
        .flatten()
        .collect();
        let recorded = output && live && matches!(r.source, SessionSource::Live(_));
        if !keys.is_empty() && !recorded {
            log::warn!(
                "robots[{i}] ({} {}): {} not used: a robot's camera frames are recorded (and with \
                 a table recognised) only from a live robot into -o",
                r.team.name(),
                r.robot_id,
                keys.join(", ")
            );
        }
        if recorded && r.lut.is_none() && r.params.is_some() {
            log::warn!(
                "robots[{i}] ({} {}): params not used without a lut",
                r.team.name(),
                r.robot_id
            );
        }
    }
}

pub use crate::streams::world_models::{RobotModels, read_world_models};

/// A live session's sources opened: the field, the overhead cameras, each robot's feed with
/// the topic of its camera frames, its session entry and its name, each camera's files.
struct LiveOpened {
    field: crate::overhead::FieldDescription,
    cameras: Vec<super::wmd_live::LiveCamera>,
    robots: Vec<OpenedRobot>,
    files: Vec<crate::camera::CameraFiles>,
}

/// A robot's feed, the topic of its camera frames, its session entry, its name.
type OpenedRobot = (
    super::wmd_feeds::RobotFeed,
    String,
    Option<crate::session::RobotEntry>,
    String,
);

fn open_live_session(path: &Path, record: bool) -> anyhow::Result<LiveOpened> {
    let session = crate::session::Session::load(path)?;
    super::field::say_unused_intrinsics(&session);
    say_unused_session_keys(&session, record, true);
    let field = session
        .field
        .load()
        .with_context(|| format!("{}: field", path.display()))?;
    let mut cameras = Vec::new();
    let mut files = Vec::new();
    for e in &session.overhead {
        let pipeline = match (&e.source, &e.lut, &e.calibration) {
            (SessionSource::Ssl(_), ..) => None,
            (_, Some(lut), Some(cal)) => {
                let lut = super::inputs::load_lut_arg(lut)?;
                let cal = super::overhead::load_usable_calibration(cal)?;
                let params = match &e.params {
                    Some(p) => super::field::load_params(p)?,
                    None => super::overhead::params_for(&field),
                };
                Some(crate::overhead::OverheadPipeline::new(
                    lut, cal.camera, params,
                ))
            }
            _ => bail!("overhead camera {}: no table or calibration", e.id),
        };
        cameras.push(live_camera(e.id, &e.source, e.camera.as_deref(), pipeline)?);
        files.push(camera_files(e.lut.as_deref(), e.calibration.as_deref()));
    }
    let mut robots = Vec::new();
    for r in &session.robots {
        let key = RobotKey {
            team: r.team,
            identity: r.robot_id,
        };
        let wants = super::wmd_feeds::RobotWants {
            only: Some(key),
            frames: record.then(|| r.camera.clone()),
        };
        let topic = key.camera_topic();
        let name = format!("{key} ({})", source_name(&r.source));
        let feed = robot_feed(&r.source, wants, &key.to_string())?;
        robots.push((feed, topic, Some(r.clone()), name));
    }
    Ok(LiveOpened {
        field,
        cameras,
        robots,
        files,
    })
}

fn open_live_args(a: &super::wmd::Args, record: bool) -> anyhow::Result<LiveOpened> {
    let Some(overhead) = &a.overhead else {
        bail!("--overhead names the overhead camera (or give --session)");
    };
    let field = super::overhead::load_field(a.field.as_deref())?;
    let source = SessionSource::parse_arg(overhead);
    let pipeline = overhead_pipeline(a, &source, &field)?;
    let cameras = vec![live_camera(
        SslCameraId(0),
        &source,
        a.camera.get(),
        pipeline,
    )?];
    let mut robots = Vec::new();
    for (i, p) in a.robot.iter().enumerate() {
        let wants = super::wmd_feeds::RobotWants {
            only: None,
            frames: record.then_some(None),
        };
        let source = SessionSource::parse_arg(p);
        let feed = robot_feed(&source, wants, &p.display().to_string())?;
        let topic = format!("{}{}", crate::camera::SESSION_ROBOT_TOPIC_PREFIX, i + 1);
        robots.push((feed, topic, None, source_name(&source)));
    }
    Ok(LiveOpened {
        field,
        cameras,
        robots,
        files: vec![camera_files(a.lut.as_deref(), a.calibration.as_deref())],
    })
}

/// The pipeline of `--overhead`'s camera from `--lut` and `--calibration`; none for an
/// SSL-Vision source (whose packets hold detections: a table or calibration given is said to be
/// unused).
///
/// # Errors
/// An eotn camera without `--lut` or `--calibration`; an unreadable table or calibration.
pub fn overhead_pipeline(
    a: &super::wmd::Args,
    source: &SessionSource,
    field: &crate::overhead::FieldDescription,
) -> anyhow::Result<Option<crate::overhead::OverheadPipeline>> {
    if let SessionSource::Ssl(s) = source {
        if a.lut.is_some() || a.calibration.is_some() {
            log::warn!(
                "--lut, --calibration: not used: {s} is SSL-Vision, whose packets hold the \
                 detections"
            );
        }
        return Ok(None);
    }
    let (Some(lut), Some(cal)) = (&a.lut, &a.calibration) else {
        bail!(
            "--overhead {}: an eotn camera needs --lut and --calibration (only an SSL-Vision \
             source, udp://GROUP:PORT or a league .log, goes without)",
            source_name(source)
        );
    };
    Ok(Some(crate::overhead::OverheadPipeline::new(
        super::inputs::load_lut_arg(lut)?,
        super::overhead::load_usable_calibration(cal)?.camera,
        super::overhead::params_for(field),
    )))
}

/// Every source of a live session opened as a feed, and the recording started with `-o`.
///
/// # Errors
/// A malformed address, an unreadable table, calibration, parameter file or recording, a camera
/// device given as a robot (it sends no world models), a recording without world models.
pub fn open_live(
    a: &super::wmd::Args,
) -> anyhow::Result<(
    super::wmd_live::LiveInputs,
    Option<super::wmd_record::SessionRecorder>,
)> {
    let record = a.output.is_some();
    let LiveOpened {
        field,
        cameras,
        robots,
        files,
    } = match &a.session {
        Some(path) => open_live_session(path, record)?,
        None => open_live_args(a, record)?,
    };
    if a.output.is_some()
        && let Some(c) = cameras.iter().find(|c| c.pipeline.is_none())
    {
        bail!(
            "-o: {} is SSL-Vision, which sends no frames to record; record without -o, or keep \
             the league's log",
            c.name
        );
    }
    let recorder = match &a.output {
        Some(p) => {
            let described: Vec<super::wmd_record::RecordedCamera> = cameras
                .iter()
                .zip(files)
                .map(|(c, files)| super::wmd_record::RecordedCamera { id: c.id, files })
                .collect();
            let mut rec = super::wmd_record::SessionRecorder::create(p, &described)?;
            for (_, topic, entry, _) in &robots {
                if let Some(e) = entry.as_ref().filter(|e| e.lut.is_some()) {
                    rec.recognise(topic, robot_pipeline(e)?);
                    rec.name_robot_camera(
                        topic,
                        &crate::camera::CameraFiles {
                            lut: e.lut.clone(),
                            params: e.params.as_ref().map(|p| p.display().to_string()),
                            calibration: None,
                        },
                    )?;
                }
            }
            Some(rec)
        }
        None => None,
    };
    let robots = robots
        .into_iter()
        .map(|(feed, topic, _, name)| super::wmd_live::LiveRobotSource {
            name,
            topic,
            feed,
            received: 0,
        })
        .collect();
    let inputs = super::wmd_live::LiveInputs {
        field,
        cameras,
        robots,
    };
    Ok((inputs, recorder))
}

fn source_name(source: &SessionSource) -> String {
    match source {
        SessionSource::Live(url) => url.clone(),
        SessionSource::Device(p) => p.display().to_string(),
        SessionSource::Recording(p) => crate::frame::display_name(p),
        SessionSource::Ssl(s) => s.to_string(),
    }
}

fn camera_files(lut: Option<&Path>, calibration: Option<&Path>) -> crate::camera::CameraFiles {
    crate::camera::CameraFiles {
        lut: lut.map(Path::to_owned),
        params: None,
        calibration: calibration.map(Path::to_owned),
    }
}

/// A session robot's recogniser: its table and parameters.
fn robot_pipeline(e: &crate::session::RobotEntry) -> anyhow::Result<crate::pipeline::Pipeline> {
    let lut = e
        .lut
        .as_deref()
        .context("a robot's recogniser needs its table")?;
    let params = crate::pipeline::PipelineParams {
        recognition: super::detect::load_params(e.params.as_deref())?,
        ..crate::pipeline::PipelineParams::default()
    };
    Ok(crate::pipeline::Pipeline::new(
        super::inputs::load_lut_arg(lut)?,
        params,
    ))
}

/// An overhead camera's feed.
fn live_camera(
    id: SslCameraId,
    source: &SessionSource,
    topic: Option<&str>,
    pipeline: Option<crate::overhead::OverheadPipeline>,
) -> anyhow::Result<super::wmd_live::LiveCamera> {
    use super::wmd_feeds::OverheadFeed;
    let name = source_name(source);
    let feed = match source {
        SessionSource::Live(url) => OverheadFeed::live(url)?,
        SessionSource::Device(p) => OverheadFeed::device(p)?,
        SessionSource::Recording(p) => OverheadFeed::replay(p, topic)?,
        SessionSource::Ssl(s) => {
            OverheadFeed::Ssl(Box::new(super::wmd_ssl::SslOverheadFeed::open(s)?))
        }
    };
    if topic.is_some() && !matches!(source, SessionSource::Recording(_)) {
        log::warn!(
            "{name}: a camera topic is chosen only in recordings; the server's first camera is read"
        );
    }
    Ok(super::wmd_live::LiveCamera {
        id,
        name,
        pipeline,
        feed,
        connection: None,
    })
}

/// A robot's feed: a live robot's connection, or a recording's world models replayed.
fn robot_feed(
    source: &SessionSource,
    wants: super::wmd_feeds::RobotWants,
    what: &str,
) -> anyhow::Result<super::wmd_feeds::RobotFeed> {
    use super::wmd_feeds::RobotFeed;
    match source {
        SessionSource::Live(url) => RobotFeed::live(url, wants),
        SessionSource::Device(p) => bail!(
            "robot {what}: {} is a camera device; a robot's source sends its world models (a recording or a ws:// robot)",
            p.display()
        ),
        SessionSource::Ssl(s) => bail!(
            "robot {what}: {s} is SSL-Vision; a robot's source sends its world models (a \
             recording or a ws:// robot)"
        ),
        SessionSource::Recording(p) => {
            let mut models = RobotModels::new();
            read_world_models(p, wants.only, &mut models)?;
            let mut all: Vec<(u64, WorldModelMessage)> = models.into_values().flatten().collect();
            all.sort_by_key(|m| m.0);
            let first_ns = all.first().map_or(0, |m| m.0);
            Ok(RobotFeed::Replay {
                models: all,
                next: 0,
                first_ns,
            })
        }
    }
}
