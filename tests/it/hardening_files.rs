//! The second hardening round on files (issue 25): a crashed recording's `.partial` kept, one
//! writer per output, outputs that would overwrite each other, and the inputs of every kind that
//! a command reads refused or bounded. Outputs onto devices, FIFOs, links and folders are in
//! `outputs.rs`.

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{eotn, eotn_ok, repo_file};

/// Runs eotn, expects failure, returns its one `eotn:` line.
pub fn fails(args: &[&OsStr]) -> String {
    let out = eotn(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "eotn {args:?} should fail: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("eotn:")).collect();
    assert_eq!(lines.len(), 1, "one error line expected: {err}");
    lines[0].to_owned()
}

fn sim_into(out: &Path, frames: &str) -> std::process::Output {
    eotn(&[
        "sim".as_ref(),
        "--scenario".as_ref(),
        "ball-edge".as_ref(),
        "--frames".as_ref(),
        frames.as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ])
}

#[test]
fn a_crashed_recording_is_moved_aside_with_a_message_never_truncated() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rec.mcap");
    let partial = dir.path().join("rec.mcap.partial");
    // A recording cut off by a crash: the first three quarters of a stream.
    let whole = std::fs::read(repo_file("streams/sim-ball-edge.mcap")).unwrap();
    let crashed = whole[..whole.len() * 3 / 4].to_vec();
    std::fs::write(&partial, &crashed).unwrap();
    let o = sim_into(&out, "3");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    let aside = dir.path().join("rec.mcap.partial.1");
    assert!(
        err.contains(&aside.display().to_string()),
        "the message names where it went: {err}"
    );
    assert_eq!(
        std::fs::read(&aside).unwrap(),
        crashed,
        "the crashed part changed"
    );
    assert!(!partial.exists());
    assert_eq!(eotn::streams::StreamReader::open(&out).unwrap().len(), 3);
    // The moved file is still a stream by its name: `info` reads its frames.
    let info = eotn_ok(&["info".as_ref(), aside.as_os_str()]);
    assert!(String::from_utf8_lossy(&info.stdout).contains("kind: stream"));
}

#[test]
fn a_second_writer_of_an_output_being_recorded_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let served = crate::live::serve(
        &repo_file("streams/sim-ball-edge.mcap"),
        "127.0.0.1:0",
        &["--loop"],
    );
    let out = dir.path().join("live.mcap");
    let partial = dir.path().join("live.mcap.partial");
    let mut first = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .arg("record")
        .arg(format!("ws://127.0.0.1:{}", served.port))
        .args(["--seconds", "30", "-o"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while std::fs::metadata(&partial).map_or(0, |m| m.len()) == 0 {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "the first recorder never started"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let before = std::fs::metadata(&partial).unwrap().len();
    let o = sim_into(&out, "2");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("another eotn is writing"), "{err}");
    assert!(
        std::fs::metadata(&partial).unwrap().len() >= before,
        "the first recording was truncated"
    );
    assert!(
        !dir.path().join("live.mcap.partial.1").exists(),
        "the first recorder's file was moved away under it"
    );
    let _ = first.kill();
    let _ = first.wait();
    // Its file reads up to its last complete chunk.
    assert!(eotn::streams::StreamReader::open(&partial).is_ok());
}

#[test]
fn two_inputs_of_the_same_name_do_not_overwrite_each_others_output() {
    let dir = tempfile::tempdir().unwrap();
    for (folder, value) in [("a", 60u8), ("b", 200u8)] {
        std::fs::create_dir(dir.path().join(folder)).unwrap();
        std::fs::write(
            dir.path().join(folder).join("f.uyvy"),
            vec![value; 208 * 160 * 2],
        )
        .unwrap();
    }
    let out = dir.path().join("out");
    let err = fails(&[
        "export".as_ref(),
        dir.path().join("a/f.uyvy").as_os_str(),
        dir.path().join("b/f.uyvy").as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(err.contains("written already"), "{err}");
    // The first frame's picture is whole and is the first frame's.
    let png = image::open(out.join("f.uyvy.raw.png")).unwrap().to_rgb8();
    let first = eotn::frame::Frame::uyvy_from_fn(2, 1, |_, _| eotn::frame::Yuv::new(60, 60, 60))
        .unwrap()
        .to_rgb();
    assert_eq!(&png.as_raw()[..3], &first[..3]);
}
