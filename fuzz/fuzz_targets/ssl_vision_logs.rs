//! The league's SSL game logs (`SSL_LOG_FILE`): the log reader, message by message, with every
//! vision payload decoded and the detection frames indexed by camera and capture time.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(log) = eotn::ssl_vision::log::parse_log(data) {
        let _ = log.summary();
        let index =
            eotn::ssl_vision::truth::FrameIndex::new(log.frames.into_iter().map(|f| f.frame));
        let _ = index.near(0, 13_333_333);
    }
});
