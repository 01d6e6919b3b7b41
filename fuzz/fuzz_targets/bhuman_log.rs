//! B-Human log files (`eotn import-bhuman`): the log reader and its record decoders.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = eotn::import::bhuman::parse_log(data);
    let _ = eotn::import::bhuman::parse_camera_matrix(data);
});
