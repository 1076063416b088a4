//! Tight against loose coupling, whole `schuler nav` processes (issue 31: one hour of a
//! 200-Hz IMU with 1-Hz observations of about ten satellites, tightly coupled, in at
//! most twice the loosely coupled run's time).
//!
//! `schuler simulate` writes the data once (a one-hour car drive, tactical IMU at
//! 200 Hz, GPS fixes at 1 Hz and the raw observations of the nominal 24-satellite
//! constellation at 1 Hz, a 5° mask: 9 to 12 satellites); then loose (`--gnss
//! gnss.txt`) and tight (`--gnss-obs gnss_obs.rnx --gnss-nav gnss_nav.rnx`) runs
//! alternate after a warm-up of each, reading their inputs and writing 1-Hz output,
//! no report. Prints each run's wall time, the medians and their ratio.
//!
//! `cargo bench -p schuler-cli --bench nav_tight`

use std::path::Path;
use std::process::Command;
use std::time::Instant;

const PAIRS: usize = 5;

const SCENARIO: &str = r#"
seed = 11
earth = "wgs84"

[start]
time = 352800.0
position = ["45.07 deg", "7.68 deg", "245 m"]
attitude = ["0 deg", "0 deg", "10 deg"]

[[motion]]
type = "hold"
duration = "60 s"

[[motion]]
type = "accelerate"
to_speed = "20 m/s"
accel = "1 m/s^2"

[[motion]]
type = "turn"
angle = "90 deg"
rate = "3 deg/s"

[[motion]]
type = "hold"
duration = "3480 s"

[imu]
rate_hz = 200
preset = "tactical"

[gnss]
rate_hz = 1
position_std = ["0.5 m", "0.5 m", "1 m"]
velocity_std = ["0.05 m/s", "0.05 m/s", "0.1 m/s"]

[gnss.raw]
week = 1590
rate_hz = 1
systems = ["G"]
signals = ["1C"]
elevation_mask = "5 deg"
clock_bias = "250 us"
clock_drift = "40 ppb"
"#;

fn schuler() -> Command {
    Command::new(env!("CARGO_BIN_EXE_schuler"))
}

/// Wall time of one `schuler nav` of the simulated drive with the GNSS flags `gnss`.
fn nav(sim: &Path, out: &Path, gnss: &[&std::ffi::OsStr]) -> f64 {
    let t = Instant::now();
    let status = schuler()
        .args(["nav", "--imu"])
        .arg(sim.join("imu.txt"))
        .args(gnss)
        .args(["--init-pos", "45.07,7.68,245", "--init-att", "0,0,10"])
        .args([
            "--imu-grade",
            "tactical",
            "--output-rate",
            "1",
            "--no-report",
        ])
        .arg("--out")
        .arg(out)
        .output()
        .expect("schuler nav runs");
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    t.elapsed().as_secs_f64()
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn main() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("nav_tight");
    let sim = dir.join("sim");
    if !sim.join("gnss_obs.rnx").exists() {
        std::fs::create_dir_all(&dir).expect("bench directory");
        let config = dir.join("drive_1h.toml");
        std::fs::write(&config, SCENARIO).expect("scenario");
        let ok = schuler()
            .args(["simulate", "--config"])
            .arg(&config)
            .arg("--out")
            .arg(&sim)
            .status()
            .expect("schuler simulate runs");
        assert!(ok.success(), "simulate failed");
    }
    let (gnss, obs, eph) = (
        sim.join("gnss.txt"),
        sim.join("gnss_obs.rnx"),
        sim.join("gnss_nav.rnx"),
    );
    let loose_flags = ["--gnss".as_ref(), gnss.as_os_str()];
    let tight_flags = [
        "--gnss-obs".as_ref(),
        obs.as_os_str(),
        "--gnss-nav".as_ref(),
        eph.as_os_str(),
    ];
    let out = dir.join("out");
    nav(&sim, &out, &loose_flags);
    nav(&sim, &out, &tight_flags);
    let (mut loose, mut tight) = (Vec::new(), Vec::new());
    for k in 0..PAIRS {
        loose.push(nav(&sim, &out, &loose_flags));
        tight.push(nav(&sim, &out, &tight_flags));
        println!("pair {k}: loose {:.3} s, tight {:.3} s", loose[k], tight[k]);
    }
    let (l, t) = (median(loose), median(tight));
    println!(
        "1 h at 200 Hz, 1-Hz GNSS: loose {l:.3} s, tight {t:.3} s (medians of {PAIRS}); \
         tight/loose {:.2}",
        t / l
    );
}
