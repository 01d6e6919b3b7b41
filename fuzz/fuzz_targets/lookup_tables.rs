//! Lookup tables: ours (raw cells) and the six other teams' formats.
#![no_main]

use eotn::lut::LookupTable;
use eotn::lut::convert::{SourceFormat, convert_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = LookupTable::from_bytes(data.to_vec());
    for format in SourceFormat::ALL {
        let _ = convert_bytes(format, data);
    }
    let _ = SourceFormat::detect(std::path::Path::new("table"), data);
});
