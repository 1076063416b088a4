//! Interrupted and failed runs leave whole files: SIGINT to a running `simulate` and
//! `nav` stops them between lines with every file consistent with what they print,
//! and a full disk (`/dev/full`) is reported with the file's name.
#![cfg(unix)]

use crate::common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn schuler() -> Command {
    Command::new(env!("CARGO_BIN_EXE_schuler"))
}

/// Waits until `ready` holds (polling), failing after a minute.
fn wait_for(what: &str, ready: impl Fn() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "timed out: {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn sigint(child: &Child) {
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
}

/// The exit code and stderr of `child`, which must end within a minute.
fn finish(mut child: Child) -> (Option<i32>, String) {
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("the interrupted run did not stop");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        std::io::Read::read_to_string(&mut e, &mut err).expect("stderr");
    }
    (status.code(), err)
}

/// The number after `key` in `text` (up to the next blank, without a trailing colon).
fn number_after(text: &str, key: &str) -> f64 {
    let rest = &text[text
        .find(key)
        .unwrap_or_else(|| panic!("{key:?} in {text}"))
        + key.len()..];
    let word = rest.split_whitespace().next().expect("number");
    word.trim_end_matches(':').parse().expect("a number")
}

/// The lines of `path`, which must end on a whole line; each line's `column`-th field
/// as a number.
fn column(path: &Path, column: usize) -> Vec<f64> {
    let text = std::fs::read_to_string(path).expect("read");
    assert!(
        text.is_empty() || text.ends_with('\n'),
        "{} ends mid-line",
        path.display()
    );
    text.lines()
        .filter(|l| !l.starts_with(|c: char| c.is_ascii_alphabetic()))
        .map(|l| {
            let fields: Vec<&str> = l.split([' ', ',']).filter(|f| !f.is_empty()).collect();
            fields[column].parse().expect("number")
        })
        .collect()
}

/// One hour at 1 kHz at rest with 1-Hz GNSS: long enough that it is still running
/// when the signal comes, whatever the machine.
const LONG: &str = r#"
seed = 1
[start]
position = ["45 deg", "7 deg", "100 m"]
attitude = ["0 deg", "0 deg", "0 deg"]
[[motion]]
type = "hold"
duration = "3600 s"
[imu]
rate_hz = 1000
preset = "tactical"
[gnss]
rate_hz = 1
position_std = ["0.5 m", "0.5 m", "1 m"]
"#;

#[test]
fn sigint_stops_simulate_between_blocks_with_every_file_whole() {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = dir.path().join("long.toml");
    std::fs::write(&config, LONG).expect("write");
    let out = dir.path().join("sim");
    let child = schuler()
        .args(["simulate", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let imu = out.join("imu.txt");
    wait_for("the first block", || {
        std::fs::metadata(&imu).is_ok_and(|m| m.len() > 0)
    });
    sigint(&child);
    let (code, err) = finish(child);
    assert_eq!(code, Some(130), "{err}");
    assert!(err.contains("interrupted by SIGINT"), "{err}");
    let t_end = number_after(&err, "stopped at t = ");
    let samples = number_after(&err, "hold the ");
    // The IMU and its truth end on the same sample, the one printed; the fixes and
    // the sensor-error truth (1 Hz) on the last second before it.
    let t_imu = column(&imu, 0);
    assert_eq!(t_imu.len() as f64, samples);
    assert_eq!(t_imu.last().copied(), Some(t_end));
    assert!(t_end < 3600.0, "the run ended before the signal: {err}");
    let t_truth = column(&out.join("truth.nav"), 1);
    assert_eq!(t_truth, t_imu);
    assert_eq!(column(&out.join("imu.csv"), 0), t_imu);
    for (file, col) in [("gnss.txt", 0), ("gnss.csv", 0), ("imu_err_truth.txt", 0)] {
        let t = column(&out.join(file), col);
        let last = *t.last().expect("a line");
        assert!(
            last <= t_end && last > t_end - 1.0,
            "{file}: {last} vs {t_end}"
        );
    }
}

#[test]
fn sigint_stops_nav_with_its_files_as_printed() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = common::simulate_drive(dir.path());
    let imu = std::fs::read_to_string(sim.join("imu.txt")).expect("imu");
    let lines: Vec<&str> = imu.lines().collect();
    let out = dir.path().join("nav");
    // The IMU comes through a pipe, so the run waits for it where the test wants.
    let mut child = schuler()
        .args(["nav", "--imu", "/dev/stdin", "--gnss"])
        .arg(sim.join("gnss.txt"))
        .args([
            "--init-pos",
            "45.07,7.68,245",
            "--init-att",
            "0,0,10",
            "--lever-arm",
            "0.5,0,-1",
            "--imu-grade",
            "tactical",
            "--out",
        ])
        .arg(&out)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let mut stdin = child.stdin.take().expect("stdin");
    let (first, more) = (4000, 100);
    for l in &lines[..first] {
        writeln!(stdin, "{l}").expect("pipe");
    }
    wait_for("the output files", || out.join("std.txt").exists());
    sigint(&child);
    // The run sees the signal at its next sample; then it reads no more.
    for l in &lines[first..first + more] {
        if writeln!(stdin, "{l}").is_err() {
            break;
        }
    }
    drop(stdin);
    let (code, err) = finish(child);
    assert_eq!(code, Some(130), "{err}");
    assert!(err.contains("interrupted by SIGINT"), "{err}");
    let epochs = number_after(&err, "samples; ");
    let t_end = number_after(&err, "epochs up to t = ");
    let t_nav = column(&out.join("nav.txt"), 1);
    assert_eq!(t_nav.len() as f64, epochs, "{err}");
    assert_eq!(t_nav.last().copied(), Some(t_end));
    let t_last_fed = column(&sim.join("imu.txt"), 0)[first + more - 1];
    assert!(
        t_end < t_last_fed,
        "{t_end} vs {t_last_fed}: the run ignored the signal"
    );
    assert_eq!(column(&out.join("nav.csv"), 0), t_nav);
    for table in ["std.txt", "imu_err.txt"] {
        assert_eq!(column(&out.join(table), 0), t_nav, "{table}");
    }
    for t in column(&out.join("innovations.csv"), 0) {
        assert!(t <= t_end);
    }
}

/// Runs `command` with `dir/file` on `/dev/full`; the error must name the file.
fn full_disk(dir: &Path, file: &str, command: &mut Command) {
    std::fs::create_dir_all(dir).expect("dir");
    std::os::unix::fs::symlink("/dev/full", dir.join(file)).expect("symlink");
    let out = command.output().expect("run");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("{file}:")) || err.contains(&format!("{file} ")),
        "{file}: {err}"
    );
    assert!(err.contains("No space left on device"), "{err}");
}

#[test]
fn a_full_disk_names_the_file() {
    if !Path::new("/dev/full").exists() {
        eprintln!("no /dev/full here: the test needs it");
        return;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let d = |name: &str| -> PathBuf { dir.path().join(name) };
    let sim = common::simulate_drive(dir.path());
    let drive = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    full_disk(
        &d("s"),
        "imu.txt",
        schuler()
            .args(["simulate", "--config"])
            .arg(drive.join("drive.toml"))
            .arg("--out")
            .arg(d("s")),
    );
    let nav = |out: PathBuf| {
        let mut c = schuler();
        c.args(["nav", "--imu"])
            .arg(sim.join("imu.txt"))
            .args(["--init-pos", "45.07,7.68,245", "--init-att", "0,0,10"])
            .arg("--out")
            .arg(out);
        c
    };
    full_disk(&d("n"), "nav.txt", &mut nav(d("n")));
    for (name, file, args) in [
        ("c", "errors.csv", vec!["channel"]),
        ("v", "vertical.csv", vec!["vertical"]),
        ("p", "errors.csv", vec!["platform", "--config"]),
    ] {
        let mut c = schuler();
        c.args(&args);
        if name == "p" {
            c.arg(drive.join("platform.toml"));
        }
        full_disk(&d(name), file, c.arg("--out").arg(d(name)));
    }
    full_disk(
        &d("cmp"),
        "errors.csv",
        schuler()
            .arg("compare")
            .arg(sim.join("truth.nav"))
            .arg(sim.join("truth.nav"))
            .arg("--out")
            .arg(d("cmp")),
    );
}
