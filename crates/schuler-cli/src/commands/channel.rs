//! `schuler channel`: the textbook's single-channel INS or SINS run three ways
//! ([`schuler_run::channel`]); the peaks and the measured Schuler period printed.

use schuler::units::ARCSEC;
use schuler_run::channel::{Args, run_and_write};
use std::fmt::Write as _;

/// `schuler channel`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let (cfg, result, summary) = run_and_write(&args)?;
    let period = summary["schuler_period_s"]["measured"].as_f64();
    let mut line = format!(
        "schuler channel: {} over {} s; peak dr {:.3} m, dv {:.4} m/s, alpha {:.3} arcsec",
        summary["system"].as_str().unwrap_or("?"),
        cfg.duration,
        result.peak_nonlinear.dr,
        result.peak_nonlinear.dv,
        result.peak_nonlinear.alpha / ARCSEC
    );
    if let Some(p) = period {
        let _ = write!(line, "; Schuler period {:.3} min", p / 60.0);
    }
    println!("{line}; wrote {}", args.out.display());
    Ok(())
}
