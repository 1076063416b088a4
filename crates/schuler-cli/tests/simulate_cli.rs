//! `schuler simulate` end to end: perfect sensors round-trip through `schuler nav`,
//! same seed gives the same bytes, bad scenarios name the key.

use crate::common;

use assert_cmd::Command;
use predicates::prelude::*;
use std::path::Path;

const START: &str = r#"
[start]
position = ["30.5 deg", "114.3 deg", "500 m"]
attitude = ["0 deg", "0 deg", "45 deg"]
speed = "0 m/s"
"#;

/// 30 minutes of maneuvers: accelerate, coordinated turns both ways, climbs and
/// descents, a full roll, holds.
const MANEUVERS: &str = r#"
[[motion]]
type = "hold"
duration = "30 s"
[[motion]]
type = "accelerate"
to_speed = "60 m/s"
accel = "2 m/s^2"
[[motion]]
type = "turn"
angle = "120 deg"
bank = "25 deg"
[[motion]]
type = "climb"
to_height = "1500 m"
pitch = "6 deg"
[[motion]]
type = "turn"
angle = "-200 deg"
rate = "3 deg/s"
[[motion]]
type = "roll"
duration = "8 s"
[[motion]]
type = "hold"
duration = "300 s"
[[motion]]
type = "climb"
to_height = "800 m"
pitch = "4 deg"
[[motion]]
type = "turn"
angle = "360 deg"
bank = "30 deg"
[[motion]]
type = "rates"
duration = "60 s"
euler_rates = ["0 deg/s", "0 deg/s", "-1 deg/s"]
accel = ["-0.5 m/s^2", "0 m/s^2", "0 m/s^2"]
[[motion]]
type = "hold"
duration = "900 s"
"#;

fn scenario(dir: &Path, name: &str, body: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, body).expect("write scenario");
    p
}

fn schuler() -> Command {
    Command::cargo_bin("schuler").expect("binary")
}

/// Largest horizontal distance [m] between nav.txt and truth.nav epochs of equal time
/// (both KF-GINS format, 200 Hz).
fn max_horizontal_error(nav: &Path, truth: &Path) -> (f64, usize) {
    let truth: std::collections::HashMap<i64, Vec<f64>> = common::read_rows(truth)
        .into_iter()
        .map(|r| ((r[1] * 200.0).round() as i64, r))
        .collect();
    let (mut worst, mut n) = (0.0f64, 0);
    for r in common::read_rows(nav) {
        let t = &truth[&((r[1] * 200.0).round() as i64)];
        let lat = t[2].to_radians();
        // Spherical radius is enough to turn a sub-metre difference into metres.
        let dn = (r[2] - t[2]).to_radians() * 6.37e6;
        let de = (r[3] - t[3]).to_radians() * 6.37e6 * lat.cos();
        worst = worst.max(dn.hypot(de));
        n += 1;
    }
    (worst, n)
}

/// Perfect sensors: free-inertial navigation of the simulated IMU reproduces the
/// simulated truth within 0.05 m horizontally after 30 min of maneuvers at 200 Hz (the
/// issue's bound). What remains is the mechanization's own error (micrometres on exact
/// analytic trajectories) and round-off in the simulator's spline (measured: 0.3 mm).
#[test]
fn perfect_sensors_round_trip_through_nav() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = scenario(
        dir.path(),
        "perfect.toml",
        &format!("seed = 1\n{START}{MANEUVERS}\n[imu]\nrate_hz = 200\npreset = \"perfect\"\n"),
    );
    let out = dir.path().join("sim");
    schuler()
        .args(["simulate", "--config"])
        .arg(&cfg)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let truth0 = std::fs::read_to_string(out.join("truth.nav")).expect("truth");
    let first: Vec<f64> = truth0
        .lines()
        .next()
        .expect("a line")
        .split_whitespace()
        .map(|x| x.parse().expect("number"))
        .collect();
    let t_end: f64 = truth0
        .lines()
        .last()
        .and_then(|l| l.split_whitespace().nth(1))
        .expect("last time")
        .parse()
        .expect("number");
    assert!(
        t_end >= 1800.0,
        "the scenario must last 30 min, lasts {t_end} s"
    );
    schuler()
        .args(["nav", "--imu"])
        .arg(out.join("imu.txt"))
        .arg("--init-pos")
        .arg(format!("{},{},{}", first[2], first[3], first[4]))
        .arg("--init-att")
        .arg(format!("{},{},{}", first[8], first[9], first[10]))
        .args(["--output-rate", "10", "--out"])
        .arg(dir.path().join("nav"))
        .assert()
        .success();
    let (worst, n) = max_horizontal_error(&dir.path().join("nav/nav.txt"), &out.join("truth.nav"));
    eprintln!("round trip: max horizontal error {worst:.3e} m over {n} epochs");
    assert!(n > 18_000);
    assert!(worst < 0.05, "{worst} m");
}

/// The same scenario and seed give the same bytes in every file; another seed does not.
#[test]
fn same_seed_same_bytes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let body = format!(
        "seed = 5\n{START}[[motion]]\ntype = \"hold\"\nduration = \"20 s\"\n[imu]\nrate_hz = 100\npreset = \"tactical\"\n\
         [gnss]\nrate_hz = 1\nposition_std = [\"0.5 m\", \"0.5 m\", \"1 m\"]\n[baro]\nrate_hz = 10\nnoise = \"0.3 m\"\n"
    );
    let cfg = scenario(dir.path(), "s.toml", &body);
    for run in ["a", "b"] {
        schuler()
            .args(["simulate", "--config"])
            .arg(&cfg)
            .arg("--out")
            .arg(dir.path().join(run))
            .assert()
            .success();
    }
    schuler()
        .args(["simulate", "--seed", "6", "--config"])
        .arg(&cfg)
        .arg("--out")
        .arg(dir.path().join("c"))
        .assert()
        .success();
    for f in [
        "imu.txt",
        "imu.csv",
        "truth.nav",
        "truth.csv",
        "gnss.txt",
        "gnss.csv",
        "baro.csv",
        "scenario.resolved.toml",
    ] {
        let a = std::fs::read(dir.path().join("a").join(f)).expect(f);
        let b = std::fs::read(dir.path().join("b").join(f)).expect(f);
        assert_eq!(a, b, "{f} differs between identical runs");
    }
    let a = std::fs::read(dir.path().join("a/imu.txt")).expect("imu");
    let c = std::fs::read(dir.path().join("c/imu.txt")).expect("imu");
    assert_ne!(a, c);
    let resolved =
        std::fs::read_to_string(dir.path().join("a/scenario.resolved.toml")).expect("resolved");
    assert!(
        resolved.contains("seed = 5") && resolved.contains("1 deg/h"),
        "{resolved}"
    );
}

/// Bad scenarios: unknown maneuver, negative duration, a bank that cannot be flown, a
/// unit of the wrong kind; each error names the key and why.
#[test]
fn bad_scenarios_name_the_key() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = "\n[imu]\nrate_hz = 100\n";
    let cases = [
        (
            "[[motion]]\ntype = \"loop\"\nduration = \"3 s\"\n",
            "unknown variant `loop`",
        ),
        (
            "[[motion]]\ntype = \"hold\"\nduration = \"-3 s\"\n",
            "motion[0].duration: duration must be positive",
        ),
        (
            "[[motion]]\ntype = \"accelerate\"\nto_speed = \"50 m/s\"\naccel = \"2 m/s^2\"\n[[motion]]\ntype = \"turn\"\nangle = \"90 deg\"\nbank = \"85 deg\"\n",
            "motion[1].bank: a bank of 85.0 deg cannot be flown",
        ),
        (
            "[[motion]]\ntype = \"hold\"\nduration = \"3 m/s\"\n",
            "motion[0].duration: expected a time, got m/s",
        ),
    ];
    for (i, (motion, expected)) in cases.iter().enumerate() {
        let cfg = scenario(
            dir.path(),
            &format!("bad{i}.toml"),
            &format!("{START}{motion}{imu}"),
        );
        schuler()
            .args(["simulate", "--config"])
            .arg(&cfg)
            .arg("--out")
            .arg(dir.path().join(format!("o{i}")))
            .assert()
            .failure()
            .stderr(predicate::str::contains(*expected))
            .stderr(predicate::str::contains(format!("bad{i}.toml")));
    }
}

/// gnss-ins-sim's own scenario (drive9min's motion.csv) through our motion generator,
/// against gnss-ins-sim's truth: a check of conventions (body axes, Euler rates, yaw
/// sign, body-velocity commands, start time) against a trajectory our code did not
/// make. The residual is gnss-ins-sim's attitude response, which lags its commands by
/// about 0.09 s and ends turns about 0.6 deg short, where we follow the commanded
/// totals: measured 2.5 m horizontal, 0.10 m vertical, 0.6 deg yaw, 0.21 m/s at most.
/// The bounds sit just above those (a convention error, e.g. a yaw sign or a
/// body/NED mix-up, would show hundreds of metres and tens of degrees).
#[test]
fn gnss_ins_sim_motion_file_follows_its_truth() {
    let data = common::test_data("drive9min");
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::copy(data.join("motion.csv"), dir.path().join("motion.csv")).expect("copy");
    let cfg = scenario(
        dir.path(),
        "gis.toml",
        "motion_csv = \"motion.csv\"\n[imu]\nrate_hz = 100\npreset = \"perfect\"\n",
    );
    let out = dir.path().join("out");
    schuler()
        .args(["simulate", "--config"])
        .arg(&cfg)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let truth = common::unxz(&data.join("truth.nav.xz"));
    let parse = |text: &str| -> std::collections::HashMap<i64, Vec<f64>> {
        common::rows(text)
            .into_iter()
            .map(|r| ((r[1] * 100.0).round() as i64, r))
            .collect()
    };
    let theirs = parse(std::str::from_utf8(&truth).expect("utf8"));
    let ours = parse(&std::fs::read_to_string(out.join("truth.nav")).expect("ours"));
    let (mut h, mut v, mut yaw, mut vel, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0);
    for (k, t) in &theirs {
        let Some(r) = ours.get(k) else { continue };
        let lat = t[2].to_radians();
        let dn = (r[2] - t[2]).to_radians() * 6.368e6;
        let de = (r[3] - t[3]).to_radians() * 6.388e6 * lat.cos();
        h = h.max(dn.hypot(de));
        v = v.max((r[4] - t[4]).abs());
        vel = vel.max((5..8).map(|i| (r[i] - t[i]).abs()).fold(0.0, f64::max));
        yaw = yaw.max(((r[10] - t[10] + 180.0).rem_euclid(360.0) - 180.0).abs());
        n += 1;
    }
    eprintln!(
        "vs gnss-ins-sim: {n} epochs, horizontal {h:.3} m, vertical {v:.3} m, yaw {yaw:.3} deg, velocity {vel:.3} m/s"
    );
    assert_eq!(n, 53_000);
    assert!(h < 3.0 && v < 0.15 && yaw < 0.7 && vel < 0.25);
}
