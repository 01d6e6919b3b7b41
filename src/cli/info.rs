//! `eotn info`: what a file is — lookup table, frame (and, as streams land, MCAP stream).

use std::path::PathBuf;

use super::inputs::{is_frame_file, load_frame_arg, parse_size};
use crate::lut::{ColourClass, LookupTable};

/// Arguments of `eotn info`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Lookup tables (`.lut`) and frames (`.uyvy`, `.png`, `.jpg`).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Frame size of raw files, WxH; 208x160 and 640x480 are inferred.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// Print one JSON object per file per line.
    #[arg(long)]
    pub json: bool,
}

/// Runs `eotn info`.
///
/// # Errors
/// An unreadable or malformed file, naming it.
pub fn run(args: &Args) -> anyhow::Result<()> {
    for path in &args.files {
        let value = if is_frame_file(path) {
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
            println!("{value}");
        } else {
            print_human(&value);
        }
    }
    Ok(())
}

fn print_human(v: &serde_json::Value) {
    let Some(obj) = v.as_object() else { return };
    let file = obj.get("file").and_then(|f| f.as_str()).unwrap_or("?");
    println!("{file}");
    for (k, val) in obj.iter().filter(|(k, _)| k.as_str() != "file") {
        match val.as_object() {
            Some(inner) => {
                println!("  {k}:");
                for (ik, iv) in inner {
                    println!("    {ik:<14} {iv}");
                }
            }
            None => println!(
                "  {k}: {}",
                val.as_str().map_or_else(|| val.to_string(), str::to_owned)
            ),
        }
    }
}
