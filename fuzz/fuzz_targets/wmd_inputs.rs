//! What the World Model Debugger reads from outside: a robot's world-model message (from a
//! recording or, since `eotn wmd` reads live robots, straight off the network) and the session
//! file; a message that parses is written back and parsed again to the same message.
#![no_main]

use eotn::model::world_model;
use eotn::session::Session;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = world_model::parse(data) {
        let again = world_model::from_value(&m.to_json()).expect("a parsed message writes back");
        assert_eq!(again, m);
    }
    if let Ok(text) = std::str::from_utf8(data) {
        let base = std::path::Path::new("/nonexistent-eotn-fuzz");
        let _ = Session::from_json(text, &base.join("SESSION.json"), base);
    }
});
