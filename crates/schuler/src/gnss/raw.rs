//! Raw GNSS measurements of one receiver epoch, as every raw source converts them: RINEX
//! observations, u-blox RXM-RAWX, Android GnssLogger (`Raw` rows).
//!
//! A measurement is one satellite's one signal: pseudorange [m], Doppler [Hz], carrier
//! phase [cycles], C/N0 [dB-Hz], each optional (a RINEX row may lack any of them; UBX
//! flags a pseudorange or a phase invalid; Android leaves the phase state unset), the
//! phase's lock state, and the standard deviations a source reports (UBX `prStdev`,
//! `doStdev`, `cpStdev`; Android's uncertainties). The signal is named by its RINEX 3
//! band digit and tracking-mode letter (RINEX 3.05 §5.1, Tables 4–10: `1C` is GPS L1
//! C/A, `2I` BeiDou B1I), which UBX's `sigId` and Android's constellation with carrier
//! frequency and code type both map onto.
//!
//! Sign of the Doppler: positive for an approaching satellite (RINEX 3.05 §5.2.13, UBX,
//! Android), so the pseudorange rate it means is `ρ̇ = −λ·D`, λ = c/f.

use super::ephemeris::{Band, C};
use super::sat::{Sat, System};
use super::time::GpsTime;

/// One signal of a satellite system: RINEX 3's band digit and tracking-mode (attribute)
/// letter, `1C` for GPS L1 C/A.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Signal {
    /// The constellation whose signal plan the band digit belongs to.
    pub system: System,
    /// RINEX 3 band digit (`'1'`, `'2'`, `'5'`, `'6'`, `'7'`, `'8'`, `'9'`).
    pub band: char,
    /// RINEX 3 tracking mode / channel letter (`'C'`, `'I'`, `'X'`, …).
    pub attribute: char,
}

/// GLONASS FDMA: G1 = 1602 MHz + k·562.5 kHz, G2 = 1246 MHz + k·437.5 kHz (GLONASS ICD
/// 5.1 §3.3.1.4), k the frequency channel −7…+6.
const GLONASS_G1: (f64, f64) = (1_602.0e6, 562.5e3);
/// See [`GLONASS_G1`].
const GLONASS_G2: (f64, f64) = (1_246.0e6, 437.5e3);

impl Signal {
    /// The signal `band` digit, `attribute` letter of `system`.
    pub const fn new(system: System, band: char, attribute: char) -> Self {
        Self {
            system,
            band,
            attribute,
        }
    }

    /// The signal of a RINEX 3 observation code of any type (`C1C`, `L2W`, `D5Q`) or of
    /// its two last characters (`1C`); `None` when it has no band digit and letter.
    pub fn from_rinex(system: System, code: &str) -> Option<Self> {
        let b = code.as_bytes();
        let (band, attribute) = match b.len() {
            2 => (b[0], b[1]),
            3 => (b[1], b[2]),
            _ => return None,
        };
        (band.is_ascii_digit() && attribute.is_ascii_alphabetic())
            .then(|| Self::new(system, band as char, attribute as char))
    }

    /// The two-character RINEX 3 form, `1C`.
    pub fn rinex(&self) -> String {
        format!("{}{}", self.band, self.attribute)
    }

    /// The carrier frequency [Hz] (RINEX 3.05 Table A1 and the ICDs); GLONASS G1/G2
    /// need the satellite's FDMA channel `glonass_channel` (−7…+6). `None` for a band
    /// the system does not transmit, or a GLONASS FDMA band without its channel.
    pub fn frequency(&self, glonass_channel: Option<i8>) -> Option<f64> {
        use System::*;
        let mhz = |f: f64| Some(f * 1e6);
        match (self.system, self.band) {
            (Gps | Qzss | Sbas, '1') | (Galileo, '1') | (BeiDou, '1') => mhz(1_575.42),
            (Gps | Qzss, '2') => mhz(1_227.60),
            (Gps | Qzss | Sbas | Galileo | BeiDou | Navic, '5') => mhz(1_176.45),
            (Qzss | Galileo, '6') => mhz(1_278.75),
            (Galileo | BeiDou, '7') => mhz(1_207.14),
            (Galileo | BeiDou, '8') => mhz(1_191.795),
            (BeiDou, '2') => mhz(1_561.098),
            (BeiDou, '6') => mhz(1_268.52),
            (Navic, '9') => mhz(2_492.028),
            (Glonass, '1') => glonass_channel.map(|k| GLONASS_G1.0 + f64::from(k) * GLONASS_G1.1),
            (Glonass, '2') => glonass_channel.map(|k| GLONASS_G2.0 + f64::from(k) * GLONASS_G2.1),
            (Glonass, '3') => mhz(1_202.025),
            (Glonass, '4') => mhz(1_600.995),
            (Glonass, '6') => mhz(1_248.06),
            _ => None,
        }
    }

    /// The broadcast group-delay band whose correction this signal's code takes
    /// ([`crate::gnss::Ephemeris::group_delay`]): GPS/QZSS L1 and L2, Galileo E1, E5a,
    /// E5b, BeiDou B1I (`2x`), B2I (`7I/7Q/7X`; `7D/7P/7Z` is B2b) and B3I (`6I/6Q/6X`).
    /// `None` for a signal whose delay the legacy messages do not give (L5, B1C, …).
    pub fn group_delay_band(&self) -> Option<Band> {
        use System::*;
        let iqx = matches!(self.attribute, 'I' | 'Q' | 'X');
        match (self.system, self.band) {
            (Gps | Qzss, '1') => Some(Band::L1),
            (Gps | Qzss, '2') => Some(Band::L2),
            (Galileo, '1') => Some(Band::E1),
            (Galileo, '5') => Some(Band::E5a),
            (Galileo, '7') => Some(Band::E5b),
            (BeiDou, '2') if iqx => Some(Band::B1I),
            (BeiDou, '7') if iqx => Some(Band::B2I),
            (BeiDou, '6') if iqx => Some(Band::B3I),
            _ => None,
        }
    }
}

/// The carrier phase's tracking state, as the sources give it (RINEX LLI bits 0 and 1;
/// UBX `trkStat` and `locktime`; Android `AccumulatedDeltaRangeState`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PhaseLock {
    /// Lock lost (a possible cycle slip) since the previous epoch (RINEX LLI bit 0,
    /// Android `ADR_STATE_CYCLE_SLIP`/`RESET`, UBX a locktime that restarted).
    pub slip: bool,
    /// A half-cycle ambiguity not (yet) resolved (RINEX LLI bit 1, UBX `halfCyc` clear,
    /// Android `HALF_CYCLE_RESOLVED` clear).
    pub half_cycle: bool,
    /// How long the phase has been tracked without a slip [ms], when the source says
    /// (UBX `locktime`).
    pub lock_time_ms: Option<u32>,
}

/// One satellite's one signal at one epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct RawMeasurement {
    /// The satellite.
    pub sat: Sat,
    /// The signal tracked.
    pub signal: Signal,
    /// GLONASS FDMA frequency channel (−7…+6); `None` for CDMA signals.
    pub glonass_channel: Option<i8>,
    /// Pseudorange [m].
    pub pseudorange: Option<f64>,
    /// Doppler [Hz], positive when the satellite approaches.
    pub doppler: Option<f64>,
    /// Carrier phase [cycles].
    pub carrier_phase: Option<f64>,
    /// Carrier-to-noise density C/N0 [dB-Hz].
    pub cn0: Option<f64>,
    /// The phase's lock state, when the source gives one.
    pub lock: Option<PhaseLock>,
    /// Standard deviation of the pseudorange [m], when the source gives one (UBX).
    pub pseudorange_std: Option<f64>,
    /// Standard deviation of the Doppler [Hz], when the source gives one (UBX).
    pub doppler_std: Option<f64>,
    /// Standard deviation of the carrier phase [cycles], when the source gives one.
    pub carrier_phase_std: Option<f64>,
}

impl RawMeasurement {
    /// A measurement of `signal` from `sat` carrying only a pseudorange [m]; the other
    /// fields are `None`, to be filled by name.
    pub fn code(sat: Sat, signal: Signal, pseudorange: f64) -> Self {
        Self {
            sat,
            signal,
            glonass_channel: None,
            pseudorange: Some(pseudorange),
            doppler: None,
            carrier_phase: None,
            cn0: None,
            lock: None,
            pseudorange_std: None,
            doppler_std: None,
            carrier_phase_std: None,
        }
    }

    /// The carrier frequency [Hz] ([`Signal::frequency`] with this satellite's channel).
    pub fn frequency(&self) -> Option<f64> {
        self.signal.frequency(self.glonass_channel)
    }

    /// The carrier wavelength λ = c/f [m].
    pub fn wavelength(&self) -> Option<f64> {
        self.frequency().map(|f| C / f)
    }

    /// The pseudorange rate the Doppler means, `ρ̇ = −λ·D` [m/s].
    pub fn pseudorange_rate(&self) -> Option<f64> {
        Some(-self.wavelength()? * self.doppler?)
    }

    /// The standard deviation of [`RawMeasurement::pseudorange_rate`], `λ·σ_D` [m/s],
    /// when the source gives σ_D.
    pub fn pseudorange_rate_std(&self) -> Option<f64> {
        Some(self.wavelength()? * self.doppler_std?)
    }
}

/// The measurements of one receiver epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct RawEpoch {
    /// The receive time by the receiver's clock, in GPS time's week and second (the
    /// clock's error is one of the unknowns of a solution).
    pub t: GpsTime,
    /// Every measurement of the epoch, any order; at most one per satellite and signal.
    pub measurements: Vec<RawMeasurement>,
}

impl RawEpoch {
    /// The measurement of `sat` on `signal`, if any.
    pub fn get(&self, sat: Sat, signal: Signal) -> Option<&RawMeasurement> {
        self.measurements
            .iter()
            .find(|m| m.sat == sat && m.signal == signal)
    }

    /// The satellites measured, each once, in order.
    pub fn sats(&self) -> Vec<Sat> {
        let mut s: Vec<Sat> = self.measurements.iter().map(|m| m.sat).collect();
        s.sort_unstable();
        s.dedup();
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frequencies_of_the_common_signals() {
        let f = |sys, code: &str| Signal::from_rinex(sys, code).unwrap().frequency(None);
        assert_eq!(f(System::Gps, "C1C"), Some(1_575.42e6));
        assert_eq!(f(System::Gps, "L2W"), Some(1_227.60e6));
        assert_eq!(f(System::Galileo, "C7Q"), Some(1_207.14e6));
        assert_eq!(f(System::BeiDou, "C2I"), Some(1_561.098e6));
        assert_eq!(f(System::BeiDou, "C6I"), Some(1_268.52e6));
        assert_eq!(f(System::Gps, "C7Q"), None);
        // GLONASS FDMA: channel −7 on G1 is 1598.0625 MHz, +6 on G2 1248.625 MHz.
        let g1 = Signal::new(System::Glonass, '1', 'C');
        assert_eq!(g1.frequency(None), None);
        assert_eq!(g1.frequency(Some(-7)), Some(1_598.062_5e6));
        let g2 = Signal::new(System::Glonass, '2', 'C');
        assert_eq!(g2.frequency(Some(6)), Some(1_248.625e6));
        assert_eq!(Signal::from_rinex(System::Gps, "C1"), None);
        assert_eq!(Signal::from_rinex(System::Gps, "1C").unwrap().rinex(), "1C");
    }

    #[test]
    fn group_delay_bands() {
        let b = |sys, code: &str| Signal::from_rinex(sys, code).unwrap().group_delay_band();
        assert_eq!(b(System::Gps, "C1C"), Some(Band::L1));
        assert_eq!(b(System::Qzss, "C2L"), Some(Band::L2));
        assert_eq!(b(System::Gps, "C5Q"), None);
        assert_eq!(b(System::Galileo, "C1X"), Some(Band::E1));
        assert_eq!(b(System::BeiDou, "C2I"), Some(Band::B1I));
        assert_eq!(b(System::BeiDou, "C7D"), None); // B2b
        assert_eq!(b(System::BeiDou, "C1X"), None); // B1C
    }

    #[test]
    fn doppler_means_minus_lambda_d() {
        let sat = Sat::new(System::Gps, 5);
        let mut m = RawMeasurement::code(sat, Signal::new(System::Gps, '1', 'C'), 2.2e7);
        assert_eq!(m.pseudorange_rate(), None);
        m.doppler = Some(1000.0);
        m.doppler_std = Some(0.1);
        // An approaching satellite (D > 0): the range shrinks at λ·1000 Hz ≈ 190 m/s.
        let lambda = C / 1_575.42e6;
        assert_eq!(m.pseudorange_rate(), Some(-lambda * 1000.0));
        assert_eq!(m.pseudorange_rate_std(), Some(lambda * 0.1));
    }
}
