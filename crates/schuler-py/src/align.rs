//! `align(imu, pos=...)`: `schuler align` (coarse gyrocompassing, then the Kalman
//! filter on the invariants) on a log at rest, from a file or arrays, with the CLI's
//! own options and code ([`schuler_run::alignment`],
//! [`schuler_run::alignment`]); what it gives is `align.json`'s content, the
//! `align_convergence.csv` table and the printed report. The same tables describe the
//! alignment of `navigate(..., align=True)`.

use crate::columns::{CONVERGENCE, Columns};
use crate::errors::IntoPy;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler::align::Alignment;
use schuler_io::formats::ImuReader;
use schuler_run::alignment::{AlignArgs, setup};
use schuler_run::alignment::{align_on, convergence_row, read_stage, summary_text, to_json};
use schuler_run::nav::Began;

/// Aligns as `schuler align` with `options` (its flags' names with underscores; `imu`
/// names the file, or a placeholder
/// when `imu` columns `t, dtheta_xyz, dvel_xyz` are given, `dt` optional): a dict of
/// `summary` (`align.json` as JSON text), `convergence` (columns of
/// `align_convergence.csv`) and `report` (the printed text without run times). The
/// GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (options, imu=None, imu_dt=None))]
pub fn align<'py>(
    py: Python<'py>,
    options: Bound<'py, PyDict>,
    imu: Option<Vec<PyReadonlyArray1<'py, f64>>>,
    imu_dt: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let args = AlignArgs::from_options(crate::options::table(&options)?).py_err(py)?;
    let views = match &imu {
        Some(cols) => Some(crate::imu_views(cols, imu_dt.as_ref(), None).py_err(py)?),
        None => None,
    };
    let a = py
        .detach(|| -> anyhow::Result<Alignment> {
            let (cfg, noise, pos) = setup(&args)?;
            let read = args.input.read_options(args.start, None)?;
            let seconds = cfg.coarse + cfg.fine;
            let samples = match &views {
                Some(v) => read_stage(&mut v.samples(read.t_start, None)?, seconds)?,
                None => read_stage(&mut ImuReader::open(&args.imu, &read)?, seconds)?,
            };
            align_on(args.earth, pos, &samples, &noise, &cfg)
                .map_err(|e| e.context(format!("aligning {}", args.imu.display())))
        })
        .py_err(py)?;
    alignment_dict(py, &a)
}

/// An alignment as `summary` (JSON text), `convergence` (columns) and `report`.
pub fn alignment_dict<'py>(py: Python<'py>, a: &Alignment) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("summary", to_json(a).to_string())?;
    let mut c = Columns::new(CONVERGENCE);
    for p in a.fine.iter().flat_map(|f| f.convergence.iter()) {
        let row = convergence_row(p);
        c.push(row[0], &row[1..]);
    }
    d.set_item("convergence", c.take_dict(py)?)?;
    d.set_item("report", summary_text(a, &[]))?;
    Ok(d)
}

/// Adds how a run began to its dict: `alignment` (after `--align`, else None) and
/// `start_in_motion` (after `--init gnss`: time [s], speed [m/s], roll, pitch, yaw
/// [deg] and the attitude's standard deviations about north, east, down [deg]).
pub fn add_began(py: Python<'_>, d: &Bound<'_, PyDict>, began: &Began) -> PyResult<()> {
    match began {
        Began::Aligned(a) => d.set_item("alignment", alignment_dict(py, a)?)?,
        _ => d.set_item("alignment", py.None())?,
    }
    match began {
        Began::InMotion(m) => {
            let s = PyDict::new(py);
            let e = m.state.euler();
            s.set_item("t_s", m.state.t)?;
            s.set_item("speed_mps", m.speed)?;
            s.set_item("roll_deg", e.roll.to_degrees())?;
            s.set_item("pitch_deg", e.pitch.to_degrees())?;
            s.set_item("yaw_deg", e.heading_0_2pi().to_degrees())?;
            let sd: [f64; 3] = m.att_std.map(f64::to_degrees).into();
            s.set_item("att_std_deg", sd.to_vec())?;
            d.set_item("start_in_motion", s)
        }
        _ => d.set_item("start_in_motion", py.None()),
    }
}
