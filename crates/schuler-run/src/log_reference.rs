//! The device's own solution beside schuler's (`nav --log` on a log with a
//! `Reference` stream: PX4's EKF2, ArduPilot's EKF3, a u-blox receiver's fusion, the
//! phone's orientation): `reference.csv`, one row per reference sample inside our
//! run, of schuler's solution minus the device's, and their RMS.
//!
//! Our result (`nav.txt`) is interpolated at each reference time
//! ([`schuler::analysis::errors::TruthCursor`], linear, angles the short way) and
//! the differences are [`errors_at`]'s: position along the device's north, east and
//! down [m], velocity in its NED frame [m/s], roll, pitch and yaw [deg]. A reference
//! sample gives only the parts it holds (PX4 logs attitude and position in separate
//! topics): the others are empty cells and left out of their RMS. The devices'
//! heights are not all above the ellipsoid (PX4's `alt` and ArduPilot's origin are
//! above mean sea level): the down difference then holds the geoid's height.

use crate::log_input::LogPlan;
use anyhow::{Context, Result};
use schuler::analysis::errors::{NavRecord, TruthAt, TruthCursor, errors_at};
use schuler_io::formats::nav::read_nav;
use schuler_io::line_file::LineWriter;
use schuler_io::logs::{LogRecord, open_reader};
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// The header of `reference.csv`.
pub const HEADER: &str =
    "t,d_north_m,d_east_m,d_down_m,d_vn_mps,d_ve_mps,d_vd_mps,d_roll_deg,d_pitch_deg,d_yaw_deg";

/// The RMS of the differences over the samples holding each part.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReferenceComparison {
    /// The reference stream.
    pub stream: String,
    /// The file written.
    pub file: PathBuf,
    /// Reference samples compared (inside our run's span).
    pub compared: u64,
    /// Samples with a position, and the RMS of north, east, down differences [m].
    pub position: (u64, [f64; 3]),
    /// Samples with a velocity, RMS of north, east, down differences [m/s].
    pub velocity: (u64, [f64; 3]),
    /// Samples with an attitude, RMS of roll, pitch, yaw differences [deg].
    pub attitude: (u64, [f64; 3]),
}

/// Running sums of squares.
#[derive(Default)]
struct Rms {
    n: u64,
    ss: [f64; 3],
}

impl Rms {
    fn add(&mut self, d: [f64; 3]) {
        self.n += 1;
        for (s, x) in self.ss.iter_mut().zip(d) {
            *s += x * x;
        }
    }
    fn get(&self) -> (u64, [f64; 3]) {
        let n = self.n.max(1) as f64;
        (self.n, self.ss.map(|s| (s / n).sqrt()))
    }
}

/// Compares the log's reference stream with `out/nav.txt`, writing
/// `out/reference.csv`; `None` when the log has no reference stream.
pub fn compare_reference(log: &LogPlan, out: &Path) -> Result<Option<ReferenceComparison>> {
    let Some((stream, name)) = &log.reference else {
        return Ok(None);
    };
    let nav_file = out.join("nav.txt");
    let (_, ours) = read_nav(&nav_file)?;
    let mut reader = open_reader(&log.path, log.format)?
        .with_context(|| format!("{}: a ROS bag", log.path.display()))?;
    let file = out.join("reference.csv");
    let mut w = LineWriter::create(&file)?;
    writeln!(w, "{HEADER}")?;
    let (mut pos, mut vel, mut att) = (Rms::default(), Rms::default(), Rms::default());
    let mut cursor = TruthCursor::default();
    let mut compared = 0;
    let mut last_t = f64::NEG_INFINITY;
    for item in reader.by_ref() {
        let item = item?;
        let LogRecord::Reference(r) = item.record else {
            continue;
        };
        if item.stream != *stream || r.t < last_t {
            continue;
        }
        last_t = r.t;
        let at = match cursor.at(&ours, r.t) {
            TruthAt::Before => continue,
            TruthAt::After => break,
            TruthAt::Exact(x) | TruthAt::Interpolated(x, _) => x,
        };
        // The parts the device does not give are ours: no difference there.
        let device = NavRecord {
            t_sow: r.t,
            pos: r.pos.unwrap_or(at.pos),
            v_n: r.v_n.unwrap_or(at.v_n),
            att: r.att.unwrap_or(at.att),
        };
        let e = errors_at(&at, &device);
        compared += 1;
        let cells = |on: bool, v: [f64; 3]| -> String {
            if on {
                format!("{},{},{}", v[0], v[1], v[2])
            } else {
                ",,".to_owned()
            }
        };
        let dp = [e.pos_n.x, e.pos_n.y, e.pos_n.z];
        let dv = [e.v_n.x, e.v_n.y, e.v_n.z];
        let da = [e.att.roll, e.att.pitch, e.att.yaw].map(f64::to_degrees);
        if r.pos.is_some() {
            pos.add(dp);
        }
        if r.v_n.is_some() {
            vel.add(dv);
        }
        if r.att.is_some() {
            att.add(da);
        }
        writeln!(
            w,
            "{},{},{},{}",
            r.t,
            cells(r.pos.is_some(), dp),
            cells(r.v_n.is_some(), dv),
            cells(r.att.is_some(), da)
        )?;
    }
    w.finish()?;
    Ok(Some(ReferenceComparison {
        stream: name.clone(),
        file,
        compared,
        position: pos.get(),
        velocity: vel.get(),
        attitude: att.get(),
    }))
}
