//! Learning and identification figures of the coloured patterns for several tables.

use eotn::eval::patterns::{
    PatternEvalParams, PatternEvalReport, PatternFrameEval, evaluate_patterns, place_markers,
};
use eotn::lut::LookupTable;
use eotn::model::truth::GroundTruth;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::recognition::patterns::{
    LearnParams, LearnReport, LearnView, PatternMemory, PatternParams,
};
use eotn::sim::scenario::pattern_markers;
use eotn::sim::{Scenario, ScenarioKind, Simulator};

use crate::{learnt_table, table_learnt_from};

const TABLE_SCENARIOS: [ScenarioKind; 7] = [
    ScenarioKind::WalkAndPan,
    ScenarioKind::BallEdge,
    ScenarioKind::Goalkeeper,
    ScenarioKind::FastPans,
    ScenarioKind::OrangeClutter,
    ScenarioKind::BeaconTour,
    ScenarioKind::PatternTour,
];

/// Learns from `frames` frames of the pattern tour with `seed`, the robot's pose from the truth
/// (what its localisation would report), nothing else from the truth.
fn learn(lut: &LookupTable, seed: u64, frames: u64) -> (PatternMemory, LearnReport) {
    let sim = Simulator::new(Scenario::new(ScenarioKind::PatternTour, seed));
    let mut pipeline = Pipeline::new(lut.clone(), PipelineParams::default());
    let mut views = Vec::new();
    for i in 0..frames {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            panic!("a robot view");
        };
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        views.extend(r.recognition.patterns.iter().map(|c| LearnView {
            frame: i as usize,
            robot: truth.robot_pose,
            observation: c.observation,
        }));
    }
    let mut memory = PatternMemory::default();
    let report = memory.learn(&views, &PatternParams::default(), &LearnParams::default());
    (memory, report)
}

/// Identification only, on another seed, scored against the truth.
fn identify(
    lut: &LookupTable,
    memory: &PatternMemory,
    seed: u64,
    frames: u64,
) -> PatternEvalReport {
    let sim = Simulator::new(Scenario::new(ScenarioKind::PatternTour, seed));
    let mut pipeline = Pipeline::new(lut.clone(), PipelineParams::default());
    pipeline.set_pattern_memory(Some(memory.clone()));
    let p = PatternEvalParams::default();
    let mut evals: Vec<PatternFrameEval> = Vec::new();
    let mut places = Vec::new();
    for i in 0..frames {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            panic!("a robot view");
        };
        if places.is_empty() {
            places = place_markers(memory, &truth.markers, &p);
        }
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        evals.push(evaluate_patterns(
            i as usize,
            r.recognition,
            truth,
            &places,
            &p,
        ));
    }
    PatternEvalReport::from_frames(&evals, places)
}

/// Prints learning and identification figures for several tables:
/// `cargo run --example debug_recognition --no-default-features -- patterns`.
pub fn debug_patterns() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let tables = [
        ("robot scenarios", learnt_table()),
        (
            "robot scenarios + pattern tour",
            table_learnt_from(&TABLE_SCENARIOS),
        ),
        (
            "sim.lut",
            LookupTable::load(&root.join("lookup_tables/sim.lut")).unwrap(),
        ),
    ];
    for (name, lut) in &tables {
        let (memory, report) = learn(lut, 1, 480);
        let off: Vec<String> = pattern_markers()
            .iter()
            .map(|m| {
                let d = memory
                    .objects
                    .iter()
                    .map(|o| (o.field_cm[0] - m.x_cm).hypot(o.field_cm[1] - m.y_cm))
                    .fold(f64::INFINITY, f64::min);
                format!("{} {d:.1}", m.name)
            })
            .collect();
        let r = identify(lut, &memory, 2, 300);
        eprintln!(
            "{name}: {} places, {} patterns, {} dropped groups; off {off:?}; relation {:?}\n  \
             identified {}/{} wrong {} missed {} false {} distance median {:.1}% p90 {:.1}%",
            memory.objects.len(),
            memory
                .objects
                .iter()
                .map(|o| o.patterns.len())
                .sum::<usize>(),
            report.groups_dropped.len(),
            memory.relation,
            r.correct,
            r.eligible,
            r.wrong,
            r.missed,
            r.false_identifications,
            100.0 * r.distance_error.map_or(f64::NAN, |p| p.p50),
            100.0 * r.distance_error.map_or(f64::NAN, |p| p.p90)
        );
    }
}
