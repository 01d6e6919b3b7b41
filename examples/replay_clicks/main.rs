//! Makes a lookup table by replaying a hand classification's clicks (`*.clicks.json`) on a
//! frame, a stream or a folder of frames through the app's own commands, and saves it:
//!
//!   cargo run --example replay_clicks -- FRAME|STREAM CLICKS.json OUT.lut
//!   cargo run --example replay_clicks -- --onto FOLDER CLICKS.json SEED.lut [--save-as OUT.lut]
//!   cargo run --example replay_clicks -- --onto FOLDER CLICKS.json SEED.lut --look [--labels L]
//!       [--params P]
//!       [--hints N [--hint-range FIRST.jpg..LAST.jpg] [--hint-pngs DIR]] [--try CLASS:Y,U,V:FRAME:X,Y]...
//!
//! The first starts a new table. `--onto` opens every tuning frame of FOLDER (the held-out
//! ones, numbers ending in 7, 8 or 9, are never opened) and SEED.lut as it is (a table seeded
//! by `eotn lut-from-labels --boxes`), and clicks onto it as a user opening the seeded table in
//! the app would; then it saves the table where it is, or `--save-as` under another name (the
//! journal goes along: `OUT.lut.journal.jsonl` starts from the seed, kept as
//! `OUT.lut.journal-base`, and replays every click). `--look` saves nothing: it prints what the
//! app's windows would show after the clicks, for choosing the next ones — the opened labels'
//! report on the tuning frames (`--labels`), the coverage hints (what the table leaves
//! unclassified, most pixels first, with the frames showing the most of each), and for each
//! `--try` the whole-set preview of that click (the frames it changes) and the labels' report
//! with it committed.
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
mod look;

/// The command line, read by hand (an example has no clap).
#[derive(Default)]
struct Args {
    onto: bool,
    positional: Vec<PathBuf>,
    save_as: Option<PathBuf>,
    look: Option<look::Look>,
}

fn parse_args() -> anyhow::Result<Args> {
    let mut args = Args::default();
    let mut look = look::Look::default();
    let mut looking = false;
    let mut it = std::env::args_os().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .map(PathBuf::from)
                .with_context(|| format!("{name} needs a value"))
        };
        match a.to_str() {
            Some("--onto") => args.onto = true,
            Some("--save-as") => args.save_as = Some(value("--save-as")?),
            Some("--look") => looking = true,
            Some("--labels") => look.labels = Some(value("--labels")?),
            Some("--hints") => {
                let n = value("--hints")?;
                look.hints = n.to_string_lossy().parse().context("--hints N")?;
            }
            Some("--hint-range") => {
                let r = value("--hint-range")?.to_string_lossy().into_owned();
                let (a, b) = r.split_once("..").context("--hint-range FIRST..LAST")?;
                look.hint_range = Some((a.to_owned(), b.to_owned()));
            }
            Some("--params") => look.params = Some(value("--params")?),
            Some("--hint-pngs") => look.hint_pngs = Some(value("--hint-pngs")?),
            Some("--try") => look
                .tries
                .push(look::Try::parse(&value("--try")?.to_string_lossy())?),
            _ => args.positional.push(PathBuf::from(a)),
        }
    }
    if looking {
        args.look = Some(look);
    }
    Ok(args)
}

fn run(args: Args) -> anyhow::Result<()> {
    let [input, clicks, out] = args.positional.as_slice() else {
        anyhow::bail!(
            "usage: replay_clicks FRAME|STREAM CLICKS.json OUT.lut\n       \
             replay_clicks --onto FOLDER CLICKS.json SEED.lut [--save-as OUT.lut | --look ...]"
        );
    };
    let clicks = clicks::Clicks::load(clicks)?;
    let mut ws = Workspace::default();
    if !args.onto {
        let frames = if input.is_dir() {
            clicks.frames(input)?
        } else {
            vec![input.clone()]
        };
        ws.apply(Command::Open(frames))?;
        ws.apply(TableCommand::NewTable(clicks.bits).into())?;
        clicks.click(&mut ws, &[])?;
        ws.apply(TableCommand::SaveTableAs(out.clone()).into())?;
        return report(&ws, out, clicks.len());
    }
    // Every tuning frame, so the coverage hints, the previews and the labels see them all; the
    // clicks' frames are refused when held out.
    clicks.frames(input)?;
    let frames = clicks::Clicks::tuning_frames(input)?;
    ws.apply(Command::Open(frames.clone()))?;
    if let Some(look) = args.look {
        // Looking saves nothing: the seed is clicked on as a private copy, so no journal is
        // left beside it.
        let dir = tempfile::tempdir()?;
        let copy = dir.path().join("seed.lut");
        std::fs::copy(out, &copy).with_context(|| format!("{}", out.display()))?;
        ws.apply(Command::OpenTable(copy))?;
        clicks.click(&mut ws, &frames)?;
        eprintln!("{} clicks replayed", clicks.len());
        return look.print(&mut ws, &frames);
    }
    anyhow::ensure!(
        !journal::journal_path(out).exists(),
        "{} already has a journal: start from a freshly seeded table",
        out.display()
    );
    ws.apply(Command::OpenTable(out.clone()))
        .with_context(|| format!("opening {}", out.display()))?;
    clicks.click(&mut ws, &frames)?;
    let saved = match args.save_as {
        Some(to) => {
            ws.apply(TableCommand::SaveTableAs(to.clone()).into())?;
            to
        }
        None => {
            ws.apply(TableCommand::SaveTable.into())?;
            out.clone()
        }
    };
    report(&ws, &saved, clicks.len())
}

fn report(ws: &Workspace, out: &std::path::Path, clicks: usize) -> anyhow::Result<()> {
    for w in ws.warnings() {
        eprintln!("warning: {w}");
    }
    let counts = ws.lut().class_counts();
    eprintln!(
        "{}: {clicks} clicks, {} cells classified",
        out.display(),
        counts.iter().skip(1).sum::<usize>()
    );
    Ok(())
}

fn main() -> ExitCode {
    match parse_args().and_then(run) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("replay_clicks: {e:#}");
            ExitCode::FAILURE
        }
    }
}
