//! The simulated sortie held in memory: measured IMU samples, the truth and the true
//! sensor biases once a second, GNSS fixes and barometer readings.

use anyhow::{Context, Result};
use indicatif::ProgressBar;
use nalgebra::Vector3;
use schuler::filter::integration::GnssFix;
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::sim::analytic::Kinematics;
use schuler::sim::imu_model::{ImuModel, ImuSimulator};
use schuler::sim::receivers::{self, BaroReading};
use schuler::sim::run::{ScenarioSpec, SimSink, simulate};

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
    bar: ProgressBar,
}

impl SimSink for Capture {
    fn imu(
        &mut self,
        exact: &ImuSample,
        measured: &ImuSample,
        truth: &NavState,
        _kin: &Kinematics,
    ) -> std::io::Result<()> {
        // The same model and seed as the simulator's own: the same samples, with the
        // biases behind them in reach.
        let m = self.imu.measure(exact);
        debug_assert_eq!(m, *measured);
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
pub fn record(spec: &ScenarioSpec, bar: ProgressBar) -> Result<Recording> {
    let model = spec.imu.model().context("the sortie's IMU")?;
    let (traj, _) = spec
        .trajectory(schuler::earth::Wgs84)
        .context("the sortie's trajectory")?;
    let samples = ((traj.end() - traj.start()) * spec.imu.rate_hz) as usize + 2;
    let mut capture = Capture {
        rec: Recording {
            rate: spec.imu.rate_hz,
            imu: Vec::with_capacity(samples),
            truth: Vec::new(),
            gnss: Vec::new(),
            gnss_outliers: Vec::new(),
            baro: Vec::new(),
            model: model.clone(),
        },
        imu: ImuSimulator::new(model, spec.seed),
        bar,
    };
    simulate(spec, &mut capture).context("simulating the sortie")?;
    capture.bar.finish();
    Ok(capture.rec)
}
