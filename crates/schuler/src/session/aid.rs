//! Aiding measurements as a front end pushes them, and the per-kind queues that hold
//! them in time order until the samples they fall in are integrated.
//!
//! An aid is *late* when it arrives after the sample it belongs to was integrated: a
//! GNSS fix earlier than the integrated time (it is applied at its own time, inside a
//! sample), a reading applied at the nearest sample end (barometer, odometer,
//! heading) within half a sample of the integrated time or earlier, a rest interval
//! that began before it. Late aids are reported, never applied and never silently
//! dropped; [`super::SessionConfig::reorder_window`] sets how late an aid may be.

use crate::domain::{self, Domain, DomainError};
use crate::filter::integration::GnssUpdate;
use crate::filter::integration::Timed;
use crate::filter::measurement::Kind;
use crate::filter::{GnssFix, HeadingReading};
use crate::gnss::RangeEpoch;
use std::collections::VecDeque;

/// One aiding measurement.
#[derive(Debug, Clone, PartialEq)]
pub enum Aid {
    /// A GNSS position (and optionally velocity) fix with its standard deviations.
    Gnss(GnssFix),
    /// One epoch of pseudoranges and rates with their satellites (tight coupling).
    Ranges(Box<RangeEpoch>),
    /// A barometric height [m] at time `t` [s].
    Baro {
        /// Time [s].
        t: f64,
        /// Height [m].
        h: f64,
    },
    /// An odometer speed [m/s] at time `t` [s].
    Odometer {
        /// Time [s].
        t: f64,
        /// Speed of the vehicle's constraint point [m/s].
        speed: f64,
    },
    /// A dual-antenna heading.
    Heading(HeadingReading),
    /// The vehicle at rest from `t0` to `t1` [s].
    Rest {
        /// Start [s].
        t0: f64,
        /// End [s].
        t1: f64,
    },
}

impl Aid {
    /// The time the aid speaks of (a rest's start).
    pub fn t(&self) -> f64 {
        match self {
            Aid::Gnss(f) => f.t,
            Aid::Ranges(e) => e.t,
            Aid::Baro { t, .. } | Aid::Odometer { t, .. } => *t,
            Aid::Heading(h) => h.t,
            Aid::Rest { t0, .. } => *t0,
        }
    }

    /// The measurement kind it becomes.
    pub fn kind(&self) -> Kind {
        match self {
            Aid::Gnss(_) => Kind::GnssPosition,
            Aid::Ranges(_) => Kind::Pseudorange,
            Aid::Baro { .. } => Kind::BaroHeight,
            Aid::Odometer { .. } => Kind::Odometer,
            Aid::Heading(_) => Kind::Heading,
            Aid::Rest { .. } => Kind::ZeroVelocity,
        }
    }

    /// Whether its times are finite (and a rest ends after it starts).
    pub fn times_valid(&self) -> bool {
        match self {
            Aid::Rest { t0, t1 } => t0.is_finite() && t1.is_finite() && t1 >= t0,
            _ => self.t().is_finite(),
        }
    }

    /// The first value outside its physical domain ([`crate::domain`]): the field's
    /// name and why. A standard deviation of 1e308 or a height of 1e12 m is as wrong
    /// as a NaN: its variance overflows and the innovation test turns into NaN.
    pub fn out_of_domain(&self) -> Option<(&'static str, DomainError)> {
        let each = |name, d: &Domain, xs: &[f64]| {
            xs.iter().find_map(|&x| d.check(x).err().map(|e| (name, e)))
        };
        match self {
            Aid::Gnss(f) => each("lat", &domain::LATITUDE, &[f.pos.lat])
                .or_else(|| each("lon", &domain::LONGITUDE_WRAPPED, &[f.pos.lon]))
                .or_else(|| each("h", &domain::HEIGHT, &[f.pos.h]))
                .or_else(|| each("pos_std", &domain::POSITION_STD, f.pos_std.as_slice()))
                .or_else(|| {
                    f.vel.and_then(|(v, s)| {
                        each("vel", &domain::SPEED, v.as_slice())
                            .or_else(|| each("vel_std", &domain::VELOCITY_STD, s.as_slice()))
                    })
                }),
            Aid::Ranges(e) => e.sats.iter().find_map(|s| {
                let m = &s.measurement;
                each(
                    "pseudorange",
                    &domain::PSEUDORANGE,
                    &[m.pseudorange.unwrap_or(1e7)],
                )
                .or_else(|| {
                    m.pseudorange_rate()
                        .and_then(|r| each("pseudorange_rate", &domain::RANGE_RATE, &[r]))
                })
            }),
            Aid::Baro { h, .. } => each("h", &domain::HEIGHT, &[*h]),
            Aid::Odometer { speed, .. } => each("speed", &domain::SPEED, &[*speed]),
            Aid::Heading(r) => each("heading", &domain::HEADING, &[r.heading])
                .or_else(|| each("heading_std", &domain::ANGLE_STD, &[r.heading_std]))
                .or_else(|| {
                    r.pitch.and_then(|(p, s)| {
                        each("pitch", &domain::PITCH, &[p])
                            .or_else(|| each("pitch_std", &domain::ANGLE_STD, &[s]))
                    })
                }),
            Aid::Rest { .. } => None,
        }
    }
}

/// Insert `x` into `q` keeping it sorted by `t` (stable: after equal times). Aids
/// arrive nearly in order, so the search runs from the back.
pub(crate) fn insert_sorted<T>(q: &mut VecDeque<T>, x: T, t: impl Fn(&T) -> f64) {
    let tx = t(&x);
    let mut i = q.len();
    while i > 0 && t(&q[i - 1]) > tx {
        i -= 1;
    }
    q.insert(i, x);
}

/// The aids waiting for their samples, one queue per kind, each in time order.
#[derive(Debug, Clone, Default)]
pub(crate) struct AidQueues {
    pub gnss: VecDeque<GnssUpdate>,
    pub baro: VecDeque<(f64, f64)>,
    pub odometer: VecDeque<(f64, f64)>,
    pub heading: VecDeque<HeadingReading>,
    pub rest: VecDeque<(f64, f64)>,
}

impl AidQueues {
    /// Queue `aid` (checked and accepted by the caller).
    pub fn push(&mut self, aid: Aid) {
        match aid {
            Aid::Gnss(f) => insert_sorted(&mut self.gnss, GnssUpdate::Fix(f), |f| f.time()),
            Aid::Ranges(e) => insert_sorted(&mut self.gnss, GnssUpdate::Ranges(e), |f| f.time()),
            Aid::Baro { t, h } => insert_sorted(&mut self.baro, (t, h), |r| r.0),
            Aid::Odometer { t, speed } => insert_sorted(&mut self.odometer, (t, speed), |r| r.0),
            Aid::Heading(r) => insert_sorted(&mut self.heading, r, |r| r.t),
            Aid::Rest { t0, t1 } => insert_sorted(&mut self.rest, (t0, t1), |r| r.0),
        }
    }
}

/// Whether `aid` comes too late for a session that has integrated up to `t_done`
/// with a last sample interval `dt` (module doc).
pub(crate) fn is_late(aid: &Aid, t_done: f64, dt: f64) -> bool {
    match aid {
        Aid::Gnss(f) => f.t < t_done - 1e-3 * dt,
        Aid::Ranges(e) => e.t < t_done - 1e-3 * dt,
        Aid::Baro { t, .. } | Aid::Odometer { t, .. } => *t <= t_done + 0.5 * dt,
        Aid::Heading(r) => r.t <= t_done + 0.5 * dt,
        Aid::Rest { t0, .. } => *t0 < t_done,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_beyond_their_domain_are_named() {
        use crate::earth::Geodetic;
        use nalgebra::Vector3;
        let fix = GnssFix {
            t: 1.0,
            pos: Geodetic::from_degrees(45.0, 7.0, 100.0),
            pos_std: Vector3::new(0.5, 0.5, 1.0),
            vel: Some((Vector3::new(1.0, 2.0, 0.0), Vector3::repeat(0.1))),
        };
        assert_eq!(Aid::Gnss(fix).out_of_domain(), None);
        let field = |a: Aid| a.out_of_domain().map(|(f, _)| f);
        let huge = |v: &mut f64| *v = 1e308;
        let mut f = fix;
        huge(&mut f.pos_std.y);
        assert_eq!(field(Aid::Gnss(f)), Some("pos_std"));
        let mut f = fix;
        huge(&mut f.pos.h);
        assert_eq!(field(Aid::Gnss(f)), Some("h"));
        let mut f = fix;
        f.vel = Some((Vector3::new(0.0, 0.0, 1e5), Vector3::repeat(0.1)));
        assert_eq!(field(Aid::Gnss(f)), Some("vel"));
        assert_eq!(field(Aid::Baro { t: 1.0, h: 1e12 }), Some("h"));
        assert_eq!(
            field(Aid::Odometer {
                t: 1.0,
                speed: -1e308
            }),
            Some("speed")
        );
        let r = HeadingReading {
            t: 1.0,
            heading: 0.1,
            heading_std: 1e308,
            pitch: None,
        };
        assert_eq!(field(Aid::Heading(r)), Some("heading_std"));
        // A zero standard deviation is as impossible as a huge one.
        let mut f = fix;
        f.pos_std.x = 0.0;
        assert_eq!(field(Aid::Gnss(f)), Some("pos_std"));
    }

    #[test]
    fn insertion_keeps_time_order_and_arrival_order_among_equal_times() {
        let mut q = VecDeque::new();
        for (t, tag) in [(1.0, 'a'), (3.0, 'b'), (2.0, 'c'), (3.0, 'd'), (0.5, 'e')] {
            insert_sorted(&mut q, (t, tag), |x| x.0);
        }
        let tags: String = q.iter().map(|x| x.1).collect();
        assert_eq!(tags, "eacbd");
    }

    #[test]
    fn lateness_follows_each_kind_application_rule() {
        let dt = 0.01;
        // A fix inside the integrated span is late; one at its end is applied there.
        let fix = |t| {
            Aid::Gnss(GnssFix {
                t,
                pos: crate::earth::Geodetic::new(0.0, 0.0, 0.0),
                pos_std: nalgebra::Vector3::repeat(1.0),
                vel: None,
            })
        };
        assert!(is_late(&fix(9.99), 10.0, dt));
        assert!(!is_late(&fix(10.0), 10.0, dt));
        // A reading within half a sample of the last end belonged to that sample.
        assert!(is_late(&Aid::Baro { t: 10.004, h: 0.0 }, 10.0, dt));
        assert!(!is_late(&Aid::Baro { t: 10.006, h: 0.0 }, 10.0, dt));
        assert!(is_late(&Aid::Rest { t0: 9.0, t1: 11.0 }, 10.0, dt));
    }
}
