//! The library's navigation session driven in memory, as a live front end drives it:
//! aids arriving early or late (within the reorder window) give the same trajectory as
//! the batch run, bit for bit; an aid later than the window is reported and not used.
//! The truth is an exact maneuvering flight (`sim::analytic`); GNSS and barometer
//! readings are drawn around it with a seeded stream.

use nalgebra::Vector3;
use schuler::earth::{EarthModel, Geodetic, Wgs84};
use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig};
use schuler::imu::ImuSample;
use schuler::imu::random::Noise;
use schuler::session::{Aid, Epoch, Event, FilterConfig, Session, SessionConfig, Start, Summary};
use schuler::sim::analytic::{self, Maneuvering};
use schuler::sim::imu_model::ImuSimulator;
use schuler::sim::sensor_spec::{ImuSpec, Preset};

const RATE: f64 = 100.0;
const SECONDS: usize = 300;

/// The flight's measured IMU samples (tactical grade, seeded), its start and its aids:
/// GNSS at every second (0.5 m, 1 m), barometer at 10 Hz (0.5 m) with a 3-m bias.
struct Log {
    imu: Vec<ImuSample>,
    start: Start,
    aids: Vec<Aid>,
    noise: ImuNoise,
}

fn log() -> Log {
    let earth = Wgs84;
    let traj = Maneuvering::flight(Geodetic::from_degrees(45.0, 7.0, 300.0));
    let spec = ImuSpec::of_preset(RATE, Preset::Tactical);
    let model = spec.model().expect("preset");
    let noise = ImuNoise::from_model(&model);
    let mut imu_sim = ImuSimulator::new(model, 5);
    let dt = 1.0 / RATE;
    let n = SECONDS * RATE as usize;
    let imu: Vec<ImuSample> = analytic::samples(&earth, &traj, -dt, dt, n + 1)
        .map(|s| imu_sim.measure(&s))
        .collect();
    let mut rng = Noise::new(17, 0);
    let mut aids = Vec::new();
    for k in 1..=SECONDS {
        let t = k as f64;
        let truth = analytic::state(&earth, &traj, t);
        let mut pos = truth.pos;
        let r = earth.local(pos.lat, pos.h).radii;
        pos.lat += 0.5 * rng.normal() / (r.meridian + pos.h);
        pos.lon += 0.5 * rng.normal() / ((r.prime_vertical + pos.h) * pos.lat.cos());
        pos.h += rng.normal();
        aids.push(Aid::Gnss(GnssFix {
            t,
            pos,
            pos_std: Vector3::new(0.5, 0.5, 1.0),
            vel: None,
        }));
    }
    for k in 1..=10 * SECONDS {
        let t = k as f64 * 0.1;
        let h = analytic::state(&earth, &traj, t).pos.h + 3.0 + 0.5 * rng.normal();
        aids.push(Aid::Baro { t, h });
    }
    aids.sort_by(|a, b| a.t().total_cmp(&b.t()));
    Log {
        start: Start::at(analytic::state(&earth, &traj, 0.0)),
        imu,
        aids,
        noise,
    }
}

/// The filter with a barometer-bias state (prior 10 m), output at 10 Hz.
fn config(window: f64, noise: ImuNoise) -> SessionConfig {
    SessionConfig {
        output_rate: Some(10.0),
        reorder_window: window,
        filter: Some(FilterConfig {
            baro_std: 0.5,
            ..FilterConfig::new(IntegrationConfig {
                baro: Some((10.0, 0.0)),
                ..IntegrationConfig::new(noise)
            })
        }),
        ..SessionConfig::default()
    }
}

/// What a run gives: its epochs, the measurements tested, its summary and events.
struct Run {
    epochs: Vec<Epoch>,
    events: Vec<Event>,
    summary: Summary,
}

/// Push `inputs` (in the order given) into a session with `window`, taking what
/// comes out after every push.
fn run(noise: ImuNoise, start: Start, window: f64, inputs: &[Input]) -> Run {
    let mut s = Session::new(Wgs84, config(window, noise), start).expect("valid configuration");
    let (mut epochs, mut events) = (Vec::new(), Vec::new());
    for input in inputs {
        match input {
            Input::Imu(x) => s.push_imu(*x).expect("samples in order"),
            Input::Aid(a) => s.push(a.clone()).expect("finite aid"),
        }
        epochs.extend(s.epochs());
        events.extend(s.events());
    }
    let end = s.finish().expect("samples were pushed");
    epochs.extend(end.epochs);
    events.extend(end.events);
    Run {
        epochs,
        events,
        summary: end.summary,
    }
}

#[derive(Debug, Clone)]
enum Input {
    Imu(ImuSample),
    Aid(Aid),
}

/// The batch order: every aid first, then the samples.
fn batch(log: &Log) -> Vec<Input> {
    let aids = log.aids.iter().map(|a| Input::Aid(a.clone()));
    aids.chain(log.imu.iter().map(|s| Input::Imu(*s))).collect()
}

/// Arrival order of a live feed: a sample arrives at its time, an aid at its time
/// plus a uniform delay in [-0.5, 0.5] s (early or late), plus `extra` late arrivals.
fn jittered(log: &Log, seed: u64, extra: &[(f64, Aid)]) -> Vec<Input> {
    let mut rng = Noise::new(seed, 1);
    let mut timed: Vec<(f64, Input)> = log.imu.iter().map(|s| (s.t, Input::Imu(*s))).collect();
    timed.extend(
        log.aids
            .iter()
            .map(|a| (a.t() + rng.uniform() - 0.5, Input::Aid(a.clone()))),
    );
    timed.extend(extra.iter().map(|(at, a)| (*at, Input::Aid(a.clone()))));
    timed.sort_by(|a, b| a.0.total_cmp(&b.0));
    timed.into_iter().map(|x| x.1).collect()
}

fn measurements(events: &[Event]) -> Vec<(f64, f64, bool)> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Measurement(i) => Some((i.t, i.nis, i.accepted)),
            _ => None,
        })
        .collect()
}

/// Aids up to 0.5 s early or late with a 0.6-s window: the same epochs (state,
/// standard deviations, sensor estimates) and the same measurements as the batch run,
/// bit for bit (the session applies each aid at its own time whatever its arrival).
/// A fix arriving 2 s after its time is reported late and changes nothing.
#[test]
fn streaming_with_jittered_aids_equals_the_batch_run() {
    let log = log();
    let batch = run(log.noise, log.start, 0.0, &batch(&log));
    let late_fix = match log.aids.iter().find(|a| a.t() == 150.0) {
        Some(Aid::Gnss(f)) => Aid::Gnss(GnssFix {
            t: 150.5,
            pos: Geodetic {
                h: f.pos.h + 100.0,
                ..f.pos
            },
            ..*f
        }),
        _ => panic!("a fix at 150 s"),
    };
    let live = run(
        log.noise,
        log.start,
        0.6,
        &jittered(&log, 3, &[(152.5, late_fix)]),
    );
    assert_eq!(batch.epochs.len(), SECONDS * 10 + 1);
    assert_eq!(live.epochs.len(), batch.epochs.len());
    for (a, b) in live.epochs.iter().zip(&batch.epochs) {
        assert_eq!(a, b, "epochs differ at t = {}", b.state.t);
    }
    assert_eq!(measurements(&live.events), measurements(&batch.events));
    assert_eq!(live.summary.counts, batch.summary.counts);
    assert!(
        batch.summary.counts.position >= 295,
        "{:?}",
        batch.summary.counts
    );
    assert_eq!(batch.summary.late, 0);
    assert_eq!(live.summary.late, 1);
    let late: Vec<&Event> = live
        .events
        .iter()
        .filter(|e| matches!(e, Event::Late { .. }))
        .collect();
    match late.as_slice() {
        [
            Event::Late {
                t, integrated_to, ..
            },
        ] => {
            assert_eq!(*t, 150.5);
            assert!(*integrated_to > 150.5 && *integrated_to <= 152.5 - 0.6 + 0.01);
        }
        other => panic!("one late fix expected: {other:?}"),
    }
}

/// A session refuses what it cannot use, naming what: samples out of order, a
/// non-finite aid; an invalid configuration names its field.
#[test]
fn bad_input_is_refused_with_its_reason() {
    let log = log();
    let mut s = Session::new(Wgs84, config(0.0, log.noise), log.start).expect("valid");
    s.push_imu(log.imu[0]).expect("first");
    s.push_imu(log.imu[1]).expect("second");
    let e = s.push_imu(log.imu[1]).expect_err("repeated time");
    assert!(
        e.to_string().contains("is not after the previous one"),
        "{e}"
    );
    let e = s
        .push(Aid::Baro {
            t: 1.0,
            h: f64::NAN,
        })
        .expect_err("NaN height");
    assert!(e.to_string().contains("baro_height at t = 1"), "{e}");
    let mut bad = config(0.0, log.noise);
    bad.output_rate = Some(-1.0);
    let e = Session::new(Wgs84, bad, log.start).expect_err("negative rate");
    assert!(e.to_string().starts_with("output_rate:"), "{e}");
    let mut bad = config(0.0, log.noise);
    if let Some(f) = bad.filter.as_mut() {
        f.integration.init_pos_std.x = 0.0;
    }
    let e = bad.validate().expect_err("zero std");
    assert_eq!(e.field, "filter.integration.init_pos_std");
    let e = Session::new(Wgs84, SessionConfig::default(), log.start)
        .expect("free")
        .finish()
        .expect_err("no samples");
    assert!(e.to_string().contains("no IMU sample"), "{e}");
}

/// Free-inertial sessions have no use for GNSS: the fix is reported as ignored, not
/// silently dropped.
#[test]
fn aids_the_configuration_cannot_use_are_reported() {
    let log = log();
    let mut s = Session::new(Wgs84, SessionConfig::default(), log.start).expect("free");
    s.push(log.aids[0].clone()).expect("finite");
    let events: Vec<Event> = s.events().collect();
    assert!(
        matches!(events.as_slice(), [Event::Ignored { reason, .. }] if reason.contains("filter")),
        "{events:?}"
    );
    for x in &log.imu[..10] {
        s.push_imu(*x).expect("in order");
    }
    let end = s.finish().expect("samples");
    assert_eq!(end.summary.ignored, 1);
    assert_eq!(end.summary.samples, 9);
}

/// A solution outside the physical envelope is reported once per bound, with its
/// time, and the run goes on: a start at 1200 m/s (above Mach 3) and 2 km below the
/// ellipsoid, free-inertial.
#[test]
fn leaving_the_envelope_is_reported_once() {
    let log = log();
    let mut start = log.start;
    start.state.v_n.x += 1200.0;
    start.state.pos.h = -2000.0;
    let cfg = SessionConfig {
        output_rate: Some(1.0),
        ..SessionConfig::default()
    };
    let mut s = Session::new(Wgs84, cfg, start).expect("free");
    let mut warnings = Vec::new();
    for x in &log.imu[..3000] {
        s.push_imu(*x).expect("in order");
        s.epochs().for_each(drop);
        warnings.extend(s.events().filter_map(|e| match e {
            Event::Envelope { t, what } => Some((t, what)),
            _ => None,
        }));
    }
    let end = s.finish().expect("samples");
    assert_eq!(end.summary.samples, 2999);
    assert_eq!(end.summary.envelope_warnings, 2);
    let [(t0, low), (t1, fast)] = warnings.as_slice() else {
        panic!("two warnings: {warnings:?}");
    };
    assert_eq!((*t0, *t1), (0.0, 0.0));
    assert!(low.starts_with("height -2000.0 m below -1000 m"), "{low}");
    assert!(fast.starts_with("speed 12"), "{fast}");
}

/// The gate's reset after five refusals in a row accepts a fix the filter has lost
/// track of (here ten in a row 60 m off: 120 standard deviations, a jump the gate
/// refuses) but never an impossible one (ten 10 km off: 20,000 standard deviations,
/// beyond the reset's 1000); a reset is logged with its NIS.
#[test]
fn the_gate_reset_refuses_impossible_fixes() {
    let log = log();
    let run_with_jump = |jump: f64| {
        let aids: Vec<Aid> = log
            .aids
            .iter()
            .map(|a| match a {
                Aid::Gnss(f) if f.t > 100.0 && f.t <= 110.0 => {
                    let mut f = *f;
                    f.pos.lat += jump / 6_378_137.0;
                    Aid::Gnss(f)
                }
                other => other.clone(),
            })
            .collect();
        let inputs: Vec<Input> = aids
            .iter()
            .map(|a| Input::Aid(a.clone()))
            .chain(log.imu.iter().map(|s| Input::Imu(*s)))
            .collect();
        run(log.noise, log.start, 0.0, &inputs)
    };
    let resets = |r: &Run| -> Vec<(f64, f64)> {
        r.events
            .iter()
            .filter_map(|e| match e {
                Event::GateReset { t, nis } => Some((*t, *nis)),
                _ => None,
            })
            .collect()
    };
    let lost = run_with_jump(60.0);
    let impossible = run_with_jump(10_000.0);
    println!(
        "resets 60 m: {:?}; 10 km: {:?}",
        resets(&lost),
        resets(&impossible)
    );
    // 60 m off: the sixth fix in a row is let through (NIS ≈ (60/0.5)²·…, far above
    // the gate, far below the bound of 1000 sigma per axis).
    let r = resets(&lost);
    assert!(
        matches!(r.first(), Some(&(t, nis)) if t == 106.0 && nis > 100.0 && nis < 3e6),
        "{r:?}"
    );
    // 10 km off: all ten refused; the first good fix after them is accepted by the
    // reset with a small NIS.
    let r = resets(&impossible);
    assert!(r.iter().all(|&(t, nis)| t > 110.0 && nis < 100.0), "{r:?}");
    assert_eq!(impossible.summary.counts.rejected, 10);
}

/// A truth pushed in step with the samples (before each sample, its epochs up to 1 s
/// past the sample and the first one after, as `schuler nav` streams `--truth`) gives
/// the snapshots of the whole truth given at the start, NEES included, bit for bit;
/// the snapshots taken as they come are those a finished session would hand over.
/// The truth is at 3 Hz, offset from the once-a-second snapshots, so most NEES use an
/// interpolated truth, and it starts before and ends after the samples.
#[test]
fn a_streamed_truth_gives_the_snapshots_of_the_whole_truth() {
    use schuler::analysis::errors::NavRecord;
    use schuler::session::Snapshot;
    let log = log();
    let traj = Maneuvering::flight(Geodetic::from_degrees(45.0, 7.0, 300.0));
    let truth: Vec<NavRecord> = (0..3 * SECONDS + 12)
        .map(|k| NavRecord::from(&analytic::state(&Wgs84, &traj, k as f64 / 3.0 - 0.9)))
        .collect();
    let new = || Session::new(Wgs84, config(0.0, log.noise), log.start).expect("valid");
    let mut whole = new().with_truth(truth.clone());
    let mut streamed = new();
    for a in &log.aids {
        whole.push(a.clone()).expect("aid");
        streamed.push(a.clone()).expect("aid");
    }
    let (mut next, mut taken): (usize, Vec<Snapshot>) = (0, Vec::new());
    for s in &log.imu {
        // Until the last epoch pushed is past the horizon.
        while let Some(r) = truth.get(next) {
            if next > 0 && truth[next - 1].t_sow > s.t + 1.0 {
                break;
            }
            streamed.push_truth(*r);
            next += 1;
        }
        whole.push_imu(*s).expect("sample");
        streamed.push_imu(*s).expect("sample");
        taken.extend(streamed.snapshots());
    }
    let whole = whole.finish().expect("finish").snapshots;
    taken.extend(streamed.finish().expect("finish").snapshots);
    assert!(next < truth.len(), "the truth's last epochs stay unread");
    assert_eq!(whole.len(), SECONDS + 1);
    let with_nees = whole.iter().filter(|s| s.nees.is_some()).count();
    assert_eq!(with_nees, whole.len(), "every snapshot inside the truth");
    assert_eq!(taken, whole);
}
