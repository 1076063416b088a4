//! Exact IMU samples of a spline trajectory, a block of consecutive samples at a time.
//!
//! Sample `k` ends at `t_k = t0 + k dt` and holds `∫ w_ib_b` and `∫ f_b` over
//! `[t_{k-1}, t_k]`, with the truth and the kinematics at `t_k`. The kinematics are
//! analytic inside each knot piece (at a knot the jerk may jump), so every integral is
//! split at the knots and each part taken on its own piece, in one of two ways:
//!
//! - **Chebyshev** (pieces that hold several samples): `w_ib_b` and `f_b` are
//!   interpolated on the piece at [`NODES`] Chebyshev points and the interpolant's
//!   antiderivative `F` gives every part as `F(hi) - F(lo)`. The fit proves itself by
//!   its last two coefficients, which must stay under [`TAIL`] of the coefficients'
//!   sum (plus, for `f_b`, of the round-off floor of the spline's accelerations, under
//!   which every evaluation scatters anyway), else the piece falls back to the
//!   per-sample rule. At 1 kHz with 100-Hz knots this takes 1.2 kinematics
//!   evaluations per sample instead of 2.2.
//! - **Gauss–Lobatto** (few samples per piece, a failed fit, and the extension of the
//!   first and last piece beyond the knots): the 4-point rule on each part, exact for
//!   degree 5 ([`super::analytic::increment_from`]'s rule).
//!
//! Every choice depends on the piece and `dt` alone, never on where a block starts, so
//! any split into blocks gives the same bits.

use super::analytic::{
    GeodeticEuler, Kinematics, Trig, evaluate_geodetic_with, kinematics_geodetic_with,
    lobatto4_rule,
};
use super::run::ImuEpoch;
use super::spline::SplineTrajectory;
use crate::earth::EarthModel;
use crate::imu::ImuSample;
use crate::rotation::Euler;
use nalgebra::Vector3;
use std::sync::LazyLock;

/// Chebyshev nodes per piece (the interpolant's degree is one less).
pub const NODES: usize = 12;

/// Largest accepted ratio of the last two Chebyshev coefficients to the sum of all
/// (per triad, largest component; for `f_b` the sum plus [`acceleration_floor`]): 4
/// ulp, so that a piece is accepted only when its interpolant is exact to the
/// round-off of the values it interpolates.
pub const TAIL: f64 = 4.0 * f64::EPSILON;

/// `cos(n π (j + 1/2) / NODES)`: the discrete cosine transform from node `j`'s value
/// to coefficient `n`, and node `j` itself at `n = 1`.
static COSINES: LazyLock<[[f64; NODES]; NODES]> = LazyLock::new(|| {
    std::array::from_fn(|n| {
        std::array::from_fn(|j| {
            (n as f64 * std::f64::consts::PI * (j as f64 + 0.5) / NODES as f64).cos()
        })
    })
});

/// `w_ib_b` and `f_b` as one array of six.
fn six(k: &Kinematics) -> [f64; 6] {
    let (w, f) = (k.w_ib_b, k.f_b);
    [w.x, w.y, w.z, f.x, f.y, f.z]
}

/// The antiderivative of the Chebyshev interpolant of `w_ib_b` and `f_b` on one piece.
struct Antiderivative {
    /// Midpoint and half-length of the piece [s].
    mid: f64,
    half: f64,
    /// `F(s) = Σ_{n=1}^{NODES} c[n] T_n(s)` per component, `s = (t - mid)/half` (its
    /// constant left out: only differences are taken); already times `half`.
    c: [[f64; 6]; NODES + 1],
}

impl Antiderivative {
    /// The fit on piece `piece`, or `None` when its tail says the interpolant is not
    /// exact to round-off.
    fn fit<E: EarthModel>(
        earth: &E,
        traj: &SplineTrajectory,
        piece: usize,
        base: &TrigBase,
    ) -> Option<Self> {
        let times = traj.times();
        let (a, b) = (times[piece], times[piece + 1]);
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        let cos = &*COSINES;
        let values: [[f64; 6]; NODES] = std::array::from_fn(|j| {
            let t = mid - half * cos[1][j];
            six(&kinematics_on(earth, traj, piece, base, t))
        });
        // a[n] = (2/N) Σ_j f_j cos(n π (j + 1/2)/N), a[0] halved: f = Σ a[n] T_n. The
        // nodes run from -1 up (s_j = -cos(π (j + 1/2)/N)), so T_n(s_j) = (-1)^n cos(…).
        let mut coef = [[0.0; 6]; NODES];
        for (n, row) in coef.iter_mut().enumerate() {
            let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
            let scale = if n == 0 { 1.0 } else { 2.0 } * sign / NODES as f64;
            for (j, v) in values.iter().enumerate() {
                let w = scale * cos[n][j];
                for (r, x) in row.iter_mut().zip(v) {
                    *r += w * x;
                }
            }
        }
        let floor = [0.0, acceleration_floor(earth, traj, piece)];
        for (triad, floor) in [0..3, 3..6].into_iter().zip(floor) {
            let size = |n: std::ops::Range<usize>, i: usize| -> f64 {
                coef[n].iter().map(|r| r[i].abs()).sum()
            };
            let (mut tail, mut sum) = (0.0_f64, 0.0_f64);
            for i in triad {
                tail = tail.max(size(NODES - 2..NODES, i));
                sum = sum.max(size(0..NODES, i));
            }
            // A NaN anywhere fails too.
            let accepted = tail <= TAIL * (sum + floor);
            if !accepted {
                return None;
            }
        }
        // ∫ T_0 = T_1, ∫ T_1 = T_2/4, ∫ T_n = T_{n+1}/(2(n+1)) - T_{n-1}/(2(n-1)):
        // c[n] = (a[n-1] - a[n+1])/(2n) for n >= 2, c[1] = a[0] - a[2]/2.
        let at = |n: usize| coef.get(n).copied().unwrap_or([0.0; 6]);
        let mut c = [[0.0; 6]; NODES + 1];
        for (n, cn) in c.iter_mut().enumerate().skip(1) {
            let (lo, hi) = (at(n - 1), at(n + 1));
            let k = if n == 1 { 0.5 } else { 0.5 / n as f64 };
            for i in 0..6 {
                let lo = if n == 1 { 2.0 * lo[i] } else { lo[i] };
                cn[i] = half * k * (lo - hi[i]);
            }
        }
        Some(Self { mid, half, c })
    }

    /// `F` at time `t` (Clenshaw's recurrence, all six components at once).
    fn at(&self, t: f64) -> [f64; 6] {
        let s = (t - self.mid) / self.half;
        let (mut b1, mut b2) = ([0.0; 6], [0.0; 6]);
        for cn in self.c[1..].iter().rev() {
            let mut b0 = [0.0; 6];
            for i in 0..6 {
                b0[i] = 2.0 * s * b1[i] - b2[i] + cn[i];
            }
            b2 = b1;
            b1 = b0;
        }
        // The loop stopped after n = 1: F = b1 T_1 - b2 T_0 + (c_0 = 0) = s b1 - b2.
        std::array::from_fn(|i| s * b1[i] - b2[i])
    }
}

/// The size of the terms that the spline's second derivatives of position cancel down
/// to the acceleration, `6 |v| / h` [m/s^2] (the quintic Hermite weights of the value
/// and rate differences reach 6 / h^2 and their sum is the speed times `h`): their
/// round-off, about 1e-16 of this (3e-12 m/s^2 at 40 m/s and 100-Hz knots), is the
/// floor under which every evaluation of `f_b` scatters, whatever the quadrature.
fn acceleration_floor<E: EarthModel>(earth: &E, traj: &SplineTrajectory, piece: usize) -> f64 {
    let times = traj.times();
    let h = times[piece + 1] - times[piece];
    let rate = traj.knots()[piece].rate;
    // Radius: the semi-major axis, generous for a bound.
    let r = earth.semi_major_axis();
    let speed = ((r * rate[0]).powi(2) + (r * rate[1]).powi(2) + rate[2].powi(2)).sqrt();
    6.0 * speed / h
}

/// Largest angle change from a piece's start for which [`TrigBase`] adds angles
/// (0.05 rad: 25 ms at 2 rad/s; beyond it, libm): there the series below are exact to
/// 1e-20.
const SMALL_ANGLE: f64 = 0.05;

/// `(sin a, cos a)` from `(sin a0, cos a0)`: `sin a = sin a0 + (sin a0 (cos δ - 1) +
/// cos a0 sin δ)`, `cos a = cos a0 + (cos a0 (cos δ - 1) - sin a0 sin δ)` with `δ = a -
/// a0` and `sin δ`, `cos δ - 1` by their Taylor series to `δ^9` and `δ^8` (the next
/// terms, `δ^11/11!` and `δ^10/10!`, are below 3e-20 for `|δ| <= 0.05`); libm when
/// `δ` is larger.
#[inline]
fn add_angle((s0, c0): (f64, f64), a0: f64, a: f64) -> (f64, f64) {
    let d = a - a0;
    if d.abs() > SMALL_ANGLE {
        return a.sin_cos();
    }
    let d2 = d * d;
    let sin_d =
        d + d * d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0 + d2 / 362_880.0)));
    let cos_d_1 = d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 / 40_320.0)));
    (
        s0 + (s0 * cos_d_1 + c0 * sin_d),
        c0 + (c0 * cos_d_1 - s0 * sin_d),
    )
}

/// The sines and cosines of latitude, roll, pitch and yaw at a piece's start, from
/// which [`add_angle`] gives them anywhere on the piece: four libm calls per piece
/// instead of four per evaluation.
#[derive(Debug, Clone, Copy)]
struct TrigBase {
    piece: usize,
    angles: [f64; 4],
    trig: Trig,
}

impl TrigBase {
    fn new(traj: &SplineTrajectory, piece: usize) -> Self {
        let v = traj.knots()[piece].value;
        let angles = [v[0], v[3], v[4], v[5]];
        Self {
            piece,
            angles,
            trig: angles.map(f64::sin_cos),
        }
    }

    /// The sines and cosines of `c`'s angles.
    #[inline]
    fn at(&self, c: &GeodeticEuler) -> Trig {
        let a = [c[0][0], c[3][0], c[4][0], c[5][0]];
        std::array::from_fn(|i| add_angle(self.trig[i], self.angles[i], a[i]))
    }
}

/// The [`TrigBase`] of the piece where the last sample ended and of its predecessor
/// (every part of a sample lies on one of them, but for a sample spanning a whole
/// short piece, whose base is made when asked for).
struct Bases<'a> {
    traj: &'a SplineTrajectory,
    recent: [TrigBase; 2],
}

impl<'a> Bases<'a> {
    fn new(traj: &'a SplineTrajectory, piece: usize) -> Self {
        let b = TrigBase::new(traj, piece);
        Self {
            traj,
            recent: [b, b],
        }
    }

    fn get(&mut self, piece: usize) -> TrigBase {
        if let Some(b) = self.recent.iter().find(|b| b.piece == piece) {
            return *b;
        }
        let b = TrigBase::new(self.traj, piece);
        self.recent = [self.recent[1], b];
        b
    }
}

/// The kinematics at one instant on a known piece.
fn kinematics_on<E: EarthModel>(
    earth: &E,
    traj: &SplineTrajectory,
    piece: usize,
    base: &TrigBase,
    t: f64,
) -> Kinematics {
    let c = traj.derivatives_on(piece, t);
    kinematics_geodetic_with(earth, &c, &base.at(&c))
}

/// `∫ w_ib_b` and `∫ f_b` over `[lo, hi]` on piece `piece` by the 4-point
/// Gauss–Lobatto rule ([`lobatto4_rule`]), given the kinematics at both ends.
fn lobatto<E: EarthModel>(
    earth: &E,
    (traj, piece, base): (&SplineTrajectory, usize, &TrigBase),
    (lo, hi): (f64, f64),
    (left, right): (&Kinematics, &Kinematics),
) -> [f64; 6] {
    let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let (w, f) = lobatto4_rule((mid, half), (left, right), |t| {
        kinematics_on(earth, traj, piece, base, t)
    });
    [w.x, w.y, w.z, f.x, f.y, f.z]
}

/// Whether piece `piece` is integrated through its Chebyshev fit: when the per-sample
/// rule would take more evaluations (two per part of a sample in the piece) than the
/// fit's [`NODES`]. A function of the piece and `dt` only.
fn by_fit(times: &[f64], piece: usize, dt: f64) -> bool {
    let parts = (times[piece + 1] - times[piece]) / dt + 1.0;
    2.0 * parts > NODES as f64
}

/// The exact samples `k0..k1` into `out` (cleared first; `measured` set to the exact
/// sample): see the module documentation.
pub fn exact_block<E: EarthModel>(
    earth: &E,
    traj: &SplineTrajectory,
    t0: f64,
    dt: f64,
    k0: u64,
    k1: u64,
    out: &mut Vec<ImuEpoch>,
) {
    exact_block_with(earth, traj, (t0, dt), (k0, k1), true, out);
}

/// [`exact_block`], with the Chebyshev fits allowed or not (`fits`).
fn exact_block_with<E: EarthModel>(
    earth: &E,
    traj: &SplineTrajectory,
    (t0, dt): (f64, f64),
    (k0, k1): (u64, u64),
    fits: bool,
    out: &mut Vec<ImuEpoch>,
) {
    out.clear();
    let times = traj.times();
    let last = times.len() - 2;
    // The piece holding t, found forward from the previous one (the same piece the
    // trajectory's own search gives: t_i <= t < t_{i+1}, clamped to the ends).
    let advance = |mut i: usize, t: f64| {
        while i < last && times[i + 1] <= t {
            i += 1;
        }
        i
    };
    let mut lo = t0 + (k0 as f64 - 1.0) * dt;
    let mut lo_piece = traj.interval(lo);
    let mut bases = Bases::new(traj, lo_piece);
    let mut lo_kin = kinematics_on(earth, traj, lo_piece, &bases.get(lo_piece), lo);
    // The fit of the last piece that wanted one (`None` inside: it failed), and its
    // `F` at the last sample end on that piece.
    let mut fit: Option<(usize, Option<Antiderivative>)> = None;
    let mut f_end: Option<(f64, [f64; 6])> = None;
    for k in k0..k1 {
        let t = t0 + k as f64 * dt;
        let piece = advance(lo_piece, t);
        let c = traj.derivatives_on(piece, t);
        let (truth, kin) = evaluate_geodetic_with(earth, t, &c, &bases.get(piece).at(&c));
        let mut sum = [0.0; 6];
        // The parts of [lo, t] on pieces lo_piece..=piece.
        let mut left = (lo, lo_kin);
        for p in lo_piece..=piece {
            let (a, b) = (times[p], times[p + 1]);
            let right = if p == piece {
                (t, kin)
            } else {
                (b, kinematics_on(earth, traj, p + 1, &bases.get(p + 1), b))
            };
            let inside = a <= left.0 && right.0 <= b;
            if inside && fits && by_fit(times, p, dt) && fit.as_ref().is_none_or(|(q, _)| *q != p) {
                fit = Some((p, Antiderivative::fit(earth, traj, p, &bases.get(p))));
                f_end = None;
            }
            let on_fit = fit
                .as_ref()
                .and_then(|(q, f)| f.as_ref().filter(|_| inside && *q == p));
            let part = match on_fit {
                Some(f) => {
                    let from = match f_end {
                        Some((te, v)) if te == left.0 => v,
                        _ => f.at(left.0),
                    };
                    let to = f.at(right.0);
                    f_end = Some((right.0, to));
                    std::array::from_fn(|i| to[i] - from[i])
                }
                None => lobatto(
                    earth,
                    (traj, p, &bases.get(p)),
                    (left.0, right.0),
                    (&left.1, &right.1),
                ),
            };
            for (s, x) in sum.iter_mut().zip(part) {
                *s += x;
            }
            left = right;
        }
        let exact = ImuSample {
            t,
            dt,
            dtheta: Vector3::new(sum[0], sum[1], sum[2]),
            dvel: Vector3::new(sum[3], sum[4], sum[5]),
        };
        out.push(ImuEpoch {
            exact,
            measured: exact,
            truth,
            kin,
            euler: Euler::new(c[3][0], c[4][0], c[5][0]).principal(),
        });
        (lo, lo_piece, lo_kin) = (t, piece, kin);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{Geodetic, Wgs84};
    use crate::sim::analytic::increment;
    use crate::sim::motion::{Piece, Shape, Start, generate};

    /// A coordinated turn with roll, pitch and speed changes in two 0.73-s bumps (yaw
    /// rate up to 2 rad/s), scaled in rate by `speed`: the fastest motion the scripted
    /// maneuvers make, and faster.
    fn bumps(speed: f64) -> SplineTrajectory {
        let start = Start {
            t: 0.0,
            pos: Geodetic::from_degrees(45.0, 7.0, 100.0),
            v_n: Vector3::new(40.0, 0.0, 0.0),
            attitude: Euler::default(),
        };
        let turn = Piece {
            d_euler: [0.4 * speed, 0.1 * speed, 0.8 * speed],
            d_vel: [3.0, 0.5, -2.0],
            shape: Shape::Bump,
            coordinated: speed == 1.0,
            ..Piece::hold(0.73)
        };
        generate(&Wgs84, &start, &[turn, turn])
            .expect("motion")
            .trajectory
    }

    /// The reference: 6-point Gauss–Legendre on each part of `[lo, hi]` between
    /// knots (exact far beyond round-off on these parts, see
    /// `analytic::quadrature_tests`).
    fn reference(traj: &SplineTrajectory, lo: f64, hi: f64) -> [Vector3<f64>; 2] {
        use crate::sim::analytic::Trajectory;
        let mut sum = [Vector3::zeros(); 2];
        let mut left = lo;
        for &right in traj.breaks(lo, hi).iter().chain([hi].iter()) {
            let part = increment(&Wgs84, traj, right, right - left);
            sum[0] += part.dtheta;
            sum[1] += part.dvel;
            left = right;
        }
        sum
    }

    /// Largest differences from the reference over the whole trajectory at `rate_hz`,
    /// `[rad, m/s]`, with the fits allowed or not.
    fn errors(traj: &SplineTrajectory, rate_hz: f64, fits: bool) -> [f64; 2] {
        let dt = 1.0 / rate_hz;
        let t0 = traj.start() + 0.000_37;
        let n = ((traj.end() - t0) / dt) as u64;
        let mut out = Vec::new();
        exact_block_with(&Wgs84, traj, (t0, dt), (1, n + 1), fits, &mut out);
        let mut err = [0.0f64; 2];
        let mut lo = t0;
        for e in &out {
            let r = reference(traj, lo, e.exact.t);
            lo = e.exact.t;
            err[0] = err[0].max((e.exact.dtheta - r[0]).norm());
            err[1] = err[1].max((e.exact.dvel - r[1]).norm());
        }
        err
    }

    /// The fraction of pieces integrated through their fit at `rate_hz`.
    fn fitted(traj: &SplineTrajectory, rate_hz: f64) -> f64 {
        let times = traj.times();
        let pieces = times.len() - 1;
        let fitted = (0..pieces)
            .filter(|&p| {
                by_fit(times, p, 1.0 / rate_hz)
                    && Antiderivative::fit(&Wgs84, traj, p, &TrigBase::new(traj, p)).is_some()
            })
            .count();
        fitted as f64 / pieces as f64
    }

    /// The fits are as exact as the per-sample rule, to round-off: against
    /// Gauss–Legendre on the same parts both err by the round-off that scatters each
    /// evaluation of `f_b` (about 3e-12 m/s^2 here, [`acceleration_floor`]) and of
    /// `w_ib_b`. At 1 kHz the fits err at most twice as much as the per-sample rule
    /// (measured 1.4 and 1.2 times); their error is on the scale of the piece, so at
    /// 2 kHz, where the per-sample rule's halves, only the absolute bound applies: as
    /// rates (error / dt) under 1e-14 rad/s and 2e-11 m/s^2 (measured 8e-15 and
    /// 1.3e-11), a billionth of a navigation-grade IMU's bias. Nearly every 10-ms piece
    /// of the fast turn (yaw rate up to 2 rad/s) passes its tail test; 12 nodes are
    /// what it takes (10 pass 22 %, 11 pass 66 %, 12 pass 93 % at 1 kHz).
    #[test]
    fn fitted_pieces_are_as_exact_as_the_per_sample_rule() {
        let traj = bumps(1.0);
        for rate in [1000.0, 2000.0] {
            let (ours, per_sample) = (errors(&traj, rate, true), errors(&traj, rate, false));
            let fitted = fitted(&traj, rate);
            eprintln!("{rate} Hz: {ours:?} vs {per_sample:?} per sample, {fitted} fitted");
            assert!(fitted > 0.9, "{fitted}");
            if rate == 1000.0 {
                for i in 0..2 {
                    assert!(ours[i] <= 2.0 * per_sample[i], "{ours:?} {per_sample:?}");
                }
            }
            assert!(ours[0] * rate < 1e-14 && ours[1] * rate < 2e-11, "{ours:?}");
        }
    }

    /// Spinning 30 times faster (yaw rate up to 60 rad/s) the interpolant cannot follow
    /// within round-off on most pieces: the tail test refuses them and the per-sample
    /// rule takes them, and the increments stay as exact as that rule's (the few pieces
    /// that pass are as exact as above, well inside its error here).
    #[test]
    fn rough_pieces_fall_back_to_the_per_sample_rule() {
        let traj = bumps(30.0);
        let (ours, per_sample) = (errors(&traj, 1000.0, true), errors(&traj, 1000.0, false));
        let fitted = fitted(&traj, 1000.0);
        eprintln!("{ours:?} vs {per_sample:?} per sample, {fitted} fitted");
        assert!(fitted < 0.5, "{fitted}");
        for i in 0..2 {
            assert!(ours[i] <= 1.01 * per_sample[i], "{ours:?} {per_sample:?}");
        }
    }

    /// Angle addition agrees with libm to 1.5e-16 (absolute, on values up to 1: one
    /// ulp of 1 and a bit) over the whole range it is used in, at every size of angle.
    #[test]
    fn angle_addition_matches_libm() {
        let mut worst = 0.0f64;
        for i in 0..2000 {
            let a0 = -40.0 + 0.0401 * i as f64;
            let base = a0.sin_cos();
            for j in -50..=50 {
                let a = a0 + SMALL_ANGLE * j as f64 / 50.0 * 0.999;
                let (s, c) = add_angle(base, a0, a);
                let (s_ref, c_ref) = a.sin_cos();
                worst = worst.max((s - s_ref).abs()).max((c - c_ref).abs());
            }
        }
        eprintln!("angle addition: worst {worst:e}");
        assert!(worst <= 1.5e-16, "{worst:e}");
        // Beyond the small angle, libm itself.
        assert_eq!(add_angle((0.0, 1.0), 0.0, 0.3), 0.3f64.sin_cos());
    }

    /// Blocks started anywhere give the same bits as one long block.
    #[test]
    fn blocks_are_independent() {
        let traj = bumps(1.0);
        let (t0, dt) = (0.0, 1e-3);
        let mut whole = Vec::new();
        exact_block(&Wgs84, &traj, t0, dt, 0, 1400, &mut whole);
        let mut pieces = Vec::new();
        for (a, b) in [(0, 7), (7, 333), (333, 334), (334, 1400)] {
            let mut out = Vec::new();
            exact_block(&Wgs84, &traj, t0, dt, a, b, &mut out);
            pieces.extend(out);
        }
        assert_eq!(whole, pieces);
    }
}
