//! `schuler`: the command-line tool of the schuler inertial navigation toolkit.

mod commands;
mod formats;
mod output;

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
    Nav(commands::nav::NavArgs),
    /// A first end-to-end run on built-in simulated data.
    Demo(commands::demo::DemoArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Nav(args) => commands::nav::run(args),
        Command::Demo(args) => commands::demo::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
