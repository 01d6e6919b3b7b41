//! The files of the overhead camera and the coloured patterns: field descriptions, calibration
//! points, calibrations, places — each parser as the loaders call it, and the checks a
//! calibration goes through; and Tekkotsu's `.col` class file with a `.tm` table.
#![no_main]

use eotn::lut::convert::tekkotsu;
use eotn::overhead::points::PointsFile;
use eotn::overhead::{Calibration, FieldDescription};
use eotn::recognition::patterns::PatternMemory;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(field) = FieldDescription::from_json(text) {
            // Sampling a description that loaded is bounded, whatever it says.
            assert!(field.line_samples(0.5).len() <= eotn::overhead::field::MAX_LINE_SAMPLES + 2 * 1000);
        }
        if let Ok((points, _)) = PointsFile::from_json(text) {
            let field = FieldDescription::four_legged_2005();
            let _ = eotn::overhead::review::check_points(&points, &field);
        }
        if let Ok(cal) = Calibration::from_json(text) {
            let _ = eotn::overhead::review::review(&cal);
        }
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
