//! A whole simulation: scenario in, truth and sensor streams out, through a sink.
//!
//! IMU samples are taken at `t0 + k/rate` for `k = 0..=N`; sample `k` holds the exact
//! increments over `((k-1)/rate, k/rate]` corrupted by the IMU model, so sample 0 ends
//! at the start time and carries the initial state (as `schuler nav` expects). GNSS and
//! barometer epochs fall on `t0 + j/rate` of their own rates.

use super::analytic::{self, Kinematics, Trajectory};
use super::gnss_ins_sim::MotionDefinition;
use super::imu_model::ImuSimulator;
use super::motion::{MotionBuilder, Start};
use super::receivers::Interval;
use super::receivers::{BaroReading, BaroSimulator, GnssFix, GnssSimulator};
use super::scenario::{MotionSpec, ScenarioError, SegmentSpec, StartSpec};
use super::sensor_spec::{BaroSpec, GnssSpec, ImuSpec};
use super::spline::SplineTrajectory;
use crate::earth::{EarthModel, Sphere, Wgs84};
use crate::imu::ImuSample;
use crate::nav::NavState;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The Earth model of a scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EarthSpec {
    /// WGS84.
    #[default]
    Wgs84,
    /// The textbook's rotating sphere.
    Sphere,
    /// The textbook's sphere without rotation.
    SphereFixed,
}

/// A complete scenario as written in TOML.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    /// Master seed of every random draw.
    #[serde(default)]
    pub seed: u64,
    /// Earth model.
    #[serde(default)]
    pub earth: EarthSpec,
    /// Initial state (unless the motion comes from `motion_csv`).
    pub start: Option<StartSpec>,
    /// Maneuvers.
    #[serde(default)]
    pub motion: Vec<SegmentSpec>,
    /// A gnss-ins-sim motion-definition CSV file instead of `start` and `motion`
    /// (read by the caller into `imported`).
    pub motion_csv: Option<String>,
    /// The parsed `motion_csv`.
    #[serde(skip)]
    pub imported: Option<MotionDefinition>,
    /// IMU.
    pub imu: ImuSpec,
    /// GNSS receiver (none if absent).
    pub gnss: Option<GnssSpec>,
    /// Barometer (none if absent).
    pub baro: Option<BaroSpec>,
}

impl ScenarioSpec {
    /// The scenario as actually used: presets folded in, everything explicit.
    pub fn resolved(&self) -> ScenarioSpec {
        ScenarioSpec {
            imu: self.imu.resolved_spec(),
            ..self.clone()
        }
    }

    /// The trajectory on `earth`: from `imported` if present, else `start` and
    /// `motion`; and the GNSS outages the motion file adds.
    pub fn trajectory<E: EarthModel>(
        &self,
        earth: E,
    ) -> Result<(SplineTrajectory, Vec<Interval>), ScenarioError> {
        if let Some(def) = &self.imported {
            let (pieces, outages) = def.pieces();
            let start = Start {
                t: self.start.as_ref().map_or(0.0, |s| s.time),
                pos: def.pos,
                v_n: def.attitude.to_dcm() * def.v_body,
                attitude: def.attitude,
            };
            let mut b = MotionBuilder::new(earth, &start);
            for (i, p) in pieces.iter().enumerate() {
                b.push(p).map_err(|source| ScenarioError::Motion {
                    key: format!("motion_csv piece {i}"),
                    source,
                })?;
            }
            let traj = b.finish().map_err(|source| ScenarioError::Motion {
                key: "motion_csv".into(),
                source,
            })?;
            let outages = outages
                .iter()
                .map(|[a, b]| Interval {
                    start: start.t + a,
                    end: start.t + b,
                })
                .collect();
            return Ok((traj, outages));
        }
        let start = self.start.clone().ok_or_else(|| ScenarioError::Value {
            key: "start".into(),
            message: "missing: give [start] and [[motion]], or motion_csv".into(),
        })?;
        let spec = MotionSpec {
            start,
            motion: self.motion.clone(),
        };
        Ok((spec.build(earth)?, Vec::new()))
    }
}

/// One IMU epoch: the exact and the measured sample, the truth at its end time and
/// the instantaneous kinematics there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuEpoch {
    /// The exact increments over `(t - dt, t]`.
    pub exact: ImuSample,
    /// The same corrupted by the IMU model.
    pub measured: ImuSample,
    /// The true state at `t`.
    pub truth: NavState,
    /// The true angular rate and specific force at `t`.
    pub kin: Kinematics,
}

/// Consecutive epochs of every stream: IMU epochs in time order, and the GNSS fixes and
/// barometer readings that fall among them, each tagged with the index of the IMU
/// epoch it follows (it falls in `(t - dt, t]` of that epoch).
#[derive(Debug, Clone, Default)]
pub struct SimBlock {
    /// IMU epochs.
    pub imu: Vec<ImuEpoch>,
    /// GNSS fixes after `imu[index]`.
    pub gnss: Vec<(usize, GnssFix)>,
    /// Barometer readings after `imu[index]`.
    pub baro: Vec<(usize, BaroReading)>,
}

/// Receives the simulated streams in time order.
pub trait SimSink {
    /// One IMU epoch: the exact and the measured sample, the truth at its end time and
    /// the instantaneous kinematics there.
    fn imu(
        &mut self,
        exact: &ImuSample,
        measured: &ImuSample,
        truth: &NavState,
        kin: &Kinematics,
    ) -> std::io::Result<()>;
    /// One GNSS fix.
    fn gnss(&mut self, fix: &GnssFix) -> std::io::Result<()>;
    /// One barometer reading.
    fn baro(&mut self, reading: &BaroReading) -> std::io::Result<()>;
    /// A block of consecutive epochs; by default one call of [`SimSink::imu`],
    /// [`SimSink::gnss`] and [`SimSink::baro`] per epoch, in time order. A sink that
    /// writes streams to separate files may take the block whole (and format it in
    /// parallel).
    fn block(&mut self, block: &SimBlock) -> std::io::Result<()> {
        let (mut g, mut b) = (block.gnss.iter().peekable(), block.baro.iter().peekable());
        for (i, e) in block.imu.iter().enumerate() {
            self.imu(&e.exact, &e.measured, &e.truth, &e.kin)?;
            while let Some((_, fix)) = g.next_if(|(j, _)| *j == i) {
                self.gnss(fix)?;
            }
            while let Some((_, r)) = b.next_if(|(j, _)| *j == i) {
                self.baro(r)?;
            }
        }
        Ok(())
    }
}

/// Why a simulation failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// The scenario is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The sink failed to write.
    #[error("writing the simulated data failed: {0}")]
    Io(#[from] std::io::Error),
}

/// What a simulation produced.
#[derive(Debug, Clone, PartialEq)]
pub struct SimSummary {
    /// IMU samples written (including sample 0).
    pub imu_samples: u64,
    /// GNSS fixes written.
    pub gnss_fixes: u64,
    /// Barometer readings written.
    pub baro_readings: u64,
    /// Start and end time [s].
    pub t0: f64,
    /// End time [s].
    pub t1: f64,
}

/// Run `spec` into `sink`.
pub fn simulate(spec: &ScenarioSpec, sink: &mut impl SimSink) -> Result<SimSummary, SimError> {
    match spec.earth {
        EarthSpec::Wgs84 => simulate_on(Wgs84, spec, sink),
        EarthSpec::Sphere => simulate_on(Sphere::textbook(true), spec, sink),
        EarthSpec::SphereFixed => simulate_on(Sphere::textbook(false), spec, sink),
    }
}

/// Angular rate of the body relative to the navigation frame, `w_nb_b = w_ib_b -
/// C_nb (w_ie_n + w_en_n)`, for the GNSS lever-arm velocity.
fn w_nb_b<E: EarthModel>(earth: &E, s: &NavState, k: &Kinematics) -> nalgebra::Vector3<f64> {
    let l = earth.local(s.pos.lat, s.pos.h);
    k.w_ib_b - s.q_bn.inverse() * (l.w_ie_n() + l.w_en_n(&s.v_n))
}

/// Run `spec` on a given Earth model.
pub fn simulate_on<E: EarthModel>(
    earth: E,
    spec: &ScenarioSpec,
    sink: &mut impl SimSink,
) -> Result<SimSummary, SimError> {
    let imu_model = spec.imu.model()?;
    let mut gnss_model = spec.gnss.as_ref().map(GnssSpec::model).transpose()?;
    let baro_model = spec.baro.as_ref().map(BaroSpec::model).transpose()?;
    let (traj, motion_outages) = spec.trajectory(earth)?;
    if let Some(g) = gnss_model.as_mut() {
        g.outages.extend(motion_outages);
    }
    let (t0, t1) = (traj.start(), traj.end());
    let dt = 1.0 / spec.imu.rate_hz;
    let n = ((t1 - t0) / dt + 1e-9).floor() as u64;
    let mut imu = ImuSimulator::new(imu_model, spec.seed);
    let mut gnss = gnss_model.map(|m| GnssSimulator::new(m, spec.seed));
    let mut baro = baro_model.map(|m| BaroSimulator::new(m, spec.seed));
    let mut summary = SimSummary {
        imu_samples: 0,
        gnss_fixes: 0,
        baro_readings: 0,
        t0,
        t1,
    };
    let (mut next_gnss, mut next_baro) = (0u64, 0u64);
    let threads = std::thread::available_parallelism()
        .map_or(1, usize::from)
        .clamp(1, 8);
    let before = analytic::kinematics(&earth, &traj, t0 - dt);
    let mut block = SimBlock::default();
    let (mut exact, mut next) = (Vec::new(), Vec::new());
    exact_block(
        &earth,
        &traj,
        t0,
        dt,
        0,
        BLOCK.min(n + 1),
        &before,
        threads,
        &mut exact,
    );
    let mut k0 = 0u64;
    while k0 <= n {
        let k1 = (k0 + BLOCK).min(n + 1);
        let k2 = (k1 + BLOCK).min(n + 1);
        let last = exact.last().map_or(before, |e| e.2);
        // The next block's exact samples are computed while this one is measured and
        // written, so the sequential parts (the random processes, the writes) overlap
        // with parallel work and both cores stay busy.
        std::thread::scope(|scope| -> Result<(), SimError> {
            let (earth_ref, traj_ref, next_ref) = (&earth, &traj, &mut next);
            let job = scope.spawn(move || {
                exact_block(
                    earth_ref, traj_ref, t0, dt, k1, k2, &last, threads, next_ref,
                );
            });
            block.imu.clear();
            block.gnss.clear();
            block.baro.clear();
            for (i, (exact, truth, kin)) in exact.iter().enumerate() {
                let t = exact.t;
                block.imu.push(ImuEpoch {
                    exact: *exact,
                    measured: imu.measure(exact),
                    truth: *truth,
                    kin: *kin,
                });
                // Aiding epochs that fall in (t - dt, t] are taken at their own exact
                // times.
                if let Some(g) = gnss.as_mut() {
                    emit_epochs(&mut next_gnss, g.interval(), t0, t, |te| {
                        let (s, kin) = analytic::evaluate(&earth, &traj, te);
                        if let Some(fix) = g.fix(&earth, &s, &w_nb_b(&earth, &s, &kin)) {
                            block.gnss.push((i, fix));
                        }
                    });
                }
                if let Some(b) = baro.as_mut() {
                    emit_epochs(&mut next_baro, b.interval(), t0, t, |te| {
                        let h = traj.position(super::jet::Jet::constant(te))[2].v;
                        if let Some(r) = b.reading(te, t0, h) {
                            block.baro.push((i, r));
                        }
                    });
                }
            }
            let written = sink.block(&block);
            job.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            Ok(written?)
        })?;
        std::mem::swap(&mut exact, &mut next);
        summary.imu_samples += block.imu.len() as u64;
        summary.gnss_fixes += block.gnss.len() as u64;
        summary.baro_readings += block.baro.len() as u64;
        k0 = k1;
    }
    Ok(summary)
}

/// Samples computed per block (in parallel, then written in order).
const BLOCK: u64 = 8192;

/// One exact sample with the truth and kinematics at its end.
type Exact = (ImuSample, NavState, Kinematics);

/// Exact samples `k0..k1` (sample `k` ends at `t0 + k dt`) into `out` (its memory
/// reused from block to block), split over `threads` threads. Each sample is a pure
/// function of its time, so the result does not depend on the split: the same bits
/// with one thread or eight.
#[allow(clippy::too_many_arguments)]
fn exact_block<E: EarthModel, T: Trajectory + Sync>(
    earth: &E,
    traj: &T,
    t0: f64,
    dt: f64,
    k0: u64,
    k1: u64,
    before: &Kinematics,
    threads: usize,
    out: &mut Vec<Exact>,
) {
    let run = |from: u64, part: &mut [Exact], mut prev: Kinematics| {
        for (k, slot) in (from..).zip(part.iter_mut()) {
            *slot = analytic::increment_from(earth, traj, t0 + k as f64 * dt, dt, &prev);
            prev = slot.2;
        }
    };
    let len = (k1 - k0) as usize;
    let placeholder = (
        ImuSample {
            t: 0.0,
            dt: 0.0,
            dtheta: Vector3::zeros(),
            dvel: Vector3::zeros(),
        },
        NavState {
            t: 0.0,
            pos: crate::earth::Geodetic::default(),
            v_n: Vector3::zeros(),
            q_bn: nalgebra::UnitQuaternion::identity(),
        },
        Kinematics::default(),
    );
    out.clear();
    out.resize(len, placeholder);
    if threads <= 1 || len < 64 {
        run(k0, out, *before);
        return;
    }
    let chunk = len.div_ceil(threads);
    std::thread::scope(|scope| {
        let mut parts = out.chunks_mut(chunk).enumerate();
        let first = parts.next();
        for (i, part) in parts {
            let from = k0 + (i * chunk) as u64;
            let run = &run;
            scope.spawn(move || {
                let prev = analytic::kinematics(earth, traj, t0 + (from as f64 - 1.0) * dt);
                run(from, part, prev);
            });
        }
        if let Some((_, part)) = first {
            run(k0, part, *before);
        }
    });
}

/// Call `f` for every epoch `t0 + j*interval <= t` not yet emitted.
fn emit_epochs(next: &mut u64, interval: f64, t0: f64, t: f64, mut f: impl FnMut(f64)) {
    loop {
        let te = t0 + *next as f64 * interval;
        if te > t + 1e-9 * interval {
            return;
        }
        f(te);
        *next += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENARIO: &str = r#"
seed = 4
[start]
position = ["45 deg", "7 deg", "300 m"]
attitude = ["0 deg", "0 deg", "10 deg"]
speed = "30 m/s"
[[motion]]
type = "turn"
angle = "60 deg"
bank = "20 deg"
[[motion]]
type = "hold"
duration = "3 s"
[imu]
rate_hz = 400
preset = "tactical"
[gnss]
rate_hz = 5
position_std = ["0.5 m", "0.5 m", "1 m"]
[baro]
rate_hz = 20
noise = "0.5 m"
"#;

    fn spec() -> ScenarioSpec {
        toml::from_str(SCENARIO).expect("scenario")
    }

    /// The exact samples do not depend on how a block is split over threads: the
    /// same bits with one thread, two or five.
    #[test]
    fn exact_blocks_are_the_same_for_any_thread_count() {
        let (traj, _) = spec().trajectory(Wgs84).expect("trajectory");
        let (t0, dt) = (traj.start(), 1.0 / 400.0);
        let before = analytic::kinematics(&Wgs84, &traj, t0 + 99.0 * dt);
        let mut one = Vec::new();
        exact_block(&Wgs84, &traj, t0, dt, 100, 1100, &before, 1, &mut one);
        for threads in [2, 5] {
            let mut many = Vec::new();
            exact_block(
                &Wgs84, &traj, t0, dt, 100, 1100, &before, threads, &mut many,
            );
            assert!(one == many, "{threads} threads differ from one");
        }
        assert_eq!(one.len(), 1000);
    }

    /// Records the order of the calls it receives.
    #[derive(Default)]
    struct Recorder {
        events: Vec<(char, f64)>,
    }

    impl SimSink for Recorder {
        fn imu(
            &mut self,
            _exact: &ImuSample,
            measured: &ImuSample,
            _truth: &NavState,
            _kin: &Kinematics,
        ) -> std::io::Result<()> {
            self.events.push(('i', measured.t));
            Ok(())
        }
        fn gnss(&mut self, fix: &GnssFix) -> std::io::Result<()> {
            self.events.push(('g', fix.t));
            Ok(())
        }
        fn baro(&mut self, reading: &BaroReading) -> std::io::Result<()> {
            self.events.push(('b', reading.t));
            Ok(())
        }
    }

    /// Through the default `SimSink::block`, a sink still receives every stream in
    /// time order: each GNSS fix and barometer reading right after the IMU epoch whose
    /// interval `(t - dt, t]` holds it, and the counts match the summary.
    #[test]
    fn default_block_delivers_in_time_order() {
        let mut rec = Recorder::default();
        let summary = simulate(&spec(), &mut rec).expect("simulate");
        let count = |c| rec.events.iter().filter(|e| e.0 == c).count() as u64;
        assert_eq!(count('i'), summary.imu_samples);
        assert_eq!(count('g'), summary.gnss_fixes);
        assert_eq!(count('b'), summary.baro_readings);
        assert!(summary.gnss_fixes > 10 && summary.baro_readings > 40);
        let dt = 1.0 / 400.0;
        let mut last_imu = f64::NEG_INFINITY;
        for &(kind, t) in &rec.events {
            if kind == 'i' {
                assert!(t > last_imu);
                last_imu = t;
            } else {
                assert!(
                    t > last_imu - dt - 1e-9 && t <= last_imu + 1e-9,
                    "{kind} at {t}"
                );
            }
        }
    }
}
