//! The files the app keeps beside a user's work: the edit journal (parsed and replayed onto a
//! table, its undo history and all) and the settings file of this or another version.
#![no_main]

use eotn::lut::LookupTable;
use eotn::workspace::Settings;
use eotn::workspace::journal::{self, JournalEntry};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = Settings::from_json(text);
    let (entries, _) = journal::parse(text, "fuzz");
    // Replayed onto the table its start line names (6 or 7 bits: 8 would make each run
    // allocate 16 MiB, which slows the fuzzer without reaching other code).
    let bits = match entries.first() {
        Some(JournalEntry::Start { bits: b @ 6..=7, .. }) => *b,
        _ => 6,
    };
    if let Ok(mut lut) = LookupTable::new(bits) {
        let _ = journal::replay_onto(&mut lut, entries.into_iter().skip(1), "fuzz");
    }
});
