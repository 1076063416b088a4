//! The aided run's consistency report and `report.html`.
//!
//! After `schuler nav --gnss ...` has written its results:
//! - `consistency.json` (always) and a few printed lines: per measurement kind the NIS
//!   of the accepted measurements against chi-square (per-update 95 % interval, the
//!   average's interval from `chi2(N dof)`, the fraction outside), and with `--truth`
//!   the NEES of position, velocity and attitude (3 dof each) sampled once a second
//!   ([`schuler::analysis::consistency`]);
//! - unless `--no-report`, `report.html` (one self-contained file,
//!   [`schuler_report::html::Report`]) and `report/`, the SVG plots and CSV data behind
//!   them: position error against the truth (the seed's circular error dS and the
//!   vertical error, GNSS gaps shaded, the statistics of `schuler compare`), the
//!   estimated sensor errors with ±3σ bounds (with `--sensor-truth`, their truth),
//!   innovations with ±3σ of their predicted covariance, NIS and NEES with their
//!   bounds, and the accepted and refused measurements per kind.
//!
//! NIS is tested over the accepted measurements: the refused ones are outliers by the
//! filter's own test, counted apart (including them would let one 50-m jump dominate
//! the mean). Successive NEES values of one run are correlated (the error drifts
//! slowly), so the interval of their average, which assumes independence, is
//! narrower than a single run's spread; the Monte-Carlo test in the library
//! (`tests/gnss_integration.rs`) is the sharp one.

mod calibration;

use super::record::{InnovationRow, ReportSample};
use super::series::{Series, series};
use super::spilled::Spilled;
use anyhow::{Context, Result};
use schuler::analysis::consistency::ChiSquareTest;
use schuler::analysis::errors::NavRecord;
use schuler::analysis::statistics::{Comparison, QUANTITIES, compare};
use schuler::filter::integration::Counts;
use schuler::filter::measurement::Kind;
use schuler::filter::{GnssFix, Layout, SensorEstimates};
use schuler::session::MechanizationKind;
use schuler::units::{DEG_PER_H, MGAL, PPM};
use schuler_report::html::{Report, Table};
use schuler_report::plot::{LineStyle, Plot};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Probability of every chi-square interval in the report.
pub const PROBABILITY: f64 = 0.95;

/// What the report is given beyond the run (`--no-report`, `--truth`,
/// `--sensor-truth`), the files read and checked before the run starts.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportSettings {
    /// Write `report.html` and `report/`.
    pub html: bool,
    /// Navigation truth (KF-GINS text or nav.csv), for errors and NEES.
    pub truth: Option<Truth>,
    /// Sensor-error truth (`imu_err.txt`'s layout), in time order; empty: none.
    pub sensor_truth: Vec<(f64, SensorEstimates)>,
}

impl Default for ReportSettings {
    fn default() -> Self {
        Self {
            html: true,
            truth: None,
            sensor_truth: Vec::new(),
        }
    }
}

impl ReportSettings {
    /// The truth's epochs (empty without one), read whole.
    pub fn truth_records(&self) -> Result<Vec<NavRecord>> {
        self.truth.as_ref().map_or(Ok(Vec::new()), Truth::records)
    }
}

/// The navigation truth of `--truth`, or one held in memory (a campaign's simulated
/// truth).
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    /// Its file, as the report names it.
    pub path: PathBuf,
    /// Its epochs in time order when held in memory; `None`: read from `path` (checked
    /// whole when the options were loaded) as the run goes, an epoch at a time.
    pub held: Option<Vec<NavRecord>>,
}

impl Truth {
    /// A truth file, read as the run goes (checked through now).
    pub fn file(path: &Path) -> Result<Self> {
        schuler_io::formats::nav::check_nav(path)?;
        Ok(Self {
            path: path.to_path_buf(),
            held: None,
        })
    }

    /// Every epoch (the file read whole).
    pub fn records(&self) -> Result<Vec<NavRecord>> {
        match &self.held {
            Some(rows) => Ok(rows.clone()),
            None => Ok(schuler_io::formats::nav::read_nav(&self.path)?.1),
        }
    }
}

/// Facts of the run the report states.
#[derive(Debug, Clone, Copy)]
pub struct RunFacts<'a> {
    /// The IMU log.
    pub imu: &'a Path,
    /// The navigation result written (forward filter).
    pub nav_file: &'a Path,
    /// Mechanization the filter ran on.
    pub mechanization: MechanizationKind,
    /// The filter's states.
    pub layout: Layout,
    /// How many (18 under `--error-model seed18`, else the layout's).
    pub states: usize,
    /// IMU samples integrated.
    pub samples: u64,
    /// First time [s].
    pub t_first: f64,
    /// Last time [s].
    pub t_last: f64,
    /// Filter counters.
    pub counts: Counts,
    /// Times the gate was bypassed after consecutive refusals.
    pub gate_resets: usize,
    /// The GNSS fixes used (after any test outages were cut out).
    pub fixes: &'a super::fixes::Fixes,
}

/// The NIS test of one measurement kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KindConsistency {
    /// The kind.
    pub kind: Kind,
    /// Its dimension.
    pub dof: usize,
    /// Measurements accepted by the gate.
    pub accepted: usize,
    /// Measurements refused.
    pub refused: usize,
    /// The test of the accepted ones' NIS (`None` without any).
    pub test: Option<ChiSquareTest>,
}

/// NIS per kind, in order of first appearance, over the rows `rows()` yields (read
/// once per kind).
pub fn nis_by_kind<I>(rows: impl Fn() -> I) -> Vec<KindConsistency>
where
    I: Iterator<Item = InnovationRow>,
{
    let mut kinds: Vec<(Kind, usize)> = Vec::new();
    for r in rows() {
        if !kinds.iter().any(|k| k.0 == r.kind) {
            kinds.push((r.kind, r.dof));
        }
    }
    kinds
        .into_iter()
        .map(|(kind, dof)| {
            let of_kind = || rows().filter(move |r| r.kind == kind);
            let accepted = of_kind().filter(|r| r.accepted).count();
            KindConsistency {
                kind,
                dof,
                accepted,
                refused: of_kind().count() - accepted,
                test: ChiSquareTest::of(
                    of_kind().filter(|r| r.accepted).map(|r| r.nis),
                    dof,
                    PROBABILITY,
                ),
            }
        })
        .collect()
}

/// Names of the NEES blocks, in [`ReportSample::nees`] order.
pub const NEES_BLOCKS: [&str; 3] = ["position", "velocity", "attitude"];

/// NEES tests of position, velocity and attitude over the samples `samples()` yields
/// that have one.
pub fn nees_tests<I>(samples: impl Fn() -> I) -> [Option<ChiSquareTest>; 3]
where
    I: Iterator<Item = ReportSample>,
{
    std::array::from_fn(|k| {
        ChiSquareTest::of(
            samples().filter_map(|s| s.nees.map(|n| n[k].unwrap_or(f64::INFINITY))),
            3,
            PROBABILITY,
        )
    })
}

fn test_json(t: &ChiSquareTest) -> Value {
    json!({
        "dof": t.dof, "count": t.count, "non_finite": t.non_finite, "mean": t.mean,
        "epoch_interval": [t.epoch_bounds.lo, t.epoch_bounds.hi],
        "mean_interval": [t.mean_bounds.lo, t.mean_bounds.hi],
        "mean_inside": t.mean_inside(),
        "fraction_below": t.fraction_below, "fraction_above": t.fraction_above,
        "fraction_outside": t.fraction_outside(),
    })
}

/// `consistency.json`: NIS per kind and, with a truth, NEES.
pub fn consistency_json(
    nis: &[KindConsistency],
    nees: Option<&[Option<ChiSquareTest>; 3]>,
) -> Value {
    let nis: Vec<Value> = nis
        .iter()
        .map(|k| {
            json!({
                "kind": k.kind.to_string(), "dof": k.dof,
                "accepted": k.accepted, "refused": k.refused,
                "test": k.test.as_ref().map(test_json),
            })
        })
        .collect();
    let nees = nees.map(|tests| {
        let mut m = serde_json::Map::new();
        m.insert("sampling_s".to_owned(), json!(1.0));
        m.insert(
            "note".to_owned(),
            json!(
                "successive epochs are correlated: the mean's interval assumes independent epochs"
            ),
        );
        for (name, t) in NEES_BLOCKS.iter().zip(tests) {
            m.insert(
                (*name).to_owned(),
                t.as_ref().map_or(Value::Null, test_json),
            );
        }
        Value::Object(m)
    });
    json!({
        "probability": PROBABILITY,
        "nis_over": "accepted measurements",
        "nis": nis,
        "nees": nees,
    })
}

fn test_line(t: &ChiSquareTest) -> String {
    format!(
        "mean {:.3} {} [{:.3}, {:.3}]; {:.1} % outside [{:.3}, {:.3}]",
        t.mean,
        if t.mean_inside() { "in" } else { "NOT in" },
        t.mean_bounds.lo,
        t.mean_bounds.hi,
        100.0 * t.fraction_outside(),
        t.epoch_bounds.lo,
        t.epoch_bounds.hi
    )
}

/// The printed consistency summary.
pub fn consistency_text(
    nis: &[KindConsistency],
    nees: Option<&[Option<ChiSquareTest>; 3]>,
) -> String {
    let mut s = format!(
        "consistency ({:.0} % chi-square intervals; consistency.json):\n",
        100.0 * PROBABILITY
    );
    for k in nis {
        let _ = write!(s, "  NIS  {:<14} {} dof: ", k.kind.to_string(), k.dof);
        match &k.test {
            Some(t) => s.push_str(&test_line(t)),
            None => s.push_str("no accepted measurement"),
        }
        let _ = writeln!(s, "; {} accepted, {} refused", k.accepted, k.refused);
    }
    if let Some(tests) = nees {
        for (name, t) in NEES_BLOCKS.iter().zip(tests) {
            let _ = write!(s, "  NEES {name:<14} 3 dof: ");
            match t {
                Some(t) => {
                    let _ = writeln!(s, "{} ({} epochs at 1 Hz)", test_line(t), t.count);
                }
                None => s.push_str("no epoch inside the truth's span\n"),
            }
        }
    }
    s
}

/// GNSS gaps: intervals between consecutive fixes more than twice the median spacing
/// apart (outages, given or cut by `--outage-test`).
pub fn gnss_gaps(fixes: &[GnssFix]) -> Vec<(f64, f64)> {
    let times: Vec<f64> = fixes.iter().map(|f| f.t).collect();
    gaps_of_times(&times)
}

/// [`gnss_gaps`] of the fixes' times `t` [s].
pub fn gaps_of_times(t: &[f64]) -> Vec<(f64, f64)> {
    if t.len() < 3 {
        return Vec::new();
    }
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_unstable_by(f64::total_cmp);
    let median = dt[dt.len() / 2];
    t.windows(2)
        .filter(|w| w[1] - w[0] > 2.0 * median)
        .map(|w| (w[0], w[1]))
        .collect()
}

/// A series plus its ±`k`·σ envelope about `center` (a zero `center`: about zero),
/// as two lines: the series, and the envelope drawn as one series (upper, a break,
/// lower) so both bounds share a colour and a legend entry; `t` and the values carry
/// the gaps' NaN points ([`series`]), where the lines break.
fn with_envelope(
    plot: Plot,
    (name, band): (&str, &str),
    t: &[f64],
    y: &[f64],
    center: &[f64],
    sigma3: &[f64],
) -> Plot {
    let (xb, yb) = envelope(t, center, sigma3);
    plot.line(name, t, y, LineStyle::Solid)
        .line(band, &xb, &yb, LineStyle::Dashed)
}

/// The points of the envelope `center ± sigma3` as one series: the upper bound, a
/// break, the lower bound.
fn envelope(t: &[f64], center: &[f64], sigma3: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut yb: Vec<f64> = center.iter().zip(sigma3).map(|(c, s)| c + s).collect();
    yb.push(f64::NAN);
    yb.extend(center.iter().zip(sigma3).map(|(c, s)| c - s));
    let mut xb = t.to_vec();
    xb.push(f64::NAN);
    xb.extend_from_slice(t);
    (xb, yb)
}

/// What every section needs: where plots and CSVs go (`OUT/report/`), the run's
/// data, and the GNSS gaps to shade.
struct Ctx<'a> {
    dir: PathBuf,
    data: &'a ReportData<'a>,
    gaps: Vec<(f64, f64)>,
}

/// The time axis of every plot.
const T_LABEL: &str = "t − t0 [s]";

impl Ctx<'_> {
    /// Time from the run's start [s].
    fn rel(&self, t: f64) -> f64 {
        t - self.data.facts.t_first
    }

    /// The plot with the GNSS gaps shaded.
    fn shade(&self, p: Plot) -> Plot {
        if self.gaps.is_empty() {
            p
        } else {
            p.shade(
                "GNSS gap",
                self.gaps.iter().map(|&(a, b)| (self.rel(a), self.rel(b))),
            )
        }
    }

    fn svg(&self, name: &str, plot: &Plot) -> Result<String> {
        plot.write(&self.dir.join(format!("{name}.svg")))?;
        Ok(format!("report/{name}.svg"))
    }

    /// A CSV with a header and one row per item, numbers shortest round-trip, `None`
    /// empty; streamed, and removed if it cannot be written whole.
    fn csv(
        &self,
        name: &str,
        header: &str,
        rows: impl Iterator<Item = Vec<Option<f64>>>,
    ) -> Result<String> {
        let path = self.dir.join(name);
        let written = write_csv(&path, header, rows);
        if written.is_err() {
            let _ = std::fs::remove_file(&path);
        }
        written?;
        Ok(format!("report/{name}"))
    }
}

/// Writes `path`: `header`, then each row, numbers shortest round-trip, `None` empty.
fn write_csv(
    path: &Path,
    header: &str,
    rows: impl Iterator<Item = Vec<Option<f64>>>,
) -> Result<()> {
    use std::io::Write as _;
    let mut w = schuler_io::line_file::LineWriter::create(path)?;
    let mut s = String::with_capacity(1 << 10);
    writeln!(w, "{header}").with_context(|| format!("cannot write {}", path.display()))?;
    for row in rows {
        s.clear();
        for (k, v) in row.iter().enumerate() {
            if k > 0 {
                s.push(',');
            }
            if let Some(v) = v {
                let _ = write!(s, "{v}");
            }
        }
        s.push('\n');
        w.write_all(s.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    w.finish()
}

/// Everything the report is built from.
pub struct ReportData<'a> {
    /// The run.
    pub facts: RunFacts<'a>,
    /// Every tested measurement.
    pub innovations: &'a Spilled<InnovationRow>,
    /// The filter's snapshots, once a second.
    pub samples: &'a Spilled<ReportSample>,
    /// The truths.
    pub settings: &'a ReportSettings,
}

/// Writes `consistency.json` and, if `html`, `report.html` with `report/`; returns
/// the text to print.
pub fn write(out: &Path, html: bool, data: &ReportData) -> Result<String> {
    let nis = nis_by_kind(|| data.innovations.iter());
    let has_truth = data.settings.truth.is_some();
    let nees = has_truth.then(|| nees_tests(|| data.samples.iter()));
    // What the stored records could not give back fails the report here.
    data.innovations.status()?;
    data.samples.status()?;
    let path = out.join("consistency.json");
    let text = serde_json::to_string_pretty(&consistency_json(&nis, nees.as_ref()))?;
    schuler_io::line_file::write_whole(&path, text + "\n")?;
    let mut printed = consistency_text(&nis, nees.as_ref());
    if html {
        let ctx = Ctx {
            dir: out.join("report"),
            data,
            gaps: data.facts.fixes.gaps().to_vec(),
        };
        std::fs::create_dir_all(&ctx.dir)
            .with_context(|| format!("cannot create {}", ctx.dir.display()))?;
        let report = build(&ctx, &nis, nees.as_ref())?;
        let missing = report.plots_missing_units();
        debug_assert!(missing.is_empty(), "plots without units: {missing:?}");
        data.innovations.status()?;
        data.samples.status()?;
        report.write(&out.join("report.html"))?;
        let _ = writeln!(printed, "report: {}", out.join("report.html").display());
    }
    Ok(printed)
}

fn f3(x: f64) -> String {
    format!("{x:.3}")
}

/// Builds the report, writing each plot's SVG and CSV.
fn build(
    c: &Ctx,
    nis: &[KindConsistency],
    nees: Option<&[Option<ChiSquareTest>; 3]>,
) -> Result<Report> {
    let f = &c.data.facts;
    let gaps = &c.gaps;
    let mut r = Report::new("schuler nav: INS/GNSS integration");
    r.paragraph(&format!(
        "IMU log {}: {} samples from t0 = {} s to {} s ({:.1} s), {} mechanization, \
         {} filter states; {} GNSS fixes, {} gaps longer than twice their spacing \
         (shaded in the plots). Times in the plots are counted from t0.",
        f.imu.display(),
        f.samples,
        f.t_first,
        f.t_last,
        f.t_last - f.t_first,
        f.mechanization,
        f.states,
        f.fixes.len(),
        gaps.len()
    ));

    // Measurements: counts per kind.
    let s = r.section("measurements", "Measurements accepted and refused");
    let mut table = Table::new(["measurement", "dof", "accepted", "refused by the gate"]);
    for k in nis {
        table = table.row([
            k.kind.to_string(),
            k.dof.to_string(),
            k.accepted.to_string(),
            k.refused.to_string(),
        ]);
    }
    s.table(table.caption(
        "Measurements the filter tested (innovations.csv; refusals with reasons in rejected.csv)",
    ));
    s.paragraph(&format!(
        "{} GNSS fixes fell outside the IMU data and were not used; the gate was bypassed \
         {} times after consecutive refusals (filter reset).",
        f.counts.skipped, f.gate_resets
    ));

    position_section(&mut r, c)?;
    sensor_section(&mut r, c)?;
    calibration::section(&mut r, c)?;
    innovation_section(&mut r, c)?;
    nis_section(&mut r, c, nis)?;
    if let Some(nees) = nees {
        nees_section(&mut r, c, nees)?;
    }
    let s = r.section("files", "Files");
    s.paragraph(&format!(
        "In {}: the navigation result, std.txt (standard deviations), imu_err.txt \
         (estimated sensor errors), rejected.csv, innovations.csv, consistency.json, this \
         report, and report/ with every plot as SVG and the CSV behind it.",
        f.nav_file
            .parent()
            .map_or_else(String::new, |p| p.display().to_string())
    ));
    Ok(r)
}

/// One column of `sensor_errors.csv`.
type Column = Box<dyn Fn(&ReportSample) -> f64>;

/// The position section's opening: how many epochs were compared, and how the errors
/// and statistics are defined.
fn comparison_text(c: &Ctx, cmp: &Comparison, truth_path: &Path) -> String {
    format!(
        "{} epochs of {} against {} ({} exact, {} with the truth interpolated). \
         Horizontal is the seed's circular error dS = sqrt(dN² + dE²); vertical dD is \
         positive down. Statistics as `schuler compare` gives them: 95 % is the \
         nearest-rank percentile of |e|, CEP the median of dS.",
        cmp.matching.matched(),
        c.data.facts.nav_file.display(),
        truth_path.display(),
        cmp.matching.exact,
        cmp.matching.interpolated
    )
}

/// RMS, largest, 95 % and mean of each error quantity over the run, with CEP and
/// CEP95 in the caption.
fn error_table(c: &Ctx, cmp: &Comparison) -> Table {
    let mut table = Table::new([
        "error",
        "unit",
        "RMS",
        "max |e|",
        "at t − t0 [s]",
        "95 % |e|",
        "mean",
    ]);
    for (q, sm) in QUANTITIES.iter().zip(&cmp.stats.summaries) {
        table = table.row([
            q.name.to_owned(),
            q.unit.to_owned(),
            format!("{:.4}", sm.rms),
            format!("{:.4}", sm.max_abs),
            format!("{:.1}", c.rel(sm.t_max_sow)),
            format!("{:.4}", sm.p95_abs),
            format!("{:.4}", sm.mean),
        ]);
    }
    table.caption(&format!(
        "Errors over the run; CEP {:.4} m, CEP95 {:.4} m",
        cmp.stats.cep, cmp.stats.cep95
    ))
}

/// The largest errors inside each GNSS gap that has compared epochs (INS bridging)
/// and the RMS of those maxima; `None` without such a gap.
fn gap_table(c: &Ctx, cmp: &Comparison) -> Option<Table> {
    let with: Vec<_> = cmp.stats.outages.iter().filter(|o| o.epochs > 0).collect();
    if with.is_empty() {
        return None;
    }
    let mut t = Table::new([
        "GNSS gap, t − t0 [s]",
        "epochs",
        "max dS [m]",
        "max |dD| [m]",
        "max |yaw| [deg]",
    ]);
    for o in &with {
        t = t.row([
            format!("{:.1}–{:.1}", c.rel(o.from_sow), c.rel(o.to_sow)),
            o.epochs.to_string(),
            format!("{:.3}", o.horizontal),
            format!("{:.3}", o.vertical),
            format!("{:.4}", o.att.yaw.to_degrees()),
        ]);
    }
    if let Some(rms) = &cmp.stats.outage_rms {
        t = t.row([
            "RMS of the maxima".to_owned(),
            rms.epochs.to_string(),
            format!("{:.3}", rms.horizontal),
            format!("{:.3}", rms.vertical),
            format!("{:.4}", rms.att.yaw.to_degrees()),
        ]);
    }
    Some(t.caption("Largest errors inside each GNSS gap (INS bridging)"))
}

/// The circular error dS and the vertical error dD against time, gaps shaded.
fn position_plot(c: &Ctx, cmp: &Comparison) -> Plot {
    let t: Vec<f64> = cmp.errors.iter().map(|e| c.rel(e.t_sow)).collect();
    let ds: Vec<f64> = cmp.errors.iter().map(|e| e.horizontal()).collect();
    let dd: Vec<f64> = cmp.errors.iter().map(|e| e.pos_n.z).collect();
    c.shade(
        Plot::new("Position error against the truth", T_LABEL, "error [m]")
            .line("circular error dS (horizontal)", &t, &ds, LineStyle::Solid)
            .line("vertical dD (down)", &t, &dd, LineStyle::Dashed),
    )
}

/// The navigation result against the truth (`--truth`): statistics, the errors in
/// the GNSS gaps, `errors.csv` and the plot; a note without a truth.
fn position_section(r: &mut Report, c: &Ctx) -> Result<()> {
    let data = c.data;
    let s = r.section("position", "Position error against the truth");
    let Some(truth) = &data.settings.truth else {
        s.paragraph("No truth given (--truth FILE, KF-GINS navigation text or nav.csv).");
        return Ok(());
    };
    let truth_path = &truth.path;
    let (_, nav) = schuler_io::formats::nav::read_nav(data.facts.nav_file)?;
    let truth = truth.records()?;
    let cmp: Comparison = compare(&nav, &truth, None, None, &c.gaps).with_context(|| {
        format!(
            "comparing {} with {}",
            data.facts.nav_file.display(),
            truth_path.display()
        )
    })?;
    s.paragraph(&comparison_text(c, &cmp, truth_path));
    s.table(error_table(c, &cmp));
    if let Some(t) = gap_table(c, &cmp) {
        s.table(t);
    }
    schuler_io::output::write_errors_csv(&c.dir.join("errors.csv"), &cmp.errors)?;
    let plot = position_plot(c, &cmp);
    let svg = c.svg("position_error", &plot)?;
    s.plot_with_files(&plot, &[&svg, "report/errors.csv"]);
    Ok(())
}

/// One sensor quantity: name, file stem, unit and scale, and how to pick its
/// estimate, standard deviation and truth.
struct SensorQuantity {
    name: &'static str,
    stem: &'static str,
    unit: &'static str,
    scale: f64,
    block: usize,
}

const SENSORS: [SensorQuantity; 4] = [
    SensorQuantity {
        name: "Gyro bias",
        stem: "gyro_bias",
        unit: "deg/h",
        scale: DEG_PER_H,
        block: 0,
    },
    SensorQuantity {
        name: "Accelerometer bias",
        stem: "accel_bias",
        unit: "mGal",
        scale: MGAL,
        block: 1,
    },
    SensorQuantity {
        name: "Gyro scale factor",
        stem: "gyro_scale",
        unit: "ppm",
        scale: PPM,
        block: 2,
    },
    SensorQuantity {
        name: "Accelerometer scale factor",
        stem: "accel_scale",
        unit: "ppm",
        scale: PPM,
        block: 3,
    },
];

fn sensor_block(e: &SensorEstimates, block: usize) -> nalgebra::Vector3<f64> {
    match block {
        0 => e.gyro_bias,
        1 => e.accel_bias,
        2 => e.gyro_scale,
        _ => e.accel_scale,
    }
}

/// The quantities of [`SENSORS`] the filter estimates: the biases always, each scale
/// factor with its states.
fn estimated_sensors(layout: Layout) -> impl Iterator<Item = &'static SensorQuantity> {
    let estimated = [
        true,
        true,
        layout.gyro_scale.is_some(),
        layout.accel_scale.is_some(),
    ];
    SENSORS.iter().filter(move |q| estimated[q.block])
}

/// An estimate once a second with its ±3σ envelope about it, 320 px high: `pick`
/// gives a sample's `[estimate, 3σ]`.
fn estimate_plot(
    c: &Ctx,
    title: &str,
    y_label: &str,
    pick: impl Fn(&ReportSample) -> [f64; 2],
) -> Plot {
    let s: Series<2> = series(|| c.data.samples.iter().map(|x| (c.rel(x.t), pick(&x))), 0);
    let est = s.column(0);
    let mut plot = with_envelope(
        Plot::new(title, T_LABEL, y_label),
        ("estimate", "estimate ± 3σ"),
        &s.t,
        &est,
        &est,
        &s.column(1),
    );
    plot.height = 320;
    plot
}

/// Axis `i` of the sensor quantity `q`: the estimate ± 3σ and, with `--sensor-truth`,
/// the truth; GNSS gaps shaded.
fn sensor_plot(c: &Ctx, q: &SensorQuantity, i: usize, axis: &str) -> Plot {
    let mut plot = estimate_plot(
        c,
        &format!("{} {axis}", q.name),
        &format!("{}_{axis} [{}]", q.stem, q.unit),
        |x| {
            [
                sensor_block(&x.estimates, q.block)[i] / q.scale,
                3.0 * x.sensor_std[q.block][i] / q.scale,
            ]
        },
    );
    let sensor_truth = &c.data.settings.sensor_truth;
    if !sensor_truth.is_empty() {
        let tt: Vec<f64> = sensor_truth.iter().map(|x| c.rel(x.0)).collect();
        let truth: Vec<f64> = sensor_truth
            .iter()
            .map(|x| sensor_block(&x.1, q.block)[i] / q.scale)
            .collect();
        plot = plot.line("truth", &tt, &truth, LineStyle::Dotted);
    }
    c.shade(plot)
}

/// The barometer bias [m] with its ±3σ envelope; GNSS gaps shaded.
fn baro_bias_plot(c: &Ctx) -> Plot {
    c.shade(estimate_plot(c, "Barometer bias", "baro bias [m]", |x| {
        [x.estimates.baro_bias, 3.0 * x.baro_std.unwrap_or(f64::NAN)]
    }))
}

/// The last estimate of each estimated sensor quantity and of the barometer bias,
/// with their 3σ (no row without a sample).
fn final_estimates(samples: &Spilled<ReportSample>, layout: Layout) -> Table {
    let mut table = Table::new(["quantity", "unit", "x", "y", "z", "3σ x", "3σ y", "3σ z"]);
    let Some(last) = samples.last() else {
        return table;
    };
    for q in estimated_sensors(layout) {
        let e = sensor_block(&last.estimates, q.block) / q.scale;
        let sd = last.sensor_std[q.block] * 3.0 / q.scale;
        table = table.row([
            q.name.to_owned(),
            q.unit.to_owned(),
            f3(e.x),
            f3(e.y),
            f3(e.z),
            f3(sd.x),
            f3(sd.y),
            f3(sd.z),
        ]);
    }
    if layout.baro_bias.is_some() {
        table = table.row([
            "Barometer bias".to_owned(),
            "m".to_owned(),
            f3(last.estimates.baro_bias),
            String::new(),
            String::new(),
            f3(3.0 * last.baro_std.unwrap_or(f64::NAN)),
            String::new(),
            String::new(),
        ]);
    }
    table
}

/// The columns of `sensor_errors.csv` after `t`, each with its header name: per
/// estimated quantity and axis the estimate and its σ in the quantity's unit, then the
/// barometer bias and its σ [m].
fn sensor_columns(layout: Layout) -> Vec<(String, Column)> {
    let mut columns: Vec<(String, Column)> = Vec::new();
    for q in estimated_sensors(layout) {
        let u = q.unit.replace('/', "p");
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let (block, scale) = (q.block, q.scale);
            columns.push((
                format!("{}_{axis}_{u}", q.stem),
                Box::new(move |x: &ReportSample| sensor_block(&x.estimates, block)[i] / scale),
            ));
            columns.push((
                format!("{}_{axis}_std_{u}", q.stem),
                Box::new(move |x: &ReportSample| x.sensor_std[block][i] / scale),
            ));
        }
    }
    if layout.baro_bias.is_some() {
        columns.push((
            "baro_bias_m".to_owned(),
            Box::new(|x: &ReportSample| x.estimates.baro_bias),
        ));
        columns.push((
            "baro_bias_std_m".to_owned(),
            Box::new(|x: &ReportSample| x.baro_std.unwrap_or(f64::NAN)),
        ));
    }
    columns
}

/// The filter's sensor-error estimates: one plot per quantity and axis (and the
/// barometer bias), the final values, and `sensor_errors.csv`.
fn sensor_section(r: &mut Report, c: &Ctx) -> Result<()> {
    let data = c.data;
    let layout = data.facts.layout;
    let s = r.section("sensors", "Estimated sensor errors");
    s.paragraph(
        "The filter's estimates with the ±3σ envelope of its covariance, sampled once a \
         second (the seed's figures 6-7). Biases in deg/h and mGal, scale factors in ppm, \
         as in imu_err.txt.",
    );
    if data.settings.sensor_truth.is_empty() {
        s.paragraph(
            "No sensor-error truth given: --sensor-truth FILE (imu_err.txt's layout) overlays \
             it; `schuler simulate` does not write one yet.",
        );
    }
    for q in estimated_sensors(layout) {
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let plot = sensor_plot(c, q, i, axis);
            let svg = c.svg(&format!("{}_{axis}", q.stem), &plot)?;
            s.plot_with_files(&plot, &[&svg, "report/sensor_errors.csv"]);
        }
    }
    if layout.baro_bias.is_some() {
        let plot = baro_bias_plot(c);
        let svg = c.svg("baro_bias", &plot)?;
        s.plot_with_files(&plot, &[&svg, "report/sensor_errors.csv"]);
    }
    s.table(final_estimates(data.samples, layout).caption("Final estimates and their 3σ"));
    let columns = sensor_columns(layout);
    let header = columns
        .iter()
        .fold(String::from("t"), |h, (name, _)| h + "," + name);
    c.csv(
        "sensor_errors.csv",
        &header,
        data.samples.iter().map(|x| {
            std::iter::once(Some(x.t))
                .chain(
                    columns
                        .iter()
                        .map(|(_, f)| Some(f(&x)).filter(|v| v.is_finite())),
                )
                .collect()
        }),
    )?;
    Ok(())
}

/// Component names of a measurement of `dof` components in the filter's frame.
fn components(kind: MechanizationKind, dof: usize) -> Vec<&'static str> {
    match (dof, kind) {
        (3, MechanizationKind::Ned) => vec!["north", "east", "down"],
        (3, MechanizationKind::Wander) => vec!["x (wander)", "y (wander)", "down"],
        (1, _) => vec![""],
        _ => ["1", "2", "3"][..dof.min(3)].to_vec(),
    }
}

fn innovation_section(r: &mut Report, c: &Ctx) -> Result<()> {
    let data = c.data;
    let rows = data.innovations;
    let s = r.section("innovations", "Innovations");
    s.paragraph(
        "Innovation z = computed − measured of every measurement in the filter's frame, \
         with ±3σ of its predicted covariance S = H P Hᵀ + R; refused measurements as dots.",
    );
    for k in nis_by_kind(|| rows.iter()) {
        for (i, name) in components(data.facts.mechanization, k.dof)
            .into_iter()
            .enumerate()
        {
            // Per measurement: z if accepted, z if refused, 3σ, and z (the thinning's key).
            let points = || {
                rows.iter().filter(|r| r.kind == k.kind).map(|r| {
                    let z = r.z[i];
                    let (yes, no) = if r.accepted {
                        (z, f64::NAN)
                    } else {
                        (f64::NAN, z)
                    };
                    (c.rel(r.t), [yes, no, 3.0 * r.sigma[i], z])
                })
            };
            let series: Series<4> = series(points, 3);
            let t = &series.t;
            let title = if name.is_empty() {
                format!("{} innovation", k.kind)
            } else {
                format!("{} innovation, {name}", k.kind)
            };
            let mut plot = with_envelope(
                Plot::new(&title, T_LABEL, &format!("z [{}]", k.kind.unit())),
                ("accepted", "±3σ(S)"),
                t,
                &series.column(0),
                &vec![0.0; t.len()],
                &series.column(2),
            );
            if k.refused > 0 {
                let (t, refused) = series.ungapped(1);
                plot = plot.line("refused", &t, &refused, LineStyle::Dotted);
            }
            plot.height = 320;
            let plot = c.shade(plot);
            let stem = format!("innovation_{}_{}", k.kind, i + 1);
            let svg = c.svg(&stem, &plot)?;
            s.plot_with_files(&plot, &[&svg, "innovations.csv"]);
        }
    }
    Ok(())
}

fn test_row(name: String, t: &ChiSquareTest) -> [String; 7] {
    [
        name,
        t.dof.to_string(),
        t.count.to_string(),
        format!("{:.3}", t.mean),
        format!("{:.3}–{:.3}", t.mean_bounds.lo, t.mean_bounds.hi),
        if t.mean_inside() { "yes" } else { "no" }.to_owned(),
        format!("{:.1}", 100.0 * t.fraction_outside()),
    ]
}

const TEST_HEADER: [&str; 7] = [
    "statistic",
    "dof",
    "values",
    "mean",
    "95 % interval of the mean",
    "mean inside",
    "% outside the per-epoch 95 % interval",
];

/// A statistic's values (`t` and `v` with the gaps' NaN points) against its bounds.
fn bounds_plot(title: &str, y_label: &str, t: &[f64], v: &[f64], test: &ChiSquareTest) -> Plot {
    let (a, b) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(1.0),
    );
    let mut plot = Plot::new(title, T_LABEL, y_label)
        .line("value", t, v, LineStyle::Solid)
        .line(
            &format!("{:.0} % bounds", 100.0 * PROBABILITY),
            &[a, b, f64::NAN, a, b],
            &[
                test.epoch_bounds.hi,
                test.epoch_bounds.hi,
                f64::NAN,
                test.epoch_bounds.lo,
                test.epoch_bounds.lo,
            ],
            LineStyle::Dashed,
        )
        .line(
            &format!("expected ({} dof)", test.dof),
            &[a, b],
            &[test.dof as f64, test.dof as f64],
            LineStyle::Dotted,
        );
    plot.height = 320;
    plot
}

fn nis_section(r: &mut Report, c: &Ctx, nis: &[KindConsistency]) -> Result<()> {
    let rows = c.data.innovations;
    let s = r.section("nis", "Consistency: normalized innovations (NIS)");
    s.paragraph(&format!(
        "NIS = zᵀ S⁻¹ z of each accepted measurement; for a consistent filter chi-square with \
         the measurement's dimension. The per-update interval holds {:.0} % of the values; \
         the mean of N independent values lies in chi2(N dof)/N's interval (innovations of \
         an optimal filter are white).",
        100.0 * PROBABILITY
    ));
    let mut table = Table::new(TEST_HEADER);
    for k in nis {
        let Some(test) = &k.test else { continue };
        table = table.row(test_row(format!("NIS {}", k.kind), test));
        let points = || {
            rows.iter()
                .filter(|r| r.kind == k.kind && r.accepted)
                .map(|r| (c.rel(r.t), [r.nis]))
        };
        let v: Series<1> = series(points, 0);
        let plot = c.shade(bounds_plot(
            &format!("NIS, {}", k.kind),
            "NIS [-]",
            &v.t,
            &v.column(0),
            test,
        ));
        let svg = c.svg(&format!("nis_{}", k.kind), &plot)?;
        s.plot_with_files(&plot, &[&svg, "innovations.csv"]);
    }
    s.table(table.caption("NIS against chi-square"));
    Ok(())
}

fn nees_section(r: &mut Report, c: &Ctx, nees: &[Option<ChiSquareTest>; 3]) -> Result<()> {
    let data = c.data;
    let samples = data.samples;
    let s = r.section("nees", "Consistency: normalized estimation errors (NEES)");
    s.paragraph(
        "NEES = eᵀ P⁻¹ e of the position, velocity and attitude errors against the truth, \
         with the filter's 3x3 covariance blocks in NED, once a second; chi-square with 3 \
         dof for a consistent filter. Successive values are correlated, so the interval of \
         the mean (which assumes independence) is narrower than one run's spread.",
    );
    let nees_of = |s: &ReportSample, k: usize| s.nees.and_then(|n| n[k]);
    c.csv(
        "nees.csv",
        "t,nees_position,nees_velocity,nees_attitude",
        samples
            .iter()
            .filter(|x| x.nees.is_some())
            .map(|x| vec![Some(x.t), nees_of(&x, 0), nees_of(&x, 1), nees_of(&x, 2)]),
    )?;
    let mut table = Table::new(TEST_HEADER);
    for (k, (name, test)) in NEES_BLOCKS.iter().zip(nees).enumerate() {
        let Some(test) = test else { continue };
        table = table.row(test_row(format!("NEES {name}"), test));
        let points = || {
            samples
                .iter()
                .filter(|x| x.nees.is_some())
                .map(|x| (c.rel(x.t), [nees_of(&x, k).unwrap_or(f64::NAN)]))
        };
        let v: Series<1> = series(points, 0);
        let plot = c.shade(bounds_plot(
            &format!("NEES, {name}"),
            "NEES [-]",
            &v.t,
            &v.column(0),
            test,
        ));
        let svg = c.svg(&format!("nees_{name}"), &plot)?;
        s.plot_with_files(&plot, &[&svg, "report/nees.csv"]);
    }
    s.table(table.caption("NEES against chi-square"));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use schuler::earth::Geodetic;

    fn row(t: f64, kind: Kind, dof: usize, nis: f64, accepted: bool) -> InnovationRow {
        InnovationRow {
            t,
            kind,
            accepted,
            dof,
            nis,
            z: [0.0; 3],
            sigma: [1.0; 3],
        }
    }

    #[test]
    fn nis_is_tested_per_kind_over_accepted_measurements() {
        let rows = [
            row(1.0, Kind::GnssPosition, 3, 2.0, true),
            row(1.0, Kind::GnssVelocity, 3, 4.0, true),
            row(1.1, Kind::BaroHeight, 1, 6.0, true),
            row(2.0, Kind::GnssPosition, 3, 2500.0, false),
            row(3.0, Kind::GnssPosition, 3, 10.0, true),
        ];
        let k = nis_by_kind(|| rows.iter().copied());
        assert_eq!(
            k.iter()
                .map(|k| (k.kind, k.dof, k.accepted, k.refused))
                .collect::<Vec<_>>(),
            [
                (Kind::GnssPosition, 3, 2, 1),
                (Kind::GnssVelocity, 3, 1, 0),
                (Kind::BaroHeight, 1, 1, 0)
            ]
        );
        let pos = k[0].test.expect("accepted");
        // The refused 2500 is left out: mean of 2 and 10. chi2(3) 97.5 % is 9.348
        // (mpmath), so 10 is above the per-update interval.
        assert_eq!(pos.mean, 6.0);
        assert_eq!(pos.fraction_above, 0.5);
        assert!((pos.epoch_bounds.hi - 9.348_403_60).abs() < 1e-6);
        // Baro: chi2(1) 97.5 % is 5.0239, 6 is above.
        assert_eq!(k[2].test.expect("baro").fraction_above, 1.0);
        let j = consistency_json(&k, None);
        assert_eq!(j["nis"][0]["kind"], "gnss_position");
        assert_eq!(j["nis"][0]["refused"], 1);
        assert_eq!(j["nis"][0]["test"]["mean"], 6.0);
        assert!(j["nees"].is_null());
        let text = consistency_text(&k, None);
        assert!(
            text.contains("NIS  gnss_position  3 dof: mean 6.000"),
            "{text}"
        );
    }

    #[test]
    fn gaps_are_intervals_longer_than_twice_the_spacing() {
        let fix = |t: f64| GnssFix {
            t,
            pos: Geodetic::from_degrees(45.0, 7.0, 0.0),
            pos_std: nalgebra::Vector3::repeat(1.0),
            vel: None,
        };
        let fixes: Vec<GnssFix> = [0.0, 1.0, 2.0, 3.0, 63.0, 64.0, 66.5, 67.0]
            .into_iter()
            .map(fix)
            .collect();
        assert_eq!(gnss_gaps(&fixes), [(3.0, 63.0), (64.0, 66.5)]);
        assert!(gnss_gaps(&fixes[..2]).is_empty());
    }
}
