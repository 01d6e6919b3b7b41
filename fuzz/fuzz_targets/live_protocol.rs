//! A robot's messages over the Foxglove WebSocket protocol: text (JSON) and binary frames, and
//! the `foxglove.RawImage` payloads inside them.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = eotn::live::protocol::parse_binary(data);
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = eotn::live::protocol::parse_text(text);
    }
    let _ = eotn::streams::schema::decode_image_with_time(data);
});
