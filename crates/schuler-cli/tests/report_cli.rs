//! `schuler nav --gnss --baro --truth` on the simulated example drive (20 minutes at
//! 200 Hz, tactical IMU, GNSS at 1 Hz with a lever arm and a 60-s outage, a biased
//! barometer): innovations.csv, consistency.json against chi-square quantiles computed
//! outside the code, and report.html's structure (every section, every plot with
//! labelled axes and units, every linked file present, nothing external).

use serde_json::Value;
use std::ffi::OsStr;
use std::path::Path;

use crate::common;

/// `schuler nav --gnss --baro` of the simulated drive into `out`, with `extra` flags.
fn nav(sim: &Path, out: &Path, extra: &[&OsStr]) -> assert_cmd::assert::Assert {
    let baro = sim.join("baro.csv");
    let mut args: Vec<&OsStr> = vec!["--baro".as_ref(), baro.as_os_str()];
    args.extend_from_slice(extra);
    common::nav_drive(sim, out, &args)
}

/// Chi-square quantiles at 0.025 and 0.975 from mpmath 1.3.0 (the root of
/// `gammainc(k/2, 0, x/2, regularized=True) = p`, 9 significant digits).
const CHI2_1: (f64, f64) = (0.000_982_069_117, 5.023_886_19);
const CHI2_3: (f64, f64) = (0.215_795_283, 9.348_403_60);

/// The Wilson–Hilferty (1931) quantile `k (1 − 2/(9k) + z sqrt(2/(9k)))³`, within
/// 8e-5 relative of the exact one for k >= 100 (checked against mpmath at k = 100,
/// 290, 774, 2886).
fn wilson_hilferty(k: f64, z: f64) -> f64 {
    let c = 2.0 / (9.0 * k);
    k * (1.0 - c + z * c.sqrt()).powi(3)
}

const Z_975: f64 = 1.959_963_985;

fn pair(v: &Value) -> (f64, f64) {
    (v[0].as_f64().expect("lower"), v[1].as_f64().expect("upper"))
}

/// Checks one chi-square test object of consistency.json: its per-epoch interval
/// against the known quantiles, the interval of its mean against Wilson–Hilferty for
/// `count · dof` degrees of freedom.
fn check_test(t: &Value, dof: u64, quantiles: (f64, f64)) -> (u64, f64) {
    assert_eq!(t["dof"], dof, "{t}");
    let (lo, hi) = pair(&t["epoch_interval"]);
    // The library's quantiles are good to 1e-10; the references carry 9 digits.
    assert!(
        (lo / quantiles.0 - 1.0).abs() < 1e-8,
        "{lo} vs {}",
        quantiles.0
    );
    assert!(
        (hi / quantiles.1 - 1.0).abs() < 1e-8,
        "{hi} vs {}",
        quantiles.1
    );
    let n = t["count"].as_u64().expect("count");
    let k = (n * dof) as f64;
    let (mlo, mhi) = pair(&t["mean_interval"]);
    assert!(
        k >= 100.0,
        "{k} degrees of freedom: Wilson–Hilferty's bound needs 100"
    );
    assert!((mlo * n as f64 / wilson_hilferty(k, -Z_975) - 1.0).abs() < 1e-4);
    assert!((mhi * n as f64 / wilson_hilferty(k, Z_975) - 1.0).abs() < 1e-4);
    let mean = t["mean"].as_f64().expect("mean");
    assert_eq!(t["mean_inside"], mlo <= mean && mean <= mhi);
    (n, mean)
}

/// `innovations.csv`: one row per measurement tested, GNSS rows with 3 components,
/// baro rows with 1 (the others empty); returns the counts of GNSS and baro rows.
fn count_innovations(out: &Path) -> (u64, u64) {
    let innovations = std::fs::read_to_string(out.join("innovations.csv")).expect("csv");
    let mut lines = innovations.lines();
    assert_eq!(
        lines.next(),
        Some("t,kind,accepted,dof,nis,z_1,z_2,z_3,sigma_1,sigma_2,sigma_3")
    );
    let (mut gnss, mut baro) = (0u64, 0u64);
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        assert_eq!(f.len(), 11, "{l}");
        match f[1] {
            "gnss_position" => {
                gnss += 1;
                assert!(f[5..].iter().all(|x| x.parse::<f64>().is_ok()), "{l}");
            }
            "baro_height" => {
                baro += 1;
                assert!(f[6..8].iter().chain(&f[9..]).all(|x| x.is_empty()), "{l}");
            }
            other => panic!("unexpected kind {other}"),
        }
    }
    (gnss, baro)
}

/// `consistency.json`: NIS per kind over the accepted measurements (of the `gnss` and
/// `baro` tested), each mean inside its interval; NEES once a second against the truth.
fn assert_consistency(out: &Path, (gnss, baro): (u64, u64)) {
    let j: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("consistency.json")).expect("json"))
            .expect("parse");
    assert_eq!(j["probability"], 0.95);
    let nis = j["nis"].as_array().expect("nis");
    assert_eq!(nis.len(), 2, "{j}");
    for k in nis {
        let (dof, quantiles, tested) = match k["kind"].as_str() {
            Some("gnss_position") => (3, CHI2_3, gnss),
            Some("baro_height") => (1, CHI2_1, baro),
            other => panic!("unexpected kind {other:?}"),
        };
        let (accepted, mean) = check_test(&k["test"], dof, quantiles);
        assert_eq!(k["accepted"], accepted);
        assert_eq!(accepted + k["refused"].as_u64().expect("refused"), tested);
        // Innovations of a consistent filter are white: their average lies in the
        // interval of the mean (the simulator's errors are drawn from the tactical
        // preset the filter models).
        assert_eq!(k["test"]["mean_inside"], true, "{}: mean {mean}", k["kind"]);
    }
    // The drive lasts 1099.225 s (truth.nav's last epoch): one NEES at each whole
    // second from 0 to 1099.
    for block in ["position", "velocity", "attitude"] {
        let (epochs, _) = check_test(&j["nees"][block], 3, CHI2_3);
        assert_eq!(epochs, 1100, "{block}");
    }
}

/// `report.html`: every section, in the contents and in the body.
fn assert_sections(html: &str) {
    for id in [
        "measurements",
        "position",
        "sensors",
        "innovations",
        "nis",
        "nees",
        "files",
    ] {
        assert!(
            html.contains(&format!("<a href=\"#{id}\">")),
            "contents lack {id}"
        );
        assert!(
            html.contains(&format!("<section id=\"{id}\">")),
            "no section {id}"
        );
    }
}

/// Every plot of `report.html` has both axis labels with a unit in brackets and its
/// files exist in `out`; there is one figure per SVG in `report/`, as many as the
/// drive's run plots.
fn assert_figures(out: &Path, html: &str) {
    let mut figures = 0;
    for fig in html.split("<figure ").skip(1) {
        figures += 1;
        let head = &fig[..fig.find('>').expect("tag")];
        for attr in ["data-x-label=\"", "data-y-label=\""] {
            let at = head.find(attr).expect(attr) + attr.len();
            let label = &head[at..at + head[at..].find('"').expect("quote")];
            let open = label
                .find('[')
                .unwrap_or_else(|| panic!("no unit in {label:?}"));
            assert!(open > 0 && label[open..].len() > 2, "{label:?}");
        }
        assert!(fig.contains("<svg "), "figure without its plot");
        let caption = &fig[fig.find("<figcaption>").expect("caption")..];
        for href in caption.split("<a href=\"").skip(1) {
            let file = &href[..href.find('"').expect("quote")];
            assert!(out.join(file).is_file(), "{file} is missing");
        }
    }
    let svgs = std::fs::read_dir(out.join("report"))
        .expect("report dir")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "svg"))
        })
        .count();
    // position, 3 gyro + 3 accel bias + baro bias, 3 + 1 innovation components,
    // 2 NIS, 3 NEES.
    assert_eq!(svgs, 1 + 7 + 4 + 2 + 3);
    assert_eq!(figures, svgs);
}

/// `report.html` opens offline: no script, stylesheet link, image source or URL but
/// the SVG namespace.
fn assert_self_contained(html: &str) {
    for external in ["<script", "<link", " src=", "url(", "@import", "https://"] {
        assert!(!html.contains(external), "{external}");
    }
    assert_eq!(
        html.matches("http://").count(),
        html.matches("xmlns=\"http://www.w3.org/2000/svg\"").count()
    );
}

/// The report's statistics are `schuler compare`'s: the same CEP for `nav` against
/// `truth` (compared into `cmp`).
fn assert_cep_as_compare(html: &str, nav: &Path, truth: &Path, cmp: &Path) {
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .arg("compare")
        .arg(nav)
        .arg(truth)
        .arg("--out")
        .arg(cmp)
        .assert()
        .success();
    let c: Value =
        serde_json::from_str(&std::fs::read_to_string(cmp.join("compare.json")).expect("json"))
            .expect("parse");
    let cep = c["statistics"]["cep_m"].as_f64().expect("cep");
    assert!(html.contains(&format!("CEP {cep:.4} m")), "CEP {cep}");
}

#[test]
fn aided_run_writes_a_consistent_report() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = common::simulate_drive(dir.path());
    let out = dir.path().join("out");
    let truth = sim.join("truth.nav");
    let run = nav(&sim, &out, &["--truth".as_ref(), truth.as_os_str()]).success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).into_owned();
    println!("{stdout}");
    assert!(
        stdout.contains("NIS  gnss_position  3 dof: mean"),
        "{stdout}"
    );
    assert!(stdout.contains("NEES attitude"), "{stdout}");
    assert!(stdout.contains("report.html"), "{stdout}");
    let tested = count_innovations(&out);
    assert_consistency(&out, tested);
    let html = std::fs::read_to_string(out.join("report.html")).expect("html");
    assert_sections(&html);
    assert_figures(&out, &html);
    assert_self_contained(&html);
    let cmp = dir.path().join("compare");
    assert_cep_as_compare(&html, &out.join("nav.txt"), &truth, &cmp);
}

#[test]
fn no_report_keeps_the_consistency_files_and_bad_sensor_truth_names_its_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = common::simulate_drive(dir.path());
    let out = dir.path().join("plain");
    nav(&sim, &out, &["--no-report".as_ref()]).success();
    assert!(out.join("innovations.csv").is_file());
    assert!(out.join("consistency.json").is_file());
    assert!(!out.join("report.html").exists());
    assert!(!out.join("report").exists());

    // The simulator's sensor-error truth (imu_err.txt's layout, once a second) is
    // drawn in the sensor plots, and at the end of the drive the estimated vertical
    // accelerometer bias (observed through GNSS and baro heights) is within 3 sigma of
    // it. The filter has no scale-factor states here, so it takes the z scale factor
    // times the specific force, -g on a road, for bias: what it should match is
    // `b_z + s_z (-g)` (the tactical 300 ppm times g is 294 mGal, 20 sigma).
    let truth = sim.join("imu_err_truth.txt");
    let out = dir.path().join("with_truth");
    nav(&sim, &out, &["--sensor-truth".as_ref(), truth.as_os_str()]).success();
    let svg = std::fs::read_to_string(out.join("report/gyro_bias_x.svg")).expect("svg");
    assert!(svg.contains(">truth</text>"), "no truth in the legend");
    let last = |path: &Path| -> Vec<f64> {
        let rows = common::read_rows(path);
        rows.last().expect("a row").clone()
    };
    let (truth_end, estimate, std) = (
        last(&truth),
        last(&out.join("imu_err.txt")),
        last(&out.join("std.txt")),
    );
    assert!((truth_end[0] - estimate[0]).abs() < 1.0, "same end time");
    // Columns: accelerometer bias z [mGal] is 6 in imu_err.txt, 15 in std.txt; its
    // scale factor [ppm] 12 in imu_err.txt. g = 9.8062 m/s^2 at 45 deg, in mGal.
    let effective = truth_end[6] + truth_end[12] * 1e-6 * -980_620.0;
    let miss = (estimate[6] - effective).abs();
    println!(
        "accel bias z: estimate {} truth {} as bias {effective} sigma {}",
        estimate[6], truth_end[6], std[15]
    );
    assert!(miss < 3.0 * std[15], "{miss} mGal vs sigma {}", std[15]);
    let html = std::fs::read_to_string(out.join("report.html")).expect("html");
    assert!(
        !html.contains("<section id=\"nees\">"),
        "NEES without a truth"
    );
    assert!(html.contains("No truth given"));

    let truth = dir.path().join("sensor_truth.txt");
    std::fs::write(&truth, "0 1 -1 0.5 100 -50 20\n1 1 -1 0.5 1OO -50 20\n").expect("write");
    let e = nav(
        &sim,
        &dir.path().join("bad"),
        &["--sensor-truth".as_ref(), truth.as_os_str()],
    )
    .failure();
    let err = String::from_utf8_lossy(&e.get_output().stderr).into_owned();
    assert!(
        err.contains("sensor_truth.txt:2: field ab_x: not a number"),
        "{err}"
    );
}
