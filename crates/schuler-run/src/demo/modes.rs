//! A recording navigated the seed's ways through the library's session, each from a
//! given start on a given mechanization (NED, or the all-latitude wander frame): the
//! inertial mode (free strapdown, its vertical channel
//! with or without the baro loop) and the inertial-satellite mode (error-state Kalman
//! filter on GNSS position and velocity and the barometer; forward, and smoothed).

use super::capture::Recording;
use crate::progress::Task;
use nalgebra::Vector3;
use schuler::channel::detector::DetectorConfig;
use schuler::channel::vertical::{DetectorCounts, Gains};
use schuler::earth::{EarthModel, Wgs84};
use schuler::filter::integration::{IntegrationConfig, SensorEstimates};
use schuler::filter::spill::SpillError;
use schuler::filter::{GnssFix, ImuNoise};
use schuler::nav::NavState;
use schuler::session::{
    Aid, BaroLoopConfig, Event, FilterConfig, Finished, MechanizationChoice, MechanizationConfig,
    MechanizationKind, Session, SessionConfig,
};
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

pub use schuler::session::{Prior, Start};

/// Standard deviation of the pad's surveyed position [m] (the filter's position
/// prior after the alignment on the pad).
pub const PAD_SURVEY_STD: f64 = 0.5;

/// Time constant of the baro loop [s] (the seed: tens of seconds).
pub const BARO_LOOP_TAU: f64 = 30.0;

/// Critically damped baro-loop gains (34) for [`BARO_LOOP_TAU`] at the start's height.
pub fn baro_gains(start: &NavState) -> anyhow::Result<Gains> {
    let l = Wgs84.local(start.pos.lat, start.pos.h);
    let radius = (l.radii.meridian * l.radii.prime_vertical).sqrt() + start.pos.h;
    let w0_sq = l.g_n.z / radius;
    Ok(Gains::critical(BARO_LOOP_TAU, w0_sq)?)
}

/// The first reading after `t`.
fn first_after(baro: &[(f64, f64)], t: f64) -> usize {
    baro.partition_point(|(tb, _)| *tb <= t + 1e-9)
}

/// Run `config` from `start` over the recording's samples from the start on, with the
/// barometer readings after the start and `fixes`; the epochs once a second.
fn run_session(
    rec: &Recording,
    start: &Start,
    config: SessionConfig,
    fixes: &[GnssFix],
    bar: &dyn Task,
) -> (Track, Finished) {
    let clock = Instant::now();
    let i0 = rec.sample_at(start.state.t);
    let per_second = rec.per_second();
    let mut track = Track::default();
    let mut session = match Session::new(Wgs84, config, *start) {
        Ok(s) => s,
        Err(e) => unreachable!("the demo's session configuration is valid: {e}"),
    };
    let baro = &rec.baro[first_after(&rec.baro, start.state.t)..];
    let aids = fixes
        .iter()
        .map(|f| Aid::Gnss(*f))
        .chain(baro.iter().map(|&(t, h)| Aid::Baro { t, h }));
    for aid in aids {
        // The simulator's aids are finite: nothing to refuse.
        let _ = session.push(aid);
    }
    for (k, raw) in rec.imu[i0..].iter().enumerate() {
        // The simulator's samples are finite and in time order.
        let _ = session.push_imu(*raw);
        track.epochs.extend(session.epochs().map(|e| epoch(&e)));
        track
            .rejected
            .extend(session.events().filter_map(|e| match e {
                Event::Refused(r) => Some(r.t),
                _ => None,
            }));
        if k % per_second == 0 && k > 0 {
            bar.inc(1);
        }
    }
    let finished = match session.finish() {
        Ok(f) => f,
        Err(e) => unreachable!("the recording has samples: {e}"),
    };
    track.epochs.extend(finished.epochs.iter().map(epoch));
    track.seconds = clock.elapsed().as_secs_f64();
    (track, finished)
}

/// A session's epoch as the demo keeps it.
fn epoch(e: &schuler::session::Epoch) -> Epoch {
    Epoch {
        state: e.state,
        std: e.filter.map(|f| f.nav_std),
        wander_azimuth: (e.mechanization == MechanizationKind::Wander).then_some(e.wander_azimuth),
    }
}

/// The session configuration for `choice`, epochs once a second.
fn config(choice: MechanizationChoice) -> SessionConfig {
    SessionConfig {
        mechanization: MechanizationConfig {
            choice,
            ..MechanizationConfig::default()
        },
        output_rate: Some(1.0),
        ..SessionConfig::default()
    }
}

/// The inertial mode on the mechanization `choice`: free strapdown from `start`, the
/// vertical channel damped by the baro loop when `gains` are given.
pub fn inertial(
    rec: &Recording,
    start: &Start,
    gains: Option<Gains>,
    choice: MechanizationChoice,
    bar: &dyn Task,
) -> Track {
    let cfg = SessionConfig {
        baro_loop: gains.map(|gains| BaroLoopConfig {
            gains,
            detector: DetectorConfig::default(),
        }),
        ..config(choice)
    };
    let (mut track, finished) = run_session(rec, start, cfg, &[], bar);
    track.baro = finished.summary.baro_loop;
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

/// The inertial-satellite mode on the mechanization `choice`: the 15-state
/// error-state filter (plus the barometer bias) from `start` with the uncertainties
/// `prior`; returns the forward track and the Rauch–Tung–Striebel smoothed one (or
/// why the smoother's record could not be kept).
pub fn aided(
    rec: &Recording,
    start: &Start,
    prior: &Prior,
    settings: &AidedSettings,
    choice: MechanizationChoice,
    bar: &dyn Task,
) -> (Track, Result<Track, SpillError>) {
    let integration = IntegrationConfig {
        lever_arm: settings.lever_arm,
        baro: Some(settings.baro_bias),
        ..IntegrationConfig::new(ImuNoise::from_model(&rec.model))
    };
    let cfg = SessionConfig {
        filter: Some(prior.apply_to(FilterConfig {
            baro_std: settings.baro_std,
            smooth: true,
            ..FilterConfig::new(integration)
        })),
        ..config(choice)
    };
    let first_fix = rec.gnss.partition_point(|f| f.t <= start.state.t + 1e-9);
    let (mut forward, finished) = run_session(rec, start, cfg, &rec.gnss[first_fix..], bar);
    forward.sensors = finished
        .snapshots
        .iter()
        .map(|s| SensorEpoch {
            t: s.t,
            est: s.estimates,
            gyro_std: s.sensor_std[0],
            accel_std: s.sensor_std[1],
        })
        .collect();
    let clock = Instant::now();
    let smoothed = match finished.smoothed.map(|s| s.collect_states(Wgs84)) {
        Some(Ok(s)) => s,
        Some(Err(e)) => return (forward, Err(e)),
        None => Vec::new(),
    };
    let back = Track {
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
        seconds: forward.seconds + clock.elapsed().as_secs_f64(),
    };
    (forward, Ok(back))
}
