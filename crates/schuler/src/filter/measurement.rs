//! Measurement models of the error-state filter, written `z = H x + v` with `z` the
//! computed quantity minus the measured one, all resolved in the computation frame `c`
//! (psi-angle errors, [`crate::nav::frame`]).
//!
//! - GNSS position at an antenna with lever arm `l` (body axes):
//!   `r_ant = r + C_ec C_cb l`, so `z = C_ce (r̂_ant − r_gnss) = δr + [(Ĉ_cb l)×] ψ + v`.
//! - GNSS velocity: `v_ant = v + C_cb (ω_eb^b × l)`, `ω_eb^b = ω_ib^b − C_bc ω_ie^c`:
//!   `z = δv + [(Ĉ_cb (ω_eb × l))×] ψ − Ĉ_cb [l×] δb_g + v` (Groves 2013 §14.2.1
//!   with the psi-angle attitude error).
//! - Barometric height `h_b = h + b + v` with a bias state: `c`'s third axis is down in
//!   both mechanizations, so `z = ĥ − (h_b − b̂) = −δr_z − δb + v`.
//! - Measurement noise given in NED is turned into `c`: `R_c = C_cn R_n C_nc`.
//!
//! The vehicle measurements (zero velocity and angular rate, non-holonomic constraint,
//! odometer, dual-antenna heading) are in [`super::vehicle`].

use super::layout::Layout;
use crate::earth::{EarthModel, Geodetic, c_ne};
use crate::nav::FrameSnapshot;
use crate::rotation::skew;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// What a measurement observed (for logs and statistics).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Kind {
    /// GNSS position.
    GnssPosition,
    /// GNSS velocity.
    GnssVelocity,
    /// Barometric height.
    BaroHeight,
    /// Zero velocity at rest (ZUPT).
    ZeroVelocity,
    /// Zero angular rate relative to the Earth at rest (ZARU).
    ZeroRate,
    /// Non-holonomic constraint: no lateral or vertical velocity of the vehicle.
    NonHolonomic,
    /// Odometer forward speed.
    Odometer,
    /// Dual-antenna GNSS baseline heading (and pitch).
    Heading,
    /// One satellite's pseudorange (tight coupling).
    Pseudorange,
    /// One satellite's pseudorange rate from its Doppler (tight coupling).
    RangeRate,
}

impl Kind {
    /// Unit of the innovation's components, for reports: `m`, `m/s`, `rad/s`, `rad`.
    pub fn unit(self) -> &'static str {
        match self {
            Kind::GnssPosition | Kind::BaroHeight | Kind::Pseudorange => "m",
            Kind::GnssVelocity
            | Kind::ZeroVelocity
            | Kind::NonHolonomic
            | Kind::Odometer
            | Kind::RangeRate => "m/s",
            Kind::ZeroRate => "rad/s",
            Kind::Heading => "rad",
        }
    }
}

impl std::fmt::Display for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Kind::GnssPosition => "gnss_position",
            Kind::GnssVelocity => "gnss_velocity",
            Kind::BaroHeight => "baro_height",
            Kind::ZeroVelocity => "zupt",
            Kind::ZeroRate => "zaru",
            Kind::NonHolonomic => "nhc",
            Kind::Odometer => "odometer",
            Kind::Heading => "heading",
            Kind::Pseudorange => "pseudorange",
            Kind::RangeRate => "range_rate",
        })
    }
}

/// One linearized measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// What it observed.
    pub kind: Kind,
    /// Innovation (computed minus measured).
    pub z: DVector<f64>,
    /// Sensitivity to the error state.
    pub h: DMatrix<f64>,
    /// Noise covariance.
    pub r: DMatrix<f64>,
}

/// Rotation from NED at a geodetic position to `c`.
pub fn c_nc(frame: &FrameSnapshot, at: &Geodetic) -> Matrix3<f64> {
    frame.c_ce_to_e.transpose() * c_ne(at.lat, at.lon)
}

pub(crate) fn ned_covariance(c: &Matrix3<f64>, std: &Vector3<f64>) -> DMatrix<f64> {
    let r = c * Matrix3::from_diagonal(&std.component_mul(std)) * c.transpose();
    DMatrix::from_fn(3, 3, |i, j| r[(i, j)])
}

pub(crate) fn put(h: &mut DMatrix<f64>, c: usize, m: &Matrix3<f64>) {
    h.fixed_view_mut::<3, 3>(0, c).copy_from(m);
}

/// GNSS position `fix` with NED standard deviations `std`, antenna at `lever` (body).
pub fn gnss_position<E: EarthModel>(
    earth: &E,
    layout: &Layout,
    frame: &FrameSnapshot,
    fix: &Geodetic,
    std: &Vector3<f64>,
    lever: &Vector3<f64>,
) -> Measurement {
    let c_bc = frame.q_bc.to_rotation_matrix().into_inner();
    let l_c = c_bc * lever;
    let c_ce = frame.c_ce_to_e.transpose();
    let z = c_ce * (frame.r_e - earth.geodetic_to_ecef(fix)) + l_c;
    let mut h = DMatrix::zeros(3, layout.n);
    put(&mut h, Layout::POS, &Matrix3::identity());
    put(&mut h, Layout::ATT, &skew(&l_c));
    Measurement {
        kind: Kind::GnssPosition,
        z: DVector::from_column_slice(z.as_slice()),
        h,
        r: ned_covariance(&c_nc(frame, fix), std),
    }
}

/// GNSS velocity `v_ned` (NED at `fix`) with standard deviations `std`, antenna at
/// `lever`, body angular rate `w_ib_b` (compensated).
#[allow(clippy::too_many_arguments)]
pub fn gnss_velocity(
    layout: &Layout,
    frame: &FrameSnapshot,
    fix: &Geodetic,
    v_ned: &Vector3<f64>,
    std: &Vector3<f64>,
    lever: &Vector3<f64>,
    w_ib_b: &Vector3<f64>,
) -> Measurement {
    let c_bc = frame.q_bc.to_rotation_matrix().into_inner();
    let w_eb = w_ib_b - c_bc.transpose() * frame.w_ie_c;
    let lever_v = c_bc * w_eb.cross(lever);
    let c = c_nc(frame, fix);
    let z = frame.v_c + lever_v - c * v_ned;
    let mut h = DMatrix::zeros(3, layout.n);
    put(&mut h, Layout::VEL, &Matrix3::identity());
    put(&mut h, Layout::ATT, &skew(&lever_v));
    put(&mut h, Layout::GYRO_BIAS, &(-c_bc * skew(lever)));
    Measurement {
        kind: Kind::GnssVelocity,
        z: DVector::from_column_slice(z.as_slice()),
        h,
        r: ned_covariance(&c, std),
    }
}

/// Barometric height `h_baro` with standard deviation `std`, the bias estimated so
/// far `bias` removed; needs a layout with a baro bias state.
pub fn baro_height(
    layout: &Layout,
    h: f64,
    h_baro: f64,
    bias: f64,
    std: f64,
) -> Option<Measurement> {
    let b = layout.baro_bias?;
    let mut hm = DMatrix::zeros(1, layout.n);
    hm[(0, Layout::POS + 2)] = -1.0;
    hm[(0, b)] = -1.0;
    Some(Measurement {
        kind: Kind::BaroHeight,
        z: DVector::from_element(1, h - (h_baro - bias)),
        h: hm,
        r: DMatrix::from_element(1, 1, std * std),
    })
}
