//! Covariance propagation along a true trajectory, the whole filter and each error
//! source alone through the same closed loop.
//!
//! The whole run is the filter's covariance bookkeeping without its estimates: the
//! true (error-free) IMU increments are summed into the filter's propagation interval
//! ([`Interval`]), whose means give `Φ` and `Q_d` ([`ErrorModel::transition`]) at the
//! true frame; each measurement's `H` and `R` are the filter's own
//! ([`crate::filter::measurement`]) at the true state, and the update is
//! [`Kalman::update`] with the gate off (no innovation exists: every measurement is
//! taken). The frame is local-level (`c` = NED), so the covariance's blocks are NED.
//!
//! Each source `i` alone (the standard error-budget method, e.g. Maybeck 1979, §6.8;
//! Grewal & Andrews 2015, §8.6): its own prior `P₀ᵢ`, discrete noise `Q_dᵢ` and, for a
//! measurement-noise source, `Rᵢ = R` of its kind (else 0), through the gains `K` of
//! the whole filter:
//!
//! - `Pᵢ ← Φ Pᵢ Φᵀ + Q_dᵢ`;
//! - `Pᵢ ← (I − K H) Pᵢ (I − K H)ᵀ + K Rᵢ Kᵀ` (Joseph), `K = P Hᵀ (H P Hᵀ + R)⁻¹` of
//!   the whole `P` before the update.
//!
//! Both steps are linear in `(Pᵢ, Q_dᵢ, Rᵢ)` and the parts add up to `(P₀, Q_d, R)`
//! ([`super::source`]), so `Σ Pᵢ = P` at every instant, to round-off. The gains being
//! computed causally from the whole `P`, one pass carries the whole filter and every
//! source together (no record of the gains is needed).

use super::source::{MODEL_SOURCES, Source, process_model};
use crate::earth::EarthModel;
use crate::filter::interval::Interval;
use crate::filter::kalman::{Gate, Kalman};
use crate::filter::measurement::{self, Kind, Measurement};
use crate::filter::{ErrorModel, IntegrationConfig, Integrator, Layout};
use crate::imu::ImuSample;
use crate::nav::{ErrorFrame, FrameSnapshot, LocalLevel, NavState};
use nalgebra::{DMatrix, DVector, Vector3};

/// One source's share of the covariance.
#[derive(Debug, Clone)]
pub struct Part {
    /// The source.
    pub source: Source,
    /// Its covariance `Pᵢ`.
    pub p: DMatrix<f64>,
    /// Its process model (the filter's, with only its own noise), if it has noise.
    model: Option<ErrorModel>,
}

/// The whole filter's covariance and every source's share, along a true trajectory.
#[derive(Debug, Clone)]
pub struct Budget<E: EarthModel> {
    earth: E,
    cfg: IntegrationConfig,
    model: ErrorModel,
    kf: Kalman,
    parts: Vec<Part>,
    interval: Interval,
    truth: NavState,
    w_ib_b: Vector3<f64>,
    updates: u64,
}

/// `P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ` (given `K R Kᵀ`, or none), symmetrized as
/// [`Kalman::update`] does.
fn joseph(p: &mut DMatrix<f64>, ikh: &DMatrix<f64>, krk: Option<&DMatrix<f64>>) {
    let mut q = ikh * &*p * ikh.transpose();
    if let Some(krk) = krk {
        q += krk;
    }
    *p = (&q + q.transpose()) * 0.5;
}

impl<E: EarthModel> Budget<E> {
    /// A budget from the true state `start` with the filter configuration `cfg`: the
    /// whole prior is the filter's own ([`Integrator::new`] on a local-level
    /// mechanization at `start`), each source's the same of its masked configuration.
    /// Sources that contribute nothing are left out.
    pub fn new(earth: E, start: NavState, cfg: IntegrationConfig) -> Self {
        let prior = |c: IntegrationConfig| {
            let f = Integrator::new(LocalLevel::new(earth, start), earth, c);
            (f.layout(), f.covariance().clone())
        };
        let (layout, p) = prior(cfg);
        // A source whose prior and noise are both zero contributes nothing: left out.
        let parts = MODEL_SOURCES
            .iter()
            .filter_map(|&source| {
                let keep = source.keep(&cfg);
                let model = process_model(layout, &keep);
                let q = model.process_noise(&probe_means(earth, &start));
                let noisy = q.iter().any(|&q| q != 0.0);
                let p = prior(keep).1;
                (noisy || p.iter().any(|&p| p != 0.0)).then(|| Part {
                    source,
                    p,
                    model: noisy.then_some(model),
                })
            })
            .collect();
        Self {
            earth,
            cfg,
            model: process_model(layout, &cfg),
            kf: Kalman::new(p),
            parts,
            interval: Interval::default(),
            truth: start,
            w_ib_b: Vector3::zeros(),
            updates: 0,
        }
    }

    /// Add the noise source of measurements of `kind` now (its share is zero until
    /// its first update; [`Budget::update`] adds it on first use otherwise), so that
    /// tables can name it from the start.
    pub fn declare(&mut self, kind: Kind) {
        let source = Source::Noise(kind);
        if self.parts.iter().all(|p| p.source != source) {
            let n = self.model.layout.n;
            self.parts.push(Part {
                source,
                p: DMatrix::zeros(n, n),
                model: None,
            });
        }
    }

    /// One true IMU sample (error-free increments over `(t − dt, t]`) and the true
    /// state at its end; the covariance is propagated when the interval reaches the
    /// filter's `propagation_interval`, as the filter does.
    pub fn step(&mut self, exact: &ImuSample, truth: &NavState) {
        self.interval.add(exact, &self.truth.q_bn);
        self.truth = *truth;
        if exact.dt > 0.0 {
            self.w_ib_b = exact.dtheta / exact.dt;
        }
        if self.interval.t >= self.cfg.propagation_interval {
            self.propagate();
        }
    }

    /// Propagate over the interval summed so far (nothing if it is empty).
    pub fn propagate(&mut self) {
        if self.interval.t <= 0.0 {
            return;
        }
        let means = self.interval.means(self.frame());
        let (phi, qd) = self.model.transition(&means);
        self.kf.predict(&phi, &qd);
        for part in &mut self.parts {
            let mut p = &phi * &part.p * phi.transpose();
            if let Some(model) = &part.model {
                p += model.transition(&means).1;
            }
            part.p = (&p + p.transpose()) * 0.5;
        }
        self.interval = Interval::default();
    }

    /// Apply a measurement (its `H` and `R`; the innovation is not used) at the current
    /// time, after propagating to it. `false` if its innovation covariance is not
    /// positive definite (the filter would refuse it too), nothing changed then.
    pub fn update(&mut self, m: &Measurement) -> bool {
        self.propagate();
        self.declare(m.kind);
        let pht = &self.kf.p * m.h.transpose();
        let Some(chol) = (&m.h * &pht + &m.r).cholesky() else {
            return false;
        };
        // K = P Hᵀ S⁻¹, as Kalman::update solves it.
        let k = chol.solve(&pht.transpose()).transpose();
        let zero = DVector::zeros(m.h.nrows());
        if self.kf.update(&zero, &m.h, &m.r, Gate::Off).is_err() {
            return false;
        }
        let n = self.model.layout.n;
        let ikh = DMatrix::identity(n, n) - &k * &m.h;
        let krk = &k * &m.r * k.transpose();
        let own = Source::Noise(m.kind);
        for part in &mut self.parts {
            joseph(&mut part.p, &ikh, (part.source == own).then_some(&krk));
        }
        self.updates += 1;
        true
    }

    /// A GNSS fix at the true antenna position, with NED position standard deviations
    /// and, if measured, velocity ones: the filter's position then velocity update
    /// ([`Integrator::update_gnss`]).
    pub fn gnss(&mut self, pos_std: &Vector3<f64>, vel_std: Option<&Vector3<f64>>) {
        self.propagate();
        let (layout, frame, lever) = (self.model.layout, self.frame(), self.cfg.lever_arm);
        let pos = self.truth.pos;
        let m = measurement::gnss_position(&self.earth, &layout, &frame, &pos, pos_std, &lever);
        self.update(&m);
        if let Some(std) = vel_std {
            let v = self.truth.v_n;
            let w = self.w_ib_b;
            let m = measurement::gnss_velocity(&layout, &frame, &pos, &v, std, &lever, &w);
            self.update(&m);
        }
    }

    /// A barometric height with standard deviation `std` [m] (needs the filter's
    /// barometer, `cfg.baro`; `false` without).
    pub fn baro(&mut self, std: f64) -> bool {
        let h = self.truth.pos.h;
        match measurement::baro_height(&self.model.layout, h, h, 0.0, std) {
            Some(m) => self.update(&m),
            None => false,
        }
    }

    /// The true frame at the current time.
    pub fn frame(&self) -> FrameSnapshot {
        LocalLevel::new(self.earth, self.truth).frame()
    }

    /// The current true state.
    pub fn truth(&self) -> &NavState {
        &self.truth
    }

    /// The filter's state layout.
    pub fn layout(&self) -> Layout {
        self.model.layout
    }

    /// The whole filter's covariance (NED blocks).
    pub fn total(&self) -> &DMatrix<f64> {
        &self.kf.p
    }

    /// Every source's share, in the order of [`MODEL_SOURCES`] then of first use.
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// Measurements applied so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }
}

/// The means of an empty interval at a state, to ask a process model whether it has
/// noise at all (its `Q` depends on the state only through a rotation).
fn probe_means<E: EarthModel>(earth: E, s: &NavState) -> crate::filter::IntervalMeans {
    Interval::default().means(LocalLevel::new(earth, *s).frame())
}

/// Variances of position, velocity and attitude (NED, per axis) in a covariance.
pub fn nav_variances(p: &DMatrix<f64>) -> [Vector3<f64>; 3] {
    [Layout::POS, Layout::VEL, Layout::ATT]
        .map(|o| Vector3::new(p[(o, o)], p[(o + 1, o + 1)], p[(o + 2, o + 2)]))
}
