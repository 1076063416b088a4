//! Vehicle aiding of `schuler nav` (flags or `[aiding]` keys): zero-velocity updates at
//! rest from a file of rest intervals or detected from the IMU, optionally with
//! zero-angular-rate updates; the non-holonomic constraint; odometer speed with an
//! optional scale-factor state; dual-antenna GNSS heading. [`resolve`] checks the
//! options and loads the files; [`VehicleRun`] applies the measurements after each IMU
//! sample of the loop in [`super::aided`]:
//!
//! - zero velocity (and rate) every `--zupt-interval` inside a rest interval (the
//!   whole interval's increments at rest), or at the end of each detector block whose
//!   1-s window is at rest while the navigation's speed is below `--zupt-max-speed`;
//! - the NHC every `--nhc-interval`;
//! - an odometer or heading reading at the sample ending nearest its time (the
//!   library's choice for the barometer too, [`schuler::filter::integration`]).
//!
//! Readings before the first sample or after the last are recorded as skipped in
//! `rejected.csv`.

use super::aided::{AidingOptions, quantity};
use anyhow::{Result, bail};
use nalgebra::Vector3;
use schuler::align::prefilter::BlockSums;
use schuler::align::{Gravity, RestDetector};
use schuler::earth::EarthModel;
use schuler::filter::integration::{Counts, SkipReason};
use schuler::filter::measurement::Kind;
use schuler::filter::{Baseline, HeadingReading, ImuNoise, Integrator, VehicleMount};
use schuler::imu::ImuSample;
use schuler::nav::ErrorFrame;
use schuler::rotation::Euler;
use schuler::units::Dimension;

/// Blocks in the rest detector's window.
const DETECTOR_WINDOW: usize = 10;

/// Where rests come from.
#[derive(Debug, Clone, PartialEq)]
pub enum RestSource {
    /// Given intervals `[t0, t1]` [s].
    Intervals(Vec<(f64, f64)>),
    /// Detected from the IMU (with this noise model), while the navigation's speed is
    /// at most `max_speed` [m/s].
    Detect {
        /// The IMU's noise model (the detector's thresholds).
        noise: ImuNoise,
        /// Largest navigation speed for an update [m/s].
        max_speed: f64,
    },
}

/// Zero-velocity (and zero-rate) updates.
#[derive(Debug, Clone, PartialEq)]
pub struct Rest {
    /// Where the rests come from.
    pub source: RestSource,
    /// Velocity standard deviation [m/s].
    pub std: f64,
    /// Time between updates, the detector's block [s].
    pub interval: f64,
    /// Standard deviation of the rate averaged over an interval [rad/s], for
    /// zero-rate updates; `None`: none.
    pub zaru_std: Option<f64>,
}

/// Vehicle aiding of a run, resolved and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleAiding {
    /// Mounting angles and the constraint point (NHC, odometer).
    pub mount: VehicleMount,
    /// Zero-velocity updates.
    pub rest: Option<Rest>,
    /// NHC: standard deviation [m/s] and time between updates [s].
    pub nhc: Option<(f64, f64)>,
    /// Odometer readings `(t, speed)` and their standard deviation [m/s].
    pub odometer: Option<(Vec<(f64, f64)>, f64)>,
    /// Prior standard deviation of the odometer scale factor (a state), if estimated.
    pub odometer_scale_std: Option<f64>,
    /// Dual-antenna readings and the baseline.
    pub heading: Option<(Vec<HeadingReading>, Baseline)>,
}

impl Default for VehicleAiding {
    fn default() -> Self {
        Self {
            mount: VehicleMount::aligned(),
            rest: None,
            nhc: None,
            odometer: None,
            odometer_scale_std: None,
            heading: None,
        }
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
            o.odometer.is_some(),
            "--odometer",
        ),
        (
            o.odometer_scale_std.is_some(),
            "odometer-scale-std",
            o.odometer.is_some(),
            "--odometer",
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

/// Check the vehicle options and load their files.
pub fn resolve(o: &AidingOptions, noise: &ImuNoise) -> Result<VehicleAiding> {
    check_dependencies(o)?;
    let positive = |flag: &str, v: &Option<String>, dim: Dimension, default: f64| {
        let x = quantity(flag, v, dim)?.unwrap_or(default);
        if x <= 0.0 {
            bail!("--{flag} must be positive, got {x}");
        }
        Ok(x)
    };
    let interval = positive("zupt-interval", &o.zupt_interval, Dimension::Time, 0.1)?;
    let source = match (&o.zupt, o.zupt_detect) {
        (Some(path), _) => Some(RestSource::Intervals(
            crate::formats::vehicle::read_rest_intervals(path)?,
        )),
        (None, true) => Some(RestSource::Detect {
            noise: *noise,
            max_speed: positive(
                "zupt-max-speed",
                &o.zupt_max_speed,
                Dimension::Velocity,
                0.5,
            )?,
        }),
        (None, false) => None,
    };
    let rest = match source {
        None => None,
        Some(source) => Some(Rest {
            source,
            std: positive("zupt-std", &o.zupt_std, Dimension::Velocity, 0.02)?,
            interval,
            zaru_std: if o.zaru {
                let white = noise.arw.max() / interval.sqrt();
                Some(positive(
                    "zaru-std",
                    &o.zaru_std,
                    Dimension::AngularRate,
                    white,
                )?)
            } else {
                None
            },
        }),
    };
    let nhc = if o.nhc {
        Some((
            positive("nhc-std", &o.nhc_std, Dimension::Velocity, 0.1)?,
            positive("nhc-interval", &o.nhc_interval, Dimension::Time, 0.1)?,
        ))
    } else {
        None
    };
    let odometer = match &o.odometer {
        None => None,
        Some(path) => Some((
            crate::formats::vehicle::read_odometer(path)?,
            positive("odometer-std", &o.odometer_std, Dimension::Velocity, 0.05)?,
        )),
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
    let finite = |flag: &str, v: Option<f64>| -> Result<f64> {
        let x = v.unwrap_or(0.0);
        if !x.is_finite() {
            bail!("--{flag} must be a finite angle in degrees, got {x}");
        }
        Ok(x.to_radians())
    };
    let heading = match &o.dual_antenna {
        None => None,
        Some(path) => {
            let baseline = Baseline {
                yaw: finite("dual-antenna-baseline-yaw", o.dual_antenna_baseline_yaw)?,
                pitch: finite("dual-antenna-baseline-pitch", o.dual_antenna_baseline_pitch)?,
            };
            if baseline.pitch.abs() >= 89f64.to_radians() {
                bail!(
                    "--dual-antenna-baseline-pitch: a baseline within 1° of the vertical has no heading"
                );
            }
            Some((crate::formats::vehicle::read_heading(path)?, baseline))
        }
    };
    let triple = |flag: &str, v: &Option<super::nav::Triple>| -> Result<[f64; 3]> {
        let t = v.map_or([0.0; 3], |t| t.0);
        if t.iter().any(|x| !x.is_finite()) {
            bail!("--{flag} must be three finite numbers, got {t:?}");
        }
        Ok(t)
    };
    let [roll, pitch, yaw] = triple("mounting-angles", &o.mounting_angles)?;
    let lever = triple("vehicle-lever-arm", &o.vehicle_lever_arm)?;
    Ok(VehicleAiding {
        mount: VehicleMount::new(Euler::from_degrees(roll, pitch, yaw), Vector3::from(lever)),
        rest,
        nhc,
        odometer,
        odometer_scale_std,
        heading,
    })
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

impl VehicleAiding {
    /// The integrator with the states these aids need (the odometer scale factor).
    pub fn configure<M: ErrorFrame, E: EarthModel>(
        &self,
        integ: Integrator<M, E>,
    ) -> Integrator<M, E> {
        match self.odometer_scale_std {
            Some(std) => integ.with_odometer_scale(std, 0.0),
            None => integ,
        }
    }

    /// The state of a run through the samples.
    pub fn start(&self) -> VehicleRun<'_> {
        let detector = match &self.rest {
            Some(Rest {
                source: RestSource::Detect { noise, .. },
                interval,
                ..
            }) => Some(RestDetector::new(noise, *interval, DETECTOR_WINDOW)),
            _ => None,
        };
        VehicleRun {
            aiding: self,
            detector,
            window: BlockSums::default(),
            next_rest: 0,
            next_odometer: 0,
            next_heading: 0,
            last_nhc: f64::NEG_INFINITY,
        }
    }
}

/// Where a run stands in the vehicle aids.
#[derive(Debug, Clone)]
pub struct VehicleRun<'a> {
    aiding: &'a VehicleAiding,
    detector: Option<RestDetector>,
    /// The increments at rest since the last zero-velocity update (intervals).
    window: BlockSums,
    next_rest: usize,
    next_odometer: usize,
    next_heading: usize,
    last_nhc: f64,
}

/// The readings of `times` due at a sample ending at `t` after `dt`: from `*next` up
/// to half a sample past `t`; those before the sample's half are past (skipped by the
/// caller). Returns the range and advances `*next`.
fn due(
    times: impl Fn(usize) -> Option<f64>,
    next: &mut usize,
    t: f64,
    dt: f64,
) -> std::ops::Range<usize> {
    let start = *next;
    while let Some(tr) = times(*next) {
        if tr > t + 0.5 * dt {
            break;
        }
        *next += 1;
    }
    start..*next
}

impl VehicleRun<'_> {
    /// Apply what is due after the sample `s` (raw, as read) was mechanized.
    pub fn after_sample<M: ErrorFrame, E: EarthModel>(
        &mut self,
        integ: &mut Integrator<M, E>,
        s: &ImuSample,
    ) {
        let a = self.aiding;
        let early = s.t - 0.5 * s.dt;
        if let Some((readings, std)) = &a.odometer {
            for i in due(
                |i| readings.get(i).map(|r| r.0),
                &mut self.next_odometer,
                s.t,
                s.dt,
            ) {
                let (t, speed) = readings[i];
                if t <= early {
                    integ.skip_measurement(t, Kind::Odometer, SkipReason::BeforeImu);
                } else {
                    integ.update_odometer(t, speed, *std, &a.mount);
                }
            }
        }
        if let Some((readings, baseline)) = &a.heading {
            for i in due(
                |i| readings.get(i).map(|r| r.t),
                &mut self.next_heading,
                s.t,
                s.dt,
            ) {
                let r = &readings[i];
                if r.t <= early {
                    integ.skip_measurement(r.t, Kind::Heading, SkipReason::BeforeImu);
                } else {
                    integ.update_heading(r, baseline);
                }
            }
        }
        if let Some((std, interval)) = a.nhc
            && s.t - self.last_nhc >= interval - 0.5 * s.dt
        {
            integ.update_non_holonomic(&a.mount, std);
            self.last_nhc = s.t;
        }
        if let Some(rest) = &a.rest {
            self.rest(integ, rest, s);
        }
    }

    fn rest<M: ErrorFrame, E: EarthModel>(
        &mut self,
        integ: &mut Integrator<M, E>,
        rest: &Rest,
        s: &ImuSample,
    ) {
        let block = match (&rest.source, self.detector.as_mut()) {
            (RestSource::Intervals(intervals), _) => {
                while intervals.get(self.next_rest).is_some_and(|iv| iv.1 < s.t) {
                    self.next_rest += 1;
                }
                let inside = intervals
                    .get(self.next_rest)
                    .is_some_and(|&(a, b)| s.t - s.dt >= a - 1e-9 && s.t <= b);
                if !inside {
                    self.window = BlockSums::default();
                    return;
                }
                self.window.add(s);
                if self.window.t < rest.interval - 0.5 * s.dt {
                    return;
                }
                std::mem::take(&mut self.window)
            }
            (RestSource::Detect { max_speed, .. }, Some(detector)) => {
                if !detector.push(s) {
                    return;
                }
                let frame = integ.mechanization().frame();
                let p = integ.covariance();
                let tilt = (p[(6, 6)] + p[(7, 7)]).max(0.0).sqrt();
                let f_rest = frame.q_bc.inverse() * Vector3::new(0.0, 0.0, -frame.gravity);
                let v = detector.verdict(Gravity::Body(f_rest, tilt), frame.w_ie_c.norm());
                if !v.rest || frame.v_c.norm() > *max_speed {
                    return;
                }
                v.block
            }
            (RestSource::Detect { .. }, None) => return,
        };
        integ.update_zero_velocity(rest.std);
        if let Some(std) = rest.zaru_std {
            let window = ImuSample {
                t: s.t,
                dt: block.t,
                dtheta: block.dtheta,
                dvel: block.dvel,
            };
            integ.update_zero_rate(&window, std);
        }
    }

    /// Record the readings after the IMU data as skipped.
    pub fn finish<M: ErrorFrame, E: EarthModel>(&mut self, integ: &mut Integrator<M, E>) {
        if let Some((readings, _)) = &self.aiding.odometer {
            for r in &readings[self.next_odometer..] {
                integ.skip_measurement(r.0, Kind::Odometer, SkipReason::AfterImu);
            }
            self.next_odometer = readings.len();
        }
        if let Some((readings, _)) = &self.aiding.heading {
            for r in &readings[self.next_heading..] {
                integ.skip_measurement(r.t, Kind::Heading, SkipReason::AfterImu);
            }
            self.next_heading = readings.len();
        }
    }
}
