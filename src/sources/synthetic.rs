//! The synthetic renderer as a live source: a scenario of [`crate::sim`] played at its frame
//! rate, frame after frame, with its sensor readings, ground truth and world models, as a camera
//! would deliver them. Frame `k` is always the same picture, so a recording of it is repeatable.

use super::{
    CameraKind, FrameSource, SourceError, SourceFrame, SourceInfo, SourceKind, SourceSettings,
};
use crate::sim::{FRAME_INTERVAL_S, Scenario, ScenarioKind, Simulator, View};
use crate::streams::GROUND_TRUTH_TOPIC;

/// A scenario rendered on demand.
#[derive(Debug)]
pub struct SyntheticSource {
    sim: Simulator,
    connected: bool,
    /// The next frame's index.
    next: u64,
}

impl SyntheticSource {
    /// Scenario `kind` with `seed`, from its first frame.
    #[must_use]
    pub fn new(kind: ScenarioKind, seed: u64) -> Self {
        Self {
            sim: Simulator::new(Scenario::new(kind, seed)),
            connected: false,
            next: 0,
        }
    }

    /// The scenario with this command-line name (`walk-and-pan`, …).
    ///
    /// # Errors
    /// An unknown name, listing the known ones.
    pub fn named(name: &str, seed: u64) -> Result<Self, SourceError> {
        let kind = ScenarioKind::from_name(name).ok_or_else(|| {
            let known: Vec<&str> = ScenarioKind::ALL.iter().map(|k| k.name()).collect();
            SourceError::Unsupported {
                label: "synthetic".to_owned(),
                detail: format!("unknown scenario {name:?}; known: {}", known.join(", ")),
            }
        })?;
        Ok(Self::new(kind, seed))
    }

    fn label(&self) -> String {
        format!("synthetic {}", self.sim.scenario().kind.name())
    }
}

impl FrameSource for SyntheticSource {
    fn info(&self) -> SourceInfo {
        // As `eotn sim` records it; the overhead scenario's name says "overhead".
        let stream_source = format!("sim:{}", self.sim.scenario().kind.name());
        SourceInfo {
            kind: SourceKind::Synthetic,
            label: self.label(),
            camera: CameraKind::of_stream_source(&stream_source),
            paths: Vec::new(),
            stream_source,
        }
    }

    fn connect(&mut self) -> Result<(), SourceError> {
        self.connected = true;
        Ok(())
    }

    fn disconnect(&mut self) {
        self.connected = false;
    }

    fn is_connected(&self) -> bool {
        self.connected
    }

    fn settings(&self) -> SourceSettings {
        let (width, height) = match self.sim.scenario().view() {
            View::Overhead => (640, 480),
            View::Robot { .. } => (208, 160),
        };
        SourceSettings {
            resolution: Some(super::Resolution { width, height }),
            frame_rate: Some(1.0 / FRAME_INTERVAL_S),
            ..SourceSettings::default()
        }
    }

    fn grab(&mut self) -> Result<SourceFrame, SourceError> {
        if !self.connected {
            return Err(SourceError::NotConnected(self.label()));
        }
        let index = self.next;
        self.next += 1;
        let f = self.sim.frame(index).map_err(|e| SourceError::Device {
            label: self.label(),
            detail: e.to_string(),
        })?;
        let mut out = SourceFrame::new(f.time_ns, f.frame);
        out.sensors = f.sensors;
        match serde_json::to_value(&f.ground_truth) {
            Ok(truth) => out.extra.push((GROUND_TRUTH_TOPIC.to_owned(), truth)),
            Err(e) => out.warnings.push(format!("ground truth not kept: {e}")),
        }
        out.extra.extend(f.extra);
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scenario_plays_its_frames_in_order_at_thirty_a_second() {
        let mut s = SyntheticSource::new(ScenarioKind::BallEdge, 3);
        assert!(matches!(s.grab(), Err(SourceError::NotConnected(_))));
        s.connect().unwrap();
        let a = s.grab().unwrap();
        let b = s.grab().unwrap();
        assert_eq!(a.time_ns, 0);
        assert_eq!(b.time_ns, 33_333_333);
        let size = s.settings().resolution.unwrap();
        assert_eq!(
            (b.frame.width(), b.frame.height()),
            (size.width as usize, size.height as usize)
        );
        assert!(b.sensors.is_some() && b.channel(GROUND_TRUTH_TOPIC).is_some());
        let again = Simulator::new(Scenario::new(ScenarioKind::BallEdge, 3))
            .frame(1)
            .unwrap();
        assert_eq!(*b.frame, again.frame, "frame k is always the same picture");
    }

    #[test]
    fn the_overhead_scenario_is_an_overhead_camera_and_others_robots() {
        let overhead = SyntheticSource::new(ScenarioKind::OverheadGame, 1).info();
        assert_eq!(overhead.camera, CameraKind::Overhead);
        assert_eq!(overhead.stream_source, "sim:overhead-game");
        let robot = SyntheticSource::named("walk-and-pan", 1).unwrap().info();
        assert_eq!(robot.camera, CameraKind::Robot);
        for k in ScenarioKind::ALL {
            let overhead = Scenario::new(k, 1).view() == View::Overhead;
            let camera = SyntheticSource::new(k, 1).info().camera;
            assert_eq!(camera == CameraKind::Overhead, overhead, "{}", k.name());
        }
        let e = SyntheticSource::named("nope", 1).unwrap_err().to_string();
        assert!(e.contains("walk-and-pan"), "{e}");
    }
}
