//! The invariant (7) of seed 003 and the pieces it is built from, (8)–(12).

use crate::rotation::{Euler, skew};
use nalgebra::{Matrix3, Rotation3, SMatrix, Vector3};

/// `c_ei`, Earth to inertial axes after `t` seconds of the Earth's rotation at
/// `earth_rate` [rad/s] about the common polar z axis (the frames coincide at `t = 0`):
/// the transpose of the seed's `C2` of (11).
pub fn earth_to_inertial(earth_rate: f64, t: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), earth_rate * t).into_inner()
}

/// The body's rate relative to the navigation frame, `ω_nb^b` [rad/s], from the
/// system's own matrices by (11)–(12): `Ċ3 = Ċ0 C2ᵀ C1ᵀ + C0 Ċ2ᵀ C1ᵀ + C0 C2ᵀ Ċ1ᵀ` with
/// `C3 = c_nb = c_biᵀ c_ei c_ne`, `ċ_bi = c_bi [Θ̇×]`, `ċ_ei = c_ei [ω_ie^e×]`,
/// `ċ_ne = c_ne [ω_en^n×]`, and `ċ_nb = −[ω_nb^b×] c_nb`.
///
/// `c_bi` body to inertial, `c_ei` Earth to inertial, `c_ne` navigation to Earth;
/// `theta_dot_b` the gyro output [rad/s]; `w_en_n` the frame's rate relative to the
/// Earth in its own axes [rad/s].
pub fn own_rate_nb(
    c_bi: &Matrix3<f64>,
    c_ei: &Matrix3<f64>,
    c_ne: &Matrix3<f64>,
    theta_dot_b: &Vector3<f64>,
    earth_rate: f64,
    w_en_n: &Vector3<f64>,
) -> Vector3<f64> {
    let c_ib = c_bi.transpose();
    let c_nb = c_ib * c_ei * c_ne;
    let w_ie_e = Vector3::new(0.0, 0.0, earth_rate);
    let dc_nb =
        -skew(theta_dot_b) * c_nb + c_ib * c_ei * skew(&w_ie_e) * c_ne + c_nb * skew(w_en_n);
    let w = -dc_nb * c_nb.transpose();
    // The antisymmetric part of [ω×] (its symmetric part is rounding).
    0.5 * Vector3::new(
        w[(2, 1)] - w[(1, 2)],
        w[(0, 2)] - w[(2, 0)],
        w[(1, 0)] - w[(0, 1)],
    )
}

/// The body's rate relative to the navigation frame in the frame's axes, `ω_nb^n`
/// [rad/s], from Euler angles and their rates: the seed's (8)–(10) written for this
/// crate's FRD body, NED-like frame and Z-Y-X (yaw, pitch, roll) angles,
/// `ω_nb^n = ψ̇ z + θ̇ C_z(ψ) y + φ̇ C_z(ψ) C_y(θ) x`:
/// `[φ̇ cosψ cosθ − θ̇ sinψ, φ̇ sinψ cosθ + θ̇ cosψ, ψ̇ − φ̇ sinθ]`. (The seed's frame is
/// east-north-up with its heading positive to the left, which flips signs only.)
pub fn nav_rate_from_euler_rates(angles: &Euler, rates: &Euler) -> Vector3<f64> {
    let (sy, cy) = angles.yaw.sin_cos();
    let (sp, cp) = angles.pitch.sin_cos();
    Vector3::new(
        rates.roll * cy * cp - rates.pitch * sy,
        rates.roll * sy * cp + rates.pitch * cy,
        rates.yaw - rates.roll * sp,
    )
}

/// The integrand of (7) in inertial axes [rad/s]:
/// `c_bi Θ̇ − c_ni (ω_en^n + ω_nb^n) − [0, 0, Ω]`.
pub fn invariant(
    c_bi: &Matrix3<f64>,
    theta_dot_b: &Vector3<f64>,
    c_ni: &Matrix3<f64>,
    w_en_n: &Vector3<f64>,
    w_nb_n: &Vector3<f64>,
    earth_rate: f64,
) -> Vector3<f64> {
    c_bi * theta_dot_b - c_ni * (w_en_n + w_nb_n) - Vector3::new(0.0, 0.0, earth_rate)
}

/// The reference side of (7) over one sample of `dt` seconds in inertial axes [rad]:
/// `∫ c_ni (ω_en^n + ω_nb^n) dτ + [0, 0, Ω dt]` by the trapezoid rule from the values
/// at the sample's two ends (`w_*_n = ω_en^n + ω_nb^n` there), exact to `O(dt³)`.
pub fn reference_increment(
    c_ni: [&Matrix3<f64>; 2],
    w_n: [&Vector3<f64>; 2],
    earth_rate: f64,
    dt: f64,
) -> Vector3<f64> {
    0.5 * dt * (c_ni[0] * w_n[0] + c_ni[1] * w_n[1]) + Vector3::new(0.0, 0.0, earth_rate * dt)
}

/// One step `[t_{i−1}, t_i]` of the invariant (7) with what its first-order model needs
/// (module docs): `z = Σ (ĉ_bi Δθ − r)`, `A = Σ ĉ_bi Δθ`, `B = Σ ĉ_bi dt`,
/// `M = Σ [ĉ_bi Δθ ×] B(τ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InvariantWindow {
    z: Vector3<f64>,
    a: Vector3<f64>,
    b: Matrix3<f64>,
    m: Matrix3<f64>,
    span: f64,
}

impl Default for InvariantWindow {
    fn default() -> Self {
        Self {
            z: Vector3::zeros(),
            a: Vector3::zeros(),
            b: Matrix3::zeros(),
            m: Matrix3::zeros(),
            span: 0.0,
        }
    }
}

impl InvariantWindow {
    /// Adds one sample: `c_bi` the system's attitude at the sample's start (body to
    /// inertial), `dtheta_b` the gyro increment [rad], `reference_i` the reference
    /// side over the sample ([`reference_increment`], rad), `dt` its length [s].
    /// `c_bi Δθ` is the exact inertial rotation of a sample at constant rate.
    pub fn push(
        &mut self,
        c_bi: &Matrix3<f64>,
        dtheta_b: &Vector3<f64>,
        reference_i: &Vector3<f64>,
        dt: f64,
    ) {
        let rotation_i = c_bi * dtheta_b;
        self.z += rotation_i - reference_i;
        self.m += skew(&rotation_i) * (self.b + c_bi * (0.5 * dt));
        self.a += rotation_i;
        self.b += c_bi * dt;
        self.span += dt;
    }

    /// The observation `z` of (7) [rad].
    pub fn z(&self) -> Vector3<f64> {
        self.z
    }

    /// The step's length [s].
    pub fn span(&self) -> f64 {
        self.span
    }

    /// `∫ c_bi dτ`, the drift's effect on the inertial attitude over the step
    /// (`ψ(t_i) − ψ(t_{i−1}) = −B ε`) [s].
    pub fn drift_to_attitude(&self) -> Matrix3<f64> {
        self.b
    }

    /// The observation matrix on `[ψ(t_i), ε]`: `[[A×], B + [A×]B − M]`.
    pub fn h(&self) -> SMatrix<f64, 3, 6> {
        let a = skew(&self.a);
        let mut h = SMatrix::<f64, 3, 6>::zeros();
        h.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
        h.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(self.b + a * self.b - self.m));
        h
    }
}
