//! gnss-ins-sim motion-definition CSV files, read into our scenario segments so its
//! users can bring their scenarios.
//!
//! Layout (Aceinna gnss-ins-sim, `demo_motion_def_files`): a header line, the initial
//! state `lat (deg), lon (deg), alt (m), vx, vy, vz body (m/s), yaw, pitch, roll (deg)`,
//! a second header line, then commands
//! `type, yaw, pitch, roll (deg or deg/s), vx, vy, vz body (m/s or m/s^2), duration (s),
//! GPS visibility (1/0)`. Command types:
//! 1. Euler-angle rates and body-velocity rates held for the duration — a plateau
//!    piece in body axes with exactly the commanded totals, ramped over 0.02 s at each
//!    end where gnss-ins-sim steps, so accelerations stay continuous (gnss-ins-sim's
//!    own attitude response lags its commands by about 0.09 s and ends turns short:
//!    on its drive9min data set our trajectory differs from its truth by at most
//!    0.6 deg of yaw and 2.5 m);
//! 2. absolute attitude and body velocity to reach; 3. relative attitude and velocity;
//! 4. absolute attitude, relative velocity; 5. relative attitude, absolute velocity.
//!    Types 2–5 change smoothly (absolute yaw and roll the short way round) (bump profile) as fast as gnss-ins-sim's "high
//!    mobility" limits allow (1 m/s^2, 0.5 rad/s^2, 2 rad/s peak), then hold for the
//!    rest of the duration; a duration too short for the change is extended to it.
//!
//! Rows with GPS visibility 0 become GNSS outage intervals.

use super::motion::{Piece, Shape, VelocityAxes};
use super::scenario::ScenarioError;
use crate::earth::Geodetic;
use crate::rotation::Euler;
use crate::units::DEG;
use nalgebra::Vector3;

/// A parsed motion definition.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionDefinition {
    /// Initial position.
    pub pos: Geodetic,
    /// Initial body-frame velocity [m/s].
    pub v_body: Vector3<f64>,
    /// Initial attitude.
    pub attitude: Euler,
    /// Commands in order.
    pub commands: Vec<Command>,
}

/// One command line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// 1-based line number in the file.
    pub line: usize,
    /// Command type 1..=5.
    pub kind: u8,
    /// Yaw, pitch, roll values [rad or rad/s].
    pub ypr: [f64; 3],
    /// Body velocity values [m/s or m/s^2].
    pub v_body: [f64; 3],
    /// Duration [s].
    pub duration: f64,
    /// GNSS visible during the command.
    pub gps: bool,
}

fn err(line: usize, field: &str, message: String) -> ScenarioError {
    ScenarioError::Value {
        key: format!("line {line}, {field}"),
        message,
    }
}

fn numbers(line: usize, text: &str, names: &[&str]) -> Result<Vec<f64>, ScenarioError> {
    let fields: Vec<&str> = text.split(',').map(str::trim).collect();
    if fields.len() < names.len() {
        return Err(err(
            line,
            "columns",
            format!("expected {} columns, found {}", names.len(), fields.len()),
        ));
    }
    fields
        .iter()
        .zip(names)
        .map(|(f, name)| {
            f.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| err(line, name, format!("not a finite number: {f:?}")))
        })
        .collect()
}

const INIT: [&str; 9] = [
    "lat", "lon", "alt", "vx", "vy", "vz", "yaw", "pitch", "roll",
];
const CMD: [&str; 9] = [
    "type",
    "yaw",
    "pitch",
    "roll",
    "vx",
    "vy",
    "vz",
    "duration",
    "GPS visibility",
];

/// Parse the text of a motion-definition file.
pub fn parse(text: &str) -> Result<MotionDefinition, ScenarioError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l))
        .filter(|(_, l)| !l.trim().is_empty());
    let _header = lines
        .next()
        .ok_or_else(|| err(1, "file", "empty file".into()))?;
    let (ln, init) = lines
        .next()
        .ok_or_else(|| err(2, "initial state", "missing".into()))?;
    let v = numbers(ln, init, &INIT)?;
    let _header2 = lines
        .next()
        .ok_or_else(|| err(ln + 1, "command header", "missing".into()))?;
    let mut commands = Vec::new();
    for (ln, l) in lines {
        let c = numbers(ln, l, &CMD)?;
        let kind = c[0];
        if !(1.0..=5.0).contains(&kind) || kind.fract() != 0.0 {
            return Err(err(
                ln,
                "type",
                format!("unknown command type {kind}: expected 1 to 5"),
            ));
        }
        if c[7] <= 0.0 {
            return Err(err(
                ln,
                "duration",
                format!("must be positive, got {} s", c[7]),
            ));
        }
        commands.push(Command {
            line: ln,
            kind: kind as u8,
            ypr: [c[1] * DEG, c[2] * DEG, c[3] * DEG],
            v_body: [c[4], c[5], c[6]],
            duration: c[7],
            gps: c[8] != 0.0,
        });
    }
    if commands.is_empty() {
        return Err(err(ln, "commands", "no command lines".into()));
    }
    Ok(MotionDefinition {
        pos: Geodetic::new(v[0] * DEG, v[1] * DEG, v[2]),
        v_body: Vector3::new(v[3], v[4], v[5]),
        attitude: Euler::new(v[8] * DEG, v[7] * DEG, v[6] * DEG),
        commands,
    })
}

/// gnss-ins-sim's high-mobility limits: acceleration [m/s^2], angular rate [rad/s].
const MAX_ACCEL: f64 = 1.0;
const MAX_RATE: f64 = 2.0;
const MAX_ANG_ACCEL: f64 = 0.5;
/// Ramp of a type-1 step at each end [s] (two samples at 100 Hz).
const MIN_RAMP: f64 = 0.02;

/// Shortest bump duration that changes angles by `d_ang` and speed by `d_v` within the
/// limits (bump peak rate 1.875 mean, peak derivative 5.77 mean / T).
fn change_time(d_ang: f64, d_v: f64) -> f64 {
    let by_rate = 1.875 * d_ang / MAX_RATE;
    let by_ang_accel = (5.774 * d_ang / MAX_ANG_ACCEL).sqrt();
    let by_accel = 1.875 * d_v / MAX_ACCEL;
    by_rate.max(by_ang_accel).max(by_accel)
}

impl MotionDefinition {
    /// Pieces of motion and the GNSS outages, following the commands from the initial
    /// attitude and body velocity (tracked exactly: the pieces' totals are exact).
    pub fn pieces(&self) -> (Vec<Piece>, Vec<[f64; 2]>) {
        let mut pieces = Vec::new();
        let mut outages: Vec<[f64; 2]> = Vec::new();
        let mut att = [self.attitude.yaw, self.attitude.pitch, self.attitude.roll];
        let mut vb = [self.v_body.x, self.v_body.y, self.v_body.z];
        let mut t = 0.0;
        for c in &self.commands {
            let start = t;
            match c.kind {
                1 => {
                    let d = c.duration;
                    pieces.push(Piece {
                        duration: d,
                        d_euler: [c.ypr[2] * d, c.ypr[1] * d, c.ypr[0] * d],
                        d_vel: c.v_body.map(|a| a * d),
                        axes: VelocityAxes::Body,
                        shape: Shape::Plateau((MIN_RAMP / d).min(0.5)),
                        coordinated: false,
                    });
                    for i in 0..3 {
                        att[i] += c.ypr[i] * d;
                        vb[i] += c.v_body[i] * d;
                    }
                    t += d;
                }
                kind => {
                    let abs_att = kind == 2 || kind == 4;
                    let abs_vel = kind == 2 || kind == 5;
                    // Absolute yaw and roll go the short way round; pitch is within +-90.
                    let wrap = |x: f64| {
                        (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI
                    };
                    let d_att: [f64; 3] = std::array::from_fn(|i| {
                        if abs_att {
                            wrap(c.ypr[i] - att[i])
                        } else {
                            c.ypr[i]
                        }
                    });
                    let d_v: [f64; 3] = std::array::from_fn(|i| {
                        if abs_vel {
                            c.v_body[i] - vb[i]
                        } else {
                            c.v_body[i]
                        }
                    });
                    let ang = d_att.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    let dv = d_v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    let change = change_time(ang, dv);
                    if change > 0.0 {
                        pieces.push(Piece {
                            duration: change,
                            d_euler: [d_att[2], d_att[1], d_att[0]],
                            d_vel: d_v,
                            axes: VelocityAxes::Body,
                            shape: Shape::Bump,
                            coordinated: false,
                        });
                    }
                    if c.duration > change {
                        pieces.push(Piece::hold(c.duration - change));
                    }
                    for i in 0..3 {
                        att[i] += d_att[i];
                        vb[i] += d_v[i];
                    }
                    t += c.duration.max(change);
                }
            }
            if !c.gps {
                match outages.last_mut() {
                    Some(last) if last[1] == start => last[1] = t,
                    _ => outages.push([start, t]),
                }
            }
        }
        (pieces, outages)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = "ini lat (deg),ini lon (deg),ini alt (m),ini vx_body (m/s),ini vy_body (m/s),ini vz_body (m/s),ini yaw (deg),ini pitch (deg),ini roll (deg)
45.0,7.0,100.0,0,0,0,10,0,0
command type,yaw (deg),pitch (deg),roll (deg),vx_body (m/s),vy_body (m/s),vz_body (m/s),command duration (s),GPS visibility
1,0,0,0,1.0,0,0,20,1
1,-3,0,0,0,0,0,60,0
2,90,0,0,10,0,0,30,0
";

    #[test]
    fn parses_and_maps_commands() {
        let m = parse(FILE).expect("parses");
        assert_eq!(m.commands.len(), 3);
        assert!((m.attitude.yaw - 10.0 * DEG).abs() < 1e-15);
        let (pieces, outages) = m.pieces();
        assert!((pieces[0].d_vel[0] - 20.0).abs() < 1e-12);
        assert!((pieces[1].d_euler[2] + 180.0 * DEG).abs() < 1e-12);
        // Type 2: yaw from 10 - 180 = -170 deg to 90 deg the short way (-100 deg),
        // speed 20 -> 10.
        assert!((pieces[2].d_euler[2] + 100.0 * DEG).abs() < 1e-12);
        assert!((pieces[2].d_vel[0] + 10.0).abs() < 1e-12);
        // Two consecutive invisible commands make one outage from 20 s to the end.
        assert_eq!(outages.len(), 1);
        assert_eq!(outages[0][0], 20.0);
    }

    #[test]
    fn errors_name_line_and_field() {
        let bad = FILE.replace("1,-3,0,0,0,0,0,60,0", "1,-3,x,0,0,0,0,60,0");
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.starts_with("line 5, pitch: not a finite number"), "{e}");
        let bad = FILE.replace("1,-3,0,0,0,0,0,60,0", "7,-3,0,0,0,0,0,60,0");
        assert!(
            parse(&bad)
                .unwrap_err()
                .to_string()
                .contains("unknown command type 7")
        );
    }
}
