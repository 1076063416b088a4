//! `allan(imu)`: the overlapping Allan deviations of the six channels of a static log
//! ([`schuler::analysis::allan::ImuAllan`], as `schuler allan` computes them), in SI.

use crate::columns::Columns;
use crate::errors::IntoPy;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler::analysis::allan::{CurveOptions, ImuAllan};
use schuler::imu::ImuSample;
use schuler_io::formats::ImuReader;
use std::path::PathBuf;

/// Columns: cluster time, cluster size, the deviations of the gyros [rad/s] and the
/// accelerometers [m/s^2].
const ALLAN: &[&str] = &[
    "tau_s",
    "m",
    "gyro_x_radps",
    "gyro_y_radps",
    "gyro_z_radps",
    "accel_x_mps2",
    "accel_y_mps2",
    "accel_z_mps2",
];

/// The Allan deviations of the IMU file `path` (read as `schuler allan` reads it, with
/// the IMU input `options`) or of the columns `imu` (`t, dtheta_xyz, dvel_xyz`, `dt`
/// optional): `per_decade` cluster sizes a decade up to `max_tau` [s] (default a
/// tenth of the log). The GIL is released.
#[pyfunction]
#[pyo3(signature = (path=None, options=None, imu=None, imu_dt=None, per_decade=10.0, max_tau=None))]
pub fn allan<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    options: Option<Bound<'py, PyDict>>,
    imu: Option<Vec<PyReadonlyArray1<'py, f64>>>,
    imu_dt: Option<PyReadonlyArray1<'py, f64>>,
    per_decade: f64,
    max_tau: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let views = match &imu {
        Some(cols) => Some(crate::imu_views(cols, imu_dt.as_ref(), None).py_err(py)?),
        None => None,
    };
    let options = match &options {
        Some(o) => crate::options::table(o)?,
        None => toml::Table::new(),
    };
    let opts = crate::options::imu_options(options).py_err(py)?;
    let a = py
        .detach(|| -> anyhow::Result<ImuAllan> {
            let samples: Vec<ImuSample> = match (&views, &path) {
                (Some(v), _) => v.samples(None, None)?.collect::<Result<_, _>>()?,
                (None, Some(p)) => ImuReader::open(p, &opts)?.collect::<Result<_, _>>()?,
                (None, None) => anyhow::bail!("give an IMU file or IMU columns"),
            };
            let options = CurveOptions {
                per_decade,
                max_tau,
            };
            Ok(ImuAllan::from_samples(&samples, &options)?)
        })
        .py_err(py)?;
    let mut c = Columns::new(ALLAN);
    for (i, p) in a.channels[0].points.iter().enumerate() {
        let mut row = vec![p.m as f64];
        row.extend(a.channels.iter().map(|ch| ch.points[i].adev()));
        c.push(p.tau, &row);
    }
    c.take_dict(py)
}

/// `schuler allan`'s arguments.
#[derive(clap::Parser, Debug)]
#[command(name = "allan", no_binary_name = true)]
struct AllanFlags {
    #[command(flatten)]
    args: schuler_run::allan::Args,
}

/// `schuler allan` with `flags` (the IMU file first, or a placeholder name when the
/// columns `imu` are given, `dt` optional): a dict of `curves` (`allan.csv`'s columns:
/// per channel the deviation, its 95 % interval and the IEEE 952 fit, in SI), `fits`
/// (one row per channel, model and term: value and 95 % interval in SI, the fit's
/// chi2/dof), `report` (the printed tables), `noise_toml` (`imu_noise.toml`'s text)
/// and `warnings` (a moving or gappy log). The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (flags, imu=None, imu_dt=None))]
pub fn allan_fit<'py>(
    py: Python<'py>,
    flags: Vec<String>,
    imu: Option<Vec<PyReadonlyArray1<'py, f64>>>,
    imu_dt: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    use schuler_run::allan as analysis;
    crate::options::check_flag_names::<schuler_run::allan::Args>(&flags).py_err(py)?;
    let args = <AllanFlags as clap::Parser>::try_parse_from(&flags)
        .py_err(py)?
        .args;
    let views = match &imu {
        Some(cols) => Some(crate::imu_views(cols, imu_dt.as_ref(), None).py_err(py)?),
        None => None,
    };
    let (allan, fits, warnings) = py
        .detach(|| -> anyhow::Result<_> {
            let max_tau = schuler_run::options::quantity(
                "max-tau",
                &args.max_tau,
                schuler::units::Dimension::Time,
            )?;
            let mut warnings = Vec::new();
            let samples: Vec<ImuSample> = match &views {
                Some(v) => v.samples(args.start, args.end)?.collect::<Result<_, _>>()?,
                None => {
                    let opts = args.input.read_options(args.start, args.end)?;
                    let mut reader = ImuReader::open(&args.imu, &opts)?;
                    let samples = (&mut reader).collect::<Result<_, _>>()?;
                    let gaps = reader.gaps();
                    if !gaps.is_empty() {
                        warnings.push(format!(
                            "{}: {gaps}: the samples spanning a gap are left out and the \
                             uniformly sampled stretches between gaps pooled (no cluster \
                             spans a gap)",
                            args.imu.display()
                        ));
                    }
                    samples
                }
            };
            let options = CurveOptions {
                max_tau,
                ..CurveOptions::default()
            };
            let allan = ImuAllan::from_samples(&samples, &options)
                .map_err(|e| anyhow::anyhow!("{}: {e}", args.imu.display()))?;
            warnings.extend(analysis::static_warnings(&args.imu, &samples, &allan));
            let fits = analysis::fit_channels(&allan);
            Ok((allan, fits, warnings))
        })
        .py_err(py)?;
    let d = PyDict::new(py);
    d.set_item("curves", curves(py, &allan, &fits)?)?;
    d.set_item("fits", fit_rows(py, &fits)?)?;
    d.set_item("report", analysis::summary(&args.imu, &allan, &fits))?;
    d.set_item("noise_toml", analysis::noise_toml(&args.imu, &allan, &fits))?;
    d.set_item("warnings", warnings)?;
    Ok(d)
}

/// `allan.csv`'s columns with the package's unit names: `tau_s`, `m`, then per
/// channel its deviation, the interval's bounds `_lo`, `_hi` and the IEEE fit `_fit`.
fn curves<'py>(
    py: Python<'py>,
    allan: &ImuAllan,
    fits: &[schuler_run::allan::ChannelFit],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let p0 = &allan.channels[0].points;
    d.set_item("tau_s", p0.iter().map(|p| p.tau).collect::<Vec<_>>())?;
    d.set_item("m", p0.iter().map(|p| p.m as u64).collect::<Vec<_>>())?;
    for (c, name) in ALLAN[2..].iter().enumerate() {
        let (base, unit) = name.rsplit_once('_').unwrap_or((name, ""));
        let curve = &allan.channels[c];
        let ieee = fits[c].ieee.as_ref();
        let iv = schuler_run::allan::point_intervals(curve, ieee);
        let fit = |tau: f64| ieee.map_or(f64::NAN, |f| f.avar(tau).sqrt());
        let pts = &curve.points;
        d.set_item(*name, pts.iter().map(|p| p.adev()).collect::<Vec<_>>())?;
        d.set_item(
            format!("{base}_lo_{unit}"),
            iv.iter().map(|i| i.0).collect::<Vec<_>>(),
        )?;
        d.set_item(
            format!("{base}_hi_{unit}"),
            iv.iter().map(|i| i.1).collect::<Vec<_>>(),
        )?;
        d.set_item(
            format!("{base}_fit_{unit}"),
            pts.iter().map(|p| fit(p.tau)).collect::<Vec<_>>(),
        )?;
    }
    Ok(d)
}

/// The fitted terms, one row each: `channel` (`gyro x`, ...), `model` (`ieee952` or
/// `gauss_markov`), `term` (`N`, `B`, `K`, `Q`, `sigma`, `T`), `value`, `lo`, `hi`
/// (SI: rad/sqrt(s), rad/s, rad/s/sqrt(s), rad for gyros; m/s/sqrt(s), m/s^2,
/// m/s^2/sqrt(s), m/s for accelerometers; s for `T`) and the fit's `chi2_per_dof`.
fn fit_rows<'py>(
    py: Python<'py>,
    fits: &[schuler_run::allan::ChannelFit],
) -> PyResult<Bound<'py, PyDict>> {
    use schuler::analysis::allan::fit::Term;
    let (mut channel, mut model, mut term) = (Vec::new(), Vec::new(), Vec::new());
    let mut num = Columns::new(&["value", "lo", "hi", "chi2_per_dof"]);
    for (c, f) in fits.iter().enumerate() {
        let name = schuler::analysis::allan::CHANNEL_NAMES[c];
        for (m, fit) in [("ieee952", &f.ieee), ("gauss_markov", &f.filter)] {
            let Some(fit) = fit else { continue };
            let mut row = |t: &str, v: f64, (lo, hi): (f64, f64)| {
                channel.push(name);
                model.push(m);
                term.push(t.to_owned());
                num.push(v, &[lo, hi, fit.chi2_per_dof]);
            };
            for t in &fit.terms {
                let symbol = match t.term {
                    Term::GaussMarkov { .. } => "sigma",
                    other => other.name().rsplit(' ').next().unwrap_or("?"),
                };
                row(symbol, t.value, t.interval);
            }
            if let Some(ct) = fit.correlation_time {
                row("T", ct.value, ct.interval);
            }
        }
    }
    let d = num.take_dict(py)?;
    d.set_item("channel", channel)?;
    d.set_item("model", model)?;
    d.set_item("term", term)?;
    Ok(d)
}
