//! Peak memory of `schuler nav` on long logs (issues 21 and 22): the forward run at
//! 200 Hz with 1-Hz GNSS over 1 h and 10 h, aided with its report (1-Hz output), aided
//! against a streamed `--truth` (NEES, no HTML), and the KF-GINS mode (every sample
//! written, as KF-GINS does). Each case runs the `schuler` binary under
//! `/usr/bin/time -f %M` (its peak resident set) on an IMU log written into a FIFO as
//! it is read, so a 10-hour log (720 MB of text) costs no disk; the GNSS and truth
//! files are written beside it.
//!
//! `cargo bench -p schuler-cli --bench memory` prints the table; `-- kf-gins` (or any
//! part of a case's name) runs only those cases. The IMU is at rest (exact increments
//! of the Earth's rate and gravity at 45° N) so that writing the log costs little;
//! what the run keeps does not depend on the motion.

use schuler::earth::{Geodetic, Wgs84};
use schuler::imu::ImuSample;
use schuler::rotation::Euler;
use schuler::sim::analytic::{self, Stationary};
use schuler_io::output::{ImuDigits, push_imu_line};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

mod kf_gins_yaml;
use kf_gins_yaml::{T0, yaml};

/// IMU rate [Hz].
const RATE_HZ: f64 = 200.0;

/// What a case runs.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// `schuler nav --gnss` with the report.
    Aided,
    /// `schuler nav --gnss --truth --no-report`: NEES against the streamed truth.
    Truth,
    /// `schuler nav --kf-gins-config`.
    KfGins,
}

/// The cases: name, hours, mode.
const CASES: [(&str, f64, Mode); 6] = [
    ("nav-aided-report-1h", 1.0, Mode::Aided),
    ("nav-aided-report-10h", 10.0, Mode::Aided),
    ("nav-truth-nees-1h", 1.0, Mode::Truth),
    ("nav-truth-nees-10h", 10.0, Mode::Truth),
    ("kf-gins-1h", 1.0, Mode::KfGins),
    ("kf-gins-10h", 10.0, Mode::KfGins),
];

fn here() -> Stationary {
    Stationary {
        pos: Geodetic::from_degrees(45.0, 7.0, 300.0),
        attitude: Euler::new(0.0, 0.0, 0.5),
    }
}

/// The GNSS log (a fix each whole second, 0.5 m / 1 m std) and the truth (each whole
/// second) over `hours`.
fn write_aids(dir: &Path, hours: f64) {
    let p = here().pos;
    let (lat, lon) = (p.lat.to_degrees(), p.lon.to_degrees());
    let (mut gnss, mut truth) = (String::new(), String::new());
    for k in 1..=(hours * 3600.0) as u64 {
        let t = T0 + k as f64;
        let _ = writeln!(gnss, "{t} {lat:.12} {lon:.12} {:.4} 0.5 0.5 1.0", p.h);
        let _ = writeln!(
            truth,
            "2200 {t} {lat:.12} {lon:.12} {:.4} 0 0 0 0 0 {:.9}",
            p.h,
            0.5f64.to_degrees()
        );
    }
    std::fs::write(dir.join("gnss.txt"), gnss).expect("gnss.txt");
    std::fs::write(dir.join("truth.nav"), truth).expect("truth.nav");
}

/// The `schuler` command of a case reading `dir/imu.txt`.
fn command(dir: &Path, mode: Mode) -> Command {
    let mut c = Command::new("/usr/bin/time");
    c.args(["-f", "%M", env!("CARGO_BIN_EXE_schuler")]);
    if mode == Mode::KfGins {
        let p = here().pos;
        let (lat, lon) = (p.lat.to_degrees(), p.lon.to_degrees());
        let att = [0.0, 0.0, 0.5f64.to_degrees()];
        let text = yaml(dir, lat, lon, p.h, [0.0; 3], att);
        std::fs::write(dir.join("kf-gins.yaml"), text).expect("yaml");
        std::fs::create_dir_all(dir.join("out")).expect("out");
        c.arg("nav")
            .arg("--kf-gins-config")
            .arg(dir.join("kf-gins.yaml"));
        return c;
    }
    let p = here().pos;
    c.arg("nav")
        .arg("--imu")
        .arg(dir.join("imu.txt"))
        .arg("--gnss")
        .arg(dir.join("gnss.txt"))
        .arg("--init-pos")
        .arg(format!(
            "{:.12},{:.12},{}",
            p.lat.to_degrees(),
            p.lon.to_degrees(),
            p.h
        ))
        .arg("--init-att")
        .arg(format!("0,0,{}", 0.5f64.to_degrees()))
        .args(["--imu-grade", "tactical", "--output-rate", "1", "--out"])
        .arg(dir.join("out"));
    if mode == Mode::Truth {
        c.arg("--truth")
            .arg(dir.join("truth.nav"))
            .arg("--no-report");
    }
    c
}

/// Writes the IMU log at rest over `hours` into the FIFO `path` (blocking until the
/// reader opens it).
fn feed_imu(path: &Path, hours: f64) {
    let dt = 1.0 / RATE_HZ;
    let at_rest: ImuSample = analytic::samples(&Wgs84, &here(), T0 - dt, dt, 1)
        .next()
        .expect("a sample");
    let file = std::fs::OpenOptions::new()
        .write(true)
        .open(path)
        .expect("open the FIFO");
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    let mut line = Vec::with_capacity(256);
    for k in 0..=(hours * 3600.0 * RATE_HZ) as u64 {
        let s = ImuSample {
            t: T0 + k as f64 * dt,
            ..at_rest
        };
        line.clear();
        push_imu_line(&mut line, &s, b' ', ImuDigits::Significant(13));
        line.push(b'\n');
        if w.write_all(&line).is_err() {
            // The reader stopped (its error is in its output).
            return;
        }
    }
    let _ = w.flush();
}

/// Runs one case; `(peak RSS [kB], seconds)` or the failure.
fn run(hours: f64, mode: Mode) -> Result<(u64, f64), String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let imu = dir.path().join("imu.txt");
    let made = Command::new("mkfifo").arg(&imu).status();
    if !made.is_ok_and(|s| s.success()) {
        return Err("mkfifo failed".into());
    }
    write_aids(dir.path(), hours);
    let clock = Instant::now();
    let child = command(dir.path(), mode)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run /usr/bin/time: {e}"))?;
    feed_imu(&imu, hours);
    let out = child.wait_with_output().map_err(|e| e.to_string())?;
    let seconds = clock.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(err.trim().to_owned());
    }
    let kb = err
        .lines()
        .last()
        .and_then(|l| l.trim().parse().ok())
        .ok_or_else(|| format!("no peak in {err:?}"))?;
    Ok((kb, seconds))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let only: Vec<&String> = args.iter().filter(|a| !a.starts_with('-')).collect();
    println!("| case | samples | seconds | peak RSS |");
    println!("|---|---|---|---|");
    for (name, hours, mode) in CASES {
        if !only.is_empty() && !only.iter().any(|o| name.contains(o.as_str())) {
            continue;
        }
        let samples = (hours * 3600.0 * RATE_HZ) as u64 + 1;
        match run(hours, mode) {
            Ok((kb, seconds)) => println!(
                "| {name} | {samples} | {seconds:.1} | {:.1} MB |",
                kb as f64 / 1024.0
            ),
            Err(e) => println!("| {name} | failed: {e} |"),
        }
    }
}
