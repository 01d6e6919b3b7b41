//! World models in time: each is paired with the overhead frame nearest in time, within half a
//! frame period, after its robot's clock offset is applied (overhead time = robot time +
//! offset).
//!
//! The offset between a robot's clock and the overhead camera's is estimated from the data
//! itself ([`estimate_offset`]): the search starts at 0 when the robot's times overlap the
//! overhead frames' (one machine, or clocks kept in step by NTP/PTP), else at the offset that
//! lines up the first world model with the first overhead frame. Around that start, offsets in
//! steps of half a frame period up to the given bound are tried; each is scored by the median
//! distance between the robot's own position estimates and the overhead robot wearing its
//! marker in the paired frames, among the offsets that pair at least 80 % as many world models
//! as the best-paired one. The lowest score wins, but among offsets scoring within 2 cm or 10 %
//! of it the one nearest the start is taken: a robot standing still, or one whose own estimate
//! drifts, keeps the start; a moving robot whose clock is off shows a clear dip. The resolution
//! is one frame period: pairing is to whole frames.

use crate::overhead::merge::frame_near;

/// A frame period when the frames do not say (30 fps), nanoseconds.
pub const DEFAULT_PERIOD_NS: u64 = 33_333_333;

/// Most world models one offset is scored on (evenly spread over the robot's messages).
const MAX_SCORED: usize = 400;

/// Most offsets tried on each side of the start.
const MAX_STEPS: i64 = 4000;

/// The frames' period: the median gap between consecutive frame times, nanoseconds.
#[must_use]
pub fn frame_period_ns(times_ns: &[u64]) -> u64 {
    let mut gaps: Vec<u64> = times_ns
        .windows(2)
        .map(|w| w[1].saturating_sub(w[0]))
        .collect();
    gaps.sort_unstable();
    gaps.get(gaps.len() / 2)
        .copied()
        .filter(|&g| g > 0)
        .unwrap_or(DEFAULT_PERIOD_NS)
}

/// Where the search for an offset started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OffsetStart {
    /// The robot's times overlap the overhead frames': the same clock, offset 0.
    SameClock,
    /// They do not: the first world model lined up with the first overhead frame.
    FirstMessages,
    /// A live robot: not searched but measured on arrival ([`arrival_offset`]).
    Arrival,
}

/// A robot's estimated clock offset.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ClockOffset {
    /// Overhead time − robot time, nanoseconds.
    pub offset_ns: i64,
    /// Where the search started.
    pub start: OffsetStart,
    /// World models scored at the chosen offset (paired with a frame reading its marker).
    pub pairs: usize,
    /// Their median position error at the chosen offset, centimetres.
    pub median_error_cm: Option<f64>,
}

/// A live robot's clock offset, measured rather than searched: live world models and overhead
/// frames are both timed by their arrival on this machine and paired by it, so the robot's
/// clock does not move the pairing; what it is is still shown: the median of (arrival − the
/// message's time on the robot's clock) over `arrival_minus_robot_ns`, which is the two clocks'
/// difference plus the network's latency. `pairs` and `median_error_cm` as for a searched offset.
#[must_use]
pub fn arrival_offset(
    arrival_minus_robot_ns: &[i64],
    pairs: usize,
    median_error_cm: Option<f64>,
) -> ClockOffset {
    let mut sorted = arrival_minus_robot_ns.to_vec();
    sorted.sort_unstable();
    ClockOffset {
        offset_ns: sorted.get(sorted.len() / 2).copied().unwrap_or(0),
        start: OffsetStart::Arrival,
        pairs,
        median_error_cm,
    }
}

/// The overhead time a robot time `t_ns` maps to under `offset_ns`, if not before 0.
#[must_use]
pub fn shifted(t_ns: u64, offset_ns: i64) -> Option<u64> {
    u64::try_from(i128::from(t_ns) + i128::from(offset_ns)).ok()
}

/// Estimates one robot's clock offset (see the module documentation).
///
/// `frames_ns`: the overhead frames' times, ascending; `period_ns` their period; `robot_at(i)`:
/// where the overhead camera read this robot's marker in frame `i`; `messages`: the robot's
/// (time on its clock, own position estimate), in time order; `max_offset_ns`: how far from
/// the start to search (0: take the start).
#[must_use]
pub fn estimate_offset(
    frames_ns: &[u64],
    period_ns: u64,
    robot_at: impl Fn(usize) -> Option<[f64; 2]>,
    messages: &[(u64, [f64; 2])],
    max_offset_ns: u64,
) -> ClockOffset {
    let (Some(&f0), Some(&f1)) = (frames_ns.first(), frames_ns.last()) else {
        return unscored(0, OffsetStart::SameClock);
    };
    let (Some(m0), Some(m1)) = (messages.first(), messages.last()) else {
        return unscored(0, OffsetStart::SameClock);
    };
    let (start, how) = if m0.0 <= f1 && m1.0 >= f0 {
        (0, OffsetStart::SameClock)
    } else {
        (
            i64::try_from(i128::from(f0) - i128::from(m0.0)).unwrap_or(0),
            OffsetStart::FirstMessages,
        )
    };
    let every = messages.len().div_ceil(MAX_SCORED).max(1);
    let scored: Vec<(u64, [f64; 2])> = messages.iter().step_by(every).copied().collect();
    let score = |offset: i64| -> (usize, Option<f64>) {
        let errors: Vec<f64> = scored
            .iter()
            .filter_map(|&(t, p)| {
                let i = frame_near(frames_ns, shifted(t, offset)?, period_ns)?;
                robot_at(i).map(|r| (p[0] - r[0]).hypot(p[1] - r[1]))
            })
            .collect();
        (errors.len(), crate::stats::median(&errors))
    };
    let step = i64::try_from((period_ns / 2).max(1_000_000)).unwrap_or(16_666_666);
    let steps = (i64::try_from(max_offset_ns).unwrap_or(i64::MAX) / step).min(MAX_STEPS);
    // Enough pairs to trust a score: a quarter of the scored messages, at least 3.
    let enough = (scored.len() / 4).max(3);
    let mut tried: Vec<(i64, usize, f64)> = (-steps..=steps)
        .filter_map(|k| {
            let offset = start.saturating_add(k.saturating_mul(step));
            let (n, median) = score(offset);
            median.filter(|_| n >= enough).map(|m| (offset, n, m))
        })
        .collect();
    let most = tried.iter().map(|t| t.1).max().unwrap_or(0);
    tried.retain(|t| 5 * t.1 >= 4 * most);
    let Some(best) = tried.iter().map(|t| t.2).min_by(f64::total_cmp) else {
        let (n, median) = score(start);
        return ClockOffset {
            offset_ns: start,
            start: how,
            pairs: n,
            median_error_cm: median,
        };
    };
    let tolerance = (0.1 * best).max(2.0);
    tried.retain(|t| t.2 <= best + tolerance);
    tried.sort_by_key(|t| t.0.abs_diff(start));
    let (offset_ns, pairs, median) = tried[0];
    ClockOffset {
        offset_ns,
        start: how,
        pairs,
        median_error_cm: Some(median),
    }
}

const fn unscored(offset_ns: i64, start: OffsetStart) -> ClockOffset {
    ClockOffset {
        offset_ns,
        start,
        pairs: 0,
        median_error_cm: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A robot walking along x at 100 cm/s, seen every 1/30 s.
    fn walk(frames: usize) -> (Vec<u64>, Vec<[f64; 2]>) {
        let times: Vec<u64> = (0..frames as u64).map(|i| i * DEFAULT_PERIOD_NS).collect();
        let at = times.iter().map(|&t| [t as f64 * 1e-7, 0.0]).collect();
        (times, at)
    }

    #[test]
    fn an_offset_is_found_to_a_frame() {
        let (times, at) = walk(120);
        // The robot's clock runs 0.5 s ahead of the overhead camera's.
        let messages: Vec<(u64, [f64; 2])> = times
            .iter()
            .zip(&at)
            .map(|(&t, &p)| (t + 500_000_000, p))
            .collect();
        let c = estimate_offset(
            &times,
            DEFAULT_PERIOD_NS,
            |i| at.get(i).copied(),
            &messages,
            2_000_000_000,
        );
        assert_eq!(c.start, OffsetStart::SameClock);
        assert!((c.offset_ns + 500_000_000).abs() <= 17_000_000, "{c:?}");
        assert!(c.median_error_cm.unwrap() < 2.0, "{c:?}");
    }

    #[test]
    fn clocks_far_apart_start_from_the_first_messages() {
        let (times, at) = walk(60);
        let messages: Vec<(u64, [f64; 2])> = times
            .iter()
            .zip(&at)
            .map(|(&t, &p)| (t + 1_000_000_000_000, p))
            .collect();
        let c = estimate_offset(
            &times,
            DEFAULT_PERIOD_NS,
            |i| at.get(i).copied(),
            &messages,
            0,
        );
        assert_eq!(c.start, OffsetStart::FirstMessages);
        assert_eq!(c.offset_ns, -1_000_000_000_000);
        assert_eq!(c.pairs, 60);
    }

    #[test]
    fn a_robot_standing_still_keeps_the_start() {
        let (times, _) = walk(60);
        let messages: Vec<(u64, [f64; 2])> = times.iter().map(|&t| (t, [5.0, 5.0])).collect();
        let c = estimate_offset(
            &times,
            DEFAULT_PERIOD_NS,
            |_| Some([0.0, 0.0]),
            &messages,
            1_000_000_000,
        );
        assert_eq!(c.offset_ns, 0);
    }

    #[test]
    fn the_period_is_the_median_gap() {
        assert_eq!(frame_period_ns(&[0, 10, 20, 35, 45]), 10);
        assert_eq!(frame_period_ns(&[7]), DEFAULT_PERIOD_NS);
    }

    #[test]
    fn a_live_offset_is_the_median_of_arrival_minus_robot_time() {
        // A robot 0.4 s ahead with 1-9 ms of latency, and one message held up for 300 ms.
        let mut samples: Vec<i64> = (1..10).map(|ms| ms * 1_000_000 - 400_000_000).collect();
        samples.push(-100_000_000);
        let c = arrival_offset(&samples, 10, Some(3.0));
        assert_eq!(c.start, OffsetStart::Arrival);
        assert_eq!(c.offset_ns, -394_000_000);
        assert_eq!((c.pairs, c.median_error_cm), (10, Some(3.0)));
        assert_eq!(arrival_offset(&[], 0, None).offset_ns, 0);
    }
}
