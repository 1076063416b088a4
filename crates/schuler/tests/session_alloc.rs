//! The session's per-sample path does not touch the heap: once its queues have their
//! capacity, pushing a sample and taking the epochs allocates nothing, free-inertial
//! or under the filter between its covariance propagations and measurements (which
//! work on heap matrices once a second, whatever the sample rate). Counted with a
//! counting global allocator (`allocation-counter`, this thread only).

use nalgebra::Vector3;
use schuler::earth::{Geodetic, Wgs84};
use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig};
use schuler::imu::ImuSample;
use schuler::session::{Aid, FilterConfig, Session, SessionConfig, Start};
use schuler::sim::analytic::{self, Maneuvering};
use schuler::sim::sensor_spec::{ImuSpec, Preset};

const RATE: f64 = 200.0;

fn flight(seconds: usize) -> (Vec<ImuSample>, Start, Vec<GnssFix>) {
    let traj = Maneuvering::flight(Geodetic::from_degrees(30.0, 114.0, 500.0));
    let dt = 1.0 / RATE;
    let imu = analytic::samples(&Wgs84, &traj, -dt, dt, seconds * RATE as usize + 1).collect();
    let fixes = (1..=seconds)
        .map(|k| GnssFix {
            t: k as f64,
            pos: analytic::state(&Wgs84, &traj, k as f64).pos,
            pos_std: Vector3::new(0.05, 0.05, 0.1),
            vel: None,
        })
        .collect();
    (imu, Start::at(analytic::state(&Wgs84, &traj, 0.0)), fixes)
}

/// Pushes `samples` and takes the epochs and events; the allocations it made.
fn pushes(session: &mut Session<Wgs84>, samples: &[ImuSample]) -> u64 {
    allocation_counter::measure(|| {
        for s in samples {
            session.push_imu(*s).expect("in order");
            for e in session.epochs() {
                std::hint::black_box(e);
            }
            for e in session.events() {
                std::hint::black_box(e);
            }
        }
    })
    .count_total
}

#[test]
fn free_inertial_samples_allocate_nothing() {
    let (imu, start, _) = flight(60);
    let cfg = SessionConfig::default();
    let mut session = Session::new(Wgs84, cfg, start).expect("valid");
    // Warm-up: the first sample starts the mechanization and sizes the queues.
    assert!(pushes(&mut session, &imu[..200]) > 0);
    assert_eq!(pushes(&mut session, &imu[200..]), 0);
}

#[test]
fn filtered_samples_allocate_only_at_propagations_and_updates() {
    let (imu, start, fixes) = flight(60);
    let spec = ImuSpec::of_preset(RATE, Preset::Tactical);
    let noise = ImuNoise::from_model(&spec.model().expect("preset"));
    let cfg = SessionConfig {
        output_rate: Some(10.0),
        filter: Some(FilterConfig::new(IntegrationConfig::new(noise))),
        ..SessionConfig::default()
    };
    let mut session = Session::new(Wgs84, cfg, start).expect("valid");
    for f in fixes {
        session.push(Aid::Gnss(f)).expect("finite");
    }
    let per_second = RATE as usize;
    // Up to the fix at 10 s (sample i ends at i/200 s).
    pushes(&mut session, &imu[..10 * per_second + 1]);
    let mut at_seconds = Vec::new();
    for k in 10..59 {
        let second = k * per_second;
        // Inside a second (nine epochs written, no fix, no propagation, no
        // snapshot): nothing.
        let inside = &imu[second + 10..second + per_second - 10];
        assert_eq!(pushes(&mut session, inside), 0, "second {k}");
        // Around the whole second: the fix, the propagation before it, the snapshot.
        let around = &imu[second + per_second - 10..second + per_second + 10];
        at_seconds.push(pushes(&mut session, around));
    }
    println!("allocations around each whole second (fix, propagation, snapshot): {at_seconds:?}");
    assert!(at_seconds.iter().all(|&n| n > 0));
}
