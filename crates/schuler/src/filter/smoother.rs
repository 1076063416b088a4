//! Rauch–Tung–Striebel smoothing of the closed-loop error-state filter.
//!
//! The forward filter feeds its estimate back at once, so its error estimate is zero
//! after every epoch `k`; what it leaves behind are the covariances `P_k|k`,
//! `P_k+1|k`, the transition `Φ_k` and the feedback `δx_k` applied at `t_k` (which
//! moved the nominal state from its pre-update to its post-update value). Relative to
//! the post-update nominal, the smoothed error obeys (Rauch, Tung & Striebel 1965, in
//! the indirect form of e.g. Groves 2013 §3.4.2):
//!
//! `s_N = 0`, `s_k = C_k (s_{k+1} + δx_{k+1})`, `C_k = P_k|k Φ_kᵀ P_k+1|k⁻¹`,
//! `P^s_k = P_k|k + C_k (P^s_{k+1} − P_k+1|k) C_kᵀ`.
//!
//! Between epochs the nominal runs freely from the post-update state at `t_k` to the
//! pre-update state at `t_{k+1}`, and its smoothed error is interpolated linearly
//! between `s_k` and `s_{k+1} + δx_{k+1}`.
//!
//! What the forward pass leaves grows with the log (10.8 kB per epoch of the 21-state
//! filter, 176 bytes per output instant), so it goes through [`spill::Records`]: kept
//! in memory up to a budget, then in a temporary file. The backward pass reads the
//! epochs from the last and keeps per epoch only what the outputs need (`s_k`,
//! `s_k + δx_k` and the standard deviations of `P^s_k`); the smoothed outputs are then
//! computed one at a time as [`SmoothedTrajectory`] is read, so a 10-h 1-kHz log
//! smooths in bounded memory.

use super::integration::SensorEstimates;
use super::layout::Layout;
use super::spill::{self, Records, Sequence, SpillError};
use crate::earth::EarthModel;
use crate::nav::frame::{corrected_ecef_of, nav_state_from_ecef};
use crate::nav::{FrameSnapshot, NavErrors, NavState};
use nalgebra::{DMatrix, DVector, Quaternion, UnitQuaternion, Vector3};

/// The epoch still open: what the forward pass leaves for it so far.
#[derive(Debug, Clone, PartialEq)]
struct Epoch {
    t: f64,
    p_post: DMatrix<f64>,
    dx: DVector<f64>,
    /// Transition to the next epoch and the predicted covariance there.
    next: Option<(DMatrix<f64>, DMatrix<f64>)>,
}

/// Values of a stored epoch of dimension `n`: `t, δx (n), has next, P_k|k, Φ_k,
/// P_k+1|k` (column-major `n×n` each).
const fn epoch_width(n: usize) -> usize {
    2 + n + 3 * n * n
}

/// Values of a stored output instant: `t, C_ec (9, column-major), r_e (3), v_c (3),
/// q_bc (i, j, k, w), epoch index, estimates index`.
const OUTPUT_WIDTH: usize = 22;

impl Epoch {
    fn record(&self, out: &mut Vec<f64>) {
        let n = self.dx.len();
        out.clear();
        out.push(self.t);
        out.extend(self.dx.iter());
        out.push(if self.next.is_some() { 1.0 } else { 0.0 });
        out.extend(self.p_post.iter());
        match &self.next {
            Some((phi, p_pred)) => {
                out.extend(phi.iter());
                out.extend(p_pred.iter());
            }
            None => out.resize(epoch_width(n), 0.0),
        }
    }

    fn from_record(r: &[f64], n: usize) -> Self {
        let nn = n * n;
        let m = |o: usize| DMatrix::from_column_slice(n, n, &r[o..o + nn]);
        let o = 2 + n;
        Self {
            t: r[0],
            dx: DVector::from_column_slice(&r[1..1 + n]),
            p_post: m(o),
            next: (r[1 + n] != 0.0).then(|| (m(o + nn), m(o + 2 * nn))),
        }
    }
}

/// The values of `e`'s fields as bits (so that `-0.0` and `0.0` differ).
fn bits(e: &SensorEstimates) -> [u64; 21] {
    let mut b = [0u64; 21];
    let v = [
        &e.gyro_bias,
        &e.accel_bias,
        &e.gyro_scale,
        &e.accel_scale,
        &e.mounting,
        &e.lever_arm,
    ];
    for (i, x) in v.iter().flat_map(|v| v.iter()).enumerate() {
        b[i] = x.to_bits();
    }
    b[18] = e.baro_bias.to_bits();
    b[19] = e.odometer_scale.to_bits();
    b[20] = e.gnss_time_offset.to_bits();
    b
}

/// The forward pass's record for smoothing.
#[derive(Debug, Clone)]
pub struct SmootherLog {
    dim: usize,
    budget: usize,
    /// The epoch still open (the last).
    open: Option<Epoch>,
    /// The epochs before it.
    closed: Records,
    outputs: Records,
    /// Sensor-error estimates, a new entry each time an output sees them changed.
    estimates: Vec<SensorEstimates>,
    scratch: Vec<f64>,
}

impl Default for SmootherLog {
    fn default() -> Self {
        Self::with_budget(spill::DEFAULT_BUDGET)
    }
}

/// A smoothed output epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Smoothed {
    /// Navigation state (NED).
    pub state: NavState,
    /// Sensor errors.
    pub estimates: SensorEstimates,
    /// Standard deviations of position, velocity (in `c`, m and m/s) and attitude
    /// error (rad), from the smoothed covariance of the nearest epoch.
    pub std: [Vector3<f64>; 3],
}

impl SmootherLog {
    /// A log keeping about `budget` values of each kind in memory before spilling.
    pub fn with_budget(budget: usize) -> Self {
        Self {
            dim: 0,
            budget,
            open: None,
            closed: Records::new(1, budget),
            outputs: Records::new(OUTPUT_WIDTH, budget),
            estimates: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// Open the first epoch at `t` with covariance `p`.
    pub fn start(&mut self, t: f64, p: &DMatrix<f64>) {
        self.dim = p.nrows();
        self.closed = Records::new(epoch_width(self.dim), self.budget);
        self.open = Some(Epoch {
            t,
            p_post: p.clone(),
            dx: DVector::zeros(p.nrows()),
            next: None,
        });
    }

    /// The filter fed `dx` back at the current epoch; `p` is the covariance after.
    pub fn feedback(&mut self, dx: &DVector<f64>, p: &DMatrix<f64>) {
        if let Some(e) = self.open.as_mut() {
            e.dx += dx;
            e.p_post.copy_from(p);
        }
    }

    /// The filter propagated from the current epoch to `t` with `phi`, reaching `p_pred`.
    pub fn propagated(
        &mut self,
        t: f64,
        p_post: &DMatrix<f64>,
        phi: DMatrix<f64>,
        p_pred: &DMatrix<f64>,
    ) {
        if let Some(mut e) = self.open.take() {
            e.p_post.copy_from(p_post);
            e.next = Some((phi, p_pred.clone()));
            e.record(&mut self.scratch);
            self.closed.push(&self.scratch);
        }
        self.open = Some(Epoch {
            t,
            p_post: p_pred.clone(),
            dx: DVector::zeros(p_pred.nrows()),
            next: None,
        });
    }

    /// Record an output instant.
    pub fn output(&mut self, frame: FrameSnapshot, estimates: SensorEstimates) {
        let epoch = self.epochs().saturating_sub(1);
        if self.estimates.last().map(bits) != Some(bits(&estimates)) {
            self.estimates.push(estimates);
        }
        let f = &frame;
        let mut r = [0.0; OUTPUT_WIDTH];
        r[0] = f.t;
        r[1..10].copy_from_slice(f.c_ce_to_e.as_slice());
        r[10..13].copy_from_slice(f.r_e.as_slice());
        r[13..16].copy_from_slice(f.v_c.as_slice());
        r[16..20].copy_from_slice(f.q_bc.as_ref().coords.as_slice());
        r[20] = epoch as f64;
        r[21] = (self.estimates.len() - 1) as f64;
        self.outputs.push(&r);
    }

    /// Number of filter epochs recorded.
    pub fn epochs(&self) -> usize {
        self.closed.len() + usize::from(self.open.is_some())
    }

    /// Epoch `k` (the open one last).
    fn epoch(&self, k: usize, buf: &mut [f64]) -> Result<Epoch, SpillError> {
        if k == self.closed.len()
            && let Some(e) = &self.open
        {
            return Ok(e.clone());
        }
        self.closed.read(k, buf)?;
        Ok(Epoch::from_record(buf, self.dim))
    }

    /// The backward pass: the smoothed states at every recorded output instant, to be
    /// read in order.
    pub fn smooth(self, layout: &Layout) -> Result<SmoothedTrajectory, SpillError> {
        let n = self.epochs();
        let dim = self.dim;
        let mut backward = Backward::new(dim, n);
        let mut buf = vec![0.0; self.closed.width()];
        if n > 0 {
            let last = self.epoch(n - 1, &mut buf)?;
            let mut ps_next = last.p_post.clone();
            let mut s_next = DVector::zeros(dim);
            backward.set(n - 1, last.t, &s_next, &last.dx, &ps_next);
            let mut dx_next = last.dx;
            for k in (0..n - 1).rev() {
                let e = self.epoch(k, &mut buf)?;
                let (s, ps) = rts_step(&e, &s_next, &dx_next, &ps_next);
                backward.set(k, e.t, &s, &e.dx, &ps);
                (s_next, ps_next, dx_next) = (s, ps, e.dx);
            }
        }
        // Without an epoch (a log never started) there is nothing to smooth.
        let outputs = match n {
            0 => Records::new(OUTPUT_WIDTH, 0),
            _ => self.outputs,
        };
        Ok(SmoothedTrajectory {
            layout: *layout,
            backward,
            estimates: self.estimates,
            remaining: outputs.len(),
            outputs: outputs.into_sequence()?,
        })
    }
}

/// One step of the backward recursion at epoch `e` (module doc), from the smoothed
/// error `s_next` and covariance `ps_next` of the next epoch and its feedback
/// `dx_next`: `(s_k, P^s_k)`.
fn rts_step(
    e: &Epoch,
    s_next: &DVector<f64>,
    dx_next: &DVector<f64>,
    ps_next: &DMatrix<f64>,
) -> (DVector<f64>, DMatrix<f64>) {
    let dim = e.dx.len();
    let Some((phi, p_pred)) = &e.next else {
        return (DVector::zeros(dim), e.p_post.clone());
    };
    // C = P Φᵀ P_pred⁻¹, from P_pred C ᵀ = Φ P (both symmetric).
    let Some(chol) = p_pred.clone().cholesky() else {
        return (DVector::zeros(dim), e.p_post.clone());
    };
    let c = chol.solve(&(phi * &e.p_post)).transpose();
    let target = s_next + dx_next;
    let s = &c * target;
    let p = &e.p_post + &c * (ps_next - p_pred) * c.transpose();
    (s, (&p + p.transpose()) * 0.5)
}

/// What the output pass needs of each epoch after the backward pass: `t`, `s_k`,
/// `s_k + δx_k` and the standard deviations of position, velocity and attitude of
/// `P^s_k`.
#[derive(Debug, Clone)]
struct Backward {
    dim: usize,
    values: Vec<f64>,
}

impl Backward {
    fn new(dim: usize, epochs: usize) -> Self {
        Self {
            dim,
            values: vec![0.0; epochs * (1 + 2 * dim + 9)],
        }
    }

    fn width(&self) -> usize {
        1 + 2 * self.dim + 9
    }

    fn set(&mut self, k: usize, t: f64, s: &DVector<f64>, dx: &DVector<f64>, ps: &DMatrix<f64>) {
        let (w, n) = (self.width(), self.dim);
        let r = &mut self.values[k * w..(k + 1) * w];
        r[0] = t;
        r[1..1 + n].copy_from_slice(s.as_slice());
        r[1 + n..1 + 2 * n].copy_from_slice((s + dx).as_slice());
        for (i, o) in [Layout::POS, Layout::VEL, Layout::ATT]
            .into_iter()
            .enumerate()
        {
            let std = super::kalman::std3(ps, o);
            r[1 + 2 * n + 3 * i..1 + 2 * n + 3 * i + 3].copy_from_slice(std.as_slice());
        }
    }

    fn epochs(&self) -> usize {
        self.values.len() / self.width()
    }

    fn t(&self, k: usize) -> f64 {
        self.values[k * self.width()]
    }

    /// `s_k` (`plus_dx`: `s_k + δx_k`).
    fn s(&self, k: usize, plus_dx: bool) -> DVector<f64> {
        let o = k * self.width() + 1 + if plus_dx { self.dim } else { 0 };
        DVector::from_column_slice(&self.values[o..o + self.dim])
    }

    fn std(&self, k: usize) -> [Vector3<f64>; 3] {
        let o = k * self.width() + 1 + 2 * self.dim;
        let v = |i: usize| Vector3::from_column_slice(&self.values[o + 3 * i..o + 3 * i + 3]);
        [v(0), v(1), v(2)]
    }
}

/// The smoothed trajectory, computed one output instant at a time as it is read.
#[derive(Debug)]
pub struct SmoothedTrajectory {
    layout: Layout,
    backward: Backward,
    estimates: Vec<SensorEstimates>,
    outputs: Sequence,
    remaining: usize,
}

impl SmoothedTrajectory {
    /// Output instants not read yet.
    pub fn len(&self) -> usize {
        self.remaining
    }

    /// Whether every output instant was read.
    pub fn is_empty(&self) -> bool {
        self.remaining == 0
    }

    /// The next smoothed output epoch on `earth` (`None` after the last).
    pub fn next_on<E: EarthModel>(&mut self, earth: &E) -> Option<Result<Smoothed, SpillError>> {
        let mut r = [0.0; OUTPUT_WIDTH];
        match self.outputs.next_into(&mut r) {
            Ok(true) => {
                self.remaining -= 1;
                Some(Ok(self.at(earth, &r)))
            }
            Ok(false) => None,
            Err(e) => {
                self.remaining = 0;
                Some(Err(e))
            }
        }
    }

    /// Every smoothed output epoch on `earth`, in time order.
    pub fn states<E: EarthModel>(
        mut self,
        earth: E,
    ) -> impl Iterator<Item = Result<Smoothed, SpillError>> {
        std::iter::from_fn(move || self.next_on(&earth))
    }

    /// Every smoothed output epoch on `earth`, in memory.
    pub fn collect_states<E: EarthModel>(self, earth: E) -> Result<Vec<Smoothed>, SpillError> {
        self.states(earth).collect()
    }

    /// The smoothed state of stored output `r` (module doc).
    fn at<E: EarthModel>(&self, earth: &E, r: &[f64; OUTPUT_WIDTH]) -> Smoothed {
        let t = r[0];
        let k = r[20] as usize;
        let b = &self.backward;
        let n = b.epochs();
        let (err, std) = if t <= b.t(k) + 1e-9 || k + 1 >= n {
            (b.s(k, false), b.std(k))
        } else {
            let a = ((t - b.t(k)) / (b.t(k + 1) - b.t(k))).clamp(0.0, 1.0);
            let pre = b.s(k + 1, true);
            (
                b.s(k, false) * (1.0 - a) + pre * a,
                if a < 0.5 { b.std(k) } else { b.std(k + 1) },
            )
        };
        let v3 = |o: usize| Vector3::new(err[o], err[o + 1], err[o + 2]);
        let errors = NavErrors {
            dr: v3(Layout::POS),
            dv: v3(Layout::VEL),
            psi: v3(Layout::ATT),
        };
        let c_ec = nalgebra::Matrix3::from_column_slice(&r[1..10]);
        let r_e = Vector3::from_column_slice(&r[10..13]);
        let v_c = Vector3::from_column_slice(&r[13..16]);
        let q_bc = UnitQuaternion::new_unchecked(Quaternion::new(r[19], r[16], r[17], r[18]));
        let (pos, vel, q) = corrected_ecef_of(&c_ec, &r_e, &v_c, &q_bc, &errors);
        let est = self.corrected(self.estimates[r[21] as usize], &err);
        Smoothed {
            state: nav_state_from_ecef(earth, t, &pos, &vel, &q),
            estimates: est,
            std,
        }
    }

    /// The sensor errors `est` with the smoothed error `err` removed.
    fn corrected(&self, mut est: SensorEstimates, err: &DVector<f64>) -> SensorEstimates {
        let layout = &self.layout;
        let v3 = |o: usize| Vector3::new(err[o], err[o + 1], err[o + 2]);
        est.gyro_bias += v3(Layout::GYRO_BIAS);
        est.accel_bias += v3(Layout::ACCEL_BIAS);
        if let Some(g) = layout.gyro_scale {
            est.gyro_scale += v3(g);
        }
        if let Some(a) = layout.accel_scale {
            est.accel_scale += v3(a);
        }
        if let Some(b) = layout.baro_bias {
            est.baro_bias += err[b];
        }
        if let Some(o) = layout.odometer_scale {
            est.odometer_scale += err[o];
        }
        if let Some(o) = layout.mounting {
            est.mounting += Vector3::new(0.0, err[o], err[o + 1]);
        }
        if let Some(o) = layout.lever_arm {
            est.lever_arm += v3(o);
        }
        if let Some(o) = layout.time_offset {
            est.gnss_time_offset += err[o];
        }
        est
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{Geodetic, Wgs84};
    use crate::nav::LocalLevel;
    use crate::nav::frame::ErrorFrame;
    use crate::rotation::Euler;

    /// A forward pass's record of 40 epochs (propagations with a transition that
    /// couples the states, feedbacks at every third) and 7 outputs per epoch, on a
    /// log that keeps at most `budget` values in memory.
    fn record(budget: usize) -> SmootherLog {
        let layout = Layout::core();
        let n = layout.n;
        let state = NavState::new(
            0.0,
            Geodetic::from_degrees(45.0, 7.0, 300.0),
            Vector3::new(10.0, -3.0, 0.5),
            Euler::new(0.01, -0.02, 1.0),
        );
        let mech = LocalLevel::new(Wgs84, state);
        let mut log = SmootherLog::with_budget(budget);
        let mut p = DMatrix::<f64>::identity(n, n);
        log.start(0.0, &p);
        let phi = DMatrix::from_fn(n, n, |i, j| match (i, j) {
            _ if i == j => 1.0,
            _ if j == i + 3 => 0.1,
            _ => 0.0,
        });
        for k in 0..40 {
            for m in 0..7 {
                let mut frame = mech.frame();
                frame.t = k as f64 + m as f64 / 7.0;
                frame.r_e.x += frame.t;
                let estimates = SensorEstimates {
                    baro_bias: (k / 3) as f64,
                    ..SensorEstimates::default()
                };
                log.output(frame, estimates);
            }
            let pred = &phi * &p * phi.transpose() + DMatrix::identity(n, n) * 0.01;
            log.propagated(k as f64 + 1.0, &p, phi.clone(), &pred);
            p = pred;
            if k % 3 == 0 {
                p *= 0.5;
                let dx = DVector::from_fn(n, |i, _| 1e-3 * (i as f64 - k as f64));
                log.feedback(&dx, &p);
            }
        }
        log
    }

    #[test]
    fn outputs_without_an_epoch_smooth_to_nothing() {
        let mut log = SmootherLog::default();
        let state = NavState::new(
            0.0,
            Geodetic::from_degrees(45.0, 7.0, 300.0),
            Vector3::zeros(),
            Euler::new(0.0, 0.0, 0.0),
        );
        let mech = LocalLevel::new(Wgs84, state);
        log.output(mech.frame(), SensorEstimates::default());
        let smoothed = log.smooth(&Layout::core()).expect("smooth");
        assert!(smoothed.is_empty());
        assert_eq!(smoothed.collect_states(Wgs84).expect("states").len(), 0);
    }

    #[test]
    fn a_spilled_record_smooths_bit_for_bit_as_one_in_memory() {
        let layout = Layout::core();
        let in_memory = record(usize::MAX)
            .smooth(&layout)
            .expect("smooth")
            .collect_states(Wgs84)
            .expect("states");
        assert_eq!(in_memory.len(), 280);
        // A budget of one value: every epoch and output goes through the file; a
        // clone of the log (its own file) must give the same too.
        let log = record(1);
        assert_eq!(log.closed.len(), 40);
        for spilled in [log.clone(), log] {
            let states = spilled
                .smooth(&layout)
                .expect("smooth")
                .collect_states(Wgs84)
                .expect("states");
            assert_eq!(states.len(), in_memory.len());
            for (a, b) in states.iter().zip(&in_memory) {
                let bits = |s: &Smoothed| {
                    let q = s.state.q_bn.as_ref().coords;
                    [
                        s.state.t,
                        s.state.pos.lat,
                        s.state.pos.lon,
                        s.state.pos.h,
                        s.state.v_n.x,
                        s.state.v_n.y,
                        s.state.v_n.z,
                        q.x,
                        q.y,
                        q.z,
                        q.w,
                        s.estimates.gyro_bias.x,
                        s.estimates.baro_bias,
                        s.std[0].x,
                        s.std[1].y,
                        s.std[2].z,
                    ]
                    .map(f64::to_bits)
                };
                assert_eq!(bits(a), bits(b), "at t = {}", a.state.t);
            }
        }
    }
}
