//! Which paths a command reads and which it writes, from the command line's own definition, so
//! that the guard against replacing an input covers every command, including those added
//! later, without each command listing its files.
//!
//! An option that names a file to write says so by its value name: [`OUT`] (a file) or
//! [`OUT_DIR`] (a folder the command writes files into), as in
//! `#[arg(short, long, value_name = OUT)]`; `--help` shows them as `-o <OUT>`. Every other path
//! option or argument is an input, except one marked [`UPDATED`] (a file read and then
//! replaced on purpose, `patterns learn --update`). [`parse`] reads the command line and gives
//! the inputs, folders expanded to the frames in them (and the label masks beside those), for
//! [`crate::atomic_file::guard_command`]; `tests/it/outputs.rs` walks the same definition to run
//! every output option against a device node, a FIFO, a symbolic link and a folder.

use std::any::TypeId;
use std::ffi::OsString;
use std::path::PathBuf;

use clap::{CommandFactory as _, FromArgMatches as _};

use super::Cli;

/// The value name of an option naming one output file.
pub const OUT: &str = "OUT";
/// The value name of an option naming a folder the command writes its output files into.
pub const OUT_DIR: &str = "OUT_DIR";
/// The value name of an input that the command may replace on purpose (read, then written).
pub const UPDATED: &str = "UPDATED";

/// What a path option is to its command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathRole {
    /// A file or folder read.
    Input,
    /// A file written (through [`crate::atomic_file`]).
    Output,
    /// A folder the command writes files into.
    OutputFolder,
    /// A file read and replaced on purpose.
    Updated,
}

/// The role of an option or argument, `None` when it takes no path.
#[must_use]
pub fn path_role(arg: &clap::Arg) -> Option<PathRole> {
    if arg.get_value_parser().type_id() != TypeId::of::<PathBuf>() {
        return None;
    }
    let names = arg.get_value_names().unwrap_or_default();
    let named = |n: &str| names.iter().any(|v| v.as_str() == n);
    Some(if named(OUT) {
        PathRole::Output
    } else if named(OUT_DIR) {
        PathRole::OutputFolder
    } else if named(UPDATED) {
        PathRole::Updated
    } else {
        PathRole::Input
    })
}

/// The parsed command line and the files the command reads.
#[derive(Debug)]
pub struct Parsed {
    /// The command line.
    pub cli: Cli,
    /// Every input path (see the module docs), for the guard.
    pub inputs: Vec<PathBuf>,
    /// Every output path (files and folders), checked against the inputs before the command
    /// runs.
    pub outputs: Vec<PathBuf>,
    /// The files read and replaced on purpose ([`UPDATED`]): never inputs.
    pub updated: Vec<PathBuf>,
}

/// Parses the process's command line; exits with clap's message (and usage) when it is wrong,
/// as [`clap::Parser::parse`] does.
#[must_use]
pub fn parse() -> Parsed {
    parse_from(std::env::args_os())
}

/// Like [`parse`], from given arguments (the first is the program name). A wrong command line
/// is one line, `eotn: invalid value 'NaN' for '--fps <FPS>': …`, like every other error;
/// `--help` and `--version` print as clap prints them.
#[must_use]
pub fn parse_from(args: impl IntoIterator<Item = OsString>) -> Parsed {
    let command = Cli::command();
    let matches = match command.clone().try_get_matches_from(args) {
        Ok(m) => m,
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            eprintln!("eotn: {}", one_line(&e));
            std::process::exit(e.exit_code());
        }
    };
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    let (mut inputs, mut outputs) = (Vec::new(), Vec::new());
    collect(&command, &matches, &[PathRole::Input], &mut inputs);
    collect(
        &command,
        &matches,
        &[PathRole::Output, PathRole::OutputFolder],
        &mut outputs,
    );
    let mut updated = Vec::new();
    collect(&command, &matches, &[PathRole::Updated], &mut updated);
    Parsed {
        inputs: expand_inputs(inputs),
        outputs,
        updated,
        cli,
    }
}

/// A clap error as one line: its message without the `error:` prefix, the usage and the
/// pointer to `--help`, folded onto one line.
fn one_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let message = text.split("\n\n").next().unwrap_or_default();
    let message = message.strip_prefix("error: ").unwrap_or(message);
    let words: Vec<&str> = message.split_whitespace().collect();
    format!("{} (--help says more)", words.join(" "))
}

/// The values of every path option of `command` (and of the subcommand chosen, recursively)
/// with one of `roles`.
fn collect(
    command: &clap::Command,
    matches: &clap::ArgMatches,
    roles: &[PathRole],
    out: &mut Vec<PathBuf>,
) {
    for arg in command.get_arguments() {
        if !path_role(arg).is_some_and(|r| roles.contains(&r)) {
            continue;
        }
        if let Ok(Some(values)) = matches.try_get_raw(arg.get_id().as_str()) {
            out.extend(values.map(PathBuf::from));
        }
    }
    if let Some((name, sub_matches)) = matches.subcommand()
        && let Some(sub) = command.find_subcommand(name)
    {
        collect(sub, sub_matches, roles, out);
    }
}

/// The inputs with each folder's frame files added, and the label masks beside every frame
/// file that has one (`NAME.cls`, `NAME.uyvy.cls`: `lut-from-labels` reads them).
fn expand_inputs(inputs: Vec<PathBuf>) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for p in inputs {
        if p.is_dir()
            && let Ok(files) = crate::sources::expand_frame_paths(std::slice::from_ref(&p))
        {
            out.extend(files);
        }
        out.push(p);
    }
    let masks: Vec<PathBuf> = out
        .iter()
        .filter(|p| crate::sources::is_frame_file(p))
        .flat_map(|p| {
            let mut beside = p.as_os_str().to_owned();
            beside.push(".cls");
            [p.with_extension("cls"), PathBuf::from(beside)]
        })
        .filter(|m| m.is_file())
        .collect();
    out.extend(masks);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(args: &[&str]) -> Parsed {
        parse_from(
            std::iter::once("eotn")
                .chain(args.iter().copied())
                .map(OsString::from),
        )
    }

    #[test]
    fn inputs_are_every_path_but_the_outputs() {
        let p = parsed(&[
            "detect",
            "a.mcap",
            "b.png",
            "--lut",
            "t.lut",
            "--params",
            "p.json",
            "--annotate",
            "out.mcap",
        ]);
        let names: Vec<_> = p.inputs.iter().map(|p| p.display().to_string()).collect();
        assert_eq!(names, ["a.mcap", "b.png", "t.lut", "p.json"]);
        let p = parsed(&[
            "patterns", "learn", "s.mcap", "--lut", "t.lut", "--update", "pl.json", "-o", "pl.json",
        ]);
        let names: Vec<_> = p.inputs.iter().map(|p| p.display().to_string()).collect();
        assert_eq!(names, ["s.mcap", "t.lut"], "--update may be the output");
        assert_eq!(p.updated, [PathBuf::from("pl.json")]);
    }

    #[test]
    fn a_folder_of_frames_brings_its_frames_and_their_masks() {
        let dir = tempfile::tempdir().expect("tempdir");
        for n in ["a.uyvy", "a.uyvy.cls", "b.png", "b.cls", "notes.txt"] {
            std::fs::write(dir.path().join(n), b"x").expect("write");
        }
        let d = dir.path().to_string_lossy().into_owned();
        let p = parsed(&["classify", &d, "--lut", "t.lut"]);
        let names: Vec<_> = p
            .inputs
            .iter()
            .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect();
        for n in ["a.uyvy", "a.uyvy.cls", "b.png", "b.cls", "t.lut"] {
            assert!(names.iter().any(|m| m == n), "{n} missing from {names:?}");
        }
        assert!(!names.iter().any(|m| m == "notes.txt"), "{names:?}");
    }
}
