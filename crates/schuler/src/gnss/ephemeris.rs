//! Keplerian broadcast ephemerides: GPS and QZSS LNAV (IS-GPS-200N §20.3.3.4, IS-QZSS-PNT
//! §5.2), Galileo I/NAV and F/NAV (Galileo OS SIS ICD 2.1 §5.1.1–5.1.5), BeiDou D1 and D2
//! (BDS-SIS-ICD-B1I 3.0 §5.2.4). The four share one parameter set (Kepler elements with
//! harmonic corrections, a clock polynomial); they differ in their constants, their
//! group-delay parameters, their health bits and, for BeiDou's geostationary
//! satellites, the frame rotation ([`crate::gnss::orbit`]).
//!
//! Units are SI: metres, seconds, radians (RINEX already writes radians and rad/s).

use super::sat::{Sat, System};
use super::time::GpsTime;

/// The speed of light in vacuum [m/s] (IS-GPS-200 §20.3.4.3, every ICD).
pub const C: f64 = 299_792_458.0;
/// π as the ICDs fix it for the orbit computation (IS-GPS-200 §20.3.3.4.3.3), 5e-15
/// below the f64 nearest π: kept to convert semicircles exactly as receivers do.
#[allow(clippy::approx_constant)]
pub const ICD_PI: f64 = 3.141_592_653_589_8;

/// A system's constants for its broadcast orbit and clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SystemConstants {
    /// Earth's gravitational constant μ [m³/s²].
    pub mu: f64,
    /// Earth's rotation rate Ω̇e [rad/s].
    pub omega_e: f64,
}

impl SystemConstants {
    /// GPS and QZSS (WGS 84 as IS-GPS-200 Table 20-IV fixes it; IS-QZSS-PNT Table 5.2-x
    /// takes the same values).
    pub const GPS: Self = Self {
        mu: 3.986_005e14,
        omega_e: 7.292_115_146_7e-5,
    };
    /// Galileo (OS SIS ICD Table 59: GTRF's μ with GPS's rotation rate).
    pub const GALILEO: Self = Self {
        mu: 3.986_004_418e14,
        omega_e: 7.292_115_146_7e-5,
    };
    /// BeiDou (CGCS2000, BDS-SIS-ICD §5.2.4.12 Table 5-11).
    pub const BEIDOU: Self = Self {
        mu: 3.986_004_418e14,
        omega_e: 7.292_115e-5,
    };

    /// The constants of `system`'s Keplerian ephemeris (`None` for the systems that
    /// broadcast none: GLONASS, SBAS; NavIC takes GPS's).
    pub fn of(system: System) -> Option<Self> {
        match system {
            System::Gps | System::Qzss | System::Navic => Some(Self::GPS),
            System::Galileo => Some(Self::GALILEO),
            System::BeiDou => Some(Self::BEIDOU),
            System::Glonass | System::Sbas => None,
        }
    }

    /// The relativistic clock coefficient F = −2√μ / c² [s/√m] (IS-GPS-200
    /// §20.3.3.3.3.1: −4.442807633e-10 for GPS).
    pub fn f_rel(&self) -> f64 {
        -2.0 * self.mu.sqrt() / (C * C)
    }
}

/// Which navigation message an ephemeris came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum NavMessage {
    /// GPS or QZSS legacy navigation message (L1 C/A).
    Lnav,
    /// Galileo I/NAV (E1-B, E5b-I): clock for the E1/E5b combination.
    Inav,
    /// Galileo F/NAV (E5a-I): clock for the E1/E5a combination.
    Fnav,
    /// BeiDou D1 (MEO and IGSO satellites, B1I/B3I).
    D1,
    /// BeiDou D2 (GEO satellites).
    D2,
}

/// A frequency band whose code a single-frequency user corrects with the broadcast
/// group delays ([`Ephemeris::group_delay`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Band {
    /// GPS/QZSS L1 (1575.42 MHz).
    L1,
    /// GPS/QZSS L2 (1227.60 MHz).
    L2,
    /// Galileo E1 (1575.42 MHz).
    E1,
    /// Galileo E5a (1176.45 MHz).
    E5a,
    /// Galileo E5b (1207.14 MHz).
    E5b,
    /// BeiDou B1I (1561.098 MHz).
    B1I,
    /// BeiDou B2I (1207.14 MHz).
    B2I,
    /// BeiDou B3I (1268.52 MHz).
    B3I,
}

impl Band {
    /// The carrier frequency [Hz].
    pub fn frequency(self) -> f64 {
        match self {
            Band::L1 | Band::E1 => 1_575.42e6,
            Band::L2 => 1_227.60e6,
            Band::E5a => 1_176.45e6,
            Band::E5b | Band::B2I => 1_207.14e6,
            Band::B1I => 1_561.098e6,
            Band::B3I => 1_268.52e6,
        }
    }
}

/// The Kepler elements and their harmonic corrections (IS-GPS-200 Table 20-III).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Kepler {
    /// Square root of the semi-major axis √A [√m].
    pub sqrt_a: f64,
    /// Eccentricity e.
    pub e: f64,
    /// Inclination at toe, i₀ [rad].
    pub i0: f64,
    /// Longitude of the ascending node at the week's start, Ω₀ [rad].
    pub omega0: f64,
    /// Argument of perigee ω [rad].
    pub omega: f64,
    /// Mean anomaly at toe, M₀ [rad].
    pub m0: f64,
    /// Mean motion difference Δn [rad/s].
    pub delta_n: f64,
    /// Rate of inclination IDOT [rad/s].
    pub i_dot: f64,
    /// Rate of right ascension Ω̇ [rad/s].
    pub omega_dot: f64,
    /// Argument of latitude corrections Cuc, Cus [rad].
    pub cuc: f64,
    /// See `cuc`.
    pub cus: f64,
    /// Orbit radius corrections Crc, Crs [m].
    pub crc: f64,
    /// See `crc`.
    pub crs: f64,
    /// Inclination corrections Cic, Cis [rad].
    pub cic: f64,
    /// See `cic`.
    pub cis: f64,
    /// Time of ephemeris as broadcast: seconds of the system's own week (BDT for
    /// BeiDou), the `toe` of Ω = Ω₀ + (Ω̇ − Ω̇e)tk − Ω̇e·toe.
    pub toe_sow: f64,
}

/// One broadcast ephemeris of one satellite: orbit, clock, group delays and health.
#[derive(Debug, Clone, PartialEq)]
pub struct Ephemeris {
    /// The satellite.
    pub sat: Sat,
    /// The message it came from.
    pub message: NavMessage,
    /// Time of clock, as a GPS instant.
    pub toc: GpsTime,
    /// Clock bias af0 [s], drift af1 [s/s], drift rate af2 [s/s²], relative to the
    /// system's own time scale (GPST, GST, BDT).
    pub af0: f64,
    /// See `af0`.
    pub af1: f64,
    /// See `af0`.
    pub af2: f64,
    /// Time of ephemeris, as a GPS instant.
    pub toe: GpsTime,
    /// The orbit.
    pub kepler: Kepler,
    /// Issue of data: IODE (GPS, QZSS), IODnav (Galileo), AODE (BeiDou).
    pub iode: u32,
    /// Issue of data of the clock: IODC (GPS, QZSS), AODC (BeiDou); 0 for Galileo.
    pub iodc: u32,
    /// Health as broadcast (GPS 6-bit health, Galileo's DVS/HS bits as RINEX packs
    /// them, BeiDou SatH1); see [`Ephemeris::is_healthy`].
    pub health: u32,
    /// Galileo's data-source bits (RINEX 3.04 Table A8); 0 for other systems.
    pub data_source: u32,
    /// User range accuracy (URA/SISA) [m] as broadcast; negative when none is given.
    pub accuracy_m: f64,
    /// Group delays [s]: GPS/QZSS [TGD, 0]; Galileo [BGD E1/E5a, BGD E1/E5b];
    /// BeiDou [TGD1 (B1I/B3I), TGD2 (B2I/B3I)].
    pub group_delays: [f64; 2],
    /// The curve-fit interval [s] (GPS/QZSS; 0 when not broadcast).
    pub fit_interval_s: f64,
}

/// The largest |t − toe| [s] for which a GPS or QZSS ephemeris is used when its
/// message gives no longer fit interval: 2 h, half of GPS's 4-hour fit interval
/// (IS-GPS-200 §20.3.4.4), whose toe is the middle of the interval.
pub const DEFAULT_VALIDITY_S: f64 = 7_200.0;

/// How long after its toe [s] a Galileo ephemeris is used: 4 h, the validity of a
/// Galileo navigation data set (OS SIS ICD §5.1.9.2 "age of data"; also RTKLIB's
/// bound). Galileo fits each set for the time after its toe: extrapolated backwards an
/// hour it errs by metres, so it is used at most [`EARLY_S`] before toe.
pub const GALILEO_VALIDITY_S: f64 = 14_400.0;

/// How long before its toe [s] a Galileo or BeiDou ephemeris may be used: 10 min,
/// Galileo's refresh interval (BeiDou's toe falls on the hour, a few seconds after a
/// GPS-time epoch on the hour since BDT lags GPST by 14 s).
pub const EARLY_S: f64 = 600.0;

impl Ephemeris {
    /// The system's constants (GPS's for a system without its own, which cannot occur
    /// for an ephemeris the reader made).
    pub fn constants(&self) -> SystemConstants {
        SystemConstants::of(self.sat.system).unwrap_or(SystemConstants::GPS)
    }

    /// Whether this is a BeiDou geostationary satellite (C01–C05, C59–C63), whose
    /// orbit is computed in a frame inclined by 5° (BDS-SIS-ICD §5.2.4.12).
    pub fn is_beidou_geo(&self) -> bool {
        self.sat.system == System::BeiDou && matches!(self.sat.prn, 1..=5 | 59..=63)
    }

    /// Whether the satellite declares itself usable on this message's signals: GPS
    /// and QZSS health 0; BeiDou SatH1 0; Galileo with no data-validity or signal-health
    /// bit set for the signals of its message (E1-B and E5b for I/NAV, E5a for F/NAV).
    pub fn is_healthy(&self) -> bool {
        match self.message {
            NavMessage::Lnav | NavMessage::D1 | NavMessage::D2 => self.health == 0,
            // Bits 0-2: E1-B DVS and HS; 6-8: E5b DVS and HS.
            NavMessage::Inav => self.health & 0x1C7 == 0,
            // Bits 3-5: E5a DVS and HS.
            NavMessage::Fnav => self.health & 0x038 == 0,
        }
    }

    /// The interval of `t − toe` [s] over which this ephemeris is used: GPS and QZSS
    /// ±half the fit interval, at least ±[`DEFAULT_VALIDITY_S`] (toe mid-interval);
    /// Galileo from −[`EARLY_S`] to [`GALILEO_VALIDITY_S`], BeiDou from −[`EARLY_S`]
    /// to [`DEFAULT_VALIDITY_S`] (toe at the start of their use, refreshed every 10 min
    /// and every hour).
    pub fn fit_window_s(&self) -> (f64, f64) {
        match self.sat.system {
            System::Galileo => (-EARLY_S, GALILEO_VALIDITY_S),
            System::BeiDou => (-EARLY_S, DEFAULT_VALIDITY_S),
            _ => {
                let v = (0.5 * self.fit_interval_s).max(DEFAULT_VALIDITY_S);
                (-v, v)
            }
        }
    }

    /// Whether the ephemeris is chosen by the nearest toe (GPS, QZSS: toe in the middle
    /// of the fit) rather than the latest toe (Galileo, BeiDou: toe at its start).
    pub fn toe_is_mid_fit(&self) -> bool {
        !matches!(self.sat.system, System::Galileo | System::BeiDou)
    }

    /// The group delay [s] a single-frequency user of `band` subtracts from the
    /// satellite clock bias (`Δt_band = Δt_sv − T`): GPS/QZSS T = TGD on L1 and
    /// γ·TGD on L2, γ = (f_L1/f_L2)² (IS-GPS-200 §20.3.3.3.3.2); Galileo BGD on E1 and
    /// (f_E1/f)²·BGD on E5a/E5b, with the BGD that matches the message's clock (E1/E5a
    /// for F/NAV, E1/E5b for I/NAV; OS SIS ICD §5.1.5); BeiDou TGD1 on B1I, TGD2 on B2I,
    /// 0 on B3I, the clock's own signal (BDS-SIS-ICD §5.2.4.10). `None` when the band is
    /// not one of the satellite's or its message does not give it (Galileo E5a from an
    /// I/NAV clock, E5b from an F/NAV clock).
    pub fn group_delay(&self, band: Band) -> Option<f64> {
        let [g0, g1] = self.group_delays;
        let scaled = |g: f64| {
            let r = Band::L1.frequency() / band.frequency();
            r * r * g
        };
        match (self.sat.system, self.message, band) {
            (System::Gps | System::Qzss, _, Band::L1) => Some(g0),
            (System::Gps | System::Qzss, _, Band::L2) => Some(scaled(g0)),
            (System::Galileo, NavMessage::Fnav, Band::E1) => Some(g0),
            (System::Galileo, NavMessage::Fnav, Band::E5a) => Some(scaled(g0)),
            (System::Galileo, NavMessage::Inav, Band::E1) => Some(g1),
            (System::Galileo, NavMessage::Inav, Band::E5b) => Some(scaled(g1)),
            (System::BeiDou, _, Band::B1I) => Some(g0),
            (System::BeiDou, _, Band::B2I) => Some(g1),
            (System::BeiDou, _, Band::B3I) => Some(0.0),
            _ => None,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn sample(system: System, prn: u8, message: NavMessage) -> Ephemeris {
        Ephemeris {
            sat: Sat::new(system, prn),
            message,
            toc: GpsTime::new(1590, 345_600.0),
            af0: 0.0,
            af1: 0.0,
            af2: 0.0,
            toe: GpsTime::new(1590, 345_600.0),
            kepler: Kepler::default(),
            iode: 0,
            iodc: 0,
            health: 0,
            data_source: 0,
            accuracy_m: 2.0,
            group_delays: [-4e-9, 3e-9],
            fit_interval_s: 0.0,
        }
    }

    #[test]
    fn gps_relativistic_coefficient_is_the_icds() {
        // IS-GPS-200 §20.3.3.3.3.1: F = −4.442807633e-10 s/√m.
        assert!((SystemConstants::GPS.f_rel() + 4.442_807_633e-10).abs() < 1e-19);
        // Galileo OS SIS ICD §5.1.4 gives −4.442807309e-10 with its μ.
        assert!((SystemConstants::GALILEO.f_rel() + 4.442_807_309e-10).abs() < 1e-18);
    }

    #[test]
    fn group_delays_follow_each_icd() {
        let gps = sample(System::Gps, 1, NavMessage::Lnav);
        assert_eq!(gps.group_delay(Band::L1), Some(-4e-9));
        let gamma = (77.0f64 / 60.0).powi(2);
        assert!((gps.group_delay(Band::L2).unwrap() - gamma * -4e-9).abs() < 1e-20);
        assert_eq!(gps.group_delay(Band::E5a), None);
        let fnav = sample(System::Galileo, 11, NavMessage::Fnav);
        let inav = sample(System::Galileo, 11, NavMessage::Inav);
        assert_eq!(fnav.group_delay(Band::E1), Some(-4e-9));
        assert_eq!(inav.group_delay(Band::E1), Some(3e-9));
        assert_eq!(inav.group_delay(Band::E5a), None);
        let r = (1575.42f64 / 1207.14).powi(2);
        assert!((inav.group_delay(Band::E5b).unwrap() - r * 3e-9).abs() < 1e-20);
        let bds = sample(System::BeiDou, 30, NavMessage::D1);
        assert_eq!(bds.group_delay(Band::B1I), Some(-4e-9));
        assert_eq!(bds.group_delay(Band::B2I), Some(3e-9));
        assert_eq!(bds.group_delay(Band::B3I), Some(0.0));
    }

    #[test]
    fn health_bits_of_the_message_in_use() {
        let mut e = sample(System::Galileo, 1, NavMessage::Inav);
        e.health = 0x038; // E5a unhealthy: I/NAV still usable.
        assert!(e.is_healthy());
        e.message = NavMessage::Fnav;
        assert!(!e.is_healthy());
        e.health = 0x100; // E5b HS.
        assert!(e.is_healthy());
        e.message = NavMessage::Inav;
        assert!(!e.is_healthy());
        let mut g = sample(System::Gps, 1, NavMessage::Lnav);
        assert!(g.is_healthy());
        g.health = 1;
        assert!(!g.is_healthy());
    }

    #[test]
    fn beidou_geo_prns() {
        for (prn, geo) in [(1, true), (5, true), (6, false), (58, false), (59, true)] {
            assert_eq!(
                sample(System::BeiDou, prn, NavMessage::D2).is_beidou_geo(),
                geo
            );
        }
        assert!(!sample(System::Gps, 1, NavMessage::Lnav).is_beidou_geo());
    }
}
