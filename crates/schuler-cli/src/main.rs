//! `schuler`: the command-line tool of the schuler inertial navigation toolkit.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Inertial navigation toolkit: strapdown mechanization, error theory, alignment and
/// INS/GNSS integration.
#[derive(Parser, Debug)]
#[command(name = "schuler", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
#[allow(clippy::large_enum_variant)] // parsed once per run
enum Command {
    /// Navigation of an IMU log (KF-GINS text or CSV): free-inertial or aided (GNSS,
    /// barometer, vehicle aids), from a given start, an alignment or in motion.
    Nav(schuler_run::nav::NavArgs),
    /// Initial alignment at rest: gyrocompassing, then the Kalman filter on invariants.
    Align(schuler_run::alignment::AlignArgs),
    /// A first end-to-end run on built-in simulated data.
    Demo(schuler_cli::commands::demo::DemoArgs),
    /// Simulate a trajectory and its IMU, GNSS and barometer data.
    Simulate(schuler_cli::commands::simulate::Args),
    /// The textbook's single-channel INS/SINS: nonlinear, linear and closed-form errors.
    Channel(schuler_run::channel::Args),
    /// The vertical channel: free, baro-aided, with faults and prediction.
    Vertical(schuler_run::vertical::Args),
    /// Lecture 22's systems on one trajectory: SINS, platform INS (geographic,
    /// orthodromic, free-azimuth), analytic INS and gyro-free INS, errors compared.
    Platform(schuler_run::platform::Args),
    /// Errors of a navigation result (KF-GINS text or CSV) against a truth file.
    Compare(schuler_run::compare::Args),
    /// ROS 2 bags (MCAP): `bag info FILE` lists topics, types, counts, rates, spans.
    Bag(schuler_cli::commands::bag::Args),
    /// Noise of a static IMU log: Allan deviations, IEEE 952 terms, nav's noise config.
    Allan(schuler_run::allan::Args),
    /// Single-point positioning of a RINEX observation file with broadcast ephemerides:
    /// nav.txt, nav.csv, an RTKLIB .pos and the satellites of every epoch.
    Gnss(schuler_run::gnss::Args),
    /// Monte-Carlo campaign: N seeds of a scenario simulated, navigated and compared
    /// on every core; a table of one row per run and a report.
    Montecarlo(schuler_cli::commands::montecarlo::Args),
    /// Error budget: the filter's covariance along a scenario's truth and each error
    /// source's share of it (sigma.csv, shares.csv).
    Budget(schuler_cli::commands::budget::Args),
    /// What device logs hold (PX4 ULog, ROS bags, u-blox UBX, ArduPilot DataFlash,
    /// Android GnssLogger): streams, rates, gaps, GNSS quality, the IMU's units and
    /// axes, and the `schuler nav` command line that navigates each.
    Inspect(schuler_cli::commands::inspect::Args),
}

/// `cmd` and its subcommands with every option that takes a value accepting one that
/// starts with a hyphen (`--start -1`, `--max-tau -5s`, `--seed -1`): without it clap
/// reads `-1` as an unknown flag and its error does not name the option; with it the
/// option's own check does. Options whose value is optional (`--earth-rate` alone) or
/// that take several keep clap's reading, so that a following flag is not taken for
/// their value.
fn hyphen_values(cmd: clap::Command) -> clap::Command {
    cmd.mut_args(|a| {
        let one = a
            .get_num_args()
            .is_none_or(|n| n.min_values() == 1 && n.max_values() == 1);
        let takes = a.get_action().takes_values() && !a.is_positional() && one;
        a.allow_hyphen_values(takes)
    })
    .mut_subcommands(hyphen_values)
}

/// Exit status of a tool whose output pipe was closed: 128 + SIGPIPE, what the shell
/// reports for a program the signal ended.
const BROKEN_PIPE_STATUS: i32 = 141;

/// `schuler … | head`: once the reader of stdout has gone, the print macros panic on
/// the broken pipe (Rust ignores SIGPIPE, and restoring the signal's default needs
/// `unsafe`, which the workspace forbids). This hook ends the process quietly with
/// [`BROKEN_PIPE_STATUS`] there, as a tool the signal ended would; any other panic
/// goes to the default hook. The files a command writes are finished before it prints
/// its summary, so nothing written is lost.
fn quiet_on_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        // std's message: "failed printing to stdout: Broken pipe (os error 32)".
        if message.starts_with("failed printing to stdout")
            && message.to_ascii_lowercase().contains("broken pipe")
        {
            std::process::exit(BROKEN_PIPE_STATUS);
        }
        default(info);
    }));
}

fn main() -> ExitCode {
    use clap::{CommandFactory, FromArgMatches};
    quiet_on_broken_pipe();
    let matches = hyphen_values(Cli::command()).get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    let result = match cli.command {
        Command::Nav(args) => schuler_cli::commands::run_nav(args),
        Command::Align(args) => schuler_cli::commands::align::run(args),
        Command::Demo(args) => schuler_cli::commands::demo::run(args),
        Command::Simulate(args) => schuler_cli::commands::simulate::run(args),
        Command::Channel(args) => schuler_cli::commands::channel::run(args),
        Command::Vertical(args) => schuler_cli::commands::vertical::run(args),
        Command::Platform(args) => schuler_cli::commands::platform::run(args),
        Command::Compare(args) => schuler_cli::commands::compare::run(args),
        Command::Allan(args) => schuler_cli::commands::allan::run(args),
        Command::Bag(args) => schuler_cli::commands::bag::run(args),
        Command::Gnss(args) => schuler_cli::commands::gnss::run(args),
        Command::Montecarlo(args) => schuler_cli::commands::montecarlo::run(args),
        Command::Budget(args) => schuler_cli::commands::budget::run(args),
        Command::Inspect(args) => schuler_cli::commands::inspect::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => match schuler_run::interrupt::find(&e) {
            // Not a failure of the program: what it says is how far the files got.
            Some(i) => {
                eprintln!("{}", chain_message(&e));
                ExitCode::from(i.exit_code())
            }
            None => {
                eprintln!("error: {}", chain_message(&e));
                ExitCode::FAILURE
            }
        },
    }
}

/// `e` and its causes on one line, `a: b: c` as anyhow's `{:#}` prints them, each
/// message once: a cause whose message the line already ends with is left out (an
/// error that puts its source's message in its own, such as the simulator's
/// `SimError::Io`, would otherwise repeat it).
fn chain_message(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let m = cause.to_string();
        if line.is_empty() {
            line = m;
        } else if !line.ends_with(&m) {
            line.push_str(": ");
            line.push_str(&m);
        }
    }
    line
}

#[cfg(test)]
mod tests {
    use super::chain_message;

    /// An error that shows its source in its own message as well.
    #[derive(Debug, thiserror::Error)]
    #[error("writing failed: {0}")]
    struct Repeats(#[from] std::io::Error);

    #[test]
    fn each_message_once() {
        let io = || std::io::Error::other("disk full");
        let e = anyhow::Error::new(Repeats(io())).context("in a.toml");
        assert_eq!(
            format!("{e:#}"),
            "in a.toml: writing failed: disk full: disk full"
        );
        assert_eq!(chain_message(&e), "in a.toml: writing failed: disk full");
        // A chain without repetition is anyhow's.
        let e = anyhow::Error::new(io())
            .context("reading b")
            .context("in a.toml");
        assert_eq!(chain_message(&e), format!("{e:#}"));
    }
}
