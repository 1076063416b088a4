//! What an error-state filter needs from a mechanization, independent of whether it
//! navigates in NED or in the wander frame: the computation frame `c` (the
//! mechanization's own local-level frame at its computed position) and a way to feed
//! estimated errors back.
//!
//! The filter uses the psi-angle error model (Benson 1975, IEEE TAES 11(4); Savage
//! 2000 ch. 12), whose errors are all resolved in `c`:
//!
//! - `δr = C_ce (r̂^e − r^e)`: ECEF position error, resolved in `c` [m];
//! - `δv = v̂^c − C_ce v^e`: velocity error [m/s];
//! - `ψ`: attitude error of the computed body attitude relative to `c`,
//!   `Ĉ_cb = (I − ψ×) C_cb` [rad].
//!
//! Neither latitude nor longitude appears, so the model is non-singular wherever the
//! mechanization is (everywhere for the wander frame, including at a pole).

use super::{LocalLevel, Mechanization, NavState};
use crate::earth::EarthModel;
use crate::rotation::quaternion_from_rotation_vector;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// The computation frame of a mechanization at its current time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameSnapshot {
    /// Time [s].
    pub t: f64,
    /// Rotation from `c` to ECEF, `r^e = C_ec r^c`.
    pub c_ce_to_e: Matrix3<f64>,
    /// ECEF position [m].
    pub r_e: Vector3<f64>,
    /// Velocity relative to the Earth in `c` [m/s].
    pub v_c: Vector3<f64>,
    /// Attitude, body to `c`.
    pub q_bc: UnitQuaternion<f64>,
    /// Earth rate in `c` [rad/s].
    pub w_ie_c: Vector3<f64>,
    /// Transport rate (rotation of `c` relative to the Earth) in `c` [rad/s].
    pub rho_c: Vector3<f64>,
    /// Magnitude of gravity [m/s^2].
    pub gravity: f64,
    /// Geocentric radius of the position, `sqrt(R_M R_N) + h` [m] (the gravity
    /// gradient's length scale).
    pub radius: f64,
}

/// Estimated errors of a mechanization's state (computed minus true, in `c`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NavErrors {
    /// Position error `δr` [m].
    pub dr: Vector3<f64>,
    /// Velocity error `δv` [m/s].
    pub dv: Vector3<f64>,
    /// Attitude error `ψ` [rad].
    pub psi: Vector3<f64>,
}

/// A mechanization that an error-state filter can observe and correct.
pub trait ErrorFrame: Mechanization {
    /// The computation frame at the current time.
    fn frame(&self) -> FrameSnapshot;
    /// The attitude, body to `c` (cheap: no Earth model evaluation).
    fn q_bc(&self) -> UnitQuaternion<f64>;
    /// Remove estimated errors from the state (closed-loop feedback).
    fn correct(&mut self, errors: &NavErrors);
}

/// The corrected state in ECEF: position, velocity and body-to-ECEF attitude,
/// `r^e = r̂^e − C_ec δr`, `v^e = C_ec (v̂^c − δv)`, `C_eb = C_ec exp(ψ×) Ĉ_cb`.
pub fn corrected_ecef(
    f: &FrameSnapshot,
    e: &NavErrors,
) -> (Vector3<f64>, Vector3<f64>, UnitQuaternion<f64>) {
    let c_ec = f.c_ce_to_e;
    let r = f.r_e - c_ec * e.dr;
    let v = c_ec * (f.v_c - e.dv);
    let q_ce = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_ec));
    let q_be = q_ce * quaternion_from_rotation_vector(&e.psi) * f.q_bc;
    (r, v, q_be)
}

/// The NED state at ECEF position `r`, ECEF velocity `v_e` and body-to-ECEF attitude
/// `q_be` (defined everywhere but exactly at a pole, where north is undefined).
pub fn nav_state_from_ecef<E: EarthModel>(
    earth: &E,
    t: f64,
    r: &Vector3<f64>,
    v_e: &Vector3<f64>,
    q_be: &UnitQuaternion<f64>,
) -> NavState {
    let pos = earth.ecef_to_geodetic(r);
    let c_ne = crate::earth::c_ne(pos.lat, pos.lon);
    let q_en =
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_ne.transpose()));
    NavState {
        t,
        pos,
        v_n: c_ne.transpose() * v_e,
        q_bn: q_en * q_be,
    }
}

impl<E: EarthModel> ErrorFrame for LocalLevel<E> {
    fn frame(&self) -> FrameSnapshot {
        let s = self.state();
        let earth = self.earth();
        let local = earth.local(s.pos.lat, s.pos.h);
        FrameSnapshot {
            t: s.t,
            c_ce_to_e: crate::earth::c_ne(s.pos.lat, s.pos.lon),
            r_e: earth.geodetic_to_ecef(&s.pos),
            v_c: s.v_n,
            q_bc: s.q_bn,
            w_ie_c: local.w_ie_n(),
            rho_c: local.w_en_n(&s.v_n),
            gravity: local.g_n.norm(),
            radius: (local.radii.meridian * local.radii.prime_vertical).sqrt() + s.pos.h,
        }
    }

    fn q_bc(&self) -> UnitQuaternion<f64> {
        self.state().q_bn
    }

    fn correct(&mut self, errors: &NavErrors) {
        let f = self.frame();
        let (r, v, q_be) = corrected_ecef(&f, errors);
        let earth = *self.earth();
        let mut state = nav_state_from_ecef(&earth, f.t, &r, &v, &q_be);
        // Keep the longitude on the branch it was on (ECEF gives it in (−π, π]).
        let tau = std::f64::consts::TAU;
        state.pos.lon += ((self.state().pos.lon - state.pos.lon) / tau).round() * tau;
        *self = LocalLevel::new(earth, state)
            .with_corrections(self.corrections())
            .with_history(self.history());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{Geodetic, Wgs84};
    use crate::rotation::{Euler, rotation_vector_from_quaternion};

    fn q_of(m: &Matrix3<f64>) -> UnitQuaternion<f64> {
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*m))
    }

    #[test]
    fn feeding_back_the_exact_errors_restores_the_true_state() {
        let truth = NavState::new(
            0.0,
            Geodetic::from_degrees(59.9, 30.3, 120.0),
            Vector3::new(12.0, -7.0, 0.5),
            Euler::from_degrees(3.0, -4.0, 250.0),
        );
        let computed = NavState::new(
            0.0,
            Geodetic::new(truth.pos.lat + 2e-5, truth.pos.lon - 3e-5, 108.0),
            Vector3::new(12.4, -7.3, 0.1),
            Euler::from_degrees(3.01, -3.98, 250.2),
        );
        let mut mech = LocalLevel::new(Wgs84, computed);
        let f = mech.frame();
        let c_ce = f.c_ce_to_e.transpose();
        // The definitions of the module doc, from the two states.
        let r_true = Wgs84.geodetic_to_ecef(&truth.pos);
        let c_en_true = crate::earth::c_ne(truth.pos.lat, truth.pos.lon);
        let v_e_true = c_en_true * truth.v_n;
        let c_cb_true = c_ce * c_en_true * truth.q_bn.to_rotation_matrix().into_inner();
        let errors = NavErrors {
            dr: c_ce * (f.r_e - r_true),
            dv: f.v_c - c_ce * v_e_true,
            psi: -rotation_vector_from_quaternion(&(f.q_bc * q_of(&c_cb_true).inverse())),
        };
        mech.correct(&errors);
        let s = mech.state();
        // The corrections are exact (ECEF differences, rotation vectors), so only
        // round-off remains: ECEF <-> geodetic at 6.4e6 m is good to ~1e-9 m.
        let dr = Wgs84.geodetic_to_ecef(&s.pos) - r_true;
        assert!(dr.norm() < 1e-8, "{dr}");
        assert!((s.v_n - truth.v_n).norm() < 1e-12);
        let dpsi = rotation_vector_from_quaternion(&(s.q_bn * truth.q_bn.inverse()));
        assert!(dpsi.norm() < 1e-14, "{dpsi}");
    }
}
