//! One trajectory, one set of instrument error magnitudes, every system of lecture 22:
//! the strapdown INS (NED mechanization on exact increments), the platform INS in its
//! three azimuth mechanizations, the analytic INS and the gyro-free INS, with their
//! navigation errors against the truth at common epochs.
//!
//! The same [`InstrumentErrors`], and optionally the same simulator IMU model with the
//! same seed (so the same turn-on biases and noise sequence), act in each system's own
//! sensor axes: body for the SINS, the platform for the platform and analytic systems.
//! The gyro-free INS has no gyros; its six accelerometers carry their own constant
//! biases (see [`CompareConfig`]).

use super::gyro_free::AccelerometerArray;
use super::truth::{TruthPoint, truth_at};
use super::{
    AnalyticIns, Azimuth, GyroFreeIns, InstrumentErrors, PlatformIns, Sensors, TruthDriven,
    VerticalChannel, level_rotation,
};
use crate::earth::{EarthModel, Geodetic};
use crate::imu::model::ImuModel;
use crate::nav::{LocalLevel, Mechanization, NavState};
use crate::rotation::rotation_vector_from_quaternion;
use crate::sim::analytic::{self, Trajectory};
use crate::sim::imu_model::ImuSimulator;
use nalgebra::{UnitQuaternion, Vector3, Vector6};
use std::f64::consts::{PI, TAU};

/// One of the compared systems.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SystemKind {
    /// Strapdown INS, NED mechanization ([`LocalLevel`]).
    Sins,
    /// Platform INS in an azimuth mechanization.
    Platform(Azimuth),
    /// Analytic INS (inertially stabilized platform).
    Analytic,
    /// Gyro-free six-accelerometer INS.
    GyroFree,
}

impl SystemKind {
    /// All six, in the order of the lecture's classification after the SINS.
    pub const ALL: [SystemKind; 6] = [
        SystemKind::Sins,
        SystemKind::Platform(Azimuth::Geographic),
        SystemKind::Platform(Azimuth::Orthodromic),
        SystemKind::Platform(Azimuth::FreeAzimuth),
        SystemKind::Analytic,
        SystemKind::GyroFree,
    ];

    /// Short name for files, plots and tables.
    pub fn name(self) -> &'static str {
        match self {
            SystemKind::Sins => "sins",
            SystemKind::Platform(a) => a.name(),
            SystemKind::Analytic => "analytic",
            SystemKind::GyroFree => "gyro-free",
        }
    }
}

/// Settings of a comparison run.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareConfig {
    /// Biases and drifts of the SINS, platform and analytic instruments.
    pub errors: InstrumentErrors,
    /// The simulator's IMU error model on top of `errors` for the same instruments
    /// (none: constant errors only).
    pub sensor_model: Option<ImuModel>,
    /// Seed of the model's random draws.
    pub seed: u64,
    /// The gyro-free INS's accelerometers.
    pub gyro_free_array: AccelerometerArray,
    /// Their biases [m/s^2], in the array's order.
    pub gyro_free_biases: Vector6<f64>,
    /// Level every system on its biased accelerometers at the start.
    pub leveled: bool,
    /// Vertical channel handling.
    pub vertical: VerticalChannel,
    /// RK4 step of the truth-driven (platform, analytic, gyro-free) systems [s].
    pub step: f64,
    /// SINS sample rate [Hz].
    pub imu_rate: f64,
    /// Interval between compared epochs [s]; a whole number of steps and of IMU
    /// samples.
    pub output_interval: f64,
    /// The systems to run.
    pub systems: Vec<SystemKind>,
}

/// Why a comparison cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CompareError {
    /// A setting out of range.
    #[error("{key}: {message}")]
    Setting {
        /// Which setting.
        key: &'static str,
        /// Why.
        message: String,
    },
}

/// Navigation error of one system at one epoch (estimate minus truth).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NavError {
    /// Position error north, east, down [m].
    pub pos_ned: Vector3<f64>,
    /// Velocity error NED [m/s].
    pub v_ned: Vector3<f64>,
    /// Attitude error as the rotation vector of `C_bn_est C_bn_true^T`, NED axes
    /// [rad]: tilts about north and east, heading error about down.
    pub attitude: Vector3<f64>,
}

/// Angle wrapped to (−π, π].
fn wrap_pi(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

impl NavError {
    /// The error of `est` against `truth`; metres from the truth's radii.
    pub fn between<E: EarthModel>(earth: &E, est: &NavState, truth: &NavState) -> Self {
        let r = earth.radii(truth.pos.lat);
        let h = truth.pos.h;
        let q: UnitQuaternion<f64> = est.q_bn * truth.q_bn.inverse();
        Self {
            pos_ned: Vector3::new(
                (est.pos.lat - truth.pos.lat) * (r.meridian + h),
                wrap_pi(est.pos.lon - truth.pos.lon) * (r.prime_vertical + h) * truth.pos.lat.cos(),
                -(est.pos.h - h),
            ),
            v_ned: est.v_n - truth.v_n,
            attitude: rotation_vector_from_quaternion(&q),
        }
    }

    /// Horizontal (circular) position error [m].
    pub fn horizontal(&self) -> f64 {
        self.pos_ned.x.hypot(self.pos_ned.y)
    }
}

/// The result: errors of each system at common epochs.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// The systems, in the order of `errors`.
    pub systems: Vec<SystemKind>,
    /// Epochs [s].
    pub times: Vec<f64>,
    /// True state at each epoch.
    pub truth: Vec<NavState>,
    /// `errors[s][k]`: system `s` at epoch `k`.
    pub errors: Vec<Vec<NavError>>,
}

/// A positive whole ratio `a / b`, or an error naming `key` with `what` the ratio is.
fn whole(a: f64, b: f64, key: &'static str, what: &str) -> Result<usize, CompareError> {
    let n = (a / b).round();
    if !(n >= 1.0 && ((a / b) - n).abs() < 1e-6) {
        return Err(CompareError::Setting {
            key,
            message: format!("{what} = {} must be a whole number", a / b),
        });
    }
    Ok(n as usize)
}

/// Run every configured system over `[t0, t1]` on `traj` and return their errors
/// every `output_interval` (the epochs `t0 + k·interval` within `[t0, t1]`).
pub fn compare<E: EarthModel, T: Trajectory + Sync + ?Sized>(
    earth: E,
    traj: &T,
    t0: f64,
    t1: f64,
    cfg: &CompareConfig,
) -> Result<Comparison, CompareError> {
    let positive = |x: f64, key: &'static str| {
        if x.is_finite() && x > 0.0 {
            Ok(())
        } else {
            Err(CompareError::Setting {
                key,
                message: format!("must be positive and finite, got {x}"),
            })
        }
    };
    positive(cfg.step, "step")?;
    positive(cfg.imu_rate, "imu_rate_hz")?;
    positive(cfg.output_interval, "output_interval")?;
    positive(t1 - t0, "duration")?;
    let steps = whole(
        cfg.output_interval,
        cfg.step,
        "step",
        "output_interval / step",
    )?;
    let samples = whole(
        cfg.output_interval * cfg.imu_rate,
        1.0,
        "imu_rate_hz",
        "output_interval × imu_rate_hz",
    )?;
    let epochs = ((t1 - t0) / cfg.output_interval + 1e-9).floor() as usize;
    let times: Vec<f64> = (0..=epochs)
        .map(|k| t0 + k as f64 * cfg.output_interval)
        .collect();
    let truth: Vec<NavState> = times
        .iter()
        .map(|&t| truth_at(&earth, traj, t).state)
        .collect();

    let errors = std::thread::scope(|scope| {
        let handles: Vec<_> = cfg
            .systems
            .iter()
            .map(|&kind| {
                let truth = &truth;
                let times = &times;
                scope.spawn(move || match kind {
                    SystemKind::Sins => run_sins(&earth, traj, times, truth, samples, cfg),
                    _ => run_truth_driven(&earth, traj, kind, times, steps, cfg),
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect::<Vec<_>>()
    });
    Ok(Comparison {
        systems: cfg.systems.clone(),
        times,
        truth,
        errors,
    })
}

/// A platform, analytic or gyro-free system stepped by RK4 on the truth.
fn run_truth_driven<E: EarthModel, T: Trajectory + ?Sized>(
    earth: &E,
    traj: &T,
    kind: SystemKind,
    times: &[f64],
    steps: usize,
    cfg: &CompareConfig,
) -> Vec<NavError> {
    let start = truth_at(earth, traj, times[0]);
    let sensors = || match &cfg.sensor_model {
        Some(m) => Sensors::with_model(cfg.errors, m.clone(), cfg.seed),
        None => Sensors::constant(cfg.errors),
    };
    let mut sys: Box<dyn TruthDriven> = match kind {
        SystemKind::Platform(az) => Box::new(PlatformIns::new(
            *earth,
            az,
            sensors(),
            cfg.vertical,
            cfg.leveled,
            &start,
        )),
        SystemKind::Analytic => Box::new(AnalyticIns::new(
            *earth,
            sensors(),
            cfg.vertical,
            cfg.leveled,
            &start,
        )),
        SystemKind::GyroFree => Box::new(GyroFreeIns::new(
            *earth,
            cfg.gyro_free_array,
            cfg.gyro_free_biases,
            cfg.vertical,
            cfg.leveled,
            &start,
        )),
        SystemKind::Sins => unreachable!("the SINS runs on increments"),
    };
    let mut out = Vec::with_capacity(times.len());
    out.push(NavError::between(earth, &sys.state(&start), &start.state));
    let mut a: TruthPoint = start;
    for w in times.windows(2) {
        let dt = (w[1] - w[0]) / steps as f64;
        for j in 0..steps {
            let ta = w[0] + j as f64 * dt;
            let tc = if j + 1 == steps { w[1] } else { ta + dt };
            let m = truth_at(earth, traj, 0.5 * (ta + tc));
            let c = truth_at(earth, traj, tc);
            sys.step(&a, &m, &c);
            a = c;
        }
        out.push(NavError::between(earth, &sys.state(&a), &a.state));
    }
    out
}

/// The strapdown INS on exact increments with the same biases and drifts in body axes.
fn run_sins<E: EarthModel, T: Trajectory + ?Sized>(
    earth: &E,
    traj: &T,
    times: &[f64],
    truth: &[NavState],
    samples: usize,
    cfg: &CompareConfig,
) -> Vec<NavError> {
    let start = truth_at(earth, traj, times[0]);
    let mut model = cfg
        .sensor_model
        .as_ref()
        .map(|m| ImuSimulator::new(m.clone(), cfg.seed));
    let mut initial = start.state;
    if cfg.leveled {
        let c_bn = start.state.q_bn.to_rotation_matrix();
        let f_n = c_bn * start.f_b();
        let bias = cfg.errors.accel_bias
            + match (&model, &cfg.sensor_model) {
                (Some(sim), Some(m)) => m.accel.bias + sim.turn_on_biases().1,
                _ => Vector3::zeros(),
            };
        let r = level_rotation(&(f_n + c_bn * bias), &f_n, &Vector3::z_axis());
        initial.q_bn = UnitQuaternion::from_rotation_matrix(&r) * initial.q_bn;
    }
    let mut sins = LocalLevel::new(*earth, initial);
    let mut prev = analytic::kinematics(earth, traj, times[0]);
    let mut out = Vec::with_capacity(times.len());
    out.push(NavError::between(earth, &sins.state(), &truth[0]));
    for (k, w) in times.windows(2).enumerate() {
        let dt = (w[1] - w[0]) / samples as f64;
        for j in 0..samples {
            let t = if j + 1 == samples {
                w[1]
            } else {
                w[0] + (j + 1) as f64 * dt
            };
            let (mut s, tr, end) = analytic::increment_from(earth, traj, t, dt, &prev);
            prev = end;
            if let Some(sim) = &mut model {
                s = sim.measure(&s);
            }
            s.dtheta += cfg.errors.gyro_drift * dt;
            s.dvel += cfg.errors.accel_bias * dt;
            sins.step(&s);
            if cfg.vertical == VerticalChannel::TrueHeight {
                let mut st = sins.state();
                st.pos = Geodetic::new(st.pos.lat, st.pos.lon, tr.pos.h);
                st.v_n.z = tr.v_n.z;
                let history = sins.history();
                sins = LocalLevel::new(*earth, st).with_history(history);
            }
        }
        out.push(NavError::between(earth, &sins.state(), &truth[k + 1]));
    }
    out
}
