//! Label sets teams hand over: YOLO frame files and `classes.txt`, COCO JSON, Pascal VOC XML
//! (`eotn eval --labels`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        use eotn::eval::label_sets::{ClassMap, parse_coco, parse_voc, parse_yolo_classes, parse_yolo_frame};
        let map = ClassMap::default();
        let names = parse_yolo_classes(text);
        let _ = parse_yolo_frame(text, &["robot".into(), "ball".into(), "goal".into()], &map);
        let _ = parse_yolo_frame(text, &names, &map);
        let _ = parse_coco(text, &map);
        let _ = parse_voc(text, &map);
        let _ = ClassMap::parse(text);
    }
});
