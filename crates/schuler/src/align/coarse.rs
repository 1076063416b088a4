//! Coarse alignment on a base at rest: leveling from the mean specific force and
//! analytic gyrocompassing from the mean angular rate (the TRIAD construction), or
//! leveling with an external heading; and the accuracy it can reach.
//!
//! At rest the body senses `f^b = C_bn f^n`, `f^n = −g^n`, and `ω^b = C_bn ω_ie^n`,
//! `ω_ie^n = Ω [cos φ, 0, −sin φ]`. With the orthonormal triads
//! `a₁ = f/|f|`, `a₂ = f×ω/|f×ω|`, `a₃ = a₁×a₂` built from the same two vectors in
//! either frame, `C_nb = [a₁ a₂ a₃]^n ([a₁ a₂ a₃]^b)ᵀ` (Britting 1971 §10; Titterton &
//! Weston 2004 §10.3.1). Gravity fixes level exactly; the Earth rate's horizontal
//! part `Ω cos φ` fixes north, so its errors scale as `1/cos φ`:
//!
//! - level: `ψ_N ≈ b_E/g`, `ψ_E ≈ −b_N/g` (accelerometer bias `b`);
//! - heading: `ψ_D ≈ (ε_E + Ω sin φ ψ_N)/(Ω cos φ)` plus the noise term
//!   `N/(Ω cos φ √T)` (gyro bias `ε`, angle random walk `N`, averaging time `T`).
//!
//! [`CoarseAlignment::error_jacobian`] gives these sensitivities exactly (by central
//! differences of the construction), which the fine alignment uses as its prior's
//! correlation between attitude and sensor errors.

use crate::earth::{EarthModel, Geodetic};
use crate::filter::ImuNoise;
use crate::rotation::{Euler, rotation_vector_from_quaternion};
use nalgebra::{Matrix3, Rotation3, SMatrix, UnitQuaternion, Vector3};

/// How the heading is found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HeadingSource {
    /// Analytic gyrocompassing from the Earth rate.
    Gyrocompass,
    /// An external heading [rad] with its standard deviation [rad].
    External {
        /// Heading (yaw) [rad].
        yaw: f64,
        /// Its standard deviation [rad].
        std: f64,
    },
}

/// The coarse attitude and the data it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoarseAlignment {
    /// Attitude, body to NED.
    pub q_bn: UnitQuaternion<f64>,
    /// Mean specific force over the stage, body axes [m/s^2].
    pub f_b: Vector3<f64>,
    /// Mean angular rate over the stage, body axes [rad/s].
    pub w_b: Vector3<f64>,
    /// Averaging time [s].
    pub duration: f64,
    /// The heading source used.
    pub heading: HeadingSource,
}

/// The nominal specific force and Earth rate in NED at a position.
pub fn reference_vectors<E: EarthModel>(earth: &E, pos: &Geodetic) -> (Vector3<f64>, Vector3<f64>) {
    (-earth.gravity_n(pos.lat, pos.h), earth.w_ie_n(pos.lat))
}

fn triad(f: &Vector3<f64>, w: &Vector3<f64>) -> Option<Matrix3<f64>> {
    let a1 = f.try_normalize(0.0)?;
    // Parallel vectors (a pole) within round-off: no north.
    let a2 = f.cross(w).try_normalize(1e-12 * f.norm() * w.norm())?;
    let a3 = a1.cross(&a2);
    Some(Matrix3::from_columns(&[a1, a2, a3]))
}

/// Body-to-NED attitude from mean body vectors (`None` where the construction is
/// undefined: no specific force, or the Earth rate parallel to it, i.e. at a pole).
pub fn attitude_from(
    f_b: &Vector3<f64>,
    w_b: &Vector3<f64>,
    f_n: &Vector3<f64>,
    w_n: &Vector3<f64>,
    heading: HeadingSource,
) -> Option<UnitQuaternion<f64>> {
    match heading {
        HeadingSource::Gyrocompass => {
            let c = triad(f_n, w_n)? * triad(f_b, w_b)?.transpose();
            Some(UnitQuaternion::from_rotation_matrix(
                &Rotation3::from_matrix_unchecked(c),
            ))
        }
        HeadingSource::External { yaw, .. } => {
            // f_b = C_bn [0, 0, −g]: f_x = g sin θ, f_y = −g sin φ cos θ, f_z = −g cos φ cos θ.
            let roll = (-f_b.y).atan2(-f_b.z);
            let pitch = f_b.x.atan2(f_b.y.hypot(f_b.z));
            Some(Euler { roll, pitch, yaw }.to_quaternion())
        }
    }
}

impl CoarseAlignment {
    /// Align from mean body vectors over `duration` seconds at `pos`.
    pub fn from_means<E: EarthModel>(
        earth: &E,
        pos: &Geodetic,
        f_b: Vector3<f64>,
        w_b: Vector3<f64>,
        duration: f64,
        heading: HeadingSource,
    ) -> Option<Self> {
        let (f_n, w_n) = reference_vectors(earth, pos);
        let q_bn = attitude_from(&f_b, &w_b, &f_n, &w_n, heading)?;
        Some(Self {
            q_bn,
            f_b,
            w_b,
            duration,
            heading,
        })
    }

    /// Sensitivity of the attitude error `ψ` (NED, `Ĉ = (I − ψ×) C`) to errors in the
    /// mean angular rate (columns 0–2) and specific force (columns 3–5), body axes.
    pub fn error_jacobian<E: EarthModel>(&self, earth: &E, pos: &Geodetic) -> SMatrix<f64, 3, 6> {
        let (f_n, w_n) = reference_vectors(earth, pos);
        let mut j = SMatrix::<f64, 3, 6>::zeros();
        for col in 0..6 {
            // Steps well inside the linear range and far above round-off.
            let h = if col < 3 {
                1e-3 * w_n.norm().max(1e-9)
            } else {
                1e-6 * f_n.norm().max(1e-9)
            };
            let mut psi = [Vector3::zeros(); 2];
            for (k, sign) in [1.0, -1.0].into_iter().enumerate() {
                let (mut f, mut w) = (self.f_b, self.w_b);
                if col < 3 {
                    w[col] += sign * h;
                } else {
                    f[col - 3] += sign * h;
                }
                psi[k] = match attitude_from(&f, &w, &f_n, &w_n, self.heading) {
                    // Ĉ Cᵀ = I − ψ×: ψ = −rotvec(Ĉ Cᵀ).
                    Some(q) => -rotation_vector_from_quaternion(&(q * self.q_bn.inverse())),
                    None => Vector3::repeat(f64::INFINITY),
                };
            }
            j.set_column(col, &((psi[0] - psi[1]) / (2.0 * h)));
        }
        j
    }

    /// Covariance of `ψ` and its cross-covariance with the gyro and accelerometer
    /// biases, from the sensor statistics: `ψ = J_w (ε + n_w) + J_f (b + n_f)`, with
    /// mean noises of variance `N²/T`. Returns `(P_ψψ, P_ψε, P_ψb)`.
    pub fn error_covariance<E: EarthModel>(
        &self,
        earth: &E,
        pos: &Geodetic,
        noise: &ImuNoise,
    ) -> (Matrix3<f64>, Matrix3<f64>, Matrix3<f64>) {
        let j = self.error_jacobian(earth, pos);
        let jw: Matrix3<f64> = j.fixed_view::<3, 3>(0, 0).into_owned();
        let jf: Matrix3<f64> = j.fixed_view::<3, 3>(0, 3).into_owned();
        let d = |v: &Vector3<f64>| Matrix3::from_diagonal(&v.component_mul(v));
        let t = self.duration.max(f64::MIN_POSITIVE);
        let pbg = d(&noise.gyro_bias);
        let pba = d(&noise.accel_bias);
        let mut ppsi = jw * (pbg + d(&noise.arw) / t) * jw.transpose()
            + jf * (pba + d(&noise.vrw) / t) * jf.transpose();
        if let HeadingSource::External { std, .. } = self.heading {
            ppsi[(2, 2)] += std * std;
        }
        (ppsi, jw * pbg, jf * pba)
    }

    /// Predicted one-sigma errors `[level north, level east, heading]` [rad].
    pub fn predicted_std<E: EarthModel>(
        &self,
        earth: &E,
        pos: &Geodetic,
        noise: &ImuNoise,
    ) -> Vector3<f64> {
        self.error_covariance(earth, pos, noise)
            .0
            .diagonal()
            .map(f64::sqrt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::Wgs84;

    fn exact_means(pos: &Geodetic, att: Euler) -> (Vector3<f64>, Vector3<f64>) {
        let (f_n, w_n) = reference_vectors(&Wgs84, pos);
        let c_bn = att.to_dcm().transpose();
        (c_bn * f_n, c_bn * w_n)
    }

    #[test]
    fn exact_means_give_the_exact_attitude() {
        let pos = Geodetic::from_degrees(60.0, 30.0, 100.0);
        let att = Euler::from_degrees(2.0, -3.0, 123.0);
        let (f, w) = exact_means(&pos, att);
        let c = CoarseAlignment::from_means(&Wgs84, &pos, f, w, 100.0, HeadingSource::Gyrocompass)
            .unwrap();
        let err = rotation_vector_from_quaternion(&(c.q_bn * att.to_quaternion().inverse()));
        // Round-off of the cross products only.
        assert!(err.norm() < 1e-12, "{err}");
    }

    #[test]
    fn bias_sensitivities_are_the_textbook_ones() {
        // Level body heading north: body y is east, body x north.
        let lat = 60f64.to_radians();
        let pos = Geodetic::new(lat, 0.0, 0.0);
        let att = Euler::from_degrees(0.0, 0.0, 0.0);
        let (f, w) = exact_means(&pos, att);
        let c = CoarseAlignment::from_means(&Wgs84, &pos, f, w, 100.0, HeadingSource::Gyrocompass)
            .unwrap();
        let j = c.error_jacobian(&Wgs84, &pos);
        let g = f.norm();
        let omega = Wgs84.rotation_rate();
        // Accelerometer east (y) bias tilts the computed level about north by b/g.
        assert!(
            (j[(0, 4)].abs() - 1.0 / g).abs() < 1e-6 / g,
            "{}",
            j[(0, 4)]
        );
        assert!((j[(1, 3)].abs() - 1.0 / g).abs() < 1e-6 / g);
        // East gyro bias: heading error 1/(Ω cos φ).
        let expect = 1.0 / (omega * lat.cos());
        assert!(
            (j[(2, 1)].abs() / expect - 1.0).abs() < 1e-3,
            "{} vs {expect}",
            j[(2, 1)]
        );
        // The accelerometer's leak into heading through the vertical Earth rate: tan φ / g.
        assert!(
            (j[(2, 4)].abs() / (lat.tan() / g) - 1.0).abs() < 1e-3,
            "{}",
            j[(2, 4)]
        );
    }

    #[test]
    fn at_the_pole_gyrocompassing_is_undefined_and_an_external_heading_works() {
        let pos = Geodetic::from_degrees(90.0, 0.0, 0.0);
        let (f, w) = exact_means(&pos, Euler::from_degrees(1.0, 2.0, 0.0));
        assert!(
            CoarseAlignment::from_means(&Wgs84, &pos, f, w, 100.0, HeadingSource::Gyrocompass)
                .is_none()
        );
        let ext = HeadingSource::External {
            yaw: 0.5,
            std: 0.01,
        };
        let c = CoarseAlignment::from_means(&Wgs84, &pos, f, w, 100.0, ext).unwrap();
        let e = Euler::from_quaternion(&c.q_bn);
        assert!((e.roll - 1f64.to_radians()).abs() < 1e-9 && (e.yaw - 0.5).abs() < 1e-12);
    }
}
