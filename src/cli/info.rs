//! `eotn info`: what a file is — lookup table, frame, or recording (MCAP stream, ROS 2 bag).

use std::path::PathBuf;

use super::inputs::{is_frame_file, load_frame_arg, parse_size};
use crate::lut::{ColourClass, LookupTable};
use crate::streams::{StreamReader, is_recording};

/// Arguments of `eotn info`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Lookup tables (`.lut`), frames (`.uyvy`, `.png`, `.jpg`) and recordings: MCAP streams
    /// (`.mcap`), ROS 2 bags (a folder with `metadata.yaml`, or its `.db3`/`.mcap` file).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Frame size of raw files, WxH; 208x160 and 640x480 are inferred.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// Print one JSON object per file per line.
    #[arg(long)]
    pub json: bool,
    /// The camera (image topic) of recordings to describe (`frames`, `width`, …); default: the
    /// first. Every camera is listed under `cameras` whichever is chosen.
    #[arg(long, value_name = "TOPIC")]
    pub camera: Option<String>,
}

/// Runs `eotn info`.
///
/// # Errors
/// An unreadable or malformed file, naming it.
pub fn run(args: &Args) -> anyhow::Result<()> {
    for path in &args.files {
        let value = if is_recording(path) || path.is_dir() {
            // A folder is a ROS 2 bag or nothing `info` describes: the reader says which.
            stream_info(path, args.camera.as_deref())?
        } else if is_frame_file(path) {
            let f = load_frame_arg(path, args.size)?;
            serde_json::json!({
                "file": path.display().to_string(), "kind": "frame",
                "width": f.width(), "height": f.height(), "layout": format!("{:?}", f.layout()),
            })
        } else {
            let lut = LookupTable::load(path)?;
            let counts = lut.class_counts();
            let classes: serde_json::Map<String, serde_json::Value> = ColourClass::ALL
                .iter()
                .zip(counts)
                .filter(|(_, n)| *n > 0)
                .map(|(c, n)| (c.name().to_owned(), n.into()))
                .collect();
            serde_json::json!({
                "file": path.display().to_string(), "kind": "lookup_table",
                "bits": lut.bits(), "cells": lut.cells().len(), "cells_per_class": classes,
            })
        };
        if args.json {
            outln!("{value}");
        } else {
            print_human(&value);
        }
    }
    Ok(())
}

/// Every camera of a recording: topic, frames, and the size and encoding of its first
/// readable frame (`null` when none reads), its first and last times and frame rate; every size
/// when it changes mid-recording. With several cameras, the lines worth a warning: a camera
/// whose frame size changes, one that ends (or begins) well before (after) the others, and
/// cameras at different frame rates — each shown as it is, never matched by frame number.
fn cameras(reader: &StreamReader) -> anyhow::Result<(Vec<serde_json::Value>, Vec<String>)> {
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    // (topic, first ns, last ns, frames per second) of each camera with frames.
    let mut spans: Vec<(String, u64, u64, Option<f64>)> = Vec::new();
    for t in reader.image_topics() {
        let mut one = StreamReader::open_camera(reader.path(), Some(&t.topic))?;
        let n = one.len();
        let first = (0..n).find_map(|i| one.read_with_image(i).ok().map(|r| (i, r)));
        let (width, height, encoding) =
            first
                .as_ref()
                .map_or((None, None, None), |(_, (r, image))| {
                    (
                        Some(r.frame.width()),
                        Some(r.frame.height()),
                        Some(image.encoding().to_owned()),
                    )
                });
        let mut one_value = serde_json::json!({
            "topic": t.topic, "frames": n,
            "width": width, "height": height, "encoding": encoding,
        });
        if let (Some(a), Some(b)) = (
            one.time_ns(0),
            n.checked_sub(1).and_then(|i| one.time_ns(i)),
        ) {
            let fps = (n > 1 && b > a).then(|| duration_and_rate(b - a, n).1);
            one_value["first_time_ns"] = a.into();
            one_value["last_time_ns"] = b.into();
            one_value["fps"] = fps.into();
            spans.push((t.topic.clone(), a, b, fps));
        }
        if let Some((i, _)) = first {
            let sizes = frame_sizes(&mut one, i);
            if sizes.len() > 1 {
                let list: Vec<String> = sizes
                    .iter()
                    .map(|((w, h), k)| format!("{w}x{h}: {k} frames"))
                    .collect();
                warnings.push(format!(
                    "camera {}: the frame size changes mid-recording ({})",
                    t.topic,
                    list.join(", ")
                ));
                one_value["sizes"] = list.into();
            }
        }
        out.push(one_value);
    }
    warnings.extend(span_warnings(&spans));
    Ok((out, warnings))
}

/// With several cameras: one that ends (or begins) more than a second before (after) the
/// others, and cameras at frame rates more than 5% apart.
fn span_warnings(spans: &[(String, u64, u64, Option<f64>)]) -> Vec<String> {
    let mut out = Vec::new();
    if spans.len() < 2 {
        return out;
    }
    let end = spans.iter().map(|s| s.2).max().unwrap_or(0);
    let start = spans.iter().map(|s| s.1).min().unwrap_or(0);
    for (topic, a, b, _) in spans {
        if end - b > 1_000_000_000 {
            out.push(format!(
                "camera {topic} ends {:.2} s before the recording's last frame: side by side it shows its last frame, marked as ended",
                (end - b) as f64 / 1e9
            ));
        }
        if a - start > 1_000_000_000 {
            out.push(format!(
                "camera {topic} begins {:.2} s after the recording's first frame",
                (a - start) as f64 / 1e9
            ));
        }
    }
    let rates: Vec<(&str, f64)> = spans
        .iter()
        .filter_map(|(t, _, _, f)| f.map(|f| (t.as_str(), f)))
        .collect();
    let (lo, hi) = rates.iter().fold((f64::MAX, 0.0_f64), |(lo, hi), (_, f)| {
        (lo.min(*f), hi.max(*f))
    });
    if rates.len() > 1 && hi > lo * 1.05 {
        let list: Vec<String> = rates
            .iter()
            .map(|(t, f)| format!("{t} {f:.1} fps"))
            .collect();
        out.push(format!(
            "the cameras run at different frame rates ({}): frames are matched by time, never by number",
            list.join(", ")
        ));
    }
    out
}

/// A stream's description: source, frames, times, frame size, which channels the first readable
/// frame has, every channel of the file with its message count, record counts, and the
/// reader's notes and warnings.
fn stream_info(path: &std::path::Path, camera: Option<&str>) -> anyhow::Result<serde_json::Value> {
    let mut reader = StreamReader::open_camera(path, camera)?;
    let n = reader.len();
    let (first, last) = (
        reader.time_ns(0),
        n.checked_sub(1).and_then(|i| reader.time_ns(i)),
    );
    let counts = reader.counts();
    let channels: Vec<serde_json::Value> = reader
        .channels()
        .iter()
        .map(|c| {
            serde_json::json!({
                "topic": c.topic, "message_encoding": c.message_encoding,
                "schema": c.schema.as_ref().map(|s| &s.name),
                "schema_encoding": c.schema.as_ref().map(|s| &s.encoding),
                "messages": c.message_count,
            })
        })
        .collect();
    let mut value = serde_json::json!({
        "file": path.display().to_string(), "kind": "stream",
        "source": reader.info().source, "description": reader.info().description,
        "frames": n, "chunks": reader.chunk_count(),
        "first_time_ns": first, "last_time_ns": last,
        "messages": counts.messages, "schemas": counts.schemas,
        "attachments": counts.attachments, "metadata": counts.metadata,
        "channels": channels,
    });
    if let (Some(a), Some(b)) = (first, last)
        && n > 1
        && b > a
    {
        let (secs, fps) = duration_and_rate(b - a, n);
        value["duration_s"] = secs.into();
        value["fps"] = fps.into();
    }
    // The first readable frame: a damaged first chunk costs its frames, not the description.
    let mut unreadable = Vec::new();
    let topics: Vec<serde_json::Value> = reader
        .image_topics()
        .iter()
        .map(|t| serde_json::json!({"topic": t.topic, "type": t.kind.schema_name()}))
        .collect();
    value["image_topics"] = topics.into();
    let (camera_values, camera_warnings) = cameras(&reader)?;
    value["cameras"] = camera_values.into();
    value["camera"] = reader.camera().into();
    let first_readable = (0..n).find_map(|i| match reader.read_with_image(i) {
        Ok((r, image)) => {
            value["image_encoding"] = image.encoding().into();
            Some((i, r))
        }
        Err(e) => {
            unreadable.push(format!("frame {i}: {e}"));
            None
        }
    });
    if let Some((i, r)) = first_readable {
        if i > 0 {
            value["first_readable_frame"] = i.into();
        }
        value["width"] = r.frame.width().into();
        value["height"] = r.frame.height().into();
        let mut channels = vec!["/camera/image".to_owned()];
        if r.sensors.is_some() {
            channels.push("/sensors".to_owned());
        }
        if r.ground_truth.is_some() {
            channels.push("/ground_truth".to_owned());
        }
        if r.recognition.is_some() {
            channels.push("/recognition".to_owned());
        }
        channels.extend(r.extra.iter().map(|(t, _)| t.clone()));
        value["frame0_channels"] = channels.into();
        // Every frame's size: streams imported from frames of several cameras mix them.
        let sizes = frame_sizes(&mut reader, i);
        if sizes.len() > 1 {
            value["sizes"] = sizes
                .iter()
                .map(|((w, h), n)| (format!("{w}x{h}"), serde_json::Value::from(*n)))
                .collect::<serde_json::Map<_, _>>()
                .into();
        }
    }
    let mut warnings = reader.warnings().to_vec();
    warnings.extend(camera_warnings);
    warnings.extend(unreadable_warning(&unreadable));
    value["notes"] = reader.notes().into();
    value["warnings"] = warnings.into();
    Ok(value)
}

/// The warning for the frames unreadable before the first readable one (`None`: none).
fn unreadable_warning(unreadable: &[String]) -> Option<String> {
    let (first, last) = (unreadable.first()?, unreadable.last()?);
    Some(if unreadable.len() == 1 {
        first.clone()
    } else {
        format!(
            "{} frames unreadable before the first readable one ({first} … {last})",
            unreadable.len()
        )
    })
}

/// How many readable frames from `first` on have each size (width, height).
fn frame_sizes(
    reader: &mut StreamReader,
    first: usize,
) -> std::collections::BTreeMap<(usize, usize), usize> {
    let mut sizes = std::collections::BTreeMap::new();
    for i in first..reader.len() {
        if let Ok(r) = reader.read(i) {
            *sizes
                .entry((r.frame.width(), r.frame.height()))
                .or_insert(0) += 1;
        }
    }
    sizes
}

/// Seconds spanned by `span_ns` and frames per second for `n` frames over it.
fn duration_and_rate(span_ns: u64, n: usize) -> (f64, f64) {
    let secs = span_ns as f64 / 1e9;
    (secs, n.saturating_sub(1) as f64 / secs)
}

fn print_human(v: &serde_json::Value) {
    let Some(obj) = v.as_object() else { return };
    let file = obj.get("file").and_then(|f| f.as_str()).unwrap_or("?");
    outln!("{file}");
    let text =
        |val: &serde_json::Value| val.as_str().map_or_else(|| val.to_string(), str::to_owned);
    for (k, val) in obj.iter().filter(|(k, _)| k.as_str() != "file") {
        if let Some(inner) = val.as_object() {
            outln!("  {k}:");
            for (ik, iv) in inner {
                outln!("    {ik:<14} {iv}");
            }
        } else if k == "channels" {
            outln!("  channels:");
            for c in val.as_array().into_iter().flatten() {
                outln!("    {}", channel_line(c));
            }
        } else if let Some(lines) = val.as_array().filter(|a| a.iter().all(|x| x.is_string())) {
            // Notes and warnings: one per line (none: nothing).
            if !lines.is_empty() {
                outln!("  {k}:");
                for line in lines {
                    outln!("    {}", text(line));
                }
            }
        } else {
            outln!("  {k}: {}", text(val));
        }
    }
}

/// One channel of `eotn info`: `topic  N messages  encoding  schema (schema encoding)`.
fn channel_line(c: &serde_json::Value) -> String {
    let s = |k: &str| c[k].as_str().unwrap_or("").to_owned();
    let schema = if c["schema"].is_string() {
        format!("{} ({})", s("schema"), s("schema_encoding"))
    } else {
        "no schema".to_owned()
    };
    format!(
        "{:<24} {:>8} messages  {:<10} {schema}",
        s("topic"),
        c["messages"],
        s("message_encoding")
    )
}
