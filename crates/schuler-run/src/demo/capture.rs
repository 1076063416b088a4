//! A simulated flight held in memory: measured IMU samples, the truth and the true
//! sensor biases once a second, GNSS fixes and barometer readings; from a scenario
//! (the sortie) or from an analytic trajectory written in ECEF (the pole crossing).

use crate::progress::Task;
use anyhow::{Context, Result};
use nalgebra::Vector3;
use schuler::earth::{EarthModel, Wgs84};
use schuler::filter::integration::GnssFix;
use schuler::imu::ImuSample;
use schuler::imu::model::ImuModel;
use schuler::nav::NavState;
use schuler::sim::analytic::{self, Kinematics, Trajectory};
use schuler::sim::imu_model::ImuSimulator;
use schuler::sim::receivers::{self, BaroReading, BaroSimulator, GnssSimulator};
use schuler::sim::run::{ScenarioSpec, SimSink, simulate};
use schuler::sim::sensor_spec::{BaroSpec, GnssSpec};

/// One second's truth: the state and the IMU's biases then.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthEpoch {
    /// True state.
    pub state: NavState,
    /// Gyro bias [rad/s].
    pub gyro_bias: Vector3<f64>,
    /// Accelerometer bias [m/s^2].
    pub accel_bias: Vector3<f64>,
}

/// Everything simulated.
#[derive(Debug)]
pub struct Recording {
    /// IMU sample rate [Hz].
    pub rate: f64,
    /// Measured IMU samples; sample 0 ends at the start time.
    pub imu: Vec<ImuSample>,
    /// The truth at every whole second from the start.
    pub truth: Vec<TruthEpoch>,
    /// GNSS fixes (position and velocity).
    pub gnss: Vec<GnssFix>,
    /// Times of the fixes the simulator made outliers.
    pub gnss_outliers: Vec<f64>,
    /// Barometer readings: time, height [m].
    pub baro: Vec<(f64, f64)>,
    /// The IMU's error model.
    pub model: ImuModel,
}

impl Recording {
    /// IMU samples per second.
    pub fn per_second(&self) -> usize {
        self.rate.round() as usize
    }

    /// The truth at whole second `t` (nearest epoch).
    pub fn truth_at(&self, t: f64) -> &TruthEpoch {
        let t0 = self.truth.first().map_or(0.0, |e| e.state.t);
        let i = ((t - t0).round().max(0.0) as usize).min(self.truth.len().saturating_sub(1));
        &self.truth[i]
    }

    /// Index of the IMU sample that ends at `t`.
    pub fn sample_at(&self, t: f64) -> usize {
        let t0 = self.imu.first().map_or(0.0, |s| s.t);
        (((t - t0) * self.rate).round().max(0.0) as usize).min(self.imu.len().saturating_sub(1))
    }
}

struct Capture {
    rec: Recording,
    imu: ImuSimulator,
    bar: Box<dyn Task>,
}

impl Capture {
    /// An empty recording of `samples` samples at `rate` [Hz] of an IMU `model` drawing
    /// from `seed` (the simulator's own model and seed: the same samples, with the
    /// biases behind them in reach).
    fn new(model: ImuModel, seed: u64, rate: f64, samples: usize, bar: Box<dyn Task>) -> Self {
        Self {
            rec: Recording {
                rate,
                imu: Vec::with_capacity(samples),
                truth: Vec::new(),
                gnss: Vec::new(),
                gnss_outliers: Vec::new(),
                baro: Vec::new(),
                model: model.clone(),
            },
            imu: ImuSimulator::new(model, seed),
            bar,
        }
    }

    /// Measure and keep the next sample; keep the truth at its end once a second.
    fn push(&mut self, exact: &ImuSample, truth: &NavState) -> ImuSample {
        let m = self.imu.measure(exact);
        let k = self.rec.imu.len();
        self.rec.imu.push(m);
        if k.is_multiple_of(self.rec.per_second()) {
            let (gyro_bias, accel_bias) = self.imu.biases();
            self.rec.truth.push(TruthEpoch {
                state: *truth,
                gyro_bias,
                accel_bias,
            });
            self.bar.inc(1);
        }
        m
    }

    fn finish(self) -> Recording {
        self.bar.finish();
        self.rec
    }
}

impl SimSink for Capture {
    fn imu(
        &mut self,
        exact: &ImuSample,
        measured: &ImuSample,
        truth: &NavState,
        _kin: &Kinematics,
    ) -> std::io::Result<()> {
        let m = self.push(exact, truth);
        debug_assert_eq!(m, *measured);
        Ok(())
    }

    fn gnss(&mut self, f: &receivers::GnssFix) -> std::io::Result<()> {
        if f.outlier {
            self.rec.gnss_outliers.push(f.t);
        }
        self.rec.gnss.push(GnssFix {
            t: f.t,
            pos: f.pos,
            pos_std: f.pos_std,
            vel: Some((f.v_n, f.vel_std)),
        });
        Ok(())
    }

    fn baro(&mut self, r: &BaroReading) -> std::io::Result<()> {
        self.rec.baro.push((r.t, r.h));
        Ok(())
    }
}

/// Simulate `spec` into memory, advancing `bar` by one per simulated second.
pub fn record(spec: &ScenarioSpec, bar: Box<dyn Task>) -> Result<Recording> {
    let model = spec.imu.model().context("the sortie's IMU")?;
    let (traj, _) = spec
        .trajectory(schuler::earth::Wgs84)
        .context("the sortie's trajectory")?;
    let samples = ((traj.end() - traj.start()) * spec.imu.rate_hz) as usize + 2;
    let mut capture = Capture::new(model, spec.seed, spec.imu.rate_hz, samples, bar);
    simulate(spec, &mut capture).context("simulating the sortie")?;
    Ok(capture.finish())
}

/// Every `interval` seconds as a whole number of samples at `rate` [Hz].
fn samples_per(interval: f64, rate: f64, what: &str) -> Result<usize> {
    let n = (interval * rate).round();
    anyhow::ensure!(
        n >= 1.0 && (n - interval * rate).abs() < 1e-9,
        "the {what} interval {interval} s is not a whole number of IMU samples at {rate} Hz"
    );
    Ok(n as usize)
}

/// Simulate the sensors of `spec` (IMU, GNSS, barometer and seed; its motion is not
/// used) along the analytic trajectory `traj` from `t0` for `duration` seconds into
/// memory, advancing `bar` by one per simulated second.
///
/// For trajectories the scripted simulator cannot fly: written in ECEF
/// ([`Trajectory::ecef_pose`]), they pass over the poles, where `spec`'s maneuver
/// scripting (latitude and longitude rates) stops at 89.9 deg. The increments are
/// [`analytic::increment_from`]'s quadrature of the exact rates; GNSS fixes and
/// barometer readings fall on IMU sample times, every `1/rate_hz` of their own.
/// The receiver gets the body rate relative to the Earth, `w_eb_b = w_ib_b − C_bn^T
/// w_ie_n` ([`GnssSimulator::fix_w_eb`]), defined at the pole, where the rate
/// relative to NED that [`simulate`] passes is not.
pub fn record_trajectory<T: Trajectory>(
    traj: &T,
    t0: f64,
    duration: f64,
    spec: &ScenarioSpec,
    bar: Box<dyn Task>,
) -> Result<Recording> {
    let earth = Wgs84;
    let rate = spec.imu.rate_hz;
    let model = spec.imu.model().context("the IMU")?;
    let gnss = spec.gnss.as_ref().map(GnssSpec::model).transpose();
    let baro = spec.baro.as_ref().map(BaroSpec::model).transpose();
    // Each receiver with the number of IMU samples between its epochs.
    let mut gnss = match gnss.context("the GNSS receiver")? {
        Some(m) => Some((
            samples_per(m.interval, rate, "GNSS")?,
            GnssSimulator::new(m, spec.seed),
        )),
        None => None,
    };
    let mut baro = match baro.context("the barometer")? {
        Some(m) => Some((
            samples_per(m.interval, rate, "barometer")?,
            BaroSimulator::new(m, spec.seed),
        )),
        None => None,
    };
    let n = (duration * rate).round() as usize;
    let mut capture = Capture::new(model, spec.seed, rate, n + 1, bar);
    let dt = 1.0 / rate;
    let mut kin = analytic::kinematics(&earth, traj, t0 - dt);
    for k in 0..=n {
        let t = t0 + k as f64 / rate;
        let (exact, truth, end) = analytic::increment_from(&earth, traj, t, dt, &kin);
        kin = end;
        capture.push(&exact, &truth);
        if let Some((_, g)) = gnss.as_mut().filter(|(every, _)| k % *every == 0) {
            let c_bn = truth.q_bn.to_rotation_matrix().into_inner();
            let w_ie_n = earth.local(truth.pos.lat, truth.pos.h).w_ie_n();
            let w_eb_b = kin.w_ib_b - c_bn.transpose() * w_ie_n;
            if let Some(fix) = g.fix_w_eb(&earth, &truth, &w_eb_b) {
                capture.gnss(&fix)?;
            }
        }
        if let Some((_, b)) = baro.as_mut().filter(|(every, _)| k % *every == 0)
            && let Some(r) = b.reading(t, t0, truth.pos.h)
        {
            capture.baro(&r)?;
        }
    }
    Ok(capture.finish())
}
