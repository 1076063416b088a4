//! `schuler channel` through the binary: the files the issue names (errors.csv header,
//! summary.json, SVG plots with axes and units), the textbook's numbers in the summary,
//! and errors that name the flag and the reason, never a panic.

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;
use std::path::Path;

fn channel(out: &Path, extra: &[&str]) -> assert_cmd::assert::Assert {
    Command::cargo_bin("schuler")
        .expect("binary")
        .arg("channel")
        .arg("--out")
        .arg(out)
        .args(extra)
        .assert()
}

fn summary(dir: &Path) -> Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("valid JSON")
}

#[test]
fn accel_bias_run_writes_every_file_with_the_textbook_numbers() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("run");
    channel(&out, &["--accel-bias", "1e-3m/s^2", "--duration", "4h"])
        .success()
        .stdout(predicate::str::contains("Schuler period 84.39"));
    let csv = std::fs::read_to_string(out.join("errors.csv")).expect("errors.csv");
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("t,dr,dv,alpha,dr_linear,dv_linear,alpha_linear,dr_closed,dv_closed,alpha_closed")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|f| f.parse::<f64>().expect("number"))
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 14_401, "a row per second over 4 h");
    // Row at t = T0/2 (2532 s): Δr = 2Δf/ω0² = 1299 m (20), in metres.
    let half = &rows[2532];
    assert!((half[1] - 1298.8).abs() < 1.0, "{half:?}");
    let s = summary(&out);
    let period = &s["schuler_period_s"];
    let rel = period["measured"].as_f64().expect("measured")
        / period["theory"].as_f64().expect("theory")
        - 1.0;
    assert!(rel.abs() < 1e-3, "{period}");
    assert_eq!(s["inputs"]["accel_bias_m_s2"], 1e-3);
    assert_eq!(s["closed_form"], "(18)-(19)");
    for k in ["dr", "dv", "alpha"] {
        let r = s["relative_to_peak"]["nonlinear_minus_linear"][k]
            .as_f64()
            .expect("ratio");
        assert!(r < 1e-3, "{k}: {r}");
    }
    for (file, unit) in [
        ("dr.svg", "dr [km]"),
        ("dv.svg", "dV [m/s]"),
        ("alpha.svg", "alpha [arcsec]"),
    ] {
        let svg = std::fs::read_to_string(out.join(file)).expect("svg");
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{file}"
        );
        assert!(
            svg.contains(unit) && svg.contains("t [h]") && svg.contains("<polyline"),
            "{file}"
        );
        assert!(svg.contains("closed form"), "{file}: legend");
    }
}

#[test]
fn sins_turn_run_has_no_closed_form_columns() {
    let dir = tempfile::tempdir().expect("tempdir");
    channel(
        dir.path(),
        &[
            "--system",
            "sins",
            "--accel-bias-p2",
            "1e-3m/s^2",
            "--level",
            "--turn",
            "1h:180deg",
            "--duration",
            "2h",
        ],
    )
    .success();
    let csv = std::fs::read_to_string(dir.path().join("errors.csv")).expect("csv");
    let last = csv.lines().last().expect("rows");
    assert!(last.ends_with(",,,"), "{last}");
    let s = summary(dir.path());
    assert!(s["closed_form"].is_null());
    // Leveled: alpha0 = df/g = 1.019e-4 rad.
    let a0 = s["alpha0_rad"]["nonlinear"].as_f64().expect("alpha0");
    assert!((a0 / (1e-3 / 9.81) - 1.0).abs() < 1e-6);
    // After the turn the doubled bias shows: peak dr ≈ 4 Δf/ω0² = 2.6 km.
    let dr = s["peak"]["nonlinear"]["dr_m"].as_f64().expect("peak");
    assert!((2500.0..2700.0).contains(&dr), "{dr}");
    assert_eq!(s["inputs"]["turns"][0]["duration_s"], 6.0);
}

#[test]
fn bare_earth_rate_flag_uses_the_textbook_rate() {
    let dir = tempfile::tempdir().expect("tempdir");
    channel(
        dir.path(),
        &[
            "--earth-rate",
            "--init-vel-error",
            "1m/s",
            "--duration",
            "1h",
        ],
    )
    .success();
    let s = summary(dir.path());
    assert_eq!(s["inputs"]["earth_rate_rad_s"], 7.2921158553e-5);
    // The linear model's g is the vertical specific force g - a w^2 (5).
    let g = s["linear_model_g_m_s2"].as_f64().expect("g");
    assert!((g - (9.81 - 6.371e6 * 7.2921158553e-5f64.powi(2))).abs() < 1e-12);
}

fn rejects(extra: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut a = channel(dir.path(), extra).failure();
    for n in needles {
        a = a.stderr(predicate::str::contains(*n));
    }
    a.stderr(predicate::str::contains("panicked").not());
}

#[test]
fn bad_flags_name_the_flag_and_the_reason() {
    rejects(&["--accel-bias", "1e-3"], &["--accel-bias", "unit"]);
    rejects(
        &["--accel-bias", "0.01deg/h"],
        &["--accel-bias", "acceleration"],
    );
    rejects(
        &["--gyro-drift", "1e-3m/s^2"],
        &["--gyro-drift", "angular rate"],
    );
    rejects(&["--turn", "1h:180deg"], &["--turn", "--system sins"]);
    rejects(
        &["--system", "sins", "--accel-bias", "1e-3m/s^2"],
        &["--accel-bias", "--accel-bias-p1"],
    );
    rejects(
        &["--level", "--init-tilt", "20arcsec"],
        &["--level", "--init-tilt"],
    );
    rejects(
        &["--system", "sins", "--turn", "1h"],
        &["--turn", "AT:ANGLE"],
    );
    rejects(
        &["--system", "sins", "--turn", "1h:180deg", "--dt", "2s"],
        &["--dt", "too coarse", "turn"],
    );
    rejects(&["--duration", "-1h"], &["--duration", "positive"]);
    rejects(
        &["--accel-bias", "20m/s^2", "--level"],
        &["--level", "cannot level"],
    );
}

/// `--accelerate`: a platform INS leveled with a 1e-3 m/s^2 accelerometer bias keeps
/// its position error at the text's neglected term while the vehicle speeds up to
/// 100 m/s: the leveling cancels the bias (alpha0 = df/g) and what remains is
/// 2 V^2 df / g^2 = 0.208 m from the a lambda'^2 part of the specific force (the
/// unleveled error would be 2 df/w0^2 = 1299 m).
#[test]
fn leveled_ins_stays_put_through_an_acceleration() {
    let dir = tempfile::tempdir().expect("tempdir");
    channel(
        dir.path(),
        &[
            "--system",
            "ins",
            "--accel-bias",
            "1e-3m/s^2",
            "--level",
            "--accelerate",
            "10min:100m/s:50s",
            "--duration",
            "2h",
        ],
    )
    .success();
    let s = summary(dir.path());
    let peak = s["peak"]["nonlinear"]["dr_m"].as_f64().expect("peak dr");
    let bound = 2.0 * 100.0f64.powi(2) * 1e-3 / 9.81f64.powi(2);
    assert!(peak <= 1.01 * bound, "{peak} m vs {bound} m");
}

/// Issue "Reliability"'s reproducer: an initial position error of exactly 1 km on the
/// INS and SINS systems panicked while labelling a plot whose series is constant (a
/// tick step of 0). The run succeeds and writes its plots.
#[test]
fn a_constant_error_series_plots_without_panicking() {
    for system in ["ins", "sins"] {
        let dir = tempfile::tempdir().expect("tempdir");
        channel(dir.path(), &["--system", system, "--init-pos-error=1km"]).success();
        let svgs = std::fs::read_dir(dir.path())
            .expect("out dir")
            .filter(|e| {
                e.as_ref()
                    .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "svg"))
            })
            .count();
        assert!(svgs > 0, "{system}: no plot written");
    }
}
