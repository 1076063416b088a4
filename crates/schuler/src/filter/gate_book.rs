//! The gate's choice and the record of its decisions, shared by the psi-angle filter
//! ([`super::Integrator`]) and the 18-state filter ([`super::seed18::Seed18`]): every
//! measurement tested, the refusals, the skipped, the counts, and the reset rule (after
//! `reset_after` GNSS positions refused in a row the next one passes unless it is
//! beyond [`RESET_MAX_SIGMA`] standard deviations per degree of freedom).

use super::integration::{
    Counts, Innovation, IntegrationConfig, RESET_MAX_SIGMA, Rejected, SkipReason, Skipped,
};
use super::kalman::{Gate, Rejection, Update};
use super::measurement::Kind;
use nalgebra::DVector;

/// What a filter recorded of its measurements, and the refusals in a row behind the
/// gate's reset.
#[derive(Debug, Clone, Default)]
pub struct GateBook {
    /// Every measurement tested, in time order (take it with `std::mem::take` now
    /// and then to bound memory on long runs).
    pub innovations: Vec<Innovation>,
    /// Gate decisions, in time order.
    pub rejected: Vec<Rejected>,
    /// Measurements not used at all (outside the IMU span), in time order.
    pub skipped: Vec<Skipped>,
    /// Counters.
    pub counts: Counts,
    /// Times at which the gate was bypassed after `reset_after` refusals in a row,
    /// with the normalized innovation squared of the fix then accepted.
    pub gate_resets: Vec<(f64, f64)>,
    consecutive_rejections: u32,
}

impl GateBook {
    /// The gate for a measurement of `kind` with `dof` components under `cfg`, and
    /// whether it is the reset: the configured gate, or for a GNSS position after
    /// `cfg.reset_after` refused in a row the bound `RESET_MAX_SIGMA² · dof` (a reset
    /// still refuses the impossible).
    pub fn gate(&self, cfg: &IntegrationConfig, kind: Kind, dof: usize) -> (Gate, bool) {
        let reset = kind == Kind::GnssPosition
            && cfg.reset_after > 0
            && self.consecutive_rejections >= cfg.reset_after;
        if reset {
            (
                Gate::Bound(RESET_MAX_SIGMA * RESET_MAX_SIGMA * dof as f64),
                true,
            )
        } else {
            (cfg.gate, false)
        }
    }

    /// Records the outcome of the update of innovation `z` at `t` (of satellite `sat`,
    /// for a range) through the gate [`GateBook::gate`] chose (`reset`); returns the
    /// update to feed back if it was accepted.
    pub fn record(
        &mut self,
        t: f64,
        kind: Kind,
        sat: Option<crate::gnss::Sat>,
        z: DVector<f64>,
        reset: bool,
        outcome: Result<Update, Rejection>,
    ) -> Option<Update> {
        let position = kind == Kind::GnssPosition;
        let (nis, s_diag) = match &outcome {
            Ok(u) => (u.nis, &u.s_diag),
            Err(r) => (r.nis, &r.s_diag),
        };
        self.innovations.push(Innovation {
            t,
            kind,
            sat,
            z,
            s_diag: s_diag.clone(),
            nis,
            accepted: outcome.is_ok(),
        });
        match outcome {
            Ok(u) => {
                if reset {
                    self.gate_resets.push((t, u.nis));
                }
                if position {
                    self.consecutive_rejections = 0;
                }
                self.counts.accept(kind);
                Some(u)
            }
            Err(rejection) => {
                if position {
                    self.consecutive_rejections += 1;
                }
                self.counts.rejected += 1;
                self.rejected.push(Rejected {
                    t,
                    kind,
                    sat,
                    rejection,
                });
                None
            }
        }
    }

    /// Records a measurement of `kind` that could not be used.
    pub fn skip(&mut self, t: f64, kind: Kind, reason: SkipReason) {
        self.counts.skipped += 1;
        self.skipped.push(Skipped { t, kind, reason });
    }
}
