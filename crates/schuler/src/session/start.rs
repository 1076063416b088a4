//! Where a session starts: the state the first IMU sample carries, the sensor errors
//! known then, and the filter's uncertainty about them — made in one place from an
//! alignment, for every front end.

use super::FilterConfig;
use super::config::{ConfigError, each_within, within};
use crate::align::Alignment;
use crate::align::in_motion::InMotionStart;
use crate::domain;
use crate::filter::{IntegrationConfig, SensorEstimates};
use crate::nav::NavState;
use nalgebra::{SMatrix, Vector3};

/// The start of a session.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// Position, velocity and attitude at the first IMU sample pushed (its time
    /// replaces `state.t`; the sample's increments prime the two-sample corrections).
    pub state: NavState,
    /// Sensor errors removed from every sample from the first on (the filter's first
    /// estimates when it runs).
    pub estimates: SensorEstimates,
}

impl Start {
    /// Checks the start against the physical domains ([`crate::domain`]): position,
    /// velocity, a finite time and attitude, and sensor errors within what a sensor
    /// reads. The error names the field as `start.…`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let s = &self.state;
        within("start.state.pos.lat", &domain::LATITUDE, s.pos.lat)?;
        within("start.state.pos.lon", &domain::LONGITUDE, s.pos.lon)?;
        within("start.state.pos.h", &domain::HEIGHT, s.pos.h)?;
        each_within("start.state.v_n", &domain::SPEED, &s.v_n)?;
        if !(s.t.is_finite() && s.q_bn.coords.iter().all(|x| x.is_finite())) {
            return Err(ConfigError::new(
                "start.state.q_bn",
                "the time and the attitude must be finite",
            ));
        }
        let e = &self.estimates;
        each_within(
            "start.estimates.gyro_bias",
            &domain::ANGULAR_RATE_COMPONENT,
            &e.gyro_bias,
        )?;
        each_within(
            "start.estimates.accel_bias",
            &domain::SPECIFIC_FORCE_COMPONENT,
            &e.accel_bias,
        )?;
        each_within(
            "start.estimates.gyro_scale",
            &domain::SCALE_FACTOR,
            &e.gyro_scale,
        )?;
        each_within(
            "start.estimates.accel_scale",
            &domain::SCALE_FACTOR,
            &e.accel_scale,
        )?;
        Ok(())
    }

    /// At `state` with no sensor error known.
    pub fn at(state: NavState) -> Self {
        Self {
            state,
            estimates: SensorEstimates::default(),
        }
    }

    /// The start an alignment gives: its state at the end of the fine stage, at rest,
    /// with the gyro and accelerometer biases it estimated.
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

impl Start {
    /// The start a start in motion gives (no sensor error known).
    pub fn from_motion(m: &InMotionStart) -> Self {
        Self::at(m.state)
    }
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
    /// The joint covariance of the attitude error (about north, east, down), the gyro
    /// and the accelerometer biases, when known with its correlations (overrides
    /// `att_std` and `bias_std`).
    pub att_bias_cov: Option<SMatrix<f64, 9, 9>>,
}

impl Prior {
    /// Velocity standard deviation after an alignment at rest [m/s]: the vehicle was
    /// held still, so only the rest's own jitter remains.
    pub const ALIGNED_VELOCITY_STD: f64 = 0.01;

    /// After an alignment at rest at a position known to `pos_std` [m] (NED): velocity
    /// held at zero ([`Prior::ALIGNED_VELOCITY_STD`]), attitude and biases with the
    /// covariance the alignment's fine filter reached, correlations included (at rest
    /// a tilt and the horizontal accelerometer bias along it are one unknown, the
    /// specific force's direction, so only their combination is known closely; in
    /// motion the filter separates them), or the coarse stage's standard deviations.
    pub fn from_alignment(a: &Alignment, pos_std: Vector3<f64>) -> Self {
        let att_bias_cov = a.fine.as_ref().map(|f| {
            let o = crate::filter::Layout::ATT;
            SMatrix::<f64, 9, 9>::from_fn(|i, j| f.covariance[(o + i, o + j)])
        });
        Self {
            pos_std,
            vel_std: Vector3::repeat(Self::ALIGNED_VELOCITY_STD),
            att_std: a.attitude_std,
            bias_std: Some([a.gyro_bias_std, a.accel_bias_std]),
            att_bias_cov,
        }
    }

    /// After a start in motion: the standard deviations it derived, the biases at the
    /// IMU model's prior.
    pub fn from_motion(m: &InMotionStart) -> Self {
        Self {
            pos_std: m.pos_std,
            vel_std: m.vel_std,
            att_std: m.att_std,
            bias_std: None,
            att_bias_cov: None,
        }
    }

    /// `filter` with this prior as its initial covariance (scale factors keep the
    /// noise model's prior).
    pub fn apply_to(&self, mut filter: FilterConfig) -> FilterConfig {
        filter.integration = self.apply(filter.integration);
        filter.att_bias_cov = self.att_bias_cov;
        filter
    }

    /// `cfg` with this prior's standard deviations (without the correlations of
    /// [`Prior::att_bias_cov`], which [`Prior::apply_to`] carries).
    pub fn apply(&self, mut cfg: IntegrationConfig) -> IntegrationConfig {
        cfg.init_pos_std = self.pos_std;
        cfg.init_vel_std = self.vel_std;
        cfg.init_att_std = self.att_std;
        if let Some([g, a]) = self.bias_std {
            let old = cfg.init_sensor_std;
            cfg.init_sensor_std = Some([
                g,
                a,
                old.map_or(cfg.noise.gyro_scale, |o| o[2]),
                old.map_or(cfg.noise.accel_scale, |o| o[3]),
            ]);
        }
        cfg
    }
}
