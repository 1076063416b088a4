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

use super::integration::SensorEstimates;
use super::layout::Layout;
use crate::earth::EarthModel;
use crate::nav::frame::{corrected_ecef, nav_state_from_ecef};
use crate::nav::{FrameSnapshot, NavErrors, NavState};
use nalgebra::{DMatrix, DVector, Vector3};

/// What the forward pass leaves for one epoch.
#[derive(Debug, Clone, PartialEq)]
struct Epoch {
    t: f64,
    p_post: DMatrix<f64>,
    dx: DVector<f64>,
    /// Transition to the next epoch and the predicted covariance there.
    next: Option<(DMatrix<f64>, DMatrix<f64>)>,
}

/// One output instant of the forward pass.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Output {
    frame: FrameSnapshot,
    estimates: SensorEstimates,
    /// Index of the epoch open at that time.
    epoch: usize,
}

/// The forward pass's record for smoothing.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SmootherLog {
    epochs: Vec<Epoch>,
    outputs: Vec<Output>,
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
    /// Open the first epoch at `t` with covariance `p`.
    pub fn start(&mut self, t: f64, p: &DMatrix<f64>) {
        self.epochs.push(Epoch {
            t,
            p_post: p.clone(),
            dx: DVector::zeros(p.nrows()),
            next: None,
        });
    }

    /// The filter fed `dx` back at the current epoch; `p` is the covariance after.
    pub fn feedback(&mut self, dx: &DVector<f64>, p: &DMatrix<f64>) {
        if let Some(e) = self.epochs.last_mut() {
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
        if let Some(e) = self.epochs.last_mut() {
            e.p_post.copy_from(p_post);
            e.next = Some((phi, p_pred.clone()));
        }
        self.epochs.push(Epoch {
            t,
            p_post: p_pred.clone(),
            dx: DVector::zeros(p_pred.nrows()),
            next: None,
        });
    }

    /// Record an output instant.
    pub fn output(&mut self, frame: FrameSnapshot, estimates: SensorEstimates) {
        let epoch = self.epochs.len().saturating_sub(1);
        self.outputs.push(Output {
            frame,
            estimates,
            epoch,
        });
    }

    /// Number of filter epochs recorded.
    pub fn epochs(&self) -> usize {
        self.epochs.len()
    }

    /// The backward pass: smoothed states at every recorded output instant.
    pub fn smooth<E: EarthModel>(&self, earth: &E, layout: &Layout) -> Vec<Smoothed> {
        let n = self.epochs.len();
        if n == 0 {
            return Vec::new();
        }
        let dim = self.epochs[0].p_post.nrows();
        let mut s = vec![DVector::zeros(dim); n];
        let mut ps = vec![DMatrix::zeros(dim, dim); n];
        ps[n - 1] = self.epochs[n - 1].p_post.clone();
        for k in (0..n - 1).rev() {
            let e = &self.epochs[k];
            let Some((phi, p_pred)) = &e.next else {
                s[k] = DVector::zeros(dim);
                ps[k] = e.p_post.clone();
                continue;
            };
            // C = P Φᵀ P_pred⁻¹, from P_pred C ᵀ = Φ P (both symmetric).
            let Some(chol) = p_pred.clone().cholesky() else {
                ps[k] = e.p_post.clone();
                continue;
            };
            let c = chol.solve(&(phi * &e.p_post)).transpose();
            let target = &s[k + 1] + &self.epochs[k + 1].dx;
            s[k] = &c * target;
            let p = &e.p_post + &c * (&ps[k + 1] - p_pred) * c.transpose();
            ps[k] = (&p + p.transpose()) * 0.5;
        }
        self.outputs
            .iter()
            .map(|o| {
                let k = o.epoch;
                let t = o.frame.t;
                let e = &self.epochs[k];
                let (err, p) = if t <= e.t + 1e-9 || k + 1 >= n {
                    (s[k].clone(), &ps[k])
                } else {
                    let next = &self.epochs[k + 1];
                    let a = ((t - e.t) / (next.t - e.t)).clamp(0.0, 1.0);
                    let pre = &s[k + 1] + &next.dx;
                    (
                        &s[k] * (1.0 - a) + pre * a,
                        if a < 0.5 { &ps[k] } else { &ps[k + 1] },
                    )
                };
                let v3 = |o: usize| Vector3::new(err[o], err[o + 1], err[o + 2]);
                let std3 = |o: usize| super::kalman::std3(p, o);
                let errors = NavErrors {
                    dr: v3(Layout::POS),
                    dv: v3(Layout::VEL),
                    psi: v3(Layout::ATT),
                };
                let (r, v, q) = corrected_ecef(&o.frame, &errors);
                let mut est = o.estimates;
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
                Smoothed {
                    state: nav_state_from_ecef(earth, t, &r, &v, &q),
                    estimates: est,
                    std: [std3(Layout::POS), std3(Layout::VEL), std3(Layout::ATT)],
                }
            })
            .collect()
    }
}
