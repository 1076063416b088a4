//! What the instruments of every system see: the true motion at one instant, from a
//! [`Trajectory`], in ECEF and body axes, with the angular acceleration the gyro-free
//! INS needs.
//!
//! The same formulas as [`crate::sim::analytic::evaluate`] (angular rate from
//! `skew(w_eb_b) = C_eb dC_be/dt`, specific force `f_e = r_e'' + 2 W × r_e' − g_e`),
//! plus one more derivative: `dw_ib_b/dt = (dC_eb/dt) w_ie_e + dw_eb_b/dt` with
//! `skew(dw_eb_b/dt) = dC_eb/dt dC_be/dt + C_eb d²C_be/dt²`, exact through the jets.
//!
//! The inertial frame `i` of this module coincides with ECEF at the run's start `t0`
//! and does not rotate: `C_ei(t) = R_z(W (t − t0))` takes ECEF coordinates to inertial.

use crate::earth::{EarthModel, c_ne};
use crate::nav::NavState;
use crate::sim::analytic::Trajectory;
use crate::sim::jet::{self, Jet};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// The true motion at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthPoint {
    /// Navigation state in NED.
    pub state: NavState,
    /// ECEF position [m].
    pub r_e: Vector3<f64>,
    /// Velocity relative to the Earth in ECEF [m/s].
    pub v_e: Vector3<f64>,
    /// Body-to-ECEF DCM.
    pub c_be: Matrix3<f64>,
    /// Specific force in ECEF axes [m/s^2].
    pub f_e: Vector3<f64>,
    /// Angular rate of the body relative to inertial space, body axes [rad/s].
    pub w_ib_b: Vector3<f64>,
    /// Its time derivative (the same in body and inertial frames) [rad/s^2].
    pub dw_ib_b: Vector3<f64>,
}

impl TruthPoint {
    /// Specific force in body axes [m/s^2].
    pub fn f_b(&self) -> Vector3<f64> {
        self.c_be.transpose() * self.f_e
    }
}

/// Vector of a skew-symmetric part: `(S − S^T)/2` as a vector.
fn vee(s: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        0.5 * (s[(2, 1)] - s[(1, 2)]),
        0.5 * (s[(0, 2)] - s[(2, 0)]),
        0.5 * (s[(1, 0)] - s[(0, 1)]),
    )
}

/// The true motion at time `t`.
pub fn truth_at<E: EarthModel, T: Trajectory + ?Sized>(earth: &E, traj: &T, t: f64) -> TruthPoint {
    let (r, c) = traj.ecef_pose(earth, Jet::variable(t));
    let c_be = c.value();
    let dc_be = c.derivative();
    let ddc_be = Matrix3::from_fn(|i, j| c.0[i][j].dd);
    let c_eb = c_be.transpose();
    let dc_eb = dc_be.transpose();
    let w_eb_b = vee(&(c_eb * dc_be));
    let dw_eb_b = vee(&(dc_eb * dc_be + c_eb * ddc_be));
    let w_ie_e = Vector3::new(0.0, 0.0, earth.rotation_rate());
    let r_e = jet::value(&r);
    let v_e = jet::derivative(&r);
    let a_e = jet::second_derivative(&r);
    let pos = earth.ecef_to_geodetic(&r_e);
    let c_ne = c_ne(pos.lat, pos.lon);
    let g_e = c_ne * earth.gravity_n(pos.lat, pos.h);
    let f_e = a_e + 2.0 * w_ie_e.cross(&v_e) - g_e;
    let c_bn = c_ne.transpose() * c_be;
    TruthPoint {
        state: NavState {
            t,
            pos,
            v_n: c_ne.transpose() * v_e,
            q_bn: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_bn)),
        },
        r_e,
        v_e,
        c_be,
        f_e,
        w_ib_b: c_eb * w_ie_e + w_eb_b,
        dw_ib_b: dc_eb * w_ie_e + dw_eb_b,
    }
}

/// `C_ei(t)`: ECEF to the inertial frame fixed to ECEF at `t0`, for Earth rate `w`.
pub fn c_ei(w: f64, t: f64, t0: f64) -> Matrix3<f64> {
    let (s, c) = (w * (t - t0)).sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Gravitation (mass attraction only) in ECEF at ECEF position `r_e`: the model's
/// gravity plus back the centrifugal term, `G_e = g_e + W × (W × r_e)` (22.2 for the
/// sphere: `−mu r / r^3`).
pub fn gravitation_e<E: EarthModel>(earth: &E, r_e: &Vector3<f64>) -> Vector3<f64> {
    let pos = earth.ecef_to_geodetic(r_e);
    let w = Vector3::new(0.0, 0.0, earth.rotation_rate());
    c_ne(pos.lat, pos.lon) * earth.gravity_n(pos.lat, pos.h) + w.cross(&w.cross(r_e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{Geodetic, Sphere, Wgs84};
    use crate::sim::analytic::{Maneuvering, evaluate};

    /// Same state, rate and force as the simulator's own evaluation (one formula, two
    /// codes), and the angular acceleration equals the central difference of the rate
    /// to the difference's own truncation error (h^2/6 |w'''| < 1e-9 rad/s^2 at h = 1 ms).
    #[test]
    fn agrees_with_the_simulator_and_differentiates_the_rate() {
        let traj = Maneuvering::flight(Geodetic::from_degrees(40.0, 10.0, 500.0));
        for t in [0.0, 17.3, 120.0, 600.5] {
            let p = truth_at(&Wgs84, &traj, t);
            let (s, k) = evaluate(&Wgs84, &traj, t);
            assert!((p.w_ib_b - k.w_ib_b).norm() < 1e-15);
            assert!((p.f_b() - k.f_b).norm() < 1e-12);
            assert!((p.state.v_n - s.v_n).norm() < 1e-12);
            assert!(p.state.q_bn.angle_to(&s.q_bn) < 1e-15);
            let h = 1e-3;
            let fd = (evaluate(&Wgs84, &traj, t + h).1.w_ib_b
                - evaluate(&Wgs84, &traj, t - h).1.w_ib_b)
                / (2.0 * h);
            assert!(
                (p.dw_ib_b - fd).norm() < 1e-9,
                "{}",
                (p.dw_ib_b - fd).norm()
            );
            assert!(p.dw_ib_b.norm() > 1e-3);
        }
    }

    /// On the sphere the gravitation is the central field (22.2), `−mu r/r^3`.
    #[test]
    fn gravitation_is_central_on_the_sphere() {
        let s = Sphere::textbook(true);
        let r = s.geodetic_to_ecef(&Geodetic::from_degrees(33.0, -70.0, 1200.0));
        let g = gravitation_e(&s, &r);
        let central = -r * (s.mu / r.norm().powi(3));
        assert!((g - central).norm() < 1e-14 * central.norm());
    }
}
