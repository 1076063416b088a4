//! `schuler compare` against truth that does not come from the code under test: the
//! drive9min truth (gnss-ins-sim) against itself and against copies with offsets
//! injected by hand, decimated copies, a trajectory linear in time (where linear
//! interpolation is exact), malformed files, and statistics of a hand-made
//! distribution whose percentiles follow from their definition.

use crate::common;
use assert_cmd::Command;
use schuler::analysis::errors::EpochErrors;
use schuler::analysis::statistics::statistics;
use serde_json::Value;
use std::path::{Path, PathBuf};

use nalgebra::{Rotation3, Vector3};
use schuler::rotation::Euler;

/// The drive9min truth (100 Hz, 53,000 rows) as text lines.
fn truth_lines() -> Vec<String> {
    let bytes = common::unxz(&common::test_data("drive9min").join("truth.nav.xz"));
    String::from_utf8(bytes)
        .expect("utf-8")
        .lines()
        .map(str::to_owned)
        .collect()
}

fn write_lines(dir: &Path, name: &str, lines: &[String]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, lines.join("\n") + "\n").expect("write");
    p
}

fn compare(nav: &Path, truth: &Path, out: &Path, extra: &[&str]) -> assert_cmd::assert::Assert {
    Command::cargo_bin("schuler")
        .expect("binary")
        .arg("compare")
        .arg(nav)
        .arg(truth)
        .arg("--out")
        .arg(out)
        .args(extra)
        .assert()
}

fn json(out: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("compare.json")).expect("json"))
        .expect("valid json")
}

fn stat(j: &Value, quantity: &str, what: &str) -> f64 {
    j["statistics"][quantity][what]
        .as_f64()
        .unwrap_or_else(|| panic!("statistics.{quantity}.{what} in {j}"))
}

const QUANTITIES: [&str; 11] = [
    "north_m",
    "east_m",
    "horizontal_m",
    "vertical_m",
    "3_d_m",
    "v_north_mps",
    "v_east_mps",
    "v_down_mps",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
];

/// Rows of `errors.csv` (header checked, then numbers).
fn errors_csv(out: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(out.join("errors.csv")).expect("errors.csv");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "t_sow,north_m,east_m,down_m,horizontal_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,interpolated"
        )
    );
    lines
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect()
}

/// North error [m] of the point at (`lat_deg`, `h`) against the truth at (`lat_t_deg`,
/// `h_t`) on the same meridian: their ECEF difference in the meridian plane along the
/// truth's north, `−sin φ_t Δρ + cos φ_t Δz`, with `ρ = (N + h) cos φ`,
/// `z = (N (1 − e²) + h) sin φ`, `N = a / sqrt(1 − e² sin² φ)`, WGS84 written out here
/// from its definition (a = 6378137 m, f = 1/298.257223563).
fn wgs84_north_offset(lat_t_deg: f64, h_t: f64, lat_deg: f64, h: f64) -> f64 {
    let a = 6_378_137.0;
    let f = 1.0 / 298.257_223_563;
    let e2 = f * (2.0 - f);
    let rho_z = |lat_deg: f64, h: f64| {
        let (s, c) = lat_deg.to_radians().sin_cos();
        let n = a / (1.0 - e2 * s * s).sqrt();
        ((n + h) * c, (n * (1.0 - e2) + h) * s)
    };
    let ((rho_t, z_t), (rho, z)) = (rho_z(lat_t_deg, h_t), rho_z(lat_deg, h));
    let (s, c) = lat_t_deg.to_radians().sin_cos();
    -s * (rho - rho_t) + c * (z - z_t)
}

/// (1) The truth against itself: every error is exactly zero, all epochs exact.
#[test]
fn truth_against_itself_is_zero() {
    let dir = tempfile::tempdir().expect("tempdir");
    let truth = write_lines(dir.path(), "truth.nav", &truth_lines());
    let out = dir.path().join("self");
    compare(&truth, &truth, &out, &[])
        .success()
        .stdout(predicates::str::contains(
            "53000 epochs compared (53000 exact",
        ));
    let j = json(&out);
    assert_eq!(j["epochs"]["matched"], 53000);
    assert_eq!(j["nav"]["format"], "kf-gins");
    for q in QUANTITIES {
        for what in ["rms", "max", "p95", "mean"] {
            assert_eq!(stat(&j, q, what), 0.0, "{q}.{what}");
        }
    }
    assert_eq!(j["statistics"]["cep_m"], 0.0);
    for name in [
        "errors.csv",
        "position_error.svg",
        "velocity_error.svg",
        "attitude_error.svg",
    ] {
        assert!(out.join(name).is_file(), "{name}");
    }
    let svg = std::fs::read_to_string(out.join("attitude_error.svg")).expect("svg");
    assert!(svg.contains("t [s of week]") && svg.contains("error [deg]"));
}

/// (2) A copy with +1e-5 deg latitude, +0.25 m height and +0.5 deg yaw on every row
/// (yaw written back into [0, 360), so rows at 359.5..360 deg wrap to 0..0.5), as
/// schuler's nav.csv. Its NED frame is the truth's turned about east by the latitude
/// difference `δ` (the normals at two geodetic latitudes of one meridian are `δ`
/// apart): `C_nt = R_y(−δ)`. The errors, computed here from the WGS84 definition and
/// nalgebra's rotations: north the ECEF difference along the truth's north
/// ([`wgs84_north_offset`]: 1e-5 deg x (R_M + h), 1.1 m, and 0.25 m x δ = 4.4e-8 m
/// more for the height); east zero; down -0.25 m; velocity `R_y(−δ) v − v` (down
/// about `v_N δ`, up to 4e-6 m/s); attitude the Euler angles of `R_y(−δ) C_bn`, with
/// yaw 0.5 deg more, minus the truth's (roll and pitch about `δ` = 1.7e-7 rad, yaw
/// 0.5 deg and `δ tan(pitch) sin(yaw)`).
///
/// Tolerances: the copy is written with shortest round-trip numbers, so the file holds
/// the f64 of lat + 1e-5 used here; the ECEF coordinates (6.4e6 m) round to 1e-9 m, the
/// degree-to-radian conversions and the difference a few ulps of 0.79 rad (1.1e-16
/// rad = 7e-10 m each): 1e-8 m covers them with margin. Angles: ulps of 360 deg are
/// 5.7e-14 deg, so 1e-10 deg; height: ulps of 300 m, 1e-12 m; velocity: ulps of
/// 20 m/s, 1e-12 m/s.
#[test]
fn injected_offsets_come_out_exactly() {
    let lines = truth_lines();
    let copy = offset_copy(&lines);
    // 26 rows of the drive (its circle) have yaw in [359.5, 360).
    assert!(
        copy.wrapped >= 20,
        "the copy must cross 0/360 deg: {} rows",
        copy.wrapped
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let truth = write_lines(dir.path(), "truth.nav", &lines);
    let nav = write_lines(dir.path(), "nav.csv", &copy.csv);
    let out = dir.path().join("offset");
    compare(&nav, &truth, &out, &[]).success();
    let j = json(&out);
    assert_eq!(j["nav"]["format"], "csv");
    assert_eq!(j["epochs"]["exact"], 53000);
    let rows = errors_csv(&out);
    assert_eq!(rows.len(), 53000);
    for ((row, north), dv_att) in rows.iter().zip(&copy.north).zip(&copy.v_att) {
        assert_offset_row(row, *north, dv_att);
    }
    assert_offset_statistics(&j, &copy);
}

/// The truth's copy with the offsets of [`injected_offsets_come_out_exactly`], and the
/// errors expected of it.
struct OffsetCopy {
    /// The copy as `nav.csv` lines, header first (with an extra column).
    csv: Vec<String>,
    /// Expected north error per epoch [m].
    north: Vec<f64>,
    /// Expected velocity [m/s] and attitude [deg] errors per epoch.
    v_att: Vec<[Vector3<f64>; 2]>,
    /// Rows whose yaw + 0.5 deg wrapped past 360 deg.
    wrapped: usize,
}

/// The copy of the truth `lines` 1e-5 deg north, 0.25 m up and 0.5 deg to the right,
/// with the errors expected from the WGS84 definition and nalgebra's rotations.
fn offset_copy(lines: &[String]) -> OffsetCopy {
    let mut copy = OffsetCopy {
        csv: vec![
            "t_sow,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,extra"
                .to_owned(),
        ],
        north: Vec::new(),
        v_att: Vec::new(),
        wrapped: 0,
    };
    for l in lines {
        let r: Vec<f64> = l
            .split_whitespace()
            .map(|x| x.parse().expect("n"))
            .collect();
        let yaw = r[10] + 0.5;
        let yaw = if yaw >= 360.0 {
            copy.wrapped += 1;
            yaw - 360.0
        } else {
            yaw
        };
        copy.csv.push(format!(
            "{},{},{},{},{},{},{},{},{},{},7",
            r[1],
            r[2] + 1e-5,
            r[3],
            r[4] + 0.25,
            r[5],
            r[6],
            r[7],
            r[8],
            r[9],
            yaw
        ));
        copy.north
            .push(wgs84_north_offset(r[2], r[4], r[2] + 1e-5, r[4] + 0.25));
        copy.v_att.push(expected_v_att(&r, yaw));
    }
    copy
}

/// Velocity and attitude errors of a truth row `r` (KF-GINS columns) moved 1e-5 deg
/// north with yaw `yaw`: `C_nt = R_y(−δ)` turns the velocity and the attitude.
fn expected_v_att(r: &[f64], yaw: f64) -> [Vector3<f64>; 2] {
    let c_nt = Rotation3::from_axis_angle(&Vector3::y_axis(), -(r[2] + 1e-5 - r[2]).to_radians());
    let v = Vector3::new(r[5], r[6], r[7]);
    let rad = |x: f64| x.to_radians();
    let (roll, pitch, yaw_nav) =
        (c_nt * Rotation3::from_euler_angles(rad(r[8]), rad(r[9]), rad(yaw))).euler_angles();
    let wrap = |x: f64| (x + 180.0).rem_euclid(360.0) - 180.0;
    [
        c_nt * v - v,
        Vector3::new(
            wrap(roll.to_degrees() - r[8]),
            wrap(pitch.to_degrees() - r[9]),
            wrap(yaw_nav.to_degrees() - r[10]),
        ),
    ]
}

/// One row of `errors.csv` against the expected north error and velocity and
/// attitude errors (tolerances: see [`injected_offsets_come_out_exactly`]).
fn assert_offset_row(row: &[f64], north: f64, [dv, att]: &[Vector3<f64>; 2]) {
    assert!(
        (row[1] - north).abs() < 1e-8,
        "t {}: north {} vs {north}",
        row[0],
        row[1]
    );
    assert!(row[2].abs() < 1e-8, "east {}", row[2]);
    assert!((row[3] + 0.25).abs() < 1e-12, "down {}", row[3]);
    assert!((row[4] - north).abs() < 1e-8, "horizontal");
    assert!(
        (Vector3::new(row[5], row[6], row[7]) - dv).norm() < 1e-12,
        "t {}: velocity {row:?} vs {dv}",
        row[0]
    );
    assert!(
        (Vector3::new(row[8], row[9], row[10]) - att).abs().max() < 1e-10,
        "t {}: attitude {row:?} vs {att}",
        row[0]
    );
    assert!(
        (row[10] - 0.5).abs() < 1e-6,
        "t {}: yaw {}",
        row[0],
        row[10]
    );
    assert_eq!(row[11], 0.0);
}

/// The table of `compare.json` agrees with the rows: RMS and max of a near-constant
/// north error, the yaw's mean and 95 %, the vertical mean and the 3-D maximum.
fn assert_offset_statistics(j: &Value, copy: &OffsetCopy) {
    let max_north = copy.north.iter().fold(0.0f64, |m, x| m.max(*x));
    assert!((stat(j, "north_m", "max") - max_north).abs() < 1e-8);
    let yaw_mean = copy.v_att.iter().map(|[_, a]| a.z).sum::<f64>() / 53000.0;
    assert!((stat(j, "yaw_deg", "mean") - yaw_mean).abs() < 1e-10);
    assert!((stat(j, "yaw_deg", "p95") - 0.5).abs() < 1e-6);
    assert!((stat(j, "vertical_m", "mean") + 0.25).abs() < 1e-12);
    let h3 = stat(j, "3_d_m", "max");
    assert!(
        (h3 - (max_north.powi(2) + 0.0625).sqrt()).abs() < 1e-6,
        "{h3}"
    );
}

/// (3a) A 10-Hz copy against the 100-Hz truth: every epoch exact, zero error.
/// (3b) The 100-Hz truth against the 10-Hz copy as truth: nine epochs in ten
/// interpolated across 0.1 s, the nine after the copy's last epoch skipped; the
/// interpolation error of a car turning at 6 deg/s at 20 m/s is v w dt^2 / 8 = 2.6 mm.
#[test]
fn decimated_copies_match_and_interpolate() {
    let lines = truth_lines();
    let decimated: Vec<String> = lines.iter().step_by(10).cloned().collect();
    let dir = tempfile::tempdir().expect("tempdir");
    let truth = write_lines(dir.path(), "truth.nav", &lines);
    let ten_hz = write_lines(dir.path(), "nav10.nav", &decimated);

    let out = dir.path().join("a");
    compare(&ten_hz, &truth, &out, &[]).success();
    let j = json(&out);
    assert_eq!(j["epochs"]["exact"], 5300);
    assert_eq!(j["epochs"]["interpolated"], 0);
    for q in QUANTITIES {
        assert_eq!(stat(&j, q, "max"), 0.0, "{q}");
    }

    let out = dir.path().join("b");
    compare(&truth, &ten_hz, &out, &[]).success();
    let j = json(&out);
    assert_eq!(j["epochs"]["exact"], 5300);
    assert_eq!(j["epochs"]["interpolated"], 53000 - 5300 - 9);
    assert_eq!(j["epochs"]["after_truth"], 9);
    assert!((j["epochs"]["max_bridged_s"].as_f64().expect("s") - 0.1).abs() < 1e-9);
    let h = stat(&j, "horizontal_m", "max");
    assert!(h > 0.0 && h < 5e-3, "horizontal interpolation error {h} m");
    // Yaw crosses 0/360 in the data: unwrapped interpolation keeps the error small.
    let yaw = stat(&j, "yaw_deg", "max");
    assert!(yaw < 0.05, "yaw interpolation error {yaw} deg");
}

/// One epoch of a trajectory linear in time, written as a KF-GINS row with longitude
/// in (-180, 180], roll in (-180, 180] and yaw in [0, 360): it crosses the
/// antimeridian, roll ±180 and yaw 360 between t = 100 and 110 s.
fn linear_row(t: f64) -> String {
    let k = t - 100.0;
    let wrap180 = |x: f64| if x > 180.0 { x - 360.0 } else { x };
    let yaw = 359.0 + 0.25 * k;
    let yaw = if yaw >= 360.0 { yaw - 360.0 } else { yaw };
    format!(
        "2300 {t} {} {} {} {} {} {} {} {} {yaw}",
        30.0 + 1e-4 * k,
        wrap180(179.9995 + 1e-4 * k),
        100.0 + 2.0 * k,
        1.0 + 0.5 * k,
        -2.0 + 0.1 * k,
        0.3 * k,
        wrap180(179.0 + 0.5 * k),
        1.0 + 0.1 * k
    )
}

/// (3c) Truth at 1 Hz on a linear trajectory, NAV at 10 Hz on the same lines: linear
/// interpolation is exact there, so every error is zero up to f64 rounding of the
/// printed values (1e-13 deg on ~180 deg; 1e-6 m covers 1e-13 deg x 6.4e6 m / 57);
/// NAV epochs 0.5 s outside the truth are skipped and counted.
#[test]
fn lower_rate_truth_is_interpolated_exactly_on_a_linear_trajectory() {
    let truth: Vec<String> = (0..=10).map(|k| linear_row(100.0 + f64::from(k))).collect();
    let nav: Vec<String> = (-5..=105)
        .map(|k| linear_row(100.0 + f64::from(k) / 10.0))
        .collect();
    let dir = tempfile::tempdir().expect("tempdir");
    let truth = write_lines(dir.path(), "truth.nav", &truth);
    let nav = write_lines(dir.path(), "nav.nav", &nav);
    let out = dir.path().join("lin");
    compare(&nav, &truth, &out, &[]).success();
    let j = json(&out);
    assert_eq!(j["epochs"]["exact"], 11);
    assert_eq!(j["epochs"]["interpolated"], 90);
    assert_eq!(j["epochs"]["before_truth"], 5);
    assert_eq!(j["epochs"]["after_truth"], 5);
    assert_eq!(j["epochs"]["max_bridged_s"], 1.0);
    for q in QUANTITIES {
        let tol = if q.ends_with("_deg") { 1e-9 } else { 1e-6 };
        assert!(stat(&j, q, "max") < tol, "{q}: {}", stat(&j, q, "max"));
    }
    // The window flags select epochs: [102, 104] holds 21 NAV epochs.
    let out = dir.path().join("win");
    compare(&nav, &truth, &out, &["--start", "102", "--end", "104"]).success();
    let j = json(&out);
    assert_eq!(j["epochs"]["matched"], 21);
    assert_eq!(j["epochs"]["outside_window"], 111 - 21);
}

/// (4) Malformed input stops with `file:line: field NAME: reason` (exit 1, no panic).
#[test]
fn bad_input_names_file_line_and_field() {
    let lines = truth_lines();
    let head: Vec<String> = lines[..10].to_vec();
    let dir = tempfile::tempdir().expect("tempdir");
    let truth = write_lines(dir.path(), "truth.nav", &head);

    let mut truncated = head.clone();
    truncated[4] = truncated[4]
        .split_whitespace()
        .take(7)
        .collect::<Vec<_>>()
        .join(" ");
    let mut not_number = head.clone();
    not_number[6] = not_number[6].replacen("7.6812", "7.6x12", 1);
    let mut backwards = head.clone();
    backwards.swap(2, 3);
    let csv_missing = vec![
        "t_sow,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg".to_owned(),
        "1,45,7,100,0,0,0,0,0".to_owned(),
    ];
    let csv_nan = vec![
        "t_sow,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg".to_owned(),
        "0.01,45,7,100,0,0,0,0,0,0".to_owned(),
        "0.02,45,7,NaN,0,0,0,0,0,0".to_owned(),
    ];
    let cases: [(&str, Vec<String>, &str); 5] = [
        ("truncated.nav", truncated, ":5: 7 columns, expected 11"),
        (
            "word.nav",
            not_number,
            ":7: field lon: not a number: \"7.6x12",
        ),
        (
            "backwards.nav",
            backwards,
            ":4: field sow: time 0.02 does not increase",
        ),
        (
            "missing.csv",
            csv_missing,
            ":1: field yaw_deg: the header lacks column yaw_deg",
        ),
        ("nan.csv", csv_nan, ":3: field h_m: not finite"),
    ];
    for (name, text, message) in cases {
        let bad = write_lines(dir.path(), name, &text);
        let expected = format!("{}{message}", bad.display());
        compare(&bad, &truth, &dir.path().join("o"), &[])
            .code(1)
            .stderr(predicates::str::contains(expected));
        // The same file as the truth is named the same way.
        compare(&truth, &bad, &dir.path().join("o"), &[])
            .code(1)
            .stderr(predicates::str::contains(name));
    }
    compare(&truth, &truth, &dir.path().join("o"), &["--outages", "5-3"])
        .code(2)
        .stderr(predicates::str::contains("must end after it starts"));
}

/// Errors with a horizontal error of `h[i]` m (north only) at t = i s.
fn north_errors(h: &[f64]) -> Vec<EpochErrors> {
    h.iter()
        .enumerate()
        .map(|(i, &x)| EpochErrors {
            t_sow: i as f64,
            pos_n: Vector3::new(x, 0.0, -x / 2.0),
            v_n: Vector3::zeros(),
            att: Euler::new(0.0, 0.0, x.to_radians() / 100.0),
            psi: Vector3::new(0.0, 0.0, -x.to_radians() / 100.0),
            interpolated: false,
        })
        .collect()
}

/// (5) Statistics of 1..100 m in scrambled order, by their definitions: nearest-rank
/// percentiles (the smallest value at least P % of the values do not exceed) give
/// CEP = 50 m and CEP95 = 95 m; RMS = sqrt(101 x 201 / 6) m; mean 50.5 m; the max at
/// its own epoch. Outage maxima and their RMS by hand.
#[test]
fn percentiles_and_cep_follow_their_definitions() {
    // 37 is prime to 100: k -> 37 k mod 100 + 1 visits 1..100 once each.
    let h: Vec<f64> = (0..100).map(|k| f64::from((37 * k) % 100 + 1)).collect();
    let t_of_100 = h.iter().position(|&x| x == 100.0).expect("100") as f64;
    let s = statistics(
        &north_errors(&h),
        &[(0.0, 9.0), (50.0, 50.0), (200.0, 300.0)],
    )
    .expect("stats");
    assert_eq!(s.epochs, 100);
    assert_eq!(s.cep, 50.0);
    assert_eq!(s.cep95, 95.0);
    let hor = s.get("horizontal").expect("horizontal");
    assert_eq!(hor.p95_abs, 95.0);
    assert_eq!(hor.max_abs, 100.0);
    assert_eq!(hor.t_max_sow, t_of_100);
    assert!((hor.rms - (101.0f64 * 201.0 / 6.0).sqrt()).abs() < 1e-12);
    assert!((hor.mean - 50.5).abs() < 1e-12);
    // Signed: the down error is -h/2, so its mean is negative and |e| percentiles halve.
    let down = s.get("vertical (down)").expect("down");
    assert!((down.mean + 25.25).abs() < 1e-12);
    assert_eq!(down.p95_abs, 47.5);
    // Outages: epochs 0..=9 hold h = 1, 38, 75, 12, 49, 86, 23, 60, 97, 34 (max 97);
    // epoch 50 holds 37 * 50 mod 100 + 1 = 51; the third holds no epoch.
    assert_eq!(s.outages[0].epochs, 10);
    assert_eq!(s.outages[0].horizontal, 97.0);
    assert_eq!(s.outages[0].vertical, 48.5);
    assert_eq!(s.outages[1].horizontal, 51.0);
    assert_eq!(s.outages[2].epochs, 0);
    let rms = s.outage_rms.expect("rms");
    assert_eq!(rms.epochs, 2);
    assert!((rms.horizontal - ((97.0f64.powi(2) + 51.0f64.powi(2)) / 2.0).sqrt()).abs() < 1e-12);
    assert!((rms.att.yaw.to_degrees() - rms.horizontal / 100.0).abs() < 1e-12);

    // 20 values: the 95th percentile is the ceil(19)th = 19th, the median the 10th.
    let s = statistics(
        &north_errors(&(1..=20).map(f64::from).collect::<Vec<_>>()),
        &[],
    )
    .expect("stats");
    assert_eq!((s.cep, s.cep95), (10.0, 19.0));
    assert!(s.outage_rms.is_none());
}
