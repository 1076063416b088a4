//! The report's section for the seed's figure 3 against figure 2 (`figure3.rs`): the
//! circular error of each inertial leg against the time since its start, the ratio,
//! and the stage-by-stage table of the closed forms (`figure3.csv`).

use super::ModeRun;
use super::figure3::{self, Figure3, LegBudget};
use super::page::{m, svg, table_with_csv};
use anyhow::Result;
use schuler::analysis::errors::EpochErrors;
use schuler::units::{DEG_PER_H, UG};
use schuler_report::html::Report;
use schuler_report::plot::{LineStyle, Plot};
use std::path::Path;

const HEADER: [&str; 15] = [
    "leg",
    "start_s",
    "heading_arcmin",
    "drift_deg_per_h",
    "bias_ug",
    "level_ug",
    "velocity_mps",
    "heading_x_displacement_m",
    "heading_x_earth_rate_m",
    "drift_m",
    "level_m",
    "bias_in_turns_m",
    "velocity_m",
    "bound_m",
    "observed_max_m",
];

fn row(b: &LegBudget, g: f64) -> Vec<String> {
    let mut r = vec![
        b.label.to_string(),
        format!("{:.0}", b.t0),
        format!("{:.2}", b.heading.to_degrees() * 60.0),
        format!("{:.4}", b.drift / DEG_PER_H),
        format!("{:.1}", b.bias / UG),
        format!("{:.1}", b.level / (g * 1e-6)),
        format!("{:.3}", b.velocity),
    ];
    r.extend(b.terms.iter().map(|&x| m(x)));
    r.extend([m(b.bound()), m(b.observed)]);
    r
}

/// The circular error of `run` over `[t0, t0 + length]` against the time since `t0`.
fn since(run: &ModeRun, t0: f64, length: f64) -> (Vec<f64>, Vec<f64>) {
    run.errors
        .iter()
        .filter(|e| e.t_sow >= t0 && e.t_sow <= t0 + length)
        .map(|e| (e.t_sow - t0, EpochErrors::horizontal(e)))
        .unzip()
}

/// The section for `fig`, whose budgets belong to the runs `inertial_coarse` and
/// `inertial` of `runs` and to its own leg.
pub fn section(dir: &Path, report: &mut Report, runs: &[ModeRun], fig: &Figure3) -> Result<()> {
    let legs = [
        (super::page::find(runs, "inertial_coarse")?, &fig.budgets[0]),
        (super::page::find(runs, "inertial")?, &fig.budgets[1]),
        (&fig.run, &fig.budgets[2]),
    ];
    let (length, g) = (fig.length, fig.g);
    let styles = [LineStyle::Dashed, LineStyle::Dotted, LineStyle::Solid];
    let mut p = Plot::new(
        "Inertial legs of equal length: circular error dS",
        "time since the leg's start [s]",
        "dS [m]",
    );
    for ((run, b), style) in legs.iter().zip(styles.iter().cycle()) {
        let (x, y) = since(run, b.t0, length);
        p = p.line(run.label, &x, &y, *style);
    }
    svg(dir, "figure3.svg", &p)?;
    let rows: Vec<Vec<String>> = legs.iter().map(|(_, b)| row(b, g)).collect();
    let (fig2, fig3) = (legs[0].1, legs[2].1);
    let table = table_with_csv(dir, "figure3.csv", &HEADER, &rows)?;
    let sec = report.section(
        "figure3",
        "Figure 3 against figure 2: what each stage removes",
    );
    sec.paragraph(&format!(
        "The seed's figure 2 is the inertial mode after coarse alignment alone, its figure 3 \
         after fine alignment, refinement and compensation of the drift estimates. Here \
         figure 3's leg starts at {:.0} s from the inertial-satellite mode's corrected state, \
         its gyro drifts and accelerometer biases compensated (estimated on the pad by the \
         fine alignment and refined in flight by the filter, whose turns separate heading \
         from the east drift and tilt from the level biases); figure 2's leg starts at \
         {:.0} s after coarse alignment only. Over {:.0} s each, the largest circular error is \
         {} m against {} m: a ratio of {:.1} (the seed: at least 10). The closed forms \
         bound them at {} m and {} m (ratio {:.1}); the table says which term each stage \
         removed. The IMU is the navigation-grade FOG preset (0.01 deg/h, 50 ug turn-on, \
         after Groves 2013, table 4.1, and Titterton and Weston 2004, table 1.1), the class \
         of the seed's BINS-500NS, not tuned to produce a ratio; the sortie's seed decides \
         its draw (see the bias column). {}",
        fig3.t0,
        fig2.t0,
        length,
        m(fig2.observed),
        m(fig3.observed),
        fig2.observed / fig3.observed,
        m(fig2.bound()),
        m(fig3.bound()),
        fig2.bound() / fig3.bound(),
        figure3::explain(&fig.budgets),
    ));
    sec.table(table.caption("Each leg's errors at its start, the closed forms' terms over the leg and the largest observed circular error (figure3.csv)"));
    sec.plot_with_files(&p, &["figure3.svg", "figure3.csv"]);
    Ok(())
}
