//! `eotn serve`: a stand-in robot, a Foxglove WebSocket server playing a stream at its recorded
//! rate, for the app, `eotn record` and Foxglove itself to connect to. It ends when the stream
//! does (never with `--loop`) or on Ctrl+C / SIGTERM, saying what its gate did: viewers served
//! and refused, handshakes closed, frames dropped for slow viewers.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;

use super::bounds::deadline_seconds;
use super::interrupt;
use crate::live::gate::{GateFigures, GateOptions};
use crate::live::serve::StandInRobot;
use crate::streams::StreamReader;

/// Arguments of `eotn serve`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The stream to play (`.mcap`, e.g. one made by `eotn sim`).
    pub stream: PathBuf,
    /// Address to listen on, HOST:PORT (port 0: any free port, printed at start).
    #[arg(long, default_value = "127.0.0.1:8765")]
    pub listen: String,
    /// Play the stream again and again.
    #[arg(long = "loop")]
    pub looping: bool,
    /// Server name viewers see (and `eotn record` names its files after); default: the stream's
    /// file name.
    #[arg(long)]
    pub name: Option<String>,
    /// Wait for the first viewer to subscribe before sending the first frame.
    #[arg(long)]
    pub wait: bool,
    /// Viewers connected at once (1 to 4096); the next is refused with a close reason.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u16).range(1..=4096), allow_negative_numbers = true)]
    pub max_clients: u16,
    /// Seconds a new connection has to finish its WebSocket handshake (above 0, at most 600).
    #[arg(long, default_value_t = 5.0, value_parser = deadline_seconds, allow_negative_numbers = true)]
    pub handshake_timeout: f64,
    /// Which camera of the recordings.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
}

/// Runs `eotn serve` until the stream ends (or forever with `--loop`).
///
/// # Errors
/// The stream cannot be read, or the address cannot be listened on.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let mut reader = StreamReader::open_camera(&args.stream, args.camera.get())?;
    let (host, port) = args
        .listen
        .rsplit_once(':')
        .and_then(|(h, p)| Some((h.trim_matches(['[', ']']), p.parse::<u16>().ok()?)))
        .with_context(|| format!("--listen {}: expected HOST:PORT", args.listen))?;
    let name = args.name.clone().unwrap_or_else(|| {
        args.stream
            .file_stem()
            .map_or_else(|| "eotn".to_owned(), |s| s.to_string_lossy().into_owned())
    });
    let options = GateOptions {
        max_clients: usize::from(args.max_clients),
        handshake_timeout: Duration::from_secs_f64(args.handshake_timeout),
        ..GateOptions::default()
    };
    let mut robot = StandInRobot::start_with(&name, host, port, options)?;
    println!(
        "serving {} ({} frames) as '{name}' on ws://{host}:{}",
        args.stream.display(),
        reader.len(),
        robot.port()
    );
    let interrupted = interrupt::catch("stopping")?;
    let played = robot.play(&mut reader, args.looping, args.wait, interrupted.flag());
    // Let the last frames leave the server's queues before it closes.
    std::thread::sleep(Duration::from_millis(300));
    let skipped = robot.skipped();
    let figures = robot.stop();
    let sent = played?;
    eprintln!(
        "eotn serve: sent {sent} frames{}",
        summary(&figures, skipped)
    );
    Ok(())
}

/// What the gate did, for the last line.
fn summary(f: &GateFigures, skipped: usize) -> String {
    let mut parts = vec![format!("{} viewers served", f.served)];
    let counts = [
        (f.refused, "refused (--max-clients)"),
        (f.handshake_timeouts, "handshakes timed out"),
        (f.handshake_failures, "handshakes failed"),
        (f.evicted, "unfinished handshakes closed for room"),
        (f.overflowed, "viewers disconnected for not reading"),
        (f.accept_errors, "accept errors (retried)"),
    ];
    parts.extend(
        counts
            .iter()
            .filter(|(n, _)| *n > 0)
            .map(|(n, what)| format!("{n} {what}")),
    );
    parts.push(format!(
        "{} frames dropped for slow viewers",
        f.dropped_frames
    ));
    if skipped > 0 {
        parts.push(format!("{skipped} unreadable frames skipped"));
    }
    format!("; {}", parts.join(", "))
}
