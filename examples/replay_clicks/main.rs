//! Makes a lookup table by replaying a hand classification's clicks (`*.clicks.json`) on a
//! frame, a stream or a folder of frames through the app's own commands, and saves it:
//!
//!   cargo run --example replay_clicks -- FRAME|STREAM CLICKS.json OUT.lut
//!   cargo run --example replay_clicks -- --onto FOLDER CLICKS.json TABLE.lut
//!
//! The first starts a new table. `--onto` opens TABLE.lut as it is (a table seeded by `eotn
//! lut-from-labels --boxes`) and clicks onto it, as a user opening the seeded table in the app
//! would: its journal (`TABLE.lut.journal.jsonl`, with the seeded table kept as
//! `TABLE.lut.journal-base`) records every click from the first, and replays to the saved table.
//! The groups name the frames of FOLDER they were clicked on; held-out frames are refused.
//!
//! `params/overhead/ssl-field-2008.clicks.json` is the classification of the real SSL 2008
//! overhead frame (docs/overhead.md); `params/ssl-onboard.clicks.json` the clicks onto the SSL
//! on-board table (docs/recognition.md).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use eotn::workspace::{Command, TableCommand, Workspace, journal};

#[allow(
    dead_code,
    reason = "shared by the example and the tests, each using a part of it"
)]
mod clicks;

fn main() -> ExitCode {
    let mut args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let onto = args.first().is_some_and(|a| a.as_os_str() == "--onto");
    if onto {
        args.remove(0);
    }
    let [input, clicks, out] = args.as_slice() else {
        eprintln!("usage: replay_clicks FRAME|STREAM CLICKS.json OUT.lut");
        eprintln!("       replay_clicks --onto FOLDER CLICKS.json TABLE.lut");
        return ExitCode::FAILURE;
    };
    let run = || -> anyhow::Result<()> {
        let clicks = clicks::Clicks::load(clicks)?;
        let mut ws = Workspace::default();
        let frames = if input.is_dir() {
            clicks.frames(input)?
        } else {
            vec![input.clone()]
        };
        ws.apply(Command::Open(frames.clone()))?;
        if onto {
            anyhow::ensure!(
                !journal::journal_path(out).exists(),
                "{} already has a journal: start from a freshly seeded table",
                out.display()
            );
            ws.apply(Command::OpenTable(out.clone()))
                .with_context(|| format!("opening {}", out.display()))?;
            clicks.click(&mut ws, &frames)?;
            ws.apply(TableCommand::SaveTable.into())?;
        } else {
            ws.apply(TableCommand::NewTable(clicks.bits).into())?;
            clicks.click(&mut ws, &frames)?;
            ws.apply(TableCommand::SaveTableAs(out.clone()).into())?;
        }
        for w in ws.warnings() {
            eprintln!("warning: {w}");
        }
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
