//! The demo's second flight: the sortie's helicopter, IMU and receivers on a short leg
//! over the North Pole, written in ECEF because latitude and longitude are singular
//! there (the scripted simulator stops at 89.9 deg).
//!
//! The nominal track runs along a meridian ellipse at constant height: the point at
//! meridian angle `ψ` is `p(ψ) = [(R_N + h) cos ψ, 0, (R_N (1 − e²) + h) sin ψ]` in the
//! start meridian's frame (x to the equator, z polar), geodetic latitude `ψ` before the
//! pole and `180° − ψ` on the opposite meridian after it; `ψ` grows at
//! `V / (R_M(90°) + h)`, so the ground speed along the track is `V` at the pole
//! (and `V (R_M + h) / (R_M(90°) + h)`, 1.2e-7 less, at 89.8 deg). On top of it the
//! helicopter weaves: the whole point is turned about the frame's x axis by
//! `m(t) = (A / (b + h)) sin(2π (t − t_pole) / P)`, a sideways offset of about `A`
//! sin(...) near the pole, zero at the pole itself, where the cross-track speed is
//! largest: the track crosses the pole exactly, at an angle to the meridian. The body
//! is yawed into the velocity (`tan β = v_right / v_forward`, with `v_right = −m' p_z`)
//! and banked for the sideways acceleration (`tan φ = −m'' p_z cos β / g`, `g` = 9.83
//! m/s² at the pole; coordinated but for the neglected `m' ṗ_z`, below 1e-6 of it).

use super::sortie::Sortie;
use anyhow::{Context, Result};
use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use schuler::earth::{EarthModel, Wgs84, c_ned_to_ned};
use schuler::nav::NavState;
use schuler::rotation::quaternion_from_rotation_vector;
use schuler::sim::analytic::{self, Trajectory};
use schuler::sim::jet::{Jet, JetMat3, JetVec3};
use schuler::sim::receivers::offset_ned;
use schuler::sim::run::ScenarioSpec;
use schuler::sim::scenario::Quantity;
use std::f64::consts::{FRAC_PI_2, TAU};

/// Gravity at the pole for the bank angle [m/s^2] (WGS84 normal gravity there,
/// 9.832; the bank only shapes the motion, the IMU sees its exact consequences).
const G_POLE: f64 = 9.83;

/// The pole-crossing flight in ECEF (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoleCrossing {
    /// Longitude of the start meridian [rad].
    lon0: f64,
    /// Height [m].
    h: f64,
    /// Time at the pole [s].
    t_pole: f64,
    /// Meridian-angle rate [rad/s].
    psi_rate: f64,
    /// Weave: amplitude as an angle about the frame's x axis [rad], angular frequency
    /// [rad/s].
    weave: (f64, f64),
}

impl PoleCrossing {
    /// Body frame (FRD) in the level frame: yawed by `β` into the velocity, rolled by
    /// `φ`; `Rz(β) Rx(φ)` from the two angles' sines and cosines.
    fn body_in_level(cb: Jet, sb: Jet, cf: Jet, sf: Jet) -> JetMat3 {
        let z = Jet::constant(0.0);
        JetMat3([
            [cb, -(sb * cf), sb * sf],
            [sb, cb * cf, -(cb * sf)],
            [z, sf, cf],
        ])
    }
}

impl Trajectory for PoleCrossing {
    /// The nominal track's meridian angle, start longitude and height: the geodetic
    /// position only before the pole and off the weave. Not used: the kinematics and
    /// the truth come from [`PoleCrossing::ecef_pose`], valid everywhere.
    fn position(&self, t: Jet) -> JetVec3 {
        [
            (t - self.t_pole) * self.psi_rate + FRAC_PI_2,
            Jet::constant(self.lon0),
            Jet::constant(self.h),
        ]
    }

    /// Level with the nominal track (not used, as [`PoleCrossing::position`]).
    fn c_bn(&self, _t: Jet) -> JetMat3 {
        JetMat3::from_euler(Jet::constant(0.0), Jet::constant(0.0), Jet::constant(0.0))
    }

    fn ecef_pose<E: EarthModel>(&self, earth: &E, t: Jet) -> (JetVec3, JetMat3) {
        let (a, e2) = (earth.semi_major_axis(), earth.eccentricity_squared());
        let one = Jet::constant(1.0);
        let z = Jet::constant(0.0);
        let psi = (t - self.t_pole) * self.psi_rate + FRAC_PI_2;
        let (s, c) = psi.sin_cos();
        let w = one - s * s * e2;
        let rn = w.sqrt().recip() * a;
        let rm = rn * (1.0 - e2) / w;
        let p = [(rn + self.h) * c, z, (rn * (1.0 - e2) + self.h) * s];
        // Weave about x: m, m', m'' as jets of t.
        let (amp, freq) = self.weave;
        let (sp, cp) = ((t - self.t_pole) * freq).sin_cos();
        let (sm, cm) = (sp * amp).sin_cos();
        let m_rate = cp * (amp * freq);
        let m_acc = sp * (-amp * freq * freq);
        // Velocity in the level frame (forward, right) and the bank for the sideways
        // acceleration.
        let forward = (rm + self.h) * self.psi_rate;
        let right = -(m_rate * p[2]);
        let speed = (forward * forward + right * right).sqrt();
        let (cb, sb) = (forward / speed, right / speed);
        let lateral = -(m_acc * p[2]) * cb;
        let norm = (lateral * lateral + G_POLE * G_POLE).sqrt();
        let (sf, cf) = (lateral / norm, Jet::constant(G_POLE) / norm);
        // Columns of the level frame: forward (along the meridian), right, down.
        let level = JetMat3([[-s, z, -c], [z, one, z], [c, z, -s]]);
        let weave = JetMat3([[one, z, z], [z, cm, -sm], [z, sm, cm]]);
        let (so, co) = self.lon0.sin_cos();
        let meridian = JetMat3([
            [Jet::constant(co), Jet::constant(-so), z],
            [Jet::constant(so), Jet::constant(co), z],
            [z, z, one],
        ]);
        let to_e = meridian.mul(&weave);
        (
            to_e.mul_vec(&p),
            to_e.mul(&level).mul(&Self::body_in_level(cb, sb, cf, sf)),
        )
    }
}

/// Errors of the state navigation starts from, handed over in flight (navigated minus
/// true, in the truth's NED frame as [`schuler::analysis::errors`] takes them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Handover {
    /// Position error [m].
    pub pos_n: Vector3<f64>,
    /// Velocity error [m/s].
    pub v_n: Vector3<f64>,
    /// Attitude error `ψ` about north, east, down [rad] (`Ĉ_bn = (I − ψ×) C_bn`).
    pub psi: Vector3<f64>,
}

/// The pole crossing and how it is flown and processed.
#[derive(Debug, Clone)]
pub struct Crossing {
    /// The sortie's sensors and seed (its motion is not used), with the crossing's
    /// GNSS outage and IMU rate.
    pub spec: ScenarioSpec,
    /// The trajectory.
    pub traj: PoleCrossing,
    /// Start time [s].
    pub t0: f64,
    /// Length [s].
    pub duration: f64,
    /// Ground speed along the meridian at the pole [m/s].
    pub speed: f64,
    /// Weave amplitude [m] and period [s].
    pub weave: (f64, f64),
    /// GNSS outage around the pole [s].
    pub outage: (f64, f64),
    /// The errors navigation starts with.
    pub handover: Handover,
    /// The filter's prior standard deviations of position [m], velocity [m/s] and
    /// attitude [rad] (the hand-over's uncertainty).
    pub prior_std: [Vector3<f64>; 3],
}

fn text(s: &str) -> Quantity {
    Quantity::Text(s.to_string())
}

impl Crossing {
    /// The sortie's helicopter at 70 m/s and 300 m over the pole from longitude 25 E
    /// to 155 W, weaving 300 m either side every 120 s, for `duration` s with the pole
    /// at half time and GNSS lost for the 60 s around it; the sortie's sensors at its
    /// IMU rate. A `duration` of whole weave periods puts both ends on their meridians.
    /// The hand-over errors are those of a good in-flight inertial-satellite solution
    /// (1.4 m horizontally, 0.04 m/s, 0.7 arcmin level, 3 arcmin heading).
    pub fn from_sortie(sortie: &Sortie, duration: f64) -> Result<Self> {
        let (speed, h, lon0) = (70.0, 300.0, 25f64.to_radians());
        let weave = (300.0, 120.0);
        let earth = Wgs84;
        let (a, e2) = (earth.semi_major_axis(), earth.eccentricity_squared());
        let rm_pole = a / (1.0 - e2).sqrt();
        let b = a * (1.0 - e2).sqrt();
        let t0 = 0.0;
        let t_pole = t0 + 0.5 * duration;
        let outage = (t_pole - 30.0, t_pole + 30.0);
        let mut spec = sortie.spec.clone();
        spec.motion.clear();
        let g = spec.gnss.as_mut().context("the sortie has GNSS")?;
        g.outages = vec![[
            text(&format!("{} s", outage.0)),
            text(&format!("{} s", outage.1)),
        ]];
        g.outliers.clear();
        let arcmin = (1.0f64 / 60.0).to_radians();
        Ok(Self {
            spec,
            traj: PoleCrossing {
                lon0,
                h,
                t_pole,
                psi_rate: speed / (rm_pole + h),
                weave: (weave.0 / (b + h), TAU / weave.1),
            },
            t0,
            duration,
            speed,
            weave,
            outage,
            handover: Handover {
                pos_n: Vector3::new(1.0, -1.0, 0.5),
                v_n: Vector3::new(0.03, -0.02, 0.01),
                psi: Vector3::new(0.5, -0.5, 3.0) * arcmin,
            },
            prior_std: [
                Vector3::new(1.5, 1.5, 1.0),
                Vector3::new(0.05, 0.05, 0.03),
                Vector3::new(1.0, 1.0, 5.0) * arcmin,
            ],
        })
    }

    /// The full demo's crossing: 600 s (from 89.81 N).
    pub fn full(sortie: &Sortie) -> Result<Self> {
        Self::from_sortie(sortie, 600.0)
    }

    /// The `--quick` crossing: 240 s (from 89.92 N), at the quick sortie's IMU rate.
    pub fn quick(sortie: &Sortie) -> Result<Self> {
        Self::from_sortie(sortie, 240.0)
    }

    /// Time over the pole [s].
    pub fn t_pole(&self) -> f64 {
        self.traj.t_pole
    }

    /// End time [s].
    pub fn end(&self) -> f64 {
        self.t0 + self.duration
    }

    /// The true state at `t` (NED; at the pole relative to the meridian
    /// `ecef_to_geodetic` reports).
    pub fn truth(&self, t: f64) -> NavState {
        analytic::evaluate(&Wgs84, &self.traj, t).0
    }

    /// The state navigation starts from: the truth at the start with the hand-over's
    /// errors, made in the truth's NED frame (position offset through ECEF) and carried
    /// into the NED frame at the offset position, which 21 km from the pole is turned
    /// by the meridian convergence over a metre east, 5e-5 rad (10″, 3 mm/s at 70
    /// m/s).
    pub fn start(&self) -> NavState {
        let truth = self.truth(self.t0);
        let e = &self.handover;
        let pos = offset_ned(&Wgs84, &truth.pos, &e.pos_n);
        let c = c_ned_to_ned(&truth.pos, &pos);
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c));
        NavState {
            t: truth.t,
            pos,
            v_n: c * (truth.v_n + e.v_n),
            q_bn: q * quaternion_from_rotation_vector(&-e.psi) * truth.q_bn,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use schuler::earth::c_ne;

    fn crossing() -> Crossing {
        Crossing::full(&Sortie::full().expect("sortie")).expect("crossing")
    }

    /// The track passes through the pole at half time and ends on the opposite
    /// meridian: the latitude of the ECEF position is 90 deg to 1e-9 deg at `t_pole`;
    /// the start and end are speed x half the duration (21 km) from the polar axis, to
    /// the arc's sine, `ρ Δψ²/6` = 0.046 m (measured 0.038 m), on longitudes 25 E and
    /// 155 W (the weave is back on the meridian there: whole half periods from the
    /// pole), at 300 m.
    #[test]
    fn crosses_the_pole_between_opposite_meridians() {
        let c = crossing();
        let r = |t: f64| analytic::ecef_truth(&Wgs84, &c.traj, t).r_e;
        let pole = Wgs84.ecef_to_geodetic(&r(c.t_pole()));
        assert!((pole.lat.to_degrees() - 90.0).abs() < 1e-9, "{pole:?}");
        for (t, lon) in [(c.t0, 25.0), (c.end(), -155.0)] {
            let p = r(t);
            let rho = p.xy().norm();
            assert!((rho - 0.5 * c.duration * c.speed).abs() < 0.06, "{rho}");
            let g = Wgs84.ecef_to_geodetic(&p);
            assert!((g.lon.to_degrees() - lon).abs() < 1e-9, "{g:?}");
            assert!((g.h - 300.0).abs() < 1e-6, "{g:?}");
        }
    }

    /// The body is yawed into the velocity and the flight is level: the ECEF velocity
    /// in body axes has no sideways part (to round-off, 1e-9: the yaw is built from the
    /// velocity's components), nor one along the ellipsoid's normal beyond the tilt
    /// the weave's turn about x gives the turned level frame, at most `e² m` = 0.0067
    /// x 300 m / 6357 km = 3.2e-7 rad (measured 3e-8); and the speed is 70 m/s along
    /// plus the weave's 2π 300/120 = 15.7 m/s across at the pole.
    #[test]
    fn flies_nose_first_at_the_stated_speed() {
        let c = crossing();
        for t in [c.t0, 100.0, c.t_pole(), 437.0, c.end()] {
            let tr = analytic::ecef_truth(&Wgs84, &c.traj, t);
            let v_b = tr.c_be.transpose() * tr.v_e;
            assert!(v_b.y.abs() < 1e-9 * v_b.x, "{t}: {v_b}");
            let n = Wgs84.ecef_to_geodetic(&tr.r_e);
            let down = c_ne(n.lat, n.lon).column(2).into_owned();
            assert!(tr.v_e.dot(&down).abs() < 3.2e-7 * v_b.x, "{t}: climbing");
        }
        let v = analytic::ecef_truth(&Wgs84, &c.traj, c.t_pole()).v_e;
        let across = TAU * 300.0 / 120.0;
        assert!(
            (v.norm() - 70f64.hypot(across)).abs() < 1e-3,
            "{}",
            v.norm()
        );
    }

    /// The hand-over is the truth with the stated errors: position offset 1.5 m
    /// (through ECEF; height to the Earth's curvature under 1.4 m, 1.5e-7 m), velocity
    /// and attitude turned by the stated amounts (0.7' level, 3' heading) in space.
    #[test]
    fn start_carries_the_handover_errors() {
        let c = crossing();
        let (truth, start) = (c.truth(c.t0), c.start());
        let d = Wgs84.geodetic_to_ecef(&start.pos) - Wgs84.geodetic_to_ecef(&truth.pos);
        let d_n = c_ne(truth.pos.lat, truth.pos.lon).transpose() * d;
        assert!((d_n - c.handover.pos_n).norm() < 1e-6, "{d_n}");
        let e = schuler::analysis::errors::errors_between(&Wgs84, &start, &truth);
        assert!((e.pos_n - c.handover.pos_n).norm() < 1e-6, "{e:?}");
        assert!((e.v_n - c.handover.v_n).norm() < 1e-12, "{e:?}");
        assert!((e.psi - c.handover.psi).norm() < 1e-12, "{e:?}");
    }
}
