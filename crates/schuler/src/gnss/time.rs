//! GNSS time: GPS time (GPST) as a week number and seconds of week, and the broadcast
//! systems' own scales expressed in it.
//!
//! - GPST counts from 1980-01-06 00:00:00 UTC without leap seconds (IS-GPS-200 §3.3.4).
//! - Galileo system time (GST) is steered to GPST within tens of nanoseconds; its week
//!   0 began on 1999-08-22, GPS week 1024 (Galileo OS SIS ICD §5.1.2). RINEX 3 and 4
//!   write Galileo's week *aligned to GPS's* (RINEX 3.04 Table A8: "GAL week # …
//!   identical to the continuous GPS week"), so a RINEX Galileo week and second of week
//!   are GPST's; the few-ns GPS–Galileo offset (GGTO) is left to the receiver's
//!   inter-system clock bias.
//! - BeiDou time (BDT) began on 2006-01-01 00:00:00 UTC, when GPST − UTC was 14 s:
//!   `BDT = GPST − 14 s`, and BDT week 0 is GPS week 1356 (BDS-SIS-ICD-B1I 3.0 §5.2).
//!   RINEX writes BeiDou's toe, toc and week in BDT.
//!
//! A second of week is kept beside an integer week so that a time keeps 1.2e-10 s
//! resolution whatever the date (an ulp of 604800; a satellite moves 0.5 µm in it),
//! where an f64 count of seconds since 1980 resolves only 2.4e-7 s.

use std::cmp::Ordering;

/// Seconds in a week.
pub const WEEK_S: f64 = 604_800.0;
/// Half a week [s]: the bound of the ICDs' rule for `t − toe` across a week's end.
pub const HALF_WEEK_S: f64 = 302_400.0;
/// GPST − BDT [s] (BDS-SIS-ICD §5.2).
pub const GPST_MINUS_BDT_S: f64 = 14.0;
/// The GPS week in which BDT week 0 began (2006-01-01).
pub const BDT_WEEK_OFFSET: i64 = 1356;
/// The GPS week in which GST week 0 began (1999-08-22).
pub const GST_WEEK_OFFSET: i64 = 1024;

/// An instant in GPS time: a week since the GPS epoch and seconds into it, kept
/// normalised to `0 ≤ sow < 604800`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpsTime {
    /// GPS week (continuous, not the broadcast 10-bit count).
    pub week: i64,
    /// Seconds of week, `0 ≤ sow < 604800`.
    pub sow: f64,
}

impl GpsTime {
    /// The instant `sow` seconds after the start of GPS week `week` (any finite `sow`;
    /// the week absorbs whole weeks of it).
    pub fn new(week: i64, sow: f64) -> Self {
        let mut t = Self { week, sow };
        t.normalise();
        t
    }

    /// The GPS instant of BeiDou week `week` (BDT), second `sow` of it.
    pub fn from_bdt(week: i64, sow: f64) -> Self {
        Self::new(week + BDT_WEEK_OFFSET, sow + GPST_MINUS_BDT_S)
    }

    /// The instant as BeiDou week and second of week (BDT).
    pub fn to_bdt(self) -> (i64, f64) {
        let t = self.add_s(-GPST_MINUS_BDT_S);
        (t.week - BDT_WEEK_OFFSET, t.sow)
    }

    /// The GPS instant of a Galileo week counted from GST's own origin (as broadcast,
    /// not as RINEX writes it) and its second of week.
    pub fn from_gst(gst_week: i64, sow: f64) -> Self {
        Self::new(gst_week + GST_WEEK_OFFSET, sow)
    }

    /// Seconds since the GPS epoch (loses resolution: 2.4e-7 s today; for display and
    /// coarse ordering).
    pub fn seconds_since_epoch(self) -> f64 {
        self.week as f64 * WEEK_S + self.sow
    }

    /// This instant shifted by `dt` seconds.
    pub fn add_s(self, dt: f64) -> Self {
        Self::new(self.week, self.sow + dt)
    }

    /// `self − earlier` in seconds, exact to the resolution of the seconds of week.
    pub fn diff_s(self, earlier: GpsTime) -> f64 {
        (self.week - earlier.week) as f64 * WEEK_S + (self.sow - earlier.sow)
    }

    /// Keeps `sow` in `[0, 604800)` by moving whole weeks into `week` (non-finite
    /// seconds are left as they are rather than looping).
    fn normalise(&mut self) {
        if !self.sow.is_finite() {
            return;
        }
        let weeks = (self.sow / WEEK_S).floor();
        if weeks != 0.0 {
            self.week += weeks as i64;
            self.sow -= weeks * WEEK_S;
        }
        // Rounding can leave sow == WEEK_S after a negative shift.
        if self.sow >= WEEK_S {
            self.week += 1;
            self.sow -= WEEK_S;
        }
    }
}

impl PartialOrd for GpsTime {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        match self.week.cmp(&other.week) {
            Ordering::Equal => self.sow.partial_cmp(&other.sow),
            o => Some(o),
        }
    }
}

/// A time difference `dt` [s] brought into `[−302400, 302400]` by whole weeks: the
/// ICDs' rule for `t − toe` and `t − toc` when only seconds of week are known
/// (IS-GPS-200 Table 20-IV, note on `t_k`).
pub fn wrap_half_week(dt: f64) -> f64 {
    if dt > HALF_WEEK_S {
        dt - WEEK_S * ((dt + HALF_WEEK_S) / WEEK_S).floor()
    } else if dt < -HALF_WEEK_S {
        dt + WEEK_S * ((HALF_WEEK_S - dt) / WEEK_S).floor()
    } else {
        dt
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weeks_absorb_whole_weeks_both_ways() {
        let t = GpsTime::new(1590, 604_799.5).add_s(1.0);
        assert_eq!((t.week, t.sow), (1591, 0.5));
        let t = GpsTime::new(1591, 0.5).add_s(-1.0);
        assert_eq!((t.week, t.sow), (1590, 604_799.5));
        assert_eq!(GpsTime::new(2000, -3.0 * WEEK_S).week, 1997);
        assert_eq!(
            GpsTime::new(1591, 0.5).diff_s(GpsTime::new(1590, 604_799.5)),
            1.0
        );
        assert!(GpsTime::new(1591, 0.0) > GpsTime::new(1590, 604_799.9));
    }

    #[test]
    fn beidou_time_is_gpst_minus_14_s_from_week_1356() {
        // BDT 0 (2006-01-01 00:00:00 UTC) was GPS week 1356, second 14 of its
        // Sunday: 2006-01-01 was itself a Sunday, GPST − UTC = 14 s then.
        let t = GpsTime::from_bdt(0, 0.0);
        assert_eq!((t.week, t.sow), (1356, 14.0));
        // A BDT second just before its week's end is in the next GPS week.
        let t = GpsTime::from_bdt(760, 604_795.0);
        assert_eq!((t.week, t.sow), (2117, 9.0));
        assert_eq!(t.to_bdt(), (760, 604_795.0));
    }

    #[test]
    fn galileo_week_zero_is_gps_week_1024() {
        // GST began 1999-08-22 00:00:00 UTC less 13 leap seconds: GPS week 1024 (the
        // first GPS rollover), second 0.
        let t = GpsTime::from_gst(1087, 345_600.0);
        assert_eq!((t.week, t.sow), (2111, 345_600.0));
    }

    #[test]
    fn the_half_week_rule() {
        assert_eq!(wrap_half_week(100.0), 100.0);
        // toe at the end of a week, t just after the start of the next.
        assert_eq!(wrap_half_week(10.0 - 597_600.0), 7_210.0);
        assert_eq!(wrap_half_week(597_600.0 - 10.0), -7_210.0);
        assert_eq!(wrap_half_week(HALF_WEEK_S), HALF_WEEK_S);
        assert!(wrap_half_week(f64::NAN).is_nan());
    }
}
