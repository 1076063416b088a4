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
        // A finite SI value beyond the display unit's range (1e308 rad/s in deg/s)
        // prints as a bound, never as `inf`.
        let show = |v: f64| {
            let u = v / d.scale;
            if u.is_finite() || !v.is_finite() {
                number(u)
            } else {
                format!("{}1.8e308", if u < 0.0 { "below -" } else { "above " })
            }
        };
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

/// A pseudorange [m]: a satellite of any system is 19 000–42 000 km from a receiver
/// on or near the Earth, plus the receiver clock's bias (within a few ms when it is
/// not steered); 100 km to 100 000 km holds every one.
pub const PSEUDORANGE: Domain = Domain {
    quantity: "pseudorange",
    min: 1e5,
    max: 1e8,
    unit: "m",
    scale: 1.0,
    why: "no satellite signal travels less than 100 km or more than 1e5 km",
};

/// A pseudorange rate [m/s]: a satellite's line-of-sight speed (below 1 km/s) plus
/// the receiver oscillator's frequency offset (c·1 ppm = 300 m/s); ±100 km/s is 300
/// ppm, beyond any oscillator that still tracks.
pub const RANGE_RATE: Domain = Domain {
    quantity: "pseudorange rate",
    min: -1e5,
    max: 1e5,
    unit: "m/s",
    scale: 1.0,
    why: "beyond 300 ppm of oscillator offset",
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

/// A GNSS time offset from the IMU's clock [s] (or its prior standard deviation):
/// receivers stamp within a second or two of the IMU on a shared clock; a minute off is
/// another time scale (GPS against UTC is 18 s, a time zone 3600 s), not an offset.
pub const GNSS_TIME_OFFSET: Domain = Domain {
    quantity: "GNSS time offset",
    min: -60.0,
    max: 60.0,
    unit: "s",
    scale: 1.0,
    why: "a minute off is another time scale, not an offset",
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

/// A time or a time offset [s] (a stamp, a shift between clocks): within three
/// centuries of its epoch (Unix, GPS or the log's start). At 1e10 s an f64 still
/// resolves 2 µs, a 10-kHz IMU's step a fiftieth; beyond, consecutive samples
/// collapse onto the same time.
pub const TIME: Domain = Domain {
    quantity: "time",
    min: -1e10,
    max: 1e10,
    unit: "s",
    scale: 1.0,
    why: "within three centuries of its epoch",
};

/// An IMU's sample rate [Hz]: at least one sample per [`IMU_INTERVAL`]'s longest step,
/// at most 10 kHz (navigation and tactical IMUs deliver 100 Hz to 2 kHz, the fastest
/// MEMS parts' output data rates end near 8 kHz). Beyond, a simulated or recorded
/// stream is gigabytes a minute and no strapdown step resolves anything more.
pub const IMU_RATE: Domain = Domain {
    quantity: "IMU sample rate",
    min: 1.0 / 60.0,
    max: 1e4,
    unit: "Hz",
    scale: 1.0,
    why: "one sample a minute to 10 kHz",
};

/// A GNSS receiver's fix rate [Hz]: positive, at most 100 Hz (the fastest survey and
/// automotive receivers output 20 to 100 Hz; the tracking loops update at 1 kHz, but
/// no receiver delivers positions that fast).
pub const GNSS_RATE: Domain = Domain {
    quantity: "GNSS fix rate",
    min: f64::MIN_POSITIVE,
    max: 100.0,
    unit: "Hz",
    scale: 1.0,
    why: "positive, at most 100 Hz, the fastest receivers' output",
};

/// An aiding sensor's reading rate [Hz] (barometer, odometer, heading): positive, at
/// most 1 kHz (barometers sample at 1 to 200 Hz, wheel encoders' speeds at up to a
/// few hundred).
pub const AID_RATE: Domain = Domain {
    quantity: "reading rate",
    min: f64::MIN_POSITIVE,
    max: 1e3,
    unit: "Hz",
    scale: 1.0,
    why: "positive, at most 1 kHz",
};

/// A standard deviation of an angular rate [rad/s] (a zero-rate update's noise, a gyro
/// bias's prior): positive, at most [`ANGULAR_RATE`]'s bound.
pub const ANGULAR_RATE_STD: Domain = Domain {
    quantity: "angular rate standard deviation",
    min: f64::MIN_POSITIVE,
    ..ANGULAR_RATE
};

/// A standard deviation of a specific force [m/s²] (an accelerometer bias's prior):
/// positive, at most [`SPECIFIC_FORCE`]'s bound.
pub const SPECIFIC_FORCE_STD: Domain = Domain {
    quantity: "specific force standard deviation",
    min: f64::MIN_POSITIVE,
    ..SPECIFIC_FORCE
};

/// An angle random walk [rad/√s] (a gyro's white noise density): zero (a perfect gyro)
/// up to a noise of the gyro's whole range over one second.
pub const ANGLE_RANDOM_WALK: Domain = Domain {
    quantity: "angle random walk",
    min: 0.0,
    max: ANGULAR_RATE.max,
    unit: "deg/sqrt(h)",
    scale: DEG / 60.0,
    why: "at most the gyro's range over one second",
};

/// A velocity random walk [m/s/√s] (an accelerometer's white noise density): zero up
/// to a noise of the accelerometer's whole range over one second.
pub const VELOCITY_RANDOM_WALK: Domain = Domain {
    quantity: "velocity random walk",
    min: 0.0,
    max: SPECIFIC_FORCE.max,
    unit: "m/s/sqrt(s)",
    scale: 1.0,
    why: "at most the accelerometer's range over one second",
};

/// A rate random walk [rad/s/√s] (a gyro bias's random walk or instability per
/// √s): zero up to the gyro's whole range reached within one second.
pub const RATE_RANDOM_WALK: Domain = Domain {
    quantity: "rate random walk",
    min: 0.0,
    max: ANGULAR_RATE.max,
    unit: "deg/s/sqrt(s)",
    scale: DEG,
    why: "at most the gyro's range within one second",
};

/// An acceleration random walk [m/s²/√s] (an accelerometer bias's random walk): zero
/// up to the accelerometer's whole range reached within one second.
pub const ACCELERATION_RANDOM_WALK: Domain = Domain {
    quantity: "acceleration random walk",
    min: 0.0,
    max: SPECIFIC_FORCE.max,
    unit: "m/s^2/sqrt(s)",
    scale: 1.0,
    why: "at most the accelerometer's range within one second",
};

/// A correlation time of a Gauss-Markov process [s] (a bias instability's): at least
/// one second, since a bias correlated over less is the white noise the random walks
/// (ARW, VRW) already model and its discrete process noise `2 sigma^2 / tau`
/// overflows as `tau` goes to 0; at most a century (beyond, the process is a random
/// walk over any run).
pub const CORRELATION_TIME: Domain = Domain {
    quantity: "correlation time",
    min: 1.0,
    max: 3.2e9,
    unit: "s",
    scale: 1.0,
    why: "one second to a century",
};

/// A count given by a user ("how many": runs, threads, samples in a row) with its
/// bounds: the one rule every count option goes through, so none reaches an
/// allocation or a thread pool unbounded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Count {
    /// What is counted ("runs").
    pub quantity: &'static str,
    /// Fewest allowed.
    pub min: u64,
    /// Most allowed.
    pub max: u64,
    /// Why the bound is where it is.
    pub why: &'static str,
}

/// A count outside its [`Count`] bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CountError {
    /// The bounds that refused it.
    pub count: Count,
    /// The count read.
    pub value: u64,
}

impl fmt::Display for CountError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.count;
        write!(
            f,
            "{} {} is outside [{}, {}] ({})",
            c.quantity, self.value, c.min, c.max, c.why
        )
    }
}

impl std::error::Error for CountError {}

impl Count {
    /// `value` if it is within `[min, max]`.
    pub fn check(&self, value: u64) -> Result<u64, CountError> {
        if (self.min..=self.max).contains(&value) {
            Ok(value)
        } else {
            Err(CountError {
                count: *self,
                value,
            })
        }
    }
}

/// The bound of every count of repetitions or samples a user asks for: 10 000. A
/// Monte-Carlo campaign of that many runs estimates a standard deviation to 0.7 %
/// (`1/sqrt(2N)`), past any use; what each repetition keeps (a run's row and NEES
/// series, tens of kB) then stays within hundreds of MB.
pub const COUNT_MAX: u64 = 10_000;

/// Monte-Carlo runs: 1 to [`COUNT_MAX`].
pub const RUNS: Count = Count {
    quantity: "number of runs",
    min: 1,
    max: COUNT_MAX,
    why: "at least one; 10 000 runs estimate a standard deviation to 0.7 %",
};

/// Consecutive readings (a detector's streak to reacquire): 1 to [`COUNT_MAX`].
pub const IN_A_ROW: Count = Count {
    quantity: "readings in a row",
    min: 1,
    max: COUNT_MAX,
    why: "at least one, at most 10 000",
};

/// Worker threads: 1 to 1024. The work is CPU-bound, so threads beyond the cores
/// only share them; 1024 is above any single machine's core count, and each thread
/// reserves its stack.
pub const THREADS: Count = Count {
    quantity: "number of threads",
    min: 1,
    max: 1024,
    why: "at least one; more threads than cores only share them",
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
    fn counts_and_rates_are_bounded() {
        assert_eq!(RUNS.check(1), Ok(1));
        let e = RUNS.check(4_294_967_296).expect_err("2^32 runs");
        assert!(
            e.to_string()
                .starts_with("number of runs 4294967296 is outside [1, 10000]"),
            "{e}"
        );
        assert!(RUNS.check(0).is_err());
        assert!(THREADS.check(99_999_999_999).is_err());
        assert!(IMU_RATE.check(1e6).is_err());
        assert!(GNSS_RATE.check(1e308).is_err());
        assert!(GNSS_RATE.check(0.0).is_err());
        assert!(CORRELATION_TIME.check(1e-30).is_err());
        assert!(ANGULAR_RATE_STD.check(0.0).is_err());
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
