//! The navigation state shared by all mechanizations.

use crate::earth::Geodetic;
use crate::rotation::Euler;
use nalgebra::{UnitQuaternion, Vector3};

/// Position, velocity and attitude at one time, in the local-level NED frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavState {
    /// Time [s] on the IMU log's clock.
    pub t: f64,
    /// Geodetic position.
    pub pos: Geodetic,
    /// Velocity relative to the Earth in NED [m/s].
    pub v_n: Vector3<f64>,
    /// Attitude: rotation from body (FRD) to NED, `v_n = q_bn * v_b`.
    pub q_bn: UnitQuaternion<f64>,
}

impl NavState {
    /// A state from position, NED velocity and Euler angles.
    pub fn new(t: f64, pos: Geodetic, v_n: Vector3<f64>, attitude: Euler) -> Self {
        Self {
            t,
            pos,
            v_n,
            q_bn: attitude.to_quaternion(),
        }
    }

    /// Z-Y-X Euler angles of the attitude.
    pub fn euler(&self) -> Euler {
        Euler::from_quaternion(&self.q_bn)
    }
}
