//! Sensor descriptions in engineering units, IMU grade presets, and their resolution
//! into the SI models of [`crate::imu::model`] and [`super::receivers`].
//!
//! Presets (typical one-sigma values of the three classic grades, after Groves,
//! *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd
//! ed. 2013, §4.4 and table 4.1, and Titterton & Weston 2004 table 1.1; the seed's
//! FOG system is of the first class):
//!
//! | preset | gyro turn-on bias | gyro instability (τ) | ARW | accel turn-on bias | accel instability (τ) | VRW | scale gyro / accel |
//! |---|---|---|---|---|---|---|---|
//! | `navigation` (FOG/RLG) | 0.01 deg/h | 0.003 deg/h (3600 s) | 0.002 deg/sqrt(h) | 50 ug | 10 ug (3600 s) | 0.01 m/s/sqrt(h) | 5 / 50 ppm |
//! | `tactical` | 1 deg/h | 0.1 deg/h (1800 s) | 0.1 deg/sqrt(h) | 1 mg | 50 ug (1800 s) | 0.05 m/s/sqrt(h) | 100 / 300 ppm |
//! | `consumer-mems` | 10 deg/h | 3 deg/h (300 s) | 0.5 deg/sqrt(h) | 5 mg | 0.5 mg (300 s) | 0.2 m/s/sqrt(h) | 1000 / 3000 ppm |
//! | `perfect` | none | | | | | | |
//!
//! The presets leave out what the references tabulate less uniformly; give them per
//! triad when wanted: the bias random walk (`rate_random_walk`, e.g.
//! "0.01 deg/h/sqrt(h)", or `acceleration_random_walk`, e.g. "10 ug/sqrt(h)"),
//! misalignment, asymmetry, quantization, and the gyro g-sensitivity
//! (`g_sensitivity = "2 deg/h/g"` in `[imu]`).

use super::receivers::{BaroModel, GnssModel, Interval, Outlier};
use super::scenario::{Quantity, ScenarioError};
use crate::domain::{self, Domain};
use crate::imu::model::{ImuModel, TriadModel, VibrationLine};
use crate::units::Dimension;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// A per-axis value: one quantity for all three axes, or one per axis.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Axes {
    /// The same on x, y, z.
    All(Quantity),
    /// x, y, z.
    Each([Quantity; 3]),
}

impl Axes {
    fn si(&self, key: &str, dim: Dimension) -> Result<Vector3<f64>, ScenarioError> {
        match self {
            Axes::All(q) => {
                let v = q.si(key, dim)?;
                Ok(Vector3::new(v, v, v))
            }
            Axes::Each(qs) => {
                let mut v = Vector3::zeros();
                for (i, q) in qs.iter().enumerate() {
                    v[i] = q.si(&format!("{key}[{i}]"), dim)?;
                }
                Ok(v)
            }
        }
    }
}

fn text(s: &str) -> Option<Axes> {
    Some(Axes::All(Quantity::Text(s.to_string())))
}

/// One triad's errors as written; every field optional (a preset or zero fills it).
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TriadSpec {
    /// Constant bias.
    pub bias: Option<Axes>,
    /// Turn-on bias standard deviation (drawn once per run).
    pub turn_on: Option<Axes>,
    /// Gauss–Markov bias instability (standard deviation).
    pub instability: Option<Axes>,
    /// Gauss–Markov correlation time.
    pub correlation_time: Option<Axes>,
    /// White noise: angle random walk (gyro) or velocity random walk (accelerometer).
    pub random_walk: Option<Axes>,
    /// Random walk of the bias: rate random walk (gyro, e.g. "0.01 deg/h/sqrt(h)") or
    /// acceleration random walk (accelerometer, e.g. "10 ug/sqrt(h)"); also read as
    /// `rate_random_walk` or `acceleration_random_walk`.
    #[serde(
        default,
        alias = "rate_random_walk",
        alias = "acceleration_random_walk",
        skip_serializing_if = "Option::is_none"
    )]
    pub bias_random_walk: Option<Axes>,
    /// Scale-factor error.
    pub scale: Option<Axes>,
    /// Scale-factor asymmetry.
    pub asymmetry: Option<Axes>,
    /// Misalignment angles `[xy, xz, yx, yz, zx, zy]` (sensor axis, true axis).
    pub misalignment: Option<[Quantity; 6]>,
    /// Quantization step of the increments.
    pub quantum: Option<Axes>,
}

impl TriadSpec {
    /// `self` with every missing field taken from `base`.
    fn over(&self, base: &TriadSpec) -> TriadSpec {
        macro_rules! pick {
            ($($f:ident),*) => { TriadSpec { $($f: self.$f.clone().or_else(|| base.$f.clone()),)* } };
        }
        pick!(
            bias,
            turn_on,
            instability,
            correlation_time,
            random_walk,
            bias_random_walk,
            scale,
            asymmetry,
            misalignment,
            quantum
        )
    }

    fn resolve(&self, key: &str, dims: &TriadDimensions) -> Result<TriadModel, ScenarioError> {
        let TriadDimensions {
            rate,
            white,
            walk,
            quantum,
        } = *dims;
        let get =
            |f: &Option<Axes>, name: &str, dim: Dimension| -> Result<Vector3<f64>, ScenarioError> {
                f.as_ref().map_or(Ok(Vector3::zeros()), |a| {
                    a.si(&format!("{key}.{name}"), dim)
                })
            };
        let mut misalignment = Matrix3::zeros();
        if let Some(m) = &self.misalignment {
            let slots = [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)];
            for (q, (i, j)) in m.iter().zip(slots) {
                misalignment[(i, j)] = q.si(&format!("{key}.misalignment"), Dimension::Angle)?;
            }
        }
        let model = TriadModel {
            bias: get(&self.bias, "bias", rate)?,
            turn_on: get(&self.turn_on, "turn_on", rate)?,
            gm_sigma: get(&self.instability, "instability", rate)?,
            gm_tau: get(&self.correlation_time, "correlation_time", Dimension::Time)?,
            white: get(&self.random_walk, "random_walk", white)?,
            random_walk: get(&self.bias_random_walk, "bias_random_walk", walk)?,
            scale: get(&self.scale, "scale", Dimension::Dimensionless)?,
            asymmetry: get(&self.asymmetry, "asymmetry", Dimension::Dimensionless)?,
            misalignment,
            quantum: get(&self.quantum, "quantum", quantum)?,
        };
        for i in 0..3 {
            if model.gm_sigma[i] != 0.0 && model.gm_tau[i] <= 0.0 {
                return Err(ScenarioError::Value {
                    key: format!("{key}.correlation_time"),
                    message: "a bias instability needs a positive correlation time".into(),
                });
            }
            for (name, v) in [
                ("turn_on", model.turn_on[i]),
                ("instability", model.gm_sigma[i]),
                ("random_walk", model.white[i]),
                ("bias_random_walk", model.random_walk[i]),
                ("quantum", model.quantum[i]),
            ] {
                if v < 0.0 {
                    return Err(ScenarioError::Value {
                        key: format!("{key}.{name}"),
                        message: format!(
                            "a standard deviation or step cannot be negative, got {v}"
                        ),
                    });
                }
            }
        }
        Ok(model)
    }
}

/// The dimensions of one triad's terms.
struct TriadDimensions {
    /// Bias, turn-on bias, instability (angular rate or acceleration).
    rate: Dimension,
    /// White noise density (angle or velocity random walk).
    white: Dimension,
    /// Random walk of the bias (rate or acceleration random walk).
    walk: Dimension,
    /// Quantization step (angle or velocity).
    quantum: Dimension,
}

/// IMU grade presets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// Navigation grade (FOG/RLG, about 0.01 deg/h and 50 ug).
    Navigation,
    /// Tactical grade (about 1 deg/h and 1 mg).
    Tactical,
    /// Consumer MEMS (about 10 deg/h and 5 mg).
    ConsumerMems,
    /// No errors.
    Perfect,
}

impl Preset {
    /// The preset's gyro and accelerometer specs (module table).
    pub fn specs(self) -> (TriadSpec, TriadSpec) {
        let triad = |bias: &str, instab: &str, tau: &str, rw: &str, scale: &str| TriadSpec {
            turn_on: text(bias),
            instability: text(instab),
            correlation_time: text(tau),
            random_walk: text(rw),
            scale: text(scale),
            ..TriadSpec::default()
        };
        match self {
            Preset::Navigation => (
                triad(
                    "0.01 deg/h",
                    "0.003 deg/h",
                    "3600 s",
                    "0.002 deg/sqrt(h)",
                    "5 ppm",
                ),
                triad("50 ug", "10 ug", "3600 s", "0.01 m/s/sqrt(h)", "50 ppm"),
            ),
            Preset::Tactical => (
                triad(
                    "1 deg/h",
                    "0.1 deg/h",
                    "1800 s",
                    "0.1 deg/sqrt(h)",
                    "100 ppm",
                ),
                triad("1 mg", "50 ug", "1800 s", "0.05 m/s/sqrt(h)", "300 ppm"),
            ),
            Preset::ConsumerMems => (
                triad(
                    "10 deg/h",
                    "3 deg/h",
                    "300 s",
                    "0.5 deg/sqrt(h)",
                    "1000 ppm",
                ),
                triad("5 mg", "0.5 mg", "300 s", "0.2 m/s/sqrt(h)", "3000 ppm"),
            ),
            Preset::Perfect => (TriadSpec::default(), TriadSpec::default()),
        }
    }
}

/// A vibration line as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct VibrationSpec {
    /// Frequency [Hz].
    pub freq_hz: f64,
    /// Amplitude per axis (acceleration).
    pub amplitude: Axes,
    /// Phase (angle), default 0.
    pub phase: Option<Quantity>,
}

/// The IMU as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ImuSpec {
    /// Sample rate [Hz].
    pub rate_hz: f64,
    /// Base grade; fields given below override it.
    pub preset: Option<Preset>,
    /// Gyro errors.
    #[serde(default)]
    pub gyro: TriadSpec,
    /// Accelerometer errors.
    #[serde(default)]
    pub accel: TriadSpec,
    /// Gyro g-sensitivity per axis (the diagonal: each gyro's rate error per unit of
    /// specific force along its own axis), e.g. "2 deg/h/g".
    pub g_sensitivity: Option<Axes>,
    /// Accelerometer vibration lines.
    #[serde(default)]
    pub vibration: Vec<VibrationSpec>,
}

impl ImuSpec {
    /// The preset alone at `rate_hz` [Hz]: no overrides, no g-sensitivity, no
    /// vibration.
    pub fn of_preset(rate_hz: f64, preset: Preset) -> Self {
        Self {
            rate_hz,
            preset: Some(preset),
            gyro: Default::default(),
            accel: Default::default(),
            g_sensitivity: None,
            vibration: Vec::new(),
        }
    }

    /// The spec with the preset folded in (what was actually used, for the record).
    pub fn resolved_spec(&self) -> ImuSpec {
        let (g, a) = self.preset.unwrap_or(Preset::Perfect).specs();
        ImuSpec {
            gyro: self.gyro.over(&g),
            accel: self.accel.over(&a),
            preset: None,
            ..self.clone()
        }
    }

    /// The SI model.
    pub fn model(&self) -> Result<ImuModel, ScenarioError> {
        within(&domain::IMU_RATE, "imu.rate_hz", self.rate_hz)?;
        let r = self.resolved_spec();
        let gyro = r.gyro.resolve(
            "imu.gyro",
            &TriadDimensions {
                rate: Dimension::AngularRate,
                white: Dimension::AngleRandomWalk,
                walk: Dimension::RateRandomWalk,
                quantum: Dimension::Angle,
            },
        )?;
        let accel = r.accel.resolve(
            "imu.accel",
            &TriadDimensions {
                rate: Dimension::Acceleration,
                white: Dimension::VelocityRandomWalk,
                walk: Dimension::AccelerationRandomWalk,
                quantum: Dimension::Velocity,
            },
        )?;
        let mut vibration = Vec::new();
        for (i, v) in r.vibration.iter().enumerate() {
            let key = format!("imu.vibration[{i}]");
            if !(v.freq_hz.is_finite() && v.freq_hz > 0.0) {
                return Err(ScenarioError::Value {
                    key: format!("{key}.freq_hz"),
                    message: format!("must be a positive frequency, got {}", v.freq_hz),
                });
            }
            vibration.push(VibrationLine {
                freq_hz: v.freq_hz,
                amplitude: v
                    .amplitude
                    .si(&format!("{key}.amplitude"), Dimension::Acceleration)?,
                phase: v
                    .phase
                    .as_ref()
                    .map_or(Ok(0.0), |p| p.si(&format!("{key}.phase"), Dimension::Angle))?,
            });
        }
        Ok(ImuModel {
            gyro,
            accel,
            g_sensitivity: Matrix3::from_diagonal(
                &r.g_sensitivity.as_ref().map_or(Ok(Vector3::zeros()), |g| {
                    g.si("imu.g_sensitivity", Dimension::GSensitivity)
                })?,
            ),
            vibration,
        })
    }
}

/// An interval as written: `["215 s", "276 s"]`.
pub type IntervalSpec = [Quantity; 2];

fn intervals(specs: &[IntervalSpec], key: &str) -> Result<Vec<Interval>, ScenarioError> {
    specs
        .iter()
        .enumerate()
        .map(|(i, [a, b])| {
            let k = format!("{key}[{i}]");
            let (start, end) = (a.si(&k, Dimension::Time)?, b.si(&k, Dimension::Time)?);
            if end < start {
                return Err(ScenarioError::Value {
                    key: k,
                    message: format!("the interval ends ({end} s) before it starts ({start} s)"),
                });
            }
            Ok(Interval { start, end })
        })
        .collect()
}

/// A GNSS receiver as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GnssSpec {
    /// Output rate [Hz].
    pub rate_hz: f64,
    /// Position noise std N, E, D.
    pub position_std: [Quantity; 3],
    /// Velocity noise std N, E, D.
    pub velocity_std: Option<[Quantity; 3]>,
    /// Antenna lever arm in body axes.
    pub lever_arm: Option<[Quantity; 3]>,
    /// Time offset `τ`: the fix of the instant `t` is stamped `t − τ`.
    pub time_offset: Option<Quantity>,
    /// Outages `[start, end]`.
    #[serde(default)]
    pub outages: Vec<IntervalSpec>,
    /// Outliers: time and NED jump.
    #[serde(default)]
    pub outliers: Vec<GnssOutlierSpec>,
    /// Raw observations (`[gnss.raw]`), simulated beside the fixes.
    pub raw: Option<super::raw_gnss::spec::RawGnssSpec>,
}

/// A GNSS outlier as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GnssOutlierSpec {
    /// Time.
    pub at: Quantity,
    /// NED jump.
    pub jump: [Quantity; 3],
}

fn vec3(q: &[Quantity; 3], key: &str, dim: Dimension) -> Result<Vector3<f64>, ScenarioError> {
    Axes::Each(q.clone()).si(key, dim)
}

/// A value of the scenario in `domain` (its SI value), or an error naming `key`.
fn within(domain: &Domain, key: &str, v: f64) -> Result<f64, ScenarioError> {
    domain.check(v).map_err(|e| ScenarioError::Value {
        key: key.into(),
        message: e.to_string(),
    })
}

/// [`vec3`] with each axis in `domain`.
fn vec3_in(
    q: &[Quantity; 3],
    key: &str,
    dim: Dimension,
    domain: &Domain,
) -> Result<Vector3<f64>, ScenarioError> {
    let v = vec3(q, key, dim)?;
    for (i, x) in v.iter().enumerate() {
        within(domain, &format!("{key}[{i}]"), *x)?;
    }
    Ok(v)
}

/// A simulated noise standard deviation [m]: zero (a perfect sensor) up to the
/// Earth's quadrant, as [`domain::POSITION_STD`] bounds a filter's.
const SIM_POSITION_STD: Domain = Domain {
    min: 0.0,
    ..domain::POSITION_STD
};
/// A simulated velocity noise standard deviation [m/s]: zero up to the escape
/// velocity.
const SIM_VELOCITY_STD: Domain = Domain {
    min: 0.0,
    ..domain::VELOCITY_STD
};
/// An outlier's jump or a bias of a position or height [m]: within the Earth's
/// quadrant, either sign.
const SIM_OFFSET: Domain = Domain {
    quantity: "offset",
    min: -1e7,
    why: "at most the Earth's quadrant",
    ..domain::POSITION_STD
};

impl GnssSpec {
    /// The SI model.
    pub fn model(&self) -> Result<GnssModel, ScenarioError> {
        within(&domain::GNSS_RATE, "gnss.rate_hz", self.rate_hz)?;
        let zero = || Ok(Vector3::zeros());
        Ok(GnssModel {
            interval: 1.0 / self.rate_hz,
            pos_std: vec3_in(
                &self.position_std,
                "gnss.position_std",
                Dimension::Length,
                &SIM_POSITION_STD,
            )?,
            vel_std: self.velocity_std.as_ref().map_or_else(zero, |v| {
                vec3_in(
                    v,
                    "gnss.velocity_std",
                    Dimension::Velocity,
                    &SIM_VELOCITY_STD,
                )
            })?,
            lever_arm: self.lever_arm.as_ref().map_or_else(zero, |v| {
                vec3_in(v, "gnss.lever_arm", Dimension::Length, &domain::LEVER_ARM)
            })?,
            time_offset: match &self.time_offset {
                None => 0.0,
                Some(q) => within(
                    &domain::GNSS_TIME_OFFSET,
                    "gnss.time_offset",
                    q.si("gnss.time_offset", Dimension::Time)?,
                )?,
            },
            outages: intervals(&self.outages, "gnss.outages")?,
            outliers: self
                .outliers
                .iter()
                .enumerate()
                .map(|(i, o)| {
                    let k = format!("gnss.outliers[{i}]");
                    Ok(Outlier {
                        t: o.at.si(&format!("{k}.at"), Dimension::Time)?,
                        jump: vec3_in(
                            &o.jump,
                            &format!("{k}.jump"),
                            Dimension::Length,
                            &SIM_OFFSET,
                        )?,
                    })
                })
                .collect::<Result<_, ScenarioError>>()?,
        })
    }
}

/// A barometer as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BaroSpec {
    /// Output rate [Hz].
    pub rate_hz: f64,
    /// Constant bias (length).
    pub bias: Option<Quantity>,
    /// Drift (velocity, e.g. "0.01 m/s").
    pub drift: Option<Quantity>,
    /// White noise std (length).
    pub noise: Option<Quantity>,
    /// Dropouts `[start, end]`.
    #[serde(default)]
    pub dropouts: Vec<IntervalSpec>,
    /// Outliers: time and height jump.
    #[serde(default)]
    pub outliers: Vec<BaroOutlierSpec>,
}

/// A barometer outlier as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BaroOutlierSpec {
    /// Time.
    pub at: Quantity,
    /// Height jump.
    pub jump: Quantity,
}

impl BaroSpec {
    /// The SI model.
    pub fn model(&self) -> Result<BaroModel, ScenarioError> {
        within(&domain::AID_RATE, "baro.rate_hz", self.rate_hz)?;
        let opt = |q: &Option<Quantity>, key: &str, dim, domain: &Domain| {
            q.as_ref()
                .map_or(Ok(0.0), |q| within(domain, key, q.si(key, dim)?))
        };
        Ok(BaroModel {
            interval: 1.0 / self.rate_hz,
            bias: opt(&self.bias, "baro.bias", Dimension::Length, &SIM_OFFSET)?,
            drift: opt(
                &self.drift,
                "baro.drift",
                Dimension::Velocity,
                &domain::SPEED,
            )?,
            noise: opt(
                &self.noise,
                "baro.noise",
                Dimension::Length,
                &SIM_POSITION_STD,
            )?,
            dropouts: intervals(&self.dropouts, "baro.dropouts")?,
            outliers: self
                .outliers
                .iter()
                .enumerate()
                .map(|(i, o)| {
                    let k = format!("baro.outliers[{i}]");
                    Ok(Outlier {
                        t: o.at.si(&format!("{k}.at"), Dimension::Time)?,
                        jump: within(
                            &SIM_OFFSET,
                            &format!("{k}.jump"),
                            o.jump.si(&format!("{k}.jump"), Dimension::Length)?,
                        )?,
                    })
                })
                .collect::<Result<_, ScenarioError>>()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::{DEG_PER_H, DEG_PER_SQRT_H, UG};
    use approx::assert_relative_eq;

    /// The tactical preset resolves to its table values; a field given overrides it.
    #[test]
    fn preset_values_and_override() {
        let spec: ImuSpec = toml::from_str(
            "rate_hz = 200\npreset = \"tactical\"\n[accel]\nturn_on = [\"100 ug\", \"200 ug\", \"300 ug\"]\n",
        )
        .expect("toml");
        let m = spec.model().expect("model");
        assert_relative_eq!(m.gyro.turn_on.x, DEG_PER_H, max_relative = 1e-15);
        assert_relative_eq!(m.gyro.white.z, 0.1 * DEG_PER_SQRT_H, max_relative = 1e-15);
        assert_relative_eq!(m.accel.turn_on.y, 200.0 * UG, max_relative = 1e-15);
        assert_relative_eq!(m.gyro.gm_tau.y, 1800.0);
        let back = toml::to_string(&spec.resolved_spec()).expect("serialize");
        assert!(back.contains("0.1 deg/h"), "{back}");
    }

    #[test]
    fn errors_name_the_key() {
        let spec: ImuSpec =
            toml::from_str("rate_hz = 200\n[gyro]\nbias = \"1 mg\"\n").expect("toml");
        let e = spec.model().unwrap_err().to_string();
        assert!(
            e.starts_with("imu.gyro.bias: expected an angular rate"),
            "{e}"
        );
        let spec: ImuSpec =
            toml::from_str("rate_hz = 200\n[gyro]\ninstability = \"1 deg/h\"\n").expect("toml");
        assert!(
            spec.model()
                .unwrap_err()
                .to_string()
                .starts_with("imu.gyro.correlation_time")
        );
        let e = toml::from_str::<ImuSpec>("rate_hz = 200\n[gyro]\nbais = \"1 deg/h\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown field `bais`"), "{e}");
    }
}
