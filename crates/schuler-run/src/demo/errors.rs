//! Errors of a navigated track against the simulator's truth, in the seed's terms
//! ([`schuler::analysis::errors`], through ECEF and valid at and across the poles): the
//! circular position error `ΔS` (the horizontal error), the height error and the
//! attitude errors.

use super::capture::Recording;
use super::modes::Track;
use schuler::analysis::errors::{EpochErrors, errors_between};
use schuler::earth::Wgs84;

/// The errors of every epoch of `track` (navigated minus true,
/// [`errors_between`] on WGS84).
pub fn errors(track: &Track, rec: &Recording) -> Vec<EpochErrors> {
    track
        .epochs
        .iter()
        .map(|e| errors_between(&Wgs84, &e.state, &rec.truth_at(e.state.t).state))
        .collect()
}

/// Height error (up) [m].
pub fn height(e: &EpochErrors) -> f64 {
    -e.pos_n.z
}

/// The epoch at time `t` (nearest whole second), if the track reaches it.
pub fn at(errors: &[EpochErrors], t: f64) -> Option<&EpochErrors> {
    let t0 = errors.first()?.t_sow;
    errors.get((t - t0).round().max(0.0) as usize)
}

/// Largest circular error over epochs in `[from, to]` [m].
pub fn max_circular(errors: &[EpochErrors], from: f64, to: f64) -> f64 {
    errors
        .iter()
        .filter(|e| e.t_sow >= from && e.t_sow <= to)
        .map(EpochErrors::horizontal)
        .fold(0.0, f64::max)
}
