//! GNSS receiver and barometric altimeter models.
//!
//! GNSS: antenna position `r^e + C_eb l` (lever arm `l` in body axes, through ECEF) and
//! its velocity relative to the Earth, the derivative of that position,
//! `C_en (v_n + C_bn (ω_eb^b × l))` with `ω_eb^b = ω_ib^b − C_nb ω_ie^n` the body's rate
//! relative to the Earth (Groves 2013 §14.2.1, as the filter's measurement model has
//! it), resolved in NED at the fix's reported position as a receiver resolves its ECEF
//! solution; plus white noise per NED axis; no fix inside outage intervals; outliers
//! add a given jump at given epochs. The body's rate relative to NED, `ω_nb^b`, lacks
//! the transport rate `ω_en^n`, whose vertical part `v_E tan φ / (R_N + h)` grows
//! without bound near a pole (1e-2 rad/s at 89.8° and 70 m/s east), and the NED frames
//! at the body and at the antenna differ there by the meridian convergence over the
//! lever arm: both matter near a pole (mm/s at 89.8° for a 2-m arm) and nowhere else
//! (1e-5 m/s at 45°).
//! Barometer: true height plus bias, a linear drift, white noise; no reading inside
//! dropouts; outliers add a jump at given epochs.

use crate::earth::{EarthModel, Geodetic, c_ned_to_ned};
use crate::imu::random::Noise;
use crate::nav::NavState;
use nalgebra::Vector3;

/// A time interval `[start, end]` [s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Start [s].
    pub start: f64,
    /// End [s].
    pub end: f64,
}

impl Interval {
    /// Whether `t` lies in the interval.
    pub fn contains(&self, t: f64) -> bool {
        t >= self.start && t <= self.end
    }
}

/// An injected outlier: at the first epoch at or after `t`, add `jump` (NED metres for
/// GNSS positions, metres of height for the barometer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outlier<J> {
    /// Time [s].
    pub t: f64,
    /// The jump.
    pub jump: J,
}

/// GNSS receiver parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct GnssModel {
    /// Output interval [s].
    pub interval: f64,
    /// Position noise std, north, east, down [m].
    pub pos_std: Vector3<f64>,
    /// Velocity noise std, north, east, down [m/s].
    pub vel_std: Vector3<f64>,
    /// Antenna lever arm in body axes [m].
    pub lever_arm: Vector3<f64>,
    /// Time offset `τ` [s]: the fix of the instant `t` is stamped `t − τ`
    /// (`t_imu = t_gnss + τ`, as [`crate::filter::calibration`] estimates it).
    pub time_offset: f64,
    /// No fixes inside these intervals.
    pub outages: Vec<Interval>,
    /// Position jumps (NED metres).
    pub outliers: Vec<Outlier<Vector3<f64>>>,
}

/// One GNSS fix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssFix {
    /// Time [s].
    pub t: f64,
    /// Antenna position.
    pub pos: Geodetic,
    /// Antenna velocity NED [m/s].
    pub v_n: Vector3<f64>,
    /// Position std N, E, D [m] as the receiver reports it.
    pub pos_std: Vector3<f64>,
    /// Velocity std N, E, D [m/s].
    pub vel_std: Vector3<f64>,
    /// Whether an outlier was injected into this fix.
    pub outlier: bool,
}

/// Barometer parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct BaroModel {
    /// Output interval [s].
    pub interval: f64,
    /// Constant bias [m].
    pub bias: f64,
    /// Drift [m/s].
    pub drift: f64,
    /// White noise std [m].
    pub noise: f64,
    /// No readings inside these intervals.
    pub dropouts: Vec<Interval>,
    /// Height jumps [m].
    pub outliers: Vec<Outlier<f64>>,
}

/// One barometric height reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaroReading {
    /// Time [s].
    pub t: f64,
    /// Height [m].
    pub h: f64,
    /// Whether an outlier was injected.
    pub outlier: bool,
}

/// Stream ids (see `imu_model`).
const STREAM_GNSS: u64 = 2;
const STREAM_BARO: u64 = 3;

/// Outliers not yet applied, consumed in time order.
#[derive(Debug)]
struct Pending<J> {
    outliers: Vec<Outlier<J>>,
    next: usize,
}

impl<J: Copy> Pending<J> {
    fn new(mut outliers: Vec<Outlier<J>>) -> Self {
        outliers.sort_by(|a, b| a.t.total_cmp(&b.t));
        Self { outliers, next: 0 }
    }

    fn take(&mut self, t: f64) -> Option<J> {
        let o = self.outliers.get(self.next)?;
        if t >= o.t {
            self.next += 1;
            Some(o.jump)
        } else {
            None
        }
    }
}

/// A seeded GNSS receiver.
#[derive(Debug)]
pub struct GnssSimulator {
    model: GnssModel,
    noise: Noise,
    pending: Pending<Vector3<f64>>,
}

impl GnssSimulator {
    /// A receiver of `model` drawing from `seed`.
    pub fn new(model: GnssModel, seed: u64) -> Self {
        let pending = Pending::new(model.outliers.clone());
        Self {
            model,
            noise: Noise::new(seed, STREAM_GNSS),
            pending,
        }
    }

    /// The output interval [s].
    pub fn interval(&self) -> f64 {
        self.model.interval
    }

    /// The fix at truth `s` with the body's angular rate relative to NED `w_nb_b` (as
    /// `sim::run` has it), or `None` in an outage: [`GnssSimulator::fix_w_eb`] with the
    /// rate relative to the Earth `w_eb_b = w_nb_b + C_nb w_en_n` (the transport rate
    /// put back; singular exactly at a pole, as `w_nb_b` itself is).
    pub fn fix<E: EarthModel>(
        &mut self,
        earth: &E,
        s: &NavState,
        w_nb_b: &Vector3<f64>,
    ) -> Option<GnssFix> {
        let w_en_n = earth.local(s.pos.lat, s.pos.h).w_en_n(&s.v_n);
        self.fix_w_eb(earth, s, &(w_nb_b + s.q_bn.inverse() * w_en_n))
    }

    /// The fix at truth `s` with the body's angular rate relative to the Earth
    /// `w_eb_b = w_ib_b − C_nb w_ie_n` (defined at the poles), or `None` in an outage
    /// (module docs). Noise is drawn for every epoch, in or out of an outage, so
    /// outages do not shift the noise of later fixes.
    pub fn fix_w_eb<E: EarthModel>(
        &mut self,
        earth: &E,
        s: &NavState,
        w_eb_b: &Vector3<f64>,
    ) -> Option<GnssFix> {
        let m = &self.model;
        let n_pos = Vector3::new(
            self.noise.normal(),
            self.noise.normal(),
            self.noise.normal(),
        );
        let n_vel = Vector3::new(
            self.noise.normal(),
            self.noise.normal(),
            self.noise.normal(),
        );
        if m.outages.iter().any(|o| o.contains(s.t)) {
            return None;
        }
        let jump = self.pending.take(s.t);
        let c_bn = s.q_bn.to_rotation_matrix().into_inner();
        let d_n = c_bn * m.lever_arm + m.pos_std.component_mul(&n_pos) + jump.unwrap_or_default();
        let pos = offset_ned(earth, &s.pos, &d_n);
        // d/dt (r^e + C_eb l) in the body's NED, then turned into the fix's.
        let v_ant = s.v_n + c_bn * w_eb_b.cross(&m.lever_arm);
        let v_n = c_ned_to_ned(&s.pos, &pos) * v_ant + m.vel_std.component_mul(&n_vel);
        Some(GnssFix {
            t: s.t - m.time_offset,
            pos,
            v_n,
            pos_std: m.pos_std,
            vel_std: m.vel_std,
            outlier: jump.is_some(),
        })
    }
}

/// The position `d_n` metres (NED) from `p`, through ECEF (exact for any offset).
pub fn offset_ned<E: EarthModel>(earth: &E, p: &Geodetic, d_n: &Vector3<f64>) -> Geodetic {
    let r = earth.geodetic_to_ecef(p) + crate::earth::c_ne(p.lat, p.lon) * d_n;
    earth.ecef_to_geodetic(&r)
}

/// A seeded barometer.
#[derive(Debug)]
pub struct BaroSimulator {
    model: BaroModel,
    noise: Noise,
    pending: Pending<f64>,
}

impl BaroSimulator {
    /// A barometer of `model` drawing from `seed`.
    pub fn new(model: BaroModel, seed: u64) -> Self {
        let pending = Pending::new(model.outliers.clone());
        Self {
            model,
            noise: Noise::new(seed, STREAM_BARO),
            pending,
        }
    }

    /// The output interval [s].
    pub fn interval(&self) -> f64 {
        self.model.interval
    }

    /// The reading for true height `h` at time `t` (from `t0`, the start of the run),
    /// or `None` in a dropout.
    pub fn reading(&mut self, t: f64, t0: f64, h: f64) -> Option<BaroReading> {
        let m = &self.model;
        let w = self.noise.normal();
        if m.dropouts.iter().any(|d| d.contains(t)) {
            return None;
        }
        let jump = self.pending.take(t);
        Some(BaroReading {
            t,
            h: h + m.bias + m.drift * (t - t0) + m.noise * w + jump.unwrap_or(0.0),
            outlier: jump.is_some(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{Wgs84, c_ne};
    use crate::rotation::Euler;
    use approx::assert_relative_eq;

    fn state(t: f64) -> NavState {
        NavState::new(
            t,
            Geodetic::from_degrees(45.0, 7.0, 100.0),
            Vector3::new(10.0, 0.0, 0.0),
            Euler::from_degrees(0.0, 0.0, 90.0),
        )
    }

    /// Without noise, the antenna sits at the lever arm rotated into NED: a 1 m arm
    /// forward with the vehicle heading east puts the antenna 1 m east.
    #[test]
    fn lever_arm_without_noise() {
        let model = GnssModel {
            interval: 1.0,
            pos_std: Vector3::zeros(),
            vel_std: Vector3::zeros(),
            lever_arm: Vector3::new(1.0, 0.0, 0.0),
            time_offset: 0.0,
            outages: vec![],
            outliers: vec![],
        };
        let mut g = GnssSimulator::new(model, 1);
        let s = state(5.0);
        let fix = g
            .fix(&Wgs84, &s, &Vector3::new(0.0, 0.0, 0.1))
            .expect("fix");
        let d = crate::earth::c_ne(s.pos.lat, s.pos.lon).transpose()
            * (Wgs84.geodetic_to_ecef(&fix.pos) - Wgs84.geodetic_to_ecef(&s.pos));
        assert_relative_eq!(d, Vector3::new(0.0, 1.0, 0.0), epsilon = 1e-9);
        // Lever-arm velocity: yaw rate 0.1 rad/s x 1 m forward = 0.1 m/s to the
        // right of the nose, i.e. south when heading east (in the antenna's NED, turned
        // from the body's by the meridian convergence over 1 m east, 1.6e-7 rad: the
        // 9.9 m/s north shows 1.6e-6 m/s east).
        assert_relative_eq!(fix.v_n, Vector3::new(10.0 - 0.1, 0.0, 0.0), epsilon = 2e-6);
    }

    /// The antenna's velocity relative to the Earth is the derivative of its ECEF
    /// position `r_e + C_be l` along an exact trajectory (the maneuvering flight: 52 m/s
    /// circles drifting east at 20 m/s, ±25° roll, ±8° pitch; lever arm 1.5 m forward,
    /// 0.8 m left, 1.2 m up), taken on jets (exact) and checked by a four-point central
    /// difference over ±0.1 s (truncation below 1e-10 m/s, rounding of the 6.4e6-m
    /// coordinates 2e-8 m/s), resolved in NED at the fix's position, where a receiver
    /// resolves it. The fix gets the body rate relative to NED as `sim::run` passes
    /// it, and (`fix_w_eb`) the rate relative to the Earth. At 45° and at 89.8° (22 km
    /// from the pole, where the NED frame turns about down at `v_E tan φ / R` ≈ 1e-2
    /// rad/s), within 1e-9 m/s; the position to 1e-8 m. (Before the transport rate
    /// and the antenna's frame were taken into account: 1.2e-5 m/s off at 45°,
    /// 2.7e-3 m/s at 89.8°.)
    #[test]
    fn antenna_velocity_is_the_derivative_of_its_position() {
        use crate::sim::analytic::{self, Maneuvering, Trajectory};
        use crate::sim::jet::{self, Jet};
        let lever = Vector3::new(1.5, -0.8, -1.2);
        for lat in [45.0, 89.8] {
            let traj = Maneuvering::flight(Geodetic::from_degrees(lat, 25.0, 300.0));
            let model = GnssModel {
                interval: 1.0,
                pos_std: Vector3::zeros(),
                vel_std: Vector3::zeros(),
                lever_arm: lever,
                time_offset: 0.0,
                outages: vec![],
                outliers: vec![],
            };
            let mut g = GnssSimulator::new(model.clone(), 1);
            let mut g_eb = GnssSimulator::new(model, 1);
            let antenna = |t: Jet| {
                let (r, c_be) = traj.ecef_pose(&Wgs84, t);
                (
                    jet::value(&r) + c_be.value() * lever,
                    jet::derivative(&r) + c_be.derivative() * lever,
                )
            };
            for t in [10.0, 37.0, 95.0, 200.0] {
                let (s, kin) = analytic::evaluate(&Wgs84, &traj, t);
                let l = Wgs84.local(s.pos.lat, s.pos.h);
                let w_nb_b = kin.w_ib_b - s.q_bn.inverse() * (l.w_ie_n() + l.w_en_n(&s.v_n));
                let fix = g.fix(&Wgs84, &s, &w_nb_b).expect("fix");
                let w_eb_b = kin.w_ib_b - s.q_bn.inverse() * l.w_ie_n();
                let fix_eb = g_eb.fix_w_eb(&Wgs84, &s, &w_eb_b).expect("fix");
                assert_eq!(fix.pos, fix_eb.pos);
                assert!((fix.v_n - fix_eb.v_n).norm() < 1e-12, "{lat} {t}");
                let (r_a, v_a) = antenna(Jet::variable(t));
                let at = |dt: f64| antenna(Jet::constant(t + dt)).0;
                let h = 0.1;
                let fd = (at(-2.0 * h) - 8.0 * at(-h) + 8.0 * at(h) - at(2.0 * h)) / (12.0 * h);
                assert!((fd - v_a).norm() < 1e-7, "{lat} {t}: {fd} vs {v_a}");
                assert!(
                    (Wgs84.geodetic_to_ecef(&fix.pos) - r_a).norm() < 1e-8,
                    "{lat} {t}: position"
                );
                let v_n = c_ne(fix.pos.lat, fix.pos.lon).transpose() * v_a;
                assert!(
                    (fix.v_n - v_n).norm() < 1e-9,
                    "{lat} {t}: {} off by {:.3e} m/s",
                    fix.v_n,
                    (fix.v_n - v_n).norm()
                );
            }
        }
    }

    #[test]
    fn outages_and_outliers() {
        let model = GnssModel {
            interval: 1.0,
            pos_std: Vector3::zeros(),
            vel_std: Vector3::zeros(),
            lever_arm: Vector3::zeros(),
            time_offset: 0.0,
            outages: vec![Interval {
                start: 10.0,
                end: 20.0,
            }],
            outliers: vec![Outlier {
                t: 25.0,
                jump: Vector3::new(0.0, 0.0, -200.0),
            }],
        };
        let mut g = GnssSimulator::new(model, 1);
        assert!(g.fix(&Wgs84, &state(15.0), &Vector3::zeros()).is_none());
        let before = g.fix(&Wgs84, &state(24.0), &Vector3::zeros()).expect("fix");
        assert!(!before.outlier);
        let hit = g.fix(&Wgs84, &state(25.0), &Vector3::zeros()).expect("fix");
        assert!(hit.outlier);
        assert_relative_eq!(hit.pos.h, 300.0, epsilon = 1e-6);
        assert!(
            !g.fix(&Wgs84, &state(26.0), &Vector3::zeros())
                .expect("fix")
                .outlier
        );
    }

    #[test]
    fn baro_bias_drift_dropout() {
        let model = BaroModel {
            interval: 0.1,
            bias: 5.0,
            drift: 0.01,
            noise: 0.0,
            dropouts: vec![Interval {
                start: 100.0,
                end: 400.0,
            }],
            outliers: vec![],
        };
        let mut b = BaroSimulator::new(model, 1);
        let r = b.reading(50.0, 0.0, 1000.0).expect("reading");
        assert_relative_eq!(r.h, 1000.0 + 5.0 + 0.5, epsilon = 1e-12);
        assert!(b.reading(200.0, 0.0, 1000.0).is_none());
    }
}
