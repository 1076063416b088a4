//! Rest detection on a stream of IMU samples, for zero-velocity updates: the motion
//! detector of [`super::prefilter`] run on a sliding window of blocks, plus the two
//! tests of a body at rest that the alignment's detector need not make.
//!
//! The samples are summed into blocks of `block` seconds ([`BlockSums`]); at the end of
//! each block the window of the last `window` blocks (length `T`) is at rest when
//!
//! 1. the motion detector sees neither angular motion (block-mean rates scattering
//!    beyond `3 N_g/√T_block`) nor vibration (samples scattering beyond `3 N_a/√dt`)
//!    ([`motion_of_blocks`]), nor do the block-mean specific forces scatter beyond
//!    `3 N_a/√T_block` (a changing acceleration);
//! 2. the mean specific force is gravity's: with only its magnitude known,
//!    `| |f̄| − g | ≤ 3 (N_a/√T + σ_ba)`, with the velocity random walk `N_a` and the
//!    accelerometer bias's standard deviation `σ_ba` (the samples are raw or only
//!    partly compensated); with the navigation's attitude, the whole vector,
//!    `|f̄ − f_rest| ≤ 3 (N_a/√T + σ_ba) + g σ_tilt`, `f_rest = −C_bn g^n`;
//! 3. the mean rate is the Earth's: `|ω̄| ≤ Ω + 3 (N_g/√T + σ_bg)`.
//!
//! Like every IMU-only detector (Skog et al. 2010, IEEE TBME 57(11), "zero-velocity
//! detection — an algorithm evaluation"), it cannot tell rest from motion at constant
//! velocity without vibration: a simulated vehicle on a straight road at constant
//! speed passes all three tests. Nor, from the magnitude alone, a steady horizontal
//! acceleration `a` from a tilt: it changes `|f|` by only `a²/2g` (the attitude's
//! vector test sees `a` itself). Real vehicles vibrate when they move; otherwise the
//! caller must rule these out by other means (the navigation's own speed, the
//! innovation gate).

use super::prefilter::{BlockSums, motion_of_blocks};
use crate::filter::ImuNoise;
use crate::imu::ImuSample;
use nalgebra::Vector3;

/// Multiple of the noise a rest window may show (as [`super::prefilter::MOTION_FACTOR`]).
const FACTOR: f64 = super::prefilter::MOTION_FACTOR;

/// What the caller knows of the specific force a body at rest feels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gravity {
    /// Gravity's magnitude [m/s^2] (no attitude): the test is on `|f̄|`.
    Magnitude(f64),
    /// The specific force at rest in body axes, `−C_bn g^n` [m/s^2], from the
    /// navigation's attitude, and the attitude's tilt uncertainty [rad]: the test is
    /// on the vector.
    Body(Vector3<f64>, f64),
}

/// What the detector says at the end of a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestVerdict {
    /// Time of the block's end [s].
    pub t: f64,
    /// Whether the window ending here is at rest.
    pub rest: bool,
    /// The block that just ended.
    pub block: BlockSums,
}

/// The streaming rest detector (see the module doc).
#[derive(Debug, Clone)]
pub struct RestDetector {
    block: f64,
    window: usize,
    blocks: Vec<BlockSums>,
    current: BlockSums,
    arw: Vector3<f64>,
    vrw: Vector3<f64>,
    gyro_bias: f64,
    accel_bias: f64,
    last_t: f64,
}

impl RestDetector {
    /// A detector for an IMU with noise model `noise`, blocks of `block` seconds and a
    /// window of `window` blocks (at least 2: the angular-motion test compares
    /// blocks).
    pub fn new(noise: &ImuNoise, block: f64, window: usize) -> Self {
        let window = window.max(2);
        Self {
            block,
            window,
            blocks: Vec::with_capacity(window),
            current: BlockSums::default(),
            arw: noise.arw,
            vrw: noise.vrw,
            gyro_bias: noise.gyro_bias.norm(),
            accel_bias: noise.accel_bias.norm(),
            last_t: f64::NAN,
        }
    }

    /// Add a sample; true when it ends a block (within half a sample of `block`
    /// seconds), whose verdict [`RestDetector::verdict`] then gives. Allocation-free.
    pub fn push(&mut self, s: &ImuSample) -> bool {
        if s.dt <= 0.0 {
            return false;
        }
        self.current.add(s);
        if self.current.t < self.block - 0.5 * s.dt {
            return false;
        }
        if self.blocks.len() == self.window {
            self.blocks.remove(0);
        }
        self.blocks.push(std::mem::take(&mut self.current));
        self.last_t = s.t;
        true
    }

    /// The verdict on the window ending with the last block, with `gravity` as known
    /// now and the Earth rate `earth_rate` [rad/s]. Allocation-free.
    pub fn verdict(&self, gravity: Gravity, earth_rate: f64) -> RestVerdict {
        RestVerdict {
            t: self.last_t,
            rest: self.blocks.len() == self.window && self.at_rest(gravity, earth_rate),
            block: self.blocks.last().copied().unwrap_or_default(),
        }
    }

    /// [`RestDetector::push`], and at the end of a block its verdict.
    pub fn add(&mut self, s: &ImuSample, gravity: Gravity, earth_rate: f64) -> Option<RestVerdict> {
        self.push(s).then(|| self.verdict(gravity, earth_rate))
    }

    fn at_rest(&self, gravity: Gravity, earth_rate: f64) -> bool {
        let motion = motion_of_blocks(&self.blocks, &self.arw, &self.vrw);
        if motion.angular_motion || motion.vibration {
            return false;
        }
        let (mut t, mut dtheta, mut dvel) = (0.0, Vector3::zeros(), Vector3::zeros());
        for b in &self.blocks {
            t += b.t;
            dtheta += b.dtheta;
            dvel += b.dvel;
        }
        let t_block = t / self.blocks.len() as f64;
        let steady = (0..3).all(|i| {
            motion.accel_block_scatter[i]
                <= FACTOR * self.vrw[i].max(f64::MIN_POSITIVE) / t_block.sqrt()
        });
        let sqrt_t = t.sqrt();
        let allowance = FACTOR * (self.vrw.max() / sqrt_t + self.accel_bias);
        let f = dvel / t;
        let force_ok = match gravity {
            Gravity::Magnitude(g) => (f.norm() - g).abs() <= allowance,
            Gravity::Body(f_rest, tilt) => (f - f_rest).norm() <= allowance + f_rest.norm() * tilt,
        };
        let rate_ok =
            (dtheta / t).norm() <= earth_rate + FACTOR * (self.arw.max() / sqrt_t + self.gyro_bias);
        steady && force_ok && rate_ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::imu::random::Noise;

    fn noise() -> ImuNoise {
        // Consumer-MEMS-like: 0.5 deg/sqrt(h), 0.2 m/s/sqrt(h), 10 deg/h, 5 mg.
        let mut n = ImuNoise::from_model(&Default::default());
        n.arw = Vector3::repeat(0.5f64.to_radians() / 60.0);
        n.vrw = Vector3::repeat(0.2 / 60.0);
        n.gyro_bias = Vector3::repeat(10f64.to_radians() / 3600.0);
        n.accel_bias = Vector3::repeat(5e-3 * 9.81);
        n
    }

    /// Samples at 100 Hz with white noise of the model's densities on `w` and `f`.
    fn samples(
        n: usize,
        w: impl Fn(f64) -> Vector3<f64>,
        f: impl Fn(f64) -> Vector3<f64>,
    ) -> Vec<ImuSample> {
        let (dt, nz) = (0.01, noise());
        let mut rng = Noise::new(5, 9);
        let mut g = || Vector3::new(rng.normal(), rng.normal(), rng.normal());
        (1..=n)
            .map(|k| {
                let t = k as f64 * dt;
                ImuSample {
                    t,
                    dt,
                    dtheta: w(t) * dt + nz.arw.component_mul(&g()) * dt.sqrt(),
                    dvel: f(t) * dt + nz.vrw.component_mul(&g()) * dt.sqrt(),
                }
            })
            .collect()
    }

    fn verdicts(s: &[ImuSample]) -> Vec<RestVerdict> {
        let mut d = RestDetector::new(&noise(), 0.1, 10);
        s.iter()
            .filter_map(|s| d.add(s, Gravity::Magnitude(9.81), 7.292e-5))
            .collect()
    }

    #[test]
    fn rest_is_found_once_the_window_fills_and_motion_is_not_rest() {
        let still = samples(
            1000,
            |_| Vector3::new(3e-5, 0.0, -5e-5),
            |_| Vector3::new(0.02, -0.01, -9.81),
        );
        let v = verdicts(&still);
        // A block every 0.1 s; the first nine have no full window.
        assert_eq!(v.len(), 100);
        assert!(v[..9].iter().all(|v| !v.rest));
        assert!(v[9..].iter().all(|v| v.rest));
        assert!((v[9].t - 1.0).abs() < 1e-9 && v[9].block.n == 10);
        // A vertical acceleration of 0.5 m/s² changes |f| by twice the allowance
        // 3 (N_a/√T + σ_ba) = 0.26 m/s²: never rest.
        let lift = samples(
            1000,
            |_| Vector3::zeros(),
            |_| Vector3::new(0.0, 0.0, -9.81 - 0.5),
        );
        assert!(verdicts(&lift).iter().all(|v| !v.rest));
        // Braking that varies (0.3 m/s² at 0.3 Hz about 0.3 m/s²): the block means
        // scatter by ~0.2 m/s², far above 3 N_a/√0.1 s = 0.03 m/s².
        let braking = samples(
            1000,
            |_| Vector3::zeros(),
            |t| {
                Vector3::new(
                    -0.3 - 0.3 * (0.6 * std::f64::consts::PI * t).sin(),
                    0.0,
                    -9.81,
                )
            },
        );
        assert!(verdicts(&braking).iter().all(|v| !v.rest));
        // A steady horizontal acceleration is a tilt to the accelerometers (the
        // module doc): 0.5 m/s² changes |f| by 0.013 m/s² only...
        let steady = samples(
            1000,
            |_| Vector3::zeros(),
            |_| Vector3::new(-0.5, 0.0, -9.81),
        );
        assert!(verdicts(&steady)[9..].iter().all(|v| v.rest));
        // ... but not with the attitude (level, known to 1 mrad): 0.5 m/s² against an
        // allowance of 0.26 + 0.01 m/s².
        let mut d = RestDetector::new(&noise(), 0.1, 10);
        let level = Gravity::Body(Vector3::new(0.0, 0.0, -9.81), 1e-3);
        assert!(
            steady
                .iter()
                .filter_map(|s| d.add(s, level, 7.292e-5))
                .all(|v| !v.rest)
        );
        let mut d = RestDetector::new(&noise(), 0.1, 10);
        let v: Vec<RestVerdict> = still
            .iter()
            .filter_map(|s| d.add(s, level, 7.292e-5))
            .collect();
        assert!(v[9..].iter().all(|v| v.rest));
        // Turning at 1 deg/s: never rest.
        let turning = samples(
            1000,
            |_| Vector3::new(0.0, 0.0, 1f64.to_radians()),
            |_| Vector3::new(0.0, 0.0, -9.81),
        );
        assert!(verdicts(&turning).iter().all(|v| !v.rest));
        // Rocking (±2 deg/s at 0.5 Hz): the rates average out over the window, the
        // block scatter does not.
        let rocking = samples(
            1000,
            |t| {
                Vector3::new(
                    2f64.to_radians() * (std::f64::consts::PI * t).sin(),
                    0.0,
                    0.0,
                )
            },
            |_| Vector3::new(0.0, 0.0, -9.81),
        );
        assert!(verdicts(&rocking).iter().all(|v| !v.rest));
    }
}
