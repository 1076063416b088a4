//! SIGINT and SIGTERM as a request to stop: a command that calls [`watch`] checks
//! [`requested`] between samples, stops feeding its input there and closes every
//! output file on a whole line, as at the end of its input, then reports how far the
//! files got and exits with `128 + signal` (130 for Ctrl-C, 143 for `kill`). A second
//! signal while the first is being handled ends the process at once.
//!
//! Commands that never call [`watch`] keep the default action of the signals.

use signal_hook::consts::{SIGINT, SIGTERM};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The signal received (0 before any).
static RECEIVED: AtomicUsize = AtomicUsize::new(0);
/// Set by the first signal: the next one exits at once.
static ARMED: AtomicBool = AtomicBool::new(false);
/// Whether the handlers are installed.
static INSTALLED: OnceLock<Result<(), String>> = OnceLock::new();

/// The run was stopped by a signal; every output file ends on a whole line at the
/// point the message that carries it names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("interrupted by {}", signal_name(*.signal))]
pub struct Interrupted {
    /// The signal's number.
    pub signal: i32,
}

impl Interrupted {
    /// The process's exit status for it: `128 + signal`, as a shell reports a process
    /// the signal killed.
    pub fn exit_code(&self) -> u8 {
        u8::try_from(128 + self.signal).unwrap_or(1)
    }
}

fn signal_name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

/// Installs the handlers of SIGINT and SIGTERM (once per process). An error here
/// (the system refused a handler) leaves the default action: the run is not stopped
/// gracefully but nothing else changes, so it is reported and not fatal.
pub fn watch() {
    let installed = INSTALLED.get_or_init(|| {
        [SIGINT, SIGTERM]
            .into_iter()
            .try_for_each(|signal| -> std::io::Result<()> {
                // The shutdown goes first: it sees ARMED as the previous signal left it.
                signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, &ARMED)?;
                signal_hook::flag::register(signal, &ARMED)?;
                signal_hook::flag::register_usize(
                    signal,
                    &RECEIVED,
                    usize::try_from(signal).unwrap_or(0),
                )?;
                Ok(())
            })
            .map_err(|e| e.to_string())
    });
    if let Err(e) = installed {
        eprintln!(
            "warning: cannot handle SIGINT/SIGTERM ({e}); an interrupted run may cut its files"
        );
    }
}

/// The signal that asked the run to stop, if one came.
#[inline]
pub fn requested() -> Option<Interrupted> {
    match RECEIVED.load(Ordering::Relaxed) {
        0 => None,
        s => Some(Interrupted {
            signal: i32::try_from(s).unwrap_or(SIGINT),
        }),
    }
}

/// The interruption in an error's chain, if it is one.
pub fn find(e: &anyhow::Error) -> Option<Interrupted> {
    e.chain()
        .find_map(|c| c.downcast_ref::<Interrupted>().copied())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_follow_the_shell() {
        assert_eq!(Interrupted { signal: SIGINT }.exit_code(), 130);
        assert_eq!(Interrupted { signal: SIGTERM }.exit_code(), 143);
        assert_eq!(
            Interrupted { signal: SIGINT }.to_string(),
            "interrupted by SIGINT"
        );
    }

    #[test]
    fn found_under_context() {
        let e = anyhow::Error::new(Interrupted { signal: SIGTERM }).context("stopped after 3");
        assert_eq!(find(&e), Some(Interrupted { signal: SIGTERM }));
        assert_eq!(find(&anyhow::anyhow!("other")), None);
    }
}
