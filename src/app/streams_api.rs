//! TEMPORARY until the `streams` branch is merged: the contract's reader signatures so the app
//! compiles. Replaced by `use crate::streams as streams_api;`.
#![allow(missing_docs, clippy::unused_self, dead_code)]

use std::path::Path;

pub struct StreamInfo {
    pub source: String,
    pub description: String,
}
pub struct FrameRecord {
    pub time_ns: u64,
    pub frame: crate::frame::Frame,
    pub sensors: Option<crate::sensors::SensorReadings>,
    pub ground_truth: Option<serde_json::Value>,
    pub recognition: Option<serde_json::Value>,
    pub extra: Vec<(String, serde_json::Value)>,
}
pub struct StreamReader {
    info: StreamInfo,
}
impl StreamReader {
    pub fn open(path: &Path) -> anyhow::Result<Self> {
        anyhow::bail!("{}: streams are not merged yet", path.display())
    }
    pub fn info(&self) -> &StreamInfo {
        &self.info
    }
    pub fn len(&self) -> usize {
        0
    }
    pub fn time_ns(&self, _index: usize) -> Option<u64> {
        None
    }
    pub fn index_at_time(&self, _time_ns: u64) -> usize {
        0
    }
    pub fn read(&mut self, _index: usize) -> anyhow::Result<FrameRecord> {
        anyhow::bail!("not merged")
    }
    pub fn warnings(&self) -> &[String] {
        &[]
    }
}
