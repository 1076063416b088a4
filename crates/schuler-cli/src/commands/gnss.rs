//! `schuler gnss`: single-point positioning of a RINEX observation file with broadcast
//! ephemerides ([`schuler_run::gnss`]); its summary, printed.

use schuler_run::gnss::{Args, Summary, run as run_gnss};
use std::time::Instant;

/// `schuler gnss`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let start = Instant::now();
    let s = run_gnss(&args)?;
    print_summary(&s, start.elapsed().as_secs_f64());
    Ok(())
}

/// The summary of a run of `seconds`.
fn print_summary(s: &Summary, seconds: f64) {
    println!(
        "schuler gnss: {} epochs, {} solved, {} failed ({} ephemerides; {:.2} s, {:.0} epochs/s)",
        s.epochs,
        s.solved,
        s.epochs - s.solved,
        s.ephemerides,
        seconds,
        s.epochs as f64 / seconds.max(1e-9)
    );
    for (reason, n) in &s.failed {
        println!("  failed: {n} × {reason}");
    }
    if s.solved > 0 {
        println!("  mean PDOP {:.2}, HDOP {:.2}", s.mean_pdop, s.mean_hdop);
    }
    println!("  satellites excluded by FDE: {}", s.fde_excluded);
    println!(
        "  wrote nav.txt, nav.csv, solution.pos, satellites.csv in {}",
        s.out.display()
    );
}
