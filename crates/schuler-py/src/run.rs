//! A navigation run as `schuler nav` sets it up ([`schuler_run::nav`]):
//! the options parsed and checked, the aiding resolved, the library's
//! [`schuler::session::Session`] opened on the chosen Earth model; what comes out is
//! collected into tables instead of files, with the CLI's conversions, so the numbers
//! are those `nav.txt`, `std.txt`, `imu_err.txt`, `innovations.csv` and
//! `rejected.csv` print.

use crate::columns::{Columns, INNOVATIONS, NAV, SENSOR, STD};
use anyhow::Result;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler::earth::EarthModel;
use schuler::earth::{Sphere, Wgs84, Wgs84Series};
use schuler::filter::smoother::Smoothed;
use schuler::imu::ImuSample;
use schuler::session::Start;
use schuler::session::{Epoch, Event, Finished, Session};
use schuler_io::formats::InputError;
use schuler_io::output::nav_fields;
use schuler_run::aided::record::InnovationRow;
use schuler_run::aided::{Aiding, GivenReadings};
use schuler_run::alignment::AlignOptions;
use schuler_run::drive::{Refusal, imu_err_row, std_row};
use schuler_run::nav::{
    BANK_MEMBERS, BANK_SECONDS, Began, InitChoice, begin, plan_of, resolve_aiding,
};
use schuler_run::navigate::{NavSettings, decide_heading, open_session};
use schuler_run::options::EarthChoice;

/// The settings and aiding of a run, from its keyword arguments.
pub struct Plan {
    /// Settings (the IMU path among them, unused for arrays).
    pub settings: NavSettings,
    /// The filter and the aids, if any aiding is given.
    pub aiding: Option<Aiding>,
    /// The alignment options with `--align`.
    pub align: Option<AlignOptions>,
    /// How the run starts (`--init`).
    pub init: InitChoice,
}

impl Plan {
    /// The plan of `options` with `given` readings in place of `gnss`/`baro` files.
    pub fn new(options: toml::Table, given: GivenReadings) -> Result<Self> {
        let plan = plan_of(crate::options::nav_description(options)?)?;
        let aiding = resolve_aiding(&plan.alignment, &plan.aiding, given)?;
        Ok(Self {
            settings: plan.settings,
            aiding,
            align: plan.align.then_some(plan.alignment),
            init: plan.init,
        })
    }

    /// The start as `schuler nav` makes it (given, aligned at rest on the first
    /// samples, or in motion from the fixes), the samples it read past the start
    /// (its carrier first), and how it began; the filter's prior follows the start.
    pub fn begin<I>(&mut self, samples: &mut I) -> Result<(Start, Vec<ImuSample>, Began)>
    where
        I: Iterator<Item = Result<ImuSample, InputError>>,
    {
        let (s, aiding) = (&self.settings, self.aiding.as_mut());
        begin(s, self.align.as_ref(), self.init, samples, aiding)
    }
}

/// A session on the Earth model the options chose.
pub enum AnySession {
    /// WGS84.
    Wgs84(Session<Wgs84>),
    /// WGS84 with KF-GINS's gravity series (`gravity="kf-gins"`).
    Wgs84Series(Session<Wgs84Series>),
    /// The textbook sphere, rotating or not.
    Sphere(Session<Sphere>),
}

/// `$body` with `$s` bound to the session whatever its Earth model.
macro_rules! each {
    ($session:expr, $s:ident => $body:expr) => {
        match $session {
            AnySession::Wgs84($s) => $body,
            AnySession::Wgs84Series($s) => $body,
            AnySession::Sphere($s) => $body,
        }
    };
}

impl AnySession {
    /// The session of `plan` from `start`, aids pushed; with `--init
    /// gnss-any-heading` the heading bank's choice after it ran on as many of
    /// `samples` as it needed (its events so far go into `tables`).
    pub fn open<I>(plan: &Plan, start: Start, samples: &mut I, tables: &mut Tables) -> Result<Self>
    where
        I: Iterator<Item = Result<ImuSample, InputError>>,
    {
        let (p, s, t) = (plan, start, samples);
        Ok(match plan.settings.earth {
            EarthChoice::Wgs84 => Self::Wgs84(open_on(Wgs84, p, s, t, tables)?),
            EarthChoice::Wgs84Series => Self::Wgs84Series(open_on(Wgs84Series, p, s, t, tables)?),
            EarthChoice::Sphere => Self::Sphere(open_on(Sphere::textbook(true), p, s, t, tables)?),
            EarthChoice::SphereFixed => {
                Self::Sphere(open_on(Sphere::textbook(false), p, s, t, tables)?)
            }
        })
    }

    /// Pushes one IMU sample.
    pub fn push_imu(&mut self, s: ImuSample) -> Result<()> {
        Ok(each!(self, x => x.push_imu(s))?)
    }

    /// Pushes one aid.
    pub fn push(&mut self, aid: schuler::session::Aid) -> Result<()> {
        Ok(each!(self, x => x.push(aid))?)
    }

    /// Moves the epochs and events so far into `tables`.
    pub fn take(&mut self, tables: &mut Tables) {
        each!(self, x => {
            for e in x.epochs() {
                tables.epoch(&e);
            }
            for e in x.events() {
                tables.event(e);
            }
        })
    }

    /// Ends the input and the session; the epochs and events it still held go to
    /// `tables`, the smoothed trajectory (when asked) is read into memory.
    pub fn finish(mut self, tables: &mut Tables) -> Result<(Finished, Option<Vec<Smoothed>>)> {
        each!(&mut self, x => x.end_of_input());
        self.take(tables);
        each!(self, x => {
            let earth = x.earth();
            let mut finished = x.finish()?;
            let smoothed = finished.smoothed.take().map(|s| s.collect_states(earth));
            Ok((finished, smoothed.transpose()?))
        })
    }
}

/// The session of [`AnySession::open`] on `earth`.
fn open_on<E: EarthModel, I>(
    earth: E,
    plan: &Plan,
    start: Start,
    samples: &mut I,
    tables: &mut Tables,
) -> Result<Session<E>>
where
    I: Iterator<Item = Result<ImuSample, InputError>>,
{
    let (s, a) = (&plan.settings, plan.aiding.as_ref());
    match a.filter(|_| plan.init == InitChoice::GnssAnyHeading) {
        Some(a) => {
            let bank = (BANK_MEMBERS, BANK_SECONDS);
            let (chosen, _) = decide_heading(earth, s, a, start, bank, samples)?;
            for e in chosen.events {
                tables.event(e);
            }
            Ok(chosen.session)
        }
        None => open_session(earth, s, a, start),
    }
}

/// What a run gives, table by table.
pub struct Tables {
    /// The navigation result at the output epochs.
    pub trajectory: Columns,
    /// The filter's standard deviations at the output epochs.
    pub std: Columns,
    /// The filter's sensor-error estimates at the output epochs.
    pub sensor_errors: Columns,
    /// Every tested measurement (numbers).
    pub innovations: Columns,
    /// The measurement kind of each innovation.
    pub innovation_kinds: Vec<String>,
    /// Measurements not used, with why.
    pub refused: Vec<Refusal>,
    /// Warnings (the solution leaving the physical envelope).
    pub warnings: Vec<String>,
}

impl Default for Tables {
    fn default() -> Self {
        Self {
            trajectory: Columns::new(NAV),
            std: Columns::new(STD),
            sensor_errors: Columns::new(SENSOR),
            innovations: Columns::new(INNOVATIONS),
            innovation_kinds: Vec::new(),
            refused: Vec::new(),
            warnings: Vec::new(),
        }
    }
}

impl Tables {
    /// One output epoch, in `nav.txt`'s, `std.txt`'s and `imu_err.txt`'s units.
    fn epoch(&mut self, e: &Epoch) {
        let t = e.state.t;
        self.trajectory.push(t, &nav_fields(&e.state));
        if let Some(f) = &e.filter {
            self.std.push(t, &std_row(f));
            self.sensor_errors.push(t, &imu_err_row(&f.estimates));
        }
    }

    /// One event: an innovation, a refusal, or a warning.
    fn event(&mut self, e: Event) {
        if let Event::Envelope { t, what } = &e {
            self.warnings.push(format!(
                "at t = {t} s the solution left the physical envelope: {what}"
            ));
        }
        if let Event::Measurement(i) = &e {
            if let Ok(r) = InnovationRow::of(i) {
                let unused = |k: usize, x: f64| if k < r.dof { x } else { f64::NAN };
                let z: Vec<f64> = (0..3).map(|k| unused(k, r.z[k])).collect();
                let s: Vec<f64> = (0..3).map(|k| unused(k, r.sigma[k])).collect();
                let head = [f64::from(u8::from(r.accepted)), r.dof as f64, r.nis];
                self.innovations.push(r.t, &[&head[..], &z, &s].concat());
                self.innovation_kinds.push(r.kind.to_string());
            }
            return;
        }
        if let Some(r) = Refusal::of(&e) {
            self.refused.push(r);
        }
    }

    /// The tables so far as a dict of dicts of numpy arrays (`trajectory`, `std`,
    /// `sensor_errors`, `innovations` with `kind`, `refused`, `warnings`), leaving them
    /// empty.
    pub fn take_dict<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("trajectory", self.trajectory.take_dict(py)?)?;
        d.set_item("std", self.std.take_dict(py)?)?;
        d.set_item("sensor_errors", self.sensor_errors.take_dict(py)?)?;
        let inn = self.innovations.take_dict(py)?;
        inn.set_item("kind", std::mem::take(&mut self.innovation_kinds))?;
        d.set_item("innovations", inn)?;
        let mut refused = std::mem::take(&mut self.refused);
        refused.sort_by(|a, b| a.t.total_cmp(&b.t));
        let r = PyDict::new(py);
        let nan = |x: Option<f64>| x.unwrap_or(f64::NAN);
        r.set_item("t_s", refused.iter().map(|x| x.t).collect::<Vec<_>>())?;
        r.set_item(
            "measurement",
            refused
                .iter()
                .map(|x| x.measurement.clone())
                .collect::<Vec<_>>(),
        )?;
        r.set_item(
            "reason",
            refused.iter().map(|x| x.reason.clone()).collect::<Vec<_>>(),
        )?;
        r.set_item(
            "nis",
            refused.iter().map(|x| nan(x.nis)).collect::<Vec<_>>(),
        )?;
        r.set_item(
            "threshold",
            refused.iter().map(|x| nan(x.threshold)).collect::<Vec<_>>(),
        )?;
        d.set_item("refused", r)?;
        d.set_item("warnings", std::mem::take(&mut self.warnings))?;
        Ok(d)
    }
}

/// Runs `plan` on `samples` as `schuler nav` does: the start (given, aligned, in
/// motion, or through the heading bank), then every sample pushed, what comes out
/// collected into `tables`; the finished session, its smoothed trajectory (when
/// asked) and how it began.
pub fn run<I>(
    plan: &mut Plan,
    tables: &mut Tables,
    samples: I,
) -> Result<(Finished, Option<Vec<Smoothed>>, Began)>
where
    I: Iterator<Item = Result<ImuSample, InputError>>,
{
    let mut samples = samples.peekable();
    if samples.peek().is_none() {
        anyhow::bail!(
            "{}: no IMU sample in the requested time window",
            plan.settings.imu.display()
        );
    }
    let (start, head, began) = plan.begin(&mut samples)?;
    let mut all = head.into_iter().map(Ok).chain(samples);
    let mut session = AnySession::open(plan, start, &mut all, tables)?;
    drive(&mut session, tables, all)?;
    let (finished, smoothed) = session.finish(tables)?;
    Ok((finished, smoothed, began))
}

/// Pushes `samples` into `session`, collecting what comes out into `tables` after
/// each; returns the count pushed. A read error or a refused sample stops the run.
pub fn drive(
    session: &mut AnySession,
    tables: &mut Tables,
    samples: impl Iterator<Item = Result<ImuSample, InputError>>,
) -> Result<u64> {
    let mut n = 0;
    for s in samples {
        session.push_imu(s?)?;
        session.take(tables);
        n += 1;
    }
    Ok(n)
}

/// The smoothed trajectory: `nav.txt`'s columns, then the position, velocity and
/// attitude standard deviations of `std.txt`.
pub fn smoothed_columns(smoothed: &[Smoothed]) -> Columns {
    // nav.txt's columns, then std.txt's of position, velocity and attitude.
    let mut c = Columns::joined(&[NAV, &STD[1..10]]);
    for s in smoothed {
        let mut row = nav_fields(&s.state).to_vec();
        row.extend(s.std[0].iter().chain(s.std[1].iter()));
        row.extend(s.std[2].iter().map(|x| x.to_degrees()));
        c.push(s.state.t, &row);
    }
    c
}

/// The session's summary as a dict: samples, time span, measurement counts, mean NIS
/// per degree of freedom, hand-overs.
pub fn summary_dict<'py>(py: Python<'py>, f: &Finished) -> PyResult<Bound<'py, PyDict>> {
    let s = &f.summary;
    let d = PyDict::new(py);
    d.set_item("samples", s.samples)?;
    d.set_item("t_first_s", s.t_first)?;
    d.set_item("t_last_s", s.t_last)?;
    d.set_item("first_mechanization", s.first_mechanization.to_string())?;
    let c = &s.counts;
    let counts = PyDict::new(py);
    for (k, v) in [
        ("gnss_position", c.position),
        ("gnss_velocity", c.velocity),
        ("baro_height", c.baro),
        ("zero_velocity", c.zupt),
        ("zero_rate", c.zaru),
        ("non_holonomic", c.nhc),
        ("odometer", c.odometer),
        ("heading", c.heading),
        ("rejected", c.rejected),
        ("skipped", c.skipped),
    ] {
        counts.set_item(k, v)?;
    }
    d.set_item("counts", counts)?;
    d.set_item("late", s.late)?;
    d.set_item("gate_resets", s.gate_resets)?;
    d.set_item("mean_nis_per_dof", s.mean_nis_per_dof)?;
    let h: Vec<(f64, f64, String)> = s
        .handovers
        .iter()
        .map(|h| (h.t, h.lat.to_degrees(), h.to.to_string()))
        .collect();
    d.set_item("handovers", h)?;
    d.set_item("calibration", calibration_dict(py, f)?)?;
    Ok(d)
}

/// The self-calibration (`estimate_lever_arm`, `estimate_gnss_time_offset`): at the
/// end, each estimate, its standard deviation and whether the motion observed it;
/// and its history at the snapshots (once a second). The time offset is the
/// estimate on top of `gnss_time_offset` (added to the GNSS times as they are read).
/// Empty without calibration.
fn calibration_dict<'py>(py: Python<'py>, f: &Finished) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let c = &f.summary.calibration;
    let history = PyDict::new(py);
    let t: Vec<f64> = f.snapshots.iter().map(|s| s.t).collect();
    if let Some(l) = &c.lever_arm {
        d.set_item("lever_arm_m", l.value.as_slice().to_vec())?;
        d.set_item("lever_arm_std_m", l.std.as_slice().to_vec())?;
        d.set_item("lever_arm_observed", l.observed().to_vec())?;
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            let pick = |std: bool| -> Vec<f64> {
                f.snapshots
                    .iter()
                    .map(|s| {
                        s.calibration
                            .lever_arm
                            .map_or(f64::NAN, |e| if std { e.std[k] } else { e.value[k] })
                    })
                    .collect()
            };
            history.set_item(format!("lever_arm_{axis}_m"), pick(false))?;
            history.set_item(format!("lever_arm_{axis}_std_m"), pick(true))?;
        }
    }
    if let Some(o) = &c.time_offset {
        d.set_item("gnss_time_offset_s", o.value)?;
        d.set_item("gnss_time_offset_std_s", o.std)?;
        d.set_item("gnss_time_offset_observed", o.observed())?;
        let pick = |std: bool| -> Vec<f64> {
            f.snapshots
                .iter()
                .map(|s| {
                    s.calibration
                        .time_offset
                        .map_or(f64::NAN, |e| if std { e.std } else { e.value })
                })
                .collect()
        };
        history.set_item("gnss_time_offset_s", pick(false))?;
        history.set_item("gnss_time_offset_std_s", pick(true))?;
    }
    if !d.is_empty() {
        history.set_item("t_s", t)?;
        d.set_item("history", history)?;
    }
    Ok(d)
}
