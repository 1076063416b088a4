//! `schuler nav --error-model seed18` end to end on the committed drive9min data set
//! (gnss-ins-sim's 530-s car drive, GNSS positions and velocities at the IMU, no lever
//! arm; `tests/data/README.md`): the flight-test paper's 18-state filter against the
//! psi-angle 15-state filter on the same run, within the standard deviations the
//! seed18 run itself writes, the report's state count, and the settings the 18 states
//! cannot serve refused by name.

use crate::common;
use std::path::{Path, PathBuf};

/// Decompress the drive's `IMU.txt.xz` into `dir`.
fn imu(dir: &Path) -> PathBuf {
    let dst = dir.join("IMU.txt");
    let xz = common::test_data("drive9min").join("IMU.txt.xz");
    std::fs::write(&dst, common::unxz(&xz)).expect("write");
    dst
}

/// `schuler nav` of the drive on the wander mechanization from the truth's state at
/// t = 1 s, with the data set's noise (its README), positions and velocities, writing
/// once a second into `out`, with `extra` flags.
fn nav(imu: &Path, out: &Path, extra: &[&str]) -> assert_cmd::assert::Assert {
    let data = common::test_data("drive9min");
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(imu)
        .arg("--gnss")
        .arg(data.join("GNSS.txt"))
        .arg("--gnss-vel")
        .arg(data.join("GNSS_vel.txt"))
        .args(common::DRIVE9MIN_START_AND_NOISE)
        .args(["--gnss-vel-std", "0.05 m/s", "--output-rate", "1", "--out"])
        .arg(out)
        .args(extra)
        .assert()
}

/// The run's navigation rows, standard deviations and sensor-error estimates.
struct Run {
    nav: Vec<Vec<f64>>,
    std: Vec<Vec<f64>>,
    imu_err: Vec<Vec<f64>>,
}

fn read(out: &Path) -> Run {
    Run {
        nav: common::read_rows(&out.join("nav.txt")),
        std: common::read_rows(&out.join("std.txt")),
        imu_err: common::read_rows(&out.join("imu_err.txt")),
    }
}

/// Names of the compared quantities, in the order of [`differences`].
const NAMES: [&str; 15] = [
    "pos N", "pos E", "pos D", "vel N", "vel E", "vel D", "roll", "pitch", "yaw", "bg x", "bg y",
    "bg z", "ba x", "ba y", "ba z",
];

/// Per epoch, `|seed18 − psi15|` of each quantity over the seed18 run's own standard
/// deviation of it (std.txt). Position in metres (the latitude and longitude
/// difference on the WGS-84 radii at 45° N, far finer than the metre-level sigmas
/// need), velocity in m/s, attitude and sensor errors in the files' units (deg, deg/h,
/// mGal). Roll and pitch are set against the horizontal tilt's sigma
/// `hypot(σ_N, σ_E)` and yaw against σ_D: at the drive's few degrees of roll and
/// pitch the Euler-angle differences are the NED attitude error turned by the heading
/// to first order.
fn differences(seed: &Run, psi: &Run) -> Vec<[f64; 15]> {
    let (r_m, r_n) = (6_367_000.0, 6_388_000.0);
    let lat = 45.07f64.to_radians();
    seed.nav
        .iter()
        .zip(&psi.nav)
        .zip(seed.std.iter().zip(&seed.imu_err).zip(&psi.imu_err))
        .map(|((a, b), ((s, ea), eb))| {
            assert_eq!(a[1], b[1], "epochs out of step");
            assert_eq!(a[1], s[0], "std.txt out of step");
            let d = [
                (a[2] - b[2]).to_radians() * r_m,
                (a[3] - b[3]).to_radians() * r_n * lat.cos(),
                -(a[4] - b[4]),
                a[5] - b[5],
                a[6] - b[6],
                a[7] - b[7],
                a[8] - b[8],
                a[9] - b[9],
                (a[10] - b[10] + 540.0).rem_euclid(360.0) - 180.0,
            ];
            let tilt = s[7].hypot(s[8]);
            let sigma = [s[1], s[2], s[3], s[4], s[5], s[6], tilt, tilt, s[9]];
            let mut ratio = [0.0; 15];
            for k in 0..9 {
                ratio[k] = d[k].abs() / sigma[k];
            }
            for k in 0..6 {
                ratio[9 + k] = (ea[1 + k] - eb[1 + k]).abs() / s[10 + k];
            }
            ratio
        })
        .collect()
}

/// The 18-state filter runs the committed drive end to end and gives the psi-angle
/// filter's estimates within one of its own printed standard deviations at every
/// second (the library's tests measured 0.003σ on a drive like this one); its report
/// counts 18 states.
#[test]
fn seed18_runs_the_drive_and_agrees_with_psi15_within_its_printed_sigmas() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = imu(dir.path());
    let (seed_out, psi_out) = (dir.path().join("seed18"), dir.path().join("psi15"));
    let seed_run = nav(
        &imu,
        &seed_out,
        &["--mechanization", "wander", "--error-model", "seed18"],
    )
    .success();
    let printed = String::from_utf8_lossy(&seed_run.get_output().stdout).into_owned();
    println!("{printed}");
    // Every fix in the IMU's span used, positions and velocities both.
    assert!(
        printed.contains("469 position and 469 velocity updates"),
        "{printed}"
    );
    nav(
        &imu,
        &psi_out,
        &["--mechanization", "wander", "--error-model", "psi15"],
    )
    .success();
    let (seed, psi) = (read(&seed_out), read(&psi_out));
    assert_eq!(seed.nav.len(), psi.nav.len());
    assert!(seed.nav.len() > 500, "{} epochs", seed.nav.len());
    let ratios = differences(&seed, &psi);
    let mut worst = [(0.0f64, 0.0f64); 15];
    for (r, row) in ratios.iter().zip(&seed.nav) {
        for k in 0..15 {
            if r[k] > worst[k].0 {
                worst[k] = (r[k], row[1]);
            }
        }
    }
    for k in 0..15 {
        println!(
            "{:6}: max |seed18 - psi15| / sigma {:.4} at {:.0} s",
            NAMES[k], worst[k].0, worst[k].1
        );
    }
    for k in 0..15 {
        assert!(
            worst[k].0 <= 1.0,
            "{} differs by {} sigma",
            NAMES[k],
            worst[k].0
        );
    }
    let report = std::fs::read_to_string(seed_out.join("report.html")).expect("report");
    assert!(report.contains("18 filter states"), "the report's count");
    let report = std::fs::read_to_string(psi_out.join("report.html")).expect("report");
    assert!(report.contains("15 filter states"), "the report's count");
}

/// What the 18 states cannot serve is refused before anything runs, naming the flag,
/// the configuration field and what is missing; nothing is written.
#[test]
fn seed18_refuses_what_it_lacks_by_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = imu(dir.path());
    let baro = dir.path().join("baro.txt");
    std::fs::write(&baro, "1.0 245.0\n2.0 245.0\n").expect("write");
    let baro = baro.to_str().expect("utf-8 path");
    let cases: [(&[&str], &str); 7] = [
        (&["--mechanization", "ned"], "wander mechanization"),
        (&[], "wander mechanization"),
        (
            &["--mechanization", "wander", "--lever-arm", "0.5,0,-1"],
            "no lever arm",
        ),
        (&["--mechanization", "wander", "--smooth"], "no smoother"),
        (
            &["--mechanization", "wander", "--scale-factors"],
            "no scale-factor states",
        ),
        (
            &["--mechanization", "wander", "--baro", baro],
            "no barometer bias state",
        ),
        (&["--mechanization", "wander", "--nhc"], "no vehicle aids"),
    ];
    for (k, (flags, why)) in cases.iter().enumerate() {
        let out = dir.path().join(format!("refused{k}"));
        let mut args = vec!["--error-model", "seed18"];
        args.extend_from_slice(flags);
        let failed = nav(&imu, &out, &args).failure();
        let stderr = String::from_utf8_lossy(&failed.get_output().stderr).into_owned();
        println!("{flags:?}: {stderr}");
        assert!(
            stderr.contains("--error-model (filter.error_model)") && stderr.contains(why),
            "{flags:?}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out.join("nav.txt").exists(), "{flags:?} wrote nav.txt");
    }
}
