//! `eotn record`: record live robots into MCAP streams, every message bit-exact and in order.
//!
//! It runs until every robot has sent `--frames` frames, `--seconds` have passed, or Ctrl+C /
//! SIGTERM; each recording is then finished (indexed) whatever the robots are doing: a robot
//! stuck in a handshake cannot hold it. A robot's file is made when its first message arrives;
//! one robot's failure (a name the file system refuses, a full disk) ends only its recording.
//! Nothing recorded at all is a failure (exit status 1), as is any robot's failed recording.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use anyhow::Context;

use super::bounds::{MAX_FRAMES, seconds};
use super::interrupt;
use crate::live::recorder::{MAX_CHANNELS, Recorded, file_stem};
use crate::live::{ClientOptions, LiveEvent, LiveRecorder, RobotClient, RobotUrl};
use crate::streams::{IMAGE_TOPIC, StreamInfo};

/// Arguments of `eotn record`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Robots: `ws://HOST:PORT` (or `HOST:PORT`), one or more.
    #[arg(required = true)]
    pub urls: Vec<String>,
    /// Output: the `.mcap` file for one robot; for several, a folder that gets one file per
    /// robot, named after its server name.
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: PathBuf,
    /// Stop once every robot has sent this many frames (1 to 100000000).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_FRAMES), allow_negative_numbers = true)]
    pub frames: Option<u64>,
    /// Stop after this many seconds (above 0, at most 604800: a week). Without `--frames` and
    /// `--seconds`, record until Ctrl+C or SIGTERM.
    #[arg(long, value_parser = seconds, allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Keep only this camera (image topic, e.g. `/camera/top`) and its own channels; repeat
    /// for several. Default: every camera the robot sends.
    #[arg(long = "camera", value_name = "TOPIC")]
    pub cameras: Vec<String>,
}

/// One robot's recording as the connection thread fills it.
struct Recording {
    url: RobotUrl,
    /// Its server name, once it said it.
    name: Option<String>,
    recorder: Option<LiveRecorder>,
    frames: u64,
    /// The frame limit was reached and the next frame began: nothing more is written.
    closed: bool,
    /// Why its recording ended early.
    error: Option<String>,
    /// The error was reported on stderr.
    reported: bool,
    /// `--camera`: the cameras kept (empty: every one).
    cameras: Vec<String>,
}

/// Where each robot's file goes; file names given out so far.
struct Naming {
    output: PathBuf,
    single: bool,
    taken: HashSet<String>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl Naming {
    fn path_for(&mut self, name: &str, url: &RobotUrl) -> PathBuf {
        if self.single {
            return self.output.clone();
        }
        let stem = file_stem(name, url);
        let mut candidate = stem.clone();
        let mut n = 2;
        while !self.taken.insert(candidate.clone()) {
            candidate = format!("{stem}-{n}");
            n += 1;
        }
        self.output.join(format!("{candidate}.mcap"))
    }
}

impl Recording {
    /// Writes one message, making the robot's file with its first.
    fn write(
        &mut self,
        naming: &Mutex<Naming>,
        channel: &Arc<crate::live::protocol::AdvertisedChannel>,
        log_time_ns: u64,
        payload: &[u8],
    ) {
        if self.error.is_some() {
            return;
        }
        if self.recorder.is_none() {
            let name = self.name.clone().unwrap_or_else(|| self.url.to_string());
            let path = lock(naming).path_for(&name, &self.url);
            let info = StreamInfo {
                source: "robot".to_owned(),
                description: format!("recorded live from {name} ({})", self.url),
            };
            match LiveRecorder::create(&path, &info) {
                Ok(r) => self.recorder = Some(r.only_cameras(self.cameras.clone())),
                Err(e) => {
                    self.error = Some(e.to_string());
                    return;
                }
            }
        }
        let Some(r) = self.recorder.as_mut() else {
            return;
        };
        match r.message(channel, log_time_ns, payload) {
            Ok(Recorded::Written | Recorded::OtherCamera) => {}
            Ok(Recorded::OverChannelLimit) => {
                if r.over_limit() == 1 {
                    eprintln!(
                        "{}: the recording holds {MAX_CHANNELS} channels: messages on later channels are not written",
                        self.url
                    );
                }
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }
}

fn on_event(rec: &mut Recording, naming: &Mutex<Naming>, limit: Option<u64>, event: LiveEvent) {
    match event {
        LiveEvent::Connected { server_name } => {
            if rec.name.is_some() {
                eprintln!("{}: reconnected ({server_name})", rec.url);
            } else {
                eprintln!("{}: connected to '{server_name}'", rec.url);
                rec.name = Some(server_name);
            }
        }
        LiveEvent::Disconnected {
            reason, retry_in, ..
        } => {
            eprintln!(
                "{}: {reason}; reconnecting in {:.1} s",
                rec.url,
                retry_in.as_secs_f64()
            );
        }
        LiveEvent::Status(s) => eprintln!("{}: {s}", rec.url),
        LiveEvent::Warning(w) => eprintln!("{}: {w}", rec.url),
        LiveEvent::Advertised(_) => {}
        LiveEvent::Message {
            channel,
            log_time_ns,
            payload,
            ..
        } => {
            let is_image = channel.topic == IMAGE_TOPIC;
            // After the last frame's image and its JSON nothing more is written.
            if is_image && limit.is_some_and(|n| rec.frames >= n) {
                rec.closed = true;
            }
            if rec.closed {
                return;
            }
            if is_image {
                rec.frames += 1;
            }
            rec.write(naming, &channel, log_time_ns, &payload);
        }
    }
}

/// Runs `eotn record` until every robot sent `--frames` frames, `--seconds` passed, or Ctrl+C /
/// SIGTERM.
///
/// # Errors
/// A bad address, an output that cannot be written, a recording that failed, or nothing
/// recorded.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let urls = args
        .urls
        .iter()
        .map(|u| u.parse::<RobotUrl>())
        .collect::<Result<Vec<_>, _>>()?;
    let single = urls.len() == 1;
    if !single {
        crate::atomic_file::output_folder(&args.output)
            .with_context(|| format!("{}", args.output.display()))?;
    }
    let interrupted = interrupt::catch("finishing the recordings")?;
    let naming = Arc::new(Mutex::new(Naming {
        output: args.output.clone(),
        single,
        taken: HashSet::new(),
    }));
    let mut robots = Vec::new();
    for url in urls {
        let rec = Arc::new(Mutex::new(Recording {
            url: url.clone(),
            name: None,
            recorder: None,
            frames: 0,
            closed: false,
            error: None,
            reported: false,
            cameras: args.cameras.clone(),
        }));
        let client = RobotClient::spawn(url, ClientOptions::default(), {
            let (rec, naming, limit) = (Arc::clone(&rec), Arc::clone(&naming), args.frames);
            move |event| on_event(&mut lock(&rec), &naming, limit, event)
        })?;
        robots.push((client, rec));
    }
    let start = Instant::now();
    let deadline = args.seconds.map(|s| start + Duration::from_secs_f64(s));
    loop {
        std::thread::sleep(Duration::from_millis(50));
        if tick(&robots, args.frames) || deadline.is_some_and(|d| Instant::now() >= d) {
            break;
        }
        if interrupted.is_set() {
            break;
        }
    }
    finish(robots, start.elapsed())
}

/// Closes idle chunks and reports failed recordings; true when every robot has its frames (or
/// has failed).
fn tick(robots: &[(RobotClient, Arc<Mutex<Recording>>)], frames: Option<u64>) -> bool {
    let mut all_full = frames.is_some();
    for (_, rec) in robots {
        let mut rec = lock(rec);
        if let Some(r) = rec.recorder.as_mut()
            && let Err(e) = r.tick()
        {
            rec.error = Some(e.to_string());
        }
        if let Some(e) = rec.error.clone()
            && !rec.reported
        {
            eprintln!("{}: recording failed: {e}", rec.url);
            rec.reported = true;
        }
        all_full &= rec.error.is_some() || frames.is_some_and(|n| rec.frames >= n);
    }
    all_full
}

/// Stops every connection (without waiting on any robot for long) and finishes each file.
fn finish(
    robots: Vec<(RobotClient, Arc<Mutex<Recording>>)>,
    elapsed: Duration,
) -> anyhow::Result<()> {
    let mut failed = Vec::new();
    let mut recorded = 0;
    for (client, _) in &robots {
        client.request_stop();
    }
    for (client, rec) in robots {
        client.stop();
        let mut rec = lock(&rec);
        let name = rec.name.clone().unwrap_or_else(|| rec.url.to_string());
        let result = rec
            .recorder
            .take()
            .map(|r| (r.frames(), r.messages(), r.finish()));
        match (result, rec.error.take()) {
            (Some((frames, messages, Ok(path))), error) => {
                recorded += 1;
                println!(
                    "{name}: {frames} frames, {messages} messages in {:.1} s -> {}",
                    elapsed.as_secs_f64(),
                    display(&path)
                );
                if let Some(e) = error {
                    failed.push(format!("{name}: {e}"));
                }
            }
            (Some((.., Err(e))), _) => failed.push(format!("{name}: {e}")),
            (None, Some(e)) => failed.push(format!("{name}: {e}")),
            (None, None) if rec.name.is_some() => {
                eprintln!("{name}: connected, but sent nothing; no file written");
            }
            (None, None) => eprintln!("{name}: never connected; nothing recorded"),
        }
    }
    if !failed.is_empty() {
        anyhow::bail!("recording failed: {}", failed.join("; "));
    }
    anyhow::ensure!(
        recorded > 0,
        "nothing was recorded: no robot sent a message in {:.1} s",
        elapsed.as_secs_f64()
    );
    Ok(())
}

fn display(path: &Path) -> String {
    path.display().to_string()
}
