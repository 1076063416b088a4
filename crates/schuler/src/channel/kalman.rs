//! Kalman-filter variant of the aided vertical channel (text at the end of section 3.2:
//! the optimal filter gives feedback of the same form as (34) with time-varying gains).
//!
//! State `[h̃, Ṽ]`, propagated exactly as the constant-gain loop predicts (38) (RK4 on
//! the nonlinear equations); covariance through the linearized free channel
//! `F = [[0, 1], [2ω0², 0]]` (32) with white accelerometer noise of density `q`
//! [m²/s³] on the velocity: `Φ = exp(F dt)` and `Q_d` by Van Loan's method
//! (exp of `[[-F, G q Gᵀ], [0, Fᵀ]] dt`, both with [`super::expm::expm`]).
//! Update with the reference height, variance `R = σ²`:
//! `K = P Hᵀ / (H P Hᵀ + R)`, Joseph form for P. The update is the discrete form of
//! (34): over a step, `k1 = -K_h / dt`, `k2 = -K_v / dt` (reported per sample).
//! Gate: innovations beyond `gate_sigmas * sqrt(HPHᵀ + R)` are rejected (the gate widens
//! by itself as P grows in prediction); on reacquisition after a run of consistent
//! rejected samples, `P_hh` is inflated by the innovation squared so the filter trusts
//! the returning reference.

use super::ChannelError;
use super::detector::{DetectorConfig, FaultDetector};
use super::error::{finite, positive};
use super::expm::expm;
use super::vertical::{DetectorCounts, Mode, VerticalConfig};
use nalgebra::{Matrix2, Matrix4, Vector2};

/// Tuning of the Kalman variant (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanTuning {
    /// Accelerometer white-noise density (velocity random walk) [m/s/sqrt(s)].
    pub accel_noise: f64,
    /// Reference-height standard deviation \[m\] (R = σ²).
    pub ref_sigma: f64,
    /// Initial height standard deviation \[m\].
    pub sigma_h0: f64,
    /// Initial vertical-velocity standard deviation [m/s].
    pub sigma_v0: f64,
    /// Gate in innovation standard deviations.
    pub gate_sigmas: f64,
}

impl KalmanTuning {
    /// Checks every value is finite and positive.
    pub fn validate(&self) -> Result<(), ChannelError> {
        positive("Kalman accelerometer noise", self.accel_noise)?;
        positive("Kalman reference sigma", self.ref_sigma)?;
        positive("Kalman initial height sigma", self.sigma_h0)?;
        positive("Kalman initial velocity sigma", self.sigma_v0)?;
        positive("Kalman gate", self.gate_sigmas)?;
        Ok(())
    }
}

/// One sample of the Kalman run (after the update at `t`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanSample {
    /// Time \[s\].
    pub t: f64,
    /// Height error \[m\].
    pub dh: f64,
    /// Vertical-velocity error [m/s].
    pub dvh: f64,
    /// Whether the sample was used.
    pub mode: Mode,
    /// Equivalent gain k1 = -K_h/dt [1/s] (0 when predicting).
    pub k1: f64,
    /// Equivalent gain k2 = -K_v/dt [1/s²] (0 when predicting).
    pub k2: f64,
    /// Filter's height standard deviation sqrt(P_hh) \[m\].
    pub sigma_h: f64,
}

/// A Kalman run.
#[derive(Debug, Clone, PartialEq)]
pub struct KalmanRun {
    /// One sample per grid point.
    pub samples: Vec<KalmanSample>,
    /// What the detector did.
    pub counts: DetectorCounts,
}

/// Transition matrix and process noise of the free channel over `h` (Van Loan).
fn discretize(w0_sq: f64, q: f64, h: f64) -> Result<(Matrix2<f64>, Matrix2<f64>), ChannelError> {
    let f = Matrix2::new(0.0, 1.0, 2.0 * w0_sq, 0.0);
    let mut m = Matrix4::zeros();
    m.fixed_view_mut::<2, 2>(0, 0).copy_from(&(-f * h));
    m[(1, 3)] = q * h;
    m.fixed_view_mut::<2, 2>(2, 2)
        .copy_from(&(f.transpose() * h));
    let e = expm(&m)?;
    let phi = e.fixed_view::<2, 2>(2, 2).transpose();
    let qd = phi * e.fixed_view::<2, 2>(0, 2);
    // Symmetrize against round-off.
    Ok((phi, (qd + qd.transpose()) * 0.5))
}

/// Runs the Kalman variant on the same reference samples as the constant-gain loop.
pub fn simulate_kalman(
    cfg: &VerticalConfig,
    tuning: KalmanTuning,
    reference: &[Option<f64>],
    detector: DetectorConfig,
) -> Result<KalmanRun, ChannelError> {
    cfg.validate()?;
    tuning.validate()?;
    let grid = cfg.grid();
    if reference.len() != grid.steps + 1 {
        return Err(ChannelError::ReferenceLength {
            expected: grid.steps + 1,
            got: reference.len(),
        });
    }
    let w0_sq = cfg.w0_sq();
    let q = tuning.accel_noise * tuning.accel_noise;
    let r = tuning.ref_sigma * tuning.ref_sigma;
    let (phi, qd) = discretize(w0_sq, q, grid.dt)?;
    let mut det = FaultDetector::new(detector);
    let mut counts = DetectorCounts::default();
    let mut x = Vector2::new(cfg.height + cfg.init_height_error, cfg.init_vel_error);
    let mut p = Matrix2::new(tuning.sigma_h0.powi(2), 0.0, 0.0, tuning.sigma_v0.powi(2));
    let mut out = Vec::with_capacity(grid.steps + 1);
    for (k, sample) in reference.iter().enumerate() {
        let t = grid.time(k);
        let nu = sample.map(|h| h - x[0]);
        let s = p[(0, 0)] + r;
        let gate = tuning.gate_sigmas * s.sqrt();
        let verdict = det.assess(nu, gate);
        counts.count(verdict);
        let (mut k1, mut k2) = (0.0, 0.0);
        if let (true, Some(nu)) = (verdict.is_aided(), nu) {
            if verdict == super::detector::Verdict::Reacquire {
                p[(0, 0)] += nu * nu;
            }
            let s = p[(0, 0)] + r;
            let gain = Vector2::new(p[(0, 0)], p[(1, 0)]) / s;
            x += gain * nu;
            let ikh = Matrix2::new(1.0 - gain[0], 0.0, -gain[1], 1.0);
            p = ikh * p * ikh.transpose() + gain * gain.transpose() * r;
            k1 = -gain[0] / grid.dt;
            k2 = -gain[1] / grid.dt;
        }
        finite("Kalman height", x[0])?;
        out.push(KalmanSample {
            t,
            dh: x[0] - cfg.height,
            dvh: x[1],
            mode: if verdict.is_aided() {
                Mode::Aided
            } else {
                Mode::Predict
            },
            k1,
            k2,
            sigma_h: p[(0, 0)].sqrt(),
        });
        if k < grid.steps {
            let h = grid.time(k + 1) - t;
            x = cfg.predict(&x, h);
            let (phi_h, qd_h) = if (h - grid.dt).abs() > 1e-12 * grid.dt {
                discretize(w0_sq, q, h)?
            } else {
                (phi, qd)
            };
            p = phi_h * p * phi_h.transpose() + qd_h;
        }
    }
    Ok(KalmanRun {
        samples: out,
        counts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn van_loan_matches_the_white_noise_integral_for_small_w0() {
        // With w0 -> 0 the channel is a double integrator: Q_d = q [[h³/3, h²/2], [h²/2, h]].
        let (phi, qd) = discretize(0.0, 2.0, 0.5).unwrap();
        assert!((phi - Matrix2::new(1.0, 0.5, 0.0, 1.0)).amax() < 1e-15);
        let want = Matrix2::new(2.0 * 0.125 / 3.0, 2.0 * 0.125, 2.0 * 0.125, 1.0);
        assert!((qd - want).amax() < 1e-14, "{qd}");
    }
}
