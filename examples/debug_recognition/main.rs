//! Debugging and measuring aids for recognition on rendered scenarios (they print, they check
//! nothing; the tests in `tests/it/` check). One command per aid:
//!
//! ```sh
//! cargo run --example debug_recognition --no-default-features -- scenario   # per-frame ball and goal detail
//! cargo run --example debug_recognition --no-default-features -- bias       # BIAS, CSV lines: distance error's sign
//! cargo run --example debug_recognition --no-default-features -- rim        # which ball pixels classification loses
//! cargo run --example debug_recognition --no-default-features -- posts      # each post against the renderer's corners
//! cargo run --example debug_recognition --no-default-features -- post-profiles
//! cargo run --example debug_recognition --no-default-features -- patterns   # places learnt and identified per table
//! cargo run --example debug_recognition --no-default-features -- beacons    # true beacons and candidates per frame
//! ```
//!
//! `EOTN_DEBUG_SCENARIO`, `EOTN_DEBUG_LUT`, `EOTN_DEBUG_SEED`, `EOTN_DEBUG_NFRAMES` and
//! `EOTN_DEBUG_FRAMES` pick the scenario, table, seed, frame count and frames shown in full;
//! `EOTN_BIAS_FRAMES` and `EOTN_BIAS_SEEDS` the bias table's; `EOTN_DEBUG_LEARN_STEP` learns the
//! table from every Nth frame (10).

#![allow(
    clippy::unwrap_used,
    reason = "a debugging aid: a panic on a missing file names it"
)]

mod beacons;
mod patterns;
mod posts;
mod scenario;

use eotn::lut::LookupTable;
use eotn::lut::learn::{LearnParams, TableBuilder};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

const ROBOT_SCENARIOS: [ScenarioKind; 6] = [
    ScenarioKind::WalkAndPan,
    ScenarioKind::BallEdge,
    ScenarioKind::Goalkeeper,
    ScenarioKind::FastPans,
    ScenarioKind::OrangeClutter,
    ScenarioKind::BeaconTour,
];

/// A table learnt from every 10th frame of each robot scenario with seed 100.
fn learnt_table() -> LookupTable {
    table_learnt_from(&ROBOT_SCENARIOS)
}

/// A table learnt from every 10th frame of `kinds` with seed 100 (test frames use seed 7).
fn table_learnt_from(kinds: &[ScenarioKind]) -> LookupTable {
    let mut builder = TableBuilder::new(7).expect("7 bits");
    for &kind in kinds {
        let sim = Simulator::new(Scenario::new(kind, 100));
        let step = std::env::var("EOTN_DEBUG_LEARN_STEP")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(10);
        for i in (0..90).step_by(step) {
            let f = sim.frame(i).expect("frame");
            builder.add_frame(&f.frame, &f.labels).expect("labels fit");
        }
    }
    builder.build(&LearnParams::default())
}

/// The debugging aids' table, seed and frame count: the learnt table, seed 7 and 90 frames
/// unless `EOTN_DEBUG_LUT` (a table file), `EOTN_DEBUG_SEED` or `EOTN_DEBUG_NFRAMES` say
/// otherwise.
fn debug_setup() -> (eotn::lut::LookupTable, u64, u64) {
    let lut = std::env::var("EOTN_DEBUG_LUT")
        .ok()
        .filter(|p| !p.is_empty())
        .map_or_else(learnt_table, |path| {
            eotn::lut::LookupTable::load(std::path::Path::new(&path)).expect("table")
        });
    let number = |name: &str, default: u64| {
        std::env::var(name)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    (
        lut,
        number("EOTN_DEBUG_SEED", 7),
        number("EOTN_DEBUG_NFRAMES", 90),
    )
}

fn main() {
    let command = std::env::args().nth(1).unwrap_or_default();
    match command.as_str() {
        "scenario" => scenario::debug_scenario(),
        "bias" => scenario::ball_distance_bias(),
        "rim" => scenario::ball_rim_study(),
        "posts" => posts::debug_posts(),
        "post-profiles" => posts::debug_post_profiles(),
        "patterns" => patterns::debug_patterns(),
        "beacons" => beacons::debug_beacons(),
        _ => {
            eprintln!(
                "usage: debug_recognition scenario|bias|rim|posts|post-profiles|patterns|beacons \
                 (see the file's documentation)"
            );
            std::process::exit(2);
        }
    }
}
