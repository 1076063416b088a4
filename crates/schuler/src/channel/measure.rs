//! What a run shows, measured from its samples alone (no model parameters inside):
//! peaks, the oscillation period and trend, the growth time of the free vertical channel,
//! and settling times.

use nalgebra::{Matrix4, Vector4};

/// Largest absolute value of a series (0 for an empty one).
pub fn peak_abs(xs: impl IntoIterator<Item = f64>) -> f64 {
    xs.into_iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// A least-squares fit `x(t) ≈ c0 + c1 t + A cos(w t + φ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SinusoidFit {
    /// Angular frequency w [rad/s].
    pub frequency: f64,
    /// Period 2π/w \[s\].
    pub period: f64,
    /// Offset c0.
    pub offset: f64,
    /// Trend c1 [unit/s].
    pub slope: f64,
    /// Amplitude A.
    pub amplitude: f64,
    /// RMS of the residual.
    pub rms_residual: f64,
}

/// Linear least squares of `c0 + c1 t + c2 cos wt + c3 sin wt` at fixed `w`:
/// coefficients and residual sum of squares (`None` if singular).
fn fit_at(t: &[f64], x: &[f64], w: f64) -> Option<(Vector4<f64>, f64)> {
    // Time scaled to [0, 1] for a well-conditioned trend column.
    let span = t.last()? - t.first()?;
    if span <= 0.0 {
        return None;
    }
    let mut n = Matrix4::zeros();
    let mut b = Vector4::zeros();
    for (&ti, &xi) in t.iter().zip(x) {
        let (s, c) = (w * ti).sin_cos();
        let row = Vector4::new(1.0, ti / span, c, s);
        n += row * row.transpose();
        b += row * xi;
    }
    let coef = n.try_inverse()? * b;
    let rss = t
        .iter()
        .zip(x)
        .map(|(&ti, &xi)| {
            let (s, c) = (w * ti).sin_cos();
            let r = xi - (coef[0] + coef[1] * ti / span + coef[2] * c + coef[3] * s);
            r * r
        })
        .sum::<f64>();
    Some((Vector4::new(coef[0], coef[1] / span, coef[2], coef[3]), rss))
}

/// Fits `c0 + c1 t + A cos(w t + φ)` with `w` searched in `[w_lo, w_hi]` (a 400-point
/// logarithmic grid, then golden-section refinement of the best cell). This is the exact
/// shape of every constant-input solution (18)/(19), and it ignores fast ripple (a body
/// rotation) that is orthogonal to it. Series longer than 2000 samples are fitted on
/// every n-th sample (a Schuler period still holds hundreds). `None` for fewer than 8
/// samples or a flat series.
pub fn fit_sinusoid(t: &[f64], x: &[f64], w_lo: f64, w_hi: f64) -> Option<SinusoidFit> {
    if t.len() != x.len() || t.len() < 8 || !(w_lo > 0.0 && w_hi > w_lo) {
        return None;
    }
    let stride = t.len().div_ceil(2000);
    let (t, x): (Vec<f64>, Vec<f64>) = t
        .iter()
        .zip(x)
        .step_by(stride)
        .map(|(a, b)| (*a, *b))
        .unzip();
    let (t, x) = (t.as_slice(), x.as_slice());
    let scale = peak_abs(x.iter().copied());
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    let rss = |w: f64| fit_at(t, x, w).map_or(f64::INFINITY, |(_, r)| r);
    const GRID: usize = 400;
    let ratio = (w_hi / w_lo).powf(1.0 / (GRID - 1) as f64);
    let grid: Vec<f64> = (0..GRID).map(|k| w_lo * ratio.powi(k as i32)).collect();
    let (best, _) = grid.iter().enumerate().map(|(k, &w)| (k, rss(w))).fold(
        (0, f64::INFINITY),
        |acc, (k, r)| if r < acc.1 { (k, r) } else { acc },
    );
    let (mut lo, mut hi) = (grid[best.saturating_sub(1)], grid[(best + 1).min(GRID - 1)]);
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
    let (mut fc, mut fd) = (rss(c), rss(d));
    for _ in 0..80 {
        if fc < fd {
            hi = d;
            d = c;
            fd = fc;
            c = hi - phi * (hi - lo);
            fc = rss(c);
        } else {
            lo = c;
            c = d;
            fc = fd;
            d = lo + phi * (hi - lo);
            fd = rss(d);
        }
    }
    let w = 0.5 * (lo + hi);
    let (coef, rss_w) = fit_at(t, x, w)?;
    let amplitude = coef[2].hypot(coef[3]);
    // A fitted "oscillation" at round-off level is no oscillation.
    if amplitude <= 1e-9 * scale {
        return None;
    }
    Some(SinusoidFit {
        frequency: w,
        period: std::f64::consts::TAU / w,
        offset: coef[0],
        slope: coef[1],
        amplitude,
        rms_residual: (rss_w / t.len() as f64).sqrt(),
    })
}

/// Growth constant of `x'' = κ x` measured from samples: for any solution,
/// `x(t+L) + x(t-L) = 2 ch(L √κ) x(t)`, so `1/√κ = L / arcosh((x(t+L)+x(t-L)) / 2x(t))`.
/// Returns the median over the series of this e-fold time \[s\] (samples equally spaced,
/// `lag` in samples); `None` if no triple qualifies.
pub fn e_fold_time(x: &[f64], dt: f64, lag: usize) -> Option<f64> {
    if lag == 0 || x.len() <= 2 * lag {
        return None;
    }
    let scale = peak_abs(x.iter().copied());
    let mut taus: Vec<f64> = (lag..x.len() - lag)
        .filter(|&k| x[k].abs() > 1e-6 * scale)
        .filter_map(|k| {
            let ratio = (x[k + lag] + x[k - lag]) / (2.0 * x[k]);
            (ratio > 1.0).then(|| lag as f64 * dt / ratio.acosh())
        })
        .filter(|tau| tau.is_finite())
        .collect();
    if taus.is_empty() {
        return None;
    }
    taus.sort_by(f64::total_cmp);
    Some(taus[taus.len() / 2])
}

/// Least-squares slope of `ln |x|` against `t` over samples with `t` in `[from, to]`:
/// the exponential rate [1/s] of a decaying or growing error. `None` if fewer than 3
/// usable samples.
pub fn log_rate(t: &[f64], x: &[f64], from: f64, to: f64) -> Option<f64> {
    let pts: Vec<(f64, f64)> = t
        .iter()
        .zip(x)
        .filter(|(ti, xi)| **ti >= from && **ti <= to && xi.abs() > 0.0)
        .map(|(ti, xi)| (*ti, xi.abs().ln()))
        .collect();
    if pts.len() < 3 {
        return None;
    }
    let n = pts.len() as f64;
    let (mt, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mt).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mt) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Settling time: the earliest `ts >= t[start]` such that `|x - target| <= band` for every
/// sample from `ts` up to (not including) index `end`; returned relative to `t[start]`.
/// `None` if the series never settles before `end`.
pub fn settling_time(
    t: &[f64],
    x: &[f64],
    target: f64,
    band: f64,
    start: usize,
    end: usize,
) -> Option<f64> {
    let end = end.min(x.len()).min(t.len());
    if start >= end {
        return None;
    }
    // Walk back from the end while inside the band.
    let mut k = end;
    while k > start && (x[k - 1] - target).abs() <= band {
        k -= 1;
    }
    (k < end).then(|| t[k] - t[start])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_known_sinusoid_with_trend_and_ripple() {
        let w = 1.2e-3;
        let t: Vec<f64> = (0..14_400).map(|k| k as f64).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&t| 3.0 - 0.3 * t + 100.0 * (w * t + 0.4).cos() + 5.0 * (0.1 * t).sin())
            .collect();
        let f = fit_sinusoid(&t, &x, w / 4.0, w * 4.0).unwrap();
        assert!((f.frequency / w - 1.0).abs() < 1e-3, "{f:?}");
        assert!((f.slope + 0.3).abs() < 3e-3, "{f:?}");
    }

    #[test]
    fn e_fold_time_of_a_pure_cosh() {
        let tau = 570.0;
        let x: Vec<f64> = (0..3600)
            .map(|k| 3.0 * (k as f64 / tau).cosh() - (k as f64 / tau).sinh())
            .collect();
        let m = e_fold_time(&x, 1.0, 60).unwrap();
        assert!((m / tau - 1.0).abs() < 1e-9, "{m}");
    }

    #[test]
    fn settling_walks_back_from_the_end() {
        let t: Vec<f64> = (0..10).map(f64::from).collect();
        let x = [5.0, 4.0, 3.0, 0.5, 2.0, 0.4, 0.3, 0.2, 0.1, 0.0];
        assert_eq!(settling_time(&t, &x, 0.0, 1.0, 0, 10), Some(5.0));
        assert_eq!(settling_time(&t, &x, 0.0, 1.0, 2, 10), Some(3.0));
        assert_eq!(settling_time(&t, &x, 0.0, 1e-3, 0, 9), None);
    }
}
