//! Single-point positioning (SPP) and Doppler velocity from one epoch of raw
//! measurements and the broadcast ephemerides, with fault detection and exclusion.
//!
//! **Position.** Unknowns: the receiver's ECEF position `r` and one clock bias `b_s`
//! [m] per system present (inter-system biases as separate clocks). The code
//! pseudorange of satellite i on signal k (Misra & Enge 2006, §5.1; RTKLIB `pntpos.c`):
//!
//! `P = |r_i − r| + b_s − c·(Δt_i − T_k) + I_k + T + ε`,
//!
//! with `r_i` the satellite at transmission in the ECEF frame at reception and `Δt_i`
//! its clock with the relativistic term, both from
//! [`Ephemeris::state_at_reception`] (which does the Sagnac rotation), `T_k` the group
//! delay of the signal's band ([`Ephemeris::group_delay`]), `I_k` the Klobuchar delay
//! scaled to the signal's frequency (GPS's coefficients used for every system: BeiDou's
//! own and Galileo's NeQuick are not applied) and `T` Saastamoinen's with DO-229's
//! mapping ([`crate::gnss::atmosphere`]). Iterated weighted least squares (Gauss–Newton)
//! from the Earth's centre or a prior, until the step (position and clocks) is below
//! `convergence_m` (1e-4 m). While the iterate lies inside the Earth (|r| < 6000 km)
//! elevations mean nothing: every satellite counts as at the zenith, with no mask and
//! no atmosphere; once outside, the mask, the weights and the corrections follow the
//! current iterate, so at convergence they are those of the solution.
//!
//! **Weights.** `σ² = σ_meas² + σ_model²`: the measurement's own σ when the source
//! gives one (UBX) and [`SppConfig::use_reported_std`] is set, else [`Weighting`]'s
//! (default: elevation, `a² + b²/sin²el` with a = b = 0.3 m, RTKLIB's defaults
//! `err = 0.003 m` × `eratio = 100`); with [`SppConfig::model_errors`] (default on)
//! RTKLIB's model terms are added: the broadcast URA², (0.5·I)² with Klobuchar or
//! (5 m)² without, (0.3 m/(sin el + 0.1))² with Saastamoinen or (3 m/(sin el + 0.1))²
//! without (`ERR_BRDCI`, `ERR_ION`, `ERR_SAAS`, `ERR_TROP`).
//!
//! **Fault detection and exclusion.** The weighted sum of squared residuals
//! `vᵀWv` is χ²(n − m) when the σ are right; above its `1 − P_fa` quantile
//! ([`crate::filter::kalman::chi_square_quantile`], exact to 1e-10 by Newton on the
//! incomplete gamma function) the satellite with the largest normalised residual
//! `w_i = |v_i|/√(Q_v)_ii`, `Q_v = W⁻¹ − H(HᵀWH)⁻¹Hᵀ` (Baarda's w-test) is excluded and
//! the solution repeated, while at least two degrees of freedom remain before the
//! exclusion (with one, every w is equal and none can be told). Every exclusion is
//! reported with its statistic.
//!
//! **Velocity.** With the position fixed, the pseudorange rate `ρ̇ = −λ·D`
//! ([`RawMeasurement::pseudorange_rate`]) of each satellite used is, in the inertial
//! frame aligned with ECEF at reception (where the satellite's velocity is
//! `V_i = v_i + ω×r_i` and the receiver's `v + ω×r`):
//! `ρ̇ = u·(v_i − v)/(1 + u·V_i/c) + d − c·Δṫ_i`, u the unit line of sight, d the
//! receiver's clock drift [m/s]. The Earth-rotation terms `u·(ω×r_i − ω×r)` vanish (ω×
//! of the line of sight is perpendicular to it), and `1/(1 + u·V_i/c)` is the light
//! time's rate (dτ/dt_rx; it changes ρ̇ by up to 3 mm/s). One linear weighted least
//! squares in (v, d).

use nalgebra::{DMatrix, Matrix4, SVector, Vector3, Vector4};
use thiserror::Error;

use super::atmosphere::{Klobuchar, LookAngles, tropo_delay_m};
use super::dop::{Dop, MAX_UNKNOWNS, Normal, factor};
use super::ephemeris::{C, Ephemeris, NavMessage};
use super::orbit::SatState;
use super::raw::{RawEpoch, RawMeasurement, Signal};
use super::sat::{Sat, System};
use super::store::EphemerisStore;
use super::time::GpsTime;
use crate::earth::{EarthModel, Geodetic, Wgs84, c_ne};
use crate::filter::kalman::chi_square_quantile;

/// How pseudoranges are weighted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Weighting {
    /// By elevation: `σ² = a² + b²/sin²(el)` [m²] (RTKLIB's `varerr`).
    Elevation {
        /// Constant part [m].
        a: f64,
        /// Elevation-dependent part [m].
        b: f64,
    },
    /// By C/N0: `σ² = a² + k·10^(−C/N0/10)` [m²], the σ-ε model of Hartinger & Brunner
    /// (1999) with a floor `a`. A measurement without C/N0 is weighted by elevation with
    /// a = b = 0.3 m.
    Cn0 {
        /// Floor [m].
        a: f64,
        /// Scale [m²·Hz]; 11 384 makes 45 dB-Hz weigh as 30° elevation by default
        /// elevation weights (σ² = 0.45 m²).
        k: f64,
    },
}

impl Default for Weighting {
    fn default() -> Self {
        Self::Elevation { a: 0.3, b: 0.3 }
    }
}

/// The default elevation weighting's `a` and `b` [m].
const DEFAULT_AB: f64 = 0.3;

impl Weighting {
    /// The C/N0 weighting with its default constants (a = 0.3 m, k = 11 384 m²·Hz).
    pub const CN0_DEFAULT: Self = Self::Cn0 {
        a: 0.3,
        k: 11_384.0,
    };

    /// The measurement σ [m] at elevation `el` [rad] and C/N0 `cn0` [dB-Hz].
    pub fn sigma(&self, el: f64, cn0: Option<f64>) -> f64 {
        let by_elevation = |a: f64, b: f64| {
            let s = el.sin().max(1e-3);
            (a * a + b * b / (s * s)).sqrt()
        };
        match (*self, cn0) {
            (Self::Elevation { a, b }, _) => by_elevation(a, b),
            (Self::Cn0 { a, k }, Some(cn0)) => (a * a + k * 10f64.powf(-cn0 / 10.0)).sqrt(),
            (Self::Cn0 { .. }, None) => by_elevation(DEFAULT_AB, DEFAULT_AB),
        }
    }

    /// The σ [m] of a reference measurement (zenith; 45 dB-Hz) that the Doppler's σ
    /// ([`SppConfig::doppler_sigma`]) refers to.
    fn reference_sigma(&self) -> f64 {
        self.sigma(std::f64::consts::FRAC_PI_2, Some(45.0))
    }
}

/// Fault detection and exclusion settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FdeConfig {
    /// False-alarm probability of the chi-square test per epoch (default 1e-3).
    pub false_alarm: f64,
    /// The most satellites excluded in one epoch (default 8).
    pub max_exclusions: usize,
}

impl Default for FdeConfig {
    fn default() -> Self {
        Self {
            false_alarm: 1e-3,
            max_exclusions: 8,
        }
    }
}

/// Settings of a single-point solution.
#[derive(Debug, Clone, PartialEq)]
pub struct SppConfig {
    /// Elevation mask [rad] (default 10°).
    pub elevation_mask: f64,
    /// Pseudorange weights (default by elevation, a = b = 0.3 m).
    pub weighting: Weighting,
    /// Use a measurement's own σ ([`RawMeasurement::pseudorange_std`]) in place of
    /// [`SppConfig::weighting`] when it has one (default true).
    pub use_reported_std: bool,
    /// Add the variances of the broadcast orbit (URA) and of the atmosphere models to
    /// the measurement's (default true; see the module's doc).
    pub model_errors: bool,
    /// The signals used, per system, in order of preference (the first one measured
    /// is used). A system not listed is not used.
    pub signals: Vec<(System, Vec<Signal>)>,
    /// Apply the Klobuchar ionosphere when coefficients are given (default true).
    pub ionosphere: bool,
    /// Apply the Saastamoinen troposphere (default true).
    pub troposphere: bool,
    /// Fault detection and exclusion; `None` to skip it.
    pub fde: Option<FdeConfig>,
    /// σ of a pseudorange rate from Doppler [m/s] of the reference measurement (zenith,
    /// or 45 dB-Hz), scaled for others as the code's σ (default 0.1 m/s); a
    /// measurement's own σ replaces it as for the code.
    pub doppler_sigma: f64,
    /// The most least-squares iterations (default 20).
    pub max_iterations: usize,
    /// Convergence: the step of position and clocks [m] (default 1e-4).
    pub convergence_m: f64,
}

impl Default for SppConfig {
    fn default() -> Self {
        let s = Signal::new;
        Self {
            elevation_mask: 10f64.to_radians(),
            weighting: Weighting::default(),
            use_reported_std: true,
            model_errors: true,
            signals: vec![
                (System::Gps, vec![s(System::Gps, '1', 'C')]),
                (
                    System::Galileo,
                    vec![s(System::Galileo, '1', 'C'), s(System::Galileo, '1', 'X')],
                ),
                (System::BeiDou, vec![s(System::BeiDou, '2', 'I')]),
                (System::Qzss, vec![s(System::Qzss, '1', 'C')]),
            ],
            ionosphere: true,
            troposphere: true,
            fde: Some(FdeConfig::default()),
            doppler_sigma: 0.1,
            max_iterations: 20,
            convergence_m: 1e-4,
        }
    }
}

impl SppConfig {
    /// Checks every setting's domain.
    pub fn validate(&self) -> Result<(), SppError> {
        let bad = |what| Err(SppError::InvalidConfig(what));
        let half_pi = std::f64::consts::FRAC_PI_2;
        if self.elevation_mask.is_nan() || self.elevation_mask.abs() > half_pi {
            return bad("elevation_mask must be within ±90°");
        }
        let finite_nonneg = |x: f64| x.is_finite() && x >= 0.0;
        let weights_ok = match self.weighting {
            Weighting::Elevation { a, b } => finite_nonneg(a) && finite_nonneg(b) && a + b > 0.0,
            Weighting::Cn0 { a, k } => finite_nonneg(a) && finite_nonneg(k) && a + k > 0.0,
        };
        if !weights_ok {
            return bad("weighting constants must be finite, ≥ 0 and not all 0");
        }
        if let Some(f) = self.fde
            && !(f.false_alarm > 0.0 && f.false_alarm < 1.0)
        {
            return bad("fde.false_alarm must be in (0, 1)");
        }
        if !(self.doppler_sigma.is_finite() && self.doppler_sigma > 0.0) {
            return bad("doppler_sigma must be finite and > 0");
        }
        if self.max_iterations == 0 {
            return bad("max_iterations must be ≥ 1");
        }
        if !(self.convergence_m.is_finite() && self.convergence_m > 0.0) {
            return bad("convergence_m must be finite and > 0");
        }
        Ok(())
    }

    /// The preferred signals of `system` (empty when it is not used).
    fn signals_of(&self, system: System) -> &[Signal] {
        self.signals
            .iter()
            .find(|(s, _)| *s == system)
            .map_or(&[], |(_, v)| v.as_slice())
    }
}

/// Why a satellite of the epoch is not in the solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exclusion {
    /// Its system is not in [`SppConfig::signals`].
    SystemNotUsed,
    /// None of its system's preferred signals carries a pseudorange.
    NoSignal,
    /// The chosen signal's pseudorange is not finite and positive.
    InvalidMeasurement,
    /// No ephemeris of it is valid at the epoch.
    NoEphemeris,
    /// Its ephemerides valid at the epoch all say it is unhealthy.
    Unhealthy,
    /// The ephemeris gives no group delay (or the signal no frequency) for this signal.
    NoGroupDelay(Signal),
    /// Below the elevation mask at the solution [rad].
    BelowMask {
        /// Its elevation [rad].
        elevation: f64,
    },
    /// Excluded by the fault detection: its w-test statistic (normalised residual) and
    /// the chi-square test that failed.
    Fault {
        /// `|v_i|/σ_v,i`, the largest of the epoch.
        w: f64,
        /// The failed test's `vᵀWv`.
        statistic: f64,
        /// Its threshold, the χ² quantile.
        threshold: f64,
    },
}

/// A satellite left out, and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Excluded {
    /// The satellite.
    pub sat: Sat,
    /// Why.
    pub reason: Exclusion,
}

/// Why there is no solution.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SppError {
    /// Fewer usable satellites than unknowns (position and one clock per system).
    #[error("{have} usable satellites for {need} unknowns ({} excluded)", excluded.len())]
    TooFewSatellites {
        /// Satellites usable.
        have: usize,
        /// Unknowns.
        need: usize,
        /// The satellites left out, with their reasons.
        excluded: Vec<Excluded>,
    },
    /// The iteration did not converge.
    #[error("no convergence in {iterations} iterations (last step {step_m:.3e} m)")]
    NotConverged {
        /// Iterations made.
        iterations: usize,
        /// The last step [m].
        step_m: f64,
    },
    /// The geometry is singular (satellites in a plane with the receiver, or nearly).
    #[error("singular satellite geometry")]
    SingularGeometry,
    /// A setting out of its domain.
    #[error("invalid SPP configuration: {0}")]
    InvalidConfig(&'static str),
}

/// A satellite in the solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UsedSat {
    /// The satellite.
    pub sat: Sat,
    /// The signal used.
    pub signal: Signal,
    /// Its state at transmission, ECEF at reception (clock without group delay).
    pub state: SatState,
    /// Post-fit pseudorange residual [m] (measured − modelled).
    pub residual: f64,
    /// The σ it was weighted with [m].
    pub sigma: f64,
    /// Elevation [rad].
    pub elevation: f64,
    /// Azimuth [rad], clockwise from north.
    pub azimuth: f64,
    /// Ionospheric delay applied [m].
    pub iono_m: f64,
    /// Tropospheric delay applied [m].
    pub tropo_m: f64,
    /// Post-fit pseudorange-rate residual [m/s] when its Doppler was used.
    pub rate_residual: Option<f64>,
}

/// The chi-square test of the final solution's residuals (at the FDE's false-alarm
/// probability; at 1e-3 when FDE is off).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualTest {
    /// `vᵀWv`.
    pub statistic: f64,
    /// Degrees of freedom, satellites − unknowns.
    pub dof: usize,
    /// The χ²(dof) quantile at 1 − P_fa.
    pub threshold: f64,
    /// Whether the statistic is within it (false: a fault left, no redundancy to
    /// exclude it).
    pub passed: bool,
}

/// A single-point solution of one epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct SppSolution {
    /// The epoch's receive time by the receiver's clock; GPS time is
    /// [`SppSolution::gps_time`].
    pub t: GpsTime,
    /// Position, ECEF [m].
    pub r_e: Vector3<f64>,
    /// The same as latitude, longitude, height (WGS84).
    pub geodetic: Geodetic,
    /// Receiver clock bias [m] per system, in [`System`]'s order; the order of the
    /// clocks in [`SppSolution::cov`].
    pub clock_bias: Vec<(System, f64)>,
    /// Velocity, ECEF [m/s], when four or more satellites used have a Doppler.
    pub v_e: Option<Vector3<f64>>,
    /// Receiver clock drift [m/s], with the velocity.
    pub clock_drift: Option<f64>,
    /// Covariance of position [m²] and clocks (the weighted least squares' `(HᵀWH)⁻¹`).
    pub cov: DMatrix<f64>,
    /// Covariance of velocity and clock drift, with them.
    pub cov_velocity: Option<Matrix4<f64>>,
    /// The satellites used.
    pub used: Vec<UsedSat>,
    /// The satellites of the epoch left out, with their reasons, in the order met.
    pub excluded: Vec<Excluded>,
    /// Dilutions of precision of the satellites used.
    pub dop: Dop,
    /// The residuals' chi-square test (`None` without redundancy).
    pub residual_test: Option<ResidualTest>,
    /// Least-squares iterations, over every solution of the exclusions.
    pub iterations: usize,
}

impl SppSolution {
    /// GPS time of reception: `t − b/c` with the clock bias of GPS, or of the first
    /// system when GPS is not used.
    pub fn gps_time(&self) -> GpsTime {
        let b = self
            .clock_bias
            .iter()
            .find(|(s, _)| *s == System::Gps)
            .or(self.clock_bias.first())
            .map_or(0.0, |(_, b)| *b);
        self.t.add_s(-b / C)
    }

    /// The clock bias of `system` [m], if it is in the solution.
    pub fn clock_of(&self, system: System) -> Option<f64> {
        self.clock_bias
            .iter()
            .find(|(s, _)| *s == system)
            .map(|(_, b)| *b)
    }
}

/// A satellite that passed the checks of the epoch: its measurement and ephemeris.
pub(crate) struct Candidate<'a> {
    pub(crate) sat: Sat,
    pub(crate) signal: Signal,
    pub(crate) m: &'a RawMeasurement,
    pub(crate) eph: &'a Ephemeris,
    pub(crate) pseudorange: f64,
    /// Group delay of the signal [s].
    pub(crate) tgd: f64,
    /// Carrier frequency [Hz].
    pub(crate) freq: f64,
    /// Index of its system's clock.
    clock: usize,
    /// Still in the solution (not excluded by the FDE).
    active: bool,
    /// Its state, computed at `state_at`.
    state: SatState,
}

/// One row of the linearised problem.
#[derive(Clone, Copy)]
struct Row {
    cand: usize,
    /// Its system's clock.
    clock: usize,
    /// Unit line of sight, receiver to satellite, ECEF.
    u: Vector3<f64>,
    residual: f64,
    var: f64,
    look: LookAngles,
    iono: f64,
    tropo: f64,
}

/// The converged least squares of one set of satellites.
struct Fix {
    x: SVector<f64, MAX_UNKNOWNS>,
    rows: Vec<Row>,
    normal: Normal,
    /// Clocks with at least one row.
    clock_used: [bool; MAX_UNKNOWNS - 3],
    masked: Vec<(usize, f64)>,
    /// Iterations made (in [`finish`]: over every solution of the exclusions).
    iterations: usize,
}

/// Where the iterate counts as outside the Earth [m] (see the module's doc).
const OUTSIDE_EARTH_M: f64 = 6.0e6;
/// How far the iterate may move [m] before the satellites' states are recomputed: the
/// Sagnac rotation moves a satellite by Ω̇e·|r_i|·δ/c ≈ 6e-6·δ, 0.6 µm for 0.1 m.
const STATE_REFRESH_M: f64 = 0.1;

/// The single-point solution of `epoch`: position and clocks, then velocity and clock
/// drift, with fault detection and exclusion (see the module's doc). `klobuchar`: the
/// broadcast ionosphere coefficients, if any; `prior`: a starting position (ECEF [m];
/// the Earth's centre when `None`).
pub fn solve(
    epoch: &RawEpoch,
    store: &EphemerisStore,
    klobuchar: Option<&Klobuchar>,
    config: &SppConfig,
    prior: Option<Vector3<f64>>,
) -> Result<SppSolution, SppError> {
    config.validate()?;
    let (mut cands, mut excluded, systems) = candidates(epoch, store, config);
    let iono = klobuchar.filter(|_| config.ionosphere);
    let start = prior.filter(|p| p.iter().all(|x| x.is_finite()));
    let mut x = SVector::<f64, MAX_UNKNOWNS>::zeros();
    if let Some(p) = start {
        x.fixed_rows_mut::<3>(0).copy_from(&p);
    }
    let mut iterations = 0;
    let mut faults = Vec::new();
    let (mut fix, test) = loop {
        let fix = match least_squares(epoch.t, &mut cands, x, iono, config, !faults.is_empty()) {
            Ok(f) => f,
            Err(SppError::TooFewSatellites {
                have,
                need,
                excluded: masked,
            }) => {
                let mut all = excluded.clone();
                all.extend(faults.iter().copied());
                all.extend(masked);
                return Err(SppError::TooFewSatellites {
                    have,
                    need,
                    excluded: all,
                });
            }
            Err(e) => return Err(e),
        };
        iterations += fix.iterations;
        x = fix.x;
        let m = 3 + fix.clock_used.iter().filter(|&&u| u).count();
        let n = fix.rows.len();
        let Some(fde) = config.fde.filter(|_| n > m) else {
            let test = (n > m).then(|| residual_test(&fix.rows, n - m, 1e-3));
            break (fix, test);
        };
        let test = residual_test(&fix.rows, n - m, fde.false_alarm);
        if test.passed || test.dof < 2 || faults.len() >= fde.max_exclusions {
            break (fix, Some(test));
        }
        match largest_w(&fix) {
            Some((row, w)) => {
                let i = fix.rows[row].cand;
                cands[i].active = false;
                faults.push(Excluded {
                    sat: cands[i].sat,
                    reason: Exclusion::Fault {
                        w,
                        statistic: test.statistic,
                        threshold: test.threshold,
                    },
                });
            }
            None => break (fix, Some(test)),
        }
    };
    excluded.extend(faults);
    excluded.extend(masked_exclusions(&cands, &fix.masked));
    fix.iterations = iterations;
    Ok(finish(epoch, &cands, fix, test, excluded, &systems, config))
}

/// The epoch's satellites sorted into candidates and exclusions; the systems of the
/// candidates (their clocks' order).
pub(crate) fn candidates<'a>(
    epoch: &'a RawEpoch,
    store: &'a EphemerisStore,
    config: &SppConfig,
) -> (Vec<Candidate<'a>>, Vec<Excluded>, Vec<System>) {
    let mut cands = Vec::new();
    let mut excluded = Vec::new();
    let mut systems: Vec<System> = Vec::new();
    for sat in epoch.sats() {
        let exclude = |reason| Excluded { sat, reason };
        let prefs = config.signals_of(sat.system);
        if prefs.is_empty() {
            excluded.push(exclude(Exclusion::SystemNotUsed));
            continue;
        }
        let Some(m) = prefs
            .iter()
            .find_map(|&s| epoch.get(sat, s).filter(|m| m.pseudorange.is_some()))
        else {
            excluded.push(exclude(Exclusion::NoSignal));
            continue;
        };
        let p = m.pseudorange.unwrap_or(f64::NAN);
        if !(p.is_finite() && p > 0.0) {
            excluded.push(exclude(Exclusion::InvalidMeasurement));
            continue;
        }
        let Some(eph) = ephemeris_for(store, sat, m.signal, epoch.t) else {
            let any_window = store.of(sat).iter().any(|e| {
                let (early, late) = e.fit_window_s();
                let age = epoch.t.diff_s(e.toe);
                age >= early && age <= late
            });
            let reason = if any_window {
                Exclusion::Unhealthy
            } else {
                Exclusion::NoEphemeris
            };
            excluded.push(exclude(reason));
            continue;
        };
        let tgd = m.signal.group_delay_band().and_then(|b| eph.group_delay(b));
        let (Some(tgd), Some(freq)) = (tgd, m.frequency()) else {
            excluded.push(exclude(Exclusion::NoGroupDelay(m.signal)));
            continue;
        };
        let clock = match systems.iter().position(|&s| s == sat.system) {
            Some(i) => i,
            None => {
                systems.push(sat.system);
                systems.len() - 1
            }
        };
        cands.push(Candidate {
            sat,
            signal: m.signal,
            m,
            eph,
            pseudorange: p,
            tgd,
            freq,
            clock,
            active: true,
            // Computed by the least squares before its first use.
            state: SatState {
                t: epoch.t,
                r_e: Vector3::zeros(),
                v_e: Vector3::zeros(),
                clock_bias: 0.0,
                clock_drift: 0.0,
            },
        });
    }
    // `epoch.sats()` is sorted, so the systems come in `System`'s order.
    (cands, excluded, systems)
}

/// The ephemeris for `signal`: Galileo E1 and E5b from I/NAV, E5a from F/NAV (the
/// clocks those messages are fitted for) when there is one, else any.
fn ephemeris_for(
    store: &EphemerisStore,
    sat: Sat,
    signal: Signal,
    t: GpsTime,
) -> Option<&Ephemeris> {
    let preferred = match (sat.system, signal.band) {
        (System::Galileo, '1' | '7') => Some(NavMessage::Inav),
        (System::Galileo, '5') => Some(NavMessage::Fnav),
        _ => None,
    };
    preferred
        .and_then(|msg| store.select_message(sat, t, msg))
        .or_else(|| store.select(sat, t))
}

/// The chi-square test of rows' weighted residuals at false-alarm probability `pfa`.
fn residual_test(rows: &[Row], dof: usize, pfa: f64) -> ResidualTest {
    let statistic: f64 = rows.iter().map(|r| r.residual * r.residual / r.var).sum();
    let threshold = chi_square_quantile(dof, 1.0 - pfa);
    ResidualTest {
        statistic,
        dof,
        threshold,
        passed: statistic <= threshold,
    }
}

/// The row with the largest normalised residual `|v_i|/√(σ_i² − h_i N⁻¹ h_iᵀ)` and its
/// value; rows whose residual variance vanishes (the only satellite of its system) are
/// skipped.
fn largest_w(fix: &Fix) -> Option<(usize, f64)> {
    let chol = factor(&fix.normal, MAX_UNKNOWNS)?;
    let mut best: Option<(usize, f64)> = None;
    for (k, row) in fix.rows.iter().enumerate() {
        let h = design_row(&row.u, row.clock);
        let q = row.var - h.dot(&chol.solve(&h));
        if q <= 1e-9 * row.var {
            continue;
        }
        let w = row.residual.abs() / q.sqrt();
        if best.is_none_or(|(_, b)| w > b) {
            best = Some((k, w));
        }
    }
    best
}

/// Adds one row `h = [−u, 1 at the clock]` of weight `1/var` and residual `v` to the
/// normal equations: `N += hᵀh/var`, `b += hᵀv/var` (h's five non-zeros only; a
/// general 10×10 outer product was a sixth of the solver's time).
fn accumulate(
    normal: &mut Normal,
    b: &mut SVector<f64, MAX_UNKNOWNS>,
    u: &Vector3<f64>,
    clock: usize,
    v: f64,
    var: f64,
) {
    let w = 1.0 / var;
    let k = 3 + clock;
    for i in 0..3 {
        let hi = -u[i] * w;
        for j in 0..3 {
            normal[(i, j)] += hi * -u[j];
        }
        normal[(i, k)] += hi;
        normal[(k, i)] += hi;
        b[i] += hi * v;
    }
    normal[(k, k)] += w;
    b[k] += w * v;
}

/// The design vector `[−u, 1 at the clock]`.
fn design_row(u: &Vector3<f64>, clock: usize) -> SVector<f64, MAX_UNKNOWNS> {
    let mut h = SVector::<f64, MAX_UNKNOWNS>::zeros();
    h[0] = -u.x;
    h[1] = -u.y;
    h[2] = -u.z;
    h[3 + clock] = 1.0;
    h
}

/// The last step [m] below which the linearisation counts as settled: the mask, the
/// weights and the atmosphere then follow the iterate (before, an iterate hundreds of
/// kilometres off would mask satellites wrongly).
const SETTLED_STEP_M: f64 = 1e4;

/// Gauss–Newton on the active candidates from `x0` to convergence; `settled_start`:
/// `x0` is a converged solution (of the same epoch with one satellite more).
fn least_squares(
    t: GpsTime,
    cands: &mut [Candidate<'_>],
    x0: SVector<f64, MAX_UNKNOWNS>,
    iono: Option<&Klobuchar>,
    config: &SppConfig,
    settled_start: bool,
) -> Result<Fix, SppError> {
    let mut x = x0;
    let mut rows = Vec::with_capacity(cands.len());
    let mut masked = Vec::new();
    let mut states_at: Option<Vector3<f64>> = None;
    let mut step = if settled_start { 0.0 } else { f64::INFINITY };
    let mut converged = false;
    for iteration in 0..=config.max_iterations {
        let r: Vector3<f64> = x.fixed_rows::<3>(0).into_owned();
        if states_at.is_none_or(|s| (s - r).norm() > STATE_REFRESH_M) {
            for c in cands.iter_mut().filter(|c| c.active) {
                c.state = c.eph.state_at_reception(t, c.pseudorange, &r);
            }
            states_at = Some(r);
        }
        let settled = r.norm() > OUTSIDE_EARTH_M && step < SETTLED_STEP_M;
        let lin = Linearisation {
            t,
            iono,
            config,
            settled,
        };
        let (normal, b, clock_used) = lin.run(cands, &x, &mut rows, &mut masked);
        let m = 3 + clock_used.iter().filter(|&&u| u).count();
        if rows.len() < m {
            return Err(SppError::TooFewSatellites {
                have: rows.len(),
                need: m.max(4),
                excluded: masked_exclusions(cands, &masked),
            });
        }
        if converged {
            return Ok(Fix {
                x,
                rows,
                normal,
                clock_used,
                masked,
                iterations: iteration,
            });
        }
        if iteration == config.max_iterations {
            break;
        }
        let chol = factor(&normal, MAX_UNKNOWNS).ok_or(SppError::SingularGeometry)?;
        let dx = chol.solve(&b);
        step = dx.norm();
        if !step.is_finite() {
            return Err(SppError::SingularGeometry);
        }
        x += dx;
        converged = settled && step < config.convergence_m;
    }
    Err(SppError::NotConverged {
        iterations: config.max_iterations,
        step_m: step,
    })
}

/// What one linearisation needs besides the candidates.
struct Linearisation<'a> {
    t: GpsTime,
    iono: Option<&'a Klobuchar>,
    config: &'a SppConfig,
    settled: bool,
}

impl Linearisation<'_> {
    /// The rows of the active candidates at `x` (masked ones into `masked`) and the
    /// weighted normal equations `HᵀWH`, `HᵀWv`, with the clocks that have a row.
    fn run(
        &self,
        cands: &[Candidate<'_>],
        x: &SVector<f64, MAX_UNKNOWNS>,
        rows: &mut Vec<Row>,
        masked: &mut Vec<(usize, f64)>,
    ) -> (Normal, SVector<f64, MAX_UNKNOWNS>, [bool; MAX_UNKNOWNS - 3]) {
        rows.clear();
        masked.clear();
        let mut normal = Normal::zeros();
        let mut b = SVector::<f64, MAX_UNKNOWNS>::zeros();
        let mut clock_used = [false; MAX_UNKNOWNS - 3];
        let r: Vector3<f64> = x.fixed_rows::<3>(0).into_owned();
        let local = self.settled.then(|| {
            let g = Wgs84.ecef_to_geodetic(&r);
            (g, c_ne(g.lat, g.lon).transpose())
        });
        for (i, c) in cands.iter().enumerate().filter(|(_, c)| c.active) {
            let d = c.state.r_e - r;
            let range = d.norm();
            let u = d / range;
            let (look, iono_m, tropo_m) = match local {
                Some((g, c_en)) => {
                    // `atmosphere::look_angles` with the geodetic conversion hoisted.
                    let los_n = c_en * d;
                    let elevation = (-los_n.z).atan2(los_n.x.hypot(los_n.y));
                    if elevation < self.config.elevation_mask {
                        masked.push((i, elevation));
                        continue;
                    }
                    let azimuth = los_n.y.atan2(los_n.x).rem_euclid(std::f64::consts::TAU);
                    let look = LookAngles { elevation, azimuth };
                    let iono_m = self
                        .iono
                        .map_or(0.0, |k| k.delay_m(g.lat, g.lon, look, self.t.sow, c.freq));
                    let tropo_m = if self.config.troposphere {
                        tropo_delay_m(g.lat, g.h, elevation)
                    } else {
                        0.0
                    };
                    (look, iono_m, tropo_m)
                }
                None => (
                    LookAngles {
                        elevation: std::f64::consts::FRAC_PI_2,
                        azimuth: 0.0,
                    },
                    0.0,
                    0.0,
                ),
            };
            let modelled =
                range + x[3 + c.clock] - C * (c.state.clock_bias - c.tgd) + iono_m + tropo_m;
            let residual = c.pseudorange - modelled;
            let var = self.variance(c, look.elevation, iono_m);
            accumulate(&mut normal, &mut b, &u, c.clock, residual, var);
            clock_used[c.clock] = true;
            rows.push(Row {
                cand: i,
                clock: c.clock,
                u,
                residual,
                var,
                look,
                iono: iono_m,
                tropo: tropo_m,
            });
        }
        // A clock without a row: the identity there (its step and variance 0 and 1).
        for (k, used) in clock_used.iter().enumerate() {
            if !used {
                normal[(3 + k, 3 + k)] = 1.0;
            }
        }
        (normal, b, clock_used)
    }

    /// The pseudorange's variance [m²] (see the module's doc).
    fn variance(&self, c: &Candidate<'_>, el: f64, iono_m: f64) -> f64 {
        let iono = self.iono.map(|_| iono_m);
        pseudorange_variance(self.config, c.m, c.eph.accuracy_m, el, iono)
    }
}

/// The variance [m²] of pseudorange `m` at elevation `el` [rad] from a satellite
/// whose broadcast accuracy is `ura` [m]: the measurement's own σ or the weighting's,
/// plus the model terms of the module's doc; `iono_m` the Klobuchar delay applied,
/// `None` without one.
pub(crate) fn pseudorange_variance(
    cfg: &SppConfig,
    m: &RawMeasurement,
    ura: f64,
    el: f64,
    iono_m: Option<f64>,
) -> f64 {
    let reported = m
        .pseudorange_std
        .filter(|s| cfg.use_reported_std && s.is_finite() && *s > 0.0);
    let meas = reported.unwrap_or_else(|| cfg.weighting.sigma(el, m.cn0));
    let mut var = meas * meas;
    if cfg.model_errors {
        if ura.is_finite() && ura > 0.0 {
            var += ura * ura;
        }
        var += match iono_m {
            Some(i) => (0.5 * i).powi(2),
            None => 5.0 * 5.0,
        };
        let tropo_err = if cfg.troposphere { 0.3 } else { 3.0 };
        var += (tropo_err / (el.sin() + 0.1)).powi(2);
    }
    var
}

/// The σ [m/s] of the pseudorange rate of `m` at elevation `el` [rad]: its own when
/// the source gives one, else [`SppConfig::doppler_sigma`] scaled as the code's σ.
pub(crate) fn rate_sigma(cfg: &SppConfig, m: &RawMeasurement, el: f64) -> f64 {
    let reported = m
        .pseudorange_rate_std()
        .filter(|s| cfg.use_reported_std && s.is_finite() && *s > 0.0);
    reported.unwrap_or_else(|| {
        cfg.doppler_sigma * cfg.weighting.sigma(el, m.cn0) / cfg.weighting.reference_sigma()
    })
}

/// The masked candidates as exclusions.
fn masked_exclusions(cands: &[Candidate<'_>], masked: &[(usize, f64)]) -> Vec<Excluded> {
    masked
        .iter()
        .map(|&(i, elevation)| Excluded {
            sat: cands[i].sat,
            reason: Exclusion::BelowMask { elevation },
        })
        .collect()
}

/// The solution from the final fix: clocks, covariance, DOP, velocity.
fn finish(
    epoch: &RawEpoch,
    cands: &[Candidate<'_>],
    fix: Fix,
    residual_test: Option<ResidualTest>,
    excluded: Vec<Excluded>,
    systems: &[System],
    config: &SppConfig,
) -> SppSolution {
    let r_e: Vector3<f64> = fix.x.fixed_rows::<3>(0).into_owned();
    let geodetic = Wgs84.ecef_to_geodetic(&r_e);
    // The unknowns kept: position and the clocks with a row; `slot[k]` is clock k's
    // index among them.
    let mut keep = vec![0, 1, 2];
    let mut slot = [usize::MAX; MAX_UNKNOWNS - 3];
    let mut clock_bias = Vec::new();
    for (k, &system) in systems.iter().enumerate() {
        if fix.clock_used[k] {
            slot[k] = clock_bias.len();
            clock_bias.push((system, fix.x[3 + k]));
            keep.push(3 + k);
        }
    }
    let m = keep.len();
    let inverse = factor(&fix.normal, MAX_UNKNOWNS).map(|c| c.inverse());
    let cov = DMatrix::from_fn(m, m, |i, j| {
        inverse.map_or(f64::NAN, |g| g[(keep[i], keep[j])])
    });
    let c_en = c_ne(geodetic.lat, geodetic.lon).transpose();
    let dop = Dop::of(
        fix.rows.iter().map(|row| (c_en * row.u, slot[row.clock])),
        clock_bias.len(),
    )
    .unwrap_or(Dop {
        gdop: f64::NAN,
        pdop: f64::NAN,
        hdop: f64::NAN,
        vdop: f64::NAN,
        tdop: f64::NAN,
    });
    let vel = velocity(cands, &fix.rows, config);
    let used = fix
        .rows
        .iter()
        .enumerate()
        .map(|(k, row)| {
            let c = &cands[row.cand];
            UsedSat {
                sat: c.sat,
                signal: c.signal,
                state: c.state,
                residual: row.residual,
                sigma: row.var.sqrt(),
                elevation: row.look.elevation,
                azimuth: row.look.azimuth,
                iono_m: row.iono,
                tropo_m: row.tropo,
                rate_residual: vel.as_ref().and_then(|v| v.residuals[k]),
            }
        })
        .collect();
    SppSolution {
        t: epoch.t,
        r_e,
        geodetic,
        clock_bias,
        v_e: vel.as_ref().map(|v| v.v_e),
        clock_drift: vel.as_ref().map(|v| v.drift),
        cov,
        cov_velocity: vel.as_ref().map(|v| v.cov),
        used,
        excluded,
        dop,
        residual_test,
        iterations: fix.iterations,
    }
}

/// A Doppler velocity.
struct Velocity {
    v_e: Vector3<f64>,
    drift: f64,
    cov: Matrix4<f64>,
    /// Per row of the position fix: its rate residual, when its Doppler was used.
    residuals: Vec<Option<f64>>,
}

/// Velocity and clock drift from the Dopplers of the rows' satellites (see the
/// module's doc); `None` with fewer than four or a singular geometry.
fn velocity(cands: &[Candidate<'_>], rows: &[Row], config: &SppConfig) -> Option<Velocity> {
    let mut normal = Matrix4::<f64>::zeros();
    let mut b = Vector4::<f64>::zeros();
    let mut lin = Vec::with_capacity(rows.len());
    for row in rows {
        let c = &cands[row.cand];
        let Some(rate) = c.m.pseudorange_rate().filter(|r| r.is_finite()) else {
            lin.push(None);
            continue;
        };
        let s = &c.state;
        let omega = c.eph.constants().omega_e;
        let v_inertial = s.v_e + Vector3::new(-omega * s.r_e.y, omega * s.r_e.x, 0.0);
        let k = 1.0 + row.u.dot(&v_inertial) / C;
        let h = Vector4::new(-row.u.x / k, -row.u.y / k, -row.u.z / k, 1.0);
        let y = rate - row.u.dot(&s.v_e) / k + C * s.clock_drift;
        let sigma = rate_sigma(config, c.m, row.look.elevation);
        let var = sigma * sigma;
        normal += (h / var) * h.transpose();
        b += h * (y / var);
        lin.push(Some((h, y)));
    }
    if lin.iter().flatten().count() < 4 {
        return None;
    }
    let chol = normal.cholesky()?;
    let l = chol.l_dirty();
    let (lo, hi) = (0..4).fold((f64::INFINITY, 0.0f64), |(lo, hi), i| {
        (lo.min(l[(i, i)]), hi.max(l[(i, i)]))
    });
    if (lo / hi).powi(2) <= 1e-12 {
        return None;
    }
    let sol = chol.solve(&b);
    Some(Velocity {
        v_e: sol.xyz(),
        drift: sol[3],
        cov: chol.inverse(),
        residuals: lin
            .iter()
            .map(|l| l.map(|(h, y)| y - h.dot(&sol)))
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::orbit::tests::g02_2010_07_01;

    const L1C: Signal = Signal::new(System::Gps, '1', 'C');
    const E1C: Signal = Signal::new(System::Galileo, '1', 'C');

    /// A hand-made constellation from G02's 2010-07-01 ephemeris: 6 planes 60° apart in
    /// node, 4 satellites 90° apart in each (staggered 15° from plane to plane), GPS
    /// G01–G24; and 8 "Galileo" E01–E08 on two more planes (I/NAV, BGD E1/E5b 2 ns).
    fn store() -> EphemerisStore {
        let mut s = EphemerisStore::new();
        for plane in 0..6 {
            for slot in 0..4 {
                let mut e = g02_2010_07_01();
                e.sat = Sat::new(System::Gps, (1 + plane * 4 + slot) as u8);
                e.kepler.omega0 += f64::from(plane) * 60f64.to_radians();
                e.kepler.m0 += f64::from(slot) * 90f64.to_radians() + f64::from(plane) * 0.26;
                e.af0 = 1e-5 * f64::from(slot + plane);
                s.push(e);
            }
        }
        for plane in 0..2 {
            for slot in 0..4 {
                let mut e = g02_2010_07_01();
                e.sat = Sat::new(System::Galileo, (1 + plane * 4 + slot) as u8);
                e.message = NavMessage::Inav;
                e.group_delays = [0.0, 2e-9];
                e.kepler.omega0 += 30f64.to_radians() + f64::from(plane) * 120f64.to_radians();
                e.kepler.m0 += f64::from(slot) * 90f64.to_radians() + 0.5;
                s.push(e);
            }
        }
        s
    }

    fn receiver() -> Vector3<f64> {
        Wgs84.geodetic_to_ecef(&Geodetic::from_degrees(45.0, 10.0, 250.0))
    }

    /// Exact pseudoranges (no atmosphere) of every satellite above the horizon, by the
    /// library's light-time iteration ([`Ephemeris::state_by_light_time`], tested on
    /// its own): `P = ρ + b_sys − c·(Δt_sv − T_gd)`, with the receiver clock's 1 ms
    /// (GPS) and 1 ms + 40 ns (Galileo) in the time tag and the ranges.
    fn epoch(store: &EphemerisStore, t: GpsTime) -> RawEpoch {
        let r = receiver();
        let mut measurements = Vec::new();
        for sat in store.sats() {
            let Some(eph) = store.select(sat, t) else {
                continue;
            };
            let s = eph.state_by_light_time(t, &r);
            if crate::gnss::atmosphere::look_angles(&r, &s.r_e).elevation < 0.0 {
                continue;
            }
            let (signal, band, bias) = match sat.system {
                System::Galileo => (E1C, crate::gnss::Band::E1, C * (1e-3 + 40e-9)),
                _ => (L1C, crate::gnss::Band::L1, C * 1e-3),
            };
            let tgd = eph.group_delay(band).unwrap_or(f64::NAN);
            let p = (s.r_e - r).norm() + bias - C * (s.clock_bias - tgd);
            measurements.push(RawMeasurement::code(sat, signal, p));
        }
        RawEpoch {
            t: t.add_s(1e-3),
            measurements,
        }
    }

    fn exact() -> SppConfig {
        SppConfig {
            ionosphere: false,
            troposphere: false,
            elevation_mask: 0.0,
            ..SppConfig::default()
        }
    }

    #[test]
    fn exact_pseudoranges_give_the_receiver_back() {
        let store = store();
        let t = GpsTime::new(1590, 345_600.0 + 1800.0);
        let ep = epoch(&store, t);
        let sol = solve(&ep, &store, None, &exact(), None).unwrap();
        // To the least squares' convergence (1e-4 m) and the transmission time's
        // rounding: a 1-mm bound with margin.
        assert!(
            (sol.r_e - receiver()).norm() < 1e-3,
            "{}",
            (sol.r_e - receiver()).norm()
        );
        let gps = sol.clock_of(System::Gps).unwrap();
        let gal = sol.clock_of(System::Galileo).unwrap();
        assert!((gps - C * 1e-3).abs() < 1e-3, "{gps}");
        assert!((gal - C * (1e-3 + 40e-9)).abs() < 1e-3, "{gal}");
        assert!(sol.excluded.is_empty(), "{:?}", sol.excluded);
        assert_eq!(sol.cov.shape(), (5, 5));
        assert!(sol.used.iter().all(|u| u.residual.abs() < 1e-3));
        assert!(sol.residual_test.is_some_and(|t| t.passed));
        // From a prior: fewer iterations, the same point.
        let again = solve(&ep, &store, None, &exact(), Some(receiver())).unwrap();
        assert!(again.iterations < sol.iterations);
        assert!((again.r_e - sol.r_e).norm() < 1e-3);
    }

    #[test]
    fn every_refusal_is_typed_and_reasoned() {
        let store = store();
        let t = GpsTime::new(1590, 345_600.0 + 1800.0);
        let mut ep = epoch(&store, t);
        // No ephemeris at all.
        let empty = EphemerisStore::new();
        match solve(&ep, &empty, None, &exact(), None) {
            Err(SppError::TooFewSatellites {
                have: 0, excluded, ..
            }) => {
                assert_eq!(excluded.len(), ep.sats().len());
                assert!(excluded.iter().all(|e| e.reason == Exclusion::NoEphemeris));
            }
            other => panic!("{other:?}"),
        }
        // Every satellite below an 89° mask.
        let high = SppConfig {
            elevation_mask: 89f64.to_radians(),
            ..exact()
        };
        match solve(&ep, &store, None, &high, None) {
            Err(SppError::TooFewSatellites {
                have: 0,
                need: 4,
                excluded,
            }) => {
                assert!(excluded
                    .iter()
                    .all(|e| matches!(e.reason, Exclusion::BelowMask { elevation } if elevation < 89f64.to_radians())));
            }
            other => panic!("{other:?}"),
        }
        // Three GPS satellites: four unknowns.
        let gps: Vec<_> = ep
            .sats()
            .into_iter()
            .filter(|s| s.system == System::Gps)
            .take(3)
            .collect();
        let three = RawEpoch {
            t: ep.t,
            measurements: ep
                .measurements
                .iter()
                .filter(|m| gps.contains(&m.sat))
                .cloned()
                .collect(),
        };
        assert!(matches!(
            solve(&three, &store, None, &exact(), None),
            Err(SppError::TooFewSatellites {
                have: 3,
                need: 4,
                ..
            })
        ));
        // A GLONASS satellite, a NaN pseudorange, a signal not preferred, an unhealthy
        // satellite: each excluded with its reason, the rest solved.
        let sick = ep.measurements[0].sat;
        let store2: EphemerisStore = store
            .sats()
            .flat_map(|s| store.of(s).iter().cloned())
            .map(|mut e| {
                e.health = u32::from(e.sat == sick);
                e
            })
            .collect();
        ep.measurements[1].pseudorange = Some(f64::NAN);
        ep.measurements[2].signal = Signal::new(System::Gps, '2', 'W');
        let r01 = Sat::new(System::Glonass, 1);
        ep.measurements.push(RawMeasurement::code(
            r01,
            Signal::new(System::Glonass, '1', 'C'),
            2e7,
        ));
        let sol = solve(&ep, &store2, None, &exact(), None).unwrap();
        let reason = |sat| sol.excluded.iter().find(|e| e.sat == sat).map(|e| e.reason);
        assert_eq!(reason(sick), Some(Exclusion::Unhealthy));
        assert_eq!(
            reason(ep.measurements[1].sat),
            Some(Exclusion::InvalidMeasurement)
        );
        assert_eq!(reason(ep.measurements[2].sat), Some(Exclusion::NoSignal));
        assert_eq!(reason(r01), Some(Exclusion::SystemNotUsed));
        assert!((sol.r_e - receiver()).norm() < 1e-3);
    }

    #[test]
    fn bad_settings_are_refused() {
        let store = store();
        let ep = epoch(&store, GpsTime::new(1590, 347_400.0));
        for cfg in [
            SppConfig {
                elevation_mask: 2.0,
                ..exact()
            },
            SppConfig {
                weighting: Weighting::Elevation { a: 0.0, b: 0.0 },
                ..exact()
            },
            SppConfig {
                doppler_sigma: f64::NAN,
                ..exact()
            },
            SppConfig {
                fde: Some(FdeConfig {
                    false_alarm: 0.0,
                    max_exclusions: 1,
                }),
                ..exact()
            },
        ] {
            assert!(matches!(
                solve(&ep, &store, None, &cfg, None),
                Err(SppError::InvalidConfig(_))
            ));
        }
    }

    #[test]
    fn weights_by_elevation_and_cn0() {
        let w = Weighting::default();
        // At the zenith a² + b² = 0.18 m²; at 30° a² + 4b² = 0.45 m².
        assert!((w.sigma(std::f64::consts::FRAC_PI_2, None) - 0.18f64.sqrt()).abs() < 1e-12);
        assert!((w.sigma(30f64.to_radians(), Some(20.0)) - 0.45f64.sqrt()).abs() < 1e-12);
        let c = Weighting::CN0_DEFAULT;
        assert!((c.sigma(0.1, Some(45.0)) - 0.45f64.sqrt()).abs() < 1e-3);
        // 10 dB less C/N0, ten times the variance's C/N0 part.
        let s35 = c.sigma(0.1, Some(35.0));
        assert!((s35 * s35 - 0.09 - 10.0 * 0.36).abs() < 1e-2);
        assert_eq!(
            c.sigma(30f64.to_radians(), None),
            w.sigma(30f64.to_radians(), None)
        );
    }
}
