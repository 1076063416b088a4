//! The seeded simulation of an [`ImuModel`]: what a real gyro and accelerometer triad
//! add to the exact increments, drawn sample after sample (the model's terms are in
//! [`crate::imu::model`]).

use crate::imu::ImuSample;
use crate::imu::model::{ImuModel, TriadModel};
use crate::imu::random::Noise;
use nalgebra::Vector3;

/// Running state of one triad's random processes.
#[derive(Debug)]
struct TriadState {
    turn_on: Vector3<f64>,
    gm: Vector3<f64>,
    rw: Vector3<f64>,
    carry: Vector3<f64>,
    step: Option<Step>,
}

/// A seeded simulation of an [`ImuModel`], applied sample after sample.
#[derive(Debug)]
pub struct ImuSimulator {
    model: ImuModel,
    gyro: TriadState,
    accel: TriadState,
    noise: Noise,
}

/// Stream ids of the random draws, fixed so adding a term never reshuffles another.
const STREAM_IMU: u64 = 1;

/// Three standard normals (ziggurat: the IMU draws nine pairs per sample).
fn draw3(noise: &mut Noise) -> Vector3<f64> {
    Vector3::new(
        noise.normal_ziggurat(),
        noise.normal_ziggurat(),
        noise.normal_ziggurat(),
    )
}

/// Per-interval constants of one triad's processes for one `dt` (computed once: the
/// exponential and square roots cost more than the rest of a sample).
#[derive(Debug, Clone, Copy)]
struct Step {
    dt: f64,
    sqrt_dt: f64,
    /// Gauss–Markov `e^{-dt/τ}` (0 where the process is off).
    gm_phi: Vector3<f64>,
    /// Gauss–Markov innovation std `σ sqrt(1 - e^{-2dt/τ})`.
    gm_q: Vector3<f64>,
}

impl Step {
    fn new(m: &TriadModel, dt: f64) -> Self {
        let (mut gm_phi, mut gm_q) = (Vector3::zeros(), Vector3::zeros());
        for i in 0..3 {
            if m.gm_sigma[i] > 0.0 && m.gm_tau[i] > 0.0 {
                let phi = (-dt / m.gm_tau[i]).exp();
                gm_phi[i] = phi;
                gm_q[i] = m.gm_sigma[i] * (1.0 - phi * phi).sqrt();
            }
        }
        Self {
            dt,
            sqrt_dt: dt.sqrt(),
            gm_phi,
            gm_q,
        }
    }
}

impl TriadState {
    fn new(m: &TriadModel, noise: &mut Noise) -> Self {
        let turn_on = m.turn_on.component_mul(&draw3(noise));
        // Start the Gauss–Markov process in its stationary distribution.
        let gm = m.gm_sigma.component_mul(&draw3(noise));
        Self {
            turn_on,
            gm,
            rw: Vector3::zeros(),
            carry: Vector3::zeros(),
            step: None,
        }
    }

    /// Advance the random processes over `dt` and return the erroneous increment of
    /// the true increment `x` (before g-sensitivity and vibration, which the caller
    /// adds, and before quantization).
    fn corrupt(
        &mut self,
        m: &TriadModel,
        x: &Vector3<f64>,
        dt: f64,
        noise: &mut Noise,
    ) -> Vector3<f64> {
        let w_gm = draw3(noise);
        let w_rw = draw3(noise);
        let w_white = draw3(noise);
        let step = match self.step {
            Some(st) if st.dt == dt => st,
            _ => *self.step.insert(Step::new(m, dt)),
        };
        let mis = &m.misalignment;
        // The cross-axis terms `Σ_{j != i} M_ij x_j`, in that order (and from zero, as
        // a sum: the same bits).
        let cross = [
            mis[(0, 1)] * x[1] + mis[(0, 2)] * x[2],
            mis[(1, 0)] * x[0] + mis[(1, 2)] * x[2],
            mis[(2, 0)] * x[0] + mis[(2, 1)] * x[1],
        ];
        let mut y = Vector3::zeros();
        for i in 0..3 {
            if m.gm_sigma[i] > 0.0 && m.gm_tau[i] > 0.0 {
                self.gm[i] = step.gm_phi[i] * self.gm[i] + step.gm_q[i] * w_gm[i];
            }
            self.rw[i] += m.random_walk[i] * step.sqrt_dt * w_rw[i];
            let gain = 1.0 + m.scale[i] + m.asymmetry[i] * x[i].signum();
            let bias = m.bias[i] + self.turn_on[i] + self.gm[i] + self.rw[i];
            y[i] =
                gain * x[i] + (0.0 + cross[i]) + bias * dt + m.white[i] * step.sqrt_dt * w_white[i];
        }
        y
    }

    /// Quantize with carry: output whole steps, keep the remainder for the next sample.
    fn quantize(&mut self, m: &TriadModel, y: Vector3<f64>) -> Vector3<f64> {
        let mut out = y;
        for i in 0..3 {
            let q = m.quantum[i];
            if q > 0.0 {
                let total = y[i] + self.carry[i];
                out[i] = (total / q).round() * q;
                self.carry[i] = total - out[i];
            }
        }
        out
    }
}

impl ImuSimulator {
    /// A simulator of `model` whose random draws come from `seed`.
    pub fn new(model: ImuModel, seed: u64) -> Self {
        let mut noise = Noise::new(seed, STREAM_IMU);
        let gyro = TriadState::new(&model.gyro, &mut noise);
        let accel = TriadState::new(&model.accel, &mut noise);
        Self {
            model,
            gyro,
            accel,
            noise,
        }
    }

    /// The turn-on biases drawn for this run (gyro, accelerometer), for the record.
    pub fn turn_on_biases(&self) -> (Vector3<f64>, Vector3<f64>) {
        (self.gyro.turn_on, self.accel.turn_on)
    }

    /// The biases in effect now, gyro [rad/s] and accelerometer [m/s^2]: constant,
    /// turn-on, Gauss–Markov and random-walk parts summed (the truth an estimator's
    /// bias estimates are compared with).
    pub fn biases(&self) -> (Vector3<f64>, Vector3<f64>) {
        let sum = |m: &TriadModel, s: &TriadState| m.bias + s.turn_on + s.gm + s.rw;
        (
            sum(&self.model.gyro, &self.gyro),
            sum(&self.model.accel, &self.accel),
        )
    }

    /// The errors in effect now as an estimator's sensor-error states hold them: the
    /// biases ([`ImuSimulator::biases`]) and the scale-factor errors (their asymmetry
    /// has no such state and is left out).
    pub fn sensor_errors(&self) -> crate::filter::SensorEstimates {
        let (gyro_bias, accel_bias) = self.biases();
        crate::filter::SensorEstimates {
            gyro_bias,
            accel_bias,
            gyro_scale: self.model.gyro.scale,
            accel_scale: self.model.accel.scale,
            ..Default::default()
        }
    }

    /// The measured sample for a true sample.
    pub fn measure(&mut self, truth: &ImuSample) -> ImuSample {
        let dt = truth.dt;
        let m = &self.model;
        let mut dtheta = self
            .gyro
            .corrupt(&m.gyro, &truth.dtheta, dt, &mut self.noise);
        dtheta += m.g_sensitivity * truth.dvel;
        let mut dvel = self
            .accel
            .corrupt(&m.accel, &truth.dvel, dt, &mut self.noise);
        let (t0, t1) = (truth.t - dt, truth.t);
        for line in &m.vibration {
            let w = std::f64::consts::TAU * line.freq_hz;
            if w > 0.0 {
                // ∫ A sin(w t + φ) dt = A/w (cos(w t0 + φ) - cos(w t1 + φ)).
                let k = ((w * t0 + line.phase).cos() - (w * t1 + line.phase).cos()) / w;
                dvel += line.amplitude * k;
            }
        }
        ImuSample {
            dtheta: self.gyro.quantize(&m.gyro, dtheta),
            dvel: self.accel.quantize(&m.accel, dvel),
            ..*truth
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::imu::model::VibrationLine;
    use approx::assert_relative_eq;

    fn sample(t: f64, dt: f64) -> ImuSample {
        ImuSample {
            t,
            dt,
            dtheta: Vector3::new(1e-3, -2e-3, 5e-4),
            dvel: Vector3::new(0.01, 0.0, -0.049),
        }
    }

    /// Constant bias and scale factor show up exactly: y = (1 + s) x + b dt.
    #[test]
    fn bias_and_scale_are_exact() {
        let mut m = ImuModel::default();
        m.gyro.bias = Vector3::new(1e-5, 0.0, 0.0);
        m.accel.scale = Vector3::new(0.0, 0.0, 1e-4);
        let mut sim = ImuSimulator::new(m, 1);
        let s = sample(1.0, 0.005);
        let y = sim.measure(&s);
        assert_eq!(y.dtheta.x, 1e-3 + 1e-5 * 0.005);
        assert_eq!(y.dtheta.y, -2e-3);
        assert_relative_eq!(y.dvel.z, -0.049 * 1.0001, max_relative = 1e-16);
    }

    /// The reported biases are the ones in the samples: with no noise, scale or
    /// misalignment, a zero motion measures `b dt` exactly, sample after sample, while
    /// the Gauss–Markov and random-walk parts move.
    #[test]
    fn reported_biases_are_the_ones_applied() {
        let mut m = ImuModel::default();
        let v = Vector3::new(1e-5, 2e-5, 3e-5);
        for t in [&mut m.gyro, &mut m.accel] {
            t.bias = v;
            t.turn_on = v;
            t.gm_sigma = v;
            t.gm_tau = Vector3::repeat(10.0);
            t.random_walk = v;
        }
        let mut sim = ImuSimulator::new(m, 3);
        let zero = |k: u32| ImuSample {
            t: f64::from(k) * 0.01,
            dt: 0.01,
            dtheta: Vector3::zeros(),
            dvel: Vector3::zeros(),
        };
        let first = sim.biases();
        for k in 1..=100 {
            let y = sim.measure(&zero(k));
            let (bg, ba) = sim.biases();
            assert_relative_eq!(y.dtheta / 0.01, bg, max_relative = 1e-12);
            assert_relative_eq!(y.dvel / 0.01, ba, max_relative = 1e-12);
        }
        assert_ne!(sim.biases(), first);
    }

    /// Quantization: every output is a whole number of steps, and the running sum
    /// stays within one step of the true sum (carry).
    #[test]
    fn quantization_steps_and_carry() {
        let mut m = ImuModel::default();
        let q = 1e-6;
        m.gyro.quantum = Vector3::new(q, q, q);
        let mut sim = ImuSimulator::new(m, 1);
        let (mut sum_in, mut sum_out) = (0.0, 0.0);
        for k in 1..=1000 {
            let s = sample(k as f64 * 0.005, 0.005);
            let y = sim.measure(&s);
            let steps = y.dtheta.x / q;
            assert!((steps - steps.round()).abs() < 1e-6, "{steps}");
            sum_in += s.dtheta.x;
            sum_out += y.dtheta.x;
        }
        assert!((sum_in - sum_out).abs() <= 0.5 * q + 1e-12);
    }

    /// Vibration integrates exactly: over a whole number of periods the lines add
    /// nothing to the velocity.
    #[test]
    fn vibration_integrates_to_zero_over_periods() {
        let mut m = ImuModel::default();
        m.vibration.push(VibrationLine {
            freq_hz: 20.0,
            amplitude: Vector3::new(0.5, 0.0, 1.0),
            phase: 0.3,
        });
        let mut sim = ImuSimulator::new(m, 1);
        let mut sum = Vector3::zeros();
        for k in 1..=200 {
            let s = ImuSample {
                dvel: Vector3::zeros(),
                ..sample(k as f64 * 0.005, 0.005)
            };
            sum += sim.measure(&s).dvel;
        }
        assert!(sum.norm() < 1e-14, "{sum}");
    }
}
