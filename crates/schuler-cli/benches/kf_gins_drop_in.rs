//! Criterion benchmark of `schuler nav --kf-gins-config` end to end (issue 22: the
//! KF-GINS drop-in on 360,000 samples, 30 min at 200 Hz, with 1-Hz GNSS, against
//! KF-GINS timed on the same files on the same machine). The files (KF-GINS IMU text,
//! 13 significant digits, of an exact maneuvering flight; KF-GINS GNSS text with a fix
//! at every whole second from the same truth, 0.05 m / 0.1 m std) and the YAML are
//! written once into the target's bench directory, whose path is printed, so that
//! KF-GINS can be run on the very same files (`KF-GINS kf-gins.yaml` there).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler::earth::{Geodetic, Wgs84};
use schuler::sim::analytic::{self, Maneuvering};
use schuler_cli::commands::kf_gins::run;
use schuler_io::output::write_imu_text;
use schuler_run::kf_gins::KfGinsOptions;
use std::fmt::Write as _;
use std::path::PathBuf;

mod kf_gins_yaml;
use kf_gins_yaml::{T0, yaml};

const RATE_HZ: f64 = 200.0;
const SECONDS: usize = 1800;

/// The flight's files in the bench directory (written once); returns the YAML's path.
fn setup() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("kf_gins_drop_in");
    std::fs::create_dir_all(dir.join("out")).expect("bench directory");
    let imu = dir.join("imu.txt");
    let traj = Maneuvering::flight(Geodetic::from_degrees(30.5, 114.3, 500.0));
    let dt = 1.0 / RATE_HZ;
    let n = (SECONDS as f64 * RATE_HZ) as usize;
    if !imu.exists() {
        // The first sample ends at T0, KF-GINS's start; the trajectory's clock is the
        // files' clock.
        let samples = analytic::samples(&Wgs84, &traj, T0 - dt, dt, n + 1);
        write_imu_text(&imu, samples, 13).expect("write bench IMU file");
        let mut gnss = String::new();
        for k in 1..=SECONDS {
            let p = analytic::state(&Wgs84, &traj, T0 + k as f64).pos;
            let _ = writeln!(
                gnss,
                "{:.4} {:.12} {:.12} {:.6} 0.05 0.05 0.1",
                T0 + k as f64,
                p.lat.to_degrees(),
                p.lon.to_degrees(),
                p.h
            );
        }
        std::fs::write(dir.join("gnss.txt"), gnss).expect("write bench GNSS file");
    }
    let s = analytic::state(&Wgs84, &traj, T0);
    let e = s.euler();
    let cfg = dir.join("kf-gins.yaml");
    let text = yaml(
        &dir,
        s.pos.lat.to_degrees(),
        s.pos.lon.to_degrees(),
        s.pos.h,
        [s.v_n.x, s.v_n.y, s.v_n.z],
        [
            e.roll.to_degrees(),
            e.pitch.to_degrees(),
            e.yaw.to_degrees(),
        ],
    );
    std::fs::write(&cfg, text).expect("write bench YAML");
    eprintln!("KF-GINS drop-in bench files: {}", dir.display());
    cfg
}

fn bench_drop_in(c: &mut Criterion) {
    let cfg = setup();
    let mut group = c.benchmark_group("kf_gins_drop_in");
    group.sample_size(10);
    group.throughput(Throughput::Elements((SECONDS as f64 * RATE_HZ) as u64));
    group.bench_function("30min_200hz_gnss_1hz", |b| {
        b.iter(|| run(&cfg, &KfGinsOptions::default()).expect("run"))
    });
    group.finish();
}

criterion_group!(benches, bench_drop_in);
criterion_main!(benches);
