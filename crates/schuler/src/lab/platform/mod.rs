//! Platform (gimballed) INS variants, the analytic INS and the gyro-free INS of
//! lecture 22, simulated from a trajectory's truth so they can be compared with the
//! strapdown mechanizations on the same motion.
//!
//! Lecture 22 classifies systems by the two trihedra of (22.10)–(22.14): the
//! accelerometers' (rate `ω1`) and the gyros' (rate `ω2`); the navigation equation in
//! the accelerometer trihedron is (22.10) `dV/dt = a + g − ω1 × V`.
//!
//! - **Semi-analytic** (22.16): both trihedra on a level platform commanded with the
//!   computed frame rate (22.17), so it is Schuler tuned. Its azimuth is chosen by the
//!   vertical rate `ω_ζ`: geographic (north-slaved, `ω_ζ = (V/R) tan φ sin ψ + ω3 sin φ`),
//!   orthodromic (`ω_ζ = ω3 sin φ`: no azimuth rotation relative to the Earth) and
//!   free-azimuth (`ω_ζ = 0`: none relative to inertial space). See [`gimbaled`].
//! - **Analytic** (22.15): both trihedra fixed in inertial space; navigation in the
//!   inertial frame (22.1) with gravitation computed from position (22.2). See
//!   [`analytic`].
//! - **Gyro-free**: six single-axis accelerometers on a rigid base; the differences
//!   between their readings give the angular motion, (22.18)–(22.21). See
//!   [`gyro_free`].
//!
//! A platform system is continuous hardware, so it is simulated as an ODE (the
//! platform's true attitude driven by the commanded rate plus gyro drift, the computer's
//! navigation equations driven by what the accelerometers read), integrated by RK4 with
//! the truth evaluated at each step's start, middle and end ([`truth`]). Instrument
//! errors are constant biases and drifts ([`InstrumentErrors`]), optionally with the
//! simulator's full IMU error model ([`sensors`]); the initial leveling
//! ([`leveling`]) tilts the sensors so that the biased accelerometers read the true
//! horizontal specific force, as a real leveling does. [`compare`] runs every system
//! on one trajectory.

pub mod analytic;
pub mod compare;
pub mod gimbaled;
pub mod gyro_free;
pub mod inertial;
pub mod sensors;
pub mod truth;

pub use analytic::AnalyticIns;
pub use compare::{CompareConfig, Comparison, NavError, SystemKind, compare};
pub use gimbaled::{Azimuth, PlatformIns};
pub use gyro_free::{AccelerometerArray, GyroFreeError, GyroFreeIns};
pub use sensors::Sensors;
pub use truth::{TruthPoint, truth_at};

use nalgebra::{Quaternion, Rotation3, Unit, UnitQuaternion, Vector3};

/// Constant instrument errors, in the instruments' own axes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InstrumentErrors {
    /// Accelerometer biases [m/s^2] (textbook reference: 1e-3, SEEDS.md (20)).
    pub accel_bias: Vector3<f64>,
    /// Gyro drifts [rad/s] (textbook reference: 0.01 deg/h = 4.85e-8, (22)).
    pub gyro_drift: Vector3<f64>,
}

/// How the unstable vertical channel (SEEDS.md (30)–(32)) is handled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VerticalChannel {
    /// Free inertial: height diverges with the e-fold time `1/(√2 ω0)` ≈ 570 s.
    Free,
    /// Height and vertical velocity reset to the truth after every step, as an ideal
    /// barometric loop would hold them, so the horizontal channels are compared alone.
    #[default]
    TrueHeight,
}

/// Leveling of sensors with biased accelerometers: the true rotation `C_sx` from the
/// sensor axes `s` to the computer's frame `x` (`v_x = C_sx v_s`; the computer takes
/// the sensor axes to be `x`) for which the sensors read, with bias `b_s`, a specific
/// force whose horizontal part (normal to `down_x`) equals the true one `f_x`. To first
/// order this is the textbook's `α0 = Δf/g` (SEEDS.md, leveling), here exact
/// (fixed-point passes on the bias's small rotation; each gains about `|b|/g`, six
/// reach round-off).
pub fn leveling(
    f_x: &Vector3<f64>,
    b_s: &Vector3<f64>,
    down_x: &Unit<Vector3<f64>>,
) -> Rotation3<f64> {
    // c_xs: computer frame to sensor axes, `m = C_xs f_x + b`.
    let mut c_xs = Rotation3::identity();
    for _ in 0..6 {
        let u = f_x + c_xs.inverse() * b_s;
        c_xs = level_rotation(&u, f_x, down_x);
    }
    c_xs.inverse()
}

/// The rotation `R` (about a horizontal axis) with `R u` having the horizontal part of
/// `f_true` and `u`'s length and vertical sign: what a leveled computer's resolution of
/// the measured `u` must do. Used directly for strapdown systems, where the computer's
/// attitude (not the sensor) is rotated.
pub fn level_rotation(
    u: &Vector3<f64>,
    f_true: &Vector3<f64>,
    down: &Unit<Vector3<f64>>,
) -> Rotation3<f64> {
    let d = down.into_inner();
    let horizontal = f_true - d * f_true.dot(&d);
    let vertical = (u.norm_squared() - horizontal.norm_squared())
        .max(0.0)
        .sqrt();
    let target = horizontal + d * vertical.copysign(u.dot(&d));
    // Angle by atan2, not acos of the dot product: the tilts are ~1e-4 rad, where acos
    // would lose 1e-12 rad.
    let axis = u.cross(&target);
    let s = axis.norm();
    if s == 0.0 {
        return Rotation3::identity();
    }
    Rotation3::from_axis_angle(&Unit::new_unchecked(axis / s), s.atan2(u.dot(&target)))
}

/// A state an RK4 step can combine: `self + h * d`.
pub(crate) trait OdeState: Copy {
    /// `self + h * d`.
    fn plus(&self, d: &Self, h: f64) -> Self;
}

/// One classical RK4 step of `y' = f(node, y)`, `node` 0 = start, 1 = middle, 2 = end.
pub(crate) fn rk4<S: OdeState>(y: &S, dt: f64, f: impl Fn(usize, &S) -> S) -> S {
    let k1 = f(0, y);
    let k2 = f(1, &y.plus(&k1, 0.5 * dt));
    let k3 = f(1, &y.plus(&k2, 0.5 * dt));
    let k4 = f(2, &y.plus(&k3, dt));
    y.plus(&k1, dt / 6.0)
        .plus(&k2, dt / 3.0)
        .plus(&k3, dt / 3.0)
        .plus(&k4, dt / 6.0)
}

/// `dq/dt = ½ q ⊗ (0, w)` for a frame rotating at `w` in its own axes.
pub(crate) fn quat_rate(q: &Quaternion<f64>, w: &Vector3<f64>) -> Quaternion<f64> {
    q * Quaternion::new(0.0, w.x, w.y, w.z) * 0.5
}

/// The unit quaternion of an RK4-integrated (slightly non-unit) one.
pub(crate) fn unit(q: &Quaternion<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(*q)
}

/// Driving a truth-driven system one step: the truth at the step's start, middle and
/// end.
pub trait TruthDriven {
    /// Advance over `[a.state.t, c.state.t]` with the truth at the start `a`, middle `m`
    /// and end `c`.
    fn step(&mut self, a: &TruthPoint, m: &TruthPoint, c: &TruthPoint);
    /// The computed navigation state; the attitude comes from the computer's frame and
    /// the gimbal angles, which measure the true body attitude relative to the platform
    /// (`truth` is the truth at the current time).
    fn state(&self, truth: &TruthPoint) -> crate::nav::NavState;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// After leveling, the biased reading resolved in the computer's frame has the true
    /// horizontal part to round-off, and the tilt is the textbook's Δf/g.
    #[test]
    fn leveling_cancels_the_horizontal_bias() {
        let f = Vector3::new(0.0, 0.0, -9.81);
        let b = Vector3::new(1e-3, -2e-3, 5e-4);
        let down = Vector3::z_axis();
        let c_sx = leveling(&f, &b, &down);
        let m = c_sx.inverse() * f + b;
        assert!(m.x.abs() < 1e-15 && m.y.abs() < 1e-15, "{m}");
        let (roll, pitch, _) = c_sx.euler_angles();
        assert!((pitch - (-1e-3 / 9.81)).abs() < 1e-9);
        assert!((roll - (-2e-3 / 9.81)).abs() < 1e-9);
    }
}
