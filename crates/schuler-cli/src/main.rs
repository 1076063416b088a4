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
    /// Free-inertial navigation of an IMU log (KF-GINS text or CSV).
    Nav(schuler_cli::commands::nav::NavArgs),
    /// Initial alignment at rest: gyrocompassing, then the Kalman filter on invariants.
    Align(schuler_cli::commands::align::Args),
    /// A first end-to-end run on built-in simulated data.
    Demo(schuler_cli::commands::demo::DemoArgs),
    /// Simulate a trajectory and its IMU, GNSS and barometer data.
    Simulate(schuler_cli::commands::simulate::Args),
    /// The textbook's single-channel INS/SINS: nonlinear, linear and closed-form errors.
    Channel(schuler_cli::commands::channel::Args),
    /// The vertical channel: free, baro-aided, with faults and prediction.
    Vertical(schuler_cli::commands::vertical::Args),
    /// Lecture 22's systems on one trajectory: SINS, platform INS (geographic,
    /// orthodromic, free-azimuth), analytic INS and gyro-free INS, errors compared.
    Platform(schuler_cli::commands::platform::Args),
    /// Errors of a navigation result (KF-GINS text or CSV) against a truth file.
    Compare(schuler_cli::commands::compare::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Nav(args) => schuler_cli::commands::nav::run(args),
        Command::Align(args) => schuler_cli::commands::align::run(args),
        Command::Demo(args) => schuler_cli::commands::demo::run(args),
        Command::Simulate(args) => schuler_cli::commands::simulate::run(args),
        Command::Channel(args) => schuler_cli::commands::channel::run(args),
        Command::Vertical(args) => schuler_cli::commands::vertical::run(args),
        Command::Platform(args) => schuler_cli::commands::platform::run(args),
        Command::Compare(args) => schuler_cli::commands::compare::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
