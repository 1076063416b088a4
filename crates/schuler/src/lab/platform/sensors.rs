//! The instruments of a truth-driven system: constant biases and drifts
//! ([`InstrumentErrors`]) plus, optionally, the simulator's full IMU error model
//! ([`crate::imu::model`]: turn-on bias, bias instability, random walks, white
//! noise, scale factor, misalignment, quantization...), applied to what a platform's
//! own sensors see.
//!
//! The model works on increments, so over each RK4 step `(t − dt, t]` the ideal
//! increments are formed from the sensors' inputs at the step's start (`w dt`, `f dt`,
//! in the sensors' axes), passed through the model, and the difference, divided by
//! `dt`, is held as the step's error rate. Additive errors are reproduced exactly;
//! input-proportional ones (scale factor, misalignment) use the step's starting input,
//! an `O(dt)` approximation of their effect.

use super::InstrumentErrors;
use crate::imu::ImuSample;
use crate::imu::model::ImuModel;
use crate::sim::imu_model::ImuSimulator;
use nalgebra::Vector3;

/// Error sources of one triad of gyros and one of accelerometers.
#[derive(Debug)]
pub struct Sensors {
    constant: InstrumentErrors,
    model: Option<ImuSimulator>,
    initial_accel_bias: Vector3<f64>,
}

impl From<InstrumentErrors> for Sensors {
    fn from(errors: InstrumentErrors) -> Self {
        Self::constant(errors)
    }
}

impl Sensors {
    /// Constant errors only.
    pub fn constant(errors: InstrumentErrors) -> Self {
        Self {
            constant: errors,
            model: None,
            initial_accel_bias: errors.accel_bias,
        }
    }

    /// Constant errors plus the simulator's model drawn from `seed`.
    pub fn with_model(errors: InstrumentErrors, model: ImuModel, seed: u64) -> Self {
        let bias = model.accel.bias;
        let sim = ImuSimulator::new(model, seed);
        Self {
            constant: errors,
            initial_accel_bias: errors.accel_bias + bias + sim.turn_on_biases().1,
            model: Some(sim),
        }
    }

    /// The accelerometer bias known at the start (constant plus the model's constant
    /// and turn-on bias), which the leveling cancels [m/s^2].
    pub fn initial_accel_bias(&self) -> Vector3<f64> {
        self.initial_accel_bias
    }

    /// Error rates (gyro [rad/s], accelerometer [m/s^2]) over the step `(t − dt, t]`
    /// for the ideal inputs `w` and `f` at its start.
    pub fn step(
        &mut self,
        t: f64,
        dt: f64,
        w: &Vector3<f64>,
        f: &Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let (mut e_w, mut e_f) = (self.constant.gyro_drift, self.constant.accel_bias);
        if let Some(sim) = &mut self.model {
            let ideal = ImuSample {
                t,
                dt,
                dtheta: w * dt,
                dvel: f * dt,
            };
            let m = sim.measure(&ideal);
            e_w += (m.dtheta - ideal.dtheta) / dt;
            e_f += (m.dvel - ideal.dvel) / dt;
        }
        (e_w, e_f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Constant errors pass through; a model's bias and scale factor appear as rates.
    #[test]
    fn constant_and_model_errors_as_rates() {
        let c = InstrumentErrors {
            accel_bias: Vector3::new(1e-3, 0.0, 0.0),
            gyro_drift: Vector3::new(0.0, 5e-8, 0.0),
        };
        let mut s = Sensors::constant(c);
        let (w, f) = s.step(1.0, 0.1, &Vector3::zeros(), &Vector3::new(0.0, 0.0, -9.8));
        assert_eq!((w, f), (c.gyro_drift, c.accel_bias));
        let mut m = ImuModel::default();
        m.accel.scale = Vector3::new(0.0, 0.0, 1e-4);
        m.gyro.bias = Vector3::new(2e-7, 0.0, 0.0);
        let mut s = Sensors::with_model(c, m, 3);
        let (w, f) = s.step(1.0, 0.1, &Vector3::zeros(), &Vector3::new(0.0, 0.0, -9.8));
        assert!((w - Vector3::new(2e-7, 5e-8, 0.0)).norm() < 1e-20);
        assert!((f - Vector3::new(1e-3, 0.0, -9.8e-4)).norm() < 1e-15);
        assert_eq!(s.initial_accel_bias(), c.accel_bias);
    }
}
