//! Semi-analytic platform INS (lecture 22, (22.16)–(22.17)): a level platform carrying
//! the accelerometers and gyros, torqued at the computed rate of the navigation frame
//! so that it tracks the local vertical (Schuler tuning, T = 84.36 min).
//!
//! The computer's frame `c` is level (x, y horizontal, z down) at azimuth `α` from
//! north (`v_n = R_z(α) v_c`); it is carried by the DCM `C_ce` (c to ECEF) and height.
//! Its rate relative to the Earth is the transport rate, horizontal part fixed by the
//! velocity, vertical part chosen by the azimuth mechanization (22.17), NED signs:
//!
//! | mechanization | `ω_ec` down | `ω_ic` down (lecture's `ω_ζ`, up) |
//! |---|---|---|
//! | geographic | `−v_E tan φ/(R_N+h)` | `−(V/R) tan φ sin ψ − ω3 sin φ` |
//! | orthodromic | `0` | `−ω3 sin φ` |
//! | free azimuth | `ω3 sin φ` | `0` |
//!
//! The platform is commanded with `ω_ic_c = ω_ie_c + ω_ec_c`; its true rate in its own
//! axes is that plus the gyro drift. The accelerometers read the true specific force
//! in the platform's true axes plus bias, and the computer takes those axes to be `c`:
//! the navigation equation (22.10) in `c`,
//! `dv_c/dt = f_p + g_c − (2 ω_ie_c + ω_ec_c) × v_c`, `dC_ce/dt = C_ce [ω_ec_c ×]`,
//! `dh/dt = −v_z`. The gimbal angles measure the true body attitude relative to the
//! platform, so the computed `C_bn = R_z(α) C_pb`.

use super::sensors::Sensors;
use super::truth::{TruthPoint, c_ei};
use super::{OdeState, TruthDriven, VerticalChannel, leveling, quat_rate, rk4, unit};
use crate::earth::{EarthModel, c_ne};
use crate::nav::NavState;
use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

/// Azimuth mechanization of a level platform, by its vertical rate (22.17).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Azimuth {
    /// North-slaved: one axis along the meridian; vertical rate grows as tan(lat).
    Geographic,
    /// Great-circle: no azimuth rotation relative to the Earth, `ω_ζ = ω3 sin φ`.
    Orthodromic,
    /// Free azimuth: no azimuth rotation relative to inertial space, `ω_ζ = 0`.
    FreeAzimuth,
}

impl Azimuth {
    /// Short name for files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Azimuth::Geographic => "geographic",
            Azimuth::Orthodromic => "orthodromic",
            Azimuth::FreeAzimuth => "free-azimuth",
        }
    }
}

/// The computer's frame at one state: everything the equations need.
#[derive(Debug, Clone, Copy)]
struct Frame {
    /// `R_z(α)`: c to NED.
    c_nc: Matrix3<f64>,
    lat: f64,
    lon: f64,
    w_ie_c: Vector3<f64>,
    w_ec_c: Vector3<f64>,
    g_c: Vector3<f64>,
}

/// Continuous state: platform attitude (true), computer's frame, height, velocity.
#[derive(Debug, Clone, Copy)]
struct State {
    /// True platform-to-inertial rotation `C_pi`.
    q_pi: Quaternion<f64>,
    /// Computer's frame to ECEF, `C_ce`.
    q_ce: Quaternion<f64>,
    h: f64,
    v_c: Vector3<f64>,
}

impl OdeState for State {
    fn plus(&self, d: &Self, h: f64) -> Self {
        Self {
            q_pi: self.q_pi + d.q_pi * h,
            q_ce: self.q_ce + d.q_ce * h,
            h: self.h + d.h * h,
            v_c: self.v_c + d.v_c * h,
        }
    }
}

/// A platform INS in one azimuth mechanization over an Earth model.
#[derive(Debug)]
pub struct PlatformIns<E: EarthModel> {
    earth: E,
    azimuth: Azimuth,
    sensors: Sensors,
    vertical: VerticalChannel,
    t0: f64,
    x: State,
}

/// Latitude, longitude and azimuth of a level frame from `C_ce` (z = down).
fn lat_lon_azimuth(c_ce: &Matrix3<f64>) -> (f64, f64, f64) {
    let d = c_ce.column(2);
    let lat = (-d.z).atan2(d.x.hypot(d.y));
    let lon = (-d.y).atan2(-d.x);
    let c_nc = c_ne(lat, lon).transpose() * c_ce;
    (lat, lon, c_nc[(1, 0)].atan2(c_nc[(0, 0)]))
}

fn rz(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

impl<E: EarthModel> PlatformIns<E> {
    /// A platform INS starting at the truth `start`, its x axis north (α = 0), except
    /// the orthodromic platform's, which starts along the initial track (the great
    /// circle being flown, when the ground speed exceeds 0.1 m/s); when `leveled`, the platform is tilted so the biased accelerometers read the
    /// true horizontal specific force ([`leveling`]), otherwise it is exactly level.
    pub fn new(
        earth: E,
        azimuth: Azimuth,
        sensors: impl Into<Sensors>,
        vertical: VerticalChannel,
        leveled: bool,
        start: &TruthPoint,
    ) -> Self {
        let sensors = sensors.into();
        let s = &start.state;
        let alpha0 = match azimuth {
            Azimuth::Orthodromic if s.v_n.x.hypot(s.v_n.y) > 0.1 => s.v_n.y.atan2(s.v_n.x),
            _ => 0.0,
        };
        let c_ce = c_ne(s.pos.lat, s.pos.lon) * rz(alpha0);
        let c_pc = if leveled {
            let f_c = c_ce.transpose() * start.f_e;
            leveling(&f_c, &sensors.initial_accel_bias(), &Vector3::z_axis()).into_inner()
        } else {
            Matrix3::identity()
        };
        let q = |m: Matrix3<f64>| {
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m)).into_inner()
        };
        Self {
            earth,
            azimuth,
            sensors,
            vertical,
            t0: s.t,
            x: State {
                q_pi: q(c_ce * c_pc),
                q_ce: q(c_ce),
                h: s.pos.h,
                v_c: rz(alpha0).transpose() * s.v_n,
            },
        }
    }

    /// The azimuth mechanization.
    pub fn azimuth(&self) -> Azimuth {
        self.azimuth
    }

    fn frame(&self, x: &State) -> Frame {
        let c_ce = unit(&x.q_ce).to_rotation_matrix().into_inner();
        let (lat, lon, alpha) = lat_lon_azimuth(&c_ce);
        let c_nc = rz(alpha);
        let local = self.earth.local(lat, x.h);
        let v_n = c_nc * x.v_c;
        let rn = local.radii.prime_vertical + x.h;
        let rm = local.radii.meridian + x.h;
        let w = self.earth.rotation_rate();
        let down = match self.azimuth {
            Azimuth::Geographic => -v_n.y * local.sin_lat / (local.cos_lat * rn),
            Azimuth::Orthodromic => 0.0,
            Azimuth::FreeAzimuth => w * local.sin_lat,
        };
        let w_en = Vector3::new(v_n.y / rn, -v_n.x / rm, down);
        Frame {
            c_nc,
            lat,
            lon,
            w_ie_c: c_ce.transpose() * Vector3::new(0.0, 0.0, w),
            w_ec_c: c_nc.transpose() * w_en,
            g_c: c_nc.transpose() * local.g_n,
        }
    }

    /// True specific force in the platform's axes.
    fn specific_force(&self, x: &State, truth: &TruthPoint) -> Vector3<f64> {
        let c_pi = unit(&x.q_pi).to_rotation_matrix().into_inner();
        let c_ei = c_ei(self.earth.rotation_rate(), truth.state.t, self.t0);
        c_pi.transpose() * (c_ei * truth.f_e)
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
        let fr = self.frame(x);
        let w_ic_c = fr.w_ie_c + fr.w_ec_c;
        let f_p = self.specific_force(x, truth) + e_f;
        State {
            q_pi: quat_rate(&x.q_pi, &(w_ic_c + e_w)),
            q_ce: quat_rate(&x.q_ce, &fr.w_ec_c),
            h: -x.v_c.z,
            v_c: f_p + fr.g_c - (2.0 * fr.w_ie_c + fr.w_ec_c).cross(&x.v_c),
        }
    }

    /// The rate at which the platform is commanded, `ω_ic` in its axes [rad/s]
    /// (22.17; its z component is the lecture's `−ω_ζ`, NED being down).
    pub fn commanded_rate(&self) -> Vector3<f64> {
        let fr = self.frame(&self.x);
        fr.w_ie_c + fr.w_ec_c
    }

    /// Azimuth of the platform's x axis from north [rad].
    pub fn platform_azimuth(&self) -> f64 {
        lat_lon_azimuth(&unit(&self.x.q_ce).to_rotation_matrix().into_inner()).2
    }
}

impl<E: EarthModel> TruthDriven for PlatformIns<E> {
    fn step(&mut self, a: &TruthPoint, m: &TruthPoint, c: &TruthPoint) {
        let dt = c.state.t - a.state.t;
        let nodes = [a, m, c];
        let fr = self.frame(&self.x);
        let (e_w, e_f) = self.sensors.step(
            c.state.t,
            dt,
            &(fr.w_ie_c + fr.w_ec_c),
            &self.specific_force(&self.x, a),
        );
        let mut x = rk4(&self.x, dt, |k, x| self.derivative(x, nodes[k], &e_w, &e_f));
        x.q_pi = unit(&x.q_pi).into_inner();
        x.q_ce = unit(&x.q_ce).into_inner();
        if self.vertical == VerticalChannel::TrueHeight {
            x.h = c.state.pos.h;
            x.v_c.z = c.state.v_n.z;
        }
        self.x = x;
    }

    fn state(&self, truth: &TruthPoint) -> NavState {
        let fr = self.frame(&self.x);
        let c_pi = unit(&self.x.q_pi).to_rotation_matrix().into_inner();
        let c_ib = c_ei(self.earth.rotation_rate(), truth.state.t, self.t0) * truth.c_be;
        let c_pb = c_pi.transpose() * c_ib;
        let c_bn = fr.c_nc * c_pb;
        NavState {
            t: truth.state.t,
            pos: crate::earth::Geodetic::new(fr.lat, fr.lon, self.x.h),
            v_n: fr.c_nc * self.x.v_c,
            q_bn: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_bn)),
        }
    }
}
