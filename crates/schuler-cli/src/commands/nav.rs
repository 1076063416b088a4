//! `schuler nav`: free-inertial navigation of an IMU log.
//!
//! Reads the log lazily, starts from the given initial state at the time tag of the
//! first processed sample, mechanizes every later sample and writes `nav.txt`
//! (KF-GINS navigation-result format) and `nav.csv` (with ECEF position and wander
//! azimuth) at the requested output rate.
//!
//! Mechanizations (`--mechanization`): `ned` (latitude/longitude, singular at the
//! poles), `wander` (the all-latitude free-azimuth mechanization of seed 003, valid
//! everywhere), or `auto` (default): NED while `|lat| <= auto_latitude`, wander above
//! it, back to NED below `auto_latitude − auto_hysteresis` (defaults 75° and 0.5°).
//! A hand-over converts the state and the two-sample step history exactly (NED →
//! wander with wander azimuth 0; wander → NED by turning velocity, attitude and the
//! history through the azimuth), so the run continues as if uninterrupted.

use super::aided::{Aiding, AidingOptions};
use super::align::AlignOptions;
use crate::formats::{ImuFormat, ImuLayout, ImuReadOptions, ImuReader};
use crate::output::{NavEpoch, NavWriter};
use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use nalgebra::Vector3;
use schuler::earth::{EarthModel, Geodetic, Sphere, Wgs84};
use schuler::imu::ImuSample;
use schuler::nav::{LocalLevel, Mechanization, NavState, Wander, WanderEarth};
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

impl FormatChoice {
    /// The reader's format.
    pub fn format(self) -> ImuFormat {
        match self {
            FormatChoice::Auto => ImuFormat::Auto,
            FormatChoice::KfGins => ImuFormat::KfGinsText,
            FormatChoice::Csv => ImuFormat::Csv,
        }
    }
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

impl LayoutChoice {
    /// The reader's layout.
    pub fn layout(self) -> ImuLayout {
        match self {
            LayoutChoice::Increments => ImuLayout::Increments,
            LayoutChoice::Rates => ImuLayout::Rates,
        }
    }
}

/// Which strapdown mechanization integrates the log.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum MechanizationChoice {
    /// Local-level NED (latitude, longitude): singular at the poles.
    Ned,
    /// All-latitude free-azimuth (wander) frame with quaternion position (seed 003).
    Wander,
    /// NED up to `--auto-latitude`, wander above it (hand-over both ways with
    /// hysteresis).
    #[default]
    Auto,
}

/// Which mechanization is running.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MechanizationKind {
    /// [`LocalLevel`] (NED).
    Ned,
    /// [`Wander`].
    Wander,
}

impl std::fmt::Display for MechanizationKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Ned => "NED",
            Self::Wander => "wander",
        })
    }
}

/// The mechanization and, for `auto`, its switching latitudes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MechanizationSettings {
    /// NED, wander or automatic.
    pub choice: MechanizationChoice,
    /// `auto` switches to wander when `|lat|` exceeds this [rad] (default 75°).
    pub auto_latitude: f64,
    /// `auto` switches back to NED when `|lat|` falls below
    /// `auto_latitude − hysteresis` [rad] (default 0.5°).
    pub hysteresis: f64,
}

impl MechanizationSettings {
    /// Default `auto` switching latitude [deg].
    pub const AUTO_LATITUDE_DEG: f64 = 75.0;
    /// Default hysteresis of the hand-back [deg]: 55 km of latitude, so a flight
    /// along the threshold does not hand over at every sample.
    pub const HYSTERESIS_DEG: f64 = 0.5;
}

impl Default for MechanizationSettings {
    fn default() -> Self {
        Self {
            choice: MechanizationChoice::Auto,
            auto_latitude: Self::AUTO_LATITUDE_DEG.to_radians(),
            hysteresis: Self::HYSTERESIS_DEG.to_radians(),
        }
    }
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
    /// Strapdown mechanization (default auto: NED, wander at high latitude).
    #[arg(long, value_enum)]
    pub mechanization: Option<MechanizationChoice>,
    /// `auto`: latitude [deg] above which the wander mechanization runs (default 75).
    #[arg(long, value_name = "DEG")]
    pub auto_latitude: Option<f64>,
    /// `auto`: NED resumes below `auto_latitude` minus this [deg] (default 0.5).
    #[arg(long, value_name = "DEG")]
    pub auto_hysteresis: Option<f64>,
    /// Align first on the log's first `coarse + fine` seconds (the vehicle at rest at
    /// --init-pos), then navigate from the aligned state with the estimated biases
    /// removed; --init-att is then not needed. Writes align.json beside nav.txt.
    #[arg(long)]
    pub align: bool,
    /// Run a KF-GINS configuration file (its paths, initial state, IMU noise and lever
    /// arm, in its units) and write KF-GINS's output files into its outputpath; the
    /// other options do not apply.
    #[arg(long, value_name = "FILE.yaml", conflicts_with_all = ["imu", "config"])]
    pub kf_gins_config: Option<PathBuf>,
    /// Alignment options (with --align).
    #[command(flatten)]
    pub alignment: AlignOptions,
    /// GNSS aiding (with --gnss): the error-state Kalman filter.
    #[command(flatten)]
    pub aiding: AidingOptions,
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
    mechanization: Option<MechanizationChoice>,
    auto_latitude: Option<f64>,
    auto_hysteresis: Option<f64>,
    align: Option<bool>,
    alignment: Option<AlignOptions>,
    aiding: Option<AidingOptions>,
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
    /// Merge flags over the config file and check every value (the mechanization
    /// options are checked and dropped: see [`parse_nav_args`]).
    pub fn from_args(args: NavArgs) -> Result<Self> {
        parse_nav_args(args).map(|(settings, ..)| settings)
    }
}

/// The mechanization options of flags over config, checked.
fn mechanization_settings(args: &NavArgs, cfg: &NavConfig) -> Result<MechanizationSettings> {
    let choice = args.mechanization.or(cfg.mechanization).unwrap_or_default();
    let lat = args
        .auto_latitude
        .or(cfg.auto_latitude)
        .unwrap_or(MechanizationSettings::AUTO_LATITUDE_DEG);
    if !(lat.is_finite() && lat > 0.0 && lat < 90.0) {
        bail!("--auto-latitude must be between 0 and 90 deg (exclusive), got {lat}");
    }
    let hysteresis = args
        .auto_hysteresis
        .or(cfg.auto_hysteresis)
        .unwrap_or(MechanizationSettings::HYSTERESIS_DEG);
    if !(hysteresis.is_finite() && hysteresis >= 0.0 && hysteresis < lat) {
        bail!(
            "--auto-hysteresis must be at least 0 and below --auto-latitude ({lat} deg), \
             got {hysteresis}"
        );
    }
    Ok(MechanizationSettings {
        choice,
        auto_latitude: lat.to_radians(),
        hysteresis: hysteresis.to_radians(),
    })
}

/// Merge flags over the config file and check every value: the run's settings and
/// its mechanization. (The mechanization is kept apart from [`NavSettings`] so that
/// code building `NavSettings` field by field keeps compiling; it goes to
/// [`navigate_with`].)
/// A parsed `nav` command line: settings, mechanization, and the optional alignment
/// and aiding options (not yet resolved).
pub type NavPlan = (
    NavSettings,
    MechanizationSettings,
    (bool, AlignOptions),
    AidingOptions,
);

/// Merge flags over the config file and check every value (see [`NavPlan`]).
pub fn parse_nav_args(args: NavArgs) -> Result<NavPlan> {
    {
        let cfg = match &args.config {
            Some(p) => load_config(p)?,
            None => NavConfig::default(),
        };
        let mechanization = mechanization_settings(&args, &cfg)?;
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
        let align_on = args.align || cfg.align.unwrap_or(false);
        let align = (
            align_on,
            args.alignment
                .clone()
                .or(cfg.alignment.clone().unwrap_or_default()),
        );
        let init_att = match (args.init_att.or(cfg.init_att), align_on) {
            (Some(a), _) => a,
            (None, true) => Triple([0.0; 3]),
            (None, false) => bail!(
                "no initial attitude: give --init-att ROLL,PITCH,YAW (deg), or --align to \
                 align at rest first; free-inertial navigation cannot start without one"
            ),
        };
        let Triple([roll, pitch, yaw]) = init_att;
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
            format: args
                .imu_format
                .or(cfg.imu_format)
                .unwrap_or_default()
                .format(),
            layout: args.imu_layout.or(cfg.imu_layout).map(LayoutChoice::layout),
            nominal_dt: imu_rate.map(|r| 1.0 / r),
            t_start: start,
            t_end: end,
            check_layout: !(args.no_layout_check || cfg.no_layout_check.unwrap_or(false)),
        };
        let settings = NavSettings {
            imu,
            read,
            init_pos: Geodetic::from_degrees(lat, lon, h),
            init_vel: Vector3::from(v),
            init_att: Euler::from_degrees(roll, pitch, yaw),
            output_rate,
            out: args.out.or(cfg.out).unwrap_or_else(|| PathBuf::from(".")),
            earth: args.earth.or(cfg.earth).unwrap_or_default(),
            week: args.week.or(cfg.week).unwrap_or(0),
        };
        let base = args
            .config
            .as_deref()
            .and_then(Path::parent)
            .unwrap_or(Path::new(""));
        let aiding =
            args.aiding
                .clone()
                .or(cfg.aiding.clone().unwrap_or_default().relative_to(base));
        Ok((settings, mechanization, align, aiding))
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
    /// The mechanization at the start.
    pub first_mechanization: MechanizationKind,
    /// Hand-overs between mechanizations (`auto`), in order.
    pub handovers: Vec<Handover>,
}

/// One hand-over of `auto`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Handover {
    /// Time [s] of the state handed over.
    pub t: f64,
    /// Latitude [rad] there.
    pub lat: f64,
    /// The mechanization taking over.
    pub to: MechanizationKind,
}

/// What the sample loop needs from a mechanization (NED only, or hand-over).
trait Runner {
    fn kind(&self) -> MechanizationKind;
    fn prime(&mut self, s: &ImuSample);
    fn step(&mut self, s: &ImuSample);
    fn state(&self) -> NavState;
    fn epoch(&self) -> NavEpoch;
    fn handovers(self) -> Vec<Handover>;
}

/// The NED mechanization alone, for any Earth model.
struct NedOnly<E: EarthModel>(LocalLevel<E>);

impl<E: EarthModel> Runner for NedOnly<E> {
    fn kind(&self) -> MechanizationKind {
        MechanizationKind::Ned
    }
    fn prime(&mut self, s: &ImuSample) {
        self.0.prime(s);
    }
    #[inline]
    fn step(&mut self, s: &ImuSample) {
        self.0.step(s);
    }
    fn state(&self) -> NavState {
        self.0.state()
    }
    fn epoch(&self) -> NavEpoch {
        let state = self.0.state();
        NavEpoch {
            state,
            r_e: self.0.earth().geodetic_to_ecef(&state.pos),
            wander_azimuth: 0.0,
        }
    }
    fn handovers(self) -> Vec<Handover> {
        Vec::new()
    }
}

/// The running mechanization.
#[derive(Debug, Clone)]
enum Engine<E: WanderEarth> {
    Ned(LocalLevel<E>),
    Wander(Wander<E>),
}

/// A mechanization that hands over between NED and wander as `settings` says.
#[derive(Debug, Clone)]
struct Navigator<E: WanderEarth> {
    engine: Engine<E>,
    earth: E,
    auto: bool,
    /// `auto`: wander above this `|sin lat|`, NED below `sin_leave`.
    sin_enter: f64,
    sin_leave: f64,
    handovers: Vec<Handover>,
}

impl<E: WanderEarth> Navigator<E> {
    fn new(earth: E, init: NavState, settings: &MechanizationSettings) -> Self {
        let sin_enter = settings.auto_latitude.sin();
        let sin_leave = (settings.auto_latitude - settings.hysteresis).sin();
        let wander = match settings.choice {
            MechanizationChoice::Ned => false,
            MechanizationChoice::Wander => true,
            MechanizationChoice::Auto => init.pos.lat.sin().abs() > sin_enter,
        };
        let engine = if wander {
            Engine::Wander(Wander::new(earth, init))
        } else {
            Engine::Ned(LocalLevel::new(earth, init))
        };
        Self {
            engine,
            earth,
            auto: settings.choice == MechanizationChoice::Auto,
            sin_enter,
            sin_leave,
            handovers: Vec::new(),
        }
    }

    fn record(&mut self, s: NavState, to: MechanizationKind) {
        self.handovers.push(Handover {
            t: s.t,
            lat: s.pos.lat,
            to,
        });
    }
}

impl<E: WanderEarth> Runner for Navigator<E> {
    fn kind(&self) -> MechanizationKind {
        match self.engine {
            Engine::Ned(_) => MechanizationKind::Ned,
            Engine::Wander(_) => MechanizationKind::Wander,
        }
    }

    fn handovers(self) -> Vec<Handover> {
        self.handovers
    }

    fn prime(&mut self, s: &ImuSample) {
        match &mut self.engine {
            Engine::Ned(m) => m.prime(s),
            Engine::Wander(m) => m.prime(s),
        }
    }

    #[inline]
    fn step(&mut self, s: &ImuSample) {
        match &mut self.engine {
            Engine::Ned(m) => {
                m.step(s);
                if self.auto && m.state().pos.lat.sin().abs() > self.sin_enter {
                    let w = Wander::from_local_level(m);
                    self.record(w.state(), MechanizationKind::Wander);
                    self.engine = Engine::Wander(w);
                }
            }
            Engine::Wander(m) => {
                m.step(s);
                if self.auto && m.sin_lat().abs() < self.sin_leave {
                    let n = m.to_local_level();
                    self.record(n.state(), MechanizationKind::Ned);
                    self.engine = Engine::Ned(n);
                }
            }
        }
    }

    fn state(&self) -> NavState {
        match &self.engine {
            Engine::Ned(m) => m.state(),
            Engine::Wander(m) => m.state(),
        }
    }

    /// The epoch to write: NED state, ECEF position, wander azimuth (0 in NED).
    fn epoch(&self) -> NavEpoch {
        match &self.engine {
            Engine::Ned(m) => {
                let state = m.state();
                NavEpoch {
                    state,
                    r_e: self.earth.geodetic_to_ecef(&state.pos),
                    wander_azimuth: 0.0,
                }
            }
            Engine::Wander(m) => {
                let (state, wander_azimuth) = m.nav_state_and_azimuth();
                NavEpoch {
                    state,
                    r_e: m.ecef_position(),
                    wander_azimuth,
                }
            }
        }
    }
}

/// Decides which epochs to write: every one, or the first epoch at or after each
/// multiple of `1/rate` (a thousandth of a sample interval of tolerance absorbs the
/// decimal time tags of logs).
pub(crate) struct Decimator {
    rate: Option<f64>,
    last_slot: f64,
}

impl Decimator {
    pub(crate) fn new(rate: Option<f64>) -> Self {
        Self {
            rate,
            last_slot: f64::NEG_INFINITY,
        }
    }

    pub(crate) fn take(&mut self, t: f64, dt: f64) -> bool {
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
/// state) with the NED mechanization, writing through `writer`, for any Earth model.
/// On a read error everything computed so far is flushed before the error is
/// returned. (For the wander and automatic mechanizations see [`navigate_with`].)
pub fn navigate<E: EarthModel, I>(
    earth: E,
    settings: &NavSettings,
    samples: I,
    writer: NavWriter,
    on_sample: impl FnMut(u64),
) -> Result<NavSummary>
where
    I: Iterator<Item = Result<ImuSample, crate::formats::InputError>>,
{
    run_samples(
        |init| NedOnly(LocalLevel::new(earth, init)),
        settings,
        samples,
        writer,
        on_sample,
    )
}

/// As [`navigate`], with the mechanization `mechanization` (NED, wander, or
/// automatic hand-over), on an Earth model the wander mechanization can evaluate
/// ([`WanderEarth`]: WGS84 and the sphere).
pub fn navigate_with<E: WanderEarth, I>(
    earth: E,
    settings: &NavSettings,
    mechanization: &MechanizationSettings,
    samples: I,
    writer: NavWriter,
    on_sample: impl FnMut(u64),
) -> Result<NavSummary>
where
    I: Iterator<Item = Result<ImuSample, crate::formats::InputError>>,
{
    run_samples(
        |init| Navigator::new(earth, init, mechanization),
        settings,
        samples,
        writer,
        on_sample,
    )
}

/// The first sample of the window and the initial state at its time (the settings'
/// position, velocity and attitude), or an error naming the IMU file when the window
/// holds no sample.
pub fn first_sample<I>(settings: &NavSettings, samples: &mut I) -> Result<(ImuSample, NavState)>
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
    Ok((first, init))
}

/// The sample loop: start `make(initial state)` at the first sample, prime it with
/// that sample, step every later one, write decimated epochs.
fn run_samples<R: Runner, I>(
    make: impl FnOnce(NavState) -> R,
    settings: &NavSettings,
    mut samples: I,
    mut writer: NavWriter,
    mut on_sample: impl FnMut(u64),
) -> Result<NavSummary>
where
    I: Iterator<Item = Result<ImuSample, crate::formats::InputError>>,
{
    let (first, init) = first_sample(settings, &mut samples)?;
    let mut nav = make(init);
    let first_mechanization = nav.kind();
    nav.prime(&first);
    let mut decimator = Decimator::new(settings.output_rate);
    decimator.take(first.t, first.dt);
    writer.write_epoch(&nav.epoch())?;
    let mut n = 0u64;
    let mut last_t = first.t;
    let mut last_written = first.t;
    for s in samples {
        let s = match s {
            Ok(s) => s,
            Err(e) => {
                let epoch = nav.epoch();
                if last_written != epoch.state.t {
                    writer.write_epoch(&epoch)?;
                }
                let rows = writer.finish()?;
                return Err(anyhow::Error::new(e).context(format!(
                    "stopped after {n} samples; {rows} epochs up to t = {} were written to {}",
                    epoch.state.t,
                    settings.out.display()
                )));
            }
        };
        nav.step(&s);
        n += 1;
        last_t = s.t;
        if decimator.take(s.t, s.dt) {
            writer.write_epoch(&nav.epoch())?;
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
        first_mechanization,
        handovers: nav.handovers(),
    })
}

/// `schuler nav`.
pub fn run(args: NavArgs) -> Result<()> {
    if let Some(path) = &args.kf_gins_config {
        return super::kf_gins::run(path);
    }
    let (mut settings, mechanization, (align_on, align_opts), aiding_opts) = parse_nav_args(args)?;
    // --imu-grade serves the alignment and the filter alike. Its default is
    // navigation grade for alignment (gyrocompassing needs it) but tactical for the
    // filter: an optimistic noise model makes the gate refuse good fixes, a
    // pessimistic one only costs a little accuracy.
    let grade = align_opts.imu_grade.unwrap_or(if aiding_opts.any() {
        super::align::GradeChoice::Tactical
    } else {
        super::align::GradeChoice::Navigation
    });
    let align = align_on.then(|| align_opts.resolve()).transpose()?;
    let aiding: Option<Aiding> = aiding_opts.resolve(grade.noise()?)?;
    // With aiding there is no hand-over: `auto` picks the wander mechanization when
    // the start is above --auto-latitude, NED otherwise.
    let aided_wander = match mechanization.choice {
        MechanizationChoice::Ned => false,
        MechanizationChoice::Wander => true,
        MechanizationChoice::Auto => settings.init_pos.lat.abs() > mechanization.auto_latitude,
    };
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
    let on_sample = |_| bar.set_position(progress.bytes());
    let mech = &mechanization;
    // With --align: align on the first stages, then start from the aligned state at
    // the last aligned sample with the estimated biases removed.
    let mut head = Vec::new();
    let mut bias = (Vector3::zeros(), Vector3::zeros());
    if let Some((cfg, noise)) = &align {
        let samples = super::align::read_stage(&mut reader, cfg.coarse + cfg.fine)?;
        let a = super::align::align_on(settings.earth, settings.init_pos, &samples, noise, cfg)
            .with_context(|| format!("aligning {}", settings.imu.display()))?;
        bar.suspend(|| print!("{}", super::align::summary_text(&a, &[])));
        super::align::write_outputs(&settings.out, &a)?;
        settings.init_att = a.state.euler();
        settings.init_vel = Vector3::zeros();
        bias = (a.gyro_bias, a.accel_bias);
        let carrier = samples
            .partition_point(|s| s.t <= a.t_end + 1e-9)
            .saturating_sub(1);
        head = samples[carrier..].to_vec();
    }
    let compensate = |r: Result<ImuSample, crate::formats::InputError>| {
        r.map(|s| ImuSample {
            dtheta: s.dtheta - bias.0 * s.dt,
            dvel: s.dvel - bias.1 * s.dt,
            ..s
        })
    };
    let samples = head.into_iter().map(Ok).chain(&mut reader).map(compensate);
    if let Some(aiding) = &aiding {
        use super::aided::navigate_aided_on as run_on;
        let summary = match settings.earth {
            EarthChoice::Wgs84 => {
                let w = NavWriter::create_extended(&settings.out, settings.week, &Wgs84)?;
                if aided_wander {
                    run_on::<Wander<Wgs84>, _, _>(Wgs84, &settings, aiding, samples, w, on_sample)
                } else {
                    run_on::<LocalLevel<Wgs84>, _, _>(
                        Wgs84, &settings, aiding, samples, w, on_sample,
                    )
                }
            }
            EarthChoice::Sphere | EarthChoice::SphereFixed => {
                let sphere = Sphere::textbook(settings.earth == EarthChoice::Sphere);
                let w = NavWriter::create_extended(&settings.out, settings.week, &sphere)?;
                if aided_wander {
                    run_on::<Wander<Sphere>, _, _>(sphere, &settings, aiding, samples, w, on_sample)
                } else {
                    run_on::<LocalLevel<Sphere>, _, _>(
                        sphere, &settings, aiding, samples, w, on_sample,
                    )
                }
            }
        }?;
        bar.finish_and_clear();
        let c = summary.counts;
        let secs = started.elapsed().as_secs_f64();
        println!(
            "integrated {} samples with {} GNSS fixes in {:.2} s: {} position and {} velocity updates, {} rejected by the gate, {} outside the IMU data (see rejected.csv); mean NIS per dimension {:.2}",
            summary.nav.samples,
            aiding.fixes.len(),
            secs,
            c.position,
            c.velocity,
            c.rejected,
            c.skipped,
            summary.mean_nis_per_dof
        );
        print!("{}", summary.report_text);
        if let Some(line) = super::vehicle::summary(&c) {
            println!("{line}");
        }
        if let Some(test) = &aiding.outage_test {
            super::aided::report_outage_test(
                &settings.out.join("nav.txt"),
                &test.windows,
                test.truth.as_deref(),
                &settings.out,
            )?;
        }
        let tried = c.position
            + c.velocity
            + c.baro
            + c.zupt
            + c.zaru
            + c.nhc
            + c.odometer
            + c.heading
            + c.rejected;
        if c.rejected * 10 > tried {
            eprintln!(
                "warning: the gate refused {} of {} measurements (see rejected.csv): the IMU noise model is probably too optimistic for this sensor (--imu-grade, --arw, --gyro-bias-std, ...)",
                c.rejected, tried
            );
        }
        println!(
            "wrote {} epochs to {} (and nav.csv, std.txt, imu_err.txt, rejected.csv)",
            summary.nav.epochs,
            settings.out.join("nav.txt").display()
        );
        return Ok(());
    }
    let mut summary = match settings.earth {
        EarthChoice::Wgs84 => {
            let writer = NavWriter::create_extended(&settings.out, settings.week, &Wgs84)?;
            navigate_with(Wgs84, &settings, mech, samples, writer, on_sample)
        }
        EarthChoice::Sphere | EarthChoice::SphereFixed => {
            let sphere = Sphere::textbook(settings.earth == EarthChoice::Sphere);
            let writer = NavWriter::create_extended(&settings.out, settings.week, &sphere)?;
            navigate_with(sphere, &settings, mech, samples, writer, on_sample)
        }
    }?;
    bar.set_position(reader.bytes_read());
    bar.finish_and_clear();
    let report = reader.gaps();
    if !report.is_empty() {
        eprintln!("warning: {}: {report}", settings.imu.display());
        summary.gaps = Some(report.to_string());
    }
    let secs = started.elapsed().as_secs_f64();
    println!(
        "mechanization: {} from the start",
        summary.first_mechanization
    );
    for h in &summary.handovers {
        println!(
            "  hand-over to {} at t = {} s, lat {:.6} deg",
            h.to,
            h.t,
            h.lat.to_degrees()
        );
    }
    let last = summary.last.normalized();
    let e = last.euler();
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
        last.pos.lat.to_degrees(),
        (last.pos.lon.to_degrees() + 180.0).rem_euclid(360.0) - 180.0,
        last.pos.h,
        last.v_n.x,
        last.v_n.y,
        last.v_n.z,
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
