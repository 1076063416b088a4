//! IMU samples and deterministic sensor-error compensation.
//!
//! Convention (KF-GINS, sidereon `ImuSampleKind::Increment`): a sample tagged `t`
//! holds the angle increment `dtheta` [rad] and velocity increment `dvel` [m/s]
//! integrated over the interval `(t - dt, t]`, in body axes front-right-down (FRD).
//!
//! Beside them, what describes a sensor rather than simulates one: the IMU error
//! model's parameters ([`model`]), where its axes point on the vehicle ([`axes`]), and
//! the seeded random stream ([`random`]) that every random draw of the crate comes
//! from, so that `nav`, `filter` and `align` need not import `sim`.

pub mod axes;
pub mod model;
pub mod random;

use nalgebra::{Matrix3, Vector3};

/// One IMU sample: increments over `(t - dt, t]`, body axes FRD.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    /// End of the interval [s] on the log's clock (GPS seconds of week for KF-GINS files).
    pub t: f64,
    /// Length of the interval [s], > 0.
    pub dt: f64,
    /// Angle increment `∫ w_ib_b dt` over the interval [rad].
    pub dtheta: Vector3<f64>,
    /// Velocity increment `∫ f_b dt` over the interval [m/s].
    pub dvel: Vector3<f64>,
}

impl ImuSample {
    /// A sample from rates that are the mean over `(t - dt, t]` (rad/s, m/s^2):
    /// increments are rate times `dt`.
    pub fn from_mean_rates(t: f64, dt: f64, w_ib_b: Vector3<f64>, f_b: Vector3<f64>) -> Self {
        Self {
            t,
            dt,
            dtheta: w_ib_b * dt,
            dvel: f_b * dt,
        }
    }

    /// The same sample in other axes: `c_vs` maps the sample's axes to the new ones
    /// (e.g. [`axes::SensorAxes::c_vs`], sensor to vehicle FRD).
    pub fn rotated(&self, c_vs: &Matrix3<f64>) -> Self {
        Self {
            dtheta: c_vs * self.dtheta,
            dvel: c_vs * self.dvel,
            ..*self
        }
    }

    /// A sample from instantaneous rates at the two ends of the interval, integrated
    /// by the trapezoidal rule (exact for rates varying linearly over the interval).
    pub fn from_endpoint_rates(
        t: f64,
        dt: f64,
        (w0, f0): (Vector3<f64>, Vector3<f64>),
        (w1, f1): (Vector3<f64>, Vector3<f64>),
    ) -> Self {
        Self {
            t,
            dt,
            dtheta: (w0 + w1) * (0.5 * dt),
            dvel: (f0 + f1) * (0.5 * dt),
        }
    }
}

/// Deterministic errors of one sensor triad: `measured = (I + diag(scale) + M) true +
/// bias`, where `M` holds the small misalignment and non-orthogonality angles off the
/// diagonal (rad; `M[(i, j)]` couples true axis j into sensor axis i).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriadErrors {
    /// Bias in the sensor's SI unit (rad/s or m/s^2).
    pub bias: Vector3<f64>,
    /// Scale-factor error per axis (dimensionless; 100 ppm = 1e-4).
    pub scale: Vector3<f64>,
    /// Misalignment matrix (zero diagonal) [rad].
    pub misalignment: Matrix3<f64>,
}

impl Default for TriadErrors {
    fn default() -> Self {
        Self {
            bias: Vector3::zeros(),
            scale: Vector3::zeros(),
            misalignment: Matrix3::zeros(),
        }
    }
}

impl TriadErrors {
    /// `I + diag(scale) + M`.
    pub fn gain(&self) -> Matrix3<f64> {
        let mut m = self.misalignment;
        m.fill_diagonal(0.0);
        Matrix3::identity() + Matrix3::from_diagonal(&self.scale) + m
    }
}

/// Gyro and accelerometer deterministic errors.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SensorErrors {
    /// Gyro triad errors (bias in rad/s).
    pub gyro: TriadErrors,
    /// Accelerometer triad errors (bias in m/s^2).
    pub accel: TriadErrors,
}

/// Errors in setting up a compensation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ImuError {
    /// The error model's gain matrix cannot be inverted.
    #[error("the {0} scale-factor/misalignment matrix is singular")]
    SingularGain(&'static str),
    /// A parameter is NaN or infinite.
    #[error("the {0} error model has a non-finite parameter")]
    NonFinite(&'static str),
}

impl SensorErrors {
    /// Apply the errors to a true sample (the forward model, for simulation):
    /// `dtheta_m = G_g dtheta + b_g dt`, `dvel_m = G_a dvel + b_a dt`.
    pub fn corrupt(&self, s: &ImuSample) -> ImuSample {
        ImuSample {
            dtheta: self.gyro.gain() * s.dtheta + self.gyro.bias * s.dt,
            dvel: self.accel.gain() * s.dvel + self.accel.bias * s.dt,
            ..*s
        }
    }
}

/// Removes known deterministic errors from samples: the inverse of
/// [`SensorErrors::corrupt`], `dtheta = G_g^-1 (dtheta_m - b_g dt)` and likewise for
/// `dvel`; the inverse gains are computed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compensation {
    gyro_inv: Matrix3<f64>,
    accel_inv: Matrix3<f64>,
    gyro_bias: Vector3<f64>,
    accel_bias: Vector3<f64>,
}

impl Compensation {
    /// Compensation for the given errors.
    pub fn new(errors: &SensorErrors) -> Result<Self, ImuError> {
        let invert = |t: &TriadErrors, name: &'static str| {
            let g = t.gain();
            if !g.iter().chain(t.bias.iter()).all(|x| x.is_finite()) {
                return Err(ImuError::NonFinite(name));
            }
            g.try_inverse().ok_or(ImuError::SingularGain(name))
        };
        Ok(Self {
            gyro_inv: invert(&errors.gyro, "gyro")?,
            accel_inv: invert(&errors.accel, "accelerometer")?,
            gyro_bias: errors.gyro.bias,
            accel_bias: errors.accel.bias,
        })
    }

    /// The compensated sample.
    #[inline]
    pub fn apply(&self, s: &ImuSample) -> ImuSample {
        ImuSample {
            dtheta: self.gyro_inv * (s.dtheta - self.gyro_bias * s.dt),
            dvel: self.accel_inv * (s.dvel - self.accel_bias * s.dt),
            ..*s
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn sample() -> ImuSample {
        ImuSample {
            t: 10.0,
            dt: 0.005,
            dtheta: Vector3::new(1e-3, -2e-4, 5e-5),
            dvel: Vector3::new(0.01, 0.002, -0.049),
        }
    }

    /// A hand-computed case: 100 ppm scale on x, 1 deg/h gyro bias on z, 1 mg
    /// accelerometer bias on y.
    #[test]
    fn corrupt_matches_hand_values() {
        let mut e = SensorErrors::default();
        e.gyro.scale.x = 1e-4;
        e.gyro.bias.z = 1f64.to_radians() / 3600.0;
        e.accel.bias.y = 9.80665e-3;
        let s = sample();
        let m = e.corrupt(&s);
        assert_relative_eq!(m.dtheta.x, 1e-3 * 1.0001, max_relative = 1e-15);
        assert_relative_eq!(
            m.dtheta.z,
            5e-5 + 4.84813681109536e-6 * 0.005,
            max_relative = 1e-14
        );
        assert_relative_eq!(m.dvel.y, 0.002 + 9.80665e-3 * 0.005, max_relative = 1e-15);
    }

    /// Compensation inverts the forward model with misalignment and scale on every
    /// axis, to round-off (1e-15 relative of the largest component).
    #[test]
    fn compensation_inverts_corruption() {
        let mut e = SensorErrors::default();
        e.gyro.bias = Vector3::new(1e-5, -2e-5, 3e-6);
        e.gyro.scale = Vector3::new(1e-4, -3e-4, 2e-5);
        e.gyro.misalignment = Matrix3::new(0.0, 1e-4, -2e-4, 3e-4, 0.0, 5e-5, -1e-4, 2e-4, 0.0);
        e.accel = e.gyro;
        e.accel.bias = Vector3::new(1e-3, 2e-3, -5e-3);
        let s = sample();
        let back = Compensation::new(&e)
            .expect("invertible")
            .apply(&e.corrupt(&s));
        assert_relative_eq!(back.dtheta, s.dtheta, epsilon = 1e-18);
        assert_relative_eq!(back.dvel, s.dvel, epsilon = 1e-16);
    }

    #[test]
    fn singular_and_non_finite_are_errors() {
        let mut e = SensorErrors::default();
        e.accel.scale.y = -1.0;
        assert_eq!(
            Compensation::new(&e),
            Err(ImuError::SingularGain("accelerometer"))
        );
        let mut e = SensorErrors::default();
        e.gyro.bias.x = f64::NAN;
        assert_eq!(Compensation::new(&e), Err(ImuError::NonFinite("gyro")));
    }

    #[test]
    fn rotated_turns_both_increments() {
        let c = axes::SensorAxes::FRD.c_vs();
        assert_eq!(sample().rotated(&c), sample());
        let rbd: axes::SensorAxes = "RBD".parse().expect("right-handed");
        let s = sample().rotated(&rbd.c_vs());
        assert_eq!(s.dtheta, Vector3::new(2e-4, 1e-3, 5e-5));
        assert_eq!(s.dvel, Vector3::new(-0.002, 0.01, -0.049));
        assert_eq!((s.t, s.dt), (10.0, 0.005));
    }

    #[test]
    fn rate_conversions() {
        let w = Vector3::new(0.1, 0.2, 0.3);
        let f = Vector3::new(0.0, 0.0, -9.8);
        let s = ImuSample::from_mean_rates(1.0, 0.01, w, f);
        assert_relative_eq!(s.dtheta, w * 0.01);
        let s = ImuSample::from_endpoint_rates(1.0, 0.01, (w, f), (w * 3.0, f));
        assert_relative_eq!(s.dtheta, w * 0.02, epsilon = 1e-17);
        assert_relative_eq!(s.dvel, f * 0.01, epsilon = 1e-17);
    }
}
