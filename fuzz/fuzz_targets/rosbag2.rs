//! rosbag2 bags: `metadata.yaml` parsed from the bytes; the bytes as a `.db3` (SQLite) file read
//! through the whole reader, alone and as a bag folder's storage file.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = eotn::streams::rosbag2::BagMetadata::parse(data);
    let dir = std::env::temp_dir().join(format!("eotn-fuzz-bag-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let db3 = dir.join("bag_0.db3");
    if std::fs::write(&db3, data).is_err() {
        return;
    }
    for path in [db3.as_path(), dir.as_path()] {
        if let Ok(mut reader) = eotn::streams::StreamReader::open(path) {
            for index in 0..reader.len().min(16) {
                let _ = reader.read(index);
            }
        }
    }
});
