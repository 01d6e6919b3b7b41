//! SSL-Vision as the overhead source of `eotn wmd` (`--overhead udp://GROUP:PORT` or a league
//! `.log`; a session's overhead entry naming one): ssl-vision's detection frames take the place
//! of eotn's overhead pipeline, so no table or calibration is read.
//!
//! Each field frame is a frame of the reference camera (a log's lowest `camera_id`; live, the
//! first camera heard) with every camera's frame nearest its capture time within half a frame
//! period, merged ([`crate::ssl_vision::truth::detections`]: a robot seen by two cameras once,
//! the more confident reading; the most confident ball). A robot becomes the marker of its team
//! colour (blue → blue, yellow → yellow) with its `robot_id` as identity; robots with an id
//! beyond 0–15 or without an orientation are left out and counted. The world models are then
//! matched with them as with eotn's detections: by marker, else by position.
//!
//! A log is read through like a recording, its capture times (ssl-vision's clock) the field
//! frames' times; live packets run on this machine's clock (arrival times), as the other live
//! sources do ([`SslOverheadFeed`]).

use std::collections::VecDeque;
use std::path::Path;
use std::time::Instant;

use anyhow::Context;

use super::wmd_inputs::FieldFrame;
use crate::overhead::OverheadDetections;
use crate::overhead::merge::{SslCameraId, merge_detections};
use crate::session::SslSource;
use crate::ssl_vision::CameraFrame;
use crate::ssl_vision::listener::{Listener, Received};
use crate::ssl_vision::truth::{FrameIndex, detections};

/// Frames kept per camera of a live feed for joining the reference camera's.
const LIVE_FRAMES_KEPT: usize = 64;

/// The `camera_id` of an SSL camera as a session camera id (ids above 255 become 255).
fn camera_id(id: u32) -> SslCameraId {
    SslCameraId(u8::try_from(id).unwrap_or(u8::MAX))
}

/// The median gap of ascending times, nanoseconds; `None` with fewer than two.
fn period_of(times: &[u64]) -> Option<u64> {
    (times.len() >= 2).then(|| crate::wmd::clock::frame_period_ns(times))
}

/// One field frame from the cameras' frames near `t_ns`: the merged detections and the frames
/// used; the robots left out are added to `left_out`.
fn field_frame(frames: &[&CameraFrame], t_ns: u64, left_out: &mut usize) -> FieldFrame {
    let (d, left) = detections(frames);
    *left_out += left;
    FieldFrame {
        time_ns: t_ns,
        picture: merge_detections(&[(SslCameraId(0), &d)]),
        single: Some(d),
        cameras: frames
            .iter()
            .filter_map(|f| Some((camera_id(f.camera_id), f.t_capture_ns()?)))
            .collect(),
    }
}

/// A league log's field frames, read through (see the module documentation); what the log
/// held is said on stderr.
///
/// # Errors
/// A file that is not a league log (a B-Human log gets the line pointing to its importer), a
/// log without a timed detection frame.
pub fn log_field_frames(path: &Path) -> anyhow::Result<Vec<FieldFrame>> {
    let name = path.display().to_string();
    let log = crate::ssl_vision::log::read_log_file(path).with_context(|| name.clone())?;
    log::info!("{name}: {}", log.summary());
    let index = FrameIndex::new(log.frames.into_iter().map(|f| f.frame));
    let reference = index
        .camera_ids()
        .next()
        .with_context(|| format!("{name}: no detection frame with a capture time"))?;
    let times = index.times_of(reference);
    let period = period_of(&times).unwrap_or(crate::wmd::clock::DEFAULT_PERIOD_NS);
    let mut left_out = 0;
    let frames = times
        .iter()
        .map(|&t| field_frame(&index.near(t, period), t, &mut left_out))
        .collect();
    say_left_out(&name, left_out);
    Ok(frames)
}

fn say_left_out(name: &str, left_out: usize) {
    if left_out > 0 {
        log::warn!(
            "{name}: {left_out} robot readings left out: no robot_id of 0-15 (eotn's markers) or \
             no orientation"
        );
    }
}

/// Where a live session's SSL-Vision frames come from.
#[derive(Debug)]
enum Input {
    /// Packets on `udp://…`, timed by arrival.
    Udp(Listener),
    /// A log replayed on its own clock from the session's start: (capture time after the
    /// log's first, frame).
    Replay(VecDeque<(u64, CameraFrame)>),
}

/// SSL-Vision as a live session's overhead camera: frames received (or a log replayed), a
/// field frame per reference-camera frame once half a frame period has passed since it arrived
/// (so the other cameras' frames of that instant are in), merged by capture time.
#[derive(Debug)]
pub struct SslOverheadFeed {
    input: Input,
    index: FrameIndex,
    reference: Option<u32>,
    /// Reference frames waiting: (arrival on this machine's clock, capture time).
    waiting: VecDeque<(u64, u64)>,
    /// The reference camera's last capture times, for its period.
    times: VecDeque<u64>,
    bad: usize,
    left_out: usize,
}

impl SslOverheadFeed {
    /// Listens on `udp://…` or reads a log for replay.
    ///
    /// # Errors
    /// A port in use, a group that cannot be joined, a malformed address; an unreadable log.
    pub fn open(source: &SslSource) -> anyhow::Result<Self> {
        let input = match source {
            SslSource::Udp(url) => {
                let listener = Listener::start(url)?;
                log::info!("listening for SSL-Vision packets on {url}");
                Input::Udp(listener)
            }
            SslSource::Log(path) => {
                let log = crate::ssl_vision::log::read_log_file(path)
                    .with_context(|| path.display().to_string())?;
                let mut frames: Vec<(u64, CameraFrame)> = log
                    .frames
                    .into_iter()
                    .filter_map(|f| Some((f.frame.t_capture_ns()?, f.frame)))
                    .collect();
                frames.sort_by_key(|f| f.0);
                let first = frames.first().map_or(0, |f| f.0);
                Input::Replay(frames.into_iter().map(|(t, f)| (t - first, f)).collect())
            }
        };
        Ok(Self {
            input,
            index: FrameIndex::default(),
            reference: None,
            waiting: VecDeque::new(),
            times: VecDeque::new(),
            bad: 0,
            left_out: 0,
        })
    }

    /// True for a log replayed to its end with nothing waiting.
    #[must_use]
    pub fn ended(&self) -> bool {
        matches!(&self.input, Input::Replay(q) if q.is_empty()) && self.waiting.is_empty()
    }

    fn period_ns(&self) -> u64 {
        let times: Vec<u64> = self.times.iter().copied().collect();
        period_of(&times).unwrap_or(crate::wmd::clock::DEFAULT_PERIOD_NS)
    }

    fn take(&mut self, arrival_ns: u64, frame: CameraFrame) {
        let Some(t) = frame.t_capture_ns() else {
            self.index.push(frame);
            return;
        };
        let reference = *self.reference.get_or_insert(frame.camera_id);
        if frame.camera_id == reference {
            self.waiting.push_back((arrival_ns, t));
            self.times.push_back(t);
            if self.times.len() > 31 {
                self.times.pop_front();
            }
        }
        self.index.push(frame);
    }

    /// The field frames due since the last call: (time on this machine's clock, merged
    /// detections). `start` and `start_unix_ns` are the session's start; a packet that is not
    /// SSL-Vision is warned about under `name` (the first; later ones counted).
    pub fn poll(
        &mut self,
        start: Instant,
        start_unix_ns: u64,
        name: &str,
    ) -> Vec<(u64, OverheadDetections)> {
        let now = crate::live::unix_time_ns();
        let mut arrived = Vec::new();
        match &mut self.input {
            Input::Udp(listener) => {
                for item in listener.drain() {
                    match item {
                        Received::Packet {
                            packet,
                            received_ns,
                            ..
                        } => {
                            if let Some(d) = &packet.detection {
                                let at = u64::try_from(received_ns).unwrap_or(now);
                                arrived.push((at, CameraFrame::from_message(d)));
                            }
                        }
                        Received::Bad { from, why } => {
                            self.bad += 1;
                            if self.bad == 1 {
                                log::warn!(
                                    "{name}: a packet from {from} is not SSL-Vision: {why} \
                                     (skipped; later ones counted)"
                                );
                            }
                        }
                    }
                }
            }
            Input::Replay(queue) => {
                let elapsed = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
                while queue.front().is_some_and(|f| f.0 <= elapsed) {
                    if let Some((after, f)) = queue.pop_front() {
                        arrived.push((start_unix_ns.saturating_add(after), f));
                    }
                }
            }
        }
        for (at, f) in arrived {
            self.take(at, f);
        }
        let period = self.period_ns();
        let replay_ended = matches!(&self.input, Input::Replay(q) if q.is_empty());
        let mut out = Vec::new();
        while let Some(&(arrival, t)) = self.waiting.front() {
            if arrival.saturating_add(period / 2) > now && !replay_ended {
                break;
            }
            self.waiting.pop_front();
            let frames = self.index.near(t, period);
            let (d, left) = detections(&frames);
            self.left_out += left;
            out.push((arrival, d));
        }
        self.index.keep_last(LIVE_FRAMES_KEPT);
        out
    }

    /// Says on stderr what was left out (robots without a marker identity, bad packets).
    pub fn finish(&self, name: &str) {
        say_left_out(name, self.left_out);
        if self.bad > 1 {
            log::warn!("{name}: {} packets were not SSL-Vision", self.bad);
        }
        if let Input::Udp(l) = &self.input
            && l.dropped() > 0
        {
            log::warn!(
                "{name}: {} packets dropped (the session fell behind)",
                l.dropped()
            );
        }
    }
}
