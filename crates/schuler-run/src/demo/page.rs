//! The demo's outputs: one CSV per table or plot, the SVG plots, and `report.html`
//! with everything embedded. Numbers in the report's tables are the strings written
//! to the CSVs (one formatter for both), so the report and the data never disagree.

use super::capture::{Recording, TruthEpoch};
use super::errors::{self, height};
use super::modes::{BARO_LOOP_TAU, SensorEpoch, Track};
use super::polar::Polar;
use super::{Alignments, ModeRun, Sortie, page_polar};
use anyhow::{Context, Result};
use nalgebra::Vector3;
use schuler::analysis::errors::EpochErrors;
use schuler::channel::vertical::Gains;
use schuler::units::{DEG_PER_H, UG};
use schuler_report::html::{Report, Table};
use schuler_report::plot::{LineStyle, Plot};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;
use std::time::Instant;

/// Wall-clock times of the stages before navigation [s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Simulation.
    pub simulate: f64,
    /// Both alignments.
    pub align: f64,
}

/// Metres with millimetres (the CSVs' and the report's format).
pub(super) fn m(x: f64) -> String {
    format!("{x:.3}")
}

/// Radians as arc minutes with two decimals.
fn arcmin(x: f64) -> String {
    format!("{:.2}", x.to_degrees() * 60.0)
}

/// `name` in `dir`: a header line, then one line per row.
pub(super) fn csv(
    dir: &Path,
    name: &str,
    header: &str,
    rows: impl IntoIterator<Item = String>,
) -> Result<()> {
    let path = dir.join(name);
    let mut w = schuler_io::line_file::LineWriter::create(&path)?;
    writeln!(w, "{header}")?;
    for r in rows {
        writeln!(w, "{r}")?;
    }
    w.finish()
}

/// A table of `rows` under `header`, also written as `name` in `dir` (the same
/// strings in both).
pub(super) fn table_with_csv(
    dir: &Path,
    name: &str,
    header: &[&str],
    rows: &[Vec<String>],
) -> Result<Table> {
    csv(
        dir,
        name,
        &header.join(","),
        rows.iter().map(|r| r.join(",")),
    )?;
    Ok(rows
        .iter()
        .fold(Table::new(header.iter().copied()), |t, r| t.row(r.clone())))
}

/// `plot` as `name` in `dir`.
pub(super) fn svg(dir: &Path, name: &str, plot: &Plot) -> Result<()> {
    plot.write(&dir.join(name))
}

/// Time axis of a series of errors [s].
pub(super) fn times(e: &[EpochErrors]) -> Vec<f64> {
    e.iter().map(|x| x.t_sow).collect()
}

/// `errors_<key>.csv` and `nav_<key>.csv` of one mode.
pub(super) fn write_mode(dir: &Path, run: &ModeRun) -> Result<()> {
    csv(
        dir,
        &format!("errors_{}.csv", run.key),
        "t_s,north_m,east_m,circular_m,height_m,roll_arcmin,pitch_arcmin,yaw_arcmin",
        run.errors.iter().map(|e| {
            format!(
                "{:.0},{},{},{},{},{},{},{}",
                e.t_sow,
                m(e.pos_n.x),
                m(e.pos_n.y),
                m(e.horizontal()),
                m(height(e)),
                arcmin(e.att.roll),
                arcmin(e.att.pitch),
                arcmin(e.att.yaw)
            )
        }),
    )?;
    csv(
        dir,
        &format!("nav_{}.csv", run.key),
        "t_s,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,\
         std_n_m,std_e_m,std_d_m",
        run.track.epochs.iter().map(|e| {
            let s = &e.state;
            let eu = s.euler();
            let sd = e.std.map_or([f64::NAN; 3], |[p, _, _]| [p.x, p.y, p.z]);
            format!(
                "{:.0},{:.9},{:.9},{:.3},{:.4},{:.4},{:.4},{:.5},{:.5},{:.5},{:.3},{:.3},{:.3}",
                s.t,
                s.pos.lat.to_degrees(),
                s.pos.lon.to_degrees(),
                s.pos.h,
                s.v_n.x,
                s.v_n.y,
                s.v_n.z,
                eu.roll.to_degrees(),
                eu.pitch.to_degrees(),
                eu.yaw.to_degrees().rem_euclid(360.0),
                sd[0],
                sd[1],
                sd[2]
            )
        }),
    )
}

/// One row of the summary table (the same strings go to `summary.csv`).
fn summary_row(run: &ModeRun, s: &Sortie, end: f64) -> Vec<String> {
    debug_assert!(!run.label.contains(','), "labels are CSV cells");
    let e = &run.errors;
    let at = |t: f64| errors::at(e, t).map_or("-".to_string(), |x| m(x.horizontal()));
    let outage_end = s.outages.last().map_or(end, |o| o.1);
    let dh = e
        .iter()
        .filter(|x| x.t_sow >= s.takeoff)
        .map(|x| height(x).abs())
        .fold(0.0, f64::max);
    let yaw = e.last().map_or("-".to_string(), |x| arcmin(x.att.yaw));
    vec![
        run.label.to_string(),
        at(s.takeoff),
        at(outage_end),
        at(end),
        m(errors::max_circular(e, s.takeoff, end)),
        m(dh),
        yaw,
        format!("{:.2}", run.track.seconds),
        format!("errors_{}.csv", run.key),
    ]
}

const SUMMARY_HEADER: [&str; 9] = [
    "mode",
    "dS at take-off [m]",
    "dS at end of outage [m]",
    "dS at end [m]",
    "max dS in flight [m]",
    "max |dh| in flight [m]",
    "yaw error at end [arcmin]",
    "run time [s]",
    "data",
];

/// Circular error dS of `runs` against time, the GNSS `outages` shaded.
pub(super) fn plot_circular(title: &str, runs: &[&ModeRun], outages: &[(f64, f64)]) -> Plot {
    let mut p = Plot::new(title, "t [s]", "dS [m]");
    let styles = [LineStyle::Solid, LineStyle::Dashed, LineStyle::Dotted];
    for (r, style) in runs.iter().zip(styles.iter().cycle()) {
        let y: Vec<f64> = r.errors.iter().map(EpochErrors::horizontal).collect();
        p = p.line(r.label, &times(&r.errors), &y, *style);
    }
    p.shade("GNSS outage", outages.iter().copied())
}

/// The run `key`.
pub(super) fn find<'a>(runs: &'a [ModeRun], key: &str) -> Result<&'a ModeRun> {
    runs.iter()
        .find(|r| r.key == key)
        .with_context(|| format!("no {key} run"))
}

/// An instrument triad of the sensor outputs.
#[derive(Debug, Clone, Copy)]
enum Triad {
    /// Gyro drift [deg/h].
    Gyros,
    /// Accelerometer bias [ug].
    Accelerometers,
}

impl Triad {
    /// Both, in the CSV's order.
    const ALL: [Triad; 2] = [Triad::Gyros, Triad::Accelerometers];

    /// File and axis-label stem, plot title stem, display unit [SI] and its label.
    fn names(self) -> (&'static str, &'static str, f64, &'static str) {
        match self {
            Triad::Gyros => ("gyro", "Gyro drift", DEG_PER_H, "deg/h"),
            Triad::Accelerometers => ("accel", "Accelerometer bias", UG, "ug"),
        }
    }

    /// The filter's estimate and standard deviation in `x`, and the truth in `tr` [SI].
    fn values(self, x: &SensorEpoch, tr: &TruthEpoch) -> [Vector3<f64>; 3] {
        match self {
            Triad::Gyros => [x.est.gyro_bias, x.gyro_std, tr.gyro_bias],
            Triad::Accelerometers => [x.est.accel_bias, x.accel_std, tr.accel_bias],
        }
    }
}

/// `sensors.csv`: once a second, each axis's estimate, standard deviation and truth.
fn sensors_csv(dir: &Path, rec: &Recording, track: &Track) -> Result<()> {
    let rows = track.sensors.iter().map(|x| {
        let tr = rec.truth_at(x.t);
        let mut row = format!("{:.0}", x.t);
        for k in Triad::ALL {
            let (_, _, unit, _) = k.names();
            let [est, sd, truth] = k.values(x, tr);
            for i in 0..3 {
                let _ = write!(
                    row,
                    ",{:.5},{:.5},{:.5}",
                    est[i] / unit,
                    sd[i] / unit,
                    truth[i] / unit
                );
            }
        }
        row
    });
    csv(
        dir,
        "sensors.csv",
        "t_s,gx_est_deg_h,gx_std_deg_h,gx_true_deg_h,gy_est_deg_h,gy_std_deg_h,gy_true_deg_h,\
         gz_est_deg_h,gz_std_deg_h,gz_true_deg_h,ax_est_ug,ax_std_ug,ax_true_ug,\
         ay_est_ug,ay_std_ug,ay_true_ug,az_est_ug,az_std_ug,az_true_ug",
        rows,
    )
}

/// Axis `i` of the triad `k`: the estimate, the truth and the estimate ± 3σ.
fn sensor_plot(rec: &Recording, track: &Track, k: Triad, i: usize, axis: &str) -> Plot {
    let (name, what, unit, label) = k.names();
    let t: Vec<f64> = track.sensors.iter().map(|x| x.t).collect();
    let [est, sd, truth]: [Vec<f64>; 3] = std::array::from_fn(|j| {
        track
            .sensors
            .iter()
            .map(|x| k.values(x, rec.truth_at(x.t))[j][i] / unit)
            .collect()
    });
    let hi: Vec<f64> = est.iter().zip(&sd).map(|(e, s)| e + 3.0 * s).collect();
    let lo: Vec<f64> = est.iter().zip(&sd).map(|(e, s)| e - 3.0 * s).collect();
    Plot::new(
        &format!("{what}, {axis} axis"),
        "t [s]",
        &format!("{name}_{axis} [{label}]"),
    )
    .line("estimate", &t, &est, LineStyle::Solid)
    .line("truth", &t, &truth, LineStyle::Dashed)
    .line("estimate + 3 sigma", &t, &hi, LineStyle::Dotted)
    .line("estimate - 3 sigma", &t, &lo, LineStyle::Dotted)
}

/// Sensor estimates, truth and 3σ per axis: `sensors.csv` and six plots.
fn sensors(dir: &Path, report: &mut Report, rec: &Recording, track: &Track) -> Result<()> {
    sensors_csv(dir, rec, track)?;
    let sec = report.section("sensors", "Sensor errors estimated in flight");
    sec.paragraph(
        "The inertial-satellite filter's gyro drift and accelerometer bias estimates \
         (the seed's figures 6 and 7) with the simulator's true values and the filter's \
         3-sigma bounds around the estimate. Vertical gyro drift and level accelerometer \
         biases are observable only when the helicopter turns and accelerates.",
    );
    for k in Triad::ALL {
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let p = sensor_plot(rec, track, k, i, axis);
            let file = format!("{}_{axis}.svg", k.names().0);
            svg(dir, &file, &p)?;
            sec.plot_with_files(&p, &[&file, "sensors.csv"]);
        }
    }
    Ok(())
}

fn alignment_section(
    dir: &Path,
    report: &mut Report,
    rec: &Recording,
    a: &Alignments,
    s: &Sortie,
) -> Result<()> {
    let truth = rec.truth_at(s.nav_start()).state.euler();
    let sec = report.section("alignment", "Alignment on the pad");
    sec.paragraph(&format!(
        "Coarse alignment (leveling and analytic gyrocompassing) over {:.0} s, then the fine \
         alignment's Kalman filter on the invariants (position unchanged, zero velocity, \
         attitude unchanged while the gyros turn with the Earth) over {:.0} s, with the rotor \
         turning. For comparison, a coarse alignment alone over the last {:.0} s before \
         navigation starts at {:.0} s.",
        s.coarse,
        s.fine,
        s.coarse,
        s.nav_start()
    ));
    let mut table = Table::new([
        "alignment",
        "roll error [arcmin]",
        "pitch error [arcmin]",
        "yaw error [arcmin]",
        "roll std [arcmin]",
        "pitch std [arcmin]",
        "yaw std [arcmin]",
    ]);
    let mut rows = Vec::new();
    for (name, al) in [("coarse only", &a.coarse_only), ("coarse + fine", &a.fine)] {
        let e = al.state.euler();
        let row = vec![
            name.to_string(),
            arcmin(e.roll - truth.roll),
            arcmin(e.pitch - truth.pitch),
            arcmin(schuler::rotation::wrap_pi(e.yaw - truth.yaw)),
            arcmin(al.attitude_std.x),
            arcmin(al.attitude_std.y),
            arcmin(al.attitude_std.z),
        ];
        rows.push(row.join(","));
        table = table.row(row);
    }
    csv(dir, "alignment.csv", &table.header.join(","), rows)?;
    sec.table(table.caption("Attitude at the start of navigation against the truth"));
    if let Some(fine) = &a.fine.fine {
        let t: Vec<f64> = fine.convergence.iter().map(|c| c.t).collect();
        let col = |i: usize| -> Vec<f64> {
            fine.convergence
                .iter()
                .map(|c| c.attitude_std[i].to_degrees() * 60.0)
                .collect()
        };
        let (r, p, y) = (col(0), col(1), col(2));
        csv(
            dir,
            "alignment_convergence.csv",
            "t_s,roll_std_arcmin,pitch_std_arcmin,yaw_std_arcmin",
            (0..t.len()).map(|k| format!("{:.1},{:.4},{:.4},{:.4}", t[k], r[k], p[k], y[k])),
        )?;
        let plot = Plot::new(
            "Fine alignment: attitude standard deviations",
            "t [s]",
            "std [arcmin]",
        )
        .line("roll", &t, &r, LineStyle::Solid)
        .line("pitch", &t, &p, LineStyle::Dashed)
        .line("yaw", &t, &y, LineStyle::Dotted);
        svg(dir, "alignment_convergence.svg", &plot)?;
        sec.plot_with_files(
            &plot,
            &["alignment_convergence.svg", "alignment_convergence.csv"],
        );
    }
    Ok(())
}

/// The report's opening paragraph: the flight test, the sortie's timing and the data.
fn introduction(s: &Sortie, rec: &Recording, end: f64) -> String {
    format!(
        "The second seed document's flight test of a strapdown inertial-satellite system on \
         fibre-optic gyros, re-enacted on simulated data: a helicopter at {:.1} N, {:.0} s on the \
         pad with the rotor turning, then {:.0} s of flight; IMU at {:.0} Hz (navigation \
         grade, rotor vibration at 17.5 and 35 Hz), GNSS at 1 Hz with an outage, a \
         barometer at 10 Hz. The truth is the simulator's exact trajectory. Scenario: \
         examples/polar_flight.toml{}. Then a short second flight straight over the North \
         Pole, navigated with the all-latitude wander-azimuth mechanization.",
        rec.truth[0].state.pos.lat.to_degrees(),
        s.takeoff,
        end - s.takeoff,
        rec.rate,
        if rec.rate < 1000.0 {
            " (shortened with --quick)"
        } else {
            ""
        }
    )
}

/// The truth's east and north of the pad [km], on the plane tangent at the pad (the
/// pad's meridian and prime-vertical radii).
fn track_from_pad(rec: &Recording) -> (Vec<f64>, Vec<f64>) {
    let t0 = &rec.truth[0].state;
    let r0 = schuler::earth::EarthModel::radii(&schuler::earth::Wgs84, t0.pos.lat);
    let east: Vec<f64> = rec
        .truth
        .iter()
        .map(|e| (e.state.pos.lon - t0.pos.lon) * r0.prime_vertical * t0.pos.lat.cos() / 1e3)
        .collect();
    let north: Vec<f64> = rec
        .truth
        .iter()
        .map(|e| (e.state.pos.lat - t0.pos.lat) * r0.meridian / 1e3)
        .collect();
    (east, north)
}

/// The sortie's phases, each from and to [s].
fn timeline(s: &Sortie, end: f64) -> Table {
    [
        ("coarse alignment", s.t0(), s.coarse_end()),
        ("fine alignment", s.coarse_end(), s.nav_start()),
        ("navigation on the pad", s.nav_start(), s.takeoff),
        ("flight", s.takeoff, end),
    ]
    .into_iter()
    .fold(
        Table::new(["phase", "from [s]", "to [s]"]),
        |table, (phase, from, to)| {
            table.row([phase.to_string(), format!("{from:.0}"), format!("{to:.0}")])
        },
    )
    .caption("Timeline")
}

/// The sortie's section: its timeline, the GNSS outages and the ground track
/// (`trajectory.csv`, `trajectory.svg`).
fn sortie_section(
    dir: &Path,
    report: &mut Report,
    s: &Sortie,
    rec: &Recording,
    end: f64,
) -> Result<()> {
    let (east, north) = track_from_pad(rec);
    csv(
        dir,
        "trajectory.csv",
        "t_s,east_km,north_km,h_m",
        rec.truth
            .iter()
            .zip(east.iter().zip(&north))
            .map(|(e, (x, y))| format!("{:.0},{x:.4},{y:.4},{:.2}", e.state.t, e.state.pos.h)),
    )?;
    let map = Plot::new("Ground track from the pad", "east [km]", "north [km]").line(
        "truth",
        &east,
        &north,
        LineStyle::Solid,
    );
    svg(dir, "trajectory.svg", &map)?;
    let sec = report.section("sortie", "The sortie");
    sec.table(timeline(s, end));
    for (a0, b0) in &s.outages {
        sec.paragraph(&format!("GNSS outage from {a0:.0} s to {b0:.0} s."));
    }
    sec.plot_with_files(&map, &["trajectory.svg", "trajectory.csv"]);
    Ok(())
}

/// The inertial mode's section: the circular error after the fine alignment and after
/// the coarse one alone (`inertial_circular.svg`).
fn inertial_section(
    dir: &Path,
    report: &mut Report,
    s: &Sortie,
    rec: &Recording,
    a: &Alignments,
    runs: &[ModeRun],
    end: f64,
) -> Result<()> {
    let inertial = find(runs, "inertial")?;
    let coarse = find(runs, "inertial_coarse")?;
    let p = plot_circular(
        "Inertial mode: circular error dS",
        &[coarse, inertial],
        &s.outages,
    );
    svg(dir, "inertial_circular.svg", &p)?;
    let ratio = errors::max_circular(&coarse.errors, s.nav_start(), end)
        / errors::max_circular(&inertial.errors, s.nav_start(), end);
    report
        .section("inertial", "Inertial mode")
        .paragraph(&format!(
            "Free strapdown navigation from the aligned state, the vertical channel damped by \
             the barometer (loop time constant {BARO_LOOP_TAU:.0} s). After the fine alignment \
             on the invariants the largest circular error is {:.1} times {} than after coarse \
             alignment alone. The seed reports at least an order of magnitude; here the \
             navigation-grade FOG already gives a coarse heading good to {} arcmin (1 sigma), \
             and at {:.0} N the east gyro drift, which no alignment at rest separates from \
             heading, holds the fine one to {} arcmin. What remains is mostly the level \
             accelerometer biases: leveling hides them on the pad, and turns reveal them (the \
             textbook: the cancellation holds only while the heading stays constant). The \
             error oscillates with the 84.4-minute Schuler period.",
            ratio.max(1.0 / ratio),
            if ratio >= 1.0 { "smaller" } else { "larger" },
            arcmin(a.coarse_only.attitude_std.z),
            rec.truth[0].state.pos.lat.to_degrees(),
            arcmin(a.fine.attitude_std.z),
        ))
        .plot_with_files(
            &p,
            &[
                "inertial_circular.svg",
                "errors_inertial.csv",
                "errors_inertial_coarse.csv",
            ],
        );
    Ok(())
}

/// How many GNSS fixes the filter's gate refused (a fix refused twice counts once).
fn refused_fixes(track: &Track) -> usize {
    let mut t = track.rejected.clone();
    t.dedup();
    t.len()
}

/// The inertial-satellite mode's section: the filter's and the smoother's circular
/// error (`aided_circular.svg`) and the gate's refusals.
fn aided_section(
    dir: &Path,
    report: &mut Report,
    s: &Sortie,
    rec: &Recording,
    runs: &[ModeRun],
) -> Result<()> {
    let forward = find(runs, "aided")?;
    let smoothed = find(runs, "smoothed")?;
    let p = plot_circular(
        "Inertial-satellite mode: circular error dS",
        &[forward, smoothed],
        &s.outages,
    );
    svg(dir, "aided_circular.svg", &p)?;
    let sec = report.section("aided", "Inertial-satellite mode");
    sec.paragraph(&format!(
        "The error-state Kalman filter (15 states and the barometer bias) on GNSS position and \
         velocity differences with the antenna's lever arm, the barometer's height, and a \
         chi-square gate; then the Rauch-Tung-Striebel smoother. The gate refused {} fix(es) \
         (the simulator injected outliers at {}).",
        refused_fixes(&forward.track),
        rec.gnss_outliers
            .iter()
            .map(|t| format!("{t:.0} s"))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    sec.plot_with_files(
        &p,
        &[
            "aided_circular.svg",
            "errors_aided.csv",
            "errors_smoothed.csv",
        ],
    );
    Ok(())
}

/// The vertical channel's section: the height error free, with the baro loop (34) and
/// in the filter (`vertical.svg`), and the loop's fault detector.
fn vertical_section(dir: &Path, report: &mut Report, runs: &[ModeRun], gains: Gains) -> Result<()> {
    let no_baro = find(runs, "inertial_no_baro")?;
    let inertial = find(runs, "inertial")?;
    let forward = find(runs, "aided")?;
    let mut p = Plot::new("Vertical channel: height error", "t [s]", "dh [m]");
    for r in [no_baro, inertial, forward] {
        let y: Vec<f64> = r.errors.iter().map(height).collect();
        p = p.line(r.label, &times(&r.errors), &y, LineStyle::Solid);
    }
    svg(dir, "vertical.svg", &p)?;
    let counts = inertial.track.baro.unwrap_or_default();
    report
        .section("vertical", "Vertical channel")
        .paragraph(&format!(
            "Free, the vertical channel is unstable (e-fold time 1/(sqrt(2) w0), about 570 s). \
             The barometer loop r' = V + k1 (r - r*), V' = f - g(r) + k2 (r - r*) with \
             critically damped gains k1 = {:.4} 1/s, k2 = {:.3e} 1/s^2 holds it; its fault \
             detector accepted {} and rejected {} readings.",
            gains.k1, gains.k2, counts.accepted, counts.rejected
        ))
        .plot_with_files(
            &p,
            &[
                "vertical.svg",
                "errors_inertial_no_baro.csv",
                "errors_inertial.csv",
            ],
        );
    Ok(())
}

/// The summary section: the table of `rows` (also `summary.csv`) and the run times;
/// returns the run time so far [s].
fn summary_section(
    dir: &Path,
    report: &mut Report,
    rows: &[Vec<String>],
    polar: &Polar,
    timing: Timing,
    started: Instant,
) -> Result<f64> {
    let table = table_with_csv(dir, "summary.csv", &SUMMARY_HEADER, rows)?;
    let total = started.elapsed().as_secs_f64();
    let sec = report.section("summary", "Summary");
    sec.table(table.caption("Errors at the end of each phase (summary.csv)"));
    sec.paragraph(&format!(
        "Run time: simulation {:.2} s, alignment {:.2} s, navigation in parallel, then the \
         pole crossing (simulation {:.2} s, navigation in parallel); {:.1} s in all before \
         this report. The crossing's errors are in its own table (section Across the pole).",
        timing.simulate, timing.align, polar.simulate_s, total
    ));
    Ok(total)
}

/// The text for stdout: the `headline`, one line per mode of the sortie (`rows`) and of
/// the crossing (`polar_rows`), and where the report is.
fn stdout_text(
    headline: &str,
    rows: &[Vec<String>],
    polar: &Polar,
    polar_rows: &[Vec<String>],
    report: &Path,
) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "{headline}");
    for r in rows {
        let _ = writeln!(
            out,
            "  {:<36} dS at end {:>10} m, max in flight {:>10} m",
            r[0], r[3], r[4]
        );
    }
    let _ = writeln!(
        out,
        "across the pole ({:.0} s at {:.0} Hz):",
        polar.crossing.duration, polar.rec.rate
    );
    for r in polar_rows {
        let _ = writeln!(
            out,
            "  {:<36} dS at end {:>10} m, max {:>10} m",
            r[0], r[4], r[5]
        );
    }
    let _ = write!(out, "report: {}", report.display());
    out
}

/// Write every output and return the text summary for stdout.
#[allow(clippy::too_many_arguments)]
pub fn write(
    dir: &Path,
    s: &Sortie,
    rec: &Recording,
    a: &Alignments,
    runs: &[ModeRun],
    polar: &Polar,
    fig3: &super::figure3::Figure3,
    gains: Gains,
    timing: Timing,
    started: Instant,
) -> Result<String> {
    for r in runs.iter().chain([&fig3.run]) {
        write_mode(dir, r)?;
    }
    let end = rec.truth.last().map_or(0.0, |e| e.state.t);
    let mut report = Report::new("schuler demo: a polar helicopter sortie, re-enacted");
    report.paragraph(&introduction(s, rec, end));
    sortie_section(dir, &mut report, s, rec, end)?;
    alignment_section(dir, &mut report, rec, a, s)?;
    inertial_section(dir, &mut report, s, rec, a, runs, end)?;
    super::page_figure3::section(dir, &mut report, runs, fig3)?;
    aided_section(dir, &mut report, s, rec, runs)?;
    sensors(dir, &mut report, rec, &find(runs, "aided")?.track)?;
    vertical_section(dir, &mut report, runs, gains)?;
    let polar_rows = page_polar::section(dir, &mut report, polar)?;
    let rows: Vec<Vec<String>> = runs.iter().map(|r| summary_row(r, s, end)).collect();
    let total = summary_section(dir, &mut report, &rows, polar, timing, started)?;
    let missing = report.plots_missing_units();
    anyhow::ensure!(missing.is_empty(), "plots without units: {missing:?}");
    let path = dir.join("report.html");
    report.write(&path)?;
    let headline = format!(
        "schuler demo: polar helicopter sortie ({:.0} s at {:.0} Hz) in {total:.1} s",
        end - s.t0(),
        rec.rate
    );
    Ok(stdout_text(&headline, &rows, polar, &polar_rows, &path))
}
