//! `eotn import --bhuman LOG -o OUT.mcap`: the B-Human 2009 Nao log as a stream.

use std::path::Path;

use anyhow::Context;

use crate::import::bhuman;
use crate::streams::{FrameRecord, StreamInfo, StreamWriter, WriterOptions};

/// JSON channel holding B-Human's raw joint and sensor records of each frame.
pub const RAW_TOPIC: &str = "/bhuman2009";

/// Reads the log and writes its frames, sensor readings and raw records as a stream; returns the
/// number of frames written.
///
/// # Errors
/// An unreadable or invalid log, or an unwritable stream, naming the file.
pub fn run(log_path: &Path, output: &Path, options: WriterOptions) -> anyhow::Result<usize> {
    let log = bhuman::read_log(log_path)?;
    for w in &log.warnings {
        log::warn!("{}: {w}", log_path.display());
    }
    let info = StreamInfo {
        source: "bhuman2009".into(),
        description: format!(
            "B-Human 2009 Nao log ({}): {} camera images as 320x240 UYVY (B-Human's own grid: \
             one pixel per YUYV macropixel, every second camera row), joint and sensor data; \
             raw records on {RAW_TOPIC}. This product includes software developed by B-Human \
             (http://www.b-human.de); see streams/LICENSE-bhuman2009.txt.",
            crate::frame::display_name(log_path),
            log.frames.len()
        ),
    };
    let mut writer = StreamWriter::create_with(output, &info, options)?;
    if let Some(set) = crate::streams::param_set_of_source(&info.source) {
        writer.name_param_set(set)?;
    }
    let t0 = log.frames.first().map_or(0, |f| f.time_ms);
    for (i, f) in log.frames.iter().enumerate() {
        let time_ns = u64::from(f.time_ms.saturating_sub(t0)) * 1_000_000;
        let mut record = FrameRecord::new(time_ns, f.frame.clone());
        record.sensors = Some(f.sensors);
        record.extra.push((RAW_TOPIC.into(), f.raw.clone()));
        writer
            .write(&record)
            .with_context(|| format!("{}: frame {i}", log_path.display()))?;
    }
    writer.finish()?;
    Ok(log.frames.len())
}
