//! Vehicle aiding measurements of the error-state filter: zero velocity and zero
//! angular rate at rest, the non-holonomic constraint and odometer speed of a land
//! vehicle, and the heading of a dual-antenna GNSS baseline. Conventions as in
//! [`super::measurement`]: `z = computed − measured = H x + v`, psi-angle errors in
//! the computation frame `c`, `Ĉ_cb = (I − ψ×) C_cb` (`C_cb`: body to `c`), `v̂_c = v_c
//! + δv`, and the compensated angular rate `ω̂_ib = ω_ib + δb_g + diag(ω_ib) δs_g`
//! (the residual gyro bias and scale factor, as in [`super::error_model`]).
//!
//! - Zero velocity (ZUPT) at rest, at the IMU (every point of a body at rest is
//!   still): `z = v̂_c = δv + v`.
//! - Zero angular rate (ZARU) at rest: the body turns with the Earth only, so
//!   `z = ω̂_ib − Ĉ_bc ω_ie^c = δb_g + diag(ω_ib) δs_g + C_bc [ω_ie^c×] ψ + v`
//!   (from `Ĉ_bc = C_bc (I + ψ×)`), with `ω̂_ib` the mean rate over a window at rest.
//! - Vehicle-frame velocity of a point `l` (body axes; a wheel, the rear axle) of a
//!   body whose vehicle frame `v` is turned from the IMU body by the mounting angles
//!   (`C_vb`: body to vehicle): `v_v = C_vb (C_bc v_c + ω_eb × l)`, `ω_eb = ω_ib −
//!   C_bc ω_ie^c`. Perturbed:
//!   `δv_v = C_vb C_bc δv − C_vb (C_bc [v_c×] + [l×] C_bc [ω_ie^c×]) ψ
//!   − C_vb [l×] (δb_g + diag(ω_ib) δs_g)` (the literature writes the same for the
//!   phi-angle error and without the Earth-rate term, below 1e-7 m/s per mrad of
//!   attitude error for a metre-long arm: Dissanayake et al. 2001, IEEE Trans.
//!   Robotics and Automation 17(5); Groves 2013 ch. 15, zero updates and motion
//!   constraints).
//! - Mounting errors: with the vehicle frame assumed at `Ĉ_vb = (I − [μ×]) C_vb` (`μ`
//!   in the vehicle frame), `v̂_v = v_v + [v_v×] μ`; on a forward drive `v_v ≈ (s, 0,
//!   0)` this is `(0, −s μ_z, s μ_y)`: the constraint's lateral row sees the yaw
//!   misalignment, its vertical row the pitch one (the roll one turns the constrained
//!   plane into itself and is not observable, so it is not a state).
//! - Non-holonomic constraint (NHC): a land vehicle's wheels neither slip sideways nor
//!   leave the road, `z = (v̂_v,y, v̂_v,z) − 0`: rows 2 and 3 of `δv_v`.
//! - Odometer speed `s = (1 + k) v_v,x + v` with a scale-factor error `k` (a state
//!   `δk = k − k̂`, the residual like the biases'): the reading corrected by the
//!   estimate, `s / (1 + k̂) = v_v,x (1 + δk / (1 + k̂))`, so
//!   `z = v̂_v,x − s / (1 + k̂) = δv_v,x − (s / (1 + k̂)²) δk + v`.
//! - Dual-antenna heading: the baseline between the antennas has direction `u_b` in
//!   body axes (azimuth `α` and elevation `ε` of the mounting,
//!   `u_b = (cos ε cos α, cos ε sin α, −sin ε)`); in NED `b_n = C_nc Ĉ_cb u_b`,
//!   heading `ψ_b = atan2(b_E, b_N)`, pitch `θ_b = atan2(−b_D, √(b_N² + b_E²))`. With
//!   `δb_c = [b_c×] ψ`, `δψ_b = g_ψᵀ C_nc [b_c×] ψ`, `g_ψ = (−b_E, b_N, 0)/h²`,
//!   `δθ_b = g_θᵀ C_nc [b_c×] ψ`, `g_θ = (b_D b_N / h, b_D b_E / h, −h)` (`h² =
//!   b_N² + b_E²`, `|b| = 1`); the heading innovation is wrapped to (−π, π]. The
//!   measured heading is relative to north at the true position and the computed one
//!   to north at the computed position: the frame's turn between them, `|δr| / R`
//!   (1.6e-7 rad per metre of position error), is neglected against the heading noise.

use super::layout::Layout;
use super::measurement::{Kind, Measurement, c_nc};
use crate::earth::Geodetic;
use crate::nav::FrameSnapshot;
use crate::rotation::{Euler, skew, wrap_pi};
use nalgebra::{DMatrix, DVector, Matrix3, RowVector3, UnitQuaternion, Vector3};

/// How the vehicle frame sits on the IMU, and the point whose velocity the vehicle
/// constrains.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleMount {
    /// Vehicle frame to IMU body, `x_b = q_vb x_v`: the vehicle frame's attitude
    /// relative to the IMU body, as `q_bn` is the body's relative to NED.
    pub q_vb: UnitQuaternion<f64>,
    /// The constraint point (wheel contact, rear-axle centre) in body axes (FRD) [m].
    pub lever: Vector3<f64>,
}

impl VehicleMount {
    /// From the mounting angles (roll, pitch, yaw of the vehicle frame relative to the
    /// IMU body, ZYX as for attitude; all zero when the IMU's axes are the vehicle's
    /// front, right, down) and the constraint point's lever arm.
    pub fn new(angles: Euler, lever: Vector3<f64>) -> Self {
        Self {
            q_vb: angles.to_quaternion(),
            lever,
        }
    }

    /// IMU axes along the vehicle's (zero mounting angles, lever arm zero).
    pub fn aligned() -> Self {
        Self::new(Euler::default(), Vector3::zeros())
    }

    /// The mount with the estimated mounting errors `mu` (rotation vector in the
    /// vehicle frame, `Ĉ_vb = (I − [μ×]) C_vb`) removed: `C_vb ← R(μ) Ĉ_vb`, i.e.
    /// `q_vb ← q_vb ⊗ q(−μ)`.
    pub fn corrected(&self, mu: &Vector3<f64>) -> Self {
        if *mu == Vector3::zeros() {
            return *self;
        }
        Self {
            q_vb: self.q_vb * crate::rotation::quaternion_from_rotation_vector(&-mu),
            ..*self
        }
    }
}

/// The direction of a dual-antenna baseline in body axes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Baseline {
    /// Azimuth of the baseline from the body's front axis towards its right [rad].
    pub yaw: f64,
    /// Elevation of the baseline above the body's front-right plane [rad].
    pub pitch: f64,
}

impl Baseline {
    /// Unit vector `u_b = (cos ε cos α, cos ε sin α, −sin ε)`.
    pub fn unit_b(&self) -> Vector3<f64> {
        let (sa, ca) = self.yaw.sin_cos();
        let (se, ce) = self.pitch.sin_cos();
        Vector3::new(ce * ca, ce * sa, -se)
    }
}

/// One dual-antenna reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingReading {
    /// Time [s].
    pub t: f64,
    /// Heading of the baseline from true north, clockwise [rad].
    pub heading: f64,
    /// Its standard deviation [rad].
    pub heading_std: f64,
    /// Pitch (elevation) of the baseline and its standard deviation [rad], if given.
    pub pitch: Option<(f64, f64)>,
}

fn put_rows<const R: usize>(h: &mut DMatrix<f64>, col: usize, m: &nalgebra::SMatrix<f64, R, 3>) {
    h.fixed_view_mut::<R, 3>(0, col).copy_from(m);
}

fn c_bc(frame: &FrameSnapshot) -> Matrix3<f64> {
    frame.q_bc.to_rotation_matrix().into_inner()
}

/// Zero velocity at rest with standard deviation `std` [m/s] per axis.
pub fn zero_velocity(layout: &Layout, frame: &FrameSnapshot, std: f64) -> Measurement {
    let mut h = DMatrix::zeros(3, layout.n);
    put_rows(&mut h, Layout::VEL, &Matrix3::identity());
    Measurement {
        kind: Kind::ZeroVelocity,
        z: DVector::from_column_slice(frame.v_c.as_slice()),
        h,
        r: DMatrix::from_diagonal_element(3, 3, std * std),
    }
}

/// Zero angular rate relative to the Earth at rest: `w_ib_b` the compensated body
/// rate averaged over the window at rest, `std` [rad/s] per axis.
pub fn zero_rate(
    layout: &Layout,
    frame: &FrameSnapshot,
    w_ib_b: &Vector3<f64>,
    std: f64,
) -> Measurement {
    let c = c_bc(frame);
    let z = w_ib_b - c.transpose() * frame.w_ie_c;
    let mut h = DMatrix::zeros(3, layout.n);
    put_rows(&mut h, Layout::GYRO_BIAS, &Matrix3::identity());
    put_rows(&mut h, Layout::ATT, &(c.transpose() * skew(&frame.w_ie_c)));
    if let Some(o) = layout.gyro_scale {
        put_rows(&mut h, o, &Matrix3::from_diagonal(w_ib_b));
    }
    Measurement {
        kind: Kind::ZeroRate,
        z: DVector::from_column_slice(z.as_slice()),
        h,
        r: DMatrix::from_diagonal_element(3, 3, std * std),
    }
}

/// The vehicle-frame velocity of the mount's constraint point, `v_v`, and its
/// sensitivity to the error state (3 rows), for the compensated body rate `w_ib_b`.
pub fn vehicle_velocity(
    layout: &Layout,
    frame: &FrameSnapshot,
    mount: &VehicleMount,
    w_ib_b: &Vector3<f64>,
) -> (Vector3<f64>, DMatrix<f64>) {
    let c = c_bc(frame);
    let c_vb = mount.q_vb.to_rotation_matrix().into_inner().transpose();
    let w_eb = w_ib_b - c.transpose() * frame.w_ie_c;
    let v_b = c.transpose() * frame.v_c + w_eb.cross(&mount.lever);
    let c_vc = c_vb * c.transpose();
    let l = skew(&mount.lever);
    let mut h = DMatrix::zeros(3, layout.n);
    put_rows(&mut h, Layout::VEL, &c_vc);
    put_rows(
        &mut h,
        Layout::ATT,
        &(-(c_vc * skew(&frame.v_c)) - c_vb * l * c.transpose() * skew(&frame.w_ie_c)),
    );
    let lw = -(c_vb * l);
    put_rows(&mut h, Layout::GYRO_BIAS, &lw);
    if let Some(o) = layout.gyro_scale {
        put_rows(&mut h, o, &(lw * Matrix3::from_diagonal(w_ib_b)));
    }
    let v_v = c_vb * v_b;
    if let Some(o) = layout.mounting {
        // v̂_v = (I − [μ×]) v_v = v_v + [v_v×] μ: the pitch and yaw columns.
        let s = skew(&v_v);
        for r in 0..3 {
            h[(r, o)] = s[(r, 1)];
            h[(r, o + 1)] = s[(r, 2)];
        }
    }
    (v_v, h)
}

/// The non-holonomic constraint: no lateral or vertical velocity of the mount's
/// point in the vehicle frame, standard deviation `std` [m/s] each.
pub fn non_holonomic(
    layout: &Layout,
    frame: &FrameSnapshot,
    mount: &VehicleMount,
    w_ib_b: &Vector3<f64>,
    std: f64,
) -> Measurement {
    let (v_v, h3) = vehicle_velocity(layout, frame, mount, w_ib_b);
    Measurement {
        kind: Kind::NonHolonomic,
        z: DVector::from_column_slice(&v_v.as_slice()[1..]),
        h: h3.rows(1, 2).into_owned(),
        r: DMatrix::from_diagonal_element(2, 2, std * std),
    }
}

/// Odometer forward `speed` [m/s] of the mount's point with standard deviation `std`,
/// corrected by the scale-factor estimate `scale` (`speed / (1 + scale)`); with a
/// scale-factor state in the layout, its column is filled.
pub fn odometer(
    layout: &Layout,
    frame: &FrameSnapshot,
    mount: &VehicleMount,
    w_ib_b: &Vector3<f64>,
    speed: f64,
    scale: f64,
    std: f64,
) -> Measurement {
    let (v_v, h3) = vehicle_velocity(layout, frame, mount, w_ib_b);
    let corrected = speed / (1.0 + scale);
    let mut h = h3.rows(0, 1).into_owned();
    if let Some(o) = layout.odometer_scale {
        h[(0, o)] = -corrected / (1.0 + scale);
    }
    Measurement {
        kind: Kind::Odometer,
        z: DVector::from_element(1, v_v.x - corrected),
        h,
        r: DMatrix::from_element(1, 1, std * std),
    }
}

/// Heading `atan2(b_E, b_N)` and pitch `atan2(−b_D, √(b_N² + b_E²))` of a direction
/// `b_n` in NED; `None` within 1e-6 rad of the vertical (no heading).
pub fn heading_pitch(b_n: &Vector3<f64>) -> Option<(f64, f64)> {
    let h = b_n.x.hypot(b_n.y);
    (h >= 1e-6 * b_n.norm()).then(|| (b_n.y.atan2(b_n.x), (-b_n.z).atan2(h)))
}

/// The heading (and pitch) of a dual-antenna `baseline` read at `reading.t`, the frame
/// being at the computed position `at`; the computed angles are carried from the
/// frame's time to the reading's with the body rate `w_ib_b` (`u_b + (ω_eb × u_b) Δt`,
/// first order; the caller applies the reading at the IMU sample nearest its time).
/// `None` for a vertical baseline.
pub fn heading(
    layout: &Layout,
    frame: &FrameSnapshot,
    at: &Geodetic,
    baseline: &Baseline,
    w_ib_b: &Vector3<f64>,
    reading: &HeadingReading,
) -> Option<Measurement> {
    let c = c_bc(frame);
    let c_cn = c_nc(frame, at).transpose();
    let u = baseline.unit_b();
    let b_c = c * u;
    let b = c_cn * b_c;
    let w_eb = w_ib_b - c.transpose() * frame.w_ie_c;
    let ahead = c_cn * c * (u + w_eb.cross(&u) * (reading.t - frame.t));
    let (yaw, pitch) = heading_pitch(&ahead)?;
    heading_pitch(&b)?;
    let d_psi = c_cn * skew(&b_c);
    let h2 = b.x * b.x + b.y * b.y;
    let hz = h2.sqrt();
    let g_yaw = RowVector3::new(-b.y / h2, b.x / h2, 0.0);
    let g_pitch = RowVector3::new(b.z * b.x / hz, b.z * b.y / hz, -hz) / b.norm_squared();
    let rows = 1 + usize::from(reading.pitch.is_some());
    let mut h = DMatrix::zeros(rows, layout.n);
    let mut z = DVector::zeros(rows);
    let mut r = DMatrix::zeros(rows, rows);
    h.fixed_view_mut::<1, 3>(0, Layout::ATT)
        .copy_from(&(g_yaw * d_psi));
    z[0] = wrap_pi(yaw - reading.heading);
    r[(0, 0)] = reading.heading_std * reading.heading_std;
    if let Some((p, std)) = reading.pitch {
        h.fixed_view_mut::<1, 3>(1, Layout::ATT)
            .copy_from(&(g_pitch * d_psi));
        z[1] = pitch - p;
        r[(1, 1)] = std * std;
    }
    Some(Measurement {
        kind: Kind::Heading,
        z,
        h,
        r,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{EarthModel, Wgs84};
    use crate::nav::{ErrorFrame, LocalLevel, NavErrors, NavState, Wander};
    use nalgebra::DVector;

    const LAT_DEG: f64 = 40.0;

    /// The errors the Jacobian tests apply: sizes of a filter between updates.
    struct Errors {
        dr: Vector3<f64>,
        dv: Vector3<f64>,
        psi: Vector3<f64>,
        bg: Vector3<f64>,
        sg: Vector3<f64>,
        dk: f64,
    }

    fn errors() -> Errors {
        Errors {
            dr: Vector3::new(0.6, -0.4, 0.3),
            dv: Vector3::new(0.04, -0.03, 0.02),
            psi: Vector3::new(3e-4, -2e-4, 8e-4),
            bg: Vector3::new(2e-5, -1e-5, 3e-5),
            sg: Vector3::new(1e-4, -2e-4, 1.5e-4),
            dk: 3e-3,
        }
    }

    fn layout() -> Layout {
        Layout::core().with_scale_factors().with_odometer_scale()
    }

    fn state_vector(l: &Layout, e: &Errors) -> DVector<f64> {
        let mut x = DVector::zeros(l.n);
        for (o, v) in [
            (Layout::POS, e.dr),
            (Layout::VEL, e.dv),
            (Layout::ATT, e.psi),
            (Layout::GYRO_BIAS, e.bg),
            (l.gyro_scale.unwrap_or(0), e.sg),
        ] {
            x.fixed_rows_mut::<3>(o).copy_from(&v);
        }
        x[l.odometer_scale.unwrap_or(0)] = e.dk;
        x
    }

    /// The computed mechanization: the true one with the errors put in through
    /// `correct` (which removes `e`, so it is given `−e`).
    fn perturbed<M: ErrorFrame + Clone>(truth: &M, e: &Errors) -> M {
        let mut m = truth.clone();
        m.correct(&NavErrors {
            dr: -e.dr,
            dv: -e.dv,
            psi: -e.psi,
        });
        m
    }

    /// The compensated rate the computed state sees: `ω + δb_g + diag(ω) δs_g`.
    fn rate_with_errors(w: &Vector3<f64>, e: &Errors) -> Vector3<f64> {
        w + e.bg + w.component_mul(&e.sg)
    }

    fn truth_state(v_n: Vector3<f64>, att: Euler) -> NavState {
        NavState::new(0.0, Geodetic::from_degrees(LAT_DEG, -3.0, 700.0), v_n, att)
    }

    fn w_ie_b(s: &NavState) -> Vector3<f64> {
        s.q_bn.inverse() * Wgs84.local(s.pos.lat, s.pos.h).w_ie_n()
    }

    /// Run `check` on the NED and the wander mechanization started at `truth`.
    fn on_both_frames(truth: NavState, mut check: impl FnMut(&dyn Fn(&Errors) -> Probe, &str)) {
        let ned = LocalLevel::new(Wgs84, truth);
        check(&|e: &Errors| Probe::of(&perturbed(&ned, e)), "ned");
        // A wander azimuth other than zero: the frame is turned from NED.
        let wander = Wander::new(Wgs84, truth);
        check(&|e: &Errors| Probe::of(&perturbed(&wander, e)), "wander");
    }

    /// The computed state's frame and position.
    struct Probe {
        computed: FrameSnapshot,
        at: Geodetic,
    }

    impl Probe {
        fn of<M: ErrorFrame>(c: &M) -> Self {
            Self {
                computed: c.frame(),
                at: c.state().pos,
            }
        }
    }

    /// The angle between the computation frames at the true and the computed
    /// position, at most `|δr| (1 + tan φ) / R` with `R ≥ b²/a = 6.335e6 m` (the NED
    /// frame also turns about the vertical by `δr_E tan φ / R_N`): the perturbation
    /// puts `x` in through ECEF, so the computed frame sees it turned by this much.
    fn frame_turn(e: &Errors) -> f64 {
        e.dr.norm() * (1.0 + LAT_DEG.to_radians().tan()) / 6.335e6
    }

    fn assert_linear(name: &str, z_lin: &DVector<f64>, z: &DVector<f64>, tol: f64) {
        let d = (z - z_lin).amax();
        println!(
            "{name}: |z| {:.3e}, |z - Hx| {d:.3e}, tolerance {tol:.3e}",
            z.amax()
        );
        assert!(d <= tol, "{name}: {z} vs {z_lin}");
        // The check has teeth: the measurement moved by much more than the residual.
        assert!(z.amax() > 20.0 * d, "{name}: {z}");
    }

    #[test]
    fn zero_velocity_and_rate_jacobians_match_perturbed_states() {
        let l = layout();
        let e = errors();
        let x = state_vector(&l, &e);
        let truth = truth_state(Vector3::zeros(), Euler::from_degrees(4.0, -3.0, 130.0));
        // At rest the body turns with the Earth only.
        let w = w_ie_b(&truth);
        on_both_frames(truth, |probe, frame| {
            let p = probe(&e);
            let m = zero_velocity(&l, &p.computed, 0.01);
            // z = v̂_c exactly; only the frame turn times |δv| (and round-off).
            let tol = frame_turn(&e) * e.dv.norm() + 1e-12;
            assert_linear(&format!("zupt {frame}"), &(&m.h * &x), &m.z, tol);
            let w_hat = rate_with_errors(&w, &e);
            let m = zero_rate(&l, &p.computed, &w_hat, 1e-5);
            // Second order: |ω_ie| |ψ|² from exp(ψ×) and |δs_g| |δb_g + diag(ω) δs_g|
            // from H's diag(ω̂) against diag(ω).
            let tol = 7.3e-5 * e.psi.norm_squared()
                + e.sg.norm() * (e.bg.norm() + w.norm() * e.sg.norm())
                + 1e-15;
            assert_linear(&format!("zaru {frame}"), &(&m.h * &x), &m.z, tol);
        });
    }

    /// A vehicle turning and climbing at 15 m/s, its IMU turned in it, the constraint
    /// point away from the IMU.
    fn driving() -> (NavState, VehicleMount, Vector3<f64>) {
        let mount = VehicleMount::new(
            Euler::from_degrees(0.5, 2.0, 90.0),
            Vector3::new(-1.2, 0.3, 0.9),
        );
        let att = Euler::from_degrees(4.0, -3.0, 130.0);
        let w_eb = Vector3::new(0.01, -0.02, 0.15);
        // The point moves along the vehicle's front axis: v_b = C_bv (s, 0, 0) − ω×l.
        let v_b = mount.q_vb * Vector3::new(15.0, 0.0, 0.0) - w_eb.cross(&mount.lever);
        let truth = truth_state(att.to_quaternion() * v_b, att);
        let w_ib = w_eb + w_ie_b(&truth);
        (truth, mount, w_ib)
    }

    #[test]
    fn non_holonomic_and_odometer_jacobians_match_perturbed_states() {
        let l = layout();
        let e = errors();
        let x = state_vector(&l, &e);
        let (truth, mount, w) = driving();
        let w_hat = rate_with_errors(&w, &e);
        let dw = (w_hat - w).norm();
        let (k_true, speed) = (0.02, 15.0);
        let k_est = k_true - e.dk;
        let reading = (1.0 + k_true) * speed;
        on_both_frames(truth, |probe, frame| {
            let p = probe(&e);
            // Second order: |v| |ψ|² (the rotation's square), |δv| |ψ|, |l| |δω| |ψ|
            // and |l| |ω| |δs_g| |δω|-like products; the frame turn times |v| |ψ|.
            let second = speed * e.psi.norm_squared()
                + e.dv.norm() * e.psi.norm()
                + mount.lever.norm() * (dw * e.psi.norm() + w.norm() * e.sg.norm() * dw)
                + frame_turn(&e) * (e.dv.norm() + speed * e.psi.norm());
            let m = non_holonomic(&l, &p.computed, &mount, &w_hat, 0.1);
            assert_linear(&format!("nhc {frame}"), &(&m.h * &x), &m.z, second);
            let m = odometer(&l, &p.computed, &mount, &w_hat, reading, k_est, 0.1);
            // The scale factor's own second order: s δk² / (1 + k̂)².
            let tol = second + reading * e.dk * e.dk;
            assert_linear(&format!("odometer {frame}"), &(&m.h * &x), &m.z, tol);
        });
    }

    #[test]
    fn heading_jacobian_matches_perturbed_states() {
        let l = layout();
        let e = errors();
        let x = state_vector(&l, &e);
        let (truth, _, w) = driving();
        let baseline = Baseline {
            yaw: 80f64.to_radians(),
            pitch: 5f64.to_radians(),
        };
        let b_n = truth.q_bn * baseline.unit_b();
        let (yaw, pitch) = heading_pitch(&b_n).expect("not vertical");
        let reading = HeadingReading {
            t: 0.0,
            heading: yaw,
            heading_std: 1e-3,
            pitch: Some((pitch, 2e-3)),
        };
        on_both_frames(truth, |probe, frame| {
            let p = probe(&e);
            let m = heading(&l, &p.computed, &p.at, &baseline, &w, &reading).expect("heading");
            // Second order in ψ, |ψ|² / h² with h the baseline's horizontal part
            // (≥ cos 13° here); first order, the north of the computed position
            // against the true one's (the module doc): the frame turn.
            let h2 = b_n.xy().norm_squared();
            let tol = e.psi.norm_squared() / h2 + frame_turn(&e);
            assert_linear(&format!("heading {frame}"), &(&m.h * &x), &m.z, tol);
        });
    }

    #[test]
    fn a_point_behind_the_imu_moves_as_a_rigid_body_does() {
        // IMU 1.5 m ahead of the rear axle, turning right at 0.1 rad/s at 10 m/s: the
        // IMU slides right at ω l = 0.15 m/s while the axle does not (ω_eb from the
        // rate minus the Earth's).
        let truth = truth_state(Vector3::zeros(), Euler::from_degrees(0.0, 0.0, 30.0));
        let v_b = Vector3::new(10.0, 0.15, 0.0);
        let truth = NavState {
            v_n: truth.q_bn * v_b,
            ..truth
        };
        let w = Vector3::new(0.0, 0.0, 0.1) + w_ie_b(&truth);
        let frame = LocalLevel::new(Wgs84, truth).frame();
        let l = Layout::core();
        let axle = VehicleMount::new(Euler::default(), Vector3::new(-1.5, 0.0, 0.0));
        let (v_v, _) = vehicle_velocity(&l, &frame, &axle, &w);
        assert!((v_v - Vector3::new(10.0, 0.0, 0.0)).norm() < 1e-12, "{v_v}");
        // The IMU itself slides: the constraint at the IMU sees 0.15 m/s.
        let (v_v, _) = vehicle_velocity(&l, &frame, &VehicleMount::aligned(), &w);
        assert!((v_v.y - 0.15).abs() < 1e-12, "{v_v}");
        // Mounted turned by 90° (the vehicle's front is the IMU's right axis): a body
        // velocity along the IMU's y axis is the vehicle's forward speed.
        let turned = VehicleMount::new(Euler::from_degrees(0.0, 0.0, 90.0), Vector3::zeros());
        let still = NavState {
            v_n: truth.q_bn * Vector3::new(0.0, 10.0, 0.0),
            ..truth
        };
        let frame = LocalLevel::new(Wgs84, still).frame();
        let (v_v, _) = vehicle_velocity(&l, &frame, &turned, &w_ie_b(&still));
        assert!((v_v - Vector3::new(10.0, 0.0, 0.0)).norm() < 1e-12, "{v_v}");
    }

    #[test]
    fn baseline_angles_are_the_bodys_turned_by_the_mounting() {
        // Level body heading 30°, baseline 90° to the right: heading 120°.
        let q = Euler::from_degrees(0.0, 0.0, 30.0).to_quaternion();
        let b = Baseline {
            yaw: 90f64.to_radians(),
            pitch: 0.0,
        };
        let (y, p) = heading_pitch(&(q * b.unit_b())).expect("horizontal");
        assert!((y - 120f64.to_radians()).abs() < 1e-15 && p.abs() < 1e-15);
        // Body pitched up 10°, baseline along the front axis: heading 30°, pitch 10°.
        let q = Euler::from_degrees(0.0, 10.0, 30.0).to_quaternion();
        let (y, p) = heading_pitch(&(q * Baseline::default().unit_b())).expect("tilted");
        assert!((y - 30f64.to_radians()).abs() < 1e-15);
        assert!((p - 10f64.to_radians()).abs() < 1e-15);
        // Straight up: no heading.
        assert!(heading_pitch(&Vector3::new(0.0, 0.0, -1.0)).is_none());
    }

    #[test]
    fn the_heading_innovation_wraps_across_north() {
        let truth = truth_state(Vector3::zeros(), Euler::from_degrees(0.0, 0.0, 179.9));
        let frame = LocalLevel::new(Wgs84, truth).frame();
        let reading = HeadingReading {
            t: 0.0,
            heading: (-179.9f64).to_radians(),
            heading_std: 1e-3,
            pitch: None,
        };
        let m = heading(
            &Layout::core(),
            &frame,
            &truth.pos,
            &Baseline::default(),
            &Vector3::zeros(),
            &reading,
        )
        .expect("heading");
        assert!(
            (m.z[0] - (-0.2f64).to_radians()).abs() < 1e-12,
            "{}",
            m.z[0]
        );
        assert_eq!(m.z.len(), 1);
    }
}
