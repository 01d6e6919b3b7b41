//! Criterion benchmark of the edit journal: reopening a table whose journal holds 20,000 small
//! edits (what a long day of clicking gives), replayed into the table and its undo history —
//! the work the app does before it shows a table at start. Two kinds of small edit, alternating:
//! a sample pixel with ±1 cell (27 cells), and two cells picked in the U–V plane.
//!
//! And the worst a small journal can ask: 40 whole-table edits of an 8-bit table (a 7.9 KB
//! journal, 670 million cell writes), replayed with the undo history bounded by its bytes.
//!
//!     cargo bench --bench journal

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use eotn::frame::Yuv;
use eotn::lut::{ColourClass, EditRecord, Region, Sensitivity};
use eotn::workspace::journal::{self, JournalEntry};

/// Edits in the journal.
const EDITS: usize = 20_000;

/// The journal text of `EDITS` small edits on a 7-bit table, with an undo and a redo now and
/// then.
fn journal_text() -> String {
    let mut lines = vec![JournalEntry::Start {
        bits: 7,
        base: false,
        time_unix_ms: 0,
    }];
    for i in 0..EDITS {
        let class = ColourClass::ALL[1 + i % 8];
        let region = if i % 2 == 0 {
            Region::AroundSample {
                sample: Yuv::new(
                    (i * 7 % 256) as u8,
                    (i * 13 % 256) as u8,
                    (i * 29 % 256) as u8,
                ),
                sensitivity: Sensitivity::uniform(1),
            }
        } else {
            let cell = i * 7919 % (1 << 21);
            Region::Cells {
                indices: vec![cell, (cell + 1) % (1 << 21)],
            }
        };
        lines.push(JournalEntry::Commit {
            record: EditRecord {
                class,
                region,
                time_unix_ms: i as u64,
                sampled_at: None,
            },
        });
        if i % 50 == 49 {
            lines.push(JournalEntry::Undo { time_unix_ms: 0 });
            lines.push(JournalEntry::Redo { time_unix_ms: 0 });
        }
    }
    let mut text = String::new();
    for l in &lines {
        text.push_str(&serde_json::to_string(l).expect("json"));
        text.push('\n');
    }
    text
}

fn benches(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let table = dir.path().join("t.lut");
    std::fs::write(journal::journal_path(&table), journal_text()).expect("write");
    let mut group = c.benchmark_group("journal");
    group.sample_size(10);
    group.bench_function("replay_20000_small_edits", |b| {
        b.iter(|| {
            let r = journal::replay(black_box(&table)).expect("replays");
            assert_eq!(r.commits, EDITS);
            r
        });
    });
    let whole = dir.path().join("whole.lut");
    std::fs::write(journal::journal_path(&whole), whole_table_journal()).expect("write");
    group.bench_function("replay_40_whole_table_edits_8bit", |b| {
        b.iter(|| {
            let r = journal::replay(black_box(&whole)).expect("replays");
            assert_eq!(r.commits, 40);
            r
        });
    });
    // The same after a small edit and its undo: the replay cannot begin at a whole-table edit
    // (an undo comes before them), so all 40 are applied, as every replay did before.
    let undo_first = dir.path().join("undo-first.lut");
    std::fs::write(
        journal::journal_path(&undo_first),
        whole_table_journal_after(&[
            JournalEntry::Commit {
                record: EditRecord {
                    class: ColourClass::White,
                    region: Region::Cells { indices: vec![7] },
                    time_unix_ms: 0,
                    sampled_at: None,
                },
            },
            JournalEntry::Undo { time_unix_ms: 0 },
        ]),
    )
    .expect("write");
    group.bench_function("replay_40_whole_table_edits_8bit_from_the_start", |b| {
        b.iter(|| {
            let r = journal::replay(black_box(&undo_first)).expect("replays");
            assert_eq!(r.commits, 41);
            r
        });
    });
    group.finish();
}

/// A journal of 40 edits, each of the whole 8-bit table, alternating two classes.
fn whole_table_journal() -> String {
    whole_table_journal_after(&[])
}

/// [`whole_table_journal`] with `first` before the 40 edits.
fn whole_table_journal_after(first: &[JournalEntry]) -> String {
    let start = JournalEntry::Start {
        bits: 8,
        base: false,
        time_unix_ms: 0,
    };
    let mut text = serde_json::to_string(&start).expect("json");
    for e in first {
        text.push('\n');
        text.push_str(&serde_json::to_string(e).expect("json"));
    }
    for i in 0..40 {
        let record = EditRecord {
            class: [ColourClass::Orange, ColourClass::Green][i % 2],
            region: Region::AroundSample {
                sample: Yuv::new(128, 128, 128),
                sensitivity: Sensitivity::uniform(255),
            },
            time_unix_ms: i as u64,
            sampled_at: None,
        };
        text.push('\n');
        text.push_str(&serde_json::to_string(&JournalEntry::Commit { record }).expect("json"));
    }
    text
}

criterion_group!(journal_benches, benches);
criterion_main!(journal_benches);
