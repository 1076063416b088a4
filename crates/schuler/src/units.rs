//! Engineering units <-> SI: parse and print the units used in navigation.
//!
//! Inside the library every quantity is SI with radians: rad, rad/s, rad/sqrt(s) (angle
//! random walk), m/s/sqrt(s) (velocity random walk), rad/s/sqrt(s) (rate random walk),
//! m/s^2/sqrt(s) (acceleration random walk), rad/s/(m/s^2) (gyro g-sensitivity), m/s^2,
//! a plain ratio, s, m, m/s.
//! This module is the edge: configs, file headers and reports write `"0.01 deg/h"`,
//! `"25 ug"`, `"20 arcsec"`, `"100 ppm"`, `"0.003 deg/sqrt(h)"`, `"15 mGal"` or
//! `"1 nmi/h"`, and [`parse_as`] turns them into SI `f64`s while [`format()`] prints SI
//! values back in a chosen unit.
//!
//! Grammar: a decimal number (`-3.5e-2`, `.5`, `20`), optional whitespace, a unit name.
//! Unit names are case-sensitive (`mg` is milli-g, `mGal` is milligal). Spaces around
//! `/`, `^` and parentheses are ignored; `µ`/`μ` read as `u`, `°` as `deg`, `²` as `^2`
//! and `√x` as `sqrt(x)`. NaN and infinities are rejected. A bare number is accepted only
//! by [`parse_as_or_si`], where the caller declares that SI is the default.
//!
//! Every unit is one row of a single table: name, dimension, size in SI as a ratio
//! `mul / div` of two f64s, aliases; the SI value is `number * mul / div`. Standard
//! gravity is `G0 = 9.80665 m/s^2` (CGPM 1901); 1 Gal = 1 cm/s^2, 1 nmi = 1852 m,
//! 1 ft = 0.3048 m (international foot).
//!
//! ```
//! use schuler::units::{self, Dimension, DEG_PER_H};
//! let bias = units::parse_as("0.01 deg/h", Dimension::AngularRate).unwrap();
//! assert!((bias - 0.01 * DEG_PER_H).abs() < 1e-22);
//! assert_eq!(units::format(bias, "deg/h").unwrap(), "0.01 deg/h");
//! ```

use std::fmt;
use std::str::FromStr;

// ---------------------------------------------------------------------------------------
// SI factors: the SI value of one engineering unit.

/// Standard acceleration of gravity g0 = 9.80665 m/s^2 (3rd CGPM, 1901); basis of g, mg, ug.
pub const G0: f64 = 9.80665;
/// One degree in radians, pi/180 (correctly rounded, as `f64::to_radians` uses).
pub const DEG: f64 = 1.0_f64.to_radians();
/// One arc minute in radians, pi/10800.
pub const ARCMIN: f64 = DEG / 60.0;
/// One arc second in radians, pi/648000.
pub const ARCSEC: f64 = DEG / 3600.0;
/// One milliradian in radians.
pub const MRAD: f64 = 1e-3;
/// One microradian in radians.
pub const URAD: f64 = 1e-6;
/// One minute in seconds.
pub const MINUTE: f64 = 60.0;
/// One hour in seconds.
pub const HOUR: f64 = 3600.0;
/// One degree per second in rad/s.
pub const DEG_PER_S: f64 = DEG;
/// One degree per minute in rad/s.
pub const DEG_PER_MIN: f64 = DEG / MINUTE;
/// One degree per hour in rad/s (pi/648000, the gyro bias unit).
pub const DEG_PER_H: f64 = DEG / HOUR;
/// One deg/sqrt(h) of angle random walk in rad/sqrt(s): DEG / 60, since sqrt(3600 s) = 60 sqrt(s).
pub const DEG_PER_SQRT_H: f64 = DEG / 60.0;
/// One deg/h/sqrt(Hz) of angle random walk in rad/sqrt(s); equals 1/60 deg/sqrt(h).
pub const DEG_PER_H_PER_SQRT_HZ: f64 = DEG_PER_H;
/// One m/s/sqrt(h) of velocity random walk in m/s/sqrt(s): 1/60.
pub const M_PER_S_PER_SQRT_H: f64 = 1.0 / 60.0;
/// One deg/h/sqrt(h) of rate random walk in rad/s/sqrt(s): DEG / (3600 * 60).
pub const DEG_PER_H_PER_SQRT_H: f64 = DEG / (HOUR * 60.0);
/// One deg/h per g of gyro g-sensitivity in rad/s per m/s^2: DEG / 3600 / G0.
pub const DEG_PER_H_PER_G: f64 = DEG / (HOUR * G0);
/// One milli-g in m/s^2 (1e-3 G0); spelled `mg`, not to be confused with [`MGAL`].
pub const MG: f64 = G0 / 1e3;
/// One micro-g in m/s^2 (1e-6 G0); also the SI value of 1 ug/sqrt(Hz) in m/s/sqrt(s).
pub const UG: f64 = G0 / 1e6;
/// One gal (galileo, 1 cm/s^2) in m/s^2.
pub const GAL: f64 = 1e-2;
/// One milligal in m/s^2 (1e-5), the gravimetry and KF-GINS accelerometer-bias unit.
pub const MGAL: f64 = 1e-5;
/// One microgal in m/s^2 (1e-8).
pub const UGAL: f64 = 1e-8;
/// One part per million as a ratio (1e-6).
pub const PPM: f64 = 1e-6;
/// One part per billion as a ratio (1e-9).
pub const PPB: f64 = 1e-9;
/// One percent as a ratio (1e-2).
pub const PERCENT: f64 = 1e-2;
/// One international nautical mile in metres (1852 m).
pub const NMI: f64 = 1852.0;
/// One international foot in metres (0.3048 m).
pub const FT: f64 = 0.3048;
/// One kilometre per hour in m/s (1/3.6).
pub const KM_PER_H: f64 = 1000.0 / HOUR;
/// One knot (nautical mile per hour) in m/s (1852/3600).
pub const KNOT: f64 = NMI / HOUR;

// ---------------------------------------------------------------------------------------
// Dimensions and the unit table.

/// The physical dimension of a quantity; each has one SI unit ([`Dimension::si_name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Dimension {
    /// Plane angle, SI rad.
    Angle,
    /// Angular rate, SI rad/s.
    AngularRate,
    /// Angle random walk (gyro white noise density), SI rad/sqrt(s).
    AngleRandomWalk,
    /// Velocity random walk (accelerometer white noise density), SI m/s/sqrt(s).
    VelocityRandomWalk,
    /// Rate random walk (random walk of a gyro bias), SI rad/s/sqrt(s).
    RateRandomWalk,
    /// Acceleration random walk (random walk of an accelerometer bias), SI
    /// m/s^2/sqrt(s).
    AccelerationRandomWalk,
    /// Gyro g-sensitivity (rate error per specific force), SI rad/s per m/s^2.
    GSensitivity,
    /// Acceleration (specific force, gravity), SI m/s^2.
    Acceleration,
    /// Dimensionless ratio (scale factor, ppm, percent), SI 1.
    Dimensionless,
    /// Time, SI s.
    Time,
    /// Length, SI m.
    Length,
    /// Velocity, SI m/s.
    Velocity,
}

impl Dimension {
    /// Every dimension, in declaration order.
    pub const ALL: [Dimension; 12] = [
        Dimension::Angle,
        Dimension::AngularRate,
        Dimension::AngleRandomWalk,
        Dimension::VelocityRandomWalk,
        Dimension::RateRandomWalk,
        Dimension::AccelerationRandomWalk,
        Dimension::GSensitivity,
        Dimension::Acceleration,
        Dimension::Dimensionless,
        Dimension::Time,
        Dimension::Length,
        Dimension::Velocity,
    ];

    /// The name of the SI unit values of this dimension are held in ("1" for a ratio).
    pub fn si_name(self) -> &'static str {
        match self {
            Dimension::Angle => "rad",
            Dimension::AngularRate => "rad/s",
            Dimension::AngleRandomWalk => "rad/sqrt(s)",
            Dimension::VelocityRandomWalk => "m/s/sqrt(s)",
            Dimension::RateRandomWalk => "rad/s/sqrt(s)",
            Dimension::AccelerationRandomWalk => "m/s^2/sqrt(s)",
            Dimension::GSensitivity => "rad/s/(m/s^2)",
            Dimension::Acceleration => "m/s^2",
            Dimension::Dimensionless => "1",
            Dimension::Time => "s",
            Dimension::Length => "m",
            Dimension::Velocity => "m/s",
        }
    }

    /// The units of this dimension, in table order (SI first).
    pub fn units(self) -> impl Iterator<Item = Unit> + Clone {
        Unit::all().filter(move |u| u.dimension == self)
    }

    /// The words used in messages, with article: "an angle", "an angular rate", ...
    fn words(self) -> &'static str {
        match self {
            Dimension::Angle => "an angle",
            Dimension::AngularRate => "an angular rate",
            Dimension::AngleRandomWalk => "an angle random walk",
            Dimension::VelocityRandomWalk => "a velocity random walk",
            Dimension::RateRandomWalk => "a rate random walk",
            Dimension::AccelerationRandomWalk => "an acceleration random walk",
            Dimension::GSensitivity => "a g-sensitivity (angular rate per acceleration)",
            Dimension::Acceleration => "an acceleration",
            Dimension::Dimensionless => "a dimensionless ratio",
            Dimension::Time => "a time",
            Dimension::Length => "a length",
            Dimension::Velocity => "a velocity",
        }
    }
}

impl fmt::Display for Dimension {
    /// Writes the words used in error messages: "an angle", "an angular rate", ...
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.words())
    }
}

/// An engineering unit: its printed name, its dimension and its size in SI.
///
/// The size is held as an exact ratio `mul / div` of two f64s (e.g. mGal = 1 / 1e5, deg/h =
/// DEG / 3600) so that decimal prefixes convert with one correctly rounded division:
/// `"15 mGal"` is the same f64 as `1.5e-4`, which multiplying by the inexact `1e-5` is not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    name: &'static str,
    dimension: Dimension,
    mul: f64,
    div: f64,
}

/// One row of the unit table: a unit and the other spellings that read as it.
struct Entry {
    unit: Unit,
    aliases: &'static [&'static str],
}

/// Builds a table row for a unit worth `mul / div` SI units.
const fn entry(
    name: &'static str,
    dimension: Dimension,
    (mul, div): (f64, f64),
    aliases: &'static [&'static str],
) -> Entry {
    Entry {
        unit: Unit {
            name,
            dimension,
            mul,
            div,
        },
        aliases,
    }
}

/// The one table of units: name, dimension, size in SI as (mul, div), aliases. Within a
/// dimension the SI unit comes first. Aliases are in the normalized form (after `µ`->`u`,
/// `°`->`deg`, `²`->`^2`, `√x`->`sqrt(x)`; see `normalize`).
static TABLE: &[Entry] = {
    use Dimension as D;
    const ONE: (f64, f64) = (1.0, 1.0);
    &[
        // Angle
        entry("rad", D::Angle, ONE, &["radian", "radians"]),
        entry("mrad", D::Angle, (1.0, 1e3), &[]),
        entry("urad", D::Angle, (1.0, 1e6), &[]),
        entry("deg", D::Angle, (DEG, 1.0), &["degree", "degrees"]),
        entry(
            "arcmin",
            D::Angle,
            (DEG, 60.0),
            &["arcminute", "arcminutes"],
        ),
        entry(
            "arcsec",
            D::Angle,
            (DEG, 3600.0),
            &["arcsecond", "arcseconds"],
        ),
        // Angular rate
        entry("rad/s", D::AngularRate, ONE, &["rad/sec"]),
        entry("deg/s", D::AngularRate, (DEG, 1.0), &["deg/sec", "dps"]),
        entry("deg/min", D::AngularRate, (DEG, MINUTE), &[]),
        entry("deg/h", D::AngularRate, (DEG, HOUR), &["deg/hr", "dph"]),
        // Angle random walk: sqrt(1 h) = 60 sqrt(s); x/sqrt(Hz) = x*sqrt(s)
        entry("rad/sqrt(s)", D::AngleRandomWalk, ONE, &[]),
        entry("deg/sqrt(s)", D::AngleRandomWalk, (DEG, 1.0), &[]),
        entry(
            "deg/sqrt(h)",
            D::AngleRandomWalk,
            (DEG, 60.0),
            &["deg/sqrt(hr)"],
        ),
        entry("rad/s/sqrt(Hz)", D::AngleRandomWalk, ONE, &[]),
        entry("deg/s/sqrt(Hz)", D::AngleRandomWalk, (DEG, 1.0), &[]),
        entry(
            "deg/h/sqrt(Hz)",
            D::AngleRandomWalk,
            (DEG, HOUR),
            &["deg/hr/sqrt(Hz)"],
        ),
        // Velocity random walk: m/s/sqrt(s) = m/s^2/sqrt(Hz)
        entry("m/s/sqrt(s)", D::VelocityRandomWalk, ONE, &[]),
        entry(
            "m/s/sqrt(h)",
            D::VelocityRandomWalk,
            (1.0, 60.0),
            &["m/s/sqrt(hr)"],
        ),
        entry(
            "ft/s/sqrt(h)",
            D::VelocityRandomWalk,
            (FT, 60.0),
            &["ft/s/sqrt(hr)"],
        ),
        entry(
            "m/s^2/sqrt(Hz)",
            D::VelocityRandomWalk,
            ONE,
            &["m/s2/sqrt(Hz)"],
        ),
        entry("g/sqrt(Hz)", D::VelocityRandomWalk, (G0, 1.0), &[]),
        entry("mg/sqrt(Hz)", D::VelocityRandomWalk, (G0, 1e3), &[]),
        entry("ug/sqrt(Hz)", D::VelocityRandomWalk, (G0, 1e6), &[]),
        // Rate random walk: deg/h/sqrt(h) = DEG / 3600 / 60 rad/s/sqrt(s)
        entry("rad/s/sqrt(s)", D::RateRandomWalk, ONE, &[]),
        entry("deg/s/sqrt(s)", D::RateRandomWalk, (DEG, 1.0), &[]),
        entry(
            "deg/h/sqrt(h)",
            D::RateRandomWalk,
            (DEG, HOUR * 60.0),
            &["deg/hr/sqrt(hr)"],
        ),
        // Acceleration random walk
        entry(
            "m/s^2/sqrt(s)",
            D::AccelerationRandomWalk,
            ONE,
            &["m/s2/sqrt(s)"],
        ),
        entry(
            "m/s^2/sqrt(h)",
            D::AccelerationRandomWalk,
            (1.0, 60.0),
            &["m/s2/sqrt(h)"],
        ),
        entry(
            "m/s/h/sqrt(h)",
            D::AccelerationRandomWalk,
            (1.0, HOUR * 60.0),
            &["m/s/hr/sqrt(hr)"],
        ),
        entry(
            "mg/sqrt(h)",
            D::AccelerationRandomWalk,
            (G0, 1e3 * 60.0),
            &["mg/sqrt(hr)"],
        ),
        entry(
            "ug/sqrt(h)",
            D::AccelerationRandomWalk,
            (G0, 1e6 * 60.0),
            &["ug/sqrt(hr)"],
        ),
        // Gyro g-sensitivity: rate per specific force
        entry("rad/s/(m/s^2)", D::GSensitivity, ONE, &["rad/s/(m/s2)"]),
        entry("rad/s/g", D::GSensitivity, (1.0, G0), &[]),
        entry("deg/s/g", D::GSensitivity, (DEG, G0), &[]),
        entry(
            "deg/h/g",
            D::GSensitivity,
            (DEG, HOUR * G0),
            &["deg/hr/g", "dph/g"],
        ),
        // Acceleration
        entry("m/s^2", D::Acceleration, ONE, &["m/s2", "m/s/s"]),
        entry("g", D::Acceleration, (G0, 1.0), &[]),
        entry("mg", D::Acceleration, (G0, 1e3), &[]),
        entry("ug", D::Acceleration, (G0, 1e6), &[]),
        entry("Gal", D::Acceleration, (1.0, 1e2), &[]),
        entry("mGal", D::Acceleration, (1.0, 1e5), &[]),
        entry("uGal", D::Acceleration, (1.0, 1e8), &[]),
        entry("ft/s^2", D::Acceleration, (FT, 1.0), &["ft/s2"]),
        // Dimensionless
        entry("ppm", D::Dimensionless, (1.0, 1e6), &[]),
        entry("ppb", D::Dimensionless, (1.0, 1e9), &[]),
        entry("%", D::Dimensionless, (1.0, 1e2), &["percent"]),
        // Time
        entry("s", D::Time, ONE, &["sec"]),
        entry("ms", D::Time, (1.0, 1e3), &[]),
        entry("us", D::Time, (1.0, 1e6), &[]),
        entry("min", D::Time, (MINUTE, 1.0), &[]),
        entry("h", D::Time, (HOUR, 1.0), &["hr", "hour", "hours"]),
        // Length
        entry("m", D::Length, ONE, &[]),
        entry("mm", D::Length, (1.0, 1e3), &[]),
        entry("km", D::Length, (1e3, 1.0), &[]),
        entry("ft", D::Length, (FT, 1.0), &[]),
        entry("nmi", D::Length, (NMI, 1.0), &[]),
        // Velocity
        entry("m/s", D::Velocity, ONE, &[]),
        entry("km/h", D::Velocity, (1e3, HOUR), &["km/hr", "kph"]),
        entry("kn", D::Velocity, (NMI, HOUR), &["kt", "knot", "knots"]),
        entry("nmi/h", D::Velocity, (NMI, HOUR), &["nmi/hr"]),
        entry("ft/s", D::Velocity, (FT, 1.0), &[]),
    ]
};

impl Unit {
    /// Every known unit, in table order (grouped by dimension, SI first in each group).
    pub fn all() -> impl Iterator<Item = Unit> + Clone {
        TABLE.iter().map(|e| e.unit)
    }

    /// Looks up a unit by name or alias (`"deg/h"`, `"deg/hr"`, `"°/h"`, `"µg"`, ...).
    pub fn parse(name: &str) -> Result<Unit, UnitError> {
        lookup(name, name, None)
    }

    /// The canonical name, as printed (`"deg/h"`).
    pub fn name(self) -> &'static str {
        self.name
    }

    /// The dimension of this unit.
    pub fn dimension(self) -> Dimension {
        self.dimension
    }

    /// The SI value of one of this unit (`DEG_PER_H` for deg/h): `mul / div`, rounded once.
    pub fn factor(self) -> f64 {
        self.mul / self.div
    }

    /// Converts a value in this unit to SI: `value * mul / div` (one rounding when mul or div is 1).
    pub fn to_si(self, value: f64) -> f64 {
        let si = value * self.mul / self.div;
        // Multiplying first overflows for huge values that divide back into range.
        if si.is_finite() {
            si
        } else {
            value / self.div * self.mul
        }
    }

    /// Converts an SI value to this unit: `value_si * div / mul`.
    pub fn from_si(self, value_si: f64) -> f64 {
        let v = value_si * self.div / self.mul;
        if v.is_finite() {
            v
        } else {
            value_si / self.mul * self.div
        }
    }

    /// A `Display`-able SI value printed in this unit (see [`InUnit`]).
    pub fn show(self, value_si: f64) -> InUnit {
        InUnit {
            value_si,
            unit: self,
        }
    }
}

impl fmt::Display for Unit {
    /// Writes the canonical name.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name)
    }
}

impl FromStr for Unit {
    type Err = UnitError;

    /// Same as [`Unit::parse`].
    fn from_str(s: &str) -> Result<Unit, UnitError> {
        Unit::parse(s)
    }
}

// ---------------------------------------------------------------------------------------
// Errors.

/// Why a quantity or unit could not be parsed or printed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum UnitError {
    /// The input was empty or only whitespace.
    #[error("empty quantity: expected a number and a unit, like \"0.01 deg/h\"")]
    Empty,
    /// The input does not start with a well-formed decimal number.
    #[error("bad number in {input:?}: expected a decimal number then a unit, like \"0.01 deg/h\"")]
    BadNumber {
        /// The whole input.
        input: String,
    },
    /// The number is NaN or infinite, or overflows once converted to SI.
    #[error("not a finite number in {input:?}")]
    NonFinite {
        /// The whole input.
        input: String,
    },
    /// A number without a unit where a unit is required.
    #[error("missing unit in {input:?}{}", missing_hint(*.expected))]
    MissingUnit {
        /// The whole input.
        input: String,
        /// The dimension the caller expected, if it said.
        expected: Option<Dimension>,
    },
    /// The unit name is not in the table.
    #[error("unknown unit {unit:?}{}", unknown_hint(.unit, .input, .suggestions, *.expected))]
    UnknownUnit {
        /// The unit as written.
        unit: String,
        /// The whole input.
        input: String,
        /// Known units with a similar spelling (canonical names), best first.
        suggestions: Vec<&'static str>,
        /// The dimension the caller expected, if it said.
        expected: Option<Dimension>,
    },
    /// A known unit of another dimension than the caller expected.
    #[error("expected {expected}, got {unit} ({got}) in {input:?}")]
    Mismatch {
        /// The dimension the caller expected.
        expected: Dimension,
        /// The dimension of the unit found.
        got: Dimension,
        /// The unit as written.
        unit: String,
        /// The whole input.
        input: String,
    },
    /// Printing a quantity in a unit of another dimension.
    #[error("cannot express {value} in {unit} ({got})")]
    WrongUnit {
        /// The dimension of the value.
        value: Dimension,
        /// The unit asked for.
        unit: &'static str,
        /// The dimension of that unit.
        got: Dimension,
    },
}

/// The canonical names of a dimension's units, comma separated.
fn unit_list(dimension: Dimension) -> String {
    dimension
        .units()
        .map(Unit::name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// The tail of a missing-unit message.
fn missing_hint(expected: Option<Dimension>) -> String {
    match expected {
        Some(d) => format!(" (expected {d}: {})", unit_list(d)),
        None => String::new(),
    }
}

/// The tail of an unknown-unit message: where, then suggestions or the accepted units.
fn unknown_hint(
    unit: &str,
    input: &str,
    suggestions: &[&'static str],
    expected: Option<Dimension>,
) -> String {
    let mut s = String::new();
    if input.trim() != unit {
        s.push_str(&format!(" in {input:?}"));
    }
    if !suggestions.is_empty() {
        s.push_str(&format!("; did you mean {}?", suggestions.join(", ")));
    } else if let Some(d) = expected {
        s.push_str(&format!("; accepted units for {d}: {}", unit_list(d)));
    }
    s
}

// ---------------------------------------------------------------------------------------
// Lookup.

/// Rewrites a unit spelling into the table's form: drops spaces next to `/ ^ ( )`, reads
/// `µ`/`μ` as `u`, `°` as `deg`, `²` as `^2`, `√x` as `sqrt(x)`. Other spaces stay (so that
/// `"m s"` is not silently read as `ms`).
fn normalize(text: &str) -> String {
    const JOINERS: &[char] = &['/', '^', '(', ')'];
    let mut out = String::with_capacity(text.len() + 8);
    let mut chars = text.trim().chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            c if c.is_whitespace() => {
                while chars.next_if(|c| c.is_whitespace()).is_some() {}
                let next_joins = chars.peek().is_some_and(|n| JOINERS.contains(n));
                let prev_joins = out.ends_with(JOINERS);
                if !next_joins && !prev_joins {
                    out.push(' ');
                }
            }
            'µ' | 'μ' => out.push('u'),
            '°' => out.push_str("deg"),
            '²' => out.push_str("^2"),
            '√' => {
                while chars.next_if(|c| c.is_whitespace()).is_some() {}
                if chars.peek() == Some(&'(') {
                    out.push_str("sqrt");
                } else {
                    out.push_str("sqrt(");
                    while let Some(n) = chars.next_if(|c| c.is_alphanumeric()) {
                        out.push(n);
                    }
                    out.push(')');
                }
            }
            c => out.push(c),
        }
    }
    out
}

/// Levenshtein distance between two strings, by characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let sub = diag + usize::from(ca != cb);
            diag = row[j + 1];
            row[j + 1] = sub.min(row[j] + 1).min(diag + 1);
        }
    }
    row[b.len()]
}

/// Canonical names of the units spelled most like `name` (case-insensitive edit distance,
/// at most 1 + len/4; ties kept, at most four); only units of `expected` when given.
fn suggestions(name: &str, expected: Option<Dimension>) -> Vec<&'static str> {
    let lower = name.to_lowercase();
    let limit = 1 + lower.chars().count() / 4;
    let mut found: Vec<(usize, usize, &'static str)> = Vec::new();
    for (row, e) in TABLE.iter().enumerate() {
        if expected.is_some_and(|d| d != e.unit.dimension) {
            continue;
        }
        let best = std::iter::once(e.unit.name)
            .chain(e.aliases.iter().copied())
            .map(|spelling| edit_distance(&lower, &spelling.to_lowercase()))
            .min()
            .unwrap_or(usize::MAX);
        if best <= limit {
            found.push((best, row, e.unit.name));
        }
    }
    found.sort_unstable();
    let best = found.first().map_or(0, |f| f.0);
    found
        .into_iter()
        .take_while(|f| f.0 == best)
        .take(4)
        .map(|(_, _, n)| n)
        .collect()
}

/// Finds the unit spelled `text` (part of `input`); on failure suggests similar units.
fn lookup(text: &str, input: &str, expected: Option<Dimension>) -> Result<Unit, UnitError> {
    let name = normalize(text);
    TABLE
        .iter()
        .find(|e| e.unit.name == name || e.aliases.contains(&name.as_str()))
        .map(|e| e.unit)
        .ok_or_else(|| UnitError::UnknownUnit {
            unit: text.trim().to_owned(),
            input: input.to_owned(),
            suggestions: suggestions(&name, expected),
            expected,
        })
}

// ---------------------------------------------------------------------------------------
// Parsing.

/// A value in SI with its dimension, as parsed from `"0.01 deg/h"`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantity {
    /// The value in the SI unit of `dimension` (rad, rad/s, m/s^2, ...).
    pub value_si: f64,
    /// What the value measures.
    pub dimension: Dimension,
}

impl Quantity {
    /// A quantity from an SI value and its dimension.
    pub fn new(value_si: f64, dimension: Dimension) -> Quantity {
        Quantity {
            value_si,
            dimension,
        }
    }

    /// Parses `"<number>[ ]<unit>"`; same as the module's [`parse`].
    pub fn parse(s: &str) -> Result<Quantity, UnitError> {
        parse(s)
    }

    /// The value expressed in `unit`, which must be of the same dimension.
    pub fn value_in(&self, unit: &str) -> Result<f64, UnitError> {
        Ok(self.checked_unit(unit)?.from_si(self.value_si))
    }

    /// A `Display`-able form of the value in `unit`, which must be of the same dimension.
    pub fn format_in(&self, unit: &str) -> Result<InUnit, UnitError> {
        Ok(self.checked_unit(unit)?.show(self.value_si))
    }

    /// Looks `unit` up and checks that it measures this quantity's dimension.
    fn checked_unit(&self, unit: &str) -> Result<Unit, UnitError> {
        let u = lookup(unit, unit, Some(self.dimension))?;
        if u.dimension != self.dimension {
            return Err(UnitError::WrongUnit {
                value: self.dimension,
                unit: u.name,
                got: u.dimension,
            });
        }
        Ok(u)
    }
}

impl fmt::Display for Quantity {
    /// Writes the value in its SI unit, `"1.5 rad/s"` (just the number for a ratio).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.dimension {
            Dimension::Dimensionless => write_number(f, self.value_si),
            d => {
                write_number(f, self.value_si)?;
                write!(f, " {}", d.si_name())
            }
        }
    }
}

impl FromStr for Quantity {
    type Err = UnitError;

    /// Same as the module's [`parse`].
    fn from_str(s: &str) -> Result<Quantity, UnitError> {
        parse(s)
    }
}

/// Length of the decimal number at the start of `s`: `[+-] digits [. digits] [e [+-] digits]`
/// with at least one mantissa digit; 0 if there is none.
fn number_len(s: &str) -> usize {
    let b = s.as_bytes();
    let digits_from = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let int_end = digits_from(i);
    let mut mantissa_digits = int_end - i;
    i = int_end;
    if b.get(i) == Some(&b'.') {
        let frac_end = digits_from(i + 1);
        mantissa_digits += frac_end - (i + 1);
        i = frac_end;
    }
    if mantissa_digits == 0 {
        return 0;
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let j = i + 1 + usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let exp_end = digits_from(j);
        if exp_end > j {
            i = exp_end;
        }
    }
    i
}

/// Parses `s` into a quantity; with `expected`, unknown-unit hints use that dimension; with
/// `bare_si`, a number without a unit is taken as SI of `expected`.
fn parse_impl(s: &str, expected: Option<Dimension>, bare_si: bool) -> Result<Quantity, UnitError> {
    let text = s.trim();
    if text.is_empty() {
        return Err(UnitError::Empty);
    }
    let unsigned = text.trim_start_matches(['+', '-']);
    let lower_start = unsigned.get(..3).map(str::to_ascii_lowercase);
    if matches!(lower_start.as_deref(), Some("nan" | "inf")) {
        return Err(UnitError::NonFinite {
            input: s.to_owned(),
        });
    }
    let bad_number = || UnitError::BadNumber {
        input: s.to_owned(),
    };
    let n = number_len(text);
    let (number, rest) = text.split_at(n);
    // A number running on into digits, dots or signs ("1.2.3", "1,5", "1e5-2") is malformed,
    // not a number followed by a strange unit.
    if n == 0 || rest.starts_with(|c: char| c.is_ascii_digit() || ".,_+-".contains(c)) {
        return Err(bad_number());
    }
    let value: f64 = number.parse().map_err(|_| bad_number())?;
    if !value.is_finite() {
        return Err(UnitError::NonFinite {
            input: s.to_owned(),
        });
    }
    let unit_text = rest.trim();
    if unit_text.is_empty() {
        return match (bare_si, expected) {
            (true, Some(dimension)) => Ok(Quantity::new(value, dimension)),
            _ => Err(UnitError::MissingUnit {
                input: s.to_owned(),
                expected,
            }),
        };
    }
    let unit = lookup(unit_text, s, expected)?;
    let value_si = unit.to_si(value);
    if !value_si.is_finite() {
        return Err(UnitError::NonFinite {
            input: s.to_owned(),
        });
    }
    Ok(Quantity::new(value_si, unit.dimension))
}

/// Parses `"<number>[ ]<unit>"` (`"0.01 deg/h"`, `"20arcsec"`) into an SI value and its dimension.
pub fn parse(s: &str) -> Result<Quantity, UnitError> {
    parse_impl(s, None, false)
}

/// Parses a quantity that must have dimension `expected`, returning its SI value.
pub fn parse_as(s: &str, expected: Dimension) -> Result<f64, UnitError> {
    checked(s, parse_impl(s, Some(expected), false)?, expected)
}

/// Like [`parse_as`], but a bare number (`"1e-5"`) is accepted as already SI.
pub fn parse_as_or_si(s: &str, expected: Dimension) -> Result<f64, UnitError> {
    checked(s, parse_impl(s, Some(expected), true)?, expected)
}

/// Returns the SI value of `q` if it has dimension `expected`, else a mismatch error.
fn checked(s: &str, q: Quantity, expected: Dimension) -> Result<f64, UnitError> {
    if q.dimension == expected {
        return Ok(q.value_si);
    }
    // The quantity parsed, so the text after the number is a known unit.
    let text = s.trim();
    let unit = text[number_len(text)..].trim().to_owned();
    Err(UnitError::Mismatch {
        expected,
        got: q.dimension,
        unit,
        input: s.to_owned(),
    })
}

// ---------------------------------------------------------------------------------------
// Printing.

/// An SI value shown in a unit: `Display` writes `"<number> <unit>"`, e.g. `"0.01 deg/h"`.
///
/// Without a precision the number is the shortest decimal that parses back to exactly the
/// same SI value when possible (else the shortest round trip of the converted value), in
/// plain notation for magnitudes in [1e-5, 1e16) and exponent notation otherwise. With a
/// precision (`{:.3}`) the converted value is printed with that many decimals. A width pads
/// the whole text with spaces. NaN and infinities print as `NaN`/`inf` (and do not parse).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InUnit {
    /// The value in SI.
    pub value_si: f64,
    /// The unit to print it in.
    pub unit: Unit,
}

impl InUnit {
    /// The value converted to the unit, as printed (shortest form, see the type's doc).
    pub fn value(&self) -> f64 {
        let unit = self.unit;
        let v = unit.from_si(self.value_si);
        if !v.is_finite() || v == 0.0 || (unit.mul == 1.0 && unit.div == 1.0) {
            return v;
        }
        // Prefer the shortest decimal d with to_si(d) == value_si, exactly what parsing
        // computes; 17 significant digits always round-trip v itself.
        (1..17)
            .filter_map(|digits| format!("{:.*e}", digits - 1, v).parse::<f64>().ok())
            .find(|&d| unit.to_si(d) == self.value_si)
            .unwrap_or(v)
    }
}

/// Writes a number in plain notation for magnitudes in [1e-5, 1e16), else in exponent form.
fn write_number(f: &mut impl fmt::Write, v: f64) -> fmt::Result {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-5..1e16).contains(&a) {
        write!(f, "{v}")
    } else {
        write!(f, "{v:e}")
    }
}

impl fmt::Display for InUnit {
    /// Writes `"<number> <unit>"`; honours precision and (space-padded) width and alignment.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut s = String::new();
        match f.precision() {
            Some(p) => {
                let v = self.unit.from_si(self.value_si);
                fmt::Write::write_fmt(&mut s, format_args!("{v:.p$}"))?;
            }
            None => write_number(&mut s, self.value())?,
        }
        s.push(' ');
        s.push_str(self.unit.name);
        match (f.width(), f.align()) {
            (None, _) => f.write_str(&s),
            (Some(w), Some(fmt::Alignment::Left)) => write!(f, "{s:<w$}"),
            (Some(w), Some(fmt::Alignment::Center)) => write!(f, "{s:^w$}"),
            (Some(w), _) => write!(f, "{s:>w$}"),
        }
    }
}

/// A `Display`-able SI value in the named unit: `format_in(0.01 * DEG_PER_H, "deg/h")` shows `"0.01 deg/h"`.
pub fn format_in(value_si: f64, unit: &str) -> Result<InUnit, UnitError> {
    Ok(Unit::parse(unit)?.show(value_si))
}

/// Prints an SI value in the named unit: `format(20.0 * ARCSEC, "arcsec")` is `"20 arcsec"`.
pub fn format(value_si: f64, unit: &str) -> Result<String, UnitError> {
    Ok(format_in(value_si, unit)?.to_string())
}

// ---------------------------------------------------------------------------------------

#[cfg(test)]
#[allow(
    clippy::excessive_precision,
    reason = "hand values carry the digits of the exact value, independent of f64 rounding"
)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Relative closeness; `tol` is stated at each call.
    fn close(a: f64, b: f64, tol: f64) -> bool {
        a == b || (a - b).abs() <= tol * a.abs().max(b.abs())
    }

    /// Every unit, one value each, with the SI result written out by hand from the unit's
    /// definition (pi/180 = 0.0174532925199432957692..., g0 = 9.80665, 1852 m, 0.3048 m).
    /// Tolerance: relative 1e-15. Each case is a pure scale factor; the factor is a constant
    /// folded from at most two roundings (e.g. (pi/180)/3600) and parsing adds one product,
    /// so the result is within ~3 ulp (3 * 1.1e-16) of the exact value.
    const CASES: &[(&str, f64, Dimension)] = {
        use Dimension as D;
        &[
            // Angle
            ("1 rad", 1.0, D::Angle),
            ("2.5 mrad", 2.5e-3, D::Angle),
            ("7 urad", 7e-6, D::Angle),
            ("1 deg", 0.017_453_292_519_943_295_77, D::Angle),
            ("1 arcmin", 2.908_882_086_657_215_961_5e-4, D::Angle),
            ("20 arcsec", 9.696_273_622_190_719_871_8e-5, D::Angle),
            // Angular rate
            ("1 rad/s", 1.0, D::AngularRate),
            ("1 deg/s", 0.017_453_292_519_943_295_77, D::AngularRate),
            ("1 deg/min", 2.908_882_086_657_215_961_5e-4, D::AngularRate),
            ("1 deg/h", 4.848_136_811_095_359_935_9e-6, D::AngularRate),
            // Angle random walk
            ("1 rad/sqrt(s)", 1.0, D::AngleRandomWalk),
            (
                "1 deg/sqrt(s)",
                0.017_453_292_519_943_295_77,
                D::AngleRandomWalk,
            ),
            (
                "1 deg/sqrt(h)",
                2.908_882_086_657_215_961_5e-4,
                D::AngleRandomWalk,
            ),
            ("1 rad/s/sqrt(Hz)", 1.0, D::AngleRandomWalk),
            (
                "1 deg/s/sqrt(Hz)",
                0.017_453_292_519_943_295_77,
                D::AngleRandomWalk,
            ),
            (
                "1 deg/h/sqrt(Hz)",
                4.848_136_811_095_359_935_9e-6,
                D::AngleRandomWalk,
            ),
            // Velocity random walk
            ("1 m/s/sqrt(s)", 1.0, D::VelocityRandomWalk),
            (
                "1 m/s/sqrt(h)",
                0.016_666_666_666_666_666_667,
                D::VelocityRandomWalk,
            ),
            ("1 ft/s/sqrt(h)", 0.00508, D::VelocityRandomWalk),
            ("1 m/s^2/sqrt(Hz)", 1.0, D::VelocityRandomWalk),
            ("1 g/sqrt(Hz)", 9.80665, D::VelocityRandomWalk),
            ("1 mg/sqrt(Hz)", 9.80665e-3, D::VelocityRandomWalk),
            ("1 ug/sqrt(Hz)", 9.80665e-6, D::VelocityRandomWalk),
            // Rate random walk
            ("1 rad/s/sqrt(s)", 1.0, D::RateRandomWalk),
            (
                "1 deg/s/sqrt(s)",
                0.017_453_292_519_943_295_77,
                D::RateRandomWalk,
            ),
            (
                "1 deg/h/sqrt(h)",
                8.080_228_018_492_266_559_8e-8,
                D::RateRandomWalk,
            ),
            // Acceleration random walk
            ("1 m/s^2/sqrt(s)", 1.0, D::AccelerationRandomWalk),
            (
                "1 m/s^2/sqrt(h)",
                0.016_666_666_666_666_666_667,
                D::AccelerationRandomWalk,
            ),
            (
                "1 m/s/h/sqrt(h)",
                4.629_629_629_629_629_629_6e-6,
                D::AccelerationRandomWalk,
            ),
            (
                "1 mg/sqrt(h)",
                1.634_441_666_666_666_666_7e-4,
                D::AccelerationRandomWalk,
            ),
            (
                "1 ug/sqrt(h)",
                1.634_441_666_666_666_666_7e-7,
                D::AccelerationRandomWalk,
            ),
            // Gyro g-sensitivity
            ("1 rad/s/(m/s^2)", 1.0, D::GSensitivity),
            ("1 rad/s/g", 0.101_971_621_297_792_824_26, D::GSensitivity),
            ("1 deg/s/g", 1.779_740_535_243_257_969_8e-3, D::GSensitivity),
            ("1 deg/h/g", 4.943_723_709_009_049_916e-7, D::GSensitivity),
            // Acceleration
            ("1e-3 m/s^2", 1e-3, D::Acceleration),
            ("1 g", 9.80665, D::Acceleration),
            ("-3.5e-2 mg", -3.432_327_5e-4, D::Acceleration),
            ("25 ug", 2.451_662_5e-4, D::Acceleration),
            ("1 Gal", 0.01, D::Acceleration),
            ("15 mGal", 1.5e-4, D::Acceleration),
            ("3 uGal", 3e-8, D::Acceleration),
            ("1 ft/s^2", 0.3048, D::Acceleration),
            // Dimensionless
            ("100 ppm", 1e-4, D::Dimensionless),
            ("5 ppb", 5e-9, D::Dimensionless),
            ("2 %", 0.02, D::Dimensionless),
            // Time
            ("1 s", 1.0, D::Time),
            ("5 ms", 5e-3, D::Time),
            ("5 us", 5e-6, D::Time),
            ("1 min", 60.0, D::Time),
            ("1 h", 3600.0, D::Time),
            // Length
            ("1 m", 1.0, D::Length),
            ("1 mm", 1e-3, D::Length),
            ("1 km", 1000.0, D::Length),
            ("1 ft", 0.3048, D::Length),
            ("1 nmi", 1852.0, D::Length),
            // Velocity
            ("1 m/s", 1.0, D::Velocity),
            ("1 km/h", 0.277_777_777_777_777_777_78, D::Velocity),
            ("1 kn", 0.514_444_444_444_444_444_44, D::Velocity),
            ("1 nmi/h", 0.514_444_444_444_444_444_44, D::Velocity),
            ("1 ft/s", 0.3048, D::Velocity),
        ]
    };

    #[test]
    fn every_unit_matches_its_hand_written_value() {
        for &(s, want, dimension) in CASES {
            let q = parse(s).unwrap_or_else(|e| panic!("{s}: {e}"));
            assert_eq!(q.dimension, dimension, "{s}");
            assert!(
                close(q.value_si, want, 1e-15),
                "{s}: {} vs {want}",
                q.value_si
            );
            assert_eq!(parse_as(s, dimension), Ok(q.value_si), "{s}");
        }
    }

    #[test]
    fn every_unit_has_a_hand_written_case() {
        for u in Unit::all() {
            let covered = CASES
                .iter()
                .any(|(s, _, _)| s.split_once(' ').is_some_and(|(_, n)| n == u.name()));
            assert!(covered, "no hand-written case for {}", u.name());
        }
    }

    #[test]
    fn names_and_aliases_are_unique_and_already_normalized() {
        let mut seen = std::collections::HashSet::new();
        for e in TABLE {
            for &n in std::iter::once(&e.unit.name).chain(e.aliases) {
                assert!(seen.insert(n), "{n} appears twice");
                assert_eq!(normalize(n), n, "{n} is not in normalized form");
            }
        }
        for d in Dimension::ALL {
            let first = d.units().next().map(Unit::name);
            if d != Dimension::Dimensionless {
                assert_eq!(first, Some(d.si_name()), "SI unit first for {d}");
            }
        }
    }

    #[test]
    fn the_constants_are_the_hand_written_values() {
        // Same values and 1e-15 relative tolerance as CASES (pure scale factors).
        let pairs = [
            (G0, 9.80665),
            (DEG, 0.017_453_292_519_943_295_77),
            (ARCSEC, 4.848_136_811_095_359_935_9e-6),
            (DEG_PER_H, 4.848_136_811_095_359_935_9e-6),
            (DEG_PER_SQRT_H, 2.908_882_086_657_215_961_5e-4),
            (M_PER_S_PER_SQRT_H, 0.016_666_666_666_666_666_667),
            (DEG_PER_H_PER_SQRT_H, 8.080_228_018_492_266_559_8e-8),
            (DEG_PER_H_PER_G, 4.943_723_709_009_049_916e-7),
            (MGAL, 1e-5),
            (MG, 9.80665e-3),
            (UG, 9.80665e-6),
            (PPM, 1e-6),
            (NMI, 1852.0),
            (KNOT, 0.514_444_444_444_444_444_44),
        ];
        for (got, want) in pairs {
            assert!(close(got, want, 1e-15), "{got} vs {want}");
        }
        // Each constant is, bit for bit, the factor of its unit in the table.
        let named = [
            (DEG, "deg"),
            (ARCMIN, "arcmin"),
            (ARCSEC, "arcsec"),
            (MRAD, "mrad"),
            (URAD, "urad"),
            (DEG_PER_S, "deg/s"),
            (DEG_PER_MIN, "deg/min"),
            (DEG_PER_H, "deg/h"),
            (DEG_PER_SQRT_H, "deg/sqrt(h)"),
            (DEG_PER_H_PER_SQRT_HZ, "deg/h/sqrt(Hz)"),
            (M_PER_S_PER_SQRT_H, "m/s/sqrt(h)"),
            (DEG_PER_H_PER_SQRT_H, "deg/h/sqrt(h)"),
            (DEG_PER_H_PER_G, "deg/h/g"),
            (G0, "g"),
            (MG, "mg"),
            (UG, "ug"),
            (UG, "ug/sqrt(Hz)"),
            (GAL, "Gal"),
            (MGAL, "mGal"),
            (UGAL, "uGal"),
            (PPM, "ppm"),
            (PPB, "ppb"),
            (PERCENT, "%"),
            (MINUTE, "min"),
            (HOUR, "h"),
            (NMI, "nmi"),
            (FT, "ft"),
            (KM_PER_H, "km/h"),
            (KNOT, "kn"),
            (KNOT, "nmi/h"),
        ];
        for (constant, name) in named {
            assert_eq!(Unit::parse(name).map(Unit::factor), Ok(constant), "{name}");
        }
        // DEG is the correctly rounded pi/180, bit for bit what f64::to_radians uses.
        assert_eq!(
            DEG,
            std::f64::consts::PI.to_radians() / std::f64::consts::PI
        );
    }

    #[test]
    fn spelling_variants() {
        let same = [
            ("20arcsec", "20 arcsec"),
            ("0.01deg/h", "0.01 deg/h"),
            ("0.01 deg/hr", "0.01 deg/h"),
            ("0.01 °/h", "0.01 deg/h"),
            ("0.01°/hr", "0.01 deg/h"),
            ("0.01 dph", "0.01 deg/h"),
            ("3 °", "3 deg"),
            ("0.003 deg/sqrt(hr)", "0.003 deg/sqrt(h)"),
            ("0.003 °/√h", "0.003 deg/sqrt(h)"),
            ("0.003 deg / sqrt( h )", "0.003 deg/sqrt(h)"),
            ("0.18 deg/h/sqrt(Hz)", "0.18 deg/h/sqrt(Hz)"),
            ("0.18 °/hr/√Hz", "0.18 deg/h/sqrt(Hz)"),
            ("25 µg", "25 ug"),
            ("25 μg", "25 ug"),
            ("25µg/√Hz", "25 ug/sqrt(Hz)"),
            ("1 m/s2", "1 m/s^2"),
            ("1 m/s/s", "1 m/s^2"),
            ("1 m/s²", "1 m/s^2"),
            ("1 m / s ^ 2", "1 m/s^2"),
            ("  1 m/s  ", "1 m/s"),
            ("+1 m/s", "1 m/s"),
            (".5 h", "0.5 h"),
            ("5. h", "5 h"),
            ("1E3 m", "1 km"),
            ("100%", "1e6 ppm"),
        ];
        for (a, b) in same {
            let (qa, qb) = (parse(a), parse(b));
            assert!(qa.is_ok(), "{a}: {qa:?}");
            assert_eq!(qa, qb, "{a} vs {b}");
        }
    }

    #[test]
    fn bare_numbers_only_where_si_is_the_default() {
        assert_eq!(parse_as_or_si("1e-5", Dimension::Acceleration), Ok(1e-5));
        assert_eq!(parse_as_or_si(" -2 ", Dimension::Angle), Ok(-2.0));
        assert_eq!(
            parse_as_or_si("15 mGal", Dimension::Acceleration),
            Ok(1.5e-4)
        );
        assert_eq!(
            parse("3"),
            Err(UnitError::MissingUnit {
                input: "3".into(),
                expected: None
            })
        );
        assert_eq!(
            parse_as("3", Dimension::Time).map_err(|e| e.to_string()),
            Err("missing unit in \"3\" (expected a time: s, ms, us, min, h)".into())
        );
    }

    #[test]
    fn mismatch_message() {
        let e = parse_as("3 m/s^2", Dimension::AngularRate).unwrap_err();
        assert_eq!(
            e.to_string(),
            "expected an angular rate, got m/s^2 (an acceleration) in \"3 m/s^2\""
        );
        let e = parse_as_or_si("20arcsec", Dimension::Time).unwrap_err();
        assert_eq!(
            e.to_string(),
            "expected a time, got arcsec (an angle) in \"20arcsec\""
        );
    }

    #[test]
    fn unknown_unit_messages() {
        let msg = |r: Result<f64, UnitError>| r.map_err(|e| e.to_string());
        assert_eq!(
            msg(parse("0.1 deg/hh").map(|q| q.value_si)),
            Err("unknown unit \"deg/hh\" in \"0.1 deg/hh\"; did you mean deg/h?".into())
        );
        assert_eq!(
            msg(parse_as("15 mgal", Dimension::Acceleration)),
            Err("unknown unit \"mgal\" in \"15 mgal\"; did you mean mGal?".into())
        );
        assert_eq!(
            msg(parse_as("1 furlong", Dimension::Velocity)),
            Err(
                "unknown unit \"furlong\" in \"1 furlong\"; accepted units for a velocity: \
                 m/s, km/h, kn, nmi/h, ft/s"
                    .into()
            )
        );
        assert_eq!(
            Unit::parse("furlong").map_err(|e| e.to_string()),
            Err("unknown unit \"furlong\"".into())
        );
        assert_eq!(
            format(1.0, "degs").map_err(|e| e.to_string()),
            Err("unknown unit \"degs\"; did you mean deg, deg/s?".into())
        );
        // "m s" is not read as "ms".
        assert!(matches!(parse("1 m s"), Err(UnitError::UnknownUnit { .. })));
    }

    #[test]
    fn bad_input_errors() {
        use UnitError as E;
        let bad = |s: &str| E::BadNumber { input: s.into() };
        let nonfinite = |s: &str| E::NonFinite { input: s.into() };
        assert_eq!(parse(""), Err(E::Empty));
        assert_eq!(parse(" \t "), Err(E::Empty));
        for s in ["deg", "- 1 m", ".m", "1.2.3 m", "1,5 m", "e5 m", "--1 m"] {
            assert_eq!(parse(s), Err(bad(s)), "{s}");
        }
        for s in [
            "NaN m",
            "nan",
            "inf deg",
            "-Infinity s",
            "1e999 m",
            "1e308 km",
        ] {
            assert_eq!(parse(s), Err(nonfinite(s)), "{s}");
        }
        assert_eq!(
            parse("").map_err(|e| e.to_string()),
            Err("empty quantity: expected a number and a unit, like \"0.01 deg/h\"".into())
        );
        assert_eq!(
            parse("inf m").map_err(|e| e.to_string()),
            Err("not a finite number in \"inf m\"".into())
        );
    }

    #[test]
    fn printing() {
        let f = |v: f64, u: &str| format(v, u).unwrap_or_else(|e| e.to_string());
        assert_eq!(f(0.01 * DEG_PER_H, "deg/h"), "0.01 deg/h");
        assert_eq!(f(20.0 * ARCSEC, "arcsec"), "20 arcsec");
        assert_eq!(
            f(0.003 * DEG_PER_SQRT_H, "deg/sqrt(h)"),
            "0.003 deg/sqrt(h)"
        );
        assert_eq!(f(1.5e-4, "mGal"), "15 mGal");
        assert_eq!(f(1e-4, "ppm"), "100 ppm");
        assert_eq!(f(KNOT, "nmi/h"), "1 nmi/h");
        assert_eq!(f(-3.5e-2 * MG, "mg"), "-0.035 mg");
        assert_eq!(f(0.0, "deg"), "0 deg");
        assert_eq!(f(1e-20, "rad"), "1e-20 rad");
        assert_eq!(f(2.5e20, "m"), "2.5e20 m");
        assert_eq!(f(1.0, "°"), "57.29577951308232 deg");
        let shown = format_in(DEG, "deg").map(|d| format!("[{d:.2}] [{d:>10}] [{d:<8}]"));
        assert_eq!(shown, Ok("[1.00 deg] [     1 deg] [1 deg   ]".into()));
        let q = Quantity::new(0.5, Dimension::AngularRate);
        assert_eq!(q.to_string(), "0.5 rad/s");
        assert_eq!(
            q.format_in("deg").map_err(|e| e.to_string()),
            Err("cannot express an angular rate in deg (an angle)".into())
        );
        assert_eq!(q.value_in("rad/s"), Ok(0.5));
    }

    #[test]
    fn dimension_words() {
        let words: Vec<String> = Dimension::ALL.iter().map(|d| d.to_string()).collect();
        assert_eq!(
            words,
            [
                "an angle",
                "an angular rate",
                "an angle random walk",
                "a velocity random walk",
                "a rate random walk",
                "an acceleration random walk",
                "a g-sensitivity (angular rate per acceleration)",
                "an acceleration",
                "a dimensionless ratio",
                "a time",
                "a length",
                "a velocity",
            ]
        );
    }

    /// Any unit of the table, by index.
    fn any_unit() -> impl Strategy<Value = Unit> {
        let units: Vec<Unit> = Unit::all().collect();
        (0..units.len()).prop_map(move |i| units[i])
    }

    /// Finite values over a wide range of magnitudes, both signs, and zero.
    fn any_value() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(0.0),
            (-1e6..1e6f64),
            (any::<bool>(), -100.0..100.0f64).prop_map(|(neg, e)| {
                let v = 10f64.powf(e);
                if neg { -v } else { v }
            }),
        ]
    }

    proptest! {
        /// parse(format(x, u)) == x within relative 1e-15: when an exact decimal exists
        /// printing finds it; otherwise converting there and back costs at most ~4 roundings.
        #[test]
        fn format_then_parse_round_trips(u in any_unit(), x in any_value()) {
            let text = format(x, u.name()).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let back = parse_as(&text, u.dimension());
            prop_assert!(back.is_ok(), "{text}: {back:?}");
            let back = back.unwrap_or(f64::NAN);
            prop_assert!(close(back, x, 1e-15), "{x} -> {text} -> {back}");
        }

        /// With and without a space, the same SI value: `Unit::to_si` of the number.
        #[test]
        fn space_is_optional(u in any_unit(), v in any_value()) {
            let spaced = parse(&format!("{v} {}", u.name()));
            let tight = parse(&format!("{v}{}", u.name()));
            prop_assert_eq!(&spaced, &tight);
            prop_assert_eq!(spaced, Ok(Quantity::new(u.to_si(v), u.dimension())));
        }

        /// Arbitrary text never panics.
        #[test]
        fn arbitrary_strings_do_not_panic(s in any::<String>()) {
            let _ = parse(&s);
            let _ = parse_as_or_si(&s, Dimension::Angle);
            let _ = Unit::parse(&s);
            let _ = format(1.0, &s);
        }

        /// Unit-like text (numbers, unit letters, symbols) never panics either.
        #[test]
        fn unit_like_strings_do_not_panic(s in "[-+0-9.eE µμ°√²a-zA-Z/^()%,_]{0,24}") {
            if let Ok(q) = parse(&s) {
                prop_assert!(q.value_si.is_finite());
            }
            let _ = parse_as(&s, Dimension::AngularRate);
            let _ = parse_as_or_si(&s, Dimension::Dimensionless);
        }
    }
}
