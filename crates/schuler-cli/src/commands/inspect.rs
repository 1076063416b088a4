//! `schuler inspect FILE…`: what each device log holds ([`schuler_run::inspect`]),
//! as a table or as JSON (`--json`, schema `schuler-inspect/1`: one object per file in
//! an array).

use anyhow::Result;
use schuler_run::inspect::{Inspection, StreamInfo, inspect};
use std::path::PathBuf;

/// Arguments of `schuler inspect`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Device logs (PX4 ULog, ROS 1 bag, ROS 2 MCAP, u-blox UBX, ArduPilot
    /// DataFlash, Android GnssLogger; gzip too), told by content.
    #[arg(value_name = "FILE", required = true)]
    pub files: Vec<PathBuf>,
    /// Print JSON (an array, one object per file) instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// `schuler inspect`.
pub fn run(args: Args) -> Result<()> {
    let mut all = Vec::new();
    for file in &args.files {
        let i = inspect(file)?;
        if !args.json {
            print_inspection(&i);
        }
        all.push(i);
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&all)?);
    }
    Ok(())
}

/// A time or `-`.
fn t(x: Option<f64>) -> String {
    x.map_or("-".to_owned(), |v| format!("{v:.3}"))
}

/// One file's table.
fn print_inspection(i: &Inspection) {
    let clock = match i.week {
        Some(w) => format!("GPS seconds of week (week {w})"),
        None if i.time_scale == "bag-stamps" => "the bag's log time [s]".to_owned(),
        None => "the device's clock (s since boot)".to_owned(),
    };
    println!("{}: {}, times in {clock}", i.path, i.format_name);
    let (shown, unread): (Vec<&StreamInfo>, Vec<&StreamInfo>) = i
        .streams
        .iter()
        .partition(|s| s.kind != "other" || s.timing.records > 0);
    let w = shown.iter().map(|s| s.name.len()).max().unwrap_or(6).max(6);
    println!(
        "  {:<w$} {:<13} {:>8} {:>10} {:>11} {:>13} {:>13}  gaps (> 5 median spacings)",
        "stream", "kind", "records", "rate Hz", "jitter ms", "first s", "last s"
    );
    for s in shown {
        print_stream(s, w);
    }
    if !unread.is_empty() {
        let names: Vec<&str> = unread.iter().map(|s| s.name.as_str()).collect();
        println!("  not read by schuler: {}", names.join(", "));
    }
    for s in &i.streams {
        print_details(s);
    }
    for n in &i.notes {
        println!("  note: {n}");
    }
    match &i.command {
        Some(c) => println!("  navigate with: {}", shell_line(c)),
        None => println!("  cannot navigate it as it is:"),
    }
    if let Some(n) = &i.command_note {
        println!("    ({n})");
    }
}

/// The stream's row.
fn print_stream(s: &StreamInfo, w: usize) {
    let tm = &s.timing;
    let gaps = match tm.gaps.count {
        0 => "-".to_owned(),
        n => format!(
            "{n}, {:.3} s in all, longest {:.3} s{}",
            tm.gaps.total_s,
            tm.gaps.longest_s,
            tm.gaps
                .first
                .first()
                .map(|g| format!(", first after t = {:.3}", g.t))
                .unwrap_or_default()
        ),
    };
    let (rate, jitter) = match tm.t_first {
        Some(_) => (
            format!("{:.3}", tm.rate_hz),
            format!("{:.3}", tm.jitter_s * 1e3),
        ),
        None => ("-".to_owned(), "-".to_owned()),
    };
    println!(
        "  {:<w$} {:<13} {:>8} {rate:>10} {jitter:>11} {:>13} {:>13}  {gaps}",
        s.name,
        s.kind,
        tm.records,
        t(tm.t_first),
        t(tm.t_last)
    );
}

/// What the data say of IMU, GNSS, raw and reference streams.
fn print_details(s: &StreamInfo) {
    if let Some(m) = &s.imu {
        println!(
            "  {}: mean specific force {:.3} m/s^2: {}; {}; increments cover {} of the time between samples{}",
            s.name,
            m.mean_specific_force,
            m.units,
            match &m.gravity_axis {
                Some(g) => format!("at rest at the start, gravity along {g}"),
                None => "moving at the start (gravity's axis not told)".to_owned(),
            },
            m.increment_coverage
                .map_or("-".to_owned(), |c| format!("{:.1} %", c * 100.0)),
            match m.continuous_increments {
                Some(false) => " (NOT continuous: decimated samples, unusable for strapdown)",
                _ => "",
            }
        );
    }
    if let Some(g) = &s.gnss {
        let m = |x: Option<f64>| x.map_or("-".to_owned(), |v| format!("{v:.2} m"));
        println!(
            "  {}: {} fixes ({} with velocity), median sigma horizontal {} vertical {}",
            s.name,
            g.fixes,
            g.with_velocity,
            m(g.median_horizontal_std_m),
            m(g.median_vertical_std_m)
        );
    }
    if let Some(r) = &s.raw {
        println!(
            "  {}: {} raw epochs, {} measurements, {:.1} satellites per epoch (at most {})",
            s.name, r.epochs, r.measurements, r.satellites_mean, r.satellites_max
        );
    }
    if let Some(r) = &s.reference {
        println!(
            "  {}: the device's own solution: {} positions, {} velocities, {} attitudes",
            s.name, r.with_position, r.with_velocity, r.with_attitude
        );
    }
}

/// The arguments as one shell line (quoted where needed).
fn shell_line(args: &[String]) -> String {
    args.iter()
        .map(|a| {
            if a.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_./,=:+".contains(c))
                && !a.is_empty()
            {
                a.clone()
            } else {
                format!("'{}'", a.replace('\'', r"'\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}
