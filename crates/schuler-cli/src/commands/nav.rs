//! `schuler nav`: free-inertial navigation of an IMU log.
//!
//! Reads the log lazily, starts from the given initial state at the time tag of the
//! first processed sample, mechanizes every later sample and writes `nav.txt`
//! (KF-GINS navigation-result format) and `nav.csv` at the requested output rate.

use crate::formats::{ImuFormat, ImuLayout, ImuReadOptions, ImuReader};
use crate::output::NavWriter;
use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use nalgebra::Vector3;
use schuler::earth::{EarthModel, Geodetic, Sphere, Wgs84};
use schuler::imu::ImuSample;
use schuler::nav::{LocalLevel, Mechanization, NavState};
use schuler::rotation::Euler;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Three comma-separated numbers, e.g. `45.07,7.68,245`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(transparent)]
pub struct Triple(pub [f64; 3]);

impl std::str::FromStr for Triple {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.len() != 3 {
            return Err(format!("expected three comma-separated numbers, got {s:?}"));
        }
        let mut v = [0.0; 3];
        for (slot, p) in v.iter_mut().zip(&parts) {
            *slot = p
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("not a finite number: {p:?} in {s:?}"))?;
        }
        Ok(Self(v))
    }
}

/// The Earth model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum EarthChoice {
    /// WGS84 ellipsoid with normal gravity.
    #[default]
    Wgs84,
    /// The textbook's rotating sphere (a = 6371 km, g = 9.81 m/s^2 at the surface).
    Sphere,
    /// The textbook's sphere without rotation.
    SphereFixed,
}

/// The IMU log's file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FormatChoice {
    /// Decide from the first line (a number: KF-GINS text; otherwise a CSV header).
    #[default]
    Auto,
    /// KF-GINS text: time, dtheta xyz [rad], dvel xyz [m/s].
    KfGins,
    /// CSV with a header (`t,dtheta_x,...` or `t,w_x,...,f_z`).
    Csv,
}

/// Whether the sensor columns are increments or rates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LayoutChoice {
    /// Increments over (t_prev, t] [rad, m/s].
    Increments,
    /// Mean rates over (t_prev, t] [rad/s, m/s^2].
    Rates,
}

/// Arguments of `schuler nav`; every flag can also come from `--config FILE.toml`
/// under the same name with underscores (flags win).
#[derive(clap::Args, Debug, Default)]
pub struct NavArgs {
    /// TOML configuration holding any of the options below (e.g. `imu = "IMU.txt"`,
    /// `init_pos = [45.07, 7.68, 245.0]`); paths in it are relative to its folder.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// IMU log: KF-GINS text (time, dtheta xyz, dvel xyz; FRD) or CSV with a header.
    #[arg(long, value_name = "FILE")]
    pub imu: Option<PathBuf>,
    /// Initial position: latitude [deg], longitude [deg], ellipsoidal height [m].
    #[arg(long, value_name = "LAT,LON,H", allow_hyphen_values = true)]
    pub init_pos: Option<Triple>,
    /// Initial velocity north, east, down [m/s] (default 0,0,0).
    #[arg(long, value_name = "VN,VE,VD", allow_hyphen_values = true)]
    pub init_vel: Option<Triple>,
    /// Initial attitude roll, pitch, yaw [deg] (Z-Y-X Euler angles, body FRD).
    #[arg(long, value_name = "ROLL,PITCH,YAW", allow_hyphen_values = true)]
    pub init_att: Option<Triple>,
    /// Start time [s of week, the log's clock]: the first sample at or after it
    /// carries the initial state.
    #[arg(long, value_name = "SOW")]
    pub start: Option<f64>,
    /// End time [s of week]: samples after it are not read.
    #[arg(long, value_name = "SOW")]
    pub end: Option<f64>,
    /// Output rate [Hz]; default: every IMU sample.
    #[arg(long, value_name = "HZ")]
    pub output_rate: Option<f64>,
    /// Output directory for nav.txt and nav.csv (default: current directory).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Earth model.
    #[arg(long, value_enum)]
    pub earth: Option<EarthChoice>,
    /// IMU file format.
    #[arg(long, value_enum)]
    pub imu_format: Option<FormatChoice>,
    /// Whether the IMU columns hold increments or rates (default: increments for
    /// KF-GINS text, the header's names for CSV).
    #[arg(long, value_enum)]
    pub imu_layout: Option<LayoutChoice>,
    /// Nominal IMU rate [Hz] (default: estimated from the first intervals).
    #[arg(long, value_name = "HZ")]
    pub imu_rate: Option<f64>,
    /// GPS week written in the first column of nav.txt (default 0, as KF-GINS).
    #[arg(long)]
    pub week: Option<u32>,
    /// Skip the check that accelerometer magnitudes match the declared layout (for
    /// free fall, centrifuges and other starts far from 1 g).
    #[arg(long)]
    pub no_layout_check: bool,
}

/// The same options as a TOML file.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct NavConfig {
    imu: Option<PathBuf>,
    init_pos: Option<Triple>,
    init_vel: Option<Triple>,
    init_att: Option<Triple>,
    start: Option<f64>,
    end: Option<f64>,
    output_rate: Option<f64>,
    out: Option<PathBuf>,
    earth: Option<EarthChoice>,
    imu_format: Option<FormatChoice>,
    imu_layout: Option<LayoutChoice>,
    imu_rate: Option<f64>,
    week: Option<u32>,
    no_layout_check: Option<bool>,
}

/// Everything `nav` needs, validated.
#[derive(Debug, Clone)]
pub struct NavSettings {
    /// IMU log.
    pub imu: PathBuf,
    /// Reader options.
    pub read: ImuReadOptions,
    /// Initial position, velocity, attitude (time filled from the first sample).
    pub init_pos: Geodetic,
    /// Initial NED velocity.
    pub init_vel: Vector3<f64>,
    /// Initial attitude.
    pub init_att: Euler,
    /// Output rate [Hz], `None`: every sample.
    pub output_rate: Option<f64>,
    /// Output directory.
    pub out: PathBuf,
    /// Earth model.
    pub earth: EarthChoice,
    /// GPS week for nav.txt.
    pub week: u32,
}

fn load_config(path: &Path) -> Result<NavConfig> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut cfg: NavConfig =
        toml::from_str(&text).with_context(|| format!("in {}", path.display()))?;
    let base = path.parent().unwrap_or(Path::new(""));
    for p in [&mut cfg.imu, &mut cfg.out].into_iter().flatten() {
        if p.is_relative() {
            *p = base.join(&*p);
        }
    }
    Ok(cfg)
}

impl NavSettings {
    /// Merge flags over the config file and check every value.
    pub fn from_args(args: NavArgs) -> Result<Self> {
        let cfg = match &args.config {
            Some(p) => load_config(p)?,
            None => NavConfig::default(),
        };
        let imu = args
            .imu
            .or(cfg.imu)
            .context("no IMU log: give --imu FILE (or `imu = \"FILE\"` in the config)")?;
        let Triple([lat, lon, h]) = args
            .init_pos
            .or(cfg.init_pos)
            .context("no initial position: give --init-pos LAT,LON,H (deg, deg, m)")?;
        if !(-90.0..=90.0).contains(&lat) {
            bail!("--init-pos: latitude {lat} deg is outside [-90, 90]");
        }
        let Triple(v) = args.init_vel.or(cfg.init_vel).unwrap_or(Triple([0.0; 3]));
        let Triple([roll, pitch, yaw]) = args.init_att.or(cfg.init_att).context(
            "no initial attitude: give --init-att ROLL,PITCH,YAW (deg); free-inertial \
             navigation cannot start without one",
        )?;
        if !(-90.0..=90.0).contains(&pitch) {
            bail!("--init-att: pitch {pitch} deg is outside [-90, 90]");
        }
        let output_rate = args.output_rate.or(cfg.output_rate);
        if let Some(r) = output_rate
            && !(r.is_finite() && r > 0.0)
        {
            bail!("--output-rate must be a positive number of Hz, got {r}");
        }
        let imu_rate = args.imu_rate.or(cfg.imu_rate);
        if let Some(r) = imu_rate
            && !(r.is_finite() && r > 0.0)
        {
            bail!("--imu-rate must be a positive number of Hz, got {r}");
        }
        let (start, end) = (args.start.or(cfg.start), args.end.or(cfg.end));
        if let (Some(s), Some(e)) = (start, end)
            && s >= e
        {
            bail!("--start {s} is not before --end {e}");
        }
        let read = ImuReadOptions {
            format: match args.imu_format.or(cfg.imu_format).unwrap_or_default() {
                FormatChoice::Auto => ImuFormat::Auto,
                FormatChoice::KfGins => ImuFormat::KfGinsText,
                FormatChoice::Csv => ImuFormat::Csv,
            },
            layout: args.imu_layout.or(cfg.imu_layout).map(|l| match l {
                LayoutChoice::Increments => ImuLayout::Increments,
                LayoutChoice::Rates => ImuLayout::Rates,
            }),
            nominal_dt: imu_rate.map(|r| 1.0 / r),
            t_start: start,
            t_end: end,
            check_layout: !(args.no_layout_check || cfg.no_layout_check.unwrap_or(false)),
        };
        Ok(Self {
            imu,
            read,
            init_pos: Geodetic::from_degrees(lat, lon, h),
            init_vel: Vector3::from(v),
            init_att: Euler::from_degrees(roll, pitch, yaw),
            output_rate,
            out: args.out.or(cfg.out).unwrap_or_else(|| PathBuf::from(".")),
            earth: args.earth.or(cfg.earth).unwrap_or_default(),
            week: args.week.or(cfg.week).unwrap_or(0),
        })
    }
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct NavSummary {
    /// Samples integrated (the first sample, which carries the initial state, excluded).
    pub samples: u64,
    /// Epochs written.
    pub epochs: u64,
    /// First and last time [s].
    pub t_first: f64,
    /// Last time [s].
    pub t_last: f64,
    /// Final state.
    pub last: NavState,
    /// Gap warning, if any.
    pub gaps: Option<String>,
}

/// Decides which epochs to write: every one, or the first epoch at or after each
/// multiple of `1/rate` (a thousandth of a sample interval of tolerance absorbs the
/// decimal time tags of logs).
struct Decimator {
    rate: Option<f64>,
    last_slot: f64,
}

impl Decimator {
    fn new(rate: Option<f64>) -> Self {
        Self {
            rate,
            last_slot: f64::NEG_INFINITY,
        }
    }

    fn take(&mut self, t: f64, dt: f64) -> bool {
        match self.rate {
            None => true,
            Some(r) => {
                let slot = ((t + 1e-3 * dt) * r).floor();
                let take = slot > self.last_slot;
                if take {
                    self.last_slot = slot;
                }
                take
            }
        }
    }
}

/// Run free-inertial navigation over `samples` (the first one carries the initial
/// state), writing through `writer`. On a read error everything computed so far is
/// flushed before the error is returned.
pub fn navigate<E: EarthModel, I>(
    earth: E,
    settings: &NavSettings,
    mut samples: I,
    mut writer: NavWriter,
    mut on_sample: impl FnMut(u64),
) -> Result<NavSummary>
where
    I: Iterator<Item = Result<ImuSample, crate::formats::InputError>>,
{
    let first = match samples.next() {
        Some(s) => s?,
        None => bail!(
            "{}: no IMU sample in the requested time window",
            settings.imu.display()
        ),
    };
    let init = NavState::new(
        first.t,
        settings.init_pos,
        settings.init_vel,
        settings.init_att,
    );
    let mut nav = LocalLevel::new(earth, init);
    nav.prime(&first);
    let mut decimator = Decimator::new(settings.output_rate);
    decimator.take(first.t, first.dt);
    writer.write(&init)?;
    let mut n = 0u64;
    let mut last_t = first.t;
    let mut last_written = first.t;
    for s in samples {
        let s = match s {
            Ok(s) => s,
            Err(e) => {
                let state = nav.state();
                if last_written != state.t {
                    writer.write(&state)?;
                }
                let rows = writer.finish()?;
                return Err(anyhow::Error::new(e).context(format!(
                    "stopped after {n} samples; {rows} epochs up to t = {} were written to {}",
                    state.t,
                    settings.out.display()
                )));
            }
        };
        nav.step(&s);
        n += 1;
        last_t = s.t;
        if decimator.take(s.t, s.dt) {
            writer.write(&nav.state())?;
            last_written = s.t;
        }
        if n.is_multiple_of(65_536) {
            on_sample(n);
        }
    }
    let epochs = writer.finish()?;
    Ok(NavSummary {
        samples: n,
        epochs,
        t_first: first.t,
        t_last: last_t,
        last: nav.state(),
        gaps: None,
    })
}

/// `schuler nav`.
pub fn run(args: NavArgs) -> Result<()> {
    let settings = NavSettings::from_args(args)?;
    let started = Instant::now();
    let mut reader = ImuReader::open(&settings.imu, &settings.read)?;
    eprintln!(
        "{}: {}, {}, nominal rate {:.6} Hz",
        settings.imu.display(),
        match reader.format() {
            ImuFormat::Csv => "CSV",
            _ => "KF-GINS text",
        },
        reader.layout(),
        1.0 / reader.nominal_dt()
    );
    let total = std::fs::metadata(&settings.imu)
        .map(|m| m.len())
        .unwrap_or(0);
    let bar = ProgressBar::with_draw_target(Some(total), indicatif::ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} navigating [{bar:40}] {percent:>3}% {bytes}/{total_bytes} eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let progress = reader.progress();
    let writer = NavWriter::create(&settings.out, settings.week)?;
    let on_sample = |_| bar.set_position(progress.bytes());
    let mut summary = match settings.earth {
        EarthChoice::Wgs84 => navigate(Wgs84, &settings, &mut reader, writer, on_sample),
        EarthChoice::Sphere => navigate(
            Sphere::textbook(true),
            &settings,
            &mut reader,
            writer,
            on_sample,
        ),
        EarthChoice::SphereFixed => navigate(
            Sphere::textbook(false),
            &settings,
            &mut reader,
            writer,
            on_sample,
        ),
    }?;
    bar.set_position(reader.bytes_read());
    bar.finish_and_clear();
    let report = reader.gaps();
    if !report.is_empty() {
        eprintln!("warning: {}: {report}", settings.imu.display());
        summary.gaps = Some(report.to_string());
    }
    let secs = started.elapsed().as_secs_f64();
    let e = summary.last.euler();
    println!(
        "navigated {} samples, t = {} .. {} s ({:.1} s of data) in {:.2} s ({:.2} M samples/s)",
        summary.samples,
        summary.t_first,
        summary.t_last,
        summary.t_last - summary.t_first,
        secs,
        summary.samples as f64 / secs / 1e6
    );
    println!(
        "final: lat {:.9} deg, lon {:.9} deg, h {:.3} m, v_ned [{:.3}, {:.3}, {:.3}] m/s, roll {:.4} pitch {:.4} yaw {:.4} deg",
        summary.last.pos.lat.to_degrees(),
        summary.last.pos.lon.to_degrees(),
        summary.last.pos.h,
        summary.last.v_n.x,
        summary.last.v_n.y,
        summary.last.v_n.z,
        e.roll.to_degrees(),
        e.pitch.to_degrees(),
        e.heading_0_2pi().to_degrees()
    );
    println!(
        "wrote {} epochs to {} and {}",
        summary.epochs,
        settings.out.join("nav.txt").display(),
        settings.out.join("nav.csv").display()
    );
    Ok(())
}
