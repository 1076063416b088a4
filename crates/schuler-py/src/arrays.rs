//! IMU samples and aids from numpy arrays, read in place (views, any strides: no copy),
//! each value checked as the file readers check it; errors name the array, the
//! 1-based row and the column.

use crate::columns::GNSS;
use nalgebra::Vector3;
use numpy::ndarray::ArrayView1;
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::imu::ImuSample;
use schuler_io::formats::InputError;
use schuler_io::formats::error::InputErrorKind;
use schuler_io::formats::vehicle::Rows;
use std::path::Path;

/// Name of the IMU arrays in errors.
const IMU_ARRAY: &str = "<imu array>";

/// IMU columns: time [s], optional interval [s], angle increments [rad] and velocity
/// increments [m/s] in FRD body axes.
pub struct ImuArrays<'a> {
    /// Interval ends [s].
    pub t: ArrayView1<'a, f64>,
    /// Interval lengths [s]; `None`: differences of `t` (the first sample's, the first
    /// difference).
    pub dt: Option<ArrayView1<'a, f64>>,
    /// `dtheta_x..z`, `dvel_x..z`.
    pub inc: [ArrayView1<'a, f64>; 6],
    /// Time of the sample before the first row [s], if one was pushed before.
    pub t_before: Option<f64>,
}

/// Column names of the increments, for errors.
const INC: [&str; 6] = [
    "dtheta_x_rad",
    "dtheta_y_rad",
    "dtheta_z_rad",
    "dvel_x_mps",
    "dvel_y_mps",
    "dvel_z_mps",
];

fn err(kind: InputErrorKind, what: &str, row: usize, field: &str, msg: String) -> InputError {
    InputError::new(kind, Path::new(what), row as u64 + 1, Some(field), msg)
}

fn finite(what: &str, row: usize, field: &str, x: f64) -> Result<f64, InputError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(err(
            InputErrorKind::NotFinite,
            what,
            row,
            field,
            format!("not finite: {x}"),
        ))
    }
}

impl ImuArrays<'_> {
    /// The columns' common length, or an error naming the first that differs.
    pub fn len(&self) -> Result<usize, InputError> {
        let n = self.t.len();
        let others = self.dt.iter().map(|d| ("dt_s", d.len()));
        let incs = INC.iter().zip(&self.inc).map(|(f, c)| (*f, c.len()));
        for (f, m) in others.chain(incs) {
            if m != n {
                let msg = format!("{m} values where the time column has {n}");
                return Err(err(InputErrorKind::ColumnCount, IMU_ARRAY, 0, f, msg));
            }
        }
        if n < 2 && self.dt.is_none() && self.t_before.is_none() {
            let msg = "at least two samples are needed to tell the interval".to_owned();
            return Err(err(InputErrorKind::NoData, IMU_ARRAY, 0, "t_s", msg));
        }
        Ok(n)
    }

    /// Sample `i`, checked: finite values, time strictly increasing, interval > 0.
    pub fn sample(&self, i: usize) -> Result<ImuSample, InputError> {
        let t = finite(IMU_ARRAY, i, "t_s", self.t[i])?;
        let before = if i > 0 {
            Some(self.t[i - 1])
        } else {
            self.t_before
        };
        if let Some(b) = before
            && t <= b
        {
            let msg = format!("time {t} does not increase (previous {b})");
            return Err(err(
                InputErrorKind::TimeNotIncreasing,
                IMU_ARRAY,
                i,
                "t_s",
                msg,
            ));
        }
        let dt = match (&self.dt, before) {
            (Some(d), _) => finite(IMU_ARRAY, i, "dt_s", d[i])?,
            (None, Some(b)) => t - b,
            (None, None) => self.t[1] - self.t[0],
        };
        if dt.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            let msg = format!("interval {dt} is not positive");
            return Err(err(InputErrorKind::Usage, IMU_ARRAY, i, "dt_s", msg));
        }
        let mut v = [0.0; 6];
        for (k, x) in v.iter_mut().enumerate() {
            *x = finite(IMU_ARRAY, i, INC[k], self.inc[k][i])?;
        }
        Ok(ImuSample {
            t,
            dt,
            dtheta: Vector3::new(v[0], v[1], v[2]),
            dvel: Vector3::new(v[3], v[4], v[5]),
        })
    }

    /// The samples in the window `[t_start, t_end]`, checked, in order (an error
    /// first if the columns' lengths differ).
    pub fn samples(
        &self,
        t_start: Option<f64>,
        t_end: Option<f64>,
    ) -> Result<impl Iterator<Item = Result<ImuSample, InputError>> + '_, InputError> {
        let n = self.len()?;
        let (from, to) = (
            t_start.unwrap_or(f64::NEG_INFINITY),
            t_end.unwrap_or(f64::INFINITY),
        );
        Ok((0..n)
            .map(move |i| self.sample(i))
            .filter(move |s| s.as_ref().map_or(true, |s| s.t >= from))
            .take_while(move |s| s.as_ref().map_or(true, |s| s.t <= to)))
    }
}

/// GNSS fixes from columns: time [s], latitude, longitude [deg], height [m], position
/// standard deviations north, east, down [m], and optionally velocity north, east, down
/// [m/s] with their standard deviations (a row with any of them NaN has none).
pub fn gnss_fixes(cols: &[ArrayView1<'_, f64>]) -> Result<Vec<GnssFix>, InputError> {
    const WHAT: &str = "<gnss array>";
    if !(cols.len() == 7 || cols.len() == 13) {
        let msg = format!("7 or 13 columns ({}), got {}", GNSS.join(", "), cols.len());
        return Err(err(InputErrorKind::ColumnCount, WHAT, 0, "columns", msg));
    }
    let n = cols[0].len();
    let mut fixes = Vec::with_capacity(n);
    for i in 0..n {
        let mut v = [f64::NAN; 13];
        for (k, c) in cols.iter().enumerate() {
            let x = *c.get(i).ok_or_else(|| {
                err(
                    InputErrorKind::ColumnCount,
                    WHAT,
                    i,
                    GNSS[k],
                    "column too short".into(),
                )
            })?;
            v[k] = if k < 7 {
                finite(WHAT, i, GNSS[k], x)?
            } else {
                x
            };
        }
        if i > 0 && v[0] <= cols[0][i - 1] {
            let msg = format!("time {} does not increase", v[0]);
            return Err(err(InputErrorKind::TimeNotIncreasing, WHAT, i, "t_s", msg));
        }
        let vel = v[7..].iter().all(|x| x.is_finite()).then(|| {
            (
                Vector3::new(v[7], v[8], v[9]),
                Vector3::new(v[10], v[11], v[12]),
            )
        });
        fixes.push(GnssFix {
            t: v[0],
            pos: Geodetic::from_degrees(v[1], v[2], v[3]),
            pos_std: Vector3::new(v[4], v[5], v[6]),
            vel,
        });
    }
    Ok(fixes)
}

/// Numbered rows of `cols` named `names` (as many columns as one of `counts`, of equal
/// lengths, every value finite, the first column's times increasing), row `i` as line
/// `i + 1`: the rows a log's file reader gives ([`schuler_io::formats::vehicle::Rows`]).
pub fn rows(
    what: &str,
    names: &[&str],
    counts: &[usize],
    cols: &[ArrayView1<'_, f64>],
) -> Result<Rows, InputError> {
    if !counts.contains(&cols.len()) {
        let counts: Vec<String> = counts.iter().map(usize::to_string).collect();
        let msg = format!(
            "{} columns ({}), got {}",
            counts.join(" or "),
            names.join(", "),
            cols.len()
        );
        return Err(err(InputErrorKind::ColumnCount, what, 0, "columns", msg));
    }
    let n = cols.first().map_or(0, |c| c.len());
    for (name, c) in names.iter().zip(cols) {
        if c.len() != n {
            let msg = format!("{} values where the first column has {n}", c.len());
            return Err(err(InputErrorKind::ColumnCount, what, 0, name, msg));
        }
    }
    let mut out: Rows = Vec::with_capacity(n);
    for i in 0..n {
        let v = (0..cols.len())
            .map(|k| finite(what, i, names[k], cols[k][i]))
            .collect::<Result<Vec<f64>, _>>()?;
        if let Some((_, prev)) = out.last()
            && v[0] <= prev[0]
        {
            let msg = format!("time {} does not increase (previous {})", v[0], prev[0]);
            return Err(err(
                InputErrorKind::TimeNotIncreasing,
                what,
                i,
                names[0],
                msg,
            ));
        }
        out.push((i as u64 + 1, v));
    }
    Ok(out)
}

/// Barometer readings `(t, h)` from columns time [s] and height [m].
pub fn baro_readings(
    t: ArrayView1<'_, f64>,
    h: ArrayView1<'_, f64>,
) -> Result<Vec<(f64, f64)>, InputError> {
    const WHAT: &str = "<baro array>";
    if t.len() != h.len() {
        let msg = format!("{} heights for {} times", h.len(), t.len());
        return Err(err(InputErrorKind::ColumnCount, WHAT, 0, "h_m", msg));
    }
    (0..t.len())
        .map(|i| Ok((finite(WHAT, i, "t_s", t[i])?, finite(WHAT, i, "h_m", h[i])?)))
        .collect()
}
