//! Peak memory of a session on long logs (issue 22): the forward filter on 1 h and
//! 10 h at 200 Hz, and the Rauch–Tung–Striebel smoother on 1 h at 200 Hz and 10 h at
//! 1 kHz, every one with 1-Hz GNSS fixes and an output epoch at every sample (as
//! `schuler nav` by default), the epochs and events taken as they come and the
//! smoothed trajectory read to its end. Each case runs in a child process of this
//! binary, which reports its own peak resident set (`VmHWM` of /proc/self/status,
//! Linux), so the figures are the peaks of one case each.
//!
//! `cargo bench -p schuler --bench memory` prints the table; `-- forward-1h` (or any
//! part of a case's name, e.g. `soak`) runs only those cases. The IMU is at rest (exact increments of the Earth's
//! rate and gravity, the same every sample) so that generating the log costs neither
//! time nor memory; what the session keeps does not depend on the motion.

use nalgebra::Vector3;
use schuler::earth::{Geodetic, Wgs84};
use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig};
use schuler::imu::ImuSample;
use schuler::rotation::Euler;
use schuler::session::{Aid, FilterConfig, Session, SessionConfig, Start};
use schuler::sim::analytic::{self, Stationary};
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use std::process::Command;
use std::time::Instant;

/// A case: its name, hours of log, IMU rate [Hz], whether it smooths.
/// The `soak` cases are issue "Reliability"'s: the forward filter over a day at 1 kHz,
/// its peak at 1 h, 6 h and 24 h.
const CASES: [(&str, f64, f64, bool); 7] = [
    ("forward-1h-200Hz", 1.0, 200.0, false),
    ("forward-10h-200Hz", 10.0, 200.0, false),
    ("smoother-1h-200Hz", 1.0, 200.0, true),
    ("smoother-10h-1kHz", 10.0, 1000.0, true),
    ("soak-1h-1kHz", 1.0, 1000.0, false),
    ("soak-6h-1kHz", 6.0, 1000.0, false),
    ("soak-24h-1kHz", 24.0, 1000.0, false),
];

/// The peak resident set of this process [kB].
fn peak_rss_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Run one case in this process; prints `samples epochs smoothed seconds peak_kB`.
fn run(hours: f64, rate: f64, smooth: bool) {
    let clock = Instant::now();
    let here = Stationary {
        pos: Geodetic::from_degrees(45.07, 7.68, 245.0),
        attitude: Euler::new(0.0, 0.0, 0.3),
    };
    let dt = 1.0 / rate;
    let at_rest: Vec<ImuSample> = analytic::samples(&Wgs84, &here, -dt, dt, 1).collect();
    let noise = ImuNoise::from_model(
        &ImuSpec::of_preset(rate, Preset::Tactical)
            .model()
            .expect("preset"),
    );
    let config = SessionConfig {
        output_rate: None,
        snapshot_rate: 0.0,
        filter: Some(FilterConfig {
            smooth,
            ..FilterConfig::new(IntegrationConfig::new(noise))
        }),
        ..SessionConfig::default()
    };
    let start = Start::at(analytic::state(&Wgs84, &here, 0.0));
    let mut session = Session::new(Wgs84, config, start).expect("session");
    let n = (hours * 3600.0 * rate) as u64;
    let (mut epochs, mut smoothed) = (0u64, 0u64);
    for k in 0..=n {
        let t = k as f64 * dt;
        // The fix of each whole second is pushed just before the sample that reaches it.
        if k % rate as u64 == 1 {
            let second = t.ceil();
            let fix = GnssFix {
                t: second,
                pos: here.pos,
                pos_std: Vector3::new(0.5, 0.5, 1.0),
                vel: None,
            };
            session.push(Aid::Gnss(fix)).expect("fix");
        }
        session
            .push_imu(ImuSample { t, ..at_rest[0] })
            .expect("sample");
        epochs += session.epochs().count() as u64;
        session.events().for_each(drop);
    }
    let mut finished = session.finish().expect("finish");
    epochs += finished.epochs.len() as u64;
    if let Some(trajectory) = finished.smoothed.take() {
        for s in trajectory.states(Wgs84) {
            s.expect("smoothed state");
            smoothed += 1;
        }
    }
    println!(
        "{} {epochs} {smoothed} {:.1} {}",
        n + 1,
        clock.elapsed().as_secs_f64(),
        peak_rss_kb().unwrap_or(0)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(i) = args.iter().position(|a| a == "--case") {
        let name = args.get(i + 1).map(String::as_str).unwrap_or("");
        let Some(&(_, hours, rate, smooth)) = CASES.iter().find(|c| c.0 == name) else {
            eprintln!("unknown case {name}");
            std::process::exit(2);
        };
        run(hours, rate, smooth);
        return;
    }
    let only: Vec<&String> = args.iter().filter(|a| !a.starts_with('-')).collect();
    let exe = std::env::current_exe().expect("this benchmark's path");
    println!("| case | samples | output epochs | smoothed epochs | seconds | peak RSS |");
    println!("|---|---|---|---|---|---|");
    for (name, ..) in CASES {
        if !only.is_empty() && !only.iter().any(|o| name.contains(o.as_str())) {
            continue;
        }
        let out = Command::new(&exe)
            .args(["--case", name])
            .output()
            .expect("run a case");
        let text = String::from_utf8_lossy(&out.stdout);
        let v: Vec<&str> = text.split_whitespace().collect();
        match (out.status.success(), v.as_slice()) {
            (true, [samples, epochs, smoothed, seconds, kb]) => {
                let mb = kb.parse::<f64>().unwrap_or(f64::NAN) / 1024.0;
                println!("| {name} | {samples} | {epochs} | {smoothed} | {seconds} | {mb:.1} MB |");
            }
            _ => println!(
                "| {name} | failed: {} |",
                String::from_utf8_lossy(&out.stderr).trim()
            ),
        }
    }
}
