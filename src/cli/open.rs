//! `eotn open FILE…`: opens the desktop app on streams, tables and frames. The app itself lives
//! in `crate::app` (feature `gui`); `main` starts it with [`Args::run_options`], so this file
//! holds the arguments and their conversion into the app's [`RunOptions`].

use std::path::PathBuf;
use std::time::Duration;

use crate::app_options::{PlaySpeed, RendererSetting, RunOptions};

/// Arguments of `eotn open`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Streams (`.mcap`), lookup tables (`.lut`), frames (`.uyvy`, `.png`, `.jpg`) or folders of
    /// frames; several frames open as one sequence to step through. SSL-Vision's detections
    /// show in the field view: a league log (`GAME.log`, `GAME.log.gz`) or packets received
    /// live (`udp://224.5.23.2:10006`, the league's group; `udp://HOST:PORT` for a unicast port).
    /// A session file (`SESSION.json`) shows its overhead cameras on one field: the first as the
    /// stream, the field view with every camera's coverage and which cameras saw what.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// The renderer: `auto` (wgpu on a GPU, OpenGL on a software rasteriser), `wgpu` or `gl`.
    /// Given, it is saved for later starts; not given, the saved choice (else auto) is used.
    #[arg(long)]
    pub renderer: Option<RendererSetting>,
    /// Start playing at once.
    #[arg(long)]
    pub play: bool,
    /// Playback speed: `1x` (the recorded rate, late frames dropped), another factor, or
    /// `every` (every frame, as fast as the window can).
    #[arg(long, default_value = "1x", requires = "play")]
    pub speed: PlaySpeed,
    /// Switch every overlay on (blob boxes and labels, candidates, scan areas and points,
    /// circles, posts, gaps, horizon, object labels): the heaviest view, for benchmarks.
    #[arg(long)]
    pub all_overlays: bool,
    /// Close the window after this many seconds (for demos, scripts and benchmarks).
    #[arg(long, value_name = "SECONDS", value_parser = super::values::number_in(0.0, super::values::MAX_SECONDS))]
    pub quit_after: Option<f64>,
    /// Which camera of the recordings.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
    /// Boxed labels of the frames (a YOLO folder, a COCO JSON file or a Pascal VOC folder, as
    /// `eotn eval --labels`): drawn over each frame by class, recognition scored against them,
    /// the missed and false frames listed as events (Windows ▸ Events and bookmarks).
    #[arg(long, value_name = "LABELS")]
    pub labels: Option<PathBuf>,
    /// Send each overhead frame's detections as SSL-Vision packets over UDP to HOST:PORT (a
    /// unicast address, or the league's group 224.5.23.2:10006), camera 0, with the field and
    /// the calibration in use every few seconds, as `eotn overhead detect --ssl-vision` sends
    /// them (also in the app: Windows ▸ Overhead calibration, "Send SSL-Vision").
    #[arg(long, value_name = "HOST:PORT", value_parser = ssl_address)]
    pub ssl_vision: Option<String>,
}

impl Args {
    /// The app's start options from these arguments: `--speed` only with `--play`, a
    /// `--quit-after` that is negative or not finite ignored.
    #[must_use]
    pub fn run_options(&self) -> RunOptions {
        RunOptions {
            files: self.files.clone(),
            camera: self.camera.topic.clone(),
            renderer: self.renderer,
            play: self.play.then_some(self.speed),
            quit_after: self
                .quit_after
                .filter(|s| s.is_finite() && *s >= 0.0)
                .map(|s| Duration::from_secs_f64(s.min(1e9))),
            all_overlays: self.all_overlays,
            labels: self.labels.clone(),
            ssl_vision: self.ssl_vision.clone(),
        }
    }
}

/// `--ssl-vision`'s address, checked before the window opens: `HOST:PORT` that resolves, port
/// not 0.
fn ssl_address(text: &str) -> Result<String, String> {
    use std::net::ToSocketAddrs as _;
    let first = text
        .to_socket_addrs()
        .map_err(|e| {
            format!(
                "not HOST:PORT (e.g. {}): {e}",
                crate::ssl_vision::LEAGUE_ADDRESS
            )
        })?
        .next()
        .ok_or("the host has no address")?;
    if first.port() == 0 {
        return Err("port 0 is not a port to send to".to_owned());
    }
    Ok(text.to_owned())
}

/// Runs `eotn open` in a build without the app: there is nothing to open it with.
///
/// # Errors
/// Always: this build has no desktop app.
pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::bail!(
        "this eotn was built without the desktop app (cargo feature `gui`), so it cannot open {}",
        args.files
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    )
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Parser)]
    struct Open {
        #[command(flatten)]
        args: Args,
    }

    fn options(line: &[&str]) -> RunOptions {
        let open = Open::try_parse_from(std::iter::once("open").chain(line.iter().copied()))
            .expect("the arguments parse");
        open.args.run_options()
    }

    #[test]
    fn run_options_take_the_speed_only_with_play_and_a_quit_time_in_range() {
        let o = options(&["a.mcap", "--renderer", "gl", "--all-overlays"]);
        assert_eq!(o.files, vec![PathBuf::from("a.mcap")]);
        assert_eq!(o.renderer, Some(RendererSetting::Gl));
        assert_eq!(o.play, None);
        assert!(o.all_overlays);
        assert_eq!(o.quit_after, None);
        let o = options(&[
            "a.mcap",
            "--play",
            "--speed",
            "every",
            "--quit-after",
            "2.5",
        ]);
        assert_eq!(o.play, Some(PlaySpeed::Every));
        assert_eq!(o.quit_after, Some(Duration::from_millis(2500)));
        assert_eq!(
            options(&["a.mcap", "--play"]).play,
            Some(PlaySpeed::Times(1.0))
        );
        // A quit time outside its range is refused when the line is parsed, naming the range.
        for bad in ["--quit-after=-1", "--quit-after=NaN"] {
            let refused = Open::try_parse_from(["open", "a.mcap", bad]).err();
            let said = refused.map(|e| e.to_string()).unwrap_or_default();
            assert!(said.contains("must be a number from 0"), "{bad}: {said}");
        }
    }

    #[test]
    fn ssl_vision_takes_an_address_that_resolves() {
        let o = options(&["a.mcap", "--ssl-vision", "127.0.0.1:10006"]);
        assert_eq!(o.ssl_vision.as_deref(), Some("127.0.0.1:10006"));
        assert_eq!(options(&["a.mcap"]).ssl_vision, None);
        for bad in ["nowhere", "127.0.0.1:0", "127.0.0.1:99999"] {
            let refused = Open::try_parse_from(["open", "a.mcap", "--ssl-vision", bad]).err();
            let said = refused.map(|e| e.to_string()).unwrap_or_default();
            assert!(said.contains("--ssl-vision"), "{bad}: {said}");
        }
    }
}
