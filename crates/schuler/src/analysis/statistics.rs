//! Statistics of navigation errors over a run, as `schuler compare` and the aided
//! run's report give them.
//!
//! For each error `e` over the matched epochs: RMS, the largest `|e|` and the time of
//! its first occurrence, the 95th percentile of `|e|` and the mean of `e` (signed: a
//! bias shows). Percentiles are nearest-rank: the `P`th percentile of `n` values is the
//! `ceil(P n / 100)`th smallest, the smallest value that at least `P` % of the epochs
//! do not exceed (so of 1..100 m the 95th is 95 m). CEP is the 50th percentile of the
//! horizontal error, CEP95 the 95th. Given outage intervals, per interval (ends included) the
//! largest horizontal, vertical and per-axis attitude error, and the RMS of those
//! maxima over the intervals holding an epoch (the protocol of the KF-GINS paper).

use super::errors::{EpochErrors, Matching, NavRecord, match_epochs};
use crate::rotation::Euler;

/// RMS, largest magnitude, 95th percentile and mean of one error over the epochs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Root mean square.
    pub rms: f64,
    /// Largest `|e|`.
    pub max_abs: f64,
    /// Time of the first epoch where `|e|` is largest [s of week].
    pub t_max_sow: f64,
    /// 95th percentile (nearest rank) of `|e|`.
    pub p95_abs: f64,
    /// Mean of the signed error.
    pub mean: f64,
}

/// The `p`th percentile (nearest rank, `0 < p <= 100`) of values sorted ascending:
/// the `ceil(p n / 100)`th smallest. `None` for no values.
pub fn percentile_sorted(sorted: &[f64], p: f64) -> Option<f64> {
    let n = sorted.len();
    let rank = ((p * n as f64 / 100.0).ceil() as usize).clamp(1, n.max(1));
    sorted.get(rank - 1).copied()
}

impl Summary {
    /// The summary of errors `e` at times `t` (same length); `None` when empty.
    pub fn of(t: &[f64], e: &[f64]) -> Option<Summary> {
        if e.is_empty() {
            return None;
        }
        let n = e.len() as f64;
        let (mut sum, mut sum2, mut max_abs, mut t_max) = (0.0, 0.0, -1.0, t[0]);
        for (&ti, &x) in t.iter().zip(e) {
            sum += x;
            sum2 += x * x;
            if x.abs() > max_abs {
                max_abs = x.abs();
                t_max = ti;
            }
        }
        let mut abs: Vec<f64> = e.iter().map(|x| x.abs()).collect();
        abs.sort_unstable_by(f64::total_cmp);
        let (mut rms, mut mean) = ((sum2 / n).sqrt(), sum / n);
        if !(rms.is_finite() && mean.is_finite()) && max_abs.is_finite() {
            // Squares (or sums) of errors beyond 1e154 overflow: scaled by the largest,
            // the same statistics stay finite (used only then, so that ordinary
            // errors keep the bits of the plain sums).
            (rms, mean) = scaled_rms_mean(e, max_abs);
        }
        Some(Summary {
            rms,
            max_abs,
            t_max_sow: t_max,
            p95_abs: percentile_sorted(&abs, 95.0)?,
            mean,
        })
    }
}

/// Root mean square and mean of `e` as `m sqrt(Σ(x/m)²/n)` and `m Σ(x/m)/n`, with
/// `m` the largest `|x|`: finite for any finite errors.
fn scaled_rms_mean(e: &[f64], m: f64) -> (f64, f64) {
    if m == 0.0 {
        return (0.0, 0.0);
    }
    let n = e.len() as f64;
    let (s, s2) = e
        .iter()
        .fold((0.0, 0.0), |(s, s2), x| (s + x / m, s2 + (x / m) * (x / m)));
    (m * (s2 / n).sqrt(), m * (s / n))
}

/// One error quantity of the table: its name, unit, and value for an epoch.
#[derive(Debug, Clone, Copy)]
pub struct Quantity {
    /// Name in the table.
    pub name: &'static str,
    /// Unit of the value.
    pub unit: &'static str,
    /// The epoch's error in that unit.
    pub of: fn(&EpochErrors) -> f64,
}

const fn q(name: &'static str, unit: &'static str, of: fn(&EpochErrors) -> f64) -> Quantity {
    Quantity { name, unit, of }
}

/// The error quantities summarized, in table order.
pub const QUANTITIES: [Quantity; 11] = [
    q("north", "m", |e| e.pos_n.x),
    q("east", "m", |e| e.pos_n.y),
    q("horizontal", "m", |e| e.horizontal()),
    q("vertical (down)", "m", |e| e.pos_n.z),
    q("3-D", "m", |e| e.pos_n.norm()),
    q("v north", "m/s", |e| e.v_n.x),
    q("v east", "m/s", |e| e.v_n.y),
    q("v down", "m/s", |e| e.v_n.z),
    q("roll", "deg", |e| e.att.roll.to_degrees()),
    q("pitch", "deg", |e| e.att.pitch.to_degrees()),
    q("yaw", "deg", |e| e.att.yaw.to_degrees()),
];

/// The largest errors inside one outage interval (ends included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutageMax {
    /// Interval start [s of week].
    pub from_sow: f64,
    /// Interval end [s of week].
    pub to_sow: f64,
    /// Matched epochs inside.
    pub epochs: usize,
    /// Largest horizontal error [m] (0 without epochs).
    pub horizontal: f64,
    /// Largest `|dD|` [m].
    pub vertical: f64,
    /// Largest `|roll|`, `|pitch|`, `|yaw|` error [rad].
    pub att: Euler,
}

/// Every statistic `schuler compare` reports.
#[derive(Debug, Clone, PartialEq)]
pub struct Statistics {
    /// Matched epochs.
    pub epochs: usize,
    /// One summary per entry of [`QUANTITIES`] (in its units), in that order.
    pub summaries: Vec<Summary>,
    /// 50th percentile of the horizontal error [m].
    pub cep: f64,
    /// 95th percentile of the horizontal error [m].
    pub cep95: f64,
    /// Per outage interval, in the order given.
    pub outages: Vec<OutageMax>,
    /// RMS over the intervals with epochs of their maxima (same fields as an
    /// [`OutageMax`]; `epochs` counts the intervals); `None` without such intervals.
    pub outage_rms: Option<OutageMax>,
}

impl Statistics {
    /// The summary of a quantity by its name in [`QUANTITIES`].
    pub fn get(&self, name: &str) -> Option<&Summary> {
        QUANTITIES
            .iter()
            .position(|q| q.name == name)
            .and_then(|i| self.summaries.get(i))
    }
}

/// Statistics of the matched epochs' errors and the largest errors per outage
/// interval; `None` without epochs.
pub fn statistics(errors: &[EpochErrors], outages: &[(f64, f64)]) -> Option<Statistics> {
    if errors.is_empty() {
        return None;
    }
    let t: Vec<f64> = errors.iter().map(|e| e.t_sow).collect();
    let mut summaries = Vec::with_capacity(QUANTITIES.len());
    for quantity in QUANTITIES {
        let v: Vec<f64> = errors.iter().map(quantity.of).collect();
        summaries.push(Summary::of(&t, &v)?);
    }
    let mut hor: Vec<f64> = errors.iter().map(EpochErrors::horizontal).collect();
    hor.sort_unstable_by(f64::total_cmp);
    let mut per_outage = Vec::with_capacity(outages.len());
    for &(from, to) in outages {
        let mut o = OutageMax {
            from_sow: from,
            to_sow: to,
            epochs: 0,
            horizontal: 0.0,
            vertical: 0.0,
            att: Euler::default(),
        };
        for e in errors.iter().filter(|e| e.t_sow >= from && e.t_sow <= to) {
            o.epochs += 1;
            o.horizontal = o.horizontal.max(e.horizontal());
            o.vertical = o.vertical.max(e.pos_n.z.abs());
            o.att.roll = o.att.roll.max(e.att.roll.abs());
            o.att.pitch = o.att.pitch.max(e.att.pitch.abs());
            o.att.yaw = o.att.yaw.max(e.att.yaw.abs());
        }
        per_outage.push(o);
    }
    let with: Vec<&OutageMax> = per_outage.iter().filter(|o| o.epochs > 0).collect();
    let outage_rms = (!with.is_empty()).then(|| {
        let rms = |f: fn(&OutageMax) -> f64| {
            let plain = (with.iter().map(|o| f(o).powi(2)).sum::<f64>() / with.len() as f64).sqrt();
            if plain.is_finite() {
                return plain;
            }
            let xs: Vec<f64> = with.iter().map(|o| f(o)).collect();
            scaled_rms_mean(&xs, xs.iter().fold(0.0, |m: f64, x| m.max(x.abs()))).0
        };
        OutageMax {
            from_sow: with[0].from_sow,
            to_sow: with[with.len() - 1].to_sow,
            epochs: with.len(),
            horizontal: rms(|o| o.horizontal),
            vertical: rms(|o| o.vertical),
            att: Euler::new(
                rms(|o| o.att.roll),
                rms(|o| o.att.pitch),
                rms(|o| o.att.yaw),
            ),
        }
    });
    Some(Statistics {
        epochs: errors.len(),
        summaries,
        cep: percentile_sorted(&hor, 50.0)?,
        cep95: percentile_sorted(&hor, 95.0)?,
        outages: per_outage,
        outage_rms,
    })
}

/// Why a comparison has nothing to report.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CompareError {
    /// No NAV epoch lies inside both the window and the truth's span.
    #[error(
        "no epoch to compare: {before} before the truth's span, {after} after it, \
         {outside} outside --start/--end (NAV {nav_from}..{nav_to} s, truth {truth_from}..{truth_to} s)"
    )]
    NoOverlap {
        /// Epochs before the truth.
        before: usize,
        /// Epochs after the truth.
        after: usize,
        /// Epochs outside the window.
        outside: usize,
        /// NAV span [s of week].
        nav_from: f64,
        /// NAV span end.
        nav_to: f64,
        /// Truth span [s of week].
        truth_from: f64,
        /// Truth span end.
        truth_to: f64,
    },
}

/// A comparison: every epoch's errors, how the epochs matched, and the statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Errors per matched epoch, in NAV order.
    pub errors: Vec<EpochErrors>,
    /// How the epochs met the truth.
    pub matching: Matching,
    /// The statistics.
    pub stats: Statistics,
}

/// Compares parsed NAV rows with truth rows (both sorted by time): match the epochs,
/// compute the errors and their statistics.
pub fn compare(
    nav: &[NavRecord],
    truth: &[NavRecord],
    start: Option<f64>,
    end: Option<f64>,
    outages: &[(f64, f64)],
) -> Result<Comparison, CompareError> {
    let (errors, matching) = match_epochs(nav, truth, start, end);
    let span = |r: &[NavRecord]| {
        (
            r.first().map_or(f64::NAN, |x| x.t_sow),
            r.last().map_or(f64::NAN, |x| x.t_sow),
        )
    };
    let Some(stats) = statistics(&errors, outages) else {
        let (nav_from, nav_to) = span(nav);
        let (truth_from, truth_to) = span(truth);
        return Err(CompareError::NoOverlap {
            before: matching.before_truth,
            after: matching.after_truth,
            outside: matching.outside_window,
            nav_from,
            nav_to,
            truth_from,
            truth_to,
        });
    };
    Ok(Comparison {
        errors,
        matching,
        stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_errors_give_finite_statistics() {
        // rms of (m, 0, -m) is m sqrt(2/3), mean 0: the plain sum of squares is inf.
        let m = 1.5e308;
        let s = Summary::of(&[0.0, 1.0, 2.0], &[m, 0.0, -m]).expect("values");
        assert!(s.rms.is_finite() && s.mean.is_finite());
        // Scaled by m, every step is exact to an ulp or two.
        assert!((s.rms / (m * (2.0f64 / 3.0).sqrt()) - 1.0).abs() < 4.0 * f64::EPSILON);
        assert_eq!(s.mean, 0.0);
        assert_eq!(s.max_abs, m);
        // Ordinary errors keep the plain sums' bits.
        let s = Summary::of(&[0.0, 1.0], &[3.0, 4.0]).expect("values");
        assert_eq!(s.rms, (25.0f64 / 2.0).sqrt());
        assert_eq!(s.mean, 3.5);
    }
}
