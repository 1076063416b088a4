//! A satellite's position, velocity and clock from its broadcast ephemeris at a GPS
//! instant: IS-GPS-200N Table 20-IV (GPS, QZSS; Galileo OS SIS ICD Table 60 and BDS-SIS-ICD
//! Table 5-11 are the same algorithm with their constants), BeiDou's geostationary
//! satellites by BDS-SIS-ICD §5.2.4.12 (the orbit in a frame inclined −5° about X,
//! then turned by the Earth's rotation since toe).
//!
//! The velocity is the analytic time derivative of the same expressions (not a finite
//! difference), the clock drift that of the clock polynomial and the relativistic term
//! `Δt_r = F·e·√A·sin E` (IS-GPS-200 §20.3.3.3.3.1), `dΔt_r/dt = F·e·√A·cos E·Ė`.

use nalgebra::{Matrix3, Vector3};

use super::ephemeris::Ephemeris;
use super::time::{GpsTime, wrap_half_week};

/// Kepler's equation `M = E − e·sin E` solved for the eccentric anomaly E [rad] by
/// Newton's method on M reduced to [−π, π], from E₀ = M (or ±π for e > 0.8), until a
/// step is below 1e-14 rad (at most 50 steps; e must be in [0, 1)). The result is
/// in the same revolution as `m`.
pub fn eccentric_anomaly(m: f64, e: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let turns = (m / TAU).round();
    let m = m - turns * TAU;
    let mut big_e = if e > 0.8 { PI.copysign(m) } else { m };
    for _ in 0..50 {
        let step = (big_e - e * big_e.sin() - m) / (1.0 - e * big_e.cos());
        big_e -= step;
        // Stops on a NaN step too (a NaN anomaly or eccentricity).
        if step.abs() <= 1e-14 || step.is_nan() {
            break;
        }
    }
    big_e + turns * TAU
}

/// A satellite's state at one instant, ECEF (the system's realisation of it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatState {
    /// The instant the state belongs to (the transmission time when the state was
    /// computed for a reception).
    pub t: GpsTime,
    /// Position of the antenna phase centre the ephemeris refers to [m].
    pub r_e: Vector3<f64>,
    /// Velocity [m/s] in the same rotating frame.
    pub v_e: Vector3<f64>,
    /// Clock bias Δt_sv [s] with the relativistic term, relative to the system's time,
    /// without group delays (see [`Ephemeris::group_delay`]).
    pub clock_bias: f64,
    /// Clock drift [s/s], with the rate of the relativistic term.
    pub clock_drift: f64,
}

/// The orbit at one instant: ECEF position and velocity and the eccentric anomaly
/// with its rate (for the relativistic clock term).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitPoint {
    /// Position [m], ECEF at the instant.
    pub r_e: Vector3<f64>,
    /// Velocity [m/s] relative to the rotating ECEF frame.
    pub v_e: Vector3<f64>,
    /// Eccentric anomaly E [rad].
    pub ecc_anomaly: f64,
    /// Its rate Ė [rad/s].
    pub ecc_anomaly_rate: f64,
}

/// The inclination of BeiDou GEO's computation frame, −5° (BDS-SIS-ICD §5.2.4.12).
const BEIDOU_GEO_TILT: f64 = -5.0 * super::ephemeris::ICD_PI / 180.0;

impl Ephemeris {
    /// The orbit at GPS instant `t` (IS-GPS-200 Table 20-IV with its derivative;
    /// BeiDou GEO per BDS-SIS-ICD §5.2.4.12). `t − toe` is taken across weeks exactly.
    pub fn orbit_at(&self, t: GpsTime) -> OrbitPoint {
        let k = &self.kepler;
        let c = self.constants();
        let a = k.sqrt_a * k.sqrt_a;
        let tk = t.diff_s(self.toe);
        let n = (c.mu / (a * a * a)).sqrt() + k.delta_n;
        let big_e = eccentric_anomaly(k.m0 + n * tk, k.e);
        let (sin_e, cos_e) = big_e.sin_cos();
        let one_m_ecos = 1.0 - k.e * cos_e;
        let e_dot = n / one_m_ecos;
        let root = (1.0 - k.e * k.e).sqrt();
        let phi = (root * sin_e).atan2(cos_e - k.e) + k.omega;
        let phi_dot = root * e_dot / one_m_ecos;
        let (s2, c2) = (2.0 * phi).sin_cos();
        let u = phi + k.cus * s2 + k.cuc * c2;
        let r = a * one_m_ecos + k.crs * s2 + k.crc * c2;
        let i = k.i0 + k.cis * s2 + k.cic * c2 + k.i_dot * tk;
        let u_dot = phi_dot * (1.0 + 2.0 * (k.cus * c2 - k.cuc * s2));
        let r_dot = a * k.e * sin_e * e_dot + 2.0 * phi_dot * (k.crs * c2 - k.crc * s2);
        let i_dot = k.i_dot + 2.0 * phi_dot * (k.cis * c2 - k.cic * s2);
        let (sin_u, cos_u) = u.sin_cos();
        let (xp, yp) = (r * cos_u, r * sin_u);
        let (xp_dot, yp_dot) = (
            r_dot * cos_u - r * u_dot * sin_u,
            r_dot * sin_u + r * u_dot * cos_u,
        );
        let geo = self.is_beidou_geo();
        // The node: in ECEF for every satellite but BeiDou's GEOs, whose node is
        // inertial over the interval (the Earth's rotation is applied after the tilt).
        let node_rate = if geo {
            k.omega_dot
        } else {
            k.omega_dot - c.omega_e
        };
        let node = k.omega0 + node_rate * tk - c.omega_e * k.toe_sow;
        let (sin_o, cos_o) = node.sin_cos();
        let (sin_i, cos_i) = i.sin_cos();
        let r_k = Vector3::new(
            xp * cos_o - yp * cos_i * sin_o,
            xp * sin_o + yp * cos_i * cos_o,
            yp * sin_i,
        );
        let v_k = Vector3::new(
            xp_dot * cos_o - yp_dot * cos_i * sin_o + yp * sin_i * sin_o * i_dot
                - r_k.y * node_rate,
            xp_dot * sin_o + yp_dot * cos_i * cos_o - yp * sin_i * cos_o * i_dot
                + r_k.x * node_rate,
            yp_dot * sin_i + yp * cos_i * i_dot,
        );
        let (r_e, v_e) = if geo {
            let (sin_x, cos_x) = BEIDOU_GEO_TILT.sin_cos();
            let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cos_x, sin_x, 0.0, -sin_x, cos_x);
            let (sz, cz) = (c.omega_e * tk).sin_cos();
            let rz = Matrix3::new(cz, sz, 0.0, -sz, cz, 0.0, 0.0, 0.0, 1.0);
            let rz_dot = c.omega_e * Matrix3::new(-sz, cz, 0.0, -cz, -sz, 0.0, 0.0, 0.0, 0.0);
            let g = rx * r_k;
            (rz * g, rz * (rx * v_k) + rz_dot * g)
        } else {
            (r_k, v_k)
        };
        OrbitPoint {
            r_e,
            v_e,
            ecc_anomaly: big_e,
            ecc_anomaly_rate: e_dot,
        }
    }

    /// The relativistic clock correction `Δt_r = F·e·√A·sin E` [s] and its rate [s/s]
    /// at an orbit point of this ephemeris (IS-GPS-200 §20.3.3.3.3.1).
    pub fn relativistic(&self, p: &OrbitPoint) -> (f64, f64) {
        let k = self.constants().f_rel() * self.kepler.e * self.kepler.sqrt_a;
        let (s, c) = p.ecc_anomaly.sin_cos();
        (k * s, k * c * p.ecc_anomaly_rate)
    }

    /// The clock polynomial `af0 + af1·(t − toc) + af2·(t − toc)²` [s] and its rate, at
    /// GPS instant `t` (no relativistic term, no group delay).
    pub fn clock_polynomial(&self, t: GpsTime) -> (f64, f64) {
        let dt = wrap_half_week(t.diff_s(self.toc));
        (
            self.af0 + (self.af1 + self.af2 * dt) * dt,
            self.af1 + 2.0 * self.af2 * dt,
        )
    }

    /// The satellite's state at GPS instant `t` (of transmission): orbit, and clock
    /// with the relativistic term.
    pub fn state_at(&self, t: GpsTime) -> SatState {
        let p = self.orbit_at(t);
        let (rel, rel_dot) = self.relativistic(&p);
        let (poly, poly_dot) = self.clock_polynomial(t);
        SatState {
            t,
            r_e: p.r_e,
            v_e: p.v_e,
            clock_bias: poly + rel,
            clock_drift: poly_dot + rel_dot,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::gnss::ephemeris::{Kepler, NavMessage};
    use crate::gnss::sat::{Sat, System};

    /// G02's first ephemeris of 2010-07-01 in RINEX file brdc1820.10n (IGS, CDDIS;
    /// tests/data/orbits), as printed there. (G01, the file's first, is SVN49, then
    /// unhealthy: health 63.)
    pub(crate) fn g02_2010_07_01() -> Ephemeris {
        Ephemeris {
            sat: Sat::new(System::Gps, 2),
            message: NavMessage::Lnav,
            toc: GpsTime::new(1590, 345_600.0),
            af0: 0.269108917564e-03,
            af1: 0.318323145621e-11,
            af2: 0.0,
            toe: GpsTime::new(1590, 345_600.0),
            kepler: Kepler {
                crs: 0.414375000000e+02,
                delta_n: 0.525557597442e-08,
                m0: 0.165772167412e+01,
                cuc: 0.232271850109e-05,
                e: 0.960697804112e-02,
                cus: 0.617466866970e-05,
                sqrt_a: 0.515359739113e+04,
                toe_sow: 0.345600000000e+06,
                cic: -0.558793544769e-08,
                omega0: -0.127458719764e+01,
                cis: 0.167638063431e-06,
                i0: 0.939349150611e+00,
                crc: 0.249937500000e+03,
                omega: 0.309739903949e+01,
                omega_dot: -0.838784952606e-08,
                i_dot: -0.232152526369e-10,
            },
            iode: 85,
            iodc: 85,
            health: 0,
            data_source: 0,
            accuracy_m: 2.0,
            group_delays: [-0.172294676304e-07, 0.0],
            fit_interval_s: 4.0 * 3600.0,
        }
    }

    #[test]
    fn kepler_is_solved_to_1e_12() {
        for &e in &[0.0, 1e-3, 0.02, 0.1, 0.5, 0.9, 0.99] {
            for k in 0..64 {
                let m = -7.0 + 14.0 * k as f64 / 63.0;
                let big_e = eccentric_anomaly(m, e);
                assert!((big_e - e * big_e.sin() - m).abs() < 1e-12, "e {e} M {m}");
            }
        }
        assert!(eccentric_anomaly(f64::NAN, 0.1).is_nan());
    }

    /// The central difference (p(t+h) − p(t−h))/2h of a satellite's position has a
    /// truncation error p‴h²/6: with |p‴| ≈ n³·r ≈ 2.6e7·(1.46e-4)³ = 8e-5 m/s³ for a
    /// GPS orbit and h = 0.5 s, 3.4e-6 m/s; rounding adds 1e-8 m/1 s. Bound: 1e-5 m/s.
    fn velocity_matches_central_difference(eph: &Ephemeris, t: GpsTime) {
        let p = eph.orbit_at(t);
        let h = 0.5;
        let fd = (eph.orbit_at(t.add_s(h)).r_e - eph.orbit_at(t.add_s(-h)).r_e) / (2.0 * h);
        assert!((p.v_e - fd).norm() < 1e-5, "{} {:?}", eph.sat, p.v_e - fd);
        assert!(p.v_e.norm() > 2_000.0);
    }

    #[test]
    fn velocity_is_the_derivative_of_position() {
        let eph = g02_2010_07_01();
        for dt in [-7200.0, -100.0, 0.0, 3000.0, 7200.0] {
            velocity_matches_central_difference(&eph, eph.toe.add_s(dt));
        }
        // The same orbit as a BeiDou GEO (the tilted frame and its rotation).
        let mut geo = eph.clone();
        geo.sat = Sat::new(System::BeiDou, 3);
        geo.message = NavMessage::D2;
        for dt in [-3600.0, 0.0, 3600.0] {
            velocity_matches_central_difference(&geo, eph.toe.add_s(dt));
        }
    }

    #[test]
    fn clock_drift_is_the_derivative_of_the_bias() {
        let mut eph = g02_2010_07_01();
        eph.af2 = 1e-18;
        for dt in [-7000.0, 0.0, 5000.0] {
            let t = eph.toe.add_s(dt);
            let s = eph.state_at(t);
            let h = 0.5;
            let fd = (eph.state_at(t.add_s(h)).clock_bias - eph.state_at(t.add_s(-h)).clock_bias)
                / (2.0 * h);
            // Truncation Δt_r‴h²/6 ≈ 2.3e-8·n³/6·h² ≈ 3e-21; rounding 1e-19 s/1 s.
            assert!((s.clock_drift - fd).abs() < 1e-17, "{}", s.clock_drift - fd);
        }
    }

    #[test]
    fn relativistic_term_equals_its_closed_form_from_the_state() {
        // Δt_r = −2 r·v / c² on a Kepler orbit (IS-GPS-200 §20.3.3.3.3.1), since
        // r·v = √(μA)·e·sin E there. Without the harmonic corrections and Δn the two agree
        // to rounding; with G01's (Crc = 278 m changes r·v by about 2n·Crc·r = 2e6 m²/s)
        // to 5e-11 s of a 1.1e-8-s term.
        let eph = g02_2010_07_01();
        let mut bare = eph.clone();
        let k = &mut bare.kepler;
        (k.cuc, k.cus, k.crc, k.crs, k.cic, k.cis, k.delta_n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let c2 = super::super::ephemeris::C.powi(2);
        for dt in [-3600.0, 0.0, 1800.0, 5400.0] {
            for (e, bound) in [(&bare, 1e-16), (&eph, 1e-10)] {
                let p = e.orbit_at(e.toe.add_s(dt));
                let (rel, _) = e.relativistic(&p);
                let closed = -2.0 * p.r_e.dot(&p.v_e) / c2;
                assert!(rel.abs() > 1e-10);
                assert!((rel - closed).abs() < bound, "{rel} {closed}");
            }
        }
    }

    #[test]
    fn g02_against_the_precise_orbit_at_toe() {
        // IGS final orbit igs15904.sp3 (tests/data/orbits), 2010-07-01 00:00:00 GPST,
        // G02 at its centre of mass: −14889.160729, −5131.952946, −21416.801336 km,
        // clock 269.108429 µs. The broadcast orbit refers to the antenna phase centre,
        // 0.614 m towards the Earth on this Block IIR-B satellite (igs05.atx): the two
        // agree to the broadcast orbit's metre or two, the clocks to a few ns.
        let eph = g02_2010_07_01();
        let p = eph.orbit_at(eph.toe);
        let com: Vector3<f64> =
            Vector3::new(-14_889.160_729, -5_131.952_946, -21_416.801_336) * 1e3;
        let apc = com - 0.614 * com.normalize();
        assert!((p.r_e - apc).norm() < 2.0, "{}", (p.r_e - apc).norm());
        let (clock, _) = eph.clock_polynomial(eph.toe);
        assert!((clock - 269.108_429e-6).abs() < 5e-9, "{clock}");
    }
}
