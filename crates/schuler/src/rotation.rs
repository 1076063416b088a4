//! Attitude representations: quaternion, direction cosine matrix (DCM), ZYX Euler
//! angles and rotation vector.
//!
//! Conventions (KF-GINS `cbn`, pyins `mat_nb`, Titterton & Weston ch. 3):
//! - `c_bn` is the DCM from body to navigation frame, so `v_n = c_bn * v_b`;
//!   `q_bn` is the same rotation as a unit quaternion (`v_n = q_bn * v_b`).
//! - Euler angles are the Z-Y-X sequence: rotate the navigation frame by yaw about
//!   down, then by pitch about the new right axis, then by roll about the new front
//!   axis: `c_bn = Rz(yaw) Ry(pitch) Rx(roll)`. They are held in [`Euler`], written in
//!   files in the order roll, pitch, yaw.
//! - A rotation vector `phi` is the axis times the angle; `exp(phi)` is the rotation
//!   by `|phi|` about `phi/|phi|` (right-handed), e.g. the body-frame rotation over
//!   one IMU interval, `c_b(k)b(k-1) = exp(phi)` in Savage's notation.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

/// Z-Y-X Euler angles [rad]: `c_bn = Rz(yaw) Ry(pitch) Rx(roll)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Euler {
    /// Rotation about the body front axis, (-pi, pi].
    pub roll: f64,
    /// Rotation about the body right axis, [-pi/2, pi/2].
    pub pitch: f64,
    /// Rotation about the down axis (heading), (-pi, pi].
    pub yaw: f64,
}

/// Below this `cos(pitch)` roll and yaw are not separable (gimbal lock, |pitch| within
/// about 2e-8 deg of 90 deg); [`Euler::from_dcm`] then sets roll to zero and gives the
/// whole rotation about the vertical to yaw.
const GIMBAL_LOCK_COS_PITCH: f64 = 1e-9;

impl Euler {
    /// Euler angles from roll, pitch, yaw [rad].
    pub const fn new(roll: f64, pitch: f64, yaw: f64) -> Self {
        Self { roll, pitch, yaw }
    }

    /// Euler angles from roll, pitch, yaw [deg].
    pub fn from_degrees(roll_deg: f64, pitch_deg: f64, yaw_deg: f64) -> Self {
        Self::new(
            roll_deg.to_radians(),
            pitch_deg.to_radians(),
            yaw_deg.to_radians(),
        )
    }

    /// `c_bn = Rz(yaw) Ry(pitch) Rx(roll)` (Titterton & Weston eq. 3.47).
    pub fn to_dcm(&self) -> Matrix3<f64> {
        let (sr, cr) = self.roll.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let (sy, cy) = self.yaw.sin_cos();
        Matrix3::new(
            cp * cy,
            -cr * sy + sr * sp * cy,
            sr * sy + cr * sp * cy,
            cp * sy,
            cr * cy + sr * sp * sy,
            -sr * cy + cr * sp * sy,
            -sp,
            sr * cp,
            cr * cp,
        )
    }

    /// Euler angles of `c_bn`; at gimbal lock roll is set to zero and yaw carries the
    /// rotation about the vertical, so that `Euler::from_dcm(c).to_dcm() == c` holds
    /// everywhere.
    pub fn from_dcm(c_bn: &Matrix3<f64>) -> Self {
        let cos_pitch = c_bn[(2, 1)].hypot(c_bn[(2, 2)]);
        let pitch = (-c_bn[(2, 0)]).atan2(cos_pitch);
        if cos_pitch < GIMBAL_LOCK_COS_PITCH {
            // c12 = -sin(yaw - roll*sign), c22 = cos(...): with roll = 0 both pitch
            // signs give yaw = atan2(-c12, c22).
            let yaw = (-c_bn[(0, 1)]).atan2(c_bn[(1, 1)]);
            return Self::new(0.0, pitch, yaw);
        }
        let roll = c_bn[(2, 1)].atan2(c_bn[(2, 2)]);
        let yaw = c_bn[(1, 0)].atan2(c_bn[(0, 0)]);
        Self::new(roll, pitch, yaw)
    }

    /// `q_bn` of these angles: `q_yaw ⊗ q_pitch ⊗ q_roll`.
    pub fn to_quaternion(&self) -> UnitQuaternion<f64> {
        let (sr, cr) = (0.5 * self.roll).sin_cos();
        let (sp, cp) = (0.5 * self.pitch).sin_cos();
        let (sy, cy) = (0.5 * self.yaw).sin_cos();
        UnitQuaternion::new_unchecked(Quaternion::new(
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ))
    }

    /// Euler angles of `q_bn` (through the DCM, so gimbal lock is handled the same way).
    pub fn from_quaternion(q_bn: &UnitQuaternion<f64>) -> Self {
        Self::from_dcm(&q_bn.to_rotation_matrix().into_inner())
    }

    /// The same attitude as [`Euler::from_dcm`] gives it, from angles of any range
    /// (e.g. a trajectory's unwrapped ones) without trigonometry: roll and yaw in
    /// (−π, π], pitch in [−π/2, π/2] (past ±π/2 the equivalent `(roll + π, ±π −
    /// pitch, yaw + π)`); within gimbal lock through the DCM, for `from_dcm`'s
    /// convention there. Angles already in range are returned bit for bit.
    pub fn principal(&self) -> Self {
        use std::f64::consts::{FRAC_PI_2, PI};
        let pitch = wrap_pi(self.pitch);
        // cos(pitch) < GIMBAL_LOCK_COS_PITCH, with room for the rounding of both.
        if FRAC_PI_2 - pitch.abs() < 2.0 * GIMBAL_LOCK_COS_PITCH {
            return Self::from_dcm(&self.to_dcm());
        }
        if pitch.abs() <= FRAC_PI_2 {
            return Self::new(wrap_pi(self.roll), pitch, wrap_pi(self.yaw));
        }
        Self::new(
            wrap_pi(self.roll + PI),
            PI.copysign(pitch) - pitch,
            wrap_pi(self.yaw + PI),
        )
    }

    /// Yaw wrapped to [0, 2*pi), the heading convention of navigation output files.
    pub fn heading_0_2pi(&self) -> f64 {
        let y = self.yaw.rem_euclid(std::f64::consts::TAU);
        // rem_euclid can return exactly TAU for tiny negative inputs.
        if y >= std::f64::consts::TAU { 0.0 } else { y }
    }
}

/// Angle [rad] wrapped to (−π, π]; unchanged, bit for bit, when already inside (so
/// wrapping twice changes nothing, and in-range angles keep every digit).
#[inline]
pub fn wrap_pi(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if x > -PI && x <= PI {
        return x;
    }
    // (x + π) mod 2π is in [0, 2π] (rem_euclid may round up to 2π), so w is in
    // [−π, π]; −π itself maps to π.
    let w = (x + PI).rem_euclid(TAU) - PI;
    if w <= -PI { w + TAU } else { w }
}

/// Skew-symmetric (cross-product) matrix: `skew(a) * b == a.cross(&b)`.
#[inline]
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Quaternion `exp(phi)` of a rotation vector: `[cos(|phi|/2), sin(|phi|/2) phi/|phi|]`,
/// with Taylor series below 1e-4 rad where they are exact to the last bit.
#[inline]
pub fn quaternion_from_rotation_vector(phi: &Vector3<f64>) -> UnitQuaternion<f64> {
    let x2 = phi.norm_squared();
    let (c, s_over_x) = if x2 < 1e-8 {
        // cos(x/2) = 1 - x^2/8 + x^4/384;  sin(x/2)/x = 1/2 - x^2/48 + x^4/3840.
        // The first omitted terms are below 2e-27 relative for |x| < 1e-4.
        (
            1.0 - x2 / 8.0 + x2 * x2 / 384.0,
            0.5 - x2 / 48.0 + x2 * x2 / 3840.0,
        )
    } else {
        let x = x2.sqrt();
        let (s, c) = (0.5 * x).sin_cos();
        (c, s / x)
    };
    UnitQuaternion::new_unchecked(Quaternion::new(
        c,
        s_over_x * phi.x,
        s_over_x * phi.y,
        s_over_x * phi.z,
    ))
}

/// Rotation vector `log(q)` with angle in [0, pi]: the inverse of
/// [`quaternion_from_rotation_vector`].
pub fn rotation_vector_from_quaternion(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    // Choose the representative with non-negative scalar part: angle in [0, pi].
    let (w, v) = if q.w < 0.0 {
        (-q.w, -q.imag())
    } else {
        (q.w, q.imag())
    };
    let s = v.norm();
    if s < 1e-8 {
        // angle = 2 atan2(s, w) ~ 2 s / w (1 - s^2/(3 w^2)); phi = v * angle / s.
        return v * (2.0 / w) * (1.0 - s * s / (3.0 * w * w));
    }
    let angle = 2.0 * s.atan2(w);
    v * (angle / s)
}

/// DCM `exp(skew(phi))` of a rotation vector (Rodrigues' formula).
pub fn dcm_from_rotation_vector(phi: &Vector3<f64>) -> Matrix3<f64> {
    quaternion_from_rotation_vector(phi)
        .to_rotation_matrix()
        .into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    fn angle_between(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
        a.angle_to(b)
    }

    /// `wrap_pi`: in-range angles unchanged to the bit, −π and odd multiples of π to
    /// +π, whole turns removed.
    #[test]
    fn wrap_pi_examples() {
        for x in [0.0, -0.0, 1.0, -3.0, PI, -PI + 1e-15, 3.1] {
            assert_eq!(wrap_pi(x).to_bits(), x.to_bits(), "{x}");
        }
        assert_eq!(wrap_pi(-PI), PI);
        assert_eq!(wrap_pi(3.0 * PI), PI);
        assert_eq!(wrap_pi(-3.0 * PI), PI);
        assert_relative_eq!(
            wrap_pi(190f64.to_radians()),
            -170f64.to_radians(),
            epsilon = 1e-14
        );
        assert_relative_eq!(
            wrap_pi(-190f64.to_radians()),
            170f64.to_radians(),
            epsilon = 1e-14
        );
        assert_relative_eq!(wrap_pi(1.0 + 10.0 * TAU), 1.0, epsilon = 1e-13);
    }

    /// Frame direction check with an independent construction: yaw 90 deg turns the
    /// body front axis to east, pitch 90 deg turns it up (-down), roll 90 deg turns the
    /// body right axis to down.
    #[test]
    fn axis_directions_match_frd_ned() {
        let e = Euler::from_degrees(0.0, 0.0, 90.0).to_dcm();
        assert_relative_eq!(
            e * Vector3::x(),
            Vector3::new(0.0, 1.0, 0.0),
            epsilon = 1e-15
        );
        let p = Euler::from_degrees(0.0, 90.0, 0.0).to_dcm();
        assert_relative_eq!(
            p * Vector3::x(),
            Vector3::new(0.0, 0.0, -1.0),
            epsilon = 1e-15
        );
        let r = Euler::from_degrees(90.0, 0.0, 0.0).to_dcm();
        assert_relative_eq!(
            r * Vector3::y(),
            Vector3::new(0.0, 0.0, 1.0),
            epsilon = 1e-15
        );
    }

    /// nalgebra's own Euler constructor (`from_euler_angles(roll, pitch, yaw)` =
    /// Rz Ry Rx) is an independent implementation of the same convention.
    #[test]
    fn dcm_matches_nalgebra() {
        for &(r, p, y) in &[(0.1, -0.4, 2.5), (-3.0, 1.2, -0.7), (0.0, 0.0, 0.0)] {
            let ours = Euler::new(r, p, y).to_dcm();
            let theirs = nalgebra::Rotation3::from_euler_angles(r, p, y).into_inner();
            assert_relative_eq!(ours, theirs, epsilon = 1e-15);
        }
    }

    /// Gimbal lock: pitch exactly +-90 deg; only yaw -+ roll is defined. The DCM
    /// round trip must hold and roll is reported as zero.
    #[test]
    fn gimbal_lock_round_trip() {
        for &pitch in &[FRAC_PI_2, -FRAC_PI_2] {
            let c = Euler::new(0.3, pitch, 1.1).to_dcm();
            let e = Euler::from_dcm(&c);
            assert_eq!(e.roll, 0.0);
            assert_relative_eq!(e.pitch, pitch, epsilon = 1e-7);
            assert_relative_eq!(e.to_dcm(), c, epsilon = 1e-14);
        }
    }

    #[test]
    fn heading_wraps_into_0_2pi() {
        assert_eq!(Euler::new(0.0, 0.0, -1e-300).heading_0_2pi(), 0.0);
        assert_relative_eq!(Euler::new(0.0, 0.0, -FRAC_PI_2).heading_0_2pi(), 1.5 * PI);
        assert_eq!(Euler::new(0.0, 0.0, PI).heading_0_2pi(), PI);
    }

    /// Small-angle limits: for |phi| -> 0, exp(phi) ~ I + skew(phi) to second order.
    #[test]
    fn small_angle_limit() {
        let phi = Vector3::new(1e-6, -2e-6, 3e-6);
        let c = dcm_from_rotation_vector(&phi);
        let first_order = Matrix3::identity() + skew(&phi);
        // Residual is 0.5 skew(phi)^2: |phi|^2 / 2 ~ 7e-12.
        assert_relative_eq!(c, first_order, epsilon = 1e-11);
        assert_relative_eq!(
            rotation_vector_from_quaternion(&quaternion_from_rotation_vector(&phi)),
            phi,
            epsilon = 1e-22
        );
    }

    /// The series branch and the trigonometric branch agree at the switch-over.
    #[test]
    fn series_branch_is_continuous() {
        let axis = Vector3::new(0.48, -0.6, 0.64);
        let below = quaternion_from_rotation_vector(&(axis * (1e-4 * (1.0 - 1e-12))));
        let above = quaternion_from_rotation_vector(&(axis * (1e-4 * (1.0 + 1e-12))));
        assert!(angle_between(&below, &above) < 1e-15);
    }

    fn angle() -> impl Strategy<Value = f64> {
        -PI..PI
    }

    proptest! {
        /// Angles of any range: the same rotation as `from_dcm` gives it, within the
        /// round-off of both (angles of ±10 turns, whose ulp is 1e-14), gimbal lock
        /// included.
        #[test]
        fn principal_is_what_from_dcm_gives(
            r in -60.0..60.0f64,
            p in -60.0..60.0f64,
            y in -60.0..60.0f64,
            lock in 0usize..4,
        ) {
            // Every fourth case at gimbal lock (pitch ±90° plus whole turns).
            let p = if lock == 0 { FRAC_PI_2 * (2.0 * (p / 20.0).round() + 1.0) } else { p };
            let e = Euler::new(r, p, y);
            let got = e.principal();
            prop_assert!((got.to_dcm() - e.to_dcm()).abs().max() < 1e-13);
            prop_assert!(got.roll > -PI && got.roll <= PI);
            prop_assert!(got.yaw > -PI && got.yaw <= PI);
            prop_assert!(got.pitch.abs() <= FRAC_PI_2);
            let want = Euler::from_dcm(&e.to_dcm());
            let d = |a: f64, b: f64| wrap_pi(a - b).abs();
            prop_assert!(d(got.pitch, want.pitch) < 1e-7, "{got:?} {want:?}");
            if lock != 0 && FRAC_PI_2 - want.pitch.abs() > 1e-6 {
                prop_assert!(d(got.roll, want.roll) < 1e-13, "{got:?} {want:?}");
                prop_assert!(d(got.yaw, want.yaw) < 1e-13, "{got:?} {want:?}");
            }
        }

        #[test]
        fn euler_dcm_round_trip(r in angle(), p in -1.5..1.5f64, y in angle()) {
            let e = Euler::new(r, p, y);
            let back = Euler::from_dcm(&e.to_dcm());
            prop_assert!((back.roll - r).abs() < 1e-12);
            prop_assert!((back.pitch - p).abs() < 1e-12);
            prop_assert!((back.yaw - y).abs() < 1e-12);
        }

        #[test]
        fn dcm_euler_dcm_round_trip_everywhere(r in angle(), p in -FRAC_PI_2..=FRAC_PI_2, y in angle()) {
            let c = Euler::new(r, p, y).to_dcm();
            let back = Euler::from_dcm(&c).to_dcm();
            // Near gimbal lock pitch is recovered from asin-like conditioning:
            // an error of 1e-8 rad in pitch moves elements by 1e-8.
            prop_assert!((back - c).abs().max() < 1e-7);
        }

        #[test]
        fn quaternion_matches_dcm(r in angle(), p in -FRAC_PI_2..FRAC_PI_2, y in angle()) {
            let e = Euler::new(r, p, y);
            let from_q = e.to_quaternion().to_rotation_matrix().into_inner();
            prop_assert!((from_q - e.to_dcm()).abs().max() < 1e-15 * 4.0);
        }

        #[test]
        fn rotation_vector_round_trip(x in -3.1..3.1f64, y in -3.1..3.1f64, z in -3.1..3.1f64) {
            let phi = Vector3::new(x, y, z);
            prop_assume!(phi.norm() < PI - 1e-6);
            let back = rotation_vector_from_quaternion(&quaternion_from_rotation_vector(&phi));
            prop_assert!((back - phi).norm() < 1e-13);
        }

        /// exp(phi) rotates by |phi| about phi: it leaves phi fixed, and
        /// composition of rotations about one axis adds the angles.
        #[test]
        fn rotation_vector_composition(x in -1.0..1.0f64, y in -1.0..1.0f64, z in -1.0..1.0f64,
                                       a in -1.0..1.0f64, b in -1.0..1.0f64) {
            let axis = Vector3::new(x, y, z);
            prop_assume!(axis.norm() > 1e-3);
            let u = axis.normalize();
            let qa = quaternion_from_rotation_vector(&(u * a));
            let qb = quaternion_from_rotation_vector(&(u * b));
            let qab = quaternion_from_rotation_vector(&(u * (a + b)));
            prop_assert!(angle_between(&(qa * qb), &qab) < 1e-14);
            prop_assert!(((qa * u) - u).norm() < 1e-15 * 4.0);
        }

        /// Composition of DCMs equals composition of quaternions.
        #[test]
        fn dcm_and_quaternion_compose_alike(r1 in angle(), p1 in -1.5..1.5f64, y1 in angle(),
                                            r2 in angle(), p2 in -1.5..1.5f64, y2 in angle()) {
            let (a, b) = (Euler::new(r1, p1, y1), Euler::new(r2, p2, y2));
            let c = a.to_dcm() * b.to_dcm();
            let q = (a.to_quaternion() * b.to_quaternion()).to_rotation_matrix().into_inner();
            prop_assert!((c - q).abs().max() < 1e-14);
        }
    }
}
