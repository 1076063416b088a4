//! Land-vehicle sensors from the simulator's truth: an odometer (forward speed with a
//! scale-factor error and white noise), a dual-antenna GNSS heading (the baseline's
//! true heading and pitch plus white noise), and the rest intervals of a trajectory
//! (where its speed is zero), for zero-velocity updates.

use crate::filter::vehicle::{Baseline, HeadingReading, heading_pitch};
use crate::imu::random::Noise;
use crate::nav::NavState;

/// Stream ids (after the IMU's 1, GNSS's 2 and the barometer's 3).
const STREAM_ODOMETER: u64 = 4;
const STREAM_HEADING: u64 = 5;

/// Odometer parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometerModel {
    /// Scale-factor error `k`: the reading is `(1 + k) s + noise`.
    pub scale: f64,
    /// White noise std [m/s].
    pub noise: f64,
}

/// A seeded odometer.
#[derive(Debug)]
pub struct OdometerSimulator {
    model: OdometerModel,
    noise: Noise,
}

impl OdometerSimulator {
    /// An odometer of `model` drawing from `seed`.
    pub fn new(model: OdometerModel, seed: u64) -> Self {
        Self {
            model,
            noise: Noise::new(seed, STREAM_ODOMETER),
        }
    }

    /// The reading for the true forward speed `speed` [m/s]: `(1 + k) speed + noise`.
    pub fn reading(&mut self, speed: f64) -> f64 {
        (1.0 + self.model.scale) * speed + self.model.noise * self.noise.normal()
    }
}

/// A seeded dual-antenna receiver.
#[derive(Debug)]
pub struct HeadingSimulator {
    baseline: Baseline,
    heading_std: f64,
    pitch_std: Option<f64>,
    noise: Noise,
}

impl HeadingSimulator {
    /// A receiver whose antennas lie along `baseline` in body axes, reporting heading
    /// with noise `heading_std` [rad] and, with `pitch_std`, the baseline's pitch.
    pub fn new(baseline: Baseline, heading_std: f64, pitch_std: Option<f64>, seed: u64) -> Self {
        Self {
            baseline,
            heading_std,
            pitch_std,
            noise: Noise::new(seed, STREAM_HEADING),
        }
    }

    /// The reading at truth `s`; `None` for a vertical baseline. Noise is drawn for
    /// both angles every time.
    pub fn reading(&mut self, s: &NavState) -> Option<HeadingReading> {
        let (n_heading, n_pitch) = (self.noise.normal(), self.noise.normal());
        let (heading, pitch) = heading_pitch(&(s.q_bn * self.baseline.unit_b()))?;
        Some(HeadingReading {
            t: s.t,
            heading: crate::rotation::wrap_pi(heading + self.heading_std * n_heading),
            heading_std: self.heading_std,
            pitch: self.pitch_std.map(|std| (pitch + std * n_pitch, std)),
        })
    }
}

/// The intervals `[t0, t1]` over which the truth's speed stays at most `max_speed`
/// [m/s], at least `min_length` [s] long, from states in time order.
pub fn rest_intervals<'a>(
    truth: impl IntoIterator<Item = &'a NavState>,
    max_speed: f64,
    min_length: f64,
) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut open: Option<(f64, f64)> = None;
    for s in truth {
        let still = s.v_n.norm() <= max_speed;
        open = match (open, still) {
            (None, true) => Some((s.t, s.t)),
            (Some((a, _)), true) => Some((a, s.t)),
            (Some(iv), false) => {
                out.push(iv);
                None
            }
            (None, false) => None,
        };
    }
    out.extend(open);
    out.retain(|(a, b)| b - a >= min_length);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::Geodetic;
    use crate::rotation::Euler;
    use nalgebra::Vector3;

    fn state(t: f64, speed: f64) -> NavState {
        NavState::new(
            t,
            Geodetic::from_degrees(45.0, 7.0, 100.0),
            Vector3::new(speed, 0.0, 0.0),
            Euler::from_degrees(0.0, 0.0, 170.0),
        )
    }

    #[test]
    fn rest_intervals_follow_the_speed() {
        let speeds = [0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 5.0, 0.0];
        let states: Vec<NavState> = speeds
            .iter()
            .enumerate()
            .map(|(i, &v)| state(i as f64, v))
            .collect();
        assert_eq!(
            rest_intervals(&states, 1e-9, 0.5),
            vec![(0.0, 2.0), (4.0, 5.0)]
        );
        // The last single rest sample is shorter than 0.5 s.
        assert_eq!(rest_intervals(&states, 1e-9, 0.0).last(), Some(&(7.0, 7.0)));
    }

    #[test]
    fn readings_are_the_truth_plus_their_errors() {
        let mut odo = OdometerSimulator::new(
            OdometerModel {
                scale: 0.01,
                noise: 0.0,
            },
            1,
        );
        assert!((odo.reading(10.0) - 10.1).abs() < 1e-12);
        let b = Baseline {
            yaw: 20f64.to_radians(),
            pitch: 0.0,
        };
        // Heading 170° + 20° = 190°, written in (−180°, 180°].
        let mut h = HeadingSimulator::new(b, 0.0, Some(0.0), 1);
        let r = h.reading(&state(3.0, 0.0)).expect("horizontal");
        assert!((r.heading - (-170f64).to_radians()).abs() < 1e-12);
        assert_eq!(r.t, 3.0);
        assert!(r.pitch.is_some_and(|(p, _)| p.abs() < 1e-12));
        // Noise of the given std: the RMS of 1000 draws scatters by 1/√2000 = 2.2 %,
        // so within 10 % (4.5 of those).
        let mut h = HeadingSimulator::new(b, 0.01, None, 2);
        let d: Vec<f64> = (0..1000)
            .map(|_| {
                h.reading(&state(0.0, 0.0))
                    .map_or(0.0, |r| r.heading + 170f64.to_radians())
            })
            .collect();
        let rms = (d.iter().map(|x| x * x).sum::<f64>() / 1000.0).sqrt();
        assert!((rms / 0.01 - 1.0).abs() < 0.1, "{rms}");
    }
}
