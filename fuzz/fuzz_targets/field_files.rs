//! The files of the overhead camera and the coloured patterns: field descriptions, calibration
//! points, calibrations, places; and Tekkotsu's `.col` class file with a `.tm` table.
#![no_main]

use eotn::lut::convert::tekkotsu;
use eotn::overhead::points::PointsFile;
use eotn::overhead::{Calibration, FieldDescription};
use eotn::recognition::patterns::PatternMemory;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("eotn-fuzz-{}.json", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = FieldDescription::load(&path);
        let _ = PointsFile::load(&path);
        let _ = Calibration::load(&path);
    }
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = PatternMemory::from_json(text);
        if let Ok(col) = tekkotsu::parse_col(text) {
            let _ = tekkotsu::convert(data, &col);
        }
    }
    // A .tm with a small class file of its own.
    if let Ok(col) = tekkotsu::parse_col("1 (255 128 0) \"orange\" 1\n2 (0 255 0) \"green\" 1\n") {
        let _ = tekkotsu::convert(data, &col);
    }
});
