//! The world as the tools know it, below everything that renders, recognises or evaluates it:
//! the field and what stands on it ([`scene`]: field dimensions, materials and their colour
//! classes, goal colours, teams, beacons, markers, robots) and the per-frame ground truth
//! ([`truth`]: what a perfect recognition would report). Plain serde data; the simulator
//! (`crate::sim`) renders this model, the overhead recogniser reads its field, and evaluation
//! compares recognition with its truth. [`world_model`]: the message a robot sends saying where
//! it thinks it and the ball are (written by the simulator, read by the world-model debugger).

pub mod scene;
pub mod truth;
pub mod world_model;

pub use scene::Scene;
pub use truth::GroundTruth;
