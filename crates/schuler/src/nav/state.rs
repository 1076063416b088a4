//! The navigation state shared by all mechanizations.

use crate::earth::Geodetic;
use crate::rotation::Euler;
use nalgebra::{UnitQuaternion, Vector3};
use std::f64::consts::{FRAC_PI_2, PI};

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

    /// The same state with latitude in [−90°, 90°]: a NED mechanization carried past
    /// a pole reports `|lat| > 90°`, which is the point at latitude `±180° − lat` on
    /// the opposite meridian (longitude + 180°), whose NED frame is this one turned by
    /// 180° about down (`C_ne(π − lat, lon + π) = C_ne(lat, lon) R_z(π)`), so `v_N`,
    /// `v_E` change sign and yaw gains 180°. States already in range are returned
    /// unchanged, bit for bit; longitude is not wrapped.
    pub fn normalized(&self) -> Self {
        let lat = self.pos.lat;
        if (-FRAC_PI_2..=FRAC_PI_2).contains(&lat) || !lat.is_finite() {
            return *self;
        }
        let (s, c) = lat.sin_cos();
        if c >= 0.0 {
            // Beyond a full turn: the same meridian again.
            return Self {
                pos: Geodetic::new(s.atan2(c), self.pos.lon, self.pos.h),
                ..*self
            };
        }
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), PI);
        Self {
            t: self.t,
            pos: Geodetic::new(s.atan2(-c), self.pos.lon + PI, self.pos.h),
            v_n: Vector3::new(-self.v_n.x, -self.v_n.y, self.v_n.z),
            q_bn: turn * self.q_bn,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{EarthModel, Wgs84, c_ne};
    use approx::assert_relative_eq;

    /// A state 1.2 deg past the North Pole is the same point, velocity and attitude
    /// in ECEF as its normalized form (checked through `c_ne`), and in-range states
    /// are untouched.
    #[test]
    fn normalized_past_the_pole_is_the_same_state() {
        for lat_deg in [91.2f64, -93.0] {
            let s = NavState::new(
                5.0,
                Geodetic::from_degrees(lat_deg, 20.0, 900.0),
                Vector3::new(240.0, -3.0, 1.0),
                Euler::from_degrees(4.0, -2.0, 10.0),
            );
            let n = s.normalized();
            assert!(n.pos.lat.abs() <= FRAC_PI_2);
            assert_relative_eq!(
                Wgs84.geodetic_to_ecef(&n.pos),
                Wgs84.geodetic_to_ecef(&s.pos),
                epsilon = 1e-8
            );
            let c_old = c_ne(s.pos.lat, s.pos.lon);
            let c_new = c_ne(n.pos.lat, n.pos.lon);
            assert_relative_eq!(c_new * n.v_n, c_old * s.v_n, epsilon = 1e-12);
            let a_old = c_old * s.q_bn.to_rotation_matrix().into_inner();
            let a_new = c_new * n.q_bn.to_rotation_matrix().into_inner();
            assert_relative_eq!(a_new, a_old, epsilon = 1e-14);
        }
        let inside = NavState::new(
            0.0,
            Geodetic::from_degrees(89.0, 200.0, 0.0),
            Vector3::zeros(),
            Euler::default(),
        );
        assert_eq!(inside.normalized(), inside);
    }
}
