//! Beacons against the truth: each beacon whose two bands the frame shows whole must be found
//! where it is, with its colours in the right order and its distance; an accepted beacon over no
//! beacon is false.

use serde::{Deserialize, Serialize};

use super::{EvalParams, FrameEval};
use crate::frame::PixelBox;
use crate::model::truth::{BeaconTruth, RobotViewTruth};
use crate::recognition::{Beacon, Recognition};

/// A found beacon's distance against the truth (the data of the distance figures).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct BeaconDistance {
    /// True camera distance of the boundary between the bands on the beacon's axis, cm.
    pub true_cm: f64,
    /// Reported camera distance, centimetres.
    pub measured_cm: f64,
}

/// Whether a beacon had to be found: both bands inside the image (none of their projection
/// cut by a border), at least `beacon_min_visible_fraction` of them in view and at least
/// `beacon_min_band_pixels` pixels of them.
#[must_use]
pub fn beacon_is_whole(t: &BeaconTruth, p: &EvalParams) -> bool {
    !t.bands_cut_off.any()
        && t.bands_visible_fraction >= p.beacon_min_visible_fraction
        && t.band_pixels >= p.beacon_min_band_pixels
}

/// The accepted beacon over a true one's bands: the one whose box it covers most, when that is
/// at least half of the reported box.
fn reported_over<'a>(t: &BeaconTruth, accepted: &[&'a Beacon]) -> Option<&'a Beacon> {
    let truth_box = t.bands_box.or(t.image_box)?;
    accepted
        .iter()
        .map(|b| (b, b.bounds.overlap_fraction(&truth_box)))
        .filter(|(_, f)| *f >= 0.5)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(b, _)| *b)
}

/// Scores the frame's beacons into `e`.
pub(super) fn score_beacons(
    e: &mut FrameEval,
    r: &Recognition,
    t: &RobotViewTruth,
    p: &EvalParams,
) {
    let accepted: Vec<&Beacon> = r.beacons.iter().filter(|b| b.accepted).collect();
    for tb in &t.beacons {
        if !beacon_is_whole(tb, p) {
            continue;
        }
        e.beacons_eligible += 1;
        let Some(b) = reported_over(tb, &accepted) else {
            continue;
        };
        e.beacons_found += 1;
        if tb.colours == Some([b.kind.top, b.kind.bottom]) {
            e.beacons_colours_right += 1;
        }
        e.beacon_distances_cm.push(BeaconDistance {
            true_cm: tb.relative.camera_distance_cm,
            measured_cm: b.camera.distance_cm,
        });
    }
    // False: an accepted beacon that covers no beacon's pixels (any beacon, whole or not).
    let shown: Vec<PixelBox> = t
        .beacons
        .iter()
        .filter(|tb| tb.visible_pixels > 0)
        .filter_map(|tb| tb.image_box)
        .collect();
    e.beacons_false = accepted
        .iter()
        .filter(|b| shown.iter().all(|s| b.bounds.overlap_fraction(s) < 0.5))
        .count();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::CutOff;
    use crate::lut::ColourClass;
    use crate::model::truth::GroundTruth;
    use crate::recognition::beacons::BeaconKind;
    use crate::recognition::confidence::Confidence;
    use crate::recognition::context::Relative as Seen;

    fn truth(bands: PixelBox, distance_cm: f64) -> BeaconTruth {
        serde_json::from_value(serde_json::json!({
            "name": "pink_yellow",
            "relative": {
                "field_cm": [135.0, 215.0], "camera_distance_cm": distance_cm,
                "body_distance_cm": distance_cm, "body_bearing_rad": 0.0,
                "camera_bearing_rad": 0.0, "camera_elevation_rad": 0.0, "image": null
            },
            "visible_pixels": 400,
            "image_box": {"min_x": bands.min_x, "min_y": bands.min_y,
                          "max_x": bands.max_x, "max_y": bands.max_y + 20},
            "colours": ["Pink", "Yellow"],
            "band_pixels": 300,
            "bands_visible_fraction": 0.97,
            "bands_cut_off": CutOff::default(),
            "bands_box": {"min_x": bands.min_x, "min_y": bands.min_y,
                          "max_x": bands.max_x, "max_y": bands.max_y},
        }))
        .expect("truth JSON")
    }

    fn reported(bounds: PixelBox, top: ColourClass, distance_cm: f64) -> Beacon {
        Beacon {
            kind: BeaconKind {
                top,
                bottom: if top == ColourClass::Pink {
                    ColourClass::Yellow
                } else {
                    ColourClass::Pink
                },
            },
            bounds,
            cut_off: false,
            camera: Seen {
                distance_cm,
                bearing_rad: 0.0,
                elevation_rad: 0.0,
            },
            body: None,
            distance_from: crate::recognition::beacons::DistanceSource::BandEdges,
            edges: Vec::new(),
            confidence: Confidence::default(),
            accepted: true,
        }
    }

    fn frame(truths: Vec<BeaconTruth>, found: Vec<Beacon>) -> FrameEval {
        let sim = crate::sim::Simulator::new(crate::sim::Scenario::new(
            crate::sim::ScenarioKind::BeaconTour,
            1,
        ));
        let GroundTruth::Robot(mut t) = sim.frame(0).expect("frame").ground_truth else {
            panic!("a robot's view");
        };
        t.beacons = truths;
        let r = Recognition {
            beacons: found,
            ..Recognition::default()
        };
        let mut e = FrameEval::default();
        score_beacons(&mut e, &r, &t, &EvalParams::default());
        e
    }

    #[test]
    fn a_beacon_found_in_place_scores_its_colours_and_distance() {
        let bands = PixelBox::new(100, 40, 110, 60);
        let e = frame(
            vec![truth(bands, 200.0)],
            vec![reported(bands, ColourClass::Pink, 190.0)],
        );
        assert_eq!((e.beacons_eligible, e.beacons_found), (1, 1));
        assert_eq!((e.beacons_colours_right, e.beacons_false), (1, 0));
        assert_eq!(
            e.beacon_distances_cm,
            vec![BeaconDistance {
                true_cm: 200.0,
                measured_cm: 190.0
            }]
        );
        // The colours swapped: found, but not right.
        let e = frame(
            vec![truth(bands, 200.0)],
            vec![reported(bands, ColourClass::Yellow, 190.0)],
        );
        assert_eq!((e.beacons_found, e.beacons_colours_right), (1, 0));
    }

    #[test]
    fn a_beacon_elsewhere_is_false_and_the_true_one_missed() {
        let e = frame(
            vec![truth(PixelBox::new(100, 40, 110, 60), 200.0)],
            vec![reported(
                PixelBox::new(10, 40, 20, 60),
                ColourClass::Pink,
                190.0,
            )],
        );
        assert_eq!(
            (e.beacons_eligible, e.beacons_found, e.beacons_false),
            (1, 0, 1)
        );
        // A beacon cut by the image border need not be found.
        let mut cut = truth(PixelBox::new(0, 40, 8, 60), 200.0);
        cut.bands_cut_off.left = true;
        let e = frame(vec![cut], vec![]);
        assert_eq!(e.beacons_eligible, 0);
    }
}
