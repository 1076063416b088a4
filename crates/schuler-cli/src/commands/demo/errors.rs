//! Errors of a navigated track against the simulator's truth, in the seed's terms
//! ([`schuler::analysis::errors`]): the circular position error `ΔS` (the horizontal
//! error), the height error and the attitude errors; near a pole through ECEF
//! ([`errors_through_ecef`]), where latitude and longitude differences fail.

use super::capture::Recording;
use super::modes::Track;
use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use schuler::analysis::errors::{EpochErrors, NavRecord, errors_at};
use schuler::earth::{EarthModel, Wgs84, c_ne};
use schuler::nav::NavState;
use schuler::rotation::{Euler, wrap_pi};

/// The errors of every epoch of `track` (navigated minus true) by `at`
/// ([`errors_at`] through [`NavRecord`]s for the sortie, [`errors_through_ecef`]
/// across the pole).
fn each(
    track: &Track,
    rec: &Recording,
    at: impl Fn(&NavState, &NavState) -> EpochErrors,
) -> Vec<EpochErrors> {
    track
        .epochs
        .iter()
        .map(|e| at(&e.state, &rec.truth_at(e.state.t).state))
        .collect()
}

/// The errors of every epoch of `track` (navigated minus true) in latitude and
/// longitude differences ([`errors_at`], as `schuler compare` computes them).
pub fn errors(track: &Track, rec: &Recording) -> Vec<EpochErrors> {
    each(track, rec, |nav, truth| {
        errors_at(&NavRecord::from(nav), &NavRecord::from(truth))
    })
}

/// The errors of every epoch of `track` through ECEF ([`errors_through_ecef`]),
/// valid at and across the poles.
pub fn errors_near_pole(track: &Track, rec: &Recording) -> Vec<EpochErrors> {
    each(track, rec, errors_through_ecef)
}

/// Height error (up) [m].
pub fn height(e: &EpochErrors) -> f64 {
    -e.pos_n.z
}

/// The epoch at time `t` (nearest whole second), if the track reaches it.
pub fn at(errors: &[EpochErrors], t: f64) -> Option<&EpochErrors> {
    let t0 = errors.first()?.t_sow;
    errors.get((t - t0).round().max(0.0) as usize)
}

/// Largest circular error over epochs in `[from, to]` [m].
pub fn max_circular(errors: &[EpochErrors], from: f64, to: f64) -> f64 {
    errors
        .iter()
        .filter(|e| e.t_sow >= from && e.t_sow <= to)
        .map(EpochErrors::horizontal)
        .fold(0.0, f64::max)
}

/// Errors of `nav` against `truth` at the same time through ECEF, defined at and
/// across the poles (navigated minus true): the position difference in ECEF resolved
/// along the truth's north and east (`dN`, `dE`; `hypot` is the seed's `ΔS`), the height
/// difference as `dD = −(h − h_t)`, and velocity and attitude carried into the
/// truth's NED frame (`C_nt = C_ne(truth)ᵀ C_ne(nav)`) before differencing.
///
/// [`errors_at`] linearizes latitude and longitude differences (`R δφ`, `R cos φ δλ`),
/// which holds while the error is small against the distance to the pole: two points
/// 30 m from the pole on opposite meridians are 60 m apart, not `π` 30 m, and each
/// state's velocity and yaw are resolved in its own NED frame, turned by `δλ` from the
/// other's. Away from the poles the two agree to second order in the error over the
/// radius (chord against arc).
pub fn errors_through_ecef(nav: &NavState, truth: &NavState) -> EpochErrors {
    let c_ne_t = c_ne(truth.pos.lat, truth.pos.lon);
    let c_nt = c_ne_t.transpose() * c_ne(nav.pos.lat, nav.pos.lon);
    let d = c_ne_t.transpose()
        * (Wgs84.geodetic_to_ecef(&nav.pos) - Wgs84.geodetic_to_ecef(&truth.pos));
    let q_nt = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_nt));
    let att = Euler::from_quaternion(&(q_nt * nav.q_bn));
    let att_t = truth.euler();
    EpochErrors {
        t_sow: nav.t,
        pos_n: Vector3::new(d.x, d.y, truth.pos.h - nav.pos.h),
        v_n: c_nt * nav.v_n - truth.v_n,
        att: Euler::new(
            wrap_pi(att.roll - att_t.roll),
            wrap_pi(att.pitch - att_t.pitch),
            wrap_pi(att.yaw - att_t.yaw),
        ),
        interpolated: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use schuler::earth::Geodetic;

    fn state(lat: f64, lon: f64, h: f64, yaw: f64) -> NavState {
        NavState::new(
            0.0,
            Geodetic::from_degrees(lat, lon, h),
            Vector3::zeros(),
            Euler::from_degrees(0.0, 0.0, yaw),
        )
    }

    /// Across the pole: two points on opposite meridians, each `ρ` from the polar axis
    /// at the same height, are `2ρ` apart (plane geometry in the equatorial plane;
    /// latitude from `ρ` by the ellipse at the pole, `ρ = (R_N + h) cos lat`), while the
    /// latitude/longitude linearization gives `π ρ`; heading north on one side is
    /// heading south on the other, the same direction in space: no yaw error.
    #[test]
    fn across_the_pole_the_error_is_the_distance() {
        let a: f64 = 6_378_137.0;
        let e2: f64 = 6.694_379_990_14e-3;
        let h = 300.0;
        let rn = a / (1.0 - e2).sqrt();
        let rho = 30.0;
        let lat = (rho / (rn + h)).acos().to_degrees();
        let (north, south) = (state(lat, 25.0, h, 0.0), state(lat, -155.0, h, 180.0));
        let e = errors_through_ecef(&north, &south);
        assert!(
            (e.horizontal() - 2.0 * rho).abs() < 1e-6,
            "{}",
            e.horizontal()
        );
        assert!(e.pos_n.z.abs() < 1e-9 && e.att.yaw.abs() < 1e-9, "{e:?}");
        let lin = errors_at(&NavRecord::from(&north), &NavRecord::from(&south));
        assert!((lin.horizontal() - std::f64::consts::PI * rho).abs() < 1e-3);
    }

    /// At 70 N the two agree: 20 m north and 30 m east of the truth, 5 m higher, yaw
    /// 0.1 deg more: horizontal to the chord-against-arc difference (d^2 / R = 2e-4 m),
    /// height exactly; yaw differs by the meridian convergence over the 30 m, which
    /// only the ECEF form removes: `δλ sin lat` = 30 tan(70 deg) / (R_N + h) = 1.29e-5
    /// rad (to its second order, 1e-10 rad).
    #[test]
    fn away_from_the_poles_it_agrees_with_latitude_and_longitude() {
        let truth = state(70.0, 25.0, 300.0, 40.0);
        let r = Wgs84.radii(truth.pos.lat);
        let lat = 70.0 + (20.0 / (r.meridian + 300.0)).to_degrees();
        let lon =
            25.0 + (30.0 / ((r.prime_vertical + 300.0) * 70f64.to_radians().cos())).to_degrees();
        let nav = state(lat, lon, 305.0, 40.1);
        let (e, lin) = (
            errors_through_ecef(&nav, &truth),
            errors_at(&NavRecord::from(&nav), &NavRecord::from(&truth)),
        );
        assert!(
            (e.pos_n.xy() - lin.pos_n.xy()).norm() < 1e-3,
            "{e:?} {lin:?}"
        );
        assert_eq!(e.pos_n.z, lin.pos_n.z);
        let convergence = 30.0 * 70f64.to_radians().tan() / (r.prime_vertical + 300.0);
        assert!(
            ((lin.att.yaw - e.att.yaw).abs() - convergence).abs() < 1e-9,
            "{e:?} {lin:?}"
        );
    }
}
