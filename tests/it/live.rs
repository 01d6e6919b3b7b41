//! Live robots on loopback: `eotn serve` to `eotn record` bit-exact; a robot killed mid-frame;
//! garbage and oversized messages; a sender that stops and comes back; the recorder killed;
//! four robots at 30 fps; the Python Foxglove SDK's own server as the sender.

use std::ffi::OsStr;
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use base64::Engine as _;
use eotn::frame::{Frame, Yuv};
use eotn::live::serve::StandInRobot;
use eotn::live::{ClientOptions, Limits, LiveRobot, RobotUrl};
use eotn::sensors::SensorReadings;
use eotn::streams::schema::{ImageEncoding, encode_image, raw_image_schema};
use eotn::streams::{FrameRecord, StreamReader};
use tungstenite::Message;

use crate::common::{eotn_ok, python_with_foxglove, sim_stream};

/// A small frame whose every byte depends on the frame number, so mix-ups show.
pub fn frame(i: usize) -> Frame {
    Frame::uyvy_from_fn(32, 24, |x, y| {
        Yuv::new(
            ((x * 7 + y * 3 + i * 11) % 220 + 16) as u8,
            ((x + i * 5) % 200 + 20) as u8,
            ((y * 2 + i) % 200 + 30) as u8,
        )
    })
    .unwrap()
}

pub fn record(i: usize) -> FrameRecord {
    let mut r = FrameRecord::new(1_000_000 + i as u64 * 33_333_333, frame(i));
    r.sensors = Some(SensorReadings {
        head_pan_rad: Some(0.01 * i as f64),
        ..SensorReadings::default()
    });
    r
}

/// Waits up to `secs` for `done`; false when it never came.
pub fn wait_for(secs: f64, mut done: impl FnMut() -> bool) -> bool {
    let until = Instant::now() + Duration::from_secs_f64(secs);
    while Instant::now() < until {
        if done() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    done()
}

fn url(port: u16) -> RobotUrl {
    format!("127.0.0.1:{port}").parse().unwrap()
}

fn fast_retry() -> ClientOptions {
    ClientOptions {
        backoff_min: Duration::from_millis(50),
        backoff_max: Duration::from_millis(200),
        ..ClientOptions::default()
    }
}

/// A hand-made Foxglove server speaking the protocol byte by byte: the handshake, `serverInfo`,
/// an image and a sensors channel; returns the socket and the image subscription id once the
/// client subscribed.
#[allow(
    clippy::result_large_err,
    reason = "tungstenite's handshake callback type"
)]
pub fn fake_robot_session(listener: &TcpListener) -> (tungstenite::WebSocket<TcpStream>, u32) {
    let (stream, _) = listener.accept().unwrap();
    stream.set_nodelay(true).unwrap();
    let mut ws = tungstenite::accept_hdr(
        stream,
        |req: &tungstenite::handshake::server::Request,
         mut resp: tungstenite::handshake::server::Response| {
            let offered = req
                .headers()
                .get("Sec-WebSocket-Protocol")
                .and_then(|v| v.to_str().ok())
                .unwrap_or_default()
                .to_owned();
            assert!(offered.contains("foxglove.sdk.v1"), "offered {offered}");
            resp.headers_mut()
                .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
            Ok(resp)
        },
    )
    .unwrap();
    let schema = raw_image_schema().unwrap();
    let schema = base64::engine::general_purpose::STANDARD.encode(&*schema.data);
    ws.send(Message::text(
        r#"{"op":"serverInfo","name":"fake","capabilities":[],"metadata":{}}"#,
    ))
    .unwrap();
    ws.send(Message::text(
        serde_json::json!({"op": "advertise", "channels": [
            {"id": 1, "topic": "/camera/image", "encoding": "protobuf",
             "schemaName": "foxglove.RawImage", "schema": schema, "schemaEncoding": "protobuf"},
            {"id": 2, "topic": "/sensors", "encoding": "json",
             "schemaName": "eotn.SensorReadings", "schema": "{}", "schemaEncoding": "jsonschema"}]})
        .to_string(),
    ))
    .unwrap();
    loop {
        if let Message::Text(t) = ws.read().unwrap() {
            let v: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
            if v["op"] == "subscribe" {
                let sub = v["subscriptions"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|s| s["channelId"] == 1)
                    .unwrap();
                return (ws, sub["id"].as_u64().unwrap() as u32);
            }
        }
    }
}

pub fn image_message(sub: u32, i: usize) -> Vec<u8> {
    let r = record(i);
    let mut payload = Vec::new();
    // The hand-made robot sends the cameras' own order; eotn serve sends yuyv.
    encode_image(r.time_ns, &r.frame, ImageEncoding::Uyvy, &mut payload).unwrap();
    eotn::live::protocol::encode_message_data(sub, r.time_ns, &payload)
}

#[test]
fn a_robot_killed_mid_frame_costs_that_frame_and_is_reconnected() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let dir = tempfile::tempdir().unwrap();
    let server = std::thread::spawn(move || {
        let (mut ws, sub) = fake_robot_session(&listener);
        for i in 0..3 {
            ws.send(Message::binary(image_message(sub, i))).unwrap();
        }
        // Frame 3 dies half-way: a binary frame header promising the whole message, then half.
        let msg = image_message(sub, 3);
        let mut raw = vec![0x82, 127];
        raw.extend_from_slice(&(msg.len() as u64).to_be_bytes());
        raw.extend_from_slice(&msg[..msg.len() / 2]);
        let mut stream = ws.into_inner();
        stream.write_all(&raw).unwrap();
        stream.flush().unwrap();
        drop(stream);
        let (mut ws, sub) = fake_robot_session(&listener);
        for i in 4..6 {
            ws.send(Message::binary(image_message(sub, i))).unwrap();
        }
        std::thread::sleep(Duration::from_millis(500));
    });
    let robot = LiveRobot::connect(url(port), fast_retry(), 1 << 20, None).unwrap();
    assert!(wait_for(5.0, || !robot.is_empty()), "no first frame");
    let out = dir.path().join("cut.mcap");
    robot.start_recording(&out).unwrap();
    assert!(
        wait_for(10.0, || robot.len() >= 5),
        "got {} frames",
        robot.len()
    );
    server.join().unwrap();
    let got: Vec<Frame> = (0..robot.len())
        .map(|i| robot.frame(i).unwrap().record.frame.clone())
        .collect();
    let want: Vec<Frame> = [0, 1, 2, 4, 5].iter().map(|&i| frame(i)).collect();
    assert_eq!(got, want, "frame 3 alone is lost");
    let log = robot.log().join("\n");
    assert!(
        log.contains("disconnected") && log.contains("reconnected"),
        "{log}"
    );
    assert_eq!(robot.stats().connections, 2);
    let (path, frames) = robot.stop_recording().unwrap().unwrap();
    let mut reader = StreamReader::open(&path).unwrap();
    assert_eq!(reader.len(), frames);
    assert_eq!(reader.read(frames - 1).unwrap().frame, frame(5));
}

#[test]
fn garbage_and_oversized_messages_close_only_their_own_robot() {
    let garbage = TcpListener::bind("127.0.0.1:0").unwrap();
    let big = TcpListener::bind("127.0.0.1:0").unwrap();
    let (gport, bport) = (
        garbage.local_addr().unwrap().port(),
        big.local_addr().unwrap().port(),
    );
    let done = Arc::new(AtomicBool::new(false));
    let g = std::thread::spawn({
        let done = Arc::clone(&done);
        move || {
            while !done.load(Ordering::Relaxed) {
                garbage.set_nonblocking(false).unwrap();
                let (mut ws, sub) = fake_robot_session(&garbage);
                let _ = ws.send(Message::text("{not json"));
                let _ = ws.send(Message::binary(vec![1, 2, 3]));
                let _ = ws.send(Message::binary(image_message(sub, 0)));
                std::thread::sleep(Duration::from_millis(100));
            }
        }
    });
    let b = std::thread::spawn(move || {
        let (mut ws, sub) = fake_robot_session(&big);
        let _ = ws.send(Message::binary(eotn::live::protocol::encode_message_data(
            sub,
            1,
            &vec![0_u8; 2 << 20],
        )));
        std::thread::sleep(Duration::from_millis(300));
    });
    let mut good = StandInRobot::start("good", "127.0.0.1", 0).unwrap();
    let small_limit = ClientOptions {
        limits: Limits {
            max_message_bytes: 1 << 20,
            ..Limits::default()
        },
        ..fast_retry()
    };
    let bad_text = LiveRobot::connect(url(gport), fast_retry(), 1 << 20, None).unwrap();
    let too_big = LiveRobot::connect(url(bport), small_limit, 1 << 20, None).unwrap();
    let ok = LiveRobot::connect(url(good.port()), fast_retry(), 1 << 20, None).unwrap();
    assert!(wait_for(5.0, || good.has_viewer()));
    for i in 0..30 {
        good.send(&record(i)).unwrap();
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(
        wait_for(5.0, || ok.len() == 30),
        "good robot got {}",
        ok.len()
    );
    assert!(wait_for(5.0, || bad_text
        .log()
        .join("\n")
        .contains("malformed message")));
    assert!(wait_for(5.0, || too_big
        .log()
        .join("\n")
        .contains("too large")));
    assert_eq!(
        bad_text.len(),
        0,
        "the garbage robot's later frame came after its garbage"
    );
    assert_eq!(ok.stats().drops, 0);
    done.store(true, Ordering::Relaxed);
    drop(bad_text);
    // Unblocks the garbage server's last accept.
    let _ = TcpStream::connect(("127.0.0.1", gport));
    drop(too_big);
    b.join().unwrap();
    let _ = g.join();
    good.stop();
}

#[test]
fn four_robots_at_30_fps_lose_no_frame_and_keep_up() {
    // Longer with EOTN_LIVE_SECONDS (scripts/live-soak.sh runs the workspace's version of this
    // test, tests/it/robots.rs, for a minute); a short run in the suite.
    let seconds: f64 = std::env::var("EOTN_LIVE_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2.0);
    let frames = (seconds * 30.0) as usize;
    let mut servers: Vec<StandInRobot> = (0..4)
        .map(|i| StandInRobot::start(&format!("r{i}"), "127.0.0.1", 0).unwrap())
        .collect();
    let robots: Vec<LiveRobot> = servers
        .iter()
        .map(|s| LiveRobot::connect(url(s.port()), fast_retry(), 256 << 20, None).unwrap())
        .collect();
    assert!(wait_for(5.0, || servers
        .iter()
        .all(StandInRobot::has_viewer)));
    let start = Instant::now();
    for n in 0..frames {
        let due = start + Duration::from_secs_f64(n as f64 / 30.0);
        std::thread::sleep(due.saturating_duration_since(Instant::now()));
        for s in &mut servers {
            s.send(&record(n)).unwrap();
        }
    }
    for r in &robots {
        assert!(
            // A frame's sensors follow its image by a moment: wait for the last one's too.
            wait_for(5.0, || r.len() == frames
                && r.latest().is_some_and(|f| f.record.sensors.is_some())),
            "{} of {frames}",
            r.len()
        );
        let stats = r.stats();
        assert_eq!(stats.drops, 0);
        for i in 0..frames {
            let f = r.frame(i).unwrap();
            assert_eq!(f.record.frame, frame(i), "frame {i}");
            assert!(f.record.sensors.is_some(), "frame {i} has its sensors");
            // Falling behind would show as a growing latency; a second is far beyond any jitter.
            assert!(
                f.latency_ns < 1_000_000_000,
                "frame {i}: {} ns",
                f.latency_ns
            );
        }
    }
    drop(robots);
    for s in servers {
        s.stop();
    }
}

/// `eotn serve` in the background; its port, read from its first line.
pub struct Served {
    child: Child,
    /// The port it listens on.
    pub port: u16,
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub fn serve(stream: &Path, listen: &str, extra: &[&str]) -> Served {
    let mut child = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .arg("serve")
        .arg(stream)
        .args(["--listen", listen])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let port = line
        .rsplit(':')
        .next()
        .and_then(|p| p.trim().parse().ok())
        .unwrap_or_else(|| panic!("no port in {line:?}"));
    Served { child, port }
}

/// Every image message's bytes in an MCAP file, in order, read with the `mcap` crate alone.
pub fn image_payloads(path: &Path) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/camera/image")
        .map(|m| m.data.to_vec())
        .collect()
}

#[test]
fn frames_from_eotn_serve_are_recorded_bit_exact_by_eotn_record() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 12, None);
    let served = serve(&stream, "127.0.0.1:0", &["--wait"]);
    let out = dir.path().join("rec.mcap");
    let address = format!("ws://127.0.0.1:{}", served.port);
    eotn_ok(&[
        OsStr::new("record"),
        OsStr::new(&address),
        OsStr::new("-o"),
        out.as_os_str(),
        OsStr::new("--frames"),
        OsStr::new("12"),
    ]);
    let mut source = StreamReader::open(&stream).unwrap();
    let mut recorded = StreamReader::open(&out).unwrap();
    assert_eq!(recorded.len(), 12);
    let payloads = image_payloads(&out);
    assert_eq!(payloads.len(), 12);
    for (i, payload) in payloads.iter().enumerate() {
        let s = source.read(i).unwrap();
        let r = recorded.read(i).unwrap();
        assert_eq!(r.frame, s.frame, "frame {i}");
        assert_eq!(
            r.sensors,
            s.sensors.map(|x| x.sanitised().0),
            "frame {i} sensors"
        );
        assert_eq!(r.extra, s.extra, "frame {i} extra channels");
        let mut sent = Vec::new();
        encode_image(s.time_ns, &s.frame, ImageEncoding::default(), &mut sent).unwrap();
        assert_eq!(
            *payload, sent,
            "frame {i}: the recorded bytes are the sent bytes"
        );
    }
}

pub fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

#[test]
fn a_sender_that_stops_and_comes_back_is_reconnected_and_a_killed_recorder_leaves_a_readable_file()
{
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 10, None);
    let port = free_port();
    let listen = format!("127.0.0.1:{port}");
    let first = serve(&stream, &listen, &["--loop"]);
    let out = dir.path().join("rec.mcap");
    let address = format!("127.0.0.1:{port}");
    let recorder = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .args(["record", &address, "--frames", "40", "-o"])
        .arg(&out)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(600));
    drop(first);
    std::thread::sleep(Duration::from_millis(400));
    let second = serve(&stream, &listen, &["--loop"]);
    let done = recorder.wait_with_output().unwrap();
    drop(second);
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert!(done.status.success(), "{stderr}");
    assert!(stderr.contains("reconnected"), "{stderr}");
    let mut recorded = StreamReader::open(&out).unwrap();
    assert_eq!(recorded.len(), 40);
    let mut source = StreamReader::open(&stream).unwrap();
    let frames: Vec<Frame> = (0..10).map(|i| source.read(i).unwrap().frame).collect();
    for i in 0..40 {
        assert!(
            frames.contains(&recorded.read(i).unwrap().frame),
            "frame {i} is a sent frame"
        );
    }

    // The recorder killed with SIGKILL: the .partial file reads to its last chunk.
    let served = serve(&stream, &listen, &["--loop"]);
    let killed = dir.path().join("killed.mcap");
    let mut recorder = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .args(["record", &address, "-o"])
        .arg(&killed)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1200));
    recorder.kill().unwrap();
    recorder.wait().unwrap();
    drop(served);
    let partial = dir.path().join("killed.mcap.partial");
    let mut reader = StreamReader::open(&partial).unwrap();
    assert!(reader.len() >= 10, "{} frames survived", reader.len());
    for i in 0..reader.len() {
        assert!(frames.contains(&reader.read(i).unwrap().frame), "frame {i}");
    }
}

#[test]
fn frames_from_the_python_foxglove_sdk_server_arrive_intact() {
    let Some(python) = python_with_foxglove() else {
        return;
    };
    let port = free_port();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/it/foxglove_sender.py");
    let mut sender = Command::new(&python)
        .arg(&script)
        .args(["--port", &port.to_string(), "--frames", "20"])
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let robot = LiveRobot::connect(url(port), fast_retry(), 1 << 24, None).unwrap();
    let got_all = wait_for(20.0, || robot.len() >= 20);
    let _ = sender.kill();
    let _ = sender.wait();
    assert!(
        got_all,
        "got {} frames; log: {:?}",
        robot.len(),
        robot.log()
    );
    assert!(robot.name().contains("python-robot"), "{}", robot.name());
    for i in 0..20 {
        let f = robot.frame(i).unwrap();
        let (w, h) = (f.record.frame.width(), f.record.frame.height());
        assert_eq!((w, h), (64, 48));
        // The sender's pattern: UYVY byte k of frame i is (k + 3 i) mod 256.
        let want: Vec<u8> = (0..w * h * 2).map(|k| ((k + 3 * i) % 256) as u8).collect();
        assert_eq!(f.record.frame.data(), &want[..], "frame {i}");
        let sensors = f.record.sensors.as_ref().expect("sensors attached");
        assert_eq!(sensors.head_pan_rad, Some(0.01 * i as f64));
    }
}
