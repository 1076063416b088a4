//! The command line the reader-dump examples share: `NAME FILE` dumps one file,
//! `NAME --time FILE...` times the reader on each; an error is printed and exits 1,
//! a wrong command line exits 2.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The result of a dump or a timing.
pub type DumpResult = Result<(), Box<dyn std::error::Error>>;

/// Runs `dump` or `time` as the command line of example `name` asks.
pub fn run(name: &str, dump: fn(&Path) -> DumpResult, time: fn(&Path) -> DumpResult) -> ExitCode {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let result = match args.as_slice() {
        [path] => dump(path),
        [flag, paths @ ..] if flag.as_os_str() == "--time" => {
            paths.iter().try_for_each(|p| time(p))
        }
        _ => {
            eprintln!("usage: {name} FILE | {name} --time FILE...");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}
