//! `schuler nav --gnss --baro` on `schuler simulate`'s output for the example drive
//! (a tactical IMU at 200 Hz, GNSS at 1 Hz with a lever arm and a 60-s outage,
//! a barometer with a 3-m bias): the barometer holds the height through the outage.

use std::path::Path;
mod common;

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
    let sim = dir.path().join("sim");
    common::simulate_example_drive(&sim);
    let run = |name: &str, baro: bool| {
        let out = dir.path().join(name);
        let mut c = assert_cmd::Command::cargo_bin("schuler").expect("binary");
        c.args(["nav", "--imu"])
            .arg(sim.join("imu.txt"))
            .arg("--gnss")
            .arg(sim.join("gnss.txt"))
            .args(["--init-pos", "45.07,7.68,245", "--init-att", "0,0,10"])
            .args([
                "--lever-arm",
                "0.5,0,-1",
                "--imu-grade",
                "tactical",
                "--output-rate",
                "10",
                "--out",
            ])
            .arg(&out);
        if baro {
            c.arg("--baro")
                .arg(sim.join("baro.csv"))
                .args(["--baro-std", "0.5 m"]);
        }
        c.assert().success();
        vertical_max_in(&out.join("nav.txt"), &sim.join("truth.nav"), 400.0, 460.0)
    };
    let (without, with) = (run("gnss", false), run("baro", true));
    println!("vertical max in the outage: GNSS only {without:.3} m, with baro {with:.3} m");
    assert!(with < without, "{with} vs {without}");
    // The barometer's 0.5 m noise, averaged by the filter, with its bias estimated
    // under GNSS beforehand.
    assert!(with < 1.0, "{with}");
}
