//! A whole simulation: scenario in, truth and sensor streams out, through a sink.
//!
//! IMU samples are taken at `t0 + k/rate` for `k = 0..=N`; sample `k` holds the exact
//! increments over `((k-1)/rate, k/rate]` corrupted by the IMU model, so sample 0 ends
//! at the start time and carries the initial state (as `schuler nav` expects). GNSS and
//! barometer epochs fall on `t0 + j/rate` of their own rates.

use super::analytic::{self, Kinematics, Trajectory};
use super::gnss_ins_sim::MotionDefinition;
use super::imu_model::ImuSimulator;
use super::motion::{KnotFeed, MotionBuilder, Start};
use super::receivers::Interval;
use super::receivers::{BaroReading, BaroSimulator, GnssFix, GnssSimulator};
use super::scenario::{MotionSpec, ScenarioError, SegmentSpec, StartSpec};
use super::sensor_spec::{BaroSpec, GnssSpec, ImuSpec};
use super::spline::{Knot, SplineTrajectory};
use crate::earth::{EarthModel, Sphere, Wgs84};
use crate::imu::ImuSample;
use crate::nav::NavState;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::sync::{Condvar, Mutex};

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
        let trajectory = match &self.imported {
            Some(def) => self
                .imported_builder(earth, def, None)?
                .finish()
                .map_err(imported_error)?,
            None => self.motion_spec()?.build(earth)?,
        };
        Ok((trajectory, self.motion_outages()))
    }

    /// The GNSS outages the motion file adds (none without one).
    pub fn motion_outages(&self) -> Vec<Interval> {
        let Some(def) = &self.imported else {
            return Vec::new();
        };
        let t0 = self.start.as_ref().map_or(0.0, |s| s.time);
        def.pieces()
            .1
            .iter()
            .map(|[a, b]| Interval {
                start: t0 + a,
                end: t0 + b,
            })
            .collect()
    }

    /// The motion's span, with its knots sent to `feed` as they are made and not kept
    /// (constant memory however long the motion).
    pub fn trajectory_fed<E: EarthModel>(
        &self,
        earth: E,
        feed: KnotFeed,
    ) -> Result<Interval, ScenarioError> {
        match &self.imported {
            Some(def) => self
                .imported_builder(earth, def, Some(feed))?
                .finish_fed()
                .map_err(imported_error),
            None => self.motion_spec()?.build_fed(earth, feed),
        }
    }

    /// A builder with the motion file's pieces pushed.
    fn imported_builder<E: EarthModel>(
        &self,
        earth: E,
        def: &MotionDefinition,
        feed: Option<KnotFeed>,
    ) -> Result<MotionBuilder<E>, ScenarioError> {
        let start = Start {
            t: self.start.as_ref().map_or(0.0, |s| s.time),
            pos: def.pos,
            v_n: def.attitude.to_dcm() * def.v_body,
            attitude: def.attitude,
        };
        let mut b = MotionBuilder::new(earth, &start);
        if let Some(feed) = feed {
            b.feed(feed);
        }
        for (i, p) in def.pieces().0.iter().enumerate() {
            b.push(p).map_err(|source| ScenarioError::Motion {
                key: format!("motion_csv piece {i}"),
                source,
            })?;
        }
        Ok(b)
    }

    /// The scripted motion (`start` and `motion`).
    fn motion_spec(&self) -> Result<MotionSpec, ScenarioError> {
        let start = self.start.clone().ok_or_else(|| ScenarioError::Value {
            key: "start".into(),
            message: "missing: give [start] and [[motion]], or motion_csv".into(),
        })?;
        Ok(MotionSpec {
            start,
            motion: self.motion.clone(),
        })
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
    /// The true attitude at `t` as Z-Y-X Euler angles in the ranges of
    /// [`crate::rotation::Euler::from_dcm`] (from the trajectory's own angles where it
    /// has them).
    pub euler: crate::rotation::Euler,
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
    /// The true IMU errors every [`IMU_ERRORS_INTERVAL`], after `imu[index]`.
    pub imu_errors: Vec<(usize, ImuErrorTruth)>,
}

/// Interval of the IMU error truth [s]: the errors change over minutes (bias
/// instability correlation times of 300 s and more, random walks), so one record a
/// second shows all of their motion.
pub const IMU_ERRORS_INTERVAL: f64 = 1.0;

/// The true IMU errors at one instant: the truth of what an estimator's sensor-error
/// states estimate ([`ImuSimulator::sensor_errors`]), in effect for the IMU sample
/// that holds `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuErrorTruth {
    /// Time [s].
    pub t: f64,
    /// The biases and scale-factor errors.
    pub errors: crate::filter::SensorEstimates,
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
    /// The true IMU errors at one instant; ignored by default.
    fn imu_errors(&mut self, _truth: &ImuErrorTruth) -> std::io::Result<()> {
        Ok(())
    }
    /// A block of consecutive epochs; by default one call of [`SimSink::imu`],
    /// [`SimSink::gnss`] and [`SimSink::baro`] per epoch, in time order. A sink that
    /// writes streams to separate files may take the block whole (and format it in
    /// parallel).
    fn block(&mut self, block: &SimBlock) -> std::io::Result<()> {
        let (mut g, mut b) = (block.gnss.iter().peekable(), block.baro.iter().peekable());
        let mut errors = block.imu_errors.iter().peekable();
        for (i, e) in block.imu.iter().enumerate() {
            self.imu(&e.exact, &e.measured, &e.truth, &e.kin)?;
            while let Some((_, truth)) = errors.next_if(|(j, _)| *j == i) {
                self.imu_errors(truth)?;
            }
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
    #[error("writing the simulated data failed")]
    Io(#[from] std::io::Error),
}

/// A motion file's error at its end.
fn imported_error(source: super::motion::MotionError) -> ScenarioError {
    ScenarioError::Motion {
        key: "motion_csv".into(),
        source,
    }
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

/// Run `spec` into `sink`: the blocks reach [`SimSink::block`] in time order (copied
/// out of the workers, see [`simulate_with`]).
pub fn simulate(
    spec: &ScenarioSpec,
    sink: &mut (impl SimSink + Send),
) -> Result<SimSummary, SimError> {
    simulate_on(spec, default_workers(), sink)
}

/// [`simulate`] on `workers` threads (at least one; the bits do not depend on it): for
/// a caller that runs many simulations at once, such as a Monte-Carlo campaign that
/// gives each of them one.
pub fn simulate_on(
    spec: &ScenarioSpec,
    workers: usize,
    sink: &mut (impl SimSink + Send),
) -> Result<SimSummary, SimError> {
    workers_with(
        spec,
        workers,
        |block: &SimBlock, copy: &mut SimBlock| {
            // Field by field: a Vec's clone_from keeps its memory.
            copy.imu.clone_from(&block.imu);
            copy.gnss.clone_from(&block.gnss);
            copy.baro.clone_from(&block.baro);
            copy.imu_errors.clone_from(&block.imu_errors);
        },
        |copy: &mut SimBlock| sink.block(copy),
    )
}

/// Run `spec` on as many workers as there are cores (at most 8), each taking whole
/// blocks of samples through every stage: the exact samples (a pure function of time,
/// any block at any moment), the sensor errors (random processes, so blocks take
/// turns, in time order), `format` (any block at any moment, into the worker's own
/// `T`, kept from block to block) and `write` (turns again, in time order). The cores
/// stay busy without more threads than cores, and the result is the same bits for any
/// number of workers.
pub fn simulate_with<T: Default + Send>(
    spec: &ScenarioSpec,
    format: impl Fn(&SimBlock, &mut T) + Sync,
    write: impl FnMut(&mut T) -> std::io::Result<()> + Send,
) -> Result<SimSummary, SimError> {
    workers_with(spec, default_workers(), format, write)
}

/// As many workers as there are cores, at most 8.
fn default_workers() -> usize {
    std::thread::available_parallelism()
        .map_or(1, usize::from)
        .clamp(1, 8)
}

/// [`simulate_with`] on `workers` threads.
fn workers_with<T: Default + Send>(
    spec: &ScenarioSpec,
    workers: usize,
    format: impl Fn(&SimBlock, &mut T) + Sync,
    write: impl FnMut(&mut T) -> std::io::Result<()> + Send,
) -> Result<SimSummary, SimError> {
    let run = Run {
        workers: workers.max(1),
        block: BLOCK,
    };
    match spec.earth {
        EarthSpec::Wgs84 => run.on(Wgs84, spec, format, write),
        EarthSpec::Sphere => run.on(Sphere::textbook(true), spec, format, write),
        EarthSpec::SphereFixed => run.on(Sphere::textbook(false), spec, format, write),
    }
}

/// Angular rate of the body relative to the Earth, `w_eb_b = w_ib_b - C_nb w_ie_n`,
/// for the GNSS lever-arm velocity (defined at the poles, unlike the rate relative to
/// NED).
fn w_eb_b<E: EarthModel>(earth: &E, s: &NavState, k: &Kinematics) -> nalgebra::Vector3<f64> {
    k.w_ib_b - s.q_bn.inverse() * earth.w_ie_n(s.pos.lat)
}

/// Samples per block: small enough that a worker's buffers stay in its cache (about
/// 1.8 MB at 2048; at 8192 page faults on them alone cost 5 % of the run), large
/// enough that taking turns costs nothing.
const BLOCK: u64 = 2048;

/// How a simulation is split: workers and samples per block (any split gives the same
/// bits).
#[derive(Debug, Clone, Copy)]
struct Run {
    workers: usize,
    block: u64,
}

/// The sensors' running state: what must see the samples in time order.
struct Sensors {
    imu: ImuSimulator,
    gnss: Option<GnssSimulator>,
    baro: Option<BaroSimulator>,
    /// Index of the next GNSS, barometer and IMU error truth epoch.
    next_gnss: u64,
    next_baro: u64,
    next_imu_errors: u64,
    summary: SimSummary,
}

impl Sensors {
    /// Measure the exact samples of `block` and add the aiding epochs that fall among
    /// them, each taken at its own exact time.
    fn measure<E: EarthModel>(
        &mut self,
        earth: &E,
        traj: &SplineTrajectory,
        t0: f64,
        block: &mut SimBlock,
    ) {
        block.gnss.clear();
        block.baro.clear();
        block.imu_errors.clear();
        for (i, e) in block.imu.iter_mut().enumerate() {
            e.measured = self.imu.measure(&e.exact);
            let t = e.exact.t;
            let imu = &self.imu;
            emit_epochs(
                &mut self.next_imu_errors,
                IMU_ERRORS_INTERVAL,
                t0,
                t,
                |te| {
                    let errors = imu.sensor_errors();
                    block.imu_errors.push((i, ImuErrorTruth { t: te, errors }));
                },
            );
            if let Some(g) = self.gnss.as_mut() {
                emit_epochs(&mut self.next_gnss, g.interval(), t0, t, |te| {
                    let (s, kin) = analytic::evaluate(earth, traj, te);
                    if let Some(fix) = g.fix_w_eb(earth, &s, &w_eb_b(earth, &s, &kin)) {
                        block.gnss.push((i, fix));
                    }
                });
            }
            if let Some(b) = self.baro.as_mut() {
                emit_epochs(&mut self.next_baro, b.interval(), t0, t, |te| {
                    let h = traj.position(super::jet::Jet::constant(te))[2].v;
                    if let Some(r) = b.reading(te, t0, h) {
                        block.baro.push((i, r));
                    }
                });
            }
        }
        self.summary.imu_samples += block.imu.len() as u64;
        self.summary.gnss_fixes += block.gnss.len() as u64;
        self.summary.baro_readings += block.baro.len() as u64;
    }
}

/// A stage that blocks pass through one at a time in index order, with its state.
struct Turns<S> {
    state: Mutex<TurnState<S>>,
    next: Condvar,
}

struct TurnState<S> {
    /// Index of the block whose turn it is.
    turn: u64,
    /// A worker failed: nobody waits any more.
    failed: bool,
    data: S,
}

impl<S> Turns<S> {
    fn new(data: S) -> Self {
        Self {
            state: Mutex::new(TurnState {
                turn: 0,
                failed: false,
                data,
            }),
            next: Condvar::new(),
        }
    }

    /// Wait for block `k`'s turn, run `f` on the state, pass the turn on; `None` if a
    /// worker failed (or panicked while holding the state).
    fn take<R>(&self, k: u64, f: impl FnOnce(&mut S) -> R) -> Option<R> {
        let mut g = self.state.lock().ok()?;
        while g.turn != k && !g.failed {
            g = self.next.wait(g).ok()?;
        }
        if g.failed {
            return None;
        }
        let r = f(&mut g.data);
        g.turn += 1;
        self.next.notify_all();
        Some(r)
    }

    /// Release every waiter: the run is over.
    fn fail(&self) {
        let mut g = self
            .state
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        g.failed = true;
        self.next.notify_all();
    }

    fn into_data(self) -> S {
        self.state
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .data
    }
}

/// Fails the stages when dropped unless disarmed: a worker that stops early (an error
/// or a panic) releases the others.
struct FailGuard<'a, A, B> {
    sensors: &'a Turns<A>,
    writer: &'a Turns<B>,
    feed: &'a Feed,
    armed: bool,
}

impl<A, B> Drop for FailGuard<'_, A, B> {
    fn drop(&mut self) {
        if self.armed {
            self.sensors.fail();
            self.writer.fail();
            self.feed.end(None);
        }
    }
}

/// The knots the builder has made and the workers may still need, shared with them.
struct Built {
    /// From the last knot at or before the oldest window a worker may still ask for,
    /// to the builder's head.
    knots: VecDeque<Knot>,
    /// The first knot's time [s], once made (its knot may be gone).
    first: Option<f64>,
    /// Set when the build is over: the trajectory's end time, or `None` if it failed
    /// (or a worker did: nobody waits any more).
    end: Option<Option<f64>>,
    /// Blocks claimed whose window has not been taken yet, with the window's start.
    claimed: Vec<(u64, f64)>,
    /// The next block to claim, and its window's start once the first claim told how
    /// a block's start is found.
    next: u64,
    next_start: Option<f64>,
    /// The latest time a worker has waited for [s]: the builder goes on past
    /// [`KNOTS_AHEAD`] until its head is beyond it.
    wanted: f64,
    /// The most knots held at once (for the test of the bound).
    peak: usize,
}

impl Default for Built {
    fn default() -> Self {
        Self {
            knots: VecDeque::new(),
            first: None,
            end: None,
            claimed: Vec::new(),
            next: 0,
            next_start: None,
            wanted: f64::NEG_INFINITY,
            peak: 0,
        }
    }
}

/// Knots the builder keeps ahead of the workers before it waits for them (80 s of
/// motion at the longest step, 1.2 MB): what bounds a simulation's memory.
const KNOTS_AHEAD: usize = 8 * super::motion::FEED_CHUNK;

/// What a worker needs for a block: the knots around its samples, or the news that
/// the build ended first.
enum Window {
    /// The trajectory over the block's samples (the knots covering them; evaluated
    /// on these, every sample is the same bits as on the whole trajectory).
    Knots(SplineTrajectory),
    /// The build is over and ended at this time before the block's last sample.
    Ended(f64),
    /// The build failed: stop.
    Failed,
}

/// The knots as the builder publishes them ([`super::motion::KnotFeed`]), for the
/// workers, who start on the first blocks while the rest of the motion is
/// integrated.
#[derive(Default)]
struct Feed {
    built: Mutex<Built>,
    more: Condvar,
}

impl Feed {
    fn lock(&self) -> std::sync::MutexGuard<'_, Built> {
        self.built
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    fn wait<'a>(&self, g: std::sync::MutexGuard<'a, Built>) -> std::sync::MutexGuard<'a, Built> {
        self.more
            .wait(g)
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Take `knots` from the builder; wait first while it holds [`KNOTS_AHEAD`] and
    /// has made every knot a worker waits for (so a worker always gets its window, and
    /// memory stays bounded when the workers are slower than the builder).
    fn push(&self, knots: &[Knot]) {
        let mut built = self.lock();
        while built.end.is_none()
            && built.knots.len() >= KNOTS_AHEAD
            && built.knots.back().is_some_and(|k| k.t > built.wanted)
        {
            built = self.wait(built);
        }
        // After a failure nobody takes knots any more: keep none.
        if built.end.is_some() {
            return;
        }
        if built.first.is_none() {
            built.first = knots.first().map(|k| k.t);
        }
        built.knots.extend(knots.iter().cloned());
        built.peak = built.peak.max(built.knots.len());
        drop(built);
        self.more.notify_all();
    }

    /// The build is over (`None`: it or a worker failed).
    fn end(&self, end: Option<f64>) {
        let mut built = self.lock();
        if built.end.is_none() {
            built.end = Some(end);
        }
        drop(built);
        self.more.notify_all();
    }

    /// The first knot's time, once there is one (`None` if the build failed first).
    fn start(&self) -> Option<f64> {
        let mut built = self.lock();
        loop {
            if built.first.is_some() {
                return built.first;
            }
            if built.end.is_some() {
                return None;
            }
            built = self.wait(built);
        }
    }

    /// The next block, whose window starts at `window_start(block)` [s] (increasing
    /// with the block): its knots are kept until [`Feed::taken`].
    fn claim(&self, window_start: impl Fn(u64) -> f64) -> u64 {
        let mut built = self.lock();
        let k = built.next;
        built.claimed.push((k, window_start(k)));
        built.next = k + 1;
        built.next_start = Some(window_start(k + 1));
        k
    }

    /// Block `k`'s window has been taken (or is not needed): drop the knots no
    /// claimed or future block needs, and let the builder go on.
    fn taken(&self, k: u64) {
        let mut built = self.lock();
        built.claimed.retain(|&(b, _)| b != k);
        let oldest = built
            .claimed
            .iter()
            .map(|&(_, a)| a)
            .chain(built.next_start)
            .fold(f64::INFINITY, f64::min);
        // A window starting at `oldest` begins at the last knot at or before it.
        while built.knots.get(1).is_some_and(|k| k.t <= oldest) {
            built.knots.pop_front();
        }
        drop(built);
        self.more.notify_all();
    }

    /// The knots covering `[a, b]`: from the last at or before `a` to the first after
    /// `b` (or the ends), once the builder has gone past `b`; [`Window::Ended`] if
    /// the trajectory ends before `b`.
    fn window(&self, a: f64, b: f64) -> Window {
        let mut built = self.lock();
        loop {
            match built.end {
                Some(None) => return Window::Failed,
                Some(Some(end)) if b > end => return Window::Ended(end),
                Some(Some(_)) => break,
                None if built.knots.back().is_some_and(|k| k.t > b) => break,
                None => {}
            }
            built.wanted = built.wanted.max(b);
            self.more.notify_all();
            built = self.wait(built);
        }
        let knots = &built.knots;
        let from = knots.partition_point(|k| k.t <= a).saturating_sub(1);
        let to = knots.partition_point(|k| k.t <= b).min(knots.len() - 1);
        match SplineTrajectory::new(knots.range(from..=to).cloned().collect()) {
            Ok(traj) => Window::Knots(traj),
            // The builder's knots always form a trajectory; a failure ends the run.
            Err(_) => Window::Failed,
        }
    }
}

/// Ends the feed as failed when dropped, unless it has already ended.
struct EndsFeed<'a>(&'a Feed);

impl Drop for EndsFeed<'_> {
    fn drop(&mut self) {
        self.0.end(None);
    }
}

impl Run {
    /// Run `spec` on a given Earth model ([`simulate_with`]): the trajectory is
    /// integrated on its own thread while the workers take the blocks its knots
    /// already cover.
    fn on<E: EarthModel, T: Default + Send>(
        self,
        earth: E,
        spec: &ScenarioSpec,
        format: impl Fn(&SimBlock, &mut T) + Sync,
        write: impl FnMut(&mut T) -> std::io::Result<()> + Send,
    ) -> Result<SimSummary, SimError> {
        let imu_model = spec.imu.model()?;
        let mut gnss_model = spec.gnss.as_ref().map(GnssSpec::model).transpose()?;
        let baro_model = spec.baro.as_ref().map(BaroSpec::model).transpose()?;
        if let Some(g) = gnss_model.as_mut() {
            g.outages.extend(spec.motion_outages());
        }
        let dt = 1.0 / spec.imu.rate_hz;
        let sensors = Turns::new(Sensors {
            imu: ImuSimulator::new(imu_model, spec.seed),
            gnss: gnss_model.map(|m| GnssSimulator::new(m, spec.seed)),
            baro: baro_model.map(|m| BaroSimulator::new(m, spec.seed)),
            next_gnss: 0,
            next_baro: 0,
            next_imu_errors: 0,
            summary: SimSummary {
                imu_samples: 0,
                gnss_fixes: 0,
                baro_readings: 0,
                t0: 0.0,
                t1: 0.0,
            },
        });
        let writer = Turns::new((write, None::<std::io::Error>));
        let feed = std::sync::Arc::new(Feed::default());
        let worker = || {
            let mut guard = FailGuard {
                sensors: &sensors,
                writer: &writer,
                feed: &feed,
                armed: true,
            };
            let Some(t0) = feed.start() else {
                return;
            };
            let (mut block, mut text) = (SimBlock::default(), T::default());
            // Sample k ends at t0 + k dt; the first integrates from the one before.
            let time = |k: u64| t0 + k as f64 * dt;
            loop {
                let k = feed.claim(|k| time(k * self.block) - dt);
                let k0 = k * self.block;
                let mut k1 = k0 + self.block;
                let window = match feed.window(time(k0) - dt, time(k1 - 1)) {
                    Window::Ended(t1) => {
                        let n = ((t1 - t0) / dt + 1e-9).floor() as u64;
                        if k0 > n {
                            feed.taken(k);
                            break;
                        }
                        k1 = k1.min(n + 1);
                        // The last sample may end up to 1e-9 dt past the end.
                        feed.window(time(k0) - dt, time(k1 - 1).min(t1))
                    }
                    other => other,
                };
                feed.taken(k);
                let Window::Knots(traj) = window else {
                    return;
                };
                super::exact::exact_block(&earth, &traj, t0, dt, k0, k1, &mut block.imu);
                if sensors
                    .take(k, |s| s.measure(&earth, &traj, t0, &mut block))
                    .is_none()
                {
                    return;
                }
                format(&block, &mut text);
                // After a failed write nothing more is written, even by a worker whose
                // turn comes before the failed one has released the others.
                let written = writer.take(k, |(write, error)| {
                    error.is_none()
                        && match write(&mut text) {
                            Ok(()) => true,
                            Err(e) => {
                                *error = Some(e);
                                false
                            }
                        }
                });
                if written != Some(true) {
                    return;
                }
            }
            guard.armed = false;
        };
        let built = std::thread::scope(|scope| {
            let builder = scope.spawn(|| {
                // Should the build panic, the workers waiting for its knots are let go.
                let _ends = EndsFeed(&feed);
                let to_workers = std::sync::Arc::clone(&feed);
                let result = spec.trajectory_fed(earth, Box::new(move |k| to_workers.push(k)));
                feed.end(result.as_ref().ok().map(|span| span.end));
                result
            });
            let others: Vec<_> = (1..self.workers).map(|_| scope.spawn(worker)).collect();
            worker();
            for w in others {
                w.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            }
            builder
                .join()
                .unwrap_or_else(|e| std::panic::resume_unwind(e))
        });
        let span = built?;
        if let (_, Some(e)) = writer.into_data() {
            return Err(SimError::Io(e));
        }
        let mut summary = sensors.into_data().summary;
        (summary.t0, summary.t1) = (span.start, span.end);
        Ok(summary)
    }
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
    use nalgebra::Vector3;

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

    /// Everything a run delivers, in order, and its summary.
    type Delivered = (Vec<ImuEpoch>, Vec<GnssFix>, Vec<BaroReading>);

    fn collect(run: Run) -> (Delivered, SimSummary) {
        let mut out: Delivered = Default::default();
        let summary = run
            .on(
                Wgs84,
                &spec(),
                |block: &SimBlock, copy: &mut SimBlock| copy.clone_from(block),
                |copy: &mut SimBlock| {
                    out.0.extend_from_slice(&copy.imu);
                    out.1.extend(copy.gnss.iter().map(|g| g.1));
                    out.2.extend(copy.baro.iter().map(|b| b.1));
                    Ok(())
                },
            )
            .expect("simulate");
        (out, summary)
    }

    /// The IMU error truth: a record each second from the start (in the sample that
    /// holds it), holding what the samples carry. With a constant bias, turn-on biases
    /// and scale factors only, the bias is their sum (as drawn) and the scale the
    /// configured one, and in the sample that holds a record the measured minus exact
    /// increment is `s x + b dt` for the recorded `b` and `s`; the bias stays within 5
    /// sigma of the turn-on draw around the constant.
    #[test]
    fn imu_error_truth_is_recorded_each_second() {
        let text = SCENARIO.replace(
            "preset = \"tactical\"",
            "gyro = { bias = \"3 deg/h\", turn_on = \"1 deg/h\", scale = \"100 ppm\" }\n\
             accel = { bias = \"200 ug\", turn_on = \"50 ug\", scale = \"300 ppm\" }",
        );
        let spec: ScenarioSpec = toml::from_str(&text).expect("scenario");
        let mut out: Vec<ImuEpoch> = Vec::new();
        let mut truth: Vec<(usize, ImuErrorTruth)> = Vec::new();
        let summary = Run {
            workers: 2,
            block: 333,
        }
        .on(
            Wgs84,
            &spec,
            |block: &SimBlock, copy: &mut SimBlock| copy.clone_from(block),
            |copy: &mut SimBlock| {
                let base = out.len();
                out.extend_from_slice(&copy.imu);
                truth.extend(copy.imu_errors.iter().map(|(i, e)| (base + i, *e)));
                Ok(())
            },
        )
        .expect("simulate");
        let whole_seconds = (summary.t1 - summary.t0).floor() as usize;
        assert_eq!(truth.len(), whole_seconds + 1);
        for (j, (i, e)) in truth.iter().enumerate() {
            assert_eq!(e.t, summary.t0 + j as f64);
            let sample = &out[*i];
            assert!(sample.exact.t - sample.exact.dt < e.t + 1e-9 && e.t <= sample.exact.t + 1e-9);
            let m = e.errors;
            assert_eq!(m.gyro_scale, Vector3::repeat(100e-6));
            assert_eq!(m.accel_scale, Vector3::repeat(300e-6));
            // Measured minus exact: the scale factor times the input plus bias dt, to
            // the round-off of the increments (1e-16 of them).
            let (x, y) = (sample.exact.dtheta, sample.measured.dtheta);
            let expect = x.component_mul(&m.gyro_scale) + m.gyro_bias * sample.exact.dt;
            assert!((y - x - expect).norm() < 1e-15 * x.norm().max(1e-6), "{j}");
            let (x, y) = (sample.exact.dvel, sample.measured.dvel);
            let expect = x.component_mul(&m.accel_scale) + m.accel_bias * sample.exact.dt;
            assert!((y - x - expect).norm() < 1e-15 * x.norm(), "{j}");
        }
        let b = truth[0].1.errors.gyro_bias;
        assert!(
            truth.iter().all(|(_, e)| e.errors.gyro_bias == b),
            "constant"
        );
        assert!(((b.x - 3.0 * crate::units::DEG_PER_H).abs()) < 5.0 * crate::units::DEG_PER_H);
    }

    /// The samples do not depend on how the run is split into blocks and workers: the
    /// same bits (exact and measured increments, truth, aiding epochs) with one worker
    /// or three, blocks of 4096 samples or 100 or 777.
    #[test]
    fn any_split_gives_the_same_bits() {
        let (one, summary) = collect(Run {
            workers: 1,
            block: 4096,
        });
        assert_eq!(one.0.len() as u64, summary.imu_samples);
        assert!(one.1.len() > 10 && one.2.len() > 40);
        for run in [
            Run {
                workers: 2,
                block: 4096,
            },
            Run {
                workers: 3,
                block: 100,
            },
            Run {
                workers: 2,
                block: 777,
            },
        ] {
            let (many, s) = collect(run);
            assert!(
                many == one && s == summary,
                "{run:?} differs from one worker"
            );
        }
    }

    /// However far the builder could run ahead of a worker, the feed holds at most
    /// [`KNOTS_AHEAD`] knots and one chunk more (the builder stops on the chunk that
    /// passes the bound unless a worker waits for knots beyond its head, and a window
    /// here spans one chunk), while every window is the same knots as the whole list
    /// gives: the memory of a simulation does not grow with its length.
    #[test]
    fn the_feed_holds_a_bounded_number_of_knots() {
        use super::super::motion::FEED_CHUNK;
        let feed = Feed::default();
        let knot = |i: usize| Knot {
            t: i as f64 * 0.01,
            value: [i as f64; 6],
            rate: [0.0; 6],
            accel: [0.0; 6],
        };
        let chunks = 60;
        let all: Vec<Knot> = (0..chunks * FEED_CHUNK).map(knot).collect();
        let end = all[all.len() - 1].t;
        std::thread::scope(|s| {
            s.spawn(|| {
                for chunk in all.chunks(FEED_CHUNK) {
                    feed.push(chunk);
                }
                feed.end(Some(end));
            });
            // The worker starts late: the builder has run as far ahead as it may.
            let mut built = feed.lock();
            while built.knots.len() < KNOTS_AHEAD {
                built = feed.wait(built);
            }
            drop(built);
            // Blocks of 10 s, each window from 0.01 s before the block's start.
            let start = |k: u64| k as f64 * 10.0 - 0.01;
            loop {
                let k = feed.claim(start);
                let (a, b) = (start(k), start(k) + 10.0);
                if b > end {
                    feed.taken(k);
                    break;
                }
                let window = feed.window(a, b);
                feed.taken(k);
                let Window::Knots(traj) = window else {
                    panic!("block {k}: no window");
                };
                let from = all.partition_point(|x| x.t <= a).saturating_sub(1);
                let to = all.partition_point(|x| x.t <= b).min(all.len() - 1);
                let expected = SplineTrajectory::new(all[from..=to].to_vec()).expect("knots");
                assert!(traj == expected, "block {k}: other knots");
            }
        });
        let peak = feed.lock().peak;
        assert!(peak <= KNOTS_AHEAD + FEED_CHUNK, "{peak} knots held");
        assert!(peak >= KNOTS_AHEAD, "{peak}: the builder was not held");
    }

    /// A write that fails stops every worker and is returned; nothing is written after
    /// it.
    #[test]
    fn a_failed_write_stops_the_run() {
        let mut written = 0;
        let result = Run {
            workers: 3,
            block: 50,
        }
        .on(
            Wgs84,
            &spec(),
            |_: &SimBlock, _: &mut ()| {},
            |_: &mut ()| {
                written += 1;
                if written == 4 {
                    Err(std::io::Error::other("disk full"))
                } else {
                    Ok(())
                }
            },
        );
        assert!(matches!(result, Err(SimError::Io(e)) if e.to_string() == "disk full"));
        assert_eq!(written, 4);
    }

    /// A worker that panics releases the others (who would otherwise wait for its
    /// turn) and the panic reaches the caller.
    #[test]
    #[should_panic(expected = "format failed")]
    fn a_panicking_worker_releases_the_others() {
        let _ = Run {
            workers: 2,
            block: 50,
        }
        .on(
            Wgs84,
            &spec(),
            |block: &SimBlock, _: &mut ()| {
                assert!(block.imu[0].exact.t < 1.0, "format failed");
            },
            |_: &mut ()| Ok(()),
        );
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
