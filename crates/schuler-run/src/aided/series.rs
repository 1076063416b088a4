//! The series a report plot draws, built from a stored record in bounded memory: at
//! most [`CAP`] points are kept as they are; a longer series is thinned to the
//! lowest and highest value of each run of consecutive points (as the SVG writer
//! thins each pixel column, [`schuler_report::plot`]), so a 10-hour run's plot costs the
//! memory of a 1-hour one's and keeps its extremes (outliers, spikes) visible.
//!
//! Lines break across data gaps: a NaN point goes before each step longer than twice
//! the median step. The median is over every step of a series of up to [`CAP`]
//! points (so such a series is the one drawn before the thinning existed) and over its
//! first [`CAP`] steps beyond.

/// Points kept as they are (a 1-Hz series of 68 minutes).
pub const CAP: usize = 4096;

/// Times and `K` values per point, with NaN points at the gaps.
#[derive(Debug, Clone, PartialEq)]
pub struct Series<const K: usize> {
    /// Times (NaN at a gap).
    pub t: Vec<f64>,
    /// Values (NaN at a gap).
    pub v: Vec<[f64; K]>,
}

impl<const K: usize> Series<K> {
    /// Column `k` of the values.
    pub fn column(&self, k: usize) -> Vec<f64> {
        self.v.iter().map(|v| v[k]).collect()
    }

    /// The points of columns `k` without the gaps' NaN points, as `(t, v_k)`.
    pub fn ungapped(&self, k: usize) -> (Vec<f64>, Vec<f64>) {
        self.t
            .iter()
            .zip(&self.v)
            .filter(|(t, _)| !t.is_nan())
            .map(|(&t, v)| (t, v[k]))
            .unzip()
    }

    fn push(&mut self, t: f64, v: [f64; K]) {
        self.t.push(t);
        self.v.push(v);
    }

    fn gap(&mut self) {
        self.push(f64::NAN, [f64::NAN; K]);
    }
}

/// Twice the median of the steps of `t`, infinite without a step.
fn gap_limit(t: &[f64]) -> f64 {
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_unstable_by(f64::total_cmp);
    dt.get(dt.len() / 2).map_or(f64::INFINITY, |m| 2.0 * m)
}

/// The series of the points `points()` yields in time order (called twice: a count,
/// then the points), gaps marked; beyond [`CAP`] points, each run of `stride`
/// consecutive points between gaps (`stride` such that about `CAP / 2` runs remain)
/// is kept as its lowest and highest finite value of column `key`, in time order (its
/// first point when it has no finite one).
pub fn series<const K: usize, I>(points: impl Fn() -> I, key: usize) -> Series<K>
where
    I: Iterator<Item = (f64, [f64; K])>,
{
    let n = points().count();
    let head: Vec<(f64, [f64; K])> = points().take(CAP).collect();
    let limit = gap_limit(&head.iter().map(|p| p.0).collect::<Vec<f64>>());
    let mut out = Series {
        t: Vec::new(),
        v: Vec::new(),
    };
    if n <= CAP {
        for (k, &(t, v)) in head.iter().enumerate() {
            if k > 0 && t - head[k - 1].0 > limit {
                out.gap();
            }
            out.push(t, v);
        }
        return out;
    }
    drop(head);
    let stride = n.div_ceil(CAP / 2);
    let mut run = Run::default();
    let mut previous = f64::NAN;
    for (t, v) in points() {
        if t - previous > limit || run.len == stride {
            run.flush(&mut out);
            if t - previous > limit {
                out.gap();
            }
        }
        run.add(t, v, key);
        previous = t;
    }
    run.flush(&mut out);
    out
}

/// A run of consecutive points being thinned: its first, lowest and highest.
#[derive(Debug)]
struct Run<const K: usize> {
    len: usize,
    first: Option<(usize, f64, [f64; K])>,
    low: Option<(usize, f64, [f64; K])>,
    high: Option<(usize, f64, [f64; K])>,
}

impl<const K: usize> Default for Run<K> {
    fn default() -> Self {
        Self {
            len: 0,
            first: None,
            low: None,
            high: None,
        }
    }
}

impl<const K: usize> Run<K> {
    fn add(&mut self, t: f64, v: [f64; K], key: usize) {
        let p = (self.len, t, v);
        self.len += 1;
        self.first.get_or_insert(p);
        let y = v[key];
        if !y.is_finite() {
            return;
        }
        if self.low.is_none_or(|l| y < l.2[key]) {
            self.low = Some(p);
        }
        if self.high.is_none_or(|h| y > h.2[key]) {
            self.high = Some(p);
        }
    }

    /// Appends the kept points to `out` and empties the run.
    fn flush(&mut self, out: &mut Series<K>) {
        let run = std::mem::take(self);
        let mut keep: Vec<(usize, f64, [f64; K])> = match (run.low, run.high) {
            (Some(l), Some(h)) => vec![l, h],
            _ => run.first.into_iter().collect(),
        };
        keep.sort_by_key(|p| p.0);
        keep.dedup_by_key(|p| p.0);
        for (_, t, v) in keep {
            out.push(t, v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Up to CAP points the series is the one drawn before: every point, a NaN point
    /// before each step longer than twice the median step.
    #[test]
    fn a_short_series_is_kept_whole_with_its_gaps() {
        let t = [0.0, 1.0, 2.0, 3.0, 63.0, 64.0, 65.0];
        let s = series(|| t.iter().map(|&t| (t, [t * 2.0])), 0);
        let shown: Vec<String> = s.t.iter().map(|t| t.to_string()).collect();
        assert_eq!(shown, ["0", "1", "2", "3", "NaN", "63", "64", "65"]);
        assert_eq!(s.v[5], [126.0]);
        assert_eq!(s.ungapped(0).0, t);
    }

    /// A long series keeps at most about CAP points whatever its length, keeps its
    /// extremes (a single spike among 100 000 points) and its gap.
    #[test]
    fn a_long_series_is_bounded_and_keeps_extremes_and_gaps() {
        for n in [CAP + 1, 40_000, 100_000] {
            let t = |k: usize| {
                if k < n / 2 {
                    k as f64
                } else {
                    k as f64 + 500.0
                }
            };
            let y = |k: usize| if k == n / 3 { 1e6 } else { (k % 7) as f64 };
            let s = series(|| (0..n).map(|k| (t(k), [y(k), -y(k)])), 0);
            assert!(s.t.len() <= CAP + 3, "{n}: {} points", s.t.len());
            assert!(s.v.iter().any(|v| v[0] == 1e6 && v[1] == -1e6), "{n}");
            let gaps = s.t.iter().filter(|t| t.is_nan()).count();
            assert_eq!(gaps, 1, "{n}");
            assert!(s.t.iter().filter(|t| !t.is_nan()).is_sorted(), "{n}");
        }
    }
}
