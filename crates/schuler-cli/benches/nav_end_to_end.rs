//! Criterion benchmark of the whole `schuler nav` pipeline.
//! `schuler nav` end to end (issue 2: >= 1 million samples/s including parsing and
//! writing at 10 Hz): a 1-hour 200 Hz KF-GINS IMU text file (720,000 lines, 13
//! significant digits as in published data sets) is generated once, then each
//! iteration opens, parses, mechanizes and writes nav.txt and nav.csv at 10 Hz, and
//! at 1 Hz (issue 22: >= 3 million samples/s), with the log parsed on a reader thread
//! as `schuler nav` does ([`ImuReader::read_ahead`]).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler::earth::{Geodetic, Wgs84};
use schuler::sim::analytic::{self, Maneuvering};
use schuler_io::formats::{ImuReadOptions, ImuReader};
use schuler_io::output::write_imu_text;
use schuler_run::navigate::{NavSettings, navigate, samples_of};
use schuler_run::options::EarthChoice;
use std::path::PathBuf;

const RATE_HZ: f64 = 200.0;
const SAMPLES: usize = 720_000;

fn bench_nav(c: &mut Criterion) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("nav_end_to_end");
    std::fs::create_dir_all(&dir).expect("bench directory");
    let imu = dir.join("imu_1h_200hz.txt");
    let traj = Maneuvering::flight(Geodetic::from_degrees(30.5, 114.3, 500.0));
    let dt = 1.0 / RATE_HZ;
    if !imu.exists() {
        let samples = analytic::samples(&Wgs84, &traj, 86_400.0 - dt, dt, SAMPLES + 1);
        write_imu_text(&imu, samples, 13).expect("write bench IMU file");
    }
    let init = analytic::state(&Wgs84, &traj, 0.0);
    let mut group = c.benchmark_group("nav_end_to_end");
    group.sample_size(10);
    group.throughput(Throughput::Elements(SAMPLES as u64));
    // 10 Hz: issue 2's case; 1 Hz: issue 22's (parsing and mechanization alone).
    for output_hz in [10.0, 1.0] {
        let settings = NavSettings {
            imu: imu.clone(),
            read: ImuReadOptions::default(),
            init_pos: init.pos,
            init_vel: init.v_n,
            init_att: init.euler(),
            output_rate: Some(output_hz),
            out: dir.join("out"),
            earth: EarthChoice::Wgs84,
            week: 2200,
            mechanization: Default::default(),
            out_bag: None,
        };
        let name = format!("kf_gins_text_1h_200hz_out_{output_hz}hz");
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut reader = ImuReader::open(&settings.imu, &settings.read)
                    .expect("open")
                    .read_ahead()
                    .expect("helper thread");
                navigate(
                    EarthChoice::Wgs84,
                    &settings,
                    None,
                    settings.start(),
                    &mut samples_of(&mut reader),
                    &mut |_| {},
                )
                .expect("navigate")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_nav);
criterion_main!(benches);
