//! The robots' world models a recording holds (docs/formats.md, "World models"): every JSON
//! message on `/world_model` or `/world_model/<anything>`, by robot and in time order. `eotn wmd`
//! reads its robots' recordings with it, and the app a session file's robots'.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, bail};

use super::StreamReader;
use crate::model::world_model::{self, RobotKey, WorldModelMessage};

/// The world models of every robot, each in time order: (time on the robot's clock —
/// the message's `time_ns`, else the recording's log time —, message).
pub type RobotModels = BTreeMap<RobotKey, Vec<(u64, WorldModelMessage)>>;

/// What one robot recording gave.
#[derive(Debug, Default)]
pub struct ReadModels {
    /// World models read.
    pub read: usize,
    /// The robots whose world models a session recording (`eotn wmd -o`) holds: logged at the
    /// overhead frame each was paired with, so they are taken at their log times with no clock
    /// offset (a replay pairs them as the session did).
    pub paired_when_recorded: Vec<RobotKey>,
}

/// Reads the world models of one robot recording into `into`: every JSON message on
/// `/world_model` or `/world_model/<anything>`; with `only`, the messages naming that robot
/// (others counted and warned about). A message refused is warned about (the first few by
/// reason) and skipped. A message's time is its `time_ns` (the robot's clock), else its log
/// time; in a session recording always its log time ([`ReadModels`]).
///
/// # Errors
/// An unreadable recording, naming it; a recording with no world-model channel.
pub fn read_world_models(
    path: &Path,
    only: Option<RobotKey>,
    into: &mut RobotModels,
) -> anyhow::Result<ReadModels> {
    let name = crate::frame::display_name(path);
    let mut reader = StreamReader::open(path).with_context(|| name.clone())?;
    let session = reader.info().source == super::WMD_SESSION_SOURCE;
    let mut keys = std::collections::BTreeSet::new();
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
                    let t = if session {
                        m.log_time_ns
                    } else {
                        w.time_ns.unwrap_or(m.log_time_ns)
                    };
                    keys.insert(w.robot);
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
    Ok(ReadModels {
        read,
        paired_when_recorded: if session {
            keys.into_iter().collect()
        } else {
            Vec::new()
        },
    })
}
