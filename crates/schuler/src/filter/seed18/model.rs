//! The 18-state model's algebra: quaternion product matrices, the point of
//! linearisation, the local dynamics `F`, the maps between the additive states `x`
//! and the local coordinates `y`, the transition and the process noise (equations in
//! the [module doc](super)).

use crate::earth::EarthModel;
use crate::filter::noise::ImuNoise;
use crate::nav::Wander;
use crate::nav::wander::{Curvature, geodetic_from_q_we, gravity_w, polar_axis_w};
use crate::rotation::skew;
use nalgebra::{Matrix2, Matrix3, Matrix4, SMatrix, UnitQuaternion, Vector3, Vector4};

/// Number of states.
pub const N: usize = 18;
/// An 18 × 18 matrix.
pub type Mat18 = SMatrix<f64, N, N>;

/// Velocity errors `δV` (3).
pub const VEL: usize = 0;
/// Errors of the navigation quaternion `δp` (4: `w, x, y, z`).
pub const NAV_Q: usize = 3;
/// Errors of the orientation quaternion `δq0` (4: `w, x, y, z`).
pub const ORI_Q: usize = 7;
/// Gyro drifts `ε` (3, body) [rad/s].
pub const GYRO: usize = 11;
/// Accelerometer biases `Δf` (3, body) [m/s²].
pub const ACCEL: usize = 14;
/// Height error `δh` (1) [m].
pub const HEIGHT: usize = 17;

/// Names of the states, for reports.
pub const NAMES: [&str; N] = [
    "dV_x", "dV_y", "dV_z", "dp_0", "dp_1", "dp_2", "dp_3", "dq0_0", "dq0_1", "dq0_2", "dq0_3",
    "eps_x", "eps_y", "eps_z", "df_x", "df_y", "df_z", "dh",
];

// Offsets in the local coordinates y = [δV, η_p, φ_w, η_0, φ_i, ε, Δf, δh].
const ETA_P: usize = 3;
/// Offset of the frame angle `φ_w` in the local coordinates.
pub(crate) const PHI_W_COLS: usize = 4;
const PHI_W: usize = PHI_W_COLS;
const ETA_0: usize = 7;
const PHI_I: usize = 8;

/// A unit quaternion as the 4-vector `[w, x, y, z]` (the paper's `p0..p3`).
pub fn q4(q: &UnitQuaternion<f64>) -> Vector4<f64> {
    Vector4::new(q.w, q.i, q.j, q.k)
}

/// Left-product matrix: `a ⊗ b = L(a) b` (4-vectors `[w, x, y, z]`).
pub fn lmat(a: &Vector4<f64>) -> Matrix4<f64> {
    let (w, x, y, z) = (a[0], a[1], a[2], a[3]);
    Matrix4::new(w, -x, -y, -z, x, w, -z, y, y, z, w, -x, z, -y, x, w)
}

/// Right-product matrix: `a ⊗ b = R(b) a`.
pub fn rmat(b: &Vector4<f64>) -> Matrix4<f64> {
    let (w, x, y, z) = (b[0], b[1], b[2], b[3]);
    Matrix4::new(w, -x, -y, -z, x, w, z, -y, y, -z, w, x, z, y, -x, w)
}

/// Earth-to-inertial rotation `q_ei = q_z(Ω (t − t_ref))` (the inertial frame is
/// the ECEF frame at `t_ref`).
pub fn earth_to_inertial(omega: f64, t: f64, t_ref: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), omega * (t - t_ref))
}

/// Transport rate and gravity in the wander frame at polar axis `u`, velocity `v` and
/// height `h`, as the mechanization forms them.
fn rho_gravity<E: EarthModel>(
    earth: &E,
    u: &Vector3<f64>,
    v: &Vector3<f64>,
    h: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let local = earth.local_from_sin_cos(-u.z, u.xy().norm(), h);
    let c = Curvature::at(&local, earth.eccentricity_squared());
    (c.transport_rate(u, v), gravity_w(&local.g_n, u))
}

/// Step of the central differences in the frame angle [rad] and in height [m]: the
/// truncation error is O(step²) relative (1e-12 and 1e-13), the round-off
/// 1e-16 / step relative (1e-10 of the partial at most for the angle).
const ANGLE_STEP: f64 = 1e-6;
const HEIGHT_STEP: f64 = 1.0;

/// The mechanization's quantities the model is linearised about, at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Time [s].
    pub t: f64,
    /// Navigation quaternion `p = q_we` as `[w, x, y, z]`.
    pub p: Vector4<f64>,
    /// Orientation quaternion `q0 = q_bi = q_ei ⊗ p ⊗ q_bw`.
    pub q0: Vector4<f64>,
    /// Body to wander `C_bw`.
    pub c_bw: Matrix3<f64>,
    /// Inertial to wander `C_iw = C_ew C_ie`.
    pub c_iw: Matrix3<f64>,
    /// Velocity in the wander frame [m/s].
    pub v_w: Vector3<f64>,
    /// Polar axis in the wander frame.
    pub u: Vector3<f64>,
    /// Transport rate [rad/s].
    pub rho: Vector3<f64>,
    /// Earth rate magnitude [rad/s].
    pub omega: f64,
    /// Latitude, longitude (the seed's formulas) [rad] and height [m].
    pub lat: f64,
    /// Longitude [rad].
    pub lon: f64,
    /// Height [m].
    pub h: f64,
    /// Wander azimuth `α` [rad].
    pub alpha: f64,
    /// Meridian and prime-vertical radii plus height [m].
    pub rm_h: f64,
    /// `R_N + h` [m].
    pub rn_h: f64,
    /// `∂ρ/∂V` (the curvature map `T`, `ρ = T V`).
    pub r_v: Matrix3<f64>,
    /// `∂ρ/∂φ_w` through the polar axis and the curvature's latitude.
    pub r_phi: Matrix3<f64>,
    /// `∂ρ/∂h`.
    pub r_h: Vector3<f64>,
    /// `∂g/∂φ_w`.
    pub g_phi: Matrix3<f64>,
    /// `∂g/∂h`.
    pub g_h: Vector3<f64>,
}

impl Point {
    /// The point of a wander mechanization now; `t_ref` fixes the inertial frame.
    pub fn of<E: EarthModel>(mech: &Wander<E>, t_ref: f64) -> Self {
        let earth = mech.earth();
        let s = mech.wander_state();
        let omega = earth.rotation_rate();
        let q_ei = earth_to_inertial(omega, s.t, t_ref);
        let q0 = q_ei * s.q_we * s.q_bw;
        let u = polar_axis_w(&s.q_we);
        let (rho, _) = rho_gravity(earth, &u, &s.v_w, s.h);
        let mut r_v = Matrix3::zeros();
        let mut r_phi = Matrix3::zeros();
        let mut g_phi = Matrix3::zeros();
        for j in 0..3 {
            r_v.set_column(j, &rho_gravity(earth, &u, &Vector3::ith(j, 1.0), s.h).0);
            let du = u.cross(&Vector3::ith(j, ANGLE_STEP));
            let (rp, gp) = rho_gravity(earth, &(u + du), &s.v_w, s.h);
            let (rm, gm) = rho_gravity(earth, &(u - du), &s.v_w, s.h);
            r_phi.set_column(j, &((rp - rm) / (2.0 * ANGLE_STEP)));
            g_phi.set_column(j, &((gp - gm) / (2.0 * ANGLE_STEP)));
        }
        let (rp, gp) = rho_gravity(earth, &u, &s.v_w, s.h + HEIGHT_STEP);
        let (rm, gm) = rho_gravity(earth, &u, &s.v_w, s.h - HEIGHT_STEP);
        let (lat, lon, alpha) = geodetic_from_q_we(&s.q_we, mech.pole_longitude());
        let radii = earth.radii(lat);
        Self {
            t: s.t,
            p: q4(&s.q_we),
            q0: q4(&q0),
            c_bw: s.q_bw.to_rotation_matrix().into_inner(),
            c_iw: (q_ei * s.q_we).inverse().to_rotation_matrix().into_inner(),
            v_w: s.v_w,
            u,
            rho,
            omega,
            lat,
            lon,
            h: s.h,
            alpha,
            rm_h: radii.meridian + s.h,
            rn_h: radii.prime_vertical + s.h,
            r_v,
            r_phi,
            r_h: (rp - rm) / (2.0 * HEIGHT_STEP),
            g_phi,
            g_h: (gp - gm) / (2.0 * HEIGHT_STEP),
        }
    }

    /// Horizontal rotation wander → NED, `R_z(α)` on the first two axes.
    pub fn r2(&self) -> Matrix2<f64> {
        let (s, c) = self.alpha.sin_cos();
        Matrix2::new(c, -s, s, c)
    }

    /// `R_z(α)`: wander → NED.
    pub fn rz(&self) -> Matrix3<f64> {
        let (s, c) = self.alpha.sin_cos();
        Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
    }

    /// The horizontal displacement (wander axes) per unit of horizontal frame angle:
    /// `T⁻¹` (`φ_h = T d`); `None` where `T` is singular (never on an Earth model).
    pub fn displacement_of_angle(&self) -> Option<Matrix2<f64>> {
        self.r_v.fixed_view::<2, 2>(0, 0).into_owned().try_inverse()
    }

    /// `x = M y`: the additive errors from the local coordinates
    /// (`δp = p ⊗ (η_p, ½φ_w)`, `δq0 = (η_0, ½φ_i) ⊗ q0`).
    pub fn to_additive(&self) -> Mat18 {
        let half = Matrix4::from_diagonal(&Vector4::new(1.0, 0.5, 0.5, 0.5));
        let mut m = Mat18::identity();
        m.fixed_view_mut::<4, 4>(NAV_Q, ETA_P)
            .copy_from(&(lmat(&self.p) * half));
        m.fixed_view_mut::<4, 4>(ORI_Q, ETA_0)
            .copy_from(&(rmat(&self.q0) * half));
        m
    }

    /// `y = M⁻¹ x` (`L` and `R` of unit quaternions are orthogonal).
    pub fn to_local(&self) -> Mat18 {
        let double = Matrix4::from_diagonal(&Vector4::new(1.0, 2.0, 2.0, 2.0));
        let mut m = Mat18::identity();
        m.fixed_view_mut::<4, 4>(ETA_P, NAV_Q)
            .copy_from(&(double * lmat(&self.p).transpose()));
        m.fixed_view_mut::<4, 4>(ETA_0, ORI_Q)
            .copy_from(&(double * rmat(&self.q0).transpose()));
        m
    }

    /// The local dynamics `F` (module doc) with mean specific force `f_w` (wander axes).
    pub fn dynamics(&self, f_w: &Vector3<f64>, noise: &ImuNoise) -> Mat18 {
        let mut a = Mat18::zeros();
        let vx = skew(&self.v_w);
        let two_omega = 2.0 * self.omega;
        let mut put = |r: usize, c: usize, b: &Matrix3<f64>| {
            a.fixed_view_mut::<3, 3>(r, c).copy_from(b);
        };
        put(
            VEL,
            VEL,
            &(-skew(&(self.u * two_omega + self.rho)) + vx * self.r_v),
        );
        put(
            VEL,
            PHI_W,
            &(skew(f_w) + vx * skew(&self.u) * two_omega + self.g_phi + vx * self.r_phi),
        );
        put(VEL, PHI_I, &(-skew(f_w) * self.c_iw));
        put(VEL, ACCEL, &self.c_bw);
        put(PHI_W, VEL, &self.r_v);
        put(PHI_W, PHI_W, &(self.r_phi - skew(&self.rho)));
        let c_bi = self.c_iw.transpose() * self.c_bw;
        put(PHI_I, GYRO, &c_bi);
        let vh = self.g_h + vx * self.r_h;
        for i in 0..3 {
            a[(VEL + i, HEIGHT)] = vh[i];
            a[(PHI_W + i, HEIGHT)] = self.r_h[i];
            a[(GYRO + i, GYRO + i)] = -1.0 / noise.gyro_bias_tau;
            a[(ACCEL + i, ACCEL + i)] = -1.0 / noise.accel_bias_tau;
        }
        a[(HEIGHT, VEL + 2)] = -1.0;
        a
    }

    /// The local process noise density `Q`: velocity and accelerometer noise through
    /// `C_bw`, angle noise through `C_bi`, the bias walks.
    pub fn process_noise(&self, noise: &ImuNoise) -> Mat18 {
        let mut q = Mat18::zeros();
        let sq = |v: &Vector3<f64>| Matrix3::from_diagonal(&v.component_mul(v));
        let c_bi = self.c_iw.transpose() * self.c_bw;
        let blocks = [
            (VEL, self.c_bw * sq(&noise.vrw) * self.c_bw.transpose()),
            (PHI_I, c_bi * sq(&noise.arw) * c_bi.transpose()),
            (GYRO, sq(&noise.gyro_bias_walk)),
            (ACCEL, sq(&noise.accel_bias_walk)),
        ];
        for (o, b) in blocks {
            q.fixed_view_mut::<3, 3>(o, o).copy_from(&b);
        }
        q
    }

    /// The physical errors the additive state `x` stands for, `e = G x`: position
    /// error north, east, down [m], velocity error in NED (relative to the Earth,
    /// computed minus true) [m/s] and the attitude error `ψ` about north, east, down
    /// (`Ĉ_bn = (I − ψ×) C_bn`) [rad]. `None` where `T` is singular.
    pub fn physical(&self) -> Option<SMatrix<f64, 9, N>> {
        let t_inv = self.displacement_of_angle()?;
        let rz = self.rz();
        let mut g = SMatrix::<f64, 9, N>::zeros();
        g.fixed_view_mut::<2, 2>(0, PHI_W)
            .copy_from(&(self.r2() * t_inv));
        g[(2, HEIGHT)] = -1.0;
        g.fixed_view_mut::<3, 3>(3, VEL).copy_from(&rz);
        g.fixed_view_mut::<3, 3>(3, PHI_W)
            .copy_from(&(-rz * skew(&self.v_w)));
        g.fixed_view_mut::<3, 3>(6, PHI_I)
            .copy_from(&(-rz * self.c_iw));
        Some(g * self.to_local())
    }

    /// The additive state of physical errors and sensor errors, `x = M A e'` with
    /// `e' = [position NED, velocity NED, ψ NED, ε, Δf]` (the inverse of
    /// [`Point::physical`], with the gauge `φ_w,z = 0`: the true free-azimuth
    /// trihedron parallel to the computed one about the vertical).
    pub fn from_physical(&self) -> SMatrix<f64, N, 15> {
        let rz = self.rz();
        let mut a = SMatrix::<f64, N, 15>::zeros();
        let t = self.r_v.fixed_view::<2, 2>(0, 0).into_owned();
        let phi_h = t * self.r2().transpose();
        a.fixed_view_mut::<2, 2>(PHI_W, 0).copy_from(&phi_h);
        a[(HEIGHT, 2)] = -1.0;
        // δV = R_zᵀ δv_n + [V×] φ_w.
        a.fixed_view_mut::<3, 3>(VEL, 3).copy_from(&rz.transpose());
        let vx = skew(&self.v_w);
        let vphi = vx.fixed_view::<3, 2>(0, 0) * phi_h;
        a.fixed_view_mut::<3, 2>(VEL, 0).copy_from(&vphi);
        // φ_i = −C_wi R_zᵀ ψ.
        a.fixed_view_mut::<3, 3>(PHI_I, 6)
            .copy_from(&(-self.c_iw.transpose() * rz.transpose()));
        a.fixed_view_mut::<6, 6>(GYRO, 9)
            .copy_from(&SMatrix::<f64, 6, 6>::identity());
        self.to_additive() * a
    }

    /// The projector on the unit-norm tangent of both quaternions,
    /// `Π = diag(I, I − p pᵀ, I − q0 q0ᵀ, I)` (the linearised normalisation
    /// `d(q/|q|) = (I − q qᵀ) dq` at `|q| = 1`).
    pub fn norm_projector(&self) -> Mat18 {
        let mut m = Mat18::identity();
        m.fixed_view_mut::<4, 4>(NAV_Q, NAV_Q)
            .copy_from(&(Matrix4::identity() - self.p * self.p.transpose()));
        m.fixed_view_mut::<4, 4>(ORI_Q, ORI_Q)
            .copy_from(&(Matrix4::identity() - self.q0 * self.q0.transpose()));
        m
    }
}

/// Transition matrix and discrete process noise of the additive state over an
/// interval from `start` to `end` of length `dt` with mean specific force `f_w`:
/// `Φ = M_end Φ_y M_start⁻¹`, `Φ_y = I + A + A²/2 + A³/6` (`A = F T`, `F` at the
/// end, as the psi-angle model), `Q_d = M_end Q_y M_endᵀ` with
/// `Q_y = Q T + (F Q + Q Fᵀ) T²/2 + F Q Fᵀ T³/3`.
pub fn transition(
    start: &Point,
    end: &Point,
    f_w: &Vector3<f64>,
    dt: f64,
    noise: &ImuNoise,
) -> (Mat18, Mat18) {
    let f = end.dynamics(f_w, noise);
    let q = end.process_noise(noise);
    let a = f * dt;
    let a2 = a * a;
    let phi_y = Mat18::identity() + a + a2 * 0.5 + a2 * a / 6.0;
    let fq = f * q;
    let qd_y = q * dt
        + (fq + fq.transpose()) * (0.5 * dt * dt)
        + fq * f.transpose() * (dt * dt * dt / 3.0);
    let m = end.to_additive();
    (m * phi_y * start.to_local(), m * qd_y * m.transpose())
}
