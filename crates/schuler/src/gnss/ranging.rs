//! One epoch of pseudoranges and pseudorange rates with their satellites' states, as
//! a navigation filter takes them (tight coupling), and their model seen from an
//! antenna whose position and velocity the filter predicts.
//!
//! [`RangeEpoch::from_raw`] does what needs no receiver position: the signal chosen
//! per satellite and the ephemeris (as [`super::spp`] chooses them), the transmission
//! time and the satellite's state then, in the ECEF frame *of the transmission*
//! ([`super::Ephemeris::state_at_transmission`]). [`RangeModel::predict`] does the
//! rest at the antenna the filter predicts: the Sagnac rotation into the frame at
//! reception ([`SatState::seen_from`]), look angles and mask, the Klobuchar and
//! Saastamoinen delays, and the measurement variances — the single-point model of
//! [`super::spp`]'s doc, with the same weights:
//!
//! `P = |r_i − r_a| + b_s − c·(Δt_i − T_k) + I_k + T + ε`,
//! `ρ̇ = u·(v_i − v_a)/(1 + u·V_i/c) + d − c·Δṫ_i + ε̇`,
//!
//! `r_a`, `v_a` the antenna's ECEF position and velocity, `b_s` the receiver clock
//! bias of system s [m], `d` its drift [m/s]. The epoch's time tag is the receiver
//! clock's; the filter uses the antenna at that tag, which is off the true reception
//! time by the clock bias: at 0.5 ms and 30 m/s, 1.5 cm along the line of sight, far
//! below the code noise.

use nalgebra::Vector3;

use super::atmosphere::{Klobuchar, LookAngles, tropo_delay_m};
use super::ephemeris::C;
use super::orbit::SatState;
use super::raw::{RawEpoch, RawMeasurement, Signal};
use super::sat::{Sat, System};
use super::spp::{self, Excluded, SppConfig};
use super::store::EphemerisStore;
use super::time::GpsTime;
use crate::earth::{EarthModel, Wgs84, c_ne};

/// One satellite's measurements of an epoch and its state at their transmission.
#[derive(Debug, Clone, PartialEq)]
pub struct SatRange {
    /// The satellite.
    pub sat: Sat,
    /// The measurement (signal, pseudorange, Doppler, C/N0, reported σ).
    pub measurement: RawMeasurement,
    /// The satellite at the transmission, ECEF frame of the transmission; clock bias
    /// with the relativistic term.
    pub state: SatState,
    /// The system's Earth rotation rate [rad/s] (for the Sagnac rotation).
    pub omega_e: f64,
    /// Group delay of the signal's band [s].
    pub group_delay: f64,
    /// Carrier frequency [Hz].
    pub freq: f64,
    /// Broadcast accuracy of the ephemeris (URA, SISA) [m].
    pub ura: f64,
}

impl SatRange {
    /// The signal measured.
    pub fn signal(&self) -> Signal {
        self.measurement.signal
    }
}

/// One epoch of ranges ready for a filter, and the satellites left out with why.
#[derive(Debug, Clone, PartialEq)]
pub struct RangeEpoch {
    /// The receive time by the receiver's clock on the run's clock [s].
    pub t: f64,
    /// The same as a GPS instant (for the ionosphere's local time).
    pub time: GpsTime,
    /// The satellites with a measurement, an ephemeris and a group delay.
    pub sats: Vec<SatRange>,
    /// The satellites left out before any model (system not used, no ephemeris, …).
    pub excluded: Vec<Excluded>,
}

impl RangeEpoch {
    /// The epoch's satellites that `config` uses, with their states from `store`;
    /// `t` the epoch's time on the run's clock.
    pub fn from_raw(epoch: &RawEpoch, store: &EphemerisStore, config: &SppConfig, t: f64) -> Self {
        let (cands, excluded, _) = spp::candidates(epoch, store, config);
        let sats = cands
            .iter()
            .map(|c| SatRange {
                sat: c.sat,
                measurement: c.m.clone(),
                state: c.eph.state_at_transmission(epoch.t, c.pseudorange),
                omega_e: c.eph.constants().omega_e,
                group_delay: c.tgd,
                freq: c.freq,
                ura: c.eph.accuracy_m,
            })
            .collect();
        Self {
            t,
            time: epoch.t,
            sats,
            excluded,
        }
    }

    /// The systems of its satellites, each once, in [`System`]'s order.
    pub fn systems(&self) -> Vec<System> {
        let mut s: Vec<System> = self.sats.iter().map(|r| r.sat.system).collect();
        s.sort_unstable();
        s.dedup();
        s
    }
}

/// The model of an epoch's measurements: the broadcast ionosphere (if any) and the
/// single-point settings (mask, weights, which corrections).
#[derive(Debug, Clone, PartialEq)]
pub struct RangeModel {
    /// Klobuchar coefficients, applied when [`SppConfig::ionosphere`] is set.
    pub klobuchar: Option<Klobuchar>,
    /// Mask, weights, corrections.
    pub config: SppConfig,
}

/// One satellite's measurements predicted at an antenna, without the receiver clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Predicted {
    /// Elevation and azimuth from the antenna.
    pub look: LookAngles,
    /// Unit line of sight, antenna to satellite, ECEF.
    pub u: Vector3<f64>,
    /// `|r_i − r_a| − c·(Δt_i − T_k) + I + T` [m]: the pseudorange less the clock bias.
    pub pseudorange: f64,
    /// Its variance [m²].
    pub pseudorange_var: f64,
    /// `1 + u·V_i/c`, the light time's rate (divides the antenna's velocity).
    pub k: f64,
    /// `u·v_i/k − c·Δṫ_i − u·v_a/k` [m/s]: the pseudorange rate less the clock drift,
    /// when the satellite has a Doppler.
    pub rate: Option<f64>,
    /// Its variance [m²/s²].
    pub rate_var: f64,
    /// Ionospheric delay applied [m].
    pub iono_m: f64,
    /// Tropospheric delay applied [m].
    pub tropo_m: f64,
}

impl RangeModel {
    /// `s` seen from an antenna at ECEF `r_a` moving at `v_a` (ECEF, relative to the
    /// Earth) at GPS instant `t`; `None` below the elevation mask.
    pub fn predict(
        &self,
        s: &SatRange,
        t: GpsTime,
        r_a: &Vector3<f64>,
        v_a: &Vector3<f64>,
    ) -> Option<Predicted> {
        let cfg = &self.config;
        let sat = s.state.seen_from(s.omega_e, r_a);
        let d = sat.r_e - r_a;
        let range = d.norm();
        let u = d / range;
        let g = Wgs84.ecef_to_geodetic(r_a);
        let los_n = c_ne(g.lat, g.lon).transpose() * d;
        let elevation = (-los_n.z).atan2(los_n.x.hypot(los_n.y));
        if elevation < cfg.elevation_mask {
            return None;
        }
        let azimuth = los_n.y.atan2(los_n.x).rem_euclid(std::f64::consts::TAU);
        let look = LookAngles { elevation, azimuth };
        let iono = (cfg.ionosphere)
            .then_some(self.klobuchar.as_ref())
            .flatten()
            .map(|k| k.delay_m(g.lat, g.lon, look, t.sow, s.freq));
        let iono_m = iono.unwrap_or(0.0);
        let tropo_m = if cfg.troposphere {
            tropo_delay_m(g.lat, g.h, elevation)
        } else {
            0.0
        };
        let pseudorange = range - C * (sat.clock_bias - s.group_delay) + iono_m + tropo_m;
        let pseudorange_var =
            spp::pseudorange_variance(cfg, &s.measurement, s.ura, elevation, iono);
        let v_inertial = sat.v_e + Vector3::new(-s.omega_e * sat.r_e.y, s.omega_e * sat.r_e.x, 0.0);
        let k = 1.0 + u.dot(&v_inertial) / C;
        let rate = s
            .measurement
            .pseudorange_rate()
            .filter(|r| r.is_finite())
            .map(|_| u.dot(&(sat.v_e - v_a)) / k - C * sat.clock_drift);
        let sigma = spp::rate_sigma(cfg, &s.measurement, elevation);
        Some(Predicted {
            look,
            u,
            pseudorange,
            pseudorange_var,
            k,
            rate,
            rate_var: sigma * sigma,
            iono_m,
            tropo_m,
        })
    }
}
