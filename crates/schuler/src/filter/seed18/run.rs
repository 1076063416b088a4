//! The loosely coupled INS/GNSS filter on the 18 states: the wander mechanization,
//! the additive covariance, GNSS fixes at their own times, gating and feedback with
//! renormalisation ([module doc](super)).

use super::measure::{self, Measurement3};
use super::model::{self, ACCEL, GYRO, HEIGHT, Mat18, N, NAV_Q, ORI_Q, Point, VEL};
use crate::earth::EarthModel;
use crate::filter::gate_book::GateBook;
use crate::filter::integration::{
    FixConsumer, FixSource, GnssFix, GnssUpdate, IntegrationConfig, SensorEstimates, SkipReason,
    Timed, step_with_fixes,
};
use crate::filter::interval::Interval;
use crate::filter::kalman::Kalman;
use crate::filter::measurement::Kind;
use crate::imu::ImuSample;
use crate::nav::{Mechanization, NavState, Wander, WanderState};
use nalgebra::{DMatrix, DVector, Matrix3, Quaternion, SMatrix, UnitQuaternion, Vector3, Vector4};

/// Why the 18-state filter cannot run a configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Unsupported {
    /// The paper's measurements are of the navigation point itself.
    #[error(
        "the 18-state model has no lever arm (the paper's z_k and z_V are of the INS itself); use psi15 or psi21"
    )]
    LeverArm,
    /// No scale-factor states.
    #[error("the 18-state model has no scale-factor states; use psi21")]
    ScaleFactors,
    /// No barometer bias state.
    #[error("the 18-state model has no barometer bias state; use psi15 or psi21")]
    Barometer,
}

/// Whether the 18-state filter runs with these settings.
pub fn check(cfg: &IntegrationConfig) -> Result<(), Unsupported> {
    if cfg.lever_arm != Vector3::zeros() {
        return Err(Unsupported::LeverArm);
    }
    if cfg.scale_factors {
        return Err(Unsupported::ScaleFactors);
    }
    if cfg.baro.is_some() {
        return Err(Unsupported::Barometer);
    }
    Ok(())
}

/// The wander mechanization under the paper's 18-state filter.
#[derive(Debug, Clone)]
pub struct Seed18<E: EarthModel> {
    mech: Wander<E>,
    cfg: IntegrationConfig,
    kf: Kalman,
    /// The inertial frame is the ECEF frame at this time [s].
    t_ref: f64,
    /// The point at the start of the current propagation interval.
    start: Point,
    interval: Interval,
    estimates: SensorEstimates,
    /// The measurements tested, refused and skipped, the counts and gate resets
    /// (the same gate and reset rule as [`crate::filter::Integrator`]'s).
    pub book: GateBook,
    /// Fixes not used because they fell within [`measure::POLE_COS_LAT`] of a pole.
    pub polar_skips: u64,
}

fn dyn18(m: &Mat18) -> DMatrix<f64> {
    DMatrix::from_column_slice(N, N, m.as_slice())
}

impl<E: EarthModel> Seed18<E> {
    /// Start from a wander mechanization at its initial state, with `cfg`'s prior
    /// (position, velocity, attitude standard deviations in NED; sensor errors from
    /// the noise model or `init_sensor_std`). Refuses settings the model does not
    /// have ([`check`]).
    pub fn new(mech: Wander<E>, cfg: IntegrationConfig) -> Result<Self, Unsupported> {
        check(&cfg)?;
        let t_ref = mech.wander_state().t;
        let start = Point::of(&mech, t_ref);
        let sq = |v: &Vector3<f64>| v.component_mul(v);
        let nz = &cfg.noise;
        let (bg, ba) = match cfg.init_sensor_std {
            Some(sd) => (sd[0], sd[1]),
            None => (nz.gyro_bias, nz.accel_bias),
        };
        let mut d = SMatrix::<f64, 15, 1>::zeros();
        for (o, v) in [
            (0, cfg.init_pos_std),
            (3, cfg.init_vel_std),
            (6, cfg.init_att_std),
            (9, bg),
            (12, ba),
        ] {
            d.fixed_view_mut::<3, 1>(o, 0).copy_from(&sq(&v));
        }
        let a = start.from_physical();
        let p = a * SMatrix::<f64, 15, 15>::from_diagonal(&d) * a.transpose();
        Ok(Self {
            mech,
            cfg,
            kf: Kalman::new(dyn18(&p)),
            t_ref,
            start,
            interval: Interval::default(),
            estimates: SensorEstimates::default(),
            book: GateBook::default(),
            polar_skips: 0,
        })
    }

    /// Replace the prior of attitude error (about north, east, down), gyro and
    /// accelerometer biases by their joint covariance `p` (an alignment's).
    pub fn with_attitude_bias_covariance(mut self, p: &SMatrix<f64, 9, 9>) -> Self {
        let a = self.start.from_physical();
        let mut phys = SMatrix::<f64, 15, 15>::zeros();
        // Keep position and velocity as they are: recover them from the current P.
        let g = self.physical_map();
        let cur = g * self.covariance18() * g.transpose();
        phys.fixed_view_mut::<6, 6>(0, 0)
            .copy_from(&cur.fixed_view::<6, 6>(0, 0));
        phys.fixed_view_mut::<9, 9>(6, 6).copy_from(p);
        let p18 = a * phys * a.transpose();
        self.kf.p = dyn18(&p18);
        self
    }

    /// Start from sensor-error estimates other than zero (the compensation applied
    /// before the residual drifts and biases the states carry).
    pub fn with_estimates(mut self, estimates: SensorEstimates) -> Self {
        self.estimates = estimates;
        self
    }

    fn covariance18(&self) -> Mat18 {
        Mat18::from_column_slice(self.kf.p.as_slice())
    }

    fn physical_map(&self) -> SMatrix<f64, 9, N> {
        // T is the curvature map of an Earth model: never singular.
        self.start.physical().unwrap_or_else(SMatrix::zeros)
    }

    /// Prime the two-sample corrections with the sample that ends at the start.
    pub fn prime(&mut self, s: &ImuSample) {
        self.mech.prime(&self.estimates.compensate(s));
    }

    /// Mechanize one sample (no measurement inside it).
    pub fn step(&mut self, raw: &ImuSample) {
        let s = self.estimates.compensate(raw);
        let q_bw = self.mech.wander_state().q_bw;
        self.mech.step(&s);
        self.interval.add(&s, &q_bw);
        if self.interval.t >= self.cfg.propagation_interval {
            self.propagate();
        }
    }

    /// Propagate the covariance over the accumulated interval and project it on the
    /// quaternions' unit-norm tangent.
    pub fn propagate(&mut self) {
        if self.interval.t <= 0.0 {
            return;
        }
        let end = Point::of(&self.mech, self.t_ref);
        let dt = self.interval.t;
        let f_w = self.interval.f_c_dt / dt;
        let (phi, qd) = model::transition(&self.start, &end, &f_w, dt, &self.cfg.noise);
        let pi = end.norm_projector();
        let p = pi * (phi * self.covariance18() * phi.transpose() + qd) * pi.transpose();
        self.kf.p = dyn18(&((p + p.transpose()) * 0.5));
        self.start = end;
        self.interval = Interval::default();
    }

    /// Mechanize a sample during which GNSS fixes may fall (applied at their times).
    pub fn step_with_fixes<T, F: FixSource<T>>(&mut self, raw: &ImuSample, fixes: &mut F)
    where
        Self: FixConsumer<T>,
    {
        step_with_fixes(self, raw, fixes);
    }

    /// Apply a GNSS fix now: `z_k`, then `z_V` if the fix has a velocity.
    pub fn update_gnss(&mut self, fix: &GnssFix) {
        self.propagate();
        let Some(m) = measure::position(&self.start, &fix.pos, &fix.pos_std) else {
            self.polar_skips += 1;
            return;
        };
        self.apply(fix.t, Kind::GnssPosition, m);
        if let Some((v, std)) = fix.vel
            && let Some(m) = measure::velocity(&self.start, &v, &std)
        {
            self.apply(fix.t, Kind::GnssVelocity, m);
        }
    }

    /// Gate a measurement, record it in [`Seed18::book`] and, if accepted, update
    /// and feed back.
    pub fn apply(&mut self, t: f64, kind: Kind, m: Measurement3) -> bool {
        let (gate, reset) = self.book.gate(&self.cfg, kind, 3);
        let z = DVector::from_column_slice(m.z.as_slice());
        let h = DMatrix::from_column_slice(3, N, m.h.as_slice());
        let r = DMatrix::from_column_slice(3, 3, m.r.as_slice());
        let outcome = self.kf.update(&z, &h, &r, gate);
        let Some(u) = self.book.record(t, kind, None, z, reset, outcome) else {
            return false;
        };
        self.feed_back(&u.dx);
        true
    }

    /// Closed-loop feedback: `p ← (p̂ − δp)/|·|`, `q0 ← (q̂0 − δq0)/|·|`,
    /// `V ← V̂ − δV`, `h ← ĥ − δh`, biases added to the compensation; the attitude
    /// `q_bw = p* ⊗ q_ei* ⊗ q0`; the covariance projected on the new tangent.
    fn feed_back(&mut self, dx: &DVector<f64>) {
        let v4 = |o: usize| Vector4::new(dx[o], dx[o + 1], dx[o + 2], dx[o + 3]);
        let v3 = |o: usize| Vector3::new(dx[o], dx[o + 1], dx[o + 2]);
        let unit = |q: Vector4<f64>| {
            UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3]))
        };
        let s = *self.mech.wander_state();
        let q_we = unit(self.start.p - v4(NAV_Q));
        let q0 = unit(self.start.q0 - v4(ORI_Q));
        let omega = self.mech.earth().rotation_rate();
        let q_ei = model::earth_to_inertial(omega, s.t, self.t_ref);
        let state = WanderState {
            t: s.t,
            q_we,
            h: s.h - dx[HEIGHT],
            v_w: s.v_w - v3(VEL),
            q_bw: q_we.inverse() * q_ei.inverse() * q0,
        };
        self.mech = Wander::from_wander_state(*self.mech.earth(), state)
            .with_corrections(self.mech.corrections())
            .with_history(self.mech.history())
            .with_pole_longitude(self.mech.pole_longitude());
        self.estimates.gyro_bias += v3(GYRO);
        self.estimates.accel_bias += v3(ACCEL);
        self.start = Point::of(&self.mech, self.t_ref);
        let pi = self.start.norm_projector();
        let p = pi * self.covariance18() * pi.transpose();
        self.kf.p = dyn18(&((p + p.transpose()) * 0.5));
    }

    /// The mechanization.
    pub fn mechanization(&self) -> &Wander<E> {
        &self.mech
    }

    /// The state now.
    pub fn state(&self) -> NavState {
        self.mech.state()
    }

    /// Estimated sensor errors.
    pub fn estimates(&self) -> SensorEstimates {
        self.estimates
    }

    /// The 18 × 18 covariance of the additive state (as of the last propagation or
    /// update).
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.kf.p
    }

    /// The point of linearisation of the last propagation or update.
    pub fn point(&self) -> &Point {
        &self.start
    }

    /// Covariance of the physical errors `[position NED, velocity NED, ψ NED]`,
    /// `G P Gᵀ` ([`Point::physical`]), the same quantities as the psi-angle filter's.
    pub fn physical_covariance(&self) -> SMatrix<f64, 9, 9> {
        let g = self.physical_map();
        g * self.covariance18() * g.transpose()
    }

    /// The three 3 × 3 blocks of [`Seed18::physical_covariance`].
    pub fn nav_covariance(&self) -> [Matrix3<f64>; 3] {
        let p = self.physical_covariance();
        [0, 3, 6].map(|o| p.fixed_view::<3, 3>(o, o).into_owned())
    }

    /// Standard deviations of position and velocity (NED) and attitude error.
    pub fn nav_std(&self) -> [Vector3<f64>; 3] {
        self.nav_covariance()
            .map(|p| p.diagonal().map(|v| v.max(0.0).sqrt()))
    }

    /// Record a fix that could not be used.
    pub fn skip(&mut self, t: f64, reason: SkipReason) {
        self.book.skip(t, Kind::GnssPosition, reason);
    }

    /// Standard deviations of the gyro drifts and accelerometer biases.
    pub fn sensor_std(&self) -> [Vector3<f64>; 2] {
        [GYRO, ACCEL].map(|o| crate::filter::kalman::std3(&self.kf.p, o))
    }
}

impl<E: EarthModel> FixConsumer for Seed18<E> {
    fn now(&self) -> f64 {
        self.mech.wander_state().t
    }
    fn step_sample(&mut self, s: &ImuSample) {
        self.step(s);
    }
    fn apply_fix(&mut self, f: &GnssFix) {
        self.update_gnss(f);
    }
    fn skip_fix(&mut self, f: &GnssFix, reason: SkipReason) {
        self.skip(f.t, reason);
    }
}

/// The 18-state model takes fixes only: [`crate::session::SessionConfig::validate`]
/// refuses tight coupling with it, and a range epoch that reaches it all the same is
/// recorded as skipped, never applied.
impl<E: EarthModel> FixConsumer<GnssUpdate> for Seed18<E> {
    fn now(&self) -> f64 {
        self.mech.wander_state().t
    }
    fn step_sample(&mut self, s: &ImuSample) {
        self.step(s);
    }
    fn apply_fix(&mut self, u: &GnssUpdate) {
        match u {
            GnssUpdate::Fix(f) => self.update_gnss(f),
            GnssUpdate::Ranges(e) => self.skip(e.t, SkipReason::NotModelled),
        }
    }
    fn skip_fix(&mut self, u: &GnssUpdate, reason: SkipReason) {
        self.skip(u.time(), reason);
    }
}
