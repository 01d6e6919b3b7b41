//! SSL-Vision as the overhead source of `eotn wmd` (issue 32, item 2): the truth of the
//! simulated game of `wmd.rs` (whose robots' world models carry known errors) as SSL-Vision
//! packets — a league log read through, the same packets sent live over loopback, and a session
//! file naming the log — comes through `--json` at the packets' positions (≤ 1 mm), and the
//! world models are compared with it: matched by marker, the known errors measured. A port in
//! use, a missing table for an eotn camera and `-o` give clear lines.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use eotn::model::truth::{GroundTruth, OverheadTruth};
use eotn::ssl_vision::SslWrapperPacket;
use eotn::ssl_vision::log::{MessageType, write_header, write_message};
use prost::Message as _;
use serde_json::Value;

use crate::common::{eotn, eotn_ok};
use crate::ssl_vision::truth_packets;
use crate::wmd::{entry, fixture, marker_of};

/// Each frame of the game's truth: ball and robots (team, id, x, y) in centimetres.
type Truth = (Option<[f64; 2]>, Vec<(String, u64, [f64; 2])>);

fn truths() -> Vec<Truth> {
    let mut r = eotn::streams::StreamReader::open(&fixture().stream).unwrap();
    (0..r.len())
        .map(|i| {
            let rec = r.read(i).unwrap();
            let GroundTruth::Overhead(t) =
                serde_json::from_value(rec.ground_truth.unwrap()).unwrap()
            else {
                panic!("overhead truth expected");
            };
            let t: &OverheadTruth = &t;
            let robots = t
                .robots
                .iter()
                .filter_map(|r| {
                    let m = r.marker?;
                    Some((
                        m.team.name().to_owned(),
                        u64::from(m.identity.value()),
                        r.field_cm,
                    ))
                })
                .collect();
            (t.ball.map(|b| b.field_cm), robots)
        })
        .collect()
}

/// Whether a `--json` line's ball and robots are those of `truth`, each within 1 mm.
fn line_is(line: &Value, truth: &Truth) -> bool {
    let near = |v: &Value, p: [f64; 2]| {
        (v["x_cm"].as_f64().unwrap() - p[0]).abs() <= 0.1
            && (v["y_cm"].as_f64().unwrap() - p[1]).abs() <= 0.1
    };
    let ball = match (&line["ball"], truth.0) {
        (Value::Null, None) => true,
        (b, Some(p)) if !b.is_null() => near(b, p),
        _ => false,
    };
    let robots = line["robots"].as_array().unwrap();
    ball && robots.len() == truth.1.len()
        && truth.1.iter().all(|(team, id, p)| {
            robots
                .iter()
                .any(|r| r["team"] == team.as_str() && r["id"] == *id && near(r, *p))
        })
}

/// The game's truth as a league log (with a referee message between, skipped).
fn truth_log(dir: &Path) -> PathBuf {
    let log = dir.join("game.log");
    let mut bytes = Vec::new();
    write_header(&mut bytes);
    for (t, p) in &truth_packets(&fixture().stream) {
        write_message(&mut bytes, *t, MessageType::Vision2014, p);
        write_message(&mut bytes, *t, MessageType::Refbox2013, &[]);
    }
    std::fs::write(&log, bytes).unwrap();
    log
}

fn json_lines(stdout: &[u8]) -> Vec<Value> {
    String::from_utf8_lossy(stdout)
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Robot 1's known error (50 cm off, 10° turned) measured against the exact truth.
fn assert_known_error(line: &Value) {
    let (model, seen) = entry(line, &marker_of(1));
    if !seen {
        return;
    }
    let model = model.expect("robot 1 sends every frame");
    assert_eq!(model["matched"], "marker", "{model}");
    let p = model["position_error_cm"].as_f64().unwrap();
    assert!((p - 50.0).abs() < 0.5, "{p}");
    let h = model["heading_error_deg"].as_f64().unwrap();
    assert!((h - 10.0).abs() < 0.5, "{h}");
}

#[test]
fn an_ssl_log_is_the_overhead_of_wmd_read_through_and_named_by_a_session() {
    let dir = tempfile::tempdir().unwrap();
    let log = truth_log(dir.path());
    let truth = truths();
    let out = eotn_ok(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        log.as_os_str(),
        OsStr::new("--robot"),
        fixture().stream.as_os_str(),
        OsStr::new("--json"),
    ]);
    let lines = json_lines(&out.stdout);
    assert_eq!(lines.len(), truth.len(), "a field frame per packet");
    for (k, (line, t)) in lines.iter().zip(&truth).enumerate() {
        assert!(line_is(line, t), "frame {k}: {line} is not {t:?}");
        assert_known_error(line);
    }
    let seen = lines.iter().filter(|l| entry(l, &marker_of(1)).1).count();
    assert!(seen >= 40, "robot 1 in {seen} frames");
    // A session file naming the log (no table, no calibration) gives the same lines.
    let one = marker_of(1);
    let session = dir.path().join("SESSION.json");
    let json = serde_json::json!({
        "field": "four-legged-2005",
        "overhead": [{"id": 0, "source": "game.log"}],
        "robots": [{"team": one.0, "robot_id": one.1, "source": fixture().stream}],
    });
    std::fs::write(&session, json.to_string()).unwrap();
    let out = eotn_ok(&[
        OsStr::new("wmd"),
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--json"),
    ]);
    let from_session = json_lines(&out.stdout);
    assert_eq!(from_session.len(), lines.len());
    for (a, b) in from_session.iter().zip(&lines) {
        assert_eq!(a["robots"], b["robots"]);
        assert_eq!(a["ball"], b["ball"]);
        assert_known_error(a);
    }
    // -o: nothing to record from SSL-Vision, said before anything runs.
    let rec = dir.path().join("rec.mcap");
    let out = eotn(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        log.as_os_str(),
        OsStr::new("--robot"),
        fixture().stream.as_os_str(),
        OsStr::new("-o"),
        rec.as_os_str(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("is SSL-Vision"),
        "{stderr}"
    );
    assert!(!rec.exists());
    // An eotn camera still needs its table and calibration.
    let out = eotn(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        fixture().stream.as_os_str(),
        OsStr::new("--robot"),
        fixture().stream.as_os_str(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("needs --lut and --calibration"),
        "{stderr}"
    );
}

#[test]
fn ssl_packets_live_on_loopback_are_the_overhead_of_wmd() {
    let probe = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let port = probe.local_addr().unwrap().port();
    drop(probe);
    let packets = truth_packets(&fixture().stream);
    let truth = truths();
    // The game's packets over and over at 30 Hz for 3.5 s, with a packet that is not
    // SSL-Vision first (the robot's recording replays from the session's start meanwhile).
    let sender = std::thread::spawn(move || {
        let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
        let start = std::time::Instant::now();
        std::thread::sleep(std::time::Duration::from_millis(300));
        socket
            .send_to(&[0xff, 0xff, 0x07], ("127.0.0.1", port))
            .unwrap();
        for (k, (_, p)) in packets.iter().cycle().enumerate().take(105) {
            // Each round's capture times step on from the last, as a camera's do.
            let mut packet = SslWrapperPacket::decode(p.as_slice()).unwrap();
            if let Some(d) = packet.detection.as_mut() {
                d.t_capture += 1.5 * (k / packets.len()) as f64;
                d.frame_number = u32::try_from(k).unwrap();
            }
            socket
                .send_to(&packet.encode_to_vec(), ("127.0.0.1", port))
                .unwrap();
            std::thread::sleep(std::time::Duration::from_millis(33));
            if start.elapsed().as_secs_f64() > 3.8 {
                break;
            }
        }
    });
    let url = format!("udp://127.0.0.1:{port}");
    let out = eotn_ok(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        OsStr::new(&url),
        OsStr::new("--robot"),
        fixture().stream.as_os_str(),
        OsStr::new("--seconds"),
        OsStr::new("4"),
        OsStr::new("--json"),
    ]);
    sender.join().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("is not SSL-Vision"), "{stderr}");
    let lines = json_lines(&out.stdout);
    assert!(lines.len() >= 30, "{} field frames: {stderr}", lines.len());
    let mut compared = 0;
    for line in &lines {
        assert!(
            truth.iter().any(|t| line_is(line, t)),
            "{line} is no frame of the game"
        );
        let models = line["world_models"].as_array().unwrap();
        compared += models.iter().filter(|m| m["matched"] == "marker").count();
    }
    assert!(compared >= 10, "{compared} world models matched by marker");
}

#[test]
fn a_port_in_use_is_said_clearly() {
    let taken = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let url = format!("udp://{}", taken.local_addr().unwrap());
    let out = eotn(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        OsStr::new(&url),
        OsStr::new("--robot"),
        fixture().stream.as_os_str(),
        OsStr::new("--seconds"),
        OsStr::new("1"),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("port in use"), "{stderr}");
}
