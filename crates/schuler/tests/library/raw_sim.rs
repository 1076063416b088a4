//! Simulated raw GNSS observations against independent truths: single-point
//! positioning of noiseless epochs gives back the antenna and the clock; the
//! pseudorange and Doppler agree with a light-time range computed here from the
//! orbit alone; with noise the position errors are as large as the solution's
//! covariance says (NEES); windows hold exactly N satellites; a step fault appears
//! on one satellite only.

use nalgebra::Vector3;
use schuler::earth::{EarthModel, Geodetic, Wgs84, c_ne};
use schuler::filter::kalman::chi_square_quantile;
use schuler::gnss::spp::{self, SppConfig, Weighting};
use schuler::gnss::{C, GpsTime, Sat, Signal, System};
use schuler::sim::raw_gnss::clock::ClockModel;
use schuler::sim::raw_gnss::constellation::{NOMINAL_KLOBUCHAR, nominal_gps};
use schuler::sim::raw_gnss::spec::NavData;
use schuler::sim::raw_gnss::{
    Antenna, Fault, GaussMarkov, Keep, RawGnssModel, RawGnssSimulator, RawSimEpoch, Window,
};

const WEEK: i64 = 1590;
/// 2010-07-01 02:00 GPST.
const T0: f64 = 352_800.0;

/// An antenna moving at a constant ECEF velocity from a point at 45° N.
struct Linear {
    r0: Vector3<f64>,
    v: Vector3<f64>,
}

impl Antenna for Linear {
    fn at(&self, t: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
        Some((self.r0 + self.v * (t - T0), self.v))
    }
}

fn antenna() -> Linear {
    let p = Geodetic::from_degrees(45.07, 7.68, 245.0);
    Linear {
        r0: Wgs84.geodetic_to_ecef(&p),
        v: c_ne(p.lat, p.lon) * Vector3::new(12.0, -15.0, 0.5),
    }
}

/// A noiseless model: clock bias 0.3 ms and drift 50 ppb without random walks.
fn quiet() -> RawGnssModel {
    RawGnssModel {
        week: WEEK,
        signals: vec![Signal::new(System::Gps, '1', 'C')],
        interval: 1.0,
        elevation_mask: 10f64.to_radians(),
        clock: ClockModel {
            bias: 3e-4,
            drift: 5e-8,
            h0: 0.0,
            h_2: 0.0,
        },
        iono_scale: 1.0,
        tropo_scale: 1.0,
        code_std: [0.0, 0.0],
        rate_std: 0.0,
        multipath: None,
        cn0: [30.0, 50.0],
        windows: vec![],
        faults: vec![],
    }
}

fn nominal() -> NavData {
    let t = GpsTime::new(WEEK, T0);
    NavData {
        store: nominal_gps(WEEK, t, t.add_s(4000.0)),
        klobuchar: Some(NOMINAL_KLOBUCHAR),
        file: None,
    }
}

fn run(model: RawGnssModel, n: usize, seed: u64) -> Vec<RawSimEpoch> {
    let data = nominal();
    let mut sim = RawGnssSimulator::new(model, data.store, data.klobuchar, seed);
    let a = antenna();
    (0..n)
        .map(|k| sim.epoch(T0 + k as f64, &a).expect("inside"))
        .collect()
}

/// SPP without a mask of its own (the simulator's applies), no FDE, the same
/// elevation weights as the simulated noise and no model terms.
fn spp_config(atmosphere: bool) -> SppConfig {
    SppConfig {
        elevation_mask: 0.0,
        weighting: Weighting::Elevation { a: 0.3, b: 0.3 },
        model_errors: false,
        ionosphere: atmosphere,
        troposphere: atmosphere,
        fde: None,
        ..SppConfig::default()
    }
}

/// Noiseless epochs (atmosphere on, a moving antenna, a biased and drifting clock)
/// solved by `spp::solve`: the antenna's position to 1 mm (the solver stops on a
/// 0.1 mm step; the solver's transmission time leaves out the relativistic clock
/// term, ≤ 45 ns, moving a satellite by ≤ 0.2 mm), the clock bias to 1 mm of range,
/// the velocity to 1 mm/s and the drift to 1 mm/s.
#[test]
fn spp_of_noiseless_epochs_gives_back_the_antenna_and_clock() {
    for atmosphere in [false, true] {
        let mut model = quiet();
        if !atmosphere {
            model.iono_scale = 0.0;
            model.tropo_scale = 0.0;
        }
        let data = nominal();
        let cfg = spp_config(atmosphere);
        for e in run(model, 300, 1).iter().step_by(37) {
            assert!(
                e.epoch.measurements.len() >= 5,
                "{}",
                e.epoch.measurements.len()
            );
            let sol = spp::solve(&e.epoch, &data.store, data.klobuchar.as_ref(), &cfg, None)
                .expect("solved");
            let err = (sol.r_e - e.r_e).norm();
            assert!(err < 1e-3, "position off by {err} m");
            let b = sol.clock_of(System::Gps).unwrap();
            assert!(
                (b - C * e.clock_bias).abs() < 1e-3,
                "{b} {}",
                C * e.clock_bias
            );
            let v_err = (sol.v_e.unwrap() - e.v_e).norm();
            assert!(v_err < 1e-3, "velocity off by {v_err} m/s");
            assert!((sol.clock_drift.unwrap() - C * e.clock_drift).abs() < 1e-3);
        }
    }
}

/// The light-time range computed here from the orbit alone: τ from the satellite at
/// `t − τ` turned by Ω̇e·τ about Z, iterated to 1e-14 s.
fn range_here(eph: &schuler::gnss::Ephemeris, t: GpsTime, r: &Vector3<f64>) -> f64 {
    let w = eph.constants().omega_e;
    let mut tau = 0.07;
    for _ in 0..20 {
        let s = eph.orbit_at(t.add_s(-tau)).r_e;
        let (sn, cs) = (w * tau).sin_cos();
        let turned = Vector3::new(cs * s.x + sn * s.y, -sn * s.x + cs * s.y, s.z);
        tau = (turned - r).norm() / C;
    }
    tau * C
}

/// Atmosphere and noise off: `P − c(δt_r − Δt_sv + TGD)` is the range computed here
/// (to 1 µm: the light-time iterations agree to 1e-14 s), and the pseudorange rate
/// `−λD − c·δṫ_r + c·Δṫ_sv` is its time derivative by central differences over
/// ±0.05 s at the true reception time (to 0.1 mm/s: the differences' error is
/// ρ⃛·h²/6 ≈ 1e-6 m/s, the antenna moving linearly).
#[test]
fn pseudorange_and_doppler_match_a_range_computed_here() {
    let mut model = quiet();
    model.iono_scale = 0.0;
    model.tropo_scale = 0.0;
    let data = nominal();
    let a = antenna();
    let lambda = C / 1_575.42e6;
    let mut checked = 0;
    for e in run(model, 120, 2).iter().step_by(11) {
        for m in &e.epoch.measurements {
            let eph = data.store.select(m.sat, e.epoch.t).unwrap();
            let r = a
                .at(T0 + e.t_true.diff_s(GpsTime::new(WEEK, T0)))
                .unwrap()
                .0;
            let rho = range_here(eph, e.t_true, &r);
            let tx = e.t_true.add_s(-rho / C);
            let sat_clock = eph.state_at(tx);
            let tgd = eph.group_delays[0];
            let p = m.pseudorange.unwrap();
            let geometric = p - C * (e.clock_bias - sat_clock.clock_bias + tgd);
            assert!(
                (geometric - rho).abs() < 1e-6,
                "{} {}",
                m.sat,
                geometric - rho
            );
            let h = 0.05;
            let at = |dt: f64| {
                let t = e.t_true.add_s(dt);
                let r = a.at(T0 + t.diff_s(GpsTime::new(WEEK, T0))).unwrap().0;
                range_here(eph, t, &r)
            };
            let rate = (at(h) - at(-h)) / (2.0 * h);
            let measured =
                -lambda * m.doppler.unwrap() - C * e.clock_drift + C * sat_clock.clock_drift;
            assert!(
                (measured - rate).abs() < 1e-4,
                "{} {}",
                m.sat,
                measured - rate
            );
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked}");
}

/// With code noise (a = b = 0.3 m), the Gauss–Markov-free clock random walks of a
/// TCXO, Doppler noise and the atmosphere modelled exactly, SPP weighted by the same
/// σ: the position error's NEES `eᵀP⁻¹e` over 1200 independent epochs sums to a
/// χ²(3600) variable; it must lie within its two-sided 99.9 % interval
/// [3318, 3887] (a mean NEES of 2.77 to 3.24).
#[test]
fn position_errors_are_consistent_with_the_covariance() {
    let mut model = quiet();
    model.code_std = [0.3, 0.3];
    model.rate_std = 0.05;
    model.clock.h0 = 2e-19;
    model.clock.h_2 = 2e-20;
    let data = nominal();
    let cfg = spp_config(true);
    let n = 1200;
    let mut sum = 0.0;
    for e in run(model, n, 3) {
        let sol =
            spp::solve(&e.epoch, &data.store, data.klobuchar.as_ref(), &cfg, None).expect("solved");
        let p = sol.cov.view((0, 0), (3, 3)).into_owned();
        let err = sol.r_e - e.r_e;
        let p3 = nalgebra::Matrix3::from_fn(|i, j| p[(i, j)]);
        sum += (err.transpose() * p3.try_inverse().unwrap() * err)[0];
    }
    let (lo, hi) = (
        chi_square_quantile(3 * n, 0.0005),
        chi_square_quantile(3 * n, 0.9995),
    );
    assert!(lo > 3300.0 && hi < 3900.0, "{lo} {hi}");
    assert!(sum > lo && sum < hi, "NEES sum {sum} outside [{lo}, {hi}]");
}

/// A window of 3 satellites then one of 2: exactly that many measured inside, the
/// highest ones; more than 4 outside.
#[test]
fn windows_hold_exactly_n_satellites() {
    let mut model = quiet();
    model.windows = vec![
        Window {
            start: T0 + 20.0,
            end: T0 + 80.0,
            keep: Keep::Highest(3),
        },
        Window {
            start: T0 + 80.0,
            end: T0 + 110.0,
            keep: Keep::Highest(2),
        },
        Window {
            start: T0 + 130.0,
            end: T0 + 140.0,
            keep: Keep::Listed(vec![Sat::new(System::Gps, 99)]),
        },
    ];
    let open = run(quiet(), 150, 4);
    for (e, o) in run(model, 150, 4).iter().zip(&open) {
        let k = e.epoch.t.diff_s(GpsTime::new(WEEK, T0));
        let n = e.epoch.sats().len();
        let want = match k {
            k if (20.0..80.0).contains(&k) => Some(3),
            k if (80.0..110.0).contains(&k) => Some(2),
            k if (130.0..140.0).contains(&k) => Some(0),
            _ => None,
        };
        match want {
            Some(w) => {
                assert_eq!(n, w, "t = {k}");
                // The highest of the open sky's.
                let mut els: Vec<f64> = o.sats.iter().map(|s| s.elevation).collect();
                els.sort_by(|a, b| b.total_cmp(a));
                for s in &e.sats {
                    assert!(els[..w].contains(&s.elevation));
                }
            }
            None => assert!(n > 4, "t = {k}: {n}"),
        }
    }
}

/// A 50-m step on one satellite for 20 s: the pseudoranges differ from the run
/// without it on that satellite inside the interval alone, by 50 m (to 1e-7 m, the
/// rounding of 2e7 m), and nothing else differs at all (the same draws).
#[test]
fn a_step_fault_appears_on_one_satellite_only() {
    // The lowest-numbered satellite seen all through the interval.
    let clean = run(quiet(), 200, 5);
    let g05 = *clean[50]
        .epoch
        .sats()
        .iter()
        .find(|s| clean[50..70].iter().all(|e| e.epoch.sats().contains(s)))
        .expect("a satellite seen throughout");
    let mut model = quiet();
    model.code_std = [0.3, 0.3];
    model.multipath = Some(GaussMarkov {
        sigma: 0.5,
        tau: 30.0,
    });
    let start = T0 + 50.0;
    let mut faulty = model.clone();
    faulty.faults = vec![Fault {
        sat: g05,
        start,
        end: start + 20.0,
        step_m: 50.0,
    }];
    let (a, b) = (run(model, 200, 5), run(faulty, 200, 5));
    let mut stepped = 0;
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.epoch.measurements.len(), y.epoch.measurements.len());
        let t = x.epoch.t.diff_s(GpsTime::new(WEEK, 0.0));
        for (m, n) in x.epoch.measurements.iter().zip(&y.epoch.measurements) {
            assert_eq!(m.sat, n.sat);
            assert_eq!(m.doppler, n.doppler);
            let d = n.pseudorange.unwrap() - m.pseudorange.unwrap();
            if m.sat == g05 && t >= start && t < start + 20.0 {
                assert!((d - 50.0).abs() < 1e-7, "{d}");
                stepped += 1;
            } else {
                assert_eq!(d, 0.0, "{} at {t}", m.sat);
            }
        }
    }
    assert_eq!(stepped, 20);
}

/// Same seed, same bits; another seed, other noise.
#[test]
fn deterministic_by_seed() {
    let mut model = quiet();
    model.code_std = [0.3, 0.3];
    model.clock.h0 = 2e-19;
    let (a, b, c) = (
        run(model.clone(), 30, 9),
        run(model.clone(), 30, 9),
        run(model, 30, 10),
    );
    assert_eq!(a, b);
    assert_ne!(a, c);
}
