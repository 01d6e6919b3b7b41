//! MCAP streams: opened from a file (damaged chunks, truncation, wrong schemas, records outside
//! chunks, summaries that do not describe the file), every frame read (the first 64), and every
//! message walked.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("eotn-fuzz-{}.mcap", std::process::id()));
    if std::fs::write(&path, data).is_err() {
        return;
    }
    if let Ok(mut reader) = eotn::streams::StreamReader::open(&path) {
        for index in 0..reader.len().min(64) {
            let _ = reader.read(index);
        }
        let mut bytes = 0usize;
        let _ = reader.for_each_message(|m| bytes += m.data.len());
        let _ = (reader.channels().len(), reader.counts());
    }
});
