//! A nominal GPS constellation as broadcast ephemerides, for simulations without a
//! navigation file: 24 satellites in a Walker delta pattern 55°: 24/6/1 (six planes
//! 60° apart in right ascension, four satellites 90° apart in each, neighbouring
//! planes phased by 15°), on circular-ish orbits of the GPS reference semi-major axis
//! 26 559 710 m (IS-GPS-200N Table 20-IV's `A_REF` for CNAV: a 12-sidereal-hour
//! period). This is the pattern GPS's 24 baseline slots approximate (SPS Performance
//! Standard 2020 §3.2.1), not its published slot table.
//!
//! Each satellite's orbit is one Keplerian ellipse (e = 0.005, no harmonic
//! corrections, the node regressing at −8·10⁻⁹ rad/s, GPS's typical rate), cut into
//! ephemerides every two hours (toe on even hours of GPS time, a 4-hour fit interval)
//! whose elements follow from the one orbit, so consecutive ephemerides agree exactly
//! where they meet. Clocks: a polynomial per satellite continuous across ephemerides
//! (af0 within ±100 µs, af1 within ±1e-11), and a TGD within ±5 ns: values of the
//! sizes GPS broadcasts, not any satellite's.

use crate::gnss::atmosphere::Klobuchar;
use crate::gnss::{
    Ephemeris, EphemerisStore, GpsTime, Kepler, NavMessage, Sat, System, SystemConstants,
};

/// The semi-major axis [m] (IS-GPS-200N Table 20-IV, `A_REF`).
pub const A_REF: f64 = 26_559_710.0;
/// The inclination [rad].
pub const INCLINATION: f64 = 55.0 * std::f64::consts::PI / 180.0;
/// Eccentricity of every orbit.
const ECCENTRICITY: f64 = 0.005;
/// Rate of right ascension [rad/s].
const OMEGA_DOT: f64 = -8.0e-9;
/// Interval between ephemerides [s], and their fit interval.
const EPH_INTERVAL_S: f64 = 7_200.0;
const FIT_INTERVAL_S: f64 = 4.0 * 3_600.0;

/// The Klobuchar coefficients the nominal constellation broadcasts: those of IGS's
/// brdc1820.10n (2010-07-01), a quiet day's.
pub const NOMINAL_KLOBUCHAR: Klobuchar = Klobuchar {
    alpha: [0.4657e-08, 0.1490e-07, -0.5960e-07, -0.1192e-06],
    beta: [0.8192e+05, 0.8192e+05, -0.6554e+05, -0.5243e+06],
};

/// The ephemerides of the nominal constellation covering GPS instants `from` to `to`
/// (every toe within two hours of the span), the orbits' reference the start of GPS
/// week `week`: satellite G(p·4 + s + 1) is satellite s of plane p.
pub fn nominal_gps(week: i64, from: GpsTime, to: GpsTime) -> EphemerisStore {
    let c = SystemConstants::GPS;
    let t_ref = GpsTime::new(week, 0.0);
    let n = (c.mu / (A_REF * A_REF * A_REF)).sqrt();
    let deg = std::f64::consts::PI / 180.0;
    let first = (from.diff_s(t_ref) / EPH_INTERVAL_S).floor() - 1.0;
    let last = (to.diff_s(t_ref) / EPH_INTERVAL_S).ceil() + 1.0;
    let mut store = EphemerisStore::new();
    for plane in 0..6u8 {
        for slot in 0..4u8 {
            let prn = plane * 4 + slot + 1;
            let node_ref = f64::from(plane) * 60.0 * deg + 10.0 * deg;
            let m_ref = (f64::from(slot) * 90.0 + f64::from(plane) * 15.0) * deg;
            let p = f64::from(prn);
            let af0 = ((p * 37.0) % 200.0 - 100.0) * 1e-6;
            let af1 = ((p * 13.0) % 20.0 - 10.0) * 1e-12;
            let tgd = ((p * 7.0) % 10.0 - 5.0) * 1e-9;
            let mut k = first;
            while k <= last {
                let toe = t_ref.add_s(k * EPH_INTERVAL_S);
                let since = toe.diff_s(t_ref);
                let week_start = GpsTime::new(toe.week, 0.0);
                // Ω0 is the node's longitude at the start of toe's week: the inertial
                // node less the Earth's turn since the reference week's start.
                let omega0 = node_ref + OMEGA_DOT * since - c.omega_e * week_start.diff_s(t_ref);
                let issue = (k.rem_euclid(256.0)) as u32;
                store.push(Ephemeris {
                    sat: Sat::new(System::Gps, prn),
                    message: NavMessage::Lnav,
                    toc: toe,
                    af0: af0 + af1 * since,
                    af1,
                    af2: 0.0,
                    toe,
                    kepler: Kepler {
                        sqrt_a: A_REF.sqrt(),
                        e: ECCENTRICITY,
                        i0: INCLINATION,
                        omega0: wrap(omega0),
                        omega: 0.0,
                        m0: wrap(m_ref + n * since),
                        omega_dot: OMEGA_DOT,
                        toe_sow: toe.sow,
                        ..Kepler::default()
                    },
                    iode: issue,
                    iodc: issue,
                    health: 0,
                    data_source: 0,
                    accuracy_m: 2.0,
                    group_delays: [tgd, 0.0],
                    fit_interval_s: FIT_INTERVAL_S,
                });
                k += 1.0;
            }
        }
    }
    store
}

/// An angle brought into (−π, π].
fn wrap(a: f64) -> f64 {
    crate::rotation::wrap_pi(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Consecutive ephemerides meet: at the midpoint between two toes both give the
    /// same position (to 1 mm: the node and anomaly are carried exactly, the rest is
    /// rounding of 2.6e7 m) and clock (1e-15 s), and the orbit's radius is A(1 ± e).
    #[test]
    fn ephemerides_join_and_the_orbit_is_gps_sized() {
        let week = 1590;
        let from = GpsTime::new(week, 345_600.0);
        let store = nominal_gps(week, from, from.add_s(6.0 * 3600.0));
        assert_eq!(store.sats().count(), 24);
        for sat in store.sats() {
            let ephs = store.of(sat);
            assert!(ephs.len() >= 5);
            for w in ephs.windows(2) {
                let mid = w[0].toe.add_s(3600.0);
                let (a, b) = (w[0].state_at(mid), w[1].state_at(mid));
                assert!(
                    (a.r_e - b.r_e).norm() < 1e-3,
                    "{sat} {}",
                    (a.r_e - b.r_e).norm()
                );
                assert!((a.clock_bias - b.clock_bias).abs() < 1e-15);
                let r = a.r_e.norm();
                assert!(
                    r > A_REF * (1.0 - ECCENTRICITY) - 1.0
                        && r < A_REF * (1.0 + ECCENTRICITY) + 1.0
                );
            }
        }
    }

    /// The 12-sidereal-hour period: one orbit later (in the inertial frame, so the
    /// ECEF position turned back by the Earth's rotation and the node's regression)
    /// the satellite is where it was.
    #[test]
    fn the_period_is_half_a_sidereal_day() {
        let week = 1590;
        let t0 = GpsTime::new(week, 345_600.0);
        let c = SystemConstants::GPS;
        let period = 2.0 * std::f64::consts::PI / (c.mu / A_REF.powi(3)).sqrt();
        // Half a sidereal day is 43 082 s; A_REF gives it to 10 s.
        assert!((period - 43_082.0).abs() < 10.0, "{period}");
        let store = nominal_gps(week, t0, t0.add_s(period));
        let e = &store.of(Sat::new(System::Gps, 5))[2];
        let (a, b) = (e.orbit_at(t0).r_e, e.orbit_at(t0.add_s(period)).r_e);
        // ECEF → inertial at each instant: turn by +Ω̇e·t about Z.
        let turn = |r: nalgebra::Vector3<f64>, t: f64| {
            let (s, co) = (c.omega_e * t).sin_cos();
            nalgebra::Vector3::new(co * r.x - s * r.y, s * r.x + co * r.y, r.z)
        };
        let (ai, bi) = (turn(a, 0.0), turn(b, period));
        // The node regresses by Ω̇·T = 0.34 mrad about Z: at most 9 km of the orbit.
        let drift = OMEGA_DOT.abs() * period * A_REF * (1.0 + ECCENTRICITY);
        assert!((ai - bi).norm() <= drift, "{} {drift}", (ai - bi).norm());
        assert!((ai - bi).norm() > 0.1 * drift * INCLINATION.cos());
    }
}
