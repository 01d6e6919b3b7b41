//! `eotn open FILE…`: opens the desktop app on streams, tables and frames. The app itself lives
//! in `crate::app` (feature `gui`); `main` starts it, so this file only holds the arguments.

use std::path::PathBuf;

/// Arguments of `eotn open`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Streams (`.mcap`), lookup tables (`.lut`), frames (`.uyvy`, `.png`, `.jpg`) or folders of
    /// frames; several frames open as one sequence to step through.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
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
