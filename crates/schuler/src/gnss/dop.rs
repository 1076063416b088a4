//! Dilution of precision: the geometry's share of a position's error (Misra & Enge
//! 2006, §6.1.3).
//!
//! With unit lines of sight `u_i` (receiver to satellite) in the local NED frame and
//! one clock per system, the design matrix's rows are `h_i = [−u_iᵀ, 1_clock(i)]` and
//! `G = (HᵀH)⁻¹` (unit weights): `HDOP = √(G_NN + G_EE)`, `VDOP = √G_DD`,
//! `PDOP = √(HDOP² + VDOP²)`, `TDOP = √(Σ G_clock)` over the clocks and
//! `GDOP = √trace G`. With several systems' clocks, TDOP and GDOP count every clock.

use nalgebra::{Cholesky, Const, SMatrix, SVector, Vector3};

/// The most unknowns of a snapshot solution: position and one clock per system.
pub(crate) const MAX_UNKNOWNS: usize = 3 + crate::gnss::System::ALL.len();

/// The normal matrix of a snapshot solution (padded with the identity past its size).
pub(crate) type Normal = SMatrix<f64, MAX_UNKNOWNS, MAX_UNKNOWNS>;

/// Dilutions of precision of one geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dop {
    /// Geometric: position and every clock.
    pub gdop: f64,
    /// Position.
    pub pdop: f64,
    /// Horizontal.
    pub hdop: f64,
    /// Vertical.
    pub vdop: f64,
    /// Time: every clock.
    pub tdop: f64,
}

impl Dop {
    /// The DOPs of lines of sight `los_n` (unit vectors, NED, receiver to satellite),
    /// each with the index of its clock (`< n_clocks`); `None` when the geometry is
    /// singular (fewer satellites than unknowns, a clock with no satellite, coplanar
    /// lines) or an index is out of range.
    pub fn of(
        los_n: impl IntoIterator<Item = (Vector3<f64>, usize)>,
        n_clocks: usize,
    ) -> Option<Dop> {
        if n_clocks == 0 || 3 + n_clocks > MAX_UNKNOWNS {
            return None;
        }
        let mut a = Normal::zeros();
        for (u, clock) in los_n {
            if clock >= n_clocks {
                return None;
            }
            let mut h = SVector::<f64, MAX_UNKNOWNS>::zeros();
            h.fixed_rows_mut::<3>(0).copy_from(&(-u));
            h[3 + clock] = 1.0;
            a += h * h.transpose();
        }
        Self::from_normal(&a, n_clocks)
    }

    /// The DOPs of an unweighted normal matrix `a = HᵀH` whose position part is in NED
    /// and whose first `n_clocks` clocks are used (the rest of `a` is ignored).
    pub(crate) fn from_normal(a: &Normal, n_clocks: usize) -> Option<Dop> {
        let m = 3 + n_clocks;
        let g = factor(a, m)?.inverse();
        let tdop2: f64 = (3..m).map(|i| g[(i, i)]).sum();
        let h2 = g[(0, 0)] + g[(1, 1)];
        let v2 = g[(2, 2)];
        let dop = Dop {
            gdop: (h2 + v2 + tdop2).sqrt(),
            pdop: (h2 + v2).sqrt(),
            hdop: h2.sqrt(),
            vdop: v2.sqrt(),
            tdop: tdop2.sqrt(),
        };
        dop.gdop.is_finite().then_some(dop)
    }
}

/// The Cholesky factor of the leading `m × m` block of a normal matrix, the rest
/// replaced by the identity (so that its solution and inverse there are zero and one);
/// `None` when the block is not positive definite or is nearly singular: a pivot
/// ratio (min/max of L's diagonal)² below 1e-12, a condition number above about 1e12
/// (the rounding of a rank-deficient matrix leaves pivots of 1e-16 relative).
pub(crate) fn factor(a: &Normal, m: usize) -> Option<Cholesky<f64, Const<MAX_UNKNOWNS>>> {
    let mut padded = *a;
    for i in 0..MAX_UNKNOWNS {
        for j in 0..MAX_UNKNOWNS {
            if i >= m || j >= m {
                padded[(i, j)] = if i == j { 1.0 } else { 0.0 };
            }
        }
    }
    let chol = padded.cholesky()?;
    let l = chol.l_dirty();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for i in 0..m {
        lo = lo.min(l[(i, i)]);
        hi = hi.max(l[(i, i)]);
    }
    let ratio = lo / hi;
    (ratio * ratio > 1e-12).then_some(chol)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit line of sight at elevation `el` and azimuth `az` [rad], NED.
    fn los(el: f64, az: f64) -> Vector3<f64> {
        Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), -el.sin())
    }

    /// One satellite at the zenith and three at elevation θ, 120° apart. With s = sin θ
    /// and unit weights, HᵀH splits into a horizontal block (3/2)cos²θ·I₂ (the three
    /// azimuths' sin², cos² average ½; every cross term sums to zero over 120°) and a
    /// vertical–clock block [[1 + 3s², −(1 + 3s)], [−(1 + 3s), 4]] of determinant
    /// 4(1 + 3s²) − (1 + 3s)² = 3(1 − s)². Hence HDOP = 2/(√3·cos θ),
    /// VDOP = 2/(√3·(1 − s)), TDOP = √((1 + 3s²)/3)/(1 − s).
    #[test]
    fn zenith_and_three_at_equal_elevation() {
        for el_deg in [0.0f64, 10.0, 30.0, 55.0] {
            let el = el_deg.to_radians();
            let az0 = 0.3;
            let rows = [
                (los(std::f64::consts::FRAC_PI_2, 0.0), 0),
                (los(el, az0), 0),
                (los(el, az0 + 120f64.to_radians()), 0),
                (los(el, az0 + 240f64.to_radians()), 0),
            ];
            let d = Dop::of(rows, 1).unwrap();
            let s = el.sin();
            let hdop = 2.0 / (3f64.sqrt() * el.cos());
            let vdop = 2.0 / (3f64.sqrt() * (1.0 - s));
            let tdop = ((1.0 + 3.0 * s * s) / 3.0).sqrt() / (1.0 - s);
            // Four satellites, four unknowns: an exact inverse, to rounding.
            assert!((d.hdop - hdop).abs() < 1e-12 * hdop, "{el_deg}: {}", d.hdop);
            assert!((d.vdop - vdop).abs() < 1e-12 * vdop, "{el_deg}: {}", d.vdop);
            assert!((d.tdop - tdop).abs() < 1e-12 * tdop, "{el_deg}: {}", d.tdop);
            let pdop = hdop.hypot(vdop);
            assert!((d.pdop - pdop).abs() < 1e-12 * pdop);
            assert!((d.gdop - pdop.hypot(tdop)).abs() < 1e-12 * d.gdop);
        }
    }

    #[test]
    fn singular_geometries_give_none() {
        // Three satellites for four unknowns.
        let three = [(los(1.0, 0.0), 0), (los(1.0, 2.0), 0), (los(1.0, 4.0), 0)];
        assert_eq!(Dop::of(three, 1), None);
        // A second clock that no satellite uses.
        let four = [
            (los(1.5, 0.0), 0),
            (los(0.3, 0.0), 0),
            (los(0.3, 2.0), 0),
            (los(0.3, 4.0), 0),
        ];
        assert!(Dop::of(four, 1).is_some());
        assert_eq!(Dop::of(four, 2), None);
        assert_eq!(Dop::of(four, 0), None);
    }
}
