//! What a [`super::Session`] is told before it starts: the mechanization and its
//! hand-over latitudes, the output cadence, the reorder window for aids, and the
//! optional filter (with its vehicle aids) or, without a filter, the seed's baro loop.
//! [`SessionConfig::validate`] checks every value and names the field it refuses.

use crate::channel::detector::DetectorConfig;
use crate::channel::vertical::Gains;
use crate::domain::{self, Domain};
use crate::filter::{Baseline, Gate, ImuNoise, IntegrationConfig, VehicleMount};
use nalgebra::{SMatrix, Vector3};

/// A configuration value the session refuses: the field's path (e.g.
/// `filter.integration.init_pos_std`) and why. Front ends map the path to their own
/// names (a flag, a YAML key, a keyword argument).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {reason}")]
pub struct ConfigError {
    /// The field, as a dotted path from [`SessionConfig`].
    pub field: &'static str,
    /// What is wrong with its value.
    pub reason: String,
}

impl ConfigError {
    pub(super) fn new(field: &'static str, reason: impl Into<String>) -> Self {
        Self {
            field,
            reason: reason.into(),
        }
    }
}

/// Which strapdown mechanization integrates the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MechanizationChoice {
    /// Local-level NED (latitude, longitude): singular at the poles.
    Ned,
    /// The all-latitude free-azimuth (wander) frame with quaternion position (seed 003).
    Wander,
    /// NED up to [`MechanizationConfig::auto_latitude`], wander above it (hand-over
    /// both ways with hysteresis, the filter carried over).
    #[default]
    Auto,
}

/// Which mechanization is running.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MechanizationKind {
    /// [`crate::nav::LocalLevel`] (NED).
    Ned,
    /// [`crate::nav::Wander`].
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

/// The mechanization and, for [`MechanizationChoice::Auto`], its switching latitudes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MechanizationConfig {
    /// NED, wander or automatic.
    pub choice: MechanizationChoice,
    /// `Auto` hands over to wander when `|lat|` exceeds this [rad] (default 75°).
    pub auto_latitude: f64,
    /// `Auto` hands back to NED when `|lat|` falls below `auto_latitude − hysteresis`
    /// [rad] (default 0.5°).
    pub hysteresis: f64,
}

impl MechanizationConfig {
    /// Default `auto` switching latitude [deg].
    pub const AUTO_LATITUDE_DEG: f64 = 75.0;
    /// Default hysteresis of the hand-back [deg]: 55 km of latitude, so a flight
    /// along the threshold does not hand over at every sample.
    pub const HYSTERESIS_DEG: f64 = 0.5;
}

impl Default for MechanizationConfig {
    fn default() -> Self {
        Self {
            choice: MechanizationChoice::Auto,
            auto_latitude: Self::AUTO_LATITUDE_DEG.to_radians(),
            hysteresis: Self::HYSTERESIS_DEG.to_radians(),
        }
    }
}

/// Zero-velocity (and zero-rate) updates: where the rests come from.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(clippy::large_enum_variant)] // a configuration value, copied once per session
pub enum RestSource {
    /// Rest intervals pushed as [`super::Aid::Rest`].
    Intervals,
    /// Detected from the IMU (thresholds from this noise model) while the navigation's
    /// speed is at most `max_speed` [m/s].
    Detect {
        /// The IMU's noise model (the detector's thresholds).
        noise: ImuNoise,
        /// Largest navigation speed for an update [m/s].
        max_speed: f64,
    },
}

/// Zero-velocity (and zero-rate) updates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestConfig {
    /// Where the rests come from.
    pub source: RestSource,
    /// Velocity standard deviation [m/s].
    pub std: f64,
    /// Time between updates inside a rest, the detector's block [s].
    pub interval: f64,
    /// Standard deviation of the rate averaged over an interval [rad/s], for zero-rate
    /// updates; `None`: none.
    pub zaru_std: Option<f64>,
}

/// Vehicle aiding: constraints the session applies by itself and the readings it
/// accepts as aids.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleConfig {
    /// Mounting angles and the point the NHC and the odometer speak of.
    pub mount: VehicleMount,
    /// Zero-velocity updates.
    pub rest: Option<RestConfig>,
    /// Non-holonomic constraint: standard deviation [m/s] and time between updates [s].
    pub nhc: Option<(f64, f64)>,
    /// Standard deviation of an odometer speed [m/s]; `None`: odometer aids ignored.
    pub odometer_std: Option<f64>,
    /// Prior standard deviation of the odometer scale factor (a state), if estimated.
    pub odometer_scale_std: Option<f64>,
    /// The dual-antenna baseline; `None`: heading aids ignored.
    pub heading_baseline: Option<Baseline>,
    /// Estimate the vehicle frame's pitch and yaw relative to `mount` with this prior
    /// standard deviation [rad] (two filter states; needs the NHC or the odometer).
    pub mounting_std: Option<f64>,
}

impl VehicleConfig {
    /// Whether any vehicle aid is configured.
    pub fn any(&self) -> bool {
        self.rest.is_some()
            || self.nhc.is_some()
            || self.odometer_std.is_some()
            || self.heading_baseline.is_some()
            || self.odometer_scale_std.is_some()
    }
}

impl Default for VehicleConfig {
    fn default() -> Self {
        Self {
            mount: VehicleMount::aligned(),
            rest: None,
            nhc: None,
            odometer_std: None,
            odometer_scale_std: None,
            heading_baseline: None,
            mounting_std: None,
        }
    }
}

/// The filter's error model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ErrorModelChoice {
    /// The psi-angle model ([`crate::filter::error_model`]): 15 states, 21 with
    /// [`IntegrationConfig::scale_factors`].
    #[default]
    Psi,
    /// The flight-test paper's 18 states ([`crate::filter::seed18`]), on the wander
    /// mechanization only, with GNSS position and velocity only.
    Seed18,
}

/// The error-state filter of an aided session.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterConfig {
    /// The filter's settings (noise, prior, lever arm, gate, barometer bias state).
    pub integration: IntegrationConfig,
    /// Standard deviation of a barometric height [m] (with `integration.baro`).
    pub baro_std: f64,
    /// Keep what the Rauch–Tung–Striebel smoother needs; [`super::Session::finish`]
    /// then returns the smoothed trajectory at the output epochs.
    pub smooth: bool,
    /// Vehicle aiding.
    pub vehicle: VehicleConfig,
    /// The joint prior covariance of attitude error (about north, east, down), gyro
    /// and accelerometer biases, overriding `integration`'s standard deviations of
    /// these (an alignment's, [`super::Prior::from_alignment`]).
    pub att_bias_cov: Option<SMatrix<f64, 9, 9>>,
    /// The error model (psi-angle by default).
    pub error_model: ErrorModelChoice,
}

impl FilterConfig {
    /// A filter with `integration`'s settings, barometer noise 0.5 m, no smoother and
    /// no vehicle aids.
    pub fn new(integration: IntegrationConfig) -> Self {
        Self {
            integration,
            baro_std: 0.5,
            smooth: false,
            vehicle: VehicleConfig::default(),
            att_bias_cov: None,
            error_model: ErrorModelChoice::Psi,
        }
    }
}

/// The seed's baro loop on the vertical channel of free-inertial navigation
/// ([`crate::nav::BaroLoop`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaroLoopConfig {
    /// Feedback gains (34).
    pub gains: Gains,
    /// The fault detector on the reference height.
    pub detector: DetectorConfig,
}

/// The physical envelope of a solution: leaving it means the navigation has failed (a
/// wrong input, a diverged free-inertial solution), and the session warns once per
/// bound with the time ([`super::Event::Envelope`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    /// Lowest plausible height [m] (default −1 km: below the Dead Sea shore by far).
    pub min_height: f64,
    /// Highest plausible height [m] (default 100 km: the edge of space).
    pub max_height: f64,
    /// Highest plausible speed [m/s] (default Mach 3 at sea level, 1029 m/s).
    pub max_speed: f64,
}

impl Default for Envelope {
    fn default() -> Self {
        Self {
            min_height: -1000.0,
            max_height: 100_000.0,
            max_speed: 3.0 * 343.0,
        }
    }
}

/// Everything a session needs besides its start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SessionConfig {
    /// The mechanization and its hand-over.
    pub mechanization: MechanizationConfig,
    /// Output rate [Hz] (the first epoch at or after each multiple of `1/rate`);
    /// `None`: every sample.
    pub output_rate: Option<f64>,
    /// How long [s] IMU samples wait before they are integrated, so that aids arriving
    /// up to this much after their time are still applied at it (0: at once; aids must
    /// then arrive before the samples they fall in).
    pub reorder_window: f64,
    /// The filter; `None`: free-inertial navigation.
    pub filter: Option<FilterConfig>,
    /// Free-inertial only: the seed's baro loop on the vertical channel, fed by
    /// barometer aids.
    pub baro_loop: Option<BaroLoopConfig>,
    /// Cadence [Hz] of the filter's snapshots (sensor errors, covariance, NEES
    /// against a truth) kept for reports; default 1 Hz; 0: none (the forward run
    /// then keeps nothing per epoch: constant memory).
    pub snapshot_rate: f64,
    /// The envelope checked at every output epoch; `None`: no check (space, missiles).
    pub envelope: Option<Envelope>,
}

impl Default for SessionConfig {
    fn default() -> Self {
        Self {
            mechanization: MechanizationConfig::default(),
            output_rate: None,
            reorder_window: 0.0,
            filter: None,
            baro_loop: None,
            snapshot_rate: 1.0,
            envelope: Some(Envelope::default()),
        }
    }
}

fn positive(field: &'static str, x: f64) -> Result<(), ConfigError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(ConfigError::new(
            field,
            format!("must be a positive finite number, got {x}"),
        ))
    }
}

fn non_negative(field: &'static str, x: f64) -> Result<(), ConfigError> {
    if x.is_finite() && x >= 0.0 {
        Ok(())
    } else {
        Err(ConfigError::new(
            field,
            format!("must be a finite number, not negative, got {x}"),
        ))
    }
}

/// `x` within `d` (a lower bound of 0 for a magnitude or a noise density).
pub(super) fn within(field: &'static str, d: &Domain, x: f64) -> Result<(), ConfigError> {
    d.check(x)
        .map(|_| ())
        .map_err(|e| ConfigError::new(field, e.to_string()))
}

/// Every component of `v` within `d`.
pub(super) fn each_within(
    field: &'static str,
    d: &Domain,
    v: &Vector3<f64>,
) -> Result<(), ConfigError> {
    v.iter().try_for_each(|&x| within(field, d, x))
}

/// The domain of a noise term's magnitude: from 0 to `max`'s bound, since a 1-s
/// sigma beyond the sensor's range is no sensor.
const fn noise(max: &Domain) -> Domain {
    Domain {
        quantity: "noise",
        min: 0.0,
        why: "at most the sensor's range",
        ..*max
    }
}

/// The domains of the gyro bias, accelerometer bias, gyro and accelerometer
/// scale-factor noise terms (and their initial standard deviations).
const SENSOR_NOISE: [Domain; 4] = [
    noise(&domain::ANGULAR_RATE),
    noise(&domain::SPECIFIC_FORCE),
    noise(&domain::SCALE_FACTOR),
    noise(&domain::SCALE_FACTOR),
];

/// Check every term of the IMU noise model.
fn validate_noise(n: &ImuNoise) -> Result<(), ConfigError> {
    let [rate, force, scale, _] = SENSOR_NOISE;
    for (field, d, v) in [
        ("filter.integration.noise.arw", &rate, &n.arw),
        ("filter.integration.noise.vrw", &force, &n.vrw),
        ("filter.integration.noise.gyro_bias", &rate, &n.gyro_bias),
        ("filter.integration.noise.accel_bias", &force, &n.accel_bias),
        (
            "filter.integration.noise.gyro_bias_walk",
            &rate,
            &n.gyro_bias_walk,
        ),
        (
            "filter.integration.noise.accel_bias_walk",
            &force,
            &n.accel_bias_walk,
        ),
        ("filter.integration.noise.gyro_scale", &scale, &n.gyro_scale),
        (
            "filter.integration.noise.accel_scale",
            &scale,
            &n.accel_scale,
        ),
    ] {
        each_within(field, d, v)?;
    }
    for (field, tau) in [
        ("filter.integration.noise.gyro_bias_tau", n.gyro_bias_tau),
        ("filter.integration.noise.accel_bias_tau", n.accel_bias_tau),
        ("filter.integration.noise.scale_tau", n.scale_tau),
    ] {
        // An infinite correlation time is a random walk.
        if tau.is_nan() || tau <= 0.0 {
            return Err(ConfigError::new(
                field,
                format!("must be positive, got {tau}"),
            ));
        }
    }
    Ok(())
}

impl SessionConfig {
    /// Check every value; the error names the first field refused.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let m = &self.mechanization;
        if !(m.auto_latitude.is_finite()
            && m.auto_latitude > 0.0
            && m.auto_latitude < std::f64::consts::FRAC_PI_2)
        {
            return Err(ConfigError::new(
                "mechanization.auto_latitude",
                format!(
                    "must be between 0 and 90 deg (exclusive), got {} deg",
                    m.auto_latitude.to_degrees()
                ),
            ));
        }
        if !(m.hysteresis.is_finite() && m.hysteresis >= 0.0 && m.hysteresis < m.auto_latitude) {
            return Err(ConfigError::new(
                "mechanization.hysteresis",
                format!(
                    "must be at least 0 and below the switching latitude ({} deg), got {} deg",
                    m.auto_latitude.to_degrees(),
                    m.hysteresis.to_degrees()
                ),
            ));
        }
        if let Some(r) = self.output_rate {
            positive("output_rate", r)?;
        }
        non_negative("reorder_window", self.reorder_window)?;
        non_negative("snapshot_rate", self.snapshot_rate)?;
        if let Some(e) = &self.envelope
            && !(e.min_height < e.max_height && e.max_speed > 0.0)
        {
            return Err(ConfigError::new(
                "envelope",
                format!("needs min_height < max_height and a positive max_speed, got {e:?}"),
            ));
        }
        if let Some(b) = &self.baro_loop {
            if self.filter.is_some() {
                return Err(ConfigError::new(
                    "baro_loop",
                    "the baro loop damps free-inertial navigation; with a filter the barometer is a filter measurement",
                ));
            }
            if !(b.gains.k1 < 0.0 && b.gains.k1.is_finite() && b.gains.k2.is_finite()) {
                return Err(ConfigError::new(
                    "baro_loop.gains",
                    format!("k1 must be negative and both finite, got {:?}", b.gains),
                ));
            }
            non_negative("baro_loop.detector.gate", b.detector.gate)?;
        }
        if let Some(f) = &self.filter {
            f.validate()?;
            if f.error_model == ErrorModelChoice::Seed18 {
                self.validate_seed18(f)?;
            }
        }
        Ok(())
    }

    /// What the 18-state model needs: the wander mechanization throughout (it has no
    /// NED form to hand over to), GNSS only, no smoother.
    fn validate_seed18(&self, f: &FilterConfig) -> Result<(), ConfigError> {
        let field = "filter.error_model";
        if self.mechanization.choice != MechanizationChoice::Wander {
            return Err(ConfigError::new(
                field,
                "seed18 runs only on the wander mechanization (its states are the wander quaternions); choose the wander mechanization",
            ));
        }
        if let Err(e) = crate::filter::seed18::check(&f.integration) {
            return Err(ConfigError::new(field, e.to_string()));
        }
        let refuse = |what: &str| {
            Err(ConfigError::new(
                field,
                format!("seed18 has no {what}; use psi15 or psi21"),
            ))
        };
        if f.smooth {
            return refuse("smoother");
        }
        if f.integration.calibration.any() || f.integration.gnss_time_offset != 0.0 {
            return refuse("lever-arm or time-offset calibration");
        }
        if f.vehicle.any() {
            return refuse("vehicle aids (zero velocity, non-holonomic, odometer, heading)");
        }
        Ok(())
    }
}

impl FilterConfig {
    /// Check every value of the filter and its vehicle aids.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let c = &self.integration;
        let n = &c.noise;
        validate_noise(n)?;
        each_within(
            "filter.integration.lever_arm",
            &domain::LEVER_ARM,
            &c.lever_arm,
        )?;
        if let Gate::Level(a) = c.gate
            && !(a > 0.0 && a < 1.0)
        {
            return Err(ConfigError::new(
                "filter.integration.gate",
                format!("a significance level must be in (0, 1), got {a}"),
            ));
        }
        positive(
            "filter.integration.propagation_interval",
            c.propagation_interval,
        )?;
        for (field, d, v) in [
            (
                "filter.integration.init_pos_std",
                &domain::POSITION_STD,
                &c.init_pos_std,
            ),
            (
                "filter.integration.init_vel_std",
                &domain::VELOCITY_STD,
                &c.init_vel_std,
            ),
            (
                "filter.integration.init_att_std",
                &domain::ANGLE_STD,
                &c.init_att_std,
            ),
        ] {
            each_within(field, d, v)?;
        }
        if let Some(sd) = &c.init_sensor_std {
            for (v, d) in sd.iter().zip(&SENSOR_NOISE) {
                each_within("filter.integration.init_sensor_std", d, v)?;
            }
        }
        if let Some(p) = &self.att_bias_cov {
            let symmetric = (p - p.transpose()).abs().max() <= 1e-12 * p.abs().max();
            if !(p.iter().all(|x| x.is_finite()) && symmetric && (*p).cholesky().is_some()) {
                return Err(ConfigError::new(
                    "filter.att_bias_cov",
                    "must be a finite, symmetric, positive definite covariance",
                ));
            }
        }
        if let Some((std, walk)) = c.baro {
            positive("filter.integration.baro", std)?;
            non_negative("filter.integration.baro", walk)?;
            positive("filter.baro_std", self.baro_std)?;
        }
        within(
            "filter.integration.gnss_time_offset",
            &domain::GNSS_TIME_OFFSET,
            c.gnss_time_offset,
        )?;
        let cal = &c.calibration;
        if let Some(std) = cal.lever_arm_std {
            positive("filter.integration.calibration.lever_arm_std", std)?;
            within(
                "filter.integration.calibration.lever_arm_std",
                &domain::LEVER_ARM,
                std,
            )?;
        }
        if let Some(std) = cal.time_offset_std {
            positive("filter.integration.calibration.time_offset_std", std)?;
            within(
                "filter.integration.calibration.time_offset_std",
                &domain::GNSS_TIME_OFFSET,
                std,
            )?;
        }
        non_negative(
            "filter.integration.calibration.time_offset_walk",
            cal.time_offset_walk,
        )?;
        self.vehicle.validate()
    }
}

impl VehicleConfig {
    /// Check every value of the vehicle aids (fields named from the session config).
    fn validate(&self) -> Result<(), ConfigError> {
        let v = self;
        each_within(
            "filter.vehicle.mount.lever",
            &domain::LEVER_ARM,
            &v.mount.lever,
        )?;
        if !v.mount.q_vb.coords.iter().all(|x| x.is_finite()) {
            return Err(ConfigError::new(
                "filter.vehicle.mount.q_vb",
                "the mounting angles must be finite",
            ));
        }
        if let Some(r) = &v.rest {
            positive("filter.vehicle.rest.std", r.std)?;
            positive("filter.vehicle.rest.interval", r.interval)?;
            if let Some(z) = r.zaru_std {
                positive("filter.vehicle.rest.zaru_std", z)?;
            }
            if let RestSource::Detect { max_speed, .. } = r.source {
                positive("filter.vehicle.rest.max_speed", max_speed)?;
            }
        }
        if let Some((std, interval)) = v.nhc {
            positive("filter.vehicle.nhc.std", std)?;
            positive("filter.vehicle.nhc.interval", interval)?;
        }
        if let Some(s) = v.odometer_std {
            positive("filter.vehicle.odometer_std", s)?;
        }
        if let Some(s) = v.odometer_scale_std {
            positive("filter.vehicle.odometer_scale_std", s)?;
        }
        if let Some(s) = v.mounting_std {
            positive("filter.vehicle.mounting_std", s)?;
            if v.nhc.is_none() && v.odometer_std.is_none() {
                return Err(ConfigError::new(
                    "filter.vehicle.mounting_std",
                    "the mounting is observed through the NHC or the odometer: configure one",
                ));
            }
        }
        if let Some(b) = &v.heading_baseline
            && !(b.yaw.is_finite() && b.pitch.is_finite() && b.pitch.abs() < 89f64.to_radians())
        {
            return Err(ConfigError::new(
                "filter.vehicle.heading_baseline",
                "finite angles with the baseline more than 1 deg from the vertical",
            ));
        }
        Ok(())
    }
}
