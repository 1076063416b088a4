//! Fine alignment on a base at rest: an error-state Kalman filter on the invariants
//! of seed 003 — the base does not move and the Earth's rotation is known.
//!
//! The NED mechanization runs from the coarse attitude with the sensor biases
//! estimated so far removed; every window of `T` seconds the filter (states of
//! [`crate::filter::error_model`] plus the attitude error at the start, 18 in all)
//! takes three observations and feeds its estimate back:
//!
//! - unchanged position: `C_ce (r̂^e − r₀^e) = δr + v`;
//! - zero velocity, as the window mean (robust to vibration):
//!   `mean v̂ = δv(t) − (T/2) δv̇(t) + v`, with `δv̇` the velocity rows of `F x`;
//! - the Earth-rate invariant on the integrated gyro output: the mechanization turns
//!   the body by the gyro increments minus the Earth's rotation, so on a base at rest
//!   its attitude must not change: `rotvec(Ĉ_cb(t) Ĉ_cb(t₀)ᵀ) = −ψ(t) + ψ(t₀) + v`.
//!
//! What a base at rest cannot separate stays at its prior: the horizontal
//! accelerometer biases (indistinguishable from tilt) and the east gyro bias
//! (indistinguishable from heading); the report says which states the data reduced.

use crate::earth::{EarthModel, Geodetic};
use crate::filter::interval::Interval;
use crate::filter::{ErrorModel, Gate, ImuNoise, Kalman, Layout};
use crate::imu::ImuSample;
use crate::nav::{ErrorFrame, LocalLevel, Mechanization, NavErrors, NavState};
use crate::rotation::{
    Euler, quaternion_from_rotation_vector, rotation_vector_from_quaternion, wrap_pi,
};
use nalgebra::{DMatrix, DVector, Matrix3, UnitQuaternion, Vector3};

/// Measurement noise of the fine alignment's observations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FineConfig {
    /// Measurement window [s].
    pub window: f64,
    /// How still the base's position is [m].
    pub position_std: f64,
    /// How still the base's window-mean velocity is [m/s].
    pub velocity_std: f64,
    /// How still the base's attitude is [rad].
    pub attitude_std: f64,
}

/// One point of the convergence history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convergence {
    /// Time [s].
    pub t: f64,
    /// Standard deviations of roll, pitch, yaw [rad].
    pub attitude_std: Vector3<f64>,
    /// Standard deviations of the gyro biases [rad/s].
    pub gyro_bias_std: Vector3<f64>,
    /// Standard deviations of the accelerometer biases [m/s^2].
    pub accel_bias_std: Vector3<f64>,
}

/// The result of the fine alignment.
#[derive(Debug, Clone, PartialEq)]
pub struct FineAlignment {
    /// Attitude at the end, body to NED.
    pub q_bn: UnitQuaternion<f64>,
    /// The filter's estimate of the attitude at its start (the reference attitude
    /// state, corrected window by window from the coarse attitude it began with).
    pub q_start: UnitQuaternion<f64>,
    /// End time [s].
    pub t_end: f64,
    /// Estimated gyro biases [rad/s].
    pub gyro_bias: Vector3<f64>,
    /// Estimated accelerometer biases [m/s^2].
    pub accel_bias: Vector3<f64>,
    /// Final covariance (layout [`Layout::core`] plus the reference attitude).
    pub covariance: DMatrix<f64>,
    /// Prior standard deviations, per state.
    pub prior_std: Vec<f64>,
    /// History at each window.
    pub convergence: Vec<Convergence>,
}

/// Covariance of roll, pitch, yaw from the covariance of `ψ` (`C = exp(ψ×) Ĉ`), through
/// the Jacobian of the Euler angles (central differences).
pub fn euler_covariance(q_bn: &UnitQuaternion<f64>, p_psi: &Matrix3<f64>) -> Matrix3<f64> {
    let mut j = Matrix3::zeros();
    let h = 1e-6;
    for i in 0..3 {
        let mut d = Vector3::zeros();
        d[i] = h;
        let plus = Euler::from_quaternion(&(quaternion_from_rotation_vector(&d) * q_bn));
        let minus = Euler::from_quaternion(&(quaternion_from_rotation_vector(&-d) * q_bn));
        j.set_column(
            i,
            &(Vector3::new(
                wrap_pi(plus.roll - minus.roll),
                wrap_pi(plus.pitch - minus.pitch),
                wrap_pi(plus.yaw - minus.yaw),
            ) / (2.0 * h)),
        );
    }
    j * p_psi * j.transpose()
}

fn block3(p: &DMatrix<f64>, r: usize, c: usize) -> Matrix3<f64> {
    p.fixed_view::<3, 3>(r, c).into_owned()
}

fn diag_std(p: &DMatrix<f64>, r: usize) -> Vector3<f64> {
    Vector3::new(p[(r, r)], p[(r + 1, r + 1)], p[(r + 2, r + 2)]).map(|v| v.max(0.0).sqrt())
}

/// Run the fine alignment over `samples` (a base at rest at `pos`), starting at the
/// first sample's start from attitude `q_bn` with prior covariance `prior` (layout
/// [`Layout::core`] + reference attitude; see [`super::prior_covariance`]).
pub fn fine_align<E: EarthModel>(
    earth: E,
    pos: Geodetic,
    samples: &[ImuSample],
    q_bn: UnitQuaternion<f64>,
    prior: DMatrix<f64>,
    noise: &ImuNoise,
    cfg: &FineConfig,
) -> FineAlignment {
    let layout = Layout::core().with_attitude_ref();
    let model = ErrorModel {
        layout,
        noise: *noise,
        baro_bias_walk: 0.0,
        odometer_scale_walk: 0.0,
        clock: Default::default(),
        time_offset_walk: 0.0,
    };
    let r_ref = layout.attitude_ref.unwrap_or(15);
    let t0 = samples.first().map_or(0.0, |s| s.t - s.dt);
    let mut mech = LocalLevel::new(
        earth,
        NavState {
            t: t0,
            pos,
            v_n: Vector3::zeros(),
            q_bn,
        },
    );
    let r0 = earth.geodetic_to_ecef(&pos);
    let mut q_ref = q_bn;
    let (mut bg, mut ba) = (Vector3::zeros(), Vector3::zeros());
    let prior_std: Vec<f64> = (0..layout.n)
        .map(|i| prior[(i, i)].max(0.0).sqrt())
        .collect();
    let mut kf = Kalman::new(prior);
    let mut convergence = Vec::new();

    let mut acc = Interval::default();
    let mut v_prev = Vector3::zeros();
    let gate = Gate::Off;
    let r = DMatrix::from_diagonal(&DVector::from_vec(
        [cfg.position_std; 3]
            .into_iter()
            .chain([cfg.velocity_std; 3])
            .chain([cfg.attitude_std; 3])
            .map(|s| s * s)
            .collect(),
    ));
    for (k, s) in samples.iter().enumerate() {
        let comp = ImuSample {
            dtheta: s.dtheta - bg * s.dt,
            dvel: s.dvel - ba * s.dt,
            ..*s
        };
        let q_before = mech.state().q_bn;
        mech.step(&comp);
        let v = mech.state().v_n;
        acc.add(&comp, &q_before);
        acc.add_velocity(comp.dt, &v_prev, &v);
        v_prev = v;
        let last = k + 1 == samples.len();
        if acc.t < cfg.window - 0.5 * s.dt && !last {
            continue;
        }
        // --- propagate over the window with its mean kinematics ---
        let frame = mech.frame();
        let means = acc.means(frame);
        let f = model.dynamics(&means);
        let (phi, qd) = model.transition(&means);
        kf.predict(&phi, &qd);
        // --- the three invariants ---
        let t_w = acc.t;
        let mut h = DMatrix::zeros(9, layout.n);
        let mut z = DVector::zeros(9);
        let dr = frame.c_ce_to_e.transpose() * (frame.r_e - r0);
        let v_mean = acc.v_dt / t_w;
        let dpsi = rotation_vector_from_quaternion(&(frame.q_bc * q_ref.inverse()));
        z.fixed_rows_mut::<3>(0).copy_from(&dr);
        z.fixed_rows_mut::<3>(3).copy_from(&v_mean);
        z.fixed_rows_mut::<3>(6).copy_from(&dpsi);
        for i in 0..3 {
            h[(i, Layout::POS + i)] = 1.0;
            h[(3 + i, Layout::VEL + i)] = 1.0;
            h[(6 + i, Layout::ATT + i)] = -1.0;
            h[(6 + i, r_ref + i)] = 1.0;
        }
        let lag = f.rows(Layout::VEL, 3) * (0.5 * t_w);
        let mut hv = h.rows_mut(3, 3);
        hv -= lag;
        if let Ok(u) = kf.update(&z, &h, &r, gate) {
            let dx = &u.dx;
            let v3 = |o: usize| Vector3::new(dx[o], dx[o + 1], dx[o + 2]);
            mech.correct(&NavErrors {
                dr: v3(Layout::POS),
                dv: v3(Layout::VEL),
                psi: v3(Layout::ATT),
            });
            bg += v3(Layout::GYRO_BIAS);
            ba += v3(Layout::ACCEL_BIAS);
            q_ref = quaternion_from_rotation_vector(&v3(r_ref)) * q_ref;
            v_prev = mech.state().v_n;
        }
        let q_now = mech.state().q_bn;
        let p_psi = block3(&kf.p, Layout::ATT, Layout::ATT);
        convergence.push(Convergence {
            t: mech.state().t,
            attitude_std: euler_covariance(&q_now, &p_psi)
                .diagonal()
                .map(|v| v.max(0.0).sqrt()),
            gyro_bias_std: diag_std(&kf.p, Layout::GYRO_BIAS),
            accel_bias_std: diag_std(&kf.p, Layout::ACCEL_BIAS),
        });
        acc = Interval::default();
    }
    let end = mech.state();
    FineAlignment {
        q_bn: end.q_bn,
        q_start: q_ref,
        t_end: end.t,
        gyro_bias: bg,
        accel_bias: ba,
        covariance: kf.p,
        prior_std,
        convergence,
    }
}
