//! The noise terms of IEEE Std 952-1997 annex C fitted to an Allan curve, with a
//! confidence interval for each.
//!
//! Model: `σ²(τ) = Σ_j v_j² g_j(τ)`, linear in the variance coefficients `c_j = v_j²`:
//!
//! | term | `v` | `g(τ)` | slope of `σ` |
//! |---|---|---|---|
//! | [`Term::Quantization`] | `Q` | `3/τ²` | −1 |
//! | [`Term::WhiteRate`] | angle/velocity random walk `N` | `1/τ` | −1/2 (reads `N` at τ = 1 s) |
//! | [`Term::BiasInstability`] | `B` | `2 ln 2/π` | 0 (floor `σ_min = 0.664 B`) |
//! | [`Term::RateRandomWalk`] | `K` | `τ/3` | +1/2 (reads `K` at τ = 3 s) |
//! | [`Term::RateRamp`] | `R` | `τ²/2` | +1 |
//! | [`Term::GaussMarkov`] | `σ` (correlation time `T`) | `(2T/τ)(1 − (T/2τ)(3 − 4e^{−τ/T} + e^{−2τ/T}))` | +1/2, peak `0.617 σ` at `1.89 T`, −1/2 |
//!
//! Method, and why:
//!
//! 1. **Weighted least squares on `σ²`** with non-negative coefficients: the model is
//!    linear in `c = v²`, so the fit is a small non-negative least-squares problem,
//!    solved exactly by trying every set of free terms (at most 2⁵; the best feasible
//!    one is the constrained optimum, the problem being convex). Reading the slopes
//!    by hand (IEEE 952's tangent lines) uses one point per term and ignores the
//!    others; a fit uses them all and gives an interval.
//! 2. **Weights from the points' confidence**: `w_i = ν_i / (2 σ_i⁴)`, the inverse
//!    variance of a `σ² χ²(ν)/ν` estimate, with `ν_i` the equivalent degrees of
//!    freedom of [`super::confidence`] for the fitted model's mix of terms at `τ_i`
//!    and `σ_i²` the *model's* value (iterated from the measured values: weighting by
//!    the measured `σ̂²` would favour the points that happen to fall low).
//! 3. **Interval of each term from the full covariance**: the estimates at nearby `τ`
//!    share their data (correlations over 0.9 between neighbours), so the textbook
//!    `(GᵀWG)⁻¹` of independent points would be several times too narrow. The
//!    coefficients' covariance is the sandwich `(GᵀWG)⁻¹ GᵀW C W G (GᵀWG)⁻¹` with `C`
//!    the covariance of the estimates under the fitted model
//!    ([`super::spectral::Spectrum::covariance`]), over the free terms (a term fitted
//!    at zero gets its own with it added). The interval of `c` is `ĉ ± z sd`
//!    (normal, `z` at the chosen probability), cut at 0, and that of `v` its square
//!    root. The estimates' own skewness at long `τ` is neglected: the intervals are
//!    approximate there.
//!
//! [`fit_ieee952`] fits the five IEEE terms; [`fit_gauss_markov`] fits what the
//! navigation filter and the simulator model instead of the flicker floor: white
//! noise, a first-order Gauss–Markov bias (its correlation time searched on a log grid,
//! then refined by golden section, and given an interval by adding `∂σ²/∂ln T` to the
//! sandwich) and a bias random walk.

use super::confidence::{NoiseType, edf_mixture};
use super::spectral::Spectrum;
use super::{AllanCurve, AllanPoint};
use crate::filter::kalman::normal_quantile;
use nalgebra::{DMatrix, DVector};

/// `2 ln 2 / π`: the flicker floor `σ² = (2 ln 2/π) B²` (IEEE 952 annex C).
pub const FLICKER_FACTOR: f64 = 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI;

/// One noise term of the model (module table).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Term {
    /// Quantization `Q` [unit]: `σ² = 3Q²/τ²`.
    Quantization,
    /// Angle or velocity random walk `N` [unit/sqrt(s)]: `σ² = N²/τ`.
    WhiteRate,
    /// Bias instability `B` [unit/s]: `σ² = (2 ln 2/π) B²`.
    BiasInstability,
    /// Rate or acceleration random walk `K` [unit/s/sqrt(s)]: `σ² = K² τ/3`.
    RateRandomWalk,
    /// Rate ramp `R` [unit/s²]: `σ² = R² τ²/2`.
    RateRamp,
    /// First-order Gauss–Markov bias of standard deviation `σ` [unit/s] and
    /// correlation time `tau` [s]: `σ² f(τ/T)` ([`gauss_markov_avar`]).
    GaussMarkov {
        /// Correlation time `T` [s].
        tau: f64,
    },
}

/// The IEEE Std 952 terms [`fit_ieee952`] fits: quantization, white noise, bias
/// instability and rate random walk. The rate ramp is left out: over a log a few
/// times longer than the longest `τ` it is hard to tell from the random walk, and the
/// few degrees of freedom of the last points made its 95 % interval exclude zero in 24
/// of 100 seeded runs of white noise and random walk without any ramp; give it to
/// [`fit_terms`] to fit it too.
pub const IEEE952_TERMS: [Term; 4] = [
    Term::Quantization,
    Term::WhiteRate,
    Term::BiasInstability,
    Term::RateRandomWalk,
];

/// Allan variance of a unit Gauss–Markov process at `x = τ/T`:
/// `f(x) = (2/x)(1 − (3 − 4e^{−x} + e^{−2x})/(2x))` (e.g. Zhang et al. 2008; the
/// series `2x/3 − x²/2 + 7x³/30 − x⁴/12` below x = 0.05, where the closed form cancels).
pub fn gauss_markov_avar(x: f64) -> f64 {
    if x < 0.05 {
        return x * (2.0 / 3.0 + x * (-0.5 + x * (7.0 / 30.0 - x / 12.0)));
    }
    let inner = -4.0 * (-x).exp_m1() + (-2.0 * x).exp_m1();
    (2.0 / x) * (1.0 - inner / (2.0 * x))
}

impl Term {
    /// `g(τ)`: the term's Allan variance per unit `v²` (module table).
    pub fn unit_avar(self, tau: f64) -> f64 {
        match self {
            Term::Quantization => 3.0 / (tau * tau),
            Term::WhiteRate => 1.0 / tau,
            Term::BiasInstability => FLICKER_FACTOR,
            Term::RateRandomWalk => tau / 3.0,
            Term::RateRamp => tau * tau / 2.0,
            Term::GaussMarkov { tau: t } => gauss_markov_avar(tau / t),
        }
    }

    /// The noise types that make the term's variance at `τ`, with their fractions: the
    /// power-law terms one each, the ramp none; the Gauss–Markov bias shared between
    /// the two types whose slopes bracket its local log-slope `μ` of `σ²` (−1 white, 0
    /// flicker, +1 random walk), linearly in `μ`.
    fn noise_types(self, tau: f64) -> [(NoiseType, f64); 2] {
        let one = |t| [(t, 1.0), (t, 0.0)];
        match self {
            Term::Quantization => one(NoiseType::WhitePhase),
            Term::WhiteRate => one(NoiseType::WhiteRate),
            Term::BiasInstability => one(NoiseType::FlickerRate),
            Term::RateRandomWalk => one(NoiseType::RandomWalkRate),
            Term::RateRamp => [(NoiseType::WhiteRate, 0.0); 2],
            Term::GaussMarkov { tau: t } => {
                let (x, h) = (tau / t, 1e-3);
                let mu = ((gauss_markov_avar(x * (1.0 + h)) / gauss_markov_avar(x / (1.0 + h)))
                    .ln()
                    / (2.0 * (1.0 + h).ln()))
                .clamp(-1.0, 1.0);
                if mu < 0.0 {
                    [
                        (NoiseType::WhiteRate, -mu),
                        (NoiseType::FlickerRate, 1.0 + mu),
                    ]
                } else {
                    [
                        (NoiseType::RandomWalkRate, mu),
                        (NoiseType::FlickerRate, 1.0 - mu),
                    ]
                }
            }
        }
    }

    /// The term's name ("angle/velocity random walk N", ...).
    pub fn name(self) -> &'static str {
        match self {
            Term::Quantization => "quantization Q",
            Term::WhiteRate => "random walk N",
            Term::BiasInstability => "bias instability B",
            Term::RateRandomWalk => "rate random walk K",
            Term::RateRamp => "rate ramp R",
            Term::GaussMarkov { .. } => "Gauss-Markov sigma",
        }
    }

    /// Whether `self` and `other` are the same kind of term (any correlation time).
    pub fn same_kind(self, other: Term) -> bool {
        std::mem::discriminant(&self) == std::mem::discriminant(&other)
    }
}

/// One fitted term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedTerm {
    /// The term.
    pub term: Term,
    /// Its coefficient `v` (`N`, `B`, `K`, `Q`, `R` or `σ`) in SI, ≥ 0.
    pub value: f64,
    /// Standard deviation of the variance coefficient `v²` (sandwich, module doc).
    pub variance_sd: f64,
    /// Interval of `v` at the fit's probability: `sqrt(max(0, v² ∓ z sd))`.
    pub interval: (f64, f64),
}

impl FittedTerm {
    /// Whether the interval excludes zero (the term is resolved by the data).
    pub fn resolved(&self) -> bool {
        self.interval.0 > 0.0
    }
}

/// The correlation time of [`fit_gauss_markov`] with its interval [s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrelationTime {
    /// The fitted `T` [s].
    pub value: f64,
    /// `exp(ln T ∓ z sd(ln T))` [s].
    pub interval: (f64, f64),
}

/// A fitted noise model.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseFit {
    /// The terms, in the order asked for.
    pub terms: Vec<FittedTerm>,
    /// Probability of the intervals.
    pub probability: f64,
    /// The Gauss–Markov correlation time ([`fit_gauss_markov`] with a non-zero `σ`).
    pub correlation_time: Option<CorrelationTime>,
    /// Goodness of fit: `rᵀ C⁻¹ r / (points − free terms)` of the relative residuals
    /// `r = σ̂²/σ² − 1` with their covariance `C` under the fitted model; near 1 when
    /// the model describes the data, much larger when a term is missing.
    pub chi2_per_dof: f64,
}

impl NoiseFit {
    /// The fitted term of `term`'s kind.
    pub fn get(&self, term: Term) -> Option<&FittedTerm> {
        self.terms.iter().find(|t| t.term.same_kind(term))
    }

    /// The fitted model's Allan variance at `τ`: `Σ v² g(τ)`.
    pub fn avar(&self, tau: f64) -> f64 {
        self.terms
            .iter()
            .map(|t| t.value * t.value * t.term.unit_avar(tau))
            .sum()
    }

    /// Equivalent degrees of freedom of `point` of a curve of `samples` increments
    /// under the fitted model's mix of terms ([`super::confidence::edf_mixture`]).
    pub fn edf(&self, point: &AllanPoint, samples: usize) -> f64 {
        let c: Vec<(Term, f64)> = self
            .terms
            .iter()
            .map(|t| (t.term, t.value.powi(2)))
            .collect();
        point_edf(&c, point, samples + 1)
    }
}

/// How to fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Probability of the intervals (default 0.95).
    pub probability: f64,
    /// Reweighting passes (default 8).
    pub iterations: usize,
    /// Points per decade of `τ` the fit uses (default 5; [`thinned`]): closer
    /// neighbours are correlated above 0.9 and add little, while the covariance of
    /// the estimates costs the square of the number of points.
    pub per_decade: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            probability: 0.95,
            iterations: 8,
            per_decade: 5.0,
        }
    }
}

/// The points of `curve` nearest (in `ln τ`) to `per_decade` log-spaced times from its
/// first point, each once, the last point always kept.
pub fn thinned(curve: &AllanCurve, per_decade: f64) -> AllanCurve {
    let pts = &curve.points;
    let mut keep: Vec<AllanPoint> = Vec::new();
    if let (Some(first), Some(last)) = (pts.first(), pts.last()) {
        let span = (last.tau / first.tau).log10();
        let targets = (span * per_decade).floor() as usize;
        for k in 0..=targets {
            let target = first.tau.ln() + k as f64 * std::f64::consts::LN_10 / per_decade;
            let near = pts.iter().min_by(|a, b| {
                (a.tau.ln() - target)
                    .abs()
                    .total_cmp(&(b.tau.ln() - target).abs())
            });
            if let Some(p) = near
                && keep.last().is_none_or(|q| q.m != p.m)
            {
                keep.push(*p);
            }
        }
        if keep.last().is_some_and(|q| q.m != last.m) {
            keep.push(*last);
        }
    }
    AllanCurve {
        points: keep,
        ..curve.clone()
    }
}

/// Why a curve cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// Fewer points than terms plus one.
    #[error("{points} Allan points are too few to fit {terms} terms")]
    TooFewPoints {
        /// Points on the curve.
        points: usize,
        /// Terms asked for.
        terms: usize,
    },
    /// Every Allan variance is zero or not finite (a constant or broken channel).
    #[error("the Allan variances are all zero or not finite")]
    Degenerate,
}

/// `ν` at `point` under the variance coefficients `c` of the terms.
fn point_edf(c: &[(Term, f64)], point: &AllanPoint, n_phase: usize) -> f64 {
    let parts: Vec<(NoiseType, f64)> = c
        .iter()
        .flat_map(|&(term, c)| {
            let v = c * term.unit_avar(point.tau);
            term.noise_types(point.tau).map(|(t, f)| (t, f * v))
        })
        .collect();
    edf_mixture(&parts, n_phase, point.m)
}

/// The design matrix `G[i][j] = g_j(τ_i)`.
fn design(points: &[AllanPoint], terms: &[Term]) -> DMatrix<f64> {
    DMatrix::from_fn(points.len(), terms.len(), |i, j| {
        terms[j].unit_avar(points[i].tau)
    })
}

/// Least squares of `y ≈ G c` with rows weighted by `rw` over the columns `cols`,
/// columns scaled to unit norm for conditioning; `None` if a coefficient is negative
/// or not finite.
fn weighted_ls(g: &DMatrix<f64>, y: &[f64], rw: &[f64], cols: &[usize]) -> Option<DVector<f64>> {
    let n = y.len();
    let mut a = DMatrix::from_fn(n, cols.len(), |i, k| rw[i] * g[(i, cols[k])]);
    let norms: Vec<f64> = a.column_iter().map(|c| c.norm()).collect();
    if norms.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        return None;
    }
    for (k, nk) in norms.iter().enumerate() {
        a.column_mut(k).scale_mut(1.0 / nk);
    }
    let b = DVector::from_fn(n, |i, _| rw[i] * y[i]);
    let x = a.svd(true, true).solve(&b, 1e-13).ok()?;
    let c = DVector::from_fn(cols.len(), |k, _| x[k] / norms[k]);
    c.iter().all(|v| v.is_finite() && *v >= 0.0).then_some(c)
}

/// Non-negative least squares by trying every set of free columns (module doc, 1).
fn nnls(g: &DMatrix<f64>, y: &[f64], rw: &[f64]) -> Vec<f64> {
    let p = g.ncols();
    let cost = |c: &[f64]| -> f64 {
        (0..y.len())
            .map(|i| {
                let m: f64 = (0..p).map(|j| g[(i, j)] * c[j]).sum();
                (rw[i] * (y[i] - m)).powi(2)
            })
            .sum()
    };
    let mut best = vec![0.0; p];
    let mut best_cost = cost(&best);
    for mask in 1u32..(1 << p) {
        let cols: Vec<usize> = (0..p).filter(|j| mask & (1 << j) != 0).collect();
        if let Some(x) = weighted_ls(g, y, rw, &cols) {
            let mut c = vec![0.0; p];
            for (k, &j) in cols.iter().enumerate() {
                c[j] = x[k];
            }
            let e = cost(&c);
            if e < best_cost {
                best_cost = e;
                best = c;
            }
        }
    }
    best
}

/// A converged reweighted fit: the coefficients, the model's values, the points'
/// degrees of freedom and the weighted cost `Σ ν/2 (σ̂²/σ² − 1)²`.
struct Reweighted {
    c: Vec<f64>,
    model: Vec<f64>,
    nu: Vec<f64>,
    cost: f64,
}

/// Iteratively reweighted non-negative least squares (module doc, 2).
fn reweighted(curve: &AllanCurve, terms: &[Term], iterations: usize) -> Reweighted {
    let pts = &curve.points;
    let n_phase = curve.samples + 1;
    let g = design(pts, terms);
    let y: Vec<f64> = pts.iter().map(|p| p.avar).collect();
    let floor = y.iter().copied().fold(0.0, f64::max) * 1e-300;
    let mut scale: Vec<f64> = y.iter().map(|v| v.max(floor)).collect();
    let mut nu: Vec<f64> = pts
        .iter()
        .map(|p| point_edf(&[(Term::WhiteRate, 1.0)], p, n_phase))
        .collect();
    let mut c = vec![0.0; terms.len()];
    for _ in 0..iterations.max(1) {
        let rw: Vec<f64> = (0..pts.len())
            .map(|i| (0.5 * nu[i]).sqrt() / scale[i])
            .collect();
        c = nnls(&g, &y, &rw);
        let tc: Vec<(Term, f64)> = terms.iter().copied().zip(c.iter().copied()).collect();
        for (i, p) in pts.iter().enumerate() {
            let m: f64 = (0..terms.len()).map(|j| g[(i, j)] * c[j]).sum();
            scale[i] = if m > 0.0 { m } else { y[i].max(floor) };
            nu[i] = point_edf(&tc, p, n_phase);
        }
    }
    let cost = (0..pts.len())
        .map(|i| 0.5 * nu[i] * (y[i] / scale[i] - 1.0).powi(2))
        .sum();
    Reweighted {
        c,
        model: scale,
        nu,
        cost,
    }
}

/// The sandwich covariance `A⁻¹ B A⁻¹` (module doc, 3) of the parameters whose
/// model derivatives are the columns of `jac`, in the relative form (rows divided by
/// the model's value, weights `ν/2`, covariance `C` likewise scaled).
fn sandwich(jac: &DMatrix<f64>, w: &[f64], rel_cov: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let norms: Vec<f64> = jac.column_iter().map(|c| c.norm()).collect();
    if norms.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        return None;
    }
    let d = DMatrix::from_diagonal(&DVector::from_iterator(
        norms.len(),
        norms.iter().map(|x| 1.0 / x),
    ));
    let j = jac * &d;
    let wj = DMatrix::from_fn(j.nrows(), j.ncols(), |i, k| w[i] * j[(i, k)]);
    let a = j.transpose() * &wj;
    let a_inv = a.try_inverse()?;
    let b = wj.transpose() * rel_cov * &wj;
    Some(&d * (&a_inv * b * &a_inv) * &d)
}

/// Everything of a fit after the coefficients: intervals and goodness (module doc, 3).
/// `extra`: a further parameter's column of model derivatives (the Gauss–Markov
/// `∂σ²/∂ln T`), included in every sandwich when given.
fn finish(
    curve: &AllanCurve,
    terms: &[Term],
    r: &Reweighted,
    extra: Option<&DVector<f64>>,
    options: &FitOptions,
) -> (NoiseFit, Option<f64>) {
    let pts = &curve.points;
    let tc: Vec<(Term, f64)> = terms.iter().copied().zip(r.c.iter().copied()).collect();
    let cov = Spectrum::new(&tc, curve.dt).covariance(pts);
    let rel_cov = DMatrix::from_fn(pts.len(), pts.len(), |i, k| {
        cov[(i, k)] / (r.model[i] * r.model[k])
    });
    let w: Vec<f64> = r.nu.iter().map(|nu| 0.5 * nu).collect();
    let g = design(pts, terms);
    let rel = |col: DVector<f64>| DVector::from_fn(pts.len(), |i, _| col[i] / r.model[i]);
    let active: Vec<usize> = (0..terms.len()).filter(|&j| r.c[j] > 0.0).collect();
    let jacobian = |cols: &[usize]| {
        let mut columns: Vec<DVector<f64>> = cols
            .iter()
            .map(|&j| rel(g.column(j).into_owned()))
            .collect();
        if let Some(e) = extra {
            columns.push(rel(e.clone()));
        }
        DMatrix::from_columns(&columns)
    };
    let z = normal_quantile(0.5 * (1.0 + options.probability));
    let fitted = terms
        .iter()
        .enumerate()
        .map(|(j, &term)| {
            let mut cols = active.clone();
            if !cols.contains(&j) {
                cols.push(j);
                cols.sort_unstable();
            }
            let k = cols.iter().position(|&x| x == j).unwrap_or(0);
            let sd = sandwich(&jacobian(&cols), &w, &rel_cov)
                .map_or(f64::INFINITY, |s| s[(k, k)].max(0.0).sqrt());
            let c = r.c[j];
            FittedTerm {
                term,
                value: c.sqrt(),
                variance_sd: sd,
                interval: ((c - z * sd).max(0.0).sqrt(), (c + z * sd).sqrt()),
            }
        })
        .collect();
    let extra_sd = extra.and_then(|_| {
        let s = sandwich(&jacobian(&active), &w, &rel_cov)?;
        let k = active.len();
        Some(s[(k, k)].max(0.0).sqrt())
    });
    let resid = DVector::from_fn(pts.len(), |i, _| pts[i].avar / r.model[i] - 1.0);
    let dof = pts
        .len()
        .saturating_sub(active.len() + usize::from(extra.is_some()));
    let chi2 = quadratic_form(&rel_cov, &resid) / dof.max(1) as f64;
    (
        NoiseFit {
            terms: fitted,
            probability: options.probability,
            correlation_time: None,
            chi2_per_dof: chi2,
        },
        extra_sd.map(|sd| z * sd),
    )
}

/// `rᵀ C⁻¹ r` by Cholesky, with a ridge of 1e-9 of the mean diagonal if `C` is not
/// numerically positive definite; NaN if even that fails.
fn quadratic_form(c: &DMatrix<f64>, r: &DVector<f64>) -> f64 {
    let ridge = 1e-9 * c.trace() / c.nrows().max(1) as f64;
    let chol = c.clone().cholesky().or_else(|| {
        let mut c = c.clone();
        for i in 0..c.nrows() {
            c[(i, i)] += ridge;
        }
        c.cholesky()
    });
    chol.map_or(f64::NAN, |ch| r.dot(&ch.solve(r)))
}

/// Checks a curve can take `terms` terms.
fn check(curve: &AllanCurve, terms: usize) -> Result<(), FitError> {
    let points = curve.points.len();
    if points < terms + 1 {
        return Err(FitError::TooFewPoints { points, terms });
    }
    if !curve
        .points
        .iter()
        .any(|p| p.avar > 0.0 && p.avar.is_finite())
        || curve.points.iter().any(|p| !p.avar.is_finite())
    {
        return Err(FitError::Degenerate);
    }
    Ok(())
}

/// Fits `terms` to `curve` (module doc).
pub fn fit_terms(
    curve: &AllanCurve,
    terms: &[Term],
    options: &FitOptions,
) -> Result<NoiseFit, FitError> {
    let curve = &thinned(curve, options.per_decade);
    check(curve, terms.len())?;
    let r = reweighted(curve, terms, options.iterations);
    Ok(finish(curve, terms, &r, None, options).0)
}

/// Fits the five IEEE Std 952 terms ([`IEEE952_TERMS`]).
pub fn fit_ieee952(curve: &AllanCurve, options: &FitOptions) -> Result<NoiseFit, FitError> {
    fit_terms(curve, &IEEE952_TERMS, options)
}

/// The terms of [`fit_gauss_markov`] at correlation time `t`.
fn gm_terms(t: f64) -> [Term; 3] {
    [
        Term::WhiteRate,
        Term::GaussMarkov { tau: t },
        Term::RateRandomWalk,
    ]
}

/// Fits white noise `N`, a Gauss–Markov bias `σ` of correlation time `T` and a bias
/// random walk `K` (module doc): `T` over the curve's `τ` range, 10 per decade, then
/// 40 golden-section steps on `ln T` around the best.
pub fn fit_gauss_markov(curve: &AllanCurve, options: &FitOptions) -> Result<NoiseFit, FitError> {
    let curve = &thinned(curve, options.per_decade);
    check(curve, 4)?;
    let (t0, t1) = match (curve.points.first(), curve.points.last()) {
        (Some(a), Some(b)) => (a.tau.ln(), b.tau.ln()),
        _ => {
            return Err(FitError::TooFewPoints {
                points: 0,
                terms: 4,
            });
        }
    };
    let cost = |ln_t: f64| reweighted(curve, &gm_terms(ln_t.exp()), options.iterations).cost;
    let step = std::f64::consts::LN_10 / 10.0;
    let grid: Vec<f64> = (0..)
        .map(|k| t0 + k as f64 * step)
        .take_while(|x| *x <= t1 + 1e-9)
        .collect();
    let costs: Vec<f64> = grid.iter().map(|&x| cost(x)).collect();
    let best = (0..grid.len())
        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
        .unwrap_or(0);
    let (mut lo, mut hi) = (grid[best] - step, grid[best] + step);
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
    let (mut f1, mut f2) = (cost(x1), cost(x2));
    for _ in 0..40 {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - ratio * (hi - lo);
            f1 = cost(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + ratio * (hi - lo);
            f2 = cost(x2);
        }
    }
    let ln_t = if f1.min(f2) <= costs[best] {
        0.5 * (lo + hi)
    } else {
        grid[best]
    };
    let t = ln_t.exp();
    let terms = gm_terms(t);
    let r = reweighted(curve, &terms, options.iterations);
    let sigma2 = r.c[1];
    let h: f64 = 1e-4;
    let d_ln_t = (sigma2 > 0.0).then(|| {
        DVector::from_iterator(
            curve.points.len(),
            curve.points.iter().map(|p| {
                sigma2
                    * (gauss_markov_avar(p.tau / (t * h.exp()))
                        - gauss_markov_avar(p.tau / (t * (-h).exp())))
                    / (2.0 * h)
            }),
        )
    });
    let (mut fit, half_width) = finish(curve, &terms, &r, d_ln_t.as_ref(), options);
    fit.correlation_time = d_ln_t.map(|_| {
        let w = half_width.unwrap_or(f64::INFINITY);
        CorrelationTime {
            value: t,
            interval: ((ln_t - w).exp(), (ln_t + w).exp()),
        }
    });
    Ok(fit)
}
