//! `eotn serve` under load, on loopback: viewers past `--max-clients` refused with a close
//! reason, idle handshakes closed after their deadline, hundreds of idle connections past the
//! descriptor limit (set at start, and lowered while it runs so `accept` meets `EMFILE`), dozens
//! of viewers that never read beside a good one (memory bounded, the good one keeps its rate),
//! and a damaged chunk skipped. The load test runs `EOTN_SERVE_LOAD_STALLED` viewers that never
//! read for `EOTN_SERVE_LOAD_SECONDS` (24 for 5 s in the suite, 40 for 20 s in
//! `scripts/long-run.sh`).

use std::io::{BufRead, BufReader, Read};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use eotn::live::{LiveRobot, RobotUrl};
use eotn::streams::StreamReader;
use tungstenite::{Message, WebSocket};

use crate::common::{eotn_ok, sim_stream, skipped};
use crate::live::wait_for;
use crate::live_peers::peak_rss_kb;

/// `eotn serve` in the background with its stderr collected; stopped with SIGTERM.
struct Served {
    child: Child,
    port: u16,
    stderr: Option<JoinHandle<String>>,
}

/// Starts `eotn serve STREAM --listen 127.0.0.1:0 EXTRA…`, with at most `nofile` open files
/// when given (`ulimit -n`, through `sh`).
fn start(stream: &Path, extra: &[&str], nofile: Option<u32>) -> Served {
    let exe = env!("CARGO_BIN_EXE_eotn");
    let mut cmd = match nofile {
        Some(n) => {
            let mut c = Command::new("sh");
            c.args(["-c", &format!("ulimit -n {n} && exec \"$0\" \"$@\""), exe]);
            c
        }
        None => Command::new(exe),
    };
    let mut child = cmd
        .arg("serve")
        .arg(stream)
        .args(["--listen", "127.0.0.1:0"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
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
    let mut err = child.stderr.take().unwrap();
    let stderr = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = err.read_to_string(&mut text);
        text
    });
    Served {
        child,
        port,
        stderr: Some(stderr),
    }
}

impl Served {
    /// SIGTERM unless it has ended, then its stderr (it must exit by itself within 10 s).
    fn stop(mut self) -> String {
        if self.child.try_wait().unwrap().is_none() {
            let status = Command::new("kill")
                .args(["-TERM", &self.child.id().to_string()])
                .status()
                .unwrap();
            assert!(status.success());
        }
        let until = Instant::now() + Duration::from_secs(10);
        while self.child.try_wait().unwrap().is_none() {
            assert!(Instant::now() < until, "eotn serve did not end on SIGTERM");
            std::thread::sleep(Duration::from_millis(20));
        }
        self.stderr.take().unwrap().join().unwrap()
    }

    fn url(&self) -> RobotUrl {
        format!("127.0.0.1:{}", self.port).parse().unwrap()
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

type Viewer = WebSocket<TcpStream>;

/// A viewer: connects and handshakes with the Foxglove subprotocol.
fn viewer(port: u16) -> Viewer {
    let stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    let mut request = tungstenite::client::IntoClientRequest::into_client_request(format!(
        "ws://127.0.0.1:{port}/"
    ))
    .unwrap();
    request
        .headers_mut()
        .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
    tungstenite::client::client(request, stream).unwrap().0
}

/// The next text message (at most 5 s), or how the connection was closed.
fn next_text(ws: &mut Viewer) -> Result<serde_json::Value, String> {
    loop {
        match ws.read() {
            Ok(Message::Text(t)) => return Ok(serde_json::from_str(t.as_str()).unwrap()),
            Ok(Message::Close(frame)) => {
                return Err(frame.map(|f| f.reason.to_string()).unwrap_or_default());
            }
            Ok(_) => {}
            Err(e) => return Err(e.to_string()),
        }
    }
}

#[test]
fn viewers_past_max_clients_are_refused_with_a_reason_and_idle_handshakes_closed() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 10, None);
    let served = start(
        &stream,
        &["--loop", "--max-clients", "2", "--handshake-timeout", "0.5"],
        None,
    );
    let mut a = viewer(served.port);
    let mut b = viewer(served.port);
    assert_eq!(next_text(&mut a).unwrap()["op"], "serverInfo");
    assert_eq!(next_text(&mut b).unwrap()["op"], "serverInfo");
    let mut c = viewer(served.port);
    let refused = next_text(&mut c).unwrap_err();
    assert!(refused.contains("--max-clients"), "{refused}");
    // A place freed is taken by the next.
    drop(a);
    let mut admitted = false;
    for _ in 0..20 {
        std::thread::sleep(Duration::from_millis(100));
        if next_text(&mut viewer(served.port)).is_ok_and(|v| v["op"] == "serverInfo") {
            admitted = true;
            break;
        }
    }
    assert!(admitted, "a viewer was admitted after one left");
    // A connection that never handshakes is closed after its deadline.
    let mut idle = TcpStream::connect(("127.0.0.1", served.port)).unwrap();
    idle.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let t = Instant::now();
    let read = idle.read(&mut [0_u8; 16]);
    let took = t.elapsed();
    assert!(matches!(read, Ok(0)) || read.is_err(), "{read:?}");
    assert!(
        took >= Duration::from_millis(400) && took < Duration::from_secs(3),
        "closed after {took:?}"
    );
    drop(b);
    let err = served.stop();
    assert!(err.contains("refused (--max-clients)"), "{err}");
    assert!(err.contains("handshakes timed out"), "{err}");
}

/// Opens `n` connections that never handshake.
fn idle_connections(port: u16, n: usize) -> Vec<TcpStream> {
    (0..n)
        .map(|_| TcpStream::connect(("127.0.0.1", port)).unwrap())
        .collect()
}

/// Connects a robot and waits (at most 20 s) for `frames` frames.
fn gets_frames(url: RobotUrl, frames: usize) -> bool {
    let robot = LiveRobot::connect(url, Default::default(), 16 << 20, None).unwrap();
    wait_for(20.0, || robot.len() >= frames)
}

#[test]
fn hundreds_of_idle_connections_past_the_descriptor_limit_leave_room_for_a_good_viewer() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 10, None);

    // A limit set at start: viewers and handshakes are kept within it.
    let served = start(&stream, &["--loop"], Some(128));
    let idle = idle_connections(served.port, 400);
    assert!(gets_frames(served.url(), 10), "a good viewer got frames");
    drop(idle);
    let err = served.stop();
    assert!(
        err.contains("`ulimit -n` is 128: at most 13 viewers"),
        "{err}"
    );
    assert!(
        err.contains("unfinished handshakes closed for room"),
        "{err}"
    );

    // A limit lowered while it runs: `accept` meets EMFILE, says so once, and serves on.
    let Some(prlimit) = which("prlimit") else {
        skipped(
            "prlimit is not installed: the EMFILE half (a limit lowered while serving) is not tested",
            "install util-linux's prlimit",
        );
        return;
    };
    let served = start(&stream, &["--loop"], None);
    let lowered = Command::new(prlimit)
        .args(["--pid", &served.child.id().to_string(), "--nofile=64:64"])
        .status()
        .unwrap();
    assert!(lowered.success());
    let idle = idle_connections(served.port, 400);
    assert!(gets_frames(served.url(), 10), "a good viewer got frames");
    let idle_later = idle_connections(served.port, 200);
    assert!(gets_frames(served.url(), 10), "and another, later");
    drop((idle, idle_later));
    let err = served.stop();
    let said = err.matches("cannot accept more connections").count();
    assert_eq!(said, 1, "said once: {err}");
    assert!(err.contains("accept errors (retried)"), "{err}");
}

fn which(tool: &str) -> Option<std::path::PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join(tool))
            .find(|p| p.is_file())
    })
}

/// A viewer that subscribes to every channel and then never reads again.
fn stalled_viewer(port: u16) -> Viewer {
    let mut ws = viewer(port);
    let ids: Vec<u64> = loop {
        let v = next_text(&mut ws).unwrap();
        if v["op"] == "advertise" {
            break v["channels"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| c["id"].as_u64().unwrap())
                .collect();
        }
    };
    let subs: Vec<_> = ids
        .iter()
        .enumerate()
        .map(|(i, id)| serde_json::json!({"id": i, "channelId": id}))
        .collect();
    let subscribe = serde_json::json!({"op": "subscribe", "subscriptions": subs});
    ws.send(Message::text(subscribe.to_string())).unwrap();
    ws
}

/// Reads (at most 10 s) until a message sent after the call arrives: true when one does.
fn reads_fresh_frames(ws: &mut Viewer) -> bool {
    let from_ns = eotn::live::unix_time_ns();
    let until = Instant::now() + Duration::from_secs(10);
    while Instant::now() < until {
        let Ok(Message::Binary(b)) = ws.read() else {
            continue;
        };
        let sent_ns = b
            .get(5..13)
            .map(|t| u64::from_le_bytes(t.try_into().unwrap()));
        if b.first() == Some(&1) && sent_ns.is_some_and(|t| t >= from_ns) {
            return true;
        }
    }
    false
}

/// CPU time process `pid` has used, seconds (user + system, from `/proc/PID/stat`).
fn cpu_seconds(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    // Fields after the command name (in parentheses): utime and stime are the 12th and 13th.
    let after = &stat[stat.rfind(')').unwrap() + 2..];
    let fields: Vec<&str> = after.split(' ').collect();
    let ticks: f64 = fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap();
    ticks / 100.0
}

/// Current resident memory of process `pid`, kB (`VmRSS`).
fn rss_kb(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap()
}

#[test]
fn viewers_that_never_read_cost_bounded_memory_and_a_good_viewer_keeps_its_rate() {
    let seconds: f64 = std::env::var("EOTN_SERVE_LOAD_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5.0);
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "walk-and-pan", 30, None);
    let reader = StreamReader::open(&stream).unwrap();
    let span_ns = reader.time_ns(29).unwrap() - reader.time_ns(0).unwrap();
    let fps = 29.0 / (span_ns as f64 / 1e9);
    let served = start(&stream, &["--loop"], None);
    let pid = served.child.id();
    let stalled_count: usize = std::env::var("EOTN_SERVE_LOAD_STALLED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(24);
    let stalled: Vec<Viewer> = (0..stalled_count)
        .map(|_| stalled_viewer(served.port))
        .collect();
    let good = LiveRobot::connect(served.url(), Default::default(), 16 << 20, None).unwrap();
    assert!(
        wait_for(10.0, || good.len() >= 5),
        "the good viewer started"
    );
    let (start_frames, t0, cpu0) = (good.len(), Instant::now(), cpu_seconds(pid));
    let mut peak_kb = 0;
    while t0.elapsed().as_secs_f64() < seconds {
        std::thread::sleep(Duration::from_millis(200));
        peak_kb = peak_kb.max(rss_kb(pid));
    }
    let elapsed = t0.elapsed().as_secs_f64();
    let got = (good.len() - start_frames) as f64 / elapsed;
    let lost = good.stats().drops;
    let cpu = (cpu_seconds(pid) - cpu0) / elapsed;
    let hwm = peak_rss_kb(pid).unwrap_or(0);
    // A stalled viewer that reads again catches up: after what was queued for it, frames sent
    // now reach it (its subscriptions were held back, not lost).
    let mut stalled = stalled;
    if let Some(mut back) = stalled.pop() {
        assert!(
            reads_fresh_frames(&mut back),
            "a viewer that reads again gets new frames"
        );
    }
    drop(good);
    let err = served.stop();
    drop(stalled);
    // "eotn serve: sent N frames; …, D frames dropped for slow viewers"
    let dropped: u64 = err
        .lines()
        .find(|l| l.starts_with("eotn serve: sent"))
        .and_then(|l| l.split(" frames dropped for slow viewers").next())
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{err}"));
    eprintln!(
        "serve with {stalled_count} stalled viewers for {seconds} s: resident {peak_kb} kB at most (VmHWM {hwm} kB), CPU {:.0} % of a core, {dropped} frames dropped for them; the good viewer {got:.1} fps of {fps:.1}, {lost} lost",
        cpu * 100.0
    );
    // Before the gate each stalled viewer cost about 68 MB (40: about 2.7 GB); measured 78 to
    // 108 MB for 40 now.
    assert!(peak_kb < 300_000, "serve held {peak_kb} kB");
    // The good viewer keeps up (measured alone: 25.6 to 30.2 fps of 30, 0 to 13 of about 600
    // frames lost, on 2 shared cores loaded by other builds) and loses few frames if any: its
    // outbox holds about 10 frames, which a relay starved of CPU for a third of a second fills.
    // The whole suite runs beside this test on the same 2 cores, hence the margins.
    let received = got * elapsed;
    assert!(
        (lost as f64) <= 0.1 * received,
        "the good viewer lost {lost} of {received:.0} frames"
    );
    assert!(
        got >= 0.6 * fps,
        "the good viewer got {got:.1} fps of {fps:.1}"
    );
    if seconds >= 5.0 && stalled_count > 0 {
        assert!(
            dropped > 0,
            "frames dropped for the stalled viewers are counted: {err}"
        );
    }
}

#[test]
fn a_damaged_chunk_in_the_served_stream_is_skipped_as_detect_skips_it() {
    let dir = tempfile::tempdir().unwrap();
    let good = sim_stream(dir.path(), "walk-and-pan", 40, None);
    let mut bytes = std::fs::read(&good).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0xff;
    let bad = dir.path().join("bad.mcap");
    std::fs::write(&bad, &bytes).unwrap();
    let mut reader = StreamReader::open(&bad).unwrap();
    let readable: Vec<_> = (0..reader.len())
        .filter_map(|i| reader.read(i).ok().map(|r| r.frame))
        .collect();
    assert!(
        !readable.is_empty() && readable.len() < 40,
        "{}",
        readable.len()
    );
    let served = start(&bad, &["--wait"], None);
    let out = dir.path().join("rec.mcap");
    let n = readable.len().to_string();
    let address = format!("127.0.0.1:{}", served.port);
    eotn_ok(&[
        "record".as_ref(),
        address.as_ref(),
        "--frames".as_ref(),
        n.as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let mut recorded = StreamReader::open(&out).unwrap();
    assert_eq!(recorded.len(), readable.len());
    for (i, frame) in readable.iter().enumerate() {
        assert_eq!(recorded.read(i).unwrap().frame, *frame, "frame {i}");
    }
    let err = served.stop();
    assert!(err.contains("skipped, unreadable"), "{err}");
    assert!(err.contains("unreadable frames skipped"), "{err}");
}
