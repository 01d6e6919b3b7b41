//! `eotn sources`: what can be connected as a frame source here — cameras found (or one line
//! saying there are none) and the scenarios the synthetic source plays. Recorded streams and
//! frame files are opened by path.

use crate::sources::{SourceKind, available};

/// Arguments of `eotn sources`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `eotn sources`.
///
/// # Errors
/// Never; listing finds what is there.
pub fn run(_args: &Args) -> anyhow::Result<()> {
    let a = available();
    println!("{}:", SourceKind::Camera.name());
    match &a.camera_note {
        Some(note) => println!("  {note}"),
        None => {
            for (path, name) in &a.cameras {
                println!("  {:<15} {name}", path.display());
            }
        }
    }
    println!("{} (scenarios):", SourceKind::Synthetic.name());
    for k in &a.scenarios {
        println!("  {:<15} {}", k.name(), k.description());
    }
    println!(
        "{} and {}: open any .mcap stream or frame files (.uyvy, .png, .jpg) by path",
        SourceKind::Stream.name(),
        SourceKind::Files.name()
    );
    Ok(())
}
