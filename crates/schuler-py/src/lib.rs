//! The `schuler` Python package's native module `schuler._schuler`: a thin layer over
//! the library's navigation session and the CLI's readers and option parsing. The
//! Python side (`python/schuler/`) turns keyword arguments into the CLI's flags and
//! the dicts of numpy arrays returned here into pandas DataFrames.

mod align;
mod allan;
mod arrays;
mod channel;
mod columns;
mod compare;
mod errors;
mod montecarlo;
mod options;
mod readers;
mod run;
mod session;
mod simulate;
mod vehicle;

use arrays::ImuArrays;
use errors::IntoPy;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use run::{Plan, Tables};
use schuler_run::aided::GivenReadings;

/// Views of IMU columns `t, dtheta_x..z, dvel_x..z` and an optional `dt`.
pub(crate) fn imu_views<'a>(
    cols: &'a [PyReadonlyArray1<'_, f64>],
    dt: Option<&'a PyReadonlyArray1<'_, f64>>,
    t_before: Option<f64>,
) -> anyhow::Result<ImuArrays<'a>> {
    let [t, a, b, c, d, e, f] = cols else {
        anyhow::bail!(
            "IMU arrays: 7 columns t, dtheta_x..z, dvel_x..z, got {}",
            cols.len()
        );
    };
    Ok(ImuArrays {
        t: t.as_array(),
        dt: dt.map(|d| d.as_array()),
        inc: [a, b, c, d, e, f].map(|x| x.as_array()),
        t_before,
    })
}

/// Columns given by Python, read in place.
type ColumnsIn<'py> = Option<Vec<PyReadonlyArray1<'py, f64>>>;

/// Views of `cols`.
fn views<'a>(cols: &'a ColumnsIn<'_>) -> Option<Vec<numpy::ndarray::ArrayView1<'a, f64>>> {
    cols.as_ref()
        .map(|c| c.iter().map(|x| x.as_array()).collect())
}

/// The aiding readings given as arrays: `gnss` and `baro` columns, and the vehicle
/// aids' `[rest, odometer, heading]` columns ([`vehicle::REST`],
/// [`vehicle::ODOMETER`], [`vehicle::HEADING`]).
pub(crate) fn given_readings(
    gnss: Option<Vec<PyReadonlyArray1<'_, f64>>>,
    baro: Option<(PyReadonlyArray1<'_, f64>, PyReadonlyArray1<'_, f64>)>,
    [rest, odometer, heading]: [&ColumnsIn<'_>; 3],
) -> anyhow::Result<GivenReadings> {
    let fixes = match gnss {
        Some(g) => Some(arrays::gnss_fixes(
            &g.iter().map(|c| c.as_array()).collect::<Vec<_>>(),
        )?),
        None => None,
    };
    let baro = match baro {
        Some((t, h)) => Some(arrays::baro_readings(t.as_array(), h.as_array())?),
        None => None,
    };
    let (rest, odometer, heading) = (views(rest), views(odometer), views(heading));
    let vehicle = vehicle::given(rest.as_deref(), odometer.as_deref(), heading.as_deref())?;
    Ok(GivenReadings {
        fixes,
        baro,
        vehicle,
    })
}

/// Navigates as `schuler nav` with `options` (its flags' names with underscores): the
/// IMU samples from `imu` (columns) or the file of the `imu` option, aids from `gnss`/`baro`/`rest`/`odometer`/`heading` columns or
/// their files. Returns the tables (see [`Tables::take_dict`]), `smoothed` (with
/// `--smooth`), `summary` and how the run started (`alignment` with `--align`,
/// `start_in_motion` with `--init gnss`). The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (options, imu=None, imu_dt=None, gnss=None, baro=None, rest=None, odometer=None, heading=None))]
#[allow(clippy::too_many_arguments)] // one keyword argument per input, as Python passes them
fn navigate<'py>(
    py: Python<'py>,
    options: Bound<'py, PyDict>,
    imu: Option<Vec<PyReadonlyArray1<'py, f64>>>,
    imu_dt: Option<PyReadonlyArray1<'py, f64>>,
    gnss: Option<Vec<PyReadonlyArray1<'py, f64>>>,
    baro: Option<(PyReadonlyArray1<'py, f64>, PyReadonlyArray1<'py, f64>)>,
    rest: ColumnsIn<'py>,
    odometer: ColumnsIn<'py>,
    heading: ColumnsIn<'py>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = options::table(&options)?;
    let mut plan = given_readings(gnss, baro, [&rest, &odometer, &heading])
        .and_then(|given| Plan::new(options, given))
        .py_err(py)?;
    let views = match &imu {
        Some(cols) => Some(imu_views(cols, imu_dt.as_ref(), None).py_err(py)?),
        None => None,
    };
    let mut tables = Tables::default();
    let (finished, smoothed, began) = py
        .detach(|| -> anyhow::Result<_> {
            let (path, read) = (plan.settings.imu.clone(), plan.settings.read.clone());
            match &views {
                Some(v) => run::run(&mut plan, &mut tables, v.samples(read.t_start, read.t_end)?),
                None => {
                    let reader = schuler_io::formats::ImuReader::open(&path, &read)?;
                    run::run(&mut plan, &mut tables, reader)
                }
            }
        })
        .py_err(py)?;
    let d = tables.take_dict(py)?;
    session::add_finished(py, &d, &finished, smoothed.as_deref())?;
    align::add_began(py, &d, &began)?;
    Ok(d)
}

/// The native module.
#[pymodule]
fn _schuler(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(navigate, m)?)?;
    m.add_function(wrap_pyfunction!(readers::read_imu, m)?)?;
    m.add_function(wrap_pyfunction!(readers::read_gnss, m)?)?;
    m.add_function(wrap_pyfunction!(readers::read_baro, m)?)?;
    m.add_function(wrap_pyfunction!(readers::read_nav, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    m.add_function(wrap_pyfunction!(allan::allan, m)?)?;
    m.add_function(wrap_pyfunction!(allan::allan_fit, m)?)?;
    m.add_function(wrap_pyfunction!(align::align, m)?)?;
    m.add_function(wrap_pyfunction!(channel::channel, m)?)?;
    m.add_function(wrap_pyfunction!(channel::closed_form, m)?)?;
    m.add_function(wrap_pyfunction!(montecarlo::montecarlo_seeds, m)?)?;
    m.add_class::<session::PySession>()?;
    m.add("SchulerError", m.py().get_type::<errors::SchulerError>())?;
    m.add("InputError", m.py().get_type::<errors::InputError>())?;
    m.add("CAMPAIGN_COLUMNS", schuler_run::campaign::COLUMNS.to_vec())?;
    m.add("NAV_COLUMNS", columns::NAV.to_vec())?;
    Ok(())
}
