//! From a reception to the satellite's state: the transmission time and the Earth's
//! rotation while the signal travels (the Sagnac effect), IS-GPS-200N §20.3.3.3.3.1 and
//! §20.3.3.4.3.3.2.
//!
//! A pseudorange `P` received at receiver-clock time `t_rx` left the satellite when
//! the *satellite's* clock read `t_sv = t_rx − P/c` (whatever the receiver clock's
//! error: it is inside P). System time is then `t = t_sv − Δt_sv(t)`, solved by two
//! fixed-point passes on the clock polynomial (it moves by < 1e-9 s per second, so the
//! second pass changes t by < 1e-12 s; the relativistic term, ≤ 4.5e-8 s, moves the
//! satellite by at most 0.2 mm and is left out of t). The orbit at t is in the ECEF
//! frame *of the transmission*; the receiver's frame has turned by `Ω̇e·τ` about Z
//! during the travel time τ, so the state is rotated by −Ω̇e·τ about Z (the satellite
//! appears displaced eastwards): `r_rx-frame = R_z(Ω̇e·τ)·r_tx-frame`.

use nalgebra::{Matrix3, Vector3};

use super::ephemeris::{C, Ephemeris};
use super::orbit::SatState;
use super::time::GpsTime;

/// The rotation of the ECEF frame during a travel time: `R_z(θ)`, θ = Ω̇e·τ, which
/// takes a vector from the ECEF frame at transmission to that at reception.
fn earth_rotation(omega_e: f64, tau: f64) -> Matrix3<f64> {
    let (s, c) = (omega_e * tau).sin_cos();
    Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

impl Ephemeris {
    /// The GPS instant (in the system's time) at which a signal received at `t_rx`
    /// (receiver clock) with pseudorange `pseudorange` [m] left the satellite.
    pub fn transmit_time(&self, t_rx: GpsTime, pseudorange: f64) -> GpsTime {
        let t_sv = t_rx.add_s(-pseudorange / C);
        let mut t = t_sv;
        for _ in 0..2 {
            t = t_sv.add_s(-self.clock_polynomial(t).0);
        }
        t
    }

    /// The satellite's state for a pseudorange received at `t_rx` by a receiver at
    /// `r_rx` (ECEF [m], the current estimate: the travel time τ = |r_sat − r_rx|/c
    /// depends on it by 1/c, 1 km of error turning the satellite by 0.26 mm). The state
    /// is at the transmission time (its `t`), expressed in the ECEF frame at reception.
    pub fn state_at_reception(
        &self,
        t_rx: GpsTime,
        pseudorange: f64,
        r_rx: &Vector3<f64>,
    ) -> SatState {
        self.state_at_transmission(t_rx, pseudorange)
            .seen_from(self.constants().omega_e, r_rx)
    }

    /// The satellite's state at the transmission of a pseudorange received at `t_rx`,
    /// in the ECEF frame *of the transmission* (no receiver position needed; turn it
    /// into the receiver's frame with [`SatState::seen_from`]).
    pub fn state_at_transmission(&self, t_rx: GpsTime, pseudorange: f64) -> SatState {
        self.state_at(self.transmit_time(t_rx, pseudorange))
    }

    /// The satellite's state whose signal reaches `r_rx` (ECEF [m]) at GPS instant
    /// `t_rx` (true time, no receiver clock): the light-time equation
    /// `τ = |R_z(Ω̇e·τ)·r_sat(t_rx − τ) − r_rx| / c` iterated from τ = 0.075 s until τ
    /// moves by less than 1e-13 s (three or four passes; at most ten). In the ECEF frame
    /// at reception; its `t` is the transmission time. For simulating observations.
    pub fn state_by_light_time(&self, t_rx: GpsTime, r_rx: &Vector3<f64>) -> SatState {
        let omega_e = self.constants().omega_e;
        let mut tau = 0.075;
        let mut state = self.state_at(t_rx.add_s(-tau));
        for _ in 0..10 {
            let s = rotated(
                self.state_at(t_rx.add_s(-tau)),
                earth_rotation(omega_e, tau),
            );
            let next = (s.r_e - r_rx).norm() / C;
            state = s;
            let done = (next - tau).abs() < 1e-13;
            tau = next;
            if done {
                break;
            }
        }
        state
    }
}

impl SatState {
    /// This state (in the ECEF frame of its transmission) in the ECEF frame at the
    /// reception by a receiver at `r_rx`: turned by `R_z(Ω̇e·τ)`, `omega_e` the
    /// system's Earth rate. τ from the unrotated position, then once more from the
    /// rotated one (the rotation changes the range by up to 40 m, τ by 1.3e-7 s; the
    /// second pass leaves 1e-12 s).
    pub fn seen_from(&self, omega_e: f64, r_rx: &Vector3<f64>) -> SatState {
        let mut tau = (self.r_e - r_rx).norm() / C;
        tau = (earth_rotation(omega_e, tau) * self.r_e - r_rx).norm() / C;
        rotated(*self, earth_rotation(omega_e, tau))
    }
}

/// `s` with its position and velocity turned by `rot`.
fn rotated(s: SatState, rot: Matrix3<f64>) -> SatState {
    SatState {
        r_e: rot * s.r_e,
        v_e: rot * s.v_e,
        ..s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{EarthModel, Geodetic, Wgs84};
    use crate::gnss::orbit::tests::g02_2010_07_01;

    /// A receiver on the ellipsoid 20° of longitude east of the point under G02 at
    /// `t` (so that the satellite is above its horizon).
    fn receiver(t: GpsTime) -> Vector3<f64> {
        let under = Wgs84.ecef_to_geodetic(&g02_2010_07_01().orbit_at(t).r_e);
        Wgs84.geodetic_to_ecef(&Geodetic::new(under.lat, under.lon + 0.35, 0.0))
    }

    #[test]
    fn light_time_closes_the_range_equation() {
        let eph = g02_2010_07_01();
        let t_rx = eph.toe.add_s(1234.5);
        let r_rx = receiver(t_rx);
        let s = eph.state_by_light_time(t_rx, &r_rx);
        let tau = t_rx.diff_s(s.t);
        // The range equation holds to the iteration's 1e-13 s, seen through the
        // transmission instant's rounding (an ulp of the second of week, 6e-11 s).
        assert!(((s.r_e - r_rx).norm() / C - tau).abs() < 2e-10);
        assert!(tau > 0.066 && tau < 0.075, "{tau}");
        // The Sagnac rotation moved the satellite by Ω̇e·τ·ρ_xy (about 100 m) about Z.
        let unrotated = eph.state_at(s.t).r_e;
        let moved = (s.r_e - unrotated).norm();
        let expected = eph.constants().omega_e * tau * unrotated.xy().norm();
        assert!(
            (moved - expected).abs() < 1e-3 * expected,
            "{moved} {expected}"
        );
    }

    #[test]
    fn a_pseudorange_gives_back_the_transmission_instant() {
        // A pseudorange made from the true geometry, a receiver clock 1 ms fast and the
        // satellite clock reading t_tx + Δt_sv: P = c·(τ + δt_r − Δt_sv(t_tx)).
        let mut eph = g02_2010_07_01();
        eph.af1 = 1e-9; // a steep clock, to exercise the fixed point
        let t_rx = eph.toe.add_s(-2000.0);
        let r_rx = receiver(t_rx);
        let truth = eph.state_by_light_time(t_rx, &r_rx);
        let rx_clock = 1e-3;
        let dt_sv = eph.clock_polynomial(truth.t).0;
        let p = C * (t_rx.diff_s(truth.t) + rx_clock - dt_sv);
        let s = eph.state_at_reception(t_rx.add_s(rx_clock), p, &r_rx);
        // To the seconds of week's rounding (6e-11 s, 0.2 µm of satellite motion).
        assert!(s.t.diff_s(truth.t).abs() < 1e-9, "{}", s.t.diff_s(truth.t));
        assert!(
            (s.r_e - truth.r_e).norm() < 1e-5,
            "{}",
            (s.r_e - truth.r_e).norm()
        );
    }
}
