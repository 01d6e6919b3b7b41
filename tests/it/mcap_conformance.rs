//! MCAP as its specification says: every valid file of the MCAP conformance suite
//! (`tests/data/mcap-conformance/`, 416 files from foxglove/mcap with the records each holds)
//! opens through eotn's reader with no warning, its true counts, and its messages read back
//! byte for byte; and frames are found in every layout another writer may choose.

use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

use eotn::frame::{Frame, Yuv};
use eotn::streams::{
    ChannelSummary, RecordCounts, SchemaSummary, StreamReader, schema::ImageEncoding,
};
use serde_json::Value;

use crate::common::eotn_ok;

/// Valid variants in the suite (six inputs × the feature combinations that apply to each).
const VARIANTS: usize = 416;

fn suite_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mcap-conformance")
}

/// Every `.mcap` file of the suite, sorted.
fn suite_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for group in std::fs::read_dir(suite_dir()).unwrap() {
        let group = group.unwrap().path();
        if !group.is_dir() {
            continue;
        }
        for f in std::fs::read_dir(&group).unwrap() {
            let f = f.unwrap().path();
            if f.extension() == Some(OsStr::new("mcap")) {
                files.push(f);
            }
        }
    }
    files.sort();
    files
}

/// A message as the suite's expected JSON lists it (and as the reader gives it back).
#[derive(Debug, PartialEq, Eq)]
struct Message {
    channel: u16,
    sequence: u32,
    log_time: u64,
    publish_time: u64,
    data: Vec<u8>,
}

/// What a file holds according to its expected JSON: the records of its data section.
#[derive(Debug, Default)]
struct Expected {
    counts: RecordCounts,
    channels: Vec<ChannelSummary>,
    messages: Vec<Message>,
}

fn field<'a>(record: &'a Value, name: &str) -> &'a Value {
    let fields = record["fields"].as_array().unwrap();
    fields
        .iter()
        .find(|f| f[0] == name)
        .map_or(&Value::Null, |f| &f[1])
}

fn number<T: std::str::FromStr>(record: &Value, name: &str) -> T
where
    T::Err: std::fmt::Debug,
{
    field(record, name).as_str().unwrap().parse().unwrap()
}

fn text(record: &Value, name: &str) -> String {
    field(record, name).as_str().unwrap().to_owned()
}

fn bytes(record: &Value, name: &str) -> Vec<u8> {
    let items = field(record, name).as_array().unwrap();
    items
        .iter()
        .map(|b| b.as_str().unwrap().parse().unwrap())
        .collect()
}

/// Reads `NAME.json` beside `NAME.mcap`: schemas, channels, messages, attachments and metadata
/// before the Data End record (the summary only repeats them); one chunk when the variant has
/// feature `ch` (the generator puts all records of such a file in one chunk).
fn expected(mcap: &Path) -> Expected {
    let json: Value =
        serde_json::from_slice(&std::fs::read(mcap.with_extension("json")).unwrap()).unwrap();
    let features = json["meta"]["variant"]["features"].as_array().unwrap();
    let mut e = Expected::default();
    e.counts.chunks = u64::from(features.iter().any(|f| f == "ch"));
    let mut schemas = BTreeMap::new();
    let mut channels = BTreeMap::new();
    for r in json["records"].as_array().unwrap() {
        match r["type"].as_str().unwrap() {
            "DataEnd" => break,
            "Schema" => {
                let id: u16 = number(r, "id");
                let s = SchemaSummary {
                    name: text(r, "name"),
                    encoding: text(r, "encoding"),
                };
                schemas.entry(id).or_insert(s);
            }
            "Channel" => {
                let id: u16 = number(r, "id");
                let schema_id: u16 = number(r, "schema_id");
                channels.entry(id).or_insert_with(|| ChannelSummary {
                    id,
                    topic: text(r, "topic"),
                    message_encoding: text(r, "message_encoding"),
                    schema: schemas.get(&schema_id).cloned(),
                    message_count: 0,
                });
            }
            "Message" => e.messages.push(Message {
                channel: number(r, "channel_id"),
                sequence: number(r, "sequence"),
                log_time: number(r, "log_time"),
                publish_time: number(r, "publish_time"),
                data: bytes(r, "data"),
            }),
            "Attachment" => e.counts.attachments += 1,
            "Metadata" => e.counts.metadata += 1,
            _ => {}
        }
    }
    for m in &e.messages {
        channels.get_mut(&m.channel).unwrap().message_count += 1;
    }
    e.counts.messages = e.messages.len() as u64;
    e.counts.schemas = schemas.len() as u64;
    e.counts.channels = channels.len() as u64;
    e.channels = channels.into_values().collect();
    e
}

/// What is wrong with how the reader opens `path`, or `None` when it reads as expected.
fn check_file(path: &Path) -> Option<String> {
    let want = expected(path);
    let mut r = match StreamReader::open(path) {
        Ok(r) => r,
        Err(e) => return Some(format!("does not open: {e}")),
    };
    let mut problems = Vec::new();
    if !r.warnings().is_empty() {
        problems.push(format!("warnings {:?}", r.warnings()));
    }
    if r.counts() != want.counts {
        problems.push(format!("counts {:?}, want {:?}", r.counts(), want.counts));
    }
    if r.chunk_count() as u64 != want.counts.chunks {
        problems.push(format!("chunk_count {}", r.chunk_count()));
    }
    if r.channels() != want.channels.as_slice() {
        problems.push(format!(
            "channels {:?}, want {:?}",
            r.channels(),
            want.channels
        ));
    }
    let mut distinct = r.notes().to_vec();
    distinct.sort();
    distinct.dedup();
    if !r.is_empty()
        || !r.notes().iter().any(|n| n.contains("no camera frames"))
        || distinct.len() != r.notes().len()
    {
        problems.push(format!("{} frames, notes {:?}", r.len(), r.notes()));
    }
    let mut got = Vec::new();
    let read = r.for_each_message(|m| {
        got.push(Message {
            channel: m.channel,
            sequence: m.sequence,
            log_time: m.log_time_ns,
            publish_time: m.publish_time_ns,
            data: m.data.to_vec(),
        });
    });
    if let Err(e) = read {
        problems.push(format!("messages unreadable: {e}"));
    }
    if got != want.messages {
        problems.push(format!("messages {got:?}, want {:?}", want.messages));
    }
    (!problems.is_empty()).then(|| problems.join("; "))
}

/// The committed files are the suite's own bytes: each one's SHA-256 is the `oid` of its Git
/// LFS pointer in foxglove/mcap (listed in `SHA256SUMS`).
#[test]
fn suite_files_are_the_upstream_bytes() {
    let dir = suite_dir();
    assert_eq!(suite_files().len(), VARIANTS);
    let sums = std::fs::read_to_string(dir.join("SHA256SUMS")).unwrap();
    assert_eq!(sums.lines().count(), VARIANTS);
    let out = Command::new("sha256sum")
        .args(["--check", "--quiet", "SHA256SUMS"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every valid conformance file opens with no warning, the counts and channels its records
/// give, and every message's channel, sequence, times and data in file order.
#[test]
fn every_conformance_file_opens_with_its_true_counts() {
    let files = suite_files();
    assert_eq!(files.len(), VARIANTS);
    let failures: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let name = f.strip_prefix(suite_dir()).unwrap().display().to_string();
            check_file(f).map(|why| format!("{name}: {why}"))
        })
        .collect();
    println!(
        "MCAP conformance: {} of {} valid files open with their true counts and no warning",
        files.len() - failures.len(),
        files.len()
    );
    assert!(
        failures.is_empty(),
        "{} of {} files fail; the first:\n{}",
        failures.len(),
        files.len(),
        failures
            .iter()
            .take(12)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// `eotn info` on a file without camera frames lists its channels and counts and says it holds
/// no camera frames — no warning, no "cut off".
#[test]
fn info_lists_the_channels_of_a_file_without_frames() {
    let p = suite_dir().join("TenMessages/TenMessages-ch-chx-mx-rch-st-sum.mcap");
    let out = eotn_ok(&[OsStr::new("info"), OsStr::new("--json"), p.as_os_str()]);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["frames"], 0);
    assert_eq!(v["messages"], 10);
    assert_eq!(v["chunks"], 1);
    assert_eq!(v["schemas"], 1);
    assert_eq!(v["warnings"], serde_json::json!([]), "{v}");
    assert_eq!(v["channels"][0]["topic"], "example");
    assert_eq!(v["channels"][0]["schema"], "Example");
    assert_eq!(v["channels"][0]["messages"], 10);
    let human = eotn_ok(&[OsStr::new("info"), p.as_os_str()]);
    let text = String::from_utf8_lossy(&human.stdout);
    assert!(text.contains("no camera frames"), "{text}");
    assert!(text.contains("example") && text.contains("10"), "{text}");
    assert!(!text.contains("cut off"), "{text}");
}

/// One writer layout: the `mcap` crate's options a file is written with.
#[derive(Debug, Clone, Copy)]
struct Layout {
    chunks: bool,
    statistics: bool,
    repeat_schemas: bool,
    repeat_channels: bool,
    message_indexes: bool,
    chunk_indexes: bool,
    summary_offsets: bool,
}

/// A `foxglove.RawImage` stream from the `mcap` crate's writer (an independent MCAP writer)
/// in `layout`: frames on `/cam` with a JSON `/sensors` message after each, and a ROS-style
/// channel without schema in between; when chunked, a chunk every 7 frames (the reader takes a
/// frame's other messages from the image's own chunk, so a chunk never splits a frame here).
fn write_foreign(path: &Path, layout: Layout, frames: usize) {
    let options = mcap::WriteOptions::new()
        .use_chunks(layout.chunks)
        .chunk_size(None)
        .emit_statistics(layout.statistics)
        .repeat_schemas(layout.repeat_schemas)
        .repeat_channels(layout.repeat_channels)
        .emit_message_indexes(layout.message_indexes)
        .emit_chunk_indexes(layout.chunk_indexes)
        .emit_summary_offsets(layout.summary_offsets);
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = options.create(file).unwrap();
    let s = eotn::streams::schema::raw_image_schema().unwrap();
    let sid = w.add_schema(&s.name, &s.encoding, &s.data).unwrap();
    let cam = w
        .add_channel(sid, "/cam", "protobuf", &BTreeMap::new())
        .unwrap();
    let tf = w.add_channel(0, "/tf", "ros1", &BTreeMap::new()).unwrap();
    let sensors = w
        .add_channel(0, "/sensors", "json", &BTreeMap::new())
        .unwrap();
    let mut buf = Vec::new();
    for i in 0..frames {
        let t = 1_000 + i as u64 * 40;
        let f = Frame::filled_uyvy(16, 8, Yuv::new(20 + i as u8, 128, 128)).unwrap();
        eotn::streams::schema::encode_image(t, &f, ImageEncoding::Uyvy, &mut buf).unwrap();
        let header = |channel_id| mcap::records::MessageHeader {
            channel_id,
            sequence: i as u32,
            log_time: t,
            publish_time: t,
        };
        w.write_to_known_channel(&header(cam), &buf).unwrap();
        w.write_to_known_channel(&header(tf), &[1, 2, 3]).unwrap();
        let json = format!("{{\"head_pan_rad\": {}}}", i as f64 / 100.0);
        w.write_to_known_channel(&header(sensors), json.as_bytes())
            .unwrap();
        if i % 7 == 6 {
            w.flush().unwrap();
        }
    }
    w.finish().unwrap();
}

/// Frames are found and read in every layout the `mcap` crate writes — chunked or not, with or
/// without statistics, repeated schemas and channels, message and chunk indexes, summary offsets —
/// with their sensor readings, the true counts, and no warning.
#[test]
fn frames_are_read_in_every_writer_layout() {
    let dir = tempfile::tempdir().unwrap();
    let frames = 30;
    let mut layouts = 0;
    for bits in 0u32..128 {
        let on = |k: u32| bits & (1 << k) != 0;
        let layout = Layout {
            chunks: on(0),
            statistics: on(1),
            repeat_schemas: on(2),
            repeat_channels: on(3),
            message_indexes: on(4),
            chunk_indexes: on(5),
            summary_offsets: on(6),
        };
        if !layout.chunks && (layout.message_indexes || layout.chunk_indexes) {
            continue;
        }
        layouts += 1;
        let p = dir.path().join(format!("layout{bits}.mcap"));
        write_foreign(&p, layout, frames);
        let mut r = StreamReader::open(&p).unwrap();
        assert!(r.warnings().is_empty(), "{layout:?}: {:?}", r.warnings());
        let notes = r.notes().join("\n");
        assert_eq!(notes.matches("not written by eotn").count(), 1, "{notes}");
        assert_eq!(r.len(), frames, "{layout:?}");
        let c = r.counts();
        assert_eq!(
            (c.messages, c.channels, c.schemas),
            (90, 3, 1),
            "{layout:?}"
        );
        assert_eq!(c.chunks > 1, layout.chunks, "{layout:?}: {c:?}");
        let per_channel: Vec<(&str, u64)> = r
            .channels()
            .iter()
            .map(|c| (c.topic.as_str(), c.message_count))
            .collect();
        assert_eq!(
            per_channel,
            [("/cam", 30), ("/tf", 30), ("/sensors", 30)],
            "{layout:?}"
        );
        for i in [0, 17, 29, 1, 28] {
            let rec = r.read(i).unwrap();
            assert_eq!(rec.time_ns, 1_000 + i as u64 * 40, "{layout:?}");
            assert_eq!(rec.frame.pixel(3, 2).unwrap().y, 20 + i as u8, "{layout:?}");
            let pan = rec.sensors.and_then(|s| s.head_pan_rad);
            assert_eq!(pan, Some(i as f64 / 100.0), "{layout:?} frame {i}");
        }
    }
    assert_eq!(layouts, 80);
}

/// Reads everything the reader offers of a damaged file: it opens or fails naming the file, and
/// its frames and messages read or fail cleanly. Returns whether it opened with warnings.
fn read_all_of_damaged(path: &Path) -> Option<bool> {
    match StreamReader::open(path) {
        Err(e) => {
            assert!(e.to_string().contains("damaged.mcap"), "{e}");
            None
        }
        Ok(mut r) => {
            for i in 0..r.len() {
                if let Err(e) = r.read(i) {
                    assert!(e.to_string().contains("damaged.mcap"), "{e}");
                }
            }
            if let Err(e) = r.for_each_message(|_| {}) {
                assert!(e.to_string().contains("damaged.mcap"), "{e}");
            }
            Some(!r.warnings().is_empty())
        }
    }
}

/// A foreign file cut short anywhere, or with a byte changed anywhere, in the layouts that take
/// each path (summary alone; the data section walked, messages outside chunks): never a panic;
/// a cut file that opens says it was cut.
#[test]
fn damaged_foreign_files_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let full = Layout {
        chunks: true,
        statistics: true,
        repeat_schemas: true,
        repeat_channels: true,
        message_indexes: true,
        chunk_indexes: true,
        summary_offsets: true,
    };
    let loose = Layout {
        chunks: false,
        message_indexes: false,
        chunk_indexes: false,
        ..full
    };
    let damaged = dir.path().join("damaged.mcap");
    for layout in [full, loose] {
        let p = dir.path().join("whole.mcap");
        write_foreign(&p, layout, 8);
        let bytes = std::fs::read(&p).unwrap();
        for cut in (0..bytes.len()).step_by(5) {
            std::fs::write(&damaged, &bytes[..cut]).unwrap();
            if let Some(warned) = read_all_of_damaged(&damaged) {
                assert!(
                    warned,
                    "{layout:?}: cut at {cut} of {} unreported",
                    bytes.len()
                );
            }
        }
        for at in (0..bytes.len()).step_by(3) {
            let mut changed = bytes.clone();
            changed[at] ^= 0xa5;
            std::fs::write(&damaged, &changed).unwrap();
            read_all_of_damaged(&damaged);
        }
    }
}
