//! The refinement's six-state Kalman filter on `[ψ, ε]`: the inertial attitude error
//! (inertial axes, `ĉ_bi = (I − [ψ×]) c_bi`) and the gyro drift (body axes), observed
//! through the invariant (7) with an independent source of the angle rates (module
//! docs of [`crate::refine`]).

use super::invariant::InvariantWindow;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

pub(super) type Matrix6 = SMatrix<f64, 6, 6>;
type Vector6 = SVector<f64, 6>;

/// Noise of the refinement's model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineNoise {
    /// The system's gyro angle random walk [rad/sqrt(s)].
    pub arw: f64,
    /// Random walk of the drift [rad/s/sqrt(s)].
    pub drift_walk: f64,
    /// White noise density of the independent source's angle rates [rad/sqrt(s)].
    pub reference_rate: f64,
}

/// The refinement filter: estimates of `[ψ, ε]` and their covariance, open loop (the
/// system is not corrected; the estimates describe its error).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineFilter {
    x: Vector6,
    p: Matrix6,
}

impl RefineFilter {
    /// Zero estimates with independent priors: attitude [rad] and drift [rad/s] per
    /// axis.
    pub fn new(attitude_std: Vector3<f64>, drift_std: Vector3<f64>) -> Self {
        Self {
            x: Vector6::zeros(),
            p: prior(&attitude_std, &drift_std),
        }
    }

    /// Propagates over the step `window` covered: `ψ(t_i) = ψ(t_{i−1}) − B ε`, the
    /// drift constant but for its random walk.
    pub fn propagate(&mut self, window: &InvariantWindow, noise: &RefineNoise) {
        let mut phi = Matrix6::identity();
        phi.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-window.drift_to_attitude()));
        let t = window.span();
        let mut q = Matrix6::zeros();
        for k in 0..3 {
            q[(k, k)] = noise.arw.powi(2) * t;
            q[(k + 3, k + 3)] = noise.drift_walk.powi(2) * t;
        }
        self.x = phi * self.x;
        self.p = phi * self.p * phi.transpose() + q;
    }

    /// Updates with the step's observation (7); the measurement noise is the
    /// reference's and the gyros' white rate noise over the step. Returns the
    /// innovation [rad], or `None` when its covariance is singular (an empty step).
    pub fn update(
        &mut self,
        window: &InvariantWindow,
        noise: &RefineNoise,
    ) -> Option<Vector3<f64>> {
        let h = window.h();
        let r = Matrix3::identity()
            * ((noise.reference_rate.powi(2) + noise.arw.powi(2)) * window.span());
        let innovation = window.z() - h * self.x;
        let s = h * self.p * h.transpose() + r;
        let s_inv = s.try_inverse()?;
        let k = self.p * h.transpose() * s_inv;
        self.x += k * innovation;
        // Joseph form keeps P symmetric and positive.
        let i_kh = Matrix6::identity() - k * h;
        self.p = i_kh * self.p * i_kh.transpose() + k * r * k.transpose();
        Some(innovation)
    }

    /// Estimated inertial attitude error `ψ` [rad].
    pub fn attitude_error(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(0).into_owned()
    }

    /// Estimated gyro drift `ε` [rad/s].
    pub fn drift(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(3).into_owned()
    }

    /// The covariance of `[ψ, ε]`.
    pub fn covariance(&self) -> Matrix6 {
        self.p
    }

    /// The standard deviation of `u · ψ` for a unit vector `u` (inertial axes) [rad].
    pub fn attitude_std_along(&self, u: &Vector3<f64>) -> f64 {
        std_along(&self.p, u)
    }

    /// Standard deviations of the drift per body axis [rad/s].
    pub fn drift_std(&self) -> Vector3<f64> {
        drift_std(&self.p)
    }
}

/// Independent priors of `[ψ, ε]`: attitude [rad] and drift [rad/s] per axis.
pub(super) fn prior(attitude_std: &Vector3<f64>, drift_std: &Vector3<f64>) -> Matrix6 {
    let mut p = Matrix6::zeros();
    for k in 0..3 {
        p[(k, k)] = attitude_std[k].powi(2);
        p[(k + 3, k + 3)] = drift_std[k].powi(2);
    }
    p
}

/// The standard deviation of `u · ψ` under the covariance `p` of `[ψ, ε]`.
pub(super) fn std_along(p: &Matrix6, u: &Vector3<f64>) -> f64 {
    let p = p.fixed_view::<3, 3>(0, 0);
    (u.transpose() * p * u)[(0, 0)].max(0.0).sqrt()
}

/// The drift's standard deviations per axis under the covariance `p` of `[ψ, ε]`.
pub(super) fn drift_std(p: &Matrix6) -> Vector3<f64> {
    Vector3::from_fn(|k, _| p[(k + 3, k + 3)].max(0.0).sqrt())
}
