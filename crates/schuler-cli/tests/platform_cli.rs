//! `schuler platform` through the binary: every file the issue names (one plot per
//! error quantity with all six systems, the table at 1 h or at the end of a shorter
//! run), the textbook's leveling result in the table, the example config, and config
//! errors that name the key.

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn run(config: &Path, out: &Path) -> assert_cmd::assert::Assert {
    Command::cargo_bin("schuler")
        .expect("binary")
        .arg("platform")
        .arg("--config")
        .arg(config)
        .arg("--out")
        .arg(out)
        .assert()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write config");
    p
}

/// At rest on the non-rotating textbook sphere, leveled, biases only: every platform
/// mechanization and the analytic INS stay at zero error (the tilt cancels the bias,
/// SEEDS.md (24)), as does the SINS while it does not turn; 20 min, so the table is
/// at the end.
const REST: &str = r#"
earth = "sphere-fixed"
duration = "20 min"
step = "1 s"
imu_rate_hz = 20
output_interval = "20 s"
[start]
position = ["30 deg", "0 deg", "0 m"]
attitude = ["0 deg", "0 deg", "45 deg"]
[[motion]]
type = "hold"
duration = "1300 s"
[errors]
accel_bias = ["1e-3 m/s^2", "-1e-3 m/s^2", "5e-4 m/s^2"]
[gyro_free]
accel_bias = ["1e-9 m/s^2", "0 m/s^2", "0 m/s^2", "0 m/s^2", "0 m/s^2", "0 m/s^2"]
"#;

#[test]
fn writes_every_file_and_the_leveled_systems_stay_at_zero() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = write(dir.path(), "rest.toml", REST);
    let out = dir.path().join("run");
    run(&cfg, &out)
        .success()
        .stdout(predicate::str::contains("| free-azimuth |"));
    let systems = [
        "sins",
        "geographic",
        "orthodromic",
        "free-azimuth",
        "analytic",
        "gyro-free",
    ];
    let csv = std::fs::read_to_string(out.join("errors.csv")).expect("errors.csv");
    let header = csv.lines().next().expect("header");
    assert!(header.starts_with("t,sins_north,sins_east,sins_down,sins_vn"));
    assert_eq!(header.split(',').count(), 1 + 9 * 6);
    assert_eq!(csv.lines().count(), 1 + 61, "epochs every 20 s over 20 min");
    for plot in [
        "north",
        "east",
        "horizontal",
        "height",
        "v_north",
        "v_east",
        "v_down",
        "tilt_north",
        "tilt_east",
        "heading",
    ] {
        let svg = std::fs::read_to_string(out.join(format!("{plot}.svg"))).expect("svg");
        assert!(svg.starts_with("<svg"));
        for s in systems {
            assert!(svg.contains(s), "{plot}.svg lacks {s}");
        }
    }
    let md = std::fs::read_to_string(out.join("table.md")).expect("table.md");
    assert!(md.starts_with("Errors at t = 1200 s (0.333 h after the start)"));
    let s: Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("summary.json")).expect("summary.json"),
    )
    .expect("JSON");
    assert_eq!(s["table_t_s"], 1200.0);
    let table = s["table"].as_array().expect("table");
    assert_eq!(table.len(), 6);
    for row in table {
        let name = row["system"].as_str().expect("name");
        let h = row["horizontal_m"].as_f64().expect("number");
        if name == "gyro-free" {
            // 1e-9 m/s^2 on the cube's +x accelerometer (rho = 0.5 m): angular
            // acceleration d/(2 sqrt2 rho) = 7.07e-10 rad/s^2 about the (level) body y
            // axis (and as much about down); the growth law of lab::platform::gyro_free,
            // (g eps/w0^2)(t^2/2 - (1 - cos w0 t)/w0^2), gives 561 m at 20 min.
            let (g, a, t) = (9.81f64, 6.371e6f64, 1200.0f64);
            let w0 = (g / a).sqrt();
            let eps = 1e-9 / (2.0 * 2f64.sqrt() * 0.5);
            let law = g * eps / (w0 * w0) * (t * t / 2.0 - (1.0 - (w0 * t).cos()) / (w0 * w0));
            assert!((h / law - 1.0).abs() < 0.02, "{name}: {h} vs {law}");
        } else {
            assert!(h < 1e-4, "{name}: {h}");
        }
    }
}

/// The example in examples/ runs as documented (shortened to 2 min here).
#[test]
fn example_config_runs() {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/platform.toml");
    let text = std::fs::read_to_string(&example).expect("example");
    assert!(text.contains("duration = \"1 h\""));
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = write(
        dir.path(),
        "short.toml",
        &text.replace("duration = \"1 h\"", "duration = \"2 min\""),
    );
    run(&cfg, &dir.path().join("run"))
        .success()
        .stdout(predicate::str::contains("| gyro-free |"));
}

/// The simulator's IMU model: a navigation-grade `[imu]` with a seed runs, is
/// recorded in the summary, and conflicts with a second SINS rate.
#[test]
fn imu_model_from_a_scenario_table() {
    let dir = tempfile::tempdir().expect("tempdir");
    let with_imu = REST.replace("imu_rate_hz = 20\n", "seed = 3\n")
        + "[imu]\nrate_hz = 20\npreset = \"navigation\"\n";
    let cfg = write(dir.path(), "imu.toml", &with_imu);
    let out = dir.path().join("run");
    run(&cfg, &out).success();
    let s: Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("summary.json")).expect("summary.json"),
    )
    .expect("JSON");
    assert_eq!(s["inputs"]["imu_model"], true);
    assert_eq!(s["inputs"]["seed"], 3);
    let both = write(
        dir.path(),
        "both.toml",
        &(REST.to_owned() + "[imu]\nrate_hz = 20\n"),
    );
    run(&both, &dir.path().join("both"))
        .failure()
        .stderr(predicate::str::contains("imu_rate_hz"));
}

/// Bad configs fail with the key and the reason, never a panic.
#[test]
fn config_errors_name_the_key() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases: [(&str, &str, &str); 7] = [
        (
            "accel_bias = [\"1e-3 m/s^2\"",
            "accel_bias = [\"1e-3 deg\"",
            "errors.accel_bias[0]",
        ),
        ("step = \"1 s\"", "step = \"7 s\"", "step"),
        ("step = \"1 s\"", "step = \"-1 s\"", "step"),
        ("duration = \"20 min\"", "duration = \"2 h\"", "duration"),
        (
            "imu_rate_hz = 20",
            "imu_rate_hz = 20\nsystems = [\"sins\", \"gimbal\"]",
            "systems[1]",
        ),
        ("imu_rate_hz = 20", "imu_rate_hz = 20\nbogus = 1", "bogus"),
        (
            "[gyro_free]",
            "[gyro_free]\nbaseline = \"0 m\"",
            "gyro_free.baseline",
        ),
    ];
    for (i, (from, to, key)) in cases.iter().enumerate() {
        assert!(REST.contains(from), "{from}");
        let cfg = write(dir.path(), &format!("bad{i}.toml"), &REST.replace(from, to));
        run(&cfg, &dir.path().join(format!("out{i}")))
            .failure()
            .stderr(predicate::str::contains(*key))
            .stderr(predicate::str::contains("panicked").not());
    }
}
