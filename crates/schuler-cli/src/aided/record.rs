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

use crate::line_file::LineWriter;
use anyhow::{Result, bail};
use schuler::filter::integration::Innovation;
use schuler::filter::measurement::Kind;
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

/// Streams `innovations.csv` and keeps the rows for the report.
#[derive(Debug)]
pub struct InnovationLog {
    w: LineWriter,
    line: String,
    /// Every row written, in time order.
    pub rows: Vec<InnovationRow>,
}

impl InnovationLog {
    /// Creates `dir/innovations.csv` with its header.
    pub fn create(dir: &Path) -> Result<Self> {
        let mut w = LineWriter::create(dir.join("innovations.csv"))?;
        writeln!(w, "{INNOVATIONS_HEADER}")?;
        Ok(Self {
            w,
            line: String::with_capacity(256),
            rows: Vec::new(),
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
        self.rows.push(r);
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
        log.push_row(InnovationRow::of(&baro).expect("1 component"))
            .expect("write");
        let pos = Innovation {
            t: 13.0,
            kind: Kind::GnssPosition,
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
