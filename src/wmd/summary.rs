//! Each robot's world-model errors over a session: medians and 95th percentiles (nearest rank)
//! of the position, heading, ball and tape-measure errors, how it was matched, and the frames
//! where its error jumped (a sudden mislocalisation, a kidnap, a wrong match).

use std::collections::{BTreeMap, VecDeque};

use serde::Serialize;

use super::{Comparison, Matched, RobotKey};
use crate::stats::median;

/// A position error this far above the robot's recent median is a jump, centimetres.
pub const JUMP_CM: f64 = 50.0;
/// A heading error this far above the robot's recent median is a jump, degrees.
pub const JUMP_DEG: f64 = 45.0;
/// How many recent frames the median of a jump is taken over.
const RECENT: usize = 15;
/// Frames needed before a jump can be called.
const RECENT_MIN: usize = 5;

/// The median and 95th percentile of a set of (absolute) errors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    /// Number of values.
    pub n: usize,
    /// Median.
    pub median: f64,
    /// 95th percentile, nearest rank.
    pub p95: f64,
}

impl Spread {
    /// The spread of `values`; `None` without values.
    #[must_use]
    pub fn of(values: &[f64]) -> Option<Self> {
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let rank = (0.95 * n as f64).ceil();
        #[expect(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            reason = "1 ≤ rank ≤ n"
        )]
        let p95 = *sorted.get((rank as usize).max(1) - 1)?;
        Some(Self {
            n,
            median: median(&sorted)?,
            p95,
        })
    }
}

/// One robot's errors over the session.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotSummary {
    /// The robot.
    pub robot: RobotKey,
    /// World models compared (paired with an overhead frame).
    pub world_models: usize,
    /// Of those, matched by marker.
    pub by_marker: usize,
    /// Of those, matched by position.
    pub by_position: usize,
    /// Of those, unmatched.
    pub unmatched: usize,
    /// Position error, centimetres.
    pub position_cm: Option<Spread>,
    /// Heading error (absolute), degrees.
    pub heading_deg: Option<Spread>,
    /// Ball error, centimetres.
    pub ball_cm: Option<Spread>,
    /// Tape measure: distance error (absolute) of its `seen` measurements, centimetres.
    pub distance_cm: Option<Spread>,
    /// Tape measure: bearing error (absolute), degrees.
    pub bearing_deg: Option<Spread>,
    /// Overhead frame times where its error jumped, nanoseconds.
    pub jumps_ns: Vec<u64>,
    /// Its first and last paired world model, overhead time, nanoseconds.
    pub first_ns: u64,
    /// See `first_ns`.
    pub last_ns: u64,
}

#[derive(Debug, Default, Clone)]
struct Gathered {
    counts: [usize; 3],
    position: Vec<f64>,
    heading: Vec<f64>,
    ball: Vec<f64>,
    distance: Vec<f64>,
    bearing: Vec<f64>,
    recent: VecDeque<(f64, f64)>,
    jumps: Vec<u64>,
    first_ns: Option<u64>,
    last_ns: u64,
}

/// The summaries being gathered, frame by frame in time order.
#[derive(Debug, Default, Clone)]
pub struct Summaries {
    robots: BTreeMap<RobotKey, Gathered>,
}

impl Summaries {
    /// Adds one comparison made at overhead time `time_ns`; `true` when its error jumped.
    pub fn add(&mut self, time_ns: u64, c: &Comparison) -> bool {
        let g = self.robots.entry(c.robot).or_default();
        g.counts[match c.matched {
            Matched::Marker => 0,
            Matched::Position => 1,
            Matched::Unmatched => 2,
        }] += 1;
        g.first_ns.get_or_insert(time_ns);
        g.last_ns = time_ns;
        g.ball.extend(c.ball_error_cm);
        for m in &c.measurements {
            g.distance.extend(m.error_cm.map(f64::abs));
            g.bearing.extend(m.bearing_error_deg.map(f64::abs));
        }
        let (Some(p), Some(h)) = (c.position_error_cm, c.heading_error_deg.map(f64::abs)) else {
            return false;
        };
        g.position.push(p);
        g.heading.push(h);
        let jump = g.recent.len() >= RECENT_MIN && {
            let ps: Vec<f64> = g.recent.iter().map(|r| r.0).collect();
            let hs: Vec<f64> = g.recent.iter().map(|r| r.1).collect();
            median(&ps).is_some_and(|m| p > m + JUMP_CM)
                || median(&hs).is_some_and(|m| h > m + JUMP_DEG)
        };
        if jump {
            g.jumps.push(time_ns);
        }
        g.recent.push_back((p, h));
        if g.recent.len() > RECENT {
            g.recent.pop_front();
        }
        jump
    }

    /// Each robot's summary, blue team first, then by identity.
    #[must_use]
    pub fn finish(self) -> Vec<RobotSummary> {
        self.robots
            .into_iter()
            .map(|(robot, g)| RobotSummary {
                robot,
                world_models: g.counts.iter().sum(),
                by_marker: g.counts[0],
                by_position: g.counts[1],
                unmatched: g.counts[2],
                position_cm: Spread::of(&g.position),
                heading_deg: Spread::of(&g.heading),
                ball_cm: Spread::of(&g.ball),
                distance_cm: Spread::of(&g.distance),
                bearing_deg: Spread::of(&g.bearing),
                jumps_ns: g.jumps,
                first_ns: g.first_ns.unwrap_or(0),
                last_ns: g.last_ns,
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{MarkerIdentity, MarkerTeam};

    fn comparison(p: f64) -> Comparison {
        Comparison {
            robot: RobotKey {
                team: MarkerTeam::Blue,
                identity: MarkerIdentity::MIN,
            },
            matched: Matched::Marker,
            overhead_robot: None,
            position_error_cm: Some(p),
            heading_error_deg: Some(-2.0),
            ball_error_cm: None,
            measurements: Vec::new(),
        }
    }

    #[test]
    fn a_jump_is_marked_once_and_spreads_are_nearest_rank() {
        let mut s = Summaries::default();
        let jumps: Vec<bool> = [10.0, 11.0, 9.0, 10.0, 12.0, 10.0, 90.0, 11.0]
            .iter()
            .enumerate()
            .map(|(i, &p)| s.add(i as u64, &comparison(p)))
            .collect();
        assert_eq!(jumps.iter().filter(|&&j| j).count(), 1);
        assert!(jumps[6]);
        let r = &s.finish()[0];
        assert_eq!(r.jumps_ns, [6]);
        assert_eq!(r.by_marker, 8);
        let p = r.position_cm.unwrap();
        // The median is the upper middle value of an even count (`stats::median`).
        assert_eq!((p.n, p.median, p.p95), (8, 11.0, 90.0));
        assert_eq!(r.heading_deg.unwrap().median, 2.0);
        assert_eq!(Spread::of(&[]), None);
    }
}
