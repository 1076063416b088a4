//! The clock of a bag's header stamps. ROS stamps are UNIX time (`sec`, `nanosec` since
//! 1970-01-01 UTC, leap seconds not counted); schuler's outputs are GPS time, week and
//! seconds of week as KF-GINS writes them. GPS time started at 1980-01-06 00:00:00 UTC
//! and counts every second, so `gps = unix − 315 964 800 + (GPS − UTC)`, where GPS − UTC
//! is the number of leap seconds inserted since 1980 ([`LEAP_SECONDS`]: 18 since
//! 2017-01-01, IERS Bulletin C). A stamp before the GPS epoch is no UNIX wall-clock
//! time (a simulator's clock, or time since boot): such stamps are read as they are.

/// 1980-01-06 00:00:00 UTC, GPS time's origin, in UNIX seconds.
pub const GPS_EPOCH_UNIX: i64 = 315_964_800;

/// Seconds in a GPS week.
pub const WEEK: i64 = 604_800;

/// GPS − UTC [s] from each UNIX time on (00:00:00 UTC of the day after each leap
/// second of IERS Bulletin C, 1981-07-01 to 2017-01-01).
pub const LEAP_SECONDS: [(i64, i64); 18] = [
    (362_793_600, 1),
    (394_329_600, 2),
    (425_865_600, 3),
    (489_024_000, 4),
    (567_993_600, 5),
    (631_152_000, 6),
    (662_688_000, 7),
    (709_948_800, 8),
    (741_484_800, 9),
    (773_020_800, 10),
    (820_454_400, 11),
    (867_715_200, 12),
    (915_148_800, 13),
    (1_136_073_600, 14),
    (1_230_768_000, 15),
    (1_341_100_800, 16),
    (1_435_708_800, 17),
    (1_483_228_800, 18),
];

/// GPS − UTC [s] at UNIX time `unix` [s] by [`LEAP_SECONDS`] (0 before 1981-07-01).
pub fn leap_seconds_at(unix: i64) -> i64 {
    LEAP_SECONDS
        .iter()
        .rev()
        .find(|(from, _)| unix >= *from)
        .map_or(0, |(_, n)| *n)
}

/// How a run reads its bag's stamps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StampClock {
    /// As they are: `sec + nanosec·10⁻⁹` (stamps before the GPS epoch).
    #[default]
    Raw,
    /// UNIX stamps as GPS seconds of `week` (past 604 800 in the weeks after it).
    Gps {
        /// The GPS week of the first IMU stamp.
        week: u32,
        /// GPS − UTC [s] given (`--leap-seconds`); `None`: [`LEAP_SECONDS`] at each stamp.
        leap: Option<i64>,
    },
}

impl StampClock {
    /// The clock of a bag whose first IMU stamp has `sec` UNIX seconds: GPS time of
    /// that stamp's week if it is after the GPS epoch, else the stamps as they are;
    /// `leap` overrides the table. `Err` when `leap` is given for stamps that are no
    /// UNIX time.
    pub fn of_first_stamp(sec: i64, leap: Option<i64>) -> Result<Self, String> {
        if sec < GPS_EPOCH_UNIX {
            return match leap {
                Some(n) => Err(format!(
                    "--leap-seconds {n} converts UNIX stamps to GPS time, and the first IMU \
                     stamp ({sec} s) is before 1980-01-06, the GPS epoch: no UNIX time"
                )),
                None => Ok(StampClock::Raw),
            };
        }
        let gps = sec - GPS_EPOCH_UNIX + leap.unwrap_or_else(|| leap_seconds_at(sec));
        let week = u32::try_from(gps.div_euclid(WEEK)).map_err(|e| e.to_string())?;
        Ok(StampClock::Gps { week, leap })
    }

    /// The GPS week of the run's time 0, if the stamps are UNIX time.
    pub fn week(&self) -> Option<u32> {
        match self {
            StampClock::Raw => None,
            StampClock::Gps { week, .. } => Some(*week),
        }
    }

    /// GPS − UTC [s] at UNIX time `unix`.
    fn leap(leap: Option<i64>, unix: i64) -> i64 {
        leap.unwrap_or_else(|| leap_seconds_at(unix))
    }

    /// The whole seconds of stamp second `sec` on the run's time scale.
    fn whole(&self, sec: i64) -> i64 {
        match *self {
            StampClock::Raw => sec,
            StampClock::Gps { week, leap } => {
                sec - GPS_EPOCH_UNIX + Self::leap(leap, sec) - i64::from(week) * WEEK
            }
        }
    }

    /// The run's time [s] of stamp `(sec, nanosec)`: whole seconds first, in integers,
    /// then the nanoseconds (so a GPS second of week keeps 1e-10 s where the UNIX
    /// seconds as a double would keep 2e-7 s).
    pub fn seconds(&self, sec: i32, nanosec: u32) -> f64 {
        self.whole(i64::from(sec)) as f64 + f64::from(nanosec) * 1e-9
    }

    /// The UNIX second of the run's whole second `s` (the inverse of [`Self::seconds`]'s
    /// whole part; during an inserted leap second UNIX time repeats a second, and this
    /// gives the second after it).
    pub fn unix_second(&self, s: i64) -> i64 {
        match *self {
            StampClock::Raw => s,
            StampClock::Gps { week, leap } => {
                let gps = s + i64::from(week) * WEEK;
                let unix = gps + GPS_EPOCH_UNIX;
                // GPS − UTC at that instant: the table's count of the UNIX time it gives.
                let n = Self::leap(leap, unix - Self::leap(leap, unix));
                unix - n
            }
        }
    }
}

/// What the clock does, for the run's log line.
pub fn describe(clock: &StampClock) -> String {
    match clock {
        StampClock::Raw => {
            "header stamps before 1980-01-06 (no UNIX time): read as they are".to_owned()
        }
        StampClock::Gps { week, leap } => format!(
            "header stamps are UNIX time: GPS week {week}, seconds of week with GPS - UTC = {}",
            match leap {
                Some(n) => format!("{n} s (--leap-seconds)"),
                None => "the leap seconds of each stamp's date (18 s since 2017)".to_owned(),
            }
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2023-11-14 22:13:20 UTC is UNIX 1 700 000 000, a Tuesday: two days and 22:13:20
    /// into the GPS week that began on Sunday 2023-11-12, which is week
    /// (1 700 000 000 − 315 964 800 + 18) div 604 800 = 2288: the second rollover, week
    /// 2048, began on Sunday 2019-04-07, 1680 days (240 weeks) before. Seconds of week:
    /// 2·86 400 + 80 000 + 18 leap seconds.
    #[test]
    fn a_known_date_gives_its_gps_week_and_second() {
        let clock = StampClock::of_first_stamp(1_700_000_000, None).expect("UNIX time");
        assert_eq!(clock.week(), Some(2288));
        let sow = 2.0 * 86_400.0 + 22.0 * 3600.0 + 13.0 * 60.0 + 20.0 + 18.0;
        assert_eq!(clock.seconds(1_700_000_000, 250_000_000), sow + 0.25);
        assert_eq!(clock.unix_second(sow as i64), 1_700_000_000);
        // The GPS epoch itself is week 0, second 0.
        let epoch = StampClock::of_first_stamp(GPS_EPOCH_UNIX, None).expect("epoch");
        assert_eq!(
            (epoch.week(), epoch.seconds(315_964_800, 0)),
            (Some(0), 0.0)
        );
    }

    /// The last leap second, 2016-12-31 23:59:60: the count is 17 up to its UNIX
    /// second 1 483 228 799 and 18 from 1 483 228 800 on, so GPS time steps two seconds
    /// across that one UNIX second; the inverse gives the UNIX seconds back.
    #[test]
    fn the_leap_second_of_2016_is_counted_from_2017() {
        assert_eq!(leap_seconds_at(1_483_228_799), 17);
        assert_eq!(leap_seconds_at(1_483_228_800), 18);
        assert_eq!(leap_seconds_at(GPS_EPOCH_UNIX), 0);
        let clock = StampClock::of_first_stamp(1_483_228_700, None).expect("UNIX");
        let (a, b) = (
            clock.seconds(1_483_228_799, 0),
            clock.seconds(1_483_228_800, 0),
        );
        assert_eq!(b - a, 2.0);
        for unix in [1_483_228_799, 1_483_228_800, 1_483_228_801] {
            let s = clock.seconds(unix as i32, 0) as i64;
            assert_eq!(clock.unix_second(s), unix);
        }
        // Given, the count is the same at every stamp.
        let fixed = StampClock::of_first_stamp(1_483_228_700, Some(18)).expect("UNIX");
        assert_eq!(
            fixed.seconds(1_483_228_800, 0) - fixed.seconds(1_483_228_799, 0),
            1.0
        );
    }

    /// Stamps before the GPS epoch stay as they are, bit for bit; a leap-second count
    /// given for them is refused.
    #[test]
    fn stamps_before_1980_are_read_as_they_are() {
        let clock = StampClock::of_first_stamp(345_600, None).expect("raw");
        assert_eq!(clock, StampClock::Raw);
        assert_eq!(
            clock.seconds(345_600, 5_000_000),
            f64::from(345_600) + f64::from(5_000_000u32) * 1e-9
        );
        let e = StampClock::of_first_stamp(345_600, Some(18)).expect_err("not UNIX");
        assert!(e.contains("GPS epoch"), "{e}");
    }
}
