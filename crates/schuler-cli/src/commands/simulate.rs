//! `schuler simulate --config scenario.toml --out DIR`: trajectory, IMU, GNSS and
//! barometer data with exact truth, in the formats `schuler nav` and KF-GINS read
//! ([`schuler_run::simulate`] says which files); what was simulated, printed.

use anyhow::{Context, Result};
use schuler_run::scenario::load_scenario;
use schuler_run::simulate::simulate_to_dir;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `schuler simulate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scenario TOML (start, motion, imu, optional gnss and baro; see the README).
    #[arg(long, value_name = "FILE")]
    pub config: PathBuf,
    /// Output directory.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Override the scenario's seed.
    #[arg(long)]
    pub seed: Option<u64>,
}

/// `schuler simulate`.
pub fn run(args: Args) -> Result<()> {
    schuler_run::interrupt::watch();
    let started = Instant::now();
    let mut spec = load_scenario(&args.config)?;
    if let Some(seed) = args.seed {
        spec.seed = seed;
    }
    let s = simulate_to_dir(&spec, &args.out)
        .with_context(|| format!("in {}", args.config.display()))?;
    println!(
        "simulated {:.1} s: {} IMU samples, {} GNSS fixes, {} baro readings in {:.2} s; files in {}",
        s.t1 - s.t0,
        s.imu_samples,
        s.gnss_fixes,
        s.baro_readings,
        started.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}
