//! Robots that misbehave, on loopback: one that never speaks, one that handshakes a byte at a
//! time, one that never sends `serverInfo`, one that advertises channels without end, one with
//! names hundreds of bytes long, one that advertises a channel again with another encoding; and
//! `eotn record` stopped by SIGTERM / Ctrl+C. Each against `eotn record`, the client, or the
//! workspace the app draws. Every peer is a hand-made server on its own threads, ended when the
//! test drops it; every wait is bounded.

use std::collections::HashMap;
use std::ffi::OsStr;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use base64::Engine as _;
use eotn::live::{ClientOptions, Connection, Limits, LiveRobot};
use eotn::streams::StreamReader;
use eotn::streams::schema::raw_image_schema;
use eotn::workspace::{Command as WsCommand, Workspace};
use tungstenite::{Message, WebSocket};

use crate::common::{eotn, sim_stream};
use crate::live::{image_message, serve, wait_for};

/// A hand-made server on a loopback port: `serve_one` runs for each connection on a thread of
/// its own, with a flag that says the test is over.
pub struct Peer {
    /// Its port.
    pub port: u16,
    done: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Peer {
    pub fn start(serve_one: impl Fn(TcpStream, &AtomicBool) + Send + Sync + 'static) -> Self {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        listener.set_nonblocking(true).unwrap();
        let port = listener.local_addr().unwrap().port();
        let done = Arc::new(AtomicBool::new(false));
        let serve_one = Arc::new(serve_one);
        let thread = std::thread::spawn({
            let done = Arc::clone(&done);
            move || {
                while !done.load(Ordering::Relaxed) {
                    match listener.accept() {
                        Ok((stream, _)) => {
                            stream.set_nonblocking(false).unwrap();
                            stream.set_nodelay(true).unwrap();
                            let (serve_one, done) = (Arc::clone(&serve_one), Arc::clone(&done));
                            std::thread::spawn(move || serve_one(stream, &done));
                        }
                        Err(_) => std::thread::sleep(Duration::from_millis(5)),
                    }
                }
            }
        });
        Self {
            port,
            done,
            thread: Some(thread),
        }
    }

    pub fn address(&self) -> String {
        format!("127.0.0.1:{}", self.port)
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        self.done.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Holds the connection until the test ends, saying nothing.
fn silent(stream: TcpStream, done: &AtomicBool) {
    while !done.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(20));
    }
    drop(stream);
}

/// Reads the client's request, then answers the handshake one byte every 100 ms (it would take
/// about 15 s).
fn slow_handshake(mut stream: TcpStream, done: &AtomicBool) {
    stream
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    let mut request = Vec::new();
    let mut buf = [0_u8; 1024];
    while !request.ends_with(b"\r\n\r\n") && !done.load(Ordering::Relaxed) {
        match stream.read(&mut buf) {
            Ok(0) => return,
            Ok(n) => request.extend_from_slice(&buf[..n]),
            Err(_) => {}
        }
    }
    let response = b"HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: xxxxxxxxxxxxxxxxxxxxxxxxxxxx\r\nSec-WebSocket-Protocol: foxglove.sdk.v1\r\n\r\n";
    for byte in response {
        if done.load(Ordering::Relaxed) || stream.write_all(&[*byte]).is_err() {
            return;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The server side of the WebSocket handshake, answering with the Foxglove subprotocol.
#[allow(
    clippy::result_large_err,
    reason = "tungstenite's handshake callback type"
)]
pub fn handshake(stream: TcpStream) -> WebSocket<TcpStream> {
    tungstenite::accept_hdr(
        stream,
        |_: &tungstenite::handshake::server::Request,
         mut resp: tungstenite::handshake::server::Response| {
            resp.headers_mut()
                .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
            Ok(resp)
        },
    )
    .unwrap()
}

/// Handshakes, then never sends `serverInfo`.
fn no_server_info(stream: TcpStream, done: &AtomicBool) {
    let ws = handshake(stream);
    silent(ws.into_inner(), done);
}

/// The `advertise` entry of the camera image channel `id`.
fn image_channel(id: u32) -> serde_json::Value {
    let schema = raw_image_schema().unwrap();
    let schema = base64::engine::general_purpose::STANDARD.encode(&*schema.data);
    serde_json::json!({"id": id, "topic": "/camera/image", "encoding": "protobuf",
        "schemaName": "foxglove.RawImage", "schema": schema, "schemaEncoding": "protobuf"})
}

/// A JSON channel's `advertise` entry.
fn json_channel(id: u32, topic: &str, schema_name: &str) -> serde_json::Value {
    serde_json::json!({"id": id, "topic": topic, "encoding": "json", "schemaName": schema_name,
        "schema": "{}", "schemaEncoding": "jsonschema"})
}

fn send_json(ws: &mut WebSocket<TcpStream>, value: &serde_json::Value) -> bool {
    ws.send(Message::text(value.to_string())).is_ok()
}

/// Reads until the client has subscribed to every one of `channels` (at most 5 s): their
/// subscription ids, in order.
fn subscriptions(ws: &mut WebSocket<TcpStream>, channels: &[u32]) -> Option<Vec<u32>> {
    let _ = ws
        .get_ref()
        .set_read_timeout(Some(Duration::from_millis(50)));
    let mut found = HashMap::new();
    let until = Instant::now() + Duration::from_secs(5);
    while Instant::now() < until && found.len() < channels.len() {
        let text = match ws.read() {
            Ok(Message::Text(t)) => t,
            Ok(_) => continue,
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                continue;
            }
            Err(_) => return None,
        };
        let v: serde_json::Value = serde_json::from_str(text.as_str()).ok()?;
        if v["op"] != "subscribe" {
            continue;
        }
        for s in v["subscriptions"].as_array()? {
            let (Some(channel), Some(id)) = (s["channelId"].as_u64(), s["id"].as_u64()) else {
                continue;
            };
            if channels.contains(&(channel as u32)) {
                found.insert(channel as u32, id as u32);
            }
        }
    }
    channels.iter().map(|c| found.get(c).copied()).collect()
}

/// Reads until the client subscribes to `channel`: its subscription id.
fn subscription_of(ws: &mut WebSocket<TcpStream>, channel: u32) -> Option<u32> {
    subscriptions(ws, &[channel]).map(|ids| ids[0])
}

/// One message on subscription `sub`.
fn data(sub: u32, time_ns: u64, payload: &[u8]) -> Message {
    Message::binary(eotn::live::protocol::encode_message_data(
        sub, time_ns, payload,
    ))
}

fn fast(limits: Limits) -> ClientOptions {
    ClientOptions {
        limits,
        backoff_min: Duration::from_millis(50),
        backoff_max: Duration::from_millis(200),
    }
}

#[test]
fn a_silent_or_slow_peer_gives_a_deadline_line_and_cannot_hold_record_past_its_seconds() {
    let silent = Peer::start(silent);
    let slow = Peer::start(slow_handshake);
    let mute = Peer::start(no_server_info);
    let limits = Limits {
        handshake_timeout: Duration::from_millis(400),
        first_message_timeout: Duration::from_millis(400),
        ..Limits::default()
    };
    let robots: Vec<LiveRobot> = [&silent, &slow, &mute]
        .iter()
        .map(|p| {
            LiveRobot::connect(
                p.address().parse().unwrap(),
                fast(limits.clone()),
                1 << 20,
                None,
            )
            .unwrap()
        })
        .collect();
    let expected = [
        "no WebSocket handshake within 0.4 s",
        "no WebSocket handshake within 0.4 s",
        "no serverInfo within 0.4 s",
    ];
    for (robot, want) in robots.iter().zip(expected) {
        assert!(
            wait_for(5.0, || robot
                .stats()
                .problem
                .is_some_and(|p| p.contains(want))),
            "{want}: {:?} {:?}",
            robot.connection(),
            robot.stats().problem
        );
        assert!(matches!(
            robot.connection(),
            Connection::Disconnected { .. } | Connection::Connecting
        ));
    }
    // Dropping a robot stuck in a handshake does not wait on it.
    let t = Instant::now();
    drop(robots);
    assert!(
        t.elapsed() < Duration::from_millis(200),
        "{:?}",
        t.elapsed()
    );

    // `record --seconds 1` ends on time against all three, and says nothing was recorded.
    let dir = tempfile::tempdir().unwrap();
    let t = Instant::now();
    let out = eotn(&[
        OsStr::new("record"),
        OsStr::new(&silent.address()),
        OsStr::new(&slow.address()),
        OsStr::new(&mute.address()),
        OsStr::new("-o"),
        dir.path().as_os_str(),
        OsStr::new("--seconds"),
        OsStr::new("1"),
    ]);
    let took = t.elapsed();
    eprintln!("record --seconds 1 against three stuck robots took {took:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("nothing was recorded"), "{err}");
    // One second, then at most half a second to stop them; measured 1.06–1.09 s.
    assert!(took < Duration::from_secs(3), "record took {took:?}: {err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "no file");
}

#[test]
fn disconnecting_a_robot_stuck_in_a_slow_handshake_is_immediate_and_ticks_never_wait() {
    let slow = Peer::start(slow_handshake);
    let mut w = Workspace::default();
    w.apply(WsCommand::from(
        eotn::workspace::RobotsCommand::ConnectRobot(slow.address()),
    ))
    .unwrap();
    let id = w.robots()[0].id;
    let mut longest = Duration::ZERO;
    let until = Instant::now() + Duration::from_millis(800);
    while Instant::now() < until {
        let t = Instant::now();
        w.tick(Duration::from_millis(16));
        let _ = w.robots();
        longest = longest.max(t.elapsed());
        std::thread::sleep(Duration::from_millis(16));
    }
    eprintln!("longest tick beside a robot stuck in its handshake: {longest:?}");
    // A tick reads the robots' state and never waits on their sockets (measured 0.04–0.1 ms).
    assert!(
        longest < Duration::from_millis(250),
        "a tick took {longest:?}"
    );
    let t = Instant::now();
    w.apply(WsCommand::from(
        eotn::workspace::RobotsCommand::DisconnectRobot(id),
    ))
    .unwrap();
    let took = t.elapsed();
    eprintln!("Disconnect took {took:?}");
    // Measured 26 µs.
    assert!(
        took < Duration::from_millis(250),
        "Disconnect took {took:?}"
    );
    assert!(w.robots().is_empty());
}

/// An endless advertiser: the image channel and frames, and between frames, advertisements
/// without end: lists of 2000 channels at a time (withdrawn again), and one new channel after
/// another, each sent a message and withdrawn.
fn endless_advertiser(stream: TcpStream, done: &AtomicBool) {
    let mut ws = handshake(stream);
    let info = serde_json::json!({"op": "serverInfo", "name": "endless", "capabilities": []});
    let advertise = serde_json::json!({"op": "advertise", "channels": [image_channel(1)]});
    if !send_json(&mut ws, &info) || !send_json(&mut ws, &advertise) {
        return;
    }
    let Some(image_sub) = subscription_of(&mut ws, 1) else {
        return;
    };
    let schema = "x".repeat(200);
    let big: Vec<serde_json::Value> = (0..2000)
        .map(|i| json_channel(1_000_000 + i, &format!("/flood/{i}"), &schema))
        .collect();
    let big = serde_json::json!({"op": "advertise", "channels": big});
    let withdraw_big = serde_json::json!({"op": "unadvertise", "channelIds": (1_000_000..1_002_000).collect::<Vec<u32>>()});
    let mut frame = 0;
    for n in 10_u32.. {
        if done.load(Ordering::Relaxed) {
            return;
        }
        if n % 20 == 0 {
            let ok = send_json(&mut ws, &big) && send_json(&mut ws, &withdraw_big);
            let ok = ok
                && ws
                    .send(Message::binary(image_message(image_sub, frame)))
                    .is_ok();
            frame += 1;
            if !ok {
                return;
            }
        }
        let advertise = serde_json::json!({"op": "advertise",
            "channels": [json_channel(n, &format!("/endless/{n}"), "e")]});
        if !send_json(&mut ws, &advertise) {
            return;
        }
        if let Some(sub) = subscription_of(&mut ws, n)
            && ws.send(data(sub, 1, b"{}")).is_err()
        {
            return;
        }
        let withdraw = serde_json::json!({"op": "unadvertise", "channelIds": [n]});
        if !send_json(&mut ws, &withdraw) {
            return;
        }
    }
}

/// Peak resident memory of process `pid` so far, kB (`VmHWM`).
pub fn peak_rss_kb(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()
}

#[test]
fn an_endless_advertiser_costs_record_bounded_memory_and_recording_goes_on() {
    let peer = Peer::start(endless_advertiser);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("endless.mcap");
    let child = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .args(["record", &peer.address(), "--seconds", "4", "-o"])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (pid, start) = (child.id(), Instant::now());
    let mut peak_kb = 0;
    while let Some(kb) = peak_rss_kb(pid) {
        peak_kb = kb;
        std::thread::sleep(Duration::from_millis(100));
        if start.elapsed() > Duration::from_secs(10) {
            break;
        }
    }
    let done = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&done.stderr);
    eprintln!("record's peak resident memory against the endless advertiser: {peak_kb} kB");
    assert!(done.status.success(), "{err}");
    assert!(err.contains("more than 256 channels advertised"), "{err}");
    assert!(err.contains("the recording holds 256 channels"), "{err}");
    // Before the limits this grew by about 120 MB a second; measured about 30 MB now.
    assert!(peak_kb < 150_000, "record peaked at {peak_kb} kB");
    let bytes = std::fs::read(&out).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert!(
        summary.channels.len() <= 256 + 2,
        "{} channels in the file",
        summary.channels.len()
    );
    let frames = StreamReader::open(&out).unwrap().len();
    assert!(frames >= 1, "frames kept coming through: {frames}");
}

/// A robot whose name is 300 bytes long, with a channel whose topic is too, beside a normal
/// JSON channel; then frames with a message on the normal channel each.
fn long_names(stream: TcpStream, done: &AtomicBool) {
    let mut ws = handshake(stream);
    let info = serde_json::json!({"op": "serverInfo", "name": "R".repeat(300), "capabilities": []});
    let advertise = serde_json::json!({"op": "advertise", "channels": [
        image_channel(1), json_channel(2, &format!("/{}", "x".repeat(300)), "long"),
        json_channel(3, "/ok", "ok")]});
    if !send_json(&mut ws, &info) || !send_json(&mut ws, &advertise) {
        return;
    }
    let Some([image, ok]) = subscriptions(&mut ws, &[1, 3]).map(|ids| [ids[0], ids[1]]) else {
        return;
    };
    for i in 0.. {
        let sent = ws.send(Message::binary(image_message(image, i))).is_ok()
            && ws.send(data(ok, 5, br#"{"i":1}"#)).is_ok();
        if !sent || done.load(Ordering::Relaxed) {
            return;
        }
        std::thread::sleep(Duration::from_millis(30));
    }
}

/// Every channel's topic and message encoding in an MCAP file with its message count.
fn channel_counts(path: &Path) -> HashMap<(String, String), usize> {
    let bytes = std::fs::read(path).unwrap();
    let mut counts = HashMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        *counts
            .entry((m.channel.topic.clone(), m.channel.message_encoding.clone()))
            .or_insert(0) += 1;
    }
    counts
}

#[test]
fn a_robot_with_300_byte_names_is_recorded_beside_another_without_its_long_channel() {
    let peer = Peer::start(long_names);
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 10, None);
    let served = serve(&stream, "127.0.0.1:0", &["--loop"]);
    let folder = dir.path().join("out");
    let out = eotn(&[
        OsStr::new("record"),
        OsStr::new(&peer.address()),
        OsStr::new(&format!("127.0.0.1:{}", served.port)),
        OsStr::new("-o"),
        folder.as_os_str(),
        OsStr::new("--frames"),
        OsStr::new("5"),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("name is 300 bytes long: cut to 255"), "{err}");
    assert!(err.contains("a name of 301 bytes"), "{err}");
    let files: Vec<_> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 2, "{files:?}");
    let long = files
        .iter()
        .find(|p| p.file_name().unwrap().to_string_lossy().starts_with("RRR"))
        .unwrap();
    assert!(long.file_name().unwrap().len() <= 100 + ".mcap".len());
    let counts = channel_counts(long);
    assert!(
        counts.contains_key(&("/ok".to_owned(), "json".to_owned())),
        "{counts:?}"
    );
    assert!(
        counts.keys().all(|(topic, _)| topic.len() < 300),
        "{counts:?}"
    );
    assert_eq!(StreamReader::open(long).unwrap().len(), 5);
}

/// `/odometry` as JSON, then advertised again under the same id as CDR (no unadvertise), then
/// withdrawn and advertised as JSON again; messages on each, between frames.
fn readvertiser(stream: TcpStream, _: &AtomicBool) {
    let mut ws = handshake(stream);
    let info = serde_json::json!({"op": "serverInfo", "name": "readvertiser", "capabilities": []});
    let json = json_channel(2, "/odometry", "a.Odom");
    let cdr = serde_json::json!({"id": 2, "topic": "/odometry", "encoding": "cdr",
        "schemaName": "b.Odom", "schema": "float64 x", "schemaEncoding": "ros2msg"});
    let advertise = |c: &serde_json::Value| serde_json::json!({"op": "advertise", "channels": [c]});
    let first = serde_json::json!({"op": "advertise", "channels": [image_channel(1), json]});
    if !send_json(&mut ws, &info) || !send_json(&mut ws, &first) {
        return;
    }
    let Some([image, odom]) = subscriptions(&mut ws, &[1, 2]).map(|ids| [ids[0], ids[1]]) else {
        return;
    };
    let mut ok = ws.send(Message::binary(image_message(image, 0))).is_ok();
    for _ in 0..3 {
        ok &= ws.send(data(odom, 10, br#"{"x":1}"#)).is_ok();
    }
    ok &= send_json(&mut ws, &advertise(&cdr));
    for _ in 0..3 {
        ok &= ws
            .send(data(odom, 20, &[0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]))
            .is_ok();
    }
    ok &= send_json(
        &mut ws,
        &serde_json::json!({"op": "unadvertise", "channelIds": [2]}),
    );
    ok &= send_json(&mut ws, &advertise(&json));
    let Some(again) = subscription_of(&mut ws, 2).filter(|_| ok) else {
        return;
    };
    for _ in 0..2 {
        ok &= ws.send(data(again, 30, br#"{"x":2}"#)).is_ok();
    }
    for i in 1..5 {
        ok &= ws.send(Message::binary(image_message(image, i))).is_ok();
    }
    if ok {
        std::thread::sleep(Duration::from_secs(2));
    }
}

#[test]
fn a_channel_advertised_again_with_another_encoding_is_recorded_as_a_new_channel() {
    let peer = Peer::start(readvertiser);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("odometry.mcap");
    let done = eotn(&[
        OsStr::new("record"),
        OsStr::new(&peer.address()),
        OsStr::new("-o"),
        out.as_os_str(),
        OsStr::new("--frames"),
        OsStr::new("4"),
    ]);
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(done.status.success(), "{err}");
    assert!(err.contains("advertised again as cdr b.Odom"), "{err}");
    let counts = channel_counts(&out);
    let odometry = |encoding: &str| counts.get(&("/odometry".to_owned(), encoding.to_owned()));
    assert_eq!(odometry("json"), Some(&5), "{counts:?}");
    assert_eq!(odometry("cdr"), Some(&3), "{counts:?}");
    let bytes = std::fs::read(&out).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let cdr = summary
        .channels
        .values()
        .find(|c| c.message_encoding == "cdr")
        .unwrap();
    let schema = cdr.schema.as_ref().unwrap();
    assert_eq!(
        (schema.name.as_str(), schema.encoding.as_str()),
        ("b.Odom", "ros2msg")
    );
    assert_eq!(&*schema.data, b"float64 x");
}

/// Sends `signal` (`TERM`, `INT`) to process `pid` with `kill`.
fn signal(pid: u32, signal: &str) {
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &pid.to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

#[test]
fn sigterm_or_ctrl_c_ends_an_open_ended_record_with_every_frame_in_a_finished_indexed_file() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 10, None);
    let mut source = StreamReader::open(&stream).unwrap();
    let sent: Vec<_> = (0..10).map(|i| source.read(i).unwrap().frame).collect();
    let served = serve(&stream, "127.0.0.1:0", &["--loop"]);
    for (name, sig) in [("term.mcap", "TERM"), ("int.mcap", "INT")] {
        let out = dir.path().join(name);
        let child = Command::new(env!("CARGO_BIN_EXE_eotn"))
            .args(["record", &format!("127.0.0.1:{}", served.port), "-o"])
            .arg(&out)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let partial = dir.path().join(format!("{name}.partial"));
        assert!(wait_for(10.0, || partial.exists()), "recording started");
        std::thread::sleep(Duration::from_millis(1500));
        signal(child.id(), sig);
        let done = child.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&done.stdout);
        let err = String::from_utf8_lossy(&done.stderr);
        assert!(done.status.success(), "{sig}: {err}");
        assert!(!partial.exists(), "{sig}: the file was finished");
        // "NAME: N frames, M messages in S s -> PATH"
        let frames: usize = stdout
            .split(": ")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{stdout}"));
        let mut recorded = StreamReader::open(&out).unwrap();
        assert_eq!(
            recorded.len(),
            frames,
            "{sig}: every frame recorded is in the file"
        );
        assert!(frames >= 20, "{sig}: {frames} frames in 1.5 s at 30 fps");
        // The frames follow the stream's order, none missing between the first and the last.
        let first = sent
            .iter()
            .position(|f| *f == recorded.read(0).unwrap().frame)
            .unwrap();
        for i in 0..frames {
            assert_eq!(
                recorded.read(i).unwrap().frame,
                sent[(first + i) % 10],
                "{sig}: frame {i}"
            );
        }
        let bytes = std::fs::read(&out).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().expect("a summary");
        assert!(!summary.chunk_indexes.is_empty(), "{sig}: indexed");
    }
}

#[test]
fn non_finite_negative_and_absurd_durations_and_counts_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never.mcap");
    let o = out.to_string_lossy().into_owned();
    let cases: [&[&str]; 13] = [
        &["record", "127.0.0.1:9", "-o", &o, "--seconds", "inf"],
        &["record", "127.0.0.1:9", "-o", &o, "--seconds", "NaN"],
        &["record", "127.0.0.1:9", "-o", &o, "--seconds", "-1"],
        &["record", "127.0.0.1:9", "-o", &o, "--seconds", "0"],
        &["record", "127.0.0.1:9", "-o", &o, "--seconds", "1e300"],
        &["record", "127.0.0.1:9", "-o", &o, "--frames", "0"],
        &["record", "127.0.0.1:9", "-o", &o, "--frames", "-3"],
        &["record", "127.0.0.1:9", "-o", &o, "--frames", "100000001"],
        &["serve", &o, "--max-clients", "0"],
        &["serve", &o, "--handshake-timeout", "inf"],
        &["bench-live", "--fps", "NaN"],
        &["bench-live", "--robots", "0"],
        &["bench-live", "--seconds", "-5"],
    ];
    for args in cases {
        let args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
        let t = Instant::now();
        let done = eotn(&args);
        let err = String::from_utf8_lossy(&done.stderr);
        assert_eq!(done.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("invalid value"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(
            t.elapsed() < Duration::from_secs(5),
            "{args:?} answered at once"
        );
    }
    assert!(!out.exists() && !dir.path().join("never.mcap.partial").exists());
}

/// Sends "{not json" after a proper start.
pub fn garbage(stream: TcpStream, _: &AtomicBool) {
    let mut ws = handshake(stream);
    let info = serde_json::json!({"op": "serverInfo", "name": "garbage", "capabilities": []});
    if send_json(&mut ws, &info) {
        let _ = ws.send(Message::text("{not json"));
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// Sends a message of `bytes` bytes after a proper start.
fn oversized(stream: TcpStream, bytes: usize) {
    let mut ws = handshake(stream);
    let _ = ws.get_ref().set_write_timeout(Some(Duration::from_secs(2)));
    let info = serde_json::json!({"op": "serverInfo", "name": "oversized", "capabilities": []});
    if send_json(&mut ws, &info) {
        let _ = ws.send(Message::binary(vec![1_u8; bytes]));
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// Advertises lists of 1000 channels, again and again.
fn flood(stream: TcpStream, done: &AtomicBool) {
    let mut ws = handshake(stream);
    let info = serde_json::json!({"op": "serverInfo", "name": "flood", "capabilities": []});
    if !send_json(&mut ws, &info) {
        return;
    }
    for round in 0_u32.. {
        let channels: Vec<_> = (0..1000)
            .map(|i| json_channel(round * 1000 + i, &format!("/f{i}"), "f"))
            .collect();
        let advertise = serde_json::json!({"op": "advertise", "channels": channels});
        if done.load(Ordering::Relaxed) || !send_json(&mut ws, &advertise) {
            return;
        }
        // Subscriptions arrive; reading them keeps the socket flowing.
        let _ = ws
            .get_ref()
            .set_read_timeout(Some(Duration::from_millis(1)));
        while let Ok(m) = ws.read() {
            if matches!(m, Message::Close(_)) {
                return;
            }
        }
        if round > 200 {
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

#[test]
fn garbage_oversized_and_endless_advertisements_each_give_one_line_in_the_robots_list() {
    let garbage = Peer::start(garbage);
    let big = Peer::start(|s, _| oversized(s, (64 << 20) + 1));
    let flood = Peer::start(flood);
    let mut w = Workspace::default();
    for p in [&garbage, &big, &flood] {
        w.apply(WsCommand::from(
            eotn::workspace::RobotsCommand::ConnectRobot(p.address()),
        ))
        .unwrap();
    }
    let wanted = [
        "malformed message",
        "message too large",
        "more than 256 channels",
    ];
    let mut longest = Duration::ZERO;
    let until = Instant::now() + Duration::from_secs(10);
    let lines = loop {
        let t = Instant::now();
        w.tick(Duration::from_millis(16));
        let rows = w.robots();
        longest = longest.max(t.elapsed());
        let lines: Vec<String> = rows
            .iter()
            .map(|r| r.stats.problem.clone().unwrap_or_default())
            .collect();
        if lines.iter().zip(wanted).all(|(l, want)| l.contains(want)) || Instant::now() > until {
            break lines;
        }
        std::thread::sleep(Duration::from_millis(16));
    };
    for (line, want) in lines.iter().zip(wanted) {
        assert!(line.contains(want), "{want}: {lines:?}");
        assert!(!line.contains('\n') && line.len() < 600, "one line: {line}");
    }
    eprintln!("longest tick beside garbage, oversized and flooding robots: {longest:?}");
    // Ticks read the robots' state; none waits on a socket (measured 0.04–0.05 ms).
    assert!(
        longest < Duration::from_millis(250),
        "a tick took {longest:?}"
    );
    // The flood is not subscribed past the limit.
    let flood_row = &w.robots()[2];
    assert!(
        matches!(flood_row.connection, Connection::Connected(_)),
        "{:?}",
        flood_row.connection
    );
}
