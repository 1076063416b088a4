//! The drop-in for KF-GINS (i2Nav-WHU/KF-GINS), `schuler nav --kf-gins-config
//! FILE.yaml`. Reads its configuration ([`schuler_io::formats::kf_gins_config`]) — paths, processing interval,
//! initial state and standard deviations, IMU noise, antenna lever arm, in the units
//! KF-GINS defines (deg, deg/h, mGal, ppm, deg/sqrt(h), m/s/sqrt(h), hours) — and
//! writes `KF_GINS_Navresult.nav`, `KF_GINS_IMU_ERR.txt` and `KF_GINS_STD.txt` into its
//! `outputpath` at the IMU rate, with KF-GINS's columns and units (whitespace
//! separated). The filter is the 21-state one with Gauss–Markov biases and scale
//! factors, as KF-GINS's. Relative paths are taken from the working directory, as
//! KF-GINS does.
//!
//! By default it behaves as KF-GINS: only its three files, no innovation gate, its
//! normal gravity ([`schuler::earth::Wgs84Series`]), the first IMU sample at or after
//! `starttime` as the start (its state not written: the first row is one sample
//! later) and only the GNSS fixes after `starttime`. [`KfGinsOptions`] asks for more:
//! the report and diagnostics, `nav.csv`, a gate, TR8350.2's gravity.

use crate::aided::report::ReportSettings;
use crate::aided::{Aiding, OutputNames};
use crate::navigate::{NavSettings, RunSummary, navigate, samples_of};
use crate::options::{EarthChoice, GravityChoice};
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use schuler::earth::Geodetic;
use schuler::filter::integration::SensorEstimates;
use schuler::filter::{Gate, IntegrationConfig};
use schuler::rotation::Euler;
use schuler::session::{FilterConfig, MechanizationChoice, MechanizationConfig, Start};
use schuler::units::{DEG_PER_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H, MGAL, PPM};
use schuler_io::formats::kf_gins_config::{ImuNoiseYaml, KfGinsYaml, read_kf_gins_config};
use schuler_io::formats::{ImuFormat, ImuLayout, ImuReadOptions};
use std::path::Path;

/// What a KF-GINS run does beyond KF-GINS (the flags of `schuler nav` that apply).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct KfGinsOptions {
    /// Write report.html, innovations.csv, rejected.csv and consistency.json too.
    pub report: bool,
    /// Write nav.csv beside the navigation result.
    pub nav_csv: bool,
    /// Innovation gate's significance level (`None` or 0: no gate, as KF-GINS).
    pub gate: Option<f64>,
    /// Normal gravity (`None`: KF-GINS's series).
    pub gravity: Option<GravityChoice>,
    /// Longest covariance propagation step [s] (`None`: 1 s; KF-GINS propagates at
    /// every sample, which any step shorter than the sample interval reproduces).
    pub propagation_interval: Option<f64>,
}

/// A run set up from a KF-GINS configuration.
#[derive(Debug, Clone)]
pub struct KfGinsRun {
    /// Navigation settings (paths, interval, initial state; output at the IMU rate).
    pub settings: NavSettings,
    /// The filter, the GNSS data and the initial sensor errors.
    pub aiding: Aiding,
    /// The gravity it navigates with.
    pub gravity: GravityChoice,
}

fn positive(key: &str, v: &[f64]) -> Result<Vector3<f64>> {
    if v.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        bail!("{key}: standard deviations must be positive numbers, got {v:?}");
    }
    Ok(Vector3::from_column_slice(v))
}

fn non_negative(key: &str, v: &[f64]) -> Result<Vector3<f64>> {
    if v.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
        bail!("{key}: must not be negative, got {v:?}");
    }
    Ok(Vector3::from_column_slice(v))
}

/// The IMU noise model of `imunoise`, in SI units (Gauss–Markov biases and scale
/// factors with the correlation time `corrtime`, as KF-GINS models them).
fn noise(n: &ImuNoiseYaml, key: &dyn Fn(&str) -> String) -> Result<schuler::filter::ImuNoise> {
    let tau = n.corrtime * 3600.0;
    let gb = non_negative(&key("imunoise.gbstd"), &n.gbstd)? * DEG_PER_H;
    let ab = non_negative(&key("imunoise.abstd"), &n.abstd)? * MGAL;
    let walk = |s: Vector3<f64>| s * (2.0 / tau).sqrt();
    Ok(schuler::filter::ImuNoise {
        arw: non_negative(&key("imunoise.arw"), &n.arw)? * DEG_PER_SQRT_H,
        vrw: non_negative(&key("imunoise.vrw"), &n.vrw)? * M_PER_S_PER_SQRT_H,
        gyro_bias: gb,
        gyro_bias_walk: walk(gb),
        accel_bias: ab,
        accel_bias_walk: walk(ab),
        gyro_bias_tau: tau,
        accel_bias_tau: tau,
        gyro_scale: non_negative(&key("imunoise.gsstd"), &n.gsstd)? * PPM,
        accel_scale: non_negative(&key("imunoise.asstd"), &n.asstd)? * PPM,
        scale_tau: tau,
    })
}

/// The innovation gate of a significance level `level` (`None` or 0: none, as
/// KF-GINS).
fn gate(level: Option<f64>) -> Result<Gate> {
    match level {
        None | Some(0.0) => Ok(Gate::Off),
        Some(a) if a > 0.0 && a < 1.0 => Ok(Gate::Level(a)),
        Some(a) => bail!("--gate must be a significance level in [0, 1), got {a}"),
    }
}

/// The covariance propagation step [s] of `--propagation-interval` (default 1 s:
/// the covariance is propagated once a second and at every update, where KF-GINS
/// propagates it at every sample; on `tests/data/drive9min` per-sample propagation
/// costs 7x the run time for standard deviations closer to KF-GINS's, see
/// `tests/kf_gins_parity.rs`).
fn propagation_interval(s: Option<f64>) -> Result<f64> {
    match s {
        None => Ok(1.0),
        Some(s) if s > 0.0 => Ok(s),
        Some(s) => bail!("--propagation-interval must be positive, got {s} s"),
    }
}

/// The filter of a configuration: KF-GINS's 21 states with its prior, the gate and
/// the covariance propagation step.
fn integration(
    y: &KfGinsYaml,
    key: &dyn Fn(&str) -> String,
    (gate, propagation_interval): (Gate, f64),
) -> Result<IntegrationConfig> {
    let noise = noise(&y.imunoise, key)?;
    let init_std =
        |k: &str, v: Option<[f64; 3]>, default: Vector3<f64>, unit: f64| -> Result<Vector3<f64>> {
            v.map_or(Ok(default), |v| positive(&key(k), &v).map(|x| x * unit))
        };
    let sensor_std = [
        init_std("initbgstd", y.initbgstd, noise.gyro_bias, DEG_PER_H)?,
        init_std("initbastd", y.initbastd, noise.accel_bias, MGAL)?,
        init_std("initsgstd", y.initsgstd, noise.gyro_scale, PPM)?,
        init_std("initsastd", y.initsastd, noise.accel_scale, PPM)?,
    ];
    Ok(IntegrationConfig {
        noise,
        scale_factors: true,
        lever_arm: Vector3::from(y.antlever),
        gate,
        reset_after: 5,
        propagation_interval,
        init_pos_std: positive(&key("initposstd"), &y.initposstd)?,
        init_vel_std: positive(&key("initvelstd"), &y.initvelstd)?,
        init_att_std: positive(&key("initattstd"), &y.initattstd)?.map(f64::to_radians),
        init_sensor_std: Some(sensor_std),
        baro: None,
        gnss_time_offset: 0.0,
        calibration: Default::default(),
    })
}

/// Read and check a KF-GINS configuration, with the options `opts`.
pub fn load(path: &Path, opts: &KfGinsOptions) -> Result<KfGinsRun> {
    let y = read_kf_gins_config(path)?;
    let key = |k: &str| format!("{}: {k}", path.display());
    // KF-GINS skips the fixes up to and including `starttime` (its start is the
    // configured state, not a fix). The log is streamed into the store (memory
    // bounded whatever its length); it must give standard deviations.
    let mut fixes = crate::aided::fixes::Fixes::default();
    schuler_io::formats::gnss::for_each_text_record(&y.gnsspath, None, |r| {
        if r.fix.t > y.starttime && (y.endtime < 0.0 || r.fix.t <= y.endtime) {
            fixes.push(&r.fix);
        }
    })
    .with_context(|| format!("{}: gnsspath", path.display()))?;
    let settings = NavSettings {
        imu: y.imupath.clone(),
        read: ImuReadOptions {
            format: ImuFormat::KfGinsText,
            layout: Some(ImuLayout::Increments),
            nominal_dt: Some(1.0 / y.imudatarate),
            t_start: Some(y.starttime),
            t_end: (y.endtime >= 0.0).then_some(y.endtime),
            check_layout: true,
            ..ImuReadOptions::default()
        },
        init_pos: Geodetic {
            // 0-360 deg wrapped, as everywhere (checked by `check_domains`).
            lon: schuler::domain::wrap_longitude(y.initpos[1].to_radians())?,
            ..Geodetic::from_degrees(y.initpos[0], 0.0, y.initpos[2])
        },
        init_vel: Vector3::from(y.initvel),
        init_att: Euler::from_degrees(y.initatt[0], y.initatt[1], y.initatt[2]),
        output_rate: None,
        out: y.outputpath.clone(),
        earth: EarthChoice::Wgs84,
        week: 0,
        // KF-GINS navigates in NED.
        mechanization: MechanizationConfig {
            choice: MechanizationChoice::Ned,
            ..MechanizationConfig::default()
        },
        out_bag: None,
    };
    let aiding = Aiding {
        raw: None,
        gnss_time_shift: 0.0,
        fixes: fixes.closed(),
        filter: FilterConfig::new(integration(
            &y,
            &key,
            (
                gate(opts.gate)?,
                propagation_interval(opts.propagation_interval)?,
            ),
        )?),
        names: OutputNames {
            nav_csv: opts.nav_csv,
            diagnostics: opts.report,
            ..OutputNames::KF_GINS
        },
        outage_test: None,
        baro: Vec::new(),
        report: ReportSettings {
            html: opts.report,
            ..ReportSettings::default()
        },
        vehicle: Default::default(),
        initial_errors: SensorEstimates {
            gyro_bias: Vector3::from(y.initgyrbias) * DEG_PER_H,
            accel_bias: Vector3::from(y.initaccbias) * MGAL,
            gyro_scale: Vector3::from(y.initgyrscale) * PPM,
            accel_scale: Vector3::from(y.initaccscale) * PPM,
            ..SensorEstimates::default()
        },
    };
    Ok(KfGinsRun {
        settings,
        aiding,
        gravity: opts.gravity.unwrap_or(GravityChoice::KfGins),
    })
}

/// Runs a KF-GINS configuration end to end with the options `opts`: the run set up
/// and its summary.
pub fn run_kf_gins(path: &Path, opts: &KfGinsOptions) -> Result<(KfGinsRun, RunSummary)> {
    let run = load(path, opts)?;
    let (settings, aiding) = (&run.settings, &run.aiding);
    let reader = schuler_io::formats::ImuReader::open(&settings.imu, &settings.read)
        .with_context(|| format!("{}: imupath", path.display()))?;
    // Read and parsed on a second thread, overlapping the navigation; the samples
    // come in the same order, so the files are the same bytes.
    let mut reader = reader.read_ahead()?;
    let start = Start {
        estimates: aiding.initial_errors,
        ..settings.start()
    };
    let earth = match run.gravity {
        GravityChoice::KfGins => EarthChoice::Wgs84Series,
        GravityChoice::Tr8350 => EarthChoice::Wgs84,
    };
    let mut samples = samples_of(&mut reader);
    let summary = navigate(
        earth,
        settings,
        Some(aiding),
        start,
        &mut samples,
        &mut |_| {},
    )?;
    Ok((run, summary))
}
