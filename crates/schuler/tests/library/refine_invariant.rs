//! The in-motion refinement invariant of seed 003, eq. (7): the claims of the
//! derivation in `schuler::refine`'s module docs, checked on flights whose attitude is
//! known in closed form (piecewise-constant body rates, composed exactly by
//! rotation-vector exponentials), and a system that integrates its own, erroneous gyro
//! output.

use nalgebra::{Matrix3, Vector3};
use schuler::earth::c_ne;
use schuler::imu::random::Noise;
use schuler::refine::{
    InvariantWindow, RefineFilter, RefineNoise, earth_to_inertial, invariant,
    nav_rate_from_euler_rates, own_rate_nb, reference_increment,
};
use schuler::rotation::{Euler, dcm_from_rotation_vector, rotation_vector_from_quaternion};

const OMEGA: f64 = 7.292_115e-5;
const DEG_H: f64 = std::f64::consts::PI / 180.0 / 3600.0;
const DT: f64 = 0.01;

/// Rotation vector of a DCM (its logarithm), through the quaternion (Shepperd's
/// method): exact to rounding for small angles, where the arc cosine of the trace
/// loses half the digits.
fn log(c: &Matrix3<f64>) -> Vector3<f64> {
    let r = nalgebra::Rotation3::from_matrix_unchecked(*c);
    rotation_vector_from_quaternion(&nalgebra::UnitQuaternion::from_rotation_matrix(&r))
}

/// A flight: the navigation frame turning at a constant `w_en_n` over the Earth, the
/// body at constant rates `w_nb_b` relative to it per phase; the system's attitude
/// starts off by `psi0` (inertial axes) and integrates the gyro output plus `drift`.
struct Flight {
    t: f64,
    c_ne: Matrix3<f64>,
    c_bn: Matrix3<f64>,
    w_en_n: Vector3<f64>,
    c_bi_sys: Matrix3<f64>,
    drift: Vector3<f64>,
}

/// One sample as the system and the independent source see it.
struct Sample {
    /// The system's attitude at the sample's start (body to inertial).
    c_bi_sys: Matrix3<f64>,
    /// The measured gyro increment [rad].
    dtheta: Vector3<f64>,
    /// The independent source's reference side of (7) over the sample (no noise) [rad].
    reference: Vector3<f64>,
}

impl Flight {
    fn new(
        c_ne: Matrix3<f64>,
        w_en_n: Vector3<f64>,
        c_bn: Matrix3<f64>,
        psi0: Vector3<f64>,
        drift: Vector3<f64>,
    ) -> Self {
        let c_bi = c_ne * c_bn;
        Self {
            t: 0.0,
            c_ne,
            c_bn,
            w_en_n,
            c_bi_sys: dcm_from_rotation_vector(&-psi0) * c_bi,
            drift,
        }
    }

    fn c_ni(&self) -> Matrix3<f64> {
        earth_to_inertial(OMEGA, self.t) * self.c_ne
    }

    fn c_bi(&self) -> Matrix3<f64> {
        self.c_ni() * self.c_bn
    }

    /// The system's inertial attitude error `ψ` (`ĉ_bi = exp(−[ψ×]) c_bi`).
    fn psi(&self) -> Vector3<f64> {
        -log(&(self.c_bi_sys * self.c_bi().transpose()))
    }

    /// Advances one sample with the body turning at `w_nb_b` relative to the frame.
    fn step(&mut self, w_nb_b: &Vector3<f64>) -> Sample {
        let (c_bi0, c_ni0, w0) = (self.c_bi(), self.c_ni(), self.w_en_n + self.c_bn * w_nb_b);
        self.c_bn *= dcm_from_rotation_vector(&(w_nb_b * DT));
        self.c_ne *= dcm_from_rotation_vector(&(self.w_en_n * DT));
        self.t += DT;
        let (c_bi1, c_ni1, w1) = (self.c_bi(), self.c_ni(), self.w_en_n + self.c_bn * w_nb_b);
        let dtheta = log(&(c_bi0.transpose() * c_bi1)) + self.drift * DT;
        let sample = Sample {
            c_bi_sys: self.c_bi_sys,
            dtheta,
            reference: reference_increment([&c_ni0, &c_ni1], [&w0, &w1], OMEGA, DT),
        };
        self.c_bi_sys *= dcm_from_rotation_vector(&dtheta);
        sample
    }
}

/// At the North Pole: the frame's z (down) along the Earth's −z, level body.
fn pole_flight(psi0: Vector3<f64>, drift: Vector3<f64>) -> Flight {
    let c_ne = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
    Flight::new(c_ne, Vector3::zeros(), Matrix3::identity(), psi0, drift)
}

/// A maneuvering flight at 70° N, 70 m/s north-east (the frame's transport rate).
fn flight_70n(psi0: Vector3<f64>, drift: Vector3<f64>) -> Flight {
    let lat = 70f64.to_radians();
    let r = 6.4e6;
    let (vn, ve) = (50.0, 50.0);
    let w_en_n = Vector3::new(ve / r, -vn / r, -ve * lat.tan() / r);
    let c_bn = Euler::from_degrees(3.0, 2.0, 45.0).to_dcm();
    Flight::new(c_ne(lat, 25f64.to_radians()), w_en_n, c_bn, psi0, drift)
}

/// The body rates of the 70° N flight at time `t`: a banked turn, a pull-up, a roll.
fn maneuver(t: f64) -> Vector3<f64> {
    let d = std::f64::consts::PI / 180.0;
    match (t / 10.0) as u32 % 3 {
        0 => Vector3::new(0.0, 0.02, 3.0 * d),
        1 => Vector3::new(0.0, 2.0 * d, 0.5 * d),
        _ => Vector3::new(4.0 * d, 0.0, -d),
    }
}

#[test]
fn euler_rates_map_to_the_frame_rate_of_the_dcm() {
    // (8)-(10) against the rate of the DCM itself, ċ_bn = [ω_nb^n×] c_bn, by central
    // differences (step 1e-5 s: truncation ~ ω³h² ≈ 1e-13, rounding ~ 1e-16/h ≈ 1e-11).
    let angles = |t: f64| Euler {
        roll: 0.3 + 0.2 * t,
        pitch: -0.4 + 0.1 * t,
        yaw: 2.0 - 0.3 * t,
    };
    let rates = Euler {
        roll: 0.2,
        pitch: 0.1,
        yaw: -0.3,
    };
    for t in [0.0, 1.0, 3.0] {
        let h = 1e-5;
        let dc = (angles(t + h).to_dcm() - angles(t - h).to_dcm()) / (2.0 * h);
        let w = dc * angles(t).to_dcm().transpose();
        let w_n = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        let got = nav_rate_from_euler_rates(&angles(t), &rates);
        assert!((got - w_n).norm() < 1e-9, "t = {t}: {got} vs {w_n}");
    }
}

#[test]
fn with_its_own_angle_rates_the_invariant_is_identically_zero() {
    // The system has a 0.5 deg/h drift, a 1° attitude error and a 1 % error in its
    // transport rate; the drift alone would give |z| = 2.4e-6 rad/s.
    let drift = Vector3::new(0.5, -0.3, 0.2) * DEG_H;
    let mut f = flight_70n(Vector3::new(0.01, -0.012, 0.017), drift);
    let w_en_sys = f.w_en_n * 1.01;
    let mut c_ne_sys = f.c_ne;
    let (mut worst_11_12, mut worst_euler) = (0.0f64, 0.0f64);
    for k in 0..6000 {
        let s = f.step(&maneuver(k as f64 * DT));
        let rate = s.dtheta / DT;
        let c_ei = earth_to_inertial(OMEGA, f.t - DT);
        let c_ni = c_ei * c_ne_sys;
        // (11)-(12): the angle rates from the system's own matrices.
        let w_nb_b = own_rate_nb(&s.c_bi_sys, &c_ei, &c_ne_sys, &rate, OMEGA, &w_en_sys);
        let c_bn = c_ni.transpose() * s.c_bi_sys;
        let z = invariant(
            &s.c_bi_sys,
            &rate,
            &c_ni,
            &w_en_sys,
            &(c_bn * w_nb_b),
            OMEGA,
        );
        worst_11_12 = worst_11_12.max(z.norm());
        // The Euler route (8)-(10), angles of the system's C3 differenced over ±1 ms
        // (truncation ~ ω³h²/6 ≈ 1e-11 rad/s).
        let h = 1e-3;
        let c_bn_at = |dt: f64| {
            (earth_to_inertial(OMEGA, f.t - DT + dt)
                * c_ne_sys
                * dcm_from_rotation_vector(&(w_en_sys * dt)))
            .transpose()
                * s.c_bi_sys
                * dcm_from_rotation_vector(&(rate * dt))
        };
        let (e0, ep, em) = (
            Euler::from_dcm(&c_bn),
            Euler::from_dcm(&c_bn_at(h)),
            Euler::from_dcm(&c_bn_at(-h)),
        );
        let d = |a: f64, b: f64| schuler::rotation::wrap_pi(a - b) / (2.0 * h);
        let rates = Euler {
            roll: d(ep.roll, em.roll),
            pitch: d(ep.pitch, em.pitch),
            yaw: d(ep.yaw, em.yaw),
        };
        let z = invariant(
            &s.c_bi_sys,
            &rate,
            &c_ni,
            &w_en_sys,
            &nav_rate_from_euler_rates(&e0, &rates),
            OMEGA,
        );
        worst_euler = worst_euler.max(z.norm());
        c_ne_sys *= dcm_from_rotation_vector(&(w_en_sys * DT));
    }
    // Rounding: four chained products of orthonormal matrices applied to rates up to
    // 0.07 rad/s, a few hundred ulps of the rate (observed 1.4e-14 rad/s).
    assert!(
        worst_11_12 < 1e-13,
        "(11)-(12): |z| up to {worst_11_12:e} rad/s"
    );
    assert!(
        worst_euler < 1e-9,
        "(8)-(10): |z| up to {worst_euler:e} rad/s"
    );
    assert!(drift.norm() > 1e3 * worst_euler);
}

/// The invariant (7) over 1-s steps of `f` with the body turning at `rates(t)`, built
/// with the independent source's exact angle rates; per step `(window, ψ at its end)`.
fn windows(
    f: &mut Flight,
    steps: usize,
    rates: impl Fn(f64) -> Vector3<f64>,
) -> Vec<(InvariantWindow, Vector3<f64>)> {
    (0..steps)
        .map(|_| {
            let mut w = InvariantWindow::default();
            for _ in 0..(1.0 / DT).round() as usize {
                let s = f.step(&rates(f.t));
                w.push(&s.c_bi_sys, &s.dtheta, &s.reference, DT);
            }
            (w, f.psi())
        })
        .collect()
}

#[test]
fn with_an_independent_source_the_invariant_is_nonzero_exactly_as_predicted() {
    let yaw_turn = |_: f64| Vector3::new(0.0, 0.0, 2f64.to_radians());
    let still = |_: f64| Vector3::zeros();
    let max_z = |ws: &[(InvariantWindow, Vector3<f64>)]| {
        ws.iter().map(|(w, _)| w.z().norm()).fold(0.0, f64::max)
    };
    // No error: zero up to the trapezoid's O(dt³) and rounding (~1e-15 rad per step).
    let exact = windows(
        &mut pole_flight(Vector3::zeros(), Vector3::zeros()),
        20,
        yaw_turn,
    );
    assert!(max_z(&exact) < 1e-13, "{:e}", max_z(&exact));
    // At the pole the body's inertial rotation is about the polar axis: a heading
    // error of 1 mrad along it is invisible (second order, |ψ|·|A| ≈ 1e-3 of the
    // first-order signal), the same error about a horizontal axis is seen at |A||ψ|.
    for rates in [still, yaw_turn] {
        let along = windows(
            &mut pole_flight(Vector3::new(0.0, 0.0, 1e-3), Vector3::zeros()),
            20,
            rates,
        );
        let across = windows(
            &mut pole_flight(Vector3::new(1e-3, 0.0, 0.0), Vector3::zeros()),
            20,
            rates,
        );
        assert!(
            max_z(&along) < 2e-3 * max_z(&across),
            "{:e} vs {:e}",
            max_z(&along),
            max_z(&across)
        );
        for (w, psi) in &across {
            let predicted = w.h() * nalgebra::Vector6::new(psi.x, psi.y, psi.z, 0.0, 0.0, 0.0);
            assert!((w.z() - predicted).norm() < 2e-3 * predicted.norm());
        }
    }
    // In a maneuvering flight at 70° N with a drift and an attitude error, z follows
    // H [ψ, ε] to second order (|ψ|·|z| ≈ 2e-3 relative), and the drift makes it
    // non-zero in every step.
    let drift = Vector3::new(0.5, -0.3, 0.2) * DEG_H;
    let mut f = flight_70n(Vector3::new(1e-3, -2e-3, 1.5e-3), drift);
    for (w, psi) in windows(&mut f, 60, maneuver) {
        let x = nalgebra::Vector6::new(psi.x, psi.y, psi.z, drift.x, drift.y, drift.z);
        let predicted = w.h() * x;
        assert!(
            (w.z() - predicted).norm() < 5e-3 * predicted.norm(),
            "{} vs {}",
            w.z(),
            predicted
        );
        assert!(w.z().norm() > 0.5 * drift.norm() * w.span());
    }
}

/// The refinement's noise in the convergence test: no gyro noise, a reference of good
/// tactical class (0.01 deg/sqrt(h)).
const NOISE: RefineNoise = RefineNoise {
    arw: 0.0,
    drift_walk: 0.0,
    reference_rate: 0.01 * std::f64::consts::PI / 180.0 / 60.0,
};

/// Runs `filter` over `steps` 1-s steps of `f` with the reference's noise from `rng`.
fn refine(
    f: &mut Flight,
    filter: &mut RefineFilter,
    rng: &mut Noise,
    steps: usize,
    rates: &dyn Fn(f64) -> Vector3<f64>,
) {
    for (mut w, _) in windows(f, steps, rates) {
        let n = Vector3::from_fn(|_, _| rng.normal()) * NOISE.reference_rate * w.span().sqrt();
        // The reference's noise enters as a zero-length sample whose reference side is n.
        w.push(&Matrix3::zeros(), &Vector3::zeros(), &n, 0.0);
        filter.propagate(&w, &NOISE);
        filter.update(&w, &NOISE);
    }
}

/// Every state's estimate within 3 sigma of the truth.
fn within_3_sigma(filter: &RefineFilter, f: &Flight) {
    let (err_psi, err_eps) = (filter.attitude_error() - f.psi(), filter.drift() - f.drift);
    for (k, u) in [Vector3::x(), Vector3::y(), Vector3::z()]
        .iter()
        .enumerate()
    {
        assert!(
            err_psi.dot(u).abs() < 3.0 * filter.attitude_std_along(u),
            "ψ {k}: {err_psi}"
        );
        assert!(
            err_eps[k].abs() < 3.0 * filter.drift_std()[k],
            "ε {k}: {err_eps}"
        );
    }
}

/// The project's test of observability: a state is observed when the data reduced its
/// standard deviation below half its prior (`schuler::align::OBSERVABLE_RATIO`).
const OBSERVED: f64 = schuler::align::OBSERVABLE_RATIO;

#[test]
fn the_refinement_converges_on_what_it_observes_and_leaves_the_rest_at_its_prior() {
    // At the North Pole (Earth rate along the vertical), level body.
    let drift = Vector3::new(0.5, -0.4, 0.3) * DEG_H;
    let (a, b) = (1e-3, 1.0 * DEG_H);
    let prior = (Vector3::new(a, a, 10e-3), Vector3::repeat(b));
    let mut filter = RefineFilter::new(prior.0, prior.1);
    let mut rng = Noise::new(20, 1);
    let mut f = pole_flight(Vector3::new(0.5e-3, -0.3e-3, 5e-3), drift);
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    // 1. Yawing at a constant 2°/s for 600 s: at a constant inertial rate ω the
    // invariant is constant, z/T = ω × ψ(0) + c_bi(0) ε (module docs). It gives the
    // vertical drift alone, 1/σ² = 1/σ₀² + T/q² (the system's 0.5-mrad tilt leaks the
    // horizontal drifts into that row at 5e-4: 2.5e-7 relative); in the plane only
    // |ω| J ψ + ε, so tilt and horizontal drift share what they learn,
    // σ_ψ = a b / sqrt(ω² a² + b²) and σ_ε = b ω a / sqrt(ω² a² + b²) (1 % for the
    // reference's finite noise); the heading error is not seen at all.
    let yaw_rate = 2f64.to_radians();
    refine(&mut f, &mut filter, &mut rng, 600, &|_| {
        Vector3::new(0.0, 0.0, yaw_rate)
    });
    let w = yaw_rate + OMEGA;
    let closed_eps_z = (1.0 / b.powi(2) + 600.0 / NOISE.reference_rate.powi(2))
        .sqrt()
        .recip();
    let (closed_psi, closed_eps) = (
        a * b / (w * w * a * a + b * b).sqrt(),
        b * w * a / (w * w * a * a + b * b).sqrt(),
    );
    let close = |got: f64, want: f64, tol: f64| {
        assert!((got / want - 1.0).abs() < tol, "{got:e} vs {want:e}")
    };
    close(filter.drift_std().z, closed_eps_z, 1e-5);
    close(filter.attitude_std_along(&x), closed_psi, 1e-2);
    close(filter.attitude_std_along(&y), closed_psi, 1e-2);
    close(filter.drift_std().x, closed_eps, 1e-2);
    close(filter.drift_std().y, closed_eps, 1e-2);
    assert!(filter.attitude_std_along(&z) >= prior.0.z);
    within_3_sigma(&filter, &f);
    // 2. Turning left and right (±2°/s, 30 s each) for 600 s: the rate changes
    // separate tilt from the horizontal drift; the heading stays unseen.
    refine(&mut f, &mut filter, &mut rng, 600, &|t| {
        Vector3::new(
            0.0,
            0.0,
            if ((t / 30.0) as u32).is_multiple_of(2) {
                -yaw_rate
            } else {
                yaw_rate
            },
        )
    });
    assert!(filter.attitude_std_along(&z) >= prior.0.z);
    for k in 0..2 {
        assert!(
            filter.drift_std()[k] < OBSERVED * b,
            "drift {k}: {:e}",
            filter.drift_std()[k]
        );
    }
    assert!(filter.attitude_std_along(&x) < OBSERVED * closed_psi);
    within_3_sigma(&filter, &f);
    // 3. Rolling to 20° and back: a rotation about a horizontal axis shows the heading.
    for rate in [yaw_rate, 0.0, -yaw_rate] {
        refine(&mut f, &mut filter, &mut rng, 10, &|_| {
            Vector3::new(rate, 0.0, 0.0)
        });
    }
    assert!(
        filter.attitude_std_along(&z) < OBSERVED * prior.0.z,
        "heading std {:e}",
        filter.attitude_std_along(&z)
    );
    within_3_sigma(&filter, &f);
}
