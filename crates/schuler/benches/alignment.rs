//! Alignment of 15 minutes of 1 kHz data at rest (issue 9: "well under a second"):
//! spike test and motion detector over all 900 000 samples, coarse stage, and the
//! fine stage (NED mechanization at 1 kHz, 18-state filter at 1 Hz). The data are
//! a navigation-grade IMU's output, precomputed. Measured (2-core VM shared with
//! other builds): 312 ms (2.9 M samples/s).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use schuler::align::{AlignConfig, align};
use schuler::earth::{EarthModel, Geodetic, Wgs84};
use schuler::filter::ImuNoise;
use schuler::imu::ImuSample;
use schuler::rotation::Euler;
use schuler::sim::imu_model::ImuSimulator;
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use std::hint::black_box;

fn bench_alignment(c: &mut Criterion) {
    let spec = ImuSpec::of_preset(1000.0, Preset::Navigation);
    let model = spec.model().expect("preset resolves");
    let pos = Geodetic::from_degrees(70.0, 30.0, 20.0);
    let c_nb = Euler::from_degrees(0.5, -1.0, 40.0).to_dcm().transpose();
    let w_b = c_nb * Wgs84.w_ie_n(pos.lat);
    let f_b = -(c_nb * Wgs84.gravity_n(pos.lat, pos.h));
    let mut sim = ImuSimulator::new(model.clone(), 1);
    let n = 900_000;
    let samples: Vec<ImuSample> = (1..=n)
        .map(|k| sim.measure(&ImuSample::from_mean_rates(k as f64 * 1e-3, 1e-3, w_b, f_b)))
        .collect();
    let noise = ImuNoise::from_model(&model);
    let cfg = AlignConfig {
        coarse: 190.0,
        fine: 710.0,
        ..AlignConfig::default()
    };
    let mut group = c.benchmark_group("alignment");
    group.sample_size(10);
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function("15_min_1khz", |b| {
        b.iter(|| black_box(align(Wgs84, pos, &samples, &noise, &cfg).expect("aligns")))
    });
    group.finish();
}

criterion_group!(benches, bench_alignment);
criterion_main!(benches);
