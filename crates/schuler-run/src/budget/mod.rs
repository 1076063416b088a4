//! `schuler budget`: the error budget of a scenario ([`schuler::analysis::budget`]).
//!
//! The configuration is a Monte-Carlo campaign's ([`CampaignConfig`]: a `schuler
//! simulate` scenario, `[navigate]` with `schuler nav`'s options, `[campaign]` with the
//! streams the filter gets), so that a budget and a campaign of one file describe the
//! same filter on the same trajectory. The scenario is simulated once (its exact
//! samples and truth; the random draws are not used), the filter's configuration is
//! nav's plan of `[navigate]` ([`crate::campaign::navigate`]'s start at the truth),
//! and the budget propagates along the truth with the GNSS fixes' and barometer
//! readings' times and accuracies, on the scenario's Earth.
//!
//! Not yet here: vehicle aids (ZUPT, NHC, odometer, heading), tight coupling, a recorded
//! navigation file as trajectory.

pub mod held;
pub mod tables;

use crate::aided::GivenReadings;
use crate::campaign::navigate::start_options;
use crate::campaign::{CampaignConfig, outages};
use crate::nav::{NavConfig, plan_of, resolve_aiding};
use anyhow::{Context, Result, bail};
use held::Held;
use nalgebra::Vector3;
use schuler::analysis::budget::{Budget, nav_variances};
use schuler::analysis::errors::NavRecord;
use schuler::earth::{EarthModel, Sphere, Wgs84};
use schuler::filter::IntegrationConfig;
use schuler::sim::run::{EarthSpec, simulate_on};

/// The navigation standard deviations at one time (NED; m, m/s, rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SigmaRow {
    /// Time [s].
    pub t: f64,
    /// Position, velocity, attitude standard deviations per NED axis.
    pub std: [Vector3<f64>; 3],
}

/// The variances of one source (or the whole) at one time, by what they matter for.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Share {
    /// Horizontal position `σ_N² + σ_E²` [m²].
    pub pos_h: f64,
    /// Down position [m²].
    pub pos_d: f64,
    /// Horizontal velocity [m²/s²].
    pub vel_h: f64,
    /// Tilt, about north and east [rad²].
    pub tilt: f64,
    /// Heading, about down [rad²].
    pub heading: f64,
}

impl Share {
    fn of(p: &nalgebra::DMatrix<f64>) -> Self {
        let [r, v, a] = nav_variances(p);
        Self {
            pos_h: r.x + r.y,
            pos_d: r.z,
            vel_h: v.x + v.y,
            tilt: a.x + a.y,
            heading: a.z,
        }
    }
}

/// Every source's share and the whole at one event.
#[derive(Debug, Clone, PartialEq)]
pub struct Shares {
    /// What the time is (`outage 1 end`, `end`).
    pub event: String,
    /// Time [s].
    pub t: f64,
    /// One per source, in [`BudgetResult::sources`]' order.
    pub parts: Vec<Share>,
    /// The whole filter's.
    pub total: Share,
}

/// What a budget gave.
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetResult {
    /// The sources' names, in table order.
    pub sources: Vec<String>,
    /// Standard deviations every second.
    pub sigma: Vec<SigmaRow>,
    /// The shares at the end of each GNSS outage and at the end.
    pub shares: Vec<Shares>,
    /// The largest `|Σ Pᵢ − P|` of the navigation variances over `P`'s, at the events.
    pub largest_gap: f64,
    /// Measurements applied.
    pub updates: u64,
}

/// The budget of `c`'s scenario and filter.
pub fn run(c: &CampaignConfig) -> Result<BudgetResult> {
    let mut held = Held::default();
    simulate_on(&c.scenario, 1, &mut held).context("simulating the scenario")?;
    let (_, first) = *held
        .imu
        .first()
        .context("the simulation gave no IMU sample")?;
    let plan = plan_of(NavConfig::from_options(start_options(
        &c.nav_options,
        &NavRecord::from(&first),
    ))?)?;
    let s = &c.scenario;
    let gnss = c.streams.gnss && s.gnss.is_some();
    let baro = c.streams.baro && s.baro.is_some();
    if !gnss {
        held.fixes.clear();
    }
    if !c.streams.gnss_velocity {
        held.fixes.iter_mut().for_each(|f| f.vel = None);
    }
    if !baro {
        held.baro.clear();
    }
    let readings = GivenReadings {
        fixes: gnss.then(|| held.fixes.clone()),
        baro: baro.then(|| held.baro.clone()),
        ..Default::default()
    };
    let Some(aiding) = resolve_aiding(&plan.alignment, &plan.aiding, readings)? else {
        bail!(
            "{}: the filter gets no aid; a free-inertial budget is not available yet",
            c.origin
        );
    };
    let filter = &aiding.filter;
    let events = outages(s)?;
    let run = Run {
        held: &held,
        cfg: filter.integration,
        baro_std: filter.baro_std,
        outage_ends: events.iter().map(|o| o.1).collect(),
    };
    Ok(match s.earth {
        EarthSpec::Wgs84 => run.on(Wgs84),
        EarthSpec::Sphere => run.on(Sphere::textbook(true)),
        EarthSpec::SphereFixed => run.on(Sphere::textbook(false)),
    })
}

/// One budget's inputs.
struct Run<'a> {
    held: &'a Held,
    cfg: IntegrationConfig,
    baro_std: f64,
    outage_ends: Vec<f64>,
}

impl Run<'_> {
    fn on<E: EarthModel>(&self, earth: E) -> BudgetResult {
        let imu = &self.held.imu;
        let start = imu[0].1;
        let mut b = Budget::new(earth, start, self.cfg);
        if let Some(f) = self.held.fixes.first() {
            b.declare(schuler::filter::measurement::Kind::GnssPosition);
            if f.vel.is_some() {
                b.declare(schuler::filter::measurement::Kind::GnssVelocity);
            }
        }
        if !self.held.baro.is_empty() {
            b.declare(schuler::filter::measurement::Kind::BaroHeight);
        }
        let sources = b.parts().iter().map(|p| p.source.name()).collect();
        let (mut fixes, mut baro) = (
            self.held.fixes.iter().peekable(),
            self.held.baro.iter().peekable(),
        );
        let mut ends = self.outage_ends.iter().enumerate().peekable();
        let mut out = BudgetResult {
            sources,
            sigma: Vec::new(),
            shares: Vec::new(),
            largest_gap: 0.0,
            updates: 0,
        };
        let mut next_second = start.t.ceil();
        for (s, truth) in imu {
            if s.t > start.t {
                b.step(s, truth);
            }
            while let Some((i, _)) = ends.next_if(|(_, e)| **e <= s.t) {
                b.propagate();
                out.shares.push(shares(&b, format!("outage {} end", i + 1)));
            }
            if s.t >= next_second {
                b.propagate();
                out.sigma.push(sigma(&b));
                next_second = s.t.floor() + 1.0;
            }
            while let Some(f) = fixes.next_if(|f| f.t <= s.t) {
                b.gnss(&f.pos_std, f.vel.as_ref().map(|v| &v.1));
            }
            while baro.next_if(|r| r.0 <= s.t).is_some() {
                b.baro(self.baro_std);
            }
        }
        b.propagate();
        out.shares.push(shares(&b, "end".into()));
        out.largest_gap = out.shares.iter().map(gap).fold(0.0, f64::max);
        out.updates = b.updates();
        out
    }
}

fn sigma<E: EarthModel>(b: &Budget<E>) -> SigmaRow {
    SigmaRow {
        t: b.truth().t,
        std: nav_variances(b.total()).map(|v| v.map(|x| x.max(0.0).sqrt())),
    }
}

fn shares<E: EarthModel>(b: &Budget<E>, event: String) -> Shares {
    Shares {
        event,
        t: b.truth().t,
        parts: b.parts().iter().map(|p| Share::of(&p.p)).collect(),
        total: Share::of(b.total()),
    }
}

/// The largest relative difference between the sum of the parts and the whole.
fn gap(s: &Shares) -> f64 {
    let field = |f: fn(&Share) -> f64| {
        let sum: f64 = s.parts.iter().map(f).sum();
        let whole = f(&s.total);
        if whole > 0.0 {
            (sum - whole).abs() / whole
        } else {
            0.0
        }
    };
    [
        field(|x| x.pos_h),
        field(|x| x.pos_d),
        field(|x| x.vel_h),
        field(|x| x.tilt),
        field(|x| x.heading),
    ]
    .into_iter()
    .fold(0.0, f64::max)
}
