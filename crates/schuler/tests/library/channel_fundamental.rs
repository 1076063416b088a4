//! Issue 4: the fundamental matrix (16) equals expm(A t) to 1e-12 relative; and our
//! matrix exponential agrees with nalgebra's own (an independent implementation) on
//! arbitrary matrices.
//!
//! "Relative" for a matrix whose entries have different units: (16) mixes 1/sqrt(ga)
//! [rad per m/s] and sqrt(ga) [m/s per rad]. In the state scaling
//! `S = diag(1, sqrt(ga), 1)` (velocity in units of sqrt(ga)), `S^-1 Φ S` has every
//! entry a sine, a cosine or 1; we require `max |S^-1 (Φ16 - expm) S| <= 1e-12 *
//! max |S^-1 Φ16 S|`, i.e. each entry within 1e-12 of its natural scale.

use nalgebra::{Matrix3, SMatrix};
use schuler::channel::expm::expm;
use schuler::channel::linear::ErrorModel;

const A: f64 = 6_371_000.0;
const G: f64 = 9.81;

/// (16) typed from the text.
fn phi16(t: f64) -> Matrix3<f64> {
    let w0 = (G / A).sqrt();
    let sga = (G * A).sqrt();
    let (s, c) = (w0 * t).sin_cos();
    Matrix3::new(1.0, s / sga, c - 1.0, 0.0, c, -sga * s, 0.0, s / sga, c)
}

/// (15) typed from the text.
fn a15() -> Matrix3<f64> {
    Matrix3::new(0.0, 1.0 / A, 0.0, 0.0, 0.0, -G, 0.0, 1.0 / A, 0.0)
}

fn scaled(m: &Matrix3<f64>) -> Matrix3<f64> {
    let s = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, (G * A).sqrt(), 1.0));
    s.try_inverse().expect("diagonal") * m * s
}

#[test]
fn fundamental_matrix_16_is_expm_of_15() {
    let t0 = std::f64::consts::TAU * (A / G).sqrt();
    let mut worst = 0.0f64;
    for &t in &[
        1e-3,
        1.0,
        60.0,
        1000.0,
        t0 / 4.0,
        t0 / 2.0,
        3600.0,
        14_400.0,
        86_400.0,
    ] {
        let want = phi16(t);
        let got = expm(&(a15() * t)).expect("finite");
        let rel = scaled(&(got - want)).amax() / scaled(&want).amax();
        worst = worst.max(rel);
        assert!(
            rel <= 1e-12,
            "t = {t} s: relative difference {rel:e}\n{got}\n{want}"
        );
        // The library's (16) and (15) are the text's.
        let m = ErrorModel::new(A, G);
        assert_eq!(m.matrix(), a15());
        assert!(scaled(&(m.fundamental(t) - want)).amax() <= 1e-15 * (1.0 + t * 1.3e-3));
    }
    eprintln!("(16) vs expm(A t), t from 1 ms to 24 h: worst relative difference {worst:.2e}");
}

/// A deterministic pseudo-random matrix (SplitMix64), entries in [-1, 1] times `scale`.
fn matrix<const N: usize>(seed: u64, scale: f64) -> SMatrix<f64, N, N> {
    let mut s = seed;
    SMatrix::from_fn(|_, _| {
        let z = schuler::imu::random::splitmix64(&mut s);
        ((z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * scale
    })
}

#[test]
fn expm_agrees_with_nalgebra_on_arbitrary_matrices() {
    // Norms from 1e-3 to ~40: every Padé degree and up to 4 squarings. The bound 1e-11
    // relative (normwise) covers both algorithms' rounding: ~2^s * 100 eps each.
    let mut worst = 0.0f64;
    for seed in 0..40u64 {
        let scale = 10f64.powf(-3.0 + (seed % 8) as f64 * 0.6);
        let a4: SMatrix<f64, 4, 4> = matrix(seed, scale);
        let ours = expm(&a4).expect("finite");
        let theirs = a4.exp();
        let rel = (ours - theirs).amax() / theirs.amax();
        worst = worst.max(rel);
        assert!(rel < 1e-11, "seed {seed}, scale {scale}: {rel:e}");
        let a6: SMatrix<f64, 6, 6> = matrix(seed + 1000, scale);
        let rel6 = (expm(&a6).expect("finite") - a6.exp()).amax() / a6.exp().amax();
        worst = worst.max(rel6);
        assert!(rel6 < 1e-11, "6x6 seed {seed}: {rel6:e}");
    }
    eprintln!("expm vs nalgebra exp, 80 random 4x4/6x6 matrices: worst relative {worst:.2e}");
}

#[test]
fn expm_satisfies_the_group_property() {
    // exp(A(t1+t2)) = exp(A t1) exp(A t2) for the badly scaled (15): balancing keeps it
    // to round-off in the natural scaling.
    let (t1, t2) = (1234.5, 5432.1);
    let lhs = expm(&(a15() * (t1 + t2))).expect("finite");
    let rhs = expm(&(a15() * t1)).expect("finite") * expm(&(a15() * t2)).expect("finite");
    assert!(scaled(&(lhs - rhs)).amax() < 1e-13);
}
