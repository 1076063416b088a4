//! Second-order forward-mode automatic differentiation in one variable (time).
//!
//! A [`Jet`] carries a value and its first and second derivatives with respect to time;
//! arithmetic and the elementary functions apply the chain rule exactly, so a trajectory
//! written as ordinary formulas in `t` yields exact velocity and acceleration with no
//! finite differences.

use nalgebra::Vector3;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A value with its first and second time derivatives: `(x, x', x'')`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jet {
    /// Value.
    pub v: f64,
    /// First derivative.
    pub d: f64,
    /// Second derivative.
    pub dd: f64,
}

impl Jet {
    /// A constant: both derivatives zero.
    pub const fn constant(v: f64) -> Self {
        Self { v, d: 0.0, dd: 0.0 }
    }

    /// The independent variable `t` itself: `(t, 1, 0)`.
    pub const fn variable(t: f64) -> Self {
        Self {
            v: t,
            d: 1.0,
            dd: 0.0,
        }
    }

    /// Chain rule for a scalar function with value `f`, slope `f1`, curvature `f2` at `v`.
    #[inline]
    fn chain(self, f: f64, f1: f64, f2: f64) -> Self {
        Self {
            v: f,
            d: f1 * self.d,
            dd: f2 * self.d * self.d + f1 * self.dd,
        }
    }

    /// Sine.
    pub fn sin(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.chain(s, c, -s)
    }

    /// Cosine.
    pub fn cos(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.chain(c, -s, -c)
    }

    /// Sine and cosine from one `sin_cos` of the value.
    #[inline]
    pub fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }

    /// Square root (of a positive value).
    pub fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        self.chain(r, 0.5 / r, -0.25 / (r * r * r))
    }

    /// Reciprocal `1/x`.
    pub fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r, 2.0 * r * r * r)
    }

    /// `tanh(x)`, for smooth steps.
    pub fn tanh(self) -> Self {
        let th = self.v.tanh();
        let s2 = 1.0 - th * th;
        self.chain(th, s2, -2.0 * th * s2)
    }
}

impl From<f64> for Jet {
    fn from(v: f64) -> Self {
        Self::constant(v)
    }
}

impl Add for Jet {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            d: self.d + o.d,
            dd: self.dd + o.dd,
        }
    }
}

impl Sub for Jet {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            d: self.d - o.d,
            dd: self.dd - o.dd,
        }
    }
}

impl Mul for Jet {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            d: self.d * o.v + self.v * o.d,
            dd: self.dd * o.v + 2.0 * self.d * o.d + self.v * o.dd,
        }
    }
}

impl Div for Jet {
    type Output = Self;
    #[inline]
    #[allow(clippy::suspicious_arithmetic_impl)] // a / b = a * (1/b) with the jet rules
    fn div(self, o: Self) -> Self {
        self * o.recip()
    }
}

impl Neg for Jet {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self {
            v: -self.v,
            d: -self.d,
            dd: -self.dd,
        }
    }
}

impl Add<f64> for Jet {
    type Output = Self;
    #[inline]
    fn add(self, o: f64) -> Self {
        Self {
            v: self.v + o,
            ..self
        }
    }
}

impl Sub<f64> for Jet {
    type Output = Self;
    #[inline]
    fn sub(self, o: f64) -> Self {
        Self {
            v: self.v - o,
            ..self
        }
    }
}

impl Mul<f64> for Jet {
    type Output = Self;
    #[inline]
    fn mul(self, o: f64) -> Self {
        Self {
            v: self.v * o,
            d: self.d * o,
            dd: self.dd * o,
        }
    }
}

impl Mul<Jet> for f64 {
    type Output = Jet;
    #[inline]
    fn mul(self, o: Jet) -> Jet {
        o * self
    }
}

impl Add<Jet> for f64 {
    type Output = Jet;
    #[inline]
    fn add(self, o: Jet) -> Jet {
        o + self
    }
}

/// What one formula needs of its numbers so that it runs on plain values (`f64`) and
/// on jets (`Jet`) alike: the value part of every `Jet` operation is the `f64`
/// operation on the values, so both give the same value bits (division is written
/// `a * b.recip()`, as `Jet` divides).
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
{
    /// A constant.
    fn constant(v: f64) -> Self;
    /// The value.
    fn value(self) -> f64;
    /// Sine and cosine.
    fn sin_cos(self) -> (Self, Self);
    /// Square root.
    fn sqrt(self) -> Self;
    /// Reciprocal `1/x`.
    fn recip(self) -> Self;
}

/// `impl Scalar` for a type with inherent `sin_cos`, `sqrt` and `recip` (which take
/// precedence over the trait's in `<$t>::name`), given its constant and value.
macro_rules! impl_scalar {
    ($t:ty, |$v:ident| $constant:expr, |$x:ident| $value:expr) => {
        impl Scalar for $t {
            #[inline]
            fn constant($v: f64) -> Self {
                $constant
            }
            #[inline]
            fn value(self) -> f64 {
                let $x = self;
                $value
            }
            #[inline]
            fn sin_cos(self) -> (Self, Self) {
                <$t>::sin_cos(self)
            }
            #[inline]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline]
            fn recip(self) -> Self {
                <$t>::recip(self)
            }
        }
    };
}

impl_scalar!(f64, |v| v, |x| x);
impl_scalar!(Jet, |v| Jet::constant(v), |x| x.v);

/// `c_bn = Rz(yaw) Ry(pitch) Rx(roll)` on any [`Scalar`] (see
/// [`crate::rotation::Euler`]), row-major.
pub fn euler_dcm<S: Scalar>(roll: S, pitch: S, yaw: S) -> [[S; 3]; 3] {
    euler_dcm_sin_cos(roll.sin_cos(), pitch.sin_cos(), yaw.sin_cos())
}

/// [`euler_dcm`] from the angles' `(sin, cos)` pairs, for a caller that needs them
/// too.
pub fn euler_dcm_sin_cos<S: Scalar>(
    (sr, cr): (S, S),
    (sp, cp): (S, S),
    (sy, cy): (S, S),
) -> [[S; 3]; 3] {
    [
        [cp * cy, -(cr * sy) + sr * sp * cy, sr * sy + cr * sp * cy],
        [cp * sy, cr * cy + sr * sp * sy, -(sr * cy) + cr * sp * sy],
        [-sp, sr * cp, cr * cp],
    ]
}

/// Matrix (row-major) times vector, `m x`, on any [`Scalar`].
pub fn mat_vec<S: Scalar>(m: &[[S; 3]; 3], x: &[S; 3]) -> [S; 3] {
    [0, 1, 2].map(|i| m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2])
}

/// Transposed matrix (row-major) times vector, `mᵀ x`, on any [`Scalar`].
pub fn mat_t_vec<S: Scalar>(m: &[[S; 3]; 3], x: &[S; 3]) -> [S; 3] {
    [0, 1, 2].map(|i| m[0][i] * x[0] + m[1][i] * x[1] + m[2][i] * x[2])
}

/// A 3-vector of jets.
pub type JetVec3 = [Jet; 3];

/// A 3x3 matrix of jets, row-major.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JetMat3(pub [[Jet; 3]; 3]);

impl JetMat3 {
    /// Matrix product.
    pub fn mul(&self, o: &Self) -> Self {
        let mut r = [[Jet::default(); 3]; 3];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                *cell =
                    self.0[i][0] * o.0[0][j] + self.0[i][1] * o.0[1][j] + self.0[i][2] * o.0[2][j];
            }
        }
        Self(r)
    }

    /// Matrix times vector.
    pub fn mul_vec(&self, x: &JetVec3) -> JetVec3 {
        mat_vec(&self.0, x)
    }

    /// Transpose.
    pub fn transpose(&self) -> Self {
        let m = &self.0;
        Self([0, 1, 2].map(|i| [m[0][i], m[1][i], m[2][i]]))
    }

    /// Values as an f64 matrix.
    pub fn value(&self) -> nalgebra::Matrix3<f64> {
        nalgebra::Matrix3::from_fn(|i, j| self.0[i][j].v)
    }

    /// First derivatives as an f64 matrix.
    pub fn derivative(&self) -> nalgebra::Matrix3<f64> {
        nalgebra::Matrix3::from_fn(|i, j| self.0[i][j].d)
    }

    /// `c_bn = Rz(yaw) Ry(pitch) Rx(roll)` with jets (see [`crate::rotation::Euler`]).
    pub fn from_euler(roll: Jet, pitch: Jet, yaw: Jet) -> Self {
        Self(euler_dcm(roll, pitch, yaw))
    }

    /// Rotation by angle `angle` about the unit axis `u` (Rodrigues):
    /// `I + sin(a) [u×] + (1 − cos(a)) [u×]^2`.
    pub fn from_axis_angle(u: &JetVec3, angle: Jet) -> Self {
        let (s, c1) = (angle.sin(), Jet::constant(1.0) - angle.cos());
        let one = Jet::constant(1.0);
        let zero = Jet::constant(0.0);
        let k = [
            [zero, -u[2], u[1]],
            [u[2], zero, -u[0]],
            [-u[1], u[0], zero],
        ];
        let k2 = JetMat3(k).mul(&JetMat3(k)).0;
        let mut r = [[zero; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let id = if i == j { one } else { zero };
                r[i][j] = id + s * k[i][j] + c1 * k2[i][j];
            }
        }
        Self(r)
    }
}

/// Values of a jet vector.
pub fn value(x: &JetVec3) -> Vector3<f64> {
    Vector3::new(x[0].v, x[1].v, x[2].v)
}

/// First derivatives of a jet vector.
pub fn derivative(x: &JetVec3) -> Vector3<f64> {
    Vector3::new(x[0].d, x[1].d, x[2].d)
}

/// Second derivatives of a jet vector.
pub fn second_derivative(x: &JetVec3) -> Vector3<f64> {
    Vector3::new(x[0].dd, x[1].dd, x[2].dd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Derivatives of a composite function against hand-derived formulas.
    #[test]
    fn chain_rule_matches_hand_derivatives() {
        // f(t) = sin(t^2) / sqrt(1 + t): check at t = 0.7 against central differences
        // of the value with step 1e-4 (truncation ~1e-8, round-off ~1e-12 / 1e-8).
        let f = |t: Jet| (t * t).sin() / (t + 1.0).sqrt();
        let t0 = 0.7;
        let j = f(Jet::variable(t0));
        let h = 1e-4;
        let fv = |t: f64| f(Jet::constant(t)).v;
        let d_fd = (fv(t0 + h) - fv(t0 - h)) / (2.0 * h);
        let dd_fd = (fv(t0 + h) - 2.0 * fv(t0) + fv(t0 - h)) / (h * h);
        assert_relative_eq!(j.d, d_fd, epsilon = 1e-7);
        assert_relative_eq!(j.dd, dd_fd, epsilon = 1e-6);
        // Exact: f' for sin(t^2)/sqrt(1+t) written out by hand.
        let (s, c) = (t0 * t0).sin_cos();
        let r = (1.0 + t0).sqrt();
        let d_exact = 2.0 * t0 * c / r - 0.5 * s / (r * r * r);
        assert_relative_eq!(j.d, d_exact, epsilon = 1e-15);
    }

    /// A rotation about a fixed axis at a constant rate has angular rate equal to that
    /// rate: skew(w) = C^T C'.
    #[test]
    fn axis_angle_derivative_gives_rate() {
        let u = [0.6, 0.0, 0.8].map(Jet::constant);
        let t = Jet::variable(0.3);
        let c = JetMat3::from_axis_angle(&u, t * 2.0);
        let w = c.value().transpose() * c.derivative();
        assert_relative_eq!(w[(2, 1)], 2.0 * 0.6, epsilon = 1e-15);
        assert_relative_eq!(w[(1, 0)], 2.0 * 0.8, epsilon = 1e-15);
        assert_relative_eq!(w[(0, 2)], 0.0, epsilon = 1e-15);
    }
}
