//! The IMU noise model of the filter: white noise densities and bias statistics.
//!
//! Biases are modelled either as a random constant plus a random walk whose rate
//! matches a first-order Gauss–Markov instability over times short against its
//! correlation time `τ`: `E[(b(t) − b(0))²] = 2σ²(1 − e^{−t/τ}) ≈ (2σ²/τ) t` (driving
//! density `2σ²/τ`; `*_bias_tau` infinite, the default for a sensor model whose
//! constant and turn-on parts dominate), or as the Gauss–Markov process itself,
//! `ḃ = −b/τ + w` with the same density (finite `τ`, as KF-GINS models them). The prior
//! is the total of constant, turn-on and instability variances.

use crate::imu::model::{ImuModel, TriadModel};
use nalgebra::Vector3;

/// Noise and bias statistics per axis (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuNoise {
    /// Angle random walk [rad/sqrt(s)].
    pub arw: Vector3<f64>,
    /// Velocity random walk [m/s/sqrt(s)].
    pub vrw: Vector3<f64>,
    /// Prior standard deviation of the gyro bias [rad/s].
    pub gyro_bias: Vector3<f64>,
    /// Gyro bias random-walk density [rad/s/sqrt(s)].
    pub gyro_bias_walk: Vector3<f64>,
    /// Prior standard deviation of the accelerometer bias [m/s^2].
    pub accel_bias: Vector3<f64>,
    /// Accelerometer bias random-walk density [m/s^2/sqrt(s)].
    pub accel_bias_walk: Vector3<f64>,
    /// Gauss–Markov correlation time of the gyro bias [s] (infinite: random walk).
    pub gyro_bias_tau: f64,
    /// Gauss–Markov correlation time of the accelerometer bias [s].
    pub accel_bias_tau: f64,
    /// Prior standard deviation of the gyro scale-factor error.
    pub gyro_scale: Vector3<f64>,
    /// Prior standard deviation of the accelerometer scale-factor error.
    pub accel_scale: Vector3<f64>,
    /// Gauss–Markov correlation time of the scale-factor errors [s] (infinite:
    /// constants); finite, they vary with the stationary standard deviations above.
    pub scale_tau: f64,
}

fn prior(t: &TriadModel) -> Vector3<f64> {
    (t.bias.component_mul(&t.bias)
        + t.turn_on.component_mul(&t.turn_on)
        + t.gm_sigma.component_mul(&t.gm_sigma))
    .map(f64::sqrt)
}

fn walk(t: &TriadModel) -> Vector3<f64> {
    let gm = Vector3::from_fn(|i, _| {
        if t.gm_tau[i] > 0.0 {
            t.gm_sigma[i] * (2.0 / t.gm_tau[i]).sqrt()
        } else {
            0.0
        }
    });
    (gm.component_mul(&gm) + t.random_walk.component_mul(&t.random_walk)).map(f64::sqrt)
}

impl ImuNoise {
    /// The statistics of a sensor error model (the simulator's, or a preset's).
    pub fn from_model(m: &ImuModel) -> Self {
        Self {
            arw: m.gyro.white,
            vrw: m.accel.white,
            gyro_bias: prior(&m.gyro),
            gyro_bias_walk: walk(&m.gyro),
            accel_bias: prior(&m.accel),
            accel_bias_walk: walk(&m.accel),
            gyro_bias_tau: f64::INFINITY,
            accel_bias_tau: f64::INFINITY,
            gyro_scale: m.gyro.scale.abs(),
            accel_scale: m.accel.scale.abs(),
            scale_tau: f64::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prior_adds_variances_and_walk_matches_gauss_markov_growth() {
        let mut m = ImuModel::default();
        m.gyro.bias = Vector3::repeat(3.0);
        m.gyro.turn_on = Vector3::repeat(4.0);
        m.gyro.gm_sigma = Vector3::repeat(12.0);
        m.gyro.gm_tau = Vector3::repeat(8.0);
        let n = ImuNoise::from_model(&m);
        // sqrt(9 + 16 + 144) = 13.
        assert_eq!(n.gyro_bias, Vector3::repeat(13.0));
        // 2 sigma^2 / tau = 2 * 144 / 8 = 36.
        assert!((n.gyro_bias_walk.x - 6.0).abs() < 1e-12);
        assert_eq!(n.accel_bias_walk, Vector3::zeros());
    }
}
