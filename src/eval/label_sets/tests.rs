use super::*;

fn names() -> Vec<String> {
    parse_yolo_classes("robot\nball\n\ngoal\n")
}

const VOC: &str = r#"<annotation>
	<folder>x</folder><filename>00002.jpg</filename>
	<size><width>224</width><height>224</height><depth>3</depth></size>
	<object><name>robot</name><pose>Unspecified</pose>
		<bndbox><xmin>28</xmin><ymin>21</ymin><xmax>192</xmax><ymax>197</ymax></bndbox></object>
	<object><name>ball</name>
		<bndbox><xmin>25</xmin><ymin>143</ymin><xmax>70</xmax><ymax>189</ymax></bndbox></object>
</annotation>"#;

const COCO: &str = r#"{"images": [{"id": 7, "file_name": "sub/00002.jpg", "width": 224, "height": 224},
  {"id": 8, "file_name": "00003.jpg", "width": 224, "height": 224}],
 "annotations": [{"id": 1, "image_id": 7, "category_id": 2, "bbox": [25, 143, 45, 46], "area": 9},
   {"id": 2, "image_id": 7, "category_id": 1, "bbox": [28, 21, 164, 176]}],
 "categories": [{"id": 1, "name": "robot"}, {"id": 2, "name": "ball"}], "info": {}}"#;

#[test]
fn the_three_formats_read_the_same_box() {
    let map = ClassMap::default();
    let (yolo, warnings) = parse_yolo_frame(
        "0 0.491071 0.486607 0.732143 0.785714\n1 0.212054 0.741071 0.200893 0.205357\n",
        &names(),
        &map,
    )
    .expect("yolo");
    assert!(warnings.is_empty());
    let set = LabelSet {
        format: LabelFormat::Yolo,
        frames: [("00002".to_owned(), yolo)].into(),
        fractional: true,
        warnings: vec![],
    };
    let yolo = set.frame_in_pixels("00002", 224, 224).expect("frame");
    let (stem, voc) = parse_voc(VOC, &map).expect("voc");
    assert_eq!(stem.as_deref(), Some("00002"));
    assert_eq!(voc.size, Some((224, 224)));
    let (coco, _) = parse_coco(COCO, &map).expect("coco");
    let coco = &coco["00002"];
    for boxes in [&yolo, &voc, coco] {
        let ball = boxes.balls().next().expect("a ball");
        assert_eq!(ball.object, LabelObject::Ball);
        for (got, want) in [
            (ball.min_x, 25.0),
            (ball.min_y, 143.0),
            (ball.max_x, 70.0),
            (ball.max_y, 189.0),
        ] {
            assert!((got - want).abs() < 0.01, "{got} vs {want}");
        }
        assert_eq!(boxes.boxes.len(), 2);
    }
}

#[test]
fn class_names_map_to_objects() {
    let map = ClassMap::parse("orange=ball, bot=robot").expect("map");
    assert_eq!(map.object("Orange"), LabelObject::Ball);
    assert_eq!(map.object("bot"), LabelObject::Robot);
    assert_eq!(map.object("goal"), LabelObject::Goal);
    assert_eq!(map.object("referee"), LabelObject::Other);
    assert!(matches!(
        ClassMap::parse("orange"),
        Err(LabelSetProblem::ClassMapping(_))
    ));
    assert!(ClassMap::parse("orange=sun").is_err());
    assert!(ClassMap::parse("=ball").is_err());
}

#[test]
fn bad_files_say_why() {
    let map = ClassMap::default();
    let yolo = |t: &str| parse_yolo_frame(t, &names(), &map);
    assert!(matches!(
        yolo("1 0.5 0.5 0.1"),
        Err(LabelSetProblem::YoloLine { line: 1, .. })
    ));
    assert!(matches!(
        yolo("\n1 0.5 NaN 0.1 0.1"),
        Err(LabelSetProblem::YoloLine { line: 2, .. })
    ));
    assert!(matches!(
        yolo("5 0.5 0.5 0.1 0.1"),
        Err(LabelSetProblem::YoloClass { class: 5, .. })
    ));
    // A box without area is skipped with a warning, not an error.
    let (f, w) = yolo("1 0.5 0.5 0 0.1\n1 0.5 0.5 0.1 0.1").expect("read");
    assert_eq!((f.boxes.len(), w.len()), (1, 1));
    assert!(parse_voc("<other/>", &map).is_err());
    assert!(
        parse_voc(
            "<annotation><object><name>ball</name></object></annotation>",
            &map
        )
        .is_err()
    );
    assert!(parse_voc(&VOC.replace("<xmin>25", "<xmin>x25"), &map).is_err());
    assert!(parse_voc(&VOC.replace("</annotation>", ""), &map).is_err());
    assert!(parse_voc(&"<annotation>".repeat(40), &map).is_err());
    assert!(matches!(
        parse_coco("[]", &map),
        Err(LabelSetProblem::Coco(_))
    ));
    assert!(
        parse_coco(
            &COCO.replace("\"category_id\": 2", "\"category_id\": 9"),
            &map
        )
        .is_err()
    );
    assert!(parse_coco(&COCO.replace("\"id\": 8", "\"id\": 7"), &map).is_err());
}

#[test]
fn folders_are_told_apart_by_content() {
    let dir = tempfile::tempdir().expect("temp");
    let yolo = dir.path().join("yolo");
    std::fs::create_dir(&yolo).expect("dir");
    std::fs::write(yolo.join("00002.txt"), "1 0.5 0.5 0.1 0.1\n").expect("write");
    let options = ReadOptions::default();
    let err = LabelSet::load(&yolo, &options).expect_err("no class names");
    assert!(err.to_string().contains("--class-names"), "{err}");
    let named = ReadOptions {
        class_names: Some(names()),
        ..ReadOptions::default()
    };
    let set = LabelSet::load(&yolo, &named).expect("yolo");
    assert_eq!(set.format, LabelFormat::Yolo);
    let voc = dir.path().join("voc");
    std::fs::create_dir(&voc).expect("dir");
    std::fs::write(voc.join("00002.xml"), VOC).expect("write");
    assert_eq!(
        LabelSet::load(&voc, &options).expect("voc").format,
        LabelFormat::Voc
    );
    let coco = dir.path().join("labels.json");
    std::fs::write(&coco, COCO).expect("write");
    let set = LabelSet::load(&coco, &options).expect("coco");
    assert_eq!((set.format, set.frames.len()), (LabelFormat::Coco, 2));
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).expect("dir");
    assert!(LabelSet::load(&empty, &options).is_err());
}

#[test]
fn held_out_frames_end_in_7_8_or_9() {
    assert!(is_held_out("00007") && is_held_out("00018") && is_held_out("frame_29"));
    assert!(!is_held_out("00010") && !is_held_out("00006") && !is_held_out("still"));
    assert!(Split::HeldOut.takes("00649") && !Split::HeldOut.takes("00640"));
    assert!(Split::Tuning.takes("00640") && Split::All.takes("00649"));
}
