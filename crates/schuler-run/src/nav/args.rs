//! The description of a navigation run: `schuler nav`'s flags, and the same options
//! as keys of a TOML configuration file (`--config`), one name for each.

use crate::aided::AidingOptions;
use crate::alignment::AlignOptions;
use crate::bag_input::BagArgs;
use crate::flat_options::{keys_of, partition, read_group, unknown_option};
use crate::imu_input::ImuInputOptions;
use crate::log_input::LogArgs;
use crate::options::{EarthChoice, GravityChoice, MechanizationChoice, Triple};
use anyhow::{Context, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};

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
    /// ROS bags: `--bag` as the input (ROS 1 or 2), `--out-bag` for the result.
    #[command(flatten)]
    pub bag: BagArgs,
    /// Device logs: `--log` as the input (ULog, UBX, GnssLogger, DataFlash, bags).
    #[command(flatten)]
    pub log: LogArgs,
}

/// The same options as data: a TOML file's keys ([`load_config`]; alignment options in
/// its `[alignment]` table, aiding options in `[aiding]`) or flat options by name
/// ([`NavConfig::from_options`]: Python's keyword arguments).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NavConfig {
    pub(crate) imu: Option<PathBuf>,
    pub(crate) init_pos: Option<Triple>,
    pub(crate) init_vel: Option<Triple>,
    pub(crate) init_att: Option<Triple>,
    pub(crate) start: Option<f64>,
    pub(crate) end: Option<f64>,
    pub(crate) output_rate: Option<f64>,
    pub(crate) out: Option<PathBuf>,
    pub(crate) earth: Option<EarthChoice>,
    pub(crate) gravity: Option<GravityChoice>,
    pub(crate) week: Option<u32>,
    pub(crate) mechanization: Option<MechanizationChoice>,
    pub(crate) auto_latitude: Option<f64>,
    pub(crate) auto_hysteresis: Option<f64>,
    pub(crate) align: Option<bool>,
    pub(crate) init: Option<InitChoice>,
    pub(crate) alignment: Option<AlignOptions>,
    pub(crate) aiding: Option<AidingOptions>,
    pub(crate) bag: Option<PathBuf>,
    pub(crate) imu_topic: Option<String>,
    pub(crate) gnss_topic: Option<String>,
    pub(crate) gnss_vel_topic: Option<String>,
    pub(crate) baro_topic: Option<String>,
    pub(crate) odom_topic: Option<String>,
    pub(crate) base_frame: Option<String>,
    pub(crate) out_bag: Option<PathBuf>,
    pub(crate) leap_seconds: Option<i64>,
    pub(crate) log: Option<PathBuf>,
    pub(crate) imu_stream: Option<String>,
    pub(crate) gnss_stream: Option<String>,
    /// The IMU input keys, read apart ([`ImuInputOptions::split_config`]).
    #[serde(skip)]
    pub(crate) input: ImuInputOptions,
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

pub(super) fn load_config(path: &Path) -> Result<NavConfig> {
    let text = schuler_io::formats::read_config_text(path)?;
    let (mut cfg, input): (NavConfig, _) =
        ImuInputOptions::split_config(&text).with_context(|| format!("in {}", path.display()))?;
    cfg.input = input;
    let base = path.parent().unwrap_or(Path::new(""));
    let paths = [
        &mut cfg.imu,
        &mut cfg.out,
        &mut cfg.bag,
        &mut cfg.out_bag,
        &mut cfg.log,
    ];
    for p in paths.into_iter().flatten() {
        if p.is_relative() {
            *p = base.join(&*p);
        }
    }
    Ok(cfg)
}

impl NavConfig {
    /// A run described by flat options, each the name of a flag with underscores
    /// (`lever_arm`, `imu_grade`, `gnss`): each goes to the group that owns it and is
    /// read by serde, so that a misspelt name or a bad value is refused naming the
    /// option. Paths are taken as given (relative to the working directory).
    pub fn from_options(options: toml::Table) -> Result<Self> {
        let input_keys = ImuInputOptions::keys();
        let align_keys = keys_of::<AlignOptions>();
        let aid_keys = keys_of::<AidingOptions>();
        let (groups, top) = partition(options, &[&input_keys, &align_keys, &aid_keys]);
        let known = keys_of::<NavArgs>();
        if let Some(k) = top.keys().find(|k| !known.contains(k)) {
            return Err(unknown_option(k, &known));
        }
        let [input, alignment, aiding] = <[toml::Table; 3]>::try_from(groups)
            .map_err(|_| anyhow::anyhow!("three option groups"))?;
        Ok(Self {
            input: read_group(input)?,
            alignment: Some(read_group(alignment)?),
            aiding: Some(read_group(aiding)?),
            ..read_group(top)?
        })
    }

    /// The bag keys (paths already relative to the file's folder).
    pub(super) fn bag_args(&self) -> BagArgs {
        BagArgs {
            bag: self.bag.clone(),
            imu_topic: self.imu_topic.clone(),
            gnss_topic: self.gnss_topic.clone(),
            gnss_vel_topic: self.gnss_vel_topic.clone(),
            baro_topic: self.baro_topic.clone(),
            odom_topic: self.odom_topic.clone(),
            base_frame: self.base_frame.clone(),
            out_bag: self.out_bag.clone(),
            leap_seconds: self.leap_seconds,
        }
    }

    /// The device-log keys (the path already relative to the file's folder).
    pub(super) fn log_args(&self) -> LogArgs {
        LogArgs {
            log: self.log.clone(),
            imu_stream: self.imu_stream.clone(),
            gnss_stream: self.gnss_stream.clone(),
        }
    }
}
