//! The command line as a user runs it: outputs, exit codes, one-line errors.

use std::ffi::OsStr;

use eotn::frame::{Frame, Yuv};
use eotn::lut::{ColourClass, EditRecord, LookupTable, Region, Sensitivity};

use crate::common::{eotn, eotn_ok};

fn orange_table(dir: &std::path::Path) -> std::path::PathBuf {
    let mut t = LookupTable::new(7).unwrap();
    t.apply(EditRecord::now(
        ColourClass::Orange,
        Region::AroundSample {
            sample: Yuv::new(120, 80, 190),
            sensitivity: Sensitivity::uniform(1),
        },
    ));
    let p = dir.join("t.lut");
    t.save(&p).unwrap();
    p
}

fn ball_frame(dir: &std::path::Path) -> std::path::PathBuf {
    // An orange patch on even column boundaries, so no UYVY pair mixes its chroma.
    let f = Frame::uyvy_from_fn(208, 160, |x, y| {
        if (92..110).contains(&x) && (70..90).contains(&y) {
            Yuv::new(120, 80, 190)
        } else {
            Yuv::new(90, 110, 110)
        }
    })
    .unwrap();
    let p = dir.join("ball.uyvy");
    std::fs::write(&p, f.data()).unwrap();
    p
}

#[test]
fn blobs_json_has_the_fixed_shape() {
    let dir = tempfile::tempdir().unwrap();
    let (lut, frame) = (orange_table(dir.path()), ball_frame(dir.path()));
    let out = eotn(&[
        OsStr::new("blobs"),
        frame.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
        OsStr::new("--json"),
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["frame"], "ball.uyvy");
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(208), Some(160))
    );
    assert_eq!(
        (v["lut_bits"].as_u64(), v["connectivity"].as_u64()),
        (Some(7), Some(8))
    );
    let blobs = v["blobs"].as_array().unwrap();
    assert_eq!(blobs.len(), 1);
    let b = &blobs[0];
    assert_eq!(b["colour"], 1);
    assert_eq!(
        (b["minx"].as_u64(), b["maxx"].as_u64()),
        (Some(92), Some(109))
    );
    assert_eq!(
        (b["miny"].as_u64(), b["maxy"].as_u64()),
        (Some(70), Some(89))
    );
    assert_eq!(b["pixels"].as_u64(), Some(18 * 20));
}

#[test]
fn bench_json_ends_with_medians() {
    let dir = tempfile::tempdir().unwrap();
    let (lut, frame) = (orange_table(dir.path()), ball_frame(dir.path()));
    let out = eotn_ok(&[
        OsStr::new("bench"),
        frame.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
        OsStr::new("--json"),
        OsStr::new("--reps"),
        OsStr::new("5"),
        OsStr::new("--warmup"),
        OsStr::new("1"),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    let last: serde_json::Value = serde_json::from_str(text.lines().last().unwrap()).unwrap();
    for key in ["classify_ns_per_px", "blobs_ns_per_px", "total_ns_per_px"] {
        assert!(
            last[key].as_f64().is_some_and(|v| v > 0.0),
            "{key} in {last}"
        );
    }
    let chosen = last["kernels"].as_str().unwrap_or_default();
    assert!(
        eotn::kernels::KernelSet::from_name(chosen).is_some(),
        "kernels in {last}"
    );
    // Every set this CPU can run was measured, the chosen one among them, portable first.
    let sets: Vec<&str> = last["sets"]
        .as_array()
        .map(|a| a.iter().filter_map(|s| s["kernels"].as_str()).collect())
        .unwrap_or_default();
    let runnable = eotn::kernels::runnable(eotn::kernels::cpu());
    assert_eq!(
        sets,
        runnable.iter().map(|s| s.name()).collect::<Vec<_>>(),
        "{last}"
    );
    assert!(sets.contains(&chosen), "{last}");
    assert!(text.contains("# cpu: "), "{text}");
}

#[test]
fn bad_input_exits_non_zero_with_one_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let lut = orange_table(dir.path());
    let bad = dir.path().join("short.uyvy");
    std::fs::write(&bad, [0u8; 999]).unwrap();
    let garbage = dir.path().join("garbage.lut");
    std::fs::write(&garbage, [0u8; 12]).unwrap();
    for args in [
        vec![
            OsStr::new("blobs"),
            bad.as_os_str(),
            OsStr::new("--lut"),
            lut.as_os_str(),
        ],
        vec![
            OsStr::new("classify"),
            bad.as_os_str(),
            OsStr::new("--lut"),
            garbage.as_os_str(),
        ],
        vec![OsStr::new("info"), garbage.as_os_str()],
    ] {
        let out = eotn(&args);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(
            err.contains("short.uyvy") || err.contains("garbage.lut"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn classify_writes_png_and_raw_codes() {
    let dir = tempfile::tempdir().unwrap();
    let (lut, frame) = (orange_table(dir.path()), ball_frame(dir.path()));
    let outdir = dir.path().join("out");
    let out = eotn_ok(&[
        OsStr::new("classify"),
        frame.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
        OsStr::new("-o"),
        outdir.as_os_str(),
        OsStr::new("--raw"),
        OsStr::new("--json"),
    ]);
    let codes = std::fs::read(outdir.join("ball.uyvy.cls")).unwrap();
    assert_eq!(codes.len(), 208 * 160);
    // Orange (code 1) exactly on the 18 × 20 patch of `ball_frame`, nowhere else; the JSON
    // count says the same.
    for (i, &c) in codes.iter().enumerate() {
        let (x, y) = (i % 208, i / 208);
        let inside = (92..110).contains(&x) && (70..90).contains(&y);
        assert_eq!(c == 1, inside, "pixel ({x}, {y}) has code {c}");
    }
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["pixels"]["orange"].as_u64(), Some(18 * 20));
    assert!(outdir.join("ball.uyvy.classified.png").exists());
}

#[test]
fn sources_lists_cameras_or_says_there_are_none_in_one_line_and_every_scenario() {
    let out = eotn_ok(&["sources".as_ref()]);
    let text = String::from_utf8(out.stdout).unwrap();
    let cameras = eotn::sources::available().cameras;
    if cameras.is_empty() {
        assert_eq!(
            text.lines()
                .filter(|l| l.contains("no camera found"))
                .count(),
            1,
            "{text}"
        );
    } else {
        for (path, _) in cameras {
            assert!(text.contains(&path.display().to_string()), "{text}");
        }
    }
    for k in eotn::sim::ScenarioKind::ALL {
        assert!(text.contains(k.name()), "{} missing: {text}", k.name());
    }
}

/// Every numeric option of the command line, found by walking its clap definition, refuses NaN,
/// infinities and absurd sizes before any work (`eotn::cli::values`): a number option added
/// later without a range fails here.
#[test]
fn every_numeric_option_refuses_nan_infinity_and_absurd_values() {
    use std::any::TypeId;
    fn walk(cmd: &clap::Command, path: &str, checked: &mut usize) {
        for arg in cmd.get_arguments() {
            let parser = arg.get_value_parser();
            let id = parser.type_id();
            let float = id == TypeId::of::<f64>() || id == TypeId::of::<f32>();
            let whole = [
                TypeId::of::<u8>(),
                TypeId::of::<u16>(),
                TypeId::of::<u32>(),
                TypeId::of::<u64>(),
                TypeId::of::<usize>(),
                TypeId::of::<i32>(),
                TypeId::of::<i64>(),
            ]
            .iter()
            .any(|t| id == *t);
            if !float && !whole {
                continue;
            }
            let name = format!("{path} --{}", arg.get_long().unwrap_or_default());
            // The option's own value parser, alone on a probe command (its relations to other
            // options left out).
            let probe = clap::Command::new("probe").arg(
                clap::Arg::new("v")
                    .long("v")
                    .value_parser(parser.clone())
                    .allow_hyphen_values(true),
            );
            let accepts = |v: &str| {
                probe
                    .clone()
                    .try_get_matches_from(["probe", "--v", v])
                    .is_ok()
            };
            for bad in ["NaN", "nan", "inf", "-inf", "1e300", "-1"] {
                assert!(!accepts(bad), "{name} accepts {bad}");
            }
            // Any seed is a seed; every other count has a ceiling.
            if arg.get_long() != Some("seed") {
                assert!(!accepts("18446744073709551615"), "{name} accepts 2^64 - 1");
            }
            if let Some(default) = arg.get_default_values().first() {
                assert!(
                    accepts(&default.to_string_lossy()),
                    "{name} refuses its own default {default:?}"
                );
            }
            *checked += 1;
        }
        for sub in cmd.get_subcommands() {
            walk(sub, &format!("{path} {}", sub.get_name()), checked);
        }
    }
    let mut checked = 0;
    walk(
        &<eotn::cli::Cli as clap::CommandFactory>::command(),
        "eotn",
        &mut checked,
    );
    assert!(checked >= 25, "only {checked} numeric options found");
}
