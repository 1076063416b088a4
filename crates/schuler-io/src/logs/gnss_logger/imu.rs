//! Android's accelerometer and gyroscope, two sensors with their own timestamps and
//! rates, paired into IMU increments.
//!
//! The gyroscope's events are the samples' clock: for consecutive gyro events at
//! `t₀ < t₁` (the sensor's `elapsedRealtimeNanos`, kept in integer nanoseconds) the
//! sample is the trapezoid over `(t₀, t₁]`:
//! `Δθ = (ω(t₀) + ω(t₁))/2 · Δt`, `Δv = (f(t₀) + f(t₁))/2 · Δt`, `Δt = t₁ − t₀`,
//! where `f(t)` is the accelerometer linearly interpolated between the two accelerometer
//! events around `t`. Both are exact when the rate and the specific force vary linearly
//! over the interval; an Android sensor event is a low-pass-filtered sample at its
//! timestamp, not an integral, so this is the integral of the samples' straight-line
//! interpolation.
//!
//! A gyro event waits until an accelerometer event at or after its time has arrived
//! (the two streams interleave in the file by a few lines). Gyro events before the
//! first accelerometer event, or older than the accelerometer events kept
//! ([`ACCEL_KEPT`]), or still waiting at the end of the log, are dropped and counted; a
//! gap between gyro events longer than [`MAX_GAP_NS`] starts the pairing afresh
//! (counted) instead of integrating across it.

use nalgebra::Vector3;
use std::collections::VecDeque;

/// The longest interval between gyro events integrated into one sample [ns]: 0.2 s,
/// twenty periods of Android's slowest IMU rate that navigation uses (`SENSOR_DELAY_GAME`,
/// 50 Hz); a longer silence is a gap in the log.
pub(super) const MAX_GAP_NS: i64 = 200_000_000;
/// Accelerometer events kept for the interpolation.
const ACCEL_KEPT: usize = 64;
/// Gyro events that may wait for the accelerometer before the oldest is dropped.
const GYRO_WAITING: usize = 4096;

/// One paired sample: the interval `(t_ns − dt_ns, t_ns]` on the phone's clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Paired {
    pub t_ns: i64,
    pub dt_ns: i64,
    pub dtheta: Vector3<f64>,
    pub dvel: Vector3<f64>,
}

/// What the pairing left out.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PairingCounts {
    /// Gyro events without accelerometer events around them (dropped).
    pub unpaired_gyro: u64,
    /// Gaps longer than 0.2 s between gyro events (not integrated across).
    pub gaps: u64,
}

/// The pairing state (see the module's doc); vectors already in the body's axes.
#[derive(Debug, Default)]
pub(super) struct Pairer {
    accel: VecDeque<(i64, Vector3<f64>)>,
    waiting: VecDeque<(i64, Vector3<f64>)>,
    prev: Option<(i64, Vector3<f64>, Vector3<f64>)>,
    last_gyro: Option<i64>,
    pub counts: PairingCounts,
}

/// A sensor's timestamp that did not increase: the time met and the previous one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct NotIncreasing {
    pub t_ns: i64,
    pub previous_ns: i64,
}

impl Pairer {
    /// An accelerometer event `f` [m/s²] at `t_ns`; the samples it completes go to `out`.
    pub fn accel(
        &mut self,
        t_ns: i64,
        f: Vector3<f64>,
        out: &mut Vec<Paired>,
    ) -> Result<(), NotIncreasing> {
        if let Some(&(last, _)) = self.accel.back()
            && t_ns <= last
        {
            return Err(NotIncreasing {
                t_ns,
                previous_ns: last,
            });
        }
        self.accel.push_back((t_ns, f));
        if self.accel.len() > ACCEL_KEPT {
            self.accel.pop_front();
        }
        self.drain(out);
        Ok(())
    }

    /// A gyro event `w` [rad/s] at `t_ns`; the samples it completes go to `out`.
    pub fn gyro(
        &mut self,
        t_ns: i64,
        w: Vector3<f64>,
        out: &mut Vec<Paired>,
    ) -> Result<(), NotIncreasing> {
        if let Some(last) = self.last_gyro
            && t_ns <= last
        {
            return Err(NotIncreasing {
                t_ns,
                previous_ns: last,
            });
        }
        self.last_gyro = Some(t_ns);
        self.waiting.push_back((t_ns, w));
        if self.waiting.len() > GYRO_WAITING {
            self.waiting.pop_front();
            self.counts.unpaired_gyro += 1;
        }
        self.drain(out);
        Ok(())
    }

    /// Counts the gyro events still waiting at the end of the log.
    pub fn finish(&mut self) {
        self.counts.unpaired_gyro += self.waiting.len() as u64;
        self.waiting.clear();
    }

    /// The accelerometer at `t`, linearly interpolated; `Err(true)` when `t` is before
    /// the events kept, `Err(false)` when the event after `t` has not arrived yet.
    fn accel_at(&self, t: i64) -> Result<Vector3<f64>, bool> {
        let after = self
            .accel
            .iter()
            .position(|&(ta, _)| ta >= t)
            .ok_or(false)?;
        let (t1, f1) = self.accel[after];
        if t1 == t {
            return Ok(f1);
        }
        let (t0, f0) = *self
            .accel
            .get(after.checked_sub(1).ok_or(true)?)
            .ok_or(true)?;
        let s = (t - t0) as f64 / (t1 - t0) as f64;
        Ok(f0 + (f1 - f0) * s)
    }

    fn drain(&mut self, out: &mut Vec<Paired>) {
        while let Some(&(t, w)) = self.waiting.front() {
            let f = match self.accel_at(t) {
                Ok(f) => f,
                Err(false) => break,
                Err(true) => {
                    self.waiting.pop_front();
                    self.counts.unpaired_gyro += 1;
                    continue;
                }
            };
            self.waiting.pop_front();
            if let Some((t0, w0, f0)) = self.prev {
                let dt_ns = t - t0;
                if dt_ns > MAX_GAP_NS {
                    self.counts.gaps += 1;
                } else {
                    let dt = dt_ns as f64 * 1e-9;
                    out.push(Paired {
                        t_ns: t,
                        dt_ns,
                        dtheta: (w0 + w) * (0.5 * dt),
                        dvel: (f0 + f) * (0.5 * dt),
                    });
                }
            }
            self.prev = Some((t, w, f));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rates and forces linear in time are integrated exactly, whatever the two
    /// sensors' rates and phases.
    #[test]
    fn linear_signals_integrate_exactly() {
        let w = |t: f64| Vector3::new(0.1 + 0.02 * t, -0.3 * t, 0.05);
        let f = |t: f64| Vector3::new(1.0 - 0.5 * t, 0.2, -9.8 + 0.1 * t);
        // Closed forms of the integrals from a to b.
        let iw = |a: f64, b: f64| {
            Vector3::new(
                0.1 * (b - a) + 0.01 * (b * b - a * a),
                -0.15 * (b * b - a * a),
                0.05 * (b - a),
            )
        };
        let iff = |a: f64, b: f64| {
            Vector3::new(
                (b - a) - 0.25 * (b * b - a * a),
                0.2 * (b - a),
                -9.8 * (b - a) + 0.05 * (b * b - a * a),
            )
        };
        let mut p = Pairer::default();
        let mut out = Vec::new();
        // Gyro every 2.5 ms from 1 ms, accelerometer every 2.4 ms from 0.
        let (mut tg, mut ta) = (1_000_000i64, 0i64);
        while tg < 100_000_000 {
            if ta <= tg {
                p.accel(ta, f(ta as f64 * 1e-9), &mut out).unwrap();
                ta += 2_400_000;
            } else {
                p.gyro(tg, w(tg as f64 * 1e-9), &mut out).unwrap();
                tg += 2_500_000;
            }
        }
        assert!(out.len() > 30);
        for s in &out {
            let (a, b) = ((s.t_ns - s.dt_ns) as f64 * 1e-9, s.t_ns as f64 * 1e-9);
            // Rounding of sums of terms of order 1e-2: 1e-15.
            assert!((s.dtheta - iw(a, b)).amax() < 1e-15, "{s:?}");
            assert!((s.dvel - iff(a, b)).amax() < 1e-14, "{s:?}");
        }
        // Every interval follows the previous one.
        for pair in out.windows(2) {
            assert_eq!(pair[1].t_ns - pair[1].dt_ns, pair[0].t_ns);
        }
    }

    #[test]
    fn gaps_early_gyros_and_backward_times() {
        let mut p = Pairer::default();
        let mut out = Vec::new();
        let z = Vector3::zeros();
        p.gyro(0, z, &mut out).unwrap(); // before any accelerometer: dropped
        p.accel(1, z, &mut out).unwrap();
        assert_eq!(p.counts.unpaired_gyro, 1);
        p.gyro(10, z, &mut out).unwrap();
        p.accel(20, z, &mut out).unwrap();
        p.gyro(MAX_GAP_NS + 11, z, &mut out).unwrap();
        p.accel(MAX_GAP_NS + 20, z, &mut out).unwrap();
        assert!(out.is_empty());
        assert_eq!(p.counts.gaps, 1);
        p.gyro(MAX_GAP_NS + 15, z, &mut out).unwrap();
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].dt_ns, 4);
        let e = p.gyro(MAX_GAP_NS + 15, z, &mut out).unwrap_err();
        assert_eq!(e.previous_ns, MAX_GAP_NS + 15);
        assert!(p.accel(5, z, &mut out).is_err());
        p.gyro(MAX_GAP_NS + 100, z, &mut out).unwrap();
        p.finish();
        assert_eq!(p.counts.unpaired_gyro, 2);
    }
}
