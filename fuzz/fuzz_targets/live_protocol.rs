//! A robot's messages over the Foxglove WebSocket protocol, as the live client takes them: text
//! (JSON) and binary frames parsed, an `advertise` kept within the client's limits (channels,
//! names, schemas) and withdrawn again, and the `foxglove.RawImage` payloads inside them.
#![no_main]

use eotn::live::Limits;
use eotn::live::channels::Channels;
use eotn::live::protocol::{ServerMessage, parse_binary, parse_text};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = Limits {
        max_channels: 16,
        max_name_bytes: 64,
        max_schema_bytes: 1024,
        ..Limits::default()
    };
    let mut channels = Channels::new(limits.clone());
    let _ = parse_binary(data);
    // One message per line, so an input can advertise, withdraw and advertise again.
    for line in data.split(|&b| b == b'\n') {
        let Ok(text) = std::str::from_utf8(line) else {
            continue;
        };
        match parse_text(text, limits.max_channels) {
            Ok(ServerMessage::Advertise { channels: list, beyond }) => {
                assert!(list.len() <= limits.max_channels);
                let outcome = channels.advertise(list, beyond);
                assert!(outcome.subscribe.len() <= limits.max_channels);
                assert!(channels.len() <= limits.max_channels);
            }
            Ok(ServerMessage::Unadvertise(ids)) => channels.unadvertise(&ids),
            _ => {}
        }
    }
    let _ = eotn::streams::schema::decode_image_with_time(data);
});
