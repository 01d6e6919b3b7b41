//! Snapshots of `eotn detect --json` on the bundled streams (`insta`): any change of what
//! recognition finds shows as a reviewed diff of these files.
//!
//! Each snapshot is a compact summary, one line per frame: the JSON line with its timing, its
//! `body_` placements and its nulls dropped and its numbers rounded (radians to 0.001,
//! everything else to 0.1), so a refactor
//! that moves a value in its last bits does not show, and a real change does. The evidence
//! snapshots add every candidate's tests (name, outcome, effect) and rejections for two short
//! streams. Review a change with `cargo insta review` (or `INSTA_UPDATE=always` and `git diff`).

use std::fmt::Write as _;

use serde_json::Value;

use crate::common::{SHIPPED_ROBOT_SCENARIOS, eotn_ok, repo_file};

/// The parsed `eotn detect --json` lines of `stream` with `lut` (and `extra` arguments).
fn detect_lines(stream: &str, lut: &str, extra: &[&str]) -> Vec<Value> {
    let (stream, lut) = (repo_file(stream), repo_file(lut));
    let mut args: Vec<std::ffi::OsString> = vec![
        "detect".into(),
        stream.into(),
        "--lut".into(),
        lut.into(),
        "--json".into(),
    ];
    args.extend(extra.iter().map(std::ffi::OsString::from));
    let refs: Vec<&std::ffi::OsStr> = args.iter().map(std::ffi::OsString::as_os_str).collect();
    let out = eotn_ok(&refs);
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Rounds every number under `key` (radians to 0.001, the rest to 0.1); drops timings, the
/// body-relative copies of the camera-relative placements (one fixed transform away) and nulls.
fn compact(key: &str, v: &Value) -> Value {
    match v {
        Value::Number(n) if n.is_f64() => {
            let scale = if key.ends_with("_rad") { 1000.0 } else { 10.0 };
            let x = n.as_f64().unwrap_or(f64::NAN);
            let r = (x * scale).round() / scale;
            // -0.0 and 0.0 print alike.
            serde_json::Number::from_f64(r + 0.0).map_or(Value::Null, Value::Number)
        }
        Value::Array(items) => Value::Array(items.iter().map(|i| compact(key, i)).collect()),
        Value::Object(map) => Value::Object(
            map.iter()
                .filter(|(k, v)| {
                    let dropped = k.ends_with("_us")
                        || k.ends_with("_ns")
                        || *k == "timings"
                        || k.starts_with("body_")
                        || v.is_null();
                    !dropped
                })
                .map(|(k, v)| (k.clone(), compact(k, v)))
                .collect(),
        ),
        other => other.clone(),
    }
}

/// One line per frame: its index in the stream, then the rounded JSON without name and evidence.
fn summary(lines: &[Value]) -> String {
    let mut text = String::new();
    for (i, line) in lines.iter().enumerate() {
        let mut v = compact("", line);
        if let Value::Object(map) = &mut v {
            map.remove("frame");
            map.remove("evidence");
        }
        writeln!(text, "{i:03} {v}").unwrap();
    }
    text
}

/// `ok` for a passed test, `FAIL` for a failed one, `skip` for a skipped one, and the effect.
fn tests_line(confidence: &Value) -> String {
    let mut parts = Vec::new();
    for t in confidence["tests"].as_array().into_iter().flatten() {
        let outcome = match t["outcome"].as_str() {
            Some("passed") => "ok",
            Some("failed") => "FAIL",
            Some("skipped") => "skip",
            _ => "?",
        };
        let effect = t["effect"].as_f64().unwrap_or(f64::NAN);
        parts.push(format!(
            "{}:{outcome}{:+.1}",
            t["test"].as_str().unwrap_or("?"),
            effect + 0.0
        ));
    }
    parts.join(" ")
}

/// Every candidate of every frame: kind, index, box, accepted, tests, and any rejection.
fn evidence_summary(lines: &[Value]) -> String {
    let mut text = String::new();
    for (i, line) in lines.iter().enumerate() {
        let ev = &line["evidence"];
        let kinds = [
            ("ball", &ev["ball"]["candidates"]),
            ("goal", &ev["goals"]["candidates"]),
            ("beacon", &ev["beacons"]),
            ("pattern", &ev["patterns"]),
        ];
        for (kind, list) in kinds {
            for (j, c) in list.as_array().into_iter().flatten().enumerate() {
                let accepted = if c["accepted"].as_bool() == Some(true) {
                    "accepted"
                } else {
                    "rejected"
                };
                write!(
                    text,
                    "{i:03} {kind}#{j} {} {accepted}: {}",
                    compact("", &c["bounds"]),
                    tests_line(&c["confidence"])
                )
                .unwrap();
                if let Value::Object(map) = c {
                    for (k, v) in map.iter().filter(|(k, _)| k.contains("reject")) {
                        if !v.is_null() && v.as_array().is_none_or(|a| !a.is_empty()) {
                            write!(text, " | {k} {}", compact(k, v)).unwrap();
                        }
                    }
                }
                writeln!(text).unwrap();
            }
        }
    }
    text
}

#[test]
fn detect_on_the_bundled_simulated_streams_is_unchanged() {
    for scenario in SHIPPED_ROBOT_SCENARIOS {
        let lines = detect_lines(
            &format!("streams/sim-{scenario}.mcap"),
            "lookup_tables/sim.lut",
            &[],
        );
        insta::assert_snapshot!(format!("detect_sim_{scenario}"), summary(&lines));
    }
}

#[test]
fn detect_refuses_an_overhead_stream_and_names_the_overhead_command() {
    // The robot camera's recogniser on a top-down image reads the robots' marker dots as
    // beacons and the ball as 6 m away; the overhead stream has its own (tests/it/overhead.rs).
    let stream = repo_file("streams/sim-overhead-game.mcap");
    let lut = repo_file("lookup_tables/sim.lut");
    let out = crate::common::eotn(&[
        std::ffi::OsStr::new("detect"),
        stream.as_os_str(),
        std::ffi::OsStr::new("--lut"),
        lut.as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("overhead camera's stream"), "{err}");
    assert!(err.contains("eotn overhead detect"), "{err}");
    assert!(out.stdout.is_empty(), "no detections printed");
}

#[test]
fn detect_on_the_bundled_sample_is_unchanged() {
    let lines = detect_lines("streams/sample.mcap", "lookup_tables/sample.lut", &[]);
    insta::assert_snapshot!("detect_sample", summary(&lines));
}

#[test]
fn detect_on_the_bhuman_stream_is_unchanged() {
    let params = repo_file("params/spl2009.json");
    let params = params.to_str().unwrap();
    let lines = detect_lines(
        "streams/bhuman2009.mcap",
        "lookup_tables/bhuman2009.lut",
        &["--params", params],
    );
    insta::assert_snapshot!("detect_bhuman2009_spl2009", summary(&lines));
}

#[test]
fn detect_evidence_names_every_test_and_rejection_unchanged() {
    for scenario in ["walk-and-pan", "beacon-tour"] {
        let lines = detect_lines(
            &format!("streams/sim-{scenario}.mcap"),
            "lookup_tables/sim.lut",
            &["--evidence"],
        );
        insta::assert_snapshot!(
            format!("detect_evidence_sim_{scenario}"),
            evidence_summary(&lines)
        );
    }
}
