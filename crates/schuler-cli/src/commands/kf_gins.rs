//! `schuler nav --kf-gins-config FILE.yaml`: the drop-in for KF-GINS
//! ([`schuler_run::kf_gins`]); what it did, printed.

use anyhow::Result;
use schuler_run::kf_gins::{KfGinsOptions, run_kf_gins};
use std::path::Path;
use std::time::Instant;

/// Run a KF-GINS configuration end to end, with the options `opts`.
pub fn run(path: &Path, opts: &KfGinsOptions) -> Result<()> {
    let started = Instant::now();
    let (run, summary) = run_kf_gins(path, opts)?;
    let (settings, aiding) = (&run.settings, &run.aiding);
    let c = summary.nav.counts;
    println!(
        "KF-GINS configuration {}: {} samples, {} GNSS fixes ({} position updates, {} rejected, {} outside the IMU data) in {:.2} s; wrote {} epochs to {}",
        path.display(),
        summary.nav.samples,
        aiding.fixes.len(),
        c.position,
        c.rejected,
        c.skipped,
        started.elapsed().as_secs_f64(),
        summary.epochs,
        settings.out.join(aiding.names.nav).display()
    );
    print!("{}", summary.report_text);
    Ok(())
}
