//! Satellite identities: the constellation and the number within it, as RINEX writes
//! them (`G05`, `E11`, `C30`; RINEX 2 allows a blank for GPS, ` 5`).

use std::fmt;

/// A satellite navigation system (RINEX 3 system letter).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum System {
    /// GPS (`G`).
    Gps,
    /// GLONASS (`R`).
    Glonass,
    /// Galileo (`E`).
    Galileo,
    /// BeiDou (`C`).
    BeiDou,
    /// QZSS (`J`).
    Qzss,
    /// NavIC/IRNSS (`I`).
    Navic,
    /// SBAS payloads (`S`).
    Sbas,
}

impl System {
    /// Every system, in RINEX's usual order.
    pub const ALL: [System; 7] = [
        System::Gps,
        System::Glonass,
        System::Galileo,
        System::BeiDou,
        System::Qzss,
        System::Navic,
        System::Sbas,
    ];

    /// The RINEX 3 system letter.
    pub fn letter(self) -> char {
        match self {
            System::Gps => 'G',
            System::Glonass => 'R',
            System::Galileo => 'E',
            System::BeiDou => 'C',
            System::Qzss => 'J',
            System::Navic => 'I',
            System::Sbas => 'S',
        }
    }

    /// The system of a RINEX letter (a blank is GPS, as RINEX 2 allows).
    pub fn from_letter(c: char) -> Option<System> {
        match c {
            'G' | ' ' => Some(System::Gps),
            'R' => Some(System::Glonass),
            'E' => Some(System::Galileo),
            'C' => Some(System::BeiDou),
            'J' => Some(System::Qzss),
            'I' => Some(System::Navic),
            'S' => Some(System::Sbas),
            _ => None,
        }
    }
}

/// One satellite: its system and its number in that system (PRN, slot or SVID).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Sat {
    /// The constellation.
    pub system: System,
    /// The number within it (1-based, as broadcast).
    pub prn: u8,
}

impl Sat {
    /// A satellite of `system` numbered `prn`.
    pub fn new(system: System, prn: u8) -> Self {
        Self { system, prn }
    }

    /// Parses RINEX's three-character form (`G05`, `E11`, ` 5`, `G 5`); `None` when it
    /// is not one.
    pub fn parse(s: &str) -> Option<Sat> {
        let mut chars = s.chars();
        let system = System::from_letter(chars.next()?)?;
        let number = chars.as_str().trim();
        if number.is_empty() || !number.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let prn: u8 = number.parse().ok()?;
        (prn > 0).then_some(Sat { system, prn })
    }
}

impl fmt::Display for Sat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{:02}", self.system.letter(), self.prn)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rinex_forms_round_trip() {
        for s in ["G05", "E11", "C30", "R24", "J02", "S20", "I07"] {
            assert_eq!(Sat::parse(s).unwrap().to_string(), s);
        }
        assert_eq!(Sat::parse(" 5"), Some(Sat::new(System::Gps, 5)));
        assert_eq!(Sat::parse("G 5"), Some(Sat::new(System::Gps, 5)));
    }

    #[test]
    fn what_is_not_a_satellite_is_refused() {
        for s in ["", "G", "X01", "G0x", "G00", "G-1", "G999"] {
            assert_eq!(Sat::parse(s), None, "{s:?}");
        }
    }
}
