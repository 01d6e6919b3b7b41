//! What `eotn wmd` reads: the overhead cameras' field frames (one camera from the command line,
//! or a session's cameras merged as `eotn overhead detect --session` merges them) and the
//! robots' world models from their recordings.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, bail};

use super::field::FieldCamera;
use crate::model::world_model::{self, RobotKey, WorldModelMessage};
use crate::overhead::merge::{FieldPicture, SslCameraId, merge_detections};
use crate::overhead::recognise::OverheadDetections;
use crate::session::SessionSource;
use crate::streams::StreamReader;
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
/// camera; another camera's frame within half a frame period joins it.
///
/// # Errors
/// A camera's frame of another shape than its calibration. An unreadable frame is warned about
/// and left out.
pub fn field_frames(cameras: &mut [FieldCamera], single: bool) -> anyhow::Result<Vec<FieldFrame>> {
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

/// The world models of every robot, each in time order: (time on the robot's clock —
/// the message's `time_ns`, else the recording's log time —, message).
pub type RobotModels = BTreeMap<RobotKey, Vec<(u64, WorldModelMessage)>>;

/// Refuses sources `eotn wmd` cannot read yet, naming them.
///
/// # Errors
/// A live (`ws://`) or device source.
pub fn recorded(source: &SessionSource, what: &str) -> anyhow::Result<std::path::PathBuf> {
    match source {
        SessionSource::Recording(p) => Ok(p.clone()),
        SessionSource::Live(url) => bail!(
            "{what} {url}: `eotn wmd` reads recordings; a live source is not read here yet (record it with `eotn record` and give the recording)"
        ),
        SessionSource::Device(p) => bail!(
            "{what} {}: `eotn wmd` reads recordings; a camera device is not read here yet (record it with `eotn record`)",
            p.display()
        ),
    }
}

/// Reads the world models of one robot recording into `into`: every JSON message on
/// `/world_model` or `/world_model/<anything>`; with `only`, the messages naming that robot
/// (others counted and warned about). A message refused is warned about (the first few by
/// reason) and skipped.
///
/// # Errors
/// An unreadable recording, naming it; a recording with no world-model channel.
pub fn read_world_models(
    path: &Path,
    only: Option<RobotKey>,
    into: &mut RobotModels,
) -> anyhow::Result<usize> {
    let name = crate::frame::display_name(path);
    let mut reader = StreamReader::open(path).with_context(|| name.clone())?;
    let channels: Vec<u16> = reader
        .channels()
        .iter()
        .filter(|c| world_model::is_world_model_topic(&c.topic) && c.message_encoding == "json")
        .map(|c| c.id)
        .collect();
    if channels.is_empty() {
        bail!("{name}: no world-model channel (JSON on /world_model or /world_model/<name>)");
    }
    let (mut read, mut refused, mut others) = (0, 0_usize, 0_usize);
    reader
        .for_each_message(|m| {
            if !channels.contains(&m.channel) {
                return;
            }
            match world_model::parse(m.data) {
                Ok(w) if only.is_some_and(|k| k != w.robot) => others += 1,
                Ok(w) => {
                    let t = w.time_ns.unwrap_or(m.log_time_ns);
                    into.entry(w.robot).or_default().push((t, w));
                    read += 1;
                }
                Err(e) => {
                    refused += 1;
                    if refused <= 5 {
                        log::warn!("{name}: world model at {} ns skipped: {e}", m.log_time_ns);
                    }
                }
            }
        })
        .with_context(|| name.clone())?;
    if refused > 5 {
        log::warn!("{name}: {refused} world models skipped in all");
    }
    if let Some(k) = only.filter(|_| others > 0) {
        log::warn!("{name}: {others} world models of other robots than {k} left out");
    }
    for models in into.values_mut() {
        models.sort_by_key(|m| m.0);
    }
    Ok(read)
}
