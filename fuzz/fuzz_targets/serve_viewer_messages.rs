//! `eotn serve`'s gate, server side: a viewer's messages (`subscribe`, `unsubscribe`, anything
//! else) and the server's (`advertise`, `unadvertise`, message data) as the gate reads them,
//! and the viewer's bounded outbox they fill. Each input is a list of segments split at 0xff;
//! a segment's first byte says what it is.
#![no_main]

use eotn::live::gate::outbox::{MAX_CONTROL, Outbox, QueueBound};
use eotn::live::gate::traffic::Traffic;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let bound = QueueBound {
        messages: 4,
        bytes: 4096,
    };
    let mut traffic = Traffic::new();
    let mut outbox = Outbox::new(bound);
    for segment in data.split(|&b| b == 0xff) {
        let Some((&what, rest)) = segment.split_first() else {
            continue;
        };
        let text = std::str::from_utf8(rest).unwrap_or_default();
        match what % 4 {
            0 => {
                traffic.from_viewer(text);
                let _ = (traffic.pause_request(), traffic.resume_request());
            }
            1 => {
                traffic.from_server(text);
                let _ = outbox.push(rest.len(), eotn::live::gate::outbox::Kind::Control, rest.len());
            }
            2 => {
                let kind = traffic.kind_of_binary(rest);
                let _ = outbox.push(rest.len(), kind, rest.len());
            }
            _ => {
                let _ = outbox.pop();
            }
        }
        assert!(outbox.len() <= MAX_CONTROL + bound.messages);
    }
    let dropped = outbox.dropped();
    assert!(dropped.frames <= dropped.messages);
    while outbox.pop().is_some() {}
    assert_eq!(outbox.bytes(), 0);
});
