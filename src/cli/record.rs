//! `eotn record`: record live robots into MCAP streams, every message bit-exact and in order.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use anyhow::Context;

use crate::live::recorder::file_stem;
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
    /// Stop once every robot has sent this many frames.
    #[arg(long, value_parser = super::values::whole_in::<usize>(1, super::values::MAX_FRAMES))]
    pub frames: Option<usize>,
    /// Stop after this many seconds.
    #[arg(long, value_parser = super::values::number_in(0.0, super::values::MAX_SECONDS))]
    pub seconds: Option<f64>,
}

/// One robot's recording as the connection thread fills it.
struct Recording {
    url: RobotUrl,
    name: Option<String>,
    recorder: Option<LiveRecorder>,
    frames: usize,
    /// The frame limit was reached and the next frame began: nothing more is written.
    closed: bool,
    error: Option<String>,
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

fn on_event(rec: &mut Recording, naming: &Mutex<Naming>, limit: Option<usize>, event: LiveEvent) {
    match event {
        LiveEvent::Connected { server_name } => {
            if rec.name.is_some() {
                eprintln!("{}: reconnected ({server_name})", rec.url);
            } else {
                eprintln!("{}: connected to '{server_name}'", rec.url);
                let path = lock(naming).path_for(&server_name, &rec.url);
                let info = StreamInfo {
                    source: "robot".to_owned(),
                    description: format!("recorded live from {server_name} ({})", rec.url),
                };
                match LiveRecorder::create(&path, &info) {
                    Ok(r) => rec.recorder = Some(r),
                    Err(e) => rec.error = Some(e.to_string()),
                }
                rec.name = Some(server_name);
            }
        }
        LiveEvent::Disconnected { reason, retry_in } => {
            eprintln!(
                "{}: {reason}; reconnecting in {:.1} s",
                rec.url,
                retry_in.as_secs_f64()
            );
        }
        LiveEvent::Status(s) => eprintln!("{}: {s}", rec.url),
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
            if let Some(r) = rec.recorder.as_mut()
                && let Err(e) = r.message(&channel, log_time_ns, &payload)
            {
                rec.error = Some(e.to_string());
                rec.recorder = None;
            }
        }
    }
}

/// Runs `eotn record` until every robot sent `--frames` frames or `--seconds` passed.
///
/// # Errors
/// A bad address, an output that cannot be written, or a recording that failed.
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
        }));
        let client = RobotClient::spawn(url, ClientOptions::default(), {
            let (rec, naming, limit) = (Arc::clone(&rec), Arc::clone(&naming), args.frames);
            move |event| on_event(&mut lock(&rec), &naming, limit, event)
        })?;
        robots.push((client, rec));
    }
    let start = Instant::now();
    let deadline = args
        .seconds
        .map(|s| start + Duration::from_secs_f64(s.max(0.0)));
    loop {
        std::thread::sleep(Duration::from_millis(50));
        let mut all_full = args.frames.is_some();
        for (_, rec) in &robots {
            let mut rec = lock(rec);
            if let Some(r) = rec.recorder.as_mut()
                && let Err(e) = r.tick()
            {
                rec.error = Some(e.to_string());
                rec.recorder = None;
            }
            if let Some(e) = &rec.error {
                anyhow::bail!("{}: recording failed: {e}", rec.url);
            }
            all_full &= args.frames.is_some_and(|n| rec.frames >= n);
        }
        if all_full || deadline.is_some_and(|d| Instant::now() >= d) {
            break;
        }
    }
    finish(robots, start.elapsed())
}

fn finish(
    robots: Vec<(RobotClient, Arc<Mutex<Recording>>)>,
    elapsed: Duration,
) -> anyhow::Result<()> {
    for (client, rec) in robots {
        client.stop();
        let mut rec = lock(&rec);
        let name = rec.name.clone().unwrap_or_else(|| rec.url.to_string());
        match rec.recorder.take() {
            Some(r) => {
                let (frames, messages) = (r.frames(), r.messages());
                let path = r.finish()?;
                println!(
                    "{name}: {frames} frames, {messages} messages in {:.1} s -> {}",
                    elapsed.as_secs_f64(),
                    display(&path)
                );
            }
            None => eprintln!("{name}: never connected; nothing recorded"),
        }
    }
    Ok(())
}

fn display(path: &Path) -> String {
    path.display().to_string()
}
