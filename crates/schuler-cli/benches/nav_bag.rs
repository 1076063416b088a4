//! Criterion benchmark of `schuler nav --bag` against the KF-GINS text path (issue 19:
//! within 1.5× of it): one hour of 200 Hz IMU and 10 Hz GNSS of an exact maneuvering
//! flight, as KF-GINS text files (IMU to 13 significant digits, GNSS positions) and as
//! a ROS 2 bag (sensor_msgs/Imu rates in FLU, NavSatFix, zstd chunks as the `mcap`
//! crate writes them by default), navigated end to end through the 21-state filter
//! with 1-Hz output: the GNSS read, the IMU streamed, nav.txt written.

use criterion::{Criterion, Throughput, criterion_group};
use mcap::records::MessageHeader;
use schuler::earth::{Geodetic, Wgs84};
use schuler::imu::ImuSample;
use schuler::sim::analytic::{self, Maneuvering};
use schuler_io::bag::input::{BagReadOptions, plan};
use schuler_io::bag::messages::{Header, Imu, NavSatFix, definitions};
use schuler_io::formats::ImuReader;
use schuler_run::aided::AidingOptions;
use schuler_run::navigate::{NavSettings, navigate, samples_of};
use schuler_run::options::EarthChoice;
use schuler_run::options::GradeChoice;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod common;

const T0: f64 = 86_400.0;
const SECONDS: usize = 3600;
const RATE_HZ: f64 = 200.0;
const GNSS_HZ: usize = 10;

/// The fixes' times and positions (every 0.1 s from 0.1 s on).
fn fixes(traj: &Maneuvering) -> Vec<(f64, Geodetic)> {
    (1..=SECONDS * GNSS_HZ)
        .map(|k| {
            let t = k as f64 / GNSS_HZ as f64;
            (T0 + t, analytic::state(&Wgs84, traj, t).pos)
        })
        .collect()
}

/// `gnss.txt`: `t lat lon h 0.05 0.05 0.1`.
fn write_gnss_text(path: &Path, fixes: &[(f64, Geodetic)]) {
    let mut s = String::new();
    for (t, p) in fixes {
        let (lat, lon) = (p.lat.to_degrees(), p.lon.to_degrees());
        writeln!(s, "{t} {lat:.12} {lon:.12} {:.6} 0.05 0.05 0.1", p.h).expect("string");
    }
    std::fs::write(path, s).expect("gnss.txt");
}

fn header(t: f64, frame: &str) -> Header {
    let (sec, nanosec, _) = schuler_io::bag::output::stamp(t).expect("stamp");
    Header {
        sec,
        nanosec,
        frame_id: frame.into(),
    }
}

/// The bag: `/imu` (rates `Δ/dt`, FRD to FLU) and `/fix`, in time order.
fn write_bag(path: &Path, samples: &[ImuSample], fixes: &[(f64, Geodetic)]) {
    let file = std::fs::File::create(path).expect("bag");
    let mut w = mcap::Writer::new(std::io::BufWriter::new(file)).expect("writer");
    let mut channel = |topic: &str, ty: &str, def: String| {
        let schema = w.add_schema(ty, "ros2msg", def.as_bytes()).expect("schema");
        w.add_channel(schema, topic, "cdr", &BTreeMap::new())
            .expect("channel")
    };
    let imu = channel("/imu", "sensor_msgs/msg/Imu", definitions::imu());
    let fix = channel(
        "/fix",
        "sensor_msgs/msg/NavSatFix",
        definitions::nav_sat_fix(),
    );
    let mut put = |channel_id: u16, t: f64, data: Vec<u8>| {
        let log_time = schuler_io::bag::output::stamp(t).expect("stamp").2;
        let h = MessageHeader {
            channel_id,
            sequence: 0,
            log_time,
            publish_time: log_time,
        };
        w.write_to_known_channel(&h, &data).expect("message");
    };
    let flu = |v: nalgebra::Vector3<f64>, dt: f64| [v.x / dt, -v.y / dt, -v.z / dt];
    let mut next_fix = fixes.iter().peekable();
    for s in samples {
        let msg = Imu {
            header: header(s.t, "imu"),
            angular_velocity: flu(s.dtheta, s.dt),
            angular_velocity_covariance: [0.0; 9],
            linear_acceleration: flu(s.dvel, s.dt),
            linear_acceleration_covariance: [0.0; 9],
        };
        put(imu, s.t, msg.encode());
        while let Some((t, p)) = next_fix.next_if(|(t, _)| *t <= s.t) {
            let msg = NavSatFix {
                header: header(*t, "gnss"),
                status: 0,
                service: 1,
                latitude: p.lat.to_degrees(),
                longitude: p.lon.to_degrees(),
                altitude: p.h,
                position_covariance: [0.0025, 0.0, 0.0, 0.0, 0.0025, 0.0, 0.0, 0.0, 0.01],
                position_covariance_type: 2,
            };
            put(fix, *t, msg.encode());
        }
    }
    w.finish().expect("finish");
}

/// The files (made once) and the settings both runs share.
fn setup() -> (PathBuf, NavSettings) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("nav_bag");
    std::fs::create_dir_all(&dir).expect("bench directory");
    let traj = common::flight();
    let dt = 1.0 / RATE_HZ;
    if !dir.join("drive.mcap").exists() {
        let n = (SECONDS as f64 * RATE_HZ) as usize;
        let samples: Vec<ImuSample> =
            analytic::samples(&Wgs84, &traj, T0 - dt, dt, n + 1).collect();
        let fixes = fixes(&traj);
        schuler_io::output::write_imu_text(&dir.join("imu.txt"), samples.iter().copied(), 13)
            .expect("imu.txt");
        write_gnss_text(&dir.join("gnss.txt"), &fixes);
        write_bag(&dir.join("drive.mcap"), &samples, &fixes);
    }
    let settings = common::settings(dir.join("imu.txt"), dir.join("out"));
    std::fs::create_dir_all(&settings.out).expect("out");
    (dir, settings)
}

/// The two runs compared: the KF-GINS text path and the bag path, each end to end.
struct Runs {
    dir: PathBuf,
    settings: NavSettings,
}

impl Runs {
    fn options(
        gnss: Option<PathBuf>,
        bag: Option<schuler_io::bag::input::BagAids>,
    ) -> AidingOptions {
        AidingOptions {
            gnss,
            bag,
            scale_factors: true,
            no_report: true,
            ..Default::default()
        }
    }

    fn text(&self) {
        let noise = GradeChoice::Tactical.noise().expect("preset");
        let aiding = Self::options(Some(self.dir.join("gnss.txt")), None)
            .resolve(noise)
            .expect("aiding");
        let s = &self.settings;
        let mut reader = ImuReader::open(&s.imu, &s.read).expect("open");
        let mut samples = samples_of(&mut reader);
        navigate(
            EarthChoice::Wgs84,
            s,
            aiding.as_ref(),
            s.start(),
            &mut samples,
            &mut |_| {},
        )
        .expect("navigate");
    }

    fn bag(&self) {
        let noise = GradeChoice::Tactical.noise().expect("preset");
        let p = plan(&self.dir.join("drive.mcap"), &BagReadOptions::default()).expect("plan");
        let aiding = Self::options(None, Some(p.aids.clone()))
            .resolve(noise)
            .expect("aiding");
        let samples = p.imu_samples().expect("samples");
        let s = &self.settings;
        let mut samples = samples_of(samples);
        navigate(
            EarthChoice::Wgs84,
            s,
            aiding.as_ref(),
            s.start(),
            &mut samples,
            &mut |_| {},
        )
        .expect("navigate");
    }
}

fn bench_bag(c: &mut Criterion) {
    let (dir, settings) = setup();
    let runs = Runs { dir, settings };
    let mut group = c.benchmark_group("nav_bag");
    group.sample_size(10);
    group.throughput(Throughput::Elements((SECONDS as f64 * RATE_HZ) as u64));
    group.bench_function("text_1h_200hz_gnss_10hz", |b| b.iter(|| runs.text()));
    group.bench_function("bag_1h_200hz_gnss_10hz", |b| b.iter(|| runs.bag()));
    group.finish();
}

/// This process's CPU time so far (user + system, every thread) [s], from
/// `/proc/self/stat` (fields 14 and 15, in clock ticks of 1/100 s).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat");
    // The command name (field 2) is in parentheses and may hold blanks.
    let after = &stat[stat.rfind(')').expect("stat") + 2..];
    let f: Vec<f64> = after
        .split_whitespace()
        .skip(11)
        .take(2)
        .map(|x| x.parse().expect("ticks"))
        .collect();
    (f[0] + f[1]) / 100.0
}

/// `--cpu N`: N alternating pairs of runs (text, then bag), each timed by the CPU
/// time it took (every thread, so the writer thread counts; less sensitive to the
/// machine's load than wall time), and the ratio bag/text of each pair and of the sums.
fn cpu_pairs(n: usize) {
    let (dir, settings) = setup();
    let runs = Runs { dir, settings };
    let (mut text_sum, mut bag_sum) = (0.0, 0.0);
    println!("| pair | text CPU [s] | bag CPU [s] | bag/text |");
    println!("|---|---|---|---|");
    for k in 1..=n {
        let t0 = cpu_seconds();
        runs.text();
        let t1 = cpu_seconds();
        runs.bag();
        let t2 = cpu_seconds();
        let (text, bag) = (t1 - t0, t2 - t1);
        text_sum += text;
        bag_sum += bag;
        println!("| {k} | {text:.2} | {bag:.2} | {:.2} |", bag / text);
    }
    println!(
        "| all | {text_sum:.2} | {bag_sum:.2} | {:.2} |",
        bag_sum / text_sum
    );
}

criterion_group!(benches, bench_bag);

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(k) = args.iter().position(|a| a == "--cpu") {
        let n = args.get(k + 1).and_then(|x| x.parse().ok()).unwrap_or(5);
        cpu_pairs(n);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
