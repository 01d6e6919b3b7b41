//! `eotn wmd` with a live source (a `ws://` server or a camera device): the session runs on
//! this machine's clock. Live sources count from their arrival, recordings replay on their own
//! clocks from the session's start ([`super::wmd_feeds`]). Each overhead frame is processed as
//! it arrives; a field frame is made once the reference camera's frame is a frame period old, so
//! every world model within half a period of it has arrived: of each robot the one that arrived
//! nearest it is paired with it. A line is printed per field frame as it is made.
//!
//! A robot that goes quiet is warned about (and again when it comes back), one that disconnects
//! is said as such, and nothing waits on a robot: the session ends at `--seconds`, on Ctrl+C or
//! SIGTERM, or when every overhead source is a recording played to its end.

use super::ssl_vision_out::SslOut;
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::io::Write;
use std::time::{Duration, Instant};

use anyhow::Context;

use super::overhead::SizeCheck;
use super::wmd_feeds::{ArrivedModel, OverheadFeed, RobotFeed};
use super::wmd_inputs::FieldFrame;
use super::wmd_record::{CameraFrame, SessionRecorder};
use crate::frame::Frame;
use crate::live::unix_time_ns;
use crate::model::world_model::RobotKey;
use crate::overhead::merge::{SslCameraId, frame_near, merge_detections};
use crate::overhead::recognise::OverheadDetections;
use crate::overhead::{FieldDescription, OverheadPipeline};
use crate::wmd::clock::{ClockOffset, DEFAULT_PERIOD_NS, arrival_offset, frame_period_ns};
use crate::wmd::summary::Summaries;
use crate::wmd::{Targets, WorldModelMessage, compare};

/// Longest a robot may send nothing before it is warned about (or ten frame periods, if longer).
const QUIET: Duration = Duration::from_secs(1);
/// Frames of another camera kept for joining the reference camera's.
const RECENT_FRAMES: usize = 16;
/// Reference frame times kept for the frame period.
const PERIOD_WINDOW: usize = 31;

/// One overhead camera of a live session.
#[derive(Debug)]
pub struct LiveCamera {
    /// Its session id.
    pub id: SslCameraId,
    /// Its name in messages (the source).
    pub name: String,
    /// Its pipeline (none for SSL-Vision, whose packets hold detections).
    pub pipeline: Option<OverheadPipeline>,
    /// Its frames.
    pub feed: OverheadFeed,
    /// Its connection as last said (live servers).
    pub connection: Option<String>,
}

/// One robot source of a live session.
#[derive(Debug)]
pub struct LiveRobotSource {
    /// Its name in messages (the source).
    pub name: String,
    /// Where its camera frames go in the recording.
    pub topic: String,
    /// Its world models (and frames).
    pub feed: RobotFeed,
    /// World models received from it so far.
    pub received: usize,
}

/// What a live session reads.
#[derive(Debug)]
pub struct LiveInputs {
    /// The field.
    pub field: FieldDescription,
    /// The overhead cameras, the reference first.
    pub cameras: Vec<LiveCamera>,
    /// The robots' sources.
    pub robots: Vec<LiveRobotSource>,
}

/// An overhead frame processed on arrival.
struct Seen {
    time_ns: u64,
    detections: OverheadDetections,
    /// Kept for the recording.
    frame: Option<Frame>,
}

/// Everything a live session keeps between polls.
struct Session<'a> {
    inputs: LiveInputs,
    targets: Targets,
    json: bool,
    out: &'a mut dyn Write,
    recorder: Option<SessionRecorder>,
    /// `--ssl-vision`: each camera's detections sent as SSL-Vision packets.
    ssl: Option<SslOut>,
    start: Instant,
    start_unix_ns: u64,
    sizes: Vec<SizeCheck>,
    /// Reference frames waiting to become field frames.
    pending: VecDeque<Seen>,
    /// Each other camera's latest frames.
    recent: Vec<VecDeque<Seen>>,
    /// The last reference frame times, for the period.
    times: VecDeque<u64>,
    last_field_ns: Option<u64>,
    /// World models waiting for their frame, by robot.
    waiting: BTreeMap<RobotKey, VecDeque<ArrivedModel>>,
    /// Per robot: arrival − robot time of each paired world model; position errors.
    clock: BTreeMap<RobotKey, (Vec<i64>, Vec<f64>)>,
    last_arrival: BTreeMap<RobotKey, u64>,
    quiet: BTreeSet<RobotKey>,
    unpaired: BTreeMap<RobotKey, usize>,
    summaries: Summaries,
    field_frames: usize,
    last_ns: u64,
}

/// Runs a live session until `seconds` have passed, Ctrl+C / SIGTERM, or every overhead source
/// is a recording played to its end. Lines go to `out` as field frames are made.
///
/// # Errors
/// A frame of another shape than its camera's calibration, the output or recording failing.
pub fn run(
    inputs: LiveInputs,
    json: bool,
    seconds: Option<f64>,
    (recorder, ssl): (Option<SessionRecorder>, Option<SslOut>),
    out: &mut dyn Write,
) -> anyhow::Result<super::wmd::Outcome> {
    let interrupted = super::interrupt::catch("ending the session")?;
    let cameras = inputs.cameras.len();
    let mut s = Session {
        targets: Targets::from_field(&inputs.field),
        inputs,
        json,
        out,
        recorder,
        ssl,
        start: Instant::now(),
        start_unix_ns: unix_time_ns(),
        sizes: (0..cameras).map(|_| SizeCheck::default()).collect(),
        pending: VecDeque::new(),
        recent: (0..cameras).map(|_| VecDeque::new()).collect(),
        times: VecDeque::new(),
        last_field_ns: None,
        waiting: BTreeMap::new(),
        clock: BTreeMap::new(),
        last_arrival: BTreeMap::new(),
        quiet: BTreeSet::new(),
        unpaired: BTreeMap::new(),
        summaries: Summaries::default(),
        field_frames: 0,
        last_ns: 0,
    };
    let deadline = seconds.map(|x| s.start + Duration::from_secs_f64(x));
    let result = s.run_until(deadline, &interrupted);
    for r in &s.inputs.robots {
        r.feed.request_stop();
    }
    let outcome = s.finish();
    result?;
    outcome
}

impl Session<'_> {
    fn run_until(
        &mut self,
        deadline: Option<Instant>,
        interrupted: &super::interrupt::Interrupted,
    ) -> anyhow::Result<()> {
        loop {
            self.poll_cameras()?;
            self.poll_robots();
            self.make_field_frames(unix_time_ns())?;
            self.warn_quiet(unix_time_ns());
            let all_played = self.inputs.cameras.iter().all(|c| c.feed.ended());
            if interrupted.is_set()
                || deadline.is_some_and(|d| Instant::now() >= d)
                || (all_played && self.pending.is_empty())
            {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(3));
        }
    }

    fn period_ns(&self) -> u64 {
        let times: Vec<u64> = self.times.iter().copied().collect();
        if times.len() < 2 {
            DEFAULT_PERIOD_NS
        } else {
            frame_period_ns(&times)
        }
    }

    /// Each camera's new frames through its pipeline.
    fn poll_cameras(&mut self) -> anyhow::Result<()> {
        let keep = self.recorder.is_some();
        for (k, cam) in self.inputs.cameras.iter_mut().enumerate() {
            let connection = cam.feed.connection();
            if connection != cam.connection {
                match &connection {
                    Some(c) if c.starts_with("closed") => log::warn!("overhead {}: {c}", cam.name),
                    Some(c) => log::info!("overhead {}: {c}", cam.name),
                    None => {}
                }
                cam.connection = connection;
            }
            let mut arrived: Vec<Seen> = Vec::new();
            if let OverheadFeed::Ssl(feed) = &mut cam.feed {
                for (time_ns, detections) in feed.poll(self.start, self.start_unix_ns, &cam.name) {
                    arrived.push(Seen {
                        time_ns,
                        detections,
                        frame: None,
                    });
                }
            }
            for (time_ns, frame) in cam.feed.poll(self.start, self.start_unix_ns, &cam.name) {
                let Some(pipeline) = cam.pipeline.as_mut() else {
                    continue;
                };
                let camera = *pipeline.camera();
                if let Some(size) = self.sizes.get_mut(k) {
                    size.check(&camera, &cam.name, frame.width(), frame.height())?;
                }
                let detections = pipeline.process(&frame).clone();
                arrived.push(Seen {
                    time_ns,
                    detections,
                    frame: keep.then_some(frame),
                });
            }
            for seen in arrived {
                let time_ns = seen.time_ns;
                if k == 0 {
                    self.times.push_back(time_ns);
                    if self.times.len() > PERIOD_WINDOW {
                        self.times.pop_front();
                    }
                    self.pending.push_back(seen);
                } else if let Some(recent) = self.recent.get_mut(k) {
                    recent.push_back(seen);
                    if recent.len() > RECENT_FRAMES {
                        recent.pop_front();
                    }
                }
            }
        }
        Ok(())
    }

    /// Each robot's news: lines said, world models kept for pairing, camera frames recorded.
    fn poll_robots(&mut self) {
        for r in &mut self.inputs.robots {
            let inbox = r.feed.poll(self.start, self.start_unix_ns);
            for line in &inbox.lines {
                if line.starts_with("connected") {
                    log::info!("{}: {line}", r.name);
                } else {
                    log::warn!("{}: {line}", r.name);
                }
            }
            if inbox.dropped > 0 {
                log::warn!(
                    "{}: {} messages let go (the session fell behind)",
                    r.name,
                    inbox.dropped
                );
            }
            if inbox.others > 0 {
                log::debug!("{}: {} world models of other robots", r.name, inbox.others);
            }
            r.received += inbox.models.len();
            for m in inbox.models {
                let key = m.message.robot;
                if self.quiet.remove(&key) {
                    log::warn!("{key}: world models again");
                }
                self.last_arrival.insert(key, m.arrival_ns);
                self.waiting.entry(key).or_default().push_back(m);
            }
            for f in inbox.frames {
                if let Some(rec) = self.recorder.as_mut()
                    && let Err(e) = rec.robot_frame(&r.topic, f.arrival_ns, f.image)
                {
                    log::warn!("{}: {} frame not recorded: {e:#}", r.name, f.topic);
                }
            }
        }
    }

    /// Warns once about each robot that has sent nothing for a while.
    fn warn_quiet(&mut self, now_ns: u64) {
        let quiet_ns = u64::try_from(QUIET.as_nanos())
            .unwrap_or(u64::MAX)
            .max(10 * self.period_ns());
        for (key, &last) in &self.last_arrival {
            let silent = now_ns.saturating_sub(last);
            if silent > quiet_ns && self.quiet.insert(*key) {
                log::warn!(
                    "{key}: no world model for {:.1} s (it stopped sending, or its connection did)",
                    silent as f64 * 1e-9
                );
            }
        }
    }

    /// Makes every field frame whose reference frame is a period old (all of them with
    /// `now_ns` = `u64::MAX`).
    fn make_field_frames(&mut self, now_ns: u64) -> anyhow::Result<()> {
        let period = self.period_ns();
        while let Some(front) = self.pending.front() {
            if front.time_ns.saturating_add(period) > now_ns {
                break;
            }
            if let Some(seen) = self.pending.pop_front() {
                self.field_frame(seen, period)?;
            }
        }
        Ok(())
    }

    /// The world model of each robot that arrived nearest `t` within half a period (and after
    /// the middle between the previous field frame and this one); older ones are let go.
    fn paired(&mut self, t: u64, period: u64) -> Vec<ArrivedModel> {
        let half = period / 2;
        let after = self
            .last_field_ns
            .map_or(0, |p| p + t.saturating_sub(p) / 2);
        let mut paired = Vec::new();
        for (key, list) in &mut self.waiting {
            let mut best: Option<ArrivedModel> = None;
            let mut let_go = 0;
            while list
                .front()
                .is_some_and(|m| m.arrival_ns <= t.saturating_add(half))
            {
                let Some(m) = list.pop_front() else { break };
                let near = m.arrival_ns.abs_diff(t) <= half && m.arrival_ns > after;
                if !near {
                    let_go += 1;
                } else if best
                    .as_ref()
                    .is_none_or(|b| m.arrival_ns.abs_diff(t) < b.arrival_ns.abs_diff(t))
                {
                    let_go += usize::from(best.is_some());
                    best = Some(m);
                } else {
                    let_go += 1;
                }
            }
            *self.unpaired.entry(*key).or_default() += let_go;
            paired.extend(best);
        }
        paired
    }

    fn field_frame(&mut self, reference: Seen, period: u64) -> anyhow::Result<()> {
        let t = reference.time_ns;
        let half = period / 2;
        let arrived = self.paired(t, period);
        self.last_field_ns = Some(t);
        let mut views = vec![(self.camera_id(0), reference.detections.clone())];
        let mut frames = vec![(self.camera_id(0), t)];
        let mut used: Vec<(SslCameraId, u64, Option<&Frame>)> = Vec::new();
        for (k, recent) in self.recent.iter().enumerate().skip(1) {
            let times: Vec<u64> = recent.iter().map(|s| s.time_ns).collect();
            if let Some(seen) = frame_near(&times, t, period).and_then(|i| recent.get(i))
                && seen.time_ns.abs_diff(t) <= half
            {
                let id = self.inputs.cameras.get(k).map_or(SslCameraId(0), |c| c.id);
                views.push((id, seen.detections.clone()));
                frames.push((id, seen.time_ns));
                used.push((id, seen.time_ns, seen.frame.as_ref()));
            }
        }
        if let Some(out) = self.ssl.as_mut() {
            for ((id, d), (_, time_ns)) in views.iter().zip(&frames) {
                out.send(super::ssl_vision_out::session_camera_id(*id), *time_ns, d);
            }
        }
        let refs: Vec<(SslCameraId, &OverheadDetections)> =
            views.iter().map(|(id, d)| (*id, d)).collect();
        let frame = FieldFrame {
            time_ns: t,
            single: (self.inputs.cameras.len() == 1).then(|| reference.detections.clone()),
            picture: merge_detections(&refs),
            cameras: frames,
        };
        let models: Vec<&WorldModelMessage> = arrived.iter().map(|m| &m.message).collect();
        let view = frame.view();
        let results = compare(&view, &models, &self.targets);
        let jumps: Vec<bool> = results.iter().map(|c| self.summaries.add(t, c)).collect();
        for (m, c) in arrived.iter().zip(&results) {
            let (offsets, errors) = self.clock.entry(m.message.robot).or_default();
            offsets.push(
                i64::try_from(i128::from(m.arrival_ns) - i128::from(m.robot_ns)).unwrap_or(0),
            );
            errors.extend(c.position_error_cm);
        }
        let line = super::wmd::line_json(&frame, &results, &jumps)?;
        if self.json {
            serde_json::to_writer(&mut *self.out, &line)?;
            writeln!(self.out)?;
            self.out.flush().context("writing output")?;
        }
        if let Some(rec) = self.recorder.as_mut() {
            let scene =
                crate::wmd::scene::scene_update(t, &self.inputs.field, &view, &models, &results);
            let mut cameras = Vec::new();
            if let Some(f) = &reference.frame {
                cameras.push(CameraFrame {
                    id: self.inputs.cameras.first().map_or(SslCameraId(0), |c| c.id),
                    time_ns: t,
                    frame: f,
                });
            }
            for (id, time_ns, f) in used {
                if let Some(frame) = f {
                    cameras.push(CameraFrame { id, time_ns, frame });
                }
            }
            rec.field_frame(t, &cameras, &models, &line, &scene)?;
        }
        self.field_frames += 1;
        self.last_ns = t;
        Ok(())
    }

    fn camera_id(&self, k: usize) -> SslCameraId {
        self.inputs.cameras.get(k).map_or(SslCameraId(0), |c| c.id)
    }

    /// Makes the last field frames, stops the robots, finishes the recording; the session's
    /// summaries and clock offsets.
    fn finish(mut self) -> anyhow::Result<super::wmd::Outcome> {
        let made = self.make_field_frames(u64::MAX);
        for (key, n) in &self.unpaired {
            if *n > 0 {
                log::info!(
                    "{key}: {n} world models arrived with no overhead frame within half a period"
                );
            }
        }
        for c in &self.inputs.cameras {
            if let OverheadFeed::Ssl(feed) = &c.feed {
                feed.finish(&c.name);
            }
        }
        for r in std::mem::take(&mut self.inputs.robots) {
            if r.received == 0 {
                log::warn!("{}: no world model arrived from it", r.name);
            }
            r.feed.stop();
        }
        let recorded = self
            .recorder
            .take()
            .map(SessionRecorder::finish)
            .transpose();
        if let Some(ssl) = &self.ssl {
            super::ssl_vision_out::finish(ssl);
        }
        made?;
        recorded?;
        let offsets: Vec<(RobotKey, ClockOffset)> = self
            .clock
            .iter()
            .map(|(k, (offsets, errors))| {
                (
                    *k,
                    arrival_offset(offsets, offsets.len(), crate::stats::median(errors)),
                )
            })
            .collect();
        let period_ns = self.period_ns();
        Ok(super::wmd::Outcome {
            summaries: self.summaries.finish(),
            offsets,
            last_ns: self.last_ns,
            period_ns,
            field_frames: self.field_frames,
        })
    }
}
