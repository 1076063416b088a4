//! The textbook's single channel: `channel(...)` runs `schuler channel` (the nonlinear
//! system, the linear error model and the closed form side by side, with the CLI's
//! options and checks, [`schuler_run::channel`]) and `closed_form(t, ...)`
//! evaluates the general solution (18)/(19) of the error equations (13) for constant
//! errors and the free vertical channel (32) at any times
//! ([`schuler::channel::closed`]).

use crate::columns::Columns;
use crate::errors::IntoPy;
use anyhow::bail;
use clap::Parser;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler::channel::closed::{ConstantErrors, response, vertical_free_response};
use schuler::channel::linear::{ErrorModel, ErrorState};
use schuler::channel::run::simulate;
use schuler_run::channel::{Args, config, explain, summary};

/// Columns of the channel's errors (`errors.csv`'s, units in the names; the
/// closed form's NaN where the inputs are not constant).
const ERRORS: &[&str] = &[
    "t_s",
    "dr_m",
    "dv_mps",
    "alpha_rad",
    "dr_linear_m",
    "dv_linear_mps",
    "alpha_linear_rad",
    "dr_closed_m",
    "dv_closed_mps",
    "alpha_closed_rad",
];

/// `schuler channel`'s arguments.
#[derive(Parser, Debug)]
#[command(name = "channel", no_binary_name = true)]
struct ChannelFlags {
    #[command(flatten)]
    args: Args,
}

/// Runs `schuler channel` with `flags` (an `--out` placeholder among them; nothing is
/// written): `errors` (columns of `errors.csv`) and `summary` (`summary.json` as JSON
/// text). The GIL is released while it runs.
#[pyfunction]
pub fn channel<'py>(py: Python<'py>, flags: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
    crate::options::check_flag_names::<Args>(&flags).py_err(py)?;
    let args = ChannelFlags::try_parse_from(&flags).py_err(py)?.args;
    let (cfg, run) = py
        .detach(|| -> anyhow::Result<_> {
            let cfg = config(&args)?;
            let run = simulate(&cfg).map_err(explain)?;
            Ok((cfg, run))
        })
        .py_err(py)?;
    let mut errors = Columns::new(ERRORS);
    let nan = ErrorState {
        dr: f64::NAN,
        dv: f64::NAN,
        alpha: f64::NAN,
    };
    for r in &run.rows {
        let (n, l, c) = (r.nonlinear, r.linear, r.closed.unwrap_or(nan));
        let row = [
            n.dr, n.dv, n.alpha, l.dr, l.dv, l.alpha, c.dr, c.dv, c.alpha,
        ];
        errors.push(r.t, &row);
    }
    let d = PyDict::new(py);
    d.set_item("errors", errors.take_dict(py)?)?;
    d.set_item("summary", summary(&cfg, &run).to_string())?;
    Ok(d)
}

/// The closed-form errors of the single channel (13) at the times `t` [s] for the
/// constant errors given (SI: accelerometer bias [m/s^2], drift [rad/s] in (13)'s
/// sign, initial vertical error [rad], velocity error [m/s], position error [m]) on a
/// sphere of `radius` [m] with vertical specific force `g` [m/s^2]: columns `t_s`,
/// `dr_m`, `dv_mps`, `alpha_rad` of (18)/(19), and `dh_m`, `dvh_mps` of the free
/// vertical channel (32) from `dh0`, `dvh0` and `vertical_accel_bias`.
#[pyfunction]
#[pyo3(signature = (t, accel_bias=0.0, drift=0.0, alpha0=0.0, dv0=0.0, dr0=0.0, dh0=0.0, dvh0=0.0, vertical_accel_bias=0.0, radius=6.371e6, g=9.81))]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments
pub fn closed_form<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    accel_bias: f64,
    drift: f64,
    alpha0: f64,
    dv0: f64,
    dr0: f64,
    dh0: f64,
    dvh0: f64,
    vertical_accel_bias: f64,
    radius: f64,
    g: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let check = || -> anyhow::Result<()> {
        for (name, v) in [("radius", radius), ("g", g)] {
            if !(v.is_finite() && v > 0.0) {
                bail!("{name} must be a positive number, got {v}");
            }
        }
        let inputs = [
            ("accel_bias", accel_bias),
            ("drift", drift),
            ("alpha0", alpha0),
            ("dv0", dv0),
            ("dr0", dr0),
            ("dh0", dh0),
            ("dvh0", dvh0),
            ("vertical_accel_bias", vertical_accel_bias),
        ];
        if let Some((name, v)) = inputs.iter().find(|(_, v)| !v.is_finite()) {
            bail!("{name} must be finite, got {v}");
        }
        if let Some((i, x)) = t
            .as_array()
            .iter()
            .enumerate()
            .find(|(_, x)| !x.is_finite())
        {
            bail!("t[{i}] must be finite, got {x}");
        }
        Ok(())
    };
    check().py_err(py)?;
    let model = ErrorModel::new(radius, g);
    let e = ConstantErrors {
        accel_bias,
        drift,
        alpha0,
        dv0,
        dr0,
    };
    let w0 = model.schuler_frequency();
    let mut c = Columns::new(&["t_s", "dr_m", "dv_mps", "alpha_rad", "dh_m", "dvh_mps"]);
    for &t in t.as_array() {
        let x = response(&model, &e, t);
        let (dh, dvh) = vertical_free_response(w0, dh0, dvh0, vertical_accel_bias, t);
        c.push(t, &[x.dr, x.dv, x.alpha, dh, dvh]);
    }
    c.take_dict(py)
}
