//! Frame files: raw UYVY (size inferred from the length), PNG and JPEG, through the bounded
//! loader that refuses oversized images before decoding them.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir();
    let id = std::process::id();
    for extension in ["uyvy", "png", "jpg"] {
        let path = dir.join(format!("eotn-fuzz-{id}.{extension}"));
        if std::fs::write(&path, data).is_ok() {
            let _ = eotn::frame::load_frame(&path, None);
        }
    }
});
