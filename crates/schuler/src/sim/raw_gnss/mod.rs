//! Raw GNSS observations simulated from the antenna's true trajectory: pseudoranges,
//! Dopplers and C/N0 of every satellite above the mask, as a receiver's
//! [`RawEpoch`]s, with their truth.
//!
//! At each epoch the receiver's clock reads `t_rx` (a whole multiple of the interval);
//! GPS time is then `t = t_rx − δt_r` (δt_r the clock's bias, [`clock`]) and the
//! antenna is where the trajectory puts it at t. For each satellite, with its
//! ephemeris chosen at `t_rx` as a solution chooses it ([`EphemerisStore::select`]):
//!
//! - the state at transmission in the ECEF frame at reception by the light-time
//!   equation with the Earth's rotation ([`Ephemeris::state_by_light_time`]), hence
//!   the geometric range ρ = |r_sat − r_ant|;
//! - the code pseudorange (IS-GPS-200N §20.3.3.3.3; Misra & Enge 2006 §5.1)
//!   `P = ρ + c·(δt_r − Δt_sv + T_gd) + k_I·I + k_T·T + ε + m + f`, with Δt_sv the
//!   satellite clock with its relativistic term, T_gd the signal's broadcast group
//!   delay ([`Ephemeris::group_delay`]), I the Klobuchar delay on the signal's
//!   frequency at the antenna and `t_rx`'s second of week, T Saastamoinen's with
//!   DO-229's mapping ([`crate::gnss::atmosphere`]), k_I and k_T 1 plus the stated
//!   perturbations (0 to switch a model off), ε white noise of σ² = a² + b²/sin²(el)
//!   (the single-point solution's elevation weights), m a first-order Gauss–Markov
//!   multipath-like error per satellite (σ_m, τ_m) and f a stated step fault: the
//!   very model [`crate::gnss::spp`] inverts, so a noiseless epoch gives back the
//!   antenna and the clock exactly;
//! - the Doppler `D = −(ρ̇ + c·δṫ_r − c·Δṫ_sv + ε_ρ̇)/λ`, with the range rate of the
//!   light-time geometry `ρ̇ = u·(v_sat − v_ant)/(1 + u·V_sat/c)` (u the unit line of
//!   sight, V_sat the satellite's velocity in the inertial frame aligned with ECEF at
//!   reception; the rate of the light time τ̇ = ρ̇/c solved for) and ε_ρ̇ white of
//!   σ = σ_ρ̇·σ(el)/σ(90°);
//! - C/N0 `C/N0_min + (C/N0_max − C/N0_min)·sin(el)`.
//!
//! Only satellites above the elevation mask are seen; inside a window of the
//! scenario only its N highest, or its list of satellites, are. Random draws come
//! from the scenario's seed on a stream of their own, the same number at every epoch
//! for every satellite of the constellation (seen or not), so masks, windows and
//! faults never shift the noise of what is seen.

pub mod clock;
pub mod constellation;
pub mod spec;
pub mod trajectory;

use std::collections::BTreeMap;

use nalgebra::Vector3;

use crate::earth::{EarthModel, Wgs84};
use crate::gnss::atmosphere::{Klobuchar, look_angles, tropo_delay_m};
use crate::gnss::{C, Ephemeris, EphemerisStore, GpsTime, RawEpoch, RawMeasurement, Sat, Signal};
use crate::imu::random::Noise;
use clock::{Clock, ClockModel};

/// The stream of the raw GNSS draws (see `imu_model`, `receivers`, `vehicle`).
const STREAM_RAW_GNSS: u64 = 6;

/// Which satellites a window lets through.
#[derive(Debug, Clone, PartialEq)]
pub enum Keep {
    /// The `n` highest of those above the mask.
    Highest(usize),
    /// These, when above the mask.
    Listed(Vec<Sat>),
}

/// An interval of receiver time [s] in which only some satellites are seen.
#[derive(Debug, Clone, PartialEq)]
pub struct Window {
    /// Start [s], scenario time (inclusive).
    pub start: f64,
    /// End [s] (exclusive).
    pub end: f64,
    /// What is seen.
    pub keep: Keep,
}

/// A step added to one satellite's pseudoranges over an interval.
#[derive(Debug, Clone, PartialEq)]
pub struct Fault {
    /// The satellite.
    pub sat: Sat,
    /// Start [s], scenario time (inclusive).
    pub start: f64,
    /// End [s] (exclusive).
    pub end: f64,
    /// The step [m].
    pub step_m: f64,
}

/// A first-order Gauss–Markov error: standard deviation and correlation time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussMarkov {
    /// Steady-state standard deviation [m].
    pub sigma: f64,
    /// Correlation time [s].
    pub tau: f64,
}

/// Everything the simulation of raw observations needs, in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct RawGnssModel {
    /// The GPS week of the scenario's time (which is the second of that week).
    pub week: i64,
    /// The signals tracked (one measurement per satellite and signal).
    pub signals: Vec<Signal>,
    /// The interval between epochs [s].
    pub interval: f64,
    /// The elevation mask [rad].
    pub elevation_mask: f64,
    /// The receiver's clock.
    pub clock: ClockModel,
    /// The ionosphere's factor k_I (0: none; 1: Klobuchar's; 1.2: 20 % more).
    pub iono_scale: f64,
    /// The troposphere's factor k_T.
    pub tropo_scale: f64,
    /// Code noise `σ² = a² + b²/sin²(el)`: `[a, b]` [m].
    pub code_std: [f64; 2],
    /// The pseudorange rate's noise at the zenith [m/s].
    pub rate_std: f64,
    /// Multipath-like error on the code (none when `None`).
    pub multipath: Option<GaussMarkov>,
    /// C/N0 at the horizon and at the zenith [dB-Hz].
    pub cn0: [f64; 2],
    /// Windows of fewer satellites.
    pub windows: Vec<Window>,
    /// Step faults.
    pub faults: Vec<Fault>,
}

/// The truth of one satellite's measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatTruth {
    /// The satellite.
    pub sat: Sat,
    /// Elevation [rad].
    pub elevation: f64,
    /// Geometric range [m].
    pub range_m: f64,
    /// Ionospheric delay of the first signal [m], troposphere [m].
    pub iono_m: f64,
    /// See `iono_m`.
    pub tropo_m: f64,
    /// The multipath-like error [m].
    pub multipath_m: f64,
    /// The fault's step [m] (0 outside faults).
    pub fault_m: f64,
}

/// One simulated epoch: the measurements and their truth.
#[derive(Debug, Clone, PartialEq)]
pub struct RawSimEpoch {
    /// What the receiver reports.
    pub epoch: RawEpoch,
    /// GPS time of reception.
    pub t_true: GpsTime,
    /// The antenna's position [m] and velocity [m/s], ECEF, at `t_true`.
    pub r_e: Vector3<f64>,
    /// See `r_e`.
    pub v_e: Vector3<f64>,
    /// Receiver clock bias [s] and drift [s/s].
    pub clock_bias: f64,
    /// See `clock_bias`.
    pub clock_drift: f64,
    /// Per satellite seen, in the order of the measurements' satellites.
    pub sats: Vec<SatTruth>,
}

/// One satellite's draws of an epoch: its multipath state and, per signal, the
/// code's and the rate's standard normals.
type Draw = (Sat, f64, Vec<(f64, f64)>);

/// A satellite above the mask: its ephemeris, state, elevation and azimuth [rad].
type Seen<'a> = (Sat, &'a Ephemeris, crate::gnss::SatState, f64, f64);

/// The antenna's state at a scenario time: ECEF position [m] and velocity [m/s].
pub trait Antenna {
    /// The state at scenario time `t` [s], `None` outside the trajectory.
    fn at(&self, t: f64) -> Option<(Vector3<f64>, Vector3<f64>)>;
}

/// A seeded generator of raw epochs.
#[derive(Debug)]
pub struct RawGnssSimulator {
    model: RawGnssModel,
    store: EphemerisStore,
    klobuchar: Option<Klobuchar>,
    noise: Noise,
    clock: Clock,
    /// Multipath state per satellite of the constellation (every one, seen or not).
    multipath: BTreeMap<Sat, f64>,
    started: bool,
}

impl RawGnssSimulator {
    /// The receiver of `model` seeing the satellites of `store` (the ionosphere from
    /// `klobuchar`, none without), drawing from `seed`.
    pub fn new(
        model: RawGnssModel,
        store: EphemerisStore,
        klobuchar: Option<Klobuchar>,
        seed: u64,
    ) -> Self {
        let clock = Clock::new(&model.clock, model.interval);
        let multipath = store
            .sats()
            .filter(|s| model.signals.iter().any(|g| g.system == s.system))
            .map(|s| (s, 0.0))
            .collect();
        Self {
            model,
            store,
            klobuchar,
            noise: Noise::new(seed, STREAM_RAW_GNSS),
            clock,
            multipath,
            started: false,
        }
    }

    /// The model.
    pub fn model(&self) -> &RawGnssModel {
        &self.model
    }

    /// The epoch whose receiver clock reads scenario time `t_rx` [s]; call at
    /// consecutive epochs `interval` apart. `None` when the antenna has no state at
    /// the true time (before or after the trajectory); the clock still steps.
    pub fn epoch(&mut self, t_rx: f64, antenna: &impl Antenna) -> Option<RawSimEpoch> {
        self.advance();
        let m = &self.model;
        let bias = self.clock.bias;
        let rx = GpsTime::new(m.week, t_rx);
        let truth_t = rx.add_s(-bias);
        // The draws of every satellite, whatever is seen: per signal, the code's
        // and the rate's standard normals; the multipath's state.
        let mut draws: Vec<Draw> = Vec::with_capacity(self.multipath.len());
        for (&s, &mp) in &self.multipath {
            let v = m
                .signals
                .iter()
                .map(|_| (self.noise.normal(), self.noise.normal()))
                .collect();
            draws.push((s, mp, v));
        }
        let (r_ant, v_ant) = antenna.at(t_rx - bias)?;
        let geo = Wgs84.ecef_to_geodetic(&r_ant);
        let mut seen: Vec<Seen<'_>> = Vec::new();
        for (sat, _, _) in &draws {
            let Some(eph) = self.store.select(*sat, rx) else {
                continue;
            };
            let state = eph.state_by_light_time(truth_t, &r_ant);
            let look = look_angles(&r_ant, &state.r_e);
            if look.elevation >= m.elevation_mask {
                seen.push((*sat, eph, state, look.elevation, look.azimuth));
            }
        }
        self.apply_windows(t_rx, &mut seen);
        let mut measurements = Vec::new();
        let mut sats = Vec::new();
        for (sat, eph, state, el, az) in seen {
            let (_, mp, noise) = draws.iter().find(|d| d.0 == sat).expect("drawn");
            let d = state.r_e - r_ant;
            let range = d.norm();
            let u = d / range;
            let omega = eph.constants().omega_e;
            let v_inertial =
                state.v_e + Vector3::new(-omega * state.r_e.y, omega * state.r_e.x, 0.0);
            let range_rate = u.dot(&(state.v_e - v_ant)) / (1.0 + u.dot(&v_inertial) / C);
            let look = crate::gnss::atmosphere::LookAngles {
                elevation: el,
                azimuth: az,
            };
            let sin_el = el.sin().max(1e-3);
            let sigma = (m.code_std[0].powi(2) + (m.code_std[1] / sin_el).powi(2)).sqrt();
            let sigma_zenith = m.code_std[0].hypot(m.code_std[1]);
            let rate_sigma = if sigma_zenith > 0.0 {
                m.rate_std * sigma / sigma_zenith
            } else {
                m.rate_std
            };
            let fault: f64 = m
                .faults
                .iter()
                .filter(|f| f.sat == sat && (f.start..f.end).contains(&t_rx))
                .map(|f| f.step_m)
                .sum();
            let tropo = m.tropo_scale * tropo_delay_m(geo.lat, geo.h, el);
            let cn0 = m.cn0[0] + (m.cn0[1] - m.cn0[0]) * el.sin().max(0.0);
            let mut first_iono = None;
            for (signal, (n_code, n_rate)) in m.signals.iter().zip(noise) {
                if signal.system != sat.system {
                    continue;
                }
                let tgd = signal.group_delay_band().and_then(|b| eph.group_delay(b));
                let (Some(tgd), Some(freq)) = (tgd, signal.frequency(None)) else {
                    continue;
                };
                let iono = match (&self.klobuchar, m.iono_scale) {
                    (Some(k), s) if s != 0.0 => s * k.delay_m(geo.lat, geo.lon, look, rx.sow, freq),
                    _ => 0.0,
                };
                first_iono.get_or_insert(iono);
                let p = range
                    + C * (bias - state.clock_bias + tgd)
                    + iono
                    + tropo
                    + sigma * n_code
                    + mp
                    + fault;
                let rate =
                    range_rate + C * self.clock.drift - C * state.clock_drift + rate_sigma * n_rate;
                let mut meas = RawMeasurement::code(sat, *signal, p);
                meas.doppler = Some(-rate * freq / C);
                meas.cn0 = Some(cn0);
                measurements.push(meas);
            }
            sats.push(SatTruth {
                sat,
                elevation: el,
                range_m: range,
                iono_m: first_iono.unwrap_or(0.0),
                tropo_m: tropo,
                multipath_m: *mp,
                fault_m: fault,
            });
        }
        Some(RawSimEpoch {
            epoch: RawEpoch {
                t: rx,
                measurements,
            },
            t_true: truth_t,
            r_e: r_ant,
            v_e: v_ant,
            clock_bias: bias,
            clock_drift: self.clock.drift,
            sats,
        })
    }

    /// Steps the clock and the multipath states to this epoch (at the first epoch
    /// the clock keeps its initial state and the multipath is drawn from its
    /// steady state).
    fn advance(&mut self) {
        let first = !std::mem::replace(&mut self.started, true);
        if first {
            // Two draws as a step would take, so that every epoch draws the same.
            let _ = (self.noise.normal(), self.noise.normal());
        } else {
            self.clock.step(&mut self.noise);
        }
        let gm = self.model.multipath;
        let dt = self.model.interval;
        for mp in self.multipath.values_mut() {
            let w = self.noise.normal();
            *mp = match gm {
                None => 0.0,
                Some(g) if first => g.sigma * w,
                Some(g) => {
                    let phi = (-dt / g.tau).exp();
                    phi * *mp + g.sigma * (1.0 - phi * phi).sqrt() * w
                }
            };
        }
    }

    /// Keeps, inside a window, only what it lets through (the first window holding
    /// `t_rx` decides).
    fn apply_windows(&self, t_rx: f64, seen: &mut Vec<Seen<'_>>) {
        let Some(w) = self
            .model
            .windows
            .iter()
            .find(|w| (w.start..w.end).contains(&t_rx))
        else {
            return;
        };
        match &w.keep {
            Keep::Highest(n) => {
                // Highest first; equal elevations by satellite, for determinism.
                seen.sort_by(|a, b| b.3.total_cmp(&a.3).then(a.0.cmp(&b.0)));
                seen.truncate(*n);
                seen.sort_by_key(|s| s.0);
            }
            Keep::Listed(list) => seen.retain(|s| list.contains(&s.0)),
        }
    }
}

/// The ECEF position of geodetic `p` on WGS84 (for the antenna's implementors).
pub fn ecef(p: &crate::earth::Geodetic) -> Vector3<f64> {
    Wgs84.geodetic_to_ecef(p)
}
