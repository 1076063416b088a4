//! Exact IMU increments from analytic trajectories.
//!
//! A trajectory gives geodetic position and the body-to-NED DCM as smooth formulas in
//! time, evaluated on [`Jet`]s so their derivatives are exact. From them, with `C_be =
//! C_ne C_bn` and ECEF position `r_e`:
//!
//! - angular rate `w_ib_b = C_eb w_ie_e + w_eb_b`, where `skew(w_eb_b) = C_be^T dC_be/dt`;
//! - specific force from Newton's law in the rotating ECEF frame,
//!   `f_e = r_e'' + 2 W × r_e' − g_e`, `f_b = C_eb f_e`, with `g_e = C_ne g_n` the same
//!   gravity (gravitation plus centrifugal) the mechanizations use.
//!
//! Increments `∫ w_ib_b dt` and `∫ f_b dt` over each interval come from 6-point
//! Gauss–Legendre quadrature ([`increment`]: exact for polynomials of degree 11; for
//! the smooth motions here the quadrature error is far below double-precision
//! round-off at 100–1000 Hz) or, for a stream of samples, from 4-point Gauss–Lobatto
//! on each smooth piece of the interval ([`increment_from`]: the same to round-off,
//! three pose evaluations per sample).

use super::jet::{self, Jet, JetMat3, JetVec3};
use crate::earth::{EarthModel, Geodetic};
use crate::imu::ImuSample;
use crate::nav::NavState;
use nalgebra::{UnitQuaternion, Vector3};

/// A smooth trajectory: position and attitude as formulas in time.
///
/// Trajectories are written either in geodetic terms (`position`, `c_bn`) or, where
/// latitude and longitude are singular (over a pole), directly in ECEF by overriding
/// [`Trajectory::ecef_pose`]; the kinematics use only the ECEF pose.
pub trait Trajectory {
    /// Latitude [rad], longitude [rad], height [m] at time `t`.
    fn position(&self, t: Jet) -> JetVec3;
    /// Body-to-NED DCM `c_bn` at time `t`.
    fn c_bn(&self, t: Jet) -> JetMat3;
    /// ECEF position `r_e` [m] and body-to-ECEF DCM `c_be` at time `t`; by default
    /// from the geodetic position and `c_be = c_ne c_bn`.
    fn ecef_pose<E: EarthModel>(&self, earth: &E, t: Jet) -> (JetVec3, JetMat3) {
        geodetic_pose(earth, &self.position(t), &self.c_bn(t))
    }
    /// True state and kinematics at time `t`; by default from [`Trajectory::ecef_pose`]
    /// ([`evaluate_ecef`]). A trajectory with a cheaper closed form overrides it.
    fn evaluate_at<E: EarthModel>(&self, earth: &E, t: f64) -> (NavState, Kinematics) {
        evaluate_ecef(earth, self, t)
    }
    /// True kinematics at time `t`; by default those of [`Trajectory::evaluate_at`].
    fn kinematics_at<E: EarthModel>(&self, earth: &E, t: f64) -> Kinematics {
        self.evaluate_at(earth, t).1
    }
    /// The trajectory's own Z-Y-X Euler angles at `t` (any range), where it is written
    /// in them: cheaper than taking them back out of the attitude. None by default.
    fn euler_at(&self, _t: f64) -> Option<crate::rotation::Euler> {
        None
    }
    /// The times in `(a, b)`, increasing, where the motion is less smooth than
    /// elsewhere (a spline's knots, where the jerk may jump): [`increment_from`] splits
    /// its interval there. None by default (smooth everywhere).
    fn breaks(&self, _a: f64, _b: f64) -> &[f64] {
        &[]
    }
}

/// ECEF position and body-to-ECEF DCM of a geodetic position and a `c_bn`, on jets.
pub fn geodetic_pose<E: EarthModel>(earth: &E, p: &JetVec3, c_bn: &JetMat3) -> (JetVec3, JetMat3) {
    (
        geodetic_to_ecef_jet(earth, p),
        c_ne_jet(p[0], p[1]).mul(c_bn),
    )
}

/// The truth in ECEF at one instant, defined everywhere (poles included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EcefTruth {
    /// Position [m].
    pub r_e: Vector3<f64>,
    /// Velocity relative to the Earth [m/s].
    pub v_e: Vector3<f64>,
    /// Body-to-ECEF DCM.
    pub c_be: nalgebra::Matrix3<f64>,
}

/// True ECEF position, velocity and attitude at time `t`.
pub fn ecef_truth<E: EarthModel, T: Trajectory + ?Sized>(earth: &E, traj: &T, t: f64) -> EcefTruth {
    let (r_e, c_be) = traj.ecef_pose(earth, Jet::variable(t));
    EcefTruth {
        r_e: jet::value(&r_e),
        v_e: jet::derivative(&r_e),
        c_be: c_be.value(),
    }
}

/// True angular rate and specific force at one instant, body axes FRD.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Kinematics {
    /// `w_ib_b` [rad/s].
    pub w_ib_b: Vector3<f64>,
    /// `f_b` [m/s^2].
    pub f_b: Vector3<f64>,
}

/// ECEF position of a geodetic position, on jets (same formula as
/// [`EarthModel::geodetic_to_ecef`]).
fn geodetic_to_ecef_jet<E: EarthModel>(earth: &E, p: &JetVec3) -> JetVec3 {
    let (a, e2) = (earth.semi_major_axis(), earth.eccentricity_squared());
    let [lat, lon, h] = *p;
    let sl = lat.sin();
    let rn = (Jet::constant(1.0) - sl * sl * e2).sqrt().recip() * a;
    let cl = lat.cos();
    [
        (rn + h) * cl * lon.cos(),
        (rn + h) * cl * lon.sin(),
        (rn * (1.0 - e2) + h) * sl,
    ]
}

/// NED-to-ECEF DCM on jets (see [`crate::earth::c_ne`]).
fn c_ne_jet(lat: Jet, lon: Jet) -> JetMat3 {
    let (sl, cl) = (lat.sin(), lat.cos());
    let (so, co) = (lon.sin(), lon.cos());
    let z = Jet::constant(0.0);
    JetMat3([
        [-(sl * co), -so, -(cl * co)],
        [-(sl * so), co, -(cl * so)],
        [cl, z, -sl],
    ])
}

/// True kinematics at time `t` ([`Trajectory::kinematics_at`]).
pub fn kinematics<E: EarthModel, T: Trajectory + ?Sized>(
    earth: &E,
    traj: &T,
    t: f64,
) -> Kinematics {
    traj.kinematics_at(earth, t)
}

/// True state (NED) and kinematics at time `t` ([`Trajectory::evaluate_at`]).
pub fn evaluate<E: EarthModel, T: Trajectory + ?Sized>(
    earth: &E,
    traj: &T,
    t: f64,
) -> (NavState, Kinematics) {
    traj.evaluate_at(earth, t)
}

/// True state (NED; latitude and longitude from the ECEF position, so undefined only
/// exactly at a pole) and kinematics at time `t`, from one evaluation of the ECEF pose
/// on jets: valid for any trajectory, poles included.
pub fn evaluate_ecef<E: EarthModel, T: Trajectory + ?Sized>(
    earth: &E,
    traj: &T,
    t: f64,
) -> (NavState, Kinematics) {
    let (r_e, c_be) = traj.ecef_pose(earth, Jet::variable(t));
    let c_be_v = c_be.value();
    let c_eb = c_be_v.transpose();
    let s = c_eb * c_be.derivative();
    let w_eb_b = Vector3::new(
        0.5 * (s[(2, 1)] - s[(1, 2)]),
        0.5 * (s[(0, 2)] - s[(2, 0)]),
        0.5 * (s[(1, 0)] - s[(0, 1)]),
    );
    let w_ie_e = Vector3::new(0.0, 0.0, earth.rotation_rate());
    let w_ib_b = c_eb * w_ie_e + w_eb_b;
    let v_e = jet::derivative(&r_e);
    let a_e = jet::second_derivative(&r_e);
    // Gravity along the local normal: north/east are arbitrary exactly at a pole,
    // where the normal-gravity field has no horizontal component.
    let pos = earth.ecef_to_geodetic(&jet::value(&r_e));
    let c_ne = crate::earth::c_ne(pos.lat, pos.lon);
    let g_e = c_ne * earth.gravity_n(pos.lat, pos.h);
    let f_e = a_e + 2.0 * w_ie_e.cross(&v_e) - g_e;
    let c_bn = c_ne.transpose() * c_be_v;
    let state = NavState {
        t,
        pos,
        v_n: c_ne.transpose() * v_e,
        q_bn: UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(
            c_bn,
        )),
    };
    (
        state,
        Kinematics {
            w_ib_b,
            f_b: c_eb * f_e,
        },
    )
}

/// Geodetic position and ZYX Euler angles with their first and second time
/// derivatives, `[value, rate, acceleration]` for lat, lon [rad], h [m], roll, pitch,
/// yaw [rad] (as [`super::spline::SplineTrajectory::derivatives`] gives them).
pub type GeodeticEuler = [[f64; 3]; 6];

/// What [`geodetic_kinematics`] computes besides the kinematics.
struct GeodeticExtras {
    v_n: Vector3<f64>,
    c_bn: nalgebra::Matrix3<f64>,
}

/// Kinematics in closed form from geodetic position and Euler angles with their
/// derivatives and the sines and cosines of latitude and the three Euler angles
/// (longitude enters only through its rates); no jets, no ECEF round trip.
///
/// Angular rate: `w_ib_b = w_nb_b + C_nb (w_ie_n + w_en_n)` with the exact kinematic
/// transport rate `w_en_n = [lon' cos lat, −lat', −lon' sin lat]`, `w_ie_n =
/// W [cos lat, 0, −sin lat]` and the ZYX Euler kinematics `w_nb_b = [roll' − yaw' sin
/// pitch, pitch' cos roll + yaw' sin roll cos pitch, −pitch' sin roll + yaw' cos roll
/// cos pitch]` (Titterton & Weston eq. 3.52 inverted).
///
/// Specific force: the same Newton's law as [`evaluate_ecef`], `f = r'' + 2 W × r' − g`,
/// written in the meridian frame (x from the polar axis towards the point, z polar,
/// turning with longitude at `lon'` relative to ECEF) where `r = [p, 0, z]` with `p =
/// (R_N + h) cos lat`, `z = (R_N (1 − e²) + h) sin lat`: relative to ECEF, `r' = [p',
/// p lon', z']` and `r'' = [p'' − p lon'², p lon'' + 2 p' lon', z'']`; the Earth's
/// rate has the same axis in both. `p`, `z` and their derivatives come from jets of
/// `sin lat`, `cos lat` built from one `sin_cos`. Then NED = (north `[−sin lat, 0, cos
/// lat]`, east `y`, down `[−cos lat, 0, −sin lat]`) and gravity from
/// [`EarthModel::local_from_sin_cos`], the mechanizations' gravity.
fn geodetic_kinematics<E: EarthModel>(
    earth: &E,
    c: &GeodeticEuler,
    trig: &Trig,
) -> (Kinematics, GeodeticExtras) {
    let [_, lon, hh, roll, pitch, yaw] = c;
    let lat = &c[0];
    let [(sl, cl), (sr, cr), (sp, cp), (sy, cy)] = *trig;
    let (l1, l2) = (lat[1], lat[2]);
    let (o1, o2) = (lon[1], lon[2]);
    let sin_lat = Jet {
        v: sl,
        d: cl * l1,
        dd: cl * l2 - sl * l1 * l1,
    };
    let cos_lat = Jet {
        v: cl,
        d: -sl * l1,
        dd: -sl * l2 - cl * l1 * l1,
    };
    let h = Jet {
        v: hh[0],
        d: hh[1],
        dd: hh[2],
    };
    let (a, e2) = (earth.semi_major_axis(), earth.eccentricity_squared());
    let rn = (Jet::constant(1.0) - sin_lat * sin_lat * e2).sqrt().recip() * a;
    let p = (rn + h) * cos_lat;
    let z = (rn * (1.0 - e2) + h) * sin_lat;
    let w = earth.rotation_rate();
    let v_m = Vector3::new(p.d, p.v * o1, z.d);
    let a_m = Vector3::new(p.dd - p.v * o1 * o1, p.v * o2 + 2.0 * p.d * o1, z.dd);
    let f_m = a_m + 2.0 * w * Vector3::new(-v_m.y, v_m.x, 0.0);
    let to_ned = |x: Vector3<f64>| Vector3::new(-sl * x.x + cl * x.z, x.y, -cl * x.x - sl * x.z);
    let g_n = earth.local_from_sin_cos(sl, cl, hh[0]).g_n;
    let f_n = to_ned(f_m) - g_n;
    let v_n = to_ned(v_m);

    let c_bn = nalgebra::Matrix3::new(
        cp * cy,
        -cr * sy + sr * sp * cy,
        sr * sy + cr * sp * cy,
        cp * sy,
        cr * cy + sr * sp * sy,
        -sr * cy + cr * sp * sy,
        -sp,
        sr * cp,
        cr * cp,
    );
    let (r1, p1, y1) = (roll[1], pitch[1], yaw[1]);
    let w_nb_b = Vector3::new(
        r1 - y1 * sp,
        p1 * cr + y1 * sr * cp,
        -p1 * sr + y1 * cr * cp,
    );
    let w_in_n = Vector3::new((w + o1) * cl, -l1, -(w + o1) * sl);
    let c_nb = c_bn.transpose();
    (
        Kinematics {
            w_ib_b: w_nb_b + c_nb * w_in_n,
            f_b: c_nb * f_n,
        },
        GeodeticExtras { v_n, c_bn },
    )
}

/// Sines and cosines `(sin, cos)` of latitude, roll, pitch and yaw.
pub type Trig = [(f64, f64); 4];

/// The [`Trig`] of `c`'s angles.
pub fn trig(c: &GeodeticEuler) -> Trig {
    [
        c[0][0].sin_cos(),
        c[3][0].sin_cos(),
        c[4][0].sin_cos(),
        c[5][0].sin_cos(),
    ]
}

/// True kinematics from geodetic position and Euler angles with their derivatives
/// (closed form, see [`evaluate_geodetic`]).
pub fn kinematics_geodetic<E: EarthModel>(earth: &E, c: &GeodeticEuler) -> Kinematics {
    kinematics_geodetic_with(earth, c, &trig(c))
}

/// [`kinematics_geodetic`] given the sines and cosines of `c`'s angles.
pub fn kinematics_geodetic_with<E: EarthModel>(
    earth: &E,
    c: &GeodeticEuler,
    trig: &Trig,
) -> Kinematics {
    geodetic_kinematics(earth, c, trig).0
}

/// True state at time `t` and kinematics from geodetic position and Euler angles with
/// their derivatives, in closed form: the same physics as [`evaluate_ecef`] at a
/// fraction of its cost (longitude wrapped to (−π, π]). Valid away from the poles,
/// where a geodetic trajectory is defined.
pub fn evaluate_geodetic<E: EarthModel>(
    earth: &E,
    t: f64,
    c: &GeodeticEuler,
) -> (NavState, Kinematics) {
    evaluate_geodetic_with(earth, t, c, &trig(c))
}

/// [`evaluate_geodetic`] given the sines and cosines of `c`'s angles.
pub fn evaluate_geodetic_with<E: EarthModel>(
    earth: &E,
    t: f64,
    c: &GeodeticEuler,
    trig: &Trig,
) -> (NavState, Kinematics) {
    let (kin, x) = geodetic_kinematics(earth, c, trig);
    let state = NavState {
        t,
        pos: Geodetic::new(c[0][0], crate::rotation::wrap_pi(c[1][0]), c[2][0]),
        v_n: x.v_n,
        q_bn: UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(
            x.c_bn,
        )),
    };
    (state, kin)
}

/// True navigation state at time `t`.
pub fn state<E: EarthModel, T: Trajectory + ?Sized>(earth: &E, traj: &T, t: f64) -> NavState {
    let tj = Jet::variable(t);
    let p = traj.position(tj);
    let r_e = geodetic_to_ecef_jet(earth, &p);
    let c_ne = c_ne_jet(p[0], p[1]).value();
    let v_n = c_ne.transpose() * jet::derivative(&r_e);
    let c_bn = traj.c_bn(tj).value();
    let q_bn =
        UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(c_bn));
    NavState {
        t,
        pos: Geodetic::new(p[0].v, p[1].v, p[2].v),
        v_n,
        q_bn,
    }
}

/// 6-point Gauss–Legendre nodes on [-1, 1] and weights.
const GL6: [(f64, f64); 6] = [
    (-0.932_469_514_203_152, 0.171_324_492_379_170_3),
    (-0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
    (-0.238_619_186_083_196_9, 0.467_913_934_572_691),
    (0.238_619_186_083_196_9, 0.467_913_934_572_691),
    (0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
    (0.932_469_514_203_152, 0.171_324_492_379_170_3),
];

/// The exact IMU sample for the interval `(t - dt, t]`.
pub fn increment<E: EarthModel, T: Trajectory + ?Sized>(
    earth: &E,
    traj: &T,
    t: f64,
    dt: f64,
) -> ImuSample {
    let mid = t - 0.5 * dt;
    let half = 0.5 * dt;
    let (mut dtheta, mut dvel) = (Vector3::zeros(), Vector3::zeros());
    for (x, w) in GL6 {
        let k = kinematics(earth, traj, mid + half * x);
        dtheta += k.w_ib_b * (w * half);
        dvel += k.f_b * (w * half);
    }
    ImuSample {
        t,
        dt,
        dtheta,
        dvel,
    }
}

/// Inner nodes `±1/√5` of the 4-point Gauss–Lobatto rule on [-1, 1] (weights 5/6; the
/// end nodes `±1` weigh 1/6; exact for degree 5). The end nodes are shared by
/// adjacent intervals, so a stream of samples costs three pose evaluations per sample,
/// one of which is the truth at the sample time.
const LOBATTO4_INNER: f64 = 0.447_213_595_499_957_9;

/// `∫ w_ib_b` and `∫ f_b` over `[mid - half, mid + half]` by the 4-point
/// Gauss–Lobatto rule, given the kinematics at both ends and `at`, the kinematics at
/// any instant inside (called at the two inner nodes).
pub(crate) fn lobatto4_rule(
    (mid, half): (f64, f64),
    (left, right): (&Kinematics, &Kinematics),
    mut at: impl FnMut(f64) -> Kinematics,
) -> (Vector3<f64>, Vector3<f64>) {
    let k1 = at(mid - half * LOBATTO4_INNER);
    let k2 = at(mid + half * LOBATTO4_INNER);
    let (w_end, w_inner) = (half / 6.0, half * (5.0 / 6.0));
    (
        (left.w_ib_b + right.w_ib_b) * w_end + (k1.w_ib_b + k2.w_ib_b) * w_inner,
        (left.f_b + right.f_b) * w_end + (k1.f_b + k2.f_b) * w_inner,
    )
}

/// `∫ w_ib_b` and `∫ f_b` over the piece of length `2 half` ending at `end`, given the
/// kinematics at both ends ([`lobatto4_rule`]), added to `dtheta` and `dvel`.
#[allow(clippy::too_many_arguments)]
fn lobatto4<E: EarthModel, T: Trajectory + ?Sized>(
    earth: &E,
    traj: &T,
    end: f64,
    half: f64,
    left: &Kinematics,
    right: &Kinematics,
    dtheta: &mut Vector3<f64>,
    dvel: &mut Vector3<f64>,
) {
    let (w, f) = lobatto4_rule((end - half, half), (left, right), |t| {
        kinematics(earth, traj, t)
    });
    *dtheta += w;
    *dvel += f;
}

/// The exact sample over `(t - dt, t]` and the truth at `t`, given the kinematics at
/// `t - dt` (from the previous call).
///
/// The interval is split at the trajectory's [`Trajectory::breaks`] (a spline's
/// knots, where the jerk may jump) and each piece integrated by the 4-point
/// Gauss–Lobatto rule, which is exact far below round-off on a smooth piece: on the
/// maneuvering flight at 100 Hz it agrees with 6-point Gauss–Legendre (degree 11) to
/// 1e-15 relative. Across a knot a single rule of any order would err by the jump
/// times `dt³` (2e-4 relative at 100 Hz with 5 points): split, the increments are
/// exact there too. The first piece takes what the others leave of `dt`, so the pieces
/// tile the interval exactly.
pub fn increment_from<E: EarthModel, T: Trajectory + ?Sized>(
    earth: &E,
    traj: &T,
    t: f64,
    dt: f64,
    at_start: &Kinematics,
) -> (ImuSample, NavState, Kinematics) {
    let breaks = traj.breaks(t - dt, t);
    let (mut dtheta, mut dvel) = (Vector3::zeros(), Vector3::zeros());
    let mut left = *at_start;
    let mut len = breaks.first().map_or(dt, |&b| dt - (t - b));
    for (j, &b) in breaks.iter().enumerate() {
        let right = kinematics(earth, traj, b);
        lobatto4(
            earth,
            traj,
            b,
            0.5 * len,
            &left,
            &right,
            &mut dtheta,
            &mut dvel,
        );
        len = breaks.get(j + 1).unwrap_or(&t) - b;
        left = right;
    }
    let (state, end) = evaluate(earth, traj, t);
    lobatto4(
        earth,
        traj,
        t,
        0.5 * len,
        &left,
        &end,
        &mut dtheta,
        &mut dvel,
    );
    (
        ImuSample {
            t,
            dt,
            dtheta,
            dvel,
        },
        state,
        end,
    )
}

/// Exact samples at times `t0 + k*dt` for `k = 1..=n`, each over the preceding interval.
pub fn samples<'a, E: EarthModel, T: Trajectory + ?Sized>(
    earth: &'a E,
    traj: &'a T,
    t0: f64,
    dt: f64,
    n: usize,
) -> impl Iterator<Item = ImuSample> + 'a {
    (1..=n).map(move |k| increment(earth, traj, t0 + k as f64 * dt, dt))
}

#[cfg(test)]
mod quadrature_tests {
    use super::*;
    use crate::earth::Wgs84;

    /// The streaming Gauss–Lobatto increments equal the Gauss–Legendre ones on the
    /// maneuvering flight to 1e-15 relative of the increment's size (both quadratures
    /// are exact far beyond round-off for this smooth motion at 100 Hz).
    #[test]
    fn lobatto_matches_legendre() {
        let traj = Maneuvering::flight(Geodetic::from_degrees(30.0, 100.0, 100.0));
        let dt = 0.01;
        let mut prev = kinematics(&Wgs84, &traj, 5.0);
        for k in 1..=200 {
            let t = 5.0 + k as f64 * dt;
            let (s, truth, end) = increment_from(&Wgs84, &traj, t, dt, &prev);
            let g = increment(&Wgs84, &traj, t, dt);
            assert!((s.dtheta - g.dtheta).norm() <= 2e-15 * g.dtheta.norm().max(1e-9));
            assert!((s.dvel - g.dvel).norm() <= 2e-15 * g.dvel.norm());
            let direct = state(&Wgs84, &traj, t);
            assert!((truth.pos.lat - direct.pos.lat).abs() < 1e-15);
            assert!(truth.q_bn.angle_to(&direct.q_bn) < 1e-15);
            assert!((truth.v_n - direct.v_n).norm() < 1e-12);
            prev = end;
        }
    }

    /// Across a spline knot, where the jerk jumps, the streaming increments equal
    /// 6-point Gauss–Legendre applied to each side of the knot separately; Legendre
    /// over the whole interval, blind to the knot, cannot integrate the kink and
    /// differs by orders of magnitude more. A coordinated turn with roll, pitch and
    /// speed changes in two 0.73-s bumps (yaw rate up to 2 rad/s), sampled at 100 Hz
    /// between its 100 Hz knots. Bounds: twice the 4-point rule's own error, `(b-a)^7
    /// f^(6) / 1.512e6`, on these fast bumps at 100 Hz (measured 5.6e-16 rad and
    /// 4.0e-14 m/s, i.e. 6e-14 rad/s and 4e-12 m/s^2 as rates, a millionth of a
    /// navigation-grade bias; at 200 Hz 2^7 times less); the knot-blind rule errs by
    /// 1e-10 rad and 3e-7 m/s, over 10^5 times more.
    #[test]
    fn knots_split_the_interval() {
        use crate::sim::motion::{Piece, Shape, Start, generate};
        let start = Start {
            t: 0.0,
            pos: Geodetic::from_degrees(45.0, 7.0, 100.0),
            v_n: Vector3::new(40.0, 0.0, 0.0),
            attitude: crate::rotation::Euler::default(),
        };
        let turn = Piece {
            d_euler: [0.4, 0.1, 0.8],
            d_vel: [3.0, 0.5, -2.0],
            shape: Shape::Bump,
            coordinated: true,
            ..Piece::hold(0.73)
        };
        let traj = generate(&Wgs84, &start, &[turn, turn])
            .expect("motion")
            .trajectory;
        let dt = 0.01;
        let t0 = 0.0037;
        let mut prev = kinematics(&Wgs84, &traj, t0);
        let (mut split, mut blind, mut splits) = ([0.0f64; 2], [0.0f64; 2], 0);
        for k in 1..=140 {
            let t = t0 + k as f64 * dt;
            let (s, _, end) = increment_from(&Wgs84, &traj, t, dt, &prev);
            prev = end;
            let mut reference = (Vector3::zeros(), Vector3::zeros());
            let mut left = t - dt;
            for &right in traj.breaks(t - dt, t).iter().chain([t].iter()) {
                let piece = increment(&Wgs84, &traj, right, right - left);
                reference.0 += piece.dtheta;
                reference.1 += piece.dvel;
                left = right;
            }
            splits += traj.breaks(t - dt, t).len();
            let whole = increment(&Wgs84, &traj, t, dt);
            split[0] = split[0].max((s.dtheta - reference.0).norm());
            split[1] = split[1].max((s.dvel - reference.1).norm());
            blind[0] = blind[0].max((whole.dtheta - reference.0).norm());
            blind[1] = blind[1].max((whole.dvel - reference.1).norm());
        }
        eprintln!("{splits} knots: split {split:?} rad, m/s; knot-blind {blind:?}");
        assert!(splits >= 139);
        assert!(split[0] < 1e-15 && split[1] < 1e-13, "{split:?}");
        assert!(
            blind[0] > 1e5 * split[0] && blind[1] > 1e5 * split[1],
            "{blind:?}"
        );
    }
}

/// At rest at a fixed position with a fixed attitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stationary {
    /// Position.
    pub pos: Geodetic,
    /// Attitude.
    pub attitude: crate::rotation::Euler,
}

impl Trajectory for Stationary {
    fn position(&self, _t: Jet) -> JetVec3 {
        [self.pos.lat, self.pos.lon, self.pos.h].map(Jet::constant)
    }
    fn c_bn(&self, _t: Jet) -> JetMat3 {
        let e = self.attitude;
        JetMat3::from_euler(
            Jet::constant(e.roll),
            Jet::constant(e.pitch),
            Jet::constant(e.yaw),
        )
    }
}

/// A 30-minute-class flight of turns, climbs, pitch and roll motion about a start point,
/// written as sums of sinusoids and a steady drift so every derivative is smooth:
/// horizontal circles of radius `turn_radius` at angular rate `turn_rate` superposed on a
/// steady eastward drift, a height oscillation, and attitude that follows the turn with
/// roll and pitch oscillations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Maneuvering {
    /// Start position.
    pub origin: Geodetic,
    /// Radius of the horizontal circles [m].
    pub turn_radius: f64,
    /// Angular rate of the circles [rad/s].
    pub turn_rate: f64,
    /// Steady eastward drift [m/s].
    pub drift_east: f64,
    /// Amplitude of the climbs and descents [m], period `climb_period` [s].
    pub climb_amplitude: f64,
    /// Period of the climbs [s].
    pub climb_period: f64,
    /// Roll amplitude [rad] and period [s].
    pub roll_amplitude: f64,
    /// Roll period [s].
    pub roll_period: f64,
    /// Pitch amplitude [rad] and period [s].
    pub pitch_amplitude: f64,
    /// Pitch period [s].
    pub pitch_period: f64,
}

impl Maneuvering {
    /// The default test flight: 2 km circles every 4 min (52 m/s), 20 m/s drift east,
    /// +-150 m climbs every 5 min, +-25 deg roll every 37 s, +-8 deg pitch every 23 s.
    pub fn flight(origin: Geodetic) -> Self {
        Self {
            origin,
            turn_radius: 2000.0,
            turn_rate: std::f64::consts::TAU / 240.0,
            drift_east: 20.0,
            climb_amplitude: 150.0,
            climb_period: 300.0,
            roll_amplitude: 25f64.to_radians(),
            roll_period: 37.0,
            pitch_amplitude: 8f64.to_radians(),
            pitch_period: 23.0,
        }
    }
}

impl Trajectory for Maneuvering {
    fn position(&self, t: Jet) -> JetVec3 {
        use std::f64::consts::TAU;
        // Metres north/east mapped to angles with fixed scale factors: any smooth map
        // is a valid trajectory; this one keeps the motion close to the nominal speeds.
        let a = 6_378_137.0;
        let wt = t * self.turn_rate;
        let north = wt.sin() * self.turn_radius;
        let east = (Jet::constant(1.0) - wt.cos()) * self.turn_radius + t * self.drift_east;
        let up = (t * (TAU / self.climb_period)).sin() * self.climb_amplitude;
        [
            north * (1.0 / a) + self.origin.lat,
            east * (1.0 / (a * self.origin.lat.cos())) + self.origin.lon,
            up + self.origin.h,
        ]
    }

    fn c_bn(&self, t: Jet) -> JetMat3 {
        use std::f64::consts::TAU;
        let yaw = t * self.turn_rate + (t * (TAU / 90.0)).sin() * 0.2;
        let roll = (t * (TAU / self.roll_period)).sin() * self.roll_amplitude;
        let pitch = (t * (TAU / self.pitch_period)).sin() * self.pitch_amplitude;
        JetMat3::from_euler(roll, pitch, yaw)
    }
}

/// Classical coning at a fixed position: the body rotates by the cone half-angle
/// `half_angle` about an axis in the body y-z plane that itself turns about x at
/// `rate` [rad/s] (Savage 1998, the classical coning environment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coning {
    /// Position.
    pub pos: Geodetic,
    /// Cone half-angle [rad].
    pub half_angle: f64,
    /// Coning frequency [rad/s].
    pub rate: f64,
}

impl Trajectory for Coning {
    fn position(&self, _t: Jet) -> JetVec3 {
        [self.pos.lat, self.pos.lon, self.pos.h].map(Jet::constant)
    }
    fn c_bn(&self, t: Jet) -> JetMat3 {
        let wt = t * self.rate;
        let u = [Jet::constant(0.0), wt.cos(), wt.sin()];
        JetMat3::from_axis_angle(&u, Jet::constant(self.half_angle))
    }
}

/// Classical sculling: roll oscillation `roll_amplitude sin(rate t)` in phase with an
/// east position oscillation `-east_amplitude sin(rate t)` (body-y acceleration in
/// phase with roll angle), which rectifies into a steady velocity change along body z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sculling {
    /// Centre position.
    pub pos: Geodetic,
    /// Roll amplitude [rad].
    pub roll_amplitude: f64,
    /// East displacement amplitude [m].
    pub east_amplitude: f64,
    /// Angular frequency [rad/s].
    pub rate: f64,
}

impl Trajectory for Sculling {
    fn position(&self, t: Jet) -> JetVec3 {
        let s = (t * self.rate).sin();
        let east = s * (-self.east_amplitude);
        let scale = 1.0 / (6_378_137.0 * self.pos.lat.cos());
        [
            Jet::constant(self.pos.lat),
            east * scale + self.pos.lon,
            Jet::constant(self.pos.h),
        ]
    }
    fn c_bn(&self, t: Jet) -> JetMat3 {
        let roll = (t * self.rate).sin() * self.roll_amplitude;
        JetMat3::from_euler(roll, Jet::constant(0.0), Jet::constant(0.0))
    }
}
