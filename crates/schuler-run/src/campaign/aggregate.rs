//! A campaign's aggregate: each column's mean, standard deviation, minimum and maximum
//! over the runs, and the filter's consistency over the runs.
//!
//! Consistency (Bar-Shalom, Li & Kirubarajan 2001, §5.4): at one instant the NEES of
//! a 3-dof error in `N` independent runs of a consistent filter are `N` independent
//! chi-square(3) values, so their average is `χ²_{3N} / N` and lies in
//! [`mean_bounds`]`(N, 3, p)` with probability `p`. The campaign's NEES is that
//! average at each snapshot; its time average (the grand mean) is an average of such
//! averages, whose variance is at most that of one of them, so the same interval holds
//! it with at least about the same probability.

use super::RunResult;
use super::row::COLUMNS;
use schuler::analysis::consistency::{Bounds, mean_bounds};

/// Probability of the consistency intervals.
pub const PROBABILITY: f64 = 0.95;

/// One column over the runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnStats {
    /// Mean over the runs with a finite value.
    pub mean: f64,
    /// Sample standard deviation (n − 1).
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Runs with a finite value.
    pub count: usize,
}

impl ColumnStats {
    /// The statistics of the finite `values` (NaN without any).
    pub fn of(values: impl Iterator<Item = f64>) -> Self {
        let v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        Self {
            mean,
            std: var.sqrt(),
            min: v.iter().copied().fold(f64::NAN, f64::min),
            max: v.iter().copied().fold(f64::NAN, f64::max),
            count: v.len(),
        }
    }
}

/// The average over the runs of each block's NEES at each snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct NeesOverRuns {
    /// Snapshot times [s].
    pub t: Vec<f64>,
    /// Average NEES of position, velocity and attitude at each time.
    pub mean: [Vec<f64>; 3],
    /// Interval of an average of `runs` chi-square(3) values at [`PROBABILITY`].
    pub bounds: Bounds,
    /// Time average of each block's campaign NEES.
    pub grand_mean: [f64; 3],
    /// Fraction of the snapshots whose average lies in `bounds`, per block.
    pub inside: [f64; 3],
}

impl NeesOverRuns {
    /// The averages over `results` (snapshots matched by index: every run of one
    /// scenario has the same sample times); `None` without NEES.
    pub fn of(results: &[RunResult]) -> Option<Self> {
        let n = results.iter().map(|r| r.nees.len()).min()?;
        if n == 0 {
            return None;
        }
        let runs = results.len() as f64;
        let bounds = mean_bounds(results.len(), 3, PROBABILITY);
        let t: Vec<f64> = results[0].nees[..n].iter().map(|e| e.0).collect();
        let mean = [0, 1, 2].map(|k| {
            (0..n)
                .map(|i| results.iter().map(|r| r.nees[i].1[k]).sum::<f64>() / runs)
                .collect::<Vec<f64>>()
        });
        let grand_mean = [0, 1, 2].map(|k| mean[k].iter().sum::<f64>() / n as f64);
        let inside = [0, 1, 2]
            .map(|k| mean[k].iter().filter(|x| bounds.contains(**x)).count() as f64 / n as f64);
        Some(Self {
            t,
            mean,
            bounds,
            grand_mean,
            inside,
        })
    }
}

/// A campaign's aggregate.
#[derive(Debug, Clone, PartialEq)]
pub struct Aggregate {
    /// Runs.
    pub runs: usize,
    /// Each column's statistics, in [`COLUMNS`] order.
    pub columns: Vec<ColumnStats>,
    /// The NEES over the runs, when the filter ran against the truth.
    pub nees: Option<NeesOverRuns>,
}

impl Aggregate {
    /// The aggregate of `results`.
    pub fn of(results: &[RunResult]) -> Self {
        let columns = (0..COLUMNS.len())
            .map(|i| ColumnStats::of(results.iter().map(|r| r.row.values[i])))
            .collect();
        Self {
            runs: results.len(),
            columns,
            nees: NeesOverRuns::of(results),
        }
    }

    /// The statistics of column `name`.
    pub fn column(&self, name: &str) -> Option<&ColumnStats> {
        COLUMNS
            .iter()
            .position(|c| *c == name)
            .and_then(|i| self.columns.get(i))
    }
}
