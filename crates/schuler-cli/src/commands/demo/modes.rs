//! A recording navigated the seed's ways, each from a given start on a given
//! mechanization (NED, or the all-latitude wander frame through
//! [`AidedMechanization`]): the inertial mode (free strapdown, its vertical channel
//! with or without the baro loop) and the inertial-satellite mode (error-state Kalman
//! filter on GNSS position and velocity and the barometer; forward, and smoothed).

use super::capture::Recording;
use crate::commands::aided::AidedMechanization;
use crate::commands::nav::MechanizationKind;
use indicatif::ProgressBar;
use nalgebra::Vector3;
use schuler::align::Alignment;
use schuler::channel::detector::DetectorConfig;
use schuler::channel::vertical::{DetectorCounts, Gains};
use schuler::earth::{EarthModel, Wgs84};
use schuler::filter::integration::{IntegrationConfig, Integrator, SensorEstimates};
use schuler::filter::kalman::std3;
use schuler::filter::{Gate, ImuNoise, Layout};
use schuler::nav::{BaroLoop, NavState};
use std::time::Instant;

/// One output epoch (once a second).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Epoch {
    /// The navigation state.
    pub state: NavState,
    /// Filter standard deviations of position, velocity (NED, m and m/s) and attitude
    /// (about north, east, down, rad), when a filter runs.
    pub std: Option<[Vector3<f64>; 3]>,
    /// Wander azimuth [rad] (the navigation frame's x axis east of north), when the
    /// wander mechanization runs.
    pub wander_azimuth: Option<f64>,
}

impl Epoch {
    /// The epoch a mechanization reports now, with the filter's `std` if any.
    fn of<M: AidedMechanization<Wgs84>>(mech: &M, std: Option<[Vector3<f64>; 3]>) -> Self {
        let e = mech.epoch(&Wgs84);
        Self {
            state: e.state,
            std,
            wander_azimuth: (M::KIND == MechanizationKind::Wander).then_some(e.wander_azimuth),
        }
    }
}

/// The filter's sensor-error estimates at one epoch with their standard deviations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorEpoch {
    /// Time [s].
    pub t: f64,
    /// Estimates.
    pub est: SensorEstimates,
    /// Gyro bias standard deviations [rad/s].
    pub gyro_std: Vector3<f64>,
    /// Accelerometer bias standard deviations [m/s^2].
    pub accel_std: Vector3<f64>,
}

/// A navigated track.
#[derive(Debug, Clone, Default)]
pub struct Track {
    /// Once a second.
    pub epochs: Vec<Epoch>,
    /// The filter's sensor estimates, once a second (filter modes only).
    pub sensors: Vec<SensorEpoch>,
    /// Times of the GNSS fixes the filter's gate refused.
    pub rejected: Vec<f64>,
    /// What the baro loop's fault detector did (inertial mode with baro).
    pub baro: Option<DetectorCounts>,
    /// Wall-clock run time [s].
    pub seconds: f64,
}

/// Where navigation starts: the aligned state and the sensor errors alignment found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// The aligned state.
    pub state: NavState,
    /// Sensor errors removed from every sample.
    pub estimates: SensorEstimates,
}

impl Start {
    /// The start an alignment gives.
    pub fn from_alignment(a: &Alignment) -> Self {
        Self {
            state: a.state,
            estimates: SensorEstimates {
                gyro_bias: a.gyro_bias,
                accel_bias: a.accel_bias,
                ..SensorEstimates::default()
            },
        }
    }
}

/// Time constant of the baro loop [s] (the seed: tens of seconds).
pub const BARO_LOOP_TAU: f64 = 30.0;

/// Critically damped baro-loop gains (34) for [`BARO_LOOP_TAU`] at the start's height.
pub fn baro_gains(start: &NavState) -> anyhow::Result<Gains> {
    let l = Wgs84.local(start.pos.lat, start.pos.h);
    let radius = (l.radii.meridian * l.radii.prime_vertical).sqrt() + start.pos.h;
    let w0_sq = l.g_n.z / radius;
    Ok(Gains::critical(BARO_LOOP_TAU, w0_sq)?)
}

/// Readings `baro[*next..]` that fall at or before the end of `sample` (to half a
/// sample): their heights, advancing `next`.
fn due<'a>(baro: &'a [(f64, f64)], next: &mut usize, t: f64, dt: f64) -> &'a [(f64, f64)] {
    let from = *next;
    while *next < baro.len() && baro[*next].0 <= t + 0.5 * dt {
        *next += 1;
    }
    &baro[from..*next]
}

/// The first reading after `t`.
fn first_after(baro: &[(f64, f64)], t: f64) -> usize {
    baro.partition_point(|(tb, _)| *tb <= t + 1e-9)
}

/// The inertial mode on the mechanization `M`: free strapdown from `start`, the
/// vertical channel damped by the baro loop when `gains` are given.
pub fn inertial<M: AidedMechanization<Wgs84>>(
    rec: &Recording,
    start: &Start,
    gains: Option<Gains>,
    bar: &ProgressBar,
) -> Track {
    let clock = Instant::now();
    let i0 = rec.sample_at(start.state.t);
    let per_second = rec.per_second();
    let mut mech = M::start(Wgs84, start.state);
    mech.prime(&start.estimates.compensate(&rec.imu[i0]));
    let mut baro_loop = gains.map(|g| BaroLoop::new(g, DetectorConfig::default()));
    let mut next_baro = first_after(&rec.baro, start.state.t);
    let mut track = Track::default();
    track.epochs.push(Epoch::of(&mech, None));
    for (k, raw) in rec.imu[i0 + 1..].iter().enumerate() {
        mech.step(&start.estimates.compensate(raw));
        if let Some(l) = baro_loop.as_mut() {
            for &(_, h) in due(&rec.baro, &mut next_baro, raw.t, raw.dt) {
                l.update(&mut mech, Some(h));
            }
        }
        if (k + 1) % per_second == 0 {
            track.epochs.push(Epoch::of(&mech, None));
            bar.inc(1);
        }
    }
    track.baro = baro_loop.map(|l| l.counts);
    track.seconds = clock.elapsed().as_secs_f64();
    track
}

/// Settings of the inertial-satellite mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AidedSettings {
    /// GNSS antenna in body axes [m].
    pub lever_arm: Vector3<f64>,
    /// Barometer noise [m].
    pub baro_std: f64,
    /// Prior std of the barometer bias [m] and its random-walk density [m/sqrt(s)].
    pub baro_bias: (f64, f64),
}

/// The filter's initial uncertainty about the start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prior {
    /// Position standard deviations (NED) [m].
    pub pos_std: Vector3<f64>,
    /// Velocity standard deviations (NED) [m/s].
    pub vel_std: Vector3<f64>,
    /// Attitude standard deviations (about north, east, down) [rad].
    pub att_std: Vector3<f64>,
    /// Gyro and accelerometer bias standard deviations [rad/s, m/s^2], when they
    /// differ from the IMU model's.
    pub bias_std: Option<[Vector3<f64>; 2]>,
}

impl Prior {
    /// After an alignment on the pad: the position held to the pad's survey (0.5 m),
    /// the velocity at zero (0.01 m/s), attitude and biases as alignment found them.
    pub fn from_alignment(a: &Alignment) -> Self {
        Self {
            pos_std: Vector3::repeat(0.5),
            vel_std: Vector3::repeat(0.01),
            att_std: a.attitude_std,
            bias_std: Some([a.gyro_bias_std, a.accel_bias_std]),
        }
    }
}

/// The inertial-satellite mode on the mechanization `M`: the 15-state error-state
/// filter (plus the barometer bias) from `start` with the uncertainties `prior`;
/// returns the forward track and the Rauch–Tung–Striebel smoothed one.
pub fn aided<M: AidedMechanization<Wgs84>>(
    rec: &Recording,
    start: &Start,
    prior: &Prior,
    settings: &AidedSettings,
    bar: &ProgressBar,
) -> (Track, Track) {
    let clock = Instant::now();
    let cfg = IntegrationConfig {
        noise: ImuNoise::from_model(&rec.model),
        scale_factors: false,
        lever_arm: settings.lever_arm,
        gate: Gate::Level(1e-4),
        reset_after: 5,
        propagation_interval: 1.0,
        init_pos_std: prior.pos_std,
        init_vel_std: prior.vel_std,
        init_att_std: prior.att_std,
        baro: Some(settings.baro_bias),
        init_sensor_std: prior
            .bias_std
            .map(|[g, a]| [g, a, Vector3::zeros(), Vector3::zeros()]),
    };
    let i0 = rec.sample_at(start.state.t);
    let per_second = rec.per_second();
    let mut integ = Integrator::new(M::start(Wgs84, start.state), Wgs84, cfg)
        .with_estimates(start.estimates)
        .with_smoother();
    integ.prime(&rec.imu[i0]);
    let first_fix = rec.gnss.partition_point(|f| f.t <= start.state.t + 1e-9);
    let mut fixes = rec.gnss[first_fix..].iter().copied().peekable();
    let mut next_baro = first_after(&rec.baro, start.state.t);
    let mut forward = Track::default();
    let record = |integ: &mut Integrator<M, Wgs84>, track: &mut Track| {
        integ.record_output();
        let p = integ.covariance();
        track
            .epochs
            .push(Epoch::of(integ.mechanization(), Some(integ.nav_std())));
        track.sensors.push(SensorEpoch {
            t: integ.state().t,
            est: integ.estimates(),
            gyro_std: std3(p, Layout::GYRO_BIAS),
            accel_std: std3(p, Layout::ACCEL_BIAS),
        });
    };
    record(&mut integ, &mut forward);
    for (k, raw) in rec.imu[i0 + 1..].iter().enumerate() {
        integ.step_with_fixes(raw, &mut fixes);
        for &(t, h) in due(&rec.baro, &mut next_baro, raw.t, raw.dt) {
            integ.update_baro(t, h, settings.baro_std);
        }
        if (k + 1) % per_second == 0 {
            record(&mut integ, &mut forward);
            bar.inc(1);
        }
    }
    forward.rejected = integ.rejected.iter().map(|r| r.t).collect();
    forward.seconds = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    let smoothed = integ.smoothed();
    let mut back = Track {
        epochs: smoothed
            .iter()
            .map(|s| Epoch {
                state: s.state,
                std: Some(s.std),
                wander_azimuth: None,
            })
            .collect(),
        sensors: Vec::new(),
        rejected: forward.rejected.clone(),
        baro: None,
        seconds: 0.0,
    };
    back.seconds = forward.seconds + clock.elapsed().as_secs_f64();
    (forward, back)
}
