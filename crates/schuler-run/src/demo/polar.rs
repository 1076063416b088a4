//! The demo's polar part: the pole crossing ([`super::crossing`]) simulated, then
//! navigated from its in-flight hand-over with the all-latitude wander mechanization
//! in the inertial mode (baro loop) and the inertial-satellite mode (the filter's
//! errors in the wander frame, forward and smoothed), and for contrast with the NED
//! mechanization in the inertial mode on the same samples; errors through ECEF
//! ([`super::errors::errors`]).

use super::capture::{self, Recording};
use super::crossing::Crossing;
use super::modes::{self, AidedSettings, Prior, Start};
use super::{ModeRun, errors};
use crate::progress::Progress;
use anyhow::Result;
use schuler::session::MechanizationChoice;
use std::time::Instant;

/// Across the pole the all-latitude mechanization runs.
const WANDER: MechanizationChoice = MechanizationChoice::Wander;

/// The crossing, its recording and its runs.
pub struct Polar {
    /// The flight.
    pub crossing: Crossing,
    /// Its simulated data.
    pub rec: Recording,
    /// Wander inertial, wander inertial-satellite forward and smoothed, NED inertial.
    pub runs: Vec<ModeRun>,
    /// Wall-clock time of the simulation [s].
    pub simulate_s: f64,
}

/// Simulate and navigate `crossing`, its progress told to `progress`.
pub fn run(crossing: Crossing, settings: &AidedSettings, progress: &dyn Progress) -> Result<Polar> {
    let clock = Instant::now();
    let span = crossing.duration as u64;
    let rec = capture::record_trajectory(
        &crossing.traj,
        crossing.t0,
        crossing.duration,
        &crossing.spec,
        progress.task("simulate the pole crossing", span),
    )?;
    let simulate_s = clock.elapsed().as_secs_f64();

    let start = Start {
        state: crossing.start(),
        estimates: Default::default(),
    };
    let [pos_std, vel_std, att_std] = crossing.prior_std;
    let prior = Prior {
        pos_std,
        vel_std,
        att_std,
        bias_std: None,
        att_bias_cov: None,
    };
    let gains = modes::baro_gains(&start.state)?;
    let bars = [
        progress.task("pole: wander, satellite", span),
        progress.task("pole: wander, inertial", span),
        progress.task("pole: NED, inertial", span),
    ];
    let ((forward, smoothed), inertial, ned) = std::thread::scope(|scope| {
        let aided = scope.spawn(|| modes::aided(&rec, &start, &prior, settings, WANDER, &bars[0]));
        let inertial = modes::inertial(&rec, &start, Some(gains), WANDER, &bars[1]);
        let ned = modes::inertial(
            &rec,
            &start,
            Some(gains),
            MechanizationChoice::Ned,
            &bars[2],
        );
        let aided = aided
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (aided, inertial, ned)
    });
    let smoothed = smoothed?;
    for b in &bars {
        b.finish();
    }
    let runs = [
        ("polar_inertial", "wander inertial with baro loop", inertial),
        ("polar_aided", "wander inertial-satellite forward", forward),
        (
            "polar_smoothed",
            "wander inertial-satellite smoothed",
            smoothed,
        ),
        ("polar_ned", "NED inertial with baro loop", ned),
    ]
    .into_iter()
    .map(|(key, label, track)| ModeRun::new(key, label, track, |t| errors::errors(t, &rec)))
    .collect();
    Ok(Polar {
        crossing,
        rec,
        runs,
        simulate_s,
    })
}
