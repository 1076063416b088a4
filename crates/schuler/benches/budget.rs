//! Criterion benchmark of the error budget (issue 34's goal: a 1-h budget of 10
//! sources at 100 Hz in under 2 s): the manoeuvring test flight's exact increments at
//! 100 Hz for one hour with their truth, GNSS position and velocity every second but
//! for a 60-s outage every 10 minutes, the tactical preset with scale factors (12 model
//! sources and the two GNSS noises, 14 in all: more than the goal's 10).
//!
//! Measured once: 3.9 s (3.81–3.98) on the shared 2-core VM while other builds ran
//! (load average 4.5–7), so the 2-s goal is not shown met. The work is per second of
//! data, not per sample: 14 propagations `Φ Pᵢ Φᵀ` of 21 states, the filter's own
//! `transition` once more for each of the 6 sources with process noise, and two
//! Joseph updates for each of the 14 (position, then velocity).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use schuler::analysis::budget::Budget;
use schuler::earth::{Geodetic, Wgs84};
use schuler::filter::{ImuNoise, IntegrationConfig};
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::sim::analytic::{self, Maneuvering};
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use std::hint::black_box;

const RATE: usize = 100;
const SECONDS: usize = 3600;

fn data() -> (Vec<(ImuSample, NavState)>, NavState, IntegrationConfig) {
    let traj = Maneuvering::flight(Geodetic::from_degrees(30.5, 114.3, 500.0));
    let dt = 1.0 / RATE as f64;
    let n = SECONDS * RATE;
    let noise = ImuNoise::from_model(
        &ImuSpec::of_preset(RATE as f64, Preset::Tactical)
            .model()
            .expect("preset"),
    );
    let epochs = analytic::samples(&Wgs84, &traj, 0.0, dt, n)
        .map(|s| (s, analytic::state(&Wgs84, &traj, s.t)))
        .collect();
    let cfg = IntegrationConfig {
        scale_factors: true,
        ..IntegrationConfig::new(noise)
    };
    (epochs, analytic::state(&Wgs84, &traj, 0.0), cfg)
}

fn run(epochs: &[(ImuSample, NavState)], start: NavState, cfg: IntegrationConfig) -> f64 {
    let mut b = Budget::new(Wgs84, start, cfg);
    let (pos, vel) = (Vector3::new(0.5, 0.5, 1.0), Vector3::new(0.05, 0.05, 0.1));
    for (k, (s, truth)) in epochs.iter().enumerate() {
        b.step(s, truth);
        let second = (k + 1) / RATE;
        if (k + 1) % RATE == 0 && second % 600 >= 60 {
            b.gnss(&pos, Some(&vel));
        }
    }
    b.propagate();
    assert!(b.parts().len() >= 10, "{}", b.parts().len());
    b.total()[(0, 0)]
}

fn bench_budget(c: &mut Criterion) {
    let (epochs, start, cfg) = data();
    let mut group = c.benchmark_group("budget");
    group.sample_size(10);
    group.bench_function("1 h at 100 Hz, 14 sources", |b| {
        b.iter(|| black_box(run(&epochs, start, cfg)))
    });
    group.finish();
}

criterion_group!(benches, bench_budget);
criterion_main!(benches);
