//! Overlapping Allan deviation (IEEE Std 952-1997 annex C; Riley, NIST SP 1065 §5.2.4).
//!
//! From the integrated signal `θ_k` (the running sum of increments, e.g. angle from
//! gyro increments) sampled every `dt`, for a cluster of `m` samples (`τ = m dt`):
//!
//! `σ²(τ) = Σ_{k=0}^{N-2m-1} (θ_{k+2m} − 2 θ_{k+m} + θ_k)² / (2 τ² (N − 2m))`.
//!
//! White rate noise of density `N` gives `σ(τ) = N / sqrt(τ)` (slope −1/2); a rate
//! random walk `K` gives `σ(τ) = K sqrt(τ/3)` (slope +1/2).

/// Allan deviation of the rate whose increments are `increments` (one per `dt`
/// seconds) at cluster size `m`; `None` if there are fewer than `2m + 1` samples or
/// `m` is 0.
pub fn allan_deviation(increments: &[f64], dt: f64, m: usize) -> Option<f64> {
    let n = increments.len() + 1;
    if m == 0 || n < 2 * m + 1 {
        return None;
    }
    let mut theta = Vec::with_capacity(n);
    theta.push(0.0);
    let mut acc = 0.0;
    for x in increments {
        acc += x;
        theta.push(acc);
    }
    let tau = m as f64 * dt;
    let terms = n - 2 * m;
    let sum: f64 = (0..terms)
        .map(|k| {
            let d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
            d * d
        })
        .sum();
    Some((sum / (2.0 * tau * tau * terms as f64)).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constant rate has zero Allan deviation (second differences of a line).
    #[test]
    fn constant_rate_has_zero_deviation() {
        let x = vec![0.25; 1000];
        assert!(allan_deviation(&x, 0.01, 10).expect("enough") < 1e-12);
    }

    /// A rate ramp r(t) = R t gives σ(τ) = R τ / sqrt(2) exactly (NIST SP 1065 table
    /// 5: linear drift), whatever the cluster size.
    #[test]
    fn ramp_gives_r_tau_over_sqrt2() {
        let dt = 0.1;
        let r = 2e-3;
        // Increment over ((k-1) dt, k dt] of the rate R t: R dt^2 (k - 1/2).
        let x: Vec<f64> = (1..=5000).map(|k| r * dt * dt * (k as f64 - 0.5)).collect();
        for m in [1, 10, 100] {
            let tau = m as f64 * dt;
            let s = allan_deviation(&x, dt, m).expect("enough");
            assert!(
                (s - r * tau / 2f64.sqrt()).abs() < 1e-9 * r * tau,
                "{m}: {s}"
            );
        }
    }

    #[test]
    fn too_short_is_none() {
        assert_eq!(allan_deviation(&[1.0, 2.0], 1.0, 2), None);
        assert_eq!(allan_deviation(&[1.0, 2.0], 1.0, 0), None);
    }
}
