//! Self-calibration: the GNSS antenna's lever arm and the GNSS-to-IMU time offset as
//! states of the error-state filter.
//!
//! - Lever arm `l` (body axes): the residual `δl = l − l̂` (fed back into
//!   [`super::SensorEstimates::lever_arm`], as the sensor biases), constant.
//! - Time offset `τ`: a GNSS measurement stamped `t` describes the IMU's instant
//!   `t + τ` (`t_imu = t_gnss + τ`). The filter applies it when the IMU reaches
//!   `t + τ̂` (the configured offset plus the estimate), so only the residual
//!   `δτ = τ − τ̂` is linearised: a prior of seconds costs no accuracy. A constant, or a
//!   random walk for a drifting clock.
//!
//! Any GNSS measurement (position, velocity, pseudorange, rate) predicts from the
//! antenna's position `r_a = r + Ĉ_cb l̂` and velocity `v_a = v + Ĉ_cb (ω_eb × l̂)`
//! through its position columns `H_r` and velocity columns `H_v` ([`super::measurement`],
//! [`super::ranging`]; `z` = predicted − measured), so the two calibrations add, for all
//! four alike,
//!
//! - `H_l = −(H_r Ĉ_cb + H_v Ĉ_cb [ω_eb×])` (the measured antenna sits at `l̂ + δl`),
//! - `H_τ = −(H_r v_a + H_v a)` (the measurement is of the instant `t + τ̂ + δτ`,
//!   `x(t + τ̂ + δτ) ≈ x(t + τ̂) + ẋ δτ`),
//!
//! with `a = Ĉ_cb f + g − (2ω_ie + ρ) × v` the acceleration relative to the Earth in `c`
//! (the antenna's angular acceleration term `Ĉ_cb (ω̇ × l)` is left out: at most mm/s²
//! per rad/s² and metre). A measurement applied a time `g = (t + τ̂) − t_now` away from
//! its instant (after the estimate moved back past a fix already due) has its
//! prediction carried there, `z += (H_r v_a + H_v a) g + H_r a g²/2`.
//!
//! While the offset's σ is wide, the linear model misses `½ h_ττ δτ²` (the turn's
//! entry or the braking that the next second of prior holds); its variance is added
//! to the measurement's noise, the truncated second-order filter's term
//! ([`add_second_order_noise`]).
//!
//! The offset's column is left out of a row whose rate `H_r v_a + H_v a` is within
//! three of its own standard deviations (from the covariance of `δv` and of the
//! acceleration error `f^c × ψ + Ĉ_cb δb_a`, and the specific force's noise): the
//! filter drops the product of two errors `δa δτ`, which dominates there (at rest, a
//! tilt error's 0.02 m/s² against none), and the offset would wander with the noise
//! while nothing observes it, far enough for the first acceleration to be beyond the
//! linear model.
//! (Groves 2013 §14.2.1 for the lever arm; the time-offset state as in visual–inertial
//! calibration, Li & Mourikis 2014.)

use super::layout::Layout;
use super::measurement::Measurement;
use crate::nav::FrameSnapshot;
use crate::rotation::skew;
use nalgebra::{DMatrix, Matrix3, RowVector3, Vector3};

/// Which calibrations the filter estimates, with their priors.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Calibration {
    /// Estimate the antenna lever arm (from the configured one): prior standard
    /// deviation per body axis [m].
    pub lever_arm_std: Option<f64>,
    /// Estimate the GNSS time offset (from the configured one): prior standard
    /// deviation [s].
    pub time_offset_std: Option<f64>,
    /// Random-walk density of the time offset [s/√s] (0: a constant offset).
    pub time_offset_walk: f64,
}

impl Calibration {
    /// Whether anything is estimated.
    pub fn any(&self) -> bool {
        self.lever_arm_std.is_some() || self.time_offset_std.is_some()
    }
}

/// A calibration estimate's standard deviation above this fraction of its prior's
/// means the motion did not observe it: the estimate is the prior's, not the data's
/// (a state the data observe loses most of its prior: a tenth of it after a handful
/// of turns for a lever arm).
pub const UNOBSERVED_FRACTION: f64 = 0.5;

/// One calibrated quantity at an instant: the value (configured plus estimated), its
/// standard deviation and its prior's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate<T> {
    /// The value.
    pub value: T,
    /// Its standard deviation.
    pub std: T,
    /// The prior standard deviation.
    pub prior_std: f64,
    /// The standard deviation the motion alone gives it ([`Excitation`]).
    pub excited_std: T,
}

fn observed(std: f64, prior: f64, excited: f64) -> bool {
    let bound = UNOBSERVED_FRACTION * prior;
    std < bound && excited < bound
}

impl Estimate<f64> {
    /// Whether the motion observed it: both its standard deviation and the one the
    /// motion alone gives it below [`UNOBSERVED_FRACTION`] of the prior's.
    pub fn observed(&self) -> bool {
        observed(self.std, self.prior_std, self.excited_std)
    }
}

impl Estimate<Vector3<f64>> {
    /// Whether the motion observed each axis.
    pub fn observed(&self) -> [bool; 3] {
        std::array::from_fn(|i| observed(self.std[i], self.prior_std, self.excited_std[i]))
    }
}

/// What the motion showed of each calibration (lever arm x, y, z, time offset): the
/// information `Σ k²/σ²` of the GNSS measurements' sensitivities `k` to it, where the
/// part through the antenna's position counts only by its variation over the run
/// (`Σ w (k − k̄)²` per axis, `w = 1/σ²`), since a constant part is a constant position
/// offset that the position's own error takes as well: a lever arm that never turns,
/// an offset at a constant velocity. The filter's covariance cannot say this (its
/// prior on the position splits such an offset between the two); this can:
/// `1/√info` is the standard deviation the motion alone would give. Ranges (tight
/// coupling) count by their rates' part only (their position part changes with the
/// satellites as much as with the motion).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Excitation {
    /// Per state and position axis: `Σ w`, `Σ w k`, `Σ w k²`.
    position: [[[f64; 3]; 3]; 4],
    /// Per state: `Σ k²/σ²` of the velocity-type parts.
    velocity: [f64; 4],
}

impl Excitation {
    fn add_position(&mut self, state: usize, axis: usize, w: f64, k: f64) {
        let s = &mut self.position[state][axis];
        s[0] += w;
        s[1] += w * k;
        s[2] += w * k * k;
    }

    /// The standard deviation the motion alone gives state `state` (0..3 the lever
    /// arm's axes, 3 the offset), infinite without information.
    pub fn std(&self, state: usize) -> f64 {
        let spread: f64 = self.position[state]
            .iter()
            .filter(|s| s[0] > 0.0)
            .map(|s| (s[2] - s[1] * s[1] / s[0]).max(0.0))
            .sum();
        1.0 / (spread + self.velocity[state]).sqrt()
    }
}

/// The calibration estimates at an instant (`None` for what is not estimated).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CalibrationState {
    /// The antenna lever arm in body axes [m].
    pub lever_arm: Option<Estimate<Vector3<f64>>>,
    /// The GNSS time offset `τ` (`t_imu = t_gnss + τ`) [s].
    pub time_offset: Option<Estimate<f64>>,
}

/// The antenna's kinematics a GNSS measurement is predicted from, in `c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AntennaMotion {
    /// Body to `c`.
    pub c_bc: Matrix3<f64>,
    /// The body's rate relative to the Earth, body axes [rad/s].
    pub w_eb_b: Vector3<f64>,
    /// The antenna's velocity relative to the Earth [m/s].
    pub v_a: Vector3<f64>,
    /// The acceleration relative to the Earth [m/s²].
    pub a: Vector3<f64>,
    /// Covariance of the velocity estimate [m²/s²].
    pub p_v: Matrix3<f64>,
    /// Covariance of the acceleration estimate [m²/s⁴].
    pub p_a: Matrix3<f64>,
    /// The acceleration's rate of change over the last GNSS interval [m/s³]
    /// ([`JerkMemory`]).
    pub jerk: Vector3<f64>,
    /// The variance of the time offset's residual `δτ` [s²] (zero when not estimated).
    pub tau_var: f64,
}

/// The acceleration at the last GNSS epoch, for the rate of change the second-order
/// term of the time offset needs (module doc): `j = (a − a₀)/(t − t₀)` over the last
/// interval of half a second or more, zero after a gap of more than [`Self::SPAN`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct JerkMemory {
    last: Option<(f64, Vector3<f64>)>,
    jerk: Vector3<f64>,
}

impl JerkMemory {
    /// The longest interval a difference is taken over [s].
    const SPAN: f64 = 3.0;

    /// Remember the acceleration `a` at `t` (when half a second or more has passed
    /// since the last) and give the current rate of change.
    pub fn update(&mut self, t: f64, a: &Vector3<f64>) -> Vector3<f64> {
        let since = self.last.map_or(f64::INFINITY, |(t0, _)| t - t0);
        if since >= 0.5 {
            self.jerk = match self.last {
                Some((t0, a0)) if since <= Self::SPAN => (a - a0) / (t - t0),
                _ => Vector3::zeros(),
            };
            self.last = Some((t, *a));
        }
        self.jerk
    }
}

impl AntennaMotion {
    /// From the frame, the compensated rate `w_ib_b` and specific force `f_ib_b` of
    /// the last sample and the variance of its specific force per axis `f_var`
    /// [m²/s⁴], the lever arm `lever` (body axes) and the filter's covariance `p`.
    pub fn of(
        frame: &FrameSnapshot,
        w_ib_b: &Vector3<f64>,
        f_ib_b: &Vector3<f64>,
        f_var: f64,
        lever: &Vector3<f64>,
        p: &DMatrix<f64>,
    ) -> Self {
        let antenna = super::ranging::Antenna::of(frame, lever, w_ib_b);
        let c_bc = antenna.c_bc;
        let g_c = Vector3::new(0.0, 0.0, frame.gravity);
        let f_c = c_bc * f_ib_b;
        let a = f_c + g_c - (2.0 * frame.w_ie_c + frame.rho_c).cross(&frame.v_c);
        let block = |o: usize| p.fixed_view::<3, 3>(o, o).into_owned();
        let f_x = skew(&f_c);
        let p_a = f_x * block(Layout::ATT) * f_x.transpose()
            + c_bc * block(Layout::ACCEL_BIAS) * c_bc.transpose()
            + Matrix3::from_diagonal_element(f_var);
        Self {
            c_bc,
            w_eb_b: antenna.w_eb_b,
            v_a: frame.v_c + antenna.lever_v_c,
            a,
            p_v: block(Layout::VEL),
            p_a,
            jerk: Vector3::zeros(),
            tau_var: 0.0,
        }
    }
}

/// The truncated second-order filter's noise for the offset (Gelb 1974 §6.1): the
/// measurement's second derivative in `τ`, `h_ττ = H_r a + H_v j`, adds
/// `½ h_ττ h_ττᵀ σ_τ⁴` to its covariance. While `σ_τ` is wide (a prior of seconds)
/// this is what the linear model misses across a turn's entry or a braking (at 1 s
/// and 2.5 m/s³, 1.2 m/s), and without it an accurate velocity fix pulls the offset
/// to a wrong minimum; once `σ_τ` is a few milliseconds it is nothing.
fn add_second_order_noise(m: &mut Measurement, k: &AntennaMotion) {
    let rows = m.z.len();
    let h_tt = nalgebra::DVector::from_fn(rows, |row, _| {
        (columns(&m.h, row, Layout::POS) * k.a + columns(&m.h, row, Layout::VEL) * k.jerk)[0]
    });
    m.r += &h_tt * h_tt.transpose() * (0.5 * k.tau_var * k.tau_var);
}

fn columns(h: &DMatrix<f64>, row: usize, at: usize) -> RowVector3<f64> {
    RowVector3::new(h[(row, at)], h[(row, at + 1)], h[(row, at + 2)])
}

/// Add the calibration columns to GNSS measurement `m` (module doc), carry its
/// prediction over the gap `gap` [s] from now to its instant, and count what it shows
/// of the calibrations into `seen`.
pub(crate) fn add_columns(
    m: &mut Measurement,
    layout: &Layout,
    k: &AntennaMotion,
    gap: f64,
    seen: &mut Excitation,
) {
    let lever_v = k.c_bc * skew(&k.w_eb_b);
    if layout.time_offset.is_some() {
        add_second_order_noise(m, k);
    }
    for row in 0..m.z.len() {
        let h_r = columns(&m.h, row, Layout::POS);
        let h_v = columns(&m.h, row, Layout::VEL);
        // A position fix: its three axes as rows (a velocity fix has no position part;
        // a range one row of its own direction).
        let axes = m.z.len() == 3 && h_r != RowVector3::zeros();
        let w = 1.0 / m.r[(row, row)];
        let rate = (h_r * k.v_a + h_v * k.a)[0];
        if gap != 0.0 {
            m.z[row] += rate * gap + 0.5 * (h_r * k.a)[0] * gap * gap;
        }
        if let Some(o) = layout.lever_arm {
            let (by_pos, by_vel) = (-(h_r * k.c_bc), -(h_v * lever_v));
            m.h.fixed_view_mut::<1, 3>(row, o)
                .copy_from(&(by_pos + by_vel));
            for i in 0..3 {
                if axes {
                    seen.add_position(i, row, w, by_pos[i]);
                }
                seen.velocity[i] += w * by_vel[i] * by_vel[i];
            }
        }
        if let Some(o) = layout.time_offset {
            let var = (h_r * k.p_v * h_r.transpose() + h_v * k.p_a * h_v.transpose())[0];
            if rate * rate > 9.0 * var {
                m.h[(row, o)] = -rate;
                let (by_pos, by_vel) = ((h_r * k.v_a)[0], (h_v * k.a)[0]);
                if axes {
                    seen.add_position(3, row, w, by_pos);
                }
                seen.velocity[3] += w * by_vel * by_vel;
            } else {
                m.h[(row, o)] = 0.0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{EarthModel, Geodetic, Wgs84};
    use crate::filter::measurement::{gnss_position, gnss_velocity};
    use nalgebra::UnitQuaternion;

    fn frame() -> FrameSnapshot {
        let pos = Geodetic::new(0.7, 0.2, 100.0);
        let c_ne = crate::earth::c_ne(pos.lat, pos.lon);
        FrameSnapshot {
            t: 0.0,
            c_ce_to_e: c_ne,
            r_e: Wgs84.geodetic_to_ecef(&pos),
            v_c: Vector3::new(12.0, -5.0, 0.3),
            q_bc: UnitQuaternion::from_euler_angles(0.05, -0.08, 1.1),
            w_ie_c: Vector3::new(5.6e-5, 0.0, -4.7e-5),
            rho_c: Vector3::new(-1e-6, -2e-6, 0.0),
            gravity: 9.80,
            radius: 6.37e6,
        }
    }

    /// The lever-arm columns are the derivative of the innovations with respect to the
    /// residual `δl`: moving the predicted lever arm by `d` moves `δl` by `−d`, so the
    /// innovations change by `−H_l d`. Checked by finite differences: both models are
    /// linear in `l`, so they agree to rounding (1e-8 m for a 1-cm step on a 6.4e6-m
    /// ECEF position).
    #[test]
    fn lever_columns_are_the_models_derivative() {
        let f = frame();
        let layout = Layout::core().with_lever_arm().with_time_offset();
        let fix = Geodetic::new(0.7, 0.2, 101.0);
        let std = Vector3::repeat(1.0);
        let w_ib = Vector3::new(0.1, -0.2, 0.3);
        let f_ib = Vector3::new(0.5, 0.4, -9.7);
        let l0 = Vector3::new(0.8, -0.3, -1.2);
        let v_ned = Vector3::new(11.0, -4.0, 0.2);
        let z = |l: &Vector3<f64>| {
            let p = gnss_position(&Wgs84, &layout, &f, &fix, &std, l);
            let v = gnss_velocity(&layout, &f, &fix, &v_ned, &std, l, &w_ib);
            (p, v)
        };
        let (mut p, mut v) = z(&l0);
        let cov = DMatrix::zeros(layout.n, layout.n);
        let k = AntennaMotion::of(&f, &w_ib, &f_ib, 0.0, &l0, &cov);
        add_columns(&mut p, &layout, &k, 0.0, &mut Excitation::default());
        add_columns(&mut v, &layout, &k, 0.0, &mut Excitation::default());
        let o = layout.lever_arm.unwrap();
        for axis in 0..3 {
            let d = Vector3::ith(axis, 0.01);
            let (p1, v1) = z(&(l0 + d));
            // The predicted lever arm moved by d: the residual δl = l − l̂ moved by −d.
            for (m0, m1, tol) in [(&p, &p1, 1e-8), (&v, &v1, 1e-12)] {
                for r in 0..3 {
                    let dz = m1.z[r] - m0.z[r];
                    assert!(
                        (dz - m0.h[(r, o + axis)] * -0.01).abs() < tol,
                        "axis {axis} row {r}: {dz} against {}",
                        m0.h[(r, o + axis)] * -0.01
                    );
                }
            }
        }
    }

    /// The time-offset column of a position is minus the antenna's velocity, of a
    /// velocity minus the acceleration `Ĉ_cb f + g − (2ω_ie + ρ) × v`; a gap carries
    /// the predicted position by `v_a g + a g²/2` (a constant-acceleration step, exact).
    #[test]
    fn time_columns_and_gap() {
        let f = frame();
        let layout = Layout::core().with_time_offset();
        let fix = Geodetic::new(0.7, 0.2, 101.0);
        let std = Vector3::repeat(1.0);
        let w_ib = Vector3::new(0.0, 0.0, 0.3);
        let f_ib = Vector3::new(1.5, 0.4, -9.7);
        let lever = Vector3::new(1.0, 0.0, 0.0);
        let cov = DMatrix::zeros(layout.n, layout.n);
        let k = AntennaMotion::of(&f, &w_ib, &f_ib, 0.0, &lever, &cov);
        let mut p = gnss_position(&Wgs84, &layout, &f, &fix, &std, &lever);
        let z0 = p.z.clone();
        add_columns(&mut p, &layout, &k, -0.5, &mut Excitation::default());
        let o = layout.time_offset.unwrap();
        for r in 0..3 {
            assert_eq!(p.h[(r, o)], -k.v_a[r]);
            let carried = z0[r] - 0.5 * k.v_a[r] + 0.125 * k.a[r];
            assert!((p.z[r] - carried).abs() < 1e-12);
        }
        // The antenna 1 m ahead turning at 0.3 rad/s moves 0.3 m/s sideways.
        let c_bc = f.q_bc.to_rotation_matrix().into_inner();
        let side = c_bc.transpose() * (k.v_a - f.v_c);
        assert!((side.y - 0.3).abs() < 1e-4, "{side}");
        let mut v = gnss_velocity(&layout, &f, &fix, &f.v_c, &std, &lever, &w_ib);
        add_columns(&mut v, &layout, &k, 0.0, &mut Excitation::default());
        let g = Vector3::new(0.0, 0.0, 9.80);
        let a = c_bc * f_ib + g - (2.0 * f.w_ie_c + f.rho_c).cross(&f.v_c);
        for r in 0..3 {
            assert_eq!(v.h[(r, o)], -a[r]);
        }
    }

    /// The second-order noise is the variance of the term the linear model drops: for
    /// a position, `½ a δτ²` with `δτ ~ N(0, σ²)` has variance `¼ a aᵀ (3σ⁴ − σ⁴)` =
    /// `½ a aᵀ σ⁴` (Gaussian fourth moment); for a velocity the same with the jerk.
    #[test]
    fn second_order_noise_is_the_dropped_terms_variance() {
        let f = frame();
        let layout = Layout::core().with_time_offset();
        let fix = Geodetic::new(0.7, 0.2, 101.0);
        let std = Vector3::repeat(1.0);
        let w_ib = Vector3::new(0.0, 0.0, 0.3);
        let f_ib = Vector3::new(1.5, 0.4, -9.7);
        let cov = DMatrix::zeros(layout.n, layout.n);
        let mut k = AntennaMotion::of(&f, &w_ib, &f_ib, 0.0, &Vector3::zeros(), &cov);
        k.jerk = Vector3::new(2.0, -1.0, 0.5);
        k.tau_var = 0.25;
        let sigma4 = k.tau_var * k.tau_var;
        let mut p = gnss_position(&Wgs84, &layout, &f, &fix, &std, &Vector3::zeros());
        let r0 = p.r.clone();
        add_columns(&mut p, &layout, &k, 0.0, &mut Excitation::default());
        let mut v = gnss_velocity(&layout, &f, &fix, &f.v_c, &std, &Vector3::zeros(), &w_ib);
        add_columns(&mut v, &layout, &k, 0.0, &mut Excitation::default());
        // The fixes' rows are in `c` with unit position and velocity columns.
        for (m, d2) in [(&p, k.a), (&v, k.jerk)] {
            let added = &m.r - &r0;
            for i in 0..3 {
                for j in 0..3 {
                    let want = 0.5 * d2[i] * d2[j] * sigma4;
                    assert!(
                        (added[(i, j)] - want).abs() < 1e-9 * (1.0 + want.abs()),
                        "{i}{j}"
                    );
                }
            }
        }
    }

    /// The jerk is the acceleration's difference over the last interval of half a
    /// second or more, kept between; nothing after a gap.
    #[test]
    fn jerk_memory() {
        let mut j = JerkMemory::default();
        let a = |t: f64| Vector3::new(1.0 + 2.0 * t, -t, 0.0);
        assert_eq!(j.update(0.0, &a(0.0)), Vector3::zeros());
        assert_eq!(j.update(1.0, &a(1.0)), Vector3::new(2.0, -1.0, 0.0));
        // The velocity fix of the same epoch sees the same jerk.
        assert_eq!(
            j.update(1.0, &Vector3::zeros()),
            Vector3::new(2.0, -1.0, 0.0)
        );
        assert_eq!(j.update(5.0, &a(5.0)), Vector3::zeros());
    }
}
