//! The receiver's clock: bias and drift driven by white frequency noise and random-walk
//! frequency noise, the two-state model of Brown & Hwang (*Introduction to Random
//! Signals and Applied Kalman Filtering*, 4th ed. 2012, §9.3).
//!
//! `ḃ = d + w_b`, `ḋ = w_d` with spectral densities `q_b = h₀/2` [s²/s] and
//! `q_d = 2π²·h₋₂` [s²/s³] from the Allan-variance coefficients `h₀` (white frequency)
//! and `h₋₂` (random-walk frequency). Over a step Δt the exact discrete process noise
//! is `Q = [[q_b Δt + q_d Δt³/3, q_d Δt²/2], [q_d Δt²/2, q_d Δt]]`, drawn through its
//! Cholesky factor.

use crate::imu::random::Noise;

/// A temperature-compensated crystal's `h₀` (Brown & Hwang 2012, Table 9.1): 2e-19.
pub const TCXO_H0: f64 = 2e-19;
/// A temperature-compensated crystal's `h₋₂` (Brown & Hwang 2012, Table 9.1): 2e-20.
pub const TCXO_H_2: f64 = 2e-20;

/// The clock's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClockModel {
    /// Bias at the first epoch [s] (the receiver's reading minus GPS time).
    pub bias: f64,
    /// Drift at the first epoch [s/s].
    pub drift: f64,
    /// White-frequency coefficient h₀ [s].
    pub h0: f64,
    /// Random-walk-frequency coefficient h₋₂ [1/s].
    pub h_2: f64,
}

impl ClockModel {
    /// The discrete process noise's Cholesky factor `[l11, l21, l22]` over `dt` [s].
    fn cholesky(&self, dt: f64) -> [f64; 3] {
        let q_b = self.h0 / 2.0;
        let q_d = 2.0 * std::f64::consts::PI * std::f64::consts::PI * self.h_2;
        let q11 = q_b * dt + q_d * dt * dt * dt / 3.0;
        let q21 = q_d * dt * dt / 2.0;
        let q22 = q_d * dt;
        let l11 = q11.sqrt();
        let l21 = if l11 > 0.0 { q21 / l11 } else { 0.0 };
        let l22 = (q22 - l21 * l21).max(0.0).sqrt();
        [l11, l21, l22]
    }
}

/// A running clock, stepped at a fixed interval.
#[derive(Debug, Clone)]
pub struct Clock {
    /// Bias [s].
    pub bias: f64,
    /// Drift [s/s].
    pub drift: f64,
    l: [f64; 3],
    dt: f64,
}

impl Clock {
    /// The clock of `model` stepped every `dt` [s].
    pub fn new(model: &ClockModel, dt: f64) -> Self {
        Self {
            bias: model.bias,
            drift: model.drift,
            l: model.cholesky(dt),
            dt,
        }
    }

    /// One step: two standard normals from `noise` (always two, whatever the model).
    pub fn step(&mut self, noise: &mut Noise) {
        let (n1, n2) = (noise.normal(), noise.normal());
        let [l11, l21, l22] = self.l;
        self.bias += self.drift * self.dt + l11 * n1;
        self.drift += l21 * n1 + l22 * n2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sample variance of the bias after n steps from zero against the
    /// continuous model's `q_b t + q_d t³/3`: 4000 runs, within 10 % (the sample
    /// variance of 4000 normals has a relative σ of √(2/4000) = 2.2 %: 10 % is 4.5σ).
    #[test]
    fn bias_variance_grows_as_the_model_says() {
        let model = ClockModel {
            bias: 0.0,
            drift: 0.0,
            h0: TCXO_H0,
            h_2: TCXO_H_2,
        };
        let (dt, n, runs) = (1.0, 100, 4000);
        let mut noise = Noise::new(11, 99);
        let (mut s2b, mut s2d) = (0.0, 0.0);
        for _ in 0..runs {
            let mut c = Clock::new(&model, dt);
            for _ in 0..n {
                c.step(&mut noise);
            }
            s2b += c.bias * c.bias;
            s2d += c.drift * c.drift;
        }
        let t = f64::from(n) * dt;
        let q_b = TCXO_H0 / 2.0;
        let q_d = 2.0 * std::f64::consts::PI.powi(2) * TCXO_H_2;
        let want_b = q_b * t + q_d * t * t * t / 3.0;
        let want_d = q_d * t;
        let got_b = s2b / f64::from(runs);
        let got_d = s2d / f64::from(runs);
        assert!((got_b / want_b - 1.0).abs() < 0.1, "{got_b} {want_b}");
        assert!((got_d / want_d - 1.0).abs() < 0.1, "{got_d} {want_d}");
    }

    #[test]
    fn a_quiet_clock_keeps_its_drift() {
        let model = ClockModel {
            bias: 1e-4,
            drift: 1e-8,
            h0: 0.0,
            h_2: 0.0,
        };
        let mut c = Clock::new(&model, 1.0);
        let mut noise = Noise::new(1, 1);
        for _ in 0..10 {
            c.step(&mut noise);
        }
        assert!((c.bias - (1e-4 + 10.0 * 1e-8)).abs() < 1e-18);
        assert_eq!(c.drift, 1e-8);
    }
}
