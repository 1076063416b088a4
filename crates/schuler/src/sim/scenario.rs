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

use super::motion::{KnotFeed, MotionBuilder, MotionError, Piece, Shape, Start, VelocityAxes};
use super::receivers::Interval;
use super::spline::SplineTrajectory;
use crate::earth::{EarthModel, Geodetic};
use crate::rotation::{Euler, wrap_pi};
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
    /// Follow waypoints: for each, turn towards it (coordinated, at most `bank`),
    /// change speed (at most `accel`), climb or descend to its height (at most
    /// `pitch`), then fly straight to it. Every piece is smooth, so acceleration and
    /// jerk stay bounded.
    Route {
        /// The waypoints in order.
        waypoints: Vec<WaypointSpec>,
        /// Largest bank angle (default 20 deg).
        bank: Option<Quantity>,
        /// Largest acceleration (default 1 m/s^2).
        accel: Option<Quantity>,
        /// Largest flight-path angle (default 5 deg).
        pitch: Option<Quantity>,
    },
}

/// One waypoint of a route.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WaypointSpec {
    /// Latitude, longitude, height.
    pub position: [Quantity; 3],
    /// Speed on the leg to this waypoint (default: the current speed).
    pub speed: Option<Quantity>,
    /// Arrival time [scenario time]; sets the leg's speed (exclusive with `speed`).
    pub time: Option<Quantity>,
}

/// A scenario's motion part.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct MotionSpec {
    /// Initial state.
    pub start: StartSpec,
    /// Segments in order.
    pub motion: Vec<SegmentSpec>,
}

/// Why a scenario is invalid: the key and the reason. A [`ScenarioError::Motion`]
/// names the key and gives the motion's error as its `source()`, as an error chain
/// does (anyhow's `{:#}`, `key: reason`), not in its own message as well.
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
    /// The motion could not be integrated; why is the `source()`.
    #[error("{key}")]
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

/// Change forward speed to `target` [m/s] with peak acceleration `a` [m/s^2]
/// (plateau profile: smooth ramps, bounded jerk).
fn accelerate_to<E: EarthModel>(
    b: &mut MotionBuilder<E>,
    key: &str,
    target: f64,
    a: f64,
) -> Result<(), ScenarioError> {
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

/// Coordinated turn by `angle` [rad] at bank `bank` [rad, sign of `angle`], rolling
/// in and out with peak roll rate `roll_rate` [rad/s].
fn turn_by<E: EarthModel>(
    b: &mut MotionBuilder<E>,
    key: &str,
    angle: f64,
    bank: f64,
    roll_rate: f64,
) -> Result<(), ScenarioError> {
    let v = b.state().v_n.xy().norm();
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

/// Climb or descend to `target` [m] at flight-path angle `theta` [rad, > 0], pitching
/// with peak rate `pitch_rate` [rad/s].
fn climb_to<E: EarthModel>(
    b: &mut MotionBuilder<E>,
    key: &str,
    target: f64,
    theta: f64,
    pitch_rate: f64,
) -> Result<(), ScenarioError> {
    let s = b.state();
    let dh = target - s.pos.h;
    if dh.abs() < 1e-6 {
        return Ok(());
    }
    let v = forward_speed(&s);
    let theta = theta.copysign(dh);
    let ramp = BUMP_PEAK * theta.abs() / pitch_rate;
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

/// Defaults of route following.
const DEFAULT_ROUTE_BANK: f64 = 20.0 * units::DEG;
const DEFAULT_ROUTE_ACCEL: f64 = 1.0;
/// Peak yaw rate of a turn on the spot [rad/s].
const SPOT_TURN_RATE: f64 = 20.0 * units::DEG;
/// Heading errors below this are not corrected [rad].
const ROUTE_HEADING_TOLERANCE: f64 = 1e-4;

/// NED offset of `p` from the state's position, and its horizontal bearing.
fn offset_to<E: EarthModel>(earth: &E, s: &Start, p: &Geodetic) -> (Vector3<f64>, f64) {
    let d_e = earth.geodetic_to_ecef(p) - earth.geodetic_to_ecef(&s.pos);
    let d_n = crate::earth::c_ne(s.pos.lat, s.pos.lon).transpose() * d_e;
    (d_n, d_n.y.atan2(d_n.x))
}

/// Turn towards `p` if the heading is off by more than the tolerance, at a bank no
/// larger than `bank` and small enough that rolling in and out does not overshoot.
fn head_for<E: EarthModel>(
    b: &mut MotionBuilder<E>,
    earth: &E,
    key: &str,
    p: &Geodetic,
    bank: f64,
) -> Result<(), ScenarioError> {
    let s = b.state();
    let (_, bearing) = offset_to(earth, &s, p);
    let d_psi = wrap_pi(bearing - s.attitude.yaw);
    if d_psi.abs() < ROUTE_HEADING_TOLERANCE {
        return Ok(());
    }
    let v = s.v_n.xy().norm();
    // Rolling in and out turns about 1.875 g bank^2 / (V roll_rate); keep it to 80 %
    // of the turn.
    let feasible = (0.8 * d_psi.abs() * v * DEFAULT_ROLL_RATE / (BUMP_PEAK * units::G0)).sqrt();
    turn_by(
        b,
        key,
        d_psi,
        bank.min(feasible).copysign(d_psi),
        DEFAULT_ROLL_RATE,
    )
}

/// Follow a route (see [`SegmentSpec::Route`]).
fn route<E: EarthModel>(
    b: &mut MotionBuilder<E>,
    key: &str,
    points: &[WaypointSpec],
    bank: f64,
    accel: f64,
    pitch: f64,
) -> Result<(), ScenarioError> {
    let earth = b.earth();
    for (i, w) in points.iter().enumerate() {
        let wk = format!("{key}.waypoints[{i}]");
        let p = Geodetic::new(
            w.position[0].si(&format!("{wk}.position[0]"), Dimension::Angle)?,
            w.position[1].si(&format!("{wk}.position[1]"), Dimension::Angle)?,
            w.position[2].si(&format!("{wk}.position[2]"), Dimension::Length)?,
        );
        let s = b.state();
        let (d_n, _) = offset_to(&earth, &s, &p);
        let arrival = match &w.time {
            Some(q) => Some(q.si(&format!("{wk}.time"), Dimension::Time)?),
            None => None,
        };
        let speed = match (&w.speed, &w.time) {
            (Some(_), Some(_)) => {
                return Err(ScenarioError::value(
                    &wk,
                    "give speed or time, not both".into(),
                ));
            }
            (Some(q), None) => positive(
                &format!("{wk}.speed"),
                q.si(&format!("{wk}.speed"), Dimension::Velocity)?,
                "speed",
            )?,
            (None, Some(q)) => {
                let t = q.si(&format!("{wk}.time"), Dimension::Time)?;
                positive(
                    &format!("{wk}.time"),
                    t - s.t,
                    "time left to reach the waypoint",
                )
                .map(|left| d_n.xy().norm() / left)?
            }
            (None, None) => s.v_n.xy().norm(),
        };
        match arrival {
            None => fly_leg(b, &earth, &wk, &p, speed, bank, accel, pitch)?,
            Some(t_arrive) => {
                // The turns, speed change and climb at the start of the leg make the
                // flight longer than the straight line: adjust the speed until the
                // arrival time matches (the leg time is close to a + d/v, so the
                // ratio update converges in a few passes).
                let t0 = s.t;
                let mut v = speed;
                let mut best = None;
                for _ in 0..8 {
                    let mut trial = b.clone();
                    fly_leg(&mut trial, &earth, &wk, &p, v, bank, accel, pitch)?;
                    let took = trial.state().t - t0;
                    let miss = took - (t_arrive - t0);
                    best = Some(trial);
                    if miss.abs() < 1e-3 {
                        break;
                    }
                    v *= took / (t_arrive - t0);
                }
                if let Some(trial) = best {
                    *b = trial;
                }
            }
        }
    }
    Ok(())
}

/// One leg of a route: turn towards `p`, change speed, climb, fly straight to it.
#[allow(clippy::too_many_arguments)]
fn fly_leg<E: EarthModel>(
    b: &mut MotionBuilder<E>,
    earth: &E,
    wk: &str,
    p: &Geodetic,
    speed: f64,
    bank: f64,
    accel: f64,
    pitch: f64,
) -> Result<(), ScenarioError> {
    let s = b.state();
    let (leg, _) = offset_to(earth, &s, p);
    if speed < 1.0 {
        return Err(ScenarioError::value(
            wk,
            format!("a leg needs a speed of at least 1 m/s, got {speed:.3} m/s"),
        ));
    }
    if s.v_n.norm() < 1.0 {
        // From rest: face the waypoint, then accelerate.
        let (_, bearing) = offset_to(earth, &s, p);
        let d_psi = wrap_pi(bearing - s.attitude.yaw);
        if d_psi.abs() > ROUTE_HEADING_TOLERANCE {
            let d = (BUMP_PEAK * d_psi.abs() / SPOT_TURN_RATE).max(1.0);
            push(b, wk, &bump(d, [0.0, 0.0, d_psi], false))?;
        }
        accelerate_to(b, wk, speed, accel)?;
    } else {
        accelerate_to(b, wk, speed, accel)?;
        head_for(b, earth, wk, p, bank)?;
    }
    // The turn displaced the vehicle: correct the heading once more.
    head_for(b, earth, wk, p, bank)?;
    let s = b.state();
    let dh = p.h - s.pos.h;
    if dh.abs() > 1e-3 {
        // Pitching up and down alone changes about V theta^2 1.875/rate: keep it to
        // 80 % of the height change.
        let feasible = (0.8 * dh.abs() * DEFAULT_PITCH_RATE / (BUMP_PEAK * speed)).sqrt();
        climb_to(b, wk, p.h, pitch.min(feasible), DEFAULT_PITCH_RATE)?;
    }
    let s = b.state();
    let (d_n_now, _) = offset_to(earth, &s, p);
    let heading = Vector3::new(s.attitude.yaw.cos(), s.attitude.yaw.sin(), 0.0);
    let along = d_n_now.dot(&heading);
    if along < 0.0 {
        return Err(ScenarioError::value(
            wk,
            format!(
                "the waypoint ({:.0} m away at the start of the leg) is too close for the turn, speed and height changes before it: they overshoot it by {:.0} m",
                leg.xy().norm(),
                -along
            ),
        ));
    }
    let v = forward_speed(&s);
    if along > 1e-3 {
        push(b, wk, &Piece::hold(along / v))?;
    }
    Ok(())
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
            accelerate_to(b, key, target, a)
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
            turn_by(b, key, angle, bank, roll_rate)
        }
        SegmentSpec::Climb {
            to_height,
            pitch,
            pitch_rate,
        } => {
            let target = to_height.si(&k("to_height"), Dimension::Length)?;
            let v = forward_speed(&b.state());
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
            let rate = match pitch_rate {
                Some(q) => positive(
                    &k("pitch_rate"),
                    q.si(&k("pitch_rate"), Dimension::AngularRate)?,
                    "pitch_rate",
                )?,
                None => DEFAULT_PITCH_RATE,
            };
            climb_to(b, key, target, theta, rate)
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
        SegmentSpec::Route {
            waypoints,
            bank,
            accel,
            pitch,
        } => {
            let bank = match bank {
                Some(q) => q.si(&k("bank"), Dimension::Angle)?.abs(),
                None => DEFAULT_ROUTE_BANK,
            };
            if !(bank > 0.0 && bank < 80.0 * units::DEG) {
                return Err(ScenarioError::value(
                    &k("bank"),
                    "the bank limit must be between 0 and 80 deg".into(),
                ));
            }
            let accel = match accel {
                Some(q) => positive(
                    &k("accel"),
                    q.si(&k("accel"), Dimension::Acceleration)?.abs(),
                    "accel",
                )?,
                None => DEFAULT_ROUTE_ACCEL,
            };
            let pitch = match pitch {
                Some(q) => q.si(&k("pitch"), Dimension::Angle)?.abs(),
                None => DEFAULT_CLIMB_PITCH,
            };
            if !(pitch > 0.0 && pitch < 60.0 * units::DEG) {
                return Err(ScenarioError::value(
                    &k("pitch"),
                    "the flight-path angle limit must be between 0 and 60 deg".into(),
                ));
            }
            if waypoints.is_empty() {
                return Err(ScenarioError::value(&k("waypoints"), "no waypoints".into()));
            }
            route(b, key, waypoints, bank, accel, pitch)
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
        self.builder(earth, None)?
            .finish()
            .map_err(Self::motion_error)
    }

    /// [`MotionSpec::build`] with the knots sent to `feed` as they are made and not
    /// kept (constant memory): the motion's span.
    pub fn build_fed<E: EarthModel>(
        &self,
        earth: E,
        feed: KnotFeed,
    ) -> Result<Interval, ScenarioError> {
        self.builder(earth, Some(feed))?
            .finish_fed()
            .map_err(Self::motion_error)
    }

    /// A builder with every segment pushed.
    fn builder<E: EarthModel>(
        &self,
        earth: E,
        feed: Option<KnotFeed>,
    ) -> Result<MotionBuilder<E>, ScenarioError> {
        let start = self.start.resolve()?;
        if self.motion.is_empty() {
            return Err(ScenarioError::value(
                "motion",
                "no segments: add at least one [[motion]] table".into(),
            ));
        }
        let mut b = MotionBuilder::new(earth, &start);
        if let Some(feed) = feed {
            b.feed(feed);
        }
        for (i, seg) in self.motion.iter().enumerate() {
            compile(&mut b, &format!("motion[{i}]"), seg)?;
        }
        Ok(b)
    }

    fn motion_error(source: MotionError) -> ScenarioError {
        ScenarioError::Motion {
            key: "motion".into(),
            source,
        }
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

    /// A route of three waypoints 2.5-6 km apart, one with an arrival time: the vehicle
    /// ends level within a metre of the last waypoint (measured 0.8 m: the residual
    /// heading error after the correcting turn, below 1e-4 rad, over a 4-km leg) and
    /// on time (the leg speed is iterated until the arrival time matches to 1 ms).
    #[test]
    fn route_reaches_waypoints() {
        let t = spec(
            "[[motion]]\ntype = \"route\"\nbank = \"25 deg\"\nwaypoints = [\n\
             { position = [\"45.05 deg\", \"7.02 deg\", \"300 m\"], speed = \"60 m/s\" },\n\
             { position = [\"45.05 deg\", \"7.10 deg\", \"250 m\"] },\n\
             { position = [\"45.01 deg\", \"7.10 deg\", \"400 m\"], time = \"450 s\" },\n]\n",
        )
        .build(Wgs84)
        .expect("builds");
        let end = analytic::state(&Wgs84, &t, t.end());
        let last = Geodetic::from_degrees(45.01, 7.10, 400.0);
        let (d_n, _) = offset_to(
            &Wgs84,
            &Start {
                t: 0.0,
                pos: end.pos,
                v_n: end.v_n,
                attitude: end.euler(),
            },
            &last,
        );
        eprintln!(
            "route: end {:.3} m from the last waypoint, at t = {:.1} s",
            d_n.norm(),
            t.end()
        );
        assert!(d_n.norm() < 1.0, "{d_n}");
        assert!(end.euler().roll.abs() < 1e-9 && end.euler().pitch.abs() < 1e-9);
        assert!((t.end() - 450.0).abs() < 1e-2, "{}", t.end());
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

    /// A motion that flies past 89.9 deg names its key, with the reason as the error's
    /// source and not in its message too (a chain printer would show it twice): from
    /// 89.89 deg north at 50 m/s, 1.1 km from the limit, a 60-s hold reaches it.
    #[test]
    fn a_motion_error_gives_its_reason_once() {
        let text = "[start]\nposition = [\"89.89 deg\", \"7 deg\", \"100 m\"]\nattitude = [\"0 deg\", \"0 deg\", \"0 deg\"]\nspeed = \"50 m/s\"\n[[motion]]\ntype = \"hold\"\nduration = \"60 s\"\n";
        let e = toml::from_str::<MotionSpec>(text)
            .expect("valid TOML")
            .build(Wgs84)
            .unwrap_err();
        assert!(matches!(e, ScenarioError::Motion { .. }), "{e:?}");
        assert_eq!(e.to_string(), "motion[0]");
        let reason = std::error::Error::source(&e).expect("a source").to_string();
        assert!(reason.contains("reaches latitude 89.9"), "{reason}");
    }
}
