//! The physical domain of every navigation input: the ranges a value can take for a
//! vehicle on or near the Earth and a sensor that exists, checked at the edges (file
//! readers, flags, configurations) so that a typo or a corrupt row is refused by name
//! instead of being integrated into NaN or a position thousands of kilometres away.
//!
//! Each [`Domain`] is stated in SI with the unit its messages use and the reason for
//! its bounds; [`Domain::check`] returns the value or a [`DomainError`] saying what was
//! read, the range and why.

use std::fmt;

use crate::units::{DEG, G0};

/// A closed range `[min, max]` of one physical quantity [SI], with its display unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    /// What the quantity is ("latitude", "angular rate").
    pub quantity: &'static str,
    /// Smallest value allowed [SI].
    pub min: f64,
    /// Largest value allowed [SI].
    pub max: f64,
    /// The unit messages print the value in.
    pub unit: &'static str,
    /// SI value of one display unit.
    pub scale: f64,
    /// Why the bounds are where they are.
    pub why: &'static str,
}

/// A value outside its [`Domain`] (or not finite).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DomainError {
    /// The domain that refused it.
    pub domain: Domain,
    /// The value read [SI].
    pub value: f64,
}

/// `v` in plain decimals, or in exponent form from 1e9 up and below 1e-6.
fn number(v: f64) -> String {
    if v.is_finite() && (v.abs() >= 1e9 || (v != 0.0 && v.abs() < 1e-6)) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

impl fmt::Display for DomainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = &self.domain;
        let show = |v: f64| number(v / d.scale);
        // A lower bound of the smallest positive number reads as an open 0.
        let lower = if d.min == f64::MIN_POSITIVE {
            "(0".to_owned()
        } else {
            format!("[{}", show(d.min))
        };
        write!(
            f,
            "{} {} {} is outside {lower}, {}] {} ({})",
            d.quantity,
            show(self.value),
            d.unit,
            show(d.max),
            d.unit,
            d.why
        )
    }
}

impl std::error::Error for DomainError {}

impl Domain {
    /// `value` [SI] if it is finite and within `[min, max]`.
    pub fn check(&self, value: f64) -> Result<f64, DomainError> {
        if value.is_finite() && value >= self.min && value <= self.max {
            Ok(value)
        } else {
            Err(DomainError {
                domain: *self,
                value,
            })
        }
    }

    /// [`Self::check`] of a value given in the display unit; returns it in SI.
    pub fn check_in_unit(&self, value: f64) -> Result<f64, DomainError> {
        self.check(value * self.scale)
    }
}

/// Geodetic latitude [rad].
pub const LATITUDE: Domain = Domain {
    quantity: "latitude",
    min: -90.0 * DEG,
    max: 90.0 * DEG,
    unit: "deg",
    scale: DEG,
    why: "a geodetic latitude",
};

/// Longitude [rad] as read: (-180, 180] or [0, 360), then wrapped by
/// [`wrap_longitude`]; anything else is refused, not wrapped, since 400 deg is a typo
/// more often than a turn and a half.
pub const LONGITUDE: Domain = Domain {
    quantity: "longitude",
    min: -180.0 * DEG,
    max: 360.0 * DEG,
    unit: "deg",
    scale: DEG,
    why: "east longitude, -180 to 180 or 0 to 360",
};

/// Ellipsoidal height [m]: from below the deepest ocean trench (11 km) to a lunar
/// distance's quarter; an inertial solution beyond is no longer about the Earth.
pub const HEIGHT: Domain = Domain {
    quantity: "height",
    min: -12e3,
    max: 1e8,
    unit: "m",
    scale: 1.0,
    why: "below the deepest trench or beyond 1e5 km",
};

/// Speed (a velocity component or magnitude) [m/s]: escape velocity is 11.2 km/s.
pub const SPEED: Domain = Domain {
    quantity: "speed",
    min: -12e3,
    max: 12e3,
    unit: "m/s",
    scale: 1.0,
    why: "faster than the Earth's escape velocity",
};

/// Angular rate magnitude a gyro can report [rad/s]: MEMS gyros end at 4000-6000
/// deg/s; 20 000 deg/s (55 turns a second) covers spin-stabilised projectiles' sensors.
pub const ANGULAR_RATE: Domain = Domain {
    quantity: "angular rate",
    min: 0.0,
    max: 20_000.0 * DEG,
    unit: "deg/s",
    scale: DEG,
    why: "beyond any gyro's range; columns swapped or units wrong?",
};

/// Specific force magnitude an accelerometer can report [m/s²]: shock-rated MEMS
/// parts end near 10 000 g; tactical and navigation grades at 50 g.
pub const SPECIFIC_FORCE: Domain = Domain {
    quantity: "specific force",
    min: 0.0,
    max: 10_000.0 * G0,
    unit: "g",
    scale: G0,
    why: "beyond any accelerometer's range; columns swapped or units wrong?",
};

/// One axis of an angular rate [rad/s] (a gyro bias, a reading), either sign: within
/// [`ANGULAR_RATE`]'s bound.
pub const ANGULAR_RATE_COMPONENT: Domain = Domain {
    min: -ANGULAR_RATE.max,
    ..ANGULAR_RATE
};

/// One axis of a specific force [m/s²] (an accelerometer bias), either sign: within
/// [`SPECIFIC_FORCE`]'s bound.
pub const SPECIFIC_FORCE_COMPONENT: Domain = Domain {
    min: -SPECIFIC_FORCE.max,
    ..SPECIFIC_FORCE
};

/// Interval between two IMU samples [s]: the increments after a gap are the sensor's
/// over its own short interval while the step is the whole gap, so the gap is
/// integrated as free fall: over a minute that is kilometres (g t²/2 = 18 km), and a
/// clock jump of years is a corrupt stamp.
pub const IMU_INTERVAL: Domain = Domain {
    quantity: "IMU sample interval",
    min: 0.0,
    max: 60.0,
    unit: "s",
    scale: 1.0,
    why: "a gap no single integration step spans; cut the log there (--start/--end)",
};

/// A standard deviation of a position [m]: positive; 10 000 km is "unknown".
pub const POSITION_STD: Domain = Domain {
    quantity: "position standard deviation",
    min: f64::MIN_POSITIVE,
    max: 1e7,
    unit: "m",
    scale: 1.0,
    why: "positive, and at most the Earth's quadrant",
};

/// A standard deviation of a velocity [m/s]: positive, at most [`SPEED`]'s bound.
pub const VELOCITY_STD: Domain = Domain {
    quantity: "velocity standard deviation",
    min: f64::MIN_POSITIVE,
    max: 12e3,
    unit: "m/s",
    scale: 1.0,
    why: "positive, and at most the escape velocity",
};

/// A standard deviation of an angle [rad]: positive, at most a full turn (a heading
/// known to no better than that is unknown).
pub const ANGLE_STD: Domain = Domain {
    quantity: "angle standard deviation",
    min: f64::MIN_POSITIVE,
    max: 360.0 * DEG,
    unit: "deg",
    scale: DEG,
    why: "positive, and at most a full turn",
};

/// A scale-factor error or its standard deviation [1]: a sensor reading double or
/// nothing of the truth is not calibrated, it is broken.
pub const SCALE_FACTOR: Domain = Domain {
    quantity: "scale factor",
    min: -1.0,
    max: 1.0,
    unit: "",
    scale: 1.0,
    why: "at most 100 %",
};

/// One component of a lever arm [m] (antenna, wheel or baseline from the IMU): the
/// largest vehicles that carry an IMU are a few hundred metres long.
pub const LEVER_ARM: Domain = Domain {
    quantity: "lever arm",
    min: -1000.0,
    max: 1000.0,
    unit: "m",
    scale: 1.0,
    why: "longer than any vehicle",
};

/// Longitude [rad] after [`wrap_longitude`]: (-180, 180] deg.
pub const LONGITUDE_WRAPPED: Domain = Domain {
    min: -180.0 * DEG,
    max: 180.0 * DEG,
    why: "east longitude after wrapping, -180 to 180",
    ..LONGITUDE
};

/// A heading or yaw reading [rad], in either convention (-180..180 or 0..360 deg) and
/// a turn beyond for an unwrapped one; anything larger is not an angle read in degrees.
pub const HEADING: Domain = Domain {
    quantity: "heading",
    min: -360.0 * DEG,
    max: 720.0 * DEG,
    unit: "deg",
    scale: DEG,
    why: "a heading in degrees, -360 to 720",
};

/// A pitch angle [rad].
pub const PITCH: Domain = Domain {
    quantity: "pitch",
    min: -90.0 * DEG,
    max: 90.0 * DEG,
    unit: "deg",
    scale: DEG,
    why: "a pitch angle",
};

/// Longitude [rad] checked by [`LONGITUDE`] and wrapped into (-π, π].
pub fn wrap_longitude(lon: f64) -> Result<f64, DomainError> {
    let lon = LONGITUDE.check(lon)?;
    Ok(if lon > std::f64::consts::PI {
        lon - 2.0 * std::f64::consts::PI
    } else {
        lon
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_and_messages() {
        assert_eq!(LATITUDE.check_in_unit(90.0), Ok(90.0 * DEG));
        let e = LATITUDE.check_in_unit(90.5).expect_err("beyond the pole");
        assert_eq!(
            e.to_string(),
            "latitude 90.5 deg is outside [-90, 90] deg (a geodetic latitude)"
        );
        assert!(HEIGHT.check(f64::NAN).is_err());
        assert!(HEIGHT.check(-1e7).is_err());
        let std = POSITION_STD.check(0.0).expect_err("zero");
        assert!(
            std.to_string().contains("0 m is outside (0, 10000000] m"),
            "{std}"
        );
        assert!(POSITION_STD.check(1e308).is_err());
        let rate = ANGULAR_RATE.check(1e6).expect_err("1e6 rad/s");
        assert!(
            rate.to_string()
                .contains("deg/s is outside [0, 20000] deg/s"),
            "{rate}"
        );
    }

    #[test]
    fn longitudes_wrap_from_0_360_and_refuse_beyond() {
        let w = |deg: f64| wrap_longitude(deg * DEG).map(|r| r / DEG);
        assert_eq!(w(-180.0), Ok(-180.0));
        assert_eq!(w(180.0), Ok(180.0));
        assert!((w(270.0).expect("0-360") + 90.0).abs() < 1e-12);
        assert!(w(400.0).is_err());
        assert!(w(-181.0).is_err());
    }
}
