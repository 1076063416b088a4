//! `schuler budget`: the error budget of a scenario ([`schuler_run::budget`]), its
//! tables written into `--out` and the shares at the end printed.

use anyhow::Result;
use schuler_run::budget;
use schuler_run::campaign::CampaignConfig;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `schuler budget`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scenario: a `schuler simulate` scenario with optional `[navigate]`
    /// (`schuler nav` options: the filter) and `[campaign]` (`gnss`, `gnss_velocity`,
    /// `baro`: the streams the filter gets) tables, as `schuler montecarlo` reads.
    #[arg(long)]
    pub config: PathBuf,
    /// Output directory (sigma.csv, shares.csv).
    #[arg(long, default_value = "budget")]
    pub out: PathBuf,
}

/// Runs the budget and writes its tables.
pub fn run(args: Args) -> Result<()> {
    let config = CampaignConfig::load(&args.config)?;
    let started = Instant::now();
    let r = budget::run(&config)?;
    budget::tables::write(&args.out, &r)?;
    println!(
        "budget of {} sources, {} updates, in {:.1} s: {}",
        r.sources.len(),
        r.updates,
        started.elapsed().as_secs_f64(),
        args.out.join("shares.csv").display()
    );
    println!(
        "  the shares add up to the whole within {:.1e} (relative)",
        r.largest_gap
    );
    for e in &r.shares {
        println!(
            "  {} (t = {:.0} s): horizontal position σ {:.3} m",
            e.event,
            e.t,
            e.total.pos_h.sqrt()
        );
        let mut parts: Vec<_> = r.sources.iter().zip(&e.parts).collect();
        parts.sort_by(|a, b| b.1.pos_h.total_cmp(&a.1.pos_h));
        for (name, x) in parts.iter().take(3) {
            let fraction = x.pos_h / e.total.pos_h.max(f64::MIN_POSITIVE);
            println!("    {name:<24} {:5.1} %", 100.0 * fraction);
        }
    }
    Ok(())
}
