//! Scenario descriptions: the initial state and the maneuvers people script, in
//! engineering units, compiled into motion pieces.
//!
//! The description is plain data (serde), read from TOML by the CLI:
//!
//! ```toml
//! earth = "wgs84"
//! [start]
//! position = ["45.07 deg", "7.68 deg", "245 m"]
//! attitude = ["0 deg", "0 deg", "10 deg"]      # roll, pitch, yaw
//! speed = "0 m/s"                               # along the nose (or velocity = [N, E, D])
//! [[motion]]
//! type = "hold"
//! duration = "60 s"
//! [[motion]]
//! type = "accelerate"
//! to_speed = "20 m/s"
//! accel = "1 m/s^2"
//! [[motion]]
//! type = "turn"
//! angle = "90 deg"
//! bank = "20 deg"                               # or rate = "3 deg/s"
//! ```
//!
//! Every quantity carries its unit (see [`crate::units`]); a bare number is refused
//! unless the quantity is dimensionless. Errors name the key (`motion[3].bank`) and
//! why.

use super::motion::{MotionBuilder, MotionError, Piece, Shape, Start, VelocityAxes};
use super::spline::SplineTrajectory;
use crate::earth::{EarthModel, Geodetic};
use crate::rotation::Euler;
use crate::units::{self, Dimension};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A quantity as written: text with a unit ("30 deg"), or a bare number.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Quantity {
    /// Number and unit.
    Text(String),
    /// A bare number (accepted for dimensionless quantities only).
    Number(f64),
}

impl Quantity {
    /// The SI value, or an error naming `key`.
    pub fn si(&self, key: &str, dim: Dimension) -> Result<f64, ScenarioError> {
        let value = match self {
            Quantity::Text(t) => {
                units::parse_as(t, dim).map_err(|e| ScenarioError::value(key, e.to_string()))?
            }
            Quantity::Number(x) if dim == Dimension::Dimensionless => *x,
            Quantity::Number(x) => {
                return Err(ScenarioError::value(
                    key,
                    format!(
                        "{x} has no unit: write {dim} as a string with its unit, e.g. \"{x} s\" or \"{x} deg\""
                    ),
                ));
            }
        };
        if value.is_finite() {
            Ok(value)
        } else {
            Err(ScenarioError::value(key, "not a finite number".to_string()))
        }
    }
}

/// The initial state.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct StartSpec {
    /// Time tag of the start [s] (seconds of week in the written files).
    #[serde(default)]
    pub time: f64,
    /// Latitude, longitude, height.
    pub position: [Quantity; 3],
    /// Roll, pitch, yaw.
    pub attitude: [Quantity; 3],
    /// Speed along the body x axis (exclusive with `velocity`).
    pub speed: Option<Quantity>,
    /// NED velocity.
    pub velocity: Option<[Quantity; 3]>,
}

/// Axes of a commanded acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum AxesSpec {
    /// Body axes (the velocity turns with the body).
    #[default]
    Body,
    /// North-east-down.
    Ned,
}

/// One segment of motion, by `type`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SegmentSpec {
    /// Constant commanded Euler-angle rates and acceleration for a duration (smoothly
    /// ramped over 0.25 s at both ends, totals exact).
    Rates {
        /// Duration.
        duration: Quantity,
        /// Roll, pitch, yaw rates.
        #[serde(default)]
        euler_rates: Option<[Quantity; 3]>,
        /// Acceleration in `axes`.
        #[serde(default)]
        accel: Option<[Quantity; 3]>,
        /// Axes of `accel`.
        #[serde(default)]
        axes: AxesSpec,
    },
    /// Keep the current velocity and attitude.
    Hold {
        /// Duration.
        duration: Quantity,
    },
    /// Change forward speed to `to_speed` with peak acceleration `accel`.
    Accelerate {
        /// Target speed along the nose.
        to_speed: Quantity,
        /// Peak acceleration magnitude.
        accel: Quantity,
    },
    /// Coordinated turn by `angle` (positive right) at a bank angle or a turn rate.
    Turn {
        /// Heading change.
        angle: Quantity,
        /// Bank angle (exclusive with `rate`).
        bank: Option<Quantity>,
        /// Turn rate (exclusive with `bank`).
        rate: Option<Quantity>,
        /// Peak roll rate when rolling in and out (default 10 deg/s).
        roll_rate: Option<Quantity>,
    },
    /// Climb or descend to a height at a flight-path angle (default 5 deg).
    Climb {
        /// Target height.
        to_height: Quantity,
        /// Flight-path angle magnitude.
        pitch: Option<Quantity>,
        /// Peak pitch rate (default 3 deg/s).
        pitch_rate: Option<Quantity>,
    },
    /// Turn on the spot (at rest) by `angle` over `duration`.
    TurnOnSpot {
        /// Heading change.
        angle: Quantity,
        /// Duration.
        duration: Quantity,
    },
    /// A full 360-degree roll over `duration` (positive right).
    Roll {
        /// Duration.
        duration: Quantity,
        /// Roll to the left instead.
        #[serde(default)]
        left: bool,
    },
    /// Hover: hold at zero speed (vibration comes from the IMU's vibration lines).
    Hover {
        /// Duration.
        duration: Quantity,
    },
}

/// A scenario's motion part.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct MotionSpec {
    /// Initial state.
    pub start: StartSpec,
    /// Segments in order.
    pub motion: Vec<SegmentSpec>,
}

/// Why a scenario is invalid: the key and the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// A value is wrong.
    #[error("{key}: {message}")]
    Value {
        /// Dotted key path, e.g. `motion[3].bank`.
        key: String,
        /// Why.
        message: String,
    },
    /// The motion could not be integrated.
    #[error("{key}: {source}")]
    Motion {
        /// Segment key.
        key: String,
        /// What went wrong.
        source: MotionError,
    },
}

impl ScenarioError {
    fn value(key: &str, message: String) -> Self {
        Self::Value {
            key: key.to_string(),
            message,
        }
    }
}

/// Default peak roll rate for turns [rad/s].
const DEFAULT_ROLL_RATE: f64 = 10.0 * units::DEG;
/// Default peak pitch rate for climbs [rad/s].
const DEFAULT_PITCH_RATE: f64 = 3.0 * units::DEG;
/// Default flight-path angle for climbs [rad].
const DEFAULT_CLIMB_PITCH: f64 = 5.0 * units::DEG;
/// Ramp at each end of a constant-rate segment [s].
const RATES_RAMP: f64 = 0.25;
/// Ramp fraction of an acceleration segment at each end.
const ACCEL_RAMP_FRACTION: f64 = 0.2;
/// Peak over mean of [`Shape::Bump`].
const BUMP_PEAK: f64 = 1.875;
/// Below this speed [m/s] the vehicle is at rest for hover and turn-on-spot checks.
const REST_SPEED: f64 = 0.1;

fn vec3(q: &[Quantity; 3], key: &str, dim: Dimension) -> Result<[f64; 3], ScenarioError> {
    let mut v = [0.0; 3];
    for (i, x) in q.iter().enumerate() {
        v[i] = x.si(&format!("{key}[{i}]"), dim)?;
    }
    Ok(v)
}

impl StartSpec {
    /// The resolved start.
    pub fn resolve(&self) -> Result<Start, ScenarioError> {
        let lat = self.position[0].si("start.position[0]", Dimension::Angle)?;
        let lon = self.position[1].si("start.position[1]", Dimension::Angle)?;
        let h = self.position[2].si("start.position[2]", Dimension::Length)?;
        if lat.abs() >= 89.9 * units::DEG {
            return Err(ScenarioError::value(
                "start.position[0]",
                "latitude must be within 89.9 deg of the equator for maneuver scripting (the NED equations are singular at the poles)".into(),
            ));
        }
        let [roll, pitch, yaw] = vec3(&self.attitude, "start.attitude", Dimension::Angle)?;
        let attitude = Euler::new(roll, pitch, yaw);
        let v_n = match (&self.speed, &self.velocity) {
            (Some(_), Some(_)) => {
                return Err(ScenarioError::value(
                    "start",
                    "give either speed or velocity, not both".into(),
                ));
            }
            (Some(s), None) => {
                attitude.to_dcm()
                    * Vector3::new(s.si("start.speed", Dimension::Velocity)?, 0.0, 0.0)
            }
            (None, Some(v)) => Vector3::from(vec3(v, "start.velocity", Dimension::Velocity)?),
            (None, None) => Vector3::zeros(),
        };
        Ok(Start {
            t: self.time,
            pos: Geodetic::new(lat, lon, h),
            v_n,
            attitude,
        })
    }
}

fn positive(key: &str, x: f64, what: &str) -> Result<f64, ScenarioError> {
    if x > 0.0 {
        Ok(x)
    } else {
        Err(ScenarioError::value(
            key,
            format!("{what} must be positive, got {x}"),
        ))
    }
}

fn bump(duration: f64, d_euler: [f64; 3], coordinated: bool) -> Piece {
    Piece {
        duration,
        d_euler,
        d_vel: [0.0; 3],
        axes: VelocityAxes::Body,
        shape: Shape::Bump,
        coordinated,
    }
}

/// Forward speed (body x) of a state.
fn forward_speed(s: &Start) -> f64 {
    (s.attitude.to_dcm().transpose() * s.v_n).x
}

/// Push `piece` on `b`, naming `key` on failure.
fn push<E: EarthModel>(
    b: &mut MotionBuilder<E>,
    key: &str,
    piece: &Piece,
) -> Result<(), ScenarioError> {
    b.push(piece).map_err(|source| ScenarioError::Motion {
        key: key.to_string(),
        source,
    })
}

/// Compile one segment and integrate it.
fn compile<E: EarthModel>(
    b: &mut MotionBuilder<E>,
    key: &str,
    seg: &SegmentSpec,
) -> Result<(), ScenarioError> {
    let k = |name: &str| format!("{key}.{name}");
    match seg {
        SegmentSpec::Hold { duration } | SegmentSpec::Hover { duration } => {
            let d = positive(
                &k("duration"),
                duration.si(&k("duration"), Dimension::Time)?,
                "duration",
            )?;
            if matches!(seg, SegmentSpec::Hover { .. }) {
                let v = b.state().v_n.norm();
                if v > REST_SPEED {
                    return Err(ScenarioError::value(
                        key,
                        format!(
                            "hover needs the vehicle at rest, but it moves at {v:.3} m/s: decelerate first"
                        ),
                    ));
                }
            }
            push(b, key, &Piece::hold(d))
        }
        SegmentSpec::Rates {
            duration,
            euler_rates,
            accel,
            axes,
        } => {
            let d = positive(
                &k("duration"),
                duration.si(&k("duration"), Dimension::Time)?,
                "duration",
            )?;
            let rates = match euler_rates {
                Some(r) => vec3(r, &k("euler_rates"), Dimension::AngularRate)?,
                None => [0.0; 3],
            };
            let acc = match accel {
                Some(a) => vec3(a, &k("accel"), Dimension::Acceleration)?,
                None => [0.0; 3],
            };
            let piece = Piece {
                duration: d,
                d_euler: rates.map(|r| r * d),
                d_vel: acc.map(|a| a * d),
                axes: match axes {
                    AxesSpec::Body => VelocityAxes::Body,
                    AxesSpec::Ned => VelocityAxes::Ned,
                },
                shape: Shape::Plateau((RATES_RAMP / d).min(0.5)),
                coordinated: false,
            };
            push(b, key, &piece)
        }
        SegmentSpec::Accelerate { to_speed, accel } => {
            let target = to_speed.si(&k("to_speed"), Dimension::Velocity)?;
            let a = positive(
                &k("accel"),
                accel.si(&k("accel"), Dimension::Acceleration)?.abs(),
                "accel",
            )?;
            let dv = target - forward_speed(&b.state());
            if dv.abs() < 1e-9 {
                return Ok(());
            }
            let piece = Piece {
                duration: dv.abs() / (a * (1.0 - ACCEL_RAMP_FRACTION)),
                d_euler: [0.0; 3],
                d_vel: [dv, 0.0, 0.0],
                axes: VelocityAxes::Body,
                shape: Shape::Plateau(ACCEL_RAMP_FRACTION),
                coordinated: false,
            };
            push(b, key, &piece)
        }
        SegmentSpec::Turn {
            angle,
            bank,
            rate,
            roll_rate,
        } => {
            let angle = angle.si(&k("angle"), Dimension::Angle)?;
            let v = b.state().v_n.xy().norm();
            if v < 1.0 {
                return Err(ScenarioError::value(
                    key,
                    format!(
                        "a coordinated turn needs forward speed, but the vehicle moves at {v:.3} m/s: use turn_on_spot"
                    ),
                ));
            }
            let bank = match (bank, rate) {
                (Some(bq), None) => {
                    let b = bq.si(&k("bank"), Dimension::Angle)?.abs();
                    if !(b > 0.0 && b < 80.0 * units::DEG) {
                        return Err(ScenarioError::value(
                            &k("bank"),
                            format!("a bank of {:.1} deg cannot be flown: it must be between 0 and 80 deg", b.to_degrees()),
                        ));
                    }
                    b
                }
                (None, Some(rq)) => {
                    let r = positive(&k("rate"), rq.si(&k("rate"), Dimension::AngularRate)?.abs(), "rate")?;
                    (r * v / units::G0).atan()
                }
                _ => {
                    return Err(ScenarioError::value(key, "give exactly one of bank or rate".into()));
                }
            }
            .copysign(angle);
            let roll_rate = match roll_rate {
                Some(q) => positive(
                    &k("roll_rate"),
                    q.si(&k("roll_rate"), Dimension::AngularRate)?,
                    "roll_rate",
                )?,
                None => DEFAULT_ROLL_RATE,
            };
            let ramp = BUMP_PEAK * bank.abs() / roll_rate;
            let yaw0 = b.state().attitude.yaw;
            push(b, key, &bump(ramp, [bank, 0.0, 0.0], true))?;
            let turned_in = b.state().attitude.yaw - yaw0;
            let rest = angle - 2.0 * turned_in;
            if rest * angle.signum() < 0.0 {
                return Err(ScenarioError::value(
                    key,
                    format!(
                        "turning by {:.1} deg is too little for a {:.1} deg bank at {v:.1} m/s: rolling in and out alone turns {:.1} deg; use a smaller bank or rate",
                        angle.to_degrees(),
                        bank.to_degrees(),
                        2.0 * turned_in.to_degrees()
                    ),
                ));
            }
            let rate_full = units::G0 * bank.tan() / v;
            if rest.abs() > 1e-12 {
                let hold = Piece {
                    coordinated: true,
                    ..Piece::hold(rest / rate_full)
                };
                push(b, key, &hold)?;
            }
            push(b, key, &bump(ramp, [-bank, 0.0, 0.0], true))
        }
        SegmentSpec::Climb {
            to_height,
            pitch,
            pitch_rate,
        } => {
            let target = to_height.si(&k("to_height"), Dimension::Length)?;
            let s = b.state();
            let dh = target - s.pos.h;
            let v = forward_speed(&s);
            if v < 1.0 {
                return Err(ScenarioError::value(
                    key,
                    format!(
                        "a climb along the flight path needs forward speed, got {v:.3} m/s; use a rates segment with NED acceleration for vertical motion"
                    ),
                ));
            }
            let theta = match pitch {
                Some(q) => q.si(&k("pitch"), Dimension::Angle)?.abs(),
                None => DEFAULT_CLIMB_PITCH,
            };
            if !(theta > 0.0 && theta < 60.0 * units::DEG) {
                return Err(ScenarioError::value(
                    &k("pitch"),
                    "the flight-path angle must be between 0 and 60 deg".into(),
                ));
            }
            let theta = theta.copysign(dh);
            let rate = match pitch_rate {
                Some(q) => positive(
                    &k("pitch_rate"),
                    q.si(&k("pitch_rate"), Dimension::AngularRate)?,
                    "pitch_rate",
                )?,
                None => DEFAULT_PITCH_RATE,
            };
            let ramp = BUMP_PEAK * theta.abs() / rate;
            push(b, key, &bump(ramp, [0.0, theta, 0.0], false))?;
            let climbed_in = b.state().pos.h - s.pos.h;
            let rest = dh - 2.0 * climbed_in;
            if rest * dh.signum() < 0.0 {
                return Err(ScenarioError::value(
                    key,
                    format!(
                        "a height change of {dh:.1} m is too small for a {:.1} deg flight-path angle at {v:.1} m/s (pitching up and down alone changes {:.1} m); use a smaller pitch",
                        theta.to_degrees(),
                        2.0 * climbed_in
                    ),
                ));
            }
            if rest.abs() > 1e-9 {
                push(b, key, &Piece::hold(rest / (v * theta.sin())))?;
            }
            push(b, key, &bump(ramp, [0.0, -theta, 0.0], false))
        }
        SegmentSpec::TurnOnSpot { angle, duration } => {
            let angle = angle.si(&k("angle"), Dimension::Angle)?;
            let d = positive(
                &k("duration"),
                duration.si(&k("duration"), Dimension::Time)?,
                "duration",
            )?;
            let v = b.state().v_n.norm();
            if v > REST_SPEED {
                return Err(ScenarioError::value(
                    key,
                    format!("turn_on_spot needs the vehicle at rest, but it moves at {v:.3} m/s"),
                ));
            }
            push(b, key, &bump(d, [0.0, 0.0, angle], false))
        }
        SegmentSpec::Roll { duration, left } => {
            let d = positive(
                &k("duration"),
                duration.si(&k("duration"), Dimension::Time)?,
                "duration",
            )?;
            let turn = if *left {
                -std::f64::consts::TAU
            } else {
                std::f64::consts::TAU
            };
            push(b, key, &bump(d, [turn, 0.0, 0.0], false))
        }
    }
}

impl MotionSpec {
    /// Compile and integrate the motion on `earth`.
    pub fn build<E: EarthModel>(&self, earth: E) -> Result<SplineTrajectory, ScenarioError> {
        let start = self.start.resolve()?;
        if self.motion.is_empty() {
            return Err(ScenarioError::value(
                "motion",
                "no segments: add at least one [[motion]] table".into(),
            ));
        }
        let mut b = MotionBuilder::new(earth, &start);
        for (i, seg) in self.motion.iter().enumerate() {
            compile(&mut b, &format!("motion[{i}]"), seg)?;
        }
        b.finish().map_err(|source| ScenarioError::Motion {
            key: "motion".into(),
            source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::Wgs84;
    use crate::sim::analytic;
    use approx::assert_relative_eq;

    fn spec(motion: &str) -> MotionSpec {
        let text = format!(
            "[start]\nposition = [\"45 deg\", \"7 deg\", \"100 m\"]\nattitude = [\"0 deg\", \"0 deg\", \"0 deg\"]\nspeed = \"50 m/s\"\n{motion}"
        );
        toml::from_str(&text).expect("valid TOML")
    }

    /// A turn by 90 deg at 20 deg bank ends 90 deg from where it began (to the RK4's
    /// accuracy, 1e-9 rad) and level.
    #[test]
    fn turn_by_angle() {
        let t = spec("[[motion]]\ntype = \"turn\"\nangle = \"90 deg\"\nbank = \"20 deg\"\n")
            .build(Wgs84)
            .expect("builds");
        let end = analytic::state(&Wgs84, &t, t.end()).euler();
        assert_relative_eq!(end.yaw, std::f64::consts::FRAC_PI_2, epsilon = 1e-9);
        assert_relative_eq!(end.roll, 0.0, epsilon = 1e-12);
    }

    /// A climb to 600 m ends at 600 m, level, within 1e-6 m (RK4).
    #[test]
    fn climb_to_height() {
        let t = spec("[[motion]]\ntype = \"climb\"\nto_height = \"600 m\"\n")
            .build(Wgs84)
            .expect("builds");
        let end = analytic::state(&Wgs84, &t, t.end());
        assert_relative_eq!(end.pos.h, 600.0, epsilon = 1e-6);
        assert_relative_eq!(end.euler().pitch, 0.0, epsilon = 1e-12);
    }

    /// Accelerate from 50 to 70 m/s with a 2 m/s^2 peak: the duration is
    /// 20 / (2 * 0.8) = 12.5 s and the peak specific force along x is 2 m/s^2 more than
    /// at rest.
    #[test]
    fn accelerate_to_speed() {
        let t =
            spec("[[motion]]\ntype = \"accelerate\"\nto_speed = \"70 m/s\"\naccel = \"2 m/s^2\"\n")
                .build(Wgs84)
                .expect("builds");
        assert_relative_eq!(t.end() - t.start(), 12.5, epsilon = 1e-12);
        assert_relative_eq!(
            analytic::state(&Wgs84, &t, t.end()).v_n.norm(),
            70.0,
            epsilon = 1e-9
        );
        let k = analytic::kinematics(&Wgs84, &t, 6.25);
        assert_relative_eq!(k.f_b.x, 2.0, epsilon = 1e-3);
    }

    /// Bad scenarios name the key and why.
    #[test]
    fn errors_name_the_key() {
        let e = spec("[[motion]]\ntype = \"turn\"\nangle = \"90 deg\"\nbank = \"95 deg\"\n")
            .build(Wgs84)
            .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("motion[0].bank: a bank of 95.0 deg cannot be flown"),
            "{e}"
        );
        let e = spec("[[motion]]\ntype = \"hold\"\nduration = \"-3 s\"\n")
            .build(Wgs84)
            .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("motion[0].duration: duration must be positive"),
            "{e}"
        );
        let e = spec("[[motion]]\ntype = \"hold\"\nduration = \"3 deg/s\"\n")
            .build(Wgs84)
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("motion[0].duration: expected a time, got deg/s"),
            "{e}"
        );
        let e = spec("[[motion]]\ntype = \"hold\"\nduration = 3\n")
            .build(Wgs84)
            .unwrap_err();
        assert!(e.to_string().contains("has no unit"), "{e}");
        let e = toml::from_str::<MotionSpec>(
            "[start]\nposition = [\"45 deg\", \"7 deg\", \"100 m\"]\nattitude = [\"0 deg\", \"0 deg\", \"0 deg\"]\n[[motion]]\ntype = \"loop\"\nduration = \"3 s\"\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("unknown variant `loop`"), "{e}");
        let e = spec("[[motion]]\ntype = \"hover\"\nduration = \"3 s\"\n")
            .build(Wgs84)
            .unwrap_err();
        assert!(
            e.to_string().contains("hover needs the vehicle at rest"),
            "{e}"
        );
    }
}
