//! `schuler gnss` on the public stations of `tests/data/rinex_obs`, against coordinates
//! that do not come from a code solution: `stations.toml` there (IGS weekly SINEX moved
//! to the observation epoch, or the European header's ETRS89 turned into ITRF2014, or
//! GSI's header for GEONET 0759; README.md, "Station coordinates").
//!
//! Each station's horizontal and vertical RMS of the single-point positions about the
//! antenna reference point is bounded by what RTKLIB 2.4.2 p13 `rnx2rtkp` does on the
//! same files with the same settings (single mode, L1 C/A, GPS only, elevation mask 10°,
//! broadcast Klobuchar ionosphere, Saastamoinen troposphere, RAIM FDE on, elevation
//! weights err = 0.003 m × eratio 100), measured for this test and tabulated in
//! docs/validation/gnss_spp.md. The bound is rnx2rtkp's figure plus a margin (stated per
//! station) that covers the reference's own uncertainty and the differences of the two
//! solvers that are not errors of either (schuler maps the troposphere by DO-229 with
//! 50 % humidity where rnx2rtkp uses 1/sin E with 70 %, weights by 1/sin²el where 2.4.2
//! uses 1/sin el, and excludes one faulty satellite at a time by Baarda's w-test where
//! rnx2rtkp tries every subset of n − 1; the two solutions differ by 0.1–0.9 m per
//! epoch): so a regression of schuler to clearly worse than RTKLIB fails, while these
//! differences do not.

use assert_cmd::Command;
use schuler::earth::{EarthModel, Wgs84, c_ne};
use schuler_io::formats::nav::read_nav;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/rinex_obs")
        .join(name)
}

/// One station of `stations.toml`.
struct Station {
    name: String,
    obs: String,
    nav: Vec<String>,
    /// Antenna reference point, ECEF [m].
    arp: nalgebra::Vector3<f64>,
}

fn stations() -> Vec<Station> {
    let text = std::fs::read_to_string(data("stations.toml")).expect("stations.toml");
    let doc: toml::Table = text.parse().expect("stations.toml parses");
    let list = doc["station"].as_array().expect("[[station]]");
    list.iter()
        .map(|s| {
            let f = |k: &str| s[k].as_float().unwrap_or_else(|| panic!("{k} is a number"));
            let marker = nalgebra::Vector3::new(f("x"), f("y"), f("z"));
            let p = Wgs84.ecef_to_geodetic(&marker);
            // The ellipsoidal normal (up) at the marker, the third column of C_n^e
            // negated (down is the third axis of NED).
            let up = -c_ne(p.lat, p.lon).column(2).into_owned();
            Station {
                name: s["name"].as_str().expect("name").to_string(),
                obs: s["obs"].as_str().expect("obs").to_string(),
                nav: s["nav"]
                    .as_array()
                    .expect("nav")
                    .iter()
                    .map(|n| n.as_str().expect("nav file").to_string())
                    .collect(),
                arp: marker + up * f("antenna_up"),
            }
        })
        .collect()
}

/// Runs `schuler gnss` on `s` and returns (solved epochs, horizontal RMS, vertical RMS)
/// about the antenna reference point [m].
fn solve(s: &Station) -> (usize, f64, f64) {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let mut cmd = Command::cargo_bin("schuler").expect("binary");
    cmd.args(["gnss", "--gnss-obs"]).arg(data(&s.obs));
    for n in &s.nav {
        cmd.arg("--gnss-nav").arg(data(n));
    }
    cmd.arg("--out")
        .arg(&out)
        .args(["--elevation-mask", "10", "--systems", "G"])
        .assert()
        .success();
    let (_, records) = read_nav(&out.join("nav.txt")).expect("nav.txt reads back");
    let p0 = Wgs84.ecef_to_geodetic(&s.arp);
    let c_en = c_ne(p0.lat, p0.lon).transpose();
    let (mut h2, mut v2) = (0.0, 0.0);
    for r in &records {
        let d = c_en * (Wgs84.geodetic_to_ecef(&r.pos) - s.arp);
        h2 += d.x * d.x + d.y * d.y;
        v2 += d.z * d.z;
    }
    let n = records.len();
    let (h, v) = ((h2 / n as f64).sqrt(), (v2 / n as f64).sqrt());
    eprintln!(
        "{}: {n} epochs, horizontal RMS {h:.3} m, vertical RMS {v:.3} m",
        s.name
    );
    (n, h, v)
}

fn station(name: &str) -> Station {
    stations()
        .into_iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("{name} in stations.toml"))
}

/// Every station with navigation data has a test below; the two without (AJAC and
/// ACOR, 2021-12-21: no broadcast file of that day was found) are listed so that one
/// added later is noticed.
#[test]
fn every_station_with_navigation_data_is_tested() {
    let mut with_nav: Vec<String> = stations()
        .into_iter()
        .filter(|s| !s.nav.is_empty())
        .map(|s| s.name)
        .collect();
    with_nav.sort();
    assert_eq!(with_nav, ["0759", "VLNS", "WSRA"]);
}

/// GEONET 0759, 2005-04-02 00:00–01:00, 120 epochs of 7–9 GPS satellites.
/// rnx2rtkp gives H 0.52 m, V 1.09 m (120 of 120 epochs) on these files with the options
/// above; our bound is H 0.72 m, V 1.29 m (rnx2rtkp's plus 0.2 m; schuler gave H 0.49 m,
/// V 0.80 m when this was written). The reference's own uncertainty (σ ≈ 0.3 m per axis
/// assumed, README.md) is shared by both solvers and already inside their figures.
#[test]
fn geonet_0759() {
    let (n, h, v) = solve(&station("0759"));
    assert_eq!(n, 120, "every epoch solves (rnx2rtkp solves 120)");
    assert!(h < 0.72, "horizontal RMS {h} m");
    assert!(v < 1.29, "vertical RMS {v} m");
}

/// WSRA (Westerbork), 2021-01-01 00:00–00:08, 17 epochs of 11 GPS satellites, against
/// the IGS05 coordinate moved to 2021.0 (σ ≈ 5 cm).
/// rnx2rtkp gives H 1.00 m, V 2.59 m (17 of 17 epochs) on these files with the options
/// above; our bound is H 1.20 m, V 2.79 m (rnx2rtkp's plus 0.2 m; schuler gave H 0.93 m,
/// V 2.16 m). Both sit 2.1–2.6 m low on average, so the cause is in what they share
/// (most likely Klobuchar's 5 ns night-time floor over-correcting a winter night's
/// ionosphere, which lowers the height), not in either solver.
#[test]
fn epn_wsra() {
    let (n, h, v) = solve(&station("WSRA"));
    assert_eq!(n, 17, "every epoch solves (rnx2rtkp solves 17)");
    assert!(h < 1.20, "horizontal RMS {h} m");
    assert!(v < 2.79, "vertical RMS {v} m");
}

/// VLNS (Vilnius), 2022-01-01 00:00–00:01, 3 epochs of 9 GPS satellites, against the
/// header's ETRS89 turned into ITRF2014 (σ ≈ 0.1 m).
/// rnx2rtkp gives H 1.89 m, V 0.11 m (3 of 3 epochs) on these files with the options
/// above; our bound is H 2.09 m (rnx2rtkp's plus 0.2 m) and V 0.50 m. schuler gave
/// V 0.34 m, worse than rnx2rtkp's here only, and the troposphere is why: rnx2rtkp maps
/// Saastamoinen's zenith delays by 1/sin E with 70 % humidity, schuler by DO-229's
/// 1.001/√(0.002001 + sin²E) (within 0.5 % of Niell's; 1/sin E is 3 % above it at 10°)
/// with 50 %; rnx2rtkp rebuilt with only those two changed gives V 0.28 m here (and
/// H 0.50/V 0.88 m on 0759, H 0.97/V 2.25 m on WSRA, closer to schuler's), i.e. it
/// moves most of the way to schuler's figure. Three epochs 30 s apart are one sample of
/// slowly varying errors; the 0.39 m above rnx2rtkp's figure is that model difference
/// plus 0.2 m.
#[test]
fn epn_vlns() {
    let (n, h, v) = solve(&station("VLNS"));
    assert_eq!(n, 3, "every epoch solves (rnx2rtkp solves 3)");
    assert!(h < 2.09, "horizontal RMS {h} m");
    assert!(v < 0.50, "vertical RMS {v} m");
}
