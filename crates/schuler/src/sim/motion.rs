//! Motion generation: commanded maneuvers integrated into a C² trajectory.
//!
//! A motion is an initial state and a list of [`Piece`]s. Each piece lasts `duration`
//! seconds and changes the Euler angles by `d_euler` and the velocity by `d_vel` (in
//! body axes, as the vehicle feels it, or in NED), with rates that follow a smooth
//! [`Shape`] whose integral is one: so the totals are exact, and rates start and end
//! with zero slope, which keeps angular acceleration and jerk bounded and continuous
//! across pieces. A coordinated piece adds the yaw rate `g tan(roll) / V` of a turn
//! without sideslip. Named maneuvers (accelerate to a speed, turn by an angle at a bank,
//! climb to a height, ...) compile into such pieces in [`super::scenario`].
//!
//! The state `x = [lat, lon, h, roll, pitch, yaw, vN, vE, vD]` obeys
//! `lat' = vN/(R_M+h)`, `lon' = vE/((R_N+h) cos lat)`, `h' = -vD`,
//! `euler' = d_euler/T s(τ/T) (+ coordinated yaw rate)`, and either
//! `v_n' = d_vel/T s(τ/T)` (NED) or `v_n' = C_bn (a_b + w_nb_b × v_b)` with
//! `a_b = d_vel/T s(τ/T)`, `v_b = C_nb v_n` (body: the velocity turns with the body, as
//! a car's or an aircraft's does). It is integrated by classical Runge–Kutta at steps of
//! at most [`MAX_STEP`] s, and every step emits a [`Knot`] with the exact first and
//! second derivatives of the state there (forward-mode jets through the same equations),
//! so the [`SplineTrajectory`] through the knots is the truth.

use super::jet::{self, Jet, Scalar};
use super::receivers::Interval;
use super::spline::{Knot, SplineTrajectory};
use crate::domain::{DomainError, HEIGHT, SPEED};
use crate::earth::{EarthModel, Geodetic};
use crate::rotation::Euler;
use nalgebra::Vector3;

/// Longest integration step and knot spacing [s].
pub const MAX_STEP: f64 = 0.01;

/// How a piece's rates are distributed over its duration (each integrates to one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// `30 x^2 (1-x)^2`: rates rise and fall smoothly, peak 1.875 times the mean.
    Bump,
    /// A plateau with smoothstep ramps taking the given fraction (0 < f <= 0.5) of the
    /// duration at each end; peak `1/(1-f)` times the mean.
    Plateau(f64),
    /// No change (a hold).
    Zero,
}

impl Shape {
    /// The shape's value at `x = τ/T` in [0, 1], on a value or a jet.
    fn eval<S: Scalar>(self, x: S) -> S {
        let one = S::constant(1.0);
        match self {
            Shape::Zero => S::constant(0.0),
            Shape::Bump => x * x * (one - x) * (one - x) * 30.0,
            Shape::Plateau(f) => {
                // Smoothstep S(s) = 6s^5 - 15s^4 + 10s^3 (C2 at both ends).
                let step = |s: S| s * s * s * (s * (s * 6.0 - 15.0) + 10.0);
                let w = if x.value() < f {
                    step(x * (1.0 / f))
                } else if x.value() > 1.0 - f {
                    step((one - x) * (1.0 / f))
                } else {
                    one
                };
                w * (1.0 / (1.0 - f))
            }
        }
    }
}

/// The axes in which a piece's velocity change is commanded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VelocityAxes {
    /// Body axes: the change the vehicle feels; the velocity turns with the body.
    Body,
    /// North-east-down.
    Ned,
}

/// One piece of motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Duration [s], > 0.
    pub duration: f64,
    /// Total change of roll, pitch, yaw [rad] (the coordinated yaw rate comes on top).
    pub d_euler: [f64; 3],
    /// Total change of velocity [m/s] in `axes`.
    pub d_vel: [f64; 3],
    /// Axes of `d_vel`.
    pub axes: VelocityAxes,
    /// Rate profile.
    pub shape: Shape,
    /// Add the coordinated-turn yaw rate `g tan(roll) / V_horizontal`.
    pub coordinated: bool,
}

impl Piece {
    /// A hold: nothing changes for `duration` (the vehicle keeps its velocity).
    pub fn hold(duration: f64) -> Self {
        Self {
            duration,
            d_euler: [0.0; 3],
            d_vel: [0.0; 3],
            axes: VelocityAxes::Body,
            shape: Shape::Zero,
            coordinated: false,
        }
    }
}

/// Gravity used for the coordinated-turn rate [m/s^2] (standard gravity; the turn is
/// defined by this relation, the simulated specific force follows from the motion).
const G_TURN: f64 = 9.806_65;

/// Below this horizontal speed [m/s] a coordinated piece adds no yaw rate.
const MIN_TURN_SPEED: f64 = 0.1;

/// The state derivative `x'` at time `tau` into `piece`: on values for the
/// Runge–Kutta stages, on jets so that the derivative of the result is `x''` (the same
/// value bits either way, [`Scalar`]).
fn derivative<E: EarthModel, S: Scalar>(earth: &E, piece: &Piece, tau: S, x: &[S; 9]) -> [S; 9] {
    let [lat, _lon, h, roll, pitch, yaw, vn, ve, vd] = *x;
    let (a, e2) = (earth.semi_major_axis(), earth.eccentricity_squared());
    let (sl, cl) = lat.sin_cos();
    let (sr, cr) = roll.sin_cos();
    let w = (S::constant(1.0) - sl * sl * e2).sqrt();
    let rn = w.recip() * a;
    let rm = (w * w * w).recip() * (a * (1.0 - e2));
    let s = piece.shape.eval(tau * (1.0 / piece.duration)) * (1.0 / piece.duration);
    let mut euler_rate = piece.d_euler.map(|d| s * d);
    if piece.coordinated {
        let v_h = (vn * vn + ve * ve).sqrt();
        if v_h.value() > MIN_TURN_SPEED {
            euler_rate[2] = euler_rate[2] + sr * cr.recip() * G_TURN * v_h.recip();
        }
    }
    let accel = piece.d_vel.map(|d| s * d);
    let v_n = [vn, ve, vd];
    let a_n = match piece.axes {
        VelocityAxes::Ned => accel,
        VelocityAxes::Body => {
            let (sp, cp) = pitch.sin_cos();
            let c_bn = jet::euler_dcm_sin_cos((sr, cr), (sp, cp), yaw.sin_cos());
            let v_b = jet::mat_t_vec(&c_bn, &v_n);
            // w_nb_b from Euler rates (Titterton & Weston eq. 3.52 inverted).
            let [dr, dp, dy] = euler_rate;
            let w = [dr - dy * sp, dp * cr + dy * sr * cp, dy * cr * cp - dp * sr];
            let wxv = [
                w[1] * v_b[2] - w[2] * v_b[1],
                w[2] * v_b[0] - w[0] * v_b[2],
                w[0] * v_b[1] - w[1] * v_b[0],
            ];
            jet::mat_vec(
                &c_bn,
                &[accel[0] + wxv[0], accel[1] + wxv[1], accel[2] + wxv[2]],
            )
        }
    };
    [
        vn * (rm + h).recip(),
        ve * ((rn + h) * cl).recip(),
        -vd,
        euler_rate[0],
        euler_rate[1],
        euler_rate[2],
        a_n[0],
        a_n[1],
        a_n[2],
    ]
}

/// Values of the derivative at plain f64 state (no jets: a third of the work).
fn derivative_value<E: EarthModel>(earth: &E, piece: &Piece, tau: f64, x: &[f64; 9]) -> [f64; 9] {
    derivative(earth, piece, tau, x)
}

/// The knot at state `x` whose first derivatives `d1` come from the equations:
/// second derivatives by differentiating them along the motion (jets seeded with `x'`).
fn knot<E: EarthModel>(
    earth: &E,
    piece: &Piece,
    t: f64,
    tau: f64,
    x: &[f64; 9],
    d1: &[f64; 9],
) -> Knot {
    let xj: [Jet; 9] = std::array::from_fn(|i| Jet {
        v: x[i],
        d: d1[i],
        dd: 0.0,
    });
    let d2 = derivative(earth, piece, Jet::variable(tau), &xj).map(|j| j.d);
    Knot {
        t,
        value: std::array::from_fn(|i| x[i]),
        rate: std::array::from_fn(|i| d1[i]),
        accel: std::array::from_fn(|i| d2[i]),
    }
}

/// Start of a motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// Time [s] of the start.
    pub t: f64,
    /// Position.
    pub pos: Geodetic,
    /// Velocity NED [m/s].
    pub v_n: Vector3<f64>,
    /// Attitude.
    pub attitude: Euler,
}

/// Why a motion cannot be generated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MotionError {
    /// A piece with a non-positive or non-finite duration.
    #[error("piece {index}: duration must be positive and finite, got {duration} s")]
    BadDuration {
        /// Piece index.
        index: usize,
        /// Its duration.
        duration: f64,
    },
    /// The motion left the domain of the local-level equations (a pole, or NaN).
    #[error("piece {index}: the motion reaches latitude {lat_deg} deg or becomes non-finite")]
    OutOfDomain {
        /// Piece index.
        index: usize,
        /// Latitude reached [deg].
        lat_deg: f64,
    },
    /// No pieces.
    #[error("a motion needs at least one piece")]
    Empty,
    /// The motion would last longer than the builder's limit
    /// ([`MAX_MOTION_DURATION`] unless set otherwise).
    #[error(
        "piece {index}: the motion would last {total_s:.3e} s, beyond the limit of {limit_s} s \
         (its knots, 100 a second, take 16 kB of memory per second)"
    )]
    TooLong {
        /// Piece index.
        index: usize,
        /// The motion's duration with this piece [s].
        total_s: f64,
        /// The limit [s].
        limit_s: f64,
    },
    /// The motion's height or speed left its physical domain.
    #[error("piece {index}: at t = {t} s the motion's {reason}")]
    Leaves {
        /// Piece index.
        index: usize,
        /// Time [s].
        t: f64,
        /// Which domain, and the value (boxed: errors stay small on the happy path).
        reason: Box<DomainError>,
    },
}

/// Longest motion a builder integrates by default [s]: a day, whose knots take 1.4 GB
/// (152 + 8 bytes at 100 Hz) when kept for a trajectory in memory (a fed builder, as
/// the simulator's, keeps none); longer runs are soak tests, which repeat a shorter
/// motion ([`MotionBuilder::with_max_duration`] lifts the limit).
pub const MAX_MOTION_DURATION: f64 = 24.0 * 3600.0;

/// Integrates pieces one after another, so a maneuver can be planned from the state
/// the previous ones reached (current speed, height, bank).
#[derive(Debug, Clone)]
pub struct MotionBuilder<E: EarthModel> {
    earth: E,
    x: [f64; 9],
    t: f64,
    /// The knots kept for [`MotionBuilder::finish`]: all of them, unless the builder
    /// is fed (then none: they went to the feed, and memory stays constant however
    /// long the motion).
    knots: Vec<Knot>,
    /// Whether the first knot (at the start) has been made.
    started: bool,
    /// The last knot's time [s] (within an ulp of `t`, which sums the durations).
    last_knot_t: f64,
    pieces: usize,
    /// Who hears of the knots as they are made ([`MotionBuilder::feed`]).
    feed: FeedSlot,
    /// Start time and the longest duration allowed [s].
    span: (f64, f64),
}

/// A builder's [`KnotFeed`], if any. A clone (a trial integration) has none: its
/// knots are not the motion's (and a clone of a fed builder keeps only the knots made
/// after the clone).
#[derive(Default)]
struct FeedSlot(Option<KnotFeed>);

impl Clone for FeedSlot {
    fn clone(&self) -> Self {
        Self(None)
    }
}

impl std::fmt::Debug for FeedSlot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() { "fed" } else { "not fed" })
    }
}

/// Receives every knot, in order, as soon as it is made: a long piece in chunks of
/// [`FEED_CHUNK`], so that a consumer (the simulator's workers) can start on the
/// beginning of a motion while the rest is integrated.
pub type KnotFeed = Box<dyn FnMut(&[Knot]) + Send>;

/// Knots per chunk a [`KnotFeed`] receives (10 s of motion at the longest step).
pub const FEED_CHUNK: usize = 1000;

impl<E: EarthModel> MotionBuilder<E> {
    /// Start at `start`.
    pub fn new(earth: E, start: &Start) -> Self {
        let e = start.attitude;
        let x = [
            start.pos.lat,
            start.pos.lon,
            start.pos.h,
            e.roll,
            e.pitch,
            e.yaw,
            start.v_n.x,
            start.v_n.y,
            start.v_n.z,
        ];
        Self {
            earth,
            x,
            t: start.t,
            knots: Vec::new(),
            started: false,
            last_knot_t: start.t,
            pieces: 0,
            feed: FeedSlot::default(),
            span: (start.t, MAX_MOTION_DURATION),
        }
    }

    /// Allow motions up to `seconds` long instead of [`MAX_MOTION_DURATION`].
    pub fn with_max_duration(mut self, seconds: f64) -> Self {
        self.span.1 = seconds;
        self
    }

    /// Send every knot from now on to `feed` instead of keeping it: the motion is then
    /// ended by [`MotionBuilder::finish_fed`].
    pub fn feed(&mut self, feed: KnotFeed) {
        self.feed = FeedSlot(Some(feed));
    }

    /// The Earth model.
    pub fn earth(&self) -> E {
        self.earth
    }

    /// The current state (end of the pieces pushed so far).
    pub fn state(&self) -> Start {
        let x = &self.x;
        Start {
            t: self.t,
            pos: Geodetic::new(x[0], x[1], x[2]),
            v_n: Vector3::new(x[6], x[7], x[8]),
            attitude: Euler::new(x[3], x[4], x[5]),
        }
    }

    /// Integrate one piece.
    pub fn push(&mut self, piece: &Piece) -> Result<(), MotionError> {
        let index = self.pieces;
        if !(piece.duration.is_finite() && piece.duration > 0.0) {
            return Err(MotionError::BadDuration {
                index,
                duration: piece.duration,
            });
        }
        let total_s = self.t + piece.duration - self.span.0;
        if total_s > self.span.1 {
            return Err(MotionError::TooLong {
                index,
                total_s,
                limit_s: self.span.1,
            });
        }
        let n = (piece.duration / MAX_STEP).ceil().max(1.0) as usize;
        let h = piece.duration / n as f64;
        let mut x = self.x;
        // A fed builder holds one chunk at a time, an unfed one the whole piece.
        let fed_builder = self.feed.0.is_some();
        let mut knots = Vec::with_capacity(if fed_builder { FEED_CHUNK } else { n + 1 });
        // The derivative at each knot is also the first stage of the next step.
        let mut d1 = derivative_value(&self.earth, piece, 0.0, &x);
        if !self.started {
            knots.push(knot(&self.earth, piece, self.t, 0.0, &x, &d1));
        }
        for k in 0..n {
            x = rk4_step(&self.earth, piece, k as f64 * h, h, &x, &d1);
            let ok = x.iter().all(|v| v.is_finite()) && x[0].abs() < 89.9f64.to_radians();
            if !ok {
                return Err(MotionError::OutOfDomain {
                    index,
                    lat_deg: x[0].to_degrees(),
                });
            }
            let tau1 = (k + 1) as f64 * h;
            let speed = (x[6] * x[6] + x[7] * x[7] + x[8] * x[8]).sqrt();
            if let Err(reason) = HEIGHT.check(x[2]).and_then(|_| SPEED.check(speed)) {
                return Err(MotionError::Leaves {
                    index,
                    t: self.t + tau1,
                    reason: Box::new(reason),
                });
            }
            d1 = derivative_value(&self.earth, piece, tau1, &x);
            knots.push(knot(&self.earth, piece, self.t + tau1, tau1, &x, &d1));
            if let Some(feed) = self.feed.0.as_mut()
                && (knots.len() >= FEED_CHUNK || k + 1 == n)
            {
                feed(&knots);
                knots.clear();
            }
        }
        self.knots.extend(knots);
        // The last knot's time, as the loop computed it.
        self.last_knot_t = self.t + n as f64 * h;
        self.started = true;
        self.x = x;
        self.t += piece.duration;
        self.pieces += 1;
        Ok(())
    }

    /// The span of a fed builder's motion (its knots went to the feed).
    pub fn finish_fed(self) -> Result<Interval, MotionError> {
        if self.pieces == 0 {
            return Err(MotionError::Empty);
        }
        Ok(Interval {
            start: self.span.0,
            end: self.last_knot_t,
        })
    }

    /// The trajectory through everything pushed (an unfed builder's).
    pub fn finish(self) -> Result<SplineTrajectory, MotionError> {
        if self.pieces == 0 {
            return Err(MotionError::Empty);
        }
        let lat_deg = self.x[0].to_degrees();
        SplineTrajectory::new(self.knots).map_err(|_| MotionError::OutOfDomain {
            index: self.pieces - 1,
            lat_deg,
        })
    }
}

/// The trajectory of `pieces` from `start`, and the state at its end.
pub struct Generated {
    /// The trajectory.
    pub trajectory: SplineTrajectory,
    /// State at the end.
    pub end: Start,
}

/// Integrate `pieces` from `start` into a trajectory.
pub fn generate<E: EarthModel>(
    earth: &E,
    start: &Start,
    pieces: &[Piece],
) -> Result<Generated, MotionError> {
    let mut b = MotionBuilder::new(*earth, start);
    for p in pieces {
        b.push(p)?;
    }
    let end = b.state();
    Ok(Generated {
        trajectory: b.finish()?,
        end,
    })
}

/// One classical Runge–Kutta step of length `h` from `tau`, given the first stage
/// `k1 = x'(tau)`.
fn rk4_step<E: EarthModel>(
    earth: &E,
    piece: &Piece,
    tau: f64,
    h: f64,
    x: &[f64; 9],
    k1: &[f64; 9],
) -> [f64; 9] {
    let add = |a: &[f64; 9], b: &[f64; 9], s: f64| -> [f64; 9] {
        std::array::from_fn(|i| a[i] + s * b[i])
    };
    let k2 = derivative_value(earth, piece, tau + 0.5 * h, &add(x, k1, 0.5 * h));
    let k3 = derivative_value(earth, piece, tau + 0.5 * h, &add(x, &k2, 0.5 * h));
    let k4 = derivative_value(earth, piece, tau + h, &add(x, &k3, h));
    std::array::from_fn(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::Wgs84;
    use crate::sim::analytic;
    use approx::assert_relative_eq;

    /// Each shape integrates to one (Simpson's rule with 2000 intervals is exact to
    /// ~1e-13 for these polynomials and piecewise polynomials).
    #[test]
    fn shapes_integrate_to_one() {
        for shape in [Shape::Bump, Shape::Plateau(0.1), Shape::Plateau(0.5)] {
            let n = 2000;
            let f = |i: usize| shape.eval(Jet::constant(i as f64 / n as f64)).v;
            let sum: f64 = (0..=n)
                .map(|i| {
                    let w = if i == 0 || i == n {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * f(i)
                })
                .sum::<f64>()
                / (3.0 * n as f64);
            assert_relative_eq!(sum, 1.0, epsilon = 1e-9);
            assert_eq!(f(0), 0.0);
            assert_eq!(f(n), 0.0);
        }
    }

    fn start() -> Start {
        Start {
            t: 0.0,
            pos: Geodetic::from_degrees(45.0, 7.0, 100.0),
            v_n: Vector3::new(20.0, 0.0, 0.0),
            attitude: Euler::default(),
        }
    }

    /// A fed builder sends its knots and keeps none (its memory does not grow with
    /// the motion), and what it sends is the unfed builder's trajectory, bit for bit,
    /// over exactly the span it reports.
    #[test]
    fn a_fed_builder_sends_every_knot_and_keeps_none() {
        let pieces = [
            Piece::hold(25.0),
            Piece {
                d_vel: [5.0, 0.0, 0.0],
                shape: Shape::Bump,
                ..Piece::hold(12.3)
            },
        ];
        let sent = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let to = std::sync::Arc::clone(&sent);
        let mut fed = MotionBuilder::new(Wgs84, &start());
        fed.feed(Box::new(move |k| {
            to.lock().expect("lock").extend_from_slice(k)
        }));
        let mut unfed = MotionBuilder::new(Wgs84, &start());
        for p in &pieces {
            fed.push(p).expect("fed");
            unfed.push(p).expect("unfed");
            assert!(fed.knots.is_empty());
        }
        let span = fed.finish_fed().expect("span");
        let traj = unfed.finish().expect("trajectory");
        let sent = std::mem::take(&mut *sent.lock().expect("lock"));
        assert!(SplineTrajectory::new(sent).expect("knots") == traj);
        assert_eq!((span.start, span.end), (traj.start(), traj.end()));
    }

    /// Issue "Reliability"'s reproducers, which aborted on allocation or ran for ever:
    /// a hold of 1e9 s (and 1e308 s) is refused before any knot is made; speeding up
    /// to 1e8 m/s stops where the speed passes the escape velocity, naming the time.
    #[test]
    fn absurd_motions_are_refused_not_allocated() {
        for duration in [1e9, 1e308] {
            let mut b = MotionBuilder::new(Wgs84, &start());
            let e = b.push(&Piece::hold(duration)).expect_err("too long");
            assert!(matches!(e, MotionError::TooLong { index: 0, .. }), "{e}");
            assert!(b.knots.is_empty());
        }
        let mut b = MotionBuilder::new(Wgs84, &start());
        let fast = Piece {
            d_vel: [1e8, 0.0, 0.0],
            shape: Shape::Bump,
            ..Piece::hold(1000.0)
        };
        // The bump's integral 10x³ - 15x⁴ + 6x⁵ brings 20 m/s to 12 km/s at x*.
        let gained = |x: f64| 1e8 * x.powi(3) * (10.0 - 15.0 * x + 6.0 * x * x);
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if 20.0 + gained(mid) < SPEED.max {
                lo = mid
            } else {
                hi = mid
            }
        }
        match b.push(&fast).expect_err("too fast") {
            MotionError::Leaves {
                index: 0,
                t,
                reason,
            } => {
                // Checked at the end of each step: within one step after the crossing.
                let crossing = 1000.0 * lo;
                assert!(
                    t >= crossing && t <= crossing + MAX_STEP,
                    "{t} vs {crossing}"
                );
                assert_eq!(reason.domain, SPEED);
            }
            other => panic!("{other}"),
        }
        let b = MotionBuilder::new(Wgs84, &start()).with_max_duration(2e9);
        assert_eq!(b.span.1, 2e9);
    }

    /// A piece changes Euler angles and body speed by exactly its totals (RK4 on a
    /// polynomial rate profile: exact to round-off).
    #[test]
    fn totals_are_exact() {
        let piece = Piece {
            duration: 10.0,
            d_euler: [0.0, 0.1, 1.0],
            d_vel: [5.0, 0.0, 0.0],
            axes: VelocityAxes::Body,
            shape: Shape::Bump,
            coordinated: false,
        };
        let g = generate(&Wgs84, &start(), &[piece]).expect("motion");
        let e = g.end.attitude;
        assert_relative_eq!(e.pitch, 0.1, epsilon = 1e-12);
        assert_relative_eq!(e.yaw, 1.0, epsilon = 1e-12);
        // Body-axes velocity: speed 25 m/s along the new nose direction.
        let v_b = e.to_dcm().transpose() * g.end.v_n;
        assert_relative_eq!(v_b, Vector3::new(25.0, 0.0, 0.0), epsilon = 1e-9);
    }

    /// A level coordinated turn at 30 deg bank and 50 m/s: yaw rate g tan(30)/50 =
    /// 6.484 deg/s, and the truth's specific force is then along body z with magnitude
    /// g/cos(30) (no side force: the turn is coordinated; uncoordinated it would be
    /// g sin(30) = 4.9 m/s^2). The tolerance 8e-3 m/s^2 is what the ideal relation
    /// ignores: the Coriolis acceleration 2 W v = 7.3e-3 m/s^2 at 50 m/s, and local
    /// gravity (9.8059 here) differing from the standard g of the turn-rate law (4e-4).
    #[test]
    fn coordinated_turn_has_no_side_force() {
        let s = Start {
            v_n: Vector3::new(50.0, 0.0, 0.0),
            ..start()
        };
        let bank = 30f64.to_radians();
        let roll_in = Piece {
            duration: 5.0,
            d_euler: [bank, 0.0, 0.0],
            d_vel: [0.0; 3],
            axes: VelocityAxes::Body,
            shape: Shape::Bump,
            coordinated: true,
        };
        let hold = Piece {
            duration: 20.0,
            coordinated: true,
            ..Piece::hold(20.0)
        };
        let g = generate(&Wgs84, &s, &[roll_in, hold]).expect("motion");
        let k = analytic::kinematics(&Wgs84, &g.trajectory, 15.0);
        assert!(k.f_b.y.abs() < 8e-3, "side force {}", k.f_b.y);
        assert_relative_eq!(k.f_b.z, -9.8059 / bank.cos(), epsilon = 8e-3);
        // At a knot the spline yaw rate is the turn law at the integrated speed (50 m/s
        // held by RK4 to ~1e-11 relative).
        let yaw_rate = g.trajectory.components(Jet::variable(15.0))[5].d;
        assert_relative_eq!(yaw_rate, 9.80665 * bank.tan() / 50.0, max_relative = 1e-10);
    }

    /// The closed-form kinematics of a spline trajectory
    /// ([`analytic::evaluate_geodetic`]) agree with the generic route through the ECEF
    /// pose on jets and Bowring's geodetic latitude ([`analytic::evaluate_ecef`]), two
    /// independent derivations of the same physics, on a turning, climbing, rolling
    /// motion between and at knots, on WGS84 and on the rotating sphere.
    #[test]
    fn closed_form_kinematics_match_ecef_jets() {
        fn check<E: EarthModel>(earth: E) {
            let turn = Piece {
                duration: 7.3,
                d_euler: [0.4, 0.1, 1.2],
                d_vel: [3.0, 0.5, -2.0],
                axes: VelocityAxes::Body,
                shape: Shape::Bump,
                coordinated: true,
            };
            let climb = Piece {
                duration: 4.1,
                d_euler: [-0.4, -0.1, 0.0],
                d_vel: [0.0, 1.0, 4.0],
                axes: VelocityAxes::Ned,
                shape: Shape::Plateau(0.25),
                coordinated: false,
            };
            let g = generate(&earth, &start(), &[turn, climb]).expect("motion");
            let (mut max_w, mut max_f, mut max_v): (f64, f64, f64) = (0.0, 0.0, 0.0);
            for k in 0..=1140 {
                let t = k as f64 * 0.01 + 0.0037 * (k % 3) as f64;
                let (fast, kf) = analytic::evaluate(&earth, &g.trajectory, t);
                let (slow, ks) = analytic::evaluate_ecef(&earth, &g.trajectory, t);
                assert_eq!(kf, analytic::kinematics(&earth, &g.trajectory, t));
                max_w = max_w.max((kf.w_ib_b - ks.w_ib_b).norm());
                max_f = max_f.max((kf.f_b - ks.f_b).norm());
                max_v = max_v.max((fast.v_n - slow.v_n).norm());
                assert!((fast.pos.lat - slow.pos.lat).abs() < 1e-15, "{t}");
                assert!((fast.pos.lon - slow.pos.lon).abs() < 1e-15, "{t}");
                assert!((fast.pos.h - slow.pos.h).abs() < 1e-8, "{t}");
                assert!(fast.q_bn.angle_to(&slow.q_bn) < 1e-15, "{t}");
            }
            // Round-off: rates ~1 rad/s, forces ~10 m/s^2 and speeds ~25 m/s, both
            // routes a few dozen operations deep (the ECEF one on 6.4e6 m coordinates);
            // measured 2.2e-16 rad/s, 1.2e-14 m/s^2 and 1.0e-14 m/s.
            assert!(max_w < 1e-15, "w_ib_b differs by {max_w:e} rad/s");
            assert!(max_f < 5e-14, "f_b differs by {max_f:e} m/s^2");
            assert!(max_v < 5e-14, "v_n differs by {max_v:e} m/s");
        }
        check(Wgs84);
        check(crate::earth::Sphere::textbook(true));
    }

    #[test]
    fn bad_pieces_are_errors() {
        assert!(matches!(
            generate(&Wgs84, &start(), &[]),
            Err(MotionError::Empty)
        ));
        assert!(matches!(
            generate(&Wgs84, &start(), &[Piece::hold(-1.0)]),
            Err(MotionError::BadDuration { index: 0, .. })
        ));
    }
}
