//! `schuler nav` reads GNSS files by what they are: the simulator's `gnss.csv` by its
//! header, giving the very navigation `gnss.txt` gives (the simulator writes the same
//! shortest round-trip numbers into both), its velocities only when it is also named
//! as the velocity log, its outlier flag never; and a position log given as the
//! velocity log is an error naming the file and the line.

use assert_cmd::Command;
use predicates::prelude::*;
use std::path::{Path, PathBuf};

/// Four minutes of a car: at rest, accelerate, turn both ways; a tactical IMU at 100 Hz;
/// GNSS at 1 Hz with velocity noise, a lever arm and one 30-m outlier at 150 s.
const SCENARIO: &str = r#"
seed = 11
[start]
position = ["30.5 deg", "114.3 deg", "50 m"]
attitude = ["0 deg", "0 deg", "30 deg"]
speed = "0 m/s"
[[motion]]
type = "hold"
duration = "30 s"
[[motion]]
type = "accelerate"
to_speed = "15 m/s"
accel = "1 m/s^2"
[[motion]]
type = "turn"
angle = "90 deg"
rate = "3 deg/s"
[[motion]]
type = "hold"
duration = "60 s"
[[motion]]
type = "turn"
angle = "-120 deg"
rate = "3 deg/s"
[[motion]]
type = "hold"
duration = "70 s"
[imu]
rate_hz = 100
preset = "tactical"
[gnss]
rate_hz = 1
position_std = ["0.5 m", "0.5 m", "1 m"]
velocity_std = ["0.05 m/s", "0.05 m/s", "0.1 m/s"]
lever_arm = ["0.5 m", "0 m", "-1 m"]
outliers = [{ at = "150 s", jump = ["30 m", "0 m", "0 m"] }]
"#;

fn schuler() -> Command {
    Command::cargo_bin("schuler").expect("binary")
}

/// `schuler simulate` of `body` into `dir/name`.
fn simulate(dir: &Path, name: &str, body: &str) -> PathBuf {
    let cfg = dir.join(format!("{name}.toml"));
    std::fs::write(&cfg, body).expect("write scenario");
    let out = dir.join(name);
    schuler()
        .args(["simulate", "--config"])
        .arg(&cfg)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    out
}

/// `schuler nav` of the simulated IMU from the scenario's start into `out`, with `gnss`
/// flags; no HTML report.
fn nav(sim: &Path, out: &Path, gnss: &[&std::ffi::OsStr]) -> assert_cmd::assert::Assert {
    schuler()
        .args(["nav", "--imu"])
        .arg(sim.join("imu.txt"))
        .args(gnss)
        .args(["--init-pos", "30.5,114.3,50", "--init-att", "0,0,30"])
        .args(["--lever-arm", "0.5,0,-1", "--imu-grade", "tactical"])
        .args(["--output-rate", "10", "--no-report", "--out"])
        .arg(out)
        .assert()
}

/// Every file in `dir` (no subdirectories: `--no-report`), by name.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .expect("output directory")
        .map(|e| {
            let e = e.expect("entry");
            assert!(e.file_type().expect("type").is_file(), "{:?}", e.path());
            let name = e.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(e.path()).expect("read output"))
        })
        .collect();
    out.sort();
    out
}

/// Asserts `a` and `b` hold the same files with the same bytes.
fn assert_same_outputs(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    let names = |f: &[(String, Vec<u8>)]| f.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(names(&fa), names(&fb));
    assert!(
        names(&fa).contains(&"nav.txt".to_owned()),
        "{:?}",
        names(&fa)
    );
    for ((name, x), (_, y)) in fa.iter().zip(&fb) {
        assert!(x == y, "{name} differs between {a:?} and {b:?}");
    }
}

#[test]
fn the_simulators_csv_navigates_as_its_text_twin() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = simulate(dir.path(), "sim", SCENARIO);
    let (txt, csv) = (sim.join("gnss.txt"), sim.join("gnss.csv"));
    let run = |name: &str, gnss: &[&std::ffi::OsStr]| {
        let out = dir.path().join(name);
        nav(&sim, &out, gnss).success();
        out
    };
    // The same fixes, so the same bytes in every output (nav, std, imu_err, rejected,
    // innovations, consistency): the CSV carries gnss.txt's numbers, and neither its
    // velocities nor its outlier flag are used.
    let from_txt = run("txt", &["--gnss".as_ref(), txt.as_os_str()]);
    let from_csv = run("csv", &["--gnss".as_ref(), csv.as_os_str()]);
    assert_same_outputs(&from_txt, &from_csv);

    // The outlier is the simulator's truth: nav did not drop it, the gate refused it.
    let records = schuler_io::formats::gnss::read_gnss_records(&csv).expect("reads");
    let flagged: Vec<f64> = records
        .iter()
        .filter(|r| r.outlier == Some(true))
        .map(|r| r.fix.t)
        .collect();
    assert_eq!(flagged, vec![150.0]);
    let rejected = std::fs::read_to_string(from_csv.join("rejected.csv")).expect("rejected");
    assert!(
        rejected
            .lines()
            .any(|l| l.starts_with("150,gnss_position,")),
        "{rejected}"
    );

    // The CSV's velocities, through --gnss-vel, whichever file gives the positions.
    let vel_txt = run(
        "vel_txt",
        &[
            "--gnss".as_ref(),
            txt.as_os_str(),
            "--gnss-vel".as_ref(),
            csv.as_os_str(),
        ],
    );
    let vel_csv = run(
        "vel_csv",
        &[
            "--gnss".as_ref(),
            csv.as_os_str(),
            "--gnss-vel".as_ref(),
            csv.as_os_str(),
        ],
    );
    assert_same_outputs(&vel_txt, &vel_csv);
    let innovations =
        std::fs::read_to_string(vel_csv.join("innovations.csv")).expect("innovations");
    let velocities = innovations
        .lines()
        .filter(|l| l.contains(",gnss_velocity,"))
        .count();
    assert!(velocities > 200, "{velocities} velocity updates");
    assert!(
        std::fs::read(vel_csv.join("nav.txt")).expect("nav")
            != std::fs::read(from_csv.join("nav.txt")).expect("nav")
    );
}

#[test]
fn a_position_log_as_the_velocity_log_names_file_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    // Ten seconds at rest, no velocity_std in the scenario: the receiver measures no
    // velocity, and gnss.csv has no velocity columns (the simulator once wrote the
    // true velocity with standard deviations of 0).
    let body = "seed = 3\n[start]\nposition = [\"30.5 deg\", \"114.3 deg\", \"50 m\"]\n\
                attitude = [\"0 deg\", \"0 deg\", \"30 deg\"]\n[[motion]]\ntype = \"hold\"\n\
                duration = \"10 s\"\n[imu]\nrate_hz = 100\npreset = \"tactical\"\n[gnss]\n\
                rate_hz = 1\nposition_std = [\"0.5 m\", \"0.5 m\", \"1 m\"]\n";
    let sim = simulate(dir.path(), "rest", body);
    let (txt, csv) = (sim.join("gnss.txt"), sim.join("gnss.csv"));
    let text = std::fs::read_to_string(&csv).expect("csv");
    assert_eq!(
        text.lines().next(),
        Some("t,lat_deg,lon_deg,h_m,std_n_m,std_e_m,std_d_m,outlier")
    );
    assert!(text.lines().skip(1).all(|l| l.split(',').count() == 8));
    let out = dir.path().join("out");
    // The CSV gives its positions...
    nav(&sim, &out, &["--gnss".as_ref(), csv.as_os_str()]).success();
    // ... and, named as the velocity log, its header says it has none.
    nav(
        &sim,
        &out,
        &[
            "--gnss".as_ref(),
            txt.as_os_str(),
            "--gnss-vel".as_ref(),
            csv.as_os_str(),
        ],
    )
    .failure()
    .stderr(predicate::str::contains(format!(
        "{}:1: the header lacks columns vn_mps, ve_mps, vd_mps",
        csv.display()
    )));
    // A perfect velocity sensor (velocity_std 0, written as such) cannot be weighed.
    let perfect = body.to_owned() + "velocity_std = [\"0 m/s\", \"0 m/s\", \"0 m/s\"]\n";
    let sim0 = simulate(dir.path(), "perfect", &perfect);
    let csv0 = sim0.join("gnss.csv");
    nav(
        &sim0,
        &out,
        &[
            "--gnss".as_ref(),
            sim0.join("gnss.txt").as_os_str(),
            "--gnss-vel".as_ref(),
            csv0.as_os_str(),
        ],
    )
    .failure()
    .stderr(predicate::str::contains(format!(
        "{}:2: field std_vn_mps: a standard deviation must be positive, got 0",
        csv0.display()
    )));
    // gnss.txt as the velocity log: its first fix repeats itself.
    nav(
        &sim,
        &out,
        &[
            "--gnss".as_ref(),
            txt.as_os_str(),
            "--gnss-vel".as_ref(),
            txt.as_os_str(),
        ],
    )
    .failure()
    .stderr(
        predicate::str::contains(format!("{}:1: vn ve vd = 30.5", txt.display())).and(
            predicate::str::contains("this is a GNSS position log (t lat lon h std_n"),
        ),
    );
    // A CSV of positions only as the velocity log: the header says what it is.
    let positions = dir.path().join("positions.csv");
    let text = std::fs::read_to_string(&csv).expect("csv");
    let cut: String = text
        .lines()
        .map(|l| l.split(',').take(7).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    std::fs::write(&positions, cut).expect("write");
    nav(
        &sim,
        &out,
        &[
            "--gnss".as_ref(),
            positions.as_os_str(),
            "--gnss-vel".as_ref(),
            positions.as_os_str(),
        ],
    )
    .failure()
    .stderr(predicate::str::contains(format!(
        "{}:1: the header lacks columns vn_mps, ve_mps, vd_mps",
        positions.display()
    )));
}
