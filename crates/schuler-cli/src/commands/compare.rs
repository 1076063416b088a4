//! `schuler compare NAV TRUTH [--out DIR] [--start T] [--end T] [--outages T0-T1,...]`:
//! errors of any navigation result (schuler's, KF-GINS's, another tool's) against a
//! truth file, as a table, `compare.json`, `errors.csv` and SVG plots.
//!
//! # Inputs
//! Either file may be KF-GINS navigation text (11 columns: `week sow lat lon h vn ve vd
//! roll pitch yaw`, degrees, metres, m/s; as schuler's `nav.txt`, KF-GINS's
//! `KF_GINS_Navresult.nav` and the data sets' `truth.nav`) or schuler's `nav.csv` (a
//! header naming at least `t_sow,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,
//! pitch_deg,yaw_deg`, in any order, other columns ignored). The format is told by the
//! first data line: a header starts with a letter. Blank lines and `#`/`%` comments are
//! skipped. The time is the second of week; in a KF-GINS file a later week continues
//! it (`sow + 604800 (week - first week)`), so a rollover inside a file is no step, but
//! the two files' weeks are not compared (schuler writes week 0 where it knows none).
//! Both files are read whole (80 bytes per epoch).
//!
//! # Matching
//! Every NAV epoch in the `--start`/`--end` window is compared with the truth at its
//! time: a truth epoch within 1e-6 s is taken as it is; otherwise the truth is
//! interpolated linearly in time between the two epochs around it (longitude, roll and
//! yaw unwrapped across ±180°/360°). Linear interpolation of Euler angles is exact only
//! for rotation about one axis; between truth epochs 1 s apart the error it makes is of
//! second order in the angle turned. NAV epochs outside the truth's span are skipped and
//! counted, as is the longest truth interval bridged.
//!
//! # Errors (NAV minus truth)
//! Position in metres along the truth's NED axes, with the WGS84 radii at the truth's
//! latitude (`EarthModel::radii`): `dN = (lat - lat_t) (R_M + h_t)`,
//! `dE = wrap(lon - lon_t) (R_N + h_t) cos(lat_t)`, `dD = -(h - h_t)`; the arc-length
//! linearization is good to a relative `d / R` (1e-6 for an error of 6 m). Horizontal
//! `hypot(dN, dE)` (the seed's circular error ΔS), 3-D `|(dN, dE, dD)|`, vertical `dD`.
//! Velocity `v_n - v_n,t` [m/s]. Attitude: the differences of roll, pitch and yaw, each
//! wrapped to (-180°, 180°].
//!
//! # Statistics
//! For each error `e` over the matched epochs: RMS, the largest `|e|` and the time of
//! its first occurrence, the 95th percentile of `|e|` and the mean of `e` (signed: a
//! bias shows). Percentiles are nearest-rank: the `P`th percentile of `n` values is the
//! `ceil(P n / 100)`th smallest, the smallest value that at least `P` % of the epochs
//! do not exceed (so of 1..100 m the 95th is 95 m). CEP is the 50th percentile of the
//! horizontal error, CEP95 the 95th. With `--outages`, per interval (ends included) the
//! largest horizontal, vertical and per-axis attitude error, and the RMS of those
//! maxima over the intervals holding an epoch (the protocol of the KF-GINS paper).

use crate::formats::error::{InputError, InputErrorKind, quote_field};
use crate::plot::{LineStyle, Plot};
use anyhow::{Context, Result};
use nalgebra::Vector3;
use schuler::earth::{EarthModel, Geodetic, Wgs84};
use schuler::rotation::Euler;
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Write as _};
use std::path::{Path, PathBuf};

/// Two epochs closer than this [s] are the same epoch.
pub const TIME_TOLERANCE_S: f64 = 1e-6;

/// Seconds in a GPS week.
const WEEK_S: f64 = 604_800.0;

/// Arguments of `schuler compare`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Navigation result: KF-GINS text (`week sow lat lon h vn ve vd roll pitch yaw`)
    /// or schuler's nav.csv.
    #[arg(value_name = "NAV")]
    pub nav: PathBuf,
    /// Truth, in either format; interpolated in time where its epochs differ.
    #[arg(value_name = "TRUTH")]
    pub truth: PathBuf,
    /// Output directory for compare.json, errors.csv and the plots (created if
    /// missing); without it only the table is printed.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Compare NAV epochs from this time on [s of week].
    #[arg(long, value_name = "SOW")]
    pub start: Option<f64>,
    /// Compare NAV epochs up to this time [s of week].
    #[arg(long, value_name = "SOW")]
    pub end: Option<f64>,
    /// GNSS outage intervals [s of week], e.g. `215-276,400-460`: the largest errors
    /// inside each and the RMS of those maxima.
    #[arg(long, value_name = "T0-T1,...", value_parser = parse_outages)]
    pub outages: Option<Outages>,
}

/// Time intervals `[from, to]` [s of week], as `--outages` gives them.
#[derive(Debug, Clone, PartialEq)]
pub struct Outages(pub Vec<(f64, f64)>);

/// Parses `T0-T1,T2-T3` (each `T0 < T1`, finite).
pub fn parse_outages(text: &str) -> Result<Outages, String> {
    let mut out = Vec::new();
    for part in text.split(',').map(str::trim) {
        // The separating '-' is not a leading sign nor an exponent's sign.
        let bytes = part.as_bytes();
        let dash = (1..bytes.len())
            .find(|&i| bytes[i] == b'-' && !matches!(bytes[i - 1], b'e' | b'E' | b'-'))
            .ok_or_else(|| format!("{part:?}: expected an interval T0-T1"))?;
        let (a, b) = (part[..dash].trim(), part[dash + 1..].trim());
        let num = |s: &str| -> Result<f64, String> {
            s.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{part:?}: {s:?} is not a time in seconds"))
        };
        let (from, to) = (num(a)?, num(b)?);
        if from >= to {
            return Err(format!("{part:?}: the interval must end after it starts"));
        }
        out.push((from, to));
    }
    Ok(Outages(out))
}

/// One epoch of a navigation result or truth: position, NED velocity and ZYX attitude
/// of the body (FRD) in the local-level NED frame, SI units and radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavRow {
    /// Time [s of week; continued past a week rollover inside one file].
    pub t_sow: f64,
    /// Geodetic position (WGS84).
    pub pos: Geodetic,
    /// Velocity in NED [m/s].
    pub v_n: Vector3<f64>,
    /// Attitude, body to NED.
    pub att: Euler,
}

/// The layouts [`read_nav`] tells apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NavFormat {
    /// KF-GINS navigation text, 11 columns, no header.
    KfGins,
    /// CSV with a header naming the columns (schuler's `nav.csv`).
    Csv,
}

impl NavFormat {
    /// The name used in the report.
    pub fn name(self) -> &'static str {
        match self {
            NavFormat::KfGins => "kf-gins",
            NavFormat::Csv => "csv",
        }
    }
}

/// KF-GINS column names, in file order.
const KF_GINS_FIELDS: [&str; 11] = [
    "week", "sow", "lat", "lon", "h", "vn", "ve", "vd", "roll", "pitch", "yaw",
];

/// CSV columns read, in [`NavRow`] order after time.
const CSV_FIELDS: [&str; 10] = [
    "t_sow",
    "lat_deg",
    "lon_deg",
    "h_m",
    "vn_mps",
    "ve_mps",
    "vd_mps",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
];

/// Reads a navigation file whole (either layout, told by its first data line),
/// checking column counts, numbers, finiteness, latitude range, whole weeks and
/// strictly increasing time; errors name the file, line and field.
pub fn read_nav(path: &Path) -> Result<(NavFormat, Vec<NavRow>), InputError> {
    let io_err = |e: std::io::Error| {
        InputError::new(
            InputErrorKind::Io,
            path,
            0,
            None,
            format!("cannot read: {e}"),
        )
    };
    let file = std::fs::File::open(path).map_err(io_err)?;
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let mut buf: Vec<u8> = Vec::new();
    let mut n: u64 = 0;
    let mut format = None;
    // For CSV: the column count and the index of each of CSV_FIELDS.
    let mut csv_columns = (0usize, [0usize; 10]);
    let mut first_week = None;
    let mut rows: Vec<NavRow> = Vec::new();
    loop {
        buf.clear();
        if reader.read_until(b'\n', &mut buf).map_err(io_err)? == 0 {
            break;
        }
        n += 1;
        let l = std::str::from_utf8(&buf)
            .map_err(|_| {
                InputError::new(InputErrorKind::NotANumber, path, n, None, "not UTF-8 text")
            })?
            .trim();
        if l.is_empty() || l.starts_with('#') || l.starts_with('%') {
            continue;
        }
        let fmt = match format {
            Some(f) => f,
            None => {
                let f = if l.starts_with(|c: char| c.is_ascii_alphabetic() || c == '"') {
                    csv_columns = csv_header(path, n, l)?;
                    NavFormat::Csv
                } else {
                    NavFormat::KfGins
                };
                format = Some(f);
                if f == NavFormat::Csv {
                    continue;
                }
                f
            }
        };
        let at = |field: &str, kind, msg: String| InputError::new(kind, path, n, Some(field), msg);
        let number = |field: &str, text: &str| -> Result<f64, InputError> {
            let x: f64 = text.parse().map_err(|_| {
                at(
                    field,
                    InputErrorKind::NotANumber,
                    format!("not a number: {}", quote_field(text.as_bytes())),
                )
            })?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(at(
                    field,
                    InputErrorKind::NotFinite,
                    format!("not finite: {}", quote_field(text.as_bytes())),
                ))
            }
        };
        // v: time, lat, lon [deg], h, vn, ve, vd, roll, pitch, yaw [deg].
        let mut v = [0.0; 10];
        let names: [&str; 10];
        match fmt {
            NavFormat::KfGins => {
                let fields: Vec<&str> = l
                    .split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|f| !f.is_empty())
                    .collect();
                if fields.len() != KF_GINS_FIELDS.len() {
                    return Err(InputError::new(
                        InputErrorKind::ColumnCount,
                        path,
                        n,
                        None,
                        format!(
                            "{} columns, expected 11 (week sow lat lon h vn ve vd roll pitch yaw)",
                            fields.len()
                        ),
                    ));
                }
                let mut x = [0.0; 11];
                for (k, f) in fields.iter().enumerate() {
                    x[k] = number(KF_GINS_FIELDS[k], f)?;
                }
                let week = x[0];
                if week < 0.0 || week.fract() != 0.0 {
                    return Err(at(
                        "week",
                        InputErrorKind::NotANumber,
                        format!("a GPS week is a whole number >= 0, got {}", fields[0]),
                    ));
                }
                let week0 = *first_week.get_or_insert(week);
                v[0] = x[1] + (week - week0) * WEEK_S;
                v[1..].copy_from_slice(&x[2..]);
                names = [
                    "sow", "lat", "lon", "h", "vn", "ve", "vd", "roll", "pitch", "yaw",
                ];
            }
            NavFormat::Csv => {
                let fields: Vec<&str> = l.split(',').map(str::trim).collect();
                if fields.len() != csv_columns.0 {
                    return Err(InputError::new(
                        InputErrorKind::ColumnCount,
                        path,
                        n,
                        None,
                        format!(
                            "{} columns, the header names {}",
                            fields.len(),
                            csv_columns.0
                        ),
                    ));
                }
                for (k, &i) in csv_columns.1.iter().enumerate() {
                    v[k] = number(CSV_FIELDS[k], fields[i])?;
                }
                names = CSV_FIELDS;
            }
        }
        if !(-90.0..=90.0).contains(&v[1]) {
            return Err(at(
                names[1],
                InputErrorKind::NotANumber,
                format!("latitude {} is outside [-90, 90]", v[1]),
            ));
        }
        if let Some(prev) = rows.last()
            && v[0] <= prev.t_sow
        {
            return Err(at(
                names[0],
                InputErrorKind::TimeNotIncreasing,
                format!("time {} does not increase (previous {})", v[0], prev.t_sow),
            ));
        }
        rows.push(NavRow {
            t_sow: v[0],
            pos: Geodetic::from_degrees(v[1], v[2], v[3]),
            v_n: Vector3::new(v[4], v[5], v[6]),
            att: Euler::from_degrees(v[7], v[8], v[9]),
        });
    }
    match format {
        Some(f) if !rows.is_empty() => Ok((f, rows)),
        _ => Err(InputError::new(
            InputErrorKind::NoData,
            path,
            0,
            None,
            "no data line",
        )),
    }
}

/// The column count of a CSV header and where each of [`CSV_FIELDS`] is.
fn csv_header(path: &Path, n: u64, l: &str) -> Result<(usize, [usize; 10]), InputError> {
    let names: Vec<&str> = l.split(',').map(|s| s.trim().trim_matches('"')).collect();
    let mut index = [0usize; 10];
    for (k, want) in CSV_FIELDS.iter().enumerate() {
        index[k] = names.iter().position(|h| h == want).ok_or_else(|| {
            InputError::new(
                InputErrorKind::Header,
                path,
                n,
                Some(want),
                format!(
                    "the header lacks column {want} (needs {})",
                    CSV_FIELDS.join(",")
                ),
            )
        })?;
    }
    Ok((names.len(), index))
}

/// Errors of one NAV epoch against the truth at its time (NAV minus truth).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochErrors {
    /// Time of the NAV epoch [s of week].
    pub t_sow: f64,
    /// Position error along the truth's north, east, down axes [m].
    pub pos_n: Vector3<f64>,
    /// Velocity error in NED [m/s].
    pub v_n: Vector3<f64>,
    /// Roll, pitch and yaw differences, each wrapped to (-pi, pi] [rad].
    pub att: Euler,
    /// Whether the truth was interpolated (no truth epoch within 1e-6 s).
    pub interpolated: bool,
}

impl EpochErrors {
    /// Horizontal error `hypot(dN, dE)` [m] (the seed's circular error ΔS).
    pub fn horizontal(&self) -> f64 {
        self.pos_n.x.hypot(self.pos_n.y)
    }
}

/// How the NAV epochs met the truth.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Matching {
    /// Epochs with a truth epoch within 1e-6 s.
    pub exact: usize,
    /// Epochs at which the truth was interpolated.
    pub interpolated: usize,
    /// Epochs before the truth's first epoch (skipped).
    pub before_truth: usize,
    /// Epochs after the truth's last epoch (skipped).
    pub after_truth: usize,
    /// Epochs outside the `--start`/`--end` window (skipped).
    pub outside_window: usize,
    /// Longest truth interval interpolated across [s] (0 if none).
    pub max_bridged_s: f64,
}

impl Matching {
    /// Epochs compared.
    pub fn matched(&self) -> usize {
        self.exact + self.interpolated
    }
}

/// Wraps an angle to (-pi, pi].
fn wrap_pi(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let w = (x + PI).rem_euclid(TAU) - PI;
    if w == -PI { PI } else { w }
}

/// The truth at `t` between epochs `a` and `b` (`a.t_sow < t < b.t_sow`), linear in
/// time; longitude, roll and yaw follow the shorter way round.
pub fn interpolate(a: &NavRow, b: &NavRow, t: f64) -> NavRow {
    let f = (t - a.t_sow) / (b.t_sow - a.t_sow);
    let lin = |x: f64, y: f64| x + f * (y - x);
    let ang = |x: f64, y: f64| x + f * wrap_pi(y - x);
    NavRow {
        t_sow: t,
        pos: Geodetic {
            lat: lin(a.pos.lat, b.pos.lat),
            lon: ang(a.pos.lon, b.pos.lon),
            h: lin(a.pos.h, b.pos.h),
        },
        v_n: a.v_n + (b.v_n - a.v_n) * f,
        att: Euler::new(
            ang(a.att.roll, b.att.roll),
            lin(a.att.pitch, b.att.pitch),
            ang(a.att.yaw, b.att.yaw),
        ),
    }
}

/// Errors of `nav` against `truth` at the same time (module docs: the NED position
/// error with WGS84 radii at the truth's latitude and height).
pub fn errors_at(nav: &NavRow, truth: &NavRow) -> EpochErrors {
    let r = Wgs84.radii(truth.pos.lat);
    let h = truth.pos.h;
    let pos_n = Vector3::new(
        (nav.pos.lat - truth.pos.lat) * (r.meridian + h),
        wrap_pi(nav.pos.lon - truth.pos.lon) * (r.prime_vertical + h) * truth.pos.lat.cos(),
        h - nav.pos.h,
    );
    EpochErrors {
        t_sow: nav.t_sow,
        pos_n,
        v_n: nav.v_n - truth.v_n,
        att: Euler::new(
            wrap_pi(nav.att.roll - truth.att.roll),
            wrap_pi(nav.att.pitch - truth.att.pitch),
            wrap_pi(nav.att.yaw - truth.att.yaw),
        ),
        interpolated: false,
    }
}

/// The error of every NAV epoch inside `[start, end]` and the truth's span (both
/// sorted by time), exact within [`TIME_TOLERANCE_S`] else interpolated.
pub fn match_epochs(
    nav: &[NavRow],
    truth: &[NavRow],
    start: Option<f64>,
    end: Option<f64>,
) -> (Vec<EpochErrors>, Matching) {
    let mut m = Matching::default();
    let mut out = Vec::with_capacity(nav.len());
    let (Some(first), Some(last)) = (truth.first(), truth.last()) else {
        m.after_truth = nav.len();
        return (out, m);
    };
    let mut j = 0; // truth[j].t_sow <= t + tol, advanced monotonically
    for row in nav {
        let t = row.t_sow;
        if start.is_some_and(|s| t < s) || end.is_some_and(|e| t > e) {
            m.outside_window += 1;
            continue;
        }
        if t < first.t_sow - TIME_TOLERANCE_S {
            m.before_truth += 1;
            continue;
        }
        if t > last.t_sow + TIME_TOLERANCE_S {
            m.after_truth += 1;
            continue;
        }
        while j + 1 < truth.len() && truth[j + 1].t_sow <= t + TIME_TOLERANCE_S {
            j += 1;
        }
        let e = if (truth[j].t_sow - t).abs() <= TIME_TOLERANCE_S {
            m.exact += 1;
            errors_at(row, &truth[j])
        } else {
            // truth[j].t < t - tol and truth[j + 1].t > t + tol: t is inside the span
            // and not within the tolerance of its last epoch, so j + 1 exists.
            let (a, b) = (&truth[j], &truth[j + 1]);
            m.interpolated += 1;
            m.max_bridged_s = m.max_bridged_s.max(b.t_sow - a.t_sow);
            EpochErrors {
                interpolated: true,
                ..errors_at(row, &interpolate(a, b, t))
            }
        };
        out.push(e);
    }
    (out, m)
}

/// RMS, largest magnitude, 95th percentile and mean of one error over the epochs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Root mean square.
    pub rms: f64,
    /// Largest `|e|`.
    pub max_abs: f64,
    /// Time of the first epoch where `|e|` is largest [s of week].
    pub t_max_sow: f64,
    /// 95th percentile (nearest rank) of `|e|`.
    pub p95_abs: f64,
    /// Mean of the signed error.
    pub mean: f64,
}

/// The `p`th percentile (nearest rank, `0 < p <= 100`) of values sorted ascending:
/// the `ceil(p n / 100)`th smallest. `None` for no values.
pub fn percentile_sorted(sorted: &[f64], p: f64) -> Option<f64> {
    let n = sorted.len();
    let rank = ((p * n as f64 / 100.0).ceil() as usize).clamp(1, n.max(1));
    sorted.get(rank - 1).copied()
}

impl Summary {
    /// The summary of errors `e` at times `t` (same length); `None` when empty.
    pub fn of(t: &[f64], e: &[f64]) -> Option<Summary> {
        if e.is_empty() {
            return None;
        }
        let n = e.len() as f64;
        let (mut sum, mut sum2, mut max_abs, mut t_max) = (0.0, 0.0, -1.0, t[0]);
        for (&ti, &x) in t.iter().zip(e) {
            sum += x;
            sum2 += x * x;
            if x.abs() > max_abs {
                max_abs = x.abs();
                t_max = ti;
            }
        }
        let mut abs: Vec<f64> = e.iter().map(|x| x.abs()).collect();
        abs.sort_unstable_by(f64::total_cmp);
        Some(Summary {
            rms: (sum2 / n).sqrt(),
            max_abs,
            t_max_sow: t_max,
            p95_abs: percentile_sorted(&abs, 95.0)?,
            mean: sum / n,
        })
    }
}

/// One error quantity of the table: its name, unit, and value for an epoch.
#[derive(Debug, Clone, Copy)]
pub struct Quantity {
    /// Name in the table.
    pub name: &'static str,
    /// Unit of the value.
    pub unit: &'static str,
    /// The epoch's error in that unit.
    pub of: fn(&EpochErrors) -> f64,
}

const fn q(name: &'static str, unit: &'static str, of: fn(&EpochErrors) -> f64) -> Quantity {
    Quantity { name, unit, of }
}

/// The error quantities summarized, in table order.
pub const QUANTITIES: [Quantity; 11] = [
    q("north", "m", |e| e.pos_n.x),
    q("east", "m", |e| e.pos_n.y),
    q("horizontal", "m", |e| e.horizontal()),
    q("vertical (down)", "m", |e| e.pos_n.z),
    q("3-D", "m", |e| e.pos_n.norm()),
    q("v north", "m/s", |e| e.v_n.x),
    q("v east", "m/s", |e| e.v_n.y),
    q("v down", "m/s", |e| e.v_n.z),
    q("roll", "deg", |e| e.att.roll.to_degrees()),
    q("pitch", "deg", |e| e.att.pitch.to_degrees()),
    q("yaw", "deg", |e| e.att.yaw.to_degrees()),
];

/// The largest errors inside one outage interval (ends included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutageMax {
    /// Interval start [s of week].
    pub from_sow: f64,
    /// Interval end [s of week].
    pub to_sow: f64,
    /// Matched epochs inside.
    pub epochs: usize,
    /// Largest horizontal error [m] (0 without epochs).
    pub horizontal: f64,
    /// Largest `|dD|` [m].
    pub vertical: f64,
    /// Largest `|roll|`, `|pitch|`, `|yaw|` error [rad].
    pub att: Euler,
}

/// Every statistic `schuler compare` reports.
#[derive(Debug, Clone, PartialEq)]
pub struct Statistics {
    /// Matched epochs.
    pub epochs: usize,
    /// One summary per entry of [`QUANTITIES`] (in its units), in that order.
    pub summaries: Vec<Summary>,
    /// 50th percentile of the horizontal error [m].
    pub cep: f64,
    /// 95th percentile of the horizontal error [m].
    pub cep95: f64,
    /// Per outage interval, in the order given.
    pub outages: Vec<OutageMax>,
    /// RMS over the intervals with epochs of their maxima (same fields as an
    /// [`OutageMax`]; `epochs` counts the intervals); `None` without such intervals.
    pub outage_rms: Option<OutageMax>,
}

impl Statistics {
    /// The summary of a quantity by its name in [`QUANTITIES`].
    pub fn get(&self, name: &str) -> Option<&Summary> {
        QUANTITIES
            .iter()
            .position(|q| q.name == name)
            .and_then(|i| self.summaries.get(i))
    }
}

/// Statistics of the matched epochs' errors and the largest errors per outage
/// interval; `None` without epochs.
pub fn statistics(errors: &[EpochErrors], outages: &[(f64, f64)]) -> Option<Statistics> {
    if errors.is_empty() {
        return None;
    }
    let t: Vec<f64> = errors.iter().map(|e| e.t_sow).collect();
    let mut summaries = Vec::with_capacity(QUANTITIES.len());
    for quantity in QUANTITIES {
        let v: Vec<f64> = errors.iter().map(quantity.of).collect();
        summaries.push(Summary::of(&t, &v)?);
    }
    let mut hor: Vec<f64> = errors.iter().map(EpochErrors::horizontal).collect();
    hor.sort_unstable_by(f64::total_cmp);
    let mut per_outage = Vec::with_capacity(outages.len());
    for &(from, to) in outages {
        let mut o = OutageMax {
            from_sow: from,
            to_sow: to,
            epochs: 0,
            horizontal: 0.0,
            vertical: 0.0,
            att: Euler::default(),
        };
        for e in errors.iter().filter(|e| e.t_sow >= from && e.t_sow <= to) {
            o.epochs += 1;
            o.horizontal = o.horizontal.max(e.horizontal());
            o.vertical = o.vertical.max(e.pos_n.z.abs());
            o.att.roll = o.att.roll.max(e.att.roll.abs());
            o.att.pitch = o.att.pitch.max(e.att.pitch.abs());
            o.att.yaw = o.att.yaw.max(e.att.yaw.abs());
        }
        per_outage.push(o);
    }
    let with: Vec<&OutageMax> = per_outage.iter().filter(|o| o.epochs > 0).collect();
    let outage_rms = (!with.is_empty()).then(|| {
        let rms = |f: fn(&OutageMax) -> f64| {
            (with.iter().map(|o| f(o).powi(2)).sum::<f64>() / with.len() as f64).sqrt()
        };
        OutageMax {
            from_sow: with[0].from_sow,
            to_sow: with[with.len() - 1].to_sow,
            epochs: with.len(),
            horizontal: rms(|o| o.horizontal),
            vertical: rms(|o| o.vertical),
            att: Euler::new(
                rms(|o| o.att.roll),
                rms(|o| o.att.pitch),
                rms(|o| o.att.yaw),
            ),
        }
    });
    Some(Statistics {
        epochs: errors.len(),
        summaries,
        cep: percentile_sorted(&hor, 50.0)?,
        cep95: percentile_sorted(&hor, 95.0)?,
        outages: per_outage,
        outage_rms,
    })
}

/// Why a comparison has nothing to report.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CompareError {
    /// No NAV epoch lies inside both the window and the truth's span.
    #[error(
        "no epoch to compare: {before} before the truth's span, {after} after it, \
         {outside} outside --start/--end (NAV {nav_from}..{nav_to} s, truth {truth_from}..{truth_to} s)"
    )]
    NoOverlap {
        /// Epochs before the truth.
        before: usize,
        /// Epochs after the truth.
        after: usize,
        /// Epochs outside the window.
        outside: usize,
        /// NAV span [s of week].
        nav_from: f64,
        /// NAV span end.
        nav_to: f64,
        /// Truth span [s of week].
        truth_from: f64,
        /// Truth span end.
        truth_to: f64,
    },
}

/// A comparison: every epoch's errors, how the epochs matched, and the statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Errors per matched epoch, in NAV order.
    pub errors: Vec<EpochErrors>,
    /// How the epochs met the truth.
    pub matching: Matching,
    /// The statistics.
    pub stats: Statistics,
}

/// Compares parsed NAV rows with truth rows (both sorted by time): match the epochs,
/// compute the errors and their statistics.
pub fn compare(
    nav: &[NavRow],
    truth: &[NavRow],
    start: Option<f64>,
    end: Option<f64>,
    outages: &[(f64, f64)],
) -> Result<Comparison, CompareError> {
    let (errors, matching) = match_epochs(nav, truth, start, end);
    let span = |r: &[NavRow]| {
        (
            r.first().map_or(f64::NAN, |x| x.t_sow),
            r.last().map_or(f64::NAN, |x| x.t_sow),
        )
    };
    let Some(stats) = statistics(&errors, outages) else {
        let (nav_from, nav_to) = span(nav);
        let (truth_from, truth_to) = span(truth);
        return Err(CompareError::NoOverlap {
            before: matching.before_truth,
            after: matching.after_truth,
            outside: matching.outside_window,
            nav_from,
            nav_to,
            truth_from,
            truth_to,
        });
    };
    Ok(Comparison {
        errors,
        matching,
        stats,
    })
}

/// Decimals printed for a unit.
fn decimals(unit: &str) -> usize {
    if unit == "deg" { 5 } else { 4 }
}

/// The report printed: what was matched, then one row per quantity.
pub fn table(c: &Comparison) -> String {
    let m = &c.matching;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} epochs compared ({} exact, {} with the truth interpolated{}); skipped: {} before \
         the truth, {} after it, {} outside --start/--end",
        m.matched(),
        m.exact,
        m.interpolated,
        if m.interpolated > 0 {
            // Rounded to the time tolerance: 0.1, not 0.10000000000002274.
            format!(
                " across at most {} s",
                (m.max_bridged_s * 1e6).round() / 1e6
            )
        } else {
            String::new()
        },
        m.before_truth,
        m.after_truth,
        m.outside_window
    );
    let _ = writeln!(
        s,
        "\n{:<16} {:<4} {:>12} {:>12} {:>12} {:>12} {:>12}",
        "error", "unit", "RMS", "max |e|", "at t [s]", "95 % |e|", "mean"
    );
    for (Quantity { name, unit, .. }, q) in QUANTITIES.iter().zip(&c.stats.summaries) {
        let d = decimals(unit);
        let _ = writeln!(
            s,
            "{name:<16} {unit:<4} {:>12.d$} {:>12.d$} {:>12.3} {:>12.d$} {:>12.d$}",
            q.rms, q.max_abs, q.t_max_sow, q.p95_abs, q.mean
        );
    }
    let _ = writeln!(
        s,
        "\nCEP (50 % of horizontal errors) {:.4} m, CEP95 {:.4} m",
        c.stats.cep, c.stats.cep95
    );
    if !c.stats.outages.is_empty() {
        let _ = writeln!(
            s,
            "\n{:<21} {:>7} {:>11} {:>11} {:>11} {:>11} {:>11}",
            "outage [s]",
            "epochs",
            "horiz [m]",
            "vert [m]",
            "roll [deg]",
            "pitch [deg]",
            "yaw [deg]"
        );
        let row = |s: &mut String, label: String, o: &OutageMax| {
            let _ = writeln!(
                s,
                "{label:<21} {:>7} {:>11.4} {:>11.4} {:>11.5} {:>11.5} {:>11.5}",
                o.epochs,
                o.horizontal,
                o.vertical,
                o.att.roll.to_degrees(),
                o.att.pitch.to_degrees(),
                o.att.yaw.to_degrees()
            );
        };
        for o in &c.stats.outages {
            if o.epochs == 0 {
                let _ = writeln!(s, "{:<21} {:>7} (no epoch inside)", interval(o), 0);
            } else {
                row(&mut s, interval(o), o);
            }
        }
        if let Some(r) = &c.stats.outage_rms {
            row(&mut s, "RMS of the maxima".to_owned(), r);
        }
    }
    s
}

fn interval(o: &OutageMax) -> String {
    format!("{}-{}", o.from_sow, o.to_sow)
}

/// `compare.json`: inputs, matching, statistics (attitude in degrees).
pub fn summary_json(c: &Comparison, nav: (&Path, NavFormat), truth: (&Path, NavFormat)) -> Value {
    let m = &c.matching;
    let mut stats = serde_json::Map::new();
    for (Quantity { name, unit, .. }, q) in QUANTITIES.iter().zip(&c.stats.summaries) {
        let key = format!(
            "{}_{}",
            name.replace(" (down)", "").replace([' ', '-'], "_"),
            unit.replace('/', "p")
        )
        .to_lowercase();
        stats.insert(
            key,
            json!({"rms": q.rms, "max": q.max_abs, "t_max_sow": q.t_max_sow,
                   "p95": q.p95_abs, "mean": q.mean}),
        );
    }
    stats.insert("cep_m".to_owned(), json!(c.stats.cep));
    stats.insert("cep95_m".to_owned(), json!(c.stats.cep95));
    let outage = |o: &OutageMax| {
        json!({
            "from_sow": o.from_sow, "to_sow": o.to_sow, "epochs": o.epochs,
            "max_horizontal_m": (o.epochs > 0).then_some(o.horizontal),
            "max_vertical_m": (o.epochs > 0).then_some(o.vertical),
            "max_roll_deg": (o.epochs > 0).then_some(o.att.roll.to_degrees()),
            "max_pitch_deg": (o.epochs > 0).then_some(o.att.pitch.to_degrees()),
            "max_yaw_deg": (o.epochs > 0).then_some(o.att.yaw.to_degrees()),
        })
    };
    json!({
        "nav": {"path": nav.0.display().to_string(), "format": nav.1.name()},
        "truth": {"path": truth.0.display().to_string(), "format": truth.1.name()},
        "epochs": {
            "matched": m.matched(), "exact": m.exact, "interpolated": m.interpolated,
            "before_truth": m.before_truth, "after_truth": m.after_truth,
            "outside_window": m.outside_window, "max_bridged_s": m.max_bridged_s,
        },
        "statistics": Value::Object(stats),
        "outages": c.stats.outages.iter().map(outage).collect::<Vec<_>>(),
        "outage_rms": c.stats.outage_rms.as_ref().map(|r| json!({
            "outages": r.epochs,
            "horizontal_m": r.horizontal, "vertical_m": r.vertical,
            "roll_deg": r.att.roll.to_degrees(), "pitch_deg": r.att.pitch.to_degrees(),
            "yaw_deg": r.att.yaw.to_degrees(),
        })),
    })
}

/// Header of `errors.csv`.
pub const ERRORS_CSV_HEADER: &str = "t_sow,north_m,east_m,down_m,horizontal_m,vn_mps,ve_mps,\
vd_mps,roll_deg,pitch_deg,yaw_deg,interpolated";

/// Writes `errors.csv`: one row per matched epoch, shortest round-trip numbers.
fn write_errors_csv(path: &Path, errors: &[EpochErrors]) -> Result<()> {
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut w = std::io::BufWriter::new(file);
    let mut line = String::with_capacity(256);
    writeln!(w, "{ERRORS_CSV_HEADER}")?;
    for e in errors {
        line.clear();
        let _ = write!(line, "{}", e.t_sow);
        for x in [
            e.pos_n.x,
            e.pos_n.y,
            e.pos_n.z,
            e.horizontal(),
            e.v_n.x,
            e.v_n.y,
            e.v_n.z,
            e.att.roll.to_degrees(),
            e.att.pitch.to_degrees(),
            e.att.yaw.to_degrees(),
        ] {
            let _ = write!(line, ",{x}");
        }
        let _ = writeln!(line, ",{}", u8::from(e.interpolated));
        w.write_all(line.as_bytes())?;
    }
    w.flush()
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes the three plots: position, velocity and attitude errors against time, the
/// outage intervals shaded.
fn write_plots(dir: &Path, c: &Comparison) -> Result<()> {
    let t: Vec<f64> = c.errors.iter().map(|e| e.t_sow).collect();
    let col = |f: &dyn Fn(&EpochErrors) -> f64| c.errors.iter().map(f).collect::<Vec<f64>>();
    let spans: Vec<(f64, f64)> = c
        .stats
        .outages
        .iter()
        .map(|o| (o.from_sow, o.to_sow))
        .collect();
    let shade = |p: Plot| {
        if spans.is_empty() {
            p
        } else {
            p.shade("outage", spans.iter().copied())
        }
    };
    shade(
        Plot::new("Position error", "t [s of week]", "error [m]")
            .line(
                "horizontal",
                &t,
                &col(&EpochErrors::horizontal),
                LineStyle::Solid,
            )
            .line("down", &t, &col(&|e| e.pos_n.z), LineStyle::Dashed),
    )
    .write(&dir.join("position_error.svg"))?;
    shade(
        Plot::new("Velocity error", "t [s of week]", "error [m/s]")
            .line("north", &t, &col(&|e| e.v_n.x), LineStyle::Solid)
            .line("east", &t, &col(&|e| e.v_n.y), LineStyle::Dashed)
            .line("down", &t, &col(&|e| e.v_n.z), LineStyle::Dotted),
    )
    .write(&dir.join("velocity_error.svg"))?;
    shade(
        Plot::new("Attitude error", "t [s of week]", "error [deg]")
            .line(
                "roll",
                &t,
                &col(&|e| e.att.roll.to_degrees()),
                LineStyle::Solid,
            )
            .line(
                "pitch",
                &t,
                &col(&|e| e.att.pitch.to_degrees()),
                LineStyle::Dashed,
            )
            .line(
                "yaw",
                &t,
                &col(&|e| e.att.yaw.to_degrees()),
                LineStyle::Dotted,
            ),
    )
    .write(&dir.join("attitude_error.svg"))
}

/// Runs `schuler compare`.
pub fn run(args: Args) -> Result<()> {
    if let (Some(s), Some(e)) = (args.start, args.end)
        && s > e
    {
        anyhow::bail!("--start {s} is after --end {e}");
    }
    let (nav_format, nav) = read_nav(&args.nav)?;
    let (truth_format, truth) = read_nav(&args.truth)?;
    let outages = args.outages.map(|o| o.0).unwrap_or_default();
    let c = compare(&nav, &truth, args.start, args.end, &outages).with_context(|| {
        format!(
            "comparing {} with {}",
            args.nav.display(),
            args.truth.display()
        )
    })?;
    println!(
        "{} ({}) against {} ({})",
        args.nav.display(),
        nav_format.name(),
        args.truth.display(),
        truth_format.name()
    );
    print!("{}", table(&c));
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let json = summary_json(&c, (&args.nav, nav_format), (&args.truth, truth_format));
        let text = serde_json::to_string_pretty(&json).context("encoding compare.json")?;
        let path = dir.join("compare.json");
        std::fs::write(&path, text + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
        write_errors_csv(&dir.join("errors.csv"), &c.errors)?;
        write_plots(dir, &c)?;
        println!(
            "\nwrote compare.json, errors.csv, position_error.svg, velocity_error.svg, \
             attitude_error.svg to {}",
            dir.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outages_parse_and_reject_nonsense() {
        assert_eq!(
            parse_outages("215-276, 400.5-460").expect("parses").0,
            vec![(215.0, 276.0), (400.5, 460.0)]
        );
        assert_eq!(
            parse_outages("1e2-2e+2").expect("exponents").0,
            vec![(100.0, 200.0)]
        );
        for bad in ["215", "276-215", "a-b", "1-", ""] {
            assert!(parse_outages(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn wrap_is_half_open_and_takes_the_short_way() {
        use std::f64::consts::PI;
        assert_eq!(wrap_pi(-PI), PI);
        // NAV yaw 0.5 deg, truth 359.5 deg: the error is +1 deg, not -359 deg (a few
        // ulps of 2 pi from the shift and wrap).
        let e = wrap_pi(0.5f64.to_radians() - 359.5f64.to_radians());
        assert!((e - 1f64.to_radians()).abs() < 1e-14, "{e}");
    }

    fn file(text: &[u8]) -> tempfile::NamedTempFile {
        let f = tempfile::NamedTempFile::new().expect("temp");
        std::fs::write(f.path(), text).expect("write");
        f
    }

    #[test]
    fn a_week_rollover_inside_a_file_continues_the_time() {
        let f = file(b"2299 604799.5 45 7 100 0 0 0 0 0 10\n2300 0.5 45 7 100 0 0 0 0 0 10\n");
        let (format, rows) = read_nav(f.path()).expect("reads");
        assert_eq!(format, NavFormat::KfGins);
        assert_eq!(rows[1].t_sow, 604_800.5);
        let f = file(b"0 1.0 45 7 100 0 0 0 0 0 10\n0.5 2.0 45 7 100 0 0 0 0 0 10\n");
        let e = read_nav(f.path()).expect_err("half a week").to_string();
        assert!(
            e.contains(":2: field week: a GPS week is a whole number"),
            "{e}"
        );
    }

    #[test]
    fn invalid_utf8_names_its_line() {
        let f = file(b"0 1.0 45 7 100 0 0 0 0 0 10\n0 2.0 45 7 1\xff0 0 0 0 0 0 10\n");
        let e = read_nav(f.path()).expect_err("not text").to_string();
        assert!(e.contains(":2: not UTF-8 text"), "{e}");
    }
}
