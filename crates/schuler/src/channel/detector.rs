//! Fault detection on the reference height (text after (37), and (38)): a sample whose
//! innovation (prediction minus reference) exceeds a gate is rejected and the loop runs
//! in prediction (38); with no sample (dropout) it predicts as well.
//!
//! Two refinements make this work through long outages. Prediction drifts (the free
//! channel grows with e-fold time `1/(√2 ω0)`), so a reference that comes back far from
//! the prediction would be rejected for ever: when `reacquire` consecutive rejected
//! samples agree with one another (their innovations spread by no more than the gate),
//! the reference is taken as valid again and the loop reconnects. And while the loop
//! converges after that, its innovation is still large but moves smoothly: a sample is
//! also accepted when its innovation differs from the last accepted one by no more than
//! the gate. An outlier jumps away from both and never forms a consistent run, so it is
//! rejected either way.

/// Settings of the fault detector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectorConfig {
    /// When false every sample is accepted (to show what an outlier does).
    pub enabled: bool,
    /// Innovation gate \[m\] for the constant-gain loop (the Kalman variant gates on its own
    /// innovation sigma, see [`super::kalman`]).
    pub gate: f64,
    /// Consecutive mutually consistent rejected samples that reconnect the loop.
    pub reacquire: usize,
}

impl Default for DetectorConfig {
    /// Enabled, 50 m gate, 5 samples to reacquire.
    fn default() -> Self {
        Self {
            enabled: true,
            gate: 50.0,
            reacquire: 5,
        }
    }
}

/// What to do with one reference sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Inside the gate: use it (34).
    Accept,
    /// Outside the gate but consistent with the previous rejected ones: reconnect (34).
    Reacquire,
    /// Outside the gate: predict (38).
    Reject,
    /// No sample (dropout): predict (38).
    Missing,
}

impl Verdict {
    /// True when the feedback of (34) is on for this sample.
    pub fn is_aided(self) -> bool {
        matches!(self, Verdict::Accept | Verdict::Reacquire)
    }
}

/// The detector's state: the last accepted innovation and the current run of rejected ones.
#[derive(Debug, Clone, PartialEq)]
pub struct FaultDetector {
    cfg: DetectorConfig,
    last_accepted: Option<f64>,
    streak: Vec<f64>,
}

impl FaultDetector {
    /// A detector with no history.
    pub fn new(cfg: DetectorConfig) -> Self {
        Self {
            cfg,
            last_accepted: None,
            streak: Vec::with_capacity(cfg.reacquire.max(1)),
        }
    }

    /// Judges one sample's innovation \[m\] (`None`: no sample) against `gate` \[m\].
    pub fn assess(&mut self, innovation: Option<f64>, gate: f64) -> Verdict {
        let Some(nu) = innovation else {
            // Prediction drifts while data are missing: the last innovation is stale.
            self.streak.clear();
            self.last_accepted = None;
            return Verdict::Missing;
        };
        let continuous = self
            .last_accepted
            .is_some_and(|last| (nu - last).abs() <= gate);
        if !self.cfg.enabled || nu.abs() <= gate || continuous {
            self.streak.clear();
            self.last_accepted = Some(nu);
            return Verdict::Accept;
        }
        self.streak.push(nu);
        let need = self.cfg.reacquire.max(1);
        if self.streak.len() > need {
            self.streak.remove(0);
        }
        if self.streak.len() == need {
            let lo = self.streak.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = self
                .streak
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            if hi - lo <= gate {
                self.streak.clear();
                self.last_accepted = Some(nu);
                return Verdict::Reacquire;
            }
        }
        Verdict::Reject
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isolated_outlier_rejected_persistent_offset_reacquired() {
        let mut d = FaultDetector::new(DetectorConfig::default());
        assert_eq!(d.assess(Some(1.0), 50.0), Verdict::Accept);
        assert_eq!(d.assess(Some(200.0), 50.0), Verdict::Reject);
        assert_eq!(d.assess(Some(-0.5), 50.0), Verdict::Accept);
        assert_eq!(d.assess(None, 50.0), Verdict::Missing);
        let verdicts: Vec<Verdict> = (0..5)
            .map(|k| d.assess(Some(120.0 + k as f64), 50.0))
            .collect();
        assert_eq!(verdicts[..4], [Verdict::Reject; 4]);
        assert_eq!(verdicts[4], Verdict::Reacquire);
        // Converging smoothly from 124 m: accepted; an outlier jump on top: rejected.
        assert_eq!(d.assess(Some(110.0), 50.0), Verdict::Accept);
        assert_eq!(d.assess(Some(310.0), 50.0), Verdict::Reject);
        assert_eq!(d.assess(Some(100.0), 50.0), Verdict::Accept);
    }
}
