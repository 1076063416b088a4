//! A start from any heading: a bank of sessions, one per sector of heading, run side
//! by side on the same samples and aids until the data have told them apart; the most
//! likely one goes on (a multiple-model start, e.g. Groves 2013 §14.3.2 on
//! in-motion alignment; Bar-Shalom, Li & Kirubarajan 2001 ch. 11 on the likelihood).
//!
//! Member `k` of `n` starts at heading `2πk/n` with a heading standard deviation of
//! `π/n`, so the true heading is within one standard deviation of one member (an
//! error-state filter linearized about a heading several tens of degrees off diverges;
//! one within its sector converges once accelerations or turns make the heading
//! observable). Each tested measurement adds its Gaussian log-likelihood
//! `−½ (zᵀ S⁻¹ z + ln det S + d ln 2π)` to its member's score (the diagonal of `S`
//! stands for its determinant: the innovations of one fix are nearly uncorrelated),
//! refused measurements included: a wrong heading makes the fixes disagree with the
//! inertial solution, and its score falls behind. Nothing depends on how the vehicle
//! moves relative to its axes, so this serves multicopters, which the course start
//! ([`crate::align::in_motion`]) cannot.

use super::{Aid, Event, Session, SessionConfig, SessionError, Start};
use crate::earth::EarthModel;
use crate::imu::ImuSample;
use crate::nav::NavState;

/// One member of the bank.
#[derive(Debug, Clone)]
struct Member<E: EarthModel> {
    yaw: f64,
    session: Session<E>,
    events: Vec<Event>,
    log_likelihood: f64,
}

/// The bank (module doc).
#[derive(Debug, Clone)]
pub struct HeadingBank<E: EarthModel> {
    members: Vec<Member<E>>,
}

/// The member the bank keeps.
#[derive(Debug)]
pub struct Chosen<E: EarthModel> {
    /// Its session, to go on with (its epochs so far not yet taken).
    pub session: Session<E>,
    /// Its events so far.
    pub events: Vec<Event>,
    /// Its initial heading [rad].
    pub yaw0: f64,
    /// Every member's initial heading [rad] and log-likelihood, in order.
    pub scores: Vec<(f64, f64)>,
}

impl<E: EarthModel> HeadingBank<E> {
    /// `n` sessions with `config` from `start`, whose heading each member replaces
    /// (and whose filter's heading standard deviation becomes `π/n`).
    pub fn new(
        earth: E,
        config: SessionConfig,
        start: Start,
        n: usize,
    ) -> Result<Self, SessionError> {
        let n = n.max(1);
        let sector = std::f64::consts::PI / n as f64;
        let members = (0..n)
            .map(|k| {
                let yaw = 2.0 * sector * k as f64;
                let mut cfg = config;
                if let Some(f) = cfg.filter.as_mut() {
                    f.integration.init_att_std.z = sector;
                }
                let e = start.state.euler();
                let state = NavState::new(
                    start.state.t,
                    start.state.pos,
                    start.state.v_n,
                    crate::rotation::Euler { yaw, ..e },
                );
                Ok(Member {
                    yaw,
                    session: Session::new(earth, cfg, Start { state, ..start })?,
                    events: Vec::new(),
                    log_likelihood: 0.0,
                })
            })
            .collect::<Result<Vec<_>, SessionError>>()?;
        Ok(Self { members })
    }

    /// Every member's snapshots carry NEES against `truth`
    /// ([`Session::with_truth`]).
    pub fn with_truth(self, truth: &[crate::analysis::errors::NavRecord]) -> Self {
        let members = self
            .members
            .into_iter()
            .map(|m| Member {
                session: m.session.with_truth(truth.to_vec()),
                ..m
            })
            .collect();
        Self { members }
    }

    /// Push a sample into every member and score what they tested.
    pub fn push_imu(&mut self, s: ImuSample) -> Result<(), SessionError> {
        for m in &mut self.members {
            m.session.push_imu(s)?;
            for e in m.session.events() {
                if let Event::Measurement(i) = &e {
                    let ln_det: f64 = i.s_diag.iter().map(|v| v.max(f64::MIN_POSITIVE).ln()).sum();
                    let d = i.z.len() as f64;
                    m.log_likelihood -=
                        0.5 * (i.nis + ln_det + d * (2.0 * std::f64::consts::PI).ln());
                }
                m.events.push(e);
            }
        }
        Ok(())
    }

    /// Push an aid into every member.
    pub fn push(&mut self, aid: Aid) -> Result<(), SessionError> {
        self.members
            .iter_mut()
            .try_for_each(|m| m.session.push(aid.clone()))
    }

    /// Every member's initial heading [rad] and log-likelihood so far.
    pub fn scores(&self) -> Vec<(f64, f64)> {
        self.members
            .iter()
            .map(|m| (m.yaw, m.log_likelihood))
            .collect()
    }

    /// Whether the data have told the headings apart: the most likely member leads
    /// every member more than one sector away from it by `margin` in log-likelihood
    /// (its neighbours may stay close: the true heading can lie between two).
    pub fn separated(&self, margin: f64) -> bool {
        let n = self.members.len();
        let Some(best) = (0..n).max_by(|&a, &b| {
            self.members[a]
                .log_likelihood
                .total_cmp(&self.members[b].log_likelihood)
        }) else {
            return false;
        };
        let far = (0..n).filter(|&k| {
            let d = (k + n - best) % n;
            d > 1 && d < n - 1
        });
        let rival = far
            .map(|k| self.members[k].log_likelihood)
            .fold(f64::NEG_INFINITY, f64::max);
        self.members[best].log_likelihood - rival > margin
    }

    /// Keep the most likely member.
    pub fn decide(self) -> Chosen<E> {
        let scores = self.scores();
        let best = self
            .members
            .into_iter()
            .max_by(|a, b| a.log_likelihood.total_cmp(&b.log_likelihood));
        match best {
            Some(m) => Chosen {
                session: m.session,
                events: m.events,
                yaw0: m.yaw,
                scores,
            },
            // `new` makes at least one member.
            None => unreachable!("a heading bank has at least one member"),
        }
    }
}
