//! Navigation-result writers: the KF-GINS text format (`nav.txt`) and our CSV
//! (`nav.csv`), both streamed through one fixed-decimal number writer.
//!
//! KF-GINS navigation result, one epoch per line, space separated:
//! `week sow lat[deg] lon[deg] h[m] vn ve vd[m/s] roll pitch yaw[deg]`. We write yaw in
//! [0, 360) (the convention of the awesome-gins-datasets truth files), longitude in
//! (-180, 180] and latitude in [-90, 90] (a state carried past a pole is written as
//! the equivalent point on the opposite meridian, [`NavState::normalized`]), so the
//! file stays valid over the poles.
//!
//! `nav.csv` has the same columns after `t_sow` and, from a writer made with
//! [`NavWriter::create_extended`] (as `schuler nav` does), four more that are defined
//! everywhere, poles included: the ECEF position `x_ecef_m, y_ecef_m, z_ecef_m` and
//! the wander azimuth `wander_azimuth_deg` (angle of the navigation frame's x axis
//! east of north; 0 for the NED mechanization).

use anyhow::{Context, Result};
use nalgebra::Vector3;
use schuler::analysis::errors::EpochErrors;
use schuler::earth::{EarthModel, Geodetic};
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::rotation::Euler;
use std::io::Write;
use std::path::Path;

pub use crate::fixed::push_fixed;
use crate::fixed::{Line, Twin, Words, put_bytes, put_field};
use crate::line_file::{LineFile, LineWriter};
use crate::text_block::{TextBlock, put_first_field, window};
use std::f64::consts::FRAC_PI_2;

/// Longitude (or any angle) [rad] in degrees, wrapped to (-180, 180]
/// ([`schuler::rotation::wrap_pi`]).
fn wrap_lon_deg(lon_rad: f64) -> f64 {
    schuler::rotation::wrap_pi(lon_rad).to_degrees()
}

/// Longitude-like angle `x` [deg] in (−180, 180] that stays there when printed
/// with `decimals` digits: −180 + 1e-13 would print as −180.000…, so it becomes 180.
fn printable_lon(x: f64, decimals: i32) -> f64 {
    if x < -180.0 + 0.5 * 10f64.powi(-decimals) {
        180.0
    } else {
        x
    }
}

/// Heading `y` [deg] in [0, 360) that stays there when printed with `decimals`
/// digits: 360 − 1e-13 would print as 360.000…, so it becomes 0.
fn printable_heading(y: f64, decimals: i32) -> f64 {
    if y >= 360.0 - 0.5 * 10f64.powi(-decimals) {
        0.0
    } else {
        y
    }
}

/// [`Euler::heading_0_2pi`], the same bits, without its `fmod` for a yaw within one
/// turn (where `yaw % 2π` is `yaw` exactly and `rem_euclid` adds 2π to a negative
/// one).
#[inline(always)]
fn heading_0_2pi(e: &Euler) -> f64 {
    use std::f64::consts::TAU;
    let yaw = e.yaw;
    if (0.0..TAU).contains(&yaw) {
        yaw
    } else if yaw > -TAU && yaw < 0.0 {
        let y = yaw + TAU;
        if y >= TAU { 0.0 } else { y }
    } else {
        e.heading_0_2pi()
    }
}

/// A state's fields as `nav.txt` prints them, before rounding: latitude and longitude
/// [deg] (longitude in [-180, 180)), height [m], velocity north, east, down [m/s],
/// roll, pitch [deg] and yaw [deg, in [0, 360)]. For front ends that hand numbers
/// over instead of text (the Python package).
pub fn nav_fields(s: &NavState) -> [f64; 9] {
    let r = Row::of(s);
    [
        r.lat_deg,
        r.lon_deg,
        r.h,
        r.v[0],
        r.v[1],
        r.v[2],
        r.roll_deg,
        r.pitch_deg,
        r.yaw_deg,
    ]
}

/// One navigation epoch in output units.
struct Row {
    lat_deg: f64,
    lon_deg: f64,
    h: f64,
    v: [f64; 3],
    roll_deg: f64,
    pitch_deg: f64,
    yaw_deg: f64,
}

impl Row {
    fn of(s: &NavState) -> Self {
        let s = &s.normalized();
        Self::with_euler(s, &s.euler())
    }

    /// The row of a state within latitude [-90°, 90°] whose attitude is `e`.
    fn with_euler(s: &NavState, e: &Euler) -> Self {
        Self {
            lat_deg: s.pos.lat.to_degrees(),
            lon_deg: printable_lon(wrap_lon_deg(s.pos.lon), 11),
            h: s.pos.h,
            v: [s.v_n.x, s.v_n.y, s.v_n.z],
            roll_deg: e.roll.to_degrees(),
            pitch_deg: e.pitch.to_degrees(),
            yaw_deg: printable_heading(heading_0_2pi(e).to_degrees(), 9),
        }
    }

    /// Fields after the time, with `sep` between them. Decimals: 1e-11 deg (< 2 um)
    /// for latitude and longitude, 1 um for height, 1 um/s for velocity, 1e-9 deg for
    /// attitude: finer than any INS resolves, so files round-trip our results.
    fn push(&self, out: &mut Vec<u8>, sep: u8) {
        // One call per field, each with its decimals as a constant (push_fixed is
        // inlined into each), rather than a loop over (value, decimals) pairs.
        let mut field = |x: f64, decimals: usize| {
            out.push(sep);
            push_fixed(out, x, decimals);
        };
        field(self.lat_deg, 11);
        field(self.lon_deg, 11);
        field(self.h, 6);
        field(self.v[0], 6);
        field(self.v[1], 6);
        field(self.v[2], 6);
        field(self.roll_deg, 9);
        field(self.pitch_deg, 9);
        field(self.yaw_deg, 9);
    }

    /// [`Row::push`] into words at `pos`: the same bytes, each field preceded by the
    /// separator; returns the end, or `None` when a field is outside
    /// [`put_field`]'s range (then [`Row::push`] writes the row).
    #[inline(always)]
    fn put<W: Words + ?Sized>(&self, out: &mut W, pos: usize) -> Option<usize> {
        // As in `push`, one call per field with constant decimals.
        let mut field = |pos: usize, x: f64, decimals: usize| put_field(out, pos, x, decimals);
        let pos = field(pos, self.lat_deg, 11)?;
        let pos = field(pos, self.lon_deg, 11)?;
        let pos = field(pos, self.h, 6)?;
        let pos = field(pos, self.v[0], 6)?;
        let pos = field(pos, self.v[1], 6)?;
        let pos = field(pos, self.v[2], 6)?;
        let pos = field(pos, self.roll_deg, 9)?;
        let pos = field(pos, self.pitch_deg, 9)?;
        field(pos, self.yaw_deg, 9)
    }
}

/// Append the columns of a navigation row after its time, each preceded by `sep`:
/// lat, lon [deg], h [m], vn, ve, vd [m/s], roll, pitch, yaw [deg], with the decimals
/// of `nav.txt` (1e-11 deg, 1 um, 1 um/s, 1e-9 deg) and its ranges (latitude in
/// [-90, 90], longitude in (-180, 180], yaw in [0, 360)). The attitude comes as
/// Euler angles (`s`'s own, e.g. a trajectory's, in [`Euler::from_dcm`]'s ranges),
/// which spares three arctangents; a state past a pole is turned by
/// [`NavState::normalized`], so its attitude then comes from `q_bn`.
pub fn push_nav_fields(out: &mut Vec<u8>, s: &NavState, e: &Euler, sep: u8) {
    let n = s.normalized();
    if n == *s {
        Row::with_euler(s, e).push(out, sep);
    } else {
        Row::with_euler(&n, &n.euler()).push(out, sep);
    }
}

/// [`push_nav_fields`] into words at `pos` (the same bytes, separators from `out`);
/// returns the end, or `None` when [`push_nav_fields`] must write the row: a field
/// outside [`put_field`]'s range, a NaN in the state, or a state past a pole.
#[inline(always)]
pub fn put_nav_fields<W: Words + ?Sized>(
    out: &mut W,
    pos: usize,
    s: &NavState,
    e: &Euler,
) -> Option<usize> {
    // push_nav_fields takes `e` when `s.normalized() == *s`: latitude within
    // [-90, 90] deg and no NaN anywhere (NaN != NaN). A NaN in a printed field makes
    // `put` decline the row; the time and the quaternion are not printed: their sum is
    // NaN when one of them is (or on inf - inf, which only sends the row the other way).
    let q = &s.q_bn;
    if !(-FRAC_PI_2..=FRAC_PI_2).contains(&s.pos.lat) || (s.t + q.i + q.j + q.k + q.w).is_nan() {
        return None;
    }
    Row::with_euler(s, e).put(out, pos)
}

/// One navigation epoch with the quantities defined everywhere (poles included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavEpoch {
    /// The NED state (at a pole relative to the mechanization's pole meridian).
    pub state: NavState,
    /// ECEF position [m].
    pub r_e: Vector3<f64>,
    /// Wander azimuth [rad]: the navigation frame's x axis east of north (0 in NED).
    pub wander_azimuth: f64,
}

/// ECEF position of a geodetic position on the ellipsoid (`a`, `e²`), as
/// [`EarthModel::geodetic_to_ecef`].
fn ecef_of(p: &Geodetic, a: f64, e2: f64) -> Vector3<f64> {
    let (sl, cl) = p.lat.sin_cos();
    let (so, co) = p.lon.sin_cos();
    let rn = a / (1.0 - e2 * sl * sl).sqrt();
    Vector3::new(
        (rn + p.h) * cl * co,
        (rn + p.h) * cl * so,
        (rn * (1.0 - e2) + p.h) * sl,
    )
}

/// Writes `nav.txt` (KF-GINS) and `nav.csv` side by side (or the text alone),
/// through the fast row writer ([`TextBlock`]).
pub struct NavWriter {
    txt: LineFile,
    /// `nav.csv`, unless the text is written alone.
    csv: Option<LineFile>,
    /// `week` and a space: the start of every `nav.txt` line.
    week: Vec<u8>,
    txt_text: TextBlock,
    csv_text: TextBlock,
    line: Vec<u8>,
    rows: u64,
    /// Ellipsoid `(a, e²)` when the CSV has the ECEF and wander-azimuth columns.
    extended: Option<(f64, f64)>,
}

/// Windows of a `nav.txt` line after its week (the time and 9 fields of at most 17
/// bytes with their separators, 188 bytes) and of a `nav.csv` line (14 such fields:
/// 273 bytes).
const NAV_WINDOW: usize = 256 + 8;
const CSV_WINDOW: usize = 512 + 8;
/// Text gathered before it goes to the files [bytes].
const NAV_BLOCK: usize = 1 << 16;

/// Header of `nav.csv` from [`NavWriter::create`].
pub const CSV_HEADER: &str =
    "t_sow,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg";

/// Header of `nav.csv` from [`NavWriter::create_extended`]: [`CSV_HEADER`], then
/// ECEF position and wander azimuth.
pub const CSV_HEADER_EXTENDED: &str = "t_sow,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,\
     roll_deg,pitch_deg,yaw_deg,x_ecef_m,y_ecef_m,z_ecef_m,wander_azimuth_deg";

impl NavWriter {
    /// Create `dir/nav.txt` and `dir/nav.csv` with the ten columns of
    /// [`CSV_HEADER`] (the directory is created if needed).
    pub fn create(dir: &Path, week: u32) -> Result<Self> {
        Self::open(dir, week, None)
    }

    /// Create `dir/nav.txt` and `dir/nav.csv` with the columns of
    /// [`CSV_HEADER_EXTENDED`]; [`NavWriter::write`] then computes ECEF on `earth`'s
    /// ellipsoid.
    pub fn create_extended<E: EarthModel>(dir: &Path, week: u32, earth: &E) -> Result<Self> {
        let geometry = (earth.semi_major_axis(), earth.eccentricity_squared());
        Self::open(dir, week, Some(geometry))
    }

    /// As [`NavWriter::create_extended`], with the navigation text named `txt_name`
    /// (e.g. KF-GINS's `KF_GINS_Navresult.nav`), and `nav.csv` only if `csv`.
    pub fn create_named<E: EarthModel>(
        dir: &Path,
        txt_name: &str,
        week: u32,
        earth: &E,
        csv: bool,
    ) -> Result<Self> {
        let geometry = (earth.semi_major_axis(), earth.eccentricity_squared());
        Self::open_named(dir, txt_name, week, Some(geometry), csv)
    }

    fn open(dir: &Path, week: u32, extended: Option<(f64, f64)>) -> Result<Self> {
        Self::open_named(dir, "nav.txt", week, extended, true)
    }

    fn open_named(
        dir: &Path,
        txt_name: &str,
        week: u32,
        extended: Option<(f64, f64)>,
        with_csv: bool,
    ) -> Result<Self> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output directory {}", dir.display()))?;
        let txt = LineFile::create(dir.join(txt_name))?;
        let csv = if with_csv {
            let mut csv = LineFile::create(dir.join("nav.csv"))?;
            let header = if extended.is_some() {
                CSV_HEADER_EXTENDED
            } else {
                CSV_HEADER
            };
            csv.append(format!("{header}\n").as_bytes())?;
            Some(csv)
        } else {
            None
        };
        Ok(Self {
            txt,
            csv,
            week: format!("{week} ").into_bytes(),
            txt_text: TextBlock::default(),
            csv_text: TextBlock::default(),
            line: Vec::with_capacity(256),
            rows: 0,
            extended,
        })
    }

    /// Write one NED epoch to both files (in an extended CSV with ECEF from the
    /// geodetic position and wander azimuth 0).
    pub fn write(&mut self, s: &NavState) -> Result<()> {
        let (a, e2) = self.extended.unwrap_or((1.0, 0.0));
        let r_e = if self.extended.is_some() {
            ecef_of(&s.pos, a, e2)
        } else {
            Vector3::zeros()
        };
        self.write_epoch(&NavEpoch {
            state: *s,
            r_e,
            wander_azimuth: 0.0,
        })
    }

    /// Write one epoch to both files; the ECEF position and wander azimuth go to the
    /// extended CSV only. Decimals: 1 um for ECEF, 1e-9 deg for the azimuth.
    pub fn write_epoch(&mut self, epoch: &NavEpoch) -> Result<()> {
        if !self.put_epoch(epoch) {
            self.push_epoch(epoch);
        }
        self.rows += 1;
        if self.txt_text.len() >= NAV_BLOCK || self.csv_text.len() >= NAV_BLOCK {
            self.flush()?;
        }
        Ok(())
    }

    /// [`NavWriter::write_epoch`]'s lines through the windows; `false` (and nothing
    /// counted) where [`put_nav_fields`] or [`put_field`] decline a number.
    #[inline(always)]
    fn put_epoch(&mut self, epoch: &NavEpoch) -> bool {
        let s = &epoch.state;
        let e = s.euler();
        let week = self.week.len();
        let txt = self.txt_text.scratch(week + NAV_WINDOW);
        let (start, txt) = txt.split_at_mut(week);
        start.copy_from_slice(&self.week);
        let txt = Line {
            bytes: window::<NAV_WINDOW>(txt, 0),
            sep: b' ',
        };
        if self.csv.is_none() {
            let mut w = txt;
            let Some(end) = put_first_field(&mut w, 0, s.t, 6)
                .and_then(|end| put_nav_fields(&mut w, end, s, &e))
            else {
                return false;
            };
            w.put(end, u64::from(b'\n'));
            self.txt_text
                .advance(week + Line::<NAV_WINDOW>::end(end) + 1);
            return true;
        }
        let csv = Line {
            bytes: window::<CSV_WINDOW>(self.csv_text.scratch(CSV_WINDOW), 0),
            sep: b',',
        };
        let mut w = Twin(txt, csv);
        let Some(end) =
            put_first_field(&mut w, 0, s.t, 6).and_then(|end| put_nav_fields(&mut w, end, s, &e))
        else {
            return false;
        };
        w.0.put(end, u64::from(b'\n'));
        let mut csv = w.1;
        let csv_end = match self.extended {
            Some(_) => {
                let r = &epoch.r_e;
                let azimuth = printable_lon(wrap_lon_deg(epoch.wander_azimuth), 9);
                let Some(end) = put_field(&mut csv, end, r.x, 6)
                    .and_then(|p| put_field(&mut csv, p, r.y, 6))
                    .and_then(|p| put_field(&mut csv, p, r.z, 6))
                    .and_then(|p| put_field(&mut csv, p, azimuth, 9))
                else {
                    return false;
                };
                end
            }
            None => end,
        };
        csv.put(csv_end, u64::from(b'\n'));
        self.txt_text
            .advance(week + Line::<NAV_WINDOW>::end(end) + 1);
        self.csv_text.advance(Line::<CSV_WINDOW>::end(csv_end) + 1);
        true
    }

    /// [`NavWriter::write_epoch`]'s lines through the `Vec` writers, for any numbers.
    fn push_epoch(&mut self, epoch: &NavEpoch) {
        let s = &epoch.state;
        let row = Row::of(s);
        self.line.clear();
        self.line.extend_from_slice(&self.week);
        push_fixed(&mut self.line, s.t, 6);
        row.push(&mut self.line, b' ');
        self.line.push(b'\n');
        self.txt_text.extend(&self.line);
        if self.csv.is_none() {
            return;
        }
        self.line.clear();
        push_fixed(&mut self.line, s.t, 6);
        row.push(&mut self.line, b',');
        if self.extended.is_some() {
            for (x, d) in [
                (epoch.r_e.x, 6),
                (epoch.r_e.y, 6),
                (epoch.r_e.z, 6),
                (printable_lon(wrap_lon_deg(epoch.wander_azimuth), 9), 9),
            ] {
                self.line.push(b',');
                push_fixed(&mut self.line, x, d);
            }
        }
        self.line.push(b'\n');
        self.csv_text.extend(&self.line);
    }

    /// Writes the gathered text to the files.
    fn flush(&mut self) -> Result<()> {
        self.txt.append(self.txt_text.as_bytes())?;
        self.txt_text.clear();
        if let Some(csv) = self.csv.as_mut() {
            csv.append(self.csv_text.as_bytes())?;
        }
        self.csv_text.clear();
        Ok(())
    }

    /// Writes what is left to both files; returns the number of epochs written.
    pub fn finish(mut self) -> Result<u64> {
        self.flush()?;
        Ok(self.rows)
    }
}

/// Write states as a KF-GINS navigation text file (week 0), e.g. a simulation's truth.
pub fn write_truth_text(path: &Path, states: impl Iterator<Item = NavState>) -> Result<()> {
    let mut w = LineWriter::create(path)?;
    let mut line = Vec::with_capacity(256);
    for s in states {
        line.clear();
        line.extend_from_slice(b"0 ");
        push_fixed(&mut line, s.t, 6);
        Row::of(&s).push(&mut line, b' ');
        line.push(b'\n');
        w.write_all(&line)?;
    }
    w.finish()
}

/// How [`push_imu_line`] prints the numbers of an IMU line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImuDigits {
    /// Every number (time included) in shortest round-trip form: nothing is lost, and
    /// the file reads back to the same f64s.
    Shortest,
    /// Time to 1e-9 s, increments in exponent notation with this many significant
    /// digits (clamped to 1..=17; 17 round-trip every f64 exactly; KF-GINS data sets
    /// carry about 13).
    Significant(usize),
}

/// Append one KF-GINS IMU line `t dtheta_xyz dvel_xyz` [s, rad, m/s; FRD], fields
/// separated by `sep` (b' ' for KF-GINS text, b',' for CSV), without the newline.
pub fn push_imu_line(out: &mut Vec<u8>, s: &ImuSample, sep: u8, digits: ImuDigits) {
    let (a, v) = (s.dtheta, s.dvel);
    let increments = [a.x, a.y, a.z, v.x, v.y, v.z];
    match digits {
        ImuDigits::Shortest => {
            let mut num = zmij::Buffer::new();
            out.extend_from_slice(num.format(s.t).as_bytes());
            for x in increments {
                out.push(sep);
                out.extend_from_slice(num.format(x).as_bytes());
            }
        }
        ImuDigits::Significant(d) => {
            let p = d.clamp(1, 17) - 1;
            // Writing to a Vec cannot fail.
            let _ = write!(out, "{:.9}", s.t);
            for x in increments {
                out.push(sep);
                let _ = write!(out, "{x:.p$e}");
            }
        }
    }
}

/// The increments of [`push_imu_line`]'s [`ImuDigits::Shortest`] line, each preceded
/// by the separator, into words at `pos`; returns the end. `num` is scratch.
#[inline(always)]
pub fn put_imu_increments<W: Words + ?Sized>(
    out: &mut W,
    pos: usize,
    s: &ImuSample,
    num: &mut zmij::Buffer,
) -> usize {
    // One call per field (not a loop over an array of them).
    let mut field = |pos: usize, x: f64| {
        out.sep(pos);
        put_bytes(out, pos + 1, num.format(x).as_bytes())
    };
    let (a, v) = (s.dtheta, s.dvel);
    let pos = field(pos, a.x);
    let pos = field(pos, a.y);
    let pos = field(pos, a.z);
    let pos = field(pos, v.x);
    let pos = field(pos, v.y);
    field(pos, v.z)
}

/// Write samples as a KF-GINS IMU text file: `t dtheta_xyz dvel_xyz`, time to 1e-9 s
/// and increments in exponent notation with `digits` significant digits (17 round-trip
/// every f64 exactly; KF-GINS data sets carry about 13); lines from
/// [`push_imu_line`].
pub fn write_imu_text(
    path: &Path,
    samples: impl Iterator<Item = ImuSample>,
    digits: usize,
) -> Result<()> {
    let mut w = LineWriter::create(path)?;
    let mut line = Vec::with_capacity(256);
    for s in samples {
        line.clear();
        push_imu_line(&mut line, &s, b' ', ImuDigits::Significant(digits));
        line.push(b'\n');
        w.write_all(&line)?;
    }
    w.finish()
}

/// Header of `errors.csv`.
pub const ERRORS_CSV_HEADER: &str = "t_sow,north_m,east_m,down_m,horizontal_m,vn_mps,ve_mps,\
vd_mps,roll_deg,pitch_deg,yaw_deg,interpolated";

/// An epoch's errors as `errors.csv` holds them after the time: position north, east,
/// down and horizontal [m], velocity north, east, down [m/s], roll, pitch, yaw [deg].
pub fn error_fields(e: &EpochErrors) -> [f64; 10] {
    [
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
    ]
}

/// Writes `errors.csv`: one row per matched epoch, shortest round-trip numbers.
pub fn write_errors_csv(path: &Path, errors: &[EpochErrors]) -> Result<()> {
    let mut w = LineWriter::create(path)?;
    let mut line = String::with_capacity(256);
    use std::fmt::Write as _;
    writeln!(w, "{ERRORS_CSV_HEADER}")?;
    for e in errors {
        line.clear();
        let _ = write!(line, "{}", e.t_sow);
        for x in error_fields(e) {
            let _ = write!(line, ",{x}");
        }
        let _ = writeln!(line, ",{}", u8::from(e.interpolated));
        w.write_all(line.as_bytes())?;
    }
    w.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::{Line, Twin};
    use proptest::prelude::*;
    use std::f64::consts::{PI, TAU};

    /// [`put_nav_fields`] and [`put_imu_increments`] into a text and CSV twin, with
    /// [`push_nav_fields`] and [`push_imu_line`] (the Vec writers) as the oracle: the
    /// same bytes, or `None` exactly where the Vec writer must take the row.
    fn twin_text(
        put: impl FnOnce(&mut Twin<'_, 264, 264>) -> Option<usize>,
    ) -> Option<[String; 2]> {
        let (mut a, mut b) = ([b'#'; 264], [b'#'; 264]);
        let mut w = Twin(
            Line {
                bytes: &mut a,
                sep: b' ',
            },
            Line {
                bytes: &mut b,
                sep: b',',
            },
        );
        let end = Line::<264>::end(put(&mut w)?);
        let text = |bytes: &[u8]| String::from_utf8(bytes[..end].to_vec()).expect("ascii");
        Some([text(&a), text(&b)])
    }

    fn pushed_nav(s: &NavState, e: &Euler) -> [String; 2] {
        [b' ', b','].map(|sep| {
            let mut v = Vec::new();
            push_nav_fields(&mut v, s, e, sep);
            String::from_utf8(v).expect("ascii")
        })
    }

    fn nav_state(lat_deg: f64, lon_deg: f64, h: f64, v: [f64; 3], e: &Euler) -> NavState {
        NavState::new(
            12.5,
            Geodetic::new(lat_deg.to_radians(), lon_deg.to_radians(), h),
            Vector3::from(v),
            *e,
        )
    }

    /// The fast heading is [`Euler::heading_0_2pi`], bit for bit, at and around the
    /// ends of its ranges.
    #[test]
    fn heading_without_fmod() {
        let mut yaws = vec![0.0, -0.0, PI, -PI, TAU, -TAU, 3.0 * PI, -3.0 * PI, 1e-300];
        for y in [0.0f64, TAU, -TAU, PI, -PI, 1e-17, -1e-17] {
            for k in 1..4u64 {
                yaws.push(f64::from_bits(y.to_bits() + k));
                yaws.push(f64::from_bits(y.to_bits().wrapping_sub(k)));
            }
        }
        yaws.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
        for yaw in yaws {
            let e = Euler::new(0.0, 0.0, yaw);
            assert_eq!(
                heading_0_2pi(&e).to_bits(),
                e.heading_0_2pi().to_bits(),
                "{yaw:e}"
            );
        }
    }

    /// Rows the fast writer declines (past a pole, NaN, out of its range) and rows it
    /// writes, at the edges of the printed ranges.
    #[test]
    fn nav_fields_examples() {
        let e = Euler::from_degrees(1.0, -2.0, 359.9999999999);
        let cases = [
            nav_state(45.0, 7.0, 300.0, [30.0, 0.0, -0.0], &e),
            nav_state(-90.0, -180.0 + 1e-13, -0.0, [0.0; 3], &e),
            nav_state(90.0, 180.0, 1e8, [-1e3, 1e-7, -5e-7], &e),
            nav_state(91.0, 20.0, 100.0, [1.0, 2.0, 3.0], &e),
            nav_state(45.0, 7.0, 1e300, [1.0, 2.0, 3.0], &e),
            nav_state(45.0, 7.0, f64::NAN, [1.0, 2.0, 3.0], &e),
            nav_state(f64::NAN, 7.0, 1.0, [1.0, 2.0, 3.0], &e),
            nav_state(45.0, 7.0, 1.0, [f64::INFINITY, 2.0, 3.0], &e),
        ];
        let mut written = 0;
        for s in &cases {
            let pushed = pushed_nav(s, &e);
            if let Some(put) = twin_text(|w| put_nav_fields(w, 0, s, &e)) {
                assert_eq!(put, pushed);
                written += 1;
            }
        }
        assert_eq!(written, 3);
        // NaN time: not the same state after normalizing, so `e` is not taken.
        let mut s = cases[0];
        s.t = f64::NAN;
        assert_eq!(twin_text(|w| put_nav_fields(w, 0, &s, &e)), None);
    }

    proptest! {
        /// Any state within the range: the Vec writer's bytes; past a pole: declined.
        #[test]
        fn nav_fields_agree_with_push(
            lat_deg in -95.0..95.0f64,
            lon_deg in -400.0..400.0f64,
            h in -1e4..1e7f64,
            v in prop::array::uniform3(-1e3..1e3f64),
            rpy in prop::array::uniform3(-7.0..7.0f64),
        ) {
            let e = Euler::new(rpy[0], rpy[1], rpy[2]);
            let s = nav_state(lat_deg, lon_deg, h, v, &e);
            let pushed = pushed_nav(&s, &e);
            match twin_text(|w| put_nav_fields(w, 0, &s, &e)) {
                Some(put) => prop_assert_eq!(put, pushed),
                None => prop_assert!(lat_deg.abs() > 90.0),
            }
        }

        /// IMU increments of any bits: the Vec writer's shortest line after the time.
        #[test]
        fn imu_increments_agree_with_push(bits in prop::array::uniform6(any::<u64>())) {
            let x = bits.map(f64::from_bits);
            let s = ImuSample {
                t: 0.25,
                dt: 0.005,
                dtheta: Vector3::new(x[0], x[1], x[2]),
                dvel: Vector3::new(x[3], x[4], x[5]),
            };
            let mut num = zmij::Buffer::new();
            let put = twin_text(|w| {
                let end = put_bytes(w, 0, b"0.25");
                Some(put_imu_increments(w, end, &s, &mut num))
            })
            .expect("always written");
            let pushed = [b' ', b','].map(|sep| {
                let mut v = Vec::new();
                push_imu_line(&mut v, &s, sep, ImuDigits::Shortest);
                String::from_utf8(v).expect("ascii")
            });
            prop_assert_eq!(put, pushed);
        }
    }

    /// The two IMU line forms: shortest round trip, and fixed significant digits
    /// (what `{:.9}` and `{:.12e}` print).
    #[test]
    fn imu_lines() {
        let s = ImuSample {
            t: 0.1 + 0.2,
            dt: 0.005,
            dtheta: Vector3::new(1e-5, -2.5e-4, 0.0),
            dvel: Vector3::new(0.049, -1.0 / 3.0, 1e-300),
        };
        let line = |sep, digits| {
            let mut out = Vec::new();
            push_imu_line(&mut out, &s, sep, digits);
            String::from_utf8(out).expect("ascii")
        };
        assert_eq!(
            line(b',', ImuDigits::Shortest),
            "0.30000000000000004,0.00001,-0.00025,0.0,0.049,-0.3333333333333333,1e-300"
        );
        assert_eq!(
            line(b' ', ImuDigits::Significant(13)),
            "0.300000000 1.000000000000e-5 -2.500000000000e-4 0.000000000000e0 \
             4.900000000000e-2 -3.333333333333e-1 1.000000000000e-300"
        );
    }

    #[test]
    fn longitude_wraps() {
        assert!((wrap_lon_deg(190f64.to_radians()) + 170.0).abs() < 1e-12);
        assert!((wrap_lon_deg(-190f64.to_radians()) - 170.0).abs() < 1e-12);
        assert_eq!(wrap_lon_deg(180f64.to_radians()), 180.0);
        assert_eq!(wrap_lon_deg(-180f64.to_radians()), 180.0);
    }

    /// Angles a hair inside the range print inside it: yaw just below 360 deg as 0,
    /// longitude just above -180 deg as 180 (seen on a polar flight: yaw
    /// 360 - 1e-13 deg printed as 360.000000000).
    #[test]
    fn printed_angles_stay_half_open() {
        let mut s = NavState::new(
            1.0,
            Geodetic::new(0.3, (-180.0f64 + 1e-13).to_radians(), 10.0),
            Vector3::zeros(),
            schuler::rotation::Euler::new(0.0, 0.0, -1e-15),
        );
        let row = Row::of(&s);
        assert_eq!(row.yaw_deg, 0.0);
        assert_eq!(row.lon_deg, 180.0);
        s.q_bn = schuler::rotation::Euler::from_degrees(0.0, 0.0, 359.9).to_quaternion();
        let row = Row::of(&s);
        assert!((row.yaw_deg - 359.9).abs() < 1e-9);
        let mut line = Vec::new();
        row.push(&mut line, b' ');
        let text = String::from_utf8(line).expect("ascii");
        let fields: Vec<&str> = text.split_whitespace().collect();
        assert_eq!(fields[1], "180.00000000000");
        assert_eq!(fields[8], "359.900000000");
    }

    /// The extended CSV: header, 14 columns, ECEF from the geodetic position for a
    /// NED state, azimuth 0; the classic writer keeps its 10 columns.
    #[test]
    fn extended_and_classic_csv() {
        let dir = tempfile::tempdir().expect("tempdir");
        let s = NavState::new(
            2.0,
            Geodetic::from_degrees(45.0, 7.0, 100.0),
            Vector3::new(1.0, 2.0, 3.0),
            schuler::rotation::Euler::from_degrees(1.0, 2.0, 3.0),
        );
        let mut w =
            NavWriter::create_extended(dir.path(), 7, &schuler::earth::Wgs84).expect("writer");
        w.write(&s).expect("write");
        assert_eq!(w.finish().expect("finish"), 1);
        let csv = std::fs::read_to_string(dir.path().join("nav.csv")).expect("csv");
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some(CSV_HEADER_EXTENDED));
        let f: Vec<f64> = lines
            .next()
            .expect("row")
            .split(',')
            .map(|x| x.parse().expect("number"))
            .collect();
        assert_eq!(f.len(), 14);
        let r = schuler::earth::Wgs84.geodetic_to_ecef(&s.pos);
        for (got, want) in f[10..13].iter().zip(r.iter()) {
            assert!((got - want).abs() <= 5e-7, "{got} {want}");
        }
        assert_eq!(f[13], 0.0);

        let classic = dir.path().join("classic");
        let mut w = NavWriter::create(&classic, 7).expect("writer");
        w.write(&s).expect("write");
        w.finish().expect("finish");
        let csv = std::fs::read_to_string(classic.join("nav.csv")).expect("csv");
        assert!(csv.starts_with(&format!("{CSV_HEADER}\n")));
        assert!(csv.lines().all(|l| l.split(',').count() == 10));
    }
}
