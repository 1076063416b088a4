//! Tight against loose coupling through the command line, on the drive with raw GNSS
//! (`examples/drive_raw.toml`: 20 minutes, a tactical IMU at 200 Hz, GPS
//! pseudoranges and Dopplers at 1 Hz with a drifting receiver clock, 20 % of the
//! ionosphere and 5 % of the troposphere left uncorrected, correlated multipath; 3
//! satellites for 60 s, then 2 for 30 s; a 50-m step on G17 for 20 s).
//!
//! Both filters see the same observations: the loose one takes the single-point
//! solutions `schuler gnss` makes of them (`solution.pos`, none with fewer than four
//! satellites), the tight one the observations themselves (`--gnss-obs`/`--gnss-nav`).
//! Errors are taken once a second against the simulator's `truth.nav`.

use serde_json::Value;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use crate::common;
use common::{nav_drive_gnss, simulate};

use schuler::analysis::errors::errors_between;
use schuler::earth::Wgs84;
use schuler::nav::NavState;
use schuler_io::formats::nav::read_nav;

/// The raw windows and the fault, in scenario time (GPS seconds of week 1590).
const FEW: (f64, f64) = (353_200.0, 353_290.0);
const FAULT: (f64, f64) = (353_600.0, 353_620.0);

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/drive_raw.toml")
}

/// `schuler nav` of the simulated drive with the GNSS flags `gnss` and the truth.
fn nav(sim: &Path, out: &Path, gnss: &[&OsStr]) {
    let truth = sim.join("truth.nav");
    nav_drive_gnss(sim, out, gnss, &["--truth".as_ref(), truth.as_os_str()]).success();
}

fn nav_tight(sim: &Path, out: &Path) {
    let (obs, eph) = (sim.join("gnss_obs.rnx"), sim.join("gnss_nav.rnx"));
    nav(
        sim,
        out,
        &[
            "--gnss-obs".as_ref(),
            obs.as_os_str(),
            "--gnss-nav".as_ref(),
            eph.as_os_str(),
        ],
    );
}

/// `(t, horizontal error [m])` at each whole second of `out/nav.txt` against the truth.
fn horizontal_errors(out: &Path, sim: &Path) -> Vec<(f64, f64)> {
    let (_, truth) = read_nav(&sim.join("truth.nav")).expect("truth.nav");
    let (_, nav) = read_nav(&out.join("nav.txt")).expect("nav.txt");
    let (t0, dt) = (truth[0].t_sow, truth[1].t_sow - truth[0].t_sow);
    nav.iter()
        .filter(|r| (r.t_sow - r.t_sow.round()).abs() < 1e-6)
        .filter_map(|r| {
            let k = ((r.t_sow - t0) / dt).round() as usize;
            let t = truth.get(k)?;
            assert!(
                (t.t_sow - r.t_sow).abs() < 1e-6,
                "{} vs {}",
                t.t_sow,
                r.t_sow
            );
            let e = errors_between(&Wgs84, &NavState::from(r), &NavState::from(t));
            Some((r.t_sow, e.pos_n.xy().norm()))
        })
        .collect()
}

fn rms(xs: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = xs.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
    assert!(n > 0, "no errors");
    (s / n as f64).sqrt()
}

fn worst_in(e: &[(f64, f64)], (t0, t1): (f64, f64)) -> f64 {
    e.iter()
        .filter(|(t, _)| *t >= t0 && *t < t1)
        .map(|x| x.1)
        .fold(0.0, f64::max)
}

/// The mean NEES (3 dof) of position, velocity and attitude in `consistency.json`,
/// sampled once a second: successive seconds are correlated through the filter's
/// memory (tens of seconds), so the mean of ~1100 is that of about 40 independent
/// draws: χ²(120)/40 at 0.1 % and 99.9 %, 2.2–4.0 for 3 dof; wider still (1.5–5),
/// as the library's tight-coupling tests take it, because the multipath and the
/// atmosphere left over are correlated over 20 s and more and the filter models
/// them as white.
fn assert_nees_consistent(out: &Path) {
    let j: Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("consistency.json")).expect("consistency.json"),
    )
    .expect("json");
    for block in ["position", "velocity", "attitude"] {
        let mean = j["nees"][block]["mean"].as_f64().expect("mean");
        println!("mean {block} NEES {mean:.2} (3 dof)");
        assert!(mean > 1.5 && mean < 5.0, "{block}: mean NEES {mean}");
    }
}

#[test]
fn tight_against_loose_on_the_raw_drive() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = simulate(&example(), dir.path());
    let spp = dir.path().join("spp");
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["gnss", "--gnss-obs"])
        .arg(sim.join("gnss_obs.rnx"))
        .arg("--gnss-nav")
        .arg(sim.join("gnss_nav.rnx"))
        .arg("--out")
        .arg(&spp)
        .assert()
        .success();
    let (loose, tight) = (dir.path().join("loose"), dir.path().join("tight"));
    let pos = spp.join("solution.pos");
    nav(&sim, &loose, &["--gnss".as_ref(), pos.as_os_str()]);
    nav_tight(&sim, &tight);
    let (el, et) = (
        horizontal_errors(&loose, &sim),
        horizontal_errors(&tight, &sim),
    );
    assert_eq!(el.len(), et.len());

    // Full sky: away from the windows (and the time the loose filter takes to come
    // back after them) and the fault, the two agree to 10 %.
    let full_sky = |e: &[(f64, f64)]| {
        rms(e
            .iter()
            .filter(|(t, _)| !(FEW.0..FEW.1 + 60.0).contains(t) && !(FAULT.0..FAULT.1).contains(t))
            .map(|x| x.1))
    };
    let (rl, rt) = (full_sky(&el), full_sky(&et));
    println!("full sky: horizontal RMS {rl:.3} m loose, {rt:.3} m tight");
    assert!(rt <= 1.1 * rl, "tight {rt} m against loose {rl} m");

    // 3 then 2 satellites: no fix at all for the loose filter (free inertial), the
    // tight one held by each range. Both curves printed.
    for ((t, l), (_, h)) in el
        .iter()
        .zip(&et)
        .filter(|((t, _), _)| (FEW.0 - 5.0..FEW.1 + 5.0).contains(t))
    {
        println!("t {t:.0} s  horizontal error: loose {l:6.3} m, tight {h:6.3} m");
    }
    let (wl, wt) = (worst_in(&el, FEW), worst_in(&et, FEW));
    println!("3 then 2 satellites: worst horizontal error {wl:.3} m loose, {wt:.3} m tight");
    assert!(wt <= wl / 3.0, "tight {wt} m against loose {wl} m");
    assert_nees_consistent(&tight);

    // `--init gnss` with no start given: the single-point solutions give the position
    // and the course at the first long straight chord (the acceleration after the
    // first minute's hold); from the end of the first turn on (t > 352 900 s, the
    // heading then observable) the run tracks as the run from the true start does.
    let started = dir.path().join("started");
    let (obs, eph) = (sim.join("gnss_obs.rnx"), sim.join("gnss_nav.rnx"));
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(sim.join("imu.txt"))
        .arg("--gnss-obs")
        .arg(&obs)
        .arg("--gnss-nav")
        .arg(&eph)
        .args([
            "--init",
            "gnss",
            "--lever-arm",
            "0.5,0,-1",
            "--imu-grade",
            "tactical",
        ])
        .args(["--output-rate", "10", "--out"])
        .arg(&started)
        .assert()
        .success();
    let es = horizontal_errors(&started, &sim);
    let late = |e: &[(f64, f64)]| {
        rms(e
            .iter()
            .filter(|(t, _)| *t > 352_900.0 && !(FEW.0..FEW.1 + 60.0).contains(t))
            .map(|x| x.1))
    };
    let (rs, rt_late) = (late(&es), late(&et));
    println!("--init gnss: horizontal RMS {rs:.3} m, from the true start {rt_late:.3} m");
    assert!(rs <= 1.2 * rt_late, "{rs} m against {rt_late} m");

    // The 50-m step: G17's pseudoranges refused, each alone, one a second.
    let rejected = std::fs::read_to_string(tight.join("rejected.csv")).expect("rejected.csv");
    let in_fault: Vec<&str> = rejected
        .lines()
        .skip(1)
        .filter(|l| {
            let t: f64 = l.split(',').next().and_then(|x| x.parse().ok()).expect("t");
            (FAULT.0..FAULT.1 + 1.0).contains(&t)
        })
        .collect();
    assert_eq!(in_fault.len(), 20, "{in_fault:?}");
    assert!(
        in_fault.iter().all(|l| l.contains("pseudorange G17")),
        "{in_fault:?}"
    );

    // And the solution holds: against the same drive without the step (same seed,
    // same draws; only G17's pseudoranges differ), it moves less than 1 m.
    let text = std::fs::read_to_string(example()).expect("example");
    let clean_text = without_fault(&text);
    let clean_dir = dir.path().join("clean");
    std::fs::create_dir(&clean_dir).expect("dir");
    let clean_config = clean_dir.join("drive_raw_clean.toml");
    // The nav file is named relative to the scenario: keep it found.
    let clean_text = clean_text.replace(
        "nav = \"../tests/data/",
        &format!(
            "nav = \"{}/",
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../tests/data")
                .display()
        ),
    );
    std::fs::write(&clean_config, clean_text).expect("write");
    let clean_sim = simulate(&clean_config, &clean_dir);
    let clean = clean_dir.join("tight");
    nav_tight(&clean_sim, &clean);
    let (_, a) = read_nav(&tight.join("nav.txt")).expect("nav");
    let (_, b) = read_nav(&clean.join("nav.txt")).expect("nav");
    let moved = a
        .iter()
        .zip(&b)
        .map(|(x, y)| {
            errors_between(&Wgs84, &NavState::from(x), &NavState::from(y))
                .pos_n
                .norm()
        })
        .fold(0.0, f64::max);
    println!("the step moved the solution by at most {moved:.4} m");
    assert!(moved < 1.0, "{moved} m");
}

/// The scenario text without its `[[gnss.raw.fault]]` block.
fn without_fault(text: &str) -> String {
    let mut out = String::new();
    let mut skipping = false;
    for line in text.lines() {
        if line.trim_start().starts_with('[') {
            skipping = line.trim() == "[[gnss.raw.fault]]";
        }
        if !skipping {
            out.push_str(line);
            out.push('\n');
        }
    }
    assert_ne!(out.len(), text.len(), "the example has a fault block");
    out
}
