//! The error sources of a budget: a partition of the filter's prior `P₀`, its process
//! noise density `Q` and its measurement noise `R` into independent parts.
//!
//! Each source is the filter's own configuration ([`IntegrationConfig`]) with every
//! term but its own set to zero: `P₀` is a sum of per-block variances
//! (`C diag(σ²) Cᵀ` for the navigation blocks, [`crate::filter::Integrator::new`]),
//! `Q` a sum of per-density terms ([`ErrorModel::process_noise`]) and the discrete
//! `Q_d` is linear in `Q` ([`ErrorModel::transition`]), so the masked parts add up to
//! the whole exactly and every matrix comes from the filter's own code.

use crate::filter::measurement::Kind;
use crate::filter::{ErrorModel, ImuNoise, IntegrationConfig, Layout};
use nalgebra::Vector3;

/// One independent error source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Source {
    /// Initial position error (prior `init_pos_std`).
    InitialPosition,
    /// Initial velocity error (`init_vel_std`).
    InitialVelocity,
    /// Initial tilt: attitude error about north and east (`init_att_std` x, y).
    InitialTilt,
    /// Initial heading error: attitude error about down (`init_att_std` z).
    InitialHeading,
    /// Gyro bias: its prior (a random constant).
    GyroBias,
    /// Gyro bias instability: the random walk (or Gauss–Markov) driving noise.
    GyroBiasWalk,
    /// Accelerometer bias: its prior.
    AccelBias,
    /// Accelerometer bias instability.
    AccelBiasWalk,
    /// Gyro white noise (angle random walk).
    AngleRandomWalk,
    /// Accelerometer white noise (velocity random walk).
    VelocityRandomWalk,
    /// Gyro scale-factor errors (prior, and the Gauss–Markov noise if finite `τ`).
    GyroScale,
    /// Accelerometer scale-factor errors.
    AccelScale,
    /// Barometer bias (prior and walk).
    BaroBias,
    /// The white noise of one kind of measurement (its `R`).
    Noise(Kind),
}

/// The sensor and prior sources, in table order.
pub const MODEL_SOURCES: [Source; 13] = [
    Source::InitialPosition,
    Source::InitialVelocity,
    Source::InitialTilt,
    Source::InitialHeading,
    Source::GyroBias,
    Source::GyroBiasWalk,
    Source::AccelBias,
    Source::AccelBiasWalk,
    Source::AngleRandomWalk,
    Source::VelocityRandomWalk,
    Source::GyroScale,
    Source::AccelScale,
    Source::BaroBias,
];

impl Source {
    /// Column name for tables (`gyro_bias`, `noise_gnss_position`, ...).
    pub fn name(self) -> String {
        match self {
            Source::InitialPosition => "initial_position".into(),
            Source::InitialVelocity => "initial_velocity".into(),
            Source::InitialTilt => "initial_tilt".into(),
            Source::InitialHeading => "initial_heading".into(),
            Source::GyroBias => "gyro_bias".into(),
            Source::GyroBiasWalk => "gyro_bias_walk".into(),
            Source::AccelBias => "accel_bias".into(),
            Source::AccelBiasWalk => "accel_bias_walk".into(),
            Source::AngleRandomWalk => "angle_random_walk".into(),
            Source::VelocityRandomWalk => "velocity_random_walk".into(),
            Source::GyroScale => "gyro_scale".into(),
            Source::AccelScale => "accel_scale".into(),
            Source::BaroBias => "baro_bias".into(),
            Source::Noise(kind) => format!("noise_{kind}"),
        }
    }

    /// The filter configuration with only this source's terms kept (standard
    /// deviations and densities of every other term zero; correlation times, the
    /// state layout and the lever arm unchanged). For [`Source::Noise`], nothing of
    /// the configuration is kept: its part is the measurement's `R` alone.
    pub fn keep(self, cfg: &IntegrationConfig) -> IntegrationConfig {
        let z = Vector3::zeros();
        let n = &cfg.noise;
        let sensor = cfg.init_sensor_std;
        let mut out = IntegrationConfig {
            noise: ImuNoise {
                arw: z,
                vrw: z,
                gyro_bias: z,
                gyro_bias_walk: z,
                accel_bias: z,
                accel_bias_walk: z,
                gyro_scale: z,
                accel_scale: z,
                ..*n
            },
            init_pos_std: z,
            init_vel_std: z,
            init_att_std: z,
            baro: cfg.baro.map(|_| (0.0, 0.0)),
            init_sensor_std: sensor.map(|_| [z; 4]),
            ..*cfg
        };
        // Keep the prior of sensor block `i` (0: gyro bias, 1: accelerometer bias,
        // 2: gyro scale, 3: accelerometer scale) whichever of the two it comes from.
        let keep_sensor = |i: usize, out: &mut IntegrationConfig| {
            if let (Some(s), Some(o)) = (sensor, out.init_sensor_std.as_mut()) {
                o[i] = s[i];
            }
        };
        match self {
            Source::InitialPosition => out.init_pos_std = cfg.init_pos_std,
            Source::InitialVelocity => out.init_vel_std = cfg.init_vel_std,
            Source::InitialTilt => {
                out.init_att_std = Vector3::new(cfg.init_att_std.x, cfg.init_att_std.y, 0.0)
            }
            Source::InitialHeading => out.init_att_std = Vector3::new(0.0, 0.0, cfg.init_att_std.z),
            Source::GyroBias => {
                out.noise.gyro_bias = n.gyro_bias;
                keep_sensor(0, &mut out);
            }
            Source::AccelBias => {
                out.noise.accel_bias = n.accel_bias;
                keep_sensor(1, &mut out);
            }
            Source::GyroScale => {
                out.noise.gyro_scale = n.gyro_scale;
                keep_sensor(2, &mut out);
            }
            Source::AccelScale => {
                out.noise.accel_scale = n.accel_scale;
                keep_sensor(3, &mut out);
            }
            Source::GyroBiasWalk => out.noise.gyro_bias_walk = n.gyro_bias_walk,
            Source::AccelBiasWalk => out.noise.accel_bias_walk = n.accel_bias_walk,
            Source::AngleRandomWalk => out.noise.arw = n.arw,
            Source::VelocityRandomWalk => out.noise.vrw = n.vrw,
            Source::BaroBias => out.baro = cfg.baro,
            Source::Noise(_) => {}
        }
        out
    }
}

/// The process model of a masked configuration on `layout`: the filter's
/// [`ErrorModel`] as [`crate::filter::Integrator::new`] makes it (no odometer walk, the
/// default clock: neither has a state here).
pub fn process_model(layout: Layout, cfg: &IntegrationConfig) -> ErrorModel {
    ErrorModel {
        layout,
        noise: cfg.noise,
        baro_bias_walk: cfg.baro.map_or(0.0, |(_, walk)| walk),
        odometer_scale_walk: 0.0,
        clock: Default::default(),
        time_offset_walk: cfg.calibration.time_offset_walk,
    }
}
