//! `schuler allan IMU_FILE`: the noise of a static IMU log from its overlapping Allan
//! deviations ([`schuler_run::allan`]): the warnings, the tables of each triad's
//! terms and the files written, printed.

use schuler_run::allan::{Args, analyse, summary, write_outputs};
use std::path::PathBuf;

/// `schuler allan`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let run = analyse(&args)?;
    for w in &run.warnings {
        eprintln!("warning: {w}");
    }
    print!("{}", summary(&args.imu, &run.allan, &run.fits));
    let dir = args.out.clone().unwrap_or_else(|| PathBuf::from("."));
    for path in write_outputs(&dir, &args.imu, &run)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}
