//! Criterion benchmark of `schuler simulate`.
//! `schuler simulate` throughput (issue 3 asks >= 1 million IMU samples/s generated
//! and written): 78 s of maneuvers at 1 kHz with a tactical IMU, GNSS at 1 Hz and a
//! barometer at 10 Hz, all files written (606 bytes of text per IMU sample) into a
//! fresh directory, as a user's run does (the previous iteration's files are removed
//! before the clock starts: freeing their pages is not this run's work); and the same
//! generated into a sink that discards everything, to separate generation from
//! formatting and writing. Each iteration includes building the trajectory.

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::sim::analytic::Kinematics;
use schuler::sim::receivers::{BaroReading, GnssFix};
use schuler::sim::run::{SimSink, simulate};
use schuler_run::simulate::simulate_to_dir;
use std::path::PathBuf;

const SCENARIO: &str = r#"
seed = 3
[start]
position = ["45 deg", "7 deg", "300 m"]
attitude = ["0 deg", "0 deg", "0 deg"]
speed = "30 m/s"
[[motion]]
type = "turn"
angle = "90 deg"
bank = "20 deg"
[[motion]]
type = "climb"
to_height = "400 m"
[[motion]]
type = "hold"
duration = "20 s"
[imu]
rate_hz = 1000
preset = "tactical"
[gnss]
rate_hz = 1
position_std = ["0.5 m", "0.5 m", "1 m"]
[baro]
rate_hz = 10
noise = "0.5 m"
"#;

/// Discards everything: the cost of generating the streams alone.
struct NullSink;

impl SimSink for NullSink {
    fn imu(
        &mut self,
        exact: &ImuSample,
        measured: &ImuSample,
        truth: &NavState,
        kin: &Kinematics,
    ) -> std::io::Result<()> {
        std::hint::black_box((exact, measured, truth, kin));
        Ok(())
    }
    fn gnss(&mut self, fix: &GnssFix) -> std::io::Result<()> {
        std::hint::black_box(fix);
        Ok(())
    }
    fn baro(&mut self, reading: &BaroReading) -> std::io::Result<()> {
        std::hint::black_box(reading);
        Ok(())
    }
}

fn bench_simulate(c: &mut Criterion) {
    let spec = toml::from_str(SCENARIO).expect("scenario");
    // SCHULER_BENCH_DIR puts the files elsewhere, e.g. on a tmpfs to leave the disk
    // out of the measurement.
    let dir = std::env::var_os("SCHULER_BENCH_DIR")
        .map_or_else(|| PathBuf::from(env!("CARGO_TARGET_TMPDIR")), PathBuf::from)
        .join("simulate_bench");
    let samples = simulate_to_dir(&spec, &dir).expect("simulate").imu_samples;
    let mut group = c.benchmark_group("simulate");
    group.sample_size(10);
    group.throughput(Throughput::Elements(samples));
    group.bench_function("maneuvers_1khz_tactical_gnss_baro", |b| {
        b.iter_batched(
            || std::fs::remove_dir_all(&dir).expect("remove the previous files"),
            |()| simulate_to_dir(&spec, &dir).expect("simulate"),
            BatchSize::PerIteration,
        )
    });
    group.bench_function("generate_only_1khz_tactical_gnss_baro", |b| {
        b.iter(|| simulate(&spec, &mut NullSink).expect("simulate"))
    });
    group.finish();
}

criterion_group!(benches, bench_simulate);
criterion_main!(benches);
