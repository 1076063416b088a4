//! Filter consistency: are the errors as large as the covariance says?
//!
//! A consistent filter's normalized innovation squared `NIS = zᵀ S⁻¹ z` of an
//! `m`-dimensional measurement is chi-square with `m` degrees of freedom, and with a
//! truth its normalized estimation error squared `NEES = eᵀ P⁻¹ e` of an
//! `n`-dimensional error is chi-square with `n` (Bar-Shalom, Li & Kirubarajan 2001,
//! §5.4). Two tests at probability `p` (0.95):
//! - per epoch: the two-sided interval `[χ²_m((1−p)/2), χ²_m((1+p)/2)]`, which a
//!   fraction `1 − p` of the epochs falls outside;
//! - time average of `N` values: if they are independent (innovations of an optimal
//!   filter are white), `N` times the average is `χ²_{N m}`, so the average lies in
//!   `[χ²_{Nm}((1−p)/2), χ²_{Nm}((1+p)/2)] / N`. Successive NEES values of one run are
//!   correlated, so for NEES this interval is narrower than the truth of one run; it
//!   holds for the average over independent Monte-Carlo runs at one epoch.
//!
//! The quantiles are [`crate::filter::kalman::chi_square_quantile`]'s.

use crate::filter::kalman::chi_square_quantile;
use nalgebra::{SMatrix, SVector};

/// A two-sided interval `[lo, hi]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Bounds {
    /// Whether `x` lies in `[lo, hi]`.
    pub fn contains(&self, x: f64) -> bool {
        x >= self.lo && x <= self.hi
    }
}

/// The per-epoch interval of a chi-square(`dof`) statistic at probability `p`:
/// `[χ²_dof((1−p)/2), χ²_dof((1+p)/2)]`.
pub fn epoch_bounds(dof: usize, p: f64) -> Bounds {
    Bounds {
        lo: chi_square_quantile(dof, 0.5 * (1.0 - p)),
        hi: chi_square_quantile(dof, 0.5 * (1.0 + p)),
    }
}

/// The interval of the average of `n` independent chi-square(`dof`) values at
/// probability `p`: `[χ²_{n dof}((1−p)/2), χ²_{n dof}((1+p)/2)] / n`.
pub fn mean_bounds(n: usize, dof: usize, p: f64) -> Bounds {
    let b = epoch_bounds(n * dof, p);
    let n = n.max(1) as f64;
    Bounds {
        lo: b.lo / n,
        hi: b.hi / n,
    }
}

/// Normalized squared error `eᵀ P⁻¹ e` (NEES or NIS); `None` when `P` is not positive
/// definite or the result is not finite.
pub fn normalized_squared<const D: usize>(
    e: &SVector<f64, D>,
    p: &SMatrix<f64, D, D>,
) -> Option<f64> {
    let chol = p.cholesky()?;
    let x = e.dot(&chol.solve(e));
    x.is_finite().then_some(x)
}

/// A series of chi-square(`dof`) statistics tested at probability `probability`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChiSquareTest {
    /// Degrees of freedom of each value.
    pub dof: usize,
    /// Probability of the intervals (e.g. 0.95).
    pub probability: f64,
    /// Finite values tested.
    pub count: usize,
    /// Values left out because they were not finite.
    pub non_finite: usize,
    /// Average of the finite values (its expectation is `dof`).
    pub mean: f64,
    /// Per-epoch interval.
    pub epoch_bounds: Bounds,
    /// Interval of the average of `count` independent values.
    pub mean_bounds: Bounds,
    /// Fraction of the values below the per-epoch interval.
    pub fraction_below: f64,
    /// Fraction above it.
    pub fraction_above: f64,
}

impl ChiSquareTest {
    /// The test of `values` (non-finite ones counted apart); `None` without a finite
    /// value or with `dof = 0`.
    pub fn of(values: impl IntoIterator<Item = f64>, dof: usize, probability: f64) -> Option<Self> {
        if dof == 0 {
            return None;
        }
        let bounds = epoch_bounds(dof, probability);
        let (mut count, mut non_finite, mut sum, mut below, mut above) = (0usize, 0, 0.0, 0, 0);
        for x in values {
            if !x.is_finite() {
                non_finite += 1;
                continue;
            }
            count += 1;
            sum += x;
            below += usize::from(x < bounds.lo);
            above += usize::from(x > bounds.hi);
        }
        if count == 0 {
            return None;
        }
        let n = count as f64;
        Some(Self {
            dof,
            probability,
            count,
            non_finite,
            mean: sum / n,
            epoch_bounds: bounds,
            mean_bounds: mean_bounds(count, dof, probability),
            fraction_below: below as f64 / n,
            fraction_above: above as f64 / n,
        })
    }

    /// Fraction of the values outside the per-epoch interval (expected `1 − p`).
    pub fn fraction_outside(&self) -> f64 {
        self.fraction_below + self.fraction_above
    }

    /// Whether the average lies in its interval.
    pub fn mean_inside(&self) -> bool {
        self.mean_bounds.contains(self.mean)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    /// Chi-square quantiles at 0.025 and 0.975 from mpmath 1.3.0 (40 digits): the root
    /// of `gammainc(k/2, 0, x/2, regularized=True) = p` by bisection, rounded here to
    /// 9 significant digits.
    const REFERENCE: [(usize, f64, f64); 8] = [
        (1, 0.000_982_069_117, 5.023_886_19),
        (2, 0.050_635_616_0, 7.377_758_91),
        (3, 0.215_795_283, 9.348_403_60),
        (9, 2.700_389_50, 19.022_767_8),
        (100, 74.221_927_5, 129.561_197),
        (180, 144.741_256, 219.044_317),
        (1000, 914.257_154, 1_089.530_91),
        (10_800, 10_513.844_3, 11_089.944_3),
    ];

    #[test]
    fn bounds_match_independent_quantiles() {
        for (k, lo, hi) in REFERENCE {
            let b = epoch_bounds(k, 0.95);
            // The quantile function promises 1e-10 relative (Newton on the exact
            // distribution function); the references carry 9 digits.
            assert!((b.lo / lo - 1.0).abs() < 1e-8, "k={k}: {} vs {lo}", b.lo);
            assert!((b.hi / hi - 1.0).abs() < 1e-8, "k={k}: {} vs {hi}", b.hi);
        }
        // 60 epochs of a 3-dof statistic: chi2(180) / 60.
        let m = mean_bounds(60, 3, 0.95);
        assert!((m.lo - 144.741_256 / 60.0).abs() < 1e-6, "{m:?}");
        assert!((m.hi - 219.044_317 / 60.0).abs() < 1e-6, "{m:?}");
    }

    #[test]
    fn nees_is_the_quadratic_form_and_rejects_singular_covariances() {
        // Diagonal P = diag(1, 4, 9), e = (1, 2, 3): 1 + 1 + 1.
        let p = Matrix3::from_diagonal(&Vector3::new(1.0, 4.0, 9.0));
        let e = Vector3::new(1.0, 2.0, 3.0);
        assert!((normalized_squared(&e, &p).expect("P > 0") - 3.0).abs() < 1e-14);
        // Correlated 2x2: P = [[2, 1], [1, 2]], P⁻¹ = [[2, -1], [-1, 2]] / 3;
        // e = (1, 1): eᵀ P⁻¹ e = 2/3.
        let p2 = nalgebra::Matrix2::new(2.0, 1.0, 1.0, 2.0);
        let e2 = nalgebra::Vector2::new(1.0, 1.0);
        assert!((normalized_squared(&e2, &p2).expect("P > 0") - 2.0 / 3.0).abs() < 1e-14);
        assert_eq!(normalized_squared(&e, &Matrix3::zeros()), None);
    }

    #[test]
    fn the_test_counts_outside_and_averages_finite_values() {
        // dof 1, p 0.95: interval [0.000982, 5.0239].
        let t = ChiSquareTest::of([0.0001, 1.0, 2.0, 6.0, f64::INFINITY], 1, 0.95).expect("values");
        assert_eq!((t.count, t.non_finite), (4, 1));
        assert!((t.mean - 9.0001 / 4.0).abs() < 1e-12);
        assert_eq!((t.fraction_below, t.fraction_above), (0.25, 0.25));
        assert!((t.fraction_outside() - 0.5).abs() < 1e-15);
        // Average of 4 chi2(1): chi2(4) quantiles / 4 = [0.4844, 11.143] / 4.
        assert!((t.mean_bounds.lo - 0.484_418_557 / 4.0).abs() < 1e-8);
        assert!((t.mean_bounds.hi - 11.143_286_8 / 4.0).abs() < 1e-7);
        assert!(t.mean_inside());
        assert_eq!(ChiSquareTest::of([f64::NAN], 3, 0.95), None);
        assert_eq!(ChiSquareTest::of([1.0], 0, 0.95), None);
    }
}
