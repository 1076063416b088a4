//! Overlapping Allan deviation (IEEE Std 952-1997 annex C; Riley, NIST SP 1065 §5.2.4)
//! of IMU logs, its confidence, and the IEEE Std 952 noise terms fitted to it.
//!
//! From the integrated signal `θ_k` (the running sum of increments, e.g. angle from
//! gyro increments) sampled every `dt`, for a cluster of `m` samples (`τ = m dt`):
//!
//! `σ²(τ) = Σ_{k=0}^{N-2m-1} (θ_{k+2m} − 2 θ_{k+m} + θ_k)² / (2 τ² (N − 2m))`.
//!
//! White rate noise of density `N` gives `σ(τ) = N / sqrt(τ)` (slope −1/2); a rate
//! random walk `K` gives `σ(τ) = K sqrt(τ/3)` (slope +1/2).
//!
//! - here: one cumulative sum per channel ([`Cumulative`]) serves every cluster size,
//!   each in O(N); [`ImuAllan`] holds the six channels of a log at log-spaced cluster
//!   sizes ([`cluster_sizes`]);
//! - [`confidence`]: equivalent degrees of freedom and chi-square intervals of each
//!   point;
//! - [`spectral`]: the noise terms' spectra and the covariance of the estimates
//!   between cluster sizes;
//! - [`fit`]: the IEEE Std 952 terms (and the filter's Gauss–Markov bias) fitted by
//!   weighted least squares, with confidence intervals.

pub mod confidence;
pub mod fit;
pub mod spectral;
#[cfg(test)]
mod tests;

use crate::imu::ImuSample;

/// The integrated signal of one channel: `θ_0 = 0`, `θ_{k+1} = θ_k + (x_k − x̄)` for
/// increments `x_k` over `dt` seconds each (the mean `x̄` removed: a constant rate
/// has no Allan variance, and the sums stay small against the noise).
///
/// A log with gaps is a set of uniformly sampled segments: `θ` runs on over the gap
/// (the sample that spans it left out), and a second difference is taken only inside
/// one segment, so the overlapping sum pools the segments' terms (Riley, NIST SP 1065
/// §5.2.4 applied to each segment, the sums and counts added).
#[derive(Debug, Clone, PartialEq)]
pub struct Cumulative {
    theta: Vec<f64>,
    dt: f64,
    /// Indices of `θ` where one segment ends and the next begins (increasing).
    breaks: Vec<usize>,
}

impl Cumulative {
    /// The running sum of `increments` (one per `dt` seconds), mean removed.
    pub fn new(increments: &[f64], dt: f64) -> Self {
        Self::from_iter(increments.iter().copied(), increments.len(), dt, Vec::new())
    }

    /// The running sum of `n` increments given by `values` twice (once for the mean),
    /// segments ending at the `θ` indices `breaks`.
    fn from_iter(
        values: impl Iterator<Item = f64> + Clone,
        n: usize,
        dt: f64,
        breaks: Vec<usize>,
    ) -> Self {
        let mean = values.clone().sum::<f64>() / n.max(1) as f64;
        let mut theta = Vec::with_capacity(n + 1);
        theta.push(0.0);
        let mut acc = 0.0;
        for x in values {
            acc += x - mean;
            theta.push(acc);
        }
        Self { theta, dt, breaks }
    }

    /// Number of increments `N`.
    pub fn samples(&self) -> usize {
        self.theta.len() - 1
    }

    /// The segments as ranges of `θ` indices `[start, end)`.
    fn segments(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        let ends = self.breaks.iter().copied().chain([self.theta.len() - 1]);
        let starts = std::iter::once(0).chain(self.breaks.iter().copied());
        starts.zip(ends).map(|(a, b)| a..b + 1)
    }

    /// Number of second differences in the overlapping sum at cluster size `m`:
    /// `N + 1 − 2m` (0 when there are none), summed over the segments.
    pub fn terms(&self, m: usize) -> usize {
        self.segments().map(|r| r.len().saturating_sub(2 * m)).sum()
    }

    /// Allan variance `σ²(m dt)` of the rate [(unit/s)²] (module doc); `None` if `m`
    /// is 0 or no segment holds `2m + 1` points of `θ`.
    pub fn avar(&self, m: usize) -> Option<f64> {
        let terms = self.terms(m);
        if m == 0 || terms == 0 {
            return None;
        }
        let t = &self.theta;
        let sum: f64 = self
            .segments()
            .flat_map(|r| r.start..r.end.saturating_sub(2 * m))
            .map(|k| {
                let d = t[k + 2 * m] - 2.0 * t[k + m] + t[k];
                d * d
            })
            .sum();
        let tau = m as f64 * self.dt;
        Some(sum / (2.0 * tau * tau * terms as f64))
    }
}

/// Allan deviation of the rate whose increments are `increments` (one per `dt`
/// seconds) at cluster size `m`: `sqrt` of [`Cumulative::avar`]; `None` if there are
/// fewer than `2m + 1` samples or `m` is 0.
pub fn allan_deviation(increments: &[f64], dt: f64, m: usize) -> Option<f64> {
    Cumulative::new(increments, dt).avar(m).map(f64::sqrt)
}

/// Log-spaced cluster sizes `m = round(10^(k / per_decade))`, `k = 0, 1, ...`, each
/// once, from 1 up to `m_max`.
pub fn cluster_sizes(per_decade: f64, m_max: usize) -> Vec<usize> {
    let mut sizes: Vec<usize> = Vec::new();
    for k in 0.. {
        let m = 10f64.powf(k as f64 / per_decade).round() as usize;
        if m > m_max {
            break;
        }
        if sizes.last() != Some(&m) {
            sizes.push(m);
        }
    }
    sizes
}

/// One point of an Allan curve: `σ²(τ)` at `τ = m dt` from `terms` second differences.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AllanPoint {
    /// Cluster size `m`.
    pub m: usize,
    /// Cluster time `τ = m dt` [s].
    pub tau: f64,
    /// Allan variance `σ²(τ)` [(unit/s)²].
    pub avar: f64,
    /// Number of second differences averaged, `N + 1 − 2m`.
    pub terms: usize,
}

impl AllanPoint {
    /// Allan deviation `σ(τ) = sqrt(σ²(τ))`.
    pub fn adev(&self) -> f64 {
        self.avar.sqrt()
    }
}

/// One channel's Allan variances at several cluster sizes.
#[derive(Debug, Clone, PartialEq)]
pub struct AllanCurve {
    /// Sample interval [s].
    pub dt: f64,
    /// Number of increments `N`.
    pub samples: usize,
    /// The points, `τ` increasing.
    pub points: Vec<AllanPoint>,
}

impl AllanCurve {
    /// The Allan variances of `c` at the cluster sizes `sizes` (those with at least
    /// one second difference).
    pub fn of(c: &Cumulative, sizes: &[usize]) -> Self {
        let points = sizes
            .iter()
            .filter_map(|&m| {
                c.avar(m).map(|avar| AllanPoint {
                    m,
                    tau: m as f64 * c.dt,
                    avar,
                    terms: c.terms(m),
                })
            })
            .collect();
        Self {
            dt: c.dt,
            samples: c.samples(),
            points,
        }
    }

    /// The curve of `increments` (one per `dt` seconds) at the cluster sizes `sizes`.
    pub fn from_increments(increments: &[f64], dt: f64, sizes: &[usize]) -> Self {
        Self::of(&Cumulative::new(increments, dt), sizes)
    }
}

/// The median of the samples' intervals [s] (0 without samples): the log's usual
/// interval, which a few gaps do not move.
fn median_interval(samples: &[ImuSample]) -> f64 {
    let mut dt: Vec<f64> = samples.iter().map(|s| s.dt).collect();
    if dt.is_empty() {
        return 0.0;
    }
    let mid = dt.len() / 2;
    *dt.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Names of the six channels, in [`ImuAllan::channels`] order.
pub const CHANNEL_NAMES: [&str; 6] = [
    "gyro x", "gyro y", "gyro z", "accel x", "accel y", "accel z",
];

/// Fewest cluster sizes an [`ImuAllan`] needs: two decades at 10 per decade, so the
/// terms of different slopes can be told apart.
pub const MIN_DECADES: f64 = 2.0;

/// How to build an [`ImuAllan`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveOptions {
    /// Cluster sizes per decade (default 10).
    pub per_decade: f64,
    /// Longest cluster time [s]; `None`: a tenth of the log (the overlapping estimate
    /// there still averages `0.8 N` second differences, about 12 degrees of freedom
    /// for white noise).
    pub max_tau: Option<f64>,
}

impl Default for CurveOptions {
    fn default() -> Self {
        Self {
            per_decade: 10.0,
            max_tau: None,
        }
    }
}

/// Why a log gives no Allan curve.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AllanError {
    /// The log is shorter than ten times the longest cluster time.
    #[error(
        "{samples} samples cover {span:.1} s: too short for a longest cluster time of \
         {max_tau:.1} s (the log must last ten times it, {needed:.1} s)"
    )]
    TooShort {
        /// Number of samples.
        samples: usize,
        /// Time the samples cover [s].
        span: f64,
        /// The longest cluster time asked for [s].
        max_tau: f64,
        /// Log length needed [s].
        needed: f64,
    },
    /// The longest cluster time is under [`MIN_DECADES`] decades above the sample
    /// interval.
    #[error(
        "the longest cluster time {max_tau} s is less than {MIN_DECADES} decades above the \
         sample interval {dt} s: {samples} samples are too few to tell the noise terms apart"
    )]
    TooFewDecades {
        /// Number of samples.
        samples: usize,
        /// Sample interval [s].
        dt: f64,
        /// The longest cluster time [s].
        max_tau: f64,
    },
    /// A sample has a non-finite or non-positive interval or a non-finite increment.
    #[error("sample {index} (t = {t}) has a non-finite increment or a non-positive interval")]
    BadSample {
        /// Index of the sample.
        index: usize,
        /// Its time [s].
        t: f64,
    },
}

/// The Allan curves of the six channels of a static IMU log: gyro x, y, z (rate in
/// rad/s) then accelerometer x, y, z (specific force in m/s²).
#[derive(Debug, Clone, PartialEq)]
pub struct ImuAllan {
    /// Mean sample interval `Σ dt / N` [s] (the estimate assumes uniform sampling).
    pub dt: f64,
    /// Number of samples.
    pub samples: usize,
    /// Mean angular rate [rad/s] and specific force [m/s²] over the log, per channel.
    pub mean: [f64; 6],
    /// The curves, [`CHANNEL_NAMES`] order.
    pub channels: [AllanCurve; 6],
}

impl ImuAllan {
    /// The six channels' curves of `samples` at [`cluster_sizes`] up to the longest
    /// cluster time of `options`.
    pub fn from_samples(samples: &[ImuSample], options: &CurveOptions) -> Result<Self, AllanError> {
        if let Some((index, s)) = samples.iter().enumerate().find(|(_, s)| {
            !(s.dt.is_finite()
                && s.dt > 0.0
                && s.dtheta.iter().chain(s.dvel.iter()).all(|x| x.is_finite()))
        }) {
            return Err(AllanError::BadSample { index, t: s.t });
        }
        // A sample whose interval is over half again the usual spans a gap: it is left
        // out and the segments on either side are pooled (see [`Cumulative`]). Its
        // increment is the sensor's over its own interval (increment logs) or the
        // rate times the whole gap (rate logs); either way not one `dt`'s.
        let usual = median_interval(samples);
        let spans_gap = |s: &ImuSample| s.dt > 1.5 * usual;
        let kept = || samples.iter().filter(|s| !spans_gap(s));
        let mut breaks = Vec::new();
        let mut k = 0;
        for s in samples {
            if spans_gap(s) {
                if k > 0 && breaks.last() != Some(&k) {
                    breaks.push(k);
                }
            } else {
                k += 1;
            }
        }
        let breaks = breaks.into_iter().filter(|&b| b < k).collect::<Vec<_>>();
        let n = k;
        let span: f64 = kept().map(|s| s.dt).sum();
        let dt = span / n.max(1) as f64;
        let max_tau = options.max_tau.unwrap_or(span / 10.0);
        if !(n > 0 && 10.0 * max_tau <= span * (1.0 + 1e-12)) {
            return Err(AllanError::TooShort {
                samples: n,
                span,
                max_tau,
                needed: 10.0 * max_tau,
            });
        }
        if max_tau < 10f64.powf(MIN_DECADES) * dt {
            return Err(AllanError::TooFewDecades {
                samples: n,
                dt,
                max_tau,
            });
        }
        let sizes = cluster_sizes(options.per_decade, (max_tau / dt + 1e-9) as usize);
        let channel = |c: usize| {
            let x = kept().map(move |s| if c < 3 { s.dtheta[c] } else { s.dvel[c - 3] });
            let mean = x.clone().sum::<f64>() / span;
            let cumulative = Cumulative::from_iter(x, n, dt, breaks.clone());
            (AllanCurve::of(&cumulative, &sizes), mean)
        };
        let curves: [(AllanCurve, f64); 6] = std::array::from_fn(channel);
        Ok(Self {
            dt,
            samples: n,
            mean: std::array::from_fn(|c| curves[c].1),
            channels: curves.map(|(curve, _)| curve),
        })
    }
}
