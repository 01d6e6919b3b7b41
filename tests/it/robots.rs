//! Several robots in the workspace, through the same `Command`s the app sends: recording each
//! bit-exact while one is shown, stepping back while frames keep arriving, a faulty robot beside
//! a good one, a robot that goes away and comes back, and four robots at 30 fps (the soak: a
//! minute with `EOTN_LIVE_SECONDS=60`, `scripts/live-soak.sh`; two seconds in the suite).

use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use eotn::live::serve::StandInRobot;
use eotn::live::{Connection, unix_time_ns};
use eotn::streams::StreamReader;
use eotn::streams::schema::{ImageEncoding, encode_image};
use eotn::workspace::{
    Command, PlaybackCommand, RobotId, RobotRow, RobotsCommand, SourceCommand, Window, Workspace,
};
use tungstenite::Message;

use crate::live::{fake_robot_session, frame, image_message, image_payloads, record};

/// Ticks the workspace as the app's UI does (about 60 times a second) until `done` holds;
/// false when `secs` passed first.
pub fn tick_until(w: &mut Workspace, secs: f64, mut done: impl FnMut(&Workspace) -> bool) -> bool {
    let until = Instant::now() + Duration::from_secs_f64(secs);
    while Instant::now() < until {
        w.tick(Duration::from_millis(16));
        if done(w) {
            return true;
        }
        std::thread::sleep(Duration::from_millis(8));
    }
    done(w)
}

fn row(w: &Workspace, id: RobotId) -> RobotRow {
    w.robots().into_iter().find(|r| r.id == id).unwrap()
}

fn connect(w: &mut Workspace, port: u16) -> RobotId {
    w.apply(RobotsCommand::ConnectRobot(format!("127.0.0.1:{port}")).into())
        .unwrap();
    w.robots().last().unwrap().id
}

/// The image bytes a stand-in robot sends for `record(i)`.
fn sent_image(i: usize) -> Vec<u8> {
    let r = record(i);
    let mut bytes = Vec::new();
    encode_image(r.time_ns, &r.frame, ImageEncoding::default(), &mut bytes).unwrap();
    bytes
}

/// Sends `record(i)` for `frames` to `robot`, ticking the workspace between frames.
fn send_ticking(w: &mut Workspace, robot: &mut StandInRobot, frames: std::ops::Range<usize>) {
    for i in frames {
        robot.send(&record(i)).unwrap();
        w.tick(Duration::from_millis(16));
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn is_connected(c: &Connection) -> bool {
    matches!(c, Connection::Connected(_))
}

/// Checks a finished recording against what was sent, byte for byte per frame.
fn assert_recorded_bit_exact(path: &Path, sent: &[usize]) {
    let payloads = image_payloads(path);
    assert_eq!(payloads.len(), sent.len(), "{}", path.display());
    for (payload, &i) in payloads.iter().zip(sent) {
        assert_eq!(*payload, sent_image(i), "{}: frame {i}", path.display());
    }
    let mut reader = StreamReader::open(path).unwrap();
    assert_eq!(reader.len(), sent.len());
    let last = reader.read(sent.len() - 1).unwrap();
    assert_eq!(last.frame, frame(sent[sent.len() - 1]));
    assert!(
        last.sensors.is_some(),
        "the sensor readings are recorded too"
    );
}

#[test]
fn two_robots_are_recorded_bit_exact_one_file_each_and_a_dropped_robot_leaves_a_valid_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut alpha = StandInRobot::start("alpha", "127.0.0.1", 0).unwrap();
    let mut bravo = StandInRobot::start("bravo", "127.0.0.1", 0).unwrap();
    let mut w = Workspace::default();
    let wakes = Arc::new(std::sync::atomic::AtomicUsize::new(0));
    w.set_wake(Arc::new({
        let wakes = Arc::clone(&wakes);
        move || {
            wakes.fetch_add(1, Ordering::Relaxed);
        }
    }));
    let a = connect(&mut w, alpha.port());
    let b = connect(&mut w, bravo.port());
    assert_eq!(w.shown_robot(), Some(a), "the first robot is shown");
    assert!(tick_until(&mut w, 10.0, |w| w
        .robots()
        .iter()
        .all(|r| is_connected(&r.connection))));
    assert!(w.title().ends_with("robot alpha"), "{}", w.title());
    assert!(tick_until(&mut w, 5.0, |_| alpha.has_viewer() && bravo.has_viewer()));
    let folder = dir.path().join("rec");
    w.apply(RobotsCommand::RecordAllRobots(folder.clone()).into())
        .unwrap();
    let (pa, pb) = (folder.join("alpha.mcap"), folder.join("bravo.mcap"));
    assert_eq!(row(&w, a).recording.as_deref(), Some(pa.as_path()));
    assert_eq!(row(&w, b).recording.as_deref(), Some(pb.as_path()));
    for i in 0..20 {
        alpha.send(&record(i)).unwrap();
        bravo.send(&record(100 + i)).unwrap();
        w.tick(Duration::from_millis(16));
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(tick_until(&mut w, 10.0, |w| {
        row(w, a).stats.recorded == Some(20) && row(w, b).stats.recorded == Some(20)
    }));
    // The shown robot's newest frame is in the views with its sensors; bravo, not shown,
    // received and recorded every frame all the same.
    assert!(tick_until(&mut w, 5.0, |w| w.index() == 19
        && w.current().is_some_and(|c| c.sensors.is_some())));
    assert_eq!(w.frame(), Some(&frame(19)));
    assert_eq!(row(&w, b).stats.frames, 20);
    // Only the shown robot's frames woke the UI (bravo's 20 did not).
    assert_eq!(wakes.load(Ordering::Relaxed), 20);

    // Alpha goes away: its connection closes (said in the list and the status line), its
    // recording stays open and readable, and finishes into a valid file.
    alpha.stop();
    assert!(tick_until(&mut w, 10.0, |w| matches!(
        row(w, a).connection,
        Connection::Disconnected { .. }
    )));
    assert!(
        w.warnings()
            .iter()
            .any(|m| m.starts_with("alpha: connection closed")),
        "{:?}",
        w.warnings()
    );
    let partial = PathBuf::from(format!("{}.partial", pa.display()));
    assert!(tick_until(&mut w, 5.0, |_| StreamReader::open(&partial)
        .is_ok_and(|r| r.len() == 20)));
    w.apply(RobotsCommand::StopRecordingRobot(a).into())
        .unwrap();
    assert!(
        w.status.contains("recorded 20 frames of alpha"),
        "{}",
        w.status
    );
    assert_recorded_bit_exact(&pa, &(0..20).collect::<Vec<_>>());
    // Disconnecting bravo finishes its file too.
    w.apply(RobotsCommand::DisconnectRobot(b).into()).unwrap();
    assert_recorded_bit_exact(&pb, &(100..120).collect::<Vec<_>>());
    assert_eq!(w.robots().len(), 1);
    bravo.stop();
}

#[test]
fn stepping_back_holds_the_view_while_frames_arrive_and_are_recorded_and_live_returns() {
    let dir = tempfile::tempdir().unwrap();
    let mut robot = StandInRobot::start("steps", "127.0.0.1", 0).unwrap();
    let mut w = Workspace::default();
    let id = connect(&mut w, robot.port());
    assert!(tick_until(&mut w, 10.0, |_| robot.has_viewer()));
    let out = dir.path().join("steps.mcap");
    // Camera ▸ Start recording… records the shown robot with its own bit-exact recorder.
    w.apply(SourceCommand::StartRecording(out.clone()).into())
        .unwrap();
    assert_eq!(w.recording(), Some(out.clone()));
    send_ticking(&mut w, &mut robot, 0..10);
    assert!(tick_until(&mut w, 5.0, |w| w.index() == 9));
    assert!(w.following_live());

    w.apply(PlaybackCommand::Step(-3).into()).unwrap();
    assert!(!w.following_live(), "stepping holds the view");
    assert_eq!((w.index(), w.frame()), (6, Some(&frame(6))));
    let pan = |w: &Workspace| w.current().and_then(|c| c.sensors?.head_pan_rad);
    assert_eq!(pan(&w), Some(0.06), "the shown frame's own sensor readings");
    send_ticking(&mut w, &mut robot, 10..20);
    assert!(tick_until(&mut w, 5.0, |w| row(w, id).stats.recorded == Some(20)));
    assert_eq!(w.index(), 6, "the view stayed where it was held");
    assert_eq!(w.source().unwrap().len(), 20, "the timeline grew");
    w.apply(PlaybackCommand::Seek(2).into()).unwrap();
    assert_eq!(w.frame(), Some(&frame(2)));
    // Playing through what has arrived runs at the arrival rate and stops at the newest.
    w.apply(PlaybackCommand::SetSpeed(0.0).into()).unwrap();
    w.apply(PlaybackCommand::SetPlaying(true).into()).unwrap();
    assert!(tick_until(&mut w, 5.0, |w| !w.playing()));
    assert_eq!(w.index(), 19);
    w.apply(PlaybackCommand::Step(-10).into()).unwrap();
    w.apply(RobotsCommand::SetFollowLive(true).into()).unwrap();
    assert!(w.following_live());
    assert_eq!(w.index(), 19, "live is the newest frame");
    send_ticking(&mut w, &mut robot, 20..25);
    assert!(tick_until(&mut w, 5.0, |w| w.index() == 24));
    assert_eq!(w.frame(), Some(&frame(24)));
    // A frame's sensors follow its image by a moment (through `eotn serve`'s relay, a little
    // longer on a loaded machine): wait for the last one's.
    assert!(tick_until(&mut w, 5.0, |w| {
        w.robot_frames(id)
            .and_then(|f| f.latest())
            .is_some_and(|f| f.record.sensors.is_some())
    }));
    // The sensor dialog's plots cover every frame that has arrived, with its readings.
    w.apply(Command::ShowWindow(Window::Sensors, true)).unwrap();
    assert!(tick_until(&mut w, 5.0, |w| w.sensor_series.points.len() == 25));
    let pans: Vec<Option<f64>> = w
        .sensor_series
        .points
        .iter()
        .map(|(_, r)| r.as_ref().and_then(|r| r.head_pan_rad))
        .collect();
    assert_eq!(pans[24], Some(0.24));
    assert!(pans.iter().all(Option::is_some));
    w.apply(SourceCommand::StopRecording.into()).unwrap();
    assert_eq!(w.recording(), None);
    assert_recorded_bit_exact(&out, &(0..25).collect::<Vec<_>>());
    w.apply(SourceCommand::Disconnect.into()).unwrap();
    assert!(w.robots().is_empty() && w.source().is_none());
    robot.stop();
}

/// A robot that sends garbage on every connection (and is connected again and again).
fn garbage_robot(listener: TcpListener, done: Arc<AtomicBool>) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        while !done.load(Ordering::Relaxed) {
            let (mut ws, sub) = fake_robot_session(&listener);
            let _ = ws.send(Message::text("{not json"));
            let _ = ws.send(Message::binary(vec![1, 2, 3]));
            let _ = ws.send(Message::binary(image_message(sub, 0)));
            std::thread::sleep(Duration::from_millis(100));
        }
    })
}

#[test]
fn a_faulty_robot_closes_only_its_own_connection_and_a_robot_that_comes_back_is_reconnected() {
    let garbage = TcpListener::bind("127.0.0.1:0").unwrap();
    let gport = garbage.local_addr().unwrap().port();
    let done = Arc::new(AtomicBool::new(false));
    let g = garbage_robot(garbage, Arc::clone(&done));
    let mut good = StandInRobot::start("good", "127.0.0.1", 0).unwrap();
    let port = good.port();
    let mut w = Workspace::default();
    let ok = connect(&mut w, port);
    let bad = connect(&mut w, gport);
    assert_eq!(w.shown_robot(), Some(ok));
    assert!(tick_until(&mut w, 10.0, |_| good.has_viewer()));
    send_ticking(&mut w, &mut good, 0..30);
    assert!(tick_until(&mut w, 5.0, |w| w.index() == 29));
    let stats = row(&w, ok).stats;
    assert_eq!((stats.frames, stats.drops), (30, 0));
    assert!(
        w.warnings()
            .iter()
            .any(|m| m.contains("connection closed") && m.contains("malformed message")),
        "{:?}",
        w.warnings()
    );
    assert_eq!(
        row(&w, bad).stats.frames,
        0,
        "nothing of the garbage is shown"
    );
    assert!(
        w.robot_log(bad)
            .iter()
            .any(|l| l.contains("malformed message"))
    );
    // Showing the faulty robot shows nothing (it has no frame), and the good one is back with
    // a click.
    w.apply(RobotsCommand::ShowRobot(bad).into()).unwrap();
    assert!(w.frame().is_none());
    w.apply(RobotsCommand::ShowRobot(ok).into()).unwrap();
    assert_eq!(w.frame(), Some(&frame(29)));

    // The good robot goes away and comes back on the same port.
    good.stop();
    assert!(tick_until(&mut w, 10.0, |w| matches!(
        row(w, ok).connection,
        Connection::Disconnected { .. }
    )));
    assert!(
        w.status.starts_with("good: connection closed"),
        "{}",
        w.status
    );
    // The stopped server lets go of its port a moment later.
    let mut again = None;
    assert!(tick_until(&mut w, 10.0, |_| {
        again = again
            .take()
            .or_else(|| StandInRobot::start("good", "127.0.0.1", port).ok());
        again.is_some()
    }));
    let mut again = again.unwrap();
    assert!(tick_until(&mut w, 15.0, |_| again.has_viewer()));
    assert!(tick_until(&mut w, 5.0, |w| is_connected(
        &row(w, ok).connection
    )));
    assert_eq!(row(&w, ok).stats.connections, 2);
    send_ticking(&mut w, &mut again, 30..35);
    assert!(tick_until(&mut w, 5.0, |w| w.index() == 34));
    assert_eq!(w.frame(), Some(&frame(34)));

    done.store(true, Ordering::Relaxed);
    w.apply(RobotsCommand::DisconnectRobot(bad).into()).unwrap();
    // Unblocks the garbage robot's last accept.
    let _ = TcpStream::connect(("127.0.0.1", gport));
    let _ = g.join();
    again.stop();
}

/// Sends `frames` frames at 30 fps to every robot on this thread; the log time of each.
fn send_at_30_fps(mut robots: Vec<StandInRobot>, frames: usize) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let start = Instant::now();
        for n in 0..frames {
            let due = start + Duration::from_secs_f64(n as f64 / 30.0);
            std::thread::sleep(due.saturating_duration_since(Instant::now()));
            for r in &mut robots {
                r.send(&record(n)).unwrap();
            }
        }
        // Wait for the viewers to read the last frames before the servers go.
        std::thread::sleep(Duration::from_millis(500));
        for r in robots {
            r.stop();
        }
    })
}

#[test]
fn four_robots_at_30_fps_into_the_workspace_lose_no_frame_and_keep_up() {
    let seconds: f64 = std::env::var("EOTN_LIVE_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2.0);
    let frames = (seconds * 30.0) as usize;
    let dir = tempfile::tempdir().unwrap();
    let robots: Vec<StandInRobot> = (0..4)
        .map(|i| StandInRobot::start(&format!("r{i}"), "127.0.0.1", 0).unwrap())
        .collect();
    let mut w = Workspace::default();
    let ids: Vec<RobotId> = robots.iter().map(|r| connect(&mut w, r.port())).collect();
    assert!(tick_until(&mut w, 10.0, |_| robots
        .iter()
        .all(StandInRobot::has_viewer)));
    w.apply(RobotsCommand::RecordAllRobots(dir.path().to_owned()).into())
        .unwrap();
    let sender = send_at_30_fps(robots, frames);
    // The UI's loop: tick, and note how long each newly shown frame took from the sender.
    let mut shown_latency_ms = Vec::new();
    let mut last = None;
    let until = Instant::now() + Duration::from_secs_f64(seconds + 10.0);
    while Instant::now() < until && w.robots().iter().any(|r| r.stats.frames < frames) {
        w.tick(Duration::from_millis(16));
        if last != Some(w.index())
            && let Some(f) = w.robot_frames(ids[0]).and_then(|v| v.frame(w.index()))
        {
            last = Some(w.index());
            shown_latency_ms
                .push((unix_time_ns() - f.record.time_ns.min(unix_time_ns())) as f64 / 1e6);
        }
        std::thread::sleep(Duration::from_millis(16));
    }
    sender.join().unwrap();
    assert!(tick_until(&mut w, 5.0, |w| w.index() + 1 == frames));
    for (k, id) in ids.iter().enumerate() {
        let r = row(&w, *id);
        eprintln!(
            "robot {k}: latency median {:?} ms, p99 {:?} ms",
            r.stats.latency_median_ms, r.stats.latency_p99_ms
        );
        assert_eq!((r.stats.frames, r.stats.drops), (frames, 0), "robot {k}");
        // Keeping up: 99% of frames in before the next one is sent (one frame interval, 33 ms),
        // and the median within half of one. On this shared machine both move tenfold with the
        // load (2026-12-07, 2 cores at load 13–17, runs of 2 s: median 0.7–0.9 ms in most runs,
        // up to 8.7 ms in some; p99 1.2–12.4 ms; a run of 60 s: p99 28 ms), so these limits are
        // what keeping up means, about 2× the worst seen, not 2–3× a quiet run.
        assert!(
            r.stats.latency_median_ms.is_some_and(|ms| ms < 16.7),
            "robot {k}: {:?}",
            r.stats
        );
        assert!(
            r.stats.latency_p99_ms.is_some_and(|ms| ms < 33.0),
            "robot {k}: {:?}",
            r.stats
        );
        let view = w.robot_frames(*id).unwrap();
        for i in 0..frames {
            let f = view.frame(i).unwrap();
            assert_eq!(f.record.frame, frame(i), "robot {k} frame {i}");
            assert!(
                f.record.sensors.is_some(),
                "robot {k} frame {i} has its sensors"
            );
        }
    }
    shown_latency_ms.sort_by(f64::total_cmp);
    let pick = |p: f64| shown_latency_ms[((shown_latency_ms.len() - 1) as f64 * p) as usize];
    // Shown within a frame interval at the median (it includes the UI's 16 ms poll): achieved
    // 2026-12-07 at load 14 a median of 7.5–14.0 ms in three runs, the limit 2.4× the worst.
    assert!(
        shown_latency_ms.len() >= frames / 2,
        "{} shown",
        shown_latency_ms.len()
    );
    assert!(pick(0.5) < 33.0, "median {} ms", pick(0.5));
    println!(
        "four robots, {frames} frames each: sender's write to the frame shown in the workspace (UI polling every 16 ms): median {:.1} ms, p99 {:.1} ms over {} shown frames",
        pick(0.5),
        pick(0.99),
        shown_latency_ms.len()
    );
    let paths: Vec<PathBuf> = w.robots().into_iter().filter_map(|r| r.recording).collect();
    assert_eq!(paths.len(), 4);
    for id in ids {
        w.apply(RobotsCommand::DisconnectRobot(id).into()).unwrap();
    }
    let all: Vec<usize> = (0..frames).collect();
    for p in paths {
        assert_recorded_bit_exact(&p, &all);
    }
}

#[test]
fn a_first_robot_that_never_connects_gives_way_to_one_that_sends_unless_the_user_chose_it() {
    // A port nobody listens on: the first robot connected is shown, and never gets a frame.
    let dead_port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let mut good = StandInRobot::start("good", "127.0.0.1", 0).unwrap();
    let mut w = Workspace::default();
    let dead = connect(&mut w, dead_port);
    let ok = connect(&mut w, good.port());
    assert_eq!(w.shown_robot(), Some(dead));
    assert!(tick_until(&mut w, 10.0, |w| matches!(
        row(w, dead).connection,
        Connection::Disconnected { .. }
    )));
    assert!(tick_until(&mut w, 10.0, |_| good.has_viewer()));
    send_ticking(&mut w, &mut good, 0..5);
    // The workspace chose the dead robot, so it shows the one that sends instead of nothing.
    assert!(tick_until(&mut w, 5.0, |w| w.shown_robot() == Some(ok)
        && w.index() == 4));
    assert_eq!(w.frame(), Some(&frame(4)));
    // A robot the user chose stays shown, frames or not.
    w.apply(RobotsCommand::ShowRobot(dead).into()).unwrap();
    send_ticking(&mut w, &mut good, 5..10);
    assert!(tick_until(&mut w, 2.0, |w| row(w, ok).stats.frames == 10));
    assert_eq!(w.shown_robot(), Some(dead));
    assert!(w.frame().is_none());
    w.apply(SourceCommand::Disconnect.into()).unwrap();
    good.stop();
}
