//! Sums over one covariance-propagation interval, and the interval's mean
//! kinematics for [`super::error_model`].

use super::error_model::IntervalMeans;
use crate::imu::ImuSample;
use crate::nav::FrameSnapshot;
use nalgebra::{UnitQuaternion, Vector3};

/// Accumulated increments since the last propagation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Interval {
    /// Length so far [s].
    pub t: f64,
    /// `Σ Ĉ_cb dv` [m/s].
    pub f_c_dt: Vector3<f64>,
    /// `Σ dv` [m/s].
    pub f_b_dt: Vector3<f64>,
    /// `Σ dθ` [rad].
    pub w_b_dt: Vector3<f64>,
    /// `∫ v̂ dt` (trapezoid) [m], when [`Interval::add_velocity`] is called.
    pub v_dt: Vector3<f64>,
}

impl Interval {
    /// Add a (compensated) sample, with the attitude before it.
    pub fn add(&mut self, s: &ImuSample, q_bc: &UnitQuaternion<f64>) {
        self.t += s.dt;
        self.f_c_dt += q_bc * s.dvel;
        self.f_b_dt += s.dvel;
        self.w_b_dt += s.dtheta;
    }

    /// Add the velocity before and after a sample of length `dt` to `∫ v̂ dt` (for a
    /// window-mean velocity observation).
    pub fn add_velocity(&mut self, dt: f64, v0: &Vector3<f64>, v1: &Vector3<f64>) {
        self.v_dt += (v0 + v1) * (0.5 * dt);
    }

    /// The mean kinematics, with the frame at the interval's end.
    pub fn means(&self, frame: FrameSnapshot) -> IntervalMeans {
        let t = self.t.max(f64::MIN_POSITIVE);
        IntervalMeans {
            dt: self.t,
            frame,
            f_c: self.f_c_dt / t,
            f_b: self.f_b_dt / t,
            w_b: self.w_b_dt / t,
        }
    }
}
