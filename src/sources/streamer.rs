//! Any source grabbed at a fixed rate on its own thread. The thread owns the source and the
//! recorder; the UI (or a CLI loop) only polls a channel, so a camera waiting for its next frame
//! or a renderer drawing one never blocks it. Recording happens on the thread too, so every
//! grabbed frame is written even when the UI shows only the latest.

use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, SyncSender, TrySendError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::{FrameSource, Recorder, SourceError, SourceFrame, SourceInfo, SourceSettings};
use crate::streams::StreamError;

/// Frames waiting for the UI before new ones are dropped (the UI shows the latest anyway).
const QUEUE_FRAMES: usize = 4;

/// What the streaming thread reports.
#[derive(Debug)]
pub enum StreamerEvent {
    /// A new frame (boxed: sensor readings make it large).
    Frame(Box<SourceFrame>),
    /// The settings now in effect (after a change was asked for).
    Settings(SourceSettings),
    /// A recording finished: its file and frame count, or why it failed.
    RecordingStopped {
        /// The stream written.
        path: std::path::PathBuf,
        /// Frames written, or why writing failed.
        result: Result<usize, StreamError>,
    },
    /// A grab or a settings change failed; streaming goes on.
    Error(SourceError),
}

enum Control {
    SetSettings(SourceSettings),
    SetRate(f64),
    StartRecording(Box<Recorder>),
    StopRecording,
    SetStreaming(bool),
    GrabOne,
    Stop,
}

/// A source streaming on its own thread; see the module documentation.
#[derive(Debug)]
pub struct Streamer {
    info: SourceInfo,
    control: Sender<Control>,
    /// Everything but frames: never dropped, never blocks the thread.
    events: Receiver<StreamerEvent>,
    /// Frames, at most [`QUEUE_FRAMES`] waiting; the thread drops new ones when it is full.
    frames: Receiver<SourceFrame>,
    thread: Option<JoinHandle<Box<dyn FrameSource>>>,
    recording: Option<std::path::PathBuf>,
    rate_hz: f64,
    streaming: bool,
}

impl Streamer {
    /// Connects `source` and starts grabbing `rate_hz` frames a second on a new thread.
    ///
    /// # Errors
    /// The source cannot connect; a rate that is not positive and finite.
    pub fn start(mut source: Box<dyn FrameSource>, rate_hz: f64) -> Result<Self, SourceError> {
        let info = source.info();
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(SourceError::Unsupported {
                label: info.label,
                detail: format!("cannot stream at {rate_hz} frames a second"),
            });
        }
        source.connect()?;
        let (control, control_rx) = mpsc::channel();
        let (events_tx, events) = mpsc::channel();
        let (frames_tx, frames) = mpsc::sync_channel(QUEUE_FRAMES);
        let thread = std::thread::Builder::new()
            .name(format!("source {}", info.label))
            .spawn(move || {
                let out = Outbox {
                    events: events_tx,
                    frames: frames_tx,
                };
                run(source, rate_hz, &control_rx, &out)
            })
            .map_err(|e| SourceError::Device {
                label: info.label.clone(),
                detail: format!("cannot start its thread: {e}"),
            })?;
        Ok(Self {
            info,
            control,
            events,
            frames,
            thread: Some(thread),
            recording: None,
            rate_hz,
            streaming: true,
        })
    }

    /// What is streaming.
    #[must_use]
    pub const fn info(&self) -> &SourceInfo {
        &self.info
    }

    /// Frames a second asked for.
    #[must_use]
    pub const fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    /// Everything reported since the last call (settings, errors and recordings first, then
    /// the frames, oldest first); never waits.
    #[must_use]
    pub fn poll(&self) -> Vec<StreamerEvent> {
        let mut out: Vec<StreamerEvent> = self.events.try_iter().collect();
        out.extend(
            self.frames
                .try_iter()
                .map(|f| StreamerEvent::Frame(Box::new(f))),
        );
        out
    }

    /// Waits up to `timeout` for the next frame (tests and CLI loops; the UI polls).
    #[must_use]
    pub fn wait_frame(&self, timeout: Duration) -> Option<SourceFrame> {
        self.frames.recv_timeout(timeout).ok()
    }

    /// Waits up to `timeout` for the next event that is not a frame (frames meanwhile stay
    /// queued or are dropped).
    #[must_use]
    pub fn wait_event(&self, timeout: Duration) -> Option<StreamerEvent> {
        self.events.recv_timeout(timeout).ok()
    }

    /// Asks for other settings; the outcome arrives as [`StreamerEvent::Settings`] or
    /// [`StreamerEvent::Error`].
    pub fn set_settings(&self, wanted: SourceSettings) {
        self.send(Control::SetSettings(wanted));
    }

    /// Grabs at another rate from now on (ignored unless positive and finite).
    pub fn set_rate(&mut self, rate_hz: f64) {
        if rate_hz.is_finite() && rate_hz > 0.0 {
            self.rate_hz = rate_hz;
            self.send(Control::SetRate(rate_hz));
        }
    }

    /// Grabs at the rate (`true`, as it starts) or only when asked ([`Self::grab_one`]).
    pub fn set_streaming(&mut self, on: bool) {
        self.streaming = on;
        self.send(Control::SetStreaming(on));
    }

    /// True while grabbing at the rate.
    #[must_use]
    pub const fn streaming(&self) -> bool {
        self.streaming
    }

    /// Grabs one frame now (while paused: the one image of "Grab image").
    pub fn grab_one(&self) {
        self.send(Control::GrabOne);
    }

    /// Starts writing every grabbed frame to `recorder` (a recording in progress is finished
    /// first).
    pub fn start_recording(&mut self, recorder: Recorder) {
        self.recording = Some(recorder.path().to_owned());
        self.send(Control::StartRecording(Box::new(recorder)));
    }

    /// Finishes the recording; [`StreamerEvent::RecordingStopped`] says how it went.
    pub fn stop_recording(&mut self) {
        self.recording = None;
        self.send(Control::StopRecording);
    }

    /// The stream being recorded, if any.
    #[must_use]
    pub fn recording(&self) -> Option<&std::path::Path> {
        self.recording.as_deref()
    }

    /// Stops the thread (finishing a recording) and hands the source back, disconnected.
    pub fn stop(mut self) -> Option<Box<dyn FrameSource>> {
        self.send(Control::Stop);
        self.thread.take().and_then(|t| t.join().ok())
    }

    fn send(&self, c: Control) {
        // A send fails only when the thread has ended (it panicked): nothing left to control.
        let _ = self.control.send(c);
    }
}

impl Drop for Streamer {
    fn drop(&mut self) {
        if let Some(t) = self.thread.take() {
            let _ = self.control.send(Control::Stop);
            let _ = t.join();
        }
    }
}

/// Where the thread reports to.
struct Outbox {
    events: Sender<StreamerEvent>,
    frames: SyncSender<SourceFrame>,
}

impl Outbox {
    fn event(&self, e: StreamerEvent) {
        // Fails only when the Streamer is gone; then nobody is listening.
        let _ = self.events.send(e);
    }
}

/// What the thread keeps between grabs.
struct Worker {
    source: Box<dyn FrameSource>,
    rate_hz: f64,
    recorder: Option<Box<Recorder>>,
    streaming: bool,
    /// The last error reported, so a failing source says so once, not 30 times a second.
    last_error: String,
}

/// What the thread does after waiting.
enum Next {
    Grab,
    Stop,
}

/// The thread: grab, record, hand over, wait for the next tick or a control message.
fn run(
    source: Box<dyn FrameSource>,
    rate_hz: f64,
    control: &Receiver<Control>,
    out: &Outbox,
) -> Box<dyn FrameSource> {
    let mut w = Worker {
        source,
        rate_hz,
        recorder: None,
        streaming: true,
        last_error: String::new(),
    };
    let mut next = Instant::now();
    loop {
        if !w.grab_and_send(out) {
            break;
        }
        if w.streaming {
            next += Duration::from_secs_f64(1.0 / w.rate_hz);
            // Behind (a slow source): start counting again rather than grabbing in a burst.
            next = next.max(Instant::now());
        }
        if matches!(w.wait(control, out, &mut next), Next::Stop) {
            break;
        }
    }
    finish(w.recorder.take(), out);
    w.source.disconnect();
    w.source
}

impl Worker {
    /// Grabs one frame, records it and queues it; false when nobody listens any more.
    fn grab_and_send(&mut self, out: &Outbox) -> bool {
        match self.source.grab() {
            Ok(frame) => {
                self.last_error.clear();
                if let Some(r) = self.recorder.as_mut()
                    && let Err(e) = r.record(&frame)
                {
                    let path = r.path().to_owned();
                    self.recorder = None;
                    let result = Err(e);
                    out.event(StreamerEvent::RecordingStopped { path, result });
                }
                match out.frames.try_send(frame) {
                    Ok(()) | Err(TrySendError::Full(_)) => true,
                    Err(TrySendError::Disconnected(_)) => false,
                }
            }
            Err(e) => {
                let msg = e.to_string();
                if msg != self.last_error {
                    out.event(StreamerEvent::Error(e));
                    self.last_error = msg;
                }
                true
            }
        }
    }

    /// Handles control messages until the next grab is due (streaming) or asked for (paused).
    fn wait(&mut self, control: &Receiver<Control>, out: &Outbox, next: &mut Instant) -> Next {
        loop {
            let message = if self.streaming {
                match control.recv_timeout(next.saturating_duration_since(Instant::now())) {
                    Ok(c) => c,
                    Err(RecvTimeoutError::Timeout) => return Next::Grab,
                    Err(RecvTimeoutError::Disconnected) => return Next::Stop,
                }
            } else {
                match control.recv() {
                    Ok(c) => c,
                    Err(_) => return Next::Stop,
                }
            };
            match message {
                Control::Stop => return Next::Stop,
                Control::SetSettings(s) => {
                    let event = match self.source.set_settings(&s) {
                        Ok(now) => StreamerEvent::Settings(now),
                        Err(e) => StreamerEvent::Error(e),
                    };
                    out.event(event);
                }
                Control::SetRate(r) => {
                    self.rate_hz = r;
                    *next = Instant::now() + Duration::from_secs_f64(1.0 / r);
                }
                Control::StartRecording(r) => finish(self.recorder.replace(r), out),
                Control::StopRecording => finish(self.recorder.take(), out),
                Control::SetStreaming(on) => {
                    self.streaming = on;
                    if on {
                        *next = Instant::now();
                        return Next::Grab;
                    }
                }
                Control::GrabOne => return Next::Grab,
            }
        }
    }
}

fn finish(recorder: Option<Box<Recorder>>, out: &Outbox) {
    if let Some(r) = recorder {
        let path = r.path().to_owned();
        let result = r.finish();
        out.event(StreamerEvent::RecordingStopped { path, result });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sources::{FileSource, StreamSource};

    fn two_frames(dir: &std::path::Path) -> FileSource {
        let paths = (0..2)
            .map(|i| {
                let p = dir.join(format!("{i}.uyvy"));
                std::fs::write(&p, vec![128u8; 208 * 160 * 2]).unwrap();
                p
            })
            .collect();
        FileSource::new(paths, None).unwrap()
    }

    #[test]
    fn a_streamed_source_delivers_frames_and_records_them_on_its_thread() {
        let dir = tempfile::tempdir().unwrap();
        let source = two_frames(dir.path());
        let mut s = Streamer::start(Box::new(source), 200.0).unwrap();
        assert!(s.wait_frame(Duration::from_secs(5)).is_some());
        let out = dir.path().join("live.mcap");
        s.start_recording(Recorder::create(&out, s.info()).unwrap());
        // Up to QUEUE_FRAMES frames and one in flight were grabbed before recording began.
        for _ in 0..QUEUE_FRAMES + 1 + 3 {
            assert!(s.wait_frame(Duration::from_secs(5)).is_some());
        }
        s.stop_recording();
        let done = s.wait_event(Duration::from_secs(5));
        let Some(StreamerEvent::RecordingStopped { path, result }) = done else {
            panic!("expected the recording to stop, got {done:?}");
        };
        assert_eq!(path, out);
        assert!(
            result.unwrap() >= 3,
            "every frame grabbed while recording is written"
        );
        let source = s.stop().unwrap();
        assert!(
            !source.is_connected(),
            "a stopped streamer disconnects its source"
        );
        let mut back = StreamSource::open(&out).unwrap();
        assert!(back.recorded().unwrap().len() >= 3);
    }

    #[test]
    fn a_settings_change_the_source_refuses_comes_back_as_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let s = Streamer::start(Box::new(two_frames(dir.path())), 50.0).unwrap();
        s.set_settings(SourceSettings {
            exposure: Some(10),
            ..SourceSettings::default()
        });
        let e = s.wait_event(Duration::from_secs(5));
        assert!(
            matches!(&e, Some(StreamerEvent::Error(m)) if m.to_string().contains("exposure")),
            "{e:?}"
        );
        assert!(Streamer::start(Box::new(two_frames(dir.path())), 0.0).is_err());
    }

    #[test]
    fn a_paused_streamer_grabs_only_when_asked() {
        let dir = tempfile::tempdir().unwrap();
        let mut s = Streamer::start(Box::new(two_frames(dir.path())), 100.0).unwrap();
        s.set_streaming(false);
        // Whatever was grabbed before the pause took effect drains away; then nothing comes.
        while s.wait_frame(Duration::from_millis(300)).is_some() {}
        s.grab_one();
        assert!(s.wait_frame(Duration::from_secs(5)).is_some());
        assert!(s.wait_frame(Duration::from_millis(300)).is_none());
        s.set_streaming(true);
        assert!(s.wait_frame(Duration::from_secs(5)).is_some());
    }
}
