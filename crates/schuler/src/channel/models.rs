//! Nonlinear single-channel models: the true motion, the sensors it excites, and the
//! navigation computers of the ideal and the perturbed platform INS (6)/(9) and SINS
//! (7)/(26), integrated side by side in one state vector.
//!
//! Truth (5): on the sphere (radius a, gravitation g at the surface, rotation ω), a point
//! moving along the equator at speed V has vertical specific force
//! `f_x1 = g - (V + aω)²/a` and horizontal `f_x2 = V'`. The body angle D (SINS) is the
//! angle from the horizon axis x2 to the body axis p2, so the body-axis accelerometers
//! read `f_p1 = f_x1 cos D - f_x2 sin D`, `f_p2 = f_x1 sin D + f_x2 cos D` and the gyro
//! reads `ω_p3 = V/a + ω - D'` ((7): `D' = -ω_p3 + ω_x3`).
//!
//! Computers. Platform INS (6)/(9): `λ' = V/a`, `V' = f_z2` (the accelerometer on the
//! platform), platform commanded at `(1 + θ)(V/a + ω) + ν` (θ: torquer scale error,
//! ν: drift). SINS (7)/(26): `λ' = V/a`, `V' = -f_p1 sin D + f_p2 cos D`,
//! `D' = -ω_p3 + V/a + ω`, fed with `f'_pi = f_pi + Δf_pi`, `ω'_p3 = (1 + θ) ω_p3 + ν_p3`.
//! The ideal computer gets exact sensors and exact initial conditions.
//!
//! State layout ([`NonlinearState`]): `[λ, V, angle, λ', V', angle']`, unprimed = ideal,
//! primed = perturbed. For the INS `angle` is the platform's angle from the true local
//! horizon Mx (zero for the ideal platform up to round-off), so `α = angle' - angle`;
//! for the SINS `angle` is the computed D, and `α = D' - D` (the text's `α = ΔD`).
//! Errors are formed ideal-to-perturbed, as in the text: `Δr = a(λ' - λ)`, `ΔV = V' - V`.

use super::ChannelError;
use super::linear::ErrorState;
use super::profile::{BodyAngleProfile, SpeedProfile};
use crate::earth::Sphere;
use nalgebra::Vector6;

/// Which single-channel system: platform INS (6)/(9) or strapdown SINS (7)/(26).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum System {
    /// Platform (gimballed) INS, (6) and (9).
    Ins,
    /// Strapdown INS, (7) and (26).
    Sins,
}

/// Instrument errors, constant in time (SI).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SensorErrors {
    /// INS: bias Δf of the platform accelerometer (axis z2) [m/s^2] (12).
    pub accel_bias: f64,
    /// SINS: bias Δf_p1 of the body-vertical accelerometer [m/s^2] (28).
    pub accel_bias_p1: f64,
    /// SINS: bias Δf_p2 of the body-longitudinal accelerometer [m/s^2] (28).
    pub accel_bias_p2: f64,
    /// INS: platform drift ν_z3; SINS: gyro drift ν_p3 [rad/s] (8), (28).
    pub drift: f64,
    /// Gyro scale-factor error θ (INS: of the platform torquing rate) \[1\] (text after (29)).
    pub gyro_scale: f64,
}

/// Initial vertical: given directly, or from leveling at t = 0 (text before (24), (7)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Alignment {
    /// Initial vertical error α0 \[rad\] typed in.
    Tilt(f64),
    /// Level at t = 0: INS, turn the platform until its accelerometer reads zero (24);
    /// SINS, `tan D'(0) = f'_p2 / f'_p1` (7).
    Level,
}

/// Named indices of the nonlinear state `[λ, V, angle, λ', V', angle']`.
#[derive(Debug, Clone, Copy)]
pub struct NonlinearState;

impl NonlinearState {
    /// Ideal longitude λ \[rad\].
    pub const LAMBDA: usize = 0;
    /// Ideal speed V [m/s].
    pub const V: usize = 1;
    /// Ideal angle (INS: platform from Mx; SINS: computed D) \[rad\].
    pub const ANGLE: usize = 2;
    /// Perturbed longitude λ' \[rad\].
    pub const LAMBDA_P: usize = 3;
    /// Perturbed speed V' [m/s].
    pub const V_P: usize = 4;
    /// Perturbed angle (INS: platform from Mx; SINS: computed D') \[rad\].
    pub const ANGLE_P: usize = 5;
}

/// The true motion on the sphere and the sensor readings it produces (5), (7).
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    /// The sphere: radius, gravitation, rotation rate.
    pub earth: Sphere,
    /// Speed along the equator.
    pub speed: SpeedProfile,
    /// Body angle D(t) (SINS; ignored by the platform INS).
    pub body: BodyAngleProfile,
}

impl Truth {
    /// Gravitation at the surface `g = μ/a²` [m/s^2] (5).
    pub fn g(&self) -> f64 {
        self.earth.gravitation(self.earth.radius)
    }

    /// Specific force in the reference trihedron `(f_x1, f_x2)` [m/s^2] (5) with Earth rate.
    pub fn specific_force(&self, t: f64) -> (f64, f64) {
        let a = self.earth.radius;
        let w_inertial = self.speed.speed(t) + a * self.earth.rotation_rate;
        (self.g() - w_inertial * w_inertial / a, self.speed.accel(t))
    }

    /// Specific force on the body axes `(f_p1, f_p2)` [m/s^2] (fig. 1, after (27)).
    pub fn body_specific_force(&self, t: f64) -> (f64, f64) {
        let (f1, f2) = self.specific_force(t);
        let (s, c) = self.body.angle(t).sin_cos();
        (f1 * c - f2 * s, f1 * s + f2 * c)
    }

    /// Gyro reading on p3 `ω_p3 = V/a + ω - D'` [rad/s] (7).
    pub fn gyro_rate(&self, t: f64) -> f64 {
        self.frame_rate(t) - self.body.angle_rate(t)
    }

    /// Inertial rate of the reference trihedron Mx, `V/a + ω` [rad/s] (6) with Earth rate.
    pub fn frame_rate(&self, t: f64) -> f64 {
        self.speed.speed(t) / self.earth.radius + self.earth.rotation_rate
    }
}

/// The ideal and perturbed computers of one system, integrated side by side.
#[derive(Debug, Clone, PartialEq)]
pub struct Nonlinear {
    /// Which system.
    pub system: System,
    /// True motion and sensors.
    pub truth: Truth,
    /// Instrument errors of the perturbed system.
    pub sensors: SensorErrors,
}

impl Nonlinear {
    /// Right-hand side of the ideal (6)/(7) and perturbed (9)/(26) equations at `t`.
    pub fn derivative(&self, t: f64, x: &Vector6<f64>) -> Vector6<f64> {
        type S = NonlinearState;
        let a = self.truth.earth.radius;
        let w = self.truth.earth.rotation_rate;
        let e = &self.sensors;
        let mut d = Vector6::zeros();
        d[S::LAMBDA] = x[S::V] / a;
        d[S::LAMBDA_P] = x[S::V_P] / a;
        match self.system {
            System::Ins => {
                let (f1, f2) = self.truth.specific_force(t);
                let frame = self.truth.frame_rate(t);
                // Accelerometer on a platform tilted by `angle` from Mx: f_x2 cos - f_x1 sin.
                let read = |angle: f64| {
                    let (s, c) = angle.sin_cos();
                    f2 * c - f1 * s
                };
                d[S::V] = read(x[S::ANGLE]);
                d[S::V_P] = read(x[S::ANGLE_P]) + e.accel_bias;
                d[S::ANGLE] = (x[S::V] / a + w) - frame;
                d[S::ANGLE_P] = (1.0 + e.gyro_scale) * (x[S::V_P] / a + w) + e.drift - frame;
            }
            System::Sins => {
                let (fp1, fp2) = self.truth.body_specific_force(t);
                let w_p3 = self.truth.gyro_rate(t);
                let horizontal = |f1: f64, f2: f64, dd: f64| {
                    let (s, c) = dd.sin_cos();
                    -f1 * s + f2 * c
                };
                d[S::V] = horizontal(fp1, fp2, x[S::ANGLE]);
                d[S::V_P] = horizontal(fp1 + e.accel_bias_p1, fp2 + e.accel_bias_p2, x[S::ANGLE_P]);
                d[S::ANGLE] = -w_p3 + x[S::V] / a + w;
                d[S::ANGLE_P] = -((1.0 + e.gyro_scale) * w_p3 + e.drift) + x[S::V_P] / a + w;
            }
        }
        d
    }

    /// Initial state: exact for the ideal computer; for the perturbed one, position and
    /// velocity errors and the initial vertical from `alignment`.
    pub fn initial_state(
        &self,
        alignment: Alignment,
        init_vel_error: f64,
        init_pos_error: f64,
    ) -> Result<Vector6<f64>, ChannelError> {
        type S = NonlinearState;
        let v0 = self.truth.speed.speed(0.0);
        let mut x = Vector6::zeros();
        x[S::V] = v0;
        x[S::V_P] = v0 + init_vel_error;
        x[S::LAMBDA_P] = init_pos_error / self.truth.earth.radius;
        let d0 = match self.system {
            System::Ins => 0.0,
            System::Sins => self.truth.body.angle(0.0),
        };
        x[S::ANGLE] = d0;
        x[S::ANGLE_P] = d0 + self.initial_vertical(alignment)?;
        Ok(x)
    }

    /// Initial vertical error α0 \[rad\] of the perturbed computer: typed in, or the result
    /// of leveling with the biased sensors (24), (7).
    pub fn initial_vertical(&self, alignment: Alignment) -> Result<f64, ChannelError> {
        match alignment {
            Alignment::Tilt(alpha0) => Ok(alpha0),
            Alignment::Level => match self.system {
                System::Ins => {
                    // f_x2 cos α - f_x1 sin α + Δf = 0  <=>  sin(α - φ) = Δf / R.
                    let (f1, f2) = self.truth.specific_force(0.0);
                    let r = f1.hypot(f2);
                    let b = self.sensors.accel_bias;
                    if b.abs() >= r || r.is_nan() {
                        return Err(ChannelError::CannotLevel { bias: b, force: r });
                    }
                    Ok(f2.atan2(f1) + (b / r).asin())
                }
                System::Sins => {
                    let (fp1, fp2) = self.truth.body_specific_force(0.0);
                    let (m1, m2) = (
                        fp1 + self.sensors.accel_bias_p1,
                        fp2 + self.sensors.accel_bias_p2,
                    );
                    if m1.hypot(m2) == 0.0 {
                        return Err(ChannelError::CannotLevel {
                            bias: self.sensors.accel_bias_p1.hypot(self.sensors.accel_bias_p2),
                            force: fp1.hypot(fp2),
                        });
                    }
                    // tan D'(0) = f'_p2 / f'_p1 (7); α0 = D'(0) - D(0).
                    Ok(m2.atan2(m1) - self.truth.body.angle(0.0))
                }
            },
        }
    }

    /// Errors of the perturbed computer against the ideal one: `Δr = a(λ' - λ)`,
    /// `ΔV = V' - V`, `α = angle' - angle` (9), (26).
    pub fn errors(&self, x: &Vector6<f64>) -> ErrorState {
        type S = NonlinearState;
        ErrorState {
            dr: self.truth.earth.radius * (x[S::LAMBDA_P] - x[S::LAMBDA]),
            dv: x[S::V_P] - x[S::V],
            alpha: x[S::ANGLE_P] - x[S::ANGLE],
        }
    }

    /// Kinematic error `β = α - γ`, with `γ = Δλ` the position error in angle (8), (26).
    pub fn kinematic_error(&self, x: &Vector6<f64>) -> f64 {
        type S = NonlinearState;
        (x[S::ANGLE_P] - x[S::ANGLE]) - (x[S::LAMBDA_P] - x[S::LAMBDA])
    }
}
