//! The workspace's playback: the Step, Seek, Play and Speed commands, the once-per-UI-frame
//! [`Workspace::tick`] that moves playback and the background scans on, when the next frame is
//! due, and the frame-time records of the readout. The clock itself is [`super::Player`].

use std::time::Duration;

use anyhow::Context as _;

use super::timings::push_capped;
use super::{PlaybackCommand, SCAN_BUDGET, Workspace};

impl Workspace {
    /// Applies the playback commands (the rest of [`Workspace::apply`]).
    pub(super) fn apply_playback(&mut self, command: PlaybackCommand) -> anyhow::Result<()> {
        match command {
            PlaybackCommand::Step(delta) => self.step(delta)?,
            PlaybackCommand::Seek(i) => self.seek(i)?,
            PlaybackCommand::SetPlaying(p) => self.set_playing(p)?,
            PlaybackCommand::SetSpeed(s) => {
                self.settings.speed = if s.is_finite() { s.max(0.0) } else { 1.0 }
            }
        }
        Ok(())
    }

    fn set_playing(&mut self, on: bool) -> anyhow::Result<()> {
        if !on {
            self.player.stop();
            return Ok(());
        }
        let len = self
            .source
            .as_ref()
            .context("no stream or frames open")?
            .len();
        if self.index + 1 >= len {
            // Playing from the end starts again.
            self.seek(0)?;
        }
        if let Some(src) = &self.source {
            self.player.play_from(src, self.index);
        }
        Ok(())
    }

    /// Advances playback and background scans by `dt` of wall time. Called once per UI frame.
    pub fn tick(&mut self, dt: Duration) {
        self.poll_live();
        self.poll_robots();
        self.poll_ssl();
        self.scan_sensor_series();
        if let (Some(t), Some(src)) = (self.try_edit.as_mut(), self.source.as_mut()) {
            let (conn, min) = (self.settings.connectivity, self.settings.min_blob_pixels);
            t.scan(src, self.pipeline.lut(), conn, min, SCAN_BUDGET);
        }
        self.tick_hints();
        self.tick_labels();
        self.scan_try_params(SCAN_BUDGET);
        let Some(src) = self.source.as_ref() else {
            self.player.stop();
            return;
        };
        if let Some(target) = self.player.tick(dt, self.settings.speed, self.index, src) {
            self.timings.played_frames += 1;
            self.timings.dropped_frames += target.saturating_sub(self.index + 1) as u64;
            self.timings.late_frames += u64::from(self.player.last_was_late());
            self.run(PlaybackCommand::Seek(target).into());
        }
    }

    /// While playing, the wall time until the next frame is due (zero when playing every frame
    /// or already late); `None` when not playing. The UI sleeps until then instead of redrawing
    /// an unchanged frame.
    #[must_use]
    pub fn next_frame_due(&self) -> Option<Duration> {
        if let Some(live) = self.live.as_ref().filter(|l| l.streaming()) {
            // Frames arrive on their own thread: look for one about twice a frame interval.
            let rate = live
                .settings()
                .frame_rate
                .filter(|r| *r > 0.0)
                .unwrap_or(30.0);
            return Some(Duration::from_secs_f64(0.5 / rate.min(240.0)));
        }
        // A live SSL-Vision feed is looked at about 20 times a second.
        let robots = self.robots_poll_due().or_else(|| {
            self.ssl_vision()
                .filter(|f| f.is_live())
                .map(|_| Duration::from_millis(50))
        });
        let player = self.source.as_ref().and_then(|src| {
            self.player
                .next_frame_due(self.settings.speed, self.index, src)
        });
        match (robots, player) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Records one UI frame interval for the frame-time readout.
    pub fn record_frame_time(&mut self, dt: Duration) {
        let ms = dt.as_secs_f64() * 1e3;
        push_capped(&mut self.timings.frames_ms, ms);
        if self.player.playing() {
            push_capped(&mut self.timings.playing_frames_ms, ms);
        }
    }

    /// Records a UI frame interval that followed a frame with input.
    pub fn record_input_frame_time(&mut self, dt: Duration) {
        push_capped(&mut self.timings.input_frames_ms, dt.as_secs_f64() * 1e3);
    }

    /// Records, while playing, how long our UI code and eframe's whole frame took (CPU time).
    pub fn record_ui_time(&mut self, ui: Duration, cpu_s: Option<f32>) {
        if self.player.playing() {
            push_capped(&mut self.timings.playing_ui_ms, ui.as_secs_f64() * 1e3);
            if let Some(c) = cpu_s.filter(|c| c.is_finite()) {
                push_capped(&mut self.timings.playing_cpu_ms, f64::from(c) * 1e3);
            }
        }
    }

    /// Records the texture-upload part of the last step (measured by the UI).
    pub fn record_upload(&mut self, d: Duration) {
        self.timings.last_step.upload = d;
        let total = self.timings.last_step.total().as_secs_f64() * 1e3;
        push_capped(&mut self.timings.steps_ms, total);
        if self.timings.step_parts.len() >= self.timings.steps_ms.len() {
            self.timings.step_parts.remove(0);
        }
        self.timings.step_parts.push(self.timings.last_step);
    }
}
