//! A trajectory stored as knots and interpolated by quintic Hermite polynomials.
//!
//! Each knot holds a time and, for latitude, longitude, height and the three Euler
//! angles, the value and its first and second time derivatives. Between two knots each
//! component is the unique quintic matching all six end conditions, so position and
//! attitude are C² in time: velocity, acceleration and angular rate are continuous, and
//! [`super::analytic`] turns the curve into exact truth and exact IMU increments. A
//! motion generator that integrates commanded maneuvers only has to emit knots.

use super::analytic::Trajectory;
use super::jet::{Jet, JetMat3, JetVec3};

/// One knot: time [s] and, per component (lat, lon, h, roll, pitch, yaw; rad and m),
/// value, first and second derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knot {
    /// Time [s].
    pub t: f64,
    /// Values: lat, lon [rad], h [m], roll, pitch, yaw [rad] (angles unwrapped).
    pub value: [f64; 6],
    /// First derivatives per second.
    pub rate: [f64; 6],
    /// Second derivatives per second squared.
    pub accel: [f64; 6],
}

/// A C² trajectory through knots (at least two, strictly increasing times).
#[derive(Debug, Clone, PartialEq)]
pub struct SplineTrajectory {
    knots: Vec<Knot>,
    /// The knot times, apart from the knots: the interval search touches only these
    /// (a binary search through the 152-byte knots missed the cache at every step and
    /// cost more than the interpolation itself).
    times: Vec<f64>,
}

/// Why knots cannot form a trajectory.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SplineError {
    /// Fewer than two knots.
    #[error("a trajectory needs at least two knots, got {0}")]
    TooFewKnots(usize),
    /// Times not strictly increasing at the given knot index.
    #[error("knot {index}: time {t} s does not increase over the previous knot")]
    TimeNotIncreasing {
        /// Index of the offending knot.
        index: usize,
        /// Its time.
        t: f64,
    },
    /// A non-finite number at the given knot index.
    #[error("knot {0}: non-finite value")]
    NonFinite(usize),
}

impl SplineTrajectory {
    /// A trajectory through `knots`.
    pub fn new(knots: Vec<Knot>) -> Result<Self, SplineError> {
        if knots.len() < 2 {
            return Err(SplineError::TooFewKnots(knots.len()));
        }
        for (i, k) in knots.iter().enumerate() {
            let finite = k.t.is_finite()
                && k.value
                    .iter()
                    .chain(&k.rate)
                    .chain(&k.accel)
                    .all(|x| x.is_finite());
            if !finite {
                return Err(SplineError::NonFinite(i));
            }
            if i > 0 && k.t <= knots[i - 1].t {
                return Err(SplineError::TimeNotIncreasing { index: i, t: k.t });
            }
        }
        let times = knots.iter().map(|k| k.t).collect();
        Ok(Self { knots, times })
    }

    /// First knot time [s].
    pub fn start(&self) -> f64 {
        self.knots[0].t
    }

    /// Last knot time [s].
    pub fn end(&self) -> f64 {
        self.knots[self.knots.len() - 1].t
    }

    /// The knots.
    pub fn knots(&self) -> &[Knot] {
        &self.knots
    }

    /// Index of the interval holding `t` (clamped to the first and last): the `i`
    /// with `t_i <= t < t_{i+1}`.
    ///
    /// Motion knots are nearly evenly spaced (steps of [`super::motion::MAX_STEP`],
    /// shorter only at the ends of pieces), so the search starts from the proportional
    /// guess and gallops outwards to a bracket before bisecting it: a few steps in
    /// place of a dozen scattered ones, for any spacing.
    #[inline]
    pub(crate) fn interval(&self, t: f64) -> usize {
        let times = &self.times;
        let last = times.len() - 2; // the last interval
        let (first_t, last_t) = (times[0], times[last + 1]);
        let guess = (t - first_t) / (last_t - first_t) * (last + 1) as f64;
        // `as` truncates, which is the floor from 0 up, and saturates (negatives and
        // NaN to 0); then clamp into the intervals. (No `floor()`: without SSE4.1 it is
        // a call into libm.)
        let guess = (guess as usize).min(last);
        // Bracket [lo, hi) of candidate counts of knots with time <= t, minus one.
        let (mut lo, mut hi);
        if times[guess] <= t {
            lo = guess;
            let mut step = 1;
            hi = guess + 1;
            while hi <= last && times[hi] <= t {
                lo = hi;
                hi = (hi + step).min(last + 1);
                step *= 2;
            }
        } else {
            hi = guess;
            let mut step = 1;
            lo = guess.saturating_sub(1);
            while lo > 0 && times[lo] > t {
                hi = lo;
                lo = lo.saturating_sub(step);
                step *= 2;
            }
        }
        // Now times[lo] <= t (or lo == 0) and t < times[hi] (or hi == last + 1).
        lo + times[lo + 1..hi.max(lo + 1)].partition_point(|&x| x <= t)
    }

    /// The knot times.
    pub(crate) fn times(&self) -> &[f64] {
        &self.times
    }

    /// The knots around `t`, their spacing `h` and `s = (t - t_0)/h` in [0, 1].
    #[inline]
    fn locate(&self, t: f64) -> (&Knot, &Knot, f64, f64) {
        self.locate_on(self.interval(t), t)
    }

    /// [`Self::locate`] on the piece from knot `i` to knot `i + 1` (`t` outside it
    /// extends the piece's polynomial).
    #[inline]
    fn locate_on(&self, i: usize, t: f64) -> (&Knot, &Knot, f64, f64) {
        let (k0, k1) = (&self.knots[i], &self.knots[i + 1]);
        let h = k1.t - k0.t;
        (k0, k1, h, (t - k0.t) / h)
    }

    /// The quintic Hermite basis at `s`, for the weights of `p1 - p0`, `h p0'`,
    /// `h^2 p0''`, `h^2 p1''`, `h p1'`: H5 (the value enters as `p0 + H5 (p1 - p0)`,
    /// see [`Self::basis_sum`]), H1, H2, H3, H4, each factored so that it is computed
    /// without cancellation.
    #[inline]
    fn value_basis(s: f64) -> [f64; 5] {
        let u = 1.0 - s;
        let (s2, u2) = (s * s, u * u);
        let s3 = s2 * s;
        [
            s3 * (10.0 + s * (6.0 * s - 15.0)),
            s * (1.0 + s2 * (s * (8.0 - 3.0 * s) - 6.0)),
            0.5 * s2 * u2 * u,
            0.5 * s3 * u2,
            -s3 * u * (4.0 - 3.0 * s),
        ]
    }

    /// [`Self::value_basis`] with its first and second derivatives in `s`, `[H, H',
    /// H'']` per basis function.
    #[inline]
    fn basis(s: f64) -> [[f64; 3]; 5] {
        let v = Self::value_basis(s);
        let u = 1.0 - s;
        let (s2, u2) = (s * s, u * u);
        [
            [v[0], 30.0 * s2 * u2, 60.0 * s * u * (1.0 - 2.0 * s)],
            [
                v[1],
                u2 * (1.0 + s * (2.0 - 15.0 * s)),
                -12.0 * s * u * (3.0 - 5.0 * s),
            ],
            [
                v[2],
                s * u2 * (1.0 - 2.5 * s),
                u * (1.0 + s * (10.0 * s - 8.0)),
            ],
            [
                v[3],
                0.5 * s2 * u * (3.0 - 5.0 * s),
                s * (3.0 + s * (10.0 * s - 12.0)),
            ],
            [
                v[4],
                -s2 * (12.0 + s * (15.0 * s - 28.0)),
                -12.0 * s * u * (2.0 - 5.0 * s),
            ],
        ]
    }

    /// Component `c`'s basis sum `Σ w_k b_k` over a piece: with the basis values
    /// ([`Self::value_basis`]) the change from `p0`, with their first (second)
    /// derivatives `h` (`h^2`) times the rate (acceleration). The value enters as `p0 + H5 (p1 - p0)` (`H0 = 1 - H5`):
    /// written as `H0 p0 + H5 p1` the derivatives would cancel two large terms (for a
    /// latitude of 0.8 rad at 100 Hz knots, 3e-4 m/s^2 of round-off in the
    /// acceleration).
    #[inline]
    fn basis_sum(k0: &Knot, k1: &Knot, h: f64, b: [f64; 5], c: usize) -> f64 {
        let hh = h * h;
        let w = [
            k1.value[c] - k0.value[c],
            h * k0.rate[c],
            hh * k0.accel[c],
            hh * k1.accel[c],
            h * k1.rate[c],
        ];
        w[0] * b[0] + w[1] * b[1] + w[2] * b[2] + w[3] * b[3] + w[4] * b[4]
    }

    /// All six components at time `t` with their first and second time derivatives,
    /// `[value, rate, acceleration]` each, from the basis derivatives in closed form.
    pub fn derivatives(&self, t: f64) -> [[f64; 3]; 6] {
        self.derivatives_on(self.interval(t), t)
    }

    /// [`Self::derivatives`] on the piece from knot `i` to knot `i + 1` (the same bits
    /// when `i` is the piece holding `t`; any `i` when the caller knows it).
    #[inline]
    pub(crate) fn derivatives_on(&self, i: usize, t: f64) -> [[f64; 3]; 6] {
        let (k0, k1, h, s) = self.locate_on(i, t);
        let b = Self::basis(s);
        let column = |j: usize| b.map(|f| f[j]);
        let (b0, b1, b2) = (column(0), column(1), column(2));
        // d/dt = (1/h) d/ds.
        let (r1, r2) = (1.0 / h, 1.0 / (h * h));
        // Component by component in plain loops over arrays, so the six run two at a
        // time on vector lanes.
        let (mut v, mut d, mut dd) = ([0.0; 6], [0.0; 6], [0.0; 6]);
        for c in 0..6 {
            v[c] = k0.value[c] + Self::basis_sum(k0, k1, h, b0, c);
            d[c] = Self::basis_sum(k0, k1, h, b1, c) * r1;
            dd[c] = Self::basis_sum(k0, k1, h, b2, c) * r2;
        }
        std::array::from_fn(|c| [v[c], d[c], dd[c]])
    }

    /// All six components at time `t`, as jets ([`SplineTrajectory::derivatives`]
    /// composed with `t`'s own derivatives).
    pub fn components(&self, t: Jet) -> [Jet; 6] {
        self.derivatives(t.v).map(|[v, d, dd]| Jet {
            v,
            d: d * t.d,
            dd: dd * t.d * t.d + d * t.dd,
        })
    }
}

impl Trajectory for SplineTrajectory {
    fn position(&self, t: Jet) -> JetVec3 {
        let c = self.components(t);
        [c[0], c[1], c[2]]
    }

    fn c_bn(&self, t: Jet) -> JetMat3 {
        let c = self.components(t);
        JetMat3::from_euler(c[3], c[4], c[5])
    }

    /// One evaluation of the components for both position and attitude.
    fn ecef_pose<E: crate::earth::EarthModel>(&self, earth: &E, t: Jet) -> (JetVec3, JetMat3) {
        let c = self.components(t);
        super::analytic::geodetic_pose(
            earth,
            &[c[0], c[1], c[2]],
            &JetMat3::from_euler(c[3], c[4], c[5]),
        )
    }

    /// In closed form from the components' derivatives
    /// ([`super::analytic::evaluate_geodetic`]).
    fn evaluate_at<E: crate::earth::EarthModel>(
        &self,
        earth: &E,
        t: f64,
    ) -> (crate::nav::NavState, super::analytic::Kinematics) {
        super::analytic::evaluate_geodetic(earth, t, &self.derivatives(t))
    }

    /// Roll, pitch and yaw as the spline holds them (unwrapped), values only: the same
    /// bits as [`SplineTrajectory::derivatives`] gives.
    fn euler_at(&self, t: f64) -> Option<crate::rotation::Euler> {
        let (k0, k1, h, s) = self.locate(t);
        let b = Self::value_basis(s);
        let v = |c: usize| k0.value[c] + Self::basis_sum(k0, k1, h, b, c);
        Some(crate::rotation::Euler::new(v(3), v(4), v(5)))
    }

    /// The interior knots in `(a, b)` (the first and last knot are no breaks: the end
    /// pieces extend smoothly beyond them).
    fn breaks(&self, a: f64, b: f64) -> &[f64] {
        let times = &self.times;
        let from = self.interval(a) + 1;
        let mut to = from;
        while to < times.len() - 1 && times[to] < b {
            to += 1;
        }
        &times[from..to]
    }

    /// In closed form ([`super::analytic::kinematics_geodetic`]).
    fn kinematics_at<E: crate::earth::EarthModel>(
        &self,
        earth: &E,
        t: f64,
    ) -> super::analytic::Kinematics {
        super::analytic::kinematics_geodetic(earth, &self.derivatives(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn knot(t: f64, f: impl Fn(f64) -> (f64, f64, f64)) -> Knot {
        let (v, d, dd) = f(t);
        Knot {
            t,
            value: [v; 6],
            rate: [d; 6],
            accel: [dd; 6],
        }
    }

    /// A quintic reproduces any polynomial of degree <= 5 exactly, derivatives included.
    #[test]
    fn reproduces_quintic_polynomials() {
        let p = |t: f64| {
            (
                1.0 + 2.0 * t - 0.5 * t.powi(3) + 0.1 * t.powi(5),
                2.0 - 1.5 * t * t + 0.5 * t.powi(4),
                -3.0 * t + 2.0 * t.powi(3),
            )
        };
        let s =
            SplineTrajectory::new(vec![knot(0.5, p), knot(2.0, p), knot(2.5, p)]).expect("knots");
        for &t in &[0.5, 0.9, 1.7, 2.0, 2.2, 2.5] {
            let c = s.components(Jet::variable(t))[4];
            let (v, d, dd) = p(t);
            assert_relative_eq!(c.v, v, max_relative = 1e-13);
            assert_relative_eq!(c.d, d, max_relative = 1e-13, epsilon = 1e-13);
            assert_relative_eq!(c.dd, dd, max_relative = 1e-12, epsilon = 1e-12);
        }
    }

    /// Continuity at a knot between two different pieces: value, slope, curvature.
    #[test]
    fn c2_at_knots() {
        let s = SplineTrajectory::new(vec![
            knot(0.0, |_| (0.0, 1.0, 0.0)),
            knot(1.0, |_| (1.0, 0.5, -2.0)),
            knot(3.0, |_| (0.0, 0.0, 0.0)),
        ])
        .expect("knots");
        let left = s.components(Jet::variable(1.0 - 1e-9))[0];
        let right = s.components(Jet::variable(1.0 + 1e-9))[0];
        assert_relative_eq!(left.v, right.v, epsilon = 1e-8);
        assert_relative_eq!(left.d, right.d, epsilon = 1e-7);
        assert_relative_eq!(left.dd, right.dd, epsilon = 1e-6);
        assert_relative_eq!(right.dd, -2.0, epsilon = 1e-6);
    }

    proptest::proptest! {
        /// The galloping interval search agrees with a plain binary search over the
        /// knot times, for uneven spacing and times outside the knots.
        #[test]
        fn interval_matches_binary_search(
            steps in proptest::collection::vec(1e-3..1.0f64, 1..60),
            uneven in proptest::collection::vec(0usize..60, 0..8),
            probes in proptest::collection::vec(-0.2..1.2f64, 1..40),
        ) {
            let mut t = 3.0;
            let mut ts = vec![t];
            for (i, dt) in steps.iter().enumerate() {
                t += if uneven.contains(&i) { dt * 37.0 } else { *dt };
                ts.push(t);
            }
            let knots = ts.iter().map(|&t| knot(t, |_| (0.0, 0.0, 0.0))).collect();
            let s = SplineTrajectory::new(knots).expect("knots");
            let span = ts[ts.len() - 1] - ts[0];
            let mut probes: Vec<f64> = probes.iter().map(|p| ts[0] + p * span).collect();
            probes.extend(&ts);
            for p in probes {
                let want = ts.partition_point(|&x| x <= p).clamp(1, ts.len() - 1) - 1;
                proptest::prop_assert_eq!(s.interval(p), want, "t = {}", p);
            }
        }
    }

    #[test]
    fn bad_knots_are_errors() {
        let k = knot(0.0, |_| (0.0, 0.0, 0.0));
        assert_eq!(
            SplineTrajectory::new(vec![k]),
            Err(SplineError::TooFewKnots(1))
        );
        assert_eq!(
            SplineTrajectory::new(vec![k, k]),
            Err(SplineError::TimeNotIncreasing { index: 1, t: 0.0 })
        );
        let mut bad = k;
        bad.t = 1.0;
        bad.rate[2] = f64::NAN;
        assert_eq!(
            SplineTrajectory::new(vec![k, bad]),
            Err(SplineError::NonFinite(1))
        );
    }
}
