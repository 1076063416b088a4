//! Helpers shared by the CLI's integration tests: the data sets kept in the repository
//! (`tests/data/`, provenance in its README) and the KF-GINS text files the commands write.

#![allow(dead_code)] // each test crate uses its own subset

use std::path::{Path, PathBuf};

/// A data set under the repository's `tests/data/`, which must exist.
pub fn test_data(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(name);
    assert!(
        dir.is_dir(),
        "{} is missing: the test data sets are part of the repository",
        dir.display()
    );
    dir
}

/// `nav` flags of the drive9min data set: the truth's state at t = 1.0 s (its README's
/// KF-GINS set-up) and the IMU noise the data were made with.
pub const DRIVE9MIN_START_AND_NOISE: [&str; 14] = [
    "--init-pos",
    "45.0712345678,7.6812345678,245",
    "--init-att",
    "0,0,10",
    "--start",
    "1.0",
    "--arw",
    "0.1 deg/sqrt(h)",
    "--vrw",
    "0.08 m/s/sqrt(h)",
    "--gyro-bias-std",
    "2 deg/h",
    "--accel-bias-std",
    "300 mGal",
];

/// The decompressed bytes of an `.xz` file.
pub fn unxz(path: &Path) -> Vec<u8> {
    let mut input = std::io::BufReader::new(std::fs::File::open(path).expect("open .xz"));
    let mut out = Vec::new();
    lzma_rs::xz_decompress(&mut input, &mut out).expect("xz");
    out
}

/// Rows of whitespace-separated numbers (KF-GINS text formats).
pub fn rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .map(|l| {
            l.split_whitespace()
                .map(|x| x.parse().expect("number"))
                .collect()
        })
        .collect()
}

/// Rows of a KF-GINS text file.
pub fn read_rows(path: &Path) -> Vec<Vec<f64>> {
    rows(&std::fs::read_to_string(path).expect("read"))
}

/// `schuler simulate` of the example drive (`examples/drive.toml`: 20 minutes, a
/// tactical IMU at 200 Hz, GNSS at 1 Hz with a lever arm and a 60-s outage at
/// 400-460 s, a barometer with a 3-m bias) into `dir/sim`.
pub fn simulate_drive(dir: &Path) -> PathBuf {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/drive.toml");
    simulate(&example, dir)
}

/// `schuler simulate` of the scenario `config` into `dir/sim`.
pub fn simulate(config: &Path, dir: &Path) -> PathBuf {
    let sim = dir.join("sim");
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["simulate", "--config"])
        .arg(config)
        .arg("--out")
        .arg(&sim)
        .assert()
        .success();
    sim
}

/// `schuler nav --gnss` of the simulated drive into `out` (its initial state, lever
/// arm and IMU grade, 10-Hz output), with `extra` flags.
pub fn nav_drive(sim: &Path, out: &Path, extra: &[&std::ffi::OsStr]) -> assert_cmd::assert::Assert {
    nav_drive_imu(sim, &sim.join("imu.txt"), out, extra)
}

/// [`nav_drive`] on another IMU file than the simulated one (the same drive written
/// otherwise).
pub fn nav_drive_imu(
    sim: &Path,
    imu: &Path,
    out: &Path,
    extra: &[&std::ffi::OsStr],
) -> assert_cmd::assert::Assert {
    let gnss = sim.join("gnss.txt");
    nav_drive_with(imu, &["--gnss".as_ref(), gnss.as_os_str()], out, extra)
}

/// [`nav_drive`] with the GNSS flags `gnss` in place of `--gnss sim/gnss.txt`.
pub fn nav_drive_gnss(
    sim: &Path,
    out: &Path,
    gnss: &[&std::ffi::OsStr],
    extra: &[&std::ffi::OsStr],
) -> assert_cmd::assert::Assert {
    nav_drive_with(&sim.join("imu.txt"), gnss, out, extra)
}

/// `schuler nav` of the drive's IMU log `imu` with the GNSS flags `gnss` (the drive's
/// initial state, lever arm and IMU grade, 10-Hz output) into `out`, with `extra`.
fn nav_drive_with(
    imu: &Path,
    gnss: &[&std::ffi::OsStr],
    out: &Path,
    extra: &[&std::ffi::OsStr],
) -> assert_cmd::assert::Assert {
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(imu)
        .args(gnss)
        .args(["--init-pos", "45.07,7.68,245", "--init-att", "0,0,10"])
        .args([
            "--lever-arm",
            "0.5,0,-1",
            "--imu-grade",
            "tactical",
            "--output-rate",
            "10",
        ])
        .args(extra)
        .arg("--out")
        .arg(out)
        .assert()
}

pub mod bag;
