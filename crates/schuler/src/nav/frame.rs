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

use super::wander::{Curvature, polar_axis_w};
use super::{LocalLevel, Mechanization, NavState, Wander, WanderState};
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
    corrected_ecef_of(&f.c_ce_to_e, &f.r_e, &f.v_c, &f.q_bc, e)
}

/// [`corrected_ecef`] from the parts of a snapshot it uses: `c_ec` (`c` to ECEF),
/// ECEF position `r_e`, velocity in `c` `v_c` and attitude body to `c` `q_bc`.
pub fn corrected_ecef_of(
    c_ec: &Matrix3<f64>,
    r_e: &Vector3<f64>,
    v_c: &Vector3<f64>,
    q_bc: &UnitQuaternion<f64>,
    e: &NavErrors,
) -> (Vector3<f64>, Vector3<f64>, UnitQuaternion<f64>) {
    let r = r_e - c_ec * e.dr;
    let v = c_ec * (v_c - e.dv);
    let q_ce = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*c_ec));
    let q_be = q_ce * quaternion_from_rotation_vector(&e.psi) * q_bc;
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

impl<E: EarthModel> ErrorFrame for Wander<E> {
    fn frame(&self) -> FrameSnapshot {
        let s = self.wander_state();
        let earth = self.earth();
        let u = polar_axis_w(&s.q_we);
        let local = earth.local_from_sin_cos(-u.z, u.xy().norm(), s.h);
        let curvature = Curvature::at(&local, earth.eccentricity_squared());
        FrameSnapshot {
            t: s.t,
            c_ce_to_e: s.q_we.to_rotation_matrix().into_inner(),
            r_e: self.ecef_position(),
            v_c: s.v_w,
            q_bc: s.q_bw,
            w_ie_c: u * earth.rotation_rate(),
            rho_c: curvature.transport_rate(&u, &s.v_w),
            gravity: local.g_n.norm(),
            radius: (local.radii.meridian * local.radii.prime_vertical).sqrt() + s.h,
        }
    }

    fn q_bc(&self) -> UnitQuaternion<f64> {
        self.wander_state().q_bw
    }

    /// The wander frame moves with the corrected position by the smallest rotation
    /// that takes its old down axis to the new geodetic down (no azimuth change), so
    /// the correction is as regular at a pole as anywhere.
    fn correct(&mut self, errors: &NavErrors) {
        let f = self.frame();
        let (r, v_e, q_be) = corrected_ecef(&f, errors);
        let earth = *self.earth();
        let s = *self.wander_state();
        let p = earth.ecef_to_geodetic(&r);
        let (sl, cl) = p.lat.sin_cos();
        let (so, co) = p.lon.sin_cos();
        let down_new = -Vector3::new(cl * co, cl * so, sl);
        let down_old = s.q_we * Vector3::z();
        // The angle as atan2(|a×b|, a·b): an acos of the dot product (as
        // `rotation_between` takes) loses half the digits of a micro-radian turn.
        let axis = down_old.cross(&down_new);
        let angle = axis.norm().atan2(down_old.dot(&down_new));
        let turn = match axis.try_normalize(0.0) {
            Some(k) => quaternion_from_rotation_vector(&(k * angle)),
            None => UnitQuaternion::identity(),
        };
        let q_we = turn * s.q_we;
        let q_ew = q_we.inverse();
        let state = WanderState {
            t: s.t,
            q_we,
            h: p.h,
            v_w: q_ew * v_e,
            q_bw: q_ew * q_be,
        };
        *self = Wander::from_wander_state(earth, state)
            .with_corrections(self.corrections())
            .with_history(self.history())
            .with_pole_longitude(self.pole_longitude());
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

    #[test]
    fn wander_feedback_restores_the_true_state_exactly_at_the_pole() {
        use crate::nav::wander::q_we_from_geodetic;
        let earth = Wgs84;
        let truth = WanderState {
            t: 0.0,
            q_we: q_we_from_geodetic(std::f64::consts::FRAC_PI_2, 0.0, 0.3),
            h: 1000.0,
            v_w: Vector3::new(250.0, 3.0, -1.0),
            q_bw: Euler::from_degrees(2.0, -1.0, 40.0).to_quaternion(),
        };
        // The computed state: 30 m off (a rotation of the frame), other velocity and
        // attitude, other height.
        let off = crate::rotation::quaternion_from_rotation_vector(&Vector3::new(3e-6, -4e-6, 0.0));
        let computed = WanderState {
            q_we: truth.q_we * off,
            h: 1012.0,
            v_w: Vector3::new(250.5, 2.7, -0.6),
            q_bw: Euler::from_degrees(2.02, -0.97, 40.1).to_quaternion(),
            ..truth
        };
        let mut mech = Wander::from_wander_state(earth, computed);
        let f = mech.frame();
        let c_ce = f.c_ce_to_e.transpose();
        let r_true = truth.ecef_position(&earth);
        let c_cb_true = c_ce * truth.q_be().to_rotation_matrix().into_inner();
        let errors = NavErrors {
            dr: c_ce * (f.r_e - r_true),
            dv: f.v_c - c_ce * truth.v_e(),
            psi: -rotation_vector_from_quaternion(&(f.q_bc * q_of(&c_cb_true).inverse())),
        };
        mech.correct(&errors);
        let w = mech.wander_state();
        // Exact corrections: round-off only (ECEF at 6.4e6 m).
        let dr = mech.ecef_position() - r_true;
        assert!(dr.norm() < 1e-8, "{dr}");
        assert!((w.v_e() - truth.v_e()).norm() < 1e-10);
        let dpsi = rotation_vector_from_quaternion(&(w.q_be() * truth.q_be().inverse()));
        assert!(dpsi.norm() < 1e-13, "{dpsi}");
    }

    #[test]
    fn wander_and_ned_frames_coincide_at_zero_azimuth() {
        let s = NavState::new(
            0.0,
            Geodetic::from_degrees(60.0, 20.0, 500.0),
            Vector3::new(100.0, -50.0, 3.0),
            Euler::from_degrees(1.0, 2.0, 30.0),
        );
        let a = LocalLevel::new(Wgs84, s).frame();
        let b = Wander::new(Wgs84, s).frame();
        assert!((a.c_ce_to_e - b.c_ce_to_e).norm() < 1e-14);
        assert!((a.r_e - b.r_e).norm() < 1e-8);
        assert!((a.v_c - b.v_c).norm() < 1e-12);
        assert!(a.q_bc.angle_to(&b.q_bc) < 1e-14);
        assert!((a.w_ie_c - b.w_ie_c).norm() < 1e-18);
        // NED's transport rate has a vertical part (−v_E tan φ / R); the wander
        // frame's has none, and the horizontal parts agree.
        assert!(
            (a.rho_c.xy() - b.rho_c.xy()).norm() < 1e-15,
            "{} {}",
            a.rho_c,
            b.rho_c
        );
        assert_eq!(b.rho_c.z, 0.0);
        assert!((a.gravity - b.gravity).abs() < 1e-12 && (a.radius - b.radius).abs() < 1e-6);
    }

    #[test]
    fn wander_and_ned_corrections_agree() {
        let s = NavState::new(
            0.0,
            Geodetic::from_degrees(88.5, 0.0, 1000.0),
            Vector3::new(250.0, 0.0, 0.0),
            Euler::from_degrees(5.0, 2.0, 0.0),
        );
        let e = NavErrors {
            dr: Vector3::new(3.0, -2.0, 1.0),
            dv: Vector3::new(0.1, 0.2, -0.05),
            psi: Vector3::new(1e-4, -2e-4, 5e-4),
        };
        let mut a = LocalLevel::new(Wgs84, s);
        let mut b = Wander::new(Wgs84, s);
        let f0 = a.frame();
        let target = f0.r_e - f0.c_ce_to_e * e.dr;
        a.correct(&e);
        b.correct(&e);
        let (fa, fb) = (a.frame(), b.frame());
        println!(
            "ned {} wander {}",
            (fa.r_e - target).norm(),
            (fb.r_e - target).norm()
        );
        let c = |f: &FrameSnapshot| f.c_ce_to_e;
        assert!((fa.r_e - fb.r_e).norm() < 1e-6);
        assert!((c(&fa) * fa.v_c - c(&fb) * fb.v_c).norm() < 1e-9);
        let ca = c(&fa) * fa.q_bc.to_rotation_matrix().into_inner();
        let cb = c(&fb) * fb.q_bc.to_rotation_matrix().into_inner();
        assert!((ca - cb).norm() < 1e-12);
    }
}
