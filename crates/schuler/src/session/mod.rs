//! The navigation loop, owned by the library: one streaming session that every front
//! end (the command line, the Python package, a ROS 2 bag reader, a live stream)
//! drives the same way.
//!
//! ```text
//! let mut s = Session::new(Wgs84, config, start)?;   // config.validate() first
//! s.push(Aid::Gnss(fix))?;                             // aids in arrival order
//! s.push_imu(sample)?;                                 // samples in time order
//! for epoch in s.epochs() { ... }                      // output at the cadence
//! for event in s.events() { ... }                      // measurements, refusals, ...
//! let finished = s.finish()?;                          // summary, smoothed, snapshots
//! ```
//!
//! The first IMU sample pushed carries the start state (at its time; its increments
//! prime the two-sample corrections). Each later sample is integrated — with the
//! filter, GNSS fixes inside it applied at their own times, then the barometer and the
//! vehicle aids due at its end ([`vehicle`]) — once it is
//! [`SessionConfig::reorder_window`] older than the newest sample pushed, so aids up to
//! that late still apply at their own times; later ones are reported ([`aid`]). With
//! [`MechanizationChoice::Auto`] the mechanization hands over between NED and the
//! wander frame ([`engine`]), the filter's covariance carried across.

pub mod aid;
pub mod config;
pub mod engine;
pub mod heading_bank;
pub mod output;
pub mod start;
mod vehicle;

pub use aid::Aid;
pub use config::{
    BaroLoopConfig, ConfigError, Envelope, ErrorModelChoice, FilterConfig, MechanizationChoice,
    MechanizationConfig, MechanizationKind, RestConfig, RestSource, SessionConfig, VehicleConfig,
};
pub use heading_bank::{Chosen, HeadingBank};
pub use output::{Decimator, Epoch, Event, FilterEpoch, Handover, Snapshot};
pub use start::{Prior, Start};

use aid::AidQueues;
use engine::{Core, Navigating, Switch};
use output::SnapshotTaker;
use vehicle::VehicleRun;

use crate::analysis::errors::NavRecord;
use crate::channel::vertical::DetectorCounts;
use crate::earth::EarthModel;
use crate::filter::gate_book::GateBook;
use crate::filter::integration::{Counts, FixConsumer, GnssUpdate, SkipReason, Skipped, Timed};
use crate::filter::measurement::Kind;
use crate::filter::seed18::Seed18;
use crate::filter::smoother::SmoothedTrajectory;
use crate::filter::{Integrator, Layout};
use crate::imu::ImuSample;
use crate::nav::{BaroLoop, ErrorFrame, Mechanization, NavState};
use std::collections::VecDeque;

/// Why a session refused an input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SessionError {
    /// The configuration is not valid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// An IMU sample with a number that is not finite.
    #[error("IMU sample at t = {t}: a value is not finite")]
    ImuNotFinite {
        /// Its time [s].
        t: f64,
    },
    /// An IMU sample not after the previous one.
    #[error("IMU sample at t = {t} s is not after the previous one at {previous} s")]
    ImuTimeNotIncreasing {
        /// Its time [s].
        t: f64,
        /// The previous sample's time [s].
        previous: f64,
    },
    /// An IMU sample whose interval is not positive.
    #[error("IMU sample at t = {t} s: interval dt = {dt} s is not positive")]
    ImuIntervalNotPositive {
        /// Its time [s].
        t: f64,
        /// Its interval [s].
        dt: f64,
    },
    /// An aid whose time is not finite (or a rest that ends before it starts).
    #[error("{kind} at t = {t}: its time is not finite or its interval ends before it starts")]
    AidNotFinite {
        /// Its time [s].
        t: f64,
        /// What it was.
        kind: Kind,
    },
    /// An aid with a value outside its physical domain ([`crate::domain`]).
    #[error("{kind} at t = {t}: field {field}: {error}")]
    AidOutOfDomain {
        /// Its time [s].
        t: f64,
        /// What it was.
        kind: Kind,
        /// The field (`lat`, `pos_std`, `speed`, ...).
        field: &'static str,
        /// The value and its domain.
        error: crate::domain::DomainError,
    },
    /// No IMU sample was pushed.
    #[error("no IMU sample was pushed: nothing to navigate")]
    NoImu,
    /// The smoother's record could not be kept (its temporary file failed).
    #[error(transparent)]
    Smoother(#[from] crate::filter::spill::SpillError),
    /// The solution stopped being a number (an input far outside what the sensors can
    /// read, or a diverged filter); nothing after it is computed.
    #[error(
        "the solution is not finite at t = {t} s (after the sample ending then; last finite output at {last_good} s): \
         an IMU sample or an aid far outside the sensors' range?"
    )]
    NotFinite {
        /// The output time at which it was found [s].
        t: f64,
        /// The last output time with a finite state [s] (NaN if none).
        last_good: f64,
    },
}

/// What a session did, at its end.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Samples integrated (the first, which carries the start, excluded).
    pub samples: u64,
    /// Time of the first sample [s].
    pub t_first: f64,
    /// Time of the last sample integrated [s].
    pub t_last: f64,
    /// The state at the end.
    pub last: NavState,
    /// The mechanization at the start.
    pub first_mechanization: MechanizationKind,
    /// Hand-overs between mechanizations, in order.
    pub handovers: Vec<Handover>,
    /// The filter's counts (accepted per kind, refused, skipped).
    pub counts: Counts,
    /// Aids that arrived too late.
    pub late: u64,
    /// Aids the configuration had no use for.
    pub ignored: u64,
    /// Envelope bounds the solution crossed.
    pub envelope_warnings: u64,
    /// GNSS positions accepted without the gate after consecutive refusals.
    pub gate_resets: u64,
    /// Mean normalized innovation squared per dimension of the accepted measurements
    /// (NaN without any).
    pub mean_nis_per_dof: f64,
    /// The filter's state layout, when it ran (the psi-angle filters).
    pub layout: Option<Layout>,
    /// How many states the filter had at the end, when it ran: its layout's, or the
    /// 18 of [`crate::filter::seed18`] (which has no [`Layout`]).
    pub states: Option<usize>,
    /// The filter's sensor-error estimates at the end, when it ran.
    pub estimates: Option<crate::filter::SensorEstimates>,
    /// The vehicle mount at the end (the configured one with the estimated mounting
    /// errors removed) and the standard deviations of its pitch and yaw [rad], when
    /// the mounting was estimated.
    pub mounting: Option<(crate::filter::VehicleMount, [f64; 2])>,
    /// The lever arm and GNSS time offset at the end, when calibrated.
    pub calibration: crate::filter::CalibrationState,
    /// What the baro loop's fault detector did, when it ran.
    pub baro_loop: Option<DetectorCounts>,
}

/// Everything a session leaves at its end.
#[derive(Debug)]
pub struct Finished {
    /// What it did.
    pub summary: Summary,
    /// Output epochs not yet taken with [`Session::epochs`].
    pub epochs: Vec<Epoch>,
    /// Events not yet taken with [`Session::events`].
    pub events: Vec<Event>,
    /// The filter's snapshots (empty without a filter).
    pub snapshots: Vec<Snapshot>,
    /// The smoothed trajectory at every output epoch, when asked
    /// ([`FilterConfig::smooth`]), computed as it is read.
    pub smoothed: Option<SmoothedTrajectory>,
}

/// Everything of a session but its running navigation (so that the two can be
/// borrowed apart).
#[derive(Debug, Clone)]
struct Loop {
    cfg: SessionConfig,
    switch: Switch,
    /// Samples waiting for the reorder window.
    imu: VecDeque<ImuSample>,
    last_pushed: Option<f64>,
    /// Time and interval of the last sample integrated.
    done: Option<(f64, f64)>,
    queues: AidQueues,
    vehicle: Option<VehicleRun>,
    baro_loop: Option<BaroLoop>,
    decimator: Decimator,
    epochs: VecDeque<Epoch>,
    events: VecDeque<Event>,
    snapshots: Option<SnapshotTaker>,
    samples: u64,
    t_first: f64,
    first_mechanization: MechanizationKind,
    handovers: Vec<Handover>,
    late: u64,
    ignored: u64,
    gate_resets: u64,
    /// Skipped outside a filter (barometer readings of the baro loop).
    skipped_free: u64,
    nis: (f64, usize),
    ended: bool,
    /// Which envelope bounds were crossed (low height, high height, speed).
    left_envelope: [bool; 3],
    /// The last output time with a finite state, and the failure once it is not.
    last_good: f64,
    failure: Option<SessionError>,
    /// Tight coupling's settings ([`Session::with_tight`]).
    tight: Option<crate::filter::TightConfig>,
}

impl Aid {
    /// The error [`Session::push`] gives this aid, if any: times not finite, or a
    /// value outside its domain (so that a front end can check its aids before it
    /// pushes them).
    pub fn validate(&self) -> Result<(), SessionError> {
        if !self.times_valid() {
            return Err(SessionError::AidNotFinite {
                t: self.t(),
                kind: self.kind(),
            });
        }
        if let Some((field, error)) = self.out_of_domain() {
            return Err(SessionError::AidOutOfDomain {
                t: self.t(),
                kind: self.kind(),
                field,
                error,
            });
        }
        Ok(())
    }
}

/// A navigation session (module doc).
#[derive(Debug, Clone)]
pub struct Session<E: EarthModel> {
    earth: E,
    start: Start,
    /// The start's sensor errors when there are any (free-inertial compensation).
    compensation: Option<crate::filter::SensorEstimates>,
    core: Option<Core<E>>,
    run: Loop,
}

impl<E: EarthModel> Session<E> {
    /// A session on `earth` that starts at `start` when the first sample arrives.
    pub fn new(earth: E, config: SessionConfig, start: Start) -> Result<Self, SessionError> {
        config.validate()?;
        start.validate()?;
        Ok(Self {
            earth,
            start,
            compensation: (start.estimates != Default::default()).then_some(start.estimates),
            core: None,
            run: Loop {
                switch: Switch::new(&config.mechanization),
                imu: VecDeque::new(),
                last_pushed: None,
                done: None,
                queues: AidQueues::default(),
                vehicle: config
                    .filter
                    .filter(|f| f.vehicle.any())
                    .map(|f| VehicleRun::new(f.vehicle)),
                baro_loop: config.baro_loop.map(|b| BaroLoop::new(b.gains, b.detector)),
                decimator: Decimator::new(config.output_rate),
                epochs: VecDeque::new(),
                events: VecDeque::new(),
                snapshots: config
                    .filter
                    .filter(|_| config.snapshot_rate > 0.0)
                    .map(|_| SnapshotTaker::new(config.snapshot_rate, Vec::new())),
                samples: 0,
                t_first: f64::NAN,
                first_mechanization: MechanizationKind::Ned,
                handovers: Vec::new(),
                late: 0,
                ignored: 0,
                gate_resets: 0,
                skipped_free: 0,
                nis: (0.0, 0),
                ended: false,
                left_envelope: [false; 3],
                last_good: f64::NAN,
                failure: None,
                tight: None,
                cfg: config,
            },
        })
    }

    /// Tight coupling: [`Aid::Ranges`] become pseudorange and rate updates of the
    /// filter, whose state gains the receiver clock ([`crate::filter::ranging`]).
    /// Needs the psi-angle filter; call before the first sample.
    pub fn with_tight(mut self, cfg: crate::filter::TightConfig) -> Result<Self, SessionError> {
        let refuse = |why: &str| {
            Err(SessionError::Config(ConfigError::new(
                "tight",
                why.to_string(),
            )))
        };
        match &self.run.cfg.filter {
            None => return refuse("tight coupling needs the filter"),
            Some(f) if f.error_model == ErrorModelChoice::Seed18 => {
                return refuse("tight coupling needs the psi-angle error model, not seed18");
            }
            Some(_) => {}
        }
        if cfg.systems.is_empty() {
            return refuse("tight coupling needs at least one system");
        }
        if self.core.is_some() {
            return refuse("tight coupling must be set before the first sample");
        }
        self.run.tight = Some(cfg);
        Ok(self)
    }

    /// The filter's snapshots carry NEES against `truth` (sorted by time).
    pub fn with_truth(mut self, truth: Vec<NavRecord>) -> Self {
        if self.run.snapshots.is_some() {
            self.run.snapshots = Some(SnapshotTaker::new(self.run.cfg.snapshot_rate, truth));
        }
        self
    }

    /// Appends an epoch to the truth the snapshots' NEES is computed against (times
    /// increasing, after those of [`Session::with_truth`]): a front end streaming a
    /// truth file pushes each epoch before the samples that reach its time, and one
    /// epoch past them, so that the session holds a window of the truth, not all of
    /// it. Without snapshots it is not kept.
    pub fn push_truth(&mut self, r: NavRecord) {
        if let Some(taker) = self.run.snapshots.as_mut() {
            taker.push_truth(r);
        }
    }

    /// The configuration.
    pub fn config(&self) -> &SessionConfig {
        &self.run.cfg
    }

    /// The Earth model (the one [`Finished::smoothed`] is read on).
    pub fn earth(&self) -> E {
        self.earth
    }

    /// Push the next IMU sample (times strictly increasing). Samples older than the
    /// newest by the reorder window or more are integrated now.
    pub fn push_imu(&mut self, s: ImuSample) -> Result<(), SessionError> {
        if let Some(e) = &self.run.failure {
            return Err(e.clone());
        }
        if !(s.t.is_finite()
            && s.dt.is_finite()
            && s.dtheta.iter().all(|x| x.is_finite())
            && s.dvel.iter().all(|x| x.is_finite()))
        {
            return Err(SessionError::ImuNotFinite { t: s.t });
        }
        if s.dt <= 0.0 {
            return Err(SessionError::ImuIntervalNotPositive { t: s.t, dt: s.dt });
        }
        if let Some(previous) = self.run.last_pushed
            && s.t <= previous
        {
            return Err(SessionError::ImuTimeNotIncreasing { t: s.t, previous });
        }
        self.run.last_pushed = Some(s.t);
        // A negative GNSS time offset applies fixes before their stamps: the samples
        // wait that much longer, so that fixes pushed in stamp order are there.
        let lead = self
            .run
            .cfg
            .filter
            .map_or(0.0, |f| f.integration.gnss_lead());
        let window = self.run.cfg.reorder_window + lead;
        if window == 0.0 && self.run.imu.is_empty() {
            self.integrate(&s);
        } else {
            self.run.imu.push_back(s);
            while let Some(&front) = self.run.imu.front() {
                if s.t - front.t < window || self.run.failure.is_some() {
                    break;
                }
                self.run.imu.pop_front();
                self.integrate(&front);
            }
        }
        match &self.run.failure {
            Some(e) => Err(e.clone()),
            None => Ok(()),
        }
    }

    /// Push an aid (in arrival order; see [`aid`] for when it is late).
    pub fn push(&mut self, aid: Aid) -> Result<(), SessionError> {
        aid.validate()?;
        if let Some((t_done, dt)) = self.run.done
            && aid::is_late(&aid, t_done, dt)
        {
            self.run.late += 1;
            self.run.events.push_back(Event::Late {
                t: aid.t(),
                kind: aid.kind(),
                integrated_to: t_done,
            });
            return Ok(());
        }
        match self.run.unused(&aid) {
            Some(reason) => {
                self.run.ignored += 1;
                self.run.events.push_back(Event::Ignored {
                    t: aid.t(),
                    kind: aid.kind(),
                    reason,
                });
            }
            None => self.run.queues.push(aid),
        }
        Ok(())
    }

    /// The filter's snapshots so far, oldest first, taken out of the session (so that
    /// a long run that takes them as they come keeps none; those not taken are in
    /// [`Finished::snapshots`]).
    pub fn snapshots(&mut self) -> std::vec::IntoIter<Snapshot> {
        let taken = self
            .run
            .snapshots
            .as_mut()
            .map(|s| std::mem::take(&mut s.taken))
            .unwrap_or_default();
        taken.into_iter()
    }

    /// The output epochs so far, oldest first (taken out of the session as the
    /// iterator goes; what it does not reach stays for the next call).
    pub fn epochs(&mut self) -> impl Iterator<Item = Epoch> + '_ {
        std::iter::from_fn(|| self.run.epochs.pop_front())
    }

    /// The events so far, in order (taken out of the session as the iterator goes).
    pub fn events(&mut self) -> impl Iterator<Item = Event> + '_ {
        std::iter::from_fn(|| self.run.events.pop_front())
    }

    /// The epoch of the state now (with the filter's view), whether or not it is an
    /// output epoch; `None` before the first sample.
    pub fn epoch_now(&self) -> Option<Epoch> {
        self.core.as_ref().map(epoch_of)
    }

    /// Time [s] up to which samples are integrated (`None` before the first).
    pub fn integrated_to(&self) -> Option<f64> {
        self.run.done.map(|d| d.0)
    }

    /// The input has ended: integrate the samples still waiting and record the aids
    /// after the last sample as skipped. Epochs and events stay to be taken.
    pub fn end_of_input(&mut self) {
        if self.run.ended {
            return;
        }
        while let Some(s) = self.run.imu.pop_front() {
            if self.run.failure.is_some() {
                break;
            }
            self.integrate(&s);
        }
        self.run.ended = true;
        let run = &mut self.run;
        match self.core.as_mut() {
            Some(Core::FilterNed(i)) => run.finish_filter(i),
            Some(Core::FilterWander(i)) => run.finish_filter(i),
            Some(Core::FilterSeed18(i)) => run.finish_seed18(i),
            _ => {
                let q = &mut run.queues;
                let after = if run.done.is_some() {
                    SkipReason::AfterImu
                } else {
                    SkipReason::BeforeImu
                };
                let mut left: Vec<(f64, Kind)> = q
                    .gnss
                    .drain(..)
                    .map(|u| match u {
                        GnssUpdate::Fix(f) => (f.t, Kind::GnssPosition),
                        GnssUpdate::Ranges(e) => (e.t, Kind::Pseudorange),
                    })
                    .collect();
                left.extend(q.baro.drain(..).map(|r| (r.0, Kind::BaroHeight)));
                left.extend(q.odometer.drain(..).map(|r| (r.0, Kind::Odometer)));
                left.extend(q.heading.drain(..).map(|r| (r.t, Kind::Heading)));
                q.rest.clear();
                for (t, kind) in left {
                    run.skipped_free += 1;
                    run.events.push_back(Event::Skipped(Skipped {
                        t,
                        kind,
                        reason: after,
                    }));
                }
            }
        }
    }

    /// End the session: [`Session::end_of_input`], then the summary, what was not
    /// taken yet, the snapshots and, when asked, the smoothed trajectory.
    pub fn finish(mut self) -> Result<Finished, SessionError> {
        self.end_of_input();
        let Some(mut core) = self.core else {
            return Err(SessionError::NoImu);
        };
        if let Some(e) = self.run.failure {
            return Err(e);
        }
        let (last, ..) = core.read_out();
        if !state_is_finite(&last) {
            return Err(SessionError::NotFinite {
                t: last.t,
                last_good: self.run.last_good,
            });
        }
        let run = self.run;
        let end = match &mut core {
            Core::FilterNed(i) => filter_end(i, &run.cfg)?,
            Core::FilterWander(i) => filter_end(i, &run.cfg)?,
            Core::FilterSeed18(i) => FilterEnd {
                counts: i.book.counts,
                states: Some(crate::filter::seed18::model::N),
                estimates: Some(i.estimates()),
                ..FilterEnd::default()
            },
            _ => FilterEnd {
                counts: Counts {
                    skipped: run.skipped_free,
                    ..Counts::default()
                },
                ..FilterEnd::default()
            },
        };
        let (sum, dof) = run.nis;
        Ok(Finished {
            summary: Summary {
                samples: run.samples,
                t_first: run.t_first,
                t_last: run.done.map_or(run.t_first, |d| d.0),
                last,
                first_mechanization: run.first_mechanization,
                handovers: run.handovers,
                counts: end.counts,
                late: run.late,
                ignored: run.ignored,
                envelope_warnings: run.left_envelope.iter().filter(|x| **x).count() as u64,
                gate_resets: run.gate_resets,
                mean_nis_per_dof: if dof > 0 { sum / dof as f64 } else { f64::NAN },
                layout: end.layout,
                states: end.states,
                estimates: end.estimates,
                mounting: end.mounting,
                calibration: end.calibration,
                baro_loop: run.baro_loop.map(|l| l.counts),
            },
            epochs: run.epochs.into(),
            events: run.events.into(),
            snapshots: run.snapshots.map_or_else(Vec::new, |s| s.taken),
            smoothed: end.smoothed,
        })
    }

    /// Integrate one sample (the first starts the navigation).
    #[inline]
    fn integrate(&mut self, s: &ImuSample) {
        let run = &mut self.run;
        let Some(core) = self.core.as_mut() else {
            self.core = Some(run.begin(self.earth, &self.start, s));
            return;
        };
        let estimates = self.compensation.as_ref();
        match core {
            Core::Ned(m) => run.free_step(m, estimates, s),
            Core::Wander(m) => run.free_step(m, estimates, s),
            Core::FilterNed(i) => run.filter_step(&self.earth, i, s),
            Core::FilterWander(i) => run.filter_step(&self.earth, i, s),
            Core::FilterSeed18(i) => run.seed18_step(&self.earth, i, s),
        }
        run.samples += 1;
        run.done = Some((s.t, s.dt));
        if run.switch.due_for(core)
            && let Some(old) = self.core.take()
        {
            let (new, handover) = old.handed_over();
            run.handovers.push(handover);
            run.events.push_back(Event::Handover(handover));
            self.core = Some(new);
        }
        if run.decimator.take(s.t, s.dt)
            && let Some(core) = self.core.as_mut()
        {
            run.emit(core);
        }
    }
}

/// Whether every number of `s` is finite.
fn state_is_finite(s: &NavState) -> bool {
    let q = s.q_bn.as_ref();
    [
        s.pos.lat, s.pos.lon, s.pos.h, s.v_n.x, s.v_n.y, s.v_n.z, q.w, q.i, q.j, q.k,
    ]
    .iter()
    .all(|x| x.is_finite())
}

/// The epoch a running navigation reports now.
fn epoch_of<E: EarthModel>(core: &Core<E>) -> Epoch {
    let (state, r_e, wander_azimuth) = core.read_out();
    Epoch {
        state,
        r_e,
        wander_azimuth,
        mechanization: core.kind(),
        filter: match core {
            Core::FilterNed(i) => Some(FilterEpoch::of(i)),
            Core::FilterWander(i) => Some(FilterEpoch::of(i)),
            Core::FilterSeed18(i) => Some(FilterEpoch::of_seed18(i)),
            _ => None,
        },
    }
}

/// What the filter leaves at the end of a session.
#[derive(Default)]
struct FilterEnd {
    counts: Counts,
    layout: Option<Layout>,
    states: Option<usize>,
    estimates: Option<crate::filter::SensorEstimates>,
    mounting: Option<(crate::filter::VehicleMount, [f64; 2])>,
    calibration: crate::filter::CalibrationState,
    smoothed: Option<SmoothedTrajectory>,
}

/// The filter's counts, layout, estimates and mount, and the smoothed trajectory when
/// asked.
fn filter_end<M: ErrorFrame, E: EarthModel>(
    i: &mut Integrator<M, E>,
    cfg: &SessionConfig,
) -> Result<FilterEnd, SessionError> {
    let filter = cfg.filter.as_ref();
    let smooth = filter.is_some_and(|f| f.smooth);
    let p = i.covariance();
    let mounting = match (i.layout().mounting, filter) {
        (Some(o), Some(f)) => Some((
            f.vehicle.mount.corrected(&i.estimates().mounting),
            [p[(o, o)].max(0.0).sqrt(), p[(o + 1, o + 1)].max(0.0).sqrt()],
        )),
        _ => None,
    };
    let smoothed = if smooth {
        i.smoothed().transpose()?
    } else {
        None
    };
    Ok(FilterEnd {
        counts: i.book.counts,
        layout: Some(i.layout()),
        states: Some(i.layout().n),
        estimates: Some(i.estimates()),
        mounting,
        calibration: i.calibration(),
        smoothed,
    })
}

impl Loop {
    /// Why the configuration has no use for `aid` (`None`: it has).
    fn unused(&self, aid: &Aid) -> Option<&'static str> {
        let f = self.cfg.filter.as_ref();
        match aid {
            Aid::Gnss(_) if f.is_none() => Some("GNSS needs the filter"),
            Aid::Ranges(_) if self.tight.is_none() => {
                Some("raw GNSS ranges need tight coupling in the configuration")
            }
            Aid::Baro { .. }
                if f.is_none_or(|f| f.integration.baro.is_none()) && self.baro_loop.is_none() =>
            {
                Some("no barometer in the configuration (filter bias state or baro loop)")
            }
            Aid::Odometer { .. } if f.is_none_or(|f| f.vehicle.odometer_std.is_none()) => {
                Some("no odometer in the configuration")
            }
            Aid::Heading(_) if f.is_none_or(|f| f.vehicle.heading_baseline.is_none()) => {
                Some("no dual-antenna baseline in the configuration")
            }
            Aid::Rest { .. }
                if f.is_none_or(|f| {
                    f.vehicle
                        .rest
                        .is_none_or(|r| r.source != RestSource::Intervals)
                }) =>
            {
                Some("no zero-velocity updates on given rest intervals in the configuration")
            }
            _ => None,
        }
    }

    /// Start at the first sample: the mechanization (and filter) at the start state at
    /// its time, primed with its increments; its epoch and snapshot.
    fn begin<E: EarthModel>(&mut self, earth: E, start: &Start, s: &ImuSample) -> Core<E> {
        let init = NavState {
            t: s.t,
            ..start.state
        };
        let wander = self
            .switch
            .starts_wander(self.cfg.mechanization.choice, init.pos.lat.sin());
        let mut core = match (self.cfg.filter, wander) {
            (None, false) => Core::Ned(Navigating::start(earth, init)),
            (None, true) => Core::Wander(Navigating::start(earth, init)),
            (Some(f), false) => Core::FilterNed(self.start_filter(earth, init, start, &f)),
            (Some(f), true) if f.error_model == ErrorModelChoice::Seed18 => {
                match self.start_seed18(earth, init, start, &f) {
                    Ok(i) => Core::FilterSeed18(Box::new(i)),
                    // `SessionConfig::validate` has refused what the model lacks.
                    Err(e) => {
                        self.failure = Some(SessionError::Config(ConfigError::new(
                            "filter.error_model",
                            e.to_string(),
                        )));
                        Core::Wander(Navigating::start(earth, init))
                    }
                }
            }
            (Some(f), true) => Core::FilterWander(self.start_filter(earth, init, start, &f)),
        };
        let compensated = start.estimates.compensate(s);
        match &mut core {
            Core::Ned(m) => m.prime(&compensated),
            Core::Wander(m) => m.prime(&compensated),
            Core::FilterNed(i) => i.prime(s),
            Core::FilterWander(i) => i.prime(s),
            Core::FilterSeed18(i) => i.prime(s),
        }
        self.first_mechanization = core.kind();
        self.t_first = s.t;
        self.done = Some((s.t, s.dt));
        self.decimator.take(s.t, s.dt);
        self.emit(&mut core);
        if let (Some(taker), Core::FilterNed(i)) = (self.snapshots.as_mut(), &core) {
            taker.after_sample(&earth, i, s.t, s.dt);
        }
        if let (Some(taker), Core::FilterWander(i)) = (self.snapshots.as_mut(), &core) {
            taker.after_sample(&earth, i, s.t, s.dt);
        }
        if let (Some(taker), Core::FilterSeed18(i)) = (self.snapshots.as_mut(), &core) {
            taker.after_sample(&earth, i.as_ref(), s.t, s.dt);
        }
        core
    }

    fn start_filter<M: Navigating<E>, E: EarthModel>(
        &self,
        earth: E,
        init: NavState,
        start: &Start,
        f: &FilterConfig,
    ) -> Integrator<M, E> {
        let mut integ = Integrator::new(M::start(earth, init), earth, f.integration)
            .with_estimates(start.estimates);
        if let Some(p) = &f.att_bias_cov {
            integ = integ.with_attitude_bias_covariance(p);
        }
        let integ = match &self.vehicle {
            Some(v) => v.configure(integ),
            None => integ,
        };
        let integ = match &self.tight {
            Some(t) => integ.with_tight(t.clone()),
            None => integ,
        };
        if f.smooth {
            integ.with_smoother()
        } else {
            integ
        }
    }

    /// The 18-state filter at the start state, with the start's sensor estimates
    /// standing as the compensation and the alignment's prior if any.
    fn start_seed18<E: EarthModel>(
        &self,
        earth: E,
        init: NavState,
        start: &Start,
        f: &FilterConfig,
    ) -> Result<Seed18<E>, crate::filter::seed18::Unsupported> {
        let mut s = Seed18::new(Navigating::start(earth, init), f.integration)?
            .with_estimates(start.estimates);
        if let Some(p) = &f.att_bias_cov {
            s = s.with_attitude_bias_covariance(p);
        }
        Ok(s)
    }

    /// Record an output epoch (and the smoother's output instant).
    fn emit<E: EarthModel>(&mut self, core: &mut Core<E>) {
        match core {
            Core::FilterNed(i) => i.record_output(),
            Core::FilterWander(i) => i.record_output(),
            _ => {}
        }
        let epoch = epoch_of(core);
        if !state_is_finite(&epoch.state) {
            self.failure = Some(SessionError::NotFinite {
                t: epoch.state.t,
                last_good: self.last_good,
            });
            return;
        }
        self.last_good = epoch.state.t;
        self.check_envelope(&epoch.state);
        self.epochs.push_back(epoch);
    }

    /// Warn once per bound when `state` is outside the envelope.
    fn check_envelope(&mut self, state: &NavState) {
        let Some(e) = self.cfg.envelope else { return };
        let speed = state.v_n.norm();
        let h = state.pos.h;
        let crossed = [
            (h < e.min_height || h.is_nan())
                .then(|| format!("height {h:.1} m below {} m", e.min_height)),
            (h > e.max_height).then(|| format!("height {h:.1} m above {} m", e.max_height)),
            (speed > e.max_speed || speed.is_nan())
                .then(|| format!("speed {speed:.1} m/s above {} m/s", e.max_speed)),
        ];
        for (k, what) in crossed.into_iter().enumerate() {
            if let Some(what) = what
                && !self.left_envelope[k]
            {
                self.left_envelope[k] = true;
                self.events.push_back(Event::Envelope { t: state.t, what });
            }
        }
    }

    /// One sample of free-inertial navigation (with the baro loop when configured),
    /// compensated with `estimates` when there are any.
    #[inline]
    fn free_step<M: ErrorFrame>(
        &mut self,
        m: &mut M,
        estimates: Option<&crate::filter::SensorEstimates>,
        s: &ImuSample,
    ) {
        match estimates {
            None => m.step(s),
            Some(e) => m.step(&e.compensate(s)),
        }
        if let Some(l) = self.baro_loop.as_mut() {
            let early = s.t - 0.5 * s.dt;
            while let Some(&(t, h)) = self.queues.baro.front().filter(|r| r.0 <= s.t + 0.5 * s.dt) {
                self.queues.baro.pop_front();
                if t <= early {
                    self.skipped_free += 1;
                    self.events.push_back(Event::Skipped(Skipped {
                        t,
                        kind: Kind::BaroHeight,
                        reason: SkipReason::BeforeImu,
                    }));
                } else {
                    l.update(m, Some(h));
                }
            }
        }
    }

    /// One sample under the filter: GNSS inside it, then the barometer and the vehicle
    /// aids due at its end; the filter's records become events.
    fn filter_step<M: ErrorFrame, E: EarthModel>(
        &mut self,
        earth: &E,
        integ: &mut Integrator<M, E>,
        s: &ImuSample,
    ) {
        integ.step_with_fixes(s, &mut self.queues.gnss);
        if let Some(f) = &self.cfg.filter {
            // Readings up to half a sample past this one's end apply here.
            while let Some(&(t, h)) = self.queues.baro.front().filter(|r| r.0 <= s.t + 0.5 * s.dt) {
                self.queues.baro.pop_front();
                if t > s.t - 0.5 * s.dt {
                    integ.update_baro(t, h, f.baro_std);
                } else {
                    integ.skip_measurement(t, Kind::BaroHeight, SkipReason::BeforeImu);
                }
            }
        }
        if let Some(v) = self.vehicle.as_mut() {
            v.after_sample(integ, &mut self.queues, s);
        }
        self.take_records(integ);
        if let Some(taker) = self.snapshots.as_mut() {
            taker.after_sample(earth, integ, s.t, s.dt);
        }
    }

    /// Move what the filter recorded into the events.
    fn take_records<M: ErrorFrame, E: EarthModel>(&mut self, integ: &mut Integrator<M, E>) {
        self.take(&mut integ.book);
    }

    /// Move a filter's records (tested, refused, skipped measurements, gate resets)
    /// into the events.
    fn take(&mut self, book: &mut GateBook) {
        let GateBook {
            innovations,
            rejected,
            skipped,
            gate_resets,
            ..
        } = book;
        if !innovations.is_empty() {
            for i in innovations.drain(..) {
                if i.accepted {
                    self.nis.0 += i.nis;
                    self.nis.1 += i.z.len();
                }
                self.events.push_back(Event::Measurement(i));
            }
        }
        if !rejected.is_empty() {
            self.events.extend(rejected.drain(..).map(Event::Refused));
        }
        if !skipped.is_empty() {
            self.events.extend(skipped.drain(..).map(Event::Skipped));
        }
        if !gate_resets.is_empty() {
            self.gate_resets += gate_resets.len() as u64;
            self.events.extend(
                gate_resets
                    .drain(..)
                    .map(|(t, nis)| Event::GateReset { t, nis }),
            );
        }
    }

    /// One sample under the 18-state filter: GNSS inside it (the configuration
    /// allows no other aid); its records become events.
    fn seed18_step<E: EarthModel>(&mut self, earth: &E, f: &mut Seed18<E>, s: &ImuSample) {
        f.step_with_fixes(s, &mut self.queues.gnss);
        self.take_seed18(f);
        if let Some(taker) = self.snapshots.as_mut() {
            taker.after_sample(earth, f, s.t, s.dt);
        }
    }

    fn take_seed18<E: EarthModel>(&mut self, f: &mut Seed18<E>) {
        self.take(&mut f.book);
    }

    /// At the end of the input under the 18-state filter: fixes after the last
    /// sample are skipped.
    fn finish_seed18<E: EarthModel>(&mut self, f: &mut Seed18<E>) {
        while let Some(u) = self.queues.gnss.pop_front() {
            f.skip(u.time(), SkipReason::AfterImu);
        }
        self.take_seed18(f);
    }

    /// At the end of the input: aids after the last sample are skipped.
    fn finish_filter<M: ErrorFrame, E: EarthModel>(&mut self, integ: &mut Integrator<M, E>) {
        while let Some(u) = self.queues.gnss.pop_front() {
            FixConsumer::<GnssUpdate>::skip_fix(integ, &u, SkipReason::AfterImu);
        }
        while let Some((t, _)) = self.queues.baro.pop_front() {
            integ.skip_measurement(t, Kind::BaroHeight, SkipReason::AfterImu);
        }
        if let Some(v) = self.vehicle.as_mut() {
            v.finish(integ, &mut self.queues);
        }
        self.take_records(integ);
    }
}
