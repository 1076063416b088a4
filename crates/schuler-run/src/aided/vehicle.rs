//! Vehicle aiding of `schuler nav` (flags or `[aiding]` keys): zero-velocity updates at
//! rest from a file of rest intervals or detected from the IMU, optionally with
//! zero-angular-rate updates; the non-holonomic constraint; odometer speed with an
//! optional scale-factor state; dual-antenna GNSS heading. [`resolve`] checks the
//! options and loads the files (or takes the readings a caller holds in memory,
//! [`GivenVehicle`]) into the session's [`VehicleConfig`] and the readings the run
//! pushes as aids; the library's session applies them ([`schuler::session`]).

use super::AidingOptions;
use crate::options::quantity;
use anyhow::{Result, bail};
use nalgebra::Vector3;
use schuler::domain::VELOCITY_STD;
use schuler::filter::integration::Counts;
use schuler::filter::{Baseline, HeadingReading, ImuNoise, VehicleMount};
use schuler::rotation::Euler;
use schuler::session::{Aid, RestConfig, RestSource, VehicleConfig};
use schuler::units::Dimension;

/// The vehicle aids' readings, pushed into the session as aids.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VehicleReadings {
    /// Rest intervals `[t0, t1]` [s].
    pub rests: Vec<(f64, f64)>,
    /// Odometer readings `(t, speed)`.
    pub odometer: Vec<(f64, f64)>,
    /// Dual-antenna headings.
    pub headings: Vec<HeadingReading>,
}

impl VehicleReadings {
    /// The readings as session aids.
    pub fn aids(&self) -> impl Iterator<Item = Aid> + '_ {
        let rests = self.rests.iter().map(|&(t0, t1)| Aid::Rest { t0, t1 });
        let odometer = self
            .odometer
            .iter()
            .map(|&(t, speed)| Aid::Odometer { t, speed });
        rests
            .chain(odometer)
            .chain(self.headings.iter().map(|&h| Aid::Heading(h)))
    }
}

/// Vehicle readings held in memory in place of the files of `--zupt`, `--odometer`
/// and `--dual-antenna` (the Python package's arrays and pushes). `Some`, even empty,
/// sets the aid up as its file would; the options that tune it act alike.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GivenVehicle {
    /// Rest intervals `[t0, t1]` [s], in place of `--zupt FILE`.
    pub rests: Option<Vec<(f64, f64)>>,
    /// Odometer readings `(t, speed)` [s, m/s], in place of `--odometer FILE`.
    pub odometer: Option<Vec<(f64, f64)>>,
    /// Dual-antenna headings, in place of `--dual-antenna FILE`.
    pub headings: Option<Vec<HeadingReading>>,
}

impl GivenVehicle {
    /// Whether any readings are given.
    pub fn any(&self) -> bool {
        self.rests.is_some() || self.odometer.is_some() || self.headings.is_some()
    }
}

/// Refuse options given without the aid they tune (e.g. `--nhc-std` without `--nhc`);
/// `given`: readings in memory standing for their files.
pub fn check_dependencies(o: &AidingOptions, given: &GivenVehicle) -> Result<()> {
    let rests = o.zupt.is_some() || given.rests.is_some();
    let odometer = o.has_odometer() || given.odometer.is_some();
    let dual_antenna = o.dual_antenna.is_some() || given.headings.is_some();
    for (given, flag, needs, main) in [
        (
            o.zupt_std.is_some(),
            "zupt-std",
            rests || o.zupt_detect,
            "--zupt or --zupt-detect",
        ),
        (
            o.zupt_interval.is_some(),
            "zupt-interval",
            rests || o.zupt_detect,
            "--zupt or --zupt-detect",
        ),
        (
            o.zupt_max_speed.is_some(),
            "zupt-max-speed",
            o.zupt_detect,
            "--zupt-detect",
        ),
        (
            o.zaru,
            "zaru",
            rests || o.zupt_detect,
            "--zupt or --zupt-detect",
        ),
        (o.zaru_std.is_some(), "zaru-std", o.zaru, "--zaru"),
        (o.nhc_std.is_some(), "nhc-std", o.nhc, "--nhc"),
        (o.nhc_interval.is_some(), "nhc-interval", o.nhc, "--nhc"),
        (
            o.odometer_std.is_some(),
            "odometer-std",
            odometer,
            "--odometer",
        ),
        (
            o.odometer_scale_std.is_some(),
            "odometer-scale-std",
            odometer,
            "--odometer",
        ),
        (
            o.estimate_mounting.is_some(),
            "estimate-mounting",
            o.nhc || odometer,
            "--nhc or --odometer",
        ),
        (
            o.dual_antenna_baseline_yaw.is_some(),
            "dual-antenna-baseline-yaw",
            dual_antenna,
            "--dual-antenna",
        ),
        (
            o.dual_antenna_baseline_pitch.is_some(),
            "dual-antenna-baseline-pitch",
            dual_antenna,
            "--dual-antenna",
        ),
    ] {
        if given && !needs {
            bail!("--{flag} needs {main}");
        }
    }
    if rests && o.zupt_detect {
        bail!("--zupt FILE (or given rest intervals) and --zupt-detect exclude each other");
    }
    Ok(())
}

/// The value of `--flag` with its unit (or `default` when not given) within `domain`
/// (a measurement's standard deviation: positive, and bounded above so that its
/// variance and the innovations stay finite).
fn std_in(
    flag: &str,
    v: &Option<String>,
    dim: Dimension,
    domain: &schuler::domain::Domain,
    default: f64,
) -> Result<f64> {
    Ok(crate::options::quantity_in(flag, v, dim, domain)?.unwrap_or(default))
}

/// The value of `--flag` with its unit (or `default` when not given), which must be
/// positive.
fn positive(flag: &str, v: &Option<String>, dim: Dimension, default: f64) -> Result<f64> {
    let x = quantity(flag, v, dim)?.unwrap_or(default);
    if x <= 0.0 {
        bail!("--{flag} must be positive, got {x}");
    }
    Ok(x)
}

/// Zero-velocity updates (`given` intervals or those of `--zupt FILE`, put into
/// `rests`, or `--zupt-detect`) with their noise, interval and optional zero-rate
/// updates; `None` without either.
fn rest_config(
    o: &AidingOptions,
    noise: &ImuNoise,
    given: Option<Vec<(f64, f64)>>,
    rests: &mut Vec<(f64, f64)>,
) -> Result<Option<RestConfig>> {
    let interval = positive("zupt-interval", &o.zupt_interval, Dimension::Time, 0.1)?;
    let source = match (given, &o.zupt, o.zupt_detect) {
        (Some(given), _, _) => {
            *rests = given;
            RestSource::Intervals
        }
        (None, Some(path), _) => {
            *rests = schuler_io::formats::vehicle::read_rest_intervals(path)?;
            RestSource::Intervals
        }
        (None, None, true) => RestSource::Detect {
            noise: *noise,
            max_speed: positive(
                "zupt-max-speed",
                &o.zupt_max_speed,
                Dimension::Velocity,
                0.5,
            )?,
        },
        (None, None, false) => return Ok(None),
    };
    let std = std_in(
        "zupt-std",
        &o.zupt_std,
        Dimension::Velocity,
        &VELOCITY_STD,
        0.02,
    )?;
    let zaru_std = if o.zaru {
        // Default: the gyro's white noise averaged over one interval.
        let white = noise.arw.max() / interval.sqrt();
        Some(std_in(
            "zaru-std",
            &o.zaru_std,
            Dimension::AngularRate,
            &schuler::domain::ANGULAR_RATE_STD,
            white,
        )?)
    } else {
        None
    };
    Ok(Some(RestConfig {
        source,
        std,
        interval,
        zaru_std,
    }))
}

/// The odometer's speed noise (`given` readings, those of `--odometer FILE` or the
/// bag's, put into `readings`) and its scale-factor prior (`--odometer-scale-std`).
fn odometer(
    o: &AidingOptions,
    given: Option<Vec<(f64, f64)>>,
    readings: &mut Vec<(f64, f64)>,
) -> Result<(Option<f64>, Option<f64>)> {
    let from_bag = o
        .bag
        .as_ref()
        .map(|b| &b.odometer)
        .filter(|v| !v.is_empty());
    let odometer_std = match (given, &o.odometer, from_bag) {
        (None, None, None) => None,
        (given, path, bag) => {
            *readings = match (given, path, bag) {
                (Some(given), _, _) => given,
                (None, Some(path), _) => schuler_io::formats::vehicle::read_odometer(path)?,
                (None, None, bag) => bag.cloned().unwrap_or_default(),
            };
            Some(std_in(
                "odometer-std",
                &o.odometer_std,
                Dimension::Velocity,
                &VELOCITY_STD,
                0.05,
            )?)
        }
    };
    let odometer_scale_std = match &o.odometer_scale_std {
        None => None,
        Some(_) => Some(positive(
            "odometer-scale-std",
            &o.odometer_scale_std,
            Dimension::Dimensionless,
            0.0,
        )?),
    };
    Ok((odometer_std, odometer_scale_std))
}

/// The angle of `--flag` in degrees (0 when not given) in radians, which must be
/// finite.
fn finite_degrees(flag: &str, v: Option<f64>) -> Result<f64> {
    let x = v.unwrap_or(0.0);
    if !x.is_finite() {
        bail!("--{flag} must be a finite angle in degrees, got {x}");
    }
    Ok(x.to_radians())
}

/// The dual-antenna baseline (with `given` headings or those of `--dual-antenna
/// FILE`, put into `headings`): yaw and pitch from the IMU's front, not within 1° of
/// the vertical.
fn heading_baseline(
    o: &AidingOptions,
    given: Option<Vec<HeadingReading>>,
    headings: &mut Vec<HeadingReading>,
) -> Result<Option<Baseline>> {
    if given.is_none() && o.dual_antenna.is_none() {
        return Ok(None);
    }
    let baseline = Baseline {
        yaw: finite_degrees("dual-antenna-baseline-yaw", o.dual_antenna_baseline_yaw)?,
        pitch: finite_degrees("dual-antenna-baseline-pitch", o.dual_antenna_baseline_pitch)?,
    };
    if baseline.pitch.abs() >= 89f64.to_radians() {
        bail!("--dual-antenna-baseline-pitch: a baseline within 1° of the vertical has no heading");
    }
    *headings = match (given, &o.dual_antenna) {
        (Some(given), _) => given,
        (None, Some(path)) => schuler_io::formats::vehicle::read_heading(path)?,
        (None, None) => Vec::new(),
    };
    Ok(Some(baseline))
}

/// Three numbers of `--flag` (zeros when not given), which must be finite.
fn finite_triple(flag: &str, v: &Option<crate::options::Triple>) -> Result<[f64; 3]> {
    let t = v.map_or([0.0; 3], |t| t.0);
    if t.iter().any(|x| !x.is_finite()) {
        bail!("--{flag} must be three finite numbers, got {t:?}");
    }
    Ok(t)
}

/// How the vehicle sits on the IMU: `--mounting-angles` [deg] and
/// `--vehicle-lever-arm` [m].
fn mount(o: &AidingOptions) -> Result<VehicleMount> {
    let [roll, pitch, yaw] = finite_triple("mounting-angles", &o.mounting_angles)?;
    let lever = finite_triple("vehicle-lever-arm", &o.vehicle_lever_arm)?;
    Ok(VehicleMount::new(
        Euler::from_degrees(roll, pitch, yaw),
        Vector3::from(lever),
    ))
}

/// Check the vehicle options and load their files; `given` readings stand in for
/// theirs.
pub fn resolve(
    o: &AidingOptions,
    noise: &ImuNoise,
    given: GivenVehicle,
) -> Result<(VehicleConfig, VehicleReadings)> {
    check_dependencies(o, &given)?;
    let mut readings = VehicleReadings::default();
    let rest = rest_config(o, noise, given.rests, &mut readings.rests)?;
    let nhc = if o.nhc {
        Some((
            std_in(
                "nhc-std",
                &o.nhc_std,
                Dimension::Velocity,
                &VELOCITY_STD,
                0.1,
            )?,
            positive("nhc-interval", &o.nhc_interval, Dimension::Time, 0.1)?,
        ))
    } else {
        None
    };
    let (odometer_std, odometer_scale_std) = odometer(o, given.odometer, &mut readings.odometer)?;
    let heading_baseline = heading_baseline(o, given.headings, &mut readings.headings)?;
    let mounting_std = match &o.estimate_mounting {
        None => None,
        Some(_) => Some(positive(
            "estimate-mounting",
            &o.estimate_mounting,
            Dimension::Angle,
            0.0,
        )?),
    };
    let config = VehicleConfig {
        mount: mount(o)?,
        rest,
        nhc,
        odometer_std,
        odometer_scale_std,
        heading_baseline,
        mounting_std,
    };
    Ok((config, readings))
}

/// The counts of accepted vehicle measurements, for the run's summary (`None` if
/// there were none).
pub fn summary(c: &Counts) -> Option<String> {
    let parts: Vec<String> = [
        (c.zupt, "zero-velocity"),
        (c.zaru, "zero-rate"),
        (c.nhc, "NHC"),
        (c.odometer, "odometer"),
        (c.heading, "heading"),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}"))
    .collect();
    (!parts.is_empty()).then(|| format!("vehicle updates: {}", parts.join(", ")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::GradeChoice;

    /// A temporary file holding `text`.
    fn temp_file(text: &str) -> tempfile::NamedTempFile {
        let f = tempfile::NamedTempFile::new().expect("temp");
        std::fs::write(f.path(), text).expect("write");
        f
    }

    /// Readings given in memory set the aids up as their files do: the same session
    /// configuration and the same readings pushed.
    #[test]
    fn given_readings_stand_for_their_files() {
        let noise = GradeChoice::Tactical.noise().expect("noise");
        let (rest, odo, heading) = (
            temp_file("0 60\n100.5 130\n"),
            temp_file("t,speed\n60.1 0.5\n60.2 -0.25\n"),
            temp_file("1 350 0.1\n2 10 0.2 -2 0.3\n"),
        );
        let tuning = AidingOptions {
            zaru: true,
            odometer_scale_std: Some("1 %".into()),
            dual_antenna_baseline_yaw: Some(90.0),
            ..Default::default()
        };
        let files = AidingOptions {
            zupt: Some(rest.path().into()),
            odometer: Some(odo.path().into()),
            dual_antenna: Some(heading.path().into()),
            ..tuning.clone()
        };
        let read = resolve(&files, &noise, GivenVehicle::default()).expect("files");
        let v = schuler_io::formats::vehicle::read_heading(heading.path()).expect("headings");
        let given = GivenVehicle {
            rests: Some(vec![(0.0, 60.0), (100.5, 130.0)]),
            odometer: Some(vec![(60.1, 0.5), (60.2, -0.25)]),
            headings: Some(v),
        };
        assert_eq!(
            resolve(&tuning, &noise, given.clone()).expect("given"),
            read
        );
        // Given readings win over a file, as given GNSS fixes do.
        let mut one = given.clone();
        one.odometer = Some(vec![(1.0, 2.0)]);
        let (_, r) = resolve(&files, &noise, one).expect("given over files");
        assert_eq!(r.odometer, vec![(1.0, 2.0)]);
        // Their options need them, and rests exclude the detector.
        let lone = AidingOptions {
            odometer_std: Some("0.05 m/s".into()),
            ..Default::default()
        };
        let e = resolve(&lone, &noise, GivenVehicle::default()).expect_err("no odometer");
        assert!(
            e.to_string().contains("--odometer-std needs --odometer"),
            "{e}"
        );
        let detect = AidingOptions {
            zupt_detect: true,
            ..Default::default()
        };
        let e = resolve(&detect, &noise, given).expect_err("both");
        assert!(e.to_string().contains("exclude each other"), "{e}");
    }
}
