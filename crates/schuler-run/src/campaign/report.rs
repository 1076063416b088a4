//! A campaign's files: `runs.csv` (one row per run), `summary.json` (the aggregate)
//! and `report.html` (the aggregate table, each run's errors against its seed, and the
//! NEES averaged over the runs with its interval), on the CLI's report and plot code.

use super::aggregate::{Aggregate, NeesOverRuns};
use super::row::{COLUMNS, RunRow, csv};
use anyhow::{Context, Result};
use schuler_report::html::{Report, Table};
use schuler_report::plot::{LineStyle, Plot};
use serde_json::{Value, json};
use std::path::Path;

/// The aggregate as JSON: runs, each column's statistics, the NEES test.
pub fn summary_json(a: &Aggregate) -> Value {
    let num = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    let columns: serde_json::Map<String, Value> = COLUMNS
        .iter()
        .zip(&a.columns)
        .map(|(name, c)| {
            let v = json!({"mean": num(c.mean), "std": num(c.std), "min": num(c.min),
                           "max": num(c.max), "runs": c.count});
            (name.to_string(), v)
        })
        .collect();
    let nees = a.nees.as_ref().map(|n| {
        json!({"probability": super::aggregate::PROBABILITY, "dof": 3,
               "interval_of_the_mean": [n.bounds.lo, n.bounds.hi],
               "grand_mean": {"position": n.grand_mean[0], "velocity": n.grand_mean[1],
                              "attitude": n.grand_mean[2]},
               "fraction_of_epochs_inside": {"position": n.inside[0], "velocity": n.inside[1],
                                             "attitude": n.inside[2]}})
    });
    json!({"runs": a.runs, "columns": columns, "nees": nees})
}

/// Each run's horizontal RMS and maximum (and outage maximum) against its seed.
fn errors_plot(rows: &[RunRow]) -> Plot {
    let seed: Vec<f64> = rows.iter().map(|r| r.seed as f64).collect();
    let col = |name: &str| -> Vec<f64> {
        rows.iter()
            .map(|r| r.get(name).unwrap_or(f64::NAN))
            .collect()
    };
    Plot::new("Horizontal error of each run", "seed [-]", "error [m]")
        .line("RMS", &seed, &col("horizontal_rms_m"), LineStyle::Solid)
        .line("max", &seed, &col("horizontal_max_m"), LineStyle::Dashed)
        .line(
            "max in outages",
            &seed,
            &col("outage_horizontal_max_m"),
            LineStyle::Dotted,
        )
}

/// The NEES averaged over the runs against time, with its interval.
fn nees_plot(n: &NeesOverRuns) -> Plot {
    let flat = |x: f64| vec![x; n.t.len()];
    Plot::new(
        "NEES averaged over the runs (3 dof each)",
        "t [s]",
        "NEES [-]",
    )
    .line("position", &n.t, &n.mean[0], LineStyle::Solid)
    .line("velocity", &n.t, &n.mean[1], LineStyle::Solid)
    .line("attitude", &n.t, &n.mean[2], LineStyle::Solid)
    .line("95 % interval", &n.t, &flat(n.bounds.lo), LineStyle::Dashed)
    .line(
        "95 % interval (upper)",
        &n.t,
        &flat(n.bounds.hi),
        LineStyle::Dashed,
    )
}

/// The HTML report of `rows` and their aggregate `a`; `what` names the configuration.
pub fn html(what: &str, rows: &[RunRow], a: &Aggregate) -> Report {
    let mut r = Report::new("Monte-Carlo campaign");
    let seeds = match (rows.first(), rows.last()) {
        (Some(f), Some(l)) => format!("seeds {} to {}", f.seed, l.seed),
        _ => "no run".to_string(),
    };
    r.paragraph(&format!(
        "{} runs of {what} ({seeds}): simulated, navigated and compared with the \
         simulated truth; one row per run in runs.csv.",
        a.runs
    ));
    let mut t =
        Table::new(["quantity", "mean", "std", "min", "max", "runs"]).caption("Over the runs");
    for (name, c) in COLUMNS.iter().zip(&a.columns) {
        // A column without a value (no outage) or a spread of one run has none.
        let f = |x: f64| {
            if x.is_finite() {
                format!("{x:.4}")
            } else {
                "–".to_owned()
            }
        };
        t = t.row([
            name.to_string(),
            f(c.mean),
            f(c.std),
            f(c.min),
            f(c.max),
            c.count.to_string(),
        ]);
    }
    r.section("aggregate", "Errors and consistency over the runs")
        .table(t);
    r.section("runs", "Each run").plot(&errors_plot(rows));
    if let Some(n) = &a.nees {
        r.section("nees", "Consistency: NEES over the runs")
            .paragraph(&format!(
                "At each second the NEES of the {} runs are averaged; for a consistent \
                 filter that average lies in [{:.3}, {:.3}] with probability 95 % \
                 (chi-square(3N)/N). Time averages: position {:.3}, velocity {:.3}, \
                 attitude {:.3}; inside the interval at {:.0} %, {:.0} %, {:.0} % of \
                 the seconds.",
                a.runs,
                n.bounds.lo,
                n.bounds.hi,
                n.grand_mean[0],
                n.grand_mean[1],
                n.grand_mean[2],
                100.0 * n.inside[0],
                100.0 * n.inside[1],
                100.0 * n.inside[2]
            ))
            .plot(&nees_plot(n));
    }
    r
}

/// Writes `runs.csv`, `summary.json` and `report.html` into `dir`.
pub fn write(dir: &Path, what: &str, rows: &[RunRow], a: &Aggregate) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let path = dir.join("runs.csv");
    std::fs::write(&path, csv(rows)).with_context(|| format!("writing {}", path.display()))?;
    let path = dir.join("summary.json");
    let text = serde_json::to_string_pretty(&summary_json(a))?;
    std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    html(what, rows, a).write(&dir.join("report.html"))
}
