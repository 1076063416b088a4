//! `compare(nav, truth)`: `schuler compare`'s errors and statistics (RMS, max, 95 %,
//! mean, CEP/CEP95, outage maxima; errors through ECEF in the truth's NED frame, valid
//! at the poles) of a navigation result against a truth, files or tables.

use crate::columns::Columns;
use crate::errors::IntoPy;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler::analysis::errors::NavRecord;
use schuler::earth::Geodetic;
use schuler::rotation::Euler;
use schuler_io::formats::nav::{NavFormat, read_nav};
use schuler_io::output::error_fields;
use schuler_run::compare::summary_json;
use std::path::{Path, PathBuf};

/// Columns of the errors (`errors.csv`'s, units in the names).
const ERRORS: &[&str] = &[
    "t_s",
    "north_m",
    "east_m",
    "down_m",
    "horizontal_m",
    "vn_mps",
    "ve_mps",
    "vd_mps",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "interpolated",
];

/// A navigation result given as a file or as `read_nav`'s ten columns.
#[derive(FromPyObject)]
pub enum NavInput<'py> {
    /// A file (KF-GINS text or `nav.csv`).
    Path(PathBuf),
    /// Columns `t_s, lat_deg, lon_deg, h_m, vn_mps, ve_mps, vd_mps, roll_deg,
    /// pitch_deg, yaw_deg`.
    Columns(Vec<PyReadonlyArray1<'py, f64>>),
}

impl NavInput<'_> {
    /// The records, the path to report and the format.
    fn records(&self) -> anyhow::Result<(Vec<NavRecord>, PathBuf, NavFormat)> {
        match self {
            NavInput::Path(p) => {
                let (format, rows) = read_nav(p)?;
                Ok((rows, p.clone(), format))
            }
            NavInput::Columns(cols) => {
                let [t, lat, lon, h, vn, ve, vd, r, p, y] = cols.as_slice() else {
                    anyhow::bail!("a navigation table needs 10 columns, got {}", cols.len());
                };
                let c = [t, lat, lon, h, vn, ve, vd, r, p, y].map(|c| c.as_array());
                let rows = (0..c[0].len())
                    .map(|i| NavRecord {
                        t_sow: c[0][i],
                        pos: Geodetic::from_degrees(c[1][i], c[2][i], c[3][i]),
                        v_n: nalgebra::Vector3::new(c[4][i], c[5][i], c[6][i]),
                        att: Euler::from_degrees(c[7][i], c[8][i], c[9][i]),
                    })
                    .collect();
                Ok((rows, PathBuf::from("<table>"), NavFormat::Csv))
            }
        }
    }
}

/// Compares `nav` with `truth` as `schuler compare` does within `[start, end]` with the
/// `outages` windows [s]: `summary` (compare.json's content, as JSON text) and `errors`
/// (columns of `errors.csv`).
#[pyfunction]
#[pyo3(signature = (nav, truth, start=None, end=None, outages=Vec::new()))]
pub fn compare<'py>(
    py: Python<'py>,
    nav: NavInput<'py>,
    truth: NavInput<'py>,
    start: Option<f64>,
    end: Option<f64>,
    outages: Vec<(f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let (n, t) = (nav.records().py_err(py)?, truth.records().py_err(py)?);
    let c = py
        .detach(|| schuler::analysis::statistics::compare(&n.0, &t.0, start, end, &outages))
        .py_err(py)?;
    let summary = summary_json(&c, (Path::new(&n.1), n.2), (Path::new(&t.1), t.2));
    let mut errors = Columns::new(ERRORS);
    for e in &c.errors {
        let mut row = error_fields(e).to_vec();
        row.push(f64::from(u8::from(e.interpolated)));
        errors.push(e.t_sow, &row);
    }
    let d = PyDict::new(py);
    d.set_item("summary", summary.to_string())?;
    d.set_item("errors", errors.take_dict(py)?)?;
    Ok(d)
}
