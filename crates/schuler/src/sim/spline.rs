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
        Ok(Self { knots })
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

    /// Index of the interval holding `t` (clamped to the first and last).
    fn interval(&self, t: f64) -> usize {
        let i = self.knots.partition_point(|k| k.t <= t);
        i.clamp(1, self.knots.len() - 1) - 1
    }

    /// All six components at time `t`, as jets.
    pub fn components(&self, t: Jet) -> [Jet; 6] {
        let i = self.interval(t.v);
        let (k0, k1) = (&self.knots[i], &self.knots[i + 1]);
        let h = k1.t - k0.t;
        let s = (t - k0.t) * (1.0 / h);
        let s2 = s * s;
        let s3 = s2 * s;
        let s4 = s3 * s;
        let s5 = s4 * s;
        // Quintic Hermite basis: value, slope and curvature at both ends. The value
        // basis enters as p0 + H5 (p1 - p0) (H0 = 1 - H5): written as H0 p0 + H5 p1 the
        // derivatives would cancel two large terms (for a latitude of 0.8 rad at 100 Hz
        // knots, 3e-4 m/s^2 of round-off in the acceleration).
        let h1 = s - s3 * 6.0 + s4 * 8.0 - s5 * 3.0;
        let h2 = s2 * 0.5 - s3 * 1.5 + s4 * 1.5 - s5 * 0.5;
        let h3 = s3 * 0.5 - s4 + s5 * 0.5;
        let h4 = s3 * (-4.0) + s4 * 7.0 - s5 * 3.0;
        let h5 = s3 * 10.0 - s4 * 15.0 + s5 * 6.0;
        std::array::from_fn(|c| {
            h5 * (k1.value[c] - k0.value[c])
                + h1 * (h * k0.rate[c])
                + h2 * (h * h * k0.accel[c])
                + h3 * (h * h * k1.accel[c])
                + h4 * (h * k1.rate[c])
                + k0.value[c]
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
