//! The PX4 topics schuler uses, decoded from a data message's payload into the
//! library's types (field names and units from PX4's `msg/*.msg` definitions; each
//! topic's fields found by name in the log's own format, so that the layouts of
//! different PX4 versions read alike).
//!
//! - `sensor_combined`: `gyro_rad[3]` [rad/s] and `accelerometer_m_s2[3]` [m/s²], the
//!   means over `gyro_integral_dt` and `accelerometer_integral_dt` (µs as `uint32_t`
//!   since PX4 1.9, s as `float` before); the gyro's time is `timestamp`, the
//!   accelerometer's `timestamp + accelerometer_timestamp_relative` (`0x7fffffff`:
//!   no accelerometer data). Increments: `Δθ = ω·dt_gyro`, `Δv = f·dt_accel` (each
//!   sensor's own interval, so the increments add up to the sensor's integral),
//!   stamped at the gyro's time with the gyro's interval. PX4's body frame is FRD.
//! - `vehicle_gps_position` / `sensor_gps`: `lat`, `lon` [1e-7 deg] and
//!   `alt_ellipsoid` [mm] (`latitude_deg`, `longitude_deg`, `altitude_ellipsoid_m`
//!   since PX4 1.14), `eph`, `epv` [m] taken as the north and east, and down standard
//!   deviations (as PX4's EKF2 takes them), `vel_n_m_s`, `vel_e_m_s`, `vel_d_m_s` when
//!   `vel_ned_valid`, with `s_variance_m_s` (a standard deviation [m/s] despite its
//!   name) on each axis; only 3-D fixes (`fix_type` ≥ 3) are records.
//! - `vehicle_air_data`: `baro_alt_meter` [m above mean sea level, standard atmosphere].
//! - `vehicle_attitude`: `q[4]` (w, x, y, z; Hamilton; body FRD to NED).
//! - `vehicle_global_position`: `lat`, `lon` [deg], `alt_ellipsoid` [m] (`alt`, above
//!   mean sea level, in logs without it), and `vel_n`, `vel_e`, `vel_d` in old logs.
//! - `vehicle_local_position`: `vx`, `vy`, `vz` [m/s, NED] when `v_xy_valid` and
//!   `v_z_valid` (logs before PX4 1.6 have no such flags: always).
//!
//! Each record's device time is `timestamp_sample` where the topic has it (the
//! sensor's sampling time, PX4 1.12 on) and it is not 0, else `timestamp`.

use super::format::{BaseType, Layout, int_at, value_at};
use crate::logs::{LogRecord, ReferenceSample, StreamKind};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::imu::ImuSample;
use schuler::rotation::Euler;

/// `accelerometer_timestamp_relative` of a sample without accelerometer data.
const RELATIVE_TIMESTAMP_INVALID: i128 = 0x7fff_ffff;

/// A scalar field's place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct F {
    ty: BaseType,
    offset: usize,
}

impl F {
    #[inline]
    fn f(self, p: &[u8]) -> f64 {
        value_at(p, self.ty, self.offset)
    }
    #[inline]
    fn i(self, p: &[u8]) -> i128 {
        int_at(p, self.ty, self.offset)
    }
    #[inline]
    fn u64(self, p: &[u8]) -> u64 {
        u64::try_from(self.i(p)).unwrap_or(0)
    }
    /// Element `k` of an array field.
    fn at(self, k: usize) -> F {
        F {
            ty: self.ty,
            offset: self.offset + k * self.ty.size(),
        }
    }
}

/// A decoder's fields, found in a topic's layout.
struct Finder<'a> {
    layout: &'a Layout,
    topic: &'a str,
}

impl Finder<'_> {
    fn opt(&self, name: &str, min_array: usize) -> Option<F> {
        self.layout
            .field(name)
            .filter(|f| f.array >= min_array && (min_array > 0 || f.array == 0))
            .map(|f| F {
                ty: f.ty,
                offset: f.offset,
            })
    }
    fn req(&self, name: &str, min_array: usize) -> Result<F, (String, String)> {
        self.opt(name, min_array).ok_or_else(|| {
            let shape = if min_array > 0 {
                format!("an array of {min_array} or more")
            } else {
                "a scalar".to_owned()
            };
            (
                name.to_owned(),
                format!("topic {} has no field {name} ({shape})", self.topic),
            )
        })
    }
    /// `timestamp_sample` if the topic has it, and `timestamp`.
    fn times(&self) -> Result<Times, (String, String)> {
        Ok(Times {
            sample: self.opt("timestamp_sample", 0),
            stamp: self.req("timestamp", 0)?,
        })
    }
}

/// A record's device time fields.
#[derive(Debug, Clone, Copy)]
struct Times {
    sample: Option<F>,
    stamp: F,
}

impl Times {
    fn us(&self, p: &[u8]) -> u64 {
        match self.sample.map(|f| f.u64(p)) {
            Some(t) if t != 0 => t,
            _ => self.stamp.u64(p),
        }
    }
}

/// How the data messages of one subscription are decoded.
#[derive(Debug, Clone)]
pub enum Decoder {
    /// `sensor_combined`.
    Imu(ImuFields),
    /// `vehicle_gps_position` or `sensor_gps`.
    Gnss(GnssFields),
    /// `vehicle_air_data`.
    Baro(BaroFields),
    /// `vehicle_attitude`.
    Attitude(AttitudeFields),
    /// `vehicle_global_position`.
    Global(GlobalFields),
    /// `vehicle_local_position`.
    Local(LocalFields),
    /// Any other topic (listed, not decoded).
    Other,
}

/// A decoded data message: a record with its device time [µs], or why none.
#[derive(Debug, Clone, PartialEq)]
pub enum Decoded {
    /// A record whose time is to be set from `us` (it holds 0 until then).
    Record {
        /// Device time [µs].
        us: u64,
        /// The record, its time field still to be set.
        record: LogRecord,
    },
    /// An IMU sample; its interval [µs, rounded] for the continuity check.
    Imu {
        /// Device time [µs].
        us: u64,
        /// The gyro's integration interval [s].
        dt: f64,
        /// The increments (time set later).
        sample: ImuSample,
    },
    /// A GNSS message; the fix when it is a 3-D one, and its UTC [µs since 1970].
    Gnss {
        /// Device time [µs].
        us: u64,
        /// `time_utc_usec`.
        utc_us: u64,
        /// The fix, `None` below a 3-D fix or without standard deviations.
        fix: Option<GnssFix>,
    },
    /// The message holds no usable record (reason for the report).
    Skipped(Skip),
}

/// Why a message gave no record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Skip {
    /// An IMU sample without accelerometer data or with a zero interval.
    ImuIncomplete,
    /// A reference sample that is not valid (zero quaternion, invalid velocity).
    ReferenceInvalid,
}

impl Decoder {
    /// The decoder of topic `name`, instance `multi_id`, with layout `layout`;
    /// `gnss_topic` is the topic read as GNSS fixes. `Err((field, message))` when a
    /// topic schuler uses lacks a field it needs.
    pub fn new(
        name: &str,
        multi_id: u8,
        layout: &Layout,
        gnss_topic: &str,
    ) -> Result<Self, (String, String)> {
        let f = Finder {
            layout,
            topic: name,
        };
        if multi_id != 0 {
            return Ok(Decoder::Other);
        }
        Ok(match name {
            "sensor_combined" => Decoder::Imu(ImuFields {
                t: f.req("timestamp", 0)?,
                gyro: f.req("gyro_rad", 3)?,
                gyro_dt: f.req("gyro_integral_dt", 0)?,
                accel: f.req("accelerometer_m_s2", 3)?,
                accel_dt: f.req("accelerometer_integral_dt", 0)?,
                accel_rel: f.req("accelerometer_timestamp_relative", 0)?,
            }),
            n if n == gnss_topic => Decoder::Gnss(GnssFields::new(&f)?),
            "vehicle_air_data" => Decoder::Baro(BaroFields {
                t: f.times()?,
                alt: f.req("baro_alt_meter", 0)?,
            }),
            "vehicle_attitude" => Decoder::Attitude(AttitudeFields {
                t: f.times()?,
                q: f.req("q", 4)?,
            }),
            "vehicle_global_position" => Decoder::Global(GlobalFields {
                t: f.times()?,
                lat: f.req("lat", 0)?,
                lon: f.req("lon", 0)?,
                alt: f
                    .opt("alt_ellipsoid", 0)
                    .map_or_else(|| f.req("alt", 0), Ok)?,
                vel: match (f.opt("vel_n", 0), f.opt("vel_e", 0), f.opt("vel_d", 0)) {
                    (Some(n), Some(e), Some(d)) => Some([n, e, d]),
                    _ => None,
                },
            }),
            "vehicle_local_position" => Decoder::Local(LocalFields {
                t: f.times()?,
                v: [f.req("vx", 0)?, f.req("vy", 0)?, f.req("vz", 0)?],
                xy_valid: f.opt("v_xy_valid", 0),
                z_valid: f.opt("v_z_valid", 0),
            }),
            _ => Decoder::Other,
        })
    }

    /// What kind of stream this decoder gives.
    pub fn kind(&self) -> StreamKind {
        match self {
            Decoder::Imu(_) => StreamKind::Imu,
            Decoder::Gnss(_) => StreamKind::Gnss,
            Decoder::Baro(_) => StreamKind::Baro,
            Decoder::Attitude(_) | Decoder::Global(_) | Decoder::Local(_) => StreamKind::Reference,
            Decoder::Other => StreamKind::Other,
        }
    }

    /// Decodes payload `p` (its length checked against the layout); `None` for
    /// [`Decoder::Other`].
    pub fn decode(&self, p: &[u8]) -> Option<Decoded> {
        Some(match self {
            Decoder::Imu(f) => f.decode(p),
            Decoder::Gnss(f) => f.decode(p),
            Decoder::Baro(f) => Decoded::Record {
                us: f.t.us(p),
                record: LogRecord::Baro {
                    t: 0.0,
                    h: f.alt.f(p),
                },
            },
            Decoder::Attitude(f) => f.decode(p),
            Decoder::Global(f) => f.decode(p),
            Decoder::Local(f) => f.decode(p),
            Decoder::Other => return None,
        })
    }
}

/// `sensor_combined`'s fields.
#[derive(Debug, Clone)]
pub struct ImuFields {
    t: F,
    gyro: F,
    gyro_dt: F,
    accel: F,
    accel_dt: F,
    accel_rel: F,
}

/// An integration interval [s]: µs as an integer type, seconds as a float.
fn interval(f: F, p: &[u8]) -> f64 {
    if f.ty.is_float() {
        f.f(p)
    } else {
        f.f(p) / 1e6
    }
}

fn vec3(f: F, p: &[u8]) -> Vector3<f64> {
    Vector3::new(f.at(0).f(p), f.at(1).f(p), f.at(2).f(p))
}

impl ImuFields {
    fn decode(&self, p: &[u8]) -> Decoded {
        let dt = interval(self.gyro_dt, p);
        let dt_a = interval(self.accel_dt, p);
        let valid = self.accel_rel.i(p) != RELATIVE_TIMESTAMP_INVALID;
        if !(valid && dt > 0.0 && dt_a > 0.0) {
            return Decoded::Skipped(Skip::ImuIncomplete);
        }
        Decoded::Imu {
            us: self.t.u64(p),
            dt,
            sample: ImuSample {
                t: 0.0,
                dt,
                dtheta: vec3(self.gyro, p) * dt,
                dvel: vec3(self.accel, p) * dt_a,
            },
        }
    }
}

/// The GNSS topic's fields.
#[derive(Debug, Clone)]
pub struct GnssFields {
    t: Times,
    utc: F,
    /// Latitude, longitude and their units per degree.
    lat: F,
    lon: F,
    per_deg: f64,
    /// Ellipsoidal height and its units per metre.
    h: F,
    per_metre: f64,
    eph: F,
    epv: F,
    s: F,
    vel: [F; 3],
    vel_valid: F,
    fix_type: F,
}

impl GnssFields {
    fn new(f: &Finder<'_>) -> Result<Self, (String, String)> {
        let (lat, lon, per_deg, h, per_metre) = match f.opt("latitude_deg", 0) {
            Some(lat) => (
                lat,
                f.req("longitude_deg", 0)?,
                1.0,
                f.req("altitude_ellipsoid_m", 0)?,
                1.0,
            ),
            None => (
                f.req("lat", 0)?,
                f.req("lon", 0)?,
                1e7,
                f.req("alt_ellipsoid", 0)?,
                1e3,
            ),
        };
        Ok(Self {
            t: f.times()?,
            utc: f.req("time_utc_usec", 0)?,
            lat,
            lon,
            per_deg,
            h,
            per_metre,
            eph: f.req("eph", 0)?,
            epv: f.req("epv", 0)?,
            s: f.req("s_variance_m_s", 0)?,
            vel: [
                f.req("vel_n_m_s", 0)?,
                f.req("vel_e_m_s", 0)?,
                f.req("vel_d_m_s", 0)?,
            ],
            vel_valid: f.req("vel_ned_valid", 0)?,
            fix_type: f.req("fix_type", 0)?,
        })
    }

    fn decode(&self, p: &[u8]) -> Decoded {
        let us = self.t.us(p);
        let utc_us = self.utc.u64(p);
        let (eph, epv) = (self.eph.f(p), self.epv.f(p));
        let fix = (self.fix_type.i(p) >= 3 && eph > 0.0 && epv > 0.0).then(|| {
            let s = self.s.f(p);
            let vel = (self.vel_valid.i(p) != 0 && s > 0.0).then(|| {
                (
                    Vector3::new(self.vel[0].f(p), self.vel[1].f(p), self.vel[2].f(p)),
                    Vector3::repeat(s),
                )
            });
            GnssFix {
                t: 0.0,
                pos: Geodetic::new(
                    (self.lat.f(p) / self.per_deg).to_radians(),
                    (self.lon.f(p) / self.per_deg).to_radians(),
                    self.h.f(p) / self.per_metre,
                ),
                pos_std: Vector3::new(eph, eph, epv),
                vel,
            }
        });
        Decoded::Gnss { us, utc_us, fix }
    }
}

/// `vehicle_air_data`'s fields.
#[derive(Debug, Clone)]
pub struct BaroFields {
    t: Times,
    alt: F,
}

/// `vehicle_attitude`'s fields.
#[derive(Debug, Clone)]
pub struct AttitudeFields {
    t: Times,
    q: F,
}

impl AttitudeFields {
    fn decode(&self, p: &[u8]) -> Decoded {
        let q = Quaternion::new(
            self.q.at(0).f(p),
            self.q.at(1).f(p),
            self.q.at(2).f(p),
            self.q.at(3).f(p),
        );
        let n = q.norm();
        if !(n.is_finite() && n > 0.5) {
            return Decoded::Skipped(Skip::ReferenceInvalid);
        }
        let q_bn = UnitQuaternion::new_normalize(q);
        Decoded::Record {
            us: self.t.us(p),
            record: LogRecord::Reference(ReferenceSample {
                t: 0.0,
                pos: None,
                v_n: None,
                att: Some(Euler::from_quaternion(&q_bn)),
            }),
        }
    }
}

/// `vehicle_global_position`'s fields.
#[derive(Debug, Clone)]
pub struct GlobalFields {
    t: Times,
    lat: F,
    lon: F,
    alt: F,
    vel: Option<[F; 3]>,
}

impl GlobalFields {
    fn decode(&self, p: &[u8]) -> Decoded {
        Decoded::Record {
            us: self.t.us(p),
            record: LogRecord::Reference(ReferenceSample {
                t: 0.0,
                pos: Some(Geodetic::new(
                    self.lat.f(p).to_radians(),
                    self.lon.f(p).to_radians(),
                    self.alt.f(p),
                )),
                v_n: self
                    .vel
                    .map(|v| Vector3::new(v[0].f(p), v[1].f(p), v[2].f(p))),
                att: None,
            }),
        }
    }
}

/// `vehicle_local_position`'s fields.
#[derive(Debug, Clone)]
pub struct LocalFields {
    t: Times,
    v: [F; 3],
    xy_valid: Option<F>,
    z_valid: Option<F>,
}

impl LocalFields {
    fn decode(&self, p: &[u8]) -> Decoded {
        let invalid = |f: Option<F>| f.is_some_and(|f| f.i(p) == 0);
        if invalid(self.xy_valid) || invalid(self.z_valid) {
            return Decoded::Skipped(Skip::ReferenceInvalid);
        }
        Decoded::Record {
            us: self.t.us(p),
            record: LogRecord::Reference(ReferenceSample {
                t: 0.0,
                pos: None,
                v_n: Some(Vector3::new(self.v[0].f(p), self.v[1].f(p), self.v[2].f(p))),
                att: None,
            }),
        }
    }
}

/// Sets the time of `record` to `t`.
pub fn set_time(record: &mut LogRecord, t: f64) {
    match record {
        LogRecord::Imu(s) => s.t = t,
        LogRecord::Gnss(f) => f.t = t,
        LogRecord::Baro { t: tb, .. } => *tb = t,
        LogRecord::Reference(r) => r.t = t,
        LogRecord::Raw(_) | LogRecord::Ephemeris(_) => {}
    }
}
