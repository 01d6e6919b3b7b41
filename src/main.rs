//! The `eotn` binary: the desktop app with no arguments, the headless tools with a command.

use std::process::ExitCode;

use eotn::cli::{Parsed, report};

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    // The command line, and the files it names as inputs: no output may replace them.
    let Parsed {
        cli,
        inputs,
        outputs,
        updated,
    } = eotn::cli::parse();
    // A kernel set forced by name is checked before anything runs (unknown, or not on this CPU).
    if let Err(e) = eotn::kernels::from_env() {
        return report(&anyhow::Error::new(e));
    }
    let result = match cli.command {
        #[cfg(feature = "gui")]
        Some(eotn::cli::Command::Open(args)) => eotn::app::run(args.run_options()),
        Some(command) => eotn::cli::run(command, &inputs, &outputs, &updated),
        #[cfg(feature = "gui")]
        None => eotn::app::run(eotn::app_options::RunOptions::default()),
        #[cfg(not(feature = "gui"))]
        None => Err(anyhow::anyhow!(
            "this eotn was built without the desktop app (cargo feature `gui`); see `eotn --help` for the headless commands"
        )),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => report(&e),
    }
}
