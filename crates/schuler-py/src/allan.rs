//! `allan(imu)`: the overlapping Allan deviations of the six channels of a static log
//! ([`schuler::analysis::allan::ImuAllan`], as `schuler allan` computes them), in SI.

use crate::columns::Columns;
use crate::errors::IntoPy;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler::analysis::allan::{CurveOptions, ImuAllan};
use schuler::imu::ImuSample;
use schuler_cli::formats::ImuReader;
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
/// the IMU input `flags`) or of the columns `imu` (`t, dtheta_xyz, dvel_xyz`, `dt`
/// optional): `per_decade` cluster sizes a decade up to `max_tau` [s] (default a
/// tenth of the log). The GIL is released.
#[pyfunction]
#[pyo3(signature = (path=None, flags=Vec::new(), imu=None, imu_dt=None, per_decade=10.0, max_tau=None))]
pub fn allan<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    flags: Vec<String>,
    imu: Option<Vec<PyReadonlyArray1<'py, f64>>>,
    imu_dt: Option<PyReadonlyArray1<'py, f64>>,
    per_decade: f64,
    max_tau: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let views = match &imu {
        Some(cols) => Some(crate::imu_views(cols, imu_dt.as_ref(), None).py_err(py)?),
        None => None,
    };
    let opts = crate::options::imu_options(&flags).py_err(py)?;
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
