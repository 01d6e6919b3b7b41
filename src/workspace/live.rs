//! Connected sources: a live source (camera, synthetic scenario, network) streaming on its own
//! thread and shown as its frames arrive, a recorded source opened through the same menu, and
//! recording either into an MCAP stream.

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use super::source::Source;
use super::{SourceCommand, Workspace};
use crate::sources::{
    Recorder, SourceControls, SourceFrame, SourceInfo, SourceSettings, SourceSpec, Streamer,
    StreamerEvent,
};

/// Frames a second a live source streams at when it does not say (the cameras' 30).
const DEFAULT_RATE_HZ: f64 = 30.0;

/// A live source streaming on its own thread.
#[derive(Debug)]
pub struct Live {
    streamer: Streamer,
    settings: SourceSettings,
    controls: SourceControls,
    frames: u64,
}

impl Live {
    /// What is connected.
    #[must_use]
    pub const fn info(&self) -> &SourceInfo {
        self.streamer.info()
    }

    /// Its settings as last reported.
    #[must_use]
    pub const fn settings(&self) -> &SourceSettings {
        &self.settings
    }

    /// What may be changed (sizes, rates, exposure and gain ranges).
    #[must_use]
    pub const fn controls(&self) -> &SourceControls {
        &self.controls
    }

    /// Frames shown since connecting.
    #[must_use]
    pub const fn frames(&self) -> u64 {
        self.frames
    }

    /// True while it streams at its rate (false after Grab image until streaming again).
    #[must_use]
    pub const fn streaming(&self) -> bool {
        self.streamer.streaming()
    }
}

impl Workspace {
    /// Applies the Camera menu's source commands: connect, disconnect, settings, grab,
    /// streaming, recording (the rest of [`Workspace::apply`]).
    pub(super) fn apply_source(&mut self, command: SourceCommand) -> anyhow::Result<()> {
        match command {
            SourceCommand::Connect(spec) => self.connect(&spec)?,
            SourceCommand::Disconnect => self.disconnect()?,
            SourceCommand::SetSourceSettings(s) => self.set_source_settings(s)?,
            SourceCommand::GrabImage => self.grab_image()?,
            SourceCommand::SetStreaming(on) => self.set_streaming(on)?,
            SourceCommand::StartRecording(p) => self.start_recording(&p)?,
            SourceCommand::StopRecording => self.stop_recording()?,
        }
        Ok(())
    }

    /// Connects `spec`: a recorded source is opened for stepping and playback, a live one starts
    /// streaming on its own thread. What was connected before is disconnected.
    pub(super) fn connect(&mut self, spec: &SourceSpec) -> anyhow::Result<()> {
        if let SourceSpec::Network(address) = spec {
            // One way to connect a robot: into the robots list, shown at once.
            let id = self.connect_robot(address)?;
            return self.show_robot(id);
        }
        if spec.is_recorded() {
            let source = Source::new(spec.open_recorded()?);
            self.disconnect_live();
            for p in source.paths() {
                self.remember_recent(&p);
            }
            return self.set_source(source);
        }
        let source = open_live(spec)?;
        let settings = source.settings();
        let controls = source.controls();
        let rate = settings
            .frame_rate
            .filter(|r| *r > 0.0)
            .unwrap_or(DEFAULT_RATE_HZ);
        let streamer = Streamer::start(source, rate)?;
        self.disconnect_live();
        self.stop_recording_recorded();
        self.source = None;
        self.robots.unshow();
        self.player.stop();
        self.try_edit = None;
        self.current = None;
        self.index = 0;
        self.reset_overhead_for_source();
        let info = streamer.info().clone();
        self.use_table_of(info.camera);
        self.sensor_series = super::SensorSeries::default();
        self.status = format!("connected {} ({} camera)", info.label, info.camera.name());
        self.live = Some(Live {
            streamer,
            settings,
            controls,
            frames: 0,
        });
        Ok(())
    }

    /// Disconnects the live source or closes the recorded one, finishing a recording.
    pub(super) fn disconnect(&mut self) -> anyhow::Result<()> {
        if let Some(id) = self.shown_robot() {
            return self.disconnect_robot(id);
        }
        if let Some(label) = self.disconnect_live() {
            self.status = format!("disconnected {label}");
            return Ok(());
        }
        let src = self.source.take().context("nothing connected")?;
        self.stop_recording_recorded();
        self.player.stop();
        self.try_edit = None;
        self.current = None;
        self.frame_generation += 1;
        self.status = format!("closed {}", src.label());
        Ok(())
    }

    /// Stops the live source's thread (finishing its recording); its label, if one was live.
    pub(super) fn disconnect_live(&mut self) -> Option<String> {
        let live = self.live.take()?;
        let label = live.info().label.clone();
        let mut streamer = live.streamer;
        if streamer.recording().is_some() {
            streamer.stop_recording();
        }
        let events = streamer.poll();
        drop(streamer.stop());
        self.handle_events(events);
        Some(label)
    }

    /// Asks the source for other settings (resolution, frame rate, exposure, gain).
    pub(super) fn set_source_settings(&mut self, wanted: SourceSettings) -> anyhow::Result<()> {
        let live = self
            .live
            .as_mut()
            .context("settings change only for a connected camera or live source")?;
        if let Some(rate) = wanted.frame_rate {
            live.streamer.set_rate(rate);
        }
        live.streamer.set_settings(wanted);
        Ok(())
    }

    /// One new image: a live source stops streaming and grabs one; a recorded one steps on.
    pub(super) fn grab_image(&mut self) -> anyhow::Result<()> {
        if let Some(live) = self.live.as_mut() {
            live.streamer.set_streaming(false);
            live.streamer.grab_one();
            self.status = "grabbing one image (Camera ▸ Stream live resumes)".to_owned();
            return Ok(());
        }
        anyhow::ensure!(self.source.is_some(), "nothing connected to grab from");
        self.step(1)
    }

    /// Streams the live source at its rate again, or holds it (after Grab image).
    pub(super) fn set_streaming(&mut self, on: bool) -> anyhow::Result<()> {
        let live = self.live.as_mut().context("no live source connected")?;
        live.streamer.set_streaming(on);
        Ok(())
    }

    /// Records what the connected source delivers into `path` (a live source: every frame it
    /// grabs, on its thread; a recorded one: every frame shown from now on).
    pub(super) fn start_recording(&mut self, path: &Path) -> anyhow::Result<()> {
        anyhow::ensure!(
            crate::streams::is_stream_file(path),
            "{}: a recording is an MCAP stream: name it NAME.mcap",
            path.display()
        );
        if let Some(id) = self.shown_robot() {
            // A robot records every message as it came, with its own recorder.
            return self.record_robot(id, path);
        }
        let info = self
            .connected_info()
            .context("nothing connected to record")?;
        anyhow::ensure!(
            !info.paths.iter().any(|p| same_file(p, path)),
            "{}: cannot record a stream into itself",
            path.display()
        );
        let recorder = Recorder::create(path, &info)?;
        if let Some(live) = self.live.as_mut() {
            live.streamer.start_recording(recorder);
        } else {
            self.stop_recording_recorded();
            let mut recorder = recorder;
            if let Some(c) = &self.current {
                recorder.record(c)?;
            }
            self.recorder = Some(recorder);
        }
        self.status = format!("recording {} into {}", info.label, path.display());
        Ok(())
    }

    /// Finishes the recording.
    pub(super) fn stop_recording(&mut self) -> anyhow::Result<()> {
        if let Some(id) = self.shown_robot() {
            return self.stop_recording_robot(id);
        }
        if let Some(live) = self.live.as_mut()
            && live.streamer.recording().is_some()
        {
            // The thread finishes the file; tick reports how it went.
            live.streamer.stop_recording();
            self.status = "finishing the recording…".to_owned();
            return Ok(());
        }
        anyhow::ensure!(self.recorder.is_some(), "not recording");
        self.stop_recording_recorded();
        Ok(())
    }

    pub(super) fn stop_recording_recorded(&mut self) {
        if let Some(r) = self.recorder.take() {
            let path = r.path().to_owned();
            match r.finish() {
                Ok(n) => self.status = format!("recorded {n} frames into {}", path.display()),
                Err(e) => self.warn(format!("recording stopped: {e}")),
            }
        }
    }

    /// Writes a newly shown frame of a recorded source into the recording, if one runs.
    pub(super) fn record_shown(&mut self, frame: &SourceFrame) {
        if let Some(r) = self.recorder.as_mut()
            && let Err(e) = r.record(frame)
        {
            self.recorder = None;
            self.warn(format!("recording stopped: {e}"));
        }
    }

    /// Shows what the live source delivered since the last UI frame (the latest frame only).
    pub(super) fn poll_live(&mut self) {
        let Some(live) = self.live.as_ref() else {
            return;
        };
        let events = live.streamer.poll();
        self.handle_events(events);
    }

    fn handle_events(&mut self, events: Vec<StreamerEvent>) {
        let mut latest = None;
        for e in events {
            match e {
                StreamerEvent::Frame(f) => latest = Some(*f),
                StreamerEvent::Settings(s) => {
                    if let Some(live) = self.live.as_mut() {
                        live.settings = s;
                    }
                    self.status = "source settings changed".to_owned();
                }
                StreamerEvent::RecordingStopped { path, result } => match result {
                    Ok(n) => {
                        self.status = format!("recorded {n} frames into {}", path.display());
                    }
                    Err(e) => self.warn(format!("recording into {} stopped: {e}", path.display())),
                },
                StreamerEvent::Error(e) => self.warn(e.to_string()),
            }
        }
        if let Some(f) = latest {
            self.show_live_frame(f);
        }
    }

    fn show_live_frame(&mut self, frame: SourceFrame) {
        let t = self.run_pipeline(&frame);
        self.rgb.reset();
        for w in &frame.warnings {
            if !self.warnings.contains(w) {
                self.warn(w.clone());
            }
        }
        self.current = Some(frame);
        if let Some(live) = self.live.as_mut() {
            live.frames += 1;
            self.index = usize::try_from(live.frames - 1).unwrap_or(usize::MAX);
        }
        self.refresh_preview();
        self.timings.last_step = super::StepTiming {
            classify: t.classify,
            blobs: t.blobs,
            recognition: t.recognition,
            ..super::StepTiming::default()
        };
        self.frame_generation += 1;
    }

    /// What is connected, live or recorded.
    #[must_use]
    pub fn connected_info(&self) -> Option<SourceInfo> {
        self.live
            .as_ref()
            .map(|l| l.info().clone())
            .or_else(|| self.source.as_ref().map(|s| s.info().clone()))
    }

    /// The live source, when one is connected.
    #[must_use]
    pub const fn live(&self) -> Option<&Live> {
        self.live.as_ref()
    }

    /// The stream being recorded into, if any.
    #[must_use]
    pub fn recording(&self) -> Option<PathBuf> {
        self.live
            .as_ref()
            .and_then(|l| l.streamer.recording().map(Path::to_owned))
            .or_else(|| self.recorder.as_ref().map(|r| r.path().to_owned()))
            .or_else(|| self.shown_robot_recording())
    }
}

/// Builds and connects a live source. Every kind is built by [`SourceSpec::open`] except the
/// network source, which lives in a module after `sources` in the data flow and is built here.
fn open_live(spec: &SourceSpec) -> anyhow::Result<Box<dyn crate::sources::FrameSource>> {
    match spec {
        SourceSpec::Network(address) => {
            let mut robot = crate::live::NetworkSource::new(address)?;
            crate::sources::FrameSource::connect(&mut robot)?;
            Ok(Box::new(robot))
        }
        other => Ok(other.open()?),
    }
}

/// True when `a` and `b` name the same file (either may not exist yet).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

#[cfg(test)]
mod tests {
    use std::time::{Duration, Instant};

    use super::*;
    use crate::sim::ScenarioKind;
    use crate::sources::{CameraKind, FrameSource as _, RecordedSource as _, StreamSource};
    use crate::workspace::{PlaybackCommand, TableCommand};

    fn synthetic(scenario: ScenarioKind) -> SourceSpec {
        SourceSpec::Synthetic { scenario, seed: 2 }
    }

    /// Ticks until `done` holds (frames arrive from the source's thread), at most 60 s.
    fn tick_until(w: &mut Workspace, done: impl Fn(&Workspace) -> bool) {
        let start = Instant::now();
        while !done(w) {
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "{:?}",
                w.warnings()
            );
            w.tick(Duration::from_millis(10));
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    #[test]
    fn a_connected_scenario_streams_its_frames_into_the_workspace() {
        let mut w = Workspace::default();
        w.apply(SourceCommand::Connect(synthetic(ScenarioKind::BallEdge)).into())
            .unwrap();
        assert!(w.live().is_some() && w.source().is_none());
        assert!(
            w.next_frame_due().is_some(),
            "a streaming source keeps the UI polling"
        );
        tick_until(&mut w, |w| w.live().is_some_and(|l| l.frames() >= 2));
        assert_eq!(w.image_size(), (208, 160));
        assert!(w.current().is_some_and(|f| f.sensors.is_some()));
        assert!(w.title().contains("synthetic ball-edge"), "{}", w.title());
        w.apply(SourceCommand::Disconnect.into()).unwrap();
        assert!(w.live().is_none());
        assert!(
            w.apply(SourceCommand::Disconnect.into()).is_err(),
            "nothing left to disconnect"
        );
    }

    #[test]
    fn grab_image_holds_a_live_source_on_one_new_frame() {
        let mut w = Workspace::default();
        w.apply(SourceCommand::Connect(synthetic(ScenarioKind::BallEdge)).into())
            .unwrap();
        tick_until(&mut w, |w| w.live().is_some_and(|l| l.frames() >= 1));
        w.apply(SourceCommand::GrabImage.into()).unwrap();
        assert!(!w.live().unwrap().streaming());
        assert_eq!(w.next_frame_due(), None, "a held source needs no polling");
        let before = w.live().unwrap().frames();
        tick_until(&mut w, |w| w.live().is_some_and(|l| l.frames() > before));
        w.apply(SourceCommand::SetStreaming(true).into()).unwrap();
        assert!(w.live().unwrap().streaming());
    }

    #[test]
    fn an_overhead_source_uses_the_overhead_table_and_keeps_the_robot_table() {
        let mut w = Workspace::default();
        w.apply(TableCommand::NewTable(6).into()).unwrap();
        assert_eq!(w.lut().bits(), 6);
        w.apply(SourceCommand::Connect(synthetic(ScenarioKind::OverheadGame)).into())
            .unwrap();
        assert_eq!(w.camera_kind(), CameraKind::Overhead);
        assert_eq!(w.table_kind(), CameraKind::Overhead);
        assert_eq!(w.lut().bits(), 7, "the overhead slot starts as a new table");
        assert_eq!(w.other_table().lut.bits(), 6);
        w.apply(SourceCommand::Connect(synthetic(ScenarioKind::BallEdge)).into())
            .unwrap();
        assert_eq!(w.table_kind(), CameraKind::Robot);
        assert_eq!(w.lut().bits(), 6, "the robot table is back");
    }

    #[test]
    fn recording_a_live_source_writes_a_stream_that_opens_as_the_same_camera_kind() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("live.mcap");
        let mut w = Workspace::default();
        w.apply(SourceCommand::Connect(synthetic(ScenarioKind::OverheadGame)).into())
            .unwrap();
        assert!(
            w.apply(SourceCommand::StartRecording(dir.path().join("x.txt")).into())
                .is_err()
        );
        w.apply(SourceCommand::StartRecording(out.clone()).into())
            .unwrap();
        assert_eq!(w.recording(), Some(out.clone()));
        let start = w.live().unwrap().frames();
        tick_until(&mut w, |w| {
            w.live().is_some_and(|l| l.frames() >= start + 3)
        });
        w.apply(SourceCommand::StopRecording.into()).unwrap();
        tick_until(&mut w, |_| out.exists());
        assert!(w.recording().is_none());
        let mut back = StreamSource::open(&out).unwrap();
        assert!(back.len() >= 2, "{} frames", back.len());
        assert_eq!(back.info().camera, CameraKind::Overhead);
        assert!(back.read(0).unwrap().channel("/ground_truth").is_some());
    }

    #[test]
    fn recording_a_recorded_source_writes_the_frames_shown() {
        let dir = tempfile::tempdir().unwrap();
        let paths: Vec<PathBuf> = (0..3)
            .map(|i| {
                let p = dir.path().join(format!("{i}.uyvy"));
                std::fs::write(&p, vec![128u8; 208 * 160 * 2]).unwrap();
                p
            })
            .collect();
        let mut w = Workspace::default();
        w.apply(SourceCommand::Connect(SourceSpec::Files(paths)).into())
            .unwrap();
        let out = dir.path().join("shown.mcap");
        w.apply(SourceCommand::StartRecording(out.clone()).into())
            .unwrap();
        w.apply(SourceCommand::GrabImage.into()).unwrap();
        w.apply(PlaybackCommand::Step(1).into()).unwrap();
        w.apply(PlaybackCommand::Step(-2).into()).unwrap();
        w.apply(SourceCommand::StopRecording.into()).unwrap();
        let back = StreamSource::open(&out).unwrap();
        assert_eq!(
            back.len(),
            3,
            "frames 0, 1, 2; stepping back records nothing"
        );
        assert!(w.apply(SourceCommand::StopRecording.into()).is_err());
    }
}
