//! What an aided run keeps for its consistency report: every innovation the filter
//! tested, streamed to `OUT/innovations.csv` as it comes and kept in a compact form
//! for the report's plots.
//!
//! `innovations.csv`, one row per measurement, accepted or refused:
//! `t,kind,accepted,dof,nis,z_1,z_2,z_3,sigma_1,sigma_2,sigma_3` — time [s], the
//! measurement kind (`gnss_position`, `gnss_velocity`, `baro_height`), 1 if the gate let
//! it through, its dimension, the normalized innovation squared `zᵀ S⁻¹ z`, the
//! innovation `z` (computed minus measured, in the filter's computation frame: north,
//! east, down on the NED mechanization, the wander axes on the wander one; metres or
//! m/s) and `sqrt(S_ii)`, the standard deviation the filter predicted for each
//! component. Components past `dof` are empty.
//!
//! The report also takes the session's once-a-second [`ReportSample`]s: the estimated
//! sensor errors with their standard deviations and, against a truth, the normalized
//! estimation errors squared (NEES) of position, velocity and attitude.
//!
//! Both are kept as [`Spilled`] records (bounded memory, the rest on disk), so that
//! the report of a long run costs no more memory than a short one's.

use super::spilled::{Record, Spilled};
use anyhow::{Result, bail};
use nalgebra::Vector3;
use schuler::filter::integration::Innovation;
use schuler::filter::measurement::Kind;
use schuler_io::line_file::LineWriter;
use std::io::Write;
use std::path::Path;

/// Components `innovations.csv` holds per row (every measurement kind has at most 3).
pub const MAX_COMPONENTS: usize = 3;

/// Header of `innovations.csv`.
pub const INNOVATIONS_HEADER: &str = "t,kind,accepted,dof,nis,z_1,z_2,z_3,sigma_1,sigma_2,sigma_3";

/// One tested measurement, compactly: components past `dof` are zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InnovationRow {
    /// Time [s].
    pub t: f64,
    /// Measurement kind.
    pub kind: Kind,
    /// Let through by the gate.
    pub accepted: bool,
    /// Dimension.
    pub dof: usize,
    /// Normalized innovation squared.
    pub nis: f64,
    /// Innovation components.
    pub z: [f64; MAX_COMPONENTS],
    /// Predicted standard deviation of each component, `sqrt(S_ii)`.
    pub sigma: [f64; MAX_COMPONENTS],
}

impl InnovationRow {
    /// The compact row of a library record; an error if it has more components than
    /// the file holds.
    pub fn of(i: &Innovation) -> Result<Self> {
        let dof = i.z.len();
        if dof > MAX_COMPONENTS {
            bail!(
                "innovations.csv holds {MAX_COMPONENTS} components per row; a {} measurement has {dof}",
                i.kind
            );
        }
        let mut row = InnovationRow {
            t: i.t,
            kind: i.kind,
            accepted: i.accepted,
            dof,
            nis: i.nis,
            z: [0.0; MAX_COMPONENTS],
            sigma: [0.0; MAX_COMPONENTS],
        };
        for k in 0..dof {
            row.z[k] = i.z[k];
            row.sigma[k] = i.s_diag[k].max(0.0).sqrt();
        }
        Ok(row)
    }
}

/// The measurement kinds in the order of their code in a stored [`InnovationRow`].
const KINDS: [Kind; 10] = [
    Kind::GnssPosition,
    Kind::GnssVelocity,
    Kind::BaroHeight,
    Kind::ZeroVelocity,
    Kind::ZeroRate,
    Kind::NonHolonomic,
    Kind::Odometer,
    Kind::Heading,
    Kind::Pseudorange,
    Kind::RangeRate,
];

/// The code of `kind` in [`KINDS`].
fn kind_code(kind: Kind) -> usize {
    match kind {
        Kind::GnssPosition => 0,
        Kind::GnssVelocity => 1,
        Kind::BaroHeight => 2,
        Kind::ZeroVelocity => 3,
        Kind::ZeroRate => 4,
        Kind::NonHolonomic => 5,
        Kind::Odometer => 6,
        Kind::Heading => 7,
        Kind::Pseudorange => 8,
        Kind::RangeRate => 9,
    }
}

impl Record for InnovationRow {
    /// `t, kind code, accepted, dof, nis, z (3), sigma (3)`.
    const WIDTH: usize = 5 + 2 * MAX_COMPONENTS;

    fn encode(&self, out: &mut [f64]) {
        out[..5].copy_from_slice(&[
            self.t,
            kind_code(self.kind) as f64,
            f64::from(u8::from(self.accepted)),
            self.dof as f64,
            self.nis,
        ]);
        out[5..5 + MAX_COMPONENTS].copy_from_slice(&self.z);
        out[5 + MAX_COMPONENTS..].copy_from_slice(&self.sigma);
    }

    fn decode(r: &[f64]) -> Self {
        let mut row = InnovationRow {
            t: r[0],
            // The codes are written by `encode` from `KINDS`: always in range.
            kind: KINDS[(r[1] as usize).min(KINDS.len() - 1)],
            accepted: r[2] != 0.0,
            dof: r[3] as usize,
            nis: r[4],
            z: [0.0; MAX_COMPONENTS],
            sigma: [0.0; MAX_COMPONENTS],
        };
        row.z.copy_from_slice(&r[5..5 + MAX_COMPONENTS]);
        row.sigma.copy_from_slice(&r[5 + MAX_COMPONENTS..]);
        row
    }
}

/// Streams `innovations.csv` and keeps the rows for the report (spilled).
#[derive(Debug)]
pub struct InnovationLog {
    w: LineWriter,
    line: String,
    /// Every row written, in time order.
    pub rows: Spilled<InnovationRow>,
}

impl InnovationLog {
    /// Creates `dir/innovations.csv` with its header.
    pub fn create(dir: &Path) -> Result<Self> {
        let mut w = LineWriter::create(dir.join("innovations.csv"))?;
        writeln!(w, "{INNOVATIONS_HEADER}")?;
        Ok(Self {
            w,
            line: String::with_capacity(256),
            rows: Spilled::default(),
        })
    }

    /// Writes one tested measurement and keeps it for the report.
    pub fn push(&mut self, i: &Innovation) -> Result<()> {
        self.push_row(InnovationRow::of(i)?)
    }

    fn push_row(&mut self, r: InnovationRow) -> Result<()> {
        use std::fmt::Write as _;
        self.line.clear();
        let _ = write!(
            self.line,
            "{},{},{},{},{}",
            r.t,
            r.kind,
            u8::from(r.accepted),
            r.dof,
            r.nis
        );
        for values in [&r.z, &r.sigma] {
            for (k, v) in values.iter().enumerate() {
                if k < r.dof {
                    let _ = write!(self.line, ",{v}");
                } else {
                    self.line.push(',');
                }
            }
        }
        self.line.push('\n');
        self.w.write_all(self.line.as_bytes())?;
        self.rows.push(&r);
        Ok(())
    }

    /// Flushes the file; the rows stay for the report.
    pub fn finish(&mut self) -> Result<()> {
        // Every row ends on a newline: all of them go to the file.
        Ok(self.w.flush()?)
    }
}

/// The filter's view of the sensor errors and, against a truth, its NEES, at one
/// instant (the session's snapshot, taken once a second).
pub use schuler::session::Snapshot as ReportSample;

/// A value and whether it is there (`None` stored as flag 0 and value 0).
fn opt_in(x: Option<f64>) -> [f64; 2] {
    x.map_or([0.0, 0.0], |x| [1.0, x])
}

/// The option [`opt_in`] stored.
fn opt_out(r: &[f64]) -> Option<f64> {
    (r[0] != 0.0).then_some(r[1])
}

impl Record for ReportSample {
    /// `t`; the 21 sensor estimates (gyro and accelerometer biases and scale
    /// factors, barometer bias, odometer scale factor, mounting, lever-arm and time
    /// offset corrections); the 12 sensor standard deviations; the barometer bias's
    /// (flag, value); the lever arm's (flag, value ×3, std ×3, prior std, std from
    /// the motion ×3); the time offset's (flag, value, std, prior std, std from the
    /// motion); whether there is a NEES, then each NEES's (flag, value).
    const WIDTH: usize = 1 + 21 + 12 + 2 + 11 + 5 + 1 + 6;

    fn encode(&self, out: &mut [f64]) {
        let e = &self.estimates;
        let mut w = Cursor { out, at: 0 };
        w.put(&[self.t]);
        for v in [e.gyro_bias, e.accel_bias, e.gyro_scale, e.accel_scale] {
            w.put(v.as_slice());
        }
        w.put(&[e.baro_bias, e.odometer_scale]);
        w.put(e.mounting.as_slice());
        w.put(e.lever_arm.as_slice());
        w.put(&[e.gnss_time_offset]);
        for v in &self.sensor_std {
            w.put(v.as_slice());
        }
        w.put(&opt_in(self.baro_std));
        match &self.calibration.lever_arm {
            Some(l) => {
                w.put(&[1.0]);
                w.put(l.value.as_slice());
                w.put(l.std.as_slice());
                w.put(&[l.prior_std]);
                w.put(l.excited_std.as_slice());
            }
            None => w.put(&[0.0; 11]),
        }
        match &self.calibration.time_offset {
            Some(t) => w.put(&[1.0, t.value, t.std, t.prior_std, t.excited_std]),
            None => w.put(&[0.0; 5]),
        }
        w.put(&[f64::from(u8::from(self.nees.is_some()))]);
        for n in self.nees.unwrap_or([None; 3]) {
            w.put(&opt_in(n));
        }
        debug_assert_eq!(w.at, Self::WIDTH);
    }

    fn decode(r: &[f64]) -> Self {
        let v = |o: usize| Vector3::new(r[o], r[o + 1], r[o + 2]);
        let estimates = schuler::filter::SensorEstimates {
            gyro_bias: v(1),
            accel_bias: v(4),
            gyro_scale: v(7),
            accel_scale: v(10),
            baro_bias: r[13],
            odometer_scale: r[14],
            mounting: v(15),
            lever_arm: v(18),
            gnss_time_offset: r[21],
        };
        let calibration = schuler::filter::CalibrationState {
            lever_arm: (r[36] != 0.0).then(|| schuler::filter::Estimate {
                value: v(37),
                std: v(40),
                prior_std: r[43],
                excited_std: v(44),
            }),
            time_offset: (r[47] != 0.0).then(|| schuler::filter::Estimate {
                value: r[48],
                std: r[49],
                prior_std: r[50],
                excited_std: r[51],
            }),
        };
        ReportSample {
            t: r[0],
            estimates,
            sensor_std: [v(22), v(25), v(28), v(31)],
            baro_std: opt_out(&r[34..36]),
            calibration,
            nees: (r[52] != 0.0).then(|| std::array::from_fn(|k| opt_out(&r[53 + 2 * k..]))),
        }
    }
}

/// Writes values one after the other into a record.
struct Cursor<'a> {
    out: &'a mut [f64],
    at: usize,
}

impl Cursor<'_> {
    fn put(&mut self, v: &[f64]) {
        self.out[self.at..self.at + v.len()].copy_from_slice(v);
        self.at += v.len();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// A sample with every field distinct comes back bit for bit, with and without
    /// the optional parts.
    #[test]
    fn report_samples_round_trip() {
        use schuler::filter::{CalibrationState, Estimate, SensorEstimates};
        let mut k = 0.0;
        let mut next = || {
            k += 1.0;
            k * 0.37
        };
        let mut v3 = || Vector3::new(next(), next(), next());
        let estimates = SensorEstimates {
            gyro_bias: v3(),
            accel_bias: v3(),
            gyro_scale: v3(),
            accel_scale: v3(),
            mounting: v3(),
            lever_arm: v3(),
            baro_bias: 1.5,
            odometer_scale: -2.5,
            gnss_time_offset: 0.08,
        };
        let full = ReportSample {
            t: 12.0,
            estimates,
            sensor_std: [v3(), v3(), v3(), v3()],
            baro_std: Some(0.7),
            calibration: CalibrationState {
                lever_arm: Some(Estimate {
                    value: v3(),
                    std: v3(),
                    prior_std: 0.9,
                    excited_std: v3(),
                }),
                time_offset: Some(Estimate {
                    value: 1.3,
                    std: 0.01,
                    prior_std: 2.0,
                    excited_std: 0.5,
                }),
            },
            nees: Some([Some(1.0), None, Some(3.0)]),
        };
        let bare = ReportSample {
            baro_std: None,
            calibration: CalibrationState::default(),
            nees: None,
            ..full
        };
        for s in [full, bare] {
            let mut r = vec![f64::NAN; ReportSample::WIDTH];
            s.encode(&mut r);
            assert!(r.iter().all(|x| x.is_finite()), "every slot written");
            assert_eq!(ReportSample::decode(&r), s);
        }
    }

    #[test]
    fn rows_are_padded_and_too_many_components_is_an_error() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut log = InnovationLog::create(dir.path()).expect("create");
        let baro = Innovation {
            t: 12.5,
            kind: Kind::BaroHeight,
            sat: None,
            z: DVector::from_element(1, -0.25),
            s_diag: DVector::from_element(1, 0.0625),
            nis: 1.0,
            accepted: true,
        };
        log.push_row(InnovationRow::of(&baro).expect("1 component"))
            .expect("write");
        let pos = Innovation {
            t: 13.0,
            kind: Kind::GnssPosition,
            sat: None,
            z: DVector::from_column_slice(&[1.0, -2.0, 0.5]),
            s_diag: DVector::from_column_slice(&[4.0, 9.0, 0.25]),
            nis: 1.5,
            accepted: false,
        };
        log.push_row(InnovationRow::of(&pos).expect("3 components"))
            .expect("write");
        log.finish().expect("flush");
        let text = std::fs::read_to_string(dir.path().join("innovations.csv")).expect("read");
        assert_eq!(
            text,
            format!(
                "{INNOVATIONS_HEADER}\n12.5,baro_height,1,1,1,-0.25,,,0.25,,\n\
                 13,gnss_position,0,3,1.5,1,-2,0.5,2,3,0.5\n"
            )
        );
        let wide = Innovation {
            z: DVector::zeros(4),
            s_diag: DVector::zeros(4),
            ..pos
        };
        let e = InnovationRow::of(&wide)
            .expect_err("4 components")
            .to_string();
        assert!(e.contains("gnss_position measurement has 4"), "{e}");
    }
}
