//! `schuler vertical` through the binary: vertical.csv (`t,dh,dvh,mode`), summary.json
//! (eigenvalues, e-fold time, settling and reconvergence), plots; flag errors.

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;
use std::path::Path;

fn vertical(out: &Path, extra: &[&str]) -> assert_cmd::assert::Assert {
    Command::cargo_bin("schuler")
        .expect("binary")
        .arg("vertical")
        .arg("--out")
        .arg(out)
        .args(extra)
        .assert()
}

fn summary(dir: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).expect("summary"))
        .expect("JSON")
}

#[test]
fn free_channel_reports_its_e_fold_time() {
    let dir = tempfile::tempdir().expect("tempdir");
    vertical(
        dir.path(),
        &[
            "--mode",
            "free",
            "--init-height-error",
            "10m",
            "--duration",
            "1h",
            "--dt",
            "0.5s",
        ],
    )
    .success();
    let csv = std::fs::read_to_string(dir.path().join("vertical.csv")).expect("csv");
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t,dh,dvh,mode"));
    assert!(lines.all(|l| l.ends_with(",predict")));
    let s = summary(dir.path());
    let e = &s["e_fold_time_s"];
    let theory = e["theory"].as_f64().expect("theory");
    assert!((theory - 569.84).abs() < 0.01, "{theory}");
    assert!(e["relative_error"].as_f64().expect("measured").abs() < 0.005);
    for f in ["dh.svg", "dvh.svg"] {
        let svg = std::fs::read_to_string(dir.path().join(f)).expect("svg");
        assert!(svg.contains("[m") && svg.contains("t [min]") && svg.contains("closed form (32)"));
    }
}

#[test]
fn aided_loop_with_dropout_and_outlier() {
    let dir = tempfile::tempdir().expect("tempdir");
    vertical(
        dir.path(),
        &[
            "--mode",
            "aided",
            "--time-constant",
            "20s",
            "--accel-bias",
            "1e-3m/s^2",
            "--ref-noise",
            "0.5m",
            "--ref-bias",
            "2m",
            "--ref-dropout",
            "1000s:300s",
            "--ref-outlier",
            "600s:200m",
            "--gate",
            "20m",
            "--seed",
            "7",
            "--duration",
            "30min",
        ],
    )
    .success();
    let csv = std::fs::read_to_string(dir.path().join("vertical.csv")).expect("csv");
    assert!(csv.starts_with("t,dh,dvh,mode\n"));
    assert!(csv.contains(",predict\n") && csv.contains(",aided\n"));
    let kf = std::fs::read_to_string(dir.path().join("vertical_kf.csv")).expect("kf csv");
    assert!(kf.starts_with("t,dh,dvh,mode,k1,k2,sigma_h\n"));
    let s = summary(dir.path());
    // Critical damping at tau = 20 s: a double eigenvalue -1/tau.
    for l in s["eigenvalues"].as_array().expect("eigenvalues") {
        assert!(
            (l["re"].as_f64().expect("re") + 0.05).abs() < 1e-9 && l["im"] == 0.0,
            "{l}"
        );
    }
    assert_eq!(
        s["detector"]["rejected"].as_u64().map(|r| r >= 1),
        Some(true)
    );
    let outages = s["outages"].as_array().expect("outages");
    let long = outages
        .iter()
        .find(|o| o["start_s"].as_f64() == Some(1000.0))
        .expect("the dropout");
    let n = long["reconverge_time_constants"]
        .as_f64()
        .expect("reconverged");
    assert!(n <= 5.0, "{long}");
    let svg = std::fs::read_to_string(dir.path().join("dh.svg")).expect("svg");
    assert!(svg.contains("dh [m]") && svg.contains("predicting") && svg.contains("Kalman"));
}

fn rejects(extra: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut a = vertical(dir.path(), extra).failure();
    for n in needles {
        a = a.stderr(predicate::str::contains(*n));
    }
    a.stderr(predicate::str::contains("panicked").not());
}

#[test]
fn bad_flags_name_the_flag_and_the_reason() {
    rejects(&["--k1", "-0.1"], &["--k2"]);
    rejects(
        &["--k1", "0.1", "--k2", "0"],
        &["--k1/--k2", "not stabilizing"],
    );
    rejects(&["--time-constant", "20"], &["--time-constant", "unit"]);
    rejects(
        &["--time-constant", "20s", "--k1", "-0.1", "--k2", "-0.01"],
        &["--time-constant"],
    );
    rejects(&["--dt", "100s"], &["--dt", "too coarse"]);
    rejects(
        &["--ref-dropout", "1000s"],
        &["--ref-dropout", "FROM:DURATION"],
    );
    rejects(
        &["--ref-outlier-prob", "2"],
        &["--ref-outlier-prob", "probability"],
    );
    rejects(
        &["--mode", "free", "--time-constant", "20s"],
        &["--mode aided"],
    );
}
