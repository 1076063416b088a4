//! The aids of a run pushed into the session in step with the IMU samples, so that the
//! session's queues hold about a second of them instead of the whole log (issue 22:
//! before, every fix was held twice, in the readings and in the session).
//!
//! Before each sample at `t` every aid up to `t + H` is pushed, with the horizon
//! `H = reorder window + 1 s + the longest sample interval so far`. An aid pushed then
//! is never late ([`schuler::session`]'s rule: a fix before the integrated time, a
//! reading within half a sample of it), since every earlier push covered only times
//! more than `H` before it; and it is queued before the sample it falls in is
//! integrated, as it was when all aids were pushed at the start, so the run is the
//! same bit for bit. Each kind's readings are merged in time order; a kind whose
//! readings are not in time order is pushed whole at the start, as before.
//!
//! A `--truth` file is streamed the same way ([`NavReader`]): its epochs up to
//! `t + H` and the first one after go into the session
//! ([`Session::push_truth`]) before the sample, so that the NEES of each snapshot
//! finds the epochs around its time, as it found them in the whole truth.

use super::Aiding;
use anyhow::Result;
use schuler::earth::EarthModel;
use schuler::imu::ImuSample;
use schuler::session::{Aid, Session, SessionError};
use schuler_io::formats::nav::NavReader;
use std::iter::Peekable;

/// One kind's aids, in time order.
type Source<'a> = Peekable<Box<dyn Iterator<Item = Aid> + 'a>>;

/// One kind's aids, made as often as asked.
type Kind<'a> = Box<dyn Fn() -> Box<dyn Iterator<Item = Aid> + 'a> + 'a>;

/// The aids not pushed yet, per kind.
pub struct AidFeed<'a> {
    sources: Vec<Source<'a>>,
    /// The session's reorder window [s].
    window: f64,
    /// The longest sample interval so far [s].
    longest_dt: f64,
    /// The time of the earliest aid not pushed [s] (infinite: none).
    due: f64,
    /// The truth file being streamed, until its end.
    truth: Option<NavReader>,
    /// The time of the last truth epoch pushed [s].
    truth_until: f64,
    /// Aids pushed so far.
    pushed: usize,
    /// The fixes' store, checked at the end (a read that failed ends its iteration).
    fixes: Option<&'a super::fixes::Fixes>,
    /// The raw GNSS stream, whose read error ([`super::raw_gnss::RawGnss::aids`]) is
    /// checked after the first pass and at the end.
    raw: Option<&'a super::raw_gnss::RawGnss>,
}

impl<'a> AidFeed<'a> {
    /// A feed with nothing to push.
    pub fn none() -> Self {
        Self {
            sources: Vec::new(),
            window: 0.0,
            longest_dt: 0.0,
            due: f64::INFINITY,
            truth: None,
            truth_until: f64::INFINITY,
            pushed: 0,
            fixes: None,
            raw: None,
        }
    }

    /// The aids of `a` and its truth file, for `session`: every aid is checked first
    /// (the error [`Session::push`] would give, before anything is written), and the
    /// kinds not in time order are pushed now.
    pub fn open<E: EarthModel>(a: &'a Aiding, session: &mut Session<E>) -> Result<Self> {
        let v = &a.vehicle;
        let kinds: [Kind<'a>; 6] = [
            Box::new(|| Box::new(a.fixes.iter().map(Aid::Gnss))),
            Box::new(|| Box::new(a.baro.iter().map(|&(t, h)| Aid::Baro { t, h }))),
            Box::new(|| Box::new(v.rests.iter().map(|&(t0, t1)| Aid::Rest { t0, t1 }))),
            Box::new(|| {
                Box::new(
                    v.odometer
                        .iter()
                        .map(|&(t, speed)| Aid::Odometer { t, speed }),
                )
            }),
            Box::new(|| Box::new(v.headings.iter().map(|&h| Aid::Heading(h)))),
            Box::new(move || match &a.raw {
                Some(r) => r.aids(),
                None => Box::new(std::iter::empty()),
            }),
        ];
        let mut sources = Vec::new();
        for kind in kinds {
            // One pass checks every aid and the order (a GNSS store spilled to a file
            // is read once here and once as it is fed).
            let (mut sorted, mut last) = (true, f64::NEG_INFINITY);
            for aid in kind() {
                aid.validate()?;
                sorted &= last <= aid.t();
                last = aid.t();
            }
            if let Some(e) = a.raw.as_ref().and_then(|r| r.take_error()) {
                return Err(e);
            }
            if sorted {
                sources.push(kind().peekable());
            } else {
                for aid in kind() {
                    session.push(aid)?;
                }
            }
        }
        let truth = match &a.report.truth {
            Some(t) if t.held.is_none() => Some(NavReader::open(&t.path)?),
            _ => None,
        };
        let mut feed = Self {
            sources,
            window: session.config().reorder_window,
            longest_dt: 0.0,
            due: f64::NEG_INFINITY,
            truth_until: if truth.is_some() {
                f64::NEG_INFINITY
            } else {
                f64::INFINITY
            },
            truth,
            pushed: 0,
            fixes: Some(&a.fixes),
            raw: a.raw.as_ref(),
        };
        a.fixes.status()?;
        feed.push_until(session, f64::NEG_INFINITY)?;
        Ok(feed)
    }

    /// Pushes the aids up to `t` [s] (every one with `t` infinite), earliest first
    /// (the first kind among equal times).
    fn push_until<E: EarthModel>(
        &mut self,
        session: &mut Session<E>,
        t: f64,
    ) -> Result<(), SessionError> {
        loop {
            let mut next: Option<(usize, f64)> = None;
            for (k, s) in self.sources.iter_mut().enumerate() {
                if let Some(aid) = s.peek()
                    && aid.t() <= t
                    && next.is_none_or(|n| aid.t() < n.1)
                {
                    next = Some((k, aid.t()));
                }
            }
            let Some((k, _)) = next else {
                self.due = self
                    .sources
                    .iter_mut()
                    .filter_map(|s| s.peek().map(Aid::t))
                    .fold(f64::INFINITY, f64::min);
                return Ok(());
            };
            if let Some(aid) = self.sources[k].next() {
                session.push(aid)?;
                self.pushed += 1;
            }
        }
    }

    /// Pushes the truth's epochs up to `t` [s] and the first one after it.
    fn push_truth<E: EarthModel>(&mut self, session: &mut Session<E>, t: f64) -> Result<()> {
        while self.truth_until <= t {
            let Some(reader) = self.truth.as_mut() else {
                break;
            };
            match reader.next() {
                Some(r) => {
                    let r = r?;
                    self.truth_until = r.t_sow;
                    session.push_truth(r);
                }
                None => {
                    self.truth = None;
                    self.truth_until = f64::INFINITY;
                }
            }
        }
        Ok(())
    }

    /// Pushes what is due before sample `s` goes into the session.
    pub fn before<E: EarthModel>(&mut self, session: &mut Session<E>, s: &ImuSample) -> Result<()> {
        self.longest_dt = self.longest_dt.max(s.dt);
        let until = s.t + self.window + 1.0 + self.longest_dt;
        if until < self.due && until < self.truth_until {
            return Ok(());
        }
        self.push_truth(session, until)?;
        Ok(self.push_until(session, until)?)
    }

    /// Pushes every aid left (the input has ended; the truth already holds an epoch
    /// after the last sample, or all of it).
    pub fn rest<E: EarthModel>(&mut self, session: &mut Session<E>) -> Result<()> {
        self.push_until(session, f64::INFINITY)?;
        self.sources.clear();
        if let Some(e) = self.raw.and_then(|r| r.take_error()) {
            return Err(e);
        }
        self.fixes.map_or(Ok(()), super::fixes::Fixes::status)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aided::{OutputNames, report::ReportSettings};
    use nalgebra::Vector3;
    use schuler::earth::{Geodetic, Wgs84};
    use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig};
    use schuler::session::{Epoch, Event, FilterConfig, SessionConfig, Start};
    use schuler::sim::analytic::{self, Stationary};
    use schuler::sim::sensor_spec::{ImuSpec, Preset};

    const RATE: f64 = 50.0;
    const SECONDS: usize = 120;

    fn here() -> Stationary {
        Stationary {
            pos: Geodetic::from_degrees(45.0, 7.0, 300.0),
            attitude: schuler::rotation::Euler::new(0.0, 0.0, 0.3),
        }
    }

    /// Fixes every second (none from 40 to 50 s) a few decimetres off, the barometer
    /// every half second 2 m off; the filter with a barometer-bias state.
    fn aiding() -> Aiding {
        let noise = ImuNoise::from_model(
            &ImuSpec::of_preset(RATE, Preset::Tactical)
                .model()
                .expect("preset"),
        );
        let p = here().pos;
        let fixes: Vec<GnssFix> = (1..=SECONDS)
            .filter(|k| !(40..50).contains(k))
            .map(|k| GnssFix {
                t: k as f64,
                pos: Geodetic {
                    lat: p.lat + 3e-8 * (k as f64).sin(),
                    ..p
                },
                pos_std: Vector3::new(0.5, 0.5, 1.0),
                vel: None,
            })
            .collect();
        let baro = (1..=2 * SECONDS)
            .map(|k| (0.5 * k as f64, p.h + 2.0 + 0.1 * (k as f64).cos()))
            .collect();
        Aiding {
            fixes: fixes.into(),
            filter: FilterConfig {
                baro_std: 0.5,
                ..FilterConfig::new(IntegrationConfig {
                    baro: Some((10.0, 0.0)),
                    ..IntegrationConfig::new(noise)
                })
            },
            names: OutputNames::SCHULER,
            initial_errors: Default::default(),
            outage_test: None,
            baro,
            report: ReportSettings::default(),
            vehicle: Default::default(),
            raw: None,
            gnss_time_shift: 0.0,
        }
    }

    fn session(a: &Aiding) -> Session<Wgs84> {
        let cfg = SessionConfig {
            output_rate: Some(10.0),
            filter: Some(a.filter),
            ..SessionConfig::default()
        };
        Session::new(Wgs84, cfg, Start::at(analytic::state(&Wgs84, &here(), 0.0))).expect("valid")
    }

    /// Epochs and events of a run: every sample pushed after `before` was called.
    fn run(
        s: &mut Session<Wgs84>,
        mut before: impl FnMut(&mut Session<Wgs84>, &ImuSample),
    ) -> (Vec<Epoch>, Vec<Event>) {
        let dt = 1.0 / RATE;
        let n = SECONDS * RATE as usize;
        let (mut epochs, mut events) = (Vec::new(), Vec::new());
        for x in analytic::samples(&Wgs84, &here(), -dt, dt, n + 1) {
            before(s, &x);
            s.push_imu(x).expect("sample");
            epochs.extend(s.epochs());
            events.extend(s.events());
        }
        (epochs, events)
    }

    /// Fed in step, the run is the run with every aid pushed first (the batch run),
    /// epoch for epoch and event for event, bit for bit; and the aids pushed ahead of
    /// the samples never exceed those of the horizon (1 s and a sample: at most 2
    /// fixes and 3 barometer readings), whatever the log's length.
    #[test]
    fn fed_in_step_equals_the_batch_run_and_stays_a_bounded_count_ahead() {
        let a = aiding();
        let mut batch = session(&a);
        for aid in a.fixes.iter().map(Aid::Gnss) {
            batch.push(aid).expect("aid");
        }
        for &(t, h) in &a.baro {
            batch.push(Aid::Baro { t, h }).expect("aid");
        }
        let expected = run(&mut batch, |_, _| {});
        let mut fed = session(&a);
        let mut feed = AidFeed::open(&a, &mut fed).expect("feed");
        let mut most_ahead = 0;
        let got = run(&mut fed, |s, x| {
            feed.before(s, x).expect("push");
            let reached = a.fixes.iter().filter(|f| f.t <= x.t).count()
                + a.baro.iter().filter(|r| r.0 <= x.t).count();
            most_ahead = most_ahead.max(feed.pushed - reached);
        });
        assert!(most_ahead <= 5, "{most_ahead} aids ahead");
        assert!(most_ahead >= 2, "{most_ahead}: the feed must run ahead");
        let updates = expected
            .1
            .iter()
            .filter(|e| matches!(e, Event::Measurement(_)))
            .count();
        assert_eq!(updates, a.fixes.len() + a.baro.len());
        assert_eq!(got.0, expected.0);
        assert_eq!(got.1, expected.1);
    }
}
