//! What a session gives back as it goes: output epochs at the chosen cadence, events
//! (every measurement tested, refused, skipped, late or ignored; hand-overs), and the
//! filter's snapshots for consistency reports.

use super::config::MechanizationKind;
use crate::analysis::consistency::normalized_squared;
use crate::analysis::errors::{NavRecord, TIME_TOLERANCE_S, TruthAt, TruthCursor, errors_between};
use crate::earth::EarthModel;
use crate::filter::integration::{Innovation, Rejected, Skipped};
use crate::filter::kalman::std3;
use crate::filter::measurement::Kind;
use crate::filter::seed18::Seed18;
use crate::filter::{CalibrationState, Integrator, Layout, SensorEstimates};
use crate::nav::{ErrorFrame, NavState};
use nalgebra::{Matrix3, Vector3};
use std::collections::VecDeque;

/// One output epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Epoch {
    /// The navigation state (NED; at a pole relative to the pole longitude's meridian).
    pub state: NavState,
    /// ECEF position [m] (defined everywhere, poles included).
    pub r_e: Vector3<f64>,
    /// Wander azimuth [rad]: the navigation frame's x axis east of north (0 on NED).
    pub wander_azimuth: f64,
    /// The mechanization that produced it.
    pub mechanization: MechanizationKind,
    /// The filter's view, when a filter runs.
    pub filter: Option<FilterEpoch>,
}

/// The filter's uncertainty and sensor-error estimates at an output epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterEpoch {
    /// Covariances of position, velocity (NED, m² and m²/s²) and attitude error
    /// (about north, east, down, rad²).
    pub nav_cov: [Matrix3<f64>; 3],
    /// Standard deviations of position, velocity (NED, m and m/s) and attitude
    /// (about north, east, down, rad): square roots of the covariances' diagonals.
    pub nav_std: [Vector3<f64>; 3],
    /// Estimated sensor errors.
    pub estimates: SensorEstimates,
    /// Standard deviations of gyro bias [rad/s], accelerometer bias [m/s^2], gyro and
    /// accelerometer scale factors (zero where not estimated).
    pub sensor_std: [Vector3<f64>; 4],
}

impl FilterEpoch {
    /// The filter's view now.
    pub fn of<M: ErrorFrame, E: EarthModel>(integ: &Integrator<M, E>) -> Self {
        let p = integ.covariance();
        let l = integ.layout();
        let std = |o: Option<usize>| o.map_or(Vector3::zeros(), |o| std3(p, o));
        let nav_cov = integ.nav_covariance();
        Self {
            nav_cov,
            nav_std: nav_cov.map(|p| p.diagonal().map(|v| v.max(0.0).sqrt())),
            estimates: integ.estimates(),
            sensor_std: [
                std(Some(Layout::GYRO_BIAS)),
                std(Some(Layout::ACCEL_BIAS)),
                std(l.gyro_scale),
                std(l.accel_scale),
            ],
        }
    }
}

impl FilterEpoch {
    /// The 18-state filter's view now: the covariances of its physical errors
    /// ([`Seed18::physical_covariance`]), no scale factors.
    pub fn of_seed18<E: EarthModel>(f: &Seed18<E>) -> Self {
        let nav_cov = f.nav_covariance();
        let [g, a] = f.sensor_std();
        Self {
            nav_cov,
            nav_std: nav_cov.map(|p| p.diagonal().map(|v| v.max(0.0).sqrt())),
            estimates: f.estimates(),
            sensor_std: [g, a, Vector3::zeros(), Vector3::zeros()],
        }
    }
}

/// What a snapshot reads of a running filter: the psi-angle [`Integrator`] or the
/// 18-state [`Seed18`].
pub(crate) trait FilterView {
    /// The state now.
    fn view_state(&self) -> NavState;
    /// The filter's view now.
    fn view_epoch(&self) -> FilterEpoch;
    /// Standard deviation of the barometer bias, when estimated.
    fn view_baro_std(&self) -> Option<f64>;
    /// The calibration estimates ([`crate::filter::calibration`]).
    fn view_calibration(&self) -> CalibrationState {
        CalibrationState::default()
    }
}

impl<M: ErrorFrame, E: EarthModel> FilterView for Integrator<M, E> {
    fn view_state(&self) -> NavState {
        self.state()
    }
    fn view_epoch(&self) -> FilterEpoch {
        FilterEpoch::of(self)
    }
    fn view_baro_std(&self) -> Option<f64> {
        let p = self.covariance();
        self.layout().baro_bias.map(|b| p[(b, b)].max(0.0).sqrt())
    }
    fn view_calibration(&self) -> CalibrationState {
        self.calibration()
    }
}

impl<E: EarthModel> FilterView for Seed18<E> {
    fn view_state(&self) -> NavState {
        self.state()
    }
    fn view_epoch(&self) -> FilterEpoch {
        FilterEpoch::of_seed18(self)
    }
    fn view_baro_std(&self) -> Option<f64> {
        None
    }
}

/// A hand-over between mechanizations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Handover {
    /// Time [s] of the state handed over.
    pub t: f64,
    /// Latitude [rad] there.
    pub lat: f64,
    /// The mechanization taking over.
    pub to: MechanizationKind,
}

/// Something the session did that its caller may want to know, in time order.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A measurement the filter tested, accepted or refused, with its innovation and
    /// normalized innovation squared.
    Measurement(Innovation),
    /// A measurement the gate refused, with the test's numbers.
    Refused(Rejected),
    /// A GNSS position accepted without the gate after consecutive refusals.
    GateReset {
        /// Time [s].
        t: f64,
        /// Its normalized innovation squared.
        nis: f64,
    },
    /// A measurement outside the IMU data.
    Skipped(Skipped),
    /// An aid that arrived after the sample it belongs to was integrated.
    Late {
        /// The aid's time [s].
        t: f64,
        /// What it was.
        kind: Kind,
        /// How far the session had integrated when it arrived [s].
        integrated_to: f64,
    },
    /// An aid the configuration has no use for (e.g. GNSS without a filter).
    Ignored {
        /// The aid's time [s].
        t: f64,
        /// What it was.
        kind: Kind,
        /// Why.
        reason: &'static str,
    },
    /// A hand-over between mechanizations.
    Handover(Handover),
    /// The solution left the physical envelope (reported once per bound).
    Envelope {
        /// Time [s].
        t: f64,
        /// Which bound, with the value: e.g. `height -1234.5 m below -1000 m`.
        what: String,
    },
}

/// Decides which epochs to emit: every one, or the first epoch at or after each
/// multiple of `1/rate` (a thousandth of a sample interval of tolerance absorbs the
/// decimal time tags of logs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decimator {
    rate: Option<f64>,
    last_slot: f64,
}

impl Decimator {
    /// Every epoch (`None`) or `rate` [Hz].
    pub fn new(rate: Option<f64>) -> Self {
        Self {
            rate,
            last_slot: f64::NEG_INFINITY,
        }
    }

    /// Whether the sample ending at `t` after `dt` is an output epoch.
    #[inline]
    pub fn take(&mut self, t: f64, dt: f64) -> bool {
        match self.rate {
            None => true,
            Some(r) => {
                // `floor(x) > last` is `x >= last + 1` for an integer `last`: the
                // floor is taken only at an output epoch.
                let x = (t + 1e-3 * dt) * r;
                let take = x >= self.last_slot + 1.0;
                if take {
                    self.last_slot = x.floor();
                }
                take
            }
        }
    }
}

/// The filter's sensor errors, covariance and, against a truth, its normalized
/// estimation errors squared (NEES) at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Snapshot {
    /// Time [s].
    pub t: f64,
    /// Estimated sensor errors.
    pub estimates: SensorEstimates,
    /// Standard deviations of gyro bias [rad/s], accelerometer bias [m/s^2], gyro and
    /// accelerometer scale factors (zero where not estimated).
    pub sensor_std: [Vector3<f64>; 4],
    /// Standard deviation of the barometer bias [m], when estimated.
    pub baro_std: Option<f64>,
    /// The lever arm and time offset, when calibrated.
    pub calibration: CalibrationState,
    /// NEES of position, velocity and attitude (3 dof each): `None` without a truth
    /// at this time; an entry `None` where the covariance block is not positive
    /// definite.
    pub nees: Option<[Option<f64>; 3]>,
}

/// Takes a [`Snapshot`] at a cadence, with NEES against a truth when it has one.
///
/// The truth is held from the epoch at or before the last snapshot on: the epochs
/// behind it are dropped as the snapshots pass them, so a truth pushed ahead of the
/// samples ([`super::Session::push_truth`]) costs a window, not the whole file. The
/// truth at a time is then [`TruthCursor`]'s on the whole truth: the epoch within
/// [`TIME_TOLERANCE_S`], else interpolated between the two around it, provided an
/// epoch after the time is already held (or the truth has ended).
#[derive(Debug, Clone)]
pub(crate) struct SnapshotTaker {
    truth: VecDeque<NavRecord>,
    cadence: Decimator,
    pub taken: Vec<Snapshot>,
}

impl SnapshotTaker {
    pub fn new(rate: f64, truth: Vec<NavRecord>) -> Self {
        Self {
            truth: truth.into(),
            cadence: Decimator::new(Some(rate)),
            taken: Vec::new(),
        }
    }

    /// Appends a truth epoch (after the last one held).
    pub fn push_truth(&mut self, r: NavRecord) {
        self.truth.push_back(r);
    }

    /// The truth at `t` (times that do not decrease), the epochs before the one at
    /// or before `t` dropped.
    fn truth_at(&mut self, t: f64) -> TruthAt {
        while self.truth.len() >= 2 && self.truth[1].t_sow <= t + TIME_TOLERANCE_S {
            self.truth.pop_front();
        }
        TruthCursor::default().at(self.truth.make_contiguous(), t)
    }

    /// After a sample ending at `t` after `dt`: a snapshot at the first epoch of each
    /// period.
    pub fn after_sample<F: FilterView, E: EarthModel>(
        &mut self,
        earth: &E,
        integ: &F,
        t: f64,
        dt: f64,
    ) {
        if !self.cadence.take(t, dt) {
            return;
        }
        let state = integ.view_state();
        let f = integ.view_epoch();
        let nees = if self.truth.is_empty() {
            None
        } else {
            match self.truth_at(state.t) {
                TruthAt::Exact(truth) | TruthAt::Interpolated(truth, _) => {
                    let e = errors_between(earth, &state, &(&truth).into());
                    let [pp, pv, pa]: [Matrix3<f64>; 3] = f.nav_cov;
                    Some([
                        normalized_squared(&e.pos_n, &pp),
                        normalized_squared(&e.v_n, &pv),
                        normalized_squared(&e.psi, &pa),
                    ])
                }
                TruthAt::Before | TruthAt::After => None,
            }
        };
        self.taken.push(Snapshot {
            t: state.t,
            estimates: f.estimates,
            sensor_std: f.sensor_std,
            baro_std: integ.view_baro_std(),
            calibration: integ.view_calibration(),
            nees,
        });
    }
}
