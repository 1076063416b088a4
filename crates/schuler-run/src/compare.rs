//! The errors of any navigation result (schuler's, KF-GINS's, another tool's) against a
//! truth file, as a table, `compare.json`, `errors.csv` and SVG plots.
//!
//! The file formats are [`schuler_io::formats::nav`]'s; the matching, the errors and the
//! statistics are the library's ([`schuler::analysis::errors`],
//! [`schuler::analysis::statistics`]), shared with the aided run's report.

use anyhow::{Context, Result};
use schuler::analysis::errors::EpochErrors;
use schuler::analysis::statistics::{Comparison, OutageMax, QUANTITIES, Quantity, compare};
use schuler_io::formats::nav::{NavFormat, read_nav};
use schuler_io::output::write_errors_csv;
use schuler_report::plot::{LineStyle, Plot};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// Arguments of `schuler compare`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Navigation result: KF-GINS text (`week sow lat lon h vn ve vd roll pitch yaw`)
    /// or schuler's nav.csv.
    #[arg(value_name = "NAV")]
    pub nav: PathBuf,
    /// Truth, in either format; interpolated in time where its epochs differ.
    #[arg(value_name = "TRUTH")]
    pub truth: PathBuf,
    /// Output directory for compare.json, errors.csv and the plots (created if
    /// missing); without it only the table is printed.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Compare NAV epochs from this time on [s of week].
    #[arg(long, value_name = "SOW")]
    pub start: Option<f64>,
    /// Compare NAV epochs up to this time [s of week].
    #[arg(long, value_name = "SOW")]
    pub end: Option<f64>,
    /// GNSS outage intervals [s of week], e.g. `215-276,400-460`: the largest errors
    /// inside each and the RMS of those maxima.
    #[arg(long, value_name = "T0-T1,...", value_parser = parse_outages)]
    pub outages: Option<Outages>,
}

/// Time intervals `[from, to]` [s of week], as `--outages` gives them.
#[derive(Debug, Clone, PartialEq)]
pub struct Outages(pub Vec<(f64, f64)>);

/// Parses `T0-T1,T2-T3` (each `T0 < T1`, finite).
pub fn parse_outages(text: &str) -> Result<Outages, String> {
    let mut out = Vec::new();
    for part in text.split(',').map(str::trim) {
        // The separating '-' is not a leading sign nor an exponent's sign.
        let bytes = part.as_bytes();
        let dash = (1..bytes.len())
            .find(|&i| bytes[i] == b'-' && !matches!(bytes[i - 1], b'e' | b'E' | b'-'))
            .ok_or_else(|| format!("{part:?}: expected an interval T0-T1"))?;
        let (a, b) = (part[..dash].trim(), part[dash + 1..].trim());
        let num = |s: &str| -> Result<f64, String> {
            s.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{part:?}: {s:?} is not a time in seconds"))
        };
        let (from, to) = (num(a)?, num(b)?);
        if from >= to {
            return Err(format!("{part:?}: the interval must end after it starts"));
        }
        out.push((from, to));
    }
    Ok(Outages(out))
}

/// `compare.json`: inputs, matching, statistics (attitude in degrees).
pub fn summary_json(c: &Comparison, nav: (&Path, NavFormat), truth: (&Path, NavFormat)) -> Value {
    let m = &c.matching;
    let mut stats = serde_json::Map::new();
    for (Quantity { name, unit, .. }, q) in QUANTITIES.iter().zip(&c.stats.summaries) {
        let key = format!(
            "{}_{}",
            name.replace(" (down)", "").replace([' ', '-'], "_"),
            unit.replace('/', "p")
        )
        .to_lowercase();
        stats.insert(
            key,
            json!({"rms": q.rms, "max": q.max_abs, "t_max_sow": q.t_max_sow,
                   "p95": q.p95_abs, "mean": q.mean}),
        );
    }
    stats.insert("cep_m".to_owned(), json!(c.stats.cep));
    stats.insert("cep95_m".to_owned(), json!(c.stats.cep95));
    let outage = |o: &OutageMax| {
        json!({
            "from_sow": o.from_sow, "to_sow": o.to_sow, "epochs": o.epochs,
            "max_horizontal_m": (o.epochs > 0).then_some(o.horizontal),
            "max_vertical_m": (o.epochs > 0).then_some(o.vertical),
            "max_roll_deg": (o.epochs > 0).then_some(o.att.roll.to_degrees()),
            "max_pitch_deg": (o.epochs > 0).then_some(o.att.pitch.to_degrees()),
            "max_yaw_deg": (o.epochs > 0).then_some(o.att.yaw.to_degrees()),
        })
    };
    json!({
        "nav": {"path": nav.0.display().to_string(), "format": nav.1.name()},
        "truth": {"path": truth.0.display().to_string(), "format": truth.1.name()},
        "epochs": {
            "matched": m.matched(), "exact": m.exact, "interpolated": m.interpolated,
            "before_truth": m.before_truth, "after_truth": m.after_truth,
            "outside_window": m.outside_window, "max_bridged_s": m.max_bridged_s,
        },
        "statistics": Value::Object(stats),
        "outages": c.stats.outages.iter().map(outage).collect::<Vec<_>>(),
        "outage_rms": c.stats.outage_rms.as_ref().map(|r| json!({
            "outages": r.epochs,
            "horizontal_m": r.horizontal, "vertical_m": r.vertical,
            "roll_deg": r.att.roll.to_degrees(), "pitch_deg": r.att.pitch.to_degrees(),
            "yaw_deg": r.att.yaw.to_degrees(),
        })),
    })
}

/// Writes the three plots: position, velocity and attitude errors against time, the
/// outage intervals shaded.
fn write_plots(dir: &Path, c: &Comparison) -> Result<()> {
    let t: Vec<f64> = c.errors.iter().map(|e| e.t_sow).collect();
    let col = |f: &dyn Fn(&EpochErrors) -> f64| c.errors.iter().map(f).collect::<Vec<f64>>();
    let spans: Vec<(f64, f64)> = c
        .stats
        .outages
        .iter()
        .map(|o| (o.from_sow, o.to_sow))
        .collect();
    let shade = |p: Plot| {
        if spans.is_empty() {
            p
        } else {
            p.shade("outage", spans.iter().copied())
        }
    };
    shade(
        Plot::new("Position error", "t [s of week]", "error [m]")
            .line(
                "horizontal",
                &t,
                &col(&EpochErrors::horizontal),
                LineStyle::Solid,
            )
            .line("down", &t, &col(&|e| e.pos_n.z), LineStyle::Dashed),
    )
    .write(&dir.join("position_error.svg"))?;
    shade(
        Plot::new("Velocity error", "t [s of week]", "error [m/s]")
            .line("north", &t, &col(&|e| e.v_n.x), LineStyle::Solid)
            .line("east", &t, &col(&|e| e.v_n.y), LineStyle::Dashed)
            .line("down", &t, &col(&|e| e.v_n.z), LineStyle::Dotted),
    )
    .write(&dir.join("velocity_error.svg"))?;
    shade(
        Plot::new("Attitude error", "t [s of week]", "error [deg]")
            .line(
                "roll",
                &t,
                &col(&|e| e.att.roll.to_degrees()),
                LineStyle::Solid,
            )
            .line(
                "pitch",
                &t,
                &col(&|e| e.att.pitch.to_degrees()),
                LineStyle::Dashed,
            )
            .line(
                "yaw",
                &t,
                &col(&|e| e.att.yaw.to_degrees()),
                LineStyle::Dotted,
            ),
    )
    .write(&dir.join("attitude_error.svg"))
}

/// The errors of `args.nav` against `args.truth` in the window and outages of `args`,
/// with the two files' formats.
pub fn compare_files(args: &Args) -> Result<(Comparison, NavFormat, NavFormat)> {
    if let (Some(s), Some(e)) = (args.start, args.end)
        && s > e
    {
        anyhow::bail!("--start {s} is after --end {e}");
    }
    let (nav_format, nav) = read_nav(&args.nav)?;
    let (truth_format, truth) = read_nav(&args.truth)?;
    let outages = args.outages.clone().map(|o| o.0).unwrap_or_default();
    let c = compare(&nav, &truth, args.start, args.end, &outages).with_context(|| {
        format!(
            "comparing {} with {}",
            args.nav.display(),
            args.truth.display()
        )
    })?;
    Ok((c, nav_format, truth_format))
}

/// Writes `compare.json`, `errors.csv` and the three plots of `c` into `dir`
/// (created if needed).
pub fn write_outputs(
    dir: &Path,
    args: &Args,
    c: &Comparison,
    formats: [NavFormat; 2],
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let json = summary_json(c, (&args.nav, formats[0]), (&args.truth, formats[1]));
    let text = serde_json::to_string_pretty(&json).context("encoding compare.json")?;
    schuler_io::line_file::write_whole(&dir.join("compare.json"), text + "\n")?;
    write_errors_csv(&dir.join("errors.csv"), &c.errors)?;
    write_plots(dir, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outages_parse_and_reject_nonsense() {
        assert_eq!(
            parse_outages("215-276, 400.5-460").expect("parses").0,
            vec![(215.0, 276.0), (400.5, 460.0)]
        );
        assert_eq!(
            parse_outages("1e2-2e+2").expect("exponents").0,
            vec![(100.0, 200.0)]
        );
        for bad in ["215", "276-215", "a-b", "1-", ""] {
            assert!(parse_outages(bad).is_err(), "{bad:?}");
        }
    }
}
