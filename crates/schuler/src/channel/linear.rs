//! Linear error models of the single-channel INS (13)/(15) and SINS (28)/(29), and the
//! fundamental matrix (16).
//!
//! State `x = [Δλ, ΔV, α]` (rad, m/s, rad), system `x' = A x + u(t)` with
//! `A = [[0, 1/a, 0], [0, 0, -g], [0, 1/a, 0]]` (15) and forcing `u = [0, Δf, ν]`:
//! the platform INS takes the accelerometer bias Δf (instrument axis z2) and platform
//! drift ν directly (12)/(13); the SINS takes `Δf = -Δf_p1 sin D + Δf_p2 cos D` and
//! `ν = -ν_p3` (the strapdown gyro's drift enters with its sign reversed, (28)).
//! (29) writes the projection with the computed angle `D' = D + α`: the difference is a
//! product of two small errors, so both forms are the same linear model.
//!
//! The coupling `g` is the vertical specific force `f_x1` (5); the text sets
//! `f_x1 = g - a λ'^2 ≈ g` (11). Callers that want the Earth-rate or speed term kept
//! pass `g = f_x1` (see [`super::run`]).

use nalgebra::{Matrix3, Vector3};

/// The single-channel error model (13)/(15): sphere radius `a` \[m\] and vertical specific force `g` [m/s^2].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorModel {
    /// Sphere radius a \[m\].
    pub radius: f64,
    /// Vertical specific force g [m/s^2] (the coupling `-g α` of (11)).
    pub g: f64,
}

/// Errors in the text's output units (18)-(23): position `Δr = a Δλ` \[m\], velocity ΔV [m/s], vertical α \[rad\].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorState {
    /// Position error Δr = a Δλ \[m\].
    pub dr: f64,
    /// Velocity error ΔV [m/s].
    pub dv: f64,
    /// Vertical (attitude) error α \[rad\].
    pub alpha: f64,
}

impl ErrorState {
    /// From the state `x = [Δλ, ΔV, α]` of (15) on a sphere of radius `radius`.
    pub fn from_state(x: &Vector3<f64>, radius: f64) -> Self {
        Self {
            dr: radius * x[0],
            dv: x[1],
            alpha: x[2],
        }
    }

    /// The state `x = [Δλ, ΔV, α]` of (15).
    pub fn to_state(&self, radius: f64) -> Vector3<f64> {
        Vector3::new(self.dr / radius, self.dv, self.alpha)
    }

    /// Component-wise difference `self - other`.
    pub fn minus(&self, other: &ErrorState) -> ErrorState {
        ErrorState {
            dr: self.dr - other.dr,
            dv: self.dv - other.dv,
            alpha: self.alpha - other.alpha,
        }
    }
}

impl ErrorModel {
    /// The model on a sphere of radius `radius` \[m\] with vertical specific force `g` [m/s^2].
    pub fn new(radius: f64, g: f64) -> Self {
        Self { radius, g }
    }

    /// Schuler frequency `ω0 = sqrt(g / a)` [rad/s] (16).
    pub fn schuler_frequency(&self) -> f64 {
        (self.g / self.radius).sqrt()
    }

    /// Schuler period `T0 = 2π / ω0 = 2π sqrt(a / g)` \[s\] (16).
    pub fn schuler_period(&self) -> f64 {
        std::f64::consts::TAU * (self.radius / self.g).sqrt()
    }

    /// System matrix `A` of (15).
    pub fn matrix(&self) -> Matrix3<f64> {
        let ia = 1.0 / self.radius;
        Matrix3::new(0.0, ia, 0.0, 0.0, 0.0, -self.g, 0.0, ia, 0.0)
    }

    /// Right-hand side of (13): `x' = A x + [0, accel, drift]`, with the accelerometer
    /// error `accel` [m/s^2] and drift `drift` [rad/s] already in the model axes.
    pub fn derivative(&self, x: &Vector3<f64>, accel: f64, drift: f64) -> Vector3<f64> {
        Vector3::new(
            x[1] / self.radius,
            -self.g * x[2] + accel,
            x[1] / self.radius + drift,
        )
    }

    /// Fundamental matrix `Φ(t) = exp(A t)` in the closed form (16).
    pub fn fundamental(&self, t: f64) -> Matrix3<f64> {
        let w0 = self.schuler_frequency();
        let (s, c) = (w0 * t).sin_cos();
        let sga = (self.g * self.radius).sqrt();
        Matrix3::new(1.0, s / sga, c - 1.0, 0.0, c, -sga * s, 0.0, s / sga, c)
    }
}

/// SINS accelerometer error projected on the model horizontal axis (28)/(29):
/// `-Δf_p1 sin D + Δf_p2 cos D` [m/s^2] for body angle `d` \[rad\].
pub fn sins_accel_error(bias_p1: f64, bias_p2: f64, d: f64) -> f64 {
    let (s, c) = d.sin_cos();
    -bias_p1 * s + bias_p2 * c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fundamental_is_identity_at_zero_and_solves_the_ode() {
        let m = ErrorModel::new(6_371_000.0, 9.81);
        assert_eq!(m.fundamental(0.0), Matrix3::identity());
        // dΦ/dt = A Φ by central differences; h = 1 s gives O((w0 h)^2 / 6) ~ 3e-7 relative.
        let t = 1234.0;
        let d = (m.fundamental(t + 1.0) - m.fundamental(t - 1.0)) / 2.0;
        let want = m.matrix() * m.fundamental(t);
        for (x, y) in d.iter().zip(want.iter()) {
            assert!((x - y).abs() <= 1e-6 * y.abs() + 1e-18, "{x} vs {y}");
        }
    }
}
