//! The vehicle aids of a session, applied after each integrated sample:
//!
//! - zero velocity (and rate) every [`RestConfig::interval`] inside a pushed rest
//!   interval (the increments summed over the block at rest), or at the end of each
//!   detector block whose window is at rest while the navigation's speed is below the
//!   configured limit;
//! - the non-holonomic constraint every `nhc.1` seconds;
//! - an odometer or heading reading at the sample ending nearest its time (the rule
//!   the barometer follows too, [`crate::filter::integration`]).
//!
//! Readings before the first sample or after the last are recorded as skipped.

use super::aid::AidQueues;
use super::config::{RestConfig, RestSource, VehicleConfig};
use crate::align::prefilter::BlockSums;
use crate::align::{Gravity, RestDetector};
use crate::earth::EarthModel;
use crate::filter::Integrator;
use crate::filter::integration::SkipReason;
use crate::filter::measurement::Kind;
use crate::imu::ImuSample;
use crate::nav::ErrorFrame;
use nalgebra::Vector3;

/// Blocks in the rest detector's window.
const DETECTOR_WINDOW: usize = 10;

/// Where a session stands in its vehicle aids.
#[derive(Debug, Clone)]
pub(crate) struct VehicleRun {
    cfg: VehicleConfig,
    detector: Option<RestDetector>,
    /// The increments at rest since the last zero-velocity update (pushed intervals).
    window: BlockSums,
    last_nhc: f64,
}

impl VehicleRun {
    pub fn new(cfg: VehicleConfig) -> Self {
        let detector = match &cfg.rest {
            Some(RestConfig {
                source: RestSource::Detect { noise, .. },
                interval,
                ..
            }) => Some(RestDetector::new(noise, *interval, DETECTOR_WINDOW)),
            _ => None,
        };
        Self {
            cfg,
            detector,
            window: BlockSums::default(),
            last_nhc: f64::NEG_INFINITY,
        }
    }

    /// The integrator with the states these aids need (the odometer scale factor, the
    /// mounting).
    pub fn configure<M: ErrorFrame, E: EarthModel>(
        &self,
        integ: Integrator<M, E>,
    ) -> Integrator<M, E> {
        let integ = match self.cfg.odometer_scale_std {
            Some(std) => integ.with_odometer_scale(std, 0.0),
            None => integ,
        };
        match self.cfg.mounting_std {
            Some(std) => integ.with_mounting(std),
            None => integ,
        }
    }

    /// Apply what is due after the sample `s` (raw, as pushed) was integrated.
    pub fn after_sample<M: ErrorFrame, E: EarthModel>(
        &mut self,
        integ: &mut Integrator<M, E>,
        queues: &mut AidQueues,
        s: &ImuSample,
    ) {
        let c = &self.cfg;
        let (early, due) = (s.t - 0.5 * s.dt, s.t + 0.5 * s.dt);
        if let Some(std) = c.odometer_std {
            while let Some(&(t, speed)) = queues.odometer.front().filter(|r| r.0 <= due) {
                queues.odometer.pop_front();
                if t <= early {
                    integ.skip_measurement(t, Kind::Odometer, SkipReason::BeforeImu);
                } else {
                    integ.update_odometer(t, speed, std, &c.mount);
                }
            }
        }
        if let Some(baseline) = &c.heading_baseline {
            while let Some(r) = queues.heading.front().copied().filter(|r| r.t <= due) {
                queues.heading.pop_front();
                if r.t <= early {
                    integ.skip_measurement(r.t, Kind::Heading, SkipReason::BeforeImu);
                } else {
                    integ.update_heading(&r, baseline);
                }
            }
        }
        if let Some((std, interval)) = c.nhc
            && s.t - self.last_nhc >= interval - 0.5 * s.dt
        {
            integ.update_non_holonomic(&c.mount, std);
            self.last_nhc = s.t;
        }
        if let Some(rest) = c.rest {
            self.rest(integ, queues, &rest, s);
        }
    }

    fn rest<M: ErrorFrame, E: EarthModel>(
        &mut self,
        integ: &mut Integrator<M, E>,
        queues: &mut AidQueues,
        rest: &RestConfig,
        s: &ImuSample,
    ) {
        let block = match (&rest.source, self.detector.as_mut()) {
            (RestSource::Intervals, _) => {
                while queues.rest.front().is_some_and(|iv| iv.1 < s.t) {
                    queues.rest.pop_front();
                }
                let inside = queues
                    .rest
                    .front()
                    .is_some_and(|&(a, b)| s.t - s.dt >= a - 1e-9 && s.t <= b);
                if !inside {
                    self.window = BlockSums::default();
                    return;
                }
                self.window.add(s);
                if self.window.t < rest.interval - 0.5 * s.dt {
                    return;
                }
                std::mem::take(&mut self.window)
            }
            (RestSource::Detect { max_speed, .. }, Some(detector)) => {
                if !detector.push(s) {
                    return;
                }
                let frame = integ.mechanization().frame();
                let p = integ.covariance();
                let tilt = (p[(6, 6)] + p[(7, 7)]).max(0.0).sqrt();
                let f_rest = frame.q_bc.inverse() * Vector3::new(0.0, 0.0, -frame.gravity);
                let v = detector.verdict(Gravity::Body(f_rest, tilt), frame.w_ie_c.norm());
                if !v.rest || frame.v_c.norm() > *max_speed {
                    return;
                }
                v.block
            }
            (RestSource::Detect { .. }, None) => return,
        };
        integ.update_zero_velocity(rest.std);
        if let Some(std) = rest.zaru_std {
            let window = ImuSample {
                t: s.t,
                dt: block.t,
                dtheta: block.dtheta,
                dvel: block.dvel,
            };
            integ.update_zero_rate(&window, std);
        }
    }

    /// Record the readings after the IMU data as skipped.
    pub fn finish<M: ErrorFrame, E: EarthModel>(
        &mut self,
        integ: &mut Integrator<M, E>,
        queues: &mut AidQueues,
    ) {
        for (t, _) in queues.odometer.drain(..) {
            integ.skip_measurement(t, Kind::Odometer, SkipReason::AfterImu);
        }
        for r in queues.heading.drain(..) {
            integ.skip_measurement(r.t, Kind::Heading, SkipReason::AfterImu);
        }
        queues.rest.clear();
    }
}
