//! Reproducible random numbers: ChaCha8 streams seeded from (master seed, stream id)
//! through SplitMix64, and our own normal sampler, so the same seed gives the same bits
//! whatever version of `rand_distr` is around (ECOSYSTEM.md, reproducibility).

use rand::{Rng, SeedableRng, rngs::ChaCha8Rng};

/// SplitMix64 (Steele, Lea & Flood 2014): a seed mixer whose successive outputs are
/// well-distributed 64-bit values.
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// 64-bit words drawn from the generator at a time ([`Noise::bits`]).
const WORDS: usize = 32;

/// A stream of uniform and normal variates, independent for each `(seed, stream)`.
#[derive(Debug)]
pub struct Noise {
    rng: ChaCha8Rng,
    /// The generator's next words, taken in order: the same sequence as its `next_u64`
    /// gives (both read its 32-bit output little-endian, in order), without the
    /// per-call bookkeeping of its block buffer (a sixth of a normal variate's cost).
    words: [u64; WORDS],
    /// Index of the next unused word (`WORDS`: none left).
    next: usize,
    spare: Option<f64>,
    /// The ziggurat's layer edges, looked up once.
    edges: &'static [f64; ZIG_LAYERS + 1],
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
            words: [0; WORDS],
            next: WORDS,
            spare: None,
            edges: ziggurat_edges(),
        }
    }

    /// The next 64 random bits.
    #[inline(always)]
    fn bits(&mut self) -> u64 {
        if self.next >= WORDS {
            self.refill();
        }
        let w = self.words[self.next];
        self.next += 1;
        w
    }

    /// The generator's next [`WORDS`] words into `words` (one of its 256-byte blocks).
    #[cold]
    #[inline(never)]
    fn refill(&mut self) {
        let mut bytes = [0u8; 8 * WORDS];
        self.rng.fill_bytes(&mut bytes);
        for (w, b) in self.words.iter_mut().zip(bytes.chunks_exact(8)) {
            *w = u64::from_le_bytes(b.try_into().expect("8 bytes"));
        }
        self.next = 0;
    }

    /// Uniform on (0, 1): 53 random bits, never exactly 0.
    pub fn uniform(&mut self) -> f64 {
        let bits = self.bits();
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

/// Layers of the ziggurat ([`Noise::normal_ziggurat`]).
const ZIG_LAYERS: usize = 256;
/// Right edge of the base layer (Marsaglia & Tsang 2000, 256 layers).
const ZIG_R: f64 = 3.654_152_885_361_009;
/// Area of each layer, base layer's tail included (Marsaglia & Tsang 2000).
const ZIG_V: f64 = 4.928_673_233_99e-3;

/// The ziggurat's layer edges `x[0..=256]` for the density `f(x) = exp(-x²/2)`:
/// `x[0] = V/f(r)` (the base layer as a rectangle of area V), `x[1] = r`,
/// `x[i+1] = f⁻¹(V/x[i] + f(x[i]))`, `x[256] = 0`.
fn ziggurat_edges() -> &'static [f64; ZIG_LAYERS + 1] {
    static EDGES: std::sync::OnceLock<[f64; ZIG_LAYERS + 1]> = std::sync::OnceLock::new();
    EDGES.get_or_init(|| {
        let f = |x: f64| (-0.5 * x * x).exp();
        let mut x = [0.0; ZIG_LAYERS + 1];
        x[0] = ZIG_V / f(ZIG_R);
        x[1] = ZIG_R;
        for i in 1..ZIG_LAYERS - 1 {
            x[i + 1] = (-2.0 * (ZIG_V / x[i] + f(x[i])).ln()).sqrt();
        }
        x[ZIG_LAYERS] = 0.0;
        x
    })
}

impl Noise {
    /// Standard normal by the ziggurat method (Marsaglia & Tsang 2000, 256 layers, in
    /// Doornik's 2005 form with a signed uniform): one 64-bit draw per variate for 99 %
    /// of them (8 bits pick the layer, 53 others the abscissa), no logarithm or
    /// trigonometry; the rare wedge and tail cases draw more. Several times faster than
    /// [`Noise::normal`], for the per-sample sensor noise; another sequence of variates
    /// from the same stream.
    #[inline]
    pub fn normal_ziggurat(&mut self) -> f64 {
        let x = self.edges;
        let bits = self.bits();
        let i = (bits & 0xff) as usize;
        // Signed uniform in (-1, 1) from the top 53 bits, never 0.
        let u = ((bits >> 11) as f64 + 0.5) * (2.0 / (1u64 << 53) as f64) - 1.0;
        let z = u * x[i];
        if z.abs() < x[i + 1] {
            return z;
        }
        self.normal_ziggurat_edge(i, u, z)
    }

    /// [`Noise::normal_ziggurat`] past the rectangle of layer `i` (1 % of the draws):
    /// the tail or the wedge, then again from the start if refused.
    #[cold]
    #[inline(never)]
    fn normal_ziggurat_edge(&mut self, i: usize, u: f64, z: f64) -> f64 {
        let x = self.edges;
        if i == 0 {
            // The tail beyond r (Marsaglia 1964): x = -ln(U1)/r, y = -ln(U2),
            // accepted when 2y > x².
            loop {
                let t = -self.uniform().ln() / ZIG_R;
                let y = -self.uniform().ln();
                if 2.0 * y > t * t {
                    return if u < 0.0 { -(ZIG_R + t) } else { ZIG_R + t };
                }
            }
        }
        // Wedge between the layer's rectangle and the density.
        let f0 = (-0.5 * (x[i] * x[i] - z * z)).exp();
        let f1 = (-0.5 * (x[i + 1] * x[i + 1] - z * z)).exp();
        if f1 + self.uniform() * (f0 - f1) < 1.0 {
            return z;
        }
        self.normal_ziggurat()
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

    /// The buffered words are the generator's own `next_u64` sequence (so the streams
    /// are those of the unbuffered generator), across refills.
    #[test]
    fn buffered_words_are_the_generators_sequence() {
        let mut n = Noise::new(42, 3);
        let mut direct = Noise::new(42, 3).rng;
        for _ in 0..3 * WORDS + 5 {
            assert_eq!(n.bits(), direct.next_u64());
        }
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

    /// The ziggurat's layers: each has area V, the base one (rectangle r f(r) plus the
    /// tail beyond r) too, and the top one closes at the mode: x[255] (1 - f(x[255]))
    /// = V to 1e-9 relative, the precision of the published V (12 digits).
    #[test]
    fn ziggurat_layers_have_equal_areas() {
        let x = ziggurat_edges();
        let f = |x: f64| (-0.5 * x * x).exp();
        for i in 1..ZIG_LAYERS - 1 {
            let area = x[i] * (f(x[i + 1]) - f(x[i]));
            assert!((area - ZIG_V).abs() < 1e-15, "layer {i}: {area}");
        }
        let top = x[ZIG_LAYERS - 1] * (1.0 - f(x[ZIG_LAYERS - 1]));
        assert!((top - ZIG_V).abs() < 2e-9 * ZIG_V, "top layer {top}");
        // The tail integral by Simpson's rule on [r, r + 10] (f(r + 10) ~ 1e-37).
        let (n, h) = (20_000, 10.0 / 20_000.0);
        let tail = (0..=n)
            .map(|k| {
                let w = if k == 0 || k == n {
                    1.0
                } else {
                    [2.0, 4.0][k % 2]
                };
                w * f(ZIG_R + k as f64 * h)
            })
            .sum::<f64>()
            * h
            / 3.0;
        let base = ZIG_R * f(ZIG_R) + tail;
        assert!((base - ZIG_V).abs() < 2e-9 * ZIG_V, "base layer {base}");
    }

    /// Moments of 400,000 ziggurat normals as for Box–Muller below, the tail
    /// probability P(|z| > 3) = 0.0026998 within 4 sigma (1.0e-4), and the fraction
    /// beyond the ziggurat's edge r = 3.654 (2.58e-4) within 4 sigma (1.0e-4).
    #[test]
    fn ziggurat_moments_and_tails() {
        let mut n = Noise::new(11, 0);
        let xs: Vec<f64> = (0..400_000).map(|_| n.normal_ziggurat()).collect();
        let len = xs.len() as f64;
        let m = xs.iter().sum::<f64>() / len;
        let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / len;
        let k = xs.iter().map(|x| (x - m).powi(4)).sum::<f64>() / len / (v * v);
        assert!(m.abs() < 0.0064, "{m}");
        assert!((v - 1.0).abs() < 0.009, "{v}");
        assert!((k - 3.0).abs() < 0.04, "{k}");
        let beyond = |a: f64| xs.iter().filter(|x| x.abs() > a).count() as f64 / len;
        assert!(
            (beyond(3.0) - 0.002_699_8).abs() < 1.0e-4,
            "{}",
            beyond(3.0)
        );
        assert!(
            (beyond(ZIG_R) - 2.58e-4).abs() < 1.0e-4,
            "{}",
            beyond(ZIG_R)
        );
        assert!(xs.iter().any(|x| x.abs() > ZIG_R), "the tail is sampled");
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
