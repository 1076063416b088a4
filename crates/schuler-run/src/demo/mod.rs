//! The second seed document's flight test re-enacted end to end (`schuler demo`).
//!
//! A helicopter sortie above the Arctic circle is simulated in memory (FOG-class IMU at
//! 1 kHz with rotor vibration, GNSS at 1 Hz, barometer; 15 min on the pad and 45 min of
//! flight with a GNSS outage, `examples/polar_flight.toml`), then processed as the
//! seed's system does: coarse alignment 0–190 s, fine alignment 190–860 s, then
//! navigation in the inertial mode (free, with and without the baro loop on the
//! vertical channel; also after coarse alignment alone, the seed's comparison) and in
//! the inertial-satellite mode (Kalman filter on GNSS position and velocity and the
//! barometer, forward and smoothed). Then a short second flight crosses the North
//! Pole (`crossing.rs`, `polar.rs`), navigated with the all-latitude wander-azimuth
//! mechanization in both modes and with NED in the inertial mode for contrast.
//! Everything goes into one self-contained HTML report with the CSV and SVG files
//! behind its plots.

mod capture;
mod crossing;
mod errors;
mod figure3;
mod modes;
mod page;
mod page_figure3;
mod page_polar;
mod polar;
mod sortie;

use crate::progress::Progress;
use anyhow::{Context, Result};
use nalgebra::Vector3;
use schuler::align::{AlignConfig, Alignment, align};
use schuler::channel::vertical::Gains;
use schuler::earth::Wgs84;
use schuler::filter::ImuNoise;
use schuler::session::MechanizationChoice;
use std::path::Path;
use std::time::Instant;

pub use crossing::Crossing;
pub use sortie::{POLAR_FLIGHT, Sortie};

/// The sortie's mechanization: NED (70 N is far from the poles).
/// The sortie navigates in NED (70° N).
const NED: MechanizationChoice = MechanizationChoice::Ned;

/// One navigation mode's run and its errors.
pub struct ModeRun {
    /// File-name key.
    pub key: &'static str,
    /// What it is.
    pub label: &'static str,
    /// The track.
    pub track: modes::Track,
    /// Its errors against the truth.
    pub errors: Vec<schuler::analysis::errors::EpochErrors>,
}

impl ModeRun {
    /// The run `track` under `key` and `label`, with the errors `errors` finds in it.
    pub fn new(
        key: &'static str,
        label: &'static str,
        track: modes::Track,
        errors: impl Fn(&modes::Track) -> Vec<schuler::analysis::errors::EpochErrors>,
    ) -> Self {
        Self {
            key,
            label,
            errors: errors(&track),
            track,
        }
    }
}

/// Both alignments: coarse and fine from the start, and coarse alone over the last
/// coarse-stage length before navigation (so both end at the same instant).
pub struct Alignments {
    /// Coarse 0–190 s, fine 190–860 s.
    pub fine: Alignment,
    /// Coarse only, 670–860 s.
    pub coarse_only: Alignment,
}

fn align_both(rec: &capture::Recording, s: &Sortie) -> Result<Alignments> {
    let noise = ImuNoise::from_model(&rec.model);
    let pos = rec.truth[0].state.pos;
    let cfg = AlignConfig {
        coarse: s.coarse,
        fine: s.fine,
        ..AlignConfig::default()
    };
    let fine = align(Wgs84, pos, &rec.imu[1..], &noise, &cfg).context("fine alignment")?;
    let from = rec.sample_at(s.nav_start() - s.coarse) + 1;
    let coarse_only = align(
        Wgs84,
        pos,
        &rec.imu[from..],
        &noise,
        &AlignConfig { fine: 0.0, ..cfg },
    )
    .context("coarse-only alignment")?;
    Ok(Alignments { fine, coarse_only })
}

/// The sortie simulated in memory; returns the recording, the trajectory's span [s]
/// and the wall-clock time it took [s].
fn simulate(sortie: &Sortie, progress: &dyn Progress) -> Result<(capture::Recording, f64, f64)> {
    let clock = Instant::now();
    let (traj, _) = sortie.spec.trajectory(Wgs84).context("the sortie")?;
    let span = traj.end() - traj.start();
    let rec = capture::record(&sortie.spec, progress.task("simulate", span as u64))?;
    Ok((rec, span, clock.elapsed().as_secs_f64()))
}

/// Both alignments on the pad ([`align_both`]) behind a progress bar; returns them and
/// the wall-clock time they took [s].
fn align_timed(
    rec: &capture::Recording,
    sortie: &Sortie,
    progress: &dyn Progress,
) -> Result<(Alignments, f64)> {
    let clock = Instant::now();
    let align_bar = progress.task("align (coarse, fine)", 2);
    let alignments = align_both(rec, sortie)?;
    align_bar.inc(2);
    align_bar.finish();
    Ok((alignments, clock.elapsed().as_secs_f64()))
}

/// The inertial-satellite mode's settings: the scenario's GNSS lever arm, the
/// barometer's noise and its bias prior.
fn aided_settings(sortie: &Sortie) -> Result<modes::AidedSettings> {
    let gnss = sortie.spec.gnss.as_ref().context("the sortie has GNSS")?;
    let lever = gnss
        .lever_arm
        .as_ref()
        .map(|l| {
            let si = |i: usize| l[i].si("gnss.lever_arm", schuler::units::Dimension::Length);
            Ok::<_, anyhow::Error>(Vector3::new(si(0)?, si(1)?, si(2)?))
        })
        .transpose()?
        .unwrap_or_default();
    Ok(modes::AidedSettings {
        lever_arm: lever,
        baro_std: 0.5,
        baro_bias: (10.0, 0.05),
    })
}

/// The sortie's five runs, navigated in parallel over the `flight` seconds after the
/// alignment: the filter (forward and smoothed) and the inertial mode with the baro
/// loop, after coarse alignment alone, and without the baro loop.
fn navigate_sortie(
    rec: &capture::Recording,
    alignments: &Alignments,
    gains: Gains,
    aided_settings: &modes::AidedSettings,
    progress: &dyn Progress,
    flight: u64,
) -> Result<Vec<ModeRun>> {
    let fine_start = modes::Start::from_alignment(&alignments.fine);
    let coarse_start = modes::Start::from_alignment(&alignments.coarse_only);
    let bars = [
        progress.task("inertial-satellite (KF)", flight),
        progress.task("inertial, baro loop", flight),
        progress.task("inertial, coarse only", flight),
        progress.task("inertial, no baro", flight),
    ];
    let ((forward, smoothed), inertial, coarse_only, no_baro) = std::thread::scope(|scope| {
        let aided = scope.spawn(|| {
            modes::aided(
                rec,
                &fine_start,
                &modes::Prior::from_alignment(
                    &alignments.fine,
                    Vector3::repeat(modes::PAD_SURVEY_STD),
                ),
                aided_settings,
                MechanizationChoice::Ned,
                &bars[0],
            )
        });
        let inertial = modes::inertial(rec, &fine_start, Some(gains), NED, &bars[1]);
        let coarse_only = modes::inertial(rec, &coarse_start, Some(gains), NED, &bars[2]);
        let no_baro = modes::inertial(rec, &fine_start, None, NED, &bars[3]);
        let aided = aided
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (aided, inertial, coarse_only, no_baro)
    });
    let (forward, smoothed) = (forward, smoothed?);
    for b in &bars {
        b.finish();
    }
    Ok([
        (
            "inertial_coarse",
            "inertial after coarse alignment only",
            coarse_only,
        ),
        ("inertial", "inertial with baro loop", inertial),
        (
            "inertial_no_baro",
            "inertial with free vertical channel",
            no_baro,
        ),
        ("aided", "inertial-satellite forward", forward),
        ("smoothed", "inertial-satellite smoothed", smoothed),
    ]
    .into_iter()
    .map(|(key, label, track)| ModeRun::new(key, label, track, |t| errors::errors(t, rec)))
    .collect())
}

/// The demo into `out` (the full sortie, or with `quick` the short one), its progress
/// told to `progress`; returns the summary for the terminal.
pub fn run(out: &Path, quick: bool, progress: &dyn Progress) -> Result<String> {
    let started = Instant::now();
    let sortie = if quick {
        Sortie::quick()?
    } else {
        Sortie::full()?
    };
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let (rec, span, simulate_s) = simulate(&sortie, progress)?;
    let (alignments, align_s) = align_timed(&rec, &sortie, progress)?;
    let gains = modes::baro_gains(&modes::Start::from_alignment(&alignments.fine).state)?;
    let settings = aided_settings(&sortie)?;
    let flight = (span - sortie.nav_start()) as u64;
    let runs = navigate_sortie(&rec, &alignments, gains, &settings, progress, flight)?;
    let fig3_bar = progress.task("inertial, figure 3's leg", flight);
    let fig3 = figure3::figure3(&rec, &sortie, &alignments, &runs, gains, &fig3_bar)?;
    fig3_bar.finish();

    let crossing = if quick {
        crossing::Crossing::quick(&sortie)?
    } else {
        crossing::Crossing::full(&sortie)?
    };
    let polar = polar::run(crossing, &settings, progress)?;
    let timing = page::Timing {
        simulate: simulate_s,
        align: align_s,
    };
    let summary = page::write(
        out,
        &sortie,
        &rec,
        &alignments,
        &runs,
        &polar,
        &fig3,
        gains,
        timing,
        started,
    )?;
    Ok(summary)
}
