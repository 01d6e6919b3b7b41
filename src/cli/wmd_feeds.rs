//! What a live `eotn wmd` session reads from: each overhead camera's frames and each robot's
//! world models (and camera frames), from a live server, a camera device or a recording
//! replayed on its own clock. Every feed is polled without blocking: a live robot's connection
//! runs on its own thread ([`crate::live::RobotClient`]) and hands what arrives to an inbox; a
//! camera device is grabbed on its own thread ([`crate::sources::Streamer`]).
//!
//! Times are this machine's clock (nanoseconds since the Unix epoch): a live message's arrival,
//! a device frame's grab, a replayed recording's time moved to the session's start.

use std::collections::VecDeque;
use std::path::Path;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Instant;

use anyhow::Context;

use crate::formats::{ImageMessage, MessageKind};
use crate::frame::Frame;
use crate::live::protocol::AdvertisedChannel;
use crate::live::{ClientOptions, LiveEvent, LiveRobot, RobotClient, RobotUrl, unix_time_ns};
use crate::model::world_model::{self, RobotKey, WorldModelMessage};
use crate::sources::{CameraKind, CameraSource, Streamer, StreamerEvent};
use crate::streams::StreamReader;

/// Frame bytes a live overhead camera keeps in memory (its frames are processed as they come).
const OVERHEAD_KEEP_BYTES: usize = 16 << 20;
/// Camera frames a robot's inbox holds before the oldest are let go.
const INBOX_FRAMES: usize = 32;
/// World models a robot's inbox holds before the oldest are let go.
const INBOX_MODELS: usize = 4096;

/// A recording played on its own clock from the session's start.
#[derive(Debug)]
pub struct Replay {
    reader: StreamReader,
    next: usize,
    first_ns: u64,
}

/// Where an overhead camera's frames come from.
pub enum OverheadFeed {
    /// A `ws://` overhead server: frames by arrival.
    Live {
        /// The connection and its frames.
        robot: LiveRobot,
        /// The next frame index to take.
        next: usize,
    },
    /// A camera device, grabbed on its own thread.
    Device(Streamer),
    /// A recording, replayed on its own clock.
    Replay(Box<Replay>),
    /// SSL-Vision's detection frames (udp:// or a log replayed): detections, not frames
    /// ([`super::wmd_ssl`]).
    Ssl(Box<super::wmd_ssl::SslOverheadFeed>),
}

impl std::fmt::Debug for OverheadFeed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Live { robot, .. } => write!(f, "Live({})", robot.url()),
            Self::Device(s) => write!(f, "Device({s:?})"),
            Self::Replay(r) => write!(f, "Replay({})", r.reader.path().display()),
            Self::Ssl(s) => write!(f, "Ssl({s:?})"),
        }
    }
}

impl OverheadFeed {
    /// A `ws://` server's frames.
    ///
    /// # Errors
    /// A malformed address; the connection thread cannot start.
    pub fn live(url: &str) -> anyhow::Result<Self> {
        let url: RobotUrl = url.parse()?;
        let robot = LiveRobot::connect(url, ClientOptions::default(), OVERHEAD_KEEP_BYTES, None)?;
        Ok(Self::Live { robot, next: 0 })
    }

    /// A camera device's frames.
    ///
    /// # Errors
    /// The device cannot be opened.
    pub fn device(path: &Path) -> anyhow::Result<Self> {
        let camera = CameraSource::new(path, CameraKind::Overhead);
        // Grabbing waits for the camera's next frame: the rate is only an upper bound.
        let streamer = Streamer::start(Box::new(camera), 240.0)
            .with_context(|| format!("{}", path.display()))?;
        Ok(Self::Device(streamer))
    }

    /// A recording's frames (of `camera`, its first by default), replayed on its own clock.
    ///
    /// # Errors
    /// An unreadable recording, an unknown camera.
    pub fn replay(path: &Path, camera: Option<&str>) -> anyhow::Result<Self> {
        let reader = StreamReader::open_camera(path, camera)?;
        let first_ns = reader.time_ns(0).unwrap_or(0);
        Ok(Self::Replay(Box::new(Replay {
            reader,
            next: 0,
            first_ns,
        })))
    }

    /// True for a recording played to its end (a live source never ends by itself).
    #[must_use]
    pub fn ended(&self) -> bool {
        match self {
            Self::Replay(r) => r.next >= r.reader.len(),
            Self::Ssl(s) => s.ended(),
            Self::Live { .. } | Self::Device(_) => false,
        }
    }

    /// The frames that arrived since the last call, with their times (see the module
    /// documentation); `start` and `start_unix_ns` are the session's start. Problems (a frame
    /// that cannot be read, a device error) are warned about under `name`. An SSL-Vision feed
    /// gives no frames: its detections come from [`super::wmd_ssl::SslOverheadFeed::poll`].
    pub fn poll(&mut self, start: Instant, start_unix_ns: u64, name: &str) -> Vec<(u64, Frame)> {
        let mut out = Vec::new();
        match self {
            Self::Ssl(_) => {}
            Self::Live { robot, next } => {
                while *next < robot.len() {
                    if let Some(f) = robot.frame(*next) {
                        out.push((f.received_ns, f.record.frame.clone()));
                    }
                    *next += 1;
                }
            }
            Self::Device(streamer) => {
                for event in streamer.poll() {
                    match event {
                        StreamerEvent::Frame(f) => {
                            let frame = Arc::unwrap_or_clone(f.frame);
                            out.push((unix_time_ns(), frame));
                        }
                        StreamerEvent::Error(e) => log::warn!("{name}: {e}"),
                        StreamerEvent::Settings(_) | StreamerEvent::RecordingStopped { .. } => {}
                    }
                }
            }
            Self::Replay(r) => {
                let elapsed = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
                while let Some(t) = r.reader.time_ns(r.next) {
                    let after = t.saturating_sub(r.first_ns);
                    if after > elapsed {
                        break;
                    }
                    match r.reader.read(r.next) {
                        Ok(rec) => out.push((start_unix_ns.saturating_add(after), rec.frame)),
                        Err(e) => log::warn!("{name} frame {}: {e}; skipped", r.next),
                    }
                    r.next += 1;
                }
            }
        }
        out
    }

    /// A line on the feed's connection, for the live status (none for recordings).
    #[must_use]
    pub fn connection(&self) -> Option<String> {
        match self {
            Self::Live { robot, .. } => Some(robot.connection().to_string()),
            Self::Device(_) | Self::Replay(_) | Self::Ssl(_) => None,
        }
    }
}

/// One world model as it arrived.
#[derive(Debug, Clone)]
pub struct ArrivedModel {
    /// Arrival, nanoseconds on this machine's clock (see the module documentation).
    pub arrival_ns: u64,
    /// When, on the robot's clock: the message's `time_ns`, else its log time.
    pub robot_ns: u64,
    /// The message.
    pub message: WorldModelMessage,
}

/// One camera frame of a robot as it arrived: its image message as sent, for the recording.
#[derive(Debug, Clone)]
pub struct ArrivedFrame {
    /// Arrival, nanoseconds on this machine's clock.
    pub arrival_ns: u64,
    /// The image channel's topic.
    pub topic: String,
    /// The message as it came (its pixels are stored unchanged).
    pub image: ImageMessage,
}

/// What a live robot's connection thread hands over, emptied by each poll.
#[derive(Debug, Default)]
pub struct Inbox {
    /// World models, oldest first.
    pub models: VecDeque<ArrivedModel>,
    /// Camera frames, oldest first (only when they are wanted).
    pub frames: VecDeque<ArrivedFrame>,
    /// Lines to say: connected, disconnected, refused messages.
    pub lines: Vec<String>,
    /// Frames and world models let go because the session fell behind.
    pub dropped: usize,
    /// Messages naming another robot than the session's entry (counted, not kept).
    pub others: usize,
    /// World models refused (not the format), in all.
    pub refused: usize,
}

/// What a robot feed takes from its source.
#[derive(Debug, Clone, Default)]
pub struct RobotWants {
    /// Only the world models naming this robot (a session entry); others are counted.
    pub only: Option<RobotKey>,
    /// Its camera frames: the topic (`None`: the first image channel it sends), or not at all.
    pub frames: Option<Option<String>>,
}

/// Where a robot's world models come from.
pub enum RobotFeed {
    /// A `ws://` robot: world models (and camera frames) by arrival.
    Live {
        /// Its address.
        url: RobotUrl,
        /// The connection thread.
        client: RobotClient,
        /// What the thread handed over.
        inbox: Arc<Mutex<Inbox>>,
    },
    /// A recording's world models, replayed on their own clock.
    Replay {
        /// (time on the robot's clock, message), in time order.
        models: Vec<(u64, WorldModelMessage)>,
        /// The next one to hand over.
        next: usize,
        /// The first one's time.
        first_ns: u64,
    },
}

impl std::fmt::Debug for RobotFeed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Live { url, .. } => write!(f, "Live({url})"),
            Self::Replay { models, .. } => write!(f, "Replay({} world models)", models.len()),
        }
    }
}

fn lock(inbox: &Mutex<Inbox>) -> MutexGuard<'_, Inbox> {
    inbox
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl RobotFeed {
    /// Connects to a `ws://` robot.
    ///
    /// # Errors
    /// A malformed address; the connection thread cannot start.
    pub fn live(url: &str, wants: RobotWants) -> anyhow::Result<Self> {
        let url: RobotUrl = url.parse()?;
        let inbox = Arc::new(Mutex::new(Inbox::default()));
        let mut camera: Option<String> = None;
        let client = RobotClient::spawn(url.clone(), ClientOptions::default(), {
            let inbox = Arc::clone(&inbox);
            move |event| on_event(&mut lock(&inbox), &wants, &mut camera, event)
        })?;
        Ok(Self::Live { url, client, inbox })
    }

    /// Asks the connection thread to end (without waiting).
    pub fn request_stop(&self) {
        if let Self::Live { client, .. } = self {
            client.request_stop();
        }
    }

    /// Ends the connection thread, waiting at most half a second.
    pub fn stop(self) {
        if let Self::Live { client, .. } = self {
            client.stop();
        }
    }

    /// What arrived since the last call: world models, camera frames, lines to say, and how
    /// many were dropped or refused since.
    pub fn poll(&mut self, start: Instant, start_unix_ns: u64) -> Inbox {
        match self {
            Self::Live { inbox, .. } => std::mem::take(&mut *lock(inbox)),
            Self::Replay {
                models,
                next,
                first_ns,
            } => {
                let elapsed = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
                let mut out = Inbox::default();
                while let Some((t, m)) = models.get(*next) {
                    let after = t.saturating_sub(*first_ns);
                    if after > elapsed {
                        break;
                    }
                    out.models.push_back(ArrivedModel {
                        arrival_ns: start_unix_ns.saturating_add(after),
                        robot_ns: *t,
                        message: m.clone(),
                    });
                    *next += 1;
                }
                out
            }
        }
    }
}

/// One event of a live robot's connection, on its thread: world models parsed (refusals said),
/// wanted camera frames decoded into their messages, the connection's changes said.
fn on_event(inbox: &mut Inbox, wants: &RobotWants, camera: &mut Option<String>, event: LiveEvent) {
    match event {
        LiveEvent::Connected { server_name } => {
            inbox.lines.push(format!("connected to '{server_name}'"));
        }
        LiveEvent::Disconnected {
            reason, retry_in, ..
        } => inbox.lines.push(format!(
            "disconnected: {reason}; reconnecting in {:.1} s",
            retry_in.as_secs_f64()
        )),
        LiveEvent::Status(s) => inbox.lines.push(format!("robot says {s}")),
        LiveEvent::Warning(w) => inbox.lines.push(w),
        LiveEvent::Advertised(_) => {}
        LiveEvent::Message {
            channel,
            log_time_ns,
            received_ns,
            payload,
        } => {
            if world_model::is_world_model_topic(&channel.topic) && channel.encoding == "json" {
                model(inbox, wants, log_time_ns, received_ns, &payload);
            } else if let Some(topic) = &wants.frames {
                frame(
                    inbox,
                    topic.as_deref(),
                    camera,
                    &channel,
                    received_ns,
                    &payload,
                );
            }
        }
    }
}

fn model(inbox: &mut Inbox, wants: &RobotWants, log_ns: u64, arrival_ns: u64, payload: &[u8]) {
    match world_model::parse(payload) {
        Ok(m) if wants.only.is_some_and(|k| k != m.robot) => inbox.others += 1,
        Ok(m) => {
            if inbox.models.len() >= INBOX_MODELS {
                inbox.models.pop_front();
                inbox.dropped += 1;
            }
            inbox.models.push_back(ArrivedModel {
                arrival_ns,
                robot_ns: m.time_ns.unwrap_or(log_ns),
                message: m,
            });
        }
        Err(e) => {
            inbox.refused += 1;
            if inbox.refused <= 5 {
                inbox.lines.push(format!("world model skipped: {e}"));
            }
        }
    }
}

/// A camera frame of the wanted topic (the first image channel when none is named).
fn frame(
    inbox: &mut Inbox,
    wanted: Option<&str>,
    camera: &mut Option<String>,
    channel: &AdvertisedChannel,
    arrival_ns: u64,
    payload: &[u8],
) {
    let Some(kind) =
        MessageKind::of(&channel.schema_name, &channel.encoding).filter(|k| k.is_image())
    else {
        return;
    };
    let chosen = camera.get_or_insert_with(|| wanted.unwrap_or(&channel.topic).to_owned());
    if *chosen != channel.topic {
        return;
    }
    match ImageMessage::decode(kind, payload) {
        Ok(image) => {
            if inbox.frames.len() >= INBOX_FRAMES {
                inbox.frames.pop_front();
                inbox.dropped += 1;
            }
            inbox.frames.push_back(ArrivedFrame {
                arrival_ns,
                topic: channel.topic.clone(),
                image,
            });
        }
        Err(e) => inbox
            .lines
            .push(format!("{}: frame skipped: {e}", channel.topic)),
    }
}
