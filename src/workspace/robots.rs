//! Robots over the network (Camera ▸ Connect to robot…): several connected at once, each on its
//! own thread, each receiving — and recording, bit-exact, into a file of its own — whether it
//! is shown or not. One robot is shown: its frames are the workspace's [`Source`] (the robot's
//! [`crate::live::RobotFrames`], a timeline that grows as frames arrive), so its sensor
//! readings, recognition, stepping back and playback work as for a recording. Following live,
//! the newest frame is shown as it arrives (its arrival wakes the UI); stepping, seeking, playing
//! or pausing holds the view while reception and recording go on.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use anyhow::Context as _;

use super::source::Source;
use super::{RobotsCommand, Workspace};
use crate::live::recorder::file_stem;
use crate::live::robot::DEFAULT_KEEP_BYTES;
use crate::live::{ClientOptions, Connection, LiveRobot, RobotStats, RobotUrl};
use crate::sources::CameraKind;

/// How often the UI looks for a shown robot's new frame: about twice its 30 fps.
const FOLLOW_POLL: Duration = Duration::from_millis(16);
/// How often the robots' figures are refreshed when no robot is followed live.
const STATS_POLL: Duration = Duration::from_millis(250);

/// Wakes the UI (the app passes its repaint request), from a robot's thread.
pub type Wake = Arc<dyn Fn() + Send + Sync>;

/// The UI's wake, set once by the app; robots connected before it is set wake nothing.
#[derive(Default, Clone)]
struct WakeSlot(Arc<OnceLock<Wake>>);

impl fmt::Debug for WakeSlot {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.get().is_some() {
            "WakeSlot(set)"
        } else {
            "WakeSlot(unset)"
        })
    }
}

/// A connected robot's identity in this workspace (its place in the robots list never moves).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RobotId(pub u32);

impl fmt::Display for RobotId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "robot #{}", self.0)
    }
}

/// One line of the robots list.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotRow {
    /// Its identity.
    pub id: RobotId,
    /// The robot's server name (its address until it says).
    pub name: String,
    /// Its address.
    pub url: RobotUrl,
    /// Connected, reconnecting (with why the connection closed) or connecting.
    pub connection: Connection,
    /// Frames, drops, frame rate, latency.
    pub stats: RobotStats,
    /// The file its recording goes to, while recording.
    pub recording: Option<PathBuf>,
    /// True for the robot the views show.
    pub shown: bool,
}

/// A connected robot and what the workspace last reported about it.
#[derive(Debug)]
struct Entry {
    id: RobotId,
    robot: LiveRobot,
    /// The connection state last reported in the status line.
    reported: Connection,
    /// The recording last seen running (to report one the robot's thread had to stop).
    recording: Option<PathBuf>,
    /// True while shown: only the shown robot's new frames wake the UI.
    shown: Arc<AtomicBool>,
}

/// The connected robots; see the module documentation.
#[derive(Debug, Default)]
pub struct Robots {
    entries: Vec<Entry>,
    shown: Option<RobotId>,
    /// True when the user chose the shown robot; false when the workspace did (the first robot
    /// connected, the next after a disconnection), which it may then change (see
    /// [`Workspace::poll_robots`]).
    chosen: bool,
    follow_live: bool,
    next_id: u32,
    wake: WakeSlot,
    /// The shown robot's camera whose own files (table, parameters) were last applied: a
    /// robot names its cameras only once connected, so they are applied when it does.
    camera_applied: Option<crate::camera::CameraId>,
}

impl Robots {
    /// Forgets which robot is shown (another source took the views); they all keep receiving.
    pub(super) fn unshow(&mut self) {
        self.set_shown(None);
        self.follow_live = false;
    }

    fn set_shown(&mut self, id: Option<RobotId>) {
        self.shown = id;
        self.camera_applied = None;
        for e in &self.entries {
            e.shown.store(Some(e.id) == id, Ordering::Relaxed);
        }
    }

    fn entry(&self, id: RobotId) -> anyhow::Result<&Entry> {
        self.entries
            .iter()
            .find(|e| e.id == id)
            .with_context(|| format!("no {id} connected"))
    }
}

/// True when two states say the same to the user (a retry's changing wait is not news).
fn same_state(a: &Connection, b: &Connection) -> bool {
    match (a, b) {
        (
            Connection::Disconnected { reason: x, .. },
            Connection::Disconnected { reason: y, .. },
        ) => x == y,
        _ => a == b,
    }
}

impl Workspace {
    /// Applies a robot command (the robots list, the shown robot, their recordings).
    pub(super) fn apply_robot_command(&mut self, command: RobotsCommand) -> anyhow::Result<()> {
        match command {
            RobotsCommand::ConnectRobot(address) => self.connect_robot(&address).map(drop),
            RobotsCommand::ShowRobot(id) => {
                self.show_robot(id)?;
                self.robots.chosen = true;
                Ok(())
            }
            RobotsCommand::DisconnectRobot(id) => self.disconnect_robot(id),
            RobotsCommand::RecordRobot(id, path) => self.record_robot(id, &path),
            RobotsCommand::RecordAllRobots(folder) => self.record_all_robots(&folder),
            RobotsCommand::StopRecordingRobot(id) => self.stop_recording_robot(id),
            RobotsCommand::SetFollowLive(on) => self.set_follow_live(on),
        }
    }

    /// Connects a robot at `address` (`HOST:PORT` or `ws://HOST:PORT`) beside those already
    /// connected; it is shown when no robot is. Connecting goes on in the background.
    pub(super) fn connect_robot(&mut self, address: &str) -> anyhow::Result<RobotId> {
        let url: RobotUrl = address.parse()?;
        anyhow::ensure!(
            !self.robots.entries.iter().any(|e| *e.robot.url() == url),
            "{url} is connected already"
        );
        let shown = Arc::new(AtomicBool::new(false));
        let wake: crate::live::robot::Notify = {
            let (shown, slot) = (Arc::clone(&shown), self.robots.wake.clone());
            Arc::new(move || {
                if shown.load(Ordering::Relaxed)
                    && let Some(wake) = slot.0.get()
                {
                    wake();
                }
            })
        };
        let robot = LiveRobot::connect(
            url.clone(),
            ClientOptions::default(),
            DEFAULT_KEEP_BYTES,
            Some(wake),
        )
        .with_context(|| format!("cannot start the connection to {url}"))?;
        let id = RobotId(self.robots.next_id);
        self.robots.next_id += 1;
        self.robots.entries.push(Entry {
            id,
            robot,
            reported: Connection::Connecting,
            recording: None,
            shown,
        });
        self.status = format!("connecting to {url}");
        if self.robots.shown.is_none() {
            self.show_robot(id)?;
        }
        Ok(id)
    }

    /// Shows robot `id` in the views, following its newest frame; the others keep receiving.
    pub(super) fn show_robot(&mut self, id: RobotId) -> anyhow::Result<()> {
        let view = self.robots.entry(id)?.robot.frames_view();
        self.close_side_by_side()?;
        self.disconnect_live();
        self.stop_recording_recorded();
        self.source = Some(Source::robot(view));
        self.robots.set_shown(Some(id));
        self.robots.chosen = false;
        self.robots.follow_live = true;
        self.use_table_of(CameraKind::Robot);
        self.player.stop();
        self.try_edit = None;
        self.current = None;
        self.index = 0;
        self.sensor_series = super::SensorSeries::default();
        self.frame_generation += 1;
        self.status = format!("showing {}", self.connected_label());
        self.follow_newest();
        self.apply_robot_camera_files();
        Ok(())
    }

    /// Shows another camera of the shown robot (`source`: its frames), following its newest
    /// frame when the robot was followed live.
    pub(super) fn show_robot_camera(&mut self, source: Source) -> anyhow::Result<()> {
        anyhow::ensure!(self.robots.shown.is_some(), "no robot shown");
        self.close_side_by_side()?;
        let total = source.len();
        self.robots.camera_applied = source.camera_id();
        self.source = Some(source);
        self.try_edit = None;
        self.current = None;
        self.selection = None;
        self.sensor_series = super::SensorSeries {
            total,
            ..super::SensorSeries::default()
        };
        self.frame_generation += 1;
        if self.robots.follow_live {
            self.follow_newest();
        }
        Ok(())
    }

    /// The camera now shown (focused side by side) came with its own table and parameters:
    /// nothing is to be applied for it.
    pub(super) fn robot_camera_shown(&mut self) {
        if self.robots.shown.is_some() {
            self.robots.camera_applied = self.source.as_ref().and_then(Source::camera_id);
        }
    }

    /// Once the shown robot names its camera: that camera's own table and parameters, as
    /// remembered for it (a table with unsaved edits is kept, said as a warning).
    fn apply_robot_camera_files(&mut self) {
        let Some(id) = self
            .source
            .as_ref()
            .filter(|s| s.robot_frames().is_some())
            .and_then(Source::camera_id)
        else {
            return;
        };
        if self.robots.camera_applied.as_ref() == Some(&id) {
            return;
        }
        self.robots.camera_applied = Some(id.clone());
        let files = self.camera_files(&id);
        if let Some(t) = &files.lut
            && self.table_path() != Some(t.as_path())
        {
            if self.dirty {
                self.warn(format!(
                    "camera {}: its table {} is not opened: the table shown has unsaved edits",
                    id.topic(),
                    crate::frame::display_name(t)
                ));
            } else if let Err(e) = self.open_table(t) {
                self.warn(format!("{e:#}"));
            }
        }
        if let Err(e) = self.open_camera_files(&id, &files) {
            self.warn(format!("{e:#}"));
        }
    }

    /// Disconnects robot `id`, finishing its recording; another robot is shown if it was.
    pub(super) fn disconnect_robot(&mut self, id: RobotId) -> anyhow::Result<()> {
        let pos = self
            .robots
            .entries
            .iter()
            .position(|e| e.id == id)
            .with_context(|| format!("no {id} connected"))?;
        let entry = self.robots.entries.remove(pos);
        let name = entry.robot.name();
        self.status = match entry.robot.stop_recording() {
            Ok(Some((path, n))) => format!(
                "disconnected {name}; recorded {n} frames into {}",
                path.display()
            ),
            Ok(None) => format!("disconnected {name}"),
            Err(e) => {
                self.warn(format!("recording of {name} stopped: {e}"));
                format!("disconnected {name}")
            }
        };
        if self.robots.shown == Some(id) {
            self.robots.unshow();
            self.source = None;
            self.current = None;
            self.player.stop();
            self.try_edit = None;
            self.frame_generation += 1;
            if let Some(next) = self.robots.entries.first().map(|e| e.id) {
                let status = self.status.clone();
                self.show_robot(next)?;
                self.status = status;
            }
        }
        Ok(())
    }

    /// Records robot `id` into `path` with its own bit-exact recorder (every message as it
    /// arrives, whether shown or not).
    pub(super) fn record_robot(&mut self, id: RobotId, path: &Path) -> anyhow::Result<()> {
        anyhow::ensure!(
            crate::streams::is_stream_file(path),
            "{}: a recording is an MCAP stream: name it NAME.mcap",
            path.display()
        );
        let entry = self.robots.entry(id)?;
        anyhow::ensure!(
            entry.robot.recording_path().is_none(),
            "{} is recording already",
            entry.robot.name()
        );
        entry.robot.start_recording(path)?;
        let name = entry.robot.name();
        if let Some(e) = self.robots.entries.iter_mut().find(|e| e.id == id) {
            e.recording = Some(path.to_owned());
        }
        self.status = format!("recording {name} into {}", path.display());
        Ok(())
    }

    /// Records every robot not recording yet into `folder`, one file per robot named after it.
    pub(super) fn record_all_robots(&mut self, folder: &Path) -> anyhow::Result<()> {
        anyhow::ensure!(!self.robots.entries.is_empty(), "no robot connected");
        crate::atomic_file::output_folder(folder)
            .with_context(|| format!("{}", folder.display()))?;
        let mut started = 0;
        let ids: Vec<RobotId> = self
            .robots
            .entries
            .iter()
            .filter(|e| e.robot.recording_path().is_none())
            .map(|e| e.id)
            .collect();
        for id in ids {
            let path = self.robot_recording_path(id, folder);
            self.record_robot(id, &path)?;
            started += 1;
        }
        self.status = format!("recording {started} robots into {}", folder.display());
        Ok(())
    }

    /// A file in `folder` for robot `id`'s recording, named after the robot, not used yet.
    #[must_use]
    pub fn robot_recording_path(&self, id: RobotId, folder: &Path) -> PathBuf {
        let stem = self.robots.entry(id).map_or_else(
            |_| id.0.to_string(),
            |e| {
                // Until a robot names itself its name is its address: HOST_PORT then.
                let name = e.robot.name();
                let named = name != e.robot.url().to_string();
                file_stem(if named { &name } else { "" }, e.robot.url())
            },
        );
        let mut path = folder.join(format!("{stem}.mcap"));
        let mut n = 2;
        while path.exists() || self.robot_recording_to(&path) {
            path = folder.join(format!("{stem}-{n}.mcap"));
            n += 1;
        }
        path
    }

    fn robot_recording_to(&self, path: &Path) -> bool {
        self.robots
            .entries
            .iter()
            .any(|e| e.robot.recording_path().as_deref() == Some(path))
    }

    /// Finishes robot `id`'s recording.
    pub(super) fn stop_recording_robot(&mut self, id: RobotId) -> anyhow::Result<()> {
        let entry = self.robots.entry(id)?;
        let name = entry.robot.name();
        let (path, n) = entry
            .robot
            .stop_recording()?
            .with_context(|| format!("{name} is not recording"))?;
        if let Some(e) = self.robots.entries.iter_mut().find(|e| e.id == id) {
            e.recording = None;
        }
        self.status = format!("recorded {n} frames of {name} into {}", path.display());
        Ok(())
    }

    /// Follows the shown robot's newest frame (true) or holds the view where it is (false).
    pub(super) fn set_follow_live(&mut self, on: bool) -> anyhow::Result<()> {
        anyhow::ensure!(self.robots.shown.is_some(), "no robot shown");
        self.robots.follow_live = on;
        if on {
            self.player.stop();
            self.follow_newest();
        }
        Ok(())
    }

    /// A step, seek or playback holds the view (reception and recording go on).
    pub(super) fn leave_live(&mut self) {
        self.robots.follow_live = false;
    }

    /// Once per UI frame: reports connection changes in the status line, closes idle
    /// recordings' chunks, and shows the shown robot's newest frame when following it.
    pub(super) fn poll_robots(&mut self) {
        let mut notes = Vec::new();
        let mut shown_changed = false;
        for e in &mut self.robots.entries {
            e.robot.tick();
            let name = e.robot.name();
            let now = e.robot.connection();
            if !same_state(&now, &e.reported) {
                let was_down = matches!(e.reported, Connection::Disconnected { .. });
                notes.push(match &now {
                    Connection::Disconnected { reason, .. } => (
                        true,
                        format!("{name}: connection closed: {reason}; reconnecting"),
                    ),
                    Connection::Connected(_) if was_down => (false, format!("{name}: reconnected")),
                    _ => (false, format!("{name}: {now}")),
                });
                e.reported = now;
                shown_changed |= self.robots.shown == Some(e.id);
            }
            let recording = e.robot.recording_path();
            if e.recording.is_some() && recording.is_none() {
                let why = e.robot.log().pop().unwrap_or_default();
                notes.push((true, format!("{name}: {why}")));
            }
            e.recording = recording;
        }
        if shown_changed && let Some(src) = self.source.as_mut() {
            // Its label (title, status) carries the name it gave on connecting.
            src.refresh_info();
        }
        for (warning, note) in notes {
            if warning {
                self.warn(note.clone());
            }
            self.status = note;
        }
        self.show_a_robot_with_frames();
        self.apply_robot_camera_files();
        if self.robots.follow_live {
            self.follow_newest();
        }
        if self.robots.shown.is_some() {
            // Cameras beside the robot's shown one gain frames too.
            self.sync_beside();
        }
        if self.robots.shown.is_some()
            && let Some(src) = &self.source
        {
            // The sensor dialog's plots grow with the frames that arrive.
            self.sensor_series.total = src.len();
        }
    }

    /// When the workspace (not the user) chose the shown robot and it has never delivered a frame
    /// and is not connected (a wrong address, a robot switched off), shows the first robot that
    /// has frames instead: the image is not left empty while the others stream.
    fn show_a_robot_with_frames(&mut self) {
        let Some(shown) = self.robots.shown.filter(|_| !self.robots.chosen) else {
            return;
        };
        let stuck = self.robots.entry(shown).is_ok_and(|e| {
            e.robot.is_empty() && matches!(e.robot.connection(), Connection::Disconnected { .. })
        });
        if !stuck {
            return;
        }
        let other = self
            .robots
            .entries
            .iter()
            .find(|e| e.id != shown && !e.robot.is_empty())
            .map(|e| e.id);
        if let Some(next) = other {
            let status = self.status.clone();
            if let Err(e) = self.show_robot(next) {
                self.warn(format!("{e:#}"));
            }
            self.status = status;
        }
    }

    /// Shows the shown robot's camera's newest frame if it is not shown yet (or has gained its
    /// sensor readings since).
    pub(super) fn follow_newest(&mut self) {
        let Some(latest) = self
            .robots
            .shown
            .and(self.source.as_ref())
            .and_then(Source::robot_frames)
            .and_then(crate::live::RobotFrames::latest)
        else {
            return;
        };
        let stale = match &self.current {
            None => true,
            Some(c) => {
                self.index != latest.index
                    || (c.sensors.is_none() && latest.record.sensors.is_some())
                    || c.extra.len() != latest.record.extra.len()
            }
        };
        if stale && let Err(e) = self.seek(latest.index) {
            self.warn(format!("{e:#}"));
        }
    }

    /// While robots are connected, how soon the UI should look again: often while a shown
    /// robot is followed live, now and then for the list's figures.
    pub(super) fn robots_poll_due(&self) -> Option<Duration> {
        if self.robots.entries.is_empty() {
            None
        } else if self.robots.follow_live {
            Some(FOLLOW_POLL)
        } else {
            Some(STATS_POLL)
        }
    }

    fn connected_label(&self) -> String {
        self.source
            .as_ref()
            .map_or_else(String::new, super::Source::label)
    }

    /// Lets a shown robot's new frame wake the UI at once (the app passes its repaint request),
    /// rather than wait for the next look. Set once; later calls are ignored.
    pub fn set_wake(&mut self, wake: Wake) {
        let _ = self.robots.wake.0.set(wake);
    }

    // ---- reading ----

    /// The connected robots, in the order they were connected.
    #[must_use]
    pub fn robots(&self) -> Vec<RobotRow> {
        self.robots
            .entries
            .iter()
            .map(|e| RobotRow {
                id: e.id,
                name: e.robot.name(),
                url: e.robot.url().clone(),
                connection: e.robot.connection(),
                stats: e.robot.stats(),
                recording: e.robot.recording_path(),
                shown: self.robots.shown == Some(e.id),
            })
            .collect()
    }

    /// The robot the views show, if one is.
    #[must_use]
    pub const fn shown_robot(&self) -> Option<RobotId> {
        self.robots.shown
    }

    /// True while the views follow the shown robot's newest frame.
    #[must_use]
    pub const fn following_live(&self) -> bool {
        self.robots.follow_live
    }

    /// The shown robot's recording file, while it records.
    #[must_use]
    pub(super) fn shown_robot_recording(&self) -> Option<PathBuf> {
        let id = self.robots.shown?;
        self.robots.entry(id).ok()?.robot.recording_path()
    }

    /// Robot `id`'s log (connections, closed connections, skipped messages).
    #[must_use]
    pub fn robot_log(&self, id: RobotId) -> Vec<String> {
        self.robots
            .entry(id)
            .map(|e| e.robot.log())
            .unwrap_or_default()
    }

    /// Frames robot `id` has received (whether shown or not).
    #[must_use]
    pub fn robot_frames(&self, id: RobotId) -> Option<crate::live::RobotFrames> {
        self.robots.entry(id).ok().map(|e| e.robot.frames_view())
    }
}
