//! `eotn lut …`: lookup-table tools; `eotn lut convert` reads other teams' tables.

use std::path::PathBuf;

use anyhow::{Context, bail};

use crate::lut::ColourClass;
use crate::lut::convert::{SourceFormat, convert_file};

/// Arguments of `eotn lut`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// What to do with tables.
    #[command(subcommand)]
    pub command: LutCommand,
}

/// The `eotn lut` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum LutCommand {
    /// Convert another team's colour table to ours (FORMATS.md), mapping its classes to our
    /// codes; prints how many source cells each of its values had and what they became.
    Convert(ConvertArgs),
}

/// Arguments of `eotn lut convert`.
#[derive(Debug, clap::Args)]
pub struct ConvertArgs {
    /// The foreign table: rUNSWift `.cal`, NUbots `.lut`, B-Human `.c64`, UPennalizers `.raw`,
    /// ssl-vision `.xml`, Tekkotsu `.tm`.
    pub input: PathBuf,
    /// Its format; `auto` guesses from the header, extension and size.
    #[arg(long, default_value = "auto", value_parser = parse_format)]
    pub format: FormatChoice,
    /// Tekkotsu's colour file naming the `.tm` values (default: the `.col` beside the `.tm`).
    #[arg(long)]
    pub col: Option<PathBuf>,
    /// The table to write (`.lut`, raw FORMATS.md cells), written atomically.
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: PathBuf,
    /// Print one JSON object instead of the table of classes.
    #[arg(long)]
    pub json: bool,
}

/// `--format`: a named format, or `None` for `auto`.
#[derive(Debug, Clone, Copy)]
pub struct FormatChoice(pub Option<SourceFormat>);

fn parse_format(text: &str) -> anyhow::Result<FormatChoice> {
    if text == "auto" {
        return Ok(FormatChoice(None));
    }
    SourceFormat::parse(text)
        .map(|f| FormatChoice(Some(f)))
        .with_context(|| {
            let names: Vec<&str> = SourceFormat::ALL.iter().map(|f| f.name()).collect();
            format!("'{text}' is not a format: auto, {}", names.join(", "))
        })
}

/// Runs `eotn lut …`.
///
/// # Errors
/// An unreadable or malformed table, or an unwritable output, naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    match &args.command {
        LutCommand::Convert(a) => run_convert(a),
    }
}

fn run_convert(args: &ConvertArgs) -> anyhow::Result<()> {
    if let (Ok(a), Ok(b)) = (args.input.canonicalize(), args.output.canonicalize())
        && a == b
    {
        bail!(
            "{}: the output would overwrite the table being converted",
            args.output.display()
        );
    }
    let converted = convert_file(&args.input, args.format.0, args.col.as_deref())?;
    converted
        .table
        .save(&args.output)
        .with_context(|| format!("writing the converted {}", args.input.display()))?;
    let counts = converted.table.class_counts();
    if args.json {
        let ours: serde_json::Map<String, serde_json::Value> = ColourClass::ALL
            .iter()
            .zip(counts)
            .filter(|(_, n)| *n > 0)
            .map(|(c, n)| (c.name().to_owned(), n.into()))
            .collect();
        let value = serde_json::json!({
            "input": args.input.display().to_string(),
            "output": args.output.display().to_string(),
            "format": converted.format.name(),
            "source_bits": converted.source_bits,
            "bits": converted.table.bits(),
            "source_classes": converted.source_classes,
            "cells_per_class": ours,
            "notes": converted.notes,
        });
        outln!("{value}");
    } else {
        let [y, u, v] = converted.source_bits;
        outln!(
            "{} ({}, {y}/{u}/{v} bits) → {} ({} bits)",
            args.input.display(),
            converted.format,
            args.output.display(),
            converted.table.bits()
        );
        outln!(
            "  {:>5}  {:<24} {:<14} {:>9}",
            "value",
            "source class",
            "eotn class",
            "cells"
        );
        for s in &converted.source_classes {
            outln!(
                "  {:>5}  {:<24} {:<14} {:>9}",
                s.value,
                s.name,
                s.class.name(),
                s.cells
            );
        }
        outln!("  cells per eotn class at {} bits:", converted.table.bits());
        for (c, n) in ColourClass::ALL.iter().zip(counts).filter(|(_, n)| *n > 0) {
            outln!("    {:<14} {n:>9}", c.name());
        }
    }
    for note in &converted.notes {
        eprintln!("eotn: note: {}: {note}", args.input.display());
    }
    Ok(())
}
