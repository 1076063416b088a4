//! The refinement with a second strapdown unit as the independent source of the angle
//! rates (module docs of [`crate::refine`]): two units on the same body (their own
//! gyros, the same motion), each keeping its inertial attitude `ĉ_bi,k` from its own
//! increments.
//!
//! # The observation
//!
//! The second unit gives its rates relative to the navigation frame as an INS or AHRS
//! does, `ω_nb^n = ĉ_bn,2 Θ̇₂ − ω_in^n` ((8)–(10) from its Euler angles are the same
//! vector). With the same frame on both sides (`c_ni`, `ω_en^n`; its error from a
//! position error is second order, module docs), the reference side of (7) over a
//! sample is `c_ni (ω_en^n + ω_nb^n) dt + Ω dt = ĉ_bi,2 Θ̇₂ dt`: the second unit's own
//! inertial rotation, so `z = Σ (ĉ_bi,1 Δθ₁ − ĉ_bi,2 Δθ₂)`.
//!
//! To first order, with the second unit's attitude error `ψ₂` and drift `β`, its side
//! errs by `ω × ψ₂ + c_bi β`: the derivation's `z` holds for the **differences**
//! `ψ = ψ₁ − ψ₂` and `ε = ε₁ − β`, which obey the same `ψ̇ = −c_bi ε`. The mode
//! estimates what one unit does relative to the other; it refines the system's drift
//! only as far as the second unit's is known.
//!
//! # The noise is the process noise
//!
//! The units' white rate noise `n₁ − n₂` is not an independent measurement noise:
//! with `w = ∫ c_bi (n₁ − n₂) dτ` over a step, `ψ(t_i) = ψ(t_{i−1}) − B ε − w` and
//! `z = [A×] ψ(t_i) + (B + [A×]B − M) ε + w`, i.e. on the state at the step's start
//! `x = [ψ(t_{i−1}), ε]`,
//!
//! ```text
//! z = H₀ x + (I − [A×]) w,   H₀ = [[A×], B − M],   x(t_i) = Φ x − [w; 0],
//! ```
//!
//! the same `w` in both (`cov w = (q₁² + q₂²) T I`). [`TwoUnitFilter`] is the Kalman
//! filter for that correlated pair (Simon, *Optimal State Estimation*, 2006, §7.1):
//! with `S = H₀ P H₀ᵀ + R` and `C = cov(process noise, measurement noise)`,
//! `x ← Φ x + (Φ P H₀ᵀ + C) S⁻¹ (z − H₀ x)`,
//! `P ← Φ P Φᵀ + Q − (Φ P H₀ᵀ + C) S⁻¹ (Φ P H₀ᵀ + C)ᵀ`. Treating `w` twice as
//! independent (as [`super::RefineFilter`] does for a reference whose noise is its
//! own) would double its weight and let `ψ` wander by it in the covariance while the
//! data pin it.

use super::filter::{self, Matrix6};
use super::invariant::InvariantWindow;
use crate::imu::ImuSample;
use crate::rotation::dcm_from_rotation_vector;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

type Vector6 = SVector<f64, 6>;

/// The Kalman filter on the units' attitude difference `ψ = ψ₁ − ψ₂` (inertial axes)
/// and drift difference `ε = ε₁ − β` (body axes), with the invariant's noise as the
/// process noise it is (module docs). Open loop: the units are not corrected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoUnitFilter {
    x: Vector6,
    p: Matrix6,
    /// `q₁² + q₂²`, the two units' angle random walks squared summed [rad²/s].
    arw2: f64,
}

impl TwoUnitFilter {
    /// Zero estimates with independent priors of the attitude difference [rad] and
    /// the drift difference [rad/s] per axis; `arw` the two units' angle random walks
    /// [rad/√s].
    pub fn new(attitude_std: Vector3<f64>, drift_std: Vector3<f64>, arw: [f64; 2]) -> Self {
        Self {
            x: Vector6::zeros(),
            p: filter::prior(&attitude_std, &drift_std),
            arw2: arw[0].powi(2) + arw[1].powi(2),
        }
    }

    /// One step's observation and propagation together (module docs); returns the
    /// innovation [rad], or `None` when its covariance is singular.
    pub fn step(&mut self, window: &InvariantWindow) -> Option<Vector3<f64>> {
        let h_end = window.h();
        let a = h_end.fixed_view::<3, 3>(0, 0).into_owned();
        let b = window.drift_to_attitude();
        // H₀ on the step's start: ψ(t_i) = ψ(t_{i−1}) − B ε.
        let mut h0 = h_end;
        let eps_cols = h_end.fixed_view::<3, 3>(0, 3) - a * b;
        h0.fixed_view_mut::<3, 3>(0, 3).copy_from(&eps_cols);
        let mut phi = Matrix6::identity();
        phi.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-b));
        let qw = Matrix3::identity() * (self.arw2 * window.span());
        let d = Matrix3::identity() - a;
        let r = d * qw * d.transpose();
        let mut q = Matrix6::zeros();
        q.fixed_view_mut::<3, 3>(0, 0).copy_from(&qw);
        // cov(−w, (I − [A×]) w) on the attitude rows.
        let mut c = SMatrix::<f64, 6, 3>::zeros();
        c.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(-qw * d.transpose()));
        let innovation = window.z() - h0 * self.x;
        let s = h0 * self.p * h0.transpose() + r;
        let s_inv = s.try_inverse()?;
        let gain = (phi * self.p * h0.transpose() + c) * s_inv;
        self.x = phi * self.x + gain * innovation;
        let p = phi * self.p * phi.transpose() + q - gain * s * gain.transpose();
        self.p = (p + p.transpose()) * 0.5;
        Some(innovation)
    }

    /// Estimated attitude difference `ψ₁ − ψ₂` [rad] (inertial axes).
    pub fn attitude_difference(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(0).into_owned()
    }

    /// Estimated drift difference `ε₁ − β` [rad/s] (body axes).
    pub fn drift_difference(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(3).into_owned()
    }

    /// The standard deviation of `u · ψ` for a unit vector `u` (inertial axes) [rad].
    pub fn attitude_std_along(&self, u: &Vector3<f64>) -> f64 {
        filter::std_along(&self.p, u)
    }

    /// Standard deviations of the drift difference per body axis [rad/s].
    pub fn drift_std(&self) -> Vector3<f64> {
        filter::drift_std(&self.p)
    }
}

/// The mode: both units' attitudes integrated from their increments, the invariant
/// summed over steps of `step` seconds and each step given to the filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SecondUnitRefinement {
    c_bi: [Matrix3<f64>; 2],
    window: InvariantWindow,
    filter: TwoUnitFilter,
    step: f64,
}

impl SecondUnitRefinement {
    /// Start from the two units' attitudes (body to inertial) with `filter`'s priors,
    /// observing over steps of `step` seconds.
    pub fn new(c_bi: [Matrix3<f64>; 2], filter: TwoUnitFilter, step: f64) -> Self {
        Self {
            c_bi,
            window: InvariantWindow::default(),
            filter,
            step,
        }
    }

    /// One sample of both units over the same interval: each side of (7) summed, each
    /// attitude advanced by its own increment (`ĉ ← ĉ exp([Δθ×])`, exact at a constant
    /// rate); at the end of a step, the filter's step. Returns the window and the
    /// innovation when a step ended.
    pub fn push(
        &mut self,
        system: &ImuSample,
        second: &ImuSample,
    ) -> Option<(InvariantWindow, Option<Vector3<f64>>)> {
        let reference = self.c_bi[1] * second.dtheta;
        self.window
            .push(&self.c_bi[0], &system.dtheta, &reference, system.dt);
        self.c_bi[0] *= dcm_from_rotation_vector(&system.dtheta);
        self.c_bi[1] *= dcm_from_rotation_vector(&second.dtheta);
        if self.window.span() < self.step - 1e-9 {
            return None;
        }
        let window = std::mem::take(&mut self.window);
        Some((window, self.filter.step(&window)))
    }

    /// The filter.
    pub fn filter(&self) -> &TwoUnitFilter {
        &self.filter
    }

    /// The two units' attitudes now (body to inertial).
    pub fn attitudes(&self) -> [Matrix3<f64>; 2] {
        self.c_bi
    }
}
