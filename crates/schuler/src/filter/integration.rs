//! Loosely coupled INS/GNSS integration: the mechanization, its error-state filter
//! with closed-loop feedback, GNSS measurements at their own times, gating and the
//! record of every rejection.
//!
//! Each IMU sample is compensated with the sensor errors estimated so far
//! (`dθ' = (dθ − b_g dt) ⊙ (1 − s_g)`, the same for `dv`), mechanized, and summed into
//! the current propagation interval; the covariance is propagated when the interval
//! reaches [`IntegrationConfig::propagation_interval`] and before every update. A GNSS
//! fix that falls inside a sample's interval splits the sample there (increments
//! divided in proportion to time, the constant-rate assumption over one sample), so
//! the update happens at the fix's own time.
//!
//! Vehicle measurements ([`super::vehicle`]) apply at the instant the caller calls
//! them, after a sample: zero velocity and rate and the non-holonomic constraint hold
//! at any instant of a rest or a drive, so the sample's end is their time; an odometer
//! or heading reading is applied at the sample ending nearest its time (at most half
//! a sample away: at 200 Hz, 2.5 ms, or 2.5 mm/s of speed at 1 m/s² — the heading is
//! carried over the offset with the body rate).

use super::calibration::{self, AntennaMotion, Calibration, CalibrationState, Estimate};
use super::error_model::ErrorModel;
use super::gate_book::GateBook;
use super::interval::Interval;
use super::kalman::{Gate, Kalman, Rejection};
use super::layout::Layout;
use super::measurement::{self, Kind, Measurement};
use super::noise::ImuNoise;
use super::ranging::{self, Tight, TightConfig};
use super::vehicle::{self, Baseline, HeadingReading, VehicleMount};
use crate::earth::{EarthModel, Geodetic};
use crate::gnss::RangeEpoch;
use crate::imu::ImuSample;
use crate::nav::{ErrorFrame, NavErrors, NavState};
use nalgebra::{DMatrix, DVector, Matrix3, SMatrix, Vector3};

/// One GNSS epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssFix {
    /// Time [s].
    pub t: f64,
    /// Antenna position.
    pub pos: Geodetic,
    /// Position standard deviations north, east, down [m].
    pub pos_std: Vector3<f64>,
    /// Velocity north, east, down [m/s] and its standard deviations, if measured.
    pub vel: Option<(Vector3<f64>, Vector3<f64>)>,
}

/// A GNSS measurement at one instant: a position (and velocity) fix, or one epoch of
/// pseudoranges and rates for tight coupling.
#[derive(Debug, Clone, PartialEq)]
pub enum GnssUpdate {
    /// A fix (loose coupling).
    Fix(GnssFix),
    /// Raw ranges (tight coupling).
    Ranges(Box<RangeEpoch>),
}

/// Something applied at its own time inside a sample ([`step_with_fixes`]).
pub trait Timed {
    /// Its time [s].
    fn time(&self) -> f64;
}

impl Timed for GnssFix {
    fn time(&self) -> f64 {
        self.t
    }
}

impl Timed for GnssUpdate {
    fn time(&self) -> f64 {
        match self {
            GnssUpdate::Fix(f) => f.t,
            GnssUpdate::Ranges(e) => e.t,
        }
    }
}

/// The gate's reset after consecutive refusals accepts a GNSS position only within
/// this many standard deviations per degree of freedom of the prediction (the filter
/// may have lost track after a long outage, but an innovation of a thousand standard
/// deviations is a wrong fix, not a lost track).
pub const RESET_MAX_SIGMA: f64 = 1000.0;

/// Filter settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegrationConfig {
    /// IMU noise and bias statistics.
    pub noise: ImuNoise,
    /// Estimate gyro and accelerometer scale factors (21 states).
    pub scale_factors: bool,
    /// GNSS antenna position in body axes (FRD) [m].
    pub lever_arm: Vector3<f64>,
    /// Innovation gate.
    pub gate: Gate,
    /// After this many GNSS positions in a row refused by the gate, accept the next
    /// one without the test (the filter has lost the GNSS track, e.g. after a long
    /// outage with an optimistic noise model; refusing forever would never recover).
    /// 0: never.
    pub reset_after: u32,
    /// Longest covariance propagation step [s].
    pub propagation_interval: f64,
    /// Initial standard deviations: position (NED) [m].
    pub init_pos_std: Vector3<f64>,
    /// Initial velocity standard deviations (NED) [m/s].
    pub init_vel_std: Vector3<f64>,
    /// Initial attitude standard deviations (about north, east, down) [rad].
    pub init_att_std: Vector3<f64>,
    /// Barometer: prior standard deviation of its bias [m] and the bias's random-walk
    /// density [m/sqrt(s)]; `None` without a barometer.
    pub baro: Option<(f64, f64)>,
    /// Initial standard deviations of gyro bias, accelerometer bias, gyro and
    /// accelerometer scale factors, when they differ from the noise model's.
    pub init_sensor_std: Option<[Vector3<f64>; 4]>,
    /// GNSS time offset `τ` [s]: a GNSS measurement stamped `t` describes the IMU's
    /// instant `t + τ` ([`super::calibration`]).
    pub gnss_time_offset: f64,
    /// The lever arm and time offset as filter states, from `lever_arm` and
    /// `gnss_time_offset`.
    pub calibration: Calibration,
}

impl IntegrationConfig {
    /// The settings `schuler nav` starts from with this noise model: 15 states, no
    /// lever arm or barometer, the gate at 1e-4 reset after 5 refusals in a row,
    /// propagation every second, initial standard deviations 1 m, 0.1 m/s and
    /// 0.1°, 0.1°, 0.5° (about north, east, down).
    pub fn new(noise: ImuNoise) -> Self {
        Self {
            noise,
            scale_factors: false,
            lever_arm: Vector3::zeros(),
            gate: Gate::Level(1e-4),
            reset_after: 5,
            propagation_interval: 1.0,
            init_pos_std: Vector3::repeat(1.0),
            init_vel_std: Vector3::repeat(0.1),
            init_att_std: Vector3::new(0.1, 0.1, 0.5).map(f64::to_radians),
            baro: None,
            init_sensor_std: None,
            gnss_time_offset: 0.0,
            calibration: Calibration::default(),
        }
    }

    /// How far ahead of the IMU [s] a GNSS measurement may be needed: a stamp `t`
    /// is applied at `t + τ`, earlier than `t` for a negative offset, which a prior of
    /// `σ` may reach to 3σ (a session holds its samples back this much longer).
    pub fn gnss_lead(&self) -> f64 {
        let spread = 3.0 * self.calibration.time_offset_std.unwrap_or(0.0);
        (spread - self.gnss_time_offset).max(0.0)
    }
}

/// A measurement the gate refused.
#[derive(Debug, Clone, PartialEq)]
pub struct Rejected {
    /// Time [s].
    pub t: f64,
    /// What it was.
    pub kind: Kind,
    /// The satellite, for a pseudorange or a rate.
    pub sat: Option<crate::gnss::Sat>,
    /// Why: the test's numbers.
    pub rejection: Rejection,
}

/// One measurement as the filter tested it, accepted or refused: the innovation
/// `z` (computed minus measured, in the computation frame `c` of
/// [`crate::filter::measurement`]; NED on the local-level mechanization), the diagonal
/// of its covariance `S = H P Hᵀ + R` and the normalized innovation squared
/// `zᵀ S⁻¹ z`, chi-square with `z.len()` degrees of freedom for a consistent filter.
#[derive(Debug, Clone, PartialEq)]
pub struct Innovation {
    /// Time [s].
    pub t: f64,
    /// What it was.
    pub kind: Kind,
    /// The satellite, for a pseudorange or a rate.
    pub sat: Option<crate::gnss::Sat>,
    /// Innovation (units of the measurement: m, m/s).
    pub z: DVector<f64>,
    /// Diagonal of the innovation covariance `S` (units squared).
    pub s_diag: DVector<f64>,
    /// Normalized innovation squared (infinite when `S` is not positive definite).
    pub nis: f64,
    /// Whether the gate let it through.
    pub accepted: bool,
}

/// A measurement that could not be used at all.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Skipped {
    /// Time [s].
    pub t: f64,
    /// What it was.
    pub kind: Kind,
    /// Why.
    pub reason: SkipReason,
}

/// Why a measurement was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkipReason {
    /// Its time is before the IMU data being processed.
    BeforeImu,
    /// Its time is after the IMU data ended.
    AfterImu,
    /// The filter has no model of it (range epochs in the 18-state filter).
    NotModelled,
}

/// Estimated sensor errors (what the compensation removes).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SensorEstimates {
    /// Gyro bias [rad/s].
    pub gyro_bias: Vector3<f64>,
    /// Accelerometer bias [m/s^2].
    pub accel_bias: Vector3<f64>,
    /// Gyro scale-factor error.
    pub gyro_scale: Vector3<f64>,
    /// Accelerometer scale-factor error.
    pub accel_scale: Vector3<f64>,
    /// Barometer bias [m].
    pub baro_bias: f64,
    /// Odometer scale-factor error (reading = (1 + k) speed).
    pub odometer_scale: f64,
    /// Mounting errors of the vehicle frame removed from the configured mount
    /// (rotation vector in the vehicle frame: 0, pitch, yaw) [rad]
    /// ([`VehicleMount::corrected`]).
    pub mounting: Vector3<f64>,
    /// Correction to the configured GNSS lever arm [m] ([`super::calibration`]).
    pub lever_arm: Vector3<f64>,
    /// Correction to the configured GNSS time offset [s].
    pub gnss_time_offset: f64,
}

impl SensorEstimates {
    /// The sample with these errors removed.
    pub fn compensate(&self, s: &ImuSample) -> ImuSample {
        let one = Vector3::repeat(1.0);
        ImuSample {
            dtheta: (s.dtheta - self.gyro_bias * s.dt).component_mul(&(one - self.gyro_scale)),
            dvel: (s.dvel - self.accel_bias * s.dt).component_mul(&(one - self.accel_scale)),
            ..*s
        }
    }
}

/// Counts of what the filter did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counts {
    /// Accepted position updates.
    pub position: u64,
    /// Accepted velocity updates.
    pub velocity: u64,
    /// Accepted barometer updates.
    pub baro: u64,
    /// Accepted zero-velocity updates.
    pub zupt: u64,
    /// Accepted zero-angular-rate updates.
    pub zaru: u64,
    /// Accepted non-holonomic constraints.
    pub nhc: u64,
    /// Accepted odometer speeds.
    pub odometer: u64,
    /// Accepted dual-antenna headings.
    pub heading: u64,
    /// Accepted pseudoranges.
    pub pseudorange: u64,
    /// Accepted pseudorange rates.
    pub range_rate: u64,
    /// Rejected by the gate.
    pub rejected: u64,
    /// Not usable (outside the IMU's time span).
    pub skipped: u64,
}

impl Counts {
    /// Count an accepted measurement of `kind`.
    pub fn accept(&mut self, kind: Kind) {
        *match kind {
            Kind::GnssPosition => &mut self.position,
            Kind::GnssVelocity => &mut self.velocity,
            Kind::BaroHeight => &mut self.baro,
            Kind::ZeroVelocity => &mut self.zupt,
            Kind::ZeroRate => &mut self.zaru,
            Kind::NonHolonomic => &mut self.nhc,
            Kind::Odometer => &mut self.odometer,
            Kind::Heading => &mut self.heading,
            Kind::Pseudorange => &mut self.pseudorange,
            Kind::RangeRate => &mut self.range_rate,
        } += 1;
    }
}

/// The integrated navigation: mechanization plus filter.
#[derive(Debug, Clone)]
pub struct Integrator<M: ErrorFrame, E: EarthModel> {
    mech: M,
    earth: E,
    model: ErrorModel,
    kf: Kalman,
    cfg: IntegrationConfig,
    interval: Interval,
    estimates: SensorEstimates,
    w_ib_b: Vector3<f64>,
    /// The last sample's specific force (compensated) [m/s²], and the longest sample
    /// interval so far [s].
    f_ib_b: Vector3<f64>,
    f_dt: f64,
    /// The time the mechanization started [s].
    t_start: f64,
    /// What the motion showed of the calibrations so far.
    excitation: calibration::Excitation,
    /// The antenna's acceleration at the last GNSS epoch and its rate of change.
    jerk: calibration::JerkMemory,
    /// The measurements tested, refused and skipped, the counts and gate resets.
    pub book: GateBook,
    /// The record for the smoother, when smoothing.
    smoother: Option<super::smoother::SmootherLog>,
    /// Tight coupling's settings, clock and counters, when it is on.
    tight: Option<Box<Tight>>,
}

/// `c B cᵀ` of the 3x3 block `B` of `p` at `(o, o)`, element by element in the order of
/// nalgebra's `c * B * c.transpose()` (each element `(x₀y₀ + x₁y₁) + x₂y₂`, so the same
/// bits) without its generic loops and copies: the output epoch's covariances come
/// from it at every sample.
#[inline]
fn congruence(c: &Matrix3<f64>, p: &DMatrix<f64>, o: usize) -> Matrix3<f64> {
    let b = |i: usize, j: usize| p[(o + i, o + j)];
    let m =
        Matrix3::from_fn(|i, j| c[(i, 0)] * b(0, j) + c[(i, 1)] * b(1, j) + c[(i, 2)] * b(2, j));
    Matrix3::from_fn(|i, j| m[(i, 0)] * c[(j, 0)] + m[(i, 1)] * c[(j, 1)] + m[(i, 2)] * c[(j, 2)])
}

impl<M: ErrorFrame, E: EarthModel> Integrator<M, E> {
    /// Start from a mechanization at its initial state.
    pub fn new(mech: M, earth: E, cfg: IntegrationConfig) -> Self {
        let mut layout = Layout::core();
        if cfg.scale_factors {
            layout = layout.with_scale_factors();
        }
        if cfg.baro.is_some() {
            layout = layout.with_baro_bias();
        }
        if cfg.calibration.lever_arm_std.is_some() {
            layout = layout.with_lever_arm();
        }
        if cfg.calibration.time_offset_std.is_some() {
            layout = layout.with_time_offset();
        }
        let (baro_std, baro_walk) = cfg.baro.unwrap_or((0.0, 0.0));
        let model = ErrorModel {
            layout,
            noise: cfg.noise,
            baro_bias_walk: baro_walk,
            odometer_scale_walk: 0.0,
            clock: Default::default(),
            time_offset_walk: cfg.calibration.time_offset_walk,
        };
        let frame = mech.frame();
        let state = mech.state();
        let c = measurement::c_nc(&frame, &state.pos);
        let mut p = model.initial_covariance(
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::zeros(),
            baro_std,
        );
        let rot = |std: &Vector3<f64>| {
            c * Matrix3::from_diagonal(&std.component_mul(std)) * c.transpose()
        };
        if let Some(sd) = cfg.init_sensor_std {
            let blocks = [
                Some(Layout::GYRO_BIAS),
                Some(Layout::ACCEL_BIAS),
                layout.gyro_scale,
                layout.accel_scale,
            ];
            for (o, v) in blocks.into_iter().zip(sd) {
                if let Some(o) = o {
                    p.fixed_view_mut::<3, 3>(o, o)
                        .copy_from(&Matrix3::from_diagonal(&v.component_mul(&v)));
                }
            }
        }
        for (o, std) in [
            (Layout::POS, cfg.init_pos_std),
            (Layout::VEL, cfg.init_vel_std),
            (Layout::ATT, cfg.init_att_std),
        ] {
            p.fixed_view_mut::<3, 3>(o, o).copy_from(&rot(&std));
        }
        if let (Some(o), Some(std)) = (layout.lever_arm, cfg.calibration.lever_arm_std) {
            for i in 0..3 {
                p[(o + i, o + i)] = std * std;
            }
        }
        if let (Some(o), Some(std)) = (layout.time_offset, cfg.calibration.time_offset_std) {
            p[(o, o)] = std * std;
        }
        Self {
            t_start: state.t,
            excitation: Default::default(),
            jerk: Default::default(),
            mech,
            earth,
            model,
            kf: Kalman::new(p),
            cfg,
            interval: Interval::default(),
            estimates: SensorEstimates::default(),
            w_ib_b: Vector3::zeros(),
            f_ib_b: Vector3::zeros(),
            f_dt: 0.0,
            book: GateBook::default(),
            smoother: None,
            tight: None,
        }
    }

    /// Replace the prior of the attitude error (about north, east, down) and the gyro
    /// and accelerometer biases by the joint covariance `p` (order: attitude, gyro
    /// bias, accelerometer bias), e.g. an alignment's, whose tilts and horizontal
    /// accelerometer biases are correlated at rest. The attitude rows are turned into
    /// the computation frame (`C_cn P C_nc`). Call before [`Integrator::with_smoother`].
    pub fn with_attitude_bias_covariance(mut self, p: &SMatrix<f64, 9, 9>) -> Self {
        let frame = self.mech.frame();
        let c = measurement::c_nc(&frame, &self.mech.state().pos);
        let mut t = SMatrix::<f64, 9, 9>::identity();
        t.fixed_view_mut::<3, 3>(0, 0).copy_from(&c);
        let rotated = t * p * t.transpose();
        let at = [Layout::ATT, Layout::GYRO_BIAS, Layout::ACCEL_BIAS];
        for (i, oi) in at.iter().enumerate() {
            for (j, oj) in at.iter().enumerate() {
                self.kf
                    .p
                    .fixed_view_mut::<3, 3>(*oi, *oj)
                    .copy_from(&rotated.fixed_view::<3, 3>(3 * i, 3 * j));
            }
        }
        self
    }

    /// Start from sensor-error estimates other than zero (e.g. a previous run's).
    pub fn with_estimates(mut self, estimates: SensorEstimates) -> Self {
        self.estimates = estimates;
        self
    }

    /// Estimate the odometer's scale-factor error: prior standard deviation `std` and
    /// random-walk density `walk` [1/sqrt(s)] (a state appended to the layout; the
    /// smoother's record, if any, restarts with the larger covariance).
    pub fn with_odometer_scale(mut self, std: f64, walk: f64) -> Self {
        if self.model.layout.odometer_scale.is_some() {
            return self;
        }
        let old = self.model.layout.n;
        self.model.layout = self.model.layout.with_odometer_scale();
        self.model.odometer_scale_walk = walk;
        let n = self.model.layout.n;
        let mut p = DMatrix::zeros(n, n);
        p.view_mut((0, 0), (old, old)).copy_from(&self.kf.p);
        p[(old, old)] = std * std;
        self.kf.p = p;
        if self.smoother.is_some() {
            self = self.with_smoother();
        }
        self
    }

    /// Estimate the vehicle frame's pitch and yaw mounting relative to the configured
    /// mount, prior standard deviation `std` [rad] each, constant (two states appended
    /// to the layout; the smoother's record, if any, restarts).
    pub fn with_mounting(mut self, std: f64) -> Self {
        if self.model.layout.mounting.is_some() {
            return self;
        }
        let old = self.model.layout.n;
        self.model.layout = self.model.layout.with_mounting();
        let n = self.model.layout.n;
        let mut p = DMatrix::zeros(n, n);
        p.view_mut((0, 0), (old, old)).copy_from(&self.kf.p);
        p[(old, old)] = std * std;
        p[(old + 1, old + 1)] = std * std;
        self.kf.p = p;
        if self.smoother.is_some() {
            self = self.with_smoother();
        }
        self
    }

    /// Tight coupling under `cfg` ([`super::ranging`]): the receiver clock's biases
    /// and drift appended to the layout (their variances set when the first
    /// measurements start them; the smoother's record, if any, restarts).
    pub fn with_tight(mut self, cfg: TightConfig) -> Self {
        if self.tight.is_some() {
            return self;
        }
        let old = self.model.layout.n;
        self.model.layout = self.model.layout.with_clock(cfg.systems.len());
        self.model.clock = cfg.clock;
        let n = self.model.layout.n;
        let mut p = DMatrix::zeros(n, n);
        p.view_mut((0, 0), (old, old)).copy_from(&self.kf.p);
        self.kf.p = p;
        self.tight = Some(Box::new(Tight::new(cfg)));
        if self.smoother.is_some() {
            self = self.with_smoother();
        }
        self
    }

    /// Tight coupling's clock and counters, when it is on.
    pub fn tight(&self) -> Option<&Tight> {
        self.tight.as_deref()
    }

    /// Keep what the smoother needs (covariances, transitions, feedback, and the
    /// state at each [`Integrator::record_output`]).
    pub fn with_smoother(mut self) -> Self {
        let mut log = super::smoother::SmootherLog::default();
        log.start(self.mech.state().t, &self.kf.p);
        self.smoother = Some(log);
        self
    }

    /// Record the current instant as an output of the smoothed trajectory.
    pub fn record_output(&mut self) {
        if let Some(log) = self.smoother.as_mut() {
            log.output(self.mech.frame(), self.estimates);
        }
    }

    /// The smoothed trajectory at the recorded outputs, read as it is computed
    /// (`None` without [`Integrator::with_smoother`]); the record is taken, so a second
    /// call gives `None`.
    pub fn smoothed(
        &mut self,
    ) -> Option<Result<super::smoother::SmoothedTrajectory, super::spill::SpillError>> {
        let layout = self.model.layout;
        self.smoother.take().map(|log| log.smooth(&layout))
    }

    /// The mechanization (current state).
    pub fn mechanization(&self) -> &M {
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

    /// The GNSS antenna's lever arm in use: the configured one plus the estimate [m].
    pub fn lever_arm(&self) -> Vector3<f64> {
        self.cfg.lever_arm + self.estimates.lever_arm
    }

    /// The GNSS time offset in use: the configured one plus the estimate [s].
    pub fn gnss_time_offset(&self) -> f64 {
        self.cfg.gnss_time_offset + self.estimates.gnss_time_offset
    }

    /// The calibration estimates now, with their standard deviations.
    pub fn calibration(&self) -> CalibrationState {
        let p = &self.kf.p;
        let sd = |i: usize| p[(i, i)].max(0.0).sqrt();
        let c = &self.cfg.calibration;
        let l = &self.model.layout;
        let seen = |i: usize| self.excitation.std(i);
        CalibrationState {
            lever_arm: l.lever_arm.zip(c.lever_arm_std).map(|(o, prior)| Estimate {
                value: self.lever_arm(),
                std: Vector3::new(sd(o), sd(o + 1), sd(o + 2)),
                prior_std: prior,
                excited_std: Vector3::new(seen(0), seen(1), seen(2)),
            }),
            time_offset: l
                .time_offset
                .zip(c.time_offset_std)
                .map(|(o, prior)| Estimate {
                    value: self.gnss_time_offset(),
                    std: sd(o),
                    prior_std: prior,
                    excited_std: seen(3),
                }),
        }
    }

    /// The IMU time at which a GNSS measurement stamped `t` applies: `t + τ̂`, or now
    /// if that has passed after the start (the estimate moved back past it; the
    /// prediction is carried back, [`super::calibration`]).
    pub fn gnss_instant(&self, t: f64) -> f64 {
        let at = t + self.gnss_time_offset();
        if at >= self.t_start {
            at.max(self.mech.state().t)
        } else {
            at
        }
    }

    /// The antenna's motion now and the gap to the instant of a GNSS measurement
    /// stamped `t`.
    fn antenna_motion(&mut self, t: f64) -> (AntennaMotion, f64) {
        let frame = self.mech.frame();
        let gap = t + self.gnss_time_offset() - frame.t;
        // White accelerometer noise over the last sample: VRW² / dt.
        let f_var = self.cfg.noise.vrw.norm_squared() / 3.0 / self.f_dt.max(1e-6);
        let mut k = AntennaMotion::of(
            &frame,
            &self.w_ib_b,
            &self.f_ib_b,
            f_var,
            &self.lever_arm(),
            &self.kf.p,
        );
        k.jerk = self.jerk.update(frame.t, &k.a);
        k.tau_var = self
            .model
            .layout
            .time_offset
            .map_or(0.0, |o| self.kf.p[(o, o)]);
        (k, gap)
    }

    /// The state layout.
    pub fn layout(&self) -> Layout {
        self.model.layout
    }

    /// The error covariance (as of the last propagation or update).
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.kf.p
    }

    /// Covariances of the position and velocity errors in NED and of the attitude
    /// error about north, east, down: `C_cn P_c C_nc` of each 3x3 block.
    pub fn nav_covariance(&self) -> [Matrix3<f64>; 3] {
        let frame = self.mech.frame();
        let c = measurement::c_nc(&frame, &self.mech.state().pos).transpose();
        let p = &self.kf.p;
        let ned = |o: usize| congruence(&c, p, o);
        [ned(Layout::POS), ned(Layout::VEL), ned(Layout::ATT)]
    }

    /// Standard deviations of position and velocity in NED and of the attitude error
    /// about north, east, down, from the covariance.
    pub fn nav_std(&self) -> [Vector3<f64>; 3] {
        self.nav_covariance()
            .map(|p| p.diagonal().map(|v| v.max(0.0).sqrt()))
    }

    /// Prime the two-sample corrections with the sample that ends at the start.
    pub fn prime(&mut self, s: &ImuSample) {
        self.mech.prime(&self.estimates.compensate(s));
    }

    /// Mechanize one sample (no measurement inside it).
    pub fn step(&mut self, raw: &ImuSample) {
        let s = self.estimates.compensate(raw);
        let q_bc = self.mech.q_bc();
        self.mech.step(&s);
        self.interval.add(&s, &q_bc);
        if s.dt > 0.0 {
            self.w_ib_b = s.dtheta / s.dt;
            self.f_ib_b = s.dvel / s.dt;
            // The IMU's period: split samples (at a fix) are shorter, not noisier.
            self.f_dt = self.f_dt.max(s.dt);
        }
        if self.interval.t >= self.cfg.propagation_interval {
            self.propagate();
        }
    }

    /// Propagate the covariance over the accumulated interval.
    pub fn propagate(&mut self) {
        if self.interval.t <= 0.0 {
            return;
        }
        let means = self.interval.means(self.mech.frame());
        let (phi, qd) = self.model.transition(&means);
        match self.smoother.as_mut() {
            Some(log) => {
                let p_post = self.kf.p.clone();
                self.kf.predict(&phi, &qd);
                log.propagated(means.frame.t, &p_post, phi, &self.kf.p);
            }
            None => self.kf.predict(&phi, &qd),
        }
        self.interval = Interval::default();
    }

    /// Mechanize a sample during which GNSS fixes may fall: fixes from `fixes` with
    /// times up to the sample's end are applied at their own times.
    pub fn step_with_fixes<T, F: FixSource<T>>(&mut self, raw: &ImuSample, fixes: &mut F)
    where
        Self: FixConsumer<T>,
    {
        step_with_fixes(self, raw, fixes);
    }

    /// Continue on another mechanization of the same instant (the NED <-> wander
    /// hand-over): `to` makes it from the current one, and the navigation error
    /// blocks of the covariance are turned from the old computation frame `c` to the
    /// new `c'`, `P' = T P Tᵀ` with `T = diag(C, C, C, I)`, `C = C_c'e C_ec` (position,
    /// velocity and attitude errors are all resolved in `c`, [`crate::nav::frame`];
    /// the sensor errors are in body axes and stay). The smoother records the turn as
    /// a transition `Φ = T` without process noise, so it smooths across it.
    pub fn hand_over<M2: ErrorFrame>(mut self, to: impl FnOnce(&M) -> M2) -> Integrator<M2, E> {
        self.propagate();
        let before = self.mech.frame();
        let mech = to(&self.mech);
        let after = mech.frame();
        let c = after.c_ce_to_e.transpose() * before.c_ce_to_e;
        let n = self.model.layout.n;
        let mut t = DMatrix::identity(n, n);
        for o in [Layout::POS, Layout::VEL, Layout::ATT] {
            t.fixed_view_mut::<3, 3>(o, o).copy_from(&c);
        }
        let p_post = self.kf.p.clone();
        let p = &t * &p_post * t.transpose();
        self.kf.p = (&p + p.transpose()) * 0.5;
        if let Some(log) = self.smoother.as_mut() {
            log.propagated(before.t, &p_post, t, &self.kf.p);
        }
        Integrator {
            mech,
            earth: self.earth,
            model: self.model,
            kf: self.kf,
            cfg: self.cfg,
            interval: Interval::default(),
            estimates: self.estimates,
            w_ib_b: self.w_ib_b,
            f_ib_b: self.f_ib_b,
            f_dt: self.f_dt,
            t_start: self.t_start,
            excitation: self.excitation,
            jerk: self.jerk,
            book: self.book,
            smoother: self.smoother,
            tight: self.tight,
        }
    }

    /// Record a GNSS fix that could not be used.
    pub fn skip(&mut self, t: f64, reason: SkipReason) {
        self.skip_measurement(t, Kind::GnssPosition, reason);
    }

    /// Record a measurement of `kind` that could not be used.
    pub fn skip_measurement(&mut self, t: f64, kind: Kind, reason: SkipReason) {
        self.book.skip(t, kind, reason);
    }

    /// Apply a GNSS fix now (position, then velocity if present), of the instant
    /// [`Integrator::gnss_instant`] gives its time.
    pub fn update_gnss(&mut self, fix: &GnssFix) {
        self.propagate();
        let layout = self.model.layout;
        let mut m = measurement::gnss_position(
            &self.earth,
            &layout,
            &self.mech.frame(),
            &fix.pos,
            &fix.pos_std,
            &self.lever_arm(),
        );
        self.calibrate(&mut m, fix.t);
        self.apply(fix.t, m);
        if let Some((v, std)) = fix.vel {
            let mut m = measurement::gnss_velocity(
                &layout,
                &self.mech.frame(),
                &fix.pos,
                &v,
                &std,
                &self.lever_arm(),
                &self.w_ib_b,
            );
            self.calibrate(&mut m, fix.t);
            self.apply(fix.t, m);
        }
    }

    /// The calibration columns of GNSS measurement `m` stamped `t`, and its
    /// prediction carried to its instant ([`super::calibration`]); nothing to do
    /// without calibration and a time offset of zero.
    fn calibrate(&mut self, m: &mut Measurement, t: f64) {
        let l = self.model.layout;
        if l.lever_arm.is_none() && l.time_offset.is_none() && self.gnss_time_offset() == 0.0 {
            return;
        }
        let (k, gap) = self.antenna_motion(t);
        calibration::add_columns(m, &l, &k, gap, &mut self.excitation);
    }

    /// Gate a measurement, record it in [`Integrator::book`] and, if accepted,
    /// update and feed back.
    pub fn apply(&mut self, t: f64, m: Measurement) -> bool {
        let (gate, reset) = self.book.gate(&self.cfg, m.kind, m.z.len());
        let outcome = self.kf.update(&m.z, &m.h, &m.r, gate);
        let Some(u) = self.book.record(t, m.kind, None, m.z, reset, outcome) else {
            return false;
        };
        self.feed_back(&u.dx);
        if let Some(log) = self.smoother.as_mut() {
            log.feedback(&u.dx, &self.kf.p);
        }
        true
    }

    fn feed_back(&mut self, dx: &nalgebra::DVector<f64>) {
        let v3 = |o: usize| Vector3::new(dx[o], dx[o + 1], dx[o + 2]);
        self.mech.correct(&NavErrors {
            dr: v3(Layout::POS),
            dv: v3(Layout::VEL),
            psi: v3(Layout::ATT),
        });
        let l = self.model.layout;
        self.estimates.gyro_bias += v3(Layout::GYRO_BIAS);
        self.estimates.accel_bias += v3(Layout::ACCEL_BIAS);
        if let Some(o) = l.gyro_scale {
            self.estimates.gyro_scale += v3(o);
        }
        if let Some(o) = l.accel_scale {
            self.estimates.accel_scale += v3(o);
        }
        if let Some(b) = l.baro_bias {
            self.estimates.baro_bias += dx[b];
        }
        if let Some(o) = l.odometer_scale {
            self.estimates.odometer_scale += dx[o];
        }
        if let Some(o) = l.mounting {
            self.estimates.mounting += Vector3::new(0.0, dx[o], dx[o + 1]);
        }
        if let Some(o) = l.lever_arm {
            self.estimates.lever_arm += v3(o);
        }
        if let Some(o) = l.time_offset {
            self.estimates.gnss_time_offset += dx[o];
        }
        if let Some(t) = self.tight.as_mut() {
            t.clocks.feed_back(&l, dx);
        }
    }

    /// Apply one epoch of pseudoranges and rates now ([`super::ranging`]); ignored
    /// without [`Integrator::with_tight`]. Returns how many measurements were accepted.
    pub fn update_ranges(&mut self, e: &RangeEpoch) -> usize {
        let Some(mut tight) = self.tight.take() else {
            return 0;
        };
        let accepted = self.ranges_with(&mut tight, e);
        self.tight = Some(tight);
        accepted
    }

    fn ranges_with(&mut self, tight: &mut Tight, e: &RangeEpoch) -> usize {
        self.propagate();
        let layout = self.model.layout;
        let (Some(b0), Some(d)) = (layout.clock, layout.clock_drift()) else {
            return 0;
        };
        let lever = self.lever_arm();
        tight.counts.epochs += 1;
        tight.clocks.advance(e.t);
        let antenna = ranging::Antenna::of(&self.mech.frame(), &lever, &self.w_ib_b);
        let (preds, masked) = ranging::predictions(&tight.cfg.model, e, &antenna);
        tight.counts.masked += masked;
        self.start_clocks(tight, e, &preds, b0, d);
        let (gate, reset) = tight.gate(self.cfg.gate, self.cfg.reset_after);
        let (mut tested, mut accepted) = (0usize, 0usize);
        for &(i, _) in &preds {
            let s = &e.sats[i];
            let Some(k) = tight.clock_index(s.sat.system) else {
                continue;
            };
            let Some(bias) = tight.clocks.bias[k] else {
                continue;
            };
            // Each measurement at the state its predecessors corrected.
            let a = ranging::Antenna::of(&self.mech.frame(), &lever, &self.w_ib_b);
            let Some(p) = tight.cfg.model.predict(s, e.time, &a.r_e, &a.v_e) else {
                continue;
            };
            let pr = s.measurement.pseudorange.unwrap_or(f64::NAN);
            let z = p.pseudorange + bias - pr;
            let mut m = ranging::pseudorange(&layout, &a, &p.u, z, p.pseudorange_var, b0 + k);
            self.calibrate(&mut m, e.t);
            tested += 1;
            accepted += usize::from(self.apply_range(e.t, m, s.sat, gate, reset, tight));
            let (Some(rate), Some(drift), true) = (
                s.measurement.pseudorange_rate(),
                tight.clocks.drift,
                tight.cfg.use_doppler,
            ) else {
                continue;
            };
            let a = ranging::Antenna::of(&self.mech.frame(), &lever, &self.w_ib_b);
            let Some(p) = tight.cfg.model.predict(s, e.time, &a.r_e, &a.v_e) else {
                continue;
            };
            let Some(predicted) = p.rate else { continue };
            let z = predicted + drift - rate;
            let mut m = ranging::range_rate(&layout, &a, &lever, &p.u, p.k, z, p.rate_var, d);
            self.calibrate(&mut m, e.t);
            tested += 1;
            accepted += usize::from(self.apply_range(e.t, m, s.sat, gate, reset, tight));
        }
        if tested > 0 && accepted == 0 {
            tight.refused_in_a_row += 1;
            tight.counts.all_refused += 1;
        } else if accepted > 0 {
            tight.refused_in_a_row = 0;
        }
        accepted
    }

    /// Start each system's clock bias (and the drift) the epoch finds unstarted, or
    /// restart a bias after a clock jump, from the median residual ([`super::ranging`]).
    fn start_clocks(
        &mut self,
        tight: &mut Tight,
        e: &RangeEpoch,
        preds: &[(usize, crate::gnss::Predicted)],
        b0: usize,
        d: usize,
    ) {
        let mut restarted = Vec::new();
        for k in 0..tight.cfg.systems.len() {
            let system = tight.cfg.systems[k];
            let mut res: Vec<f64> = preds
                .iter()
                .filter(|(i, _)| e.sats[*i].sat.system == system)
                .filter_map(|(i, p)| Some(e.sats[*i].measurement.pseudorange? - p.pseudorange))
                .collect();
            let Some(m) = ranging::median(&mut res) else {
                continue;
            };
            let start = match tight.clocks.bias[k] {
                None => true,
                Some(b) if (m - b).abs() > ranging::CLOCK_JUMP_M => {
                    tight.clocks.jumps.push(e.t);
                    true
                }
                Some(_) => false,
            };
            if start {
                tight.clocks.bias[k] = Some(m);
                restarted.push((b0 + k, tight.cfg.init_bias_std));
            }
        }
        if tight.clocks.drift.is_none() && tight.cfg.use_doppler {
            let mut res: Vec<f64> = preds
                .iter()
                .filter_map(|(i, p)| Some(e.sats[*i].measurement.pseudorange_rate()? - p.rate?))
                .collect();
            if let Some(m) = ranging::median(&mut res) {
                tight.clocks.drift = Some(m);
                restarted.push((d, tight.cfg.init_drift_std));
            } else if tight.clocks.bias.iter().any(Option::is_some) {
                // No Doppler: the drift from the biases' course, from 0 with an
                // oscillator's offset for prior.
                tight.clocks.drift = Some(0.0);
                restarted.push((d, ranging::DRIFT_STD_WITHOUT_DOPPLER));
            }
        }
        if restarted.is_empty() {
            return;
        }
        // A restarted state: its own prior, uncorrelated with the rest.
        for (i, std) in restarted {
            self.kf.p.row_mut(i).fill(0.0);
            self.kf.p.column_mut(i).fill(0.0);
            self.kf.p[(i, i)] = std * std;
        }
        if let Some(log) = self.smoother.as_mut() {
            log.feedback(&DVector::zeros(self.model.layout.n), &self.kf.p);
        }
    }

    /// Gate one range measurement of `sat` through `gate` (`reset`: the epoch passes
    /// the reset's bound) and, if accepted, update and feed back.
    fn apply_range(
        &mut self,
        t: f64,
        m: Measurement,
        sat: crate::gnss::Sat,
        gate: Gate,
        reset: bool,
        tight: &mut Tight,
    ) -> bool {
        let outcome = self.kf.update(&m.z, &m.h, &m.r, gate);
        let Some(u) = self.book.record(t, m.kind, Some(sat), m.z, reset, outcome) else {
            return false;
        };
        // `tight` is out of `self` while its epoch runs: its clock is fed back here.
        self.feed_back(&u.dx);
        tight.clocks.feed_back(&self.model.layout, &u.dx);
        if let Some(log) = self.smoother.as_mut() {
            log.feedback(&u.dx, &self.kf.p);
        }
        true
    }

    /// Apply a barometric height `h_baro` [m] with standard deviation `std` now (the
    /// caller applies it at the IMU sample ending nearest its time: at 200 Hz the
    /// offset is at most 2.5 ms, 2.5 mm at 1 m/s of climb). Ignored without a
    /// barometer in the configuration.
    pub fn update_baro(&mut self, t: f64, h_baro: f64, std: f64) -> bool {
        let h = self.mech.state().pos.h;
        let layout = self.model.layout;
        let Some(m) = measurement::baro_height(&layout, h, h_baro, self.estimates.baro_bias, std)
        else {
            return false;
        };
        self.propagate();
        self.apply(t, m)
    }
}

impl<M: ErrorFrame, E: EarthModel> Integrator<M, E> {
    /// Zero velocity now (the vehicle at rest), standard deviation `std` [m/s] per
    /// axis ([`vehicle::zero_velocity`]).
    pub fn update_zero_velocity(&mut self, std: f64) -> bool {
        self.propagate();
        let frame = self.mech.frame();
        let m = vehicle::zero_velocity(&self.model.layout, &frame, std);
        self.apply(frame.t, m)
    }

    /// Zero angular rate relative to the Earth now, from `window`: the raw increments
    /// summed over a window at rest that ends now (compensated here with the current
    /// estimates), standard deviation `std` [rad/s] per axis of the window's mean
    /// rate ([`vehicle::zero_rate`]).
    pub fn update_zero_rate(&mut self, window: &ImuSample, std: f64) -> bool {
        if window.dt <= 0.0 {
            return false;
        }
        self.propagate();
        let frame = self.mech.frame();
        let w = self.estimates.compensate(window).dtheta / window.dt;
        let m = vehicle::zero_rate(&self.model.layout, &frame, &w, std);
        self.apply(frame.t, m)
    }

    /// The non-holonomic constraint now: no lateral or vertical velocity of `mount`'s
    /// point, standard deviation `std` [m/s] ([`vehicle::non_holonomic`]).
    pub fn update_non_holonomic(&mut self, mount: &VehicleMount, std: f64) -> bool {
        self.propagate();
        let frame = self.mech.frame();
        let mount = mount.corrected(&self.estimates.mounting);
        let m = vehicle::non_holonomic(&self.model.layout, &frame, &mount, &self.w_ib_b, std);
        self.apply(frame.t, m)
    }

    /// An odometer `speed` [m/s] read at `t` of `mount`'s point, standard deviation
    /// `std`, applied now (at the sample ending nearest `t`; [`vehicle::odometer`]).
    pub fn update_odometer(&mut self, t: f64, speed: f64, std: f64, mount: &VehicleMount) -> bool {
        self.propagate();
        let m = vehicle::odometer(
            &self.model.layout,
            &self.mech.frame(),
            &mount.corrected(&self.estimates.mounting),
            &self.w_ib_b,
            speed,
            self.estimates.odometer_scale,
            std,
        );
        self.apply(t, m)
    }

    /// A dual-antenna heading `reading` of `baseline`, applied now (at the sample
    /// ending nearest its time, the computed heading carried to it with the body
    /// rate; [`vehicle::heading`]). Refused (false) for a vertical baseline.
    pub fn update_heading(&mut self, reading: &HeadingReading, baseline: &Baseline) -> bool {
        let frame = self.mech.frame();
        let at = self.mech.state().pos;
        let Some(m) = vehicle::heading(
            &self.model.layout,
            &frame,
            &at,
            baseline,
            &self.w_ib_b,
            reading,
        ) else {
            return false;
        };
        self.propagate();
        self.apply(reading.t, m)
    }
}

/// A filter that [`step_with_fixes`] drives with measurements `T`: it steps samples,
/// applies GNSS fixes (or range epochs) and records the ones it cannot use (the
/// psi-angle [`Integrator`] and the 18-state [`super::seed18::Seed18`]).
pub trait FixConsumer<T = GnssFix> {
    /// The mechanization's time [s].
    fn now(&self) -> f64;
    /// The IMU time at which a fix stamped `t` applies (`t` itself unless the
    /// filter has a GNSS time offset, [`super::calibration`]).
    fn instant(&self, t: f64) -> f64 {
        t
    }
    /// Mechanize one sample with no fix inside it.
    fn step_sample(&mut self, s: &ImuSample);
    /// Apply a fix now.
    fn apply_fix(&mut self, f: &T);
    /// Record a fix that could not be used.
    fn skip_fix(&mut self, f: &T, reason: SkipReason);
}

impl<M: ErrorFrame, E: EarthModel> FixConsumer for Integrator<M, E> {
    fn now(&self) -> f64 {
        self.mech.state().t
    }
    fn instant(&self, t: f64) -> f64 {
        self.gnss_instant(t)
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

impl<M: ErrorFrame, E: EarthModel> FixConsumer<GnssUpdate> for Integrator<M, E> {
    fn now(&self) -> f64 {
        self.mech.state().t
    }
    fn instant(&self, t: f64) -> f64 {
        self.gnss_instant(t)
    }
    fn step_sample(&mut self, s: &ImuSample) {
        self.step(s);
    }
    fn apply_fix(&mut self, u: &GnssUpdate) {
        match u {
            GnssUpdate::Fix(f) => self.update_gnss(f),
            GnssUpdate::Ranges(e) => {
                self.update_ranges(e);
            }
        }
    }
    fn skip_fix(&mut self, u: &GnssUpdate, reason: SkipReason) {
        match u {
            GnssUpdate::Fix(f) => self.skip(f.t, reason),
            GnssUpdate::Ranges(e) => self.skip_measurement(e.t, Kind::Pseudorange, reason),
        }
    }
}

/// Mechanize a sample of `c` during which GNSS fixes may fall: fixes from `fixes`
/// whose instants ([`FixConsumer::instant`]) fall up to the sample's end are applied
/// there (the sample is split there, [`split`]); fixes before the mechanization's
/// time are skipped.
pub fn step_with_fixes<T, C: FixConsumer<T>, F: FixSource<T>>(
    c: &mut C,
    raw: &ImuSample,
    fixes: &mut F,
) {
    let tol = 1e-3 * raw.dt.max(1e-9);
    let mut rest = Some(*raw);
    while let Some(stamp) = fixes.next_time() {
        let ft = c.instant(stamp);
        let now = c.now();
        if ft < now - tol {
            if let Some(f) = fixes.pop_fix() {
                c.skip_fix(&f, SkipReason::BeforeImu);
            }
            continue;
        }
        if ft <= now + tol {
            if let Some(f) = fixes.pop_fix() {
                c.apply_fix(&f);
            }
            continue;
        }
        let Some(r) = rest else { break };
        if ft > r.t + tol {
            break;
        }
        let Some(f) = fixes.pop_fix() else { break };
        if ft < r.t - tol {
            let (a, b) = split(&r, ft);
            c.step_sample(&a);
            rest = Some(b);
        } else {
            c.step_sample(&r);
            rest = None;
        }
        c.apply_fix(&f);
    }
    if let Some(r) = rest {
        c.step_sample(&r);
    }
}

/// GNSS fixes (or range epochs) in time order, taken one at a time by
/// [`Integrator::step_with_fixes`]: a peekable iterator (a batch) or a queue that a
/// streaming caller keeps filling.
pub trait FixSource<T = GnssFix> {
    /// The time of the next fix, which stays in place.
    fn next_time(&mut self) -> Option<f64>;
    /// Take the next fix.
    fn pop_fix(&mut self) -> Option<T>;
}

impl<T: Timed, I: Iterator<Item = T>> FixSource<T> for std::iter::Peekable<I> {
    fn next_time(&mut self) -> Option<f64> {
        self.peek().map(Timed::time)
    }
    fn pop_fix(&mut self) -> Option<T> {
        self.next()
    }
}

impl<T: Timed> FixSource<T> for std::collections::VecDeque<T> {
    #[inline]
    fn next_time(&mut self) -> Option<f64> {
        self.front().map(Timed::time)
    }
    fn pop_fix(&mut self) -> Option<T> {
        self.pop_front()
    }
}

/// Split a sample at time `t` inside its interval: increments in proportion to time.
pub fn split(s: &ImuSample, t: f64) -> (ImuSample, ImuSample) {
    let t0 = s.t - s.dt;
    let k = ((t - t0) / s.dt).clamp(0.0, 1.0);
    (
        ImuSample {
            t,
            dt: t - t0,
            dtheta: s.dtheta * k,
            dvel: s.dvel * k,
        },
        ImuSample {
            t: s.t,
            dt: s.t - t,
            dtheta: s.dtheta * (1.0 - k),
            dvel: s.dvel * (1.0 - k),
        },
    )
}

#[cfg(test)]
mod congruence_tests {
    use super::*;

    fn block(p: &DMatrix<f64>, o: usize) -> Matrix3<f64> {
        p.fixed_view::<3, 3>(o, o).into_owned()
    }

    /// The same bits as nalgebra's product on matrices of every sign and scale
    /// (a rotation and a covariance block inside a larger matrix).
    #[test]
    fn congruence_is_nalgebras_product_bit_for_bit() {
        let mut seed = 0x9E37_79B9_7F4A_7C15_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for k in 0..2000 {
            let scale = 10f64.powi(k % 17 - 8);
            let p = DMatrix::from_fn(9, 9, |_, _| next() * scale);
            let c = Matrix3::from_fn(|_, _| next());
            for o in [0, 3, 6] {
                let want = c * block(&p, o) * c.transpose();
                let got = congruence(&c, &p, o);
                for (a, b) in got.iter().zip(want.iter()) {
                    assert_eq!(a.to_bits(), b.to_bits(), "{got} {want}");
                }
            }
        }
    }
}
