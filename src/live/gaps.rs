//! Lost frames counted from the gaps between a robot's capture times (the frame period learnt
//! as frames come; a clock that jumps is not counted as losses).

/// A jump in frame times this large (forward) is a clock change, not a network outage.
const CLOCK_JUMP_NS: u64 = 60_000_000_000;

/// What one frame's capture time says about the frames before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Gap {
    /// The next frame, or the first one.
    Regular,
    /// This many frames were lost: the gap held them (more than 1.5 frame periods).
    Missed(usize),
    /// The times went backwards or leapt ahead by more than [`CLOCK_JUMP_NS`]: a looping or
    /// restarted sender, or one that switched clocks. Nothing can be said about losses.
    ClockJump {
        /// From the previous frame's time to this one's, nanoseconds.
        by_ns: i128,
    },
}

/// Counts lost frames from the gaps between capture times, learning the frame period as it goes.
#[derive(Debug, Default, Clone)]
pub(super) struct FrameGaps {
    /// The shortest recent gap, slowly averaged: the camera's frame period, nanoseconds.
    period_ns: Option<f64>,
    /// The previous frame's capture time, nanoseconds.
    last_ns: Option<u64>,
}

impl FrameGaps {
    /// After a reconnection the next frame starts afresh (its gap says nothing).
    pub(super) fn forget_last(&mut self) {
        self.last_ns = None;
    }

    pub(super) fn observe(&mut self, capture_ns: u64) -> Gap {
        let Some(last) = self.last_ns.replace(capture_ns) else {
            return Gap::Regular;
        };
        if capture_ns < last || capture_ns - last > CLOCK_JUMP_NS {
            return Gap::ClockJump {
                by_ns: i128::from(capture_ns) - i128::from(last),
            };
        }
        let gap = (capture_ns - last) as f64;
        if gap == 0.0 {
            return Gap::Regular;
        }
        let verdict = match self.period_ns {
            Some(period) if gap > 1.5 * period => {
                Gap::Missed(((gap / period).round() as usize).saturating_sub(1))
            }
            _ => Gap::Regular,
        };
        // Slow average so one gap does not make the next frames look late.
        self.period_ns = Some(self.period_ns.map_or(gap, |p| p.min(0.9 * p + 0.1 * gap)));
        verdict
    }
}

#[cfg(test)]
mod tests {
    use super::{CLOCK_JUMP_NS, FrameGaps, Gap};

    const PERIOD: u64 = 33_333_333;

    fn observe_all(gaps: &mut FrameGaps, times: impl IntoIterator<Item = u64>) -> Vec<Gap> {
        times.into_iter().map(|t| gaps.observe(t)).collect()
    }

    #[test]
    fn regular_frames_lose_nothing_and_a_gap_counts_the_frames_it_held() {
        let mut gaps = FrameGaps::default();
        let verdicts = observe_all(&mut gaps, (0..10).map(|i| 1_000 + i * PERIOD));
        assert!(verdicts.iter().all(|v| *v == Gap::Regular), "{verdicts:?}");
        // Frames 10, 11 and 12 never came.
        assert_eq!(gaps.observe(1_000 + 13 * PERIOD), Gap::Missed(3));
        assert_eq!(gaps.observe(1_000 + 14 * PERIOD), Gap::Regular);
    }

    #[test]
    fn a_looping_sender_starting_over_is_a_clock_jump_not_a_loss() {
        let mut gaps = FrameGaps::default();
        let times = (0..30)
            .map(|i| i * PERIOD)
            .chain((0..30).map(|i| i * PERIOD));
        let verdicts = observe_all(&mut gaps, times);
        let jumps = verdicts
            .iter()
            .filter(|v| matches!(v, Gap::ClockJump { by_ns } if *by_ns < 0))
            .count();
        assert_eq!(jumps, 1, "{verdicts:?}");
        assert!(!verdicts.iter().any(|v| matches!(v, Gap::Missed(_))));
    }

    #[test]
    fn a_switch_from_stream_time_to_wall_clock_time_is_not_billions_of_drops() {
        // A sender whose first image has no timestamp (its log time, the Unix clock, stands in),
        // then stream times from 0, then the Unix clock again when it loops.
        let unix = 1_796_000_000_000_000_000;
        let mut gaps = FrameGaps::default();
        let times = [unix]
            .into_iter()
            .chain((1..30).map(|i| i * PERIOD))
            .chain([unix + 2_000_000_000]);
        let verdicts = observe_all(&mut gaps, times);
        assert!(
            !verdicts.iter().any(|v| matches!(v, Gap::Missed(_))),
            "{verdicts:?}"
        );
        assert!(
            matches!(verdicts.last(), Some(Gap::ClockJump { by_ns }) if *by_ns > CLOCK_JUMP_NS.into())
        );
    }

    #[test]
    fn after_a_reconnection_the_first_gap_is_not_judged() {
        let mut gaps = FrameGaps::default();
        observe_all(&mut gaps, (0..10).map(|i| i * PERIOD));
        gaps.forget_last();
        // Twenty seconds later: the outage is the disconnection's, already reported.
        assert_eq!(gaps.observe(20_000_000_000), Gap::Regular);
        assert_eq!(gaps.observe(20_000_000_000 + PERIOD), Gap::Regular);
    }
}
