//! Streaming statistics of one stream, in constant memory: record count, span, the
//! spacing's mean and standard deviation (Welford's update), its median over the first
//! [`MEDIAN_SPACINGS`] spacings, and the gaps longer than [`GAP_FACTOR`] medians.

use serde::Serialize;

/// Spacings whose median is the stream's nominal spacing (held until then).
pub const MEDIAN_SPACINGS: usize = 4096;
/// A spacing longer than this many median spacings is a gap.
pub const GAP_FACTOR: f64 = 5.0;
/// Gaps listed one by one (the rest only counted).
pub const GAPS_LISTED: usize = 5;

/// One gap: its start and length [s].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Gap {
    /// The time of the record before it [s].
    pub t: f64,
    /// Its length [s].
    pub length_s: f64,
}

/// The gaps of a stream.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Gaps {
    /// How many.
    pub count: u64,
    /// Their total length [s].
    pub total_s: f64,
    /// The longest [s].
    pub longest_s: f64,
    /// The first few ([`GAPS_LISTED`]).
    pub first: Vec<Gap>,
}

/// The time statistics of one stream.
#[derive(Debug, Clone, Default)]
pub struct Timing {
    count: u64,
    first: f64,
    last: f64,
    /// Welford's running mean and sum of squared deviations of the spacing.
    mean: f64,
    m2: f64,
    spacings: u64,
    /// The first spacings (with the time before each), until the median is known.
    held: Vec<(f64, f64)>,
    median: Option<f64>,
    gaps: Gaps,
    /// Records whose time does not increase.
    pub not_increasing: u64,
}

impl Timing {
    /// Takes in a record at `t`.
    pub fn add(&mut self, t: f64) {
        if self.count == 0 {
            self.first = t;
        } else {
            let dt = t - self.last;
            if dt <= 0.0 {
                self.not_increasing += 1;
            }
            self.spacings += 1;
            let d = dt - self.mean;
            self.mean += d / self.spacings as f64;
            self.m2 += d * (dt - self.mean);
            match self.median {
                Some(m) => self.check_gap(self.last, dt, m),
                None => {
                    self.held.push((self.last, dt));
                    if self.held.len() >= MEDIAN_SPACINGS {
                        self.settle();
                    }
                }
            }
        }
        self.last = t;
        self.count += 1;
    }

    /// The median of the held spacings, and their gaps.
    fn settle(&mut self) {
        if self.median.is_some() || self.held.is_empty() {
            return;
        }
        let mut s: Vec<f64> = self.held.iter().map(|h| h.1).collect();
        s.sort_by(f64::total_cmp);
        let n = s.len();
        let m = if n % 2 == 1 {
            s[n / 2]
        } else {
            0.5 * (s[n / 2 - 1] + s[n / 2])
        };
        self.median = Some(m);
        for (t, dt) in std::mem::take(&mut self.held) {
            self.check_gap(t, dt, m);
        }
    }

    fn check_gap(&mut self, t: f64, dt: f64, median: f64) {
        if median > 0.0 && dt > GAP_FACTOR * median {
            let g = &mut self.gaps;
            g.count += 1;
            g.total_s += dt;
            g.longest_s = g.longest_s.max(dt);
            if g.first.len() < GAPS_LISTED {
                g.first.push(Gap { t, length_s: dt });
            }
        }
    }

    /// The summary, once every record is in.
    pub fn finish(mut self) -> TimingSummary {
        self.settle();
        let span = self.last - self.first;
        let jitter = if self.spacings > 1 {
            (self.m2 / (self.spacings - 1) as f64).sqrt()
        } else {
            0.0
        };
        TimingSummary {
            records: self.count,
            t_first: (self.count > 0).then_some(self.first),
            t_last: (self.count > 0).then_some(self.last),
            span_s: if self.count > 0 { span } else { 0.0 },
            rate_hz: if self.count > 1 && span > 0.0 {
                (self.count - 1) as f64 / span
            } else {
                0.0
            },
            spacing_median_s: self.median,
            jitter_s: jitter,
            gaps: self.gaps,
            not_increasing: self.not_increasing,
        }
    }
}

/// A stream's timing (in `inspect --json`: the keys below).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TimingSummary {
    /// Records read.
    pub records: u64,
    /// First and last record time [s, the log's clock].
    pub t_first: Option<f64>,
    /// See `t_first`.
    pub t_last: Option<f64>,
    /// `t_last − t_first` [s].
    pub span_s: f64,
    /// Mean rate `(records − 1) / span` [Hz].
    pub rate_hz: f64,
    /// Median spacing [s] (of the first [`MEDIAN_SPACINGS`]).
    pub spacing_median_s: Option<f64>,
    /// Jitter: the standard deviation of the spacing [s].
    pub jitter_s: f64,
    /// Spacings longer than [`GAP_FACTOR`] medians.
    pub gaps: Gaps,
    /// Records whose time did not increase.
    pub not_increasing: u64,
}

/// The median of positive values in constant memory: a histogram of logarithmic
/// bins from 1 mm to 100 km, 100 per decade (each 2.3 % wide; the median is given
/// as its bin's geometric centre, within 1.2 %).
#[derive(Debug, Clone)]
pub struct LogMedian {
    bins: Vec<u64>,
    n: u64,
}

impl Default for LogMedian {
    fn default() -> Self {
        Self {
            bins: vec![0; LOG_BINS],
            n: 0,
        }
    }
}

const LOG_MIN: f64 = -3.0;
const PER_DECADE: f64 = 100.0;
const LOG_BINS: usize = 800;

impl LogMedian {
    /// Takes in `x` (values outside the range fall in the end bins).
    pub fn add(&mut self, x: f64) {
        if !x.is_finite() || x <= 0.0 {
            return;
        }
        let k = ((x.log10() - LOG_MIN) * PER_DECADE).floor();
        let k = k.clamp(0.0, (LOG_BINS - 1) as f64) as usize;
        self.bins[k] += 1;
        self.n += 1;
    }

    /// The median, if any value was taken in.
    pub fn median(&self) -> Option<f64> {
        if self.n == 0 {
            return None;
        }
        let half = self.n.div_ceil(2);
        let mut seen = 0;
        for (k, &c) in self.bins.iter().enumerate() {
            seen += c;
            if seen >= half {
                return Some(10f64.powf(LOG_MIN + (k as f64 + 0.5) / PER_DECADE));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_regular_stream_with_one_gap() {
        // 100 Hz for 10 s with a 0.2-s hole after t = 3 s: the gap is 20 spacings.
        let mut t = Timing::default();
        let times: Vec<f64> = (0..=1000)
            .map(|k| k as f64 * 0.01)
            .filter(|&x| !(x > 3.0 + 1e-9 && x < 3.2 - 1e-9))
            .collect();
        for &x in &times {
            t.add(x);
        }
        let s = t.finish();
        assert_eq!(s.records, times.len() as u64);
        assert!((s.spacing_median_s.expect("median") - 0.01).abs() < 1e-12);
        assert_eq!(s.gaps.count, 1);
        assert!((s.gaps.first[0].t - 3.0).abs() < 1e-9);
        assert!((s.gaps.longest_s - 0.2).abs() < 1e-9);
        // Mean rate over the span: (n − 1) / 10 s.
        assert!((s.rate_hz - (times.len() - 1) as f64 / 10.0).abs() < 1e-9);
        assert!(s.jitter_s > 0.0);
    }

    #[test]
    fn the_log_median_is_within_its_bin() {
        let mut m = LogMedian::default();
        for x in [0.5, 1.0, 2.0, 3.0, 100.0] {
            m.add(x);
        }
        let med = m.median().expect("median");
        assert!((med / 2.0 - 1.0).abs() < 0.012, "{med}");
        assert_eq!(LogMedian::default().median(), None);
    }
}
