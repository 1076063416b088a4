//! Starting in motion from GNSS alone (`align::in_motion`), then navigating with the
//! session's filter (GNSS and the non-holonomic constraint of a land vehicle), on
//! simulated drives that start at rest and drive off with headings drawn at random:
//! the truth is the simulator's trajectory, not the code under test.
//!
//! The issue's bounds: heading error below 1° within 60 s of motion for a car, below
//! 5° within 120 s for a 0.5-m/s rover with 1-m GNSS noise (where a fixed 5-m/s course
//! threshold would never start).

use schuler::align::in_motion::{InMotionConfig, start_in_motion};
use schuler::earth::Wgs84;
use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig};
use schuler::imu::ImuSample;
use schuler::imu::random::Noise;
use schuler::nav::NavState;
use schuler::rotation::wrap_pi;
use schuler::session::{Aid, FilterConfig, Prior, Session, SessionConfig, Start, VehicleConfig};
use schuler::sim::analytic::Kinematics;
use schuler::sim::receivers::BaroReading;
use schuler::sim::run::{ScenarioSpec, SimSink, simulate};

/// A drive as the sensors saw it, with the truth at every sample.
#[derive(Default)]
struct Drive {
    imu: Vec<ImuSample>,
    truth: Vec<NavState>,
    fixes: Vec<GnssFix>,
}

impl SimSink for Drive {
    fn imu(
        &mut self,
        _exact: &ImuSample,
        measured: &ImuSample,
        truth: &NavState,
        _kin: &Kinematics,
    ) -> std::io::Result<()> {
        self.imu.push(*measured);
        self.truth.push(*truth);
        Ok(())
    }
    fn gnss(&mut self, f: &schuler::sim::receivers::GnssFix) -> std::io::Result<()> {
        self.fixes.push(GnssFix {
            t: f.t,
            pos: f.pos,
            pos_std: f.pos_std,
            vel: None,
        });
        Ok(())
    }
    fn baro(&mut self, _b: &BaroReading) -> std::io::Result<()> {
        Ok(())
    }
}

/// A vehicle's drive: `motion` after 10 s at rest, heading `yaw_deg`, seeded sensors.
struct Vehicle {
    name: &'static str,
    preset: &'static str,
    gnss_std: f64,
    motion: &'static str,
    /// The heading bound [deg] and the seconds of motion after which it holds.
    bound: (f64, f64),
}

/// A car: 15 m/s, turns of 90 and 45 degrees; tactical IMU, 0.5-m GNSS.
const CAR: Vehicle = Vehicle {
    name: "car",
    preset: "tactical",
    gnss_std: 0.5,
    motion: r#"
[[motion]]
type = "accelerate"
to_speed = "15 m/s"
accel = "1.5 m/s^2"
[[motion]]
type = "hold"
duration = "20 s"
[[motion]]
type = "turn"
angle = "90 deg"
rate = "6 deg/s"
[[motion]]
type = "hold"
duration = "30 s"
[[motion]]
type = "turn"
angle = "-45 deg"
rate = "6 deg/s"
[[motion]]
type = "hold"
duration = "40 s"
"#,
    bound: (1.0, 60.0),
};

/// A slow rover: 0.5 m/s, stops to turn 90 degrees on the spot and back; consumer
/// MEMS IMU, 1-m GNSS.
const ROVER: Vehicle = Vehicle {
    name: "rover",
    preset: "consumer-mems",
    gnss_std: 1.0,
    motion: r#"
[[motion]]
type = "accelerate"
to_speed = "0.5 m/s"
accel = "0.2 m/s^2"
[[motion]]
type = "hold"
duration = "60 s"
[[motion]]
type = "accelerate"
to_speed = "0 m/s"
accel = "0.2 m/s^2"
[[motion]]
type = "turn_on_spot"
angle = "90 deg"
duration = "9 s"
[[motion]]
type = "accelerate"
to_speed = "0.5 m/s"
accel = "0.2 m/s^2"
[[motion]]
type = "hold"
duration = "40 s"
[[motion]]
type = "accelerate"
to_speed = "0 m/s"
accel = "0.2 m/s^2"
[[motion]]
type = "turn_on_spot"
angle = "-90 deg"
duration = "9 s"
[[motion]]
type = "accelerate"
to_speed = "0.5 m/s"
accel = "0.2 m/s^2"
[[motion]]
type = "hold"
duration = "40 s"
"#,
    bound: (5.0, 120.0),
};

/// The rest before the vehicle drives off [s].
const REST: f64 = 10.0;

fn drive(v: &Vehicle, yaw_deg: f64, seed: u64) -> (Drive, ImuNoise) {
    let text = format!(
        r#"seed = {seed}
earth = "wgs84"
[start]
time = 0.0
position = ["30.5 deg", "114.3 deg", "20 m"]
attitude = ["0 deg", "0 deg", "{yaw_deg} deg"]
[[motion]]
type = "hold"
duration = "{REST} s"
{}
[imu]
rate_hz = 100
preset = "{}"
[gnss]
rate_hz = 1
position_std = ["{s} m", "{s} m", "{v} m"]
"#,
        v.motion,
        v.preset,
        s = v.gnss_std,
        v = 2.0 * v.gnss_std,
    );
    let spec: ScenarioSpec = toml::from_str(&text).expect("scenario");
    let noise = ImuNoise::from_model(&spec.imu.model().expect("imu"));
    let mut d = Drive::default();
    simulate(&spec, &mut d).expect("simulate");
    (d, noise)
}

/// The start's time and heading standard deviation [deg], and the heading error
/// [deg] at every output second after it, with its time.
fn heading_errors(d: &Drive, noise: ImuNoise) -> (f64, f64, Vec<(f64, f64)>) {
    let start = start_in_motion(&Wgs84, &d.imu, &d.fixes, &InMotionConfig::default())
        .expect("the vehicle moves");
    let filter = FilterConfig {
        vehicle: VehicleConfig {
            nhc: Some((0.1, 0.1)),
            ..VehicleConfig::default()
        },
        ..FilterConfig::new(IntegrationConfig::new(noise))
    };
    let cfg = SessionConfig {
        output_rate: Some(1.0),
        filter: Some(Prior::from_motion(&start).apply_to(filter)),
        ..SessionConfig::default()
    };
    let mut session = Session::new(Wgs84, cfg, Start::from_motion(&start)).expect("valid");
    for f in &d.fixes {
        session.push(Aid::Gnss(*f)).expect("finite");
    }
    let mut errors = Vec::new();
    for (k, s) in d.imu[start.sample..].iter().enumerate() {
        session.push_imu(*s).expect("in order");
        for e in session.epochs() {
            let truth = &d.truth[start.sample + k];
            let yaw = e.state.euler().yaw - truth.euler().yaw;
            errors.push((e.state.t, wrap_pi(yaw).to_degrees().abs()));
        }
    }
    (start.state.t, start.att_std.z.to_degrees(), errors)
}

/// Ten drives with random headings: the start's heading standard deviation covers its
/// error, and after the bound's seconds of motion the heading error stays below the
/// bound to the end. Measured: car 0.2–2.7 deg at the start (after 7–8 s of motion,
/// std 1.2–1.5 deg), at most 0.07 deg after 60 s; rover 0.24–5.2 deg at the start
/// (after 23–32 s of motion, std 2.5–3.3 deg), at most 4.3 deg after 120 s (its
/// consumer-grade gyros drift while it stops to turn on the spot).
fn check(v: &Vehicle) {
    let mut rng = Noise::new(2026, 0);
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for seed in 1..=10 {
        let yaw = 360.0 * rng.uniform();
        let (d, noise) = drive(v, yaw, seed);
        let (t_start, yaw_std, errors) = heading_errors(&d, noise);
        let first = errors.first().map_or(f64::NAN, |e| e.1);
        let late = errors
            .iter()
            .filter(|(t, _)| *t >= REST + v.bound.1)
            .map(|e| e.1)
            .fold(0.0f64, f64::max);
        println!(
            "{} heading {yaw:6.1} deg: started at {t_start:.2} s with error {first:.2} deg (std {yaw_std:.2} deg), largest after {} s of motion {late:.3} deg",
            v.name, v.bound.1
        );
        // The start's standard deviation covers its error (3 sigma: ten draws).
        assert!(
            first < 3.0 * yaw_std,
            "{}: {first} deg against std {yaw_std} deg",
            v.name
        );
        worst = (worst.0.max(late), worst.1.max(first), worst.2.max(t_start));
    }
    println!(
        "{}: largest start error {:.2} deg, latest start {:.1} s, largest error after {} s of motion {:.3} deg",
        v.name, worst.1, worst.2, v.bound.1, worst.0
    );
    assert!(worst.0 < v.bound.0, "{}: {} deg", v.name, worst.0);
}

#[test]
fn a_car_finds_its_heading_within_a_minute() {
    check(&CAR);
}

#[test]
fn a_slow_rover_finds_its_heading_within_two_minutes() {
    check(&ROVER);
}

/// A rover creeping straight at `$speed` for 260 s (its coordinated turns need more
/// speed than this); consumer MEMS IMU, 1-m GNSS (the issue's creeping start).
macro_rules! creeping {
    ($name:literal, $speed:literal) => {
        Vehicle {
            name: $name,
            preset: "consumer-mems",
            gnss_std: 1.0,
            motion: concat!(
                "[[motion]]\ntype = \"accelerate\"\nto_speed = \"",
                $speed,
                " m/s\"\naccel = \"0.1 m/s^2\"\n",
                "[[motion]]\ntype = \"hold\"\nduration = \"260 s\"\n"
            ),
            bound: (5.0, 180.0),
        }
    };
}

/// The creeping start: at 0.2, 0.5 and 1 m/s with 1-m fixes a pair 10 σ apart needs
/// 70, 28 and 14 s, beyond the 30-s window at 0.2 m/s (and at 0.45 m/s, where the
/// start used to be refused): the straight chord of up to 300 s serves, and the
/// heading is within 5° after 3 minutes of motion, from ten random headings each.
/// Measured: at 0.2 m/s started 54–65 s into the motion with errors 0.2–4.6° (each
/// inside 3σ), at most 2.8° after 180 s; at 0.5 m/s 25–34 s, 0.2–8.4°, 2.0°; at 1 m/s
/// 17–23 s (10 s of it accelerating), 0.2–8.7°, 0.8°.
#[test]
fn creeping_rovers_start_from_their_course() {
    for v in [
        creeping!("rover at 0.2 m/s", "0.2"),
        creeping!("rover at 0.5 m/s", "0.5"),
        creeping!("rover at 1 m/s", "1"),
    ] {
        check(&v);
    }
}

/// A quadrotor-like vehicle: it moves north, east and back without turning towards its
/// motion (accelerations in NED axes), then turns 90° while moving; consumer MEMS IMU,
/// 0.5-m GNSS. The course says nothing of its heading.
const QUADROTOR: Vehicle = Vehicle {
    name: "quadrotor",
    preset: "consumer-mems",
    gnss_std: 0.5,
    motion: r#"
[[motion]]
type = "rates"
duration = "4 s"
accel = ["1 m/s^2", "0 m/s^2", "0 m/s^2"]
axes = "ned"
[[motion]]
type = "hold"
duration = "8 s"
[[motion]]
type = "rates"
duration = "4 s"
accel = ["-1 m/s^2", "1 m/s^2", "0 m/s^2"]
axes = "ned"
[[motion]]
type = "hold"
duration = "8 s"
[[motion]]
type = "rates"
duration = "10 s"
euler_rates = ["0 deg/s", "0 deg/s", "9 deg/s"]
accel = ["0 m/s^2", "-0.4 m/s^2", "0 m/s^2"]
axes = "ned"
[[motion]]
type = "hold"
duration = "30 s"
"#,
    bound: (2.0, 60.0),
};

/// The quadrotor started by a bank of twelve filters from every 30° of heading: the
/// most likely after 40 s of motion goes on. Ten random headings: the bank keeps the
/// member whose sector holds the true heading (measured 1.9–12.3° from it), and after
/// 60 s of motion the heading is within 2° (measured at most 1.6°).
#[test]
fn a_quadrotor_finds_its_heading_with_a_bank_of_filters() {
    use schuler::align::in_motion::start_at_fix;
    use schuler::session::HeadingBank;
    let v = &QUADROTOR;
    let mut rng = Noise::new(7, 0);
    let mut worst = 0.0f64;
    for seed in 1..=10 {
        let yaw_true = 360.0 * rng.uniform();
        let (d, noise) = drive(v, yaw_true, seed);
        // Start at the fourth fix, hovering, heading unknown.
        let start = start_at_fix(&Wgs84, &d.imu, &d.fixes, 0, 3, &InMotionConfig::default())
            .expect("start");
        let cfg = SessionConfig {
            output_rate: Some(1.0),
            filter: Some(
                Prior::from_motion(&start)
                    .apply_to(FilterConfig::new(IntegrationConfig::new(noise))),
            ),
            ..SessionConfig::default()
        };
        let mut bank = HeadingBank::new(Wgs84, cfg, Start::from_motion(&start), 12).expect("valid");
        for f in &d.fixes {
            bank.push(Aid::Gnss(*f)).expect("finite");
        }
        let decide_at = REST + 40.0;
        let mut rest = d.imu[start.sample..].iter().zip(&d.truth[start.sample..]);
        for (s, _) in rest.by_ref() {
            bank.push_imu(*s).expect("in order");
            if s.t >= decide_at {
                break;
            }
        }
        let chosen = bank.decide();
        let sector = wrap_pi(chosen.yaw0 - yaw_true.to_radians())
            .to_degrees()
            .abs();
        let mut session = chosen.session;
        let mut late = 0.0f64;
        for (s, truth) in rest {
            session.push_imu(*s).expect("in order");
            for e in session.epochs() {
                let err = wrap_pi(e.state.euler().yaw - truth.euler().yaw)
                    .to_degrees()
                    .abs();
                if e.state.t >= REST + v.bound.1 {
                    late = late.max(err);
                }
            }
        }
        println!(
            "quadrotor heading {yaw_true:6.1} deg: kept the member from {:.0} deg ({sector:.1} deg off), largest error after {} s of motion {late:.3} deg",
            chosen.yaw0.to_degrees(),
            v.bound.1
        );
        // The nearest member: within half a sector of the truth.
        assert!(sector <= 15.0, "{sector}");
        worst = worst.max(late);
    }
    println!(
        "quadrotor: largest error after {} s of motion {worst:.3} deg",
        v.bound.1
    );
    assert!(worst < v.bound.0, "{worst}");
}

/// Standing still gives no course: the error says so and what to do.
#[test]
fn no_motion_no_start() {
    let (d, _) = drive(&CAR, 10.0, 1);
    let parked: Vec<GnssFix> = d.fixes.iter().copied().filter(|f| f.t < REST).collect();
    let e =
        start_in_motion(&Wgs84, &d.imu, &parked, &InMotionConfig::default()).expect_err("at rest");
    assert!(
        e.to_string().contains("no course to take the heading from"),
        "{e}"
    );
}
