//! `read_imu`, `read_gnss`, `read_nav`: the CLI's readers (every format `schuler nav`
//! and `schuler compare` read, with their options), into columns with units in their
//! names.

use crate::columns::{Columns, GNSS, IMU, NAV};
use crate::errors::IntoPy;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler_io::formats::ImuReader;
use std::path::PathBuf;

/// IMU samples of `path` as the CLI reads them with `options` (the IMU input options,
/// `start`, `end`): columns `t_s`, `dt_s`, `dtheta_*_rad`, `dvel_*_mps` (FRD).
#[pyfunction]
pub fn read_imu<'py>(
    py: Python<'py>,
    path: PathBuf,
    options: Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let opts = crate::options::imu_options(crate::options::table(&options)?).py_err(py)?;
    let mut c = py
        .detach(|| -> anyhow::Result<Columns> {
            let mut c = Columns::new(IMU);
            for s in ImuReader::open(&path, &opts)? {
                let s = s?;
                let (a, v) = (s.dtheta, s.dvel);
                c.push(s.t, &[s.dt, a.x, a.y, a.z, v.x, v.y, v.z]);
            }
            Ok(c)
        })
        .py_err(py)?;
    c.take_dict(py)
}

/// GNSS fixes of `path` as `schuler nav --gnss` reads them with `options` (format,
/// default std, quality, time offset, velocity log): columns of [`GNSS`].
#[pyfunction]
pub fn read_gnss<'py>(
    py: Python<'py>,
    path: PathBuf,
    options: Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut opts = crate::options::aiding_options(crate::options::table(&options)?).py_err(py)?;
    opts.gnss = Some(path);
    let fixes = py.detach(|| opts.fixes(None)).py_err(py)?;
    let mut c = Columns::new(GNSS);
    for f in &fixes {
        let (v, sv) = f.vel.unwrap_or((
            nalgebra::Vector3::repeat(f64::NAN),
            nalgebra::Vector3::repeat(f64::NAN),
        ));
        let p = &f.pos;
        let s = &f.pos_std;
        c.push(
            f.t,
            &[
                degrees_back(p.lat),
                degrees_back(p.lon),
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
            ],
        );
    }
    c.take_dict(py)
}

/// `rad` in degrees, chosen among the neighbours of `rad.to_degrees()` (within 4
/// ulps) so that `to_radians` gives `rad` back where one does: a table read here and
/// given to `navigate` then holds the reader's own fixes, bit for bit.
fn degrees_back(rad: f64) -> f64 {
    let d = rad.to_degrees();
    let mut candidates = [d; 9];
    for k in 1..5 {
        candidates[2 * k - 1] = (0..k).fold(d, |x, _| x.next_up());
        candidates[2 * k] = (0..k).fold(d, |x, _| x.next_down());
    }
    candidates
        .into_iter()
        .find(|x| x.to_radians() == rad)
        .unwrap_or(d)
}

/// Barometer readings of `path` (`t,h_m` CSV or `t h` text): columns `t_s`, `h_m`.
#[pyfunction]
pub fn read_baro<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let rows = py
        .detach(|| schuler_io::formats::gnss::read_baro(&path))
        .py_err(py)?;
    let d = PyDict::new(py);
    d.set_item("t_s", rows.iter().map(|r| r.0).collect::<Vec<_>>())?;
    d.set_item("h_m", rows.iter().map(|r| r.1).collect::<Vec<_>>())?;
    Ok(d)
}

/// A navigation result or truth (KF-GINS text such as `nav.txt`, or `nav.csv`):
/// columns of [`NAV`] (angles in degrees, yaw in [0, 360), as the file holds them).
#[pyfunction]
pub fn read_nav<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let (_, rows) = py
        .detach(|| schuler_io::formats::nav::read_nav(&path))
        .py_err(py)?;
    let mut c = Columns::new(NAV);
    for r in &rows {
        let (p, v, a) = (&r.pos, &r.v_n, &r.att);
        c.push(
            r.t_sow,
            &[
                p.lat.to_degrees(),
                p.lon.to_degrees(),
                p.h,
                v.x,
                v.y,
                v.z,
                a.roll.to_degrees(),
                a.pitch.to_degrees(),
                a.yaw.to_degrees().rem_euclid(360.0),
            ],
        );
    }
    c.take_dict(py)
}
