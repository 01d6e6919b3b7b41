//! eotn — Eye Of The NUbot: the colour-vision pipeline of a robot-soccer team, and the tools to
//! see every stage of it.
//!
//! Modules read in data-flow order; each uses only those above it:
//!
//! | module | role |
//! |---|---|
//! | [`atomic_file`] | how every output is written: temporary + fsync + rename, devices and FIFOs in place, links kept, inputs never replaced |
//! | [`input_file`] | reading the files a user names: regular files only, bounded in size |
//! | [`camera`] | which camera (a recording's topic, a live robot's channel, an overhead source) and the files it is recognised with: stream metadata, the `REC.cameras.json` sidecar |
//! | [`stats`] | the median and the inverse-size least squares shared by recognition and evaluation |
//! | [`kernels`] | which hot-loop kernels (portable, AVX2, AVX-512) this CPU runs: the choosing rule, `EOTN_KERNELS` |
//! | [`frame`] | YUV frames (UYVY 4:2:2, YUV 4:4:4), RGB display conversion, frame files |
//! | [`lut`] | the 3D YUV lookup table, colour classes, the editing model, other teams' formats |
//! | [`classify`] | frame + table → classified image |
//! | [`blobs`] | classified image → connected blobs |
//! | [`sensors`] | the robot's sensor readings for a frame (units, NaN handling) |
//! | [`geometry`] | camera models, the ERS-7 body-to-camera chain, horizon, overhead camera |
//! | [`model`] | the world described (field, materials, teams, goals) and per-frame ground truth |
//! | [`sim`] | synthetic frames with ground truth: renders the model, scenarios over time |
//! | [`import`] | other teams' recordings (the B-Human 2009 Nao log) into frames and readings |
//! | [`formats`] | one decoder per message type (ROS 2 CDR, Foxglove protobuf): images, camera info, joints, TF |
//! | [`recognition`] | classified image + blobs + view → ball, goals, beacons, coloured patterns |
//! | [`overhead`] | overhead camera: field descriptions, calibration, ball and robot markers |
//! | [`session`] | the session file: a field, its overhead cameras (each its table and calibration), robots |
//! | [`pipeline`] | one frame through classification, blobs and recognition, with timings |
//! | [`overlay`] | recognition's drawing primitives on RGB images (`eotn render`) |
//! | [`annotate`] | those primitives as Foxglove image annotations (`eotn detect --annotate`) |
//! | [`eval`] | recognition against ground truth or hand labels: rates, errors, plots |
//! | [`streams`] | recorded MCAP streams: frames + sensors + truth, random access by index/time |
//! | [`sources`] | frame sources (stream, files, synthetic, V4L2 camera, network), recording |
//! | [`live`] | live robots over the Foxglove WebSocket protocol: client, frames, recording, `eotn serve` |
//! | [`workspace`] | what the app, the CLI and the tests share: table, source, playback, edits |
//! | [`app_options`] | how the desktop app starts (files, renderer, playing): the CLI fills it in |
//! | [`cli`] | the `eotn` subcommands |
//! | `app` | the desktop app (feature `gui`) |
//!
//! See `ARCHITECTURE.md` for the map.

pub mod annotate;
pub mod app_options;
pub mod atomic_file;
pub mod blobs;
pub mod camera;
pub mod classify;
pub mod eval;
pub mod formats;
pub mod frame;
pub mod geometry;
pub mod import;
pub mod input_file;
pub mod kernels;
pub mod live;
pub mod lut;
pub mod model;
pub mod overhead;
pub mod overlay;
pub mod pipeline;
pub mod recognition;
pub mod sensors;
pub mod session;
pub mod sim;
pub mod sources;
pub mod ssl_vision;
pub mod stats;
pub mod streams;
pub mod wmd;
pub mod workspace;

pub mod cli;

#[cfg(test)]
mod test_skip;

/// The desktop app (egui/eframe on wgpu); only this module names the UI crates.
#[cfg(feature = "gui")]
pub mod app;
