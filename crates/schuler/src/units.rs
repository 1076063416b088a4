//! Engineering units of navigation, parsed and printed, to and from SI.
//!
//! Inside schuler every quantity is SI with radians; people and data sheets speak in
//! deg/h, deg/sqrt(h), ug, mGal, ppm, arcsec, nmi, kn. This module is the one place that
//! converts, so a number's unit is never guessed:
//!
//! ```
//! use schuler::units::{self, Dimension};
//! let drift = units::parse_as("0.01 deg/h", Dimension::AngularRate).unwrap();
//! assert!((drift - 4.84813681109536e-8).abs() < 1e-22);
//! assert_eq!(units::format_in(drift, "deg/h").unwrap(), "0.01 deg/h");
//! let e = units::parse_as("3 m/s^2", Dimension::AngularRate).unwrap_err();
//! assert_eq!(e.to_string(), "expected an angular rate, got m/s^2 (an acceleration) in \"3 m/s^2\"");
//! ```
//!
//! Standard gravity g0 = 9.80665 m/s^2 (CGPM 1901) defines g, mg and ug; 1 Gal =
//! 0.01 m/s^2; 1 nmi = 1852 m. Random-walk coefficients: 1 deg/sqrt(h) =
//! (pi/180)/60 rad/sqrt(s); 1 m/s/sqrt(h) = 1/60 m/s/sqrt(s); a white-noise density
//! in ug/sqrt(Hz) equals the same number of ug·sqrt(s), i.e. a velocity random walk.

use std::fmt;

/// Standard gravity g0 [m/s^2].
pub const G0: f64 = 9.806_65;
/// One degree [rad].
pub const DEG: f64 = std::f64::consts::PI / 180.0;
/// One arc minute [rad].
pub const ARCMIN: f64 = DEG / 60.0;
/// One arc second [rad].
pub const ARCSEC: f64 = DEG / 3600.0;
/// One hour [s].
pub const HOUR: f64 = 3600.0;
/// One degree per hour [rad/s].
pub const DEG_PER_H: f64 = DEG / HOUR;
/// One degree per root hour [rad/sqrt(s)] (angle random walk).
pub const DEG_PER_SQRT_H: f64 = DEG / 60.0;
/// One metre per second per root hour [m/s/sqrt(s)] (velocity random walk).
pub const MPS_PER_SQRT_H: f64 = 1.0 / 60.0;
/// One milli-g [m/s^2].
pub const MG: f64 = 1e-3 * G0;
/// One micro-g [m/s^2].
pub const UG: f64 = 1e-6 * G0;
/// One milligal [m/s^2].
pub const MGAL: f64 = 1e-5;
/// One part per million.
pub const PPM: f64 = 1e-6;
/// One nautical mile [m].
pub const NMI: f64 = 1852.0;
/// One knot [m/s].
pub const KNOT: f64 = NMI / HOUR;

/// The physical dimension of a quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Dimension {
    /// Angle [rad].
    Angle,
    /// Angular rate [rad/s].
    AngularRate,
    /// Angle random walk [rad/sqrt(s)].
    AngleRandomWalk,
    /// Velocity random walk [m/s/sqrt(s)].
    VelocityRandomWalk,
    /// Acceleration [m/s^2].
    Acceleration,
    /// Pure number (scale factors).
    Dimensionless,
    /// Time [s].
    Time,
    /// Length [m].
    Length,
    /// Velocity [m/s].
    Velocity,
}

impl Dimension {
    /// The SI unit's name.
    pub fn si_unit(self) -> &'static str {
        match self {
            Self::Angle => "rad",
            Self::AngularRate => "rad/s",
            Self::AngleRandomWalk => "rad/sqrt(s)",
            Self::VelocityRandomWalk => "m/s/sqrt(s)",
            Self::Acceleration => "m/s^2",
            Self::Dimensionless => "1",
            Self::Time => "s",
            Self::Length => "m",
            Self::Velocity => "m/s",
        }
    }
}

impl fmt::Display for Dimension {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Angle => "an angle",
            Self::AngularRate => "an angular rate",
            Self::AngleRandomWalk => "an angle random walk",
            Self::VelocityRandomWalk => "a velocity random walk",
            Self::Acceleration => "an acceleration",
            Self::Dimensionless => "a dimensionless number",
            Self::Time => "a time",
            Self::Length => "a length",
            Self::Velocity => "a velocity",
        })
    }
}

/// A unit: its canonical name, dimension and size in SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// Canonical name, as printed.
    pub name: &'static str,
    /// What it measures.
    pub dimension: Dimension,
    /// Its size in the SI unit of its dimension.
    pub si: f64,
}

use Dimension as D;

/// Every unit: canonical name, dimension, SI factor, accepted aliases.
const UNITS: &[(&str, Dimension, f64, &[&str])] = &[
    ("rad", D::Angle, 1.0, &["radian", "radians"]),
    ("mrad", D::Angle, 1e-3, &[]),
    ("urad", D::Angle, 1e-6, &["µrad"]),
    ("deg", D::Angle, DEG, &["°", "degree", "degrees"]),
    ("arcmin", D::Angle, ARCMIN, &["'"]),
    ("arcsec", D::Angle, ARCSEC, &["\"", "asec"]),
    ("rad/s", D::AngularRate, 1.0, &[]),
    ("deg/s", D::AngularRate, DEG, &["°/s", "dps"]),
    ("deg/min", D::AngularRate, DEG / 60.0, &[]),
    (
        "deg/h",
        D::AngularRate,
        DEG_PER_H,
        &["deg/hr", "°/h", "dph"],
    ),
    ("rad/h", D::AngularRate, 1.0 / HOUR, &[]),
    ("rad/sqrt(s)", D::AngleRandomWalk, 1.0, &["rad/s/sqrt(hz)"]),
    (
        "deg/sqrt(h)",
        D::AngleRandomWalk,
        DEG_PER_SQRT_H,
        &["deg/sqrt(hr)", "°/sqrt(h)", "deg/rt(h)"],
    ),
    ("deg/s/sqrt(hz)", D::AngleRandomWalk, DEG, &[]),
    (
        "deg/h/sqrt(hz)",
        D::AngleRandomWalk,
        DEG_PER_H,
        &["deg/hr/sqrt(hz)"],
    ),
    (
        "m/s/sqrt(s)",
        D::VelocityRandomWalk,
        1.0,
        &["m/s^2/sqrt(hz)"],
    ),
    (
        "m/s/sqrt(h)",
        D::VelocityRandomWalk,
        MPS_PER_SQRT_H,
        &["m/s/sqrt(hr)", "m/s/rt(h)"],
    ),
    ("ug/sqrt(hz)", D::VelocityRandomWalk, UG, &["µg/sqrt(hz)"]),
    ("mg/sqrt(hz)", D::VelocityRandomWalk, MG, &[]),
    ("m/s^2", D::Acceleration, 1.0, &["m/s2", "m/s/s", "m/s²"]),
    ("g", D::Acceleration, G0, &["g0"]),
    ("mg", D::Acceleration, MG, &[]),
    ("ug", D::Acceleration, UG, &["µg", "micro-g"]),
    ("gal", D::Acceleration, 1e-2, &[]),
    ("mgal", D::Acceleration, MGAL, &[]),
    ("1", D::Dimensionless, 1.0, &[]),
    ("%", D::Dimensionless, 1e-2, &["percent"]),
    ("ppm", D::Dimensionless, PPM, &[]),
    ("s", D::Time, 1.0, &["sec"]),
    ("ms", D::Time, 1e-3, &[]),
    ("min", D::Time, 60.0, &[]),
    ("h", D::Time, HOUR, &["hr", "hour", "hours"]),
    ("m", D::Length, 1.0, &[]),
    ("km", D::Length, 1e3, &[]),
    ("ft", D::Length, 0.3048, &[]),
    ("nmi", D::Length, NMI, &[]),
    ("m/s", D::Velocity, 1.0, &["mps"]),
    ("km/h", D::Velocity, 1e3 / HOUR, &["kph", "kmh"]),
    (
        "kn",
        D::Velocity,
        KNOT,
        &["kt", "kts", "knot", "knots", "nmi/h"],
    ),
];

impl Unit {
    /// Look a unit up by name or alias (case-insensitive, spaces ignored; `hr` = `h`).
    pub fn parse(name: &str) -> Result<Self, UnitError> {
        let key: String = name
            .chars()
            .filter(|c| !c.is_whitespace())
            .flat_map(char::to_lowercase)
            .collect();
        UNITS
            .iter()
            .find(|(n, _, _, aliases)| key == *n || aliases.contains(&key.as_str()))
            .map(|&(name, dimension, si, _)| Unit {
                name,
                dimension,
                si,
            })
            .ok_or_else(|| UnitError::UnknownUnit {
                unit: name.trim().to_string(),
            })
    }

    /// The canonical names of all units of a dimension.
    pub fn names_of(dimension: Dimension) -> Vec<&'static str> {
        UNITS
            .iter()
            .filter(|u| u.1 == dimension)
            .map(|u| u.0)
            .collect()
    }

    /// The name to print: the caller's spelling (`nmi/h` stays `nmi/h`), trimmed.
    fn print_name(requested: &str, unit: &Unit) -> String {
        let trimmed = requested.trim();
        if trimmed.is_empty() {
            unit.name.to_string()
        } else {
            trimmed.to_string()
        }
    }
}

/// A number with a dimension, in SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantity {
    /// Value in the SI unit of its dimension.
    pub si: f64,
    /// Its dimension; `None` for a bare number without a unit.
    pub dimension: Option<Dimension>,
}

/// Errors of parsing or printing units.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum UnitError {
    /// Nothing to parse.
    #[error("empty quantity: expected a number and a unit such as \"0.01 deg/h\"")]
    Empty,
    /// The text does not start with a number.
    #[error("not a number in {text:?}: expected a number and a unit such as \"0.01 deg/h\"")]
    BadNumber {
        /// The whole input.
        text: String,
    },
    /// NaN or infinite.
    #[error("not a finite number in {text:?}")]
    NonFinite {
        /// The whole input.
        text: String,
    },
    /// An unknown unit name.
    #[error("unknown unit {unit:?}")]
    UnknownUnit {
        /// The unit as written.
        unit: String,
    },
    /// A unit of the wrong dimension.
    #[error("expected {expected}, got {unit} ({got}) in {text:?}")]
    Mismatch {
        /// What was expected.
        expected: Dimension,
        /// What the unit measures.
        got: Dimension,
        /// The unit as written.
        unit: String,
        /// The whole input.
        text: String,
    },
    /// A bare number where a unit is required.
    #[error("missing unit in {text:?}: expected {expected} in one of {accepted}")]
    MissingUnit {
        /// What was expected.
        expected: Dimension,
        /// Accepted unit names.
        accepted: String,
        /// The whole input.
        text: String,
    },
}

/// Split `text` into its leading number and the rest (the unit).
fn split_number(text: &str) -> Result<(f64, &str), UnitError> {
    let s = text.trim();
    if s.is_empty() {
        return Err(UnitError::Empty);
    }
    let bytes = s.as_bytes();
    let mut end = 0;
    let mut seen_digit = false;
    let mut seen_exp = false;
    while end < bytes.len() {
        let c = bytes[end];
        let ok = match c {
            b'0'..=b'9' => {
                seen_digit = true;
                true
            }
            b'+' | b'-' => end == 0 || matches!(bytes[end - 1], b'e' | b'E'),
            b'.' => !seen_exp,
            // An exponent only when a digit (or sign+digit) follows, so "2e" is not eaten.
            b'e' | b'E' => {
                let next = bytes.get(end + 1).copied();
                let next2 = bytes.get(end + 2).copied();
                let digit_follows = matches!(next, Some(b'0'..=b'9'))
                    || (matches!(next, Some(b'+' | b'-')) && matches!(next2, Some(b'0'..=b'9')));
                if seen_digit && !seen_exp && digit_follows {
                    seen_exp = true;
                    true
                } else {
                    false
                }
            }
            _ => false,
        };
        if !ok {
            break;
        }
        end += 1;
    }
    let (num, rest) = s.split_at(end);
    let lower = s.to_ascii_lowercase();
    if !seen_digit {
        if ["nan", "inf", "+inf", "-inf", "infinity"]
            .iter()
            .any(|w| lower.starts_with(w))
        {
            return Err(UnitError::NonFinite {
                text: text.to_string(),
            });
        }
        return Err(UnitError::BadNumber {
            text: text.to_string(),
        });
    }
    let value: f64 = num.parse().map_err(|_| UnitError::BadNumber {
        text: text.to_string(),
    })?;
    if !value.is_finite() {
        return Err(UnitError::NonFinite {
            text: text.to_string(),
        });
    }
    Ok((value, rest.trim()))
}

/// Parse `"<number> <unit>"` (space optional) into SI with its dimension; a bare number
/// has no dimension.
pub fn parse(text: &str) -> Result<Quantity, UnitError> {
    let (value, unit) = split_number(text)?;
    if unit.is_empty() {
        return Ok(Quantity {
            si: value,
            dimension: None,
        });
    }
    let u = Unit::parse(unit)?;
    Ok(Quantity {
        si: value * u.si,
        dimension: Some(u.dimension),
    })
}

/// Parse a quantity that must have `expected` dimension; returns SI. A unit is required.
pub fn parse_as(text: &str, expected: Dimension) -> Result<f64, UnitError> {
    let (value, unit) = split_number(text)?;
    if unit.is_empty() {
        if expected == Dimension::Dimensionless {
            return Ok(value);
        }
        return Err(UnitError::MissingUnit {
            expected,
            accepted: Unit::names_of(expected).join(", "),
            text: text.to_string(),
        });
    }
    let u = Unit::parse(unit)?;
    if u.dimension != expected {
        return Err(UnitError::Mismatch {
            expected,
            got: u.dimension,
            unit: unit.to_string(),
            text: text.to_string(),
        });
    }
    Ok(value * u.si)
}

/// As [`parse_as`], but a bare number is taken as SI.
pub fn parse_as_or_si(text: &str, expected: Dimension) -> Result<f64, UnitError> {
    let (value, unit) = split_number(text)?;
    if unit.is_empty() {
        Ok(value)
    } else {
        parse_as(text, expected)
    }
}

/// Print an SI value in the named unit: `format_in(4.848e-8, "deg/h")` is
/// `"0.01 deg/h"`. The number is the shortest that parses back to the same f64.
pub fn format_in(value_si: f64, unit: &str) -> Result<String, UnitError> {
    let u = Unit::parse(unit)?;
    Ok(format!(
        "{} {}",
        value_si / u.si,
        Unit::print_name(unit, &u)
    ))
}

/// An SI value printable in a chosen unit (`{}` via [`format_in`]).
#[derive(Debug, Clone, Copy)]
pub struct InUnit {
    /// Value in SI.
    pub si: f64,
    /// The unit to print in.
    pub unit: Unit,
}

impl InUnit {
    /// `value_si` to be printed in `unit`.
    pub fn new(value_si: f64, unit: &str) -> Result<Self, UnitError> {
        Ok(Self {
            si: value_si,
            unit: Unit::parse(unit)?,
        })
    }
}

impl fmt::Display for InUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.si / self.unit.si;
        match f.precision() {
            Some(p) => write!(f, "{v:.p$} {}", self.unit.name),
            None => write!(f, "{v} {}", self.unit.name),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// Each unit against a value written out independently (1e-15 relative: a pure
    /// scale factor is exact to one or two roundings).
    #[test]
    fn units_against_hand_values() {
        let cases: &[(&str, f64)] = &[
            ("1 deg/h", 4.84813681109536e-6),
            ("20 arcsec", 9.696273622190722e-5),
            ("1 arcmin", 2.908882086657216e-4),
            ("1 deg/sqrt(h)", 2.908882086657216e-4),
            ("1 m/s/sqrt(h)", 1.0 / 60.0),
            ("1 nmi/h", 0.514_444_444_444_444_5),
            ("1 kn", 0.514_444_444_444_444_5),
            ("36 km/h", 10.0),
            ("50 ug", 4.903325e-4),
            ("5 mg", 4.903325e-2),
            ("1 g", 9.80665),
            ("15 mGal", 1.5e-4),
            ("100 ppm", 1e-4),
            ("2.5 %", 0.025),
            ("1.5 h", 5400.0),
            ("3 min", 180.0),
            ("2 nmi", 3704.0),
            ("1.2 km", 1200.0),
            ("90 deg/s", std::f64::consts::FRAC_PI_2),
            ("10 ug/sqrt(Hz)", 9.80665e-5),
            ("0.1 deg/h/sqrt(Hz)", 4.84813681109536e-7),
        ];
        for &(text, expected) in cases {
            let q = parse(text).unwrap_or_else(|e| panic!("{text}: {e}"));
            assert_relative_eq!(q.si, expected, max_relative = 1e-15);
        }
    }

    #[test]
    fn with_or_without_space_and_aliases() {
        for text in ["20arcsec", "20 arcsec", " 20  arcsec ", "20\""] {
            assert_relative_eq!(parse_as(text, D::Angle).expect(text), 20.0 * ARCSEC);
        }
        assert_relative_eq!(parse_as("1 m/s", D::Velocity).expect("m/s"), 1.0);
        assert_relative_eq!(parse_as("1e-3 m/s2", D::Acceleration).expect("m/s2"), 1e-3);
        assert_relative_eq!(
            parse_as("-3.5e-2 mg", D::Acceleration).expect("mg"),
            -3.5e-5 * G0
        );
        assert_relative_eq!(
            parse_as("0.003 deg/sqrt(hr)", D::AngleRandomWalk).expect("arw"),
            0.003 * DEG / 60.0
        );
        assert_relative_eq!(
            parse_as("2 DEG/H", D::AngularRate).expect("case"),
            2.0 * DEG_PER_H
        );
        // An "e" that starts a unit is not an exponent.
        assert!(matches!(parse("2em"), Err(UnitError::UnknownUnit { .. })));
    }

    #[test]
    fn errors_say_what_is_wrong() {
        let e = parse_as("3 m/s^2", D::AngularRate).unwrap_err();
        assert_eq!(
            e.to_string(),
            "expected an angular rate, got m/s^2 (an acceleration) in \"3 m/s^2\""
        );
        assert_eq!(
            parse("3 furlongs").unwrap_err().to_string(),
            "unknown unit \"furlongs\""
        );
        assert!(
            parse_as("3", D::Angle)
                .unwrap_err()
                .to_string()
                .contains("missing unit")
        );
        assert!(matches!(parse("deg"), Err(UnitError::BadNumber { .. })));
        assert!(matches!(parse(""), Err(UnitError::Empty)));
        assert!(matches!(parse("NaN deg"), Err(UnitError::NonFinite { .. })));
        assert!(matches!(
            parse("1e999 deg"),
            Err(UnitError::NonFinite { .. })
        ));
        assert_eq!(parse_as_or_si("0.5", D::Angle), Ok(0.5));
        assert_eq!(parse_as("0.5", D::Dimensionless), Ok(0.5));
    }

    #[test]
    fn printing() {
        assert_eq!(
            format_in(0.01 * DEG_PER_H, "deg/h").expect("deg/h"),
            "0.01 deg/h"
        );
        assert_eq!(format_in(50.0 * UG, "ug").expect("ug"), "50 ug");
        assert_eq!(
            format!("{:.2}", InUnit::new(1.0, "deg").expect("deg")),
            "57.30 deg"
        );
        assert!(format_in(1.0, "parsec").is_err());
    }

    proptest! {
        /// parse(format(x, u)) recovers x for every unit: the shortest round-trip
        /// printing of x/si, re-multiplied by si, is within two roundings of x.
        #[test]
        fn round_trip_every_unit(x in -1e6..1e6f64, i in 0..UNITS.len()) {
            let (name, dim, _, _) = UNITS[i];
            let text = format_in(x, name).expect("known unit");
            let back = parse_as(&text, dim).expect("parses");
            prop_assert!((back - x).abs() <= 4.0 * f64::EPSILON * x.abs(), "{} -> {} -> {}", x, text, back);
        }

        /// No input panics.
        #[test]
        fn never_panics(s in "\\PC{0,40}") {
            let _ = parse(&s);
            let _ = parse_as(&s, D::AngularRate);
        }
    }
}
