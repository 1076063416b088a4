//! Building blocks shared by the local-level mechanizations (NED in
//! [`super::local_level`], wander azimuth in [`super::wander`]): the body-frame
//! increments of one IMU interval and the navigation-frame updates that use them.
//!
//! Both mechanizations integrate in a local-level frame `l` (NED, or the wander frame)
//! that turns relative to inertial space at `ω_il^l`; they differ only in that rate
//! and in how position is carried. Over one interval `(t_{k-1}, t_k]` with increments
//! `dθ_k`, `dv_k` (Savage 1998, JGCD 21(1–2); Shin & El-Sheimy 2004):
//!
//! - body velocity increment, rotation compensated to third order plus two-sample
//!   sculling: `dv_f^b = dv_k + ½ dθ_k×dv_k + ⅙ dθ_k×(dθ_k×dv_k)
//!   + (1/12)(dθ_{k-1}×dv_k + dv_{k-1}×dθ_k)` ([`body_velocity_increment`]);
//! - body rotation vector with two-sample coning:
//!   `φ_k = dθ_k + (1/12) dθ_{k-1}×dθ_k` ([`body_rotation_vector`]);
//! - velocity increment in the frame at the interval's middle:
//!   `dv_f^l = (I − ½ ζ×) C_bl(k-1) dv_f^b`, `ζ = ω_il^l dt` ([`resolve_in_nav_frame`]);
//! - attitude: `q_bl(k) = exp(−ζ) ⊗ q_bl(k-1) ⊗ exp(φ_k)` ([`update_attitude`]).

use super::Corrections;
use crate::rotation::quaternion_from_rotation_vector;
use nalgebra::{UnitQuaternion, Vector3};

/// The history a local-level mechanization carries from one step to the next: the
/// previous sample's increments (two-sample corrections) and the previous velocity
/// change (mid-interval extrapolation). Exposed so a state can be handed from one
/// mechanization to another without loss.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepHistory {
    /// Previous sample's `(dθ, dv)` [rad, m/s] in body axes; `None` before the first
    /// step (the two-sample corrections are then zero, exact for constant rates).
    pub prev_increments: Option<(Vector3<f64>, Vector3<f64>)>,
    /// Velocity change over the previous interval [m/s], in the mechanization's
    /// local-level frame (NED or wander).
    pub prev_dv: Vector3<f64>,
    /// Length of the previous interval [s]; 0 before the first step.
    pub prev_dt: f64,
}

impl Default for StepHistory {
    fn default() -> Self {
        Self {
            prev_increments: None,
            prev_dv: Vector3::zeros(),
            prev_dt: 0.0,
        }
    }
}

impl StepHistory {
    /// Fraction of the previous velocity change to add to reach the middle of an
    /// interval of length `dt`: `½ dt / dt_prev` (linear extrapolation), 0 before the
    /// first step.
    #[inline]
    pub fn midpoint_ratio(&self, dt: f64) -> f64 {
        if self.prev_dt > 0.0 {
            0.5 * dt / self.prev_dt
        } else {
            0.0
        }
    }

    /// The previous increments, or the current ones before the first step (so that
    /// the two-sample corrections vanish).
    #[inline]
    pub fn prev_or(
        &self,
        dtheta: &Vector3<f64>,
        dvel: &Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        self.prev_increments.unwrap_or((*dtheta, *dvel))
    }

    /// Record the step just taken: its increments, velocity change and length.
    #[inline]
    pub fn record(&mut self, dtheta: Vector3<f64>, dvel: Vector3<f64>, dv: Vector3<f64>, dt: f64) {
        self.prev_increments = Some((dtheta, dvel));
        self.prev_dv = dv;
        self.prev_dt = dt;
    }
}

/// Specific-force velocity increment in the body frame at the interval's start [m/s]:
/// `dv + ½ dθ×dv + ⅙ dθ×(dθ×dv)` plus, with `corrections.sculling`, the two-sample
/// sculling term `(1/12)(dθ_prev×dv + dv_prev×dθ)` (Savage 1998, eq. 56 to third
/// order in the rotation).
#[inline]
pub fn body_velocity_increment(
    dtheta: &Vector3<f64>,
    dvel: &Vector3<f64>,
    (dtheta_prev, dvel_prev): &(Vector3<f64>, Vector3<f64>),
    corrections: Corrections,
) -> Vector3<f64> {
    let dth_x_dv = dtheta.cross(dvel);
    // Products with 1/6 and 1/12 rather than divisions (six fewer per step).
    let mut dv_f_b = dvel + 0.5 * dth_x_dv + dtheta.cross(&dth_x_dv) * (1.0 / 6.0);
    if corrections.sculling {
        dv_f_b += (dtheta_prev.cross(dvel) + dvel_prev.cross(dtheta)) * (1.0 / 12.0);
    }
    dv_f_b
}

/// Rotation vector of the body over one interval [rad]: `dθ` plus, with
/// `corrections.coning`, the two-sample coning term `(1/12) dθ_prev×dθ` (Savage 1998,
/// eq. 29 in two-sample form).
#[inline]
pub fn body_rotation_vector(
    dtheta: &Vector3<f64>,
    dtheta_prev: &Vector3<f64>,
    corrections: Corrections,
) -> Vector3<f64> {
    let mut phi = *dtheta;
    if corrections.coning {
        phi += dtheta_prev.cross(dtheta) * (1.0 / 12.0);
    }
    phi
}

/// Body velocity increment resolved in the local-level frame at the interval's
/// middle: `(I − ½ ζ×) C_bl dv_f^b`, with `ζ = ω_il^l dt` the frame's rotation over
/// the interval and `q_bl` the attitude at its start.
#[inline]
pub fn resolve_in_nav_frame(
    q_bl: &UnitQuaternion<f64>,
    dv_f_b: &Vector3<f64>,
    zeta: &Vector3<f64>,
) -> Vector3<f64> {
    let dv_f_bl = q_bl * dv_f_b;
    dv_f_bl - 0.5 * zeta.cross(&dv_f_bl)
}

/// Attitude update `q_bl(k) = exp(−ζ) ⊗ q_bl(k-1) ⊗ exp(φ)`, renormalized: the body
/// turns by `φ` (body axes) while the frame turns by `ζ = ω_il^l dt` (frame axes).
#[inline]
pub fn update_attitude(
    q_bl: &UnitQuaternion<f64>,
    zeta: &Vector3<f64>,
    phi: &Vector3<f64>,
) -> UnitQuaternion<f64> {
    let q_ll = quaternion_from_rotation_vector(&(-zeta));
    let q_bb = quaternion_from_rotation_vector(phi);
    UnitQuaternion::new_normalize((q_ll * q_bl * q_bb).into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// For a constant rate `w` and constant specific force `f` in body axes the exact
    /// velocity increment resolved at the interval's start is
    /// `∫ exp(w τ) f dτ = f dt + ½ w×f dt² + ⅙ w×(w×f) dt³ + O(dt⁴)`; the function must
    /// match the series to its fourth-order remainder (|w dt|³ |f dt| / 24).
    #[test]
    fn velocity_increment_matches_constant_rate_series() {
        let w = Vector3::new(0.3, -0.2, 0.5);
        let f = Vector3::new(1.0, 2.0, -9.8);
        let dt = 0.01;
        // Exact: integrate exp(w tau) f over [0, dt] by composite Simpson on 2000 cells.
        let n = 2000;
        let h = dt / n as f64;
        let mut exact = Vector3::zeros();
        for k in 0..=n {
            let wgt = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let q = quaternion_from_rotation_vector(&(w * (k as f64 * h)));
            exact += (q * f) * (wgt * h / 3.0);
        }
        let dth = w * dt;
        let dv = f * dt;
        let got = body_velocity_increment(&dth, &dv, &(dth, dv), Corrections::default());
        let bound = (w.norm() * dt).powi(3) * (f.norm() * dt) / 24.0;
        assert!(
            (got - exact).norm() < 2.0 * bound,
            "{:e}",
            (got - exact).norm()
        );
    }

    /// Constant-rate samples: `dθ_prev × dθ = 0`, so coning adds nothing, and the
    /// attitude update with a zero frame rate is exactly `q ⊗ exp(dθ)`.
    #[test]
    fn rotation_vector_and_attitude_update() {
        let dth = Vector3::new(1e-3, 2e-3, -5e-4);
        assert_eq!(
            body_rotation_vector(&dth, &dth, Corrections::default()),
            dth
        );
        let q0 = UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3);
        let q1 = update_attitude(&q0, &Vector3::zeros(), &dth);
        assert_relative_eq!(
            q1,
            q0 * quaternion_from_rotation_vector(&dth),
            epsilon = 1e-16
        );
    }

    #[test]
    fn history_midpoint_ratio() {
        let mut h = StepHistory::default();
        assert_eq!(h.midpoint_ratio(0.005), 0.0);
        h.record(Vector3::zeros(), Vector3::zeros(), Vector3::x(), 0.01);
        assert_eq!(h.midpoint_ratio(0.005), 0.25);
    }
}
