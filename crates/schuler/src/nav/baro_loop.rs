//! The baro-damped vertical channel of a full strapdown mechanization: the seed's
//! constant-gain loop (33)–(34) around the computed height, with its fault detector and
//! prediction mode (38).
//!
//! Between readings the mechanization integrates freely; at each reference reading
//! `h*` the loop feeds back the mismatch `e = h̃ − h*` held over the interval `Δt`
//! since the previous reading:
//!
//! `h̃ ← h̃ + k1 e Δt`, `Ṽ_up ← Ṽ_up + k2 e Δt`,
//!
//! the rectangle rule for `r̃' = Ṽ + k1 (r̃ − r*)`, `Ṽ' = f − g(r̃) + k2 (r̃ − r*)` (34)
//! (exact to first order in `|k| Δt`, which [`crate::channel::vertical::Gains::check`]
//! keeps small). Gravity stays the mechanization's own, computed from `h̃`, so that with
//! the reference rejected or missing the channel simply predicts (38). The error
//! dynamics are (37): critically damped gains give one time constant, and a constant
//! reference bias `b` and vertical accelerometer bias `Δf` settle at
//! [`crate::channel::vertical::Gains::steady_state`].

use super::{ErrorFrame, NavErrors};
use crate::channel::detector::{DetectorConfig, FaultDetector, Verdict};
use crate::channel::vertical::{DetectorCounts, Gains};
use nalgebra::Vector3;

/// The loop's state: gains, fault detector and what it did.
#[derive(Debug, Clone, PartialEq)]
pub struct BaroLoop {
    gains: Gains,
    gate: f64,
    detector: FaultDetector,
    last_t: Option<f64>,
    /// What the detector decided, reading by reading.
    pub counts: DetectorCounts,
}

impl BaroLoop {
    /// A loop with feedback `gains` (34) and a fault detector (`cfg.gate` in metres).
    pub fn new(gains: Gains, cfg: DetectorConfig) -> Self {
        Self {
            gains,
            gate: cfg.gate,
            detector: FaultDetector::new(cfg),
            last_t: None,
            counts: DetectorCounts::default(),
        }
    }

    /// The gains.
    pub fn gains(&self) -> Gains {
        self.gains
    }

    /// Judge the reference height `h_ref` [m] (`None`: no reading) read at the
    /// mechanization's current time and, if it is valid, feed the mismatch back over the
    /// time since the previous reading. The first reading only starts the clock.
    pub fn update<M: ErrorFrame>(&mut self, mech: &mut M, h_ref: Option<f64>) -> Verdict {
        let t = mech.state().t;
        let h = mech.state().pos.h;
        let verdict = self.detector.assess(h_ref.map(|r| h - r), self.gate);
        self.counts.count(verdict);
        let dt = self.last_t.map_or(0.0, |t0| t - t0);
        self.last_t = Some(t);
        if let (true, Some(r)) = (verdict.is_aided(), h_ref)
            && dt > 0.0
        {
            let e = h - r;
            // Errors are computed minus true along c's third axis, which points down in
            // every mechanization: a height change +x is a down-position error of +x
            // removed, and an up-velocity change +y a down-velocity error of +y.
            mech.correct(&NavErrors {
                dr: Vector3::new(0.0, 0.0, self.gains.k1 * e * dt),
                dv: Vector3::new(0.0, 0.0, self.gains.k2 * e * dt),
                psi: Vector3::zeros(),
            });
        }
        verdict
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{EarthModel, Geodetic, Sphere};
    use crate::imu::ImuSample;
    use crate::nav::{LocalLevel, Mechanization, NavState};
    use nalgebra::UnitQuaternion;

    /// At rest on the non-rotating textbook sphere with a biased vertical accelerometer
    /// and a biased reference: the computed height settles where (37) puts it.
    #[test]
    fn settles_at_the_closed_form_steady_state() {
        let earth = Sphere::textbook(false);
        let h0 = 500.0;
        let pos = Geodetic {
            lat: 0.3,
            lon: 0.1,
            h: h0,
        };
        let g = earth.local(pos.lat, pos.h).g_n.z;
        let r = earth.radius + h0;
        let w0_sq = g / r;
        let gains = Gains::critical(30.0, w0_sq).expect("gains");
        let (ref_bias, accel_bias) = (4.0, 2e-3);
        let mut mech = LocalLevel::new(
            earth,
            NavState {
                t: 0.0,
                pos,
                v_n: Vector3::zeros(),
                q_bn: UnitQuaternion::identity(),
            },
        );
        let mut lp = BaroLoop::new(gains, DetectorConfig::default());
        let dt = 0.01;
        // Up specific force g plus the bias: the down accelerometer reads -(g + Δf).
        let dvel = Vector3::new(0.0, 0.0, -(g + accel_bias) * dt);
        for k in 1..=60_000 {
            mech.step(&ImuSample {
                t: k as f64 * dt,
                dt,
                dtheta: Vector3::zeros(),
                dvel,
            });
            if k % 10 == 0 {
                lp.update(&mut mech, Some(h0 + ref_bias));
            }
        }
        let (dh, dv) = gains.steady_state(w0_sq, ref_bias, accel_bias);
        let s = mech.state();
        // After 600 s = 20 time constants the transient is e^-20 of the start; the
        // discrete feedback at 10 Hz differs from (34) by O(|k1| Δt) = 0.7 % of the
        // offset; the free channel's gravity gradient is linearized in (37): 1e-3 m.
        assert!(
            (s.pos.h - h0 - dh).abs() < 0.01 * dh.abs() + 1e-3,
            "{} vs {dh}",
            s.pos.h - h0
        );
        assert!(
            (-s.v_n.z - dv).abs() < 0.01 * dv.abs(),
            "{} vs {dv}",
            -s.v_n.z
        );
        assert_eq!(lp.counts.accepted, 6000);
    }

    /// With the reference gone the loop predicts: the free channel's error grows.
    #[test]
    fn missing_reference_predicts() {
        let earth = Sphere::textbook(false);
        let pos = Geodetic {
            lat: 0.0,
            lon: 0.0,
            h: 0.0,
        };
        let mut mech = LocalLevel::new(
            earth,
            NavState {
                t: 0.0,
                pos,
                v_n: Vector3::new(0.0, 0.0, -0.1),
                q_bn: UnitQuaternion::identity(),
            },
        );
        let gains = Gains::critical(30.0, 1.5e-6).expect("gains");
        let mut lp = BaroLoop::new(gains, DetectorConfig::default());
        let before = mech.state();
        assert_eq!(lp.update(&mut mech, None), Verdict::Missing);
        assert_eq!(mech.state(), before);
        assert_eq!(lp.counts.missing, 1);
    }
}
