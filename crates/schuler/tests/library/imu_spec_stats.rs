//! The error terms written in engineering units in a scenario's `[imu]` table reach
//! the simulated increments with their defining statistics (issue 3): rate and
//! acceleration random walk through their Allan deviation, gyro g-sensitivity
//! exactly. Tolerances are several standard deviations of the estimator for the run
//! length, stated per test.

use nalgebra::Vector3;
use schuler::analysis::allan::allan_deviation;
use schuler::imu::ImuSample;
use schuler::imu::model::ImuModel;
use schuler::sim::imu_model::ImuSimulator;
use schuler::sim::sensor_spec::ImuSpec;
use schuler::units::{DEG_PER_H_PER_G, DEG_PER_H_PER_SQRT_H, UG};

fn model(toml_text: &str) -> ImuModel {
    let spec: ImuSpec = toml::from_str(toml_text).expect("imu spec");
    spec.model().expect("model")
}

/// The x-axis errors (gyro, accelerometer) of a stationary zero-input IMU at 1 Hz.
fn x_errors(model: ImuModel, seed: u64, n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut sim = ImuSimulator::new(model, seed);
    (1..=n)
        .map(|k| {
            let s = ImuSample {
                t: k as f64,
                dt: 1.0,
                dtheta: Vector3::zeros(),
                dvel: Vector3::zeros(),
            };
            let y = sim.measure(&s);
            (y.dtheta.x, y.dvel.x)
        })
        .unzip()
}

/// Random walk coefficient K: the Allan deviation is K sqrt(tau/3) (IEEE Std 952
/// annex C), slope +1/2. Over 1e6 s at 1 Hz the overlapping estimator's relative
/// spread is about 3 % at tau = 100 s and 9 % at 1000 s: 15 % and a slope within
/// 0.1 are over three sigma.
fn check_random_walk(x: &[f64], k: f64, what: &str) {
    let s100 = allan_deviation(x, 1.0, 100).expect("enough data");
    let s1000 = allan_deviation(x, 1.0, 1000).expect("enough data");
    let expected = k * (100.0f64 / 3.0).sqrt();
    let slope = (s1000 / s100).log10();
    eprintln!(
        "{what}: sigma(100 s)/K sqrt(tau/3) = {:.4}, slope {slope:.3}",
        s100 / expected
    );
    assert!((s100 / expected - 1.0).abs() < 0.15, "{what}");
    assert!((slope - 0.5).abs() < 0.1, "{what}: slope {slope}");
}

/// `rate_random_walk = "0.5 deg/h/sqrt(h)"` is K = 0.5 deg/h/sqrt(h) = 4.04e-8
/// rad/s/sqrt(s), and the simulated gyro shows it.
#[test]
fn rate_random_walk_in_engineering_units() {
    let m = model("rate_hz = 1\n[gyro]\nrate_random_walk = \"0.5 deg/h/sqrt(h)\"\n");
    let k = 0.5 * DEG_PER_H_PER_SQRT_H;
    assert_eq!(m.gyro.random_walk, Vector3::new(k, k, k));
    assert_eq!(m.accel.random_walk, Vector3::zeros());
    let (gyro, accel) = x_errors(m, 21, 1_000_000);
    check_random_walk(&gyro, k, "rate random walk");
    assert!(accel.iter().all(|&a| a == 0.0));
}

/// `acceleration_random_walk = "20 ug/sqrt(h)"` is K = 20 ug/sqrt(h) = 3.27e-6
/// m/s^2/sqrt(s), per axis as written, and the simulated accelerometer shows it.
#[test]
fn acceleration_random_walk_in_engineering_units() {
    let m = model(
        "rate_hz = 1\n[accel]\nacceleration_random_walk = \
         [\"20 ug/sqrt(h)\", \"0 ug/sqrt(h)\", \"1e-5 m/s^2/sqrt(s)\"]\n",
    );
    let k = 20.0 * UG / 60.0;
    assert_eq!(m.accel.random_walk, Vector3::new(k, 0.0, 1e-5));
    let (gyro, accel) = x_errors(m, 22, 1_000_000);
    check_random_walk(&accel, k, "acceleration random walk");
    assert!(gyro.iter().all(|&g| g == 0.0));
}

/// `g_sensitivity = ["2 deg/h/g", "0 deg/h/g", "1 deg/s/g"]`: each gyro's output grows
/// by exactly G times the velocity increment along its own axis, nothing else.
#[test]
fn g_sensitivity_in_engineering_units_is_exact() {
    let m = model("rate_hz = 100\ng_sensitivity = [\"2 deg/h/g\", \"0 deg/h/g\", \"1 deg/s/g\"]\n");
    let g = Vector3::new(
        2.0 * DEG_PER_H_PER_G,
        0.0,
        1f64.to_radians() / schuler::units::G0,
    );
    assert_eq!(m.g_sensitivity.diagonal(), g);
    let mut sim = ImuSimulator::new(m, 1);
    let truth = ImuSample {
        t: 1.0,
        dt: 0.01,
        dtheta: Vector3::new(1e-4, -2e-4, 3e-4),
        dvel: Vector3::new(0.5, -0.2, -0.098),
    };
    let y = sim.measure(&truth);
    assert_eq!(y.dtheta, truth.dtheta + g.component_mul(&truth.dvel));
    assert_eq!(y.dvel, truth.dvel);
}

/// Units of the wrong kind name the key and the dimension expected.
#[test]
fn wrong_units_name_the_key() {
    let err = |text: &str| {
        toml::from_str::<ImuSpec>(text)
            .expect("toml")
            .model()
            .expect_err("wrong unit")
            .to_string()
    };
    let e = err("rate_hz = 1\n[gyro]\nrate_random_walk = \"0.5 deg/sqrt(h)\"\n");
    assert!(
        e.starts_with("imu.gyro.bias_random_walk: expected a rate random walk"),
        "{e}"
    );
    let e = err("rate_hz = 1\n[accel]\nacceleration_random_walk = \"20 ug/sqrt(Hz)\"\n");
    assert!(
        e.starts_with("imu.accel.bias_random_walk: expected an acceleration random walk"),
        "{e}"
    );
    let e = err("rate_hz = 1\ng_sensitivity = \"2 deg/h\"\n");
    assert!(
        e.starts_with("imu.g_sensitivity: expected a g-sensitivity"),
        "{e}"
    );
    let e = err("rate_hz = 1\ng_sensitivity = [1e-6, 0, 0]\n");
    assert!(e.contains("has no unit"), "{e}");
}
