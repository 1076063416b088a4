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
//! Once a second of the log's clock (the first epoch at or after each whole second)
//! it also keeps a [`ReportSample`]: the estimated sensor errors with their standard
//! deviations and, against a truth, the normalized estimation errors squared (NEES)
//! of position, velocity and attitude from the filter's covariance at that instant.

use super::nav::Decimator;
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use schuler::analysis::consistency::normalized_squared;
use schuler::analysis::errors::{NavRecord, TruthAt, TruthCursor, errors_between};
use schuler::earth::{EarthModel, Wgs84};
use schuler::filter::integration::Innovation;
use schuler::filter::measurement::Kind;
use schuler::filter::{Integrator, Layout, SensorEstimates};
use schuler::nav::ErrorFrame;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

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

/// Streams `innovations.csv` and keeps the rows for the report.
#[derive(Debug)]
pub struct InnovationLog {
    w: BufWriter<File>,
    path: PathBuf,
    line: String,
    /// Every row written, in time order.
    pub rows: Vec<InnovationRow>,
}

impl InnovationLog {
    /// Creates `dir/innovations.csv` with its header.
    pub fn create(dir: &Path) -> Result<Self> {
        let path = dir.join("innovations.csv");
        let f = File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
        let mut w = BufWriter::with_capacity(1 << 16, f);
        writeln!(w, "{INNOVATIONS_HEADER}")
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(Self {
            w,
            path,
            line: String::with_capacity(256),
            rows: Vec::new(),
        })
    }

    /// Takes the innovations the integrator recorded since the last call and writes
    /// them (the integrator's record stays short whatever the run's length).
    pub fn drain<M: ErrorFrame, E: EarthModel>(
        &mut self,
        integ: &mut Integrator<M, E>,
    ) -> Result<()> {
        if integ.innovations.is_empty() {
            return Ok(());
        }
        for i in std::mem::take(&mut integ.innovations) {
            self.push(InnovationRow::of(&i)?)?;
        }
        Ok(())
    }

    fn push(&mut self, r: InnovationRow) -> Result<()> {
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
        self.w
            .write_all(self.line.as_bytes())
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        self.rows.push(r);
        Ok(())
    }

    /// Flushes the file; the rows stay for the report.
    pub fn finish(&mut self) -> Result<()> {
        self.w
            .flush()
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

/// The filter's view of the sensor errors and, against a truth, its NEES, at one
/// instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReportSample {
    /// Time [s].
    pub t: f64,
    /// Estimated sensor errors.
    pub estimates: SensorEstimates,
    /// Standard deviations of gyro bias [rad/s], accelerometer bias [m/s^2], gyro and
    /// accelerometer scale factors (zero where not estimated).
    pub sensor_std: [Vector3<f64>; 4],
    /// Standard deviation of the barometer bias [m], when estimated.
    pub baro_std: Option<f64>,
    /// NEES of position, velocity and attitude (3 dof each): `None` without a truth
    /// at this time; an entry `None` where the covariance block is not positive
    /// definite.
    pub nees: Option<[Option<f64>; 3]>,
}

/// Takes a [`ReportSample`] once a second and keeps the innovation log.
pub struct RunRecorder<'a> {
    /// Every tested measurement.
    pub innovations: InnovationLog,
    /// The samples, in time order.
    pub samples: Vec<ReportSample>,
    truth: &'a [NavRecord],
    cursor: TruthCursor,
    cadence: Decimator,
}

impl<'a> RunRecorder<'a> {
    /// Starts recording into `dir`; with a `truth` (sorted by time; empty: none) the
    /// samples carry NEES.
    pub fn create(dir: &Path, truth: &'a [NavRecord]) -> Result<Self> {
        Ok(Self {
            innovations: InnovationLog::create(dir)?,
            samples: Vec::new(),
            truth,
            cursor: TruthCursor::default(),
            cadence: Decimator::new(Some(1.0)),
        })
    }

    /// After a sample ending at `t` with interval `dt`: log the new innovations and,
    /// at the first epoch of each second, take a sample.
    pub fn after_sample<M: ErrorFrame, E: EarthModel>(
        &mut self,
        integ: &mut Integrator<M, E>,
        t: f64,
        dt: f64,
    ) -> Result<()> {
        self.innovations.drain(integ)?;
        if self.cadence.take(t, dt) {
            self.sample(integ);
        }
        Ok(())
    }

    /// Takes a sample now.
    pub fn sample<M: ErrorFrame, E: EarthModel>(&mut self, integ: &Integrator<M, E>) {
        let p = integ.covariance();
        let l = integ.layout();
        let std3 =
            |o: Option<usize>| o.map_or(Vector3::zeros(), |o| schuler::filter::kalman::std3(p, o));
        let state = integ.state();
        let nees = if self.truth.is_empty() {
            None
        } else {
            match self.cursor.at(self.truth, state.t) {
                TruthAt::Exact(truth) | TruthAt::Interpolated(truth, _) => {
                    let e = errors_between(&Wgs84, &state, &(&truth).into());
                    let [pp, pv, pa] = integ.nav_covariance();
                    Some([
                        normalized_squared(&e.pos_n, &pp),
                        normalized_squared(&e.v_n, &pv),
                        normalized_squared(&e.psi, &pa),
                    ])
                }
                TruthAt::Before | TruthAt::After => None,
            }
        };
        self.samples.push(ReportSample {
            t: state.t,
            estimates: integ.estimates(),
            sensor_std: [
                std3(Some(Layout::GYRO_BIAS)),
                std3(Some(Layout::ACCEL_BIAS)),
                std3(l.gyro_scale),
                std3(l.accel_scale),
            ],
            baro_std: l.baro_bias.map(|b| p[(b, b)].max(0.0).sqrt()),
            nees,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    #[test]
    fn rows_are_padded_and_too_many_components_is_an_error() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut log = InnovationLog::create(dir.path()).expect("create");
        let baro = Innovation {
            t: 12.5,
            kind: Kind::BaroHeight,
            z: DVector::from_element(1, -0.25),
            s_diag: DVector::from_element(1, 0.0625),
            nis: 1.0,
            accepted: true,
        };
        log.push(InnovationRow::of(&baro).expect("1 component"))
            .expect("write");
        let pos = Innovation {
            t: 13.0,
            kind: Kind::GnssPosition,
            z: DVector::from_column_slice(&[1.0, -2.0, 0.5]),
            s_diag: DVector::from_column_slice(&[4.0, 9.0, 0.25]),
            nis: 1.5,
            accepted: false,
        };
        log.push(InnovationRow::of(&pos).expect("3 components"))
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
