//! The spectra of the noise terms and what they make of overlapping Allan variance
//! estimates: the expected value at one cluster size, and the covariance between
//! cluster sizes (which the fit needs: estimates at neighbouring `τ` share their data
//! and are strongly correlated).
//!
//! The rate samples `y_k` (increments over `dt` divided by `dt`) of a term with
//! coefficient `v` have the two-sided discrete-time spectrum `v² P(ω)`, `ω` in rad per
//! sample, `R_y(ℓ) = (1/2π) ∫_{−π}^{π} P(ω) e^{iωℓ} dω`:
//!
//! | term | `P(ω)` per unit `v²` | |
//! |---|---|---|
//! | quantization `Q` | `4 sin²(ω/2) / dt²` | white angle error of variance `Q²` (IEEE 952: `σ² = 3Q²/τ²`) |
//! | white rate `N` | `1 / dt` | samples of variance `N²/dt` (`σ² = N²/τ`) |
//! | bias instability `B` | `1 / |ω|` | IEEE 952's `S(f) = B²/(2π f)` sampled (`σ² → (2 ln 2/π) B²`) |
//! | rate random walk `K` | `dt / (4 sin²(ω/2))` | steps of variance `K² dt` (`σ² ≈ K² τ/3`) |
//! | Gauss–Markov `σ`, `T` | `(1 − φ²) / ((1 − φ)² + 4φ sin²(ω/2))`, `φ = e^{−dt/T}` | the simulator's AR(1) bias |
//! | ramp `R` | 0 | deterministic |
//!
//! With the second-difference kernel of cluster size `m`, `|W_m(ω)|² = 4 sin⁴(mω/2) /
//! sin²(ω/2)`, a Gaussian process gives (Parseval; the number of overlapping terms
//! `M = N + 1 − 2m` large against the kernels' memory):
//!
//! - `E σ̂²(m) = (1/(2m²)) (1/2π) ∫ P |W_m|² dω`;
//! - `cov(σ̂²(a), σ̂²(b)) = (1/(2 a² b² max(M_a, M_b))) (1/2π) ∫ P² |W_a|² |W_b|² dω`
//!   (from `cov(d², e²) = 2 cov(d, e)²` for jointly Gaussian second differences).
//!
//! For white rate, quantization and rate random walk the integrands are trigonometric
//! polynomials of degree below `2(a + b) + 1`, so the mean over that many equally
//! spaced frequencies is the integral exactly; the bias instability's `1/|ω|` and the
//! Gauss–Markov peak (width `dt/T`) are sampled 2 and 8 times more finely (errors
//! below 1.5 % and 3 % against a 32 times finer grid, tests). For white rate the
//! variance gives `ν = 2σ⁴/var = 1.5 (N − 2m)/m · 4m²/(4m² + 5)`, Greenhall's (2004)
//! long-record value with Howe, Allan & Barnes's short-cluster factor.

use super::AllanPoint;
use super::fit::Term;
use nalgebra::DMatrix;

/// Grid refinement for a bias instability's `1/|ω|`.
const REFINE_FLICKER: usize = 2;
/// Grid refinement for a Gauss–Markov peak.
const REFINE_GAUSS_MARKOV: usize = 8;

/// The spectrum of a sum of terms (module table), ready to evaluate:
/// `P(ω) = q s² + w + f/ω + r/s² + g_num/(g_a + g_b s²)`, `s = sin(ω/2)`.
#[derive(Debug, Clone)]
pub struct Spectrum {
    q: f64,
    w: f64,
    f: f64,
    r: f64,
    g_num: f64,
    g_a: f64,
    g_b: f64,
    /// How much finer than the trigonometric-polynomial grid to sample.
    refine: usize,
}

impl Spectrum {
    /// The spectrum of `terms`, each with its variance coefficient `v²` (`N²`, `B²`,
    /// `σ²` ...), for samples every `dt` seconds; ramps and zero terms drop out (one
    /// Gauss–Markov term at most: the last given counts).
    pub fn new(terms: &[(Term, f64)], dt: f64) -> Self {
        let mut s = Self {
            q: 0.0,
            w: 0.0,
            f: 0.0,
            r: 0.0,
            g_num: 0.0,
            g_a: 1.0,
            g_b: 0.0,
            refine: 1,
        };
        for &(term, c) in terms.iter().filter(|(_, c)| *c > 0.0) {
            match term {
                Term::Quantization => s.q += 4.0 * c / (dt * dt),
                Term::WhiteRate => s.w += c / dt,
                Term::BiasInstability => {
                    s.refine = s.refine.max(REFINE_FLICKER);
                    s.f += c;
                }
                Term::RateRandomWalk => s.r += c * dt / 4.0,
                Term::RateRamp => {}
                Term::GaussMarkov { tau } => {
                    s.refine = s.refine.max(REFINE_GAUSS_MARKOV);
                    let one_minus = -(-dt / tau).exp_m1();
                    s.g_num = c * -(-2.0 * dt / tau).exp_m1();
                    s.g_a = one_minus * one_minus;
                    s.g_b = 4.0 * (-dt / tau).exp();
                }
            }
        }
        s
    }

    /// `P(ω)` at `ω` with `s2 = sin²(ω/2)` and its inverse.
    #[inline(always)]
    fn at(&self, omega: f64, s2: f64, inv_s2: f64) -> f64 {
        self.q * s2
            + self.w
            + self.f / omega
            + self.r * inv_s2
            + self.g_num / (self.g_a + self.g_b * s2)
    }

    /// The two-sided spectrum `P(ω)` of the rate samples at `ω` in (0, π] rad per sample.
    pub fn psd(&self, omega: f64) -> f64 {
        let s2 = (0.5 * omega).sin().powi(2);
        self.at(omega, s2, 1.0 / s2)
    }

    /// Expected Allan variance at cluster size `m` (module doc), on a grid 16 times
    /// finer than the covariance's (one integral: the cost is small).
    pub fn expected_avar(&self, m: usize) -> f64 {
        let m = m.max(1);
        let mean = circle_mean(16 * self.refine * 2 * m + 1, m, m, |omega, s2, sa, _| {
            let (sa2, inv) = (sa * sa, 1.0 / s2);
            self.at(omega, s2, inv) * 4.0 * sa2 * sa2 * inv
        });
        mean / (2.0 * (m * m) as f64)
    }

    /// Covariance matrix of the estimates at `points` (module doc).
    pub fn covariance(&self, points: &[AllanPoint]) -> DMatrix<f64> {
        let n = points.len();
        let mut cov = DMatrix::zeros(n, n);
        for a in 0..n {
            for b in a..n {
                let (pa, pb) = (&points[a], &points[b]);
                let l = self.refine * 2 * (pa.m + pb.m) + 1;
                let mean = circle_mean(l, pa.m, pb.m, |omega, s2, sa, sb| {
                    let inv = 1.0 / s2;
                    let p = self.at(omega, s2, inv);
                    let k = 4.0 * sa * sa * sb * sb * inv;
                    p * p * k * k
                });
                let (ma, mb) = (pa.m as f64, pb.m as f64);
                let m_terms = pa.terms.max(pb.terms).max(1) as f64;
                let c = mean / (2.0 * ma * ma * mb * mb * m_terms);
                cov[(a, b)] = c;
                cov[(b, a)] = c;
            }
        }
        cov
    }
}

/// `(1/L) Σ_{j<L} f(ω_j)` over `ω_j = 2π(j + 1/2)/L` (`L` made odd) for an even
/// function of `ω` given as `f(ω, sin²(ω/2), sin(aω/2), sin(bω/2))`: the mean over the
/// circle, exact for trigonometric polynomials of degree below `L`. The half-angle
/// sines advance by rotation (one complex product per node; the drift after 10⁶
/// nodes is about 1e-10, far below the precision the covariance needs).
fn circle_mean(l: usize, a: usize, b: usize, mut f: impl FnMut(f64, f64, f64, f64) -> f64) -> f64 {
    let l = l | 1;
    let half = (l - 1) / 2;
    let step = std::f64::consts::PI / l as f64;
    let rot = |k: f64| ((k * step).cos(), (k * step).sin());
    let start = |k: f64| ((0.5 * k * step).cos(), (0.5 * k * step).sin());
    let (r1, ra, rb) = (rot(1.0), rot(a as f64), rot(b as f64));
    let (mut z1, mut za, mut zb) = (start(1.0), start(a as f64), start(b as f64));
    let mul = |z: (f64, f64), r: (f64, f64)| (z.0 * r.0 - z.1 * r.1, z.0 * r.1 + z.1 * r.0);
    let mut sum = 0.0;
    for j in 0..=half {
        let theta = (j as f64 + 0.5) * step;
        let w = if j < half { 2.0 } else { 1.0 };
        sum += w * f(2.0 * theta, z1.1 * z1.1, za.1, zb.1);
        z1 = mul(z1, r1);
        za = mul(za, ra);
        zb = mul(zb, rb);
    }
    sum / l as f64
}

#[cfg(test)]
mod tests {
    use super::super::confidence::{NoiseType, edf};
    use super::*;

    fn point(m: usize, n: usize) -> AllanPoint {
        AllanPoint {
            m,
            tau: m as f64,
            avar: 0.0,
            terms: n + 1 - 2 * m,
        }
    }

    /// The expected Allan variances of the spectra are the IEEE 952 forms: white
    /// rate N²/τ and quantization 3Q²/τ² exactly (1e-12); rate random walk K²τ/3
    /// within 2 % from m = 10 (the samples are the walk's values, not its averages
    /// over dt, which matters at short clusters); bias instability (2 ln 2/π) B²
    /// within 3 % from m = 100 (the floor is approached slowly, the highest
    /// frequencies adding terms in 1/m); the Gauss–Markov bias its continuous form
    /// ([`Term::unit_avar`]) within 3 % from m = 10 (sampled AR(1) values against a
    /// continuous average, 0.6 % at τ = T/5, plus the sampling of its spectral peak,
    /// below 2 %: see `refined_grid_agrees`).
    #[test]
    fn expected_values_are_the_ieee_952_forms() {
        let dt = 0.01;
        for m in [1, 3, 10, 100, 1000] {
            let tau = m as f64 * dt;
            let check = |term: Term, tol: f64| {
                let s = Spectrum::new(&[(term, 1.0)], dt);
                let (got, want) = (s.expected_avar(m), term.unit_avar(tau));
                assert!(
                    (got / want - 1.0).abs() < tol,
                    "{term:?} m={m}: {got} vs {want}"
                );
            };
            check(Term::WhiteRate, 1e-12);
            check(Term::Quantization, 1e-12);
            if m >= 10 {
                check(Term::RateRandomWalk, 0.02);
                check(Term::GaussMarkov { tau: 0.5 }, 0.03);
                check(Term::GaussMarkov { tau: 50.0 }, 0.03);
            }
            if m >= 100 {
                check(Term::BiasInstability, 0.03);
            }
        }
    }

    /// The diagonal of the covariance gives ν = 2σ⁴/var: for white rate it is
    /// Greenhall's long-record 1.5 (N − 2m)/m times Howe–Allan–Barnes's
    /// 4m²/(4m² + 5) to 1e-6 (both exact for this case), and within 10 % the simple
    /// formulas of [`super::super::confidence`] for each type from m = 10 (they are
    /// approximations of a few per cent, flicker's of 10 %).
    #[test]
    fn variance_gives_the_equivalent_degrees_of_freedom() {
        let (dt, n) = (0.01, 100_000);
        for (term, ty, tol) in [
            (Term::WhiteRate, NoiseType::WhiteRate, 0.02),
            (Term::RateRandomWalk, NoiseType::RandomWalkRate, 0.1),
            (Term::BiasInstability, NoiseType::FlickerRate, 0.12),
            (Term::Quantization, NoiseType::WhitePhase, 0.1),
        ] {
            let s = Spectrum::new(&[(term, 1.0)], dt);
            for m in [10, 100, 1000] {
                let p = point(m, n);
                let var = s.covariance(&[p])[(0, 0)];
                let nu = 2.0 * s.expected_avar(m).powi(2) / var;
                let want = edf(ty, n + 1, m);
                assert!(
                    (nu / want - 1.0).abs() < tol,
                    "{term:?} m={m}: {nu} vs {want}"
                );
                if term == Term::WhiteRate {
                    let mf = m as f64;
                    let g =
                        1.5 * (n + 1 - 2 * m) as f64 / mf * 4.0 * mf * mf / (4.0 * mf * mf + 5.0);
                    assert!((nu / g - 1.0).abs() < 1e-6, "{nu} vs {g}");
                }
            }
        }
    }

    /// Sampling of the non-polynomial spectra: a grid 32 times finer than the
    /// polynomial one changes the covariances of a bias instability by under 1.5 %
    /// (1 % measured) and those of a Gauss–Markov bias by under 3 % (2.4 % measured at
    /// T = 300 s, below 1 % at T = 0.3 s). The covariance only sets the intervals'
    /// widths, for which a few per cent is ample.
    #[test]
    fn refined_grid_agrees() {
        let dt = 0.01;
        let pts: Vec<AllanPoint> = [1, 3, 10, 30, 100, 300, 1000, 3000, 10000]
            .map(|m| point(m, 200_000))
            .to_vec();
        for term in [
            Term::BiasInstability,
            Term::GaussMarkov { tau: 0.3 },
            Term::GaussMarkov { tau: 300.0 },
        ] {
            let s = Spectrum::new(&[(term, 1.0), (Term::WhiteRate, 1e-4)], dt);
            let fine = Spectrum {
                refine: 32,
                ..s.clone()
            };
            let tol = if term == Term::BiasInstability {
                0.015
            } else {
                0.03
            };
            let (c, f) = (s.covariance(&pts), fine.covariance(&pts));
            for (x, y) in c.iter().zip(f.iter()) {
                assert!((x / y - 1.0).abs() < tol, "{term:?}: {x} vs {y}");
            }
        }
    }
}
