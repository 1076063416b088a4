//! The seed's figure 3 protocol beside figure 2's: the inertial mode after fine
//! alignment, refinement and compensation of the drift estimates, against the
//! inertial mode after coarse alignment alone, over legs of equal length.
//!
//! The drifts are estimated where the seed's system estimates them: in the fine
//! alignment on the pad, and in flight by the inertial-satellite mode, which hands its
//! corrected state and its gyro-drift and accelerometer-bias estimates to the inertial
//! leg once its turns have separated the level accelerometer biases from the tilt
//! ([`handover`]). The in-flight invariant (7) needs an
//! independent source of angle rates (`schuler::refine`), which the simulated
//! helicopter does not carry, so the refinement in flight is the inertial-satellite
//! mode's.
//!
//! Each leg's error is explained from its errors at the start with the textbook's
//! closed forms of the Schuler-tuned horizontal channel (`ω_s² = g/R`): a force error
//! `a(τ)` moves the position by `∫ a(τ) sin(ω_s(t − τ))/ω_s dτ`, a tilt-rate error
//! `ε(τ)` by `R ∫ ε(τ) (1 − cos(ω_s(t − τ))) dτ`. Hence, as bounds whatever the error's
//! direction does in turns: a heading error `δψ` turns the displacement (`δψ |Δr|`) and
//! acts with the Earth's horizontal rate as a drift (`R Ω cosφ δψ f(t)`,
//! `f(t) = t − sin(ω_s t)/ω_s`); a horizontal drift `ε` gives `R ε f(t)`; the net level
//! error at the start `e = g [ψ_E, −ψ_N] + b_n` gives `e (1 − cos ω_s t)/ω_s²`; turns
//! change an accelerometer bias `b` by up to `2b`, `2b ∫₀ᵗ |sin ω_s s|/ω_s ds`; a
//! velocity error `δv` gives `δv ∫₀ᵗ |cos ω_s s| ds`. Their sum bounds the leg's
//! circular error.

use super::capture::Recording;
use super::modes::{self, Start, Track};
use super::{Alignments, ModeRun, Sortie, errors};
use crate::progress::Task;
use anyhow::{Context, Result};
use schuler::channel::vertical::Gains;
use schuler::earth::Wgs84;
use schuler::filter::integration::SensorEstimates;
use schuler::session::MechanizationChoice;

/// The inertial-satellite mode hands over once the standard deviations of both
/// horizontal accelerometer biases have fallen below this fraction of their value
/// at the navigation start: the leveling on the pad could not separate them from
/// the tilt, the turns in flight do, and an unseparated bias is the largest term of
/// an inertial leg after a good heading (module docs).
pub const HANDOVER_BIAS_RATIO: f64 = 0.2;

/// Where the handover falls when the filter never gets there (fraction of the flight
/// after the alignment).
pub const HANDOVER_FALLBACK: f64 = 0.5;

/// Mean Earth radius for the closed forms [m].
const R: f64 = 6.371e6;

/// The handover time [s]: the first of the filter's snapshots in `aided` where both
/// horizontal accelerometer-bias standard deviations are below
/// [`HANDOVER_BIAS_RATIO`] of the first snapshot's, else [`HANDOVER_FALLBACK`] into
/// the flight; on a whole second.
pub fn handover(aided: &Track, s: &Sortie, end: f64) -> f64 {
    let horizontal = |v: &nalgebra::Vector3<f64>| v.x.max(v.y);
    let first = aided
        .sensors
        .first()
        .map_or(0.0, |e| horizontal(&e.accel_std));
    aided
        .sensors
        .iter()
        .find(|e| horizontal(&e.accel_std) < HANDOVER_BIAS_RATIO * first)
        .map_or(
            s.nav_start() + HANDOVER_FALLBACK * (end - s.nav_start()),
            |e| e.t,
        )
        .round()
}

/// Figure 3's leg and the budgets of the three legs of equal length: coarse only
/// (figure 2), fine alignment, and figure 3's.
pub struct Figure3 {
    /// Figure 3's inertial leg.
    pub run: ModeRun,
    /// Budgets: coarse only, fine alignment, figure 3.
    pub budgets: [LegBudget; 3],
    /// The legs' length [s].
    pub length: f64,
    /// Gravity at the pad [m/s^2] (for the level error in ug).
    pub g: f64,
}

/// Figure 3's leg from the sortie's inertial-satellite run, and the budgets of it and
/// of the runs `inertial_coarse` and `inertial` over the same length from the
/// navigation start.
pub fn figure3(
    rec: &Recording,
    s: &Sortie,
    a: &Alignments,
    runs: &[ModeRun],
    gains: Gains,
    bar: &dyn Task,
) -> Result<Figure3> {
    let end = rec.truth.last().map_or(0.0, |e| e.state.t);
    let find = |key: &str| super::page::find(runs, key);
    let aided = &find("aided")?.track;
    let t0 = handover(aided, s, end);
    let length = end - t0;
    let (run, removed) = leg(rec, aided, t0, gains, bar)?;
    let nav = s.nav_start();
    let budgets = [
        budget(
            find("inertial_coarse")?,
            rec,
            nav,
            length,
            &Start::from_alignment(&a.coarse_only).estimates,
        )?,
        budget(
            find("inertial")?,
            rec,
            nav,
            length,
            &Start::from_alignment(&a.fine).estimates,
        )?,
        budget(&run, rec, t0, length, &removed)?,
    ];
    let p = rec.truth[0].state.pos;
    let g = schuler::earth::EarthModel::local(&Wgs84, p.lat, p.h).g_n.z;
    Ok(Figure3 {
        run,
        budgets,
        length,
        g,
    })
}

/// The inertial leg from the inertial-satellite `aided` track's state and sensor
/// estimates at `t0` to the end of the recording, with the baro loop `gains`; with
/// the estimates it removes.
fn leg(
    rec: &Recording,
    aided: &Track,
    t0: f64,
    gains: Gains,
    bar: &dyn Task,
) -> Result<(ModeRun, SensorEstimates)> {
    let epoch = aided
        .epochs
        .iter()
        .find(|e| (e.state.t - t0).abs() < 0.5)
        .context("the inertial-satellite track reaches the handover")?;
    let snapshot = aided
        .sensors
        .iter()
        .rev()
        .find(|s| s.t <= t0 + 1e-6)
        .context("the filter estimated the sensors before the handover")?;
    let start = Start {
        state: epoch.state,
        estimates: SensorEstimates {
            gyro_bias: snapshot.est.gyro_bias,
            accel_bias: snapshot.est.accel_bias,
            ..SensorEstimates::default()
        },
    };
    let track = modes::inertial(rec, &start, Some(gains), MechanizationChoice::Ned, bar);
    let run = ModeRun::new(
        "inertial_fig3",
        "inertial after fine alignment and refinement in flight with drifts compensated",
        track,
        |t| errors::errors(t, rec),
    );
    Ok((run, start.estimates))
}

/// One leg's errors at its start, the closed forms' terms at its length, and its
/// largest circular error.
#[derive(Debug, Clone, PartialEq)]
pub struct LegBudget {
    /// The run's label.
    pub label: &'static str,
    /// Start of the leg [s].
    pub t0: f64,
    /// Heading error at the start [rad].
    pub heading: f64,
    /// Horizontal gyro drift left uncompensated [rad/s].
    pub drift: f64,
    /// Horizontal accelerometer bias left uncompensated [m/s^2].
    pub bias: f64,
    /// Net level error at the start `|g [ψ_E, −ψ_N] + b_n|` [m/s^2].
    pub level: f64,
    /// Horizontal velocity error at the start [m/s].
    pub velocity: f64,
    /// Terms at the leg's length [m]: heading × displacement, heading × Earth rate,
    /// drift, level, bias in turns, velocity.
    pub terms: [f64; 6],
    /// Largest circular error over the leg [m].
    pub observed: f64,
}

impl LegBudget {
    /// The closed forms' bound: the sum of the terms [m].
    pub fn bound(&self) -> f64 {
        self.terms.iter().sum()
    }
}

/// The budget of `run` over `[t0, t0 + length]` with the sensor errors `removed` from
/// its samples.
fn budget(
    run: &ModeRun,
    rec: &Recording,
    t0: f64,
    length: f64,
    removed: &SensorEstimates,
) -> Result<LegBudget> {
    let e0 = errors::at(&run.errors, t0).context("the leg's first epoch")?;
    let truth = rec.truth_at(t0);
    let lat = truth.state.pos.lat;
    let c_bn = truth.state.q_bn.to_rotation_matrix().into_inner();
    let drift_b = truth.gyro_bias - removed.gyro_bias;
    let bias_b = truth.accel_bias - removed.accel_bias;
    let bias_n = c_bn * bias_b;
    let g = schuler::earth::EarthModel::local(&Wgs84, lat, truth.state.pos.h)
        .g_n
        .z;
    let level = (g * e0.psi.y + bias_n.x).hypot(-g * e0.psi.x + bias_n.y);
    let ws = (g / R).sqrt();
    let f = length - (ws * length).sin() / ws;
    let reach = displacement(rec, t0, length);
    let heading = e0.psi.z.abs();
    let drift = drift_b.x.hypot(drift_b.y);
    let bias = bias_b.x.hypot(bias_b.y);
    let velocity = e0.v_n.x.hypot(e0.v_n.y);
    let terms = [
        heading * reach,
        R * schuler::earth::Wgs84::OMEGA * lat.cos() * heading * f,
        R * drift * f,
        level * (1.0 - (ws * length).cos()) / (ws * ws),
        2.0 * bias * abs_integral(|s| (ws * s).sin() / ws, length),
        velocity * abs_integral(|s| (ws * s).cos(), length),
    ];
    Ok(LegBudget {
        label: run.label,
        t0,
        heading,
        drift,
        bias,
        level,
        velocity,
        terms,
        observed: errors::max_circular(&run.errors, t0, t0 + length),
    })
}

/// `∫₀ᵗ |k(s)| ds` by the midpoint rule on 1000 intervals (the kernels are smooth
/// and change sign at most twice over a leg shorter than a Schuler period: 1e-6
/// relative).
fn abs_integral(k: impl Fn(f64) -> f64, t: f64) -> f64 {
    let n = 1000;
    let h = t / n as f64;
    (0..n).map(|i| k((i as f64 + 0.5) * h).abs() * h).sum()
}

/// Largest horizontal distance of the true track from its position at `t0` within
/// `length` seconds [m] (local-level approximation on the mean sphere).
fn displacement(rec: &Recording, t0: f64, length: f64) -> f64 {
    let p0 = rec.truth_at(t0).state.pos;
    rec.truth
        .iter()
        .filter(|e| e.state.t >= t0 && e.state.t <= t0 + length)
        .map(|e| {
            let dn = (e.state.pos.lat - p0.lat) * R;
            let de = (e.state.pos.lon - p0.lon) * R * p0.lat.cos();
            dn.hypot(de)
        })
        .fold(0.0, f64::max)
}

/// Names of [`LegBudget::terms`].
const TERMS: [&str; 6] = [
    "heading error turning the displacement",
    "heading error with the Earth's horizontal rate",
    "horizontal gyro drift",
    "net level error",
    "accelerometer bias rotated in turns",
    "velocity error",
];

/// The largest term of a budget: its name and size [m].
fn largest(b: &LegBudget) -> (&'static str, f64) {
    b.terms
        .iter()
        .zip(TERMS)
        .map(|(&x, name)| (name, x))
        .fold(("", 0.0), |a, t| if t.1 > a.1 { t } else { a })
}

/// Why each term of [`LegBudget::terms`] is what it is after each stage.
const WHY: [&str; 6] = [
    "a heading error turns the whole displacement; gyrocompassing at rest leaves about \
     ε_E/(Ω cos φ), and only the turns in flight separate heading from the east drift",
    "with the Earth's horizontal rate Ω cos φ a heading error acts as a drift",
    "a drift grows as R ε (t − sin(ω_s t)/ω_s); at rest the east drift hides in the \
     heading, and in 45 minutes of flight a navigation-grade drift is barely observed",
    "leveling cancels g ψ against the bias on the pad; what the filter leaves of both \
     remains",
    "leveling hides a horizontal accelerometer bias in the tilt until the turns rotate \
     the bias out of that cancellation (up to 2b/ω_s²): no alignment at rest separates \
     them, the inertial-satellite mode's turns do",
    "the inertial-satellite mode hands over its small velocity error",
];

/// What the stages removed: `budgets` are coarse only, fine alignment and figure 3.
pub fn explain(budgets: &[LegBudget; 3]) -> String {
    let [coarse, fine, fig3] = budgets;
    let terms: Vec<String> = TERMS
        .iter()
        .enumerate()
        .map(|(k, name)| {
            format!(
                "{name} {:.0} → {:.0} → {:.0} m",
                coarse.terms[k], fine.terms[k], fig3.terms[k]
            )
        })
        .collect();
    let (name_b, _) = largest(coarse);
    let (name_a, _) = largest(fig3);
    let why = |name: &str| TERMS.iter().position(|t| *t == name).map_or("", |k| WHY[k]);
    format!(
        "Term by term, coarse only → fine alignment → figure 3: {}. The largest term after \
         coarse alignment alone is the {name_b}: {}. After figure 3's stages the largest \
         is the {name_a}: {}.",
        terms.join("; "),
        why(name_b),
        why(name_a),
    )
}
