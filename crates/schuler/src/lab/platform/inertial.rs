//! Navigation in the inertial frame (22.1), shared by the analytic and the gyro-free
//! INS: `dr/dt = V`, `dV/dt = g(r) + n`, with the gravitation of the Earth model at the
//! computed position (22.2, central `−mu r/r^3` on the sphere), and the conversions
//! between the inertial frame and the Earth-fixed outputs.
//!
//! The inertial frame coincides with ECEF at the run's start `t0` (see
//! [`super::truth::c_ei`]); `r_e = C_ie r_i`, `v_e = C_ie v_i − W × r_e`.

use super::truth::{TruthPoint, c_ei, gravitation_e};
use crate::earth::{EarthModel, Geodetic, c_ne};
use crate::nav::NavState;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Earth's rotation vector in ECEF (and inertial) axes.
fn w_ie<E: EarthModel>(earth: &E) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, earth.rotation_rate())
}

/// Gravitation in the inertial frame at inertial position `r_i`, time `t` [m/s^2].
pub fn gravitation_i<E: EarthModel>(
    earth: &E,
    t: f64,
    t0: f64,
    r_i: &Vector3<f64>,
) -> Vector3<f64> {
    let c_ei = c_ei(earth.rotation_rate(), t, t0);
    c_ei * gravitation_e(earth, &(c_ei.transpose() * r_i))
}

/// Inertial position and velocity of the truth at its time.
pub fn inertial_from_truth<E: EarthModel>(
    earth: &E,
    t0: f64,
    truth: &TruthPoint,
) -> (Vector3<f64>, Vector3<f64>) {
    let c_ei = c_ei(earth.rotation_rate(), truth.state.t, t0);
    (
        c_ei * truth.r_e,
        c_ei * (truth.v_e + w_ie(earth).cross(&truth.r_e)),
    )
}

/// The navigation state (NED) of inertial position, velocity and body attitude `C_bi`.
pub fn nav_state<E: EarthModel>(
    earth: &E,
    t: f64,
    t0: f64,
    r_i: &Vector3<f64>,
    v_i: &Vector3<f64>,
    c_bi: &Matrix3<f64>,
) -> NavState {
    let c_ie = c_ei(earth.rotation_rate(), t, t0).transpose();
    let r_e = c_ie * r_i;
    let v_e = c_ie * v_i - w_ie(earth).cross(&r_e);
    let pos = earth.ecef_to_geodetic(&r_e);
    let c_en = c_ne(pos.lat, pos.lon).transpose();
    let c_bn = c_en * c_ie * c_bi;
    NavState {
        t,
        pos,
        v_n: c_en * v_e,
        q_bn: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_bn)),
    }
}

/// Height and vertical velocity replaced by the truth's (ideal vertical aiding), the
/// horizontal position and velocity kept.
pub fn aid_vertical<E: EarthModel>(
    earth: &E,
    t0: f64,
    truth: &TruthPoint,
    r_i: &Vector3<f64>,
    v_i: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let c_ei = c_ei(earth.rotation_rate(), truth.state.t, t0);
    let r_e = c_ei.transpose() * r_i;
    let v_e = c_ei.transpose() * v_i - w_ie(earth).cross(&r_e);
    let pos = earth.ecef_to_geodetic(&r_e);
    let c_ne = c_ne(pos.lat, pos.lon);
    let mut v_n = c_ne.transpose() * v_e;
    v_n.z = truth.state.v_n.z;
    let r_e = earth.geodetic_to_ecef(&Geodetic::new(pos.lat, pos.lon, truth.state.pos.h));
    let v_e = c_ne * v_n;
    (c_ei * r_e, c_ei * (v_e + w_ie(earth).cross(&r_e)))
}
