//! Confidence of an overlapping Allan variance estimate (Riley, NIST SP 1065, 2008,
//! §5.3): the estimate `σ̂²` is taken as `σ² χ²(ν)/ν`, so with probability `p`
//!
//! `ν σ̂² / χ²_{(1+p)/2}(ν) ≤ σ² ≤ ν σ̂² / χ²_{(1−p)/2}(ν)`,
//!
//! with the equivalent degrees of freedom `ν` of the overlapping estimator. Here `ν`
//! comes from the simple approximations of Howe, Allan & Barnes (1981, "Properties of
//! signal sources and measurement methods", Proc. 35th Freq. Control Symp.), as SP
//! 1065 tabulates them, for `N` phase points (`N − 1` increments) and cluster size
//! `m`:
//!
//! | noise of the rate | IEEE 952 term | `ν` |
//! |---|---|---|
//! | white phase (α = 2) | quantization `Q` | `(N + 1)(N − 2m) / (2 (N − m))` |
//! | white rate (α = 0) | angle/velocity random walk `N` | `(3(N − 1)/(2m) − 2(N − 2)/N) · 4m²/(4m² + 5)` |
//! | flicker rate (α = −1) | bias instability `B` | `2(N − 2)/(2.3 N − 4.9)` at `m = 1`, else `5N²/(4m(N + 3m))` |
//! | random-walk rate (α = −2) | rate random walk `K` | `(N − 2)/(m (N − 3)²) · ((N − 1)² − 3m(N − 1) + 4m²)` |
//!
//! They agree with Greenhall's (2004) exact values for long records to a few per
//! cent (white rate: both `1.5 (N − 2m)/m`), which [`super::spectral`]'s covariance
//! reproduces (tests). A point where several terms contribute gets the Satterthwaite
//! (1946) combination `1/ν = Σ w_i²/ν_i`, `w_i` the share of term `i` in `σ²(τ)`
//! (the estimates of independent noises add; their cross terms, of zero mean, are
//! neglected); a deterministic ramp adds no variance.

use crate::filter::kalman::chi_square_quantile_real;

/// The power-law noise types of a rate, by the exponent `α` of its spectrum `∝ f^α`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NoiseType {
    /// White phase noise, α = 2: quantization of the integrated signal.
    WhitePhase,
    /// White rate noise, α = 0: angle or velocity random walk.
    WhiteRate,
    /// Flicker rate noise, α = −1: bias instability.
    FlickerRate,
    /// Random-walk rate, α = −2: rate or acceleration random walk.
    RandomWalkRate,
}

/// Equivalent degrees of freedom of the overlapping Allan variance at cluster size
/// `m` from `n_phase` phase points for one noise type (module table), at least 1.
pub fn edf(noise: NoiseType, n_phase: usize, m: usize) -> f64 {
    let (n, m) = (n_phase as f64, m.max(1) as f64);
    let nu = match noise {
        NoiseType::WhitePhase => (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m)),
        NoiseType::WhiteRate => {
            (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n) * 4.0 * m * m / (4.0 * m * m + 5.0)
        }
        NoiseType::FlickerRate if m < 2.0 => 2.0 * (n - 2.0) / (2.3 * n - 4.9),
        NoiseType::FlickerRate => 5.0 * n * n / (4.0 * m * (n + 3.0 * m)),
        NoiseType::RandomWalkRate => {
            (n - 2.0) / (m * (n - 3.0).powi(2))
                * ((n - 1.0).powi(2) - 3.0 * m * (n - 1.0) + 4.0 * m * m)
        }
    };
    if nu.is_finite() { nu.max(1.0) } else { 1.0 }
}

/// Equivalent degrees of freedom of a point where the noise types `parts` contribute
/// the variances given with them: `1/ν = Σ w_i²/ν_i`, `w_i = v_i / Σ v` (Satterthwaite);
/// [`NoiseType::WhiteRate`]'s when every variance is zero.
pub fn edf_mixture(parts: &[(NoiseType, f64)], n_phase: usize, m: usize) -> f64 {
    let total: f64 = parts.iter().map(|p| p.1.max(0.0)).sum();
    if !(total > 0.0 && total.is_finite()) {
        return edf(NoiseType::WhiteRate, n_phase, m);
    }
    let inv: f64 = parts
        .iter()
        .map(|&(t, v)| (v.max(0.0) / total).powi(2) / edf(t, n_phase, m))
        .sum();
    (1.0 / inv).max(1.0)
}

/// Interval `(lo, hi)` of the Allan *deviation* at probability `p` around the
/// estimate `adev` with `edf` degrees of freedom: `adev sqrt(ν/χ²_{(1±p)/2}(ν))`.
pub fn deviation_interval(adev: f64, edf: f64, p: f64) -> (f64, f64) {
    let hi_q = chi_square_quantile_real(edf, 0.5 * (1.0 + p));
    let lo_q = chi_square_quantile_real(edf, 0.5 * (1.0 - p));
    (adev * (edf / hi_q).sqrt(), adev * (edf / lo_q).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values of the formulas at N = 1025, m = 4 against hand evaluation, and the
    /// long-record limits: white rate 1.5 N/m, random-walk rate about N/m, flicker
    /// 1.25 N/m.
    #[test]
    fn formulas_and_limits() {
        let nu = edf(NoiseType::WhiteRate, 1025, 4);
        let hand = (3.0 * 1024.0 / 8.0 - 2.0 * 1023.0 / 1025.0) * 64.0 / 69.0;
        assert!((nu - hand).abs() < 1e-12, "{nu} {hand}");
        let n = 1_000_001;
        for (t, k) in [
            (NoiseType::WhiteRate, 1.5),
            (NoiseType::FlickerRate, 1.25),
            (NoiseType::RandomWalkRate, 1.0),
        ] {
            let nu = edf(t, n, 100);
            assert!((nu / (k * 1e4) - 1.0).abs() < 0.01, "{t:?}: {nu}");
        }
        // White phase: about N/2 whatever m.
        assert!((edf(NoiseType::WhitePhase, n, 100) / 5e5 - 1.0).abs() < 1e-3);
    }

    /// One type alone is itself; equal shares of equal-ν types double ν
    /// (1/ν' = 2 (1/2)²/ν); a zero share does not count.
    #[test]
    fn satterthwaite_mixture() {
        let (n, m) = (10_001, 10);
        let w = edf(NoiseType::WhiteRate, n, m);
        let only = edf_mixture(
            &[
                (NoiseType::WhiteRate, 3.0),
                (NoiseType::RandomWalkRate, 0.0),
            ],
            n,
            m,
        );
        assert!((only - w).abs() < 1e-9);
        let two = edf_mixture(
            &[(NoiseType::WhiteRate, 1.0), (NoiseType::WhiteRate, 1.0)],
            n,
            m,
        );
        assert!((two - 2.0 * w).abs() < 1e-9 * w);
    }

    /// The deviation interval at ν = 10, p = 0.95: chi-square quantiles 3.247 and
    /// 20.483 (Abramowitz & Stegun table 26.8) give sqrt(10/20.483) = 0.6987 and
    /// sqrt(10/3.247) = 1.7549 times the estimate.
    #[test]
    fn interval_from_chi_square_tables() {
        let (lo, hi) = deviation_interval(2.0, 10.0, 0.95);
        assert!((lo / 2.0 - 0.6987).abs() < 2e-4, "{lo}");
        assert!((hi / 2.0 - 1.7549).abs() < 2e-4, "{hi}");
    }
}
