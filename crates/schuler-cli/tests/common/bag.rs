//! Helpers of the ROS 2 bag tests: the committed bag and its scenario
//! (`tests/data/ros2_bag/`), the text logs of the same simulation, the two runs of
//! `schuler nav` and the comparison of their trajectories.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// `tests/data/ros2_bag/`: `scenario.toml` and `drive.mcap`.
pub fn data() -> PathBuf {
    super::test_data("ros2_bag")
}

/// `schuler simulate` of the bag's scenario into `dir/sim`, with `odometer.txt`
/// beside its files: truth.nav's speed at every multiple of 0.1 s, as
/// `scripts/write_test_bag.py --odometer-rate 10` puts it in the bag.
pub fn simulate_scenario(dir: &Path) -> PathBuf {
    let sim = super::simulate(&data().join("scenario.toml"), dir);
    write_odometer(&sim, 10.0);
    sim
}

/// `sim/odometer.txt` from `sim/truth.nav` at `rate_hz` (the script's rule: times
/// within 1e-6 of a period's multiple; speed `sqrt(vn² + ve² + vd²)` evaluated in the
/// same order, so the same bits).
pub fn write_odometer(sim: &Path, rate_hz: f64) {
    let mut text = String::new();
    for r in super::read_rows(&sim.join("truth.nav")) {
        let (t, vn, ve, vd) = (r[1], r[5], r[6], r[7]);
        if (t * rate_hz - (t * rate_hz).round()).abs() > 1e-6 {
            continue;
        }
        writeln!(text, "{t} {}", (vn * vn + ve * ve + vd * vd).sqrt()).expect("string");
    }
    std::fs::write(sim.join("odometer.txt"), text).expect("odometer.txt");
}

/// The flags both runs share: the scenario's start, lever arm, IMU grade, 10-Hz
/// output, no HTML report.
pub const COMMON: [&str; 13] = [
    "--init-pos",
    "45.07,7.68,245",
    "--init-att",
    "0,0,10",
    "--lever-arm",
    "0.5,0,-1",
    "--imu-grade",
    "tactical",
    "--output-rate",
    "10",
    "--no-report",
    "--odometer-std",
    "0.05",
];

/// `schuler nav` on the text logs of `sim` (IMU, GNSS with velocity, barometer,
/// odometer) into `out`.
pub fn nav_text(sim: &Path, out: &Path) -> assert_cmd::assert::Assert {
    nav_text_with(sim, out, &[])
}

/// [`nav_text`] with `extra` flags after [`COMMON`].
pub fn nav_text_with(sim: &Path, out: &Path, extra: &[&str]) -> assert_cmd::assert::Assert {
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .arg("nav")
        .arg("--imu")
        .arg(sim.join("imu.txt"))
        .arg("--gnss")
        .arg(sim.join("gnss.txt"))
        .arg("--gnss-vel")
        .arg(sim.join("gnss.csv"))
        .arg("--baro")
        .arg(sim.join("baro.csv"))
        .arg("--odometer")
        .arg(sim.join("odometer.txt"))
        .args(COMMON)
        .args(extra)
        .arg("--out")
        .arg(out)
        .assert()
}

/// `schuler nav --bag bag` with `extra` flags into `out`.
pub fn nav_bag(bag: &Path, out: &Path, extra: &[&str]) -> assert_cmd::assert::Assert {
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .arg("nav")
        .arg("--bag")
        .arg(bag)
        .args(COMMON)
        .args(extra)
        .arg("--out")
        .arg(out)
        .assert()
}

/// One unit of the last digit nav.txt prints, per column (week, time 1 µs,
/// latitude and longitude 1e-11 deg, height 1 µm, velocity 1 µm/s, attitude 1e-9
/// deg).
pub const LAST_DIGIT: [f64; 11] = [
    0.0, 1e-6, 1e-11, 1e-11, 1e-6, 1e-6, 1e-6, 1e-6, 1e-9, 1e-9, 1e-9,
];

/// The largest difference between two nav.txt files in units of [`LAST_DIGIT`]
/// (asserting the same epochs); a value of at most 1 means the two trajectories
/// differ only where a rounding boundary falls between them.
pub fn max_digits_apart(a: &Path, b: &Path) -> f64 {
    let (ra, rb) = (super::read_rows(a), super::read_rows(b));
    assert_eq!(
        ra.len(),
        rb.len(),
        "{} and {}: epochs",
        a.display(),
        b.display()
    );
    assert!(ra.len() > 100, "{}: only {} epochs", a.display(), ra.len());
    let mut worst: f64 = 0.0;
    for (x, y) in ra.iter().zip(&rb) {
        for (c, unit) in LAST_DIGIT.iter().enumerate() {
            let d = (x[c] - y[c]).abs();
            if *unit == 0.0 {
                assert_eq!(d, 0.0, "column {c} at t = {}", x[1]);
            } else {
                // The parse of a printed decimal is within 1e-15 relative of it.
                worst = worst.max((d - 2e-15 * x[c].abs()).max(0.0) / unit);
            }
        }
    }
    worst
}
