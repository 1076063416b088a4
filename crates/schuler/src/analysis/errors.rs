//! Errors of a navigation result against a truth at the same times: epochs matched
//! by time (or the truth interpolated between its epochs), position errors in metres
//! along the truth's north, east and down axes, velocity and attitude errors.
//!
//! # Matching
//! Every NAV epoch in the `[start, end]` window is compared with the truth at its
//! time: a truth epoch within 1e-6 s is taken as it is; otherwise the truth is
//! interpolated linearly in time between the two epochs around it (longitude, roll and
//! yaw unwrapped across ±180°/360°). Linear interpolation of Euler angles is exact only
//! for rotation about one axis; between truth epochs 1 s apart the error it makes is of
//! second order in the angle turned. NAV epochs outside the truth's span are skipped and
//! counted, as is the longest truth interval bridged.
//!
//! # Errors (NAV minus truth)
//! Position in metres along the truth's NED axes, with the WGS84 radii at the truth's
//! latitude (`EarthModel::radii`): `dN = (lat - lat_t) (R_M + h_t)`,
//! `dE = wrap(lon - lon_t) (R_N + h_t) cos(lat_t)`, `dD = -(h - h_t)`; the arc-length
//! linearization is good to a relative `d / R` (1e-6 for an error of 6 m). Horizontal
//! `hypot(dN, dE)` (the seed's circular error ΔS), 3-D `|(dN, dE, dD)|`, vertical `dD`.
//! Velocity `v_n - v_n,t` [m/s]. Attitude: the differences of roll, pitch and yaw, each
//! wrapped to (-180°, 180°].

use crate::earth::{EarthModel, Geodetic, Wgs84};
use crate::rotation::{Euler, rotation_vector_from_quaternion, wrap_pi};
use nalgebra::{UnitQuaternion, Vector3};

/// Two epochs closer than this [s] are the same epoch.
pub const TIME_TOLERANCE_S: f64 = 1e-6;

/// One epoch of a navigation result or truth: position, NED velocity and ZYX attitude
/// of the body (FRD) in the local-level NED frame, SI units and radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavRecord {
    /// Time [s of week; continued past a week rollover inside one file].
    pub t_sow: f64,
    /// Geodetic position (WGS84).
    pub pos: Geodetic,
    /// Velocity in NED [m/s].
    pub v_n: Vector3<f64>,
    /// Attitude, body to NED.
    pub att: Euler,
}

impl From<&crate::nav::NavState> for NavRecord {
    /// A mechanization's or filter's state as a record (attitude as ZYX Euler angles).
    fn from(s: &crate::nav::NavState) -> Self {
        Self {
            t_sow: s.t,
            pos: s.pos,
            v_n: s.v_n,
            att: s.euler(),
        }
    }
}

/// Errors of one NAV epoch against the truth at its time (NAV minus truth).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochErrors {
    /// Time of the NAV epoch [s of week].
    pub t_sow: f64,
    /// Position error along the truth's north, east, down axes [m].
    pub pos_n: Vector3<f64>,
    /// Velocity error in NED [m/s].
    pub v_n: Vector3<f64>,
    /// Roll, pitch and yaw differences, each wrapped to (-pi, pi] [rad].
    pub att: Euler,
    /// Whether the truth was interpolated (no truth epoch within 1e-6 s).
    pub interpolated: bool,
}

impl EpochErrors {
    /// Horizontal error `hypot(dN, dE)` [m] (the seed's circular error ΔS).
    pub fn horizontal(&self) -> f64 {
        self.pos_n.x.hypot(self.pos_n.y)
    }
}

/// How the NAV epochs met the truth.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Matching {
    /// Epochs with a truth epoch within 1e-6 s.
    pub exact: usize,
    /// Epochs at which the truth was interpolated.
    pub interpolated: usize,
    /// Epochs before the truth's first epoch (skipped).
    pub before_truth: usize,
    /// Epochs after the truth's last epoch (skipped).
    pub after_truth: usize,
    /// Epochs outside the `--start`/`--end` window (skipped).
    pub outside_window: usize,
    /// Longest truth interval interpolated across [s] (0 if none).
    pub max_bridged_s: f64,
}

impl Matching {
    /// Epochs compared.
    pub fn matched(&self) -> usize {
        self.exact + self.interpolated
    }
}

/// The truth at `t` between epochs `a` and `b` (`a.t_sow < t < b.t_sow`), linear in
/// time; longitude, roll and yaw follow the shorter way round.
pub fn interpolate(a: &NavRecord, b: &NavRecord, t: f64) -> NavRecord {
    let f = (t - a.t_sow) / (b.t_sow - a.t_sow);
    let lin = |x: f64, y: f64| x + f * (y - x);
    let ang = |x: f64, y: f64| x + f * wrap_pi(y - x);
    NavRecord {
        t_sow: t,
        pos: Geodetic {
            lat: lin(a.pos.lat, b.pos.lat),
            lon: ang(a.pos.lon, b.pos.lon),
            h: lin(a.pos.h, b.pos.h),
        },
        v_n: a.v_n + (b.v_n - a.v_n) * f,
        att: Euler::new(
            ang(a.att.roll, b.att.roll),
            lin(a.att.pitch, b.att.pitch),
            ang(a.att.yaw, b.att.yaw),
        ),
    }
}

/// Errors of `nav` against `truth` at the same time (module docs: the NED position
/// error with WGS84 radii at the truth's latitude and height).
pub fn errors_at(nav: &NavRecord, truth: &NavRecord) -> EpochErrors {
    let r = Wgs84.radii(truth.pos.lat);
    let h = truth.pos.h;
    let pos_n = Vector3::new(
        (nav.pos.lat - truth.pos.lat) * (r.meridian + h),
        wrap_pi(nav.pos.lon - truth.pos.lon) * (r.prime_vertical + h) * truth.pos.lat.cos(),
        h - nav.pos.h,
    );
    EpochErrors {
        t_sow: nav.t_sow,
        pos_n,
        v_n: nav.v_n - truth.v_n,
        att: Euler::new(
            wrap_pi(nav.att.roll - truth.att.roll),
            wrap_pi(nav.att.pitch - truth.att.pitch),
            wrap_pi(nav.att.yaw - truth.att.yaw),
        ),
        interpolated: false,
    }
}

/// Attitude error as a small rotation about north, east, down: the `ψ` with
/// `Ĉ_bn = (I − [ψ×]) C_bn`, the filter's attitude-error convention
/// ([`crate::filter::measurement`]), exactly `ψ = −rotvec(q̂_bn q_bn⁻¹)`.
pub fn attitude_error(
    q_bn_est: &UnitQuaternion<f64>,
    q_bn_true: &UnitQuaternion<f64>,
) -> Vector3<f64> {
    -rotation_vector_from_quaternion(&(q_bn_est * q_bn_true.inverse()))
}

/// The truth at one time, as [`TruthCursor::at`] finds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TruthAt {
    /// Before the truth's first epoch (by more than [`TIME_TOLERANCE_S`]).
    Before,
    /// After its last epoch.
    After,
    /// A truth epoch within [`TIME_TOLERANCE_S`].
    Exact(NavRecord),
    /// Interpolated ([`interpolate`]) across a truth interval of this length [s].
    Interpolated(NavRecord, f64),
}

/// Finds the truth at times that do not decrease, walking a sorted truth once.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TruthCursor {
    /// `truth[j].t_sow <= t + tol`, advanced monotonically.
    j: usize,
}

impl TruthCursor {
    /// The truth at `t` (the epoch within [`TIME_TOLERANCE_S`], else interpolated
    /// between the two around it); `truth` sorted by time, the same on every call.
    pub fn at(&mut self, truth: &[NavRecord], t: f64) -> TruthAt {
        let (Some(first), Some(last)) = (truth.first(), truth.last()) else {
            return TruthAt::After;
        };
        if t < first.t_sow - TIME_TOLERANCE_S {
            return TruthAt::Before;
        }
        if t > last.t_sow + TIME_TOLERANCE_S {
            return TruthAt::After;
        }
        let j = &mut self.j;
        while *j + 1 < truth.len() && truth[*j + 1].t_sow <= t + TIME_TOLERANCE_S {
            *j += 1;
        }
        if (truth[*j].t_sow - t).abs() <= TIME_TOLERANCE_S {
            TruthAt::Exact(truth[*j])
        } else {
            // truth[j].t < t - tol and truth[j + 1].t > t + tol: t is inside the span
            // and not within the tolerance of its last epoch, so j + 1 exists.
            let (a, b) = (&truth[*j], &truth[*j + 1]);
            TruthAt::Interpolated(interpolate(a, b, t), b.t_sow - a.t_sow)
        }
    }
}

/// The error of every NAV epoch inside `[start, end]` and the truth's span (both
/// sorted by time), exact within [`TIME_TOLERANCE_S`] else interpolated.
pub fn match_epochs(
    nav: &[NavRecord],
    truth: &[NavRecord],
    start: Option<f64>,
    end: Option<f64>,
) -> (Vec<EpochErrors>, Matching) {
    let mut m = Matching::default();
    let mut out = Vec::with_capacity(nav.len());
    let mut cursor = TruthCursor::default();
    for row in nav {
        let t = row.t_sow;
        if start.is_some_and(|s| t < s) || end.is_some_and(|e| t > e) {
            m.outside_window += 1;
            continue;
        }
        let e = match cursor.at(truth, t) {
            TruthAt::Before => {
                m.before_truth += 1;
                continue;
            }
            TruthAt::After => {
                m.after_truth += 1;
                continue;
            }
            TruthAt::Exact(truth) => {
                m.exact += 1;
                errors_at(row, &truth)
            }
            TruthAt::Interpolated(truth, bridged) => {
                m.interpolated += 1;
                m.max_bridged_s = m.max_bridged_s.max(bridged);
                EpochErrors {
                    interpolated: true,
                    ..errors_at(row, &truth)
                }
            }
        };
        out.push(e);
    }
    (out, m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_error_takes_the_short_way_across_north() {
        // NAV yaw 0.5 deg, truth 359.5 deg: the error is +1 deg, not -359 deg (a few
        // ulps of 2 pi from the shift and wrap); roll -179.5 vs 179.5: +1 deg too.
        let at = |roll: f64, yaw: f64| NavRecord {
            t_sow: 0.0,
            pos: Geodetic::from_degrees(45.0, 7.0, 100.0),
            v_n: Vector3::zeros(),
            att: Euler::from_degrees(roll, 0.0, yaw),
        };
        let e = errors_at(&at(-179.5, 0.5), &at(179.5, 359.5));
        assert!((e.att.yaw - 1f64.to_radians()).abs() < 1e-14, "{:?}", e.att);
        assert!(
            (e.att.roll - 1f64.to_radians()).abs() < 1e-14,
            "{:?}",
            e.att
        );
        assert_eq!(e.pos_n, Vector3::zeros());
    }

    #[test]
    fn attitude_error_is_the_small_rotation_the_filter_estimates() {
        // Truth level, heading 30 deg; the estimate turned by 1 mrad further about
        // down: C_est = (I - [psi x]) C_true with psi = (0, 0, -1e-3).
        let truth = Euler::from_degrees(0.0, 0.0, 30.0).to_quaternion();
        let est = Euler::new(0.0, 0.0, 30f64.to_radians() + 1e-3).to_quaternion();
        let psi = attitude_error(&est, &truth);
        assert!(
            (psi - Vector3::new(0.0, 0.0, -1e-3)).norm() < 1e-15,
            "{psi}"
        );
        // A tilt about north: roll +1 mrad at zero heading is a turn about north.
        let est = Euler::new(1e-3, 0.0, 0.0).to_quaternion();
        let psi = attitude_error(&est, &Euler::default().to_quaternion());
        assert!(
            (psi - Vector3::new(-1e-3, 0.0, 0.0)).norm() < 1e-15,
            "{psi}"
        );
    }
}
