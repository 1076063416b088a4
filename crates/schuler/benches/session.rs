//! Criterion benchmark of the session's per-sample cost against the loops it
//! replaced: the NED mechanization stepped directly, checking the latitude for the
//! automatic hand-over after each step and reading out at 10 Hz (what `schuler nav`'s
//! free loop did by default), against `Session::push_imu` doing the same; and the
//! 21-state filter stepped with 1-Hz GNSS fixes and 10-Hz read-outs of state and
//! standard deviations (the aided loop, which had no hand-over), against the session
//! with the same filter on NED. Samples are
//! precomputed exact increments of a maneuvering flight at 200 Hz (one minute), fixes
//! the truth at every second. Measured on the 2-core VM, whose speed drifts by up to a
//! quarter between runs: the session took 1.05–1.13 times the free loop and 1.04–1.14
//! times the aided loop in alternate runs. Counted in instructions (callgrind, which
//! load does not change), `schuler nav` end to end on a 20-min 200-Hz log costs 3.2 %
//! more through the session free-inertial and 2.5 % more aided than the loops it
//! replaced.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Vector3;
use schuler::earth::{Geodetic, Wgs84};
use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig, Integrator};
use schuler::imu::ImuSample;
use schuler::nav::{LocalLevel, Mechanization, NavState};
use schuler::session::{
    Aid, Decimator, FilterConfig, FilterEpoch, MechanizationChoice, MechanizationConfig, Session,
    SessionConfig, Start,
};
use schuler::sim::analytic::{self, Maneuvering};
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use std::hint::black_box;

const RATE: f64 = 200.0;
const SECONDS: usize = 60;

struct Data {
    samples: Vec<ImuSample>,
    start: NavState,
    fixes: Vec<GnssFix>,
    filter: IntegrationConfig,
}

fn data() -> Data {
    let traj = Maneuvering::flight(Geodetic::from_degrees(30.5, 114.3, 500.0));
    let dt = 1.0 / RATE;
    let n = SECONDS * RATE as usize;
    let noise = ImuNoise::from_model(
        &ImuSpec::of_preset(RATE, Preset::Tactical)
            .model()
            .expect("preset"),
    );
    Data {
        samples: analytic::samples(&Wgs84, &traj, -dt, dt, n + 1).collect(),
        start: analytic::state(&Wgs84, &traj, 0.0),
        fixes: (1..=SECONDS)
            .map(|k| GnssFix {
                t: k as f64,
                pos: analytic::state(&Wgs84, &traj, k as f64).pos,
                pos_std: Vector3::new(0.05, 0.05, 0.1),
                vel: None,
            })
            .collect(),
        filter: IntegrationConfig {
            scale_factors: true,
            ..IntegrationConfig::new(noise)
        },
    }
}

/// 10-Hz output; free: the automatic mechanization (the default), aided: NED.
fn config(filter: Option<IntegrationConfig>) -> SessionConfig {
    let choice = match filter {
        None => MechanizationChoice::Auto,
        Some(_) => MechanizationChoice::Ned,
    };
    SessionConfig {
        mechanization: MechanizationConfig {
            choice,
            ..MechanizationConfig::default()
        },
        output_rate: Some(10.0),
        filter: filter.map(FilterConfig::new),
        ..SessionConfig::default()
    }
}

/// The session over the data, every epoch and event taken.
#[inline(never)]
fn session(d: &Data, filter: Option<IntegrationConfig>) -> f64 {
    let mut s = Session::new(Wgs84, config(filter), Start::at(d.start)).expect("valid");
    if filter.is_some() {
        for f in &d.fixes {
            s.push(Aid::Gnss(*f)).expect("finite");
        }
    }
    let mut sum = 0.0;
    for x in &d.samples {
        s.push_imu(*black_box(x)).expect("in order");
        sum += s.epochs().map(|e| e.state.pos.h).sum::<f64>();
        s.events().for_each(drop);
    }
    sum
}

/// The free loop the session replaced: step, check the hand-over latitude,
/// decimate, read out.
#[inline(never)]
fn free_loop(d: &Data) -> f64 {
    let mut nav = LocalLevel::new(
        Wgs84,
        NavState {
            t: d.samples[0].t,
            ..d.start
        },
    );
    nav.prime(&d.samples[0]);
    let mut decimator = Decimator::new(Some(10.0));
    let sin_enter = MechanizationConfig::AUTO_LATITUDE_DEG.to_radians().sin();
    let mut sum = 0.0;
    for x in &d.samples[1..] {
        nav.step(black_box(x));
        if nav.state().pos.lat.sin().abs() > sin_enter {
            sum += 1.0;
        }
        if decimator.take(x.t, x.dt) {
            sum += nav.state().pos.h;
        }
    }
    sum
}

/// The aided loop the session replaced: step with fixes, decimate, read out the state
/// and the filter's standard deviations.
#[inline(never)]
fn aided_loop(d: &Data) -> f64 {
    let start = NavState {
        t: d.samples[0].t,
        ..d.start
    };
    let mut integ = Integrator::new(LocalLevel::new(Wgs84, start), Wgs84, d.filter);
    integ.prime(&d.samples[0]);
    let mut fixes = d.fixes.iter().copied().peekable();
    let mut decimator = Decimator::new(Some(10.0));
    let mut sum = 0.0;
    for x in &d.samples[1..] {
        integ.step_with_fixes(black_box(x), &mut fixes);
        integ.book.innovations.clear();
        if decimator.take(x.t, x.dt) {
            sum += integ.state().pos.h + FilterEpoch::of(&integ).nav_std[0].x;
        }
    }
    sum
}

fn bench_session(c: &mut Criterion) {
    let d = data();
    let mut group = c.benchmark_group("session");
    group.sample_size(20);
    group.throughput(Throughput::Elements(d.samples.len() as u64));
    group.bench_function("free_loop", |b| b.iter(|| black_box(free_loop(&d))));
    group.bench_function("free_session", |b| b.iter(|| black_box(session(&d, None))));
    group.bench_function("aided_loop", |b| b.iter(|| black_box(aided_loop(&d))));
    group.bench_function("aided_session", |b| {
        b.iter(|| black_box(session(&d, Some(d.filter))))
    });
    group.finish();
}

criterion_group!(benches, bench_session);
criterion_main!(benches);
