//! The budget against the textbook's closed forms, its shares against its whole, and
//! its whole against the filter's own covariance.

use super::*;
use crate::channel::closed;
use crate::channel::linear::ErrorModel as ChannelModel;
use crate::earth::{EarthModel, Geodetic, Sphere};
use crate::filter::{ImuNoise, IntegrationConfig, Integrator};
use crate::imu::ImuSample;
use crate::nav::{LocalLevel, NavState};
use crate::sim::analytic::Kinematics;
use crate::sim::receivers::{BaroReading, GnssFix};
use crate::sim::run::{ScenarioSpec, SimSink, simulate_on};
use nalgebra::{DMatrix, UnitQuaternion, Vector3};

/// An IMU model with every term zero (bias statistics as random constants).
fn silent() -> ImuNoise {
    let z = Vector3::zeros();
    ImuNoise {
        arw: z,
        vrw: z,
        gyro_bias: z,
        gyro_bias_walk: z,
        accel_bias: z,
        accel_bias_walk: z,
        gyro_bias_tau: f64::INFINITY,
        accel_bias_tau: f64::INFINITY,
        gyro_scale: z,
        accel_scale: z,
        scale_tau: f64::INFINITY,
    }
}

/// A filter configuration with nothing uncertain.
fn quiet() -> IntegrationConfig {
    let z = Vector3::zeros();
    IntegrationConfig {
        init_pos_std: z,
        init_vel_std: z,
        init_att_std: z,
        ..IntegrationConfig::new(silent())
    }
}

/// Free inertial, level and at rest on the textbook's non-rotating sphere (`--earth
/// sphere-fixed`) for two Schuler periods at 10 Hz: the standard deviations of north
/// and down position every second, with the one source `cfg` holds.
fn at_rest(cfg: IntegrationConfig) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let earth = Sphere::textbook(false);
    let start = NavState {
        t: 0.0,
        pos: Geodetic::default(),
        v_n: Vector3::zeros(),
        q_bn: UnitQuaternion::identity(),
    };
    let g = earth.gravitation(earth.radius);
    let mut b = Budget::new(earth, start, cfg);
    assert_eq!(b.parts().len(), 1, "one source");
    let (dt, rate) = (0.1, 10);
    let seconds = (2.0 * std::f64::consts::TAU / earth.schuler_frequency()).ceil() as usize;
    let (mut t, mut north, mut down) = (vec![0.0], vec![0.0], vec![0.0]);
    for k in 1..=seconds * rate {
        let tk = k as f64 * dt;
        let s = ImuSample {
            t: tk,
            dt,
            dtheta: Vector3::zeros(),
            dvel: Vector3::new(0.0, 0.0, -g * dt),
        };
        b.step(&s, &NavState { t: tk, ..start });
        if k % rate == 0 {
            // To this instant (the filter's interval sum of 0.1 s steps may fall a
            // rounding short of its 1 s).
            b.propagate();
            let p = b.total();
            t.push(tk);
            north.push(p[(0, 0)].sqrt());
            down.push(p[(2, 2)].sqrt());
        }
    }
    (t, north, down)
}

/// The largest difference between `got` and `want(t)`, over the largest `|want|`.
fn worst(t: &[f64], got: &[f64], want: impl Fn(f64) -> f64) -> f64 {
    let peak = t.iter().map(|&t| want(t).abs()).fold(0.0, f64::max);
    let err = t
        .iter()
        .zip(got)
        .map(|(&t, g)| (g - want(t).abs()).abs())
        .fold(0.0, f64::max);
    err / peak
}

fn textbook() -> ChannelModel {
    ChannelModel {
        radius: Sphere::TEXTBOOK_RADIUS,
        g: Sphere::TEXTBOOK_G,
    }
}

/// One source alone, free inertial at rest: the north position's σ is the closed form
/// (20)–(23) times the source's σ, within 1e-6 of its peak over two Schuler periods
/// (the issue asks 1e-3; what remains is the third-order `Φ`'s truncation over 1-s
/// steps, relative `ω₀²T²/12 ≈ 1.3e-7` of the response, found 9e-8 at most). The down
/// position's σ follows the free vertical channel (32) within 1e-6 of its value at
/// every second (it grows e-fold in 570 s, so a relative bound; the step error is
/// `(√2ω₀T)⁴/24` again).
#[test]
fn single_sources_meet_the_closed_forms() {
    let m = textbook();
    let w0 = (m.g / m.radius).sqrt();
    let sigma = 1e-3;
    let three = Vector3::repeat(sigma);

    let mut cfg = quiet();
    cfg.noise.accel_bias = three;
    let (t, n, d) = at_rest(cfg);
    let e = worst(&t, &n, |t| closed::accel_bias_response(&m, sigma, t).dr);
    assert!(e < 1e-6, "accelerometer bias (20): {e:e}");
    vertical_follows(&t, &d, |t| {
        closed::vertical_free_response(w0, 0.0, 0.0, sigma, t).0
    });

    let drift = 4.85e-8;
    let mut cfg = quiet();
    cfg.noise.gyro_bias = Vector3::repeat(drift);
    let (t, n, _) = at_rest(cfg);
    let e = worst(&t, &n, |t| closed::drift_response(&m, drift, t).dr);
    assert!(e < 1e-6, "gyro drift (22): {e:e}");

    let alpha0 = 9.7e-5;
    let mut cfg = quiet();
    cfg.init_att_std = Vector3::new(alpha0, alpha0, 0.0);
    let (t, n, _) = at_rest(cfg);
    let e = worst(&t, &n, |t| closed::initial_tilt_response(&m, alpha0, t).dr);
    assert!(e < 1e-6, "initial tilt (21): {e:e}");

    let mut cfg = quiet();
    cfg.init_vel_std = Vector3::repeat(1.0);
    let (t, n, d) = at_rest(cfg);
    let e = worst(&t, &n, |t| closed::initial_velocity_response(&m, 1.0, t).dr);
    assert!(e < 1e-6, "initial velocity (23): {e:e}");
    vertical_follows(&t, &d, |t| {
        closed::vertical_free_response(w0, 0.0, 1.0, 0.0, t).0
    });
}

/// `got` within 1e-6 of `want(t)` at every time but the start (where both are 0).
fn vertical_follows(t: &[f64], got: &[f64], want: impl Fn(f64) -> f64) {
    for (&t, &d) in t.iter().zip(got).skip(1) {
        let w = want(t);
        assert!(
            (d / w - 1.0).abs() < 1e-6,
            "vertical (32) at {t} s: {d} vs {w}"
        );
    }
}

/// A simulation in memory: the exact samples with their truth, and what follows each
/// (`g`: a GNSS fix, `b`: a barometer reading) by sample index.
#[derive(Default)]
struct Recorded {
    imu: Vec<(ImuSample, NavState)>,
    aids: Vec<(usize, char)>,
}

impl SimSink for Recorded {
    fn imu(
        &mut self,
        exact: &ImuSample,
        _measured: &ImuSample,
        truth: &NavState,
        _kin: &Kinematics,
    ) -> std::io::Result<()> {
        self.imu.push((*exact, *truth));
        Ok(())
    }
    fn gnss(&mut self, _fix: &GnssFix) -> std::io::Result<()> {
        self.aids.push((self.imu.len() - 1, 'g'));
        Ok(())
    }
    fn baro(&mut self, _reading: &BaroReading) -> std::io::Result<()> {
        self.aids.push((self.imu.len() - 1, 'b'));
        Ok(())
    }
}

/// A 6-minute drive at 100 Hz with a 60-s GNSS outage.
const DRIVE: &str = r#"
earth = "wgs84"
[start]
position = ["45 deg", "7 deg", "250 m"]
attitude = ["0 deg", "0 deg", "10 deg"]
[[motion]]
type = "hold"
duration = "30 s"
[[motion]]
type = "accelerate"
to_speed = "15 m/s"
accel = "1 m/s^2"
[[motion]]
type = "turn"
angle = "90 deg"
rate = "3 deg/s"
[[motion]]
type = "hold"
duration = "280 s"
[imu]
rate_hz = 100
preset = "tactical"
[gnss]
rate_hz = 1
position_std = ["0.5 m", "0.5 m", "1 m"]
velocity_std = ["0.05 m/s", "0.05 m/s", "0.1 m/s"]
outages = [["150 s", "210 s"]]
[baro]
rate_hz = 10
noise = "0.5 m"
"#;

const POS_STD: Vector3<f64> = Vector3::new(0.5, 0.5, 1.0);
const VEL_STD: Vector3<f64> = Vector3::new(0.05, 0.05, 0.1);

fn drive() -> (Recorded, IntegrationConfig) {
    let spec: ScenarioSpec = toml::from_str(DRIVE).expect("valid scenario");
    let mut data = Recorded::default();
    simulate_on(&spec, 1, &mut data).expect("simulated");
    let model = spec.imu.model().expect("IMU model");
    let cfg = IntegrationConfig::new(ImuNoise::from_model(&model));
    (data, cfg)
}

/// Runs the budget over `data`, calling `check` after every aid.
fn run_budget(
    data: &Recorded,
    cfg: IntegrationConfig,
    mut check: impl FnMut(&Budget<crate::earth::Wgs84>),
) -> Budget<crate::earth::Wgs84> {
    let mut b = Budget::new(crate::earth::Wgs84, data.imu[0].1, cfg);
    let mut aids = data.aids.iter().peekable();
    for (i, (s, truth)) in data.imu.iter().enumerate().skip(1) {
        b.step(s, truth);
        while let Some((_, kind)) = aids.next_if(|(j, _)| *j <= i) {
            match kind {
                'g' => b.gnss(&POS_STD, Some(&VEL_STD)),
                _ => assert!(b.baro(0.5)),
            }
            check(&b);
        }
    }
    b.propagate();
    check(&b);
    b
}

/// The largest `|Σ Pᵢ − P|_jk / sqrt(P_jj P_kk)`.
fn share_gap<E: EarthModel>(b: &Budget<E>) -> f64 {
    let p = b.total();
    let sum = b
        .parts()
        .iter()
        .fold(DMatrix::zeros(p.nrows(), p.ncols()), |s, part| s + &part.p);
    let mut worst: f64 = 0.0;
    for j in 0..p.nrows() {
        for k in 0..p.ncols() {
            let scale = (p[(j, j)] * p[(k, k)]).sqrt();
            if scale > 0.0 {
                worst = worst.max((sum[(j, k)] - p[(j, k)]).abs() / scale);
            }
        }
    }
    worst
}

/// The shares add up to the whole after every update and at the end, with scale
/// factors, a barometer and a lever arm: within 1e-9 of each element's scale
/// `sqrt(P_jj P_kk)` (round-off: a few thousand propagations and updates, each
/// good to ~1e-15 of the largest terms it sums, states of very different sizes).
#[test]
fn shares_add_up_to_the_whole() {
    let (data, mut cfg) = drive();
    cfg.scale_factors = true;
    cfg.baro = Some((3.0, 0.01));
    cfg.lever_arm = Vector3::new(0.5, 0.0, -1.0);
    let mut gap: f64 = 0.0;
    let b = run_budget(&data, cfg, |b| gap = gap.max(share_gap(b)));
    assert!(b.updates() > 3000, "{}", b.updates());
    let names: Vec<String> = b.parts().iter().map(|p| p.source.name()).collect();
    assert_eq!(names.len(), 16, "{names:?}");
    assert!(gap < 1e-9, "shares vs whole: {gap:e}");
}

/// The budget's whole is the filter's own covariance: the filter fed the same exact
/// samples and error-free fixes (so its mechanization stays on the truth and its
/// estimates at zero) ends with the same position, velocity and attitude variances,
/// within 1e-6 relative (its frames and body rates come from its mechanization, which
/// departs from the truth by the integration's own error, micrometres here).
#[test]
fn the_whole_is_the_filters_covariance() {
    let (data, cfg) = drive();
    let data = Recorded {
        aids: data.aids.into_iter().filter(|a| a.1 == 'g').collect(),
        ..data
    };
    let b = run_budget(&data, cfg, |_| {});
    let earth = crate::earth::Wgs84;
    let start = data.imu[0].1;
    let mut f = Integrator::new(LocalLevel::new(earth, start), earth, cfg);
    let mut aids = data.aids.iter().peekable();
    for (i, (s, truth)) in data.imu.iter().enumerate().skip(1) {
        f.step(s);
        while aids.next_if(|(j, _)| *j <= i).is_some() {
            f.update_gnss(&crate::filter::GnssFix {
                t: truth.t,
                pos: truth.pos,
                pos_std: POS_STD,
                vel: Some((truth.v_n, VEL_STD)),
            });
        }
    }
    f.propagate();
    assert_eq!(f.book.counts.rejected, 0);
    let (want, got) = (nav_variances(f.covariance()), nav_variances(b.total()));
    for (w, g) in want.iter().zip(&got) {
        for i in 0..3 {
            assert!((g[i] / w[i] - 1.0).abs() < 1e-6, "{g} vs {w}");
        }
    }
}
