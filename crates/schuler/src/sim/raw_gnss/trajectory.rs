//! A scenario's raw GNSS run: the antenna on the scenario's trajectory (the IMU's
//! position plus the lever arm, `r^e + C_en C_bn l`, and its velocity
//! `C_en (v_n + C_bn (ω_eb^b × l))`, as [`crate::sim::receivers`] models the fixes),
//! epochs on whole multiples of the interval inside the trajectory, and the
//! nominal constellation's ephemerides for the run's span.

use nalgebra::Vector3;

use super::constellation::{NOMINAL_KLOBUCHAR, nominal_gps};
use super::spec::{NavData, RawGnssSpec};
use super::{Antenna, RawGnssModel, RawGnssSimulator, RawSimEpoch};
use crate::earth::{EarthModel, Wgs84, c_ne};
use crate::gnss::GpsTime;
use crate::sim::analytic;
use crate::sim::run::{EarthSpec, ScenarioSpec};
use crate::sim::scenario::ScenarioError;
use crate::sim::spline::SplineTrajectory;

/// The antenna on a scenario's trajectory.
#[derive(Debug)]
pub struct ScenarioAntenna {
    traj: SplineTrajectory,
    lever_arm: Vector3<f64>,
}

impl ScenarioAntenna {
    /// The antenna at `lever_arm` (body axes [m]) on `traj`.
    pub fn new(traj: SplineTrajectory, lever_arm: Vector3<f64>) -> Self {
        Self { traj, lever_arm }
    }

    /// The trajectory's span [s].
    pub fn span(&self) -> (f64, f64) {
        (self.traj.start(), self.traj.end())
    }
}

impl Antenna for ScenarioAntenna {
    fn at(&self, t: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
        if !(self.traj.start()..=self.traj.end()).contains(&t) {
            return None;
        }
        let (s, kin) = analytic::evaluate(&Wgs84, &self.traj, t);
        let c_bn = s.q_bn.to_rotation_matrix().into_inner();
        let c_en = c_ne(s.pos.lat, s.pos.lon);
        let w_eb_b = kin.w_ib_b - s.q_bn.inverse() * Wgs84.w_ie_n(s.pos.lat);
        let r = Wgs84.geodetic_to_ecef(&s.pos) + c_en * (c_bn * self.lever_arm);
        let v = c_en * (s.v_n + c_bn * w_eb_b.cross(&self.lever_arm));
        Some((r, v))
    }
}

/// The nominal constellation's ephemerides and ionosphere for `model`'s week over
/// scenario times `span` [s].
pub fn nominal_data(model: &RawGnssModel, span: (f64, f64)) -> NavData {
    let from = GpsTime::new(model.week, span.0);
    let to = GpsTime::new(model.week, span.1);
    NavData {
        store: nominal_gps(model.week, from, to),
        klobuchar: Some(NOMINAL_KLOBUCHAR),
        file: None,
    }
}

/// The `[gnss.raw]` block of `spec`, its model, and the antenna on its trajectory;
/// errors name the key.
pub fn prepare(
    spec: &ScenarioSpec,
) -> Result<(&RawGnssSpec, RawGnssModel, ScenarioAntenna), ScenarioError> {
    let gnss = spec.gnss.as_ref();
    let raw = gnss
        .and_then(|g| g.raw.as_ref())
        .ok_or_else(|| ScenarioError::Value {
            key: "gnss.raw".into(),
            message: "missing".into(),
        })?;
    if spec.earth != EarthSpec::Wgs84 {
        return Err(ScenarioError::Value {
            key: "gnss.raw".into(),
            message: "raw observations need earth = \"wgs84\" (the orbits are WGS84's)".into(),
        });
    }
    let model = raw.model()?;
    let lever_arm = gnss
        .map(|g| g.model())
        .transpose()?
        .map_or_else(Vector3::zeros, |m| m.lever_arm);
    let (traj, _) = spec.trajectory(Wgs84)?;
    Ok((raw, model, ScenarioAntenna::new(traj, lever_arm)))
}

/// The raw epochs of `spec` with `data` (its `[gnss.raw]` navigation data): one per
/// interval of receiver time from the first whole multiple of the interval after the
/// trajectory's start, while the antenna's true time lies in the trajectory.
pub fn simulate_raw(
    spec: &ScenarioSpec,
    data: &NavData,
) -> Result<Vec<RawSimEpoch>, ScenarioError> {
    let (_, model, antenna) = prepare(spec)?;
    let (t0, t1) = antenna.span();
    let dt = model.interval;
    let mut sim = RawGnssSimulator::new(model, data.store.clone(), data.klobuchar, spec.seed);
    let first = (t0 / dt).ceil() as i64;
    let last = (t1 / dt).floor() as i64;
    let mut out = Vec::with_capacity(usize::try_from(last - first + 1).unwrap_or(0));
    for k in first..=last {
        if let Some(e) = sim.epoch(k as f64 * dt, &antenna) {
            out.push(e);
        }
    }
    Ok(out)
}
