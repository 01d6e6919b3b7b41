//! `eotn classify`: classified images as PNG (display colours) or raw class bytes.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;

use super::inputs::{InputArgs, progress};
use crate::classify::ClassifiedImage;
use crate::frame::save_rgb_png;
use crate::lut::ColourClass;

/// Arguments of `eotn classify`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Frames, table and raw frame size.
    #[command(flatten)]
    pub input: InputArgs,
    /// Folder for the outputs (`NAME.classified.png`, and `NAME.cls` with `--raw`); created if
    /// missing. Without it nothing is written (useful with `--json`).
    #[arg(short, long, value_name = super::paths::OUT_DIR)]
    pub output: Option<PathBuf>,
    /// Also write the raw class codes, one byte per pixel, row-major (`NAME.cls`).
    #[arg(long)]
    pub raw: bool,
    /// Print per frame a JSON line with the pixel count of each class present.
    #[arg(long)]
    pub json: bool,
}

/// Runs `eotn classify`.
///
/// # Errors
/// Unreadable inputs or unwritable outputs, naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let (lut, mut inputs) = args.input.open()?;

    if let Some(dir) = &args.output {
        crate::atomic_file::output_folder(dir).with_context(|| format!("{}", dir.display()))?;
    }
    let mut img = ClassifiedImage::default();
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let bar = progress(inputs.len(), "classify");
    for i in 0..inputs.len() {
        let Some(frame) = inputs
            .load_record_or_skip(i, args.input.size)?
            .map(|r| r.frame)
        else {
            bar.inc(1);
            continue;
        };
        crate::classify::classify_into(&frame, &lut, &mut img);
        let name = inputs.name(i);
        if let Some(dir) = &args.output {
            let png = dir.join(format!("{name}.classified.png"));
            save_rgb_png(&png, img.width(), img.height(), &img.to_rgb())?;
            if args.raw {
                let cls = dir.join(format!("{name}.cls"));
                crate::atomic_file::write_atomic(&cls, img.codes())
                    .with_context(|| format!("{}: cannot write", cls.display()))?;
            }
        }
        if args.json {
            let hist = img.histogram();
            let classes: BTreeMap<String, usize> = hist
                .iter()
                .enumerate()
                .filter(|(_, n)| **n > 0)
                .map(|(code, n)| {
                    let code = u8::try_from(code).unwrap_or(u8::MAX);
                    let key = ColourClass::from_code(code)
                        .map_or_else(|| code.to_string(), |c| c.name().to_owned());
                    (key, *n)
                })
                .collect();
            let line = serde_json::json!({
                "frame": name, "width": img.width(), "height": img.height(), "pixels": classes,
            });
            serde_json::to_writer(&mut out, &line)?;
            writeln!(out)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    out.flush().context("writing output")?;
    Ok(())
}
