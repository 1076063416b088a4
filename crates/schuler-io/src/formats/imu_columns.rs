//! The columns of an IMU log: the names a CSV header or `--imu-columns` may give them,
//! the units of the sensor and time columns, and the plan that maps a line's fields to
//! time, gyro x y z and accelerometer x y z.
//!
//! # Names
//! A name is matched ASCII case-insensitively after dropping blanks, `_`, `.`, `-`,
//! `/`, `^`, brackets and a leading `field.` (ROS `rostopic echo -p`): `gyro_x`,
//! `GyroX`, `gyro.x` and `field.angular_velocity.x` alike. A sensor name is a base, an
//! axis letter `x`, `y` or `z`, and optionally a unit:
//!
//! | what | bases | holds |
//! |---|---|---|
//! | angular rate | `w`, `omega`, `angular_velocity`, `angular_rate` | rates |
//! | specific force | `f`, `specific_force`, `acceleration`, `linear_acceleration` | rates |
//! | gyro | `gyro`, `gyr`, `g` | rates, unless the unit is an angle |
//! | accelerometer | `acc`, `accel`, `a` | rates, unless the unit is m/s |
//! | angle increment | `dtheta`, `dt`, `delta_theta`, `dangle`, `delta_angle` | increments |
//! | velocity increment | `dvel`, `dv`, `delta_v`, `delta_vel`, `delta_velocity` | increments |
//!
//! Units in names: `rad_s`, `rads`, `radps`, `deg_s`, `dps`, `degps` (rates), `rad`,
//! `deg` (increments; after `gyro`/`gyr`/`g` ambiguous with a rate, so the unit must
//! then be given by `--gyro-unit`), `m_s2`, `mps2`, `m_s_2`, `mss`, `g` (rates),
//! `m_s`, `mps` (increments), also in brackets (`gyro_x [deg/s]`). Time: `t`, `time`,
//! `timestamp`, optionally with `s`, `ms`, `us`, `ns` (`time_ms`, `timestamp [ns]`);
//! where several are present, `t` wins over `time` over `timestamp`.
//!
//! A name that says rates and a unit that says increments (`w_x_deg`), or the reverse,
//! is an error, as are units that contradict `--gyro-unit`, `--accel-unit`,
//! `--imu-time-unit` or `--imu-layout`.

use std::f64::consts::PI;
use std::fmt;

use serde::Deserialize;

use super::imu_log::{ImuLayout, STANDARD_GRAVITY};
use crate::named::Named;

/// Slot of the time in a parsed line (then gyro x, y, z in 1–3, accelerometer in 4–6).
pub(crate) const SLOT_TIME: u8 = 0;
/// First gyro slot.
const SLOT_GYRO: u8 = 1;
/// First accelerometer slot.
const SLOT_ACCEL: u8 = 4;
/// Marks a column the reader does not use.
pub(crate) const UNUSED: u8 = u8::MAX;

/// Canonical names of the slots for increments: time, gyro xyz, accelerometer xyz.
pub(crate) const INCREMENT_NAMES: [&str; 7] = [
    "t", "dtheta_x", "dtheta_y", "dtheta_z", "dvel_x", "dvel_y", "dvel_z",
];
/// Canonical names of the slots for rates.
pub(crate) const RATE_NAMES: [&str; 7] = ["t", "w_x", "w_y", "w_z", "f_x", "f_y", "f_z"];

/// What the reader recognises, for messages.
pub(crate) const RECOGNISED: &str = "time t, time, timestamp (units s, ms, us, ns: time_ms); \
     rates w_x, wx, omega_x, angular_velocity_x, gyro_x, gyr_x, gx and f_x, fx, \
     acceleration_x, linear_acceleration_x, acc_x, accel_x, ax; increments dtheta_x, dtx, \
     delta_theta_x and dvel_x, dvx, dv_x, delta_v_x; units in names such as gx_dps, \
     wx_rad_s, ax_g, acc_x_mps2";

/// Unit of the gyro columns: `rad/s` and `deg/s` are rates, `rad` and `deg` angle
/// increments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum GyroUnit {
    /// Radians per second (rates).
    #[serde(rename = "rad/s")]
    RadPerSecond,
    /// Degrees per second (rates).
    #[serde(rename = "deg/s")]
    DegPerSecond,
    /// Radians (increments).
    #[serde(rename = "rad")]
    Rad,
    /// Degrees (increments).
    #[serde(rename = "deg")]
    Deg,
}

impl GyroUnit {
    /// Rates or increments.
    pub fn layout(self) -> ImuLayout {
        match self {
            Self::RadPerSecond | Self::DegPerSecond => ImuLayout::Rates,
            Self::Rad | Self::Deg => ImuLayout::Increments,
        }
    }

    /// The factor to SI (rad/s or rad).
    pub fn to_si(self) -> f64 {
        match self {
            Self::RadPerSecond | Self::Rad => 1.0,
            Self::DegPerSecond | Self::Deg => PI / 180.0,
        }
    }

    /// The SI unit of a layout (rad/s or rad).
    pub fn si(layout: ImuLayout) -> Self {
        match layout {
            ImuLayout::Rates => Self::RadPerSecond,
            ImuLayout::Increments => Self::Rad,
        }
    }
}

impl Named for GyroUnit {
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (Self::RadPerSecond, "rad/s", "Radians per second (rates)"),
        (Self::DegPerSecond, "deg/s", "Degrees per second (rates)"),
        (Self::Rad, "rad", "Radians (increments)"),
        (Self::Deg, "deg", "Degrees (increments)"),
    ];
}

impl fmt::Display for GyroUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Unit of the accelerometer columns: `m/s^2` and `g` are rates (specific force),
/// `m/s` velocity increments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum AccelUnit {
    /// Metres per second squared (rates).
    #[serde(rename = "m/s^2")]
    MetrePerSecond2,
    /// Standard gravity g₀ = 9.80665 m/s² (rates).
    #[serde(rename = "g")]
    G,
    /// Metres per second (increments).
    #[serde(rename = "m/s")]
    MetrePerSecond,
}

impl AccelUnit {
    /// Rates or increments.
    pub fn layout(self) -> ImuLayout {
        match self {
            Self::MetrePerSecond2 | Self::G => ImuLayout::Rates,
            Self::MetrePerSecond => ImuLayout::Increments,
        }
    }

    /// The factor to SI (m/s² or m/s).
    pub fn to_si(self) -> f64 {
        match self {
            Self::MetrePerSecond2 | Self::MetrePerSecond => 1.0,
            Self::G => STANDARD_GRAVITY,
        }
    }

    /// The SI unit of a layout (m/s² or m/s).
    pub fn si(layout: ImuLayout) -> Self {
        match layout {
            ImuLayout::Rates => Self::MetrePerSecond2,
            ImuLayout::Increments => Self::MetrePerSecond,
        }
    }
}

impl Named for AccelUnit {
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            Self::MetrePerSecond2,
            "m/s^2",
            "Metres per second squared (rates)",
        ),
        (Self::G, "g", "Standard gravity g₀ = 9.80665 m/s² (rates)"),
        (
            Self::MetrePerSecond,
            "m/s",
            "Metres per second (increments)",
        ),
    ];
}

impl fmt::Display for AccelUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Unit of the time column: seconds, or integer ticks of ms, µs or ns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TimeUnit {
    /// Seconds.
    #[default]
    S,
    /// Milliseconds.
    Ms,
    /// Microseconds.
    Us,
    /// Nanoseconds.
    Ns,
}

impl Named for TimeUnit {
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (Self::S, "s", "Seconds"),
        (Self::Ms, "ms", "Milliseconds"),
        (Self::Us, "us", "Microseconds"),
        (Self::Ns, "ns", "Nanoseconds"),
    ];
}

impl TimeUnit {
    /// Ticks per second.
    pub fn ticks_per_second(self) -> i64 {
        match self {
            Self::S => 1,
            Self::Ms => 1_000,
            Self::Us => 1_000_000,
            Self::Ns => 1_000_000_000,
        }
    }
}

impl fmt::Display for TimeUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::S => "s",
            Self::Ms => "ms",
            Self::Us => "us",
            Self::Ns => "ns",
        })
    }
}

/// A unit written in a column's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NameUnit {
    /// None written.
    None,
    /// A time unit.
    Time(TimeUnit),
    /// A gyro unit.
    Gyro(GyroUnit),
    /// An accelerometer unit.
    Accel(AccelUnit),
    /// `deg` or `rad` after a base that does not say rates or increments: the angle,
    /// or its rate written loosely.
    GyroAngleOrRate(GyroUnit, GyroUnit),
}

/// A recognised column name: the slot it fills, rates or increments if the name says
/// so, its unit if written, and its rank among names for the same slot (lower wins).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct ColumnName {
    /// 0 time, 1–3 gyro x y z, 4–6 accelerometer x y z.
    pub slot: u8,
    /// Rates or increments, when the name (base or unit) says.
    pub layout: Option<ImuLayout>,
    /// The unit written in the name.
    pub unit: NameUnit,
    /// Rank among the names of the slot (time: `t` 0, `time` 1, `timestamp` 2).
    pub rank: u8,
}

/// Sensor bases: name, gyro (else accelerometer), what the base says.
const SENSOR_BASES: [(&str, bool, Option<ImuLayout>); 24] = {
    use ImuLayout::{Increments as I, Rates as R};
    [
        ("w", true, Some(R)),
        ("omega", true, Some(R)),
        ("angularvelocity", true, Some(R)),
        ("angularrate", true, Some(R)),
        ("gyro", true, None),
        ("gyr", true, None),
        ("g", true, None),
        ("dtheta", true, Some(I)),
        ("dt", true, Some(I)),
        ("deltatheta", true, Some(I)),
        ("dangle", true, Some(I)),
        ("deltaangle", true, Some(I)),
        ("f", false, Some(R)),
        ("specificforce", false, Some(R)),
        ("acceleration", false, Some(R)),
        ("linearacceleration", false, Some(R)),
        ("acc", false, None),
        ("accel", false, None),
        ("a", false, None),
        ("dvel", false, Some(I)),
        ("dv", false, Some(I)),
        ("deltav", false, Some(I)),
        ("deltavel", false, Some(I)),
        ("deltavelocity", false, Some(I)),
    ]
};

/// Time bases in rank order.
const TIME_BASES: [&str; 3] = ["t", "time", "timestamp"];

/// A name lower-cased, stripped of separators and a leading `field`.
fn normalized(name: &str) -> String {
    let text = name.trim().trim_matches('"').trim();
    let mut out: String = text
        .chars()
        .filter(|c| {
            !matches!(
                c,
                ' ' | '\t' | '_' | '.' | '-' | '/' | '^' | '[' | ']' | '(' | ')'
            )
        })
        .map(|c| c.to_ascii_lowercase())
        .collect();
    if let Some(rest) = out.strip_prefix("field")
        && !rest.is_empty()
    {
        out = rest.to_owned();
    }
    out
}

/// The time unit written as `rest` (after the base).
fn time_unit(rest: &str) -> Option<NameUnit> {
    Some(match rest {
        "" => NameUnit::None,
        "s" | "sec" => NameUnit::Time(TimeUnit::S),
        "ms" => NameUnit::Time(TimeUnit::Ms),
        "us" | "µs" => NameUnit::Time(TimeUnit::Us),
        "ns" => NameUnit::Time(TimeUnit::Ns),
        _ => return None,
    })
}

/// The sensor unit written as `rest` (after the axis) for a gyro or an accelerometer.
fn sensor_unit(rest: &str, gyro: bool) -> Option<NameUnit> {
    use GyroUnit::{Deg, DegPerSecond, Rad, RadPerSecond};
    Some(match (gyro, rest) {
        (_, "") => NameUnit::None,
        (true, "rads" | "radps" | "rads1" | "radpers") => NameUnit::Gyro(RadPerSecond),
        (true, "degs" | "dps" | "degps" | "degs1" | "degpers") => NameUnit::Gyro(DegPerSecond),
        (true, "rad") => NameUnit::GyroAngleOrRate(Rad, RadPerSecond),
        (true, "deg") => NameUnit::GyroAngleOrRate(Deg, DegPerSecond),
        (false, "ms2" | "mps2" | "mss" | "ms2s") => NameUnit::Accel(AccelUnit::MetrePerSecond2),
        (false, "g") => NameUnit::Accel(AccelUnit::G),
        (false, "ms" | "mps") => NameUnit::Accel(AccelUnit::MetrePerSecond),
        _ => return None,
    })
}

/// What a column name says, `Ok(None)` if it is not one the reader uses, or an error
/// if its name and unit contradict each other (`w_x_deg`: a rate in degrees).
pub(crate) fn recognise(name: &str) -> Result<Option<ColumnName>, String> {
    let n = normalized(name);
    for (rank, base) in TIME_BASES.iter().enumerate() {
        if let Some(unit) = n.strip_prefix(base).and_then(time_unit) {
            return Ok(Some(ColumnName {
                slot: SLOT_TIME,
                layout: None,
                unit,
                // At most 3 time bases.
                rank: rank as u8,
            }));
        }
    }
    for (base, gyro, says) in SENSOR_BASES {
        let Some(rest) = n.strip_prefix(base) else {
            continue;
        };
        let (axis, unit_text) = match rest.as_bytes().first() {
            Some(b'x') => (0, &rest[1..]),
            Some(b'y') => (1, &rest[1..]),
            Some(b'z') => (2, &rest[1..]),
            _ => continue,
        };
        let Some(unit) = sensor_unit(unit_text, gyro) else {
            continue;
        };
        let first = if gyro { SLOT_GYRO } else { SLOT_ACCEL };
        let by_unit = match unit {
            NameUnit::Gyro(u) => Some(u.layout()),
            NameUnit::Accel(u) => Some(u.layout()),
            NameUnit::GyroAngleOrRate(..) if says.is_some() => says,
            _ => None,
        };
        let layout = match (says, by_unit) {
            (Some(a), Some(b)) if a != b => {
                return Err(format!(
                    "column {name:?}: the name says {a} but its unit {} says {b}",
                    unit_text
                ));
            }
            (a, b) => a.or(b),
        };
        // An angle unit after a base that says rates or increments is no longer ambiguous.
        let unit = match (unit, layout) {
            (NameUnit::GyroAngleOrRate(angle, rate), Some(l)) => {
                NameUnit::Gyro(if l == ImuLayout::Increments {
                    angle
                } else {
                    rate
                })
            }
            (u, _) => u,
        };
        return Ok(Some(ColumnName {
            slot: first + axis,
            layout,
            unit,
            rank: 0,
        }));
    }
    Ok(None)
}

/// `--imu-columns`: the column order of a file (without header, or with a header the
/// reader is told to skip), e.g. `t,fx,fy,fz,wx,wy,wz`; `_` skips a column and a last
/// `...` allows further columns.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnSpec {
    /// The names as given, one per column.
    names: Vec<String>,
    /// What each column holds (`None`: skipped).
    columns: Vec<Option<ColumnName>>,
    /// Whether further columns after these are allowed (a last `...`).
    trailing: bool,
}

impl ColumnSpec {
    /// Parses a comma-separated list of column names; the error says what is wrong.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut names: Vec<String> = text.split(',').map(|s| s.trim().to_owned()).collect();
        let trailing = names.last().is_some_and(|s| s == "...");
        if trailing {
            names.pop();
        }
        let mut columns = Vec::with_capacity(names.len());
        for name in &names {
            columns.push(match name.as_str() {
                "_" => None,
                "..." => return Err("\"...\" may only end the list".to_owned()),
                _ => Some(recognise(name)?.ok_or_else(|| {
                    format!("{name:?} is not a column name the reader knows ({RECOGNISED}; _ skips a column, a last ... allows more)")
                })?),
            });
        }
        let mut seen = [None::<&str>; 7];
        for (name, c) in names.iter().zip(&columns) {
            let Some(c) = c else { continue };
            if let Some(first) = seen[usize::from(c.slot)].replace(name) {
                return Err(format!("{first:?} and {name:?} name the same column"));
            }
        }
        let missing: Vec<&str> = (0..7)
            .filter(|&s| seen[s].is_none())
            .map(|s| RATE_NAMES[s])
            .collect();
        if !missing.is_empty() {
            return Err(format!(
                "no column for {} (a time, three gyro and three accelerometer columns are needed)",
                missing.join(", ")
            ));
        }
        let says: Vec<ImuLayout> = columns.iter().flatten().filter_map(|c| c.layout).collect();
        if says.iter().any(|&l| l != says[0]) {
            return Err(
                "rates and increments mixed: name the gyro and accelerometer columns both as \
                 rates (wx, fx) or both as increments (dtx, dvx)"
                    .to_owned(),
            );
        }
        Ok(Self {
            names,
            columns,
            trailing,
        })
    }

    /// The names as given (without a last `...`).
    pub(crate) fn names(&self) -> &[String] {
        &self.names
    }

    /// What each column holds.
    pub(crate) fn columns(&self) -> &[Option<ColumnName>] {
        &self.columns
    }

    /// Whether further columns are allowed.
    pub(crate) fn trailing(&self) -> bool {
        self.trailing
    }
}

impl fmt::Display for ColumnSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.names.join(","))?;
        if self.trailing {
            f.write_str(",...")?;
        }
        Ok(())
    }
}

/// What the caller declared about the sensor columns (flags); each `None` is unknown.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Declared {
    /// `--imu-layout`.
    pub layout: Option<ImuLayout>,
    /// `--gyro-unit`.
    pub gyro: Option<GyroUnit>,
    /// `--accel-unit`.
    pub accel: Option<AccelUnit>,
    /// `--imu-time-unit`.
    pub time: Option<TimeUnit>,
}

impl Declared {
    /// The layout the declarations agree on, with the flag that first said it, or why
    /// they contradict each other.
    pub fn layout(&self) -> Result<Option<(String, ImuLayout)>, String> {
        let says = [
            self.layout.map(|l| (format!("--imu-layout {l}"), l)),
            self.gyro.map(|u| (format!("--gyro-unit {u}"), u.layout())),
            self.accel
                .map(|u| (format!("--accel-unit {u}"), u.layout())),
        ];
        let mut agreed: Option<(String, ImuLayout)> = None;
        for (flag, l) in says.into_iter().flatten() {
            match &agreed {
                Some((first, a)) if *a != l => {
                    return Err(format!(
                        "{flag} says {l}, {first} says {a}: rates and increments cannot mix \
                         (rad/s, deg/s, m/s^2, g are rates; rad, deg, m/s increments)"
                    ));
                }
                Some(_) => {}
                None => agreed = Some((flag, l)),
            }
        }
        Ok(agreed)
    }
}

/// How to read a line: which column fills which slot, and in what layout and units.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Plan {
    /// Each column's slot, or [`UNUSED`].
    pub slot_of_col: Vec<u8>,
    /// The time's column.
    pub time_col: usize,
    /// Rates or increments.
    pub layout: ImuLayout,
    /// Unit of the gyro columns.
    pub gyro: GyroUnit,
    /// Unit of the accelerometer columns.
    pub accel: AccelUnit,
    /// Unit of the time column.
    pub time: TimeUnit,
    /// Whether the column names say the layout (so that another layout needs other
    /// names).
    pub names_say_layout: bool,
}

/// Why no plan: the message, the column to blame, and whether the header (rather than
/// the caller's options) is at fault.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PlanError {
    /// The column name or option at fault.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
    /// A header problem (else the options contradict each other).
    pub in_header: bool,
}

impl PlanError {
    pub(crate) fn header(field: Option<&str>, message: String) -> Self {
        Self {
            field: field.map(str::to_owned),
            message,
            in_header: true,
        }
    }

    fn usage(field: &str, message: String) -> Self {
        Self {
            field: Some(field.to_owned()),
            message,
            in_header: false,
        }
    }
}

impl Plan {
    /// KF-GINS text: seven columns in slot order, in `layout`, SI units and seconds.
    pub fn kf_gins(layout: ImuLayout) -> Self {
        Self {
            slot_of_col: (0..7).collect(),
            time_col: 0,
            layout,
            gyro: GyroUnit::si(layout),
            accel: AccelUnit::si(layout),
            time: TimeUnit::S,
            names_say_layout: false,
        }
    }
}

/// The plan of a KF-GINS text file: seven columns in slot order, increments unless
/// declared otherwise.
pub(crate) fn default_plan(declared: &Declared) -> Result<Plan, PlanError> {
    let layout = declared
        .layout()
        .map_err(|m| PlanError::usage("imu_layout", m))?
        .map_or(ImuLayout::Increments, |(_, l)| l);
    Ok(Plan {
        gyro: declared.gyro.unwrap_or(GyroUnit::si(layout)),
        accel: declared.accel.unwrap_or(AccelUnit::si(layout)),
        time: declared.time.unwrap_or_default(),
        ..Plan::kf_gins(layout)
    })
}

/// Whether a column holds `layout` (or does not say).
fn fits(c: &ColumnName, layout: ImuLayout) -> bool {
    c.slot == SLOT_TIME || c.layout.is_none_or(|l| l == layout)
}

/// The sensor slots that no column of `cols` fills for `layout` (`strict`: only columns
/// whose names say `layout`).
fn missing(cols: &[Option<ColumnName>], layout: ImuLayout, strict: bool) -> Vec<u8> {
    (0..7)
        .filter(|&s| {
            !cols.iter().flatten().any(|c| {
                c.slot == s && fits(c, layout) && (!strict || s == SLOT_TIME || c.layout.is_some())
            })
        })
        .collect()
}

/// The layout of a header (`what`): declared (by `flag`), else increments if its names
/// give a whole set of increments, else rates (names that do not say count as rates).
fn header_layout(
    cols: &[Option<ColumnName>],
    declared: Option<(String, ImuLayout)>,
    what: &str,
) -> Result<ImuLayout, PlanError> {
    use ImuLayout::{Increments, Rates};
    let chosen = match &declared {
        Some((flag, l)) => {
            let other = if *l == Rates { Increments } else { Rates };
            if missing(cols, *l, false).is_empty() || !missing(cols, other, true).is_empty() {
                *l
            } else {
                return Err(PlanError::usage(
                    "imu_layout",
                    format!("the names of {what} say {other}, {flag} says {l}"),
                ));
            }
        }
        None if missing(cols, Increments, true).is_empty() => Increments,
        None if missing(cols, Rates, false).is_empty() => Rates,
        None if missing(cols, Increments, false).is_empty() => Increments,
        None if missing(cols, Rates, false).len() < missing(cols, Increments, false).len() => Rates,
        None => Increments,
    };
    let lacking = missing(cols, chosen, false);
    if lacking.is_empty() {
        return Ok(chosen);
    }
    let set = match chosen {
        Increments => &INCREMENT_NAMES,
        Rates => &RATE_NAMES,
    };
    let names: Vec<&str> = lacking.iter().map(|&s| set[usize::from(s)]).collect();
    let also = if declared.is_none() {
        format!(" (recognised: {RECOGNISED}; or name the columns with --imu-columns)")
    } else {
        String::new()
    };
    Err(PlanError::header(
        None,
        format!(
            "{what} lacks column(s) {} for {chosen}{also}",
            names.join(", ")
        ),
    ))
}

/// For each column of `names`/`cols`, the slot it fills for `layout` (the best-ranked
/// column of each slot), and the time's column; a tie is an error naming both columns.
fn assign(
    names: &[String],
    cols: &[Option<ColumnName>],
    layout: ImuLayout,
) -> Result<(Vec<u8>, usize), PlanError> {
    let mut slot_of_col = vec![UNUSED; cols.len()];
    let mut time_col = 0;
    for slot in 0..7u8 {
        let best = cols
            .iter()
            .enumerate()
            .filter_map(|(i, c)| {
                c.filter(|c| c.slot == slot && fits(c, layout))
                    .map(|c| (i, c.rank))
            })
            .min_by_key(|&(_, rank)| rank);
        let Some((col, rank)) = best else { continue };
        let twin = cols.iter().enumerate().find(|&(i, c)| {
            i != col && c.is_some_and(|c| c.slot == slot && c.rank == rank && fits(&c, layout))
        });
        if let Some((other, _)) = twin {
            let (first, second) = (col.min(other), col.max(other));
            return Err(PlanError::header(
                Some(&names[first]),
                format!(
                    "columns {} and {} ({:?}, {:?}) are both {}",
                    first + 1,
                    second + 1,
                    names[first],
                    names[second],
                    RATE_NAMES[usize::from(slot)]
                ),
            ));
        }
        slot_of_col[col] = slot;
        if slot == SLOT_TIME {
            time_col = col;
        }
    }
    Ok((slot_of_col, time_col))
}

/// The one unit the chosen columns of a sensor write, if any, or the error naming two
/// that differ.
fn unit_in_names(
    names: &[String],
    cols: &[Option<ColumnName>],
    slot_of_col: &[u8],
    slots: std::ops::RangeInclusive<u8>,
) -> Result<Option<(NameUnit, usize)>, PlanError> {
    let mut found: Option<(NameUnit, usize)> = None;
    for (i, (c, &s)) in cols.iter().zip(slot_of_col).enumerate() {
        let Some(c) = c else { continue };
        if !slots.contains(&s) || c.unit == NameUnit::None {
            continue;
        }
        match found {
            Some((u, j)) if u != c.unit => {
                return Err(PlanError::header(
                    Some(&names[i]),
                    format!(
                        "columns {:?} and {:?} are in different units",
                        names[j], names[i]
                    ),
                ));
            }
            Some(_) => {}
            None => found = Some((c.unit, i)),
        }
    }
    Ok(found)
}

/// The error of an option `flag` = `value` that contradicts the column `name` of
/// `what` ("the header" or "--imu-columns").
fn contradiction(flag: &str, value: impl fmt::Display, what: &str, name: &str) -> PlanError {
    PlanError::usage(
        &flag.replace('-', "_"),
        format!("--{flag} {value} contradicts the column {name:?} of {what}"),
    )
}

/// The gyro unit of the names (column index and unit written, if any) and the
/// declaration, for `layout`.
fn gyro_unit(
    named: Option<(NameUnit, usize)>,
    declared: Option<GyroUnit>,
    layout: ImuLayout,
    (names, what): (&[String], &str),
) -> Result<GyroUnit, PlanError> {
    Ok(match (named, declared) {
        (Some((NameUnit::Gyro(n), _)), Some(d)) if n == d => d,
        (Some((NameUnit::GyroAngleOrRate(a, r), _)), Some(d)) if d == a || d == r => d,
        (Some((_, col)), Some(d)) => return Err(contradiction("gyro-unit", d, what, &names[col])),
        (Some((NameUnit::Gyro(n), _)), None) => n,
        (Some((NameUnit::GyroAngleOrRate(a, r), col)), None) => {
            return Err(PlanError::header(
                Some(&names[col]),
                format!(
                    "{a} may mean an angle increment or, loosely, a rate: give --gyro-unit {a} or --gyro-unit {r}"
                ),
            ));
        }
        (_, d) => d.unwrap_or(GyroUnit::si(layout)),
    })
}

/// The plan of a header's (or `--imu-columns`') names, with the declarations applied;
/// `what` names the source in messages ("the header" or "--imu-columns").
pub(crate) fn plan(
    names: &[String],
    cols: &[Option<ColumnName>],
    declared: &Declared,
    what: &str,
) -> Result<Plan, PlanError> {
    let flags = declared
        .layout()
        .map_err(|m| PlanError::usage("imu_layout", m))?;
    let layout = header_layout(cols, flags, what)?;
    let (slot_of_col, time_col) = assign(names, cols, layout)?;
    let gyro_named = unit_in_names(names, cols, &slot_of_col, 1..=3)?;
    // Declared units agree with `layout` (Declared::layout), and so do units in names
    // (a column whose unit says the other layout does not fit it).
    let gyro = gyro_unit(gyro_named, declared.gyro, layout, (names, what))?;
    let accel = match (
        unit_in_names(names, cols, &slot_of_col, 4..=6)?,
        declared.accel,
    ) {
        (Some((NameUnit::Accel(n), col)), Some(d)) if n != d => {
            return Err(contradiction("accel-unit", d, what, &names[col]));
        }
        (Some((NameUnit::Accel(n), _)), _) => n,
        (_, d) => d.unwrap_or(AccelUnit::si(layout)),
    };
    let time = match (cols[time_col].map(|c| c.unit), declared.time) {
        (Some(NameUnit::Time(n)), Some(d)) if n != d => {
            return Err(contradiction("imu-time-unit", d, what, &names[time_col]));
        }
        (Some(NameUnit::Time(n)), _) => n,
        (_, d) => d.unwrap_or_default(),
    };
    let names_say_layout = cols
        .iter()
        .zip(&slot_of_col)
        .any(|(c, &s)| s != UNUSED && c.is_some_and(|c| c.layout.is_some()));
    Ok(Plan {
        slot_of_col,
        time_col,
        layout,
        gyro,
        accel,
        time,
        names_say_layout,
    })
}

/// `--imu-columns` names for `plan`'s columns in `layout`, with the gyro and
/// accelerometer columns exchanged if `swap` (a fix the plausibility check suggests).
pub(crate) fn spec_text(
    slot_of_col: &[u8],
    trailing: bool,
    layout: ImuLayout,
    swap: bool,
) -> String {
    const RATES: [&str; 7] = ["t", "wx", "wy", "wz", "fx", "fy", "fz"];
    const INCREMENTS: [&str; 7] = ["t", "dtx", "dty", "dtz", "dvx", "dvy", "dvz"];
    let set = match layout {
        ImuLayout::Rates => &RATES,
        ImuLayout::Increments => &INCREMENTS,
    };
    let mut parts: Vec<&str> = slot_of_col
        .iter()
        .map(|&s| match s {
            UNUSED => "_",
            1..=3 if swap => set[usize::from(s + 3)],
            4..=6 if swap => set[usize::from(s - 3)],
            s => set[usize::from(s)],
        })
        .collect();
    if trailing {
        parts.push("...");
    }
    parts.join(",")
}

#[cfg(test)]
mod tests {
    use super::*;
    use ImuLayout::{Increments, Rates};

    fn slot(name: &str) -> Option<(u8, Option<ImuLayout>, NameUnit)> {
        recognise(name)
            .expect("no contradiction")
            .map(|c| (c.slot, c.layout, c.unit))
    }

    #[test]
    fn unit_names_are_listed_as_serde_reads_them() {
        use crate::named::check_listing;
        check_listing(&[
            GyroUnit::RadPerSecond,
            GyroUnit::DegPerSecond,
            GyroUnit::Rad,
            GyroUnit::Deg,
        ]);
        check_listing(&[
            AccelUnit::MetrePerSecond2,
            AccelUnit::G,
            AccelUnit::MetrePerSecond,
        ]);
        check_listing(&[TimeUnit::S, TimeUnit::Ms, TimeUnit::Us, TimeUnit::Ns]);
    }

    #[test]
    fn common_names_are_recognised() {
        for (name, s) in [
            ("t", 0),
            ("Time", 0),
            ("timestamp", 0),
            ("w_x", 1),
            ("wy", 2),
            ("gyro_z", 3),
            ("GyroX", 1),
            ("Gyr_Y", 2),
            ("omega_x", 1),
            ("angular_velocity_z", 3),
            ("field.angular_velocity.y", 2),
            ("gx", 1),
            ("f_x", 4),
            ("acc_y", 5),
            ("Acc_Z", 6),
            ("accel_x", 4),
            ("ax", 4),
            ("a_y", 5),
            ("linear_acceleration_z", 6),
            ("field.linear_acceleration.x", 4),
            ("dtheta_x", 1),
            ("dtx", 1),
            ("delta_theta_z", 3),
            ("dvel_x", 4),
            ("dvz", 6),
            ("dv_y", 5),
        ] {
            assert_eq!(slot(name).map(|s| s.0), Some(s), "{name}");
        }
        for other in [
            "dt",
            "x",
            "temp",
            "gyro_temp",
            "mag_x",
            "max",
            "a",
            "scaledAccelX",
            "seq",
        ] {
            assert_eq!(slot(other), None, "{other}");
        }
    }

    #[test]
    fn layout_and_units_in_names() {
        use NameUnit::{Accel, Gyro, Time};
        assert_eq!(slot("w_x"), Some((1, Some(Rates), NameUnit::None)));
        assert_eq!(slot("gyro_x"), Some((1, None, NameUnit::None)));
        assert_eq!(slot("dtx"), Some((1, Some(Increments), NameUnit::None)));
        assert_eq!(
            slot("gx_dps"),
            Some((1, Some(Rates), Gyro(GyroUnit::DegPerSecond)))
        );
        assert_eq!(
            slot("wx_rad_s"),
            Some((1, Some(Rates), Gyro(GyroUnit::RadPerSecond)))
        );
        assert_eq!(
            slot("gyro_x [deg/s]"),
            Some((1, Some(Rates), Gyro(GyroUnit::DegPerSecond)))
        );
        assert_eq!(slot("ax_g"), Some((4, Some(Rates), Accel(AccelUnit::G))));
        assert_eq!(
            slot("acc_x_mps2"),
            Some((4, Some(Rates), Accel(AccelUnit::MetrePerSecond2)))
        );
        assert_eq!(
            slot("acc_x (m/s^2)"),
            Some((4, Some(Rates), Accel(AccelUnit::MetrePerSecond2)))
        );
        assert_eq!(
            slot("dvel_x_m_s"),
            Some((4, Some(Increments), Accel(AccelUnit::MetrePerSecond)))
        );
        assert_eq!(
            slot("dtheta_x_deg"),
            Some((1, Some(Increments), Gyro(GyroUnit::Deg)))
        );
        assert_eq!(
            slot("gyr_x_deg"),
            Some((
                1,
                None,
                NameUnit::GyroAngleOrRate(GyroUnit::Deg, GyroUnit::DegPerSecond)
            ))
        );
        assert_eq!(slot("time_ms"), Some((0, None, Time(TimeUnit::Ms))));
        assert_eq!(slot("timestamp [ns]"), Some((0, None, Time(TimeUnit::Ns))));
        assert_eq!(slot("t_s"), Some((0, None, Time(TimeUnit::S))));
        assert_eq!(
            slot("w_x_deg"),
            Some((1, Some(Rates), Gyro(GyroUnit::DegPerSecond)))
        );
        assert!(recognise("dvel_x_g").is_err());
        assert!(recognise("dtheta_x_dps").is_err());
        assert!(recognise("f_x_m_s").is_err());
    }

    #[test]
    fn column_specs() {
        let s = ColumnSpec::parse("t,fx,fy,fz,wx,wy,wz").expect("rates, accelerometer first");
        assert_eq!(s.columns()[1].map(|c| c.slot), Some(4));
        assert_eq!(s.to_string(), "t,fx,fy,fz,wx,wy,wz");
        let s = ColumnSpec::parse(" _, t ,dtx,dty,dtz,dvx,dvy,dvz,...").expect("increments");
        assert!(s.trailing());
        assert_eq!(s.columns()[0], None);
        for (bad, why) in [
            ("t,wx,wy,wz,fx,fy", "no column for f_z"),
            ("t,wx,wy,wz,fx,fy,fz,wx", "name the same column"),
            ("t,wx,wy,wz,dvx,dvy,dvz", "rates and increments mixed"),
            ("t,wx,wy,wz,fx,fy,fz,temp", "\"temp\" is not a column name"),
            ("t,...,wx,wy,wz,fx,fy,fz", "may only end"),
        ] {
            let e = ColumnSpec::parse(bad).expect_err(bad);
            assert!(e.contains(why), "{bad}: {e}");
        }
    }

    fn plan_of(header: &str, declared: &Declared) -> Result<Plan, PlanError> {
        let names: Vec<String> = header.split(',').map(str::to_owned).collect();
        let cols: Vec<_> = names.iter().map(|n| recognise(n).expect("ok")).collect();
        plan(&names, &cols, declared, "the header")
    }

    #[test]
    fn plans_of_headers() {
        let none = Declared::default();
        let p =
            plan_of("timestamp,acc_x,acc_y,acc_z,gyro_x,gyro_y,gyro_z", &none).expect("generic");
        assert_eq!(p.layout, Rates);
        assert_eq!(p.slot_of_col, vec![0, 4, 5, 6, 1, 2, 3]);
        let p = plan_of("time_ns,gx_dps,gy_dps,gz_dps,ax_g,ay_g,az_g,mx", &none).expect("units");
        assert_eq!(
            (p.gyro, p.accel, p.time),
            (GyroUnit::DegPerSecond, AccelUnit::G, TimeUnit::Ns)
        );
        assert_eq!(p.slot_of_col[7], UNUSED);
        // Both sets: increments unless declared.
        let both = "t,w_x,w_y,w_z,f_x,f_y,f_z,dtheta_x,dtheta_y,dtheta_z,dvel_x,dvel_y,dvel_z";
        assert_eq!(plan_of(both, &none).expect("both").layout, Increments);
        let rates = Declared {
            gyro: Some(GyroUnit::DegPerSecond),
            ..none
        };
        let p = plan_of(both, &rates).expect("declared rates");
        assert_eq!((p.layout, p.slot_of_col[1]), (Rates, 1));
    }

    #[test]
    fn plans_of_headers_refuse_what_they_cannot_tell() {
        let none = Declared::default();
        // The time: t wins over time over timestamp.
        let p = plan_of("timestamp,time,t,wx,wy,wz,fx,fy,fz", &none).expect("t");
        assert_eq!(p.time_col, 2);
        let e = plan_of("t,gyro_x,wx,wy,wz,fx,fy,fz", &none).expect_err("twice");
        assert!(e.message.contains("are both w_x"), "{}", e.message);
        let e = plan_of("t,gyr_x_deg,gyr_y_deg,gyr_z_deg,ax,ay,az", &none).expect_err("ambiguous");
        assert!(
            e.message.contains("--gyro-unit deg or --gyro-unit deg/s"),
            "{}",
            e.message
        );
        let dps = Declared {
            gyro: Some(GyroUnit::DegPerSecond),
            ..none
        };
        let p = plan_of("t,gyr_x_deg,gyr_y_deg,gyr_z_deg,ax,ay,az", &dps).expect("resolved");
        assert_eq!(p.gyro, GyroUnit::DegPerSecond);
        let e = plan_of(
            "t,gx_dps,gy_dps,gz_dps,ax,ay,az",
            &Declared {
                gyro: Some(GyroUnit::RadPerSecond),
                ..none
            },
        )
        .expect_err("contradiction");
        assert_eq!(e.field.as_deref(), Some("gyro_unit"));
        let e = plan_of("t,gx_dps,gy_rad_s,gz_dps,ax,ay,az", &none).expect_err("mixed units");
        assert!(e.message.contains("different units"), "{}", e.message);
        let e = plan_of(
            "t,dtx,dty,dtz,dvx,dvy,dvz",
            &Declared {
                accel: Some(AccelUnit::G),
                ..none
            },
        )
        .expect_err("rates unit for increments");
        assert!(
            e.message
                .contains("the names of the header say increments, --accel-unit g says rates"),
            "{}",
            e.message
        );
        let e = plan_of(
            "t,w_x,w_y,w_z,f_x,f_y",
            &Declared {
                layout: Some(Rates),
                ..none
            },
        )
        .expect_err("missing");
        assert_eq!(e.message, "the header lacks column(s) f_z for rates");
        let e = plan_of("t,x,y,z", &none).expect_err("nothing");
        assert!(e.message.contains("recognised: time t"), "{}", e.message);
        let e = Declared {
            layout: Some(Increments),
            gyro: Some(GyroUnit::DegPerSecond),
            ..none
        }
        .layout()
        .expect_err("contradiction");
        assert!(
            e.contains("--gyro-unit deg/s says rates, --imu-layout increments says increments"),
            "{e}"
        );
    }

    #[test]
    fn swapped_spec_text() {
        let slots = [0, 1, 2, 3, 4, 5, 6];
        assert_eq!(spec_text(&slots, false, Rates, true), "t,fx,fy,fz,wx,wy,wz");
        assert_eq!(
            spec_text(&slots, false, Increments, false),
            "t,dtx,dty,dtz,dvx,dvy,dvz"
        );
        assert_eq!(
            spec_text(&[UNUSED, 0, 4, 5, 6, 1, 2, 3], true, Rates, true),
            "_,t,wx,wy,wz,fx,fy,fz,..."
        );
    }
}
