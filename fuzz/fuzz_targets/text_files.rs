//! Text files a user hands over: recognition parameters, hand labels, JSON side files (sensor
//! readings, Python's NaN included).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = eotn::recognition::params_file::from_json(text);
        let _ = eotn::eval::labels::Labels::parse(text);
    }
    if let Ok((value, _)) = eotn::streams::schema::parse_json_lenient(data) {
        let _ = serde_json::from_value::<eotn::sensors::SensorReadings>(value);
    }
});
