//! Alignment on simulated bases at rest, against the closed-form limits of
//! gyrocompassing (see `schuler::align::coarse`):
//!
//! - level: `|ψ_h| = |b_h|/g` (horizontal accelerometer bias in NED);
//! - heading: `|ψ_D| ≤ |ε_E|/(Ω cos φ) + tan φ |b_E|/g`, plus the noise term
//!   `N/(Ω cos φ √T)` and the bias instability's `σ/(Ω cos φ)` in quadrature.
//!
//! The data are exact increments of a base fixed to the Earth (constant body rates
//! `ω^b = C_bn ω_ie^n`, `f^b = −C_bn g^n`, so an increment is rate × dt exactly)
//! through the simulator's sensor error model.

use nalgebra::Vector3;
use schuler::align::{AlignConfig, AlignError, Alignment, HeadingSource, align};
use schuler::analysis::errors::errors_between;
use schuler::earth::{EarthModel, Geodetic, Wgs84};
use schuler::filter::ImuNoise;
use schuler::imu::ImuSample;
use schuler::imu::model::{ImuModel, VibrationLine};
use schuler::nav::{LocalLevel, Mechanization, NavState};
use schuler::rotation::{Euler, rotation_vector_from_quaternion};
use schuler::sim::analytic::{self, Trajectory};
use schuler::sim::imu_model::ImuSimulator;
use schuler::sim::jet::{Jet, JetMat3, JetVec3};
use schuler::sim::sensor_spec::{ImuSpec, Preset};

const DEG_PER_H: f64 = std::f64::consts::PI / 180.0 / 3600.0;

fn navigation_grade() -> ImuModel {
    let spec = ImuSpec::of_preset(100.0, Preset::Navigation);
    spec.model().expect("the navigation preset resolves")
}

/// Navigation-grade noise and instability, with fixed biases instead of turn-on
/// draws so that the limits are known numbers.
fn fixed_bias_model(gyro: Vector3<f64>, accel: Vector3<f64>) -> ImuModel {
    let mut m = navigation_grade();
    m.gyro.turn_on = Vector3::zeros();
    m.accel.turn_on = Vector3::zeros();
    m.gyro.bias = gyro;
    m.accel.bias = accel;
    m.gyro.scale = Vector3::zeros();
    m.accel.scale = Vector3::zeros();
    m
}

fn stationary(
    pos: Geodetic,
    att: Euler,
    hz: f64,
    seconds: f64,
    model: ImuModel,
    seed: u64,
) -> Vec<ImuSample> {
    let c_nb = att.to_dcm().transpose();
    let w_b = c_nb * Wgs84.w_ie_n(pos.lat);
    let f_b = -(c_nb * Wgs84.gravity_n(pos.lat, pos.h));
    let dt = 1.0 / hz;
    let mut sim = ImuSimulator::new(model, seed);
    (1..=(seconds * hz).round() as usize)
        .map(|k| sim.measure(&ImuSample::from_mean_rates(k as f64 * dt, dt, w_b, f_b)))
        .collect()
}

/// Attitude error `ψ` (NED) of an estimate against the truth: `Ĉ Cᵀ = I − ψ×`.
fn psi(estimate: &NavState, truth: Euler) -> Vector3<f64> {
    -rotation_vector_from_quaternion(&(estimate.q_bn * truth.to_quaternion().inverse()))
}

fn euler_errors(estimate: &NavState, truth: Euler) -> Vector3<f64> {
    let e = estimate.euler();
    let wrap = |a: f64| {
        (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    Vector3::new(
        wrap(e.roll - truth.roll),
        wrap(e.pitch - truth.pitch),
        wrap(e.yaw - truth.yaw),
    )
}

#[test]
fn perfect_sensors_align_exactly() {
    let pos = Geodetic::from_degrees(45.0, 10.0, 200.0);
    let att = Euler::from_degrees(1.5, -2.0, 210.0);
    let data = stationary(pos, att, 100.0, 860.0, ImuModel::default(), 1);
    let noise = ImuNoise::from_model(&navigation_grade());
    let a = align(Wgs84, pos, &data, &noise, &AlignConfig::default()).unwrap();
    // Exact data: only round-off of 67 000 mechanization steps remains.
    assert!(psi(&a.coarse_state(), att).norm() < 1e-12);
    assert!(psi(&a.state, att).norm() < 1e-9, "{}", psi(&a.state, att));
    assert!((a.t_end - 860.0).abs() < 1e-9 && (a.t_coarse - 190.0).abs() < 1e-9);
    assert!(a.spikes.is_empty() && !a.motion.angular_motion && !a.motion.vibration);
}

trait CoarseState {
    fn coarse_state(&self) -> NavState;
}

impl CoarseState for Alignment {
    fn coarse_state(&self) -> NavState {
        NavState {
            t: self.t_coarse,
            pos: self.state.pos,
            v_n: Vector3::zeros(),
            q_bn: self.coarse.q_bn,
        }
    }
}

/// The signed closed-form errors of gyrocompassing with biases `ε`, `b` (NED):
/// `ψ = [b_E/g, −b_N/g, ε_E/(Ω cos φ) − tan φ b_E/g]`, and the one-sigma scatter about
/// it from white noise over `T` and the bias instability.
struct Theory {
    psi: Vector3<f64>,
    sigma: Vector3<f64>,
}

fn theory(lat: f64, att: Euler, m: &ImuModel, seconds: f64) -> Theory {
    let c_bn = att.to_dcm();
    let eps = c_bn * m.gyro.bias;
    let b = c_bn * m.accel.bias;
    let g = Wgs84.gravity_n(lat, 0.0).norm();
    let wh = Wgs84.rotation_rate() * lat.cos();
    let level = ((m.accel.white.x / (g * seconds.sqrt())).powi(2)
        + (m.accel.gm_sigma.x / g).powi(2))
    .sqrt();
    let heading = ((m.gyro.white.x / (wh * seconds.sqrt())).powi(2)
        + (m.gyro.gm_sigma.x / wh).powi(2))
    .sqrt();
    Theory {
        psi: Vector3::new(b.y / g, -b.x / g, eps.y / wh - lat.tan() * b.y / g),
        sigma: Vector3::new(level, level, heading),
    }
}

#[test]
fn level_and_heading_meet_their_limits_at_30_60_70_80_degrees() {
    // Heading 135 deg puts the gyro biases' full 0.014 deg/h on east.
    let att = Euler::from_degrees(0.8, -1.2, 135.0);
    let model = fixed_bias_model(
        Vector3::new(0.01, -0.01, 0.01) * DEG_PER_H,
        Vector3::new(50e-6, -50e-6, 50e-6) * 9.80665,
    );
    let arcsec = 180.0 / std::f64::consts::PI * 3600.0;
    println!("lat | level err, theory [arcsec] | heading coarse, fine, theory ± sigma [deg]");
    for (i, lat_deg) in [30.0, 60.0, 70.0, 80.0].into_iter().enumerate() {
        let pos = Geodetic::from_degrees(lat_deg, 20.0, 50.0);
        let data = stationary(pos, att, 100.0, 860.0, model.clone(), 100 + i as u64);
        let noise = ImuNoise::from_model(&navigation_grade());
        let a = align(Wgs84, pos, &data, &noise, &AlignConfig::default()).unwrap();
        let fine = psi(&a.state, att);
        let coarse = psi(&a.coarse_state(), att);
        let th = theory(pos.lat, att, &model, 860.0);
        println!(
            "{lat_deg:3} | {:.2}, {:.2} | {:.4}, {:.4}, {:.4} ± {:.4}",
            fine.xy().norm() * arcsec,
            th.psi.xy().norm() * arcsec,
            coarse.z.to_degrees(),
            fine.z.to_degrees(),
            th.psi.z.to_degrees(),
            th.sigma.z.to_degrees()
        );
        // The bounds: within 1.5x of the theoretical limit (bias part plus the
        // noise and instability terms).
        let level_limit = th.psi.xy().norm() + th.sigma.x;
        let heading_limit = th.psi.z.abs() + th.sigma.z;
        assert!(
            fine.xy().norm() <= 1.5 * level_limit,
            "{lat_deg}: level {fine}"
        );
        assert!(
            fine.z.abs() <= 1.5 * heading_limit,
            "{lat_deg}: heading {fine}"
        );
        // And the errors are the theory's, sign included, within 3 sigma of the
        // random terms: no stationary alignment separates the east gyro bias from
        // heading, or the horizontal accelerometer biases from tilt.
        for k in 0..3 {
            assert!(
                (fine[k] - th.psi[k]).abs() <= 3.0 * th.sigma[k],
                "{lat_deg}: axis {k}: {} vs theory {} ± {}",
                fine[k],
                th.psi[k],
                th.sigma[k]
            );
        }
    }
}

#[test]
fn reported_standard_deviations_match_the_errors_over_50_runs() {
    let pos = Geodetic::from_degrees(60.0, 25.0, 0.0);
    let model = navigation_grade();
    let noise = ImuNoise::from_model(&model);
    let mut sum_sq = Vector3::zeros();
    let runs = 50;
    for run in 0..runs {
        let att = Euler::from_degrees(
            0.5 * (run % 5) as f64,
            -0.3 * (run % 3) as f64,
            7.3 * run as f64,
        );
        let data = stationary(pos, att, 50.0, 860.0, model.clone(), 1000 + run);
        let a = align(Wgs84, pos, &data, &noise, &AlignConfig::default()).unwrap();
        let e = euler_errors(&a.state, att);
        sum_sq += e.component_div(&a.attitude_std).map(|x| x * x);
    }
    let ms = sum_sq / runs as f64;
    println!("mean squared normalized errors roll, pitch, yaw: {ms}");
    for i in 0..3 {
        assert!((0.5..=2.0).contains(&ms[i]), "axis {i}: {ms}");
    }
}

#[test]
fn fine_alignment_beats_coarse_in_one_hour_of_free_inertial_navigation() {
    let pos = Geodetic::from_degrees(60.0, 25.0, 0.0);
    let att = Euler::from_degrees(0.5, 0.7, 300.0);
    let model = navigation_grade();
    let noise = ImuNoise::from_model(&model);
    let data = stationary(pos, att, 50.0, 860.0 + 3600.0, model, 7);
    let a = align(Wgs84, pos, &data, &noise, &AlignConfig::default()).unwrap();
    let drift = |start: NavState, bias: (Vector3<f64>, Vector3<f64>)| {
        let mut nav = LocalLevel::new(Wgs84, start);
        let mut worst: f64 = 0.0;
        for s in data
            .iter()
            .filter(|s| s.t > start.t + 1e-9 && s.t <= start.t + 3600.0 + 1e-9)
        {
            let c = ImuSample {
                dtheta: s.dtheta - bias.0 * s.dt,
                dvel: s.dvel - bias.1 * s.dt,
                ..*s
            };
            nav.step(&c);
            let s = nav.state();
            let at_rest = NavState { pos, ..s };
            worst = worst.max(errors_between(&Wgs84, &s, &at_rest).horizontal());
        }
        worst
    };
    let coarse = drift(a.coarse_state(), (Vector3::zeros(), Vector3::zeros()));
    let fine = drift(a.state, (a.gyro_bias, a.accel_bias));
    println!("max horizontal error in 1 h: after coarse {coarse:.0} m, after fine {fine:.0} m");
    assert!(fine < coarse, "fine {fine} m vs coarse {coarse} m");
}

#[test]
fn rotor_vibration_and_a_spike_burst_do_not_spoil_the_alignment() {
    let pos = Geodetic::from_degrees(70.0, 30.0, 10.0);
    let att = Euler::from_degrees(1.0, 2.0, 100.0);
    let model = fixed_bias_model(
        Vector3::new(0.01, 0.01, -0.01) * DEG_PER_H,
        Vector3::new(-50e-6, 50e-6, 50e-6) * 9.80665,
    );
    let noise = ImuNoise::from_model(&navigation_grade());
    let calm = stationary(pos, att, 1000.0, 860.0, model.clone(), 11);
    let mut shaking = model.clone();
    shaking.vibration = vec![VibrationLine {
        freq_hz: 23.7,
        amplitude: Vector3::new(0.2, 0.2, 0.5) * 9.80665,
        phase: 0.3,
    }];
    let mut rough = stationary(pos, att, 1000.0, 860.0, shaking, 11);
    for s in &mut rough[400_000..400_010] {
        s.dtheta.x += 1e-3;
    }
    let cfg = AlignConfig::default();
    let a_calm = align(Wgs84, pos, &calm, &noise, &cfg).unwrap();
    let a_rough = align(Wgs84, pos, &rough, &noise, &cfg).unwrap();
    assert_eq!(a_rough.spikes.len(), 10);
    assert!(a_rough.motion.vibration && !a_calm.motion.vibration);
    let (e0, e1) = (psi(&a_calm.state, att), psi(&a_rough.state, att));
    println!(
        "psi calm {:?}, vibrating {:?} [rad]",
        e0.as_slice(),
        e1.as_slice()
    );
    assert!(e1.xy().norm() <= 1.2 * e0.xy().norm(), "level {e0} -> {e1}");
    assert!(e1.z.abs() <= 1.2 * e0.z.abs(), "heading {e0} -> {e1}");
}

/// A vehicle parked in gusty wind: roll and pitch rock about the IMU by `amplitude`
/// at two incommensurate frequencies (0.4 and 0.27 Hz).
struct Rocking {
    pos: Geodetic,
    att: Euler,
    amplitude: f64,
}

impl Trajectory for Rocking {
    fn position(&self, _t: Jet) -> JetVec3 {
        [self.pos.lat, self.pos.lon, self.pos.h].map(Jet::constant)
    }
    fn c_bn(&self, t: Jet) -> JetMat3 {
        let w1 = std::f64::consts::TAU * 0.4;
        let w2 = std::f64::consts::TAU * 0.27;
        JetMat3::from_euler(
            (t * w1 + 0.3).sin() * self.amplitude + self.att.roll,
            (t * w2).sin() * self.amplitude + self.att.pitch,
            Jet::constant(self.att.yaw),
        )
    }
}

#[test]
fn a_rocking_base_is_detected_and_still_aligns_within_the_reported_accuracy() {
    let pos = Geodetic::from_degrees(60.0, 30.0, 10.0);
    let att = Euler::from_degrees(0.5, -0.5, 200.0);
    let model = navigation_grade();
    let noise = ImuNoise::from_model(&model);
    let traj = Rocking {
        pos,
        att,
        amplitude: 0.05f64.to_radians(),
    };
    let mut sim = ImuSimulator::new(model, 21);
    let data: Vec<ImuSample> = analytic::samples(&Wgs84, &traj, 0.0, 0.01, 86_000)
        .map(|s| sim.measure(&s))
        .collect();
    let a = align(Wgs84, pos, &data, &noise, &AlignConfig::default()).unwrap();
    assert!(a.motion.angular_motion, "{:?}", a.motion);
    let truth = analytic::state(&Wgs84, &traj, a.t_end);
    let e = -rotation_vector_from_quaternion(&(a.state.q_bn * truth.q_bn.inverse()));
    let c_end = analytic::state(&Wgs84, &traj, a.t_coarse);
    let ec = -rotation_vector_from_quaternion(&(a.coarse.q_bn * c_end.q_bn.inverse()));
    println!(
        "rocking: coarse heading {:.4} deg (std {:.4}), fine {:.4} deg (std {:.4}), level {:.2e} rad",
        ec.z.to_degrees(),
        a.coarse_std.z.to_degrees(),
        e.z.to_degrees(),
        a.attitude_std.z.to_degrees(),
        e.xy().norm()
    );
    // Each error within 3 reported sigma: the filter knows what the motion costs.
    let eu = euler_errors(&a.state, truth.euler());
    for i in 0..3 {
        assert!(
            eu[i].abs() < 3.0 * a.attitude_std[i],
            "axis {i}: {eu} vs {}",
            a.attitude_std
        );
    }
    assert!(
        ec.z.abs() < 3.0 * a.coarse_std.z,
        "coarse {ec} vs {}",
        a.coarse_std
    );
}

#[test]
fn near_the_pole_gyrocompassing_is_refused_with_advice() {
    let model = navigation_grade();
    let noise = ImuNoise::from_model(&model);
    let att = Euler::from_degrees(0.0, 0.0, 0.0);
    for lat in [89.7, 90.0] {
        let pos = Geodetic::from_degrees(lat, 0.0, 0.0);
        let data = stationary(pos, att, 50.0, 860.0, model.clone(), 3);
        let err = align(Wgs84, pos, &data, &noise, &AlignConfig::default()).unwrap_err();
        let msg = err.to_string();
        assert!(
            matches!(err, AlignError::HeadingUnobservable { .. }),
            "{msg}"
        );
        assert!(msg.contains("--heading") && msg.contains("GNSS"), "{msg}");
        // An external heading still levels.
        let cfg = AlignConfig {
            heading: HeadingSource::External {
                yaw: 0.0,
                std: 1e-3,
            },
            ..AlignConfig::default()
        };
        let a = align(Wgs84, pos, &data, &noise, &cfg).unwrap();
        assert!(psi(&a.state, att).xy().norm() < 2e-4);
    }
    let short = stationary(
        Geodetic::from_degrees(45.0, 0.0, 0.0),
        att,
        50.0,
        100.0,
        model,
        3,
    );
    let err = align(
        Wgs84,
        Geodetic::from_degrees(45.0, 0.0, 0.0),
        &short,
        &noise,
        &AlignConfig::default(),
    );
    assert!(matches!(err, Err(AlignError::NotEnoughData { .. })));
}
