//! Option types shared by the commands: comma-separated triples, the Earth model,
//! the IMU file's format and layout, the mechanization, the IMU grade, and quantities
//! with units; each parsed from flags and TOML alike. Also the textbook commands' flag
//! values with units and the textbook sphere (`schuler channel`, `schuler vertical`).

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use schuler::earth::Sphere;
use schuler::filter::ImuNoise;
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use schuler::units::{self, Dimension};
use schuler_io::formats::{ImuFormat, ImuLayout};
use schuler_io::named::Named;
use serde::Deserialize;

/// A flag's parser for a [`Named`] type: its names offered (with their descriptions
/// in `--help`) and read, as clap's `ValueEnum` does for the option types here.
pub fn named<T>() -> impl clap::builder::TypedValueParser<Value = T>
where
    T: Named + Send + Sync + Clone,
{
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    let values = T::VALUES
        .iter()
        .map(|(_, name, help)| PossibleValue::new(*name).help(*help));
    PossibleValuesParser::new(values).try_map(|s| T::from_name(&s).ok_or("not a listed value"))
}

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
    /// WGS84 ellipsoid with the GRS80 normal gravity series KF-GINS uses
    /// ([`schuler::earth::Wgs84Series`]); chosen by `--gravity kf-gins`.
    #[value(skip)]
    #[serde(skip)]
    Wgs84Series,
}

impl EarthChoice {
    /// The model with normal gravity `gravity` (only WGS84 has a choice; `None`
    /// keeps the model's own).
    pub fn with_gravity(self, gravity: Option<GravityChoice>) -> Result<Self, String> {
        match (self, gravity) {
            (_, None) => Ok(self),
            (Self::Wgs84 | Self::Wgs84Series, Some(GravityChoice::Tr8350)) => Ok(Self::Wgs84),
            (Self::Wgs84 | Self::Wgs84Series, Some(GravityChoice::KfGins)) => Ok(Self::Wgs84Series),
            (Self::Sphere | Self::SphereFixed, Some(_)) => Err(
                "--gravity chooses the normal gravity of --earth wgs84; the sphere has its own"
                    .to_owned(),
            ),
        }
    }
}

/// Normal gravity on the WGS84 ellipsoid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GravityChoice {
    /// NIMA TR8350.2's closed form (Somigliana with its height series): the default
    /// of `schuler nav`.
    Tr8350,
    /// The GRS80 series in sin^2(lat) with a second-order height term, as KF-GINS
    /// computes it: the default of `--kf-gins-config`.
    KfGins,
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

/// The filter's error model (`--error-model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ErrorModelArg {
    /// The psi-angle model: position, velocity, attitude errors, gyro and
    /// accelerometer biases (15 states).
    #[default]
    Psi15,
    /// psi15 with gyro and accelerometer scale factors (21 states, as
    /// `--scale-factors`).
    Psi21,
    /// The flight-test paper's 18 states (seed 003): velocity, the navigation and
    /// orientation quaternions' errors, drifts, biases, height; wander mechanization
    /// only, GNSS position and velocity only, no lever arm.
    Seed18,
}

/// Which strapdown mechanization integrates the log (`--mechanization`).
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

impl MechanizationChoice {
    /// The library's choice.
    pub fn session(self) -> schuler::session::MechanizationChoice {
        match self {
            Self::Ned => schuler::session::MechanizationChoice::Ned,
            Self::Wander => schuler::session::MechanizationChoice::Wander,
            Self::Auto => schuler::session::MechanizationChoice::Auto,
        }
    }
}

/// IMU grade whose noise model the filter assumes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum GradeChoice {
    /// FOG/RLG: 0.01 deg/h, 50 ug, 0.002 deg/sqrt(h).
    #[default]
    Navigation,
    /// 1 deg/h, 1 mg, 0.1 deg/sqrt(h).
    Tactical,
    /// 10 deg/h, 5 mg, 0.5 deg/sqrt(h).
    ConsumerMems,
}

impl GradeChoice {
    /// The grade's noise statistics (the simulator's presets, `schuler::sim::sensor_spec`).
    pub fn noise(self) -> Result<ImuNoise> {
        let preset = match self {
            GradeChoice::Navigation => Preset::Navigation,
            GradeChoice::Tactical => Preset::Tactical,
            GradeChoice::ConsumerMems => Preset::ConsumerMems,
        };
        let spec = ImuSpec {
            rate_hz: 1.0,
            preset: Some(preset),
            gyro: Default::default(),
            accel: Default::default(),
            g_sensitivity: None,
            vibration: Vec::new(),
        };
        Ok(ImuNoise::from_model(&spec.model()?))
    }
}

/// `value` [SI] of a flag or key `key` if it is in `domain` (a number of
/// [`schuler::domain`]); else the error naming the key.
pub fn in_domain(key: &str, domain: &schuler::domain::Domain, value: f64) -> Result<f64> {
    domain.check(value).with_context(|| key.to_owned())
}

/// `Some(x)` [SI] of a flag or key `key` if `x` is in `domain`, else the error naming it.
pub fn opt_in_domain(
    key: &str,
    domain: &schuler::domain::Domain,
    value: Option<f64>,
) -> Result<Option<f64>> {
    value.map(|x| in_domain(key, domain, x)).transpose()
}

/// A count of a flag or key `key` within `count` (the bounded-count rule of
/// [`schuler::domain::Count`]); else the error naming the key.
pub fn in_count(key: &str, count: &schuler::domain::Count, value: u64) -> Result<u64> {
    count.check(value).with_context(|| key.to_owned())
}

/// A rate flag [Hz] within `domain` (an IMU's or an aid's rate, [`schuler::domain`]).
pub fn rate(flag: &str, domain: &schuler::domain::Domain, r: Option<f64>) -> Result<Option<f64>> {
    opt_in_domain(&format!("--{flag}"), domain, r)
}

/// The value of an aiding option given with a unit (or as a bare SI number), checked
/// finite and not negative; errors name the flag.
pub fn quantity(
    flag: &str,
    v: &Option<String>,
    dim: schuler::units::Dimension,
) -> Result<Option<f64>> {
    let Some(s) = v else { return Ok(None) };
    let x = schuler::units::parse_as_or_si(s, dim).with_context(|| format!("--{flag} {s:?}"))?;
    if !(x.is_finite() && x >= 0.0) {
        bail!("--{flag} must not be negative, got {s:?}");
    }
    Ok(Some(x))
}

/// [`quantity`] within `domain` (its physical range, [`schuler::domain`]); errors name
/// the flag.
pub fn quantity_in(
    flag: &str,
    v: &Option<String>,
    dim: schuler::units::Dimension,
    domain: &schuler::domain::Domain,
) -> Result<Option<f64>> {
    opt_in_domain(&format!("--{flag}"), domain, quantity(flag, v, dim)?)
}

/// `domain` with zero allowed: a noise model's standard deviation or density may be
/// zero (a perfect sensor), a measurement's may not.
pub const fn or_zero(domain: schuler::domain::Domain) -> schuler::domain::Domain {
    schuler::domain::Domain { min: 0.0, ..domain }
}

// ---------------------------------------------------------------------------------------
// Flag values with units (`schuler channel`, `schuler vertical`).

/// A flag value with a unit of dimension `dim`, in SI.
fn unit_value(s: &str, dim: Dimension) -> Result<f64, String> {
    units::parse_as(s, dim).map_err(|e| e.to_string())
}

/// An acceleration with its unit (`1e-3m/s^2`, `100ug`, `1mGal`) in m/s^2.
pub fn acceleration(s: &str) -> Result<f64, String> {
    unit_value(s, Dimension::Acceleration)
}

/// An angular rate with its unit (`0.01deg/h`, `6deg/s`) in rad/s.
pub fn angular_rate(s: &str) -> Result<f64, String> {
    unit_value(s, Dimension::AngularRate)
}

/// An angle with its unit (`20arcsec`, `180deg`) in rad.
pub fn angle(s: &str) -> Result<f64, String> {
    unit_value(s, Dimension::Angle)
}

/// A velocity with its unit (`1m/s`, `250kn`) in m/s.
pub fn velocity(s: &str) -> Result<f64, String> {
    unit_value(s, Dimension::Velocity)
}

/// A length with its unit (`100m`, `6371km`) in m.
pub fn length(s: &str) -> Result<f64, String> {
    unit_value(s, Dimension::Length)
}

/// A time with its unit (`4h`, `0.1s`) in s.
pub fn time(s: &str) -> Result<f64, String> {
    unit_value(s, Dimension::Time)
}

/// A ratio: a bare number or with `ppm`, `ppb`, `%`.
pub fn ratio(s: &str) -> Result<f64, String> {
    units::parse_as_or_si(s, Dimension::Dimensionless).map_err(|e| e.to_string())
}

/// True for a number > 0 (false for NaN).
pub fn is_positive(x: f64) -> bool {
    x > 0.0
}

/// A sphere's radius [m]: a kilometre (a small asteroid) to a million kilometres (beyond
/// the Sun's 696 000 km); with [`SURFACE_GRAVITY`] its `μ = g a²` stays a positive
/// finite number (a radius of 1e-300 m made it 0).
const SPHERE_RADIUS: schuler::domain::Domain = schuler::domain::Domain {
    quantity: "sphere radius",
    min: 1e3,
    max: 1e9,
    unit: "m",
    scale: 1.0,
    why: "an asteroid's to beyond the Sun's",
};

/// Gravitation at a sphere's surface [m/s²]: positive, at most 1000 m/s² (the Sun's
/// surface has 274).
const SURFACE_GRAVITY: schuler::domain::Domain = schuler::domain::Domain {
    quantity: "surface gravitation",
    min: 1e-6,
    max: 1e3,
    unit: "m/s^2",
    scale: 1.0,
    why: "positive, at most 1000 m/s^2",
};

/// The textbook sphere's radius and surface gravitation (`schuler channel`, `schuler vertical`).
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct SphereArgs {
    /// Sphere radius a.
    #[arg(long, value_parser = length, allow_hyphen_values = true, default_value = "6371km", value_name = "LENGTH")]
    pub radius: f64,
    /// Gravitation at the surface g.
    #[arg(long, value_parser = acceleration, allow_hyphen_values = true, default_value = "9.81m/s^2", value_name = "ACCEL")]
    pub g: f64,
}

impl SphereArgs {
    /// The sphere rotating at `rate`, after checking both values are positive.
    pub fn sphere(&self, rate: f64) -> Result<Sphere> {
        in_domain("--radius", &SPHERE_RADIUS, self.radius)?;
        in_domain("--g", &SURFACE_GRAVITY, self.g)?;
        Ok(Sphere::with_surface_gravity(self.radius, self.g, rate))
    }
}
