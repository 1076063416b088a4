//! Option types shared by the commands: comma-separated triples, the Earth model,
//! the IMU file's format and layout, the mechanization, the IMU grade, and quantities
//! with units; each parsed from flags and TOML alike.

use crate::formats::{ImuFormat, ImuLayout};
use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use schuler::filter::ImuNoise;
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use serde::Deserialize;

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
