//! Ctrl+C (SIGINT) and SIGTERM as a flag: a command that runs until stopped (`eotn record`
//! without `--frames`/`--seconds`) looks at it and finishes its files cleanly. A second signal
//! ends the process at once (exit status 130), in case finishing hangs.
//!
//! Signals are caught by tokio's `signal` (already in the build for the `foxglove` server), on a
//! thread of its own.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once Ctrl+C or SIGTERM has arrived.
#[derive(Debug, Clone)]
pub struct Interrupted(Arc<AtomicBool>);

impl Interrupted {
    /// True once a signal has arrived.
    #[must_use]
    pub fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// The flag itself, for a loop that takes a stop flag.
    #[must_use]
    pub fn flag(&self) -> &AtomicBool {
        &self.0
    }
}

/// Catches Ctrl+C and SIGTERM from now on; `what` is said when the first arrives ("finishing the
/// recordings").
///
/// # Errors
/// The OS's error when the handlers or their thread cannot be set up.
pub fn catch(what: &'static str) -> anyhow::Result<Interrupted> {
    let flag = Arc::new(AtomicBool::new(false));
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_io()
        .build()?;
    // The handlers are in place before this returns: a signal right after start is caught.
    let mut signals = {
        let _inside = runtime.enter();
        Signals::new()?
    };
    std::thread::Builder::new()
        .name("signals".to_owned())
        .spawn({
            let flag = Arc::clone(&flag);
            move || {
                runtime.block_on(async {
                    let name = signals.next().await;
                    eprintln!("{name}: {what} (again to quit at once)");
                    flag.store(true, Ordering::Relaxed);
                    let name = signals.next().await;
                    eprintln!("{name} again: quitting");
                    std::process::exit(130);
                });
            }
        })?;
    Ok(Interrupted(flag))
}

/// The signals listened for: Ctrl+C and SIGTERM.
#[cfg(unix)]
struct Signals {
    interrupt: tokio::signal::unix::Signal,
    terminate: tokio::signal::unix::Signal,
}

#[cfg(unix)]
impl Signals {
    fn new() -> std::io::Result<Self> {
        use tokio::signal::unix::{SignalKind, signal};
        Ok(Self {
            interrupt: signal(SignalKind::interrupt())?,
            terminate: signal(SignalKind::terminate())?,
        })
    }

    /// Waits for the next signal; its name.
    async fn next(&mut self) -> &'static str {
        tokio::select! {
            _ = self.interrupt.recv() => "Ctrl+C",
            _ = self.terminate.recv() => "SIGTERM",
        }
    }
}

/// The signals listened for: Ctrl+C (no SIGTERM off Unix).
#[cfg(not(unix))]
struct Signals;

#[cfg(not(unix))]
impl Signals {
    #[expect(clippy::unnecessary_wraps, reason = "the same signature as on Unix")]
    fn new() -> std::io::Result<Self> {
        Ok(Self)
    }

    /// Waits for the next Ctrl+C; its name.
    async fn next(&mut self) -> &'static str {
        let _ = tokio::signal::ctrl_c().await;
        "Ctrl+C"
    }
}
