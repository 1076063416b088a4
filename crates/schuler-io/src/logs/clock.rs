//! The clock of an autopilot's log records (PX4 ULog, ArduPilot DataFlash): every
//! timestamp is the autopilot's clock, microseconds since boot. One GNSS fix ties that
//! clock to GPS time, and every device time maps by the offset `gps_µs − device_µs` of
//! that fix (one offset for the log: the autopilot's clock drifts by its crystal's
//! 10⁻⁵ at most, 10 ms per 1000 s). The fix gives GPS time either
//! - as UTC (ULog's `time_utc_usec`, microseconds since 1970, leap seconds not
//!   counted): `gps_µs = utc_µs − 315 964 800·10⁶ + (GPS − UTC)·10⁶`, GPS − UTC by
//!   [`crate::bag::clock::leap_seconds_at`] at the fix's date ([`GpsTie`],
//!   [`Clock::new`]); or
//! - as GPS week and milliseconds of week (DataFlash `GPS.GWk`, `GPS.GMS`):
//!   `gps_µs = week·604 800·10⁶ + ms·10³` ([`Clock::from_gps_us`]).
//!
//! All sums are in integer microseconds and turned into seconds once, by one correctly
//! rounded division by 10⁶, so the same file gives the same times bit for bit (and a
//! whole number of seconds exactly).

use crate::bag::clock::{GPS_EPOCH_UNIX, WEEK, leap_seconds_at};
use crate::logs::TimeScale;

/// Microseconds in a GPS week.
const WEEK_US: i64 = WEEK * 1_000_000;

/// The first GNSS message with a fix and a UTC time: the device and UTC times it pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GpsTie {
    /// The device time of the fix [µs since boot].
    pub device_us: u64,
    /// Its UTC [µs since 1970].
    pub utc_us: u64,
    /// GPS − UTC at that date [s].
    pub leap_s: i64,
}

impl GpsTie {
    /// The tie of a fix at `device_us` with UTC `utc_us`; `None` when `utc_us` is before
    /// the GPS epoch (a receiver that has not resolved time writes 0).
    pub fn new(device_us: u64, utc_us: u64) -> Option<Self> {
        let unix_s = i64::try_from(utc_us / 1_000_000).ok()?;
        (unix_s > GPS_EPOCH_UNIX).then(|| Self {
            device_us,
            utc_us,
            leap_s: leap_seconds_at(unix_s),
        })
    }
}

/// Device microseconds to the run's seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Clock {
    /// Seconds since boot.
    Device,
    /// GPS seconds of `week`: `t = (device_µs + offset_µs − week·604 800·10⁶)·10⁻⁶`.
    Gps {
        /// GPS µs minus device µs.
        offset_us: i64,
        /// The GPS week of the log's start.
        week: u32,
    },
}

impl Clock {
    /// The clock of a log starting at device time `start_us`, tied by `tie` if any.
    pub fn new(start_us: u64, tie: Option<GpsTie>) -> Self {
        let Some(tie) = tie else {
            return Clock::Device;
        };
        let gps_us = i128::from(tie.utc_us) - i128::from(GPS_EPOCH_UNIX) * 1_000_000
            + i128::from(tie.leap_s) * 1_000_000;
        Self::tied(start_us, tie.device_us, gps_us)
    }

    /// The clock of a log starting at device time `start_us` whose fix at `device_us`
    /// was at `gps_us` microseconds since the GPS epoch (1980-01-06 00:00:00 GPS).
    pub fn from_gps_us(start_us: u64, device_us: u64, gps_us: u64) -> Self {
        Self::tied(start_us, device_us, i128::from(gps_us))
    }

    fn tied(start_us: u64, device_us: u64, gps_us: i128) -> Self {
        let offset = gps_us - i128::from(device_us);
        // The week of the log's start, or of the fix if the start maps before 1980.
        let start = i128::from(start_us) + offset;
        let start = if start >= 0 { start } else { gps_us };
        let week = start.div_euclid(i128::from(WEEK_US));
        match (i64::try_from(offset), u32::try_from(week)) {
            (Ok(offset_us), Ok(week)) => Clock::Gps { offset_us, week },
            _ => Clock::Device,
        }
    }

    /// The run's time [s] of device time `us`.
    pub fn seconds(&self, us: u64) -> f64 {
        match *self {
            Clock::Device => us as f64 / 1e6,
            Clock::Gps { offset_us, week } => {
                let t =
                    i128::from(us) + i128::from(offset_us) - i128::from(week) * i128::from(WEEK_US);
                t as f64 / 1e6
            }
        }
    }

    /// The time scale for [`crate::logs::LogReader::time_scale`].
    pub fn scale(&self) -> TimeScale {
        match *self {
            Clock::Device => TimeScale::Device,
            Clock::Gps { week, .. } => TimeScale::GpsSecondsOfWeek { week },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2023-11-14 22:13:20 UTC (UNIX 1 700 000 000) is GPS week 2288, second
    /// 2·86 400 + 80 000 + 18 (see `bag::clock`'s test); a record 1.5 s of device time
    /// after the fix is 1.5 s later.
    #[test]
    fn a_fix_ties_device_time_to_gps_seconds_of_week() {
        let tie = GpsTie::new(50_000_000, 1_700_000_000_000_000).expect("valid");
        assert_eq!(tie.leap_s, 18);
        let c = Clock::new(10_000_000, Some(tie));
        assert_eq!(c.scale(), TimeScale::GpsSecondsOfWeek { week: 2288 });
        let sow = 2.0 * 86_400.0 + 80_000.0 + 18.0;
        assert_eq!(c.seconds(50_000_000), sow);
        assert_eq!(c.seconds(51_500_000), sow + 1.5);
        assert_eq!(GpsTie::new(1, 0), None);
        assert_eq!(Clock::new(0, None).seconds(2_500_000), 2.5);
        // The same instant given as GPS week 2288 and milliseconds of week.
        let ms = (2 * 86_400 + 80_000 + 18) * 1000;
        let g = Clock::from_gps_us(
            10_000_000,
            50_000_000,
            2288 * WEEK as u64 * 1_000_000 + ms * 1000,
        );
        assert_eq!(g, c);
    }
}
