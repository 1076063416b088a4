//! One `Raw` row of a GnssLogger file as a [`RawMeasurement`]: Android's
//! `GnssClock`/`GnssMeasurement` fields turned into pseudorange, Doppler, carrier
//! phase, C/N0 and their standard deviations, as Android's reference
//! (`android.location.GnssMeasurement`, `GnssClock`) and Google's white paper "Using
//! GNSS raw measurements on Android devices" (GSA, 2017, §2.4) define them.
//!
//! - Receive time in GNSS time: `t_Rx = TimeNanos + TimeOffsetNanos − (FullBiasNanos +
//!   BiasNanos)` [ns since the GPS epoch], each epoch with its own bias (as Google's
//!   derived data of the Smartphone Decimeter Challenge do), so the epoch's time tag is
//!   the receiver's own estimate of GPS time. The integer parts are kept in `i64`
//!   nanoseconds and only the fractional `TimeOffsetNanos − BiasNanos` in `f64`.
//! - `ReceivedSvTimeNanos` is the transmit time in the satellite's scale: GPS, QZSS,
//!   Galileo and NavIC time of week (GPST's week, to which GST and NavIC are aligned);
//!   BeiDou time of week in BDT = GPST − 14 s; GLONASS time of day in GLONASS time =
//!   UTC + 3 h (so `t_Rx` becomes `t_Rx − (GPS−UTC) + 3 h` modulo a day). The
//!   pseudorange is `c·(t_Rx − t_Tx)` with the week's (day's) rollover between the two
//!   undone.
//! - Valid only with a code lock (`CODE_LOCK`, Galileo `GAL_E1BC_CODE_LOCK` or
//!   `2ND_CODE_LOCK`), the time known (`TOW_DECODED` or `TOW_KNOWN`; GLONASS
//!   `GLO_TOD_DECODED` or `GLO_TOD_KNOWN`) and no millisecond ambiguity
//!   (`MSEC_AMBIGUOUS` clear); anything else is skipped and counted.
//! - Doppler `D = −ṗ·f/c` from `PseudorangeRateMetersPerSecond` ṗ (positive when the
//!   satellite recedes) and the carrier frequency `f`: positive when approaching, as
//!   [`RawMeasurement::doppler`] is.
//! - Carrier phase `AccumulatedDeltaRangeMeters / λ` [cycles] when `ADR_STATE_VALID`;
//!   a slip when `RESET` or `CYCLE_SLIP` is set (or the clock had a discontinuity, see
//!   the reader); a half-cycle ambiguity while `HALF_CYCLE_RESOLVED` is clear.
//! - `ReceivedSvTimeUncertaintyNanos·c` is the pseudorange's σ; the rate's and
//!   ADR's uncertainties over λ are the Doppler's and phase's.
//! - The signal: band from `CarrierFrequencyHz` (within 100 kHz of the nominal
//!   carrier; GLONASS's FDMA channel `k = (f − 1602 MHz)/562.5 kHz`), attribute letter
//!   from `CodeType` (Android gives RINEX's letters), else a default per system and
//!   band ([`default_attribute`]); a log without the frequency (GnssLogger before
//!   Android O) is L1/E1/B1I/G1.
//! - Satellite numbers: Android's `Svid` is the PRN except QZSS (193–202 → J01–J10)
//!   and GLONASS, whose slot (1–24) is used; a GLONASS satellite known only by its
//!   channel (`Svid` 93–106) and SBAS are skipped and counted.

use schuler::gnss::{C, GpsTime, PhaseLock, RawMeasurement, Sat, Signal, System};

/// Nanoseconds in a GPS week.
pub(super) const WEEK_NS: i64 = 604_800_000_000_000;
/// Nanoseconds in a day.
const DAY_NS: i64 = 86_400_000_000_000;
/// GPST − BDT [ns] (BDS-SIS-ICD §5.2).
const BDT_NS: i64 = 14_000_000_000;
/// GLONASS time − UTC [ns] (Moscow time, GLONASS ICD §3.3.3).
const GLONASS_UTC_NS: i64 = 3 * 3_600_000_000_000;

// GnssMeasurement state bits (android.location.GnssMeasurement.STATE_*).
const CODE_LOCK: u32 = 1;
const TOW_DECODED: u32 = 1 << 3;
const MSEC_AMBIGUOUS: u32 = 1 << 4;
const GLO_TOD_DECODED: u32 = 1 << 7;
const GAL_E1BC_CODE_LOCK: u32 = 1 << 10;
const TOW_KNOWN: u32 = 1 << 14;
const GLO_TOD_KNOWN: u32 = 1 << 15;
const SECOND_CODE_LOCK: u32 = 1 << 16;

// AccumulatedDeltaRangeState bits (ADR_STATE_*).
const ADR_VALID: u32 = 1;
const ADR_RESET: u32 = 1 << 1;
const ADR_CYCLE_SLIP: u32 = 1 << 2;
const ADR_HALF_CYCLE_RESOLVED: u32 = 1 << 3;

/// Uncertainties at or above this are Android's "unknown" (it writes `Float.MAX_VALUE`).
const UNKNOWN_UNCERTAINTY: f64 = 1e30;

/// A `Raw` row's values, parsed (optional columns `None` when empty or absent).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct RawRow {
    pub time_nanos: i64,
    pub full_bias_nanos: i64,
    pub bias_nanos: f64,
    pub time_offset_nanos: f64,
    pub leap_second: Option<i64>,
    pub discontinuity: Option<i64>,
    pub svid: i64,
    pub constellation: i64,
    pub state: u32,
    pub received_sv_time_nanos: i64,
    pub received_sv_time_uncertainty_nanos: f64,
    pub cn0: f64,
    pub pseudorange_rate: f64,
    pub pseudorange_rate_uncertainty: f64,
    pub adr_state: u32,
    pub adr: f64,
    pub adr_uncertainty: Option<f64>,
    pub carrier_frequency: Option<f64>,
    pub code_type: Option<char>,
    pub chipset_elapsed_realtime_nanos: Option<i64>,
}

/// Why a row gives no measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Skip {
    /// No code lock, time not known, or a millisecond ambiguity.
    State,
    /// SBAS, an unknown constellation, or a GLONASS satellite without its slot.
    Satellite,
    /// A carrier frequency no band of the system has.
    Frequency,
    /// A pseudorange outside (0, 100 000 km): a receiver clock not yet set.
    Implausible,
}

impl RawRow {
    /// `TimeNanos − FullBiasNanos` [ns]: the integer part of GPS time by the receiver.
    pub fn gps_ns_int(&self) -> i64 {
        self.time_nanos.saturating_sub(self.full_bias_nanos)
    }

    /// The receive time of the epoch (GPS time by the receiver's corrected clock,
    /// without the measurement's own `TimeOffsetNanos`).
    pub fn receive_time(&self) -> GpsTime {
        let int = self.gps_ns_int();
        let week = int.div_euclid(WEEK_NS);
        let ns = int.rem_euclid(WEEK_NS);
        GpsTime::new(week, ns as f64 * 1e-9 - self.bias_nanos * 1e-9)
    }
}

/// The system and satellite of Android's `ConstellationType` and `Svid`.
fn satellite(constellation: i64, svid: i64) -> Option<Sat> {
    let (system, prn) = match constellation {
        1 => (System::Gps, svid),
        3 if (1..=24).contains(&svid) => (System::Glonass, svid),
        4 if (193..=202).contains(&svid) => (System::Qzss, svid - 192),
        5 => (System::BeiDou, svid),
        6 => (System::Galileo, svid),
        7 => (System::Navic, svid),
        _ => return None,
    };
    let prn = u8::try_from(prn).ok().filter(|p| (1..=99).contains(p))?;
    Some(Sat::new(system, prn))
}

/// The RINEX band digit of carrier frequency `f` [Hz] in `system`, with GLONASS's
/// FDMA channel (see the module's doc).
fn band(system: System, f: f64) -> Option<(char, Option<i8>)> {
    const TOL: f64 = 1e5;
    if system == System::Glonass {
        for (b, (base, step)) in [('1', (1_602.0e6, 562.5e3)), ('2', (1_246.0e6, 437.5e3))] {
            let k = ((f - base) / step).round();
            if (-7.0..=6.0).contains(&k) && (f - base - k * step).abs() < TOL {
                return Some((b, Some(k as i8)));
            }
        }
    }
    ['1', '2', '5', '6', '7', '8', '9']
        .into_iter()
        .find(|&b| {
            Signal::new(system, b, 'C')
                .frequency(None)
                .is_some_and(|nominal| (f - nominal).abs() < TOL)
        })
        .map(|b| (b, None))
}

/// The tracking-mode letter assumed when the log has no `CodeType` (Android before
/// 11): the signals phones track — GPS/QZSS L1 C/A and L5Q, Galileo E1C and E5aQ,
/// BeiDou B1I and B2aP, GLONASS C/A, NavIC L5 SPS (`A`).
fn default_attribute(system: System, band: char) -> char {
    match (system, band) {
        (System::BeiDou, '2' | '7' | '6') => 'I',
        (System::BeiDou, _) => 'P',
        (System::Navic, _) => 'A',
        (_, '5' | '7') => 'Q',
        _ => 'C',
    }
}

/// The signal, channel and carrier frequency of a row.
fn signal(row: &RawRow, system: System) -> Result<(Signal, Option<i8>, Option<f64>), Skip> {
    let (b, k) = match row.carrier_frequency {
        Some(f) => band(system, f).ok_or(Skip::Frequency)?,
        None => match system {
            System::BeiDou => ('2', None),
            _ => ('1', None),
        },
    };
    let attr = row
        .code_type
        .unwrap_or_else(|| default_attribute(system, b));
    let s = Signal::new(system, b, attr);
    let f = s.frequency(k);
    Ok((s, k, f))
}

/// Whether the row's state gives an unambiguous transmit time (see the module's doc).
fn state_valid(system: System, state: u32) -> bool {
    let locked = state & (CODE_LOCK | GAL_E1BC_CODE_LOCK | SECOND_CODE_LOCK) != 0;
    let time = if system == System::Glonass {
        GLO_TOD_DECODED | GLO_TOD_KNOWN
    } else {
        TOW_DECODED | TOW_KNOWN
    };
    locked && state & time != 0 && state & MSEC_AMBIGUOUS == 0
}

/// The pseudorange [m] of `row` in `system`; `leap_s` is GPS − UTC (GLONASS only).
fn pseudorange(row: &RawRow, system: System, leap_s: i64) -> f64 {
    let int = row.gps_ns_int();
    let (rx, period) = match system {
        System::BeiDou => ((int - BDT_NS).rem_euclid(WEEK_NS), WEEK_NS),
        System::Glonass => (
            (int - leap_s * 1_000_000_000 + GLONASS_UTC_NS).rem_euclid(DAY_NS),
            DAY_NS,
        ),
        _ => (int.rem_euclid(WEEK_NS), WEEK_NS),
    };
    let mut d = (rx - row.received_sv_time_nanos).rem_euclid(period);
    if d > period / 2 {
        d -= period;
    }
    (d as f64 + (row.time_offset_nanos - row.bias_nanos)) * 1e-9 * C
}

/// The measurement of one `Raw` row (see the module's doc); `leap_s` is GPS − UTC
/// [s] at the epoch, `discontinuity` whether the receiver's clock broke since the
/// previous epoch (every phase then slips).
pub(super) fn measurement(
    row: &RawRow,
    leap_s: i64,
    discontinuity: bool,
) -> Result<RawMeasurement, Skip> {
    let sat = satellite(row.constellation, row.svid).ok_or(Skip::Satellite)?;
    if !state_valid(sat.system, row.state) {
        return Err(Skip::State);
    }
    let (signal, channel, freq) = signal(row, sat.system)?;
    let pr = pseudorange(row, sat.system, leap_s);
    if !(pr > 0.0 && pr < 1e8) {
        return Err(Skip::Implausible);
    }
    let known = |u: f64| (0.0..UNKNOWN_UNCERTAINTY).contains(&u).then_some(u);
    let mut m = RawMeasurement::code(sat, signal, pr);
    m.glonass_channel = channel;
    m.cn0 = Some(row.cn0);
    m.pseudorange_std = known(row.received_sv_time_uncertainty_nanos).map(|u| u * 1e-9 * C);
    if let Some(f) = freq {
        let per_m = f / C;
        m.doppler = Some(-row.pseudorange_rate * per_m);
        m.doppler_std = known(row.pseudorange_rate_uncertainty).map(|u| u * per_m);
        if row.adr_state & ADR_VALID != 0 {
            m.carrier_phase = Some(row.adr * per_m);
            m.carrier_phase_std = row.adr_uncertainty.and_then(known).map(|u| u * per_m);
            m.lock = Some(PhaseLock {
                slip: discontinuity || row.adr_state & (ADR_RESET | ADR_CYCLE_SLIP) != 0,
                half_cycle: row.adr_state & ADR_HALF_CYCLE_RESOLVED == 0,
                lock_time_ms: None,
            });
        }
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A GPS L1 row of the gps-measurement-tools demo log (2016-06-30, PRN 2).
    fn row() -> RawRow {
        RawRow {
            time_nanos: 72_076_939_000_000,
            full_bias_nanos: -1_151_285_108_458_178_048,
            bias_nanos: 0.0,
            time_offset_nanos: 0.0,
            leap_second: None,
            discontinuity: Some(188),
            svid: 2,
            constellation: 1,
            state: 15,
            received_sv_time_nanos: 422_785_326_362_991,
            received_sv_time_uncertainty_nanos: 13.0,
            cn0: 31.6,
            pseudorange_rate: -384.095_031_738_281_25,
            pseudorange_rate_uncertainty: 0.0342,
            adr_state: 0,
            adr: 0.0,
            adr_uncertainty: None,
            carrier_frequency: None,
            code_type: None,
            chipset_elapsed_realtime_nanos: None,
        }
    }

    #[test]
    fn gps_pseudorange_by_hand() {
        // t_Rx = 72076939000000 + 1151285108458178048 = 1151357185397178048 ns; minus
        // 1903 weeks: 422785397178048 ns of week; minus t_Tx 422785326362991 ns =
        // 70815057 ns, times c.
        let m = measurement(&row(), 17, false).unwrap();
        assert_eq!(m.sat, Sat::new(System::Gps, 2));
        assert_eq!(m.signal, Signal::new(System::Gps, '1', 'C'));
        let expected = 70_815_057e-9 * C;
        assert!((m.pseudorange.unwrap() - expected).abs() < 1e-6);
        // Receding at −384 m/s is approaching: a positive Doppler of 384/λ Hz.
        let lambda = C / 1_575.42e6;
        assert!((m.doppler.unwrap() - 384.095_031_738_281_25 / lambda).abs() < 1e-9);
        assert!((m.pseudorange_std.unwrap() - 13e-9 * C).abs() < 1e-9);
        assert_eq!(m.carrier_phase, None);
        let t = row().receive_time();
        assert_eq!(t.week, 1903);
        assert!((t.sow - 422_785.397_178_048).abs() < 1e-9);
    }

    #[test]
    fn the_week_rollover_between_transmission_and_reception_is_undone() {
        let mut r = row();
        // Received 20 ms after the week began, sent 70 ms earlier in the last week.
        r.full_bias_nanos = -(1904 * WEEK_NS + 20_000_000) + r.time_nanos;
        r.received_sv_time_nanos = WEEK_NS - 50_000_000;
        let m = measurement(&r, 17, false).unwrap();
        assert!((m.pseudorange.unwrap() - 0.07 * C).abs() < 1e-6);
    }

    #[test]
    fn beidou_and_glonass_time_scales() {
        let mut r = row();
        let rx = r.gps_ns_int().rem_euclid(WEEK_NS);
        // BeiDou sends BDT (GPST − 14 s): a 75 ms path.
        r.constellation = 5;
        r.svid = 30;
        r.carrier_frequency = Some(1_561.098e6);
        r.received_sv_time_nanos = rx - BDT_NS - 75_000_000;
        let m = measurement(&r, 17, false).unwrap();
        assert_eq!(m.signal, Signal::new(System::BeiDou, '2', 'I'));
        assert!((m.pseudorange.unwrap() - 0.075 * C).abs() < 1e-6);
        // GLONASS sends UTC + 3 h of day: with 17 leap seconds, a 68 ms path.
        r.constellation = 3;
        r.svid = 5;
        r.state = CODE_LOCK | GLO_TOD_DECODED;
        r.carrier_frequency = Some(1_602.0e6 - 3.0 * 562.5e3);
        let tod = (r.gps_ns_int() - 17_000_000_000 + GLONASS_UTC_NS).rem_euclid(DAY_NS);
        r.received_sv_time_nanos = tod - 68_000_000;
        let m = measurement(&r, 17, false).unwrap();
        assert_eq!(m.glonass_channel, Some(-3));
        assert!((m.pseudorange.unwrap() - 0.068 * C).abs() < 1e-6);
        // A GLONASS satellite known by its channel only is skipped.
        r.svid = 97;
        assert_eq!(measurement(&r, 17, false), Err(Skip::Satellite));
    }

    #[test]
    fn invalid_states_are_skipped() {
        let mut r = row();
        r.state = TOW_KNOWN; // no code lock (a phone's L5 before it locks)
        assert_eq!(measurement(&r, 17, false), Err(Skip::State));
        r.state = CODE_LOCK; // code but no time of week
        assert_eq!(measurement(&r, 17, false), Err(Skip::State));
        r.state = CODE_LOCK | TOW_DECODED | MSEC_AMBIGUOUS;
        assert_eq!(measurement(&r, 17, false), Err(Skip::State));
        r.state = GAL_E1BC_CODE_LOCK | TOW_KNOWN;
        r.constellation = 6;
        assert!(measurement(&r, 17, false).is_ok());
        r.carrier_frequency = Some(1_600.0e6); // no Galileo band
        assert_eq!(measurement(&r, 17, false), Err(Skip::Frequency));
    }

    #[test]
    fn phase_in_cycles_with_its_lock_state() {
        let mut r = row();
        r.carrier_frequency = Some(1_176.45e6);
        r.code_type = Some('Q');
        r.adr_state = ADR_VALID | ADR_CYCLE_SLIP;
        r.adr = 1000.0;
        r.adr_uncertainty = Some(3.4e38);
        let m = measurement(&r, 17, false).unwrap();
        assert_eq!(m.signal, Signal::new(System::Gps, '5', 'Q'));
        let lambda = C / 1_176.45e6;
        assert!((m.carrier_phase.unwrap() - 1000.0 / lambda).abs() < 1e-9);
        assert_eq!(m.carrier_phase_std, None);
        let lock = m.lock.unwrap();
        assert!(lock.slip && lock.half_cycle);
        r.adr_state = ADR_VALID | ADR_HALF_CYCLE_RESOLVED;
        let lock = measurement(&r, 17, false).unwrap().lock.unwrap();
        assert!(!lock.slip && !lock.half_cycle);
        let lock = measurement(&r, 17, true).unwrap().lock.unwrap();
        assert!(lock.slip, "a clock discontinuity breaks every phase");
    }
}
