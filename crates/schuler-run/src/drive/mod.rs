//! Drives a library [`Session`] from a file's samples and streams what comes out to
//! the output files: `nav.txt`/`nav.csv` for every run; with the filter `std.txt` and
//! `imu_err.txt` (KF-GINS's column layouts) at the output epochs, `innovations.csv` as
//! the measurements come, and `rejected.csv` at the end (every measurement the gate
//! refused, that fell outside the IMU data, came too late or had no use, with time and
//! reason). On a read error everything computed so far is written before the error is
//! returned.

pub mod writer_thread;

use crate::aided::feed::AidFeed;
use crate::aided::record::InnovationLog;
use crate::aided::spilled::Spilled;
use anyhow::Result;
use nalgebra::Vector3;
use schuler::earth::EarthModel;
use schuler::filter::SensorEstimates;
use schuler::filter::integration::SkipReason;
use schuler::filter::smoother::SmoothedTrajectory;
use schuler::imu::ImuSample;
use schuler::session::{Epoch, Event, FilterEpoch, Finished, Session, Snapshot};
use schuler::units::{DEG_PER_H, MGAL, PPM};
use schuler_io::bag::output::ResultBag;
use schuler_io::fixed::{Words, put_bytes, put_field};
use schuler_io::line_file::{LineFile, write_whole};
use schuler_io::output::{NavEpoch, NavWriter, push_fixed};
use schuler_io::text_block::{TextBlock, put_first_field};
use std::path::Path;
use writer_thread::WriterThread;

/// Text writer for `std.txt` and `imu_err.txt`, through the fast row writer
/// ([`TextBlock`]).
pub struct Table {
    file: LineFile,
    text: TextBlock,
    line: Vec<u8>,
    last: LastRow,
}

/// The last row written through the window: its values, and its text after the time
/// (each field with its separator first, then the newline) with where each field
/// starts. A row's last fields that equal the last row's (the same bits, so the same
/// text) are copied from it rather than formatted again: the filter's estimates and
/// sensor standard deviations change only at its updates and propagations, while
/// KF-GINS's files have a row at every sample.
#[derive(Default)]
struct LastRow {
    values: Vec<f64>,
    text: Vec<u8>,
    starts: Vec<usize>,
}

impl LastRow {
    /// How many of the last values of `values` are those of the last row, bit for bit.
    fn same_tail(&self, values: &[f64]) -> usize {
        if values.len() != self.values.len() {
            return 0;
        }
        values
            .iter()
            .rev()
            .zip(self.values.iter().rev())
            .take_while(|(a, b)| a.to_bits() == b.to_bits())
            .count()
    }

    /// Forgets the last row (its line was made by the `Vec` writers).
    fn clear(&mut self) {
        self.values.clear();
    }
}

/// A table line's window: the time and up to [`TABLE_FAST_VALUES`] values of at most
/// 17 bytes with their separators, and the newline, fit in 512 bytes.
const TABLE_WINDOW: usize = 512 + 8;
/// Most values a line through the window holds.
const TABLE_FAST_VALUES: usize = 26;
/// Text gathered before it goes to the file [bytes].
const TABLE_BLOCK: usize = 1 << 16;

impl Table {
    /// Creates `dir/name`.
    pub fn create(dir: &Path, name: &str) -> Result<Self> {
        Ok(Self {
            file: LineFile::create(dir.join(name))?,
            text: TextBlock::default(),
            line: Vec::with_capacity(512),
            last: LastRow::default(),
        })
    }

    /// One row: time, then the values (the bytes of [`push_table_row`]).
    pub fn row(&mut self, t: f64, values: &[f64]) -> Result<()> {
        let same = self.last.same_tail(values);
        let fresh = values.len() - same;
        let before = self.text.len();
        let last = &self.last;
        // Where the time ends, and where each field starts after it.
        let mut time_end = 0;
        let mut starts = [0usize; TABLE_FAST_VALUES];
        let stored = values.len() <= TABLE_FAST_VALUES
            && self.text.put_line::<TABLE_WINDOW>(b' ', |w| {
                let mut pos = put_first_field(w, 0, t, 6)?;
                time_end = pos;
                for (start, v) in starts.iter_mut().zip(&values[..fresh]) {
                    *start = pos - time_end;
                    pos = put_field(w, pos, *v, 9)?;
                }
                if same == 0 {
                    w.put(pos, u64::from(b'\n'));
                    return Some(pos + 1);
                }
                // The last row's fields from the first unchanged one, and its newline.
                let (at, from) = (pos - time_end, last.starts[fresh]);
                for (start, old) in starts[fresh..values.len()]
                    .iter_mut()
                    .zip(&last.starts[fresh..])
                {
                    *start = at + old - from;
                }
                Some(put_bytes(w, pos, &last.text[from..]))
            });
        if !stored {
            self.last.clear();
            self.line.clear();
            push_table_row(&mut self.line, t, values);
            self.text.extend(&self.line);
        } else if fresh > 0 {
            let last = &mut self.last;
            last.values.clear();
            last.values.extend_from_slice(values);
            last.starts.clear();
            last.starts.extend_from_slice(&starts[..values.len()]);
            last.text.clear();
            last.text
                .extend_from_slice(&self.text.as_bytes()[before + time_end..]);
        }
        if self.text.len() >= TABLE_BLOCK {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the gathered text to the file.
    fn flush(&mut self) -> Result<()> {
        self.file.append(self.text.as_bytes())?;
        self.text.clear();
        Ok(())
    }

    /// Writes what is left to the file.
    pub fn finish(mut self) -> Result<()> {
        self.flush()
    }
}

/// A line of `std.txt` or `imu_err.txt`: time to 1 µs, then the values to 9 decimals,
/// space-separated.
pub fn push_table_row(line: &mut Vec<u8>, t: f64, values: &[f64]) {
    push_fixed(line, t, 6);
    for v in values {
        line.push(b' ');
        push_fixed(line, *v, 9);
    }
    line.push(b'\n');
}

/// The sensor columns of KF-GINS's IMU_ERR and STD files: gyro bias [deg/h],
/// accelerometer bias [mGal], gyro and accelerometer scale factors [ppm].
fn sensor_columns([gb, ab, gs, as_]: [Vector3<f64>; 4]) -> [f64; 12] {
    [
        gb.x / DEG_PER_H,
        gb.y / DEG_PER_H,
        gb.z / DEG_PER_H,
        ab.x / MGAL,
        ab.y / MGAL,
        ab.z / MGAL,
        gs.x / PPM,
        gs.y / PPM,
        gs.z / PPM,
        as_.x / PPM,
        as_.y / PPM,
        as_.z / PPM,
    ]
}

/// The KF-GINS IMU_ERR columns after time ([`sensor_columns`]).
pub fn imu_err_row(e: &SensorEstimates) -> [f64; 12] {
    sensor_columns([e.gyro_bias, e.accel_bias, e.gyro_scale, e.accel_scale])
}

/// The KF-GINS STD columns after time: position [m] and velocity [m/s] north, east,
/// down, attitude roll, pitch, yaw [deg], then the [`sensor_columns`].
pub fn std_row(f: &FilterEpoch) -> [f64; 21] {
    let [sp, sv, sa] = f.nav_std;
    let mut row = [0.0; 21];
    row[..9].copy_from_slice(&[
        sp.x,
        sp.y,
        sp.z,
        sv.x,
        sv.y,
        sv.z,
        sa.x.to_degrees(),
        sa.y.to_degrees(),
        sa.z.to_degrees(),
    ]);
    row[9..].copy_from_slice(&sensor_columns(f.sensor_std));
    row
}

/// A measurement the filter did not use, as `rejected.csv` lists it.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// Time [s].
    pub t: f64,
    /// The measurement kind (`gnss_position`, ...).
    pub measurement: String,
    /// Why it was not used, or how it was used after all (a gate reset).
    pub reason: String,
    /// Its normalized innovation squared, when tested.
    pub nis: Option<f64>,
    /// The gate's threshold, when refused by it.
    pub threshold: Option<f64>,
}

impl Refusal {
    /// The refusal an event reports, if it is one (refused by the gate, outside the
    /// IMU data, accepted by a gate reset, late, ignored).
    pub fn of(e: &Event) -> Option<Self> {
        let r = |t: f64, m: &dyn std::fmt::Display, reason: String, nis, threshold| Self {
            t,
            measurement: m.to_string(),
            reason,
            nis,
            threshold,
        };
        Some(match e {
            Event::Refused(x) => r(
                x.t,
                // A range names its satellite: `pseudorange G05`.
                &match x.sat {
                    Some(sat) => format!("{} {sat}", x.kind),
                    None => x.kind.to_string(),
                },
                "chi-square gate".into(),
                Some(x.rejection.nis),
                Some(x.rejection.threshold),
            ),
            Event::Skipped(k) => {
                let why = match k.reason {
                    SkipReason::BeforeImu => "before the IMU data",
                    SkipReason::AfterImu => "after the IMU data",
                    SkipReason::NotModelled => "not modelled by this error model",
                };
                r(k.t, &k.kind, why.into(), None, None)
            }
            Event::GateReset { t, nis } => r(
                *t,
                &"gnss_position",
                "accepted without the gate after consecutive refusals (filter reset)".into(),
                Some(*nis),
                None,
            ),
            Event::Late {
                t,
                kind,
                integrated_to,
            } => r(
                *t,
                kind,
                format!("arrived after its sample was integrated (at {integrated_to})"),
                None,
                None,
            ),
            Event::Ignored { t, kind, reason } => r(*t, kind, (*reason).into(), None, None),
            Event::Measurement(_) | Event::Handover(_) | Event::Envelope { .. } => return None,
        })
    }

    /// Its line of `rejected.csv`: `t,measurement,reason,nis,threshold` (empty fields
    /// for what it lacks; a pseudorange or rate names its satellite in `measurement`).
    pub fn csv_line(&self) -> String {
        let opt = |x: Option<f64>| x.map(|x| x.to_string()).unwrap_or_default();
        format!(
            "{},{},{},{},{}\n",
            self.t,
            self.measurement,
            self.reason,
            opt(self.nis),
            opt(self.threshold)
        )
    }
}

/// The filter's output files.
pub struct FilterFiles {
    std: Table,
    err: Table,
    /// Every tested measurement (`innovations.csv`), kept for the report; `None`
    /// without the diagnostics.
    pub innovations: Option<InnovationLog>,
    /// `rejected.csv`'s rows with their times, in event order.
    refused: Vec<(f64, String)>,
}

impl FilterFiles {
    /// Creates `std_name`, `err_name` and, with the diagnostics, `innovations.csv`
    /// in `dir`.
    pub fn create(dir: &Path, std_name: &str, err_name: &str, diagnostics: bool) -> Result<Self> {
        Ok(Self {
            std: Table::create(dir, std_name)?,
            err: Table::create(dir, err_name)?,
            innovations: diagnostics
                .then(|| InnovationLog::create(dir))
                .transpose()?,
            refused: Vec::new(),
        })
    }

    /// Flushes the tables and, with the diagnostics, writes `dir/rejected.csv` (rows
    /// sorted by time); returns the innovations (with the diagnostics).
    pub fn finish(mut self, dir: &Path) -> Result<Option<InnovationLog>> {
        self.std.finish()?;
        self.err.finish()?;
        let Some(mut innovations) = self.innovations else {
            return Ok(None);
        };
        innovations.finish()?;
        let mut s = String::from("t,measurement,reason,nis,threshold\n");
        self.refused.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, r) in &self.refused {
            s.push_str(r);
        }
        write_whole(&dir.join("rejected.csv"), s)?;
        Ok(Some(innovations))
    }
}

/// Where a run's output goes.
pub struct Outputs {
    /// The navigation result.
    pub nav: NavWriter,
    /// The filter's files, when a filter runs.
    pub filter: Option<FilterFiles>,
    /// The result bag (`--out-bag`).
    pub bag: Option<ResultBag>,
    last_written: f64,
    /// The first epoch whose heading standard deviation fell below 1°: its time and
    /// heading [rad].
    heading_settled: Option<(f64, f64)>,
    /// Whether the next epoch (the start) is left out, as KF-GINS does.
    skip_start: bool,
}

impl Outputs {
    /// Writes `nav` and, with a filter, `filter`.
    pub fn new(nav: NavWriter, filter: Option<FilterFiles>) -> Self {
        Self {
            nav,
            filter,
            bag: None,
            last_written: f64::NAN,
            heading_settled: None,
            skip_start: false,
        }
    }

    /// The same outputs from the epoch after the start (KF-GINS's first row is the
    /// state one sample after its start).
    pub fn without_start_epoch(self) -> Self {
        Self {
            skip_start: true,
            ..self
        }
    }

    /// Writes one output epoch.
    pub fn write_epoch(&mut self, e: &Epoch) -> Result<()> {
        if std::mem::take(&mut self.skip_start) {
            return Ok(());
        }
        self.nav.write_epoch(&NavEpoch {
            state: e.state,
            r_e: e.r_e,
            wander_azimuth: e.wander_azimuth,
        })?;
        self.last_written = e.state.t;
        if let Some(bag) = self.bag.as_mut() {
            bag.write_epoch(e)?;
        }
        if let Some(f) = &e.filter
            && self.heading_settled.is_none()
            && f.nav_std[2].z < 1f64.to_radians()
        {
            self.heading_settled = Some((e.state.t, e.state.euler().heading_0_2pi()));
        }
        if let (Some(files), Some(f)) = (self.filter.as_mut(), &e.filter) {
            files.std.row(e.state.t, &std_row(f))?;
            files.err.row(e.state.t, &imu_err_row(&f.estimates))?;
        }
        Ok(())
    }

    /// Writes the state where a failed input stopped the run, unless it was the last
    /// epoch written or is not finite.
    pub fn write_last(&mut self, e: &Epoch) -> Result<()> {
        if e.state.t != self.last_written
            && e.state.pos.lat.is_finite()
            && e.state.v_n.iter().all(|x| x.is_finite())
        {
            self.write_epoch(e)?;
        }
        Ok(())
    }

    /// Writes one event (an envelope warning to stderr, the filter's records to
    /// `innovations.csv` and `rejected.csv`).
    pub fn event(&mut self, e: Event) -> Result<()> {
        if let Event::Envelope { t, what } = &e {
            eprintln!(
                "warning: at t = {t} s the solution left the physical envelope: {what} \
                 (a wrong input: axes, units, columns, clock? or a diverged free-inertial run)"
            );
            return Ok(());
        }
        let Some(files) = self.filter.as_mut() else {
            return Ok(());
        };
        if let Event::Measurement(i) = &e {
            return files.innovations.as_mut().map_or(Ok(()), |log| log.push(i));
        }
        let Some(r) = Refusal::of(&e) else {
            return Ok(());
        };
        let row = (r.t, r.csv_line());
        files.refused.push(row);
        Ok(())
    }

    /// Writes the session's epochs and events so far.
    pub fn take<E: EarthModel>(&mut self, session: &mut Session<E>) -> Result<()> {
        for e in session.epochs() {
            self.write_epoch(&e)?;
        }
        for e in session.events() {
            self.event(e)?;
        }
        Ok(())
    }
}

/// The IMU samples a run reads, their read errors already [`anyhow::Error`]s (as
/// `anyhow::Error::new` of the reader's own error: the messages and the error chain
/// are the reader's). A trait object, so that the run's code is compiled once in this
/// crate rather than once per reader type in every crate that starts a run.
pub type Samples<'a> = dyn Iterator<Item = Result<ImuSample>> + 'a;

/// `reader`'s samples as [`Samples`]: each read error as `anyhow::Error::new(e)`.
pub fn samples_of<I, E>(reader: I) -> impl Iterator<Item = Result<ImuSample>>
where
    I: Iterator<Item = Result<ImuSample, E>>,
    E: std::error::Error + Send + Sync + 'static,
{
    reader.map(|s| s.map_err(anyhow::Error::new))
}

/// What a driven run leaves: the session's end and, if the input failed, the error
/// (everything before it was written).
pub struct Driven {
    /// The session's end.
    pub finished: Finished,
    /// The read error that stopped the run, with what was written.
    pub failure: Option<anyhow::Error>,
    /// Epochs written.
    pub epochs: u64,
    /// The filter's files, still open (for `rejected.csv` and the report).
    pub filter: Option<FilterFiles>,
    /// The first output epoch whose heading standard deviation was below 1°: its time
    /// [s] and heading [rad].
    pub heading_settled: Option<(f64, f64)>,
    /// The filter's snapshots, taken from the session as the run goes (bounded memory).
    pub snapshots: Spilled<Snapshot>,
}

/// Closes the trajectory files and the result bag; the number of epochs written.
fn close_trajectory(nav: NavWriter, bag: Option<ResultBag>) -> Result<u64> {
    let epochs = nav.finish()?;
    if let Some(bag) = bag {
        bag.finish()?;
    }
    Ok(epochs)
}

/// The writer thread's own error, after a hand-over to it failed.
fn writer_error(pipe: WriterThread) -> anyhow::Error {
    match pipe.join() {
        Err(e) => e,
        Ok(_) => anyhow::anyhow!("the writer thread stopped"),
    }
}

/// The loop of [`drive`]: each sample pushed after the aids due before it, what comes
/// out handed to the writer thread, the snapshots kept every 65,536 samples. Stops at
/// the end of the input, at a sample that fails or at a signal; returns the count
/// pushed and what stopped it, `None` when the writer thread stopped.
fn push_samples<M: EarthModel>(
    (session, feed, pipe, snapshots): Pushing<'_, '_, M>,
    samples: &mut Samples<'_>,
    on_sample: &mut dyn FnMut(u64),
) -> Option<(u64, Option<anyhow::Error>)> {
    let mut n = 0u64;
    for s in samples {
        // A signal stops the run here, as a read error does: everything before is
        // written, every file ends on a whole line.
        if let Some(i) = crate::interrupt::requested() {
            return Some((n, Some(i.into())));
        }
        let pushed = s.and_then(|s| {
            feed.before(session, &s)?;
            session.push_imu(s).map_err(anyhow::Error::new)
        });
        if let Err(e) = pushed {
            return Some((n, Some(e)));
        }
        pipe.take(session).ok()?;
        n += 1;
        if n.is_multiple_of(65_536) {
            on_sample(n);
            session.snapshots().for_each(|x| snapshots.push(&x));
        }
    }
    Some((n, None))
}

/// What [`push_samples`] pushes through: the session, the aids, the writer thread and
/// the snapshots kept.
type Pushing<'a, 'f, M> = (
    &'a mut Session<M>,
    &'a mut AidFeed<'f>,
    &'a mut WriterThread,
    &'a mut Spilled<Snapshot>,
);

/// Pushes `samples` into `session`, each after the aids `feed` has due before it
/// ([`AidFeed`]), writing what comes out to `out` on a writer thread
/// ([`WriterThread`]) and keeping the filter's snapshots as they come (in
/// [`Driven::snapshots`]); `on_sample` is called every 65,536 samples with their
/// count. On a read error the session ends there, its last state is written (if it
/// was not an output epoch) and the error is returned in [`Driven::failure`] with the
/// count and the time reached. `None` when the input held no sample at all.
pub fn drive<M: EarthModel>(
    mut session: Session<M>,
    mut feed: AidFeed<'_>,
    samples: &mut Samples<'_>,
    out: Outputs,
    dir: &Path,
    on_sample: &mut dyn FnMut(u64),
) -> Result<Option<Driven>> {
    let mut pipe = WriterThread::spawn(out)?;
    let mut snapshots = Spilled::default();
    let pushing = (&mut session, &mut feed, &mut pipe, &mut snapshots);
    let Some((n, mut failure)) = push_samples(pushing, samples, on_sample) else {
        return Err(writer_error(pipe));
    };
    if let Err(e) = feed.rest(&mut session) {
        failure.get_or_insert(e);
    }
    session.end_of_input();
    if pipe.take(&mut session).is_err() {
        return Err(writer_error(pipe));
    }
    if n == 0 && session.integrated_to().is_none() {
        // Nothing was pushed: the session has no state to report.
        pipe.join()?;
        return failure.map_or(Ok(None), Err);
    }
    if failure.is_some()
        && let Some(e) = session.epoch_now()
        && pipe.last(e).is_err()
    {
        return Err(writer_error(pipe));
    }
    let out = pipe.join()?;
    session.snapshots().for_each(|x| snapshots.push(&x));
    let finished = match session.finish() {
        Ok(f) => f,
        Err(e) => {
            // What was written stays whole: the files are closed before the error.
            let epochs = close_trajectory(out.nav, out.bag)?;
            if let Some(files) = out.filter {
                files.finish(dir)?;
            }
            return Err(anyhow::Error::new(e).context(format!(
                "{epochs} epochs up to t = {} were written to {}",
                out.last_written,
                dir.display()
            )));
        }
    };
    let mut finished = finished;
    finished
        .snapshots
        .drain(..)
        .for_each(|x| snapshots.push(&x));
    let epochs = close_trajectory(out.nav, out.bag)?;
    let failure = failure.map(|e| {
        e.context(format!(
            "stopped after {} samples; {epochs} epochs up to t = {} were written to {}",
            finished.summary.samples,
            finished.summary.t_last,
            dir.display()
        ))
    });
    Ok(Some(Driven {
        finished,
        failure,
        epochs,
        heading_settled: out.heading_settled,
        snapshots,
        filter: out.filter,
    }))
}

/// The smoothed trajectory: `nav.txt`, `nav.csv`, `std.txt`, `imu_err.txt` in `dir`,
/// written as it is computed.
pub fn write_smoothed<E: EarthModel>(
    earth: &E,
    dir: &Path,
    week: u32,
    smoothed: SmoothedTrajectory,
) -> Result<()> {
    let mut nav = NavWriter::create_extended(dir, week, earth)?;
    let mut std = Table::create(dir, "std.txt")?;
    let mut err = Table::create(dir, "imu_err.txt")?;
    for s in smoothed.states(*earth) {
        let s = s?;
        nav.write_epoch(&NavEpoch {
            state: s.state,
            r_e: earth.geodetic_to_ecef(&s.state.pos),
            wander_azimuth: 0.0,
        })?;
        let mut row: Vec<f64> = s.std[0].iter().chain(s.std[1].iter()).copied().collect();
        row.extend(s.std[2].iter().map(|x| x.to_degrees()));
        std.row(s.state.t, &row)?;
        err.row(s.state.t, &imu_err_row(&s.estimates))?;
    }
    nav.finish()?;
    std.finish()?;
    err.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows whose last fields repeat the last row's (copied, not formatted), rows that
    /// change everywhere, a row the window declines (NaN, then no copy from it) and a
    /// row of another length: the file holds the text of [`push_table_row`] for each.
    #[test]
    fn repeated_fields_are_the_vec_writers_text() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let rows: [(f64, &[f64]); 10] = [
            (1.0, &[0.5, -2.25, 1e-9, 123.456]),
            (1.005, &[0.75, -2.25, 1e-9, 123.456]),
            (1.01, &[0.75, -2.25, 1e-9, 123.456]),
            (1.015, &[12345.678, 3.0, 1e-9, 123.456]),
            (1.02, &[f64::NAN, 3.0, 1e-9, 123.456]),
            (1.025, &[1.0, 3.0, 1e-9, 123.456]),
            (1.03, &[1.0, 3.0, 1e-9, 123.457]),
            (1.035, &[-0.0, 3.0, 1e-9, 123.457]),
            (1.04, &[2.0, 1e-9, 123.457]),
            (1.045, &[2.5, 1e-9, 123.457]),
        ];
        let mut table = Table::create(dir.path(), "t.txt").expect("create");
        let mut want = Vec::new();
        for (t, values) in rows {
            table.row(t, values).expect("row");
            push_table_row(&mut want, t, values);
        }
        table.finish().expect("finish");
        let got = std::fs::read(dir.path().join("t.txt")).expect("read");
        assert_eq!(
            String::from_utf8_lossy(&got),
            String::from_utf8_lossy(&want)
        );
    }
}
