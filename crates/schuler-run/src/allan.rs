//! The noise of a static IMU log (`schuler allan IMU_FILE`) from its overlapping Allan
//! deviations ([`schuler::analysis::allan`]).
//!
//! Prints, per triad, the IEEE Std 952 terms (angle/velocity random walk `N`, bias
//! instability `B`, rate random walk `K`, quantization `Q`) and the filter's model
//! (white noise, a Gauss–Markov bias `σ` of correlation time `T`, a bias random walk),
//! each with its 95 % interval, in engineering units, and writes into `--out`:
//!
//! - `allan.csv`: `τ`, each channel's deviation (rad/s or m/s²), its 95 % interval
//!   (chi-square with the equivalent degrees of freedom of the fitted model) and the
//!   IEEE fit's value;
//! - `allan.svg`: one log-log panel per channel, the deviation with its interval, the
//!   filter model's fit, the IEEE fit and its terms' asymptotes (`N/sqrt(τ)`, the
//!   floor `0.664 B`, `K sqrt(τ/3)`);
//! - `imu_noise.toml`: the filter's model as the `[aiding]` keys of `schuler nav
//!   --config` (see `noise_toml`).
//!
//! The log must be static: the mean specific force must be gravity's magnitude, the
//! mean rate near the Earth's, and the 10-s means of rate and specific force near
//! their median; otherwise the curve measures the motion and a warning names the
//! file.

use crate::imu_input::ImuInputOptions;
use crate::options::quantity;
use anyhow::{Context, Result};
use nalgebra::Vector3;
use schuler::align::prefilter::BlockSums;
use schuler::analysis::allan::confidence::{NoiseType, deviation_interval, edf};
use schuler::analysis::allan::fit::{
    FitOptions, FittedTerm, NoiseFit, Term, fit_gauss_markov, fit_ieee952,
};
use schuler::analysis::allan::{AllanCurve, CHANNEL_NAMES, CurveOptions, ImuAllan};
use schuler::earth::Wgs84;
use schuler::imu::ImuSample;
use schuler::units::{DEG, Dimension, G0, Unit};
use schuler_io::formats::ImuReader;
use schuler_report::plot::{LineStyle, Plot};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Arguments of `schuler allan`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// IMU log recorded at rest (KF-GINS text or CSV), an hour or more for the bias
    /// terms.
    #[arg(value_name = "IMU_FILE")]
    pub imu: PathBuf,
    /// How to read the log: format, columns, units, clock and axes, as `nav` reads it.
    #[command(flatten)]
    pub input: ImuInputOptions,
    /// Output directory for allan.csv, allan.svg and imu_noise.toml (default: the
    /// current directory).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Start time [s, the log's clock] (default: the first sample).
    #[arg(long, value_name = "SOW")]
    pub start: Option<f64>,
    /// End time [s, the log's clock] (default: the last sample).
    #[arg(long, value_name = "SOW")]
    pub end: Option<f64>,
    /// Longest cluster time (e.g. `20 min`; default a tenth of the log, which must
    /// last ten times it).
    #[arg(long, value_name = "TIME")]
    pub max_tau: Option<String>,
}

/// Probability of every interval printed and written.
const PROBABILITY: f64 = 0.95;
/// Allowed departure of the mean specific force's magnitude from g0: gravity varies
/// by 0.5 % over the Earth and accelerometer biases reach 1 %; 5 % is a tilt-free
/// log in other units, free fall, or motion.
const GRAVITY_TOLERANCE: f64 = 0.05;
/// Block [s] of the motion check: long enough to average the noise of any grade.
const BLOCK_S: f64 = 10.0;
/// Largest departure of a block's mean rate from the log's [deg/s]: 0.1 deg/s is 20
/// times the 10-s noise of a 1 deg/sqrt(h) MEMS gyro and 100 times a 3 deg/h bias
/// instability, well below any handling.
const BLOCK_RATE_DEG_S: f64 = 0.1;
/// Largest departure of a block's mean specific force [m/s^2]: 5 mg, a 0.3° tilt,
/// against about 1 mg of 10-s noise and bias wander of a consumer MEMS accelerometer.
const BLOCK_FORCE: f64 = 0.05;
/// Largest mean rate above the Earth's [deg/s]: a raw gyro bias of the cheapest MEMS.
const MEAN_RATE_DEG_S: f64 = 0.1;

/// Engineering units of one triad's terms.
struct Units {
    /// Sensor name.
    name: &'static str,
    /// White-noise density `N`.
    n: &'static str,
    /// Bias: `B` and the Gauss–Markov `σ`, and the plotted deviation.
    b: &'static str,
    /// Bias random walk `K`.
    k: &'static str,
    /// Quantization `Q`.
    q: &'static str,
    /// SI unit of the deviation in the CSV's column names.
    csv: &'static str,
}

const GYRO: Units = Units {
    name: "gyro",
    n: "deg/sqrt(h)",
    b: "deg/h",
    k: "deg/h/sqrt(h)",
    q: "arcsec",
    csv: "rad_s",
};

const ACCEL: Units = Units {
    name: "accelerometer",
    n: "m/s/sqrt(h)",
    b: "ug",
    k: "m/s^2/sqrt(h)",
    q: "m/s",
    csv: "m_s2",
};

/// The units of channel `c` (gyros 0–2, accelerometers 3–5).
fn units(c: usize) -> &'static Units {
    if c < 3 { &GYRO } else { &ACCEL }
}

impl Units {
    /// The unit a term's coefficient is shown in.
    fn of(&self, term: Term) -> &'static str {
        match term {
            Term::Quantization => self.q,
            Term::WhiteRate => self.n,
            Term::RateRandomWalk => self.k,
            Term::BiasInstability | Term::GaussMarkov { .. } | Term::RateRamp => self.b,
        }
    }
}

/// An SI value in the named unit (NaN for an unknown name, which the constants above
/// never are).
fn to_unit(v: f64, unit: &str) -> f64 {
    Unit::parse(unit).map_or(f64::NAN, |u| u.from_si(v))
}

/// Four significant digits: plain between 1e-3 and 1e6, exponent form outside; an
/// interval's open end (infinite) as `unbounded`, a missing value as `n/a`.
fn sig(x: f64) -> String {
    let a = x.abs();
    if x.is_nan() {
        "n/a".to_owned()
    } else if x.is_infinite() {
        format!("{}unbounded", if x < 0.0 { "-" } else { "" })
    } else if x == 0.0 {
        format!("{x}")
    } else if (1e-3..1e6).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}

/// Both fits of one channel.
pub struct ChannelFit {
    /// IEEE Std 952 terms.
    pub ieee: Option<NoiseFit>,
    /// White noise, Gauss–Markov bias and random walk.
    pub filter: Option<NoiseFit>,
}

/// The two fits of each channel, one thread per channel.
pub fn fit_channels(allan: &ImuAllan) -> Vec<ChannelFit> {
    let opts = FitOptions {
        probability: PROBABILITY,
        ..FitOptions::default()
    };
    std::thread::scope(|scope| {
        let handles: Vec<_> = allan
            .channels
            .iter()
            .map(|curve| {
                scope.spawn(move || ChannelFit {
                    ieee: fit_ieee952(curve, &opts).ok(),
                    filter: fit_gauss_markov(curve, &opts).ok(),
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join().unwrap_or(ChannelFit {
                    ieee: None,
                    filter: None,
                })
            })
            .collect()
    })
}

/// Reads the samples of the log in the time window.
fn read(args: &Args) -> Result<(Vec<ImuSample>, Option<String>)> {
    let options = args.input.read_options(args.start, args.end)?;
    let mut reader = ImuReader::open(&args.imu, &options)?;
    let samples = (&mut reader).collect::<Result<Vec<_>, _>>()?;
    let gaps = reader.gaps();
    let gap_warning = (!gaps.is_empty()).then(|| {
        format!(
            "{}: {gaps}: the samples spanning a gap are left out and the uniformly sampled \
             stretches between gaps pooled (no cluster spans a gap)",
            args.imu.display()
        )
    });
    Ok((samples, gap_warning))
}

/// What the log's means show of motion (module doc), as warnings naming `path`: the
/// specific force against gravity, the rate against the Earth's, the 10-s blocks
/// against their median ([`motion_warning`]).
pub fn static_warnings(path: &Path, samples: &[ImuSample], allan: &ImuAllan) -> Vec<String> {
    let file = path.display();
    let mut warnings = Vec::new();
    let f = allan.mean[3..].iter().map(|x| x * x).sum::<f64>().sqrt();
    if (f / G0 - 1.0).abs() > GRAVITY_TOLERANCE {
        warnings.push(format!(
            "{file}: the mean specific force {f:.3} m/s^2 is not gravity's ({G0} m/s^2 within \
             {} %): not a static log?",
            GRAVITY_TOLERANCE * 100.0
        ));
    }
    let w = allan.mean[..3].iter().map(|x| x * x).sum::<f64>().sqrt();
    if w > Wgs84::OMEGA + MEAN_RATE_DEG_S * DEG {
        warnings.push(format!(
            "{file}: the mean rate {:.2} deg/h is far above the Earth's {:.2} deg/h: a \
             turning platform (or a gyro bias over {MEAN_RATE_DEG_S} deg/s)?",
            to_unit(w, "deg/h"),
            to_unit(Wgs84::OMEGA, "deg/h")
        ));
    }
    warnings.extend(motion_warning(path, samples, allan.dt));
    warnings
}

/// The mean rate and specific force of one block of samples, from its start time.
struct BlockMean {
    t: f64,
    rate: Vector3<f64>,
    force: Vector3<f64>,
}

/// Component-wise median of `f` over `blocks`.
fn median(blocks: &[BlockMean], f: fn(&BlockMean) -> Vector3<f64>) -> Vector3<f64> {
    Vector3::from_fn(|i, _| {
        let mut v: Vec<f64> = blocks.iter().map(|b| f(b)[i]).collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    })
}

/// Blocks of [`BLOCK_S`] whose mean rate or specific force departs from the blocks'
/// median (which motion in a minority of them leaves) by more than [`BLOCK_RATE_DEG_S`]
/// or [`BLOCK_FORCE`], as a warning naming `path`.
fn motion_warning(path: &Path, samples: &[ImuSample], dt: f64) -> Option<String> {
    let block = ((BLOCK_S / dt).round() as usize).max(1);
    let blocks: Vec<BlockMean> = samples
        .chunks_exact(block)
        .map(|chunk| {
            let mut b = BlockSums::default();
            chunk.iter().for_each(|s| b.add(s));
            BlockMean {
                t: chunk[0].t,
                rate: b.rate(),
                force: b.force(),
            }
        })
        .collect();
    let (ref_w, ref_f) = (median(&blocks, |b| b.rate), median(&blocks, |b| b.force));
    let moving: Vec<(f64, f64, f64)> = blocks
        .iter()
        .map(|b| (b.t, (b.rate - ref_w).norm(), (b.force - ref_f).norm()))
        .filter(|&(_, dw, df)| dw > BLOCK_RATE_DEG_S * DEG || df > BLOCK_FORCE)
        .collect();
    let &(t, dw, df) = moving.first()?;
    Some(format!(
        "{}: motion in {} of the {BLOCK_S}-s blocks, the first from t = {t}: its mean rate \
         departs from the blocks' median by {:.3} deg/s and its specific force by {df:.3} \
         m/s^2 (limits {BLOCK_RATE_DEG_S} deg/s, {BLOCK_FORCE} m/s^2); the Allan curve then \
         measures the motion, not the sensor",
        path.display(),
        moving.len(),
        dw / DEG
    ))
}

/// `v [lo, hi]` of a fitted term in `unit`.
fn cell(t: &FittedTerm, unit: &str) -> String {
    format!(
        "{} [{}, {}]",
        sig(to_unit(t.value, unit)),
        sig(to_unit(t.interval.0, unit)),
        sig(to_unit(t.interval.1, unit))
    )
}

/// Rows of cells as text, each column padded to its widest cell.
fn table(rows: &[Vec<String>]) -> String {
    let cols = rows.iter().map(Vec::len).max().unwrap_or(0);
    let width: Vec<usize> = (0..cols)
        .map(|k| {
            rows.iter()
                .filter_map(|r| r.get(k))
                .map(|c| c.chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut s = String::new();
    for r in rows {
        let line: Vec<String> = r
            .iter()
            .enumerate()
            .map(|(k, c)| format!("{c:<w$}", w = width[k]))
            .collect();
        let _ = writeln!(s, "  {}", line.join("  ").trim_end());
    }
    s
}

/// One triad's table of one fit: `terms` with the fit's χ²/dof.
fn fit_table(
    fits: &[ChannelFit],
    triad: usize,
    terms: &[Term],
    pick: fn(&ChannelFit) -> Option<&NoiseFit>,
) -> String {
    let u = units(3 * triad);
    let mut header = vec![u.name.to_owned()];
    for &t in terms {
        header.push(format!("{} [{}]", t.name(), u.of(t)));
    }
    header.push("chi2/dof".to_owned());
    let with_t = terms.iter().any(|t| matches!(t, Term::GaussMarkov { .. }));
    if with_t {
        header.insert(3, "T [s]".to_owned());
    }
    let mut rows = vec![header];
    for c in 3 * triad..3 * triad + 3 {
        let axis = CHANNEL_NAMES[c].rsplit(' ').next().unwrap_or("");
        let mut row = vec![axis.to_owned()];
        match pick(&fits[c]) {
            Some(fit) => {
                for &t in terms {
                    row.push(fit.get(t).map_or("-".to_owned(), |f| cell(f, u.of(t))));
                }
                if with_t {
                    let ct = fit.correlation_time.map_or("-".to_owned(), |ct| {
                        format!(
                            "{} [{}, {}]",
                            sig(ct.value),
                            sig(ct.interval.0),
                            sig(ct.interval.1)
                        )
                    });
                    row.insert(3, ct);
                }
                row.push(format!("{:.2}", fit.chi2_per_dof));
            }
            None => row.push("(no fit: the Allan variances are zero or too few)".to_owned()),
        }
        rows.push(row);
    }
    table(&rows)
}

/// The printed summary: the log, then both fits' tables per triad.
pub fn summary(path: &Path, allan: &ImuAllan, fits: &[ChannelFit]) -> String {
    let pts = &allan.channels[0].points;
    let (t0, t1) = (
        pts.first().map_or(0.0, |p| p.tau),
        pts.last().map_or(0.0, |p| p.tau),
    );
    let mut s = format!(
        "{}: {} samples at {} Hz over {} s; cluster times {} s to {} s\n",
        path.display(),
        allan.samples,
        sig(1.0 / allan.dt),
        sig(allan.dt * allan.samples as f64),
        sig(t0),
        sig(t1)
    );
    let _ = writeln!(
        s,
        "IEEE Std 952 terms, {} % intervals (chi2/dof near 1: the model describes the curve):",
        PROBABILITY * 100.0
    );
    let ieee = [
        Term::WhiteRate,
        Term::BiasInstability,
        Term::RateRandomWalk,
        Term::Quantization,
    ];
    let filter = [
        Term::WhiteRate,
        Term::GaussMarkov { tau: 1.0 },
        Term::RateRandomWalk,
    ];
    for triad in 0..2 {
        s += &fit_table(fits, triad, &ieee, |f| f.ieee.as_ref());
    }
    let _ = writeln!(
        s,
        "Filter model (white noise, Gauss-Markov bias of correlation time T, bias random walk), \
         {} % intervals:",
        PROBABILITY * 100.0
    );
    for triad in 0..2 {
        s += &fit_table(fits, triad, &filter, |f| f.filter.as_ref());
    }
    s
}

/// The 95 % interval of each point of `curve` under `fit`'s mix of terms (white noise's
/// degrees of freedom without a fit).
pub fn point_intervals(curve: &AllanCurve, fit: Option<&NoiseFit>) -> Vec<(f64, f64)> {
    curve
        .points
        .iter()
        .map(|p| {
            let nu = fit.map_or_else(
                || edf(NoiseType::WhiteRate, curve.samples + 1, p.m),
                |f| f.edf(p, curve.samples),
            );
            deviation_interval(p.adev(), nu, PROBABILITY)
        })
        .collect()
}

/// `allan.csv` (module doc).
fn csv(allan: &ImuAllan, fits: &[ChannelFit]) -> String {
    let mut s = "tau_s,m".to_owned();
    for (c, name) in CHANNEL_NAMES.iter().enumerate() {
        let n = name.replace(' ', "_");
        let u = units(c).csv;
        let _ = write!(s, ",{n}_{u},{n}_lo_{u},{n}_hi_{u},{n}_fit_{u}");
    }
    s.push('\n');
    let intervals: Vec<Vec<(f64, f64)>> = (0..6)
        .map(|c| point_intervals(&allan.channels[c], fits[c].ieee.as_ref()))
        .collect();
    for (i, p) in allan.channels[0].points.iter().enumerate() {
        let _ = write!(s, "{},{}", p.tau, p.m);
        for c in 0..6 {
            let q = &allan.channels[c].points[i];
            let fit = fits[c]
                .ieee
                .as_ref()
                .map_or(f64::NAN, |f| f.avar(q.tau).sqrt());
            let (lo, hi) = intervals[c][i];
            let _ = write!(s, ",{},{lo},{hi},{fit}", q.adev());
        }
        s.push('\n');
    }
    s
}

/// `log10` of an SI deviation in `unit`, NaN outside `[lo, hi]` (log10 units).
fn log_in(v: f64, unit: &str, (lo, hi): (f64, f64)) -> f64 {
    let y = to_unit(v, unit).log10();
    if y >= lo && y <= hi { y } else { f64::NAN }
}

/// One channel's panel (module doc), with the filter model's fit `filter` too.
fn panel(c: usize, curve: &AllanCurve, fits: &ChannelFit) -> Plot {
    let (fit, filter) = (fits.ieee.as_ref(), fits.filter.as_ref());
    let u = units(c);
    let x: Vec<f64> = curve.points.iter().map(|p| p.tau.log10()).collect();
    let ys: Vec<f64> = curve
        .points
        .iter()
        .map(|p| to_unit(p.adev(), u.b).log10())
        .collect();
    let finite = ys.iter().copied().filter(|y| y.is_finite());
    let range = (
        finite.clone().fold(f64::INFINITY, f64::min) - 0.5,
        finite.fold(f64::NEG_INFINITY, f64::max) + 0.5,
    );
    let intervals = point_intervals(curve, fit);
    // The interval: lower bounds, a break, upper bounds back.
    let (mut bx, mut by) = (x.clone(), Vec::new());
    by.extend(intervals.iter().map(|i| log_in(i.0, u.b, range)));
    bx.push(f64::NAN);
    by.push(f64::NAN);
    bx.extend(x.iter().rev());
    by.extend(intervals.iter().rev().map(|i| log_in(i.1, u.b, range)));
    let mut plot = Plot::new(
        &format!("{}: Allan deviation", CHANNEL_NAMES[c]),
        "log10 tau [s]",
        &format!("log10 sigma [{}]", u.b),
    )
    .line("measured", &x, &ys, LineStyle::Solid)
    .line("95 % interval", &bx, &by, LineStyle::Dotted);
    let curve_of = |f: &dyn Fn(f64) -> f64| -> Vec<f64> {
        curve
            .points
            .iter()
            .map(|p| log_in(f(p.tau).sqrt(), u.b, range))
            .collect()
    };
    if let Some(f) = filter {
        let y = curve_of(&|t| f.avar(t));
        plot = plot.line("Gauss-Markov fit", &x, &y, LineStyle::Dashed);
    }
    if let Some(fit) = fit {
        plot = plot.line(
            "IEEE 952 fit",
            &x,
            &curve_of(&|t| fit.avar(t)),
            LineStyle::Dashed,
        );
        for (term, label) in [
            (Term::WhiteRate, "N/sqrt(tau)"),
            (Term::BiasInstability, "floor 0.664 B"),
            (Term::RateRandomWalk, "K sqrt(tau/3)"),
        ] {
            if let Some(t) = fit.get(term).filter(|t| t.value > 0.0) {
                let v2 = t.value * t.value;
                let y = curve_of(&|tau| v2 * term.unit_avar(tau));
                plot = plot.line(label, &x, &y, LineStyle::Dotted);
            }
        }
    }
    plot.width = 600;
    plot.height = 420;
    plot
}

/// Panels side by side, `cols` to a row, as one SVG document.
fn grid_svg(panels: &[Plot], cols: usize) -> String {
    let (w, h) = panels
        .first()
        .map_or((0, 0), |p| (p.width as usize, p.height as usize));
    let rows = panels.len().div_ceil(cols.max(1));
    let (tw, th) = (w * cols, h * rows);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{tw}\" height=\"{th}\" \
         viewBox=\"0 0 {tw} {th}\">\n"
    );
    for (i, p) in panels.iter().enumerate() {
        let (x, y) = ((i % cols) * w, (i / cols) * h);
        let _ = writeln!(s, "<g transform=\"translate({x},{y})\">");
        s += &p.to_svg();
        s += "</g>\n";
    }
    s += "</svg>\n";
    s
}

/// The value a term is written at: the estimate if resolved (its interval excludes
/// zero), else the interval's upper bound (a conservative value the log allows).
fn written(t: &FittedTerm) -> (f64, bool) {
    if t.resolved() {
        (t.value, true)
    } else {
        (t.interval.1, false)
    }
}

/// The largest written value of `term` over the three axes of `triad`, and whether
/// every axis resolved it.
fn triad_value(fits: &[ChannelFit], triad: usize, term: Term) -> Option<(f64, bool)> {
    let vals: Vec<(f64, bool)> = fits[3 * triad..3 * triad + 3]
        .iter()
        .filter_map(|f| f.filter.as_ref()?.get(term).map(written))
        .collect();
    let max = vals
        .iter()
        .map(|v| v.0)
        .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))?;
    Some((max, vals.iter().all(|v| v.1)))
}

/// One correlation time for every bias (`schuler nav` has one): the mean of `ln T`
/// over the channels whose Gauss–Markov bias is resolved, weighted by the inverse
/// square of each interval's half width.
fn common_correlation_time(fits: &[ChannelFit]) -> Option<f64> {
    let (mut sum, mut weights) = (0.0, 0.0);
    for fit in fits.iter().filter_map(|f| f.filter.as_ref()) {
        let resolved = fit
            .get(Term::GaussMarkov { tau: 1.0 })
            .is_some_and(FittedTerm::resolved);
        if let (true, Some(ct)) = (resolved, fit.correlation_time) {
            let half = 0.5 * (ct.interval.1 / ct.interval.0).ln();
            let w = if half > 0.0 && half.is_finite() {
                1.0 / (half * half)
            } else {
                1e-12
            };
            sum += w * ct.value.ln();
            weights += w;
        }
    }
    (weights > 0.0).then(|| (sum / weights).exp())
}

/// `imu_noise.toml`: the filter model as `schuler nav`'s `[aiding]` keys.
///
/// `arw`, `vrw`: the white-noise densities; `gyro_bias_instability`,
/// `accel_bias_instability` with `bias_corr_time`: the Gauss–Markov biases (`nav` then
/// models the biases as first-order Gauss–Markov processes, as the simulator
/// draws them); `rate_random_walk`, `acceleration_random_walk`: the bias random walks
/// (added to the Gauss–Markov driving noise). Each is the largest of the three axes
/// (`nav` takes one value per triad; an optimistic noise model makes its gate refuse
/// good fixes, a pessimistic one costs little); a term the log does not resolve is
/// written at its upper bound and marked so. Without a resolved Gauss–Markov bias in
/// any channel the instability keys are left out (`--imu-grade`'s stay). The bias
/// priors (`gyro_bias_std`, `accel_bias_std`) are not the Allan curve's to tell: a
/// constant bias has none.
pub fn noise_toml(path: &Path, allan: &ImuAllan, fits: &[ChannelFit]) -> String {
    let mut s = format!(
        "# Noise of {} ({} samples at {} Hz) fitted by `schuler allan`: white noise, a \
         Gauss-Markov bias\n# and a bias random walk per axis; each key holds the largest \
         axis. Read by\n#   schuler nav --config imu_noise.toml --imu ... --gnss ...\n# \
         (flags win over these keys).\n",
        path.display(),
        allan.samples,
        sig(1.0 / allan.dt)
    );
    for (c, fit) in fits.iter().enumerate() {
        let u = units(c);
        let Some(f) = fit.filter.as_ref() else {
            let _ = writeln!(s, "# {}: no fit", CHANNEL_NAMES[c]);
            continue;
        };
        let _ = write!(s, "# {}:", CHANNEL_NAMES[c]);
        for t in &f.terms {
            let _ = write!(
                s,
                " {} {} {};",
                t.term.name(),
                cell(t, u.of(t.term)),
                u.of(t.term)
            );
        }
        if let Some(ct) = f.correlation_time {
            let _ = write!(
                s,
                " T {} [{}, {}] s;",
                sig(ct.value),
                sig(ct.interval.0),
                sig(ct.interval.1)
            );
        }
        s.pop();
        s.push('\n');
    }
    s += "[aiding]\n";
    let mut key = |name: &str, v: Option<(f64, bool)>, unit: &str| {
        if let Some((v, _)) = v.filter(|v| !v.0.is_finite()) {
            // An unbounded term: no value nav could use (the log is too short for it).
            let _ = writeln!(s, "# {name}: not bounded by this log ({})", sig(v));
        } else if let Some((v, resolved)) = v {
            let note = if resolved {
                ""
            } else {
                "  # upper 95 % bound: not resolved by this log"
            };
            let _ = writeln!(s, "{name} = \"{} {unit}\"{note}", sig(to_unit(v, unit)));
        }
    };
    key("arw", triad_value(fits, 0, Term::WhiteRate), GYRO.n);
    key("vrw", triad_value(fits, 1, Term::WhiteRate), ACCEL.n);
    let t = common_correlation_time(fits);
    if let Some(t) = t {
        let gm = Term::GaussMarkov { tau: t };
        key("gyro_bias_instability", triad_value(fits, 0, gm), GYRO.b);
        key("accel_bias_instability", triad_value(fits, 1, gm), ACCEL.b);
        key("bias_corr_time", Some((t, true)), "s");
    }
    key(
        "rate_random_walk",
        triad_value(fits, 0, Term::RateRandomWalk),
        GYRO.k,
    );
    key(
        "acceleration_random_walk",
        triad_value(fits, 1, Term::RateRandomWalk),
        ACCEL.k,
    );
    if t.is_none() {
        s += "# No channel resolves a Gauss-Markov bias: the bias instability keys are left \
              out (nav keeps --imu-grade's).\n";
    }
    s
}

/// Writes `text` to `dir/name`.
fn write(dir: &Path, name: &str, text: &str) -> Result<PathBuf> {
    let path = dir.join(name);
    schuler_io::line_file::write_whole(&path, text)?;
    Ok(path)
}

/// What `schuler allan` computed: the deviations, the fits of each channel and the
/// warnings about the log (gaps, motion).
pub struct AllanRun {
    /// The six channels' Allan deviations.
    pub allan: ImuAllan,
    /// Each channel's fits (IEEE 952 and the filter's model).
    pub fits: Vec<ChannelFit>,
    /// Warnings naming the file: gaps, a log that moves.
    pub warnings: Vec<String>,
}

/// The Allan deviations of `args`'s log and their fits.
pub fn analyse(args: &Args) -> Result<AllanRun> {
    let (samples, gap_warning) = read(args)?;
    let curve_options = CurveOptions {
        max_tau: quantity("max-tau", &args.max_tau, Dimension::Time)?,
        ..CurveOptions::default()
    };
    let allan = ImuAllan::from_samples(&samples, &curve_options)
        .with_context(|| format!("{}", args.imu.display()))?;
    let warnings = gap_warning
        .into_iter()
        .chain(static_warnings(&args.imu, &samples, &allan))
        .collect();
    drop(samples);
    let fits = fit_channels(&allan);
    Ok(AllanRun {
        allan,
        fits,
        warnings,
    })
}

/// Writes `allan.csv`, `allan.svg` and `imu_noise.toml` of `run` into `dir` (created
/// if needed); returns their paths.
pub fn write_outputs(dir: &Path, imu: &Path, run: &AllanRun) -> Result<[PathBuf; 3]> {
    let (allan, fits) = (&run.allan, &run.fits);
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let panels: Vec<Plot> = (0..6)
        .map(|c| panel(c, &allan.channels[c], &fits[c]))
        .collect();
    Ok([
        write(dir, "allan.csv", &csv(allan, fits))?,
        write(dir, "allan.svg", &grid_svg(&panels, 2))?,
        write(dir, "imu_noise.toml", &noise_toml(imu, allan, fits))?,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aided::AidingOptions;
    use crate::options::GradeChoice;
    use schuler::imu::model::ImuModel;
    use schuler::sim::imu_model::ImuSimulator;
    use schuler::units::{DEG_PER_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, UG};

    /// A static log of `len` samples at 100 Hz from `model` (zero rate, gravity on z).
    fn log(model: ImuModel, len: usize) -> Vec<ImuSample> {
        let mut sim = ImuSimulator::new(model, 3);
        (1..=len)
            .map(|k| {
                sim.measure(&ImuSample {
                    t: k as f64 * 0.01,
                    dt: 0.01,
                    dtheta: Vector3::zeros(),
                    dvel: Vector3::new(0.0, 0.0, -9.8 * 0.01),
                })
            })
            .collect()
    }

    #[test]
    fn four_significant_digits() {
        assert_eq!(sig(0.049_987), "0.04999");
        assert_eq!(sig(1234.56), "1235");
        assert_eq!(sig(3.464e-4), "3.464e-4");
        assert_eq!(sig(0.0), "0");
    }

    /// A tilted or moving log is named in a warning; a static one is not.
    #[test]
    fn motion_and_gravity_are_checked() {
        let mut samples = log(ImuModel::default(), 20_000);
        let path = Path::new("static.txt");
        let allan = ImuAllan::from_samples(&samples, &CurveOptions::default()).expect("curves");
        assert!(static_warnings(path, &samples, &allan).is_empty());
        // Turning at 5 deg/s for 2 s, then back (the mean rate stays near zero).
        for s in &mut samples[9000..9200] {
            s.dtheta.z = 5.0 * DEG * s.dt;
        }
        for s in &mut samples[12_000..12_200] {
            s.dtheta.z = -5.0 * DEG * s.dt;
        }
        let allan = ImuAllan::from_samples(&samples, &CurveOptions::default()).expect("curves");
        let w = static_warnings(Path::new("moving.txt"), &samples, &allan);
        assert!(
            w.len() == 1 && w[0].starts_with("moving.txt: motion in 2 of the 10-s blocks"),
            "{w:?}"
        );
        // A specific force 57 times gravity's (a unit mixed up).
        for s in &mut samples {
            s.dvel *= 1.0 / DEG;
        }
        let allan = ImuAllan::from_samples(&samples, &CurveOptions::default()).expect("curves");
        let w = static_warnings(path, &samples, &allan);
        assert!(w[0].contains("is not gravity's"), "{w:?}");
    }

    /// The written `[aiding]` block reaches the filter's noise as `schuler nav` reads
    /// it: the white-noise densities and Gauss–Markov biases of a 20-min simulated
    /// log (ARW 0.1 deg/sqrt(h), 3 deg/h over 20 s; VRW 0.05 m/s/sqrt(h), 50 ug over
    /// 20 s) within 5 % and 25 % (the written values are the largest of three axes,
    /// rounded to 4 digits; the biases' 95 % intervals over 20 minutes are about
    /// ±20 %), the driving noise `sqrt(2σ²/T + K²)`.
    #[test]
    fn the_noise_block_is_what_nav_reads() {
        let mut m = ImuModel::default();
        m.gyro.white = Vector3::repeat(0.1 * DEG_PER_SQRT_H);
        m.gyro.gm_sigma = Vector3::repeat(3.0 * DEG_PER_H);
        m.gyro.gm_tau = Vector3::repeat(20.0);
        m.accel.white = Vector3::repeat(0.05 * M_PER_S_PER_SQRT_H);
        m.accel.gm_sigma = Vector3::repeat(50.0 * UG);
        m.accel.gm_tau = Vector3::repeat(20.0);
        let samples = log(m.clone(), 120_000);
        let allan = ImuAllan::from_samples(&samples, &CurveOptions::default()).expect("curves");
        let fits = fit_channels(&allan);
        let text = noise_toml(Path::new("imu.txt"), &allan, &fits);
        let table: toml::Table = toml::from_str(&text).expect("TOML");
        let mut opts: AidingOptions = table["aiding"].clone().try_into().expect("[aiding]");
        opts.zupt_detect = true;
        let aiding = opts
            .resolve(GradeChoice::Tactical.noise().expect("grade"))
            .expect("resolves")
            .expect("aiding");
        let noise = aiding.filter.integration.noise;
        let near = |got: f64, want: f64, tol: f64| (got / want - 1.0).abs() < tol;
        assert!(near(noise.arw.x, m.gyro.white.x, 0.05), "{text}");
        assert!(near(noise.vrw.z, m.accel.white.z, 0.05), "{text}");
        let t = noise.gyro_bias_tau;
        assert!(near(t, 20.0, 0.25) && noise.accel_bias_tau == t, "{text}");
        let k = |key: &str, unit: &str| {
            let v = table["aiding"][key].as_str().expect("string");
            let q = v.strip_suffix(unit).expect("unit").trim();
            to_unit_si(q.parse().expect("number"), unit)
        };
        let (gs, gk) = (
            k("gyro_bias_instability", "deg/h"),
            k("rate_random_walk", "deg/h/sqrt(h)"),
        );
        assert!(near(gs, m.gyro.gm_sigma.x, 0.25), "{text}");
        let drive = (2.0 * gs * gs / t + gk * gk).sqrt();
        assert!(near(noise.gyro_bias_walk.y, drive, 1e-3), "{text}");
        let accel = k("accel_bias_instability", "ug");
        assert!(near(accel, m.accel.gm_sigma.x, 0.25), "{text}");
    }

    /// A value in `unit` to SI.
    fn to_unit_si(v: f64, unit: &str) -> f64 {
        Unit::parse(unit).expect("unit").to_si(v)
    }
}
