//! Vehicle aiding of `schuler nav` (flags or `[aiding]` keys): zero-velocity updates at
//! rest from a file of rest intervals or detected from the IMU, optionally with
//! zero-angular-rate updates; the non-holonomic constraint; odometer speed with an
//! optional scale-factor state; dual-antenna GNSS heading. [`resolve`] checks the
//! options and loads the files into the session's [`VehicleConfig`] and the readings
//! the run pushes as aids; the library's session applies them
//! ([`schuler::session`]).

use super::AidingOptions;
use crate::options::quantity;
use anyhow::{Result, bail};
use nalgebra::Vector3;
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

/// Refuse options given without the aid they tune (e.g. `--nhc-std` without `--nhc`).
pub fn check_dependencies(o: &AidingOptions) -> Result<()> {
    for (given, flag, needs, main) in [
        (
            o.zupt_std.is_some(),
            "zupt-std",
            o.zupt.is_some() || o.zupt_detect,
            "--zupt or --zupt-detect",
        ),
        (
            o.zupt_interval.is_some(),
            "zupt-interval",
            o.zupt.is_some() || o.zupt_detect,
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
            o.zupt.is_some() || o.zupt_detect,
            "--zupt or --zupt-detect",
        ),
        (o.zaru_std.is_some(), "zaru-std", o.zaru, "--zaru"),
        (o.nhc_std.is_some(), "nhc-std", o.nhc, "--nhc"),
        (o.nhc_interval.is_some(), "nhc-interval", o.nhc, "--nhc"),
        (
            o.odometer_std.is_some(),
            "odometer-std",
            o.has_odometer(),
            "--odometer",
        ),
        (
            o.odometer_scale_std.is_some(),
            "odometer-scale-std",
            o.has_odometer(),
            "--odometer",
        ),
        (
            o.estimate_mounting.is_some(),
            "estimate-mounting",
            o.nhc || o.has_odometer(),
            "--nhc or --odometer",
        ),
        (
            o.dual_antenna_baseline_yaw.is_some(),
            "dual-antenna-baseline-yaw",
            o.dual_antenna.is_some(),
            "--dual-antenna",
        ),
        (
            o.dual_antenna_baseline_pitch.is_some(),
            "dual-antenna-baseline-pitch",
            o.dual_antenna.is_some(),
            "--dual-antenna",
        ),
    ] {
        if given && !needs {
            bail!("--{flag} needs {main}");
        }
    }
    if o.zupt.is_some() && o.zupt_detect {
        bail!("--zupt FILE and --zupt-detect exclude each other");
    }
    Ok(())
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

/// Zero-velocity updates (`--zupt FILE`, its intervals read into `rests`, or
/// `--zupt-detect`) with their noise, interval and optional zero-rate updates; `None`
/// without either.
fn rest_config(
    o: &AidingOptions,
    noise: &ImuNoise,
    rests: &mut Vec<(f64, f64)>,
) -> Result<Option<RestConfig>> {
    let interval = positive("zupt-interval", &o.zupt_interval, Dimension::Time, 0.1)?;
    let source = match (&o.zupt, o.zupt_detect) {
        (Some(path), _) => {
            *rests = crate::formats::vehicle::read_rest_intervals(path)?;
            RestSource::Intervals
        }
        (None, true) => RestSource::Detect {
            noise: *noise,
            max_speed: positive(
                "zupt-max-speed",
                &o.zupt_max_speed,
                Dimension::Velocity,
                0.5,
            )?,
        },
        (None, false) => return Ok(None),
    };
    let std = positive("zupt-std", &o.zupt_std, Dimension::Velocity, 0.02)?;
    let zaru_std = if o.zaru {
        // Default: the gyro's white noise averaged over one interval.
        let white = noise.arw.max() / interval.sqrt();
        Some(positive(
            "zaru-std",
            &o.zaru_std,
            Dimension::AngularRate,
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

/// The odometer's speed noise (`--odometer FILE`, its readings read into `readings`)
/// and its scale-factor prior (`--odometer-scale-std`).
fn odometer(
    o: &AidingOptions,
    readings: &mut Vec<(f64, f64)>,
) -> Result<(Option<f64>, Option<f64>)> {
    let from_bag = o
        .bag
        .as_ref()
        .map(|b| &b.odometer)
        .filter(|v| !v.is_empty());
    let odometer_std = match (&o.odometer, from_bag) {
        (None, None) => None,
        (path, bag) => {
            *readings = match (path, bag) {
                (Some(path), _) => crate::formats::vehicle::read_odometer(path)?,
                (None, bag) => bag.cloned().unwrap_or_default(),
            };
            Some(positive(
                "odometer-std",
                &o.odometer_std,
                Dimension::Velocity,
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

/// The dual-antenna baseline (`--dual-antenna FILE`, its headings read into
/// `headings`): yaw and pitch from the IMU's front, not within 1° of the vertical.
fn heading_baseline(
    o: &AidingOptions,
    headings: &mut Vec<HeadingReading>,
) -> Result<Option<Baseline>> {
    let Some(path) = &o.dual_antenna else {
        return Ok(None);
    };
    let baseline = Baseline {
        yaw: finite_degrees("dual-antenna-baseline-yaw", o.dual_antenna_baseline_yaw)?,
        pitch: finite_degrees("dual-antenna-baseline-pitch", o.dual_antenna_baseline_pitch)?,
    };
    if baseline.pitch.abs() >= 89f64.to_radians() {
        bail!("--dual-antenna-baseline-pitch: a baseline within 1° of the vertical has no heading");
    }
    *headings = crate::formats::vehicle::read_heading(path)?;
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

/// Check the vehicle options and load their files.
pub fn resolve(o: &AidingOptions, noise: &ImuNoise) -> Result<(VehicleConfig, VehicleReadings)> {
    check_dependencies(o)?;
    let mut readings = VehicleReadings::default();
    let rest = rest_config(o, noise, &mut readings.rests)?;
    let nhc = if o.nhc {
        Some((
            positive("nhc-std", &o.nhc_std, Dimension::Velocity, 0.1)?,
            positive("nhc-interval", &o.nhc_interval, Dimension::Time, 0.1)?,
        ))
    } else {
        None
    };
    let (odometer_std, odometer_scale_std) = odometer(o, &mut readings.odometer)?;
    let heading_baseline = heading_baseline(o, &mut readings.headings)?;
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
