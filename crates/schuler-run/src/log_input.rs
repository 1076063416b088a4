//! A device log as a navigation run's input (`schuler nav --log FILE`): PX4 ULog,
//! u-blox UBX, Android GnssLogger or ArduPilot DataFlash, told by content
//! ([`schuler_io::logs::detect`]); a ROS 1 or ROS 2 bag goes the `--bag` way.
//!
//! The log is read three times, each pass streaming: the first gathers the chosen
//! GNSS stream's fixes and the barometer's heights (small: a few per second) into
//! the same [`BagAids`] a bag's run hands the session, and chooses the streams; the
//! second hands the chosen IMU stream's samples to the session ([`LogImu`]); after
//! the run, the third compares the device's own solution with ours
//! ([`crate::log_reference`]).
//!
//! Choices: the IMU stream with the highest mean rate (`--imu-stream NAME` to pick
//! another), the GNSS stream with the most fixes (`--gnss-stream NAME`, `none` for no
//! GNSS), the barometer stream with the most readings.
//!
//! The barometer's heights are shifted to the GNSS height at the first fix (the
//! reading nearest it in time): devices give them above mean sea level (PX4) or
//! above the ground at boot (ArduPilot), tens of metres from the fixes' ellipsoidal
//! heights, beyond the barometer bias's prior; the bias state then follows only its
//! drift. [`LogPlan::baro_shift`] says by how much.

use crate::nav::NavPlan;
use anyhow::{Context, Result, bail};
use nalgebra::Matrix3;
use schuler::imu::ImuSample;
use schuler_io::bag::input::BagAids;
use schuler_io::formats::InputError;
use schuler_io::logs::{LogFormat, LogReader, LogRecord, StreamKind, TimeScale, open_reader};
use std::path::{Path, PathBuf};

/// The device-log flags of `schuler nav`, also `--config` keys (`log = "flight.ulg"`).
#[derive(clap::Args, Debug, Default, Clone, PartialEq)]
pub struct LogArgs {
    /// A device log as the input, its format told by content: PX4 ULog, u-blox UBX,
    /// Android GnssLogger, ArduPilot DataFlash (plain or gzip), or a ROS 1/2 bag (as
    /// --bag). Its IMU, GNSS fixes and barometer are used; its own solution, where it
    /// has one, is compared with ours (reference.csv).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["imu", "bag"])]
    pub log: Option<PathBuf>,
    /// The IMU stream to use (as `schuler inspect` names it; default: the highest rate).
    #[arg(long, value_name = "NAME")]
    pub imu_stream: Option<String>,
    /// The GNSS stream to use (default: the one with the most fixes; `none`: no GNSS).
    #[arg(long, value_name = "NAME")]
    pub gnss_stream: Option<String>,
}

impl LogArgs {
    /// `self` (the flags) with what they lack taken from `other` (the configuration).
    pub fn or(self, other: LogArgs) -> LogArgs {
        LogArgs {
            log: self.log.or(other.log),
            imu_stream: self.imu_stream.or(other.imu_stream),
            gnss_stream: self.gnss_stream.or(other.gnss_stream),
        }
    }
}

/// What the first pass found on one stream.
#[derive(Debug, Clone, Default)]
struct Tally {
    count: u64,
    first: f64,
    last: f64,
}

impl Tally {
    fn add(&mut self, t: f64) {
        if self.count == 0 {
            self.first = t;
        }
        self.last = t;
        self.count += 1;
    }

    /// Mean rate [Hz] over the span; 0 for fewer than two records.
    fn rate(&self) -> f64 {
        let span = self.last - self.first;
        if self.count < 2 || span <= 0.0 {
            0.0
        } else {
            (self.count - 1) as f64 / span
        }
    }
}

/// A device log read for a run: its streams chosen, its aids gathered.
#[derive(Debug, Clone)]
pub struct LogPlan {
    /// The log.
    pub path: PathBuf,
    /// Its format.
    pub format: LogFormat,
    /// The clock of its records.
    pub time_scale: TimeScale,
    /// The IMU stream: index and name.
    pub imu: (usize, String),
    /// Its mean rate [Hz] and samples.
    pub imu_rate: f64,
    /// Its samples.
    pub imu_samples: u64,
    /// The GNSS stream's name, if one is used.
    pub gnss: Option<String>,
    /// The barometer stream's name, if any.
    pub baro: Option<String>,
    /// The device's own solution's stream name, if any.
    pub reference: Option<(usize, String)>,
    /// The fixes and barometer heights, as a bag's.
    pub aids: BagAids,
    /// What was added to the barometer's heights [m] (see the module's doc).
    pub baro_shift: Option<f64>,
}

/// The stream of `kind` named `wanted` (refused listing the log's streams of that
/// kind), else the one `best` ranks highest.
fn choose(
    path: &Path,
    reader: &dyn LogReader,
    tallies: &[Tally],
    kind: StreamKind,
    wanted: Option<&str>,
    best: impl Fn(&Tally) -> f64,
) -> Result<Option<usize>> {
    let of_kind: Vec<usize> = (0..reader.streams().len())
        .filter(|&i| {
            reader.streams()[i].kind == kind && tallies.get(i).is_some_and(|t| t.count > 0)
        })
        .collect();
    let names = || {
        of_kind
            .iter()
            .map(|&i| reader.streams()[i].name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    match wanted {
        Some(name) => match of_kind.iter().find(|&&i| reader.streams()[i].name == name) {
            Some(&i) => Ok(Some(i)),
            None => bail!(
                "{}: no {} stream named {name:?} with records; it has: {}",
                path.display(),
                crate::inspect::kind_name(kind).to_uppercase(),
                if of_kind.is_empty() {
                    "none".to_owned()
                } else {
                    names()
                }
            ),
        },
        None => Ok(of_kind.iter().copied().max_by(|&a, &b| {
            best(&tallies[a])
                .total_cmp(&best(&tallies[b]))
                .then(b.cmp(&a))
        })),
    }
}

/// Reads the log once (see the module's doc) and chooses its streams.
pub fn plan_log(path: &Path, format: LogFormat, args: &LogArgs) -> Result<LogPlan> {
    let mut reader = open_reader(path, format)?
        .with_context(|| format!("{}: a ROS bag is read by --bag", path.display()))?;
    let mut tallies: Vec<Tally> = Vec::new();
    let mut fixes: Vec<(usize, schuler::filter::GnssFix)> = Vec::new();
    let mut baro: Vec<(usize, (f64, f64))> = Vec::new();
    for item in reader.by_ref() {
        let item = item?;
        let Some(t) = item.record.t() else { continue };
        if tallies.len() <= item.stream {
            tallies.resize(item.stream + 1, Tally::default());
        }
        tallies[item.stream].add(t);
        match item.record {
            LogRecord::Gnss(f) => fixes.push((item.stream, f)),
            LogRecord::Baro { t, h } => baro.push((item.stream, (t, h))),
            _ => {}
        }
    }
    let r = reader.as_ref();
    let Some(imu) = choose(
        path,
        r,
        &tallies,
        StreamKind::Imu,
        args.imu_stream.as_deref(),
        Tally::rate,
    )?
    else {
        bail!(
            "{}: the log holds no IMU samples: nothing to navigate",
            path.display()
        );
    };
    let gnss = match args.gnss_stream.as_deref() {
        Some("none") => None,
        wanted => choose(path, r, &tallies, StreamKind::Gnss, wanted, |t| {
            t.count as f64
        })?,
    };
    let baro_stream = choose(path, r, &tallies, StreamKind::Baro, None, |t| {
        t.count as f64
    })?;
    let reference = choose(path, r, &tallies, StreamKind::Reference, None, |t| {
        t.count as f64
    })?;
    let name = |i: usize| r.streams()[i].name.clone();
    let mut aids = BagAids {
        fixes: fixes
            .into_iter()
            .filter(|(s, _)| Some(*s) == gnss)
            .map(|(_, f)| f)
            .collect(),
        baro: baro
            .into_iter()
            .filter(|(s, _)| Some(*s) == baro_stream)
            .map(|(_, b)| b)
            .collect(),
        ..BagAids::default()
    };
    aids.fixes.sort_by(|a, b| a.t.total_cmp(&b.t));
    let baro_shift = shift_baro(&mut aids);
    Ok(LogPlan {
        path: path.to_path_buf(),
        format,
        time_scale: r.time_scale(),
        imu: (imu, name(imu)),
        imu_rate: tallies[imu].rate(),
        imu_samples: tallies[imu].count,
        gnss: gnss.map(name),
        baro: baro_stream.map(name),
        reference: reference.map(|i| (i, name(i))),
        aids,
        baro_shift,
    })
}

/// Shifts the barometer's heights to the first fix's height (the reading nearest
/// the fix in time); the shift, when there are both.
fn shift_baro(aids: &mut BagAids) -> Option<f64> {
    let fix = aids.fixes.first()?;
    let nearest = aids
        .baro
        .iter()
        .min_by(|a, b| (a.0 - fix.t).abs().total_cmp(&(b.0 - fix.t).abs()))?;
    let shift = fix.pos.h - nearest.1;
    for b in &mut aids.baro {
        b.1 += shift;
    }
    Some(shift)
}

/// The chosen IMU stream's samples, read again from the start (the second pass), in
/// the run's window and turned by `--imu-axes`/`--imu-rotation` when given.
pub struct LogImu {
    reader: Box<dyn LogReader>,
    stream: usize,
    c_vs: Option<Matrix3<f64>>,
    window: (Option<f64>, Option<f64>),
    last: Option<f64>,
    done: bool,
}

impl LogPlan {
    /// The IMU samples of the run `plan` describes ([`LogImu`]).
    pub fn imu_samples(&self, plan: &NavPlan) -> Result<LogImu> {
        let reader = open_reader(&self.path, self.format)?
            .with_context(|| format!("{}: a ROS bag", self.path.display()))?;
        let read = &plan.settings.read;
        Ok(LogImu {
            reader,
            stream: self.imu.0,
            c_vs: read.c_vs,
            window: (read.t_start, read.t_end),
            last: None,
            done: false,
        })
    }

    /// The GPS week of the log's clock, if it is tied to GPS time.
    pub fn week(&self) -> Option<u32> {
        match self.time_scale {
            TimeScale::GpsSecondsOfWeek { week } => Some(week),
            TimeScale::Device => None,
        }
    }
}

impl Iterator for LogImu {
    type Item = Result<ImuSample, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        while !self.done {
            let item = match self.reader.next()? {
                Ok(item) => item,
                Err(e) => {
                    self.done = true;
                    return Some(Err(e));
                }
            };
            let LogRecord::Imu(mut s) = item.record else {
                continue;
            };
            if item.stream != self.stream {
                continue;
            }
            if self.window.0.is_some_and(|t0| s.t < t0) {
                continue;
            }
            if self.window.1.is_some_and(|t1| s.t > t1) {
                self.done = true;
                return None;
            }
            // A sample not after the last (a restart of the stream's clock) is left out.
            if self.last.is_some_and(|l| s.t <= l) {
                continue;
            }
            self.last = Some(s.t);
            if let Some(c) = &self.c_vs {
                s.dtheta = c * s.dtheta;
                s.dvel = c * s.dvel;
            }
            return Some(Ok(s));
        }
        None
    }
}
