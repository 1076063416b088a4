//! Self-calibration of the GNSS lever arm and time offset (issue 33) on a simulated
//! car: tactical IMU at 200 Hz, GNSS at 1 Hz with 0.5-m and 0.01-m/s noise, the
//! antenna at (0.8, −0.3, −1.2) m and its fixes stamped 80 ms early (`τ = +0.08 s`,
//! `t_imu = t_gnss + τ`), the filter told zero for both. The truth is the simulator's
//! exact trajectory and the values it was given.
//!
//! The drive turns both ways at 6–10 deg/s (the simulator's coordinated turns lean the
//! car into them, 4–12° at these speeds, which is what shows the vertical lever arm:
//! a level car says nothing of it) and changes speed between 8 and 20 m/s (what shows
//! the time offset: at a constant velocity an offset is a constant position error).

use crate::common;
use crate::common::{Data, scenario, simulated};
use nalgebra::{SMatrix, SVector, Vector3};
use schuler::analysis::consistency::{mean_bounds, normalized_squared};
use schuler::analysis::errors::errors_between;
use schuler::earth::Wgs84;
use schuler::filter::integration::{GnssFix, IntegrationConfig, Integrator};
use schuler::filter::{Calibration, CalibrationState, ImuNoise};
use schuler::nav::LocalLevel;
use schuler::sim::imu_model::ImuSimulator;
use schuler::sim::receivers::GnssModel;
use std::sync::OnceLock;

const HEADER: &str = r#"
seed = 5
earth = "wgs84"

[start]
time = 0.0
position = ["45.1 deg", "7.7 deg", "240 m"]
attitude = ["0 deg", "0 deg", "30 deg"]

[imu]
rate_hz = 200
preset = "tactical"
"#;

/// A city block, 84 s: away from a stop, three turns, a slow-down, a stop. The drive
/// is seven of them, alternating the turns' directions.
fn city_block(side: i32) -> String {
    let mut out = String::new();
    let mut seg = |kind: &str, body: String| {
        out.push_str(&format!("\n[[motion]]\ntype = \"{kind}\"\n{body}\n"));
    };
    let turn =
        |deg: i32, rate: f64| format!("angle = \"{} deg\"\nrate = \"{rate} deg/s\"", deg * side);
    let speed = |v: f64, a: f64| format!("to_speed = \"{v} m/s\"\naccel = \"{a} m/s^2\"");
    let hold = |t: f64| format!("duration = \"{t} s\"");
    seg("accelerate", speed(12.0, 2.0));
    seg("hold", hold(8.0));
    seg("turn", turn(90, 12.0));
    seg("hold", hold(8.0));
    seg("accelerate", speed(6.0, 2.0));
    seg("turn", turn(-90, 15.0));
    seg("accelerate", speed(14.0, 2.0));
    seg("hold", hold(10.0));
    seg("turn", turn(-90, 12.0));
    seg("hold", hold(6.0));
    seg("accelerate", speed(0.0, 2.0));
    seg("hold", hold(10.0));
    out
}

/// Seven city blocks after 20 s at rest, 10 min 10 s.
fn city_drive() -> String {
    let mut s = format!("{HEADER}\n[[motion]]\ntype = \"hold\"\nduration = \"20 s\"\n");
    for k in 0..7 {
        s.push_str(&city_block(if k % 2 == 0 { 1 } else { -1 }));
    }
    s
}

/// Straight at a constant 15 m/s for 12 min, from the start.
const STRAIGHT: &str = r#"
[[motion]]
type = "hold"
duration = "720 s"
"#;

const LEVER: [f64; 3] = [0.8, -0.3, -1.2];
/// The fixes' velocity noise [m/s]: a velocity from carrier-phase Doppler, as
/// survey-grade receivers give it. The velocity fixes carry nearly all of what is
/// learnt of the calibrations (in turns `ω × l`, in speed changes `a τ`), so their
/// σ scale with it: after 10 minutes of this drive (3.2, 2.1, 4.1) cm and 2.0 ms at
/// 0.05 m/s, (1.4, 1.0, 1.7) cm and 0.9 ms at 0.02 m/s, (0.75, 0.53, 0.87) cm and
/// 0.52 ms here, and (8.6, 5.6, 19.5) cm and 5.1 ms from the 0.5-m positions alone.
/// Those are the filter's covariances, which for this model linearised about the
/// truth are the Cramér–Rao bound: the issue's "within 3 cm and 2 ms" in every run (3σ)
/// needs σ of 1 cm and 0.7 ms, so a velocity at 0.01 m/s.
const VEL_STD: f64 = 0.01;
const TAU: f64 = 0.08;
/// Calibrations are judged after this long [s] (the issue's 10 minutes).
const SETTLED: f64 = 600.0;

fn city() -> &'static Data {
    static DATA: OnceLock<Data> = OnceLock::new();
    DATA.get_or_init(|| simulated(&scenario(&city_drive())))
}

fn straight() -> &'static Data {
    static DATA: OnceLock<Data> = OnceLock::new();
    DATA.get_or_init(|| {
        let moving = HEADER.replace("\n\n[imu]", "\nspeed = \"15 m/s\"\n\n[imu]");
        simulated(&scenario(&format!("{moving}{STRAIGHT}")))
    })
}

fn tactical() -> schuler::imu::model::ImuModel {
    scenario(&format!("{HEADER}{STRAIGHT}"))
        .imu
        .model()
        .expect("imu")
}

/// Fixes of the antenna at [`LEVER`] stamped `tau` early.
fn fixes(d: &Data, tau: f64, seed: u64) -> Vec<GnssFix> {
    let model = GnssModel {
        interval: 1.0,
        pos_std: Vector3::repeat(0.5),
        vel_std: Vector3::repeat(VEL_STD),
        lever_arm: Vector3::from(LEVER),
        time_offset: tau,
        outages: Vec::new(),
        outliers: Vec::new(),
    };
    common::gnss_fixes(d, model, seed).0
}

/// What the filter knows: `lever` and `tau` given, and what it estimates.
#[derive(Clone, Copy)]
struct Told {
    lever: Vector3<f64>,
    tau: f64,
    calibration: Calibration,
}

fn told_zero(lever_std: f64, tau_std: f64) -> Told {
    Told {
        lever: Vector3::zeros(),
        tau: 0.0,
        calibration: Calibration {
            lever_arm_std: Some(lever_std),
            time_offset_std: Some(tau_std),
            time_offset_walk: 0.0,
        },
    }
}

fn told_truth() -> Told {
    Told {
        lever: Vector3::from(LEVER),
        tau: TAU,
        calibration: Calibration::default(),
    }
}

struct Run {
    /// Horizontal position error at each second after [`SETTLED`] [m].
    horizontal: Vec<f64>,
    /// NEES of position, velocity and attitude (9 dof) at each second.
    nees: Vec<f64>,
    /// The calibration at each second.
    history: Vec<(f64, CalibrationState)>,
    gate_resets: usize,
    rejected: usize,
}

fn run(d: &Data, gnss: &[GnssFix], seed: u64, told: Told) -> Run {
    run_on(LocalLevel::new(Wgs84, d.truth[0]), d, gnss, seed, told)
}

/// [`run`] on the mechanization `mech`.
fn run_on<M: schuler::nav::ErrorFrame>(
    mech: M,
    d: &Data,
    gnss: &[GnssFix],
    seed: u64,
    told: Told,
) -> Run {
    let model = tactical();
    let cfg = IntegrationConfig {
        lever_arm: told.lever,
        gnss_time_offset: told.tau,
        calibration: told.calibration,
        ..IntegrationConfig::new(ImuNoise::from_model(&model))
    };
    let mut imu = ImuSimulator::new(model, seed);
    let mut integ = Integrator::new(mech, Wgs84, cfg);
    integ.prime(&imu.measure(&d.exact[0]));
    let mut queue = gnss.iter().copied().peekable();
    let mut r = Run {
        horizontal: Vec::new(),
        nees: Vec::new(),
        history: Vec::new(),
        gate_resets: 0,
        rejected: 0,
    };
    for (s, truth) in d.exact.iter().zip(&d.truth).skip(1) {
        integ.step_with_fixes(&imu.measure(s), &mut queue);
        if (truth.t - truth.t.round()).abs() > 1e-6 {
            continue;
        }
        let e = errors_between(&Wgs84, &integ.state(), truth);
        if truth.t >= SETTLED {
            r.horizontal.push(e.horizontal());
        }
        let mut x = SVector::<f64, 9>::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(&e.pos_n);
        x.fixed_rows_mut::<3>(3).copy_from(&e.v_n);
        x.fixed_rows_mut::<3>(6).copy_from(&e.psi);
        let mut p = SMatrix::<f64, 9, 9>::zeros();
        let c = integ.nav_covariance();
        for (k, b) in c.iter().enumerate() {
            p.fixed_view_mut::<3, 3>(3 * k, 3 * k).copy_from(b);
        }
        if truth.t > 60.0 {
            // The cross-covariances between the blocks are left out (the NED blocks
            // only): the NEES of each block, summed, is chi-square(9) when each is
            // chi-square(3), whatever their correlation, in the mean.
            let blocks: f64 = (0..3)
                .map(|k| {
                    normalized_squared(
                        &x.fixed_rows::<3>(3 * k).into_owned(),
                        &p.fixed_view::<3, 3>(3 * k, 3 * k).into_owned(),
                    )
                    .expect("P > 0")
                })
                .sum();
            r.nees.push(blocks);
        }
        r.history.push((truth.t, integ.calibration()));
    }
    r.gate_resets = integ.book.gate_resets.len();
    r.rejected = integ.book.rejected.len();
    r
}

fn v3(v: &Vector3<f64>) -> String {
    format!("({:.3}, {:.3}, {:.3})", v.x, v.y, v.z)
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// The calibration at `t` [s] or the first second after.
fn at(r: &Run, t: f64) -> CalibrationState {
    r.history.iter().find(|(s, _)| *s >= t).expect("epoch").1
}

/// The issue's first must-show, over 10 runs (different IMU and GNSS noise): after
/// 10 minutes each lever-arm axis within 3 cm and the offset within 2 ms of the truth,
/// each inside its own σ as a consistent filter's is, NEES consistent, the position
/// error at most 10 % above the run told the true values.
#[test]
fn lever_arm_and_time_offset_converge_on_a_city_drive() {
    let d = city();
    let runs = 10;
    let (mut calibrated, mut told) = (Vec::new(), Vec::new());
    let mut nees_sum: Vec<f64> = Vec::new();
    let mut worst_lever = Vector3::<f64>::zeros();
    let mut worst_tau: f64 = 0.0;
    let mut z_scores = Vec::new();
    let mut rejected = 0;
    for k in 0..runs {
        let gnss = fixes(d, TAU, 300 + k);
        let r = run(d, &gnss, 400 + k, told_zero(1.0, 0.5));
        let c = at(&r, SETTLED);
        let l = c.lever_arm.expect("lever arm estimated");
        let t = c.time_offset.expect("time offset estimated");
        let dl = l.value - Vector3::from(LEVER);
        let dt = t.value - TAU;
        println!(
            "run {k}: lever arm {} ± {} (error {}; alone ± {}) m, offset {:.4} ± {:.4} s \
             (error {:.1} ms; alone ± {:.4})",
            v3(&l.value),
            v3(&l.std),
            v3(&dl),
            v3(&l.excited_std),
            t.value,
            t.std,
            dt * 1e3,
            t.excited_std
        );
        for i in 0..3 {
            z_scores.push(dl[i] / l.std[i]);
            worst_lever[i] = worst_lever[i].max(dl[i].abs());
        }
        z_scores.push(dt / t.std);
        assert!(l.observed().iter().all(|o| *o) && t.observed());
        worst_tau = worst_tau.max(dt.abs());
        if nees_sum.is_empty() {
            nees_sum = vec![0.0; r.nees.len()];
        }
        for (s, n) in nees_sum.iter_mut().zip(&r.nees) {
            *s += n;
        }
        assert_eq!(r.gate_resets, 0);
        rejected += r.rejected;
        calibrated.push(rms(&r.horizontal));
        let truth_run = run(d, &gnss, 400 + k, told_truth());
        told.push(rms(&truth_run.horizontal));
    }
    let mean_nees = nees_sum.iter().sum::<f64>() / (nees_sum.len() * runs as usize) as f64;
    let b = mean_bounds(runs as usize, 9, 0.95);
    let (cal, tru) = (rms(&calibrated), rms(&told));
    println!(
        "worst lever-arm error {} m, offset {:.2} ms; mean NEES {mean_nees:.2} \
         (95 % interval of the mean {:.2}..{:.2}); horizontal RMS after {SETTLED} s \
         {cal:.3} m calibrated, {tru:.3} m told the truth",
        v3(&worst_lever),
        worst_tau * 1e3,
        b.lo,
        b.hi
    );
    // Each estimate's error in its own standard deviations: 40 of them (4 a run), whose
    // squares average to 1 for a consistent filter (the mean of 40 chi-square(1) lies
    // in chi2(40)/40's 95 % interval); the issue asks each inside its 3σ, which 40
    // normal draws all are with probability 0.9973⁴⁰ = 90 %: 4σ (all inside with
    // probability 99.75 %) is the test.
    let z2 = z_scores.iter().map(|z| z * z).sum::<f64>() / z_scores.len() as f64;
    let zb = mean_bounds(z_scores.len(), 1, 0.95);
    let beyond3 = z_scores.iter().filter(|z| z.abs() > 3.0).count();
    println!(
        "calibration errors in their σ: mean square {z2:.2} (95 % interval {:.2}..{:.2}), \
         largest {:.2}, {beyond3} of {} beyond 3σ",
        zb.lo,
        zb.hi,
        z_scores.iter().fold(0.0f64, |m, z| m.max(z.abs())),
        z_scores.len()
    );
    assert!((zb.lo..=zb.hi).contains(&z2), "{z2}");
    // The issue's bounds, in every run: 3 cm is 3.5σ of the vertical axis (the worst
    // known), 2 ms is 3.8σ of the offset.
    assert!(worst_lever.iter().all(|e| *e < 0.03), "{worst_lever:?}");
    assert!(worst_tau < 0.002, "{worst_tau}");
    assert!(z_scores.iter().all(|z| z.abs() < 4.0), "{z_scores:?}");
    // The gate at 1e-4 refuses a consistent filter's measurement with that
    // probability: 10 runs of 2 × 650 updates expect 1.3 refusals, Poisson; 6 or more
    // has a probability of 0.2 %.
    assert!(rejected < 6, "{rejected} refused");
    // The issue's bound on the cost of calibrating.
    assert!(cal <= 1.1 * tru, "{cal} against {tru}");
    // The mean over runs and epochs of a 9-dof NEES: the runs are independent, the
    // epochs of one run are not (the errors are correlated over minutes), so the
    // interval is that of the 10 runs' mean, chi2(90)/10.
    assert!((b.lo..=b.hi).contains(&mean_nees), "mean NEES {mean_nees}");
}

/// The issue's second must-show: fixes 1.3 s late against the IMU, a 2-s prior, the
/// filter told zero: the offset converges within 20 ms by 10 minutes, with no gate
/// reset on the way (the fixes are applied at `t + τ̂` as the estimate moves, so the
/// linear model only ever spans the residual).
#[test]
fn a_large_offset_converges() {
    let d = city();
    let tau = 1.3;
    let gnss = fixes(d, tau, 310);
    let r = run(d, &gnss, 410, told_zero(1.0, 2.0));
    let t = at(&r, SETTLED).time_offset.expect("estimated");
    let worst_after = r
        .history
        .iter()
        .filter(|(s, _)| *s >= SETTLED)
        .map(|(_, c)| (c.time_offset.expect("estimated").value - tau).abs())
        .fold(0.0f64, f64::max);
    println!(
        "offset {:.4} ± {:.4} s at {SETTLED} s (error {:.2} ms, at most {:.2} ms after); \
         {} refused, {} gate resets; horizontal RMS after {SETTLED} s {:.3} m",
        t.value,
        t.std,
        (t.value - tau) * 1e3,
        worst_after * 1e3,
        r.rejected,
        r.gate_resets,
        rms(&r.horizontal)
    );
    assert_eq!(r.gate_resets, 0);
    assert!(worst_after < 0.020, "{worst_after}");
    assert!(t.observed());
    // Converged: the solution is as good as with small offsets (0.21 m, above).
    assert!(rms(&r.horizontal) < 0.3, "{}", rms(&r.horizontal));
}

/// The issue's third must-show: straight at a constant speed, nothing observes the
/// calibrations (a lever arm that does not turn is a constant position offset, the
/// same as the position's own; an offset at a constant velocity is a constant offset
/// along the track), so the estimates keep their priors' standard deviations, say
/// so, and the solution is no worse than the same run without them.
#[test]
fn a_straight_drive_observes_nothing_and_costs_nothing() {
    let d = straight();
    let gnss = fixes(d, TAU, 320);
    let estimating = run(d, &gnss, 420, told_zero(1.0, 0.5));
    let plain = run(
        d,
        &gnss,
        420,
        Told {
            calibration: Calibration::default(),
            ..told_zero(1.0, 0.5)
        },
    );
    let c = estimating.history.last().expect("epochs").1;
    let (l, t) = (c.lever_arm.expect("lever"), c.time_offset.expect("offset"));
    let (with, without) = (rms(&estimating.horizontal), rms(&plain.horizontal));
    println!(
        "lever arm {} ± {} m (from the motion alone ± {}), offset {:.3} ± {:.3} s (from the motion alone ± {:.3}); \
         observed {:?} {}; horizontal RMS {with:.3} m estimating, {without:.3} m not",
        v3(&l.value),
        v3(&l.std),
        v3(&l.excited_std),
        t.value,
        t.std,
        t.excited_std,
        l.observed(),
        t.observed()
    );
    assert_eq!(l.observed(), [false; 3]);
    assert!(!t.observed());
    // The same fixes and IMU noise: only the estimation differs, and it must not
    // move the solution by more than the rounding of a different computation (the
    // states it adds are unobserved; 1 % is far above that and far below the 0.8-m
    // horizontal offset the unknown lever arm leaves in both).
    assert!(with <= 1.01 * without, "{with} against {without}");
}

/// With the smoother: a constant calibration is one random variable at every epoch,
/// so its smoothed estimate, given all the data, is at every epoch the forward pass's
/// estimate at the end (Rauch–Tung–Striebel on states without process noise; the
/// closed-loop feedback the smoother undoes is recorded exactly).
#[test]
fn smoothed_calibration_is_the_final_estimate_throughout() {
    let d = city();
    let gnss = fixes(d, TAU, 330);
    let model = tactical();
    let cfg = IntegrationConfig {
        calibration: told_zero(1.0, 0.5).calibration,
        ..IntegrationConfig::new(ImuNoise::from_model(&model))
    };
    let mut imu = ImuSimulator::new(model, 430);
    let mut integ = Integrator::new(LocalLevel::new(Wgs84, d.truth[0]), Wgs84, cfg).with_smoother();
    integ.prime(&imu.measure(&d.exact[0]));
    let mut queue = gnss.iter().copied().peekable();
    for (s, truth) in d.exact.iter().zip(&d.truth).skip(1) {
        integ.step_with_fixes(&imu.measure(s), &mut queue);
        if (truth.t - truth.t.round()).abs() < 1e-6 {
            integ.record_output();
        }
    }
    let end = integ.estimates();
    let smoothed = integ
        .smoothed()
        .expect("smoothing")
        .expect("the smoother's record")
        .collect_states(Wgs84)
        .expect("the smoothed trajectory");
    let (mut lever, mut tau) = (0.0f64, 0.0f64);
    for s in &smoothed {
        lever = lever.max((s.estimates.lever_arm - end.lever_arm).amax());
        tau = tau.max((s.estimates.gnss_time_offset - end.gnss_time_offset).abs());
    }
    println!(
        "{} epochs: smoothed against the final estimate at most {lever:.2e} m, {tau:.2e} s",
        smoothed.len()
    );
    assert!(smoothed.len() > 600);
    // Equal to rounding: 3e-15 m and 2e-16 s here; a thousand times that leaves room
    // for another platform's arithmetic and nothing for a smoother that moved them.
    assert!(lever < 1e-12 && tau < 1e-13, "{lever} {tau}");
}

/// On the wander mechanization the calibration is the same: the two mechanizations
/// solve the same equations in other axes (they agree to micrometres over an hour,
/// `wander_agrees_with_ned`), so the estimates agree far inside their σ; a
/// thousandth of it is the bound.
#[test]
fn the_wander_mechanization_calibrates_alike() {
    let d = city();
    let gnss = fixes(d, TAU, 340);
    let ned = run(d, &gnss, 440, told_zero(1.0, 0.5));
    let start = schuler::nav::LocalLevel::new(Wgs84, d.truth[0]);
    let wander = run_on(
        schuler::nav::Wander::from_local_level(&start),
        d,
        &gnss,
        440,
        told_zero(1.0, 0.5),
    );
    let (a, b) = (
        ned.history.last().expect("epoch").1,
        wander.history.last().expect("epoch").1,
    );
    let (la, lb) = (a.lever_arm.expect("lever"), b.lever_arm.expect("lever"));
    let (ta, tb) = (
        a.time_offset.expect("offset"),
        b.time_offset.expect("offset"),
    );
    let dl = (la.value - lb.value).abs();
    let dt = (ta.value - tb.value).abs();
    println!(
        "NED against wander: lever arm {} m, offset {dt:.2e} s",
        v3(&dl)
    );
    for i in 0..3 {
        assert!(dl[i] < 1e-3 * la.std[i], "axis {i}: {}", dl[i]);
    }
    assert!(dt < 1e-3 * ta.std, "{dt}");
}
