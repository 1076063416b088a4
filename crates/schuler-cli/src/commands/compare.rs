//! `schuler compare NAV TRUTH [--out DIR] [--start T] [--end T] [--outages T0-T1,...]`:
//! errors of any navigation result against a truth file ([`schuler_run::compare`]),
//! printed as a table; `compare.json`, `errors.csv` and SVG plots with `--out`.

use anyhow::Result;
use schuler::analysis::statistics::{Comparison, OutageMax, QUANTITIES, Quantity};
use schuler_run::compare::{Args, compare_files, write_outputs};
use std::fmt::Write as _;

/// Decimals printed for a unit.
fn decimals(unit: &str) -> usize {
    if unit == "deg" { 5 } else { 4 }
}

/// A table cell: `d` decimals, or from 1e9 up the exponent form (an error that size
/// is a broken input, and its hundreds of digits would say nothing more).
fn cell(x: f64, d: usize) -> String {
    if x.abs() >= 1e9 {
        format!("{x:.3e}")
    } else {
        format!("{x:.d$}")
    }
}

/// The report printed: what was matched, one row per quantity, the CEP, then the
/// outages' maxima.
pub fn table(c: &Comparison) -> String {
    let mut s = String::new();
    matching(&mut s, c);
    statistics(&mut s, c);
    outages(&mut s, c);
    s
}

/// What was matched, on one line.
fn matching(s: &mut String, c: &Comparison) {
    let m = &c.matching;
    let _ = writeln!(
        s,
        "{} epochs compared ({} exact, {} with the truth interpolated{}); skipped: {} before \
         the truth, {} after it, {} outside --start/--end",
        m.matched(),
        m.exact,
        m.interpolated,
        if m.interpolated > 0 {
            // Rounded to the time tolerance: 0.1, not 0.10000000000002274.
            format!(
                " across at most {} s",
                (m.max_bridged_s * 1e6).round() / 1e6
            )
        } else {
            String::new()
        },
        m.before_truth,
        m.after_truth,
        m.outside_window
    );
}

/// One row per quantity (RMS, max, its time, 95 %, mean), then the CEP.
fn statistics(s: &mut String, c: &Comparison) {
    let _ = writeln!(
        s,
        "\n{:<16} {:<4} {:>12} {:>12} {:>12} {:>12} {:>12}",
        "error", "unit", "RMS", "max |e|", "at t [s]", "95 % |e|", "mean"
    );
    for (Quantity { name, unit, .. }, q) in QUANTITIES.iter().zip(&c.stats.summaries) {
        let d = decimals(unit);
        let cell = |x: f64| cell(x, d);
        let _ = writeln!(
            s,
            "{name:<16} {unit:<4} {:>12} {:>12} {:>12.3} {:>12} {:>12}",
            cell(q.rms),
            cell(q.max_abs),
            q.t_max_sow,
            cell(q.p95_abs),
            cell(q.mean)
        );
    }
    let _ = writeln!(
        s,
        "\nCEP (50 % of horizontal errors) {:.4} m, CEP95 {:.4} m",
        c.stats.cep, c.stats.cep95
    );
}

/// The largest errors in each outage and the RMS of those maxima, if outages were
/// given.
fn outages(s: &mut String, c: &Comparison) {
    if !c.stats.outages.is_empty() {
        let _ = writeln!(
            s,
            "\n{:<21} {:>7} {:>11} {:>11} {:>11} {:>11} {:>11}",
            "outage [s]",
            "epochs",
            "horiz [m]",
            "vert [m]",
            "roll [deg]",
            "pitch [deg]",
            "yaw [deg]"
        );
        let row = |s: &mut String, label: String, o: &OutageMax| {
            let _ = writeln!(
                s,
                "{label:<21} {:>7} {:>11.4} {:>11.4} {:>11.5} {:>11.5} {:>11.5}",
                o.epochs,
                o.horizontal,
                o.vertical,
                o.att.roll.to_degrees(),
                o.att.pitch.to_degrees(),
                o.att.yaw.to_degrees()
            );
        };
        for o in &c.stats.outages {
            if o.epochs == 0 {
                let _ = writeln!(s, "{:<21} {:>7} (no epoch inside)", interval(o), 0);
            } else {
                row(s, interval(o), o);
            }
        }
        if let Some(r) = &c.stats.outage_rms {
            row(s, "RMS of the maxima".to_owned(), r);
        }
    }
}

fn interval(o: &OutageMax) -> String {
    format!("{}-{}", o.from_sow, o.to_sow)
}

/// Runs `schuler compare`.
pub fn run(args: Args) -> Result<()> {
    let (c, nav_format, truth_format) = compare_files(&args)?;
    println!(
        "{} ({}) against {} ({})",
        args.nav.display(),
        nav_format.name(),
        args.truth.display(),
        truth_format.name()
    );
    print!("{}", table(&c));
    if let Some(dir) = &args.out {
        write_outputs(dir, &args, &c, [nav_format, truth_format])?;
        println!(
            "\nwrote compare.json, errors.csv, position_error.svg, velocity_error.svg, \
             attitude_error.svg to {}",
            dir.display()
        );
    }
    Ok(())
}
