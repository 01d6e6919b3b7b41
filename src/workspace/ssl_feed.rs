//! SSL-Vision detections beside eotn's own (`Command::Open` of a league log, `FILE.log` or
//! `.log.gz`, or of `udp://GROUP:PORT`): plain data the field view draws, each camera's
//! detections marked as that camera's.
//!
//! - A **log** is read whole when opened ([`crate::ssl_vision::log`]): its detection frames by
//!   camera and capture time. With a stream open, each camera's frame nearest the shown frame's
//!   time within half a frame period is shown (the same pairing as `eotn eval --truth-ssl`);
//!   opened alone, the log has its own steps (its frames' capture times), chosen with
//!   [`super::Command::ShowSslStep`].
//! - A **live** address is listened to on a thread ([`crate::ssl_vision::listener`]); each
//!   UI frame takes what arrived, and each camera's latest frame is shown. Packets that do not
//!   decode are counted and the first reason is warned about.
//!
//! Either way the field the packets' geometry describes is kept for the field view, and what is
//! shown is handed to the field model ([`super::field_model::FieldModel::set_ssl`]).

use anyhow::Context as _;

use super::Workspace;
use crate::overhead::FieldDescription;
use crate::ssl_vision::listener::{Listener, Received, is_udp_url};
use crate::ssl_vision::truth::FrameIndex;
use crate::ssl_vision::{CameraFrame, SslGeometryData};

/// Frames kept per camera of a live feed.
pub const LIVE_FRAMES_KEPT: usize = 600;

/// An open SSL-Vision source; see the module documentation.
#[derive(Debug)]
pub struct SslFeed {
    name: String,
    live: Option<Listener>,
    index: FrameIndex,
    field: Option<FieldDescription>,
    /// The log's steps (capture times, every camera) when it is shown alone.
    steps: Vec<u64>,
    step: usize,
    shown: Vec<CameraFrame>,
    /// Packets that did not decode, and the first reason.
    bad: (usize, Option<String>),
    /// What opening said (the log's counts, the address listened on).
    pub summary: String,
}

impl SslFeed {
    /// Opens a league log file or starts listening on `udp://GROUP:PORT`.
    ///
    /// # Errors
    /// A file that is not a league log (a B-Human robot log named as such), a log without
    /// detection frames, an address that cannot be listened on (port in use, group not joined).
    pub fn open(source: &std::path::Path) -> anyhow::Result<Self> {
        let name = source.display().to_string();
        if is_udp_url(&name) {
            let listener = Listener::start(&name)?;
            return Ok(Self {
                summary: format!("listening for SSL-Vision packets on {name}"),
                name,
                live: Some(listener),
                index: FrameIndex::default(),
                field: None,
                steps: Vec::new(),
                step: 0,
                shown: Vec::new(),
                bad: (0, None),
            });
        }
        let log = crate::ssl_vision::log::read_log_file(source).with_context(|| name.clone())?;
        let summary = format!("{name}: {}", log.summary());
        let index = FrameIndex::new(log.frames.into_iter().map(|f| f.frame));
        anyhow::ensure!(
            !index.is_empty(),
            "{summary}: no detection frame with a capture time to show"
        );
        let mut feed = Self {
            name,
            live: None,
            field: log.geometry.as_ref().map(field_of),
            steps: index.times_ns(),
            index,
            step: 0,
            shown: Vec::new(),
            bad: (0, None),
            summary,
        };
        feed.show_step(0);
        Ok(feed)
    }

    /// The log file or address.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// True for a live address.
    #[must_use]
    pub const fn is_live(&self) -> bool {
        self.live.is_some()
    }

    /// Each camera's frame shown now, by camera id.
    #[must_use]
    pub fn shown(&self) -> &[CameraFrame] {
        &self.shown
    }

    /// The field the packets' geometry describes, once one has come.
    #[must_use]
    pub const fn field(&self) -> Option<&FieldDescription> {
        self.field.as_ref()
    }

    /// Frames held, every camera.
    #[must_use]
    pub fn frames(&self) -> usize {
        self.index.len()
    }

    /// The log's steps when shown alone (its capture times), and the one shown.
    #[must_use]
    pub fn steps(&self) -> (usize, usize) {
        (self.steps.len(), self.step)
    }

    /// The first and last capture time held, nanoseconds.
    #[must_use]
    pub fn span_ns(&self) -> Option<(u64, u64)> {
        self.index.span_ns()
    }

    /// Packets that did not decode.
    #[must_use]
    pub const fn bad_packets(&self) -> usize {
        self.bad.0
    }

    /// Shows each camera's frame nearest `time_ns` within half of `period_ns`.
    pub fn show_at(&mut self, time_ns: u64, period_ns: u64) {
        if self.live.is_none() {
            self.shown = self
                .index
                .near(time_ns, period_ns)
                .into_iter()
                .cloned()
                .collect();
        }
    }

    /// Shows step `step` of a log opened alone: each camera's frame nearest that capture time
    /// within 20 ms (ssl-vision's cameras run at 60–75 Hz and are not in step).
    pub fn show_step(&mut self, step: usize) {
        let Some(&t) = self.steps.get(step.min(self.steps.len().saturating_sub(1))) else {
            return;
        };
        self.step = step.min(self.steps.len() - 1);
        self.show_at(t, 2 * STEP_WINDOW_NS);
    }

    /// Takes what a live feed received since the last call; returns a warning for the first
    /// packet that did not decode.
    pub fn poll(&mut self) -> Option<String> {
        let live = self.live.as_ref()?;
        let mut warning = None;
        for item in live.drain() {
            match item {
                Received::Packet { packet, .. } => {
                    if let Some(g) = &packet.geometry {
                        self.field = Some(field_of(g));
                    }
                    if let Some(d) = &packet.detection {
                        self.index.push(CameraFrame::from_message(d));
                    }
                }
                Received::Bad { from, why } => {
                    self.bad.0 += 1;
                    if self.bad.1.is_none() {
                        warning = Some(format!(
                            "{}: a packet from {from} is not SSL-Vision: {why} (skipped; later ones counted)",
                            self.name
                        ));
                        self.bad.1 = Some(why);
                    }
                }
            }
        }
        self.index.keep_last(LIVE_FRAMES_KEPT);
        self.shown = self.index.latest().into_iter().cloned().collect();
        warning
    }
}

/// Half the window a log shown alone gathers each camera's frames in, nanoseconds.
const STEP_WINDOW_NS: u64 = 10_000_000;

/// The field of a geometry message.
fn field_of(g: &SslGeometryData) -> FieldDescription {
    crate::ssl_vision::geometry::field_description(&g.field)
}

impl Workspace {
    /// The SSL-Vision source opened beside the frames, if any.
    #[must_use]
    pub const fn ssl_vision(&self) -> Option<&SslFeed> {
        self.ssl_vision.as_ref()
    }

    /// Opens a league log or a live address (replacing one opened before); the field view
    /// window opens to show it.
    pub(super) fn open_ssl(&mut self, source: &std::path::Path) -> anyhow::Result<()> {
        let feed = SslFeed::open(source)?;
        self.status.clone_from(&feed.summary);
        self.ssl_vision = Some(feed);
        self.settings.show_field_view = true;
        self.sync_ssl();
        Ok(())
    }

    /// Pairs the SSL frames with the shown frame's time (a log beside a stream) and hands what
    /// is shown to the field model.
    pub(super) fn sync_ssl(&mut self) {
        let Some(feed) = self.ssl_vision.as_mut() else {
            return;
        };
        if let (Some(current), Some(src)) = (&self.current, &self.source) {
            let times: Vec<u64> = (0..src.len().min(200)).map(|i| src.time_ns(i)).collect();
            let period = crate::wmd::clock::frame_period_ns(&times);
            feed.show_at(current.time_ns, period);
        }
        self.overhead.field_model.set_ssl(feed.shown());
    }

    /// Takes a live feed's packets (each UI frame).
    pub(super) fn poll_ssl(&mut self) {
        let Some(feed) = self.ssl_vision.as_mut() else {
            return;
        };
        if !feed.is_live() {
            return;
        }
        let warning = feed.poll();
        self.overhead.field_model.set_ssl(feed.shown());
        if let Some(w) = warning {
            self.warn(w);
        }
    }

    /// Shows a step of a log opened alone.
    pub(super) fn show_ssl_step(&mut self, step: usize) -> anyhow::Result<()> {
        let feed = self.ssl_vision.as_mut().context("no SSL-Vision log open")?;
        anyhow::ensure!(!feed.is_live(), "a live SSL-Vision feed has no steps");
        feed.show_step(step);
        self.overhead.field_model.set_ssl(feed.shown());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use prost::Message as _;

    use super::super::Command;
    use super::*;
    use crate::ssl_vision::log::{MessageType, write_header, write_message};
    use crate::ssl_vision::messages::{SslDetectionBall, SslDetectionFrame};
    use crate::ssl_vision::{SslWrapperPacket, geometry};

    fn packet(camera_id: u32, t: f64, x_mm: f32) -> Vec<u8> {
        SslWrapperPacket {
            detection: Some(SslDetectionFrame {
                camera_id,
                t_capture: t,
                balls: vec![SslDetectionBall {
                    confidence: 0.9,
                    x: x_mm,
                    ..SslDetectionBall::default()
                }],
                ..SslDetectionFrame::default()
            }),
            geometry: None,
        }
        .encode_to_vec()
    }

    #[test]
    fn a_log_opened_alone_steps_through_its_frames_by_camera() {
        let dir = tempfile::tempdir().expect("temp");
        let path = dir.path().join("game.log");
        let mut log = Vec::new();
        write_header(&mut log);
        let field = FieldDescription::resolve("ssl-div-b").expect("shipped");
        let g = SslWrapperPacket {
            detection: None,
            geometry: Some(geometry::geometry_data(&field, &[]).0),
        };
        write_message(&mut log, 0, MessageType::Vision2014, &g.encode_to_vec());
        for k in 0..5 {
            let t = 100.0 + f64::from(k) / 60.0;
            write_message(&mut log, 0, MessageType::Vision2014, &packet(0, t, 100.0));
            write_message(
                &mut log,
                0,
                MessageType::Vision2014,
                &packet(1, t + 0.002, 200.0),
            );
            write_message(&mut log, 0, MessageType::Refbox2013, b"");
        }
        std::fs::write(&path, &log).expect("write");
        let mut w = Workspace::default();
        w.apply(Command::Open(vec![path])).expect("opens");
        let feed = w.ssl_vision().expect("a feed");
        assert_eq!(feed.frames(), 10);
        assert!(feed.summary.contains("5 referee"), "{}", feed.summary);
        assert!(
            feed.field()
                .is_some_and(|f| f.lines.len() == field.lines.len())
        );
        let shown = w.overhead().field_model.ssl();
        assert_eq!(shown.len(), 2, "both cameras near the first step");
        assert_eq!(shown[1].balls[0].field_cm, [20.0, 0.0]);
        w.apply(Command::ShowSslStep(9)).expect("last step");
        assert_eq!(w.ssl_vision().map(SslFeed::steps), Some((10, 9)));
        assert!(w.apply(Command::ShowSslStep(0)).is_ok());
    }

    #[test]
    fn a_live_feed_shows_each_cameras_latest_frame_and_counts_bad_packets() {
        let probe = std::net::UdpSocket::bind("127.0.0.1:0").expect("port");
        let port = probe.local_addr().expect("address").port();
        drop(probe);
        let mut w = Workspace::default();
        let url = format!("udp://127.0.0.1:{port}");
        w.apply(Command::Open(vec![url.into()])).expect("listens");
        let sender = std::net::UdpSocket::bind("127.0.0.1:0").expect("socket");
        for (k, bytes) in [packet(3, 1.0, 10.0), vec![0xff, 0x01], packet(3, 1.1, 30.0)]
            .iter()
            .enumerate()
        {
            sender.send_to(bytes, ("127.0.0.1", port)).expect("send");
            let _ = k;
        }
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
        while w.ssl_vision().map_or(0, SslFeed::frames) < 2 && std::time::Instant::now() < deadline
        {
            std::thread::sleep(std::time::Duration::from_millis(20));
            w.tick(std::time::Duration::from_millis(20));
        }
        let feed = w.ssl_vision().expect("a feed");
        assert_eq!(feed.frames(), 2);
        assert_eq!(feed.bad_packets(), 1);
        assert!(w.warnings().iter().any(|m| m.contains("not SSL-Vision")));
        assert_eq!(
            w.overhead().field_model.ssl()[0].balls[0].field_cm,
            [3.0, 0.0]
        );
    }
}
