//! The world as the tools know it, below everything that renders, recognises or evaluates it:
//! the field and what stands on it ([`scene`]: field dimensions, materials and their colour
//! classes, goal colours, teams, beacons, markers, robots) and the per-frame ground truth
//! ([`truth`]: what a perfect recognition would report). Plain serde data; the simulator
//! (`crate::sim`) renders this model, the overhead recogniser reads its field, and evaluation
//! compares recognition with its truth.

pub mod scene;
pub mod truth;

pub use scene::Scene;
pub use truth::GroundTruth;
