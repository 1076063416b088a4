//! Errors of a navigated track against the simulator's truth, in the seed's terms: the
//! circular position error `ΔS = sqrt(δφ² + δλ²)` with `δφ = (φ − φ*) R_M` and
//! `δλ = (λ − λ*) R_N cos φ*` (seed 003), the height error and the attitude errors.

use super::capture::Recording;
use super::modes::Track;
use schuler::earth::{EarthModel, Wgs84};
use schuler::rotation::wrap_pi;

/// Errors at one epoch (navigated minus true).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEpoch {
    /// Time [s].
    pub t: f64,
    /// North position error [m].
    pub north: f64,
    /// East position error [m].
    pub east: f64,
    /// Circular error ΔS [m].
    pub circular: f64,
    /// Height error [m].
    pub height: f64,
    /// Roll, pitch, yaw errors [rad].
    pub attitude: [f64; 3],
}

/// The errors of every epoch of `track`.
pub fn errors(track: &Track, rec: &Recording) -> Vec<ErrorEpoch> {
    track
        .epochs
        .iter()
        .map(|e| {
            let s = &e.state;
            let truth = &rec.truth_at(s.t).state;
            let r = Wgs84.radii(truth.pos.lat);
            let north = (s.pos.lat - truth.pos.lat) * (r.meridian + truth.pos.h);
            let east = wrap_pi(s.pos.lon - truth.pos.lon)
                * (r.prime_vertical + truth.pos.h)
                * truth.pos.lat.cos();
            let (a, b) = (s.euler(), truth.euler());
            ErrorEpoch {
                t: s.t,
                north,
                east,
                circular: north.hypot(east),
                height: s.pos.h - truth.pos.h,
                attitude: [
                    wrap_pi(a.roll - b.roll),
                    wrap_pi(a.pitch - b.pitch),
                    wrap_pi(a.yaw - b.yaw),
                ],
            }
        })
        .collect()
}

/// The epoch at time `t` (nearest whole second), if the track reaches it.
pub fn at(errors: &[ErrorEpoch], t: f64) -> Option<&ErrorEpoch> {
    let t0 = errors.first()?.t;
    errors.get((t - t0).round().max(0.0) as usize)
}

/// Largest circular error over epochs in `[from, to]` [m].
pub fn max_circular(errors: &[ErrorEpoch], from: f64, to: f64) -> f64 {
    errors
        .iter()
        .filter(|e| e.t >= from && e.t <= to)
        .map(|e| e.circular)
        .fold(0.0, f64::max)
}
