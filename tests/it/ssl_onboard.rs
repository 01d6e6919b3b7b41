//! The table made for the SSL on-board camera (`lookup_tables/ssl-onboard.lut`, issue 29) and
//! recognition measured with it on the held-out frames of `../shared/data/ssl-onboard/` (frame
//! numbers ending in 7, 8 or 9, never looked at while the table and `params/ssl-onboard.json`
//! were made). The journal test needs nothing outside the repository; the seed's and the
//! figures' tests say "SKIPPED" when the frames are absent and fail under `CI=true`.

use std::path::{Path, PathBuf};

use eotn::lut::LookupTable;
use eotn::workspace::journal;
use serde_json::Value;

use crate::common::{eotn_ok, repo_file, shared_file};

use crate::ssl2008::clicks;

const TABLE: &str = "lookup_tables/ssl-onboard.lut";
const PARAMS: &str = "params/ssl-onboard.json";

#[test]
fn the_committed_journal_replays_to_the_committed_ssl_onboard_table() {
    let table = repo_file(TABLE);
    let saved = LookupTable::load(&table).expect("the committed table");
    let replay = journal::replay(&table).expect("the committed journal replays");
    assert!(replay.warnings.is_empty(), "{:?}", replay.warnings);
    let clicks = clicks::Clicks::load(&repo_file("params/ssl-onboard.clicks.json")).unwrap();
    // Every click is one commit after the seed (the journal's base, `…journal-base`).
    assert_eq!(replay.commits, clicks.len());
    assert!(
        journal::base_path(&table).exists(),
        "the seeded table is the journal's base"
    );
    assert!(
        replay.table.cells() == saved.cells(),
        "the journal's replay differs from {TABLE}"
    );
    // The journal holds real edits: undoing them all gives back the seed, which differs.
    let base = LookupTable::load(&journal::base_path(&table)).unwrap();
    assert!(base.cells() != saved.cells());
}

/// How the journal's base (the seed) is made, exactly as docs/recognition.md gives it:
/// `eotn lut-from-labels IMAGES --boxes LABELS-YOLO` with these options (the tuning frames
/// only, its default split).
pub const SEED_OPTIONS: [&str; 6] = [
    "--bits",
    "7",
    "--ball-core",
    "0.95",
    "--holdout-every",
    "1000",
];

/// The seed is the journal's first step, so it must be made again byte for byte from the
/// tuning frames' labels by the documented command.
#[test]
fn the_ssl_onboard_seed_is_made_again_byte_for_byte_from_the_tuning_labels() {
    let Some(root) = shared_file("data/ssl-onboard") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let seed = dir.path().join("seed.lut");
    let (images, labels) = (root.join("images"), root.join("labels-yolo"));
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "lut-from-labels".as_ref(),
        images.as_os_str(),
        "--boxes".as_ref(),
        labels.as_os_str(),
    ];
    args.extend(SEED_OPTIONS.iter().map(std::ffi::OsStr::new));
    args.extend(["-o".as_ref(), seed.as_os_str()]);
    eotn_ok(&args);
    let made = std::fs::read(&seed).unwrap();
    let base = std::fs::read(journal::base_path(&repo_file(TABLE))).unwrap();
    assert!(made == base, "the seed differs from {TABLE}.journal-base");
}

/// The clicks name tuning frames only: a held-out frame is refused before anything opens.
#[test]
fn the_ssl_onboard_clicks_name_no_held_out_frame() {
    let clicks = clicks::Clicks::load(&repo_file("params/ssl-onboard.clicks.json")).unwrap();
    let frames = clicks
        .frames(Path::new("frames"))
        .expect("no held-out frame");
    assert!(frames.len() >= 50, "{} frames clicked", frames.len());
}

fn eval(root: &Path, split: &str) -> Value {
    let labels: PathBuf = root.join("labels-yolo");
    let out = eotn_ok(&[
        "eval".as_ref(),
        root.join("images").as_os_str(),
        "--labels".as_ref(),
        labels.as_os_str(),
        "--lut".as_ref(),
        repo_file(TABLE).as_os_str(),
        "--params".as_ref(),
        repo_file(PARAMS).as_os_str(),
        "--split".as_ref(),
        split.as_ref(),
        "--json".as_ref(),
    ]);
    serde_json::from_slice(&out.stdout).expect("eval --json")
}

/// Held-out frame recall and precision of the finished table (measured 2026-12-07: 142/160 =
/// 88.8% recall, 142/146 = 97.3% precision; docs/recognition.md). The targets (95%,
/// 98%) are not reached, so the limits sit a little below what is reached (the project's rule),
/// and a change that loses a few balls or adds false ones fails; see the docs for what stands in
/// the way.
#[test]
fn held_out_ssl_onboard_frames_recall_and_precision() {
    let Some(root) = shared_file("data/ssl-onboard") else {
        return;
    };
    let r = &eval(&root, "held-out")["report"];
    let (eligible, found) = (
        r["eligible"].as_u64().unwrap(),
        r["found"].as_u64().unwrap(),
    );
    let (reported, correct) = (
        r["reported"].as_u64().unwrap(),
        r["correct"].as_u64().unwrap(),
    );
    eprintln!("held-out: recall {found}/{eligible}, precision {correct}/{reported}");
    assert_eq!(eligible, 160);
    assert!(found >= 138, "held-out recall {found}/160 (was 142)");
    assert!(
        correct * 100 >= reported * 95 && reported >= 138,
        "held-out precision {correct}/{reported} (was 142/146)"
    );
}
