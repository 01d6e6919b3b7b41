//! [`NetworkSource`]: a robot over the Foxglove WebSocket protocol as a [`FrameSource`], so the
//! workspace shows it like any camera: Camera ▸ Connect… ▸ network.
//!
//! Frames come from the robot's own socket thread ([`LiveRobot`]); `connect` returns at once and
//! the connection (and reconnection) goes on in the background. [`FrameSource::grab`] hands out
//! the newest frame not handed out yet, waiting up to [`GRAB_WAIT`] for one; every frame stays in
//! the [`LiveRobot`]'s own history whether it was grabbed or not.
//!
//! [`RobotFrames`] is also a [`RecordedSource`]: the frames that have arrived so far, by arrival
//! index and arrival time, growing while the robot sends. The app shows a robot through it, so
//! stepping back, seeking and playing through what has arrived use the same timeline as a
//! recording while reception and recording go on. Frames older than the robot's byte budget
//! are no longer in memory: [`RecordedSource::first_index`] says where the kept ones start.

use std::time::{Duration, Instant};

use super::robot::{Connection, DEFAULT_KEEP_BYTES, LiveFrame};
use super::{ClientOptions, LiveRobot, RobotFrames, RobotUrl};
use crate::sources::{
    CameraKind, FrameSource, RecordedSource, SourceError, SourceFrame, SourceInfo, SourceKind,
    SourceSettings,
};

/// Longest a grab waits for a new frame.
pub const GRAB_WAIT: Duration = Duration::from_millis(200);
/// The rate the workspace grabs at: above a robot's 30 fps, so grabs wait on the robot.
const GRAB_RATE_HZ: f64 = 60.0;

/// A robot at a `ws://HOST:PORT` address.
#[derive(Debug)]
pub struct NetworkSource {
    url: RobotUrl,
    robot: Option<LiveRobot>,
    /// Index of the next frame to hand out.
    next: usize,
    /// Log time of the first frame handed out, nanoseconds (frame times count from it).
    first_ns: Option<u64>,
}

impl NetworkSource {
    /// A source for the robot at `address` (`ws://HOST:PORT` or `HOST:PORT`); not connected yet.
    ///
    /// # Errors
    /// [`SourceError::Unsupported`] for an address that is not one.
    pub fn new(address: &str) -> Result<Self, SourceError> {
        let url = address
            .parse::<RobotUrl>()
            .map_err(|e| SourceError::Unsupported {
                label: address.to_owned(),
                detail: e.to_string(),
            })?;
        Ok(Self {
            url,
            robot: None,
            next: 0,
            first_ns: None,
        })
    }

    /// The robot, while connected (its history, statistics, log and recording).
    #[must_use]
    pub fn robot(&self) -> Option<&LiveRobot> {
        self.robot.as_ref()
    }

    fn label(&self) -> String {
        self.robot
            .as_ref()
            .map_or_else(|| self.url.to_string(), LiveRobot::name)
    }
}

impl FrameSource for NetworkSource {
    fn info(&self) -> SourceInfo {
        SourceInfo {
            kind: SourceKind::Network,
            label: format!("robot {}", self.label()),
            camera: CameraKind::Robot,
            paths: Vec::new(),
            stream_source: "robot".to_owned(),
        }
    }

    fn connect(&mut self) -> Result<(), SourceError> {
        if self.robot.is_none() {
            let robot = LiveRobot::connect(
                self.url.clone(),
                ClientOptions::default(),
                DEFAULT_KEEP_BYTES,
                None,
            )
            .map_err(|e| SourceError::Device {
                label: self.url.to_string(),
                detail: e.to_string(),
            })?;
            self.robot = Some(robot);
            self.next = 0;
        }
        Ok(())
    }

    fn disconnect(&mut self) {
        self.robot = None;
    }

    fn is_connected(&self) -> bool {
        self.robot.is_some()
    }

    fn settings(&self) -> SourceSettings {
        SourceSettings {
            frame_rate: Some(GRAB_RATE_HZ),
            ..SourceSettings::default()
        }
    }

    fn grab(&mut self) -> Result<SourceFrame, SourceError> {
        let label = self.label();
        let robot = self
            .robot
            .as_ref()
            .ok_or_else(|| SourceError::NotConnected(label.clone()))?;
        let until = Instant::now() + GRAB_WAIT;
        loop {
            if let Some(latest) = robot.latest()
                && latest.index >= self.next
            {
                self.next = latest.index + 1;
                let r = &latest.record;
                let first = *self.first_ns.get_or_insert(r.time_ns);
                let mut frame = SourceFrame::new(r.time_ns.saturating_sub(first), r.frame.clone());
                frame.sensors = r.sensors;
                frame.extra.clone_from(&r.extra);
                return Ok(frame);
            }
            if Instant::now() >= until {
                let detail = match robot.connection() {
                    Connection::Connecting => "connecting…".to_owned(),
                    Connection::Connected(_) => "waiting for frames".to_owned(),
                    Connection::Disconnected { reason, .. } => {
                        format!("{reason}; reconnecting")
                    }
                };
                return Err(SourceError::Device { label, detail });
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

/// A frame as the workspace shows it: its time is its arrival after the robot's first frame
/// (the timeline's time), its sensors and JSON channels as they came.
fn source_frame(live: &LiveFrame, time_ns: u64) -> SourceFrame {
    let r = &live.record;
    let mut frame = SourceFrame::new(time_ns, r.frame.clone());
    frame.sensors = r.sensors;
    frame.extra.clone_from(&r.extra);
    frame
}

impl FrameSource for RobotFrames {
    fn info(&self) -> SourceInfo {
        SourceInfo {
            kind: SourceKind::Network,
            label: format!("robot {}", self.name()),
            camera: CameraKind::Robot,
            paths: Vec::new(),
            stream_source: "robot".to_owned(),
        }
    }

    /// The robot's own thread connects; a view has nothing to open.
    fn connect(&mut self) -> Result<(), SourceError> {
        Ok(())
    }

    fn disconnect(&mut self) {}

    fn is_connected(&self) -> bool {
        matches!(self.connection(), Connection::Connected(_))
    }

    fn settings(&self) -> SourceSettings {
        SourceSettings::default()
    }

    /// The newest frame.
    fn grab(&mut self) -> Result<SourceFrame, SourceError> {
        let latest = self
            .latest()
            .ok_or_else(|| SourceError::Empty(format!("robot {}: no frame yet", self.name())))?;
        Ok(source_frame(&latest, self.arrival_ns(latest.index)))
    }

    fn recorded(&mut self) -> Option<&mut dyn RecordedSource> {
        Some(self)
    }
}

impl RecordedSource for RobotFrames {
    fn len(&self) -> usize {
        RobotFrames::len(self)
    }

    fn first_index(&self) -> usize {
        self.first_kept()
    }

    fn time_ns(&self, index: usize) -> u64 {
        self.arrival_ns(index)
    }

    /// The camera's first frame on the robot's arrival clock: a robot's cameras side by side
    /// are matched on it.
    fn start_ns(&self) -> u64 {
        RobotFrames::start_ns(self)
    }

    fn index_at_time(&self, time_ns: u64) -> usize {
        self.index_at_arrival(time_ns)
    }

    fn read(&mut self, index: usize) -> Result<SourceFrame, SourceError> {
        let label = format!("robot {}", self.name());
        match self.frame(index) {
            Some(f) => Ok(source_frame(&f, self.arrival_ns(index))),
            None if index < self.first_kept() => Err(SourceError::Unsupported {
                label,
                detail: format!(
                    "frame {index} is no longer in memory (the byte budget keeps frames {} on)",
                    self.first_kept()
                ),
            }),
            None => Err(SourceError::NoSuchFrame {
                label,
                index,
                len: RobotFrames::len(self),
            }),
        }
    }
}
