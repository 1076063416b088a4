//! Calendar dates and times of GNSS logs to GPS weeks and seconds of week.
//!
//! GPS time (GPST) runs without leap seconds from 1980-01-06 00:00:00 UTC; UTC has
//! since been stepped back by the leap seconds of the IERS (Bulletin C), so
//! `GPST = UTC + leap seconds`: 18 s since 2017-01-01. The table below ends there (no
//! leap second has been announced since); a log from after a later one needs
//! `--gnss-time-offset`.

use chrono::{Datelike, NaiveDate};

/// Seconds in a day.
pub(crate) const DAY_S: f64 = 86_400.0;
/// Seconds in a GPS week.
pub(crate) const WEEK_S: f64 = 604_800.0;

/// The first day of the month on which each leap second took effect since the GPS
/// epoch (IERS Bulletin C; GPST − UTC is the number of them in force).
const LEAP_SECOND_DATES: [(i32, u32); 18] = [
    (1981, 7),
    (1982, 7),
    (1983, 7),
    (1985, 7),
    (1988, 1),
    (1990, 1),
    (1991, 1),
    (1992, 7),
    (1993, 7),
    (1994, 7),
    (1996, 1),
    (1997, 7),
    (1999, 1),
    (2006, 1),
    (2009, 1),
    (2012, 7),
    (2015, 7),
    (2017, 1),
];

/// The time scale of a log's clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TimeScale {
    /// GPS time.
    Gpst,
    /// Coordinated universal time.
    Utc,
    /// Japan standard time, UTC + 9 h (an RTKLIB option).
    Jst,
}

/// The GPS epoch, 1980-01-06, as a date.
fn gps_epoch() -> NaiveDate {
    // A valid constant date: from_ymd_opt returns Some, MIN is never used.
    NaiveDate::from_ymd_opt(1980, 1, 6).unwrap_or(NaiveDate::MIN)
}

/// GPST − UTC [s] on the UTC date `date` (the leap seconds in force that day).
pub(crate) fn leap_seconds(date: NaiveDate) -> f64 {
    let ym = (date.year(), date.month());
    LEAP_SECOND_DATES.iter().filter(|&&d| ym >= d).count() as f64
}

/// The GPS week and second of week of `sod` seconds after midnight of `date`, both in
/// time scale `scale`.
pub(crate) fn week_sow(date: NaiveDate, sod: f64, scale: TimeScale) -> (i64, f64) {
    let sod_gpst = match scale {
        TimeScale::Gpst => sod,
        TimeScale::Utc => sod + leap_seconds(date),
        TimeScale::Jst => sod - 9.0 * 3600.0 + leap_seconds(date),
    };
    let days = (date - gps_epoch()).num_days();
    let mut week = days.div_euclid(7);
    let mut sow = days.rem_euclid(7) as f64 * DAY_S + sod_gpst;
    while sow >= WEEK_S {
        sow -= WEEK_S;
        week += 1;
    }
    while sow < 0.0 {
        sow += WEEK_S;
        week -= 1;
    }
    (week, sow)
}

/// The date and seconds of day of GPS week `week`, second of week `sow`, in the same
/// time scale (a week and second given in UTC stay in UTC); `None` for a date out of
/// the calendar's range.
pub(crate) fn date_of_week(week: i64, sow: f64) -> Option<(NaiveDate, f64)> {
    let day = (sow / DAY_S).floor();
    let days = week.checked_mul(7)?.checked_add(day as i64)?;
    let date = gps_epoch().checked_add_signed(chrono::TimeDelta::try_days(days)?)?;
    Some((date, sow - day * DAY_S))
}

/// Seconds of week continued across week rollovers from the first week it is given.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WeekClock {
    first: Option<i64>,
}

impl WeekClock {
    /// `sow + 604800 (week − first week)`.
    pub(crate) fn seconds(&mut self, week: i64, sow: f64) -> f64 {
        let first = *self.first.get_or_insert(week);
        sow + (week - first) as f64 * WEEK_S
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn date(y: i32, m: u32, d: u32) -> NaiveDate {
        NaiveDate::from_ymd_opt(y, m, d).expect("valid date")
    }

    #[test]
    fn leap_seconds_step_on_their_dates() {
        assert_eq!(leap_seconds(date(1980, 1, 6)), 0.0);
        assert_eq!(leap_seconds(date(2016, 12, 31)), 17.0);
        assert_eq!(leap_seconds(date(2017, 1, 1)), 18.0);
        assert_eq!(leap_seconds(date(2025, 6, 1)), 18.0);
    }

    #[test]
    fn weeks_and_seconds_of_known_dates() {
        // The GPS epoch, and 2020-12-24 21:28:42 GPST, week 2137 422922 s (RTKPOST's
        // header of the demo5 solution in tests/data/rtklib).
        assert_eq!(week_sow(date(1980, 1, 6), 0.0, TimeScale::Gpst), (0, 0.0));
        let sod = 21.0 * 3600.0 + 28.0 * 60.0 + 42.0;
        assert_eq!(
            week_sow(date(2020, 12, 24), sod, TimeScale::Gpst),
            (2137, 422_922.0)
        );
        // UTC 18 s before the end of a Saturday is the next week's start in GPST.
        assert_eq!(
            week_sow(date(2020, 12, 26), DAY_S - 18.0, TimeScale::Utc),
            (2138, 0.0)
        );
        // JST is nine hours ahead of UTC.
        assert_eq!(
            week_sow(
                date(2020, 12, 25),
                sod + 9.0 * 3600.0 - DAY_S,
                TimeScale::Jst
            ),
            week_sow(date(2020, 12, 24), sod, TimeScale::Utc)
        );
        assert_eq!(
            date_of_week(2137, 422_922.5),
            Some((date(2020, 12, 24), sod + 0.5))
        );
        assert_eq!(date_of_week(i64::MAX, 0.0), None);
    }

    #[test]
    fn the_clock_continues_across_a_rollover() {
        let mut c = WeekClock::default();
        assert_eq!(c.seconds(2137, 604_799.0), 604_799.0);
        assert_eq!(c.seconds(2138, 1.0), 604_801.0);
    }
}
