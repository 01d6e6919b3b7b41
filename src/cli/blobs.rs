//! `eotn blobs`: blobs of classified frames, as a table or as peer-compatible JSON Lines.

use std::io::Write;

use anyhow::Context;
use serde::Serialize;

use super::inputs::{InputArgs, parse_connectivity, progress};
use crate::blobs::{Blob, BlobSet, Connectivity};
use crate::classify::ClassifiedImage;

/// Arguments of `eotn blobs`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Frames, table and raw frame size.
    #[command(flatten)]
    pub input: InputArgs,
    /// 8: diagonal neighbours join a blob; 4: they do not.
    #[arg(long, default_value = "8", value_parser = parse_connectivity)]
    pub connectivity: Connectivity,
    /// Leave out blobs with fewer pixels than this.
    #[arg(long, default_value_t = 1, value_parser = super::values::whole_in::<u32>(0, super::values::MAX_PIXELS))]
    pub min_pixels: u32,
    /// One JSON object per frame per line (the shape of `peer_pipeline.py --json`).
    #[arg(long)]
    pub json: bool,
}

/// One blob in the peer's JSON shape (inclusive boxes).
#[derive(Debug, Serialize, PartialEq, Eq, PartialOrd, Ord)]
pub struct BlobJson {
    /// Class code.
    pub colour: u8,
    /// Leftmost column.
    pub minx: u32,
    /// Top row.
    pub miny: u32,
    /// Rightmost column.
    pub maxx: u32,
    /// Bottom row.
    pub maxy: u32,
    /// Own pixels.
    pub pixels: u32,
}

/// One frame's line of `--json` output.
#[derive(Debug, Serialize)]
pub struct FrameBlobsJson {
    /// Frame file name.
    pub frame: String,
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Table bits per channel.
    pub lut_bits: u8,
    /// 4 or 8.
    pub connectivity: u8,
    /// Blobs sorted by (colour, miny, minx, maxy, maxx, pixels), as the peer sorts them.
    pub blobs: Vec<BlobJson>,
}

/// The blobs of a set in the peer's order.
#[must_use]
pub fn peer_sorted(blobs: impl Iterator<Item = Blob>, min_pixels: u32) -> Vec<BlobJson> {
    let mut out: Vec<BlobJson> = blobs
        .filter(|b| b.pixels >= min_pixels)
        .map(|b| BlobJson {
            colour: b.colour,
            minx: b.minx,
            miny: b.miny,
            maxx: b.maxx,
            maxy: b.maxy,
            pixels: b.pixels,
        })
        .collect();
    out.sort_by_key(|b| (b.colour, b.miny, b.minx, b.maxy, b.maxx, b.pixels));
    out
}

/// Runs `eotn blobs`.
///
/// # Errors
/// Unreadable or malformed inputs, naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let (lut, mut inputs) = args.input.open()?;

    let connectivity = args.connectivity;
    let mut classified = ClassifiedImage::default();
    let mut set = BlobSet::default();
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let bar = progress(inputs.len(), "blobs");
    for i in 0..inputs.len() {
        let Some(frame) = inputs
            .load_record_or_skip(i, args.input.size)?
            .map(|r| r.frame)
        else {
            continue;
        };
        crate::classify::classify_into(&frame, &lut, &mut classified);
        set.find(&classified, connectivity);
        let blobs = peer_sorted(set.active().copied(), args.min_pixels);
        if args.json {
            let line = FrameBlobsJson {
                frame: inputs.name(i),
                width: frame.width(),
                height: frame.height(),
                lut_bits: lut.bits(),
                connectivity: connectivity.neighbours(),
                blobs,
            };
            serde_json::to_writer(&mut out, &line)?;
            writeln!(out)?;
        } else {
            writeln!(
                out,
                "{} ({}×{}): {} blobs",
                inputs.name(i),
                frame.width(),
                frame.height(),
                blobs.len()
            )?;
            writeln!(
                out,
                "  {:<14} {:>5} {:>5} {:>5} {:>5} {:>7}",
                "colour", "minx", "miny", "maxx", "maxy", "pixels"
            )?;
            for b in &blobs {
                let name = crate::lut::ColourClass::from_code(b.colour).map_or("?", |c| c.name());
                writeln!(
                    out,
                    "  {name:<14} {:>5} {:>5} {:>5} {:>5} {:>7}",
                    b.minx, b.miny, b.maxx, b.maxy, b.pixels
                )?;
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    out.flush().context("writing output")?;
    Ok(())
}
