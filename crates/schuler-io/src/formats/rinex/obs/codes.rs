//! Observation codes: RINEX 3's three characters (type, band, attribute: `C1C`,
//! `L2W`, `S5Q`), and RINEX 2's two (`C1`, `P2`, `L1`) mapped onto them.
//!
//! # RINEX 2 → RINEX 3 (our mapping, per system)
//! RINEX 2 names the type and band but not the tracking mode, so the attribute is a
//! choice. We take the signal a geodetic receiver of the time tracked:
//!
//! | RINEX 2 | GPS | GLONASS | Galileo | QZSS | SBAS | BeiDou |
//! |---|---|---|---|---|---|---|
//! | `C1` | `C1C` | `C1C` | `C1X` | `C1C` | `C1C` | `C2I` |
//! | `P1` | `C1W` | `C1P` | `C1X` | `C1C` | `C1C` | `C2I` |
//! | `L1` `D1` `S1` | `·1C` | `·1C` | `·1X` | `·1C` | `·1C` | `·2I` |
//! | `C2` | `C2X` | `C2C` | — | `C2X` | — | `C2I` |
//! | `P2` | `C2W` | `C2P` | — | `C2X` | — | `C2I` |
//! | `L2` `D2` `S2` | `·2W` | `·2P` | — | `·2X` | — | `·2I` |
//! | `·5` | `·5X` | — | `·5X` | `·5X` | `·5X` | `·5X` |
//! | `·6` `·7` `·8` | — | — | `·6X` `·7X` `·8X` | `·6X` | — | `·6I` `·7I` |
//!
//! So GPS's `P1`/`P2` are the semi-codeless Y-code (`W`) and its L2 phase follows
//! them; GPS `C2` is L2C (`X`, both components); GLONASS's precise code is `P`;
//! Galileo and QZSS's modern signals are their combined components (`X`); BeiDou's B1
//! (RINEX 2.12's band 1 or 2) is band 2 of RINEX 3, `I`. A pair marked — is no signal
//! of that system: it maps to the band's `X` and is never filled by real files. The
//! RINEX 2 code is kept beside the mapped one ([`super::ObsHeader::rinex2_codes`]).

use schuler::gnss::System;
use std::fmt;

/// Most observation types a system may declare (RINEX 3 writes the count as I3; real
/// files declare at most a few dozen): bounds every record's memory.
pub const MAX_CODES_PER_SYSTEM: usize = 64;

/// What an observation measures: the first character of its code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ObsKind {
    /// `C`: pseudorange [m].
    Pseudorange,
    /// `L`: carrier phase [cycles].
    Phase,
    /// `D`: Doppler [Hz].
    Doppler,
    /// `S`: raw signal strength (C/N0 in dB-Hz when the header says `DBHZ`, and for
    /// RINEX 3's usual writers).
    SignalStrength,
    /// `X`: receiver channel number (RINEX 3.01 and later).
    Channel,
}

/// A RINEX 3 observation code, three ASCII characters: kind, band (digit), attribute
/// (letter).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ObsCode([u8; 3]);

impl ObsCode {
    /// The code spelt `s` (`"C1C"`); `None` unless a kind letter (`C L D S X`), a band
    /// digit and an attribute letter (`A`–`Z`).
    pub fn new(s: &str) -> Option<ObsCode> {
        let b: [u8; 3] = s.as_bytes().try_into().ok()?;
        let ok = matches!(b[0], b'C' | b'L' | b'D' | b'S' | b'X')
            && b[1].is_ascii_digit()
            && b[2].is_ascii_uppercase();
        ok.then_some(ObsCode(b))
    }

    /// Its three characters.
    pub fn as_str(&self) -> &str {
        // Built only from ASCII letters and digits (new, from_rinex2), so UTF-8.
        std::str::from_utf8(&self.0).unwrap_or("???")
    }

    /// What it measures.
    pub fn kind(self) -> ObsKind {
        match self.0[0] {
            b'C' => ObsKind::Pseudorange,
            b'L' => ObsKind::Phase,
            b'D' => ObsKind::Doppler,
            b'S' => ObsKind::SignalStrength,
            _ => ObsKind::Channel,
        }
    }

    /// The frequency band, RINEX 3's digit (1 for GPS L1, 2 for L2, 5 for L5…).
    pub fn band(self) -> u8 {
        self.0[1] - b'0'
    }

    /// The tracking mode or channel, RINEX 3's attribute letter.
    pub fn attribute(self) -> char {
        char::from(self.0[2])
    }

    /// The RINEX 3 code of RINEX 2's two-character `code` for satellites of `system`
    /// (the module's table); `None` for a code RINEX 2 does not define.
    pub fn from_rinex2(code: &str, system: System) -> Option<ObsCode> {
        let &[kind, band] = code.as_bytes() else {
            return None;
        };
        if !matches!(kind, b'C' | b'P' | b'L' | b'D' | b'S') || !b"125678".contains(&band) {
            return None;
        }
        let precise = kind == b'P';
        let attribute = match (system, band) {
            (System::Gps, b'1') if precise => b'W',
            (System::Gps, b'1') => b'C',
            (System::Gps, b'2') if kind == b'C' => b'X',
            (System::Gps, b'2') => b'W',
            (System::Glonass, b'1') if precise => b'P',
            (System::Glonass, b'2') if kind == b'C' => b'C',
            (System::Glonass, b'2') => b'P',
            (System::Glonass | System::Qzss | System::Sbas, b'1') => b'C',
            (System::BeiDou, _) => b'I',
            (System::Navic, _) => b'A',
            _ => b'X',
        };
        let band = match (system, band) {
            (System::BeiDou, b'1') => b'2',
            _ => band,
        };
        let kind = if precise { b'C' } else { kind };
        Some(ObsCode([kind, band, attribute]))
    }
}

impl fmt::Display for ObsCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The observation codes of each system in the order of the file's columns: an
/// epoch's observations name their code by its index in its system's list.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObsCodes {
    lists: [Vec<ObsCode>; System::ALL.len()],
}

impl ObsCodes {
    /// The codes of `system` (empty when it has none).
    pub fn of(&self, system: System) -> &[ObsCode] {
        &self.lists[slot(system)]
    }

    /// The index of `code` in `system`'s list.
    pub fn index(&self, system: System, code: ObsCode) -> Option<u8> {
        let i = self.of(system).iter().position(|&c| c == code)?;
        u8::try_from(i).ok()
    }

    /// Sets `system`'s list (at most [`MAX_CODES_PER_SYSTEM`] codes).
    pub(crate) fn set(&mut self, system: System, codes: Vec<ObsCode>) {
        self.lists[slot(system)] = codes;
    }

    /// Whether no system has a code.
    pub fn is_empty(&self) -> bool {
        self.lists.iter().all(Vec::is_empty)
    }
}

/// The place of `system` in [`System::ALL`].
pub(crate) fn slot(system: System) -> usize {
    System::ALL
        .iter()
        .position(|&s| s == system)
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_checked_and_taken_apart() {
        let c = ObsCode::new("C1C").unwrap();
        assert_eq!(
            (c.kind(), c.band(), c.attribute()),
            (ObsKind::Pseudorange, 1, 'C')
        );
        assert_eq!(ObsCode::new("S5Q").unwrap().kind(), ObsKind::SignalStrength);
        for bad in ["", "C1", "C1CC", "Q1C", "CXC", "C1c", "c1C"] {
            assert_eq!(ObsCode::new(bad), None, "{bad}");
        }
    }

    #[test]
    fn rinex2_codes_map_as_the_table_says() {
        let m = |c: &str, s| ObsCode::from_rinex2(c, s).map(|c| c.to_string());
        let g = System::Gps;
        assert_eq!(m("C1", g).as_deref(), Some("C1C"));
        assert_eq!(m("P1", g).as_deref(), Some("C1W"));
        assert_eq!(m("P2", g).as_deref(), Some("C2W"));
        assert_eq!(m("L2", g).as_deref(), Some("L2W"));
        assert_eq!(m("C2", g).as_deref(), Some("C2X"));
        assert_eq!(m("L5", g).as_deref(), Some("L5X"));
        assert_eq!(m("P2", System::Glonass).as_deref(), Some("C2P"));
        assert_eq!(m("C2", System::Glonass).as_deref(), Some("C2C"));
        assert_eq!(m("L1", System::Galileo).as_deref(), Some("L1X"));
        assert_eq!(m("S7", System::Galileo).as_deref(), Some("S7X"));
        assert_eq!(m("C1", System::BeiDou).as_deref(), Some("C2I"));
        assert_eq!(m("D1", System::Sbas).as_deref(), Some("D1C"));
        for bad in ["T1", "C3", "C", "C1C", "LA"] {
            assert_eq!(m(bad, g), None, "{bad}");
        }
    }

    #[test]
    fn lists_are_per_system() {
        let mut codes = ObsCodes::default();
        assert!(codes.is_empty());
        let c1c = ObsCode::new("C1C").unwrap();
        codes.set(System::Galileo, vec![ObsCode::new("L1C").unwrap(), c1c]);
        assert_eq!(codes.index(System::Galileo, c1c), Some(1));
        assert_eq!(codes.index(System::Gps, c1c), None);
        assert!(codes.of(System::Gps).is_empty());
    }
}
