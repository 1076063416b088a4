//! DataFlash messages to schuler's records: which messages schuler reads, the columns
//! it takes from each (by label, as ArduPilot's `LogStructure.h` files name them) and
//! their conversion.
//!
//! | message | columns | gives |
//! |---|---|---|
//! | `IMU` (`IMU2`, `IMU3` in logs before ArduPilot 4.1) | `GyrX..Z` [rad/s], `AccX..Z` [m/s²] | [`Decoded::Imu`] |
//! | `GPS` | `Status`, `GWk`, `GMS`, `Lat`, `Lng`, `Alt`, `Spd`, `GCrs`, `VZ` | [`Decoded::Gps`] |
//! | `GPA` | `HAcc`, `VAcc`, `SAcc`, `VV`, `AEl` (when present) | [`Decoded::Gpa`] |
//! | `BARO` (`BAR2`, `BAR3`) | `Alt` [m] | [`Decoded::Baro`] |
//! | `XKF1` (EKF3), `NKF1` (EKF2) | `Roll`, `Pitch`, `Yaw` [deg], `VN..VD`, `PN..PD` [m] | [`Decoded::Ekf`] |
//! | `ORGN` | `Type`, `Lat`, `Lng`, `Alt` | [`Decoded::Origin`] |
//!
//! Every record's time is its `TimeUS` (or `TimeMS` × 1000 in old logs), the autopilot's
//! microseconds since boot. ArduPilot's body frame is FRD and its navigation frame
//! NED, so no axis is turned. A message type schuler reads that lacks a column it
//! needs is refused ([`Decoder::new`]).

use super::format::{Field, Format};
use nalgebra::Vector3;
use schuler::earth::Geodetic;
use schuler::rotation::Euler;

/// What schuler reads from a message type, by its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// IMU samples.
    Imu,
    /// GNSS fixes.
    Gps,
    /// The accuracies of the GNSS fixes.
    Gpa,
    /// Barometric heights.
    Baro,
    /// The EKF's attitude, velocity and position (core given by the instance column).
    Ekf,
    /// The EKF's origin and the home position.
    Origin,
    /// Not read.
    Other,
}

/// The role of message `name`.
pub fn role_of(name: &str) -> Role {
    match name {
        "IMU" | "IMU2" | "IMU3" => Role::Imu,
        "GPS" => Role::Gps,
        "GPA" => Role::Gpa,
        "BARO" | "BAR2" | "BAR3" => Role::Baro,
        "XKF1" | "NKF1" => Role::Ekf,
        "ORGN" => Role::Origin,
        _ => Role::Other,
    }
}

/// A message's time column: `TimeUS` [µs], or `TimeMS` [ms] in old logs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimeField {
    field: Field,
    us_per_unit: i64,
}

impl TimeField {
    /// The time column of `f`, if it has one of integer type.
    pub fn of(f: &Format) -> Option<Self> {
        let (field, us_per_unit) = match f.field("TimeUS") {
            Some(t) => (t, 1),
            None => (f.field("TimeMS")?, 1000),
        };
        field.is_int().then_some(Self { field, us_per_unit })
    }

    /// The time [µs since boot]; `None` if negative.
    pub fn us(&self, body: &[u8]) -> Option<u64> {
        let v = self.field.int(body)?.checked_mul(self.us_per_unit)?;
        u64::try_from(v).ok()
    }
}

/// Decodes the messages of one type.
#[derive(Debug, Clone, PartialEq)]
pub enum Decoder {
    /// `IMU`.
    Imu {
        /// Time.
        t: TimeField,
        /// `GyrX`, `GyrY`, `GyrZ`.
        gyr: [Field; 3],
        /// `AccX`, `AccY`, `AccZ`.
        acc: [Field; 3],
    },
    /// `GPS`.
    Gps {
        /// Time.
        t: TimeField,
        /// `Status`, `GWk`, `GMS`, `Lat`, `Lng`, `Alt`, `Spd`, `GCrs`, `VZ`.
        f: [Field; 9],
    },
    /// `GPA`.
    Gpa {
        /// Time.
        t: TimeField,
        /// `HAcc`, `VAcc`, `SAcc`.
        acc: [Field; 3],
        /// `VV`, when present.
        vv: Option<Field>,
        /// `AEl`, when present.
        ael: Option<Field>,
    },
    /// `BARO`.
    Baro {
        /// Time.
        t: TimeField,
        /// `Alt`.
        alt: Field,
    },
    /// `XKF1`.
    Ekf {
        /// Time.
        t: TimeField,
        /// `Roll`, `Pitch`, `Yaw`, `VN`, `VE`, `VD`, `PN`, `PE`, `PD`.
        f: [Field; 9],
    },
    /// `ORGN`.
    Origin {
        /// `Type`, `Lat`, `Lng`, `Alt`.
        f: [Field; 4],
    },
    /// A message schuler does not read.
    Other,
}

/// A GNSS message's content.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gps {
    /// Time [µs since boot].
    pub us: u64,
    /// Fix status (0 no GPS, 1 no fix, 2 2-D, 3 3-D, 4 DGPS, 5 RTK float, 6 RTK fixed).
    pub status: i64,
    /// GPS week.
    pub week: i64,
    /// Milliseconds of the week.
    pub ms: i64,
    /// Latitude, longitude [deg].
    pub lat: f64,
    /// See `lat`.
    pub lon: f64,
    /// Height above mean sea level [m].
    pub alt: f64,
    /// Velocity north, east, down [m/s] from ground speed `Spd`, course `GCrs` and `VZ`.
    pub v_n: Vector3<f64>,
}

/// A GNSS accuracy message's content (`GPA`, written right after its `GPS`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gpa {
    /// Time [µs since boot] (that of its `GPS`).
    pub us: u64,
    /// Horizontal, vertical position and speed accuracy [m, m/s]; 0 when unknown.
    pub hacc: f64,
    /// See `hacc`.
    pub vacc: f64,
    /// See `hacc`.
    pub sacc: f64,
    /// Whether the vertical velocity is measured (`VV`; taken as measured without it).
    pub vv: bool,
    /// Height above the WGS 84 ellipsoid [m] (`AEl`, ArduPilot 4.5 on), when known.
    pub ellipsoid_h: Option<f64>,
}

/// A decoded message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Decoded {
    /// An IMU message: rates [rad/s] and specific force [m/s²], FRD.
    Imu {
        /// Time [µs since boot].
        us: u64,
        /// Angular rate.
        gyr: Vector3<f64>,
        /// Specific force.
        acc: Vector3<f64>,
    },
    /// A GNSS message.
    Gps(Gps),
    /// A GNSS accuracy message.
    Gpa(Gpa),
    /// A barometric height relative to the height at boot [m].
    Baro {
        /// Time [µs since boot].
        us: u64,
        /// Height.
        h: f64,
    },
    /// The EKF's solution.
    Ekf {
        /// Time [µs since boot].
        us: u64,
        /// Attitude, FRD to NED.
        att: Euler,
        /// Velocity north, east, down [m/s].
        v_n: Vector3<f64>,
        /// Position north, east, down of the EKF origin [m].
        p_n: Vector3<f64>,
    },
    /// An `ORGN` message.
    Origin {
        /// 0: the EKF origin, 1: the home position.
        ty: i64,
        /// Latitude, longitude [deg], height above mean sea level [m].
        lat: f64,
        /// See `lat`.
        lon: f64,
        /// See `lat`.
        alt: f64,
    },
}

/// A column schuler needs that the message lacks: `(field, message)`.
pub type Missing = (String, String);

impl Decoder {
    /// The decoder of format `f` (by its [`role_of`]); an error naming the first column
    /// it needs that `f` lacks.
    pub fn new(f: &Format) -> Result<Self, Missing> {
        let role = role_of(&f.name);
        if role == Role::Other {
            return Ok(Decoder::Other);
        }
        let col = |name: &str| -> Result<Field, Missing> {
            f.field(name).ok_or_else(|| {
                (
                    format!("{}.{name}", f.name),
                    format!(
                        "message {} (format {:?}) lacks the column {name} that schuler reads",
                        f.name, f.format
                    ),
                )
            })
        };
        let cols = |names: &[&str]| -> Result<Vec<Field>, Missing> {
            names.iter().map(|n| col(n)).collect()
        };
        let time = || -> Result<TimeField, Missing> {
            TimeField::of(f).ok_or_else(|| {
                (
                    format!("{}.TimeUS", f.name),
                    format!(
                        "message {} (format {:?}) has no integer TimeUS or TimeMS column",
                        f.name, f.format
                    ),
                )
            })
        };
        let arr = |v: Vec<Field>| -> [Field; 3] { [v[0], v[1], v[2]] };
        Ok(match role {
            Role::Imu => Decoder::Imu {
                t: time()?,
                gyr: arr(cols(&["GyrX", "GyrY", "GyrZ"])?),
                acc: arr(cols(&["AccX", "AccY", "AccZ"])?),
            },
            Role::Gps => {
                let v = cols(&[
                    "Status", "GWk", "GMS", "Lat", "Lng", "Alt", "Spd", "GCrs", "VZ",
                ])?;
                Decoder::Gps {
                    t: time()?,
                    f: std::array::from_fn(|i| v[i]),
                }
            }
            Role::Gpa => Decoder::Gpa {
                t: time()?,
                acc: arr(cols(&["HAcc", "VAcc", "SAcc"])?),
                vv: f.field("VV"),
                ael: f.field("AEl"),
            },
            Role::Baro => Decoder::Baro {
                t: time()?,
                alt: col("Alt")?,
            },
            Role::Ekf => {
                let v = cols(&["Roll", "Pitch", "Yaw", "VN", "VE", "VD", "PN", "PE", "PD"])?;
                Decoder::Ekf {
                    t: time()?,
                    f: std::array::from_fn(|i| v[i]),
                }
            }
            Role::Origin => {
                let v = cols(&["Type", "Lat", "Lng", "Alt"])?;
                Decoder::Origin {
                    f: std::array::from_fn(|i| v[i]),
                }
            }
            Role::Other => Decoder::Other,
        })
    }

    /// Decodes `body`: `Ok(None)` for a message schuler does not read, `Err(field)`
    /// naming a time column that is negative.
    pub fn decode(&self, name: &str, body: &[u8]) -> Result<Option<Decoded>, String> {
        let us = |t: &TimeField| t.us(body).ok_or_else(|| format!("{name}.TimeUS"));
        let v3 = |f: &[Field; 3]| Vector3::new(f[0].f64(body), f[1].f64(body), f[2].f64(body));
        let int = |f: &Field| f.int(body).unwrap_or_else(|| f.f64(body) as i64);
        Ok(Some(match self {
            Decoder::Imu { t, gyr, acc } => Decoded::Imu {
                us: us(t)?,
                gyr: v3(gyr),
                acc: v3(acc),
            },
            Decoder::Gps { t, f } => {
                let (spd, crs) = (f[6].f64(body), f[7].f64(body).to_radians());
                Decoded::Gps(Gps {
                    us: us(t)?,
                    status: int(&f[0]),
                    week: int(&f[1]),
                    ms: int(&f[2]),
                    lat: f[3].f64(body),
                    lon: f[4].f64(body),
                    alt: f[5].f64(body),
                    v_n: Vector3::new(spd * crs.cos(), spd * crs.sin(), f[8].f64(body)),
                })
            }
            Decoder::Gpa { t, acc, vv, ael } => Decoded::Gpa(Gpa {
                us: us(t)?,
                hacc: acc[0].f64(body),
                vacc: acc[1].f64(body),
                sacc: acc[2].f64(body),
                vv: vv.as_ref().is_none_or(|v| int(v) != 0),
                // INT32_MIN: unknown (AP_GPS/LogStructure.h).
                ellipsoid_h: ael
                    .filter(|a| a.int(body) != Some(i64::from(i32::MIN)))
                    .map(|a| a.f64(body)),
            }),
            Decoder::Baro { t, alt } => Decoded::Baro {
                us: us(t)?,
                h: alt.f64(body),
            },
            Decoder::Ekf { t, f } => {
                let g = |i: usize| f[i].f64(body);
                // Yaw is logged in [0, 360) deg; Euler's is (−180°, 180°].
                let yaw = if g(2) > 180.0 { g(2) - 360.0 } else { g(2) };
                Decoded::Ekf {
                    us: us(t)?,
                    att: Euler {
                        roll: g(0).to_radians(),
                        pitch: g(1).to_radians(),
                        yaw: yaw.to_radians(),
                    },
                    v_n: Vector3::new(g(3), g(4), g(5)),
                    p_n: Vector3::new(g(6), g(7), g(8)),
                }
            }
            Decoder::Origin { f } => Decoded::Origin {
                ty: int(&f[0]),
                lat: f[1].f64(body),
                lon: f[2].f64(body),
                alt: f[3].f64(body),
            },
            Decoder::Other => return Ok(None),
        }))
    }
}

/// ArduPilot's metres per 10⁻⁷ degree of latitude (`LATLON_TO_M`, a sphere of radius
/// 6 378 100 m: `2π · 6 378 100 / 360 · 10⁻⁷`).
pub const LATLON_TO_M: f64 = 0.011131884502145034;

/// The position `p_n` (north, east, down [m]) from an origin at `lat`, `lon` [deg] and
/// height `alt` [m], as ArduPilot itself turns its EKF's positions into locations
/// (`Location::offset`: a sphere, the longitude scale `cos` taken at the mean
/// latitude, at least 0.01), without its rounding to 10⁻⁷ degree; the height is the
/// origin's minus `PD`, above mean sea level as the origin's.
pub fn offset_location(lat: f64, lon: f64, alt: f64, p_n: &Vector3<f64>) -> Geodetic {
    let dlat = p_n.x / LATLON_TO_M * 1e-7;
    let scale = (lat + dlat / 2.0).to_radians().cos().max(0.01);
    let dlon = p_n.y / LATLON_TO_M * 1e-7 / scale;
    Geodetic::from_degrees(lat + dlat, lon + dlon, alt - p_n.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1 km north is 1000 / (6 378 100 · π/180) deg on ArduPilot's sphere; 1 km east at
    /// 60° is twice as many degrees of longitude (cos 60° = ½; the mean latitude of a
    /// due-east offset is the origin's).
    #[test]
    fn offsets_follow_ardupilots_sphere() {
        let deg_per_km = 1000.0 / (6_378_100.0 * std::f64::consts::PI / 180.0);
        let p = offset_location(0.0, 10.0, 100.0, &Vector3::new(1000.0, 0.0, -5.0));
        assert!((p.lat.to_degrees() - deg_per_km).abs() < 1e-12);
        assert_eq!(p.h, 105.0);
        let p = offset_location(60.0, 10.0, 0.0, &Vector3::new(0.0, 1000.0, 0.0));
        assert!((p.lon.to_degrees() - 10.0 - 2.0 * deg_per_km).abs() < 1e-9);
    }
}
