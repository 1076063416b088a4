//! RTKLIB solution files (`.pos`: rnx2rtkp and RTKPOST output, the GNSS solutions of
//! the awesome-gins-datasets) as GNSS position logs.
//!
//! Header lines start with `%`; the last one before the data names the columns (it is
//! what tells the format: `latitude(deg)`, `latitude(d'")` or `x-ecef(m)` among its
//! names), its first name the time system: `GPST`, `UTC` or `JST` (UTC + 9 h). Fields
//! are separated by spaces, tabs, commas or semicolons (RTKLIB's field-separator
//! option). A data line holds the time as `week tow` or `yyyy/mm/dd hh:mm:ss.sss`
//! (told by the `/`), then the columns the header names, each one field except the
//! angles of `latitude(d'")` and `longitude(d'")`, three each (degrees, minutes,
//! seconds; the sign on the degrees, `-0` included). A file without a column header
//! (with `--gnss-format rtklib`) is read as RTKLIB's default output: GPST, latitude,
//! longitude [deg], height, Q, ns, sdn, sde, sdu, ... (extra fields ignored).
//!
//! Used columns:
//! - the position: `latitude longitude height(m)` (WGS84, ellipsoidal height; a header
//!   `% (lat/lon/height=WGS84/geodetic...)` of heights above the geoid, or the Tokyo
//!   datum, is refused) or `x-ecef(m) y-ecef(m) z-ecef(m)` (WGS84);
//! - `Q`, the solution quality: 1 fix, 2 float, 3 SBAS, 4 DGPS, 5 single, 6 PPP, mapped
//!   onto [`GnssQuality`] for `--gnss-min-quality` (PPP as float); 0 (no solution) and
//!   other values (demo5's 7, dead reckoning) are skipped and counted. Without the
//!   column every fix is kept;
//! - the standard deviations `sdn(m) sde(m) sdu(m)`, or for ECEF `sdx(m) sdy(m)
//!   sdz(m)` with the signed square roots of the covariances `sdxy(m) sdyz(m) sdzx(m)`
//!   (rotated into north, east, down; only the diagonal is kept). A fix whose
//!   standard deviations are 0 (as reference trajectories write them) or absent takes
//!   `--gnss-std`;
//! - the velocity, when present: `vn(m/s) ve(m/s) vu(m/s)` with `sdvn sdve sdvu`, or
//!   ECEF `vx(m/s) vy(m/s) vz(m/s)` with `sdvx sdvy sdvz sdvxy sdvyz sdvzx`; without
//!   (positive) standard deviations it takes `--gnss-vel-std` on each axis.
//!
//! Other columns (`ns`, `age(s)`, `ratio`, the geodetic cross terms) are not read.
//! Time is GPS seconds of week (UTC and JST plus the leap seconds of the table in
//! `gps_time.rs`), continued across week rollovers from the first fix's week. Errors
//! name the file, the line and the column.

use super::error::{InputError, InputErrorKind, quote_field};
use super::gnss::{
    GnssFormat, GnssLog, GnssQuality, GnssReadOptions, below_quality, check_time, count_warnings,
    default_std, fix_in_domain, no_usable_fix, parse_field, position_in_domain,
};
use super::gps_time::{TimeScale, WeekClock, date_of_week, week_sow};
use super::lines::{fields, is_skippable};
use chrono::NaiveDate;
use nalgebra::{Matrix3, Vector3};
use schuler::domain;
use schuler::earth::{EarthModel, Geodetic, Wgs84, c_ne};
use schuler::filter::GnssFix;
use std::path::Path;

/// The columns RTKLIB writes by default, for a file without a column header.
const DEFAULT_HEADER: &str = "% GPST latitude(deg) longitude(deg) height(m) Q ns sdn(m) \
                              sde(m) sdu(m) sdne(m) sdeu(m) sdun(m) age(s) ratio";

/// What a column of the header is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Col {
    /// The time, two fields.
    Time,
    /// Latitude [deg], in degrees, minutes and seconds (three fields) if `true`.
    Lat(bool),
    /// Longitude [deg], in degrees, minutes and seconds if `true`.
    Lon(bool),
    /// Ellipsoidal height [m].
    Height,
    /// ECEF coordinate `k` [m].
    Ecef(usize),
    /// The solution quality.
    Q,
    /// Position standard deviation `k` [m]: north, east, up or ECEF x, y, z.
    Sd(usize),
    /// ECEF cross term `k` (xy, yz, zx) [m], a signed square root of a covariance.
    SdCross(usize),
    /// Velocity `k` [m/s]: north, east, up or ECEF x, y, z.
    Vel(usize),
    /// Velocity standard deviation `k` [m/s].
    SdVel(usize),
    /// ECEF velocity cross term `k` [m/s].
    SdVelCross(usize),
    /// Not read.
    Other,
}

impl Col {
    /// The column named `name` in a header whose positions are ECEF if `ecef`.
    fn of(name: &str, ecef: bool) -> Col {
        const SD: [&str; 3] = ["sdn(m)", "sde(m)", "sdu(m)"];
        const SD_ECEF: [&str; 3] = ["sdx(m)", "sdy(m)", "sdz(m)"];
        const CROSS: [&str; 3] = ["sdxy(m)", "sdyz(m)", "sdzx(m)"];
        const VEL: [&str; 3] = ["vn(m/s)", "ve(m/s)", "vu(m/s)"];
        const VEL_ECEF: [&str; 3] = ["vx(m/s)", "vy(m/s)", "vz(m/s)"];
        const SD_VEL: [&str; 3] = ["sdvn", "sdve", "sdvu"];
        const SD_VEL_ECEF: [&str; 3] = ["sdvx", "sdvy", "sdvz"];
        const VEL_CROSS: [&str; 3] = ["sdvxy", "sdvyz", "sdvzx"];
        const XYZ: [&str; 3] = ["x-ecef(m)", "y-ecef(m)", "z-ecef(m)"];
        let at = |names: &[&str; 3]| names.iter().position(|n| n.eq_ignore_ascii_case(name));
        let (sd, vel, sd_vel) = if ecef {
            (&SD_ECEF, &VEL_ECEF, &SD_VEL_ECEF)
        } else {
            (&SD, &VEL, &SD_VEL)
        };
        match name {
            "latitude(deg)" => return Col::Lat(false),
            "latitude(d'\")" => return Col::Lat(true),
            "longitude(deg)" => return Col::Lon(false),
            "longitude(d'\")" => return Col::Lon(true),
            "height(m)" => return Col::Height,
            "Q" => return Col::Q,
            _ => {}
        }
        let found = [
            (at(&XYZ), Col::Ecef as fn(usize) -> Col),
            (at(sd), Col::Sd),
            (at(vel), Col::Vel),
            (at(sd_vel), Col::SdVel),
            (at(&CROSS).filter(|_| ecef), Col::SdCross),
            (at(&VEL_CROSS).filter(|_| ecef), Col::SdVelCross),
        ];
        found
            .into_iter()
            .find_map(|(k, col)| k.map(col))
            .unwrap_or(Col::Other)
    }

    /// How many fields of a data line the column spans.
    fn width(self) -> usize {
        match self {
            Col::Time => 2,
            Col::Lat(true) | Col::Lon(true) => 3,
            _ => 1,
        }
    }
}

/// Whether `line` is an RTKLIB column header: a `%` line naming RTKLIB's position
/// columns.
pub(crate) fn is_column_header(line: &str) -> bool {
    line.starts_with('%')
        && fields(&line[1..]).any(|f| {
            matches!(
                f,
                "latitude(deg)" | "latitude(d'\")" | "x-ecef(m)" | "e-baseline(m)"
            )
        })
}

/// The columns of a solution file, from its header.
#[derive(Debug, Clone)]
struct Layout {
    /// Each column, its first field's index and its name.
    cols: Vec<(Col, usize, String)>,
    /// The fields of a data line.
    width: usize,
    /// Whether a data line must have exactly `width` fields (a file with a header) or
    /// at least (RTKLIB's default columns assumed).
    exact: bool,
    /// Whether the position is ECEF.
    ecef: bool,
    /// The time system.
    scale: TimeScale,
    /// 1-based line of the column header (0: none).
    line: u64,
}

impl Layout {
    /// The layout of column header `l` at line `n` (0: the default columns).
    fn parse(path: &Path, n: u64, l: &str) -> Result<Layout, InputError> {
        let names: Vec<&str> = fields(l.trim_start_matches('%')).collect();
        let err = |field: Option<&str>, msg: String| {
            InputError::new(InputErrorKind::Header, path, n, field, msg)
        };
        let scale = match names.first().map(|s| s.to_ascii_uppercase()).as_deref() {
            Some("GPST") => TimeScale::Gpst,
            Some("UTC") => TimeScale::Utc,
            Some("JST") => TimeScale::Jst,
            _ => {
                return Err(err(
                    None,
                    "the column header's first name must be the time system: GPST, UTC or JST"
                        .to_owned(),
                ));
            }
        };
        if names.contains(&"e-baseline(m)") {
            return Err(err(
                Some("e-baseline(m)"),
                "an east/north/up baseline is relative to the base station, not a position: \
                 output latitude/longitude/height or x/y/z-ecef"
                    .to_owned(),
            ));
        }
        let ecef = names.contains(&"x-ecef(m)");
        let mut cols = Vec::with_capacity(names.len());
        let mut width = 0;
        for (k, name) in names.iter().enumerate() {
            let col = if k == 0 {
                Col::Time
            } else {
                Col::of(name, ecef)
            };
            cols.push((col, width, (*name).to_owned()));
            width += col.width();
        }
        let layout = Layout {
            cols,
            width,
            exact: n > 0,
            ecef,
            scale,
            line: n,
        };
        let need: &[Col] = if ecef {
            &[Col::Ecef(0), Col::Ecef(1), Col::Ecef(2)]
        } else {
            &[Col::Lat(false), Col::Lon(false), Col::Height]
        };
        for &c in need {
            if layout.find(c).is_none() && layout.find(dms(c)).is_none() {
                return Err(err(None, format!("the header lacks the {c:?} column")));
            }
        }
        Ok(layout)
    }

    /// The first field of column `col`, if the header names it.
    fn find(&self, col: Col) -> Option<usize> {
        self.cols.iter().find(|c| c.0 == col).map(|c| c.1)
    }

    /// The name of the column whose first field is `at`.
    fn name(&self, at: usize) -> &str {
        self.cols
            .iter()
            .find(|c| c.1 == at)
            .map_or("?", |c| c.2.as_str())
    }
}

/// The degrees-minutes-seconds twin of an angle column (others unchanged).
fn dms(c: Col) -> Col {
    match c {
        Col::Lat(false) => Col::Lat(true),
        Col::Lon(false) => Col::Lon(true),
        c => c,
    }
}

/// Checks the `% (lat/lon/height=...)` line `l` (line `n`): WGS84 and ellipsoidal
/// heights only.
fn check_datum(path: &Path, n: u64, l: &str) -> Result<(), InputError> {
    let Some(rest) = l.split("lat/lon/height=").nth(1) else {
        return Ok(());
    };
    let refuse = |what: &str| {
        Err(InputError::new(
            InputErrorKind::Header,
            path,
            n,
            Some("height(m)"),
            format!(
                "{what}: the reader needs WGS84 latitudes, longitudes and ellipsoidal \
                 heights (RTKLIB's out-height=ellipsoidal, datum WGS84)"
            ),
        ))
    };
    if rest.starts_with("Tokyo") {
        return refuse("positions in the Tokyo datum");
    }
    if rest.starts_with("WGS84/geodetic") {
        return refuse("heights above the geoid (geodetic)");
    }
    Ok(())
}

/// One data line's numbers.
struct Row<'l> {
    path: &'l Path,
    n: u64,
    f: Vec<&'l str>,
    layout: &'l Layout,
}

impl Row<'_> {
    /// The number in field `at`.
    fn num(&self, at: usize) -> Result<f64, InputError> {
        parse_field(self.path, self.n, self.layout.name(at), self.f[at], "")
    }

    /// Column `col`'s number, if the header names it.
    fn get(&self, col: Col) -> Result<Option<f64>, InputError> {
        self.layout.find(col).map(|at| self.num(at)).transpose()
    }

    /// Columns `col(0..3)`, if the header names all three (else `None`; a missing
    /// one reads as 0 when `zero_missing`).
    fn triple(
        &self,
        col: fn(usize) -> Col,
        zero_missing: bool,
    ) -> Result<Option<Vector3<f64>>, InputError> {
        let mut v = Vector3::zeros();
        for k in 0..3 {
            match self.get(col(k))? {
                Some(x) => v[k] = x,
                None if zero_missing => {}
                None => return Ok(None),
            }
        }
        Ok(Some(v))
    }

    /// An error at this line about field `at`.
    fn error(&self, at: usize, msg: String) -> InputError {
        InputError::new(
            InputErrorKind::NotANumber,
            self.path,
            self.n,
            Some(self.layout.name(at)),
            msg,
        )
    }

    /// An angle [deg] in degrees, or degrees, minutes and seconds (`dms`), at `at`.
    fn angle(&self, at: usize, dms: bool) -> Result<f64, InputError> {
        let d = self.num(at)?;
        if !dms {
            return Ok(d);
        }
        let (m, s) = (self.num(at + 1)?, self.num(at + 2)?);
        let a = d.abs() + m / 60.0 + s / 3600.0;
        Ok(if self.f[at].starts_with('-') { -a } else { a })
    }

    /// The time as a GPS week and second of week.
    fn time(&self) -> Result<(i64, f64), InputError> {
        let (a, b) = (self.f[0], self.f[1]);
        let bad = |what: &str| {
            self.error(
                0,
                format!(
                    "{what}: {} {}",
                    quote_field(a.as_bytes()),
                    quote_field(b.as_bytes())
                ),
            )
        };
        if a.contains('/') {
            let (date, sod) = calendar(a, b).ok_or_else(|| bad("not a date and time"))?;
            return Ok(week_sow(date, sod, self.layout.scale));
        }
        let (week, tow) = (self.num(0)?, self.num(1)?);
        if week < 0.0 || week.fract() != 0.0 || !(0.0..604_800.0).contains(&tow) {
            return Err(bad("not a GPS week and time of week"));
        }
        Ok(match self.layout.scale {
            TimeScale::Gpst => (week as i64, tow),
            scale => {
                let (date, sod) =
                    date_of_week(week as i64, tow).ok_or_else(|| bad("out of range"))?;
                week_sow(date, sod, scale)
            }
        })
    }
}

/// The date and seconds of day of `yyyy/mm/dd` and `hh:mm:ss.sss` (a two-digit year:
/// 1980-2079, as RTKLIB reads it).
fn calendar(date: &str, time: &str) -> Option<(NaiveDate, f64)> {
    let d: Vec<&str> = date.split('/').collect();
    let t: Vec<&str> = time.split(':').collect();
    let ([y, mo, day], [h, mi, s]) = (d.as_slice(), t.as_slice()) else {
        return None;
    };
    let mut y: i32 = y.parse().ok()?;
    if y < 100 {
        y += if y < 80 { 2000 } else { 1900 };
    }
    let date = NaiveDate::from_ymd_opt(y, mo.parse().ok()?, day.parse().ok()?)?;
    let (h, mi, s): (u32, u32, f64) = (h.parse().ok()?, mi.parse().ok()?, s.parse().ok()?);
    (h < 24 && mi < 60 && (0.0..61.0).contains(&s))
        .then(|| (date, f64::from(h * 3600 + mi * 60) + s))
}

/// Standard deviations north, east, down of a covariance given in ECEF (diagonal
/// `sd` squared, cross terms `cross` (xy, yz, zx) as signed square roots), at `pos`.
fn ned_std_of_ecef(pos: &Geodetic, sd: &Vector3<f64>, cross: &Vector3<f64>) -> Vector3<f64> {
    let c = |x: f64| x * x.abs();
    let (xy, yz, zx) = (c(cross[0]), c(cross[1]), c(cross[2]));
    let p = Matrix3::new(
        sd[0] * sd[0],
        xy,
        zx,
        xy,
        sd[1] * sd[1],
        yz,
        zx,
        yz,
        sd[2] * sd[2],
    );
    let c_ne = c_ne(pos.lat, pos.lon);
    let q = c_ne.transpose() * p * c_ne;
    Vector3::new(q[(0, 0)], q[(1, 1)], q[(2, 2)]).map(|v| v.max(0.0).sqrt())
}

/// What a data line gives: its quality level (`None`: skipped, no solution or dead
/// reckoning) and its fix, whose standard deviations are `None` where the line gives
/// none.
type Parsed = (Option<GnssQuality>, GnssFix, bool);

/// The quality level of RTKLIB's `Q` value (`None` for 0, no solution, and values
/// past 6).
fn quality(q: f64) -> Option<GnssQuality> {
    match q as i64 {
        1 => Some(GnssQuality::Fix),
        2 | 6 => Some(GnssQuality::Float),
        3 | 4 => Some(GnssQuality::Dgps),
        5 => Some(GnssQuality::Single),
        _ => None,
    }
}

/// A velocity north, east, down [m/s] and its standard deviations.
type Velocity = (Vector3<f64>, Vector3<f64>);

/// The velocity north, east, down [m/s] of data line `row` at `pos`, if it gives one,
/// and its standard deviations (`vel_std` on each axis where it gives none).
fn velocity(row: &Row, pos: &Geodetic, vel_std: f64) -> Result<Option<Velocity>, InputError> {
    let Some(v) = row.triple(Col::Vel, false)? else {
        return Ok(None);
    };
    let sd = row
        .triple(Col::SdVel, false)?
        .filter(|s| s.iter().all(|&x| x > 0.0));
    Ok(Some(if row.layout.ecef {
        let cross = row.triple(Col::SdVelCross, true)?.unwrap_or_default();
        let std = sd.map_or(Vector3::repeat(vel_std), |s| {
            ned_std_of_ecef(pos, &s, &cross)
        });
        (c_ne(pos.lat, pos.lon).transpose() * v, std)
    } else {
        (
            Vector3::new(v[0], v[1], -v[2]),
            sd.unwrap_or(Vector3::repeat(vel_std)),
        )
    }))
}

/// The position, quality and standard deviations of data line `row` (the fix's
/// standard deviations zero where the line gives none, flagged by the `bool`).
fn parse_row(row: &Row, clock: &mut WeekClock, vel_std: f64) -> Result<Parsed, InputError> {
    let layout = row.layout;
    let (week, sow) = row.time()?;
    let t = clock.seconds(week, sow);
    let pos = if layout.ecef {
        let r = row.triple(Col::Ecef, false)?.unwrap_or_default();
        let pos = Wgs84.ecef_to_geodetic(&r);
        domain::HEIGHT.check(pos.h).map_err(|e| InputError {
            kind: InputErrorKind::OutOfDomain,
            ..row.error(layout.find(Col::Ecef(0)).unwrap_or_default(), e.to_string())
        })?;
        pos
    } else {
        let at = |c: Col| {
            layout
                .find(c)
                .map(|a| (a, false))
                .or(layout.find(dms(c)).map(|a| (a, true)))
        };
        let ((lat_at, lat_dms), (lon_at, lon_dms)) = (
            at(Col::Lat(false)).unwrap_or_default(),
            at(Col::Lon(false)).unwrap_or_default(),
        );
        let lat = row.angle(lat_at, lat_dms)?;
        let lon = row.angle(lon_at, lon_dms)?;
        let h = row.get(Col::Height)?.unwrap_or_default();
        position_in_domain(lat, lon, h).map_err(|(i, e)| {
            let at = [lat_at, lon_at, layout.find(Col::Height).unwrap_or_default()][i];
            InputError {
                kind: InputErrorKind::OutOfDomain,
                ..row.error(at, e.to_string())
            }
        })?
    };
    let q = row.get(Col::Q)?.map_or(Some(GnssQuality::Single), quality);
    let sd = row.triple(Col::Sd, false)?;
    let pos_std = match sd {
        Some(s) if layout.ecef => ned_std_of_ecef(
            &pos,
            &s,
            &row.triple(Col::SdCross, true)?.unwrap_or_default(),
        ),
        Some(s) => s,
        None => Vector3::zeros(),
    };
    let vel = velocity(row, &pos, vel_std)?;
    let given = pos_std.iter().all(|&x| x > 0.0);
    Ok((
        q,
        GnssFix {
            t,
            pos,
            pos_std,
            vel,
        },
        given,
    ))
}

/// What [`read_rtklib`] skipped, for the warnings.
#[derive(Debug, Default)]
struct Counts {
    no_solution: usize,
    below_quality: usize,
    defaulted: usize,
}

/// Checks that data line `n` has the fields `layout` names.
fn check_width(path: &Path, n: u64, got: usize, layout: &Layout) -> Result<(), InputError> {
    let ok = if layout.exact {
        got == layout.width
    } else {
        got >= layout.width
    };
    if ok {
        return Ok(());
    }
    let msg = if layout.exact {
        format!(
            "{got} fields, the column header (line {}) names {}",
            layout.line, layout.width
        )
    } else {
        format!(
            "{got} fields, expected at least {} (no column header: RTKLIB's default \
             columns, {})",
            layout.width,
            DEFAULT_HEADER.trim_start_matches("% ")
        )
    };
    Err(InputError::new(
        InputErrorKind::ColumnCount,
        path,
        n,
        None,
        msg,
    ))
}

/// Read an RTKLIB solution file (`text`, the content of `path`) as GNSS fixes (the
/// module doc), with the reader's warnings.
pub fn read_rtklib(path: &Path, text: &str, opts: &GnssReadOptions) -> Result<GnssLog, InputError> {
    let mut layout: Option<Layout> = None;
    let mut clock = WeekClock::default();
    let mut fixes: Vec<GnssFix> = Vec::new();
    let mut counts = Counts::default();
    for (i, line) in text.lines().enumerate() {
        let n = i as u64 + 1;
        let l = line.trim();
        if l.starts_with('%') {
            check_datum(path, n, l)?;
            if is_column_header(l) {
                layout = Some(Layout::parse(path, n, l)?);
            }
            continue;
        }
        if is_skippable(l.as_bytes()) {
            continue;
        }
        if layout.is_none() {
            layout = Some(Layout::parse(path, 0, DEFAULT_HEADER)?);
        }
        let Some(layout) = &layout else { continue };
        let f: Vec<&str> = fields(l).collect();
        check_width(path, n, f.len(), layout)?;
        let row = Row { path, n, f, layout };
        let (q, mut fix, given) = parse_row(&row, &mut clock, opts.vel_std)?;
        check_time(path, n, layout.name(0), fix.t, fixes.last().map(|f| f.t))?;
        let Some(q) = q else {
            counts.no_solution += 1;
            continue;
        };
        if q < opts.min_quality {
            counts.below_quality += 1;
            continue;
        }
        if !given {
            let sd = layout
                .find(Col::Sd(0))
                .map_or("sdn(m)", |at| layout.name(at));
            fix.pos_std = default_std(path, n, sd, opts.default_std)?;
            counts.defaulted += usize::from(layout.find(Col::Sd(0)).is_some());
        }
        fixes.push(fix_in_domain(path, n, fix)?);
    }
    let warnings = count_warnings(&[
        (
            counts.no_solution,
            "epochs without a solution (Q 0) or of dead reckoning skipped".to_owned(),
        ),
        (counts.below_quality, below_quality(opts.min_quality)),
        (
            counts.defaulted,
            "fixes with standard deviations of 0 took --gnss-std".to_owned(),
        ),
    ]);
    if fixes.is_empty() {
        return Err(no_usable_fix(path, &warnings));
    }
    Ok(GnssLog {
        fixes,
        format: GnssFormat::Rtklib,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str, opts: &GnssReadOptions) -> Result<GnssLog, InputError> {
        read_rtklib(Path::new("sol.pos"), text, opts)
    }

    const HEADER: &str = "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,\
                          5:single,6:ppp,ns=# of satellites)\n\
                          %  GPST          latitude(deg) longitude(deg)  height(m)   Q  ns   \
                          sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio\n";

    #[test]
    fn week_tow_geodetic_with_quality_filter() {
        let text = format!(
            "{HEADER}2137 422922.000   40.097025378 -105.147247371  1578.8456   2  11   \
             1.4193   1.3913   2.9108  -0.4639   0.9795  -1.1219   0.00    0.0\n\
             2137 422923.000   40.097025245 -105.147247922  1578.8200   1  11   0.0061   \
             0.0059   0.0135  -0.0020   0.0040  -0.0048   0.00    3.0\n"
        );
        let got = read(&text, &GnssReadOptions::default()).expect("reads");
        assert_eq!(got.fixes.len(), 2);
        let f = got.fixes[0];
        assert_eq!(f.t, 422_922.0);
        assert_eq!(
            f.pos,
            Geodetic::from_degrees(40.097025378, -105.147247371, 1578.8456)
        );
        assert_eq!(f.pos_std, Vector3::new(1.4193, 1.3913, 2.9108));
        assert!(f.vel.is_none());
        let opts = GnssReadOptions {
            min_quality: GnssQuality::Fix,
            ..GnssReadOptions::default()
        };
        let got = read(&text, &opts).expect("reads");
        assert_eq!(got.fixes.len(), 1);
        assert_eq!(got.fixes[0].t, 422_923.0);
        assert_eq!(
            got.warnings,
            ["1 fixes below --gnss-min-quality fix dropped"]
        );
    }

    #[test]
    fn utc_dates_dms_and_velocity() {
        let text = "%  UTC                   latitude(d'\")  longitude(d'\")  height(m)   Q  ns   \
                    sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdue(m) age(s)  ratio  vn(m/s) \
                    ve(m/s) vu(m/s) sdvn sdve sdvu sdvne sdveu sdvun\n\
                    2020/12/24 21:28:24.000   -0 30 00.00000  -105 08 50.09054  1578.8456   5  11   \
                    1.4193   1.3913   2.9108  -0.4639   0.9795  -1.1219   0.00    0.0  1.5 -2.0 0.25 \
                    0 0 0 0 0 0\n";
        let got = read(text, &GnssReadOptions::default()).expect("reads");
        let f = got.fixes[0];
        // UTC + 18 s: RTKPOST's GPST of the same epoch, week 2137 422922 s.
        assert_eq!(f.t, 422_922.0);
        assert!((f.pos.lat.to_degrees() + 0.5).abs() < 1e-12);
        let lon = -(105.0 + 8.0 / 60.0 + 50.09054 / 3600.0);
        assert!((f.pos.lon.to_degrees() - lon).abs() < 1e-12);
        // Zero velocity standard deviations: --gnss-vel-std on each axis.
        assert_eq!(
            f.vel,
            Some((Vector3::new(1.5, -2.0, -0.25), Vector3::repeat(0.1)))
        );
    }

    #[test]
    fn ecef_with_covariance_and_default_std() {
        let pos = Geodetic::from_degrees(35.0, 137.0, 50.0);
        let r = Wgs84.geodetic_to_ecef(&pos);
        // A covariance that is 2 m north, 3 m east and 4 m down in NED, in ECEF.
        let c = c_ne(pos.lat, pos.lon);
        let p = c * Matrix3::from_diagonal(&Vector3::new(4.0, 9.0, 16.0)) * c.transpose();
        let s = |x: f64| x.signum() * x.abs().sqrt();
        let text = format!(
            "%  GPST x-ecef(m) y-ecef(m) z-ecef(m) Q ns sdx(m) sdy(m) sdz(m) sdxy(m) sdyz(m) \
             sdzx(m) age(s) ratio\n\
             2300 100.5 {:.4} {:.4} {:.4} 1 20 {} {} {} {} {} {} 0 0\n\
             2300 101.5 {:.4} {:.4} {:.4} 1 20 0 0 0 0 0 0 0 0\n",
            r.x,
            r.y,
            r.z,
            s(p[(0, 0)]),
            s(p[(1, 1)]),
            s(p[(2, 2)]),
            s(p[(0, 1)]),
            s(p[(1, 2)]),
            s(p[(2, 0)]),
            r.x,
            r.y,
            r.z,
        );
        let opts = GnssReadOptions {
            default_std: Some(Vector3::new(7.0, 8.0, 9.0)),
            ..GnssReadOptions::default()
        };
        let got = read(&text, &opts).expect("reads");
        let f = got.fixes[0];
        assert!((f.pos.h - 50.0).abs() < 1e-4, "{}", f.pos.h);
        assert!((f.pos.lat - pos.lat).abs() < 1e-10 && (f.pos.lon - pos.lon).abs() < 1e-10);
        assert!(
            (f.pos_std - Vector3::new(2.0, 3.0, 4.0)).norm() < 1e-9,
            "{}",
            f.pos_std
        );
        assert_eq!(got.fixes[1].pos_std, Vector3::new(7.0, 8.0, 9.0));
        assert_eq!(
            got.warnings,
            ["1 fixes with standard deviations of 0 took --gnss-std"]
        );
        let e = read(&text, &GnssReadOptions::default()).expect_err("no std");
        assert_eq!(
            e.to_string(),
            "sol.pos:3: field sdx(m): the file gives no position standard deviations for this \
             fix: give them with --gnss-std N,E,D [m]"
        );
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let row = "2137 422922.0 40.0 -105.0 1578.8 1 11 0.1 0.1 0.2 0 0 0 0 0";
        let cases = [
            (
                format!("{HEADER}{row} 7\n"),
                ":3: 16 fields, the column header (line 2) names 15",
            ),
            (
                format!("{HEADER}{}\n", row.replace("40.0", "4O.0")),
                ":3: field latitude(deg): not a number: \"4O.0\"",
            ),
            (
                format!("{HEADER}{}\n", row.replace("422922.0", "700000")),
                ":3: field GPST: not a GPS week and time of week",
            ),
            (
                format!("{HEADER}{row}\n{row}\n"),
                ":4: field GPST: time 422922 does not increase",
            ),
            (
                format!("{}{row}\n", HEADER.replace("ellipsoidal", "geodetic")),
                ":1: field height(m): heights above the geoid (geodetic)",
            ),
            (
                "% GPST e-baseline(m) n-baseline(m) u-baseline(m) Q\n".to_owned(),
                ":1: field e-baseline(m): an east/north/up baseline",
            ),
            (
                format!("{HEADER}{}\n", row.replace("-105.0", "400.0")),
                ":3: field longitude(deg): longitude 400 deg is outside [-180, 360] deg",
            ),
            (
                format!("{HEADER}{}\n", row.replace("1578.8", "1e12")),
                ":3: field height(m): height 1e12 m is outside",
            ),
            (HEADER.to_owned(), "sol.pos: no data line"),
        ];
        for (text, want) in cases {
            let e = read(&text, &GnssReadOptions::default()).expect_err(want);
            assert!(e.to_string().contains(want), "{want:?}: {e}");
        }
        // Without a header: RTKLIB's default columns, extra fields allowed.
        let got = read(&format!("{row} 1 2 3\n"), &GnssReadOptions::default()).expect("reads");
        assert_eq!(got.fixes[0].pos_std, Vector3::new(0.1, 0.1, 0.2));
    }
}
