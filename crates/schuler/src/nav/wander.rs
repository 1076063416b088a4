//! All-latitude strapdown mechanization in a free-azimuth (wander) frame: the
//! quaternion algorithm of seed 003 (BINS-500NS polar flight test, eq. (1)–(2);
//! Babich 2017), written for high-rate increments with the same coning, sculling and
//! rotation terms as the NED mechanization ([`super::strapdown`]).
//!
//! # Frames and state
//!
//! The wander frame `w` is local-level with `z` down along the ellipsoid normal; its
//! `x` axis points at the wander azimuth `α` east of north, so `C_wn = R_z(α)` and
//! `C_we = C_ne(lat, lon) R_z(α)`. Its rate relative to the Earth, `ρ = ω_ew^w`, has
//! no vertical component (seed 003: `ω_ζ = 0`), so nothing in the frame's motion
//! depends on the direction of north. The state is
//!
//! - `q_we`: wander-to-ECEF quaternion (the seed's `p1`), `q̇_we = ½ q_we ⊗ ρ`;
//! - `h`: ellipsoidal height;
//! - `v^w`: velocity relative to the Earth in the wander frame;
//! - `q_bw`: body-to-wander attitude, `q̇_bw = ½ (q_bw ⊗ ω_ib^b − ω_iw^w ⊗ q_bw)`,
//!   `ω_iw^w = Ω u^w + ρ`.
//!
//! None of them is singular anywhere; latitude, longitude and `α` are read out of
//! `q_we` only for output.
//!
//! ## Attitude: `q_bw` rather than the seed's `q0`
//!
//! The seed integrates `q0 = q_bi` (body to inertial) from the gyros alone,
//! `q̇0 = ½ q0 ⊗ ω_ib^b`, and forms the body-to-navigation DCM as
//! `C3 = C0 C2ᵀ C1ᵀ` with `C2 = R_z(Ωt)` the Earth's rotation and `C1` from `p1`. We
//! carry `q_bw = q_we* ⊗ q_ei(t)* ⊗ q_bi` (the same rotation) directly. Both are exact
//! and have the same errors (the transport-rate error enters `C3` through `C1` in the
//! seed's form and through `ω_iw` in ours), but `q_bw`: (1) has the form of NED's
//! `q_bn`, so the increment algorithm — coning, the frame rotation `exp(−ζ)`, the
//! `(I − ½ζ×)` velocity resolution — is shared code, and the hand-over to and from
//! NED is one product `q_bn = q_z(α) ⊗ q_bw`; (2) needs no growing angle `Ωt` and no
//! product of three DCMs per step; (3) gives the filter its usual ψ-angle error in
//! a local-level frame.
//!
//! # Equations, per interval `(t_{k-1}, t_k]`
//!
//! With `u^w = C_ew e_z` the Earth's polar axis in the wander frame (the third row of
//! `C_we`: `u^w = [cos lat cos α, −cos lat sin α, −sin lat]`), so `sin lat = −u_z`,
//! `cos lat = |u_xy|` and Earth rate `ω_ie^w = Ω u^w`:
//!
//! 1. Middle of the interval, extrapolated: `v_mid = v_{k-1} + ½ dt/dt_{k-1} Δv_{k-1}`,
//!    `h_mid = h − ½ v_z dt`, `u_mid = u + ½ dt u × ρ(v_mid)` (`u̇ = u × ρ`); one Earth
//!    model evaluation there, from `sin lat` ([`EarthModel::local_from_sin_cos`]) extrapolated from the
//!    last two middles (as NED extrapolates its middle latitude).
//! 2. Velocity (seed eq. (2) in increment form): `ζ = (Ω u + ρ) dt`,
//!    `v_k = v_{k-1} + (I − ½ζ×) C_bw dv_f^b + (g^w − (2Ω u + ρ) × v_mid) dt`.
//!    Gravity's horizontal part (the sphere's centrifugal term) is turned from NED by
//!    the unit north `u_xy / cos lat`; at the pole it vanishes by symmetry.
//! 3. Position: `h_k = h − v̄_z dt`, `q_we(k) = q_we(k-1) ⊗ exp(ρ(v̄) dt)` with the
//!    average velocity `v̄` and the curvature moved to the average height (first
//!    order in `dh/R`, exact to round-off for the millimetres involved), composed in double-double
//!    precision (a 1e-8 rad rotation per step would otherwise lose ~1e-16 rad to
//!    correlated round-off each step: tens of micrometres in 30 min).
//! 4. Attitude: `q_bw(k) = exp(−(Ω u + ρ(v̄)) dt) ⊗ q_bw(k-1) ⊗ exp(φ_k)`.
//!
//! ## Transport rate on the ellipsoid, free of `tan lat` and `1/cos lat`
//!
//! In NED, `ρ^n = [v_E/(R_N+h), −v_N/(R_M+h), ·]`. Rotating the curvature matrix
//! `diag(1/(R_M+h), 1/(R_N+h))` by `α` and writing `cos²lat cos 2α`,
//! `cos²lat sin 2α` through `u_x, u_y` gives, with `d = e_z` (down),
//!
//! `ρ^w = (v × d)/(R_N + h) − κ (u_x v_x + u_y v_y) (d × u)`,
//! `κ = (1/(R_M+h) − 1/(R_N+h)) / cos²lat = e² R_N / ((1 − e² sin²lat)(R_N+h)(R_M+h))`,
//!
//! i.e. `ρ_x = v_y/(R_N+h) + κ (u·v) u_y`, `ρ_y = −v_x/(R_N+h) − κ (u·v) u_x`,
//! `ρ_z = 0`. At the pole `R_M = R_N` and `u_xy = 0`: `ρ = (v × d)/(R_N+h)`, regular;
//! on the sphere `κ = 0`.
//!
//! ## Latitude, longitude, azimuth from `q_we` (seed 003's formulas)
//!
//! `q_we = q_z(lon) ⊗ q_y(−lat − π/2) ⊗ q_z(α)`, a Z-Y-Z sequence, so with
//! `q_we = (w, x, y, z)`: `sin lat = x² + y² − w² − z²`,
//! `cos lat = 2 √((w² + z²)(x² + y²))`, `lon + α = 2 atan2(z, w)`,
//! `lon − α = 2 atan2(x, −y)` (the seed's `φ, λ, A` in atan2 form, for a
//! down-pointing third axis). At the north pole only `lon − α` is defined, at the
//! south pole only `lon + α`: within [`POLE_COS_LAT`] of a pole (64 nm of the axis)
//! the longitude is reported as the mechanization's pole longitude (the start's) and
//! `α` follows from the defined combination, so `C_we = C_ne(lat, lon) R_z(α)` holds
//! exactly everywhere. NED velocity `v^n = R_z(α) v^w` and attitude
//! `q_bn = q_z(α) ⊗ q_bw` are then defined everywhere too, relative to that meridian's
//! north at the pole itself; the ECEF position, wander velocity and azimuth-free
//! quantities never involve the convention.

use super::strapdown::{
    StepHistory, body_rotation_vector, body_velocity_increment, resolve_in_nav_frame,
    update_attitude,
};
use super::{Corrections, LocalLevel, Mechanization, NavState};
use crate::earth::{EarthModel, Geodetic, LocalEarth};
use crate::imu::ImuSample;
use crate::rotation::wrap_pi;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::f64::consts::FRAC_PI_2;

/// Within this `cos(lat)` of a pole (6.4e-8 m from the polar axis) longitude is
/// reported as the pole longitude (see the module doc).
pub const POLE_COS_LAT: f64 = 1e-14;

/// Wander-to-ECEF quaternion of a position and wander azimuth:
/// `q_we = q_z(lon) ⊗ q_y(−lat − π/2) ⊗ q_z(α)`, so that
/// `C_we = C_ne(lat, lon) R_z(α)` ([`crate::earth::c_ne`]).
pub fn q_we_from_geodetic(lat: f64, lon: f64, alpha: f64) -> UnitQuaternion<f64> {
    let z = Vector3::z_axis();
    UnitQuaternion::from_axis_angle(&z, lon)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -lat - FRAC_PI_2)
        * UnitQuaternion::from_axis_angle(&z, alpha)
}

/// Latitude, longitude [rad] and wander azimuth `α` [rad] of `q_we` (seed 003's
/// formulas in Z-Y-Z form, module doc); within [`POLE_COS_LAT`] of a pole the
/// longitude is `pole_longitude`. Longitude and `α` are in (−π, π].
pub fn geodetic_from_q_we(q_we: &UnitQuaternion<f64>, pole_longitude: f64) -> (f64, f64, f64) {
    let (w, x, y, z) = (q_we.w, q_we.i, q_we.j, q_we.k);
    let c2 = w * w + z * z;
    let s2 = x * x + y * y;
    let cos_lat = 2.0 * (c2 * s2).sqrt();
    let lat = (s2 - c2).atan2(cos_lat);
    let half_sum = z.atan2(w); // (lon + α) / 2
    let half_diff = x.atan2(-y); // (lon − α) / 2
    let (lon, alpha) = if cos_lat >= POLE_COS_LAT * (c2 + s2) {
        (half_sum + half_diff, half_sum - half_diff)
    } else if s2 > c2 {
        (pole_longitude, pole_longitude - 2.0 * half_diff)
    } else {
        (pole_longitude, 2.0 * half_sum - pole_longitude)
    };
    (lat, wrap_pi(lon), wrap_pi(alpha))
}

/// The Earth's polar axis in the wander frame, `u^w = C_ew e_z` (third row of
/// `C_we`): `[cos lat cos α, −cos lat sin α, −sin lat]`.
#[inline]
pub fn polar_axis_w(q_we: &UnitQuaternion<f64>) -> Vector3<f64> {
    let (w, x, y, z) = (q_we.w, q_we.i, q_we.j, q_we.k);
    Vector3::new(
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// ECEF position of the wander frame's origin at height `h` on an ellipsoid
/// (`a`, `e²`): `r_e = (R_N + h) n_e − e² R_N sin(lat) e_z`, with the outward normal
/// `n_e = −C_we e_z` (no longitude needed, valid at the poles).
#[inline]
pub fn ecef_from_q_we(q_we: &UnitQuaternion<f64>, h: f64, a: f64, e2: f64) -> Vector3<f64> {
    let (w, x, y, z) = (q_we.w, q_we.i, q_we.j, q_we.k);
    let n_e = -Vector3::new(
        2.0 * (x * z + w * y),
        2.0 * (y * z - w * x),
        1.0 - 2.0 * (x * x + y * y),
    );
    let sin_lat = n_e.z;
    let rn = a / (1.0 - e2 * sin_lat * sin_lat).sqrt();
    let mut r = n_e * (rn + h);
    r.z -= e2 * rn * sin_lat;
    r
}

/// Curvature of the ellipsoid at one position and height, in the form the wander
/// transport rate needs (module doc): `1/(R_N + h)` and
/// `κ = e² R_N / ((1 − e² sin²lat)(R_N + h)(R_M + h))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curvature {
    /// `1 / (R_N + h)` [1/m].
    pub inv_rn: f64,
    /// `κ = (1/(R_M + h) − 1/(R_N + h)) / cos²lat` [1/m], finite at the poles.
    pub kappa: f64,
    /// `1 / (R_M + h)` [1/m].
    pub inv_rm: f64,
}

impl Curvature {
    /// The curvature terms of a local Earth evaluation, for an ellipsoid of first
    /// eccentricity squared `e2`.
    #[inline]
    pub fn at(local: &LocalEarth, e2: f64) -> Self {
        let rn = local.radii.prime_vertical;
        let rn_h = rn + local.h;
        let rm_h = local.radii.meridian + local.h;
        let w2 = 1.0 - e2 * local.sin_lat * local.sin_lat;
        // One division: d = 1 / (w2 (R_N + h)(R_M + h)).
        let d = 1.0 / (w2 * rn_h * rm_h);
        Self {
            inv_rn: w2 * rm_h * d,
            kappa: e2 * rn * d,
            inv_rm: w2 * rn_h * d,
        }
    }

    /// The same terms at height `h + dh` for a small `dh` (metres against the radii):
    /// `1/(R+h+dh) = 1/(R+h) (1 − dh/(R+h))` to O((dh/R)²), ~1e-24 for the
    /// millimetres between a step's predicted and updated middle heights.
    #[inline]
    pub fn at_height_change(&self, dh: f64) -> Self {
        Self {
            inv_rn: self.inv_rn * (1.0 - dh * self.inv_rn),
            kappa: self.kappa * (1.0 - dh * (self.inv_rn + self.inv_rm)),
            inv_rm: self.inv_rm * (1.0 - dh * self.inv_rm),
        }
    }

    /// Transport rate `ρ = ω_ew^w` [rad/s] for wander velocity `v_w` and polar axis
    /// `u_w`: `[v_y/(R_N+h) + κ (u·v) u_y, −v_x/(R_N+h) − κ (u·v) u_x, 0]`, with
    /// `u·v` over the horizontal components.
    #[inline]
    pub fn transport_rate(&self, u_w: &Vector3<f64>, v_w: &Vector3<f64>) -> Vector3<f64> {
        let p = self.kappa * (u_w.x * v_w.x + u_w.y * v_w.y);
        Vector3::new(
            v_w.y * self.inv_rn + p * u_w.y,
            -v_w.x * self.inv_rn - p * u_w.x,
            0.0,
        )
    }
}

/// `(s, e)` with `s = fl(a + b)` and `a + b = s + e` exactly (Knuth's TwoSum).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// Right-multiply `q` (held as `hi + lo` per component, `lo` the round-off
/// compensation) by `exp(ε)`, for a small rotation vector `ε`, in double-double
/// precision: the increment `Δq = (cos(|ε|/2) − 1) q + q ⊗ (0, sin(|ε|/2) ε/|ε|)` is
/// formed directly (it is ~1e-8 of `q`, so its own round-off is ~1e-24) and added with
/// TwoSum. Composing 1e-8 rad rotations into a renormalized `f64` quaternion instead
/// loses about 1e-16 rad per step, and at a steady rate those round-offs are
/// correlated: 1e-5 to 1e-4 m over 30 min at 200 Hz, more than the algorithm's error.
/// Here the norm is preserved to ~1e-24 per step, so no renormalization is needed.
#[inline]
fn compose_accurate(hi: &mut Quaternion<f64>, lo: &mut Quaternion<f64>, eps: &Vector3<f64>) {
    let x2 = eps.norm_squared();
    let (cos_m1, s_over_x) = if x2 < 1e-8 {
        // cos(x/2) − 1 = −x²/8 + x⁴/384, sin(x/2)/x = 1/2 − x²/48 + x⁴/3840 (as
        // `rotation::quaternion_from_rotation_vector`, exact to the last bit for |x| < 1e-4).
        // (Horner form with constant reciprocals: no divisions.)
        (
            x2 * (-0.125 + x2 * (1.0 / 384.0)),
            0.5 + x2 * (-1.0 / 48.0 + x2 * (1.0 / 3840.0)),
        )
    } else {
        let x = x2.sqrt();
        let s4 = (0.25 * x).sin();
        (-2.0 * s4 * s4, (0.5 * x).sin() / x)
    };
    let v = eps * s_over_x;
    let (w, i, j, k) = (hi.w, hi.i, hi.j, hi.k);
    let d = [
        cos_m1 * w - (i * v.x + j * v.y + k * v.z),
        cos_m1 * i + w * v.x + (j * v.z - k * v.y),
        cos_m1 * j + w * v.y + (k * v.x - i * v.z),
        cos_m1 * k + w * v.z + (i * v.y - j * v.x),
    ];
    let h = &mut hi.coords;
    let l = &mut lo.coords;
    // coords are [i, j, k, w].
    for (n, dn) in [(3, d[0]), (0, d[1]), (1, d[2]), (2, d[3])] {
        let (s, e) = two_sum(h[n], dn);
        let e = e + l[n];
        h[n] = s + e;
        l[n] = e - (h[n] - s);
    }
}

/// Gravity in the wander frame from gravity in NED: the horizontal part
/// `g_N n + g_E (d × n)` with unit north `n = u_xy / |u_xy|`; zero horizontal part
/// exactly on the axis, where an axisymmetric field has none.
#[inline]
pub(crate) fn gravity_w(g_n: &Vector3<f64>, u_w: &Vector3<f64>) -> Vector3<f64> {
    let cos_lat = (u_w.x * u_w.x + u_w.y * u_w.y).sqrt();
    if (g_n.x != 0.0 || g_n.y != 0.0) && cos_lat > 0.0 {
        let inv = 1.0 / cos_lat;
        let (nx, ny) = (u_w.x * inv, u_w.y * inv);
        Vector3::new(g_n.x * nx - g_n.y * ny, g_n.x * ny + g_n.y * nx, g_n.z)
    } else {
        Vector3::new(0.0, 0.0, g_n.z)
    }
}

/// The Earth models the wander mechanization runs on: every [`EarthModel`].
///
/// Kept so that existing `E: WanderEarth` bounds compile; the per-step evaluation it
/// used to add, [`EarthModel::local_from_sin_cos`], is now part of [`EarthModel`].
pub trait WanderEarth: EarthModel {}

impl<E: EarthModel> WanderEarth for E {}

/// The wander mechanization's state at one time: non-singular everywhere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WanderState {
    /// Time [s] on the IMU log's clock.
    pub t: f64,
    /// Wander-to-ECEF rotation `q_we` (position and wander azimuth).
    pub q_we: UnitQuaternion<f64>,
    /// Ellipsoidal height [m].
    pub h: f64,
    /// Velocity relative to the Earth in the wander frame [m/s].
    pub v_w: Vector3<f64>,
    /// Attitude: body (FRD) to wander frame, `v_w = q_bw * v_b`.
    pub q_bw: UnitQuaternion<f64>,
}

impl WanderState {
    /// The wander state of a NED state, with wander azimuth `alpha` [rad]:
    /// `q_we = q_ne ⊗ q_z(α)`, `v_w = R_z(α)ᵀ v_n`, `q_bw = q_z(α)* ⊗ q_bn`.
    pub fn from_nav_state(s: &NavState, alpha: f64) -> Self {
        let q_nw = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), alpha);
        Self {
            t: s.t,
            q_we: q_we_from_geodetic(s.pos.lat, s.pos.lon, alpha),
            h: s.pos.h,
            v_w: q_nw.inverse() * s.v_n,
            q_bw: q_nw.inverse() * s.q_bn,
        }
    }

    /// Latitude, longitude [rad] (longitude `pole_longitude` within
    /// [`POLE_COS_LAT`] of a pole), height, and the wander azimuth `α` [rad].
    pub fn geodetic(&self, pole_longitude: f64) -> (Geodetic, f64) {
        let (lat, lon, alpha) = geodetic_from_q_we(&self.q_we, pole_longitude);
        (Geodetic::new(lat, lon, self.h), alpha)
    }

    /// The NED state (`v_n = R_z(α) v_w`, `q_bn = q_z(α) ⊗ q_bw`) and `α`; at a pole
    /// relative to the north of the meridian `pole_longitude`.
    pub fn to_nav_state(&self, pole_longitude: f64) -> (NavState, f64) {
        let (pos, alpha) = self.geodetic(pole_longitude);
        let q_nw = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), alpha);
        let s = NavState {
            t: self.t,
            pos,
            v_n: q_nw * self.v_w,
            q_bn: q_nw * self.q_bw,
        };
        (s, alpha)
    }

    /// ECEF position [m] on the Earth model `earth` (valid everywhere).
    pub fn ecef_position<E: EarthModel>(&self, earth: &E) -> Vector3<f64> {
        ecef_from_q_we(
            &self.q_we,
            self.h,
            earth.semi_major_axis(),
            earth.eccentricity_squared(),
        )
    }

    /// Velocity relative to the Earth in ECEF, `v_e = C_we v_w` [m/s].
    pub fn v_e(&self) -> Vector3<f64> {
        self.q_we * self.v_w
    }

    /// Attitude relative to ECEF, `q_be = q_we ⊗ q_bw`.
    pub fn q_be(&self) -> UnitQuaternion<f64> {
        self.q_we * self.q_bw
    }
}

/// The all-latitude wander-azimuth strapdown mechanization over an Earth model `E`
/// (module doc).
#[derive(Debug, Clone)]
pub struct Wander<E: EarthModel> {
    earth: E,
    corrections: Corrections,
    s: WanderState,
    /// Round-off compensation of `s.q_we` (double-double position, see
    /// `compose_accurate`).
    q_we_lo: Quaternion<f64>,
    history: StepHistory,
    /// Curvature at the last step's middle, to predict the next middle position.
    curvature: Curvature,
    /// `sin lat` at the last step's middle, its change over that step and the
    /// middle-to-middle time [s], to predict the next middle's (`sin lat` is smooth
    /// through the poles, unlike latitude).
    sin_lat_mid: (f64, f64, f64),
    /// Longitude reported within [`POLE_COS_LAT`] of a pole [rad].
    pole_longitude: f64,
}

impl<E: WanderEarth> Wander<E> {
    /// A mechanization starting from the NED state `initial` with the wander frame
    /// on NED (`α = 0`); its longitude becomes the pole longitude.
    pub fn new(earth: E, initial: NavState) -> Self {
        Self::from_wander_state(earth, WanderState::from_nav_state(&initial, 0.0))
            .with_pole_longitude(initial.pos.lon)
    }

    /// A mechanization starting from a wander state (pole longitude 0).
    pub fn from_wander_state(earth: E, s: WanderState) -> Self {
        let u = polar_axis_w(&s.q_we);
        let local = earth.local_from_sin_cos(-u.z, u.xy().norm(), s.h);
        Self {
            earth,
            corrections: Corrections::default(),
            s,
            q_we_lo: Quaternion::new(0.0, 0.0, 0.0, 0.0),
            history: StepHistory::default(),
            curvature: Curvature::at(&local, earth.eccentricity_squared()),
            sin_lat_mid: (-u.z, 0.0, 0.0),
            pole_longitude: 0.0,
        }
    }

    /// The NED mechanization's state and history continued in the wander frame,
    /// with `α = 0` at the hand-over (lossless: one quaternion product).
    pub fn from_local_level(ned: &LocalLevel<E>) -> Self {
        let s = ned.state();
        Self::new(*ned.earth(), s)
            .with_corrections(ned.corrections())
            .with_history(ned.history())
    }

    /// This state and history continued by the NED mechanization (lossless away from
    /// the poles; latitude and longitude are read from `q_we`, velocity, attitude and
    /// the previous velocity change turned by `α`).
    pub fn to_local_level(&self) -> LocalLevel<E> {
        let (nav, alpha) = self.s.to_nav_state(self.pole_longitude);
        let q_nw = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), alpha);
        let history = StepHistory {
            prev_dv: q_nw * self.history.prev_dv,
            ..self.history
        };
        LocalLevel::new(self.earth, nav)
            .with_corrections(self.corrections)
            .with_history(history)
    }

    /// The same mechanization with the given second-order corrections.
    pub fn with_corrections(mut self, corrections: Corrections) -> Self {
        self.corrections = corrections;
        self
    }

    /// The same mechanization continuing from `history` (previous velocity change in
    /// the wander frame).
    pub fn with_history(mut self, history: StepHistory) -> Self {
        self.history = history;
        self
    }

    /// The longitude reported at a pole [rad].
    pub fn pole_longitude(&self) -> f64 {
        self.pole_longitude
    }

    /// The same mechanization reporting `lon` [rad] as the longitude at a pole.
    pub fn with_pole_longitude(mut self, lon: f64) -> Self {
        self.pole_longitude = wrap_pi(lon);
        self
    }

    /// The Earth model in use.
    pub fn earth(&self) -> &E {
        &self.earth
    }

    /// The second-order corrections in use.
    pub fn corrections(&self) -> Corrections {
        self.corrections
    }

    /// The step history (previous increments, previous velocity change in `w`).
    pub fn history(&self) -> StepHistory {
        self.history
    }

    /// The full wander state.
    pub fn wander_state(&self) -> &WanderState {
        &self.s
    }

    /// ECEF position [m], valid everywhere.
    pub fn ecef_position(&self) -> Vector3<f64> {
        self.s.ecef_position(&self.earth)
    }

    /// Wander azimuth `α` [rad]: angle of the wander `x` axis east of north
    /// (relative to the pole longitude's meridian at a pole).
    pub fn wander_azimuth(&self) -> f64 {
        geodetic_from_q_we(&self.s.q_we, self.pole_longitude).2
    }

    /// `sin(lat) = −u_z`: cheap, for latitude thresholds.
    #[inline]
    pub fn sin_lat(&self) -> f64 {
        -polar_axis_w(&self.s.q_we).z
    }

    /// The NED state and the wander azimuth `α` together (one read-out of `q_we`).
    pub fn nav_state_and_azimuth(&self) -> (NavState, f64) {
        self.s.to_nav_state(self.pole_longitude)
    }
}

impl<E: WanderEarth> Mechanization for Wander<E> {
    #[inline]
    fn step(&mut self, sample: &ImuSample) {
        let dt = sample.dt;
        let (dth, dv) = (sample.dtheta, sample.dvel);
        let prev = self.history.prev_or(&dth, &dv);
        let omega = self.earth.rotation_rate();

        // --- 1. the middle of the interval, extrapolated; one Earth evaluation ---
        let v0 = self.s.v_w;
        let v_mid = v0 + self.history.prev_dv * self.history.midpoint_ratio(dt);
        let h_mid = self.s.h - 0.5 * v_mid.z * dt;
        let u0 = polar_axis_w(&self.s.q_we);
        let u_mid = u0 + u0.cross(&self.curvature.transport_rate(&u0, &v_mid)) * (0.5 * dt);
        // One Earth-model evaluation, at the middle's `sin lat` extrapolated from the
        // last two middles (as NED predicts its middle latitude from the last step):
        // the error, ~(sin lat)'' dt^2 < 1e-11, moves gravity and radii by < 1e-12
        // relative. It keeps the square root and divisions of the Earth model off the
        // chain from `q_we` through gravity and velocity back to `q_we`; the exact
        // middle value, `−u_z`, feeds only the next prediction.
        let mid_to_mid = 0.5 * (dt + self.history.prev_dt);
        let (sin_prev, sin_step, step_dt) = self.sin_lat_mid;
        let sin_pred = sin_prev
            + if mid_to_mid == step_dt {
                sin_step
            } else if step_dt > 0.0 {
                sin_step * (mid_to_mid / step_dt)
            } else {
                0.0
            };
        let sin_pred = sin_pred.clamp(-1.0, 1.0);
        let cos_pred = (1.0 - sin_pred * sin_pred).sqrt();
        let mid = self.earth.local_from_sin_cos(sin_pred, cos_pred, h_mid);
        let sin_now = -u_mid.z;
        self.sin_lat_mid = if self.history.prev_dt > 0.0 {
            (sin_now, sin_now - sin_prev, mid_to_mid)
        } else {
            (sin_now, 0.0, 0.0)
        };
        let e2 = self.earth.eccentricity_squared();
        let curvature = Curvature::at(&mid, e2);
        let w_ie = u_mid * omega;
        let rho = curvature.transport_rate(&u_mid, &v_mid);
        let zeta = (w_ie + rho) * dt;

        // --- 2. velocity (seed eq. (2)) ---
        let dv_f_b = body_velocity_increment(&dth, &dv, &prev, self.corrections);
        let dv_f_w = resolve_in_nav_frame(&self.s.q_bw, &dv_f_b, &zeta);
        let g_w = gravity_w(&mid.g_n, &u_mid);
        let dv_g_w = (g_w - (2.0 * w_ie + rho).cross(&v_mid)) * dt;
        let v1 = v0 + dv_f_w + dv_g_w;

        // --- 3. position: height and the frame's rotation relative to the Earth ---
        let v_avg = 0.5 * (v0 + v1);
        let h1 = self.s.h - v_avg.z * dt;
        let h_avg = 0.5 * (self.s.h + h1);
        let curvature = curvature.at_height_change(h_avg - h_mid);
        let rho_avg = curvature.transport_rate(&u_mid, &v_avg);
        let mut q_we = self.s.q_we.into_inner();
        compose_accurate(&mut q_we, &mut self.q_we_lo, &(rho_avg * dt));
        // Unit to ~1e-24 per step (see `compose_accurate`).
        self.s.q_we = UnitQuaternion::new_unchecked(q_we);

        // --- 4. attitude, with the frame's rotation at the updated middle ---
        let phi = body_rotation_vector(&dth, &prev.0, self.corrections);
        self.s.q_bw = update_attitude(&self.s.q_bw, &((w_ie + rho_avg) * dt), &phi);

        self.curvature = curvature;
        self.history.record(dth, dv, v1 - v0, dt);
        self.s.v_w = v1;
        self.s.h = h1;
        self.s.t = sample.t;
    }

    fn prime(&mut self, previous: &ImuSample) {
        self.history.prev_increments = Some((previous.dtheta, previous.dvel));
    }

    /// The NED state: latitude and longitude from `q_we`, `v_n = R_z(α) v_w`,
    /// `q_bn = q_z(α) ⊗ q_bw`; at a pole relative to the pole longitude's meridian.
    fn state(&self) -> NavState {
        self.nav_state_and_azimuth().0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{Sphere, Wgs84, c_ne};
    use crate::rotation::Euler;
    use approx::assert_relative_eq;
    use nalgebra::Matrix3;

    fn rz(a: f64) -> Matrix3<f64> {
        let (s, c) = a.sin_cos();
        Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
    }

    /// `q_we` is `C_ne(lat, lon) R_z(α)` (with the independent `c_ne` of `earth`),
    /// and the read-out returns the angles it was built from.
    #[test]
    fn q_we_round_trip() {
        for &(lat, lon, alpha) in &[
            (0.3, 1.2, -0.4),
            (-1.2, -3.0, 2.9),
            (1.5704, 0.1, 3.1),
            (-0.01, 3.1, -3.1),
            (0.0, 0.0, 0.0),
        ] {
            let q = q_we_from_geodetic(lat, lon, alpha);
            let c = q.to_rotation_matrix().into_inner();
            assert_relative_eq!(c, c_ne(lat, lon) * rz(alpha), epsilon = 1e-15);
            let (la, lo, al) = geodetic_from_q_we(&q, 0.0);
            assert_relative_eq!(la, lat, epsilon = 1e-15);
            assert_relative_eq!(lo, lon, epsilon = 2e-11);
            assert_relative_eq!(al, alpha, epsilon = 2e-11);
            // The sign of the quaternion does not matter.
            let neg = UnitQuaternion::new_unchecked(-q.into_inner());
            let (la2, lo2, al2) = geodetic_from_q_we(&neg, 0.0);
            assert_relative_eq!((la2, lo2, al2).0, la, epsilon = 1e-15);
            assert_relative_eq!(wrap_pi(lo2 - lo), 0.0, epsilon = 1e-14);
            assert_relative_eq!(wrap_pi(al2 - al), 0.0, epsilon = 1e-14);
        }
    }

    /// At a pole the read-out reports the pole longitude and an azimuth that makes
    /// `C_ne(lat, lon) R_z(α)` equal `C_we` again.
    #[test]
    fn pole_read_out_is_consistent() {
        for &(lat, pole_lon) in &[(FRAC_PI_2, 0.7), (-FRAC_PI_2, -2.0), (FRAC_PI_2, 0.0)] {
            let q = q_we_from_geodetic(lat, 1.1, 0.4);
            let (la, lo, al) = geodetic_from_q_we(&q, pole_lon);
            assert_relative_eq!(la, lat, epsilon = 1e-15);
            assert_eq!(lo, pole_lon);
            let c = q.to_rotation_matrix().into_inner();
            assert_relative_eq!(c, c_ne(la, lo) * rz(al), epsilon = 1e-15);
        }
    }

    /// The polar axis and the ECEF position from `q_we` agree with the geodetic
    /// formulas of `earth`.
    #[test]
    fn polar_axis_and_ecef() {
        for &(lat, lon, alpha, h) in &[(0.7, -2.0, 1.0, 1234.0), (-1.5, 0.3, -2.0, -50.0)] {
            let q = q_we_from_geodetic(lat, lon, alpha);
            let u = polar_axis_w(&q);
            let expected = Vector3::new(
                lat.cos() * alpha.cos(),
                -lat.cos() * alpha.sin(),
                -lat.sin(),
            );
            assert_relative_eq!(u, expected, epsilon = 1e-15);
            let r = ecef_from_q_we(&q, h, Wgs84::A, Wgs84::E2);
            let truth = Wgs84.geodetic_to_ecef(&Geodetic::new(lat, lon, h));
            assert_relative_eq!(r, truth, epsilon = 2e-9);
        }
    }

    /// The wander transport rate is the NED transport rate's horizontal part
    /// turned into the wander frame (T&W eq. 3.76 via `LocalEarth::w_en_n`).
    #[test]
    fn transport_rate_matches_ned() {
        for &(lat, alpha, h) in &[(0.3, 0.0, 100.0), (1.2, 2.0, 9000.0), (-0.8, -1.0, 0.0)] {
            let local = Wgs84.local(lat, h);
            let v_n = Vector3::new(120.0, -70.0, 3.0);
            let mut rho_n = local.w_en_n(&v_n);
            rho_n.z = 0.0;
            let c_nw = rz(alpha);
            let u = polar_axis_w(&q_we_from_geodetic(lat, 0.5, alpha));
            let rho_w =
                Curvature::at(&local, Wgs84::E2).transport_rate(&u, &(c_nw.transpose() * v_n));
            assert_relative_eq!(c_nw * rho_w, rho_n, max_relative = 1e-14, epsilon = 1e-20);
        }
    }

    /// A million 3.7e-8 rad turns about one axis compose into one turn of 0.037 rad:
    /// the double-double composition matches the closed form to round-off of the
    /// final quaternion (2e-16 rad), where the plain renormalized product drifts
    /// (measured in the output).
    #[test]
    fn accurate_composition_of_small_turns() {
        use crate::rotation::quaternion_from_rotation_vector as exp;
        let q0 = q_we_from_geodetic(0.6, 2.0, -0.3);
        let eps = Vector3::new(0.3, -0.5, 0.0).normalize() * 3.7e-8;
        let n = 1_000_000;
        let (mut hi, mut lo) = (q0.into_inner(), Quaternion::new(0.0, 0.0, 0.0, 0.0));
        let mut naive = q0;
        for _ in 0..n {
            compose_accurate(&mut hi, &mut lo, &eps);
            naive = UnitQuaternion::new_normalize((naive * exp(&eps)).into_inner());
        }
        let exact = q0 * exp(&(eps * n as f64));
        let accurate = UnitQuaternion::new_unchecked(hi);
        eprintln!(
            "accurate {:.3e} rad, naive {:.3e} rad, norm - 1 = {:.3e}",
            accurate.angle_to(&exact),
            naive.angle_to(&exact),
            hi.norm() - 1.0
        );
        assert!(accurate.angle_to(&exact) < 5e-16);
        assert!((hi.norm() - 1.0).abs() < 1e-15);
    }

    /// Gravity turned from NED on the rotating sphere (north component non-zero).
    #[test]
    fn gravity_turns_with_alpha() {
        let s = Sphere::textbook(true);
        let (lat, alpha) = (0.6, 1.3);
        let g_n = s.gravity_n(lat, 0.0);
        let u = polar_axis_w(&q_we_from_geodetic(lat, 0.0, alpha));
        let g_w = gravity_w(&g_n, &u);
        assert_relative_eq!(rz(alpha) * g_w, g_n, epsilon = 1e-15);
    }

    /// NED -> wander -> NED hand-over returns the state to round-off.
    #[test]
    fn hand_over_round_trip() {
        let s = NavState::new(
            12.0,
            Geodetic::from_degrees(76.0, -120.0, 800.0),
            Vector3::new(100.0, -200.0, 1.5),
            Euler::from_degrees(3.0, -2.0, 250.0),
        );
        let ned = LocalLevel::new(Wgs84, s);
        let w = Wander::from_local_level(&ned);
        let back = w.to_local_level().state();
        assert_relative_eq!(back.pos.lat, s.pos.lat, epsilon = 1e-15);
        assert_relative_eq!(back.pos.lon, s.pos.lon, epsilon = 1e-14);
        assert_eq!(back.pos.h, s.pos.h);
        assert_relative_eq!(back.v_n, s.v_n, epsilon = 1e-12);
        assert!(back.q_bn.angle_to(&s.q_bn) < 1e-15);
        assert_eq!(w.wander_state().t, 12.0);
    }
}
