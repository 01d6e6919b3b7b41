//! The `eotn` binary: the desktop app with no arguments, the headless tools with a command.

use std::process::ExitCode;

use clap::Parser;
use eotn::cli::{Cli, report};

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    match cli.command {
        Some(command) => match eotn::cli::run(command) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => report(&e),
        },
        None => {
            eprintln!(
                "eotn: the desktop app is not built yet; see `eotn --help` for the headless commands"
            );
            ExitCode::FAILURE
        }
    }
}
