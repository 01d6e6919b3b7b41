//! `eotn open FILE…`: opens the desktop app on streams, tables and frames. The app itself lives
//! in `crate::app` (feature `gui`); `main` starts it, so this file only holds the arguments.

use std::path::PathBuf;

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

/// Arguments of `eotn open`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Streams (`.mcap`), lookup tables (`.lut`), frames (`.uyvy`, `.png`, `.jpg`) or folders of
    /// frames; several frames open as one sequence to step through.
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
