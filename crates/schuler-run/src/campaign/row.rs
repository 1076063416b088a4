//! One run's row of the campaign table: its seed, `schuler compare`'s error
//! statistics of its navigation against the simulated truth, and the filter's
//! consistency (time-averaged NEES of position, velocity and attitude, 3 dof each,
//! and the mean NIS per dof of the accepted measurements).

use super::navigate::Navigated;
use schuler::analysis::statistics::{Comparison, Summary};
use std::fmt::Write;

/// Names of the table's columns after `seed`, units in the names.
pub const COLUMNS: [&str; 19] = [
    "epochs",
    "horizontal_rms_m",
    "horizontal_max_m",
    "cep_m",
    "cep95_m",
    "vertical_rms_m",
    "vertical_max_m",
    "velocity_rms_mps",
    "roll_rms_deg",
    "pitch_rms_deg",
    "yaw_rms_deg",
    "outage_horizontal_max_m",
    "outage_vertical_max_m",
    "nees_position",
    "nees_velocity",
    "nees_attitude",
    "nees_epochs",
    "mean_nis_per_dof",
    "rejected",
];

/// One run's results: its seed and the values of [`COLUMNS`].
#[derive(Debug, Clone, PartialEq)]
pub struct RunRow {
    /// The scenario seed of the run.
    pub seed: u64,
    /// The values in [`COLUMNS`] order (NaN where a run has none: no filter, no
    /// outage).
    pub values: [f64; COLUMNS.len()],
}

/// The NEES of one snapshot (position, velocity, attitude; NaN where none).
pub type NeesEpoch = (f64, [f64; 3]);

/// Each snapshot's NEES of `nav` (infinite where the covariance block was not
/// positive definite).
pub fn nees_series(nav: &Navigated) -> Vec<NeesEpoch> {
    nav.finished
        .snapshots
        .iter()
        .filter_map(|s| {
            let n = s.nees?;
            Some((s.t, n.map(|x| x.unwrap_or(f64::INFINITY))))
        })
        .collect()
}

impl RunRow {
    /// The row of the run with `seed`: errors from `c`, consistency from `nav` and its
    /// NEES series `nees`.
    pub fn of(seed: u64, c: &Comparison, nav: &Navigated, nees: &[NeesEpoch]) -> Self {
        let st = &c.stats;
        let get = |name: &str, f: fn(&Summary) -> f64| st.get(name).map_or(f64::NAN, f);
        let rms = |s: &Summary| s.rms;
        let max = |s: &Summary| s.max_abs;
        let v_rms = ["v north", "v east", "v down"]
            .iter()
            .map(|n| get(n, rms).powi(2))
            .sum::<f64>()
            .sqrt();
        let outages = st.outages.iter().filter(|o| o.epochs > 0);
        let out_max = |f: fn(&schuler::analysis::statistics::OutageMax) -> f64| {
            outages.clone().map(f).fold(f64::NAN, f64::max)
        };
        let mean = |k: usize| nees.iter().map(|n| n.1[k]).sum::<f64>() / nees.len() as f64;
        let s = &nav.finished.summary;
        Self {
            seed,
            values: [
                st.epochs as f64,
                get("horizontal", rms),
                get("horizontal", max),
                st.cep,
                st.cep95,
                get("vertical (down)", rms),
                get("vertical (down)", max),
                v_rms,
                get("roll", rms),
                get("pitch", rms),
                get("yaw", rms),
                out_max(|o| o.horizontal),
                out_max(|o| o.vertical),
                mean(0),
                mean(1),
                mean(2),
                nees.len() as f64,
                s.mean_nis_per_dof,
                s.counts.rejected as f64,
            ],
        }
    }

    /// The value of column `name` (`None` for an unknown name).
    pub fn get(&self, name: &str) -> Option<f64> {
        COLUMNS
            .iter()
            .position(|c| *c == name)
            .map(|i| self.values[i])
    }
}

/// The table as CSV: a header, then one line per row; numbers in Rust's shortest form
/// that reads back to the same bits, an empty field where a run has none (no outage,
/// no accepted measurement: CSV's missing value, read back as NaN by pandas).
pub fn csv(rows: &[RunRow]) -> String {
    let mut s = format!("seed,{}\n", COLUMNS.join(","));
    for r in rows {
        let _ = write!(s, "{}", r.seed);
        for v in r.values {
            if v.is_finite() {
                let _ = write!(s, ",{v:?}");
            } else {
                s.push(',');
            }
        }
        s.push('\n');
    }
    s
}
