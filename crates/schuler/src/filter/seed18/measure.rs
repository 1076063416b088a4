//! The paper's two measurements on the 18 states: `z_k`, position from the
//! navigation quaternion `p`, and `z_V`, the velocity turned by the azimuth into
//! east, north, up (the matrix `C4`); equations in the [module doc](super).

use super::model::{N, PHI_W_COLS, Point};
use crate::earth::Geodetic;
use crate::rotation::{skew, wrap_pi};
use nalgebra::{Matrix3, RowVector3, SMatrix, Vector3};

/// Closer to a pole than this `cos φ` (6.4 km from the axis) the paper's latitude,
/// longitude and azimuth lose their meaning, and neither measurement is formed.
pub const POLE_COS_LAT: f64 = 1e-3;

/// A measurement: innovation `z` (computed minus measured), model `H` on the additive
/// state, noise covariance `R`.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement3 {
    /// Innovation.
    pub z: Vector3<f64>,
    /// Model on the additive state.
    pub h: SMatrix<f64, 3, N>,
    /// Noise covariance.
    pub r: Matrix3<f64>,
}

/// `z_k = [(φ − φ_G)(R_M + h), (λ − λ_G)(R_N + h) cos φ, h − h_G]` with `φ, λ` read
/// from `p` by the seed's formulas; standard deviations north, east, down. `None`
/// near a pole ([`POLE_COS_LAT`]).
pub fn position(pt: &Point, fix: &Geodetic, std_ned: &Vector3<f64>) -> Option<Measurement3> {
    let cos_lat = pt.lat.cos();
    if cos_lat < POLE_COS_LAT {
        return None;
    }
    let z = Vector3::new(
        (pt.lat - fix.lat) * pt.rm_h,
        wrap_pi(pt.lon - fix.lon) * pt.rn_h * cos_lat,
        pt.h - fix.h,
    );
    let mut hy = SMatrix::<f64, 3, N>::zeros();
    let d = pt.r2() * pt.displacement_of_angle()?;
    hy.fixed_view_mut::<2, 2>(0, PHI_W_COLS).copy_from(&d);
    hy[(2, super::model::HEIGHT)] = 1.0;
    Some(Measurement3 {
        z,
        h: hy * pt.to_local(),
        r: Matrix3::from_diagonal(&std_ned.component_mul(std_ned)),
    })
}

/// `C4`: wander axes to east, north, up through the azimuth `α`
/// (`[v_E, v_N, v_U] = C4 V`).
pub fn c4(pt: &Point) -> Matrix3<f64> {
    let ned_to_enu = Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
    ned_to_enu * pt.rz()
}

/// `z_V = C4 V − V_G` (east, north, up) from a GNSS velocity `v_ned` with standard
/// deviations `std_ned` (north, east, down). The azimuth's error is
/// `δα = φ_w,z + tan φ δλ` (the frame's own azimuth error plus the meridian
/// convergence of the position error). `None` near a pole.
pub fn velocity(pt: &Point, v_ned: &Vector3<f64>, std_ned: &Vector3<f64>) -> Option<Measurement3> {
    let cos_lat = pt.lat.cos();
    if cos_lat < POLE_COS_LAT {
        return None;
    }
    let c4 = c4(pt);
    let enu = |v: &Vector3<f64>| Vector3::new(v.y, v.x, -v.z);
    let z = c4 * pt.v_w - enu(v_ned);
    // δα as a row on φ_w: e_zᵀ + tan φ / (R_N + h) · (east row of R2 T⁻¹).
    let d = pt.r2() * pt.displacement_of_angle()?;
    let k = pt.lat.sin() / (cos_lat * pt.rn_h);
    let a_alpha = RowVector3::new(k * d[(1, 0)], k * d[(1, 1)], 1.0);
    let mut hy = SMatrix::<f64, 3, N>::zeros();
    hy.fixed_view_mut::<3, 3>(0, super::model::VEL)
        .copy_from(&c4);
    let dv_dalpha = -c4 * skew(&pt.v_w) * Vector3::z();
    hy.fixed_view_mut::<3, 3>(0, PHI_W_COLS)
        .copy_from(&(dv_dalpha * a_alpha));
    let s = enu(std_ned);
    Some(Measurement3 {
        z,
        h: hy * pt.to_local(),
        r: Matrix3::from_diagonal(&s.component_mul(&s)),
    })
}
