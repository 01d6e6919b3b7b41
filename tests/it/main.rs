//! Integration tests, one binary with a module per area (as ripgrep does).

#![allow(clippy::unwrap_used, reason = "test helpers: a panic is a failed test")]

#[cfg(feature = "gui")]
mod app;
#[cfg(feature = "gui")]
mod app_camera;
#[cfg(feature = "gui")]
mod app_cameras;
#[cfg(feature = "gui")]
mod app_classify;
#[cfg(feature = "gui")]
mod app_daily;
#[cfg(feature = "gui")]
mod app_field_cameras;
#[cfg(feature = "gui")]
mod app_hints;
#[cfg(feature = "gui")]
mod app_layout;
#[cfg(feature = "gui")]
mod app_live;
#[cfg(feature = "gui")]
mod app_overhead;
#[cfg(feature = "gui")]
mod app_overhead_tools;
#[cfg(feature = "gui")]
mod app_papercuts;
#[cfg(feature = "gui")]
mod app_wmd;
mod beacons;
mod camera;
mod cameras;
mod cameras_input;
mod cli;
mod common;
mod crash_safety;
mod docs;
mod field;
mod hardening;
mod hardening_files;
#[cfg(feature = "gui")]
mod harness;
mod jpeg_colour;
mod kernels;
mod label_sets;
mod label_sets_cli;
mod live;
mod live_peers;
mod mcap_conformance;
mod motion;
#[cfg(unix)]
mod outputs;
mod overhead;
mod overhead_lens;
mod params_doc;
mod patterns;
mod peer;
mod properties;
mod real_data;
mod recognition;
mod recordings;
mod robot_cameras;
mod robots;
mod serve_load;
mod sim;
mod sim_table;
mod snapshots;
mod ssl2008;
mod ssl_onboard;
mod ssl_vision;
mod streams;
mod viewers;
#[cfg(feature = "gui")]
mod window;
mod without_readings;
mod wmd;
mod wmd_live;
mod wmd_ssl;
