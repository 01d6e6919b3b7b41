//! `eotn serve`: a stand-in robot, a Foxglove WebSocket server playing a stream at its recorded
//! rate, for the app, `eotn record` and Foxglove itself to connect to.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use anyhow::Context;

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
}

/// Runs `eotn serve` until the stream ends (or forever with `--loop`).
///
/// # Errors
/// The stream cannot be read, or the address cannot be listened on.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let mut reader = StreamReader::open(&args.stream)?;
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
    let mut robot = StandInRobot::start(&name, host, port)?;
    println!(
        "serving {} ({} frames) as '{name}' on ws://{host}:{}",
        args.stream.display(),
        reader.len(),
        robot.port()
    );
    let stop = AtomicBool::new(false);
    let sent = robot.play(&mut reader, args.looping, args.wait, &stop)?;
    // Let the last frames leave the server's queues before it closes.
    std::thread::sleep(std::time::Duration::from_millis(300));
    robot.stop();
    eprintln!("eotn serve: sent {sent} frames");
    Ok(())
}
