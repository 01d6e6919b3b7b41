//! `eotn bench-live`: end-to-end latency of live robots on this machine, from a sender's write to
//! the frame in the state the app reads, and the CPU the reception costs.
//!
//! Starts `--robots` stand-in robots (the same Foxglove WebSocket servers as `eotn serve`) on
//! loopback, each sending rendered frames with their sensor readings at `--fps`, connects one
//! [`LiveRobot`] to each, and measures for `--seconds`. Latency is this machine's clock at the
//! frame's arrival in the [`LiveRobot`] minus the log time the sender stamped when it wrote the
//! frame. CPU is read from `/proc/self/task/*/stat`: the robots' receiving threads (socket,
//! parsing, decoding) apart from the senders.
//!
//! With `--app` the robots are connected through the app's [`Workspace`] instead (Camera ▸
//! Connect to robot…, each recorded with Record all into a temporary folder), ticked as the window
//! is: woken by the shown robot's new frame, else about 60 times a second; it adds the latency to
//! the frame shown (the pipeline run on it) and the CPU of the whole app state, pipeline and
//! recording included.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use serde::Serialize;

use crate::live::RobotFrames;
use crate::live::robot::DEFAULT_KEEP_BYTES;
use crate::live::serve::{SendError, StandInRobot};
use crate::live::{ClientOptions, LiveRobot, RobotUrl};
use crate::sim::{Scenario, ScenarioKind, Simulator};
use crate::streams::FrameRecord;
use crate::workspace::{Command, Workspace};

/// How often `--app` ticks the workspace, as the window does while following a robot.
const APP_TICK: Duration = Duration::from_millis(16);

/// Arguments of `eotn bench-live`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Robots sending at once.
    #[arg(long, default_value_t = 4, value_parser = super::values::whole_in::<usize>(1, 64))]
    pub robots: usize,
    /// Frames per second each robot sends.
    #[arg(long, default_value_t = 30.0, value_parser = super::values::number_in(0.1, 1000.0))]
    pub fps: f64,
    /// Seconds measured.
    #[arg(long, default_value_t = 10.0, value_parser = super::values::number_in(0.1, 86_400.0))]
    pub seconds: f64,
    /// Connect through the app's workspace (ticked as the window does), recording every robot.
    #[arg(long)]
    pub app: bool,
    /// End with one JSON line of the figures.
    #[arg(long)]
    pub json: bool,
}

/// The figures (and the `--json` line).
#[derive(Debug, Serialize)]
pub struct LiveBenchJson {
    /// Robots.
    pub robots: usize,
    /// Frames per second per robot asked for.
    pub fps: f64,
    /// Frame size, pixels.
    pub width: usize,
    /// Frame size, pixels.
    pub height: usize,
    /// Frames sent, all robots.
    pub sent: usize,
    /// Frames received, all robots.
    pub received: usize,
    /// Frames counted as dropped, all robots.
    pub drops: usize,
    /// Median latency, ms.
    pub latency_median_ms: f64,
    /// 99th percentile latency, ms.
    pub latency_p99_ms: f64,
    /// Largest latency, ms.
    pub latency_max_ms: f64,
    /// CPU of the receiving threads, percent of one core.
    pub receive_cpu_percent: f64,
    /// CPU of the whole process (senders, servers, receivers), percent of one core.
    pub process_cpu_percent: f64,
    /// `--app`: frames shown (the shown robot's that the view followed).
    pub shown: Option<usize>,
    /// `--app`: median latency from the sender's write to the frame shown, ms.
    pub shown_median_ms: Option<f64>,
    /// `--app`: 99th percentile of the same, ms.
    pub shown_p99_ms: Option<f64>,
}

/// Clock ticks per second of `/proc/…/stat` (`sysconf(_SC_CLK_TCK)`, 100 on Linux).
const TICKS_PER_S: f64 = 100.0;

/// CPU seconds (user + system) of this process's threads, split into those whose name starts
/// with `robot ` (the receivers) and all.
fn cpu_seconds() -> (f64, f64) {
    let (mut robots, mut all) = (0.0, 0.0);
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return (f64::NAN, f64::NAN);
    };
    for task in tasks.flatten() {
        let Ok(stat) = std::fs::read_to_string(task.path().join("stat")) else {
            continue;
        };
        // `pid (comm) state …`: the name may hold spaces, so fields count from the last ')'.
        let (Some(open), Some(close)) = (stat.find('('), stat.rfind(')')) else {
            continue;
        };
        let comm = &stat[open + 1..close];
        let fields: Vec<&str> = stat[close + 1..].split_whitespace().collect();
        let ticks: f64 = [11, 12]
            .iter()
            .filter_map(|&i| fields.get(i)?.parse::<f64>().ok())
            .sum();
        all += ticks / TICKS_PER_S;
        if comm.starts_with("robot ") {
            robots += ticks / TICKS_PER_S;
        }
    }
    (robots, all)
}

fn frames_to_send() -> anyhow::Result<Vec<FrameRecord>> {
    let sim = Simulator::new(Scenario::new(ScenarioKind::WalkAndPan, 1));
    (0..30)
        .map(|i| {
            let f = sim.frame(i)?;
            let mut r = FrameRecord::new(f.time_ns, f.frame);
            r.sensors = f.sensors;
            Ok(r)
        })
        .collect()
}

fn percentile_ms(sorted: &[u64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let at = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted.get(at).map_or(f64::NAN, |&ns| ns as f64 / 1e6)
}

/// Runs `eotn bench-live`.
///
/// # Errors
/// A server that cannot start or frames that cannot be rendered.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let frames = Arc::new(frames_to_send()?);
    let (width, height) = frames
        .first()
        .map_or((0, 0), |f| (f.frame.width(), f.frame.height()));
    let (servers, robots, mut app) = connect_robots(args, width * height)?;
    let folder = std::env::temp_dir().join(format!("eotn-bench-live-{}", std::process::id()));
    let views: Vec<RobotFrames> = match app.as_mut() {
        Some(w) => {
            w.apply(Command::RecordAllRobots(folder.clone()))?;
            w.robots()
                .iter()
                .filter_map(|r| w.robot_frames(r.id))
                .collect()
        }
        None => robots.iter().map(LiveRobot::frames_view).collect(),
    };
    let wait_until = Instant::now() + Duration::from_secs(10);
    while servers.iter().any(|s| !s.has_viewer()) {
        anyhow::ensure!(
            Instant::now() < wait_until,
            "the robots did not subscribe within 10 s"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let stop = Arc::new(AtomicBool::new(false));
    let cpu_before = cpu_seconds();
    let start = Instant::now();
    let senders = start_senders(servers, &frames, args, &stop)?;
    let shown = app
        .as_mut()
        .map(|w| follow_in_app(w, &senders, views.first()));
    let (sent, servers) = join_senders(senders)?;
    // The last frames are in flight for a few milliseconds.
    let settle = Instant::now() + Duration::from_secs(2);
    while views.iter().map(RobotFrames::len).sum::<usize>() < sent && Instant::now() < settle {
        std::thread::sleep(Duration::from_millis(5));
    }
    let wall = start.elapsed().as_secs_f64();
    let cpu_after = cpu_seconds();
    let mut report = report(
        args,
        &views,
        (width, height),
        sent,
        wall,
        cpu_before,
        cpu_after,
    );
    if let Some(mut shown) = shown {
        shown.sort_unstable();
        report.shown = Some(shown.len());
        report.shown_median_ms = Some(percentile_ms(&shown, 0.5));
        report.shown_p99_ms = Some(percentile_ms(&shown, 0.99));
    }
    drop(robots);
    drop(app);
    // The recordings were only there to cost what they cost.
    let _ = std::fs::remove_dir_all(&folder);
    for s in servers {
        s.stop();
    }
    print_report(&report, args.json)
}

/// Starts `args.robots` stand-in robots and connects to each, through a workspace with
/// `--app`, else as bare [`LiveRobot`]s keeping enough bytes for every frame of `pixels`.
fn connect_robots(
    args: &Args,
    pixels: usize,
) -> anyhow::Result<(Vec<StandInRobot>, Vec<LiveRobot>, Option<Workspace>)> {
    let mut servers = Vec::new();
    let mut robots = Vec::new();
    let mut app = args.app.then(Workspace::default);
    for i in 0..args.robots {
        let server = StandInRobot::start(&format!("bench{i}"), "127.0.0.1", 0)?;
        let url: RobotUrl = format!("127.0.0.1:{}", server.port()).parse()?;
        if let Some(w) = app.as_mut() {
            w.apply(Command::ConnectRobot(url.to_string()))?;
        } else {
            let keep = DEFAULT_KEEP_BYTES.max(frames_needed(args) * pixels * 2);
            robots.push(LiveRobot::connect(
                url,
                ClientOptions::default(),
                keep,
                None,
            )?);
        }
        servers.push(server);
    }
    Ok((servers, robots, app))
}

/// One thread per stand-in robot sending `frames` round and round at `args.fps` for
/// `args.seconds` (or until `stop`); each returns how many it sent and its robot.
fn start_senders(
    servers: Vec<StandInRobot>,
    frames: &Arc<Vec<FrameRecord>>,
    args: &Args,
    stop: &Arc<AtomicBool>,
) -> anyhow::Result<Vec<Sender>> {
    let senders = servers
        .into_iter()
        .enumerate()
        .map(|(i, mut server)| {
            let (frames, stop, fps, seconds) =
                (Arc::clone(frames), Arc::clone(stop), args.fps, args.seconds);
            std::thread::Builder::new()
                .name(format!("sender {i}"))
                .spawn(move || -> Result<(usize, StandInRobot), SendError> {
                    let period = Duration::from_secs_f64(1.0 / fps.max(0.1));
                    let t0 = Instant::now();
                    let mut n = 0_usize;
                    while t0.elapsed().as_secs_f64() < seconds && !stop.load(Ordering::Relaxed) {
                        let due = t0 + period * u32::try_from(n).unwrap_or(u32::MAX);
                        std::thread::sleep(due.saturating_duration_since(Instant::now()));
                        let Some(f) = frames.get(n % frames.len().max(1)) else {
                            break;
                        };
                        server.send(f)?;
                        n += 1;
                    }
                    Ok((n, server))
                })
        })
        .collect::<Result<_, _>>()
        .context("cannot start a sender thread")?;
    Ok(senders)
}

/// A sender thread: frames sent and its robot, or why sending failed.
type Sender = std::thread::JoinHandle<Result<(usize, StandInRobot), SendError>>;

/// Waits for every sender: the frames sent in all, and the robots back.
fn join_senders(senders: Vec<Sender>) -> anyhow::Result<(usize, Vec<StandInRobot>)> {
    let mut sent = 0;
    let mut servers = Vec::new();
    for s in senders {
        let (n, server) = s
            .join()
            .map_err(|_| anyhow::anyhow!("a sender thread panicked"))??;
        sent += n;
        servers.push(server);
    }
    Ok((sent, servers))
}

/// Ticks the workspace as the window does (when the shown robot's new frame wakes it, else every
/// [`APP_TICK`]) until every sender is done; the latency of each frame shown (sender's write to
/// the frame in the views), nanoseconds.
fn follow_in_app<T>(
    w: &mut Workspace,
    senders: &[std::thread::JoinHandle<T>],
    shown: Option<&RobotFrames>,
) -> Vec<u64> {
    // The shown robot's new frames wake the loop as they repaint the window.
    let (wake, woken) = std::sync::mpsc::sync_channel::<()>(1);
    w.set_wake(Arc::new(move || {
        let _ = wake.try_send(());
    }));
    let mut latencies = Vec::new();
    let mut last = None;
    while senders.iter().any(|s| !s.is_finished()) {
        let _ = woken.recv_timeout(APP_TICK);
        w.tick(APP_TICK);
        let index = w.index();
        if w.frame().is_some() && last != Some(index) {
            last = Some(index);
            if let Some(f) = shown.and_then(|v| v.frame(index)) {
                latencies.push(crate::live::unix_time_ns().saturating_sub(f.record.time_ns));
            }
        }
    }
    latencies
}

fn frames_needed(args: &Args) -> usize {
    let n = (args.fps.max(0.0) * args.seconds.max(0.0)).ceil() as usize;
    n + 30
}

fn report(
    args: &Args,
    robots: &[RobotFrames],
    (width, height): (usize, usize),
    sent: usize,
    wall: f64,
    cpu_before: (f64, f64),
    cpu_after: (f64, f64),
) -> LiveBenchJson {
    let mut latencies = Vec::new();
    let (mut received, mut drops) = (0, 0);
    for r in robots {
        received += r.len();
        drops += r.stats().drops;
        for i in r.first_kept()..r.len() {
            if let Some(f) = r.frame(i) {
                latencies.push(f.latency_ns);
            }
        }
    }
    latencies.sort_unstable();
    LiveBenchJson {
        robots: args.robots,
        fps: args.fps,
        width,
        height,
        sent,
        received,
        drops,
        latency_median_ms: percentile_ms(&latencies, 0.5),
        latency_p99_ms: percentile_ms(&latencies, 0.99),
        latency_max_ms: percentile_ms(&latencies, 1.0),
        receive_cpu_percent: 100.0 * (cpu_after.0 - cpu_before.0) / wall,
        process_cpu_percent: 100.0 * (cpu_after.1 - cpu_before.1) / wall,
        shown: None,
        shown_median_ms: None,
        shown_p99_ms: None,
    }
}

fn print_report(r: &LiveBenchJson, json: bool) -> anyhow::Result<()> {
    println!(
        "{} robots x {} fps, {}x{} frames: sent {}, received {}, dropped {}",
        r.robots, r.fps, r.width, r.height, r.sent, r.received, r.drops
    );
    println!(
        "latency write -> app state: median {:.2} ms, p99 {:.2} ms, max {:.2} ms",
        r.latency_median_ms, r.latency_p99_ms, r.latency_max_ms
    );
    if let (Some(n), Some(m), Some(p)) = (r.shown, r.shown_median_ms, r.shown_p99_ms) {
        println!(
            "latency write -> frame shown in the app's workspace ({n} frames): median {m:.2} ms, p99 {p:.2} ms"
        );
    }
    println!(
        "CPU: receiving {:.1}% of a core, whole process (with senders{}) {:.1}%",
        r.receive_cpu_percent,
        if r.shown.is_some() {
            ", the workspace's pipeline and recording"
        } else {
            ""
        },
        r.process_cpu_percent
    );
    if json {
        println!("{}", serde_json::to_string(r)?);
    }
    Ok(())
}
