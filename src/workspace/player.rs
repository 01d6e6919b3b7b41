//! Playback of a recorded source: a clock that runs at a speed (× recorded rate) and says which
//! frame is due and when the next one is, so the UI redraws only when a frame changes.

use std::time::Duration;

/// The times of a recording's frames, all playback needs to know about it.
pub trait Timeline {
    /// Number of frames.
    fn frames(&self) -> usize;
    /// Time of frame `index`, nanoseconds since the first frame.
    fn time_ns(&self, index: usize) -> u64;
    /// The last frame at or before `time_ns`.
    fn index_at_time(&self, time_ns: u64) -> usize;
}

/// How far behind its clock playback at a set speed may show frames (wall time) before it skips
/// them. One slow UI frame (a scheduler hiccup on a shared machine, a stalled buffer swap) then
/// costs no frame: the next one is shown a little late and the player catches up within a few
/// UI frames, because the next frame is due at once while it is behind. A machine that is
/// steadily too slow falls behind by more than this within a few frames and then skips, so `1x`
/// still plays at the recorded rate. Three frame periods at 30 fps.
pub const MAX_LAG: Duration = Duration::from_millis(100);

/// Playback state: playing or not, and the play clock in recording time.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Player {
    playing: bool,
    /// Recording time the clock shows, nanoseconds (fractional: slow speeds add less than 1 ns
    /// in a short frame).
    clock_ns: f64,
    /// The frame the last tick returned was shown after a later one was already due.
    late: bool,
}

impl Player {
    /// True while playing.
    #[must_use]
    pub const fn playing(&self) -> bool {
        self.playing
    }

    /// Starts the clock at frame `index`'s time.
    pub fn play_from(&mut self, timeline: &dyn Timeline, index: usize) {
        self.clock_ns = timeline.time_ns(index) as f64;
        self.playing = true;
    }

    /// Stops playing.
    pub fn stop(&mut self) {
        self.playing = false;
    }

    /// True when the frame the last [`Player::tick`] returned was shown late: a later frame was
    /// already due, and the player showed this one instead of skipping it (see [`MAX_LAG`]).
    #[must_use]
    pub const fn last_was_late(&self) -> bool {
        self.late
    }

    /// Advances the clock by `dt` of wall time at `speed` (× recorded rate; 0 or less plays
    /// every frame) from the shown frame `index`; returns the frame to show next, if another.
    /// When several frames are due, the next one is shown as long as it is at most [`MAX_LAG`]
    /// behind the clock; further behind, playback skips to the frame that is due.
    /// Reaching the last frame stops playback.
    pub fn tick(
        &mut self,
        dt: Duration,
        speed: f32,
        index: usize,
        timeline: &dyn Timeline,
    ) -> Option<usize> {
        if !self.playing {
            return None;
        }
        let len = timeline.frames();
        self.late = false;
        let target = if speed <= 0.0 {
            index + 1
        } else {
            self.clock_ns += dt.as_secs_f64() * 1e9 * f64::from(speed);
            #[expect(
                clippy::cast_possible_truncation,
                clippy::cast_sign_loss,
                reason = "the clock is non-negative and far below 2^64 ns"
            )]
            let clock = self.clock_ns as u64;
            let due = timeline.index_at_time(clock).max(index);
            let next = index + 1;
            let max_lag_ns = MAX_LAG.as_secs_f64() * 1e9 * f64::from(speed);
            if due > next
                && next < len
                && self.clock_ns - timeline.time_ns(next) as f64 <= max_lag_ns
            {
                self.late = true;
                next
            } else {
                due
            }
        };
        let target = target.min(len.saturating_sub(1));
        if target + 1 >= len {
            self.playing = false;
        }
        (target != index).then_some(target)
    }

    /// While playing, the wall time until the frame after `index` is due at `speed` (zero when
    /// playing every frame or already late, at most one second); `None` when not playing.
    #[must_use]
    pub fn next_frame_due(
        &self,
        speed: f32,
        index: usize,
        timeline: &dyn Timeline,
    ) -> Option<Duration> {
        if !self.playing {
            return None;
        }
        let speed = f64::from(speed);
        if speed <= 0.0 || index + 1 >= timeline.frames() {
            return Some(Duration::ZERO);
        }
        let next = timeline.time_ns(index + 1) as f64;
        let wait_s = ((next - self.clock_ns) / speed / 1e9).max(0.0);
        Some(Duration::from_secs_f64(wait_s.min(1.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames 100 ms apart.
    struct Tenths(usize);

    impl Timeline for Tenths {
        fn frames(&self) -> usize {
            self.0
        }
        fn time_ns(&self, index: usize) -> u64 {
            index as u64 * 100_000_000
        }
        fn index_at_time(&self, time_ns: u64) -> usize {
            usize::try_from(time_ns / 100_000_000)
                .unwrap()
                .min(self.0 - 1)
        }
    }

    const MS: Duration = Duration::from_millis(1);

    fn about(d: Option<Duration>, want: Duration) -> bool {
        d.is_some_and(|d| d.abs_diff(want) < Duration::from_micros(1))
    }

    #[test]
    fn a_stopped_player_shows_no_new_frame_and_waits_for_none() {
        let mut p = Player::default();
        assert_eq!(p.tick(MS * 500, 1.0, 0, &Tenths(10)), None);
        assert_eq!(p.next_frame_due(1.0, 0, &Tenths(10)), None);
    }

    #[test]
    fn playing_at_recorded_speed_shows_the_frame_whose_time_has_come() {
        let t = Tenths(10);
        let mut p = Player::default();
        p.play_from(&t, 2);
        assert_eq!(p.tick(MS * 50, 1.0, 2, &t), None, "half a frame interval");
        assert!(about(p.next_frame_due(1.0, 2, &t), MS * 50));
        assert_eq!(p.tick(MS * 60, 1.0, 2, &t), Some(3));
        assert_eq!(
            p.tick(MS * 200, 1.0, 3, &t),
            Some(5),
            "frames more than MAX_LAG behind the clock are skipped"
        );
        assert!(!p.last_was_late());
    }

    #[test]
    fn one_slow_ui_frame_shows_every_frame_late_and_then_catches_up() {
        // At 2x the frames are 50 ms of wall time apart.
        let t = Tenths(10);
        let mut p = Player::default();
        p.play_from(&t, 0);
        // A stall of 2.5 frame periods: frames 1 and 2 are both due.
        assert_eq!(p.tick(MS * 125, 2.0, 0, &t), Some(1), "not skipped");
        assert!(p.last_was_late());
        assert!(
            about(p.next_frame_due(2.0, 1, &t), Duration::ZERO),
            "frame 2 is due at once"
        );
        assert_eq!(p.tick(MS * 2, 2.0, 1, &t), Some(2));
        assert!(!p.last_was_late(), "back on time");
        assert!(about(p.next_frame_due(2.0, 2, &t), MS * 23));
    }

    #[test]
    fn a_machine_steadily_too_slow_still_plays_at_the_recorded_rate() {
        let t = Tenths(100);
        let mut p = Player::default();
        p.play_from(&t, 0);
        // Every UI frame takes 2.5 frame periods: after a few late frames it skips.
        let mut index = 0;
        let mut shown = 0;
        while let Some(next) = p.tick(MS * 250, 1.0, index, &t) {
            index = next;
            shown += 1;
        }
        assert_eq!(index, 99);
        assert!(
            shown <= 45,
            "at most about one in 2.5 frames shown, saw {shown}"
        );
    }

    #[test]
    fn double_speed_halves_the_wait_and_speed_zero_plays_every_frame() {
        let t = Tenths(10);
        let mut p = Player::default();
        p.play_from(&t, 0);
        assert!(about(p.next_frame_due(2.0, 0, &t), MS * 50));
        assert_eq!(p.next_frame_due(0.0, 0, &t), Some(Duration::ZERO));
        assert_eq!(p.tick(Duration::ZERO, 0.0, 0, &t), Some(1));
    }

    #[test]
    fn reaching_the_last_frame_stops_playback() {
        let t = Tenths(3);
        let mut p = Player::default();
        p.play_from(&t, 0);
        assert_eq!(p.tick(MS * 5000, 1.0, 0, &t), Some(2));
        assert!(!p.playing());
        p.play_from(&t, 2);
        assert_eq!(p.tick(MS, 1.0, 2, &t), None);
        assert!(!p.playing(), "playing from the last frame stops at once");
    }
}
