//! `simulate(scenario)`: the library's simulator on a `schuler simulate` scenario
//! (TOML text, a file, or the same keys as JSON from a Python dict), its streams
//! collected into columns: the measured IMU samples, the truth, GNSS fixes, barometer
//! readings and the true sensor errors, with the values the CLI's files hold.

use crate::columns::{Columns, GNSS, IMU, NAV};
use crate::errors::IntoPy;
use anyhow::Context;
use nalgebra::Vector3;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::sim::analytic::Kinematics;
use schuler::sim::receivers::{BaroReading, GnssFix};
use schuler::sim::run::{ImuErrorTruth, ScenarioSpec, SimSink, simulate};
use schuler_io::output::nav_fields;
use schuler_run::drive::imu_err_row;
use std::path::Path;

/// Columns of the truth after [`NAV`]'s: angular rate [rad/s] and specific force
/// [m/s^2] in body axes at `t`.
const KINEMATICS: &[&str] = &[
    "w_x_radps",
    "w_y_radps",
    "w_z_radps",
    "f_x_mps2",
    "f_y_mps2",
    "f_z_mps2",
];

/// The simulated streams.
struct Collected {
    imu: Columns,
    truth: Columns,
    kinematics: Columns,
    gnss: Columns,
    baro: Columns,
    sensor_errors: Columns,
    /// Whether the scenario simulates GNSS velocity measurements (`velocity_std`).
    gnss_velocity: bool,
}

impl SimSink for Collected {
    fn imu(
        &mut self,
        _exact: &ImuSample,
        m: &ImuSample,
        truth: &NavState,
        kin: &Kinematics,
    ) -> std::io::Result<()> {
        let (a, v) = (m.dtheta, m.dvel);
        self.imu.push(m.t, &[m.dt, a.x, a.y, a.z, v.x, v.y, v.z]);
        self.truth.push(truth.t, &nav_fields(truth));
        let (w, f) = (kin.w_ib_b, kin.f_b);
        self.kinematics.push(w.x, &[w.y, w.z, f.x, f.y, f.z]);
        Ok(())
    }

    fn gnss(&mut self, g: &GnssFix) -> std::io::Result<()> {
        let (p, s) = (&g.pos, &g.pos_std);
        // Without `velocity_std` the simulator measures no velocity (its velocity is
        // the truth with a standard deviation of 0): NaN, as a fix without velocity.
        let none = Vector3::repeat(f64::NAN);
        let (v, sv) = match self.gnss_velocity {
            true => (&g.v_n, &g.vel_std),
            false => (&none, &none),
        };
        let row = [
            p.lat.to_degrees(),
            p.lon.to_degrees(),
            p.h,
            s.x,
            s.y,
            s.z,
            v.x,
            v.y,
            v.z,
            sv.x,
            sv.y,
            sv.z,
            f64::from(u8::from(g.outlier)),
        ];
        self.gnss.push(g.t, &row);
        Ok(())
    }

    fn baro(&mut self, r: &BaroReading) -> std::io::Result<()> {
        self.baro.push(r.t, &[r.h, f64::from(u8::from(r.outlier))]);
        Ok(())
    }

    fn imu_errors(&mut self, e: &ImuErrorTruth) -> std::io::Result<()> {
        self.sensor_errors.push(e.t, &imu_err_row(&e.errors));
        Ok(())
    }
}

/// The scenario of `text` (`"toml"` or `"json"`), or of the file `path`.
fn scenario(text: Option<&str>, format: &str, path: Option<&Path>) -> anyhow::Result<ScenarioSpec> {
    match (text, path) {
        (_, Some(p)) => schuler_run::scenario::load_scenario(p),
        (Some(t), None) if format == "json" => {
            serde_json::from_str(t).context("in the scenario (dict)")
        }
        (Some(t), None) => toml::from_str(t).context("in the scenario (TOML text)"),
        (None, None) => anyhow::bail!("no scenario"),
    }
}

/// Simulates a scenario (`text` in `format` "toml" or "json", or the file `path`):
/// dicts of columns `imu`, `truth`, `gnss`, `baro`, `sensor_errors` and the resolved
/// scenario as TOML (`scenario`). The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (text=None, format="toml", path=None))]
pub fn simulate_scenario<'py>(
    py: Python<'py>,
    text: Option<String>,
    format: &str,
    path: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = scenario(text.as_deref(), format, path.as_deref()).py_err(py)?;
    let mut c = Collected {
        imu: Columns::new(IMU),
        truth: Columns::new(NAV),
        kinematics: Columns::new(KINEMATICS),
        gnss: Columns::joined(&[GNSS, &["outlier"]]),
        baro: Columns::new(&["t_s", "h_m", "outlier"]),
        sensor_errors: Columns::new(crate::columns::SENSOR),
        gnss_velocity: schuler_run::scenario::simulates_gnss_velocity(&spec),
    };
    py.detach(|| simulate(&spec, &mut c)).py_err(py)?;
    let d = PyDict::new(py);
    d.set_item("imu", c.imu.take_dict(py)?)?;
    let truth = c.truth.take_dict(py)?;
    c.kinematics.drain_into(&truth)?;
    d.set_item("truth", truth)?;
    if spec.gnss.is_some() {
        d.set_item("gnss", c.gnss.take_dict(py)?)?;
    }
    if spec.baro.is_some() {
        d.set_item("baro", c.baro.take_dict(py)?)?;
    }
    d.set_item("sensor_errors", c.sensor_errors.take_dict(py)?)?;
    let resolved =
        toml::to_string(&spec.resolved()).context("cannot serialize the resolved scenario");
    d.set_item("scenario", resolved.py_err(py)?)?;
    Ok(d)
}
