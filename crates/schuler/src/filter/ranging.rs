//! Tight coupling: each pseudorange and pseudorange rate of an epoch as a scalar
//! measurement of the error-state filter, with the receiver clock in the state.
//!
//! States ([`super::Layout::with_clock`]): the residual clock bias `δb_s = b_s − b̂_s`
//! of each system [m] and the residual drift `δd` [m/s] (residuals as the sensor
//! biases, fed back into [`Clocks`]). With the antenna at `r_a = r + C_ec C_cb l`
//! ([`crate::gnss::RangeModel::predict`] for the rest of the model) and `x` the error
//! state (computed minus true for position, velocity and attitude):
//!
//! - pseudorange, `z = P̂ − P = −u_cᵀ (δr + [(Ĉ_cb l)×] ψ) − δb_s + v`,
//! - rate, `z = ρ̇̂ − ρ̇ = −(u_c/k)ᵀ (δv + [(Ĉ_cb (ω_eb × l))×] ψ − Ĉ_cb [l×] δb_g) − δd + v`,
//!
//! `u_c` the line of sight in the computation frame (the position and velocity blocks
//! of [`super::measurement`]'s GNSS models, projected on it). The measurements of an
//! epoch are independent (a diagonal `R`), so processing them one at a time is the
//! batch update; each is re-linearised at the state its predecessors corrected, and
//! gated alone (χ²(1) at the filter's level): a faulty satellite is refused by itself
//! and logged with its id. After `reset_after` epochs in a row with every measurement
//! refused (the filter lost track, a long outage), the next epoch passes unless beyond
//! [`super::integration::RESET_MAX_SIGMA`].
//!
//! The clock is started from the measurements: at a system's first epoch its bias is
//! the median of `P − P̂` (the filter's own position in `P̂`), with prior σ
//! [`TightConfig::init_bias_std`]; the drift likewise from the first Dopplers, or
//! from 0 with [`DRIFT_STD_WITHOUT_DOPPLER`] when there are none. A
//! receiver clock jump (receivers that hold their clock within 1 ms of GPS time step
//! it by a millisecond, 300 km) shows as a median more than [`CLOCK_JUMP_M`] off the
//! prediction: the bias restarts there, and the restart is counted.

use super::error_model::ClockNoise;
use super::integration::RESET_MAX_SIGMA;
use super::kalman::Gate;
use super::layout::Layout;
use super::measurement::{Kind, Measurement};
use crate::gnss::{RangeEpoch, RangeModel, System};
use crate::nav::FrameSnapshot;
use crate::rotation::skew;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// A median pseudorange residual this far from the clock's prediction [m] is a jump of
/// the receiver clock (0.1 ms; no filter is this far off and every satellite alike).
pub const CLOCK_JUMP_M: f64 = 3.0e4;

/// Prior σ of the clock drift [m/s] when the first epochs carry no Doppler: a TCXO's
/// frequency offset of 1 ppm (c·1e-6), found then from the course of the biases.
pub const DRIFT_STD_WITHOUT_DOPPLER: f64 = 300.0;

/// Settings of tight coupling.
#[derive(Debug, Clone, PartialEq)]
pub struct TightConfig {
    /// The measurement model (mask, weights, ionosphere, troposphere).
    pub model: RangeModel,
    /// The receiver clock's noise.
    pub clock: ClockNoise,
    /// The systems with a clock bias, in the order of the states.
    pub systems: Vec<System>,
    /// Prior σ of a clock bias started from the measurements [m]: the spread of the
    /// medians with the filter's position error (default 30 m).
    pub init_bias_std: f64,
    /// Prior σ of the drift started from the Dopplers [m/s] (default 5 m/s).
    pub init_drift_std: f64,
    /// Use the Dopplers (default true).
    pub use_doppler: bool,
}

impl TightConfig {
    /// Tight coupling with `model`, a TCXO clock, a bias for each system `model` uses.
    pub fn new(model: RangeModel) -> Self {
        let systems = model.config.signals.iter().map(|(s, _)| *s).collect();
        Self {
            model,
            clock: ClockNoise::default(),
            systems,
            init_bias_std: 30.0,
            init_drift_std: 5.0,
            use_doppler: true,
        }
    }
}

/// The receiver clock as the filter estimates it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Clocks {
    /// Bias of each system of [`TightConfig::systems`] [m], once started.
    pub bias: Vec<Option<f64>>,
    /// Drift [m/s], once started.
    pub drift: Option<f64>,
    /// Times [s] at which a bias restarted after a clock jump.
    pub jumps: Vec<f64>,
    /// The time the values are at [s].
    pub t: Option<f64>,
}

impl Clocks {
    /// Carry the biases to time `t` with the drift, `b̂ += d̂·(t − t₀)` (the nominal of
    /// `ḃ = d`; the residuals' covariance follows in the filter's propagation).
    pub fn advance(&mut self, t: f64) {
        if let (Some(t0), Some(d)) = (self.t, self.drift) {
            for b in self.bias.iter_mut().flatten() {
                *b += d * (t - t0);
            }
        }
        self.t = Some(t);
    }

    /// Feed the clock states of the estimate `dx` back into the started clocks.
    pub fn feed_back(&mut self, layout: &Layout, dx: &DVector<f64>) {
        let (Some(b), Some(d)) = (layout.clock, layout.clock_drift()) else {
            return;
        };
        for (i, bias) in self.bias.iter_mut().enumerate() {
            if let Some(x) = bias {
                *x += dx[b + i];
            }
        }
        if let Some(x) = self.drift.as_mut() {
            *x += dx[d];
        }
    }
}

/// What tight coupling did, epoch by epoch, for reports.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RangeCounts {
    /// Epochs processed.
    pub epochs: u64,
    /// Satellites below the mask at the filter's antenna.
    pub masked: u64,
    /// Epochs whose every measurement was refused.
    pub all_refused: u64,
}

/// The tight-coupling part of a filter: settings, clock, counters.
#[derive(Debug, Clone, PartialEq)]
pub struct Tight {
    /// Settings.
    pub cfg: TightConfig,
    /// The clock.
    pub clocks: Clocks,
    /// Counters.
    pub counts: RangeCounts,
    /// Epochs in a row with every measurement refused.
    pub(crate) refused_in_a_row: u32,
}

impl Tight {
    /// Tight coupling under `cfg`, no clock started yet.
    pub fn new(cfg: TightConfig) -> Self {
        let n = cfg.systems.len();
        Self {
            cfg,
            clocks: Clocks {
                bias: vec![None; n],
                ..Clocks::default()
            },
            counts: RangeCounts::default(),
            refused_in_a_row: 0,
        }
    }

    /// The index of `system`'s bias, if it has one.
    pub fn clock_index(&self, system: System) -> Option<usize> {
        self.cfg.systems.iter().position(|&s| s == system)
    }

    /// The gate of an epoch's measurements: the filter's, or the reset's bound after
    /// `reset_after` epochs in a row refused whole (and whether it is the reset).
    pub(crate) fn gate(&self, gate: Gate, reset_after: u32) -> (Gate, bool) {
        if reset_after > 0 && self.refused_in_a_row >= reset_after {
            (Gate::Bound(RESET_MAX_SIGMA * RESET_MAX_SIGMA), true)
        } else {
            (gate, false)
        }
    }
}

/// The antenna's ECEF position and velocity (relative to the Earth) from the
/// mechanization's frame, lever arm `lever` (body) and compensated body rate `w_ib_b`;
/// with the body rate relative to the Earth (body axes), the lever arm in `c` and the
/// lever-arm velocity in `c`.
pub(crate) struct Antenna {
    pub w_eb_b: Vector3<f64>,
    pub r_e: Vector3<f64>,
    pub v_e: Vector3<f64>,
    pub l_c: Vector3<f64>,
    pub lever_v_c: Vector3<f64>,
    pub c_bc: Matrix3<f64>,
    pub c_ce: Matrix3<f64>,
}

impl Antenna {
    pub fn of(frame: &FrameSnapshot, lever: &Vector3<f64>, w_ib_b: &Vector3<f64>) -> Self {
        let c_bc = frame.q_bc.to_rotation_matrix().into_inner();
        let c_ec = frame.c_ce_to_e;
        let l_c = c_bc * lever;
        let w_eb = w_ib_b - c_bc.transpose() * frame.w_ie_c;
        let lever_v_c = c_bc * w_eb.cross(lever);
        Self {
            w_eb_b: w_eb,
            r_e: frame.r_e + c_ec * l_c,
            v_e: c_ec * (frame.v_c + lever_v_c),
            l_c,
            lever_v_c,
            c_bc,
            c_ce: c_ec.transpose(),
        }
    }
}

fn row(n: usize) -> DMatrix<f64> {
    DMatrix::zeros(1, n)
}

fn put_row(h: &mut DMatrix<f64>, col: usize, v: &nalgebra::RowVector3<f64>) {
    h.fixed_view_mut::<1, 3>(0, col).copy_from(v);
}

/// The pseudorange measurement: innovation `z` (predicted with the bias `bias` minus
/// measured), line of sight `u_e`, variance `var`, the bias's state `clock`.
pub(crate) fn pseudorange(
    layout: &Layout,
    a: &Antenna,
    u_e: &Vector3<f64>,
    z: f64,
    var: f64,
    clock: usize,
) -> Measurement {
    let u_c = (a.c_ce * u_e).transpose();
    let mut h = row(layout.n);
    put_row(&mut h, Layout::POS, &(-u_c));
    put_row(&mut h, Layout::ATT, &(-u_c * skew(&a.l_c)));
    h[(0, clock)] = -1.0;
    Measurement {
        kind: Kind::Pseudorange,
        z: DVector::from_element(1, z),
        h,
        r: DMatrix::from_element(1, 1, var),
    }
}

/// The pseudorange-rate measurement: innovation `z`, line of sight `u_e`, light-time
/// rate `k`, variance `var`, lever arm `lever` (body), the drift's state `drift`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn range_rate(
    layout: &Layout,
    a: &Antenna,
    lever: &Vector3<f64>,
    u_e: &Vector3<f64>,
    k: f64,
    z: f64,
    var: f64,
    drift: usize,
) -> Measurement {
    let u_c = (a.c_ce * u_e).transpose() / k;
    let mut h = row(layout.n);
    put_row(&mut h, Layout::VEL, &(-u_c));
    put_row(&mut h, Layout::ATT, &(-u_c * skew(&a.lever_v_c)));
    put_row(&mut h, Layout::GYRO_BIAS, &(u_c * a.c_bc * skew(lever)));
    h[(0, drift)] = -1.0;
    Measurement {
        kind: Kind::RangeRate,
        z: DVector::from_element(1, z),
        h,
        r: DMatrix::from_element(1, 1, var),
    }
}

/// The median of `xs` (sorted in place); `None` when empty.
pub(crate) fn median(xs: &mut [f64]) -> Option<f64> {
    if xs.is_empty() {
        return None;
    }
    xs.sort_by(f64::total_cmp);
    let n = xs.len();
    Some(if n % 2 == 1 {
        xs[n / 2]
    } else {
        0.5 * (xs[n / 2 - 1] + xs[n / 2])
    })
}

/// The epoch's satellites seen from `a` with their predictions, in the epoch's order;
/// masked ones counted.
pub(crate) fn predictions(
    model: &RangeModel,
    e: &RangeEpoch,
    a: &Antenna,
) -> (Vec<(usize, crate::gnss::Predicted)>, u64) {
    let mut masked = 0;
    let mut out = Vec::with_capacity(e.sats.len());
    for (i, s) in e.sats.iter().enumerate() {
        match model.predict(s, e.time, &a.r_e, &a.v_e) {
            Some(p) => out.push((i, p)),
            None => masked += 1,
        }
    }
    (out, masked)
}

impl super::GnssFix {
    /// A single-point solution as a fix at time `t` (the run's clock): its position,
    /// the standard deviations of its covariance turned to north, east, down
    /// (`P_n = C_en P_e C_enᵀ`, diagonal), and its Doppler velocity likewise when it
    /// has one. The start of a tightly coupled run (`--init gnss`) takes these.
    pub fn from_spp(sol: &crate::gnss::SppSolution, t: f64) -> Self {
        let g = sol.geodetic;
        let c_en = crate::earth::c_ne(g.lat, g.lon).transpose();
        let std_ned = |p_e: Matrix3<f64>| (c_en * p_e * c_en.transpose()).diagonal().map(f64::sqrt);
        let p_e: Matrix3<f64> = sol.cov.fixed_view::<3, 3>(0, 0).into_owned();
        let vel = sol
            .v_e
            .zip(sol.cov_velocity)
            .map(|(v_e, p)| (c_en * v_e, std_ned(p.fixed_view::<3, 3>(0, 0).into_owned())));
        Self {
            t,
            pos: g,
            pos_std: std_ned(p_e),
            vel,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_of_odd_even_and_empty_sets() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&mut []), None);
    }
}
