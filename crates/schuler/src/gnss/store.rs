//! The ephemerides of one or more navigation files, per satellite, and the choice of
//! one for a satellite at an instant.
//!
//! The rule: among the satellite's *healthy* ephemerides whose `t − toe` lies in their
//! window ([`Ephemeris::fit_window_s`]), for GPS and QZSS the one with the nearest toe
//! (their toe is the middle of a 4-hour fit: within ±2 h, or half a longer fit
//! interval); for Galileo and BeiDou the latest toe (each set is fitted for the time
//! after its toe: from 10 min before it to 4 h after for Galileo, 2 h for BeiDou).
//! On a tie, the one stored last (a later upload of the same toe). An unhealthy
//! ephemeris is never chosen, even when it is the only one: the satellite is then
//! unavailable.

use std::collections::BTreeMap;

use super::ephemeris::{Ephemeris, NavMessage};
use super::sat::Sat;
use super::time::GpsTime;

/// Broadcast ephemerides grouped by satellite, each group in the order stored.
#[derive(Debug, Clone, Default)]
pub struct EphemerisStore {
    by_sat: BTreeMap<Sat, Vec<Ephemeris>>,
}

impl EphemerisStore {
    /// An empty store.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one ephemeris (an exact repeat of one already held is dropped).
    pub fn push(&mut self, eph: Ephemeris) {
        let list = self.by_sat.entry(eph.sat).or_default();
        if !list.contains(&eph) {
            list.push(eph);
        }
    }

    /// The number of ephemerides held.
    pub fn len(&self) -> usize {
        self.by_sat.values().map(Vec::len).sum()
    }

    /// Whether the store holds none.
    pub fn is_empty(&self) -> bool {
        self.by_sat.is_empty()
    }

    /// The satellites with at least one ephemeris, in order.
    pub fn sats(&self) -> impl Iterator<Item = Sat> + '_ {
        self.by_sat.keys().copied()
    }

    /// Every ephemeris of `sat`, in the order stored.
    pub fn of(&self, sat: Sat) -> &[Ephemeris] {
        self.by_sat.get(&sat).map_or(&[], Vec::as_slice)
    }

    /// The ephemeris for `sat` at GPS instant `t` by the rule above, from any message.
    pub fn select(&self, sat: Sat, t: GpsTime) -> Option<&Ephemeris> {
        self.select_by(sat, t, |_| true)
    }

    /// As [`EphemerisStore::select`], from message `message` only (Galileo F/NAV for an
    /// E1/E5a user, I/NAV for E1/E5b).
    pub fn select_message(&self, sat: Sat, t: GpsTime, message: NavMessage) -> Option<&Ephemeris> {
        self.select_by(sat, t, |e| e.message == message)
    }

    /// As [`EphemerisStore::select`], among the ephemerides `keep` accepts.
    pub fn select_by(
        &self,
        sat: Sat,
        t: GpsTime,
        keep: impl Fn(&Ephemeris) -> bool,
    ) -> Option<&Ephemeris> {
        let mut best: Option<(&Ephemeris, f64)> = None;
        for e in self.of(sat) {
            let age = t.diff_s(e.toe);
            let (early, late) = e.fit_window_s();
            // A NaN age (a non-finite toe) is not within the window either.
            let within = age >= early && age <= late;
            if !e.is_healthy() || !keep(e) || !within {
                continue;
            }
            // Nearest toe, or latest toe (the smallest signed age).
            let score = if e.toe_is_mid_fit() { age.abs() } else { age };
            if best.is_none_or(|(_, b)| score <= b) {
                best = Some((e, score));
            }
        }
        best.map(|(e, _)| e)
    }
}

impl Extend<Ephemeris> for EphemerisStore {
    fn extend<I: IntoIterator<Item = Ephemeris>>(&mut self, iter: I) {
        for e in iter {
            self.push(e);
        }
    }
}

impl FromIterator<Ephemeris> for EphemerisStore {
    fn from_iter<I: IntoIterator<Item = Ephemeris>>(iter: I) -> Self {
        let mut s = Self::new();
        s.extend(iter);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::ephemeris::tests::sample;
    use crate::gnss::sat::System;

    fn at(toe_h: f64, health: u32, iode: u32) -> Ephemeris {
        let mut e = sample(System::Gps, 7, NavMessage::Lnav);
        e.toe = GpsTime::new(1590, toe_h * 3600.0);
        e.health = health;
        e.iode = iode;
        e
    }

    #[test]
    fn nearest_healthy_toe_within_two_hours() {
        let store: EphemerisStore = [at(0.0, 0, 1), at(2.0, 0, 2), at(4.0, 1, 3)]
            .into_iter()
            .collect();
        let g07 = Sat::new(System::Gps, 7);
        let pick = |h: f64| {
            store
                .select(g07, GpsTime::new(1590, h * 3600.0))
                .map(|e| e.iode)
        };
        assert_eq!(pick(0.9), Some(1));
        assert_eq!(pick(1.1), Some(2));
        // The unhealthy toe 4 h is nearer, but never chosen.
        assert_eq!(pick(3.9), Some(2));
        assert_eq!(pick(4.1), None);
        assert_eq!(pick(-2.5), None);
        assert_eq!(
            store.select(Sat::new(System::Gps, 8), GpsTime::new(1590, 0.0)),
            None
        );
        // A tie goes to the one stored last.
        assert_eq!(pick(1.0), Some(2));
        assert_eq!(store.len(), 3);
    }

    #[test]
    fn across_the_week_and_by_message() {
        let mut store = EphemerisStore::new();
        store.push(at(167.5, 0, 9)); // toe half an hour before the week's end
        let t = GpsTime::new(1591, 0.25 * 3600.0);
        assert_eq!(
            store.select(Sat::new(System::Gps, 7), t).map(|e| e.iode),
            Some(9)
        );
        let mut f = sample(System::Galileo, 3, NavMessage::Fnav);
        f.toe = GpsTime::new(1590, 345_000.0);
        f.iode = 5;
        let mut i = f.clone();
        i.message = NavMessage::Inav;
        i.iode = 6;
        store.extend([f, i]);
        let e03 = Sat::new(System::Galileo, 3);
        let t = GpsTime::new(1590, 345_600.0);
        assert_eq!(store.select(e03, t).map(|e| e.iode), Some(6));
        let fnav = store.select_message(e03, t, NavMessage::Fnav);
        assert_eq!(fnav.map(|e| e.iode), Some(5));
    }

    #[test]
    fn galileo_and_beidou_take_the_latest_toe() {
        let mut store = EphemerisStore::new();
        for (sys, prn) in [(System::Galileo, 5), (System::BeiDou, 30)] {
            for (iode, toe_h) in [(1, 0.0), (2, 1.0), (3, 5.0)] {
                let mut e = sample(sys, prn, NavMessage::Inav);
                e.message = if sys == System::BeiDou {
                    NavMessage::D1
                } else {
                    NavMessage::Inav
                };
                e.toe = GpsTime::new(1590, toe_h * 3600.0);
                e.iode = iode;
                store.push(e);
            }
            let sat = Sat::new(sys, prn);
            let pick = |h: f64| {
                store
                    .select(sat, GpsTime::new(1590, h * 3600.0))
                    .map(|e| e.iode)
            };
            // At 0.8 h toe 1 h is nearer but 12 min ahead, not yet in force; at 0.9 h it is.
            assert_eq!(pick(0.8), Some(1));
            assert_eq!(pick(0.9), Some(2));
            assert_eq!(pick(1.6), Some(2));
            // Galileo keeps a set 4 h, BeiDou 2 h.
            let late = if sys == System::Galileo {
                Some(2)
            } else {
                None
            };
            assert_eq!(pick(4.5), late);
            assert_eq!(pick(5.0), Some(3));
            assert_eq!(pick(-0.5), None);
        }
    }
}
