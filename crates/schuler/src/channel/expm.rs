//! Matrix exponential `exp(A)` of an arbitrary real square matrix: the fundamental
//! matrix `Φ(t) = exp(A t)` of any autonomous linear system `x' = A x` (textbook,
//! fundamental-matrix paragraph before (15)).
//!
//! Algorithm: Higham (2005), "The scaling and squaring method for the matrix exponential
//! revisited", SIAM J. Matrix Anal. Appl. 26(4): diagonal Padé approximants of degree 3,
//! 5, 7, 9 or 13 chosen by the 1-norm, with scaling by 2^-s and s squarings. Before that,
//! an exact (power-of-two) diagonal balancing `B = D^-1 A D` (Parlett and Reinsch 1969,
//! as in LAPACK's gebal) is applied when it lowers the norm: the INS error matrix (15)
//! mixes 1/a ~ 1.6e-7 and g ~ 9.8, and balancing brings every entry to ~ω0, so fewer
//! squarings are needed and each entry keeps full relative accuracy at its own scale.

use super::ChannelError;
use nalgebra::SMatrix;

/// Padé coefficients b_0..b_m for m = 3, 5, 7, 9 (Higham 2005, table 2.3 source).
const B3: [f64; 4] = [120.0, 60.0, 12.0, 1.0];
const B5: [f64; 6] = [30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0];
const B7: [f64; 8] = [
    17_297_280.0,
    8_648_640.0,
    1_995_840.0,
    277_200.0,
    25_200.0,
    1512.0,
    56.0,
    1.0,
];
const B9: [f64; 10] = [
    17_643_225_600.0,
    8_821_612_800.0,
    2_075_673_600.0,
    302_702_400.0,
    30_270_240.0,
    2_162_160.0,
    110_880.0,
    3960.0,
    90.0,
    1.0,
];
const B13: [f64; 14] = [
    64_764_752_532_480_000.0,
    32_382_376_266_240_000.0,
    7_771_770_303_897_600.0,
    1_187_353_796_428_800.0,
    129_060_195_264_000.0,
    10_559_470_521_600.0,
    670_442_572_800.0,
    33_522_128_640.0,
    1_323_241_920.0,
    40_840_800.0,
    960_960.0,
    16_380.0,
    182.0,
    1.0,
];
/// Largest 1-norms for which degree 3, 5, 7, 9, 13 reach unit round-off (Higham 2005, table 2.3).
const THETA: [f64; 5] = [
    1.495_585_217_958_292e-2,
    2.539_398_330_063_23e-1,
    9.504_178_996_162_932e-1,
    2.097_847_961_257_068,
    5.371_920_351_148_152,
];

/// The 1-norm (largest absolute column sum).
fn norm1<const N: usize>(a: &SMatrix<f64, N, N>) -> f64 {
    (0..N)
        .map(|j| a.column(j).iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Power-of-two diagonal balancing (Parlett-Reinsch): returns `(B, d)` with
/// `B = D^-1 A D`, `D = diag(d)`. Exact in floating point (scalings are powers of two).
fn balance<const N: usize>(a: &SMatrix<f64, N, N>) -> (SMatrix<f64, N, N>, [f64; N]) {
    let mut b = *a;
    let mut d = [1.0; N];
    for _sweep in 0..100 {
        let mut converged = true;
        for i in 0..N {
            let mut c: f64 = (0..N).filter(|&j| j != i).map(|j| b[(j, i)].abs()).sum();
            let r: f64 = (0..N).filter(|&j| j != i).map(|j| b[(i, j)].abs()).sum();
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            while c < r / 2.0 {
                f *= 2.0;
                c *= 4.0;
            }
            while c > r * 2.0 {
                f /= 2.0;
                c /= 4.0;
            }
            // c now holds c_original * f^2; the new sum is c_original*f + r/f = (c + r)/f.
            if (c + r) / f < 0.95 * s {
                converged = false;
                d[i] *= f;
                for j in 0..N {
                    b[(j, i)] *= f;
                    b[(i, j)] /= f;
                }
            }
        }
        if converged {
            break;
        }
    }
    (b, d)
}

/// `Σ coeffs[k] M^k` for even powers given as (I, A2, A4, ...) pairs, one term per
/// supplied power.
fn combo<const N: usize>(terms: &[(f64, &SMatrix<f64, N, N>)]) -> SMatrix<f64, N, N> {
    let mut out = SMatrix::<f64, N, N>::zeros();
    for (c, m) in terms {
        out += *m * *c;
    }
    out
}

/// Padé approximant `r_m(A) = (V - U)^-1 (V + U)` of degree m (3, 5, 7, 9) or 13.
fn pade<const N: usize>(
    a: &SMatrix<f64, N, N>,
    degree: usize,
) -> Result<SMatrix<f64, N, N>, ChannelError> {
    let id = SMatrix::<f64, N, N>::identity();
    let a2 = a * a;
    let (u, v) = if degree == 13 {
        let b = &B13;
        let a4 = a2 * a2;
        let a6 = a4 * a2;
        let u_inner = a6 * combo(&[(b[13], &a6), (b[11], &a4), (b[9], &a2)])
            + combo(&[(b[7], &a6), (b[5], &a4), (b[3], &a2), (b[1], &id)]);
        let u = a * u_inner;
        let v = a6 * combo(&[(b[12], &a6), (b[10], &a4), (b[8], &a2)])
            + combo(&[(b[6], &a6), (b[4], &a4), (b[2], &a2), (b[0], &id)]);
        (u, v)
    } else {
        let b: &[f64] = match degree {
            3 => &B3,
            5 => &B5,
            7 => &B7,
            _ => &B9,
        };
        // Even powers I, A2, A4, ... up to A^(m-1).
        let mut powers = vec![id];
        for k in 1..=degree / 2 {
            powers.push(powers[k - 1] * a2);
        }
        let mut u_inner = SMatrix::<f64, N, N>::zeros();
        let mut v = SMatrix::<f64, N, N>::zeros();
        for (k, p) in powers.iter().enumerate() {
            u_inner += p * b[2 * k + 1];
            v += p * b[2 * k];
        }
        (a * u_inner, v)
    };
    let q = v - u;
    let q_inv = q
        .try_inverse()
        .ok_or_else(|| ChannelError::Expm("singular Pade denominator (V - U)".to_owned()))?;
    Ok(q_inv * (v + u))
}

/// `exp(A)` for any real `N x N` matrix `A` (Higham 2005 scaling and squaring with
/// Padé approximants, after exact diagonal balancing); errors on NaN/Inf entries.
pub fn expm<const N: usize>(a: &SMatrix<f64, N, N>) -> Result<SMatrix<f64, N, N>, ChannelError> {
    if let Some(&bad) = a.iter().find(|x| !x.is_finite()) {
        return Err(ChannelError::NonFinite {
            name: "matrix entry",
            value: bad,
        });
    }
    let (balanced, d) = balance(a);
    let use_balanced = norm1(&balanced) < norm1(a);
    let m = if use_balanced { balanced } else { *a };
    let norm = norm1(&m);
    let mut result = None;
    for (i, &deg) in [3usize, 5, 7, 9].iter().enumerate() {
        if norm <= THETA[i] {
            result = Some(pade(&m, deg)?);
            break;
        }
    }
    let e = match result {
        Some(e) => e,
        None => {
            let s = (norm / THETA[4]).log2().ceil().max(0.0) as i32;
            let scaled = m * 2f64.powi(-s);
            let mut e = pade(&scaled, 13)?;
            for _ in 0..s {
                e = e * e;
            }
            e
        }
    };
    if e.iter().any(|x| !x.is_finite()) {
        return Err(ChannelError::Expm(format!(
            "overflow: exp of a matrix with 1-norm {norm:e}"
        )));
    }
    if !use_balanced {
        return Ok(e);
    }
    // exp(A) = D exp(B) D^-1.
    let mut out = e;
    for i in 0..N {
        for j in 0..N {
            out[(i, j)] *= d[i] / d[j];
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3};

    #[test]
    fn rotation_generator_gives_cos_sin() {
        // exp([[0,-w],[w,0]] t) = rotation by w t, exactly known.
        for &th in &[1e-6, 0.1, 1.0, 3.0, 30.0, 300.0] {
            let e = expm(&Matrix2::new(0.0, -th, th, 0.0)).unwrap();
            let want = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
            // Round-off grows ~ eps * theta through the argument: allow 1e-15 * (1 + theta).
            assert!(
                (e - want).amax() < 1e-15 * (1.0 + th) * 10.0,
                "{th}: {e} vs {want}"
            );
        }
    }

    #[test]
    fn nilpotent_and_diagonal() {
        // exp of a strictly upper-triangular 3x3 is the finite series I + N + N^2/2.
        let n = Matrix3::new(0.0, 2.0, 3.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0);
        let want = Matrix3::identity() + n + n * n * 0.5;
        assert!((expm(&n).unwrap() - want).amax() < 1e-14);
        let dg = Matrix3::from_diagonal(&nalgebra::Vector3::new(-40.0, 0.5, 7.0));
        let e = expm(&dg).unwrap();
        for (i, x) in [-40.0f64, 0.5, 7.0].iter().enumerate() {
            // ‖A‖1 = 40 needs s = 3 squarings, each doubling the relative error of the
            // Padé value (itself a few hundred eps from its large coefficients): 1e-13.
            let rel = (e[(i, i)] / x.exp() - 1.0).abs();
            assert!(rel < 1e-13, "{x}: {rel:e}");
        }
    }

    #[test]
    fn rejects_nan() {
        let m = Matrix2::new(0.0, f64::NAN, 0.0, 0.0);
        assert!(matches!(expm(&m), Err(ChannelError::NonFinite { .. })));
    }
}
