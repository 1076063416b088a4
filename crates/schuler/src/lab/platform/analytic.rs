//! Analytic INS (lecture 22, (22.15)): the accelerometers on a platform stabilized in
//! inertial space (both trihedra fixed, `ω1 = ω2 = 0`), so the navigation equation is
//! (22.1) in the inertial frame, `d²r/dt² = n + g(r)`, with the gravitation computed
//! from the computed position (22.2). Nothing is level: the vertical is found
//! analytically, by the computer, which is what makes the system Schuler tuned (the
//! gravitation computed at a position in error turns towards the true one at
//! `ω0² = mu/r³` per metre).
//!
//! Simulation: the platform's true attitude drifts at the gyro drift
//! (`dC_pi/dt = C_pi [ε ×]`); the accelerometers read `C_ip^T n_i + b`; the computer
//! takes platform axes as inertial. The gimbal angles give `C_pb`, so the computed
//! body attitude is `C_bi = C_pb`.

use super::inertial::{aid_vertical, gravitation_i, inertial_from_truth, nav_state};
use super::sensors::Sensors;
use super::truth::{TruthPoint, c_ei};
use super::{OdeState, TruthDriven, VerticalChannel, leveling, quat_rate, rk4, unit};
use crate::earth::{EarthModel, c_ne};
use crate::nav::NavState;
use nalgebra::{Quaternion, Rotation3, Unit, UnitQuaternion, Vector3};

#[derive(Debug, Clone, Copy)]
struct State {
    /// True platform-to-inertial rotation `C_pi`.
    q_pi: Quaternion<f64>,
    r_i: Vector3<f64>,
    v_i: Vector3<f64>,
}

impl OdeState for State {
    fn plus(&self, d: &Self, h: f64) -> Self {
        Self {
            q_pi: self.q_pi + d.q_pi * h,
            r_i: self.r_i + d.r_i * h,
            v_i: self.v_i + d.v_i * h,
        }
    }
}

/// The analytic INS over an Earth model.
#[derive(Debug)]
pub struct AnalyticIns<E: EarthModel> {
    earth: E,
    sensors: Sensors,
    vertical: VerticalChannel,
    t0: f64,
    x: State,
}

impl<E: EarthModel> AnalyticIns<E> {
    /// An analytic INS starting at the truth `start`, platform along the inertial
    /// axes (tilted by the leveling when `leveled`, see [`leveling`]).
    pub fn new(
        earth: E,
        sensors: impl Into<Sensors>,
        vertical: VerticalChannel,
        leveled: bool,
        start: &TruthPoint,
    ) -> Self {
        let sensors = sensors.into();
        let t0 = start.state.t;
        let (r_i, v_i) = inertial_from_truth(&earth, t0, start);
        let c_pi = if leveled {
            // At t0 the inertial axes are ECEF's.
            let down = c_ne(start.state.pos.lat, start.state.pos.lon)
                .column(2)
                .into_owned();
            leveling(
                &start.f_e,
                &sensors.initial_accel_bias(),
                &Unit::new_normalize(down),
            )
        } else {
            Rotation3::identity()
        };
        let q_pi = UnitQuaternion::from_rotation_matrix(&c_pi).into_inner();
        Self {
            earth,
            sensors,
            vertical,
            t0,
            x: State { q_pi, r_i, v_i },
        }
    }

    /// True specific force in the platform's axes.
    fn specific_force(&self, x: &State, truth: &TruthPoint) -> Vector3<f64> {
        let c_pi = unit(&x.q_pi).to_rotation_matrix().into_inner();
        c_pi.transpose() * (c_ei(self.earth.rotation_rate(), truth.state.t, self.t0) * truth.f_e)
    }

    /// The derivative with gyro error `e_w` (platform drift) and accelerometer error
    /// `e_f`.
    fn derivative(
        &self,
        x: &State,
        truth: &TruthPoint,
        e_w: &Vector3<f64>,
        e_f: &Vector3<f64>,
    ) -> State {
        let t = truth.state.t;
        let f_p = self.specific_force(x, truth) + e_f;
        State {
            q_pi: quat_rate(&x.q_pi, e_w),
            r_i: x.v_i,
            v_i: f_p + gravitation_i(&self.earth, t, self.t0, &x.r_i),
        }
    }
}

impl<E: EarthModel> TruthDriven for AnalyticIns<E> {
    fn step(&mut self, a: &TruthPoint, m: &TruthPoint, c: &TruthPoint) {
        let dt = c.state.t - a.state.t;
        let nodes = [a, m, c];
        // The gyros hold the platform still: their input is (ideally) zero.
        let (e_w, e_f) = self.sensors.step(
            c.state.t,
            dt,
            &Vector3::zeros(),
            &self.specific_force(&self.x, a),
        );
        let mut x = rk4(&self.x, dt, |k, x| self.derivative(x, nodes[k], &e_w, &e_f));
        x.q_pi = unit(&x.q_pi).into_inner();
        if self.vertical == VerticalChannel::TrueHeight {
            (x.r_i, x.v_i) = aid_vertical(&self.earth, self.t0, c, &x.r_i, &x.v_i);
        }
        self.x = x;
    }

    fn state(&self, truth: &TruthPoint) -> NavState {
        let t = truth.state.t;
        let c_pi = unit(&self.x.q_pi).to_rotation_matrix().into_inner();
        let c_ib = c_ei(self.earth.rotation_rate(), t, self.t0) * truth.c_be;
        // Gimbal angles: C_pb; the computer takes platform axes as inertial.
        let c_bi = c_pi.transpose() * c_ib;
        nav_state(&self.earth, t, self.t0, &self.x.r_i, &self.x.v_i, &c_bi)
    }
}
