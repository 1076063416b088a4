//! `schuler montecarlo`: a campaign ([`schuler_run::campaign`]) of `--runs` seeds from
//! `--seed` on every core, its table, summary and report written into `--out`.

use anyhow::Result;
use schuler_run::campaign::{self, CampaignConfig, aggregate::Aggregate};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `schuler montecarlo`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The campaign: a `schuler simulate` scenario with a `[navigate]` table of
    /// `schuler nav` options and an optional `[campaign]` table (`gnss`,
    /// `gnss_velocity`, `baro`: the simulated streams the filter gets).
    #[arg(long)]
    pub config: PathBuf,
    /// Number of runs.
    #[arg(long)]
    pub runs: u64,
    /// Seed of the first run; run k has seed + k.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output directory (runs.csv, summary.json, report.html).
    #[arg(long, default_value = "montecarlo")]
    pub out: PathBuf,
    /// Threads (default: one per core). The results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs the campaign and writes its files.
pub fn run(args: Args) -> Result<()> {
    campaign::check_counts(args.runs, args.threads)?;
    let config = CampaignConfig::load(&args.config)?;
    let started = Instant::now();
    let results = campaign::run(&config, args.runs, args.seed, args.threads)?;
    let aggregate = Aggregate::of(&results);
    let rows: Vec<_> = results.into_iter().map(|r| r.row).collect();
    let what = args.config.display().to_string();
    campaign::report::write(&args.out, &what, &rows, &aggregate)?;
    println!(
        "{} runs in {:.1} s: {}",
        rows.len(),
        started.elapsed().as_secs_f64(),
        args.out.join("runs.csv").display()
    );
    for name in [
        "horizontal_rms_m",
        "horizontal_max_m",
        "outage_horizontal_max_m",
    ] {
        match aggregate.column(name) {
            // A standard deviation needs two runs.
            Some(c) if c.count > 1 => {
                println!("  {name:<24} mean {:.4}  std {:.4}", c.mean, c.std);
            }
            Some(c) if c.count == 1 => println!("  {name:<24} {:.4} (one run)", c.mean),
            _ => {}
        }
    }
    if let Some(n) = &aggregate.nees {
        println!(
            "  NEES over the runs (3 dof; 95 % interval of the mean {:.3}..{:.3}): \
             position {:.3}, velocity {:.3}, attitude {:.3}",
            n.bounds.lo, n.bounds.hi, n.grand_mean[0], n.grand_mean[1], n.grand_mean[2]
        );
    }
    Ok(())
}
