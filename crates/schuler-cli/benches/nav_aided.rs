//! Criterion benchmark of `schuler nav --gnss` end to end (issue 5: one hour of 200 Hz
//! IMU with 1 Hz GNSS through the 21-state filter in under 1 s on one core, including
//! parsing and writing at 1 Hz; one hour at 1 kHz in under 3 s). The logs (KF-GINS
//! IMU text, 13 significant digits, of an exact maneuvering flight; GNSS at every
//! whole second from the same truth, 0.05 m / 0.1 m std) are generated once. The
//! 200-Hz hour also runs with the lever arm and the GNSS time offset estimated
//! (issue 33: at most 1.2× the time without).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Vector3;
use schuler::earth::Wgs84;
use schuler::filter::{Calibration, Gate, GnssFix, ImuNoise, IntegrationConfig};
use schuler::session::FilterConfig;
use schuler::sim::analytic;
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use schuler_io::formats::ImuReader;
use schuler_io::output::write_imu_text;
use schuler_run::aided::{Aiding, OutputNames};
use schuler_run::navigate::{NavSettings, navigate, samples_of};
use schuler_run::options::EarthChoice;
use std::path::PathBuf;

mod common;

const T0: f64 = 86_400.0;
const SECONDS: usize = 3600;

fn setup(rate_hz: f64, calibration: Calibration) -> (NavSettings, Aiding) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("nav_aided_{rate_hz}"));
    std::fs::create_dir_all(&dir).expect("bench directory");
    let imu = dir.join("imu.txt");
    let traj = common::flight();
    let dt = 1.0 / rate_hz;
    let n = (SECONDS as f64 * rate_hz) as usize;
    if !imu.exists() {
        let samples = analytic::samples(&Wgs84, &traj, T0 - dt, dt, n + 1);
        write_imu_text(&imu, samples, 13).expect("write bench IMU file");
    }
    let fixes: Vec<GnssFix> = (1..=SECONDS)
        .map(|k| {
            let s = analytic::state(&Wgs84, &traj, k as f64);
            GnssFix {
                t: T0 + k as f64,
                pos: s.pos,
                pos_std: Vector3::new(0.05, 0.05, 0.1),
                vel: None,
            }
        })
        .collect();
    let spec = ImuSpec {
        rate_hz,
        preset: Some(Preset::Tactical),
        gyro: Default::default(),
        accel: Default::default(),
        g_sensitivity: None,
        vibration: Vec::new(),
    };
    let noise = ImuNoise::from_model(&spec.model().expect("preset"));
    let settings = common::settings(imu, dir.join("out"));
    let aiding = Aiding {
        raw: None,
        fixes: fixes.into(),
        filter: FilterConfig::new(IntegrationConfig {
            noise,
            scale_factors: true,
            lever_arm: Vector3::zeros(),
            gate: Gate::Level(1e-4),
            reset_after: 5,
            propagation_interval: 1.0,
            init_pos_std: Vector3::repeat(0.1),
            init_vel_std: Vector3::repeat(0.01),
            init_att_std: Vector3::repeat(0.01f64.to_radians()),
            init_sensor_std: None,
            baro: None,
            gnss_time_offset: 0.0,
            calibration,
        }),
        names: OutputNames::SCHULER,
        initial_errors: Default::default(),
        outage_test: None,
        baro: Vec::new(),
        // The navigation alone (the HTML report's cost is stated in the README).
        report: schuler_run::aided::report::ReportSettings {
            html: false,
            ..Default::default()
        },
        vehicle: Default::default(),
        gnss_time_shift: 0.0,
    };
    (settings, aiding)
}

fn bench_aided(c: &mut Criterion) {
    let mut group = c.benchmark_group("nav_aided");
    group.sample_size(10);
    let calibrated = Calibration {
        lever_arm_std: Some(1.0),
        time_offset_std: Some(0.5),
        time_offset_walk: 0.0,
    };
    for (rate, calibration, name) in [
        (200.0, Calibration::default(), "21_states"),
        (200.0, calibrated, "25_states_calibrating"),
        (1000.0, Calibration::default(), "21_states"),
    ] {
        let (settings, aiding) = setup(rate, calibration);
        group.throughput(Throughput::Elements((SECONDS as f64 * rate) as u64));
        group.bench_function(format!("{name}_1h_{rate}hz_gnss_1hz_out_1hz"), |b| {
            b.iter(|| {
                let mut reader = ImuReader::open(&settings.imu, &settings.read).expect("open");
                let start = settings.start();
                let mut samples = samples_of(&mut reader);
                navigate(
                    EarthChoice::Wgs84,
                    &settings,
                    Some(&aiding),
                    start,
                    &mut samples,
                    &mut |_| {},
                )
                .expect("navigate")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_aided);
criterion_main!(benches);
