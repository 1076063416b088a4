//! IMU samples and deterministic sensor-error compensation.
//!
//! Convention (KF-GINS, sidereon `ImuSampleKind::Increment`): a sample tagged `t`
//! holds the angle increment `dtheta` [rad] and velocity increment `dvel` [m/s]
//! integrated over the interval `(t - dt, t]`, in body axes front-right-down (FRD).

use nalgebra::Vector3;

/// One IMU sample: increments over `(t - dt, t]`, body axes FRD.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    /// End of the interval [s] on the log's clock (GPS seconds of week for KF-GINS files).
    pub t: f64,
    /// Length of the interval [s], > 0.
    pub dt: f64,
    /// Angle increment `∫ w_ib_b dt` over the interval [rad].
    pub dtheta: Vector3<f64>,
    /// Velocity increment `∫ f_b dt` over the interval [m/s].
    pub dvel: Vector3<f64>,
}
