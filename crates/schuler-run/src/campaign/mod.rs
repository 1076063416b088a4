//! Monte-Carlo campaigns: `N` runs of one scenario, run `k` with the scenario seed
//! `S + k`, each a pure function of (configuration, seed): simulate (the library's
//! simulator, in memory) -> navigate (`schuler nav`'s options and session set-up) ->
//! compare (`schuler compare`'s statistics against the simulated truth), one row per
//! run ([`row`]). The runs share the local cores through rayon; rows come back in
//! seed order and every run's arithmetic happens on one thread, so the table is the
//! same bits for any number of threads (or machines: a row depends on its seed only).
//!
//! A run's seed reproduces its data alone: `schuler simulate` of the scenario with
//! that `seed` writes the same samples (the navigation of those files then differs
//! only by the files' printed digits of the GNSS fixes and the start).

pub mod aggregate;
pub mod config;
pub mod navigate;
pub mod record;
pub mod report;
pub mod row;

pub use config::CampaignConfig;
pub use row::{COLUMNS, RunRow, csv};

use anyhow::{Context, Result};
use rayon::prelude::*;
use row::NeesEpoch;
use schuler::analysis::statistics::compare;
use schuler::sim::run::{ScenarioSpec, simulate_on};

/// One run's row and its NEES series (for the campaign's per-epoch average).
#[derive(Debug, Clone)]
pub struct RunResult {
    /// The table row.
    pub row: RunRow,
    /// NEES of position, velocity, attitude at each of the filter's snapshots.
    pub nees: Vec<NeesEpoch>,
}

/// The GNSS outages of the scenario, for the statistics' outage maxima [s].
pub(crate) fn outages(s: &ScenarioSpec) -> Result<Vec<(f64, f64)>> {
    Ok(match &s.gnss {
        Some(g) => g
            .model()?
            .outages
            .iter()
            .map(|i| (i.start, i.end))
            .collect(),
        None => Vec::new(),
    })
}

/// The run of `c` with the scenario seed `seed` (its simulation on one thread).
pub fn run_one(c: &CampaignConfig, seed: u64) -> Result<RunResult> {
    let inner = || -> Result<RunResult> {
        let spec = ScenarioSpec {
            seed,
            ..c.scenario.clone()
        };
        let mut data = record::Recorded::default();
        simulate_on(&spec, 1, &mut data).context("simulating")?;
        let nav = navigate::navigate(c, &data).context("navigating")?;
        let comparison = compare(&nav.epochs, &data.truth, None, None, &outages(&spec)?)
            .context("comparing with the truth")?;
        let nees = row::nees_series(&nav);
        Ok(RunResult {
            row: RunRow::of(seed, &comparison, &nav, &nees),
            nees,
        })
    };
    inner().with_context(|| format!("{}: the run with seed {seed}", c.origin))
}

/// The seeds of `runs` runs from `seed`: `seed, seed + 1, ...` (wrapping).
pub fn seeds(runs: u64, seed: u64) -> Vec<u64> {
    (0..runs).map(|k| seed.wrapping_add(k)).collect()
}

/// `runs` runs of `c` from `seed` on `threads` threads (`None`: one per core), in
/// seed order; the first failing run's error (naming its seed) if any fails. Both
/// counts are bounded ([`schuler::domain::RUNS`], [`schuler::domain::THREADS`]).
pub fn run(
    c: &CampaignConfig,
    runs: u64,
    seed: u64,
    threads: Option<usize>,
) -> Result<Vec<RunResult>> {
    check_counts(runs, threads)?;
    run_seeds(c, &seeds(runs, seed), threads)
}

/// `--runs` and `--threads` within their bounds, the error naming the flag.
pub fn check_counts(runs: u64, threads: Option<usize>) -> Result<()> {
    use crate::options::in_count;
    in_count("--runs", &schuler::domain::RUNS, runs)?;
    if let Some(n) = threads {
        in_count("--threads", &schuler::domain::THREADS, n as u64)?;
    }
    Ok(())
}

/// The runs of `c` with the scenario seeds `seeds`, in their order, on `threads`
/// threads (`None`: one per core). If runs fail, the error is that of the first
/// failing seed in that order (every run is tried), whatever the threads did first.
pub fn run_seeds(
    c: &CampaignConfig,
    seeds: &[u64],
    threads: Option<usize>,
) -> Result<Vec<RunResult>> {
    if let Some(n) = threads {
        crate::options::in_count("--threads", &schuler::domain::THREADS, n as u64)?;
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("cannot start the campaign's threads")?;
    let all: Vec<Result<RunResult>> =
        pool.install(|| seeds.par_iter().map(|&s| run_one(c, s)).collect());
    all.into_iter().collect()
}
