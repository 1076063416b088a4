//! Aiding of `schuler nav` (`--gnss`, `--baro`, vehicle aids): the options as written
//! ([`AidingOptions`], flags or a `[aiding]` table), checked and loaded into an
//! [`Aiding`]: the session's filter configuration and the readings the run pushes as
//! aids. [`report`] writes the consistency report, [`record`] `innovations.csv`,
//! [`vehicle`] resolves the vehicle aids.

pub mod calibration;
pub mod feed;
pub mod fixes;
pub mod raw_gnss;
pub mod record;
pub mod refusals;
pub mod report;
pub mod series;
pub mod spilled;
pub mod vehicle;

use crate::options::{Triple, or_zero, quantity, quantity_in};
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use report::ReportSettings;
use schuler::domain as d;
use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig, SensorEstimates};
use schuler::session::{ErrorModelChoice, FilterConfig};
use schuler::units::{Dimension, parse_as_or_si};
use schuler_io::formats::gnss::{GnssFormat, GnssQuality, GnssReadOptions, read_gnss_log};
use std::path::{Path, PathBuf};
use vehicle::VehicleReadings;

/// File names of an aided run's outputs, and which of them it writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputNames {
    /// Navigation result (KF-GINS text).
    pub nav: &'static str,
    /// Standard deviations.
    pub std: &'static str,
    /// Sensor errors.
    pub imu_err: &'static str,
    /// Whether `nav.csv` is written beside the navigation result.
    pub nav_csv: bool,
    /// Whether the filter's diagnostics are written: `innovations.csv`,
    /// `rejected.csv`, `consistency.json` and the report (if its settings ask).
    pub diagnostics: bool,
    /// Whether the start state is the first epoch written (KF-GINS writes its first
    /// row one sample after the start).
    pub start_epoch: bool,
}

impl OutputNames {
    /// schuler's own names, every output.
    pub const SCHULER: OutputNames = OutputNames {
        nav: "nav.txt",
        std: "std.txt",
        imu_err: "imu_err.txt",
        nav_csv: true,
        diagnostics: true,
        start_epoch: true,
    };
    /// KF-GINS's names, and only KF-GINS's three files, from one sample after the
    /// start (as KF-GINS writes them).
    pub const KF_GINS: OutputNames = OutputNames {
        nav: "KF_GINS_Navresult.nav",
        std: "KF_GINS_STD.txt",
        imu_err: "KF_GINS_IMU_ERR.txt",
        nav_csv: false,
        diagnostics: false,
        start_epoch: false,
    };
}

/// Barometer readings `(t, h)` and the `(noise, bias prior)` standard deviations [m].
type BaroInput = (Vec<(f64, f64)>, Option<(f64, f64)>);

/// What aiding a run has: the filter and the readings pushed as aids.
#[derive(Debug, Clone)]
pub struct Aiding {
    /// GNSS fixes in time order (spilled: bounded memory).
    pub fixes: fixes::Fixes,
    /// The session's filter (noise, prior, gate, barometer, smoother, vehicle aids).
    pub filter: FilterConfig,
    /// Output file names.
    pub names: OutputNames,
    /// Sensor errors known at the start (removed from the first sample on).
    pub initial_errors: SensorEstimates,
    /// Test outages (GNSS removed inside), with the truth to report against.
    pub outage_test: Option<OutageTest>,
    /// Barometer readings `(t, h)`.
    pub baro: Vec<(f64, f64)>,
    /// The report: whether to write `report.html`, and the truths it compares with.
    pub report: ReportSettings,
    /// Rest intervals, odometer and heading readings.
    pub vehicle: VehicleReadings,
    /// Raw GNSS for tight coupling (`--gnss-obs`).
    pub raw: Option<raw_gnss::RawGnss>,
    /// The time offset added to the GNSS times as they were read [s]
    /// (`--gnss-time-offset`).
    pub gnss_time_shift: f64,
}

/// Aiding readings held in memory, in place of the files of `--gnss`, `--baro` and the
/// vehicle aids.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GivenReadings {
    /// GNSS fixes in time order.
    pub fixes: Option<Vec<GnssFix>>,
    /// Barometer readings `(t, h)` [s, m].
    pub baro: Option<Vec<(f64, f64)>>,
    /// Rest intervals, odometer and heading readings.
    pub vehicle: vehicle::GivenVehicle,
}

impl GivenReadings {
    /// Whether any readings are given.
    pub fn any(&self) -> bool {
        self.fixes.is_some() || self.baro.is_some() || self.vehicle.any()
    }
}

/// The outage test of `--outage-test`.
#[derive(Debug, Clone, PartialEq)]
pub struct OutageTest {
    /// The outages [s].
    pub windows: Vec<(f64, f64)>,
    /// Truth to report the errors against.
    pub truth: Option<PathBuf>,
}

/// The aiding options of `schuler nav`, as written (flags, or a `[aiding]` table in
/// the TOML config).
#[derive(clap::Args, Debug, Default, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AidingOptions {
    /// GNSS position log: KF-GINS text (t lat lon h [std_n std_e std_d [vn ve vd
    /// std_vn std_ve std_vd]], whose velocities are then used), CSV whose header names
    /// t,lat_deg,lon_deg,h_m[,std_n_m,std_e_m,std_d_m] (as `schuler simulate`'s gnss.csv;
    /// its velocity columns are used only through --gnss-vel, its outlier flag never),
    /// an NMEA 0183 log (GGA, RMC, VTG, GST) or an RTKLIB solution (.pos); told by the
    /// content or by --gnss-format.
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub gnss: Option<PathBuf>,
    /// Format of --gnss (default auto: NMEA sentences, an RTKLIB `%` column header, else
    /// text).
    #[arg(long, value_name = "FORMAT", value_parser = crate::options::named::<GnssFormat>())]
    pub gnss_format: Option<GnssFormat>,
    /// Position standard deviations north, east, down [m] for GNSS fixes whose file
    /// gives none (4-column text, CSV without std columns, NMEA without GST, RTKLIB
    /// without or with zero sdn sde sdu).
    #[arg(long, allow_hyphen_values = true, value_name = "N,E,D")]
    pub gnss_std: Option<Triple>,
    /// Drop NMEA and RTKLIB fixes of a lower quality: single (default, all kept),
    /// dgps, float (PPP too) or fix.
    #[arg(long, value_name = "QUALITY", value_parser = crate::options::named::<GnssQuality>())]
    pub gnss_min_quality: Option<GnssQuality>,
    /// Added to every GNSS time after reading (e.g. `-18 s` to put GPS seconds of week
    /// onto an IMU clock in UTC; NMEA and RTKLIB times are GPS seconds of week, NMEA
    /// without a date UTC seconds of day).
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub gnss_time_offset: Option<String>,
    /// GNSS velocity log matched to the fixes by time: text t vn ve vd [std_vn std_ve
    /// std_vd] or CSV naming t,vn_mps,ve_mps,vd_mps[,std_vn_mps,...] (gnss.csv too); a
    /// position log given here is an error.
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub gnss_vel: Option<PathBuf>,
    /// Velocity standard deviation where the velocity log, or a position log's velocity
    /// (NMEA speed and course, RTKLIB vn ve vu), gives none (default 0.1 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub gnss_vel_std: Option<String>,
    /// RINEX observation file (2.xx, 3.0x, 4.0x; gzip or Hatanaka): tight coupling,
    /// each pseudorange and Doppler a measurement of the filter, whose state gains the
    /// receiver clock (needs --gnss-nav; not with --gnss).
    #[arg(long, allow_hyphen_values = true, value_name = "OBS")]
    pub gnss_obs: Option<PathBuf>,
    /// RINEX navigation file(s) of broadcast ephemerides for --gnss-obs (repeat for
    /// several).
    #[arg(long, allow_hyphen_values = true, value_name = "NAV")]
    #[serde(default)]
    pub gnss_nav: Vec<PathBuf>,
    /// Elevation mask of --gnss-obs [deg] (default 10).
    #[arg(long, allow_hyphen_values = true, value_name = "DEG")]
    pub elevation_mask: Option<f64>,
    /// Systems of --gnss-obs used, by RINEX letter (`G,E,C,J`; default every one with
    /// ephemerides).
    #[arg(long, value_delimiter = ',', value_name = "G,E,C")]
    #[serde(default)]
    pub gnss_systems: Vec<char>,
    /// Antenna position in body axes, front, right, down [m].
    #[arg(
        long,
        allow_hyphen_values = true,
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub lever_arm: Option<Triple>,
    /// Estimate the antenna lever arm as filter states, from --lever-arm (or zero),
    /// prior standard deviation per axis (e.g. `0.5 m`; the flag alone: 1 m). The run
    /// says which axes the motion observed and prints the flags to use next time.
    #[arg(long, value_name = "LENGTH", num_args = 0..=1, default_missing_value = "1 m")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub estimate_lever_arm: Option<String>,
    /// Estimate the time offset of the GNSS stamps from the IMU's clock (GNSS time +
    /// offset = IMU time) as a filter state, from --gnss-time-offset (or zero), prior
    /// standard deviation (e.g. `2 s`; the flag alone: 0.5 s).
    #[arg(long, value_name = "TIME", num_args = 0..=1, default_missing_value = "0.5 s")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub estimate_gnss_time_offset: Option<String>,
    /// Random-walk density of the estimated time offset [s/sqrt(s)], for a drifting
    /// clock (default 0: a constant offset).
    #[arg(long, value_name = "DENSITY")]
    pub gnss_time_offset_walk: Option<f64>,
    /// Innovation gate: significance level of the chi-square test (default 1e-4; 0
    /// turns the gate off).
    #[arg(long, allow_hyphen_values = true, value_name = "ALPHA")]
    pub gate: Option<f64>,
    /// Estimate gyro and accelerometer scale factors (21 states).
    #[arg(long)]
    #[serde(default)]
    pub scale_factors: bool,
    /// The filter's error model: psi15 (default; psi21 with --scale-factors), psi21 or
    /// seed18, the flight-test paper's 18 states (needs --mechanization wander; GNSS
    /// position and velocity only, no lever arm, no smoother).
    #[arg(long, value_name = "MODEL")]
    pub error_model: Option<crate::options::ErrorModelArg>,
    /// Also write the Rauch–Tung–Striebel smoothed trajectory (forward-backward) at
    /// the output rate into `OUT/smoothed/` (the forward result stays in `OUT/`).
    #[arg(long)]
    #[serde(default)]
    pub smooth: bool,
    /// Angle random walk (e.g. `0.1 deg/sqrt(h)`; default from --imu-grade).
    #[arg(long, allow_hyphen_values = true, value_name = "ARW")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub arw: Option<String>,
    /// Velocity random walk (e.g. `0.08 m/s/sqrt(h)`).
    #[arg(long, allow_hyphen_values = true, value_name = "VRW")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub vrw: Option<String>,
    /// Gyro bias standard deviation (e.g. `2 deg/h`).
    #[arg(long, allow_hyphen_values = true, value_name = "RATE")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub gyro_bias_std: Option<String>,
    /// Accelerometer bias standard deviation (e.g. `300 mGal`).
    #[arg(long, allow_hyphen_values = true, value_name = "ACCEL")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub accel_bias_std: Option<String>,
    /// Gyro scale-factor standard deviation (e.g. `1000 ppm`; with --scale-factors).
    #[arg(long, allow_hyphen_values = true, value_name = "RATIO")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub gyro_scale_std: Option<String>,
    /// Accelerometer scale-factor standard deviation.
    #[arg(long, allow_hyphen_values = true, value_name = "RATIO")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub accel_scale_std: Option<String>,
    /// Bias instability (Gauss–Markov std, e.g. `0.2 deg/h` and `2e-4 m/s^2`) with
    /// --bias-corr-time: sets the bias random walk.
    #[arg(long, allow_hyphen_values = true, value_name = "RATE")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub gyro_bias_instability: Option<String>,
    /// Accelerometer bias instability.
    #[arg(long, allow_hyphen_values = true, value_name = "ACCEL")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub accel_bias_instability: Option<String>,
    /// Correlation time of the bias instability (default 1 h); given, the biases are
    /// modelled as first-order Gauss–Markov processes, otherwise as random walks.
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub bias_corr_time: Option<String>,
    /// Gyro rate random walk (e.g. `0.01 deg/h/sqrt(h)`): added in quadrature to the
    /// gyro bias's driving noise (the instability's, or --imu-grade's).
    #[arg(long, allow_hyphen_values = true, value_name = "RRW")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub rate_random_walk: Option<String>,
    /// Accelerometer acceleration random walk (e.g. `10 ug/sqrt(h)`), likewise.
    #[arg(long, allow_hyphen_values = true, value_name = "ARW")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub acceleration_random_walk: Option<String>,
    /// Initial position standard deviation north, east, down [m] (default 1,1,1).
    #[arg(long, allow_hyphen_values = true, value_name = "N,E,D")]
    pub init_pos_std: Option<Triple>,
    /// Initial velocity standard deviation [m/s] (default 0.1,0.1,0.1).
    #[arg(long, allow_hyphen_values = true, value_name = "N,E,D")]
    pub init_vel_std: Option<Triple>,
    /// Initial attitude standard deviation roll, pitch, yaw [deg] (default 0.1,0.1,0.5).
    #[arg(long, allow_hyphen_values = true, value_name = "R,P,Y")]
    pub init_att_std: Option<Triple>,
    /// Barometer log (`baro.csv` of `schuler simulate`: t,h_m; or `t h` rows): height
    /// aiding with a bias state.
    #[arg(long, value_name = "FILE")]
    pub baro: Option<PathBuf>,
    /// Barometer noise standard deviation (default 0.5 m).
    #[arg(long, allow_hyphen_values = true, value_name = "LENGTH")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub baro_std: Option<String>,
    /// Prior standard deviation of the barometer bias (default 10 m).
    #[arg(long, allow_hyphen_values = true, value_name = "LENGTH")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub baro_bias_std: Option<String>,
    /// Outage test: remove GNSS for LEN every PERIOD (e.g. `60s/180s`), the first
    /// outage starting at --outage-start (default: one PERIOD after the first fix);
    /// with --truth, report the errors at the end of and inside each outage.
    #[arg(long, allow_hyphen_values = true, value_name = "LEN/PERIOD")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub outage_test: Option<String>,
    /// Start of the first test outage [s, the log's clock].
    #[arg(long, allow_hyphen_values = true, value_name = "SOW")]
    pub outage_start: Option<f64>,
    /// Truth (KF-GINS navigation text or schuler CSV): the report's position errors
    /// and NEES, and the outage test's errors.
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub truth: Option<PathBuf>,
    /// Truth of the sensor errors for the report, in imu_err.txt's layout (`t`, gyro
    /// bias [deg/h], accelerometer bias [mGal], optionally scale factors [ppm]).
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub sensor_truth: Option<PathBuf>,
    /// Do not write report.html and report/ (innovations.csv and consistency.json are
    /// always written).
    #[arg(long)]
    #[serde(default)]
    pub no_report: bool,
    /// Longest covariance propagation step (default 1 s; the covariance is always
    /// propagated to each measurement's time).
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub propagation_interval: Option<String>,
    /// Zero-velocity updates inside the rest intervals of FILE (`t0 t1` per line).
    #[arg(
        long,
        allow_hyphen_values = true,
        value_name = "FILE",
        conflicts_with = "zupt_detect"
    )]
    pub zupt: Option<PathBuf>,
    /// Zero-velocity updates where the IMU data look at rest (the alignment's motion
    /// detector on a 1-s window, specific force against gravity, rate against the
    /// Earth's) and the navigation's speed is below --zupt-max-speed.
    #[arg(long)]
    #[serde(default)]
    pub zupt_detect: bool,
    /// Zero-velocity standard deviation (default 0.02 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub zupt_std: Option<String>,
    /// Time between zero-velocity updates at rest, and the detector's block
    /// (default 0.1 s; the detector's window is ten blocks).
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub zupt_interval: Option<String>,
    /// --zupt-detect: no update while the navigation's speed exceeds this (an IMU
    /// cannot tell rest from constant velocity; default 0.5 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub zupt_max_speed: Option<String>,
    /// With each zero-velocity update, a zero-angular-rate update on the gyro biases
    /// (the body turns with the Earth only).
    #[arg(long)]
    #[serde(default)]
    pub zaru: bool,
    /// Standard deviation of the rate averaged over --zupt-interval (default: the angle
    /// random walk over that time, ARW/sqrt(interval)).
    #[arg(long, allow_hyphen_values = true, value_name = "RATE")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub zaru_std: Option<String>,
    /// Non-holonomic constraint of a land vehicle: no lateral or vertical velocity of
    /// the vehicle frame at --vehicle-lever-arm.
    #[arg(long)]
    #[serde(default)]
    pub nhc: bool,
    /// NHC standard deviation (default 0.1 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub nhc_std: Option<String>,
    /// Time between NHC updates (default 0.1 s).
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub nhc_interval: Option<String>,
    /// Odometer log (`t speed` per line, forward speed in m/s at --vehicle-lever-arm).
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub odometer: Option<PathBuf>,
    /// Odometer speed standard deviation (default 0.05 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub odometer_std: Option<String>,
    /// Estimate the odometer's scale factor with this prior standard deviation (e.g.
    /// `1 %`).
    #[arg(long, allow_hyphen_values = true, value_name = "RATIO")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub odometer_scale_std: Option<String>,
    /// Mounting angles: the vehicle frame's roll, pitch, yaw relative to the IMU body
    /// [deg] (0,0,0 when the IMU's axes are the vehicle's front, right, down).
    #[arg(long, allow_hyphen_values = true, value_name = "R,P,Y")]
    pub mounting_angles: Option<Triple>,
    /// Estimate the vehicle frame's pitch and yaw relative to --mounting-angles as
    /// filter states (needs --nhc or --odometer), prior standard deviation (e.g.
    /// `5 deg`; the flag alone: 5 deg).
    #[arg(long, value_name = "ANGLE", num_args = 0..=1, default_missing_value = "5 deg")]
    #[serde(default, deserialize_with = "crate::flat_options::text_or_number")]
    pub estimate_mounting: Option<String>,
    /// The point the NHC and the odometer speak of (the rear axle's centre, the
    /// odometer wheel) in IMU body axes, front, right, down [m] (default 0,0,0).
    #[arg(long, allow_hyphen_values = true, value_name = "X,Y,Z")]
    pub vehicle_lever_arm: Option<Triple>,
    /// Dual-antenna GNSS headings (`t heading std [pitch pitch_std]`, degrees).
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub dual_antenna: Option<PathBuf>,
    /// Azimuth of the antenna baseline (from the first antenna to the second) from
    /// the IMU's front axis towards its right [deg] (default 0).
    #[arg(long, allow_hyphen_values = true, value_name = "DEG")]
    pub dual_antenna_baseline_yaw: Option<f64>,
    /// Elevation of the baseline above the IMU's front-right plane [deg] (default 0).
    #[arg(long, allow_hyphen_values = true, value_name = "DEG")]
    pub dual_antenna_baseline_pitch: Option<f64>,
    /// Aids read from a ROS 2 bag (`nav --bag`): used where no file of the same kind
    /// is given.
    #[arg(skip)]
    #[serde(skip)]
    pub bag: Option<schuler_io::bag::input::BagAids>,
}

impl AidingOptions {
    /// `self` with missing fields taken from `other`.
    pub fn or(self, other: AidingOptions) -> AidingOptions {
        macro_rules! pick {
            ($($f:ident),*) => { AidingOptions { $($f: self.$f.or(other.$f),)* gnss_nav: if self.gnss_nav.is_empty() { other.gnss_nav } else { self.gnss_nav }, gnss_systems: if self.gnss_systems.is_empty() { other.gnss_systems } else { self.gnss_systems }, scale_factors: self.scale_factors || other.scale_factors, smooth: self.smooth || other.smooth, no_report: self.no_report || other.no_report, zupt_detect: self.zupt_detect || other.zupt_detect, zaru: self.zaru || other.zaru, nhc: self.nhc || other.nhc } };
        }
        pick!(
            gnss,
            gnss_obs,
            elevation_mask,
            gnss_format,
            gnss_std,
            gnss_min_quality,
            gnss_time_offset,
            gnss_vel,
            error_model,
            gnss_vel_std,
            lever_arm,
            estimate_lever_arm,
            estimate_gnss_time_offset,
            gnss_time_offset_walk,
            gate,
            arw,
            vrw,
            gyro_bias_std,
            accel_bias_std,
            gyro_scale_std,
            accel_scale_std,
            gyro_bias_instability,
            accel_bias_instability,
            bias_corr_time,
            rate_random_walk,
            acceleration_random_walk,
            init_pos_std,
            init_vel_std,
            init_att_std,
            baro,
            baro_std,
            baro_bias_std,
            outage_test,
            outage_start,
            truth,
            sensor_truth,
            propagation_interval,
            zupt,
            zupt_std,
            zupt_interval,
            zupt_max_speed,
            zaru_std,
            nhc_std,
            nhc_interval,
            odometer,
            odometer_std,
            odometer_scale_std,
            mounting_angles,
            estimate_mounting,
            vehicle_lever_arm,
            dual_antenna,
            dual_antenna_baseline_yaw,
            dual_antenna_baseline_pitch,
            bag
        )
    }

    /// Paths relative to `base` (a config file's folder).
    pub fn relative_to(mut self, base: &Path) -> Self {
        for p in self.gnss_nav.iter_mut() {
            if p.is_relative() {
                *p = base.join(&*p);
            }
        }
        for p in [
            &mut self.gnss,
            &mut self.gnss_obs,
            &mut self.gnss_vel,
            &mut self.truth,
            &mut self.sensor_truth,
            &mut self.baro,
            &mut self.zupt,
            &mut self.odometer,
            &mut self.dual_antenna,
        ]
        .into_iter()
        .flatten()
        {
            if p.is_relative() {
                *p = base.join(&*p);
            }
        }
        self
    }

    /// The input files given, each with its key (`gnss`, `baro`, ...).
    pub fn input_files(&self) -> Vec<(&'static str, &Path)> {
        [
            ("gnss", &self.gnss),
            ("gnss_vel", &self.gnss_vel),
            ("truth", &self.truth),
            ("sensor_truth", &self.sensor_truth),
            ("baro", &self.baro),
            ("zupt", &self.zupt),
            ("odometer", &self.odometer),
            ("dual_antenna", &self.dual_antenna),
        ]
        .into_iter()
        .filter_map(|(k, p)| Some((k, p.as_deref()?)))
        .collect()
    }

    /// Whether any aiding source is given (GNSS, barometer or a vehicle aid).
    pub fn any(&self) -> bool {
        self.gnss.is_some()
            || self.gnss_obs.is_some()
            || self
                .bag
                .as_ref()
                .is_some_and(|b| !b.fixes.is_empty() || !b.baro.is_empty())
            || self.has_odometer()
            || self.baro.is_some()
            || self.zupt.is_some()
            || self.zupt_detect
            || self.nhc
            || self.dual_antenna.is_some()
    }

    /// Whether odometer readings are given (`--odometer`, or a bag's odometry).
    pub fn has_odometer(&self) -> bool {
        self.odometer.is_some() || self.bag.as_ref().is_some_and(|b| !b.odometer.is_empty())
    }

    /// Load the aiding data and check every value; `None` without any aiding source
    /// ([`AidingOptions::any`]).
    pub fn resolve(&self, noise: schuler::filter::ImuNoise) -> Result<Option<Aiding>> {
        self.resolve_with(noise, GivenReadings::default())
    }

    /// [`AidingOptions::resolve`] with readings a caller holds in memory in place of
    /// the files `--gnss` and `--baro` would name (the Python package's arrays); the
    /// options that act on the readings (`--gnss-vel`, `--gnss-time-offset`,
    /// `--outage-test`, `--baro-std`, ...) act on them alike.
    pub fn resolve_with(
        &self,
        noise: schuler::filter::ImuNoise,
        given: GivenReadings,
    ) -> Result<Option<Aiding>> {
        let has_gnss = self.gnss.is_some() || given.fixes.is_some();
        if !has_gnss && self.gnss_vel.is_some() {
            bail!("--gnss-vel needs --gnss (velocities are matched to position fixes)");
        }
        vehicle::check_dependencies(self, &given.vehicle)?;
        if !(self.any() || given.any()) {
            // The truth serves the filter's report and outage test: a free-inertial
            // run has neither, so it is refused rather than ignored.
            for (given, flag) in [
                (self.truth.is_some(), "--truth"),
                (self.sensor_truth.is_some(), "--sensor-truth"),
                (self.outage_test.is_some(), "--outage-test"),
            ] {
                if given {
                    bail!(
                        "{flag} is used by the filter's report, and this run has no aid \
                         (--gnss, --baro, --odometer, ...); compare a free-inertial result \
                         with `schuler compare NAV TRUTH`"
                    );
                }
            }
            return Ok(None);
        }
        let raw = self.raw_gnss(has_gnss)?;
        let (fixes, outage_test) = self.fix_store(given.fixes)?;
        let noise = self.noise(noise)?;
        let (baro, baro_std) = self.baro(given.baro)?;
        let (vehicle_cfg, vehicle) = vehicle::resolve(self, &noise, given.vehicle)?;
        let mut integration = self.integration(noise)?;
        integration.baro = baro_std.map(|(_, bias)| (bias, 0.0));
        let error_model = self.error_model(&mut integration)?;
        Ok(Some(Aiding {
            vehicle,
            filter: FilterConfig {
                integration,
                baro_std: baro_std.map_or(0.5, |(std, _)| std),
                smooth: self.smooth,
                vehicle: vehicle_cfg,
                att_bias_cov: None,
                error_model,
            },
            names: OutputNames::SCHULER,
            initial_errors: Default::default(),
            outage_test,
            baro,
            report: self.report()?,
            fixes,
            raw,
            gnss_time_shift: self.gnss_time_offset()?.unwrap_or(0.0),
        }))
    }

    /// The raw GNSS of `--gnss-obs` (`has_fixes`: fixes are given too, refused).
    fn raw_gnss(&self, has_fixes: bool) -> Result<Option<raw_gnss::RawGnss>> {
        let Some(obs) = &self.gnss_obs else {
            if !self.gnss_nav.is_empty() {
                bail!("--gnss-nav serves --gnss-obs (tight coupling): give --gnss-obs OBS");
            }
            return Ok(None);
        };
        if has_fixes {
            bail!(
                "--gnss and --gnss-obs are two views of one receiver (its fixes and its raw \
                 measurements): give one"
            );
        }
        let offset = self.gnss_time_offset()?.unwrap_or(0.0);
        let raw = raw_gnss::RawGnss::open(
            obs,
            &self.gnss_nav,
            self.elevation_mask.unwrap_or(10.0),
            &self.gnss_systems,
            offset,
        )?;
        Ok(Some(raw))
    }

    /// How `--gnss` is read, with `vel_std` [m/s] for velocities given without one.
    fn gnss_read_options(&self, vel_std: f64) -> Result<GnssReadOptions> {
        let default_std = match self.gnss_std {
            Some(Triple(s)) if s.iter().all(|&x| x > 0.0) => Some(Vector3::from(s)),
            Some(Triple(s)) => bail!("--gnss-std must be positive, got {s:?}"),
            None => None,
        };
        Ok(GnssReadOptions {
            format: self.gnss_format.unwrap_or_default(),
            default_std,
            min_quality: self.gnss_min_quality.unwrap_or_default(),
            vel_std,
        })
    }

    /// The GNSS fixes of the run in their store, and the outage test cut from them.
    /// A text `--gnss` log (KF-GINS text or CSV) without `--gnss-vel` and
    /// `--outage-test` is streamed into the store line by line, so that its memory
    /// does not grow with the log's length (issue 22); the other formats are read
    /// whole ([`AidingOptions::fixes`]) and then stored.
    fn fix_store(&self, given: Option<Vec<GnssFix>>) -> Result<(fixes::Fixes, Option<OutageTest>)> {
        if let (None, Some(path), None, None) =
            (&given, &self.gnss, &self.gnss_vel, &self.outage_test)
        {
            let vel_std = self.gnss_vel_std()?;
            let opts = self.gnss_read_options(vel_std)?;
            if schuler_io::formats::gnss::format_of(path, opts.format)? == GnssFormat::Text {
                let offset = self.gnss_time_offset()?;
                let mut store = fixes::Fixes::default();
                schuler_io::formats::gnss::for_each_text_record(path, opts.default_std, |r| {
                    let mut fix = r.fix;
                    if let Some(dt) = offset {
                        fix.t += dt;
                    }
                    store.push(&fix);
                })?;
                return Ok((store.closed(), None));
            }
        }
        let mut fixes = self.fixes(given)?;
        let outage_test = self.outage_test(&mut fixes)?;
        Ok((fixes.into(), outage_test))
    }

    /// `--gnss-vel-std` [m/s] (0.1 when not given), which must be positive.
    fn gnss_vel_std(&self) -> Result<f64> {
        let (std, dim) = (&self.gnss_vel_std, Dimension::Velocity);
        let vel_std = quantity_in("gnss-vel-std", std, dim, &d::VELOCITY_STD)?;
        Ok(vel_std.unwrap_or(0.1))
    }

    /// `--gnss-time-offset` [s], which must be finite.
    fn gnss_time_offset(&self) -> Result<Option<f64>> {
        let Some(text) = &self.gnss_time_offset else {
            return Ok(None);
        };
        let dt = parse_as_or_si(text.trim(), Dimension::Time)
            .with_context(|| format!("--gnss-time-offset {text:?}"))?;
        if !dt.is_finite() {
            bail!("--gnss-time-offset must be finite, got {text:?}");
        }
        Ok(Some(dt))
    }

    /// The GNSS fixes (the reader's warnings printed), with the velocities of
    /// `--gnss-vel` merged in and `--gnss-time-offset` added to their times.
    /// `given`: fixes in memory in place of the file.
    pub fn fixes(&self, given: Option<Vec<GnssFix>>) -> Result<Vec<GnssFix>> {
        let vel_std = self.gnss_vel_std()?;
        let mut fixes = match (given, &self.gnss) {
            (Some(given), _) => given,
            (None, Some(gnss)) => {
                let log = read_gnss_log(gnss, &self.gnss_read_options(vel_std)?)?;
                for w in &log.warnings {
                    eprintln!("warning: {}: {w}", gnss.display());
                }
                log.fixes
            }
            (None, None) => self
                .bag
                .as_ref()
                .map(|b| b.fixes.clone())
                .unwrap_or_default(),
        };
        if let Some(v) = &self.gnss_vel {
            let unmatched = schuler_io::formats::gnss::merge_velocity(&mut fixes, v, vel_std)?;
            if unmatched > 0 {
                eprintln!(
                    "warning: {}: {unmatched} velocity epochs have no position fix at the same time and are not used",
                    v.display()
                );
            }
        }
        if let Some(dt) = self.gnss_time_offset()? {
            for f in &mut fixes {
                f.t += dt;
            }
        }
        Ok(fixes)
    }

    /// The IMU noise model with the flags' overrides: white noise, bias and scale
    /// priors, then [`AidingOptions::bias_walks`].
    fn noise(&self, mut noise: ImuNoise) -> Result<ImuNoise> {
        let q = quantity_in;
        let set = |v: &mut Vector3<f64>, x: Option<f64>| {
            if let Some(x) = x {
                *v = Vector3::repeat(x);
            }
        };
        set(
            &mut noise.arw,
            q(
                "arw",
                &self.arw,
                Dimension::AngleRandomWalk,
                &d::ANGLE_RANDOM_WALK,
            )?,
        );
        set(
            &mut noise.vrw,
            q(
                "vrw",
                &self.vrw,
                Dimension::VelocityRandomWalk,
                &d::VELOCITY_RANDOM_WALK,
            )?,
        );
        set(
            &mut noise.gyro_bias,
            q(
                "gyro-bias-std",
                &self.gyro_bias_std,
                Dimension::AngularRate,
                &or_zero(d::ANGULAR_RATE_STD),
            )?,
        );
        set(
            &mut noise.accel_bias,
            q(
                "accel-bias-std",
                &self.accel_bias_std,
                Dimension::Acceleration,
                &or_zero(d::SPECIFIC_FORCE_STD),
            )?,
        );
        set(
            &mut noise.gyro_scale,
            q(
                "gyro-scale-std",
                &self.gyro_scale_std,
                Dimension::Dimensionless,
                &d::SCALE_FACTOR,
            )?,
        );
        set(
            &mut noise.accel_scale,
            q(
                "accel-scale-std",
                &self.accel_scale_std,
                Dimension::Dimensionless,
                &d::SCALE_FACTOR,
            )?,
        );
        self.bias_walks(noise)
    }

    /// The noise model's bias processes with the flags' overrides: Gauss–Markov
    /// correlation time, instabilities and random walks.
    fn bias_walks(&self, mut noise: ImuNoise) -> Result<ImuNoise> {
        let q = quantity_in;
        let tau_given = q(
            "bias-corr-time",
            &self.bias_corr_time,
            Dimension::Time,
            &d::CORRELATION_TIME,
        )?;
        let tau = tau_given.unwrap_or(3600.0);
        if tau_given.is_some() {
            // A correlation time makes the biases Gauss–Markov (as KF-GINS models them).
            noise.gyro_bias_tau = tau;
            noise.accel_bias_tau = tau;
        }
        let walk = |x: f64| Vector3::repeat(x * (2.0 / tau).sqrt());
        let gyro = q(
            "gyro-bias-instability",
            &self.gyro_bias_instability,
            Dimension::AngularRate,
            &or_zero(d::ANGULAR_RATE_STD),
        )?;
        if let Some(x) = gyro {
            noise.gyro_bias_walk = walk(x);
        }
        let accel = q(
            "accel-bias-instability",
            &self.accel_bias_instability,
            Dimension::Acceleration,
            &or_zero(d::SPECIFIC_FORCE_STD),
        )?;
        if let Some(x) = accel {
            noise.accel_bias_walk = walk(x);
        }
        let add = |w: &mut Vector3<f64>, k: Option<f64>| {
            if let Some(k) = k {
                *w = w.map(|x| x.hypot(k));
            }
        };
        let (rrw, arw) = (&self.rate_random_walk, &self.acceleration_random_walk);
        add(
            &mut noise.gyro_bias_walk,
            q(
                "rate-random-walk",
                rrw,
                Dimension::RateRandomWalk,
                &d::RATE_RANDOM_WALK,
            )?,
        );
        add(
            &mut noise.accel_bias_walk,
            q(
                "acceleration-random-walk",
                arw,
                Dimension::AccelerationRandomWalk,
                &d::ACCELERATION_RANDOM_WALK,
            )?,
        );
        Ok(noise)
    }

    /// `--outage-test LEN/PERIOD`: the windows, with the fixes inside them removed.
    fn outage_test(&self, fixes: &mut Vec<GnssFix>) -> Result<Option<OutageTest>> {
        let Some(text) = &self.outage_test else {
            return Ok(None);
        };
        let (len, period) = text.split_once('/').with_context(|| {
            format!("--outage-test {text:?}: expected LEN/PERIOD, e.g. 60s/180s")
        })?;
        let t = |s: &str| -> Result<f64> {
            parse_as_or_si(s.trim(), Dimension::Time)
                .with_context(|| format!("--outage-test {text:?}"))
        };
        let (len, period) = (t(len)?, t(period)?);
        if !(len > 0.0 && period > len) {
            bail!("--outage-test {text:?}: need 0 < LEN < PERIOD");
        }
        let (first, last) = (
            fixes.first().map_or(0.0, |f| f.t),
            fixes.last().map_or(0.0, |f| f.t),
        );
        let mut start = self.outage_start.unwrap_or(first + period);
        let mut windows = Vec::new();
        while start + len <= last {
            windows.push((start, start + len));
            start += period;
        }
        if windows.is_empty() {
            bail!(
                "--outage-test {text:?}: no whole outage fits between the first and last GNSS fix"
            );
        }
        fixes.retain(|f| !windows.iter().any(|&(a, b)| f.t > a && f.t <= b));
        Ok(Some(OutageTest {
            windows,
            truth: self.truth.clone(),
        }))
    }

    /// The barometer's readings `(t, h)` (`given`, or read from `--baro`, or the
    /// bag's) and `(noise, bias prior)` standard deviations [m].
    fn baro(&self, given: Option<Vec<(f64, f64)>>) -> Result<BaroInput> {
        let readings = match (given, &self.baro, &self.bag) {
            (Some(given), _, _) => given,
            (None, Some(path), _) => schuler_io::formats::gnss::read_baro(path)?,
            (None, None, Some(bag)) if !bag.baro.is_empty() => bag.baro.clone(),
            _ => return Ok((Vec::new(), None)),
        };
        let length = |flag, v| quantity_in(flag, v, Dimension::Length, &d::POSITION_STD);
        let std = length("baro-std", &self.baro_std)?.unwrap_or(0.5);
        let bias = length("baro-bias-std", &self.baro_bias_std)?.unwrap_or(10.0);
        Ok((readings, Some((std, bias))))
    }

    /// The filter's settings (without the barometer).
    /// The library's error model of `--error-model` (psi21 turns the scale-factor
    /// states on in `integration`).
    fn error_model(&self, integration: &mut IntegrationConfig) -> Result<ErrorModelChoice> {
        use crate::options::ErrorModelArg;
        // Without the flag: psi15, or psi21 with --scale-factors, as before the flag.
        Ok(match self.error_model {
            None => ErrorModelChoice::Psi,
            Some(ErrorModelArg::Psi15) if self.scale_factors => {
                bail!("--error-model psi15 has no scale factors; --scale-factors is psi21")
            }
            Some(ErrorModelArg::Psi15) => ErrorModelChoice::Psi,
            Some(ErrorModelArg::Psi21) => {
                integration.scale_factors = true;
                ErrorModelChoice::Psi
            }
            Some(ErrorModelArg::Seed18) => ErrorModelChoice::Seed18,
        })
    }

    fn integration(&self, noise: ImuNoise) -> Result<IntegrationConfig> {
        let gate = match self.gate {
            None => schuler::filter::Gate::Level(1e-4),
            Some(0.0) => schuler::filter::Gate::Off,
            Some(a) if a > 0.0 && a < 1.0 => schuler::filter::Gate::Level(a),
            Some(a) => bail!("--gate must be a significance level in [0, 1), got {a}"),
        };
        let triple = |flag: &str, v: &Option<Triple>, default: [f64; 3]| -> Result<Vector3<f64>> {
            let t = v.map_or(default, |t| t.0);
            if t.iter().any(|x| *x <= 0.0) {
                bail!("--{flag} must be positive, got {t:?}");
            }
            Ok(Vector3::from(t))
        };
        let att = triple("init-att-std", &self.init_att_std, [0.1, 0.1, 0.5])?;
        let propagation_interval = quantity(
            "propagation-interval",
            &self.propagation_interval,
            Dimension::Time,
        )?
        .unwrap_or(1.0);
        if propagation_interval <= 0.0 {
            bail!("--propagation-interval must be positive");
        }
        Ok(IntegrationConfig {
            noise,
            scale_factors: self.scale_factors,
            lever_arm: self
                .lever_arm
                .map_or(Vector3::zeros(), |t| Vector3::from(t.0)),
            gate,
            reset_after: 5,
            propagation_interval,
            init_pos_std: triple("init-pos-std", &self.init_pos_std, [1.0, 1.0, 1.0])?,
            init_vel_std: triple("init-vel-std", &self.init_vel_std, [0.1, 0.1, 0.1])?,
            // Roll, pitch, yaw std taken about north, east, down (level attitude).
            init_att_std: att.map(f64::to_radians),
            init_sensor_std: None,
            baro: None,
            // --gnss-time-offset is added to the GNSS times as they are read.
            gnss_time_offset: 0.0,
            calibration: calibration::calibration(self)?,
        })
    }

    /// The report's settings and truths.
    fn report(&self) -> Result<ReportSettings> {
        Ok(ReportSettings {
            html: !self.no_report,
            truth: self.truth.as_deref().map(report::Truth::file).transpose()?,
            sensor_truth: match &self.sensor_truth {
                Some(p) => schuler_io::formats::sensor_errors::read_sensor_errors(p)?,
                None => Vec::new(),
            },
        })
    }
}

/// The outage test's report: the outages, and with a truth the largest horizontal,
/// vertical and attitude errors inside each (for an INS bridging a gap, the error at
/// its end) and the RMS of those maxima, the protocol of the KF-GINS paper; also
/// written to `DIR/outage_test.json`.
pub fn report_outage_test(
    nav: &Path,
    windows: &[(f64, f64)],
    truth: Option<&Path>,
    dir: &Path,
) -> Result<()> {
    println!(
        "outage test: {} outages of {:.0} s",
        windows.len(),
        windows[0].1 - windows[0].0
    );
    let Some(truth) = truth else {
        println!("  (give --truth FILE for the errors in each outage)");
        return Ok(());
    };
    let (_, nav_rows) = schuler_io::formats::nav::read_nav(nav)?;
    let (_, truth_rows) = schuler_io::formats::nav::read_nav(truth)?;
    let c = schuler::analysis::statistics::compare(&nav_rows, &truth_rows, None, None, windows)?;
    let mut json = Vec::new();
    println!(
        "  outage [s]          | horizontal max [m] | vertical max [m] | roll/pitch/yaw max [deg]"
    );
    for o in &c.stats.outages {
        println!(
            "  {:9.1}-{:9.1} | {:18.3} | {:16.3} | {:.4} {:.4} {:.4}",
            o.from_sow,
            o.to_sow,
            o.horizontal,
            o.vertical,
            o.att.roll.to_degrees(),
            o.att.pitch.to_degrees(),
            o.att.yaw.to_degrees()
        );
        json.push(serde_json::json!({
            "from": o.from_sow, "to": o.to_sow, "epochs": o.epochs,
            "horizontal_max_m": o.horizontal, "vertical_max_m": o.vertical,
            "roll_max_deg": o.att.roll.to_degrees(), "pitch_max_deg": o.att.pitch.to_degrees(),
            "yaw_max_deg": o.att.yaw.to_degrees(),
        }));
    }
    let rms = c.stats.outage_rms.map(|o| {
        println!(
            "  RMS of the maxima  | {:18.3} | {:16.3} | {:.4} {:.4} {:.4}",
            o.horizontal,
            o.vertical,
            o.att.roll.to_degrees(),
            o.att.pitch.to_degrees(),
            o.att.yaw.to_degrees()
        );
        serde_json::json!({
            "horizontal_m": o.horizontal, "vertical_m": o.vertical,
            "roll_deg": o.att.roll.to_degrees(), "pitch_deg": o.att.pitch.to_degrees(),
            "yaw_deg": o.att.yaw.to_degrees(),
        })
    });
    let path = dir.join("outage_test.json");
    let text = serde_json::to_string_pretty(
        &serde_json::json!({ "outages": json, "rms_of_maxima": rms }),
    )?;
    schuler_io::line_file::write_whole(&path, text + "\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A text GNSS log streamed into the store (with a time offset) holds the fixes
    /// the whole-file reader gives, bit for bit, with the same ends and gaps, while
    /// at most the store's budget stays in memory; with `--outage-test` (read whole)
    /// the store is the same too.
    #[test]
    fn a_streamed_text_log_equals_the_log_read_whole() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("gnss.txt");
        let mut text = String::from("# t lat lon h std_n std_e std_d\n");
        for k in 1..=20_000u32 {
            // A 60-s outage after 500 s, and a 13-column row now and then.
            let t = f64::from(k) + if k > 500 { 60.0 } else { 0.0 };
            let lat = 30.5 + 1e-7 * f64::from(k);
            text.push_str(&format!(
                "{t} {lat:.10} 114.3 {} 0.5 0.5 1.0",
                20.0 + 0.01 * f64::from(k)
            ));
            if k % 7 == 0 {
                text.push_str(" 1.5 -0.5 0.1 0.1 0.1 0.2");
            }
            text.push('\n');
        }
        std::fs::write(&path, text).expect("write");
        let options = AidingOptions {
            gnss: Some(path),
            gnss_time_offset: Some("-2.5 s".into()),
            ..Default::default()
        };
        let whole = options.fixes(None).expect("read whole");
        let (streamed, outage) = options.fix_store(None).expect("streamed");
        assert!(outage.is_none());
        assert_eq!(streamed.to_vec().expect("read back"), whole);
        assert_eq!(
            (streamed.first(), streamed.last()),
            (whole.first().copied(), whole.last().copied())
        );
        assert_eq!(streamed.gaps(), report::gnss_gaps(&whole));
        assert_eq!(streamed.gaps(), [(497.5, 558.5)]);
        assert!(streamed.in_memory() <= spilled::BUDGET);
    }
}
