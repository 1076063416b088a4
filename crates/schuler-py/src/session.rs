//! `schuler.Session`: the library's session for sample-by-sample or block pushes from
//! Python, configured by the same flags as `navigate`.

use crate::errors::IntoPy;
use crate::errors::SchulerError;
use crate::run::{AnySession, Plan, Tables, smoothed_columns, summary_dict};
use crate::vehicle::{self, Source};
use nalgebra::Vector3;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::filter::smoother::Smoothed;
use schuler::imu::ImuSample;
use schuler::session::{Aid, Finished};
use schuler_run::aided::GivenReadings;
use schuler_run::aided::vehicle::GivenVehicle;
use schuler_run::nav::InitChoice;

/// A navigation session fed by pushes; its tables are taken as they grow.
#[pyclass(name = "Session", module = "schuler._schuler")]
pub struct PySession {
    /// The session and what it produced, until `finish`.
    open: Option<(AnySession, Tables)>,
    /// Time of the last IMU sample pushed [s].
    last_t: Option<f64>,
}

impl PySession {
    fn open(&mut self) -> anyhow::Result<&mut (AnySession, Tables)> {
        self.open
            .as_mut()
            .ok_or_else(|| anyhow::anyhow!("the session is finished"))
    }

    fn push_samples(
        &mut self,
        samples: impl Iterator<Item = Result<ImuSample, schuler_io::formats::InputError>>,
    ) -> anyhow::Result<()> {
        let mut last = self.last_t;
        let (session, tables) = self.open()?;
        for s in samples {
            let s = s?;
            last = Some(s.t);
            session.push_imu(s)?;
            session.take(tables);
        }
        self.last_t = last;
        Ok(())
    }
}

#[pymethods]
impl PySession {
    /// A session configured by `schuler nav`'s `options` (an `imu` placeholder among
    /// them; aids are pushed, not read); `gnss`, `baro`, `rest`, `odometer`, `heading`:
    /// such aids will be pushed (the filter is set up for them as for their files:
    /// barometer bias, rest updates, odometer noise and scale factor, antenna baseline).
    #[new]
    #[pyo3(signature = (options, gnss=false, baro=false, rest=false, odometer=false, heading=false))]
    fn new(
        py: Python<'_>,
        options: Bound<'_, PyDict>,
        gnss: bool,
        baro: bool,
        rest: bool,
        odometer: bool,
        heading: bool,
    ) -> PyResult<Self> {
        let given = GivenReadings {
            fixes: gnss.then(Vec::new),
            baro: baro.then(Vec::new),
            vehicle: GivenVehicle {
                rests: rest.then(Vec::new),
                odometer: odometer.then(Vec::new),
                headings: heading.then(Vec::new),
            },
        };
        let plan = Plan::new(crate::options::table(&options)?, given).py_err(py)?;
        if plan.align.is_some() || plan.init != InitChoice::Given {
            return Err(SchulerError::new_err(
                "a Session starts from the given state (init_pos, init_vel, init_att): \
                 align=True and init=\"gnss\" read the first samples, use navigate() for them",
            ));
        }
        let mut tables = Tables::default();
        let start = plan.settings.start();
        let session = AnySession::open(&plan, start, &mut std::iter::empty(), &mut tables);
        Ok(Self {
            open: Some((session.py_err(py)?, tables)),
            last_t: None,
        })
    }

    /// Pushes one IMU sample: interval end `t` [s], angle increment `dtheta` [rad] and
    /// velocity increment `dvel` [m/s] over it (FRD), interval `dt` [s] (default: since
    /// the last sample; required for the first).
    #[pyo3(signature = (t, dtheta, dvel, dt=None))]
    fn push_imu(
        &mut self,
        py: Python<'_>,
        t: f64,
        dtheta: [f64; 3],
        dvel: [f64; 3],
        dt: Option<f64>,
    ) -> PyResult<()> {
        let cols = [
            t,
            dt.unwrap_or(f64::NAN),
            dtheta[0],
            dtheta[1],
            dtheta[2],
            dvel[0],
            dvel[1],
            dvel[2],
        ];
        let one = cols.map(|x| numpy::ndarray::arr1(&[x]));
        let v = crate::arrays::ImuArrays {
            t: one[0].view(),
            dt: dt.map(|_| one[1].view()),
            inc: [2, 3, 4, 5, 6, 7].map(|k| one[k].view()),
            t_before: self.last_t,
        };
        let samples = v.samples(None, None).py_err(py)?;
        self.push_samples(samples).py_err(py)
    }

    /// Pushes a block of IMU samples: columns `t, dtheta_x..z, dvel_x..z` (numpy
    /// arrays, read in place) and optionally `dt`. The GIL is released.
    #[pyo3(signature = (cols, dt=None))]
    fn push_imu_block(
        &mut self,
        py: Python<'_>,
        cols: Vec<PyReadonlyArray1<'_, f64>>,
        dt: Option<PyReadonlyArray1<'_, f64>>,
    ) -> PyResult<()> {
        let v = crate::imu_views(&cols, dt.as_ref(), self.last_t).py_err(py)?;
        py.detach(|| -> anyhow::Result<()> {
            let samples = v.samples(None, None)?;
            self.push_samples(samples)
        })
        .py_err(py)
    }

    /// Pushes a GNSS fix: time [s], latitude, longitude [deg], height [m], position
    /// standard deviations north, east, down [m], optionally velocity north, east, down
    /// [m/s] with its standard deviations.
    #[pyo3(signature = (t, lat_deg, lon_deg, h_m, std_ned_m, vel_ned_mps=None, vel_std_ned_mps=None))]
    #[allow(clippy::too_many_arguments)] // a fix's fields, as keyword arguments
    fn push_gnss(
        &mut self,
        py: Python<'_>,
        t: f64,
        lat_deg: f64,
        lon_deg: f64,
        h_m: f64,
        std_ned_m: [f64; 3],
        vel_ned_mps: Option<[f64; 3]>,
        vel_std_ned_mps: Option<[f64; 3]>,
    ) -> PyResult<()> {
        let vel = match (vel_ned_mps, vel_std_ned_mps) {
            (Some(v), Some(s)) => Some((Vector3::from(v), Vector3::from(s))),
            (Some(v), None) => Some((Vector3::from(v), Vector3::repeat(0.1))),
            _ => None,
        };
        let fix = GnssFix {
            t,
            pos: Geodetic::from_degrees(lat_deg, lon_deg, h_m),
            pos_std: Vector3::from(std_ned_m),
            vel,
        };
        self.push_aid(py, Aid::Gnss(fix))
    }

    /// Pushes a barometric height `h_m` [m] at time `t` [s].
    fn push_baro(&mut self, py: Python<'_>, t: f64, h_m: f64) -> PyResult<()> {
        self.push_aid(py, Aid::Baro { t, h: h_m })
    }

    /// Pushes that the vehicle was at rest from `t0_s` to `t1_s` [s] (zero-velocity
    /// updates inside; `t1_s > t0_s`), checked as a line of `--zupt`'s file.
    fn push_rest(&mut self, py: Python<'_>, t0_s: f64, t1_s: f64) -> PyResult<()> {
        let r = vehicle::rests(&one_row(&[t0_s, t1_s]).views(), Source::Push).py_err(py)?;
        self.push_aids(py, r.into_iter().map(|(t0, t1)| Aid::Rest { t0, t1 }))
    }

    /// Pushes an odometer reading: forward speed `speed_mps` [m/s] of the point at
    /// `--vehicle-lever-arm` at time `t` [s], checked as a line of `--odometer`'s file.
    fn push_odometer(&mut self, py: Python<'_>, t: f64, speed_mps: f64) -> PyResult<()> {
        let r = vehicle::odometer(&one_row(&[t, speed_mps]).views(), Source::Push).py_err(py)?;
        self.push_aids(
            py,
            r.into_iter().map(|(t, speed)| Aid::Odometer { t, speed }),
        )
    }

    /// Pushes a dual-antenna reading at time `t` [s]: the baseline's heading from true
    /// north, clockwise, and its standard deviation [deg], optionally its pitch and
    /// standard deviation [deg] (both or neither), checked as a line of
    /// `--dual-antenna`'s file.
    #[pyo3(signature = (t, heading_deg, heading_std_deg, pitch_deg=None, pitch_std_deg=None))]
    fn push_heading(
        &mut self,
        py: Python<'_>,
        t: f64,
        heading_deg: f64,
        heading_std_deg: f64,
        pitch_deg: Option<f64>,
        pitch_std_deg: Option<f64>,
    ) -> PyResult<()> {
        let mut row = vec![t, heading_deg, heading_std_deg];
        match (pitch_deg, pitch_std_deg) {
            (Some(p), Some(s)) => row.extend([p, s]),
            (None, None) => {}
            _ => {
                return Err(SchulerError::new_err(
                    "push_heading: pitch_deg and pitch_std_deg go together",
                ));
            }
        }
        let r = vehicle::headings(&one_row(&row).views(), Source::Push).py_err(py)?;
        self.push_aids(py, r.into_iter().map(Aid::Heading))
    }

    /// The tables produced since the last `take` (dict of dicts of numpy arrays).
    fn take<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (_, tables) = self.open().py_err(py)?;
        tables.take_dict(py)
    }

    /// Ends the session: the remaining tables, `smoothed` (when asked) and `summary`.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (session, mut tables) = self
            .open
            .take()
            .ok_or_else(|| SchulerError::new_err("the session is finished"))?;
        let (finished, smoothed) = py.detach(|| session.finish(&mut tables)).py_err(py)?;
        let d = tables.take_dict(py)?;
        add_finished(py, &d, &finished, smoothed.as_deref())?;
        Ok(d)
    }
}

impl PySession {
    fn push_aid(&mut self, py: Python<'_>, aid: Aid) -> PyResult<()> {
        self.push_aids(py, std::iter::once(aid))
    }

    fn push_aids(&mut self, py: Python<'_>, aids: impl Iterator<Item = Aid>) -> PyResult<()> {
        let (session, tables) = self.open().py_err(py)?;
        for aid in aids {
            session.push(aid).py_err(py)?;
        }
        session.take(tables);
        Ok(())
    }
}

/// One row of values as one-element columns.
struct OneRow(Vec<numpy::ndarray::Array1<f64>>);

impl OneRow {
    fn views(&self) -> Vec<numpy::ndarray::ArrayView1<'_, f64>> {
        self.0.iter().map(|c| c.view()).collect()
    }
}

/// `values` as a table of one row.
fn one_row(values: &[f64]) -> OneRow {
    OneRow(values.iter().map(|&x| numpy::ndarray::arr1(&[x])).collect())
}

/// Adds `smoothed` (or None) and `summary` of a finished session to `d`.
pub fn add_finished(
    py: Python<'_>,
    d: &Bound<'_, PyDict>,
    f: &Finished,
    smoothed: Option<&[Smoothed]>,
) -> PyResult<()> {
    match smoothed {
        Some(s) => d.set_item("smoothed", smoothed_columns(s).take_dict(py)?)?,
        None => d.set_item("smoothed", py.None())?,
    }
    d.set_item("summary", summary_dict(py, f)?)
}
