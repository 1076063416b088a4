//! Reproducible random numbers: ChaCha8 streams seeded from (master seed, stream id)
//! through SplitMix64, and our own normal sampler, so the same seed gives the same bits
//! whatever version of `rand_distr` is around (ECOSYSTEM.md, reproducibility).

use rand::{RngExt, SeedableRng, rngs::ChaCha8Rng};

/// SplitMix64 (Steele, Lea & Flood 2014): a seed mixer whose successive outputs are
/// well-distributed 64-bit values.
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A stream of uniform and normal variates, independent for each `(seed, stream)`.
#[derive(Debug)]
pub struct Noise {
    rng: ChaCha8Rng,
    spare: Option<f64>,
}

impl Noise {
    /// The stream `stream` of master seed `seed`.
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut s = seed ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03);
        let mut key = [0u8; 32];
        for chunk in key.chunks_exact_mut(8) {
            chunk.copy_from_slice(&splitmix64(&mut s).to_le_bytes());
        }
        Self {
            rng: ChaCha8Rng::from_seed(key),
            spare: None,
        }
    }

    /// Uniform on (0, 1): 53 random bits, never exactly 0.
    pub fn uniform(&mut self) -> f64 {
        let bits: u64 = self.rng.random();
        ((bits >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal by the Box–Muller transform (pairs; the second is kept).
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64's published first outputs for seed 1234567 (the reference C code of
    /// Vigna's xoshiro page): 6457827717110365317, 3203168211198807973.
    #[test]
    fn splitmix_reference_values() {
        let mut s = 1_234_567u64;
        assert_eq!(splitmix64(&mut s), 6_457_827_717_110_365_317);
        assert_eq!(splitmix64(&mut s), 3_203_168_211_198_807_973);
    }

    /// Same seed and stream, same bits; another stream, other bits.
    #[test]
    fn reproducible_and_independent() {
        let a: Vec<f64> = (0..5)
            .map({
                let mut n = Noise::new(42, 1);
                move |_| n.normal()
            })
            .collect();
        let b: Vec<f64> = (0..5)
            .map({
                let mut n = Noise::new(42, 1);
                move |_| n.normal()
            })
            .collect();
        let c: Vec<f64> = (0..5)
            .map({
                let mut n = Noise::new(42, 2);
                move |_| n.normal()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    /// Moments of 200,000 normals: mean within 4 sigma of 0 (4/sqrt(n) = 0.009),
    /// variance within 4 sigma of 1 (4 sqrt(2/n) = 0.013), and kurtosis near 3.
    #[test]
    fn normal_moments() {
        let mut n = Noise::new(7, 0);
        let xs: Vec<f64> = (0..200_000).map(|_| n.normal()).collect();
        let m = xs.iter().sum::<f64>() / xs.len() as f64;
        let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / xs.len() as f64;
        let k = xs.iter().map(|x| (x - m).powi(4)).sum::<f64>() / xs.len() as f64 / (v * v);
        assert!(m.abs() < 0.009, "{m}");
        assert!((v - 1.0).abs() < 0.013, "{v}");
        assert!((k - 3.0).abs() < 0.05, "{k}");
    }
}
