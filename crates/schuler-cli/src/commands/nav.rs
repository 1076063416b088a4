//! `schuler nav`: navigation of an IMU log, free-inertial or aided (`--gnss`,
//! `--baro`, vehicle aids), optionally after an alignment at rest (`--align`), or a
//! KF-GINS configuration (`--kf-gins-config`).
//!
//! Reads the log lazily and pushes it into the library's navigation session
//! ([`schuler::session`]), which starts from the given initial state at the time tag
//! of the first processed sample; writes `nav.txt` (KF-GINS navigation-result format)
//! and `nav.csv` (with ECEF position and wander azimuth) at the requested output rate
//! ([`crate::navigate`]).
//!
//! Mechanizations (`--mechanization`): `ned` (latitude/longitude, singular at the
//! poles), `wander` (the all-latitude free-azimuth mechanization of seed 003, valid
//! everywhere), or `auto` (default): NED while `|lat| <= auto_latitude`, wander above
//! it, back to NED below `auto_latitude − auto_hysteresis` (defaults 75° and 0.5°),
//! in free and aided runs alike (the filter is carried across the hand-over).

use crate::aided::{Aiding, AidingOptions, GivenReadings};
use crate::alignment::AlignOptions;
use crate::bag_input::BagArgs;
use crate::imu_input::ImuInputOptions;
use crate::navigate::{NavSettings, RunSummary, navigate};
use crate::options::{EarthChoice, GradeChoice, GravityChoice, MechanizationChoice, Triple, rate};
use anyhow::{Context, Result, anyhow, bail};
use indicatif::{ProgressBar, ProgressStyle};
use nalgebra::Vector3;
use schuler::earth::{Geodetic, Sphere, Wgs84, Wgs84Series};
use schuler::imu::ImuSample;
use schuler::rotation::Euler;
use schuler::session::{MechanizationConfig, Prior, Start};
use schuler_io::formats::{ImuFormat, ImuReadOptions, ImuReader};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
    /// Normal gravity on WGS84: tr8350 (TR8350.2's closed form, the default) or
    /// kf-gins (the GRS80 series KF-GINS uses, the default of --kf-gins-config).
    #[arg(long, value_enum)]
    pub gravity: Option<GravityChoice>,
    /// With --kf-gins-config: also write report.html (and innovations.csv,
    /// rejected.csv, consistency.json), which KF-GINS does not.
    #[arg(long, requires = "kf_gins_config")]
    pub report: bool,
    /// With --kf-gins-config: also write nav.csv beside KF_GINS_Navresult.nav.
    #[arg(long, requires = "kf_gins_config")]
    pub nav_csv: bool,
    /// How to read the IMU log: format, layout, columns, units, clock, axes.
    #[command(flatten)]
    pub input: ImuInputOptions,
    /// GPS week written in the first column of nav.txt (default 0, as KF-GINS).
    #[arg(long)]
    pub week: Option<u32>,
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
    /// How the run starts: `given` (default: --init-pos, --init-att); `gnss`: in
    /// motion, from the GNSS fixes alone (position and velocity from the fixes, heading
    /// from the course: a land vehicle driving forward along the IMU's x axis is
    /// assumed; roll and pitch from the accelerometers); `gnss-any-heading`: the same
    /// without the course, the heading found by a bank of filters (multicopters); both
    /// need --gnss.
    #[arg(long, value_enum)]
    pub init: Option<InitChoice>,
    /// Run a KF-GINS configuration file (its paths, initial state, IMU noise and lever
    /// arm, in its units) as KF-GINS does and write KF-GINS's three output files into
    /// its outputpath; of the other options only --report, --nav-csv, --gate,
    /// --gravity and --propagation-interval apply.
    #[arg(long, value_name = "FILE.yaml", conflicts_with_all = ["imu", "config"])]
    pub kf_gins_config: Option<PathBuf>,
    /// Alignment options (with --align).
    #[command(flatten)]
    pub alignment: AlignOptions,
    /// GNSS aiding (with --gnss): the error-state Kalman filter.
    #[command(flatten)]
    pub aiding: AidingOptions,
    /// ROS 2 bags: `--bag` as the input, `--out-bag` for the result.
    #[command(flatten)]
    pub bag: BagArgs,
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
    gravity: Option<GravityChoice>,
    week: Option<u32>,
    mechanization: Option<MechanizationChoice>,
    auto_latitude: Option<f64>,
    auto_hysteresis: Option<f64>,
    align: Option<bool>,
    init: Option<InitChoice>,
    alignment: Option<AlignOptions>,
    aiding: Option<AidingOptions>,
    bag: Option<PathBuf>,
    imu_topic: Option<String>,
    gnss_topic: Option<String>,
    gnss_vel_topic: Option<String>,
    baro_topic: Option<String>,
    odom_topic: Option<String>,
    out_bag: Option<PathBuf>,
    leap_seconds: Option<i64>,
    /// The IMU input keys, read apart ([`ImuInputOptions::split_config`]).
    #[serde(skip)]
    input: ImuInputOptions,
}

/// How a run starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum InitChoice {
    /// From --init-pos, --init-vel and --init-att (or --align).
    #[default]
    Given,
    /// In motion, from the GNSS fixes (land vehicles driving forward).
    Gnss,
    /// From the GNSS fixes with the heading unknown (any vehicle, multicopters too): a
    /// bank of twelve filters from every 30° of heading until the data tell them
    /// apart, the most likely kept.
    GnssAnyHeading,
}

fn load_config(path: &Path) -> Result<NavConfig> {
    let text = schuler_io::formats::read_config_text(path)?;
    let (mut cfg, input): (NavConfig, _) =
        ImuInputOptions::split_config(&text).with_context(|| format!("in {}", path.display()))?;
    cfg.input = input;
    let base = path.parent().unwrap_or(Path::new(""));
    let paths = [&mut cfg.imu, &mut cfg.out, &mut cfg.bag, &mut cfg.out_bag];
    for p in paths.into_iter().flatten() {
        if p.is_relative() {
            *p = base.join(&*p);
        }
    }
    Ok(cfg)
}

impl NavConfig {
    /// The bag keys (paths already relative to the file's folder).
    fn bag_args(&self) -> BagArgs {
        BagArgs {
            bag: self.bag.clone(),
            imu_topic: self.imu_topic.clone(),
            gnss_topic: self.gnss_topic.clone(),
            gnss_vel_topic: self.gnss_vel_topic.clone(),
            baro_topic: self.baro_topic.clone(),
            odom_topic: self.odom_topic.clone(),
            out_bag: self.out_bag.clone(),
            leap_seconds: self.leap_seconds,
        }
    }
}

/// The mechanization options of flags over config, checked.
fn mechanization_config(args: &NavArgs, cfg: &NavConfig) -> Result<MechanizationConfig> {
    let choice = args.mechanization.or(cfg.mechanization).unwrap_or_default();
    let lat = args
        .auto_latitude
        .or(cfg.auto_latitude)
        .unwrap_or(MechanizationConfig::AUTO_LATITUDE_DEG);
    if !(lat.is_finite() && lat > 0.0 && lat < 90.0) {
        bail!("--auto-latitude must be between 0 and 90 deg (exclusive), got {lat}");
    }
    let hysteresis = args
        .auto_hysteresis
        .or(cfg.auto_hysteresis)
        .unwrap_or(MechanizationConfig::HYSTERESIS_DEG);
    if !(hysteresis.is_finite() && hysteresis >= 0.0 && hysteresis < lat) {
        bail!(
            "--auto-hysteresis must be at least 0 and below --auto-latitude ({lat} deg), \
             got {hysteresis}"
        );
    }
    Ok(MechanizationConfig {
        choice: choice.session(),
        auto_latitude: lat.to_radians(),
        hysteresis: hysteresis.to_radians(),
    })
}

/// A parsed `nav` command line: settings, the optional alignment and the aiding
/// options (not yet resolved).
#[derive(Debug, Clone)]
pub struct NavPlan {
    /// The run's settings.
    pub settings: NavSettings,
    /// Whether to align first (`--align`).
    pub align: bool,
    /// How the run starts.
    pub init: InitChoice,
    /// The alignment options (`--imu-grade` among them serves the filter too).
    pub alignment: AlignOptions,
    /// The aiding options.
    pub aiding: AidingOptions,
    /// Whether the IMU's axes were given (`--imu-axes`, `--imu-rotation`): a bag's
    /// IMU is FLU otherwise.
    pub axes_given: bool,
    /// The bag flags over the configuration's bag keys.
    pub bag: BagArgs,
}

/// The initial position of flags over config, checked.
fn init_pos(args: &NavArgs, cfg: &NavConfig) -> Result<Geodetic> {
    let Triple([lat, lon, h]) = args
        .init_pos
        .or(cfg.init_pos)
        .context("no initial position: give --init-pos LAT,LON,H (deg, deg, m)")?;
    schuler_io::formats::gnss::position_in_domain(lat, lon, h)
        .map_err(|(_, e)| anyhow!("--init-pos: {e}"))
}

/// The initial attitude of flags over config (zero when aligning), checked.
fn init_att(args: &NavArgs, cfg: &NavConfig, align_on: bool) -> Result<Euler> {
    let Triple([roll, pitch, yaw]) = match (args.init_att.or(cfg.init_att), align_on) {
        (Some(a), _) => a,
        (None, true) => Triple([0.0; 3]),
        (None, false) => bail!(
            "no initial attitude: give --init-att ROLL,PITCH,YAW (deg), or --align to \
             align at rest first; free-inertial navigation cannot start without one"
        ),
    };
    if !(-90.0..=90.0).contains(&pitch) {
        bail!("--init-att: pitch {pitch} deg is outside [-90, 90]");
    }
    Ok(Euler::from_degrees(roll, pitch, yaw))
}

/// The IMU reader's options of flags over config, checked.
fn read_options(args: &NavArgs, cfg: &NavConfig) -> Result<ImuReadOptions> {
    let (start, end) = (args.start.or(cfg.start), args.end.or(cfg.end));
    if let (Some(s), Some(e)) = (start, end)
        && s >= e
    {
        bail!("--start {s} is not before --end {e}");
    }
    args.input
        .clone()
        .or(cfg.input.clone())
        .read_options(start, end)
}

/// Merge flags over the config file and check every value (see [`NavPlan`]).
pub fn parse_nav_args(args: NavArgs) -> Result<NavPlan> {
    // A value may come from the configuration file: its errors name it.
    match args.config.clone() {
        Some(config) => plan(args).with_context(|| format!("with --config {}", config.display())),
        None => plan(args),
    }
}

/// [`parse_nav_args`] itself.
fn plan(args: NavArgs) -> Result<NavPlan> {
    let cfg = match &args.config {
        Some(p) => load_config(p)?,
        None => NavConfig::default(),
    };
    let align_on = args.align || cfg.align.unwrap_or(false);
    let init = args.init.or(cfg.init).unwrap_or_default();
    // In motion the fixes give the position and the course (or the bank) the attitude.
    let in_motion = init != InitChoice::Given;
    if in_motion && align_on {
        bail!("--init gnss starts in motion; --align starts at rest: give one of them");
    }
    let input = args.input.clone().or(cfg.input.clone());
    let axes_given = input.imu_axes.is_some() || input.imu_rotation.is_some();
    let bag = args.bag.clone().or(cfg.bag_args());
    if bag.bag.is_some() {
        check_bag_input(&input)?;
        if args.imu.is_some() || cfg.imu.is_some() {
            bail!("an IMU log and a bag are both given (--imu or `imu`, --bag or `bag`): give one");
        }
    }
    let settings = NavSettings {
        imu: args
            .imu
            .clone()
            .or(cfg.imu.clone())
            .or(bag.bag.clone())
            .context(
                "no IMU log: give --imu FILE (or `imu = \"FILE\"` in the config) or --bag BAG",
            )?,
        read: read_options(&args, &cfg)?,
        init_pos: if in_motion {
            Geodetic::new(0.0, 0.0, 0.0)
        } else {
            init_pos(&args, &cfg)?
        },
        init_vel: Vector3::from(args.init_vel.or(cfg.init_vel).unwrap_or(Triple([0.0; 3])).0),
        init_att: init_att(&args, &cfg, align_on || in_motion)?,
        output_rate: rate("output-rate", args.output_rate.or(cfg.output_rate))?,
        out: args
            .out
            .clone()
            .or(cfg.out.clone())
            .unwrap_or_else(|| PathBuf::from(".")),
        earth: args
            .earth
            .or(cfg.earth)
            .unwrap_or_default()
            .with_gravity(args.gravity.or(cfg.gravity))
            .map_err(anyhow::Error::msg)?,
        week: args.week.or(cfg.week).unwrap_or(0),
        mechanization: mechanization_config(&args, &cfg)?,
        out_bag: bag
            .out_bag
            .clone()
            .map(|path| schuler_io::bag::output::OutBag {
                path,
                clock: Default::default(),
            }),
    };
    let alignment = args
        .alignment
        .clone()
        .or(cfg.alignment.clone().unwrap_or_default());
    let base = args
        .config
        .as_deref()
        .and_then(Path::parent)
        .unwrap_or(Path::new(""));
    let aiding = args
        .aiding
        .or(cfg.aiding.unwrap_or_default().relative_to(base));
    Ok(NavPlan {
        settings,
        align: align_on,
        init,
        alignment,
        aiding,
        axes_given,
        bag,
    })
}

/// The IMU input options that say how a text log is laid out have no meaning for a
/// bag (its messages say it): refused rather than ignored.
fn check_bag_input(input: &ImuInputOptions) -> Result<()> {
    for (given, flag) in [
        (input.imu_format.is_some(), "--imu-format"),
        (input.imu_layout.is_some(), "--imu-layout"),
        (input.imu_columns.is_some(), "--imu-columns"),
        (input.gyro_unit.is_some(), "--gyro-unit"),
        (input.accel_unit.is_some(), "--accel-unit"),
        (input.imu_time_unit.is_some(), "--imu-time-unit"),
        (input.imu_rate.is_some(), "--imu-rate"),
    ] {
        if given {
            bail!(
                "{flag} does not apply to --bag: sensor_msgs/Imu holds rates in rad/s and \
                 m/s^2 with header stamps"
            );
        }
    }
    Ok(())
}

/// A progress bar over the IMU file's bytes.
pub(crate) fn progress_bar(imu: &Path) -> ProgressBar {
    let total = std::fs::metadata(imu).map(|m| m.len()).unwrap_or(0);
    let bar = ProgressBar::with_draw_target(Some(total), indicatif::ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} navigating [{bar:40}] {percent:>3}% {bytes}/{total_bytes} eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// With `--align`: align on the log's first stages, print and write the result, and
/// return the start it gives and the samples after the alignment's end
/// ([`align_start`]).
fn align_first<I, E>(
    settings: &NavSettings,
    opts: &AlignOptions,
    reader: &mut I,
    aiding: Option<&mut Aiding>,
    bar: &ProgressBar,
) -> Result<(Start, Vec<ImuSample>)>
where
    I: Iterator<Item = Result<ImuSample, E>>,
    E: std::error::Error + Send + Sync + 'static,
{
    let (start, head, a) = align_start(settings, opts, reader, aiding)?;
    bar.suspend(|| print!("{}", crate::alignment::summary_text(&a, &[])));
    crate::alignment::write_outputs(&settings.out, &a)?;
    Ok((start, head))
}

/// The alignment of `--align` on the log's first stages: the start it gives (the
/// aligned state at the last aligned sample, its biases as the first estimates), the
/// samples after the alignment's end (the carrier of the start first) and the
/// alignment itself. With aiding, the filter's prior becomes the alignment's
/// ([`Prior::from_alignment`]).
pub fn align_start<I, E>(
    settings: &NavSettings,
    opts: &AlignOptions,
    reader: &mut I,
    aiding: Option<&mut Aiding>,
) -> Result<(Start, Vec<ImuSample>, schuler::align::Alignment)>
where
    I: Iterator<Item = Result<ImuSample, E>>,
    E: std::error::Error + Send + Sync + 'static,
{
    let (cfg, noise) = opts.resolve()?;
    let samples = crate::alignment::read_stage(reader, cfg.coarse + cfg.fine)?;
    let a = crate::alignment::align_on(settings.earth, settings.init_pos, &samples, &noise, &cfg)
        .with_context(|| format!("aligning {}", settings.imu.display()))?;
    if let Some(aiding) = aiding {
        let pos_std = aiding.filter.integration.init_pos_std;
        aiding.filter = Prior::from_alignment(&a, pos_std).apply_to(aiding.filter);
    }
    let carrier = samples
        .partition_point(|s| s.t <= a.t_end + 1e-9)
        .saturating_sub(1);
    Ok((Start::from_alignment(&a), samples[carrier..].to_vec(), a))
}

/// With `--init gnss` or `gnss-any-heading`: the start in motion from the fixes
/// ([`motion_start`]), printed. Returns the start and the samples from its carrier on.
fn start_from_fixes<I, E>(
    settings: &NavSettings,
    reader: &mut I,
    mut aiding: Option<&mut Aiding>,
    init: InitChoice,
) -> Result<(Start, Vec<ImuSample>)>
where
    I: Iterator<Item = Result<ImuSample, E>>,
    E: std::error::Error + Send + Sync + 'static,
{
    let (start, head, m) = motion_start(settings, reader, aiding.as_deref_mut(), init)?;
    let fixes = aiding.map(|a| &a.fixes);
    let e = m.state.euler();
    let heading = match init {
        InitChoice::Gnss => format!(
            "heading {:.2} ± {:.2} deg (the course: forward motion along the IMU's x axis assumed)",
            e.heading_0_2pi().to_degrees(),
            m.att_std.z.to_degrees()
        ),
        _ => format!("heading unknown: a bank of {BANK_MEMBERS} filters searches it"),
    };
    let fix_t = |i: usize| {
        fixes
            .and_then(|f| f.iter().nth(i))
            .map_or(f64::NAN, |f| f.t)
    };
    println!(
        "started in motion at t = {} s from the fixes at {} and {} s: {:.2} m/s, {heading}, roll {:.2} pitch {:.2} ± {:.2} deg",
        m.state.t,
        fix_t(m.fixes.0),
        fix_t(m.fixes.1),
        m.speed,
        e.roll.to_degrees(),
        e.pitch.to_degrees(),
        m.att_std.x.to_degrees()
    );
    Ok((start, head))
}

/// The start in motion of `--init gnss` or `gnss-any-heading` from the fixes and the
/// IMU samples up to just past the fix it starts at ([`schuler::align::in_motion`]:
/// the course's first long straight chord, or without a heading the first fix two
/// seconds into the log); the filter's prior becomes its standard deviations.
/// Returns the start, the samples from its carrier on, and the start's details.
pub fn motion_start<I, E>(
    settings: &NavSettings,
    reader: &mut I,
    aiding: Option<&mut Aiding>,
    init: InitChoice,
) -> Result<(
    Start,
    Vec<ImuSample>,
    schuler::align::in_motion::InMotionStart,
)>
where
    I: Iterator<Item = Result<ImuSample, E>>,
    E: std::error::Error + Send + Sync + 'static,
{
    use schuler::align::in_motion::{
        InMotionConfig, VELOCITY_SPAN, course_pair, start_at_fix, start_in_motion,
    };
    let Some(aiding) = aiding.filter(|a| !a.fixes.is_empty()) else {
        bail!("--init {init:?} needs GNSS fixes (--gnss FILE)");
    };
    let all = aiding.fixes.to_vec()?;
    let (cfg, earth, fixes) = (InMotionConfig::default(), Wgs84, &all);
    let context = || format!("--init gnss: {}", settings.imu.display());
    let first = match reader.next() {
        Some(s) => s?,
        None => bail!(
            "{}: no IMU sample in the requested time window",
            settings.imu.display()
        ),
    };
    let i0 = fixes.partition_point(|f| f.t < first.t);
    let j = match init {
        InitChoice::Gnss => course_pair(&earth, fixes, &cfg).with_context(context)?.1,
        _ => i0 + fixes[i0..].partition_point(|f| f.t < first.t + VELOCITY_SPAN),
    };
    let Some(fix) = fixes.get(j) else {
        bail!("{}: no GNSS fix two seconds into the IMU data", context());
    };
    let mut samples = vec![first];
    let until = fix.t + cfg.settle + cfg.level_window;
    samples.extend(crate::alignment::read_stage(
        reader,
        (until - first.t).max(0.0),
    )?);
    let m = match init {
        InitChoice::Gnss => start_in_motion(&earth, &samples, fixes, &cfg),
        _ => start_at_fix(&earth, &samples, fixes, i0, j, &cfg),
    }
    .with_context(context)?;
    let filter = &mut aiding.filter;
    *filter = Prior::from_motion(&m).apply_to(*filter);
    let head = samples[m.sample..].to_vec();
    Ok((Start::from_motion(&m), head, m))
}

/// Members of the heading bank of `--init gnss-any-heading` (every 30°).
pub const BANK_MEMBERS: usize = 12;

/// Longest the heading bank runs before it keeps its most likely member [s] (it
/// decides earlier once the data tell the headings apart).
pub const BANK_SECONDS: f64 = 600.0;

/// What a run starts from: the settings, the aiding, the start, and whether the
/// heading is searched by the bank.
struct Begin<'a> {
    settings: &'a NavSettings,
    aiding: Option<&'a Aiding>,
    start: Start,
    any_heading: bool,
}

impl Begin<'_> {
    /// Navigate on the settings' Earth model: from the start, or through the heading
    /// bank (printing its choice).
    fn navigate<I, E>(&self, samples: I, on_sample: impl FnMut(u64)) -> Result<RunSummary>
    where
        I: Iterator<Item = Result<ImuSample, E>>,
        E: std::error::Error + Send + Sync + 'static,
    {
        match self.settings.earth {
            EarthChoice::Wgs84 => self.navigate_on(Wgs84, samples, on_sample),
            EarthChoice::Wgs84Series => self.navigate_on(Wgs84Series, samples, on_sample),
            EarthChoice::Sphere | EarthChoice::SphereFixed => {
                let rotating = self.settings.earth == EarthChoice::Sphere;
                self.navigate_on(Sphere::textbook(rotating), samples, on_sample)
            }
        }
    }

    /// [`Begin::navigate`] on `earth`.
    fn navigate_on<M: schuler::earth::EarthModel, I, E>(
        &self,
        earth: M,
        samples: I,
        on_sample: impl FnMut(u64),
    ) -> Result<RunSummary>
    where
        I: Iterator<Item = Result<ImuSample, E>>,
        E: std::error::Error + Send + Sync + 'static,
    {
        let (settings, start) = (self.settings, self.start);
        match (self.aiding, self.any_heading) {
            (Some(a), true) => {
                let (summary, yaw0, decided) = crate::navigate::navigate_any_heading(
                    earth,
                    settings,
                    a,
                    start,
                    BANK_MEMBERS,
                    BANK_SECONDS,
                    samples,
                    on_sample,
                )?;
                println!(
                    "heading bank: kept the filter started at {:.0} deg, decided at t = {decided} s",
                    yaw0.to_degrees().rem_euclid(360.0)
                );
                Ok(summary)
            }
            _ => navigate(earth, settings, self.aiding, start, samples, on_sample),
        }
    }
}

/// The filter's IMU grade: `--imu-grade`, else navigation grade for alignment
/// (gyrocompassing needs it) but tactical for the filter (`aided`): an optimistic
/// noise model makes the gate refuse good fixes, a pessimistic one only costs a
/// little accuracy.
fn grade(alignment: &AlignOptions, aided: bool) -> GradeChoice {
    alignment.imu_grade.unwrap_or(if aided {
        GradeChoice::Tactical
    } else {
        GradeChoice::Navigation
    })
}

/// The filter's IMU grade of a plan ([`grade`]).
pub(crate) fn filter_grade(plan: &NavPlan) -> GradeChoice {
    grade(&plan.alignment, plan.aiding.any())
}

/// The run's aiding, if any: the options resolved (files read, or the `given`
/// readings) with the noise model of `--imu-grade`.
pub fn resolve_aiding(
    alignment: &AlignOptions,
    aiding: &AidingOptions,
    given: GivenReadings,
) -> Result<Option<Aiding>> {
    let noise = grade(alignment, aiding.any() || given.any()).noise()?;
    aiding.resolve_with(noise, given)
}

/// The run from an open IMU source: the start (given, aligned at rest, or from the
/// fixes in motion), then the samples navigated and written; `on_sample` as in
/// [`navigate`].
pub(crate) fn navigate_samples<I, E>(
    plan: &NavPlan,
    aiding: &mut Option<Aiding>,
    reader: &mut I,
    bar: &ProgressBar,
    on_sample: impl FnMut(u64),
) -> Result<RunSummary>
where
    I: Iterator<Item = Result<ImuSample, E>>,
    E: std::error::Error + Send + Sync + 'static,
{
    let settings = &plan.settings;
    let (start, head) = match (plan.align, plan.init) {
        (true, _) => align_first(settings, &plan.alignment, reader, aiding.as_mut(), bar)?,
        (false, InitChoice::Given) => (settings.start(), Vec::new()),
        (false, init) => start_from_fixes(settings, reader, aiding.as_mut(), init)?,
    };
    let samples = head.into_iter().map(Ok).chain(reader);
    let begin = Begin {
        settings,
        aiding: aiding.as_ref(),
        start,
        any_heading: plan.init == InitChoice::GnssAnyHeading,
    };
    begin.navigate(samples, on_sample)
}

/// The run's summary on stdout (aided or free-inertial), `secs` its wall time.
pub(crate) fn print_summary(
    plan: &NavPlan,
    aiding: Option<&Aiding>,
    summary: &RunSummary,
    secs: f64,
) -> Result<()> {
    match aiding {
        Some(a) => {
            if plan.init != InitChoice::Given {
                print_heading_settled(summary);
            }
            print_aided(&plan.settings, a, summary, secs)
        }
        None => {
            print_free(&plan.settings, summary, secs);
            Ok(())
        }
    }
}

/// `schuler nav` on an IMU log (`--kf-gins-config` is dispatched before, by
/// [`crate::commands::run_nav`]; `--bag` goes to [`crate::bag_input::run`]).
pub fn run(args: NavArgs) -> Result<()> {
    let plan = parse_nav_args(args)?;
    if plan.bag.bag.is_some() {
        return crate::bag_input::run(plan);
    }
    let mut aiding: Option<Aiding> = plan.aiding.resolve(filter_grade(&plan).noise()?)?;
    let settings = &plan.settings;
    let started = Instant::now();
    let reader = ImuReader::open(&settings.imu, &settings.read)?;
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
    let bar = progress_bar(&settings.imu);
    let progress = reader.progress();
    let on_sample = |_| bar.set_position(progress.bytes());
    // Read and parsed on a second thread, overlapping the navigation.
    let mut reader = reader.read_ahead()?;
    let summary = navigate_samples(&plan, &mut aiding, &mut reader, &bar, on_sample)?;
    bar.set_position(progress.bytes());
    bar.finish_and_clear();
    let secs = started.elapsed().as_secs_f64();
    if aiding.is_none() {
        let report = reader.gaps();
        if !report.is_empty() {
            eprintln!("warning: {}: {report}", settings.imu.display());
        }
    }
    print_summary(&plan, aiding.as_ref(), &summary, secs)
}

/// The aided run's summary on stdout (and its outage test).
fn print_aided(
    settings: &NavSettings,
    aiding: &Aiding,
    summary: &RunSummary,
    secs: f64,
) -> Result<()> {
    let c = summary.nav.counts;
    println!(
        "integrated {} samples with {} GNSS fixes in {:.2} s: {} position and {} velocity updates, {} rejected by the gate, {} outside the IMU data (see rejected.csv); mean NIS per dimension {:.2}",
        summary.nav.samples,
        aiding.fixes.len(),
        secs,
        c.position,
        c.velocity,
        c.rejected,
        c.skipped,
        summary.nav.mean_nis_per_dof
    );
    print_handovers(&summary.nav);
    print!("{}", summary.report_text);
    if let Some(line) = crate::aided::vehicle::summary(&c) {
        println!("{line}");
    }
    if let Some((mount, [sp, sy])) = summary.nav.mounting {
        let e = schuler::rotation::Euler::from_quaternion(&mount.q_vb);
        println!(
            "mounting estimated: the vehicle frame's roll {:.3}, pitch {:.3} ± {:.3}, yaw {:.3} ± {:.3} deg relative to the IMU (use as --mounting-angles)",
            e.roll.to_degrees(),
            e.pitch.to_degrees(),
            sp.to_degrees(),
            e.yaw.to_degrees(),
            sy.to_degrees()
        );
    }
    if let Some(test) = &aiding.outage_test {
        crate::aided::report_outage_test(
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
    let nis = summary.nav.mean_nis_per_dof;
    let wrote = format!(
        "wrote {} epochs to {} (and nav.csv, std.txt, imu_err.txt, rejected.csv)",
        summary.epochs,
        settings.out.join("nav.txt").display()
    );
    if c.rejected * 2 > tried && nis > INCONSISTENT_NIS_PER_DOF {
        println!("{wrote}");
        bail!(
            "the filter disagrees with its measurements: the gate refused {} of {tried} and the \
             mean NIS per dimension is {nis:.0} (a consistent filter gives 1): its solution and \
             the standard deviations it reports are not to be trusted. The IMU data do not move \
             as the aids do: gyro or accelerometer columns swapped or dead, axes mounted \
             otherwise (--imu-axes, --imu-columns), wrong units, or a far too optimistic noise \
             model (--imu-grade)",
            c.rejected
        );
    }
    if c.rejected * 10 > tried {
        eprintln!(
            "warning: the gate refused {} of {} measurements (see rejected.csv): the IMU noise model is probably too optimistic for this sensor (--imu-grade, --arw, --gyro-bias-std, ...)",
            c.rejected, tried
        );
    }
    println!("{wrote}");
    Ok(())
}

/// Mean NIS per dimension beyond which, with most measurements refused, a run is
/// reported as failed: 100 is 10 standard deviations per dimension on average, where a
/// consistent filter gives 1 and a noise model optimistic by a factor of 3 gives 9.
const INCONSISTENT_NIS_PER_DOF: f64 = 100.0;

/// When the heading of a start in motion converged (its standard deviation below 1°).
fn print_heading_settled(summary: &RunSummary) {
    let t0 = summary.nav.t_first;
    match summary.heading_settled {
        Some((t, yaw)) => println!(
            "heading converged (std below 1 deg) at t = {t} s, {:.1} s after the start: {:.3} deg",
            t - t0,
            yaw.to_degrees()
        ),
        None => println!(
            "heading did not converge below 1 deg std (turns and accelerations make it observable)"
        ),
    }
}

/// The hand-overs between mechanizations, one line each.
fn print_handovers(s: &schuler::session::Summary) {
    for h in &s.handovers {
        println!(
            "  hand-over to {} at t = {} s, lat {:.6} deg",
            h.to,
            h.t,
            h.lat.to_degrees()
        );
    }
}

/// The free-inertial run's summary on stdout.
fn print_free(settings: &NavSettings, summary: &RunSummary, secs: f64) {
    let s = &summary.nav;
    println!("mechanization: {} from the start", s.first_mechanization);
    print_handovers(s);
    let last = s.last.normalized();
    let e = last.euler();
    println!(
        "navigated {} samples, t = {} .. {} s ({:.1} s of data) in {:.2} s ({:.2} M samples/s)",
        s.samples,
        s.t_first,
        s.t_last,
        s.t_last - s.t_first,
        secs,
        s.samples as f64 / secs / 1e6
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
}
