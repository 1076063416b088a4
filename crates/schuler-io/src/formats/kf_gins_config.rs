//! KF-GINS's YAML configuration (i2Nav-WHU/KF-GINS): its keys in its units (deg,
//! deg/h, mGal, ppm, deg/sqrt(h), m/s/sqrt(h), hours), read and checked; each value
//! outside its physical domain is refused with the file, the key and the element.

use super::lines::read_config_text;
use anyhow::{Result, bail};
use schuler::units::{DEG_PER_H, MGAL, PPM};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// KF-GINS's `imunoise` table.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuNoiseYaml {
    /// Angle random walk [deg/sqrt(h)].
    pub arw: [f64; 3],
    /// Velocity random walk [m/s/sqrt(h)].
    pub vrw: [f64; 3],
    /// Gyro bias standard deviation [deg/h].
    pub gbstd: [f64; 3],
    /// Accelerometer bias standard deviation [mGal].
    pub abstd: [f64; 3],
    /// Gyro scale factor standard deviation [ppm].
    pub gsstd: [f64; 3],
    /// Accelerometer scale factor standard deviation [ppm].
    pub asstd: [f64; 3],
    /// Correlation time of the biases and scale factors [h].
    pub corrtime: f64,
}

/// A KF-GINS configuration file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KfGinsYaml {
    /// The IMU log (7-column KF-GINS text).
    pub imupath: PathBuf,
    /// The GNSS log (KF-GINS text with standard deviations).
    pub gnsspath: PathBuf,
    /// The folder of the three output files.
    pub outputpath: PathBuf,
    /// Columns of the IMU log (7).
    pub imudatalen: u32,
    /// IMU rate [Hz].
    pub imudatarate: f64,
    /// Start time [s of week].
    pub starttime: f64,
    /// End time [s of week]; negative: the end of the log.
    pub endtime: f64,
    /// Initial latitude [deg], longitude [deg], height [m].
    pub initpos: [f64; 3],
    /// Initial velocity north, east, down [m/s].
    pub initvel: [f64; 3],
    /// Initial roll, pitch, yaw [deg].
    pub initatt: [f64; 3],
    /// Initial gyro biases [deg/h].
    pub initgyrbias: [f64; 3],
    /// Initial accelerometer biases [mGal].
    pub initaccbias: [f64; 3],
    /// Initial gyro scale factors [ppm].
    pub initgyrscale: [f64; 3],
    /// Initial accelerometer scale factors [ppm].
    pub initaccscale: [f64; 3],
    /// Initial position standard deviations north, east, down [m].
    pub initposstd: [f64; 3],
    /// Initial velocity standard deviations [m/s].
    pub initvelstd: [f64; 3],
    /// Initial attitude standard deviations [deg].
    pub initattstd: [f64; 3],
    /// Initial gyro bias standard deviations [deg/h] (default: imunoise.gbstd).
    pub initbgstd: Option<[f64; 3]>,
    /// Initial accelerometer bias standard deviations [mGal] (default: imunoise.abstd).
    pub initbastd: Option<[f64; 3]>,
    /// Initial gyro scale factor standard deviations [ppm] (default: imunoise.gsstd).
    pub initsgstd: Option<[f64; 3]>,
    /// Initial accelerometer scale factor standard deviations [ppm] (default: imunoise.asstd).
    pub initsastd: Option<[f64; 3]>,
    /// The IMU noise model.
    pub imunoise: ImuNoiseYaml,
    /// GNSS antenna lever arm in the body frame, front, right, down [m].
    pub antlever: [f64; 3],
}

/// Read a KF-GINS configuration and check its header values.
pub fn read_kf_gins_config(path: &Path) -> Result<KfGinsYaml> {
    // At most 16 MiB, as every configuration file: not a stream to exhaust memory.
    let text = read_config_text(path)?;
    let y: KfGinsYaml =
        serde_saphyr::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    if y.imudatalen != 7 {
        bail!(
            "{}: imudatalen: schuler reads the 7-column KF-GINS IMU text (time, 3 gyro, 3 accelerometer increments); got {}",
            path.display(),
            y.imudatalen
        );
    }
    if !(y.imudatarate.is_finite() && y.imudatarate > 0.0) {
        bail!(
            "{}: imudatarate must be a positive rate in Hz, got {}",
            path.display(),
            y.imudatarate
        );
    }
    check_domains(path, &y)?;
    let n = &y.imunoise;
    if !(n.corrtime.is_finite() && n.corrtime > 0.0) {
        bail!(
            "{}: imunoise.corrtime must be a positive number of hours, got {}",
            path.display(),
            n.corrtime
        );
    }
    Ok(y)
}

/// Every initial value of the configuration in its physical domain
/// ([`schuler::domain`], in KF-GINS's units); the error names the key and the element
/// (`initpos[1]: longitude 400 deg is outside ...`).
fn check_domains(path: &Path, y: &KfGinsYaml) -> Result<()> {
    use schuler::domain::{self as d, Domain};
    use schuler::units::DEG;
    const ROLL: Domain = Domain {
        quantity: "roll",
        ..d::HEADING
    };
    let same = |domain: &'static Domain, unit: f64| -> Axes { [(domain, unit); 3] };
    let optional = |v: Option<[f64; 3]>| v.unwrap_or([1.0; 3]);
    // Each key: its values, and each value's domain and KF-GINS unit [SI].
    type Axes = [(&'static Domain, f64); 3];
    let table: [(&str, [f64; 3], Axes); 15] = [
        (
            "initpos",
            y.initpos,
            [(&d::LATITUDE, DEG), (&d::LONGITUDE, DEG), (&d::HEIGHT, 1.0)],
        ),
        ("initvel", y.initvel, same(&d::SPEED, 1.0)),
        (
            "initatt",
            y.initatt,
            [(&ROLL, DEG), (&d::PITCH, DEG), (&d::HEADING, DEG)],
        ),
        (
            "initgyrbias",
            y.initgyrbias,
            same(&d::ANGULAR_RATE_COMPONENT, DEG_PER_H),
        ),
        (
            "initaccbias",
            y.initaccbias,
            same(&d::SPECIFIC_FORCE_COMPONENT, MGAL),
        ),
        ("initgyrscale", y.initgyrscale, same(&d::SCALE_FACTOR, PPM)),
        ("initaccscale", y.initaccscale, same(&d::SCALE_FACTOR, PPM)),
        ("initposstd", y.initposstd, same(&d::POSITION_STD, 1.0)),
        ("initvelstd", y.initvelstd, same(&d::VELOCITY_STD, 1.0)),
        ("initattstd", y.initattstd, same(&d::ANGLE_STD, DEG)),
        (
            "initbgstd",
            optional(y.initbgstd),
            same(&d::ANGULAR_RATE, DEG_PER_H),
        ),
        (
            "initbastd",
            optional(y.initbastd),
            same(&d::SPECIFIC_FORCE, MGAL),
        ),
        (
            "initsgstd",
            optional(y.initsgstd),
            same(&d::SCALE_FACTOR, PPM),
        ),
        (
            "initsastd",
            optional(y.initsastd),
            same(&d::SCALE_FACTOR, PPM),
        ),
        ("antlever", y.antlever, same(&d::LEVER_ARM, 1.0)),
    ];
    for (key, values, domains) in &table {
        for (k, (v, (domain, unit))) in values.iter().zip(domains).enumerate() {
            if let Err(e) = domain.check(v * unit) {
                bail!("{}: {key}[{k}]: {e}", path.display());
            }
        }
    }
    Ok(())
}
