//! `schuler budget` (`schuler_run::budget`) on `examples/drive.toml` as it is: a
//! 20-minute drive at 200 Hz, tactical IMU, GNSS at 1 Hz with a 60-s outage
//! (400–460 s), the filter nav's default for an aided run (tactical). The closed-form
//! checks of the propagation itself are the library's
//! (`schuler::analysis::budget`'s tests); here: the wiring, the tables, and that the
//! shares add up to the whole.

use assert_cmd::Command;
use schuler_run::budget;
use schuler_run::campaign::CampaignConfig;
use std::path::{Path, PathBuf};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/drive.toml")
}

/// The shares add up to the whole at the outage's end and at the end, within 1e-9
/// (round-off over some 2,700 updates; found 1e-12 in the library's test); the
/// horizontal σ grows through the outage and falls back after it; the sources the
/// drive has are named (the scenario's GNSS velocity is not given to the filter by
/// default, `[campaign] gnss_velocity`).
#[test]
fn the_drive_budget_adds_up_and_follows_the_outage() {
    let c = CampaignConfig::load(&example()).expect("the example drive");
    let r = budget::run(&c).expect("budget");
    assert!(r.largest_gap < 1e-9, "{:e}", r.largest_gap);
    let events: Vec<(&str, f64)> = r.shares.iter().map(|s| (s.event.as_str(), s.t)).collect();
    assert_eq!(events.len(), 2, "{events:?}");
    assert_eq!(events[0].0, "outage 1 end");
    assert!((events[0].1 - 460.0).abs() < 0.01, "{events:?}");
    assert_eq!(events[1].0, "end");
    assert!(r.sources.iter().any(|s| s == "noise_gnss_position"));
    assert!(r.sources.iter().any(|s| s == "gyro_bias"));
    let h = |t: f64| {
        let row = r.sigma.iter().find(|s| (s.t - t).abs() < 0.5).expect("row");
        row.std[0].xy().norm()
    };
    assert!(h(459.0) > 3.0 * h(399.0), "{} vs {}", h(459.0), h(399.0));
    assert!(h(500.0) < 0.5 * h(459.0), "{} vs {}", h(500.0), h(459.0));
    // One row a second from the start (0 s) to the drive's end (1099 s).
    assert_eq!(r.sigma.len(), 1100);
    assert!(
        r.sigma
            .windows(2)
            .all(|w| (w[1].t - w[0].t - 1.0).abs() < 1e-6)
    );
}

/// The command writes both tables, one `shares.csv` row per source and event plus the
/// whole's.
#[test]
fn the_command_writes_the_tables() {
    let dir = tempfile::tempdir().expect("temp dir");
    Command::cargo_bin("schuler")
        .expect("binary")
        .arg("budget")
        .arg("--config")
        .arg(example())
        .arg("--out")
        .arg(dir.path())
        .assert()
        .success();
    let sigma = std::fs::read_to_string(dir.path().join("sigma.csv")).expect("sigma.csv");
    assert!(sigma.starts_with("t_s,pos_n_m,"));
    assert_eq!(sigma.lines().count(), 1101);
    let shares = std::fs::read_to_string(dir.path().join("shares.csv")).expect("shares.csv");
    let totals: Vec<&str> = shares.lines().filter(|l| l.contains(",total,")).collect();
    assert_eq!(totals.len(), 2, "{shares}");
    // The fractions of the horizontal position variance add up to 1 (printed to 6
    // decimals, so within 1e-5 over some 14 sources).
    for event in ["outage 1 end", "end"] {
        let sum: f64 = shares
            .lines()
            .filter(|l| l.starts_with(event) && !l.contains(",total,"))
            .map(|l| {
                l.split(',')
                    .nth(4)
                    .expect("fraction")
                    .parse::<f64>()
                    .expect("number")
            })
            .sum();
        assert!((sum - 1.0).abs() < 1e-5, "{event}: {sum}");
    }
}
