//! Covariance bookkeeping of the error-state filter: propagation, the Joseph-form
//! measurement update, and the chi-square innovation gate.
//!
//! Measurements are written `z = H x + v`, `v ~ N(0, R)`, with `x` the error state
//! (computed minus true for the navigation errors, residual sensor errors). The gain
//! `K = P Hᵀ S⁻¹`, `S = H P Hᵀ + R`; the update `P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ`
//! (Joseph) keeps `P` symmetric and positive definite under round-off (Bucy &
//! Joseph 1968); the state estimate `K z` is fed back at once, so the filter's state
//! is zero between updates.

use nalgebra::{DMatrix, DVector};

/// The chi-square innovation test: reject a measurement whose normalized innovation
/// squared `zᵀ S⁻¹ z` exceeds the `1 − alpha` quantile for its dimension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gate {
    /// Accept everything.
    Off,
    /// Reject above the quantile at this significance level (e.g. 0.001).
    Level(f64),
    /// Reject only a normalized innovation squared above this bound (physically
    /// impossible innovations, e.g. thousands of standard deviations).
    Bound(f64),
}

/// An accepted update.
#[derive(Debug, Clone, PartialEq)]
pub struct Update {
    /// The error estimate to feed back.
    pub dx: DVector<f64>,
    /// Normalized innovation squared `zᵀ S⁻¹ z`.
    pub nis: f64,
    /// Diagonal of the innovation covariance `S = H P Hᵀ + R`.
    pub s_diag: DVector<f64>,
}

/// A rejected measurement and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Rejection {
    /// Normalized innovation squared.
    pub nis: f64,
    /// The gate's threshold for this dimension (infinite when the innovation
    /// covariance is not positive definite).
    pub threshold: f64,
    /// Diagonal of the innovation covariance `S = H P Hᵀ + R`.
    pub s_diag: DVector<f64>,
}

/// The error covariance.
#[derive(Debug, Clone, PartialEq)]
pub struct Kalman {
    /// Covariance of the error state.
    pub p: DMatrix<f64>,
}

/// Standard deviations of the three states from `o` (square roots of the covariance's
/// diagonal, negative round-off taken as zero).
pub fn std3(p: &DMatrix<f64>, o: usize) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::from_fn(|i, _| p[(o + i, o + i)].max(0.0).sqrt())
}

/// Make states `to..to+k` copies of `from..from+k` in a covariance (a state that
/// equals another at this instant).
pub fn duplicate_states(p: &mut DMatrix<f64>, from: usize, to: usize, k: usize) {
    for i in 0..k {
        let row = p.row(from + i).into_owned();
        p.row_mut(to + i).copy_from(&row);
        let col = p.column(from + i).into_owned();
        p.column_mut(to + i).copy_from(&col);
    }
}

impl Kalman {
    /// A filter with covariance `p`.
    pub fn new(p: DMatrix<f64>) -> Self {
        Self { p }
    }

    /// Standard deviation of state `i`.
    pub fn std(&self, i: usize) -> f64 {
        self.p[(i, i)].max(0.0).sqrt()
    }

    /// `P ← Φ P Φᵀ + Q_d`, symmetrized.
    pub fn predict(&mut self, phi: &DMatrix<f64>, qd: &DMatrix<f64>) {
        let p = phi * &self.p * phi.transpose() + qd;
        self.p = (&p + p.transpose()) * 0.5;
    }

    /// Process a measurement with innovation `z`, model `H` and noise `R`; on
    /// acceptance the covariance is updated and the estimate returned for feedback.
    pub fn update(
        &mut self,
        z: &DVector<f64>,
        h: &DMatrix<f64>,
        r: &DMatrix<f64>,
        gate: Gate,
    ) -> Result<Update, Rejection> {
        let pht = &self.p * h.transpose();
        let s = h * &pht + r;
        let s_diag = s.diagonal();
        let Some(chol) = s.cholesky() else {
            return Err(Rejection {
                nis: f64::INFINITY,
                threshold: f64::INFINITY,
                s_diag,
            });
        };
        let s_inv_z = chol.solve(z);
        let nis = z.dot(&s_inv_z);
        let threshold = match gate {
            Gate::Off => None,
            Gate::Level(alpha) => Some(chi_square_quantile(z.len(), 1.0 - alpha)),
            Gate::Bound(b) => Some(b),
        };
        if let Some(threshold) = threshold
            && (nis > threshold || !nis.is_finite())
        {
            return Err(Rejection {
                nis,
                threshold,
                s_diag,
            });
        }
        // K = P Hᵀ S⁻¹ (S symmetric): solve S Kᵀ = H P.
        let k = chol.solve(&pht.transpose()).transpose();
        let dx = &k * z;
        let n = self.p.nrows();
        let ikh = DMatrix::identity(n, n) - &k * h;
        let p = &ikh * &self.p * ikh.transpose() + &k * r * k.transpose();
        self.p = (&p + p.transpose()) * 0.5;
        Ok(Update { dx, nis, s_diag })
    }
}

/// Quantile of the chi-square distribution with `k` degrees of freedom at
/// probability `p`: exact for `k = 1` (`z²` at `(1 + p)/2`) and `k = 2`
/// (`−2 ln(1 − p)`); otherwise [`chi_square_quantile_real`].
pub fn chi_square_quantile(k: usize, p: f64) -> f64 {
    match k {
        0 => 0.0,
        1 => normal_quantile(0.5 * (1.0 + p)).powi(2),
        2 => -2.0 * (1.0 - p).ln(),
        _ => chi_square_quantile_real(k as f64, p),
    }
}

/// Quantile of the chi-square distribution with `k > 0` (not necessarily whole)
/// degrees of freedom at probability `p`: the Wilson–Hilferty (1931) cube-root normal
/// approximation `k (1 − 2/(9k) + z_p sqrt(2/(9k)))³` refined by Newton steps on the
/// exact distribution function `P(k/2, x/2)` (to 1e-10 relative).
pub fn chi_square_quantile_real(k: f64, p: f64) -> f64 {
    if k <= 0.0 {
        return 0.0;
    }
    let a = 0.5 * k;
    let z = normal_quantile(p);
    let c = 2.0 / (9.0 * k);
    let mut x = (k * (1.0 - c + z * c.sqrt()).powi(3)).max(1e-3 * k.min(1.0));
    let ln_gamma_a = ln_gamma(a);
    for _ in 0..50 {
        // d/dx P(a, x/2) = the chi-square density.
        let density = ((a - 1.0) * (0.5 * x).ln() - 0.5 * x - ln_gamma_a).exp() * 0.5;
        let step = (regularized_gamma_p(a, 0.5 * x) - p) / density;
        if !step.is_finite() {
            break;
        }
        x = (x - step).max(0.5 * x);
        if step.abs() <= 1e-10 * x {
            break;
        }
    }
    x
}

/// `ln Γ(a)` for `a > 0` (Lanczos, g = 7, n = 9; relative error < 1e-13).
fn ln_gamma(a: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if a < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * a).sin()).ln() - ln_gamma(1.0 - a);
    }
    let a = a - 1.0;
    let t = a + 7.5;
    let sum = G[1..]
        .iter()
        .enumerate()
        .fold(G[0], |s, (i, g)| s + g / (a + i as f64 + 1.0));
    0.5 * (2.0 * std::f64::consts::PI).ln() + (a + 0.5) * t.ln() - t + sum.ln()
}

/// Regularized lower incomplete gamma `P(a, x)`: its power series below `x = a + 1`,
/// the continued fraction of `Q = 1 − P` (modified Lentz) above.
fn regularized_gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let front = (a * x.ln() - x - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        while term.abs() > 1e-17 * sum.abs() {
            n += 1.0;
            term *= x / n;
            sum += term;
        }
        return sum * front;
    }
    let tiny = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / tiny;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..500 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        d = if d.abs() < tiny { tiny } else { d };
        c = b + an / c;
        c = if c.abs() < tiny { tiny } else { c };
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    1.0 - front * h
}

/// Standard normal quantile (Acklam's rational approximation, relative error
/// < 1.2e-9).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi_square_quantiles_match_tables() {
        // Tabulated (Abramowitz & Stegun table 26.8): k=1 0.99 -> 6.635, k=3 0.999 ->
        // 16.266, k=6 0.95 -> 12.592, k=2 0.99 -> 9.210.
        for (k, p, q) in [
            (1, 0.99, 6.635),
            (3, 0.999, 16.266),
            (6, 0.95, 12.592),
            (2, 0.99, 9.210),
        ] {
            let got = chi_square_quantile(k, p);
            assert!((got / q - 1.0).abs() < 0.01, "k={k} p={p}: {got} vs {q}");
        }
        assert!((normal_quantile(0.975) - 1.959_964).abs() < 1e-6);
        assert!((normal_quantile(0.001) + 3.090_232).abs() < 1e-6);
    }

    /// Fractional and large degrees of freedom: the quantile inverts the distribution
    /// function to 1e-9; at k = 1 and 2 it meets the exact forms to 1e-8 relative (the
    /// normal quantile's own error, 1.2e-9, doubled by the square, with margin); at
    /// k = 1e6 the normal limit k + z sqrt(2k) holds to the Wilson–Hilferty order
    /// (z² − 1) 2/3 ≈ 1.9.
    #[test]
    fn real_chi_square_quantiles_invert_the_distribution() {
        for k in [0.7, 1.5, 2.5, 7.3, 150.5, 4.0e4] {
            for p in [0.025, 0.5, 0.975] {
                let x = chi_square_quantile_real(k, p);
                let back = regularized_gamma_p(0.5 * k, 0.5 * x);
                assert!((back - p).abs() < 1e-9, "k={k} p={p}: P = {back}");
            }
        }
        for (k, p) in [(1, 0.975), (2, 0.025)] {
            let (a, b) = (
                chi_square_quantile(k, p),
                chi_square_quantile_real(k as f64, p),
            );
            assert!((a / b - 1.0).abs() < 1e-8, "{k}: {a} vs {b}");
        }
        let (k, z) = (1.0e6, 1.959_964);
        let x = chi_square_quantile_real(k, 0.975);
        assert!((x - (k + z * (2.0 * k).sqrt()) - (z * z - 1.0) * 2.0 / 3.0).abs() < 0.1);
    }

    #[test]
    fn scalar_update_is_the_textbook_one() {
        // P = 4, R = 1, z = 3: K = 0.8, dx = 2.4, P+ = 0.8, NIS = 9/5.
        let mut kf = Kalman::new(DMatrix::from_element(1, 1, 4.0));
        let u = kf
            .update(
                &DVector::from_element(1, 3.0),
                &DMatrix::from_element(1, 1, 1.0),
                &DMatrix::from_element(1, 1, 1.0),
                Gate::Off,
            )
            .unwrap();
        assert!((u.dx[0] - 2.4).abs() < 1e-15);
        assert!((kf.p[(0, 0)] - 0.8).abs() < 1e-15);
        assert!((u.nis - 1.8).abs() < 1e-15);
        assert_eq!(u.s_diag.as_slice(), [5.0]);
    }

    #[test]
    fn gate_rejects_and_leaves_covariance_alone() {
        let mut kf = Kalman::new(DMatrix::from_element(1, 1, 1.0));
        let r = kf.update(
            &DVector::from_element(1, 10.0),
            &DMatrix::from_element(1, 1, 1.0),
            &DMatrix::from_element(1, 1, 1.0),
            Gate::Level(0.001),
        );
        let rej = r.unwrap_err();
        assert!((rej.nis - 50.0).abs() < 1e-12);
        assert!((rej.threshold - 10.828).abs() < 1e-3);
        assert_eq!(rej.s_diag.as_slice(), [2.0]);
        assert_eq!(kf.p[(0, 0)], 1.0);
    }
}
