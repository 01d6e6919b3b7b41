//! SSL-Vision packets out and in, on loopback only (issue 32): what `eotn overhead detect
//! --ssl-vision` sends, decoded by an independent reader (`ssl_vision.py`: a hand-written
//! protobuf wire decoder, standard library only), carries the positions `--json` prints; the log
//! that reader writes opens in eotn with every frame; an SSL log written from a simulated
//! stream's truth, as a file or sent live, scores that stream as its own truth does; bad packets,
//! bad logs and a port in use give clear lines.

use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use eotn::lut::learn::{LearnParams, TableBuilder};
use eotn::model::truth::{GroundTruth, OverheadTruth};
use eotn::sim::{Scenario, ScenarioKind, Simulator};
use eotn::ssl_vision::SslWrapperPacket;
use eotn::ssl_vision::log::{MessageType, write_header, write_message};
use eotn::ssl_vision::messages::{SslDetectionBall, SslDetectionFrame, SslDetectionRobot};
use prost::Message as _;

use crate::common::{eotn, eotn_ok, python_with, repo_file, shared_file, sim_stream};

/// An overhead table learnt from the simulator's labels of a few frames of another seed.
fn overhead_table(dir: &Path) -> PathBuf {
    let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, 99));
    let mut builder = TableBuilder::new(7).unwrap();
    for index in (0..240).step_by(60) {
        let f = sim.frame(index).unwrap();
        builder.add_frame(&f.frame, &f.labels).unwrap();
    }
    let path = dir.join("overhead.lut");
    builder.build(&LearnParams::default()).save(&path).unwrap();
    path
}

/// A calibration of the stream's camera from simulated clicks (`overhead sim-points`, then
/// `overhead calibrate`).
fn calibration(dir: &Path, stream: &Path) -> PathBuf {
    let points = dir.join("cam.points.json");
    let cal = dir.join("cam.json");
    eotn_ok(&[
        "overhead".as_ref(),
        "sim-points".as_ref(),
        "--stream".as_ref(),
        stream.as_os_str(),
        "-o".as_ref(),
        points.as_os_str(),
    ]);
    eotn_ok(&[
        "overhead".as_ref(),
        "calibrate".as_ref(),
        "--points".as_ref(),
        points.as_os_str(),
        "--accept".as_ref(),
        "-o".as_ref(),
        cal.as_os_str(),
    ]);
    cal
}

fn mm(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap() * 10.0
}

#[test]
fn packets_of_overhead_detect_carry_the_json_positions_and_their_log_opens_in_eotn() {
    let Some(python) = python_with("import struct, socket, json", "python3", "the SSL reader")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "overhead-game", 5, Some(4));
    let (table, cal) = (overhead_table(dir.path()), calibration(dir.path(), &stream));
    let (decoded, log) = (
        dir.path().join("decoded.json"),
        dir.path().join("received.log"),
    );
    let mut reader = Command::new(&python)
        .arg(repo_file("tests/it/ssl_vision.py"))
        .args(["receive".as_ref(), decoded.as_os_str(), log.as_os_str()])
        .args(["5", "30"])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut port = String::new();
    BufReader::new(reader.stdout.take().unwrap())
        .read_line(&mut port)
        .unwrap();
    let target = format!("127.0.0.1:{}", port.trim());
    let out = eotn_ok(&[
        "overhead".as_ref(),
        "detect".as_ref(),
        stream.as_os_str(),
        "--lut".as_ref(),
        table.as_os_str(),
        "--calibration".as_ref(),
        cal.as_os_str(),
        "--json".as_ref(),
        "--ssl-vision".as_ref(),
        target.as_ref(),
        "--ssl-camera-id".as_ref(),
        "3".as_ref(),
    ]);
    assert!(reader.wait().unwrap().success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("camera 3: distortion κ =") && stderr.contains("residual RMS"),
        "{stderr}"
    );
    assert!(
        stderr.contains("5 detection and 1 geometry packets"),
        "{stderr}"
    );
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let got: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&decoded).unwrap()).unwrap();
    let frames = got["detections"].as_array().unwrap();
    assert_eq!(frames.len(), lines.len());
    let mut robots_compared = 0;
    for (k, (f, line)) in frames.iter().zip(&lines).enumerate() {
        assert_eq!(f["camera_id"], 3);
        assert_eq!(f["frame_number"], k);
        match (&line["ball"], f.get("balls")) {
            (serde_json::Value::Null, None) => {}
            (b, Some(balls)) => {
                let sent = &balls[0];
                assert!(
                    (sent["x"].as_f64().unwrap() - mm(b, "x_cm")).abs() <= 1.0,
                    "{k}"
                );
                assert!(
                    (sent["y"].as_f64().unwrap() - mm(b, "y_cm")).abs() <= 1.0,
                    "{k}"
                );
            }
            (b, None) => panic!("frame {k}: ball {b} not sent"),
        }
        let mut sent: BTreeMap<(String, u64), &serde_json::Value> = BTreeMap::new();
        for (team, key) in [("blue", "robots_blue"), ("yellow", "robots_yellow")] {
            for r in f.get(key).and_then(|v| v.as_array()).into_iter().flatten() {
                sent.insert((team.to_owned(), r["robot_id"].as_u64().unwrap()), r);
            }
        }
        let printed = line["robots"].as_array().unwrap();
        assert_eq!(sent.len(), printed.len(), "frame {k}");
        for r in printed {
            let key = (
                r["team"].as_str().unwrap().to_owned(),
                r["id"].as_u64().unwrap(),
            );
            let s = sent[&key];
            assert!((s["x"].as_f64().unwrap() - mm(r, "x_cm")).abs() <= 1.0);
            assert!((s["y"].as_f64().unwrap() - mm(r, "y_cm")).abs() <= 1.0);
            let heading = r["heading_rad"].as_f64().unwrap();
            assert!((s["orientation"].as_f64().unwrap() - heading).abs() < 1e-4);
            robots_compared += 1;
        }
    }
    assert!(robots_compared >= 10, "{robots_compared} robots compared");
    let geometry = &got["geometry"][0];
    assert_eq!(geometry["calib"][0]["camera_id"], 3);
    assert!(geometry["field"]["field_length"].as_i64().unwrap() > 5000);
    // The reader's log, with a referee and a blank message among the packets, opens in eotn
    // with every frame.
    let mut w = eotn::workspace::Workspace::default();
    w.apply(eotn::workspace::Command::Open(vec![log])).unwrap();
    let feed = w.ssl_vision().unwrap();
    assert_eq!(feed.frames(), lines.len(), "{}", feed.summary);
    assert!(feed.summary.contains("1 referee") && feed.summary.contains("1 blank"));
    assert!(feed.field().is_some(), "the geometry's field");
}

/// The truth of each frame of `stream` as SSL-Vision packets (camera 0, every robot with a
/// marker, the ball).
pub fn truth_packets(stream: &Path) -> Vec<(i64, Vec<u8>)> {
    let mut reader = eotn::streams::StreamReader::open(stream).unwrap();
    (0..reader.len())
        .map(|i| {
            let record = reader.read(i).unwrap();
            let GroundTruth::Overhead(t) =
                serde_json::from_value::<GroundTruth>(record.ground_truth.unwrap()).unwrap()
            else {
                panic!("overhead truth expected");
            };
            let t: &OverheadTruth = &t;
            let robot = |r: &eotn::model::truth::OverheadRobot| {
                let m = r.marker.unwrap();
                (
                    m.team,
                    SslDetectionRobot {
                        confidence: 1.0,
                        robot_id: Some(u32::from(m.identity.value())),
                        x: (r.field_cm[0] * 10.0) as f32,
                        y: (r.field_cm[1] * 10.0) as f32,
                        orientation: Some(r.heading_rad as f32),
                        ..SslDetectionRobot::default()
                    },
                )
            };
            let robots: Vec<_> = t
                .robots
                .iter()
                .filter(|r| r.marker.is_some())
                .map(robot)
                .collect();
            let of = |team| {
                robots
                    .iter()
                    .filter(|(t, _)| *t == team)
                    .map(|(_, r)| r.clone())
                    .collect()
            };
            let frame = SslDetectionFrame {
                frame_number: u32::try_from(i).unwrap(),
                t_capture: record.time_ns as f64 * 1e-9,
                camera_id: 0,
                balls: t
                    .ball
                    .iter()
                    .map(|b| SslDetectionBall {
                        confidence: 1.0,
                        x: (b.field_cm[0] * 10.0) as f32,
                        y: (b.field_cm[1] * 10.0) as f32,
                        ..SslDetectionBall::default()
                    })
                    .collect(),
                robots_blue: of(eotn::geometry::MarkerTeam::Blue),
                robots_yellow: of(eotn::geometry::MarkerTeam::Yellow),
                ..SslDetectionFrame::default()
            };
            let packet = SslWrapperPacket {
                detection: Some(frame),
                geometry: None,
            };
            (
                i64::try_from(record.time_ns).unwrap(),
                packet.encode_to_vec(),
            )
        })
        .collect()
}

fn eval_json(args: &[&OsStr]) -> serde_json::Value {
    let out = eotn_ok(args);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn an_ssl_log_of_a_streams_truth_scores_it_as_the_truth_does_from_a_file_and_live() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "overhead-game", 5, Some(4));
    let table = overhead_table(dir.path());
    let packets = truth_packets(&stream);
    let log = dir.path().join("truth.log");
    let mut bytes = Vec::new();
    write_header(&mut bytes);
    for (t, p) in &packets {
        write_message(&mut bytes, *t, MessageType::Vision2014, p);
        write_message(&mut bytes, *t, MessageType::Refbox2013, &[]);
    }
    std::fs::write(&log, bytes).unwrap();
    let base: [&OsStr; 5] = [
        "eval".as_ref(),
        stream.as_os_str(),
        "--lut".as_ref(),
        table.as_os_str(),
        "--json".as_ref(),
    ];
    let own = eval_json(&base);
    let with_log = eval_json(&[&base[..], &["--truth-ssl".as_ref(), log.as_os_str()]].concat());
    assert_eq!(with_log["truth"], format!("SSL-Vision {}", log.display()));
    let (a, b) = (&own["overhead"], &with_log["overhead"]);
    assert_eq!(a["frames"], b["frames"]);
    assert!(a["robots_found"].as_u64().unwrap() >= 10, "{a}");
    for key in [
        "robots_found",
        "robots_eligible",
        "identity_right",
        "robots_false",
        "ball_found",
        "ball_false",
    ] {
        assert_eq!(a[key], b[key], "{key}: truth {a} ssl {b}");
    }
    for key in ["ball_error_cm", "robot_error_cm", "heading_error_deg"] {
        for p in ["p50", "p90", "p95"] {
            let (x, y) = (a[key][p].as_f64(), b[key][p].as_f64());
            assert!(
                x.zip(y).is_some_and(|(x, y)| (x - y).abs() < 0.01),
                "{key} {p}: truth {x:?} ssl {y:?}"
            );
        }
    }
    // Opened beside the stream, the log shows the frame of the shown frame's time; stepping the
    // stream steps the log's frame with it.
    let mut w = eotn::workspace::Workspace::default();
    let open = eotn::workspace::Command::Open(vec![stream.clone(), log.clone()]);
    w.apply(open).unwrap();
    let shown = |w: &eotn::workspace::Workspace| {
        let ssl = w.overhead().field_model.ssl();
        assert_eq!(ssl.len(), 1, "one camera");
        ssl[0].frame_number
    };
    assert_eq!(shown(&w), 0);
    w.apply(eotn::workspace::PlaybackCommand::Seek(3).into())
        .unwrap();
    assert_eq!(shown(&w), 3);
    // The same packets live over loopback, with a packet that is not SSL-Vision among them.
    let probe = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let port = probe.local_addr().unwrap().port();
    drop(probe);
    let sender = std::thread::spawn(move || {
        let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
        std::thread::sleep(std::time::Duration::from_millis(1500));
        socket
            .send_to(&[0xff, 0xff, 0x07], ("127.0.0.1", port))
            .unwrap();
        for (_, p) in &packets {
            socket.send_to(p, ("127.0.0.1", port)).unwrap();
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    });
    let url = format!("udp://127.0.0.1:{port}");
    let out = eotn_ok(&[&base[..], &["--truth-ssl".as_ref(), url.as_ref()]].concat());
    sender.join().unwrap();
    let live: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(live["overhead"]["robot_error_cm"], b["robot_error_cm"]);
    assert_eq!(live["overhead"]["robots_found"], b["robots_found"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("is not SSL-Vision"), "{stderr}");
    assert!(stderr.contains("5 detection frames received"), "{stderr}");
}

#[test]
fn bad_logs_and_a_port_in_use_are_said_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let stream = repo_file("streams/sim-overhead-game.mcap");
    let lut = repo_file("lookup_tables/sim.lut");
    let eval = |truth: &OsStr| {
        let out = eotn(&[
            "eval".as_ref(),
            stream.as_os_str(),
            "--lut".as_ref(),
            lut.as_os_str(),
            "--truth-ssl".as_ref(),
            truth,
        ]);
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let taken = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let url = format!("udp://{}", taken.local_addr().unwrap());
    let said = eval(url.as_ref());
    assert!(said.contains("port in use"), "{said}");
    let garbage = dir.path().join("garbage.log");
    std::fs::write(&garbage, b"not a log at all").unwrap();
    let said = eval(garbage.as_os_str());
    assert!(said.contains("not an SSL-Vision log"), "{said}");
    let v2 = dir.path().join("v2.log");
    std::fs::write(
        &v2,
        [b"SSL_LOG_FILE".as_slice(), &2i32.to_be_bytes()].concat(),
    )
    .unwrap();
    let said = eval(v2.as_os_str());
    assert!(said.contains("version 2"), "{said}");
    let empty = dir.path().join("empty.log");
    let mut bytes = Vec::new();
    write_header(&mut bytes);
    write_message(&mut bytes, 0, MessageType::Vision2014, &[0xff, 0xff]);
    std::fs::write(&empty, bytes).unwrap();
    let said = eval(empty.as_os_str());
    assert!(said.contains("1 vision packets did not decode"), "{said}");
    if let Some(bhuman) = shared_file("data/bhuman2009/logfile.log") {
        let said = eval(bhuman.as_os_str());
        assert!(said.contains("eotn import --bhuman"), "{said}");
    }
}

/// A log of two cameras' frames at three instants, shown alone in the app's field view.
#[cfg(feature = "gui")]
#[test]
fn the_field_view_marks_each_cameras_detections_of_a_log_opened_alone() {
    use egui_kittest::kittest::Queryable as _;
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("game.log");
    let mut bytes = Vec::new();
    write_header(&mut bytes);
    for k in 0..3u32 {
        for camera_id in [0, 1] {
            let frame = SslDetectionFrame {
                frame_number: k,
                t_capture: 50.0 + f64::from(k) / 60.0 + f64::from(camera_id) * 0.003,
                camera_id,
                robots_blue: vec![SslDetectionRobot {
                    confidence: 0.9,
                    robot_id: Some(camera_id + 2),
                    x: 1000.0 * camera_id as f32,
                    orientation: Some(0.5),
                    ..SslDetectionRobot::default()
                }],
                ..SslDetectionFrame::default()
            };
            let packet = SslWrapperPacket {
                detection: Some(frame),
                geometry: None,
            };
            write_message(
                &mut bytes,
                0,
                MessageType::Vision2014,
                &packet.encode_to_vec(),
            );
        }
    }
    std::fs::write(&log, bytes).unwrap();
    let mut w = eotn::workspace::Workspace::default();
    w.apply(eotn::workspace::Command::Open(vec![log])).unwrap();
    let mut h = crate::harness::harness_with(w);
    h.run();
    h.run();
    assert!(h.query_by_label("field drawing").is_some());
    for camera in ["camera 0", "camera 1"] {
        assert!(h.query_by_label(camera).is_some(), "{camera}");
    }
    assert!(h.query_all_by_label_contains("ssl-vision step").count() > 0);
    assert_eq!(h.state().state.ssl_vision().unwrap().steps(), (6, 0));
}

/// Every SSL-Vision packet that arrives at `receiver` within `wait` of the last.
fn received(receiver: &std::net::UdpSocket, wait: std::time::Duration) -> Vec<SslWrapperPacket> {
    receiver.set_read_timeout(Some(wait)).unwrap();
    let mut buf = vec![0u8; 65_536];
    let mut out = Vec::new();
    while let Ok(n) = receiver.recv(&mut buf) {
        out.push(eotn::ssl_vision::decode_packet(&buf[..n]).unwrap());
    }
    out
}

/// The app's workspace sends what it shows: with the bundled overhead stream open and an SSL
/// output to a loopback receiver, each frame shown goes out as a detection frame of camera 0
/// (after the geometry with the camera's calibration) carrying the ball and robots the
/// workspace shows, within 1 mm, at the frame's time; stopping stops it; a bad address is
/// refused and nothing is sent.
#[test]
fn the_workspace_sends_the_overhead_detections_it_shows() {
    use eotn::workspace::{Command, OverheadCommand, PlaybackCommand, Workspace};
    let receiver = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let address = receiver.local_addr().unwrap().to_string();
    let mut w = Workspace::default();
    let stream = repo_file("streams/sim-overhead-game.mcap");
    w.apply(Command::Open(vec![stream.clone()])).unwrap();
    let refused = w.apply(OverheadCommand::SendSslVision(Some("nowhere".into())).into());
    assert!(refused.is_err_and(|e| e.to_string().contains("HOST:PORT")));
    assert!(w.ssl_out_status().is_none());
    w.apply(OverheadCommand::SendSslVision(Some(address.clone())).into())
        .unwrap();
    let mut reader = eotn::streams::StreamReader::open(&stream).unwrap();
    let wait = std::time::Duration::from_millis(300);
    let mut robots_compared = 0;
    let frames = reader.len();
    assert!(frames >= 4, "{frames} frames");
    for k in 0..frames {
        if k > 0 {
            w.apply(PlaybackCommand::Seek(k).into()).unwrap();
        }
        let packets = received(&receiver, wait);
        if k == 0 {
            let g = packets[0].geometry.as_ref().expect("the geometry first");
            assert_eq!(g.calib.len(), 1, "the calibration in use");
            assert_eq!(g.calib[0].camera_id, 0);
        }
        let frame = packets
            .iter()
            .rev()
            .find_map(|p| p.detection.as_ref())
            .unwrap_or_else(|| panic!("frame {k}: no detection frame"));
        let sent = eotn::ssl_vision::CameraFrame::from_message(frame);
        assert_eq!(sent.camera_id, 0);
        let time_ns = reader.read(k).unwrap().time_ns;
        assert!((sent.t_capture_s - time_ns as f64 * 1e-9).abs() < 1e-6);
        let shown = w
            .overhead_detections()
            .expect("a calibration in use")
            .clone();
        match (shown.ball, sent.balls.first()) {
            (None, None) => {}
            (Some(b), Some(s)) => {
                assert!((b.field_cm[0] - s.field_cm[0]).abs() <= 0.1);
                assert!((b.field_cm[1] - s.field_cm[1]).abs() <= 0.1);
            }
            other => panic!("frame {k}: ball {other:?}"),
        }
        assert_eq!(shown.robots.len(), sent.robots.len(), "frame {k}");
        for r in &shown.robots {
            let s = sent
                .robots
                .iter()
                .find(|s| s.team == r.team && s.robot_id == Some(u32::from(r.identity.value())))
                .unwrap_or_else(|| panic!("frame {k}: robot {r:?} not sent"));
            assert!((r.field_cm[0] - s.field_cm[0]).abs() <= 0.1);
            assert!((r.field_cm[1] - s.field_cm[1]).abs() <= 0.1);
            assert!((r.heading_rad - s.heading_rad.unwrap()).abs() < 1e-4);
            robots_compared += 1;
        }
    }
    assert!(
        robots_compared >= 2 * frames,
        "{robots_compared} robots compared"
    );
    let status = w.ssl_out_status().unwrap();
    assert_eq!(status.address, address);
    assert!(status.detection_packets >= frames as u64, "{status:?}");
    assert_eq!(status.failures, 0);
    assert!(
        status.fits[0].contains("camera 0: distortion κ"),
        "{status:?}"
    );
    w.apply(OverheadCommand::SendSslVision(None).into())
        .unwrap();
    assert!(w.ssl_out_status().is_none());
    w.apply(PlaybackCommand::Seek(1).into()).unwrap();
    assert!(received(&receiver, wait).is_empty(), "stopped");
}
