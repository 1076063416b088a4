//! Gyro-free INS on six single-axis accelerometers on a rigid base (lecture 22,
//! (22.18)–(22.21)).
//!
//! An accelerometer at lever `r_k` (body axes, from the reference point O1) with
//! sensing axis `u_k` reads the specific force of its own point,
//! `m_k = u_k · (f + ω̇ × r_k + ω × (ω × r_k) − ΔG_k)`, where `f` is the specific force
//! at O1 and `ΔG_k = G(R1 + r_k) − G(R1)` the difference of gravitation between the two
//! points: (22.18)–(22.19) written for the two points with `R2 = R1 + ρ` (22.20) and
//! the gravitation of each from its own position (22.21). Given the computed `ω`, the
//! six readings are linear in the six unknowns `(f, ω̇)`:
//! `m_k − u_k · (ω × (ω × r_k) − ΔG_k) = u_k · f + (r_k × u_k) · ω̇`,
//! solvable when the 6×6 matrix of rows `[u_k^T, (r_k × u_k)^T]` is regular. Then `ω`
//! is the integral of `ω̇` from its known initial value, the attitude follows from `ω`
//! (Poisson's equation (22.4)), and the navigation is (22.1) in the inertial frame.
//!
//! **The lecture's literal layout is singular.** Two parallel triads separated by `ρ`
//! give rows `[e_j, 0]` and `[e_j, (ρ × e_j)]`: the vectors `ρ × e_j` span only the
//! plane normal to `ρ`, so the rank is 5 and the angular acceleration about `ρ` is
//! unobservable (a rotation about the line through both triads moves neither point).
//! [`AccelerometerArray::parallel_triads`] reports this.
//!
//! **Nor is every regular layout usable.** The centripetal terms make the computed
//! `ω̇` depend on the computed `ω` unless they cancel in the solve; where they do not,
//! the rate error obeys a linearized Euler equation, `δω̇ ≈ −∂(ω × (ω × r))/∂ω δω`,
//! which grows like `exp(|ω| t)` from round-off alone. The simplest fix of the lecture's
//! layout, [`AccelerometerArray::triad_and_offsets`] (a triad at O1 and each
//! accelerometer of the second, parallel to the first, on its own arm `ρ`, so that
//! `ω̇_z = (m − f_y)/ρ − ω_x ω_y`), has this flaw (test
//! `triad_and_offsets_diverges_under_rotation`). The layout used,
//! [`AccelerometerArray::cube`] (Chen, Lee & DeBra 1994: one accelerometer at the centre
//! of each face of a cube, distance `ρ` from the centre O1, sensing along a face
//! diagonal, the diagonals of opposite faces crossed), cancels them: `ω̇` is a fixed
//! combination of the readings, `ω̇ = Σ ±m_k/(2√2 ρ)`, and only the estimate of `f`
//! carries centripetal terms.
//!
//! **Error growth.** A difference error `d` on a baseline `ρ` is an angular
//! acceleration error `ε = d/ρ` (in the cube, a bias `d` on both accelerometers of the
//! `±y` faces is the difference `√2 d` along their common axis over the baseline `2ρ`:
//! `ε = d/(√2 ρ)` about `x`): a rate error `ε t` and an attitude error `ε t²/2`. For
//! a horizontal axis this is a gyro drift growing linearly in time, which the Schuler
//! loop (SEEDS.md (13) with `ν = ε t`: `α'' + ω0² α = ε`) turns into the tilt
//! `α = (ε/ω0²)(1 − cos ω0t)` and the position error
//! `Δr = −(g ε/ω0²) (t²/2 − (1 − cos ω0t)/ω0²)`, which is `−g ε t⁴/24` while
//! `t ≪ T0` and `−a ε t²/2` beyond (test `gyro_free_error_growth_law`).

use super::inertial::{aid_vertical, gravitation_i, inertial_from_truth, nav_state};
use super::truth::{TruthPoint, c_ei};
use super::{OdeState, TruthDriven, VerticalChannel, level_rotation, quat_rate, rk4, unit};
use crate::earth::{EarthModel, c_ne};
use crate::nav::NavState;
use nalgebra::{Matrix3, Matrix6, Quaternion, Rotation3, Unit, UnitQuaternion, Vector3, Vector6};

/// Why an accelerometer array cannot serve as a gyro-free INS.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GyroFreeError {
    /// The readings do not determine `(f, ω̇)`.
    #[error(
        "the six accelerometers do not determine the specific force and angular acceleration: rank {rank} of 6 (smallest singular value {smallest:e} of largest {largest:e}){hint}"
    )]
    Singular {
        /// Numerical rank of the measurement matrix.
        rank: usize,
        /// Smallest singular value.
        smallest: f64,
        /// Largest singular value.
        largest: f64,
        /// Explanation for a known layout.
        hint: &'static str,
    },
    /// A baseline or axis that is zero or not finite.
    #[error("baseline and axes must be finite and non-zero")]
    BadGeometry,
}

/// Six single-axis accelerometers on a rigid base, positions and axes in body axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccelerometerArray {
    /// Levers from the reference point O1 [m].
    pub positions: [Vector3<f64>; 6],
    /// Unit sensing axes.
    pub axes: [Unit<Vector3<f64>>; 6],
    /// Inverse of the measurement matrix (rows `[u_k^T, (r_k × u_k)^T]`).
    h_inv: Matrix6<f64>,
}

/// Relative singular-value threshold below which the array is rank deficient.
const RANK_TOLERANCE: f64 = 1e-9;

impl AccelerometerArray {
    /// An array from positions and axes; an error if the readings cannot be solved.
    pub fn new(
        positions: [Vector3<f64>; 6],
        axes: [Unit<Vector3<f64>>; 6],
    ) -> Result<Self, GyroFreeError> {
        Self::with_hint(positions, axes, "")
    }

    fn with_hint(
        positions: [Vector3<f64>; 6],
        axes: [Unit<Vector3<f64>>; 6],
        hint: &'static str,
    ) -> Result<Self, GyroFreeError> {
        if positions.iter().any(|p| !p.iter().all(|x| x.is_finite()))
            || axes.iter().any(|u| !u.iter().all(|x| x.is_finite()))
        {
            return Err(GyroFreeError::BadGeometry);
        }
        let h = Matrix6::from_fn(|k, j| {
            if j < 3 {
                axes[k][j]
            } else {
                positions[k].cross(&axes[k])[j - 3]
            }
        });
        let sv = h.singular_values();
        let largest = sv.max();
        let smallest = sv.min();
        // Not `smallest > tol` also catches NaN.
        if smallest.partial_cmp(&(RANK_TOLERANCE * largest)) != Some(std::cmp::Ordering::Greater) {
            let rank = sv.iter().filter(|&&s| s > RANK_TOLERANCE * largest).count();
            return Err(GyroFreeError::Singular {
                rank,
                smallest,
                largest,
                hint,
            });
        }
        let h_inv = h.try_inverse().ok_or(GyroFreeError::Singular {
            rank: 5,
            smallest,
            largest,
            hint,
        })?;
        Ok(Self {
            positions,
            axes,
            h_inv,
        })
    }

    /// The lecture's literal layout: a triad at O1 and a parallel triad at `rho`.
    /// Always an error (rank 5): rotation about `rho` moves neither triad.
    pub fn parallel_triads(rho: Vector3<f64>) -> Result<Self, GyroFreeError> {
        let e = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()];
        Self::with_hint(
            [
                Vector3::zeros(),
                Vector3::zeros(),
                Vector3::zeros(),
                rho,
                rho,
                rho,
            ],
            [e[0], e[1], e[2], e[0], e[1], e[2]],
            ": two parallel triads leave the angular acceleration about their baseline unobservable",
        )
    }

    /// A triad at O1 and three accelerometers parallel to its axes on three arms of
    /// length `rho` [m]: at `rho x` along `y`, at `rho y` along `z`, at `rho z` along `x`.
    pub fn triad_and_offsets(rho: f64) -> Result<Self, GyroFreeError> {
        if !(rho.is_finite() && rho > 0.0) {
            return Err(GyroFreeError::BadGeometry);
        }
        let e = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()];
        Self::new(
            [
                Vector3::zeros(),
                Vector3::zeros(),
                Vector3::zeros(),
                Vector3::x() * rho,
                Vector3::y() * rho,
                Vector3::z() * rho,
            ],
            [e[0], e[1], e[2], e[1], e[2], e[0]],
        )
    }

    /// Six accelerometers at the face centres `±rho e_i` of a cube (Chen, Lee & DeBra
    /// 1994), each sensing along a face diagonal `(e_j ± e_k)/√2`, `+` on the positive
    /// face and `−` on the negative one: `ω̇` needs no `ω` (see the module doc).
    pub fn cube(rho: f64) -> Result<Self, GyroFreeError> {
        if !(rho.is_finite() && rho > 0.0) {
            return Err(GyroFreeError::BadGeometry);
        }
        let e = [Vector3::x(), Vector3::y(), Vector3::z()];
        let mut positions = [Vector3::zeros(); 6];
        let mut axes = [Vector3::x_axis(); 6];
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let (lo, hi) = (j.min(k), j.max(k));
            for (n, sign) in [(2 * i, 1.0), (2 * i + 1, -1.0)] {
                positions[n] = e[i] * (sign * rho);
                axes[n] = Unit::new_normalize(e[lo] + e[hi] * sign);
            }
        }
        Self::new(positions, axes)
    }

    /// The readings for specific force `f_b` at O1, angular rate `w_b`, angular
    /// acceleration `dw_b` and gravitation differences `dg_b[k] = G(R1 + r_k) − G(R1)`,
    /// all in body axes.
    pub fn readings(
        &self,
        f_b: &Vector3<f64>,
        w_b: &Vector3<f64>,
        dw_b: &Vector3<f64>,
        dg_b: &[Vector3<f64>; 6],
    ) -> Vector6<f64> {
        Vector6::from_fn(|k, _| {
            let r = &self.positions[k];
            let f_k = f_b + dw_b.cross(r) + w_b.cross(&w_b.cross(r)) - dg_b[k];
            self.axes[k].dot(&f_k)
        })
    }

    /// Specific force at O1 and angular acceleration from six readings, given the
    /// computed angular rate and gravitation differences.
    pub fn solve(
        &self,
        m: &Vector6<f64>,
        w_b: &Vector3<f64>,
        dg_b: &[Vector3<f64>; 6],
    ) -> (Vector3<f64>, Vector3<f64>) {
        let y = Vector6::from_fn(|k, _| {
            let r = &self.positions[k];
            m[k] - self.axes[k].dot(&(w_b.cross(&w_b.cross(r)) - dg_b[k]))
        });
        let x = self.h_inv * y;
        (
            x.fixed_rows::<3>(0).into_owned(),
            x.fixed_rows::<3>(3).into_owned(),
        )
    }
}

/// Gravitation differences `G(R1 + r_k) − G(R1)` in body axes, for inertial position
/// `r_i` and attitude `C_bi`.
fn gravitation_differences<E: EarthModel>(
    earth: &E,
    t: f64,
    t0: f64,
    array: &AccelerometerArray,
    r_i: &Vector3<f64>,
    c_bi: &Matrix3<f64>,
) -> [Vector3<f64>; 6] {
    let g1 = gravitation_i(earth, t, t0, r_i);
    std::array::from_fn(|k| {
        let p = &array.positions[k];
        if p.norm_squared() == 0.0 {
            return Vector3::zeros();
        }
        c_bi.transpose() * (gravitation_i(earth, t, t0, &(r_i + c_bi * p)) - g1)
    })
}

#[derive(Debug, Clone, Copy)]
struct State {
    /// Computed body-to-inertial rotation `C_bi`.
    q_bi: Quaternion<f64>,
    /// Computed angular rate, body axes.
    w_b: Vector3<f64>,
    r_i: Vector3<f64>,
    v_i: Vector3<f64>,
}

impl OdeState for State {
    fn plus(&self, d: &Self, h: f64) -> Self {
        Self {
            q_bi: self.q_bi + d.q_bi * h,
            w_b: self.w_b + d.w_b * h,
            r_i: self.r_i + d.r_i * h,
            v_i: self.v_i + d.v_i * h,
        }
    }
}

/// The gyro-free INS over an Earth model.
#[derive(Debug, Clone)]
pub struct GyroFreeIns<E: EarthModel> {
    earth: E,
    array: AccelerometerArray,
    /// Bias of each accelerometer [m/s^2].
    biases: Vector6<f64>,
    vertical: VerticalChannel,
    t0: f64,
    x: State,
}

impl<E: EarthModel> GyroFreeIns<E> {
    /// A gyro-free INS starting at the truth `start` with the true initial angular rate
    /// (known at the start, e.g. Earth rate at rest) and, when `leveled`, an initial
    /// attitude leveled on the biased triad at O1 (the first three accelerometers of
    /// `array`; [`level_rotation`]).
    pub fn new(
        earth: E,
        array: AccelerometerArray,
        biases: Vector6<f64>,
        vertical: VerticalChannel,
        leveled: bool,
        start: &TruthPoint,
    ) -> Self {
        let t0 = start.state.t;
        let (r_i, v_i) = inertial_from_truth(&earth, t0, start);
        let mut c_bi = start.c_be;
        if leveled {
            // The triad's bias, resolved with the true attitude (at t0, i = e).
            let b_b = Vector3::from_fn(|j, _| {
                (0..3)
                    .find(|&k| array.positions[k] == Vector3::zeros() && array.axes[k][j] == 1.0)
                    .map_or(0.0, |k| biases[k])
            });
            let down = c_ne(start.state.pos.lat, start.state.pos.lon)
                .column(2)
                .into_owned();
            let r = level_rotation(
                &(start.f_e + start.c_be * b_b),
                &start.f_e,
                &Unit::new_normalize(down),
            );
            c_bi = r.into_inner() * c_bi;
        }
        let q_bi = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_bi))
            .into_inner();
        Self {
            earth,
            array,
            biases,
            vertical,
            t0,
            x: State {
                q_bi,
                w_b: start.w_ib_b,
                r_i,
                v_i,
            },
        }
    }

    /// What the six accelerometers read at the truth `p` (biases included).
    fn measure(&self, p: &TruthPoint) -> Vector6<f64> {
        let t = p.state.t;
        let (r_i, _) = inertial_from_truth(&self.earth, self.t0, p);
        let c_bi = c_ei(self.earth.rotation_rate(), t, self.t0) * p.c_be;
        let dg = gravitation_differences(&self.earth, t, self.t0, &self.array, &r_i, &c_bi);
        self.array.readings(&p.f_b(), &p.w_ib_b, &p.dw_ib_b, &dg) + self.biases
    }

    fn derivative(&self, x: &State, t: f64, m: &Vector6<f64>) -> State {
        let c_bi = unit(&x.q_bi).to_rotation_matrix().into_inner();
        let dg = gravitation_differences(&self.earth, t, self.t0, &self.array, &x.r_i, &c_bi);
        let (f_b, dw_b) = self.array.solve(m, &x.w_b, &dg);
        State {
            q_bi: quat_rate(&x.q_bi, &x.w_b),
            w_b: dw_b,
            r_i: x.v_i,
            v_i: c_bi * f_b + gravitation_i(&self.earth, t, self.t0, &x.r_i),
        }
    }

    /// The computed angular rate, body axes [rad/s].
    pub fn angular_rate(&self) -> Vector3<f64> {
        self.x.w_b
    }
}

impl<E: EarthModel> TruthDriven for GyroFreeIns<E> {
    fn step(&mut self, a: &TruthPoint, m: &TruthPoint, c: &TruthPoint) {
        let dt = c.state.t - a.state.t;
        let nodes = [a, m, c];
        let reads = nodes.map(|p| self.measure(p));
        let mut x = rk4(&self.x, dt, |k, x| {
            self.derivative(x, nodes[k].state.t, &reads[k])
        });
        x.q_bi = unit(&x.q_bi).into_inner();
        if self.vertical == VerticalChannel::TrueHeight {
            (x.r_i, x.v_i) = aid_vertical(&self.earth, self.t0, c, &x.r_i, &x.v_i);
        }
        self.x = x;
    }

    fn state(&self, truth: &TruthPoint) -> NavState {
        let c_bi = unit(&self.x.q_bi).to_rotation_matrix().into_inner();
        nav_state(
            &self.earth,
            truth.state.t,
            self.t0,
            &self.x.r_i,
            &self.x.v_i,
            &c_bi,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lecture's two parallel triads are rank 5 whatever the baseline's direction;
    /// the triad-and-offsets array is regular and its solve inverts its readings.
    #[test]
    fn parallel_triads_are_singular_and_offsets_are_not() {
        for rho in [Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.3, -0.5, 0.8)] {
            match AccelerometerArray::parallel_triads(rho) {
                Err(GyroFreeError::Singular { rank, .. }) => assert_eq!(rank, 5),
                other => panic!("expected rank 5, got {other:?}"),
            }
        }
        let a = AccelerometerArray::triad_and_offsets(0.5).expect("regular");
        let f = Vector3::new(0.3, -0.2, -9.8);
        let w = Vector3::new(0.1, -0.4, 0.25);
        let dw = Vector3::new(-0.7, 0.05, 1.1);
        let dg: [Vector3<f64>; 6] = std::array::from_fn(|k| a.positions[k] * 1.5e-6);
        let m = a.readings(&f, &w, &dw, &dg);
        let (f2, dw2) = a.solve(&m, &w, &dg);
        assert!((f2 - f).norm() < 1e-14 && (dw2 - dw).norm() < 1e-14);
        // Triad and offsets: one accelerometer's error d is d/rho in one component.
        let mut m_err = m;
        m_err[4] += 1e-3;
        let (_, dw_err) = a.solve(&m_err, &w, &dg);
        assert!((dw_err - dw - Vector3::new(1e-3 / 0.5, 0.0, 0.0)).norm() < 1e-14);

        let c = AccelerometerArray::cube(0.5).expect("regular");
        let dg: [Vector3<f64>; 6] = std::array::from_fn(|k| c.positions[k] * 1.5e-6);
        let m = c.readings(&f, &w, &dw, &dg);
        let (f2, dw2) = c.solve(&m, &w, &dg);
        assert!((f2 - f).norm() < 1e-13 && (dw2 - dw).norm() < 1e-13);
        // The cube's angular acceleration does not depend on the computed rate.
        let (_, dw_wrong_rate) = c.solve(&m, &(w * 3.0), &dg);
        assert!((dw_wrong_rate - dw).norm() < 1e-13);
        // Biases d on the two +-y accelerometers: d/(sqrt2 rho) about x.
        let mut m_err = m;
        m_err[2] += 1e-3;
        m_err[3] += 1e-3;
        let (_, dw_err) = c.solve(&m_err, &w, &dg);
        let expect = Vector3::new(1e-3 / (2f64.sqrt() * 0.5), 0.0, 0.0);
        assert!((dw_err - dw - expect).norm() < 1e-13, "{}", dw_err - dw);
    }
}
