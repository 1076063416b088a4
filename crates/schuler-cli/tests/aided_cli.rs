//! `schuler nav --gnss --baro` on `schuler simulate`'s output for the example drive
//! (a tactical IMU at 200 Hz, GNSS at 1 Hz with a lever arm and a 60-s outage,
//! a barometer with a 3-m bias): the barometer holds the height through the outage.

use crate::common;
use predicates::prelude::*;
use std::path::Path;

fn vertical_max_in(nav: &Path, truth: &Path, from: f64, to: f64) -> f64 {
    let truth = common::read_rows(truth);
    let t0 = truth[0][1];
    let dt = truth[1][1] - t0;
    common::read_rows(nav)
        .iter()
        .filter(|r| r[1] >= from && r[1] <= to)
        .map(|r| {
            let t = &truth[((r[1] - t0) / dt).round() as usize];
            (r[4] - t[4]).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_barometer_holds_the_height_through_the_outage() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = common::simulate_drive(dir.path());
    let baro = sim.join("baro.csv");
    let run = |name: &str, extra: &[&std::ffi::OsStr]| {
        let out = dir.path().join(name);
        common::nav_drive(&sim, &out, extra).success();
        vertical_max_in(&out.join("nav.txt"), &sim.join("truth.nav"), 400.0, 460.0)
    };
    let without = run("gnss", &[]);
    let with = run(
        "baro",
        &[
            "--baro".as_ref(),
            baro.as_os_str(),
            "--baro-std".as_ref(),
            "0.5 m".as_ref(),
        ],
    );
    println!("vertical max in the outage: GNSS only {without:.3} m, with baro {with:.3} m");
    assert!(with < without, "{with} vs {without}");
    // The barometer's 0.5 m noise, averaged by the filter, with its bias estimated
    // under GNSS beforehand.
    assert!(with < 1.0, "{with}");
}

/// `--error-model` beside `--scale-factors`: without the new flag `--scale-factors`
/// is the 21-state filter as it always was, the same bytes as `--error-model psi21`
/// (the Python suite's scale-factor run found it refused after the flag came in);
/// `psi15` with `--scale-factors` contradicts itself and is refused naming both.
#[test]
fn scale_factors_are_psi21_and_psi15_refuses_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = common::simulate_drive(dir.path());
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let extra: Vec<&std::ffi::OsStr> = extra.iter().map(|s| s.as_ref()).collect();
        (common::nav_drive(&sim, &out, &extra), out)
    };
    let (flag, by_flag) = run("flag", &["--scale-factors", "--no-report"]);
    flag.success();
    let (model, by_model) = run("model", &["--error-model", "psi21", "--no-report"]);
    model.success();
    for file in ["nav.txt", "std.txt", "imu_err.txt"] {
        let read = |d: &Path| std::fs::read(d.join(file)).expect("output");
        assert!(read(&by_flag) == read(&by_model), "{file} differs");
    }
    let (both, _) = run(
        "both",
        &["--error-model", "psi15", "--scale-factors", "--no-report"],
    );
    both.failure().stderr(
        predicates::str::contains("--error-model psi15")
            .and(predicates::str::contains("--scale-factors")),
    );
}
