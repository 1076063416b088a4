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
//! counted, as is the longest truth interval bridged. Interpolating latitude and
//! longitude is not valid across a pole (the longitude jumps by 180° there): near a
//! pole the truth should hold the NAV's epochs.
//!
//! # Errors (NAV minus truth), through ECEF
//! Defined at and across the poles: no latitude or longitude is differenced.
//!
//! - Position: the ECEF difference (the straight chord between the two points)
//!   resolved along the truth's north and east, `(dN, dE) = [C_ne,tᵀ (r^e − r^e_t)]_NE`
//!   (`hypot(dN, dE)` is the seed's circular error ΔS), and down as the height
//!   difference, `dD = −(h − h_t)` (not the chord's down component, which holds the
//!   Earth's curvature under the horizontal error, `d² / 2R`). Horizontal `hypot(dN, dE)`, 3-D `|(dN, dE, dD)|`,
//!   vertical `dD`.
//! - Velocity and attitude: the NAV's NED velocity and body attitude carried into the
//!   truth's NED frame by `C_nt = C_ne,tᵀ C_ne` (the rotation between the two NED
//!   frames, [`c_ned_to_ned`]) before differencing: `δv = C_nt v̂ − v_t` [m/s];
//!   roll, pitch and yaw of `C_nt Ĉ_bn` minus the truth's, each wrapped to (-180°,
//!   180°]; and `ψ` with `C_nt Ĉ_bn = (I − [ψ×]) C_bn`, the small rotation about the
//!   truth's north, east and down ([`attitude_error`]).
//!
//! These are differences of the vectors and body axes in space: the psi-angle errors of
//! [`crate::nav::frame`] (`δr`, `δv`, `ψ` in one frame), which the filter's covariance
//! describes. Differencing coordinates instead — `R_M δφ`, `R_N cos φ δλ`, and velocity
//! components and Euler angles each in its own NED frame — agrees to first order in the
//! position error `d` over the radius `R` and differs from the above by:
//! - the frames' relative turn `δθ` (`δλ sin φ` about down, the meridian convergence,
//!   and the tilt `d / R`): `δθ × v` in velocity, `δλ sin φ` in yaw, `d / R` in roll
//!   and pitch (at 45° a 10 m east error turns yaw by 1.1e-6 rad, 6e-5°);
//! - in the north error, the curvature of the parallel, `dE² tan φ / 2(R_N + h)`, and
//!   `(h − h_t) dN / R` (both below 1e-5 m for errors of metres);
//! - near a pole, everything: 30 m from the pole on opposite meridians two points are
//!   60 m apart, not `π` 30 m, and their NED frames are turned by 180°.

use crate::earth::{EarthModel, Geodetic, Wgs84, c_ne, c_ned_to_ned};
use crate::nav::NavState;
use crate::rotation::{Euler, rotation_vector_from_quaternion, wrap_pi};
use nalgebra::{Rotation3, UnitQuaternion, Vector3};

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

impl From<&NavState> for NavRecord {
    /// A mechanization's or filter's state as a record (attitude as ZYX Euler angles).
    fn from(s: &NavState) -> Self {
        Self {
            t_sow: s.t,
            pos: s.pos,
            v_n: s.v_n,
            att: s.euler(),
        }
    }
}

impl From<&NavRecord> for NavState {
    /// A record as a state (attitude as the quaternion of its Euler angles).
    fn from(r: &NavRecord) -> Self {
        NavState::new(r.t_sow, r.pos, r.v_n, r.att)
    }
}

/// Errors of one NAV epoch against the truth at its time (NAV minus truth; module
/// docs: through ECEF, in the truth's NED frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochErrors {
    /// Time of the NAV epoch [s of week].
    pub t_sow: f64,
    /// Position error along the truth's north and east (ECEF chord) and down (height
    /// difference, `h_t − h`) [m].
    pub pos_n: Vector3<f64>,
    /// Velocity error in the truth's NED frame, `C_nt v̂ − v_t` [m/s].
    pub v_n: Vector3<f64>,
    /// Roll, pitch and yaw of the NAV attitude carried into the truth's NED frame minus
    /// the truth's, each wrapped to (-pi, pi] [rad].
    pub att: Euler,
    /// Attitude error as a small rotation about the truth's north, east, down [rad]:
    /// `C_nt Ĉ_bn = (I − [ψ×]) C_bn` ([`attitude_error`]).
    pub psi: Vector3<f64>,
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

/// Errors of `nav` against `truth` at the same time on WGS84 (module docs), the
/// records taken as [`NavState`]s by [`errors_between`].
pub fn errors_at(nav: &NavRecord, truth: &NavRecord) -> EpochErrors {
    errors_between(&Wgs84, &NavState::from(nav), &NavState::from(truth))
}

/// Errors of `nav` against `truth` at the same time (navigated minus true) on `earth`,
/// through ECEF and defined at and across the poles (module docs): position as the
/// ECEF difference resolved along the truth's north and east with `dD = h_t − h`;
/// velocity and attitude carried from the NAV's NED frame into the truth's by
/// [`c_ned_to_ned`] before differencing. Latitudes past ±90° (a NED
/// mechanization carried over a pole) are the points and frames they denote. At the
/// same position the frames coincide exactly, so equal states give zero position,
/// velocity and Euler-angle errors, bit for bit.
pub fn errors_between<E: EarthModel>(earth: &E, nav: &NavState, truth: &NavState) -> EpochErrors {
    let c_nt = c_ned_to_ned(&nav.pos, &truth.pos);
    let d = c_ne(truth.pos.lat, truth.pos.lon).transpose()
        * (earth.geodetic_to_ecef(&nav.pos) - earth.geodetic_to_ecef(&truth.pos));
    let q_nt = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_nt));
    let q_bt = q_nt * nav.q_bn;
    let (att, att_t) = (Euler::from_quaternion(&q_bt), truth.euler());
    EpochErrors {
        t_sow: nav.t,
        pos_n: Vector3::new(d.x, d.y, truth.pos.h - nav.pos.h),
        v_n: c_nt * nav.v_n - truth.v_n,
        att: Euler::new(
            wrap_pi(att.roll - att_t.roll),
            wrap_pi(att.pitch - att_t.pitch),
            wrap_pi(att.yaw - att_t.yaw),
        ),
        psi: attitude_error(&q_bt, &truth.q_bn),
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
    use crate::rotation::quaternion_from_rotation_vector;
    use nalgebra::Matrix3;

    // WGS84 written out from its definition, independent of `crate::earth`.
    const A: f64 = 6_378_137.0;
    const E2: f64 = (1.0 / 298.257_223_563) * (2.0 - 1.0 / 298.257_223_563);

    /// ECEF of a geodetic position (`N = a / sqrt(1 − e² sin² φ)`).
    fn ecef(lat: f64, lon: f64, h: f64) -> Vector3<f64> {
        let n = A / (1.0 - E2 * lat.sin().powi(2)).sqrt();
        Vector3::new(
            (n + h) * lat.cos() * lon.cos(),
            (n + h) * lat.cos() * lon.sin(),
            (n * (1.0 - E2) + h) * lat.sin(),
        )
    }

    /// Geodetic position of an ECEF point by the fixed point
    /// `φ = atan2(z + e² N sin φ, p)` (contracts by e² per pass) and the height
    /// `h = p cos φ + z sin φ − a sqrt(1 − e² sin² φ)`, well conditioned at the poles.
    fn geodetic(r: &Vector3<f64>) -> Geodetic {
        let p = r.x.hypot(r.y);
        let mut lat = r.z.atan2(p * (1.0 - E2));
        for _ in 0..30 {
            let n = A / (1.0 - E2 * lat.sin().powi(2)).sqrt();
            lat = (r.z + E2 * n * lat.sin()).atan2(p);
        }
        let h = p * lat.cos() + r.z * lat.sin() - A * (1.0 - E2 * lat.sin().powi(2)).sqrt();
        Geodetic::new(lat, r.y.atan2(r.x), h)
    }

    /// North, east and down at a position as the columns of a matrix, in ECEF.
    fn ned_axes(p: &Geodetic) -> Matrix3<f64> {
        let (s, c, so, co) = (p.lat.sin(), p.lat.cos(), p.lon.sin(), p.lon.cos());
        let north = Vector3::new(-s * co, -s * so, c);
        let east = Vector3::new(-so, co, 0.0);
        Matrix3::from_columns(&[north, east, north.cross(&east)])
    }

    fn state(p: Geodetic, v_n: Vector3<f64>, q_bn: UnitQuaternion<f64>) -> NavState {
        NavState {
            t: 0.0,
            pos: p,
            v_n,
            q_bn,
        }
    }

    /// A truth state and the NAV state displaced from it by `d` along the truth's
    /// north, east and down (the point `r_t + C_ne,t d`), with the same velocity and
    /// body attitude in space, resolved in its own NED frame.
    fn displaced(truth: &NavState, d: Vector3<f64>) -> NavState {
        let c_t = ned_axes(&truth.pos);
        let p = truth.pos;
        let pos = geodetic(&(ecef(p.lat, p.lon, p.h) + c_t * d));
        let c_tn = ned_axes(&pos).transpose() * c_t;
        let q_tn = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_tn));
        state(pos, c_tn * truth.v_n, q_tn * truth.q_bn)
    }

    fn truth_at(lat_deg: f64, lon_deg: f64) -> NavState {
        state(
            Geodetic::from_degrees(lat_deg, lon_deg, 300.0),
            Vector3::new(30.0, -40.0, 1.5),
            Euler::from_degrees(2.0, -3.0, 250.0).to_quaternion(),
        )
    }

    /// A state displaced by a known north, east, down offset from the truth: at 45°,
    /// at 89.999° (112 m from the pole), and at 89.999° by 200 m north, which ends 88 m
    /// past the pole on the opposite meridian. The horizontal error is the offset's
    /// north and east (to the 1e-8 m rounding of 6.4e6-m ECEF coordinates); down is the
    /// height difference, which is the offset's down less the curvature of the Earth
    /// under the horizontal offset, `|d_h|² / 2R` (3.2e-3 m for 200 m; to 1 %, the
    /// radius in the offset's direction being between `R_M` and `R_N`); velocity
    /// and attitude, the same in space, have no error. Differencing latitude and
    /// longitude instead is metres out at 89.999° and wrong by hundreds past the pole.
    #[test]
    fn a_known_offset_is_the_error_at_45_deg_near_and_across_the_pole() {
        for (lat, d) in [
            (45.0, Vector3::new(30.0, -40.0, 15.0)),
            (89.999, Vector3::new(30.0, -40.0, 15.0)),
            (89.999, Vector3::new(200.0, 25.0, -5.0)),
        ] {
            let truth = truth_at(lat, 25.0);
            let nav = displaced(&truth, d);
            let e = errors_between(&Wgs84, &nav, &truth);
            assert!((e.pos_n.xy() - d.xy()).norm() < 1e-8, "{lat}: {e:?}");
            assert!(
                (e.pos_n.z - (truth.pos.h - nav.pos.h)).abs() < 1e-8,
                "{lat}: {e:?}"
            );
            let sag = d.xy().norm_squared() / (2.0 * 6.37e6);
            assert!((e.pos_n.z - d.z + sag).abs() < 1e-2 * sag, "{lat}: {e:?}");
            assert!(e.v_n.norm() < 1e-12, "{lat}: {e:?}");
            assert!(e.psi.norm() < 1e-14, "{lat}: {e:?}");
            for a in [e.att.roll, e.att.pitch, e.att.yaw] {
                assert!(a.abs() < 1e-13, "{lat}: {e:?}");
            }
            // The latitude/longitude linearization, for contrast.
            let r = Wgs84.radii(truth.pos.lat);
            let lin_e = wrap_pi(nav.pos.lon - truth.pos.lon)
                * (r.prime_vertical + truth.pos.h)
                * truth.pos.lat.cos();
            let lin_n = (nav.pos.lat - truth.pos.lat) * (r.meridian + truth.pos.h);
            let off = (Vector3::new(lin_n, lin_e, 0.0) - d).xy().norm();
            assert!(if lat < 80.0 { off < 1e-3 } else { off > 1.0 }, "{off}");
        }
    }

    /// Exactly across the pole: two points on opposite meridians, each `ρ` = 30 m from
    /// the polar axis at the same height, are `2ρ` apart (plane geometry in the
    /// equatorial plane; latitude from `ρ = (R_N + h) cos φ`, `R_N = a / sqrt(1 − e²)` at
    /// the pole), where latitude and longitude differences give `π ρ`. Heading north
    /// on one side is heading south on the other, the same direction in space: no
    /// yaw error. A NED state carried past the pole (latitude 90° + x on the truth's
    /// meridian) is that same point and frame, and gives the same errors.
    #[test]
    fn across_the_pole_the_error_is_the_short_chord() {
        let h = 300.0;
        let rn = A / (1.0 - E2).sqrt();
        let rho = 30.0;
        let lat = (rho / (rn + h)).acos().to_degrees();
        let at = |lat: f64, lon: f64, yaw: f64| {
            state(
                Geodetic::from_degrees(lat, lon, h),
                Vector3::zeros(),
                Euler::from_degrees(0.0, 0.0, yaw).to_quaternion(),
            )
        };
        let truth = at(lat, -155.0, 180.0);
        for nav in [at(lat, 25.0, 0.0), at(180.0 - lat, -155.0, 180.0)] {
            let e = errors_between(&Wgs84, &nav, &truth);
            assert!(
                (e.horizontal() - 2.0 * rho).abs() < 1e-8,
                "{}",
                e.horizontal()
            );
            // Towards the pole from the truth: north.
            assert!((e.pos_n.x - 2.0 * rho).abs() < 1e-8, "{e:?}");
            assert!(e.pos_n.z.abs() < 1e-9 && e.att.yaw.abs() < 1e-12, "{e:?}");
        }
        // The estimate exactly at the pole: ρ north.
        let e = errors_between(&Wgs84, &at(90.0, 0.0, 0.0), &truth);
        assert!(
            (e.pos_n - Vector3::new(rho, 0.0, 0.0)).norm() < 1e-8,
            "{e:?}"
        );
    }

    /// A known small rotation of the body: at one position, and with the NAV 40 m
    /// across the pole from the truth (its frame turned 180°), `Ĉ_bn` carried into the
    /// truth's frame is `exp(−[ψ×]) C_bn` and the error is `ψ`.
    #[test]
    fn attitude_error_is_a_known_small_rotation() {
        let psi = Vector3::new(1e-3, -2e-3, 3e-3);
        let turn = quaternion_from_rotation_vector(&-psi);
        for (lat, d) in [
            (45.0, Vector3::zeros()),
            (89.9999, Vector3::new(40.0, 0.0, 0.0)),
        ] {
            let truth = truth_at(lat, 25.0);
            let mut nav = displaced(&truth, d);
            // Turn the body in space: about the truth's axes, expressed in the NAV's.
            let c_tn = ned_axes(&nav.pos).transpose() * ned_axes(&truth.pos);
            let q_tn =
                UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_tn));
            nav.q_bn = q_tn * turn * q_tn.inverse() * nav.q_bn;
            let e = errors_between(&Wgs84, &nav, &truth);
            assert!((e.psi - psi).norm() < 1e-12, "{lat}: {:?}", e.psi);
        }
        // The filter's sign: yaw turned 1 mrad further is ψ = (0, 0, −1e-3); a roll of
        // +1 mrad at zero heading is a turn about north, ψ = (−1e-3, 0, 0).
        let truth = Euler::from_degrees(0.0, 0.0, 30.0).to_quaternion();
        let est = Euler::new(0.0, 0.0, 30f64.to_radians() + 1e-3).to_quaternion();
        let psi = attitude_error(&est, &truth);
        assert!(
            (psi - Vector3::new(0.0, 0.0, -1e-3)).norm() < 1e-15,
            "{psi}"
        );
        let est = Euler::new(1e-3, 0.0, 0.0).to_quaternion();
        let psi = attitude_error(&est, &Euler::default().to_quaternion());
        assert!(
            (psi - Vector3::new(-1e-3, 0.0, 0.0)).norm() < 1e-15,
            "{psi}"
        );
    }

    /// NAV yaw 0.5°, truth 359.5°: the error is +1°, not −359° (a few ulps of 2π from
    /// the shift and wrap); roll −179.5° against 179.5°: +1° too. At 45° and at
    /// 89.999°; equal positions, so no position error.
    #[test]
    fn heading_and_roll_errors_take_the_short_way_round() {
        for lat in [45.0, 89.999] {
            let at = |roll: f64, yaw: f64| NavRecord {
                t_sow: 0.0,
                pos: Geodetic::from_degrees(lat, 7.0, 100.0),
                v_n: Vector3::zeros(),
                att: Euler::from_degrees(roll, 0.0, yaw),
            };
            let e = errors_at(&at(-179.5, 0.5), &at(179.5, 359.5));
            let one = 1f64.to_radians();
            assert!((e.att.yaw - one).abs() < 1e-14, "{:?}", e.att);
            assert!((e.att.roll - one).abs() < 1e-14, "{:?}", e.att);
            assert_eq!(e.pos_n, Vector3::zeros());
        }
    }

    /// Equal states give zero position, velocity and Euler-angle errors, bit for bit
    /// (the frame rotation is exactly the identity there), at the pole too; `ψ` is
    /// zero to the rounding of `q q⁻¹`.
    #[test]
    fn equal_states_have_no_error() {
        for lat in [45.0, 90.0, -89.9] {
            let s = truth_at(lat, 25.0);
            let e = errors_between(&Wgs84, &s, &s);
            assert_eq!(e.pos_n, Vector3::zeros());
            assert_eq!(e.v_n, Vector3::zeros());
            assert!(e.psi.norm() < 1e-16, "{:?}", e.psi);
            assert_eq!(e.att, Euler::new(0.0, 0.0, 0.0));
        }
    }

    /// At 70° the latitude/longitude differences agree: 20 m north and 30 m east of the
    /// truth, 5 m higher, yaw 0.1° more: horizontal to 1e-3 m (the curvature of the
    /// parallel, 30² tan 70° / 2 R = 2e-4 m), height exactly; yaw differs by the
    /// meridian convergence over the 30 m, `δλ sin φ` = 30 tan(70°) / (R_N + h) =
    /// 1.29e-5 rad (to its second order, 1e-10 rad), which differencing yaw in two
    /// frames keeps.
    #[test]
    fn away_from_the_poles_it_agrees_with_latitude_and_longitude() {
        let at = |lat: f64, lon: f64, h: f64, yaw: f64| NavRecord {
            t_sow: 0.0,
            pos: Geodetic::from_degrees(lat, lon, h),
            v_n: Vector3::zeros(),
            att: Euler::from_degrees(0.0, 0.0, yaw),
        };
        let truth = at(70.0, 25.0, 300.0, 40.0);
        let r = Wgs84.radii(truth.pos.lat);
        let lat = 70.0 + (20.0 / (r.meridian + 300.0)).to_degrees();
        let lon =
            25.0 + (30.0 / ((r.prime_vertical + 300.0) * 70f64.to_radians().cos())).to_degrees();
        let nav = at(lat, lon, 305.0, 40.1);
        let e = errors_at(&nav, &truth);
        assert!(
            (e.pos_n.xy() - Vector3::new(20.0, 30.0, 0.0).xy()).norm() < 1e-3,
            "{e:?}"
        );
        assert_eq!(e.pos_n.z, -5.0);
        let convergence = 30.0 * 70f64.to_radians().tan() / (r.prime_vertical + 300.0);
        assert!(
            (0.1f64.to_radians() - convergence - e.att.yaw).abs() < 1e-9,
            "{e:?}"
        );
    }
}
