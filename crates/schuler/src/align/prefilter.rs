//! Pre-filtering of raw increments before alignment: robust spike rejection and the
//! motion detector.
//!
//! Spikes: the samples are cut into blocks (the averaging window); in each block and
//! for each of the six channels, a sample farther than `k` robust deviations from the
//! block median is a spike, and is replaced by the median (the block's sum then
//! stays what the sensor measured apart from the spike). The robust deviation is
//! `max(1.4826 MAD, 1.2533 mean|x − median|)`: both equal σ for Gaussian noise; the
//! second and the repeated-step floor (`repeated_step`) keep quantized channels
//! (MAD = 0) from flagging every quantum step. A
//! sinusoidal vibration of amplitude `A` has a deviation ≈ `A/√2 · 1.05`, so a line
//! never crosses `k ≥ 2`.
//!
//! Motion: with the sensor noise known, the block means of a base at rest scatter
//! by `N/√T` (white noise density `N`, block length `T`) about their mean; angular
//! motion (rocking) scatters them more. Within a block, the samples scatter by
//! `N/√dt`; vibration scatters them more.

use crate::imu::ImuSample;
use nalgebra::Vector3;

/// A sample replaced because one of its channels was a spike.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spike {
    /// Sample time [s].
    pub t: f64,
    /// Channel: 0–2 gyro x, y, z; 3–5 accelerometer x, y, z.
    pub channel: usize,
    /// Deviation from the block median in robust standard deviations.
    pub sigmas: f64,
}

/// Replace spikes in place, block by block (`block` samples each); returns them.
pub fn reject_spikes(samples: &mut [ImuSample], block: usize, k: f64) -> Vec<Spike> {
    let mut spikes = Vec::new();
    let mut buf = Vec::with_capacity(block);
    for chunk in samples.chunks_mut(block.max(1)) {
        if chunk.len() < 5 {
            continue;
        }
        for channel in 0..6 {
            let get = |s: &ImuSample| {
                if channel < 3 {
                    s.dtheta[channel]
                } else {
                    s.dvel[channel - 3]
                }
            };
            buf.clear();
            buf.extend(chunk.iter().map(get));
            let median = median_in_place(&mut buf);
            let mean_abs = buf.iter().map(|x| (x - median).abs()).sum::<f64>() / buf.len() as f64;
            for x in buf.iter_mut() {
                *x = (*x - median).abs();
            }
            let mad = median_in_place(&mut buf);
            let mut scale = (1.4826 * mad).max(1.2533 * mean_abs);
            if mad == 0.0 {
                scale = scale.max(repeated_step(&mut buf));
            }
            if scale <= 0.0 {
                continue;
            }
            for s in chunk.iter_mut() {
                let dev = (get(s) - median).abs() / scale;
                if dev > k {
                    spikes.push(Spike {
                        t: s.t,
                        channel,
                        sigmas: dev,
                    });
                    if channel < 3 {
                        s.dtheta[channel] = median;
                    } else {
                        s.dvel[channel - 3] = median;
                    }
                }
            }
        }
    }
    spikes.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.channel.cmp(&b.channel)));
    spikes
}

/// The smallest nonzero deviation that occurs at least twice: the quantization step
/// of a channel that mostly sits on one value (a lone spike occurs once).
fn repeated_step(dev: &mut [f64]) -> f64 {
    dev.sort_unstable_by(f64::total_cmp);
    dev.windows(2)
        .find(|w| w[0] > 0.0 && (w[1] - w[0]) <= 1e-9 * w[1])
        .map_or(0.0, |w| w[0])
}

/// Median of a slice (reordered; mean of the two middle values for even lengths).
fn median_in_place(v: &mut [f64]) -> f64 {
    let n = v.len();
    let mid = n / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    let upper = *m;
    if n % 2 == 1 {
        upper
    } else {
        let lower = v[..mid].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lower + upper)
    }
}

/// What the motion detector saw, relative to the sensor noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionReport {
    /// RMS scatter of the gyro block means about their mean, per axis [rad/s].
    pub gyro_block_scatter: Vector3<f64>,
    /// The same expected from the angle random walk alone [rad/s].
    pub gyro_block_noise: Vector3<f64>,
    /// RMS scatter of the accelerometer samples within blocks, per axis [m/s^2].
    pub accel_sample_scatter: Vector3<f64>,
    /// The same expected from the velocity random walk alone [m/s^2].
    pub accel_sample_noise: Vector3<f64>,
    /// RMS scatter of the accelerometer block means [m/s^2].
    pub accel_block_scatter: Vector3<f64>,
    /// RMS of the angle the gyro block means integrate to about their mean [rad]
    /// (how far the base turns back and forth).
    pub attitude_wander: Vector3<f64>,
    /// RMS of the velocity the accelerometer block means integrate to about their
    /// mean [m/s].
    pub velocity_wander: Vector3<f64>,
    /// Angular motion beyond the noise (rocking, handling).
    pub angular_motion: bool,
    /// Vibration beyond the noise (within-block accelerometer scatter).
    pub vibration: bool,
}

/// Scatter above this multiple of the noise-only value counts as motion (for
/// Gaussian noise, the sample RMS of hundreds of blocks exceeds its expectation by
/// 3× with negligible probability).
pub const MOTION_FACTOR: f64 = 3.0;

/// Sums over one block of samples: what the motion detector needs of it, gathered
/// in one pass (Welford's update for the scatter), so a detector can run on a stream.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BlockSums {
    /// Samples.
    pub n: usize,
    /// `Σ dt` [s].
    pub t: f64,
    /// `Σ dθ` [rad].
    pub dtheta: Vector3<f64>,
    /// `Σ dv` [m/s].
    pub dvel: Vector3<f64>,
    /// Running mean of the samples' specific force `dv/dt` [m/s^2].
    mean_f: Vector3<f64>,
    /// `Σ (dv/dt − mean_f)²` [m²/s⁴].
    m2_f: Vector3<f64>,
}

impl BlockSums {
    /// Add one sample.
    pub fn add(&mut self, s: &ImuSample) {
        self.n += 1;
        self.t += s.dt;
        self.dtheta += s.dtheta;
        self.dvel += s.dvel;
        let f = s.dvel / s.dt;
        let d = f - self.mean_f;
        self.mean_f += d / self.n as f64;
        self.m2_f += d.component_mul(&(f - self.mean_f));
    }

    /// Mean angular rate `Σ dθ / Σ dt` [rad/s].
    pub fn rate(&self) -> Vector3<f64> {
        self.dtheta / self.t
    }

    /// Mean specific force `Σ dv / Σ dt` [m/s^2].
    pub fn force(&self) -> Vector3<f64> {
        self.dvel / self.t
    }

    /// `Σ (dv/dt − a)²` about the block's mean force `a` (`Σ (f − f̄)² + n (f̄ − a)²`).
    fn scatter_about_force(&self) -> Vector3<f64> {
        let d = self.mean_f - self.force();
        self.m2_f + d.component_mul(&d) * self.n as f64
    }
}

/// Analyse the blocks of a (spike-free) stationary record.
pub fn detect_motion(
    samples: &[ImuSample],
    block: usize,
    arw: &Vector3<f64>,
    vrw: &Vector3<f64>,
) -> MotionReport {
    let blocks: Vec<BlockSums> = samples
        .chunks_exact(block.max(1))
        .map(|chunk| {
            let mut b = BlockSums::default();
            chunk.iter().for_each(|s| b.add(s));
            b
        })
        .collect();
    motion_of_blocks(&blocks, arw, vrw)
}

/// The motion detector on blocks already summed (see the module doc).
pub fn motion_of_blocks(
    blocks: &[BlockSums],
    arw: &Vector3<f64>,
    vrw: &Vector3<f64>,
) -> MotionReport {
    let nb = blocks.len().max(1) as f64;
    let mean_of =
        |m: &dyn Fn(&BlockSums) -> Vector3<f64>| blocks.iter().map(m).sum::<Vector3<f64>>() / nb;
    let scatter = |m: &dyn Fn(&BlockSums) -> Vector3<f64>| {
        let mean = mean_of(m);
        (blocks
            .iter()
            .map(|b| (m(b) - mean).component_mul(&(m(b) - mean)))
            .sum::<Vector3<f64>>()
            / nb)
            .map(f64::sqrt)
    };
    let block_t = blocks.iter().map(|b| b.t).sum::<f64>();
    let samples = blocks.iter().map(|b| b.n).sum::<usize>();
    let t_block = block_t / nb;
    let wander = |m: &dyn Fn(&BlockSums) -> Vector3<f64>| {
        let mean = mean_of(m);
        let mut sum = Vector3::zeros();
        let mut sq = Vector3::zeros();
        for b in blocks {
            sum += (m(b) - mean) * t_block;
            sq += sum.component_mul(&sum);
        }
        (sq / nb).map(f64::sqrt)
    };
    let within: Vector3<f64> = blocks.iter().map(BlockSums::scatter_about_force).sum();
    let dt = if samples > 0 {
        block_t / samples as f64
    } else {
        1.0
    };
    let gyro_block_scatter = scatter(&BlockSums::rate);
    let gyro_block_noise = arw / t_block.max(f64::MIN_POSITIVE).sqrt();
    let accel_sample_scatter = (within / samples.max(1) as f64).map(f64::sqrt);
    let accel_sample_noise = vrw / dt.sqrt();
    let exceeds = |x: &Vector3<f64>, n: &Vector3<f64>| {
        (0..3).any(|i| x[i] > MOTION_FACTOR * n[i].max(f64::MIN_POSITIVE))
    };
    MotionReport {
        gyro_block_scatter,
        gyro_block_noise,
        accel_sample_scatter,
        accel_sample_noise,
        accel_block_scatter: scatter(&BlockSums::force),
        attitude_wander: wander(&BlockSums::rate),
        velocity_wander: wander(&BlockSums::force),
        angular_motion: blocks.len() >= 2 && exceeds(&gyro_block_scatter, &gyro_block_noise),
        vibration: exceeds(&accel_sample_scatter, &accel_sample_noise),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, w: f64, f: f64) -> ImuSample {
        ImuSample::from_mean_rates(t, 0.01, Vector3::repeat(w), Vector3::repeat(f))
    }

    #[test]
    fn isolated_spikes_are_replaced_by_the_median_and_listed() {
        // Deterministic "noise": a sawtooth of ±1e-6 about the level.
        let mut v: Vec<ImuSample> = (0..1000)
            .map(|i| sample(i as f64 * 0.01, 1e-3 + 1e-6 * ((i % 7) as f64 - 3.0), 9.8))
            .collect();
        v[123].dtheta.y += 0.5;
        v[124].dvel.z -= 3.0;
        let spikes = reject_spikes(&mut v, 100, 8.0);
        assert_eq!(spikes.len(), 2);
        assert_eq!((spikes[0].channel, spikes[1].channel), (1, 5));
        assert!((v[123].dtheta.y - 1e-5).abs() < 1e-12);
        assert!((v[124].dvel.z - 0.098).abs() < 1e-12);
    }

    #[test]
    fn quantized_constant_channels_raise_no_alarm() {
        let mut v: Vec<ImuSample> = (0..1000)
            .map(|i| {
                sample(
                    i as f64 * 0.01,
                    if i % 50 == 0 { 1.1e-3 } else { 1e-3 },
                    9.8,
                )
            })
            .collect();
        assert!(reject_spikes(&mut v, 100, 8.0).is_empty());
    }

    #[test]
    fn a_base_at_rest_without_noise_shows_no_motion_and_a_rocking_one_does() {
        let still: Vec<ImuSample> = (0..2000)
            .map(|i| sample(i as f64 * 0.01, 1e-4, 9.8))
            .collect();
        let n = Vector3::repeat(1e-6);
        let r = detect_motion(&still, 100, &n, &n);
        assert!(!r.angular_motion && !r.vibration);
        let rocking: Vec<ImuSample> = (0..2000)
            .map(|i| {
                let t = i as f64 * 0.01;
                sample(t, 1e-4 + 1e-3 * (0.3 * t).sin(), 9.8)
            })
            .collect();
        assert!(detect_motion(&rocking, 100, &n, &n).angular_motion);
    }
}
