//! Monte-Carlo campaigns (`schuler montecarlo`, `schuler_run::campaign`) on
//! `examples/montecarlo.toml`: a 5-minute drive at 100 Hz with a tactical IMU, GNSS
//! at 1 Hz and a 30-s outage, navigated with the matching noise model.

use assert_cmd::Command;
use schuler::analysis::consistency::mean_bounds;
use schuler_run::campaign::{self, CampaignConfig, aggregate::Aggregate, csv};
use std::path::{Path, PathBuf};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/montecarlo.toml")
}

fn config() -> CampaignConfig {
    CampaignConfig::load(&example()).expect("the example campaign")
}

/// Each run is a pure function of (configuration, seed) computed on one thread, and
/// the rows come back in seed order: one thread and two give the same bytes, and the
/// CLI writes them.
#[test]
fn the_table_does_not_depend_on_the_thread_count() {
    let c = config();
    let table = |threads| {
        let r = campaign::run(&c, 6, 40, Some(threads)).expect("runs");
        csv(&r.into_iter().map(|r| r.row).collect::<Vec<_>>())
    };
    let (one, two) = (table(1), table(2));
    assert_eq!(one, two);
    assert_eq!(one.lines().count(), 7, "{one}");
    let seeds: Vec<&str> = one.lines().skip(1).map(|l| &l[..2]).collect();
    assert_eq!(seeds, ["40", "41", "42", "43", "44", "45"]);
    let dir = tempfile::tempdir().expect("temp dir");
    Command::cargo_bin("schuler")
        .expect("binary")
        .args([
            "montecarlo",
            "--runs",
            "6",
            "--seed",
            "40",
            "--threads",
            "2",
        ])
        .arg("--config")
        .arg(example())
        .arg("--out")
        .arg(dir.path())
        .assert()
        .success();
    let written = std::fs::read_to_string(dir.path().join("runs.csv")).expect("runs.csv");
    assert_eq!(written, one);
    let html = std::fs::read_to_string(dir.path().join("report.html")).expect("report");
    assert!(html.contains("<svg") && html.contains("NEES over the runs"));
}

/// A consistent filter's NEES of a 3-dof error, averaged over N independent runs at
/// one instant, is chi-square(3N)/N; its time average lies in that law's 95 %
/// interval (the `aggregate` module says why). The filter assumes the simulated
/// tactical IMU's own noise, so 20 runs must land there; the same filter told a
/// navigation-grade IMU (bias and noise 10-100x smaller than the truth) is
/// overconfident and must land far above.
#[test]
fn mean_nees_of_twenty_runs_lies_in_its_chi_square_interval() {
    let c = config();
    let runs = 20;
    let a = Aggregate::of(&campaign::run(&c, runs, 1, None).expect("runs"));
    let b = mean_bounds(runs as usize, 3, 0.95);
    let n = a.nees.as_ref().expect("NEES against the simulated truth");
    println!("mean NEES {:?} in [{:.3}, {:.3}]", n.grand_mean, b.lo, b.hi);
    for (block, m) in ["position", "velocity", "attitude"]
        .iter()
        .zip(n.grand_mean)
    {
        assert!(b.contains(m), "{block}: mean NEES {m}");
    }
    let mut wrong = config();
    wrong
        .nav_options
        .insert("imu_grade".into(), "navigation".into());
    let a = Aggregate::of(&campaign::run(&wrong, 5, 1, None).expect("runs"));
    let n = a.nees.as_ref().expect("NEES");
    println!("told a navigation-grade IMU: mean NEES {:?}", n.grand_mean);
    let b5 = mean_bounds(5, 3, 0.95);
    assert!(
        n.grand_mean.iter().any(|&m| m > 3.0 * b5.hi),
        "{:?}",
        n.grand_mean
    );
}

/// The campaign's configuration errors name the file and the key.
#[test]
fn a_bad_campaign_is_refused_with_its_file_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(example()).expect("example");
    std::fs::write(
        &path,
        text.replace("imu_grade = \"tactical\"", "imu_grade = \"wrong\""),
    )
    .expect("write");
    let out = Command::cargo_bin("schuler")
        .expect("binary")
        .args(["montecarlo", "--runs", "2", "--out"])
        .arg(dir.path().join("mc"))
        .arg("--config")
        .arg(&path)
        .assert()
        .failure();
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    // Refused before any run, naming the file, the table and the option.
    assert!(
        err.contains("bad.toml: [navigate]: option `imu_grade`: unknown variant `wrong`"),
        "{err}"
    );
}
