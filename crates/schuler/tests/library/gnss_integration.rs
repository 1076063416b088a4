//! INS/GNSS integration on simulated data (issue 5): a tactical-grade IMU at 200 Hz and
//! RTK-grade GNSS at 1 Hz with a lever arm, an hour of vehicle maneuvers with three
//! 60-s GNSS outages. The truth is the simulator's exact trajectory; the sensors'
//! errors are drawn per run from the tactical preset.

use crate::common;
use crate::common::{Data, scenario, simulated};
use nalgebra::Vector3;
use schuler::analysis::consistency::{ChiSquareTest, mean_bounds, normalized_squared};
use schuler::analysis::errors::errors_between;
use schuler::earth::Wgs84;
use schuler::filter::ImuNoise;
use schuler::filter::integration::{GnssFix, Innovation, IntegrationConfig, Integrator};
use schuler::filter::measurement::Kind;
use schuler::nav::LocalLevel;
use schuler::sim::imu_model::ImuSimulator;
use schuler::sim::receivers::{GnssModel, Interval};
use std::sync::OnceLock;

const SCENARIO: &str = r#"
seed = 1
earth = "wgs84"

[start]
time = 0.0
position = ["30.5 deg", "114.3 deg", "20 m"]
attitude = ["0 deg", "0 deg", "45 deg"]

[[motion]]
type = "hold"
duration = "60 s"

[[motion]]
type = "accelerate"
to_speed = "15 m/s"
accel = "1 m/s^2"

[[motion]]
type = "turn"
angle = "90 deg"
rate = "5 deg/s"

[[motion]]
type = "hold"
duration = "240 s"

[[motion]]
type = "turn"
angle = "-270 deg"
rate = "4 deg/s"

[[motion]]
type = "climb"
to_height = "60 m"
pitch = "2 deg"

[[motion]]
type = "hold"
duration = "300 s"

[[motion]]
type = "turn"
angle = "180 deg"
bank = "10 deg"

[[motion]]
type = "hold"
duration = "400 s"

[[motion]]
type = "turn"
angle = "-90 deg"
rate = "3 deg/s"

[[motion]]
type = "climb"
to_height = "20 m"
pitch = "-2 deg"

[[motion]]
type = "hold"
duration = "500 s"

[[motion]]
type = "turn"
angle = "360 deg"
rate = "3 deg/s"

[[motion]]
type = "hold"
duration = "1700 s"

[imu]
rate_hz = 200
preset = "tactical"
"#;

/// The three outages.
const OUTAGES: [(f64, f64); 3] = [(900.0, 960.0), (1800.0, 1860.0), (2700.0, 2760.0)];
const LEVER: [f64; 3] = [0.8, 0.3, -1.2];

fn data() -> &'static Data {
    static DATA: OnceLock<Data> = OnceLock::new();
    DATA.get_or_init(|| simulated(&scenario(SCENARIO)))
}

fn tactical() -> schuler::imu::model::ImuModel {
    scenario(SCENARIO).imu.model().expect("imu")
}

/// GNSS fixes of one run: RTK-grade noise (2 cm, 2 cm, 5 cm; 2 cm/s), lever arm, the
/// outages, and `outliers` jumps.
fn fixes(seed: u64, outliers: &[(f64, Vector3<f64>)]) -> (Vec<GnssFix>, usize) {
    let model = GnssModel {
        interval: 1.0,
        pos_std: Vector3::new(0.02, 0.02, 0.05),
        vel_std: Vector3::new(0.02, 0.02, 0.02),
        lever_arm: Vector3::from(LEVER),
        time_offset: 0.0,
        outages: OUTAGES
            .iter()
            .map(|&(start, end)| Interval { start, end })
            .collect(),
        outliers: outliers
            .iter()
            .map(|&(t, jump)| schuler::sim::receivers::Outlier { t, jump })
            .collect(),
    };
    common::gnss_fixes(data(), model, seed)
}

/// Per-second errors of a run: NED position error, velocity error, attitude error ψ,
/// and the filter's covariance of them (NED).
struct Epoch {
    t: f64,
    e: [f64; 9],
    p: nalgebra::SMatrix<f64, 9, 9>,
}

struct Run {
    epochs: Vec<Epoch>,
    /// Every measurement the filter tested.
    innovations: Vec<Innovation>,
    /// Horizontal error of the smoothed trajectory at each second (with `smooth`).
    smoothed: Vec<(f64, f64)>,
    rejected: usize,
    rejected_outliers: usize,
}

fn run(seed: u64, gnss: &[GnssFix], outlier_times: &[f64]) -> Run {
    run_with(seed, gnss, outlier_times, false)
}

fn run_with(seed: u64, gnss: &[GnssFix], outlier_times: &[f64], smooth: bool) -> Run {
    run_full(seed, gnss, outlier_times, smooth, false)
}

/// With `baro`: a barometer at 10 Hz (5 m bias, 0.5 m noise) aids the height.
fn run_full(seed: u64, gnss: &[GnssFix], outlier_times: &[f64], smooth: bool, baro: bool) -> Run {
    let d = data();
    let model = tactical();
    let noise = ImuNoise::from_model(&model);
    let cfg = IntegrationConfig {
        lever_arm: Vector3::from(LEVER),
        init_pos_std: Vector3::repeat(0.05),
        init_vel_std: Vector3::repeat(0.02),
        init_att_std: Vector3::new(0.05, 0.05, 0.2).map(f64::to_radians),
        baro: baro.then_some((10.0, 0.0)),
        ..IntegrationConfig::new(noise)
    };
    let mut baro_sim = schuler::sim::receivers::BaroSimulator::new(
        schuler::sim::receivers::BaroModel {
            interval: 0.1,
            bias: 5.0,
            drift: 0.0,
            noise: 0.5,
            dropouts: Vec::new(),
            outliers: Vec::new(),
        },
        seed,
    );
    let mut imu = ImuSimulator::new(model, seed);
    let start = d.truth[0];
    let mut integ = Integrator::new(LocalLevel::new(Wgs84, start), Wgs84, cfg);
    if smooth {
        integ = integ.with_smoother();
    }
    integ.prime(&imu.measure(&d.exact[0]));
    let mut fixes = gnss.iter().copied().peekable();
    let mut epochs = Vec::new();
    for (k, (s, truth)) in d.exact.iter().zip(&d.truth).enumerate().skip(1) {
        integ.step_with_fixes(&imu.measure(s), &mut fixes);
        if baro
            && k % 20 == 0
            && let Some(r) = baro_sim.reading(truth.t, 0.0, truth.pos.h)
        {
            integ.update_baro(r.t, r.h, 0.5);
        }
        if (truth.t - truth.t.round()).abs() < 1e-6 {
            integ.record_output();
            let est = integ.state();
            let err = errors_between(&Wgs84, &est, truth);
            let mut e = [0.0; 9];
            e[..3].copy_from_slice(err.pos_n.as_slice());
            e[3..6].copy_from_slice(err.v_n.as_slice());
            e[6..].copy_from_slice(err.psi.as_slice());
            let p = integ.covariance().fixed_view::<9, 9>(0, 0).into_owned();
            epochs.push(Epoch { t: truth.t, e, p });
        }
    }
    let rejected_outliers = outlier_times
        .iter()
        .filter(|t| {
            let hit = integ.book.rejected.iter().any(|r| (*t - r.t).abs() < 1e-6);
            if !hit {
                println!("outlier at {t} not rejected");
            }
            hit
        })
        .count();
    let truth_at =
        |t: f64| d.truth[((t - d.truth[0].t) / (d.truth[1].t - d.truth[0].t)).round() as usize];
    let smoothed = integ
        .smoothed()
        .map(|s| s.expect("the smoother's record").collect_states(Wgs84))
        .transpose()
        .expect("the smoothed trajectory")
        .unwrap_or_default()
        .iter()
        .map(|s| {
            let truth = truth_at(s.state.t);
            (
                s.state.t,
                errors_between(&Wgs84, &s.state, &truth).horizontal(),
            )
        })
        .collect();
    Run {
        epochs,
        innovations: std::mem::take(&mut integ.book.innovations),
        smoothed,
        rejected: integ.book.rejected.len(),
        rejected_outliers,
    }
}

fn horizontal(e: &Epoch) -> f64 {
    e.e[0].hypot(e.e[1])
}

fn in_outage(t: f64) -> bool {
    OUTAGES.iter().any(|&(a, b)| t >= a && t <= b)
}

#[test]
fn errors_meet_their_bounds_and_the_covariance_is_consistent() {
    let runs = 20;
    let mut nees_sum: Vec<f64> = Vec::new();
    let mut nis: Vec<(Kind, f64)> = Vec::new();
    let mut worst_outage: f64 = 0.0;
    let mut worst_aided: f64 = 0.0;
    let mut worst_att: f64 = 0.0;
    for k in 0..runs {
        let (gnss, _) = fixes(100 + k, &[]);
        let r = run(200 + k, &gnss, &[]);
        nis.extend(
            r.innovations
                .iter()
                .filter(|i| i.accepted)
                .map(|i| (i.kind, i.nis)),
        );
        if nees_sum.is_empty() {
            nees_sum = vec![0.0; r.epochs.len()];
        }
        for (i, ep) in r.epochs.iter().enumerate() {
            let e = nalgebra::SVector::<f64, 9>::from_column_slice(&ep.e);
            nees_sum[i] += normalized_squared(&e, &ep.p).expect("P > 0");
            if ep.t > 120.0 {
                if in_outage(ep.t) {
                    worst_outage = worst_outage.max(horizontal(ep));
                } else {
                    worst_aided = worst_aided.max(horizontal(ep));
                }
                worst_att = worst_att.max(ep.e[6].hypot(ep.e[7]));
            }
        }
    }
    let mean_nees: f64 = nees_sum.iter().sum::<f64>() / (nees_sum.len() * runs as usize) as f64;
    // 95 % interval of the mean of 20 chi-square(9) draws: chi2(180) quantiles / 20
    // (144.741 and 219.044, checked against mpmath in analysis::consistency).
    let b = mean_bounds(runs as usize, 9, 0.95);
    let (lo, hi) = (b.lo, b.hi);
    let inside = nees_sum
        .iter()
        .filter(|s| (lo..=hi).contains(&(*s / runs as f64)))
        .count() as f64
        / nees_sum.len() as f64;
    println!(
        "20 runs: mean NEES {mean_nees:.2} (95% interval {lo:.2}..{hi:.2}; {:.0}% of epochs inside), \
         worst horizontal error aided {worst_aided:.3} m, in outages {worst_outage:.2} m, level {:.2e} rad",
        inside * 100.0,
        worst_att
    );
    assert!((lo..=hi).contains(&mean_nees), "mean NEES {mean_nees}");
    for kind in [Kind::GnssPosition, Kind::GnssVelocity] {
        let t = ChiSquareTest::of(nis.iter().filter(|n| n.0 == kind).map(|n| n.1), 3, 0.95)
            .expect("updates");
        println!(
            "{kind}: {} updates, mean NIS {:.3} (interval of the mean {:.3}..{:.3}), {:.2} % outside {:.3}..{:.3}",
            t.count,
            t.mean,
            t.mean_bounds.lo,
            t.mean_bounds.hi,
            100.0 * t.fraction_outside(),
            t.epoch_bounds.lo,
            t.epoch_bounds.hi
        );
        // Innovations of a consistent filter are white: the average of N values of
        // chi2(3) lies in chi2(3N)/N's 95 % interval.
        assert!(t.mean_inside(), "{kind}: mean NIS {}", t.mean);
        // Each update falls outside its 95 % interval with probability 0.05; over N
        // independent updates the fraction outside has standard deviation
        // sqrt(0.05 · 0.95 / N) (0.08 % for N = 69 000): 3.29 of them is the
        // two-sided 99.9 % band.
        let sd = (0.05 * 0.95 / t.count as f64).sqrt();
        assert!(
            (t.fraction_outside() - 0.05).abs() < 3.29 * sd,
            "{kind}: {} outside",
            t.fraction_outside()
        );
    }
    // With GNSS: the RTK noise's horizontal std is 0.028 m; the largest of 20 x 3500
    // epochs of a filtered estimate stays below ~5 of those.
    assert!(worst_aided < 0.15, "{worst_aided}");
    // A 60-s outage must drift less than a tactical IMU's unestimated 1 mg bias would:
    // ½ · 9.81e-3 m/s² · (60 s)² = 17.7 m.
    assert!(worst_outage < 17.7, "{worst_outage}");
}

#[test]
fn injected_outliers_are_all_rejected() {
    // 50-m jumps on 1 % of the epochs (every 100th second), in random directions.
    let times: Vec<f64> = (1..36)
        .map(|k| 100.0 * k as f64 + 0.0)
        .filter(|t| !in_outage(*t))
        .collect();
    let jumps: Vec<(f64, Vector3<f64>)> = times
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            let a = i as f64 * 2.4;
            (
                t,
                Vector3::new(a.cos(), a.sin(), 0.3 * (i as f64).sin()).normalize() * 50.0,
            )
        })
        .collect();
    let end = data().truth.last().map_or(0.0, |s| s.t);
    println!("trajectory: {end} s");
    assert!(end >= 3600.0);
    let (clean, _) = fixes(7, &[]);
    let (dirty, injected) = fixes(7, &jumps);
    assert_eq!(injected, times.len());
    let a = run(8, &clean, &[]);
    let b = run(8, &dirty, &times);
    // Every jumped position is refused (the velocity of those epochs is clean).
    assert_eq!(
        b.rejected_outliers,
        times.len(),
        "rejected {} of {}",
        b.rejected_outliers,
        times.len()
    );
    let rms = |r: &Run| {
        (r.epochs.iter().map(|e| horizontal(e).powi(2)).sum::<f64>() / r.epochs.len() as f64).sqrt()
    };
    println!(
        "clean RMS {:.4} m, with outliers {:.4} m, rejected {} (clean run: {})",
        rms(&a),
        rms(&b),
        b.rejected,
        a.rejected
    );
    assert!((rms(&b) / rms(&a) - 1.0).abs() < 0.1);
}

#[test]
fn the_smoother_at_least_halves_the_error_in_outages() {
    let (gnss, _) = fixes(31, &[]);
    let r = run_with(32, &gnss, &[], true);
    assert_eq!(r.smoothed.len(), r.epochs.len());
    for (k, &(a, b)) in OUTAGES.iter().enumerate() {
        let fwd = r
            .epochs
            .iter()
            .filter(|e| e.t >= a && e.t <= b)
            .map(horizontal)
            .fold(0.0, f64::max);
        let smo = r
            .smoothed
            .iter()
            .filter(|e| e.0 >= a && e.0 <= b)
            .map(|e| e.1)
            .fold(0.0, f64::max);
        println!("outage {k}: forward max {fwd:.3} m, smoothed max {smo:.3} m");
        assert!(smo <= 0.5 * fwd, "outage {k}: {smo} vs {fwd}");
    }
    // Outside the outages the smoother is no worse than the filter's RTK level.
    let worst = r
        .smoothed
        .iter()
        .filter(|e| e.0 > 120.0 && !in_outage(e.0))
        .map(|e| e.1)
        .fold(0.0, f64::max);
    assert!(worst < 0.15, "{worst}");
}

/// A barometer bounds the height in outages: the unaided vertical channel of a
/// tactical IMU drifts (bias and the gravity-gradient instability), while baro
/// aiding holds it to the barometer's noise once its bias is estimated under GNSS.
#[test]
fn a_barometer_holds_the_height_through_outages() {
    let (gnss, _) = fixes(41, &[]);
    let without = run_full(42, &gnss, &[], false, false);
    let with = run_full(42, &gnss, &[], false, true);
    let worst = |r: &Run| {
        r.epochs
            .iter()
            .filter(|e| in_outage(e.t))
            .map(|e| e.e[2].abs())
            .fold(0.0, f64::max)
    };
    let (a, b) = (worst(&without), worst(&with));
    println!("vertical max in outages: GNSS only {a:.3} m, with baro {b:.3} m");
    assert!(b < a, "{b} vs {a}");
    // Half a metre of baro noise averaged over the outage: well under a metre.
    assert!(b < 1.0, "{b}");
}

/// The NIS test has teeth: the same data with the receiver's standard deviations
/// declared 3 times too large (a 9-fold R) gives position innovations whose NIS
/// averages far below its 3 dof, outside the interval the consistent runs meet.
#[test]
fn a_mismatched_noise_model_fails_the_nis_test() {
    let (mut gnss, _) = fixes(51, &[]);
    for f in &mut gnss {
        f.pos_std *= 3.0;
        f.vel = f.vel.map(|(v, std)| (v, std * 3.0));
    }
    let r = run(52, &gnss, &[]);
    let t = ChiSquareTest::of(
        r.innovations
            .iter()
            .filter(|i| i.accepted && i.kind == Kind::GnssPosition)
            .map(|i| i.nis),
        3,
        0.95,
    )
    .expect("updates");
    println!(
        "R 9x too large: mean position NIS {:.3}, interval of the mean {:.3}..{:.3}, {:.1} % below {:.3}",
        t.mean,
        t.mean_bounds.lo,
        t.mean_bounds.hi,
        100.0 * t.fraction_below,
        t.epoch_bounds.lo
    );
    assert!(t.mean < t.mean_bounds.lo, "{}", t.mean);
}
