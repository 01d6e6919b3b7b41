//! The shipped `lookup_tables/sim.lut` classifies freshly rendered frames of every scenario
//! (a seed it was not built from) well.

use eotn::lut::learn::Accuracy;
use eotn::lut::{ColourClass, LookupTable};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

#[test]
fn shipped_sim_table_classifies_unseen_frames() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let table = LookupTable::load(&root.join("lookup_tables/sim.lut")).unwrap();
    let mut accuracy = Accuracy::default();
    for kind in ScenarioKind::ALL {
        let sim = Simulator::new(Scenario::new(kind, 4242));
        for index in [3, 40] {
            let f = sim.frame(index).unwrap();
            accuracy.add_frame(&f.frame, &f.labels, &table).unwrap();
        }
    }
    assert!(accuracy.colour_accuracy() > 0.97, "{accuracy:?}");
    assert!(accuracy.false_colour_rate() < 0.05, "{accuracy:?}");
    for class in [ColourClass::Orange, ColourClass::Green, ColourClass::White] {
        assert!(
            accuracy.recall(class).unwrap() > 0.8,
            "{class:?}: {accuracy:?}"
        );
    }
}
