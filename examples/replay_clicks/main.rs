//! Makes a lookup table by replaying a hand classification's clicks (`*.clicks.json`) on a
//! frame or stream through the app's own commands, and saves it:
//!
//!   cargo run --example replay_clicks -- FRAME|STREAM CLICKS.json OUT.lut
//!
//! `params/overhead/ssl-field-2008.clicks.json` is the classification of the real SSL 2008
//! overhead frame (docs/overhead.md).

use std::path::PathBuf;
use std::process::ExitCode;

use eotn::workspace::{Command, TableCommand, Workspace};

mod clicks;

fn main() -> ExitCode {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [input, clicks, out] = args.as_slice() else {
        eprintln!("usage: replay_clicks FRAME|STREAM CLICKS.json OUT.lut");
        return ExitCode::FAILURE;
    };
    let run = || -> anyhow::Result<()> {
        let clicks = clicks::Clicks::load(clicks)?;
        let mut ws = Workspace::default();
        ws.apply(Command::Open(vec![input.clone()]))?;
        clicks.replay(&mut ws)?;
        ws.apply(TableCommand::SaveTableAs(out.clone()).into())?;
        let counts = ws.lut().class_counts();
        eprintln!(
            "{}: {} clicks, {} cells classified",
            out.display(),
            clicks.len(),
            counts.iter().skip(1).sum::<usize>()
        );
        Ok(())
    };
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("replay_clicks: {e:#}");
            ExitCode::FAILURE
        }
    }
}
