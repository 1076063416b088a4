//! NED strapdown mechanization against exact trajectories: the IMU increments are the
//! integrals of the analytic angular rate and specific force over each interval, so any
//! departure from the truth is the mechanization's own error.

use nalgebra::Vector3;
use schuler::analysis::errors::errors_between;
use schuler::earth::{EarthModel, Geodetic, Sphere, Wgs84};
use schuler::imu::ImuSample;
use schuler::nav::{Corrections, LocalLevel, Mechanization, NavState};
use schuler::rotation::Euler;
use schuler::sim::analytic::{self, Coning, Maneuvering, Sculling, Stationary, Trajectory};

const ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// Horizontal position difference [m] of `a` relative to `b` (the library's epoch
/// errors, through ECEF).
fn horizontal_error<E: EarthModel>(earth: &E, a: &NavState, b: &NavState) -> f64 {
    errors_between(earth, a, b).horizontal()
}

/// Runs the mechanization from the truth at t = 0 over `n` exact samples at `dt`,
/// calling `check(nav, truth)` every `every` samples and at the end.
fn run<E: EarthModel, T: Trajectory>(
    earth: E,
    traj: &T,
    dt: f64,
    n: usize,
    corrections: Corrections,
    every: usize,
    mut check: impl FnMut(&NavState, &NavState),
) -> NavState {
    let mut nav =
        LocalLevel::new(earth, analytic::state(&earth, traj, 0.0)).with_corrections(corrections);
    nav.prime(&analytic::increment(&earth, traj, 0.0, dt));
    for (k, s) in analytic::samples(&earth, traj, 0.0, dt, n).enumerate() {
        nav.step(&s);
        if (k + 1) % every == 0 || k + 1 == n {
            check(&nav.state(), &analytic::state(&earth, traj, s.t));
        }
    }
    nav.state()
}

/// A stationary IMU stays put: 1 h at 200 Hz, horizontal drift < 1 mm, attitude drift
/// < 0.01 arcsec. With exact constant increments the algorithm is exact up to
/// O(W^2 g dt^3) terms (~1e-14 m/s per step) and round-off (1e-16 per step, growing as
/// a random walk over 7.2e5 steps to ~1e-13 rad): both are far below the bounds, which
/// are the issue's. The vertical channel is unstable (e-folding 570 s), so height is
/// checked only against a 1 mm bound grown by that factor.
#[test]
fn stationary_one_hour_stays_put() {
    let traj = Stationary {
        pos: Geodetic::from_degrees(45.07, 7.68, 245.0),
        attitude: Euler::from_degrees(2.0, -1.5, 33.0),
    };
    let (dt, n) = (1.0 / 200.0, 720_000);
    let mut worst_h = 0.0f64;
    let mut worst_att = 0.0f64;
    let mut worst_v = 0.0f64;
    run(
        Wgs84,
        &traj,
        dt,
        n,
        Corrections::default(),
        2000,
        |nav, truth| {
            worst_h = worst_h.max(horizontal_error(&Wgs84, nav, truth));
            worst_att = worst_att.max(nav.q_bn.angle_to(&truth.q_bn));
            worst_v = worst_v.max((nav.v_n - truth.v_n).xy().norm());
        },
    );
    eprintln!(
        "stationary: horizontal {worst_h:.3e} m, attitude {:.3e} arcsec, velocity {worst_v:.3e} m/s",
        worst_att / ARCSEC
    );
    assert!(worst_h < 1e-3, "horizontal drift {worst_h} m");
    assert!(
        worst_att < 0.01 * ARCSEC,
        "attitude drift {} arcsec",
        worst_att / ARCSEC
    );
    assert!(worst_v < 1e-5, "horizontal velocity {worst_v} m/s");
}

/// The maneuvering flight (turns, climbs, pitch and roll) for 30 min at 200 Hz stays
/// within 0.5 m horizontally (the bound). Measured: 7e-6 m. The second check
/// guards the velocity update's third-order rotation term `(1/6) dθ×(dθ×dv)`: without
/// it the same run errs by 2.5e-2 m (second-order global convergence, measured 4x per
/// halving of dt), with it 7e-6 m, so 1e-4 m separates the two by two decades.
#[test]
fn maneuvering_thirty_minutes_within_half_metre() {
    let traj = Maneuvering::flight(Geodetic::from_degrees(30.5, 114.3, 500.0));
    let (dt, n) = (1.0 / 200.0, 360_000);
    let mut worst_h = 0.0f64;
    let mut worst_att = 0.0f64;
    run(
        Wgs84,
        &traj,
        dt,
        n,
        Corrections::default(),
        200,
        |nav, truth| {
            worst_h = worst_h.max(horizontal_error(&Wgs84, nav, truth));
            worst_att = worst_att.max(nav.q_bn.angle_to(&truth.q_bn));
        },
    );
    eprintln!(
        "maneuvering: horizontal {worst_h:.3e} m, attitude {:.3e} arcsec",
        worst_att / ARCSEC
    );
    assert!(worst_h < 0.5, "horizontal error {worst_h} m");
    assert!(
        worst_h < 1e-4,
        "third-order velocity term lost? {worst_h} m"
    );
    assert!(
        worst_att < 1.0 * ARCSEC,
        "attitude error {} arcsec",
        worst_att / ARCSEC
    );
}

/// Ratio of the uncorrected to the corrected per-step error of the previous-sample
/// two-sample correction under classical coning (or sculling), at `l = Omega dt`.
/// Averaged over phase, the exact second-order term per step is `1/2 (l - sin l)` and
/// the correction `1/3 sin^2(l/2) sin l` (times `alpha^2`, or `A B / Omega` for
/// sculling; derived from the phasor averages of `dθ_{k-1}×dθ_k`), so the ratio is
/// `(l - sin l) / ((l - sin l) - 2/3 sin^2(l/2) sin l)` ~ `5 / l^2` (50.98 at 10 Hz in
/// 200 Hz samples).
fn two_sample_ratio(l: f64) -> f64 {
    let exact = l - l.sin();
    exact / (exact - 2.0 / 3.0 * (0.5 * l).sin().powi(2) * l.sin())
}

/// Runs 10 s of `traj` at 200 Hz on the non-rotating sphere with all corrections and
/// with `without` switched off, measures `error(nav, truth)` at the end of each, and
/// checks the ratio is at least 50 (the issue) and the closed form within 1 % (the
/// residual is the motion's higher-order terms, O(amplitude^2) ~ 3e-4, and the
/// window's end phase).
fn check_correction_ratio<T: Trajectory>(
    name: &str,
    traj: &T,
    without: Corrections,
    error: impl Fn(&NavState, &NavState) -> f64,
) {
    let sphere = Sphere::textbook(false);
    let truth = analytic::state(&sphere, traj, 10.0);
    let final_error = |c| {
        error(
            &run(sphere, traj, 1.0 / 200.0, 2000, c, usize::MAX, |_, _| {}),
            &truth,
        )
    };
    let (with, without) = (final_error(Corrections::default()), final_error(without));
    let theory = two_sample_ratio(std::f64::consts::TAU * 10.0 / 200.0);
    let ratio = without / with;
    eprintln!(
        "{name}: with {with:.3e}, without {without:.3e}, ratio {ratio:.2}, theory {theory:.2}"
    );
    assert!(ratio >= 50.0, "{name} ratio {ratio}");
    assert!(
        (ratio / theory - 1.0).abs() < 0.01,
        "{name} ratio {ratio}, theory {theory}"
    );
}

/// Classical coning (1 deg half-angle) at 10 Hz sampled at 200 Hz: the coning
/// correction reduces the attitude error at least 50-fold.
#[test]
fn coning_correction_reduces_attitude_error_fifty_fold() {
    let traj = Coning {
        pos: Geodetic::from_degrees(45.0, 0.0, 0.0),
        half_angle: 1f64.to_radians(),
        rate: std::f64::consts::TAU * 10.0,
    };
    let without = Corrections {
        coning: false,
        sculling: true,
    };
    check_correction_ratio("coning [rad]", &traj, without, |nav, truth| {
        nav.q_bn.angle_to(&truth.q_bn)
    });
}

/// Classical sculling at 10 Hz sampled at 200 Hz: the sculling correction reduces the
/// rectified velocity error at least 50-fold, by the same closed-form ratio as coning
/// (sculling is coning's dual: Savage 1998, table 1).
#[test]
fn sculling_correction_reduces_velocity_error_fifty_fold() {
    let traj = Sculling {
        pos: Geodetic::from_degrees(45.0, 0.0, 0.0),
        roll_amplitude: 1f64.to_radians(),
        east_amplitude: 0.01,
        rate: std::f64::consts::TAU * 10.0,
    };
    let without = Corrections {
        coning: true,
        sculling: false,
    };
    check_correction_ratio("sculling [m/s]", &traj, without, |nav, truth| {
        (nav.v_n - truth.v_n).norm()
    });
}

/// The textbook's Schuler period: on the non-rotating sphere (a = 6371 km,
/// g = 9.81 m/s^2) a 1e-3 m/s^2 north accelerometer bias gives
/// dV(t) = df/w0 sin(w0 t) (SEEDS.md (20)); the zero crossings of the north velocity
/// error measure T0 = 2 pi sqrt(a/g) = 84.4 min to within 0.1 %. The vertical channel
/// is left free; over one period its drift (~100 m) changes w0 by ~2e-5, well inside.
#[test]
fn schuler_period_from_accelerometer_bias() {
    let sphere = Sphere::textbook(false);
    let traj = Stationary {
        pos: Geodetic::from_degrees(0.0, 0.0, 0.0),
        attitude: Euler::default(),
    };
    let dt = 0.1;
    let bias = Vector3::new(1e-3, 0.0, 0.0);
    let truth0 = analytic::state(&sphere, &traj, 0.0);
    let mut nav = LocalLevel::new(sphere, truth0);
    let mut crossings = Vec::new();
    let mut prev = 0.0f64;
    let n = (1.1 * 5064.0 / dt) as usize;
    for s in analytic::samples(&sphere, &traj, 0.0, dt, n) {
        let biased = ImuSample {
            dvel: s.dvel + bias * s.dt,
            ..s
        };
        nav.step(&biased);
        let dv = nav.state().v_n.x;
        if prev != 0.0 && prev.signum() != dv.signum() {
            // Linear interpolation of the crossing inside the step.
            crossings.push(s.t - dt * dv / (dv - prev));
        }
        prev = dv;
    }
    assert_eq!(
        crossings.len(),
        2,
        "expected crossings at T/2 and T: {crossings:?}"
    );
    let expected = std::f64::consts::TAU * (Sphere::TEXTBOOK_RADIUS / Sphere::TEXTBOOK_G).sqrt();
    let from_half_periods = 2.0 * (crossings[1] - crossings[0]);
    for measured in [crossings[1], from_half_periods] {
        let rel = (measured - expected).abs() / expected;
        eprintln!(
            "Schuler period {:.2} s ({:.3} min), expected {:.2} s",
            measured,
            measured / 60.0,
            expected
        );
        assert!(rel < 1e-3, "relative error {rel}");
    }
    assert!((expected / 60.0 - 84.4).abs() < 0.05);
}
