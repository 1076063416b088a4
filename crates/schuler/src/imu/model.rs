//! The IMU error model's parameters in SI: [`ImuModel`] (one [`TriadModel`] per
//! triad, g-sensitivity, [`VibrationLine`]s), a description of a sensor that the
//! filter's noise model and the simulator ([`crate::sim::imu_model::ImuSimulator`])
//! both read.
//!
//! Per triad (SI: gyro in rad/s, accelerometer in m/s^2), over one interval `dt`:
//!
//! `y = (I + diag(s) + diag(a) sign(x) + M) x + (b + b_on + b_gm + b_rw) dt + n + G dv + vib`
//!
//! - `b`: constant bias; `b_on`: turn-on bias, drawn once per run with std `turn_on`;
//! - `b_gm`: first-order Gauss–Markov bias instability, `b_k = e^{-dt/τ} b_{k-1} +
//!   σ sqrt(1 - e^{-2dt/τ}) w` (stationary std `σ`, correlation time `τ`);
//! - `b_rw`: rate (or acceleration) random walk, `b_rw += K sqrt(dt) w`;
//! - `n`: angle (velocity) random walk: white rate noise of density `N`, an increment
//!   noise of std `N sqrt(dt)` (IEEE Std 952-1997 annex C);
//! - `s`, `a`: scale-factor error and its asymmetry (`a` times the sign of the input);
//! - `M`: misalignment and non-orthogonality (off-diagonal, rad);
//! - `G dv`: gyro g-sensitivity, rad/s per m/s^2 times the true velocity increment;
//! - `vib`: accelerometer vibration lines `A sin(2π f t + φ)` integrated exactly;
//! - quantization to a step `q` with the residual carried to the next sample, so the
//!   sum of the outputs never drifts from the sum of the inputs by more than `q`.

use nalgebra::{Matrix3, Vector3};

/// One sinusoidal vibration line on the accelerometers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VibrationLine {
    /// Frequency [Hz].
    pub freq_hz: f64,
    /// Amplitude per axis [m/s^2].
    pub amplitude: Vector3<f64>,
    /// Phase [rad].
    pub phase: f64,
}

/// Error parameters of one triad (all per axis, SI).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriadModel {
    /// Constant bias.
    pub bias: Vector3<f64>,
    /// Standard deviation of the turn-on bias (random per run).
    pub turn_on: Vector3<f64>,
    /// Gauss–Markov bias instability: stationary standard deviation.
    pub gm_sigma: Vector3<f64>,
    /// Gauss–Markov correlation time [s] (> 0 where `gm_sigma` > 0).
    pub gm_tau: Vector3<f64>,
    /// White-noise density (ARW [rad/sqrt(s)] or VRW [m/s/sqrt(s)]).
    pub white: Vector3<f64>,
    /// Random-walk rate of the bias [unit/sqrt(s)].
    pub random_walk: Vector3<f64>,
    /// Scale-factor error (dimensionless).
    pub scale: Vector3<f64>,
    /// Scale-factor asymmetry (dimensionless).
    pub asymmetry: Vector3<f64>,
    /// Misalignment / non-orthogonality (diagonal ignored) [rad].
    pub misalignment: Matrix3<f64>,
    /// Quantization step of the increments (0: none) [rad or m/s].
    pub quantum: Vector3<f64>,
}

/// The whole IMU's error parameters.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ImuModel {
    /// Gyro triad.
    pub gyro: TriadModel,
    /// Accelerometer triad.
    pub accel: TriadModel,
    /// Gyro g-sensitivity [rad/s per m/s^2].
    pub g_sensitivity: Matrix3<f64>,
    /// Accelerometer vibration lines.
    pub vibration: Vec<VibrationLine>,
}
