//! eotn — Eye Of The NUbot: the colour-vision pipeline of a robot-soccer team, and the tools to
//! see every stage of it.
//!
//! Modules read in data-flow order; each uses only those above it:
//!
//! | module | role |
//! |---|---|
//! | [`frame`] | YUV frames (UYVY 4:2:2, YUV 4:4:4), RGB display conversion, frame files |
//! | [`lut`] | the 3D YUV lookup table, colour classes, the editing model |
//! | [`classify`] | frame + table → classified image |
//! | [`blobs`] | classified image → connected blobs |
//! | [`sensors`] | the robot's sensor readings for a frame (units, NaN handling) |
//! | [`streams`] | recorded MCAP streams: frames + sensors + truth, random access by index/time |
//! | [`geometry`] | camera models, the ERS-7 body-to-camera chain, horizon, overhead camera |
//! | [`sim`] | synthetic frames with ground truth: scenes, renderer, scenarios |
//! | [`import`] | other teams' recordings (the B-Human 2009 Nao log) into frames and readings |
//! | [`sources`] | frame sources (stream, files, synthetic, V4L2 camera, network), recording |
//! | [`workspace`] | what the app, the CLI and the tests share: table, source, playback, edits |
//!
//! See `ARCHITECTURE.md` for the map.

pub mod annotate;
pub mod atomic_file;
pub mod blobs;
pub mod classify;
pub mod eval;
pub mod frame;
pub mod geometry;
pub mod import;
pub mod lut;
pub mod overlay;
pub mod pipeline;
pub mod recognition;
pub mod sensors;
pub mod sim;
pub mod sources;
pub mod streams;
pub mod workspace;

pub mod cli;

/// The desktop app (egui/eframe on wgpu); only this module names the UI crates.
#[cfg(feature = "gui")]
pub mod app;
