//! The vehicle's motion in the single-channel models: its speed along the equator
//! `V(t) = a λ'(t)` (rest, constant speed, smooth accelerations) and, for the SINS, the
//! body angle `D(t)` between the body axis p2 and the horizon (rest, turns by an angle,
//! continuous rotation at a rate) (textbook fig. 1, (5), (7)).
//!
//! Every change is a smooth step `s(u) = u - sin(2πu)/(2π)` over its duration
//! (`s' = 1 - cos 2πu`: zero rate of change at both ends, peak twice the mean), so the
//! profiles are C1 in their derivative and RK4 resolves them; the step is symmetric, so a
//! change acts, to first order, as an instantaneous one at its midpoint.

use super::ChannelError;
use super::error::{finite, positive};
use std::f64::consts::TAU;

/// Smooth unit step at `u` in [0, 1]: value `s`, slope `s'` and integral `∫0^u s`.
fn smooth_step(u: f64) -> (f64, f64, f64) {
    if u <= 0.0 {
        (0.0, 0.0, 0.0)
    } else if u >= 1.0 {
        (1.0, 0.0, 0.5 + (u - 1.0))
    } else {
        let (s2, c2) = (TAU * u).sin_cos();
        (
            u - s2 / TAU,
            1.0 - c2,
            0.5 * u * u + (c2 - 1.0) / (TAU * TAU),
        )
    }
}

/// A smooth speed change by `delta_v` [m/s] over `[start, start + duration]` \[s\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedChange {
    /// Start time \[s\].
    pub start: f64,
    /// Duration \[s\], > 0.
    pub duration: f64,
    /// Speed change [m/s].
    pub delta_v: f64,
}

/// Speed along the equator `V(t)` [m/s] (eastward positive, (6)).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SpeedProfile {
    /// Speed at t = 0 [m/s].
    pub initial: f64,
    /// Smooth accelerations and decelerations.
    pub changes: Vec<SpeedChange>,
}

impl SpeedProfile {
    /// Constant speed `v` [m/s] (0: at rest).
    pub fn constant(v: f64) -> Self {
        Self {
            initial: v,
            changes: Vec::new(),
        }
    }

    /// Adds a smooth speed change by `delta_v` [m/s] over `[start, start + duration]`.
    pub fn with_change(mut self, start: f64, duration: f64, delta_v: f64) -> Self {
        self.changes.push(SpeedChange {
            start,
            duration,
            delta_v,
        });
        self
    }

    /// Speed `V(t)` [m/s].
    pub fn speed(&self, t: f64) -> f64 {
        self.initial
            + self
                .changes
                .iter()
                .map(|c| c.delta_v * smooth_step((t - c.start) / c.duration).0)
                .sum::<f64>()
    }

    /// Acceleration along the path `V'(t) = f_x2` [m/s^2] (5).
    pub fn accel(&self, t: f64) -> f64 {
        self.changes
            .iter()
            .map(|c| c.delta_v / c.duration * smooth_step((t - c.start) / c.duration).1)
            .sum()
    }

    /// Distance travelled since t = 0, `∫0^t V dt` \[m\] (t >= 0).
    pub fn distance(&self, t: f64) -> f64 {
        self.initial * t
            + self
                .changes
                .iter()
                .map(|c| {
                    let from = c.duration * smooth_step(-c.start / c.duration).2;
                    c.delta_v * (c.duration * smooth_step((t - c.start) / c.duration).2 - from)
                })
                .sum::<f64>()
    }

    /// True when the speed never changes.
    pub fn is_constant(&self) -> bool {
        self.changes.iter().all(|c| c.delta_v == 0.0)
    }

    /// Checks every value is finite and every duration positive.
    pub fn validate(&self) -> Result<(), ChannelError> {
        finite("initial speed", self.initial)?;
        for c in &self.changes {
            finite("speed change start", c.start)?;
            positive("speed change duration", c.duration)?;
            finite("speed change", c.delta_v)?;
        }
        Ok(())
    }
}

/// A turn of the body by `angle` \[rad\] over `[start, start + duration]` \[s\] (D increases for positive angles).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turn {
    /// Start time \[s\].
    pub start: f64,
    /// Duration \[s\], > 0.
    pub duration: f64,
    /// Turn angle \[rad\].
    pub angle: f64,
}

impl Turn {
    /// Midpoint of the turn \[s\]: where an instantaneous turn acts the same to first order.
    pub fn midpoint(&self) -> f64 {
        self.start + 0.5 * self.duration
    }
}

/// Body angle `D(t)` \[rad\] of the SINS to the horizon (fig. 1, (7)): initial angle,
/// continuous rotation at a constant rate, and turns.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BodyAngleProfile {
    /// D at t = 0 \[rad\].
    pub initial: f64,
    /// Continuous rotation rate dD/dt [rad/s].
    pub rate: f64,
    /// Turns by an angle.
    pub turns: Vec<Turn>,
}

impl BodyAngleProfile {
    /// A body held at angle `d` \[rad\].
    pub fn fixed(d: f64) -> Self {
        Self {
            initial: d,
            rate: 0.0,
            turns: Vec::new(),
        }
    }

    /// Adds a turn by `angle` \[rad\] over `[start, start + duration]`.
    pub fn with_turn(mut self, start: f64, duration: f64, angle: f64) -> Self {
        self.turns.push(Turn {
            start,
            duration,
            angle,
        });
        self
    }

    /// Sets the continuous rotation rate [rad/s].
    pub fn with_rate(mut self, rate: f64) -> Self {
        self.rate = rate;
        self
    }

    /// `D(t)` \[rad\].
    pub fn angle(&self, t: f64) -> f64 {
        self.initial
            + self.rate * t
            + self
                .turns
                .iter()
                .map(|c| c.angle * smooth_step((t - c.start) / c.duration).0)
                .sum::<f64>()
    }

    /// `dD/dt` [rad/s].
    pub fn angle_rate(&self, t: f64) -> f64 {
        self.rate
            + self
                .turns
                .iter()
                .map(|c| c.angle / c.duration * smooth_step((t - c.start) / c.duration).1)
                .sum::<f64>()
    }

    /// True when D never changes.
    pub fn is_constant(&self) -> bool {
        self.rate == 0.0 && self.turns.iter().all(|c| c.angle == 0.0)
    }

    /// Checks every value is finite and every duration positive.
    pub fn validate(&self) -> Result<(), ChannelError> {
        finite("initial body angle", self.initial)?;
        finite("rotation rate", self.rate)?;
        for c in &self.turns {
            finite("turn start", c.start)?;
            positive("turn duration", c.duration)?;
            finite("turn angle", c.angle)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_profile_derivatives_are_consistent() {
        let p = SpeedProfile::constant(10.0).with_change(100.0, 60.0, 240.0);
        assert_eq!(p.speed(0.0), 10.0);
        assert!((p.speed(160.0) - 250.0).abs() < 1e-12);
        assert!((p.speed(130.0) - 130.0).abs() < 1e-9, "symmetric midpoint");
        // Distance: 10 t before, then a trapezoid-like ramp with mean 130 m/s over 60 s.
        assert!((p.distance(100.0) - 1000.0).abs() < 1e-9);
        assert!((p.distance(160.0) - (1600.0 + 60.0 * 120.0)).abs() < 1e-9);
        // Central differences (h = 1e-3 s) of distance and speed.
        for &t in &[110.0, 130.0, 155.0] {
            let h = 1e-3;
            let v = (p.distance(t + h) - p.distance(t - h)) / (2.0 * h);
            let a = (p.speed(t + h) - p.speed(t - h)) / (2.0 * h);
            assert!((v - p.speed(t)).abs() < 1e-6);
            assert!((a - p.accel(t)).abs() < 1e-6);
        }
    }

    #[test]
    fn turn_reaches_its_angle() {
        let p = BodyAngleProfile::fixed(0.1).with_turn(50.0, 6.0, std::f64::consts::PI);
        assert_eq!(p.angle(50.0), 0.1);
        assert!((p.angle(56.0) - 0.1 - std::f64::consts::PI).abs() < 1e-15);
        assert!((p.angle_rate(53.0) - 2.0 * std::f64::consts::PI / 6.0).abs() < 1e-12);
    }
}
