//! Starting in motion from GNSS (a land vehicle's start: no static period, no
//! initial attitude).
//!
//! The start is taken at the middle `t_m` of a pair of fixes `(i, j)`: the first pair
//! whose horizontal displacement `d` exceeds [`InMotionConfig::displacement_sigmas`]
//! times its standard deviation within [`InMotionConfig::max_interval`] (for a vehicle
//! too slow for that, a longer chord up to [`InMotionConfig::max_straight_interval`]
//! over which the gyros say it drove straight), or, among the
//! pairs ending up to [`InMotionConfig::settle`] later on a straight chord, the one
//! with the largest displacement against its deviation (a car that just drove off has
//! a far longer chord a few seconds later):
//!
//! - the start is at the later fix `j` (the IMU sample ending nearest it): position
//!   that fix's; velocity differenced over the last two seconds of fixes (the chord's
//!   mean velocity belongs to its middle only under constant acceleration, which a
//!   vehicle driving off does not have);
//! - heading: the course of the chord, the least-squares line through all its fixes
//!   ([`line_course`]), carried from its middle `t_m` to the start by the angle the
//!   gyros turned. **This assumes the vehicle moves forward
//!   along the IMU's x axis** (a car, a rover: no sideslip to speak of); it is wrong for
//!   a vehicle moving sideways or backwards (a multicopter), which this start does not
//!   serve. The chord of a turn at a constant rate points along the heading at its
//!   middle;
//! - roll and pitch: from the specific force averaged over a window around the start,
//!   taken as the normal gravity's reaction: `C_y←b(θ, φ) f_b = −R_z(ψ)ᵀ g_n` for
//!   pitch `θ` and roll `φ`. The acceleration then is not known well enough from 1-Hz
//!   fixes to be removed; the change between the last velocities sizes the tilts'
//!   standard deviation instead.
//!
//! The standard deviations cover what each step neglects: the fixes' noise (the line's
//! direction), the heading's
//! change over the pair (a sixth of the angle the gyros turned), a sideslip allowance
//! ([`InMotionConfig::sideslip`]), and for the tilts the acceleration over `g`. The
//! filter then refines all of them in motion.

use crate::earth::{EarthModel, Geodetic};
use crate::filter::GnssFix;
use crate::imu::ImuSample;
use crate::nav::NavState;
use crate::rotation::Euler;
use nalgebra::Vector3;

/// Settings of the start in motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InMotionConfig {
    /// The displacement must exceed this many of its standard deviations (10: course
    /// known to 0.1 rad from the fixes' noise).
    pub displacement_sigmas: f64,
    /// Longest time between the two fixes [s]: the chord follows the heading only on
    /// a short arc.
    pub max_interval: f64,
    /// Length of the window around the start over which the specific force is
    /// averaged [s] (clipped to the pair's interval).
    pub level_window: f64,
    /// Allowance for the angle between the heading and the course [rad] (sideslip,
    /// IMU mounting).
    pub sideslip: f64,
    /// After the first pair qualifies, fixes up to this much later [s] may give a
    /// longer straight chord (the course's error falls as the chord grows).
    pub settle: f64,
    /// A chord counts as straight while the gyros turn less than this [rad] over it.
    pub straight: f64,
    /// Longest time between the two fixes of a straight chord [s]: when no pair
    /// moved far enough within [`Self::max_interval`] (a rover creeping at 0.2 m/s
    /// with 1-m fixes needs 70 s), a longer pair serves if the gyros turned less than
    /// [`Self::straight`] over it (its course is then the heading however long it is).
    pub max_straight_interval: f64,
}

impl Default for InMotionConfig {
    fn default() -> Self {
        Self {
            displacement_sigmas: 10.0,
            max_interval: 30.0,
            level_window: 1.0,
            sideslip: 1f64.to_radians(),
            settle: 3.0,
            straight: 2f64.to_radians(),
            max_straight_interval: 300.0,
        }
    }
}

/// A start in motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InMotionStart {
    /// The state at the carrier sample's time.
    pub state: NavState,
    /// Index of the carrier sample in the slice given.
    pub sample: usize,
    /// Standard deviations of position (NED) [m].
    pub pos_std: Vector3<f64>,
    /// Standard deviations of velocity (NED) [m/s].
    pub vel_std: Vector3<f64>,
    /// Standard deviations of the attitude about north, east, down [rad].
    pub att_std: Vector3<f64>,
    /// The pair of fixes used (indices in the fixes given).
    pub fixes: (usize, usize),
    /// Horizontal speed at the start [m/s].
    pub speed: f64,
}

/// Why no start could be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InMotionError {
    /// No pair of fixes moved far enough.
    #[error(
        "the GNSS fixes never moved {sigmas} standard deviations apart within {max_interval} s \
         (largest horizontal displacement {best:.2} m against its std {std:.2} m): \
         no course to take the heading from; --init gnss-any-heading finds the heading \
         with a bank of filters instead, or start from a known attitude"
    )]
    NoMotion {
        /// The criterion.
        sigmas: f64,
        /// The longest interval tried [s].
        max_interval: f64,
        /// The largest displacement seen [m].
        best: f64,
        /// Its standard deviation [m].
        std: f64,
    },
    /// The only chord long enough is longer than [`InMotionConfig::max_interval`]
    /// and not straight: its course is not the heading.
    #[error(
        "the GNSS fixes moved far enough for a course only from t = {t0} s to t = {t1} s, \
         while the vehicle turned {turned_deg:.1} deg: no straight chord to take the \
         heading from; --init gnss-any-heading finds the heading with a bank of filters \
         instead, or start from a known attitude"
    )]
    NotStraight {
        /// The earlier fix's time [s].
        t0: f64,
        /// The later fix's time [s].
        t1: f64,
        /// The angle the gyros turned over the chord [deg].
        turned_deg: f64,
    },
    /// Fewer than two fixes, or none after the start's first in time.
    #[error(
        "a start in motion needs two GNSS fixes at increasing times, the later at least \
         {span} s into the IMU data; {why}"
    )]
    TooFewFixes {
        /// Time the fixes are differenced over [s] ([`VELOCITY_SPAN`]).
        span: f64,
        /// What was found instead.
        why: String,
    },
    /// The fixes imply a motion no vehicle makes (a velocity beyond
    /// [`crate::domain::SPEED`], or an acceleration beyond `g` that leaves no tilt to
    /// take from the accelerometers).
    #[error(
        "the GNSS fixes from t = {t0} s to t = {t1} s imply {what}: fixes swapped or \
         misread (latitude and longitude exchanged, a column off)?"
    )]
    ImplausibleFixes {
        /// The earlier fix's time [s].
        t0: f64,
        /// The later fix's time [s].
        t1: f64,
        /// What they imply.
        what: String,
    },
    /// The IMU samples do not cover the start.
    #[error("no IMU samples around t = {t} s, the middle of the fixes that start the run")]
    NoSamples {
        /// The start time [s].
        t: f64,
    },
}

/// Horizontal and vertical displacement from `a` to `b` in NED at `a` [m] (small
/// separations: the local radii).
fn displacement<E: EarthModel>(earth: &E, a: &Geodetic, b: &Geodetic) -> Vector3<f64> {
    let r = earth.local(a.lat, a.h).radii;
    let dlon = crate::rotation::wrap_pi(b.lon - a.lon);
    Vector3::new(
        (b.lat - a.lat) * (r.meridian + a.h),
        dlon * (r.prime_vertical + a.h) * a.lat.cos(),
        a.h - b.h,
    )
}

/// Horizontal standard deviation of a displacement between two fixes [m].
fn displacement_std(a: &GnssFix, b: &GnssFix) -> f64 {
    let h = |f: &GnssFix| f.pos_std.x.max(f.pos_std.y);
    (h(a).powi(2) + h(b).powi(2)).sqrt()
}

/// The first pair of fixes far enough apart: `(i, j)` with the shortest interval
/// ending at the earliest fix `j`, within [`InMotionConfig::max_interval`] or else
/// within [`InMotionConfig::max_straight_interval`] (the caller checks that such a
/// long chord is straight); or the best displacement seen within the first as an
/// error.
pub fn course_pair<E: EarthModel>(
    earth: &E,
    fixes: &[GnssFix],
    cfg: &InMotionConfig,
) -> Result<(usize, usize), InMotionError> {
    if fixes.len() < 2 {
        return Err(InMotionError::TooFewFixes {
            span: VELOCITY_SPAN,
            why: format!("{} given", fixes.len()),
        });
    }
    let (mut best, mut best_std) = (0.0f64, None);
    // Short chords first; then, for a slow vehicle, long ones (straight: checked by
    // the caller, who has the gyros).
    for longest in [
        cfg.max_interval,
        cfg.max_straight_interval.max(cfg.max_interval),
    ] {
        for j in 1..fixes.len() {
            for i in (0..j).rev() {
                if fixes[j].t - fixes[i].t > longest {
                    break;
                }
                let d = displacement(earth, &fixes[i].pos, &fixes[j].pos)
                    .xy()
                    .norm();
                let std = displacement_std(&fixes[i], &fixes[j]);
                if d >= cfg.displacement_sigmas * std {
                    return Ok((i, j));
                }
                if best_std.is_none() || d > best {
                    (best, best_std) = (d, Some(std));
                }
            }
        }
    }
    match best_std {
        Some(std) => Err(InMotionError::NoMotion {
            sigmas: cfg.displacement_sigmas,
            max_interval: cfg.max_straight_interval.max(cfg.max_interval),
            best,
            std,
        }),
        None => Err(InMotionError::TooFewFixes {
            span: VELOCITY_SPAN,
            why: format!(
                "no two of the {} fixes are within {} s of each other in time order",
                fixes.len(),
                cfg.max_interval
            ),
        }),
    }
}

/// The angle the gyros turned about the body's z axis between `t0` and `t1` [rad].
fn turned(samples: &[ImuSample], t0: f64, t1: f64) -> f64 {
    samples
        .iter()
        .filter(|s| s.t > t0 && s.t <= t1)
        .map(|s| s.dtheta.z)
        .sum()
}

/// Among the pairs ending within [`InMotionConfig::settle`] of the first qualifying
/// pair `first`, the straight one (the gyros turned less than
/// [`InMotionConfig::straight`]) with the largest displacement against its standard
/// deviation; `first` if none is better.
fn best_pair<E: EarthModel>(
    earth: &E,
    samples: &[ImuSample],
    fixes: &[GnssFix],
    first: (usize, usize),
    cfg: &InMotionConfig,
) -> (usize, usize) {
    let ratio = |i: usize, j: usize| {
        displacement(earth, &fixes[i].pos, &fixes[j].pos)
            .xy()
            .norm()
            / displacement_std(&fixes[i], &fixes[j])
    };
    let end = fixes[first.1].t + cfg.settle;
    let mut best = (first, ratio(first.0, first.1));
    for j in first.1..fixes.len() {
        if fixes[j].t > end {
            break;
        }
        for i in (0..j).rev() {
            if fixes[j].t - fixes[i].t > cfg.max_interval {
                break;
            }
            let r = ratio(i, j);
            if r > best.1 && turned(samples, fixes[i].t, fixes[j].t).abs() < cfg.straight {
                best = ((i, j), r);
            }
        }
    }
    best.0
}

/// Pitch and roll that turn the unit specific force `u` (body) into `w` (the yaw
/// frame: x forward level, y right level, z down): `R_y(θ) R_x(φ) u = w`, on the branch
/// nearest `pitch_guess`.
fn tilt(u: &Vector3<f64>, w: &Vector3<f64>, pitch_guess: f64) -> (f64, f64) {
    // (R_y(θ)ᵀ w)_x = cos θ w_x − sin θ w_z must equal u_x (R_x keeps x).
    let r = w.x.hypot(w.z);
    let phi = w.z.atan2(w.x);
    let a = (u.x / r).clamp(-1.0, 1.0).acos();
    let pitch = [-a - phi, a - phi]
        .into_iter()
        .map(crate::rotation::wrap_pi)
        .min_by(|p, q| (p - pitch_guess).abs().total_cmp(&(q - pitch_guess).abs()))
        .unwrap_or(pitch_guess);
    let (s, c) = pitch.sin_cos();
    let v = Vector3::new(u.x, w.y, s * w.x + c * w.z);
    let roll = crate::rotation::wrap_pi(v.z.atan2(v.y) - u.z.atan2(u.y));
    (pitch, roll)
}

/// The course of the fixes `i..=j` [rad] and its standard deviation: the direction of
/// the least-squares line through their horizontal positions (the principal axis of
/// their scatter), oriented from `i` to `j`. Its deviation is `σ / sqrt(Σ s_k²)`, `σ`
/// a fix's horizontal deviation and `s_k` the positions along the line about their
/// mean: all the fixes count, not only the chord's ends (for `N` fixes spread evenly
/// over a length `L`, `sqrt(12 / N) σ / L` against the ends' `sqrt(2) σ / L`).
fn line_course<E: EarthModel>(earth: &E, fixes: &[GnssFix], i: usize, j: usize) -> (f64, f64) {
    let p: Vec<Vector3<f64>> = fixes[i..=j]
        .iter()
        .map(|f| displacement(earth, &fixes[i].pos, &f.pos))
        .collect();
    let n = p.len() as f64;
    let mean = p.iter().fold(Vector3::zeros(), |m, x| m + x) / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for x in &p {
        let (dx, dy) = (x.x - mean.x, x.y - mean.y);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    // Principal axis of [[sxx, sxy], [sxy, syy]] at angle ½ atan2(2 sxy, sxx − syy).
    let mut course = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let chord = p[p.len() - 1] - p[0];
    let (sc, cc) = course.sin_cos();
    if cc * chord.x + sc * chord.y < 0.0 {
        course += std::f64::consts::PI;
    }
    let spread: f64 = p
        .iter()
        .map(|x| ((x.x - mean.x) * cc + (x.y - mean.y) * sc).powi(2))
        .sum();
    let sigma = fixes[i..=j]
        .iter()
        .map(|f| f.pos_std.x.max(f.pos_std.y))
        .fold(0.0f64, f64::max);
    (crate::rotation::wrap_pi(course), sigma / spread.sqrt())
}

/// The IMU sample ending nearest `t` (within one interval), if any.
fn sample_near(samples: &[ImuSample], t: f64) -> Option<usize> {
    let k = samples.partition_point(|s| s.t < t);
    let before = k.checked_sub(1);
    match (before, samples.get(k)) {
        (Some(b), Some(next)) if t - samples[b].t < next.t - t => Some(b),
        (_, Some(_)) => Some(k),
        (Some(b), None) if t - samples[b].t <= samples[b].dt => Some(b),
        _ => None,
    }
}

/// Velocity at fix `j` from the fix at most `span` seconds before it (or the chord
/// from `i`), with its horizontal standard deviation.
fn velocity_at<E: EarthModel>(
    earth: &E,
    fixes: &[GnssFix],
    i: usize,
    j: usize,
    span: f64,
) -> (Vector3<f64>, f64) {
    let k = (i..j)
        .rev()
        .find(|&k| fixes[j].t - fixes[k].t >= 0.5 * span.min(fixes[j].t - fixes[i].t))
        .unwrap_or(i);
    let dt = fixes[j].t - fixes[k].t;
    (
        displacement(earth, &fixes[k].pos, &fixes[j].pos) / dt,
        displacement_std(&fixes[k], &fixes[j]) / dt,
    )
}

/// The start in motion from `samples` (in time order) and `fixes` (module doc).
pub fn start_in_motion<E: EarthModel>(
    earth: &E,
    samples: &[ImuSample],
    fixes: &[GnssFix],
    cfg: &InMotionConfig,
) -> Result<InMotionStart, InMotionError> {
    let first = course_pair(earth, fixes, cfg)?;
    let (t0, t1) = (fixes[first.0].t, fixes[first.1].t);
    let turned_over = turned(samples, t0, t1);
    if t1 - t0 > cfg.max_interval && turned_over.abs() >= cfg.straight {
        return Err(InMotionError::NotStraight {
            t0,
            t1,
            turned_deg: turned_over.to_degrees(),
        });
    }
    let (i, j) = best_pair(earth, samples, fixes, first, cfg);
    let mut start = start_at_fix(earth, samples, fixes, i, j, cfg)?;
    let (a, b) = (&fixes[i], &fixes[j]);
    // The course of the chord is the heading at its middle; the gyros carry it on.
    let (course, sigma_course) = line_course(earth, fixes, i, j);
    let t_m = 0.5 * (a.t + b.t);
    let yaw = crate::rotation::wrap_pi(course + turned(samples, t_m, start.state.t));
    let e = start.state.euler();
    start.state = NavState::new(
        start.state.t,
        start.state.pos,
        start.state.v_n,
        Euler { yaw, ..e },
    );
    start.att_std.z = sigma_course
        .hypot(turned(samples, a.t, b.t).abs() / 6.0)
        .hypot(cfg.sideslip);
    Ok(start)
}

/// A start at fix `j` without a heading (yaw 0 with a standard deviation of π):
/// position that fix's, velocity differenced over the last [`VELOCITY_SPAN`] of fixes
/// (not before fix `i`), tilts from the accelerometers with the acceleration's
/// uncertainty (module doc). The heading comes from elsewhere: the course
/// ([`start_in_motion`]) or a bank of filters (`session::HeadingBank`).
pub fn start_at_fix<E: EarthModel>(
    earth: &E,
    samples: &[ImuSample],
    fixes: &[GnssFix],
    i: usize,
    j: usize,
    cfg: &InMotionConfig,
) -> Result<InMotionStart, InMotionError> {
    // The velocity is differenced between fixes i..=j: two distinct fixes at least,
    // their times increasing (a log in reverse order has none after its first).
    let pair = fixes
        .get(i)
        .zip(fixes.get(j))
        .filter(|(a, b)| j > i && b.t > a.t);
    let Some((a, b)) = pair else {
        return Err(InMotionError::TooFewFixes {
            span: VELOCITY_SPAN,
            why: match fixes.get(i) {
                Some(a) => format!("no fix after the one at t = {} s", a.t),
                None => format!(
                    "{} fixes, none at or after the IMU data's start",
                    fixes.len()
                ),
            },
        });
    };
    if let Some(k) = (i..j).find(|&k| fixes[k + 1].t <= fixes[k].t) {
        return Err(InMotionError::TooFewFixes {
            span: VELOCITY_SPAN,
            why: format!(
                "the fix after t = {} s is at t = {} s (the log not in time order)",
                fixes[k].t,
                fixes[k + 1].t
            ),
        });
    }
    let sample = sample_near(samples, b.t).ok_or(InMotionError::NoSamples { t: b.t })?;
    let t_s = samples[sample].t;
    let (v_n, sigma_v) = velocity_at(earth, fixes, i, j, VELOCITY_SPAN);
    let (v_before, _) = velocity_at(
        earth,
        fixes,
        i,
        j.saturating_sub(1).max(i + 1),
        VELOCITY_SPAN,
    );
    let local = earth.local(b.pos.lat, b.pos.h);
    let shift = v_n * (t_s - b.t);
    let pos = Geodetic::new(
        b.pos.lat + shift.x / (local.radii.meridian + b.pos.h),
        b.pos.lon + shift.y / ((local.radii.prime_vertical + b.pos.h) * b.pos.lat.cos()),
        b.pos.h - shift.z,
    );
    // The tilts' error is the horizontal acceleration at the start over g: of the
    // order of the change between the last two velocities.
    let accel = (v_n - v_before).xy().norm() / VELOCITY_SPAN + 2.0 * sigma_v / VELOCITY_SPAN;
    let implausible = |what: String| InMotionError::ImplausibleFixes {
        t0: a.t,
        t1: b.t,
        what,
    };
    if crate::domain::SPEED.check(v_n.norm()).is_err() {
        return Err(implausible(format!(
            "a speed of {:.0} m/s (beyond {} m/s, the escape velocity)",
            v_n.norm(),
            crate::domain::SPEED.max
        )));
    }
    // The tilts are the specific force's direction taken as gravity's: with the
    // acceleration near g they are unknown (a standard deviation beyond 45 deg).
    if accel.is_nan() || accel >= local.g_n.z {
        return Err(implausible(format!(
            "an acceleration of {:.1} m/s^2 with a velocity uncertain by {sigma_v:.1} m/s \
             (together more than g: no tilt can be taken from the accelerometers)",
            (v_n - v_before).xy().norm() / VELOCITY_SPAN
        )));
    }
    let half = 0.5 * cfg.level_window;
    let (sum_dv, sum_dt) = samples
        .iter()
        .filter(|s| (s.t - 0.5 * s.dt - t_s).abs() <= half)
        .fold((Vector3::zeros(), 0.0), |(v, t), s| (v + s.dvel, t + s.dt));
    if sum_dt <= 0.0 {
        return Err(InMotionError::NoSamples { t: t_s });
    }
    let f_b = sum_dv / sum_dt;
    let naive_pitch = f_b.x.atan2(f_b.y.hypot(f_b.z));
    let (pitch, roll) = tilt(&f_b.normalize(), &Vector3::new(0.0, 0.0, -1.0), naive_pitch);
    let tilt_std = (accel / local.g_n.z).hypot(0.2f64.to_radians());
    let pos_h = b.pos_std.x.max(b.pos_std.y);
    Ok(InMotionStart {
        state: NavState::new(
            t_s,
            pos,
            v_n,
            Euler {
                roll,
                pitch,
                yaw: 0.0,
            },
        ),
        sample,
        pos_std: Vector3::new(pos_h, pos_h, b.pos_std.z),
        vel_std: Vector3::new(sigma_v, sigma_v, 2.0 * sigma_v)
            + Vector3::repeat(accel * VELOCITY_SPAN),
        att_std: Vector3::new(tilt_std, tilt_std, std::f64::consts::PI),
        fixes: (i, j),
        speed: v_n.xy().norm(),
    })
}

/// Time over which the start's velocity is differenced from the fixes [s].
pub const VELOCITY_SPAN: f64 = 2.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// The tilt solution turns the body's specific force into the yaw frame's, for
    /// any roll and pitch (the rotation is checked directly).
    #[test]
    fn tilt_solves_the_rotation() {
        for (roll, pitch) in [(0.1, -0.2), (-0.5, 0.3), (0.0, 0.0), (1.0, 0.7)] {
            let c_yb = nalgebra::Rotation3::from_euler_angles(roll, pitch, 0.0);
            let w = Vector3::new(0.3, -0.2, -9.7).normalize();
            let u = c_yb.inverse() * w;
            let (p, r) = tilt(&u, &w, pitch + 0.05);
            assert!(
                (p - pitch).abs() < 1e-12 && (r - roll).abs() < 1e-12,
                "{p} {r}"
            );
        }
    }
}
