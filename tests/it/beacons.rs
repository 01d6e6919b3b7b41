//! Beacons against the renderer's truth on held-out seeds, and beacons cut by the image border
//! that must not be taken for goals.
//!
//! Seeds 41 and 53 were chosen before any beacon figure was measured on them, and no change to
//! beacon or goal recognition was tried on them (that work looked at seeds 1, 7, 11 and 23):
//! they are the independent frames the figures in `docs/recognition.md` ("Beacons") come from.
//! The table is learnt from seed 100 as in `recognition.rs`, but from every third frame rather
//! than every tenth: with 54 frames a far beacon's colours in the image's shaded corners go
//! unclassified (seed 7's orange-clutter, frames 28–35), which is the table's limit, not the
//! recogniser's.

use eotn::eval::{EvalParams, EvalReport, FrameEval, evaluate_frame};
use eotn::lut::LookupTable;
use eotn::model::truth::GroundTruth;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

use crate::common::sampled;

/// Seeds no beacon or goal tuning looked at.
const HELD_OUT: [u64; 2] = [41, 53];

/// The robot scenarios that show beacons whole (ball-edge and goalkeeper never do).
const WITH_BEACONS: [ScenarioKind; 4] = [
    ScenarioKind::WalkAndPan,
    ScenarioKind::FastPans,
    ScenarioKind::OrangeClutter,
    ScenarioKind::BeaconTour,
];

/// The table of these tests: every third of the first 90 frames of the six robot scenarios,
/// seed 100.
fn beacon_table() -> LookupTable {
    crate::recognition::table_learnt_every(&crate::recognition::ROBOT_SCENARIOS, 3)
}

/// What one scenario run gave: its frames' evaluations, the frames where any goal was accepted,
/// and the frames where a beacon's bands were cut at each side (left, right, top, bottom).
struct Run {
    frames: Vec<FrameEval>,
    goal_frames: usize,
    cuts: [usize; 4],
}

/// Every `step`-th of the first `frames` frames of `kind` with `seed`, evaluated.
fn evaluate(kind: ScenarioKind, seed: u64, frames: u64, step: usize, lut: &LookupTable) -> Run {
    let sim = Simulator::new(Scenario::new(kind, seed));
    let mut pipeline = Pipeline::new(lut.clone(), PipelineParams::default());
    let mut run = Run {
        frames: Vec::new(),
        goal_frames: 0,
        cuts: [0; 4],
    };
    for i in (0..frames).step_by(step) {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            panic!("robot scenario gave an overhead frame");
        };
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        run.goal_frames += usize::from(r.recognition.goals.goals().next().is_some());
        for b in truth.beacons.iter().filter(|b| b.band_pixels > 0) {
            let c = b.bands_cut_off;
            for (n, cut) in run.cuts.iter_mut().zip([c.left, c.right, c.top, c.bottom]) {
                *n += usize::from(cut);
            }
        }
        let (w, h) = (f.frame.width() as f64, f.frame.height() as f64);
        run.frames.push(evaluate_frame(
            i as usize,
            r.recognition,
            truth,
            w,
            h,
            &EvalParams::default(),
        ));
    }
    run
}

/// One line of beacon figures.
fn line(name: &str, r: &EvalReport) -> String {
    let d = r.beacon_distance_error;
    format!(
        "{name}: beacons found {}/{} (colours right {}), false {}; distance error median {:.1}% \
         p90 {:.1}% (n = {}), signed median {:+.1}%; missed in frames {:?}",
        r.beacons_found,
        r.beacons_eligible,
        r.beacons_colours_right,
        r.beacons_false,
        100.0 * d.map_or(f64::NAN, |p| p.p50),
        100.0 * d.map_or(f64::NAN, |p| p.p90),
        d.map_or(0, |p| p.n),
        100.0 * r.beacon_distance_bias.unwrap_or(f64::NAN),
        r.beacon_misses
    )
}

/// On frames no tuning saw: every whole beacon found with its colours, none false, and the
/// distance error well inside the targets (median ≤ 3%, p90 ≤ 8%).
#[test]
fn held_out_beacons_are_found_with_their_distance() {
    let lut = beacon_table();
    let mut pooled: Vec<FrameEval> = Vec::new();
    for seed in HELD_OUT {
        for (kind, frames, step) in WITH_BEACONS.map(|k| (k, 90, 1)).into_iter().chain([(
            ScenarioKind::BeaconEdges,
            720,
            2,
        )]) {
            let run = evaluate(kind, seed, frames, step, &lut);
            let r = EvalReport::from_frames(&run.frames);
            eprintln!("{}", line(&format!("{} seed {seed}", kind.name()), &r));
            pooled.extend(run.frames);
        }
    }
    let all = EvalReport::from_frames(&pooled);
    eprintln!(
        "{}",
        line(&format!("held-out seeds {HELD_OUT:?}, all"), &all)
    );
    // The frames numbered …7, …8, …9 of those seeds on their own (the held-out part named in
    // docs/recognition.md for every set).
    let tail: Vec<FrameEval> = pooled
        .iter()
        .filter(|f| f.frame % 10 >= 7)
        .cloned()
        .collect();
    let kept = EvalReport::from_frames(&tail);
    eprintln!(
        "{}",
        line(
            &format!("held-out seeds {HELD_OUT:?}, frames ending 7-9"),
            &kept
        )
    );
    assert_eq!(
        kept.beacons_found, kept.beacons_eligible,
        "every whole beacon found"
    );
    assert_eq!(kept.beacons_false, 0, "no false beacon");
    let k = sampled(
        kept.beacon_distance_error,
        100,
        "held-out frames ending 7-9",
    );
    assert!(k.p50 <= 0.025 && k.p90 <= 0.075, "{k:?}");
    assert!(
        all.beacons_eligible >= 300,
        "{} whole beacons",
        all.beacons_eligible
    );
    assert_eq!(
        all.beacons_found, all.beacons_eligible,
        "every whole beacon found"
    );
    assert_eq!(
        all.beacons_colours_right, all.beacons_found,
        "colours right"
    );
    assert_eq!(all.beacons_false, 0, "no false beacon");
    // Achieved: median 0.9%, p90 2.9%, bias +0.6% (n = 491); the limits are about 2.5× that,
    // inside the targets (≤ 3%, ≤ 8%).
    let d = sampled(all.beacon_distance_error, 300, "held-out beacon distances");
    assert!(d.p50 <= 0.025 && d.p90 <= 0.075, "{d:?}");
    assert!(
        all.beacon_distance_bias.is_some_and(|b| b.abs() <= 0.015),
        "bias {:?}",
        all.beacon_distance_bias
    );
}

/// Beacons cut at every image edge — a yellow or sky-blue band on its white base with the pink
/// band above the image, an upper band with the lower one below it, either side sliced off —
/// are never a goal (no goal is in view in this scenario).
#[test]
fn beacons_cut_at_each_image_edge_are_no_goal() {
    let lut = beacon_table();
    for seed in HELD_OUT {
        let run = evaluate(ScenarioKind::BeaconEdges, seed, 720, 2, &lut);
        let r = EvalReport::from_frames(&run.frames);
        eprintln!(
            "beacon-edges seed {seed}: {} frames, beacons cut left/right/top/bottom in {:?} \
             frames; goals reported in {} frames, false goals {} (frames {:?})",
            r.frames, run.cuts, run.goal_frames, r.goals_false, r.goal_false_frames
        );
        assert!(
            run.cuts.iter().all(|n| *n >= 10),
            "the scenario cuts beacons at every edge: {:?}",
            run.cuts
        );
        assert_eq!(r.goals_eligible, 0, "no goal in view");
        assert_eq!(run.goal_frames, 0, "no goal reported");
        assert_eq!(r.goals_false, 0, "frames {:?}", r.goal_false_frames);
    }
}
