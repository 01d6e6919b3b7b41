//! [`LiveRobot`]: one robot's live frames, statistics and recording, filled by its
//! [`RobotClient`] thread and read by the app or the CLI at any time.
//!
//! Every frame that arrives is numbered from 0 in arrival order; the newest ones are kept in
//! memory (up to a byte budget) so a viewer can step back through them while reception goes on;
//! a recording keeps all of them. A frame's JSON messages (sensors, world model) attach to the
//! frame with the same log time, whether they come just before or just after its image.
//!
//! A robot with several image channels (a NAO's top and bottom cameras) has a camera for each
//! (`CameraFrames`): the first — the canonical `/camera/image`, else the first advertised —
//! is the one shown and counted in the statistics; each other camera keeps its own frames and
//! arrival times on the same clock ([`LiveRobot::camera_view`]), and a channel `CAMERA/sensors`
//! (or `…/recognition`, `…/ground_truth`) goes with that camera's frames.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use super::attach::{attach, image_kind};
use super::camera_frames::CameraFrames;
use super::client::{ClientOptions, LiveEvent, RobotClient};
use super::gaps::Gap;
use super::protocol::AdvertisedChannel;
use super::recorder::{LiveRecorder, MAX_CHANNELS, Recorded};
use super::{RobotUrl, unix_time_ns};
use crate::camera::CameraChannel;
use crate::formats::tf::TfTree;
use crate::formats::{ImageMessage, MessageKind, ros2};
use crate::sensors::SensorReadings;
use crate::streams::{FrameRecord, IMAGE_TOPIC, StreamError, StreamInfo};

mod frames;
pub use frames::RobotFrames;

/// Frame bytes kept in memory per robot unless told otherwise (about 2,000 ERS-7 frames).
pub const DEFAULT_KEEP_BYTES: usize = 128 << 20;
/// Latencies kept for the median and 99th percentile.
const LATENCY_WINDOW: usize = 4096;
/// Lines kept in a robot's log.
const LOG_LINES: usize = 50;

/// One frame as it arrived.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveFrame {
    /// Arrival number, from 0.
    pub index: usize,
    /// The frame and the JSON channels that came with it; `time_ns` is the sender's log time.
    pub record: FrameRecord,
    /// When its image was read off the socket, nanoseconds since the Unix epoch.
    pub received_ns: u64,
    /// From the sender's log time to the frame in this state, nanoseconds (0 when the sender's
    /// clock is ahead).
    pub latency_ns: u64,
}

/// The state of a robot's connection.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Connection {
    /// Not connected yet.
    Connecting,
    /// Connected; the robot's server name.
    Connected(String),
    /// The connection ended; retrying.
    Disconnected {
        /// Why.
        reason: String,
        /// Wait before the next attempt.
        retry_in: Duration,
    },
}

impl std::fmt::Display for Connection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Connecting => write!(f, "connecting…"),
            Self::Connected(_) => write!(f, "connected"),
            Self::Disconnected { reason, retry_in } => write!(
                f,
                "closed: {reason}; reconnecting in {:.1} s",
                retry_in.as_secs_f64()
            ),
        }
    }
}

/// A robot's figures for the connected-robots list.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RobotStats {
    /// Frames received.
    pub frames: usize,
    /// Frames lost: images that did not decode, plus gaps in the frame times longer than 1.5
    /// frame periods (counted as the frames that would fit).
    pub drops: usize,
    /// Frames received in the last second.
    pub fps: f64,
    /// Median latency over the last frames, milliseconds.
    pub latency_median_ms: Option<f64>,
    /// 99th percentile latency over the last frames, milliseconds.
    pub latency_p99_ms: Option<f64>,
    /// Times the connection was (re)established.
    pub connections: usize,
    /// Frames written to the open recording, if any.
    pub recorded: Option<usize>,
    /// The robot's latest misbehaviour, one line (garbage, a message too large, a deadline
    /// missed, a limit reached), with how often it happened; kept after it reconnects.
    pub problem: Option<String>,
}

/// A robot's latest misbehaviour and how many times in a row it was the same.
#[derive(Debug, Clone, Default)]
struct Problem {
    text: String,
    times: usize,
}

#[derive(Default)]
struct Inner {
    name: Option<String>,
    connection: Option<Connection>,
    /// The robot's cameras, the one shown first (see the module documentation); empty until
    /// an image channel is advertised.
    cameras: Vec<CameraFrames>,
    drops: usize,
    connections: usize,
    arrivals: VecDeque<Instant>,
    latencies: VecDeque<u64>,
    /// JSON messages waiting for their frame's image (the camera they go with, their channel,
    /// log time and bytes), and their bytes (bounded by the client's [`super::Limits`]:
    /// `queue`, messages and bytes).
    pending: VecDeque<(usize, Arc<AdvertisedChannel>, u64, Vec<u8>)>,
    pending_bytes: usize,
    queue: (usize, usize),
    problem: Option<Problem>,
    recorder: Option<LiveRecorder>,
    log: VecDeque<String>,
    /// When the first frame of any camera arrived (the origin of the arrival times).
    first_arrival: Option<Instant>,
    /// The robot's transform tree (`/tf`, `/tf_static`), for the camera's pose.
    tf: TfTree,
    /// The "grey frames" note was given.
    grey_noted: bool,
}

/// Called after each new frame (the app passes its repaint request).
pub type Notify = Arc<dyn Fn() + Send + Sync>;

/// A connected robot: its [`RobotClient`] and the frames it delivered.
pub struct LiveRobot {
    url: RobotUrl,
    shared: Arc<Mutex<Inner>>,
    client: Option<RobotClient>,
}

impl std::fmt::Debug for LiveRobot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveRobot")
            .field("url", &self.url)
            .finish_non_exhaustive()
    }
}

impl LiveRobot {
    /// Connects to a robot (in the background: reconnecting until dropped). At most `keep_bytes`
    /// of frame data stay in memory; `notify` runs after every new frame.
    ///
    /// # Errors
    /// The OS's error when the connection thread cannot start.
    pub fn connect(
        url: RobotUrl,
        options: ClientOptions,
        keep_bytes: usize,
        notify: Option<Notify>,
    ) -> std::io::Result<Self> {
        let shared = Arc::new(Mutex::new(Inner {
            connection: Some(Connection::Connecting),
            queue: (options.limits.queue_messages, options.limits.queue_bytes),
            ..Inner::default()
        }));
        let client = RobotClient::spawn(url.clone(), options, {
            let shared = Arc::clone(&shared);
            move |event| {
                let new_frame = lock(&shared).event(event, keep_bytes);
                if new_frame && let Some(n) = &notify {
                    n();
                }
            }
        })?;
        Ok(Self {
            url,
            shared,
            client: Some(client),
        })
    }

    /// The robot's address.
    #[must_use]
    pub fn url(&self) -> &RobotUrl {
        &self.url
    }

    /// The robot's server name once it said it, else its address.
    #[must_use]
    pub fn name(&self) -> String {
        self.frames_view().name()
    }

    /// The connection's state.
    #[must_use]
    pub fn connection(&self) -> Connection {
        self.frames_view().connection()
    }

    /// Frames of the shown camera received so far (the next frame's index).
    #[must_use]
    pub fn len(&self) -> usize {
        self.frames_view().len()
    }

    /// True before the first frame.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Index of the oldest frame still in memory (`len()` when none is).
    #[must_use]
    pub fn first_kept(&self) -> usize {
        self.frames_view().first_kept()
    }

    /// Frame `index` if it is still in memory.
    #[must_use]
    pub fn frame(&self, index: usize) -> Option<Arc<LiveFrame>> {
        self.frames_view().frame(index)
    }

    /// The newest frame.
    #[must_use]
    pub fn latest(&self) -> Option<Arc<LiveFrame>> {
        self.frames_view().latest()
    }

    /// A handle on the shown camera's frames for a viewer to step through while reception
    /// goes on.
    #[must_use]
    pub fn frames_view(&self) -> RobotFrames {
        RobotFrames {
            url: self.url.clone(),
            shared: Arc::clone(&self.shared),
            camera: None,
        }
    }

    /// A handle on the frames of the robot's camera `topic` (see [`RobotFrames::camera_view`]).
    #[must_use]
    pub fn camera_view(&self, topic: &str) -> RobotFrames {
        self.frames_view().camera_view(topic)
    }

    /// Where the running recording goes, if one runs.
    #[must_use]
    pub fn recording_path(&self) -> Option<PathBuf> {
        lock(&self.shared)
            .recorder
            .as_ref()
            .map(|r| r.path().to_owned())
    }

    /// The figures for the robot list.
    #[must_use]
    pub fn stats(&self) -> RobotStats {
        lock(&self.shared).stats()
    }

    /// The robot's log: connections, disconnections, skipped messages, its status messages.
    #[must_use]
    pub fn log(&self) -> Vec<String> {
        lock(&self.shared).log.iter().cloned().collect()
    }

    /// Starts recording every message from now on into `path` (an MCAP stream). A recording
    /// already running is finished first.
    ///
    /// # Errors
    /// [`StreamError`] when a file cannot be created or finished.
    pub fn start_recording(&self, path: &Path) -> Result<(), StreamError> {
        let info = StreamInfo {
            source: "robot".to_owned(),
            description: format!("live from {} ({})", self.name(), self.url),
        };
        let recorder = LiveRecorder::create(path, &info)?;
        let old = lock(&self.shared).recorder.replace(recorder);
        if let Some(old) = old {
            old.finish()?;
        }
        Ok(())
    }

    /// Finishes the recording (indexes written, file renamed into place) and returns its path
    /// and frame count; `None` when none was running.
    ///
    /// # Errors
    /// [`StreamError`] when the file cannot be finished.
    pub fn stop_recording(&self) -> Result<Option<(PathBuf, usize)>, StreamError> {
        let recorder = lock(&self.shared).recorder.take();
        recorder
            .map(|r| {
                let frames = r.frames();
                r.finish().map(|p| (p, frames))
            })
            .transpose()
    }

    /// Closes a recording's open chunk when the robot has been quiet (call now and then).
    pub fn tick(&self) {
        let mut inner = lock(&self.shared);
        if let Some(r) = inner.recorder.as_mut()
            && let Err(e) = r.tick()
        {
            inner.recording_failed(&e);
        }
    }
}

impl Drop for LiveRobot {
    /// Tells the connection thread to end (without waiting: the UI never waits on a socket) and
    /// finishes the recording with what has arrived.
    fn drop(&mut self) {
        drop(self.client.take());
        if let Ok(Some((path, _))) = self.stop_recording() {
            log::info!("recording finished: {}", path.display());
        }
    }
}

/// Locks the robot's state; a panic on another thread never makes it unreadable.
fn lock(shared: &Mutex<Inner>) -> MutexGuard<'_, Inner> {
    shared
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn percentile(sorted: &[u64], p: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let at = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted.get(at).map(|&ns| ns as f64 / 1e6)
}

impl Inner {
    fn stats(&self) -> RobotStats {
        let mut sorted: Vec<u64> = self.latencies.iter().copied().collect();
        sorted.sort_unstable();
        let now = Instant::now();
        let recent = self
            .arrivals
            .iter()
            .filter(|t| now.duration_since(**t) <= Duration::from_secs(1))
            .count();
        let fps = recent as f64;
        RobotStats {
            frames: self.cameras.first().map_or(0, |c| c.received),
            drops: self.drops,
            fps,
            latency_median_ms: percentile(&sorted, 0.5),
            latency_p99_ms: percentile(&sorted, 0.99),
            connections: self.connections,
            recorded: self.recorder.as_ref().map(LiveRecorder::frames),
            problem: self.problem.as_ref().map(|p| match p.times {
                1 => p.text.clone(),
                n => format!("{} ({n} times)", p.text),
            }),
        }
    }

    /// Notes a misbehaviour: the robots list shows the latest.
    fn problem(&mut self, text: &str) {
        match &mut self.problem {
            Some(p) if p.text == text => p.times += 1,
            _ => {
                self.problem = Some(Problem {
                    text: text.to_owned(),
                    times: 1,
                });
            }
        }
    }

    fn note(&mut self, line: String) {
        log::info!("{line}");
        if self.log.len() >= LOG_LINES {
            self.log.pop_front();
        }
        self.log.push_back(line);
    }

    fn recording_failed(&mut self, e: &StreamError) {
        self.note(format!("recording stopped: {e}"));
        self.recorder = None;
    }

    /// Applies one event; true when it made a new frame.
    fn event(&mut self, event: LiveEvent, keep_bytes: usize) -> bool {
        match event {
            LiveEvent::Connected { server_name } => {
                self.connections += 1;
                let again = if self.connections > 1 { "re" } else { "" };
                self.note(format!("{again}connected to {server_name}"));
                self.name = Some(server_name.clone());
                self.connection = Some(Connection::Connected(server_name));
                for c in &mut self.cameras {
                    c.gaps.forget_last();
                }
                false
            }
            LiveEvent::Advertised(channels) => {
                self.choose_camera(&channels);
                for c in channels {
                    let read = MessageKind::of(&c.schema_name, &c.encoding).is_some();
                    if !read && c.encoding != "json" && image_kind(&c).is_none() {
                        self.note(format!(
                            "channel {} ({} {}) is recorded, not shown",
                            c.topic, c.schema_name, c.encoding
                        ));
                    }
                }
                false
            }
            LiveEvent::Status(s) => {
                self.note(format!("robot says {s}"));
                false
            }
            LiveEvent::Warning(w) => {
                self.problem(&w);
                self.note(w);
                false
            }
            LiveEvent::Disconnected {
                reason,
                fault,
                retry_in,
            } => {
                if fault {
                    self.problem(&reason);
                }
                if !matches!(&self.connection, Some(Connection::Disconnected { reason: r, .. }) if *r == reason)
                {
                    self.note(format!("disconnected: {reason}; reconnecting"));
                }
                self.connection = Some(Connection::Disconnected { reason, retry_in });
                self.pending.clear();
                self.pending_bytes = 0;
                if let Some(r) = self.recorder.as_mut()
                    && let Err(e) = r.tick()
                {
                    self.recording_failed(&e);
                }
                false
            }
            LiveEvent::Message {
                channel,
                log_time_ns,
                received_ns,
                payload,
            } => {
                self.record(&channel, log_time_ns, &payload);
                match image_kind(&channel) {
                    Some(kind) => match self.camera_index(&channel.topic) {
                        Some(camera) => {
                            let message = ImageMessageIn {
                                kind,
                                log_time_ns,
                                received_ns,
                                payload: &payload,
                            };
                            self.image(camera, &message, keep_bytes)
                        }
                        None => false,
                    },
                    None if MessageKind::of(&channel.schema_name, &channel.encoding)
                        == Some(MessageKind::RosTf) =>
                    {
                        // Transforms hold until replaced: into the tree whenever they come.
                        match ros2::decode::<ros2::TfMessage>(&payload) {
                            Ok(m) => self.tf.add(&m),
                            Err(e) => {
                                self.note(format!("{}: not a TFMessage ({e})", channel.topic))
                            }
                        }
                        false
                    }
                    None => {
                        if channel.encoding == "json" || channel.encoding == "cdr" {
                            self.json(channel, log_time_ns, payload);
                        }
                        false
                    }
                }
            }
        }
    }

    /// Writes one message to the recording, if one runs.
    fn record(&mut self, channel: &Arc<AdvertisedChannel>, log_time_ns: u64, payload: &[u8]) {
        let Some(r) = self.recorder.as_mut() else {
            return;
        };
        match r.message(channel, log_time_ns, payload) {
            Ok(Recorded::Written | Recorded::OtherCamera) => {}
            Ok(Recorded::OverChannelLimit) => {
                if r.over_limit() == 1 {
                    let w = format!(
                        "the recording holds {MAX_CHANNELS} channels: messages on later channels are not written"
                    );
                    self.problem(&w);
                    self.note(w);
                }
            }
            Err(e) => self.recording_failed(&e),
        }
    }

    /// Adds a camera for each image channel advertised: on the first advertisement the
    /// canonical topic, else the first, becomes the camera shown; the others (and any advertised
    /// later) are cameras of their own, offered beside it.
    fn choose_camera(&mut self, channels: &[Arc<AdvertisedChannel>]) {
        let images: Vec<&Arc<AdvertisedChannel>> = channels
            .iter()
            .filter(|c| image_kind(c).is_some())
            .collect();
        if self.cameras.is_empty()
            && let Some(c) = images
                .iter()
                .find(|c| c.topic == IMAGE_TOPIC)
                .or_else(|| images.first())
        {
            self.cameras.push(CameraFrames::new(&c.topic));
            if c.topic != IMAGE_TOPIC {
                self.note(format!(
                    "frames are shown from {} ({} {})",
                    c.topic, c.schema_name, c.encoding
                ));
            }
        }
        for c in images {
            if self.camera_index(&c.topic).is_none() {
                self.cameras.push(CameraFrames::new(&c.topic));
                self.note(format!(
                    "channel {} ({} {}) is another camera: pick it in the camera picker or show the cameras side by side",
                    c.topic, c.schema_name, c.encoding
                ));
            }
        }
    }

    /// The camera whose image channel is `topic`.
    fn camera_index(&self, topic: &str) -> Option<usize> {
        self.cameras.iter().position(|c| c.topic == topic)
    }

    /// The camera a JSON or CDR channel goes with, and the topic it is attached as: a
    /// channel `CAMERA/sensors` (`recognition`, `ground_truth`) of a camera of this robot is
    /// that camera's `/sensors`; any other goes with the camera shown, as it is.
    fn channel_camera(&self, topic: &str) -> (usize, String) {
        if let Some((camera, channel)) = CameraChannel::of(topic)
            && let Some(i) = self.camera_index(camera)
        {
            let as_topic = match channel {
                CameraChannel::Sensors
                | CameraChannel::GroundTruth
                | CameraChannel::Recognition => channel.topic(IMAGE_TOPIC),
                CameraChannel::Annotations | CameraChannel::CameraInfo => topic.to_owned(),
            };
            return (i, as_topic);
        }
        (0, topic.to_owned())
    }

    /// Decodes an image of camera `camera` into a frame with the messages that came for it;
    /// true when it made a frame.
    fn image(&mut self, camera: usize, message: &ImageMessageIn<'_>, keep: usize) -> bool {
        let log_time_ns = message.log_time_ns;
        let decoded = ImageMessage::decode(message.kind, message.payload).and_then(|m| {
            let (time, frame_id, grey) = (m.timestamp_ns, m.frame_id.clone(), m.is_grey());
            m.into_frame().map(|f| (f, time, frame_id, grey))
        });
        let (frame, capture_ns, frame_id, grey) = match decoded {
            Ok(f) => f,
            Err(e) => {
                self.drops += 1;
                self.note(format!("frame skipped: {e}"));
                return false;
            }
        };
        if grey && !self.grey_noted {
            self.grey_noted = true;
            self.note(
                "frames are mono8 (grey): they show, but a colour table cannot classify them"
                    .to_owned(),
            );
        }
        // Gaps are judged on the camera's capture times (regular), not on when the sender got
        // round to writing (jittery); images without a timestamp use their log time.
        let capture_ns = capture_ns.filter(|&t| t > 0).unwrap_or(log_time_ns);
        let Some(gaps) = self.cameras.get_mut(camera).map(|c| &mut c.gaps) else {
            return false;
        };
        match gaps.observe(capture_ns) {
            Gap::Regular => {}
            // Drops are counted on the camera shown (the robots list's figures).
            Gap::Missed(n) => self.drops += if camera == 0 { n } else { 0 },
            Gap::ClockJump { by_ns } => self.note(format!(
                "the robot's frame times jumped by {:+.1} s (restarted or looped): not counted as drops",
                by_ns as f64 / 1e9
            )),
        }
        let mut record = FrameRecord::new(log_time_ns, frame);
        let (mine, others): (VecDeque<_>, VecDeque<_>) = std::mem::take(&mut self.pending)
            .into_iter()
            .partition(|(c, ..)| *c == camera);
        self.pending = others;
        self.pending_bytes = self.pending.iter().map(|(.., p)| p.len()).sum();
        for (_, channel, time, bytes) in mine {
            let (_, as_topic) = self.channel_camera(&channel.topic);
            if time == log_time_ns
                && let Some(n) = attach(&mut record, &channel, &as_topic, &bytes, &mut self.tf)
            {
                self.note(n);
            }
        }
        if let Some(pose) = self.tf.camera_pose(&frame_id) {
            let s = record.sensors.get_or_insert_with(SensorReadings::default);
            if s.camera_height_cm.is_none() && s.camera_pitch_rad.is_none() {
                s.camera_x_cm = pose.camera_x_cm;
                s.camera_y_cm = pose.camera_y_cm;
                s.camera_height_cm = pose.camera_height_cm;
                s.camera_roll_rad = pose.camera_roll_rad;
                s.camera_pitch_rad = pose.camera_pitch_rad;
                s.camera_yaw_rad = pose.camera_yaw_rad;
            }
        }
        self.keep_frame(camera, record, message.received_ns, keep);
        true
    }

    /// Keeps a new frame of camera `camera` (within its share of `keep` bytes) and counts it.
    fn keep_frame(&mut self, camera: usize, record: FrameRecord, received_ns: u64, keep: usize) {
        let latency_ns = unix_time_ns().saturating_sub(record.time_ns);
        let now = Instant::now();
        let first = *self.first_arrival.get_or_insert(now);
        let offset = u64::try_from(now.duration_since(first).as_nanos()).unwrap_or(u64::MAX);
        let share = keep / self.cameras.len().max(1);
        let Some(c) = self.cameras.get_mut(camera) else {
            return;
        };
        let frame = LiveFrame {
            index: c.received,
            record,
            received_ns,
            latency_ns,
        };
        c.push(frame, offset, share);
        if camera != 0 {
            // The figures are the camera shown's.
            return;
        }
        if self.latencies.len() >= LATENCY_WINDOW {
            self.latencies.pop_front();
        }
        self.latencies.push_back(latency_ns);
        self.arrivals.push_back(now);
        while self
            .arrivals
            .front()
            .is_some_and(|t| now.duration_since(*t) > Duration::from_secs(1))
        {
            self.arrivals.pop_front();
        }
    }

    /// Attaches a JSON or CDR message to its camera's frame: eotn's senders give a frame's
    /// messages the image's log time; a ROS bridge stamps each message when it came, so its
    /// `cdr` messages go with the latest frame.
    fn json(&mut self, channel: Arc<AdvertisedChannel>, log_time_ns: u64, payload: Vec<u8>) {
        let by_arrival = channel.encoding == "cdr";
        let (camera, as_topic) = self.channel_camera(&channel.topic);
        let latest = self
            .cameras
            .get_mut(camera)
            .and_then(|c| c.frames.back_mut())
            .filter(|f| by_arrival || f.record.time_ns == log_time_ns);
        if let Some(latest) = latest {
            let note = attach(
                &mut Arc::make_mut(latest).record,
                &channel,
                &as_topic,
                &payload,
                &mut self.tf,
            );
            if let Some(n) = note {
                self.note(n);
            }
        } else {
            self.pending
                .retain(|(c, _, t, _)| *t == log_time_ns || *c != camera);
            self.pending
                .push_back((camera, channel, log_time_ns, payload));
            self.pending_bytes = self.pending.iter().map(|(.., p)| p.len()).sum();
            let (messages, bytes) = self.queue;
            while self.pending.len() > messages || self.pending_bytes > bytes {
                let Some((.., old)) = self.pending.pop_front() else {
                    break;
                };
                self.pending_bytes -= old.len();
            }
        }
    }
}

/// An image message as it came: what the camera's frame is made from.
struct ImageMessageIn<'a> {
    kind: MessageKind,
    log_time_ns: u64,
    received_ns: u64,
    payload: &'a [u8],
}
