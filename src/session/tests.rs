use std::path::Path;

use super::*;

/// A folder with the files a session names: two tables, two calibrations, a recording.
fn folder() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    for name in [
        "a.lut",
        "b.lut",
        "a.cal.json",
        "b.cal.json",
        "cam.mcap",
        "rob.mcap",
    ] {
        std::fs::write(dir.path().join(name), b"x").expect("write");
    }
    dir
}

fn load(dir: &Path, json: &str) -> Result<Session, SessionError> {
    Session::from_json(json, &dir.join("SESSION.json"), dir)
}

fn message(r: Result<Session, SessionError>) -> String {
    r.expect_err("refused").to_string()
}

const TWO_CAMERAS: &str = r#"{
  "field": "four-legged-2005",
  "overhead": [
    {"id": 0, "source": "cam.mcap", "camera": "/cam0", "lut": "a.lut", "calibration": "a.cal.json"},
    {"id": 7, "source": "cam.mcap", "camera": "/cam7", "lut": "b.lut", "calibration": "b.cal.json",
     "intrinsics": "a.cal.json"}
  ],
  "robots": [
    {"team": "blue", "robot_id": 3, "source": "rob.mcap"},
    {"team": "yellow", "robot_id": 3, "source": "ws://127.0.0.1:8765"}
  ]
}"#;

#[test]
fn two_cameras_and_two_robots_load_with_paths_beside_the_file() {
    let dir = folder();
    let s = load(dir.path(), TWO_CAMERAS).expect("loads");
    assert_eq!(s.field, FieldRef::Shipped("four-legged-2005".to_owned()));
    assert_eq!(s.overhead.len(), 2);
    assert_eq!(s.overhead[1].id, SslCameraId(7));
    assert_eq!(s.overhead[1].lut, Some(dir.path().join("b.lut")));
    assert_eq!(s.overhead[1].camera.as_deref(), Some("/cam7"));
    assert_eq!(
        s.overhead[1].intrinsics.as_deref(),
        Some(dir.path().join("a.cal.json").as_path())
    );
    assert_eq!(
        s.overhead[0].source,
        SessionSource::Recording(dir.path().join("cam.mcap"))
    );
    assert_eq!(s.robots[0].team, MarkerTeam::Blue);
    assert_eq!(s.robots[1].robot_id.value(), 3);
    assert_eq!(
        s.robots[1].source,
        SessionSource::Live("ws://127.0.0.1:8765".into())
    );
    assert!(s.camera(SslCameraId(7)).is_some());
    assert!(s.camera(SslCameraId(1)).is_none());
    // Each numbered camera is a camera of its own: its source and topic.
    let (a, b) = (s.overhead[0].camera_id(), s.overhead[1].camera_id());
    assert!(a.same_source(&b) && a != b, "{a} {b}");
    assert_eq!(b.topic(), "/cam7");
    assert!(matches!(b, crate::camera::CameraId::Overhead { .. }), "{b}");
    assert!(s.field.load().is_ok());
}

#[test]
fn an_unknown_key_is_refused_naming_the_entry_and_the_key() {
    let dir = folder();
    let json = TWO_CAMERAS.replace("\"intrinsics\"", "\"intrinsic\"");
    let m = message(load(dir.path(), &json));
    assert!(m.contains("overhead[1] (id 7)"), "{m}");
    assert!(m.contains("intrinsic"), "{m}");
    let top = TWO_CAMERAS.replacen("\"field\"", "\"feild\": 1, \"field\"", 1);
    assert!(message(load(dir.path(), &top)).contains("feild"));
}

#[test]
fn two_cameras_with_one_id_are_refused() {
    let dir = folder();
    let json = TWO_CAMERAS.replace("\"id\": 7", "\"id\": 0");
    let m = message(load(dir.path(), &json));
    assert!(m.contains("overhead[1] (id 0)"), "{m}");
    assert!(m.contains("overhead[0]"), "{m}");
}

#[test]
fn two_robots_with_one_marker_are_refused() {
    let dir = folder();
    let json = TWO_CAMERAS.replace("\"yellow\"", "\"blue\"");
    let m = message(load(dir.path(), &json));
    assert!(m.contains("robots[1] (robot_id 3)"), "{m}");
}

#[test]
fn a_table_that_does_not_exist_is_refused_naming_it() {
    let dir = folder();
    let json = TWO_CAMERAS.replace("b.lut", "missing.lut");
    let m = message(load(dir.path(), &json));
    assert!(m.contains("overhead[1] (id 7)"), "{m}");
    assert!(m.contains("missing.lut"), "{m}");
}

#[test]
fn a_missing_calibration_is_refused() {
    let dir = folder();
    let json = TWO_CAMERAS.replace(", \"calibration\": \"a.cal.json\"", "");
    let m = message(load(dir.path(), &json));
    assert!(m.contains("overhead[0] (id 0)"), "{m}");
    assert!(m.contains("calibration"), "{m}");
    let json = TWO_CAMERAS.replace("b.cal.json", "gone.cal.json");
    assert!(message(load(dir.path(), &json)).contains("gone.cal.json"));
}

#[test]
fn out_of_range_ids_teams_and_missing_sources_are_refused() {
    let dir = folder();
    for (from, to, expect) in [
        ("\"id\": 7", "\"id\": 256", "overhead[1]"),
        (
            "\"robot_id\": 3, \"source\": \"rob",
            "\"robot_id\": 16, \"source\": \"rob",
            "0-15",
        ),
        ("\"yellow\"", "\"red\"", "blue or yellow"),
        ("rob.mcap", "nowhere.mcap", "nowhere.mcap"),
        ("four-legged-2005", "no-such-field", "not a shipped field"),
    ] {
        let m = message(load(dir.path(), &TWO_CAMERAS.replace(from, to)));
        assert!(m.contains(expect), "{from} → {to}: {m}");
    }
    let none = r#"{"field": "ssl-2008", "overhead": []}"#;
    assert!(message(load(dir.path(), none)).contains("at least one"));
}

#[test]
fn a_field_file_beside_the_session_is_used() {
    let dir = folder();
    let field = crate::overhead::FieldDescription::four_legged_2005();
    std::fs::write(
        dir.path().join("my-field.json"),
        serde_json::to_string(&field).expect("field json"),
    )
    .expect("write");
    let json = TWO_CAMERAS.replace("four-legged-2005", "my-field.json");
    let s = load(dir.path(), &json).expect("loads");
    assert_eq!(s.field, FieldRef::File(dir.path().join("my-field.json")));
    assert_eq!(s.field.load().expect("field loads"), field);
}

#[test]
fn a_session_file_is_read_from_disk_with_paths_beside_it() {
    let dir = folder();
    let path = dir.path().join("SESSION.json");
    std::fs::write(&path, TWO_CAMERAS).expect("write");
    let s = Session::load(&path).expect("loads");
    assert_eq!(
        s.overhead[0].calibration,
        Some(dir.path().join("a.cal.json"))
    );
    let gone = Session::load(&dir.path().join("none.json")).expect_err("missing");
    assert!(gone.to_string().contains("none.json"));
}

#[test]
fn every_shipped_field_is_a_session_field_as_it_is_a_field_argument() {
    // Regression: the session once kept its own list of two shipped fields, so
    // `"field": "ssl-div-a"` was refused though `--field ssl-div-a` worked.
    let dir = folder();
    for (name, _) in crate::overhead::field::SHIPPED_FIELDS {
        let s = load(dir.path(), &TWO_CAMERAS.replace("four-legged-2005", name))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let loaded = s.field.load().unwrap_or_else(|e| panic!("{name}: {e}"));
        let by_argument = crate::overhead::FieldDescription::resolve(name).expect("shipped");
        assert_eq!(loaded, by_argument, "{name}");
    }
}

#[test]
fn an_ssl_vision_source_needs_no_table_and_stands_alone() {
    let dir = folder();
    std::fs::write(dir.path().join("game.log"), b"SSL_LOG_FILE").expect("write");
    let one = |source: &str| {
        format!(
            r#"{{"field": "ssl-div-a", "overhead": [{{"id": 0, "source": "{source}"}}],
                "robots": [{{"team": "blue", "robot_id": 3, "source": "rob.mcap"}}]}}"#
        )
    };
    let s = load(dir.path(), &one("udp://224.5.23.2:10006")).expect("loads");
    assert_eq!(
        s.overhead[0].source,
        SessionSource::Ssl(SslSource::Udp("udp://224.5.23.2:10006".into()))
    );
    assert_eq!(
        (
            s.overhead[0].lut.as_ref(),
            s.overhead[0].calibration.as_ref()
        ),
        (None, None)
    );
    let s = load(dir.path(), &one("game.log")).expect("loads");
    assert_eq!(
        s.overhead[0].source,
        SessionSource::Ssl(SslSource::Log(dir.path().join("game.log")))
    );
    // An eotn camera still needs its table and calibration.
    let m = message(load(dir.path(), &one("cam.mcap")));
    assert!(m.contains("overhead[0]") && m.contains("`lut`"), "{m}");
    // Beside another camera: refused, naming it.
    let two = TWO_CAMERAS.replace(
        r#"{"id": 0, "source": "cam.mcap", "camera": "/cam0", "lut": "a.lut", "calibration": "a.cal.json"}"#,
        r#"{"id": 0, "source": "udp://127.0.0.1:10006"}"#,
    );
    let m = message(load(dir.path(), &two));
    assert!(
        m.contains("overhead[0] (id 0)") && m.contains("only overhead entry"),
        "{m}"
    );
    assert_eq!(
        SessionSource::parse_arg(Path::new("udp://127.0.0.1:5")),
        SessionSource::Ssl(SslSource::Udp("udp://127.0.0.1:5".into()))
    );
    assert_eq!(
        SessionSource::parse_arg(Path::new("x/Game.LOG")),
        SessionSource::Ssl(SslSource::Log("x/Game.LOG".into()))
    );
}
