//! How the desktop app starts: the files it opens, the renderer, playing at once. Plain data the
//! command line fills in (`cli::open::Args::run_options`) and the app reads (`app::run`), so
//! the app does not depend on the command line. Built with or without the `gui` feature.

use std::path::PathBuf;
use std::time::Duration;

/// Which renderer draws the window (`--renderer`); saved for the next start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum RendererSetting {
    /// wgpu where it finds a GPU, OpenGL where it finds only a software rasteriser or nothing.
    #[default]
    Auto,
    /// Always wgpu (Vulkan, Metal, DX12).
    Wgpu,
    /// Always OpenGL (eframe's glow renderer).
    Gl,
}

impl RendererSetting {
    /// The name on the command line and in the saved setting.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Wgpu => "wgpu",
            Self::Gl => "gl",
        }
    }
}

impl std::str::FromStr for RendererSetting {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "auto" => Ok(Self::Auto),
            "wgpu" => Ok(Self::Wgpu),
            "gl" => Ok(Self::Gl),
            other => Err(format!("unknown renderer '{other}' (auto, wgpu, gl)")),
        }
    }
}

/// How fast `--play` plays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlaySpeed {
    /// At this many times the recorded rate (`1x`, `0.5x`, `2x`): frames that are not ready in
    /// time are dropped, as a video player does.
    Times(f32),
    /// Every frame, as fast as the window can show them (`every`).
    Every,
}

impl PlaySpeed {
    /// The app's speed setting: × recorded rate, 0 for every frame.
    #[must_use]
    pub const fn as_factor(self) -> f32 {
        match self {
            Self::Times(f) => f,
            Self::Every => 0.0,
        }
    }
}

impl std::str::FromStr for PlaySpeed {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "every" {
            return Ok(Self::Every);
        }
        let f: f32 = s
            .strip_suffix('x')
            .unwrap_or(s)
            .parse()
            .map_err(|_| format!("speed '{s}' is not 'every' or a factor like 1x, 0.5x"))?;
        if f.is_finite() && f > 0.0 && f <= 64.0 {
            Ok(Self::Times(f))
        } else {
            Err(format!("speed '{s}' must be between 0 and 64 times"))
        }
    }
}

/// How the window starts: `eotn open` and its options (`cli::open::Args::run_options`), or
/// nothing given (the last session).
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Streams, frames, tables to open; none reopens the last session.
    pub files: Vec<PathBuf>,
    /// `--renderer`: saved and used when given; else the saved setting, else auto.
    pub renderer: Option<RendererSetting>,
    /// `--play [--speed]`: start playing at once at this speed.
    pub play: Option<PlaySpeed>,
    /// `--quit-after`: close the window after this long.
    pub quit_after: Option<Duration>,
    /// `--all-overlays`: every overlay on.
    pub all_overlays: bool,
    /// `--camera`: the camera (image topic) of the recordings to show; `None`: the first.
    pub camera: Option<String>,
    /// `--labels`: a label set (YOLO or VOC folder, COCO JSON) opened over the frames.
    pub labels: Option<PathBuf>,
    /// `--ssl-vision HOST:PORT`: the overhead detections sent as SSL-Vision packets there.
    pub ssl_vision: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_parse_as_factors_or_every() {
        assert_eq!("1x".parse(), Ok(PlaySpeed::Times(1.0)));
        assert_eq!("0.5x".parse(), Ok(PlaySpeed::Times(0.5)));
        assert_eq!("2".parse(), Ok(PlaySpeed::Times(2.0)));
        assert_eq!("every".parse(), Ok(PlaySpeed::Every));
        assert!("0x".parse::<PlaySpeed>().is_err());
        assert!("NaNx".parse::<PlaySpeed>().is_err());
        assert!("1e300x".parse::<PlaySpeed>().is_err());
    }

    #[test]
    fn renderer_names_round_trip() {
        for s in [
            RendererSetting::Auto,
            RendererSetting::Wgpu,
            RendererSetting::Gl,
        ] {
            assert_eq!(s.name().parse(), Ok(s));
        }
        assert!("vulkan".parse::<RendererSetting>().is_err());
    }
}
