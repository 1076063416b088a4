//! Psi-angle error dynamics of a local-level strapdown mechanization (errors in the
//! computation frame `c`, see [`crate::nav::frame`]), `ẋ = F x + w`:
//!
//! - `δṙ = −ρ×δr + δv`
//! - `δv̇ = G δr − (2ω_ie + ρ)×δv + f^c×ψ + Ĉ_cb (δb_a + diag(f^b) δs_a)`,
//!   `G = (g/r) diag(−1, −1, 2)` (gravity gradient, down positive)
//! - `ψ̇ = −(ω_ie + ρ)×ψ − Ĉ_cb (δb_g + diag(ω^b) δs_g)`
//! - residual biases: random walks or Gauss–Markov, `ḃ = −b/τ + w` ([`super::noise`]);
//!   scale factors, the baro bias, the odometer scale factor, the reference attitude
//!   and the calibrations ([`super::calibration`]): constants (the baro bias, the
//!   odometer scale factor and the GNSS time offset with an optional walk);
//! - receiver clock (tight coupling): `ḃ_s = d + w_b` for each system's bias and
//!   `ḋ = w_d`, the two-state clock of Brown & Hwang (2012, §9.3), white `w_b`, `w_d`
//!   of densities [`ClockNoise`], one `w_b` for every system (one oscillator: the
//!   inter-system biases are constants).
//!
//! `ρ` is the transport rate of `c` (with zero vertical component in the wander frame),
//! so nothing here is singular at a pole (Savage 2000, §12.2; Titterton & Weston 2004,
//! §12.3.2 for the NED special case).
//!
//! Discretization over an interval `T` with the means of the interval: `Φ = I + A +
//! A²/2 + A³/6` with `A = F T` (the cubic term carries the gyro bias into position),
//! and `Q_d = Q T + (F Q + Q Fᵀ) T²/2 + F Q Fᵀ T³/3`.

use super::layout::Layout;
use super::noise::ImuNoise;
use crate::nav::FrameSnapshot;
use crate::rotation::skew;
use nalgebra::{DMatrix, Matrix3, Vector3};

/// The mean kinematics over one propagation interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntervalMeans {
    /// Interval length [s].
    pub dt: f64,
    /// The computation frame (at the interval's end).
    pub frame: FrameSnapshot,
    /// Mean specific force in `c` [m/s^2].
    pub f_c: Vector3<f64>,
    /// Mean specific force in body axes [m/s^2].
    pub f_b: Vector3<f64>,
    /// Mean angular rate in body axes [rad/s].
    pub w_b: Vector3<f64>,
}

/// The process model: state layout and noise.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorModel {
    /// State layout.
    pub layout: Layout,
    /// IMU noise.
    pub noise: ImuNoise,
    /// Barometer bias random-walk density [m/sqrt(s)].
    pub baro_bias_walk: f64,
    /// Odometer scale-factor random-walk density [1/sqrt(s)].
    pub odometer_scale_walk: f64,
    /// The receiver clock's noise, with clock states.
    pub clock: ClockNoise,
    /// GNSS time offset random-walk density [s/sqrt(s)] (with its state).
    pub time_offset_walk: f64,
}

/// The receiver clock's white-noise densities: `q_b` [m²/s] drives the biases,
/// `q_d` [m²/s³] the drift. From an oscillator's Allan-variance coefficients
/// `h₀`, `h₋₂`: `q_b = c²·h₀/2`, `q_d = c²·2π²·h₋₂` (Brown & Hwang 2012, §9.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClockNoise {
    /// Bias density [m²/s].
    pub q_b: f64,
    /// Drift density [m²/s³].
    pub q_d: f64,
}

impl ClockNoise {
    /// From Allan-variance coefficients `h0` [s] and `h_2` [1/s].
    pub fn from_allan(h0: f64, h_2: f64) -> Self {
        let c2 = crate::gnss::C * crate::gnss::C;
        Self {
            q_b: c2 * h0 / 2.0,
            q_d: c2 * 2.0 * std::f64::consts::PI.powi(2) * h_2,
        }
    }

    /// A temperature-compensated crystal (TCXO), the oscillator of most receivers and
    /// phones: h₀ = 2e-19 s, h₋₂ = 2e-20 /s (Brown & Hwang 2012, Table 9.1), so
    /// q_b ≈ 9.0e-3 m²/s, q_d ≈ 3.6e-2 m²/s³.
    pub fn tcxo() -> Self {
        Self::from_allan(2e-19, 2e-20)
    }
}

impl Default for ClockNoise {
    fn default() -> Self {
        Self::tcxo()
    }
}

fn put(m: &mut DMatrix<f64>, r: usize, c: usize, b: &Matrix3<f64>) {
    m.fixed_view_mut::<3, 3>(r, c).copy_from(b);
}

impl ErrorModel {
    /// The continuous-time dynamics matrix `F` for the interval's means.
    pub fn dynamics(&self, m: &IntervalMeans) -> DMatrix<f64> {
        let (l, f) = (&self.layout, &m.frame);
        let n = l.n;
        let mut a = DMatrix::zeros(n, n);
        let c_bc = f.q_bc.to_rotation_matrix().into_inner();
        let (p, v, att) = (Layout::POS, Layout::VEL, Layout::ATT);
        put(&mut a, p, p, &(-skew(&f.rho_c)));
        put(&mut a, p, v, &Matrix3::identity());
        let gr = f.gravity / f.radius;
        put(
            &mut a,
            v,
            p,
            &Matrix3::from_diagonal(&Vector3::new(-gr, -gr, 2.0 * gr)),
        );
        put(&mut a, v, v, &(-skew(&(2.0 * f.w_ie_c + f.rho_c))));
        put(&mut a, v, att, &skew(&m.f_c));
        put(&mut a, v, Layout::ACCEL_BIAS, &c_bc);
        put(&mut a, att, att, &(-skew(&(f.w_ie_c + f.rho_c))));
        put(&mut a, att, Layout::GYRO_BIAS, &(-c_bc));
        for i in 0..3 {
            a[(Layout::GYRO_BIAS + i, Layout::GYRO_BIAS + i)] = -1.0 / self.noise.gyro_bias_tau;
            a[(Layout::ACCEL_BIAS + i, Layout::ACCEL_BIAS + i)] = -1.0 / self.noise.accel_bias_tau;
        }
        for o in [l.gyro_scale, l.accel_scale].into_iter().flatten() {
            for i in 0..3 {
                a[(o + i, o + i)] = -1.0 / self.noise.scale_tau;
            }
        }
        if let Some(sg) = l.gyro_scale {
            put(&mut a, att, sg, &(-c_bc * Matrix3::from_diagonal(&m.w_b)));
        }
        if let Some(sa) = l.accel_scale {
            put(&mut a, v, sa, &(c_bc * Matrix3::from_diagonal(&m.f_b)));
        }
        if let (Some(b), Some(d)) = (l.clock, l.clock_drift()) {
            for i in 0..l.clock_systems {
                a[(b + i, d)] = 1.0;
            }
        }
        a
    }

    /// The continuous-time process noise density `Q`.
    pub fn process_noise(&self, m: &IntervalMeans) -> DMatrix<f64> {
        let (l, nz) = (&self.layout, &self.noise);
        let mut q = DMatrix::zeros(l.n, l.n);
        let c_bc = m.frame.q_bc.to_rotation_matrix().into_inner();
        let sq = |v: &Vector3<f64>| Matrix3::from_diagonal(&v.component_mul(v));
        put(
            &mut q,
            Layout::VEL,
            Layout::VEL,
            &(c_bc * sq(&nz.vrw) * c_bc.transpose()),
        );
        put(
            &mut q,
            Layout::ATT,
            Layout::ATT,
            &(c_bc * sq(&nz.arw) * c_bc.transpose()),
        );
        put(
            &mut q,
            Layout::GYRO_BIAS,
            Layout::GYRO_BIAS,
            &sq(&nz.gyro_bias_walk),
        );
        put(
            &mut q,
            Layout::ACCEL_BIAS,
            Layout::ACCEL_BIAS,
            &sq(&nz.accel_bias_walk),
        );
        if let Some(b) = l.baro_bias {
            q[(b, b)] = self.baro_bias_walk * self.baro_bias_walk;
        }
        if let Some(o) = l.odometer_scale {
            q[(o, o)] = self.odometer_scale_walk * self.odometer_scale_walk;
        }
        if let Some(o) = l.time_offset {
            q[(o, o)] = self.time_offset_walk * self.time_offset_walk;
        }
        if let (Some(b), Some(d)) = (l.clock, l.clock_drift()) {
            // One oscillator: its noise is the same in every system's bias (the
            // inter-system biases, their differences, stay constant).
            for i in 0..l.clock_systems {
                for j in 0..l.clock_systems {
                    q[(b + i, b + j)] = self.clock.q_b;
                }
            }
            q[(d, d)] = self.clock.q_d;
        }
        if nz.scale_tau.is_finite() {
            // Gauss–Markov scale factors: density 2σ²/τ.
            for (o, s) in [
                (l.gyro_scale, nz.gyro_scale),
                (l.accel_scale, nz.accel_scale),
            ] {
                if let Some(o) = o {
                    for i in 0..3 {
                        q[(o + i, o + i)] = 2.0 * s[i] * s[i] / nz.scale_tau;
                    }
                }
            }
        }
        q
    }

    /// Transition matrix and discrete process noise over the interval.
    pub fn transition(&self, m: &IntervalMeans) -> (DMatrix<f64>, DMatrix<f64>) {
        let f = self.dynamics(m);
        let q = self.process_noise(m);
        let t = m.dt;
        let a = &f * t;
        let a2 = &a * &a;
        let a3 = &a2 * &a;
        let phi = DMatrix::identity(self.layout.n, self.layout.n) + &a + &a2 * 0.5 + &a3 / 6.0;
        let fq = &f * &q;
        let qd = &q * t
            + (&fq + fq.transpose()) * (0.5 * t * t)
            + &fq * f.transpose() * (t * t * t / 3.0);
        (phi, qd)
    }

    /// Prior covariance: position, velocity and attitude standard deviations (per axis
    /// in `c`), and the sensor errors from the noise model.
    pub fn initial_covariance(
        &self,
        pos_std: Vector3<f64>,
        vel_std: Vector3<f64>,
        att_std: Vector3<f64>,
        baro_bias_std: f64,
    ) -> DMatrix<f64> {
        let (l, nz) = (&self.layout, &self.noise);
        let mut d = vec![0.0; l.n];
        let mut set = |off: usize, v: &Vector3<f64>| {
            for i in 0..3 {
                d[off + i] = v[i] * v[i];
            }
        };
        set(Layout::POS, &pos_std);
        set(Layout::VEL, &vel_std);
        set(Layout::ATT, &att_std);
        set(Layout::GYRO_BIAS, &nz.gyro_bias);
        set(Layout::ACCEL_BIAS, &nz.accel_bias);
        if let Some(sg) = l.gyro_scale {
            set(sg, &nz.gyro_scale);
        }
        if let Some(sa) = l.accel_scale {
            set(sa, &nz.accel_scale);
        }
        if let Some(b) = l.baro_bias {
            d[b] = baro_bias_std * baro_bias_std;
        }
        let mut p = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(d));
        if let Some(r) = l.attitude_ref {
            // The reference attitude error is the attitude error at the start.
            super::kalman::duplicate_states(&mut p, Layout::ATT, r, 3);
        }
        p
    }
}
